/* Sobol indices from a Saltelli design: see sobol_indices.h. */
#include "fit/engine/sobol_indices.h"

#include <gsl/gsl_qrng.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct phc_saltelli_design {
    size_t k, f, n, block; /* columns, factors, base samples, rows per base sample */
    size_t *group_of;      /* k */
    double *base;          /* n x 2k: A_j = base[j][0..k-1], B_j = base[j][k..2k-1] */
    phc_saltelli_options o;
};

phc_saltelli_options phc_saltelli_options_default(void)
{
    phc_saltelli_options o = {1024, 0, 0, 1, 1000, 0.95};
    return o;
}

int phc_saltelli_design_new(size_t k, const size_t *group_of, size_t n_factors, const phc_saltelli_options *o,
                            phc_saltelli_design **out, phc_error *err)
{
    *out = NULL;
    if (k == 0 || n_factors == 0 || n_factors > k)
        return phc_error_set(err, PHC_ERR_INPUT, "a sensitivity study needs at least one factor to vary "
                             "(found %zu parameters in %zu factors)", k, n_factors);
    if (!group_of && n_factors != k)
        return phc_error_set(err, PHC_ERR_INVALID, "without groups every parameter is its own factor");
    const size_t n_min = o->second_order ? 16 : 8;
    if (o->n < n_min)
        return phc_error_set(err, PHC_ERR_INPUT, "samples: N = %zu is too small for %s indices: use at least %zu "
                             "(a few hundred for useful intervals)", o->n,
                             o->second_order ? "second-order" : "first-order and total", n_min);
    if (o->n > (size_t)1 << 30)
        return phc_error_set(err, PHC_ERR_INPUT, "samples: N = %zu is beyond 2^30", o->n);
    if (o->bootstrap < 100 || !(o->level > 0 && o->level < 1))
        return phc_error_set(err, PHC_ERR_INPUT, "bootstrap: needs >= 100 resamples and a level in (0, 1), "
                             "found %zu and %g", o->bootstrap, o->level);
    if (!o->randomised && 2 * k > 40)
        return phc_error_set(err, PHC_ERR_INPUT, "%zu parameters need %zu Sobol dimensions; GSL's sequence has 40: "
                             "use the randomised design (phytocal sensitivity --design random)", k, 2 * k);
    phc_saltelli_design *d = calloc(1, sizeof *d);
    if (!d)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    d->k = k;
    d->f = n_factors;
    d->n = o->n;
    d->o = *o;
    d->block = o->second_order ? 2 * n_factors + 2 : n_factors + 2;
    d->group_of = malloc(k * sizeof *d->group_of);
    d->base = malloc(o->n * 2 * k * sizeof *d->base);
    size_t *count = calloc(n_factors, sizeof *count);
    int rc = PHC_OK;
    if (!d->group_of || !d->base || !count) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t c = 0; c < k; ++c) {
        d->group_of[c] = group_of ? group_of[c] : c;
        if (d->group_of[c] >= n_factors) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "column %zu: factor %zu of %zu", c, d->group_of[c], n_factors);
            goto fail;
        }
        count[d->group_of[c]]++;
    }
    for (size_t g = 0; g < n_factors; ++g)
        if (!count[g]) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "factor %zu holds no parameter", g + 1);
            goto fail;
        }
    if (o->randomised) {
        gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
        if (!r) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        gsl_rng_set(r, o->seed);
        for (size_t i = 0; i < o->n * 2 * k; ++i)
            d->base[i] = gsl_rng_uniform_pos(r); /* (0, 1): unbounded priors stay finite */
        gsl_rng_free(r);
    } else {
        gsl_qrng *q = gsl_qrng_alloc(gsl_qrng_sobol, (unsigned)(2 * k));
        if (!q) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        double skip[40];
        gsl_qrng_get(q, skip); /* the centre: A_0 = B_0 (header) */
        for (size_t j = 0; j < o->n; ++j)
            gsl_qrng_get(q, d->base + j * 2 * k);
        gsl_qrng_free(q);
    }
    free(count);
    *out = d;
    return PHC_OK;
fail:
    free(count);
    phc_saltelli_design_free(d);
    return rc;
}

