/* result.json: the machine-readable result of a fit (DESIGN.md §4).
 *
 * Fields other tools may rely on: status, termination, iterations, cost,
 * rss, dof, parameters{name: value, stderr, ci95, fixed, at_bound, unit},
 * correlation{names, matrix}, datasets[{name, kind, n, rss, rmse, r2,
 * checks{name: value, pass}}].  Beyond those the file holds everything the
 * report shows (goodness measures, p-values, sensitivities, collinearity,
 * warnings) and the data, predictions and residuals, so that
 * `phytocal report` can recompute the checks without the original files.
 * Non-finite numbers are written as null. */
#ifndef PHC_RESULT_JSON_H
#define PHC_RESULT_JSON_H

#include "fit/engine/fit.h"
#include "model/status.h"

/* Writes res to path (through a temporary name renamed into place). */
int phc_result_write_json(const phc_fit_result *res, const char *path, phc_error *err);

/* Reads a result written by phc_result_write_json.  Errors name the file and
 * the missing or mistyped field (e.g. "result.json: datasets[0].residuals:
 * expected an array of 14 numbers"). */
int phc_result_read_json(const char *path, phc_fit_result **out, phc_error *err);

#endif /* PHC_RESULT_JSON_H */
