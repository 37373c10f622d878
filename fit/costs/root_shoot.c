/* `root_shoot` data sets: see root_shoot.h. */
#include "fit/costs/root_shoot.h"
#include "fit/engine/baseline.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "fit/growth_outputs.h"
#include "measurements/atomic_file.h"

/* The simulated trajectory: one state per step. */
typedef struct rs_traj {
    size_t m, cap;
    double *t, *d, *lrs;         /* d, m, ln(root:shoot) */
    phc_growth_summary last;
} rs_traj;

/* The last RS_CACHE trajectories, by the exact slot values that grew them.
 * The plant is deterministic (expected mode, or stochastic with its fixed
 * seed), so a second simulation at the same slot values repeats the first
 * bit for bit; the solver asks for the same point several times (Ceres
 * evaluates a trust-region candidate in its projected line search, again
 * for its cost, and once more with the Jacobian when it accepts it; the
 * analysis evaluates the solution again), and a cached trajectory answers
 * without simulating.  A trajectory that ends at diameter D answers every
 * request for diameters <= D (a plant grown for them would stop at the
 * first step past the largest, and its steps are the first steps of the
 * kept one); one that ran the whole span answers every request. */
#define RS_CACHE 32

typedef struct rs_cached {
    double *p;                   /* k slot values; NULL: empty */
    double reach;                /* m, the diameter it ends at (INFINITY: it ran the whole span) */
    rs_traj tr;
} rs_cached;

typedef struct rs_impl {
    phc_soil_setup *su;          /* NULL: no soil (fill = soil_fill) */
    size_t k_soil;               /* the soil's slots come first */
    phc_growth_params base;      /* preset + overrides */
    char preset[32];
    char *species;               /* NULL: not given */
    phc_growth_options opt;
    long *gslot;                 /* per data-set slot past k_soil: growth parameter index */
    size_t k_growth;
    double days, step;
    double *diameter;            /* n, m */
    double *age;                 /* n, d (NAN when not given) */
    double d_max;                /* m, largest observed diameter */
    char *source;                /* a sentence naming the data */
    char *notes;                 /* markdown list of excluded / skipped rows */
    size_t k;                    /* slot count (k_soil + k_growth) */
    rs_cached cache[RS_CACHE];
    size_t cache_next;           /* the slot the next new trajectory replaces */
    phc_root_shoot_counts counts;
} rs_impl;

static void traj_free(rs_traj *tr)
{
    free(tr->t);
    free(tr->d);
    free(tr->lrs);
    memset(tr, 0, sizeof *tr);
}

static int traj_push(rs_traj *tr, double t, double d, double lrs)
{
    if (tr->m == tr->cap) {
        size_t cap = tr->cap ? 2 * tr->cap : 256;
        double *a = realloc(tr->t, cap * sizeof *a);
        if (a) tr->t = a;
        double *b = realloc(tr->d, cap * sizeof *b);
        if (b) tr->d = b;
        double *c = realloc(tr->lrs, cap * sizeof *c);
        if (c) tr->lrs = c;
        if (!a || !b || !c) return -1;
        tr->cap = cap;
    }
    tr->t[tr->m] = t;
    tr->d[tr->m] = d;
    tr->lrs[tr->m] = lrs;
    tr->m++;
    return 0;
}

static void rs_free(void *p)
{
    rs_impl *im = p;
    if (!im) return;
    for (size_t i = 0; i < RS_CACHE; ++i) {
        free(im->cache[i].p);
        traj_free(&im->cache[i].tr);
    }
    phc_soil_setup_free(im->su);
    free(im->gslot);
    free(im->diameter);
    free(im->age);
    free(im->source);
    free(im->notes);
    free(im->species);
    free(im);
}

/* Grows the plant at slot values p until its diameter passes d_stop or the
 * age reaches `days`.  0, > 0 (trial point outside the model's domain) or
 * < 0 (memory); with keep the plant and its soil are handed over. */
