/* The authors' stiffness mapping (model/segment_stiffness.h, `reference`:
 * filthynobleman/plant-wilting-simulation, Demos/PlantDemo/PlantDemo.cpp)
 * on plant000 (../shared/data/plants) with the water of their demo: the
 * water model in the mode of the code their demo builds against
 * (reference_2024, pwd at 8308f91), their defaults loss rate 6e-3 and
 * initial water 8 g, BDF6 with a 0.1 s step (as test_water_reference).
 * Printed, at t = 0, 1e3, 1e4 and 3e4 s (their demo advances the water 10 s per frame): the joint water
 * w = (theta_N + theta_C) / 2 against their midpoint 0.015 g, the share of
 * joints stiffer than Emin + Emax / 2, and the joint moduli; once, the
 * joint "radius" of their code against the length-weighted mean radius it
 * evidently means, and the build-time against the per-frame masses.
 * Also printed: the relative water content theta / V that the physical
 * default maps (uniform at t = 0, since theta(0) = W0 V / sum V).
 * Checks (each can fail): segment volumes equal the water model's; W(1e3 s) and W(1e4 s) equal their matrix's values
 * (W_THEIRS of tests/realdata/test_water_reference.c) to 1e-9; every output finite, non-root moduli within
 * [Emin, Emin + Emax]; per-frame masses sum to (sum V rho + W(t) - root's
 * share) * 1e-3 with W(t) the water model's own total; at t = 0 a stem
 * segment's build-time mass is exactly 1000 x its per-frame mass (quirk 7);
 * the joint radius is r_parent (LN^2 + LC^2) / (LN + LC) in cm.
 * Skips (77) when the data folder is absent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "check.h"
#include "measurements/plant_io.h"
#include "model/segment_stiffness.h"
#include "model/water.h"

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif
#define PLANT PHC_SHARED_DATA "/plants/plant000.txt"

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* min, median, max of v[0..n-1] (sorted copy) */
static void summary(const double *v, size_t n, double out[3])
{
    double *c = malloc(n * sizeof *c);
    if (!c) {
        out[0] = out[1] = out[2] = NAN;
        return;
    }
    for (size_t i = 0; i < n; ++i)
        c[i] = v[i];
    qsort(c, n, sizeof *c, cmp_double);
    out[0] = c[0];
    out[1] = n % 2 ? c[n / 2] : 0.5 * (c[n / 2 - 1] + c[n / 2]);
    out[2] = c[n - 1];
    free(c);
}

