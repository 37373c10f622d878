/* The stretch-move ensemble sampler: see mcmc_stretch.h. */
#include "fit/engine/mcmc_stretch.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fit/engine/mcmc_dram.h" /* phc_mcmc_chains_clear */

phc_stretch_options phc_stretch_options_default(void)
{
    phc_stretch_options o;
    memset(&o, 0, sizeof o);
    o.n_iter = 2000;
    o.walkers = 32;
    o.a = 2.0;
    o.seed = 1;
    return o;
}

/* One density evaluation into its exchanged row: SS and log prior, NAN and
 * NAN where the posterior density is 0 (outside the support, model failed). */
static void eval_row(const phc_mcmc_target *t, const double *theta, double *row)
{
    double ss = NAN, lprior = 0;
    if (t->eval(t->data, theta, &ss, &lprior) != 0 || !isfinite(ss) || !isfinite(lprior))
        ss = lprior = NAN;
    row[0] = ss;
    row[1] = lprior;
}

/* log p(theta | y, s2) from a row (mcmc_target.h); -inf where it is 0. */
static double row_log_post(const double *row, double s2)
{
    return isfinite(row[0]) ? -0.5 * row[0] / s2 + row[1] : -INFINITY;
}

/* Evaluates thetas [0, n) (rows of d) into rows: here the share's block of
 * them, then the exchange; without a share, all of them. */
static int eval_batch(const phc_mcmc_target *t, const phc_stretch_share *sh, const double *theta, size_t n,
                      double *rows, phc_error *err)
{
    size_t lo = 0, hi = n;
    if (sh)
        sh->block(sh->data, n, &lo, &hi);
    for (size_t k = lo; k < hi && k < n; ++k)
        eval_row(t, theta + k * t->d, rows + k * PHC_STRETCH_ROW);
    return sh ? sh->exchange(sh->data, rows, n, err) : PHC_OK;
}

