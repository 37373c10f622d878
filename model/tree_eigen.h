/* model/tree_eigen.h: all eigenvalues and eigenvectors of a symmetric matrix
 * whose off-diagonal non-zeros form a tree (diagonal plus one entry per
 * parent link), by Cuppen's divide and conquer on the tree.
 *
 * Cuppen 1981, "A divide and conquer method for the symmetric tridiagonal
 * eigenproblem", Numer. Math. 36:177-195, cuts a tridiagonal matrix at an
 * off-diagonal entry; the same cut works at any tree edge (i, j) with entry
 * rho = A(i,j): A = diag(A1, A2) + |rho| v v^T, v = e_i + sign(rho) e_j,
 * where A1, A2 are the two subtrees' matrices with |rho| subtracted from the
 * diagonal at i and at j.  The subtrees' eigen-systems are merged through
 * the secular equation with LAPACK's dlaed1 (deflation, Gu & Eisenstat 1994,
 * "A stable and efficient algorithm for the rank-one modification of the
 * symmetric eigenproblem", SIAM J. Matrix Anal. Appl. 15:1266-1276, for
 * orthogonal vectors; the merged vectors are one dgemm), after moving node
 * i's row to the end of the first block and node j's to the start of the
 * second (rows of the eigenvector block are nodes in any order).  Each cut
 * is the edge that splits the subtree's nodes most evenly; subtrees of at
 * most PHC_TREE_EIGEN_LEAF nodes are solved densely (dsyevd), and so are
 * subtrees without a cut that leaves >= 1/8 of them on either side (a node
 * with many children: a star is one dense problem).  No tridiagonalisation
 * and no back-transformation: O(n^2) memory, the flops of the merges only
 * (far fewer with deflation: 2000 nodes in 0.04 s for a path, 0.3 s for
 * random parents, against 0.6-0.9 s for dsyevd, one thread).
 *
 * Pure C, no I/O; LAPACK through the lazy forwarders
 * (measurements/lapack_lazy.c). */
#ifndef PHC_TREE_EIGEN_H
#define PHC_TREE_EIGEN_H

#include <stddef.h>

#include "model/status.h"

/* Subtrees of at most this many nodes are solved densely. */
#define PHC_TREE_EIGEN_LEAF 48

/* A (n x n, symmetric): A(k,k) = diag[k]; A(k, par[k]) = A(par[k], k) =
 * off[k] for k = 1..n-1 (par[k] < k: node 0 is the root and every parent
 * comes before its children; off[0] and par[0] are not read); all other
 * entries 0.  On success lambda (n) holds the eigenvalues ascending and Q
 * (n x n, column major, leading dimension n) the orthonormal eigenvectors:
 * column i, component k (node k) = Q[i*n + k].  Returns PHC_OK,
 * PHC_ERR_INVALID (a parent not before its child, a non-finite entry),
 * PHC_ERR_NOMEM or PHC_ERR_NUMERIC (LAPACK did not converge), with err set. */
int phc_tree_eigen(size_t n, const size_t *par, const double *diag, const double *off,
                   double *lambda, double *Q, phc_error *err);

#endif
