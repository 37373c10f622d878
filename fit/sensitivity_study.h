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
 * squared weighted residuals over all data sets); per data set, its own
 * cost (when there are several data sets) and its mean prediction over its
 * observations; the named outputs (a data set's prediction at an x or an
 * observation, `outputs:` in the config); and per data set its prediction
 * at every observation (at most pb->series_points of them, evenly spaced),
 * whose indices are estimated per observation and summarised over them by
 * the variance-weighted generalised indices (Sobol: sobol_indices.h,
 * phc_sobol_indices_estimate_aggregate).
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
 * intervals per scalar output; per data set the indices per observation as
 * arrays and their summary), report.md (the verdict: which factors matter,
 * from the scalar outputs and the summaries), <output>_sensitivity.png per
 * scalar output (bars with interval whiskers), <data set>_over_x.png per
 * data set (indices against x with bootstrap bands), ledger.tsv and the
 * manifest. */
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

/* The outputs of one evaluation, in this order:
 *   the cost;
 *   per data set its mean prediction ("<data set>.mean"), preceded by its
 *   own cost ("<data set>.cost") when there are several data sets;
 *   the named outputs of the config's `outputs:` (pb->outputs, by name);
 *   per data set its predictions at phc_study_series_points(pb, d) of its
 *   observations ("<data set>@<observation, from 1>"): all of them when it
 *   has at most pb->series_points, else that many evenly spaced by index,
 *   the first and the last included.
 * The first phc_study_scalar_outputs(pb) are the scalar outputs (a table
 * and a bar plot each); the rest are the series (indices per observation,
 * a summary over them and a plot against x per data set). */
size_t phc_study_outputs(const phc_problem *pb);
size_t phc_study_scalar_outputs(const phc_problem *pb);
size_t phc_study_series_points(const phc_problem *pb, size_t d);
/* The 0-based observation of data set d behind its series output t. */
size_t phc_study_series_observation(const phc_problem *pb, size_t d, size_t t);
/* Name of output j, into buf. */
void phc_study_output_name(const phc_problem *pb, size_t j, char *buf, size_t size);

typedef struct phc_study_eval phc_study_eval;
phc_study_eval *phc_study_eval_new(const phc_problem *pb); /* NULL: out of memory */
void phc_study_eval_free(phc_study_eval *w);
/* The outputs at global parameter values x (n_params, slot units) into out
 * (phc_study_outputs values).  0 on success; > 0 when a model could not be
 * evaluated there or gave a non-finite value (out then holds NAN). */
int phc_study_evaluate(phc_study_eval *w, const double *x, double *out);
/* The cost alone (output 0 of phc_study_evaluate, the same number) into
 * *cost, without the other outputs' work (named outputs may solve the model
 * again): what a sampler needs at every step.  0 on success; > 0 as above
 * (*cost then NAN). */
int phc_study_cost(phc_study_eval *w, const double *x, double *cost);

#endif /* PHC_SENSITIVITY_STUDY_H */
