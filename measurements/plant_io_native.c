/* phytocal's own plant-graph CSV: reader and writer (plant_io.h).
 *
 * NATIVE CSV (phytocal's own format, what phc_plant_io_write_native writes):
 *
 *     # unit: m
 *     id,parent,radius,length,x_head,y_head,z_head,x_tail,y_tail,z_tail,leaf,fixed
 *     0,-1,0.005,0.02,0,0,0,0,0,0.02,0,1
 *     1,0,0.004,0.01,0,0,0.02,0.01,0,0.02,1,0
 *
 *   - `# unit: U` (U one of m, cm, mm, um) is optional and must come before
 *     the header; it scales radius, length and coordinates to metres.  An
 *     explicit unit_to_m given to phc_plant_io_read overrides it.
 *   - One row per segment, in any order; `id` is any integer, unique in the
 *     file; `parent` is the parent's id, or -1 (or an empty cell) for the
 *     single root.  Segment i of the graph is row i; source_id is `id`.
 *   - `length` must agree with |tail - head| to a relative 1e-4 (files
 *     written by hand with 5 significant digits pass; a length that
 *     contradicts the coordinates is an error, not silently replaced).
 *   - `leaf` and `fixed` are 0 or 1.  Other columns are ignored; the header
 *     may list the columns in any order (the CSV reader, measurements/table.h,
 *     also accepts ';' or tab as the delimiter, quotes, `#` comment lines).
 *   - The writer writes ids = source_id when these are unique, else the
 *     indices 0..n-1, and numbers with 17 significant digits (exact round
 *     trip). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "measurements/plant_io.h"
#include "measurements/plant_io_internal.h"
#include "measurements/plant_io_text.h"
#include "measurements/table.h"

static const char *const native_columns[12] = {
    "id", "parent", "radius", "length", "x_head", "y_head",
    "z_head", "x_tail", "y_tail", "z_tail", "leaf", "fixed"};

/* The optional `# unit: U` line before the header.  *unit_to_m stays 0 when
 * there is none; *header_line is the line of the header (for messages). */
static int native_unit(const char *path, const char *text, double *unit_to_m,
                       size_t *header_line, phc_error *err)
{
    static const struct {
        const char *name;
        double factor;
    } units[] = {{"m", 1.0}, {"cm", 1e-2}, {"mm", 1e-3}, {"um", 1e-6}, {"µm", 1e-6}};
    const char *s = text;
    size_t number = 1, i;
    *unit_to_m = 0;
    *header_line = 1;
    if ((unsigned char)s[0] == 0xEF && (unsigned char)s[1] == 0xBB && (unsigned char)s[2] == 0xBF)
        s += 3;
    for (;;) {
        const char *e = s + strcspn(s, "\r\n");
        const char *p = s;
        while (p < e && phc_plant_io_is_blank(*p))
            ++p;
        if (p == e) { /* blank line */
            if (!*e)
                return PHC_OK;
            *header_line = number + 1;
            s = e + (e[0] == '\r' && e[1] == '\n' ? 2 : 1);
            ++number;
            continue;
        }
        if (*p != '#') {
            *header_line = number;
            return PHC_OK; /* the header: no unit line */
        }
        ++p;
        while (p < e && phc_plant_io_is_blank(*p))
            ++p;
        if ((size_t)(e - p) >= 5 && strncasecmp(p, "unit:", 5) == 0) {
            char word[32];
            size_t len;
            p += 5;
            while (p < e && phc_plant_io_is_blank(*p))
                ++p;
            len = (size_t)(e - p);
            while (len && phc_plant_io_is_blank(p[len - 1]))
                --len;
            if (len >= sizeof word)
                len = sizeof word - 1;
            memcpy(word, p, len);
            word[len] = '\0';
            for (i = 0; i < sizeof units / sizeof units[0]; ++i)
                if (strcmp(word, units[i].name) == 0) {
                    *unit_to_m = units[i].factor;
                    /* the header is the next line that is neither blank
                     * nor a comment */
                    for (s = e; *s;) {
                        s += (s[0] == '\r' && s[1] == '\n') ? 2 : 1;
                        ++number;
                        e = s + strcspn(s, "\r\n");
                        p = s;
                        while (p < e && phc_plant_io_is_blank(*p))
                            ++p;
                        if (p < e && *p != '#')
                            break;
                        s = e;
                    }
                    *header_line = number;
                    return PHC_OK;
                }
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: '# unit:': expected m, cm, mm or um, found '%s'", path,
                                 number, word);
        }
        if (!*e)
            return PHC_OK;
        s = e + (e[0] == '\r' && e[1] == '\n' ? 2 : 1);
        ++number;
        *header_line = number;
    }
}

