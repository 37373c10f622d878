/* DRAM: see mcmc_dram.h. */
#include "fit/engine/mcmc_dram.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

phc_dram_options phc_dram_options_default(void)
{
    phc_dram_options o;
    memset(&o, 0, sizeof o);
    o.n_iter = 5000;
    o.chains = 4;
    o.adapt_every = 100;
    o.dr_scale = 0.2;
    o.seed = 1;
    return o;
}

void phc_mcmc_chains_clear(phc_mcmc_chains *c)
{
    if (!c)
        return;
    free(c->theta);
    free(c->s2);
    free(c->log_post);
    memset(c, 0, sizeof *c);
}

/* Lower Cholesky factor of a (d x d) into l; 0 when positive definite. */
static int cholesky(const double *a, size_t d, double *l)
{
    memset(l, 0, d * d * sizeof *l);
    for (size_t j = 0; j < d; ++j) {
        double s = a[j * d + j];
        for (size_t k = 0; k < j; ++k)
            s -= l[j * d + k] * l[j * d + k];
        if (!(s > 0) || !isfinite(s))
            return -1;
        l[j * d + j] = sqrt(s);
        for (size_t i = j + 1; i < d; ++i) {
            double v = a[i * d + j];
            for (size_t k = 0; k < j; ++k)
                v -= l[i * d + k] * l[j * d + k];
            l[i * d + j] = v / l[j * d + j];
        }
    }
    return 0;
}

/* (b - a)^T C^-1 (b - a) with C = L L^T: |L^-1 (b - a)|^2 (forward substitution). */
static double mahalanobis2(const double *l, size_t d, const double *a, const double *b, double *work)
{
    double q = 0;
    for (size_t i = 0; i < d; ++i) {
        double v = b[i] - a[i];
        for (size_t k = 0; k < i; ++k)
            v -= l[i * d + k] * work[k];
        work[i] = v / l[i * d + i];
        q += work[i] * work[i];
    }
    return q;
}

/* y = x + scale L z, z standard normal. */
static void propose(gsl_rng *r, const double *l, size_t d, double scale, const double *x, double *z, double *y)
{
    for (size_t i = 0; i < d; ++i)
        z[i] = gsl_ran_ugaussian(r);
    for (size_t i = 0; i < d; ++i) {
        double v = 0;
        for (size_t k = 0; k <= i; ++k)
            v += l[i * d + k] * z[k];
        y[i] = x[i] + scale * v;
    }
}

/* Log posterior at theta given s2; -INFINITY outside the support.  *ss gets SS. */
static double log_post(const phc_mcmc_target *t, const double *theta, double s2, double *ss)
{
    double lp = 0;
    *ss = NAN;
    if (t->eval(t->data, theta, ss, &lp) != 0 || !isfinite(*ss) || !isfinite(lp))
        return -INFINITY;
    return -0.5 * *ss / s2 + lp;
}

/* Gibbs step of s2 (mcmc_target.h). */
static double draw_s2(gsl_rng *r, const phc_mcmc_target *t, double ss)
{
    const double shape = 0.5 * (t->n0 + (double)t->n_obs), rate = 0.5 * (t->n0 * t->var0 + ss);
    return 1.0 / gsl_ran_gamma(r, shape, 1.0 / rate);
}

/* min(1, exp(a)) as a log, for a possibly -inf or nan. */
static double log_alpha(double num, double den)
{
    if (!(num > -INFINITY))
        return -INFINITY;
    const double a = num - den;
    return a < 0 ? a : 0;
}

