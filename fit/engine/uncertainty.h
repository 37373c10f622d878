/* Parameter covariance at the optimum from the weighted Jacobian.
 *
 * Cov = s^2 (J'J)^+, computed from the SVD of J with its columns scaled to
 * unit length (so the rank decision does not depend on parameter units):
 * J D^-1 = U S V', Cov = s^2 D^-1 V S^-2 V' D^-1 over the singular values
 * above rcond * S_max.  A rank-deficient J (a parameter the data cannot see,
 * or two that only act together) does not fail: the pseudo-inverse is used
 * and each dropped direction is returned as the combination of parameters
 * it moves (the right singular vector), e.g. "0.71 b1 - 0.71 b2".
 * Standard errors of parameters in such a direction are reported as NAN
 * ("not determined"), never as the pseudo-inverse's misleading small value. */
#ifndef PHC_UNCERTAINTY_H
#define PHC_UNCERTAINTY_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_covariance {
    size_t n;            /* free parameters */
    double *cov;         /* n x n, row-major, already times s^2 */
    double *stderr_;     /* n standard errors; NAN where not determined */
    double *correlation; /* n x n; NAN rows/cols where not determined */
    size_t rank;         /* numerical rank of J */
    double condition;    /* S_max / S_min of the scaled J (inf when rank < n) */
    size_t n_null;       /* n - rank */
    double *null_vectors;/* n_null x n, row-major: undetermined directions in
                            scaled coordinates (unit vectors) */
} phc_covariance;

/* J: m x n row-major (weighted residual Jacobian over the free parameters);
 * s2: the variance factor (RSS/dof, or 1 for absolute sigmas); rcond:
 * relative singular value cut-off (1e-10 is a good default; it is applied
 * to the column-scaled J).  scale: n typical parameter magnitudes (NULL =
 * ones); a column whose effect |J_j| * scale_j is below rcond times the
 * largest is undetermined too (a parameter driven where the model no longer
 * depends on it, e.g. a rate so fast that exp(-b x) is 0 at every x). */
int phc_covariance_compute(const double *J, size_t m, size_t n, double s2,
                           double rcond, const double *scale,
                           phc_covariance *out, phc_error *err);
void phc_covariance_clear(phc_covariance *c);

/* The rule for "the model does not depend on this parameter here": marks
 * (negligible[j] = 1) the columns of J (m x n, row stride ld) whose effect
 * |J_j| * scale_j is at most rcond times the largest effect among the
 * columns not skipped.  scale may be NULL (ones); skip may be NULL, else
 * columns with skip[j] != 0 (fixed parameters) are neither measured nor
 * marked.  Returns the number marked.  Used by the covariance and by the
 * fit's plateau test for rescue starts. */
size_t phc_negligible_columns(const double *J, size_t m, size_t n, size_t ld,
                              const double *scale, const int *skip,
                              double rcond, int *negligible);

/* Describes null vector `which` as text, e.g. "0.707 b1 - 0.707 b2",
 * listing components with |v| >= 0.05, largest first. */
void phc_covariance_describe_null(const phc_covariance *c, size_t which,
                                  const char *const *names, char *buf,
                                  size_t size);

#endif /* PHC_UNCERTAINTY_H */
