/* Plots of an MCMC run (PLplot, pngcairo, white page, labelled axes):
 *  - trace: one panel per parameter, the value of each chain (at most 8
 *    drawn) against the step, the burn-in shaded grey; beyond two steps per
 *    pixel a chain is drawn through each pixel's lowest and highest value;
 *  - pairs: a d x d grid, histograms of each parameter's kept draws on the
 *    diagonal and scatter plots of every pair below it. */
#ifndef PHC_MCMC_PLOTS_H
#define PHC_MCMC_PLOTS_H

#include <stddef.h>

#include "model/status.h"

/* labels: d axis labels ("name (unit)"); draws: chains x n x d. */
int phc_plot_mcmc_trace(const char *path, const char *title, size_t d, const char *const *labels,
                        const double *draws, size_t chains, size_t n, size_t burn, phc_error *err);
/* draws: m x d (kept, pooled). */
int phc_plot_mcmc_pairs(const char *path, const char *title, size_t d, const char *const *labels,
                        const double *draws, size_t m, phc_error *err);

#endif /* PHC_MCMC_PLOTS_H */
