/* Benchmark of the studies (issue 14, "Speed"): what `phytocal sensitivity`
 * and `phytocal mcmc --method stretch` cost beyond the model, and how they
 * compare with NumPy and emcee run in the same run.
 *
 * (a) Overhead per evaluation, one core, of phc_study_run (the library call
 *     behind `phytocal sensitivity`: design, evaluations through
 *     phc_study_evaluate, the run ledger, estimators with 1000 bootstrap
 *     resamples, result.json, report.md, plots): its evaluating stage after
 *     the first evaluation (the set-up before it is a fixed cost), per
 *     evaluation, minus the model's calls (predict, and predict_at for a named
 *     output between observations): timed directly on the same
 *     design points for the expression, clocked inside the same run for the
 *     weight curve (whose cost drifts between runs by more than the
 *     overhead).  The whole run per evaluation is printed too.  Two models:
 *       - expression: the Ishigami function (a = 7, b = 0.1) as a `curve`
 *         data set with three observations (y = 0, sigma 1; the config needs
 *         as many observations as parameters) and an expression of the three
 *         parameters on [-pi, pi] (not of x), N = 8192 (40 960 evaluations);
 *       - weight curve: the demo's seedling_sensitivity.yaml (water model on
 *         the seedling's plant graph, 3 factors, 4 parameters), N = 64 (320
 *         evaluations).
 *     The weight curve again with its model replayed (its predictions at
 *     the config's values computed once, scaled by 1 + 1e-3 p[0] per call),
 *     N = 512: the evaluating stage per evaluation is then all overhead,
 *     with no model time to subtract and no clock read per call
 *     (study_overhead_weight_curve_replayed).
 *     The study's stages are timed through its progress callback
 *     (evaluating -> estimating -> writing -> done), and the seam's parts
 *     separately: phc_study_evaluate per call, and one ledger append per
 *     record (phc_run_ledger_append into a file in /tmp, as the study does).
 * (b) The same Saltelli design of the Ishigami function in NumPy
 *     (tests/bench/study_peer.py saltelli: the N x 2k base points written
 *     here, the model vectorised, the study's five outputs (cost, mean
 *     prediction, the prediction at each of the three observations) and the
 *     series summary, estimators and 1000 bootstrap resamples in NumPy).
 *     The point estimates must agree with result.json's to 1e-9 (same
 *     points, same formulas).
 * (c) NIST Misra1a's posterior (flat priors, s2 unknown) with
 *     `phytocal mcmc --method stretch` (phc_mcmc_run: fit, sampling,
 *     diagnostics, result.json, report.md, plots) and with emcee
 *     (study_peer.py emcee: the marginal posterior of (b1, b2), s2
 *     integrated out), 32 walkers x 6000 steps each: both make 192 000
 *     proposals (ours: n_iter = 6001 with the start included).
 *
 * Times are CPU seconds of this process, all threads (the peers': Python's
 * process_time); wall time and other processes' load (bench_machine.h) are
 * printed beside them, and the NumPy comparison is made in both.  Prints `name: value unit` lines.  Runs from the build directory or anywhere:
 * files are found through PHC_SOURCE_DIR and PHC_SHARED_DATA. */
#include <jansson.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench_machine.h"
#include "fit/config.h"
#include "fit/engine/dataset.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/prior.h"
#include "fit/engine/problem.h"
#include "fit/engine/sobol_indices.h"
#include "fit/mcmc_study.h"
#include "fit/run_ledger.h"
#include "fit/sensitivity_study.h"

#ifndef PHC_SOURCE_DIR
#define PHC_SOURCE_DIR "."
#endif
#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define PEER_PY "/usr/bin/python3"
#define PEER_SCRIPT PHC_SOURCE_DIR "/tests/bench/study_peer.py"
#define TARGET_OVERHEAD_US 5.0
#define TARGET_PEER 10.0
#define N_EXPRESSION 8192
#define N_WEIGHT 64
#define N_REPLAY 512
#define REPEAT 3
#define WALKERS 32
#define STEPS 6000

static char work[64];

/* CPU seconds of this process, all its threads (the Sobol bootstrap runs
 * on OpenMP's threads; the rest of a study on this one): on this shared
 * machine wall-clock intervals stretch with other processes' load (printed
 * beside each timing) while CPU time does not; the peers are timed in CPU
 * seconds too (Python's time.process_time, also all threads). */
static double cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void print_loadavg(const char *when)
{
    char buf[128] = "";
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (!fgets(buf, sizeof buf, f))
            buf[0] = '\0';
        fclose(f);
    }
    buf[strcspn(buf, "\n")] = '\0';
    printf("machine_loadavg_%s: %s (1, 5, 15 min; %ld CPUs)\n", when, buf, sysconf(_SC_NPROCESSORS_ONLN));
}

/* ---- stage clock: the study's progress callback --------------------------------------- */

typedef struct stage_clock {
    double t_evaluating, t_estimating, t_writing; /* first report of the stage */
    double predict_at_evaluating;                 /* the model's time until then (wrapped predict) */
    size_t calls_at_evaluating;
    double t_sampling_first, t_sampling_last; /* mcmc: first and last "sampling ..." report */
    double t_fitting;
} stage_clock;

