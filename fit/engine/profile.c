/* Profile likelihood (profile.h): trace each free parameter's profile cost
 * with Ceres re-optimising the others, and find where it crosses the
 * likelihood-ratio threshold. */
#include "fit/engine/profile.h"

#include <gsl/gsl_cdf.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fit/engine/ceres_bridge.h"
#include "fit/engine/dataset.h"
#include "fit/study_dist.h"

phc_profile_options phc_profile_options_default(void)
{
    phc_profile_options o;
    memset(&o, 0, sizeof o);
    o.level = 0.95;
    o.points = 12;
    o.max_steps = 0;
    o.flat_fraction = 0.01;
    return o;
}

double phc_profile_threshold(double level, int absolute_sigma, double best_cost, size_t n_obs, size_t n_free)
{
    if (!(level > 0.0 && level < 1.0))
        return NAN;
    if (absolute_sigma)
        return 0.5 * gsl_cdf_chisq_Pinv(level, 1.0); /* chi^2 = 2 cost */
    if (n_obs <= n_free)
        return NAN;
    const double dof = (double)(n_obs - n_free);
    return best_cost * gsl_cdf_fdist_Pinv(level, 1.0, dof) / dof;
}

/* ---- one growing profile ---------------------------------------------------------------- */

typedef struct point_list {
    size_t n, cap, np;
    double *theta, *delta, *x;
} point_list;

static int push_point(point_list *l, double theta, double delta, const double *x)
{
    if (l->n == l->cap) {
        const size_t cap = l->cap ? 2 * l->cap : 32;
        double *t = realloc(l->theta, cap * sizeof *t);
        if (!t)
            return PHC_ERR_NOMEM;
        l->theta = t;
        double *d = realloc(l->delta, cap * sizeof *d);
        if (!d)
            return PHC_ERR_NOMEM;
        l->delta = d;
        double *xx = realloc(l->x, cap * l->np * sizeof *xx);
        if (!xx)
            return PHC_ERR_NOMEM;
        l->x = xx;
        l->cap = cap;
    }
    l->theta[l->n] = theta;
    l->delta[l->n] = delta;
    memcpy(l->x + l->n * l->np, x, l->np * sizeof *x);
    ++l->n;
    return PHC_OK;
}

/* The problem's residual blocks with parameter `fixed_j` (SIZE_MAX: none)
 * held fixed on top of the configured fixed ones. */
static int build_nls(phc_problem *pb, size_t fixed_j, phc_nls **out, phc_error *err)
{
    phc_nls *nls = phc_nls_new(pb->n_params);
    int rc = PHC_OK;
    if (!nls)
        return phc_nls_new_error("profile", err);
    for (size_t i = 0; i < pb->n_params && rc == PHC_OK; ++i) {
        const phc_parameter *p = &pb->params[i];
        rc = phc_nls_set_parameter(nls, i, p->lower, p->upper, p->fixed || i == fixed_j, phc_problem_scale(pb, i),
                                   err);
    }
    for (size_t d = 0; d < pb->n_datasets && rc == PHC_OK; ++d) {
        phc_dataset *ds = pb->datasets[d];
        rc = phc_nls_add_block(nls, ds->n, ds->param_index, ds->k, phc_dataset_residuals, ds->derivatives, ds->loss,
                               ds->loss_scale, ds, err);
    }
    if (rc) {
        phc_nls_free(nls);
        return rc;
    }
    *out = nls;
    return PHC_OK;
}

typedef struct tracer {
    phc_problem *pb;
    phc_nls *nls;
    const phc_profile_options *opt;
    phc_nls_options nls_opt;
    size_t j, k, n_free;      /* parameter, its number among the free ones */
    double best_cost, thr;
    point_list *pts;
    phc_profile *prof;
    double *x;                /* scratch, n_params */
} tracer;

