/* `shape_series` data sets built in C (fit/costs/shape_series.h):
 *
 * 1. limit cases (small deflection, 50 segments, to 1e-3): a stalk clamped
 *    horizontally with a tip mass and (almost) no weight of its own bends by
 *    the Euler–Bernoulli tip slope P L² / (2 E I), I = π r⁴ / 4; under its
 *    own weight only by q L³ / (6 E I);
 *    a very stiff stalk keeps its base angle;
 * 2. synthetic angles of two stalks made by the model from known kappa = 12,
 *    chi0 = 0.7, e_max = 1e8 Pa (e_min 1e6 Pa), delta = 2e-4 s-1 (and an offset of 0.05 rad
 *    on the second stalk), written as a CSV in degrees and read back
 *    (measurements/shape_series.h), fitted back from a perturbed start;
 * 3. the Jacobian (d angle / d E exact, from one sensitivity solve of the
 *    rod's equilibrium, chained with the exact d E / d slot) against central
 *    differences of the whole model in every slot; rods do not use fd_step
 *    (the Jacobians with two fd_steps are the same to the bit);
 * 4. errors: an unknown series, a zero radius, a negative E_min;
 * 5. e_min as a slot: its Jacobian column against central differences;
 * 6. a plant graph (options.plant) laid out as a stalk, its series mapped to
 *    the last segment, gives the stalk's angles; an unknown segment id is
 *    refused;
 * 7. dynamics: particles: a limit case (s = 1 with 16 iterations and
 *    dt = 1/480 s droops less than s = 0.1, and s = 1 less than s = 0.5; a
 *    solve from rest does not depend on what was solved before), the
 *    Jacobian against central differences of the whole model (central and
 *    backward differences in s both taken), particle options and an unknown
 *    dynamics refused, a step cap too small refused without a NaN; a plant
 *    graph laid out as the particle stalk gives its angles (root anchored). */
#include <math.h>

#define PHC_SS_PI 3.14159265358979323846
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/shape_series.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/shape_series.h"
#include "model/plant_graph.h"

#define N_T 61
static const double truth[] = {12.0, 0.7, 1e8, 2e-4, 0.05}; /* kappa chi0 e_max delta offset_b */

/* Tracks from CSV text: columns "t (min)", "a (deg)", "b (deg)". */
static phc_shape_series *tracks_from(const char *text)
{
    const phc_shape_series_spec sp[2] = {
        {.id = "a", .kind = PHC_SHAPE_ANGLE, .angle = "a (deg)", .angle_unit = "deg"},
        {.id = "b", .kind = PHC_SHAPE_ANGLE, .angle = "b (deg)", .angle_unit = "deg"}};
    const phc_shape_spec spec = {"t (min)", "min", NULL, 2, sp};
    phc_shape_series *s = NULL;
    phc_error err;
    if (phc_shape_series_parse(text, strlen(text), "synthetic.csv", &spec, NULL, &s, &err))
        fprintf(stderr, "%s\n", err.message);
    return s;
}

static char *csv_of(const double *a, const double *b)
{
    size_t cap = 64 + N_T * 80, used = 0;
    char *text = malloc(cap);
    used += (size_t)snprintf(text, cap, "t (min),a (deg),b (deg)\n");
    for (int i = 0; i < N_T; ++i)
        used += (size_t)snprintf(text + used, cap - used, "%d,%.15g,%.15g\n", i, a ? a[i] * 180 / PHC_SS_PI : 0.0,
                                 b ? b[i] * 180 / PHC_SS_PI : 0.0);
    return text;
}

static phc_shape_stalk stalks[2];

static phc_shape_series_options options(void)
{
    phc_shape_series_options o = phc_shape_series_options_default();
    stalks[0] = (phc_shape_stalk){.series = "a", .length = 0.05, .radius = 1e-3, .segments = 6,
                                  .tip_mass = 1e-3, .base_angle = 30 * PHC_SS_PI / 180};
    stalks[1] = (phc_shape_stalk){.series = "b", .length = 0.04, .radius = 0.8e-3, .segments = 6,
                                  .tip_mass = 0.6e-3, .base_angle = 120 * PHC_SS_PI / 180, .offset = 1};
    o.n_stalks = 2;
    o.stalks = stalks;
    o.e_min = 1e6;
    o.frames = 0;
    return o;
}

