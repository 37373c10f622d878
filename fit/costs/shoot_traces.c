/* `shoot_traces` data sets: see shoot_traces.h. */
#include "fit/costs/shoot_traces.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/shoot_tracer.h"
#include "fit/costs/unique_times.h"
#include "fit/engine/problem.h"
#include "model/climbing_statistics.h"
#include "model/jacobi_svd.h"

enum { ST_TOTAL, ST_MAIN, ST_HEIGHT, ST_ATTACHED, ST_COSINE, ST_COUNT1, ST_ANGLE_MEAN = ST_COUNT1 + 7, ST_ANGLE_SD,
       ST_N };

static const char *const stat_names[ST_N] = {
    "total_length (m)", "main_length (m)", "height (m)", "attached_fraction", "light_cosine",
    "shoots order 1", "shoots order 2", "shoots order 3", "shoots order 4", "shoots order 5",
    "shoots order 6", "shoots order 7", "angle_mean (deg)", "angle_sd (deg)"};

static const char *const slot_names[] = {"branch_probability", "direction_variance", "phototropism",
                                         "surface_adaption", "growth_rate", "apical_dominance",
                                         "thickness_falloff", "min_stiffness", "anchor_strength"};
static const char *const slot_units[] = {"1", "1", "s-1", "s-1", "s-1", "1", "1", "1", "1"};
#define N_SLOTS (sizeof slot_names / sizeof slot_names[0])

static double *slot_ref(phc_climbing_options *o, size_t s)
{
    switch (s) {
    case 0: return &o->branch_probability;
    case 1: return &o->direction_variance;
    case 2: return &o->phototropism;
    case 3: return &o->surface_adaption;
    case 4: return &o->growth_rate;
    case 5: return &o->apical_dominance;
    case 6: return &o->thickness_falloff;
    case 7: return &o->min_stiffness;
    default: return &o->anchor_strength;
    }
}

typedef struct st_impl {
    phc_shoot_traces *traces;
    phc_shoot_traces_options o;   /* times point into `times` below */
    double *times;
    size_t n_times;
    double *sigma_given;          /* n: sigma before the seed spread is added */
    double *sigma_total;          /* n: sqrt of the covariance's diagonal */
    double *y_raw;                /* n: the traced statistics (ds->y holds them whitened) */
    double *L;                    /* n x n: Cholesky factor of the statistics' covariance */
    double *frames;               /* s: the times the tracer looks at a model plant */
    size_t *frame_steps;          /* round(frame / Δt) */
    size_t n_frames;
    int *stat;                    /* n: statistic of each observation */
    size_t *tindex;               /* n: time index of each observation */
    size_t slot[N_SLOTS];         /* data-set slot j -> slot_names index */
    size_t k;
    unsigned long plants;         /* plants grown */
    double *sigma_at;             /* k: the slot values Σ was last computed at */
    size_t rounds;                /* recomputations of Σ at fitted values */
    double change;                /* the last reweight call's largest relative change (NAN: none) */
    int settled;                  /* the rounds stopped on the tolerance */
} st_impl;

phc_shoot_traces_options phc_shoot_traces_options_default(void)
{
    phc_shoot_traces_options o;
    memset(&o, 0, sizeof o);
    o.plant = phc_climbing_options_default();
    o.direction[2] = 1;
    o.time_step = 0.25;
    o.seeds = 8;
    o.first_seed = o.plant.seed;
    o.sigma_rel = 0.1;
    o.sigma_length = 0.01;
    o.sigma_fraction = 0.05;
    o.sigma_cosine = 0.05;
    o.sigma_angle = 5;
    o.fd_step = 0.2;
    o.covariance_seeds = 64;
    o.correlation = 0.5;
    o.covariance_rounds = 5;
    o.covariance_tolerance = 0.02;
    return o;
}

static void st_free(void *p)
{
    st_impl *im = p;
    if (!im) return;
    phc_shoot_traces_free(im->traces);
    if (im->o.support_free) im->o.support_free(im->o.support_owner);
    free(im->times);
    free(im->frames);
    free(im->sigma_given);
    free(im->sigma_total);
    free(im->y_raw);
    free(im->L);
    free(im->sigma_at);
    free(im->frame_steps);
    free(im->stat);
    free(im->tindex);
    free(im);
}

static double stat_value(const phc_climbing_summary *s, int id)
{
    switch (id) {
    case ST_TOTAL: return s->total_length;
    case ST_MAIN: return s->main_length;
    case ST_HEIGHT: return s->height;
    case ST_ATTACHED: return s->attached_fraction;
    case ST_COSINE: return s->light_cosine;
    case ST_ANGLE_MEAN: return s->angle_mean;
    case ST_ANGLE_SD: return s->angle_sd;
    default: return s->shoots[id - ST_COUNT1 + 1];
    }
}

static phc_climbing_stat_options stat_options(const phc_shoot_traces_options *o)
{
    phc_climbing_stat_options so;
    memset(&so, 0, sizeof so);
    memcpy(so.origin, o->position, sizeof so.origin);
    memcpy(so.light, o->plant.light.direction, sizeof so.light);
    so.attach_distance = o->plant.attach_distance;
    so.closest = o->plant.closest;
    so.closest_user = o->plant.closest_user;
    return so;
}

