/* Sensitivities of the rods' static equilibrium with respect to the
 * segments' Young's moduli (model/rod.h: phc_rod_static_sensitivity,
 * phc_rod_static_adjoint, phc_rod_end_sensitivity, phc_rod_end_gradient):
 *
 * 1. the KKT matrix they factorise is symmetric (measured, every entry);
 * 2. a cantilever with a tip mass bent far (tip angles up to 1.2 rad) at
 *    several E, uniform and per-segment directions: dz against central
 *    differences of the equilibrium (E ± h along the direction, h = 1e-5 of
 *    E), every centre and rotation;
 * 3. a branched plant with a support (the supports' Schur complement),
 *    per-segment moduli and joint factors: the same (step 1e-4 of E: this
 *    soft plant's solves leave ~1e-13 m of rounding, which smaller steps
 *    magnify), and the adjoint of a
 *    scalar of the positions (the tracked segment's angle in the x–z plane)
 *    against the forward sensitivity and against central differences in
 *    each segment's modulus;
 * 4. the exact limit: a cantilever under a small tip load deflects by
 *    δ = F L³/(3 E I) (Euler–Bernoulli; the discrete chain to its
 *    discretisation error), δ ∝ 1/E, so E dδ/dE / δ = −1 up to the
 *    geometric nonlinearity O((δ/L)²);
 * 5. refusals: a rod not at equilibrium, a non-finite direction.
 * Every checked number is printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "model/plant_graph.h"
#include "model/quaternion.h"
#include "model/rod.h"
#include "model/rod_internal.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* A cantilever along the direction `angle` (rad from +x in the x–z plane):
 * a fixed clamp 1e-3 of a segment long, then n segments of L/n. */
static phc_plant_graph *cantilever(size_t n, double L, double r, double angle)
{
    phc_plant_graph *g = phc_plant_graph_new(n + 1);
    const double h = L / (double)n, h0 = 1e-3 * h, c = cos(angle), s = sin(angle);
    for (size_t i = 0; i <= n; ++i) {
        const double a = i ? (double)(i - 1) * h : -h0, b = i ? a + h : 0.0;
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = r;
        g->length[i] = b - a;
        g->source_id[i] = (long)(10 + i);
        g->head[3 * i] = a * c;
        g->head[3 * i + 2] = a * s;
        g->tail[3 * i] = b * c;
        g->tail[3 * i + 2] = b * s;
    }
    g->fixed[0] = 1;
    phc_error err;
    if (phc_plant_graph_finish(g, "cantilever", &err)) {
        fprintf(stderr, "%s\n", err.message);
        exit(1);
    }
    return g;
}

/* The branched plant of test_rod's Newton-matrix test: 7 segments, a
 * support at the end of one branch (segment 3). */
static phc_plant_graph *branched(void)
{
    phc_plant_graph *g = phc_plant_graph_new(7);
    const double pts[7][2][3] = {
        {{0, 0, 0}, {0, 0, 0.1}},         {{0, 0, 0.1}, {0.02, 0, 0.2}},
        {{0.02, 0, 0.2}, {0.1, 0.03, 0.25}}, {{0.1, 0.03, 0.25}, {0.18, 0.05, 0.27}},
        {{0.02, 0, 0.2}, {-0.05, -0.04, 0.3}}, {{-0.05, -0.04, 0.3}, {-0.1, -0.1, 0.33}},
        {{-0.1, -0.1, 0.33}, {-0.12, -0.18, 0.3}}};
    const size_t par[7] = {PHC_PLANT_NO_PARENT, 0, 1, 2, 1, 4, 5};
    for (size_t i = 0; i < 7; ++i) {
        g->parent[i] = par[i];
        g->radius[i] = 0.004 - 0.0004 * (double)i;
        g->source_id[i] = (long)i;
        double d2 = 0;
        for (int k = 0; k < 3; ++k) {
            g->head[3 * i + k] = pts[i][0][k];
            g->tail[3 * i + k] = pts[i][1][k];
            d2 += (pts[i][1][k] - pts[i][0][k]) * (pts[i][1][k] - pts[i][0][k]);
        }
        g->length[i] = sqrt(d2);
    }
    g->fixed[3] = 1;
    phc_error err;
    if (phc_plant_graph_finish(g, "branched", &err)) {
        fprintf(stderr, "%s\n", err.message);
        exit(1);
    }
    return g;
}