static void test_limits(void)
{
    const char *text = "t (min),a (deg),b (deg)\n0,0,0\n";
    phc_shape_series *tr = tracks_from(text);
    if (!tr)
        return;
    phc_shape_series_options o = phc_shape_series_options_default();
    const double L = 0.1, r = 2e-3, m = 2e-3, E = 1e9, I = PHC_SS_PI * pow(r, 4) / 4;
    phc_shape_stalk st = {.series = "a", .length = L, .radius = r, .segments = 50, .tip_mass = m, .base_angle = 0};
    o.n_stalks = 1;
    o.stalks = &st;
    o.density = 1e-6; /* the stalk's own weight negligible against the tip */
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_OK);
    if (ds) {
        double a = NAN, stiff = NAN;
        CHECK(phc_shape_series_stalk_angle(ds, 0, E, &a, &err) == 0);
        const double want = -m * 9.81 * L * L / (2 * E * I);
        printf("tip slope under a tip load: %.8g rad, Euler-Bernoulli -PL^2/(2EI) = %.8g rad (ratio %.7f)\n", a,
               want, a / want);
        CHECK_NEAR(a, want, 0, 1e-3);
        CHECK(phc_shape_series_stalk_angle(ds, 0, 1e15, &stiff, &err) == 0);
        printf("very stiff stalk (E = 1e15 Pa): angle %.3g rad\n", stiff);
        CHECK(fabs(stiff) < 1e-7);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_dataset_free(ds);
    ds = NULL;
    /* self-weight only: tip slope q L³ / (6 E I), q = ρ π r² g */
    st.tip_mass = 0;
    o.density = 1000;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_OK);
    if (ds) {
        double a = NAN;
        CHECK(phc_shape_series_stalk_angle(ds, 0, E, &a, &err) == 0);
        const double q = 1000 * PHC_SS_PI * r * r * 9.81, want = -q * L * L * L / (6 * E * I);
        printf("tip slope under self-weight: %.8g rad, Euler-Bernoulli -qL^3/(6EI) = %.8g rad (ratio %.7f)\n", a,
               want, a / want);
        CHECK_NEAR(a, want, 0, 1e-3);
    }
    phc_dataset_free(ds);
    phc_shape_series_free(tr);
}

/* The model's angles at the truth, through a dataset over zeros. */
static int synthetic(double *a, double *b)
{
    char *text = csv_of(NULL, NULL);
    phc_shape_series *tr = tracks_from(text);
    free(text);
    if (!tr)
        return 1;
    phc_shape_series_options o = options();
    /* observed zeros are moved to within pi of the base angle: irrelevant here */
    phc_dataset *ds = NULL;
    phc_error err;
    int rc = phc_shape_series_new(tr, &o, &ds, &err);
    CHECK(rc == PHC_OK);
    if (!rc) {
        CHECK(ds->n == 2 * N_T && ds->k == 5);
        CHECK(strcmp(ds->slot_names[3], "delta") == 0 && strcmp(ds->slot_names[4], "offset_b") == 0);
        double yhat[2 * N_T];
        rc = ds->ops->predict(ds, truth, yhat, NULL);
        CHECK(rc == 0);
        memcpy(a, yhat, N_T * sizeof *a);
        memcpy(b, yhat + N_T, N_T * sizeof *b);
        double E0, E1, r0, r1;
        phc_shape_series_modulus(ds, truth, 0, &E0, &r0);
        phc_shape_series_modulus(ds, truth, 3600, &E1, &r1);
        printf("truth: RWC %.3f -> %.3f, E %.4g -> %.4g Pa, angle a %.4f -> %.4f rad, b %.4f -> %.4f rad\n", r0, r1,
               E0, E1, a[0], a[N_T - 1], b[0], b[N_T - 1]);
        CHECK(a[N_T - 1] < a[0] - 0.1); /* the stalk droops as it dries */
    }
    phc_dataset_free(ds);
    phc_shape_series_free(tr);
    return rc;
}

