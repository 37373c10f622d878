/* `weight_curve` data sets: see weight_curve.h. */
#include "fit/costs/weight_curve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/unique_times.h"
#include "fit/costs/weight_drivers.h"
#include "measurements/logger_time.h"
#include "model/plant_graph.h"
#include "model/water.h"
#include "model/water_balance.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* A stretch of the curve between irrigations.  Piece 0 starts from the
 * `initial_water` slot, piece k > 0 from its own slot `initial_water_<k+1>`. */
typedef struct piece {
    size_t first, count;  /* residuals first .. first+count-1 */
    double start_x;       /* time of the piece's start, user time unit from the first row */
    int slot;             /* slot of the piece's initial water */
} piece;

enum { SLOT_DELTA, SLOT_DRY, SLOT_MU, N_SLOT_KINDS }; /* initial waters: per piece */

typedef struct wc_impl {
    phc_plant_graph *graph;
    phc_water_params params;   /* weights (conductance), edge options */
    phc_water_method method;
    double step;               /* BDF6 step, s (0 = the model's choice) */
    phc_water_system *sys;     /* built for sys_mu; rebuilt when μ changes */
    double sys_mu;
    phc_water_bdf6 *bdf6[2];   /* the last two BDF6 runs of the plant alone with a constant
                                  loss, kept for their δ and step: the solver's repeated
                                  points, the polish, the analysis, the plot and the report
                                  read them instead of integrating again (same numbers, bit
                                  for bit); bdf6_last: the more recent */
    double bdf6_delta[2], bdf6_h[2];
    int bdf6_sens[2];          /* PHC_WATER_SENS_* each carries */
    int bdf6_last;
    double viscosity;          /* mPa·s when not a slot */
    double dry_measured;       /* g, or NAN */
    int slot[N_SLOT_KINDS];    /* slot index of each quantity, -1 when fixed */
    double *t_model;           /* n: s since the start of the residual's piece */
    double *t_unique;          /* m_unique sorted distinct values of t_model: the pieces
                                  share δ and μ, so one unit response serves them all */
    size_t m_unique;
    size_t *t_at;              /* n: index of t_model[i] in t_unique */
    size_t n_pieces;
    piece *pieces;
    double seconds_per_x;      /* the user's time unit in s */
    double t0_posix;           /* POSIX time (s) at x = 0, the first weighing kept; NAN when
                                  the time is a plain number (not timestamps or an absolute unit) */
    char *timezone;            /* IANA zone of the clock (malloc'd), NULL = UTC / as written */
    size_t tare_n, tare_line[2]; /* tare readings dropped, their first and last lines */
    double max_gap;            /* s */
    size_t n_gaps;             /* gaps longer than max_gap: their lengths (s) and the line */
    double *gap_s;             /*   of the weighing before each */
    size_t *gap_line;
    double *u, *du;            /* workspace: unit response and its derivatives
                                  (m_unique, or the largest piece, x (PHC_WB_COEF + coefs)) */
    phc_weight_drivers drv;    /* day and night, covariates, pot (weight_drivers.h) */
    int drv_slot;              /* slot of the drivers' first slot (-1: none) */
    size_t n_coef;             /* coefficients of g */
    double *t_abs;             /* n: s since the first weighing (time-varying loss) */
} wc_impl;

static void wc_free(void *p)
{
    wc_impl *w = p;
    if (!w)
        return;
    phc_plant_graph_free(w->graph);
    phc_water_bdf6_free(w->bdf6[0]);
    phc_water_bdf6_free(w->bdf6[1]);
    phc_water_system_free(w->sys);
    free(w->t_model);
    free(w->t_unique);
    free(w->t_at);
    free(w->pieces);
    free(w->u);
    free(w->du);
    free(w->timezone);
    phc_weight_drivers_free(&w->drv);
    free(w->t_abs);
    free(w->gap_s);
    free(w->gap_line);
    free(w);
}

static double slot_value(const wc_impl *w, const double *p, int kind, double fallback)
{
    return w->slot[kind] >= 0 ? p[w->slot[kind]] : fallback;
}

/* Builds the water system for viscosity mu (rebuilt only when mu changes;
 * delta is set in place, O(n)).  1 = outside the model's domain. */
static int water_system(wc_impl *w, double delta, double mu)
{
    phc_error err;
    phc_error_clear(&err);
    if (!w->sys || w->sys_mu != mu) {
        for (int c = 0; c < 2; ++c) { /* they point into the system */
            phc_water_bdf6_free(w->bdf6[c]);
            w->bdf6[c] = NULL;
        }
        phc_water_system_free(w->sys);
        w->sys = NULL;
        phc_water_params p = w->params;
        p.viscosity = mu;
        p.loss_rate = delta;
        p.initial_water = 1.0;
        int rc = phc_water_system_new(w->graph, &p, &w->sys, &err);
        if (rc)
            return rc == PHC_ERR_NOMEM ? -1 : 1;
        w->sys_mu = mu;
    }
    if (phc_water_system_set_loss_rate(w->sys, delta, &err))
        return 1; /* a trial point outside the model's domain: reject the step */
    return 0;
}

/* The plant alone by BDF6 with step h (s) at m times t (s, >= 0, the last
 * > 0): u (W for W0 = 1) and, when du is given, its rows (width nw) with
 * d/dδ, d/dW0 and, when μ is a parameter, d/dμ (else NAN).  Reuses a kept
 * integrator when δ and h are the same and it carries the sensitivities
 * asked for (advancing it when t goes further); otherwise integrates anew.
 * The values are those of phc_water_system_total_curve bit for bit (the
 * same steps; theta does not depend on the sensitivities carried; at the
 * steps' nodes the dense output is the stored total exactly). */
