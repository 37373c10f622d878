/* Traced shoots: see shoot_traces.h. */
#include "measurements/shoot_traces.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/rsml.h"
#include "measurements/table.h"

void phc_shoot_traces_free(phc_shoot_traces *tr)
{
    if (!tr) return;
    for (size_t s = 0; tr->names && s < tr->n_shoots; ++s) free(tr->names[s]);
    free(tr->names);
    free(tr->parent);
    free(tr->order);
    free(tr->first_line);
    free(tr->start);
    free(tr->t);
    free(tr->x);
    free(tr->source);
    free(tr);
}

static char *dup_text(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

static long find_name(char *const *names, size_t n, const char *name)
{
    for (size_t s = 0; s < n; ++s)
        if (!strcmp(names[s], name)) return (long)s;
    return -1;
}

/* The common part of reading a file and building from rows: rows in file
 * order, line[i] their lines, pname[i] the parent text (NULL: no column). */
static int build(const char *name, size_t n, const size_t *line, const double *t, const char *const *shoot,
                 const double *x, const double *y, const double *z, const char *const *pname,
                 phc_shoot_traces **out, phc_error *err)
{
    *out = NULL;
    phc_shoot_traces *tr = calloc(1, sizeof *tr);
    size_t *of = malloc((n ? n : 1) * sizeof *of), *count = NULL, *fill = NULL, *prow = NULL;
    int rc = PHC_OK;
    if (!tr || !of || !(tr->source = dup_text(name)) || !(tr->names = calloc(n ? n : 1, sizeof *tr->names))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if (n == 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: no traced points (a shoot needs at least 2)", name);
        goto fail;
    }
    prow = malloc(n * sizeof *prow); /* first row of each shoot */
    if (!prow) { rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory"); goto fail; }
    for (size_t i = 0; i < n; ++i) {
        if (!shoot[i] || !*shoot[i]) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column 'shoot': the shoot name is empty", name, line[i]);
            goto fail;
        }
        long s = find_name(tr->names, tr->n_shoots, shoot[i]);
        if (s < 0) {
            if (!(tr->names[tr->n_shoots] = dup_text(shoot[i]))) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto fail;
            }
            prow[tr->n_shoots] = i;
            s = (long)tr->n_shoots++;
        }
        of[i] = (size_t)s;
    }
    const size_t m = tr->n_shoots;
    tr->parent = malloc(m * sizeof *tr->parent);
    tr->order = calloc(m, sizeof *tr->order);
    tr->first_line = malloc(m * sizeof *tr->first_line);
    tr->start = calloc(m + 1, sizeof *tr->start);
    count = calloc(m, sizeof *count);
    fill = calloc(m, sizeof *fill);
    tr->t = malloc(n * sizeof *tr->t);
    tr->x = malloc(3 * n * sizeof *tr->x);
    if (!tr->parent || !tr->order || !tr->first_line || !tr->start || !count || !fill || !tr->t || !tr->x) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t s = 0; s < m; ++s) {
        tr->first_line[s] = line[prow[s]];
        tr->parent[s] = PHC_SHOOT_NONE;
        const char *p = pname ? pname[prow[s]] : NULL;
        if (p && *p) {
            long q = find_name(tr->names, m, p);
            if (q < 0) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column 'parent': shoot '%s' names parent '%s', which is not a "
                                   "shoot of the table",
                                   name, line[prow[s]], tr->names[s], p);
                goto fail;
            }
            tr->parent[s] = (size_t)q;
        }
    }
    for (size_t i = 0; i < n; ++i) {
        const size_t s = of[i];
        if (pname) {
            const char *p = pname[i] ? pname[i] : "";
            const char *p0 = tr->parent[s] == PHC_SHOOT_NONE ? "" : tr->names[tr->parent[s]];
            if (strcmp(p, p0)) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column 'parent': shoot '%s' has parent '%s' here but '%s' at "
                                   "line %zu",
                                   name, line[i], tr->names[s], p, p0, tr->first_line[s]);
                goto fail;
            }
        }
        const double v[4] = {t[i], x[i], y[i], z[i]};
        static const char *const col[4] = {"time", "x", "y", "z"};
        for (int k = 0; k < 4; ++k)
            if (!isfinite(v[k])) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': expected a finite number, found %g",
                                   name, line[i], col[k], v[k]);
                goto fail;
            }
        count[s]++;
    }
    /* orders, with a guard against cycles */
    for (size_t s = 0; s < m; ++s) {
        unsigned k = 0;
        for (size_t q = tr->parent[s]; q != PHC_SHOOT_NONE; q = tr->parent[q]) {
            if (++k > m || q == s) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column 'parent': shoot '%s' is its own ancestor (the parents form "
                                   "a cycle)",
                                   name, tr->first_line[s], tr->names[s]);
                goto fail;
            }
        }
        tr->order[s] = k;
        if (count[s] < 2) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column 'shoot': shoot '%s' has %zu point; a shoot needs at least 2",
                               name, tr->first_line[s], tr->names[s], count[s]);
            goto fail;
        }
        tr->start[s + 1] = tr->start[s] + count[s];
    }
    double t_end = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        const size_t s = of[i], j = tr->start[s] + fill[s]++;
        if (j > tr->start[s] && t[i] < tr->t[j - 1]) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column 'time': time goes backwards within shoot '%s' (%g s after %g s)",
                               name, line[i], tr->names[s], t[i], tr->t[j - 1]);
            goto fail;
        }
        tr->t[j] = t[i];
        tr->x[3 * j] = x[i];
        tr->x[3 * j + 1] = y[i];
        tr->x[3 * j + 2] = z[i];
        t_end = fmax(t_end, t[i]);
    }
    tr->n_points = n;
    tr->t_end = t_end;
    free(of);
    free(count);
    free(fill);
    free(prow);
    *out = tr;
    return PHC_OK;
