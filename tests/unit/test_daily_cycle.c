/* End to end: a daily cycle in the residuals of a time series is named by
 * the daily_cycle check and the verdict, and survives result.json.
 *
 * A "pot on a balance" as a curve data set: mass (g) every 30 min over 5
 * days, losing water along a straight line plus, in "cycle", a day/night
 * difference the straight-line model cannot follow; "flat" has only noise.
 * The data set kind is the generic curve kind (fit/costs), built through
 * the C API (phc_curve_new over the CSV table, a problem of its own), so
 * the test does not depend on the weight_curve loader: the test sets
 * x_seconds (x in hours) and time_of_day (the first reading at 06:00)
 * itself, as a loader would.  Checks: the check fails with a period near 24 h and the verdict
 * says so in words; the flat data set passes; result.json round-trips
 * x_seconds, time_of_day, the check and the time-lag ACF; the plots
 * (<name>_acf.png over time lags, <name>_time_of_day.png) are written.
 * PHC_KEEP_PLOTS=DIR keeps copies of the plots in DIR for looking at. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/costs/curve.h"
#include "fit/engine/fit.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/problem.h"
#include "measurements/table.h"
#include "fit/fit_plots.h"
#include "fit/report.h"
#include "fit/result_json.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define N 240          /* every 30 min for 5 days */
#define START_CLOCK 6.0 /* first reading at 06:00 local time */

static char tmp_dir[] = "/tmp/phc_test_daily_cycle_XXXXXX";

static unsigned long long lcg_state = 2024;
static double lcg_uniform(void)
{
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return ((double)(lcg_state >> 11) + 0.5) / 9007199254740992.0;
}
static double lcg_normal(void)
{
    const double u = lcg_uniform(), v = lcg_uniform();
    return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
}

static const char *path_in(const char *name)
{
    static char buf[4][512];
    static int which;
    which = (which + 1) % 4;
    snprintf(buf[which], sizeof buf[which], "%s/%s", tmp_dir, name);
    return buf[which];
}

/* Mass of a pot: 800 g losing 0.4 g/h on average, with (cycle = 1) an extra
 * loss by day: the mass runs 0.5 g below the line in the evening and above
 * it at dawn (a sinusoid peaking at 06:00 local time), noise 0.05 g. */
