/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 6 in spirit:
 * simulated against measured weight.  The paper compares its simulated
 * water loss with plants weighed while they wilt; we use real balance data
 * that phytocal can read: twelve detached kohlrabi leaves drying on a
 * balance (R package pvldcurve 1.2.6, `leaf_drying_data`, two treatments;
 * ../shared/data/leaf_drying).
 *
 * One joint fit built through the C API (phc_weight_curve_read_table,
 * phc_plant_graph_leaf_chain, phc_weight_curve_new, a problem of its own):
 * one loss rate delta shared by the twelve leaves, an initial water per leaf,
 * the measured dry weight as the dry mass; each leaf is a venation chain
 * built from its measured area (weight_curve `leaf_area`).  Plotted: the
 * measurements and the fitted curves of all twelve leaves, one panel per
 * treatment (soil moisture during growth), and their residuals.
 *
 * Checks (exit 1 when one fails): the fit converges, delta is positive and
 * determined, every fitted initial water lies between 0 and the first
 * weighing, every fitted curve decreases.
 *
 * Usage: notebook_wilting_fig6_leaf_drying OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <plplot.h>

#include "fit/costs/weight_curve.h"
#include "fit/costs/weight_table.h"
#include "fit/engine/fit.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/problem.h"
#include "measurements/c_number.h"
#include "measurements/table.h"
#include "measurements/units.h"
#include "model/plant_graph.h"

#include "notebook_plot.h"

#define N_LEAVES 12

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

/* Leaf `leaf` (the table's `sample`) as a weight_curve data set: times in
 * s, masses in g, a venation chain of 20 segments (vein radius 0.5 mm) from
 * its leaf.area (cm2) and its dry.weight (g) as the dry mass, both read at
 * its first weighing (fit/costs/weight_table.h, weight_curve.h). */
static phc_dataset *leaf_dataset(const phc_table *t, phc_units *units, int leaf, phc_error *err)
{
    char sample[16], name[32];
    snprintf(sample, sizeof sample, "%d", leaf);
    snprintf(name, sizeof name, "leaf%d", leaf);
    const char *sel_col[] = {"sample"}, *sel_val[] = {sample};
    phc_weight_curve_read_options ro = phc_weight_curve_read_options_default();
    ro.time_column = "date.and.time";
    ro.time_unit = "s";
    ro.mass_column = "fresh.weight";
    ro.mass_unit = "g";
    ro.n_select = 1;
    ro.select_columns = sel_col;
    ro.select_values = sel_val;
    ro.units = units;
    phc_weighings w = phc_weighings_default();
    if (phc_weight_curve_read_table(t, &ro, &w, err)) {
        phc_weighings_release(&w);
        return NULL;
    }
    const size_t row = w.rows[0];
    const long c_area = phc_table_find(t, "leaf.area"), c_dry = phc_table_find(t, "dry.weight");
    phc_unit_conversion cm2;
    int rc = phc_units_conversion(units, "cm2", "m2", "leaf_area", &cm2, err);
    if (!rc && (c_area < 0 || c_dry < 0))
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: no column leaf.area or dry.weight", phc_table_source(t));
    phc_plant_graph *g = NULL;
    phc_weight_curve_options o = phc_weight_curve_options_default();
    if (!rc) {
        g = phc_plant_graph_leaf_chain(phc_unit_apply(cm2, phc_strtod_c(phc_table_cell(t, row, (size_t)c_area), NULL)),
                                       20, 0.5e-3);
        o.dry_mass = phc_strtod_c(phc_table_cell(t, row, (size_t)c_dry), NULL);
    }
    phc_dataset *ds = NULL;
    if (g && !phc_weight_curve_new(g, &w, &o, &ds, err) && !(ds->name = strdup(name))) {
        phc_dataset_free(ds);
        ds = NULL;
    }
    phc_plant_graph_free(g);
    phc_weighings_release(&w);
    return ds;
}

/* delta (1e-3 s-1 cm-2) and w1..w12 (4 g), all >= 0; leaf l's slots bound
 * by name except initial_water -> w<l>; the units converted and the
 * stopping tolerances kept above the ODE solver's accuracy, as
 * phc_config_load does. */