static int solve(phc_rod *rod)
{
    phc_error err;
    const int rc = phc_rod_solve_static(rod, NULL, &err);
    if (rc)
        fprintf(stderr, "static solve: %s\n", err.message);
    return rc;
}

static int set_young(phc_rod *rod, const double *young)
{
    phc_error err;
    const int rc = phc_rod_set_modulus(rod, young, &err);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    return rc;
}

/* Centres and orientations of every segment. */
static void state(const phc_rod *rod, double *x, double *q)
{
    const size_t n = phc_rod_segment_count(rod);
    for (size_t i = 0; i < n; ++i) {
        double h[3], t[3];
        phc_rod_head(rod, i, h);
        phc_rod_tail(rod, i, t);
        for (int k = 0; k < 3; ++k)
            x[3 * i + k] = 0.5 * (h[k] + t[k]);
        memcpy(q + 4 * i, rod->q + 4 * i, 4 * sizeof *q);
    }
}

/* Central differences of the equilibrium along dE (step h per unit): the
 * solves start from the equilibrium at E (restored afterwards). dz_fd: 6n. */
static int fd_direction(phc_rod *rod, const double *young, const double *dE, double h, double *dz_fd)
{
    const size_t n = phc_rod_segment_count(rod);
    double *e = malloc(n * sizeof *e), *xp = malloc(3 * n * sizeof *xp), *xm = malloc(3 * n * sizeof *xm);
    double *qp = malloc(4 * n * sizeof *qp), *qm = malloc(4 * n * sizeof *qm);
    double *x0 = malloc(3 * n * sizeof *x0), *q0 = malloc(4 * n * sizeof *q0), *l0 = malloc(6 * n * sizeof *l0);
    memcpy(x0, rod->x, 3 * n * sizeof *x0);
    memcpy(q0, rod->q, 4 * n * sizeof *q0);
    memcpy(l0, rod->lambda, 6 * n * sizeof *l0);
    int rc = 0;
    for (int sgn = 1; sgn >= -1 && !rc; sgn -= 2) {
        for (size_t i = 0; i < n; ++i)
            e[i] = young[i] + sgn * h * dE[i];
        rc = set_young(rod, e) || solve(rod);
        if (!rc)
            state(rod, sgn > 0 ? xp : xm, sgn > 0 ? qp : qm);
        memcpy(rod->x, x0, 3 * n * sizeof *x0);
        memcpy(rod->q, q0, 4 * n * sizeof *q0);
        memcpy(rod->lambda, l0, 6 * n * sizeof *l0);
    }
    rc = rc || set_young(rod, young);
    for (size_t i = 0; i < n && !rc; ++i) {
        double c[4], r[4], th[3];
        for (int k = 0; k < 3; ++k)
            dz_fd[6 * i + k] = (xp[3 * i + k] - xm[3 * i + k]) / (2 * h);
        phc_quat_conj(qm + 4 * i, c);
        phc_quat_mul(qp + 4 * i, c, r);
        if (r[0] < 0)
            for (int k = 0; k < 4; ++k)
                r[k] = -r[k];
        phc_quat_log(r, th);
        for (int k = 0; k < 3; ++k)
            dz_fd[6 * i + 3 + k] = th[k] / (2 * h);
    }
    free(e);
    free(xp);
    free(xm);
    free(qp);
    free(qm);
    free(x0);
    free(q0);
    free(l0);
    return rc;
}

/* max |a − b| / max |b| over centres (scaled by L, so m per Pa × 1/L) and
 * rotations together */
static double rel_error(size_t n, const double *a, const double *b, double L, double *scale_out)
{
    double e = 0, s = 0;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 6; ++k) {
            const double w = k < 3 ? 1.0 / L : 1.0;
            e = fmax(e, w * fabs(a[6 * i + k] - b[6 * i + k]));
            s = fmax(s, w * fabs(b[6 * i + k]));
        }
    if (scale_out)
        *scale_out = s;
    return s > 0 ? e / s : INFINITY;
}