static double predict_seconds_now(void);
static size_t predict_calls_now(void);

/* Reads the clock only when a stage begins (a process CPU clock read is a
 * system call here, about 1.5 us: not once per evaluation). */
static int on_progress(const phc_progress *p, void *data)
{
    stage_clock *c = data;
    if (!p->stage)
        return 0;
    if (strcmp(p->stage, "evaluating") == 0) {
        if (isnan(c->t_evaluating)) {
            c->t_evaluating = cpu();
            c->predict_at_evaluating = predict_seconds_now();
            c->calls_at_evaluating = predict_calls_now();
        }
    } else if (strcmp(p->stage, "estimating") == 0 && isnan(c->t_estimating))
        c->t_estimating = cpu();
    else if (strcmp(p->stage, "writing") == 0 && isnan(c->t_writing))
        c->t_writing = cpu();
    else if (strcmp(p->stage, "fitting") == 0 && isnan(c->t_fitting))
        c->t_fitting = cpu();
    else if (strncmp(p->stage, "sampling", 8) == 0) {
        const double t = cpu();
        if (isnan(c->t_sampling_first))
            c->t_sampling_first = t;
        c->t_sampling_last = t;
    }
    return 0;
}

static stage_clock stage_clock_new(void)
{
    stage_clock c = {NAN, NAN, NAN, 0, 0, NAN, NAN, NAN};
    return c;
}

/* ---- the design's parameter values, as phc_study_run computes them ------------------- */

typedef struct design_points {
    size_t rows, n_params;
    double *x; /* rows x n_params, slot units */
    phc_saltelli_design *d;
} design_points;

/* The columns, factors and priors of fit/sensitivity_study.c (free
 * parameters in order; a group is one factor, numbered at its first
 * member), and the Saltelli design of N base samples with the study's
 * default options. */
static int make_design(const phc_problem *pb, size_t n, design_points *out)
{
    memset(out, 0, sizeof *out);
    const size_t np = pb->n_params;
    size_t *col = malloc(np * sizeof *col), *group_of = malloc(np * sizeof *group_of);
    size_t *gf = malloc((pb->n_groups + 1) * sizeof *gf);
    phc_prior *prior = calloc(np, sizeof *prior);
    size_t k = 0, nf = 0;
    phc_error err;
    phc_error_clear(&err);
    for (size_t g = 0; g < pb->n_groups; ++g)
        gf[g] = (size_t)-1;
    for (size_t i = 0; i < np; ++i) {
        const phc_parameter *p = &pb->params[i];
        if (p->fixed)
            continue;
        long grp = -1;
        for (size_t g = 0; g < pb->n_groups && grp < 0; ++g)
            for (size_t m = 0; m < pb->groups[g].n_members; ++m)
                if (pb->groups[g].members[m] == i)
                    grp = (long)g;
        col[k] = i;
        if (grp >= 0 && gf[grp] != (size_t)-1)
            group_of[k] = gf[grp];
        else {
            group_of[k] = nf++;
            if (grp >= 0)
                gf[grp] = group_of[k];
        }
        double lo, hi;
        phc_parameter_user_bounds(p, &lo, &hi);
        if (phc_prior_resolve(&p->prior, lo, hi, p->name, &prior[k], &err))
            return -1;
        ++k;
    }
    phc_saltelli_options so = phc_saltelli_options_default();
    so.n = n;
    so.seed = 1;
    if (phc_saltelli_design_new(k, group_of, nf, &so, &out->d, &err))
        return -1;
    out->rows = phc_saltelli_design_rows(out->d);
    out->n_params = np;
    out->x = malloc(out->rows * np * sizeof *out->x);
    double *u = malloc(k * sizeof *u);
    for (size_t r = 0; r < out->rows; ++r) {
        double *x = out->x + r * np;
        phc_saltelli_design_point(out->d, r, u);
        for (size_t i = 0; i < np; ++i)
            x[i] = pb->params[i].value;
        for (size_t c = 0; c < k; ++c) {
            const phc_parameter *p = &pb->params[col[c]];
            x[col[c]] = p->unit_scale * phc_prior_quantile(&prior[c], u[c]) + p->unit_offset;
        }
    }
    free(u);
    free(col);
    free(group_of);
    free(gf);
    free(prior);
    return 0;
}

static void design_points_free(design_points *d)
{
    free(d->x);
    phc_saltelli_design_free(d->d);
}

/* ---- (a) overhead per evaluation ------------------------------------------------------ */

/* The model's own time inside a study: each data set's predict is wrapped
 * (its ops swapped for a copy whose predict clocks the original's call in
 * this thread's CPU time), so that the overhead is measured within the same
 * run, paired, rather than as the difference of two runs of a model whose
 * cost drifts by a few per cent between runs on a shared machine.  The two
 * clock reads per call cost clock_pair seconds (calibrated below), taken
 * off the overhead. */
#define MAX_DATASETS 8
static const phc_dataset_ops *orig_ops[MAX_DATASETS];
static phc_dataset_ops timed_ops[MAX_DATASETS];
static const phc_dataset *timed_ds[MAX_DATASETS];
static double predict_seconds, clock_pair;
static size_t predict_calls;

