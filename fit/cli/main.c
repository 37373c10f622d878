/* The phytocal command (DESIGN.md §4).  The only place that prints.
 *
 *   phytocal fit CONFIG.yaml [-o DIR] [--plots all|none] [--force] [--quiet]
 *   phytocal fit A.yaml B.yaml ... -o DIR | CONFIG.yaml --each COLUMN -o DIR   (batch)
 *   phytocal simulate CONFIG.yaml [-o DIR] [--force] [--quiet]
 *   phytocal grow CONFIG.yaml [-o DIR] [--force] [--quiet]
 *   phytocal sensitivity CONFIG.yaml [-o DIR] [--method morris|sobol] [--samples N] [--seed S] [--resume] ...
 *   phytocal profile CONFIG.yaml [-o DIR] [--points N] [--level L] [--force] [--quiet]
 *   phytocal mcmc CONFIG.yaml [-o DIR] [--method dram|stretch] [--samples N] [--chains C] [--seed S] ...
 *   phytocal report DIR/result.json [--strict] [--level L]
 *   phytocal report --check DIR
 *   phytocal help [COMMAND | KIND | config | soil]   phytocal COMMAND --help
 *   phytocal version                    phytocal --version
 *
 * Exit codes: 0 success; 1 usage; 2 bad input; 3 the fit did not converge or
 * (with --strict) a report check failed, or (--check) an input or output
 * changed; 4 internal error. */
#include <errno.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "fit/batch_summary.h"
#include "fit/engine/ceres_bridge.h"
#include "fit/config.h"
#include "fit/config_help.h"
#include "fit/engine/fit.h"
#include "fit/engine/provenance.h"
#include "fit/grow.h"
#include "fit/grow_config.h"
#include "fit/mcmc_study.h"
#include "fit/report.h"
#include "fit/profile_study.h"
#include "fit/result_json.h"
#include "fit/run_dir.h"
#include "fit/sensitivity_study.h"
#include "fit/study_dist.h"
#include "fit/simulate.h"
#include "fit/version.h"
#include "measurements/atomic_file.h"
#include "phc_git_commit.h"

enum { EXIT_OK = 0, EXIT_USAGE = 1, EXIT_INPUT = 2, EXIT_FIT = 3, EXIT_INTERNAL = 4 };

/* ---- help ------------------------------------------------------------------------------ */

typedef struct command_help {
    const char *name, *synopsis, *text;
} command_help;

