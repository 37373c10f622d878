/* The phytocal command (DESIGN.md §4).  The only place that prints.
 *
 *   phytocal fit CONFIG.yaml [-o DIR] [--force] [--quiet]
 *   phytocal simulate CONFIG.yaml [-o DIR] [--force]
 *   phytocal report DIR/result.json [--strict] [--level L]
 *   phytocal version
 *
 * Exit codes: 0 success; 1 usage; 2 bad input; 3 the fit did not converge or
 * (with --strict) a report check failed; 4 internal error. */
#include <gsl/gsl_errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "fit/ceres_bridge.h"
#include "fit/config.h"
#include "fit/fit.h"
#include "fit/report.h"
#include "fit/result_json.h"
#include "fit/run_dir.h"
#include "fit/simulate.h"

#ifndef PHC_VERSION
#define PHC_VERSION "dev"
#endif

enum { EXIT_OK = 0, EXIT_USAGE = 1, EXIT_INPUT = 2, EXIT_FIT = 3, EXIT_INTERNAL = 4 };

static void usage(FILE *out)
{
    fprintf(out, "usage:\n"
                 "  phytocal fit CONFIG.yaml [-o DIR] [--force] [--quiet]\n"
                 "  phytocal simulate CONFIG.yaml [-o DIR] [--force]\n"
                 "  phytocal report DIR/result.json [--strict] [--level L]\n"
                 "  phytocal version\n");
}

static int exit_code_for(int status)
{
    switch (status) {
    case PHC_OK: return EXIT_OK;
    case PHC_ERR_INPUT:
    case PHC_ERR_IO:
    case PHC_ERR_EXISTS:
    case PHC_ERR_DOMAIN:
    case PHC_ERR_INVALID: return EXIT_INPUT;
    case PHC_ERR_NOT_CONVERGED: return EXIT_FIT;
    default: return EXIT_INTERNAL;
    }
}

static int fail(const phc_error *err)
{
    fprintf(stderr, "phytocal: %s\n", err->message[0] ? err->message : phc_strerror(err->status));
    return exit_code_for(err->status);
}

typedef struct cli_options {
    const char *input;
    const char *out_dir;
    int force, quiet, strict;
    double level;
} cli_options;

/* Parses the arguments after the command; returns -1 on a usage error. */
static int parse_args(int argc, char **argv, cli_options *o, const char *allowed)
{
    memset(o, 0, sizeof *o);
    o->level = -1;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if ((strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) && strchr(allowed, 'o')) {
            if (i + 1 >= argc) {
                fprintf(stderr, "phytocal: %s needs a directory\n", a);
                return -1;
            }
            o->out_dir = argv[++i];
        } else if (strcmp(a, "--force") == 0 && strchr(allowed, 'f')) {
            o->force = 1;
        } else if (strcmp(a, "--quiet") == 0 && strchr(allowed, 'q')) {
            o->quiet = 1;
        } else if (strcmp(a, "--strict") == 0 && strchr(allowed, 's')) {
            o->strict = 1;
        } else if (strcmp(a, "--level") == 0 && strchr(allowed, 'l')) {
            char *end = NULL;
            if (i + 1 >= argc || (o->level = strtod(argv[++i], &end), *end != '\0') || !(o->level > 0 && o->level < 1)) {
                fprintf(stderr, "phytocal: --level needs a number between 0 and 1\n");
                return -1;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "phytocal: unknown option '%s'\n", a);
            return -1;
        } else if (!o->input) {
            o->input = a;
        } else {
            fprintf(stderr, "phytocal: unexpected argument '%s'\n", a);
            return -1;
        }
    }
    if (!o->input) {
        fprintf(stderr, "phytocal: missing input file\n");
        return -1;
    }
    return 0;
}

/* Progress (DESIGN.md §3): on a terminal one line that updates in place
 * (stage, step k of n, solver iteration and cost, elapsed time); otherwise
 * plain lines, one per stage or step and at most one every 5 s within a
 * step, so that logs stay short but long work still shows it is alive. */
typedef struct progress_state {
    int tty;
    double t0, last_line;
    char last_stage[32];
    size_t last_step;
    int open_line; /* a terminal line is drawn and not yet ended */
} progress_state;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int progress_cb(const phc_progress *p, void *user_data)
{
    progress_state *st = user_data;
    const double t = now_seconds(), elapsed = t - st->t0;
    const int new_step = strcmp(p->stage, st->last_stage) != 0 || p->step != st->last_step;
    char line[256];
    int len = snprintf(line, sizeof line, "%s", p->stage);
    if (p->steps > 0)
        len += snprintf(line + len, sizeof line - (size_t)len, " %zu/%zu", p->step, p->steps);
    if (p->detail)
        len += snprintf(line + len, sizeof line - (size_t)len, " (%s)", p->detail);
    if (p->iteration >= 0)
        len += snprintf(line + len, sizeof line - (size_t)len, "  iteration %d  cost %.6g", p->iteration, p->cost);
    snprintf(line + len, sizeof line - (size_t)len, "  %.1f s", elapsed);
    if (st->tty) {
        fprintf(stderr, "\r%-78.78s", line);
        st->open_line = 1;
    } else if (new_step || t - st->last_line >= 5.0) {
        fprintf(stderr, "%s\n", line);
        st->last_line = t;
    }
    snprintf(st->last_stage, sizeof st->last_stage, "%s", p->stage);
    st->last_step = p->step;
    fflush(stderr);
    return 0;
}

