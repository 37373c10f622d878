/* The diagnostic plots of a fit, one set per data set: the data with the
 * fitted model (<name>_fit.png), the residuals against x
 * (<name>_residuals.png), a normal QQ plot of the standardised residuals
 * (<name>_qq.png) and the residual autocorrelation (<name>_acf.png, when
 * there are enough residuals; over time lags in hours for a time series
 * spanning >= 1.5 days) and, when the local clock time of the observations
 * is known, the standardised residuals by time of day
 * (<name>_time_of_day.png).  <name> is the data set's file-name-safe
 * name (phc_run_dir_safe_name).  A data set whose observations form series
 * (probes, leaves, quantiles: phc_dataset_result.series) is drawn with one
 * colour per series and a key naming them, in the fit and residual plots. */
#ifndef PHC_FIT_PLOTS_H
#define PHC_FIT_PLOTS_H

#include <stddef.h>

#include "fit/engine/fit.h"
#include "model/status.h"

/* Writes the plots of every data set of res into directory dir and appends
 * each file name (malloc'd) to names[*n_names], while fewer than
 * max_names - 1 are there (the list stays NULL-terminated for the report).
 * PHC_OK or the first error. */
int phc_fit_plots_write(const phc_fit_result *res, const char *dir, char **names, size_t *n_names,
                        size_t max_names, phc_error *err);

#endif /* PHC_FIT_PLOTS_H */
