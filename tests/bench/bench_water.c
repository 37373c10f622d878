/* Benchmarks of the water model: prints `name: value unit` lines.
 * (The SciPy peer tests/bench/water_peer.py is not written yet.) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <time.h>

#include "measurements/plant_io.h"
#include "model/water.h"

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double bdf6_ns(const phc_water_system *s, size_t steps)
{
    phc_water_bdf6 *b = NULL;
    phc_error err;
    phc_water_bdf6_new(s, 10.0, 0, &b, &err);
    double t0 = now();
    phc_water_bdf6_advance(b, 10.0 * (double)steps, &err);
    double dt = now() - t0;
    size_t taken = phc_water_bdf6_steps(b) - 5;
    phc_water_bdf6_free(b);
    return dt * 1e9 / ((double)taken * (double)phc_water_system_size(s));
}

int main(void)
{
    phc_error err;
    phc_water_params p = phc_water_params_default();
    p.weights = PHC_WATER_REFERENCE;
    p.loss_rate = 6e-3;
    p.initial_water = 8.0;
    phc_plant_graph *g = NULL;
    struct stat st;
    if (stat(PHC_SHARED_DATA "/plants/plant000.txt", &st) == 0 &&
        phc_plant_io_read(PHC_SHARED_DATA "/plants/plant000.txt", PHC_PLANT_FORMAT_PAPER, 0, &g,
                          &err) == 0) {
        phc_water_system *s = NULL;
        phc_water_system_new(g, &p, &s, &err);
        printf("bdf6_ns_per_segment_step_plant000: %.2f ns\n", bdf6_ns(s, 1000));
        phc_water_exact *e = NULL;
        double t0 = now();
        phc_water_exact_new(s, PHC_WATER_EXACT_FULL, &e, &err);
        double t1 = now();
        phc_water_exact *w = NULL;
        phc_water_exact_new(s, PHC_WATER_EXACT_TOTAL_ONLY, &w, &err);
        double t2 = now();
        printf("exact_setup_full_plant000: %.3f s\n", t1 - t0);
        printf("exact_setup_w_only_plant000: %.3f s\n", t2 - t1);
        volatile double acc = 0;
        double t3 = now();
        for (int i = 0; i < 1000; ++i)
            acc += phc_water_exact_total(w, 10.0 * i);
        printf("exact_w_eval_plant000: %.2f us\n", (now() - t3) * 1e3);
        double We = phc_water_exact_total(e, 1e4), Wb = 0;
        phc_water_bdf6 *b = NULL;
        t0 = now();
        phc_water_bdf6_new(s, 10.0, 0, &b, &err);
        phc_water_bdf6_advance(b, 1e4, &err);
        t1 = now();
        phc_water_bdf6_total(b, 1e4, &Wb, NULL, &err);
        printf("bdf6_total_time_reference_setting: %.4f s\n", t1 - t0);
        printf("bdf6_rel_error_vs_exact_reference_setting: %.2e 1 (authors' 5e-5)\n",
               fabs(Wb - We) / We);
        printf("reference_W_1e4_exact: %.6f g\n", We);
        phc_water_bdf6_free(b);
        phc_water_exact_free(e);
        phc_water_exact_free(w);
        phc_water_system_free(s);
        phc_plant_graph_free(g);
    } else {
        printf("plant000: skipped (no %s)\n", PHC_SHARED_DATA);
    }
    g = phc_plant_graph_random(100000, 1);
    if (g) {
        phc_water_system *s = NULL;
        phc_water_system_new(g, &p, &s, &err);
        printf("bdf6_ns_per_segment_step_100k: %.2f ns\n", bdf6_ns(s, 200));
        phc_water_system_free(s);
        p.weights = PHC_WATER_POISEUILLE;
        phc_water_system_new(g, &p, &s, &err);
        printf("bdf6_ns_per_segment_step_100k_poiseuille: %.2f ns\n", bdf6_ns(s, 200));
        phc_water_system_free(s);
        phc_plant_graph_free(g);
    }
    return 0;
}
