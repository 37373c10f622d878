/* MCMC samplers and diagnostics against exact answers:
 *  - the integrated autocorrelation time of an AR(1) process x_t = phi
 *    x_{t-1} + e_t is (1 + phi) / (1 - phi) (Sokal 1997 §3);
 *  - split-R-hat is near 1 for chains of one distribution and far above 1
 *    for chains of two;
 *  - linear-Gaussian problem y = a + b x + e, e ~ N(0, sigma^2), sigma
 *    known, flat prior: the posterior is N(theta_hat, sigma^2 (X^T X)^-1)
 *    (BDA3 §14.2).  Unknown sigma with p(sigma^2) ∝ 1/sigma^2 (n0 = 0):
 *    theta is multivariate t with nu = n - 2 degrees of freedom and scale
 *    s^2 (X^T X)^-1, covariance nu / (nu - 2) s^2 (X^T X)^-1 (BDA3 §14.2).
 *    Both samplers' means must lie within 4 Monte Carlo standard errors
 *    (sd / sqrt(ESS), ESS from the integrated autocorrelation time) of the
 *    exact mean, their standard deviations within 4 sqrt(1 / (2 ESS))
 *    (relative; the large-sample standard error of a standard deviation)
 *    and the correlation within 4 (1 - rho^2) / sqrt(ESS);
 *  - the same seed gives the same chains, bit for bit;
 *  - phc_mcmc_summarise's median and 2.5% / 97.5% quantiles (found by
 *    selection) equal, bit for bit, GSL's quantiles of the sorted draws, on
 *    random, tied, sorted, reversed and tiny samples. */
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/engine/mcmc_diagnostics.h"
#include "fit/engine/mcmc_dram.h"
#include "fit/engine/mcmc_stretch.h"
#include "fit/engine/prior.h"

#define NOBS 20
typedef struct lin {
    double x[NOBS], y[NOBS], sigma;
} lin;

static int lin_eval(void *data, const double *th, double *ss, double *lprior)
{
    const lin *p = data;
    double s = 0;
    for (int i = 0; i < NOBS; ++i) {
        const double r = (p->y[i] - th[0] - th[1] * p->x[i]) / p->sigma;
        s += r * r;
    }
    *ss = s;
    *lprior = 0; /* flat */
    return 0;
}

/* Pools chains x n_iter x d after burn-in (first half) into per-parameter columns. */
static double *column(const phc_mcmc_chains *c, size_t j, size_t burn)
{
    const size_t m = c->n_iter - burn;
    double *v = malloc(c->chains * m * sizeof *v);
    for (size_t ch = 0; ch < c->chains; ++ch)
        for (size_t t = 0; t < m; ++t)
            v[ch * m + t] = c->theta[(ch * c->n_iter + burn + t) * c->d + j];
    return v;
}

