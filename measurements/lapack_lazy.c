/* The LAPACKE and CBLAS functions libphytocal calls (model/water.c,
 * tree_eigen.c, water_balance.c, particles.c, rod.c; the fit analysis uses
 * model/jacobi_svd instead), forwarded to liblapacke and OpenBLAS opened on first use
 * (measurements/lazy_library_internal.h): a run that solves no eigen- or
 * singular-value problem never loads them (nor the reference LAPACK,
 * gfortran and quadmath behind them).  Prototypes: lapacke.h and
 * OpenBLAS's cblas.h. */
#include <cblas.h>
#include <lapacke.h>

#include "measurements/lazy_library_internal.h"

PHC_LAZY_FORWARD(phc_lazy_lapack, lapack_int, LAPACKE_dgesvd,
                 (int layout, char jobu, char jobvt, lapack_int m, lapack_int n, double *a, lapack_int lda,
                  double *s, double *u, lapack_int ldu, double *vt, lapack_int ldvt, double *superb),
                 (layout, jobu, jobvt, m, n, a, lda, s, u, ldu, vt, ldvt, superb))
PHC_LAZY_FORWARD(phc_lazy_lapack, lapack_int, LAPACKE_dsyevd,
                 (int layout, char jobz, char uplo, lapack_int n, double *a, lapack_int lda, double *w),
                 (layout, jobz, uplo, n, a, lda, w))

PHC_LAZY_FORWARD(phc_lazy_blas, double, cblas_ddot,
                 (OPENBLAS_CONST blasint n, OPENBLAS_CONST double *x, OPENBLAS_CONST blasint incx,
                  OPENBLAS_CONST double *y, OPENBLAS_CONST blasint incy),
                 (n, x, incx, y, incy))
PHC_LAZY_FORWARD_VOID(phc_lazy_blas, cblas_dgemm,
                      (OPENBLAS_CONST enum CBLAS_ORDER order, OPENBLAS_CONST enum CBLAS_TRANSPOSE ta,
                       OPENBLAS_CONST enum CBLAS_TRANSPOSE tb, OPENBLAS_CONST blasint m,
                       OPENBLAS_CONST blasint n, OPENBLAS_CONST blasint k, OPENBLAS_CONST double alpha,
                       OPENBLAS_CONST double *a, OPENBLAS_CONST blasint lda, OPENBLAS_CONST double *b,
                       OPENBLAS_CONST blasint ldb, OPENBLAS_CONST double beta, double *c,
                       OPENBLAS_CONST blasint ldc),
                      (order, ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc))
PHC_LAZY_FORWARD_VOID(phc_lazy_blas, cblas_dgemv,
                      (OPENBLAS_CONST enum CBLAS_ORDER order, OPENBLAS_CONST enum CBLAS_TRANSPOSE trans,
                       OPENBLAS_CONST blasint m, OPENBLAS_CONST blasint n, OPENBLAS_CONST double alpha,
                       OPENBLAS_CONST double *a, OPENBLAS_CONST blasint lda, OPENBLAS_CONST double *x,
                       OPENBLAS_CONST blasint incx, OPENBLAS_CONST double beta, double *y,
                       OPENBLAS_CONST blasint incy),
                      (order, trans, m, n, alpha, a, lda, x, incx, beta, y, incy))

/* LAPACK's divide-and-conquer merge (model/tree_eigen.c); not in lapack.h,
 * so declared here with model/tree_eigen.c's prototype.  liblapacke's
 * handle reaches it through its dependency liblapack. */
void dlaed1_(const lapack_int *n, double *d, double *q, const lapack_int *ldq, lapack_int *indxq,
             const double *rho, const lapack_int *cutpnt, double *work, lapack_int *iwork,
             lapack_int *info);
PHC_LAZY_FORWARD_VOID(phc_lazy_lapack, dlaed1_,
                      (const lapack_int *n, double *d, double *q, const lapack_int *ldq,
                       lapack_int *indxq, const double *rho, const lapack_int *cutpnt, double *work,
                       lapack_int *iwork, lapack_int *info),
                      (n, d, q, ldq, indxq, rho, cutpnt, work, iwork, info))
