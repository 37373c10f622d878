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

static double log_post(const phc_mcmc_target *t, const double *theta, double s2, double *ss, double *lprior)
{
    *ss = NAN;
    *lprior = 0;
    if (t->eval(t->data, theta, ss, lprior) != 0 || !isfinite(*ss) || !isfinite(*lprior))
        return -INFINITY;
    return -0.5 * *ss / s2 + *lprior;
}

int phc_stretch_run(const phc_mcmc_target *t, const double *x0, const phc_stretch_options *o, phc_mcmc_chains *out,
                    phc_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t d = t->d, n = o->n_iter, W = o->walkers;
    if (d == 0 || n < 2)
        return phc_error_set(err, PHC_ERR_INVALID, "stretch: needs d >= 1 and n_iter >= 2");
    if (W < 2 * d || W % 2)
        return phc_error_set(err, PHC_ERR_INVALID, "stretch: %zu walkers for %zu parameters: the ensemble needs an "
                             "even number of at least 2 d = %zu walkers (Goodman & Weare 2010)", W, d, 2 * d);
    if (!(o->a > 1))
        return phc_error_set(err, PHC_ERR_INVALID, "stretch: the scale a = %g must exceed 1", o->a);
    out->chains = W;
    out->n_iter = n;
    out->d = d;
    out->theta = malloc(W * n * d * sizeof *out->theta);
    out->s2 = malloc(W * n * sizeof *out->s2);
    out->log_post = malloc(W * n * sizeof *out->log_post);
    double *x = malloc(W * d * sizeof *x), *lp = malloc(W * sizeof *lp), *ss = malloc(W * sizeof *ss);
    double *lpr = malloc(W * sizeof *lpr), *s2 = malloc(W * sizeof *s2), *y = malloc(d * sizeof *y);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    if (!out->theta || !out->s2 || !out->log_post || !x || !lp || !ss || !lpr || !s2 || !y || !r) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    gsl_rng_set(r, o->seed);
    memcpy(x, x0, W * d * sizeof *x);
    for (size_t k = 0; k < W; ++k) {
        s2[k] = t->sample_sigma2 ? t->var0 : 1.0;
        lp[k] = log_post(t, x + k * d, s2[k], &ss[k], &lpr[k]);
        if (!(lp[k] > -INFINITY)) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "stretch: walker %zu starts where the posterior density is 0 "
                               "(outside the prior or the model fails there)", k + 1);
            goto done;
        }
    }
    const size_t half = W / 2;
    for (size_t it = 0; it < n; ++it) {
        if (it > 0)
            for (int h = 0; h < 2; ++h) {
                /* move half h against the other half (its positions as they are now) */
                const size_t first = h ? half : 0, other = h ? 0 : half;
                for (size_t k = first; k < first + half; ++k) {
                    const size_t j = other + gsl_rng_uniform_int(r, half);
                    const double u = gsl_rng_uniform(r);
                    const double zz = (o->a - 1) * u + 1, z = zz * zz / o->a;
                    for (size_t i = 0; i < d; ++i)
                        y[i] = x[j * d + i] + z * (x[k * d + i] - x[j * d + i]);
                    double ssy, lpry;
                    const double lpy = log_post(t, y, s2[k], &ssy, &lpry);
                    out->proposed++;
                    out->failed += !(lpy > -INFINITY);
                    const double la = (double)(d - 1) * log(z) + lpy - lp[k];
                    if (lpy > -INFINITY && log(gsl_rng_uniform_pos(r)) < la) {
                        memcpy(x + k * d, y, d * sizeof *y);
                        lp[k] = lpy;
                        ss[k] = ssy;
                        lpr[k] = lpry;
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
        if (o->progress && (it % 50 == 0 || it + 1 == n) && o->progress(o->progress_data, (it + 1) * W, n * W)) {
            rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
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
    gsl_rng_free(r);
    if (rc)
        phc_mcmc_chains_clear(out);
    return rc;
}
