/* model/jacobi_svd.h: singular value decomposition of a small dense matrix
 * by one-sided Jacobi rotations (Hestenes 1958, "Inversion of matrices by
 * biorthogonalization and related results", J. SIAM 6:51-90; the rotation
 * and the stopping rule as in Demmel & Veselic 1992, "Jacobi's method is
 * more accurate than QR", SIAM J. Matrix Anal. Appl. 13:1204-1245: the
 * one-sided method and its relative accuracy).
 *
 * For the fit analysis' matrices (a Jacobian of m rows and n <= ~20
 * parameters, a Gram matrix of a few columns) this replaces LAPACK's
 * dgesvd/dgelsd/dsyev: no LAPACKE to load, no work-space queries, transposes
 * or allocations, and singular values as accurate as LAPACK's (tests:
 * within 2e-15 of the largest one, against exact values).  Cost: a few sweeps of
 * n(n-1)/2 rotations of two m-vectors each.  Pure C, no allocation. */
#ifndef PHC_JACOBI_SVD_H
#define PHC_JACOBI_SVD_H

#include <stddef.h>

/* A (m x n, row-major, any m >= 1, n >= 1) = U diag(s) V'.  On return A holds
 * U diag(s) (column j = s[j] u_j; a zero column for s[j] = 0), s[0] >= s[1]
 * >= ... >= s[n-1] >= 0, and V (n x n, row-major: V[i*n + j] = component i of
 * the right singular vector j) is orthogonal.  Returns 0, or 1 when the
 * rotations did not converge in 60 sweeps (A, s, V then hold the last
 * iterate) or an input is NaN/infinite. */
int phc_jacobi_svd(double *A, size_t m, size_t n, double *s, double *V);

/* Minimum-norm least squares: x (n) minimising |A x - b| (A m x n, b an
 * m-vector), singular values <= rcond * s_max treated as zero (as LAPACK's
 * dgelsd); *rank gets the numerical rank.  A is overwritten; V (n x n) and
 * work (2 n) are work space.  Returns as phc_jacobi_svd. */
int phc_jacobi_lstsq(double *A, size_t m, size_t n, const double *b, double rcond, double *V, double *work,
                     double *x, size_t *rank);

#endif
