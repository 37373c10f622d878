/* `shape_series` with `water: plant` (fit/costs/shape_series.h,
 * fit/costs/shape_water.h): the water model on the plant graph drives every
 * segment's modulus, δ in s⁻¹ cm⁻² as in `weight_curve`.
 *
 * The plant: a vertical stem of 4 segments (r 2 mm, 2 cm each, the root
 * fixed) carrying a horizontal leaf blade of 4 leaf segments (r 1 mm, 2 cm
 * each) along +x; the tracked angle is the direction of the last leaf
 * segment.  Truth: κ 12, χ0 0.75, E_max 1e8 Pa (E_min 1e7 Pa), δ 5.8e-4
 * s⁻¹ cm⁻², every segment at relative water content 1 at t = 0; samples
 * every 10 min for 6 h.
 *
 * 1. Limit case: pressure equalises far faster than the plant dries, so
 *    every segment has nearly the same x(t) = exp(−δ Ā t) with Ā =
 *    Σ_leaf A_i V_i / Σ V_i (cm²; A = r h, V = π r² h): the water-driven
 *    angles equal a one-compartment stalk's at δ_c = δ Ā.
 * 2. The Jacobian (exact d E_i / d slot, exact d angle / d E_i from one
 *    adjoint solve of the rod's equilibrium) against central differences
 *    of the whole model in every slot.
 * 3. A joint fit: the angles (σ 2 mrad) and the plant's weighings on a
 *    balance (σ 1 mg, a weight_curve on the same plant) share δ by name;
 *    synthetic data from the models at the truth with seeded noise, fitted
 *    from a perturbed start, alone and jointly: the joint δ is within 3
 *    standard errors of the truth and its standard error is smaller.
 * 4. The same joint fit with a one-compartment shape_series (δ in s⁻¹) is
 *    refused: the slots' units differ.
 * 5. Errors: `water: plant` without a plant. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/shape_series.h"
#include "fit/costs/weight_curve.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/shape_series.h"
#include "model/plant_graph.h"
#include "model/water.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define N_T 37
#define N_SEG 8
static const double KAPPA = 12.0, CHI0 = 0.75, E_MAX = 1e8, DELTA = 5.8e-4, E_MIN = 1e7;
static const double DRY = 0.5, SIGMA_ANGLE = 2e-3, SIGMA_MASS = 1e-3;

static phc_plant_graph *plant(void)
{
    phc_plant_graph *g = phc_plant_graph_new(N_SEG);
    const double h = 0.02;
    for (size_t i = 0; i < N_SEG; ++i) {
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->length[i] = h;
        g->source_id[i] = (long)i;
        if (i < 4) { /* stem, up */
            g->radius[i] = 2e-3;
            g->head[3 * i + 2] = (double)i * h;
            g->tail[3 * i + 2] = (double)(i + 1) * h;
        } else { /* leaf blade, along +x at the stem's top */
            g->radius[i] = 1e-3;
            g->leaf[i] = 1;
            g->head[3 * i] = (double)(i - 4) * h;
            g->tail[3 * i] = (double)(i - 3) * h;
            g->head[3 * i + 2] = g->tail[3 * i + 2] = 4 * h;
        }
    }
    phc_error err;
    if (phc_plant_graph_finish(g, "test plant", &err)) {
        fprintf(stderr, "%s\n", err.message);
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

static double times_s(int i) { return 600.0 * i; }

/* Tracks of one angle column "leaf" (rad) from values. */
static phc_shape_series *tracks_of(const double *a)
{
    char text[N_T * 48 + 64];
    size_t used = (size_t)snprintf(text, sizeof text, "t,leaf\n");
    for (int i = 0; i < N_T; ++i)
        used += (size_t)snprintf(text + used, sizeof text - used, "%.17g,%.17g\n", times_s(i), a ? a[i] : 0.0);
    const phc_shape_series_spec sp = {.id = "leaf", .kind = PHC_SHAPE_ANGLE, .angle = "leaf", .angle_unit = "rad"};
    const phc_shape_spec spec = {"t", "s", NULL, 1, &sp};
    phc_shape_series *s = NULL;
    phc_error err;
    if (phc_shape_series_parse(text, strlen(text), "synthetic.csv", &spec, NULL, &s, &err))
        fprintf(stderr, "%s\n", err.message);
    return s;
}

static phc_shape_stalk stalk_spec;

static phc_shape_series_options options(const phc_plant_graph *g, int water)
{
    phc_shape_series_options o = phc_shape_series_options_default();
    stalk_spec = (phc_shape_stalk){.series = "leaf", .base_angle = NAN, .segment = N_SEG - 1};
    o.n_stalks = 1;
    o.stalks = &stalk_spec;
    o.plant = g;
    o.e_min = E_MIN;
    o.frames = 0;
    o.water_model = water;
    o.sigma = SIGMA_ANGLE;
    return o;
}

static phc_dataset *shape_set(const phc_plant_graph *g, const double *a, int water)
{
    phc_shape_series *tr = tracks_of(a);
    if (!tr)
        return NULL;
    phc_shape_series_options o = options(g, water);
    phc_dataset *ds = NULL;
    phc_error err;
    if (phc_shape_series_new(tr, &o, &ds, &err))
        fprintf(stderr, "%s\n", err.message);
    phc_shape_series_free(tr);
    if (ds)
        ds->name = strdup(water ? "angles" : "angles (one compartment)");
    return ds;
}

/* Deterministic normal deviates (an LCG and Box–Muller; seed fixed). */
static double normal(void)
{
    static unsigned long long s = 20261126ULL;
    double u[2];
    for (int k = 0; k < 2; ++k) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        u[k] = ((double)(s >> 11) + 0.5) / 9007199254740992.0;
    }
    return sqrt(-2.0 * log(u[0])) * cos(6.283185307179586 * u[1]);
}