static phc_dataset *dataset_of(const double *a, const double *b, double fd_step)
{
    char *text = csv_of(a, b);
    phc_shape_series *tr = tracks_from(text);
    free(text);
    phc_shape_series_options o = options();
    o.fd_step = fd_step;
    phc_dataset *ds = NULL;
    phc_error err;
    if (tr && phc_shape_series_new(tr, &o, &ds, &err))
        fprintf(stderr, "%s\n", err.message);
    phc_shape_series_free(tr);
    return ds;
}

static void test_jacobian(const double *a, const double *b)
{
    phc_dataset *ds = dataset_of(a, b, 1e-4), *ds2 = dataset_of(a, b, 1e-6);
    CHECK(ds && ds2);
    if (!ds || !ds2)
        goto done;
    const size_t n = ds->n, k = ds->k;
    double *jac = malloc(n * k * sizeof *jac), *jac2 = malloc(n * k * sizeof *jac2);
    double *yp = malloc(n * sizeof *yp), *ym = malloc(n * sizeof *ym), *y0 = malloc(n * sizeof *y0);
    const double p0[] = {11.0, 0.72, 0.9e8, 1.8e-4, 0.02};
    CHECK(ds->ops->predict(ds, p0, y0, jac) == 0);
    CHECK(ds2->ops->predict(ds2, p0, y0, jac2) == 0);
    double worst = 0, worst2 = 0;
    for (size_t j = 0; j < k; ++j) {
        double p[5];
        memcpy(p, p0, sizeof p);
        const double h = 1e-5 * fabs(p0[j]);
        p[j] = p0[j] + h;
        CHECK(ds->ops->predict(ds, p, yp, NULL) == 0);
        p[j] = p0[j] - h;
        CHECK(ds->ops->predict(ds, p, ym, NULL) == 0);
        double scale = 0;
        for (size_t i = 0; i < n; ++i)
            scale = fmax(scale, fabs(jac[i * k + j]));
        for (size_t i = 0; i < n; ++i) {
            const double fd = (yp[i] - ym[i]) / (2 * h);
            const double e = fabs(jac[i * k + j] - fd) / scale;
            const double e2 = fabs(jac[i * k + j] - jac2[i * k + j]) / scale;
            worst = fmax(worst, e);
            worst2 = fmax(worst2, e2);
        }
        printf("slot %-8s largest |d angle/d slot| %.4g\n", ds->slot_names[j], scale);
    }
    printf("Jacobian vs central differences of the whole model: largest error %.3g (relative to the column)\n",
           worst);
    printf("Jacobian with fd_step 1e-4 vs 1e-6 (rods do not use it): largest difference %.3g\n", worst2);
    CHECK(worst < 1e-7);
    CHECK(worst2 == 0);
    free(jac);
    free(jac2);
    free(yp);
    free(ym);
    free(y0);
done:
    phc_dataset_free(ds);
    phc_dataset_free(ds2);
}

static void test_fit(const double *a, const double *b)
{
    phc_dataset *ds = dataset_of(a, b, 1e-4);
    CHECK(ds != NULL);
    if (!ds)
        return;
    phc_error err;
    phc_problem *pb = phc_problem_new("synthetic droop");
    const char *names[] = {"kappa", "chi0", "e_max", "delta", "offset_b"};
    const double start[] = {9.0, 0.65, 0.7e8, 1.6e-4, 0.0};
    for (int j = 0; j < 5; ++j)
        CHECK(phc_problem_add_parameter(pb, names[j], start[j], NULL, &err) == PHC_OK);
    pb->params[0].lower = 0;
    pb->params[2].lower = 0;
    pb->params[3].lower = 0;
    ds->name = strdup("droop");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        for (size_t i = 0; i < 5; ++i) {
            printf("fitted %-8s %.12g (truth %g, relative error %.2g)\n", res->params[i].name, res->params[i].value, truth[i],
                   fabs(res->params[i].value / truth[i] - 1));
            CHECK_NEAR(res->params[i].value, truth[i], 1e-6, 1e-4);
        }
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

static void test_errors(void)
{
    phc_shape_series *tr = tracks_from("t (min),a (deg),b (deg)\n0,10,20\n1,11,21\n");
    if (!tr)
        return;
    phc_error err;
    phc_dataset *ds = NULL;
    phc_shape_series_options o = options();
    stalks[1].series = "flower9";
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_ERR_INPUT && !ds);
    CHECK_STR_CONTAINS(err.message, "unknown series 'flower9'");
    CHECK_STR_CONTAINS(err.message, "'a', 'b'");
    printf("unknown series: %s\n", err.message);
    o = options();
    stalks[0].radius = 0;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_ERR_INPUT && !ds);
    CHECK_STR_CONTAINS(err.message, "key 'radius': must be positive");
    printf("zero radius: %s\n", err.message);
    o = options();
    o.e_min = -1;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_ERR_INPUT && !ds);
    CHECK_STR_CONTAINS(err.message, "key 'e_min'");
    printf("negative e_min: %s\n", err.message);
    phc_shape_series_free(tr);
}

