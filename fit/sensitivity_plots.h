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

/* One line with a band: a factor's index at each point of a series and
 * its interval there. */
typedef struct phc_band_line {
    const char *label;          /* legend text (the factor) */
    const double *value;        /* n values (NAN: a gap) */
    const double *lo, *hi;      /* n interval ends (a shaded band), or NULL */
} phc_band_line;

/* Indices against x: n_panels (1 or 2) panels stacked over one x axis,
 * panel q titled y_labels[q] and drawing lines[q * n_lines + i] for the
 * n_lines factors (one colour each, the same in every panel; the band
 * translucent), a legend of the factors and a white page.  A line breaks
 * where x decreases (a data set of several series). */
int phc_plot_index_lines(const char *path, const char *title, const char *x_label, const double *x, size_t n,
                         const char *const *y_labels, size_t n_panels, const phc_band_line *lines, size_t n_lines,
                         phc_error *err);

#endif /* PHC_SENSITIVITY_PLOTS_H */
