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

/* Writes a fit's run directory (result.json, report.md, plots) by the three
 * steps below.  pb (may be NULL) is the problem that was fitted: data sets
 * whose kind writes its own files (dataset.h, fit_outputs) add them, at the
 * fitted values. */
int phc_run_dir_write(const phc_fit_result *res, const phc_problem *pb, const char *dir, int force,
                      phc_error *err);

/* The steps, for any command that writes a run directory:
 * begin checks DIR (as phc_run_dir_check), creates its parents and a
 * temporary sibling, whose path goes to tmpdir (size bytes);
 * commit renames the temporary directory to DIR (replacing an earlier run
 * only now) or, on failure, removes it and keeps the earlier run;
 * discard removes the temporary directory after a failure. */
int phc_run_dir_begin(const char *dir, int force, char *tmpdir, size_t size,
                      phc_error *err);
int phc_run_dir_commit(const char *tmpdir, const char *dir, phc_error *err);
void phc_run_dir_discard(const char *tmpdir);

/* A file-name-safe copy of a data-set name: characters other than letters,
 * digits, '-', '_' and '.' become '_'. */
void phc_run_dir_safe_name(const char *name, char *out, size_t size);

#endif /* PHC_RUN_DIR_H */
