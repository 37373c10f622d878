/* Harvested plants for root_shoot data sets: see harvest.h. */
#include "fit/costs/harvest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/source_file.h"
#include "measurements/baad.h"
#include "measurements/units.h"

#define WHERE(origin, key) phc_origin_key(origin, "root_shoot", key).text

void phc_harvest_free(phc_harvest *h)
{
    if (!h)
        return;
    free(h->diameter);
    free(h->root_mass);
    free(h->shoot_mass);
    free(h->age);
    free(h->line);
    free(h->file);
    free(h->source);
    free(h->notes);
    for (size_t i = 0; h->inputs && i < h->n_inputs; ++i)
        free(h->inputs[i]);
    free(h->inputs);
    free(h);
}

/* Checks one harvested plant's numbers (a bad value is an input error). */
static int check_row(const char *path, size_t line, double d, double root, double shoot,
                     phc_error *err)
{
    if (!(d > 0) || !isfinite(d))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: the basal diameter must be a positive number, found %g",
                             path, line, d);
    if (!(root > 0) || !isfinite(root))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: the root mass must be a positive number, found %g", path,
                             line, root);
    if (!(shoot > 0) || !isfinite(shoot))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: the shoot mass must be a positive number, found %g", path,
                             line, shoot);
    return PHC_OK;
}

int phc_harvest_check(const phc_harvest *h, phc_error *err)
{
    const char *file = h && h->file ? h->file : "plants";
    if (!h || !h->n || !h->diameter || !h->root_mass || !h->shoot_mass)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: no harvested plants", file);
    for (size_t i = 0; i < h->n; ++i) {
        int rc = check_row(file, h->line ? h->line[i] : i + 2, h->diameter[i], h->root_mass[i],
                           h->shoot_mass[i], err);
        if (rc)
            return rc;
    }
    return PHC_OK;
}

/* ---- the plants as they are read --------------------------------------------- */

static int rows_push(phc_harvest *r, size_t *cap_io, double d, double root, double shoot, double age,
                     size_t line)
{
    if (r->n == *cap_io) {
        size_t cap = *cap_io ? 2 * *cap_io : 64;
        double *a = realloc(r->diameter, cap * sizeof *a);
        if (a) r->diameter = a;
        double *b = realloc(r->root_mass, cap * sizeof *b);
        if (b) r->root_mass = b;
        double *c = realloc(r->shoot_mass, cap * sizeof *c);
        if (c) r->shoot_mass = c;
        double *e = realloc(r->age, cap * sizeof *e);
        if (e) r->age = e;
        size_t *l = realloc(r->line, cap * sizeof *l);
        if (l) r->line = l;
        if (!a || !b || !c || !e || !l) return -1;
        *cap_io = cap;
    }
    r->diameter[r->n] = d;
    r->root_mass[r->n] = root;
    r->shoot_mass[r->n] = shoot;
    r->age[r->n] = age;
    r->line[r->n] = line;
    r->n++;
    return 0;
}

/* ---- a table ------------------------------------------------------------------- */

/* The unit conversions of the columns given (to m, g and d). */
typedef struct column_units {
    phc_unit_conversion d, root, shoot, leaf, stem, age;
} column_units;

static int table_units(const phc_harvest_columns *c, column_units *u, phc_error *err)
{
    static const phc_unit_conversion one = {1, 0};
    const phc_origin *o = c->origin;
    char where[4300];
    int rc;
    *u = (column_units){one, one, one, one, one, one};
    phc_units *units = phc_units_new(err);
    if (!units) return err->status;
    snprintf(where, sizeof where, "%s: diameter unit", WHERE(o, "diameter"));
    if ((rc = phc_units_conversion(units, c->diameter_unit ? c->diameter_unit : "mm", "m", where, &u->d, err)))
        goto done;
    snprintf(where, sizeof where, "%s: root mass unit", WHERE(o, "root_mass"));
    if ((rc = phc_units_conversion(units, c->root_mass_unit ? c->root_mass_unit : "g", "g", where, &u->root, err)))
        goto done;
    if (c->shoot_mass) {
        snprintf(where, sizeof where, "%s: shoot mass unit", WHERE(o, "shoot_mass"));
        if ((rc = phc_units_conversion(units, c->shoot_mass_unit ? c->shoot_mass_unit : "g", "g", where, &u->shoot,
                                       err)))
            goto done;
    } else {
        snprintf(where, sizeof where, "%s: leaf mass unit", WHERE(o, "leaf_mass"));
        if ((rc = phc_units_conversion(units, c->leaf_mass_unit ? c->leaf_mass_unit : "g", "g", where, &u->leaf,
                                       err)))
            goto done;
        snprintf(where, sizeof where, "%s: stem mass unit", WHERE(o, "stem_mass"));
        if ((rc = phc_units_conversion(units, c->stem_mass_unit ? c->stem_mass_unit : "g", "g", where, &u->stem,
                                       err)))
            goto done;
    }
    if (c->age) {
        snprintf(where, sizeof where, "%s: age unit", WHERE(o, "age"));
        if ((rc = phc_units_conversion(units, c->age_unit ? c->age_unit : "d", "d", where, &u->age, err)))
            goto done;
    }
done:
    phc_units_free(units);
    return rc;
}

