/* Local sensitivity and identifiability at the optimum, as R's FME package
 * does with sensFun and collin (Soetaert & Petzoldt 2010, J. Stat. Softw. 33).
 *
 * Normalised sensitivity of observation i to parameter j:
 *     S_ij = d yhat_i / d p_j * p_j / sigma_i
 * (sigma_i the observation's sigma; without sigmas the fit's residual
 * standard deviation s, so S is in units of the noise; p_j = 0 uses the
 * parameter's scale instead).  Summaries per parameter: L1 = mean |S_.j|,
 * L2 = sqrt(mean S_.j^2).
 * Collinearity index of a parameter subset K (Brun et al. 2001, Water Res.
 * 35:1015): gamma_K = 1 / sqrt(lambda_min(Sn_K' Sn_K)), Sn the columns of S
 * scaled to unit length.  gamma > 20 (FME's rule of thumb) means the subset
 * is poorly identifiable: a change in one parameter can be compensated by the
 * others to within 1/gamma of the change. */
#ifndef PHC_SENSITIVITY_H
#define PHC_SENSITIVITY_H

#include <stddef.h>

#include "model/status.h"

#define PHC_COLLIN_MAX_SIZE 6

typedef struct phc_collinear_set {
    size_t size;
    size_t index[PHC_COLLIN_MAX_SIZE]; /* into the free parameters */
    double gamma;                       /* collinearity index (inf if singular) */
} phc_collinear_set;

typedef struct phc_sensitivity {
    size_t n;                 /* free parameters */
    double *l1, *l2;          /* n summaries */
    size_t n_sets;            /* subsets evaluated */
    phc_collinear_set *sets;  /* all evaluated subsets, sorted by gamma descending */
    double max_gamma[PHC_COLLIN_MAX_SIZE + 1]; /* per subset size (index 2..6) */
    size_t max_size;          /* largest subset size evaluated */
} phc_sensitivity;

/* S: m x n row-major normalised sensitivities (the caller builds them from
 * the Jacobian as above).  Subsets of size 2 .. min(6, n) are evaluated;
 * when there are more than max_sets of them, the largest sizes are dropped
 * (max_size says how far it went). */
int phc_sensitivity_compute(const double *S, size_t m, size_t n, size_t max_sets,
                            phc_sensitivity *out, phc_error *err);
void phc_sensitivity_clear(phc_sensitivity *s);

#endif /* PHC_SENSITIVITY_H */
