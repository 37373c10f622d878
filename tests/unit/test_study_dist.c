/* The study's distribution seam (fit/study_dist.h) without MPI: a fake
 * phc_dist drives phc_study_run the way the MPI module does.
 *
 * Checks: the launcher is recognised from the environment (and its rank);
 * without one phc_dist_open gives no distributor and loads nothing; a
 * master whose rows come back in reverse order (as results arrive from
 * workers in any order) writes the result.json of the one-process run,
 * byte for byte, and a ledger with the same records; a worker evaluates
 * rows but writes no ledger and no directory; a failure that agree()
 * reports from another rank stops the master with that rank's message and
 * no run directory; every rank calls agree() exactly once and run() once. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fit/costs/curve.h"
#include "fit/engine/problem.h"
#include "fit/sensitivity_study.h"
#include "fit/study_dist.h"
#include "measurements/table.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The Ishigami function of a, b, c on [-pi, pi] as a one-point curve. */
static phc_problem *ishigami_problem(void)
{
    const double x[1] = {0}, y[1] = {0};
    const char *names[] = {"x", "y"};
    const double *cols[] = {x, y};
    phc_table *t = NULL;
    phc_error err;
    phc_problem *pb = phc_problem_new("ishigami");
    CHECK(phc_table_from_columns("ishigami", 2, names, cols, 1, &t, &err) == PHC_OK);
    phc_curve_options o = phc_curve_options_default();
    o.x = "x";
    o.y = "y";
    o.expression = "sin(a) + 7 * sin(b)^2 + 0.1 * c^4 * sin(a)";
    o.sigma = 1;
    phc_dataset *ds = NULL;
    const char *pn[3] = {"a", "b", "c"};
    for (int i = 0; i < 3; ++i) {
        size_t idx;
        CHECK(phc_problem_add_parameter(pb, pn[i], 0.1, &idx, &err) == PHC_OK);
        pb->params[idx].lower = -M_PI;
        pb->params[idx].upper = M_PI;
    }
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_OK);
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_table_free(t);
    return pb;
}

/* ---- a fake distributor ------------------------------------------------------------------ */

typedef struct fake {
    int fail_rank;  /* > 0: agree() reports this rank out of memory */
    int agree_calls, run_calls;
    size_t evaluated;
} fake;

static int fake_agree(phc_dist *d, int rc, phc_error *err)
{
    fake *f = d->impl;
    f->agree_calls++;
    if (rc)
        return rc;
    if (f->fail_rank > 0)
        return phc_error_set(err, PHC_ERR_NOMEM, "rank %d: out of memory", f->fail_rank);
    return PHC_OK;
}

static int fake_run(phc_dist *d, size_t n_out, const size_t *rows, size_t n_rows, phc_dist_eval_fn eval,
                    phc_dist_record_fn record, void *ctx, phc_error *err)
{
    fake *f = d->impl;
    f->run_calls++;
    double *out = malloc(n_out * sizeof *out);
    int rc = PHC_OK;
    if (d->rank != 0) { /* a worker gets no rows and no recorder; it evaluates what it is sent */
        CHECK(rows == NULL && n_rows == 0 && record == NULL);
        for (size_t r = 0; r < 3; ++r) {
            CHECK(eval(ctx, r, out) == 0);
            CHECK(isfinite(out[0]) && isfinite(out[1]));
            f->evaluated++;
        }
    } else { /* the results arrive in another order than the rows' */
        for (size_t i = n_rows; i-- > 0 && rc == PHC_OK;) {
            const int failed = eval(ctx, rows[i], out);
            rc = record(ctx, rows[i], failed, out, err);
            f->evaluated++;
        }
    }
    free(out);
    return rc;
}

static phc_dist fake_dist(int rank, fake *f)
{
    phc_dist d;
    memset(&d, 0, sizeof d);
    d.rank = rank;
    d.size = 2;
    d.agree = fake_agree;
    d.run = fake_run;
    d.impl = f;
    return d;
}

/* ---- tests ------------------------------------------------------------------------------- */

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *text = calloc(1, 1 << 22);
    if (text)
        fread(text, 1, (1 << 22) - 1, f);
    fclose(f);
    return text;
}

static int by_text(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The ledger's records (lines starting with a digit), sorted, joined. */
static char *sorted_records(const char *path)
{
    char *text = slurp(path);
    if (!text)
        return NULL;
    size_t n = 0, cap = 64;
    char **lines = malloc(cap * sizeof *lines);
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n"))
        if (line[0] >= '0' && line[0] <= '9') {
            if (n == cap)
                lines = realloc(lines, (cap *= 2) * sizeof *lines);
            lines[n++] = line;
        }
    qsort(lines, n, sizeof *lines, by_text);
    size_t total = 1;
    for (size_t i = 0; i < n; ++i)
        total += strlen(lines[i]) + 1;
    char *joined = calloc(1, total);
    for (size_t i = 0; i < n; ++i) {
        strcat(joined, lines[i]);
        strcat(joined, "\n");
    }
    free(lines);
    free(text);
    return joined;
}

static void test_launcher_environment(void)
{
    const char *vars[] = {"OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"};
    for (size_t i = 0; i < 4; ++i)
        unsetenv(vars[i]);
    CHECK(phc_dist_launched() == 0);
    CHECK(phc_dist_launched_rank() == 0);
    phc_dist *d = (phc_dist *)&d; /* must be set to NULL */
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_dist_open(&d, &err) == PHC_OK);
    CHECK(d == NULL);
    phc_dist_close(NULL);
    setenv("PMIX_RANK", "3", 1);
    CHECK(phc_dist_launched() == 1);
    CHECK(phc_dist_launched_rank() == 3);
    setenv("OMPI_COMM_WORLD_RANK", "x1", 1); /* not a number: the next variable decides */
    CHECK(phc_dist_launched_rank() == 3);
    setenv("OMPI_COMM_WORLD_RANK", "5", 1);
    CHECK(phc_dist_launched_rank() == 5);
    unsetenv("PMIX_RANK");
    unsetenv("OMPI_COMM_WORLD_RANK");
    setenv("OMPI_COMM_WORLD_SIZE", "4", 1);
    CHECK(phc_dist_launched() == 1);
    CHECK(phc_dist_launched_rank() == 0);
    unsetenv("OMPI_COMM_WORLD_SIZE");
}

