/* `root_shoot` data sets: see root_shoot.h. */
#include "fit/costs/root_shoot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "fit/costs/soil_setup.h"
#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */
#include "fit/config/soil_setup_yaml.h" /* until this kind is YAML-free */
#include "fit/growth_outputs.h"
#include "measurements/baad.h"
#include "measurements/table.h"
#include "measurements/units.h"
#include "model/growth.h"

const char *const phc_root_shoot_keys[] = {
    "file", "diameter", "root_mass", "shoot_mass", "leaf_mass", "stem_mass", "age", "baad",
    "species", "suspicious", "select", "sigma", "preset", "growth", "mode", "seed", "uptake",
    "days", "step", "plant", "soil", "x_label", "y_label", NULL};
const phc_key_help phc_root_shoot_help[] = {
    {"file", "CSV table of harvested plants, relative to the config file. Give exactly one of "
             "file and baad."},
    {"diameter", "With file: {column: NAME, unit: UNIT} or a column name: basal diameters, "
                 "> 0; default unit mm. Required with file."},
    {"root_mass", "With file: {column, unit} or a column: root masses, > 0; default unit g. "
                  "Required with file."},
    {"shoot_mass", "With file: {column, unit} or a column: shoot masses (stem and leaves), > 0; "
                   "default unit g. Required with file unless leaf_mass and stem_mass are "
                   "given."},
    {"leaf_mass", "With file, instead of shoot_mass: {column, unit} or a column of leaf masses, "
                  "default unit g, added to stem_mass. Optional."},
    {"stem_mass", "With file, instead of shoot_mass: {column, unit} or a column of stem masses, "
                  "default unit g, added to leaf_mass. Optional."},
    {"age", "With file: {column, unit} or a column of plant ages, default unit d, compared "
            "with the simulated ages in the report. Optional."},
    {"baad", "A BAAD study folder (its data.csv), relative to the config file. Give exactly one "
             "of file and baad."},
    {"species", "With baad: the species whose plants are used. Required with baad."},
    {"suspicious", "With baad: exclude or keep the rows BAAD flags as suspicious (listed in the "
                   "report). Default: exclude."},
    {"select", "{column: NAME, equals: VALUE}: keep only the rows whose column (of the table, "
               "or a raw BAAD column) equals VALUE. Default: every row."},
    {"sigma", "Standard deviation of ln(root mass / shoot mass), > 0. Required."},
    {"preset", "Growth preset: oak, cherry, apple, poplar or maple. Default: oak."},
    {"growth", "{NAME: value, ...}: growth parameters (model/growth.h names, e.g. phi_rg) "
               "overriding the preset's. Default: none."},
    {"mode", "expected (smooth) or stochastic (branching drawn with seed). "
             "Default: expected."},
    {"seed", "Random seed of stochastic mode, a whole number >= 0. Default: 1."},
    {"uptake", "Root water uptake: physical or none (the authors' code). Default: physical."},
    {"days", "Longest simulated age, d, > 0. Default: 365."},
    {"step", "Growth step, d, 0 < step <= days. Default: 1."},
    {"plant", "{x, y, depth}: where the seed is planted in the soil grid, m. Default: the "
              "centre of the surface."},
    {"soil", "The soil the plant grows in, e.g. a pot (the soil: keys below). Default: none "
             "(the roots see the growth parameter soil_fill as fill level)."},
    {"x_label", "Axis label of the diameter. Default: \"basal diameter (mm)\"."},
    {"y_label", "Axis label of the ratio. Default: \"ln(root mass / shoot mass)\"."},
    {NULL, NULL}};

typedef struct rs_impl {
    phc_soil_setup *su;          /* NULL: no soil (fill = soil_fill) */
    size_t k_soil;               /* the soil's slots come first */
    phc_growth_params base;      /* preset + overrides */
    char preset[32];
    phc_growth_options opt;
    long *gslot;                 /* per data-set slot past k_soil: growth parameter index */
    size_t k_growth;
    double days, step;
    double *diameter;            /* n, m */
    double *age;                 /* n, d (NAN when not given) */
    double d_max;                /* m, largest observed diameter */
    char *source;                /* a sentence naming the data */
    char *notes;                 /* markdown list of excluded / skipped rows */
} rs_impl;

/* The simulated trajectory: one state per step. */
typedef struct rs_traj {
    size_t m, cap;
    double *t, *d, *lrs;         /* d, m, ln(root:shoot) */
    phc_growth_summary last;
} rs_traj;

static void traj_free(rs_traj *tr)
{
    free(tr->t);
    free(tr->d);
    free(tr->lrs);
    memset(tr, 0, sizeof *tr);
}

static int traj_push(rs_traj *tr, double t, double d, double lrs)
{
    if (tr->m == tr->cap) {
        size_t cap = tr->cap ? 2 * tr->cap : 256;
        double *a = realloc(tr->t, cap * sizeof *a);
        if (a) tr->t = a;
        double *b = realloc(tr->d, cap * sizeof *b);
        if (b) tr->d = b;
        double *c = realloc(tr->lrs, cap * sizeof *c);
        if (c) tr->lrs = c;
        if (!a || !b || !c) return -1;
        tr->cap = cap;
    }
    tr->t[tr->m] = t;
    tr->d[tr->m] = d;
    tr->lrs[tr->m] = lrs;
    tr->m++;
    return 0;
}

