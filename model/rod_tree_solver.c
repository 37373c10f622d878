/* Block tree factorisation: see rod_tree_solver.h. */
#include "model/rod_tree_solver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

phc_rod_tree *phc_rod_tree_new(size_t n)
{
    phc_rod_tree *t = calloc(1, sizeof *t);
    if (!t)
        return NULL;
    t->n = n;
    t->parent = malloc(n * sizeof *t->parent);
    t->dim = calloc(n, sizeof *t->dim);
    t->order = calloc(n, sizeof *t->order);
    t->diag = calloc(144 * n, sizeof *t->diag);
    t->coup = calloc(72 * n, sizeof *t->coup);
    t->y = calloc(72 * n, sizeof *t->y);
    t->piv = calloc(12 * n, sizeof *t->piv);
    if (!t->parent || !t->dim || !t->order || !t->diag || !t->coup || !t->y || !t->piv) {
        phc_rod_tree_free(t);
        return NULL;
    }
    for (size_t i = 0; i < n; ++i)
        t->parent[i] = PHC_TREE_NONE;
    return t;
}

void phc_rod_tree_free(phc_rod_tree *t)
{
    if (!t)
        return;
    free(t->parent);
    free(t->dim);
    free(t->order);
    free(t->diag);
    free(t->coup);
    free(t->y);
    free(t->piv);
    free(t);
}

/* The elimination order is the reverse of a depth-first preorder in which
 * each node's children are visited in ascending index: every node comes
 * after all of its descendants (children before parents), and a chain of
 * consecutively numbered nodes (a branch of a plant graph, numbered parents
 * first) is swept as one run through memory, each node followed by its
 * parent.  The breadth-first order used before jumped between the levels of
 * the whole tree: on the 100,000-segment random tree each node's blocks
 * were a cache miss (README "Speed", "The elastic rods"). */
int phc_rod_tree_set_order(phc_rod_tree *t)
{
    size_t n = t->n, top = 0, done = 0;
    size_t *count = calloc(n + 1, sizeof *count), *kids = malloc((n ? n : 1) * sizeof *kids);
    size_t *stack = malloc((n ? n : 1) * sizeof *stack);
    int rc = 0;
    if (!count || !kids || !stack) {
        rc = -1;
        goto done;
    }
    for (size_t i = 0; i < n; ++i)
        if (t->parent[i] != PHC_TREE_NONE) {
            if (t->parent[i] >= n) {
                rc = -1;
                goto done;
            }
            ++count[t->parent[i] + 1];
        }
    for (size_t i = 0; i < n; ++i)
        count[i + 1] += count[i];
    {
        size_t *fill = malloc((n ? n : 1) * sizeof *fill);
        if (!fill) {
            rc = -1;
            goto done;
        }
        memcpy(fill, count, n * sizeof *fill);
        for (size_t i = 0; i < n; ++i) /* ascending within each parent */
            if (t->parent[i] != PHC_TREE_NONE)
                kids[fill[t->parent[i]]++] = i;
        free(fill);
    }
    /* roots pushed in descending index so the smallest is visited first;
     * every node is pushed once (a tree), so the stack never exceeds n */
    for (size_t i = n; i-- > 0;)
        if (t->parent[i] == PHC_TREE_NONE)
            stack[top++] = i;
    while (top > 0) {
        const size_t i = stack[--top];
        t->order[n - 1 - done++] = i; /* preorder, written from the back */
        for (size_t k = count[i + 1]; k-- > count[i];)
            stack[top++] = kids[k];
    }
    if (done != n) /* nodes unreachable from a root: a cycle */
        rc = -1;
done:
    free(count);
    free(kids);
    free(stack);
    return rc;
}

