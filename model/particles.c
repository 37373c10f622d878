/* Oriented particles with generalized shape matching (climbing plants §4.1,
 * §4.3; Müller & Chentanez 2011).  See particles.h for the model, the
 * choices made where the paper is terse, and the units. */
#include "model/particles.h"
#include "model/quaternion.h"
#include "model/particles_joint_lanes.h"
#include "model/trig_inline.h"

#include <lapacke.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Fewer particles than this run their group loops on one thread: a fork
 * and join of the OpenMP team costs more than a small plant's whole
 * projection (a 20-particle stalk stepped thousands of times in a shape
 * fit was 80x slower with the loops always parallel). */
#ifndef PHC_PARTICLES_PARALLEL_MIN
#define PHC_PARTICLES_PARALLEL_MIN 1024
#endif

/* Whether a loop over n particles or groups forks a team: only for large
 * plants and outside any enclosing OpenMP region (a nested region, even one
 * serialised by an `if` clause, costs futex calls on every entry). */
static int team(long n) { return n >= PHC_PARTICLES_PARALLEL_MIN && omp_get_level() == 0; }

/* pi to double precision (M_PI is not ISO C). */
static const double PI = 3.14159265358979323846;

struct phc_particles {
    size_t n;
    size_t cap;              /* particles the arrays hold (>= n) */
    int layout_dirty;        /* 1 after an append: children and slots to rebuild */
    int no_stress;           /* 1: skip the stress pass when nothing breaks */
    phc_particles_closest_fn collide; /* supports, NULL: none */
    void *collide_user;
    phc_particles_segment_fn collide_segment; /* exact segment push, NULL: none */
    void *collide_segment_user;
    size_t pushed;           /* particles pushed out in the last step */
    double depth;            /* smallest δ − r before the pushes, m */
    /* Closest-point queries the collision pass skips (exact, see
     * phc_particles_collide_all): per particle six points (centre, end
     * x − h·axis, end x + h·axis of the first round; the same of the later
     * rounds: the centre pushed again, the ends), each its last queried
     * point x₀, the unsigned distance d₀ (m) from it to the supports when
     * it was in front (0 otherwise: no skip by distance), the answer c, n,
     * 1 (0: nothing known) and d₀ less the skip margin (0: no skip), 12
     * doubles each: reach[72i + 12s ..].  Facts
     * about points, not particles: kept while the collider is the same;
     * particles reach_n .. n−1 (appended since) start with 0.  skip:
     * scratch of the round-0 points skipped by distance (5 doubles: the
     * point, its radius, a lower bound of its δ − r). */
    double *reach, *skip;
    size_t reach_cap, reach_n;
    int collide_all;         /* 1: every query made (phc_particles_collide_all) */
    int supports_closed;     /* 1: skips by distance too (phc_particles_supports_closed) */
    size_t queries, skipped; /* closest-point queries made and skipped since creation */
    phc_particles_options o;
    double *x, *v, *xp;      /* 3n: position, velocity, predicted position (m, m/s) */
    double *x0;              /* 3n: rest position (m) */
    double *q, *qp, *q0;     /* 4n: orientation, predicted, rest */
    double *w;               /* 3n: angular velocity (rad/s) */
    double *m;               /* n: kg */
    double *ax;              /* 3n: ellipsoid radii (r, r, L/2), m */
    double *age;             /* n: s */
    /* The step's new velocities, angular velocities and ages, computed
     * with its new state and swapped in (with x ↔ xp, q ↔ qp) when the
     * whole step succeeded: nothing is copied back, nothing changes on a
     * failure. */
    double *vn, *wn, *agen;  /* 3n, 3n, n */
    double *s;               /* n: own stiffness (used when maturity_age == 0) */
    double *f;               /* 3n: external force, N */
    unsigned char *anchored, *hold_q;
    double *anchor_at;       /* 3n */
    double *anchor_k;        /* n */
    double *anchor_q;        /* 4n */
    size_t *parent;          /* n: parent from the graph */
    unsigned char *linked;   /* n: 1 while i is linked to its parent */
    size_t *child_start, *child; /* children (CSR, in index order) */
    size_t *topo;            /* n: every particle after its parent (roots first) */
    /* The joint pass's order (follow_parents), rebuilt after a change of
     * the parents: the top of the tree (particles whose subtree holds more
     * than a share of all) in topological order, follow_order[0 ..
     * follow_top), then whole subtrees hanging from it, item t being
     * follow_order[follow_start[t] .. follow_start[t + 1]) in preorder. */
    int follow_dirty;
    size_t follow_top, follow_items;
    size_t *follow_order;    /* n */
    size_t *follow_start;    /* n + 1 */
    size_t *subtree;         /* n: subtree sizes (scratch of the order) */
    /* The same top and items, each sorted by depth inside it (parents at
     * a smaller depth), lane_level[t] the depth of lane_order[t]: the
     * links of one depth wait for none of each other, and the own-weight
     * pass runs them four at a time (follow_lanes); lanes_off: one at a
     * time (phc_particles_joint_lanes). */
    size_t *lane_order;      /* n */
    size_t *lane_level;      /* n */
    int lanes_off;
    size_t *fstack;          /* n: depth-first stack (scratch of the order) */
    /* The projections that can change the result (plan_projections): the
     * particles to blend at iteration t are plist[0 .. pcount[t]) (t = 0:
     * to predict), the groups to match gmatch[0 .. gcount[t]), t = 1 .. N;
     * plist = NULL: all of them. */
    int project_all;         /* 1: every projection (phc_particles_project_all) */
    size_t *plist, *gmatch;  /* n each */
    int *plev, *glev;        /* n each: the last iteration a particle / group is needed at, -1 */
    size_t *pcount, *gcount; /* iterations + 1 each */
    int use_lists;
    size_t *pins, npins;     /* n: the pinned particles (k_a = 1, orientation held) */
    double *gq;              /* 4n: last rotation of each group (warm start) */
    double *stress;          /* n: group stress after the last step */
    long *source_id;         /* n: segment ids for messages */
    size_t *child_index;     /* n: position of i among its parent's children */
    double *ell0;            /* 9n: D_j R̄_jᵀ / 5 (kg-free ellipsoid term, m²) */
    /* The joint pass's rest terms of linked particle i (follow_one): j_i =
     * R(q̄_u)ᵀ (h̄_i − x̄_u) and q̄_u⁻¹ q̄_i, u its parent, kept while neither
     * rest changes: joint[7i .. 7i+7) was made at step joint_epoch[i],
     * valid while that is later than rest_epoch[i] and rest_epoch[u] (the
     * epoch of their last rest change; epoch counts the steps). */
    double *joint;           /* 7n */
    /* bending = BEAM: each particle's articulated-body terms (BEAM_PER
     * doubles, see beam_articulate), allocated at the first beam step. */
    double *beam;
    size_t beam_cap;
    size_t *joint_epoch, *rest_epoch; /* n each */
    size_t epoch;
    unsigned char *ell0_stale; /* n: 1 when ell0 awaits its rest change (made when next
                                  needed: a climbing plant's growing tips change their rest
                                  every step, and nothing matches their groups) */
    double *ell;             /* 9n: R_j D_j R̄_jᵀ / 5 of the orientations being matched (m²) */
    /* Group slots: group k owns slots goff[k] .. goff[k+1]−1: slot 0 = k,
     * slot 1 = its parent, slot 2 + c = its c-th child; a slot whose link
     * is broken has μ = 0.  Each group writes only its own slots, so the
     * groups can be matched in parallel and the blend gathers them in a
     * fixed order (the same sums for any thread count). */
    size_t *goff;            /* n + 1 */
    size_t *mem;             /* slots: member particle */
    double *mu, *goal;       /* slots: μ_jk (kg); 3·slots: goal (m) */
    double *om;              /* slots: blend weight ω_jk = μ_jk / m_j (1) */
    double *d0;              /* 3·slots: rest offset x̄_j − c̄_k (m) */
    double *gM, *gden;       /* n: group mass Σ μ (kg), Σ μ |x̄ − c̄|² (kg m²) */
    size_t polar_total, polar_fallbacks; /* counters of the current step */
};

phc_particles_options phc_particles_options_default(void)
{
    phc_particles_options o;
    o.density = 1000.0;
    o.gravity[0] = 0.0;
    o.gravity[1] = 0.0;
    o.gravity[2] = -9.81;
    o.stiffness = 1.0;
    o.maturity_age = 0.0;
    o.parent_weight = 2.0;
    o.iterations = 4;
    o.damping = 0.01;
    o.break_threshold = 0.0;
    o.follow_parent = 0;
    o.stiffness_step = 0.01;
    o.bending = PHC_PARTICLES_OWN_WEIGHT;
    o.beam_modulus = 1e7;
    o.break_stress = 0.0;
    o.anchors_carry_moment = 0;
    return o;
}

/* ---- small linear algebra (row-major 3x3) -------------------------------- */


static inline void quat_mul(const double a[4], const double b[4], double c[4])
{
    const double w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    const double x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    const double y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    const double z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
    c[0] = w;
    c[1] = x;
    c[2] = y;
    c[3] = z;
}

static inline void quat_normalize(double q[4])
{
    const double r = 1.0 / sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; ++k)
        q[k] *= r;
}

/* Unit quaternion of the rotation vector phi (rad): exp(phi/2). */
static inline void quat_exp(const double phi[3], double q[4])
{
    const double a = sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]);
    if (a < 1e-300) {
        q[0] = 1;
        q[1] = q[2] = q[3] = 0;
        return;
    }
    const double sh = sin(0.5 * a) / a;
    q[0] = cos(0.5 * a);
    q[1] = phi[0] * sh;
    q[2] = phi[1] * sh;
    q[3] = phi[2] * sh;
}

static inline void mat_vec(const double R[9], const double a[3], double b[3])
{
    b[0] = R[0] * a[0] + R[1] * a[1] + R[2] * a[2];
    b[1] = R[3] * a[0] + R[4] * a[1] + R[5] * a[2];
    b[2] = R[6] * a[0] + R[7] * a[1] + R[8] * a[2];
}

/* R = U diag(1, 1, det(U Vt)) Vt from LAPACK's SVD of A (row-major). */
static int polar_svd(const double A[9], double R[9])
{
    double a[9], s[3], u[9], vt[9], superb[2];
    memcpy(a, A, sizeof a);
    if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'A', 'A', 3, 3, a, 3, s, u, 3, vt, 3, superb) != 0)
        return -1;
    double uv[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            uv[3 * i + j] = u[3 * i] * vt[j] + u[3 * i + 1] * vt[3 + j] + u[3 * i + 2] * vt[6 + j];
    const double det = uv[0] * (uv[4] * uv[8] - uv[5] * uv[7]) -
                       uv[1] * (uv[3] * uv[8] - uv[5] * uv[6]) +
                       uv[2] * (uv[3] * uv[7] - uv[4] * uv[6]);
    const double d[3] = {1, 1, det < 0 ? -1 : 1};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            R[3 * i + j] = u[3 * i] * d[0] * vt[j] + u[3 * i + 1] * d[1] * vt[3 + j] +
                           u[3 * i + 2] * d[2] * vt[6 + j];
    return 0;
}

/* The Newton terms of tr(Rᵀ A) at R along a left turn exp([ω]×) R:
 * gradient g = Σ_c r_c × a_c = axial(B − Bᵀ) and T = tr(B) I − sym(B)
 * (the Hessian is −T), B = A Rᵀ (rows of A against rows of R); T as
 * T00, T11, T22, T01, T02, T12.  Returns tr(B) = Σ_c r_c · a_c. */
static inline double newton_terms(const double A[9], const double R[9], double g[3], double T[6])
{
    double dot = 0, B[9];
    g[0] = g[1] = g[2] = 0;
    for (int c = 0; c < 3; ++c) {
        const double r0 = R[c], r1 = R[3 + c], r2 = R[6 + c];
        const double a0 = A[c], a1 = A[3 + c], a2 = A[6 + c];
        g[0] += r1 * a2 - r2 * a1;
        g[1] += r2 * a0 - r0 * a2;
        g[2] += r0 * a1 - r1 * a0;
        dot += r0 * a0 + r1 * a1 + r2 * a2;
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            B[3 * i + j] =
                A[3 * i] * R[3 * j] + A[3 * i + 1] * R[3 * j + 1] + A[3 * i + 2] * R[3 * j + 2];
    T[0] = dot - B[0];
    T[1] = dot - B[4];
    T[2] = dot - B[8];
    T[3] = -0.5 * (B[1] + B[3]);
    T[4] = -0.5 * (B[2] + B[6]);
    T[5] = -0.5 * (B[5] + B[7]);
    return dot;
}

int phc_particles_polar_rotation(const double A[9], double q[4])
{
    double a[9], norm = 0;
    for (int k = 0; k < 9; ++k) {
        if (!isfinite(A[k]))
            return -1;
        norm += A[k] * A[k];
    }
    norm = sqrt(norm);
    if (!(norm > 0))
        return -1;
    for (int k = 0; k < 9; ++k)
        a[k] = A[k] / norm; /* scale-free: |a|_F = 1 */
    if (!(fabs(q[0]) + fabs(q[1]) + fabs(q[2]) + fabs(q[3]) > 0) ||
        !isfinite(q[0] + q[1] + q[2] + q[3])) {
        q[0] = 1;
        q[1] = q[2] = q[3] = 0;
    }
    quat_normalize(q);
    /* Müller et al. 2016, eq. 7: ω = Σ_c r_c × a_c / (|Σ_c r_c · a_c| + ε)
     * over the columns c of R and A; q ← exp(ω) q.  With B = A Rᵀ,
     * Σ_c r_c × a_c = g = axial(B − Bᵀ) is the gradient of tr(Rᵀ A) along a
     * left turn exp([ω]×) R, and the Hessian is −T, T = tr(B) I − sym(B)
     * (second-order expansion of exp).  Müller's step replaces T by tr(B) I,
     * which converges only linearly, at the rate 1 − (σ2 + σ3)/tr S, when
     * A is rod-like (σ1 ≫ σ2, σ3: the turn about the rod axis is weakly
     * determined); ours takes the Newton step ω = T⁻¹ g whenever T is
     * positive definite (near the maximum it is), Müller's step otherwise,
     * and stops after a Newton step shorter than 1e-9 rad (the next one
     * would be below rounding: quadratic convergence). */
    double R[9];
    int converged = 0, slow = 0;
    for (int it = 0; it < 100; ++it) {
        phc_quat_to_matrix(q, R);
        double om[3], Tm[6];
        const double dot = newton_terms(a, R, om, Tm);
        const double T00 = Tm[0], T11 = Tm[1], T22 = Tm[2];
        const double T01 = Tm[3], T02 = Tm[4], T12 = Tm[5];
        /* Cholesky of T; pivots must stay above 1e-10 (|a|_F = 1). */
        int newton = 0;
        double nw[3];
        const double piv_min = 1e-10;
        if (T00 > piv_min) {
            const double l00 = sqrt(T00), l10 = T01 / l00, l20 = T02 / l00;
            const double d1 = T11 - l10 * l10;
            if (d1 > piv_min) {
                const double l11 = sqrt(d1), l21 = (T12 - l20 * l10) / l11;
                const double d2 = T22 - l20 * l20 - l21 * l21;
                if (d2 > piv_min) {
                    const double l22 = sqrt(d2);
                    const double y0 = om[0] / l00, y1 = (om[1] - l10 * y0) / l11,
                                 y2 = (om[2] - l20 * y0 - l21 * y1) / l22;
                    nw[2] = y2 / l22;
                    nw[1] = (y1 - l21 * nw[2]) / l11;
                    nw[0] = (y0 - l10 * nw[1] - l20 * nw[2]) / l00;
                    /* trust the quadratic model only for turns below 1 rad:
                     * a longer Newton step (T positive definite, so still an
                     * ascent direction) is cut to 1 rad */
                    const double n2 = nw[0] * nw[0] + nw[1] * nw[1] + nw[2] * nw[2];
                    if (n2 > 1.0) {
                        const double sc = 1.0 / sqrt(n2);
                        for (int k = 0; k < 3; ++k)
                            nw[k] *= sc;
                    }
                    newton = 1;
                }
            }
        }
        if (newton) {
            memcpy(om, nw, sizeof nw);
        } else if (++slow > 16) {
            /* Müller's step far from the maximum of a rod-like A crawls
             * (hundreds of steps); the SVD below is cheaper than that */
            break;
        } else {
            const double sc = 1.0 / (fabs(dot) + 1e-12);
            for (int k = 0; k < 3; ++k)
                om[k] *= sc;
        }
        const double wn = sqrt(om[0] * om[0] + om[1] * om[1] + om[2] * om[2]);
        if (wn < 1e-14) {
            converged = 1;
            break;
        }
        double dq[4], t[4];
        quat_exp(om, dq);
        quat_mul(dq, q, t);
        memcpy(q, t, sizeof t);
        quat_normalize(q);
        if (newton && wn < 1e-9) {
            converged = 1;
            break;
        }
    }
    if (converged) {
        /* Certificate: at a maximum of tr(Rᵀa) over rotations, S = Rᵀa is
         * symmetric and nᵀSn <= tr S for all unit n (second variation
         * along a rotation about n). */
        phc_quat_to_matrix(q, R);
        double S[9];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                S[3 * i + j] = R[i] * a[j] + R[3 + i] * a[3 + j] + R[6 + i] * a[6 + j];
        /* T = tr(S) I - sym(S) must be positive semidefinite: all its
         * principal minors >= 0 (|a|_F = 1 sets the tolerance's scale). */
        const double tr = S[0] + S[4] + S[8];
        double T[9];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                T[3 * i + j] = (i == j ? tr : 0) - 0.5 * (S[3 * i + j] + S[3 * j + i]);
        const double tol = -1e-12;
        const double m01 = T[0] * T[4] - T[1] * T[3], m02 = T[0] * T[8] - T[2] * T[6],
                     m12 = T[4] * T[8] - T[5] * T[7];
        const double det = T[0] * m12 - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                           T[2] * (T[3] * T[7] - T[4] * T[6]);
        if (T[0] >= tol && T[4] >= tol && T[8] >= tol && m01 >= tol && m02 >= tol && m12 >= tol &&
            det >= tol)
            return 0;
    }
    if (polar_svd(a, R) != 0)
        return -1;
    phc_quat_from_matrix(R, q);
    return 1;
}

/* Newton steps phc_particles_polar_rotation_warm takes before it hands
 * over to the full routine (a warm start needs 1 to 3). */
#define POLAR_WARM_MAX_STEPS 8

int phc_particles_polar_rotation_warm(const double A[9], double q[4], double R[9], int *steps)
{
    double n2 = 0;
    for (int k = 0; k < 9; ++k)
        n2 += A[k] * A[k];
    int it = 0;
    if (n2 > 0 && isfinite(n2)) {
        /* the Newton step of phc_particles_polar_rotation on the unscaled
         * A: gradient g = Σ_c r_c × a_c, T = tr(B) I − sym(B), B = A Rᵀ,
         * ω = T⁻¹ g by T = L D Lᵀ (pivots above 1e-10 |A|_F: T positive
         * definite), cut to 1 rad */
        const double piv_min = 1e-10 * sqrt(n2);
        while (it < POLAR_WARM_MAX_STEPS) {
            phc_quat_to_matrix(q, R);
            double g[3], Tm[6];
            newton_terms(A, R, g, Tm);
            const double T00 = Tm[0], T11 = Tm[1], T22 = Tm[2];
            const double T01 = Tm[3], T02 = Tm[4], T12 = Tm[5];
            const double d0 = T00;
            if (!(d0 > piv_min))
                break;
            const double l10 = T01 / d0, l20 = T02 / d0;
            const double d1 = T11 - l10 * T01;
            if (!(d1 > piv_min))
                break;
            const double l21 = (T12 - l20 * T01) / d1;
            const double d2 = T22 - l20 * T02 - l21 * l21 * d1;
            if (!(d2 > piv_min))
                break;
            const double y0 = g[0], y1 = g[1] - l10 * y0, y2 = g[2] - l20 * y0 - l21 * y1;
            double w[3];
            w[2] = y2 / d2;
            w[1] = y1 / d1 - l21 * w[2];
            w[0] = y0 / d0 - l10 * w[1] - l20 * w[2];
            double wn2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
            ++it;
            if (wn2 < 1e-28) /* at the maximum: R = R(q) */
                goto done;
            if (wn2 > 1.0) {
                const double sc = 1.0 / sqrt(wn2);
                for (int k = 0; k < 3; ++k)
                    w[k] *= sc;
            }
            /* q ← (1, ω/2) ⊗ q, normalised: the turn about ω by 2 atan(|ω|/2)
             * = |ω| − |ω|³/12 + ..., exact to rounding near the maximum */
            const double h[4] = {1, 0.5 * w[0], 0.5 * w[1], 0.5 * w[2]};
            double t[4];
            quat_mul(h, q, t);
            const double inv = 1.0 / sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2] + t[3] * t[3]);
            for (int k = 0; k < 4; ++k)
                q[k] = t[k] * inv;
            if (wn2 < 1e-18) { /* a Newton step below 1e-9 rad: the next is below rounding */
                phc_quat_to_matrix(q, R);
                goto done;
            }
        }
    }
    {
        const int how = phc_particles_polar_rotation(A, q);
        if (how >= 0)
            phc_quat_to_matrix(q, R);
        if (steps)
            *steps = -1;
        return how;
    }