static void rs_free(void *p)
{
    rs_impl *im = p;
    if (!im) return;
    phc_soil_setup_free(im->su);
    free(im->gslot);
    free(im->diameter);
    free(im->age);
    free(im->source);
    free(im->notes);
    free(im);
}

/* Grows the plant at slot values p until its diameter passes d_stop or the
 * age reaches `days`.  0, > 0 (trial point outside the model's domain) or
 * < 0 (memory); with keep the plant and its soil are handed over. */
static int grow(const rs_impl *im, const double *p, double d_stop, rs_traj *tr,
                phc_growth **keep_plant, phc_soil **keep_soil, phc_error *err)
{
    phc_growth_params gp = im->base;
    for (size_t j = 0; j < im->k_growth; ++j)
        *phc_growth_param_ref(&gp, (size_t)im->gslot[j]) = p[im->k_soil + j];
    phc_error local;
    if (!err) err = &local;
    if (phc_growth_check(&gp, err)) return 1;
    phc_soil *s = NULL;
    if (im->su) {
        int rc = phc_soil_setup_build(im->su, p, &s, err);
        if (rc) return rc == PHC_ERR_NOMEM ? -1 : 1;
    }
    phc_growth *g = NULL;
    int rc = phc_growth_new(&gp, &im->opt, s, &g, err);
    if (rc) {
        phc_soil_free(s);
        return rc == PHC_ERR_NOMEM ? -1 : 1;
    }
    phc_growth_summary sm;
    phc_growth_summarize(g, &sm);
    rc = traj_push(tr, 0, sm.basal_diameter, NAN);
    for (double t = 0; !rc && t < im->days - 1e-9;) {
        double h = fmin(im->step, im->days - t);
        int r = phc_growth_step(g, h, err);
        if (r) { rc = r == PHC_ERR_NOMEM ? -1 : 1; break; }
        t += h;
        phc_growth_summarize(g, &sm);
        double lrs = sm.root_mass > 0 && sm.shoot_mass > 0 ? log(sm.root_shoot) : NAN;
        if (traj_push(tr, t, sm.basal_diameter, lrs)) rc = -1;
        if (sm.basal_diameter >= d_stop) break;
    }
    tr->last = sm;
    if (!rc && keep_plant) {
        *keep_plant = g;
        *keep_soil = s;
    } else {
        phc_growth_free(g);
        phc_soil_free(s);
    }
    return rc;
}

/* ln(root:shoot) and age when the diameter first reaches d (NAN if never). */
static void at_diameter(const rs_traj *tr, double d, double *lrs, double *age)
{
    *lrs = *age = NAN;
    for (size_t i = 1; i < tr->m; ++i) {
        if (tr->d[i] < d) continue;
        double d0 = tr->d[i - 1], d1 = tr->d[i];
        double w = d1 > d0 ? (d - d0) / (d1 - d0) : 1;
        if (w < 0) w = 0;
        double l0 = isfinite(tr->lrs[i - 1]) ? tr->lrs[i - 1] : tr->lrs[i];
        *lrs = l0 + w * (tr->lrs[i] - l0);
        *age = tr->t[i - 1] + w * (tr->t[i] - tr->t[i - 1]);
        return;
    }
}

static int rs_values(phc_dataset *ds, const double *p, const double *d, size_t m, double *y)
{
    rs_impl *im = ds->impl;
    double dmax = 0;
    for (size_t i = 0; i < m; ++i) dmax = fmax(dmax, d[i]);
    rs_traj tr = {0};
    int rc = grow(im, p, dmax, &tr, NULL, NULL, NULL);
    if (!rc)
        for (size_t i = 0; i < m; ++i) {
            double age;
            at_diameter(&tr, d[i], &y[i], &age);
        }
    traj_free(&tr);
    return rc;
}

/* Relative step of the Jacobian's central differences: the model is a
 * simulation whose events (a new segment, a flushed bud) fall on daily
 * steps, so its outputs are piecewise smooth with small jumps; steps of 2%
 * of each parameter span many events and give the slope of the trend, where
 * steps of 1e-6 would see either zero or a jump. */
#define RS_FD_STEP 0.02

static int rs_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    rs_impl *im = ds->impl;
    int rc = rs_values(ds, p, im->diameter, ds->n, yhat);
    if (rc || !jac) return rc;
    double *q = malloc(ds->k * sizeof *q), *lo = malloc(ds->n * sizeof *lo),
           *hi = malloc(ds->n * sizeof *hi);
    if (!q || !lo || !hi) rc = -1;
    for (size_t j = 0; !rc && j < ds->k; ++j) {
        memcpy(q, p, ds->k * sizeof *q);
        double h = RS_FD_STEP * (fabs(p[j]) > 0 ? fabs(p[j]) : 1);
        q[j] = p[j] + h;
        rc = rs_values(ds, q, im->diameter, ds->n, hi);
        q[j] = p[j] - h;
        if (!rc) rc = rs_values(ds, q, im->diameter, ds->n, lo);
        for (size_t i = 0; !rc && i < ds->n; ++i) jac[i * ds->k + j] = (hi[i] - lo[i]) / (2 * h);
    }
    free(q);
    free(lo);
    free(hi);
    return rc;
}