/* Inner fit at theta from the warm start x0; on success *delta and tr->x. */
static int inner_fit(tracer *tr, double theta, const double *x0, double *delta)
{
    const size_t np = tr->pb->n_params;
    memcpy(tr->x, x0, np * sizeof *x0);
    tr->x[tr->j] = theta;
    phc_nls_summary sum;
    phc_error e;
    phc_error_clear(&e);
    ++tr->prof->inner_fits;
    const int rc = phc_nls_solve(tr->nls, &tr->nls_opt, tr->x, &sum, &e);
    phc_progress_report(tr->opt->progress, tr->opt->progress_data, "profile", tr->k + 1, tr->n_free,
                        (int)tr->prof->inner_fits, rc == PHC_OK ? sum.final_cost : NAN,
                        tr->pb->params[tr->j].name);
    if (rc != PHC_OK || sum.outcome == PHC_NLS_FAILED || !isfinite(sum.final_cost)) {
        ++tr->prof->failed_fits;
        return -1;
    }
    *delta = sum.final_cost - tr->best_cost;
    if (*delta < tr->prof->min_delta)
        tr->prof->min_delta = *delta;
    return 0;
}

static double root_delta(double d) { return d > 0.0 ? sqrt(d) : 0.0; }

/* Regula falsi (Illinois) on g(theta) = sqrt(delta) - sqrt(thr) between a
 * (below) and b (at or above); returns the crossing. */
static double refine_crossing(tracer *tr, double a, double ga, const double *xa, double b, double gb, int *rc)
{
    const size_t np = tr->pb->n_params;
    double *xw = malloc(np * sizeof *xw);
    *rc = PHC_OK;
    if (!xw) {
        *rc = PHC_ERR_NOMEM;
        return NAN;
    }
    memcpy(xw, xa, np * sizeof *xw);
    const double tol = 1e-10 * sqrt(tr->thr);
    int side = 0;
    double t = b - gb * (b - a) / (gb - ga);
    for (int it = 0; it < 40; ++it) {
        t = b - gb * (b - a) / (gb - ga);
        if (!(fabs(b - a) > 1e-13 * (fabs(a) + fabs(b)) + 1e-300))
            break;
        double d;
        if (inner_fit(tr, t, xw, &d) != 0)
            break; /* keep the interpolated t */
        if ((*rc = push_point(tr->pts, t, d, tr->x)))
            break;
        const double g = root_delta(d) - sqrt(tr->thr);
        if (fabs(g) <= tol)
            break;
        if (g < 0.0) {
            a = t;
            ga = g;
            memcpy(xw, tr->x, np * sizeof *xw);
            if (side == -1)
                gb *= 0.5;
            side = -1;
        } else {
            b = t;
            gb = g;
            if (side == 1)
                ga *= 0.5;
            side = 1;
        }
    }
    free(xw);
    return t;
}

/* One side (dir = -1 or +1) from the optimum. */
static int trace_side(tracer *tr, const double *best, double h0, int dir, double *end, phc_profile_end *how)
{
    const size_t np = tr->pb->n_params;
    const phc_parameter *p = &tr->pb->params[tr->j];
    const double bound = dir > 0 ? p->upper : p->lower;
    const size_t max_steps = tr->opt->max_steps ? tr->opt->max_steps : 8 * tr->opt->points + 40;
    const double target = sqrt(tr->thr) / (double)tr->opt->points;
    double *xp = malloc(np * sizeof *xp);
    if (!xp)
        return PHC_ERR_NOMEM;
    memcpy(xp, best, np * sizeof *xp);
    double tp = best[tr->j], gp = 0.0, h = h0;
    const double reach_unit = fmax(fabs(best[tr->j]), phc_problem_scale(tr->pb, tr->j));
    int rc = PHC_OK;
    *how = PHC_PROFILE_OPEN;
    for (size_t step = 0; step < max_steps; ++step) {
        if (tp == bound) {
            *how = PHC_PROFILE_AT_BOUND;
            break;
        }
        const double tiny = 1e-12 * (fabs(tp) + phc_problem_scale(tr->pb, tr->j));
        if (!(h > tiny) || !isfinite(tp + dir * h))
            break; /* open: the step shrank to nothing or overflowed */
        if (fabs(tp - best[tr->j]) > PHC_PROFILE_MAX_REACH * reach_unit)
            break; /* open: far beyond any plausible interval */
        double t = tp + dir * h;
        if ((dir > 0 && t > bound) || (dir < 0 && t < bound))
            t = bound;
        double d;
        if (inner_fit(tr, t, xp, &d) != 0) {
            h *= 0.25;
            continue;
        }
        const double g = root_delta(d);
        const int crossed = d >= tr->thr;
        if (g - gp > 2.0 * target && h > 1e3 * tiny) {
            h *= 0.5; /* jumped: come back with a shorter step */
            continue;
        }
        if ((rc = push_point(tr->pts, t, d, tr->x)))
            break;
        if (crossed) {
            tp = refine_crossing(tr, tp, gp - sqrt(tr->thr), xp, t, g - sqrt(tr->thr), &rc);
            *how = PHC_PROFILE_CROSSED;
            break;
        }
        memcpy(xp, tr->x, np * sizeof *xp);
        tp = t;
        if (g - gp < 0.5 * target)
            h *= 2.0;
        else if (g - gp > 1.5 * target)
            h *= 0.7;
        gp = g;
    }
    if (*how != PHC_PROFILE_CROSSED && tp == bound)
        *how = PHC_PROFILE_AT_BOUND;
    *end = tp;
    free(xp);
    return rc;
}