static int bdf6_curve(wc_impl *w, double delta, double h, const double *t, size_t m, double *u,
                      double *du, size_t nw, phc_error *err)
{
    const int want = !du ? PHC_WATER_SENS_NONE
                         : w->slot[SLOT_MU] >= 0 ? PHC_WATER_SENS_ALL : PHC_WATER_SENS_DELTA;
    int c = -1;
    for (int q = 0; q < 2 && c < 0; ++q) {
        const int k = q ? 1 - w->bdf6_last : w->bdf6_last; /* the more recent first */
        if (w->bdf6[k] && w->bdf6_delta[k] == delta && w->bdf6_h[k] == h &&
            (want == PHC_WATER_SENS_NONE || w->bdf6_sens[k] == want ||
             w->bdf6_sens[k] == PHC_WATER_SENS_ALL))
            c = k;
    }
    int rc = 0;
    if (c < 0) { /* replace the older run */
        c = 1 - w->bdf6_last;
        phc_water_bdf6_free(w->bdf6[c]);
        w->bdf6[c] = NULL;
        if ((rc = phc_water_bdf6_new(w->sys, h, want, &w->bdf6[c], err)))
            return rc;
        w->bdf6_delta[c] = delta;
        w->bdf6_h[c] = h;
        w->bdf6_sens[c] = want;
    }
    w->bdf6_last = c;
    phc_water_bdf6 *b = w->bdf6[c];
    /* the system's loss is δ now (water_system), as when b was made */
    if ((rc = phc_water_bdf6_advance(b, t[m - 1], err))) /* no step when covered */
        goto fail;
    for (size_t i = 0; i < m; ++i) {
        double d[3];
        if ((rc = phc_water_bdf6_total(b, t[i], u + i, du ? d : NULL, err)))
            goto fail;
        if (du) {
            double *row = du + i * nw;
            for (size_t k = 0; k < nw; ++k)
                row[k] = 0;
            row[PHC_WB_DELTA] = d[0];
            row[PHC_WB_W0] = d[1];
            row[PHC_WB_MU] = want == PHC_WATER_SENS_ALL ? d[2] : NAN;
        }
    }
    return PHC_OK;
fail:
    phc_water_bdf6_free(b);
    w->bdf6[c] = NULL;
    return rc;
}

/* The unit response u(t) = W(t)/W(0) of the water model (plant, and pot
 * when there is one) at m sorted times t (s) of a piece starting at t_start
 * (s since the first weighing), and, when du is given, du (m x (PHC_WB_COEF
 * + n_coef): d/dδ, d/dW0, d/dμ, d/dC, d/dk, d/dc_j; model/water_balance.h).
 * p: the slot values. */
static int unit_response(wc_impl *w, const double *p, double delta, double mu, double t_start,
                         const double *t, size_t m, double *u, double *du)
{
    int rc = water_system(w, delta, mu);
    if (rc)
        return rc;
    phc_error err;
    phc_error_clear(&err);
    if (!w->drv.pot && !phc_weight_drivers_time_varying(&w->drv)) {
        /* the plant alone with a constant loss: model/water.h (du m x 3) */
        double h = 0;
        const size_t nw = PHC_WB_COEF + w->n_coef;
        if (m > 0 && t[m - 1] > 0 && isfinite(t[m - 1]) &&
            phc_water_system_curve_method(w->sys, w->method, w->step, t[m - 1], &h) == PHC_WATER_BDF6)
            rc = bdf6_curve(w, delta, h, t, m, u, du, nw, &err);
        else if (!(rc = phc_water_system_total_curve(w->sys, w->method, w->step, t, m, u, du, &err)) && du)
            /* spread to the balance's columns, back to front */
            for (size_t i = m; i-- > 0;) {
                double d0 = du[3 * i], d1 = du[3 * i + 1], d2 = du[3 * i + 2];
                double *row = du + i * (PHC_WB_COEF + w->n_coef);
                for (size_t c = 0; c < PHC_WB_COEF + w->n_coef; ++c)
                    row[c] = 0;
                row[PHC_WB_DELTA] = d0;
                row[PHC_WB_W0] = d1;
                row[PHC_WB_MU] = d2;
            }
    } else {
        const phc_water_loss_pattern *loss;
        const phc_water_pot *pot;
        phc_water_loss_pattern loss_buf;
        phc_water_pot pot_buf;
        phc_weight_drivers_model(&w->drv, w->drv_slot >= 0 ? p + w->drv_slot : NULL, &loss,
                                 &loss_buf, &pot, &pot_buf);
        if (pot && !(pot->capacity > 0 && pot->conductance >= 0))
            return 1;
        for (size_t k = 0; loss && k < loss->n; ++k)
            if (!(loss->g[k] >= 0))
                return 1; /* a negative loss: outside the domain */
        rc = phc_water_balance_curve(w->sys, pot, loss, t_start, w->method, w->step, t, m, u, du, &err);
    }
    if (rc == PHC_ERR_NOMEM || rc == PHC_ERR_INTERNAL || rc == PHC_ERR_INVALID)
        return -1;
    return rc ? 1 : 0;
}