static int rs_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m, double *y)
{
    double *d = malloc((m ? m : 1) * sizeof *d);
    if (!d) return -1;
    for (size_t i = 0; i < m; ++i) d[i] = x[i] * 1e-3; /* x is in mm */
    int rc = rs_values(ds, p, d, m, y);
    free(d);
    return rc;
}

static int rs_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    rs_impl *im = ds->impl;
    rs_traj tr = {0};
    int rc = grow(im, p, im->d_max, &tr, NULL, NULL, err);
    if (rc) {
        traj_free(&tr);
        return rc < 0 ? phc_error_set(err, PHC_ERR_NOMEM, "out of memory")
                      : phc_error_prefix(err, PHC_ERR_DOMAIN, "data set '%s': the plant",
                                         ds->name);
    }
    char *out = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    if (!f) {
        traj_free(&tr);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    const phc_growth_summary *s = &tr.last;
    fprintf(f, "Data: %s\n\n", im->source);
    if (im->notes && *im->notes) fprintf(f, "%s\n", im->notes);
    fprintf(f,
            "Model: Rhizomorph shoot-root growth (preset `%s`, %s mode, %s uptake, steps of "
            "%g d, at most %g d)%s.\n\n",
            im->preset, im->opt.mode == PHC_GROWTH_EXPECTED ? "expected" : "stochastic",
            im->opt.uptake == PHC_GROWTH_UPTAKE_PHYSICAL ? "physical" : "no", im->step, im->days,
            im->su ? " in the soil below" : " without soil");
    fprintf(f,
            "Simulated plant when it reached the largest observed diameter (%.3g mm): age %.1f d, "
            "basal diameter %.3g mm, shoot %.4g g (leaves %.4g g), roots %.4g g, root:shoot "
            "%.3g, height %.3g m, rooting depth %.3g m, root spread %.3g m, %zu shoot and %zu "
            "root segments.\n\n",
            im->d_max * 1e3, s->age, s->basal_diameter * 1e3, s->shoot_mass, s->leaf_mass,
            s->root_mass, s->root_shoot, s->height, s->rooting_depth, s->root_spread,
            s->shoot_nodes, s->root_nodes);
    if (s->basal_diameter < im->d_max)
        fprintf(f, "**Warning:** the simulated plant did not reach %.3g mm within %g d.\n\n",
                im->d_max * 1e3, im->days);
    /* Ages: the model's age at each plant's diameter against the harvest age. */
    size_t n_age = 0;
    double sum_ratio = 0;
    for (size_t i = 0; i < ds->n; ++i) {
        if (!isfinite(im->age[i]) || !(im->age[i] > 0)) continue;
        double l, a;
        at_diameter(&tr, im->diameter[i], &l, &a);
        if (!isfinite(a)) continue;
        sum_ratio += log(a / im->age[i]);
        n_age++;
    }
    if (n_age)
        fprintf(f,
                "Ages: over %zu harvested plants with an age, the model reaches their diameter "
                "at %.3g times their age (geometric mean); the fit uses diameters only.\n",
                n_age, exp(sum_ratio / (double)n_age));
    traj_free(&tr);
    if (ferror(f) | (fclose(f) != 0)) {
        free(out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *markdown = out;
    return PHC_OK;
}

static int rs_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base,
                      phc_error *err)
{
    rs_impl *im = ds->impl;
    rs_traj tr = {0};
    phc_growth *g = NULL;
    phc_soil *s = NULL;
    int rc = grow(im, p, im->d_max, &tr, &g, &s, err);
    if (rc) {
        traj_free(&tr);
        return rc < 0 ? phc_error_set(err, PHC_ERR_NOMEM, "out of memory") : PHC_ERR_DOMAIN;
    }
    char *path = NULL;
    size_t cap = strlen(dir) + strlen(base) + 64;
    path = malloc(cap);
    if (!path) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto done; }
    snprintf(path, cap, "%s/%s_roots.rsml", dir, base);
    if ((rc = phc_growth_write_rsml(g, path, err))) goto done;
    snprintf(path, cap, "%s/%s_plant.txt", dir, base);
    if ((rc = phc_growth_write_plant_graph(g, path, err))) goto done;
    snprintf(path, cap, "%s/%s_architecture.png", dir, base);
    {
        char title[160];
        snprintf(title, sizeof title, "%s: %s at %.0f d, D = %.2g mm, root:shoot %.2g", ds->name,
                 im->preset, tr.last.age, tr.last.basal_diameter * 1e3, tr.last.root_shoot);
        const phc_growth *plants[1] = {g};
        const char *titles[1] = {title};
        double top = s ? s->origin[2] + s->nz * s->dx : im->opt.base[2];
        double x0 = s ? s->origin[0] : 0, x1 = s ? s->origin[0] + s->nx * s->dx : 0;
        if ((rc = phc_growth_plot_side(path, plants, titles, 1, top, x0, x1, err))) goto done;
    }
    snprintf(path, cap, "%s/%s_trajectory.csv", dir, base);
    {
        char tmp[4200];
        snprintf(tmp, sizeof tmp, "%s.tmp", path);
        FILE *f = fopen(tmp, "w");
        if (!f) { rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write", tmp); goto done; }
        fprintf(f, "age_d,basal_diameter_mm,ln_root_shoot\n");
        for (size_t i = 0; i < tr.m; ++i)
            fprintf(f, "%.6g,%.6g,%.6g\n", tr.t[i], tr.d[i] * 1e3, tr.lrs[i]);
        if (ferror(f) | (fclose(f) != 0) || rename(tmp, path) != 0) {
            remove(tmp);
            rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
            goto done;
        }
    }
done:
    free(path);
    phc_growth_free(g);
    phc_soil_free(s);
    traj_free(&tr);
    return rc;
}

static const phc_dataset_ops root_shoot_ops = {"root_shoot", rs_predict, rs_predict_at, rs_free,
                                               rs_report_section, rs_outputs, rs_outputs, NULL};

/* ---- loading ------------------------------------------------------------------- */

typedef struct rows {
    size_t n, cap;
    double *d, *root, *shoot, *age; /* m, g, g, d */
    size_t *line;
} rows;

static int rows_push(rows *r, double d, double root, double shoot, double age, size_t line)
{
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 64;
        double *a = realloc(r->d, cap * sizeof *a);
        if (a) r->d = a;
        double *b = realloc(r->root, cap * sizeof *b);
        if (b) r->root = b;
        double *c = realloc(r->shoot, cap * sizeof *c);
        if (c) r->shoot = c;
        double *e = realloc(r->age, cap * sizeof *e);
        if (e) r->age = e;
        size_t *l = realloc(r->line, cap * sizeof *l);
        if (l) r->line = l;
        if (!a || !b || !c || !e || !l) return -1;
        r->cap = cap;
    }
    r->d[r->n] = d;
    r->root[r->n] = root;
    r->shoot[r->n] = shoot;
    r->age[r->n] = age;
    r->line[r->n] = line;
    r->n++;
    return 0;
}

