/* The plot of one profile likelihood (`phytocal profile`): delta cost (the
 * profile cost minus the best cost) against the parameter, with the
 * threshold of the likelihood-ratio test as a horizontal line, the profile
 * (likelihood-based) interval and the Wald interval of `fit` as vertical
 * lines, and the estimate.  White background, labelled axes, legend. */
#ifndef PHC_PROFILE_PLOTS_H
#define PHC_PROFILE_PLOTS_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_profile_plot {
    const char *param;      /* parameter name */
    const char *unit;       /* its unit or NULL */
    const double *theta, *delta; /* n points (the user's unit; delta in cost units) */
    size_t n;
    double estimate, threshold, level;
    double prof_lo, prof_hi;/* NAN for a side that did not cross */
    double wald_lo, wald_hi;/* NAN when not determined */
} phc_profile_plot;

/* Writes the PNG at path (atomically).  PHC_ERR_INTERNAL without PLplot's
 * pngcairo device. */
int phc_plot_profile(const char *path, const phc_profile_plot *p, phc_error *err);

#endif /* PHC_PROFILE_PLOTS_H */
