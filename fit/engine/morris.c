/* Morris elementary effects: see morris.h. */
#include "fit/engine/morris.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct phc_morris_design {
    size_t k, f, r;
    unsigned p;
    size_t *group_of; /* k */
    unsigned *start;  /* r x k start levels */
    int *dir;         /* r x f: +1 or -1 */
    size_t *pos;      /* r x f: the step (1..f) at which factor g moves */
    phc_morris_options o;
};

phc_morris_options phc_morris_options_default(void)
{
    phc_morris_options o = {20, 4, 1, 1000, 0.95};
    return o;
}

void phc_morris_design_free(phc_morris_design *d)
{
    if (!d)
        return;
    free(d->group_of);
    free(d->start);
    free(d->dir);
    free(d->pos);
    free(d);
}

int phc_morris_design_new(size_t k, const size_t *group_of, size_t n_factors, const phc_morris_options *o,
                          phc_morris_design **out, phc_error *err)
{
    *out = NULL;
    if (k == 0 || n_factors == 0 || n_factors > k)
        return phc_error_set(err, PHC_ERR_INPUT, "a sensitivity study needs at least one factor to vary "
                             "(found %zu parameters in %zu factors)", k, n_factors);
    if (!group_of && n_factors != k)
        return phc_error_set(err, PHC_ERR_INVALID, "without groups every parameter is its own factor");
    if (o->trajectories < 4)
        return phc_error_set(err, PHC_ERR_INPUT, "samples: %zu Morris trajectories are too few: use at least 4 "
                             "(10 to 50 is usual)", o->trajectories);
    if (o->trajectories > (size_t)1 << 26)
        return phc_error_set(err, PHC_ERR_INPUT, "samples: %zu trajectories are beyond 2^26", o->trajectories);
    if (o->levels < 2 || o->levels % 2 || o->levels > 1000)
        return phc_error_set(err, PHC_ERR_INPUT, "levels: Morris's grid needs an even number of levels from 2 to "
                             "1000, found %u", o->levels);
    if (o->bootstrap < 100 || !(o->level > 0 && o->level < 1))
        return phc_error_set(err, PHC_ERR_INPUT, "bootstrap: needs >= 100 resamples and a level in (0, 1), "
                             "found %zu and %g", o->bootstrap, o->level);
    phc_morris_design *d = calloc(1, sizeof *d);
    if (!d)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    const size_t r = o->trajectories, f = n_factors;
    d->k = k;
    d->f = f;
    d->r = r;
    d->p = o->levels;
    d->o = *o;
    d->group_of = malloc(k * sizeof *d->group_of);
    d->start = malloc(r * k * sizeof *d->start);
    d->dir = malloc(r * f * sizeof *d->dir);
    d->pos = malloc(r * f * sizeof *d->pos);
    size_t *order = malloc(f * sizeof *order), *count = calloc(f, sizeof *count);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    if (!d->group_of || !d->start || !d->dir || !d->pos || !order || !count || !rng) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t c = 0; c < k; ++c) {
        d->group_of[c] = group_of ? group_of[c] : c;
        if (d->group_of[c] >= f) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "column %zu: factor %zu of %zu", c, d->group_of[c], f);
            goto done;
        }
        count[d->group_of[c]]++;
    }
    for (size_t g = 0; g < f; ++g)
        if (!count[g]) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "factor %zu holds no parameter", g + 1);
            goto done;
        }
    gsl_rng_set(rng, o->seed);
    const unsigned half = d->p / 2;
    for (size_t t = 0; t < r; ++t) {
        for (size_t g = 0; g < f; ++g)
            d->dir[t * f + g] = gsl_rng_uniform_int(rng, 2) ? 1 : -1;
        for (size_t c = 0; c < k; ++c) {
            const unsigned l = (unsigned)gsl_rng_uniform_int(rng, half); /* lower half */
            d->start[t * k + c] = d->dir[t * f + d->group_of[c]] > 0 ? l : l + half;
        }
        for (size_t g = 0; g < f; ++g)
            order[g] = g;
        gsl_ran_shuffle(rng, order, f, sizeof *order);
        for (size_t s = 0; s < f; ++s)
            d->pos[t * f + order[s]] = s + 1;
    }
    *out = d;
done:
    gsl_rng_free(rng);
    free(order);
    free(count);
    if (rc)
        phc_morris_design_free(d);
    return rc;
}

size_t phc_morris_design_rows(const phc_morris_design *d)
{
    return d->r * (d->f + 1);
}

size_t phc_morris_design_factors(const phc_morris_design *d)
{
    return d->f;
}