static int grow(const rs_impl *im, const double *p, double d_stop, rs_traj *tr,
                phc_growth **keep_plant, phc_soil **keep_soil, phc_root_shoot_counts *cnt,
                phc_error *err)
{
    phc_growth_params gp = im->base;
    for (size_t j = 0; j < im->k_growth; ++j)
        *phc_growth_param_ref(&gp, (size_t)im->gslot[j]) = p[im->k_soil + j];
    phc_error local;
    if (!err) err = &local;
    if (phc_growth_check(&gp, err)) return 1;
    phc_soil *s = NULL;
    if (im->su) {
        int rc = phc_soil_setup_build(im->su, p, &s, err);
        if (rc) return rc == PHC_ERR_NOMEM ? -1 : 1;
    }
    phc_growth *g = NULL;
    int rc = phc_growth_new(&gp, &im->opt, s, &g, err);
    if (rc) {
        phc_soil_free(s);
        return rc == PHC_ERR_NOMEM ? -1 : 1;
    }
    phc_growth_summary sm;
    phc_growth_summarize(g, &sm);
    rc = traj_push(tr, 0, sm.basal_diameter, NAN);
    for (double t = 0; !rc && t < im->days - 1e-9;) {
        double h = fmin(im->step, im->days - t);
        int r = phc_growth_step(g, h, err);
        if (r) { rc = r == PHC_ERR_NOMEM ? -1 : 1; break; }
        t += h;
        phc_growth_summarize(g, &sm);
        double lrs = sm.root_mass > 0 && sm.shoot_mass > 0 ? log(sm.root_shoot) : NAN;
        if (traj_push(tr, t, sm.basal_diameter, lrs)) rc = -1;
        if (sm.basal_diameter >= d_stop) break;
    }
    tr->last = sm;
    cnt->simulated++;
    cnt->days += sm.age;
    if (s) cnt->soil_substeps += s->budget.substeps;
    if (!rc && keep_plant) {
        *keep_plant = g;
        *keep_soil = s;
    } else {
        phc_growth_free(g);
        phc_soil_free(s);
    }
    return rc;
}

/* ln(root:shoot) and age when the diameter first reaches d (NAN if never). */
static void at_diameter(const rs_traj *tr, double d, double *lrs, double *age)
{
    *lrs = *age = NAN;
    for (size_t i = 1; i < tr->m; ++i) {
        if (tr->d[i] < d) continue;
        double d0 = tr->d[i - 1], d1 = tr->d[i];
        double w = d1 > d0 ? (d - d0) / (d1 - d0) : 1;
        if (w < 0) w = 0;
        double l0 = isfinite(tr->lrs[i - 1]) ? tr->lrs[i - 1] : tr->lrs[i];
        *lrs = l0 + w * (tr->lrs[i] - l0);
        *age = tr->t[i - 1] + w * (tr->t[i] - tr->t[i - 1]);
        return;
    }
}

/* The kept trajectory grown at exactly p that reaches d_stop, or NULL. */
static const rs_traj *cache_find(const rs_impl *im, const double *p, double d_stop)
{
    for (size_t i = 0; i < RS_CACHE; ++i) {
        const rs_cached *c = &im->cache[i];
        if (c->p && c->reach >= d_stop && !memcmp(c->p, p, im->k * sizeof *p))
            return &c->tr;
    }
    return NULL;
}

/* Hands tr (grown at p until the diameter passed d_stop, or over the whole
 * span) to the cache, replacing the oldest entry; frees it when there is
 * no memory for the key. */
static void cache_keep(rs_impl *im, const double *p, double d_stop, rs_traj *tr)
{
    rs_cached *c = &im->cache[im->cache_next];
    double *key = c->p ? c->p : malloc((im->k ? im->k : 1) * sizeof *key);
    if (!key) {
        traj_free(tr);
        return;
    }
    traj_free(&c->tr);
    memcpy(key, p, im->k * sizeof *p);
    c->p = key;
    /* a plant that never reached d_stop ran the whole span: it answers any diameter */
    c->reach = tr->m && tr->d[tr->m - 1] >= d_stop ? tr->d[tr->m - 1] : INFINITY;
    c->tr = *tr;
    memset(tr, 0, sizeof *tr);
    im->cache_next = (im->cache_next + 1) % RS_CACHE;
}