/* The supports' shadows in plant c's light grid, when the options carry
 * them (0, or the error of phc_climbing_set_shadow_triangles). */
static int cast_shadows(const phc_shoot_traces_options *o, phc_climbing *c, phc_error *err)
{
    if (!o->shadow_triangle_count) return 0;
    return phc_climbing_set_shadow_triangles(c, o->shadow_vertices, o->shadow_vertex_count,
                                             o->shadow_triangles, o->shadow_triangle_count, err);
}

/* Grows one plant with options po and seed, looks at it with a tracer at
 * every frame (fit/costs/shoot_tracer.h) and summarises the traced plant
 * at each observation time j < nt into s[j], the same way as the traces
 * themselves.  0, 1 (outside the model's domain), -1 memory. */
static int grow_one(const st_impl *im, const phc_climbing_options *po, uint64_t seed, phc_climbing_summary *s)
{
    const phc_shoot_traces_options *o = &im->o;
    phc_climbing_options co = *po;
    co.seed = seed;
    phc_error e;
    phc_error_clear(&e);
    if (!(co.growth_rate * o->time_step < 1 - co.bud_fraction)) return 1;
    phc_climbing *c = phc_climbing_new(o->position, o->direction, &co, &e);
    if (!c) return e.status == PHC_ERR_NOMEM ? -1 : 1;
    if (cast_shadows(o, c, &e)) {
        phc_climbing_free(c);
        return e.status == PHC_ERR_NOMEM ? -1 : 1;
    }
    phc_shoot_tracer tracer;
    phc_shoot_tracer_init(&tracer);
    size_t done = 0;
    int rc = 0;
    for (size_t f = 0; f < im->n_frames && !rc; ++f) {
        for (; done < im->frame_steps[f] && !rc; ++done)
            if (phc_climbing_step(c, o->time_step, &e)) rc = e.status == PHC_ERR_NOMEM ? -1 : 1;
        if (!rc && phc_shoot_tracer_look(&tracer, c, im->frames[f], &e)) rc = -1;
    }
    phc_shoot_traces *traced = NULL;
    if (!rc && tracer.n && phc_shoot_tracer_traces(&tracer, "model", &traced, &e))
        rc = e.status == PHC_ERR_NOMEM ? -1 : 1;
    const phc_climbing_stat_options so = stat_options(o);
    for (size_t j = 0; j < im->n_times && !rc; ++j) {
        phc_shoot_segment *seg = NULL;
        size_t n = 0;
        if (traced && phc_shoot_traces_segments(traced, im->times[j], &seg, &n, &e)) rc = -1;
        else if (phc_climbing_summarize_segments(seg, n, &so, &s[j], &e)) rc = 1;
        free(seg);
    }
    phc_shoot_traces_free(traced);
    phc_shoot_tracer_clear(&tracer);
    phc_climbing_free(c);
    return rc;
}

/* Central differences of the K-seed means (raw, not whitened) at p, yhat the values at p. */
static int fd_jacobian(phc_dataset *ds, const double *p, const double *yhat, double *jac)
{
    st_impl *im = ds->impl;
    int rc = 0;
    const size_t k = ds->k, n = ds->n;
    double *q = malloc(k * sizeof *q), *yp = malloc(n * sizeof *yp), *ym = malloc(n * sizeof *ym);
    if (!q || !yp || !ym) { free(q); free(yp); free(ym); return -1; }
    for (size_t j = 0; j < k && !rc; ++j) {
        double scale = fabs(p[j]) > 0 ? fabs(p[j]) : 1;
        if (ds->problem && ds->param_index) {
            const phc_parameter *pa = &ds->problem->params[ds->param_index[j]];
            if (pa->scale > 0 && !(fabs(p[j]) > 0)) scale = pa->scale;
        }
        const double h = im->o.fd_step * scale;
        memcpy(q, p, k * sizeof *q);
        q[j] = p[j] + h;
        const int rp = phc_shoot_traces_model(ds, q, yp, NULL);
        q[j] = p[j] - h;
        const int rm = phc_shoot_traces_model(ds, q, ym, NULL);
        if (rp < 0 || rm < 0) { rc = -1; break; }
        for (size_t i = 0; i < n; ++i) {
            if (!rp && !rm) jac[i * k + j] = (yp[i] - ym[i]) / (2 * h);
            else if (!rp) jac[i * k + j] = (yp[i] - yhat[i]) / h;
            else if (!rm) jac[i * k + j] = (yhat[i] - ym[i]) / h;
            else jac[i * k + j] = 0;
        }
        if (rp && rm) rc = 1;
    }
    free(q);
    free(yp);
    free(ym);
    return rc;
}

/* Grows `count` plants (seeds first .. first + count - 1) at slot values p:
 * y (n) the statistics of their mean (angles pooled), per (count x n, or
 * NULL) each plant's own (NAN for an angle of a plant without laterals).
 * 0, 1 (outside the model's domain, or no lateral at all for an angle), -1. */