int main(void)
{
    struct stat st;
    if (stat(PLANT, &st) != 0) {
        printf("test_stiffness_reference: %s is absent: skipped\n", PLANT);
        return 77;
    }
    phc_error err;
    phc_plant_graph *g = NULL;
    if (phc_plant_io_read(PLANT, PHC_PLANT_FORMAT_PAPER, 0, &g, &err)) {
        fprintf(stderr, "%s\n", err.message);
        CHECK(0);
        return check_finish("test_stiffness_reference");
    }
    const size_t n = g->n;
    const phc_stiffness_reference_params rp = phc_stiffness_reference_default();
    phc_water_params wp = phc_water_params_default();
    wp.weights = PHC_WATER_REFERENCE_2024;
    wp.loss_rate = 6e-3;
    wp.initial_water = 8.0;
    phc_water_system *s = NULL;
    phc_water_bdf6 *b = NULL;
    double *theta = malloc(n * sizeof *theta), *E = malloc(n * sizeof *E),
           *W = malloc(n * sizeof *W), *R = malloc(n * sizeof *R), *L = malloc(n * sizeof *L),
           *m = malloc(n * sizeof *m), *mb = malloc(n * sizeof *mb),
           *jw = malloc(n * sizeof *jw), *je = malloc(n * sizeof *je),
           *ratio = malloc(n * sizeof *ratio);
    if (!theta || !E || !W || !R || !L || !m || !mb || !jw || !je || !ratio ||
        phc_water_system_new(g, &wp, &s, &err) || phc_water_bdf6_new(s, 0.1, 0, &b, &err)) {
        fprintf(stderr, "%s\n", err.message);
        CHECK(0);
        return check_finish("test_stiffness_reference");
    }
    printf("plant000: %zu segments, %zu joints; reference_2024 water, delta 6e-3, W0 8 g; "
           "Emin %g, Emax %g, s %g per g, mid %g g\n",
           n, n - 1, rp.e_min, rp.e_max, rp.steepness, rp.midpoint);

    /* geometry (independent of time): their joint radius vs the intended one */
    CHECK(phc_stiffness_reference_joints(g, &rp, NULL, NULL, NULL, NULL, NULL, R, L, NULL,
                                         &err) == PHC_OK);
    {
        size_t k = 0;
        double worst = 0;
        for (size_t c = 0; c < n; ++c) {
            const size_t p = g->parent[c];
            if (p == PHC_PLANT_NO_PARENT)
                continue;
            const double ln = 100 * g->length[p], lc = 100 * g->length[c];
            const double rn = 100 * g->radius[p], rc = 100 * g->radius[c];
            const double quirk = rn * (ln * ln + lc * lc) / (ln + lc);
            worst = fmax(worst, fabs(R[c] - quirk) / quirk);
            ratio[k++] = R[c] / ((rn * ln + rc * lc) / (ln + lc));
        }
        CHECK(worst < 1e-15);
        double sm[3];
        summary(ratio, k, sm);
        printf("joint radius of their code / length-weighted mean radius (cm): min %.4g, "
               "median %.4g, max %.4g; so E I differs by the 4th power: median %.4g\n",
               sm[0], sm[1], sm[2], pow(sm[1], 4));
    }

    /* the volumes behind relative water content are the water model's own */
    double *rwc = malloc(n * sizeof *rwc);
    if (!rwc) {
        CHECK(0);
        return check_finish("test_stiffness_reference");
    }
    {
        double worst = 0, vsum = 0;
        phc_water_system_volume(s, rwc);
        for (size_t i = 0; i < n; ++i) {
            worst = fmax(worst, fabs(phc_segment_volume_cm3(g, i) - rwc[i]) / rwc[i]);
            vsum += rwc[i];
        }
        CHECK(worst < 1e-14);
        printf("segment volumes vs the water model's: largest relative difference %.2g; total "
               "volume %.6g cm^3, so theta(0) = W0 V / sum V is a uniform relative content "
               "%.6g\n",
               worst, vsum, 8.0 / vsum);
    }

    const double times[4] = {0, 1e3, 1e4, 3e4};
    for (int q = 0; q < 4; ++q) {
        if (times[q] == 0) {
            phc_water_system_theta0(s, theta);
        } else {
            if (phc_water_bdf6_advance(b, times[q], &err)) {
                fprintf(stderr, "%s\n", err.message);
                CHECK(0);
                break;
            }
            CHECK(fabs(phc_water_bdf6_time(b) - times[q]) < 1e-6);
            phc_water_bdf6_state(b, theta, NULL);
        }
        CHECK(phc_stiffness_reference_joints(g, &rp, theta, E, NULL, NULL, NULL, NULL, NULL, W,
                                             &err) == PHC_OK);
        CHECK(phc_stiffness_reference_masses(g, &rp, theta, 0, m, &err) == PHC_OK);
        size_t k = 0, stiff = 0, bad = 0;
        double total = 0, mass = 0, want = 0;
        for (size_t i = 0; i < n; ++i) {
            total += theta[i];
            mass += m[i];
            if (i == g->root)
                continue;
            want += (phc_segment_volume_cm3(g, i) * (g->leaf[i] ? rp.leaf_density : rp.density) +
                     theta[i]) * rp.mass_scale;
            if (!isfinite(E[i]) || E[i] < rp.e_min || E[i] > rp.e_min + rp.e_max || !(m[i] > 0))
                ++bad;
            jw[k] = W[i];
            je[k] = E[i];
            stiff += E[i] > rp.e_min + 0.5 * rp.e_max;
            ++k;
        }
        CHECK(bad == 0);
        /* relative water content theta / V, what the physical default maps */
        for (size_t i = 0; i < n; ++i)
            rwc[i] = theta[i] / phc_segment_volume_cm3(g, i);
        double sr[3];
        summary(rwc, n, sr);
        CHECK_NEAR(mass, want, 0, 1e-13);
        /* W_THEIRS of test_water_reference.c: their matrix evaluated accurately */
        if (times[q] == 1e3)
            CHECK_NEAR(total, 7.9146570785306, 0, 1e-9);
        if (times[q] == 1e4)
            CHECK_NEAR(total, 7.1863959951622, 0, 1e-9);
        double sw[3], se[3];
        summary(jw, k, sw);
        summary(je, k, se);
        printf("t = %g s: W = %.10g g; joint water min %.3g, median %.3g, max %.3g g; "
               "stiffer than Emin + Emax/2: %zu of %zu joints; E min %.3g, median %.3g, max %.3g; "
               "frame mass %.6g; relative content theta/V median %.4g, (max - min) / median "
               "%.2g\n",
               times[q], total, sw[0], sw[1], sw[2], stiff, k, se[0], se[1], se[2], mass, sr[1],
               (sr[2] - sr[0]) / sr[1]);
        if (times[q] == 0)
            CHECK(sr[2] - sr[0] <= 1e-12 * sr[1]);
        if (times[q] == 0) {
            /* build-time masses: exactly 1000 x the frame's for stem segments (quirk 7) */
            CHECK(phc_stiffness_reference_masses(g, &rp, theta, 1, mb, &err) == PHC_OK);
            size_t stems = 0, exact = 0;
            double btot = 0;
            for (size_t i = 0; i < n; ++i) {
                btot += mb[i];
                if (i == g->root || g->leaf[i])
                    continue;
                ++stems;
                exact += fabs(mb[i] - 1000 * m[i]) <= 1e-12 * mb[i];
            }
            CHECK(stems > 0 && exact == stems);
            printf("build-time mass total %.6g vs first frame %.6g (ratio %.4g; stems exactly "
                   "1000x: %zu of %zu)\n",
                   btot, mass, btot / mass, exact, stems);
        }
    }
    phc_water_bdf6_free(b);
    phc_water_system_free(s);
    phc_plant_graph_free(g);
    free(theta), free(E), free(W), free(R), free(L), free(m), free(mb), free(jw), free(je),
        free(ratio), free(rwc);
    return check_finish("test_stiffness_reference");
}