static int native_integer_cell(const phc_table *t, long col, size_t row, const char *name,
                               long *x, phc_error *err)
{
    const char *cell = phc_table_cell(t, row, (size_t)col);
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];
    if (phc_plant_io_parse_long(cell, x) != 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: column '%s': expected a whole number, found '%s'",
                             phc_table_source(t), phc_table_row_line(t, row), name,
                             *cell ? phc_plant_io_shorten(cell, shown, sizeof shown)
                                   : "an empty cell");
    return PHC_OK;
}

int phc_plant_io_read_native(const char *path, char *text, size_t length, double unit,
                             phc_plant_graph **out, phc_error *err)
{
    phc_table *t = NULL;
    phc_plant_graph *g = NULL;
    double *col[12] = {NULL};
    long *ids = NULL;
    size_t *lines = NULL;
    phc_plant_io_id_entry *map = NULL;
    long ci[12];
    size_t n, i, header_line;
    double file_unit;
    int rc, c;
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];

    if ((rc = native_unit(path, text, &file_unit, &header_line, err)))
        return rc;
    if (unit == 0)
        unit = file_unit > 0 ? file_unit : 1.0;
    if ((rc = phc_table_parse(text, length, path, &t, err)))
        return rc;
    for (c = 0; c < 12; ++c) {
        ci[c] = phc_table_find(t, native_columns[c]);
        if (ci[c] < 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: missing column '%s' (a native plant file has the "
                               "columns id,parent,radius,length,x_head,y_head,z_head,x_tail,"
                               "y_tail,z_tail,leaf,fixed)",
                               path, header_line, native_columns[c]);
            goto fail;
        }
    }
    n = phc_table_rows(t);
    if (n == 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: no segments: the header is followed by no rows", path,
                           header_line);
        goto fail;
    }
    for (c = 2; c < 10; ++c)
        if ((rc = phc_table_column_numbers(t, native_columns[c], &col[c], err)))
            goto fail;
    g = phc_plant_graph_new(n);
    ids = malloc(n * sizeof *ids);
    lines = malloc(n * sizeof *lines);
    if (!g || !ids || !lines) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    for (i = 0; i < n; ++i) {
        lines[i] = phc_table_row_line(t, i);
        if ((rc = native_integer_cell(t, ci[0], i, "id", &ids[i], err)))
            goto fail;
    }
    if ((rc = phc_plant_io_build_id_map(path, ids, lines, n, "segment", &map, err)))
        goto fail;
    for (i = 0; i < n; ++i) {
        const char *pcell = phc_table_cell(t, i, (size_t)ci[1]);
        long parent;
        int k;
        double len_geom;
        for (k = 10; k < 12; ++k) {
            const char *cell = phc_table_cell(t, i, (size_t)ci[k]);
            if (strcmp(cell, "0") != 0 && strcmp(cell, "1") != 0) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column '%s': expected 0 or 1, found '%s'", path,
                                   lines[i], native_columns[k],
                                   *cell ? phc_plant_io_shorten(cell, shown, sizeof shown)
                                         : "an empty cell");
                goto fail;
            }
        }
        g->leaf[i] = phc_table_cell(t, i, (size_t)ci[10])[0] == '1';
        g->fixed[i] = phc_table_cell(t, i, (size_t)ci[11])[0] == '1';
        g->source_id[i] = ids[i];
        if (!*pcell) {
            parent = -1;
        } else if ((rc = native_integer_cell(t, ci[1], i, "parent", &parent, err))) {
            goto fail;
        }
        if (parent == -1) {
            g->parent[i] = PHC_PLANT_NO_PARENT;
        } else {
            const size_t p = phc_plant_io_find_id(map, n, parent);
            if (p == (size_t)-1) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: segment %ld: parent %ld is not an id in this file "
                                   "(-1 or an empty cell marks the root)",
                                   path, lines[i], ids[i], parent);
                goto fail;
            }
            if (p == i) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: segment %ld: a segment cannot be its own parent",
                                   path, lines[i], ids[i]);
                goto fail;
            }
            g->parent[i] = p;
        }
        g->radius[i] = col[2][i] * unit;
        g->length[i] = col[3][i] * unit;
        for (k = 0; k < 3; ++k) {
            g->head[3 * i + k] = col[4 + k][i] * unit;
            g->tail[3 * i + k] = col[7 + k][i] * unit;
        }
        if ((rc = phc_plant_io_check_radius(path, lines[i], ids[i], col[2][i], err)))
            goto fail;
        if (!(col[3][i] > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: length must be positive and finite, found %g",
                               path, lines[i], ids[i], col[3][i]);
            goto fail;
        }
        len_geom = phc_plant_io_distance3(g->tail + 3 * i, g->head + 3 * i);
        if (!(fabs(len_geom - g->length[i]) <= 1e-4 * g->length[i])) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: length %.9g does not match |tail - head| = "
                               "%.9g (file units)",
                               path, lines[i], ids[i], col[3][i], len_geom / unit);
            goto fail;
        }
    }
    if ((rc = phc_plant_io_check_structure(path, g, lines, err)) ||
        (rc = phc_plant_graph_finish(g, path, err)))
        goto fail;
    *out = g;
    g = NULL;