static int model_seeds(phc_dataset *ds, const double *p, uint64_t first, size_t count, double *y, double *per)
{
    st_impl *im = ds->impl;
    const size_t nt = im->n_times;
    phc_climbing_options po = im->o.plant;
    for (size_t j = 0; j < im->k; ++j) *slot_ref(&po, im->slot[j]) = p[j];
    phc_climbing_summary *s = malloc(count * nt * sizeof *s), *one = malloc(count * sizeof *one), mean;
    if (!s || !one) { free(s); free(one); return -1; }
    int rc = 0;
    for (size_t a = 0; a < count && !rc; ++a) {
        rc = grow_one(im, &po, first + a, s + a * nt);
        im->plants++;
    }
    for (size_t i = 0; !rc && i < ds->n; ++i) {
        const size_t j = im->tindex[i];
        for (size_t a = 0; a < count; ++a) one[a] = s[a * nt + j];
        phc_climbing_summary_mean(one, count, &mean);
        y[i] = stat_value(&mean, im->stat[i]);
        if (!isfinite(y[i])) rc = 1; /* no lateral at all: no angle */
        for (size_t a = 0; per && a < count; ++a) per[a * ds->n + i] = stat_value(&one[a], im->stat[i]);
    }
    free(s);
    free(one);
    return rc;
}

/* Averages over the K seeds at slot values p: y (n) and sd (n or NULL). */
int phc_shoot_traces_model(phc_dataset *ds, const double *p, double *y, double *sd)
{
    st_impl *im = ds->impl;
    const size_t K = im->o.seeds, n = ds->n;
    double *per = sd ? malloc(K * n * sizeof *per) : NULL;
    if (sd && !per) return -1;
    const int rc = model_seeds(ds, p, im->o.first_seed, K, y, per);
    for (size_t i = 0; sd && !rc && i < n; ++i) {
        double m = 0, v = 0;
        size_t q = 0;
        for (size_t a = 0; a < K; ++a)
            if (isfinite(per[a * n + i])) { m += per[a * n + i]; q++; }
        m /= (double)(q ? q : 1);
        for (size_t a = 0; a < K; ++a)
            if (isfinite(per[a * n + i])) v += (per[a * n + i] - m) * (per[a * n + i] - m);
        sd[i] = q > 1 ? sqrt(v / (double)(q - 1)) : NAN;
    }
    free(per);
    return rc;
}

/* v <- L^-1 v (L lower triangular, n x n row-major; v with stride). */
static void whiten(const double *L, size_t n, double *v, size_t stride)
{
    for (size_t i = 0; i < n; ++i) {
        double x = v[i * stride];
        for (size_t l = 0; l < i; ++l) x -= L[i * n + l] * v[l * stride];
        v[i * stride] = x / L[i * n + i];
    }
}

int phc_shoot_traces_model_jacobian(phc_dataset *ds, const double *p, double *y, double *jac)
{
    const int rc = phc_shoot_traces_model(ds, p, y, NULL);
    return rc || !jac ? rc : fd_jacobian(ds, p, y, jac);
}

const double *phc_shoot_traces_traced(const phc_dataset *ds) { return ((const st_impl *)ds->impl)->y_raw; }

static int st_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    st_impl *im = ds->impl;
    const int rc = phc_shoot_traces_model_jacobian(ds, p, yhat, jac);
    if (rc) return rc;
    /* the engine sees L^-1 (traced - model), L L^T the statistics' covariance */
    whiten(im->L, ds->n, yhat, 1);
    for (size_t j = 0; jac && j < ds->k; ++j) whiten(im->L, ds->n, jac + j, ds->k);
    return 0;
}