static int timed_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    size_t d = 0;
    while (timed_ds[d] != ds)
        ++d;
    const double t0 = cpu();
    const int rc = orig_ops[d]->predict(ds, p, yhat, jac);
    predict_seconds += cpu() - t0;
    predict_calls++;
    return rc;
}

/* A named output at a time between observations (the demo's mass_12h)
 * solves the model again through predict_at: a model call too, clocked
 * alike. */
static int timed_predict_at(phc_dataset *ds, const double *p, const double *x, size_t n, double *y)
{
    size_t d = 0;
    while (timed_ds[d] != ds)
        ++d;
    const double t0 = cpu();
    const int rc = orig_ops[d]->predict_at(ds, p, x, n, y);
    predict_seconds += cpu() - t0;
    predict_calls++;
    return rc;
}

/* The replayed model (the weight curve's overhead without a model to
 * subtract): each data set's predictions at the config's values, computed
 * once, scaled by (1 + 1e-3 p[0]) so that the outputs vary with the design
 * (the estimators need variance): a copy and a multiply per observation,
 * counted as overhead. */
static double *replay_yhat[MAX_DATASETS];

static int replay_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    (void)jac;
    size_t d = 0;
    while (timed_ds[d] != ds)
        ++d;
    const double s = 1 + 1e-3 * p[0];
    for (size_t i = 0; i < ds->n; ++i)
        yhat[i] = replay_yhat[d][i] * s;
    return 0;
}

static int replay_predict_at(phc_dataset *ds, const double *p, const double *x, size_t n, double *y)
{
    (void)x;
    size_t d = 0;
    while (timed_ds[d] != ds)
        ++d;
    for (size_t i = 0; i < n; ++i)
        y[i] = replay_yhat[d][0] * (1 + 1e-3 * p[0]);
    return 0;
}

/* wrap: 1 clocks the model, 2 replays it (above); 0 restores it. */
static int replay_model(const phc_problem *pb, int on)
{
    for (size_t d = 0; d < pb->n_datasets && d < MAX_DATASETS; ++d) {
        phc_dataset *ds = pb->datasets[d];
        if (on) {
            double *p = malloc((ds->k ? ds->k : 1) * sizeof *p);
            replay_yhat[d] = malloc((ds->n ? ds->n : 1) * sizeof(double));
            for (size_t j = 0; j < ds->k; ++j)
                p[j] = pb->params[ds->param_index[j]].value;
            const int rc = ds->ops->predict(ds, p, replay_yhat[d], NULL);
            free(p);
            if (rc)
                return -1;
            orig_ops[d] = ds->ops;
            timed_ops[d] = *ds->ops;
            timed_ops[d].predict = replay_predict;
            if (ds->ops->predict_at)
                timed_ops[d].predict_at = replay_predict_at;
            timed_ds[d] = ds;
            ds->ops = &timed_ops[d];
        } else {
            ds->ops = orig_ops[d];
            free(replay_yhat[d]);
            replay_yhat[d] = NULL;
        }
    }
    return 0;
}

static double predict_seconds_now(void)
{
    return predict_seconds;
}

static size_t predict_calls_now(void)
{
    return predict_calls;
}

static void calibrate_clock(void)
{
    double best = INFINITY;
    for (int rep = 0; rep < REPEAT; ++rep) {
        volatile double sink = 0;
        const double t0 = cpu();
        for (int i = 0; i < 20000; ++i)
            sink += cpu() - cpu();
        const double t = (cpu() - t0) / 20000;
        best = t < best ? t : best;
        (void)sink;
    }
    clock_pair = best;
}

static void wrap_predict(const phc_problem *pb, int on)
{
    for (size_t d = 0; d < pb->n_datasets && d < MAX_DATASETS; ++d) {
        phc_dataset *ds = pb->datasets[d];
        if (on) {
            orig_ops[d] = ds->ops;
            timed_ops[d] = *ds->ops;
            timed_ops[d].predict = timed_predict;
            if (ds->ops->predict_at)
                timed_ops[d].predict_at = timed_predict_at;
            timed_ds[d] = ds;
            ds->ops = &timed_ops[d];
        } else {
            ds->ops = orig_ops[d];
        }
    }
}

typedef struct overhead_result {
    double run_us, direct_us, evaluate_us, ledger_us, loop_us, marginal_us, model_after_us, setup_s, estimate_s,
        write_s, other_load, wall_s;
    size_t evaluations;
    int ok;
} overhead_result;

/* Direct model calls: predict of every data set at each design point (best
 * of REPEAT passes), in us per design point. */
static double time_direct(const phc_problem *pb, const design_points *dp)
{
    size_t kmax = 1, nmax = 1;
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        kmax = pb->datasets[d]->k > kmax ? pb->datasets[d]->k : kmax;
        nmax = pb->datasets[d]->n > nmax ? pb->datasets[d]->n : nmax;
    }
    double *p = malloc(kmax * sizeof *p), *yhat = malloc(nmax * sizeof *yhat), best = INFINITY;
    volatile double sink = 0;
    for (int rep = 0; rep < REPEAT; ++rep) {
        const double t0 = cpu();
        for (size_t r = 0; r < dp->rows; ++r) {
            const double *x = dp->x + r * dp->n_params;
            for (size_t d = 0; d < pb->n_datasets; ++d) {
                phc_dataset *ds = pb->datasets[d];
                for (size_t j = 0; j < ds->k; ++j)
                    p[j] = x[ds->param_index[j]];
                if (ds->ops->predict(ds, p, yhat, NULL) == 0)
                    sink += yhat[0];
            }
        }
        const double t = cpu() - t0;
        best = t < best ? t : best;
    }
    (void)sink;
    free(p);
    free(yhat);
    return 1e6 * best / (double)dp->rows;
}