/* Model values y (m points x n values, row-major) at the diameters d (n)
 * for m slot vectors q (m x k, row-major), each from a kept trajectory or
 * a plant grown for it.  The plants to grow are independent (each builds its
 * own soil; the model has no globals), so they grow in parallel threads
 * (OpenMP); every trajectory is the same as grown alone, bit for bit, and
 * the results are used in point order.  0, or the return code of the first
 * point (in order) whose plant failed (grow). */
static int values_many(rs_impl *im, const double *q, size_t m, const double *d, size_t n, double *y)
{
    const size_t k = im->k;
    double dmax = 0;
    for (size_t i = 0; i < n; ++i) dmax = fmax(dmax, d[i]);
    rs_traj *tr = calloc(m, sizeof *tr);
    int *rc = calloc(m, sizeof *rc);
    size_t *miss = malloc(m * sizeof *miss);
    phc_root_shoot_counts *cnt = calloc(m, sizeof *cnt);
    const rs_traj **use = calloc(m, sizeof *use);
    if (!tr || !rc || !miss || !cnt || !use) {
        free(tr); free(rc); free(miss); free(cnt); free(use);
        return -1;
    }
    size_t n_miss = 0;
    for (size_t a = 0; a < m; ++a) {
        im->counts.requested++;
        if ((use[a] = cache_find(im, q + a * k, dmax)))
            im->counts.reused++;
        else
            miss[n_miss++] = a;
    }
#pragma omp parallel for schedule(dynamic, 1) if (n_miss > 1)
    for (size_t b = 0; b < n_miss; ++b) {
        const size_t a = miss[b];
        rc[a] = grow(im, q + a * k, dmax, &tr[a], NULL, NULL, &cnt[a], NULL);
    }
    int first = 0;
    for (size_t a = 0; a < m; ++a) {
        im->counts.simulated += cnt[a].simulated;
        im->counts.days += cnt[a].days;
        im->counts.soil_substeps += cnt[a].soil_substeps;
        if (!use[a] && !rc[a])
            use[a] = &tr[a];
        if (!first && rc[a]) first = rc[a];
        if (use[a])
            for (size_t i = 0; i < n; ++i) {
                double age;
                at_diameter(use[a], d[i], &y[a * n + i], &age);
            }
    }
    for (size_t b = 0; b < n_miss; ++b) {
        const size_t a = miss[b];
        if (!rc[a]) cache_keep(im, q + a * k, dmax, &tr[a]);
        traj_free(&tr[a]);
    }
    free(tr); free(rc); free(miss); free(cnt); free(use);
    return first;
}

static int rs_values(phc_dataset *ds, const double *p, const double *d, size_t m, double *y)
{
    return values_many(ds->impl, p, 1, d, m, y);
}

int phc_root_shoot_counts_get(const phc_dataset *ds, phc_root_shoot_counts *out)
{
    if (!ds || ds->ops != &phc_root_shoot_ops || !out) return PHC_ERR_INVALID;
    *out = ((const rs_impl *)ds->impl)->counts;
    return PHC_OK;
}

/* Relative step of the Jacobian's central differences: the model is a
 * simulation whose events (a new segment, a flushed bud) fall on daily
 * steps, so its outputs are piecewise smooth with small jumps; steps of 2%
 * of each parameter span many events and give the slope of the trend, where
 * steps of 1e-6 would see either zero or a jump. */
#define RS_FD_STEP 0.02