done:
    if (steps)
        *steps = it;
    return 0;
}

/* ell0_k = D R̄ᵀ / 5, D = diag(r², r², (L/2)²): the rest half of the
 * ellipsoid moment R D R̄ᵀ / 5 (Müller & Chentanez eq. 10), m², from
 * particle k's rest orientation and radii. */
static void rest_moment(phc_particles *p, size_t k)
{
    double R0[9];
    phc_quat_to_matrix(p->q0 + 4 * k, R0);
    for (int t = 0; t < 3; ++t)
        for (int c = 0; c < 3; ++c)
            p->ell0[9 * k + 3 * t + c] = 0.2 * p->ax[3 * k + t] * p->ax[3 * k + t] * R0[3 * c + t];
}

/* ---- construction ------------------------------------------------------- */

static const char *opt_problem(const phc_particles_options *o, char *buf, size_t size)
{
    if (!(o->density > 0) || !isfinite(o->density))
        snprintf(buf, size, "density must be positive and finite, found %g kg m-3", o->density);
    else if (!(o->stiffness >= 0 && o->stiffness <= 1))
        snprintf(buf, size, "stiffness s must be in [0, 1], found %g", o->stiffness);
    else if (!(o->maturity_age >= 0) || !isfinite(o->maturity_age))
        snprintf(buf, size, "maturity age must be >= 0 and finite, found %g s", o->maturity_age);
    else if (!(o->parent_weight >= 1) || !isfinite(o->parent_weight))
        snprintf(buf, size, "parent weight must be >= 1 and finite, found %g", o->parent_weight);
    else if (o->iterations < 1)
        snprintf(buf, size, "iterations must be >= 1, found %zu", o->iterations);
    else if (!(o->damping >= 0 && o->damping < 1))
        snprintf(buf, size, "damping must be in [0, 1), found %g", o->damping);
    else if (!(o->stiffness_step > 0) || !isfinite(o->stiffness_step))
        snprintf(buf, size, "stiffness step must be positive and finite, found %g s",
                 o->stiffness_step);
    else if (o->bending != PHC_PARTICLES_OWN_WEIGHT && o->bending != PHC_PARTICLES_BEAM)
        snprintf(buf, size, "bending must be own_weight (%d) or beam (%d), found %d",
                 PHC_PARTICLES_OWN_WEIGHT, PHC_PARTICLES_BEAM, o->bending);
    else if (!(o->beam_modulus > 0) || !isfinite(o->beam_modulus))
        snprintf(buf, size, "beam modulus must be positive and finite, found %g Pa", o->beam_modulus);
    else if (!isfinite(o->break_threshold))
        snprintf(buf, size, "break threshold must be finite, found %g", o->break_threshold);
    else if (!(o->break_stress >= 0) || !isfinite(o->break_stress))
        snprintf(buf, size, "break stress must be >= 0 and finite, found %g Pa", o->break_stress);
    else if (o->break_stress > 0 && !(o->follow_parent && o->bending == PHC_PARTICLES_BEAM))
        snprintf(buf, size,
                 "break stress %g Pa needs follow_parent with bending beam (the own-weight pass carries no "
                 "bending moment)",
                 o->break_stress);
    else if (o->anchors_carry_moment && !(o->follow_parent && o->bending == PHC_PARTICLES_BEAM))
        snprintf(buf, size, "anchors carry moment needs follow_parent with bending beam (the own-weight pass "
                            "carries no moment)");
    else if (o->break_stress > 0 && o->break_threshold > 0)
        snprintf(buf, size,
                 "break stress %g Pa and break threshold %g are two rules for the same break: set one",
                 o->break_stress, o->break_threshold);
    else if (!isfinite(o->gravity[0]) || !isfinite(o->gravity[1]) || !isfinite(o->gravity[2]))
        snprintf(buf, size, "gravity must be finite");
    else
        return NULL;
    return buf;
}

void phc_particles_free(phc_particles *p)
{
    if (!p)
        return;
    free(p->x);
    free(p->v);
    free(p->xp);
    free(p->x0);
    free(p->q);
    free(p->qp);
    free(p->q0);
    free(p->w);
    free(p->m);
    free(p->ax);
    free(p->age);
    free(p->vn);
    free(p->wn);
    free(p->agen);
    free(p->s);
    free(p->f);
    free(p->anchored);
    free(p->hold_q);
    free(p->anchor_at);
    free(p->anchor_k);
    free(p->anchor_q);
    free(p->parent);
    free(p->linked);
    free(p->child_start);
    free(p->child);
    free(p->topo);
    free(p->follow_order);
    free(p->follow_start);
    free(p->subtree);
    free(p->lane_order);
    free(p->lane_level);
    free(p->fstack);
    free(p->plist);
    free(p->gmatch);
    free(p->plev);
    free(p->glev);
    free(p->pcount);
    free(p->pins);
    free(p->gcount);
    free(p->gq);
    free(p->stress);
    free(p->source_id);
    free(p->child_index);
    free(p->ell0);
    free(p->ell0_stale);
    free(p->joint);
    free(p->beam);
    free(p->joint_epoch);
    free(p->rest_epoch);
    free(p->ell);
    free(p->om);
    free(p->d0);
    free(p->gM);
    free(p->gden);
    free(p->goff);
    free(p->mem);
    free(p->mu);
    free(p->goal);
    free(p->reach);
    free(p->skip);
    free(p);
}

phc_particles *phc_particles_new(const phc_plant_graph *g, const phc_particles_options *options,
                                 phc_error *err)
{
    char buf[256];
    const phc_particles_options o = options ? *options : phc_particles_options_default();
    if (!g || g->n == 0 || !g->child_start) {
        phc_error_set(err, PHC_ERR_INVALID, "particles: the plant graph is empty or not finished");
        return NULL;
    }
    if (opt_problem(&o, buf, sizeof buf)) {
        phc_error_set(err, PHC_ERR_INVALID, "particles: options: %s", buf);
        return NULL;
    }
    const size_t n = g->n;
    phc_particles *p = calloc(1, sizeof *p);
    if (!p)
        goto nomem;
    p->n = n;
    p->cap = n;
    p->o = o;
    p->epoch = 1; /* (rest_epoch 1 for every particle: made before any step) */
    const size_t slots = 3 * n; /* Σ_k (2 + children(k)) = 2n + (n − roots) <= 3n */
#define ALLOC(field, count) \
    if (!(p->field = calloc((count), sizeof *p->field))) goto nomem
    ALLOC(x, 3 * n);
    ALLOC(v, 3 * n);
    ALLOC(xp, 3 * n);
    ALLOC(x0, 3 * n);
    ALLOC(q, 4 * n);
    ALLOC(qp, 4 * n);
    ALLOC(q0, 4 * n);
    ALLOC(w, 3 * n);
    ALLOC(m, n);
    ALLOC(ax, 3 * n);
    ALLOC(age, n);
    ALLOC(vn, 3 * n);
    ALLOC(wn, 3 * n);
    ALLOC(agen, n);
    ALLOC(s, n);
    ALLOC(f, 3 * n);
    ALLOC(anchored, n);
    ALLOC(hold_q, n);
    ALLOC(anchor_at, 3 * n);
    ALLOC(anchor_k, n);
    ALLOC(anchor_q, 4 * n);
    ALLOC(parent, n);
    ALLOC(linked, n);
    ALLOC(child_start, n + 1);
    ALLOC(child, n);
    ALLOC(topo, n);
    ALLOC(follow_order, n);
    ALLOC(follow_start, n + 1);
    ALLOC(subtree, n);
    ALLOC(lane_order, n);
    ALLOC(lane_level, n);
    ALLOC(fstack, n);
    ALLOC(plist, n);
    ALLOC(gmatch, n);
    ALLOC(plev, n);
    ALLOC(glev, n);
    ALLOC(pcount, o.iterations + 1);
    ALLOC(pins, n);
    ALLOC(gcount, o.iterations + 1);
    ALLOC(gq, 4 * n);
    ALLOC(stress, n);
    ALLOC(source_id, n);
    ALLOC(child_index, n);
    ALLOC(ell0, 9 * n);
    ALLOC(ell0_stale, n);
    ALLOC(joint, 7 * n);
    ALLOC(joint_epoch, n);
    ALLOC(rest_epoch, n);
    ALLOC(ell, 9 * n);
    ALLOC(goff, n + 1);
    ALLOC(mem, slots);
    ALLOC(mu, slots);
    ALLOC(goal, 3 * slots);
    ALLOC(om, slots);
    ALLOC(d0, 3 * slots);
    ALLOC(gM, n);
    ALLOC(gden, n);
#undef ALLOC
    memcpy(p->child_start, g->child_start, (n + 1) * sizeof *p->child_start);
    memcpy(p->topo, g->order, n * sizeof *p->topo); /* breadth-first: parents first */
    if (n > 1)
        memcpy(p->child, g->child, (n - 1) * sizeof *p->child);
    for (size_t i = 0; i < n; ++i) {
        const long id = g->source_id ? g->source_id[i] : (long)i;
        p->source_id[i] = id;
        /* joint terms to be made (joint_epoch <= rest_epoch), written here
           as non-zero values: calloc's untouched pages, read first in the
           step's parallel joint pass and written there, cost each a
           copy-on-write fault with a TLB shootdown to the other threads
           (~40 ms for a 25k plant's first steps on two threads in a VM) */
        p->rest_epoch[i] = p->joint_epoch[i] = 1;
        const double r = g->radius[i], L = g->length[i];
        if (!(r > 0) || !isfinite(r) || !(L > 0) || !isfinite(L)) {
            phc_error_set(err, PHC_ERR_INPUT,
                          "particles: particle %zu (segment %ld): radius and length must be "
                          "positive and finite, found r = %g m, L = %g m",
                          i, id, r, L);
            goto fail;
        }
        double d[3], len = 0;
        for (int k = 0; k < 3; ++k) {
            const double h = g->head[3 * i + k], t = g->tail[3 * i + k];
            if (!isfinite(h) || !isfinite(t)) {
                phc_error_set(err, PHC_ERR_INPUT,
                              "particles: particle %zu (segment %ld): coordinate %c is not finite",
                              i, id, "xyz"[k]);
                goto fail;
            }
            p->x0[3 * i + k] = p->x[3 * i + k] = 0.5 * (h + t);
            d[k] = t - h;
            len += d[k] * d[k];
        }
        len = sqrt(len);
        if (!(len > 0)) {
            phc_error_set(err, PHC_ERR_INPUT,
                          "particles: particle %zu (segment %ld): head and tail coincide", i, id);
            goto fail;
        }
        for (int k = 0; k < 3; ++k)
            d[k] /= len;
        phc_quat_from_z_inline(d, p->q0 + 4 * i);
        memcpy(p->q + 4 * i, p->q0 + 4 * i, 4 * sizeof(double));
        p->gq[4 * i] = 1;
        p->m[i] = o.density * PI * r * r * L;
        p->ax[3 * i] = p->ax[3 * i + 1] = r;
        p->ax[3 * i + 2] = 0.5 * L;
        p->s[i] = o.stiffness;
        p->parent[i] = g->parent[i];
        p->linked[i] = g->parent[i] != PHC_PLANT_NO_PARENT;
        if (g->fixed && g->fixed[i]) {
            p->anchored[i] = 1;
            p->hold_q[i] = 1;
            p->anchor_k[i] = 1;
            memcpy(p->anchor_at + 3 * i, p->x0 + 3 * i, 3 * sizeof(double));
            memcpy(p->anchor_q + 4 * i, p->q0 + 4 * i, 4 * sizeof(double));
        }
    }
    for (size_t k = 0; k < n; ++k) {
        p->goff[k + 1] = p->goff[k] + 2 + (p->child_start[k + 1] - p->child_start[k]);
        for (size_t c = p->child_start[k]; c < p->child_start[k + 1]; ++c)
            p->child_index[p->child[c]] = c - p->child_start[k];
        rest_moment(p, k);
    }
    memcpy(p->xp, p->x, 3 * n * sizeof(double));
    memcpy(p->qp, p->q, 4 * n * sizeof(double));
    p->follow_dirty = 1;
    return p;
nomem:
    phc_error_set(err, PHC_ERR_NOMEM, "particles: out of memory for %zu particles", g->n);
fail:
    phc_particles_free(p);
    return NULL;
}

size_t phc_particles_count(const phc_particles *p) { return p ? p->n : 0; }

/* ---- growing the system in place ----------------------------------------- */

/* Grows every per-particle array to hold `want` particles (amortised
 * doubling); the contents are kept.  0, or -1 when out of memory (the
 * arrays that did grow keep their contents; the system stays valid). */
static int reserve(phc_particles *p, size_t want)
{
    if (want <= p->cap)
        return 0;
    size_t cap = p->cap ? 2 * p->cap : 16;
    while (cap < want)
        cap *= 2;
#define GROW(field, per) \
    do { \
        void *t_ = realloc(p->field, (per) * cap * sizeof *p->field); \
        if (!t_) \
            return -1; \
        p->field = t_; \
    } while (0)
    GROW(x, 3);
    GROW(v, 3);
    GROW(xp, 3);
    GROW(x0, 3);
    GROW(q, 4);
    GROW(qp, 4);
    GROW(q0, 4);
    GROW(w, 3);
    GROW(m, 1);
    GROW(ax, 3);
    GROW(age, 1);
    GROW(vn, 3);
    GROW(wn, 3);
    GROW(agen, 1);
    GROW(s, 1);
    GROW(f, 3);
    GROW(anchored, 1);
    GROW(hold_q, 1);
    GROW(anchor_at, 3);
    GROW(anchor_k, 1);
    GROW(anchor_q, 4);
    GROW(parent, 1);
    GROW(linked, 1);
    GROW(child, 1);
    GROW(topo, 1);
    GROW(follow_order, 1);
    GROW(subtree, 1);
    GROW(lane_order, 1);
    GROW(lane_level, 1);
    GROW(fstack, 1);
    GROW(plist, 1);
    GROW(gmatch, 1);
    GROW(plev, 1);
    GROW(glev, 1);
    GROW(pins, 1);
    GROW(gq, 4);
    GROW(stress, 1);
    GROW(source_id, 1);
    GROW(child_index, 1);
    GROW(ell0, 9);
    GROW(ell0_stale, 1);
    GROW(joint, 7);
    GROW(joint_epoch, 1);
    GROW(rest_epoch, 1);
    GROW(ell, 9);
    GROW(mem, 3);
    GROW(mu, 3);
    GROW(goal, 9);
    GROW(om, 3);
    GROW(d0, 9);
    GROW(gM, 1);
    GROW(gden, 1);
#undef GROW
    void *t = realloc(p->child_start, (cap + 1) * sizeof *p->child_start);
    if (!t)
        return -1;
    p->child_start = t;
    t = realloc(p->follow_start, (cap + 1) * sizeof *p->follow_start);
    if (!t)
        return -1;
    p->follow_start = t;
    t = realloc(p->goff, (cap + 1) * sizeof *p->goff);
    if (!t)
        return -1;
    p->goff = t;
    p->cap = cap;
    return 0;
}

