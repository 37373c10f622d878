/* The stretch ensemble with its evaluations shared among processes
 * (mcmc_stretch.h: phc_stretch_share), without MPI: a team of OpenMP
 * threads stands for the ranks, each running phc_stretch_run with the same
 * seed and its own copy of the target, and the share's exchange is a copy
 * through a team buffer between two barriers (as MPI_Allgatherv gives every
 * rank every block).  Checks:
 *  - phc_dist_block (fit/study_dist.h) cuts n rows into contiguous blocks in
 *    rank order that cover [0, n) once, their sizes differing by at most 1;
 *  - with 2 and 3 "ranks" every rank's ensemble equals, bit for bit, the
 *    one-process run's (draws, error variances, log densities, counts), on
 *    the linear-Gaussian posterior with sigma known and sampled, with a
 *    support edge at b > 0.66 so that some proposals have density 0 (those
 *    must not change the random stream);
 *  - every rank evaluated (its own count > 0) and the ranks' counts sum to
 *    the one-process count;
 *  - a rank whose progress callback cancels stops every rank with the same
 *    status, the others' message naming it, and no rank waits forever. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/engine/mcmc_dram.h" /* phc_mcmc_chains_clear */
#include "fit/engine/mcmc_stretch.h"
#include "fit/study_dist.h"

#define NOBS 20
#define MAX_RANKS 4
#define B_MIN 0.66 /* support edge of b (the exact posterior: mean 0.698, sd 0.039) */

typedef struct lin {
    double x[NOBS], y[NOBS], sigma;
    size_t evaluations; /* model evaluations (inside the support) */
} lin;

static int lin_eval(void *data, const double *th, double *ss, double *lprior)
{
    lin *p = data;
    if (!(th[1] > B_MIN))
        return 1; /* outside the prior's support: density 0, no model run */
    p->evaluations++;
    double s = 0;
    for (int i = 0; i < NOBS; ++i) {
        const double r = (p->y[i] - th[0] - th[1] * p->x[i]) / p->sigma;
        s += r * r;
    }
    *ss = s;
    *lprior = 0;
    return 0;
}

/* ---- a team of threads as the ranks -------------------------------------------------- */

typedef struct team {
    int size;
    double *buf;                /* the exchanged rows */
    int status[MAX_RANKS];      /* agree: each rank's */
    phc_error errs[MAX_RANKS];  /* and its message */
    size_t cancel_rank;         /* this rank's progress cancels ... */
    size_t cancel_at;           /* ... at its report with done >= this (0: never) */
} team;

typedef struct member {
    team *tm;
    int rank;
} member;

static void fk_block(void *data, size_t n, size_t *lo, size_t *hi)
{
    const member *m = data;
    phc_dist_block(n, m->tm->size, m->rank, lo, hi);
}

static int fk_exchange(void *data, double *v, size_t n, phc_error *err)
{
    (void)err;
    const member *m = data;
    size_t lo, hi;
    phc_dist_block(n, m->tm->size, m->rank, &lo, &hi);
    memcpy(m->tm->buf + lo * PHC_STRETCH_ROW, v + lo * PHC_STRETCH_ROW, (hi - lo) * PHC_STRETCH_ROW * sizeof *v);
#pragma omp barrier
    memcpy(v, m->tm->buf, n * PHC_STRETCH_ROW * sizeof *v);
#pragma omp barrier
    return PHC_OK;
}

static int fk_agree(void *data, int status, phc_error *err)
{
    const member *m = data;
    team *tm = m->tm;
    tm->status[m->rank] = status;
    if (status)
        tm->errs[m->rank] = *err;
#pragma omp barrier
    int first = -1;
    for (int r = 0; r < tm->size && first < 0; ++r)
        if (tm->status[r])
            first = r;
    int rc = PHC_OK;
    if (first >= 0) {
        rc = tm->status[first];
        if (first != m->rank)
            phc_error_set(err, rc, "rank %d: %s", first, tm->errs[first].message);
    }
#pragma omp barrier
    return rc;
}

typedef struct cancel_data {
    team *tm;
    int rank;
} cancel_data;

static int fk_progress(void *data, size_t done, size_t total)
{
    (void)total;
    const cancel_data *c = data;
    return c->tm->cancel_at && (size_t)c->rank == c->tm->cancel_rank && done >= c->tm->cancel_at;
}