static int rs_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    rs_impl *im = ds->impl;
    if (!jac) return rs_values(ds, p, im->diameter, ds->n, yhat);
    /* point 0: p; 2j + 1 and 2j + 2: p + h_j and p - h_j in slot j */
    const size_t k = ds->k, n = ds->n, m = 2 * k + 1;
    double *q = malloc(m * k * sizeof *q), *y = malloc(m * n * sizeof *y), *h = malloc((k ? k : 1) * sizeof *h);
    int rc = !q || !y || !h ? -1 : 0;
    for (size_t j = 0; !rc && j < k; ++j)
        h[j] = RS_FD_STEP * (fabs(p[j]) > 0 ? fabs(p[j]) : 1);
    for (size_t a = 0; !rc && a < m; ++a) {
        memcpy(q + a * k, p, k * sizeof *q);
        if (a > 0) {
            const size_t j = (a - 1) / 2;
            q[a * k + j] = a % 2 ? p[j] + h[j] : p[j] - h[j];
        }
    }
    if (!rc) rc = values_many(im, q, m, im->diameter, n, y);
    if (!rc) {
        memcpy(yhat, y, n * sizeof *yhat);
        for (size_t j = 0; j < k; ++j)
            for (size_t i = 0; i < n; ++i)
                jac[i * k + j] = (y[(2 * j + 1) * n + i] - y[(2 * j + 2) * n + i]) / (2 * h[j]);
    }
    free(q);
    free(y);
    free(h);
    return rc;
}

static int rs_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m, double *y)
{
    double *d = malloc((m ? m : 1) * sizeof *d);
    if (!d) return -1;
    for (size_t i = 0; i < m; ++i) d[i] = x[i] * 1e-3; /* x is in mm */
    int rc = rs_values(ds, p, d, m, y);
    free(d);
    return rc;
}

/* Which preset was used, and whether it describes the plants' species
 * (phc_growth_preset_for_species): said plainly when it does not. */
static void preset_sentence(FILE *f, const rs_impl *im)
{
    const char *group = NULL;
    const char *own = phc_growth_preset_for_species(im->species, &group);
    if (!im->species)
        fprintf(f, "Preset: `%s`. The plants' species is not given, so whether the preset "
                   "describes it is not known.\n\n", im->preset);
    else if (own && !strcasecmp(own, im->preset))
        fprintf(f, "Preset: `%s`, the preset for the genus *%s* of *%s*.\n\n", im->preset, group,
                im->species);
    else {
        fprintf(f, "**Preset:** `%s` was used for *%s*, a species it does not describe. ", im->preset,
                im->species);
        if (own)
            fprintf(f, "The preset for its genus *%s* is `%s`.", group, own);
        else
            fprintf(f, "No preset describes %s: the five presets are for *Quercus* (oak), *Prunus* "
                       "(cherry), *Malus* (apple), *Populus* (poplar) and *Acer* (maple); there is "
                       "no conifer or tropical preset.",
                    !strcmp(group, "conifer") ? "conifers" : "its genus");
        fprintf(f, " The growth parameters the fit does not estimate are that preset's, and every "
                   "preset's values are ours, not measured (model/growth.c): read the fitted "
                   "values as calibration constants of this model for these plants.\n\n");
    }
}

