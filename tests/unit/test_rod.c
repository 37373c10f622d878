/* Unit tests for model/rod (elastic rods on the plant graph), model/rod_joint,
 * model/rod_tree_solver and model/quaternion: every analytic derivative
 * against central differences; cantilevers against the exact solution of the
 * discrete chain and against beam theory; large deflection against the
 * elastica (shooting inside this test); independence of the equilibrium from
 * iterations, sub-steps and the time step; the first bending frequency; the
 * authors' Gauss–Seidel scheme; bad input; a 2000-segment tree.  Every
 * checked number is printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "model/plant_graph.h"
#include "model/quaternion.h"
#include "model/rod.h"
#include "model/rod_internal.h"
#include "model/rod_joint.h"
#include "model/rod_tree_solver.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const double G0 = 9.81;

/* ---- derivatives ---------------------------------------------------------- */

static void perturb(const double x[3], const double q[4], int k, double eps, double xo[3],
                    double qo[4])
{
    memcpy(xo, x, 3 * sizeof *x);
    memcpy(qo, q, 4 * sizeof *q);
    if (k < 3) {
        xo[k] += eps;
    } else {
        double v[3] = {0, 0, 0}, e[4];
        v[k - 3] = eps;
        phc_quat_exp(v, e);
        phc_quat_mul(e, q, qo);
    }
}

/* λ·C at (exp(a) q_p, exp(b) q_c) for 12 increments z = (z_p, z_c) */
static double lagr(const phc_rod_joint_geometry *j, const double xp[3], const double qp[4],
                   const double xc[3], const double qc[4], const double lam[6], const double z[12])
{
    double X[2][3], Q[2][4], e[4], C[6];
    const double *x0[2] = {xp, xc}, *q0[2] = {qp, qc};
    for (int b = 0; b < 2; ++b) {
        for (int k = 0; k < 3; ++k)
            X[b][k] = x0[b][k] + z[6 * b + k];
        phc_quat_exp(z + 6 * b + 3, e);
        phc_quat_mul(e, q0[b], Q[b]);
    }
    phc_rod_joint_eval(j, X[0], Q[0], X[1], Q[1], C, NULL, NULL);
    double s = 0.0;
    for (int k = 0; k < 6; ++k)
        s += lam[k] * C[k];
    return s;
}

static void test_derivatives(void)
{
    phc_rod_joint_geometry j = {{0.01, -0.02, 0.05}, {-0.003, 0.01, -0.04}, 0.09, {1.0, -2.0, 0.5}};
    double xp[3] = {0.1, 0.2, -0.3}, xc[3] = {0.12, 0.18, -0.21};
    double qp[4] = {0.9, 0.1, -0.3, 0.2}, qc[4] = {0.7, -0.2, 0.4, 0.3};
    double lam[6] = {0.3, -1.2, 0.7, 0.05, -0.02, 0.08};
    phc_quat_normalize(qp);
    phc_quat_normalize(qc);
    double C[6], Jp[36], Jc[36], Hpp[36], Hpc[36], Hcc[36];
    phc_rod_joint_eval(&j, xp, qp, xc, qc, C, Jp, Jc);
    phc_rod_joint_hessian(&j, qp, qc, lam, Hpp, Hpc, Hcc);
    const double eps = 1e-6;
    double maxerr_j = 0.0, maxref_j = 0.0;
    for (int b = 0; b < 2; ++b)
        for (int k = 0; k < 6; ++k) {
            double X[3], Q[4], Cp[6], Cm[6];
            const double *J = b ? Jc : Jp;
            if (b == 0) {
                perturb(xp, qp, k, eps, X, Q);
                phc_rod_joint_eval(&j, X, Q, xc, qc, Cp, NULL, NULL);
                perturb(xp, qp, k, -eps, X, Q);
                phc_rod_joint_eval(&j, X, Q, xc, qc, Cm, NULL, NULL);
            } else {
                perturb(xc, qc, k, eps, X, Q);
                phc_rod_joint_eval(&j, xp, qp, X, Q, Cp, NULL, NULL);
                perturb(xc, qc, k, -eps, X, Q);
                phc_rod_joint_eval(&j, xp, qp, X, Q, Cm, NULL, NULL);
            }
            for (int r = 0; r < 6; ++r) {
                const double fd = (Cp[r] - Cm[r]) / (2 * eps);
                maxerr_j = fmax(maxerr_j, fabs(fd - J[r * 6 + k]));
                maxref_j = fmax(maxref_j, fabs(J[r * 6 + k]));
            }
        }
    printf("joint Jacobians (stretch, Darboux) vs central differences: max |error| %.3e "
           "(max |entry| %.3e)\n",
           maxerr_j, maxref_j);
    CHECK(maxerr_j <= 1e-8 * maxref_j);

    /* Hessian of λ·C over the 12 increments (pullback at 0) */
    double H[144];
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) {
            H[r * 12 + c] = Hpp[r * 6 + c];
            H[r * 12 + 6 + c] = Hpc[r * 6 + c];
            H[(6 + r) * 12 + c] = Hpc[c * 6 + r];
            H[(6 + r) * 12 + 6 + c] = Hcc[r * 6 + c];
        }
    const double e2 = 1e-4;
    double maxerr_h = 0.0, maxref_h = 0.0;
    for (int a = 0; a < 12; ++a)
        for (int b = 0; b < 12; ++b) {
            double z[12] = {0}, f[4];
            const double sa[4] = {1, 1, -1, -1}, sb[4] = {1, -1, 1, -1};
            for (int t = 0; t < 4; ++t) {
                memset(z, 0, sizeof z);
                z[a] += sa[t] * e2;
                z[b] += sb[t] * e2;
                f[t] = lagr(&j, xp, qp, xc, qc, lam, z);
            }
            const double fd = (f[0] - f[1] - f[2] + f[3]) / (4 * e2 * e2);
            maxerr_h = fmax(maxerr_h, fabs(fd - H[a * 12 + b]));
            maxref_h = fmax(maxref_h, fabs(H[a * 12 + b]));
        }
    printf("Hessian of lambda.C (geometric stiffness) vs central differences: max |error| %.3e "
           "(max |entry| %.3e)\n",
           maxerr_h, maxref_h);
    CHECK(maxerr_h <= 1e-6 * maxref_h);

    /* Darboux vector: Ω of a pure rotation by φ about d1 between two frames
     * is (2/ℓ) sin(φ/2) e1 */
    {
        double q1[4] = {1, 0, 0, 0}, v[3] = {0.3, 0, 0}, q2[4], om[3];
        phc_quat_exp(v, q2);
        phc_rod_darboux(q1, q2, 0.5, om);
        printf("Darboux vector of a 0.3 rad bend over l = 0.5 m: %.15g (exact %.15g) 1/m\n", om[0],
               2.0 / 0.5 * sin(0.15));
        CHECK_NEAR(om[0], 2.0 / 0.5 * sin(0.15), 1e-15, 0.0);
        CHECK_NEAR(om[1], 0.0, 1e-15, 0.0);
    }
    /* quaternion exp/log round trip and rotate vs matrix */
    {
        double v[3] = {0.4, -1.1, 0.7}, q[4], back[3], r[9], u[3] = {0.2, 0.5, -0.9}, a[3];
        phc_quat_exp(v, q);
        phc_quat_log(q, back);
        phc_quat_to_matrix(q, r);
        phc_quat_rotate(q, u, a);
        double e1 = 0.0, e2m = 0.0;
        for (int k = 0; k < 3; ++k) {
            e1 = fmax(e1, fabs(back[k] - v[k]));
            e2m = fmax(e2m, fabs(a[k] - (r[3 * k] * u[0] + r[3 * k + 1] * u[1] + r[3 * k + 2] * u[2])));
        }
        printf("quaternion log(exp(v)) error %.3e, rotate vs matrix %.3e\n", e1, e2m);
        CHECK(e1 < 1e-14 && e2m < 1e-15);
    }
}

