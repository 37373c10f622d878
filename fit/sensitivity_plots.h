/* The bar plot of a sensitivity study: one group of bars per factor (for
 * example first-order and total Sobol indices, or Morris mu* and sigma),
 * each with a whisker for its interval, on a white page with labelled axes
 * and a legend (PLplot, pngcairo; written through a temporary file). */
#ifndef PHC_SENSITIVITY_PLOTS_H
#define PHC_SENSITIVITY_PLOTS_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_bar_series {
    const char *label;          /* legend text */
    const double *value;        /* n_factors bar heights (NAN: no bar) */
    const double *lo, *hi;      /* interval ends, or NULL */
} phc_bar_series;

/* n_series (1 or 2) series over n_factors named factors. */
int phc_plot_bars(const char *path, const char *title, const char *y_label, const char *const *factors,
                  size_t n_factors, const phc_bar_series *series, size_t n_series, phc_error *err);

#endif /* PHC_SENSITIVITY_PLOTS_H */
