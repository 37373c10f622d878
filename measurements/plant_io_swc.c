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

/* The samples of an SWC file, in file order, before they become segments. */
typedef struct swc_samples {
    long *ids, *parents;
    double *pos, *rad; /* 3m, m: metres */
    size_t *lines;     /* file line of each sample */
    size_t m, cap;
    size_t root;       /* the sample with parent -1, (size_t)-1 before it is seen */
} swc_samples;

static void swc_samples_free(swc_samples *s)
{
    free(s->ids);
    free(s->parents);
    free(s->pos);
    free(s->rad);
    free(s->lines);
}

/* Room for one more sample; 0 or -1 when out of memory (s stays valid). */
static int swc_grow(swc_samples *s)
{
    size_t nc;
    long *ni, *np;
    double *nq, *nr;
    size_t *nl;
    if (s->m < s->cap)
        return 0;
    nc = s->cap ? 2 * s->cap : 1024;
    if ((ni = realloc(s->ids, nc * sizeof *ni)))
        s->ids = ni;
    if ((np = realloc(s->parents, nc * sizeof *np)))
        s->parents = np;
    if ((nq = realloc(s->pos, 3 * nc * sizeof *nq)))
        s->pos = nq;
    if ((nr = realloc(s->rad, nc * sizeof *nr)))
        s->rad = nr;
    if ((nl = realloc(s->lines, nc * sizeof *nl)))
        s->lines = nl;
    if (!ni || !np || !nq || !nr || !nl)
        return -1;
    s->cap = nc;
    return 0;
}

/* Every sample line 'id type x y z radius parent', checked one by one;
 * then at least 2 samples and exactly one root. */
static int read_samples(const char *path, char *text, size_t length, double unit,
                        swc_samples *s, phc_error *err)
{
    static const char *const names[7] = {"id", "type", "x", "y", "z", "radius", "parent"};
    phc_plant_io_cursor cur = {text, text + length, 1};
    size_t number = 0;
    char *line;
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];
    int rc;
    s->root = (size_t)-1;
    while (phc_plant_io_next_line(&cur, &line, &number, 1)) {
        char *f[7];
        double v[7];
        const size_t m = s->m;
        int nf = phc_plant_io_split_fields(line, 0, f, 7), k;
        if (nf != 7)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: expected 7 SWC fields (id type x y z radius parent), "
                                 "found %d",
                                 path, number, nf);
        if (swc_grow(s) != 0)
            return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        if (phc_plant_io_parse_long(f[0], &s->ids[m]) != 0 ||
            phc_plant_io_parse_long(f[6], &s->parents[m]) != 0) {
            const int bad = phc_plant_io_parse_long(f[0], &s->ids[m]) != 0 ? 0 : 6;
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: field '%s': expected a whole number, found '%s'", path,
                                 number, names[bad],
                                 phc_plant_io_shorten(f[bad], shown, sizeof shown));
        }
        if ((rc = phc_plant_io_parse_number_fields(path, number, f, names, 1, 6, v, err)))
            return rc;
        if ((rc = phc_plant_io_check_point(path, number, s->ids[m], "coordinate ", v + 2, err)))
            return rc;
        if (!(isfinite(v[5]) && v[5] > 0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: sample %ld: radius must be positive and finite, found "
                                 "%g",
                                 path, number, s->ids[m], v[5]);
        if (s->parents[m] == s->ids[m])
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: sample %ld: a sample cannot be its own parent", path,
                                 number, s->ids[m]);
        if (s->parents[m] < 0 && s->parents[m] != -1)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: sample %ld: parent must be a sample id or -1 for the "
                                 "root, found %ld",
                                 path, number, s->ids[m], s->parents[m]);
        for (k = 0; k < 3; ++k)
            s->pos[3 * m + k] = v[2 + k] * unit;
        s->rad[m] = v[5] * unit;
        s->lines[m] = number;
        if (s->parents[m] == -1) {
            if (s->root != (size_t)-1)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: two roots: samples %ld (line %zu) and %ld have "
                                     "parent -1; phytocal reads one tree per file",
                                     path, number, s->ids[s->root], s->lines[s->root],
                                     s->ids[m]);
            s->root = m;
        }
        ++s->m;
    }
    if (s->m < 2)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: found %zu sample%s; a plant needs at least 2 (a segment "
                             "joins a sample to its parent)",
                             path, number ? number : 1, s->m, s->m == 1 ? "" : "s");
    if (s->root == (size_t)-1)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: no root: no sample has parent -1",
                             path, s->lines[0]);
    return PHC_OK;
}

