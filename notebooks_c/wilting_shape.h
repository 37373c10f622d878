/* Shared by the wilting-shape notebooks (wilting paper, Maggioli et al.,
 * SIGGRAPH Asia 2023, Figs. 1, 5, 7, 9, 10): water model -> relative water
 * content per segment -> Young's modulus (eq. 9, model/segment_stiffness.h)
 * -> static equilibrium of the elastic rods (model/rod.h) -> side views
 * (fit/shape_plots.h).  Header-only (static functions) because ctest builds
 * each notebook as its own program.
 *
 * Our physical setting, used by every shape notebook unless its header says
 * otherwise (the paper's own values are in cm and g with a stiffness scale
 * of 1e10 "Pa" on a radius of cm^2, see model/segment_stiffness.h quirks
 * 1-8; they do not carry over to SI):
 *   plant    plant000 of the authors' code (1964 segments, 24.9 cm tall, z up,
 *            metres); one static equilibrium takes 0.02-1.5 s here (measured
 *            in these notebooks), so no smaller plant is needed.
 *   water    phytocal's physical water model (PHC_WATER_POISEUILLE), initial
 *            water W0 = sum of segment volumes (relative water content
 *            theta/V = 1 everywhere at t = 0), BDF6 with a step of WS_H s.
 *            Pressure equalises within seconds, so theta/V is nearly the same
 *            in every segment at any time (the notebooks print its range; Fig. 5
 *            its relative spread after 6 h: 1e-10).
 *   mass     dry matter WS_DRY_DENSITY kg m^-3 (rod density) plus the water
 *            of the segment (theta g -> kg) as extra mass: 1150 kg m^-3 when
 *            turgid, falling as the plant dries.
 *   modulus  eq. 9 on relative water content x = theta/V:
 *            E = E_min + E_max sigma(kappa (x - chi0)), E_min = 5e6 Pa,
 *            E_max = 1e8 Pa, kappa = 20, chi0 = 0.8 (WS_* below).  E_max
 *            1e8 Pa is at the low end of the 1e8..1e10 Pa that
 *            model/segment_stiffness.h gives for fresh green stems; E_min is the
 *            softest modulus at which plant000's static equilibrium still
 *            converges here (1e6 Pa does not: the leaves fold over).  The
 *            modulus of pith tissue falls as water is removed (maize stalks:
 *            Plant Methods 19:55, 2023, doi 10.1186/s13007-023-01039-5).
 *   rods     density WS_DRY_DENSITY, Poisson 0.5, gravity 9.81 m s^-2, the
 *            root segment fixed, tolerance 1e-10 (model/rod.h defaults). */
#ifndef PHC_WILTING_SHAPE_H
#define PHC_WILTING_SHAPE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fit/shape_plots.h"
#include "measurements/plant_io.h"
#include "model/rod.h"
#include "model/segment_stiffness.h"
#include "model/water.h"

#define WS_PLANT PHC_SHARED_DATA "/plants/plant000.txt"
#define WS_H 60.0            /* s, BDF6 step */
#define WS_DRY_DENSITY 150.0 /* kg m^-3 */
#define WS_E_MIN 5e6         /* Pa */
#define WS_E_MAX 1e8         /* Pa */
#define WS_KAPPA 20.0        /* per unit of relative water content */
#define WS_CHI0 0.8          /* relative water content */

__attribute__((unused)) static double ws_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Reads the plant (metres); NULL after printing the reason. */
__attribute__((unused)) static phc_plant_graph *ws_read(const char *path)
{
    phc_error err;
    phc_error_clear(&err);
    phc_plant_graph *g = NULL;
    if (phc_plant_io_read(path, PHC_PLANT_FORMAT_PAPER, 0, &g, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return NULL;
    }
    return g;
}

/* Segment volumes (cm^3) into v (n) and their sum. */
__attribute__((unused)) static double ws_volumes(const phc_plant_graph *g, double *v)
{
    double s = 0.0;
    for (size_t i = 0; i < g->n; ++i)
        s += v[i] = phc_segment_volume_cm3(g, i);
    return s;
}

/* The loss rate delta (1/(cm^2 s)) at which the plant, its water spread
 * evenly (theta/V the same everywhere, as pressure equalisation keeps it),
 * loses the fraction 1 - rwc of its water in t seconds:
 * W' = -delta sum_leaf(A_i theta_i) = -delta (sum_leaf A_i V_i / sum V) W,
 * so delta = -ln(rwc) / (t sum_leaf(A_i V_i) / sum V), A_i = r_i h_i (cm^2). */
__attribute__((unused)) static double ws_delta_for(const phc_plant_graph *g, double rwc, double t)
{
    double av = 0.0, vs = 0.0;
    for (size_t i = 0; i < g->n; ++i) {
        double v = phc_segment_volume_cm3(g, i), a = (g->radius[i] * 100.0) * (g->length[i] * 100.0);
        vs += v;
        if (g->leaf[i])
            av += a * v;
    }
    return -log(rwc) / (t * av / vs);
}

/* Water theta (g) at m times (s, each 0 or a multiple of WS_H, increasing),
 * row k of theta (m x n) for time t[k]; BDF6 with step WS_H. */
__attribute__((unused)) static int ws_water(const phc_plant_graph *g, const phc_water_params *p, const double *t, size_t m,
                    double *theta, phc_error *err)
{
    phc_water_system *s = NULL;
    phc_water_bdf6 *b = NULL;
    int rc = phc_water_system_new(g, p, &s, err);
    if (rc == PHC_OK)
        rc = phc_water_bdf6_new(s, WS_H, 0, &b, err);
    for (size_t k = 0; rc == PHC_OK && k < m; ++k) {
        double *row = theta + k * g->n;
        if (t[k] == 0.0) {
            phc_water_system_theta0(s, row);
            continue;
        }
        rc = phc_water_bdf6_advance(b, t[k], err);
        if (rc == PHC_OK && fabs(phc_water_bdf6_time(b) - t[k]) > 1e-6 * WS_H) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "water: sample time %g s is not a multiple of the BDF6 step %g s",
                               t[k], WS_H);
        }
        if (rc == PHC_OK)
            phc_water_bdf6_state(b, row, NULL);
    }
    phc_water_bdf6_free(b);
    phc_water_system_free(s);
    return rc;
}