/* Column `name`, named by option `key` when given, is in the table. */
static int need_column(const phc_table *t, const phc_origin *o, const char *key, const char *name, phc_error *err)
{
    if (!name || phc_table_find(t, name) >= 0)
        return PHC_OK;
    char what[64];
    snprintf(what, sizeof what, "key '%s':", key);
    return phc_unknown_column_at(WHERE(o, key), what, name, t, err);
}

/* The numbers of the selected rows: dv, rv and (sv or lv and tv), av. */
typedef struct table_numbers {
    double *d, *root, *shoot, *leaf, *stem, *age;
} table_numbers;

static int table_numbers_read(const phc_table *t, const phc_harvest_columns *c, const size_t *sel, size_t ns,
                              table_numbers *v, phc_error *err)
{
    int rc = phc_table_column_numbers_rows(t, c->diameter, sel, ns, &v->d, err);
    if (!rc) rc = phc_table_column_numbers_rows(t, c->root_mass, sel, ns, &v->root, err);
    if (!rc && c->shoot_mass) rc = phc_table_column_numbers_rows(t, c->shoot_mass, sel, ns, &v->shoot, err);
    if (!rc && !c->shoot_mass) rc = phc_table_column_numbers_rows(t, c->leaf_mass, sel, ns, &v->leaf, err);
    if (!rc && !c->shoot_mass) rc = phc_table_column_numbers_rows(t, c->stem_mass, sel, ns, &v->stem, err);
    if (!rc && c->age) rc = phc_table_column_numbers_rows(t, c->age, sel, ns, &v->age, err);
    return rc;
}

/* Checks what the columns name; PHC_OK when the table has them all. */
static int table_columns(const phc_table *t, const phc_harvest_columns *c, long *selk, phc_error *err)
{
    const phc_origin *o = c->origin;
    int rc;
    if (!c->diameter || !c->root_mass)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s' is required", WHERE(o, NULL),
                             c->diameter ? "root_mass" : "diameter");
    if ((rc = need_column(t, o, "diameter", c->diameter, err)) ||
        (rc = need_column(t, o, "root_mass", c->root_mass, err)) ||
        (rc = need_column(t, o, "shoot_mass", c->shoot_mass, err)) ||
        (!c->shoot_mass && (rc = need_column(t, o, "leaf_mass", c->leaf_mass, err))) ||
        (!c->shoot_mass && (rc = need_column(t, o, "stem_mass", c->stem_mass, err))) ||
        (rc = need_column(t, o, "age", c->age, err)))
        return rc;
    *selk = -1;
    if (c->select_column && (*selk = phc_table_find(t, c->select_column)) < 0)
        return phc_unknown_column_at(WHERE(o, "select"), "select", c->select_column, t, err);
    if (c->select_column && !c->select_value)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: select: give the value the column must equal",
                             WHERE(o, "select"));
    return PHC_OK;
}

/* Names the data for the report: "`t.csv`, 12 harvested plants with light = L". */
static int table_source(phc_harvest *h, const char *path, const phc_harvest_columns *c, phc_error *err)
{
    const char *selc = c->select_column, *selv = c->select_value;
    size_t cap = strlen(path) + 256;
    h->source = malloc(cap);
    h->file = strdup(path);
    if (!h->source || !h->file)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    snprintf(h->source, cap, "`%s`, %zu harvested plants%s%s%s%s", path, h->n, selc ? " with " : "",
             selc ? selc : "", selc ? " = " : "", selc ? selv : "");
    return PHC_OK;
}