static phc_problem *joint_problem(const char *csv, phc_error *err)
{
    phc_problem *pb = phc_problem_new("wilting-fig6-leaf-drying");
    phc_units *units = phc_units_new(err);
    phc_table *t = NULL;
    int rc = !pb || !units ? PHC_ERR_NOMEM : phc_table_read(csv, &t, err);
    for (int l = 0; l <= N_LEAVES && !rc; ++l) {
        char name[16];
        snprintf(name, sizeof name, l ? "w%d" : "delta", l);
        size_t i = 0;
        if (!(rc = phc_problem_add_parameter(pb, name, l ? 4 : 1.0e-3, &i, err))) {
            pb->params[i].lower = 0;
            if (!(pb->params[i].unit = strdup(l ? "g" : "s-1 cm-2")))
                rc = PHC_ERR_NOMEM;
        }
    }
    for (int l = 1; l <= N_LEAVES && !rc; ++l) {
        phc_dataset *ds = leaf_dataset(t, units, l, err);
        if (!ds) {
            rc = PHC_ERR_INPUT;
            break;
        }
        char w[16];
        snprintf(w, sizeof w, "w%d", l);
        for (size_t j = 0; j < ds->k; ++j)
            ds->param_index[j] = (size_t)phc_problem_find_parameter(pb, strcmp(ds->slot_names[j], "initial_water")
                                                                             ? ds->slot_names[j] : w);
        rc = phc_problem_add_dataset(pb, ds, err);
    }
    if (!rc)
        rc = phc_problem_finish(pb, 0, err);
    phc_table_free(t);
    phc_units_free(units);
    if (rc) {
        if (rc == PHC_ERR_NOMEM && !err->status)
            phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        phc_problem_free(pb);
        return NULL;
    }
    return pb;
}

