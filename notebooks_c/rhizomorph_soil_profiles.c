/* The soil identifiability study (rhizomorph_soil_identifiability, README
 * "Which data identify p and c") redone as profile likelihoods: instead of
 * the curvature at the optimum (Wald standard errors, correlation,
 * collinearity), each parameter is fixed on a grid away from the optimum
 * while the other is refitted, and its 95% interval is where the cost rises
 * by the likelihood-ratio threshold (`phytocal profile`'s driver,
 * fit/profile_study.h: phc_profile_study_run).
 *
 * The claim checked (the identifiability notebook's table): probes reading
 * w/c (design B) identify both p and c in every soil; the 80% infiltration
 * depth alone (design C) determines p alone in sandy loam, where gravity
 * carries the front, and leaves c undetermined.
 *
 * Same column, plan, data-generating run, noise and problem as the
 * identifiability notebook (rhizomorph_soil_column.h): sandy loam (c 150,
 * p 0.5 m/h) as the truth, designs B and C, the fit started at the truth,
 * profiles of p and c with PROFILE_POINTS target steps per side.
 *
 * Prints, per design and parameter, the estimate, the Wald and the profile
 * interval (an open side shown as where the profile stopped and why) and
 * the verdict.  A parameter counts as identified when its profile crosses
 * the threshold on both sides and the interval's half-width is at most
 * 1.96 x 10% of the estimate (the identifiability notebook's rule, a
 * relative SE of at most 10%, on the likelihood interval).  Checks (exit 1
 * when one fails): B identifies p and c; C identifies p and not c.  Writes OUTPUT_DIR/rhizomorph_soil_profiles/<design>/ (the
 * run directories with profile_p.png, profile_c.png) and
 * rhizomorph_soil_profiles.md.
 *
 * Usage: notebook_rhizomorph_soil_profiles OUTPUT_DIR */
#include <jansson.h>
#include <time.h>

#include "rhizomorph_soil_column.h"

#include "fit/profile_study.h"
#include "notebook_plot.h"

#define SOIL "sandy_loam"
#define PROFILE_POINTS 5

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct prof {
    double value, wald[2], ci[2], reached[2];
    char lower_end[32], upper_end[32], verdict[128];
    int flat, crossed_both;
    double half; /* half-width of the profile interval relative to the estimate (NAN when a side is open) */
} prof;

/* The identifiability notebook's rule (relative SE <= REL_SE_OK) on the
 * profile interval: both sides crossed and a half-width of at most 1.96
 * REL_SE_OK of the estimate. */
static int identified(const prof *q)
{
    return q->crossed_both && q->half <= 1.96 * REL_SE_OK;
}

static double num(json_t *v)
{
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static int read_profiles(const char *path, prof out[2], phc_error *err)
{
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root)
        return phc_error_set(err, PHC_ERR_IO, "%s: %s", path, jerr.text);
    json_t *params = json_object_get(root, "parameters");
    static const char *names[2] = {"p", "c"};
    int found = 0;
    for (size_t i = 0; i < json_array_size(params); ++i) {
        json_t *o = json_array_get(params, i);
        for (int k = 0; k < 2; ++k) {
            if (strcmp(json_string_value(json_object_get(o, "name")), names[k]) != 0)
                continue;
            prof *q = &out[k];
            q->value = num(json_object_get(o, "value"));
            for (int s = 0; s < 2; ++s) {
                q->wald[s] = num(json_array_get(json_object_get(o, "wald_ci"), (size_t)s));
                q->ci[s] = num(json_array_get(json_object_get(o, "profile_ci"), (size_t)s));
                q->reached[s] = num(json_array_get(json_object_get(o, "reached"), (size_t)s));
            }
            snprintf(q->lower_end, sizeof q->lower_end, "%s", json_string_value(json_object_get(o, "lower_end")));
            snprintf(q->upper_end, sizeof q->upper_end, "%s", json_string_value(json_object_get(o, "upper_end")));
            snprintf(q->verdict, sizeof q->verdict, "%s", json_string_value(json_object_get(o, "verdict")));
            q->flat = json_is_true(json_object_get(o, "flat"));
            q->crossed_both = !strcmp(q->lower_end, "crossed") && !strcmp(q->upper_end, "crossed");
            q->half = q->crossed_both ? 0.5 * (q->ci[1] - q->ci[0]) / fabs(q->value) : NAN;
            ++found;
        }
    }
    json_decref(root);
    return found == 2 ? PHC_OK : phc_error_set(err, PHC_ERR_INTERNAL, "%s: p and c are not both profiled", path);
}

