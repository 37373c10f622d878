/* Coverage of the shoot_traces kind's 95% intervals (fit/costs/shoot_traces.h;
 * README "Fitting growth to traced shoots"): one traced plant is one draw of
 * a random process, so an honest interval covers the truth in about 95% of
 * plants drawn with the same parameters.
 *
 * N model plants (trace seeds 1001 .. 1000 + N, default N = 16) are grown
 * by the climbing model (model/climbing_growth.h) at the same truth
 * (BP 0.3, V 0.6, η 0.02 s⁻¹, τ 0.5 s⁻¹, r 0.15 s⁻¹, apical dominance 0.6,
 * max order 2; a wall y = 0 3 cm behind the seed, light from (0, 1, 2)),
 * 60 s in steps of 0.5 s, and traced every 10 s (phc_shoot_traces_from_model).
 * Plant i is fitted with its own K model seeds (default K = 8; seeds
 * 100000 + 1000 i ..: the model mean's own error then differs between the
 * plants, so the N trials are independent, as the binomial interval below
 * assumes) from starts 30-50% off, absolute sigmas, two ways, as
 * `phytocal fit` does them:
 *   start:  Σ at the start values (covariance_at: start, the default);
 *   fitted: Σ recomputed at the fitted values and the fit solved again until
 *           the estimates settle (covariance_at: fitted; phc_fit_run's
 *           reweight rounds).
 * Per plant it prints every estimate and interval (* = the truth outside)
 * and two diagnostics: χ²/n = |L⁻¹(traced − model)|²/n at the TRUE values
 * with the Σ the start fit used and with Σ recomputed at the true values
 * (about 1 when Σ describes the traced plant's scatter around the K-seed
 * mean; the model's K-seed mean at the truth is the same in both).  Then,
 * per parameter and way, the count of intervals that cover the truth with
 * its binomial 95% interval (Clopper–Pearson), and the spread of the
 * standardised errors z = (estimate − truth)/stderr (sd about 1 when the
 * stderr is honest, above 1 when the intervals are too narrow).
 * Writes shoot_traces_coverage.md.  Exit 1 when a fit fails or the check
 * fails, which states what the README says of these intervals: both ways
 * cover the truth less often than 95% (the Clopper–Pearson interval of the
 * pooled coverage lies below 0.95), and not because Σ is too narrow (the
 * mean χ²/n at the truth with Σ at the truth is below 1).
 *
 * With `profile` or `bootstrap [B]` as the fourth argument (not run in
 * CI: many fits per plant) the fitted way's profile-likelihood intervals or
 * parametric-bootstrap intervals (fit_plant) and their coverage too; with
 * `starts S` every fit is a multistart fit (S starts: the configured one
 * and Sobol points in the box, the lowest cost kept).
 *
 * Usage: notebook_shoot_traces_coverage OUTPUT_DIR [N] [K] [profile | bootstrap [B] | starts S] */
#include <gsl/gsl_cdf.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/shoot_traces.h"
#include "fit/engine/fit.h"
#include "fit/engine/profile.h"
#include "fit/engine/problem.h"
#include "measurements/shoot_traces.h"
#include "notebook_plot.h"
#include "tests/shoot_traces_wall_plant.h"

#define NP 5
#define NWAYS 2
static const char *const names[NP + 1] = {"branch_probability", "direction_variance", "phototropism",
                                          "surface_adaption", "growth_rate", NULL};
static const double *const truth = shoot_traces_wall_truth, *const start = shoot_traces_wall_start;
static const double *const lo = shoot_traces_wall_lower, *const hi = shoot_traces_wall_upper;
static const char *const way[NWAYS] = {"start", "fitted"};

static int is_param(const char *name, void *user)
{
    (void)user;
    for (const char *const *l = names; *l; ++l)
        if (!strcmp(*l, name)) return 1;
    return 0;
}