static const command_help commands[] = {
    {"fit", "phytocal fit CONFIG.yaml [-o DIR] [--plots all|none] [--force] [--quiet]\n"
            "  phytocal fit A.yaml B.yaml ... -o DIR [--plots all|none] [--force] [--quiet]\n"
            "  phytocal fit CONFIG.yaml --each COLUMN -o DIR [--plots all|none] [--force] [--quiet]",
     "Fits the configuration's parameters to its data sets (Ceres Solver), then judges\n"
     "the residuals and parameters, and writes a run directory:\n"
     "  result.json        machine-readable result (README: result.json)\n"
     "  report.md          verdict, parameters with intervals, checks, provenance\n"
     "  *.png              data and fit, residuals, normal QQ, autocorrelation\n"
     "  phytocal-run.json  manifest: the files written here (SHA-256) and provenance\n"
     "and prints a summary table.\n"
     "\n"
     "options:\n"
     "  -o, --output DIR   run directory (default runs/<name>/, name from the config)\n"
     "  --plots all|none   all (default): the plots above and a kind's own pictures and\n"
     "                     files at the fitted values; none: result.json, report.md\n"
     "                     (saying no plots were drawn) and the manifest only, the\n"
     "                     same numbers (for batches of many fits)\n"
     "  --force            replace DIR if it is an earlier phytocal run directory that\n"
     "                     holds nothing but what phytocal wrote (its manifest lists\n"
     "                     it); anything else in DIR, and any DIR holding the run's\n"
     "                     config or data, is refused and left untouched\n"
     "  -q, --quiet        print nothing on success (no progress, no summary)\n"
     "  -h, --help         this text\n"
     "\n"
     "Progress goes to stderr: one updating line on a terminal (start k of n, solver\n"
     "iteration and cost, elapsed time), plain lines otherwise.  The files are on disk\n"
     "when phytocal returns: one sync of the file system before DIR is renamed into\n"
     "place (not one per file).\n"
     "\n"
     "Batch (many small fits in one process; -o DIR is required):\n"
     "  A.yaml B.yaml ...  each config fitted into DIR/<config stem>/ (two configs with\n"
     "                     the same stem are refused before anything is fitted)\n"
     "  --each COLUMN      one fit per value of COLUMN in the config's table(s) (kinds\n"
     "                     curve, pv_curve, weight_curve), each on its rows only, into\n"
     "                     DIR/<value>/; bytes of the value other than letters, digits,\n"
     "                     '-', '_', '.' (and a leading '.') are written %XX\n"
     "Each fit's directory is a run directory as above; DIR holds them, summary.tsv and\n"
     "summary.md (one row per fit: status, verdict, cost, R², parameters with standard\n"
     "errors) and its own manifest, so --force and report --check treat DIR as one run.\n"
     "A fit that fails to load or solve is named in the summary and the others are\n"
     "still done.  Exit code: 0 when every fit converged, else the worst (highest) of\n"
     "the fits' own codes (2 bad input, 3 not converged, 4 internal).  --each reads and\n"
     "hashes the config and its tables once for all groups; the batch is synced once."},
    {"simulate", "phytocal simulate CONFIG.yaml [-o DIR] [--force] [--quiet]",
     "Runs every data set's model at the configured start values, without fitting, and\n"
     "writes a run directory (default runs/<name>-simulation/) with <data set>_simulated.csv\n"
     "(x, observed, model) and <data set>_simulated.png, plus each kind's own outputs\n"
     "(fields, frames, plant files), so start values can be checked before a fit.\n"
     "\n"
     "options: -o DIR, --force, --quiet, --help as for fit."},
    {"grow", "phytocal grow CONFIG.yaml [-o DIR] [--force] [--quiet]",
     "Grows a climbing plant (Hadrich et al., CGF 2017; README: Climbing plants) from a\n"
     "seed on a support mesh, as a grow config says (keys below), and writes a run\n"
     "directory (default runs/<name>-grow/):\n"
     "  frame_NNNN.vtk     the plant every frame_interval (ParaView: Tube filter on radius)\n"
     "  growth.csv         per frame: particles, tips, laterals, anchored, height, length\n"
     "  plant_side.png     the final plant seen along y (x-z) and along x (y-z:\n"
     "  plant_front.png    plant_front.png), colour = branch order\n"
     "  support.vtk        the support mesh\n"
     "  result.json        the final plant: particles, laterals per order, height,\n"
     "                     attached fraction, ...; and the provenance\n"
     "  phytocal-run.json  manifest\n"
     "and prints a summary.  A grow config is not a calibration config: it has no\n"
     "parameters to fit and no data.\n"
     "\n"
     "options: -o DIR, --force, --quiet, --help as for fit."},
    {"sensitivity", "phytocal sensitivity CONFIG.yaml [-o DIR] [--method morris|sobol] [--samples N] [--seed S]\n"
                    "                     [--resume] [--second-order] [--design sobol|random] [--levels P]\n"
                    "                     [--points T] [--force] [--quiet]",
     "Global sensitivity study over the free parameters' priors (`prior:`, else uniform on\n"
     "the bounds; a `groups:` entry is one factor) of the model's outputs: the cost, per\n"
     "data set its cost and mean prediction, the config's named `outputs:`, and per data\n"
     "set its prediction at every observation (indices per observation and over x).\n"
     "Writes a run directory (default runs/<name>-sensitivity/): result.json (indices\n"
     "with 95% bootstrap intervals), report.md (which factors matter),\n"
     "<output>_sensitivity.png, <data set>_over_x.png, ledger.tsv.\n"
     "\n"
     "options:\n"
     "  --method M         sobol (default: first-order and total indices, Saltelli design)\n"
     "                     or morris (elementary effects mu*, sigma; Morris 1991 trajectories)\n"
     "  --samples N        sobol: base samples (default 512; N (k + 2) evaluations for k\n"
     "                     factors); morris: trajectories (default 20; N (k + 1) evaluations)\n"
     "  --seed S           design (morris, --design random) and bootstrap (default 1)\n"
     "  --second-order     sobol: also the second-order indices (N (2k + 2) evaluations)\n"
     "  --design D         sobol: GSL's Sobol sequence (default) or random (Mersenne Twister)\n"
     "  --levels P         morris: grid levels, even (default 4)\n"
     "  --points T         per data set, at most T observations (evenly spaced) get\n"
     "                     indices of their own (default 100; 0: none)\n"
     "  --resume           continue an interrupted study from DIR.ledger (its finished\n"
     "                     evaluations are not recomputed; a ledger of another config or\n"
     "                     design is refused, naming what differs)\n"
     "  -o DIR, --force, --quiet as for fit.\n"
     "\n"
     "Under mpirun or srun (at least 2 ranks) the evaluations are spread over the ranks:\n"
     "rank 0 hands them out, evaluates some itself, keeps the ledger, prints and writes;\n"
     "the result is the one-process run's (README: \"On a cluster\")."},
    {"profile", "phytocal profile CONFIG.yaml [-o DIR] [--points N] [--level L] [--force] [--quiet]",
     "Fits the configuration, then traces the profile likelihood of every free parameter:\n"
     "the parameter is fixed at steps away from the optimum (adaptive) while Ceres\n"
     "re-optimises the others, until the cost rises by the likelihood-ratio threshold\n"
     "(chi2_1 / 2 with absolute sigmas, else the F test of lmfit's conf_interval) or a\n"
     "bound is reached.  Writes a run directory (default runs/<name>-profile/):\n"
     "result.json (profiles, likelihood-based and Wald intervals), report.md (verdict:\n"
     "intervals that disagree, sides open to a bound, flat = practically\n"
     "non-identifiable) and profile_<parameter>.png.\n"
     "\n"
     "options:\n"
     "  --points N         target steps per side before the threshold (default 12, >= 3)\n"
     "  --level L          confidence level, 0 < L < 1 (default 0.95)\n"
     "  -o DIR, --force, --quiet as for fit.\n"
     "\n"
     "Under mpirun or srun (at least 2 ranks) the parameters' profiles are spread over the\n"
     "ranks; rank 0 prints and writes the one-process run's result (README: \"On a cluster\")."},
    {"mcmc", "phytocal mcmc CONFIG.yaml [-o DIR] [--method dram|stretch] [--samples N] [--chains C] [--seed S]\n"
             "                     [--resume] [--force] [--quiet]",
     "Bayesian posterior of the free parameters by MCMC: Gaussian likelihood of the\n"
     "weighted residuals times the priors (`prior:`, else uniform on the bounds; flat and\n"
     "improper on an open bound, said in the report).  Known sigmas when every data set\n"
     "gives them, otherwise the error variance is sampled (inverse-gamma full conditional).\n"
     "Fits first and starts at the optimum.  Burn-in: the first half of each chain.\n"
     "Writes a run directory (default runs/<name>-mcmc/): result.json (medians, 95%\n"
     "intervals, tau, ESS, split-R-hat, thinned chains), report.md (did the chains mix:\n"
     "R-hat < 1.01 and ESS > 400), mcmc_trace.png, mcmc_pairs.png.\n"
     "\n"
     "options:\n"
     "  --method M         dram (default: adaptive Metropolis with delayed rejection, as\n"
     "                     FME's modMCMC) or stretch (affine-invariant ensemble, as emcee)\n"
     "  --samples N        draws per chain (dram, default 5000) or sweeps (stretch,\n"
     "                     default 10000); at least 100\n"
     "  --chains C         dram: chains (default 4, at least 2); stretch: walkers (default\n"
     "                     max(32, 2d), even, at least 2d for d free parameters)\n"
     "  --seed S           random seed (default 1): the same seed gives the same chains\n"
     "  --resume           dram: continue an interrupted run from DIR.ledger (the chains it\n"
     "                     holds are not rerun; a ledger of another config or setting is\n"
     "                     refused, naming what differs)\n"
     "  -o DIR, --force, --quiet as for fit.\n"
     "\n"
     "Under mpirun or srun (at least 2 ranks) DRAM's chains are spread over the ranks (rank\n"
     "0 keeps the ledger, prints and writes); the stretch ensemble's proposals are: every\n"
     "rank draws the same ones and evaluates its share, one all-gather per half-step.\n"
     "The result is the one-process run's (README: \"On a cluster\")."},
    {"report", "phytocal report DIR/result.json [--strict] [--level L]\n"
               "  phytocal report --check DIR",
     "Prints the summary of an earlier fit from its result.json; with --level L the\n"
     "residual checks and the verdict are recomputed at level L (0 < L < 1).\n"
     "\n"
     "options:\n"
     "  --strict           exit 3 when any check of the verdict fails\n"
     "  --level L          significance level of the residual checks (default: the fit's)\n"
     "  --check DIR        verify a run directory against its manifest: the config and\n"
     "                     every data file still have the SHA-256 recorded when the run\n"
     "                     read them, and every file the run wrote is unchanged; exit 3\n"
     "                     when anything changed or is missing\n"
     "  -h, --help         this text"},
    {"help", "phytocal help [COMMAND | KIND | config | soil]",
     "Without an argument: the commands, exit codes and data-set kinds.  With a command:\n"
     "its options.  With a data-set kind (e.g. weight_curve): that kind's configuration\n"
     "keys.  `phytocal help config`: every key of a configuration file that is not a\n"
     "kind's own (top level, parameters, solver, report, common data-set keys) and\n"
     "what each kind fits; `phytocal help soil`: the keys of a data set's soil: block.\n"
     "The key lists come from the tables the configuration loader checks."},
    {"version", "phytocal version | phytocal --version",
     "Prints the version, the git commit it was built from (when built from a checkout)\n"
     "and the Ceres Solver version."},
};
#define N_COMMANDS (sizeof commands / sizeof commands[0])

static const char exit_codes[] = "exit codes:\n"
                                 "  0  success\n"
                                 "  1  usage error (unknown command or option, missing argument)\n"
                                 "  2  bad input: the message names the file and line or key, and why\n"
                                 "  3  the fit did not converge, or report --strict found a failed check,\n"
                                 "     or report --check found a changed or missing file\n"
                                 "  4  internal error\n";

static void usage(FILE *out)
{
    fprintf(out, "usage:\n");
    for (size_t i = 0; i < N_COMMANDS; ++i)
        fprintf(out, "  %s\n", commands[i].synopsis);
}

static void print_overview(FILE *out)
{
    fprintf(out, "phytocal %s: calibrate and validate plant-physiology models against measurements.\n\n",
            phc_version());
    usage(out);
    fprintf(out, "\n%s\n", exit_codes);
    fprintf(out, "data-set kinds (phytocal help KIND for the keys of one):\n");
    size_t col = 0;
    for (size_t i = 0; i < phc_config_kind_count(); ++i) {
        const char *name = phc_config_kind_at(i)->name;
        if (col == 0 || col + strlen(name) + 2 > 78) {
            fprintf(out, "%s  ", col ? "\n" : "");
            col = 2;
        } else {
            fprintf(out, " ");
            col++;
        }
        col += (size_t)fprintf(out, "%s%s", name, i + 1 < phc_config_kind_count() ? "," : "");
    }
    fputc('\n', out);
    fprintf(out, "\nMore: phytocal help COMMAND (its options), phytocal help KIND (its keys),\n"
                 "phytocal help config (every key of a configuration file, what each kind fits);\n"
                 "the README walks through each model.\n");
}

static const command_help *find_command(const char *name)
{
    for (size_t i = 0; i < N_COMMANDS; ++i)
        if (strcmp(commands[i].name, name) == 0)
            return &commands[i];
    return NULL;
}

static void print_command_help(const command_help *c, FILE *out)
{
    fprintf(out, "usage: %s\n\n%s\n\n", c->synopsis, c->text);
    if (strcmp(c->name, "grow") == 0) {
        phc_grow_config_help(out);
        fputc('\n', out);
    }
    fprintf(out, "%s", exit_codes);
}