int phc_shoot_traces_identifiability(phc_dataset *ds, const double *p, phc_shoot_traces_ident *out, phc_error *err)
{
    const size_t k = ds->k, n = ds->n;
    memset(out, 0, sizeof *out);
    double *y = malloc(n * sizeof *y), *J = malloc(n * k * sizeof *J), *A = calloc(k * k, sizeof *A),
           *w = malloc(k * sizeof *w), *V = malloc(k * k * sizeof *V);
    int rc = PHC_OK;
    if (!y || !J || !A || !w || !V) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    int r = st_predict(ds, p, y, J);
    if (r) {
        rc = phc_error_set(err, r < 0 ? PHC_ERR_NOMEM : PHC_ERR_DOMAIN,
                           "data set '%s': the model failed at the fitted values", ds->name);
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        const double s = ds->sigma ? ds->sigma[i] : 1;
        for (size_t j = 0; j < k; ++j) J[i * k + j] /= s;
    }
    for (size_t a = 0; a < k; ++a)
        for (size_t b = 0; b < k; ++b) {
            double sum = 0;
            for (size_t i = 0; i < n; ++i) sum += J[i * k + a] * J[i * k + b];
            A[a * k + b] = sum;
        }
    for (size_t a = 0; a < k && a < PHC_SHOOT_TRACES_MAX_SLOTS; ++a) {
        out->sensitivity[a] = sqrt(A[a * k + a]);
        out->value[a] = p[a];
    }
    /* correlations from the normal matrix: the largest |corr| of each slot with another */
    /* eigenvalues of J'J as the squared singular values of J (one-sided
     * Jacobi, model/jacobi_svd.h: no squaring of the condition number) */
    double *C = malloc(n * k * sizeof *C);
    if (!C) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto done; }
    memcpy(C, J, n * k * sizeof *C);
    if (phc_jacobi_svd(C, n, k, w, V)) {
        free(C);
        rc = phc_error_set(err, PHC_ERR_DOMAIN, "data set '%s': the sensitivities' decomposition did not converge",
                           ds->name);
        goto done;
    }
    for (size_t a = 0; a < k; ++a)
        w[a] *= w[a];
    double wmax = 0;
    for (size_t a = 0; a < k; ++a) wmax = fmax(wmax, w[a]);
    out->rank = 0;
    for (size_t a = 0; a < k; ++a)
        if (w[a] > 1e-8 * wmax && w[a] > 0) out->rank++;
    out->condition = 0;
    double wmin = INFINITY;
    for (size_t a = 0; a < k; ++a) wmin = fmin(wmin, w[a]);
    out->condition = wmin > 0 ? wmax / wmin : INFINITY;
    /* covariance = pseudo-inverse over the kept eigenvalues */
    for (size_t a = 0; a < k && a < PHC_SHOOT_TRACES_MAX_SLOTS; ++a) {
        double var = 0;
        int null_part = 0;
        for (size_t e = 0; e < k; ++e) {
            if (w[e] > 1e-8 * wmax && w[e] > 0) var += V[a * k + e] * V[a * k + e] / w[e];
            else if (fabs(V[a * k + e]) > 0.1) null_part = 1;
        }
        out->sd[a] = null_part ? INFINITY : sqrt(var);
        out->partner[a] = (size_t)-1;
        out->max_corr[a] = 0;
    }
    free(C);
    /* the correlation of the slots' estimates, from the inverse when full rank, else of
     * the sensitivities' columns (cosine of J's columns) */
    for (size_t a = 0; a < k && a < PHC_SHOOT_TRACES_MAX_SLOTS; ++a)
        for (size_t b = 0; b < k; ++b) {
            if (a == b) continue;
            const double d = sqrt(A[a * k + a] * A[b * k + b]);
            const double c = d > 0 ? A[a * k + b] / d : 0;
            if (fabs(c) > fabs(out->max_corr[a])) {
                out->max_corr[a] = c;
                out->partner[a] = b;
            }
        }
done:
    free(y);
    free(J);
    free(A);
    free(w);
    free(V);
    return rc;
}

/* Verdicts: yes when the slot moves the statistics, is not in a null
 * direction, its column is not nearly parallel (|cos| > 0.95) to another's
 * and its 95% interval (± 1.96 sd) is narrower than ± its value. */
static void ident_verdicts(const phc_dataset *ds, phc_shoot_traces_ident *id)
{
    double smax = 0;
    for (size_t a = 0; a < ds->k; ++a) smax = fmax(smax, id->sensitivity[a] * fmax(fabs(id->value[a]), 1e-12));
    for (size_t a = 0; a < ds->k && a < PHC_SHOOT_TRACES_MAX_SLOTS; ++a) {
        id->identifiable[a] = 0;
        if (!(id->sensitivity[a] > 0) || id->sensitivity[a] * fmax(fabs(id->value[a]), 1e-12) < 1e-6 * smax)
            snprintf(id->why[a], sizeof id->why[a], "the statistics do not change with it");
        else if (!isfinite(id->sd[a]))
            snprintf(id->why[a], sizeof id->why[a], "in a null direction (rank %zu of %zu)", id->rank, ds->k);
        else if (fabs(id->max_corr[a]) > 0.95 && id->partner[a] != (size_t)-1)
            snprintf(id->why[a], sizeof id->why[a], "collinear with %s (cosine %.3f)",
                     ds->slot_names[id->partner[a]], id->max_corr[a]);
        else if (1.96 * id->sd[a] >= fabs(id->value[a]))
            snprintf(id->why[a], sizeof id->why[a], "95%% interval wider than +/- its value");
        else {
            id->identifiable[a] = 1;
            snprintf(id->why[a], sizeof id->why[a], "interval +/- %.0f%% of its value",
                     100 * 1.96 * id->sd[a] / fabs(id->value[a]));
        }
    }
}