static void rows_free(rows *r)
{
    free(r->d);
    free(r->root);
    free(r->shoot);
    free(r->age);
    free(r->line);
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

/* The optional `select: {column: C, equals: V}` filter. */
static int read_select(const phc_yaml_doc *doc, const phc_yaml_node *node, const char **col,
                       const char **val, phc_error *err)
{
    *col = *val = NULL;
    const phc_yaml_node *sel = phc_yaml_get(node, "select");
    if (!sel) return PHC_OK;
    static const char *const keys[] = {"column", "equals", NULL};
    int rc = phc_yaml_check_keys(doc, sel, keys, "select", err);
    if (!rc) rc = phc_yaml_map_string(doc, sel, "column", 1, "select", col, err);
    if (!rc) rc = phc_yaml_map_string(doc, sel, "equals", 1, "select", val, err);
    return rc;
}

/* The harvest table `file`: rows into *out, the table recorded as an input
 * of ds. */
static int load_table(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                      const char *file, phc_dataset *ds, rows *out, char **source, phc_error *err)
{
    const char *ctx = "root_shoot data set";
    const char *dcol, *dunit, *rcol, *runit, *scol = NULL, *sunit = NULL, *lcol = NULL,
                                                *lunit = NULL, *tcol = NULL, *tunit = NULL;
    const char *acol = NULL, *aunit = NULL, *selc, *selv;
    phc_units *units = NULL;
    phc_table *t = NULL;
    double *dv = NULL, *rv = NULL, *sv = NULL, *lv = NULL, *tv = NULL, *av = NULL;
    char *path = NULL;
    int rc;
    int split = !phc_yaml_get(node, "shoot_mass");
    if ((rc = phc_column_spec(doc, node, "diameter", ctx, "mm", &dcol, &dunit, err)) ||
        (rc = phc_column_spec(doc, node, "root_mass", ctx, "g", &rcol, &runit, err)))
        return rc;
    if (!split) {
        if ((rc = phc_column_spec(doc, node, "shoot_mass", ctx, "g", &scol, &sunit, err)))
            return rc;
    } else if (!phc_yaml_get(node, "leaf_mass") || !phc_yaml_get(node, "stem_mass")) {
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: root_shoot data set: missing key 'shoot_mass' (or both "
                             "'leaf_mass' and 'stem_mass')",
                             doc->path, node->line);
    } else if ((rc = phc_column_spec(doc, node, "leaf_mass", ctx, "g", &lcol, &lunit, err)) ||
               (rc = phc_column_spec(doc, node, "stem_mass", ctx, "g", &tcol, &tunit, err))) {
        return rc;
    }
    if (phc_yaml_get(node, "age") &&
        (rc = phc_column_spec(doc, node, "age", ctx, "d", &acol, &aunit, err)))
        return rc;
    if ((rc = read_select(doc, node, &selc, &selv, err))) return rc;
    if (!(units = phc_units_new(err))) return err->status;
    phc_unit_conversion cd, cr, cs = {1, 0}, cl = {1, 0}, ct = {1, 0}, ca = {1, 0};
    char where[256];
    snprintf(where, sizeof where, "%s:%zu: diameter unit", doc->path, phc_key_line(node, "diameter"));
    if ((rc = phc_units_conversion(units, dunit, "m", where, &cd, err))) goto done;
    snprintf(where, sizeof where, "%s:%zu: root mass unit", doc->path, phc_key_line(node, "root_mass"));
    if ((rc = phc_units_conversion(units, runit, "g", where, &cr, err))) goto done;
    if (scol) {
        snprintf(where, sizeof where, "%s:%zu: shoot mass unit", doc->path,
                 phc_key_line(node, "shoot_mass"));
        if ((rc = phc_units_conversion(units, sunit, "g", where, &cs, err))) goto done;
    } else {
        snprintf(where, sizeof where, "%s:%zu: leaf mass unit", doc->path,
                 phc_key_line(node, "leaf_mass"));
        if ((rc = phc_units_conversion(units, lunit, "g", where, &cl, err))) goto done;
        snprintf(where, sizeof where, "%s:%zu: stem mass unit", doc->path,
                 phc_key_line(node, "stem_mass"));
        if ((rc = phc_units_conversion(units, tunit, "g", where, &ct, err))) goto done;
    }
    if (acol) {
        snprintf(where, sizeof where, "%s:%zu: age unit", doc->path, phc_key_line(node, "age"));
        if ((rc = phc_units_conversion(units, aunit, "d", where, &ca, err))) goto done;
    }
    if (!(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = phc_table_read(path, &t, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto done;
    }
    if ((rc = phc_dataset_add_input(ds, path))) {
        phc_error_set(err, rc, "out of memory");
        goto done;
    }
    if ((rc = phc_need_column(doc, node, "diameter", dcol, t, err)) ||
        (rc = phc_need_column(doc, node, "root_mass", rcol, t, err)) ||
        (scol && (rc = phc_need_column(doc, node, "shoot_mass", scol, t, err))) ||
        (lcol && (rc = phc_need_column(doc, node, "leaf_mass", lcol, t, err))) ||
        (tcol && (rc = phc_need_column(doc, node, "stem_mass", tcol, t, err))) ||
        (acol && (rc = phc_need_column(doc, node, "age", acol, t, err))))
        goto done;
    long selk = -1;
    if (selc && (selk = phc_table_find(t, selc)) < 0) {
        rc = phc_unknown_column(doc, phc_key_line(node, "select"), "select", selc, t, err);
        goto done;
    }
    /* Only the selected rows need numbers. */
    size_t nt = phc_table_rows(t), *sel = malloc((nt ? nt : 1) * sizeof *sel), ns = 0;
    if (!sel) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto done; }
    for (size_t r = 0; r < nt; ++r)
        if (selk < 0 || strcmp(phc_table_cell(t, r, (size_t)selk), selv) == 0) sel[ns++] = r;
    rc = phc_table_column_numbers_rows(t, dcol, sel, ns, &dv, err);
    if (!rc) rc = phc_table_column_numbers_rows(t, rcol, sel, ns, &rv, err);
    if (!rc && scol) rc = phc_table_column_numbers_rows(t, scol, sel, ns, &sv, err);
    if (!rc && lcol) rc = phc_table_column_numbers_rows(t, lcol, sel, ns, &lv, err);
    if (!rc && tcol) rc = phc_table_column_numbers_rows(t, tcol, sel, ns, &tv, err);
    if (!rc && acol) rc = phc_table_column_numbers_rows(t, acol, sel, ns, &av, err);
    for (size_t i = 0; !rc && i < ns; ++i) {
        size_t line = phc_table_row_line(t, sel[i]);
        double d = phc_unit_apply(cd, dv[i]), root = phc_unit_apply(cr, rv[i]);
        double shoot = scol ? phc_unit_apply(cs, sv[i])
                            : phc_unit_apply(cl, lv[i]) + phc_unit_apply(ct, tv[i]);
        if ((rc = check_row(path, line, d, root, shoot, err))) break;
        if (rows_push(out, d, root, shoot, av ? phc_unit_apply(ca, av[i]) : NAN, line))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    free(sel);
    if (!rc && out->n == 0)
        rc = selc ? phc_error_set(err, PHC_ERR_INPUT,
                                  "%s:%zu: select: no row of %s has %s = '%s'", doc->path,
                                  phc_key_line(node, "select"), path, selc, selv)
                  : phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one",
                                  path);
    if (!rc) {
        size_t cap = strlen(path) + 256;
        *source = malloc(cap);
        if (*source)
            snprintf(*source, cap, "`%s`, %zu harvested plants%s%s%s%s", path, out->n,
                     selc ? " with " : "", selc ? selc : "", selc ? " = " : "", selc ? selv : "");
        else rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_units_free(units);
    phc_table_free(t);
    free(dv); free(rv); free(sv); free(lv); free(tv); free(av);
    free(path);
    return rc;
}

/* The BAAD study folder `dir`: rows into *out, the folder's files read
 * recorded as inputs of ds. */
static int load_baad(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                     const char *dir, phc_dataset *ds, rows *out, char **source, char **notes,
                     phc_error *err)
{
    const char *ctx = "root_shoot data set", *species = NULL, *susp = "exclude", *selc, *selv;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, "species", 1, ctx, &species, err)) ||
        (rc = phc_yaml_map_string(doc, node, "suspicious", 0, ctx, &susp, err)) ||
        (rc = read_select(doc, node, &selc, &selv, err)))
        return rc;
    int keep = 0;
    if (!strcmp(susp, "keep")) keep = 1;
    else if (strcmp(susp, "exclude"))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'suspicious': expected 'exclude' or 'keep', found '%s'",
                             doc->path, phc_key_line(node, "suspicious"), susp);
    char *path = phc_join_path(base_dir, dir);
    if (!path) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    phc_baad_study *st = NULL;
    if ((rc = phc_baad_read(path, &st, err))) {
        rc = phc_error_prefix(err, rc, "%s:%zu: key 'baad'", doc->path, phc_key_line(node, "baad"));
        free(path);
        return rc;
    }
    const char *const *read_files = NULL;
    for (size_t i = 0, m = phc_baad_inputs(st, &read_files); !rc && i < m; ++i)
        if ((rc = phc_dataset_add_input(ds, read_files[i])))
            phc_error_set(err, rc, "out of memory");
    char *nb = NULL;
    size_t nlen = 0;
    FILE *nf = open_memstream(&nb, &nlen);
    size_t n_species = 0, n_missing = 0, n_excluded = 0, n_select = 0;
    for (size_t i = 0; !rc && nf && i < phc_baad_rows(st); ++i) {
        const phc_baad_row *r = phc_baad_row_at(st, i);
        if (!r->species || strcmp(r->species, species)) continue;
        n_species++;
        if (selc) {
            const char *v = phc_baad_raw(st, i, selc);
            if (!v) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: select: '%s' is not a column of %s/data.csv",
                                   doc->path, phc_key_line(node, "select"), selc, path);
                break;
            }
            if (strcmp(v, selv)) continue;
        }
        n_select++;
        if (!isfinite(r->d_ba) || !isfinite(r->m_rt) || !isfinite(r->m_so)) {
            n_missing++;
            continue;
        }
        if (r->flag == PHC_BAAD_INVALID) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s/data.csv:%zu: %s", path, r->line,
                               r->flag_reason ? r->flag_reason : "invalid row");
            break;
        }
        if (r->flag == PHC_BAAD_SUSPICIOUS) {
            fprintf(nf, "- data.csv:%zu %s: %s\n", r->line, keep ? "kept although suspicious" : "excluded as suspicious",
                    r->flag_reason ? r->flag_reason : "");
            if (!keep) { n_excluded++; continue; }
        }
        if ((rc = check_row(path, r->line, r->d_ba, r->m_rt * 1e3, r->m_so * 1e3, err))) break;
        if (rows_push(out, r->d_ba, r->m_rt * 1e3, r->m_so * 1e3,
                      isfinite(r->age) ? r->age * 365.25 : NAN, r->line))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    if (!nf && !rc) rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (nf) {
        if (n_missing)
            fprintf(nf, "- %zu rows of %s lack a basal diameter, root or shoot mass and are not used.\n",
                    n_missing, species);
        fclose(nf);
    }
    if (!rc && n_species == 0) {
        const char **names = NULL;
        size_t ns = phc_baad_species(st, &names);
        char list[512] = "";
        for (size_t k = 0; k < ns; ++k) {
            strncat(list, names[k], sizeof list - strlen(list) - 3);
            if (k + 1 < ns) strncat(list, ", ", sizeof list - strlen(list) - 1);
        }
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: species '%s' is not in %s (it has: %s)",
                           doc->path, phc_key_line(node, "species"), species, path, list);
    }
    if (!rc && out->n == 0)
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: no usable rows of '%s' in %s (%zu rows, %zu selected, %zu "
                           "without diameter or masses, %zu excluded as suspicious)",
                           doc->path, node->line, species, path, n_species, n_select, n_missing,
                           n_excluded);
    if (!rc) {
        size_t cap = strlen(path) + strlen(species) + 256;
        *source = malloc(cap);
        if (*source)
            snprintf(*source, cap,
                     "BAAD study `%s` (%s), *%s*: %zu plants used of %zu%s%s%s%s, %zu excluded "
                     "as suspicious, %zu without diameter or masses",
                     phc_baad_name(st), path, species, out->n, n_species, selc ? ", those with " : "",
                     selc ? selc : "", selc ? " = " : "", selc ? selv : "", n_excluded, n_missing);
        else rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        double shift = phc_baad_site_shift(st);
        if (!rc && isfinite(shift) && nb) {
            size_t l = strlen(nb);
            char *nn = realloc(nb, l + 160);
            if (nn) {
                nb = nn;
                snprintf(nb + l, 160, "- The study's site coordinates were corrected by BAAD's "
                                      "dataNew.csv by %.0f m.\n", shift);
            }
        }
    }
    if (!rc) { *notes = nb; nb = NULL; }
    free(nb);
    phc_baad_free(st);
    free(path);
    return rc;
}