static inline int lu_inline(double *a, const int n, int *piv)
{
    for (int k = 0; k < n; ++k) {
        int p = k;
        double best = fabs(a[k * n + k]);
        for (int r = k + 1; r < n; ++r)
            if (fabs(a[r * n + k]) > best) {
                best = fabs(a[r * n + k]);
                p = r;
            }
        piv[k] = p;
        if (!(best > 0.0) || !isfinite(best))
            return -1;
        if (p != k)
            for (int c = 0; c < n; ++c) {
                const double tmp = a[k * n + c];
                a[k * n + c] = a[p * n + c];
                a[p * n + c] = tmp;
            }
        const double inv = 1.0 / a[k * n + k];
        for (int r = k + 1; r < n; ++r) {
            const double f = a[r * n + k] * inv;
            a[r * n + k] = f;
            if (f != 0.0)
                for (int c = k + 1; c < n; ++c)
                    a[r * n + c] -= f * a[k * n + c];
        }
    }
    return 0;
}

static inline void lu_solve_inline(const double *a, const int n, const int *piv, double *b)
{
    /* rows were swapped whole during the factorisation (the multipliers
     * too), so apply every swap first, then the unit lower triangle */
    for (int k = 0; k < n; ++k) {
        const int p = piv[k];
        if (p != k) {
            const double tmp = b[k];
            b[k] = b[p];
            b[p] = tmp;
        }
    }
    for (int k = 0; k < n; ++k)
        for (int r = k + 1; r < n; ++r)
            b[r] -= a[r * n + k] * b[k];
    for (int k = n - 1; k >= 0; --k) {
        double s = b[k];
        for (int c = k + 1; c < n; ++c)
            s -= a[k * n + c] * b[c];
        b[k] = s / a[k * n + k];
    }
}

int phc_dense_lu(double *a, int n, int *piv) { return lu_inline(a, n, piv); }

void phc_dense_lu_solve(const double *a, int n, const int *piv, double *b)
{
    lu_solve_inline(a, n, piv, b);
}

/* Solves with the LU factors of a (n x n) for the 6 columns of the n x 6
 * row-major matrix y at once (row operations 6 wide). */
static inline void lu_solve6_inline(const double *a, const int n, const int *piv, double *y)
{
    for (int k = 0; k < n; ++k) {
        const int p = piv[k];
        if (p != k)
            for (int c = 0; c < 6; ++c) {
                const double tmp = y[k * 6 + c];
                y[k * 6 + c] = y[p * 6 + c];
                y[p * 6 + c] = tmp;
            }
    }
    for (int k = 0; k < n; ++k)
        for (int r = k + 1; r < n; ++r) {
            const double f = a[r * n + k];
            for (int c = 0; c < 6; ++c)
                y[r * 6 + c] -= f * y[k * 6 + c];
        }
    for (int k = n - 1; k >= 0; --k) {
        for (int j = k + 1; j < n; ++j) {
            const double f = a[k * n + j];
            for (int c = 0; c < 6; ++c)
                y[k * 6 + c] -= f * y[j * 6 + c];
        }
        const double inv = 1.0 / a[k * n + k];
        for (int c = 0; c < 6; ++c)
            y[k * 6 + c] *= inv;
    }
}

/* the node sizes: 12 (paired) and 6 (free top of a loose part), as
 * compile-time constants so the loops unroll */
static int node_lu(double *a, int d, int *piv)
{
    return d == 12 ? lu_inline(a, 12, piv) : lu_inline(a, d, piv);
}

static void node_solve(const double *a, int d, const int *piv, double *b)
{
    if (d == 12)
        lu_solve_inline(a, 12, piv, b);
    else
        lu_solve_inline(a, d, piv, b);
}

static void node_solve6(const double *a, int d, const int *piv, double *y)
{
    if (d == 12)
        lu_solve6_inline(a, 12, piv, y);
    else
        lu_solve6_inline(a, d, piv, y);
}