static int st_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    st_impl *im = ds->impl;
    const unsigned long before = im->plants;
    const size_t n = ds->n;
    double *y = malloc(n * sizeof *y), *sd = malloc(n * sizeof *sd);
    if (!y || !sd) { free(y); free(sd); return phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); }
    int r = phc_shoot_traces_model(ds, p, y, sd);
    if (r) {
        free(y); free(sd);
        return phc_error_set(err, r < 0 ? PHC_ERR_NOMEM : PHC_ERR_DOMAIN,
                             "data set '%s': the model failed at the fitted values", ds->name);
    }
    phc_shoot_traces_ident id;
    int rc = phc_shoot_traces_identifiability(ds, p, &id, err);
    if (rc) { free(y); free(sd); return rc; }
    ident_verdicts(ds, &id);
    char *out = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    if (!f) { free(y); free(sd); return phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); }
    fprintf(f, "Traces: `%s`, %zu shoots, %zu points, up to %g s.\n\n", im->traces->source,
            im->traces->n_shoots, im->traces->n_points, im->traces->t_end);
    fprintf(f, "Model: the climbing plant (Hädrich et al. 2017) grown with %zu seeds (%llu .. %llu, the same "
               "at every parameter value) in steps of %g s, traced at %zu frames like the traces; statistics "
               "averaged over the seeds. Residuals weighted by the statistics' covariance between %zu model "
               "plants (correlations times %g; sigma below is the square root of its diagonal). "
               "Derivatives: central differences, step %g of each value. %lu plants grown before this "
               "report.\n\n",
            im->o.seeds, (unsigned long long)im->o.first_seed,
            (unsigned long long)(im->o.first_seed + im->o.seeds - 1), im->o.time_step, im->n_frames,
            im->o.covariance_seeds > im->o.seeds ? im->o.covariance_seeds : im->o.seeds, im->o.correlation,
            im->o.fd_step, before);
    if (im->o.covariance_at_fitted)
        fprintf(f, "Covariance at the fitted values (`covariance_at: fitted`): recomputed %zu time%s, then the "
                   "estimates moved by at most %.3g (relative) from the values of the last covariance: %s.\n\n",
                im->rounds, im->rounds == 1 ? "" : "s", im->change,
                im->settled ? "settled within covariance_tolerance"
                            : "stopped at covariance_rounds, NOT settled within covariance_tolerance");
    else
        fprintf(f, "Covariance at the start values (`covariance_at: start`).\n\n");
    fprintf(f, "| time (s) | statistic | traced | model (mean of seeds) | seed sd | sigma |\n"
               "|---:|---|---:|---:|---:|---:|\n");
    for (size_t i = 0; i < n; ++i)
        fprintf(f, "| %g | %s | %.4g | %.4g | %.3g | %.3g |\n", im->times[im->tindex[i]], stat_names[im->stat[i]],
                im->y_raw[i], y[i], sd[i], im->sigma_total[i]);
    fprintf(f, "\nIdentifiability from the statistics (this data set's Jacobian at the fitted values, "
               "the data set's sigma, not rescaled by the fit's residual variance): rank %zu of %zu, condition number %.3g.\n\n",
            id.rank, ds->k, id.condition);
    fprintf(f, "| parameter | estimate | 95%% interval | sensitivity | most collinear with | identifiable | why |\n"
               "|---|---:|---|---:|---|---|---|\n");
    for (size_t a = 0; a < ds->k && a < PHC_SHOOT_TRACES_MAX_SLOTS; ++a) {
        char iv[64], co[96];
        if (isfinite(id.sd[a]))
            snprintf(iv, sizeof iv, "[%.4g, %.4g]", p[a] - 1.96 * id.sd[a], p[a] + 1.96 * id.sd[a]);
        else
            snprintf(iv, sizeof iv, "unbounded");
        if (id.partner[a] != (size_t)-1)
            snprintf(co, sizeof co, "%s (%.3f)", ds->slot_names[id.partner[a]], id.max_corr[a]);
        else
            snprintf(co, sizeof co, "-");
        fprintf(f, "| %s | %.4g | %s | %.3g | %s | %s | %s |\n", ds->slot_names[a], p[a], iv, id.sensitivity[a], co,
                id.identifiable[a] ? "yes" : "no", id.why[a]);
    }
    /* (the measured coverage: notebooks_c/shoot_traces_coverage.c, README
       "Fitting growth to traced shoots", "Coverage") */
    fprintf(f, "\nHow far to trust these intervals: they are linearised, from central differences of "
               "statistics averaged over the same seeds at every parameter value, and for this kind of fit "
               "they are optimistic. In phytocal's coverage study (notebook shoot_traces_coverage: model "
               "plants with known parameters, each fitted like this) about 4 in 5 of the 95%% intervals "
               "covered the truth, not 19 in 20: the cost is rugged, and there the estimates of "
               "branch_probability, phototropism and surface_adaption scattered about twice as far as "
               "their standard errors said (growth_rate's and direction_variance's did not). Read an "
               "estimate's distance from a value of interest, in standard errors, as up to twice the "
               "evidence there is.\n");
    fputc('\n', f);
    fclose(f);
    free(y);
    free(sd);
    *markdown = out;
    return PHC_OK;
}

static void st_series_name(const phc_dataset *ds, size_t g, char *buf, size_t size)
{
    (void)ds;
    snprintf(buf, size, "%s", g < ST_N ? stat_names[g] : "?");
}

static int st_name_series2(phc_dataset *ds, phc_error *err)
{
    return phc_dataset_name_series(ds, "statistic", ST_N, st_series_name, err);
}

/* The magnitude a change of slot j is measured against: |value|, or the
 * problem's scale of the parameter when the value is 0 (as fd_jacobian). */
static double slot_scale(const phc_dataset *ds, const double *p, size_t j)
{
    if (fabs(p[j]) > 0) return fabs(p[j]);
    if (ds->problem && ds->param_index && ds->problem->params[ds->param_index[j]].scale > 0)
        return ds->problem->params[ds->param_index[j]].scale;
    return 1;
}

/* covariance_at: fitted.  Σ depends on the values it is computed at
 * (Wood 2010 recomputes it at every proposal); the fit makes Σ(θ̂) and θ̂
 * agree by fixed-point rounds: Σ at the fitted values, solve again, until
 * the estimates move by at most covariance_tolerance (relative) from the
 * values of the last Σ, or covariance_rounds recomputations. */