static void compare(const char *what, const phc_mcmc_chains *c, const double *mean, const double *cov)
{
    const size_t burn = c->n_iter / 2, m = c->n_iter - burn;
    phc_mcmc_summary s[2];
    double *v[2];
    for (size_t j = 0; j < 2; ++j) {
        v[j] = column(c, j, burn);
        phc_error err;
        CHECK(phc_mcmc_summarise(v[j], c->chains, m, &s[j], &err) == PHC_OK);
    }
    double cxy = 0;
    for (size_t i = 0; i < c->chains * m; ++i)
        cxy += (v[0][i] - s[0].mean) * (v[1][i] - s[1].mean);
    const double rho = cxy / (double)(c->chains * m - 1) / (s[0].sd * s[1].sd);
    const double rho_exact = cov[1] / sqrt(cov[0] * cov[3]);
    printf("%s: acceptance %.3f, %zu chains x %zu kept draws\n", what,
           (double)c->accepted / (double)c->proposed, c->chains, m);
    for (size_t j = 0; j < 2; ++j) {
        const double sd_exact = sqrt(cov[j * 3]);
        const double tol_mean = 4 * s[j].mcse_mean, tol_sd = 4 * sqrt(1 / (2 * s[j].ess));
        printf("  %s: mean %.6f exact %.6f (|diff| %.2e, 4 MCSE %.2e); sd %.6f exact %.6f (rel diff %.3f, tol %.3f); "
               "tau %.2f ESS %.0f R-hat %.4f\n", j ? "b" : "a", s[j].mean, mean[j], fabs(s[j].mean - mean[j]), tol_mean,
               s[j].sd, sd_exact, fabs(s[j].sd / sd_exact - 1), tol_sd, s[j].tau, s[j].ess, s[j].rhat);
        CHECK(fabs(s[j].mean - mean[j]) <= tol_mean);
        CHECK(fabs(s[j].sd / sd_exact - 1) <= tol_sd);
        CHECK(s[j].rhat < 1.01);
        CHECK(s[j].ess > 400);
    }
    const double ess = s[0].ess < s[1].ess ? s[0].ess : s[1].ess;
    const double tol_rho = 4 * (1 - rho_exact * rho_exact) / sqrt(ess);
    printf("  correlation %.4f exact %.4f (|diff| %.4f, tol %.4f)\n", rho, rho_exact, fabs(rho - rho_exact), tol_rho);
    CHECK(fabs(rho - rho_exact) <= tol_rho);
    free(v[0]);
    free(v[1]);
}

/* The quantiles of phc_mcmc_summarise against a full sort. */
/* The FFT autocorrelation (mcmc_diagnostics.c) against the sums lag by
 * lag, on AR(1) chains of odd and power-of-two lengths and with one chain
 * that never moved (left out of the average): tau and the window equal the
 * direct computation's to rounding. */
static double direct_tau(const double *x, size_t chains, size_t n, double c, size_t *window)
{
    double tau = 1;
    size_t m;
    for (m = 1; m < n; ++m) {
        double rho = 0;
        size_t used = 0;
        for (size_t ch = 0; ch < chains; ++ch) {
            const double *v = x + ch * n;
            double mean = 0, var = 0, s = 0;
            for (size_t t = 0; t < n; ++t)
                mean += v[t];
            mean /= (double)n;
            for (size_t t = 0; t < n; ++t)
                var += (v[t] - mean) * (v[t] - mean);
            if (!(var > 0))
                continue;
            for (size_t t = 0; t + m < n; ++t)
                s += (v[t] - mean) * (v[t + m] - mean);
            rho += s / var;
            ++used;
        }
        tau += 2 * rho / (double)used;
        if ((double)m >= c * tau)
            break;
    }
    *window = m < n ? m : n - 1;
    return tau;
}

static void test_autocorr_fft_equals_direct(void)
{
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 11);
    const size_t sizes[3] = {777, 1024, 3001};
    const double phis[3] = {0.5, 0.9, 0.97};
    for (int k = 0; k < 3; ++k) {
        const size_t chains = 5, n = sizes[k];
        double *x = malloc(chains * n * sizeof *x);
        for (size_t c = 0; c < chains; ++c) {
            double v = 0;
            for (size_t t = 0; t < n; ++t) {
                v = phis[k] * v + gsl_ran_ugaussian(r);
                x[c * n + t] = c == 2 ? 1.5 : 100 + v; /* chain 3 never moved */
            }
        }
        size_t w_fft, w_dir;
        const double t_fft = phc_mcmc_autocorr_time(x, chains, n, 5, &w_fft, NULL);
        const double t_dir = direct_tau(x, chains, n, 5, &w_dir);
        printf("autocorrelation by FFT, n = %zu, phi = %.2f: tau %.15g (direct sums %.15g, rel. diff %.2e), window "
               "%zu (%zu)\n", n, phis[k], t_fft, t_dir, fabs(t_fft - t_dir) / t_dir, w_fft, w_dir);
        CHECK(fabs(t_fft - t_dir) <= 1e-10 * t_dir);
        CHECK(w_fft == w_dir);
        free(x);
    }
    gsl_rng_free(r);
}

