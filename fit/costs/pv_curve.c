/* `pv_curve` data sets: see pv_curve.h. */
#include "fit/costs/pv_curve.h"

#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "fit/costs/elasticity_curve.h"
#include "fit/pv_plots.h"
#include "measurements/suggest.h"
#include "measurements/table.h"
#include "model/elasticity.h"

const char *const phc_pv_curve_keys[] = {"file", "psi", "psi_unit", "fresh_mass", "bag_mass", "dry_mass",
                                         "saturated_mass", "group", "leaf", "breakpoint", "sigma", NULL};
const phc_key_help phc_pv_curve_help[] = {
    {"file", "CSV table of the pressure-volume points, at least 6 per leaf, relative to the "
             "config file. Required."},
    {"psi", "Column of water potentials, every value < 0 (enter pressure-chamber balance "
            "pressures with a minus sign). Required."},
    {"psi_unit", "Unit of psi: MPa, bar or kPa (case ignored). Default: MPa."},
    {"fresh_mass", "Column of weighed masses, g: the leaf, or the leaf in its bag when bag_mass "
                   "is given. Required."},
    {"bag_mass", "A column or a number, g, subtracted from fresh_mass (the bagged-leaf "
                 "protocol). Default: none."},
    {"dry_mass", "A column or a number, g, below every leaf mass. Required."},
    {"saturated_mass", "The turgid leaf mass, g: a column or a number; or extrapolate (the "
                       "saturated water from psi against leaf water at psi = 0 over the wettest "
                       "3 to 5 points). Required."},
    {"group", "Column of leaf ids, for a table of several leaves. Default: one leaf."},
    {"leaf", "With group: one leaf id, each (one logistic per leaf: slots kappa_<id>, "
             "chi0_<id>, e_min_<id>, e_max_<id>) or pooled (one logistic for all leaves). "
             "Required when the group column holds more than one id."},
    {"breakpoint", "How the linear (osmotic) region is chosen: min_rss, max_r2, or a whole "
                   "number >= 3 of driest points. Default: min_rss."},
    {"sigma", "Standard deviation of the moduli, a positive number, MPa. "
              "Default: unweighted."},
    {NULL, NULL}};

typedef struct pv_extra {
    size_t count;
    char **labels;
    phc_pv_result **res;
    double *swc, *swc_se; /* extrapolated saturated water mass per leaf, g (NaN if measured) */
    size_t *swc_k;
    int extrapolated;
} pv_extra;

static void pv_extra_free(void *p)
{
    pv_extra *x = p;
    if (!x)
        return;
    for (size_t i = 0; i < x->count; ++i) {
        free(x->labels[i]);
        phc_pv_result_free(x->res[i]);
    }
    free(x->labels);
    free(x->res);
    free(x->swc);
    free(x->swc_se);
    free(x->swc_k);
    free(x);
}

static int pv_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err);
static int pv_fit_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err);
static int pv_name_series(phc_dataset *ds, phc_error *err);

static const phc_dataset_ops pv_ops = {"pv_curve", phc_elasticity_predict, phc_elasticity_predict_at,
                                       phc_elasticity_impl_free, pv_report_section, NULL, pv_fit_outputs,
                                       pv_name_series};

static pv_extra *extra_of(const phc_dataset *ds)
{
    if (!ds || ds->ops != &pv_ops || !ds->impl)
        return NULL;
    return ((const phc_elasticity_impl *)ds->impl)->extra;
}

size_t phc_pv_curve_leaf_count(const phc_dataset *ds)
{
    const pv_extra *x = extra_of(ds);
    return x ? x->count : 0;
}

const phc_pv_result *phc_pv_curve_leaf(const phc_dataset *ds, size_t i, const char **label)
{
    const pv_extra *x = extra_of(ds);
    if (!x || i >= x->count)
        return NULL;
    if (label)
        *label = x->labels[i];
    return x->res[i];
}