/* ---- tree solver against a dense solve ------------------------------------ */

static void test_tree_solver(void)
{
    /* a random tree of 7 nodes with 12-blocks (6-block free root), compared
     * with dense LU of the assembled matrix */
    const size_t n = 7;
    const size_t par[7] = {PHC_TREE_NONE, 0, 0, 1, 1, 2, 5};
    phc_rod_tree *t = phc_rod_tree_new(n);
    int off[7], dimtot = 0;
    unsigned long s = 12345;
#define RND() ((s = s * 6364136223846793005UL + 1442695040888963407UL), ((double)(s >> 11) / 9007199254740992.0 - 0.5))
    for (size_t i = 0; i < n; ++i) {
        t->parent[i] = par[i];
        t->dim[i] = i ? 12 : 6;
        off[i] = dimtot;
        dimtot += t->dim[i];
    }
    double *A = calloc((size_t)(dimtot * dimtot), sizeof *A), *b = calloc((size_t)dimtot, sizeof *b);
    int *piv = calloc((size_t)dimtot, sizeof *piv);
    for (size_t i = 0; i < n; ++i) {
        const int d = t->dim[i];
        /* KKT-like blocks: a body block with an antisymmetric part (the
         * solver does not assume symmetry), constraint rows with a zero
         * diagonal (hard rows: pivoting needed) or −α */
        for (int r = 0; r < d; ++r)
            for (int c = 0; c <= r; ++c) {
                double v = RND() + (r == c ? 3.0 : 0.0), skew = 0.0;
                if (r >= 6 && c >= 6)
                    v = (r == c && r >= 9) ? -0.5 : 0.0;
                if (r < 6 && c < r)
                    skew = 0.3 * RND();
                t->diag[144 * i + r * 12 + c] = v + skew;
                t->diag[144 * i + c * 12 + r] = v - skew;
                A[(off[i] + r) * dimtot + off[i] + c] = v + skew;
                A[(off[i] + c) * dimtot + off[i] + r] = v - skew;
            }
        if (par[i] != PHC_TREE_NONE)
            for (int r = 0; r < d; ++r)
                for (int c = 0; c < 6; ++c) {
                    const double v = RND();
                    t->coup[72 * i + r * 6 + c] = v;
                    A[(off[i] + r) * dimtot + off[par[i]] + c] = v;
                    A[(off[par[i]] + c) * dimtot + off[i] + r] = v;
                }
    }
    double rhs[7 * 12] = {0};
    for (size_t i = 0; i < n; ++i)
        for (int r = 0; r < t->dim[i]; ++r)
            b[off[i] + r] = rhs[12 * i + r] = RND();
#undef RND
    CHECK(phc_rod_tree_set_order(t) == 0);
    CHECK(phc_rod_tree_factor(t) == PHC_TREE_NONE);
    phc_rod_tree_solve(t, rhs);
    CHECK(phc_dense_lu(A, dimtot, piv) == 0);
    phc_dense_lu_solve(A, dimtot, piv, b);
    double err = 0.0, ref = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (int r = 0; r < t->dim[i]; ++r) {
            err = fmax(err, fabs(rhs[12 * i + r] - b[off[i] + r]));
            ref = fmax(ref, fabs(b[off[i] + r]));
        }
    printf("tree solver vs dense LU (7 nodes, %d unknowns): max |difference| %.3e (max |x| %.3e)\n",
           dimtot, err, ref);
    CHECK(err <= 1e-12 * ref);
    free(A);
    free(b);
    free(piv);
    phc_rod_tree_free(t);
}

/* ---- graphs ---------------------------------------------------------------- */

/* A horizontal cantilever along +x: root segment of length h0 from (-h0,0,0)
 * to (0,0,0) (fixed), then n free segments of length L/n; `extra_fixed_end`
 * appends one more segment of length L/n beyond x = L, fixed (a support). */
static phc_plant_graph *cantilever(size_t n, double L, double r, double h0, int extra_fixed_end)
{
    const size_t m = n + 1 + (extra_fixed_end ? 1 : 0);
    phc_plant_graph *g = phc_plant_graph_new(m);
    const double h = L / (double)n;
    phc_error err;
    for (size_t i = 0; i < m; ++i) {
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = r;
        g->source_id[i] = (long)(100 + i);
        const double x0 = i ? (double)(i - 1) * h : -h0;
        const double x1 = i ? (double)i * h : 0.0;
        g->head[3 * i] = x0;
        g->tail[3 * i] = x1;
        g->length[i] = x1 - x0;
    }
    if (extra_fixed_end)
        g->fixed[m - 1] = 1;
    if (phc_plant_graph_finish(g, "", &err) != PHC_OK) {
        fprintf(stderr, "cantilever: %s\n", err.message);
        exit(1);
    }
    return g;
}

static phc_rod *make_rod(const phc_plant_graph *g, double E, const phc_rod_options *o)
{
    double *young = malloc(g->n * sizeof *young);
    phc_rod *rod = NULL;
    phc_error err;
    for (size_t i = 0; i < g->n; ++i)
        young[i] = E;
    if (phc_rod_new(g, young, o, &rod, &err) != PHC_OK) {
        fprintf(stderr, "phc_rod_new: %s\n", err.message);
        exit(1);
    }
    free(young);
    return rod;
}

static int solve_static(phc_rod *rod, phc_rod_report *rep)
{
    phc_error err;
    int rc = phc_rod_solve_static(rod, rep, &err);
    if (rc != PHC_OK)
        fprintf(stderr, "static solve: %s\n", err.message);
    return rc;
}

/* The small-deflection sag of the discrete chain: joint k (k = 1..n) sits at
 * x_k = (k−1)h with rotational spring EI/ℓ_k (ℓ_1 = (h0+h)/2, else h) and
 * carries the bending moment M(x_k) exactly (point masses or loads between
 * joints only move the line of action, not the moment at a joint); a joint
 * rotation φ_k = M_k ℓ_k/EI lowers the tip by φ_k (L − x_k). */