/* Children (CSR, each parent's children in index order, as
 * phc_plant_graph_finish orders them), each child's index among its
 * parent's children, and the group slot offsets, from p->parent.  O(n),
 * no allocation. */
static void relayout(phc_particles *p)
{
    const size_t n = p->n;
    memset(p->child_start, 0, (n + 1) * sizeof *p->child_start);
    memset(p->child_index, 0, n * sizeof *p->child_index);
    for (size_t i = 0; i < n; ++i)
        if (p->parent[i] != PHC_PLANT_NO_PARENT)
            ++p->child_start[p->parent[i] + 1];
    for (size_t i = 0; i < n; ++i)
        p->child_start[i + 1] += p->child_start[i];
    /* fill: child_index counts the children placed so far under each parent */
    for (size_t i = 0; i < n; ++i)
        if (p->parent[i] != PHC_PLANT_NO_PARENT) {
            const size_t u = p->parent[i];
            const size_t c = p->child_start[u] + p->child_index[u];
            p->child[c] = i;
            ++p->child_index[u];
        }
    /* child_index was used as a fill counter above; now the real one */
    for (size_t k = 0; k < n; ++k) {
        p->goff[k + 1] = p->goff[k] + 2 + (p->child_start[k + 1] - p->child_start[k]);
        for (size_t c = p->child_start[k]; c < p->child_start[k + 1]; ++c)
            p->child_index[p->child[c]] = c - p->child_start[k];
    }
    p->layout_dirty = 0;
    p->follow_dirty = 1;
}

/* Rest state of particle i from its segment head → tail (m) and radius r
 * (m): rest centre, rest orientation (z along the segment), radii, mass
 * ρπr²L and the rest half of the ellipsoid moment.  The checks are the
 * caller's. */
static void rest_from_segment(phc_particles *p, size_t i, const double head[3],
                              const double tail[3], double r, double L)
{
    double d[3];
    for (int k = 0; k < 3; ++k) {
        p->x0[3 * i + k] = 0.5 * (head[k] + tail[k]);
        d[k] = (tail[k] - head[k]) / L;
    }
    phc_quat_from_z_inline(d, p->q0 + 4 * i);
    p->m[i] = p->o.density * PI * r * r * L;
    p->ax[3 * i] = p->ax[3 * i + 1] = r;
    p->ax[3 * i + 2] = 0.5 * L;
    p->ell0_stale[i] = 1; /* rest_moment when ellipsoid_term next needs it */
    p->rest_epoch[i] = p->epoch; /* its joint terms and its children's to be made again */
}

/* Checks a segment for particle i (or the one to be appended); its length
 * into *L. */
static int check_segment(const phc_particles *p, size_t i, const double head[3],
                         const double tail[3], double r, double *L, phc_error *err)
{
    const long id = i < p->n ? p->source_id[i] : (long)i;
    if (!head || !tail)
        return phc_error_set(err, PHC_ERR_INVALID, "particles: particle %zu: segment: NULL", i);
    if (!(r > 0) || !isfinite(r))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): radius must be positive and "
                             "finite, found r = %g m",
                             i, id, r);
    double len = 0;
    for (int k = 0; k < 3; ++k) {
        if (!isfinite(head[k]) || !isfinite(tail[k]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "particles: particle %zu (segment %ld): coordinate %c is not "
                                 "finite",
                                 i, id, "xyz"[k]);
        len += (tail[k] - head[k]) * (tail[k] - head[k]);
    }
    len = sqrt(len);
    if (!(len > 0) || !isfinite(len))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): head and tail coincide", i,
                             id);
    *L = len;
    return PHC_OK;
}

int phc_particles_append(phc_particles *p, size_t parent, const double head[3],
                         const double tail[3], double radius, size_t *index, phc_error *err)
{
    if (!p)
        return phc_error_set(err, PHC_ERR_INVALID, "particles: append: no particle system");
    if (parent != PHC_PARTICLES_NONE && parent >= p->n)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "particles: append: parent %zu does not exist (%zu particles)",
                             parent, p->n);
    double L = 0;
    if (check_segment(p, p->n, head, tail, radius, &L, err))
        return err ? err->status : PHC_ERR_INPUT;
    if (reserve(p, p->n + 1))
        return phc_error_set(err, PHC_ERR_NOMEM, "particles: out of memory for %zu particles",
                             p->n + 1);
    const size_t i = p->n++;
    rest_from_segment(p, i, head, tail, radius, L);
    memcpy(p->x + 3 * i, p->x0 + 3 * i, 3 * sizeof(double));
    memcpy(p->xp + 3 * i, p->x0 + 3 * i, 3 * sizeof(double));
    memcpy(p->q + 4 * i, p->q0 + 4 * i, 4 * sizeof(double));
    memcpy(p->qp + 4 * i, p->q0 + 4 * i, 4 * sizeof(double));
    for (int k = 0; k < 3; ++k)
        p->v[3 * i + k] = p->w[3 * i + k] = p->f[3 * i + k] = p->anchor_at[3 * i + k] = 0;
    p->age[i] = 0;
    p->s[i] = p->o.stiffness;
    p->anchored[i] = p->hold_q[i] = 0;
    p->anchor_k[i] = 0;
    memcpy(p->anchor_q + 4 * i, p->q0 + 4 * i, 4 * sizeof(double));
    p->parent[i] = parent == PHC_PARTICLES_NONE ? PHC_PLANT_NO_PARENT : parent;
    p->linked[i] = parent != PHC_PARTICLES_NONE;
    p->child_index[i] = 0;
    p->topo[i] = i; /* after its parent, which exists already */
    p->joint_epoch[i] = 0; /* its joint terms not made yet */
    p->gq[4 * i] = 1; /* at rest: its group has not turned */
    p->gq[4 * i + 1] = p->gq[4 * i + 2] = p->gq[4 * i + 3] = 0;
    p->stress[i] = 0;
    p->source_id[i] = (long)i;
    p->layout_dirty = 1;
    if (index)
        *index = i;
    return PHC_OK;
}

int phc_particles_set_rest(phc_particles *p, size_t i, const double head[3], const double tail[3],
                           double radius, phc_error *err)
{
    if (!p || i >= p->n)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "particles: rest: particle %zu does not exist (%zu particles)", i,
                             p ? p->n : 0);
    double L = 0;
    if (check_segment(p, i, head, tail, radius, &L, err))
        return err ? err->status : PHC_ERR_INPUT;
    rest_from_segment(p, i, head, tail, radius, L);
    return PHC_OK;
}

int phc_particles_set_gravity(phc_particles *p, const double g[3], phc_error *err)
{
    if (!p || !g)
        return phc_error_set(err, PHC_ERR_INVALID, "particles: gravity: NULL argument");
    for (int k = 0; k < 3; ++k)
        if (!isfinite(g[k]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "particles: gravity %c must be finite, found %g m s-2", "xyz"[k],
                                 g[k]);
    memcpy(p->o.gravity, g, 3 * sizeof(double));
    return PHC_OK;
}

void phc_particles_set_collider(phc_particles *p, phc_particles_closest_fn fn, void *user)
{
    if (!p)
        return;
    if (fn != p->collide || user != p->collide_user)
        phc_particles_supports_moved(p);
    p->collide = fn;
    p->collide_user = user;
}

void phc_particles_set_segment_collider(phc_particles *p, phc_particles_segment_fn fn, void *user)
{
    if (!p)
        return;
    p->collide_segment = fn;
    p->collide_segment_user = user;
}

void phc_particles_supports_moved(phc_particles *p)
{
    if (p)
        p->reach_n = 0; /* every particle's points unknown again (zeroed at the next pass) */
}

void phc_particles_supports_closed(phc_particles *p, int on)
{
    if (p)
        p->supports_closed = on != 0;
}

void phc_particles_collide_all(phc_particles *p, int on)
{
    if (p)
        p->collide_all = on != 0;
}

void phc_particles_collision_queries(const phc_particles *p, size_t *queries, size_t *skipped)
{
    if (queries)
        *queries = p ? p->queries : 0;
    if (skipped)
        *skipped = p ? p->skipped : 0;
}

/* What the collision pass knows of one point (see struct phc_particles):
 * reach = {x₀, d₀, c, n, known, d₀ − margin} or NULL (nothing kept), whether a point
 * far enough from x₀ may be skipped (closed supports), and the pass's
 * counters. */
typedef struct point_memory {
    double *reach;
    int by_distance;
    size_t *queries, *skipped;
} point_memory;

/* A skip is certain when x lies within d₀ − r of x₀ by more than this (m):
 * δ at x >= d₀ − |x − x₀| > r holds for the exact distances, and the
 * margin covers the rounding of the query's closest point and of the
 * distances (a few ulps of the coordinates; 1e-9 relative is generous). */
static inline double skip_margin(const double x0[3])
{
    return 1e-9 * (1 + fmax(fabs(x0[0]), fmax(fabs(x0[1]), fabs(x0[2]))));
}

/* phc_particles_push_out with a memory (mem may be NULL: the plain push).
 * The point x₀ of the last query again (bit for bit): its answer is
 * reused.  With by_distance, a point within d₀ − r − margin of its x₀ is
 * not queried: the distance to a closed set is 1-Lipschitz, so its query
 * would find δ > r and push nothing (the side: see
 * phc_particles_supports_closed); *delta is then NAN and *bound (may be
 * NULL) gets d₀ − |x − x₀| − r > 0, a lower bound of δ − r (m); NAN
 * otherwise.  Every query made stores its point and answer. */
static int push_point(phc_particles_closest_fn fn, void *user, double r, double x[3], double *delta,
                      const point_memory *mem, double *bound)
{
    double c[3], nf[3];
    if (delta)
        *delta = INFINITY;
    if (bound)
        *bound = NAN;
    if (!fn)
        return 0;
    double *known = mem ? mem->reach : NULL;
    if (known && mem->by_distance && known[11] > r) {
        /* |x − x₀| < d₀ − margin − r, compared squared (known[11] = d₀ −
           margin, kept with the answer; the margin covers the rounding) */
        const double g[3] = {x[0] - known[0], x[1] - known[1], x[2] - known[2]}, room = known[11] - r;
        const double moved2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (moved2 < room * room) { /* (NaN: no skip) */
            ++*mem->skipped;
            if (delta)
                *delta = NAN;
            if (bound)
                *bound = known[3] - sqrt(moved2) - r;
            return 0;
        }
    }
    if (known && known[10] != 0 && memcmp(x, known, 3 * sizeof(double)) == 0) {
        ++*mem->skipped; /* the same point: the same answer (fn is a function of x) */
        memcpy(c, known + 4, 3 * sizeof(double));
        memcpy(nf, known + 7, 3 * sizeof(double));
    } else {
        if (mem)
            ++*mem->queries;
        if (fn(user, x, c, nf)) {
            if (known)
                known[3] = known[10] = known[11] = 0;
            return 0;
        }
        if (known) {
            memcpy(known, x, 3 * sizeof(double));
            memcpy(known + 4, c, 3 * sizeof(double));
            memcpy(known + 7, nf, 3 * sizeof(double));
            known[10] = 1;
        }
    }
    const double e[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
    const double dist = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    const int front = e[0] * nf[0] + e[1] * nf[1] + e[2] * nf[2] >= 0;
    const double d = front ? dist : -dist;
    if (known) {
        known[3] = front && isfinite(dist) ? dist : 0;
        known[11] = known[3] > 0 ? known[3] - skip_margin(known) : 0;
    }
    if (delta)
        *delta = d;
    if (!(d < r))
        return 0;
    for (int k = 0; k < 3; ++k)
        x[k] = c[k] + r * (front && dist > 0 ? e[k] / dist : nf[k]);
    return 1;
}

int phc_particles_push_out(phc_particles_closest_fn fn, void *user, double r, double x[3],
                           double *delta)
{
    return push_point(fn, user, r, x, delta, NULL, NULL);
}

void phc_particles_collisions(const phc_particles *p, size_t *pushed, double *depth)
{
    if (pushed)
        *pushed = p ? p->pushed : 0;
    if (depth)
        *depth = p ? p->depth : INFINITY;
}

/* The capsule push (phc_particles_push_segment_out) with the memories of
 * its points (mem: centre, end −, end + of round 0, then the centre pushed
 * again and the ends of the later rounds; NULL: none).  A skipped
 * round-0 point is appended to skip (5 doubles: the point, r, the lower
 * bound of its δ − r; *nskip counted) and left out of *depth. */
static int push_segment(phc_particles_closest_fn fn, void *user, double r, double h, int rounds,
                        double x[3], double axis[3], double *depth, const point_memory *mem,
                        double *skip, size_t *nskip)
{
    double d, lb;
    int pushed = push_point(fn, user, r, x, &d, mem, &lb);
    double first = INFINITY;
    if (!isnan(lb)) {
        memcpy(skip + 5 * *nskip, x, 3 * sizeof(double));
        skip[5 * *nskip + 3] = r;
        skip[5 * (*nskip)++ + 4] = lb;
    } else
        first = d - r; /* (as the plain push: fmin below) */
    /* A round's outcome is a function of the state (x, axis) it starts
     * from: when that state equals, bit for bit, the state of one of the
     * last CYCLE rounds, the rounds between repeat until the last (a push
     * that lands on the point it started from, rounding), so the whole
     * cycles are counted (their pushes) without being made: the same
     * state and count as making them (ours). */
    enum { CYCLE = 4 };
    double seen[CYCLE][6];
    int seen_pushed[CYCLE], nseen = 0;
    for (int round = 0; round < rounds; ++round) {
        double a[3], b[3], da, db, la, lbb;
        if (round > 0) {
            for (int back = 1; back <= nseen && back <= CYCLE; ++back) {
                const int j = (nseen - back) % CYCLE;
                if (memcmp(seen[j], x, 3 * sizeof(double)) || memcmp(seen[j] + 3, axis, 3 * sizeof(double)))
                    continue;
                const int cycles = (rounds - round) / back;
                pushed += cycles * (pushed - seen_pushed[j]);
                round += cycles * back;
                nseen = 0;
                break;
            }
            if (round >= rounds)
                break;
            const int j = nseen++ % CYCLE;
            memcpy(seen[j], x, 3 * sizeof(double));
            memcpy(seen[j] + 3, axis, 3 * sizeof(double));
            seen_pushed[j] = pushed;
        }
        for (int k = 0; k < 3; ++k) {
            a[k] = x[k] - h * axis[k];
            b[k] = x[k] + h * axis[k];
        }
        const point_memory *m = mem ? mem + (round ? 3 : 0) : NULL; /* round 0; later rounds */
        const int pa = push_point(fn, user, r, a, &da, m ? m + 1 : NULL, round ? NULL : &la);
        const int pb = push_point(fn, user, r, b, &db, m ? m + 2 : NULL, round ? NULL : &lbb);
        if (round == 0) {
            if (!isnan(la)) {
                for (int k = 0; k < 3; ++k)
                    skip[5 * *nskip + k] = x[k] - h * axis[k];
                skip[5 * *nskip + 3] = r;
                skip[5 * (*nskip)++ + 4] = la;
            } else
                first = fmin(first, da - r);
            if (!isnan(lbb)) {
                for (int k = 0; k < 3; ++k)
                    skip[5 * *nskip + k] = x[k] + h * axis[k];
                skip[5 * *nskip + 3] = r;
                skip[5 * (*nskip)++ + 4] = lbb;
            } else
                first = fmin(first, db - r);
        }
        pushed += pa + pb;
        if (!pa && !pb)
            break;
        const double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        if (!(len > 0))
            break; /* both ends pushed onto one point: keep the axis */
        for (int k = 0; k < 3; ++k) {
            x[k] = 0.5 * (a[k] + b[k]);
            axis[k] = e[k] / len;
        }
        pushed += push_point(fn, user, r, x, NULL, mem ? mem + 3 : NULL, NULL);
    }
    if (depth)
        *depth = first;
    return pushed;
}

int phc_particles_push_segment_out(phc_particles_closest_fn fn, void *user, double r, double h,
                                   int rounds, double x[3], double axis[3], double *depth)
{
    return push_segment(fn, user, r, h, rounds, x, axis, depth, NULL, NULL, NULL);
}

int phc_particles_push_segment_deepest(phc_particles_closest_fn fn, void *user, phc_particles_segment_fn deepest,
                                       void *deepest_user, double r, double h, double x[3], const double axis[3])
{
    int moved = 0;
    if (!fn || !deepest)
        return 0;
    for (int round = 0; round < 16; ++round) {
        double a[3], b[3], t;
        for (int k = 0; k < 3; ++k) {
            a[k] = x[k] - h * axis[k];
            b[k] = x[k] + h * axis[k];
        }
        /* a point the push left at r less rounding is not pushed again:
           deeper than 1e-13·(1 + |x|∞) m below r only (ours) */
        const double ulps = 1e-13 * (1 + fmax(fabs(x[0]), fmax(fabs(x[1]), fabs(x[2]))));
        double depth;
        if (deepest(deepest_user, a, b, r, &t, &depth) != 1 || !(depth < r - ulps))
            break;
        double y[3], y0[3];
        for (int k = 0; k < 3; ++k)
            y[k] = y0[k] = a[k] + t * (b[k] - a[k]);
        if (!push_point(fn, user, r, y, NULL, NULL, NULL))
            break;
        for (int k = 0; k < 3; ++k)
            x[k] += y[k] - y0[k];
        ++moved;
    }
    return moved;
}

/* The memories of the collision pass for particles 0 .. n−1: grown and
 * the new particles' points zeroed (nothing known).  0, or -1 when out of
 * memory (the pass then queries every point). */
static int reach_ready(phc_particles *p)
{
    if (p->reach_cap < p->n) {
        const size_t cap = p->cap > p->n ? p->cap : p->n;
        double *a = realloc(p->reach, 72 * cap * sizeof *a);
        if (!a)
            return -1;
        p->reach = a;
        double *b = realloc(p->skip, 15 * cap * sizeof *b);
        if (!b)
            return -1;
        p->skip = b;
        p->reach_cap = cap;
    }
    if (p->reach_n < p->n)
        memset(p->reach + 72 * p->reach_n, 0, 72 * (p->n - p->reach_n) * sizeof *p->reach);
    p->reach_n = p->n;
    return 0;
}

static int by_bound(const void *a, const void *b)
{
    const double x = ((const double *)a)[4], y = ((const double *)b)[4];
    return (x > y) - (x < y);
}

/* The collision pass on the predicted state (see particles.h): every
 * particle a capsule, its centre and its segment's ends pushed out, its
 * orientation turned with its axis.  Points that cannot be pushed are not
 * queried (phc_particles_collide_all); the smallest δ − r is then made
 * exact by querying the skipped points whose lower bound is below the
 * smallest measured, smallest bound first, until no bound is. */
static void collide(phc_particles *p)
{
    p->pushed = 0;
    p->depth = INFINITY;
    if (!p->collide)
        return;
    const int remember = !p->collide_all && reach_ready(p) == 0;
    size_t nskip = 0;
    for (size_t i = 0; i < p->n; ++i) {
        if (p->hold_q[i])
            continue;
        double R[9], axis[3], d;
        phc_quat_to_matrix(p->qp + 4 * i, R);
        const double axis0[3] = {R[2], R[5], R[8]}; /* R·(0, 0, 1) */
        memcpy(axis, axis0, sizeof axis);
        point_memory mem[6];
        for (int k = 0; k < 6; ++k)
            mem[k] = (point_memory){remember ? p->reach + 72 * i + 12 * k : NULL, p->supports_closed,
                                    &p->queries, &p->skipped};
        const size_t nskip0 = nskip;
        const int pushed = push_segment(p->collide, p->collide_user, p->ax[3 * i], p->ax[3 * i + 2], 64,
                                        p->xp + 3 * i, axis, &d, mem, p->skip, &nskip);
        p->pushed += (size_t)pushed;
        p->depth = fmin(p->depth, d);
        if (p->collide_segment) {
            /* in contact: pushed, or a point (its lower bound when
               skipped) within L/4 of r; else every point of the segment
               lies within L/4 of one of the three, farther than r */
            double near = d;
            for (size_t t = nskip0; t < nskip; ++t)
                near = fmin(near, p->skip[5 * t + 4]);
            if (pushed || near < 0.5 * p->ax[3 * i + 2])
                p->pushed += (size_t)phc_particles_push_segment_deepest(p->collide, p->collide_user, p->collide_segment,
                                                                        p->collide_segment_user, p->ax[3 * i],
                                                                        p->ax[3 * i + 2], p->xp + 3 * i, axis);
        }
        if (memcmp(axis, axis0, sizeof axis) == 0)
            continue;
        /* q_p turned by the shortest rotation taking axis0 to axis:
         * quaternion (1 + a0·a, a0 × a), normalised */
        const double c = axis0[0] * axis[0] + axis0[1] * axis[1] + axis0[2] * axis[2];
        double dq[4] = {1 + c, axis0[1] * axis[2] - axis0[2] * axis[1],
                        axis0[2] * axis[0] - axis0[0] * axis[2],
                        axis0[0] * axis[1] - axis0[1] * axis[0]};
        if (!(dq[0] > 1e-12))
            continue; /* a half turn: no unique shortest rotation, keep q_p */
        quat_normalize(dq);
        double qn[4];
        quat_mul(dq, p->qp + 4 * i, qn);
        quat_normalize(qn);
        memcpy(p->qp + 4 * i, qn, sizeof qn);
    }
    /* the skipped points that could hold the smallest δ − r */
    size_t m = 0;
    for (size_t t = 0; t < nskip; ++t)
        if (p->skip[5 * t + 4] < p->depth)
            memmove(p->skip + 5 * m++, p->skip + 5 * t, 5 * sizeof *p->skip);
    if (m > 1) /* (qsort must not see a NULL array, even empty) */
        qsort(p->skip, m, 5 * sizeof *p->skip, by_bound);
    for (size_t t = 0; t < m && p->skip[5 * t + 4] < p->depth; ++t) {
        double y[3], d;
        memcpy(y, p->skip + 5 * t, sizeof y);
        ++p->queries;
        push_point(p->collide, p->collide_user, p->skip[5 * t + 3], y, &d, NULL, NULL);
        p->depth = fmin(p->depth, d - p->skip[5 * t + 3]);
    }
}

void phc_particles_measure_stress(phc_particles *p, int on)
{
    if (p)
        p->no_stress = !on;
}

/* phc_particles_place of an existing particle i (the checks of its
 * values here, of i the caller's). */
static int place_checked(phc_particles *p, size_t i, const double x[3], const double q[4],
                         phc_error *err)
{
    const double r = q ? sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) : 0;
    if (!x || !q || !isfinite(x[0] + x[1] + x[2]) || !isfinite(r) || !(r > 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): place: position and "
                             "orientation must be finite (and the quaternion non-zero)",
                             i, p->source_id[i]);
    memcpy(p->x + 3 * i, x, 3 * sizeof(double));
    memcpy(p->xp + 3 * i, x, 3 * sizeof(double));
    for (int k = 0; k < 4; ++k)
        p->q[4 * i + k] = p->qp[4 * i + k] = q[k] / r;
    return PHC_OK;
}

int phc_particles_place(phc_particles *p, size_t i, const double x[3], const double q[4],
                        phc_error *err)
{
    if (!p || i >= p->n)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "particles: place: particle %zu does not exist (%zu particles)", i,
                             p ? p->n : 0);
    return place_checked(p, i, x, q, err);
}

