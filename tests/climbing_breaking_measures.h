/* Measures of a growing plant that breaks (model/climbing_breaking.h),
 * shared by tests/unit/test_climbing_breaking.c,
 * tests/unit/test_climbing_resprout.c and
 * notebooks_c/climbing_breaking_growth.c. */
#ifndef PHC_TESTS_CLIMBING_BREAKING_MEASURES_H
#define PHC_TESTS_CLIMBING_BREAKING_MEASURES_H

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "model/climbing_growth.h"

/* Largest group stress of the last substep over the plant's particles that
 * do not fall (1); *at (may be NULL) gets its particle, 0 when none. */
static inline double climbing_max_linked_stress(const phc_climbing *c, size_t *at)
{
    double m = 0;
    if (at)
        *at = 0;
    for (size_t i = 1; i < phc_climbing_count(c); ++i)
        if (!phc_climbing_is_falling(c, i) && phc_climbing_stress(c, i) > m) {
            m = phc_climbing_stress(c, i);
            if (at)
                *at = i;
        }
    return m;
}

/* Height (m) of the centre of mass of the falling particles (masses ∝ r²L,
 * one density); NAN when none falls.  *count gets how many fall. */
static inline double climbing_falling_centre_z(const phc_climbing *c, size_t *count)
{
    double w = 0, z = 0;
    *count = 0;
    for (size_t i = 0; i < phc_climbing_count(c); ++i)
        if (phc_climbing_is_falling(c, i)) {
            double x[3];
            phc_climbing_position(c, i, x);
            const double r = phc_climbing_radius(c, i), m = r * r * phc_climbing_length(c, i);
            w += m;
            z += m * x[2];
            ++*count;
        }
    return w > 0 ? z / w : NAN;
}

/* Length (m) of the axis from particle k: k and its successors (the
 * children that are not laterals); *m gets their count. */
static inline double climbing_axis_length(const phc_climbing *c, size_t k, size_t *m)
{
    double L = phc_climbing_length(c, k);
    *m = 1;
    for (size_t i = k + 1; i < phc_climbing_count(c); ++i)
        if (phc_climbing_parent(c, i) == k && !phc_climbing_is_lateral(c, i)) {
            L += phc_climbing_length(c, i);
            k = i;
            ++*m;
        }
    return L;
}

/* The bushy plant of the thread tests on `threads` OpenMP threads: grown
 * kinematically in steps of 0.25 s to 2000 particles from (0, 0, 0.01) m
 * upward with options o, then `steps` steps with 2 dynamics substeps.
 * Returns 7 numbers per particle (centre, direction, stable id; *n
 * particles, malloc'd, NULL on failure), *st the plant's counters.  The
 * thread count is restored. */
static inline double *climbing_threads_run(const phc_climbing_options *o, int steps, int threads,
                                           size_t *n, phc_climbing_stats *st)
{
    const double seed[3] = {0, 0, 0.01}, up[3] = {0, 0, 1};
    const int keep = omp_get_max_threads();
    phc_error err;
    double *xs = NULL;
    *n = 0;
    omp_set_num_threads(threads);
    phc_climbing *c = phc_climbing_new(seed, up, o, &err);
    int bad = c == NULL;
    while (!bad && phc_climbing_count(c) < 2000)
        bad = phc_climbing_step(c, 0.25, &err) != 0;
    bad = bad || phc_climbing_set_dynamics_substeps(c, 2, &err) != 0;
    for (int k = 0; k < steps && !bad; ++k)
        bad = phc_climbing_step(c, 0.25, &err) != 0;
    if (!bad) {
        phc_climbing_get_stats(c, st);
        *n = phc_climbing_count(c);
        xs = malloc(7 * *n * sizeof *xs);
        for (size_t i = 0; xs && i < *n; ++i) {
            phc_climbing_position(c, i, xs + 7 * i);
            phc_climbing_direction(c, i, xs + 7 * i + 3);
            xs[7 * i + 6] = (double)phc_climbing_id(c, i);
        }
    }
    phc_climbing_free(c);
    omp_set_num_threads(keep);
    return xs;
}

/* climbing_threads_run on 1 and then 2 threads: counts to ns[2] and
 * st[2], the numbers compared to *numbers; returns how many differ
 * (bit for bit; (size_t)-1 when a run failed or the counts differ). */
static inline size_t climbing_threads_compare(const phc_climbing_options *o, int steps, size_t ns[2],
                                              phc_climbing_stats st[2], size_t *numbers)
{
    double *xs[2] = {NULL, NULL};
    memset(st, 0, 2 * sizeof *st);
    for (int run = 0; run < 2; ++run)
        xs[run] = climbing_threads_run(o, steps, run + 1, &ns[run], &st[run]);
    size_t differ = (size_t)-1;
    *numbers = 7 * ns[0];
    if (xs[0] && xs[1] && ns[0] == ns[1]) {
        differ = 0;
        for (size_t k = 0; k < 7 * ns[0]; ++k)
            differ += memcmp(xs[0] + k, xs[1] + k, sizeof(double)) != 0;
    }
    free(xs[0]);
    free(xs[1]);
    return differ;
}

#endif /* PHC_TESTS_CLIMBING_BREAKING_MEASURES_H */
