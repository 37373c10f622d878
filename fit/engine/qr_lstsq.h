/* fit/engine/qr_lstsq.h: linear least squares min |A x - b| for a tall
 * matrix (m rows >= n columns) by Householder QR followed by the one-sided
 * Jacobi SVD of the n x n triangle (model/jacobi_svd.h).
 *
 * A = Q R with Q (m x n) orthonormal columns, so |A x - b|^2 =
 * |R x - Q'b|^2 + |(I - QQ')b|^2: the minimum-norm least-squares solution,
 * the singular values and hence the numerical rank of A are those of R with
 * the right-hand side Q'b (Golub & Van Loan, Matrix Computations, 4th ed.,
 * sections 5.2 and 5.3; QR before a one-sided Jacobi SVD: Drmac & Veselic
 * 2008, "New fast and accurate Jacobi SVD algorithm I", SIAM J. Matrix Anal.
 * Appl. 29:1322-1342).  Householder QR is column-wise backward stable, so a
 * column-scaled A keeps its accuracy.  Cost: 2 m n^2 flops for the QR and a
 * Jacobi SVD of n rows instead of m: for a Jacobian of 250 rows and 8
 * parameters about a tenth of phc_jacobi_lstsq on A.  Pure C, no
 * allocation. */
#ifndef PHC_QR_LSTSQ_H
#define PHC_QR_LSTSQ_H

#include <stddef.h>

/* Householder QR of A (m x n row-major, m >= n >= 1): R (n x n, zero below
 * the diagonal) with A = Q R, and c (m values, or NULL) replaced by Q'c
 * (full m x m Q; its first n values are the least-squares right-hand side).
 * A is overwritten.  Returns 0, 1 for a NaN/infinite entry, 2 when m < n.
 * R has A's singular values and right singular vectors. */
int phc_qr_triangle(double *A, size_t m, size_t n, double *c, double *R);

/* x (n) minimising |A x - b| (A m x n row-major, m >= n >= 1; b m values),
 * singular values <= rcond * s_max treated as zero as phc_jacobi_lstsq;
 * *rank gets the numerical rank.  A is overwritten; work holds
 * m + 2 n^2 + 2 n doubles.  Returns 0, 1 as phc_jacobi_lstsq (no
 * convergence, or a NaN/infinite input), 2 when m < n. */
int phc_qr_lstsq(double *A, size_t m, size_t n, const double *b, double rcond, double *work, double *x,
                 size_t *rank);

/* Work-space size in doubles for phc_qr_lstsq. */
size_t phc_qr_lstsq_work(size_t m, size_t n);

#endif
