/* Benchmark of the elastic rods (model/rod.h, issue 19 "Speed"): prints
 * `name: value unit` lines.  One thread.
 *
 * (a) The direct solver's cost per segment per Newton iteration: one
 *     static Newton iteration as the solver takes it at the rest state
 *     (assembly of residual and Newton matrix, then the tree factorisation
 *     and solve in one sweep, phc_rod_tree_factor_solve; rod_internal.h
 *     hooks), and apart the factorisation and the solve, best of
 *     REPEAT timings of enough iterations to take ~0.2 s; on plant000
 *     (../shared/data/plants/plant000.txt, 1964 segments; skipped with a
 *     message when absent) and on phc_plant_graph_random(100000, 1).  Also
 *     the whole static solve's time per segment per iteration (line search
 *     and residual measure included).
 * (b) plant000's static equilibrium from rest (phc_rod_reset, then
 *     phc_rod_solve_static at the default tolerance 1e-10): wall time, best
 *     and median of REPEAT, and the Newton iterations.
 * (c) memory per segment: bytes phc_rod_new allocates (mallinfo2, in-use
 *     heap before and after) / n.  A static solve allocates 26 doubles
 *     per segment more while it runs (its saved states; not measured).
 * (d) peer in the same run: the authors' Gauss–Seidel scheme
 *     (PHC_ROD_GAUSS_SEIDEL, 1 iteration × 5 sub-steps per frame,
 *     velocities × 0.99 per sub-step as in their PlantDemo) on plant000
 *     from rest, at their sub-step of 0.0025 s and at a small one of
 *     0.0002 s, timed per frame (at most GS_FRAMES frames); its error
 *     against the converged equilibrium (the static solve at tolerance
 *     1e-13, REFERENCE) after the same wall time as the direct static solve
 *     (best of REPEAT) and at the end.  The direct solve's error is that of
 *     its default-tolerance result against the same reference.  Error: the
 *     largest distance of a segment's tail from its position in the
 *     reference equilibrium, m, and that over the reference's largest tail
 *     displacement from rest (the droop).
 *
 * Moduli (Young's modulus, the same for every segment, Pa): plant000
 * E_PLANT = 5e7 Pa (a soft green stem: the 25 cm plant droops visibly, its
 * tails move by up to 6 cm, and Newton converges from rest in 4 iterations), the
 * 100k tree E_TREE = 2e8 Pa as in tests/unit/test_rod.c.  `bench_bench_rod E`
 * uses E for plant000; `bench_bench_rod E x` skips the 100k tree.  Density 1000
 * kg m⁻³, ν 0.5, gravity (0, 0, −9.81) m s⁻² (the defaults).
 *
 * Times are wall-clock (CLOCK_MONOTONIC) on a shared machine: the CPUs kept
 * busy by other processes during each timing are printed beside it
 * (bench_machine.h), and the thread's own CPU time too. */
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "bench_machine.h"
#include "measurements/plant_io.h"
#include "model/rod.h"
#include "model/segment_stiffness.h"
#include "model/water.h"
#include "model/rod_internal.h"
#include "model/rod_tree_solver.h"

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif

#define PLANT000 PHC_SHARED_DATA "/plants/plant000.txt"
static double E_PLANT = 5e7;
#define E_TREE 2e8
#define REPEAT 5
#define GS_STEP_AUTHORS 0.0025
#define GS_STEP_SMALL 0.0002
#define GS_SUBSTEPS 5
#define GS_FRAMES 1000
#define REFERENCE_TOL 1e-13
#define TARGET_US 1.0
#define TARGET_STATIC_MS 50.0
#define TARGET_ERROR_RATIO 100.0