static double chain_sag(size_t n, double L, double h0, double EI, double q, double P)
{
    const double h = L / (double)n;
    double d = 0.0;
    for (size_t k = 1; k <= n; ++k) {
        const double x = (double)(k - 1) * h, ell = (k == 1) ? 0.5 * (h0 + h) : h;
        const double M = 0.5 * q * (L - x) * (L - x) + P * (L - x);
        d += M * ell / EI * (L - x);
    }
    return d;
}

static void test_cantilevers(void)
{
    const double L = 1.0, r = 0.01, rho = 1000.0;
    const double A = M_PI * r * r, I = M_PI * r * r * r * r / 4.0;
    const double q = rho * G0 * A;
    /* E so that qL⁴/(8EI) = 1e-5 L: small load, nonlinearity ~1e-10 */
    const double E = q * L * L * L / (8.0 * I * 1e-5);
    const double EI = E * I;
    phc_rod_options o;
    phc_rod_options_default(&o);
    printf("cantilever under self-weight, L = %g m, r = %g m, rho = %g kg/m^3, E = %.6g Pa, "
           "q = %.6g N/m\n",
           L, r, rho, E, q);
    const size_t ns[4] = {10, 20, 40, 80};
    for (int t = 0; t < 4; ++t) {
        const size_t n = ns[t];
        const double h = L / (double)n;
        for (int variant = 0; variant < 2; ++variant) {
            /* variant 0: clamp segment of length h (the chain of the issue:
             * (1+1/n)² qL⁴/8EI); variant 1: clamp segment of length 1e-6 h
             * (the trapezoidal chain, second order) */
            const double h0 = variant ? 1e-6 * h : h;
            phc_plant_graph *g = cantilever(n, L, r, h0, 0);
            phc_rod *rod = make_rod(g, E, &o);
            phc_rod_report rep;
            CHECK(solve_static(rod, &rep) == PHC_OK);
            double d[3];
            phc_rod_tip_deflection(rod, n, d);
            const double sag = -d[2], exact = chain_sag(n, L, h0, EI, q, 0.0);
            const double beam = q * L * L * L * L / (8.0 * EI);
            printf("  n = %2zu clamp %-8s sag %.12e m, discrete exact %.12e (rel err %.2e), "
                   "sag/(qL^4/8EI) = %.6f%s, Newton its %d, residual %.2e\n",
                   n, variant ? "1e-6 h" : "h", sag, exact, fabs(sag / exact - 1.0), sag / beam,
                   variant ? "" : "", rep.iterations, rep.residual);
            if (!variant)
                printf("           (1+1/n)^2 = %.6f\n", (1 + 1.0 / n) * (1 + 1.0 / n));
            CHECK_NEAR(sag, exact, 0.0, 1e-8);
            if (!variant)
                CHECK_NEAR(exact / beam, (1 + 1.0 / n) * (1 + 1.0 / n), 0.0, 1e-12);
            phc_rod_free(rod);
            phc_plant_graph_free(g);
        }
    }
    /* end load P, no gravity */
    o.gravity[2] = 0.0;
    const double P = 3.0 * EI * 1e-5 / (L * L); /* PL³/3EI = 1e-5 L */
    printf("cantilever with end load P = %.6g N (gravity off)\n", P);
    for (int t = 0; t < 4; ++t) {
        const size_t n = ns[t];
        const double h = L / (double)n;
        for (int variant = 0; variant < 2; ++variant) {
            const double h0 = variant ? 1e-6 * h : h;
            phc_plant_graph *g = cantilever(n, L, r, h0, 0);
            phc_rod *rod = make_rod(g, E, &o);
            const double F[3] = {0, 0, -P};
            phc_error err;
            CHECK(phc_rod_set_load(rod, n, F, &err) == PHC_OK);
            phc_rod_report rep;
            CHECK(solve_static(rod, &rep) == PHC_OK);
            double d[3];
            phc_rod_tip_deflection(rod, n, d);
            const double sag = -d[2], exact = chain_sag(n, L, h0, EI, 0.0, P);
            const double beam = P * L * L * L / (3.0 * EI);
            printf("  n = %2zu clamp %-8s sag %.12e m, discrete exact %.12e (rel err %.2e), "
                   "sag/(PL^3/3EI) = %.6f\n",
                   n, variant ? "1e-6 h" : "h", sag, exact, fabs(sag / exact - 1.0), sag / beam);
            CHECK_NEAR(sag, exact, 0.0, 1e-8);
            if (variant && n == 80)
                CHECK_NEAR(sag / beam, 1.0, 0.0, 1e-3);
            phc_rod_free(rod);
            phc_plant_graph_free(g);
        }
    }
    /* weakened joints: factor 0.5 everywhere doubles the small-load sag */
    {
        phc_plant_graph *g = cantilever(20, L, r, L / 20, 0);
        phc_rod *rod = make_rod(g, E, &o);
        const double F[3] = {0, 0, -P};
        phc_error err;
        phc_rod_set_load(rod, 20, F, &err);
        double d1[3], d2[3];
        CHECK(solve_static(rod, NULL) == PHC_OK);
        phc_rod_tip_deflection(rod, 20, d1);
        for (size_t i = 1; i <= 20; ++i)
            CHECK(phc_rod_set_joint_factor(rod, i, 0.5, &err) == PHC_OK);
        phc_rod_reset(rod);
        CHECK(solve_static(rod, NULL) == PHC_OK);
        phc_rod_tip_deflection(rod, 20, d2);
        printf("weakened joints (factor 0.5): sag ratio %.12f (expected 2)\n", d2[2] / d1[2]);
        CHECK_NEAR(d2[2] / d1[2], 2.0, 0.0, 1e-8);
        phc_rod_free(rod);
        phc_plant_graph_free(g);
    }
}

static void test_three_point(void)
{
    const double L = 1.0, r = 0.01, I = M_PI * r * r * r * r / 4.0;
    const double E = 1e12, EI = E * I;
    phc_rod_options o;
    phc_rod_options_default(&o);
    const size_t ns[4] = {10, 20, 40, 80};
    /* simply supported (three-point bending): by symmetry the centre has
     * zero slope, so each half is a cantilever of span L/2 loaded at its end
     * by the support reaction F/2: F/δ = 48EI/L³ exactly when the half-span
     * cantilever has δ = (F/2)(L/2)³/3EI.  Measured on the cantilever with
     * the short clamp (second-order chain), n = 10..80 per half. */
    o.gravity[2] = 0.0;
    for (int t = 0; t < 4; ++t) {
        const size_t n = ns[t];
        const double half = 0.5 * L;
        phc_plant_graph *g = cantilever(n, half, r, 1e-6 * half / (double)n, 0);
        phc_rod *rod = make_rod(g, E, &o);
        const double Fh = 48.0 * EI / (L * L * L) * 1e-5 * L; /* δ ≈ 1e-5 L */
        const double Fv[3] = {0, 0, -0.5 * Fh};
        phc_error err;
        phc_rod_set_load(rod, n, Fv, &err);
        CHECK(solve_static(rod, NULL) == PHC_OK);
        double d[3];
        phc_rod_tip_deflection(rod, n, d);
        const double ratio = Fh / (-d[2]) / (48.0 * EI / (L * L * L));
        printf("  three-point bending by symmetry, %2zu segments per half: (F/delta)/(48EI/L^3) = "
               "%.8f\n",
               n, ratio);
        if (n == 80)
            CHECK_NEAR(ratio, 1.0, 0.0, 1e-4);
        phc_rod_free(rod);
        phc_plant_graph_free(g);
    }
}