static int cmd_help(int argc, char **argv)
{
    if (argc == 0) {
        print_overview(stdout);
        return EXIT_OK;
    }
    const command_help *c = find_command(argv[0]);
    if (c) {
        print_command_help(c, stdout);
        return EXIT_OK;
    }
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_write_help(stdout, strcmp(argv[0], "config") == 0 ? NULL : argv[0], &err) == PHC_OK)
        return EXIT_OK;
    fprintf(stderr, "phytocal: %s; commands: fit, simulate, grow, sensitivity, profile, mcmc, report, help, version\n", err.message);
    return EXIT_USAGE;
}

static int wants_help(int argc, char **argv)
{
    for (int i = 0; i < argc; ++i)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0)
            return 1;
    return 0;
}

/* ---- errors and options ---------------------------------------------------------------- */

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
    int force, quiet, strict, check;
    double level;
    phc_run_plots plots; /* fit --plots */
} cli_options;

/* --plots VALUE of fit: 0, or EXIT_INPUT with the message printed. */
static int parse_plots(const char *value, phc_run_plots *out)
{
    if (phc_run_plots_parse(value, out) == 0)
        return 0;
    fprintf(stderr, "phytocal fit: --plots: expected all or none, found '%s'\n", value);
    return EXIT_INPUT;
}

/* Parses the arguments after the command; returns -1 on a usage error,
 * EXIT_INPUT on a bad option value (message printed).  `allowed` holds a
 * letter per accepted option: o f q s l c p (--plots). */
static int parse_args(const char *cmd, int argc, char **argv, cli_options *o, const char *allowed)
{
    memset(o, 0, sizeof *o);
    o->level = -1;
    o->plots = PHC_RUN_PLOTS_ALL;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "--plots") == 0 && strchr(allowed, 'p')) {
            if (i + 1 >= argc) {
                fprintf(stderr, "phytocal %s: --plots needs a value (all or none)\n", cmd);
                return -1;
            }
            if (parse_plots(argv[++i], &o->plots))
                return EXIT_INPUT;
        } else if ((strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) && strchr(allowed, 'o')) {
            if (i + 1 >= argc) {
                fprintf(stderr, "phytocal %s: %s needs a directory\n", cmd, a);
                return -1;
            }
            o->out_dir = argv[++i];
        } else if (strcmp(a, "--force") == 0 && strchr(allowed, 'f')) {
            o->force = 1;
        } else if ((strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) && strchr(allowed, 'q')) {
            o->quiet = 1;
        } else if (strcmp(a, "--strict") == 0 && strchr(allowed, 's')) {
            o->strict = 1;
        } else if (strcmp(a, "--check") == 0 && strchr(allowed, 'c')) {
            o->check = 1;
        } else if (strcmp(a, "--level") == 0 && strchr(allowed, 'l')) {
            char *end = NULL;
            if (i + 1 >= argc || (o->level = strtod(argv[++i], &end), *end != '\0') || !(o->level > 0 && o->level < 1)) {
                fprintf(stderr, "phytocal %s: --level needs a number between 0 and 1\n", cmd);
                return -1;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "phytocal %s: unknown option '%s' (phytocal %s --help lists the options)\n", cmd, a,
                    cmd);
            return -1;
        } else if (!o->input) {
            o->input = a;
        } else {
            fprintf(stderr, "phytocal %s: unexpected argument '%s'\n", cmd, a);
            return -1;
        }
    }
    if (!o->input) {
        fprintf(stderr, "phytocal %s: missing %s\n", cmd,
                strcmp(cmd, "report") == 0 ? "the result.json (or, with --check, the run directory)"
                                           : "the configuration file");
        return -1;
    }
    return 0;
}

/* ---- progress -------------------------------------------------------------------------- */

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
    const char *prefix; /* batch mode: "fit k/n NAME", or NULL */
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
    int len = st->prefix ? snprintf(line, sizeof line, "%s: ", st->prefix) : 0;
    len += snprintf(line + len, sizeof line - (size_t)len, "%s", p->stage);
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

/* ---- commands -------------------------------------------------------------------------- */

/* The start of `fit` and `simulate`: options, the config, the run
 * directory (-o, or runs/<name><suffix>), its check, and the provenance
 * (inputs hashed now, as read).  Returns -1 when *exit_code is set (usage
 * or bad input), 0 with *pb and *pv made otherwise. */
static int load_for_run(const char *cmd, int full_argc, char **full_argv, int argc, char **argv,
                        const char *suffix, cli_options *o, phc_problem **pb, phc_provenance **pv, char *dir,
                        size_t size, int *exit_code)
{
    phc_error err;
    phc_error_clear(&err);
    *pb = NULL;
    *pv = NULL;
    const int prc = parse_args(cmd, argc, argv, o, strcmp(cmd, "fit") == 0 ? "ofqp" : "ofq");
    if (prc == EXIT_INPUT) {
        *exit_code = EXIT_INPUT;
        return -1;
    }
    if (prc != 0) {
        fprintf(stderr, "usage: %s\n", find_command(cmd)->synopsis);
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
    /* "out/" is the folder "out": its temporary sibling must not land inside */
    for (size_t n = strlen(dir); n > 1 && dir[n - 1] == '/'; --n)
        dir[n - 1] = '\0';
    if (phc_run_dir_check(dir, o->force, *pb, &err) ||
        phc_provenance_begin(*pb, full_argc, full_argv, phc_version(), PHC_GIT_COMMIT, pv, &err)) {
        phc_problem_free(*pb);
        *pb = NULL;
        *exit_code = fail(&err);
        return -1;
    }
    return 0;
}

static int cmd_fit_batch(int full_argc, char **full_argv, int argc, char **argv);
static int is_batch(int argc, char **argv);

static int cmd_fit(int full_argc, char **full_argv, int argc, char **argv)
{
    if (is_batch(argc, argv))
        return cmd_fit_batch(full_argc, full_argv, argc, argv);
    cli_options o;
    phc_problem *pb = NULL;
    phc_provenance *pv = NULL;
    char dir[4096];
    int code;
    if (load_for_run("fit", full_argc, full_argv, argc, argv, "", &o, &pb, &pv, dir, sizeof dir, &code))
        return code;
    phc_error err;
    phc_error_clear(&err);
    progress_state prog = {isatty(STDERR_FILENO), now_seconds(), 0, "", 0, 0, NULL};
    phc_progress_fn progress = o.quiet ? NULL : progress_cb;
    phc_fit_result *res = NULL;
    int rc = phc_fit_run(pb, progress, &prog, &res, &err);
    if (rc) {
        progress_end(&prog);
        phc_provenance_free(pv);
        phc_problem_free(pb);
        return fail(&err);
    }
    /* kinds that refit themselves while writing (cross-validation) report too */
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        pb->datasets[d]->progress = progress;
        pb->datasets[d]->progress_data = &prog;
    }
    phc_progress_report(progress, &prog, "writing", 0, 0, -1, 0, dir);
    phc_provenance_end(pv);
    res->provenance = pv;
    phc_run_dir_options wo = phc_run_dir_options_default();
    wo.force = o.force;
    wo.plots = o.plots;
    rc = phc_run_dir_write_with(res, pb, dir, &wo, &err);
    progress_end(&prog);
    phc_problem_free(pb);
    if (rc) {
        phc_fit_result_free(res);
        return fail(&err);
    }
    if (!o.quiet) {
        phc_report_print_summary(res, stdout);
        printf("results: %s/ (result.json, report.md%s)\n", dir, o.plots == PHC_RUN_PLOTS_ALL ? ", plots" : "");
    }
    const int converged = res->summary.outcome == PHC_NLS_CONVERGED;
    phc_fit_result_free(res);
    if (!converged) {
        fprintf(stderr, "phytocal: the fit did not converge; results written to %s for inspection\n", dir);
        return EXIT_FIT;
    }
    return EXIT_OK;
}

/* ---- batch: several configs, or one config's groups (--each) ------------------------- */