int phc_particles_set_rest_place(phc_particles *p, size_t i, const double head[3],
                                 const double tail[3], double radius, const double x[3],
                                 const double dz[3], phc_error *err)
{
    if (!p || i >= p->n)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "particles: rest and place: particle %zu does not exist (%zu "
                             "particles)",
                             i, p ? p->n : 0);
    if (head || tail) {
        double L = 0;
        if (check_segment(p, i, head, tail, radius, &L, err))
            return err ? err->status : PHC_ERR_INPUT;
        rest_from_segment(p, i, head, tail, radius, L);
    }
    if (!x)
        return PHC_OK;
    if (!dz)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "particles: particle %zu: rest and place: direction NULL", i);
    double q[4];
    phc_quat_from_z_inline(dz, q);
    return place_checked(p, i, x, q, err);
}

/* ---- setters ------------------------------------------------------------ */

static int check_index(const phc_particles *p, size_t i, const char *what, phc_error *err)
{
    if (!p)
        return phc_error_set(err, PHC_ERR_INVALID, "particles: %s: no particle system", what);
    if (i >= p->n)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "particles: %s: particle %zu does not exist (%zu particles)", what, i,
                             p->n);
    return PHC_OK;
}

int phc_particles_set_mass(phc_particles *p, size_t i, double mass, phc_error *err)
{
    if (check_index(p, i, "mass", err))
        return err ? err->status : PHC_ERR_INVALID;
    if (!(mass > 0) || !isfinite(mass))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): mass must be positive and "
                             "finite, found %g kg",
                             i, p->source_id[i], mass);
    p->m[i] = mass;
    return PHC_OK;
}

int phc_particles_set_stiffness(phc_particles *p, size_t i, double s, phc_error *err)
{
    if (check_index(p, i, "stiffness", err))
        return err ? err->status : PHC_ERR_INVALID;
    if (!(s >= 0 && s <= 1))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): stiffness s must be in "
                             "[0, 1], found %g",
                             i, p->source_id[i], s);
    p->s[i] = s;
    return PHC_OK;
}

static int check_age(const phc_particles *p, size_t i, double age, phc_error *err)
{
    if (!(age >= 0) || !isfinite(age))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): age must be >= 0 and "
                             "finite, found %g s",
                             i, p->source_id[i], age);
    return PHC_OK;
}

static int check_strength(const phc_particles *p, size_t i, double k, phc_error *err)
{
    if (!(k > 0 && k <= 1))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): anchor strength must be in "
                             "(0, 1], found %g",
                             i, p->source_id[i], k);
    return PHC_OK;
}

int phc_particles_set_age(phc_particles *p, size_t i, double age, phc_error *err)
{
    if (check_index(p, i, "age", err))
        return err ? err->status : PHC_ERR_INVALID;
    if (check_age(p, i, age, err))
        return err ? err->status : PHC_ERR_INPUT;
    p->age[i] = age;
    return PHC_OK;
}

static int check_vec(const phc_particles *p, size_t i, const double a[3], const char *what,
                     const char *unit, phc_error *err)
{
    if (!a)
        return phc_error_set(err, PHC_ERR_INVALID, "particles: particle %zu: %s: NULL", i, what);
    for (int k = 0; k < 3; ++k)
        if (!isfinite(a[k]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "particles: particle %zu (segment %ld): %s %c must be finite, "
                                 "found %g %s",
                                 i, p->source_id[i], what, "xyz"[k], a[k], unit);
    return PHC_OK;
}

int phc_particles_set_position(phc_particles *p, size_t i, const double x[3], phc_error *err)
{
    if (check_index(p, i, "position", err))
        return err ? err->status : PHC_ERR_INVALID;
    if (check_vec(p, i, x, "position", "m", err))
        return err ? err->status : PHC_ERR_INPUT;
    for (int k = 0; k < 3; ++k) {
        p->x[3 * i + k] = p->xp[3 * i + k] = x[k];
        p->v[3 * i + k] = 0;
    }
    return PHC_OK;
}

int phc_particles_set_orientation(phc_particles *p, size_t i, const double q[4],
                                  phc_error *err)
{
    if (check_index(p, i, "orientation", err))
        return err ? err->status : PHC_ERR_INVALID;
    if (!q)
        return phc_error_set(err, PHC_ERR_INVALID, "particles: particle %zu: orientation: NULL", i);
    const double r = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!isfinite(r) || !(r > 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): orientation quaternion must "
                             "be finite and non-zero, found (%g, %g, %g, %g)",
                             i, p->source_id[i], q[0], q[1], q[2], q[3]);
    for (int k = 0; k < 4; ++k)
        p->q[4 * i + k] = p->qp[4 * i + k] = q[k] / r;
    for (int k = 0; k < 3; ++k)
        p->w[3 * i + k] = 0;
    /* warm start of its group's rotation: the particle's own turn from
     * rest, q q̄⁻¹ (the group turns with its owner) */
    const double q0i[4] = {p->q0[4 * i], -p->q0[4 * i + 1], -p->q0[4 * i + 2], -p->q0[4 * i + 3]};
    quat_mul(p->q + 4 * i, q0i, p->gq + 4 * i);
    return PHC_OK;
}

int phc_particles_set_force(phc_particles *p, size_t i, const double f[3], phc_error *err)
{
    if (check_index(p, i, "force", err))
        return err ? err->status : PHC_ERR_INVALID;
    if (check_vec(p, i, f, "force", "N", err))
        return err ? err->status : PHC_ERR_INPUT;
    memcpy(p->f + 3 * i, f, 3 * sizeof(double));
    return PHC_OK;
}

/* phc_particles_anchor of an existing particle i (its values checked
 * here, i by the caller). */
static inline int anchor_checked(phc_particles *p, size_t i, const double a[3], double k,
                                 int hold_orientation, phc_error *err)
{
    if (check_vec(p, i, a, "anchor point", "m", err))
        return err ? err->status : PHC_ERR_INPUT;
    if (check_strength(p, i, k, err))
        return err ? err->status : PHC_ERR_INPUT;
    p->anchored[i] = 1;
    p->anchor_k[i] = k;
    memcpy(p->anchor_at + 3 * i, a, 3 * sizeof(double));
    if (hold_orientation && !p->hold_q[i])
        memcpy(p->anchor_q + 4 * i, p->q + 4 * i, 4 * sizeof(double));
    p->hold_q[i] = hold_orientation != 0;
    return PHC_OK;
}

int phc_particles_anchor(phc_particles *p, size_t i, const double a[3], double k,
                         int hold_orientation, phc_error *err)
{
    if (check_index(p, i, "anchor", err))
        return err ? err->status : PHC_ERR_INVALID;
    return anchor_checked(p, i, a, k, hold_orientation, err);
}

int phc_particles_release(phc_particles *p, size_t i, phc_error *err)
{
    if (check_index(p, i, "release", err))
        return err ? err->status : PHC_ERR_INVALID;
    p->anchored[i] = 0;
    p->hold_q[i] = 0;
    return PHC_OK;
}

/* phc_particles_set_age_anchor of an existing particle i (its values
 * checked here, i by the caller). */
static inline int age_anchor_checked(phc_particles *p, size_t i, double age, const double a[3],
                                     double k, phc_error *err)
{
    if (check_age(p, i, age, err))
        return err ? err->status : PHC_ERR_INPUT;
    p->age[i] = age;
    if (!(k > 0)) { /* released */
        p->anchored[i] = 0;
        p->hold_q[i] = 0;
        return PHC_OK;
    }
    return anchor_checked(p, i, a, k, 0, err);
}

int phc_particles_set_age_anchor(phc_particles *p, size_t i, double age, const double a[3],
                                 double k, phc_error *err)
{
    if (check_index(p, i, "age and anchor", err))
        return err ? err->status : PHC_ERR_INVALID;
    return age_anchor_checked(p, i, age, a, k, err);
}

int phc_particles_set_ages_anchors(phc_particles *p, size_t first, size_t count,
                                   const double *age, const double *a, const double *k,
                                   size_t *bad, phc_error *err)
{
    if (!p || first > p->n || count > p->n - first) {
        if (bad)
            *bad = first;
        return phc_error_set(err, PHC_ERR_INVALID,
                             "particles: ages and anchors: %zu particles from particle %zu: "
                             "not all exist (%zu particles)",
                             count, first, p ? p->n : 0);
    }
    if (count && (!age || !a || !k)) {
        if (bad)
            *bad = first;
        return phc_error_set(err, PHC_ERR_INVALID, "particles: ages and anchors: NULL array");
    }
    for (size_t j = 0; j < count; ++j)
        if (age_anchor_checked(p, first + j, age[j], a + 3 * j, k[j], err)) {
            if (bad)
                *bad = first + j;
            return err ? err->status : PHC_ERR_INPUT;
        }
    return PHC_OK;
}

int phc_particles_attach(phc_particles *p, const double *points, size_t count, double distance,
                         double k, size_t *attached, phc_error *err)
{
    if (attached)
        *attached = 0;
    if (!p || (!points && count))
        return phc_error_set(err, PHC_ERR_INVALID, "particles: attach: NULL argument");
    if (!(distance > 0) || !isfinite(distance))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: attach: distance must be positive and finite, found %g m",
                             distance);
    if (!(k > 0 && k <= 1))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: attach: strength must be in (0, 1], found %g", k);
    for (size_t j = 0; j < 3 * count; ++j)
        if (!isfinite(points[j]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "particles: attach: support point %zu coordinate %c is not finite",
                                 j / 3, "xyz"[j % 3]);
    for (size_t i = 0; i < p->n; ++i) {
        if (p->anchored[i])
            continue;
        double best = INFINITY;
        size_t bj = 0;
        for (size_t j = 0; j < count; ++j) {
            double d2 = 0;
            for (int c = 0; c < 3; ++c) {
                const double d = points[3 * j + c] - p->x[3 * i + c];
                d2 += d * d;
            }
            if (d2 < best) {
                best = d2;
                bj = j;
            }
        }
        if (count && sqrt(best) <= distance) {
            p->anchored[i] = 1;
            p->hold_q[i] = 0;
            p->anchor_k[i] = k;
            memcpy(p->anchor_at + 3 * i, points + 3 * bj, 3 * sizeof(double));
            if (attached)
                ++*attached;
        }
    }
    return PHC_OK;
}

/* ---- groups ------------------------------------------------------------- */

/* Normaliser of particle i's blend weights: 1 (own group) + w_p (parent's
 * group, if linked) + 1 per linked child. */
static double weight_sum(const phc_particles *p, size_t i)
{
    double W = 1;
    if (p->linked[i])
        W += p->o.parent_weight;
    for (size_t c = p->child_start[i]; c < p->child_start[i + 1]; ++c)
        if (p->linked[p->child[c]])
            W += 1;
    return W;
}

/* What the step keeps of group k while the rest state, the masses and the
 * links stay as they are: its slots' members, blend weights ω_jk (0 for a
 * broken link), masses μ_jk = ω_jk m_j, rest offsets x̄_j − c̄_k, the group's
 * mass Σ μ and Σ μ |x̄_j − c̄_k|².  Writes group k's slots only. */