/* Fills a Jacobian row from the piece's unit response (start: the piece's
 * initial water; d: du row). */
static void jacobian_row(const wc_impl *w, const phc_dataset *ds, const piece *pc, double start,
                         double u, const double *d, double *row)
{
    for (size_t j = 0; j < ds->k; ++j)
        row[j] = 0;
    if (w->slot[SLOT_DELTA] >= 0)
        row[w->slot[SLOT_DELTA]] = start * d[PHC_WB_DELTA];
    if (w->slot[SLOT_MU] >= 0)
        row[w->slot[SLOT_MU]] = start * d[PHC_WB_MU];
    row[pc->slot] = u;
    if (w->slot[SLOT_DRY] >= 0)
        row[w->slot[SLOT_DRY]] = 1.0;
    if (w->drv_slot >= 0) {
        int s = w->drv_slot;
        for (size_t j = 0; j < w->n_coef; ++j)
            row[s++] = start * d[PHC_WB_COEF + j];
        if (w->drv.pot && isnan(w->drv.capacity))
            row[s++] = start * d[PHC_WB_CAPACITY];
        if (w->drv.pot && isnan(w->drv.conductance))
            row[s++] = start * d[PHC_WB_CONDUCTANCE];
    }
}

static int wc_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    wc_impl *w = ds->impl;
    const double delta = slot_value(w, p, SLOT_DELTA, 0);
    const double dry = slot_value(w, p, SLOT_DRY, w->dry_measured);
    const double mu = slot_value(w, p, SLOT_MU, w->viscosity);
    const size_t nw = PHC_WB_COEF + w->n_coef;
    if (!(delta >= 0) || !(mu > 0) || !isfinite(dry))
        return 1;
    const int varying = phc_weight_drivers_time_varying(&w->drv);
    int rc = 0;
    if (!varying) /* the pieces share one response over the time since their start */
        rc = unit_response(w, p, delta, mu, 0, w->t_unique, w->m_unique, w->u, jac ? w->du : NULL);
    for (size_t k = 0; k < w->n_pieces && !rc; ++k) {
        const piece *pc = &w->pieces[k];
        const double start = p[pc->slot];
        if (varying) /* the loss depends on the clock: each piece from its own start */
            rc = unit_response(w, p, delta, mu, w->t_abs[pc->first], w->t_abs + pc->first, pc->count,
                               w->u, jac ? w->du : NULL);
        for (size_t r = pc->first; r < pc->first + pc->count && !rc; ++r) {
            const size_t i = varying ? r - pc->first : w->t_at[r];
            yhat[r] = dry + start * w->u[i];
            if (jac)
                jacobian_row(w, ds, pc, start, w->u[i], w->du + i * nw, jac + r * ds->k);
        }
    }
    return rc;
}

/* The fitted curve at arbitrary x (user time unit since the first row),
 * piece by piece; x must be sorted (the plot's grid is). */
static int wc_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m, double *y)
{
    wc_impl *w = ds->impl;
    const double delta = slot_value(w, p, SLOT_DELTA, 0);
    const double dry = slot_value(w, p, SLOT_DRY, w->dry_measured);
    const double mu = slot_value(w, p, SLOT_MU, w->viscosity);
    double *t = malloc((m ? m : 1) * sizeof *t), *u = malloc((m ? m : 1) * sizeof *u);
    int rc = 0;
    if (!t || !u) {
        rc = -1;
        goto done;
    }
    for (size_t i = 0; i < m && !rc;) {
        size_t k = 0;
        while (k + 1 < w->n_pieces && w->pieces[k + 1].start_x <= x[i])
            ++k;
        const double end = k + 1 < w->n_pieces ? w->pieces[k + 1].start_x : INFINITY;
        size_t j = i;
        while (j < m && x[j] < end) {
            const double dt = (x[j] - w->pieces[k].start_x) * w->seconds_per_x;
            t[j - i] = dt > 0 ? dt : 0;
            ++j;
        }
        if (j == i) { /* before the first piece */
            y[i++] = NAN;
            continue;
        }
        const double t_start = w->pieces[k].start_x * w->seconds_per_x;
        if (phc_weight_drivers_time_varying(&w->drv))
            for (size_t q = i; q < j; ++q) /* the clock since the first weighing */
                t[q - i] += t_start;
        rc = unit_response(w, p, delta, mu, phc_weight_drivers_time_varying(&w->drv) ? t_start : 0,
                           t, j - i, u, NULL);
        const double start = p[w->pieces[k].slot];
        for (size_t q = i; q < j && !rc; ++q)
            y[q] = dry + start * u[q - i];
        i = j;
    }
done:
    free(t);
    free(u);
    return rc;
}

static int wc_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err);

const phc_dataset_ops phc_weight_curve_ops = {.kind = "weight_curve", .predict = wc_predict,
                                              .predict_at = wc_predict_at, .free_impl = wc_free,
                                              .report_section = wc_report_section};

/* ---- building ------------------------------------------------------------- */

#define WHERE(key) phc_origin_key(opt->origin, "weight_curve", key).text

phc_weighings phc_weighings_default(void)
{
    phc_weighings w = {0};
    return w;
}

phc_weight_curve_options phc_weight_curve_options_default(void)
{
    phc_weight_curve_options o = {0};
    o.conductance = PHC_WATER_POISEUILLE;
    o.method = PHC_WATER_AUTO;
    o.viscosity = o.dry_mass = o.sigma = o.jump_threshold = NAN;
    o.day.night_factor = o.day.clock = NAN;
    o.pot.capacity = o.pot.conductance = NAN;
    return o;
}