static int rs_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    rs_impl *im = ds->impl;
    const phc_root_shoot_counts before = im->counts;
    rs_traj tr = {0};
    int rc = grow(im, p, im->d_max, &tr, NULL, NULL, &im->counts, err);
    if (rc) {
        traj_free(&tr);
        return rc < 0 ? phc_error_set(err, PHC_ERR_NOMEM, "out of memory")
                      : phc_error_prefix(err, PHC_ERR_DOMAIN, "data set '%s': the plant",
                                         ds->name);
    }
    char *out = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    if (!f) {
        traj_free(&tr);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    const phc_growth_summary *s = &tr.last;
    fprintf(f, "Data: %s\n\n", im->source);
    if (im->notes && *im->notes) fprintf(f, "%s\n", im->notes);
    fprintf(f,
            "Model: Rhizomorph shoot-root growth (preset `%s`, %s mode, %s uptake, steps of "
            "%g d, at most %g d)%s.\n\n",
            im->preset, im->opt.mode == PHC_GROWTH_EXPECTED ? "expected" : "stochastic",
            im->opt.uptake == PHC_GROWTH_UPTAKE_PHYSICAL ? "physical" : "no", im->step, im->days,
            im->su ? " in the soil below" : " without soil");
    fprintf(f,
            "Simulated plant when it reached the largest observed diameter (%.3g mm): age %.1f d, "
            "basal diameter %.3g mm, shoot %.4g g (leaves %.4g g), roots %.4g g, root:shoot "
            "%.3g, height %.3g m, rooting depth %.3g m, root spread %.3g m, %zu shoot and %zu "
            "root segments.\n\n",
            im->d_max * 1e3, s->age, s->basal_diameter * 1e3, s->shoot_mass, s->leaf_mass,
            s->root_mass, s->root_shoot, s->height, s->rooting_depth, s->root_spread,
            s->shoot_nodes, s->root_nodes);
    preset_sentence(f, im);
    fprintf(f,
            "Simulations before this report: %lu trajectories asked for (the fit's values and "
            "Jacobians), %lu of them answered by one of the last %d kept, %lu plants grown "
            "(%.0f simulated days, %lu soil sub-steps).\n\n",
            before.requested, before.reused, RS_CACHE, before.simulated, before.days,
            before.soil_substeps);
    if (s->basal_diameter < im->d_max)
        fprintf(f, "**Warning:** the simulated plant did not reach %.3g mm within %g d.\n\n",
                im->d_max * 1e3, im->days);
    /* Ages: the model's age at each plant's diameter against the harvest age. */
    size_t n_age = 0;
    double sum_ratio = 0;
    for (size_t i = 0; i < ds->n; ++i) {
        if (!isfinite(im->age[i]) || !(im->age[i] > 0)) continue;
        double l, a;
        at_diameter(&tr, im->diameter[i], &l, &a);
        if (!isfinite(a)) continue;
        sum_ratio += log(a / im->age[i]);
        n_age++;
    }
    if (n_age)
        fprintf(f,
                "Ages: over %zu harvested plants with an age, the model reaches their diameter "
                "at %.3g times their age (geometric mean); the fit uses diameters only.\n",
                n_age, exp(sum_ratio / (double)n_age));
    traj_free(&tr);
    if (ferror(f) | (fclose(f) != 0)) {
        free(out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *markdown = out;
    return PHC_OK;
}

static int rs_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base,
                      phc_error *err)
{
    rs_impl *im = ds->impl;
    rs_traj tr = {0};
    phc_growth *g = NULL;
    phc_soil *s = NULL;
    int rc = grow(im, p, im->d_max, &tr, &g, &s, &im->counts, err);
    if (rc) {
        traj_free(&tr);
        return rc < 0 ? phc_error_set(err, PHC_ERR_NOMEM, "out of memory") : PHC_ERR_DOMAIN;
    }
    char *path = NULL;
    size_t cap = strlen(dir) + strlen(base) + 64;
    path = malloc(cap);
    if (!path) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto done; }
    snprintf(path, cap, "%s/%s_roots.rsml", dir, base);
    if ((rc = phc_growth_write_rsml(g, path, err))) goto done;
    snprintf(path, cap, "%s/%s_plant.txt", dir, base);
    if ((rc = phc_growth_write_plant_graph(g, path, err))) goto done;
    snprintf(path, cap, "%s/%s_architecture.png", dir, base);
    {
        char title[160];
        snprintf(title, sizeof title, "%s: %s at %.0f d, D = %.2g mm, root:shoot %.2g", ds->name,
                 im->preset, tr.last.age, tr.last.basal_diameter * 1e3, tr.last.root_shoot);
        const phc_growth *plants[1] = {g};
        const char *titles[1] = {title};
        double top = s ? s->origin[2] + s->nz * s->dx : im->opt.base[2];
        double x0 = s ? s->origin[0] : 0, x1 = s ? s->origin[0] + s->nx * s->dx : 0;
        if ((rc = phc_growth_plot_side(path, plants, titles, 1, top, x0, x1, err))) goto done;
    }
    snprintf(path, cap, "%s/%s_trajectory.csv", dir, base);
    {
        phc_atomic_file *af = NULL;
        if ((rc = phc_atomic_file_open(path, &af, err))) goto done;
        FILE *f = phc_atomic_file_stream(af);
        fprintf(f, "age_d,basal_diameter_mm,ln_root_shoot\n");
        for (size_t i = 0; i < tr.m; ++i)
            fprintf(f, "%.6g,%.6g,%.6g\n", tr.t[i], tr.d[i] * 1e3, tr.lrs[i]);
        if ((rc = phc_atomic_file_commit(af, err))) goto done;
    }
done:
    free(path);
    phc_growth_free(g);
    phc_soil_free(s);
    traj_free(&tr);
    return rc;
}