int phc_dram_run(const phc_mcmc_target *t, const double *x0, const double *cov0, const phc_dram_options *o,
                 phc_mcmc_chains *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t d = t->d, n = o->n_iter, C = o->chains;
    if (d == 0 || n < 2 || C < 1)
        return phc_error_set(err, PHC_ERR_INVALID, "DRAM: needs d >= 1, n_iter >= 2 and a chain (d = %zu, n_iter = "
                             "%zu, chains = %zu)", d, n, C);
    const double sd = 2.4 * 2.4 / (double)d;
    out->chains = C;
    out->n_iter = n;
    out->d = d;
    out->theta = malloc(C * n * d * sizeof *out->theta);
    out->s2 = malloc(C * n * sizeof *out->s2);
    out->log_post = malloc(C * n * sizeof *out->log_post);
    double *l = malloc(d * d * sizeof *l), *ltry = malloc(d * d * sizeof *ltry), *cov = malloc(d * d * sizeof *cov), *mean = malloc(d * sizeof *mean);
    double *y1 = malloc(d * sizeof *y1), *y2 = malloc(d * sizeof *y2), *z = malloc(d * sizeof *z);
    double *work = malloc(d * sizeof *work);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    if (!out->theta || !out->s2 || !out->log_post || !l || !ltry || !cov || !mean || !y1 || !y2 || !z || !work || !r) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t c = 0; c < C && rc == PHC_OK; ++c) {
        if (o->have && o->have[c]) {
            memcpy(out->theta + c * n * d, o->have_draws->theta + c * n * d, n * d * sizeof *out->theta);
            memcpy(out->s2 + c * n, o->have_draws->s2 + c * n, n * sizeof *out->s2);
            memcpy(out->log_post + c * n, o->have_draws->log_post + c * n, n * sizeof *out->log_post);
            out->accepted += o->have_counts[4 * c];
            out->accepted_dr += o->have_counts[4 * c + 1];
            out->proposed += o->have_counts[4 * c + 2];
            out->failed += o->have_counts[4 * c + 3];
            continue;
        }
        const size_t before[4] = {out->accepted, out->accepted_dr, out->proposed, out->failed};
        gsl_rng_set(r, o->seed + 7919UL * c);
        for (size_t i = 0; i < d * d; ++i)
            cov[i] = sd * cov0[i];
        if (cholesky(cov, d, l) != 0) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "DRAM: the initial proposal covariance is not positive definite");
            goto done;
        }
        double *th = out->theta + c * n * d;
        memcpy(th, x0 + c * d, d * sizeof *th);
        double s2 = 1, ss;
        if (t->sample_sigma2)
            s2 = t->var0;
        double lp = log_post(t, th, s2, &ss);
        if (!(lp > -INFINITY)) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "DRAM: chain %zu starts where the posterior density is 0 "
                               "(outside the prior or the model fails there)", c + 1);
            goto done;
        }
        if (t->sample_sigma2) {
            s2 = draw_s2(r, t, ss);
            lp = -0.5 * ss / s2 + (lp + 0.5 * ss / t->var0);
        }
        out->s2[c * n] = s2;
        out->log_post[c * n] = lp;
        for (size_t it = 1; it < n; ++it) {
            const double *x = th + (it - 1) * d;
            double *xn = th + it * d;
            memcpy(xn, x, d * sizeof *xn);
            out->proposed++;
            double ss1, ss2;
            propose(r, l, d, 1.0, x, z, y1);
            const double lp1 = log_post(t, y1, s2, &ss1);
            out->failed += !(lp1 > -INFINITY);
            const double la1 = log_alpha(lp1, lp);
            if (log(gsl_rng_uniform_pos(r)) < la1) {
                memcpy(xn, y1, d * sizeof *xn);
                lp = lp1;
                ss = ss1;
                out->accepted++;
            } else if (o->dr_scale > 0) {
                /* second stage: a smaller step from x */
                propose(r, l, d, o->dr_scale, x, z, y2);
                const double lp2 = log_post(t, y2, s2, &ss2);
                out->failed += !(lp2 > -INFINITY);
                if (lp2 > -INFINITY) {
                    const double la_back = log_alpha(lp1, lp2); /* a1(y2, y1) */
                    const double q_fwd = -0.5 * mahalanobis2(l, d, x, y1, work);
                    const double q_back = -0.5 * mahalanobis2(l, d, y2, y1, work);
                    const double one_minus_back = 1 - exp(la_back), one_minus_fwd = 1 - exp(la1);
                    if (one_minus_back > 0 && one_minus_fwd > 0) {
                        const double num = lp2 + q_back + log(one_minus_back);
                        const double den = lp + q_fwd + log(one_minus_fwd);
                        if (log(gsl_rng_uniform_pos(r)) < log_alpha(num, den)) {
                            memcpy(xn, y2, d * sizeof *xn);
                            lp = lp2;
                            ss = ss2;
                            out->accepted++;
                            out->accepted_dr++;
                        }
                    }
                }
            }
            if (t->sample_sigma2) {
                const double lprior = lp + 0.5 * ss / s2;
                s2 = draw_s2(r, t, ss);
                lp = -0.5 * ss / s2 + lprior;
            }
            out->s2[c * n + it] = s2;
            out->log_post[c * n + it] = lp;
            /* adaptation (Haario et al. 2001): the covariance of this chain so far */
            if (o->adapt_every && (it + 1) % o->adapt_every == 0) {
                const size_t m = it + 1;
                for (size_t j = 0; j < d; ++j) {
                    double s = 0;
                    for (size_t k = 0; k < m; ++k)
                        s += th[k * d + j];
                    mean[j] = s / (double)m;
                }
                double diag = 0;
                for (size_t a = 0; a < d; ++a)
                    for (size_t b = 0; b <= a; ++b) {
                        double s = 0;
                        for (size_t k = 0; k < m; ++k)
                            s += (th[k * d + a] - mean[a]) * (th[k * d + b] - mean[b]);
                        cov[a * d + b] = cov[b * d + a] = s / (double)(m - 1);
                        if (a == b)
                            diag += cov[a * d + a];
                    }
                /* eps relative to each variance (eps I in standardised coordinates): parameters of very
                   different magnitudes keep their own scales */
                for (size_t i = 0; i < d * d; ++i)
                    cov[i] *= sd;
                for (size_t j = 0; j < d; ++j)
                    cov[j * d + j] *= 1 + 1e-10;
                /* nothing accepted yet (a zero covariance): keep the proposal */
                if (diag > 0 && cholesky(cov, d, ltry) == 0)
                    memcpy(l, ltry, d * d * sizeof *l);
            }
            if (o->progress && (it % 200 == 0 || it + 1 == n) &&
                o->progress(o->progress_data, c * n + it + 1, C * n)) {
                rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
                goto done;
            }
        }
        if (o->chain_done) {
            const size_t counts[4] = {out->accepted - before[0], out->accepted_dr - before[1],
                                      out->proposed - before[2], out->failed - before[3]};
            if ((rc = o->chain_done(o->chain_data, c, out, counts, err)))
                goto done;
        }
    }
done:
    free(l);
    free(ltry);
    free(cov);
    free(mean);
    free(y1);
    free(y2);
    free(z);
    free(work);
    gsl_rng_free(r);
    if (rc)
        phc_mcmc_chains_clear(out);
    return rc;
}