static void test_quantiles_by_selection(void)
{
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 5);
    const size_t sizes[6] = {2, 3, 7, 40, 1001, 96032};
    int all = 1, cases = 0;
    for (int kind = 0; kind < 4; ++kind)
        for (int si = 0; si < 6; ++si) {
            const size_t n = sizes[si];
            double *x = malloc(n * sizeof *x), *sorted = malloc(n * sizeof *sorted);
            for (size_t i = 0; i < n; ++i) {
                const double g = gsl_ran_gaussian(r, 2.0);
                x[i] = kind == 0 ? g : kind == 1 ? floor(g) /* many ties */ : kind == 2 ? (double)i : -(double)i;
            }
            /* one chain of n draws (two when n is even: the summary needs n >= 2 per chain) */
            const size_t chains = n % 2 == 0 && n > 2 ? 2 : 1;
            phc_mcmc_summary sm;
            phc_error err;
            CHECK(phc_mcmc_summarise(x, chains, n / chains, &sm, &err) == PHC_OK);
            memcpy(sorted, x, n * sizeof *x);
            gsl_sort(sorted, 1, n);
            const double q[3] = {gsl_stats_quantile_from_sorted_data(sorted, 1, n, 0.5),
                                 gsl_stats_quantile_from_sorted_data(sorted, 1, n, 0.025),
                                 gsl_stats_quantile_from_sorted_data(sorted, 1, n, 0.975)};
            const int same = memcmp(&q[0], &sm.median, sizeof q[0]) == 0 && memcmp(&q[1], &sm.q025, sizeof q[1]) == 0 &&
                             memcmp(&q[2], &sm.q975, sizeof q[2]) == 0;
            CHECK(same);
            all &= same;
            ++cases;
            free(x);
            free(sorted);
        }
    printf("quantiles by selection: %d samples (random, tied, sorted, reversed; n = 2 to 96032): %s bit for bit to "
           "GSL's on the sorted draws\n", cases, all ? "equal" : "NOT equal");
    gsl_rng_free(r);
}