static int same_doubles(const double *a, const double *b, size_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

/* Runs the ensemble on `size` threads; checks every rank against ref (or,
 * with a cancelling rank, that every rank stops alike). */
static void run_team(const char *what, const lin *data, const phc_mcmc_target *t0, const double *x0,
                     const phc_stretch_options *o, int size, const phc_mcmc_chains *ref, size_t ref_evals,
                     size_t cancel_rank, size_t cancel_at)
{
    team tm;
    memset(&tm, 0, sizeof tm);
    tm.size = size;
    tm.buf = malloc(o->walkers * PHC_STRETCH_ROW * sizeof *tm.buf);
    tm.cancel_rank = cancel_rank;
    tm.cancel_at = cancel_at;
    CHECK(tm.buf != NULL);
    lin d[MAX_RANKS];
    phc_mcmc_chains ch[MAX_RANKS];
    int rc[MAX_RANKS];
    phc_error err[MAX_RANKS];
    int threads = 0;
    omp_set_dynamic(0);
#pragma omp parallel num_threads(size)
    {
        const int r = omp_get_thread_num();
#pragma omp single
        threads = omp_get_num_threads();
        if (threads == size) { /* (the implicit barrier of single) */
            d[r] = *data;
            d[r].evaluations = 0;
            phc_mcmc_target t = *t0;
            t.data = &d[r];
            member m = {&tm, r};
            phc_stretch_share sh = {fk_block, fk_exchange, fk_agree, &m};
            cancel_data cd = {&tm, r};
            phc_stretch_options so = *o;
            so.share = &sh;
            so.progress = cancel_at ? fk_progress : NULL;
            so.progress_data = &cd;
            phc_error_clear(&err[r]);
            rc[r] = phc_stretch_run(&t, x0, &so, &ch[r], &err[r]);
        }
    }
    CHECK(threads == size);
    if (threads != size) {
        free(tm.buf);
        return;
    }
    size_t evals = 0;
    int identical = 1;
    for (int r = 0; r < size; ++r) {
        if (cancel_at) {
            CHECK(rc[r] == PHC_ERR_INTERNAL);
            CHECK_STR_CONTAINS(err[r].message, "cancelled");
            if ((size_t)r != cancel_rank) {
                char who[32];
                snprintf(who, sizeof who, "rank %zu: ", cancel_rank);
                CHECK_STR_CONTAINS(err[r].message, who);
            }
            CHECK(ch[r].theta == NULL);
            continue;
        }
        CHECK(rc[r] == PHC_OK);
        if (rc[r] != PHC_OK)
            continue;
        const size_t n = ref->chains * ref->n_iter;
        identical &= same_doubles(ch[r].theta, ref->theta, n * ref->d) && same_doubles(ch[r].s2, ref->s2, n) &&
                     same_doubles(ch[r].log_post, ref->log_post, n) && ch[r].accepted == ref->accepted &&
                     ch[r].proposed == ref->proposed && ch[r].failed == ref->failed;
        CHECK(d[r].evaluations > 0);
        evals += d[r].evaluations;
        phc_mcmc_chains_clear(&ch[r]);
    }
    if (cancel_at) {
        printf("%s, %d ranks, rank %zu cancels: every rank stopped (rank 0: \"%s\", rank %zu: \"%s\")\n", what,
               size, cancel_rank, err[0].message, cancel_rank, err[cancel_rank].message);
    } else {
        printf("%s, %d ranks: every rank's ensemble equals one process's bit for bit: %s; evaluations by rank:",
               what, size, identical ? "yes" : "NO");
        for (int r = 0; r < size; ++r)
            printf(" %zu", d[r].evaluations);
        printf(", sum %zu, one process %zu\n", evals, ref_evals);
        CHECK(identical);
        CHECK(evals == ref_evals);
    }
    free(tm.buf);
}

int main(void)
{
    /* ---- phc_dist_block */
    int blocks_ok = 1;
    for (size_t n = 0; n <= 40; ++n)
        for (int size = 1; size <= 7; ++size) {
            size_t end = 0, smallest = (size_t)-1, largest = 0;
            for (int r = 0; r < size; ++r) {
                size_t lo, hi;
                phc_dist_block(n, size, r, &lo, &hi);
                blocks_ok &= lo == end && hi >= lo;
                end = hi;
                smallest = hi - lo < smallest ? hi - lo : smallest;
                largest = hi - lo > largest ? hi - lo : largest;
            }
            blocks_ok &= end == n && largest - smallest <= 1;
        }
    printf("phc_dist_block: contiguous, in rank order, covering [0, n) once, sizes within 1 (n 0..40, 1..7 "
           "ranks): %s\n", blocks_ok ? "yes" : "NO");
    CHECK(blocks_ok);

    /* ---- the linear-Gaussian problem of test_mcmc.c, b > B_MIN */
    lin p;
    memset(&p, 0, sizeof p);
    p.sigma = 0.5;
    for (int i = 0; i < NOBS; ++i) {
        p.x[i] = (double)i / 2.0;
        p.y[i] = 1.5 + 0.7 * p.x[i] + p.sigma * sin(3.1 * i + 0.4); /* deterministic "noise" */
    }
    const size_t W = 32;
    double *x0 = malloc(W * 2 * sizeof *x0);
    CHECK(x0 != NULL);
    for (size_t k = 0; k < W; ++k) {
        x0[2 * k] = 1.5 + 0.01 * (double)k;
        x0[2 * k + 1] = 0.70 + 0.001 * (double)(k % 7);
    }
    phc_stretch_options o = phc_stretch_options_default();
    o.n_iter = 400;
    o.walkers = W;
    o.seed = 9;
    for (int sampled = 0; sampled < 2; ++sampled) {
        phc_mcmc_target t = {2, lin_eval, &p, sampled, NOBS, 0.25, sampled ? 2.0 : 0.0};
        const char *what = sampled ? "stretch, sigma sampled" : "stretch, sigma known";
        phc_mcmc_chains ref;
        phc_error err;
        p.evaluations = 0;
        CHECK(phc_stretch_run(&t, x0, &o, &ref, &err) == PHC_OK);
        printf("%s, one process: %zu proposals, %zu outside the support (b <= %.2f), acceptance %.3f, %zu model "
               "evaluations\n", what, ref.proposed, ref.failed, B_MIN, (double)ref.accepted / (double)ref.proposed,
               p.evaluations);
        CHECK(ref.failed > 0); /* densities of 0 occur, so the test can see a stream that depends on them */
        for (int size = 2; size <= 3; ++size)
            run_team(what, &p, &t, x0, &o, size, &ref, p.evaluations, 0, 0);
        phc_mcmc_chains_clear(&ref);
    }
    /* ---- a cancel on one rank stops them all */
    {
        phc_mcmc_target t = {2, lin_eval, &p, 0, NOBS, 0.25, 0.0};
        run_team("stretch", &p, &t, x0, &o, 3, NULL, 0, 2, 51 * W);
    }
    free(x0);
    return check_finish("mcmc_stretch_share");
}