/* ---- 12-nodes by block elimination on the constraint rows -------------
 *
 * A paired node's block is D = [[H, B], [J, C]] (6x6 blocks): H the body
 * block (updated by its children), B = Jᵀ, J the joint's Jacobian with
 * respect to this body, C = −diag(α) the compliance (Deul et al. 2018 §4;
 * rod.c assembles it so).  J is invertible for every intact joint
 * (rod_joint.h: [[±I, X], [0, ±(2/ℓ)G]], G invertible off the 180° bend),
 * while H and C may both be singular (statics: no mass; stretch rows: no
 * compliance), so the node is eliminated through J:
 *     J z + C λ = r2,  H z + B λ = r1
 *     ⇒  S λ = r1 − W r2,  z = J⁻¹ (r2 − C λ),  W = H J⁻¹,  S = B − W C,
 * with det D = ±det J det S: S is singular exactly when D is.  Stored in
 * the node's 144 doubles: J⁻¹ (36), W (36), LU(S) (36), diag C (6); the
 * pivots of S in piv[0..5], and piv[6] = BLOCK_MARK.  Only 6x6 kernels,
 * with fixed-size loops that unroll: on plant000 callgrind counts 47% fewer
 * instructions in the factorisation than with the pivoted 12x12 LU, and
 * 32% fewer in the solve (README "Speed", "The elastic rods").  When J is
 * singular or C is not diagonal (not a rods block) the node falls back to
 * the 12x12 LU. */
#define BLOCK_MARK (-7)
#define OFF_JINV 0
#define OFF_W 36
#define OFF_S 72
#define OFF_C 108

/* Inverse of a 6x6 (row-major) by Gauss–Jordan with partial pivoting, a is
 * destroyed.  0, or -1 when a pivot is zero or not finite. */
static int inv6(double *a, double *inv)
{
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
            inv[r * 6 + c] = (r == c) ? 1.0 : 0.0;
    for (int k = 0; k < 6; ++k) {
        int p = k;
        double best = fabs(a[k * 6 + k]);
        for (int r = k + 1; r < 6; ++r)
            if (fabs(a[r * 6 + k]) > best) {
                best = fabs(a[r * 6 + k]);
                p = r;
            }
        if (!(best > 0.0) || !isfinite(best))
            return -1;
        if (p != k)
            for (int c = 0; c < 6; ++c) {
                double t = a[k * 6 + c];
                a[k * 6 + c] = a[p * 6 + c];
                a[p * 6 + c] = t;
                t = inv[k * 6 + c];
                inv[k * 6 + c] = inv[p * 6 + c];
                inv[p * 6 + c] = t;
            }
        const double d = 1.0 / a[k * 6 + k];
        for (int c = 0; c < 6; ++c) {
            a[k * 6 + c] *= d;
            inv[k * 6 + c] *= d;
        }
        for (int r = 0; r < 6; ++r) {
            if (r == k)
                continue;
            const double f = a[r * 6 + k];
            if (f != 0.0)
                for (int c = 0; c < 6; ++c) {
                    a[r * 6 + c] -= f * a[k * 6 + c];
                    inv[r * 6 + c] -= f * inv[k * 6 + c];
                }
        }
    }
    return 0;
}

/* J⁻¹ of a rods joint Jacobian J = [[s I, X], [0, M]] (s = ±1; rod_joint.h)
 * as [[s I, −s X M⁻¹], [0, M⁻¹]], M⁻¹ by the adjugate: 0; 1 when J does not
 * have that structure or M is singular (then the caller inverts J by
 * Gauss–Jordan). */
static int inv_joint(const double *J, double *inv)
{
    const double s = J[0];
    if (s != 1.0 && s != -1.0)
        return 1;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (J[r * 6 + c] != (r == c ? s : 0.0) || J[(3 + r) * 6 + c] != 0.0)
                return 1;
    const double *m = J + 21; /* M[r][c] = m[r * 6 + c] */
    double a[9];
    a[0] = m[7] * m[14] - m[8] * m[13];
    a[1] = m[2] * m[13] - m[1] * m[14];
    a[2] = m[1] * m[8] - m[2] * m[7];
    a[3] = m[8] * m[12] - m[6] * m[14];
    a[4] = m[0] * m[14] - m[2] * m[12];
    a[5] = m[2] * m[6] - m[0] * m[8];
    a[6] = m[6] * m[13] - m[7] * m[12];
    a[7] = m[1] * m[12] - m[0] * m[13];
    a[8] = m[0] * m[7] - m[1] * m[6];
    const double det = m[0] * a[0] + m[1] * a[3] + m[2] * a[6];
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return 1;
    const double id = 1.0 / det;
    for (int k = 0; k < 9; ++k)
        a[k] *= id;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            inv[r * 6 + c] = (r == c) ? s : 0.0;
            inv[(3 + r) * 6 + c] = 0.0;
            inv[(3 + r) * 6 + 3 + c] = a[r * 3 + c];
            double x = 0.0;
            for (int k = 0; k < 3; ++k)
                x += J[r * 6 + 3 + k] * a[k * 3 + c];
            inv[r * 6 + 3 + c] = -s * x;
        }
    for (int k = 0; k < 36; ++k)
        if (!isfinite(inv[k]))
            return 1;
    return 0;
}