static int st_reweight(phc_dataset *ds, const double *p, int *again, phc_error *err)
{
    st_impl *im = ds->impl;
    *again = 0;
    if (!im->o.covariance_at_fitted) return PHC_OK;
    double change = 0;
    for (size_t j = 0; j < ds->k; ++j)
        change = fmax(change, fabs(p[j] - im->sigma_at[j]) / slot_scale(ds, im->sigma_at, j));
    im->change = change;
    im->settled = change <= im->o.covariance_tolerance;
    if (im->settled || im->rounds >= im->o.covariance_rounds) return PHC_OK;
    phc_error e;
    phc_error_clear(&e);
    const int rc = phc_shoot_traces_covariance_at(ds, p, &e);
    if (rc == PHC_ERR_NOMEM) return phc_error_set(err, rc, "%s", e.message);
    if (rc) return PHC_OK; /* not growable at p: Σ stays where it was, the rounds stop */
    im->rounds++;
    *again = 1;
    return PHC_OK;
}

void phc_shoot_traces_covariance_rounds(const phc_dataset *ds, size_t *rounds, double *change, int *settled)
{
    const st_impl *im = ds->impl;
    if (rounds) *rounds = im->rounds;
    if (change) *change = im->change;
    if (settled) *settled = im->settled;
}

const phc_dataset_ops phc_shoot_traces_ops = {
    .kind = "shoot_traces",
    .predict = st_predict,
    .free_impl = st_free,
    .report_section = st_report_section,
    .name_series = st_name_series2,
    .reweight = st_reweight,
};

static double sigma_for(const phc_shoot_traces_options *o, int stat, double v)
{
    switch (stat) {
    case ST_TOTAL: case ST_MAIN: case ST_HEIGHT: return fmax(o->sigma_rel * fabs(v), o->sigma_length);
    case ST_ATTACHED: return o->sigma_fraction;
    case ST_COSINE: return o->sigma_cosine;
    case ST_ANGLE_MEAN: case ST_ANGLE_SD: return o->sigma_angle;
    default: return sqrt(fmax(1, v));
    }
}

/* The frames at which the tracer looks at a model plant: multiples of
 * frame_interval, or else the distinct point times of the traces, in
 * (0, last observation time] (at time 0 the model plant is its seed, whose
 * base the first frame records). */
static int make_frames(st_impl *im, phc_error *err)
{
    const double last = im->times[im->n_times - 1], dt = im->o.frame_interval;
    double *f = NULL;
    size_t m = 0;
    if (dt > 0) {
        const size_t cap = (size_t)floor(last / dt * (1 + 1e-12)) + 1;
        if (!(f = malloc(cap * sizeof *f))) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t q = 1; q < cap + 1 && (double)q * dt <= last * (1 + 1e-12); ++q) f[m++] = (double)q * dt;
    } else {
        double *u = NULL;
        size_t nu = 0, *at = NULL;
        int rc = phc_unique_times(im->traces->t, im->traces->n_points, &u, &nu, &at, err);
        if (rc) return rc;
        free(at);
        f = u;
        for (size_t q = 0; q < nu; ++q)
            if (u[q] > 0 && u[q] <= last) f[m++] = u[q];
    }
    im->frames = f;
    im->n_frames = m;
    if (!(im->frame_steps = malloc((m ? m : 1) * sizeof *im->frame_steps)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t q = 0; q < m; ++q) im->frame_steps[q] = (size_t)llround(f[q] / im->o.time_step);
    return PHC_OK;
}