/* Ā = Σ_leaf A_i V_i / Σ V_i, cm². */
static double mean_area(const phc_plant_graph *g)
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

static void test_limit(const phc_plant_graph *g, const double *truth_angles)
{
    phc_dataset *one = shape_set(g, NULL, 0);
    CHECK(one != NULL);
    if (!one)
        return;
    const double abar = mean_area(g);
    const double p[] = {KAPPA, CHI0, E_MAX, DELTA * abar};
    double y[N_T], worst = 0;
    CHECK(one->ops->predict(one, p, y, NULL) == 0);
    for (int i = 0; i < N_T; ++i)
        worst = fmax(worst, fabs(y[i] - truth_angles[i]));
    printf("limit: water model vs one compartment at delta_c = delta * %.6g cm2: largest angle difference %.3g rad "
           "(angles %.4f .. %.4f rad)\n",
           abar, worst, truth_angles[0], truth_angles[N_T - 1]);
    CHECK(worst < 1e-6);
    CHECK(truth_angles[N_T - 1] < truth_angles[0] - 0.05); /* the leaf droops */
    phc_dataset_free(one);
}

static void test_jacobian(phc_dataset *ds)
{
    const double p[] = {KAPPA * 1.1, CHI0 * 0.97, E_MAX * 0.8, DELTA * 1.2};
    double jac[N_T * 4], yp[N_T], ym[N_T], y[N_T], worst = 0;
    CHECK(ds->k == 4 && ds->ops->predict(ds, p, y, jac) == 0);
    for (size_t j = 0; j < 4; ++j) {
        double q[4];
        memcpy(q, p, sizeof q);
        /* 1e-4: the water model's BDF6 solves leave noise in the angles that
         * smaller steps magnify (delta's column: 1.1e-6 of it at 1e-5, 5.8e-6
         * at 1e-6; truncation 7.9e-6 at 1e-3) */
        const double h = 1e-4 * fabs(p[j]);
        q[j] = p[j] + h;
        CHECK(ds->ops->predict(ds, q, yp, NULL) == 0);
        q[j] = p[j] - h;
        CHECK(ds->ops->predict(ds, q, ym, NULL) == 0);
        double col = 0, err = 0;
        for (int i = 0; i < N_T; ++i) {
            const double fd = (yp[i] - ym[i]) / (2 * h);
            col = fmax(col, fabs(fd));
            err = fmax(err, fabs(jac[i * 4 + j] - fd));
        }
        printf("jacobian: slot %s: max |analytic - central| %.3g of max |column| %.3g\n", ds->slot_names[j], err, col);
        worst = fmax(worst, err / col);
    }
    printf("jacobian: largest relative difference %.3g\n", worst);
    CHECK(worst < 1e-5);
}

