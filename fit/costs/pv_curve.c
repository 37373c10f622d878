/* `pv_curve` data sets: see pv_curve.h. */
#include "fit/costs/pv_curve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "fit/costs/elasticity_curve.h"
#include "fit/costs/source_file.h"
#include "fit/pv_plots.h"
#include "measurements/suggest.h"
#include "measurements/table.h"
#include "model/elasticity.h"

typedef struct pv_extra {
    size_t count;
    char **labels;
    phc_pv_result **res;
    double *swc, *swc_se; /* extrapolated saturated water mass per leaf, g (NaN if measured) */
    size_t *swc_k;
    int extrapolated;
    double *water_sat, *dry, *area; /* per leaf: saturated water g, dry mass g, area cm² (NaN: none) */
    phc_pv_options analysis;        /* the conventions the leaves were analysed with */
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
    free(x->water_sat);
    free(x->dry);
    free(x->area);
    free(x);
}

static int pv_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err);
static int pv_fit_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err);
static int pv_name_series(phc_dataset *ds, phc_error *err);
static int pv_report_values(phc_dataset *ds, const double *p, char **json, phc_error *err)
{
    (void)p;
    return phc_pv_curve_values_json(ds, json, err);
}

const phc_dataset_ops phc_pv_curve_ops = {.kind = "pv_curve",
                                          .predict = phc_elasticity_predict,
                                          .predict_at = phc_elasticity_predict_at,
                                          .free_impl = phc_elasticity_impl_free,
                                          .report_section = pv_report_section,
                                          .fit_outputs = pv_fit_outputs,
                                          .report_values = pv_report_values,
                                          .name_series = pv_name_series};