/* The soil: block (until this kind is YAML-free). */
static int soil_from_yaml(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_is_parameter_fn is_parameter,
                          void *user_data, phc_soil_setup **out, phc_error *err)
{
    phc_soil_setup_yaml sy;
    int rc = phc_soil_setup_yaml_read(doc, soil, &sy, err);
    if (!rc)
        rc = phc_soil_setup_new(&sy.options, "root_shoot", is_parameter, user_data, out, err);
    phc_soil_setup_yaml_free(&sy);
    return rc;
}

int phc_root_shoot_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                        phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out,
                        phc_error *err)
{
    const char *ctx = "root_shoot data set";
    const char *file = NULL, *baad = NULL, *preset = "oak", *mode = "expected",
               *uptake = "physical", *x_label = NULL, *y_label = NULL;
    double sigma = NAN, seed = 1;
    rows r = {0};
    phc_dataset *ds = NULL;
    int rc;
    *out = NULL;
    rs_impl *im = calloc(1, sizeof *im);
    if (!im) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    im->days = 365;
    im->step = 1;
    im->opt = phc_growth_options_default();
    if ((rc = phc_yaml_map_string(doc, node, "file", 0, ctx, &file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "baad", 0, ctx, &baad, err)) ||
        (rc = phc_yaml_map_number(doc, node, "sigma", 1, ctx, &sigma, err)) ||
        (rc = phc_yaml_map_string(doc, node, "preset", 0, ctx, &preset, err)) ||
        (rc = phc_yaml_map_string(doc, node, "mode", 0, ctx, &mode, err)) ||
        (rc = phc_yaml_map_number(doc, node, "seed", 0, ctx, &seed, err)) ||
        (rc = phc_yaml_map_string(doc, node, "uptake", 0, ctx, &uptake, err)) ||
        (rc = phc_yaml_map_number(doc, node, "days", 0, ctx, &im->days, err)) ||
        (rc = phc_yaml_map_number(doc, node, "step", 0, ctx, &im->step, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &y_label, err)))
        goto fail;
    if (!file == !baad) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: root_shoot data set: give exactly one of 'file' (a table) "
                           "and 'baad' (a BAAD study folder)",
                           doc->path, node->line);
        goto fail;
    }
    if (!(sigma > 0)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'sigma': must be > 0, found %g",
                           doc->path, phc_key_line(node, "sigma"), sigma);
        goto fail;
    }
    if (!(im->days > 0) || !(im->step > 0) || im->step > im->days) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: keys 'days' and 'step': need 0 < step <= days, found step "
                           "%g d and days %g d",
                           doc->path, phc_key_line(node, im->step > 0 ? "days" : "step"), im->step,
                           im->days);
        goto fail;
    }
    if ((rc = phc_growth_preset(preset, &im->base, err))) {
        rc = phc_error_prefix(err, rc, "%s:%zu: key 'preset'", doc->path, phc_key_line(node, "preset"));
        goto fail;
    }
    snprintf(im->preset, sizeof im->preset, "%s", preset);
    if (!strcasecmp(mode, "stochastic")) im->opt.mode = PHC_GROWTH_STOCHASTIC;
    else if (strcasecmp(mode, "expected")) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: key 'mode': expected 'expected' or 'stochastic', found '%s'",
                           doc->path, phc_key_line(node, "mode"), mode);
        goto fail;
    }
    if (!(seed >= 0) || seed != floor(seed)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'seed': expected a whole number >= 0, found %g",
                           doc->path, phc_key_line(node, "seed"), seed);
        goto fail;
    }
    im->opt.seed = (uint64_t)seed;
    if (!strcasecmp(uptake, "none")) im->opt.uptake = PHC_GROWTH_UPTAKE_NONE;
    else if (strcasecmp(uptake, "physical")) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: key 'uptake': expected 'physical' or 'none', found '%s'",
                           doc->path, phc_key_line(node, "uptake"), uptake);
        goto fail;
    }
    /* growth: {name: value} overrides */
    const phc_yaml_node *gr = phc_yaml_get(node, "growth");
    if (gr && gr->kind != PHC_YAML_MAPPING) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'growth': expected a mapping of growth "
                           "parameters to values", doc->path, gr->line);
        goto fail;
    }
    for (size_t q = 0; gr && q < gr->count; ++q) {
        long k = phc_growth_param_find(gr->keys[q]);
        if (k < 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: growth: unknown growth parameter '%s' (see model/growth.h "
                               "or the README's list)",
                               doc->path, gr->key_lines[q], gr->keys[q]);
            goto fail;
        }
        if ((rc = phc_yaml_number(doc, gr->values[q], gr->keys[q],
                                  phc_growth_param_ref(&im->base, (size_t)k), err)))
            goto fail;
    }
    if ((rc = phc_growth_check(&im->base, err))) {
        rc = phc_error_prefix(err, rc, "%s:%zu", doc->path, gr ? gr->line : node->line);
        goto fail;
    }
    /* the soil and the plant's position in it */
    const phc_yaml_node *soil = phc_yaml_get(node, "soil");
    if (soil && (rc = soil_from_yaml(doc, soil, is_parameter, user_data, &im->su, err)))
        goto fail;
    im->k_soil = im->su ? im->su->k : 0;
    {
        double W = im->su ? im->su->nx * im->su->dx : 0, D = im->su ? im->su->ny * im->su->dx : 0;
        double H = im->su ? im->su->nz * im->su->dx : 0;
        double x = W / 2, y = D / 2, depth = 0;
        const phc_yaml_node *pl = phc_yaml_get(node, "plant");
        static const char *const pkeys[] = {"x", "y", "depth", NULL};
        if (pl && ((rc = phc_yaml_check_keys(doc, pl, pkeys, "plant", err)) ||
                   (rc = phc_yaml_map_number(doc, pl, "x", 0, "plant", &x, err)) ||
                   (rc = phc_yaml_map_number(doc, pl, "y", 0, "plant", &y, err)) ||
                   (rc = phc_yaml_map_number(doc, pl, "depth", 0, "plant", &depth, err))))
            goto fail;
        if (im->su && (x < 0 || x > W || y < 0 || y > D || depth < 0 || depth > H)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: plant: the plant is seeded at x = %g, y = %g m, depth %g "
                               "m, outside the soil grid (x in [0, %g], y in [0, %g], depth in "
                               "[0, %g] m)",
                               doc->path, pl ? pl->line : node->line, x, y, depth, W, D, H);
            goto fail;
        }
        im->opt.base[0] = x;
        im->opt.base[1] = y;
        im->opt.base[2] = H - depth;
    }
    /* growth slots */
    im->gslot = malloc(phc_growth_param_count() * sizeof *im->gslot);
    if (!im->gslot) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto fail; }
    for (size_t q = 0; q < phc_growth_param_count(); ++q)
        if (is_parameter(phc_growth_param_name(q), user_data)) im->gslot[im->k_growth++] = (long)q;
    /* the data (the data set first: the loaders record the files they read) */
    ds = phc_dataset_new(&root_shoot_ops, im->k_soil + im->k_growth);
    if (!ds) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto fail; }
    if (file) rc = load_table(doc, node, base_dir, file, ds, &r, &im->source, err);
    else rc = load_baad(doc, node, base_dir, baad, ds, &r, &im->source, &im->notes, err);
    if (rc) goto fail;
    int bad = 0;
    for (size_t q = 0; q < im->k_soil && !bad; ++q)
        bad = !(ds->slot_names[q] = strdup(im->su->slot_names[q]));
    for (size_t j = 0; j < im->k_growth && !bad; ++j)
        bad = !(ds->slot_names[im->k_soil + j] = strdup(phc_growth_param_name((size_t)im->gslot[j])));
    ds->n = r.n;
    ds->x = malloc(r.n * sizeof *ds->x);
    ds->y = malloc(r.n * sizeof *ds->y);
    ds->sigma = malloc(r.n * sizeof *ds->sigma);
    ds->data_lines = malloc(r.n * sizeof *ds->data_lines);
    ds->data_file = file ? phc_join_path(base_dir, file) : phc_join_path(base_dir, baad);
    if (ds->data_file && baad) {
        char *df = phc_join_path(ds->data_file, "data.csv");
        free(ds->data_file);
        ds->data_file = df;
    }
    im->diameter = malloc(r.n * sizeof *im->diameter);
    im->age = malloc(r.n * sizeof *im->age);
    ds->x_label = strdup(x_label ? x_label : "basal diameter (mm)");
    ds->y_label = strdup(y_label ? y_label : "ln(root mass / shoot mass)");
    if (bad || !ds->x || !ds->y || !ds->sigma || !ds->data_lines || !ds->data_file ||
        !im->diameter || !im->age || !ds->x_label || !ds->y_label) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < r.n; ++i) {
        ds->x[i] = r.d[i] * 1e3;
        ds->y[i] = log(r.root[i] / r.shoot[i]);
        ds->sigma[i] = sigma;
        ds->data_lines[i] = r.line[i];
        im->diameter[i] = r.d[i];
        im->age[i] = r.age[i];
        if (r.d[i] > im->d_max) im->d_max = r.d[i];
    }
    ds->derivatives = PHC_DERIV_ANALYTIC; /* our own wide central differences */
    ds->model_tolerance = 1e-4;
    ds->config_line = node->line;
    ds->impl = im;
    im = NULL;
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    rows_free(&r);
    rs_free(im);
    if (ds) ds->impl = NULL;
    phc_dataset_free(ds);
    return rc;
}