/* out = a b (6x6 row-major) */
static inline void mul6(const double *a, const double *b, double *out)
{
    for (int r = 0; r < 6; ++r) {
        double acc[6] = {0, 0, 0, 0, 0, 0};
        for (int k = 0; k < 6; ++k) {
            const double f = a[r * 6 + k];
            for (int c = 0; c < 6; ++c)
                acc[c] += f * b[k * 6 + c];
        }
        for (int c = 0; c < 6; ++c)
            out[r * 6 + c] = acc[c];
    }
}

/* out = a v (6x6, 6) */
static inline void mv6(const double *a, const double *v, double *out)
{
    for (int r = 0; r < 6; ++r) {
        double s = 0.0;
        for (int k = 0; k < 6; ++k)
            s += a[r * 6 + k] * v[k];
        out[r] = s;
    }
}

/* Factorises the packed 12x12 block `a` (stride 12) by block elimination
 * into F (144 doubles) and piv; 0, or -1 (then nothing is written). */
static int block_factor(const double *a, double *F, int *piv)
{
    double J[36], Jinv[36], H[36], W[36], S[36], C[6];
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) {
            if (r != c && a[(6 + r) * 12 + 6 + c] != 0.0)
                return -1; /* C not diagonal */
            J[r * 6 + c] = a[(6 + r) * 12 + c];
            H[r * 6 + c] = a[r * 12 + c];
        }
    for (int k = 0; k < 6; ++k)
        C[k] = a[(6 + k) * 12 + 6 + k];
    if (inv_joint(J, Jinv) != 0 && inv6(J, Jinv) != 0)
        return -1;
    mul6(H, Jinv, W);
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
            S[r * 6 + c] = a[r * 12 + 6 + c] - W[r * 6 + c] * C[c];
    int sp[6];
    if (lu_inline(S, 6, sp) != 0)
        return -1;
    memcpy(F + OFF_JINV, Jinv, sizeof Jinv);
    memcpy(F + OFF_W, W, sizeof W);
    memcpy(F + OFF_S, S, sizeof S);
    memcpy(F + OFF_C, C, sizeof C);
    memcpy(piv, sp, sizeof sp);
    piv[6] = BLOCK_MARK;
    return 0;
}

/* Solves with a block-factorised node: b (12) overwritten. */
static inline void block_solve(const double *F, const int *piv, double *b)
{
    double t[6], v[6];
    mv6(F + OFF_W, b + 6, t);
    for (int k = 0; k < 6; ++k)
        t[k] = b[k] - t[k];
    lu_solve_inline(F + OFF_S, 6, piv, t); /* λ */
    for (int k = 0; k < 6; ++k)
        v[k] = b[6 + k] - F[OFF_C + k] * t[k];
    mv6(F + OFF_JINV, v, b); /* z */
    memcpy(b + 6, t, sizeof t);
}

/* Y = D⁻¹ A for a block-factorised node, A and Y 12x6 row-major. */
static inline void block_solve6(const double *F, const int *piv, const double *A, double *Y)
{
    double T[36], V[36];
    const double *A1 = A, *A2 = A + 36;
    mul6(F + OFF_W, A2, T);
    for (int k = 0; k < 36; ++k)
        T[k] = A1[k] - T[k];
    lu_solve6_inline(F + OFF_S, 6, piv, T); /* Λ */
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
            V[r * 6 + c] = A2[r * 6 + c] - F[OFF_C + r] * T[r * 6 + c];
    mul6(F + OFF_JINV, V, Y); /* Z */
    memcpy(Y + 36, T, sizeof T);
}

