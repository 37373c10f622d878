/* Symmetric eigenproblem of a tree-structured matrix by divide and conquer:
 * see tree_eigen.h.  Pure C: no I/O, no printing, no globals.
 *
 * Layout (as LAPACK's dlaed0 for a tridiagonal matrix): every subproblem
 * of the recursion owns a contiguous range [start, start + m) of rows and
 * columns of one n x n work matrix; a cut puts the first subtree at
 * [start, start + m1) and the second after it, so the block-diagonal
 * eigenvector matrix that dlaed1 merges is already in place.  ord[r] is the
 * node of row r (rows move only inside their block, at the merges). */
#include "model/tree_eigen.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* LAPACK's merge step of divide and conquer, reference LAPACK dlaed1.f
 * (lapack.h does not declare it; Fortran calling convention, lapack_int
 * integers): d (n), q (ldq x n), indxq (n), work, iwork (4n).
 * Forwarded by measurements/lapack_lazy.c with the same prototype. */
void dlaed1_(const lapack_int *n, double *d, double *q, const lapack_int *ldq, lapack_int *indxq,
             const double *rho, const lapack_int *cutpnt, double *work, lapack_int *iwork,
             lapack_int *info);

/* A cut must leave at least 1/SMALLEST_PART of its block's nodes on the
 * smaller side, else the block is solved densely: a node with many
 * children offers only uneven cuts, and peeling them off one by one would
 * cost a merge of the whole block per child (a star of 2000 nodes took
 * 162 s, against 0.9 s for dsyevd). */
#define SMALLEST_PART 8

typedef struct {
    size_t start, m1, m; /* block [start, start+m), first part m1 rows */
    size_t i, j;         /* cut edge: node i in the first part, j in the second */
    double rho;          /* A(i,j) (scaled) */
} tree_cut;

typedef struct {
    size_t start, m;
} tree_block;

/* Splits the connected node set list[0..m) (ascending, so its top node is
 * list[0] and every other node's parent is in the set) at the edge
 * (par[c], c) whose lower part (the subtree of c) has the size closest to
 * m/2.  On return list holds the smaller part first (dlaed1 wants the first
 * part <= m/2), each part ascending; *m1 is its size, *i its end of the cut
 * edge and *j the other end.  sz, flag: node-indexed work (values for the
 * set's nodes are overwritten); tmp: m. */
static void split_at_centroid_edge(size_t *list, size_t m, const size_t *par, size_t *sz,
                                   unsigned char *flag, size_t *tmp, size_t *m1, size_t *i,
                                   size_t *j)
{
    for (size_t r = 0; r < m; ++r)
        sz[list[r]] = 1;
    for (size_t r = m - 1; r >= 1; --r)
        sz[par[list[r]]] += sz[list[r]];
    size_t c = list[1], gap = (size_t)-1;
    for (size_t r = 1; r < m; ++r) {
        size_t s = sz[list[r]], g = 2 * s > m ? 2 * s - m : m - 2 * s;
        if (g < gap) {
            gap = g;
            c = list[r];
        }
    }
    /* flag = 1 on the subtree of c (parents come first in list) */
    flag[list[0]] = 0;
    for (size_t r = 1; r < m; ++r)
        flag[list[r]] = list[r] == c || flag[par[list[r]]];
    unsigned char first = 2 * sz[c] <= m; /* the subtree of c goes first */
    size_t a = 0, b = 0;
    for (size_t r = 0; r < m; ++r) {
        if (flag[list[r]] == first)
            list[a++] = list[r];
        else
            tmp[b++] = list[r];
    }
    memcpy(list + a, tmp, b * sizeof *tmp);
    *m1 = a;
    *i = first ? c : par[c];
    *j = first ? par[c] : c;
}

/* Swaps rows r and s of Q (leading dimension n) in columns [c0, c1). */
static void swap_rows(double *Q, size_t n, size_t r, size_t s, size_t c0, size_t c1, size_t *ord,
                      size_t *pos)
{
    if (r == s)
        return;
    for (size_t c = c0; c < c1; ++c) {
        double t = Q[c * n + r];
        Q[c * n + r] = Q[c * n + s];
        Q[c * n + s] = t;
    }
    size_t t = ord[r];
    ord[r] = ord[s];
    ord[s] = t;
    pos[ord[r]] = r;
    pos[ord[s]] = s;
}

