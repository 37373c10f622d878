/* SWC skeletons: reader (plant_io.h).
 *
 * SWC: `#` lines are comments; each sample line is `id type x y z radius
 *   parent` (whitespace separated; parent -1 marks the root sample; ids
 *   unique, parents may appear before or after their children).  Each sample
 *   other than the root sample becomes one segment, from its parent sample's
 *   position (head) to its own (tail), with the sample's own radius;
 *   source_id is the sample id.  ROOT CONVENTION: the root sample is a point,
 *   not a segment.  The first segment (in file order) whose parent is the
 *   root sample becomes the root segment; any other segments hanging from the
 *   root sample get that first segment as their parent (their heads stay at
 *   the root sample's position).  The SWC type column is ignored: every
 *   segment has leaf = 0.  A file needs at least two samples. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/plant_io.h"
#include "measurements/plant_io_internal.h"
#include "measurements/plant_io_text.h"

int phc_plant_io_read_swc(const char *path, char *text, size_t length, double unit,
                          phc_plant_graph **out, phc_error *err)
{
    static const char *const names[7] = {"id", "type", "x", "y", "z", "radius", "parent"};
    phc_plant_io_cursor cur = {text, text + length, 1};
    phc_plant_graph *g = NULL;
    phc_plant_io_id_entry *map = NULL;
    long *ids = NULL, *parents = NULL;
    double *pos = NULL, *rad = NULL;
    size_t *lines = NULL, *seg_of = NULL, *seg_lines = NULL;
    size_t cap = 0, m = 0, i, number = 0, root_sample = (size_t)-1, first_child = (size_t)-1;
    size_t nseg, s;
    char *line;
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];
    int rc;

    while (phc_plant_io_next_line(&cur, &line, &number, 1)) {
        char *f[7];
        double v[7];
        int nf = phc_plant_io_split_fields(line, 0, f, 7), k;
        if (nf != 7) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: expected 7 SWC fields (id type x y z radius parent), "
                               "found %d",
                               path, number, nf);
            goto fail;
        }
        if (m == cap) {
            size_t nc = cap ? 2 * cap : 1024;
            long *ni = realloc(ids, nc * sizeof *ids);
            if (ni)
                ids = ni;
            long *np = realloc(parents, nc * sizeof *parents);
            if (np)
                parents = np;
            double *nq = realloc(pos, 3 * nc * sizeof *pos);
            if (nq)
                pos = nq;
            double *nr = realloc(rad, nc * sizeof *rad);
            if (nr)
                rad = nr;
            size_t *nl = realloc(lines, nc * sizeof *lines);
            if (nl)
                lines = nl;
            if (!ni || !np || !nq || !nr || !nl) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
                goto fail;
            }
            cap = nc;
        }
        if (phc_plant_io_parse_long(f[0], &ids[m]) != 0 ||
            phc_plant_io_parse_long(f[6], &parents[m]) != 0) {
            const int bad = phc_plant_io_parse_long(f[0], &ids[m]) != 0 ? 0 : 6;
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: field '%s': expected a whole number, found '%s'", path,
                               number, names[bad],
                               phc_plant_io_shorten(f[bad], shown, sizeof shown));
            goto fail;
        }
        if ((rc = phc_plant_io_parse_number_fields(path, number, f, names, 1, 6, v, err)))
            goto fail;
        if ((rc = phc_plant_io_check_point(path, number, ids[m], "coordinate ", v + 2, err)))
            goto fail;
        if (!(isfinite(v[5]) && v[5] > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: sample %ld: radius must be positive and finite, found %g",
                               path, number, ids[m], v[5]);
            goto fail;
        }
        if (parents[m] == ids[m]) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: sample %ld: a sample cannot be its own parent", path,
                               number, ids[m]);
            goto fail;
        }
        if (parents[m] < 0 && parents[m] != -1) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: sample %ld: parent must be a sample id or -1 for the "
                               "root, found %ld",
                               path, number, ids[m], parents[m]);
            goto fail;
        }
        for (k = 0; k < 3; ++k)
            pos[3 * m + k] = v[2 + k] * unit;
        rad[m] = v[5] * unit;
        lines[m] = number;
        if (parents[m] == -1) {
            if (root_sample != (size_t)-1) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: two roots: samples %ld (line %zu) and %ld have "
                                   "parent -1; phytocal reads one tree per file",
                                   path, number, ids[root_sample], lines[root_sample], ids[m]);
                goto fail;
            }
            root_sample = m;
        }
        ++m;
    }
    if (m < 2) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: found %zu sample%s; a plant needs at least 2 (a segment "
                           "joins a sample to its parent)",
                           path, number ? number : 1, m, m == 1 ? "" : "s");
        goto fail;
    }
    if (root_sample == (size_t)-1) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: no root: no sample has parent -1", path, lines[0]);
        goto fail;
    }
    if ((rc = phc_plant_io_build_id_map(path, ids, lines, m, "sample", &map, err)))
        goto fail;

    /* segments: every sample but the root sample, in file order */
    nseg = m - 1;
    g = phc_plant_graph_new(nseg);
    seg_of = malloc(m * sizeof *seg_of);
    seg_lines = malloc(nseg * sizeof *seg_lines);
    if (!g || !seg_of || !seg_lines) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    for (i = 0, s = 0; i < m; ++i)
        seg_of[i] = i == root_sample ? (size_t)-1 : s++;
    for (i = 0; i < m; ++i) {
        size_t p, seg;
        int k;
        if (i == root_sample)
            continue;
        seg = seg_of[i];
        p = phc_plant_io_find_id(map, m, parents[i]);
        if (p == (size_t)-1) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: sample %ld: parent %ld is not a sample id in this file",
                               path, lines[i], ids[i], parents[i]);
            goto fail;
        }
        for (k = 0; k < 3; ++k) {
            g->head[3 * seg + k] = pos[3 * p + k];
            g->tail[3 * seg + k] = pos[3 * i + k];
        }
        g->length[seg] = phc_plant_io_distance3(pos + 3 * i, pos + 3 * p);
        if (!(g->length[seg] > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: sample %ld: zero-length segment: the sample lies at the "
                               "position of its parent sample %ld (line %zu)",
                               path, lines[i], ids[i], parents[i], lines[p]);
            goto fail;
        }
        if (!isfinite(g->length[seg])) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: sample %ld: the segment from its parent sample is "
                               "infinitely long",
                               path, lines[i], ids[i]);
            goto fail;
        }
        g->radius[seg] = rad[i];
        g->source_id[seg] = ids[i];
        seg_lines[seg] = lines[i];
        if (p == root_sample) {
            /* the root convention: see the top of this file */
            if (first_child == (size_t)-1) {
                first_child = seg;
                g->parent[seg] = PHC_PLANT_NO_PARENT;
            } else {
                g->parent[seg] = first_child;
            }
        } else {
            g->parent[seg] = seg_of[p];
        }
    }
    if (first_child == (size_t)-1) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: the root sample %ld has no children: no sample is "
                           "connected to it",
                           path, lines[root_sample], ids[root_sample]);
        goto fail;
    }
    /* SWC samples that are attached to the root sample only through
     * segments attached to the first child keep nothing lost: every sample
     * is a segment.  A cycle among samples shows up here. */
    if ((rc = phc_plant_io_check_structure(path, g, seg_lines, err)) ||
        (rc = phc_plant_graph_finish(g, path, err)))
        goto fail;
    *out = g;
    g = NULL;
fail:
    phc_plant_graph_free(g);
    free(map);
    free(ids);
    free(parents);
    free(pos);
    free(rad);
    free(lines);
    free(seg_of);
    free(seg_lines);
    return rc;
}