/* phc_study_evaluate at each design point, us per call (best of REPEAT). */
static double time_evaluate(const phc_problem *pb, const design_points *dp)
{
    phc_study_eval *w = phc_study_eval_new(pb);
    double *out = malloc(phc_study_outputs(pb) * sizeof *out), best = INFINITY;
    for (int rep = 0; rep < REPEAT; ++rep) {
        const double t0 = cpu();
        for (size_t r = 0; r < dp->rows; ++r)
            phc_study_evaluate(w, dp->x + r * dp->n_params, out);
        const double t = cpu() - t0;
        best = t < best ? t : best;
    }
    free(out);
    phc_study_eval_free(w);
    return 1e6 * best / (double)dp->rows;
}

/* One ledger append (flushed) per record of n_out outputs, us per record. */
static double time_ledger(size_t rows, size_t n_out)
{
    char path[128];
    snprintf(path, sizeof path, "%s/bench.ledger", work);
    const char *keys[1] = {"bench"}, *values[1] = {"ledger"};
    double *y = malloc(rows * n_out * sizeof *y), *v = malloc(n_out * sizeof *v), best = INFINITY;
    unsigned char *state = malloc(rows);
    for (int rep = 0; rep < REPEAT; ++rep) {
        phc_run_ledger *l = NULL;
        size_t found = 0;
        phc_error err;
        phc_error_clear(&err);
        if (phc_run_ledger_open(path, keys, values, 1, rows, n_out, 0, 1, y, state, &found, &l, &err))
            break;
        const double t0 = cpu();
        for (size_t r = 0; r < rows; ++r) {
            for (size_t j = 0; j < n_out; ++j)
                v[j] = sin(1.0 + (double)r) * (1.0 + (double)j) * 3.7e2; /* full-length %.17g numbers */
            phc_run_ledger_append(l, r, 0, v, &err);
        }
        const double t = cpu() - t0;
        phc_run_ledger_close(l, &err);
        best = t < best ? t : best;
    }
    unlink(path);
    free(y);
    free(v);
    free(state);
    return 1e6 * best / (double)rows;
}

/* The whole study, best of REPEAT; the stages of the best run. */
static int time_study(const phc_problem *pb, size_t n, const char *name, int wrap, overhead_result *res,
                      char *dir_out, size_t dir_size)
{
    double best = INFINITY;
    for (int rep = 0; rep < REPEAT; ++rep) {
        char dir[160];
        snprintf(dir, sizeof dir, "%s/%s-%d", work, name, rep);
        phc_study_options o = phc_study_options_default();
        o.samples = n;
        o.force = 1;
        stage_clock c = stage_clock_new();
        o.progress = on_progress;
        o.progress_data = &c;
        phc_study_summary sum;
        phc_error err;
        phc_error_clear(&err);
        predict_seconds = 0;
        predict_calls = 0;
        if (wrap == 2 && replay_model(pb, 1)) {
            printf("study_%s: the model cannot be evaluated at the config's values\n", name);
            return -1;
        }
        if (wrap == 1)
            wrap_predict(pb, 1);
        const cpu_mark m0 = cpu_now();
        const double c0 = cpu();
        const int rc = phc_study_run(pb, &o, NULL, dir, &sum, &err);
        const double c1 = cpu();
        const cpu_mark m1 = cpu_now();
        if (wrap == 1)
            wrap_predict(pb, 0);
        if (wrap == 2)
            replay_model(pb, 0);
        if (rc) {
            printf("study_%s: failed: %s\n", name, err.message);
            return -1;
        }
        const double t = c1 - c0;
        if (t < best) {
            best = t;
            res->evaluations = sum.evaluations;
            res->run_us = 1e6 * t / (double)sum.evaluations;
            res->loop_us = 1e6 * (c.t_estimating - c0) / (double)sum.evaluations;
            /* per evaluation after the first (set-up before it is a fixed cost) */
            const double later = (double)(sum.evaluations - 1);
            res->marginal_us = 1e6 * (c.t_estimating - c.t_evaluating) / later;
            res->model_after_us = wrap == 1 ? 1e6 * ((predict_seconds - c.predict_at_evaluating) +
                                                (double)(predict_calls - c.calls_at_evaluating) * clock_pair) / later
                                       : NAN;
            res->setup_s = c.t_evaluating - c0;
            res->wall_s = m1.wall - m0.wall;
            res->estimate_s = c.t_writing - c.t_estimating;
            res->write_s = c1 - c.t_writing;
            res->other_load = other_load(m0, m1);
            snprintf(dir_out, dir_size, "%s", dir);
        }
        phc_study_summary_clear(&sum);
    }
    return 0;
}