/* |L⁻¹(traced − model at the true values)|² / n under ds's current Σ; NAN when the model fails. */
static double chi2_at_truth(phc_dataset *ds)
{
    double *yhat = malloc(ds->n * sizeof *yhat), c = NAN;
    if (yhat && !ds->ops->predict(ds, truth, yhat, NULL)) {
        c = 0;
        for (size_t i = 0; i < ds->n; ++i) c += (ds->y[i] - yhat[i]) * (ds->y[i] - yhat[i]);
        c /= (double)ds->n;
    }
    free(yhat);
    return c;
}

typedef enum { EXTRA_NONE, EXTRA_PROFILE, EXTRA_BOOTSTRAP, EXTRA_MULTISTART } extra_kind;

static size_t fit_starts = 1; /* starts per fit (multistart: the configured start and Sobol points in the box) */

typedef struct fit_out {
    double est[NP], se[NP], ci[NP][2];
    size_t rounds;
    int settled;
    double chi2_start, chi2_truth; /* diagnostics (way start only) */
    double xci[NP][2];             /* the extra intervals (profile or bootstrap), else NAN */
    double bci[NP][2];             /* bootstrap: the interval about the bias-corrected estimate */
} fit_out;

/* The plant set-up of the notebook: plant pl's model seeds, traced plant seed `trace_seed`. */
static phc_shoot_traces_options plant_options(int pl, size_t K, int fitted, uint64_t trace_seed)
{
    phc_shoot_traces_options o = shoot_traces_wall_options(trace_seed);
    o.seeds = K;
    o.first_seed = 100000 + 1000 * (uint64_t)pl;
    o.is_parameter = is_param;
    o.covariance_at_fitted = fitted;
    return o;
}

/* Grows o's plant at values `at`, traces it every 10 s for 60 s and fits
 * it from values s (the data set's Σ at s) into r (est, se, ci, rounds);
 * with keep, *keep is the problem (owning the data set) for more work.
 * 0 or 1 (failed, message on stderr). */
static int fit_traces(phc_shoot_traces_options o, const double at[NP], const double s[NP], fit_out *r,
                      phc_problem **keep)
{
    static const double times[6] = {10, 20, 30, 40, 50, 60};
    phc_error err;
    phc_error_clear(&err);
    phc_shoot_traces *traces = NULL; /* the data set takes them */
    shoot_traces_wall_set(&o.plant, at);
    if (phc_shoot_traces_from_model(&o, times, 6, &traces, &err)) {
        fprintf(stderr, "traces: %s\n", err.message);
        return 1;
    }
    shoot_traces_wall_set(&o.plant, s); /* the fit knows only the starts */
    phc_dataset *ds = NULL;
    if (phc_shoot_traces_new(traces, &o, &ds, &err)) {
        fprintf(stderr, "data set: %s\n", err.message);
        return 1;
    }
    ds->name = strdup("model-traces");
    r->chi2_start = chi2_at_truth(ds);
    phc_problem *pb = phc_problem_new("coverage");
    pb->options.absolute_sigma = 1;
    pb->options.starts = fit_starts;
    for (size_t j = 0; j < NP; ++j) {
        phc_problem_add_parameter(pb, names[j], s[j], NULL, &err);
        pb->params[j].lower = lo[j];
        pb->params[j].upper = hi[j];
    }
    phc_fit_result *res = NULL;
    int bad = phc_problem_bind_by_name(pb, ds, &err) || phc_problem_add_dataset(pb, ds, &err) ||
              phc_fit_run(pb, NULL, NULL, &res, &err) || !res;
    if (!bad) {
        for (size_t j = 0; j < NP; ++j) {
            r->est[j] = res->params[j].value;
            r->se[j] = res->params[j].stderr_;
            r->ci[j][0] = res->params[j].ci_lo;
            r->ci[j][1] = res->params[j].ci_hi;
            r->xci[j][0] = r->xci[j][1] = r->bci[j][0] = r->bci[j][1] = NAN;
        }
        phc_shoot_traces_covariance_rounds(ds, &r->rounds, NULL, &r->settled);
    } else {
        fprintf(stderr, "fit: %s\n", err.message);
    }
    phc_fit_result_free(res);
    if (keep && !bad)
        *keep = pb;
    else
        phc_problem_free(pb); /* frees ds */
    return bad;
}