static double cpu_thread(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static size_t heap_in_use(void)
{
    struct mallinfo2 mi = mallinfo2();
    return mi.uordblks + mi.hblkhd;
}

/* Sets every modulus to e and builds the rod; prints the memory line. */
static phc_rod *make_rod(const phc_plant_graph *g, double e, const char *tag)
{
    phc_error err;
    phc_rod *rod = NULL;
    double *young = malloc(g->n * sizeof *young);
    if (!young)
        return NULL;
    for (size_t i = 0; i < g->n; ++i)
        young[i] = e;
    const size_t before = heap_in_use();
    const int rc = phc_rod_new(g, young, NULL, &rod, &err);
    const size_t after = heap_in_use();
    free(young);
    if (rc != PHC_OK) {
        printf("%s: %s\n", tag, err.message);
        return NULL;
    }
    printf("memory_per_segment_%s: %.0f B (phc_rod_new, in-use heap by mallinfo2, %zu segments)\n", tag,
           (double)(after - before) / (double)g->n, g->n);
    return rod;
}

/* (a): the parts of one Newton iteration, µs per segment, best of REPEAT. */
static void newton_parts(phc_rod *rod, const char *tag)
{
    phc_error err;
    const size_t n = phc_rod_segment_count(rod);
    phc_rod_reset(rod);
    if (phc_rod_internal_prepare_static(rod, &err) != PHC_OK) {
        printf("%s: %s\n", tag, err.message);
        return;
    }
    /* iterations per timing: about 0.2 s at 3 µs per segment-iteration */
    int reps = (int)(0.2 / (3e-6 * (double)n));
    if (reps < 3)
        reps = 3;
    double best[5] = {INFINITY, INFINITY, INFINITY, INFINITY, INFINITY}, cpu[5] = {0}, load = 0.0;
    for (int r = 0; r < bench_repeats(REPEAT); ++r) {
        double t[5] = {0, 0, 0, 0, 0}, c[5] = {0, 0, 0, 0, 0};
        cpu_mark m0 = cpu_now();
        for (int k = 0; k < reps; ++k) {
            double a = now(), ca = cpu_thread();
            phc_rod_internal_assemble_static(rod, 1);
            double b = now(), cb = cpu_thread();
            for (size_t i = 0; i < 12 * n; ++i)
                rod->sol[i] = -rod->res[i];
            double b2 = now(), cb2 = cpu_thread();
            const size_t bad = phc_rod_tree_factor(rod->tree);
            double d = now(), cd = cpu_thread();
            if (bad != PHC_TREE_NONE) {
                printf("%s: singular node %zu\n", tag, bad);
                return;
            }
            double e = now(), ce = cpu_thread();
            phc_rod_tree_solve(rod->tree, rod->sol);
            double f = now(), cf = cpu_thread();
            /* the solver's own path (model/rod.c): both in one sweep */
            phc_rod_internal_assemble_static(rod, 1);
            for (size_t i = 0; i < 12 * n; ++i)
                rod->sol[i] = -rod->res[i];
            double g = now(), cg = cpu_thread();
            if (phc_rod_tree_factor_solve(rod->tree, rod->sol) != PHC_TREE_NONE) {
                printf("%s: singular node\n", tag);
                return;
            }
            double h = now(), ch = cpu_thread();
            t[0] += b - a, t[1] += d - b2, t[2] += f - e, t[4] += h - g;
            c[0] += cb - ca, c[1] += cd - cb2, c[2] += cf - ce, c[4] += ch - cg;
        }
        cpu_mark m1 = cpu_now();
        /* one iteration of the solver: assembly, then factorisation and
         * solve in one sweep */
        t[3] = t[0] + t[4];
        c[3] = c[0] + c[4];
        if (t[3] < best[3]) {
            memcpy(best, t, sizeof best);
            memcpy(cpu, c, sizeof cpu);
            load = other_load(m0, m1);
        }
    }
    const double s = 1e6 / ((double)reps * (double)n);
    printf("newton_us_per_segment_iteration_%s: %.3f us (assembly %.3f + factorisation and solve "
           "in one sweep %.3f; apart: factorisation %.3f, solve %.3f; best of %d timings of %d "
           "iterations; thread CPU %.3f us; other load %.2f CPUs)\n",
           tag, best[3] * s, best[0] * s, best[4] * s, best[1] * s, best[2] * s, bench_repeats(REPEAT), reps,
           cpu[3] * s, load);
}

/* largest |tail_i − ref_i| (m) */
static double tail_error(const phc_rod *rod, const double *ref)
{
    double e = 0.0;
    for (size_t i = 0; i < phc_rod_segment_count(rod); ++i) {
        double t[3];
        phc_rod_tail(rod, i, t);
        const double dx = t[0] - ref[3 * i], dy = t[1] - ref[3 * i + 1], dz = t[2] - ref[3 * i + 2];
        e = fmax(e, sqrt(dx * dx + dy * dy + dz * dz));
    }
    return e;
}

/* (b) on a rod: best and median wall time of `repeat` (<= REPEAT) static
 * solves from rest; leaves the rod at the equilibrium.  Returns the best, s. */
static double static_from_rest(phc_rod *rod, const char *tag, int repeat)
{
    phc_error err;
    phc_rod_report rep;
    double t[REPEAT], load = 0.0, cpu_best = 0.0, best = INFINITY;
    const size_t n = phc_rod_segment_count(rod);
    for (int r = 0; r < repeat; ++r) {
        phc_rod_reset(rod);
        cpu_mark m0 = cpu_now();
        const double c0 = cpu_thread();
        const int rc = phc_rod_solve_static(rod, &rep, &err);
        const double c1 = cpu_thread();
        cpu_mark m1 = cpu_now();
        if (rc != PHC_OK) {
            printf("%s: static solve failed: %s\n", tag, err.message);
            return NAN;
        }
        t[r] = m1.wall - m0.wall;
        if (t[r] < best) {
            best = t[r];
            load = other_load(m0, m1);
            cpu_best = c1 - c0;
        }
    }
    qsort(t, (size_t)repeat, sizeof *t, cmp_double);
    printf("static_time_%s: %.2f ms (from rest, tolerance 1e-10; best of %d, median %.2f; thread "
           "CPU %.2f ms; other load %.2f CPUs)\n",
           tag, 1e3 * best, repeat, 1e3 * t[repeat / 2], 1e3 * cpu_best, load);
    printf("static_iterations_%s: %d (scaled residual %.2e)\n", tag, rep.iterations, rep.residual);
    printf("static_us_per_segment_iteration_%s: %.3f us (the whole solve, line search and residual "
           "measures included; best)\n",
           tag, 1e6 * best / ((double)n * (rep.iterations > 0 ? rep.iterations : 1)));
    return best;
}

/* (d): Gauss–Seidel frames from rest (1 iteration x GS_SUBSTEPS sub-steps of
 * `sub` s, v x 0.99 per sub-step); prints the lines (key suffix `sfx`) and
 * returns the error ratio at equal wall time over the direct solve's. */
static double gauss_seidel(phc_rod *rod, const double *ref, double droop, double t_direct,
                           double e_direct, double sub, const char *sfx)
{
    phc_error err;
    phc_rod_options o;
    phc_rod_options_default(&o);
    o.scheme = PHC_ROD_GAUSS_SEIDEL;
    o.substeps = GS_SUBSTEPS;
    o.gs_iterations = 1;
    o.damping = (1.0 / 0.99 - 1.0) / sub; /* v x 0.99 per sub-step */
    phc_rod_set_options(rod, &o, &err);
    phc_rod_reset(rod);
    const double frame = sub * GS_SUBSTEPS;
    int frames = 0, equal_frames = -1;
    double e_equal = NAN, t_equal = NAN, spent = 0.0;
    cpu_mark m0 = cpu_now();
    while (frames < GS_FRAMES) {
        const double a = now();
        if (phc_rod_step(rod, frame, NULL, &err) != PHC_OK) {
            printf("gauss_seidel_refused%s: at frame %d: %s\n", sfx, frames + 1, err.message);
            break;
        }
        spent += now() - a;
        ++frames;
        if (equal_frames < 0 && spent >= t_direct) {
            equal_frames = frames;
            t_equal = spent;
            e_equal = tail_error(rod, ref); /* outside the timed part */
        }
    }
    cpu_mark m1 = cpu_now();
    const double e_many = tail_error(rod, ref);
    printf("gauss_seidel_ms_per_frame%s: %.3f ms (1 iteration x %d sub-steps of %g s, damping %.4g "
           "s-1; mean of %d frames; other load %.2f CPUs)\n",
           sfx, 1e3 * spent / (frames ? frames : 1), GS_SUBSTEPS, sub, o.damping, frames,
           other_load(m0, m1));
    if (equal_frames > 0)
        printf("gauss_seidel_error_at_equal_time%s: %.3e m (after %d frames, %.2f ms; %.2e of the "
               "droop)\n",
               sfx, e_equal, equal_frames, 1e3 * t_equal, e_equal / droop);
    else
        printf("gauss_seidel_error_at_equal_time%s: none (it stopped before the direct solve's time)\n",
               sfx);
    printf("gauss_seidel_error_at_end%s: %.3e m (after %d frames = %.3g s simulated, %.2f s wall; "
           "%.2e of the droop; kinetic energy %.3e J)\n",
           sfx, e_many, frames, frames * frame, spent, e_many / droop, phc_rod_kinetic_energy(rod));
    const double floor_e = 1e-16 * droop, ratio = e_equal / fmax(e_direct, floor_e);
    printf("error_ratio_at_equal_time_gauss_seidel_over_direct%s: %.3g x (direct error %s)\n", sfx, ratio,
           e_direct < floor_e ? "below 1e-16 of the droop: floored there" : "as measured");
    printf("gauss_seidel_frames_in_direct_solve_time%s: %.1f (frames in the wall time of one direct static solve)\n", sfx,
           t_direct / (spent / (frames ? frames : 1)));
    phc_rod_options_default(&o);
    phc_rod_set_options(rod, &o, &err);
    return equal_frames > 0 ? ratio : 0.0;
}

/* (e) the water model and the water -> stiffness mapping against the rods,
 * per frame of a wilting simulation (the wilting paper's Fig. 11 puts the
 * water model at about 1% of a PBD frame).  A frame: the water model
 * advanced by one BDF6 step of WATER_STEP s, theta read, Young's moduli
 * mapped by eq. 9 on relative water (E_min 5e6, E_max 1e8 Pa, kappa 20,
 * chi0 0.8: the wilting notebooks' values); then the rods: the moduli set
 * and the static equilibrium solved warm from the previous frame's.  The
 * loss rate makes the plant lose water visibly over the FRAMES frames. */
#define WATER_STEP 60.0 /* s of water time per frame */
#define FRAMES 60
static void water_share(const phc_plant_graph *g, phc_rod *rod)
{
    phc_error err;
    const size_t n = g->n;
    double *theta = malloc(n * sizeof *theta), *E = malloc(n * sizeof *E);
    double volume = 0.0, t_water = 0.0, t_rod = 0.0, load = 0.0;
    double t_step = 0.0, t_state = 0.0, t_map = 0.0; /* the parts of t_water */
    int iterations = 0;
    phc_water_system *sys = NULL;
    phc_water_bdf6 *b = NULL;
    phc_water_params wp = phc_water_params_default();
    phc_segment_stiffness_params sp = phc_segment_stiffness_params_default();
    phc_rod_report rep;
    for (size_t i = 0; i < n; ++i)
        volume += phc_segment_volume_cm3(g, i);
    wp.initial_water = volume; /* relative water content 1 */
    wp.loss_rate = 1.5e-2;     /* 1/(cm^2 s): about 10% of the water in the FRAMES frames */
    sp.law = PHC_STIFFNESS_WATER;
    sp.content = PHC_STIFFNESS_RELATIVE;
    sp.logistic.kappa = 20.0;
    sp.logistic.chi0 = 0.8;
    sp.logistic.e_min = 5e6;
    sp.logistic.e_max = 1e8;
    if (!theta || !E || phc_water_system_new(g, &wp, &sys, &err) ||
        phc_water_bdf6_new(sys, WATER_STEP, 0, &b, &err)) {
        printf("water_share_plant000: set-up failed: %s\n", theta && E ? err.message : "out of memory");
        goto done;
    }
    phc_water_system_theta0(sys, theta);
    phc_rod_reset(rod);
    if (phc_segment_stiffness_water(g, &sp, theta, E, NULL, NULL, &err) ||
        phc_rod_set_modulus(rod, E, &err) || phc_rod_solve_static(rod, &rep, &err)) {
        printf("water_share_plant000: first frame failed: %s\n", err.message);
        goto done;
    }
    for (int k = 1; k <= FRAMES; ++k) {
        cpu_mark m0 = cpu_now();
        if (phc_water_bdf6_advance(b, k * WATER_STEP, &err)) {
            printf("water_share_plant000: water model failed: %s\n", err.message);
            goto done;
        }
        const double ta = now();
        phc_water_bdf6_state(b, theta, NULL);
        const double tb = now();
        if (phc_segment_stiffness_water(g, &sp, theta, E, NULL, NULL, &err)) {
            printf("water_share_plant000: mapping failed: %s\n", err.message);
            goto done;
        }
        cpu_mark m1 = cpu_now();
        t_step += ta - m0.wall;
        t_state += tb - ta;
        t_map += m1.wall - tb;
        if (phc_rod_set_modulus(rod, E, &err) || phc_rod_solve_static(rod, &rep, &err)) {
            printf("water_share_plant000: rod frame %d failed: %s\n", k, err.message);
            goto done;
        }
        cpu_mark m2 = cpu_now();
        t_water += m1.wall - m0.wall;
        t_rod += m2.wall - m1.wall;
        iterations += rep.iterations;
        load = fmax(load, other_load(m0, m2));
    }
    {
        double w = 0.0;
        for (size_t i = 0; i < n; ++i)
            w += theta[i];
        const double fraction = t_water / (t_water + t_rod);
        printf("water_frames_plant000: %d frames of %.0f s water time, water %.4f -> %.4f g, E %.3g Pa "
               "at the end\n",
               FRAMES, WATER_STEP, volume, w, E[0]);
        printf("water_mapping_us_per_frame_plant000: %.1f us (BDF6 step %.1f + state %.1f + eq. 9 "
               "mapping %.1f; other load %.2f CPUs)\n",
               1e6 * t_water / FRAMES, 1e6 * t_step / FRAMES, 1e6 * t_state / FRAMES,
               1e6 * t_map / FRAMES, load);
        printf("rod_frame_ms_plant000: %.2f ms (moduli set, static solve warm from the last frame, "
               "%.1f Newton iterations per frame)\n",
               1e3 * t_rod / FRAMES, (double)iterations / FRAMES);
        printf("water_fraction_of_frame_plant000: %.2f %%\n", 100.0 * fraction);
        printf("target_water_1pct_of_frame: %s (%.2f %%)\n", fraction <= 0.01 ? "met" : "not met",
               100.0 * fraction);
    }
done:
    phc_water_bdf6_free(b);
    phc_water_system_free(sys);
    free(theta);
    free(E);
}

static int run_plant000(void)
{
    struct stat st;
    phc_error err;
    phc_plant_graph *g = NULL;
    if (stat(PLANT000, &st) != 0) {
        printf("plant000: skipped (no %s)\n", PLANT000);
        return 0;
    }
    if (phc_plant_io_read(PLANT000, PHC_PLANT_FORMAT_PAPER, 0, &g, &err) != PHC_OK) {
        printf("plant000: %s\n", err.message);
        return 1;
    }
    const size_t n = g->n;
    printf("segments_plant000: %zu\n", n);
    printf("young_modulus_plant000: %.3g Pa (every segment)\n", E_PLANT);
    phc_rod *rod = make_rod(g, E_PLANT, "plant000");
    if (!rod) {
        phc_plant_graph_free(g);
        return 1;
    }
    newton_parts(rod, "plant000");

    /* the reference equilibrium */
    phc_rod_options o;
    phc_rod_options_default(&o);
    o.tolerance = REFERENCE_TOL;
    phc_rod_report rep;
    double *ref = malloc(3 * n * sizeof *ref);
    if (!ref || phc_rod_set_options(rod, &o, &err) != PHC_OK) {
        printf("plant000: out of memory\n");
        return 1;
    }
    phc_rod_reset(rod);
    if (phc_rod_solve_static(rod, &rep, &err) != PHC_OK) {
        printf("plant000: reference solve failed: %s\n", err.message);
        return 1;
    }
    double droop = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double d[3];
        phc_rod_tail(rod, i, ref + 3 * i);
        phc_rod_tip_deflection(rod, i, d);
        droop = fmax(droop, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    printf("reference_equilibrium_plant000: %d Newton iterations to scaled residual %.2e (tolerance "
           "%.0e)\n",
           rep.iterations, rep.residual, REFERENCE_TOL);
    printf("largest_tail_displacement_plant000: %.4f m (the droop under gravity)\n", droop);
    phc_rod_options_default(&o);
    phc_rod_set_options(rod, &o, &err);

    /* (b) */
    const double t_direct = static_from_rest(rod, "plant000", bench_repeats(REPEAT));
    if (!isfinite(t_direct))
        return 1;
    const double e_direct = tail_error(rod, ref);
    printf("direct_error_plant000: %.3e m (default tolerance vs the reference; %.2e of the droop)\n",
           e_direct, e_direct / droop);

    /* (d) the peer at the authors' sub-step and at a small one */
    const double e_ratio = gauss_seidel(rod, ref, droop, t_direct, e_direct, GS_STEP_AUTHORS, "");
    gauss_seidel(rod, ref, droop, t_direct, e_direct, GS_STEP_SMALL, "_small_step");
    printf("target_static_50ms_plant000: %s (%.2f ms)\n", 1e3 * t_direct <= TARGET_STATIC_MS ? "met" : "not met",
           1e3 * t_direct);
    printf("target_error_ratio_100x: %s (at the authors' sub-step)\n",
           e_ratio >= TARGET_ERROR_RATIO ? "met" : "not met");
    water_share(g, rod);
    free(ref);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
    return 0;
}

static int run_tree(size_t n)
{
    char tag[32];
    snprintf(tag, sizeof tag, "%zuk", n / 1000);
    phc_plant_graph *g = phc_plant_graph_random(n, 1);
    if (!g) {
        printf("tree_%s: out of memory\n", tag);
        return 1;
    }
    printf("segments_tree_%s: %zu (phc_plant_graph_random(%zu, 1))\n", tag, n, n);
    printf("young_modulus_tree_%s: %.3g Pa (every segment)\n", tag, E_TREE);
    phc_rod *rod = make_rod(g, E_TREE, tag);
    if (!rod) {
        phc_plant_graph_free(g);
        return 1;
    }
    newton_parts(rod, tag);
    static_from_rest(rod, tag, bench_repeats(3));
    phc_rod_free(rod);
    phc_plant_graph_free(g);
    return 0;
}

/* bench_bench_rod [E_plant000 [plant000]]: another modulus for plant000
 * (Pa), and plant000 alone (to choose the modulus). */
int main(int argc, char **argv)
{
    if (argc > 1)
        E_PLANT = atof(argv[1]);
    cpu_mark m0 = cpu_now();
    int rc = run_plant000();
    if (argc <= 2)
        rc |= run_tree(100000);
    cpu_mark m1 = cpu_now();
    printf("machine_other_load: %.2f CPUs (whole run, 2-core machine)\n", other_load(m0, m1));
    return rc;
}