int phc_harvest_from_table(const phc_table *t, const phc_harvest_columns *c, phc_harvest **out, phc_error *err)
{
    const phc_origin *o = c->origin;
    const char *path = phc_table_source(t), *selc = c->select_column, *selv = c->select_value;
    table_numbers v = {0};
    column_units u;
    size_t cap = 0, *sel = NULL;
    long selk = -1;
    int rc;
    *out = NULL;
    if (!c->shoot_mass && (!c->leaf_mass || !c->stem_mass))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: root_shoot data set: missing key 'shoot_mass' (or both "
                             "'leaf_mass' and 'stem_mass')",
                             WHERE(o, NULL));
    if ((rc = table_units(c, &u, err)) || (rc = table_columns(t, c, &selk, err)))
        return rc;
    phc_harvest *h = calloc(1, sizeof *h);
    if (!h) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    /* Only the selected rows need numbers. */
    size_t nt = phc_table_rows(t), ns = 0;
    sel = malloc((nt ? nt : 1) * sizeof *sel);
    if (!sel) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto done; }
    for (size_t r = 0; r < nt; ++r)
        if (selk < 0 || strcmp(phc_table_cell(t, r, (size_t)selk), selv) == 0) sel[ns++] = r;
    rc = table_numbers_read(t, c, sel, ns, &v, err);
    for (size_t i = 0; !rc && i < ns; ++i) {
        size_t line = phc_table_row_line(t, sel[i]);
        double d = phc_unit_apply(u.d, v.d[i]), root = phc_unit_apply(u.root, v.root[i]);
        double shoot = c->shoot_mass ? phc_unit_apply(u.shoot, v.shoot[i])
                                     : phc_unit_apply(u.leaf, v.leaf[i]) + phc_unit_apply(u.stem, v.stem[i]);
        if ((rc = check_row(path, line, d, root, shoot, err))) break;
        if (rows_push(h, &cap, d, root, shoot, v.age ? phc_unit_apply(u.age, v.age[i]) : NAN, line))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    if (!rc && h->n == 0)
        rc = selc ? phc_error_set(err, PHC_ERR_INPUT, "%s: select: no row of %s has %s = '%s'",
                                  WHERE(o, "select"), path, selc, selv)
                  : phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one",
                                  path);
    if (!rc) rc = table_source(h, path, c, err);
done:
    free(sel);
    free(v.d); free(v.root); free(v.shoot); free(v.leaf); free(v.stem); free(v.age);
    if (rc) phc_harvest_free(h);
    else *out = h;
    return rc;
}

/* ---- a BAAD study folder --------------------------------------------------------- */

/* What the rows of one species came to, for the notes and messages. */
typedef struct baad_counts {
    size_t species, select, missing, excluded;
    size_t derived_d, derived_rt, derived_so, aged; /* of the plants used */
} baad_counts;

/* The plants of the species: usable rows into h, the others counted and
 * (the suspicious ones) listed in nf. */
static int baad_rows(const phc_baad_study *st, const char *path, const phc_harvest_baad_options *b,
                     phc_harvest *h, FILE *nf, baad_counts *k, phc_error *err)
{
    const char *selc = b->select_column, *selv = b->select_value;
    size_t cap = 0;
    int rc = PHC_OK;
    for (size_t i = 0; !rc && i < phc_baad_rows(st); ++i) {
        const phc_baad_row *r = phc_baad_row_at(st, i);
        if (!r->species || strcmp(r->species, b->species)) continue;
        k->species++;
        if (selc) {
            const char *v = phc_baad_raw(st, i, selc);
            if (!v) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s: select: '%s' is not a column of %s/data.csv",
                                   WHERE(b->origin, "select"), selc, path);
                break;
            }
            if (strcmp(v, selv)) continue;
        }
        k->select++;
        if (!isfinite(r->d_ba) || !isfinite(r->m_rt) || !isfinite(r->m_so)) {
            k->missing++;
            continue;
        }
        if (r->flag == PHC_BAAD_INVALID) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s/data.csv:%zu: %s", path, r->line,
                               r->flag_reason ? r->flag_reason : "invalid row");
            break;
        }
        if (r->flag == PHC_BAAD_SUSPICIOUS) {
            fprintf(nf, "- data.csv:%zu %s: %s\n", r->line,
                    b->keep_suspicious ? "kept although suspicious" : "excluded as suspicious",
                    r->flag_reason ? r->flag_reason : "");
            if (!b->keep_suspicious) { k->excluded++; continue; }
        }
        if ((rc = check_row(path, r->line, r->d_ba, r->m_rt * 1e3, r->m_so * 1e3, err))) break;
        if (rows_push(h, &cap, r->d_ba, r->m_rt * 1e3, r->m_so * 1e3,
                      isfinite(r->age) ? r->age * 365.25 : NAN, r->line))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        k->derived_d += (size_t)r->d_ba_derived;
        k->derived_rt += (size_t)r->m_rt_derived;
        k->derived_so += (size_t)r->m_so_derived;
        k->aged += (size_t)isfinite(r->age);
    }
    return rc;
}

/* A species that is not in the study: name the ones that are. */
static int baad_no_species(const phc_baad_study *st, const char *path, const phc_harvest_baad_options *b,
                           phc_error *err)
{
    const char **names = NULL;
    size_t ns = phc_baad_species(st, &names);
    char list[512] = "";
    for (size_t k = 0; k < ns; ++k) {
        strncat(list, names[k], sizeof list - strlen(list) - 3);
        if (k + 1 < ns) strncat(list, ", ", sizeof list - strlen(list) - 1);
    }
    return phc_error_set(err, PHC_ERR_INPUT, "%s: species '%s' is not in %s (it has: %s)",
                         WHERE(b->origin, "species"), b->species, path, list);
}