typedef struct sort_item {
    double theta, delta;
    size_t idx;
} sort_item;

static int sort_item_cmp(const void *a, const void *b)
{
    const sort_item *x = a, *y = b;
    return (x->theta > y->theta) - (x->theta < y->theta);
}

/* Moves the points into prof, sorted by theta. */
static int store_points(const point_list *l, phc_profile *prof)
{
    const size_t n = l->n, np = l->np;
    sort_item *it = malloc(n * sizeof *it);
    prof->theta = malloc(n * sizeof *prof->theta);
    prof->delta = malloc(n * sizeof *prof->delta);
    prof->others = malloc(n * np * sizeof *prof->others);
    if (!it || !prof->theta || !prof->delta || !prof->others) {
        free(it);
        return PHC_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; ++i)
        it[i] = (sort_item){l->theta[i], l->delta[i], i};
    qsort(it, n, sizeof *it, sort_item_cmp);
    for (size_t i = 0; i < n; ++i) {
        prof->theta[i] = it[i].theta;
        prof->delta[i] = it[i].delta;
        memcpy(prof->others + i * np, l->x + it[i].idx * np, np * sizeof *prof->others);
    }
    prof->n = n;
    free(it);
    return PHC_OK;
}

static void profile_clear(phc_profile *p)
{
    free(p->theta);
    free(p->delta);
    free(p->others);
    memset(p, 0, sizeof *p);
}

/* The profile of parameter j (the k-th free one) into prof, from the
 * optimum res->best (its cost and threshold set): depends on nothing else,
 * so that the profiles can be traced in any order, on any process. */