/* The allometric line ln(root:shoot) = a + b ln D (D the basal diameter):
 * the usual description of harvests (fit/engine/baseline.h). */
static int rs_baseline(const phc_dataset *ds, phc_baseline *out)
{
    double *u = malloc(ds->n * sizeof *u);
    if (!u)
        return PHC_ERR_NOMEM;
    for (size_t i = 0; i < ds->n; ++i)
        u[i] = log(ds->x[i]); /* x: diameter, mm, > 0 */
    const int rc = phc_baseline_line(u, ds->y, ds->sigma, ds->n, "allometric",
                                     "the allometric line ln(root:shoot) = a + b ln(diameter)", out);
    free(u);
    return rc;
}

const phc_dataset_ops phc_root_shoot_ops = {
    .baseline = rs_baseline,
    .kind = "root_shoot",
    .predict = rs_predict,
    .predict_at = rs_predict_at,
    .free_impl = rs_free,
    .report_section = rs_report_section,
    .simulate_outputs = rs_outputs,
    .fit_outputs = rs_outputs,
};

/* ---- building ------------------------------------------------------------------ */

phc_root_shoot_options phc_root_shoot_options_default(void)
{
    phc_root_shoot_options o = {.sigma = NAN, .preset = "oak", .mode = PHC_GROWTH_EXPECTED, .seed = 1,
                                .uptake = PHC_GROWTH_UPTAKE_PHYSICAL, .days = 365, .step = 1,
                                .plant_x = NAN, .plant_y = NAN};
    return o;
}

#define WHERE(key) phc_origin_key(o->origin, "root_shoot", key).text

/* sigma, the simulated span and the growth parameters (preset and
 * overrides, checked as the model checks them). */