static void test_master_and_worker(const char *tmp)
{
    phc_problem *pb = ishigami_problem();
    char one[4200], two[4200], path_a[4300], path_b[4300];
    snprintf(one, sizeof one, "%s/one", tmp);
    snprintf(two, sizeof two, "%s/two", tmp);
    phc_study_options o = phc_study_options_default();
    o.samples = 64;
    phc_study_summary sum;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_study_run(pb, &o, NULL, one, &sum, &err) == PHC_OK);
    CHECK(sum.computed == 64 * 5);
    phc_study_summary_clear(&sum);

    /* the master: rows recorded in reverse order */
    fake f = {0, 0, 0, 0};
    phc_dist d = fake_dist(0, &f);
    o.dist = &d;
    CHECK(phc_study_run(pb, &o, NULL, two, &sum, &err) == PHC_OK);
    CHECK(f.agree_calls == 1 && f.run_calls == 1);
    CHECK(f.evaluated == 64 * 5);
    CHECK(sum.computed == 64 * 5 && sum.reused == 0 && sum.failed == 0);
    phc_study_summary_clear(&sum);
    snprintf(path_a, sizeof path_a, "%s/result.json", one);
    snprintf(path_b, sizeof path_b, "%s/result.json", two);
    char *a = slurp(path_a), *b = slurp(path_b);
    CHECK(a && b && strcmp(a, b) == 0);
    free(a);
    free(b);
    snprintf(path_a, sizeof path_a, "%s/ledger.tsv", one);
    snprintf(path_b, sizeof path_b, "%s/ledger.tsv", two);
    a = sorted_records(path_a);
    b = sorted_records(path_b);
    CHECK(a && b && strlen(a) > 1000 && strcmp(a, b) == 0);
    free(a);
    free(b);
    /* not in row order: the records follow arrival */
    char *raw = slurp(path_b);
    CHECK(raw && strstr(raw, "@ end\n319\t") != NULL);
    free(raw);

    /* a worker: evaluates, writes nothing */
    char three[4200], ledger[4300];
    snprintf(three, sizeof three, "%s/three", tmp);
    snprintf(ledger, sizeof ledger, "%s.ledger", three);
    fake w = {0, 0, 0, 0};
    phc_dist dw = fake_dist(1, &w);
    o.dist = &dw;
    CHECK(phc_study_run(pb, &o, NULL, three, &sum, &err) == PHC_OK);
    CHECK(w.agree_calls == 1 && w.run_calls == 1 && w.evaluated == 3);
    struct stat st;
    CHECK(stat(three, &st) != 0);
    CHECK(stat(ledger, &st) != 0);
    phc_study_summary_clear(&sum);

    /* another rank failed to set up: the master stops with its message */
    char four[4200];
    snprintf(four, sizeof four, "%s/four", tmp);
    fake bad = {1, 0, 0, 0};
    phc_dist db = fake_dist(0, &bad);
    o.dist = &db;
    phc_error_clear(&err);
    CHECK(phc_study_run(pb, &o, NULL, four, &sum, &err) == PHC_ERR_NOMEM);
    CHECK_STR_CONTAINS(err.message, "rank 1: out of memory");
    CHECK(bad.agree_calls == 1 && bad.run_calls == 0 && bad.evaluated == 0);
    CHECK(stat(four, &st) != 0);
    phc_study_summary_clear(&sum);

    /* a study that fails before its loop still agrees once (with its error) */
    fake early = {0, 0, 0, 0};
    phc_dist de = fake_dist(1, &early);
    o.dist = &de;
    o.samples = 2; /* too few: refused while building the design */
    phc_error_clear(&err);
    CHECK(phc_study_run(pb, &o, NULL, four, &sum, &err) == PHC_ERR_INPUT);
    CHECK(early.agree_calls == 1 && early.run_calls == 0);
    phc_study_summary_clear(&sum);
    phc_problem_free(pb);
}

int main(void)
{
    char tmp[] = "/tmp/phc_study_dist.XXXXXX";
    if (!mkdtemp(tmp)) {
        fprintf(stderr, "mkdtemp failed\n");
        return 1;
    }
    test_launcher_environment();
    test_master_and_worker(tmp);
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmp);
    return check_finish("test_study_dist");
}
