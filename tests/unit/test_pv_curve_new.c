/* `pv_curve` data sets built in C, without a config (fit/costs/pv_curve.h):
 *
 * 1. two leaves dried on a pretend bench, made in the test from the forward
 *    model of generate.py (measurements/examples/pressure_volume): osmotic
 *    potential pi(RWC) = pi_o (1 - a_f)/(RWC - a_f) with pi_o = -1.2 MPa,
 *    a_f = 0.25, turgor whose modulus dP/dRWC is the logistic elasticity
 *    (wilting eq. 9) with kappa = 60, chi0 = 0.92, e_min = 0, e_max = 10 MPa;
 *    psi = pi + P, exact, in bar, leaves weighed in a 0.05 g bag; 31 points
 *    per leaf, 0.01 RWC apart, from RWC 1.00 (leaf 1) or 0.995 (leaf 2).
 *    phc_pv_curve_new (pooled, the linear region fixed to the 11 driest
 *    points of each leaf) analyses both leaves, and the logistic fitted to
 *    their moduli, bound by name to a hand-built problem, comes back near
 *    the truth.  Not exactly: the classic analysis takes the driest points
 *    as turgor-free (here they keep up to 1.2e-4 MPa) and the moduli are
 *    secant slopes between neighbouring points, so the tolerances are 0.001
 *    for pi_o (MPa) and the apoplastic fraction, 2% for kappa and e_max and
 *    0.002 for chi0 (this code is off by 1.5e-4, 0.6% (kappa), 0.02% (e_max)
 *    and 1e-5);
 * 2. `each`: one block of slots per leaf, named after the leaf ids;
 * 3. without an origin the messages name the kind ("pv_curve: ..."), with
 *    one they name the config file and the key's line, as a config load
 *    does; row errors name the table and the row's line either way. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/pv_curve.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/table.h"

#define PER_LEAF 31
#define N_ROWS (2 * PER_LEAF)
static const double PI_O = -1.2, AF = 0.25, KAPPA = 60, CHI0 = 0.92, E_MAX = 10, BAG = 0.05;

/* psi (MPa) at a relative water content: osmotic plus turgor, whose
 * derivative is E_MAX sigma(KAPPA (RWC - CHI0)). */
static double psi_true(double rwc)
{
    const double z = KAPPA * (rwc - CHI0);
    const double softplus = z > 0 ? z + log1p(exp(-z)) : log1p(exp(z));
    return PI_O * (1 - AF) / (rwc - AF) + E_MAX / KAPPA * softplus;
}

/* Leaf ids 1 and 2 with dry and saturated masses (g) of generate.py's
 * leaves; psi in bar; fresh mass with the bag.  row3_psi_bar replaces the
 * third point's potential when not NaN. */
static phc_table *pv_table(double row3_psi_bar)
{
    static const double dry_g[2] = {0.352, 0.291}, sat_g[2] = {1.604, 1.377};
    double leaf[N_ROWS], psi[N_ROWS], fresh[N_ROWS], dry[N_ROWS], sat[N_ROWS];
    for (int L = 0; L < 2; ++L)
        for (int j = 0; j < PER_LEAF; ++j) {
            const int i = L * PER_LEAF + j;
            const double rwc = 1.0 - 0.005 * L - 0.01 * j;
            leaf[i] = L + 1;
            psi[i] = 10 * psi_true(rwc); /* MPa -> bar */
            dry[i] = dry_g[L];
            sat[i] = sat_g[L];
            fresh[i] = dry_g[L] + rwc * (sat_g[L] - dry_g[L]) + BAG;
        }
    if (!isnan(row3_psi_bar))
        psi[2] = row3_psi_bar;
    const char *names[] = {"leaf", "psi_bar", "fresh_g", "dry_g", "sat_g"};
    const double *cols[] = {leaf, psi, fresh, dry, sat};
    phc_table *t = NULL;
    phc_error err;
    CHECK(phc_table_from_columns("pv", 5, names, cols, N_ROWS, &t, &err) == PHC_OK);
    return t;
}

static phc_pv_curve_options pv_options(void)
{
    phc_pv_curve_options o = phc_pv_curve_options_default();
    o.psi = "psi_bar";
    o.psi_unit = "bar";
    o.fresh_mass = "fresh_g";
    o.bag_mass.value = BAG;
    o.dry_mass.column = "dry_g";
    o.saturated_mass.column = "sat_g";
    o.group = "leaf";
    o.leaf = "pooled";
    o.analysis.rule = PHC_PV_BREAK_FIXED; /* the 11 driest points, RWC 0.80 to 0.70 */
    o.analysis.n_osmotic = 11;
    return o;
}