static void group_statics(phc_particles *p, size_t k)
{
    const size_t o = p->goff[k], e = p->goff[k + 1];
    p->mem[o] = k;
    p->om[o] = 1.0 / weight_sum(p, k);
    p->mem[o + 1] = p->linked[k] ? p->parent[k] : k;
    p->om[o + 1] = p->linked[k] ? 1.0 / weight_sum(p, p->parent[k]) : 0.0;
    for (size_t c = p->child_start[k]; c < p->child_start[k + 1]; ++c) {
        const size_t ch = p->child[c], sl = o + 2 + (c - p->child_start[k]);
        p->mem[sl] = ch;
        p->om[sl] = p->linked[ch] ? p->o.parent_weight / weight_sum(p, ch) : 0.0;
    }
    double M = 0, c0[3] = {0, 0, 0};
    for (size_t a = o; a < e; ++a) {
        const size_t j = p->mem[a];
        p->mu[a] = p->om[a] * p->m[j];
        M += p->mu[a];
        for (int d = 0; d < 3; ++d)
            c0[d] += p->mu[a] * p->x0[3 * j + d];
    }
    for (int d = 0; d < 3; ++d)
        c0[d] /= M;
    double den = 0;
    for (size_t a = o; a < e; ++a) {
        const size_t j = p->mem[a];
        for (int d = 0; d < 3; ++d) {
            p->d0[3 * a + d] = p->x0[3 * j + d] - c0[d];
            den += p->mu[a] * p->d0[3 * a + d] * p->d0[3 * a + d];
        }
    }
    p->gM[k] = M;
    p->gden[k] = den;
}

/* The ellipsoid term of particle j turned to the orientation Q_j:
 * R_j D_j R̄_jᵀ / 5 = R(Q_j) · ell0_j into p->ell (m²). */
static void ellipsoid_term(phc_particles *p, size_t j, const double *Q)
{
    if (p->ell0_stale[j]) { /* (only j's own data: safe on j's thread) */
        rest_moment(p, j);
        p->ell0_stale[j] = 0;
    }
    double Rj[9];
    phc_quat_to_matrix(Q + 4 * j, Rj);
    const double *E = p->ell0 + 9 * j;
    double *F = p->ell + 9 * j;
    for (int r = 0; r < 3; ++r)
        for (int s = 0; s < 3; ++s)
            F[3 * r + s] = Rj[3 * r] * E[s] + Rj[3 * r + 1] * E[3 + s] + Rj[3 * r + 2] * E[6 + s];
}

/* Shape matching of group k against positions X (3n) and the ellipsoid
 * terms in p->ell, with the statics of group_statics: its goals into its
 * slots (p->goal), its rotation into p->gq (warm-started there) and R
 * (row-major); *stress (may be NULL) gets σ_k.  Touches only group k's
 * slots and rotation, so distinct groups may run concurrently.  Returns
 * 0, or −1 when the moment matrix is not finite. */
static int match_group(phc_particles *p, size_t k, const double *X, double R[9],
                       double *stress, size_t *polar_total, size_t *polar_fallbacks)
{
    const size_t o = p->goff[k], e = p->goff[k + 1];
    const double *xk = X + 3 * k;
    /* A = Σ μ (x − c)(x̄ − c̄)ᵀ + Σ μ R_j D_j R̄_jᵀ / 5 (Müller & Chentanez
     * eq. 9 with the ellipsoid moment of eq. 10), summed as Σ μ (x − x_k)
     * (x̄ − c̄)ᵀ: the same, since Σ μ (x̄ − c̄) = 0, and no pass for c first */
    double A[9] = {0}, cs[3] = {0, 0, 0};
    for (size_t a = o; a < e; ++a) {
        const double mu = p->mu[a];
        if (mu == 0)
            continue;
        const size_t j = p->mem[a];
        const double *F = p->ell + 9 * j, *d0 = p->d0 + 3 * a;
        const double dx[3] = {X[3 * j] - xk[0], X[3 * j + 1] - xk[1], X[3 * j + 2] - xk[2]};
        const double md[3] = {mu * d0[0], mu * d0[1], mu * d0[2]};
        for (int d = 0; d < 3; ++d)
            cs[d] += mu * dx[d];
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
                A[3 * r + s] += dx[r] * md[s] + mu * F[3 * r + s];
    }
    double c[3];
    for (int d = 0; d < 3; ++d)
        c[d] = xk[d] + cs[d] / p->gM[k];
    const int how = phc_particles_polar_rotation_warm(A, p->gq + 4 * k, R, NULL);
    if (how < 0)
        return -1;
    ++*polar_total;
    *polar_fallbacks += how == 1;
    double num = 0;
    size_t members = 0;
    for (size_t a = o; a < e; ++a) {
        if (p->mu[a] == 0)
            continue;
        ++members;
        double rd[3];
        mat_vec(R, p->d0 + 3 * a, rd);
        double *g = p->goal + 3 * a;
        const double *xj = X + 3 * p->mem[a];
        for (int d = 0; d < 3; ++d) {
            g[d] = rd[d] + c[d];
            num += p->mu[a] * (xj[d] - g[d]) * (xj[d] - g[d]);
        }
    }
    if (stress) /* one particle: 0 */
        *stress = members > 1 && p->gden[k] > 0 ? sqrt(num / p->gden[k]) : 0.0;
    return 0;
}

size_t phc_particles_group_goals(const phc_particles *p, size_t k, size_t cap, size_t *member,
                                 double *goal, double R[9], double *stress)
{
    if (!p || k >= p->n)
        return 0;
    phc_particles *pm = (phc_particles *)p; /* scratch only; state unchanged */
    if (pm->layout_dirty)
        relayout(pm); /* derived from the parents: not a change of state */
    double gq_keep[4];
    memcpy(gq_keep, pm->gq + 4 * k, sizeof gq_keep);
    double Rl[9], st;
    size_t tot = 0, fb = 0;
    const size_t o = p->goff[k], e = p->goff[k + 1];
    group_statics(pm, k);
    for (size_t a = o; a < e; ++a) /* the members' ellipsoid terms */
        ellipsoid_term(pm, p->mem[a], p->q);
    const int rc = match_group(pm, k, p->x, Rl, &st, &tot, &fb);
    memcpy(pm->gq + 4 * k, gq_keep, sizeof gq_keep);
    if (rc < 0)
        return 0;
    size_t n = 0;
    for (size_t a = o; a < e; ++a)
        n += p->mu[a] != 0;
    if (n > cap)
        return 0;
    n = 0;
    for (size_t a = o; a < e; ++a) {
        if (p->mu[a] == 0)
            continue;
        if (member)
            member[n] = p->mem[a];
        if (goal)
            memcpy(goal + 3 * n, p->goal + 3 * a, 3 * sizeof(double));
        ++n;
    }
    if (R)
        memcpy(R, Rl, sizeof Rl);
    if (stress)
        *stress = st;
    return n;
}

/* s_i in effect: own, or min(1, t_l / t_m) with a maturity age. */
/* 1 when anchored particle i is a base of the beam pass, held by its
 * support (anchors_carry_moment; particles.h). */
static inline int anchor_base(const phc_particles *p, size_t i)
{
    return p->o.anchors_carry_moment && p->anchored[i] && p->o.bending == PHC_PARTICLES_BEAM;
}

static inline double stiffness_of(const phc_particles *p, size_t i)
{
    if (p->o.maturity_age > 0) {
        const double s = p->age[i] / p->o.maturity_age; /* t_l / t_m */
        return s < 1 ? s : 1;
    }
    return p->s[i];
}

double phc_particles_stiffness(const phc_particles *p, size_t i)
{
    if (!p || i >= p->n)
        return NAN;
    return stiffness_of(p, i);
}

/* ---- the time step ------------------------------------------------------ */

/* The threads of a step: a large plant runs its step in one OpenMP
 * region, each thread taking a fixed share of every particle loop (static
 * chunks) with barriers between the passes; a small one runs it on the
 * calling thread (nth = 1, no barriers, no region). */
typedef struct crew {
    int tid, nth;
} crew;

static void share(const crew *c, size_t n, size_t *lo, size_t *hi)
{
    *lo = n * (size_t)c->tid / (size_t)c->nth;
    *hi = n * (size_t)(c->tid + 1) / (size_t)c->nth;
}

static void crew_barrier(const crew *c)
{
    if (c->nth > 1) {
#pragma omp barrier
    }
}

/* Marks particle j as needed at iteration t (its last) and lists it. */
static void need_particle(phc_particles *p, size_t j, int t, size_t *np)
{
    if (p->plev[j] < 0) {
        p->plev[j] = t;
        p->plist[(*np)++] = j;
    }
}

/* Group k is matched up to iteration t; its members are needed at t − 1. */
static void need_group(phc_particles *p, size_t k, int t, size_t *ng, size_t *np)
{
    if (p->glev[k] >= 0)
        return;
    p->glev[k] = t;
    p->gmatch[(*ng)++] = k;
    need_particle(p, k, t - 1, np);
    if (p->parent[k] != PHC_PLANT_NO_PARENT)
        need_particle(p, p->parent[k], t - 1, np);
    for (size_t c = p->child_start[k]; c < p->child_start[k + 1]; ++c)
        need_particle(p, p->child[c], t - 1, np);
}

/* Which projections can change the step's result (ours; exact).  With the
 * joint pass, a linked particle with s > 0 gets its final x_p and q_p from
 * follow_one, which reads its parent's final state, its rest state and its
 * last orientation q, never what the projections gave it; a pinned
 * particle (anchor k_a = 1, orientation held) ends at its anchor after any
 * blend.  The others (the "free" particles: roots, broken links, s = 0,
 * not pinned) keep their projected
 * state, which after N Jacobi iterations depends only on the groups near
 * them: with need_N = the free particles, iteration t must match the groups
 * with a member in need_t (M_t) and blend need_t, and need_{t−1} = the
 * members of M_t.  need_0 is predicted; everything else is left to the
 * joint pass.  Fills p->plist / p->gmatch (ordered by the last iteration
 * they are needed at, so each iteration's set is a prefix) and the prefix
 * lengths; all particles (use_lists = 0) when nearly all are needed. */
static void plan_projections(phc_particles *p)
{
    const size_t n = p->n;
    const int N = (int)p->o.iterations;
    p->use_lists = 0;
    for (int t = 0; t <= N; ++t)
        p->pcount[t] = p->gcount[t] = n;
    if (!p->o.follow_parent || p->project_all)
        return;
    size_t np = 0, ng = 0;
    p->npins = 0;
    for (size_t i = 0; i < n; ++i) {
        /* (reset here, in the same pass: below, only i's own are read
           before the pass ends; an early return leaves the lists unused) */
        p->plev[i] = p->glev[i] = -1;
        if (p->anchored[i] && p->anchor_k[i] == 1 && p->hold_q[i])
            p->pins[p->npins++] = i; /* pinned: x_p = a, q_p held after any blend */
        else if (!(p->linked[i] && (p->o.maturity_age > 0 ? p->age[i] > 0 : p->s[i] > 0)))
            need_particle(p, i, N, &np);
        if (np > n / 4)
            return; /* many free particles: project everything */
        /* (s_i > 0 read without the division: age > 0 when t_m > 0) */
    }
    /* anchored bases of the beam pass (anchors_carry_moment): their motion
       is the projections' too (a loop of its own: nothing when off) */
    if (p->o.anchors_carry_moment && p->o.bending == PHC_PARTICLES_BEAM)
        for (size_t i = 0; i < n; ++i) {
            if (p->anchored[i] && !(p->anchor_k[i] == 1 && p->hold_q[i]))
                need_particle(p, i, N, &np);
            if (np > n / 4)
                return;
        }
    /* need_t = plist[0 .. pcount[t]); M_t = gmatch[0 .. gcount[t]) */
    p->pcount[N] = np;
    for (int t = N; t >= 1; --t) {
        /* the groups of every particle needed at t: its own, its parent's,
         * its children's (the slots where it is a member) */
        const size_t upto = np;
        for (size_t a = 0; a < upto; ++a) {
            const size_t i = p->plist[a];
            if (p->plev[i] < t)
                continue;
            need_group(p, i, t, &ng, &np);
            if (p->parent[i] != PHC_PLANT_NO_PARENT)
                need_group(p, p->parent[i], t, &ng, &np);
            for (size_t c = p->child_start[i]; c < p->child_start[i + 1]; ++c)
                need_group(p, p->child[c], t, &ng, &np);
        }
        p->gcount[t] = ng;
        p->pcount[t - 1] = np;
        if (np > n / 2)
            return; /* most of the plant: project everything */
    }
    p->gcount[0] = 0;
    p->use_lists = 1;
}

void phc_particles_project_all(phc_particles *p, int on)
{
    if (p)
        p->project_all = on != 0;
}

void phc_particles_joint_lanes(phc_particles *p, int on)
{
    if (p)
        p->lanes_off = on == 0;
}

/* The anchor of particle i (eq. 5) on its predicted state: x_p ← x_p +
 * k_a (a − x_p), exactly a when k_a = 1; q_p ← the held orientation when
 * it is held. */
static void apply_anchor(phc_particles *p, size_t i)
{
    const double ka = p->anchor_k[i], *a = p->anchor_at + 3 * i;
    double *x = p->xp + 3 * i;
    for (int d = 0; d < 3; ++d)
        x[d] = ka == 1 ? a[d] : x[d] + ka * (a[d] - x[d]);
    if (p->hold_q[i])
        memcpy(p->qp + 4 * i, p->anchor_q + 4 * i, 4 * sizeof(double));
}

/* Predict (symplectic Euler) particle i: x_p = x + Δt (v + Δt a),
 * q_p = exp(ω Δt) q, and its ellipsoid term at q_p. */
static void predict(phc_particles *p, size_t i, double dt)
{
    for (int d = 0; d < 3; ++d) {
        const double a = p->o.gravity[d] + p->f[3 * i + d] / p->m[i];
        p->xp[3 * i + d] = p->x[3 * i + d] + dt * (p->v[3 * i + d] + dt * a);
    }
    double phi[3], dq[4];
    for (int d = 0; d < 3; ++d)
        phi[d] = p->w[3 * i + d] * dt;
    quat_exp(phi, dq);
    quat_mul(dq, p->q + 4 * i, p->qp + 4 * i);
    quat_normalize(p->qp + 4 * i);
    ellipsoid_term(p, i, p->qp);
}

/* Particle i's new predicted state: the blend of its groups' goals, its
 * own group's rotation, and its anchor; with `next`, its ellipsoid term
 * for the next projection.  Touches only particle i. */
static void blend(phc_particles *p, size_t i, int next)
{
    /* x_g,i = Σ_k ω_ik g_i^k over i's own group, its parent's group and
     * its children's groups, always in this order */
    double gs[3];
    const size_t own = p->goff[i];
    for (int d = 0; d < 3; ++d)
        gs[d] = p->om[own] * p->goal[3 * own + d];
    if (p->linked[i]) {
        const size_t sl = p->goff[p->parent[i]] + 2 + p->child_index[i];
        for (int d = 0; d < 3; ++d)
            gs[d] += p->om[sl] * p->goal[3 * sl + d];
    }
    for (size_t c = p->child_start[i]; c < p->child_start[i + 1]; ++c) {
        const size_t ch = p->child[c];
        if (!p->linked[ch])
            continue;
        const size_t sl = p->goff[ch] + 1;
        for (int d = 0; d < 3; ++d)
            gs[d] += p->om[sl] * p->goal[3 * sl + d];
    }
    const double s = stiffness_of(p, i);
    for (int d = 0; d < 3; ++d) /* x' = x_p + s (x_g − x_p) */
        p->xp[3 * i + d] += s * (gs[d] - p->xp[3 * i + d]);
    /* q_i = R_i q̄_i: own group's rotation applied to the rest pose. */
    quat_mul(p->gq + 4 * i, p->q0 + 4 * i, p->qp + 4 * i);
    quat_normalize(p->qp + 4 * i);
    if (p->anchored[i])
        apply_anchor(p, i);
    if (next)
        ellipsoid_term(p, i, p->qp);
}

/* Largest group index whose moment matrix was not finite (−1: none),
 * raised by any thread. */
static void raise_bad(long *bad, long k)
{
#pragma omp critical(phc_particles_bad)
    if (k > *bad)
        *bad = k;
}

/* The smallest failing particle index (n: none), lowered by any thread. */
static void lower_to(size_t *shared, size_t i)
{
#pragma omp critical(phc_particles_bad)
    if (i < *shared)
        *shared = i;
}

/* Entry t of a plan list (all particles without one). */
static inline size_t pick(const size_t *list, size_t t) { return list ? list[t] : t; }

/* Groups list[0 .. count) (list NULL: 0 .. count) matched against X; with
 * `stress`, σ_k into p->stress.  Barrier after the pass. */
static void match_pass(phc_particles *p, const crew *c, const size_t *list, size_t count,
                       const double *X, int stress, long *bad, size_t *tot, size_t *fb)
{
    size_t lo, hi;
    share(c, count, &lo, &hi);
    for (size_t t = lo; t < hi; ++t) {
        const size_t k = pick(list, t);
        double R[9], st = 0;
        if (match_group(p, k, X, R, stress ? &st : NULL, tot, fb) < 0)
            raise_bad(bad, (long)k);
        if (stress)
            p->stress[k] = st;
    }
    crew_barrier(c);
}

/* R(q) u (phc_quat_rotate: u + 2w (v × u) + 2 v × (v × u), v = Im q), and
 * R(q)(0, 0, h), the same with the zeros left out (the same numbers), here
 * so that the joint pass inlines them. */
static inline void rotate(const double q[4], const double u[3], double out[3])
{
    const double w = q[0], vx = q[1], vy = q[2], vz = q[3];
    const double tx = 2.0 * (vy * u[2] - vz * u[1]);
    const double ty = 2.0 * (vz * u[0] - vx * u[2]);
    const double tz = 2.0 * (vx * u[1] - vy * u[0]);
    out[0] = u[0] + w * tx + (vy * tz - vz * ty);
    out[1] = u[1] + w * ty + (vz * tx - vx * tz);
    out[2] = u[2] + w * tz + (vx * ty - vy * tx);
}

static inline void rotate_z(const double q[4], double h, double out[3])
{
    const double w = q[0], vx = q[1], vy = q[2], vz = q[3];
    const double tx = 2.0 * (vy * h), ty = 2.0 * -(vx * h);
    out[0] = w * tx - vz * ty;
    out[1] = w * ty + vz * tx;
    out[2] = h + (vx * ty - vy * tx);
}