/* The weighings' defaults filled in: units, names, source. */
typedef struct series_info {
    double spx, gpu;          /* s per time unit, g per mass unit */
    const char *source, *time_name, *mass_name, *time_unit, *mass_unit;
} series_info;

static series_info info_of(const phc_weighings *w)
{
    series_info s = {w->seconds_per_unit > 0 ? w->seconds_per_unit : 1.0,
                     w->grams_per_unit > 0 ? w->grams_per_unit : 1.0,
                     w->source ? w->source : "weighings", w->time_name ? w->time_name : "time",
                     w->mass_name ? w->mass_name : "mass", w->time_unit ? w->time_unit : "s",
                     w->mass_unit ? w->mass_unit : "g"};
    return s;
}

static size_t line_of(const phc_weighings *w, size_t i)
{
    return w->lines ? w->lines[i] : i + 1;
}

static int skipped(const phc_weighings *w, size_t i)
{
    return w->skip && w->skip[i];
}

/* The options' values and the plant: what the model can take. */
static int check_options(const phc_plant_graph *plant, const phc_weighings *w,
                         const phc_weight_curve_options *opt, phc_error *err)
{
    if (!w || !w->t || !w->mass)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: the weighings need times and masses", WHERE(NULL));
    if (w->seconds_per_unit < 0 || w->grams_per_unit < 0)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: seconds_per_unit and grams_per_unit must be positive "
                             "(0 = s, g)", WHERE(NULL));
    if (w->n_covariates && !w->covariates)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: %zu covariates without readings", WHERE("covariates"),
                             w->n_covariates);
    if (opt->step < 0 || !isfinite(opt->step) || !(isnan(opt->viscosity) || opt->viscosity > 0) ||
        !(isnan(opt->jump_threshold) || opt->jump_threshold > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: weight_curve data set: step must be >= 0, viscosity and jump_threshold positive",
                             WHERE(NULL));
    if (w->sigma && !isnan(opt->sigma))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': give a number or per-weighing sigmas, not both",
                             WHERE("sigma"));
    if (!isnan(opt->sigma) && !(opt->sigma > 0 && isfinite(opt->sigma)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': must be positive, found %g", WHERE("sigma"),
                             opt->sigma);
    if (!isnan(opt->dry_mass) && !(opt->dry_mass > 0 && isfinite(opt->dry_mass)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'dry_mass': must be positive, found %g",
                             WHERE("dry_mass"), opt->dry_mass);
    if (!plant || !plant->order)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: %s", WHERE("plant"),
                             plant ? "the plant graph is not finished (phc_plant_graph_finish)"
                                   : "a plant graph is required");
    if (phc_plant_graph_leaf_count(plant) == 0)
        return opt->plant_name
                   ? phc_error_set(err, PHC_ERR_INPUT, "%s: plant '%s' has no leaf segments, so it cannot lose water",
                                   WHERE("plant"), opt->plant_name)
                   : phc_error_set(err, PHC_ERR_INPUT, "%s: the plant graph has no leaf segments, so it cannot lose water",
                                   WHERE("plant"));
    return PHC_OK;
}

/* Every weighing: times in order, positive masses above the measured dry
 * mass (excluded windows too), positive sigmas; the covariates of the
 * weighings kept. */
static int check_weighings(const phc_weighings *w, const phc_weight_curve_options *opt, phc_error *err)
{
    const series_info s = info_of(w);
    for (size_t i = 0; i < w->n; ++i) {
        const size_t line = line_of(w, i);
        if (!isfinite(w->t[i]))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': time must be a finite number, found %g",
                                 s.source, line, s.time_name, w->t[i]);
        if (i > 0 && !(w->t[i] > w->t[i - 1]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: column '%s': time %g is not after the previous weighing's %g (line %zu); weighings must be in time order",
                                 s.source, line, s.time_name, w->t[i], w->t[i - 1], line_of(w, i - 1));
        if (!(w->mass[i] > 0 && isfinite(w->mass[i])))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': a mass must be positive, found %g",
                                 s.source, line, s.mass_name, w->mass[i]);
    }
    for (size_t i = 0; w->sigma && i < w->n; ++i)
        if (!(w->sigma[i] > 0 && isfinite(w->sigma[i])))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column 'sigma': sigma must be positive, found %g",
                                 s.source, line_of(w, i), w->sigma[i]);
    for (size_t i = 0; !isnan(opt->dry_mass) && i < w->n; ++i)
        if (w->mass[i] * s.gpu < opt->dry_mass)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: column '%s': mass %g is below the measured dry mass %g %s",
                                 s.source, line_of(w, i), s.mass_name, w->mass[i], opt->dry_mass / s.gpu,
                                 s.mass_unit);
    for (size_t i = 0; i < w->n; ++i)
        for (size_t j = 0; j < w->n_covariates && !skipped(w, i); ++j)
            if (!isfinite(w->covariates[i * w->n_covariates + j]))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: covariate '%s': a covariate needs a number at every kept "
                                     "weighing, found %g", s.source, line_of(w, i),
                                     w->covariate_names && w->covariate_names[j] ? w->covariate_names[j] : "?",
                                     w->covariates[i * w->n_covariates + j]);
    return PHC_OK;
}