static void test_fit(void)
{
    phc_table *t = pv_table(NAN);
    if (!t)
        return;
    const phc_pv_curve_options o = pv_options();
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_OK);
    phc_table_free(t); /* the data set keeps what it needs */
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->n == 2 * (PER_LEAF - 1) && ds->k == 4);
    CHECK(strcmp(ds->ops->kind, "pv_curve") == 0 && ds->ops == &phc_pv_curve_ops);
    CHECK(strcmp(ds->slot_names[0], "kappa") == 0 && strcmp(ds->slot_names[3], "e_max") == 0);
    CHECK(ds->sigma == NULL && ds->config_line == 0 && ds->n_inputs == 0);
    CHECK(phc_pv_curve_leaf_count(ds) == 2);
    for (size_t L = 0; L < phc_pv_curve_leaf_count(ds); ++L) {
        const char *label = NULL;
        const phc_pv_result *r = phc_pv_curve_leaf(ds, L, &label);
        if (!r)
            continue;
        printf("leaf %s: pi_o %.6f MPa (truth %g), apoplastic fraction %.6f (truth %g), %zu linear points\n",
               label, r->pi_o.value, PI_O, r->apoplastic_fraction.value, AF, r->n_osmotic);
        CHECK(strcmp(label, L ? "2" : "1") == 0 && r->n == PER_LEAF);
        CHECK_NEAR(r->pi_o.value, PI_O, 0.001, 0);
        CHECK_NEAR(r->apoplastic_fraction.value, AF, 0.001, 0);
        CHECK(r->n_osmotic == 11);
    }

    phc_problem *pb = phc_problem_new("pv");
    CHECK(phc_problem_add_parameter(pb, "kappa", 20.0, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "chi0", 0.85, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "e_min", 0.0, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "e_max", 5.0, NULL, &err) == PHC_OK);
    pb->params[0].lower = pb->params[3].lower = 0;
    pb->params[2].fixed = 1;
    ds->name = strdup("leaves");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    CHECK(ds->n_series == 2); /* the leaves, for the plots */
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        printf("fitted kappa %.6g (truth %g), chi0 %.6g (truth %g), e_max %.6g (truth %g)\n",
               res->params[0].value, KAPPA, res->params[1].value, CHI0, res->params[3].value, E_MAX);
        CHECK_NEAR(res->params[0].value, KAPPA, 0, 0.02);
        CHECK_NEAR(res->params[1].value, CHI0, 0.002, 0);
        CHECK_NEAR(res->params[3].value, E_MAX, 0, 0.02);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

static void test_each(void)
{
    phc_table *t = pv_table(NAN);
    if (!t)
        return;
    phc_pv_curve_options o = pv_options();
    o.leaf = "each";
    o.sigma = 0.25;
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_OK);
    if (ds) {
        CHECK(ds->k == 8);
        CHECK(strcmp(ds->slot_names[0], "kappa_1") == 0 && strcmp(ds->slot_names[7], "e_max_2") == 0);
        CHECK(ds->sigma && ds->sigma[0] == 0.25 && ds->sigma[ds->n - 1] == 0.25);
        printf("each: %zu slots, %s ... %s\n", ds->k, ds->slot_names[0], ds->slot_names[7]);
    }
    phc_dataset_free(ds);
    o.leaf = "2"; /* one leaf */
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_OK);
    if (ds)
        CHECK(ds->k == 4 && ds->n == PER_LEAF - 1 && phc_pv_curve_leaf_count(ds) == 1);
    phc_dataset_free(ds);
    phc_table_free(t);
}

/* The line of each key in a pretend config. */
static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return strcmp(key, "psi") == 0 ? 10 : strcmp(key, "leaf") == 0 ? 15 : 8;
}

static void test_messages(void)
{
    phc_table *t = pv_table(NAN);
    if (!t)
        return;
    phc_pv_curve_options o = pv_options();
    phc_dataset *ds = NULL;
    phc_error err;

    o.psi_unit = "psi";
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "pv_curve: key 'psi_unit': expected MPa, bar or kPa, found 'psi'") == 0);

    o.psi_unit = "BAR";
    o.leaf = "9";
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "pv_curve: key 'leaf': '9' is not a value of column 'leaf' in pv (values: '1', "
                              "'2'); did you mean '1'?") == 0);

    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 8};
    o.origin = &origin;
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strncmp(err.message, "cfg.yaml:15: key 'leaf': '9' is not a value", 43) == 0);

    o.leaf = "pooled";
    o.psi = "psi";
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:10: key 'psi': 'psi' is not a column of pv (columns: 'leaf', 'psi_bar', "
                              "'fresh_g', 'dry_g', 'sat_g')") == 0);

    o.origin = NULL;
    o.psi = "psi_bar";
    o.dry_mass.column = NULL;
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "pv_curve: key 'dry_mass' is required (a column or a number in g)") == 0);
    o.dry_mass.value = -0.3;
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "pv_curve: key 'dry_mass': a mass must not be negative, found -0.3") == 0);
    o.dry_mass.value = NAN;
    o.dry_mass.column = "dry_g";
    o.extrapolate_saturation = 1;
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "pv_curve: key 'saturated_mass': give a mass or extrapolate, not both") == 0);
    o.extrapolate_saturation = 0;
    o.group = NULL;
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "pv_curve: key 'leaf' needs key 'group' (the column of leaf ids)") == 0);
    o.group = "leaf";
    o.leaf = NULL;
    CHECK(phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "pv_curve: column 'leaf' of pv holds 2 leaves ('1', '2', ...)") == err.message);
    CHECK(ds == NULL);
    CHECK(phc_pv_curve_new(NULL, &o, &ds, &err) == PHC_ERR_INVALID && ds == NULL);
    phc_table_free(t);

    /* a positive potential: the table and the row's line, origin or not */
    t = pv_table(9.5);
    o.leaf = "1";
    CHECK(t && phc_pv_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "pv:4: column 'psi_bar': water potential must be negative, found 9.5 BAR (enter "
                              "pressure-chamber balance pressures with a minus sign)") == 0);
    phc_table_free(t);
}

int main(void)
{
    test_fit();
    test_each();
    test_messages();
    return check_finish("test_pv_curve_new");
}