/* e_min as a slot: named, in Pa, and its Jacobian column against central
 * differences (d angle/d e_min = d angle/dE). */
static void test_e_min_slot(const double *a, const double *b)
{
    char *text = csv_of(a, b);
    phc_shape_series *tr = tracks_from(text);
    free(text);
    if (!tr)
        return;
    phc_shape_series_options o = options();
    o.e_min_slot = 1;
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_OK);
    if (ds) {
        CHECK(ds->k == 6 && strcmp(ds->slot_names[4], "e_min") == 0 && strcmp(ds->slot_units[4], "Pa") == 0);
        const double p0[] = {11.0, 0.72, 0.9e8, 1.8e-4, 2e6, 0.02};
        double jac[2 * N_T * 6], y0[2 * N_T], yp[2 * N_T], ym[2 * N_T], p[6];
        CHECK(ds->ops->predict(ds, p0, y0, jac) == 0);
        memcpy(p, p0, sizeof p);
        const double h = 1e-5 * p0[4];
        p[4] = p0[4] + h;
        CHECK(ds->ops->predict(ds, p, yp, NULL) == 0);
        p[4] = p0[4] - h;
        CHECK(ds->ops->predict(ds, p, ym, NULL) == 0);
        double worst = 0, scale = 0;
        for (int i = 0; i < 2 * N_T; ++i)
            scale = fmax(scale, fabs(jac[i * 6 + 4]));
        for (int i = 0; i < 2 * N_T; ++i)
            worst = fmax(worst, fabs(jac[i * 6 + 4] - (yp[i] - ym[i]) / (2 * h)) / scale);
        printf("e_min slot: Jacobian column vs central differences: largest error %.3g (relative to the column)\n",
               worst);
        CHECK(scale > 0 && worst < 1e-7);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_dataset_free(ds);
    phc_shape_series_free(tr);
}

/* A plant graph laid out like stalk "a" (a clamp 1/1000 of a segment long,
 * then 6 segments at 30°), its series mapped to segment 6: the same angles
 * as the stalk model; an unknown segment is refused. */
static void test_plant(const double *a, const double *b)
{
    char *text = csv_of(a, b);
    phc_shape_series *tr = tracks_from(text);
    free(text);
    if (!tr)
        return;
    const size_t n = 7;
    const double h = 0.05 / 6, beta = 30 * PHC_SS_PI / 180;
    phc_plant_graph *g = phc_plant_graph_new(n);
    for (size_t i = 0; i < n; ++i) {
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = 1e-3;
        g->length[i] = i ? h : 1e-3 * h;
        const double s0 = i ? (double)(i - 1) * h : -1e-3 * h, s1 = i ? s0 + h : 0.0;
        g->head[3 * i] = s0 * cos(beta);
        g->head[3 * i + 2] = s0 * sin(beta);
        g->tail[3 * i] = s1 * cos(beta);
        g->tail[3 * i + 2] = s1 * sin(beta);
        g->source_id[i] = (long)i;
    }
    phc_error err;
    CHECK(phc_plant_graph_finish(g, "test plant", &err) == PHC_OK);
    phc_shape_series_options o = options();
    phc_shape_stalk st = {.series = "a", .tip_mass = 1e-3, .base_angle = NAN, .segment = 6};
    o.n_stalks = 1;
    o.stalks = &st;
    o.plant = g;
    phc_dataset *ds = NULL;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_OK);
    if (ds) {
        double yhat[N_T];
        const double p[] = {truth[0], truth[1], truth[2], truth[3]};
        CHECK(ds->k == 4 && ds->ops->predict(ds, p, yhat, NULL) == 0);
        double worst = 0;
        for (int i = 0; i < N_T; ++i)
            worst = fmax(worst, fabs(yhat[i] - a[i]));
        printf("plant graph laid out as stalk a, segment 6: largest angle difference %.3g rad\n", worst);
        CHECK(worst < 1e-9);
        phc_dataset_free(ds);
        ds = NULL;
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    st.segment = 99;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_ERR_INPUT && !ds);
    CHECK_STR_CONTAINS(err.message, "no segment 99");
    printf("unknown segment: %s\n", err.message);
    phc_plant_graph_free(g);
    phc_shape_series_free(tr);
}