static pv_extra *extra_of(const phc_dataset *ds)
{
    if (!ds || ds->ops != &phc_pv_curve_ops || !ds->impl)
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
    fprintf(f, "\nValues ± standard errors (linear regressions, delta method; a measured turgor loss point "
               "has none). ε is dP/dRWC on total RWC, ε_sym on symplastic RWC; the linear region is chosen by "
               "the breakpoint rule of model/pressure_volume.h.\n\n");
    fprintf(f, "| leaf | cut point: ψ (MPa), RWC (%%) | C_FT (MPa⁻¹) | C_TLP (MPa⁻¹) | RWC_tlp (%%) |\n");
    fprintf(f, "|---|---:|---:|---:|---:|\n");
    for (size_t i = 0; i < count; ++i) {
        const phc_pv_result *r = results[i];
        fprintf(f, "| %s | %.3f, %.2f |", labels[i], r->psi[r->cut], 100.0 * r->rwc[r->cut]);
        put_estimate(f, r->capacitance_ft, 4);
        put_estimate(f, r->capacitance_tlp, 4);
        const phc_pv_estimate pct = {100.0 * r->rwc_tlp.value, 100.0 * r->rwc_tlp.stderr_};
        put_estimate(f, pct, 2);
        fputc('\n', f);
    }
    fprintf(f, "\nCapacitances: slopes of RWC against ψ from the wettest point down to the cut point (C_FT) and "
               "from the cut point on (C_TLP).\n");
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
    if (rc)
        return rc;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) {
        free(table);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    fputs(table, f);
    if (x->extrapolated) {
        fprintf(f, "\nSaturated water mass extrapolated to ψ = 0 (ψ against leaf water over the wettest points):\n\n");
        for (size_t i = 0; i < x->count; ++i)
            fprintf(f, "- leaf %s: %.4f ± %.4f g (%zu points)\n", x->labels[i], x->swc[i], x->swc_se[i], x->swc_k[i]);
    }
    fprintf(f, "\nSaturated water content per dry mass (SWC) and the capacitance at full turgor per leaf area "
               "(C*_FT = C_FT · saturated water / 18 g mol⁻¹ / area; photosynthesis labels it g m⁻² MPa⁻¹ but "
               "divides by the molar mass of water, so it is mol m⁻² MPa⁻¹):\n\n");
    for (size_t i = 0; i < x->count; ++i) {
        fprintf(f, "- leaf %s: SWC %.4f g g⁻¹", x->labels[i], x->water_sat[i] / x->dry[i]);
        if (isfinite(x->area[i]))
            fprintf(f, ", C*_FT %.4f mol m⁻² MPa⁻¹ (area %.2f cm²)",
                    x->res[i]->capacitance_ft.value * x->water_sat[i] / 18.0 / (x->area[i] * 1e-4), x->area[i]);
        fputc('\n', f);
    }
    free(table);
    if (fclose(f) != 0 || !buf) {
        free(buf);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *out = buf;
    return PHC_OK;
}

/* {"value": v, "stderr": s, "unit": u} with nulls for NaN. */
static void put_json_estimate(FILE *f, const char *name, phc_pv_estimate e, const char *unit, int comma)
{
    fprintf(f, "\"%s\": {\"value\": ", name);
    if (isfinite(e.value))
        fprintf(f, "%.17g", e.value);
    else
        fprintf(f, "null");
    fprintf(f, ", \"stderr\": ");
    if (isfinite(e.stderr_))
        fprintf(f, "%.17g", e.stderr_);
    else
        fprintf(f, "null");
    fprintf(f, ", \"unit\": \"%s\"}%s", unit, comma ? ", " : "");
}

int phc_pv_curve_values_json(const phc_dataset *ds, char **out, phc_error *err)
{
    const pv_extra *x = extra_of(ds);
    *out = NULL;
    if (!x)
        return phc_error_set(err, PHC_ERR_INVALID, "data set '%s' is not a pv_curve data set",
                             ds && ds->name ? ds->name : "?");
    static const char *const rules[] = {"min_rss", "max_r2", "fixed"};
    const phc_pv_options *a = &x->analysis;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    fprintf(f, "{\"conventions\": {\"breakpoint\": \"%s\", \"tlp\": \"%s\", \"modulus_points\": \"%s\", "
               "\"cut\": \"%s\"}, \"leaves\": {",
            rules[a->rule], a->tlp == PHC_PV_TLP_MEASURED ? "measured" : "fitted",
            a->modulus_points == PHC_PV_MODULUS_SHARED_BREAK ? "shared_break" : "above_break",
            a->cut == PHC_PV_CUT_PHOTOSYNTHESIS ? "photosynthesis" : "region_start");
    for (size_t i = 0; i < x->count; ++i) {
        const phc_pv_result *r = x->res[i];
        const double swc = x->water_sat[i] / x->dry[i];
        const double cstar = r->capacitance_ft.value * x->water_sat[i] / 18.0 / (x->area[i] * 1e-4);
        fprintf(f, "%s\"", i ? ", " : "");
        for (const char *c = x->labels[i]; *c; ++c) /* leaf ids are table cells: escape quotes */
            fprintf(f, *c == '"' || *c == '\\' ? "\\%c" : "%c", *c);
        fprintf(f, "\": {\"points\": %zu, \"osmotic_points\": %zu, \"r2_osmotic\": %.17g, ", r->n, r->n_osmotic,
                r->r2_osmotic);
        put_json_estimate(f, "pi_o", r->pi_o, "MPa", 1);
        put_json_estimate(f, "psi_tlp", r->psi_tlp, "MPa", 1);
        put_json_estimate(f, "rwc_tlp", r->rwc_tlp, "1", 1);
        put_json_estimate(f, "rwc_tlp_percent", (phc_pv_estimate){100 * r->rwc_tlp.value, 100 * r->rwc_tlp.stderr_},
                          "%", 1);
        put_json_estimate(f, "epsilon", r->epsilon, "MPa", 1);
        put_json_estimate(f, "epsilon_sym", r->epsilon_sym, "MPa", 1);
        put_json_estimate(f, "apoplastic_fraction", r->apoplastic_fraction, "1", 1);
        put_json_estimate(f, "c_ft", r->capacitance_ft, "MPa-1", 1);
        put_json_estimate(f, "c_tlp", r->capacitance_tlp, "MPa-1", 1);
        put_json_estimate(f, "swc", (phc_pv_estimate){swc, NAN}, "g g-1", 1);
        put_json_estimate(f, "c_ft_star", (phc_pv_estimate){cstar, NAN}, "mol m-2 MPa-1", 1);
        put_json_estimate(f, "saturated_water", (phc_pv_estimate){x->water_sat[i], x->swc_se[i]}, "g", 0);
        fprintf(f, "}");
    }
    fprintf(f, "}}");
    if (fclose(f) != 0 || !buf) {
        free(buf);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *out = buf;
    return PHC_OK;
}

/* ---- building a data set ------------------------------------------------- */

phc_pv_curve_options phc_pv_curve_options_default(void)
{
    const phc_pv_mass none = {NULL, NAN};
    phc_pv_curve_options o = {0};
    o.bag_mass = o.dry_mass = o.saturated_mass = o.leaf_area = none;
    o.analysis = phc_pv_options_default();
    return o;
}

#define WHERE(key) phc_origin_key(b->opt->origin, "pv_curve", key).text

/* What phc_pv_curve_new works on, freed in one place (pv_build_free). */
typedef struct pv_build {
    const phc_table *t;
    const phc_pv_curve_options *opt;
    const char *path;  /* the table's source */
    const char *unit;  /* of psi, as given */
    double to_mpa;     /* psi in that unit -> MPa */
    size_t n;          /* rows */
    double *psi, *fresh, *bag, *dry, *sat; /* per row: MPa (after check_rows), g; bag, sat may be NULL */
    double *area;      /* per row: leaf area, cm², or NULL */
    size_t *gid;       /* per row: its leaf, an index into gname */
    const char **gname; /* the n_groups leaf ids, in order of appearance */
    size_t n_groups;
    int each;          /* one logistic per leaf */
    size_t only;       /* the one leaf chosen, or (size_t)-1: all */
    size_t n_leaves;   /* analysed */
    size_t *rows;      /* scratch: the rows of one leaf */
    double *lpsi, *lrwc, *lwater; /* scratch: one leaf's points */
    pv_extra *x;       /* the analyses, handed to the data set */
} pv_build;

static void pv_build_free(pv_build *b)
{
    pv_extra_free(b->x);
    free(b->psi);
    free(b->fresh);
    free(b->bag);
    free(b->dry);
    free(b->sat);
    free(b->area);
    free(b->gid);
    free(b->gname);
    free(b->rows);
    free(b->lpsi);
    free(b->lrwc);
    free(b->lwater);
}

static int mass_given(const phc_pv_mass *m)
{
    return m->column || !isnan(m->value);
}

/* The options alone, before any data: what is required, psi_unit, the
 * breakpoint rule, leaf without group, the masses given, sigma. */
static int check_options(pv_build *b, phc_error *err)
{
    const phc_pv_curve_options *o = b->opt;
    if (!o->psi || !o->psi[0])
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'psi' is required", WHERE(NULL));
    if (!o->fresh_mass || !o->fresh_mass[0])
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'fresh_mass' is required", WHERE(NULL));
    b->unit = o->psi_unit ? o->psi_unit : "MPa";
    if (strcasecmp(b->unit, "MPa") == 0)
        b->to_mpa = 1.0;
    else if (strcasecmp(b->unit, "bar") == 0)
        b->to_mpa = 0.1;
    else if (strcasecmp(b->unit, "kPa") == 0)
        b->to_mpa = 1e-3;
    else
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'psi_unit': expected MPa, bar or kPa, found '%s'",
                             WHERE("psi_unit"), b->unit);
    if (o->analysis.min_points < 3)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: analysis.min_points must be at least 3, found %zu",
                             WHERE(NULL), o->analysis.min_points);
    if (o->analysis.rule == PHC_PV_BREAK_FIXED && o->analysis.n_osmotic < o->analysis.min_points)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'breakpoint': expected a whole number of points >= %zu, "
                             "found %zu", WHERE("breakpoint"), o->analysis.min_points, o->analysis.n_osmotic);
    if (o->leaf && !o->group)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'leaf' needs key 'group' (the column of leaf ids)",
                             WHERE("leaf"));
    if (!mass_given(&o->dry_mass))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'dry_mass' is required (a column or a number in g)",
                             WHERE(NULL));
    if (!mass_given(&o->saturated_mass) && !o->extrapolate_saturation)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'saturated_mass' is required (a column or a number in g, "
                             "or extrapolate_saturation)", WHERE(NULL));
    if (mass_given(&o->saturated_mass) && o->extrapolate_saturation)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'saturated_mass': give a mass or extrapolate, not both",
                             WHERE("saturated_mass"));
    if (!(o->sigma >= 0 && isfinite(o->sigma)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': expected a positive number (MPa), found %g",
                             WHERE("sigma"), o->sigma);
    if (!o->leaf_area.column && !isnan(o->leaf_area.value) && !(o->leaf_area.value > 0 && isfinite(o->leaf_area.value)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'leaf_area': the area must be positive (cm2), found %g",
                             WHERE("leaf_area"), o->leaf_area.value);
    return PHC_OK;
}

/* A column named by option `key` that the table lacks. */
static int need_column(const pv_build *b, const char *key, const char *name, phc_error *err)
{
    if (phc_table_find(b->t, name) >= 0)
        return PHC_OK;
    char what[64];
    snprintf(what, sizeof what, "key '%s':", key);
    return phc_unknown_column_at(WHERE(key), what, name, b->t, err);
}

/* A mass option as n values in *values (NULL when not given). */
static int mass_values(const pv_build *b, const char *key, const phc_pv_mass *m, double **values, phc_error *err)
{
    int rc;
    *values = NULL;
    if (m->column) {
        if ((rc = need_column(b, key, m->column, err)))
            return rc;
        return phc_table_column_numbers(b->t, m->column, values, err);
    }
    if (isnan(m->value))
        return PHC_OK;
    if (!(m->value >= 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s': a mass must not be negative, found %g", WHERE(key),
                             key, m->value);
    if (!isfinite(m->value))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s': a mass must be finite, found %g", WHERE(key), key,
                             m->value);
    if (!(*values = malloc((b->n ? b->n : 1) * sizeof **values)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < b->n; ++i)
        (*values)[i] = m->value;
    return PHC_OK;
}

/* The columns the options name, as numbers per row. */
static int read_columns(pv_build *b, phc_error *err)
{
    const phc_pv_curve_options *o = b->opt;
    int rc;
    if (b->n == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one",
                             b->path);
    if ((rc = need_column(b, "psi", o->psi, err)) || (rc = need_column(b, "fresh_mass", o->fresh_mass, err)) ||
        (o->group && (rc = need_column(b, "group", o->group, err))) ||
        (rc = phc_table_column_numbers(b->t, o->psi, &b->psi, err)) ||
        (rc = phc_table_column_numbers(b->t, o->fresh_mass, &b->fresh, err)) ||
        (rc = mass_values(b, "bag_mass", &o->bag_mass, &b->bag, err)) ||
        (rc = mass_values(b, "dry_mass", &o->dry_mass, &b->dry, err)) ||
        (rc = mass_values(b, "saturated_mass", &o->saturated_mass, &b->sat, err)) ||
        (rc = mass_values(b, "leaf_area", &o->leaf_area, &b->area, err)))
        return rc;
    return PHC_OK;
}

/* Row checks, with file and line; psi converted to MPa. */
static int check_rows(pv_build *b, phc_error *err)
{
    for (size_t i = 0; i < b->n; ++i) {
        const size_t line = phc_table_row_line(b->t, i);
        if (b->psi[i] > 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: column '%s': water potential must be negative, found %g %s "
                                 "(enter pressure-chamber balance pressures with a minus sign)",
                                 b->path, line, b->opt->psi, b->psi[i], b->unit);
        if (b->psi[i] == 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: column '%s': water potential 0 leaves 1/psi undefined; "
                                 "a pressure-volume point needs a negative potential", b->path, line, b->opt->psi);
        b->psi[i] *= b->to_mpa;
        const double leafm = b->fresh[i] - (b->bag ? b->bag[i] : 0);
        if (!(leafm > b->dry[i]))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: leaf mass %g g (fresh%s) is not above the dry mass %g g",
                                 b->path, line, leafm, b->bag ? " minus bag" : "", b->dry[i]);
        if (b->sat && !(b->sat[i] > b->dry[i]))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: saturated mass %g g is not above the dry mass %g g",
                                 b->path, line, b->sat[i], b->dry[i]);
    }
    return PHC_OK;
}

