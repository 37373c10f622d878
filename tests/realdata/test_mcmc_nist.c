/* `phytocal mcmc` on NIST StRD Misra1a (y = b1 (1 - exp(-b2 x)), 14
 * observations, no sigmas) against emcee (Foreman-Mackey et al. 2013;
 * Debian's python3-emcee) run in the same test on the same posterior.
 *
 * The posterior: flat (improper) priors on b1, b2 (the config gives no
 * bounds); phytocal samples s2 from its inverse-gamma full conditional with
 * n0 = 0.1 n, var0 = the fit's s2, so the marginal posterior of (b1, b2) is
 *   p(b | y) ∝ (n0 var0 + SS(b))^(-(n0 + n) / 2)
 * (s2 integrated out, BDA3 §14.2), which emcee samples directly.
 * Agreement: each median and 2.5% / 97.5% quantile within 4 combined Monte
 * Carlo standard errors, SE(median) = 1.2533 sd / sqrt(ESS) and SE(q) =
 * sqrt(p (1 - p)) / (phi(z_p) sqrt(ESS)) sd (a normal posterior's quantile
 * SE; Misra1a's posterior is close to normal), ESS from each sampler's own
 * integrated autocorrelation time.  Both phytocal methods are compared.
 * Skips (77) when the NIST data or emcee is missing. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/mcmc_study.h"

static const char *emcee_script =
    "import sys, json, numpy as np, emcee\n"
    "x, y = np.loadtxt(sys.argv[1], delimiter=',', skiprows=1, unpack=True)\n"
    "var0, n0 = float(sys.argv[2]), float(sys.argv[3])\n"
    "b1, b2 = float(sys.argv[4]), float(sys.argv[5])\n"
    "n = len(y)\n"
    "def logp(b):\n"
    "    ss = np.sum((y - b[0] * (1 - np.exp(-b[1] * x)))**2)\n"
    "    return -0.5 * (n0 + n) * np.log(n0 * var0 + ss)\n"
    "nw, steps = 32, 6000\n"
    "rng = np.random.default_rng(42)\n"
    "p0 = np.array([b1, b2]) * (1 + 1e-3 * rng.standard_normal((nw, 2)))\n"
    "s = emcee.EnsembleSampler(nw, 2, logp)\n"
    "s.random_state = np.random.RandomState(42).get_state()  # seeded: the same numbers every run\n"
    "s.run_mcmc(p0, steps, progress=False)\n"
    "ch = s.get_chain(discard=steps // 2)\n"
    "tau = s.get_autocorr_time(discard=steps // 2, quiet=True)\n"
    "flat = ch.reshape(-1, 2)\n"
    "out = {}\n"
    "for j, name in enumerate(['b1', 'b2']):\n"
    "    q = np.quantile(flat[:, j], [0.025, 0.5, 0.975])\n"
    "    out[name] = dict(q025=q[0], median=q[1], q975=q[2], sd=float(np.std(flat[:, j])),\n"
    "                     ess=float(flat.shape[0] / tau[j]), tau=float(tau[j]))\n"
    "out['acceptance'] = float(np.mean(s.acceptance_fraction))\n"
    "print(json.dumps(out))\n";

/* Misra1a.dat: the pairs after the "Data:" line (y, x). */
static int load_misra1a(const char *path, const char *csv)
{
    FILE *in = fopen(path, "r");
    if (!in)
        return -1;
    FILE *out = fopen(csv, "w");
    if (!out) {
        fclose(in);
        return -1;
    }
    fprintf(out, "x,y\n");
    char line[512];
    int data = 0, n = 0;
    while (fgets(line, sizeof line, in)) {
        if (strncmp(line, "Data:", 5) == 0) {
            data = 1;
            continue;
        }
        double x, y;
        if (data && sscanf(line, "%lf %lf", &y, &x) == 2) {
            fprintf(out, "%.17g,%.17g\n", x, y);
            ++n;
        }
    }
    fclose(in);
    fclose(out);
    return n;
}

/* SE of the p-quantile of a normal posterior with sd s from ess draws. */
static double quantile_se(double p, double sd, double ess)
{
    if (p == 0.5)
        return 1.2533141373155 * sd / sqrt(ess);
    const double z = 1.959963984540054, phi = exp(-0.5 * z * z) / 2.5066282746310002;
    return sqrt(p * (1 - p)) / phi * sd / sqrt(ess);
}