int phc_shoot_traces_covariance_at(phc_dataset *ds, const double *p, phc_error *err)
{
    st_impl *im = ds->impl;
    const size_t n = ds->n, K = im->o.seeds;
    const size_t M = im->o.covariance_seeds > K ? im->o.covariance_seeds : K;
    double *y = malloc(n * sizeof *y), *per = malloc(M * n * sizeof *per), *S = calloc(n * n, sizeof *S),
           *L = calloc(n * n, sizeof *L);
    if (!y || !per || !S || !L) {
        free(y); free(per); free(S); free(L);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    const int r = model_seeds(ds, p, im->o.first_seed, M, y, per);
    if (r) {
        free(y); free(per); free(S); free(L);
        return phc_error_set(err, r < 0 ? PHC_ERR_NOMEM : PHC_ERR_DOMAIN,
                             "shoot_traces: the model plant cannot be grown at these values (sigma unchanged)");
    }
    /* deviations of each plant from the plants' mean; an angle a plant has not (no lateral) deviates by 0 */
    for (size_t i = 0; i < n; ++i) {
        double m = 0;
        size_t q = 0;
        for (size_t a = 0; a < M; ++a)
            if (isfinite(per[a * n + i])) { m += per[a * n + i]; q++; }
        m /= (double)(q ? q : 1);
        for (size_t a = 0; a < M; ++a) per[a * n + i] = isfinite(per[a * n + i]) ? per[a * n + i] - m : 0;
    }
    /* Sigma = diag(sigma_given^2) + (1 + 1/K) C_g: the traced plant is one draw (C, the plants'
     * covariance, estimated from M plants) and the model value a mean of K (C/K); C_g keeps C's
     * diagonal and g (correlation) times its off-diagonal part: the correlations shrunk toward 0
     * (Warton, JASA 103, 2008: ridge regularisation of a correlation matrix), g = 0 independent
     * sigmas, g = 1 Wood's (Nature 466, 2010) synthetic-likelihood covariance as estimated. */
    const int full = im->o.correlation > 0;
    for (size_t i = 0; i < n; ++i)
        for (size_t l = 0; l <= i; ++l) {
            if (!full && l != i) continue;
            double c = 0;
            for (size_t a = 0; a < M; ++a) c += per[a * n + i] * per[a * n + l];
            c *= (1 + 1.0 / (double)K) / (double)(M > 1 ? M - 1 : 1);
            if (l != i) c *= im->o.correlation; /* shrunk toward the diagonal (Warton 2008) */
            if (l == i) c += im->sigma_given[i] * im->sigma_given[i];
            S[i * n + l] = S[l * n + i] = c;
        }
    /* Cholesky S = L L^T (S is positive definite: sigma_given > 0 on its diagonal) */
    int ok = 1;
    for (size_t i = 0; i < n && ok; ++i)
        for (size_t l = 0; l <= i && ok; ++l) {
            double v = S[i * n + l];
            for (size_t q = 0; q < l; ++q) v -= L[i * n + q] * L[l * n + q];
            if (l == i) {
                if (!(v > 0)) ok = 0;
                else L[i * n + i] = sqrt(v);
            } else {
                L[i * n + l] = v / L[l * n + l];
            }
        }
    if (ok) {
        free(im->L);
        im->L = L;
        L = NULL;
        memcpy(im->sigma_at, p, ds->k * sizeof *p);
        for (size_t i = 0; i < n; ++i) {
            im->sigma_total[i] = sqrt(S[i * n + i]);
            ds->y[i] = im->y_raw[i];
            ds->sigma[i] = 1;
        }
        whiten(im->L, n, ds->y, 1);
    }
    free(y); free(per); free(S); free(L);
    if (!ok) return phc_error_set(err, PHC_ERR_DOMAIN, "shoot_traces: the statistics' covariance is not positive definite");
    return PHC_OK;
}

int phc_shoot_traces_new(phc_shoot_traces *traces, const phc_shoot_traces_options *o, phc_dataset **out,
                         phc_error *err)
{
    *out = NULL;
    st_impl *im = calloc(1, sizeof *im);
    phc_dataset *ds = NULL;
    phc_shoot_segment *seg = NULL;
    int rc = PHC_OK;
    if (!im) {
        phc_shoot_traces_free(traces);
        if (o->support_free) o->support_free(o->support_owner);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    im->traces = traces;
    im->o = *o;
    if (!(o->seeds >= 1) || !(o->time_step > 0) || !(o->fd_step > 0 && o->fd_step < 1) || !(o->frame_interval >= 0) || o->covariance_seeds > 100000 || !(o->correlation >= 0 && o->correlation <= 1) || !(o->covariance_rounds >= 1) || !(o->covariance_tolerance > 0) || !(o->sigma_rel >= 0) ||
        !(o->sigma_length > 0) || !(o->sigma_fraction > 0) || !(o->sigma_cosine > 0) || !(o->sigma_angle > 0)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "shoot_traces: seeds must be >= 1, time_step > 0, fd_step in (0, 1), frame_interval >= 0, covariance_seeds <= 1e5, correlation in [0, 1], covariance_rounds >= 1, covariance_tolerance > 0 and "
                           "every sigma > 0");
        goto fail;
    }
    /* times */
    im->n_times = o->times ? o->n_times : 4;
    im->times = malloc(im->n_times * sizeof *im->times);
    if (!im->times) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto fail; }
    for (size_t j = 0; j < im->n_times; ++j) {
        im->times[j] = o->times ? o->times[j] : traces->t_end * (double)(j + 1) / 4.0;
        if (!(im->times[j] > 0) || (j && !(im->times[j] > im->times[j - 1])) ||
            im->times[j] > traces->t_end * (1 + 1e-12)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "shoot_traces: observation time %g s: times must be > 0, increasing and at most "
                               "the traces' last time (%g s)",
                               im->times[j], traces->t_end);
            goto fail;
        }
    }
    if ((rc = make_frames(im, err))) goto fail;
    /* slots */
    for (size_t s = 0; s < N_SLOTS; ++s)
        if (o->is_parameter ? o->is_parameter(slot_names[s], o->user_data) : s == 0) im->slot[im->k++] = s;
    if (!im->k) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "shoot_traces: no parameter to fit: name one of branch_probability, direction_variance, "
                           "phototropism, surface_adaption, growth_rate, apical_dominance, thickness_falloff, "
                           "min_stiffness, anchor_strength");
        goto fail;
    }
    /* the traced statistics */
    const phc_climbing_stat_options so = stat_options(o);
    phc_climbing_summary *ts = calloc(im->n_times, sizeof *ts);
    if (!ts) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto fail; }
    for (size_t j = 0; j < im->n_times && !rc; ++j) {
        size_t ns = 0;
        free(seg);
        seg = NULL;
        if (!(rc = phc_shoot_traces_segments(traces, im->times[j], &seg, &ns, err)))
            rc = phc_climbing_summarize_segments(seg, ns, &so, &ts[j], err);
    }
    if (rc) { free(ts); goto fail; }
    unsigned max_order = o->plant.max_order < 7 ? o->plant.max_order : 7;
    const phc_climbing_summary *last = &ts[im->n_times - 1];
    const int angles = last->angle_n >= 2;
    const size_t n = 5 * im->n_times + max_order + (angles ? 2 : 0);
    im->stat = malloc(n * sizeof *im->stat);
    im->tindex = malloc(n * sizeof *im->tindex);
    if (!im->stat || !im->tindex || !(ds = phc_dataset_new(&phc_shoot_traces_ops, im->k))) {
        free(ts);
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->impl = im;
    ds->n = n;
    ds->x = malloc(n * sizeof *ds->x);
    ds->y = malloc(n * sizeof *ds->y);
    ds->sigma = malloc(n * sizeof *ds->sigma);
    ds->series = malloc(n * sizeof *ds->series);
    if (!ds->x || !ds->y || !ds->sigma || !ds->series) {
        free(ts);
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail_ds;
    }
    size_t i = 0;
    for (size_t j = 0; j < im->n_times; ++j)
        for (int s = ST_TOTAL; s <= ST_COSINE; ++s) {
            im->stat[i] = s;
            im->tindex[i++] = j;
        }
    for (unsigned q = 1; q <= max_order; ++q) {
        im->stat[i] = ST_COUNT1 + (int)q - 1;
        im->tindex[i++] = im->n_times - 1;
    }
    if (angles) {
        im->stat[i] = ST_ANGLE_MEAN;
        im->tindex[i++] = im->n_times - 1;
        im->stat[i] = ST_ANGLE_SD;
        im->tindex[i++] = im->n_times - 1;
    }
    for (i = 0; i < n; ++i) {
        ds->x[i] = im->times[im->tindex[i]];
        ds->y[i] = stat_value(&ts[im->tindex[i]], im->stat[i]);
        ds->sigma[i] = sigma_for(o, im->stat[i], ds->y[i]);
        ds->series[i] = (size_t)im->stat[i];
    }
    free(ts);
    free(seg);
    for (size_t j = 0; j < im->k; ++j) {
        if (!(ds->slot_names[j] = strdup(slot_names[im->slot[j]]))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail_ds;
        }
        if ((rc = phc_dataset_declare_unit(ds, slot_names[im->slot[j]], slot_units[im->slot[j]]))) {
            rc = phc_error_set(err, rc, "out of memory");
            goto fail_ds;
        }
    }
    /* the traced plant is one draw of the process and the model value a mean over K: the
     * statistics' covariance at the start options widens sigma and couples the statistics */
    im->sigma_given = malloc(n * sizeof *im->sigma_given);
    im->sigma_total = malloc(n * sizeof *im->sigma_total);
    im->y_raw = malloc(n * sizeof *im->y_raw);
    im->sigma_at = malloc(im->k * sizeof *im->sigma_at);
    im->change = NAN;
    if (!im->sigma_given || !im->sigma_total || !im->y_raw || !im->sigma_at) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail_ds;
    }
    memcpy(im->sigma_given, ds->sigma, n * sizeof *ds->sigma);
    memcpy(im->y_raw, ds->y, n * sizeof *ds->y);
    {
        double *p0 = malloc(im->k * sizeof *p0);
        if (!p0) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto fail_ds; }
        for (size_t j = 0; j < im->k; ++j) p0[j] = *slot_ref(&im->o.plant, im->slot[j]);
        rc = phc_shoot_traces_covariance_at(ds, p0, err);
        free(p0);
        if (rc) {
            if (rc != PHC_ERR_NOMEM)
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "shoot_traces: the model plant cannot be grown at the start options (or it "
                                   "makes no lateral while the traces have some)");
            goto fail_ds;
        }
        im->plants = 0;
    }
    ds->x_label = strdup("time (s)");
    ds->y_label = strdup("whitened statistic L^-1 y (1)");
    ds->derivatives = PHC_DERIV_ANALYTIC;
    ds->model_tolerance = 1e-3;
    if (!ds->x_label || !ds->y_label || (rc = phc_dataset_add_input(ds, traces->source))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail_ds;
    }
    *out = ds;
    return PHC_OK;