/* The folder of one fit of a batch: the config's stem or the group's value,
 * with every byte other than letters, digits, '-', '_' and '.' (and a
 * leading '.') written as %XX, so that distinct values give distinct folders
 * and none is a path ("a/b" -> a%2Fb, ".." -> %2E.).  Returns -1 (out
 * untouched) for an empty value or a name longer than 100 bytes. */
static int batch_dir_name(const char *value, char *out, size_t size)
{
    static const char hex[] = "0123456789ABCDEF";
    size_t j = 0;
    if (!value[0])
        return -1;
    char buf[128];
    for (size_t i = 0; value[i]; ++i) {
        const unsigned char c = (unsigned char)value[i];
        const int plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                          c == '_' || (c == '.' && i > 0);
        if (j + (plain ? 1 : 3) > 100)
            return -1;
        if (plain) {
            buf[j++] = (char)c;
        } else {
            buf[j++] = '%';
            buf[j++] = hex[c >> 4];
            buf[j++] = hex[c & 15];
        }
    }
    buf[j] = '\0';
    snprintf(out, size, "%s", buf);
    return 0;
}

static char *config_stem(const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    char *s = strdup(base);
    char *dot = s ? strrchr(s, '.') : NULL;
    if (dot && dot != s)
        *dot = '\0';
    return s;
}

/* 1 when `fit` is asked for a batch: --each, or more than one config. */
static int is_batch(int argc, char **argv)
{
    int positional = 0;
    for (int i = 0; i < argc; ++i) {
        if (strcmp(argv[i], "--each") == 0)
            return 1;
        if (strcmp(argv[i], "-o") == 0 || strcmp(argv[i], "--output") == 0 || strcmp(argv[i], "--plots") == 0)
            ++i;
        else if (argv[i][0] != '-' || argv[i][1] == '\0')
            ++positional;
    }
    return positional > 1;
}

typedef struct batch_job {
    const char *config;  /* the config file */
    const phc_provenance *shared; /* --each: the inputs every group reads, hashed once */
    phc_config_table_cache *tables; /* --each: the tables, read once */
    char *group;         /* --each: the group's value */
    char name[128];      /* its folder below DIR ("" when refused) */
    phc_problem *pb;     /* several configs: loaded up front (NULL after an error) */
    phc_error load_err;  /* the error that stopped it before fitting */
    int load_rc;
} batch_job;

static int batch_row_text(char **field, const char *text)
{
    free(*field);
    *field = text ? strdup(text) : NULL;
    return text && !*field ? -1 : 0;
}

/* Fits one job into tmpdir/<name>/ and fills its row.  Returns the exit
 * code `phytocal fit` alone would give it. */
static int batch_fit_one(batch_job *job, const char *column, size_t k, size_t n, int full_argc, char **full_argv,
                         const char *tmpdir, int quiet, phc_run_plots plots, phc_batch_row *row)
{
    phc_error err;
    phc_error_clear(&err);
    char prefix[160], subdir[8192];
    snprintf(prefix, sizeof prefix, "fit %zu/%zu %s", k + 1, n, job->name[0] ? job->name : "?");
    batch_row_text(&row->fit, job->group ? job->group : job->name);
    batch_row_text(&row->group, job->group);
    batch_row_text(&row->config, job->config);
    phc_problem *pb = job->pb;
    job->pb = NULL;
    int rc = job->load_rc;
    if (rc)
        err = job->load_err;
    else if (!pb)
        rc = phc_config_load_group_cached(job->config, column, job->group, job->tables, &pb, &err);
    phc_provenance *pv = NULL;
    phc_fit_result *res = NULL;
    const int tty = isatty(STDERR_FILENO);
    progress_state prog = {tty, now_seconds(), 0, "", 0, 0, prefix};
    phc_progress_fn progress = !quiet && tty ? progress_cb : NULL;
    if (!quiet && !tty)
        fprintf(stderr, "%s\n", prefix);
    if (!rc)
        rc = job->shared ? phc_provenance_restart(job->shared, &pv, &err)
                         : phc_provenance_begin(pb, full_argc, full_argv, phc_version(), PHC_GIT_COMMIT, &pv, &err);
    if (!rc && (rc = phc_fit_run(pb, progress, &prog, &res, &err)))
        batch_row_text(&row->status, "failed");
    if (!rc) {
        for (size_t d = 0; d < pb->n_datasets; ++d) {
            pb->datasets[d]->progress = progress;
            pb->datasets[d]->progress_data = &prog;
        }
        phc_progress_report(progress, &prog, "writing", 0, 0, -1, 0, job->name);
        phc_provenance_end(pv);
        res->provenance = pv;
        pv = NULL;
        snprintf(subdir, sizeof subdir, "%s/%s", tmpdir, job->name);
        /* written in place in the batch's new folder, which the batch syncs
           once and renames into place (cmd_fit_batch) */
        phc_run_dir_options wo = phc_run_dir_options_default();
        wo.plots = plots;
        wo.nested = 1;
        if (!(rc = phc_run_dir_write_with(res, pb, subdir, &wo, &err)))
            batch_row_text(&row->dir, job->name);
    }
    progress_end(&prog);
    int code = exit_code_for(rc);
    if (res && phc_batch_row_set_result(row, res) != PHC_OK)
        code = EXIT_INTERNAL;
    if (rc) {
        if (!row->status)
            batch_row_text(&row->status, "error");
        batch_row_text(&row->message, err.message[0] ? err.message : phc_strerror(err.status));
    } else if (res->summary.outcome != PHC_NLS_CONVERGED) {
        batch_row_text(&row->status, phc_fit_status_name(res->summary.outcome));
        batch_row_text(&row->message, "the fit did not converge; results written for inspection");
        code = EXIT_FIT;
    } else {
        batch_row_text(&row->status, "converged");
    }
    row->exit_code = code;
    if (!quiet) {
        printf("%s: %s", row->fit, row->status);
        if (row->has_result) {
            printf(", %s, cost %.6g", row->verdict, row->cost);
            for (size_t d = 0; d < row->n_datasets; ++d)
                if (row->n_datasets == 1)
                    printf(", R² %.6g", row->r2[d]);
                else
                    printf(", R² %s %.6g", row->dataset_names[d], row->r2[d]);
        }
        if (code)
            printf(" (exit %d: %s)", code, row->message ? row->message : "");
        putchar('\n');
        fflush(stdout);
    }
    phc_fit_result_free(res);
    phc_provenance_free(pv);
    phc_problem_free(pb);
    return code;
}