static int profile_one(phc_problem *pb, const phc_profile_options *opt, const phc_nls_options *nls_opt,
                       const phc_profile_result *res, const double *initial_step, size_t j, size_t k,
                       phc_profile *prof, double *scratch, phc_error *err)
{
    const size_t n_free = res->n_free, n_obs = res->n_obs;
    int rc;
    memset(prof, 0, sizeof *prof);
    prof->param = j;
    prof->min_delta = 0.0;
    point_list pts = {0, 0, pb->n_params, NULL, NULL, NULL};
    tracer tr = {pb, NULL, opt, *nls_opt, j, k, n_free, res->best_cost, res->threshold, &pts, prof, scratch};
    if ((rc = build_nls(pb, j, &tr.nls, err)))
        return rc;
    double h0 = 0.1 * phc_problem_scale(pb, j);
    /* from the Wald standard error: about `points` steps to the threshold */
    if (initial_step && isfinite(initial_step[j]) && initial_step[j] > 0.0) {
        /* near the optimum delta = s2 (theta - theta_hat)^2 / (2 se^2), with s2 the
           variance factor: the threshold is sqrt(2 thr / s2) se away */
        const double s2 = res->absolute_sigma ? 1.0 : 2.0 * res->best_cost / (double)(n_obs - n_free);
        h0 = initial_step[j] * sqrt(2.0 * res->threshold / (s2 > 0.0 ? s2 : 1.0)) / (double)opt->points;
    }
    if ((rc = push_point(&pts, res->best[j], 0.0, res->best)) == PHC_OK)
        rc = trace_side(&tr, res->best, h0, -1, &prof->lo, &prof->lo_end);
    if (rc == PHC_OK)
        rc = trace_side(&tr, res->best, h0, +1, &prof->hi, &prof->hi_end);
    phc_nls_free(tr.nls);
    if (rc == PHC_OK)
        rc = store_points(&pts, prof);
    free(pts.theta);
    free(pts.delta);
    free(pts.x);
    if (rc) {
        profile_clear(prof);
        return phc_error_set(err, rc, "profile of '%s': out of memory", pb->params[j].name);
    }
    double max_delta = 0.0;
    for (size_t i = 0; i < prof->n; ++i)
        if (prof->delta[i] > max_delta)
            max_delta = prof->delta[i];
    prof->flat = prof->lo_end != PHC_PROFILE_CROSSED && prof->hi_end != PHC_PROFILE_CROSSED &&
                 max_delta < opt->flat_fraction * res->threshold;
    return PHC_OK;
}

/* ---- the profiles shared out over processes (fit/study_dist.h) ------------------------- */

/* A profile travels as one row of doubles: 8 numbers (n, lo, hi, lo_end,
 * hi_end, inner_fits, failed_fits, min_delta), then theta, delta and the
 * others (n_params each) of at most `cap` points.  A side pushes at most one
 * point per step and 40 in its crossing's refinement, so
 * cap = 1 + 2 (max_steps + 40) holds every profile.  Doubles carry every
 * value bit for bit (counts are exact below 2^53). */
enum { HEAD = 8, REFINE_POINTS = 40 };

typedef struct dist_ctx {
    phc_problem *pb;
    const phc_profile_options *opt;
    const phc_nls_options *nls_opt;
    phc_profile_result *res;
    const double *initial_step;
    const size_t *param_of; /* k -> j */
    size_t cap;
    double *scratch;
} dist_ctx;

static size_t dist_cap(const phc_profile_options *opt)
{
    const size_t max_steps = opt->max_steps ? opt->max_steps : 8 * opt->points + 40;
    return 1 + 2 * (max_steps + REFINE_POINTS);
}

static int dist_eval(void *vctx, size_t k, double *out)
{
    dist_ctx *c = vctx;
    const size_t np = c->pb->n_params;
    phc_profile p;
    phc_error e;
    phc_error_clear(&e);
    out[0] = NAN;
    if (profile_one(c->pb, c->opt, c->nls_opt, c->res, c->initial_step, c->param_of[k], k, &p, c->scratch, &e) !=
            PHC_OK ||
        p.n > c->cap) {
        profile_clear(&p);
        return 1;
    }
    const double head[HEAD] = {(double)p.n,           p.lo, p.hi, (double)p.lo_end, (double)p.hi_end,
                               (double)p.inner_fits, (double)p.failed_fits, p.min_delta};
    memcpy(out, head, sizeof head);
    memcpy(out + HEAD, p.theta, p.n * sizeof *p.theta);
    memcpy(out + HEAD + c->cap, p.delta, p.n * sizeof *p.delta);
    memcpy(out + HEAD + 2 * c->cap, p.others, p.n * np * sizeof *p.others);
    profile_clear(&p); /* flat: the master recomputes it from the points */
    return 0;
}