static int overhead(const phc_problem *pb, size_t n, const char *name, int wrap, overhead_result *res, char *dir,
                    size_t dir_size)
{
    memset(res, 0, sizeof *res);
    design_points dp;
    if (make_design(pb, n, &dp)) {
        printf("study_%s: cannot build the design\n", name);
        return -1;
    }
    res->direct_us = time_direct(pb, &dp);
    res->evaluate_us = time_evaluate(pb, &dp);
    res->ledger_us = time_ledger(dp.rows, phc_study_outputs(pb));
    design_points_free(&dp);
    if (time_study(pb, n, name, wrap, res, dir, dir_size))
        return -1;
    res->ok = 1;
    /* the overhead of one evaluation: the evaluating stage after its first
       evaluation, per evaluation, minus the model's time: clocked inside the
       same run when wrapped (a model that costs a millisecond varies by more
       than the overhead between runs), else the direct call timed apart */
    const double ovh = res->marginal_us - (wrap ? res->model_after_us : res->direct_us);
    const double whole = res->run_us - res->direct_us;
    printf("study_evaluations_%s: %zu (N = %zu)\n", name, res->evaluations, n);
    printf("study_direct_model_us_%s: %.3f us/eval (the data set's predict alone at the design's points, CPU, best of "
           "%d)\n", name, res->direct_us, REPEAT);
    printf("study_evaluate_us_%s: %.3f us/eval (phc_study_evaluate: predict + cost and mean)\n", name,
           res->evaluate_us);
    printf("study_ledger_append_us_%s: %.3f us/record (%zu outputs, formatted, checksummed, written)\n", name,
           res->ledger_us, phc_study_outputs(pb));
    printf("study_run_time_%s: %.4f s (CPU of the whole phc_study_run, best of %d: set-up %.4f s, evaluating %.4f s, "
           "estimates %.4f s, writing %.4f s; wall %.4f s, other load %.2f CPUs)\n", name,
           res->run_us * 1e-6 * (double)res->evaluations, REPEAT, res->setup_s,
           res->loop_us * 1e-6 * (double)res->evaluations - res->setup_s, res->estimate_s, res->write_s, res->wall_s,
           res->other_load);
    if (wrap)
        printf("study_overhead_%s: %.3f us/eval (per evaluation: %.3f us in the evaluating stage minus the model's "
               "%.3f us clocked in the same run; target <= %.0f: %s)\n", name, ovh, res->marginal_us,
               res->model_after_us, TARGET_OVERHEAD_US, ovh <= TARGET_OVERHEAD_US ? "met" : "not met");
    else
        printf("study_overhead_%s: %.3f us/eval (per evaluation: %.3f us in the evaluating stage minus the direct "
               "call; target <= %.0f: %s)\n", name, ovh, res->marginal_us, TARGET_OVERHEAD_US,
               ovh <= TARGET_OVERHEAD_US ? "met" : "not met");
    printf("study_overhead_whole_%s: %.3f us/eval (the whole run per evaluation, set-up, estimates and writing "
           "included, minus the direct call)\n", name, whole);
    return 0;
}

/* The weight-curve study with its model replayed (replay_model): the
 * evaluating stage per evaluation after the first is then all overhead
 * (design point, prior quantiles, phc_study_evaluate's cost and outputs over
 * the 580 observations, the ledger record of 104 outputs, progress), with
 * no model time to subtract and no clock inside the loop. */
static void replay_overhead(const phc_problem *pb)
{
    overhead_result res;
    memset(&res, 0, sizeof res);
    char dir[256];
    if (time_study(pb, N_REPLAY, "weight_curve_replayed", 2, &res, dir, sizeof dir))
        return;
    printf("study_overhead_weight_curve_replayed: %.3f us/eval (N = %d, %zu evaluations, the model replayed: the "
           "evaluating stage per evaluation is all overhead; CPU, best of %d; other load %.2f CPUs; target <= %.0f: "
           "%s)\n", res.marginal_us, N_REPLAY, res.evaluations, REPEAT, res.other_load, TARGET_OVERHEAD_US,
           res.marginal_us <= TARGET_OVERHEAD_US ? "met" : "not met");
}

/* ---- the Ishigami config ---------------------------------------------------------------- */

static phc_problem *ishigami(void)
{
    char csv[128], yaml[128];
    snprintf(csv, sizeof csv, "%s/ishigami.csv", work);
    snprintf(yaml, sizeof yaml, "%s/ishigami.yaml", work);
    FILE *f = fopen(csv, "w");
    if (!f)
        return NULL;
    fprintf(f, "x,y\n0,0\n1,0\n2,0\n"); /* three observations: a config needs as many as parameters */
    fclose(f);
    if (!(f = fopen(yaml, "w")))
        return NULL;
    fprintf(f, "name: ishigami\nparameters:\n");
    const char *pn[3] = {"a", "b", "c"};
    for (int i = 0; i < 3; ++i)
        fprintf(f, "  %s: {value: 0.1, lower: %.17g, upper: %.17g}\n", pn[i], -M_PI, M_PI);
    fprintf(f, "datasets:\n  - kind: curve\n    name: ishigami\n    file: ishigami.csv\n    x: x\n    y: y\n"
               "    sigma: 1\n    expression: \"sin(a) + 7 * sin(b)^2 + 0.1 * c^4 * sin(a)\"\n");
    fclose(f);
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_load(yaml, &pb, &err)) {
        printf("study_expression: %s\n", err.message);
        return NULL;
    }
    return pb;
}

