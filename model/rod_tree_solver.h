/* Block tree factorisation without fill-in (Baraff 1996, "Linear-time
 * dynamics using Lagrange multipliers"; Deul et al. 2018 §4): the direct
 * solver of the elastic rods (model/rod.h).
 *
 * The system is symmetric with one node per body.  A node holds the body's 6
 * unknowns z = (Δx, δθ) and, when the body is paired with the joint towards
 * its elimination parent, that joint's 6 multipliers: dim 12 (paired), 6
 * (a free body with no parent joint) or 0 (a fixed body that roots its tree:
 * no unknowns).  The only off-diagonal blocks couple a node with the 6 body
 * unknowns of its parent node (coupling: dim × 6, the block A[node, parent
 * body]; A[parent body, node] is its transpose).  Eliminating nodes leaves
 * first touches only the parent's 6x6 body block, so there is no fill-in
 * and factor + solve cost O(n).  A 12-node whose block has the rods' form
 * [[H, B], [J, C]] (C diagonal, J invertible) is eliminated through J with
 * 6x6 kernels (rod_tree_solver.c); any other node by dense LU with partial
 * pivoting.  The caller fills diag (12x12 row-major, stride 12) and coupling
 * (12x6 row-major) per node.  Pure C, no I/O, no allocation after _new. */
#ifndef PHC_ROD_TREE_SOLVER_H
#define PHC_ROD_TREE_SOLVER_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PHC_TREE_NONE ((size_t)-1)

typedef struct phc_rod_tree {
    size_t n;        /* nodes */
    size_t *parent;  /* n: elimination parent node or PHC_TREE_NONE */
    int *dim;        /* n: 0, 6 or 12 */
    size_t *order;   /* n: children before parents (leaves first) */
    double *diag;    /* 144 n: the node blocks; factorised in place (layout of
                        the factors: rod_tree_solver.c) */
    double *coup;    /* 72 n: A[node, parent body] (A[parent body, node] = Aᵀ) */
    double *y;       /* 72 n: D⁻¹A after factor */
    int *piv;        /* 12 n: LU pivots (and the block-elimination mark) */
} phc_rod_tree;

/* Allocates a tree of n nodes (arrays zeroed, parent PHC_TREE_NONE, dim 0);
 * NULL when out of memory. */
phc_rod_tree *phc_rod_tree_new(size_t n);
void phc_rod_tree_free(phc_rod_tree *t); /* accepts NULL */

/* Builds order[] from parent[] (every parent chain must end at a node with
 * parent PHC_TREE_NONE).  Returns 0, or -1 when parent[] has a cycle. */
int phc_rod_tree_set_order(phc_rod_tree *t);

/* The node blocks need not be symmetric (the off-diagonal pairs are
 * transposes of each other).  Factorises in place.  Returns PHC_TREE_NONE on success, otherwise the node
 * whose (updated) block is singular or not finite. */
size_t phc_rod_tree_factor(phc_rod_tree *t);

/* phc_rod_tree_factor and phc_rod_tree_solve in one sweep: each node's
 * forward substitution runs right after its factorisation, while its
 * blocks are in the cache (the same operations in the same order, so the
 * same result to the last bit).  rhs (12 per node) is overwritten by u;
 * on failure (returns as phc_rod_tree_factor) it is left partly
 * transformed. */
size_t phc_rod_tree_factor_solve(phc_rod_tree *t, double *rhs);

/* Solves A u = rhs in place after phc_rod_tree_factor.  rhs/u: 12 entries
 * per node (entries beyond dim unused). */
void phc_rod_tree_solve(const phc_rod_tree *t, double *rhs);

/* Dense LU with partial pivoting of the n x n row-major matrix a (n <= any),
 * in place: returns 0, or -1 when a pivot is zero or not finite. */
int phc_dense_lu(double *a, int n, int *piv);
/* Solves with the factors of phc_dense_lu; b (n) overwritten. */
void phc_dense_lu_solve(const double *a, int n, const int *piv, double *b);

#ifdef __cplusplus
}
#endif

#endif /* PHC_ROD_TREE_SOLVER_H */
