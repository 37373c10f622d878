/* `phytocal sensitivity`: a global sensitivity study of a problem's model
 * over its parameters' priors, written as a run directory.
 *
 * Factors: the free (not fixed) parameters, each sampled from its prior
 * (`prior:` in the config, else uniform on its bounds; fit/engine/prior.h)
 * in the user's unit and converted into the slot's unit for the model; the
 * parameters of a `groups:` entry form one factor.  Fixed parameters keep
 * their values.
 *
 * Outputs of every evaluation (phc_study_evaluate): the cost (1/2 the sum of
 * squared weighted residuals over all data sets) and, per data set, its own
 * cost (when there are several data sets) and its mean prediction over its
 * observations.
 *
 * Methods: Sobol indices from a Saltelli design (fit/engine/sobol_indices.h)
 * or Morris elementary effects (fit/engine/morris.h).  The design is
 * evaluated row by row through phc_study_evaluate (one function a
 * master-worker loop can call on other processes); each result goes to
 * the run ledger (fit/run_ledger.h) at DIR.ledger beside the run directory
 * while the study runs, and into the run directory as ledger.tsv when it is
 * done.  A failed evaluation (the model returns an error or a non-finite
 * value) is retried once, then recorded as failed; the estimators leave out
 * the base samples (trajectories) it belongs to and the report counts them.
 *
 * The run directory (run_dir.h rules: written whole or not at all, an
 * earlier one replaced only with force): result.json (indices with
 * intervals per output), report.md (the verdict: which factors matter),
 * <output>_sensitivity.png per output (bars with interval whiskers),
 * ledger.tsv and the manifest. */
#ifndef PHC_SENSITIVITY_STUDY_H
#define PHC_SENSITIVITY_STUDY_H

#include <stddef.h>

#include "fit/engine/problem.h"
#include "fit/engine/progress.h"
#include "fit/engine/provenance.h"
#include "model/status.h"

typedef enum phc_study_method { PHC_STUDY_SOBOL = 0, PHC_STUDY_MORRIS = 1 } phc_study_method;

typedef struct phc_study_options {
    phc_study_method method;
    size_t samples;        /* Sobol: base samples N (default 512); Morris: trajectories r (default 20) */
    unsigned long seed;    /* design (Morris, randomised Sobol) and bootstrap (1) */
    int second_order;      /* Sobol: also S_ij (0) */
    int randomised;        /* Sobol: Mersenne Twister design instead of GSL's Sobol sequence (0) */
    unsigned levels;       /* Morris: grid levels p (4) */
    int resume;            /* continue from DIR.ledger */
    int force;             /* replace DIR (run_dir.h) and a stale DIR.ledger */
    size_t stop_after;     /* for tests: stop after this many new evaluations, leaving the ledger
                              as an interrupted study would (0: never) */
    phc_progress_fn progress;
    void *progress_data;
    struct phc_dist *dist; /* NULL: one process; else the processes of an MPI run (fit/study_dist.h,
                              phc_dist_open): every rank calls phc_study_run, rank 0 (the master) records
                              the results and writes DIR, the workers only evaluate rows and return */
} phc_study_options;

phc_study_options phc_study_options_default(void);

/* What the command prints after the study. */
typedef struct phc_study_summary {
    size_t evaluations, reused, computed, failed;
    char *verdict; /* malloc'd lines: "matters: ...", "does not matter: ..." */
} phc_study_summary;
void phc_study_summary_clear(phc_study_summary *s);

/* Runs the study and writes DIR.  Errors: bad input (a parameter without
 * finite bounds or a prior, too few samples, an empty group, a ledger from
 * another study), I/O; PHC_ERR_INTERNAL "stopped after ..." when
 * stop_after ended it. */
int phc_study_run(const phc_problem *pb, const phc_study_options *o, const phc_provenance *pv, const char *dir,
                  phc_study_summary *summary, phc_error *err);

/* ---- the evaluation seam ---------------------------------------------------------------- */

/* Number of outputs of one evaluation: 1 + 1 per data set (its mean), or
 * 1 + 2 per data set (its cost and mean) when there are several. */
size_t phc_study_outputs(const phc_problem *pb);
/* Name of output j ("cost", "<data set>.cost", "<data set>.mean"), into buf. */
void phc_study_output_name(const phc_problem *pb, size_t j, char *buf, size_t size);

typedef struct phc_study_eval phc_study_eval;
phc_study_eval *phc_study_eval_new(const phc_problem *pb); /* NULL: out of memory */
void phc_study_eval_free(phc_study_eval *w);
/* The outputs at global parameter values x (n_params, slot units) into out
 * (phc_study_outputs values).  0 on success; > 0 when a model could not be
 * evaluated there or gave a non-finite value (out then holds NAN). */
int phc_study_evaluate(phc_study_eval *w, const double *x, double *out);

#endif /* PHC_SENSITIVITY_STUDY_H */