static void put_estimate(FILE *f, phc_pv_estimate e, int digits)
{
    if (!isfinite(e.value))
        fprintf(f, " — |");
    else if (isfinite(e.stderr_))
        fprintf(f, " %.*f ± %.*f |", digits, e.value, digits, e.stderr_);
    else
        fprintf(f, " %.*f ± — |", digits, e.value);
}

int phc_pv_markdown_table(const phc_pv_result *const *results, const char *const *labels, size_t count,
                          const char *title, char **out, phc_error *err)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    *out = NULL;
    if (!f)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (title)
        fprintf(f, "### %s\n\n", title);
    fprintf(f, "| leaf | points | linear points (R²) | π_o (MPa) | ψ_tlp (MPa) | RWC_tlp | ε (MPa) | ε_sym (MPa) "
               "| apoplastic fraction |\n");
    fprintf(f, "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (size_t i = 0; i < count; ++i) {
        const phc_pv_result *r = results[i];
        fprintf(f, "| %s | %zu | %zu (%.4f) |", labels[i], r->n, r->n_osmotic, r->r2_osmotic);
        put_estimate(f, r->pi_o, 3);
        put_estimate(f, r->psi_tlp, 3);
        put_estimate(f, r->rwc_tlp, 3);
        put_estimate(f, r->epsilon, 2);
        put_estimate(f, r->epsilon_sym, 2);
        put_estimate(f, r->apoplastic_fraction, 3);
        fputc('\n', f);
    }
    fprintf(f, "\nValues ± standard errors (linear regressions, delta method). ε is dP/dRWC on total RWC, "
               "ε_sym on symplastic RWC; the linear region is chosen by the breakpoint rule of "
               "model/pressure_volume.h.\n");
    int any = 0;
    for (size_t i = 0; i < count; ++i)
        for (unsigned b = 0; b < PHC_PV_WARN_COUNT; ++b)
            if (results[i]->warnings & (1u << b)) {
                if (!any)
                    fprintf(f, "\nWarnings:\n\n");
                any = 1;
                fprintf(f, "- leaf %s: %s\n", labels[i], phc_pv_warning_text(1u << b));
            }
    if (fclose(f) != 0 || !buf) {
        free(buf);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *out = buf;
    return PHC_OK;
}

