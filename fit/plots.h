/* Diagnostic plots of a fit, drawn with PLplot's cairo PNG driver (pngcairo).
 * White background, black axes, labelled axes with units, a legend, readable
 * fonts, 1000 x 700 pixels.  Each function writes one PNG at `path`
 * (overwriting it) and returns PHC_OK, or PHC_ERR_IO / PHC_ERR_INVALID with a
 * message in err.  Non-finite values are skipped, not plotted.  The functions
 * hold no global state between calls (PLplot streams are created and ended in
 * each call), so they can be called in any order. */
#ifndef PHC_PLOTS_H
#define PHC_PLOTS_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_plot_labels {
    const char *title;    /* e.g. "misra1a: data and fit" */
    const char *x_label;  /* with unit, e.g. "time (h)" */
    const char *y_label;  /* with unit, e.g. "mass (g)" */
} phc_plot_labels;

/* Data points (x[i], y[i]) as markers with optional error bars (sigma may be
 * NULL) and the fitted model as a line through (curve_x[j], curve_y[j]),
 * j < curve_n (sorted by x; a dense grid).  Legend: "data", "fit". */
int phc_plot_fit(const char *path, const phc_plot_labels *labels,
                 const double *x, const double *y, const double *sigma,
                 size_t n, const double *curve_x, const double *curve_y,
                 size_t curve_n, phc_error *err);

/* Residuals r[i] against x[i] as markers, a zero line, and dashed lines at
 * +-2 s (s = residual standard deviation given by the caller; skipped if s is
 * not positive).  Legend: "residual", "0", "+-2 s". */
int phc_plot_residuals(const char *path, const phc_plot_labels *labels,
                       const double *x, const double *r, size_t n, double s,
                       phc_error *err);

/* Normal QQ plot: sorted standardised residuals against normal quantiles
 * (Blom positions (i - 3/8)/(n + 1/4)), with the line y = x.  x/y labels from
 * `labels` may be NULL (defaults: "normal quantile", "standardised residual"). */
int phc_plot_qq(const char *path, const phc_plot_labels *labels,
                const double *r, size_t n, phc_error *err);

/* Autocorrelation bars acf[h], h = 0..max_lag, with the +-1.96/sqrt(n) band
 * of white noise (n = number of residuals) as dashed lines. */
int phc_plot_acf(const char *path, const phc_plot_labels *labels,
                 const double *acf, size_t max_lag, size_t n, phc_error *err);

#endif /* PHC_PLOTS_H */