/* phytocal fit A.yaml B.yaml ... -o DIR  |  phytocal fit CONFIG.yaml --each COLUMN -o DIR */
static int cmd_fit_batch(int full_argc, char **full_argv, int argc, char **argv)
{
    const char *out_dir = NULL, *column = NULL;
    int force = 0, quiet = 0, n_configs = 0;
    phc_run_plots plots = PHC_RUN_PLOTS_ALL;
    const char **configs = calloc((size_t)argc + 1, sizeof *configs);
    if (!configs)
        return EXIT_INTERNAL;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0 || strcmp(a, "--each") == 0 ||
            strcmp(a, "--plots") == 0) {
            if (i + 1 >= argc) {
                fprintf(stderr, "phytocal fit: %s needs %s\nusage: %s\n", a,
                        a[2] == 'e'   ? "a column name"
                        : a[2] == 'p' ? "a value (all or none)"
                                      : "a directory",
                        find_command("fit")->synopsis);
                free(configs);
                return EXIT_USAGE;
            }
            if (a[2] == 'p') {
                if (parse_plots(argv[++i], &plots)) {
                    free(configs);
                    return EXIT_INPUT;
                }
                continue;
            }
            *(a[2] == 'e' ? &column : &out_dir) = argv[++i];
        } else if (strcmp(a, "--force") == 0) {
            force = 1;
        } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
            quiet = 1;
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "phytocal fit: unknown option '%s' (phytocal fit --help lists the options)\n", a);
            free(configs);
            return EXIT_USAGE;
        } else {
            configs[n_configs++] = a;
        }
    }
    const char *why = n_configs == 0                ? "missing the configuration file"
                      : column && n_configs > 1     ? "--each splits one configuration's tables: give one config"
                      : !out_dir                    ? "a batch (several configs, or --each) needs -o DIR"
                      : column && !column[0]        ? "--each needs a column name"
                                                    : NULL;
    if (why) {
        fprintf(stderr, "phytocal fit: %s\nusage: %s\n", why, find_command("fit")->synopsis);
        free(configs);
        return EXIT_USAGE;
    }
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", out_dir);
    for (size_t n = strlen(dir); n > 1 && dir[n - 1] == '/'; --n)
        dir[n - 1] = '\0';

    phc_error err;
    phc_error_clear(&err);
    batch_job *jobs = NULL;
    size_t n_jobs = 0;
    int code = EXIT_OK;
    phc_config_table_cache *tables = NULL;
    phc_provenance *shared = NULL;
    if (column) {
        char **values = NULL;
        size_t n_values = 0;
        phc_problem *whole = NULL;
        if (!(tables = phc_config_table_cache_new())) {
            free(configs);
            return EXIT_INTERNAL;
        }
        if (phc_config_group_values_cached(configs[0], column, tables, &values, &n_values, &whole, &err)) {
            phc_config_table_cache_free(tables);
            free(configs);
            return fail(&err);
        }
        /* DIR may not hold the config or its data (run_dir.h); the config
           and data every group reads are hashed once, for all groups */
        int rc = phc_run_dir_check(dir, force, whole, &err);
        if (!rc)
            rc = phc_provenance_begin(whole, full_argc, full_argv, phc_version(), PHC_GIT_COMMIT, &shared, &err);
        phc_problem_free(whole);
        if (rc || !(jobs = calloc(n_values ? n_values : 1, sizeof *jobs))) {
            phc_config_group_values_free(values, n_values);
            phc_config_table_cache_free(tables);
            phc_provenance_free(shared);
            free(configs);
            return rc ? fail(&err) : EXIT_INTERNAL;
        }
        for (size_t g = 0; g < n_values; ++g) {
            batch_job *j = &jobs[n_jobs++];
            j->config = configs[0];
            j->shared = shared;
            j->tables = tables;
            j->group = values[g];
            values[g] = NULL;
            if (batch_dir_name(j->group, j->name, sizeof j->name) != 0)
                j->load_rc = phc_error_set(&j->load_err, PHC_ERR_INPUT,
                                           "%s: --each %s: the group '%.60s' has no folder name: an empty cell, or "
                                           "longer than 100 bytes once escaped",
                                           configs[0], column, j->group);
        }
        phc_config_group_values_free(values, n_values);
    } else {
        if (!(jobs = calloc((size_t)n_configs, sizeof *jobs))) {
            free(configs);
            return EXIT_INTERNAL;
        }
        for (int c = 0; c < n_configs; ++c) {
            batch_job *j = &jobs[n_jobs++];
            j->config = configs[c];
            char *stem = config_stem(configs[c]);
            if (!stem || batch_dir_name(stem, j->name, sizeof j->name) != 0)
                j->load_rc = phc_error_set(&j->load_err, PHC_ERR_INPUT, "%s: its stem '%s' makes no folder name",
                                           configs[c], stem ? stem : "");
            free(stem);
            for (int b = 0; b < c && !j->load_rc; ++b)
                if (jobs[b].name[0] && strcmp(jobs[b].name, j->name) == 0) {
                    fprintf(stderr,
                            "phytocal fit: %s and %s have the same stem '%s': both would be fitted into %s/%s/; "
                            "rename one (nothing was fitted)\n", jobs[b].config, j->config, j->name, dir, j->name);
                    code = EXIT_INPUT;
                }
        }
        /* loaded up front: DIR may not hold any config or its data */
        for (size_t c = 0; c < n_jobs && code == EXIT_OK; ++c) {
            if (jobs[c].load_rc)
                continue;
            jobs[c].load_rc = phc_config_load(jobs[c].config, &jobs[c].pb, &jobs[c].load_err);
            if (!jobs[c].load_rc && phc_run_dir_check(dir, force, jobs[c].pb, &err))
                code = fail(&err);
        }
    }
    char tmpdir[4096];
    if (code == EXIT_OK && phc_run_dir_begin(dir, force, NULL, tmpdir, sizeof tmpdir, &err))
        code = fail(&err);
    phc_batch_row *rows = code == EXIT_OK ? calloc(n_jobs ? n_jobs : 1, sizeof *rows) : NULL;
    if (code == EXIT_OK && !rows) {
        phc_run_dir_discard(tmpdir);
        code = EXIT_INTERNAL;
    }
    if (code == EXIT_OK) {
        int worst = EXIT_OK;
        size_t n_ok = 0;
        /* Durability: no file of the batch is fsynced on its own; the whole
           folder is synced once, before it is renamed to DIR (run_dir.h,
           phc_run_dir_begin and phc_run_dir_commit).  DIR appears only
           complete and on disk; a crash before leaves only
           DIR.tmp-XXXXXX, as before. */
        for (size_t k = 0; k < n_jobs; ++k) {
            const int c =
                batch_fit_one(&jobs[k], column, k, n_jobs, full_argc, full_argv, tmpdir, quiet, plots, &rows[k]);
            worst = c > worst ? c : worst;
            n_ok += c == EXIT_OK;
        }
        const int src = phc_batch_summary_write(tmpdir, column, rows, n_jobs, &err);
        if (src) {
            phc_run_dir_discard(tmpdir);
            code = fail(&err);
        } else if (phc_run_dir_commit(tmpdir, dir, NULL, &err)) {
            code = fail(&err);
        } else {
            code = worst;
            if (!quiet)
                printf("%zu of %zu fits converged; summary: %s/summary.tsv, %s/summary.md\n", n_ok, n_jobs, dir,
                       dir);
            if (n_ok < n_jobs)
                fprintf(stderr, "phytocal: %zu of %zu fits did not succeed (exit %d, the worst; each is named in %s/"
                        "summary.md)\n", n_jobs - n_ok, n_jobs, worst, dir);
        }
        for (size_t k = 0; k < n_jobs; ++k)
            phc_batch_row_clear(&rows[k]);
    }
    free(rows);
    for (size_t k = 0; k < n_jobs; ++k) {
        free(jobs[k].group);
        phc_problem_free(jobs[k].pb);
    }
    free(jobs);
    free(configs);
    phc_config_table_cache_free(tables);
    phc_provenance_free(shared);
    return code;
}

/* simulate: each data set's model at the start values (simulate.h). */
static int cmd_simulate(int full_argc, char **full_argv, int argc, char **argv)
{
    cli_options o;
    phc_problem *pb = NULL;
    phc_provenance *pv = NULL;
    char dir[4096];
    int code;
    if (load_for_run("simulate", full_argc, full_argv, argc, argv, "-simulation", &o, &pb, &pv, dir, sizeof dir,
                     &code))
        return code;
    phc_error err;
    phc_error_clear(&err);
    progress_state prog = {isatty(STDERR_FILENO), now_seconds(), 0, "", 0, 0, NULL};
    if (!o.quiet)
        phc_progress_report(progress_cb, &prog, "simulating", 0, 0, -1, 0, dir);
    const int rc = phc_simulate_write(pb, pv, dir, o.force, &err);
    progress_end(&prog);
    if (rc == PHC_OK && !o.quiet)
        printf("simulated %zu data set%s: %s/\n", pb->n_datasets, pb->n_datasets == 1 ? "" : "s", dir);
    phc_provenance_free(pv);
    phc_problem_free(pb);
    return rc ? fail(&err) : EXIT_OK;
}