static int setup_growth(rs_impl *im, const phc_root_shoot_options *o, phc_error *err)
{
    int rc;
    if (!(o->sigma > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': must be > 0, found %g", WHERE("sigma"), o->sigma);
    im->days = o->days;
    im->step = o->step;
    if (!(im->days > 0) || !(im->step > 0) || im->step > im->days)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: keys 'days' and 'step': need 0 < step <= days, found step "
                             "%g d and days %g d",
                             WHERE(im->step > 0 ? "days" : "step"), im->step, im->days);
    const char *preset = o->preset ? o->preset : "oak";
    if (o->growth)
        im->base = *o->growth;
    else if ((rc = phc_growth_preset(preset, &im->base, err)))
        return phc_error_prefix(err, rc, "%s: key 'preset'", WHERE("preset"));
    snprintf(im->preset, sizeof im->preset, "%s", preset);
    if (o->species && !(im->species = strdup(o->species)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    im->opt = phc_growth_options_default();
    im->opt.mode = o->mode;
    im->opt.seed = o->seed;
    im->opt.uptake = o->uptake;
    if ((rc = phc_growth_check(&im->base, err)))
        return phc_error_prefix(err, rc, "%s", WHERE("growth"));
    return PHC_OK;
}

/* The soil and the plant's position in it. */
static int setup_soil(rs_impl *im, const phc_root_shoot_options *o, phc_error *err)
{
    int rc;
    if (o->soil && (rc = phc_soil_setup_new(o->soil, "root_shoot", o->is_parameter, o->user_data, &im->su, err)))
        return rc;
    im->k_soil = im->su ? im->su->k : 0;
    double W = im->su ? im->su->nx * im->su->dx : 0, D = im->su ? im->su->ny * im->su->dx : 0;
    double H = im->su ? im->su->nz * im->su->dx : 0;
    double x = isnan(o->plant_x) ? W / 2 : o->plant_x, y = isnan(o->plant_y) ? D / 2 : o->plant_y;
    double depth = o->plant_depth;
    if (im->su && !(x >= 0 && x <= W && y >= 0 && y <= D && depth >= 0 && depth <= H))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: plant: the plant is seeded at x = %g, y = %g m, depth %g "
                             "m, outside the soil grid (x in [0, %g], y in [0, %g], depth in "
                             "[0, %g] m)",
                             WHERE("plant"), x, y, depth, W, D, H);
    im->opt.base[0] = x;
    im->opt.base[1] = y;
    im->opt.base[2] = H - depth;
    return PHC_OK;
}

static int default_growth_slot(const char *name, void *user_data)
{
    (void)user_data;
    return !strcmp(name, "phi_rg");
}

/* The growth parameters that are fitted. */
static int choose_growth_slots(rs_impl *im, const phc_root_shoot_options *o, phc_error *err)
{
    phc_is_parameter_fn is_parameter = o->is_parameter ? o->is_parameter : default_growth_slot;
    im->gslot = malloc(phc_growth_param_count() * sizeof *im->gslot);
    if (!im->gslot) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t q = 0; q < phc_growth_param_count(); ++q)
        if (is_parameter(phc_growth_param_name(q), o->user_data)) im->gslot[im->k_growth++] = (long)q;
    return PHC_OK;
}

/* The UDUNITS-2 units of the growth parameters as model/growth.h states
 * them (Rhizomorph, Li et al. 2023, Table 4; angles in degrees, rates per
 * day); a parameter not listed has none that UDUNITS-2 can spell (the
 * model's "vigor", the inhibitor, nutrient units) and keeps `unit:` as a
 * label. */
static const struct {
    const char *name, *unit;
} growth_units[] = {
    {"internode_length", "m"},      {"shoot_elongation", "m/d"},     {"apical_angle", "degree"},
    {"branching_angle", "degree"},  {"angle_sd", "degree"},          {"apical_dominance", "1"},
    {"lateral_buds", "1"},          {"bud_flush", "d-1"},            {"inhibition_distance", "m"},
    {"phototropism", "1"},          {"prune_ratio", "1"},            {"leaf_area", "m2"},
    {"leaf_distance", "m"},         {"lma", "g/m2"},                 {"light_extinction", "1"},
    {"light_voxel", "m"},           {"light", "1"},                  {"root_node_length", "m"},
    {"root_elongation", "m/d"},     {"root_apical_angle", "degree"}, {"root_branching_angle", "degree"},
    {"root_apical_dominance", "1"}, {"root_branching", "1"},         {"gravitropism_root", "1"},
    {"hydrotropism", "1"},          {"tropism_switch", "1"},         {"water_uptake", "m3 m-1 d-1"},
    {"uptake_cap", "d-1"},          {"root_resistance", "1"},        {"soil_fill", "1"},
    {"tip_radius_shoot", "m"},      {"tip_radius_root", "m"},        {"pipe_exponent", "1"},
    {"phi_rg", "1"},                {"wood_density", "g/m3"},        {"root_density", "g/m3"},
    {"reserve_rate", "d-1"},
};

static const char *growth_unit(const char *name)
{
    for (size_t i = 0; i < sizeof growth_units / sizeof growth_units[0]; ++i)
        if (!strcmp(growth_units[i].name, name))
            return growth_units[i].unit;
    return NULL;
}

/* The slots' names and units: the soil's, then the growth parameters'. */
static int name_slots(phc_dataset *ds, const rs_impl *im)
{
    int bad = 0;
    for (size_t q = 0; q < im->k_soil && !bad; ++q)
        bad = !(ds->slot_names[q] = strdup(im->su->slot_names[q]));
    for (size_t j = 0; j < im->k_growth && !bad; ++j) {
        const char *name = phc_growth_param_name((size_t)im->gslot[j]);
        const char *unit = growth_unit(name);
        bad = !(ds->slot_names[im->k_soil + j] = strdup(name)) ||
              (unit && phc_dataset_declare_unit(ds, name, unit));
    }
    if (!bad && im->su)
        bad = phc_soil_setup_declare_units(im->su, ds) != PHC_OK;
    return bad ? PHC_ERR_NOMEM : PHC_OK;
}

/* The observations: ln(root:shoot) over the basal diameter in mm. */
static int fill_plants(phc_dataset *ds, rs_impl *im, const phc_harvest *h, const phc_root_shoot_options *o)
{
    const size_t n = h->n;
    char default_source[4200];
    ds->n = n;
    ds->x = malloc(n * sizeof *ds->x);
    ds->y = malloc(n * sizeof *ds->y);
    ds->sigma = malloc(n * sizeof *ds->sigma);
    ds->data_lines = malloc(n * sizeof *ds->data_lines);
    ds->data_file = strdup(h->file ? h->file : "plants");
    im->diameter = malloc(n * sizeof *im->diameter);
    im->age = malloc(n * sizeof *im->age);
    ds->x_label = strdup(o->x_label ? o->x_label : "basal diameter (mm)");
    ds->y_label = strdup(o->y_label ? o->y_label : "ln(root mass / shoot mass)");
    snprintf(default_source, sizeof default_source, "`%s`, %zu harvested plants", h->file ? h->file : "plants", n);
    im->source = strdup(h->source ? h->source : default_source);
    im->notes = h->notes ? strdup(h->notes) : NULL;
    if (!ds->x || !ds->y || !ds->sigma || !ds->data_lines || !ds->data_file || !im->diameter || !im->age ||
        !ds->x_label || !ds->y_label || !im->source || (h->notes && !im->notes))
        return PHC_ERR_NOMEM;
    for (size_t i = 0; i < n; ++i) {
        ds->x[i] = h->diameter[i] * 1e3;
        ds->y[i] = log(h->root_mass[i] / h->shoot_mass[i]);
        ds->sigma[i] = o->sigma;
        ds->data_lines[i] = h->line ? h->line[i] : i + 2;
        im->diameter[i] = h->diameter[i];
        im->age[i] = h->age ? h->age[i] : NAN;
        if (h->diameter[i] > im->d_max) im->d_max = h->diameter[i];
    }
    for (size_t i = 0; i < h->n_inputs; ++i)
        if (phc_dataset_add_input(ds, h->inputs[i]))
            return PHC_ERR_NOMEM;
    return PHC_OK;
}

int phc_root_shoot_new(const phc_harvest *h, const phc_root_shoot_options *o, phc_dataset **out, phc_error *err)
{
    phc_dataset *ds = NULL;
    int rc;
    *out = NULL;
    rs_impl *im = calloc(1, sizeof *im);
    if (!im) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = setup_growth(im, o, err)) || (rc = setup_soil(im, o, err)) ||
        (rc = choose_growth_slots(im, o, err)) || (rc = phc_harvest_check(h, err)))
        goto fail;
    ds = phc_dataset_new(&phc_root_shoot_ops, im->k_soil + im->k_growth);
    if (!ds || name_slots(ds, im) || fill_plants(ds, im, h, o)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    im->k = ds->k;
    ds->derivatives = PHC_DERIV_ANALYTIC; /* our own wide central differences */
    ds->model_tolerance = 1e-4;
    ds->config_line = phc_origin_line(o->origin, NULL);
    ds->impl = im;
    im = NULL;
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    rs_free(im);
    if (ds) ds->impl = NULL;
    phc_dataset_free(ds);
    return rc;
}