static void write_data(const char *name, int cycle)
{
    FILE *f = fopen(path_in(name), "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f, "t,m\n");
    for (size_t i = 0; i < N; ++i) {
        const double t = 0.5 * (double)i, clock = fmod(START_CLOCK + t, 24.0);
        const double day = cycle ? 0.5 * cos(2.0 * M_PI * (clock - 6.0) / 24.0) : 0.0;
        fprintf(f, "%.17g,%.17g\n", t, 800.0 - 0.4 * t + day + 0.05 * lcg_normal());
    }
    fclose(f);
}

/* The straight line m0 - e t fitted to the table `csv` (t in h, m in g) as
 * a curve data set "pot" built through the C API: m0 from 700 g, e from
 * 0.1 g h-1, unbounded. */
static phc_fit_result *fit_pot(const char *csv)
{
    phc_problem *pb = phc_problem_new("pot");
    phc_fit_result *res = NULL;
    phc_table *t = NULL;
    phc_dataset *built = NULL;
    phc_error err;
    phc_error_clear(&err);
    static const char *const names[2] = {"m0", "e"}, *const units[2] = {"g", "g h-1"};
    static const double start[2] = {700, 0.1};
    for (int j = 0; j < 2; ++j) {
        size_t i = 0;
        CHECK(phc_problem_add_parameter(pb, names[j], start[j], &i, &err) == PHC_OK);
        pb->params[i].unit = strdup(units[j]);
    }
    phc_curve_options o = phc_curve_options_default();
    o.x = "t";
    o.y = "m";
    o.expression = "m0 - e*t";
    int rc = phc_table_read(path_in(csv), &t, &err);
    if (!rc)
        rc = phc_curve_new(t, &o, &built, &err);
    phc_table_free(t);
    if (!rc && !(built->name = strdup("pot")))
        rc = PHC_ERR_NOMEM;
    if (!rc && (rc = phc_problem_bind_by_name(pb, built, &err)))
        phc_dataset_free(built);
    if (!rc)
        rc = phc_problem_add_dataset(pb, built, &err);
    if (!rc)
        rc = phc_problem_finish(pb, 0, &err);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    CHECK(rc == PHC_OK);
    if (rc) {
        phc_problem_free(pb);
        return NULL;
    }
    phc_dataset *ds = pb->datasets[0];
    ds->x_seconds = 3600.0; /* x in hours */
    ds->time_of_day = malloc(ds->n * sizeof *ds->time_of_day);
    CHECK(ds->time_of_day != NULL);
    for (size_t i = 0; ds->time_of_day && i < ds->n; ++i)
        ds->time_of_day[i] = fmod(START_CLOCK + ds->x[i], 24.0);
    rc = phc_fit_run(pb, NULL, NULL, &res, &err);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    CHECK(rc == PHC_OK);
    phc_problem_free(pb);
    return res;
}

static const char *find_warning(const phc_fit_result *res, const char *needle)
{
    for (size_t i = 0; i < res->n_warnings; ++i)
        if (strstr(res->warnings[i], needle))
            return res->warnings[i];
    return NULL;
}

static void test_cycle(void)
{
    write_data("cycle.csv", 1);
    phc_fit_result *res = fit_pot("cycle.csv");
    if (!res)
        return;
    const phc_dataset_result *d = &res->datasets[0];
    const phc_check_result *ck = &d->checks[PHC_CHECK_DAILY_CYCLE];
    CHECK(strcmp(ck->name, "daily_cycle") == 0);
    CHECK(ck->applicable && !ck->pass);
    CHECK(ck->p_value < 1e-6);
    CHECK(fabs(d->cycle_period_h - 24.0) < 0.5);
    /* the residuals (data - straight line) are highest at dawn, 06:00 */
    CHECK(fabs(d->cycle_peak_hour - 6.0) < 0.5);
    /* the time-lag ACF: 1 h bins (30 min sampling) to 48 h, ~ -1 at 12 h,
     * ~ +1 at 24 h (the noise is small against the cycle) */
    CHECK(d->acf_time != NULL && d->acf_time_bins == 49);
    CHECK_NEAR(d->acf_time_bin_h, 1.0, 0, 1e-12);
    if (d->acf_time && d->acf_time_bins == 49) {
        CHECK(d->acf_time[12] < -0.8);
        CHECK(d->acf_time[24] > 0.8);
    }
    CHECK(fabs(d->peak_period_h - 24.0) < 1.0 && d->peak_fap < 1e-6);
    const char *w = find_warning(res, "daily cycle");
    CHECK(w != NULL);
    if (w) {
        printf("verdict: %s\n", w);
        CHECK_STR_CONTAINS(w, "data set 'pot': the residuals follow a daily cycle (periodogram peak at 24.");
        CHECK_STR_CONTAINS(w, "the model misses a difference between day and night");
        CHECK_STR_CONTAINS(w, "highest around 06:");
    }

    /* plots and report */
    char *names[16] = {0};
    size_t n_names = 0;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_fit_plots_write(res, tmp_dir, names, &n_names, 16, &err) == PHC_OK);
    int acf = 0, tod = 0;
    for (size_t i = 0; i < n_names; ++i) {
        acf += strcmp(names[i], "pot_acf.png") == 0;
        tod += strcmp(names[i], "pot_time_of_day.png") == 0;
    }
    CHECK(acf == 1 && tod == 1);
    CHECK(phc_report_write_markdown(res, path_in("report.md"), (const char *const *)names, &err) == PHC_OK);
    FILE *f = fopen(path_in("report.md"), "r");
    char md[65536] = "";
    if (f) {
        md[fread(md, 1, sizeof md - 1, f)] = '\0';
        fclose(f);
    }
    CHECK_STR_CONTAINS(md, "| daily_cycle | a 24-hour cycle in the residuals (Lomb–Scargle) |");
    CHECK_STR_CONTAINS(md, "- **daily_cycle**");
    CHECK_STR_CONTAINS(md, "![pot_time_of_day.png](pot_time_of_day.png)");
    const char *keep = getenv("PHC_KEEP_PLOTS");
    for (size_t i = 0; i < n_names; ++i) {
        if (keep && *keep) {
            char cmd[2048];
            snprintf(cmd, sizeof cmd, "cp '%s' '%s/'", path_in(names[i]), keep);
            CHECK(system(cmd) == 0);
        }
        unlink(path_in(names[i]));
        free(names[i]);
    }
    unlink(path_in("report.md"));

    /* result.json round trip: recheck recomputes the check from the saved
     * residuals, x_seconds and time_of_day */
    CHECK(phc_result_write_json(res, path_in("result.json"), &err) == PHC_OK);
    phc_fit_result *back = NULL;
    CHECK(phc_result_read_json(path_in("result.json"), &back, &err) == PHC_OK);
    if (back) {
        const phc_dataset_result *b = &back->datasets[0];
        CHECK(b->x_seconds == 3600.0);
        CHECK(b->time_of_day != NULL);
        for (size_t i = 0; b->time_of_day && i < b->n; ++i)
            CHECK(b->time_of_day[i] == d->time_of_day[i]);
        const phc_check_result *bk = &b->checks[PHC_CHECK_DAILY_CYCLE];
        CHECK(strcmp(bk->name, "daily_cycle") == 0 && bk->applicable && !bk->pass);
        CHECK_NEAR(bk->p_value, ck->p_value, 1e-300, 1e-9);
        CHECK_NEAR(bk->statistic, ck->statistic, 0, 1e-12);
        CHECK_NEAR(b->cycle_period_h, d->cycle_period_h, 0, 1e-12);
        CHECK(b->acf_time_bins == d->acf_time_bins);
        for (size_t k = 0; b->acf_time && k < b->acf_time_bins; ++k)
            CHECK(isnan(d->acf_time[k]) ? isnan(b->acf_time[k]) : fabs(b->acf_time[k] - d->acf_time[k]) < 1e-12);
        CHECK(find_warning(back, "daily cycle") != NULL);
        /* a recheck at another level keeps it (and frees the old ACF) */
        CHECK(phc_fit_recheck(back, 1e-3, &err) == PHC_OK);
        CHECK(!back->datasets[0].checks[PHC_CHECK_DAILY_CYCLE].pass);
        phc_fit_result_free(back);
    }
    unlink(path_in("result.json"));
    phc_fit_result_free(res);
}