/* The joint pass's rest terms of linked particle i with parent u
 * (p->joint, made again after a rest change): j_i = R(q̄_u)ᵀ (h̄_i − x̄_u)
 * (m) and q̄_u⁻¹ q̄_i, h̄_i its rest head, half = L_i/2 (m). */
static inline const double *joint_terms(phc_particles *p, size_t i, size_t u, double half)
{
    double *ju = p->joint + 7 * i, *rel = ju + 3;
    if (p->joint_epoch[i] <= p->rest_epoch[i] || p->joint_epoch[i] <= p->rest_epoch[u]) {
        const double *q0i = p->q0 + 4 * i, *q0u = p->q0 + 4 * u;
        double hr[3], hb[3];
        const double q0u_inv[4] = {q0u[0], -q0u[1], -q0u[2], -q0u[3]};
        rotate_z(q0i, half, hr);
        for (int d = 0; d < 3; ++d)
            hb[d] = p->x0[3 * i + d] - hr[d] - p->x0[3 * u + d];
        rotate(q0u_inv, hb, ju);
        quat_mul(q0u_inv, q0i, rel);
        p->joint_epoch[i] = p->epoch;
    }
    return ju;
}

/* The joint pass (particles.h, "Shoots that bend"), parents first.  For
 * each linked particle i with parent u (already placed this substep):
 *   joint      J  = x_u + R(q_u) j_i,   j_i = R(q̄_u)ᵀ (h̄_i − x̄_u) (m),
 *              the rest head h̄_i = x̄_i − R(q̄_i)(0, 0, L_i/2) held in u's frame;
 *   free turn  q_f = rot(R(q_i) ẑ → d/|d|) q_i, d = R(q_i)(0, 0, L_i/2) + Δt² a_i,
 *              a_i = g + f_i/m_i (m s⁻²): the last orientation turned by what
 *              the load moves the centre in one substep from rest
 *              (follow-the-leader, Müller, Kim, Chentanez 2012 §3, on a
 *              segment; no velocity: an inertial prediction whipped a
 *              0.5 m cantilever to 19 m/s);
 *   rest turn  q* = q_u q̄_u⁻¹ q̄_i (the rest relative rotation);
 *   joint      q_i = exp(k log(q* q_f⁻¹)) q_f, k = s Δt² / (s Δt² + (1 − s) T²)
 *              (one XPBD step of the angular constraint C = log(q* q_f⁻¹),
 *              compliance α̃ = (1 − s) T² / (s Δt²) per unit inverse inertia,
 *              λ reset every substep);
 *   centre     x_i = J + R(q_i)(0, 0, L_i/2) (the segment hangs from J);
 * then its anchor.  Each particle reads only its parent's new state: a
 * small plant runs in the pass's order on one thread, a large one hands
 * whole subtrees to the threads (follow_parents), with the same numbers,
 * so the result does not depend on the thread count. */
/* follow_parents' step for one linked particle i: reads its parent's
 * final xp, qp and its own state, writes its own xp, qp only, so
 * particles whose parents are placed may run in any order or at once. */
static void follow_one(phc_particles *p, size_t i, double dt2, double T2)
{
    const size_t u = p->parent[i];
    const double s = stiffness_of(p, i);
    const double k = s >= 1 ? 1.0 : s * dt2 / (s * dt2 + (1 - s) * T2);
    if (!(s > 0))
        return; /* s = 0: no hold */
    const double *qu = p->qp + 4 * u;
    const double half = p->ax[3 * i + 2];
    const double *ju = joint_terms(p, i, u, half), *rel = ju + 3;
    /* the joint J in u's current frame */
    double hr[3], J[3];
    rotate(qu, ju, J);
    for (int d = 0; d < 3; ++d)
        J[d] += p->xp[3 * u + d];
    /* the rest turn q* = q_u q̄_u⁻¹ q̄_i */
    double qs[4];
    quat_mul(qu, rel, qs);
    double *x = p->xp + 3 * i, *q = p->qp + 4 * i;
    if (k >= 1) {
        memcpy(q, qs, sizeof qs); /* s = 1: held at the rest angle */
        quat_normalize(q);
    } else {
        /* the free turn: the segment as it was, hung from J, its centre
         * moved by its load from rest, a Δt²: the shortest turn from its
         * axis e to the direction of d = (L/2) e + a Δt² (phc_quat_from_two_vectors,
         * (1 + e·d/|d|, e × d/|d|) normalised; a half turn there when they oppose) */
        double axis[3], dir[3], dq[4], qf[4];
        const double *qt = p->q + 4 * i, *f = p->f + 3 * i;
        rotate_z(qt, 1.0, axis);
        const int loaded = f[0] != 0 || f[1] != 0 || f[2] != 0;
        for (int d = 0; d < 3; ++d)
            dir[d] = half * axis[d] + dt2 * (p->o.gravity[d] + (loaded ? f[d] / p->m[i] : 0.0));
        const double dn2 = dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2];
        if (dn2 > 0) {
            /* with d not normalised: (|d| + e·d, e × d), whose squared
             * norm is 2|d|(|d| + e·d) for |e| = 1 (one division fewer) */
            const double dn = sqrt(dn2);
            const double c = axis[0] * dir[0] + axis[1] * dir[1] + axis[2] * dir[2];
            if (c < (-1.0 + 1e-12) * dn) {
                for (int d = 0; d < 3; ++d)
                    dir[d] /= dn;
                phc_quat_from_two_vectors(axis, dir, dq);
            } else {
                const double w = dn + c, inv = 1.0 / sqrt(2.0 * dn * w);
                dq[0] = w * inv;
                dq[1] = (axis[1] * dir[2] - axis[2] * dir[1]) * inv;
                dq[2] = (axis[2] * dir[0] - axis[0] * dir[2]) * inv;
                dq[3] = (axis[0] * dir[1] - axis[1] * dir[0]) * inv;
            }
            quat_mul(dq, qt, qf);
        } else {
            memcpy(qf, qt, sizeof qf);
        }
        /* the joint's spring: turn q_f by the fraction k toward q*,
         * exp(k log δ) q_f, δ = q* q_f⁻¹ = (cos φ, sin φ n): the spherical
         * interpolation from q_f to q* (Shoemake, SIGGRAPH 1985, "slerp"),
         *   q = [sin((1 − k)φ) q_f + sin(kφ) q*] / sin φ,
         * cos φ = q*·q_f (the 4-vector dot, the real part of δ), q* taken
         * as −q* when it is negative (δ's shorter turn), and with
         * sin((1 − k)φ) = sin φ cos kφ − cos φ sin kφ:
         *   q = (cos kφ − cos φ f) q_f + f q*,  f = sin kφ / sin φ,
         * sin φ = |q* − cos φ q_f| (the part of q* normal to q_f; two
         * quaternion products fewer than δ and exp(k log δ) q_f) */
        double c = qs[0] * qf[0] + qs[1] * qf[1] + qs[2] * qf[2] + qs[3] * qf[3];
        const double sg = c < 0 ? -1.0 : 1.0;
        c *= sg;
        double qn[4], w2 = 0;
        for (int d = 0; d < 4; ++d) {
            qn[d] = sg * qs[d];
            const double w = qn[d] - c * qf[d];
            w2 += w * w;
        }
        const double sn = sqrt(w2);
        /* (1/sin φ first: the division runs beside the angle, not after it) */
        const double isn = sn > 1e-8 ? 1.0 / sn : 0.0;
        const double phi = phc_angle_unit(c, sn); /* libm's atan2 to about an ulp */
        double sk, ck;
        phc_sincos_first_quadrant(k * phi, &sk, &ck); /* kφ ≤ φ ≤ π/2 */
        /* sin(kφ)/sin φ, by its limit k/cos φ below 1e-8 (error ~ sn²) */
        const double fac = sn > 1e-8 ? sk * isn : k / c, a = ck - c * fac;
        for (int d = 0; d < 4; ++d)
            q[d] = a * qf[d] + fac * qn[d];
        /* normalised: |q|² = 1 + η, η of rounding size here (a slerp of
         * unit quaternions), so 1/|q| = (3 − |q|²)/2 to (3/8)η²: no square
         * root and division in the chain that runs from link to link along
         * a shoot; 1/sqrt beyond |η| = 1e-8 */
        const double n2 = (q[0] * q[0] + q[1] * q[1]) + (q[2] * q[2] + q[3] * q[3]);
        double rn;
        if (__builtin_expect(fabs(n2 - 1) <= 1e-8, 1))
            rn = 1.5 - 0.5 * n2;
        else
            rn = 1.0 / sqrt(n2);
        for (int d = 0; d < 4; ++d)
            q[d] *= rn;
    }
    rotate_z(q, half, hr);
    for (int d = 0; d < 3; ++d)
        x[d] = J[d] + hr[d];
    if (p->anchored[i]) /* as after every projection */
        apply_anchor(p, i);
}


/* ---- the beam joint pass (particles.h, "Shoots that bend like beams") -- */

/* p->beam, per particle (BEAM_PER doubles): the articulated-body terms of
 * its joint, made by beam_articulate, read by beam_one.  Spatial vectors
 * are 6-vectors in world axes about the step's reference point O (particle
 * 0's centre at the step's start, so that the sums stay well conditioned):
 * motion (ω; v_O), force (n_O; f) (Featherstone, "Rigid Body Dynamics
 * Algorithms", 2008, ch. 2 and 7). */
enum {
    BEAM_IA = 0,    /* 36: articulated inertia I^A (6x6, row-major; kg m², kg m, kg) */
    BEAM_PA = 36,   /* 6: articulated bias force p^A (N m, N) */
    BEAM_U = 42,    /* 18: U = I^A S (6x3) */
    BEAM_DINV = 60, /* 9: D⁻¹, D = Sᵀ U + Δt² κ 1 (3x3) */
    BEAM_UU = 69,   /* 3: u = τ − Sᵀ p^A (N m) */
    BEAM_TH = 72,   /* 3: the bend θ at the step's start (rad) */
    BEAM_WR = 75,   /* 3: the joint's angular velocity ω_i − ω_u (rad/s) */
    BEAM_J = 78,    /* 3: the joint J − O at the step's start (m) */
    BEAM_ACC = 81,  /* 6: the body's spatial acceleration (rad s⁻², m s⁻²) */
    BEAM_PER = 87
};
enum { BEAM_BASE, BEAM_WELD, BEAM_BALL };

/* How particle i hangs in the beam pass: BALL (linked, 0 < s < 1: a
 * spherical joint with a spring), WELD (linked, s = 1: held at its rest
 * angle, part of its parent's body), BASE (not linked, or s = 0, or
 * anchored with anchors_carry_moment: not held by its parent; its motion
 * is the projections' and its anchor's, its children hang from it). */
static inline int beam_kind(const phc_particles *p, size_t i)
{
    if (!p->linked[i] || anchor_base(p, i))
        return BEAM_BASE;
    const double s = stiffness_of(p, i);
    return !(s > 0) ? BEAM_BASE : s >= 1 ? BEAM_WELD : BEAM_BALL;
}

/* y = A x, A 6x6 row-major. */
static inline void mv6(const double *A, const double *x, double *y)
{
    for (int r = 0; r < 6; ++r) {
        double t = 0;
        for (int c = 0; c < 6; ++c)
            t += A[6 * r + c] * x[c];
        y[r] = t;
    }
}

/* The inverse of a symmetric positive definite 3x3 matrix (adjugate). */
static inline void inv3_sym(const double *D, double *Di)
{
    const double c00 = D[4] * D[8] - D[5] * D[7], c01 = D[5] * D[6] - D[3] * D[8];
    const double c02 = D[3] * D[7] - D[4] * D[6];
    const double det = D[0] * c00 + D[1] * c01 + D[2] * c02, inv = 1 / det;
    Di[0] = c00 * inv;
    Di[1] = Di[3] = c01 * inv;
    Di[2] = Di[6] = c02 * inv;
    Di[4] = (D[0] * D[8] - D[2] * D[6]) * inv;
    Di[5] = Di[7] = (D[2] * D[3] - D[0] * D[5]) * inv;
    Di[8] = (D[0] * D[4] - D[1] * D[3]) * inv;
}

/* The rotation vector θ (rad) of the unit quaternion a b⁻¹ (the shorter
 * way round). */
static inline void rotation_between(const double a[4], const double b[4], double th[3])
{
    const double binv[4] = {b[0], -b[1], -b[2], -b[3]};
    double d[4];
    quat_mul(a, binv, d);
    if (d[0] < 0)
        for (int k = 0; k < 4; ++k)
            d[k] = -d[k];
    const double sn = sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
    const double fac = sn > 0 ? 2 * atan2(sn, d[0]) / sn : 2.0;
    for (int k = 0; k < 3; ++k)
        th[k] = fac * d[1 + k];
}

/* Joint i's spring κ (N m rad⁻¹; particles.h): E(s) π r⁴ / (4 ℓ̄), ℓ̄ =
 * (L_i + L_u)/2 when its parent u bends (BALL), else L_i/2. */
static inline double beam_kappa(const phc_particles *p, size_t i, size_t u, double s)
{
    const double r = p->ax[3 * i];
    const double lbar = p->ax[3 * i + 2] + (beam_kind(p, u) == BEAM_BALL ? p->ax[3 * u + 2] : 0.0);
    return p->o.beam_modulus * s / (1 - s) * PI * r * r * r * r / (4 * lbar);
}

/* The articulated-body pass (Featherstone's ABA, its second sweep:
 * children before parents) at the step's start: every body's spatial
 * inertia about O and its external force (beam_body), then every BALL
 * joint's U, D⁻¹ and u with the joint's armature Δt² κ and force τ = −κ
 * (θ + Δt ω_rel) (the implicit spring), the subtree folded into its
 * parent (beam_fold: a WELD wholly, a BALL through its joint).  The
 * velocity-product terms are left out (slow shoots). */
static void beam_body(phc_particles *p, size_t i, const double O[3])
{
    double *b = p->beam + BEAM_PER * i, *Ib = b + BEAM_IA, e[3], c[3];
    const double m = p->m[i], *f = p->f + 3 * i;
    const double r2 = p->ax[3 * i] * p->ax[3 * i], h = p->ax[3 * i + 2];
    for (int d = 0; d < 3; ++d)
        c[d] = p->x[3 * i + d] - O[d];
    rotate_z(p->q + 4 * i, 1.0, e);
    /* the cylinder about its centre: m r²/2 about e, m (3r² + L²)/12 across,
     * I_c = m (a 1 + (b − a) e eᵀ), a = r²/4 + L²/12, b = r²/2 */
    const double a = r2 / 4 + h * h / 3, ba = r2 / 2 - a;
    const double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
            /* top left: I_c + m ([c]× [c]×ᵀ = |c|² 1 − c cᵀ) */
            Ib[6 * r + k] = m * ((r == k ? a + cc : 0.0) + ba * e[r] * e[k] - c[r] * c[k]);
            Ib[6 * (r + 3) + k + 3] = r == k ? m : 0.0;
        }
    /* top right m [c]×, bottom left its transpose */
    const double mc[3] = {m * c[0], m * c[1], m * c[2]};
    const double sk[9] = {0, -mc[2], mc[1], mc[2], 0, -mc[0], -mc[1], mc[0], 0};
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
            Ib[6 * r + k + 3] = sk[3 * r + k];
            Ib[6 * (k + 3) + r] = sk[3 * r + k];
        }
    /* bias: minus the external force f at the centre, (c × f; f) */
    double *pa = b + BEAM_PA;
    pa[0] = -(c[1] * f[2] - c[2] * f[1]);
    pa[1] = -(c[2] * f[0] - c[0] * f[2]);
    pa[2] = -(c[0] * f[1] - c[1] * f[0]);
    for (int d = 0; d < 3; ++d)
        pa[3 + d] = -f[d];
}