/* ---- (b) NumPy ------------------------------------------------------------------------ */

static double peer_value(const char *text, const char *key)
{
    char pat[128];
    snprintf(pat, sizeof pat, "%s: ", key);
    const char *p = strstr(text, pat);
    return p ? strtod(p + strlen(pat), NULL) : NAN;
}

static void versus_numpy(const phc_problem *pb, const overhead_result *ours, const char *dir)
{
    design_points dp;
    if (make_design(pb, N_EXPRESSION, &dp)) {
        printf("numpy_peer: cannot build the design\n");
        return;
    }
    /* the base points: row 0 (A_j) and row 1 (B_j) of every block */
    const size_t k = 3, block = k + 2;
    char base[128];
    snprintf(base, sizeof base, "%s/base.f64", work);
    FILE *f = fopen(base, "wb");
    double u[3];
    for (size_t j = 0; f && j < N_EXPRESSION; ++j)
        for (size_t s = 0; s < 2; ++s) {
            phc_saltelli_design_point(dp.d, j * block + s, u);
            fwrite(u, sizeof *u, k, f);
        }
    if (f)
        fclose(f);
    design_points_free(&dp);
    if (access(PEER_PY, X_OK) != 0) {
        printf("numpy_peer: skipped (%s is missing)\n", PEER_PY);
        return;
    }
    char cmd[512];
    snprintf(cmd, sizeof cmd, "%s %s saltelli %s %d 3 1000 1 --repeat %d", PEER_PY, PEER_SCRIPT, base, N_EXPRESSION,
             REPEAT);
    const cpu_mark m0 = cpu_now();
    FILE *p = popen(cmd, "r");
    static char text[16384];
    size_t got = p ? fread(text, 1, sizeof text - 1, p) : 0;
    text[got] = '\0';
    const int rc = p ? pclose(p) : -1;
    const cpu_mark m1 = cpu_now();
    if (rc != 0) {
        printf("numpy_peer: exited with status %d (is numpy installed for %s?)\n", rc, PEER_PY);
        return;
    }
    const double t_np = peer_value(text, "numpy_saltelli_time");
    const double n_np = peer_value(text, "numpy_saltelli_evaluations");
    /* equal work: the same evaluations and the same point estimates */
    char path[256];
    snprintf(path, sizeof path, "%s/result.json", dir);
    json_error_t je;
    json_t *res = json_load_file(path, 0, &je);
    double worst = 0;
    json_t *outs = json_object_get(res, "outputs");
    size_t compared = 0;
    for (size_t j = 0; j <= json_array_size(outs); ++j) {
        /* the outputs (cost, ishigami.mean, ishigami@1..3), then the series
           summary (series[0].summary) */
        json_t *o = j < json_array_size(outs) ? json_array_get(outs, j)
                                               : json_object_get(json_array_get(json_object_get(res, "series"), 0),
                                                                 "summary");
        const char *name = j < json_array_size(outs) ? json_string_value(json_object_get(o, "name")) : "summary";
        char peer_name[32];
        const char *at = name ? strchr(name, '@') : NULL;
        if (at)
            snprintf(peer_name, sizeof peer_name, "y%s", at);
        else
            snprintf(peer_name, sizeof peer_name, "%s", !name ? "?" : strcmp(name, "cost") == 0 ? "cost"
                                                           : strcmp(name, "summary") == 0    ? "summary"
                                                                                               : "mean");
        json_t *idx = json_object_get(o, "indices");
        compared += idx != NULL;
        const char *fn[3] = {"a", "b", "c"};
        for (int i = 0; i < 3; ++i) {
            json_t *fi = json_object_get(idx, fn[i]);
            const char *what[2] = {"S1", "ST"};
            for (int w = 0; w < 2; ++w) {
                char key[64];
                snprintf(key, sizeof key, "numpy_%s_%s_%d", what[w], peer_name, i + 1);
                const double a = json_real_value(json_object_get(fi, what[w])), b = peer_value(text, key);
                const double dlt = fabs(a - b);
                worst = !(dlt <= worst) ? dlt : worst;
            }
        }
    }
    /* the series outputs ishigami@1..3: series[0].indices.<factor>.S1[t], ST[t] */
    json_t *sidx = json_object_get(json_array_get(json_object_get(res, "series"), 0), "indices");
    for (size_t t = 0; sidx && t < 3; ++t) {
        const char *fn[3] = {"a", "b", "c"}, *what[2] = {"S1", "ST"};
        int found = 0;
        for (int i = 0; i < 3; ++i)
            for (int w = 0; w < 2; ++w) {
                json_t *arr = json_object_get(json_object_get(sidx, fn[i]), what[w]);
                char key[64];
                snprintf(key, sizeof key, "numpy_%s_y@%zu_%d", what[w], t + 1, i + 1);
                if (t >= json_array_size(arr))
                    continue;
                found = 1;
                const double dlt = fabs(json_real_value(json_array_get(arr, t)) - peer_value(text, key));
                worst = !(dlt <= worst) ? dlt : worst;
            }
        compared += found;
    }
    json_decref(res);
    const double ours_s = ours->run_us * 1e-6 * (double)ours->evaluations, w_np = peer_value(text, "numpy_saltelli_wall");
    printf("numpy_saltelli_time: %.4f s (N = %d, %.0f evaluations, model + estimators + 1000 bootstrap resamples for "
           "5 outputs and the series summary, CPU, best of %d; wall %.4f s; other load %.2f CPUs)\n", t_np,
           N_EXPRESSION, n_np, REPEAT, w_np, other_load(m0, m1));
    printf("study_saltelli_time: %.4f s (N = %d, %zu evaluations, CPU of the whole phc_study_run with ledger and "
           "writing, all threads; wall %.4f s, %d OpenMP threads)\n", ours_s, N_EXPRESSION, ours->evaluations,
           ours->wall_s, omp_get_max_threads());
    printf("study_saltelli_estimates_vs_numpy: %.1e 1 (largest |S1, ST difference| over %zu results (5 outputs and "
           "the summary) x 3 factors; equal: %s)\n", worst, compared, worst <= 1e-9 && compared == 6 ? "yes" : "no");
    const double ratio = t_np / ours_s, ratio_wall = w_np / ours->wall_s;
    printf("study_saltelli_vs_numpy: %.2f x (CPU: NumPy %.4f s / ours %.4f s; target >= %.0f: %s)\n", ratio, t_np,
           ours_s, TARGET_PEER, ratio >= TARGET_PEER ? "met" : "not met");
    printf("study_saltelli_vs_numpy_wall: %.2f x (wall: NumPy %.4f s / ours %.4f s, the machine shared; target >= "
           "%.0f: %s)\n", ratio_wall, w_np, ours->wall_s, TARGET_PEER, ratio_wall >= TARGET_PEER ? "met" : "not met");
    const double ours_core = ours->loop_us * 1e-6 * (double)ours->evaluations + ours->estimate_s;
    printf("study_saltelli_vs_numpy_no_writing: %.2f x (ours without result.json, report and plots: %.4f s)\n",
           t_np / ours_core, ours_core);
}