/* Fits plant pl's traces (seed 1001 + pl) the given way into *r, with the
 * extra intervals: profile likelihood (fit/engine/profile.h, at the final
 * covariance), or a parametric bootstrap (B plants grown at the estimates,
 * seeds 500000 + 1000 pl + b, each fitted as the plant was, from the same
 * starts (fitted from the estimates, the solver stays where it starts):
 * estimate ± 1.96 × the sd of their estimates, Efron's standard bootstrap
 * interval).  0 or 1 (failed). */
static int fit_plant(int pl, size_t K, int fitted, extra_kind extra, int B, fit_out *r)
{
    phc_problem *pb = NULL;
    if (fit_traces(plant_options(pl, K, fitted, 1001 + (uint64_t)pl), truth, start, r, &pb)) return 1;
    int bad = 0;
    r->chi2_truth = NAN;
    if (!fitted) {
        phc_error err;
        phc_error_clear(&err);
        if (!phc_shoot_traces_covariance_at(pb->datasets[0], truth, &err)) r->chi2_truth = chi2_at_truth(pb->datasets[0]);
    } else {
        r->chi2_start = NAN;
    }
    if (extra == EXTRA_PROFILE) {
        phc_error err;
        phc_error_clear(&err);
        phc_profile_options po = phc_profile_options_default();
        po.points = 3;
        phc_profile_result *pr = NULL;
        if (phc_profile_run(pb, r->est, r->se, &po, &pr, &err)) {
            fprintf(stderr, "plant %d: profile: %s\n", pl, err.message);
            bad = 1;
        }
        for (size_t j = 0; !bad && j < pr->n_profiles; ++j) {
            r->xci[pr->profiles[j].param][0] = pr->profiles[j].lo;
            r->xci[pr->profiles[j].param][1] = pr->profiles[j].hi;
        }
        phc_profile_result_free(pr);
    }
    phc_problem_free(pb);
    if (extra == EXTRA_BOOTSTRAP && !bad) {
        double sum[NP] = {0}, sq[NP] = {0};
        for (int b = 0; b < B && !bad; ++b) {
            fit_out rb;
            bad = fit_traces(plant_options(pl, K, fitted, 500000 + 1000 * (uint64_t)pl + (uint64_t)b), r->est,
                             start, &rb, NULL);
            for (size_t j = 0; !bad && j < NP; ++j) {
                sum[j] += rb.est[j];
                sq[j] += rb.est[j] * rb.est[j];
            }
        }
        for (size_t j = 0; !bad && j < NP; ++j) {
            const double m = sum[j] / B, sd = sqrt(fmax(0, (sq[j] - B * m * m) / (B - 1)));
            r->xci[j][0] = r->est[j] - 1.96 * sd;
            r->xci[j][1] = r->est[j] + 1.96 * sd;
            r->bci[j][0] = 2 * r->est[j] - m - 1.96 * sd; /* the bias m - est taken off */
            r->bci[j][1] = 2 * r->est[j] - m + 1.96 * sd;
        }
    }
    return bad;
}