static int dist_record(void *vctx, size_t k, int failed, const double *in, phc_error *err)
{
    dist_ctx *c = vctx;
    const size_t np = c->pb->n_params, j = c->param_of[k];
    if (failed)
        return phc_error_set(err, PHC_ERR_NOMEM, "profile of '%s': out of memory, or more than %zu points",
                             c->pb->params[j].name, c->cap);
    phc_profile *p = &c->res->profiles[k];
    const size_t n = (size_t)in[0];
    p->param = j;
    p->n = n;
    p->lo = in[1];
    p->hi = in[2];
    p->lo_end = (phc_profile_end)(int)in[3];
    p->hi_end = (phc_profile_end)(int)in[4];
    p->inner_fits = (size_t)in[5];
    p->failed_fits = (size_t)in[6];
    p->min_delta = in[7];
    p->theta = malloc((n ? n : 1) * sizeof *p->theta);
    p->delta = malloc((n ? n : 1) * sizeof *p->delta);
    p->others = malloc((n ? n : 1) * np * sizeof *p->others);
    if (!p->theta || !p->delta || !p->others)
        return phc_error_set(err, PHC_ERR_NOMEM, "profile of '%s': out of memory", c->pb->params[j].name);
    memcpy(p->theta, in + HEAD, n * sizeof *p->theta);
    memcpy(p->delta, in + HEAD + c->cap, n * sizeof *p->delta);
    memcpy(p->others, in + HEAD + 2 * c->cap, n * np * sizeof *p->others);
    double max_delta = 0.0;
    for (size_t i = 0; i < n; ++i)
        if (p->delta[i] > max_delta)
            max_delta = p->delta[i];
    p->flat = p->lo_end != PHC_PROFILE_CROSSED && p->hi_end != PHC_PROFILE_CROSSED &&
              max_delta < c->opt->flat_fraction * c->res->threshold;
    return PHC_OK;
}

/* Every rank has polished the same optimum; the master hands out one
 * parameter's profile per message and traces profiles itself between
 * results; the workers leave with res->n_profiles = 0. */
static int distribute(phc_problem *pb, const phc_profile_options *opt, const phc_nls_options *nls_opt,
                      phc_profile_result *res, const double *initial_step, size_t n_free, phc_error *err)
{
    phc_dist *d = opt->dist;
    const size_t np = pb->n_params, cap = dist_cap(opt);
    size_t *param_of = malloc(n_free * sizeof *param_of), *rows = malloc(n_free * sizeof *rows);
    double *scratch = malloc(np * sizeof *scratch);
    int rc = !param_of || !rows || !scratch ? phc_error_set(err, PHC_ERR_NOMEM, "profile: out of memory") : PHC_OK;
    if (rc == PHC_OK)
        for (size_t j = 0, k = 0; j < np; ++j)
            if (!pb->params[j].fixed) {
                param_of[k] = j;
                rows[k] = k;
                ++k;
            }
    dist_ctx c = {pb, opt, nls_opt, res, initial_step, param_of, cap, scratch};
    if ((rc = d->agree(d, rc, err)) == PHC_OK) {
        if (d->rank == 0) {
            res->n_profiles = n_free; /* recorded as they arrive; freed with res when the run fails */
            rc = d->run(d, HEAD + cap * (2 + np), rows, n_free, dist_eval, dist_record, &c, err);
        } else {
            rc = d->run(d, HEAD + cap * (2 + np), NULL, 0, dist_eval, NULL, &c, err);
        }
    }
    free(param_of);
    free(rows);
    free(scratch);
    return rc;
}

/* An error before the profiles: under MPI the other ranks learn it (the one
 * agree() of study_dist.h's protocol) instead of waiting for this rank. */
static int agree_failure(const phc_profile_options *opt, int rc, phc_error *err)
{
    if (opt->dist)
        opt->dist->agree(opt->dist, rc, err);
    return rc;
}