/* Our water model parameters: physical default, W0 = the plant's volume. */
__attribute__((unused)) static phc_water_params ws_water_params(const phc_plant_graph *g, double delta)
{
    phc_water_params p = phc_water_params_default();
    double *v = malloc(g->n * sizeof *v);
    p.initial_water = v ? ws_volumes(g, v) : 1.0;
    free(v);
    p.loss_rate = delta;
    return p;
}

__attribute__((unused)) static phc_segment_stiffness_params ws_stiffness(double kappa, double chi0)
{
    phc_segment_stiffness_params sp = phc_segment_stiffness_params_default();
    sp.law = PHC_STIFFNESS_WATER;
    sp.content = PHC_STIFFNESS_RELATIVE;
    sp.logistic.kappa = kappa;
    sp.logistic.chi0 = chi0;
    sp.logistic.e_min = WS_E_MIN;
    sp.logistic.e_max = WS_E_MAX;
    return sp;
}

/* Relative water content theta/V per segment into rwc; min and max. */
__attribute__((unused)) static void ws_rwc(const phc_plant_graph *g, const double *theta, double *rwc, double *lo, double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    for (size_t i = 0; i < g->n; ++i) {
        rwc[i] = theta[i] / phc_segment_volume_cm3(g, i);
        *lo = fmin(*lo, rwc[i]), *hi = fmax(*hi, rwc[i]);
    }
}

__attribute__((unused)) static phc_rod *ws_rod(const phc_plant_graph *g, const double *E, phc_error *err)
{
    phc_rod_options o;
    phc_rod_options_default(&o);
    o.density = WS_DRY_DENSITY;
    phc_rod *rod = NULL;
    if (phc_rod_new(g, E, &o, &rod, err) != PHC_OK)
        return NULL;
    return rod;
}

/* One static solve with moduli E (Pa) and water theta (g, or NULL: no water
 * mass) from the rod's current state (fresh: call phc_rod_reset first).
 * Adds the wall time to *secs; returns the status. */
__attribute__((unused)) static int ws_solve(phc_rod *rod, const double *E, const double *theta, double *secs, int *iterations,
                    phc_error *err)
{
    size_t n = phc_rod_segment_count(rod);
    double *m = calloc(n, sizeof *m);
    if (!m)
        return PHC_ERR_NOMEM;
    for (size_t i = 0; theta && i < n; ++i)
        m[i] = 1e-3 * theta[i];
    int rc = phc_rod_set_modulus(rod, E, err);
    if (rc == PHC_OK)
        rc = phc_rod_set_extra_mass(rod, m, err);
    free(m);
    phc_rod_report rep = {0};
    double t0 = ws_now();
    if (rc == PHC_OK)
        rc = phc_rod_solve_static(rod, &rep, err);
    *secs += ws_now() - t0;
    if (iterations)
        *iterations = rep.iterations;
    return rc;
}

/* The rod's current shape: heads and tails (3n each) and the height (max z
 * of the tails, m). */
__attribute__((unused)) static double ws_shape(const phc_rod *rod, double *head, double *tail)
{
    double h = -INFINITY;
    for (size_t i = 0; i < phc_rod_segment_count(rod); ++i) {
        phc_rod_head(rod, i, head + 3 * i);
        phc_rod_tail(rod, i, tail + 3 * i);
        h = fmax(h, tail[3 * i + 2]);
    }
    return h;
}

/* The segment whose tail is highest in the rest shape (the highest tip). */
__attribute__((unused)) static size_t ws_highest(const phc_plant_graph *g)
{
    size_t best = 0;
    for (size_t i = 1; i < g->n; ++i)
        if (g->tail[3 * i + 2] > g->tail[3 * best + 2])
            best = i;
    return best;
}

/* Mean of tail z minus rest tail z over the segments (m; negative = down). */
__attribute__((unused)) static double ws_mean_dz(const phc_plant_graph *g, const double *tail)
{
    double s = 0.0;
    for (size_t i = 0; i < g->n; ++i)
        s += tail[3 * i + 2] - g->tail[3 * i + 2];
    return s / (double)g->n;
}

#endif /* PHC_WILTING_SHAPE_H */