/* grow: one climbing plant from a grow config (grow.h). */
static int cmd_grow(int full_argc, char **full_argv, int argc, char **argv)
{
    cli_options o;
    if (parse_args("grow", argc, argv, &o, "ofq") != 0) {
        fprintf(stderr, "usage: %s\n", find_command("grow")->synopsis);
        return EXIT_USAGE;
    }
    phc_error err;
    phc_error_clear(&err);
    phc_grow_config *cfg = NULL;
    if (phc_grow_config_load(o.input, &cfg, &err))
        return fail(&err);
    char dir[4096];
    if (o.out_dir)
        snprintf(dir, sizeof dir, "%s", o.out_dir);
    else
        snprintf(dir, sizeof dir, "runs/%s-grow", cfg->name);
    for (size_t n = strlen(dir); n > 1 && dir[n - 1] == '/'; --n)
        dir[n - 1] = '\0';
    phc_grow_inputs in;
    phc_grow_inputs_init(&in, cfg);
    phc_provenance *pv = NULL;
    if (phc_run_dir_check(dir, o.force, &in.pb, &err) ||
        phc_provenance_begin(&in.pb, full_argc, full_argv, phc_version(), PHC_GIT_COMMIT, &pv, &err)) {
        phc_grow_config_free(cfg);
        return fail(&err);
    }
    phc_grow_summary s;
    const int rc = phc_grow_write(cfg, pv, dir, o.force, &s, &err);
    if (rc == PHC_OK && !o.quiet) {
        printf("%s: grown for %g s in steps of %g s (seed %llu)\n", cfg->name, s.time, cfg->time_step,
               (unsigned long long)cfg->options.seed);
        printf("particles %zu (growing tips %zu), total length %.4g m, height %.4g m above the seed\n", s.particles,
               s.apical, s.total_length, s.height);
        printf("laterals %zu of %zu buds; per branch order:", s.laterals, s.bud_trials);
        for (size_t k = 1; k <= s.max_order && k < 8; ++k)
            printf(" %zu: %zu", k, s.laterals_per_order[k]);
        printf("%s\n", s.max_order == 0 ? " none" : "");
        printf("anchored %zu of %zu particles (attached fraction %.3f; made %zu, released %zu)\n", s.anchored,
               s.particles, s.attached_fraction, s.anchors_made, s.anchors_released);
        if (s.leaves)
            printf("leaves %zu, mean cos(leaf normal, light direction) %.3f\n", s.leaves, s.mean_leaf_cos);
        const int breaking = cfg->options.particles.break_threshold > 0 || cfg->options.particles.break_stress > 0;
        if (breaking)
            printf("broken links %zu (pieces dropped %zu with %zu particles; %zu particles still falling, not "
                   "counted above)\n",
                   s.breaks, s.pieces_dropped, s.particles_dropped, s.falling);
        if (cfg->options.particles.break_stress > 0 && s.breaks) {
            double mm[3]; /* the joint in mm to 0.1 mm (no "-0.0") */
            for (int k = 0; k < 3; ++k) {
                mm[k] = 1e3 * s.first_break_joint[k];
                if (mm[k] > -0.05 && mm[k] < 0.05)
                    mm[k] = 0;
            }
            printf("first break at %g s: bending stress %.4g MPa (break_stress %.4g MPa) at the joint (%.1f, %.1f, "
                   "%.1f) mm, below %s particle\n",
                   s.first_break_time, 1e-6 * s.first_break_stress, 1e-6 * cfg->options.particles.break_stress, mm[0],
                   mm[1], mm[2], s.first_break_parent_anchored ? "an anchored" : "a free");
        }
        if (breaking && isfinite(cfg->options.resprout_delay))
            printf("resprouted stumps %zu (a new tip %g s after their axis broke)\n", s.resprouts,
                   cfg->options.resprout_delay);
        if (cfg->options.cambium_rate > 0)
            printf("secondary growth: thickest radius %.4g mm (primary %.4g mm)\n", 1e3 * s.max_radius,
                   1e3 * cfg->options.radius);
        printf("results: %s/ (%zu frames, growth.csv, result.json, plant_side.png, plant_front.png, plant.obj)\n",
               dir, s.frames);
    }
    phc_provenance_free(pv);
    phc_grow_config_free(cfg);
    return rc ? fail(&err) : EXIT_OK;
}

/* sensitivity: a global sensitivity study (sensitivity_study.h).  Its own
 * options are taken out first; the rest goes through load_for_run. */
static int parse_count(const char *opt, const char *text, unsigned long long max, unsigned long long *value)
{
    char *end = NULL;
    errno = 0;
    if (!text || !*text || *text == '-' || (*value = strtoull(text, &end, 10), errno != 0) || *end != '\0' ||
        *value > max) {
        fprintf(stderr, "phytocal sensitivity: %s: expected a whole number from 0 to %llu, found '%s'\n", opt, max,
                text ? text : "");
        return -1;
    }
    return 0;
}

/* A config that did not load on this rank: the other ranks may have loaded
 * it and must not wait for this one (study_dist.h: one agree per study). */
static void dist_load_failed(phc_dist *dist, int code)
{
    if (!dist)
        return;
    phc_error e;
    phc_error_clear(&e);
    phc_error_set(&e, code == EXIT_INPUT ? PHC_ERR_INPUT : PHC_ERR_INTERNAL, "the config did not load");
    dist->agree(dist, e.status, &e);
}

static int sensitivity_run(int full_argc, char **full_argv, int argc, char **argv, phc_dist *dist)
{
    phc_study_options so = phc_study_options_default();
    long long points = -1; /* --points: observations per data set with indices (-1: the default) */
    so.dist = dist;
    char **rest = calloc((size_t)argc + 1, sizeof *rest);
    int n_rest = 0;
    if (!rest)
        return EXIT_INTERNAL;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        const int has_value = i + 1 < argc;
        unsigned long long v = 0;
        if (strcmp(a, "--method") == 0 || strcmp(a, "--design") == 0 || strcmp(a, "--samples") == 0 ||
            strcmp(a, "--seed") == 0 || strcmp(a, "--levels") == 0 || strcmp(a, "--points") == 0) {
            if (!has_value) {
                fprintf(stderr, "phytocal sensitivity: %s needs a value\nusage: %s\n", a,
                        find_command("sensitivity")->synopsis);
                free(rest);
                return EXIT_USAGE;
            }
            const char *val = argv[++i];
            if (strcmp(a, "--method") == 0) {
                if (strcmp(val, "sobol") == 0)
                    so.method = PHC_STUDY_SOBOL;
                else if (strcmp(val, "morris") == 0)
                    so.method = PHC_STUDY_MORRIS;
                else {
                    fprintf(stderr, "phytocal sensitivity: --method: unknown method '%s'; expected morris or sobol\n",
                            val);
                    free(rest);
                    return EXIT_INPUT;
                }
            } else if (strcmp(a, "--design") == 0) {
                if (strcmp(val, "sobol") == 0)
                    so.randomised = 0;
                else if (strcmp(val, "random") == 0)
                    so.randomised = 1;
                else {
                    fprintf(stderr, "phytocal sensitivity: --design: unknown design '%s'; expected sobol or random\n",
                            val);
                    free(rest);
                    return EXIT_INPUT;
                }
            } else if (parse_count(a, val, strcmp(a, "--seed") == 0     ? 4294967295ULL
                                           : strcmp(a, "--points") == 0 ? 100000ULL
                                                                        : 1ULL << 30,
                                   &v) != 0) {
                free(rest);
                return EXIT_INPUT;
            } else if (strcmp(a, "--samples") == 0) {
                so.samples = (size_t)v;
                if (v == 0) {
                    fprintf(stderr, "phytocal sensitivity: --samples: N = 0 is too small\n");
                    free(rest);
                    return EXIT_INPUT;
                }
            } else if (strcmp(a, "--seed") == 0) {
                so.seed = (unsigned long)v;
            } else if (strcmp(a, "--points") == 0) {
                points = (long long)v;
            } else {
                so.levels = (unsigned)v;
            }
        } else if (strcmp(a, "--resume") == 0) {
            so.resume = 1;
        } else if (strcmp(a, "--second-order") == 0) {
            so.second_order = 1;
        } else {
            rest[n_rest++] = argv[i];
        }
    }
    cli_options o;
    phc_problem *pb = NULL;
    phc_provenance *pv = NULL;
    char dir[4096];
    int code;
    if (load_for_run("sensitivity", full_argc, full_argv, n_rest, rest, "-sensitivity", &o, &pb, &pv, dir,
                     sizeof dir, &code)) {
        free(rest);
        dist_load_failed(dist, code);
        return code;
    }
    free(rest);
    /* test hook: stop after k new evaluations, as a killed study would */
    const char *stop = getenv("PHYTOCAL_STOP_AFTER");
    if (stop && *stop)
        so.stop_after = (size_t)strtoull(stop, NULL, 10);
    so.force = o.force;
    if (points >= 0)
        pb->series_points = (size_t)points;
    progress_state prog = {isatty(STDERR_FILENO), now_seconds(), 0, "", 0, 0, NULL};
    so.progress = o.quiet ? NULL : progress_cb;
    so.progress_data = &prog;
    phc_error err;
    phc_error_clear(&err);
    phc_study_summary sum;
    const int rc = phc_study_run(pb, &so, pv, dir, &sum, &err);
    progress_end(&prog);
    phc_provenance_free(pv);
    phc_problem_free(pb);
    if (rc) {
        phc_study_summary_clear(&sum);
        return fail(&err);
    }
    if (!o.quiet) {
        printf("%s study: %zu evaluations (%zu computed, %zu from the ledger, %zu failed)\n",
               so.method == PHC_STUDY_MORRIS ? "Morris" : "Sobol", sum.evaluations, sum.computed, sum.reused,
               sum.failed);
        fputs(sum.verdict ? sum.verdict : "", stdout);
        printf("results: %s/ (result.json, report.md, plots, ledger.tsv)\n", dir);
    }
    phc_study_summary_clear(&sum);
    return EXIT_OK;
}

