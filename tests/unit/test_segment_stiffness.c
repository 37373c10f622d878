/* Water -> stiffness (model/segment_stiffness.h): the three laws of wilting
 * Fig. 5 on small graphs by hand, the limits kappa -> 0+ and x -> +-inf,
 * every analytic derivative against central differences, the reference
 * (authors' PlantDemo.cpp) joint moduli, radii, lengths and masses against
 * numbers computed by hand from their formulas on a 3-segment chain, and
 * bad parameters refused with a message. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "model/plant_graph.h"
#include "model/segment_stiffness.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* A graph from parents, radii and lengths (m), laid out along z. */
static phc_plant_graph *make_graph(size_t n, const size_t *parent, const double *r,
                                   const double *len, const unsigned char *leaf)
{
    phc_plant_graph *g = phc_plant_graph_new(n);
    phc_error err;
    for (size_t i = 0; i < n; ++i) {
        g->parent[i] = parent[i];
        g->radius[i] = r[i];
        g->length[i] = len[i];
        g->leaf[i] = leaf ? leaf[i] : 0;
    }
    /* heads at the parent's tail, tails straight up (coordinates unused here) */
    for (size_t i = 0; i < n; ++i) {
        const size_t p = parent[i];
        double z0 = 0;
        for (size_t q = p; q != PHC_PLANT_NO_PARENT; q = parent[q])
            z0 += len[q];
        g->head[3 * i + 2] = z0;
        g->tail[3 * i + 2] = z0 + len[i];
    }
    if (phc_plant_graph_finish(g, "test", &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

static double eval_one(const phc_plant_graph *g, const phc_segment_stiffness_params *p,
                       const double *theta, size_t i)
{
    double E[8];
    phc_error err;
    if (phc_segment_stiffness_water(g, p, theta, E, NULL, NULL, &err) != PHC_OK)
        return NAN;
    return E[i];
}

static void check_derivatives(const phc_plant_graph *g, phc_segment_stiffness_params p,
                              const double *theta_in)
{
    const size_t n = g->n;
    double E[8], dp[32], dth[8], theta[8];
    phc_error err;
    for (size_t i = 0; i < n; ++i)
        theta[i] = theta_in[i];
    CHECK(phc_segment_stiffness_water(g, &p, theta, E, dp, dth, &err) == PHC_OK);
    double maxrel = 0;
    for (int k = 0; k < 4; ++k) {
        double *slot[4] = {&p.logistic.kappa, &p.logistic.chi0, &p.logistic.e_min,
                           &p.logistic.e_max};
        const double v = *slot[k], h = 1e-6 * (fabs(v) + 1e-3);
        for (size_t i = 0; i < n; ++i) {
            *slot[k] = v + h;
            const double ep = eval_one(g, &p, theta, i);
            *slot[k] = v - h;
            const double em = eval_one(g, &p, theta, i);
            *slot[k] = v;
            const double fd = (ep - em) / (2 * h);
            CHECK_NEAR(dp[4 * i + k], fd, 1e-9 * fabs(E[i]), 1e-6);
            if (fabs(fd) * h > 1e-8 * fabs(E[i])) /* not drowned in rounding */
                maxrel = fmax(maxrel, fabs(dp[4 * i + k] - fd) / fabs(fd));
        }
    }
    for (size_t i = 0; i < n; ++i) {
        const double t0 = theta[i], h = 1e-6 * (fabs(t0) + 1e-6);
        theta[i] = t0 + h;
        const double ep = eval_one(g, &p, theta, i);
        theta[i] = t0 - h;
        const double em = eval_one(g, &p, theta, i);
        theta[i] = t0;
        const double fd = (ep - em) / (2 * h);
        CHECK_NEAR(dth[i], fd, 1e-9 * fabs(E[i]) / (fabs(t0) + 1e-6), 1e-6);
        if (fabs(fd) * h > 1e-8 * fabs(E[i]))
            maxrel = fmax(maxrel, fabs(dth[i] - fd) / fabs(fd));
        /* E_i depends on theta_i only: moving theta_j leaves E_i unchanged */
        for (size_t j = 0; j < n; ++j)
            if (j != i) {
                theta[j] += 0.1;
                CHECK(eval_one(g, &p, theta, i) == E[i]);
                theta[j] -= 0.1;
            }
    }
    printf("  %s content, kappa %g: largest relative difference analytic vs central "
           "difference: %.2e\n",
           p.content == PHC_STIFFNESS_RELATIVE ? "relative" : "absolute", p.logistic.kappa, maxrel);
}

int main(void)
{
    phc_error err;

    /* ---- a 4-segment tree for the laws: 0 root; 1, 3 children of 0; 2 child of 1 */
    const size_t par4[4] = {PHC_PLANT_NO_PARENT, 0, 1, 0};
    const double r4[4] = {0.01, 0.005, 0.002, 0.004};   /* m */
    const double l4[4] = {0.10, 0.05, 0.02, 0.04};      /* m */
    phc_plant_graph *g4 = make_graph(4, par4, r4, l4, NULL);
    CHECK(g4 != NULL);
    if (!g4)
        return check_finish("test_segment_stiffness");
    double V4[4];
    for (size_t i = 0; i < 4; ++i) {
        V4[i] = M_PI * (100 * r4[i]) * (100 * r4[i]) * (100 * l4[i]); /* cm^3 */
        CHECK_NEAR(phc_segment_volume_cm3(g4, i), V4[i], 0, 1e-15);
    }

    /* water law, relative: theta = (0.9, 0.7, 0.5, 1.1) V  ->  x = those RWCs;
     * kappa 10, chi0 0.7, E_min 1e6, E_max 1e9:
     * E = 1e6 + 1e9 sigma(10 (x - 0.7)): sigma(2) = 0.88079707797788231,
     * sigma(0) = 0.5, sigma(-2) = 0.11920292202211769, sigma(4) = 0.98201379003790845 */
    phc_segment_stiffness_params p = phc_segment_stiffness_params_default();
    p.logistic.kappa = 10;
    p.logistic.chi0 = 0.7;
    p.logistic.e_min = 1e6;
    p.logistic.e_max = 1e9;
    const double rwc[4] = {0.9, 0.7, 0.5, 1.1};
    double theta[4], E[4];
    for (size_t i = 0; i < 4; ++i)
        theta[i] = rwc[i] * V4[i];
    CHECK(phc_segment_stiffness_water(g4, &p, theta, E, NULL, NULL, &err) == PHC_OK);
    CHECK_NEAR(E[0], 1e6 + 1e9 * 0.88079707797788231, 0, 1e-13);
    CHECK_NEAR(E[1], 1e6 + 1e9 * 0.5, 0, 1e-13);
    CHECK_NEAR(E[2], 1e6 + 1e9 * 0.11920292202211769, 0, 1e-13);
    CHECK_NEAR(E[3], 1e6 + 1e9 * 0.98201379003790845, 0, 1e-13);
    printf("water law (relative), E (Pa): %.10g %.10g %.10g %.10g\n", E[0], E[1], E[2], E[3]);
    /* the dispatcher gives the same */
    double E2[4];
    CHECK(phc_segment_stiffness(g4, &p, theta, E2, &err) == PHC_OK);
    for (size_t i = 0; i < 4; ++i)
        CHECK(E2[i] == E[i]);

    /* water law, absolute: x = theta (g); chi0 = 0.5 g, kappa 4 per g;
     * theta = (0.5, 1.0, 0.25, 0) g -> z = (0, 2, -1, -2) */
    {
        phc_segment_stiffness_params a = p;
        a.content = PHC_STIFFNESS_ABSOLUTE;
        a.logistic.kappa = 4;
        a.logistic.chi0 = 0.5;
        const double th[4] = {0.5, 1.0, 0.25, 0.0};
        CHECK(phc_segment_stiffness_water(g4, &a, th, E, NULL, NULL, &err) == PHC_OK);
        CHECK_NEAR(E[0], 1e6 + 1e9 * 0.5, 0, 1e-13);
        CHECK_NEAR(E[1], 1e6 + 1e9 * 0.88079707797788231, 0, 1e-13);
        CHECK_NEAR(E[2], 1e6 + 1e9 * 0.2689414213699951, 0, 1e-13);
        CHECK_NEAR(E[3], 1e6 + 1e9 * 0.11920292202211769, 0, 1e-13);
        printf("water law (absolute), E (Pa): %.10g %.10g %.10g %.10g\n", E[0], E[1], E[2], E[3]);
        printf("derivatives against central differences:\n");
        check_derivatives(g4, a, th);
    }
    check_derivatives(g4, p, theta);
    {   /* a steep logistic, x on its shoulder */
        phc_segment_stiffness_params s = p;
        s.logistic.kappa = 80;
        check_derivatives(g4, s, theta);
    }

    /* limits: kappa -> 0+ gives E_min + E_max / 2 (error <= E_max kappa |x - chi0| / 4) */
    for (double kappa = 1e-2; kappa >= 1e-12; kappa /= 100) {
        phc_segment_stiffness_params q = p;
        q.logistic.kappa = kappa;
        CHECK(phc_segment_stiffness_water(g4, &q, theta, E, NULL, NULL, &err) == PHC_OK);
        for (size_t i = 0; i < 4; ++i)
            CHECK_NEAR(E[i], 1e6 + 0.5e9, 1e9 * kappa * fabs(rwc[i] - 0.7) / 4 * 1.0001 + 1e-6, 0);
    }
    /* x -> +inf: E_min + E_max; x -> -inf: E_min (relative content 1e6, -1e6) */
    {
        double big[4], small[4], Eb[4], Es[4];
        for (size_t i = 0; i < 4; ++i) {
            big[i] = 1e6 * V4[i];
            small[i] = -1e6 * V4[i];
        }
        CHECK(phc_segment_stiffness_water(g4, &p, big, Eb, NULL, NULL, &err) == PHC_OK);
        CHECK(phc_segment_stiffness_water(g4, &p, small, Es, NULL, NULL, &err) == PHC_OK);
        for (size_t i = 0; i < 4; ++i) {
            CHECK_NEAR(Eb[i], 1e6 + 1e9, 0, 1e-15);
            CHECK_NEAR(Es[i], 1e6, 0, 1e-15);
            CHECK(isfinite(Eb[i]) && isfinite(Es[i]));
        }
        printf("limits: x -> +inf E = %.6g, x -> -inf E = %.6g (E_min %.6g, E_min + E_max %.6g)\n",
               Eb[0], Es[0], 1e6, 1e6 + 1e9);
    }

    /* depth law: E_base / (1 + d), depths (0, 1, 2, 1) */
    {
        double dE[4];
        CHECK(phc_segment_stiffness_depth(g4, 3e9, E, dE, &err) == PHC_OK);
        CHECK_NEAR(E[0], 3e9, 0, 1e-15);
        CHECK_NEAR(E[1], 1.5e9, 0, 1e-15);
        CHECK_NEAR(E[2], 1e9, 0, 1e-15);
        CHECK_NEAR(E[3], 1.5e9, 0, 1e-15);
        CHECK_NEAR(dE[2], 1.0 / 3.0, 0, 1e-15);
        printf("depth law, E (Pa): %.6g %.6g %.6g %.6g\n", E[0], E[1], E[2], E[3]);
        phc_segment_stiffness_params q = p;
        q.law = PHC_STIFFNESS_DEPTH;
        q.e_base = 3e9;
        CHECK(phc_segment_stiffness(g4, &q, NULL, E2, &err) == PHC_OK);
        CHECK(E2[2] == E[2]);
    }
    /* radius law: E_base r / r_max, r = (10, 5, 2, 4) mm -> (1, 0.5, 0.2, 0.4) */
    {
        double dE[4];
        CHECK(phc_segment_stiffness_radius(g4, 3e9, E, dE, &err) == PHC_OK);
        CHECK_NEAR(E[0], 3e9, 0, 1e-15);
        CHECK_NEAR(E[1], 1.5e9, 0, 1e-15);
        CHECK_NEAR(E[2], 6e8, 0, 1e-15);
        CHECK_NEAR(E[3], 1.2e9, 0, 1e-15);
        CHECK_NEAR(dE[3], 0.4, 0, 1e-15);
        printf("radius law, E (Pa): %.6g %.6g %.6g %.6g\n", E[0], E[1], E[2], E[3]);
        /* central difference in E_base (the law is linear: exact) */
        double Ep[4], Em[4];
        CHECK(phc_segment_stiffness_radius(g4, 3e9 + 1e3, Ep, NULL, &err) == PHC_OK);
        CHECK(phc_segment_stiffness_radius(g4, 3e9 - 1e3, Em, NULL, &err) == PHC_OK);
        CHECK_NEAR((Ep[3] - Em[3]) / 2e3, dE[3], 0, 1e-6);
        CHECK(phc_segment_stiffness_depth(g4, 3e9 + 1e3, Ep, NULL, &err) == PHC_OK);
        CHECK(phc_segment_stiffness_depth(g4, 3e9 - 1e3, Em, NULL, &err) == PHC_OK);
        CHECK_NEAR((Ep[2] - Em[2]) / 2e3, 1.0 / 3.0, 0, 1e-6);
    }

    /* bad parameters and inputs: refused, with the key and the value */
    {
        phc_segment_stiffness_params q = p;
        q.logistic.kappa = 0;
        CHECK(phc_segment_stiffness_water(g4, &q, theta, E, NULL, NULL, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "kappa must be positive");
        q.logistic.kappa = -3;
        CHECK(phc_segment_stiffness_check(&q, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "found -3");
        q = p;
        q.logistic.e_min = 0;
        CHECK(phc_segment_stiffness_check(&q, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "e_min must be positive");
        q = p;
        q.logistic.e_max = -1;
        CHECK(phc_segment_stiffness_check(&q, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "e_max");
        q = p;
        q.logistic.chi0 = NAN;
        CHECK(phc_segment_stiffness_check(&q, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "chi0");
        double bad[4] = {theta[0], theta[1], NAN, theta[3]};
        CHECK(phc_segment_stiffness_water(g4, &p, bad, E, NULL, NULL, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "segment 2: water must be finite");
        CHECK(phc_segment_stiffness_water(g4, &p, NULL, E, NULL, NULL, &err) == PHC_ERR_INVALID);
        CHECK(phc_segment_stiffness_depth(g4, 0.0, E, NULL, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "e_base must be positive");
        CHECK(phc_segment_stiffness_radius(g4, -1.0, E, NULL, &err) == PHC_ERR_INVALID);
        phc_stiffness_law law;
        phc_stiffness_water_content content;
        CHECK(phc_stiffness_law_from_name("radius", &law) == 0 && law == PHC_STIFFNESS_RADIUS);
        CHECK(phc_stiffness_law_from_name("radii", &law) == -1);
        CHECK(phc_stiffness_content_from_name("absolute", &content) == 0 &&
              content == PHC_STIFFNESS_ABSOLUTE);
        CHECK(phc_stiffness_content_from_name("rwc", &content) == -1);
    }
    phc_plant_graph_free(g4);

    /* ---- reference (PlantDemo.cpp) on a chain 0 -> 1 -> 2; 2 is a leaf.
     * cm: r = (1, 0.5, 0.2), L = (10, 5, 2); V = pi r^2 L =
     * (31.415926535897931, 3.9269908169872414, 0.25132741228718347) cm^3.
     * theta = (0.02, 0.012, 0.016) g.  Defaults Emin 1, Emax 1e10, s 1e3, mid 0.015.
     * joint 1 (N=0, C=1): w = 0.016, E = 1 + 1e10 / (1 + e^-1) = 7310585787.300051,
     *   rbar = rN (LN^2 + LC^2) / (LN + LC) = 1 * 125 / 15 = 8.3333333333333339,
     *   Lbar = 7.5, I = pi/4 rbar^4 = 3787.606883668251, E I = 27689625051624.953,
     *   2 G I = 55379250103249.91;
     * joint 2 (N=1, C=2): w = 0.014, E = 1 + 1e10 / (1 + e^1) = 2689414214.699953,
     *   rbar = 0.5 * 29 / 7 = 2.0714285714285716, Lbar = 3.5,
     *   I = 14.460047855214254, E I = 38889058247.05479, 2 G I = 77778116494.10957;
     * masses per frame (V rho + theta) 1e-3, rho 1 stem, 2 leaf:
     *   (0, 0.003938990816987242, 0.0005186548245743669);
     * at build time (density V + theta0, no scale, no leaf density):
     *   (0, 3.9389908169872414, 0.2673274122871835). */
    {
        const size_t par3[3] = {PHC_PLANT_NO_PARENT, 0, 1};
        const double r3[3] = {0.01, 0.005, 0.002}, l3[3] = {0.10, 0.05, 0.02};
        const unsigned char leaf3[3] = {0, 0, 1};
        phc_plant_graph *g3 = make_graph(3, par3, r3, l3, leaf3);
        CHECK(g3 != NULL);
        if (g3) {
            const phc_stiffness_reference_params rp = phc_stiffness_reference_default();
            const double th[3] = {0.02, 0.012, 0.016};
            double Y[3], G[3], Kb[3], Kt[3], R[3], L[3], W[3], m[3];
            CHECK(phc_stiffness_reference_joints(g3, &rp, th, Y, G, Kb, Kt, R, L, W, &err) ==
                  PHC_OK);
            CHECK(Y[0] == 0 && Kb[0] == 0 && R[0] == 0 && L[0] == 0);
            CHECK_NEAR(W[1], 0.016, 0, 1e-15);
            CHECK_NEAR(W[2], 0.014, 0, 1e-15);
            CHECK_NEAR(Y[1], 7310585787.300051, 0, 1e-14);
            CHECK_NEAR(Y[2], 2689414214.699953, 0, 1e-14);
            CHECK(G[1] == Y[1] && G[2] == Y[2]);
            CHECK_NEAR(R[1], 8.3333333333333339, 0, 1e-15);
            CHECK_NEAR(R[2], 2.0714285714285716, 0, 1e-15);
            CHECK_NEAR(L[1], 7.5, 0, 1e-15);
            CHECK_NEAR(L[2], 3.5, 0, 1e-15);
            CHECK_NEAR(Kb[1], 27689625051624.953, 0, 1e-14);
            CHECK_NEAR(Kb[2], 38889058247.05479, 0, 1e-14);
            CHECK_NEAR(Kt[1], 55379250103249.91, 0, 1e-14);
            CHECK_NEAR(Kt[2], 77778116494.10957, 0, 1e-14);
            printf("reference joints: E = %.16g %.16g, rbar = %.16g %.16g, Lbar = %g %g, "
                   "E I = %.16g %.16g\n",
                   Y[1], Y[2], R[1], R[2], L[1], L[2], Kb[1], Kb[2]);
            /* build time: E = G = Emax */
            CHECK(phc_stiffness_reference_joints(g3, &rp, NULL, Y, G, Kb, Kt, NULL, NULL, W,
                                                 &err) == PHC_OK);
            CHECK(Y[1] == 1e10 && G[2] == 1e10 && W[1] == 0);
            CHECK_NEAR(Kb[1], 37876068836682.51, 0, 1e-14);
            CHECK_NEAR(Kt[2], 2 * 144600478552.14255, 0, 1e-14);
            CHECK(phc_stiffness_reference_masses(g3, &rp, th, 0, m, &err) == PHC_OK);
            CHECK(m[0] == 0);
            CHECK_NEAR(m[1], 0.003938990816987242, 0, 1e-15);
            CHECK_NEAR(m[2], 0.0005186548245743669, 0, 1e-15);
            printf("reference masses per frame: %.16g %.16g %.16g\n", m[0], m[1], m[2]);
            CHECK(phc_stiffness_reference_masses(g3, &rp, th, 1, m, &err) == PHC_OK);
            CHECK(m[0] == 0);
            CHECK_NEAR(m[1], 3.9389908169872414, 0, 1e-15);
            CHECK_NEAR(m[2], 0.2673274122871835, 0, 1e-15);
            printf("reference masses at build: %.16g %.16g %.16g\n", m[0], m[1], m[2]);
            /* latches: a fixed segment weighs 0 per frame when use_latches, not at build */
            phc_stiffness_reference_params lp = rp;
            lp.use_latches = 1;
            g3->fixed[2] = 1;
            CHECK(phc_stiffness_reference_masses(g3, &lp, th, 0, m, &err) == PHC_OK);
            CHECK(m[2] == 0 && m[1] > 0);
            CHECK(phc_stiffness_reference_masses(g3, &lp, th, 1, m, &err) == PHC_OK);
            CHECK(m[2] > 0);
            /* bad reference parameters and water */
            lp = rp;
            lp.steepness = -1;
            CHECK(phc_stiffness_reference_joints(g3, &lp, th, Y, NULL, NULL, NULL, NULL, NULL,
                                                 NULL, &err) == PHC_ERR_INVALID);
            CHECK_STR_CONTAINS(err.message, "steepness must be >= 0");
            const double thn[3] = {0.02, INFINITY, 0.016};
            CHECK(phc_stiffness_reference_masses(g3, &rp, thn, 0, m, &err) == PHC_ERR_INVALID);
            CHECK_STR_CONTAINS(err.message, "segment 1");
            phc_plant_graph_free(g3);
        }
    }
    /* ---- a single segment: no joints; the root weighs 0 and has E_base */
    {
        const size_t par1[1] = {PHC_PLANT_NO_PARENT};
        const double r1[1] = {0.003}, l1[1] = {0.05};
        phc_plant_graph *g1 = make_graph(1, par1, r1, l1, NULL);
        CHECK(g1 != NULL);
        if (g1) {
            const phc_stiffness_reference_params rp = phc_stiffness_reference_default();
            const double th[1] = {0.5};
            double Y[1] = {-1}, m[1] = {-1}, e[1] = {-1};
            CHECK(phc_stiffness_reference_joints(g1, &rp, th, Y, NULL, NULL, NULL, NULL, NULL,
                                                 NULL, &err) == PHC_OK);
            CHECK(Y[0] == 0);
            CHECK(phc_stiffness_reference_masses(g1, &rp, th, 0, m, &err) == PHC_OK);
            CHECK(m[0] == 0);
            CHECK(phc_segment_stiffness_depth(g1, 2e9, e, NULL, &err) == PHC_OK && e[0] == 2e9);
            CHECK(phc_segment_stiffness_radius(g1, 2e9, e, NULL, &err) == PHC_OK && e[0] == 2e9);
            phc_plant_graph_free(g1);
        }
        const phc_segment_stiffness_params d = phc_segment_stiffness_params_default();
        CHECK(phc_segment_stiffness_check(&d, &err) == PHC_OK);
    }
    return check_finish("test_segment_stiffness");
}