/* 1 when the 6x6 m has a rods joint Jacobian's form [[±I, X], [0, M]]
 * (exact zeros and ones, as rod_joint.c writes them), else 0. */
static int joint_form(const double *m)
{
    const double s = m[0];
    if (s != 1.0 && s != -1.0)
        return 0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (m[r * 6 + c] != (r == c ? s : 0.0) || m[(3 + r) * 6 + c] != 0.0)
                return 0;
    return 1;
}

/* The rods' coupling block A (12x6): rows 0..5 the geometric stiffness
 * between the two bodies, non-zero only in rotation x rotation (3..5 x
 * 3..5); rows 6..11 the other body's joint Jacobian (joint_form).  With J⁻¹
 * in joint_form too, Y = D⁻¹A and the parent's update AᵀY skip the known
 * zeros (about 40% of those multiply–adds). */
static int coupling_form(const double *A)
{
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < (r < 3 ? 6 : 3); ++c)
            if (A[r * 6 + c] != 0.0)
                return 0;
    return joint_form(A + 36);
}

/* Y = D⁻¹ A (as block_solve6) and acc = Aᵀ Y, for A in coupling_form and
 * J⁻¹ in joint_form. */
static void block_update_structured(const double *F, const int *piv, const double *A, double *Y,
                                    double *acc)
{
    const double *W = F + OFF_W, *Ji = F + OFF_JINV, *C = F + OFF_C, *A1 = A, *A2 = A + 36;
    const double s2 = A2[0], s1 = Ji[0];
    double T[36], V[36];
    /* T = A1 − W A2 */
    for (int r = 0; r < 6; ++r) {
        for (int c = 0; c < 3; ++c)
            T[r * 6 + c] = -s2 * W[r * 6 + c];
        for (int c = 3; c < 6; ++c) {
            double x = A1[r * 6 + c];
            for (int k = 0; k < 6; ++k)
                x -= W[r * 6 + k] * A2[k * 6 + c];
            T[r * 6 + c] = x;
        }
    }
    lu_solve6_inline(F + OFF_S, 6, piv, T); /* Λ */
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
            V[r * 6 + c] = A2[r * 6 + c] - C[r] * T[r * 6 + c];
    /* Z = J⁻¹ V, J⁻¹ = [[s1 I, X1], [0, M1]] */
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) {
            double z = r < 3 ? s1 * V[r * 6 + c] : 0.0;
            for (int k = 3; k < 6; ++k)
                z += Ji[r * 6 + k] * V[k * 6 + c];
            Y[r * 6 + c] = z;
        }
    memcpy(Y + 36, T, sizeof T);
    /* acc = A1ᵀ Z + A2ᵀ Λ */
    for (int c = 0; c < 6; ++c) {
        for (int r = 0; r < 3; ++r)
            acc[r * 6 + c] = s2 * T[r * 6 + c];
        for (int r = 3; r < 6; ++r) {
            double x = 0.0;
            for (int k = 3; k < 6; ++k)
                x += A1[k * 6 + r] * Y[k * 6 + c];
            for (int k = 0; k < 6; ++k)
                x += A2[k * 6 + r] * T[k * 6 + c];
            acc[r * 6 + c] = x;
        }
    }
}

/* The node's d x d block lives in diag with stride 12: 12-nodes are
 * eliminated by blocks when they can be, otherwise (and 6-nodes) copied to
 * a packed d x d buffer for the LU.  Factorises node i (its children done)
 * and updates its parent's body block: 0, or -1 when the block is
 * singular. */
