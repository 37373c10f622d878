/* The summary of a batch of fits (`phytocal fit A.yaml B.yaml -o DIR`,
 * `phytocal fit CONFIG.yaml --each COLUMN -o DIR`): one row per fit, written
 * as DIR/summary.tsv (for programs) and DIR/summary.md (for people).
 *
 * summary.tsv is wide: one row per fit, tab-separated, a header line, then
 *   fit      the fit's name: the config's stem, or the group's value
 *   <COLUMN> (--each only) the group's value as it is in the table
 *   config   the configuration file
 *   dir      the fit's run directory relative to DIR (empty: none written)
 *   status   converged, not_converged, failed (the solver gave no result) or
 *            error (the config or data could not be loaded, or the run
 *            directory not written)
 *   exit     the exit code `phytocal fit` alone would have given it
 *   verdict  "no problems found" or "N warnings" (empty without a result)
 *   cost     1/2 sum rho(r^2) of the weighted residuals
 *   n_obs    observations
 *   r2_<D>   R² of data set D, one column per data-set name met
 *   <P>, <P>_se  value and standard error of parameter P (user's unit), one
 *            pair per parameter name met, in order of first appearance
 *   message  why a fit failed or did not converge (empty otherwise)
 * A cell is empty where the fit has no such value (another fit's parameter,
 * no result, a standard error that is not determined).  Numbers are printed
 * with 17 significant digits: they read back as the doubles of result.json.
 * Tabs and line breaks inside text cells become spaces. */
#ifndef PHC_BATCH_SUMMARY_H
#define PHC_BATCH_SUMMARY_H

#include <stddef.h>

#include "fit/engine/fit.h"
#include "model/status.h"

typedef struct phc_batch_param {
    char *name;
    double value, stderr_; /* stderr_ NAN when not determined or fixed */
} phc_batch_param;

typedef struct phc_batch_row {
    char *fit, *group, *config, *dir, *status, *verdict, *message; /* group, dir, verdict, message may be NULL */
    int exit_code;
    int has_result;
    double cost;
    size_t n_obs;
    size_t n_datasets;
    char **dataset_names;
    double *r2;
    size_t n_params;
    phc_batch_param *params;
} phc_batch_row;

/* Fills a row's numbers from a fit result (copies; res may be freed after). */
int phc_batch_row_set_result(phc_batch_row *row, const phc_fit_result *res);
void phc_batch_row_clear(phc_batch_row *row);

/* Writes DIR/summary.tsv and DIR/summary.md (atomically); group_column is
 * the --each column or NULL. */
int phc_batch_summary_write(const char *dir, const char *group_column, const phc_batch_row *rows, size_t n,
                            phc_error *err);

#endif /* PHC_BATCH_SUMMARY_H */