int main(void)
{
    char dat[4096];
    snprintf(dat, sizeof dat, "%s/nist/Misra1a.dat", PHC_SHARED_DATA);
    if (access(dat, R_OK) != 0) {
        printf("SKIP: %s not found\n", dat);
        return 77;
    }
    if (access("/usr/bin/python3", X_OK) != 0 || system("/usr/bin/python3 -c 'import emcee' 2>/dev/null") != 0) {
        printf("SKIP: Debian's python3-emcee is not installed (scripts/setup installs it)\n");
        return 77;
    }
    char work[] = "/tmp/phc-mcmc-nist-XXXXXX";
    if (!mkdtemp(work))
        return 1;
    char csv[4200], yaml[4200], py[4200];
    snprintf(csv, sizeof csv, "%s/misra1a.csv", work);
    snprintf(yaml, sizeof yaml, "%s/misra1a.yaml", work);
    snprintf(py, sizeof py, "%s/peer.py", work);
    const int nobs = load_misra1a(dat, csv);
    CHECK(nobs == 14);
    FILE *f = fopen(yaml, "w");
    fprintf(f, "name: misra1a\nparameters:\n  b1: {value: 250}\n  b2: {value: 5.0e-4}\ndatasets:\n  - kind: curve\n"
               "    file: misra1a.csv\n    x: x\n    y: y\n    expression: \"b1*(1-exp(-b2*x))\"\n");
    fclose(f);
    f = fopen(py, "w");
    fputs(emcee_script, f);
    fclose(f);

    const char *methods[2] = {"dram", "stretch"};
    json_t *peer = NULL;
    for (int mth = 0; mth < 2; ++mth) {
        phc_problem *pb = NULL;
        phc_error err;
        phc_error_clear(&err);
        CHECK(phc_config_load(yaml, &pb, &err) == PHC_OK);
        if (!pb) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        phc_mcmc_options o = phc_mcmc_options_default();
        o.method = mth ? PHC_MCMC_STRETCH : PHC_MCMC_DRAM;
        o.samples = mth ? 12000 : 20000;
        o.seed = 3;
        char dir[4300];
        snprintf(dir, sizeof dir, "%s/run-%s", work, methods[mth]);
        phc_mcmc_run_summary sum;
        const clock_t t0 = clock();
        const int rc = phc_mcmc_run(pb, &o, NULL, dir, &sum, &err);
        const double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
        CHECK(rc == PHC_OK);
        phc_problem_free(pb);
        if (rc) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        printf("phytocal mcmc --method %s (%.2f s CPU):\n%s", methods[mth], secs, sum.text);
        CHECK(sum.mixed);
        phc_mcmc_run_summary_clear(&sum);
        char path[4400];
        snprintf(path, sizeof path, "%s/result.json", dir);
        json_error_t je;
        json_t *res = json_load_file(path, 0, &je);
        CHECK(res != NULL);
        if (!res)
            return 1;
        const double var0 = json_real_value(json_object_get(json_object_get(res, "error_variance"), "var0"));
        const double n0 = json_real_value(json_object_get(json_object_get(res, "error_variance"), "n0"));
        json_t *params = json_object_get(res, "parameters");
        if (!peer) {
            char cmd[9000];
            snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s %s %.17g %.17g %.17g %.17g", py, csv, var0, n0,
                     json_real_value(json_object_get(json_object_get(params, "b1"), "fit")),
                     json_real_value(json_object_get(json_object_get(params, "b2"), "fit")));
            const clock_t p0 = clock();
            const time_t w0 = time(NULL);
            FILE *p = popen(cmd, "r");
            char buf[8192] = "";
            size_t got = p ? fread(buf, 1, sizeof buf - 1, p) : 0;
            buf[got] = '\0';
            const int prc = p ? pclose(p) : -1;
            CHECK(prc == 0);
            peer = json_loads(buf, 0, &je);
            CHECK(peer != NULL);
            if (!peer) {
                fprintf(stderr, "emcee peer printed: %s\n", buf);
                return 1;
            }
            printf("emcee %s: 32 walkers x 6000 steps (first half discarded), acceptance %.3f, %ld s wall\n",
                   "(python3-emcee)", json_real_value(json_object_get(peer, "acceptance")), (long)(time(NULL) - w0));
            (void)p0;
        }
        const char *names[2] = {"b1", "b2"};
        for (int j = 0; j < 2; ++j) {
            json_t *a = json_object_get(params, names[j]), *b = json_object_get(peer, names[j]);
            const double sd = json_real_value(json_object_get(a, "sd"));
            const double ess_a = json_real_value(json_object_get(a, "ess")), ess_b = json_real_value(json_object_get(b, "ess"));
            const double sd_b = json_real_value(json_object_get(b, "sd"));
            json_t *ci = json_object_get(a, "ci95");
            const double va[3] = {json_real_value(json_array_get(ci, 0)), json_real_value(json_object_get(a, "median")),
                                  json_real_value(json_array_get(ci, 1))};
            const double vb[3] = {json_real_value(json_object_get(b, "q025")), json_real_value(json_object_get(b, "median")),
                                  json_real_value(json_object_get(b, "q975"))};
            const double p[3] = {0.025, 0.5, 0.975};
            const char *qn[3] = {"2.5%", "median", "97.5%"};
            printf("  %s: sd %.6g (emcee %.6g), ESS %.0f (emcee %.0f)\n", names[j], sd, sd_b, ess_a, ess_b);
            for (int k = 0; k < 3; ++k) {
                const double se = sqrt(pow(quantile_se(p[k], sd, ess_a), 2) + pow(quantile_se(p[k], sd_b, ess_b), 2));
                printf("    %-6s phytocal %.8g  emcee %.8g  |diff| %.3g  4 SE %.3g  (%.2f SE)\n", qn[k], va[k], vb[k],
                       fabs(va[k] - vb[k]), 4 * se, fabs(va[k] - vb[k]) / se);
                CHECK(fabs(va[k] - vb[k]) <= 4 * se);
            }
        }
        json_decref(res);
    }
    json_decref(peer);
    char cmd[4400];
    snprintf(cmd, sizeof cmd, "rm -rf %s", work);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", work);
    return check_finish("mcmc_nist");
}
