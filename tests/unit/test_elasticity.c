/* Logistic elasticity (model/elasticity.h): analytic derivatives against
 * central differences, the κ → 0 limit, and no overflow / NaN for large |z|. */
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "model/elasticity.h"
#include "model/status.h"

static double eval_with(const phc_elasticity_params *p, int which, double value, double theta)
{
    phc_elasticity_params q = *p;
    double *slot[4] = {&q.kappa, &q.chi0, &q.e_min, &q.e_max};
    *slot[which] = value;
    return phc_elasticity_eval(&q, theta, NULL, NULL);
}

int main(void)
{
    /* derivatives against central differences, over a spread of points */
    const phc_elasticity_params ps[] = {
        {12.0, 0.85, 0.5, 15.0}, {-4.0, 0.6, 2.0, 8.0}, {40.0, 0.9, 0.0, 20.0}, {0.3, 0.2, -1.0, 3.0}};
    for (size_t c = 0; c < sizeof ps / sizeof ps[0]; ++c)
        for (double theta = 0.0; theta <= 1.2; theta += 0.05) {
            double g[4], dth;
            const double E = phc_elasticity_eval(&ps[c], theta, g, &dth);
            const double vals[4] = {ps[c].kappa, ps[c].chi0, ps[c].e_min, ps[c].e_max};
            for (int j = 0; j < 4; ++j) {
                const double h = 1e-6 * (fabs(vals[j]) + 1e-3);
                const double fd = (eval_with(&ps[c], j, vals[j] + h, theta) -
                                   eval_with(&ps[c], j, vals[j] - h, theta)) / (2 * h);
                CHECK_NEAR(g[j], fd, 1e-7 * (1 + fabs(E)), 1e-6);
            }
            const double h = 1e-7;
            const double fd = (phc_elasticity_eval(&ps[c], theta + h, NULL, NULL) -
                               phc_elasticity_eval(&ps[c], theta - h, NULL, NULL)) / (2 * h);
            CHECK_NEAR(dth, fd, 1e-6 * (1 + fabs(E)), 1e-6);
        }

    /* κ → 0: E = E_min + E_max / 2 whatever θ; at κ = 0 exactly too */
    for (double kappa = 1e-3; kappa >= 1e-12; kappa /= 10) {
        const phc_elasticity_params p = {kappa, 0.8, 1.0, 10.0};
        /* E = 6 + E_max σ'(0) κ (θ − χ0) + O(κ³) = 6 − 1.25 κ */
        CHECK_NEAR(phc_elasticity_eval(&p, 0.3, NULL, NULL), 6.0 - 1.25 * kappa, 1e-14 + 10 * kappa * kappa * kappa, 0);
    }
    {
        const phc_elasticity_params p = {0.0, 0.8, 1.0, 10.0};
        double g[4];
        CHECK_NEAR(phc_elasticity_eval(&p, 0.3, g, NULL), 6.0, 0, 1e-15);
        CHECK_NEAR(g[0], 10.0 * 0.25 * (0.3 - 0.8), 0, 1e-15); /* ∂E/∂κ = E_max σ'(0) (θ − χ0) */
        CHECK_NEAR(g[1], 0.0, 0, 0);
        CHECK_NEAR(g[3], 0.5, 0, 1e-15);
    }
    /* limits of the logistic itself */
    CHECK_NEAR(phc_elasticity_sigmoid(0), 0.5, 0, 0);
    CHECK_NEAR(phc_elasticity_sigmoid(2.0) + phc_elasticity_sigmoid(-2.0), 1.0, 3e-16, 0);

    /* large |z|: finite, in [0, 1], derivative ≥ 0 and keeps relative accuracy */
    const double zs[] = {-1e308, -1e5, -745.2, -710, -40, 40, 710, 745.2, 1e5, 1e308};
    for (size_t i = 0; i < sizeof zs / sizeof zs[0]; ++i) {
        const double s = phc_elasticity_sigmoid(zs[i]), d = phc_elasticity_sigmoid_derivative(zs[i]);
        CHECK(isfinite(s) && s >= 0 && s <= 1);
        CHECK(isfinite(d) && d >= 0);
    }
    CHECK_NEAR(phc_elasticity_sigmoid(-40), exp(-40) / (1 + exp(-40)), 0, 1e-14);
    CHECK_NEAR(phc_elasticity_sigmoid_derivative(40), exp(-40), 0, 1e-12); /* not 0 from 1 − σ */
    CHECK(phc_elasticity_sigmoid(1e308) == 1.0 && phc_elasticity_sigmoid(-1e308) == 0.0);
    {
        const phc_elasticity_params p = {1e6, 0.5, 1.0, 10.0};
        double g[4], dth;
        const double lo = phc_elasticity_eval(&p, 0.0, g, &dth);
        CHECK_NEAR(lo, 1.0, 0, 1e-15);
        for (int j = 0; j < 4; ++j)
            CHECK(isfinite(g[j]));
        CHECK(isfinite(dth));
        const double hi = phc_elasticity_eval(&p, 1.0, g, &dth);
        CHECK_NEAR(hi, 11.0, 0, 1e-15);
        for (int j = 0; j < 4; ++j)
            CHECK(isfinite(g[j]));
    }

    /* RWC → absolute for a node of volume V: same E at θ_abs = RWC·V */
    {
        const phc_elasticity_params rwc = {12.0, 0.85, 0.5, 15.0};
        phc_elasticity_params abs_;
        CHECK(phc_elasticity_to_absolute(&rwc, 2.5, &abs_) == PHC_OK);
        for (double r = 0.5; r <= 1.0; r += 0.1)
            CHECK_NEAR(phc_elasticity_eval(&abs_, r * 2.5, NULL, NULL), phc_elasticity_eval(&rwc, r, NULL, NULL),
                       0, 1e-14);
        CHECK(phc_elasticity_to_absolute(&rwc, 0.0, &abs_) == PHC_ERR_INVALID);
        CHECK(phc_elasticity_to_absolute(&rwc, NAN, &abs_) == PHC_ERR_INVALID);
    }
    return check_finish("unit/elasticity");
}