/* ---- (c) emcee ------------------------------------------------------------------------ */

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

static void versus_emcee(void)
{
    char dat[4096], csv[128], yaml[128];
    snprintf(dat, sizeof dat, "%s/nist/Misra1a.dat", PHC_SHARED_DATA);
    snprintf(csv, sizeof csv, "%s/misra1a.csv", work);
    snprintf(yaml, sizeof yaml, "%s/misra1a.yaml", work);
    if (load_misra1a(dat, csv) != 14) {
        printf("mcmc_stretch_vs_emcee: skipped (%s not found)\n", dat);
        return;
    }
    FILE *f = fopen(yaml, "w");
    fprintf(f, "name: misra1a\nparameters:\n  b1: {value: 250}\n  b2: {value: 5.0e-4}\ndatasets:\n  - kind: curve\n"
               "    file: misra1a.csv\n    x: x\n    y: y\n    expression: \"b1*(1-exp(-b2*x))\"\n");
    fclose(f);
    double best = INFINITY, best_wall = NAN, samp = NAN, fit = NAN, diag = NAN, post = NAN, load = NAN, var0 = NAN,
           n0 = NAN;
    double b1 = NAN, b2 = NAN, med1 = NAN;
    size_t evals = 0;
    for (int rep = 0; rep < REPEAT; ++rep) {
        phc_problem *pb = NULL;
        phc_error err;
        phc_error_clear(&err);
        if (phc_config_load(yaml, &pb, &err)) {
            printf("mcmc_stretch: %s\n", err.message);
            return;
        }
        phc_mcmc_options o = phc_mcmc_options_default();
        o.method = PHC_MCMC_STRETCH;
        o.samples = STEPS + 1; /* the start included: STEPS sweeps of moves, as emcee's STEPS steps */
        o.chains = WALKERS;
        o.seed = 3;
        o.force = 1;
        stage_clock c = stage_clock_new();
        o.progress = on_progress;
        o.progress_data = &c;
        char dir[160];
        snprintf(dir, sizeof dir, "%s/mcmc-%d", work, rep);
        phc_mcmc_run_summary sum;
        const cpu_mark m0 = cpu_now();
        const double c0 = cpu();
        const int rc = phc_mcmc_run(pb, &o, NULL, dir, &sum, &err);
        const double c1 = cpu();
        const cpu_mark m1 = cpu_now();
        phc_problem_free(pb);
        if (rc) {
            printf("mcmc_stretch: %s\n", err.message);
            return;
        }
        phc_mcmc_run_summary_clear(&sum);
        const double t = c1 - c0;
        if (t < best) {
            best = t;
            best_wall = m1.wall - m0.wall;
            fit = c.t_sampling_first - c.t_fitting;
            samp = c.t_sampling_last - c.t_sampling_first;
            diag = c.t_writing - c.t_sampling_last;
            post = c1 - c.t_writing;
            load = other_load(m0, m1);
            char path[256];
            snprintf(path, sizeof path, "%s/result.json", dir);
            json_error_t je;
            json_t *res = json_load_file(path, 0, &je);
            json_t *ev = json_object_get(res, "error_variance");
            var0 = json_real_value(json_object_get(ev, "var0"));
            n0 = json_real_value(json_object_get(ev, "n0"));
            json_t *params = json_object_get(res, "parameters");
            b1 = json_real_value(json_object_get(json_object_get(params, "b1"), "fit"));
            b2 = json_real_value(json_object_get(json_object_get(params, "b2"), "fit"));
            med1 = json_real_value(json_object_get(json_object_get(params, "b1"), "median"));
            json_decref(res);
            /* the evaluation count: report.md's "Model evaluations in this run: N" */
            snprintf(path, sizeof path, "%s/report.md", dir);
            FILE *r = fopen(path, "r");
            char line[4096];
            while (r && fgets(line, sizeof line, r)) {
                const char *e = strstr(line, "Model evaluations in this run: ");
                if (e)
                    evals = strtoul(e + strlen("Model evaluations in this run: "), NULL, 10);
            }
            if (r)
                fclose(r);
        }
    }
    printf("mcmc_stretch_time: %.4f s (CPU of phc_mcmc_run, %d walkers x %d steps, best of %d: fit %.4f s, "
           "sampling %.4f s, diagnostics %.4f s, writing %.4f s; wall %.4f s, other load %.2f CPUs)\n",
           best, WALKERS, STEPS, REPEAT, fit, samp, diag, post, best_wall, load);
    printf("mcmc_stretch_evaluations: %zu (posterior evaluations: %d proposals, the starts and the fit's)\n", evals,
           WALKERS * STEPS);
    printf("mcmc_stretch_sampling_us: %.3f us/proposal\n", 1e6 * samp / (double)(WALKERS * (STEPS - 1)));
    printf("mcmc_stretch_b1_median: %.6g\n", med1);
    if (access(PEER_PY, X_OK) != 0 || system(PEER_PY " -c 'import emcee' 2>/dev/null") != 0) {
        printf("emcee_peer: skipped (Debian's python3-emcee is missing)\n");
        return;
    }
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "%s %s emcee %s %.17g %.17g %.17g %.17g %d %d", PEER_PY, PEER_SCRIPT, csv, var0, n0, b1,
             b2, WALKERS, STEPS);
    const cpu_mark m0 = cpu_now();
    FILE *p = popen(cmd, "r");
    static char text[4096];
    size_t got = p ? fread(text, 1, sizeof text - 1, p) : 0;
    text[got] = '\0';
    const int rc = p ? pclose(p) : -1;
    const cpu_mark m1 = cpu_now();
    if (rc != 0) {
        printf("emcee_peer: exited with status %d\n", rc);
        return;
    }
    const char *cpu_at = strstr(text, "CPU ");
    const double t_em = cpu_at ? strtod(cpu_at + 4, NULL) : NAN;
    printf("emcee_time: %.4f s (CPU of run_mcmc alone, %d walkers x %d steps; wall %.4f s, other load %.2f CPUs)\n",
           t_em, WALKERS, STEPS, peer_value(text, "emcee_time"), other_load(m0, m1));
    printf("emcee_evaluations: %.0f (log-posterior calls)\n", peer_value(text, "emcee_log_posterior_calls"));
    printf("emcee_b1_median: %.6g\n", peer_value(text, "emcee_b1_median"));
    const double ratio = t_em / best;
    printf("mcmc_stretch_vs_emcee: %.2f x (emcee %.4f s / ours %.4f s, our whole run with fit, diagnostics and "
           "writing; target >= %.0f: %s)\n", ratio, t_em, best, TARGET_PEER, ratio >= TARGET_PEER ? "met" : "not met");
    printf("mcmc_stretch_sampling_vs_emcee: %.2f x (emcee %.4f s / our sampling alone %.4f s)\n", t_em / samp, t_em,
           samp);
}