int phc_pv_curve_markdown(const phc_dataset *ds, char **out, phc_error *err)
{
    const pv_extra *x = extra_of(ds);
    *out = NULL;
    if (!x)
        return phc_error_set(err, PHC_ERR_INVALID, "data set '%s' is not a pv_curve data set",
                             ds && ds->name ? ds->name : "?");
    char title[300];
    snprintf(title, sizeof title, "Pressure–volume parameters: %s", ds->name ? ds->name : "pv_curve");
    char *table = NULL;
    int rc = phc_pv_markdown_table((const phc_pv_result *const *)x->res, (const char *const *)x->labels, x->count,
                                   title, &table, err);
    if (rc || !x->extrapolated) {
        *out = table;
        return rc;
    }
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) {
        free(table);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    fputs(table, f);
    fprintf(f, "\nSaturated water mass extrapolated to ψ = 0 (ψ against leaf water over the wettest points):\n\n");
    for (size_t i = 0; i < x->count; ++i)
        fprintf(f, "- leaf %s: %.4f ± %.4f g (%zu points)\n", x->labels[i], x->swc[i], x->swc_se[i], x->swc_k[i]);
    free(table);
    if (fclose(f) != 0 || !buf) {
        free(buf);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *out = buf;
    return PHC_OK;
}

/* ---- loading ------------------------------------------------------------- */


/* A mass given as a column name or a number (g): n values in *values.
 * *extrapolate is set instead when allowed and the value is `extrapolate`. */
static int mass_spec(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key, int required,
                     const phc_table *t, int *extrapolate, double **values, phc_error *err)
{
    const phc_yaml_node *v = phc_yaml_get(node, key);
    const size_t n = phc_table_rows(t);
    *values = NULL;
    if (!v) {
        if (!required)
            return PHC_OK;
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: pv_curve data set: missing key '%s' (a column of %s or a number in g%s)",
                             doc->path, node->line, key, phc_table_source(t),
                             extrapolate ? ", or 'extrapolate'" : "");
    }
    if (v->kind != PHC_YAML_SCALAR || !v->scalar[0])
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': expected a column name or a number (g)",
                             doc->path, v->line, key);
    if (extrapolate && strcmp(v->scalar, "extrapolate") == 0) {
        *extrapolate = 1;
        return PHC_OK;
    }
    if (phc_table_find(t, v->scalar) >= 0)
        return phc_table_column_numbers(t, v->scalar, values, err);
    phc_error tmp;
    double x;
    phc_error_clear(&tmp);
    if (phc_yaml_number(doc, v, key, &x, &tmp) != PHC_OK) {
        int rc = phc_need_column(doc, node, key, v->scalar, t, err);
        if (rc == PHC_ERR_INPUT)
            strncat(err->message, " (nor a number)", sizeof err->message - strlen(err->message) - 1);
        return rc;
    }
    if (!(x >= 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': a mass must not be negative, found %g", doc->path,
                             v->line, key, x);
    if (!(*values = malloc((n ? n : 1) * sizeof **values)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n; ++i)
        (*values)[i] = x;
    return PHC_OK;
}

int phc_pv_curve_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                      phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    (void)is_parameter;
    (void)user_data;
    const char *ctx = "pv_curve data set";
    const char *file = NULL, *psi_col = NULL, *unit = "MPa", *fresh_col = NULL, *group_col = NULL, *leaf = NULL;
    const char *bp = NULL;
    phc_table *t = NULL;
    phc_dataset *ds = NULL;
    pv_extra *x = NULL;
    char *path = NULL;
    double *psi = NULL, *fresh = NULL, *bag = NULL, *dry = NULL, *sat = NULL;
    size_t *gid = NULL, n_groups = 0, *rows = NULL;
    const char **gname = NULL;
    double *lpsi = NULL, *lrwc = NULL, *lwater = NULL;
    int extrapolate = 0, rc;
    *out = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "psi", 1, ctx, &psi_col, err)) ||
        (rc = phc_yaml_map_string(doc, node, "psi_unit", 0, ctx, &unit, err)) ||
        (rc = phc_yaml_map_string(doc, node, "fresh_mass", 1, ctx, &fresh_col, err)) ||
        (rc = phc_yaml_map_string(doc, node, "group", 0, ctx, &group_col, err)) ||
        (rc = phc_yaml_map_string(doc, node, "leaf", 0, ctx, &leaf, err)) ||
        (rc = phc_yaml_map_string(doc, node, "breakpoint", 0, ctx, &bp, err)))
        return rc;
    double to_mpa;
    if (strcasecmp(unit, "MPa") == 0)
        to_mpa = 1.0;
    else if (strcasecmp(unit, "bar") == 0)
        to_mpa = 0.1;
    else if (strcasecmp(unit, "kPa") == 0)
        to_mpa = 1e-3;
    else
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'psi_unit': expected MPa, bar or kPa, found '%s'",
                             doc->path, phc_key_line(node, "psi_unit"), unit);
    phc_pv_options opt = phc_pv_options_default();
    if (bp) {
        char *end = NULL;
        long m = strtol(bp, &end, 10);
        if (strcmp(bp, "min_rss") == 0)
            opt.rule = PHC_PV_BREAK_MIN_RSS;
        else if (strcmp(bp, "max_r2") == 0)
            opt.rule = PHC_PV_BREAK_MAX_R2;
        else if (end != bp && *end == '\0' && m >= 3) {
            opt.rule = PHC_PV_BREAK_FIXED;
            opt.n_osmotic = (size_t)m;
        } else
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: key 'breakpoint': expected min_rss, max_r2 or a whole number of points >= 3, "
                                 "found '%s'", doc->path, phc_key_line(node, "breakpoint"), bp);
    }
    if (leaf && !group_col)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'leaf' needs key 'group' (the column of leaf ids)",
                             doc->path, phc_key_line(node, "leaf"));

    if (!(path = phc_join_path(base_dir, file)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_table_read(path, &t, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto fail;
    }
    const size_t n = phc_table_rows(t);
    if (n == 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one", path);
        goto fail;
    }
    if ((rc = phc_need_column(doc, node, "psi", psi_col, t, err)) ||
        (rc = phc_need_column(doc, node, "fresh_mass", fresh_col, t, err)) ||
        (group_col && (rc = phc_need_column(doc, node, "group", group_col, t, err))) ||
        (rc = phc_table_column_numbers(t, psi_col, &psi, err)) ||
        (rc = phc_table_column_numbers(t, fresh_col, &fresh, err)) ||
        (rc = mass_spec(doc, node, "bag_mass", 0, t, NULL, &bag, err)) ||
        (rc = mass_spec(doc, node, "dry_mass", 1, t, NULL, &dry, err)) ||
        (rc = mass_spec(doc, node, "saturated_mass", 1, t, &extrapolate, &sat, err)))
        goto fail;

    /* Row checks, with file and line. */
    for (size_t i = 0; i < n; ++i) {
        const size_t line = phc_table_row_line(t, i);
        if (psi[i] > 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column '%s': water potential must be negative, found %g %s "
                               "(enter pressure-chamber balance pressures with a minus sign)",
                               path, line, psi_col, psi[i], unit);
            goto fail;
        }
        if (psi[i] == 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column '%s': water potential 0 leaves 1/psi undefined; "
                               "a pressure-volume point needs a negative potential", path, line, psi_col);
            goto fail;
        }
        psi[i] *= to_mpa;
        const double leafm = fresh[i] - (bag ? bag[i] : 0);
        if (!(leafm > dry[i])) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: leaf mass %g g (fresh%s) is not above the dry mass %g g", path, line, leafm,
                               bag ? " minus bag" : "", dry[i]);
            goto fail;
        }
        if (sat && !(sat[i] > dry[i])) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: saturated mass %g g is not above the dry mass %g g", path,
                               line, sat[i], dry[i]);
            goto fail;
        }
    }

    /* Leaves. */
    if (!(gid = calloc(n, sizeof *gid)) || !(gname = calloc(n, sizeof *gname)) || !(rows = malloc(n * sizeof *rows)) ||
        !(lpsi = malloc(n * sizeof *lpsi)) || !(lrwc = malloc(n * sizeof *lrwc)) ||
        !(lwater = malloc(n * sizeof *lwater))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    const long gcol = group_col ? phc_table_find(t, group_col) : -1;
    for (size_t i = 0; i < n; ++i) {
        const char *g = gcol >= 0 ? phc_table_cell(t, i, (size_t)gcol) : "all";
        size_t k = 0;
        while (k < n_groups && strcmp(gname[k], g) != 0)
            ++k;
        if (k == n_groups)
            gname[n_groups++] = g;
        gid[i] = k;
    }
    int each = 0;
    size_t only = (size_t)-1; /* selected leaf, or all */
    if (gcol >= 0) {
        if (!leaf && n_groups > 1) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column '%s' of %s holds %zu leaves ('%s', '%s', ...); choose one with "
                               "'leaf: <id>', or 'leaf: each' or 'leaf: pooled'",
                               doc->path, phc_key_line(node, "group"), group_col, path, n_groups, gname[0], gname[1]);
            goto fail;
        }
        if (leaf && strcmp(leaf, "each") == 0)
            each = 1;
        else if (leaf && strcmp(leaf, "pooled") != 0) {
            for (size_t k = 0; k < n_groups; ++k)
                if (strcmp(gname[k], leaf) == 0)
                    only = k;
            if (only == (size_t)-1) {
                char list[400] = "";
                for (size_t k = 0; k < n_groups && k < 20; ++k) {
                    size_t used = strlen(list);
                    snprintf(list + used, sizeof list - used, "%s'%s'", k ? ", " : "", gname[k]);
                }
                const char *near = phc_suggest(leaf, gname, n_groups);
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'leaf': '%s' is not a value of column '%s' in %s "
                                   "(values: %s%s)%s%s%s",
                                   doc->path, phc_key_line(node, "leaf"), leaf, group_col, path, list,
                                   n_groups > 20 ? ", ..." : "", near ? "; did you mean '" : "", near ? near : "",
                                   near ? "'?" : "");
                goto fail;
            }
        }
    }
    const size_t n_leaves = only == (size_t)-1 ? n_groups : 1;
    if (!(x = calloc(1, sizeof *x)) || !(x->labels = calloc(n_leaves, sizeof *x->labels)) ||
        !(x->res = calloc(n_leaves, sizeof *x->res)) || !(x->swc = malloc(n_leaves * sizeof *x->swc)) ||
        !(x->swc_se = malloc(n_leaves * sizeof *x->swc_se)) || !(x->swc_k = calloc(n_leaves, sizeof *x->swc_k))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    x->extrapolated = extrapolate;
    size_t n_obs = 0;
    for (size_t L = 0; L < n_leaves; ++L) {
        const size_t g = only == (size_t)-1 ? L : only;
        size_t m = 0;
        for (size_t i = 0; i < n; ++i)
            if (gid[i] == g)
                rows[m++] = i;
        x->count = L + 1;
        if (!(x->labels[L] = strdup(gname[g]))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        const size_t first = phc_table_row_line(t, rows[0]);
        const size_t need = 2 * opt.min_points;
        if (m < need) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: leaf '%s' has %zu point%s; a pressure-volume analysis needs at least %zu "
                               "(%zu on each side of the turgor loss point)",
                               path, first, gname[g], m, m == 1 ? "" : "s", need, opt.min_points);
            goto fail;
        }
        if (opt.rule == PHC_PV_BREAK_FIXED && (opt.n_osmotic > m - opt.min_points)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'breakpoint': %zu linear points leave fewer than %zu "
                               "above the turgor loss point in leaf '%s' (%zu points)",
                               doc->path, phc_key_line(node, "breakpoint"), opt.n_osmotic, opt.min_points, gname[g], m);
            goto fail;
        }
        for (size_t j = 0; j < m; ++j) {
            const size_t i = rows[j];
            lpsi[j] = psi[i];
            lwater[j] = fresh[i] - (bag ? bag[i] : 0) - dry[i];
        }
        x->swc[L] = x->swc_se[L] = NAN;
        if (extrapolate) {
            if ((rc = phc_pv_extrapolate_saturation(lpsi, lwater, m, &x->swc[L], &x->swc_se[L], &x->swc_k[L], err))) {
                rc = phc_error_prefix(err, rc, "%s:%zu: leaf '%s'", path, first, gname[g]);
                goto fail;
            }
            for (size_t j = 0; j < m; ++j)
                lrwc[j] = lwater[j] / x->swc[L];
        } else {
            for (size_t j = 0; j < m; ++j)
                lrwc[j] = lwater[j] / (sat[rows[j]] - dry[rows[j]]);
        }
        for (size_t j = 0; j < m; ++j)
            for (size_t q = 0; q < j; ++q)
                if (lrwc[q] == lrwc[j]) {
                    rc = phc_error_set(err, PHC_ERR_INPUT,
                                       "%s:%zu: leaf '%s': same relative water content (%g) as line %zu; masses "
                                       "must differ between points", path, phc_table_row_line(t, rows[j]), gname[g],
                                       lrwc[j], phc_table_row_line(t, rows[q]));
                    goto fail;
                }
        if ((rc = phc_pv_analyse(lpsi, lrwc, m, &opt, &x->res[L], err))) {
            rc = phc_error_prefix(err, rc, "%s:%zu: leaf '%s'", path, first, gname[g]);
            goto fail;
        }
        n_obs += x->res[L]->n_modulus;
    }

    /* The elasticity data set over all moduli. */
    if ((rc = phc_elasticity_dataset_new(&pv_ops, n_obs, each ? n_leaves : 1,
                                         each ? (const char *const *)x->labels : NULL, &ds, err)))
        goto fail;
    phc_elasticity_impl *impl = ds->impl;
    size_t o = 0;
    for (size_t L = 0; L < n_leaves; ++L) {
        const size_t g = only == (size_t)-1 ? L : only;
        size_t m = 0;
        for (size_t i = 0; i < n; ++i)
            if (gid[i] == g)
                rows[m++] = i;
        const phc_pv_result *r = x->res[L];
        for (size_t j = 0; j < r->n_modulus; ++j, ++o) {
            ds->x[o] = r->modulus_rwc[j];
            ds->y[o] = r->modulus[j];
            ds->data_lines[o] = phc_table_row_line(t, rows[r->order[j]]);
            impl->block[o] = each ? L : 0;
        }
    }
    impl->extra = x;
    impl->free_extra = pv_extra_free;
    x = NULL;
    const phc_yaml_node *sig = phc_yaml_get(node, "sigma");
    if (sig) {
        double s = 0;
        if ((rc = phc_yaml_number(doc, sig, "sigma", &s, err)) || !(s > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'sigma': expected a positive number (MPa), found '%s'",
                               doc->path, sig->line, sig->kind == PHC_YAML_SCALAR ? sig->scalar : "(not a scalar)");
            goto fail;
        }
        if (!(ds->sigma = malloc(n_obs * sizeof *ds->sigma))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t i = 0; i < n_obs; ++i)
            ds->sigma[i] = s;
    }
    ds->x_label = strdup("relative water content (RWC)");
    ds->y_label = strdup("bulk modulus dP/dRWC (MPa)");
    ds->data_file = strdup(path);
    if (!ds->x_label || !ds->y_label || !ds->data_file || phc_dataset_add_input(ds, path)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->config_line = node->line;
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    phc_dataset_free(ds);
    pv_extra_free(x);
    phc_table_free(t);
    free(path);
    free(psi);
    free(fresh);
    free(bag);
    free(dry);
    free(sat);
    free(gid);
    free(gname);
    free(rows);
    free(lpsi);
    free(lrwc);
    free(lwater);
    return rc;
}