static void test_symmetry(void)
{
    phc_plant_graph *g = branched();
    double young[7] = {3e7, 2e7, 1e7, 1e7, 5e6, 4e6, 3e6};
    phc_rod *rod = NULL;
    phc_error err;
    CHECK(phc_rod_new(g, young, NULL, &rod, &err) == PHC_OK);
    const double F[3] = {0.3, -0.2, -0.5};
    phc_rod_set_load(rod, 6, F, &err);
    phc_rod_set_joint_factor(rod, 5, 0.4, &err);
    CHECK(solve(rod) == 0);
    double asym = NAN, big = NAN;
    CHECK(phc_rod_internal_symmetry_check(rod, &asym, &big, &err) == PHC_OK);
    printf("KKT matrix of the sensitivities (branched plant with a support, at equilibrium): "
           "max |A - A^T| %.3g, max |A| %.3g\n",
           asym, big);
    CHECK(big > 0 && asym <= 1e-15 * big);
    /* away from equilibrium too: it is symmetric by construction */
    const double F2[3] = {-0.4, 0.6, 0.1};
    phc_rod_set_load(rod, 2, F2, &err);
    CHECK(phc_rod_internal_symmetry_check(rod, &asym, &big, &err) == PHC_OK);
    printf("  and away from equilibrium (another load added): max |A - A^T| %.3g, max |A| %.3g\n", asym, big);
    CHECK(big > 0 && asym <= 1e-15 * big);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

static void test_cantilever_large(void)
{
    const size_t n = 12;
    const double L = 0.05, r = 1e-3, m_tip = 1e-3;
    phc_plant_graph *g = cantilever(n, L, r, 30 * M_PI / 180);
    const double Es[3] = {2e6, 1e7, 1e8};
    for (int which = 0; which < 3; ++which) {
        double young[13], ones[13], var[13];
        for (size_t i = 0; i <= n; ++i) {
            young[i] = Es[which] * (1.0 + 0.3 * sin(1.7 * (double)i)); /* per segment */
            ones[i] = young[i];                                       /* d/d log E, uniform */
            var[i] = young[i] * cos(0.9 * (double)i);                 /* a per-segment direction */
        }
        phc_rod_options o;
        phc_rod_options_default(&o);
        o.tolerance = 1e-13;
        phc_rod *rod = NULL;
        phc_error err;
        CHECK(phc_rod_new(g, young, &o, &rod, &err) == PHC_OK);
        const double F[3] = {0, 0, -m_tip * 9.81};
        phc_rod_set_load(rod, n, F, &err);
        if (solve(rod)) {
            CHECK(0);
            phc_rod_free(rod);
            continue;
        }
        double h[3], t[3];
        phc_rod_head(rod, n, h);
        phc_rod_tail(rod, n, t);
        const double tip = atan2(t[2] - h[2], t[0] - h[0]);
        double dirs[2 * 13], dz[2 * 6 * 13], fd[6 * 13];
        memcpy(dirs, ones, sizeof ones);
        memcpy(dirs + 13, var, sizeof var);
        CHECK(phc_rod_static_sensitivity(rod, 2, dirs, dz, &err) == PHC_OK);
        for (int d = 0; d < 2; ++d) {
            CHECK(fd_direction(rod, young, dirs + 13 * d, 1e-5, fd) == 0);
            double scale;
            const double e = rel_error(n + 1, dz + 6 * 13 * d, fd, L, &scale);
            printf("cantilever, 12 segments, E ~ %.0e Pa, tip mass 1 g, last segment at %.3f rad: %s direction: "
                   "dz vs central differences %.2e (relative to the largest entry %.3g)\n",
                   Es[which], tip, d ? "per-segment" : "uniform (d/d log E)", e, scale);
            CHECK(e <= 1e-6);
        }
        phc_rod_free(rod);
    }
    phc_plant_graph_free(g);
}

/* the angle of segment s's axis in the x–z plane and its head/tail gradients */
static double seg_angle(const phc_rod *rod, size_t s, double gh[3], double gt[3])
{
    double h[3], t[3];
    phc_rod_head(rod, s, h);
    phc_rod_tail(rod, s, t);
    const double dx = t[0] - h[0], dz = t[2] - h[2], r2 = dx * dx + dz * dz;
    if (gh && gt) {
        gt[0] = -dz / r2;
        gt[1] = 0;
        gt[2] = dx / r2;
        for (int k = 0; k < 3; ++k)
            gh[k] = -gt[k];
    }
    return atan2(dz, dx);
}

static void test_branched(void)
{
    phc_plant_graph *g = branched();
    const size_t n = 7, s = 6;
    double young[7] = {3e7, 2e7, 1e7, 1e7, 5e6, 4e6, 3e6};
    phc_rod_options o;
    phc_rod_options_default(&o);
    o.tolerance = 1e-13;
    phc_rod *rod = NULL;
    phc_error err;
    CHECK(phc_rod_new(g, young, &o, &rod, &err) == PHC_OK);
    const double F[3] = {0.3, -0.2, -0.5};
    phc_rod_set_load(rod, 6, F, &err);
    phc_rod_set_joint_factor(rod, 5, 0.4, &err);
    if (solve(rod)) {
        CHECK(0);
        goto done;
    }
    double dz[6 * 7 * 7], fd[6 * 7], dE[7 * 7], worst = 0;
    for (size_t j = 0; j < n; ++j)
        for (size_t i = 0; i < n; ++i)
            dE[j * n + i] = i == j ? young[i] : 0.0; /* d / d log E_j */
    CHECK(phc_rod_static_sensitivity(rod, n, dE, dz, &err) == PHC_OK);
    for (size_t j = 0; j < n; ++j) {
        if (fd_direction(rod, young, dE + j * n, 1e-4, fd)) {
            CHECK(0);
            continue;
        }
        double scale;
        const double e = rel_error(n, dz + 6 * n * j, fd, 0.3, &scale);
        if (scale > 0)
            worst = fmax(worst, e);
    }
    double tip[3];
    phc_rod_tip_deflection(rod, 6, tip);
    printf("branched plant, 7 segments, a support, per-segment E and a weakened joint (tip displaced %.3f m): "
           "dz / d log E_j vs central differences (step 1e-4 in log E: smaller steps measure the solves' rounding, "
           "1.7e-6 at 1e-5), every segment j: largest %.2e\n",
           sqrt(tip[0] * tip[0] + tip[1] * tip[1] + tip[2] * tip[2]), worst);
    CHECK(worst <= 1e-6);
    /* the adjoint of the angle of segment 6 */
    double gh[3], gt[3], gz[6 * 7] = {0}, dg[7], worst_fw = 0, worst_fd = 0, big = 0;
    seg_angle(rod, s, gh, gt);
    phc_rod_end_gradient(rod, s, gh, gt, gz + 6 * s);
    CHECK(phc_rod_static_adjoint(rod, gz, dg, &err) == PHC_OK);
    for (size_t j = 0; j < n; ++j) {
        double dhd[3], dtl[3], fw = 0;
        phc_rod_end_sensitivity(rod, s, dz + 6 * n * j, dhd, dtl);
        for (int k = 0; k < 3; ++k)
            fw += gh[k] * dhd[k] + gt[k] * dtl[k];
        /* dz was per log E_j: per Pa divide by E_j */
        fw /= young[j];
        /* central difference of the angle in E_j, from the equilibrium */
        double e[7], a[2];
        memcpy(e, young, sizeof e);
        double x0[21], q0[28], l0[42];
        memcpy(x0, rod->x, sizeof x0);
        memcpy(q0, rod->q, sizeof q0);
        memcpy(l0, rod->lambda, sizeof l0);
        const double hstep = 1e-5 * young[j];
        for (int sg = 0; sg < 2; ++sg) {
            e[j] = young[j] + (sg ? -hstep : hstep);
            CHECK(set_young(rod, e) == 0 && solve(rod) == 0);
            a[sg] = seg_angle(rod, s, NULL, NULL);
            memcpy(rod->x, x0, sizeof x0);
            memcpy(rod->q, q0, sizeof q0);
            memcpy(rod->lambda, l0, sizeof l0);
        }
        CHECK(set_young(rod, young) == 0);
        const double cd = (a[0] - a[1]) / (2 * hstep);
        big = fmax(big, fabs(cd));
        worst_fw = fmax(worst_fw, fabs(dg[j] - fw));
        worst_fd = fmax(worst_fd, fabs(dg[j] - cd));
    }
    printf("  adjoint d(angle of segment 6)/dE_j, every j: vs the forward sensitivity %.2e, vs central differences "
           "%.2e (relative to the largest %.3g rad/Pa)\n",
           worst_fw / big, worst_fd / big, big);
    CHECK(big > 0 && worst_fw <= 1e-10 * big && worst_fd <= 1e-6 * big);
done:
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

static void test_limit(void)
{
    const size_t n = 50;
    const double L = 0.1, r = 2e-3, E = 1e9, I = M_PI * pow(r, 4) / 4, P = 2e-6 * 9.81;
    phc_plant_graph *g = cantilever(n, L, r, 0.0);
    phc_rod_options o;
    phc_rod_options_default(&o);
    o.density = 1e-6; /* own weight negligible */
    o.tolerance = 1e-13;
    double young[51], ones[51], dz[6 * 51];
    for (size_t i = 0; i <= n; ++i) {
        young[i] = E;
        ones[i] = 1.0;
    }
    phc_rod *rod = NULL;
    phc_error err;
    CHECK(phc_rod_new(g, young, &o, &rod, &err) == PHC_OK);
    const double F[3] = {0, 0, -P};
    phc_rod_set_load(rod, n, F, &err);
    CHECK(solve(rod) == 0);
    double d[3], dh[3], dt[3];
    phc_rod_tip_deflection(rod, n, d);
    CHECK(phc_rod_static_sensitivity(rod, 1, ones, dz, &err) == PHC_OK);
    phc_rod_end_sensitivity(rod, n, dz, dh, dt);
    const double delta = -d[2], ddelta = -dt[2], eb = P * L * L * L / (3 * E * I);
    printf("small deflection, 50 segments: tip deflection %.6e m, Euler-Bernoulli FL^3/(3EI) %.6e m (ratio %.6f); "
           "E d(delta)/dE / delta = %.12f (exact -1 for delta ~ 1/E; delta/L = %.1e)\n",
           delta, eb, delta / eb, E * ddelta / delta, delta / L);
    CHECK_NEAR(delta, eb, 0, 2e-3);
    CHECK_NEAR(E * ddelta / delta, -1.0, 1e-8, 0);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

static void test_refusals(void)
{
    phc_plant_graph *g = cantilever(4, 0.05, 1e-3, 0.0);
    double young[5] = {1e7, 1e7, 1e7, 1e7, 1e7}, dz[30] = {0}, bad[5] = {1, 1, NAN, 1, 1};
    phc_rod *rod = NULL;
    phc_error err;
    CHECK(phc_rod_new(g, young, NULL, &rod, &err) == PHC_OK);
    int rc = phc_rod_static_sensitivity(rod, 1, young, dz, &err); /* at rest under gravity: no equilibrium */
    CHECK(rc == PHC_ERR_DOMAIN);
    CHECK_STR_CONTAINS(err.message, "not at a static equilibrium");
    printf("refused at the rest shape: %s\n", err.message);
    CHECK(solve(rod) == 0);
    rc = phc_rod_static_sensitivity(rod, 1, bad, dz, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "segment 12");
    printf("refused: %s\n", err.message);
    young[2] = 2e7; /* moduli changed after the solve */
    CHECK(set_young(rod, young) == 0);
    rc = phc_rod_static_adjoint(rod, dz, young, &err);
    CHECK(rc == PHC_ERR_DOMAIN);
    printf("refused after a change of moduli: %s\n", err.message);
    phc_rod_free(rod);
    phc_plant_graph_free(g);
}

int main(void)
{
    test_symmetry();
    test_cantilever_large();
    test_branched();
    test_limit();
    test_refusals();
    return check_finish("test_rod_sensitivity");
}