fail:
    free(of);
    free(count);
    free(fill);
    free(prow);
    phc_shoot_traces_free(tr);
    return rc;
}

int phc_shoot_traces_from_rows(const char *name, size_t n, const double *t, const char *const *shoot,
                               const double *x, const double *y, const double *z,
                               const char *const *parent, phc_shoot_traces **out, phc_error *err)
{
    size_t *line = malloc((n ? n : 1) * sizeof *line);
    if (!line) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n; ++i) line[i] = i + 2;
    int rc = build(name, n, line, t, shoot, x, y, z, parent, out, err);
    free(line);
    return rc;
}

/* Metres per RSML <unit> (the lengths RSML files use), 0 when unknown. */
static double metres_per_unit(const char *u)
{
    static const struct { const char *name; double m; } units[] = {
        {"m", 1},         {"meter", 1},     {"metre", 1},     {"meters", 1}, {"metres", 1},
        {"cm", 0.01},     {"mm", 0.001},    {"um", 1e-6},     {"µm", 1e-6},  {"micron", 1e-6},
        {"inch", 0.0254}, {"in", 0.0254},   {"inches", 0.0254}};
    for (size_t k = 0; k < sizeof units / sizeof units[0]; ++k)
        if (!strcmp(u, units[k].name)) return units[k].m;
    return 0;
}

static int ends_with_rsml(const char *path)
{
    const size_t n = strlen(path);
    if (n < 5) return 0;
    const char *e = path + n - 5;
    return e[0] == '.' && (e[1] | 32) == 'r' && (e[2] | 32) == 's' && (e[3] | 32) == 'm' && (e[4] | 32) == 'l';
}

/* Traced shoots from RSML (see shoot_traces.h): every <root> polyline is a
 * shoot, its parent the root it is nested in, each point's time its sample
 * of the function named "time". */