int phc_profile_run(phc_problem *pb, const double *x0, const double *initial_step,
                    const phc_profile_options *opt, phc_profile_result **out, phc_error *err)
{
    *out = NULL;
    int rc = PHC_OK, agreed = 0; /* with opt->dist, every rank agrees once (study_dist.h) */
    if (!(opt->level > 0.0 && opt->level < 1.0))
        return agree_failure(
            opt, phc_error_set(err, PHC_ERR_INPUT, "profile: level must be between 0 and 1, found %g", opt->level),
            err);
    if (opt->points < 3)
        return agree_failure(
            opt, phc_error_set(err, PHC_ERR_INPUT, "profile: points must be at least 3, found %zu", opt->points),
            err);
    size_t n_free = 0, n_obs = 0;
    for (size_t i = 0; i < pb->n_params; ++i)
        n_free += !pb->params[i].fixed;
    for (size_t d = 0; d < pb->n_datasets; ++d)
        n_obs += pb->datasets[d]->n;
    if (n_free == 0)
        return agree_failure(opt,
                             phc_error_set(err, PHC_ERR_INPUT,
                                           "%s: no free parameter to profile (every parameter is fixed)",
                                           pb->source ? pb->source : pb->name),
                             err);
    if (!pb->options.absolute_sigma && n_obs <= n_free)
        return agree_failure(opt,
                             phc_error_set(err, PHC_ERR_INPUT,
                                           "%s: %zu observations for %zu free parameters leave no degrees of "
                                           "freedom to estimate the noise; a profile needs n > p (or absolute "
                                           "sigmas)",
                                           pb->source ? pb->source : pb->name, n_obs, n_free),
                             err);
    phc_profile_result *res = calloc(1, sizeof *res);
    if (!res)
        return agree_failure(opt, phc_error_set(err, PHC_ERR_NOMEM, "profile: out of memory"), err);
    res->n_params = pb->n_params;
    res->n_obs = n_obs;
    res->n_free = n_free;
    res->level = opt->level;
    res->absolute_sigma = pb->options.absolute_sigma;
    res->best = malloc(pb->n_params * sizeof *res->best);
    res->profiles = calloc(n_free, sizeof *res->profiles);
    double *scratch = malloc(pb->n_params * sizeof *scratch);
    if (!res->best || !res->profiles || !scratch) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "profile: out of memory");
        goto done;
    }
    for (size_t i = 0; i < pb->n_params; ++i)
        res->best[i] = x0 ? x0[i] : pb->params[i].value;
    phc_nls_options nls_opt = pb->options.nls;
    nls_opt.on_iteration = NULL;
    nls_opt.on_iteration_data = NULL;
    /* the optimum, polished by the same solver the profiles use */
    {
        phc_nls *nls = NULL;
        phc_nls_summary sum;
        if ((rc = build_nls(pb, SIZE_MAX, &nls, err)))
            goto done;
        rc = phc_nls_solve(nls, &nls_opt, res->best, &sum, err);
        phc_nls_free(nls);
        if (rc)
            goto done;
        if (sum.outcome == PHC_NLS_FAILED || !isfinite(sum.final_cost)) {
            rc = phc_error_set(err, PHC_ERR_NOT_CONVERGED, "profile: the fit at the optimum failed: %s",
                               sum.termination);
            goto done;
        }
        res->best_cost = sum.final_cost;
    }
    res->threshold = phc_profile_threshold(opt->level, res->absolute_sigma, res->best_cost, n_obs, n_free);
    if (opt->dist) { /* every rank: the same set-up, then the profiles shared out (study_dist.h) */
        rc = distribute(pb, opt, &nls_opt, res, initial_step, n_free, err);
        agreed = 1;
        goto done;
    }
    size_t k = 0;
    for (size_t j = 0; j < pb->n_params && rc == PHC_OK; ++j) {
        if (pb->params[j].fixed)
            continue;
        if ((rc = profile_one(pb, opt, &nls_opt, res, initial_step, j, k, &res->profiles[k], scratch, err)))
            break;
        ++k;
    }
    res->n_profiles = k;
done:
    free(scratch);
    if (opt->dist && !agreed) /* failed before the profiles: the other ranks must not wait for this one */
        opt->dist->agree(opt->dist, rc, err);
    if (rc) {
        phc_profile_result_free(res);
        return rc;
    }
    *out = res;
    return PHC_OK;
}

void phc_profile_result_free(phc_profile_result *res)
{
    if (!res)
        return;
    for (size_t i = 0; i < res->n_profiles; ++i) {
        free(res->profiles[i].theta);
        free(res->profiles[i].delta);
        free(res->profiles[i].others);
    }
    free(res->profiles);
    free(res->best);
    free(res);
}
