/* The MPI module phytocal_mpi.so: the master-worker loop of
 * fit/study_dist.h over MPI_COMM_WORLD (Open MPI).  Only this file
 * includes mpi.h; libphytocal loads it with dlopen under mpirun.
 *
 * Messages (all from or to rank 0):
 *   TAG_WORK   master -> worker  uint64 row indices (1 .. MAX_BATCH)
 *   TAG_RESULT worker -> master  per row: row, failed (0/1), n_out outputs,
 *                                as doubles (a row index is exact below
 *                                2^53; the outputs travel bit for bit)
 *   TAG_STOP   master -> worker  one uint64: the master's status (0: done)
 * The master keeps each worker two batches ahead, batches shrinking towards
 * the end (guided: at most the rows left over 4 x ranks, at least 1), so
 * that the workers' queues are short when the master runs out of rows and
 * waits for them; a worker sends results
 * with MPI_Isend from two alternating buffers, so it never waits for the
 * master to look.  Messages between two ranks are not overtaken (MPI), so a
 * worker evaluates every batch sent before its stop, and the master
 * receives every result in flight before it returns: nobody is left in a
 * send at MPI_Finalize.
 *
 * share() is one MPI_Allgatherv in place: rank r's block of rows
 * (phc_dist_block) goes to every rank as raw doubles. */
#include <mpi.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "fit/study_dist.h"

enum { TAG_WORK = 1, TAG_RESULT = 2, TAG_STOP = 3 };
enum { MAX_BATCH = 64, AHEAD = 2 };

int phc_mpi_module_open(int abi, phc_dist *d, phc_error *err); /* the entry point (study_dist.h) */

static int mpi_agree(phc_dist *d, int rc, phc_error *err)
{
    /* the lowest failing rank, then its status and message from it */
    int mine = rc ? d->rank : INT_MAX, first = INT_MAX;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == INT_MAX)
        return PHC_OK;
    struct {
        int status;
        char message[PHC_ERROR_MESSAGE_SIZE];
    } what;
    if (d->rank == first) {
        what.status = rc;
        snprintf(what.message, sizeof what.message, "%s", err && err->message[0] ? err->message : phc_strerror(rc));
    }
    MPI_Bcast(&what, (int)sizeof what, MPI_BYTE, first, MPI_COMM_WORLD);
    if (d->rank == first)
        return rc;
    if (first == 0)
        return phc_error_set(err, what.status, "%s", what.message);
    return phc_error_set(err, what.status, "rank %d: %s", first, what.message);
}

/* ---- share: an all-gather of blocks of rows ------------------------------------------- */

typedef struct mpi_impl {
    int *counts, *displs; /* per rank, in doubles */
} mpi_impl;

static int mpi_share(phc_dist *d, double *v, size_t n, size_t stride, phc_error *err)
{
    mpi_impl *im = d->impl;
    /* every rank computes the same blocks from the same n, so every rank
       refuses alike (no message needed) */
    for (int r = 0; r < d->size; ++r) {
        size_t lo, hi;
        phc_dist_block(n, d->size, r, &lo, &hi);
        if (stride && (hi - lo > (size_t)INT_MAX / stride || lo > (size_t)INT_MAX / stride))
            return phc_error_set(err, PHC_ERR_INPUT, "%zu rows of %zu values are too many to share over MPI "
                                 "(its counts are ints)", n, stride);
        im->counts[r] = (int)((hi - lo) * stride);
        im->displs[r] = (int)(lo * stride);
    }
    MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, v, im->counts, im->displs, MPI_DOUBLE, MPI_COMM_WORLD);
    return PHC_OK;
}

/* ---- the master ------------------------------------------------------------------------- */

typedef struct master {
    const size_t *rows;
    size_t n_rows, next, batch, ranks;
    int *outstanding; /* per rank: batches sent, results not yet received */
    uint64_t *work;   /* one batch of row indices */
} master;

/* Sends worker w the next batch of rows (none when every row is handed out). */
static void send_batch(master *m, int w)
{
    /* guided: smaller batches as the rows run out */
    size_t size = (m->n_rows - m->next) / (AHEAD * 2 * m->ranks);
    size = size < 1 ? 1 : size > m->batch ? m->batch : size;
    size_t k = 0;
    while (k < size && m->next < m->n_rows)
        m->work[k++] = (uint64_t)m->rows[m->next++];
    if (k == 0)
        return;
    MPI_Send(m->work, (int)k, MPI_UINT64_T, w, TAG_WORK, MPI_COMM_WORLD);
    m->outstanding[w]++;
}