/* Clopper–Pearson 95% interval of a binomial proportion k of n. */
static void binomial_ci(int k, int n, double *l, double *u)
{
    *l = k > 0 ? gsl_cdf_beta_Pinv(0.025, k, n - k + 1) : 0;
    *u = k < n ? gsl_cdf_beta_Pinv(0.975, k + 1, n - k) : 1;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started) return started;
    const int n_plants = argc > 2 ? atoi(argv[2]) : 16;
    const int K = argc > 3 ? atoi(argv[3]) : 8;
    const extra_kind extra = argc > 4 && !strcmp(argv[4], "profile")     ? EXTRA_PROFILE
                             : argc > 4 && !strcmp(argv[4], "bootstrap") ? EXTRA_BOOTSTRAP
                             : argc > 4 && !strcmp(argv[4], "starts")    ? EXTRA_MULTISTART
                                                                         : EXTRA_NONE;
    const int B = argc > 5 ? atoi(argv[5]) : 19;
    if (argc > 4 && (extra == EXTRA_NONE || B < 2)) {
        fprintf(stderr, "the fourth argument is profile, bootstrap B (B >= 2 plants) or starts S (S >= 2)\n");
        return 2;
    }
    if (extra == EXTRA_MULTISTART) fit_starts = (size_t)B;
    if (n_plants < 2 || n_plants > 1000 || K < 1 || K > 1000) {
        fprintf(stderr, "N must be 2..1000 and K 1..1000\n");
        return 2;
    }
    int cover[NWAYS][NP] = {{0}}, pcover[NP] = {0}, bcover[NP] = {0}, fits = 0;
    double zsum[NWAYS][NP] = {{0}}, zsq[NWAYS][NP] = {{0}}, c2s = 0, c2t = 0;
    int zn[NWAYS][NP] = {{0}}; /* plants with a stderr (none at a bound) */
    size_t rounds_sum = 0, rounds_max = 0;
    int unsettled = 0, c2n = 0;
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "shoot_traces_coverage.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Coverage of the shoot_traces intervals\n\n"
               "%d model plants at BP 0.3, V 0.6, eta 0.02, tau 0.5, r 0.15 (60 s, steps of 0.5 s, traced "
               "every 10 s), each fitted with its own K = %d seeds; absolute sigmas; covariance at the start "
               "values and at the fitted values. * = the truth outside the 95%% interval.\n\n"
               "| plant | covariance at | BP | V | eta | tau | r |\n|---|---|---|---|---|---|---|\n",
            n_plants, K);
    for (int pl = 0; pl < n_plants; ++pl) {
        fit_out r[NWAYS];
        for (int w = 0; w < NWAYS; ++w)
            if (fit_plant(pl, (size_t)K, w, w == 1 ? extra : EXTRA_NONE, B, &r[w])) {
                fprintf(stderr, "plant %d: a fit failed\n", 1001 + pl);
                return 1;
            }
        fits++;
        rounds_sum += r[1].rounds;
        rounds_max = r[1].rounds > rounds_max ? r[1].rounds : rounds_max;
        unsettled += !r[1].settled;
        if (isfinite(r[0].chi2_start) && isfinite(r[0].chi2_truth)) {
            c2s += r[0].chi2_start;
            c2t += r[0].chi2_truth;
            c2n++;
        }
        for (int w = 0; w < NWAYS; ++w) {
            printf("plant %d, %s:", 1001 + pl, way[w]);
            fprintf(f, "| %d | %s |", 1001 + pl, way[w]);
            for (size_t j = 0; j < NP; ++j) {
                const int in = truth[j] >= r[w].ci[j][0] && truth[j] <= r[w].ci[j][1];
                const double z = (r[w].est[j] - truth[j]) / r[w].se[j];
                cover[w][j] += in;
                if (isfinite(z)) {
                    zn[w][j]++;
                    zsum[w][j] += z;
                    zsq[w][j] += z * z;
                }
                printf(" %.3g [%.3g, %.3g]%s", r[w].est[j], r[w].ci[j][0], r[w].ci[j][1], in ? "" : "*");
                fprintf(f, " %.3g [%.3g, %.3g]%s |", r[w].est[j], r[w].ci[j][0], r[w].ci[j][1], in ? "" : " \\*");
            }
            if (w == 1) {
                printf(" (%zu round%s%s)", r[1].rounds, r[1].rounds == 1 ? "" : "s", r[1].settled ? "" : ", not settled");
                for (size_t j = 0; (extra == EXTRA_PROFILE || extra == EXTRA_BOOTSTRAP) && j < NP; ++j) {
                    const int in = truth[j] >= r[1].xci[j][0] && truth[j] <= r[1].xci[j][1];
                    pcover[j] += in;
                    bcover[j] += truth[j] >= r[1].bci[j][0] && truth[j] <= r[1].bci[j][1];
                    printf("%s [%.3g, %.3g]%s", j ? "" : extra == EXTRA_PROFILE ? " profile:" : " bootstrap:",
                           r[1].xci[j][0], r[1].xci[j][1], in ? "" : "*");
                }
            }
            else
                printf(" (chi2/n at the truth: %.3g with sigma at the start, %.3g at the truth)", r[0].chi2_start,
                       r[0].chi2_truth);
            printf("\n");
            fprintf(f, "\n");
        }
    }
    fprintf(f, "\n| covariance at | parameter | intervals covering the truth | binomial 95%% interval | "
               "mean z | sd z |\n|---|---|---|---|---|---|\n");
    int total[NWAYS] = {0};
    for (int w = 0; w < NWAYS; ++w) {
        for (size_t j = 0; j < NP; ++j) {
            double l, u;
            binomial_ci(cover[w][j], fits, &l, &u);
            const int m = zn[w][j];
            const double zm = m ? zsum[w][j] / m : NAN, zsd = m > 1 ? sqrt((zsq[w][j] - m * zm * zm) / (m - 1)) : NAN;
            total[w] += cover[w][j];
            printf("coverage, covariance at %s, %s: %d of %d (%.2f, 95%% interval %.2f-%.2f), z mean %.2f sd %.2f "
                   "(of %d)\n",
                   way[w], names[j], cover[w][j], fits, (double)cover[w][j] / fits, l, u, zm, zsd, m);
            fprintf(f, "| %s | %s | %d of %d | %.2f-%.2f | %.2f | %.2f |\n", way[w], names[j], cover[w][j], fits, l,
                    u, zm, zsd);
        }
    }
    for (size_t j = 0; (extra == EXTRA_PROFILE || extra == EXTRA_BOOTSTRAP) && j < NP; ++j)
        printf("coverage, covariance at fitted, %s intervals, %s: %d of %d\n",
               extra == EXTRA_PROFILE ? "profile" : "bootstrap", names[j], pcover[j], fits);
    for (size_t j = 0; extra == EXTRA_BOOTSTRAP && j < NP; ++j)
        printf("coverage, covariance at fitted, bias-corrected bootstrap intervals, %s: %d of %d\n", names[j],
               bcover[j], fits);
    printf("chi2/n at the truth, mean over %d plants: %.3g with sigma at the start values, %.3g with sigma at "
           "the truth (1 when sigma describes the traced plants' scatter)\n",
           c2n, c2s / (c2n ? c2n : 1), c2t / (c2n ? c2n : 1));
    printf("covariance at fitted: %.2f rounds on average, at most %zu; %d of %d plants not settled\n",
           (double)rounds_sum / fits, rounds_max, unsettled, fits);
    double l[NWAYS], u[NWAYS];
    for (int w = 0; w < NWAYS; ++w) {
        binomial_ci(total[w], fits * NP, &l[w], &u[w]);
        printf("coverage, covariance at %s, pooled: %d of %d (%.3f, 95%% interval %.3f-%.3f)\n", way[w], total[w],
               fits * NP, (double)total[w] / (fits * NP), l[w], u[w]);
        fprintf(f, "\nPooled, covariance at %s: %d of %d (95%% interval %.3f-%.3f).\n", way[w], total[w], fits * NP,
                l[w], u[w]);
    }
    const double chi2_truth = c2t / (c2n ? c2n : 1);
    const int ok = u[0] < 0.95 && u[1] < 0.95 && c2n == fits && chi2_truth < 1;
    printf("check: the intervals under-cover (pooled 95%% intervals of the coverage end at %.3f and %.3f, below "
           "0.95) though sigma is not too narrow (chi2/n at the truth %.3g < 1): %s\n",
           u[0], u[1], chi2_truth, ok ? "pass" : "FAIL");
    if (nb_close_md(f, md, mdtmp)) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    return ok ? 0 : 1;
}