fail_ds:
    phc_dataset_free(ds); /* frees im */
    return rc;
fail:
    free(seg);
    st_free(im);
    return rc;
}

int phc_shoot_traces_from_model(const phc_shoot_traces_options *o, const double *times, size_t n_times,
                                phc_shoot_traces **out, phc_error *err)
{
    *out = NULL;
    phc_climbing *c = phc_climbing_new(o->position, o->direction, &o->plant, err);
    if (!c) return err ? err->status : PHC_ERR_INVALID;
    if (cast_shadows(o, c, err)) {
        phc_climbing_free(c);
        return err ? err->status : PHC_ERR_INVALID;
    }
    phc_shoot_tracer tracer;
    phc_shoot_tracer_init(&tracer);
    size_t done = 0;
    int rc = PHC_OK;
    for (size_t j = 0; j < n_times && !rc; ++j) {
        const size_t steps = (size_t)llround(times[j] / o->time_step);
        for (; done < steps && !rc; ++done) rc = phc_climbing_step(c, o->time_step, err);
        if (!rc) rc = phc_shoot_tracer_look(&tracer, c, times[j], err);
    }
    if (!rc) rc = phc_shoot_tracer_traces(&tracer, "model traces", out, err);
    phc_shoot_tracer_clear(&tracer);
    phc_climbing_free(c);
    return rc;
}