/* Under mpirun or srun (study_dist.h) every rank runs the study: rank 0
 * prints, writes and returns the exit code; the workers print nothing
 * (stdout and stderr go to /dev/null) and exit 0.  Used by sensitivity,
 * profile and mcmc. */
typedef int (*dist_command_fn)(int full_argc, char **full_argv, int argc, char **argv, phc_dist *dist);

static int run_on_ranks(const char *name, dist_command_fn fn, int full_argc, char **full_argv, int argc,
                        char **argv)
{
    phc_dist *dist = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_dist_open(&dist, &err)) {
        /* Usually every rank fails alike (no module, one rank): rank 0 says
           so, and its exit ends the job.  Another rank waits 2 s for that,
           then reports its own failure (rank 0 may be waiting for it in
           MPI_Init) and exits, which ends the job too: no rank hangs. */
        const int rank = phc_dist_launched_rank();
        if (rank != 0) {
            sleep(2);
            fprintf(stderr, "phytocal %s: rank %d: %s\n", name, rank, err.message);
        } else {
            fprintf(stderr, "phytocal %s: %s\n", name, err.message);
        }
        return exit_code_for(err.status);
    }
    if (dist && dist->rank != 0 &&
        (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))) {
        /* cannot silence this worker: it still runs, and says so once */
        fprintf(stderr, "phytocal %s: rank %d: cannot redirect its output to /dev/null\n", name, dist->rank);
    }
    const int code = fn(full_argc, full_argv, argc, argv, dist);
    /* a worker's own failures reach rank 0 (study_dist.h: agree), which
       reports them; a worker exits 0, so that its exit cannot end the job
       (mpirun stops every rank at the first non-zero exit) before rank 0
       has printed */
    const int worker = dist && dist->rank != 0;
    phc_dist_close(dist);
    return worker ? EXIT_OK : code;
}

static int cmd_sensitivity(int full_argc, char **full_argv, int argc, char **argv)
{
    return run_on_ranks("sensitivity", sensitivity_run, full_argc, full_argv, argc, argv);
}

/* profile: profile likelihood of every free parameter (profile_study.h).
 * --points and --level are taken out first; the rest goes through
 * load_for_run. */
static int profile_run(int full_argc, char **full_argv, int argc, char **argv, phc_dist *dist)
{
    phc_profile_study_options po = phc_profile_study_options_default();
    char **rest = calloc((size_t)argc + 1, sizeof *rest);
    int n_rest = 0;
    if (!rest)
        return EXIT_INTERNAL;
    for (int i = 0; i < argc; ++i) {
        if (strcmp(argv[i], "--points") != 0 && strcmp(argv[i], "--level") != 0) {
            rest[n_rest++] = argv[i];
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "phytocal profile: %s needs a value\nusage: %s\n", argv[i],
                    find_command("profile")->synopsis);
            free(rest);
            return EXIT_USAGE;
        }
        const char *opt = argv[i], *val = argv[++i];
        char *end = NULL;
        errno = 0;
        if (strcmp(opt, "--points") == 0) {
            const unsigned long long v = strtoull(val, &end, 10);
            if (!*val || *val == '-' || errno || *end || v < 3 || v > 100000) {
                fprintf(stderr, "phytocal profile: --points: expected a whole number from 3 to 100000, found '%s'\n",
                        val);
                free(rest);
                return EXIT_INPUT;
            }
            po.points = (size_t)v;
        } else {
            const double v = strtod(val, &end);
            if (!*val || errno || *end || !(v > 0.0 && v < 1.0)) {
                fprintf(stderr, "phytocal profile: --level: expected a number between 0 and 1, found '%s'\n", val);
                free(rest);
                return EXIT_INPUT;
            }
            po.level = v;
        }
    }
    cli_options o;
    phc_problem *pb = NULL;
    phc_provenance *pv = NULL;
    char dir[4096];
    int code;
    if (load_for_run("profile", full_argc, full_argv, n_rest, rest, "-profile", &o, &pb, &pv, dir, sizeof dir,
                     &code)) {
        free(rest);
        dist_load_failed(dist, code);
        return code;
    }
    free(rest);
    progress_state prog = {isatty(STDERR_FILENO), now_seconds(), 0, "", 0, 0, NULL};
    po.force = o.force;
    po.dist = dist;
    po.progress = o.quiet ? NULL : progress_cb;
    po.progress_data = &prog;
    phc_error err;
    phc_error_clear(&err);
    phc_profile_summary sum;
    const int rc = phc_profile_study_run(pb, &po, pv, dir, &sum, &err);
    progress_end(&prog);
    phc_provenance_free(pv);
    phc_problem_free(pb);
    if (rc) {
        phc_profile_summary_clear(&sum);
        return fail(&err);
    }
    if (!o.quiet) {
        fputs(sum.table ? sum.table : "", stdout);
        printf("%zu parameter%s profiled: %zu with intervals that disagree with Wald, %zu open, %zu flat\n",
               sum.n_params, sum.n_params == 1 ? "" : "s", sum.n_disagree, sum.n_open, sum.n_flat);
        printf("results: %s/ (result.json, report.md, plots)\n", dir);
    }
    const int converged = sum.fit_converged;
    phc_profile_summary_clear(&sum);
    if (!converged) {
        fprintf(stderr, "phytocal: the fit did not converge; profiles written to %s for inspection\n", dir);
        return EXIT_FIT;
    }
    return EXIT_OK;
}

static int cmd_profile(int full_argc, char **full_argv, int argc, char **argv)
{
    return run_on_ranks("profile", profile_run, full_argc, full_argv, argc, argv);
}

