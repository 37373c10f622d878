/* The README's claim about the physical default (model/water.h,
 * PHC_WATER_POISEUILLE): pressure equalises so much faster than leaves lose
 * water that the total decays as one exponential, W(t) = W0 exp(-delta Abar t)
 * with the volume-weighted leaf area proxy Abar = sum A_i V_i / sum V_i
 * (A = r h, V = pi r^2 h, cm), so a weight curve sees the graph only through
 * Abar.  Checked on two different random plants and on a leaf chain. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "model/plant_graph.h"
#include "model/water.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double abar_cm2(const phc_plant_graph *g)
{
    double av = 0, v = 0;
    for (size_t i = 0; i < g->n; ++i) {
        const double r = 100 * g->radius[i], h = 100 * g->length[i], vi = M_PI * r * r * h;
        v += vi;
        if (g->leaf[i])
            av += r * h * vi;
    }
    return av / v;
}

static void check_plant(phc_plant_graph *g, const char *name)
{
    const double delta = 2e-3, times[4] = {0, 3600, 36000, 172800};
    double W[4];
    phc_error err;
    phc_error_clear(&err);
    phc_water_params p = phc_water_params_default();
    p.loss_rate = delta;
    p.initial_water = 5.0;
    CHECK(g != NULL);
    if (!g)
        return;
    CHECK(phc_water_total_curve(g, &p, PHC_WATER_BDF6, 0, times, 4, W, NULL, &err) == PHC_OK);
    const double a = abar_cm2(g);
    double worst = 0;
    for (int k = 0; k < 4; ++k) {
        const double fast = 5.0 * exp(-delta * a * times[k]);
        worst = fmax(worst, fabs(W[k] - fast) / fast);
        CHECK_NEAR(W[k], fast, 0, 1e-8);
    }
    printf("%s: %zu segments, Abar %.6g cm2, W(48 h) %.6g g, largest relative difference from "
           "W0 exp(-delta Abar t): %.2e\n", name, g->n, a, W[3], worst);
    phc_plant_graph_free(g);
}

int main(void)
{
    check_plant(phc_plant_graph_random(300, 5), "random tree 300");
    check_plant(phc_plant_graph_random(2000, 9), "random tree 2000");
    check_plant(phc_plant_graph_leaf_chain(115e-4, 20, 0.5e-3), "leaf chain 115 cm2");
    return check_finish("test_water_fast_mixing");
}