void phc_saltelli_design_free(phc_saltelli_design *d)
{
    if (!d)
        return;
    free(d->group_of);
    free(d->base);
    free(d);
}

size_t phc_saltelli_design_rows(const phc_saltelli_design *d)
{
    return d->n * d->block;
}

size_t phc_saltelli_design_factors(const phc_saltelli_design *d)
{
    return d->f;
}

void phc_saltelli_design_point(const phc_saltelli_design *d, size_t row, double *u)
{
    const size_t j = row / d->block, s = row % d->block, k = d->k;
    const double *a = d->base + j * 2 * k, *b = a + k;
    if (s == 0) {
        memcpy(u, a, k * sizeof *u);
    } else if (s == 1) {
        memcpy(u, b, k * sizeof *u);
    } else if (s < 2 + d->f) { /* A_B^i: A with factor i from B */
        const size_t i = s - 2;
        for (size_t c = 0; c < k; ++c)
            u[c] = d->group_of[c] == i ? b[c] : a[c];
    } else { /* B_A^i: B with factor i from A */
        const size_t i = s - 2 - d->f;
        for (size_t c = 0; c < k; ++c)
            u[c] = d->group_of[c] == i ? a[c] : b[c];
    }
}

void phc_sobol_indices_clear(phc_sobol_indices *s)
{
    if (!s)
        return;
    free(s->s1);
    free(s->st);
    free(s->s2);
    memset(s, 0, sizeof *s);
}

/* The indices from the base samples idx[0..m-1] (repeats allowed), with y
 * centred on its own mean over A and B of those samples (two passes: a cost
 * of 1e6 varying by 1 keeps its digits).  s1, st: f values; s2: f*f or NULL.
 * acc: scratch of 2f + f*f values.  The third pass accumulates every factor's
 * sums at once, each in the order of t (the same sums, term by term, as one
 * pass per factor: the results do not depend on the loop order). */
static void estimate(const phc_saltelli_design *d, const double *y, const size_t *idx, size_t m, double *s1,
                     double *st, double *s2, double *acc)
{
    const size_t f = d->f, bl = d->block;
    double sum = 0, sum2 = 0;
    for (size_t t = 0; t < m; ++t)
        sum += y[idx[t] * bl] + y[idx[t] * bl + 1];
    const double mean = sum / (double)(2 * m);
    for (size_t t = 0; t < m; ++t) {
        const double a = y[idx[t] * bl] - mean, b = y[idx[t] * bl + 1] - mean;
        sum2 += a * a + b * b;
    }
    const double var = sum2 / (double)(2 * m);
    double *a1 = acc, *at = acc + f, *a2 = acc + 2 * f;
    memset(acc, 0, (s2 ? 2 * f + f * f : 2 * f) * sizeof *acc);
    for (size_t t = 0; t < m; ++t) {
        const double *yb = y + idx[t] * bl;
        const double fa = yb[0] - mean, fb = yb[1] - mean;
        for (size_t i = 0; i < f; ++i) {
            const double fab = yb[2 + i] - mean;
            a1[i] += fb * (fab - fa);
            at[i] += (fa - fab) * (fa - fab);
        }
        if (s2)
            for (size_t i = 0; i < f; ++i) {
                const double fba_i = yb[2 + f + i] - mean;
                for (size_t j = i + 1; j < f; ++j) {
                    const double fab_j = yb[2 + j] - mean;
                    a2[i * f + j] += fba_i * fab_j - fa * fb;
                }
            }
    }
    for (size_t i = 0; i < f; ++i) {
        s1[i] = var > 0 ? a1[i] / (double)m / var : NAN;
        st[i] = var > 0 ? at[i] / (2.0 * (double)m) / var : NAN;
    }
    if (!s2)
        return;
    for (size_t i = 0; i < f; ++i)
        for (size_t j = 0; j < f; ++j)
            s2[i * f + j] = j <= i ? NAN : var > 0 ? a2[i * f + j] / (double)m / var - s1[i] - s1[j] : NAN;
}

/* estimate (above, without second order) for G resamples at once:
 * idx[q][0..m-1] for q < G.  Each resample's sums are taken exactly as
 * estimate takes them (same terms, same order, same expressions), so the
 * results are the same bits; the G resamples' sums are independent chains
 * that the processor overlaps, where estimate's first two passes are one
 * chain of additions each, waiting on the last.  res: G x 2f values. */