int phc_tree_eigen(size_t n, const size_t *par, const double *diag, const double *off,
                   double *lambda, double *Q, phc_error *err)
{
    if (n == 0)
        return PHC_OK;
    if (n > (size_t)1 << 30)
        return phc_error_set(err, PHC_ERR_INVALID, "tree eigensolver: %zu nodes is too many", n);
    double scale = 0.0;
    for (size_t k = 0; k < n; ++k) {
        if (k > 0 && par[k] >= k)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "tree eigensolver: node %zu has parent %zu, not before it", k,
                                 par[k]);
        if (!isfinite(diag[k]) || (k > 0 && !isfinite(off[k])))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "tree eigensolver: entry of node %zu is not finite", k);
        scale = fmax(scale, fabs(diag[k]));
        if (k > 0)
            scale = fmax(scale, fabs(off[k]));
    }
    if (scale == 0.0)
        scale = 1.0;

    int rc = PHC_OK;
    size_t *ord = malloc(n * sizeof *ord), *pos = malloc(n * sizeof *pos);
    size_t *sz = malloc(n * sizeof *sz), *tmp = malloc(n * sizeof *tmp);
    unsigned char *flag = malloc(n);
    double *d = malloc(n * sizeof *d), *D = malloc(n * sizeof *D);
    tree_cut *cuts = malloc(n * sizeof *cuts);
    tree_block *blocks = malloc(n * sizeof *blocks), *todo = malloc(n * sizeof *todo);
    lapack_int *indxq = malloc(n * sizeof *indxq), *iwork = malloc(4 * n * sizeof *iwork);
    /* dlaed1's work: 4n, the packed block vectors (n1 n12 + n2 n23 <= n^2)
     * and the secular vectors (max(n12, n23) k <= n^2); its documented
     * 4n + n^2 holds for halves of equal size only. */
    double *work = malloc((4 * n + 2 * n * n) * sizeof *work);
    if (!ord || !pos || !sz || !tmp || !flag || !d || !D || !cuts || !blocks || !todo || !indxq ||
        !iwork || !work) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "tree eigensolver: out of memory for %zu nodes", n);
        goto done;
    }
    for (size_t k = 0; k < n; ++k) {
        ord[k] = k;
        d[k] = diag[k] / scale;
    }

    /* Cut until every block has at most PHC_TREE_EIGEN_LEAF nodes.  The cut
     * |rho| v v^T with v = e_i + sign(rho) e_j leaves |rho| subtracted from
     * the diagonal at i and j (dlaed1's convention: rho signed). */
    size_t ncuts = 0, nblocks = 0, ntodo = 0;
    todo[ntodo++] = (tree_block){0, n};
    while (ntodo > 0) {
        tree_block t = todo[--ntodo];
        if (t.m <= PHC_TREE_EIGEN_LEAF) {
            blocks[nblocks++] = t;
            continue;
        }
        size_t m1, i, j;
        split_at_centroid_edge(ord + t.start, t.m, par, sz, flag, tmp, &m1, &i, &j);
        if (m1 * SMALLEST_PART < t.m) { /* no even cut (a star): dense */
            blocks[nblocks++] = t;
            continue;
        }
        double rho = off[i > j ? i : j] / scale; /* the edge's child end holds it */
        d[i] -= fabs(rho);
        d[j] -= fabs(rho);
        cuts[ncuts++] = (tree_cut){t.start, m1, t.m, i, j, rho};
        todo[ntodo++] = (tree_block){t.start, m1};
        todo[ntodo++] = (tree_block){t.start + m1, t.m - m1};
    }
    for (size_t r = 0; r < n; ++r)
        pos[ord[r]] = r;

    /* Leaves: dense eigen-decomposition into their diagonal block. */
    memset(Q, 0, n * n * sizeof *Q);
    for (size_t b = 0; b < nblocks; ++b) {
        size_t s = blocks[b].start, m = blocks[b].m;
        double *B = work; /* m x m */
        memset(B, 0, m * m * sizeof *B);
        for (size_t r = 0; r < m; ++r) {
            size_t k = ord[s + r];
            B[r * m + r] = d[k];
            if (k > 0 && pos[par[k]] >= s && pos[par[k]] < s + m) {
                size_t q = pos[par[k]] - s;
                B[q * m + r] = off[k] / scale;
                B[r * m + q] = off[k] / scale;
            }
        }
        if (LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'L', (lapack_int)m, B, (lapack_int)m, D + s) != 0) {
            rc = phc_error_set(err, PHC_ERR_NUMERIC,
                               "tree eigensolver: dsyevd did not converge on a block of %zu nodes", m);
            goto done;
        }
        for (size_t c = 0; c < m; ++c) {
            memcpy(Q + (s + c) * n + s, B + c * m, m * sizeof *B);
            indxq[s + c] = (lapack_int)c + 1;
        }
    }

    /* Merges, children before parents (reverse order of the cuts). */
    for (size_t q = ncuts; q-- > 0;) {
        const tree_cut *t = &cuts[q];
        size_t s = t->start, e1 = t->start + t->m1, e = t->start + t->m;
        swap_rows(Q, n, pos[t->i], e1 - 1, s, e1, ord, pos);
        swap_rows(Q, n, pos[t->j], e1, e1, e, ord, pos);
        lapack_int mm = (lapack_int)t->m, ld = (lapack_int)n, cut = (lapack_int)t->m1, info = 0;
        dlaed1_(&mm, D + s, Q + s * n + s, &ld, indxq + s, &t->rho, &cut, work, iwork, &info);
        if (info != 0) {
            rc = phc_error_set(err, PHC_ERR_NUMERIC,
                               "tree eigensolver: the secular equation did not converge "
                               "(dlaed1 info %d) merging %zu nodes", (int)info, t->m);
            goto done;
        }
    }

    /* Sort (indxq) and put rows back in node order. */
    memcpy(work, Q, n * n * sizeof *Q);
    for (size_t c = 0; c < n; ++c) {
        size_t src = (size_t)indxq[c] - 1;
        lambda[c] = D[src] * scale;
        const double *from = work + src * n;
        double *to = Q + c * n;
        for (size_t r = 0; r < n; ++r)
            to[ord[r]] = from[r];
    }
done:
    free(ord);
    free(pos);
    free(sz);
    free(tmp);
    free(flag);
    free(d);
    free(D);
    free(cuts);
    free(blocks);
    free(todo);
    free(indxq);
    free(iwork);
    free(work);
    return rc;
}