/* Ends a terminal progress line before other output. */
static void progress_end(progress_state *st)
{
    if (st->tty && st->open_line) {
        fputc('\n', stderr);
        st->open_line = 0;
    }
}

/* The start of `fit` and `simulate`: options, the config, the run
 * directory (-o, or runs/<name><suffix>).  Returns -1 when *exit_code is
 * set (usage or bad input), 0 with *pb loaded otherwise. */
static int load_for_run(int argc, char **argv, const char *allowed, const char *suffix, cli_options *o,
                        phc_problem **pb, char *dir, size_t size, int *exit_code)
{
    phc_error err;
    phc_error_clear(&err);
    *pb = NULL;
    if (parse_args(argc, argv, o, allowed) != 0) {
        usage(stderr);
        *exit_code = EXIT_USAGE;
        return -1;
    }
    if (phc_config_load(o->input, pb, &err)) {
        *exit_code = fail(&err);
        return -1;
    }
    if (o->out_dir)
        snprintf(dir, size, "%s", o->out_dir);
    else
        snprintf(dir, size, "runs/%s%s", (*pb)->name, suffix);
    return 0;
}

static int cmd_fit(int argc, char **argv)
{
    cli_options o;
    phc_problem *pb = NULL;
    char dir[4096];
    int code;
    if (load_for_run(argc, argv, "ofq", "", &o, &pb, dir, sizeof dir, &code))
        return code;
    phc_error err;
    phc_error_clear(&err);
    if (phc_run_dir_check(dir, o.force, &err)) {
        phc_problem_free(pb);
        return fail(&err);
    }
    progress_state prog = {isatty(STDERR_FILENO), now_seconds(), 0, "", 0, 0};
    phc_fit_result *res = NULL;
    int rc = phc_fit_run(pb, o.quiet ? NULL : progress_cb, &prog, &res, &err);
    progress_end(&prog);
    if (rc) {
        phc_problem_free(pb);
        return fail(&err);
    }
    rc = phc_run_dir_write(res, pb, dir, o.force, &err);
    phc_problem_free(pb);
    if (rc) {
        phc_fit_result_free(res);
        return fail(&err);
    }
    if (!o.quiet) {
        phc_report_print_summary(res, stdout);
        printf("results: %s/ (result.json, report.md, plots)\n", dir);
    }
    const int converged = res->summary.outcome == PHC_NLS_CONVERGED;
    phc_fit_result_free(res);
    if (!converged) {
        fprintf(stderr, "phytocal: the fit did not converge; results written to %s for inspection\n", dir);
        return EXIT_FIT;
    }
    return EXIT_OK;
}

/* simulate: each data set's model at the start values (simulate.h). */
static int cmd_simulate(int argc, char **argv)
{
    cli_options o;
    phc_problem *pb = NULL;
    char dir[4096];
    int code;
    if (load_for_run(argc, argv, "of", "-simulation", &o, &pb, dir, sizeof dir, &code))
        return code;
    phc_error err;
    phc_error_clear(&err);
    const int rc = phc_simulate_write(pb, dir, o.force, &err);
    if (rc == PHC_OK)
        printf("simulated %zu data set%s: %s/\n", pb->n_datasets, pb->n_datasets == 1 ? "" : "s", dir);
    phc_problem_free(pb);
    return rc ? fail(&err) : EXIT_OK;
}

static int cmd_report(int argc, char **argv)
{
    cli_options o;
    if (parse_args(argc, argv, &o, "sl") != 0) {
        usage(stderr);
        return EXIT_USAGE;
    }
    phc_error err;
    phc_error_clear(&err);
    phc_fit_result *res = NULL;
    if (phc_result_read_json(o.input, &res, &err))
        return fail(&err);
    if (o.level > 0 && phc_fit_recheck(res, o.level, &err)) {
        phc_fit_result_free(res);
        return fail(&err);
    }
    phc_report_print_summary(res, stdout);
    int rc = EXIT_OK;
    if (o.strict && !phc_report_all_passed(res)) {
        fprintf(stderr, "phytocal: --strict: %zu check%s failed\n", res->n_warnings, res->n_warnings == 1 ? "" : "s");
        rc = EXIT_FIT;
    }
    phc_fit_result_free(res);
    return rc;
}

int main(int argc, char **argv)
{
    /* GSL's default error handler aborts; the library checks its inputs and
     * reports errors itself. */
    gsl_set_error_handler_off();
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "fit") == 0)
        return cmd_fit(argc - 2, argv + 2);
    if (strcmp(cmd, "simulate") == 0)
        return cmd_simulate(argc - 2, argv + 2);
    if (strcmp(cmd, "report") == 0)
        return cmd_report(argc - 2, argv + 2);
    if (strcmp(cmd, "version") == 0) {
        printf("phytocal %s (Ceres Solver %s)\n", PHC_VERSION, phc_nls_version());
        return EXIT_OK;
    }
    if (strcmp(cmd, "-h") == 0 || strcmp(cmd, "--help") == 0 || strcmp(cmd, "help") == 0) {
        usage(stdout);
        return EXIT_OK;
    }
    fprintf(stderr, "phytocal: unknown command '%s'\n", cmd);
    usage(stderr);
    return EXIT_USAGE;
}