static inline int factor_node(phc_rod_tree *t, const size_t i)
{
    const int d = t->dim[i];
    if (d == 0)
        return 0;
    double *D = t->diag + 144 * i, packed[144];
    int *piv = t->piv + 12 * i;
    int blocked = 0;
    if (d == 12 && block_factor(D, packed, piv) == 0) {
        memcpy(D, packed, 114 * sizeof *D);
        blocked = 1;
    } else {
        for (int r = 0; r < d; ++r)
            for (int c = 0; c < d; ++c)
                packed[r * d + c] = D[r * 12 + c];
        if (node_lu(packed, d, piv) != 0)
            return -1;
        memcpy(D, packed, (size_t)(d * d) * sizeof *D); /* packed d x d from here on */
    }
    const size_t p = t->parent[i];
    if (p == PHC_TREE_NONE || t->dim[p] == 0)
        return 0;
    /* Y = D⁻¹ A (d x 6); parent body block −= Aᵀ Y */
    const double *A = t->coup + 72 * i;
    double *Y = t->y + 72 * i;
    double *P = t->diag + 144 * p;
    double acc[36] = {0};
    if (blocked && joint_form(D + OFF_JINV) && coupling_form(A)) {
        block_update_structured(D, piv, A, Y, acc);
    } else {
        if (blocked) {
            block_solve6(D, piv, A, Y);
        } else {
            memcpy(Y, A, (size_t)(d * 6) * sizeof *Y);
            node_solve6(D, d, piv, Y);
        }
        for (int k = 0; k < d; ++k)
            for (int r = 0; r < 6; ++r) {
                const double f = A[k * 6 + r];
                if (f != 0.0)
                    for (int c = 0; c < 6; ++c)
                        acc[r * 6 + c] += f * Y[k * 6 + c];
            }
    }
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
            P[r * 12 + c] -= acc[r * 6 + c];
    return 0;
}

/* Forward substitution at node i (its children done): y_i = D_i⁻¹ r_i,
 * r_p −= A_iᵀ y_i. */
static inline void forward_node(const phc_rod_tree *t, const size_t i, double *rhs)
{
    const int d = t->dim[i];
    if (d == 0)
        return;
    double *r = rhs + 12 * i;
    if (d == 12 && t->piv[12 * i + 6] == BLOCK_MARK)
        block_solve(t->diag + 144 * i, t->piv + 12 * i, r);
    else
        node_solve(t->diag + 144 * i, d, t->piv + 12 * i, r);
    const size_t p = t->parent[i];
    if (p != PHC_TREE_NONE && t->dim[p] != 0) {
        const double *A = t->coup + 72 * i;
        double *rp = rhs + 12 * p;
        for (int c = 0; c < 6; ++c) {
            double s = 0.0;
            for (int k = 0; k < d; ++k)
                s += A[k * 6 + c] * r[k];
            rp[c] -= s;
        }
    }
}

/* Back substitution (parents first): u_i = y_i − Y_i u_p. */
static void backward(const phc_rod_tree *t, double *rhs)
{
    for (size_t o = t->n; o-- > 0;) {
        const size_t i = t->order[o];
        const int d = t->dim[i];
        const size_t p = t->parent[i];
        if (d == 0 || p == PHC_TREE_NONE || t->dim[p] == 0)
            continue;
        const double *Y = t->y + 72 * i, *up = rhs + 12 * p;
        double *u = rhs + 12 * i;
        for (int k = 0; k < d; ++k) {
            double s = 0.0;
            for (int c = 0; c < 6; ++c)
                s += Y[k * 6 + c] * up[c];
            u[k] -= s;
        }
    }
}

size_t phc_rod_tree_factor(phc_rod_tree *t)
{
    for (size_t o = 0; o < t->n; ++o) {
        const size_t i = t->order[o];
        if (factor_node(t, i) != 0)
            return i;
    }
    return PHC_TREE_NONE;
}

size_t phc_rod_tree_factor_solve(phc_rod_tree *t, double *rhs)
{
    /* the node's factors and blocks are still in the cache when its
     * forward step reads them */
    for (size_t o = 0; o < t->n; ++o) {
        const size_t i = t->order[o];
        if (factor_node(t, i) != 0)
            return i;
        forward_node(t, i, rhs);
    }
    backward(t, rhs);
    return PHC_TREE_NONE;
}

void phc_rod_tree_solve(const phc_rod_tree *t, double *rhs)
{
    for (size_t o = 0; o < t->n; ++o)
        forward_node(t, t->order[o], rhs);
    backward(t, rhs);
}
