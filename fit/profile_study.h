/* `phytocal profile`: profile likelihood of every free parameter
 * (fit/engine/profile.h) beside the Wald intervals of `fit`, written as a
 * run directory (run_dir.h rules):
 *   result.json   the fit's estimates and Wald intervals, each parameter's
 *                 profile (theta and delta-cost arrays, the user's unit) and
 *                 likelihood-based interval with how each side ended;
 *   report.md     the verdict and a table;
 *   profile_<parameter>.png  delta cost against the parameter (profile_plots.h);
 *   the manifest.
 *
 * Verdict per parameter:
 *   "practically non-identifiable"  flat profile (delta < 1% of the threshold
 *                                   everywhere it was traced, no side crossed);
 *   "open to the lower/upper bound" a side reached the bound below the
 *                                   threshold;
 *   "open below/above"              a side stopped (step limit) below it;
 *   "profile and Wald intervals disagree"  an end differs by more than 10% of
 *                                   the Wald half-width on that side, or the
 *                                   Wald interval is not determined;
 *   "profile and Wald intervals agree" otherwise. */
#ifndef PHC_PROFILE_STUDY_H
#define PHC_PROFILE_STUDY_H

#include <stddef.h>

#include "fit/engine/problem.h"
#include "fit/engine/profile.h"
#include "fit/engine/progress.h"
#include "fit/engine/provenance.h"
#include "model/status.h"

/* Relative disagreement that flags a side: 10% of the Wald half-width. */
#define PHC_PROFILE_DISAGREE 0.10

typedef struct phc_profile_study_options {
    double level;   /* 0.95 */
    size_t points;  /* target points per side (>= 3; 12) */
    int force;      /* replace DIR (run_dir.h) */
    phc_progress_fn progress;
    void *progress_data;
    /* NULL: one process; else the processes of an MPI run
       (fit/study_dist.h, phc_dist_open): every rank calls
       phc_profile_study_run; each fits, then the profiles are shared out
       (profile.h) and rank 0 alone writes DIR, identical to one process's
       (the workers return PHC_OK with an empty summary). */
    struct phc_dist *dist;
} phc_profile_study_options;

phc_profile_study_options phc_profile_study_options_default(void);

typedef struct phc_profile_summary {
    size_t n_params, n_disagree, n_open, n_flat;
    int fit_converged;
    char *table;   /* malloc'd: one line per parameter for the terminal */
    char *verdict; /* malloc'd lines */
} phc_profile_summary;
void phc_profile_summary_clear(phc_profile_summary *s);

/* Fits pb, profiles every free parameter and writes DIR.  Errors: bad input
 * (no free parameter, no degrees of freedom, points < 3, level outside
 * (0, 1)), the fit's errors, I/O. */
int phc_profile_study_run(phc_problem *pb, const phc_profile_study_options *o, phc_provenance *pv,
                          const char *dir, phc_profile_summary *summary, phc_error *err);

#endif /* PHC_PROFILE_STUDY_H */