static phc_dataset *balance_set(const phc_plant_graph *g, double *mass_out)
{
    double t[N_T], W[N_T], mass[N_T];
    for (int i = 0; i < N_T; ++i)
        t[i] = times_s(i);
    phc_water_params wp = phc_water_params_default();
    wp.loss_rate = DELTA;
    wp.initial_water = 0;
    for (size_t i = 0; i < g->n; ++i) /* relative water content 1: W0 = Σ V (cm³ = g) */
        wp.initial_water += M_PI * pow(100 * g->radius[i], 2) * 100 * g->length[i];
    phc_error err;
    if (phc_water_total_curve(g, &wp, PHC_WATER_BDF6, 0, t, N_T, W, NULL, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return NULL;
    }
    for (int i = 0; i < N_T; ++i)
        mass[i] = mass_out[i] = DRY + W[i] + SIGMA_MASS * normal();
    phc_weighings w = phc_weighings_default();
    w.n = N_T;
    w.t = t;
    w.mass = mass;
    phc_weight_curve_options o = phc_weight_curve_options_default();
    o.sigma = SIGMA_MASS;
    o.dry_mass = DRY;
    phc_dataset *ds = NULL;
    if (phc_weight_curve_new(g, &w, &o, &ds, &err))
        fprintf(stderr, "%s\n", err.message);
    if (ds)
        ds->name = strdup("balance");
    return ds;
}

/* Fits the data sets (taken) with the shape parameters and, when a balance
 * is among them, initial_water; the result or NULL (message in err). */
static phc_fit_result *fit(phc_dataset **sets, size_t n_sets, double w0, phc_error *err)
{
    static const char *const names[] = {"kappa", "chi0", "e_max", "delta", "initial_water"};
    const double start[] = {KAPPA * 1.3, CHI0 * 0.95, E_MAX * 0.7, DELTA * 1.5, w0 * 1.1};
    phc_problem *pb = phc_problem_new("shape-water");
    phc_fit_result *res = NULL;
    int rc = 0;
    const size_t k = n_sets == 1 ? 4 : 5; /* initial_water only with the balance */
    for (size_t j = 0; j < k && !rc; ++j) {
        size_t idx;
        rc = phc_problem_add_parameter(pb, names[j], start[j], &idx, err);
        if (!rc)
            pb->params[idx].lower = 0;
    }
    for (size_t d = 0; d < n_sets; ++d) {
        if (rc) {
            phc_dataset_free(sets[d]);
            continue;
        }
        rc = phc_problem_bind_by_name(pb, sets[d], err);
        if (rc)
            phc_dataset_free(sets[d]);
        else
            rc = phc_problem_add_dataset(pb, sets[d], err);
    }
    if (!rc)
        rc = phc_problem_finish(pb, 0, err);
    if (!rc)
        rc = phc_fit_run(pb, NULL, NULL, &res, err);
    phc_problem_free(pb);
    return rc ? NULL : res;
}

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; r && i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

static void test_joint(const phc_plant_graph *g, const double *truth_angles)
{
    double noisy[N_T], mass[N_T];
    for (int i = 0; i < N_T; ++i)
        noisy[i] = truth_angles[i] + SIGMA_ANGLE * normal();
    double w0 = 0;
    for (size_t i = 0; i < g->n; ++i)
        w0 += M_PI * pow(100 * g->radius[i], 2) * 100 * g->length[i];
    phc_error err;
    phc_error_clear(&err);
    phc_dataset *alone[1] = {shape_set(g, noisy, 1)};
    phc_fit_result *r1 = alone[0] ? fit(alone, 1, w0, &err) : NULL;
    if (!r1)
        fprintf(stderr, "shape alone: %s\n", err.message);
    phc_dataset *both[2] = {shape_set(g, noisy, 1), balance_set(g, mass)};
    phc_fit_result *r2 = both[0] && both[1] ? fit(both, 2, w0, &err) : NULL;
    if (!r2)
        fprintf(stderr, "joint: %s\n", err.message);
    CHECK(r1 && r2);
    if (r1 && r2) {
        static const char *const names[] = {"kappa", "chi0", "e_max", "delta"};
        const double truth[] = {KAPPA, CHI0, E_MAX, DELTA};
        printf("joint fit: %-6s %12s | %12s %10s | %12s %10s\n", "", "truth", "angles only", "stderr", "joint",
               "stderr");
        for (int j = 0; j < 4; ++j) {
            const phc_param_result *a = param(r1, names[j]), *b = param(r2, names[j]);
            printf("joint fit: %-6s %12.5g | %12.5g %10.3g | %12.5g %10.3g\n", names[j], truth[j], a->value,
                   a->stderr_, b->value, b->stderr_);
        }
        const phc_param_result *d1 = param(r1, "delta"), *d2 = param(r2, "delta"), *w = param(r2, "initial_water");
        printf("joint fit: initial_water %.6g g (truth %.6g, stderr %.3g); delta's stderr angles only / joint = "
               "%.3g; delta in %s\n",
               w->value, w0, w->stderr_, d1->stderr_ / d2->stderr_, d2->unit ? d2->unit : "?");
        CHECK(fabs(d2->value - DELTA) < 3 * d2->stderr_);
        CHECK(d2->stderr_ < d1->stderr_);
        CHECK(d2->unit && strcmp(d2->unit, "s-1 cm-2") == 0);
        CHECK(fabs(param(r2, "kappa")->value - KAPPA) < 3 * param(r2, "kappa")->stderr_);
    }
    phc_fit_result_free(r1);
    phc_fit_result_free(r2);

    /* one compartment (δ in s⁻¹) with the balance (δ in s⁻¹ cm⁻²): refused */
    phc_dataset *mixed[2] = {shape_set(g, noisy, 0), balance_set(g, mass)};
    phc_fit_result *r3 = mixed[0] && mixed[1] ? fit(mixed, 2, w0, &err) : NULL;
    CHECK(r3 == NULL);
    CHECK_STR_CONTAINS(err.message, "delta");
    printf("one compartment sharing delta with a balance: %s\n", err.message);
    phc_fit_result_free(r3);
}

static void test_errors(void)
{
    phc_shape_series *tr = tracks_of(NULL);
    phc_shape_series_options o = options(NULL, 1);
    stalk_spec = (phc_shape_stalk){.series = "leaf", .length = 0.1, .radius = 1e-3, .segments = 4,
                                   .base_angle = NAN};
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_ERR_INPUT && !ds);
    CHECK_STR_CONTAINS(err.message, "plant");
    printf("water without a plant: %s\n", err.message);
    phc_plant_graph *g = plant();
    o = options(g, 1);
    o.t0 = 60.0; /* after the first sample */
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_ERR_INPUT && !ds);
    CHECK_STR_CONTAINS(err.message, "t0");
    printf("a sample before t0: %s\n", err.message);
    phc_plant_graph_free(g);
    phc_shape_series_free(tr);
}

int main(void)
{
    phc_plant_graph *g = plant();
    CHECK(g != NULL);
    if (g) {
        phc_dataset *ds = shape_set(g, NULL, 1);
        double truth_angles[N_T];
        const double p[] = {KAPPA, CHI0, E_MAX, DELTA};
        CHECK(ds && ds->ops->predict(ds, p, truth_angles, NULL) == 0);
        if (ds) {
            test_limit(g, truth_angles);
            test_jacobian(ds);
            phc_dataset_free(ds);
            test_joint(g, truth_angles);
        }
        phc_plant_graph_free(g);
    }
    test_errors();
    return check_finish("shape_water");
}