/* The report's sentence on the data, the data file, the files read. */
static int baad_describe(const phc_baad_study *st, const char *path, const phc_harvest_baad_options *b,
                         const baad_counts *k, phc_harvest *h, phc_error *err)
{
    const char *selc = b->select_column, *selv = b->select_value;
    size_t cap = strlen(path) + strlen(b->species) + 256;
    h->source = malloc(cap);
    h->file = phc_join_path(path, "data.csv");
    if (!h->source || !h->file) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    snprintf(h->source, cap,
             "BAAD study `%s` (%s), *%s*: %zu plants used of %zu%s%s%s%s, %zu excluded "
             "as suspicious, %zu without diameter or masses",
             phc_baad_name(st), path, b->species, h->n, k->species, selc ? ", those with " : "",
             selc ? selc : "", selc ? " = " : "", selc ? selv : "", k->excluded, k->missing);
    double shift = phc_baad_site_shift(st);
    if (isfinite(shift) && h->notes) {
        size_t l = strlen(h->notes);
        char *nn = realloc(h->notes, l + 160);
        if (nn) {
            h->notes = nn;
            snprintf(h->notes + l, 160, "- The study's site coordinates were corrected by BAAD's "
                                        "dataNew.csv by %.0f m.\n", shift);
        }
    }
    const char *const *read_files = NULL;
    size_t m = phc_baad_inputs(st, &read_files);
    if (!(h->inputs = calloc(m ? m : 1, sizeof *h->inputs)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < m; ++i, h->n_inputs = i)
        if (!(h->inputs[i] = strdup(read_files[i])))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    h->n_inputs = m;
    return PHC_OK;
}

int phc_harvest_read_baad(const char *path, const phc_harvest_baad_options *b, phc_harvest **out, phc_error *err)
{
    phc_baad_study *st = NULL;
    baad_counts k = {0};
    int rc;
    *out = NULL;
    if (!b->species)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'species' is required", WHERE(b->origin, NULL));
    if (b->select_column && !b->select_value)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: select: give the value the column must equal",
                             WHERE(b->origin, "select"));
    if ((rc = phc_baad_read(path, &st, err)))
        return phc_error_prefix(err, rc, "%s: key 'baad'", WHERE(b->origin, "baad"));
    phc_harvest *h = calloc(1, sizeof *h);
    char *nb = NULL;
    size_t nlen = 0;
    FILE *nf = h ? open_memstream(&nb, &nlen) : NULL;
    rc = nf ? baad_rows(st, path, b, h, nf, &k, err) : phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (nf) {
        const char *const *w = NULL;
        size_t nw = phc_baad_warnings(st, &w);
        if (k.missing)
            fprintf(nf, "- %zu rows of %s lack a basal diameter, root or shoot mass and are not used.\n",
                    k.missing, b->species);
        if (k.derived_d)
            fprintf(nf, "- %zu of the plants used have no basal diameter in the study; it is derived "
                        "from the stem area at base, d.ba = 2 sqrt(a.stba / pi).\n", k.derived_d);
        if (k.derived_rt)
            fprintf(nf, "- %zu of the plants used have their root mass as fine + coarse roots "
                        "(m.rf + m.rc).\n", k.derived_rt);
        if (k.derived_so)
            fprintf(nf, "- %zu of the plants used have their shoot mass as stem + leaves (m.st + m.lf).\n",
                    k.derived_so);
        if (k.aged)
            fprintf(nf, "- %zu of the plants used have an age (the study's age column).\n", k.aged);
        for (size_t i = 0; i < nw; ++i)
            fprintf(nf, "- Reading the study: %s\n", w[i]);
        fclose(nf);
    }
    if (h) { h->notes = nb; nb = NULL; }
    if (!rc && k.species == 0)
        rc = baad_no_species(st, path, b, err);
    if (!rc && h->n == 0 && phc_baad_lacks(st))
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: %s cannot give root:shoot data: %s",
                           WHERE(b->origin, "baad"), path, phc_baad_lacks(st));
    if (!rc && h->n == 0)
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s: no usable rows of '%s' in %s (%zu rows, %zu selected, %zu "
                           "without diameter or masses, %zu excluded as suspicious)",
                           WHERE(b->origin, NULL), b->species, path, k.species, k.select, k.missing, k.excluded);
    if (!rc)
        rc = baad_describe(st, path, b, &k, h, err);
    free(nb);
    phc_baad_free(st);
    if (rc) phc_harvest_free(h);
    else *out = h;
    return rc;
}