static int read_rsml(const char *path, phc_shoot_traces **out, phc_error *err)
{
    phc_rsml *doc = NULL;
    int rc = phc_rsml_read(path, &doc, err);
    if (rc) return rc;
    size_t n = 0;
    for (size_t r = 0; r < doc->n_roots; ++r) n += doc->roots[r].n_points;
    double *t = malloc((n ? n : 1) * sizeof *t), *x = malloc((n ? n : 1) * sizeof *x),
           *y = malloc((n ? n : 1) * sizeof *y), *z = malloc((n ? n : 1) * sizeof *z);
    const char **shoot = malloc((n ? n : 1) * sizeof *shoot), **parent = malloc((n ? n : 1) * sizeof *parent);
    size_t *line = malloc((n ? n : 1) * sizeof *line);
    char **names = calloc(doc->n_roots ? doc->n_roots : 1, sizeof *names);
    if (!t || !x || !y || !z || !shoot || !parent || !line || !names) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* every root must carry its time before anything else is said */
    for (size_t r = 0; r < doc->n_roots; ++r) {
        const phc_rsml_root *root = &doc->roots[r];
        if (!root->time) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: root '%s': no per-point function named 'time' (traced shoots need "
                               "<functions><function name=\"time\" domain=\"polyline\"> with one <sample> "
                               "per point, in s)",
                               path, root->source_line, root->id ? root->id : root->label ? root->label : "?");
            goto done;
        }
    }
    const char *unit = doc->unit ? doc->unit : "m";
    const double per = metres_per_unit(unit);
    if (!(per > 0)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s: metadata <unit> '%s' is not a length (traced shoots need m, cm, mm, um or "
                           "inch: coordinates / resolution are in that unit)",
                           path, unit);
        goto done;
    }
    const double scale = per / doc->resolution;
    size_t i = 0;
    for (size_t r = 0; r < doc->n_roots; ++r) {
        const phc_rsml_root *root = &doc->roots[r];
        char buf[32];
        snprintf(buf, sizeof buf, "root%zu", r + 1);
        const char *nm = root->id ? root->id : buf;
        for (size_t q = 0; q < r; ++q)
            if (!strcmp(names[q], nm)) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: root '%s': the id is used by the root at line %zu too (a shoot's "
                                   "id must be unique)",
                                   path, root->source_line, nm, doc->roots[q].source_line);
                goto done;
            }
        if (!(names[r] = dup_text(nm))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        for (size_t j = 0; j < root->n_points; ++j, ++i) {
            if (j > 0 && root->time[j] < root->time[j - 1]) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: root '%s': time goes backwards along the shoot: sample %zu is %g s, "
                                   "after %g s (points run from the base, traced in time order)",
                                   path, root->time_line[j], nm, j + 1, root->time[j], root->time[j - 1]);
                goto done;
            }
            t[i] = root->time[j];
            x[i] = root->xyz[3 * j] * scale;
            y[i] = root->xyz[3 * j + 1] * scale;
            z[i] = root->xyz[3 * j + 2] * scale;
            shoot[i] = names[r];
            parent[i] = root->parent == PHC_RSML_NO_PARENT ? "" : names[root->parent];
            line[i] = root->time_line[j];
        }
    }
    rc = build(path, n, line, t, shoot, x, y, z, parent, out, err);
done:
    for (size_t r = 0; names && r < doc->n_roots; ++r) free(names[r]);
    free(names);
    free(t);
    free(x);
    free(y);
    free(z);
    free(shoot);
    free(parent);
    free(line);
    phc_rsml_free(doc);
    return rc;
}

int phc_shoot_traces_read(const char *path, phc_shoot_traces **out, phc_error *err)
{
    *out = NULL;
    if (ends_with_rsml(path)) return read_rsml(path, out, err);
    phc_table *tab = NULL;
    int rc = phc_table_read(path, &tab, err);
    if (rc) return rc;
    const size_t n = phc_table_rows(tab);
    double *t = NULL, *x = NULL, *y = NULL, *z = NULL;
    const char **shoot = NULL, **parent = NULL;
    size_t *line = NULL;
    const long cs = phc_table_find(tab, "shoot"), cp = phc_table_find(tab, "parent");
    if (cs < 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:1: no column 'shoot' (the columns are time, shoot, x, y, z "
                           "and optionally parent)", path);
        goto done;
    }
    if ((rc = phc_table_column_numbers(tab, "time", &t, err)) || (rc = phc_table_column_numbers(tab, "x", &x, err)) ||
        (rc = phc_table_column_numbers(tab, "y", &y, err)) || (rc = phc_table_column_numbers(tab, "z", &z, err)))
        goto done;
    shoot = malloc((n ? n : 1) * sizeof *shoot);
    parent = cp >= 0 ? malloc((n ? n : 1) * sizeof *parent) : NULL;
    line = malloc((n ? n : 1) * sizeof *line);
    if (!shoot || !line || (cp >= 0 && !parent)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        shoot[i] = phc_table_cell(tab, i, (size_t)cs);
        if (parent) parent[i] = phc_table_cell(tab, i, (size_t)cp);
        line[i] = phc_table_row_line(tab, i);
    }
    rc = build(path, n, line, t, shoot, x, y, z, parent, out, err);
done:
    free(t);
    free(x);
    free(y);
    free(z);
    free(shoot);
    free(parent);
    free(line);
    phc_table_free(tab);
    return rc;
}