enum { GROUP = 4 };

static void estimate_group(const phc_saltelli_design *d, const double *y, const size_t *const idx[GROUP], size_t m,
                           double *res, double *acc)
{
    const size_t f = d->f, bl = d->block;
    const size_t *i0 = idx[0], *i1 = idx[1], *i2 = idx[2], *i3 = idx[3];
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    for (size_t t = 0; t < m; ++t) {
        s0 += y[i0[t] * bl] + y[i0[t] * bl + 1];
        s1 += y[i1[t] * bl] + y[i1[t] * bl + 1];
        s2 += y[i2[t] * bl] + y[i2[t] * bl + 1];
        s3 += y[i3[t] * bl] + y[i3[t] * bl + 1];
    }
    const double m0 = s0 / (double)(2 * m), m1 = s1 / (double)(2 * m), m2 = s2 / (double)(2 * m),
                 m3 = s3 / (double)(2 * m);
    double v0 = 0, v1 = 0, v2 = 0, v3 = 0;
    for (size_t t = 0; t < m; ++t) {
        const double a0 = y[i0[t] * bl] - m0, b0 = y[i0[t] * bl + 1] - m0;
        const double a1 = y[i1[t] * bl] - m1, b1 = y[i1[t] * bl + 1] - m1;
        const double a2 = y[i2[t] * bl] - m2, b2 = y[i2[t] * bl + 1] - m2;
        const double a3 = y[i3[t] * bl] - m3, b3 = y[i3[t] * bl + 1] - m3;
        v0 += a0 * a0 + b0 * b0;
        v1 += a1 * a1 + b1 * b1;
        v2 += a2 * a2 + b2 * b2;
        v3 += a3 * a3 + b3 * b3;
    }
    const double mean[GROUP] = {m0, m1, m2, m3};
    const double var[GROUP] = {v0 / (double)(2 * m), v1 / (double)(2 * m), v2 / (double)(2 * m),
                               v3 / (double)(2 * m)};
    double *a1 = acc, *at = acc + GROUP * f; /* [q f + i] */
    memset(acc, 0, 2 * GROUP * f * sizeof *acc);
    for (size_t t = 0; t < m; ++t)
        for (size_t q = 0; q < GROUP; ++q) {
            const double *yb = y + idx[q][t] * bl;
            const double fa = yb[0] - mean[q], fb = yb[1] - mean[q];
            double *a1q = a1 + q * f, *atq = at + q * f;
            for (size_t i = 0; i < f; ++i) {
                const double fab = yb[2 + i] - mean[q];
                a1q[i] += fb * (fab - fa);
                atq[i] += (fa - fab) * (fa - fab);
            }
        }
    for (size_t q = 0; q < GROUP; ++q)
        for (size_t i = 0; i < f; ++i) {
            res[q * 2 * f + i] = var[q] > 0 ? a1[q * f + i] / (double)m / var[q] : NAN;
            res[q * 2 * f + f + i] = var[q] > 0 ? at[q * f + i] / (2.0 * (double)m) / var[q] : NAN;
        }
}

/* Percentile interval of the R values v (sorted here) at coverage level. */
static void percentile(double *v, size_t r, double level, double *lo, double *hi)
{
    gsl_sort(v, 1, r);
    *lo = gsl_stats_quantile_from_sorted_data(v, 1, r, 0.5 * (1 - level));
    *hi = gsl_stats_quantile_from_sorted_data(v, 1, r, 1 - 0.5 * (1 - level));
}

/* The base samples whose whole block is finite in y (stride between a
 * row's values: ys); returns their count. */
static size_t usable(const phc_saltelli_design *d, const double *y, size_t ys, size_t *used)
{
    size_t m = 0;
    for (size_t j = 0; j < d->n; ++j) {
        int ok = 1;
        for (size_t s = 0; s < d->block; ++s)
            ok &= isfinite(y[(j * d->block + s) * ys]) != 0;
        if (ok)
            used[m++] = j;
    }
    return m;
}

