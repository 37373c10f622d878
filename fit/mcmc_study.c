/* `phytocal mcmc`: see mcmc_study.h. */
#include "fit/mcmc_study.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "fit/engine/fit.h"
#include "fit/engine/mcmc_diagnostics.h"
#include "fit/engine/mcmc_dram.h"
#include "fit/engine/mcmc_stretch.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/prior.h"
#include "fit/json_file_internal.h"
#include "fit/mcmc_plots.h"
#include "fit/run_dir.h"
#include "fit/run_ledger.h"
#include "fit/sensitivity_study.h"
#include "fit/study_dist.h"
#include "measurements/atomic_file.h"

/* Verdict thresholds (Vehtari et al. 2021, Bayesian Analysis 16:667: R-hat
 * < 1.01 and a bulk ESS above 400 for 4 chains). */
#define RHAT_MIXED 1.01
#define ESS_MIXED 400.0
#define THIN_MAX 500 /* draws per chain kept in result.json */

phc_mcmc_options phc_mcmc_options_default(void)
{
    phc_mcmc_options o;
    memset(&o, 0, sizeof o);
    o.method = PHC_MCMC_DRAM;
    o.seed = 1;
    return o;
}

void phc_mcmc_run_summary_clear(phc_mcmc_run_summary *s)
{
    if (!s)
        return;
    free(s->text);
    memset(s, 0, sizeof *s);
}

static int append(char **buf, const char *fmt, ...)
{
    va_list ap, ap2;
    va_start(ap, fmt);
    va_copy(ap2, ap);
    const int n = vsnprintf(NULL, 0, fmt, ap2);
    va_end(ap2);
    const size_t old = *buf ? strlen(*buf) : 0;
    char *grown = n < 0 ? NULL : realloc(*buf, old + (size_t)n + 1);
    if (!grown) {
        va_end(ap);
        return -1;
    }
    vsnprintf(grown + old, (size_t)n + 1, fmt, ap);
    va_end(ap);
    *buf = grown;
    return 0;
}

/* ---- the posterior ---------------------------------------------------------------------- */

typedef struct posterior {
    const phc_problem *pb;
    size_t d;
    size_t *col;       /* d parameter indices */
    phc_prior *prior;  /* d, in the user's unit; kind NONE with an open bound: flat improper */
    int *improper;     /* d */
    double *x;         /* n_params slot values */
    phc_study_eval *w;
    size_t evaluations;
} posterior;

static int post_eval(void *data, const double *theta, double *ss, double *log_prior)
{
    posterior *q = data;
    const phc_problem *pb = q->pb;
    double lp = 0;
    for (size_t c = 0; c < q->d; ++c) {
        const double v = phc_prior_log_density(&q->prior[c], theta[c]);
        if (!(v > -INFINITY))
            return 1;
        lp += v;
        const phc_parameter *p = &pb->params[q->col[c]];
        const double slot = p->unit_scale * theta[c] + p->unit_offset;
        if (!(slot >= p->lower && slot <= p->upper))
            return 1;
        q->x[q->col[c]] = slot;
    }
    q->evaluations++;
    double cost;
    if (phc_study_cost(q->w, q->x, &cost) != 0)
        return 1;
    *ss = 2 * cost;
    *log_prior = lp;
    return 0;
}

typedef struct progress_relay {
    const phc_mcmc_options *o;
    const char *stage;
} progress_relay;

static int relay(void *data, size_t done, size_t total)
{
    const progress_relay *r = data;
    char detail[96];
    snprintf(detail, sizeof detail, "%zu of %zu steps", done, total);
    return phc_progress_report(r->o->progress, r->o->progress_data, r->stage, 0, 0, -1, NAN, detail);
}