static void beam_fold(phc_particles *p, size_t i, double dt, const double O[3])
{
    const int kind = beam_kind(p, i);
    if (kind == BEAM_BASE)
        return;
    const size_t u = p->parent[i];
    double *b = p->beam + BEAM_PER * i, *bu = p->beam + BEAM_PER * u;
    double *IA = b + BEAM_IA, *pA = b + BEAM_PA;
    if (kind == BEAM_WELD) {
        for (int k = 0; k < 36; ++k)
            bu[BEAM_IA + k] += IA[k];
        for (int k = 0; k < 6; ++k)
            bu[BEAM_PA + k] += pA[k];
        return;
    }
    /* the joint at the step's start: J, the rest turn q*, the bend θ */
    const double half = p->ax[3 * i + 2], s = stiffness_of(p, i);
    const double *ju = joint_terms(p, i, u, half), *rel = ju + 3;
    double *J = b + BEAM_J, *th = b + BEAM_TH, *wr = b + BEAM_WR, qs[4];
    rotate(p->q + 4 * u, ju, J);
    for (int d = 0; d < 3; ++d)
        J[d] += p->x[3 * u + d] - O[d];
    quat_mul(p->q + 4 * u, rel, qs);
    rotation_between(p->q + 4 * i, qs, th);
    for (int d = 0; d < 3; ++d)
        wr[d] = p->w[3 * i + d] - p->w[3 * u + d];
    const double kappa = beam_kappa(p, i, u, s);
    /* S = [1; [J]×] (a turn about J moves O by J × ω), so for a row a =
     * (a₁; a₂) of I^A, (a S) = a₁ + a₂ × J (a₂ · (J × e_k) = e_k · (a₂ × J));
     * U = I^A S row by row */
    double *U = b + BEAM_U, D[9];
    for (int r = 0; r < 6; ++r) {
        const double *a = IA + 6 * r;
        U[3 * r] = a[0] + a[4] * J[2] - a[5] * J[1];
        U[3 * r + 1] = a[1] + a[5] * J[0] - a[3] * J[2];
        U[3 * r + 2] = a[2] + a[3] * J[1] - a[4] * J[0];
    }
    /* D = Sᵀ U + Δt² κ 1 (column k: U₁ₖ + U₂ₖ × J by the same rule),
     * u = τ − Sᵀ p^A, τ = −κ (θ + Δt ω_rel) */
    for (int k = 0; k < 3; ++k) {
        const double u0 = U[9 + k], u1 = U[12 + k], u2 = U[15 + k];
        D[k] = U[k] + u1 * J[2] - u2 * J[1];
        D[3 + k] = U[3 + k] + u2 * J[0] - u0 * J[2];
        D[6 + k] = U[6 + k] + u0 * J[1] - u1 * J[0];
    }
    D[0] += dt * dt * kappa;
    D[4] += dt * dt * kappa;
    D[8] += dt * dt * kappa;
    double *uu = b + BEAM_UU;
    const double sp[3] = {pA[0] + pA[4] * J[2] - pA[5] * J[1], pA[1] + pA[5] * J[0] - pA[3] * J[2],
                          pA[2] + pA[3] * J[1] - pA[4] * J[0]};
    for (int r = 0; r < 3; ++r)
        uu[r] = -kappa * (th[r] + dt * wr[r]) - sp[r];
    /* (symmetrised: D is symmetric up to rounding) */
    D[1] = D[3] = 0.5 * (D[1] + D[3]);
    D[2] = D[6] = 0.5 * (D[2] + D[6]);
    D[5] = D[7] = 0.5 * (D[5] + D[7]);
    double *Di = b + BEAM_DINV;
    inv3_sym(D, Di);
    /* into the parent: I^A − U D⁻¹ Uᵀ and p^A + U D⁻¹ u */
    double UD[18], Dv[3];
    for (int r = 0; r < 6; ++r)
        for (int k = 0; k < 3; ++k)
            UD[3 * r + k] = U[3 * r] * Di[k] + U[3 * r + 1] * Di[3 + k] + U[3 * r + 2] * Di[6 + k];
    for (int k = 0; k < 3; ++k)
        Dv[k] = Di[3 * k] * uu[0] + Di[3 * k + 1] * uu[1] + Di[3 * k + 2] * uu[2];
    for (int r = 0; r < 6; ++r) {
        /* (symmetric: the upper triangle, mirrored) */
        for (int k = r; k < 6; ++k) {
            const double v =
                IA[6 * r + k] - (UD[3 * r] * U[3 * k] + UD[3 * r + 1] * U[3 * k + 1] + UD[3 * r + 2] * U[3 * k + 2]);
            bu[BEAM_IA + 6 * r + k] += v;
            if (k != r)
                bu[BEAM_IA + 6 * k + r] += v;
        }
        bu[BEAM_PA + r] += pA[r] + U[3 * r] * Dv[0] + U[3 * r + 1] * Dv[1] + U[3 * r + 2] * Dv[2];
    }
}

/* The second sweep over the joint pass's order: the bodies (by index),
 * then each subtree item from its end to its second particle (children
 * before parents, inside the item), the items on the threads of a team;
 * then on one thread the items' roots (folding into the top) and the top
 * backwards.  Every parent gets its children's folds in the same order
 * for any thread count.  -1 when out of memory. */
static int beam_articulate(phc_particles *p, double dt)
{
    const size_t n = p->n;
    if (p->beam_cap < n) {
        double *t = realloc(p->beam, BEAM_PER * p->cap * sizeof *t);
        if (!t)
            return -1;
        p->beam = t;
        p->beam_cap = p->cap;
    }
    const double O[3] = {p->x[0], p->x[1], p->x[2]};
    const size_t *order = p->follow_order, *start = p->follow_start;
    size_t next = 0;
    if (team((long)n)) {
#pragma omp parallel
        {
#pragma omp for schedule(static)
            for (long i = 0; i < (long)n; ++i)
                beam_body(p, (size_t)i, O);
            for (;;) {
                size_t item;
#pragma omp atomic capture
                item = next++;
                if (item >= p->follow_items)
                    break;
                for (size_t t = start[item + 1]; t-- > start[item] + 1;)
                    beam_fold(p, order[t], dt, O);
            }
        }
    } else {
        for (size_t i = 0; i < n; ++i)
            beam_body(p, i, O);
        for (size_t item = 0; item < p->follow_items; ++item)
            for (size_t t = start[item + 1]; t-- > start[item] + 1;)
                beam_fold(p, order[t], dt, O);
    }
    for (size_t item = 0; item < p->follow_items; ++item)
        beam_fold(p, order[start[item]], dt, O);
    for (size_t t = p->follow_top; t-- > 0;)
        beam_fold(p, order[t], dt, O);
    return 0;
}

/* The beam joint of linked particle i (particles.h; the ABA's third sweep,
 * parents first): its parent's spatial acceleration a_u (gravity's
 * (0; −g) for a BASE parent), α = D⁻¹ (u − Uᵀ a_u), its own a = a_u + S α;
 * ω⁺ = ω_rel + Δt α, θ⁺ = θ + Δt ω⁺, then q = exp(θ⁺) q*, x = J +
 * R(q)(0, 0, L/2) from its parent's final state.  Reads its parent's
 * final xp, qp and acceleration, writes its own xp, qp and acceleration
 * only (as follow_one). */
static void beam_one(phc_particles *p, size_t i, double dt, double T2)
{
    const int kind = beam_kind(p, i);
    if (kind == BEAM_BASE) { /* s = 0: no hold */
        if (anchor_base(p, i)) /* held by its support: its orientation kept */
            memcpy(p->qp + 4 * i, p->q + 4 * i, 4 * sizeof(double));
        return;
    }
    const size_t u = p->parent[i];
    double *b = p->beam + BEAM_PER * i, *acc = b + BEAM_ACC;
    double au[6];
    if (beam_kind(p, u) == BEAM_BASE) {
        for (int d = 0; d < 3; ++d) {
            au[d] = 0;
            au[3 + d] = -p->o.gravity[d];
        }
    } else {
        memcpy(au, p->beam + BEAM_PER * u + BEAM_ACC, sizeof au);
    }
    if (kind == BEAM_WELD) {
        memcpy(acc, au, sizeof au);
        follow_one(p, i, dt * dt, T2); /* held at the rest angle, exactly */
        return;
    }
    const double *U = b + BEAM_U, *Di = b + BEAM_DINV, *uu = b + BEAM_UU, *J0 = b + BEAM_J;
    double rhs[3], alpha[3], th[3];
    for (int k = 0; k < 3; ++k) {
        double sum = uu[k];
        for (int r = 0; r < 6; ++r)
            sum -= U[3 * r + k] * au[r];
        rhs[k] = sum;
    }
    for (int k = 0; k < 3; ++k)
        alpha[k] = Di[3 * k] * rhs[0] + Di[3 * k + 1] * rhs[1] + Di[3 * k + 2] * rhs[2];
    /* a = a_u + S α = (α_u + α; a_O,u + J × α) */
    for (int d = 0; d < 3; ++d)
        acc[d] = au[d] + alpha[d];
    acc[3] = au[3] + J0[1] * alpha[2] - J0[2] * alpha[1];
    acc[4] = au[4] + J0[2] * alpha[0] - J0[0] * alpha[2];
    acc[5] = au[5] + J0[0] * alpha[1] - J0[1] * alpha[0];
    for (int d = 0; d < 3; ++d)
        th[d] = b[BEAM_TH + d] + dt * (b[BEAM_WR + d] + dt * alpha[d]);
    /* the new state from the parent's: q = exp(θ⁺) q*, x = J + R(q)(0, 0, L/2) */
    const double half = p->ax[3 * i + 2];
    const double *ju = joint_terms(p, i, u, half), *rel = ju + 3, *qu = p->qp + 4 * u;
    double dq[4], hr[3], J[3], qs[4];
    quat_exp(th, dq);
    rotate(qu, ju, J);
    for (int d = 0; d < 3; ++d)
        J[d] += p->xp[3 * u + d];
    quat_mul(qu, rel, qs);
    double *x = p->xp + 3 * i, *q = p->qp + 4 * i;
    quat_mul(dq, qs, q);
    quat_normalize(q);
    rotate_z(q, half, hr);
    for (int d = 0; d < 3; ++d)
        x[d] = J[d] + hr[d];
    if (p->anchored[i])
        apply_anchor(p, i);
}

/* The bending stress at the head joint of particle i in its current state
 * (particles.h, "Breaking under a bending stress"): a BALL joint's moment
 * M = κ |θ| (N m; θ = log(q_i q*⁻¹), q* = q_u q̄_u⁻¹ q̄_i its rest turn)
 * at the surface of a circular section, σ = M r / I_a = 4 M / (π r³)
 * (Pa); 0 for a WELD, a BASE or an unlinked particle. */
static double bend_stress_of(const phc_particles *p, size_t i)
{
    if (beam_kind(p, i) != BEAM_BALL)
        return 0.0;
    const size_t u = p->parent[i];
    const double *q0i = p->q0 + 4 * i, *q0u = p->q0 + 4 * u;
    const double q0u_inv[4] = {q0u[0], -q0u[1], -q0u[2], -q0u[3]};
    double rel[4], qs[4], th[3];
    quat_mul(q0u_inv, q0i, rel);
    quat_mul(p->q + 4 * u, rel, qs);
    rotation_between(p->q + 4 * i, qs, th);
    const double r = p->ax[3 * i];
    const double M = beam_kappa(p, i, u, stiffness_of(p, i)) * sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]);
    return 4 * M / (PI * r * r * r);
}

double phc_particles_bend_stress(const phc_particles *p, size_t i)
{
    if (!p || i >= p->n || p->o.bending != PHC_PARTICLES_BEAM)
        return 0.0;
    return bend_stress_of(p, i);
}

/* follow_order[lo .. hi) (the top or an item: parents before children)
 * into lane_order[lo .. hi), stably sorted by the depth in it (0: the
 * item's root, or a root of the plant in the top; a particle's parent is
 * in the range otherwise), the depths into lane_level (a counting sort;
 * dep, cnt: scratch of n each). */
static void lanes_by_depth(phc_particles *p, size_t lo, size_t hi, size_t *dep, size_t *cnt)
{
    const size_t *order = p->follow_order;
    size_t deepest = 0;
    for (size_t t = lo; t < hi; ++t) {
        const size_t i = order[t], u = p->parent[i];
        dep[i] = t == lo || u == PHC_PLANT_NO_PARENT ? 0 : dep[u] + 1;
        deepest = dep[i] > deepest ? dep[i] : deepest;
    }
    if (hi == lo)
        return;
    for (size_t d = 0; d <= deepest; ++d) /* (deepest < hi − lo <= n) */
        cnt[d] = 0;
    for (size_t t = lo; t < hi; ++t)
        ++cnt[dep[order[t]]];
    for (size_t d = 0, sum = lo; d <= deepest; ++d) {
        const size_t c = cnt[d];
        cnt[d] = sum;
        sum += c;
    }
    for (size_t t = lo; t < hi; ++t) {
        const size_t i = order[t], at = cnt[dep[i]]++;
        p->lane_order[at] = i;
        p->lane_level[at] = dep[i];
    }
}

/* The joint pass's order (see struct phc_particles): subtree sizes, the
 * top of the tree (subtrees of more than n/32 + 1 particles, a set closed
 * upwards, in topological order), then each subtree hanging from the top
 * in preorder (parents before children).  O(n), from p->parent and the
 * children; the links may break later without changing it (an unlinked
 * particle is skipped). */
static void follow_order_build(phc_particles *p)
{
    const size_t n = p->n, limit = n / 32 + 1;
    size_t *sz = p->subtree, *order = p->follow_order, *stack = p->fstack;
    for (size_t i = 0; i < n; ++i)
        sz[i] = 1;
    for (size_t t = n; t-- > 0;) {
        const size_t i = p->topo[t];
        if (p->parent[i] != PHC_PLANT_NO_PARENT)
            sz[p->parent[i]] += sz[i];
    }
    size_t m = 0, items = 0;
    for (size_t t = 0; t < n; ++t)
        if (sz[p->topo[t]] > limit)
            order[m++] = p->topo[t];
    p->follow_top = m;
    for (size_t t = 0; t < n; ++t) {
        const size_t r = p->topo[t], u = p->parent[r];
        if (sz[r] > limit || (u != PHC_PLANT_NO_PARENT && sz[u] <= limit))
            continue; /* in the top, or inside another item */
        p->follow_start[items++] = m;
        size_t top = 0;
        stack[top++] = r;
        while (top) {
            const size_t i = stack[--top];
            order[m++] = i;
            for (size_t c = p->child_start[i + 1]; c-- > p->child_start[i];)
                stack[top++] = p->child[c];
        }
    }
    p->follow_start[items] = m;
    p->follow_items = items;
    /* the lanes' order: the top, then each item, sorted by depth (sz and
       the stack are free again) */
    lanes_by_depth(p, 0, p->follow_top, sz, stack);
    for (size_t item = 0; item < items; ++item)
        lanes_by_depth(p, p->follow_start[item], p->follow_start[item + 1], sz, stack);
    p->follow_dirty = 0;
}

/* follow_one over the order: the top on thread 0, then the subtrees, each
 * on one thread, taken in turn from a shared counter (each particle reads
 * only its parent's final state, so any order of the subtrees gives the
 * same numbers). */
/* 1 when particle i's predicted state is finite (x_p, and q_p's first
 * three components as always checked). */
static inline int state_finite(const phc_particles *p, size_t i)
{
    return isfinite(p->xp[3 * i]) && isfinite(p->xp[3 * i + 1]) && isfinite(p->xp[3 * i + 2]) &&
           isfinite(p->qp[4 * i]) && isfinite(p->qp[4 * i + 1]) && isfinite(p->qp[4 * i + 2]);
}

/* atan2(s, c) for s >= 0, c > 0 (a unit quaternion's half angle): by the
 * series t − t³/3 + ... − t¹¹/11 of atan t, t = s/c, when t < 0.03 (the
 * next term is below 4e-20 of the sum: rounding), else atan2.  A step's
 * turn of a particle is small (all of the 29569 particles' turns in the
 * bench's 0.25 s frames had t < 0.03). */
static inline double half_angle(double s, double c)
{
    if (!(s < 0.03 * c))
        return atan2(s, c);
    const double t = s / c, t2 = t * t;
    return t * (1 + t2 * (-1.0 / 3 + t2 * (1.0 / 5 + t2 * (-1.0 / 7 + t2 * (1.0 / 9 - t2 / 11)))));
}

/* Particle i's new velocity from its positions (PBD), then damping, its
 * new angular velocity from its turn, its new age: into p->vn, p->wn,
 * p->agen (the step swaps them in when it succeeds). */
static inline void finish_one(phc_particles *p, size_t i, double keep_dt, double dt)
{
    for (int d = 0; d < 3; ++d)
        p->vn[3 * i + d] = keep_dt * (p->xp[3 * i + d] - p->x[3 * i + d]);
    /* ω = (1 − damping) θ n / Δt, q_p q⁻¹ = (cos θ/2, sin θ/2 n) */
    const double inv[4] = {p->q[4 * i], -p->q[4 * i + 1], -p->q[4 * i + 2], -p->q[4 * i + 3]};
    double dq[4];
    quat_mul(p->qp + 4 * i, inv, dq);
    if (dq[0] < 0)
        for (int d = 0; d < 4; ++d)
            dq[d] = -dq[d];
    const double sn = sqrt(dq[1] * dq[1] + dq[2] * dq[2] + dq[3] * dq[3]);
    const double fac = sn > 0 ? keep_dt * 2 * half_angle(sn, dq[0]) / sn : 0.0;
    for (int d = 0; d < 3; ++d)
        p->wn[3 * i + d] = fac * dq[1 + d];
    p->agen[i] = p->age[i] + dt;
}

/* follow_one on the linked particles idx[0 .. nl) (nl <= 4), none of
 * them the parent of another, four lanes of phc_joint_lanes at once
 * (follow_one's numbers bit for bit): the lanes gathered (their rest
 * terms made when stale, as follow_one makes them), computed, scattered;
 * follow_one for the ones the lanes leave (s = 0 keeps its state), then
 * each one's anchor. */
static void follow_lanes(phc_particles *p, const size_t *idx, int nl, double dt2, double T2)
{
    phc_joint_lanes_in in;
    phc_joint_lanes_out out;
    size_t lane[4];
    int used = 0;
    for (int a = 0; a < nl; ++a) {
        const size_t i = idx[a], u = p->parent[i];
        const double s = stiffness_of(p, i);
        if (!(s > 0))
            continue; /* s = 0: no hold */
        const int l = used++;
        lane[l] = i;
        in.k[l] = s >= 1 ? 1.0 : s * dt2 / (s * dt2 + (1 - s) * T2);
        const double half = p->ax[3 * i + 2], *ju = joint_terms(p, i, u, half);
        const double *qu = p->qp + 4 * u, *qt = p->q + 4 * i, *f = p->f + 3 * i;
        const int loaded = f[0] != 0 || f[1] != 0 || f[2] != 0;
        in.half[l] = half;
        for (int d = 0; d < 4; ++d) {
            in.qu[d][l] = qu[d];
            in.rel[d][l] = ju[3 + d];
            in.qt[d][l] = qt[d];
        }
        for (int d = 0; d < 3; ++d) {
            in.xu[d][l] = p->xp[3 * u + d];
            in.ju[d][l] = ju[d];
            in.acc[d][l] = p->o.gravity[d] + (loaded ? f[d] / p->m[i] : 0.0);
        }
    }
    if (!used)
        return;
    for (int l = used; l < 4; ++l) { /* idle lanes: copies of lane 0 */
        in.k[l] = in.k[0];
        in.half[l] = in.half[0];
        for (int d = 0; d < 4; ++d) {
            in.qu[d][l] = in.qu[d][0];
            in.rel[d][l] = in.rel[d][0];
            in.qt[d][l] = in.qt[d][0];
        }
        for (int d = 0; d < 3; ++d) {
            in.xu[d][l] = in.xu[d][0];
            in.ju[d][l] = in.ju[d][0];
            in.acc[d][l] = in.acc[d][0];
        }
    }
    const int placed = phc_joint_lanes(&in, dt2, &out);
    for (int l = 0; l < used; ++l) {
        const size_t i = lane[l];
        if (!(placed >> l & 1)) {
            follow_one(p, i, dt2, T2); /* (its anchor too) */
            continue;
        }
        for (int d = 0; d < 4; ++d)
            p->qp[4 * i + d] = out.q[d][l];
        for (int d = 0; d < 3; ++d)
            p->xp[3 * i + d] = out.x[d][l];
        if (p->anchored[i]) /* as after every projection */
            apply_anchor(p, i);
    }
}