/* The indices of n_out outputs (columns y[c * M ..], contiguous) that share
 * the usable base samples used[0..m-1]: every output's bootstrap draws the
 * same resamples (the generator is seeded the same for every output, so
 * each output's result is what estimating it alone gives), drawn once. */
static int estimate_outputs(const phc_saltelli_design *d, const double *cols, size_t n_out, const size_t *used,
                            size_t m, phc_sobol_indices *outs, phc_error *err)
{
    const size_t f = d->f, bl = d->block, n = d->n, R = d->o.bootstrap, nf2 = d->o.second_order ? f * f : 0;
    const size_t M = n * bl, per = 2 * f + nf2;
    size_t *draw = malloc(GROUP * n * sizeof *draw);
    double *boot = malloc(n_out * R * per * sizeof *boot), *tmp = malloc((R > 1 ? R : 1) * sizeof *tmp);
    double *acc = malloc((2 * f + f * f + 2 * GROUP * f) * sizeof *acc), *res = malloc(GROUP * 2 * f * sizeof *res);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    for (size_t c = 0; c < n_out; ++c) {
        phc_sobol_indices *out = &outs[c];
        memset(out, 0, sizeof *out);
        out->n_factors = f;
        out->s1 = malloc(3 * f * sizeof *out->s1);
        out->st = malloc(3 * f * sizeof *out->st);
        out->s2 = nf2 ? malloc(3 * nf2 * sizeof *out->s2) : NULL;
        if (!out->s1 || !out->st || (nf2 && !out->s2))
            rc = PHC_ERR_NOMEM;
    }
    if (rc || !draw || !boot || !tmp || !acc || !res || !rng) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t c = 0; c < n_out; ++c) {
        phc_sobol_indices *out = &outs[c];
        const double *y = cols + c * M;
        out->s1_lo = out->s1 + f;
        out->s1_hi = out->s1 + 2 * f;
        out->st_lo = out->st + f;
        out->st_hi = out->st + 2 * f;
        if (nf2) {
            out->s2_lo = out->s2 + nf2;
            out->s2_hi = out->s2 + 2 * nf2;
        }
        out->n_used = m;
        out->n_failed = n - m;
        if (m < 4) {
            rc = phc_error_set(err, PHC_ERR_NUMERIC, "only %zu of %zu base samples have every evaluation finished; "
                               "the indices need at least 4", m, n);
            goto done;
        }
        double sum = 0, sum2 = 0;
        for (size_t t = 0; t < m; ++t) {
            sum += y[used[t] * bl] + y[used[t] * bl + 1];
        }
        out->mean = sum / (double)(2 * m);
        for (size_t t = 0; t < m; ++t) {
            const double a = y[used[t] * bl] - out->mean, b = y[used[t] * bl + 1] - out->mean;
            sum2 += a * a + b * b;
        }
        out->variance = sum2 / (double)(2 * m);
        estimate(d, y, used, m, out->s1, out->st, out->s2, acc);
    }
    /* bootstrap: a fixed stream per estimate, so results do not depend on
       which outputs were estimated before or together */
    gsl_rng_set(rng, d->o.seed ^ 0x5deece66dUL);
    for (size_t r = 0; r < R;) {
        /* GROUP resamples at a time (drawn in turn, as one at a time would
           draw them) when there are that many left and no second order */
        const size_t g = !nf2 && R - r >= GROUP ? GROUP : 1;
        for (size_t q = 0; q < g; ++q)
            for (size_t t = 0; t < m; ++t)
                draw[q * n + t] = used[gsl_rng_uniform_int(rng, m)];
        for (size_t c = 0; c < n_out; ++c) {
            if (g == GROUP) {
                const size_t *const idx[GROUP] = {draw, draw + n, draw + 2 * n, draw + 3 * n};
                estimate_group(d, cols + c * M, idx, m, res, acc);
                for (size_t q = 0; q < GROUP; ++q)
                    memcpy(boot + (c * R + r + q) * per, res + q * 2 * f, 2 * f * sizeof *res);
            } else {
                double *b = boot + (c * R + r) * per;
                estimate(d, cols + c * M, draw, m, b, b + f, nf2 ? b + 2 * f : NULL, acc);
            }
        }
        r += g;
    }
    for (size_t c = 0; c < n_out; ++c) {
        phc_sobol_indices *out = &outs[c];
        for (size_t i = 0; i < per; ++i) {
            size_t cnt = 0;
            for (size_t r = 0; r < R; ++r) {
                const double v = boot[(c * R + r) * per + i];
                if (isfinite(v))
                    tmp[cnt++] = v;
            }
            double lo = NAN, hi = NAN;
            if (cnt >= R / 2)
                percentile(tmp, cnt, d->o.level, &lo, &hi);
            if (i < f) {
                out->s1_lo[i] = lo;
                out->s1_hi[i] = hi;
            } else if (i < 2 * f) {
                out->st_lo[i - f] = lo;
                out->st_hi[i - f] = hi;
            } else {
                out->s2_lo[i - 2 * f] = lo;
                out->s2_hi[i - 2 * f] = hi;
            }
        }
    }