/* mcmc: posterior sampling (mcmc_study.h).  Its own options first, the rest through load_for_run. */
static int mcmc_run(int full_argc, char **full_argv, int argc, char **argv, phc_dist *dist)
{
    phc_mcmc_options mo = phc_mcmc_options_default();
    char **rest = calloc((size_t)argc + 1, sizeof *rest);
    int n_rest = 0;
    if (!rest)
        return EXIT_INTERNAL;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "--method") != 0 && strcmp(a, "--samples") != 0 && strcmp(a, "--seed") != 0 &&
            strcmp(a, "--chains") != 0) {
            if (strcmp(a, "--resume") == 0)
                mo.resume = 1;
            else
                rest[n_rest++] = argv[i];
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "phytocal mcmc: %s needs a value\nusage: %s\n", a, find_command("mcmc")->synopsis);
            free(rest);
            return EXIT_USAGE;
        }
        const char *val = argv[++i];
        if (strcmp(a, "--method") == 0) {
            if (strcmp(val, "dram") == 0 || strcmp(val, "stretch") == 0) {
                mo.method = val[0] == 'd' ? PHC_MCMC_DRAM : PHC_MCMC_STRETCH;
                continue;
            }
            fprintf(stderr, "phytocal mcmc: --method: unknown method '%s'; expected dram or stretch\n", val);
            free(rest);
            return EXIT_INPUT;
        }
        char *end = NULL;
        errno = 0;
        const unsigned long long v = strtoull(val, &end, 10);
        if (!*val || *val == '-' || errno || *end || v > 4294967295ULL) {
            fprintf(stderr, "phytocal mcmc: %s: expected a whole number from 0 to 4294967295, found '%s'\n", a, val);
            free(rest);
            return EXIT_INPUT;
        }
        if (strcmp(a, "--samples") == 0)
            mo.samples = (size_t)v;
        else if (strcmp(a, "--chains") == 0)
            mo.chains = (size_t)v;
        else
            mo.seed = (unsigned long)v;
        if ((strcmp(a, "--samples") == 0 && v < PHC_MCMC_MIN_SAMPLES) || (strcmp(a, "--chains") == 0 && v < 2)) {
            fprintf(stderr, "phytocal mcmc: %s %llu is too small: at least %d %s\n", a, v,
                    a[2] == 's' ? PHC_MCMC_MIN_SAMPLES : 2, a[2] == 's' ? "draws per chain (the first half is "
                    "burn-in, split-R-hat halves the rest)" : "chains (split-R-hat compares chains; the stretch move "
                    "needs at least 2 d walkers)");
            free(rest);
            return EXIT_INPUT;
        }
    }
    cli_options o;
    phc_problem *pb = NULL;
    phc_provenance *pv = NULL;
    char dir[4096];
    int code;
    if (load_for_run("mcmc", full_argc, full_argv, n_rest, rest, "-mcmc", &o, &pb, &pv, dir, sizeof dir, &code)) {
        free(rest);
        dist_load_failed(dist, code);
        return code;
    }
    free(rest);
    mo.force = o.force;
    mo.dist = dist;
    const char *stop = getenv("PHYTOCAL_STOP_AFTER"); /* test hook: stop after k chains, as a killed run would */
    if (stop && *stop)
        mo.stop_after = (size_t)strtoull(stop, NULL, 10);
    progress_state prog = {isatty(STDERR_FILENO), now_seconds(), 0, "", 0, 0, NULL};
    mo.progress = o.quiet ? NULL : progress_cb;
    mo.progress_data = &prog;
    phc_error err;
    phc_error_clear(&err);
    phc_mcmc_run_summary sum;
    const int rc = phc_mcmc_run(pb, &mo, pv, dir, &sum, &err);
    progress_end(&prog);
    phc_provenance_free(pv);
    phc_problem_free(pb);
    if (rc)
        return fail(&err);
    if (!o.quiet)
        printf("%sresults: %s/ (result.json, report.md, mcmc_trace.png, mcmc_pairs.png)\n", sum.text ? sum.text : "",
               dir);
    phc_mcmc_run_summary_clear(&sum);
    return EXIT_OK;
}

static int cmd_mcmc(int full_argc, char **full_argv, int argc, char **argv)
{
    return run_on_ranks("mcmc", mcmc_run, full_argc, full_argv, argc, argv);
}

/* report --check DIR: the run's inputs and outputs against its manifest. */
static int check_run(const char *arg)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", arg);
    struct stat st;
    if (stat(dir, &st) == 0 && !S_ISDIR(st.st_mode)) { /* DIR/result.json given: its folder */
        char *slash = strrchr(dir, '/');
        if (slash)
            *slash = '\0';
        else
            snprintf(dir, sizeof dir, ".");
    }
    phc_error err;
    phc_error_clear(&err);
    phc_run_dir_item *items = NULL;
    size_t n = 0;
    if (phc_run_dir_verify(dir, &items, &n, &err))
        return fail(&err);
    static const char *const state_names[] = {"unchanged", "CHANGED", "MISSING"};
    size_t bad = 0;
    for (size_t i = 0; i < n; ++i) {
        printf("%-9s %-10s %s\n", state_names[items[i].state], items[i].role, items[i].path);
        bad += items[i].state != PHC_FILE_SAME;
    }
    phc_run_dir_verify_free(items, n);
    if (bad) {
        printf("check: %zu of %zu files changed or missing since the run\n", bad, n);
        return EXIT_FIT;
    }
    printf("check: all %zu files match the run's record\n", n);
    return EXIT_OK;
}

static int cmd_report(int argc, char **argv)
{
    cli_options o;
    if (parse_args("report", argc, argv, &o, "slc") != 0) {
        fprintf(stderr, "usage: %s\n", find_command("report")->synopsis);
        return EXIT_USAGE;
    }
    if (o.check)
        return check_run(o.input);
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

static int cmd_version(void)
{
    printf("phytocal %s%s%s (Ceres Solver %s)\n", phc_version(), PHC_GIT_COMMIT[0] ? ", git " : "", PHC_GIT_COMMIT,
           phc_nls_version());
    return EXIT_OK;
}

/* OpenMP's idle threads spin before they sleep (libgomp: GOMP_SPINCOUNT,
 * 300000 spins by default).  When another program holds a core, a thread
 * spinning at a barrier takes the CPU that the thread it waits for needs:
 * while other multi-threaded work held a core, a 25k-particle climbing frame
 * took 76.0 ms on two threads against 10.6 ms on one, and 10.2 ms on two
 * with passive waiting; on a quiet machine passive waiting costs 5-25%
 * (README "The command line", Threads).  libgomp reads its settings when
 * it loads, before main, so a command sets OMP_WAIT_POLICY=PASSIVE and runs
 * itself again, unless the user chose a policy (OMP_WAIT_POLICY or
 * GOMP_SPINCOUNT in the environment).  If the exec fails (no /proc), the
 * command goes on with the default policy. */
static void wait_passively(char **argv)
{
    if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT"))
        return;
    if (setenv("OMP_WAIT_POLICY", "PASSIVE", 1) != 0)
        return;
    execv("/proc/self/exe", argv);
}

int main(int argc, char **argv)
{
    /* GSL's default error handler aborts; the library checks its inputs and
     * reports errors itself. */
    gsl_set_error_handler_off();
    /* OpenBLAS (loaded with the Ceres module's SuiteSparse, or for the water
     * model's eigenproblems) starts a worker per core when it loads, and each
     * spins about 2^28 cycles waiting for work: 50-60 ms of CPU in a small
     * fit that never calls a threaded BLAS routine (README "Speed").  One
     * thread unless the user chose otherwise; phytocal's own parallel loops
     * use OpenMP, which this does not touch. */
    if (!getenv("OPENBLAS_NUM_THREADS") && !getenv("GOTO_NUM_THREADS") && !getenv("OMP_NUM_THREADS"))
        setenv("OPENBLAS_NUM_THREADS", "1", 0);
    if (argc < 2) {
        usage(stderr);
        fprintf(stderr, "(phytocal --help explains the commands, exit codes and data-set kinds)\n");
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "-h") == 0 || strcmp(cmd, "--help") == 0 || strcmp(cmd, "help") == 0)
        return cmd_help(argc - 2, argv + 2);
    if (strcmp(cmd, "version") == 0 || strcmp(cmd, "--version") == 0 || strcmp(cmd, "-V") == 0)
        return cmd_version();
    const command_help *c = find_command(cmd);
    if (c && wants_help(argc - 2, argv + 2)) {
        print_command_help(c, stdout);
        return EXIT_OK;
    }
    wait_passively(argv);
    if (strcmp(cmd, "fit") == 0)
        return cmd_fit(argc, argv, argc - 2, argv + 2);
    if (strcmp(cmd, "simulate") == 0)
        return cmd_simulate(argc, argv, argc - 2, argv + 2);
    if (strcmp(cmd, "grow") == 0)
        return cmd_grow(argc, argv, argc - 2, argv + 2);
    if (strcmp(cmd, "sensitivity") == 0)
        return cmd_sensitivity(argc, argv, argc - 2, argv + 2);
    if (strcmp(cmd, "profile") == 0)
        return cmd_profile(argc, argv, argc - 2, argv + 2);
    if (strcmp(cmd, "mcmc") == 0)
        return cmd_mcmc(argc, argv, argc - 2, argv + 2);
    if (strcmp(cmd, "report") == 0)
        return cmd_report(argc - 2, argv + 2);
    fprintf(stderr, "phytocal: unknown command '%s'\n", cmd);
    usage(stderr);
    return EXIT_USAGE;
}