static void test_flat(void)
{
    write_data("flat.csv", 0);
    phc_fit_result *res = fit_pot("flat.csv");
    if (!res)
        return;
    const phc_dataset_result *d = &res->datasets[0];
    const phc_check_result *ck = &d->checks[PHC_CHECK_DAILY_CYCLE];
    printf("no cycle: daily_cycle p = %.3g (period %.2f h)\n", ck->p_value, d->cycle_period_h);
    CHECK(ck->applicable && ck->pass && ck->p_value > 0.05);
    CHECK(find_warning(res, "daily cycle") == NULL);
    phc_fit_result_free(res);

    /* a time series shorter than 1.5 days, and a data set whose x is not a
     * time: not applicable, no time-lag ACF */
    FILE *f = fopen(path_in("short.csv"), "w");
    if (f) {
        fprintf(f, "t,m\n");
        for (size_t i = 0; i < 60; ++i)
            fprintf(f, "%g,%.17g\n", 0.5 * (double)i, 800.0 - 0.2 * (double)i + 0.05 * lcg_normal());
        fclose(f);
    }
    res = fit_pot("short.csv");
    if (res) {
        CHECK(!res->datasets[0].checks[PHC_CHECK_DAILY_CYCLE].applicable);
        CHECK(res->datasets[0].checks[PHC_CHECK_DAILY_CYCLE].pass);
        CHECK(res->datasets[0].acf_time == NULL);
        CHECK(strcmp(res->datasets[0].checks[PHC_CHECK_DAILY_CYCLE].name, "daily_cycle") == 0);
        phc_fit_result_free(res);
    }
    unlink(path_in("short.csv"));
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_cycle();
    test_flat();
    unlink(path_in("cycle.csv"));
    unlink(path_in("flat.csv"));
    CHECK(rmdir(tmp_dir) == 0);
    return check_finish("test_daily_cycle");
}