done:
    gsl_rng_free(rng);
    free(draw);
    free(boot);
    free(tmp);
    free(acc);
    free(res);
    if (rc)
        for (size_t c = 0; c < n_out; ++c)
            phc_sobol_indices_clear(&outs[c]);
    return rc;
}

int phc_sobol_indices_estimate(const phc_saltelli_design *d, const double *y, phc_sobol_indices *out,
                               phc_error *err)
{
    size_t *used = malloc(d->n * sizeof *used);
    if (!used) {
        memset(out, 0, sizeof *out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    const size_t m = usable(d, y, 1, used);
    const int rc = estimate_outputs(d, y, 1, used, m, out, err);
    free(used);
    return rc;
}

int phc_sobol_indices_estimate_outputs(const phc_saltelli_design *d, const double *y, size_t n_out,
                                       phc_sobol_indices *outs, phc_error *err)
{
    const size_t M = d->n * d->block;
    size_t *used = malloc(d->n * sizeof *used), *other = malloc(d->n * sizeof *other);
    double *cols = malloc((n_out ? n_out : 1) * M * sizeof *cols);
    int rc = PHC_OK;
    for (size_t c = 0; c < n_out; ++c)
        memset(&outs[c], 0, sizeof outs[c]);
    if (!used || !other || !cols) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t c = 0; c < n_out; ++c)
        for (size_t r = 0; r < M; ++r)
            cols[c * M + r] = y[r * n_out + c];
    /* runs of outputs with the same usable base samples share their
       resamples (a failed evaluation makes every output of its row NAN, so
       in a study all outputs are one run) */
    for (size_t c0 = 0; c0 < n_out && rc == PHC_OK;) {
        const size_t m = usable(d, cols + c0 * M, 1, used);
        size_t c1 = c0 + 1;
        while (c1 < n_out && usable(d, cols + c1 * M, 1, other) == m && memcmp(used, other, m * sizeof *used) == 0)
            ++c1;
        rc = estimate_outputs(d, cols + c0 * M, c1 - c0, used, m, outs + c0, err);
        c0 = c1;
    }
    if (rc)
        for (size_t c = 0; c < n_out; ++c)
            phc_sobol_indices_clear(&outs[c]);
done:
    free(used);
    free(other);
    free(cols);
    return rc;
}

/* The aggregated indices from the base samples idx[0..m-1] of the T
 * columns y + t M (M = n block). */
static void estimate_aggregate(const phc_saltelli_design *d, const double *y, size_t T, const size_t *idx, size_t m,
                               double *s1, double *st, double *num1, double *numt, double *var_out)
{
    const size_t f = d->f, bl = d->block, M = d->n * d->block;
    double var_sum = 0;
    for (size_t i = 0; i < f; ++i)
        num1[i] = numt[i] = 0;
    for (size_t t = 0; t < T; ++t) {
        const double *yt = y + t * M;
        double sum = 0, sum2 = 0;
        for (size_t q = 0; q < m; ++q)
            sum += yt[idx[q] * bl] + yt[idx[q] * bl + 1];
        const double mean = sum / (double)(2 * m);
        for (size_t q = 0; q < m; ++q) {
            const double a = yt[idx[q] * bl] - mean, b = yt[idx[q] * bl + 1] - mean;
            sum2 += a * a + b * b;
        }
        var_sum += sum2 / (double)(2 * m);
        for (size_t i = 0; i < f; ++i) {
            double a1 = 0, at = 0;
            for (size_t q = 0; q < m; ++q) {
                const double *yb = yt + idx[q] * bl;
                const double fa = yb[0] - mean, fb = yb[1] - mean, fab = yb[2 + i] - mean;
                a1 += fb * (fab - fa);
                at += (fa - fab) * (fa - fab);
            }
            num1[i] += a1 / (double)m;
            numt[i] += at / (2.0 * (double)m);
        }
    }
    for (size_t i = 0; i < f; ++i) {
        s1[i] = var_sum > 0 ? num1[i] / var_sum : NAN;
        st[i] = var_sum > 0 ? numt[i] / var_sum : NAN;
    }
    if (var_out)
        *var_out = var_sum;
}

/* estimate_aggregate for GROUP resamples idx[q][0..m-1] at once (the same
 * sums in the same order for each: the same bits); res: GROUP x 2f values
 * (s1, st of each resample), num: scratch of 2 GROUP f values. */
static void estimate_aggregate_group(const phc_saltelli_design *d, const double *y, size_t T,
                                     const size_t *const idx[GROUP], size_t m, double *res, double *num)
{
    const size_t f = d->f, bl = d->block, M = d->n * d->block;
    const size_t *i0 = idx[0], *i1 = idx[1], *i2 = idx[2], *i3 = idx[3];
    double var_sum[GROUP] = {0, 0, 0, 0};
    double *num1 = num, *numt = num + GROUP * f; /* [q f + i] */
    memset(num, 0, 2 * GROUP * f * sizeof *num);
    for (size_t t = 0; t < T; ++t) {
        const double *yt = y + t * M;
        double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
        for (size_t q = 0; q < m; ++q) {
            s0 += yt[i0[q] * bl] + yt[i0[q] * bl + 1];
            s1 += yt[i1[q] * bl] + yt[i1[q] * bl + 1];
            s2 += yt[i2[q] * bl] + yt[i2[q] * bl + 1];
            s3 += yt[i3[q] * bl] + yt[i3[q] * bl + 1];
        }
        const double mean[GROUP] = {s0 / (double)(2 * m), s1 / (double)(2 * m), s2 / (double)(2 * m),
                                    s3 / (double)(2 * m)};
        double v0 = 0, v1 = 0, v2 = 0, v3 = 0;
        for (size_t q = 0; q < m; ++q) {
            const double a0 = yt[i0[q] * bl] - mean[0], b0 = yt[i0[q] * bl + 1] - mean[0];
            const double a1 = yt[i1[q] * bl] - mean[1], b1 = yt[i1[q] * bl + 1] - mean[1];
            const double a2 = yt[i2[q] * bl] - mean[2], b2 = yt[i2[q] * bl + 1] - mean[2];
            const double a3 = yt[i3[q] * bl] - mean[3], b3 = yt[i3[q] * bl + 1] - mean[3];
            v0 += a0 * a0 + b0 * b0;
            v1 += a1 * a1 + b1 * b1;
            v2 += a2 * a2 + b2 * b2;
            v3 += a3 * a3 + b3 * b3;
        }
        var_sum[0] += v0 / (double)(2 * m);
        var_sum[1] += v1 / (double)(2 * m);
        var_sum[2] += v2 / (double)(2 * m);
        var_sum[3] += v3 / (double)(2 * m);
        for (size_t i = 0; i < f; ++i) {
            double a1[GROUP] = {0, 0, 0, 0}, at[GROUP] = {0, 0, 0, 0};
            for (size_t q = 0; q < m; ++q)
                for (size_t g = 0; g < GROUP; ++g) {
                    const double *yb = yt + idx[g][q] * bl;
                    const double fa = yb[0] - mean[g], fb = yb[1] - mean[g], fab = yb[2 + i] - mean[g];
                    a1[g] += fb * (fab - fa);
                    at[g] += (fa - fab) * (fa - fab);
                }
            for (size_t g = 0; g < GROUP; ++g) {
                num1[g * f + i] += a1[g] / (double)m;
                numt[g * f + i] += at[g] / (2.0 * (double)m);
            }
        }
    }
    for (size_t g = 0; g < GROUP; ++g)
        for (size_t i = 0; i < f; ++i) {
            res[g * 2 * f + i] = var_sum[g] > 0 ? num1[g * f + i] / var_sum[g] : NAN;
            res[g * 2 * f + f + i] = var_sum[g] > 0 ? numt[g * f + i] / var_sum[g] : NAN;
        }
}

int phc_sobol_indices_estimate_aggregate(const phc_saltelli_design *d, const double *y, size_t n_outputs,
                                         phc_sobol_indices *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t f = d->f, bl = d->block, n = d->n, R = d->o.bootstrap, M = d->n * d->block;
    if (n_outputs == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "aggregated indices of no output");
    size_t *used = malloc(n * sizeof *used), *draw = malloc(GROUP * n * sizeof *draw);
    double *boot = malloc(R * 2 * f * sizeof *boot), *tmp = malloc(R * sizeof *tmp);
    double *num = malloc(2 * GROUP * f * sizeof *num);
    out->n_factors = f;
    out->s1 = malloc(3 * f * sizeof *out->s1);
    out->st = malloc(3 * f * sizeof *out->st);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    if (!used || !draw || !boot || !tmp || !num || !out->s1 || !out->st || !rng) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    out->s1_lo = out->s1 + f;
    out->s1_hi = out->s1 + 2 * f;
    out->st_lo = out->st + f;
    out->st_hi = out->st + 2 * f;
    size_t m = 0;
    for (size_t j = 0; j < n; ++j) {
        int ok = 1;
        for (size_t t = 0; t < n_outputs && ok; ++t)
            for (size_t s = 0; s < bl; ++s)
                ok &= isfinite(y[t * M + j * bl + s]) != 0;
        if (ok)
            used[m++] = j;
    }
    out->n_used = m;
    out->n_failed = n - m;
    if (m < 4) {
        rc = phc_error_set(err, PHC_ERR_NUMERIC, "only %zu of %zu base samples have every evaluation finished; "
                           "the indices need at least 4", m, n);
        goto done;
    }
    {
        double mean_sum = 0;
        for (size_t t = 0; t < n_outputs; ++t) {
            double sum = 0;
            for (size_t q = 0; q < m; ++q)
                sum += y[t * M + used[q] * bl] + y[t * M + used[q] * bl + 1];
            mean_sum += sum / (double)(2 * m);
        }
        out->mean = mean_sum / (double)n_outputs;
    }
    estimate_aggregate(d, y, n_outputs, used, m, out->s1, out->st, num, num + f, &out->variance);
    gsl_rng_set(rng, d->o.seed ^ 0x5deece66dUL); /* the resamples of phc_sobol_indices_estimate */
    for (size_t r = 0; r < R;) { /* GROUP resamples at a time while that many are left (same draws, same bits) */
        const size_t g = R - r >= GROUP ? GROUP : 1;
        for (size_t k = 0; k < g; ++k)
            for (size_t q = 0; q < m; ++q)
                draw[k * n + q] = used[gsl_rng_uniform_int(rng, m)];
        if (g == GROUP) {
            const size_t *const idx[GROUP] = {draw, draw + n, draw + 2 * n, draw + 3 * n};
            estimate_aggregate_group(d, y, n_outputs, idx, m, boot + r * 2 * f, num);
        } else {
            estimate_aggregate(d, y, n_outputs, draw, m, boot + r * 2 * f, boot + r * 2 * f + f, num, num + f, NULL);
        }
        r += g;
    }
    for (size_t i = 0; i < 2 * f; ++i) {
        size_t cnt = 0;
        for (size_t r = 0; r < R; ++r)
            if (isfinite(boot[r * 2 * f + i]))
                tmp[cnt++] = boot[r * 2 * f + i];
        double lo = NAN, hi = NAN;
        if (cnt >= R / 2)
            percentile(tmp, cnt, d->o.level, &lo, &hi);
        if (i < f) {
            out->s1_lo[i] = lo;
            out->s1_hi[i] = hi;
        } else {
            out->st_lo[i - f] = lo;
            out->st_hi[i - f] = hi;
        }
    }
done:
    gsl_rng_free(rng);
    free(used);
    free(draw);
    free(boot);
    free(tmp);
    free(num);
    if (rc)
        phc_sobol_indices_clear(out);
    return rc;
}