/* The leaf `leaf` names among the group column's ids: b->only, or PHC_ERR_INPUT
 * listing the ids. */
static int choose_leaf(pv_build *b, const char *leaf, phc_error *err)
{
    for (size_t k = 0; k < b->n_groups; ++k)
        if (strcmp(b->gname[k], leaf) == 0)
            b->only = k;
    if (b->only != (size_t)-1)
        return PHC_OK;
    char list[400] = "";
    for (size_t k = 0; k < b->n_groups && k < 20; ++k) {
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s'%s'", k ? ", " : "", b->gname[k]);
    }
    const char *near = phc_suggest(leaf, b->gname, b->n_groups);
    return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'leaf': '%s' is not a value of column '%s' in %s "
                         "(values: %s%s)%s%s%s",
                         WHERE("leaf"), leaf, b->opt->group, b->path, list, b->n_groups > 20 ? ", ..." : "",
                         near ? "; did you mean '" : "", near ? near : "", near ? "'?" : "");
}

/* The leaves: the group column's ids (one leaf "all" without one), and which
 * of them the options choose; the scratch arrays and the analyses' home. */
static int find_leaves(pv_build *b, phc_error *err)
{
    const size_t n = b->n;
    const char *leaf = b->opt->leaf;
    int rc;
    if (!(b->gid = calloc(n, sizeof *b->gid)) || !(b->gname = calloc(n, sizeof *b->gname)) ||
        !(b->rows = malloc(n * sizeof *b->rows)) || !(b->lpsi = malloc(n * sizeof *b->lpsi)) ||
        !(b->lrwc = malloc(n * sizeof *b->lrwc)) || !(b->lwater = malloc(n * sizeof *b->lwater)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    const long gcol = b->opt->group ? phc_table_find(b->t, b->opt->group) : -1;
    for (size_t i = 0; i < n; ++i) {
        const char *g = gcol >= 0 ? phc_table_cell(b->t, i, (size_t)gcol) : "all";
        size_t k = 0;
        while (k < b->n_groups && strcmp(b->gname[k], g) != 0)
            ++k;
        if (k == b->n_groups)
            b->gname[b->n_groups++] = g;
        b->gid[i] = k;
    }
    b->only = (size_t)-1;
    if (gcol >= 0) {
        if (!leaf && b->n_groups > 1)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: column '%s' of %s holds %zu leaves ('%s', '%s', ...); choose one with "
                                 "'leaf: <id>', or 'leaf: each' or 'leaf: pooled'",
                                 WHERE("group"), b->opt->group, b->path, b->n_groups, b->gname[0], b->gname[1]);
        if (leaf && strcmp(leaf, "each") == 0)
            b->each = 1;
        else if (leaf && strcmp(leaf, "pooled") != 0 && (rc = choose_leaf(b, leaf, err)))
            return rc;
    }
    const size_t nl = b->n_leaves = b->only == (size_t)-1 ? b->n_groups : 1;
    pv_extra *x = b->x = calloc(1, sizeof *x);
    if (!x || !(x->labels = calloc(nl, sizeof *x->labels)) || !(x->res = calloc(nl, sizeof *x->res)) ||
        !(x->swc = malloc(nl * sizeof *x->swc)) || !(x->swc_se = malloc(nl * sizeof *x->swc_se)) ||
        !(x->swc_k = calloc(nl, sizeof *x->swc_k)) || !(x->water_sat = malloc(nl * sizeof *x->water_sat)) ||
        !(x->dry = malloc(nl * sizeof *x->dry)) || !(x->area = malloc(nl * sizeof *x->area)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    x->extrapolated = b->opt->extrapolate_saturation;
    return PHC_OK;
}

/* The rows of analysed leaf L in b->rows; returns their count. */
static size_t leaf_rows(pv_build *b, size_t L)
{
    const size_t g = b->only == (size_t)-1 ? L : b->only;
    size_t m = 0;
    for (size_t i = 0; i < b->n; ++i)
        if (b->gid[i] == g)
            b->rows[m++] = i;
    return m;
}

/* The pressure-volume analysis of leaf L (model/pressure_volume.h) into
 * b->x, with its saturated water extrapolated when asked. */
static int analyse_leaf(pv_build *b, size_t L, phc_error *err)
{
    const phc_pv_options *opt = &b->opt->analysis;
    const size_t g = b->only == (size_t)-1 ? L : b->only, m = leaf_rows(b, L);
    const size_t *rows = b->rows;
    const char *id = b->gname[g];
    pv_extra *x = b->x;
    int rc;
    x->count = L + 1;
    if (!(x->labels[L] = strdup(id)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    const size_t first = phc_table_row_line(b->t, rows[0]);
    const size_t need = 2 * opt->min_points;
    if (m < need)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: leaf '%s' has %zu point%s; a pressure-volume analysis needs at least %zu "
                             "(%zu on each side of the turgor loss point)",
                             b->path, first, id, m, m == 1 ? "" : "s", need, opt->min_points);
    if (opt->rule == PHC_PV_BREAK_FIXED && (opt->n_osmotic > m - opt->min_points))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'breakpoint': %zu linear points leave fewer than %zu "
                             "above the turgor loss point in leaf '%s' (%zu points)",
                             WHERE("breakpoint"), opt->n_osmotic, opt->min_points, id, m);
    for (size_t j = 0; j < m; ++j) {
        const size_t i = rows[j];
        b->lpsi[j] = b->psi[i];
        b->lwater[j] = b->fresh[i] - (b->bag ? b->bag[i] : 0) - b->dry[i];
    }
    x->swc[L] = x->swc_se[L] = NAN;
    x->dry[L] = b->dry[rows[0]];
    x->area[L] = b->area ? b->area[rows[0]] : NAN;
    if (b->area && !(x->area[L] > 0 && isfinite(x->area[L])))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: leaf '%s': key 'leaf_area': the area must be positive "
                             "(cm2), found %g", b->path, first, id, x->area[L]);
    if (x->extrapolated) {
        if ((rc = phc_pv_extrapolate_saturation(b->lpsi, b->lwater, m, &x->swc[L], &x->swc_se[L], &x->swc_k[L], err)))
            return phc_error_prefix(err, rc, "%s:%zu: leaf '%s'", b->path, first, id);
        for (size_t j = 0; j < m; ++j)
            b->lrwc[j] = b->lwater[j] / x->swc[L];
    } else {
        for (size_t j = 0; j < m; ++j)
            b->lrwc[j] = b->lwater[j] / (b->sat[rows[j]] - b->dry[rows[j]]);
    }
    for (size_t j = 0; j < m; ++j)
        for (size_t q = 0; q < j; ++q)
            if (b->lrwc[q] == b->lrwc[j])
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: leaf '%s': same relative water content (%g) as line %zu; masses "
                                     "must differ between points", b->path, phc_table_row_line(b->t, rows[j]), id,
                                     b->lrwc[j], phc_table_row_line(b->t, rows[q]));
    x->water_sat[L] = x->extrapolated ? x->swc[L] : b->sat[rows[0]] - b->dry[rows[0]];
    x->analysis = *opt;
    if ((rc = phc_pv_analyse(b->lpsi, b->lrwc, m, opt, &x->res[L], err)))
        return phc_error_prefix(err, rc, "%s:%zu: leaf '%s'", b->path, first, id);
    return PHC_OK;
}

/* The elasticity data set over every analysed leaf's moduli; takes b->x. */
static int moduli_dataset(pv_build *b, phc_dataset **out, phc_error *err)
{
    pv_extra *x = b->x;
    size_t n_obs = 0;
    int rc;
    for (size_t L = 0; L < b->n_leaves; ++L)
        n_obs += x->res[L]->n_modulus;
    if ((rc = phc_elasticity_dataset_new(&phc_pv_curve_ops, n_obs, b->each ? b->n_leaves : 1,
                                         b->each ? (const char *const *)x->labels : NULL, 1, out, err)))
        return rc;
    /* the moduli are in MPa (psi_unit converts the potentials), so are the
     * logistic's bounds (parameter_units.h converts a user's bar or kPa);
     * kappa and chi0 are on RWC, dimensionless */
    phc_dataset *ds = *out;
    phc_elasticity_impl *impl = ds->impl;
    size_t o = 0;
    for (size_t L = 0; L < b->n_leaves; ++L) {
        leaf_rows(b, L);
        const phc_pv_result *r = x->res[L];
        for (size_t j = 0; j < r->n_modulus; ++j, ++o) {
            ds->x[o] = r->modulus_rwc[j];
            ds->y[o] = r->modulus[j];
            ds->data_lines[o] = phc_table_row_line(b->t, b->rows[r->order[j]]);
            impl->block[o] = b->each ? L : 0;
        }
    }
    impl->extra = x;
    impl->free_extra = pv_extra_free;
    b->x = NULL;
    return PHC_OK;
}

int phc_pv_curve_new(const phc_table *table, const phc_pv_curve_options *options, phc_dataset **out,
                     phc_error *err)
{
    *out = NULL;
    if (!table || !options)
        return phc_error_set(err, PHC_ERR_INVALID, "pv_curve: a table and options are required");
    pv_build build = {.t = table, .opt = options, .path = phc_table_source(table), .n = phc_table_rows(table)};
    pv_build *b = &build;
    phc_dataset *ds = NULL;
    int rc;
    if ((rc = check_options(b, err)) || (rc = read_columns(b, err)) || (rc = check_rows(b, err)) ||
        (rc = find_leaves(b, err)))
        goto fail;
    for (size_t L = 0; L < b->n_leaves; ++L)
        if ((rc = analyse_leaf(b, L, err)))
            goto fail;
    if ((rc = moduli_dataset(b, &ds, err)))
        goto fail;
    if (options->sigma > 0) {
        if (!(ds->sigma = malloc((ds->n ? ds->n : 1) * sizeof *ds->sigma))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t i = 0; i < ds->n; ++i)
            ds->sigma[i] = options->sigma;
    }
    ds->x_label = strdup("relative water content (RWC)");
    ds->y_label = strdup("bulk modulus dP/dRWC (MPa)");
    ds->data_file = strdup(b->path);
    if (!ds->x_label || !ds->y_label || !ds->data_file) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->config_line = phc_origin_line(options->origin, NULL);
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    phc_dataset_free(ds);
    pv_build_free(b);
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