/* Particles: the stalks of options(), every 6th sample. */
static phc_shape_series_options particle_options(void)
{
    phc_shape_series_options o = options();
    o.dynamics = PHC_SHAPE_PARTICLES;
    o.every = 20;
    return o;
}

static void test_particles_limits(void)
{
    phc_shape_series *tr = tracks_from("t (min),a (deg),b (deg)\n0,0,0\n");
    if (!tr)
        return;
    phc_shape_series_options o = particle_options();
    phc_shape_stalk st = {.series = "a", .length = 0.1, .radius = 2e-3, .segments = 8, .tip_mass = 2e-3,
                          .base_angle = 0};
    o.n_stalks = 1;
    o.stalks = &st;
    o.particle_iterations = 16;
    o.particle_time_step = 1.0 / 480;
    o.particle_steps = 200000;
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_OK);
    if (ds) {
        const double s[] = {1.0, 0.5, 0.1};
        double a[3] = {NAN, NAN, NAN}, again = NAN;
        for (int j = 0; j < 3; ++j) {
            CHECK(phc_shape_series_stalk_angle(ds, 0, s[j], &a[j], &err) == 0);
            printf("particles, horizontal stalk 0.1 m, 16 iterations, dt = 1/480 s: s = %.1f: tip angle %.6f rad "
                   "(%zu steps, settling included)\n", s[j], a[j], phc_shape_series_particle_steps(ds));
        }
        CHECK(a[0] < 0 && a[0] > a[1] && a[1] > a[2]); /* droops, less when stiffer */
        CHECK(phc_shape_series_stalk_angle(ds, 0, 1.0, &again, &err) == 0);
        printf("particles: s = 1 solved again after s = 0.1: difference %.3g rad\n", again - a[0]);
        CHECK(again == a[0]); /* each solve starts from rest */
        CHECK(phc_shape_series_stalk_angle(ds, 0, 1.5, &again, &err) != 0);
        CHECK_STR_CONTAINS(err.message, "outside [0, 1]");
        printf("s = 1.5: %s\n", err.message);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_dataset_free(ds);
    ds = NULL;
    /* stalk a of options() (0.05 m, 6 segments, 1 g, base 30°): the time step
     * sets how far it droops; the damping only how fast it comes to rest */
    {
        phc_shape_series_options oa = particle_options();
        oa.n_stalks = 1;
        const double dts[2] = {1.0 / 120, 5e-4}, damps[3] = {0.05, 0.1, 0.3};
        double at[2][2] = {{NAN, NAN}, {NAN, NAN}}, damped[3] = {NAN, NAN, NAN};
        for (int u = 0; u < 2; ++u) {
            oa.particle_time_step = dts[u];
            phc_dataset *da = NULL;
            CHECK(phc_shape_series_new(tr, &oa, &da, &err) == PHC_OK);
            for (int j = 0; da && j < 2; ++j)
                CHECK(phc_shape_series_stalk_angle(da, 0, j ? 0.1 : 1.0, &at[u][j], &err) == 0);
            printf("particles, stalk a (base 0.5236 rad), 16 iterations, dt = %.3g s: tip angle %.4f rad at s = 1, "
                   "%.4f rad at s = 0.1\n", dts[u], at[u][0], at[u][1]);
            phc_dataset_free(da);
        }
        CHECK(at[1][0] > at[0][0] && at[1][1] > at[0][1]); /* a smaller step droops less */
        oa.particle_time_step = 5e-4;
        for (int u = 0; u < 3; ++u) {
            oa.particle_damping = damps[u];
            phc_dataset *da = NULL;
            CHECK(phc_shape_series_new(tr, &oa, &da, &err) == PHC_OK);
            if (da) {
                CHECK(phc_shape_series_stalk_angle(da, 0, 0.5, &damped[u], &err) == 0);
                printf("particles, stalk a, s = 0.5, damping %.2f: tip angle %.12f rad, %zu steps\n", damps[u],
                       damped[u], phc_shape_series_particle_steps(da));
            }
            phc_dataset_free(da);
        }
        CHECK(fabs(damped[0] - damped[1]) < 1e-9 && fabs(damped[2] - damped[1]) < 1e-9);
    }
    /* a step cap the relaxation cannot meet: refused, naming the series */
    o.particle_steps = 10;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_OK);
    if (ds) {
        double a = 123.0;
        CHECK(phc_shape_series_stalk_angle(ds, 0, 0.5, &a, &err) == PHC_ERR_DOMAIN);
        CHECK_STR_CONTAINS(err.message, "not at rest after particle_steps = 10");
        CHECK(a == 123.0);
        printf("step cap 10: %s\n", err.message);
    }
    phc_dataset_free(ds);
    ds = NULL;
    /* bad options */
    const struct {
        const char *key;
        phc_shape_series_options o;
    } bad[] = {
        {"'dynamics'", (phc_shape_series_options){0}},
        {"'particle_iterations'", (phc_shape_series_options){0}},
        {"'particle_time_step'", (phc_shape_series_options){0}},
        {"'particle_steps'", (phc_shape_series_options){0}},
        {"'particle_damping'", (phc_shape_series_options){0}},
        {"'parent_weight'", (phc_shape_series_options){0}},
    };
    phc_shape_series_options b[6];
    for (int j = 0; j < 6; ++j)
        b[j] = o;
    b[0].dynamics = 7;
    b[1].particle_iterations = 0;
    b[2].particle_time_step = -0.01;
    b[3].particle_steps = 0;
    b[4].particle_damping = 0;
    b[5].parent_weight = 0.5;
    for (int j = 0; j < 6; ++j) {
        (void)bad[j].o;
        CHECK(phc_shape_series_new(tr, &b[j], &ds, &err) == PHC_ERR_INPUT && !ds);
        CHECK_STR_CONTAINS(err.message, bad[j].key);
        printf("bad option: %s\n", err.message);
    }
    phc_shape_series_free(tr);
}