/* "[lo, hi]" with an open side as "(stopped at X: why" */
static void interval_text(const prof *q, char *buf, size_t cap) /* cap >= 160 */
{
    char lo[64], hi[64]; /* each at most 48 characters */
    if (!strcmp(q->lower_end, "crossed"))
        snprintf(lo, sizeof lo, "[%.4g", q->ci[0]);
    else
        snprintf(lo, sizeof lo, "(%s at %.4g", q->lower_end, q->reached[0]);
    if (!strcmp(q->upper_end, "crossed"))
        snprintf(hi, sizeof hi, "%.4g]", q->ci[1]);
    else
        snprintf(hi, sizeof hi, "%s at %.4g)", q->upper_end, q->reached[1]);
    snprintf(buf, cap, "%s, %s", lo, hi);
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started)
        return started;
    const double t_start = now();
    phc_error err;
    phc_error_clear(&err);
    char dir[900];
    snprintf(dir, sizeof dir, "%s/rhizomorph_soil_profiles", out);
    if (nb_mkdirs(dir) != 0) {
        fprintf(stderr, "%s: cannot create the directory\n", dir);
        return 1;
    }
    /* the identifiability notebook's set-up for this soil (its index fixes the noise stream) */
    int q = -1;
    for (size_t i = 0; i < NSOIL && q < 0; ++i)
        if (phc_soil_preset_name(i) && !strcmp(phc_soil_preset_name(i), SOIL))
            q = (int)i;
    double c, p;
    if (q < 0 || phc_soil_preset(SOIL, &c, &p) != 0) {
        fprintf(stderr, "soil preset %s is missing\n", SOIL);
        return 1;
    }
    plan pl;
    plan_for(c, p, &pl);
    phc_soil *s = build(&pl, c, p, &err);
    phc_soil *s0 = s ? build(&pl, c / START_FACTOR, p * START_FACTOR, &err) : NULL;
    if (!s || !s0 || pl.nt > MAX_T) {
        fprintf(stderr, "%s: %s\n", SOIL, err.message);
        return 1;
    }
    pl.limit = phc_soil_stable_dt(s, NULL);
    pl.dt = 0.5 * phc_soil_stable_dt(s0, NULL);
    phc_soil_free(s);
    phc_soil_free(s0);
    static double w[MAX_T][NPROBE], fl[MAX_T][NPROBE], d80[MAX_T];
    double closing;
    if (simulate(&pl, c, p, w, fl, d80, &closing, &err)) {
        fprintf(stderr, "%s: %s\n", SOIL, err.message);
        return 1;
    }
    double sig[NDES];
    sig[0] = NOISE_FRAC * range_of((const double(*)[NPROBE])w, pl.nt);
    sig[1] = NOISE_FRAC * range_of((const double(*)[NPROBE])fl, pl.nt);
    sig[2] = SIGMA_DEPTH;
    char probes[1100], data[NDES][1100];
    snprintf(probes, sizeof probes, "%s/%s_probes.csv", dir, SOIL);
    for (int e = 0; e < NDES; ++e)
        snprintf(data[e], sizeof data[e], "%s/%s_%c.csv", dir, SOIL, des_tag[e]);
    rng_state = 0x5eed0000ULL + (uint64_t)q; /* the identifiability notebook's stream for this soil */
    if (write_probes(probes, &pl) ||
        write_readings(data[0], &pl, (const double(*)[NPROBE])w, sig[0], "water content w (m3/m3)") ||
        write_readings(data[1], &pl, (const double(*)[NPROBE])fl, sig[1], "fill level w/c") ||
        write_depths(data[2], &pl, d80, sig[2])) {
        fprintf(stderr, "%s: cannot write the data files\n", dir);
        return 1;
    }
    printf("%s: c = %g, p = %g m/h; window %g h, readings every %g h, %zu voxels of %g m, dt %.3g h; "
           "profiles with %d target steps per side\n",
           SOIL, c, p, pl.T, pl.dt_obs, pl.nz, pl.dx, pl.dt, PROFILE_POINTS);
    static const int designs[2] = {1, 2};
    prof res[2][2];
    double secs[2];
    for (int k = 0; k < 2; ++k) {
        const int e = designs[k];
        phc_problem *pb = build_problem(SOIL, e, &pl, c, p, c, p, sig[e], data[e], probes, &err);
        if (!pb) {
            fprintf(stderr, "%s, design %c: %s\n", SOIL, des_tag[e], err.message);
            return 1;
        }
        char run[1200], path[1300];
        snprintf(run, sizeof run, "%s/%c", dir, des_tag[e]);
        phc_profile_study_options po = phc_profile_study_options_default();
        po.points = PROFILE_POINTS;
        po.force = 1;
        phc_profile_summary sum;
        const double t0 = now();
        const int rc = phc_profile_study_run(pb, &po, NULL, run, &sum, &err);
        secs[k] = now() - t0;
        phc_profile_summary_clear(&sum);
        phc_problem_free(pb);
        snprintf(path, sizeof path, "%s/result.json", run);
        if (rc || read_profiles(path, res[k], &err)) {
            fprintf(stderr, "%s, design %c: %s\n", SOIL, des_tag[e], err.message);
            return 1;
        }
    }
    static const char *pn[2] = {"p", "c"};
    printf("%-14s %-4s %10s  %-24s  %-42s  %s\n", "design", "par", "estimate", "Wald 95%", "profile 95%", "verdict");
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j) {
            const prof *r = &res[k][j];
            char wald[64], pr[160];
            snprintf(wald, sizeof wald, "[%.4g, %.4g]", r->wald[0], r->wald[1]);
            interval_text(r, pr, sizeof pr);
            printf("%-14s %-4s %10.5g  %-24s  %-42s  %s%s\n", des_name[designs[k]], pn[j], r->value, wald, pr,
                   r->verdict, r->flat ? " (flat)" : "");
        }
    const int ok_b = identified(&res[0][0]) && identified(&res[0][1]);
    const int ok_c = identified(&res[1][0]) && !identified(&res[1][1]);
    printf("B (probes w/c) identifies p and c (both profiles crossed, half-widths %.2f%% and %.2f%% <= %.1f%%): %s\n",
           100 * res[0][0].half, 100 * res[0][1].half, 196 * REL_SE_OK, ok_b ? "yes" : "no");
    printf("C (80%% depth) identifies p alone (half-width %.2f%%; c: %s%.1f%%%s): %s\n", 100 * res[1][0].half,
           res[1][1].crossed_both ? "half-width " : "an open side", res[1][1].crossed_both ? 100 * res[1][1].half : 0,
           res[1][1].flat ? ", flat" : "", ok_c ? "yes" : "no");
    printf("profile runs: B %.1f s, C %.1f s; %.1f s in all\n", secs[0], secs[1], now() - t_start);

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "rhizomorph_soil_profiles.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Soil identifiability as profile likelihoods\n\n%s (c %g, p %g m/h) as the truth, the "
               "identifiability notebook's column and noise; designs B (probes reading w/c) and C (80%% "
               "infiltration depth). Profiles: `rhizomorph_soil_profiles/B/`, `rhizomorph_soil_profiles/C/`.\n\n"
               "| design | parameter | estimate | Wald 95%% | profile 95%% | verdict |\n|---|---|---:|---|---|---|\n",
            SOIL, c, p);
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j) {
            const prof *r = &res[k][j];
            char pr[160];
            interval_text(r, pr, sizeof pr);
            fprintf(f, "| %s | %s | %.5g | [%.4g, %.4g] | %s | %s%s |\n", des_name[designs[k]], pn[j], r->value,
                    r->wald[0], r->wald[1], pr, r->verdict, r->flat ? " (flat)" : "");
        }
    fprintf(f, "\nIdentified: both sides crossed and a half-width of at most %.1f%% of the estimate. Half-widths: B "
               "p %.2f%%, c %.2f%%; C p %.2f%%, c %.1f%%.\n", 196 * REL_SE_OK, 100 * res[0][0].half,
            100 * res[0][1].half, 100 * res[1][0].half, 100 * res[1][1].half);
    fprintf(f, "\nChecks: B identifies p and c %s; C identifies p alone %s.\n", ok_b ? "(pass)" : "(**FAIL**)",
            ok_c ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    const int fail = !(ok_b && ok_c);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