fail:
    for (c = 0; c < 12; ++c)
        free(col[c]);
    phc_table_free(t);
    phc_plant_graph_free(g);
    free(ids);
    free(lines);
    free(map);
    return rc;
}

/* ---- writer ------------------------------------------------------------- */

static int cmp_long(const void *a, const void *b)
{
    const long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

/* 1 when the source ids are unique (so the native file can keep them) and
 * none is -1 (the root marker); 0 otherwise; -1 out of memory. */
static int source_ids_usable(const phc_plant_graph *g)
{
    long *s = malloc(g->n * sizeof *s);
    size_t i;
    int ok = 1;
    if (!s)
        return -1;
    memcpy(s, g->source_id, g->n * sizeof *s);
    qsort(s, g->n, sizeof *s, cmp_long);
    for (i = 0; i < g->n; ++i)
        if (s[i] == -1 || (i > 0 && s[i] == s[i - 1]))
            ok = 0;
    free(s);
    return ok;
}

static int native_body_ids(FILE *f, const phc_plant_graph *g, int keep_ids)
{
    size_t i;
    if (fprintf(f, "# unit: m\n%s", native_columns[0]) < 0)
        return -1;
    for (i = 1; i < 12; ++i)
        fprintf(f, ",%s", native_columns[i]);
    fputc('\n', f);
    for (i = 0; i < g->n; ++i) {
        const size_t p = g->parent[i];
        const long id = keep_ids ? g->source_id[i] : (long)i;
        const long pid = p == PHC_PLANT_NO_PARENT ? -1 : keep_ids ? g->source_id[p] : (long)p;
        const double *h = g->head + 3 * i, *t = g->tail + 3 * i;
        if (fprintf(f, "%ld,%ld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%d\n", id,
                    pid, g->radius[i], g->length[i], h[0], h[1], h[2], t[0], t[1], t[2],
                    g->leaf[i] ? 1 : 0, g->fixed[i] ? 1 : 0) < 0)
            return -1;
    }
    return 0;
}

static int native_body_keep(FILE *f, const phc_plant_graph *g, const void *ctx)
{
    (void)ctx;
    return native_body_ids(f, g, 1);
}

static int native_body_index(FILE *f, const phc_plant_graph *g, const void *ctx)
{
    (void)ctx;
    return native_body_ids(f, g, 0);
}

int phc_plant_io_write_native(const char *path, const phc_plant_graph *g, phc_error *err)
{
    int rc, keep;
    if ((rc = phc_plant_io_check_writable("phc_plant_io_write_native", path, g, err)))
        return rc;
    keep = source_ids_usable(g);
    if (keep < 0)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    return phc_plant_io_write_atomically(path, g, keep ? native_body_keep : native_body_index, NULL,
                                         err);
}