/* The weighings kept (not skipped), their masses in g, and where the curve
 * restarts: an irrigation (a rise above the threshold) starts a new piece
 * with jumps = split and is an error with jumps = error. */
typedef struct kept {
    size_t n, *at;          /* indices of the weighings kept */
    double *mass;           /* n, g */
    double jump;            /* the rise that counts as a jump, g */
    size_t n_pieces;
} kept;

static int keep_weighings(const phc_weighings *w, const phc_weight_curve_options *opt, kept *k, phc_error *err)
{
    const series_info s = info_of(w);
    k->at = malloc((w->n ? w->n : 1) * sizeof *k->at);
    k->mass = malloc((w->n ? w->n : 1) * sizeof *k->mass);
    if (!k->at || !k->mass)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < w->n; ++i)
        if (!skipped(w, i)) {
            k->mass[k->n] = w->mass[i] * s.gpu;
            k->at[k->n++] = i;
        }
    if (k->n < 2)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: %zu weighing%s left after select and exclude; a weight curve needs at least 2",
                             s.source, k->n, k->n == 1 ? "" : "s");
    if (isnan(opt->jump_threshold)) {
        double mmax = 0;
        for (size_t i = 0; i < k->n; ++i)
            mmax = fmax(mmax, k->mass[i]);
        k->jump = fmax(isnan(opt->sigma) ? 0 : 5 * opt->sigma * s.gpu, 0.005 * mmax);
    } else {
        k->jump = opt->jump_threshold * s.gpu;
    }
    k->n_pieces = 1;
    for (size_t i = 1; i < k->n; ++i)
        if (k->mass[i] - k->mass[i - 1] > k->jump) {
            if (opt->jumps == PHC_WEIGHT_JUMPS_ERROR)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: the mass rises by %g g since line %zu (an irrigation?); set `jumps: split` or `exclude` the window",
                                     s.source, line_of(w, k->at[i]), k->mass[i] - k->mass[i - 1],
                                     line_of(w, k->at[i - 1]));
            if (opt->jumps == PHC_WEIGHT_JUMPS_SPLIT)
                ++k->n_pieces;
        }
    return PHC_OK;
}

/* The model's part of the data set: graph, edge weights, evaluator, the
 * clock and what reading the logger found (for the report). */
static int impl_new(const phc_plant_graph *plant, const phc_weighings *w, const phc_weight_curve_options *opt,
                    wc_impl **out, phc_error *err)
{
    wc_impl *m = calloc(1, sizeof *m);
    *out = m;
    if (!m)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (int q = 0; q < N_SLOT_KINDS; ++q)
        m->slot[q] = -1;
    m->params = phc_water_params_default();
    m->params.weights = opt->conductance;
    m->method = opt->method;
    m->viscosity = !isnan(opt->viscosity) ? opt->viscosity
                   : opt->conductance >= PHC_WATER_REFERENCE ? 0.9 /* the authors' code */
                                                             : 0.89; /* mPa·s, water at 25 °C */
    m->dry_measured = opt->dry_mass;
    m->step = opt->step;
    m->seconds_per_x = info_of(w).spx;
    m->tare_n = w->tare_n;
    m->tare_line[0] = w->tare_line[0];
    m->tare_line[1] = w->tare_line[1];
    m->max_gap = w->max_gap;
    m->n_gaps = w->gap_s && w->gap_line ? w->n_gaps : 0;
    m->graph = phc_plant_graph_copy(plant);
    if (!m->graph || (w->timezone && !(m->timezone = strdup(w->timezone))))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (m->n_gaps) {
        m->gap_s = malloc(m->n_gaps * sizeof *m->gap_s);
        m->gap_line = malloc(m->n_gaps * sizeof *m->gap_line);
        if (!m->gap_s || !m->gap_line)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        memcpy(m->gap_s, w->gap_s, m->n_gaps * sizeof *m->gap_s);
        memcpy(m->gap_line, w->gap_line, m->n_gaps * sizeof *m->gap_line);
    }
    return PHC_OK;
}

/* Day and night, covariates, a pot (weight_drivers.h), over the kept
 * weighings' times since the first (s). */