/* Segment i of g joins every sample but the root sample to its parent
 * sample, in file order; the root convention is at the top of this file.
 * seg_of (m) and seg_lines (m - 1) are the caller's scratch. */
static int build_segments(const char *path, const swc_samples *s,
                          const phc_plant_io_id_entry *map, phc_plant_graph *g, size_t *seg_of,
                          size_t *seg_lines, phc_error *err)
{
    const size_t m = s->m;
    size_t i, k, first_child = (size_t)-1, next = 0;
    for (i = 0; i < m; ++i)
        seg_of[i] = i == s->root ? (size_t)-1 : next++;
    for (i = 0; i < m; ++i) {
        size_t p, seg;
        if (i == s->root)
            continue;
        seg = seg_of[i];
        p = phc_plant_io_find_id(map, m, s->parents[i]);
        if (p == (size_t)-1)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: sample %ld: parent %ld is not a sample id in this file",
                                 path, s->lines[i], s->ids[i], s->parents[i]);
        for (k = 0; k < 3; ++k) {
            g->head[3 * seg + k] = s->pos[3 * p + k];
            g->tail[3 * seg + k] = s->pos[3 * i + k];
        }
        g->length[seg] = phc_plant_io_distance3(s->pos + 3 * i, s->pos + 3 * p);
        if (!(g->length[seg] > 0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: sample %ld: zero-length segment: the sample lies at "
                                 "the position of its parent sample %ld (line %zu)",
                                 path, s->lines[i], s->ids[i], s->parents[i], s->lines[p]);
        if (!isfinite(g->length[seg]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: sample %ld: the segment from its parent sample is "
                                 "infinitely long",
                                 path, s->lines[i], s->ids[i]);
        g->radius[seg] = s->rad[i];
        g->source_id[seg] = s->ids[i];
        seg_lines[seg] = s->lines[i];
        if (p != s->root)
            g->parent[seg] = seg_of[p];
        else if (first_child == (size_t)-1) {
            first_child = seg;
            g->parent[seg] = PHC_PLANT_NO_PARENT;
        } else {
            g->parent[seg] = first_child;
        }
    }
    if (first_child == (size_t)-1)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: the root sample %ld has no children: no sample is "
                             "connected to it",
                             path, s->lines[s->root], s->ids[s->root]);
    return PHC_OK;
}

int phc_plant_io_read_swc(const char *path, char *text, size_t length, double unit,
                          phc_plant_graph **out, phc_error *err)
{
    swc_samples s = {0};
    phc_plant_io_id_entry *map = NULL;
    phc_plant_graph *g = NULL;
    size_t *seg_of = NULL, *seg_lines = NULL;
    int rc;
    if ((rc = read_samples(path, text, length, unit, &s, err)) ||
        (rc = phc_plant_io_build_id_map(path, s.ids, s.lines, s.m, "sample", &map, err)))
        goto done;
    g = phc_plant_graph_new(s.m - 1);
    seg_of = malloc(s.m * sizeof *seg_of);
    seg_lines = malloc((s.m - 1) * sizeof *seg_lines);
    if (!g || !seg_of || !seg_lines) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    /* a cycle among samples shows up in the structure check */
    if ((rc = build_segments(path, &s, map, g, seg_of, seg_lines, err)) ||
        (rc = phc_plant_io_check_structure(path, g, seg_lines, err)) ||
        (rc = phc_plant_graph_finish(g, path, err)))
        goto done;
    *out = g;
    g = NULL;
done:
    phc_plant_graph_free(g);
    swc_samples_free(&s);
    free(map);
    free(seg_of);
    free(seg_lines);
    return rc;
}