/* The particle path's Jacobian: d angle/ds by differences chained with the
 * exact ds/d slot, against central differences of the whole model, at two
 * points (stalks of 3 segments, 3 samples each): one where s stays away from 1 (central differences in s), one
 * where early samples have s within fd_step of 1 (backward differences). */
static void test_particles_jacobian(const double *a, const double *b)
{
    char *text = csv_of(a, b);
    phc_shape_series *tr = tracks_from(text);
    free(text);
    if (!tr)
        return;
    phc_shape_series_options o = particle_options();
    o.e_min_slot = 1;
    o.every = 30; /* t = 0, 30, 60 min; 3 segments per stalk: the test's time */
    stalks[0].segments = stalks[1].segments = 3;
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_shape_series_new(tr, &o, &ds, &err) == PHC_OK);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        phc_shape_series_free(tr);
        return;
    }
    const size_t n = ds->n, k = ds->k;
    CHECK(k == 6 && n == 6);
    const double points[2][6] = {{11.0, 0.72, 0.9e8, 1.8e-4, 2e6, 0.02}, {40.0, 0.6, 0.9e8, 1.8e-4, 2e6, 0.02}};
    double *jac = malloc(n * k * sizeof *jac), *y0 = malloc(n * sizeof *y0), *yp = malloc(n * sizeof *yp),
           *ym = malloc(n * sizeof *ym);
    for (int q = 0; q < 2; ++q) {
        const double *p0 = points[q];
        CHECK(ds->ops->predict(ds, p0, y0, jac) == 0);
        double s_first, s_last;
        phc_shape_series_stiffness(ds, p0, 0, &s_first);
        phc_shape_series_stiffness(ds, p0, 3600, &s_last);
        double worst = 0;
        for (size_t j = 0; j < k; ++j) {
            double p[6];
            memcpy(p, p0, sizeof p);
            const double h = 1e-5 * fabs(p0[j]);
            p[j] = p0[j] + h;
            CHECK(ds->ops->predict(ds, p, yp, NULL) == 0);
            p[j] = p0[j] - h;
            CHECK(ds->ops->predict(ds, p, ym, NULL) == 0);
            double scale = 0, e = 0;
            for (size_t i = 0; i < n; ++i)
                scale = fmax(scale, fabs(jac[i * k + j]));
            for (size_t i = 0; i < n; ++i)
                e = fmax(e, fabs(jac[i * k + j] - (yp[i] - ym[i]) / (2 * h)) / scale);
            CHECK(scale > 0);
            printf("particles: slot %-8s largest |d angle/d slot| %.4g, error %.3g\n", ds->slot_names[j], scale, e);
            worst = fmax(worst, e);
        }
        printf("particles: s %.6f -> %.6f over the hour%s; Jacobian vs central differences of the whole model: "
               "largest error %.3g (relative to the column)\n", s_first, s_last,
               1.0 - s_first < 1e-4 * s_first ? " (backward differences in s at the start)" : "", worst);
        CHECK(worst < 1e-5);
        if (q == 1)
            CHECK(1.0 - s_first < 1e-4 * s_first); /* the backward branch was taken */
    }
    free(jac);
    free(y0);
    free(yp);
    free(ym);
    phc_dataset_free(ds);
    phc_shape_series_free(tr);
}

