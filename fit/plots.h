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
    const char *model;    /* legend text of the model line (NULL: "fit"), e.g.
                             "model at start values" */
} phc_plot_labels;

/* Observations in groups (the probes of soil readings, the leaves of PV
 * curves, the quantiles of a colour histogram): one colour per group and a
 * key beside the plot that names them.  Up to 10 groups get distinct
 * colours (matplotlib's "tab10"); more get a colour ramp in group order
 * (viridis, its light yellow end left out), and the key lists the names in
 * up to three columns, or, when they do not fit, labels every k-th cell of
 * a colour bar. */
typedef struct phc_plot_groups {
    size_t count;             /* groups, >= 1; every id is below it */
    const size_t *id;         /* group of each observation (n ids) */
    const char *const *names; /* count names, or NULL: "1", "2", ... */
    const char *title;        /* what a group is ("probe"), the key's heading; NULL: "group" */
} phc_plot_groups;

/* Data points (x[i], y[i]) as markers with optional error bars (sigma may be
 * NULL) and the fitted model as a line through (curve_x[j], curve_y[j]),
 * j < curve_n (sorted by x; a dense grid).  Legend: "data", labels->model. */
int phc_plot_fit(const char *path, const phc_plot_labels *labels,
                 const double *x, const double *y, const double *sigma,
                 size_t n, const double *curve_x, const double *curve_y,
                 size_t curve_n, phc_error *err);

/* phc_plot_fit with groups (NULL: one group, drawn as phc_plot_fit draws):
 * markers in their group's colour, and the model either as
 *   - yhat (n model values at the observations, may be NULL): one line per
 *     group through its observations in x order, in the group's colour; or
 *   - the curve (curve_n > 0): one model line for all groups, in black
 *     (labelled "<model> (shared)"); given both, only the curve is drawn.
 * The key says what markers and lines are and names the groups. */
int phc_plot_fit_groups(const char *path, const phc_plot_labels *labels,
                        const double *x, const double *y, const double *sigma,
                        size_t n, const phc_plot_groups *groups,
                        const double *yhat, const double *curve_x,
                        const double *curve_y, size_t curve_n, phc_error *err);

/* Residuals r[i] against x[i] as markers, a zero line, and dashed lines at
 * +-2 s (s = residual standard deviation given by the caller; skipped if s is
 * not positive).  Legend: "residual", "0", "+-2 s". */
int phc_plot_residuals(const char *path, const phc_plot_labels *labels,
                       const double *x, const double *r, size_t n, double s,
                       phc_error *err);

/* The same with the markers coloured by group (groups may be NULL). */
int phc_plot_residuals_groups(const char *path, const phc_plot_labels *labels,
                              const double *x, const double *r, size_t n,
                              double s, const phc_plot_groups *groups,
                              phc_error *err);

/* ---- any x-y plot made of layers (what the functions above draw with) ---- */

typedef enum phc_plot_mark {
    PHC_MARK_DOTS,     /* filled circles, vertical error bars when sigma is given */
    PHC_MARK_LINE,     /* a solid line through the points in the order given,
                          broken at non-finite points */
    PHC_MARK_DASHED,   /* the same, dashed */
    PHC_MARK_DIAMONDS, /* large diamonds edged in black: points to point out
                          (a turgor loss point) */
    PHC_MARK_HLINE,    /* a horizontal line at y[0] across the whole plot */
    PHC_MARK_HDASHED   /* the same, dashed */
} phc_plot_mark;

/* Colours of layers: a group's (0, 1, ... < groups->count) or one of these. */
enum {
    PHC_COLOUR_DATA = -1,  /* blue: data of an ungrouped plot */
    PHC_COLOUR_FIT = -2,   /* red: the model of an ungrouped plot */
    PHC_COLOUR_REF = -3,   /* dark grey: reference lines (zero) */
    PHC_COLOUR_BAND = -4,  /* orange: bands (+-2 s) */
    PHC_COLOUR_BLACK = -5  /* black: a model shared by every group */
};

typedef struct phc_plot_layer {
    phc_plot_mark mark;
    int colour;            /* a group index or PHC_COLOUR_* */
    const double *x, *y;   /* n points (x unused for PHC_MARK_HLINE, _HDASHED) */
    size_t n;              /* 0: an entry of the key only */
    const double *sigma;   /* PHC_MARK_DOTS: n error bar half-lengths, or NULL */
    const char *label;     /* the key's text for this layer, or NULL: none */
} phc_plot_layer;

/* Draws the layers in order (markers under lines: put them first) on axes
 * that hold every finite point and error bar.  Labelled layers make the
 * legend: inside the axes where it covers least when groups is NULL, in a
 * key beside the axes above the group names otherwise (only count, names
 * and title of groups are used).  At least one layer must have a finite
 * point. */
int phc_plot_layers(const char *path, const phc_plot_labels *labels,
                    const phc_plot_layer *layers, size_t n_layers,
                    const phc_plot_groups *groups, phc_error *err);

/* Normal QQ plot: sorted standardised residuals against normal quantiles
 * (Blom positions (i - 3/8)/(n + 1/4)), with the line y = x.  x/y labels from
 * `labels` may be NULL (defaults: "normal quantile", "standardised residual"). */
int phc_plot_qq(const char *path, const phc_plot_labels *labels,
                const double *r, size_t n, phc_error *err);

/* Autocorrelation bars acf[h], h = 0..max_lag, with the +-1.96/sqrt(n) band
 * of white noise (n = number of residuals) as dashed lines. */
int phc_plot_acf(const char *path, const phc_plot_labels *labels,
                 const double *acf, size_t max_lag, size_t n, phc_error *err);

/* Autocorrelation of a time series over time lags (phc_check_acf_time):
 * bars acf[k] at lags k bin_h hours, k < bins (NAN bins left empty), the
 * +-1.96/sqrt(n) band of white noise (n residuals; the usual band: for bins
 * holding N_k > n pairs the exact white-noise band 1.96/sqrt(N_k) is
 * narrower), ticks every 6 h when the lags reach 18-100 h, and a dotted
 * line at 24 h ("24 h (one day)") when the lags reach it.  x label default
 * "lag (h)". */
int phc_plot_acf_time(const char *path, const phc_plot_labels *labels,
                      const double *acf, size_t bins, double bin_h, size_t n,
                      phc_error *err);

/* Residuals by local clock time: r[i] (standardised residuals) against
 * hour[i] in [0, 24) as markers, the mean of each clock hour (bins
 * [h, h + 1)) as a line closed over midnight, a zero line and dashed lines
 * at +-2.  Observations with a non-finite or out-of-range hour are not
 * drawn.  Default labels "local clock time (h)", "standardised residual". */
int phc_plot_time_of_day(const char *path, const phc_plot_labels *labels,
                         const double *hour, const double *r, size_t n,
                         phc_error *err);

#endif /* PHC_PLOTS_H */