/* The elastica of a cantilever under a dead end load P (down):
 * EI θ'' = −P cos θ, θ(0) = 0, θ'(L) = 0 (θ the downward angle), shot on
 * θ'(0) by bisection with RK4 (steps of L/20000).  Returns the tip (x, z). */
static void elastica_rhs(double k, const double y[4], double f[4])
{
    /* y = (θ, θ', x, z) */
    f[0] = y[1];
    f[1] = -k * cos(y[0]);
    f[2] = cos(y[0]);
    f[3] = -sin(y[0]);
}

static void elastica_shoot(double k, double L, double k0, int steps, double y[4])
{
    const double ds = L / steps;
    y[0] = 0.0;
    y[1] = k0;
    y[2] = 0.0;
    y[3] = 0.0;
    for (int s = 0; s < steps; ++s) {
        double k1[4], k2[4], k3[4], k4[4], t[4];
        elastica_rhs(k, y, k1);
        for (int i = 0; i < 4; ++i)
            t[i] = y[i] + 0.5 * ds * k1[i];
        elastica_rhs(k, t, k2);
        for (int i = 0; i < 4; ++i)
            t[i] = y[i] + 0.5 * ds * k2[i];
        elastica_rhs(k, t, k3);
        for (int i = 0; i < 4; ++i)
            t[i] = y[i] + ds * k3[i];
        elastica_rhs(k, t, k4);
        for (int i = 0; i < 4; ++i)
            y[i] += ds / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
}

static void elastica_tip(double P_over_EI, double L, double tip[2])
{
    double lo = 0.0, hi = P_over_EI * L, y[4];
    for (int it = 0; it < 200 && hi - lo > 1e-15 * P_over_EI * L; ++it) {
        const double mid = 0.5 * (lo + hi);
        elastica_shoot(P_over_EI, L, mid, 20000, y);
        if (y[1] < 0.0)
            lo = mid;
        else
            hi = mid;
    }
    elastica_shoot(P_over_EI, L, 0.5 * (lo + hi), 20000, y);
    tip[0] = y[2];
    tip[1] = y[3];
}

static void test_elastica(void)
{
    const double L = 1.0, r = 0.01, I = M_PI * r * r * r * r / 4.0, E = 1e9, EI = E * I;
    const double alpha = 3.0, P = alpha * EI / (L * L); /* PL²/EI = 3 */
    double tip[2];
    elastica_tip(P / EI, L, tip);
    printf("elastica, PL^2/EI = %g: tip x = %.10f L, z = %.10f L (shooting, RK4 20000 steps)\n",
           alpha, tip[0] / L, tip[1] / L);
    phc_rod_options o;
    phc_rod_options_default(&o);
    o.gravity[2] = 0.0;
    const size_t ns[3] = {25, 50, 100};
    for (int t = 0; t < 3; ++t) {
        const size_t n = ns[t];
        phc_plant_graph *g = cantilever(n, L, r, 1e-6 * L / (double)n, 0);
        phc_rod *rod = make_rod(g, E, &o);
        const double Fv[3] = {0, 0, -P};
        phc_error err;
        phc_rod_set_load(rod, n, Fv, &err);
        phc_rod_report rep;
        CHECK(solve_static(rod, &rep) == PHC_OK);
        double p[3];
        phc_rod_tail(rod, n, p);
        const double e = sqrt((p[0] - tip[0]) * (p[0] - tip[0]) + (p[2] - tip[1]) * (p[2] - tip[1])) /
                         sqrt(tip[0] * tip[0] + tip[1] * tip[1]);
        printf("  n = %3zu: tip x = %.8f, z = %.8f, |tip - elastica|/|tip| = %.2e, Newton its %d, "
               "residual %.2e\n",
               n, p[0], p[2], e, rep.iterations, rep.residual);
        if (n == 100)
            CHECK(e <= 1e-3);
        phc_rod_free(rod);
        phc_plant_graph_free(g);
    }
    /* with too small an iteration budget the solve refuses and keeps the
     * state it started from */
    {
        phc_plant_graph *g = cantilever(25, L, r, 1e-6 * L / 25.0, 0);
        o.max_iterations = 2;
        phc_rod *rod = make_rod(g, E, &o);
        const double Fv[3] = {0, 0, -P};
        phc_error err;
        phc_rod_set_load(rod, 25, Fv, &err);
        const int rc = phc_rod_solve_static(rod, NULL, &err);
        double d[3];
        phc_rod_tip_deflection(rod, 25, d);
        printf("  max_iterations 2 -> %d: %s; tip moved %.1e m\n", rc, err.message,
               fabs(d[0]) + fabs(d[1]) + fabs(d[2]));
        CHECK(rc == PHC_ERR_NOT_CONVERGED);
        CHECK_STR_CONTAINS(err.message, "2 Newton iterations");
        CHECK(fabs(d[0]) + fabs(d[1]) + fabs(d[2]) <= 1e-15); /* the rest shape, to rounding */
        phc_rod_free(rod);
        phc_plant_graph_free(g);
    }
}

/* Runs the dynamics with frames of dt until t_end; 0 on success. */
static int run_dynamics(phc_rod *rod, double dt, double t_end, int *steps_out)
{
    phc_error err;
    int steps = (int)ceil(t_end / dt - 1e-9);
    for (int s = 0; s < steps; ++s)
        if (phc_rod_step(rod, dt, NULL, &err) != PHC_OK) {
            fprintf(stderr, "step %d: %s\n", s, err.message);
            return 1;
        }
    if (steps_out)
        *steps_out = steps;
    return 0;
}

/* Supports.  (1) A cut joint with a support beyond it: the cantilever of
 * n segments is cut between segments k and k+1 and its last segment is
 * fixed; the outer part hangs from that support (the solver re-roots it
 * there) and is the mirror image of a cantilever of n−1−k segments, so
 * both parts have exact discrete sags.  (2) Two supports in one part
 * (solved through the Schur complement): a half-circle arch clamped at both
 * ends under its weight, built once from each end (different roots,
 * different elimination trees, the other end the support): the two
 * equilibria must agree. */
static phc_plant_graph *arch(size_t n, double R, double r, int reversed)
{
    phc_plant_graph *g = phc_plant_graph_new(n);
    phc_error err;
    for (size_t i = 0; i < n; ++i) {
        const size_t s = reversed ? n - 1 - i : i; /* arc piece of segment i */
        const double a0 = M_PI * (double)s / (double)n, a1 = M_PI * (double)(s + 1) / (double)n;
        const double p0[3] = {R * (1 - cos(a0)), 0.0, R * sin(a0)};
        const double p1[3] = {R * (1 - cos(a1)), 0.0, R * sin(a1)};
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = r;
        g->source_id[i] = (long)i;
        for (int k = 0; k < 3; ++k) {
            g->head[3 * i + k] = reversed ? p1[k] : p0[k];
            g->tail[3 * i + k] = reversed ? p0[k] : p1[k];
        }
        g->length[i] = 2.0 * R * sin(0.5 * M_PI / (double)n);
    }
    g->fixed[n - 1] = 1;
    if (phc_plant_graph_finish(g, "", &err) != PHC_OK) {
        fprintf(stderr, "arch: %s\n", err.message);
        exit(1);
    }
    return g;
}

static void test_supports(void)
{
    const double L = 1.0, r = 0.01, rho = 1000.0;
    const double A = M_PI * r * r, I = M_PI * r * r * r * r / 4.0, q = rho * G0 * A;
    const double E = q * L * L * L / (8.0 * I * 1e-5), EI = E * I;
    const size_t n = 40, k = 15;
    const double h = L / (double)n;
    phc_rod_options o;
    phc_rod_options_default(&o);
    phc_plant_graph *g = cantilever(n, L, r, h, 0);
    phc_rod *rod = make_rod(g, E, &o);
    phc_error err;
    CHECK(phc_rod_set_joint_factor(rod, k + 1, 0.0, &err) == PHC_OK);
    /* without a support the outer part cannot rest */
    phc_error_clear(&err);
    CHECK(phc_rod_solve_static(rod, NULL, &err) == PHC_ERR_INPUT);
    printf("cut without support: %s\n", err.message);
    CHECK_STR_CONTAINS(err.message, "segment 116");
    CHECK(phc_rod_set_fixed(rod, n, 1, &err) == PHC_OK);
    phc_rod_report rep;
    CHECK(solve_static(rod, &rep) == PHC_OK);
    double d_in[3], head[3];
    phc_rod_tip_deflection(rod, k, d_in);
    phc_rod_head(rod, k + 1, head);
    const double sag_in = -d_in[2], sag_out = -head[2];
    const double ex_in = chain_sag(k, (double)k * h, h, EI, q, 0.0);
    const double ex_out = chain_sag(n - 1 - k, (double)(n - 1 - k) * h, h, EI, q, 0.0);
    printf("cut at joint %zu/%zu, last segment fixed: inner tip sag %.12e (exact %.12e, rel err "
           "%.2e), outer tip sag %.12e (exact %.12e, rel err %.2e)\n",
           k, k + 1, sag_in, ex_in, fabs(sag_in / ex_in - 1), sag_out, ex_out,
           fabs(sag_out / ex_out - 1));
    CHECK_NEAR(sag_in, ex_in, 0.0, 1e-8);
    CHECK_NEAR(sag_out, ex_out, 0.0, 1e-8);
    phc_rod_free(rod);
    phc_plant_graph_free(g);

    /* the arch, from both ends */
    const size_t na = 24;
    const double R = 0.3, Ea = 2e7;
    phc_plant_graph *ga = arch(na, R, r, 0), *gb = arch(na, R, r, 1);
    phc_rod *ra = make_rod(ga, Ea, &o), *rb = make_rod(gb, Ea, &o);
    phc_rod_report repa, repb;
    CHECK(solve_static(ra, &repa) == PHC_OK);
    CHECK(solve_static(rb, &repb) == PHC_OK);
    double maxdiff = 0.0, maxdefl = 0.0, endmove = 0.0;
    for (size_t i = 0; i < na; ++i) {
        double pa[3], pb[3], da[3];
        phc_rod_tail(ra, i, pa);
        phc_rod_head(rb, na - 1 - i, pb);
        phc_rod_tip_deflection(ra, i, da);
        for (int c = 0; c < 3; ++c) {
            maxdiff = fmax(maxdiff, fabs(pa[c] - pb[c]));
            maxdefl = fmax(maxdefl, fabs(da[c]));
        }
    }
    {
        double da[3], db[3];
        phc_rod_tip_deflection(ra, na - 1, da);
        phc_rod_tip_deflection(rb, na - 1, db);
        endmove = fmax(sqrt(da[0] * da[0] + da[1] * da[1] + da[2] * da[2]),
                       sqrt(db[0] * db[0] + db[1] * db[1] + db[2] * db[2]));
    }
    printf("arch clamped at both ends (%zu segments, R = %g m, E = %g Pa): max deflection %.6e m, "
           "built from either end: max |difference| %.3e m (%.2e relative), supports moved %.1e m, "
           "Newton its %d / %d\n",
           na, R, Ea, maxdefl, maxdiff, maxdiff / maxdefl, endmove, repa.iterations,
           repb.iterations);
    CHECK(maxdefl > 1e-4);
    CHECK(maxdiff <= 1e-8 * maxdefl);
    CHECK(endmove <= 1e-12);
    /* the dynamics of the arch (supports through the Schur complement in
     * every implicit step), damped, come to the same rest */
    {
        phc_rod_options od = o;
        od.damping = 30.0;
        phc_error err;
        double pa[3], pd[3], worst = 0.0;
        phc_rod_tail(ra, na / 2, pa);
        CHECK(phc_rod_set_options(rb, &od, &err) == PHC_OK);
        phc_rod_reset(rb);
        int steps = 0;
        CHECK(run_dynamics(rb, 2e-3, 4.0, &steps) == 0);
        phc_rod_head(rb, na - 1 - na / 2, pd);
        for (int c = 0; c < 3; ++c)
            worst = fmax(worst, fabs(pa[c] - pd[c]));
        printf("  the arch's damped dynamics after %d steps of 2 ms: apex differs from the static "
               "solve by %.2e m (%.2e of the largest deflection)\n",
               steps, worst, worst / maxdefl);
        CHECK(worst <= 1e-6 * maxdefl);
    }
    phc_rod_free(ra);
    phc_rod_free(rb);
    phc_plant_graph_free(ga);
    phc_plant_graph_free(gb);
}

static void test_independence(void)
{
    /* a cantilever sagging 10% of its length: dynamics with damping run to
     * rest against the static solve, for several time steps and sub-steps */
    const double L = 1.0, r = 0.01, rho = 1000.0;
    const double A = M_PI * r * r, I = M_PI * r * r * r * r / 4.0, q = rho * G0 * A;
    const double E = q * L * L * L / (8.0 * I * 0.1), EI = E * I;
    const size_t n = 20;
    const double f1 = 1.875 * 1.875 / (2 * M_PI) * sqrt(EI / (rho * A * L * L * L * L));
    const double T1 = 1.0 / f1;
    phc_rod_options o;
    phc_rod_options_default(&o);
    phc_plant_graph *g = cantilever(n, L, r, 1e-6 * L / (double)n, 0);
    phc_rod *rod = make_rod(g, E, &o);
    phc_rod_report rep;
    CHECK(solve_static(rod, &rep) == PHC_OK);
    double ref[3];
    phc_rod_tip_deflection(rod, n, ref);
    const double refn = sqrt(ref[0] * ref[0] + ref[2] * ref[2]);
    printf("independence: static tip deflection (%.10f, %.10f) m, Newton its %d; first period "
           "%.4f s\n",
           ref[0], ref[2], rep.iterations, T1);
    struct {
        double dt;
        int substeps;
    } runs[3] = {{T1 / 50, 1}, {T1 / 50, 4}, {T1 / 200, 1}};
    for (int k = 0; k < 3; ++k) {
        o.damping = 2.0 * 2.0 * M_PI * f1; /* critical for the first mode */
        o.substeps = runs[k].substeps;
        phc_error err;
        CHECK(phc_rod_set_options(rod, &o, &err) == PHC_OK);
        phc_rod_reset(rod);
        int steps = 0;
        CHECK(run_dynamics(rod, runs[k].dt, 15.0 * T1, &steps) == 0);
        double d[3];
        phc_rod_tip_deflection(rod, n, d);
        const double diff = sqrt((d[0] - ref[0]) * (d[0] - ref[0]) + (d[2] - ref[2]) * (d[2] - ref[2]));
        printf("  dynamics to rest, dt = T1/%.0f, %d sub-step(s), %d steps: tip (%.10f, %.10f), "
               "|difference from static| / |deflection| = %.2e, kinetic energy %.2e J\n",
               T1 / runs[k].dt, runs[k].substeps, steps, d[0], d[2], diff / refn,
               phc_rod_kinetic_energy(rod));
        CHECK(diff <= 1e-6 * refn);
    }
    /* the static solve itself with a smaller iteration budget per stage and
     * a tighter tolerance: same answer */
    o.damping = 0.0;
    o.substeps = 1;
    o.tolerance = 1e-13;
    phc_error err;
    phc_rod_set_options(rod, &o, &err);
    phc_rod_reset(rod);
    CHECK(solve_static(rod, &rep) == PHC_OK);
    double d[3];
    phc_rod_tip_deflection(rod, n, d);
    printf("  static with tolerance 1e-13: %d Newton its, |difference| / |deflection| = %.2e\n",
           rep.iterations, sqrt((d[0] - ref[0]) * (d[0] - ref[0]) + (d[2] - ref[2]) * (d[2] - ref[2])) / refn);
    CHECK(sqrt((d[0] - ref[0]) * (d[0] - ref[0]) + (d[2] - ref[2]) * (d[2] - ref[2])) <= 1e-9 * refn);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

/* Dynamics of a cut part without a support: it falls freely.  Backward
 * Euler from rest under gravity g gives, after N steps of h, the drop
 * ½ g h² N (N+1) exactly (uniform gravity does not bend the part, so the
 * joint forces inside it stay zero); the loose part is solved as a free
 * top body (a 6x6 node) of its own elimination tree. */
static void test_free_fall(void)
{
    const size_t n = 10, k = 6;
    phc_plant_graph *g = cantilever(n, 1.0, 0.01, 0.1, 0);
    phc_rod_options o;
    phc_rod_options_default(&o);
    phc_rod *rod = make_rod(g, 1e9, &o);
    phc_error err;
    CHECK(phc_rod_set_joint_factor(rod, k, 0.0, &err) == PHC_OK);
    const double h = 1e-3;
    const int N = 50;
    for (int s = 0; s < N; ++s)
        CHECK(phc_rod_step(rod, h, NULL, &err) == PHC_OK);
    const double expect = 0.5 * G0 * h * h * N * (N + 1);
    double worst = 0.0, d[3];
    for (size_t i = k; i <= n; ++i) {
        phc_rod_tip_deflection(rod, i, d);
        worst = fmax(worst, fabs(-d[2] - expect) + fabs(d[0]) + fabs(d[1]));
    }
    phc_rod_tip_deflection(rod, n, d);
    printf("cut part without support, %d backward Euler steps of %g s: drop %.12e m, exact "
           "discrete %.12e m, worst error over its segments %.2e m\n",
           N, h, -d[2], expect, worst);
    CHECK(worst <= 1e-9 * expect);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

static void test_frequency(void)
{
    const double L = 1.0, r = 0.01, rho = 1000.0, E = 1e10;
    const double A = M_PI * r * r, I = M_PI * r * r * r * r / 4.0, EI = E * I;
    const size_t n = 40;
    const double f_eb = 1.875104 * 1.875104 / (2 * M_PI) * sqrt(EI / (rho * A * L * L * L * L));
    phc_rod_options o;
    phc_rod_options_default(&o);
    phc_plant_graph *g = cantilever(n, L, r, 1e-6 * L / (double)n, 0);
    phc_rod *rod = make_rod(g, E, &o);
    phc_error err;
    CHECK(solve_static(rod, NULL) == PHC_OK);
    double eq[3];
    phc_rod_tip_deflection(rod, n, eq);
    /* pull the tip up by ~1 mm with a load, release from that rest state */
    const double P = 3.0 * EI * 1e-3 / (L * L * L), F[3] = {0, 0, P}, zero[3] = {0, 0, 0};
    phc_rod_set_load(rod, n, F, &err);
    CHECK(solve_static(rod, NULL) == PHC_OK);
    phc_rod_set_load(rod, n, zero, &err);
    const double T = 1.0 / f_eb, dt = T / 400.0;
    double prev = 0.0, t_first = -1.0, t_last = -1.0;
    int crossings = 0;
    for (int s = 0; s <= 1300; ++s) {
        double d[3];
        phc_rod_tip_deflection(rod, n, d);
        const double z = d[2] - eq[2];
        if (s > 0 && prev > 0.0 && z <= 0.0) { /* downward crossing */
            const double tc = (s - 1) * dt + dt * prev / (prev - z);
            if (t_first < 0)
                t_first = tc;
            else
                ++crossings;
            t_last = tc;
        }
        prev = z;
        if (phc_rod_step(rod, dt, NULL, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            CHECK(0);
            break;
        }
    }
    const double f = crossings / (t_last - t_first);
    /* the same release without gravity: the force scale of a sub-step then
     * comes from the motion alone */
    {
        phc_rod_options og = o;
        og.gravity[2] = 0.0;
        phc_rod_set_options(rod, &og, &err);
        phc_rod_reset(rod);
        phc_rod_set_load(rod, n, F, &err);
        CHECK(solve_static(rod, NULL) == PHC_OK);
        phc_rod_set_load(rod, n, zero, &err);
        int ok = 1;
        double zmin = 1.0;
        for (int s = 0; s < 200 && ok; ++s) {
            ok = phc_rod_step(rod, dt, NULL, &err) == PHC_OK;
            double d[3];
            phc_rod_tip_deflection(rod, n, d);
            zmin = fmin(zmin, d[2]);
        }
        printf("  released without gravity: 200 steps %s, lowest tip %.4e m (released at %.4e m)\n",
               ok ? "taken" : err.message, zmin, P * L * L * L / (3.0 * EI));
        CHECK(ok);
        CHECK(zmin < -0.9 * P * L * L * L / (3.0 * EI)); /* swung through to the other side */
    }
    printf("first bending frequency (n = %zu, dt = T/400, %d periods between zero crossings): "
           "%.6f Hz, Euler-Bernoulli 1.875^2 sqrt(EI/(rho A L^4))/(2 pi) = %.6f Hz, ratio %.6f\n",
           n, crossings, f, f_eb, f / f_eb);
    CHECK(crossings >= 2);
    CHECK_NEAR(f / f_eb, 1.0, 0.0, 5e-3);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

/* The authors' scheme on a 20-segment cantilever: sag at rest / true sag.
 * Their PlantDemo (filthynobleman/plant-wilting-simulation) steps the
 * PositionBasedDynamics library with h = 0.0025 s, 1 position iteration,
 * velocities × 0.99 per step (here: damping c = (1/0.99 − 1)/h = 4.04 s⁻¹,
 * the same factor); with h = 0.001 s both rods come to rest, with the
 * authors' h the stiff one does not. */
static void test_gauss_seidel(void)
{
    const double L = 0.2, r = 0.002; /* density: the default 1000 kg/m^3 */
    const size_t n = 20;
    const struct {
        double E, frame, damping;
        int expect_rest;
    } runs[4] = {{1e10, 0.005, 2.0, 1}, {1e6, 0.005, 2.0, 1},
                 {1e10, 0.0125, (1.0 / 0.99 - 1.0) / 0.0025, 0},
                 {1e6, 0.0125, (1.0 / 0.99 - 1.0) / 0.0025, 1}};
    for (int k = 0; k < 4; ++k) {
        phc_rod_options o;
        phc_rod_options_default(&o);
        phc_plant_graph *g = cantilever(n, L, r, L / (double)n, 0);
        phc_rod *rod = make_rod(g, runs[k].E, &o);
        CHECK(solve_static(rod, NULL) == PHC_OK);
        double d[3];
        phc_rod_tip_deflection(rod, n, d);
        const double truth = -d[2];
        o.scheme = PHC_ROD_GAUSS_SEIDEL;
        o.substeps = 5;
        o.gs_iterations = 1;
        o.damping = runs[k].damping;
        phc_error err;
        CHECK(phc_rod_set_options(rod, &o, &err) == PHC_OK);
        phc_rod_reset(rod);
        const int frames = (int)ceil(40.0 / runs[k].frame - 1e-9);
        int done = 0, rc = PHC_OK;
        for (; done < frames; ++done)
            if ((rc = phc_rod_step(rod, runs[k].frame, NULL, &err)) != PHC_OK)
                break;
        const double ke = phc_rod_kinetic_energy(rod);
        phc_rod_tip_deflection(rod, n, d);
        const double gs = -d[2];
        printf("gauss_seidel (1 iteration x 5 sub-steps of %g s, damping %.3g/s) on a 20-segment "
               "cantilever L = %g m, r = %g m, E = %g Pa: ",
               runs[k].frame / 5, runs[k].damping, L, r, runs[k].E);
        if (rc != PHC_OK)
            printf("refused at frame %d: %s\n", done, err.message);
        else
            printf("after %d frames sag %.6e m, true sag %.6e m, ratio %.3f, kinetic energy %.1e J\n",
                   done, gs, truth, gs / truth, ke);
        if (runs[k].expect_rest) {
            CHECK(rc == PHC_OK && ke < 1e-20);
            if (runs[k].E > 1e9)
                CHECK(gs / truth > 10.0); /* the stiff rod is far too soft */
            else
                CHECK(gs / truth > 1.0 && gs / truth < 1.3);
        } else {
            CHECK(rc != PHC_OK || ke > 1e-6); /* never comes to rest */
        }
        phc_rod_free(rod);
        phc_plant_graph_free(g);
    }
}

static void test_bad_input(void)
{
    phc_plant_graph *g = cantilever(4, 1.0, 0.01, 0.25, 0);
    double young[5] = {1e9, 1e9, 1e9, 1e9, 1e9};
    phc_rod *rod = NULL;
    phc_rod_options o;
    phc_error err;
    int rc;
    phc_rod_options_default(&o);

    g->radius[2] = 0.0;
    rc = phc_rod_new(g, young, &o, &rod, &err);
    printf("bad input: zero radius -> %d: %s\n", rc, err.message);
    CHECK(rc == PHC_ERR_INPUT && rod == NULL);
    CHECK_STR_CONTAINS(err.message, "segment 102");
    g->radius[2] = -0.01;
    rc = phc_rod_new(g, young, &o, &rod, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "radius");
    g->radius[2] = 0.01;

    young[3] = -5.0;
    rc = phc_rod_new(g, young, &o, &rod, &err);
    printf("bad input: negative modulus -> %d: %s\n", rc, err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "segment 103");
    young[3] = 0.0;
    CHECK(phc_rod_new(g, young, &o, &rod, &err) == PHC_ERR_INPUT);
    young[3] = 1e9;

    o.density = 0.0;
    rc = phc_rod_new(g, young, &o, &rod, &err);
    printf("bad input: zero density -> %d: %s\n", rc, err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "density");
    o.density = -3.0;
    CHECK(phc_rod_new(g, young, &o, &rod, &err) == PHC_ERR_INPUT);
    phc_rod_options_default(&o);

    g->tail[3 * 1 + 2] = NAN;
    rc = phc_rod_new(g, young, &o, &rod, &err);
    printf("bad input: NaN coordinate -> %d: %s\n", rc, err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "segment 101");
    g->tail[3 * 1 + 2] = 0.0;

    /* every segment fixed */
    CHECK(phc_rod_new(g, young, &o, &rod, &err) == PHC_OK);
    for (size_t i = 0; i < 5; ++i)
        phc_rod_set_fixed(rod, i, 1, &err);
    rc = phc_rod_solve_static(rod, NULL, &err);
    printf("bad input: every segment fixed -> %d: %s\n", rc, err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "every segment is fixed");
    CHECK(phc_rod_set_fixed(rod, 0, 0, &err) == PHC_ERR_INPUT);
    CHECK(phc_rod_set_fixed(rod, 9, 1, &err) == PHC_ERR_INPUT);
    printf("bad input: support on segment index 9 of 5 -> %s\n", err.message);
    CHECK(phc_rod_set_joint_factor(rod, 2, 1.5, &err) == PHC_ERR_INPUT);
    CHECK(phc_rod_set_joint_factor(rod, 2, NAN, &err) == PHC_ERR_INPUT);
    const double bad_load[3] = {0, NAN, 0};
    CHECK(phc_rod_set_load(rod, 2, bad_load, &err) == PHC_ERR_INPUT);
    phc_rod_free(rod);
    {
        phc_plant_graph *one = cantilever(1, 1.0, 0.01, 1.0, 0);
        phc_plant_graph *solo = phc_plant_graph_new(1);
        solo->radius[0] = 0.01;
        solo->length[0] = 0.1;
        solo->tail[2] = 0.1;
        phc_plant_graph_finish(solo, "", &err);
        rc = phc_rod_new(solo, young, &o, &rod, &err);
        printf("bad input: a one-segment plant (only the fixed root) -> %d: %s\n", rc, err.message);
        CHECK(rc == PHC_ERR_INPUT);
        phc_plant_graph_free(solo);
        phc_plant_graph_free(one);
    }

    /* a time step at which the dynamics would diverge: a soft heavy rod
     * released with dt = 1 s turns by far more than max_rotation per step */
    young[0] = young[1] = young[2] = young[3] = young[4] = 1e5;
    CHECK(phc_rod_new(g, young, &o, &rod, &err) == PHC_OK);
    double before[3], after[3];
    phc_rod_tail(rod, 4, before);
    rc = phc_rod_step(rod, 1.0, NULL, &err);
    phc_rod_tail(rod, 4, after);
    printf("bad input: time step 1 s on a soft rod -> %d: %s\n", rc, err.message);
    CHECK(rc == PHC_ERR_DOMAIN);
    CHECK_STR_CONTAINS(err.message, "time step");
    CHECK(after[0] == before[0] && after[2] == before[2]); /* nothing half-written */
    CHECK(phc_rod_step(rod, NAN, NULL, &err) == PHC_ERR_DOMAIN);
    CHECK(phc_rod_step(rod, -0.1, NULL, &err) == PHC_ERR_DOMAIN);
    /* the same rod with a sane step works */
    CHECK(phc_rod_step(rod, 1e-3, NULL, &err) == PHC_OK);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void test_random_tree(void)
{
    const size_t n = 2000;
    phc_plant_graph *g = phc_plant_graph_random(n, 7);
    phc_rod_options o;
    phc_rod_options_default(&o);
    phc_rod *rod = make_rod(g, 2e8, &o);
    phc_rod_report rep;
    const double t0 = now();
    const int rc = solve_static(rod, &rep);
    const double t1 = now();
    CHECK(rc == PHC_OK);
    double maxd = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double d[3];
        phc_rod_tip_deflection(rod, i, d);
        maxd = fmax(maxd, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
        CHECK(isfinite(d[0]) && isfinite(d[1]) && isfinite(d[2]));
    }
    printf("random tree, %zu segments, E = 2e8 Pa: static equilibrium in %d Newton iterations, "
           "residual %.2e, largest tip displacement %.4f m, %.3f s = %.3f us per segment per "
           "iteration (assembly, factorisation, solve and line search; not asserted)\n",
           n, rep.iterations, rep.residual, maxd, t1 - t0,
           1e6 * (t1 - t0) / ((double)n * (rep.iterations > 0 ? rep.iterations : 1)));
    /* dynamics from that equilibrium after gravity tilts by 3 degrees:
     * implicit steps of 1 ms, each a few Newton iterations */
    {
        phc_error err;
        int its = 0, ok = 1;
        o.gravity[0] = 9.81 * sin(3.0 * M_PI / 180.0);
        o.gravity[2] = -9.81 * cos(3.0 * M_PI / 180.0);
        CHECK(phc_rod_set_options(rod, &o, &err) == PHC_OK);
        const double t2 = now();
        for (int s = 0; s < 20 && ok; ++s) {
            ok = phc_rod_step(rod, 1e-3, &rep, &err) == PHC_OK;
            if (!ok)
                fprintf(stderr, "step %d: %s\n", s, err.message);
            its += rep.total_iterations;
        }
        const double t3 = now();
        CHECK(ok);
        printf("  20 implicit steps of 1 ms: %d Newton iterations, %.3f us per segment per "
               "iteration (not asserted)\n",
               its, 1e6 * (t3 - t2) / ((double)n * (its > 0 ? its : 1)));
    }
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

/* The whole Newton matrix (joint Jacobians, geometric stiffness of the
 * constraints and of the tail loads, the −½[r]× term of the moving chart)
 * against central differences of the residual, on a branched plant with a
 * support, away from equilibrium. */
static void test_newton_matrix(void)
{
    phc_plant_graph *g = phc_plant_graph_new(7);
    const double pts[7][2][3] = {
        {{0, 0, 0}, {0, 0, 0.1}},         {{0, 0, 0.1}, {0.02, 0, 0.2}},
        {{0.02, 0, 0.2}, {0.1, 0.03, 0.25}}, {{0.1, 0.03, 0.25}, {0.18, 0.05, 0.27}},
        {{0.02, 0, 0.2}, {-0.05, -0.04, 0.3}}, {{-0.05, -0.04, 0.3}, {-0.1, -0.1, 0.33}},
        {{-0.1, -0.1, 0.33}, {-0.12, -0.18, 0.3}}};
    const size_t par[7] = {PHC_PLANT_NO_PARENT, 0, 1, 2, 1, 4, 5};
    phc_error err;
    for (size_t i = 0; i < 7; ++i) {
        g->parent[i] = par[i];
        g->radius[i] = 0.004 - 0.0004 * (double)i;
        for (int k = 0; k < 3; ++k) {
            g->head[3 * i + k] = pts[i][0][k];
            g->tail[3 * i + k] = pts[i][1][k];
        }
        const double dx = pts[i][1][0] - pts[i][0][0], dy = pts[i][1][1] - pts[i][0][1],
                     dz = pts[i][1][2] - pts[i][0][2];
        g->length[i] = sqrt(dx * dx + dy * dy + dz * dz);
    }
    g->fixed[3] = 1; /* a support at the end of one branch */
    CHECK(phc_plant_graph_finish(g, "", &err) == PHC_OK);
    double young[7] = {3e7, 2e7, 1e7, 1e7, 5e6, 4e6, 3e6};
    phc_rod *rod = NULL;
    CHECK(phc_rod_new(g, young, NULL, &rod, &err) == PHC_OK);
    const double F1[3] = {0.3, -0.2, -0.5}, F2[3] = {-0.4, 0.6, 0.1};
    phc_rod_set_load(rod, 6, F1, &err);
    phc_rod_set_joint_factor(rod, 5, 0.4, &err);
    CHECK(solve_static(rod, NULL) == PHC_OK);
    phc_rod_set_load(rod, 6, F2, &err); /* away from equilibrium */
    phc_rod_set_load(rod, 2, F1, &err);
    double e, m;
    CHECK(phc_rod_internal_jacobian_check(rod, 1e-6, &e, &m, &err) == PHC_OK);
    printf("Newton matrix of a branched plant with a support, away from equilibrium, vs central "
           "differences of the residual: max |error| %.3e (max |entry| %.3e)\n",
           e, m);
    CHECK(e <= 1e-7 * m);
    /* and the solve from there converges */
    phc_rod_report rep;
    CHECK(solve_static(rod, &rep) == PHC_OK);
    printf("  then the static solve: %d Newton iterations, residual %.2e\n", rep.iterations,
           rep.residual);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

int main(void)
{
    test_derivatives();
    test_tree_solver();
    test_newton_matrix();
    test_cantilevers();
    test_three_point();
    test_elastica();
    test_supports();
    test_independence();
    test_free_fall();
    test_frequency();
    test_gauss_seidel();
    test_bad_input();
    test_random_tree();
    return check_finish("test_rod");
}
