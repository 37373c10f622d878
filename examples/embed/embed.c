/* Embedding phytocal: a plant graph built in C arrays, the wilting paper's
 * water model run forward, and the calibration engine fitting the water-loss
 * rate delta to the noisy curve: no YAML, no files, only -lphytocal.
 *
 *   cc embed.c $(pkg-config --cflags --libs phytocal) -o embed && ./embed
 *
 * The story: a small plant stands on a balance for 48 hours and dries.  Its
 * mass is its dry mass (weighed afterwards, so known) plus its water W(t).
 * We make that curve with the model (delta = 2e-3 s-1 cm-2, 1.2 g of
 * water), add balance noise, and ask phytocal for delta and the initial
 * water back, with 95% intervals. */
#define _POSIX_C_SOURCE 200809L /* strdup: the library frees the names it is given */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <phytocal/phytocal.h>

#define N_SEG 11             /* 3 stem segments, 2 branches of petiole + 3 veins */
#define N_OBS 193            /* a weighing every 15 min for 48 h */
#define DELTA_TRUE 2.0e-3    /* s-1 cm-2 */
#define WATER_TRUE 1.2       /* g */
#define DRY_MASS 0.25        /* g, known */
#define NOISE_SD 0.002       /* g: a 1 mg balance */

/* ---- the plant: parent, radius (m), length (m), leaf flag per segment ---- */
static phc_plant_graph *make_plant(phc_error *err)
{
    static const size_t parent[N_SEG] = {PHC_PLANT_NO_PARENT, 0, 1, /* stem */
                                         2, 3, 4, 5,                /* branch 1 */
                                         2, 7, 8, 9};               /* branch 2 */
    static const double radius[N_SEG] = {2e-3, 2e-3, 2e-3, 1e-3, 5e-4, 5e-4, 5e-4,
                                         1e-3, 5e-4, 5e-4, 5e-4};
    static const double length[N_SEG] = {0.03, 0.03, 0.03, 0.02, 0.015, 0.015, 0.015,
                                         0.02, 0.015, 0.015, 0.015};
    static const unsigned char leaf[N_SEG] = {0, 0, 0, 0, 1, 1, 1, 0, 1, 1, 1};
    phc_plant_graph *g = phc_plant_graph_new(N_SEG);
    if (!g)
        return NULL;
    for (size_t i = 0; i < N_SEG; ++i) {
        g->parent[i] = parent[i];
        g->radius[i] = radius[i];
        g->length[i] = length[i];
        g->leaf[i] = leaf[i];
    }
    /* checks the tree and derives children and order; positions may stay 0
     * (the water model uses only radii, lengths and the tree) */
    if (phc_plant_graph_finish(g, "embed", err)) {
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

/* ---- a data-set kind of our own: the balance curve ---------------------- */
typedef struct balance {
    const phc_plant_graph *plant;
    double t[N_OBS];         /* s */
} balance;

/* yhat = dry mass + W(t) at the slot values p = {delta, initial water};
 * jac (N_OBS x 2) from the model's exact sensitivities.  0 = success,
 * > 0 = outside the model's domain (the solver rejects the step), < 0 = fatal. */
static int balance_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    const balance *b = ds->impl;
    phc_water_params wp = phc_water_params_default();
    wp.loss_rate = p[0];
    wp.initial_water = p[1];
    double W[N_OBS], dW[N_OBS * 3]; /* dW columns: d/d delta, d/d W0, d/d mu */
    phc_error err;
    int rc = phc_water_total_curve(b->plant, &wp, PHC_WATER_AUTO, 0, b->t, N_OBS, W, jac ? dW : NULL, &err);
    if (rc)
        return rc == PHC_ERR_DOMAIN || rc == PHC_ERR_INVALID ? 1 : -1;
    for (size_t i = 0; i < N_OBS; ++i) {
        yhat[i] = DRY_MASS + W[i];
        if (jac) {
            jac[2 * i] = dW[3 * i];
            jac[2 * i + 1] = dW[3 * i + 1];
        }
    }
    return 0;
}

static const phc_dataset_ops balance_ops = {
    .kind = "balance",
    .predict = balance_predict,
    .free_impl = free, /* other ops are optional */
};

/* ---- balance noise: a seeded Gaussian (splitmix64 + Box-Muller) --------- */
static double uniform01(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return ((z ^ (z >> 31)) >> 11) * 0x1.0p-53 + 0x1.0p-54; /* in (0, 1) */
}

static double gaussian(uint64_t *s)
{
    const double u = uniform01(s), v = uniform01(s);
    return sqrt(-2 * log(u)) * cos(6.283185307179586 * v);
}

int main(void)
{
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = NULL;
    phc_fit_result *res = NULL;
    int rc = 1;
    phc_plant_graph *plant = make_plant(&err);
    if (!plant) {
        if (!err.status)
            phc_error_set(&err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    printf("phytocal %s: a plant of %zu segments (%zu leaf veins), volume %.3f cm3\n", phc_version(),
           plant->n, phc_plant_graph_leaf_count(plant), phc_plant_graph_volume(plant) * 1e6);

    /* 1. The forward model: the true mass curve, plus noise (seed 42). */
    balance *b = malloc(sizeof *b);
    double *hours = malloc(N_OBS * sizeof *hours), *mass = malloc(N_OBS * sizeof *mass);
    double *sigma = malloc(N_OBS * sizeof *sigma);
    phc_dataset *ds = phc_dataset_new(&balance_ops, 2);
    if (!ds || !b || !hours || !mass || !sigma) {
        free(b), free(hours), free(mass), free(sigma), phc_dataset_free(ds);
        phc_error_set(&err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->impl = b; /* from here on, the data set owns b and the arrays below */
    ds->x = hours, ds->y = mass, ds->sigma = sigma, ds->n = N_OBS;
    b->plant = plant;
    for (size_t i = 0; i < N_OBS; ++i) {
        hours[i] = 0.25 * (double)i;
        b->t[i] = 3600 * hours[i];
        sigma[i] = NOISE_SD;
    }
    const double truth[2] = {DELTA_TRUE, WATER_TRUE};
    if (balance_predict(ds, truth, mass, NULL) != 0) {
        phc_dataset_free(ds);
        phc_error_set(&err, PHC_ERR_INTERNAL, "the water model failed at the true values");
        goto fail;
    }
    uint64_t seed = 42;
    for (size_t i = 0; i < N_OBS; ++i)
        mass[i] += NOISE_SD * gaussian(&seed);
    printf("balance: %d weighings over 48 h, %.4f g -> %.4f g, noise sd %g g (seed 42)\n\n", N_OBS,
           mass[0], mass[N_OBS - 1], NOISE_SD);

    /* 2. The problem, by hand: two global parameters, and the data set's
     *    slots {delta, initial_water} (with the units the model works in)
     *    bound to them by name. */
    ds->name = strdup("balance");
    ds->x_label = strdup("time (h)");
    ds->y_label = strdup("mass (g)");
    ds->x_seconds = 3600;                   /* x is a time: lets the checks look at time lags */
    ds->derivatives = PHC_DERIV_ANALYTIC;   /* predict() fills the Jacobian */
    ds->model_tolerance = 1e-10;            /* BDF6's relative accuracy */
    ds->slot_names[0] = strdup("delta");
    ds->slot_names[1] = strdup("initial_water");
    pb = phc_problem_new("embed");
    size_t i_delta, i_water;
    if (!pb || !ds->name || !ds->x_label || !ds->y_label || !ds->slot_names[0] || !ds->slot_names[1] ||
        phc_dataset_declare_unit(ds, "delta", "s-1 cm-2") ||
        phc_dataset_declare_unit(ds, "initial_water", "g") ||
        phc_problem_add_parameter(pb, "delta", 1e-3, &i_delta, &err) ||
        phc_problem_add_parameter(pb, "initial_water", 1.0, &i_water, &err) ||
        phc_problem_bind_by_name(pb, ds, &err)) {
        phc_dataset_free(ds);
        if (!err.status)
            phc_error_set(&err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    pb->params[i_delta].lower = 0;          /* a loss rate is not negative */
    pb->params[i_water].lower = 0;
    if (phc_problem_add_dataset(pb, ds, &err) || /* takes ds, also on failure */
        phc_problem_finish(pb, 0, &err))         /* slots' units, tolerances, checks */
        goto fail;

    /* 3. Fit: solve, covariance, intervals, residual checks. */
    if (phc_fit_run(pb, NULL, NULL, &res, &err))
        goto fail;
    phc_report_print_summary(res, stdout);
    putchar('\n');
    for (size_t i = 0; i < 2; ++i) { /* results in the order the parameters were added */
        const phc_param_result *r = &res->params[i];
        const int inside = r->ci_lo <= truth[i] && truth[i] <= r->ci_hi;
        printf("%s = %.6g %s, 95%% interval [%.6g, %.6g], truth %g: %s\n", r->name, r->value,
               r->unit ? r->unit : "", r->ci_lo, r->ci_hi, truth[i], inside ? "inside" : "OUTSIDE");
    }
    rc = res->summary.outcome == PHC_NLS_CONVERGED ? 0 : 3;
fail:
    if (err.status)
        fprintf(stderr, "embed: %s\n", err.message);
    phc_fit_result_free(res);
    phc_problem_free(pb);
    phc_plant_graph_free(plant);
    return rc;
}
