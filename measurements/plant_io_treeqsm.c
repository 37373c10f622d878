/* TreeQSM cylinder files: reader (plant_io.h).
 *
 * TREEQSM: one cylinder a line, 15 columns (aRchi's export) or 16 (some
 *   TreeQSM versions append one more; it is ignored), separated by tabs or
 *   blanks.  Cylinder k (1-based line order among non-blank lines) is segment
 *   k-1 with source_id k.  head = start, tail = start + length * axis (the
 *   axis must be a unit vector to 1%; it is normalised).  TreeQSM has no
 *   leaves: every segment has leaf = 0. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/plant_io.h"
#include "measurements/plant_io_internal.h"
#include "measurements/plant_io_text.h"

static int count_treeqsm_lines(char *text, size_t length)
{
    /* non-blank lines; used to size the graph before parsing */
    size_t i, count = 0;
    int in_line = 0;
    for (i = 0; i < length; ++i) {
        const char c = text[i];
        if (c == '\n' || c == '\r')
            in_line = 0;
        else if (!phc_plant_io_is_blank(c) && !in_line) {
            in_line = 1;
            ++count;
        }
    }
    return count > INT_MAX ? -1 : (int)count;
}

int phc_plant_io_read_treeqsm(const char *path, char *text, size_t length, double unit,
                              phc_plant_graph **out, phc_error *err)
{
    static const char *const names[9] = {"radius", "length", "start x", "start y", "start z",
                                         "axis x", "axis y", "axis z", "parent"};
    phc_plant_io_cursor cur = {text, text + length, 1};
    phc_plant_graph *g = NULL;
    size_t *lines = NULL, n, i, number = 0;
    int counted = count_treeqsm_lines(text, length), rc;
    char *line;
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];

    if (counted <= 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             counted == 0 ? "%s:1: expected TreeQSM cylinder lines, found an "
                                            "empty file"
                                          : "%s:1: too many lines",
                             path);
    n = (size_t)counted;
    g = phc_plant_graph_new(n);
    lines = malloc(n * sizeof *lines);
    if (!g || !lines) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    for (i = 0; i < n && phc_plant_io_next_line(&cur, &line, &number, 0); ++i) {
        char *f[16];
        double v[9], axis_norm;
        long parent;
        int nf = phc_plant_io_split_fields(line, 0, f, 16), k;
        const long id = (long)i + 1;
        lines[i] = number;
        if (nf != 15 && nf != 16) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: expected 15 or 16 tab-separated TreeQSM columns "
                               "(radius, length, start xyz, axis xyz, parent, ...), found %d",
                               path, number, nf);
            goto fail;
        }
        for (k = 0; k < 8; ++k)
            if (phc_plant_io_parse_double(f[k], &v[k]) != 0) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column %d (%s): expected a number, found '%s'", path,
                                   number, k + 1, names[k],
                                   phc_plant_io_shorten(f[k], shown, sizeof shown));
                goto fail;
            }
        if (phc_plant_io_parse_long(f[8], &parent) != 0) {
            /* TreeQSM writes integers; accept "3.0" but not "3.5" */
            double pv;
            if (phc_plant_io_parse_double(f[8], &pv) != 0 || pv != floor(pv) || fabs(pv) > 1e15) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column 9 (parent): expected a whole number, found "
                                   "'%s'",
                                   path, number, phc_plant_io_shorten(f[8], shown, sizeof shown));
                goto fail;
            }
            parent = (long)pv;
        }
        if ((rc = phc_plant_io_check_radius(path, number, id, v[0], err)))
            goto fail;
        if (!(isfinite(v[1]) && v[1] > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: length must be positive and finite, found %g",
                               path, number, id, v[1]);
            goto fail;
        }
        if ((rc = phc_plant_io_check_point(path, number, id, "start ", v + 2, err)) ||
            (rc = phc_plant_io_check_point(path, number, id, "axis ", v + 5, err)))
            goto fail;
        axis_norm = sqrt(v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
        if (!(fabs(axis_norm - 1.0) <= 0.01)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: the axis must be a unit vector, found "
                               "length %g",
                               path, number, id, axis_norm);
            goto fail;
        }
        if (parent < 0 || (unsigned long)parent > n) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: parent %ld out of range 0..%zu "
                               "(1-based cylinder number, 0 for none)",
                               path, number, id, parent, n);
            goto fail;
        }
        if (parent == id) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: a cylinder cannot be its own parent", path,
                               number, id);
            goto fail;
        }
        g->parent[i] = parent == 0 ? PHC_PLANT_NO_PARENT : (size_t)(parent - 1);
        g->radius[i] = v[0] * unit;
        g->length[i] = v[1] * unit;
        for (k = 0; k < 3; ++k) {
            g->head[3 * i + k] = v[2 + k] * unit;
            g->tail[3 * i + k] = (v[2 + k] + v[1] * v[5 + k] / axis_norm) * unit;
        }
        /* A length below the rounding of the start coordinates leaves the
         * tail on the start: refuse it as the native reader would (same
         * relative tolerance, 1e-4). */
        const double geom = phc_plant_io_distance3(g->tail + 3 * i, g->head + 3 * i);
        if (!(fabs(geom - g->length[i]) <= 1e-4 * g->length[i])) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: length %g is lost in the rounding of its "
                               "start point: |tail - start| = %g",
                               path, number, id, v[1], geom / unit);
            goto fail;
        }
        g->source_id[i] = id;
    }
    if ((rc = phc_plant_io_check_structure(path, g, lines, err)) ||
        (rc = phc_plant_graph_finish(g, path, err)))
        goto fail;
    *out = g;
    g = NULL;
fail:
    phc_plant_graph_free(g);
    free(lines);
    return rc;
}