/* Particles on a plant graph laid out as stalk "a" with the particles'
 * clamp (a root segment one free segment long behind the base): the same
 * particle system, so the same angles as the particle stalk; the root is
 * anchored although the graph marks nothing fixed. */
static void test_particles_plant(const double *a, const double *b)
{
    char *text = csv_of(a, b);
    phc_shape_series *tr = tracks_from(text);
    free(text);
    if (!tr)
        return;
    const size_t n = 7;
    const double h = 0.05 / 6, beta = 30 * PHC_SS_PI / 180;
    phc_plant_graph *g = phc_plant_graph_new(n);
    for (size_t i = 0; i < n; ++i) {
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = 1e-3;
        g->length[i] = h;
        const double s0 = ((double)i - 1) * h, s1 = s0 + h;
        g->head[3 * i] = s0 * cos(beta);
        g->head[3 * i + 2] = s0 * sin(beta);
        g->tail[3 * i] = s1 * cos(beta);
        g->tail[3 * i + 2] = s1 * sin(beta);
        g->source_id[i] = (long)i;
    }
    phc_error err;
    CHECK(phc_plant_graph_finish(g, "test plant", &err) == PHC_OK);
    phc_shape_series_options o = particle_options();
    phc_dataset *stalk = NULL, *plant = NULL;
    o.n_stalks = 1; /* stalk "a" of options() */
    CHECK(phc_shape_series_new(tr, &o, &stalk, &err) == PHC_OK);
    phc_shape_stalk st = {.series = "a", .tip_mass = 1e-3, .base_angle = NAN, .segment = 6};
    o.stalks = &st;
    o.plant = g;
    CHECK(phc_shape_series_new(tr, &o, &plant, &err) == PHC_OK);
    if (stalk && plant) {
        double ys[4], yp[4];
        const double p[] = {truth[0], truth[1], truth[2], truth[3]};
        CHECK(stalk->n == 4 && plant->n == 4);
        CHECK(stalk->ops->predict(stalk, p, ys, NULL) == 0 && plant->ops->predict(plant, p, yp, NULL) == 0);
        double worst = 0;
        for (int i = 0; i < 4; ++i)
            worst = fmax(worst, fabs(ys[i] - yp[i]));
        printf("particles: plant graph laid out as particle stalk a: angles %.4f .. %.4f rad, largest difference "
               "%.3g rad\n", yp[0], yp[3], worst);
        CHECK(worst < 1e-12);
        CHECK(yp[3] < yp[0] - 0.1);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_dataset_free(stalk);
    phc_dataset_free(plant);
    phc_plant_graph_free(g);
    phc_shape_series_free(tr);
}

int main(void)
{

    test_limits();
    double a[N_T], b[N_T];
    if (synthetic(a, b) == 0) {
        test_jacobian(a, b);
        test_fit(a, b);
        test_plant(a, b);
        test_e_min_slot(a, b);
        test_particles_jacobian(a, b);
        test_particles_plant(a, b);
    }
    test_particles_limits();
    test_errors();
    return check_finish("shape_series_new");
}