void phc_morris_design_point(const phc_morris_design *d, size_t row, double *u)
{
    const size_t t = row / (d->f + 1), s = row % (d->f + 1);
    const int half = (int)(d->p / 2);
    for (size_t c = 0; c < d->k; ++c) {
        const size_t g = d->group_of[c];
        int l = (int)d->start[t * d->k + c];
        if (d->pos[t * d->f + g] <= s)
            l += d->dir[t * d->f + g] * half;
        u[c] = ((double)l + 0.5) / (double)d->p;
    }
}

void phc_morris_effects_clear(phc_morris_effects *e)
{
    if (!e)
        return;
    free(e->mu);
    memset(e, 0, sizeof *e);
}

/* mu, mu*, sigma of factor g over the trajectories idx[0..m-1] from the
 * effects ee (r x f). */
static void stats(const double *ee, size_t f, size_t g, const size_t *idx, size_t m, double *mu, double *mu_star,
                  double *sigma)
{
    double s = 0, sa = 0;
    for (size_t t = 0; t < m; ++t) {
        const double e = ee[idx[t] * f + g];
        s += e;
        sa += fabs(e);
    }
    *mu = s / (double)m;
    *mu_star = sa / (double)m;
    double ss = 0;
    for (size_t t = 0; t < m; ++t) {
        const double e = ee[idx[t] * f + g] - *mu;
        ss += e * e;
    }
    *sigma = m > 1 ? sqrt(ss / (double)(m - 1)) : NAN;
}

int phc_morris_estimate(const phc_morris_design *d, const double *y, phc_morris_effects *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t f = d->f, r = d->r, R = d->o.bootstrap;
    const double delta = (double)d->p / (2.0 * ((double)d->p - 1.0));
    double *ee = malloc(r * f * sizeof *ee), *boot = malloc(3 * R * sizeof *boot);
    size_t *used = malloc(r * sizeof *used), *draw = malloc(r * sizeof *draw);
    out->n_factors = f;
    out->mu = malloc(9 * f * sizeof *out->mu);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    if (!ee || !boot || !used || !draw || !out->mu || !rng) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    out->mu_lo = out->mu + f;
    out->mu_hi = out->mu + 2 * f;
    out->mu_star = out->mu + 3 * f;
    out->mu_star_lo = out->mu + 4 * f;
    out->mu_star_hi = out->mu + 5 * f;
    out->sigma = out->mu + 6 * f;
    out->sigma_lo = out->mu + 7 * f;
    out->sigma_hi = out->mu + 8 * f;
    size_t m = 0;
    for (size_t t = 0; t < r; ++t) {
        const double *yt = y + t * (f + 1);
        int ok = 1;
        for (size_t s = 0; s <= f; ++s)
            ok &= isfinite(yt[s]) != 0;
        if (!ok)
            continue;
        used[m++] = t;
        for (size_t g = 0; g < f; ++g) {
            const size_t s = d->pos[t * f + g];
            ee[t * f + g] = (yt[s] - yt[s - 1]) / ((double)d->dir[t * f + g] * delta);
        }
    }
    out->n_used = m;
    out->n_failed = r - m;
    if (m < 2) {
        rc = phc_error_set(err, PHC_ERR_NUMERIC, "only %zu of %zu Morris trajectories have every evaluation "
                           "finished; the effects need at least 2", m, r);
        goto done;
    }
    gsl_rng_set(rng, d->o.seed ^ 0x5deece66dUL);
    for (size_t g = 0; g < f; ++g) {
        stats(ee, f, g, used, m, &out->mu[g], &out->mu_star[g], &out->sigma[g]);
        for (size_t b = 0; b < R; ++b) {
            for (size_t t = 0; t < m; ++t)
                draw[t] = used[gsl_rng_uniform_int(rng, m)];
            stats(ee, f, g, draw, m, &boot[b], &boot[R + b], &boot[2 * R + b]);
        }
        double *lo[3] = {out->mu_lo, out->mu_star_lo, out->sigma_lo};
        double *hi[3] = {out->mu_hi, out->mu_star_hi, out->sigma_hi};
        for (int q = 0; q < 3; ++q) {
            double *v = boot + (size_t)q * R;
            gsl_sort(v, 1, R);
            lo[q][g] = gsl_stats_quantile_from_sorted_data(v, 1, R, 0.5 * (1 - d->o.level));
            hi[q][g] = gsl_stats_quantile_from_sorted_data(v, 1, R, 1 - 0.5 * (1 - d->o.level));
        }
    }
done:
    gsl_rng_free(rng);
    free(ee);
    free(boot);
    free(used);
    free(draw);
    if (rc)
        phc_morris_effects_clear(out);
    return rc;
}
