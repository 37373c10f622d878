/* What a `shape_series` Jacobian row costs with rods (fit/costs/shape_series.c),
 * exact against differenced: a stalk of the real-data flowers' geometry
 * (measurements/examples/plant_motion/flowers.yaml, flower 1: 8 segments,
 * L = 37 mm, r = 1 mm, a 1 g flower, clamped at 142°) walked through 103
 * observations as E falls from 11.6 to 3.6 MPa (the fitted history), each
 * warm-started from the previous equilibrium as the fit does.  Per
 * observation:
 *   exact:       the static solve + phc_rod_static_sensitivity (one
 *                factorisation and solve) → d angle / dE;
 *   differenced: the static solve + two more warm-started solves at
 *                E (1 ± 1e-4) (the data set's path before the sensitivities).
 * Prints the thread CPU time per observation (best of the repeats), the
 * ratio that decides the fit's speed-up (differenced / exact), the Newton
 * iterations, the largest difference between the two derivatives, and the
 * other processes' load during the timing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench/bench_machine.h"
#include "model/plant_graph.h"
#include "model/rod.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define N_OBS 103
#define N_SEG 8

static double thread_cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static phc_plant_graph *stalk(void)
{
    const double L = 0.037, r = 1e-3, beta = 142.0 * M_PI / 180.0, h = L / N_SEG, h0 = 1e-3 * h;
    phc_plant_graph *g = phc_plant_graph_new(N_SEG + 1);
    for (size_t i = 0; i <= N_SEG; ++i) {
        const double a = i ? (double)(i - 1) * h : -h0, b = i ? a + h : 0.0;
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = r;
        g->length[i] = b - a;
        g->source_id[i] = (long)i;
        g->head[3 * i] = a * cos(beta);
        g->head[3 * i + 2] = a * sin(beta);
        g->tail[3 * i] = b * cos(beta);
        g->tail[3 * i + 2] = b * sin(beta);
    }
    g->fixed[0] = 1;
    phc_error err;
    if (phc_plant_graph_finish(g, "bench stalk", &err)) {
        fprintf(stderr, "%s\n", err.message);
        exit(1);
    }
    return g;
}

static double angle(const phc_rod *rod, double gh[3], double gt[3])
{
    double h[3], t[3];
    phc_rod_head(rod, N_SEG, h);
    phc_rod_tail(rod, N_SEG, t);
    const double dx = t[0] - h[0], dz = t[2] - h[2], r2 = dx * dx + dz * dz;
    if (gh) {
        gt[0] = -dz / r2;
        gt[1] = 0;
        gt[2] = dx / r2;
        for (int k = 0; k < 3; ++k)
            gh[k] = -gt[k];
    }
    return atan2(dz, dx);
}

static int solve_at(phc_rod *rod, double E, int *its)
{
    double young[N_SEG + 1];
    phc_rod_report rep;
    phc_error err;
    for (int i = 0; i <= N_SEG; ++i)
        young[i] = E;
    if (phc_rod_set_modulus(rod, young, &err) || phc_rod_solve_static(rod, &rep, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    *its += rep.iterations;
    return 0;
}

/* One pass over the observations; derivative[i] = d angle / dE. */
static int pass(phc_rod *rod, int exact, double *deriv, int *its)
{
    phc_rod_reset(rod);
    double ones[N_SEG + 1], dz[6 * (N_SEG + 1)];
    for (int i = 0; i <= N_SEG; ++i)
        ones[i] = 1.0;
    for (int o = 0; o < N_OBS; ++o) {
        const double E = 11.6e6 * pow(3.6 / 11.6, (double)o / (N_OBS - 1));
        if (solve_at(rod, E, its))
            return 1;
        if (exact) {
            double gh[3], gt[3], dh[3], dt[3];
            phc_error err;
            angle(rod, gh, gt);
            if (phc_rod_static_sensitivity(rod, 1, ones, dz, &err)) {
                fprintf(stderr, "%s\n", err.message);
                return 1;
            }
            phc_rod_end_sensitivity(rod, N_SEG, dz, dh, dt);
            deriv[o] = 0;
            for (int k = 0; k < 3; ++k)
                deriv[o] += gh[k] * dh[k] + gt[k] * dt[k];
        } else {
            const double h = 1e-4 * E;
            if (solve_at(rod, E + h, its))
                return 1;
            const double ap = angle(rod, NULL, NULL);
            if (solve_at(rod, E - h, its))
                return 1;
            deriv[o] = (ap - angle(rod, NULL, NULL)) / (2 * h);
        }
    }
    return 0;
}

int main(void)
{
    phc_plant_graph *g = stalk();
    double young[N_SEG + 1];
    for (int i = 0; i <= N_SEG; ++i)
        young[i] = 1e7;
    phc_rod *rod = NULL;
    phc_error err;
    if (phc_rod_new(g, young, NULL, &rod, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const double F[3] = {0, 0, -1e-3 * 9.81};
    phc_rod_set_load(rod, N_SEG, F, &err);
    const int repeats = bench_repeats(20);
    double best[2] = {INFINITY, INFINITY}, d[2][N_OBS];
    int its[2] = {0, 0};
    const cpu_mark m0 = cpu_now();
    for (int r = 0; r < repeats; ++r)
        for (int exact = 0; exact < 2; ++exact) {
            int it = 0;
            const double t0 = thread_cpu();
            if (pass(rod, exact, d[exact], &it))
                return 1;
            best[exact] = fmin(best[exact], thread_cpu() - t0);
            its[exact] = it;
        }
    const cpu_mark m1 = cpu_now();
    double worst = 0, scale = 0;
    for (int o = 0; o < N_OBS; ++o) {
        worst = fmax(worst, fabs(d[0][o] - d[1][o]));
        scale = fmax(scale, fabs(d[1][o]));
    }
    printf("stalk: 8 segments, 103 observations, E 11.6 -> 3.6 MPa, warm-started\n");
    printf("Newton iterations per pass: exact %d, differenced %d\n", its[1], its[0]);
    printf("d angle/dE, exact vs differenced (fd_step 1e-4): largest difference %.2e of %.3g rad/Pa\n",
           worst / scale, scale);
    printf("thread CPU per observation, solve + d angle/dE: exact %.1f us, differenced %.1f us\n",
           1e6 * best[1] / N_OBS, 1e6 * best[0] / N_OBS);
    printf("ratio differenced / exact: %.2f\n", best[0] / best[1]);
    printf("other processes' load during the timing: %.2f CPUs (best of %d passes each)\n", other_load(m0, m1),
           repeats);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
    return 0;
}
