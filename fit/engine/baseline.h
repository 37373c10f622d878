/* Baselines a fitted model must beat (issue 18, "verdicts against
 * baselines"): the weighted mean of the data, which any model should beat
 * (R² < 0 means it does not), and simpler models a kind names for its data
 * (the straight line for curves, the allometric line ln R:S = a + b ln D
 * for root:shoot harvests).  Each baseline is fitted by weighted least
 * squares to the same observations and weights and measured with the same
 * goodness figures as the model (fit/engine/goodness.h), so their AICc
 * compare directly: the verdict warns when a baseline predicts the data
 * better (fit/engine/fit.c). */
#ifndef PHC_BASELINE_H
#define PHC_BASELINE_H

#include <stddef.h>

#include "fit/engine/goodness.h"
#include "model/status.h"

#define PHC_MAX_BASELINES 3

typedef struct phc_baseline {
    char name[32];         /* "mean", "line", "allometric", ... */
    char what[128];        /* in words: "a straight line in x", ... */
    phc_goodness goodness; /* of the baseline's predictions (k = its parameters) */
} phc_baseline;

/* The weighted mean ȳ = Σ w y / Σ w (w = 1/σ², 1 without sigmas; one
 * parameter).  PHC_ERR_INVALID for n = 0 or invalid sigmas. */
int phc_baseline_mean(const double *y, const double *sigma, size_t n, phc_baseline *out);

/* The weighted least-squares line y = a + b·u (two parameters) with u
 * given per observation (x, ln x, ...); name and what as above.  Returns 1
 * (out untouched) when the line is not defined: fewer than 3 observations
 * or all u equal; PHC_ERR_INVALID for non-finite input. */
int phc_baseline_line(const double *u, const double *y, const double *sigma, size_t n, const char *name,
                      const char *what, phc_baseline *out);

#endif /* PHC_BASELINE_H */
