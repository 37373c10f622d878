/* Distributing a study's model evaluations over processes (issue 14, "Runs
 * on many machines"): the interface between the studies and the MPI
 * module, with no MPI type in it.
 *
 * The MPI code lives in its own module, phytocal_mpi.so (fit/mpi/), built
 * beside libphytocal and linked against Open MPI; libphytocal and the
 * phytocal command do not link libmpi, so a run without mpirun (and
 * `phytocal version`) never loads it.  phc_dist_open loads the module with
 * dlopen only when the process was started by an MPI launcher (mpirun or
 * Slurm's srun --mpi=pmix: OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_RANK in
 * the environment), from the folder libphytocal was loaded from.
 *
 * The loop is a dynamic master-worker loop over design rows: rank 0 (the
 * master) hands small batches of rows to the workers (two batches ahead,
 * so a worker never waits for the master), evaluates rows itself between
 * checks for results (non-blocking probes), and is the only process that
 * records results (the run ledger).  Every row's outputs travel as IEEE
 * doubles, so the results are bit for bit those of one process.
 *
 * Protocol, per study, on every rank: exactly one call of agree() (each
 * rank's set-up status; any failure stops every rank), then, when it
 * agreed, exactly one call of run().  A result the master cannot record
 * (an I/O error, a cancelled or stopped study) stops the workers: the
 * master sends each a stop with its status and receives what they still
 * had in flight, so no process hangs.
 *
 * A sampler that runs on every rank alike (mcmc --method stretch) instead
 * makes the same sequence of agree() and share() calls on every rank: the
 * calls depend only on what every rank computes alike (the sampler's
 * settings, the agreed statuses), never on one rank's evaluations. */
#ifndef PHC_STUDY_DIST_H
#define PHC_STUDY_DIST_H

#include <stddef.h>

#include "model/status.h"

/* Evaluates design row `row` into out (n_out values); returns 0 when it
 * succeeded, 1 when it failed (after its own retry; out then holds NAN).
 * Called on every rank. */
typedef int (*phc_dist_eval_fn)(void *ctx, size_t row, double *out);
/* Records row's result (master only); non-zero (with err set) stops the
 * study on every rank. */
typedef int (*phc_dist_record_fn)(void *ctx, size_t row, int failed, const double *out, phc_error *err);

/* The version of this interface; the module refuses another.  2: share. */
#define PHC_DIST_ABI 2

/* Rank r's block of n rows in share(): [r n / size, (r + 1) n / size),
 * contiguous, the sizes differing by at most 1, in rank order. */
static inline void phc_dist_block(size_t n, int size, int rank, size_t *lo, size_t *hi)
{
    *lo = n * (size_t)rank / (size_t)size;
    *hi = n * ((size_t)rank + 1) / (size_t)size;
}

typedef struct phc_dist phc_dist;
struct phc_dist {
    int rank; /* 0: the master */
    int size; /* number of processes (>= 2) */
    /* Collective.  rc: this rank's set-up status (err set when non-zero).
     * Returns PHC_OK when every rank is ready; otherwise the status of the
     * lowest failing rank, with err holding its message (prefixed
     * "rank N: " on the other ranks). */
    int (*agree)(phc_dist *d, int rc, phc_error *err);
    /* Collective.  Master: evaluates and records the n_rows rows listed in
     * rows (any order; each exactly once); workers pass rows = NULL,
     * n_rows = 0, record = NULL and evaluate what they are sent.  Returns
     * PHC_OK when every row is recorded; otherwise the master's status
     * (on the workers with the message "the master (rank 0) stopped the
     * study"). */
    int (*run)(phc_dist *d, size_t n_out, const size_t *rows, size_t n_rows, phc_dist_eval_fn eval,
               phc_dist_record_fn record, void *ctx, phc_error *err);
    /* Collective, every rank with the same n and stride: v holds n rows of
     * stride doubles, of which this rank filled its block (phc_dist_block);
     * on return every rank holds all n rows, bit for bit (an all-gather).
     * For samplers whose every rank draws the same proposals and evaluates
     * its share of them (the stretch ensemble: mcmc_study.c).  Returns
     * PHC_OK, or on every rank alike PHC_ERR_INPUT when a block holds more
     * than INT_MAX doubles (MPI's counts are ints); MPI's own errors abort
     * the job (Open MPI's default handler). */
    int (*share)(phc_dist *d, double *v, size_t n, size_t stride, phc_error *err);
    /* Ends MPI (MPI_Finalize).  Called by phc_dist_close. */
    void (*finish)(phc_dist *d);
    void *impl;   /* the module's */
    void *handle; /* dlopen's */
};

/* The module's one entry point (the symbol phytocal looks up), filling d's
 * function pointers, rank and size after MPI_Init. */
#define PHC_DIST_MODULE_ENTRY "phc_mpi_module_open"
typedef int (*phc_dist_module_open_fn)(int abi, phc_dist *d, phc_error *err);

/* 1 when an MPI launcher started this process (the environment says so). */
int phc_dist_launched(void);
/* This process's rank as the launcher's environment gives it
 * (OMPI_COMM_WORLD_RANK, PMIX_RANK or PMI_RANK), known before MPI is
 * loaded: so that only rank 0 reports a module that cannot be loaded; 0
 * when not launched or not said. */
int phc_dist_launched_rank(void);

/* Under an MPI launcher: loads phytocal_mpi.so, initialises MPI and sets
 * *out (free with phc_dist_close); otherwise *out = NULL (one process).
 * Errors: PHC_ERR_INPUT when the launcher started one process ("a
 * master-worker study needs at least 2 ranks"); PHC_ERR_IO when the module
 * cannot be loaded (its path and dlerror()); the module's own errors. */
int phc_dist_open(phc_dist **out, phc_error *err);
/* Finishes MPI (the module stays loaded until the process exits: Open
 * MPI's exit handlers live in it); accepts NULL. */
void phc_dist_close(phc_dist *d);

#endif /* PHC_STUDY_DIST_H */