/* The report hook: the classic PV parameters do not depend on the fitted
 * logistic, so p is not needed. */
static int pv_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    (void)p;
    return phc_pv_curve_markdown(ds, markdown, err);
}

/* fit: the classic pressure–volume plot of every leaf (fit/pv_plots.h). */
static int pv_fit_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err)
{
    (void)p;
    const pv_extra *x = extra_of(ds);
    return phc_pv_plot_write(ds->name, (const phc_pv_result *const *)x->res, (const char *const *)x->labels,
                             x->count, dir, base, err);
}

/* The leaves are the series: the moduli of leaf L follow those of leaf L - 1. */
static void pv_series_name(const phc_dataset *ds, size_t g, char *buf, size_t size)
{
    snprintf(buf, size, "%s", extra_of(ds)->labels[g]);
}

static int pv_name_series(phc_dataset *ds, phc_error *err)
{
    const pv_extra *x = extra_of(ds);
    if (!ds->series && !(ds->series = malloc((ds->n ? ds->n : 1) * sizeof *ds->series)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t L = 0, o = 0; L < x->count; ++L)
        for (size_t j = 0; j < x->res[L]->n_modulus && o < ds->n; ++j)
            ds->series[o++] = L;
    return phc_dataset_name_series(ds, "leaf", x->count, pv_series_name, err);
}