/* follow_one (beam_one for beams) on order[lo .. hi) (the linked ones),
 * the own-weight links four at a time (follow_lanes); with `check`, each
 * particle's new state is checked there, while it is in the cache (the
 * smallest non-finite index lowers *bad). */
static void follow_range(phc_particles *p, size_t lo, size_t hi, double dt, double T2, int check,
                         size_t *bad)
{
    const size_t *order = p->follow_order;
    const double dt2 = dt * dt;
    const int beam = p->o.bending == PHC_PARTICLES_BEAM;
    if (beam || p->lanes_off) { /* one link at a time, in the order */
        for (size_t t = lo; t < hi; ++t) {
            const size_t i = order[t];
            if (p->linked[i] && beam)
                beam_one(p, i, dt, T2);
            else if (p->linked[i])
                follow_one(p, i, dt2, T2);
            if (check && i < *bad && !state_finite(p, i))
                *bad = i;
        }
        return;
    }
    /* the same range sorted by depth: up to four linked links of one
     * depth at a time (no one of them waits for another) */
    const size_t *lorder = p->lane_order, *level = p->lane_level;
    for (size_t t = lo; t < hi;) {
        const size_t t0 = t, depth = level[t];
        size_t idx[4];
        int nl = 0;
        for (; t < hi && level[t] == depth && nl < 4; ++t)
            if (p->linked[lorder[t]])
                idx[nl++] = lorder[t];
        follow_lanes(p, idx, nl, dt2, T2);
        for (size_t a = t0; check && a < t; ++a)
            if (lorder[a] < *bad && !state_finite(p, lorder[a]))
                *bad = lorder[a];
    }
}

/* The joint pass over the order (from the top's end when `top_done`: the
 * caller placed the top before the threads started); with `check` (no
 * collision pass after it), every particle's new state is checked by the
 * thread that placed it (the smallest non-finite index lowers
 * *bad_state).  Ends with a barrier. */
static void follow_parents(phc_particles *p, const crew *c, double dt, size_t *next_item,
                           int top_done, int check, size_t *bad_state)
{
    const double T2 = p->o.stiffness_step * p->o.stiffness_step;
    size_t bad = p->n;
    if (c->nth == 1) {
        follow_range(p, top_done ? p->follow_top : 0, p->n, dt, T2, check, &bad);
        if (bad < p->n)
            lower_to(bad_state, bad);
        return;
    }
    if (!top_done) {
        if (c->tid == 0)
            follow_range(p, 0, p->follow_top, dt, T2, check, &bad);
        crew_barrier(c);
    }
    for (;;) {
        size_t item;
#pragma omp atomic capture
        item = (*next_item)++;
        if (item >= p->follow_items)
            break;
        follow_range(p, p->follow_start[item], p->follow_start[item + 1], dt, T2, check, &bad);
    }
    if (bad < p->n)
        lower_to(bad_state, bad);
    crew_barrier(c);
}

/* The step up to the collision pass, on one thread of the crew: the
 * groups' statics and the prediction, the N projections (the planned
 * groups' goals from the current x_p, then the planned particles'
 * blends), the joint pass.  *bad: a group whose moment matrix was not
 * finite (the step stops there). */
static void step_body(phc_particles *p, const crew *c, double dt, long *bad, size_t *next_item,
                      int top_done, size_t *bad_state, size_t *tot, size_t *fb)
{
    const size_t N = p->o.iterations;
    const size_t *plist = p->use_lists ? p->plist : NULL;
    const size_t *glist = p->use_lists ? p->gmatch : NULL;
    size_t lo, hi;
    share(c, p->gcount[1], &lo, &hi);
    for (size_t t = lo; t < hi; ++t)
        group_statics(p, pick(glist, t));
    share(c, p->pcount[0], &lo, &hi);
    for (size_t t = lo; t < hi; ++t)
        predict(p, pick(plist, t), dt);
    for (size_t it = 1; it <= N; ++it) {
        if (p->gcount[it] == 0)
            break; /* nothing planned from here on (the sets shrink with it) */
        crew_barrier(c);
        match_pass(p, c, glist, p->gcount[it], p->xp, 0, bad, tot, fb);
        if (*bad >= 0)
            return;
        share(c, p->pcount[it], &lo, &hi);
        for (size_t t = lo; t < hi; ++t)
            blend(p, pick(plist, t), it < N);
    }
    if (p->gcount[1] > 0) /* (no group: nothing was predicted either) */
        crew_barrier(c);
    if (p->use_lists && c->tid == 0 && !top_done) /* the pinned particles no blend reached */
        for (size_t t = 0; t < p->npins; ++t)
            apply_anchor(p, p->pins[t]);
    if (p->o.follow_parent)
        follow_parents(p, c, dt, next_item, top_done, !p->collide, bad_state);
}

/* What the threads of a step share: the first particle with a non-finite
 * position (n: none), the largest group with a non-finite moment matrix
 * (−1: none), the first particle with a non-finite new state (n: none),
 * the joint pass's next subtree. */
typedef struct step_shared {
    long bad;
    size_t bad_x, bad_state;
    size_t next_item;
    int top_done; /* the pins and the joint pass's top placed before the threads started */
} step_shared;

/* The whole step on one thread of the crew: positions checked, step_body,
 * the collision pass (one thread, index order), the new state checked,
 * then (nothing non-finite) velocities and the new state (finish).  The
 * checks' verdicts are read after a barrier, by all threads alike; a
 * non-finite position is judged with the new state (what runs before
 * writes only the predicted state and the warm starts, and a group's
 * non-finite moment matrix stops the projections). */
static void whole_step(phc_particles *p, const crew *c, double dt, step_shared *sh, size_t *tot,
                       size_t *fb)
{
    size_t lo, hi;
    share(c, p->n, &lo, &hi);
    for (size_t i = lo; i < hi; ++i)
        if (!isfinite(p->x[3 * i]) || !isfinite(p->x[3 * i + 1]) || !isfinite(p->x[3 * i + 2])) {
            lower_to(&sh->bad_x, i);
            break;
        }
    step_body(p, c, dt, &sh->bad, &sh->next_item, sh->top_done, &sh->bad_state, tot, fb);
    if (sh->bad >= 0)
        return;
    if (p->collide) { /* (step_body ended with a barrier: every check of x is in) */
        if (c->tid == 0 && sh->bad_x == p->n)
            collide(p);
        crew_barrier(c);
    } else if (c->tid == 0) {
        p->pushed = 0;
        p->depth = INFINITY;
    }
    /* velocities in index order (streams; the joint pass's order jumps),
     * the new state checked here unless the joint pass did */
    const int checked = p->o.follow_parent && !p->collide;
    const double keep_dt = (1 - p->o.damping) / dt;
    size_t bad = p->n;
    for (size_t i = lo; i < hi; ++i) {
        if (!checked && i < bad && !state_finite(p, i))
            bad = i;
        finish_one(p, i, keep_dt, dt);
    }
    if (bad < p->n)
        lower_to(&sh->bad_state, bad);
}

static void swap_arrays(double **a, double **b)
{
    double *t = *a;
    *a = *b;
    *b = t;
}

/* Every group matched against the new state with its stress (§4.3), on
 * one thread of the crew. */
static void stress_pass(phc_particles *p, const crew *c, long *bad, size_t *tot, size_t *fb)
{
    size_t lo, hi;
    share(c, p->n, &lo, &hi);
    for (size_t j = lo; j < hi; ++j) {
        group_statics(p, j);
        ellipsoid_term(p, j, p->q);
    }
    crew_barrier(c);
    match_pass(p, c, NULL, p->n, p->x, 1, bad, tot, fb);
}

static int bad_group(const phc_particles *p, long bad, phc_error *err)
{
    return phc_error_set(err, PHC_ERR_NUMERIC,
                         "particles: particle %ld (segment %ld): the moment matrix of its "
                         "group is not finite",
                         bad, p->source_id[bad]);
}

/* The report of a break of k's parent link: k and its joint, the head
 * x_k − R(q_k)(0, 0, L_k/2) (m). */
static void report_break(const phc_particles *p, size_t k, phc_particles_report *report)
{
    double hr[3];
    rotate_z(p->q + 4 * k, p->ax[3 * k + 2], hr);
    report->broken = 1;
    report->broken_particle = k;
    for (int d = 0; d < 3; ++d)
        report->broken_joint[d] = p->x[3 * k + d] - hr[d];
}

int phc_particles_step(phc_particles *p, double dt, phc_particles_report *report, phc_error *err)
{
    if (report) {
        report->max_stress = 0;
        report->max_stress_group = PHC_PARTICLES_NONE;
        report->broken = 0;
        report->broken_particle = PHC_PARTICLES_NONE;
        report->broken_stress = 0;
        report->max_bend_stress = 0;
        report->max_bend_particle = PHC_PARTICLES_NONE;
        report->broken_bend_stress = 0;
        for (int d = 0; d < 3; ++d)
            report->broken_joint[d] = NAN;
        report->polar_total = 0;
        report->polar_fallbacks = 0;
    }
    if (!p)
        return phc_error_set(err, PHC_ERR_INVALID, "particles: step: no particle system");
    if (!(dt > 0) || !isfinite(dt))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: step: time step must be positive and finite, found %g s",
                             dt);
    if (p->layout_dirty)
        relayout(p);
    const size_t n = p->n;
    ++p->epoch; /* (the joint terms made in this step carry it) */
    p->polar_total = p->polar_fallbacks = 0;
    if (p->o.follow_parent && p->follow_dirty)
        follow_order_build(p);
    plan_projections(p);
    if (p->o.follow_parent && p->o.bending == PHC_PARTICLES_BEAM && beam_articulate(p, dt))
        return phc_error_set(err, PHC_ERR_NOMEM, "particles: step: out of memory (the beam pass of %zu particles)",
                             n);
    step_shared sh = {-1, n, n, 0, 0};
    size_t tot = 0, fb = 0;
    if (p->use_lists && p->gcount[1] == 0 && p->o.follow_parent && team((long)n)) {
        /* nothing projected (the climbing plants): the pins and the joint
         * pass's top here, so that the threads meet once (one barrier) */
        const double T2 = p->o.stiffness_step * p->o.stiffness_step;
        size_t bad = n;
        for (size_t t = 0; t < p->npins; ++t)
            apply_anchor(p, p->pins[t]);
        follow_range(p, 0, p->follow_top, dt, T2, !p->collide, &bad);
        sh.bad_state = bad;
        sh.top_done = 1;
    }
    if (!team((long)n)) {
        const crew one = {0, 1};
        whole_step(p, &one, dt, &sh, &tot, &fb);
    } else {
#pragma omp parallel reduction(+ : tot, fb)
        {
            const crew c = {omp_get_thread_num(), omp_get_num_threads()};
            whole_step(p, &c, dt, &sh, &tot, &fb);
        }
    }
    p->polar_total += tot;
    p->polar_fallbacks += fb;
    if (sh.bad_x < n) {
        const size_t i = sh.bad_x;
        const int d = !isfinite(p->x[3 * i]) ? 0 : !isfinite(p->x[3 * i + 1]) ? 1 : 2;
        return phc_error_set(err, PHC_ERR_INPUT,
                             "particles: particle %zu (segment %ld): position %c is not finite "
                             "(%g m)",
                             i, p->source_id[i], "xyz"[d], p->x[3 * i + d]);
    }
    if (sh.bad >= 0)
        return bad_group(p, sh.bad, err);
    if (sh.bad_state < n)
        return phc_error_set(err, PHC_ERR_NUMERIC,
                             "particles: particle %zu (segment %ld): the step of %g s gave a "
                             "non-finite state; nothing was changed",
                             sh.bad_state, p->source_id[sh.bad_state], dt);
    /* the step succeeded: its new state becomes the current one */
    swap_arrays(&p->x, &p->xp);
    swap_arrays(&p->q, &p->qp);
    swap_arrays(&p->v, &p->vn);
    swap_arrays(&p->w, &p->wn);
    swap_arrays(&p->age, &p->agen);

    /* Breaking under a bending stress (the beam pass; particles.h): the
     * link whose joint's σ passes break_stress by the most, at most one. */
    if (p->o.break_stress > 0) {
        double top = 0;
        size_t kt = PHC_PARTICLES_NONE;
        for (size_t k = 0; k < n; ++k) {
            if (!p->linked[k])
                continue;
            const double sg = bend_stress_of(p, k);
            if (sg > top) {
                top = sg;
                kt = k;
            }
        }
        const int breaks = kt != PHC_PARTICLES_NONE && top > p->o.break_stress;
        if (breaks)
            p->linked[kt] = 0;
        if (report) {
            report->max_bend_stress = top;
            report->max_bend_particle = kt;
            if (breaks) {
                report_break(p, kt, report);
                report->broken_bend_stress = top;
            }
        }
    }

    /* Stress of every group on the new state (§4.3), and breaking. */
    if (p->no_stress && !(p->o.break_threshold > 0)) {
        if (report) {
            report->polar_total = p->polar_total;
            report->polar_fallbacks = p->polar_fallbacks;
        }
        return PHC_OK;
    }
    tot = fb = 0;
    long bad = -1;
    if (!team((long)n)) {
        const crew one = {0, 1};
        stress_pass(p, &one, &bad, &tot, &fb);
    } else {
#pragma omp parallel reduction(+ : tot, fb)
        {
            const crew c = {omp_get_thread_num(), omp_get_num_threads()};
            stress_pass(p, &c, &bad, &tot, &fb);
        }
    }
    p->polar_total += tot;
    p->polar_fallbacks += fb;
    if (bad >= 0)
        return bad_group(p, bad, err);
    double smax = 0, bmax = -1;
    size_t gmax = PHC_PARTICLES_NONE, bk = PHC_PARTICLES_NONE;
    for (size_t k = 0; k < n; ++k) {
        const double st = p->stress[k];
        if (st > smax || gmax == PHC_PARTICLES_NONE) {
            smax = st;
            gmax = k;
        }
        if (p->o.break_threshold > 0 && p->linked[k] && st > p->o.break_threshold && st > bmax) {
            bmax = st;
            bk = k;
        }
    }
    if (bk != PHC_PARTICLES_NONE)
        p->linked[bk] = 0;
    if (report) {
        report->polar_total = p->polar_total;
        report->polar_fallbacks = p->polar_fallbacks;
        report->max_stress = smax;
        report->max_stress_group = gmax;
        if (bk != PHC_PARTICLES_NONE) {
            report_break(p, bk, report);
            report->broken_stress = bmax;
        }
    }
    return PHC_OK;
}

/* ---- accessors ---------------------------------------------------------- */

void phc_particles_position(const phc_particles *p, size_t i, double x[3])
{
    memcpy(x, p->x + 3 * i, 3 * sizeof(double));
}

void phc_particles_velocity(const phc_particles *p, size_t i, double v[3])
{
    memcpy(v, p->v + 3 * i, 3 * sizeof(double));
}

void phc_particles_orientation(const phc_particles *p, size_t i, double q[4])
{
    memcpy(q, p->q + 4 * i, 4 * sizeof(double));
}

void phc_particles_poses(const phc_particles *p, size_t first, size_t count, double *x,
                         double *q)
{
    memcpy(x, p->x + 3 * first, 3 * count * sizeof(double));
    memcpy(q, p->q + 4 * first, 4 * count * sizeof(double));
}

double phc_particles_mass(const phc_particles *p, size_t i) { return p->m[i]; }

double phc_particles_stress(const phc_particles *p, size_t i) { return p->stress[i]; }

size_t phc_particles_parent(const phc_particles *p, size_t i)
{
    return p->linked[i] ? p->parent[i] : PHC_PARTICLES_NONE;
}

void phc_particles_segment_ends(const phc_particles *p, double *head, double *tail)
{
    for (size_t i = 0; i < p->n; ++i) {
        double R[9], e[3] = {0, 0, p->ax[3 * i + 2]}, r[3];
        phc_quat_to_matrix(p->q + 4 * i, R);
        mat_vec(R, e, r);
        for (int d = 0; d < 3; ++d) {
            head[3 * i + d] = p->x[3 * i + d] - r[d];
            tail[3 * i + d] = p->x[3 * i + d] + r[d];
        }
    }
}

void phc_particles_momentum(const phc_particles *p, double P[3])
{
    P[0] = P[1] = P[2] = 0;
    for (size_t i = 0; i < p->n; ++i)
        for (int d = 0; d < 3; ++d)
            P[d] += p->m[i] * p->v[3 * i + d];
}

/* ---- velocities (a system rebuilt from another, model/climbing_breaking.h) */

void phc_particles_angular_velocity(const phc_particles *p, size_t i, double w[3])
{
    memcpy(w, p->w + 3 * i, 3 * sizeof(double));
}

int phc_particles_set_velocities(phc_particles *p, size_t i, const double v[3], const double w[3],
                                 phc_error *err)
{
    if (check_index(p, i, "velocity", err))
        return err ? err->status : PHC_ERR_INVALID;
    if (check_vec(p, i, v, "velocity", "m/s", err) || check_vec(p, i, w, "angular velocity", "rad/s", err))
        return err ? err->status : PHC_ERR_INPUT;
    memcpy(p->v + 3 * i, v, 3 * sizeof(double));
    memcpy(p->w + 3 * i, w, 3 * sizeof(double));
    return PHC_OK;
}