int phc_stretch_run(const phc_mcmc_target *t, const double *x0, const phc_stretch_options *o, phc_mcmc_chains *out,
                    phc_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t d = t->d, n = o->n_iter, W = o->walkers;
    const phc_stretch_share *sh = o->share;
    if (d == 0 || n < 2)
        return phc_error_set(err, PHC_ERR_INVALID, "stretch: needs d >= 1 and n_iter >= 2");
    if (W < 2 * d || W % 2)
        return phc_error_set(err, PHC_ERR_INVALID, "stretch: %zu walkers for %zu parameters: the ensemble needs an "
                             "even number of at least 2 d = %zu walkers (Goodman & Weare 2010)", W, d, 2 * d);
    if (!(o->a > 1))
        return phc_error_set(err, PHC_ERR_INVALID, "stretch: the scale a = %g must exceed 1", o->a);
    const size_t half = W / 2;
    out->chains = W;
    out->n_iter = n;
    out->d = d;
    out->theta = malloc(W * n * d * sizeof *out->theta);
    out->s2 = malloc(W * n * sizeof *out->s2);
    out->log_post = malloc(W * n * sizeof *out->log_post);
    double *x = malloc(W * d * sizeof *x), *lp = malloc(W * sizeof *lp), *ss = malloc(W * sizeof *ss);
    double *lpr = malloc(W * sizeof *lpr), *s2 = malloc(W * sizeof *s2);
    double *y = malloc(half * d * sizeof *y), *z = malloc(half * sizeof *z);
    double *rows = malloc(W * PHC_STRETCH_ROW * sizeof *rows);
    size_t *partner = malloc(half * sizeof *partner);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    if (!out->theta || !out->s2 || !out->log_post || !x || !lp || !ss || !lpr || !s2 || !y || !z || !rows ||
        !partner || !r)
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (sh) /* every process set up, or every process stops */
        rc = sh->agree(sh->data, rc, err);
    if (rc)
        goto done;
    gsl_rng_set(r, o->seed);
    memcpy(x, x0, W * d * sizeof *x);
    if ((rc = eval_batch(t, sh, x, W, rows, err)))
        goto done;
    for (size_t k = 0; k < W; ++k) {
        s2[k] = t->sample_sigma2 ? t->var0 : 1.0;
        ss[k] = rows[k * PHC_STRETCH_ROW];
        lpr[k] = rows[k * PHC_STRETCH_ROW + 1];
        lp[k] = row_log_post(rows + k * PHC_STRETCH_ROW, s2[k]);
        if (!(lp[k] > -INFINITY)) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "stretch: walker %zu starts where the posterior density is 0 "
                               "(outside the prior or the model fails there)", k + 1);
            goto done;
        }
    }
    for (size_t it = 0; it < n; ++it) {
        if (it > 0)
            for (int h = 0; h < 2; ++h) {
                /* move half h against the other half (its positions as they are now), in emcee's order: the
                   stretch factors, the partners, the densities, the acceptance draws */
                const size_t first = h ? half : 0, other = h ? 0 : half;
                for (size_t i = 0; i < half; ++i) {
                    const double zz = (o->a - 1) * gsl_rng_uniform(r) + 1;
                    z[i] = zz * zz / o->a;
                }
                for (size_t i = 0; i < half; ++i)
                    partner[i] = other + gsl_rng_uniform_int(r, half);
                for (size_t i = 0; i < half; ++i) {
                    const double *xk = x + (first + i) * d, *xj = x + partner[i] * d;
                    for (size_t c = 0; c < d; ++c)
                        y[i * d + c] = xj[c] + z[i] * (xk[c] - xj[c]);
                }
                if ((rc = eval_batch(t, sh, y, half, rows, err)))
                    goto done;
                for (size_t i = 0; i < half; ++i) {
                    const size_t k = first + i;
                    const double *row = rows + i * PHC_STRETCH_ROW;
                    const double lpy = row_log_post(row, s2[k]);
                    out->proposed++;
                    out->failed += !(lpy > -INFINITY);
                    const double la = (double)(d - 1) * log(z[i]) + lpy - lp[k];
                    const double u = gsl_rng_uniform_pos(r); /* drawn whatever lpy is */
                    if (lpy > -INFINITY && log(u) < la) {
                        memcpy(x + k * d, y + i * d, d * sizeof *y);
                        lp[k] = lpy;
                        ss[k] = row[0];
                        lpr[k] = row[1];
                        out->accepted++;
                    }
                }
            }
        for (size_t k = 0; k < W; ++k) {
            if (t->sample_sigma2) { /* Gibbs step of s2 (mcmc_target.h) */
                const double shape = 0.5 * (t->n0 + (double)t->n_obs), rate = 0.5 * (t->n0 * t->var0 + ss[k]);
                s2[k] = 1.0 / gsl_ran_gamma(r, shape, 1.0 / rate);
                lp[k] = -0.5 * ss[k] / s2[k] + lpr[k];
            }
            memcpy(out->theta + (k * n + it) * d, x + k * d, d * sizeof *x);
            out->s2[k * n + it] = s2[k];
            out->log_post[k * n + it] = lp[k];
        }
        if ((o->progress || sh) && (it % 50 == 0 || it + 1 == n)) {
            int stop = o->progress && o->progress(o->progress_data, (it + 1) * W, n * W)
                           ? phc_error_set(err, PHC_ERR_INTERNAL, "cancelled")
                           : PHC_OK;
            if (sh) /* every process stops, or none */
                stop = sh->agree(sh->data, stop, err);
            if ((rc = stop))
                goto done;
        }
    }
done:
    free(x);
    free(lp);
    free(ss);
    free(lpr);
    free(s2);
    free(y);
    free(z);
    free(rows);
    free(partner);
    gsl_rng_free(r);
    if (rc)
        phc_mcmc_chains_clear(out);
    return rc;
}