static json_t *jnum(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

/* ---- the ledger (DRAM resume) ----------------------------------------------------------- */

typedef struct chain_ledger {
    phc_run_ledger *l;
    size_t n_out, computed, stop_after;
    double *row;
    const char *path;
} chain_ledger;

/* Chain c's ledger row (its counts, samples, s2 and log posterior) appended;
 * PHC_ERR_INTERNAL once stop_after new chains are written. */
static int chain_record(chain_ledger *cl, size_t c, const double *row, phc_error *err)
{
    int rc = phc_run_ledger_append(cl->l, c, 0, row, err);
    if (rc)
        return rc;
    cl->computed++;
    if (cl->stop_after && cl->computed >= cl->stop_after)
        return phc_error_set(err, PHC_ERR_INTERNAL, "stopped after %zu new chains (stop_after); %s holds them: "
                             "--resume continues", cl->computed, cl->path);
    return PHC_OK;
}

static int chain_done(void *data, size_t c, const phc_mcmc_chains *out, const size_t counts[4], phc_error *err)
{
    chain_ledger *cl = data;
    const size_t n = out->n_iter, d = out->d;
    double *v = cl->row;
    for (int k = 0; k < 4; ++k)
        *v++ = (double)counts[k];
    memcpy(v, out->theta + c * n * d, n * d * sizeof *v);
    v += n * d;
    memcpy(v, out->s2 + c * n, n * sizeof *v);
    v += n;
    memcpy(v, out->log_post + c * n, n * sizeof *v);
    return chain_record(cl, c, cl->row, err);
}

/* ---- DRAM's chains on MPI ranks (fit/study_dist.h) ------------------------------------ */

/* DRAM is sequential within a chain (each step adapts the proposal from the
 * chain's past), so under MPI the chains, not the steps, go to the ranks:
 * one chain per message, run by phc_dram_run with every other chain marked
 * as present (its own seeded generator makes it the chain a single process
 * runs), sent back as the ledger's row (counts, draws, error variances, log
 * posterior densities) plus the number of model evaluations it took.  The
 * master records each chain as it arrives: into the ledger (resume works as
 * in one process) and into the chains the run directory is written from. */
typedef struct dram_dist {
    const phc_mcmc_target *t;
    const double *x0, *cov0;
    const phc_dram_options *dop;
    size_t C, n, d, n_out;  /* n_out: the ledger row, 4 + n (d + 2); one more value travels */
    posterior *q;
    unsigned char *only;    /* C: every chain present but the one being run */
    phc_mcmc_chains blank;  /* the absent chains' draws (zeros, never read back) */
    size_t *blank_counts;   /* 4 C zeros */
    double *row;            /* the running chain's row */
    chain_ledger *cl;       /* master: the ledger */
    unsigned char *state;   /* master: C, 1 once a chain is held */
    phc_mcmc_chains *have;  /* master: the chains held */
    size_t *counts;         /* master: 4 C */
} dram_dist;

static int dd_chain_done(void *data, size_t c, const phc_mcmc_chains *out, const size_t counts[4], phc_error *err)
{
    (void)err;
    dram_dist *dd = data;
    const size_t n = dd->n, d = dd->d;
    double *v = dd->row;
    for (int k = 0; k < 4; ++k)
        *v++ = (double)counts[k];
    memcpy(v, out->theta + c * n * d, n * d * sizeof *v);
    memcpy(v + n * d, out->s2 + c * n, n * sizeof *v);
    memcpy(v + n * (d + 1), out->log_post + c * n, n * sizeof *v);
    return PHC_OK;
}

static int dd_eval(void *ctx, size_t c, double *out)
{
    dram_dist *dd = ctx;
    memset(dd->only, 1, dd->C);
    dd->only[c] = 0;
    phc_dram_options dop = *dd->dop;
    dop.have = dd->only;
    dop.have_draws = &dd->blank;
    dop.have_counts = dd->blank_counts;
    dop.chain_done = dd_chain_done;
    dop.chain_data = dd;
    dd->row = out;
    const size_t before = dd->q->evaluations;
    phc_mcmc_chains ch;
    memset(&ch, 0, sizeof ch);
    phc_error e;
    phc_error_clear(&e);
    const int rc = phc_dram_run(dd->t, dd->x0, dd->cov0, &dop, &ch, &e);
    phc_mcmc_chains_clear(&ch);
    out[dd->n_out] = (double)(dd->q->evaluations - before);
    dd->q->evaluations = before; /* counted once, when the master records the chain */
    return rc != PHC_OK;
}

static int dd_record(void *ctx, size_t c, int failed, const double *in, phc_error *err)
{
    dram_dist *dd = ctx;
    const size_t n = dd->n, d = dd->d;
    if (failed)
        return phc_error_set(err, PHC_ERR_INVALID, "DRAM: chain %zu failed on its rank (its start outside the "
                             "support, or out of memory)", c + 1);
    dd->q->evaluations += (size_t)in[dd->n_out];
    for (int k = 0; k < 4; ++k)
        dd->counts[4 * c + k] = (size_t)in[k];
    memcpy(dd->have->theta + c * n * d, in + 4, n * d * sizeof *in);
    memcpy(dd->have->s2 + c * n, in + 4 + n * d, n * sizeof *in);
    memcpy(dd->have->log_post + c * n, in + 4 + n * (d + 1), n * sizeof *in);
    dd->state[c] = 1;
    return chain_record(dd->cl, c, in, err);
}

/* Every rank: agrees on rc (the master's ledger), then runs the chains the
 * master lacks (state[c] == 0) on the ranks.  The master then holds every
 * chain in state/have/counts. */
static int dram_on_ranks(phc_dist *dist, int rc, dram_dist *dd, phc_error *err)
{
    const size_t C = dd->C;
    size_t *rows = malloc(C * sizeof *rows), n_rows = 0;
    dd->only = malloc(C);
    dd->blank.theta = calloc(C * dd->n * dd->d, sizeof *dd->blank.theta);
    dd->blank.s2 = calloc(C * dd->n, sizeof *dd->blank.s2);
    dd->blank.log_post = calloc(C * dd->n, sizeof *dd->blank.log_post);
    dd->blank_counts = calloc(4 * C, sizeof *dd->blank_counts);
    if (rc == PHC_OK && (!rows || !dd->only || !dd->blank.theta || !dd->blank.s2 || !dd->blank.log_post ||
                         !dd->blank_counts))
        rc = phc_error_set(err, PHC_ERR_NOMEM, "rank %d: out of memory for the chains", dist->rank);
    if ((rc = dist->agree(dist, rc, err)) == PHC_OK) {
        if (dist->rank == 0) {
            for (size_t c = 0; c < C; ++c)
                if (!dd->state[c])
                    rows[n_rows++] = c;
            rc = dist->run(dist, dd->n_out + 1, rows, n_rows, dd_eval, dd_record, dd, err);
        } else {
            rc = dist->run(dist, dd->n_out + 1, NULL, 0, dd_eval, NULL, dd, err);
        }
    }
    free(rows);
    free(dd->only);
    free(dd->blank.theta);
    free(dd->blank.s2);
    free(dd->blank.log_post);
    free(dd->blank_counts);
    return rc;
}

/* ---- the stretch ensemble on MPI ranks (fit/study_dist.h) -------------------------------- */

/* Every rank runs the same ensemble with the same generator, so draws the
 * same proposals; phc_stretch_share gives each rank its block of each batch
 * (phc_dist_block) and gathers the rows on every rank (study_dist.h: share),
 * so every rank makes the same acceptance draws and holds the same
 * ensemble. */
static double wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct stretch_dist {
    phc_dist *d;
    double in_share; /* seconds in the all-gathers: waiting for the slowest rank, and the messages */
} stretch_dist;

static void sd_block(void *data, size_t n, size_t *lo, size_t *hi)
{
    const stretch_dist *sd = data;
    phc_dist_block(n, sd->d->size, sd->d->rank, lo, hi);
}

static int sd_exchange(void *data, double *v, size_t n, phc_error *err)
{
    stretch_dist *sd = data;
    const double t0 = wall_seconds();
    const int rc = sd->d->share(sd->d, v, n, PHC_STRETCH_ROW, err);
    sd->in_share += wall_seconds() - t0;
    return rc;
}

static int sd_agree(void *data, int status, phc_error *err)
{
    stretch_dist *sd = data;
    return sd->d->agree(sd->d, status, err);
}

/* Collective, after a stretch run that succeeded on every rank: each rank
 * counted the model evaluations of its own blocks since `before` (the start
 * draws', made alike on every rank); q->evaluations becomes before + their
 * sum, one process's count.  PHC_STUDY_MPI_TIMES=1: rank 0 prints each
 * rank's count, sampling time and time in the all-gathers on stderr. */
static int stretch_count(const stretch_dist *sd, posterior *q, size_t before, double seconds, phc_error *err)
{
    phc_dist *d = sd->d;
    const size_t size = (size_t)d->size;
    double *v = calloc(3 * size, sizeof *v);
    int rc = v ? PHC_OK : phc_error_set(err, PHC_ERR_NOMEM, "rank %d: out of memory", d->rank);
    if ((rc = d->agree(d, rc, err)))
        goto out;
    double *mine = v + 3 * (size_t)d->rank;
    mine[0] = (double)(q->evaluations - before); /* exact below 2^53 */
    mine[1] = seconds;
    mine[2] = sd->in_share;
    if ((rc = d->share(d, v, size, 3, err)))
        goto out;
    size_t total = 0;
    for (size_t r = 0; r < size; ++r)
        total += (size_t)v[3 * r];
    q->evaluations = before + total;
    if (d->rank == 0 && getenv("PHC_STUDY_MPI_TIMES")) {
        fprintf(stderr, "mcmc stretch: model evaluations by rank:");
        for (size_t r = 0; r < size; ++r)
            fprintf(stderr, " %zu: %.0f (%.3f s sampling, %.3f s in the all-gathers)%s", r, v[3 * r],
                    v[3 * r + 1], v[3 * r + 2], r + 1 < size ? "," : "");
        fprintf(stderr, "; %zu in all, and %zu on every rank before sampling (drawing the starts)\n", total, before);
    }
out:
    free(v);
    return rc;
}

int phc_mcmc_run(phc_problem *pb, const phc_mcmc_options *opts, const phc_provenance *pv, const char *dir,
                 phc_mcmc_run_summary *summary, phc_error *err)
{
    memset(summary, 0, sizeof *summary);
    phc_mcmc_options o = *opts;
    const char *src = pb->source ? pb->source : "config";
    posterior q;
    memset(&q, 0, sizeof q);
    q.pb = pb;
    phc_fit_result *res = NULL;
    phc_mcmc_chains ch;
    memset(&ch, 0, sizeof ch);
    double *cov0 = NULL, *x0 = NULL, *opt = NULL, *col = NULL, *pooled = NULL, *lchol = NULL;
    phc_mcmc_summary *sum = NULL, s2sum;
    char **labels = NULL;
    gsl_rng *rng = NULL;
    char tmpdir[4096] = "", ledger_path[4200] = "";
    int rc = PHC_OK, have_ledger = 0;
    int agreed = 0; /* under MPI every rank agrees once (study_dist.h), at the sampler or at done */
    const int worker = opts->dist && opts->dist->rank != 0;
    size_t reused_chains = 0;
    /* the free parameters and their priors */
    const size_t np = pb->n_params ? pb->n_params : 1;
    q.col = malloc(np * sizeof *q.col);
    q.prior = calloc(np, sizeof *q.prior);
    q.improper = calloc(np, sizeof *q.improper);
    q.x = malloc(np * sizeof *q.x);
    q.w = phc_study_eval_new(pb);
    if (!q.col || !q.prior || !q.improper || !q.x || !q.w) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < pb->n_params; ++i) {
        const phc_parameter *p = &pb->params[i];
        q.x[i] = p->value;
        if (p->fixed)
            continue;
        const size_t c = q.d++;
        q.col[c] = i;
        double lo, hi;
        phc_parameter_user_bounds(p, &lo, &hi);
        if (p->prior.kind == PHC_PRIOR_NONE && !(isfinite(lo) && isfinite(hi))) {
            q.prior[c].kind = PHC_PRIOR_NONE; /* flat, improper */
            q.prior[c].lower = lo;
            q.prior[c].upper = hi;
            q.improper[c] = 1;
            continue;
        }
        char what[600];
        const size_t line = p->prior_line ? p->prior_line : p->config_line;
        if (pb->source && line)
            snprintf(what, sizeof what, "%s:%zu: parameter '%s'", pb->source, line, p->name);
        else
            snprintf(what, sizeof what, "parameter '%s'", p->name);
        if ((rc = phc_prior_resolve(&p->prior, lo, hi, what, &q.prior[c], err)))
            goto done;
    }
    const size_t d = q.d;
    if (d == 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: every parameter is fixed: there is no posterior to sample", src);
        goto done;
    }
    if (o.samples == 0)
        o.samples = o.method == PHC_MCMC_DRAM ? 5000 : 10000;
    if (o.samples < PHC_MCMC_MIN_SAMPLES) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "--samples %zu is too small: an MCMC run needs at least %d draws per "
                           "chain (the first half is burn-in, split-R-hat halves the rest)", o.samples,
                           PHC_MCMC_MIN_SAMPLES);
        goto done;
    }
    if (o.chains == 0)
        o.chains = o.method == PHC_MCMC_DRAM ? 4 : (2 * d > 32 ? 2 * d : 32);
    if (o.method == PHC_MCMC_STRETCH && (o.chains < 2 * d || o.chains % 2)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "--chains %zu: the stretch-move ensemble needs an even number of at "
                           "least 2 d = %zu walkers for the %zu free parameters (Goodman & Weare 2010)", o.chains,
                           2 * d, d);
        goto done;
    }
    if (o.method == PHC_MCMC_DRAM && o.chains < 2) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "--chains %zu: split-R-hat needs at least 2 DRAM chains", o.chains);
        goto done;
    }
    /* the fit: optimum and covariance */
    phc_progress_report(o.progress, o.progress_data, "fitting", 0, 0, -1, NAN, NULL);
    if ((rc = phc_fit_run(pb, o.progress, o.progress_data, &res, err)))
        goto done;
    opt = malloc(d * sizeof *opt);
    cov0 = calloc(d * d, sizeof *cov0);
    lchol = calloc(d * d, sizeof *lchol);
    if (!opt || !cov0 || !lchol) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    int cov_from_fit = 1;
    for (size_t c = 0; c < d; ++c) {
        const phc_param_result *pr = &res->params[q.col[c]];
        opt[c] = pr->value;
        for (size_t e = 0; e < d; ++e) {
            const phc_param_result *pe = &res->params[q.col[e]];
            const double r = c == e ? 1.0 : res->correlation[c * res->n_free + e];
            cov0[c * d + e] = r * pr->stderr_ * pe->stderr_;
        }
    }
    /* Cholesky of cov0 (also checks it) */
    for (size_t j = 0; j < d && cov_from_fit; ++j) {
        double s = cov0[j * d + j];
        for (size_t k = 0; k < j; ++k)
            s -= lchol[j * d + k] * lchol[j * d + k];
        if (!(s > 0) || !isfinite(s)) {
            cov_from_fit = 0;
            break;
        }
        lchol[j * d + j] = sqrt(s);
        for (size_t i = j + 1; i < d; ++i) {
            double v = cov0[i * d + j];
            for (size_t k = 0; k < j; ++k)
                v -= lchol[i * d + k] * lchol[j * d + k];
            lchol[i * d + j] = v / lchol[j * d + j];
        }
    }
    if (!cov_from_fit) { /* undetermined at the optimum: a diagonal guess, 10% of each value */
        memset(cov0, 0, d * d * sizeof *cov0);
        memset(lchol, 0, d * d * sizeof *lchol);
        for (size_t c = 0; c < d; ++c) {
            const double s = 0.1 * (fabs(opt[c]) > 0 ? fabs(opt[c]) : 1.0);
            cov0[c * d + c] = s * s;
            lchol[c * d + c] = s;
        }
    }
    /* the error scale */
    int known_sigma = 1;
    size_t n_obs = 0;
    for (size_t k = 0; k < pb->n_datasets; ++k) {
        known_sigma &= pb->datasets[k]->sigma != NULL;
        n_obs += pb->datasets[k]->n;
    }
    phc_mcmc_target t = {d, post_eval, &q, !known_sigma, n_obs, 1.0, 0.0};
    if (!known_sigma) {
        t.var0 = isfinite(res->s2) && res->s2 > 0 ? res->s2 : 2 * res->cost / (double)(n_obs ? n_obs : 1);
        t.n0 = 0.1 * (double)n_obs;
        if (!(t.var0 > 0))
            t.var0 = 1e-300; /* an exact fit: s2 has nowhere else to start */
    }
    /* starts: chain 1 at the optimum, the others at draws from N(optimum, cov0) */
    const size_t C = o.chains;
    x0 = malloc(C * d * sizeof *x0);
    rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!x0 || !rng) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    gsl_rng_set(rng, o.seed + 0x9e3779b9UL);
    for (size_t c = 0; c < C; ++c) {
        double *x = x0 + c * d;
        memcpy(x, opt, d * sizeof *x);
        if (c == 0)
            continue;
        for (int attempt = 0; attempt < 100; ++attempt) {
            double ss, lp;
            double *y = malloc(d * sizeof *y);
            if (!y) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto done;
            }
            /* z ~ N(0, I), y = opt + L z */
            double *zz = malloc(d * sizeof *zz);
            if (!zz) {
                free(y);
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto done;
            }
            for (size_t i = 0; i < d; ++i)
                zz[i] = gsl_ran_ugaussian(rng);
            for (size_t i = 0; i < d; ++i) {
                double v = 0;
                for (size_t k = 0; k <= i; ++k)
                    v += lchol[i * d + k] * zz[k];
                y[i] = opt[i] + v;
            }
            free(zz);
            const int ok = post_eval(&q, y, &ss, &lp) == 0;
            if (ok)
                memcpy(x, y, d * sizeof *x);
            free(y);
            if (ok)
                break;
        }
    }
    /* sample */
    progress_relay pr = {&o, o.method == PHC_MCMC_DRAM ? "sampling (DRAM)" : "sampling (stretch)"};
    if (o.method == PHC_MCMC_DRAM) {
        phc_dram_options dop = phc_dram_options_default();
        dop.n_iter = o.samples;
        dop.chains = C;
        dop.seed = o.seed;
        dop.progress = o.progress ? relay : NULL;
        dop.progress_data = &pr;
        /* the ledger: its identity is everything the chains depend on */
        chain_ledger cl;
        memset(&cl, 0, sizeof cl);
        snprintf(ledger_path, sizeof ledger_path, "%s.ledger", dir);
        cl.path = ledger_path;
        cl.stop_after = o.stop_after;
        cl.n_out = 4 + o.samples * (d + 2);
        char *ident[6] = {NULL, NULL, NULL, NULL, NULL, NULL};
        int bad = 0;
        bad |= append(&ident[0], "%s", pv && pv->config ? pv->config->sha256 : "none");
        bad |= append(&ident[1], "%s", "");
        if (pv)
            for (size_t i = 0; i < pv->n_inputs; ++i)
                bad |= append(&ident[1], "%s%s", i ? "," : "", pv->inputs[i].sha256);
        bad |= append(&ident[2], "dram adapt=100 dr=0.2 draws=%zu chains=%zu seed=%lu", o.samples, C, o.seed);
        bad |= append(&ident[3], "%s", "");
        for (size_t c = 0; c < d; ++c)
            bad |= append(&ident[3], "%s%s=%s(%.17g,%.17g)[%.17g,%.17g]", c ? "," : "", pb->params[q.col[c]].name,
                          q.improper[c] ? "flat" : phc_prior_kind_name(q.prior[c].kind), q.prior[c].a, q.prior[c].b,
                          q.prior[c].lower, q.prior[c].upper);
        bad |= append(&ident[4], "%s", "");
        for (size_t i = 0; i < C * d; ++i)
            bad |= append(&ident[4], "%s%.17g", i ? "," : "", x0[i]);
        bad |= append(&ident[5], "known_sigma=%d var0=%.17g n0=%.17g", known_sigma, t.var0, t.n0);
        const char *keys[6] = {"config-sha256", "data-sha256", "sampler", "priors", "starts", "error-variance"};
        double *y = malloc(C * cl.n_out * sizeof *y);
        unsigned char *state = malloc(C);
        size_t *counts = calloc(4 * C, sizeof *counts);
        phc_mcmc_chains have;
        memset(&have, 0, sizeof have);
        have.theta = malloc(C * o.samples * d * sizeof *have.theta);
        have.s2 = malloc(C * o.samples * sizeof *have.s2);
        have.log_post = malloc(C * o.samples * sizeof *have.log_post);
        cl.row = malloc(cl.n_out * sizeof *cl.row);
        size_t found = 0;
        if (bad || !y || !state || !counts || !have.theta || !have.s2 || !have.log_post || !cl.row)
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        if (rc == PHC_OK && !worker && (rc = phc_run_dir_make_parents(ledger_path, err)) == PHC_OK)
            rc = phc_run_ledger_open(ledger_path, keys, (const char *const *)ident, 6, C, cl.n_out, o.resume, o.force,
                                     y, state, &found, &cl.l, err);
        if (rc == PHC_OK && !worker) {
            for (size_t c = 0; c < C; ++c) {
                state[c] = state[c] == PHC_LEDGER_OK;
                if (!state[c])
                    continue;
                const double *v = y + c * cl.n_out;
                for (int k = 0; k < 4; ++k)
                    counts[4 * c + k] = (size_t)v[k];
                memcpy(have.theta + c * o.samples * d, v + 4, o.samples * d * sizeof *v);
                memcpy(have.s2 + c * o.samples, v + 4 + o.samples * d, o.samples * sizeof *v);
                memcpy(have.log_post + c * o.samples, v + 4 + o.samples * (d + 1), o.samples * sizeof *v);
            }
            reused_chains = found;
        }
        if (o.dist) { /* the chains on the ranks; the master then holds them all */
            if (worker && rc == PHC_OK)
                memset(state, 0, C);
            dram_dist dd = {&t, x0, cov0, &dop, C, o.samples, d, cl.n_out, &q, NULL, {0}, NULL, NULL,
                            &cl,   state, &have, counts};
            rc = dram_on_ranks(o.dist, rc, &dd, err);
            agreed = 1;
        }
        if (rc == PHC_OK && !worker) {
            dop.have = state;
            dop.have_draws = &have;
            dop.have_counts = counts;
            dop.chain_done = chain_done;
            dop.chain_data = &cl;
            rc = phc_dram_run(&t, x0, cov0, &dop, &ch, err);
        }
        if (cl.l) {
            phc_error ignored;
            const int crc = phc_run_ledger_close(cl.l, rc ? &ignored : err);
            if (rc == PHC_OK)
                rc = crc;
        }
        for (int i = 0; i < 6; ++i)
            free(ident[i]);
        free(y);
        free(state);
        free(counts);
        free(have.theta);
        free(have.s2);
        free(have.log_post);
        free(cl.row);
        if (rc == PHC_OK)
            have_ledger = 1;
        if (worker) /* its chains went to the master, which writes DIR */
            goto done;
    } else if (o.resume) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "--resume: only --method dram resumes (its chains are independent); "
                           "the stretch ensemble moves every walker together");
    } else {
        phc_stretch_options sop = phc_stretch_options_default();
        sop.n_iter = o.samples;
        sop.walkers = C;
        sop.seed = o.seed;
        sop.progress = o.progress ? relay : NULL;
        sop.progress_data = &pr;
        stretch_dist sd = {o.dist, 0};
        phc_stretch_share share = {sd_block, sd_exchange, sd_agree, &sd};
        const size_t before = q.evaluations; /* the start draws', the same on every rank */
        const double t0 = o.dist ? wall_seconds() : 0;
        if (o.dist) { /* every rank runs the ensemble and evaluates its block of each half (mcmc_study.h) */
            rc = o.dist->agree(o.dist, PHC_OK, err);
            agreed = 1;
            if (rc)
                goto done;
            sop.share = &share;
        }
        rc = phc_stretch_run(&t, x0, &sop, &ch, err);
        if (o.dist && rc == PHC_OK) /* the same status on every rank: the ranks' counts, summed */
            rc = stretch_count(&sd, &q, before, wall_seconds() - t0, err);
        if (worker) /* its evaluations went to every rank; the master writes DIR */
            goto done;
    }
    if (rc)
        goto done;
    /* diagnostics over the kept second half */
    const size_t n = ch.n_iter, burn = n / 2, m = n - burn;
    col = malloc(C * m * sizeof *col);
    pooled = malloc(C * m * d * sizeof *pooled);
    sum = calloc(d, sizeof *sum);
    labels = calloc(d, sizeof *labels);
    if (!col || !pooled || !sum || !labels) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t c = 0; c < C; ++c)
        for (size_t k = 0; k < m; ++k)
            memcpy(pooled + (c * m + k) * d, ch.theta + (c * n + burn + k) * d, d * sizeof *pooled);
    int mixed = 1;
    for (size_t j = 0; j < d; ++j) {
        for (size_t i = 0; i < C * m; ++i)
            col[i] = pooled[i * d + j];
        if ((rc = phc_mcmc_summarise(col, C, m, &sum[j], err)))
            goto done;
        mixed &= sum[j].rhat < RHAT_MIXED && sum[j].ess > ESS_MIXED;
        const phc_parameter *p = &pb->params[q.col[j]];
        char label[512];
        snprintf(label, sizeof label, "%s (%s)", p->name, p->unit ? p->unit : "unitless");
        if (!(labels[j] = strdup(label))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
    memset(&s2sum, 0, sizeof s2sum);
    if (!known_sigma) {
        for (size_t c = 0; c < C; ++c)
            for (size_t k = 0; k < m; ++k)
                col[c * m + k] = ch.s2[c * n + burn + k];
        if ((rc = phc_mcmc_summarise(col, C, m, &s2sum, err)))
            goto done;
    }
    summary->mixed = mixed;
    const double acc = ch.proposed ? (double)ch.accepted / (double)ch.proposed : NAN;
    /* text: the table and verdict (printed by the command, and in report.md) */
    char *table = NULL;
    int bad = 0;
    bad |= append(&table, "| parameter | unit | fit | median | 95%% interval | mean | sd | tau | ESS | R-hat |\n"
                          "|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t j = 0; j < d; ++j) {
        const phc_parameter *p = &pb->params[q.col[j]];
        const phc_mcmc_summary *s = &sum[j];
        bad |= append(&table, "| %s | %s | %.6g | %.6g | [%.6g, %.6g] | %.6g | %.3g | %.1f%s | %.0f | %.4f |\n",
                      p->name, p->unit ? p->unit : "", opt[j], s->median, s->q025, s->q975, s->mean, s->sd, s->tau,
                      s->reliable ? "" : " (unreliable: chain < 50 tau)", s->ess, s->rhat);
    }
    if (!known_sigma)
        bad |= append(&table, "| s2 (error variance) | (weighted residual unit)^2 | %.6g | %.6g | [%.6g, %.6g] | %.6g | "
                              "%.3g | %.1f | %.0f | %.4f |\n", res->s2, s2sum.median, s2sum.q025, s2sum.q975,
                      s2sum.mean, s2sum.sd, s2sum.tau, s2sum.ess, s2sum.rhat);
    char *verdict = NULL;
    if (mixed) {
        bad |= append(&verdict, "mixed: every parameter has split-R-hat < %.2f and ESS > %.0f", RHAT_MIXED, ESS_MIXED);
    } else {
        bad |= append(&verdict, "NOT mixed:");
        for (size_t j = 0; j < d; ++j)
            if (!(sum[j].rhat < RHAT_MIXED && sum[j].ess > ESS_MIXED))
                bad |= append(&verdict, " %s (R-hat %.4f, ESS %.0f)", pb->params[q.col[j]].name, sum[j].rhat,
                              sum[j].ess);
        bad |= append(&verdict, "; need split-R-hat < %.2f and ESS > %.0f: run longer (--samples) or another "
                                "--method; do not use these intervals yet", RHAT_MIXED, ESS_MIXED);
    }
    char sampler[512];
    if (o.method == PHC_MCMC_DRAM)
        snprintf(sampler, sizeof sampler, "DRAM (Haario et al. 2006), %zu chains x %zu draws, adapting every 100 "
                 "steps, one delayed-rejection stage at 0.2 x the step", C, n);
    else
        snprintf(sampler, sizeof sampler, "stretch-move ensemble (Goodman & Weare 2010, a = 2), %zu walkers x %zu "
                 "sweeps", C, n);
    if (o.method == PHC_MCMC_DRAM && ch.proposed)
        bad |= append(&summary->text, "%s, seed %lu; burn-in: the first %zu draws of each chain; acceptance %.3f "
                      "(first stage %.3f, delayed rejection %.3f)\n%s%s\n", sampler, o.seed, burn, acc,
                      (double)(ch.accepted - ch.accepted_dr) / (double)ch.proposed,
                      (double)ch.accepted_dr / (double)ch.proposed, table, verdict);
    else
        bad |= append(&summary->text, "%s, seed %lu; burn-in: the first %zu draws of each chain; acceptance %.3f\n%s%s\n",
                      sampler, o.seed, burn, acc, table, verdict);
    if (bad) {
        free(table);
        free(verdict);
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* the run directory */
    phc_progress_report(o.progress, o.progress_data, "writing", 0, 0, -1, NAN, dir);
    if ((rc = phc_run_dir_begin(dir, o.force, pb, tmpdir, sizeof tmpdir, err))) {
        free(table);
        free(verdict);
        goto done;
    }
    char path[8400];
    /* result.json */
    {
        json_t *root = json_object(), *params = json_object();
        json_object_set_new(root, "mcmc",
                            json_pack("{s:s, s:I, s:I, s:I, s:I, s:f, s:I, s:b, s:I}", "method",
                                      o.method == PHC_MCMC_DRAM ? "dram" : "stretch", "chains", (json_int_t)C,
                                      "draws_per_chain", (json_int_t)n, "burn_in", (json_int_t)burn, "seed",
                                      (json_int_t)o.seed, "acceptance", isfinite(acc) ? acc : 0.0,
                                      "delayed_rejection_accepted", (json_int_t)ch.accepted_dr,
                                      "proposal_from_fit_covariance", cov_from_fit,
                                      "failed_proposals", (json_int_t)ch.failed));
        json_object_set_new(root, "error_variance",
                            known_sigma ? json_pack("{s:s}", "treatment", "known sigmas from the data sets")
                                        : json_pack("{s:s, s:o, s:o, s:o, s:o, s:o}", "treatment",
                                                    "sampled: inverse-gamma full conditional", "var0", jnum(t.var0),
                                                    "n0", jnum(t.n0), "median", jnum(s2sum.median), "ci95",
                                                    json_pack("[o, o]", jnum(s2sum.q025), jnum(s2sum.q975)), "rhat",
                                                    jnum(s2sum.rhat)));
        json_t *thin = json_object();
        const size_t step = m > THIN_MAX ? (m + THIN_MAX - 1) / THIN_MAX : 1;
        for (size_t j = 0; j < d; ++j) {
            const phc_parameter *p = &pb->params[q.col[j]];
            const phc_mcmc_summary *s = &sum[j];
            const phc_prior *pr_ = &q.prior[j];
            json_object_set_new(
                params, p->name,
                json_pack("{s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:b, s:{s:s, s:o, s:o, s:o, s:o, s:b}}",
                          "unit", p->unit ? json_string(p->unit) : json_null(), "fit", jnum(opt[j]), "mean",
                          jnum(s->mean), "sd", jnum(s->sd), "median", jnum(s->median), "ci95",
                          json_pack("[o, o]", jnum(s->q025), jnum(s->q975)), "tau", jnum(s->tau), "ess", jnum(s->ess),
                          "rhat", jnum(s->rhat), "mcse_mean", jnum(s->mcse_mean), "tau_window",
                          json_integer((json_int_t)s->window), "tau_reliable", s->reliable, "prior", "dist",
                          q.improper[j] ? "flat-improper" : phc_prior_kind_name(pr_->kind), "a", jnum(pr_->a), "b",
                          jnum(pr_->b), "lower", jnum(pr_->lower), "upper", jnum(pr_->upper), "improper",
                          q.improper[j]));
            json_t *chains_j = json_array();
            for (size_t c = 0; c < C; ++c) {
                json_t *a = json_array();
                for (size_t k = 0; k < m; k += step)
                    json_array_append_new(a, jnum(pooled[(c * m + k) * d + j]));
                json_array_append_new(chains_j, a);
            }
            json_object_set_new(thin, p->name, chains_j);
        }
        json_object_set_new(root, "parameters", params);
        json_object_set_new(root, "chains_thinned",
                            json_pack("{s:I, s:o}", "every", (json_int_t)step, "draws", thin));
        json_object_set_new(root, "verdict", json_pack("{s:b, s:s}", "mixed", mixed, "text", verdict));
        snprintf(path, sizeof path, "%s/result.json", tmpdir);
        rc = phc_json_file_write(root, path, err);
        json_decref(root);
    }
    /* report.md */
    if (rc == PHC_OK) {
        char *md = NULL;
        bad |= append(&md, "# MCMC: %s\n\nSampler: %s, seed %lu. Burn-in: the first half (%zu draws) of each chain, "
                           "left out of every number below. Acceptance rate %.3f", pb->name ? pb->name : "", sampler,
                      o.seed, burn, acc);
        if (o.method == PHC_MCMC_DRAM)
            bad |= append(&md, " (%zu of the accepted moves at the delayed-rejection stage)", ch.accepted_dr);
        bad |= append(&md, ". Model evaluations in this run: %zu; chains taken from the ledger (--resume): %zu.\n\n"
                           "## Verdict\n\n%s\n\n", q.evaluations, reused_chains, verdict);
        bad |= append(&md, "## Posterior\n\nLikelihood: Gaussian in the weighted residuals. Error variance: %s.\n\n",
                      known_sigma ? "the data sets' sigmas are the known standard deviations"
                                  : "sampled from its inverse-gamma full conditional (prior worth n0 = 0.1 n "
                                    "observations at the fit's s2, as FME modMCMC's wvar0 = 0.1)");
        if (known_sigma && !res->absolute_sigma && isfinite(res->s2))
            bad |= append(&md, "The sigmas are taken as true standard deviations (as `absolute_sigma`), while "
                               "`fit` scales its covariance by the variance factor WRSS/dof = %.4g: its Wald "
                               "intervals are about %.3g times these widths.\n\n", res->s2, sqrt(res->s2));
        if (res->summary.outcome != PHC_NLS_CONVERGED)
            bad |= append(&md, "The fit that gave the start did not converge (%s): the chains start at its last "
                               "point.\n\n", phc_fit_status_name(res->summary.outcome));
        bad |= append(&md, "Priors (user units):\n\n");
        for (size_t j = 0; j < d; ++j) {
            const phc_prior *pr_ = &q.prior[j];
            if (q.improper[j])
                bad |= append(&md, "- %s: flat and IMPROPER on [%g, %g] (no `prior:` and an open bound): the "
                                   "posterior is proper only if the likelihood bounds it\n",
                              pb->params[q.col[j]].name, pr_->lower, pr_->upper);
            else
                bad |= append(&md, "- %s: %s(%g, %g) on [%g, %g]\n", pb->params[q.col[j]].name,
                              phc_prior_kind_name(pr_->kind), pr_->a, pr_->b, pr_->lower, pr_->upper);
        }
        bad |= append(&md, "\nStarts: chain 1 at the fit's optimum, the others at draws from N(optimum, %s).\n\n",
                      cov_from_fit ? "the fit's covariance" : "10% of each value (the fit's covariance is not "
                                                             "positive definite)");
        bad |= append(&md, "%s\ntau: integrated autocorrelation time (Sokal's window, c = 5); ESS = draws kept / tau; "
                           "R-hat: split-R-hat over the chains (BDA3).\n\n![trace](mcmc_trace.png)\n\n"
                           "![pairs](mcmc_pairs.png)\n", table);
        char *prov = NULL;
        if (pv && phc_provenance_markdown(pv, &prov, err) == PHC_OK && prov) {
            bad |= append(&md, "\n%s", prov);
            free(prov);
        }
        snprintf(path, sizeof path, "%s/report.md", tmpdir);
        if (bad) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        } else {
            phc_atomic_file *af = NULL;
            rc = phc_atomic_file_open(path, &af, err);
            if (rc == PHC_OK) {
                fputs(md, phc_atomic_file_stream(af));
                rc = phc_atomic_file_commit(af, err);
            }
        }
        free(md);
    }
    free(table);
    free(verdict);
    if (rc == PHC_OK) {
        char title[512];
        snprintf(title, sizeof title, "MCMC trace: %s (burn-in shaded)", pb->name ? pb->name : "");
        snprintf(path, sizeof path, "%s/mcmc_trace.png", tmpdir);
        rc = phc_plot_mcmc_trace(path, title, d, (const char *const *)labels, ch.theta, C, n, burn, err);
    }
    if (rc == PHC_OK) {
        char title[512];
        snprintf(title, sizeof title, "Posterior pairs: %s (%zu kept draws)", pb->name ? pb->name : "", C * m);
        snprintf(path, sizeof path, "%s/mcmc_pairs.png", tmpdir);
        rc = phc_plot_mcmc_pairs(path, title, d, (const char *const *)labels, pooled, C * m, err);
    }
    if (rc == PHC_OK)
        rc = phc_run_dir_commit(tmpdir, dir, pv, err);
    else
        phc_run_dir_discard(tmpdir);
    if (rc == PHC_OK && have_ledger)
        unlink(ledger_path); /* the run directory holds the result */
done:
    if (o.dist && !agreed) /* failed before sampling: the other ranks must not wait for this one */
        o.dist->agree(o.dist, rc ? rc : phc_error_set(err, PHC_ERR_INTERNAL, "mcmc ended before sampling"), err);
    if (rc)
        phc_mcmc_run_summary_clear(summary);
    phc_fit_result_free(res);
    phc_mcmc_chains_clear(&ch);
    phc_study_eval_free(q.w);
    free(q.col);
    free(q.prior);
    free(q.improper);
    free(q.x);
    free(cov0);
    free(x0);
    free(opt);
    free(col);
    free(pooled);
    free(lchol);
    free(sum);
    if (labels)
        for (size_t j = 0; j < q.d; ++j)
            free(labels[j]);
    free(labels);
    gsl_rng_free(rng);
    return rc;
}