int main(int argc, char **argv)
{
    const char *csv = PHC_SHARED_DATA "/leaf_drying/pvldcurve_leaf_drying.csv";
    const char *out = NULL;
    int started = nb_begin(argc, argv, csv, &out);
    if (started)
        return started;
    /* The problem, built through the C API: one delta, twelve initial
     * waters, as a config with `parameters: {initial_water: w<l>}` per leaf
     * would say. */
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = joint_problem(csv, &err);
    phc_fit_result *r = NULL;
    if (!pb || phc_fit_run(pb, NULL, NULL, &r, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        phc_problem_free(pb);
        return 1;
    }
    phc_problem_free(pb);
    if (r->n_datasets != N_LEAVES) {
        fprintf(stderr, "expected %d data sets, found %zu\n", N_LEAVES, r->n_datasets);
        return 1;
    }

    /* Per leaf: first and last weighing, the fitted initial water, the
     * plateau a single exponential would need, residual runs. */
    const phc_param_result *delta = param(r, "delta");
    int ok_conv = r->summary.outcome == PHC_NLS_CONVERGED;
    int ok_delta = delta && delta->value > 0 && isfinite(delta->stderr_) && delta->stderr_ < delta->value;
    int ok_w = 1, ok_dec = 1;
    double rmse_all = sqrt(r->rss / (double)r->n_obs);
    double w0[N_LEAVES], first[N_LEAVES], last[N_LEAVES], dry[N_LEAVES], fit_last[N_LEAVES];
    double rmse[N_LEAVES], early[N_LEAVES], late[N_LEAVES], mid[N_LEAVES], mid_t[N_LEAVES];
    int checks_fail[N_LEAVES], leaves_with_structure = 0;
    for (int l = 0; l < N_LEAVES; ++l) {
        const phc_dataset_result *d = &r->datasets[l];
        char wn[8];
        snprintf(wn, sizeof wn, "w%d", l + 1);
        const phc_param_result *w = param(r, wn);
        w0[l] = w ? w->value : NAN;
        first[l] = d->y[0];
        last[l] = d->y[d->n - 1];
        fit_last[l] = d->yhat[d->n - 1];
        dry[l] = d->yhat[0] - w0[l]; /* yhat(0) = dry + W0 */
        rmse[l] = d->goodness.rmse;
        ok_w &= w0[l] > 0 && w0[l] < first[l];
        for (size_t j = 1; j < d->curve_n; ++j)
            ok_dec &= d->curve_y[j] <= d->curve_y[j - 1];
        /* the residual at the first weighing, the most negative one, and
         * the residual at the last weighing: the U shape of a convex curve
         * fitted by a nearly straight one */
        early[l] = d->residual[0];
        late[l] = d->residual[d->n - 1];
        mid[l] = INFINITY;
        for (size_t i = 0; i < d->n; ++i)
            if (d->residual[i] < mid[l])
                mid[l] = d->residual[i], mid_t[l] = d->x[i] / 3600.0;
        checks_fail[l] = 0;
        for (int c = 0; c < PHC_CHECK_COUNT; ++c)
            checks_fail[l] += d->checks[c].applicable && !d->checks[c].pass;
        leaves_with_structure += checks_fail[l] > 0;
    }

    printf("joint fit of %d leaves (%zu weighings): %s after %d iterations\n", N_LEAVES, r->n_obs,
           phc_fit_status_name(r->summary.outcome), (int)r->summary.iterations);
    printf("delta = %.4e +- %.2e s-1 cm-2 (95%% [%.4e, %.4e]); RMSE over all weighings %.4f g\n",
           delta ? delta->value : NAN, delta ? delta->stderr_ : NAN, delta ? delta->ci_lo : NAN,
           delta ? delta->ci_hi : NAN, rmse_all);
    printf("leaf treatment  first (g)  last (g)  fit last (g)  dry (g)  W0 fit (g)  RMSE (g)  "
           "residual first / min (at h) / last (g)  checks failed\n");
    for (int l = 0; l < N_LEAVES; ++l)
        printf("%4d %9s %10.4f %9.4f %13.4f %8.4f %11.4f %9.4f   %+.3f / %+.3f (%.1f) / %+.3f %8d\n",
               l + 1, (l % 2 == 0) ? "10%" : "40%", first[l], last[l], fit_last[l], dry[l], w0[l], rmse[l],
               early[l], mid[l], mid_t[l], late[l], checks_fail[l]);
    double end10 = 0.0, end40 = 0.0;
    for (int l = 0; l < N_LEAVES; ++l)
        *(l % 2 == 0 ? &end10 : &end40) += late[l] / (N_LEAVES / 2);
    printf("mean residual at the last weighing: 10%% leaves %+.3f g, 40%% leaves %+.3f g\n", end10, end40);
    printf("leaves whose residual checks find structure: %d of %d\n", leaves_with_structure, N_LEAVES);

    /* Plot: all twelve leaves, hours.  Columns: the two treatments (pvldcurve's
       labels "10%" and "40%": soil moisture 10-30 % or 40-60 % during the
       last 6 days of growth; odd samples are "10%", even ones "40%"); rows:
       mass, residuals.  Both columns share their y ranges. */
    static const int col[N_LEAVES / 2] = {NB_BLUE, NB_RED, NB_GREEN, NB_ORANGE, NB_PURPLE, NB_BROWN};
    static double hx[N_LEAVES][64], cx[N_LEAVES][512], res[N_LEAVES][64];
    static char lab[N_LEAVES][48];
    nb_series sa[2][N_LEAVES + 3], sb[2][N_LEAVES + 1]; /* per treatment: 6 leaves x 2 + the key */
    size_t ma[2] = {0, 0}, mb[2] = {0, 0};
    double ylo = INFINITY, yhi = -INFINITY, rlo = 0.0, rhi = 0.0, tmax = 0.0;
    for (int l = 0; l < N_LEAVES; ++l) {
        const phc_dataset_result *d = &r->datasets[l];
        const int t = l % 2, k = l / 2; /* treatment, colour */
        size_t n = d->n < 64 ? d->n : 64, cn = d->curve_n < 512 ? d->curve_n : 512;
        for (size_t i = 0; i < n; ++i) {
            hx[l][i] = d->x[i] / 3600.0;
            res[l][i] = d->residual[i];
            ylo = fmin(ylo, fmin(d->y[i], d->yhat[i])), yhi = fmax(yhi, fmax(d->y[i], d->yhat[i]));
            rlo = fmin(rlo, d->residual[i]), rhi = fmax(rhi, d->residual[i]);
            tmax = fmax(tmax, hx[l][i]);
        }
        for (size_t j = 0; j < cn; ++j)
            cx[l][j] = d->curve_x[j] / 3600.0;
        snprintf(lab[l], sizeof lab[l], "leaf %d", l + 1);
        /* the leaves' colours are keyed in the residual panels below */
        sa[t][ma[t]++] = (nb_series){hx[l], d->y, n, NULL, col[k], 0, 1, 0};
        sa[t][ma[t]++] = (nb_series){cx[l], d->curve_y, cn, NULL, col[k], 0, 0, 2.0};
        sb[t][mb[t]++] = (nb_series){hx[l], res[l], n, lab[l], col[k], 0, 1, 0};
        sb[t][mb[t]++] = (nb_series){hx[l], res[l], n, NULL, col[k], 2, 0, 1.0};
    }
    static const double zy[2] = {0.0, 0.0};
    double zx[2] = {0.0, tmax};
    static const char *const grown[2] = {"\"10%\": grown at 10\xe2\x80\x93" "30 % soil moisture",
                                         "\"40%\": grown at 40\xe2\x80\x93" "60 % soil moisture"};
    for (int t = 0; t < 2; ++t) {
        sa[t][ma[t]++] = (nb_series){NULL, NULL, 0, "measured", NB_BLACK, 0, 1, 0};
        sa[t][ma[t]++] = (nb_series){NULL, NULL, 0, "fitted (one \xce\xb4 for all 12)", NB_BLACK, 0, 0, 2.0};
        sa[t][ma[t]++] = (nb_series){NULL, NULL, 0, grown[t], NB_BG, 0, 0, 0.1}; /* text only */
        sb[t][mb[t]++] = (nb_series){zx, zy, 2, NULL, NB_GREY, 0, 0, 1.2};
    }
    /* room for the legends above (masses) and below (residuals) the data */
    double ytop = yhi + 0.55 * (yhi - ylo), rbot = rlo - 1.4 * (rhi - rlo);
    const char *xl = "time since the first weighing (h)", *rl = "measured \xe2\x88\x92 fitted (g)";
    nb_panel pan[4] = {
        {"\"10%\" leaves: fresh mass", xl, "fresh mass (g)", 0, ylo - 0.05 * (yhi - ylo), ytop, 1, sa[0], ma[0]},
        {"\"40%\" leaves: fresh mass", xl, "fresh mass (g)", 0, ylo - 0.05 * (yhi - ylo), ytop, 1, sa[1], ma[1]},
        {"\"10%\" leaves: residuals", xl, rl, 0, rbot, rhi + 0.05 * (rhi - rlo), 3, sb[0], mb[0]},
        {"\"40%\" leaves: residuals", xl, rl, 0, rbot, rhi + 0.05 * (rhi - rlo), 3, sb[1], mb[1]}};
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig6_leaf_drying.png", out);
    if (nb_plot(png, 1500, 1100, 2, 2, pan, 4) != 0) {
        fprintf(stderr, "%s: cannot write the plot\n", png);
        return 1;
    }

    char md[1024], mdtmp[1024];
    FILE *m = nb_open_md(out, "wilting_fig6_leaf_drying.md", md, mdtmp, sizeof md);
    if (!m) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(m,
            "# Wilting paper, Fig. 6 in spirit: simulated against measured weight\n\n"
            "**The paper's figure** (Maggioli et al., SIGGRAPH Asia 2023, Fig. 6) compares the water loss\n"
            "the model simulates with the weight of real plants measured while they wilt, and argues that\n"
            "modelling the internal water flow follows the measurements better than ignoring it.\n\n"
            "**What we computed.** The authors' measurements are not in phytocal's shared data; we use real balance data\n"
            "phytocal ships a reader for: twelve detached kohlrabi leaves drying on a balance for about\n"
            "11 h (R package pvldcurve 1.2.6, `leaf_drying_data`). The leaves come from two treatments, which\n"
            "the package labels \"10%%\" and \"40%%\": the plants grew at a soil moisture of 10–30 %% or of\n"
            "40–60 %% during their last 6 days; samples 1, 3, ..., 11 are \"10%%\", 2, 4, ..., 12 \"40%%\". Each leaf is\n"
            "a venation chain of 20 segments built from its measured area; its measured dry weight is the\n"
            "dry mass. One joint fit (%s): **one loss rate δ\n"
            "for all twelve leaves, one initial water per leaf**.\n\n"
            "- δ = %.4e ± %.2e s⁻¹ cm⁻² (95%% interval [%.4e, %.4e]); %s after %d iterations;\n"
            "- %zu weighings, RMSE %.4f g over all of them.\n\n"
            "![measured and fitted mass](wilting_fig6_leaf_drying.png)\n\n"
            "*The figure:* all twelve leaves, the \"10%%\" leaves on the left, the \"40%%\" leaves on the right\n"
            "(one colour per leaf within a column, keyed in the residual panels). Top: the measured fresh mass\n"
            "(dots) and the fitted curve (line, one δ for all twelve leaves); bottom: the residuals,\n"
            "measured − fitted (dots joined by dotted lines, in time order). Both columns share their y axes.\n\n"
            "| leaf | treatment | first weighing (g) | last (g) | fitted last (g) | dry (g) | fitted W0 (g) | RMSE (g) | residual at first weighing / most negative (at h) / at last weighing (g) | residual checks failed |\n"
            "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
            "built through the C API: `phc_weight_curve_new` per leaf, the same as `kind: weight_curve` with "
            "`leaf_area` and `dry_mass` columns", delta ? delta->value : NAN, delta ? delta->stderr_ : NAN,
            delta ? delta->ci_lo : NAN, delta ? delta->ci_hi : NAN, phc_fit_status_name(r->summary.outcome),
            (int)r->summary.iterations, r->n_obs, rmse_all);
    for (int l = 0; l < N_LEAVES; ++l)
        fprintf(m, "| %d | %s | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f | %+.3f / %+.3f (%.1f h) / %+.3f | %d of %d |\n",
                l + 1, l % 2 == 0 ? "10%" : "40%", first[l], last[l], fit_last[l], dry[l], w0[l], rmse[l],
                early[l], mid[l], mid_t[l], late[l], checks_fail[l], PHC_CHECK_COUNT);
    fprintf(m,
            "\n**What the residuals show.** %d of %d leaves fail at least one residual check (runs,\n"
            "Durbin–Watson, Ljung–Box, normality, Breusch–Pagan): the residuals are not noise but one\n"
            "systematic U: positive at the first weighing (the fit starts below it), negative from about\n"
            "1.5 to 6 h, positive again at the end (table). The measured curves are convex: a detached leaf\n"
            "loses water fast while its stomata are open (the 40%% leaves drop by ~0.9 g in the first\n"
            "2 h), then closes them and slows down to the much smaller cuticular loss. The model's loss is\n"
            "first order in the water present (ℓ = δ·A, one rate for the whole run) and the fitted δ\n"
            "drains the leaf towards its *measured dry mass*, about a tenth of the fresh weight and far\n"
            "below the level where the measured curves flatten (the last weighings are still ~80%% of the\n"
            "first). An exponential towards a floor that far away is nearly a straight line over 11 h: it\n"
            "cannot bend from fast to slow, so the fit cuts through the curve. One shared δ adds a second\n"
            "misfit: the 40%% leaves drop faster early and flatten more (mean residual at the last\n"
            "weighing %+.3f g against %+.3f g for the 10%% leaves).\n\n"
            "**How ours differs.** Different data (detached leaves rather than whole potted plants) and a\n"
            "fit rather than a hand-set loss rate. What carries over from the paper: the linear model with\n"
            "a constant loss rate reproduces the early, nearly linear part of a drying curve; it does not\n"
            "reproduce stomatal closure. A model that should follow these curves needs a loss rate that\n"
            "falls with the water content (e.g. through the logistic elasticity of wilting eq. 9) or a\n"
            "residual mass that is fitted rather than measured (`test_leaf_drying` fits that \"apparent\"\n"
            "dry mass for comparison).\n\n"
            "**Checks** (the notebook fails when one does not hold): converged %s; δ positive and\n"
            "determined (standard error below the value) %s; every fitted initial water between 0 and the\n"
            "first weighing %s; every fitted curve decreasing %s.\n",
            leaves_with_structure, N_LEAVES, end40, end10, ok_conv ? "(pass)" : "(**FAIL**)", ok_delta ? "(pass)" : "(**FAIL**)",
            ok_w ? "(pass)" : "(**FAIL**)", ok_dec ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(m, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    phc_fit_result_free(r);
    int fail = !(ok_conv && ok_delta && ok_w && ok_dec);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