static double dist2_point_segment(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], dd = 0, dp = 0;
    for (int k = 0; k < 3; ++k) {
        ab[k] = b[k] - a[k];
        ap[k] = p[k] - a[k];
        dd += ab[k] * ab[k];
        dp += ab[k] * ap[k];
    }
    double u = dd > 0 ? dp / dd : 0;
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    double e = 0;
    for (int k = 0; k < 3; ++k) {
        const double d = ap[k] - u * ab[k];
        e += d * d;
    }
    return e;
}

/* Points of shoot s with time <= t: start[s] .. return value - 1. */
static size_t end_at(const phc_shoot_traces *tr, size_t s, double t)
{
    size_t j = tr->start[s];
    while (j < tr->start[s + 1] && tr->t[j] <= t) ++j;
    return j;
}

/* Insertion sort of shoot indices by name (a plant has few shoots). */
static void sort_by_name(size_t *idx, size_t n, char *const *names)
{
    for (size_t i = 1; i < n; ++i) {
        const size_t v = idx[i];
        size_t j = i;
        for (; j > 0 && strcmp(names[idx[j - 1]], names[v]) > 0; --j) idx[j] = idx[j - 1];
        idx[j] = v;
    }
}

int phc_shoot_traces_segments(const phc_shoot_traces *tr, double t, phc_shoot_segment **seg, size_t *n,
                              phc_error *err)
{
    *seg = NULL;
    *n = 0;
    size_t total = 0;
    for (size_t s = 0; s < tr->n_shoots; ++s) {
        const size_t e = end_at(tr, s, t);
        if (e > tr->start[s] + 1) total += e - tr->start[s] - 1;
    }
    if (!total) return PHC_OK;
    phc_shoot_segment *g = calloc(total, sizeof *g);
    size_t *by_name = malloc(tr->n_shoots * sizeof *by_name);
    if (!g || !by_name) {
        free(g);
        free(by_name);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    /* shoots in the order of their names, so that the statistics' sums run in one order whatever
     * order the file lists the shoots in (a CSV by first appearance, RSML nested) */
    for (size_t s = 0; s < tr->n_shoots; ++s) by_name[s] = s;
    sort_by_name(by_name, tr->n_shoots, tr->names);
    size_t m = 0;
    for (size_t q = 0; q < tr->n_shoots; ++q) {
        const size_t s = by_name[q];
        const size_t e = end_at(tr, s, t);
        for (size_t j = tr->start[s]; j + 1 < e; ++j) {
            phc_shoot_segment *q = &g[m++];
            memcpy(q->base, tr->x + 3 * j, sizeof q->base);
            memcpy(q->tip, tr->x + 3 * (j + 1), sizeof q->tip);
            q->order = tr->order[s];
            if (j != tr->start[s] || tr->parent[s] == PHC_SHOOT_NONE) continue;
            /* the parent's segment (at time t) closest to the branch point */
            const size_t p = tr->parent[s], pe = end_at(tr, p, t);
            double best = INFINITY;
            for (size_t i = tr->start[p]; i + 1 < pe; ++i) {
                const double d2 = dist2_point_segment(q->base, tr->x + 3 * i, tr->x + 3 * (i + 1));
                if (d2 < best) {
                    best = d2;
                    for (int k = 0; k < 3; ++k) q->parent_dir[k] = tr->x[3 * (i + 1) + k] - tr->x[3 * i + k];
                }
            }
            q->lateral_start = isfinite(best);
        }
    }
    free(by_name);
    *seg = g;
    *n = m;
    return PHC_OK;
}