static int drivers(wc_impl *m, const phc_weighings *w, const kept *k, const phc_weight_curve_options *opt,
                   phc_error *err)
{
    const size_t J = w->n_covariates;
    double *cov = J ? malloc(k->n * J * sizeof *cov) : NULL;
    m->t_abs = malloc(k->n * sizeof *m->t_abs);
    if (!m->t_abs || (J && !cov)) {
        free(cov);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    const double t0 = w->t[k->at[0]];
    for (size_t i = 0; i < k->n; ++i) {
        m->t_abs[i] = (w->t[k->at[i]] - t0) * m->seconds_per_x;
        for (size_t j = 0; j < J; ++j)
            cov[i * J + j] = w->covariates[k->at[i] * J + j];
    }
    const double first_posix = w->calendar ? w->t0_posix + t0 * m->seconds_per_x : NAN;
    int rc = phc_weight_drivers_init(&opt->day, &opt->pot, cov, w->covariate_names, J, m->t_abs, k->n,
                                     first_posix, m->timezone, opt->origin, &m->drv, err);
    free(cov);
    if (rc)
        return rc;
    m->n_coef = phc_weight_drivers_coef_count(&m->drv);
    return PHC_OK;
}

/* The unit a slot declares, so that a parameter's `unit:` is converted into
 * it (fit/parameter_units.h): the model's units (model/water.h, wilting
 * paper eqs. 4-7: cm, g, s; model/water_balance.h for the pot), NULL for a
 * covariate's coefficient (per unit of the covariate, which has none). */
static const char *slot_unit(const char *name)
{
    if (!strcmp(name, "delta"))
        return "s-1 cm-2"; /* leaf loss l = delta A, A = r h in cm2, l in s-1 */
    if (!strncmp(name, "initial_water", 13) || !strcmp(name, "dry_mass") || !strcmp(name, "pot_capacity"))
        return "g";
    if (!strcmp(name, "viscosity"))
        return "mPa s";
    if (!strcmp(name, "night_factor"))
        return "1"; /* the loss multiplier g(t) by night */
    if (!strcmp(name, "pot_conductance"))
        return "g s-1";
    return NULL;
}

/* Slots: delta, one initial water per piece (initial_water, then
 * initial_water_2, ...), dry_mass unless measured, viscosity when the user
 * made it a parameter, then the drivers' (night_factor, loss_<col>,
 * pot_capacity, pot_conductance). */
static int name_slots(phc_dataset **out, wc_impl *m, size_t n_pieces, int viscosity_slot, phc_error *err)
{
    const size_t n_drv = phc_weight_drivers_slot_count(&m->drv);
    const size_t k_slots = 1 + n_pieces + isnan(m->dry_measured) + (viscosity_slot != 0) + n_drv;
    phc_dataset *ds = phc_dataset_new(&phc_weight_curve_ops, k_slots);
    *out = ds;
    m->pieces = calloc(n_pieces, sizeof *m->pieces);
    if (!m->pieces || !ds)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    size_t js = 0;
    char slot_name[48];
    m->slot[SLOT_DELTA] = (int)js;
    ds->slot_names[js++] = strdup("delta");
    for (size_t q = 0; q < n_pieces; ++q) {
        if (q == 0)
            snprintf(slot_name, sizeof slot_name, "initial_water");
        else
            snprintf(slot_name, sizeof slot_name, "initial_water_%zu", q + 1);
        m->pieces[q].slot = (int)js;
        ds->slot_names[js++] = strdup(slot_name);
    }
    if (isnan(m->dry_measured)) {
        m->slot[SLOT_DRY] = (int)js;
        ds->slot_names[js++] = strdup("dry_mass");
    }
    if (viscosity_slot) {
        m->slot[SLOT_MU] = (int)js;
        ds->slot_names[js++] = strdup("viscosity");
    }
    m->drv_slot = n_drv ? (int)js : -1;
    if (n_drv && phc_weight_drivers_slot_names(&m->drv, ds->slot_names + js))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t j = 0; j < k_slots; ++j) {
        const char *unit = ds->slot_names[j] ? slot_unit(ds->slot_names[j]) : NULL;
        if (!ds->slot_names[j] || (unit && phc_dataset_declare_unit(ds, ds->slot_names[j], unit)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    return PHC_OK;
}

/* The observations (x: time unit since the first weighing kept, y: g), their
 * sigmas and lines, and each one's time since the start of its piece (s). */
static int fill_series(phc_dataset *ds, wc_impl *m, const phc_weighings *w, const kept *k,
                       const phc_weight_curve_options *opt, phc_error *err)
{
    const series_info s = info_of(w);
    const size_t n = k->n;
    const int weighted = w->sigma || !isnan(opt->sigma);
    m->t_model = malloc(n * sizeof *m->t_model);
    ds->n = n;
    ds->x = malloc(n * sizeof *ds->x);
    ds->y = malloc(n * sizeof *ds->y);
    ds->sigma = weighted ? malloc(n * sizeof *ds->sigma) : NULL;
    ds->data_lines = malloc(n * sizeof *ds->data_lines);
    ds->data_file = strdup(s.source);
    if (!m->t_model || !ds->x || !ds->y || !ds->data_lines || !ds->data_file || (weighted && !ds->sigma))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    const double t0 = w->t[k->at[0]];
    double piece_t0 = t0;
    size_t q = 0;
    m->pieces[0].start_x = 0;
    for (size_t i = 0; i < n; ++i) {
        const double tv = w->t[k->at[i]];
        if (i > 0 && opt->jumps == PHC_WEIGHT_JUMPS_SPLIT && k->mass[i] - k->mass[i - 1] > k->jump) {
            m->pieces[q].count = i - m->pieces[q].first;
            ++q;
            m->pieces[q].first = i;
            m->pieces[q].start_x = tv - t0;
            piece_t0 = tv;
        }
        ds->x[i] = tv - t0;
        ds->y[i] = k->mass[i];
        m->t_model[i] = (tv - piece_t0) * s.spx;
        if (ds->sigma)
            ds->sigma[i] = w->sigma ? w->sigma[k->at[i]] * s.gpu : opt->sigma * s.gpu;
        ds->data_lines[i] = line_of(w, k->at[i]);
    }
    m->pieces[q].count = n - m->pieces[q].first;
    m->n_pieces = k->n_pieces;
    return PHC_OK;
}

/* x_seconds, t0_posix and the local clock of every weighing kept. */
static int set_clock(phc_dataset *ds, wc_impl *w, double origin, double first, phc_error *err)
{
    ds->x_seconds = w->seconds_per_x;
    w->t0_posix = origin + first * w->seconds_per_x;
    if (isnan(w->t0_posix))
        return PHC_OK;
    if (!(ds->time_of_day = malloc(ds->n * sizeof *ds->time_of_day)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < ds->n; ++i)
        ds->time_of_day[i] = w->t0_posix + ds->x[i] * w->seconds_per_x;
    int rc = phc_local_clocks(w->timezone, ds->time_of_day, ds->n, ds->time_of_day, err);
    for (size_t i = 0; i < ds->n && !rc; ++i)
        ds->time_of_day[i] /= 3600.0;
    return rc;
}

/* The distinct model times, the workspace, the clock and the labels. */
static int finish(phc_dataset *ds, wc_impl *m, const phc_weighings *w, const kept *k,
                  const phc_weight_curve_options *opt, phc_error *err)
{
    const series_info s = info_of(w);
    int rc;
    if ((rc = phc_unique_times(m->t_model, ds->n, &m->t_unique, &m->m_unique, &m->t_at, err)))
        return rc;
    const size_t rows = m->m_unique > ds->n ? m->m_unique : ds->n;
    m->u = malloc(rows * sizeof *m->u);
    m->du = malloc(rows * (PHC_WB_COEF + m->n_coef) * sizeof *m->du);
    if ((rc = set_clock(ds, m, w->calendar ? w->t0_posix : NAN, w->t[k->at[0]], err)))
        return rc;
    if (!m->u || !m->du)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    ds->derivatives = PHC_DERIV_ANALYTIC;
    /* BDF6 with its extrapolated start reaches ~1e-10 relative (model/water.h) */
    ds->model_tolerance = 1e-10;
    char label[160];
    snprintf(label, sizeof label, "time since the first weighing (%s)", s.time_unit);
    ds->x_label = strdup(opt->x_label ? opt->x_label : label);
    ds->y_label = strdup(opt->y_label ? opt->y_label : "mass (g)");
    if (!ds->x_label || !ds->y_label)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    ds->config_line = phc_origin_line(opt->origin, NULL);
    return PHC_OK;
}

int phc_weight_curve_new(const phc_plant_graph *plant, const phc_weighings *w,
                         const phc_weight_curve_options *opt, phc_dataset **out, phc_error *err)
{
    phc_dataset *ds = NULL;
    wc_impl *m = NULL;
    kept k = {0};
    int rc;

    *out = NULL;
    const int viscosity_slot = opt->is_parameter && opt->is_parameter("viscosity", opt->user_data);
    if ((rc = check_options(plant, w, opt, err)) || (rc = check_weighings(w, opt, err)) ||
        (rc = keep_weighings(w, opt, &k, err)) || (rc = impl_new(plant, w, opt, &m, err)) ||
        (rc = drivers(m, w, &k, opt, err)) || (rc = name_slots(&ds, m, k.n_pieces, viscosity_slot, err)) ||
        (rc = fill_series(ds, m, w, &k, opt, err)) || (rc = finish(ds, m, w, &k, opt, err)))
        goto fail;
    ds->impl = m;
    m = NULL;
    *out = ds;
    ds = NULL;
fail:
    phc_dataset_free(ds);
    wc_free(m);
    free(k.at);
    free(k.mass);
    return rc;
}

/* ---- the report -------------------------------------------------------------- */

/* The report rows of a logger file: the clock, tare readings, long gaps. */
static void logger_rows(const wc_impl *w, char *buf, size_t size)
{
    size_t used = strlen(buf);
    char iso[64];
    if (!isnan(w->t0_posix) && used < size && !phc_local_iso(w->timezone, w->t0_posix, iso, sizeof iso, NULL))
        used += snprintf(buf + used, size - used, "| clock | %s; time 0 (the first weighing kept) is %s |\n",
                         w->timezone ? w->timezone : "UTC (times as written)", iso);
    if (w->tare_n == 1 && used < size)
        used += snprintf(buf + used, size - used, "| tare readings dropped | 1 (line %zu) |\n", w->tare_line[0]);
    else if (w->tare_n > 1 && used < size)
        used += snprintf(buf + used, size - used, "| tare readings dropped | %zu (lines %zu–%zu) |\n",
                         w->tare_n, w->tare_line[0], w->tare_line[1]);
    if (w->n_gaps && used < size) {
        used += snprintf(buf + used, size - used, "| logger gaps longer than %g h | %zu:", w->max_gap / 3600,
                         w->n_gaps);
        for (size_t i = 0; i < w->n_gaps && i < 10 && used < size; ++i)
            used += snprintf(buf + used, size - used, "%s %.1f h after line %zu", i ? "," : "",
                             w->gap_s[i] / 3600, w->gap_line[i]);
        if (used < size)
            snprintf(buf + used, size - used, "%s |\n", w->n_gaps > 10 ? ", ..." : "");
    }
}

/* Report rows of the drivers: the night's loss, the covariates' law, the pot. */
static void driver_rows(const wc_impl *w, const double *p, char *buf, size_t size)
{
    const phc_weight_drivers *d = &w->drv;
    size_t used = strlen(buf);
    int s = w->drv_slot;
    if (d->schedule && used < size) {
        const int fitted = isnan(d->night_factor);
        const double f = fitted ? p[s++] : d->night_factor;
        used += (size_t)snprintf(buf + used, size - used,
                                 "| day and night | day %02d:%02d–%02d:%02d local; by night the leaves "
                                 "lose %.3g× the day's rate (night_factor, %s) |\n",
                                 (int)(d->day_start / 3600), (int)fmod(d->day_start / 60, 60),
                                 (int)(d->day_end / 3600), (int)fmod(d->day_end / 60, 60), f,
                                 fitted ? "fitted" : "fixed");
    }
    if (d->n_cov && used < size) {
        used += (size_t)snprintf(buf + used, size - used, "| loss law | g = 1");
        for (size_t j = 0; j < d->n_cov && used < size; ++j)
            used += (size_t)snprintf(buf + used, size - used, " %+.4g × %s", p[s++], d->cov_names[j]);
        if (used < size)
            used += (size_t)snprintf(buf + used, size - used,
                                     " (loss = δ A g; covariates averaged over each interval) |\n");
    }
    if (d->pot && used < size) {
        const double C = isnan(d->capacity) ? p[s++] : d->capacity;
        const double k = isnan(d->conductance) ? p[s++] : d->conductance;
        double vsum = phc_plant_graph_volume(w->graph) * 1e6;
        used += (size_t)snprintf(buf + used, size - used,
                                 "| pot | capacity %.4g g (%s), root–soil conductance %.4g g/s (%s); "
                                 "soil holds %.1f%% of the water at each start; the plant refills "
                                 "from the soil with time constant V/k = %.3g h (V = %.4g cm³), the "
                                 "soil empties into it over C/k = %.3g h |\n",
                                 C, isnan(d->capacity) ? "fitted" : "fixed", k,
                                 isnan(d->conductance) ? "fitted" : "fixed", 100 * C / (C + vsum),
                                 k > 0 ? vsum / k / 3600 : INFINITY, vsum,
                                 k > 0 ? C / k / 3600 : INFINITY);
    }
}

/* The report hook: what the model was (graph, weights, evaluator) and what
 * the fitted curve means in plain numbers. */
static int wc_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    wc_impl *w = ds->impl;
    static const char *const weight_names[] = {"poiseuille (physical default)", "mean conductance",
                                               "paper", "reference (authors' code)",
                                               "reference_2024"};
    static const char *const method_names[] = {"auto", "exact", "bdf6"};
    const double delta = slot_value(w, p, SLOT_DELTA, 0);
    const double w0 = p[w->pieces[0].slot];
    const double dry = slot_value(w, p, SLOT_DRY, w->dry_measured);
    const double mu = slot_value(w, p, SLOT_MU, w->viscosity);
    const piece *last = &w->pieces[w->n_pieces - 1];
    const int varying = phc_weight_drivers_time_varying(&w->drv);
    const double t_end = varying ? w->t_abs[last->first + last->count - 1]
                                 : w->t_model[last->first + last->count - 1];
    double u_end = NAN;
    if (unit_response(w, p, delta, mu, varying ? w->t_abs[last->first] : 0, &t_end, 1, &u_end, NULL) != 0)
        u_end = NAN;
    const double start = p[last->slot];
    /* Initial loss rate: dW/dt(0) = -Σ ℓ_i θ_i(0) = -δ Σ A_i V_i / Σ V_i · W0. */
    size_t n = w->graph->n, leaves = phc_plant_graph_leaf_count(w->graph);
    double vol = phc_plant_graph_volume(w->graph) * 1e6; /* cm³ */
    /* The slow mode: where pressure equalises much faster than leaves lose
     * water (stiffness >> δ·Ā), W(t) = W0 exp(−δ Ā t) with the
     * volume-weighted leaf area proxy Ā = Σ A_i V_i / Σ V_i (A = r h, cm²). */
    double av = 0, vsum = 0;
    for (size_t i = 0; i < n; ++i) {
        const double r = 100 * w->graph->radius[i], h = 100 * w->graph->length[i];
        const double v = M_PI * r * r * h;
        vsum += v;
        if (w->graph->leaf[i])
            av += r * h * v;
    }
    const double abar = vsum > 0 ? av / vsum : 0;
    char *buf = malloc(4096);
    if (!buf)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    snprintf(buf, 2048,
             "#### Water model (%s)\n\n"
             "| | |\n|---|---|\n"
             "| plant graph | %zu segments, %zu leaf, volume %.4g cm³ |\n"
             "| edge weights | %s |\n"
             "| evaluator | %s%s, stiffness %.3g s⁻¹ |\n"
             "| viscosity μ | %g mPa·s%s |\n"
             "| dry mass | %.6g g (%s) |\n"
             "| curve pieces | %zu%s |\n"
             "| water at the first weighing | %.6g g |\n"
             "| water left at the last weighing | %.6g g (%.1f%% of its piece's start) |\n"
             "| volume-weighted leaf area Ā | %.4g cm² (fast-mixing limit W0 exp(−δĀt): half-life %.4g h) |\n",
             ds->name, n, leaves, vol, weight_names[w->params.weights], method_names[w->method],
             w->step > 0 ? " (fixed step)" : "", w->sys ? phc_water_system_stiffness(w->sys) : NAN, mu,
             w->slot[SLOT_MU] >= 0 ? " (fitted)" : " (fixed)", dry,
             w->slot[SLOT_DRY] >= 0 ? "fitted" : "measured", w->n_pieces,
             w->n_pieces > 1 ? " (split at irrigations; each piece has its own initial water, initial_water_2, ...)" : "",
             w0, start * u_end, 100 * u_end, abar,
             delta > 0 && abar > 0 ? log(2.0) / (delta * abar) / 3600.0 : INFINITY);
    logger_rows(w, buf, 4096);
    driver_rows(w, p, buf, 4096);
    *markdown = buf;
    return PHC_OK;
}
