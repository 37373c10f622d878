/* The residual report: the human-readable side of a fit result.
 *
 * report.md holds, in this order: the verdict and its warnings; the solver
 * summary; the parameter table (value ± stderr, 95% interval, unit, bounds,
 * sensitivity L1/L2); strong correlations and collinearity; per data set the
 * goodness measures (n, RSS, RMSE, MAE, bias, R², NSE, reduced χ², AIC,
 * AICc, BIC) and the residual checks (statistic, p-value, pass/fail); and
 * links to the plots.  The compact summary is what the CLI prints. */
#ifndef PHC_REPORT_H
#define PHC_REPORT_H

#include <stdio.h>

#include "fit/engine/fit.h"
#include "model/status.h"

/* Markdown report.  `plots` lists the PNG file names (relative to the
 * report), NULL-terminated; each data set links the names that start with
 * its name and '_'.  NULL: no plots were drawn (`phytocal fit --plots
 * none`), which the report says. */
int phc_report_write_markdown(const phc_fit_result *res, const char *path,
                              const char *const *plots, phc_error *err);

/* Compact plain-text summary: status line, parameter table, per data set one
 * line of fit measures and the failed checks, the verdict. */
void phc_report_print_summary(const phc_fit_result *res, FILE *out);

/* 1 when the result passes every check of the verdict (no warnings). */
int phc_report_all_passed(const phc_fit_result *res);

#endif /* PHC_REPORT_H */