static int run_master(phc_dist *d, size_t n_out, const size_t *rows, size_t n_rows, phc_dist_eval_fn eval,
                      phc_dist_record_fn record, void *ctx, uint64_t *work, double *in, double *own,
                      int *outstanding, phc_error *err)
{
    const size_t stride = 2 + n_out;
    master m = {rows, n_rows, 0, 0, (size_t)d->size, outstanding, work};
    /* PHC_STUDY_MPI_TIMES=1: the master's time receiving results and waiting
       for the workers after its last row, on stderr */
    const int times = getenv("PHC_STUDY_MPI_TIMES") != NULL;
    double t_recv = 0, t_wait = 0, t_loop = MPI_Wtime();
    size_t own_rows = 0;
    /* batches small enough that the last ones end together (about 1/128 of a
       process's share each), large enough that messages cost nothing beside
       a model evaluation */
    m.batch = n_rows / ((size_t)d->size * 128);
    m.batch = m.batch < 1 ? 1 : m.batch > MAX_BATCH ? MAX_BATCH : m.batch;
    int rc = PHC_OK;
    size_t recorded = 0;
    for (int a = 0; a < AHEAD && rc == PHC_OK; ++a)
        for (int w = 1; w < d->size; ++w)
            send_batch(&m, w);
    while (rc == PHC_OK && recorded < n_rows) {
        MPI_Status st;
        int arrived = 0;
        if (m.next < n_rows) {
            MPI_Iprobe(MPI_ANY_SOURCE, TAG_RESULT, MPI_COMM_WORLD, &arrived, &st);
        } else { /* nothing left to evaluate here: wait for the workers */
            const double t0 = MPI_Wtime();
            MPI_Probe(MPI_ANY_SOURCE, TAG_RESULT, MPI_COMM_WORLD, &st);
            t_wait += MPI_Wtime() - t0;
            arrived = 1;
        }
        if (arrived) {
            int count = 0;
            MPI_Get_count(&st, MPI_DOUBLE, &count);
            const double t0 = MPI_Wtime();
            MPI_Recv(in, (int)(MAX_BATCH * stride), MPI_DOUBLE, st.MPI_SOURCE, TAG_RESULT, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
            t_recv += MPI_Wtime() - t0;
            m.outstanding[st.MPI_SOURCE]--;
            if (count <= 0 || (size_t)count % stride != 0) { /* every rank built the same study: cannot happen */
                rc = phc_error_set(err, PHC_ERR_INTERNAL, "rank %d sent %d values, not rows of %zu", st.MPI_SOURCE,
                                   count, stride);
                break;
            }
            for (size_t i = 0; i < (size_t)count / stride && rc == PHC_OK; ++i) {
                const double *r = in + i * stride;
                rc = record(ctx, (size_t)r[0], r[1] != 0, r + 2, err);
                ++recorded;
            }
            if (rc == PHC_OK)
                send_batch(&m, st.MPI_SOURCE);
            continue; /* more may have arrived: look again before evaluating */
        }
        const size_t row = rows[m.next++];
        const int failed = eval(ctx, row, own);
        rc = record(ctx, row, failed, own, err);
        ++recorded;
        ++own_rows;
    }
    if (times)
        fprintf(stderr, "rank 0: %zu of %zu rows evaluated here; %.3f s receiving results, %.3f s waiting for the "
                "workers after the last row was handed out, of %.3f s (batches of up to %zu rows)\n", own_rows,
                n_rows, t_recv, t_wait, MPI_Wtime() - t_loop, m.batch);
    /* stop every worker, then take in what they still had in flight */
    const uint64_t status = (uint64_t)rc;
    for (int w = 1; w < d->size; ++w)
        MPI_Send(&status, 1, MPI_UINT64_T, w, TAG_STOP, MPI_COMM_WORLD);
    for (int w = 1; w < d->size; ++w)
        while (m.outstanding[w] > 0) {
            MPI_Recv(in, (int)(MAX_BATCH * stride), MPI_DOUBLE, w, TAG_RESULT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            m.outstanding[w]--;
        }
    return rc;
}

/* ---- a worker --------------------------------------------------------------------------- */

static int run_worker(size_t n_out, uint64_t *work, double *out[2], phc_dist_eval_fn eval, void *ctx,
                      phc_error *err)
{
    const size_t stride = 2 + n_out;
    MPI_Request sent[2] = {MPI_REQUEST_NULL, MPI_REQUEST_NULL};
    int cur = 0, rc = PHC_OK;
    for (;;) {
        MPI_Status st;
        MPI_Recv(work, MAX_BATCH, MPI_UINT64_T, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
        if (st.MPI_TAG == TAG_STOP) {
            if (work[0] != 0)
                rc = phc_error_set(err, (int)work[0], "the master (rank 0) stopped the study");
            break;
        }
        int count = 0;
        MPI_Get_count(&st, MPI_UINT64_T, &count);
        MPI_Wait(&sent[cur], MPI_STATUS_IGNORE); /* this buffer's previous send */
        for (int i = 0; i < count; ++i) {
            double *r = out[cur] + (size_t)i * stride;
            r[0] = (double)work[i];
            r[1] = eval(ctx, (size_t)work[i], r + 2) ? 1 : 0;
        }
        MPI_Isend(out[cur], (int)((size_t)count * stride), MPI_DOUBLE, 0, TAG_RESULT, MPI_COMM_WORLD, &sent[cur]);
        cur ^= 1;
    }
    MPI_Waitall(2, sent, MPI_STATUSES_IGNORE);
    return rc;
}

static int mpi_run(phc_dist *d, size_t n_out, const size_t *rows, size_t n_rows, phc_dist_eval_fn eval,
                   phc_dist_record_fn record, void *ctx, phc_error *err)
{
    /* every rank's buffers first, agreed on, so that a rank short of memory
       stops them all instead of leaving one waiting */
    const size_t stride = 2 + n_out;
    uint64_t *work = malloc(MAX_BATCH * sizeof *work);
    double *buf[2] = {malloc(MAX_BATCH * stride * sizeof(double)), malloc(MAX_BATCH * stride * sizeof(double))};
    int *outstanding = calloc((size_t)d->size, sizeof *outstanding);
    int rc = !work || !buf[0] || !buf[1] || !outstanding
                 ? phc_error_set(err, PHC_ERR_NOMEM, "rank %d: out of memory for the study's messages", d->rank)
                 : PHC_OK;
    if ((rc = mpi_agree(d, rc, err)) == PHC_OK)
        rc = d->rank == 0 ? run_master(d, n_out, rows, n_rows, eval, record, ctx, work, buf[0], buf[1], outstanding,
                                       err)
                          : run_worker(n_out, work, buf, eval, ctx, err);
    free(work);
    free(buf[0]);
    free(buf[1]);
    free(outstanding);
    return rc;
}

static void mpi_finish(phc_dist *d)
{
    mpi_impl *im = d->impl;
    if (im) {
        free(im->counts);
        free(im->displs);
        free(im);
        d->impl = NULL;
    }
    int done = 0;
    MPI_Finalized(&done);
    if (!done)
        MPI_Finalize();
}

int phc_mpi_module_open(int abi, phc_dist *d, phc_error *err)
{
    if (abi != PHC_DIST_ABI)
        return phc_error_set(err, PHC_ERR_INTERNAL, "the MPI module speaks interface %d, phytocal %d: install "
                             "phytocal_mpi.so of the same build", PHC_DIST_ABI, abi);
    /* A rank waiting for a message polls; on a machine shared with other
       work (or with more ranks than cores) it should give the core away
       while it waits: Open MPI's mpi_yield_when_idle, unless the user set it
       (environment or mpirun --mca). */
    setenv("OMPI_MCA_mpi_yield_when_idle", "1", 0);
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised && MPI_Init(NULL, NULL) != MPI_SUCCESS)
        return phc_error_set(err, PHC_ERR_IO, "MPI_Init failed");
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    if (d->size < 2) {
        MPI_Finalize();
        return phc_error_set(err, PHC_ERR_INPUT, "the MPI launcher started 1 rank: a master-worker study needs at "
                             "least 2 ranks (mpirun -np 2 or more; without mpirun it runs as one process)");
    }
    mpi_impl *im = calloc(1, sizeof *im);
    if (im) {
        im->counts = calloc((size_t)d->size, sizeof *im->counts);
        im->displs = calloc((size_t)d->size, sizeof *im->displs);
    }
    if (!im || !im->counts || !im->displs) {
        if (im) {
            free(im->counts);
            free(im->displs);
        }
        free(im);
        MPI_Finalize();
        return phc_error_set(err, PHC_ERR_NOMEM, "rank %d: out of memory for the MPI module", d->rank);
    }
    d->impl = im;
    d->agree = mpi_agree;
    d->run = mpi_run;
    d->share = mpi_share;
    d->finish = mpi_finish;
    return PHC_OK;
}