int main(void)
{
    snprintf(work, sizeof work, "/tmp/phc-bench-study-XXXXXX");
    if (!mkdtemp(work)) {
        printf("bench_study: cannot create a folder in /tmp\n");
        return 1;
    }
    print_loadavg("start");
    calibrate_clock();
    printf("bench_clock_pair_ns: %.0f ns (two reads of the process CPU clock, taken off the paired overhead)\n",
           1e9 * clock_pair);
    overhead_result ishi, wc;
    char ishi_dir[256] = "", wc_dir[256] = "";
    phc_problem *pb = ishigami();
    if (pb && overhead(pb, N_EXPRESSION, "expression", 0, &ishi, ishi_dir, sizeof ishi_dir) == 0)
        versus_numpy(pb, &ishi, ishi_dir);
    phc_problem_free(pb);
    pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_load(PHC_SOURCE_DIR "/measurements/examples/weight_curve/seedling_sensitivity.yaml", &pb, &err))
        printf("study_weight_curve: %s\n", err.message);
    else {
        overhead(pb, N_WEIGHT, "weight_curve", 1, &wc, wc_dir, sizeof wc_dir);
        replay_overhead(pb);
    }
    phc_problem_free(pb);
    versus_emcee();
    print_loadavg("end");
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", work);
    if (system(cmd) != 0)
        printf("bench_study: could not remove %s\n", work);
    return 0;
}
