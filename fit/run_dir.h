/* Writing a run directory: result.json, report.md and the diagnostic plots.
 *
 * Everything is written into a temporary sibling directory (DIR.tmp-XXXXXX)
 * that is renamed to DIR only when complete, so a failed run leaves no
 * partial output.  An existing DIR is an error (PHC_ERR_EXISTS) unless
 * `force` is set; then it is replaced only after the new run is complete. */
#ifndef PHC_RUN_DIR_H
#define PHC_RUN_DIR_H

#include "fit/fit.h"
#include "model/status.h"

/* Checks up front that DIR can be written (absent, or force), so a long fit
 * is not wasted on a directory that will be refused. */
int phc_run_dir_check(const char *dir, int force, phc_error *err);

int phc_run_dir_write(const phc_fit_result *res, const char *dir, int force,
                      phc_error *err);

#endif /* PHC_RUN_DIR_H */
