/* Cross-validation by the engine: a data set's observations fall into
 * groups (a photo's residuals, a leaf's curve ...); each group is left out
 * in turn, the data set's free slots are refitted on the others, and the
 * kind predicts the left-out group's quantity (a photo's stage, say) from
 * the refitted slots, beside any baselines of its own.  The engine runs the
 * refits (one Ceres solve per group, fit/engine/ceres_bridge.h), reports progress
 * ("leave-one-out 3/13 (ivy)") and collects the predictions and their RMSE;
 * no kind runs a solve.
 *
 * A kind takes part through its optional op `cross_validation`
 * (fit/engine/dataset.h), which fills a phc_cv_plan: the groups, what is measured
 * and how to predict it.  phc_fit_run calls phc_cross_validate for every
 * data set whose kind has the op and adds phc_cv_result_markdown to the
 * data set's report section.
 *
 * The refit is the data set's own: its residuals, loss and derivatives,
 * over its slots with the bounds, fixed flags and scales of the problem's
 * parameters they are bound to, from the fitted values, with the problem's
 * solver options.  Other data sets are not refitted with it (their
 * parameters, shared or not, are neither read nor changed). */
#ifndef PHC_CROSS_VALIDATION_H
#define PHC_CROSS_VALIDATION_H

#include <stddef.h>

#include "fit/engine/dataset.h"
#include "fit/engine/problem.h"
#include "fit/engine/progress.h"
#include "model/status.h"

/* An observation in no group: never left out. */
#define PHC_CV_NO_GROUP ((size_t)-1)
/* Predictions per group: the model's and up to three baselines. */
#define PHC_CV_MAX_PREDICTIONS 4

/* What a kind says about its cross-validation (filled by its op). */
typedef struct phc_cv_plan {
    size_t n_groups;      /* groups left out in turn; 0: the data set asks for none */
    size_t *group;        /* ds->n: the group of each observation (< n_groups), or
                             PHC_CV_NO_GROUP; malloc'd (phc_cv_plan_clear frees it) */
    char **names;         /* n_groups names (a row's id ...); malloc'd, each malloc'd */
    double *observed;     /* n_groups: the quantity as measured; malloc'd */
    size_t n_predictions; /* values predict() gives per group, 1..PHC_CV_MAX_PREDICTIONS:
                             the model's first, then baselines */
    const char *labels[PHC_CV_MAX_PREDICTIONS]; /* their names in the report
                                                   ("model", "baseline") */
    const char *quantity;    /* what is predicted, with its units' name ("SPAD") */
    const char *group_title; /* what one group is ("row") */
    const char *how;         /* how the model's prediction is read off ("the stage read off
                                the model time whose colours match the photo best") */
    const char *note;        /* a sentence on the baselines, or NULL */
    /* The predictions of group g's quantity, values[0 .. n_predictions-1],
     * at slot values p refitted without group g (values[0]; NAN when the
     * model cannot predict it there); a baseline may use the data set's
     * other groups in its own way.  PHC_OK or an error (NOMEM ...). */
    int (*predict)(phc_dataset *ds, const double *p, size_t g, double *values, phc_error *err);
} phc_cv_plan;

/* Frees what the plan owns (group, names, observed) and zeroes it. */
void phc_cv_plan_clear(phc_cv_plan *plan);

typedef struct phc_cv_result {
    size_t n_groups, n_predictions;
    char **names;           /* n_groups */
    double *observed;       /* n_groups */
    double *predicted;      /* n_groups x n_predictions, row-major; column 0 NAN where
                               the model could not predict */
    double rmse[PHC_CV_MAX_PREDICTIONS]; /* of each prediction over the groups whose
                               model prediction is not NAN (NAN when there are none) */
    char *quantity, *group_title, *how, *note; /* copied from the plan (note may be NULL) */
    char *labels[PHC_CV_MAX_PREDICTIONS];
} phc_cv_result;

void phc_cv_result_free(phc_cv_result *res); /* accepts NULL */

/* Runs `plan` on data set ds (a data set of problem pb, whose parameters
 * give the bounds, fixed flags and scales of ds's slots) at its fitted slot
 * values p (ds->k): for each group g, progress "leave-one-out" step g+1 of
 * n_groups (detail: the data set's name; the solver's iterations relayed),
 * the refit without group g (its residuals set to zero) from p, and
 * plan->predict at the refitted values.  Leaves the data set's model
 * evaluated at p.  *out is NULL when the plan has no group.  A cancel
 * through progress is PHC_ERR_INTERNAL "cancelled". */
int phc_cross_validate_plan(const phc_problem *pb, phc_dataset *ds, const phc_cv_plan *plan, const double *p,
                            phc_progress_fn progress, void *user_data, phc_cv_result **out, phc_error *err);

/* Asks the data set's kind for its plan (ops->cross_validation) and runs
 * it; *out is NULL when the kind has no such op or asks for none. */
int phc_cross_validate(const phc_problem *pb, phc_dataset *ds, const double *p, phc_progress_fn progress,
                       void *user_data, phc_cv_result **out, phc_error *err);

/* The report's section on a result (markdown, malloc'd): a title, a table
 * of the groups the model predicted (measured, then each prediction), and
 * the RMSE of each prediction in the quantity's units. */
int phc_cv_result_markdown(const phc_cv_result *res, char **markdown, phc_error *err);

#endif /* PHC_CROSS_VALIDATION_H */
