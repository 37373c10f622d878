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
        for (int r = 0; r < d; ++r)
            for (int c = 0; c <= r; ++c) {
                double v = RND() + (r == c ? 3.0 : 0.0);
                if (r >= 6 && c >= 6)
                    v = (r == c) ? -0.5 : 0.0; /* a KKT-like −α block */
                t->diag[144 * i + r * 12 + c] = t->diag[144 * i + c * 12 + r] = v;
                A[(off[i] + r) * dimtot + off[i] + c] = A[(off[i] + c) * dimtot + off[i] + r] = v;
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

int main(void)
{
    test_derivatives();
    test_tree_solver();
    test_cantilevers();
    return check_finish("test_rod");
}