int main(void)
{
    test_quantiles_by_selection();
    test_autocorr_fft_equals_direct();
    phc_error err;
    /* ---- AR(1): tau = (1 + phi) / (1 - phi) */
    {
        gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
        gsl_rng_set(r, 7);
        const size_t chains = 4, n = 50000;
        const double phi = 0.8, exact = (1 + phi) / (1 - phi);
        double *x = malloc(chains * n * sizeof *x);
        for (size_t c = 0; c < chains; ++c) {
            double v = gsl_ran_gaussian(r, 1 / sqrt(1 - phi * phi));
            for (size_t t = 0; t < n; ++t) {
                v = phi * v + gsl_ran_ugaussian(r);
                x[c * n + t] = v;
            }
        }
        size_t w;
        int ok;
        const double tau = phc_mcmc_autocorr_time(x, chains, n, 5, &w, &ok);
        /* the estimator's relative sd is about sqrt(2 (2M + 1) / N) (Sokal §3.1) */
        const double tol = 4 * exact * sqrt(2.0 * (2.0 * (double)w + 1) / (double)(chains * n));
        printf("AR(1) phi = %.1f: tau %.4f exact %.4f (|diff| %.4f, tol %.4f), window %zu, reliable %d\n", phi, tau,
               exact, fabs(tau - exact), tol, w, ok);
        CHECK(fabs(tau - exact) <= tol);
        CHECK(ok);
        const double rh = phc_mcmc_split_rhat(x, chains, n);
        for (size_t t = 0; t < n; ++t) /* shift one chain by 3 sd */
            x[t] += 3 / sqrt(1 - phi * phi);
        const double rh_bad = phc_mcmc_split_rhat(x, chains, n);
        printf("split-R-hat: one distribution %.5f, one chain shifted by 3 sd %.3f\n", rh, rh_bad);
        CHECK(rh < 1.01);
        CHECK(rh_bad > 1.2);
        free(x);
        gsl_rng_free(r);
    }
    /* ---- linear Gaussian */
    lin p;
    p.sigma = 0.5;
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 3);
    for (int i = 0; i < NOBS; ++i) {
        p.x[i] = (double)i / 2;
        p.y[i] = 1.5 + 0.7 * p.x[i] + gsl_ran_gaussian(r, p.sigma);
    }
    gsl_rng_free(r);
    double sx = 0, sxx = 0, sy = 0, sxy = 0;
    for (int i = 0; i < NOBS; ++i) {
        sx += p.x[i];
        sxx += p.x[i] * p.x[i];
        sy += p.y[i];
        sxy += p.x[i] * p.y[i];
    }
    const double det = NOBS * sxx - sx * sx;
    const double xtx_inv[4] = {sxx / det, -sx / det, -sx / det, NOBS / det};
    const double mean[2] = {(sxx * sy - sx * sxy) / det, (NOBS * sxy - sx * sy) / det};
    double cov[4], rss = 0;
    for (int i = 0; i < 4; ++i)
        cov[i] = p.sigma * p.sigma * xtx_inv[i];
    for (int i = 0; i < NOBS; ++i) {
        const double e = p.y[i] - mean[0] - mean[1] * p.x[i];
        rss += e * e;
    }
    printf("exact posterior (known sigma %.2f): mean (%.6f, %.6f), sd (%.6f, %.6f)\n", p.sigma, mean[0], mean[1],
           sqrt(cov[0]), sqrt(cov[3]));
    phc_mcmc_target t = {2, lin_eval, &p, 0, NOBS, 1, 0};
    /* starts: chain 0 at the optimum, others 2 sd away (overdispersed) */
    double x0[64 * 2];
    for (int k = 0; k < 64; ++k) {
        x0[2 * k] = mean[0] + (k ? 2 * sqrt(cov[0]) * ((k % 3) - 1) : 0);
        x0[2 * k + 1] = mean[1] + (k ? 2 * sqrt(cov[3]) * (((k / 3) % 3) - 1) : 0);
    }
    phc_dram_options dop = phc_dram_options_default();
    dop.n_iter = 20000;
    dop.seed = 11;
    phc_mcmc_chains c1, c2;
    CHECK(phc_dram_run(&t, x0, cov, &dop, &c1, &err) == PHC_OK);
    compare("DRAM, known sigma", &c1, mean, cov);
    printf("  delayed-rejection acceptances %zu of %zu accepted\n", c1.accepted_dr, c1.accepted);
    CHECK(c1.accepted_dr > 0);
    CHECK(phc_dram_run(&t, x0, cov, &dop, &c2, &err) == PHC_OK);
    const int same = memcmp(c1.theta, c2.theta, c1.chains * c1.n_iter * c1.d * sizeof(double)) == 0;
    printf("DRAM: the same seed gives the same chains: %s\n", same ? "yes" : "no");
    CHECK(same);
    phc_mcmc_chains_clear(&c2);
    dop.seed = 12;
    CHECK(phc_dram_run(&t, x0, cov, &dop, &c2, &err) == PHC_OK);
    const int differ = memcmp(c1.theta, c2.theta, c1.chains * c1.n_iter * c1.d * sizeof(double)) != 0;
    printf("DRAM: another seed gives other chains: %s\n", differ ? "yes" : "no");
    CHECK(differ);
    phc_mcmc_chains_clear(&c1);
    phc_mcmc_chains_clear(&c2);

    phc_stretch_options sop = phc_stretch_options_default();
    sop.n_iter = 12000;
    sop.walkers = 32;
    sop.seed = 5;
    CHECK(phc_stretch_run(&t, x0, &sop, &c1, &err) == PHC_OK);
    compare("stretch, known sigma", &c1, mean, cov);
    CHECK(phc_stretch_run(&t, x0, &sop, &c2, &err) == PHC_OK);
    const int same2 = memcmp(c1.theta, c2.theta, c1.chains * c1.n_iter * c1.d * sizeof(double)) == 0;
    printf("stretch: the same seed gives the same ensemble: %s\n", same2 ? "yes" : "no");
    CHECK(same2);
    phc_mcmc_chains_clear(&c1);
    phc_mcmc_chains_clear(&c2);

    /* ---- unknown sigma: Gibbs step for s2 with n0 = 0 (p(s2) ∝ 1/s2) */
    {
        lin q = p;
        q.sigma = 1; /* unweighted residuals */
        const double nu = NOBS - 2, s2 = rss / nu;
        double covt[4];
        for (int i = 0; i < 4; ++i)
            covt[i] = nu / (nu - 2) * s2 * xtx_inv[i];
        printf("exact posterior (unknown sigma, s^2 = %.6f, nu = %.0f): sd (%.6f, %.6f)\n", s2, nu, sqrt(covt[0]),
               sqrt(covt[3]));
        phc_mcmc_target tu = {2, lin_eval, &q, 1, NOBS, s2, 0};
        dop.seed = 13;
        CHECK(phc_dram_run(&tu, x0, covt, &dop, &c1, &err) == PHC_OK);
        compare("DRAM, sigma sampled", &c1, mean, covt);
        phc_mcmc_chains_clear(&c1);
        CHECK(phc_stretch_run(&tu, x0, &sop, &c1, &err) == PHC_OK);
        compare("stretch, sigma sampled", &c1, mean, covt);
        phc_mcmc_chains_clear(&c1);
    }
    /* ---- prior log densities: differences equal those of GSL's densities */
    {
        const phc_prior nrm = {PHC_PRIOR_NORMAL, 2.0, 0.5, 0.0, INFINITY};
        const phc_prior lnm = {PHC_PRIOR_LOG_NORMAL, -1.0, 0.7, 0.0, INFINITY};
        const phc_prior lun = {PHC_PRIOR_LOG_UNIFORM, 0.1, 10.0, 0.1, 10.0};
        const phc_prior uni = {PHC_PRIOR_UNIFORM, 1.0, 3.0, 1.0, 3.0};
        const double x1 = 1.3, x2 = 2.9;
        const double dn = phc_prior_log_density(&nrm, x1) - phc_prior_log_density(&nrm, x2);
        const double dn_gsl = log(gsl_ran_gaussian_pdf(x1 - 2.0, 0.5) / gsl_ran_gaussian_pdf(x2 - 2.0, 0.5));
        const double dl = phc_prior_log_density(&lnm, x1) - phc_prior_log_density(&lnm, x2);
        const double dl_gsl = log(gsl_ran_lognormal_pdf(x1, -1.0, 0.7) / gsl_ran_lognormal_pdf(x2, -1.0, 0.7));
        const double du = phc_prior_log_density(&lun, x1) - phc_prior_log_density(&lun, x2);
        printf("prior log-density differences: normal %.15g (GSL %.15g), log-normal %.15g (GSL %.15g), "
               "log-uniform %.15g (exact %.15g)\n", dn, dn_gsl, dl, dl_gsl, du, log(x2 / x1));
        CHECK_NEAR(dn, dn_gsl, 1e-12, 1e-12);
        CHECK_NEAR(dl, dl_gsl, 1e-12, 1e-12);
        CHECK_NEAR(du, log(x2 / x1), 1e-12, 1e-12);
        CHECK(phc_prior_log_density(&uni, 2.0) == 0);
        CHECK(phc_prior_log_density(&uni, 3.5) == -INFINITY);
        CHECK(phc_prior_log_density(&nrm, -0.1) == -INFINITY); /* truncated at 0 */
        CHECK(phc_prior_log_density(&lnm, 0.0) == -INFINITY);
    }
    /* ---- bad input */
    sop.walkers = 3;
    CHECK(phc_stretch_run(&t, x0, &sop, &c1, &err) == PHC_ERR_INVALID);
    printf("3 walkers: %s\n", err.message);
    CHECK_STR_CONTAINS(err.message, "at least 2 d = 4 walkers");
    return check_finish("mcmc");
}
