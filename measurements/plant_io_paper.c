/* The wilting paper's plant-graph files: reader and writer (plant_io.h).
 *
 * PAPER: see plant_io.h.  Vertex ids must be 0..N-1, each once, in any order;
 *   segment i of the graph is vertex id i.  The root is the vertex whose tail
 *   is nearest the origin (the first in file order on a tie, as in the
 *   authors' reader); on_leaf is 0 or 1.  Blank lines are skipped, CRLF is
 *   accepted.  The writer stores only tails: heads are rebuilt on reading
 *   (the root's head at the origin), so a graph whose heads are not its
 *   parents' tails does not survive the trip.  The writer refuses a graph
 *   whose root's tail is not the one nearest the origin, because reading it
 *   back would pick another root. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/plant_io.h"
#include "measurements/plant_io_internal.h"
#include "measurements/plant_io_text.h"

static int parse_count_line(const char *path, char *line, size_t number, const char *keyword,
                            const char *expect_where, long *count, phc_error *err)
{
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];
    size_t kl = strlen(keyword);
    char *rest;
    if (strncmp(line, keyword, kl) != 0 || !phc_plant_io_is_blank(line[kl]))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: expected '%s N' %s, found '%s'",
                             path, number, keyword, expect_where,
                             phc_plant_io_shorten(line, shown, sizeof shown));
    rest = phc_plant_io_trim(line + kl);
    if (phc_plant_io_parse_long(rest, count) != 0 || *count < 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: '%s': expected a count (a whole number >= 0) after '%s', "
                             "found '%s'",
                             path, number, keyword, keyword,
                             phc_plant_io_shorten(rest, shown, sizeof shown));
    return PHC_OK;
}

/* What the reader carries between its stages: the text cursor, the graph
 * being filled, the line of each vertex (for messages), the root and the
 * edges in file order. */
typedef struct paper_reader {
    const char *path;
    size_t length;          /* bytes of text: bounds the counts a header may announce */
    phc_plant_io_cursor cur;
    phc_plant_graph *g;
    size_t n, m;            /* vertices, edges */
    size_t *lines;          /* n: file line of vertex i */
    size_t root;            /* the vertex whose tail is nearest the origin */
    size_t *edge_a, *edge_b, *edge_line; /* m */
} paper_reader;

/* The n vertex lines 'id,x,y,z,radius,on_leaf': tails, radii, leaf flags,
 * and the root (tail nearest the origin, first in file order on a tie: the
 * authors' reader compares with a strict '<'). */
static int read_vertices(paper_reader *r, double unit, phc_error *err)
{
    static const char *const names[6] = {"id", "x", "y", "z", "radius", "on_leaf"};
    const char *path = r->path;
    phc_plant_graph *g = r->g;
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];
    double best = INFINITY;
    size_t i, number = 0, n = r->n;
    char *line;
    int rc;
    for (i = 0; i < n; ++i) {
        char *f[6];
        double v[6], d2;
        long id;
        int nf, k;
        const int got = phc_plant_io_next_line(&r->cur, &line, &number, 0);
        if (!got || strncmp(line, "edges", 5) == 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: expected %zu vertex lines after 'verts %zu', found "
                                 "%zu before %s",
                                 path, got ? number : r->cur.next_line - 1, n, n, i,
                                 got ? "'edges'" : "the end of the file");
        nf = phc_plant_io_split_fields(line, ',', f, 6);
        if (nf != 6)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: expected 6 comma-separated fields "
                                 "(id,x,y,z,radius,on_leaf), found %d",
                                 path, number, nf);
        if (phc_plant_io_parse_long(f[0], &id) != 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: field 'id': expected a whole number, found '%s'",
                                 path, number, phc_plant_io_shorten(f[0], shown, sizeof shown));
        if ((rc = phc_plant_io_parse_number_fields(path, number, f, names, 1, 6, v, err)))
            return rc;
        if (id < 0 || (unsigned long)id >= n)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: vertex id %ld out of range 0..%zu",
                                 path, number, id, n - 1);
        if (r->lines[id])
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: vertex id %ld repeats line %zu",
                                 path, number, id, r->lines[id]);
        r->lines[id] = number;
        if ((rc = phc_plant_io_check_point(path, number, id, "coordinate ", v + 1, err)))
            return rc;
        if ((rc = phc_plant_io_check_radius(path, number, id, v[4], err)))
            return rc;
        if (!(v[5] == 0.0 || v[5] == 1.0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: field 'on_leaf': expected 0 or 1, found '%s'", path,
                                 number, phc_plant_io_shorten(f[5], shown, sizeof shown));
        for (k = 0; k < 3; ++k)
            g->tail[3 * id + k] = v[1 + k] * unit;
        g->radius[id] = v[4] * unit;
        g->leaf[id] = v[5] != 0.0;
        g->source_id[id] = id;
        d2 = v[1] * v[1] + v[2] * v[2] + v[3] * v[3];
        if (d2 < best) {
            best = d2;
            r->root = (size_t)id;
        }
    }
    return PHC_OK;
}

/* The 'edges M' header and the M edge lines 'id1,id2', checked with
 * union-find in file order so that the first edge closing a loop is the one
 * reported; then nothing may follow.  `uf` (n) is scratch. */
static int read_edges(paper_reader *r, size_t *uf, phc_error *err)
{
    const char *path = r->path;
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];
    size_t i, m, number = 0, n = r->n;
    long count;
    char *line;
    int rc;
    if (!phc_plant_io_next_line(&r->cur, &line, &number, 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: expected 'edges M' after the %zu vertex lines, found the "
                             "end of the file",
                             path, r->cur.next_line - 1, n);
    if ((rc = parse_count_line(path, line, number, "edges",
                               "after the vertex lines (more vertex lines than 'verts' says?)",
                               &count, err)))
        return rc;
    if ((unsigned long)count > (size_t)-1 / 64 || (double)count > (double)r->length)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: 'edges %ld' announces more edge lines than the file can "
                             "hold",
                             path, number, count);
    r->m = m = (size_t)count;
    r->edge_a = malloc((m ? m : 1) * sizeof *r->edge_a);
    r->edge_b = malloc((m ? m : 1) * sizeof *r->edge_b);
    r->edge_line = malloc((m ? m : 1) * sizeof *r->edge_line);
    if (!r->edge_a || !r->edge_b || !r->edge_line)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    for (i = 0; i < n; ++i)
        uf[i] = i;
    for (i = 0; i < m; ++i) {
        char *f[2];
        long a, b;
        size_t ra, rb, j;
        int nf;
        if (!phc_plant_io_next_line(&r->cur, &line, &number, 0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: expected %zu edge lines after 'edges %zu', found %zu "
                                 "before the end of the file",
                                 path, r->cur.next_line - 1, m, m, i);
        nf = phc_plant_io_split_fields(line, ',', f, 2);
        if (nf != 2)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: expected 2 comma-separated fields (id1,id2), found %d",
                                 path, number, nf);
        if (phc_plant_io_parse_long(f[0], &a) != 0 || phc_plant_io_parse_long(f[1], &b) != 0) {
            const char *bad = phc_plant_io_parse_long(f[0], &a) != 0 ? f[0] : f[1];
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: edge: expected a whole-number segment id, found '%s'",
                                 path, number, phc_plant_io_shorten(bad, shown, sizeof shown));
        }
        if (a < 0 || (unsigned long)a >= n || b < 0 || (unsigned long)b >= n)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: edge %ld,%ld: segment id %ld out of range 0..%zu",
                                 path, number, a, b, (a < 0 || (unsigned long)a >= n) ? a : b,
                                 n - 1);
        if (a == b)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: edge %ld,%ld: a segment cannot be its own neighbour",
                                 path, number, a, b);
        /* find with path halving */
        for (ra = (size_t)a; uf[ra] != ra; ra = uf[ra])
            uf[ra] = uf[uf[ra]];
        for (rb = (size_t)b; uf[rb] != rb; rb = uf[rb])
            uf[rb] = uf[uf[rb]];
        if (ra == rb) {
            for (j = 0; j < i; ++j)
                if ((r->edge_a[j] == (size_t)a && r->edge_b[j] == (size_t)b) ||
                    (r->edge_a[j] == (size_t)b && r->edge_b[j] == (size_t)a))
                    return phc_error_set(err, PHC_ERR_INPUT,
                                         "%s:%zu: edge %ld,%ld repeats the edge of line %zu",
                                         path, number, a, b, r->edge_line[j]);
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: edge %ld,%ld closes a cycle: segments %ld and %ld are "
                                 "already connected by earlier edges",
                                 path, number, a, b, a, b);
        }
        uf[ra] = rb;
        r->edge_a[i] = (size_t)a;
        r->edge_b[i] = (size_t)b;
        r->edge_line[i] = number;
    }
    if (phc_plant_io_next_line(&r->cur, &line, &number, 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: unexpected line after the %zu edges that 'edges %zu' "
                             "announced: '%s'",
                             path, number, m, m, phc_plant_io_shorten(line, shown, sizeof shown));
    return PHC_OK;
}

/* Parents by breadth-first search from the root over the edges (as CSR
 * adjacency), then heads (the parent's tail; the root's head at the origin)
 * and lengths, parents first.  `fill` (n) is scratch. */
static int orient_from_root(paper_reader *r, size_t *fill, phc_error *err)
{
    const char *path = r->path;
    phc_plant_graph *g = r->g;
    const size_t n = r->n, m = r->m, root = r->root;
    size_t *adj_start = calloc(n + 1, sizeof *adj_start);
    size_t *adj = malloc((m ? 2 * m : 1) * sizeof *adj);
    size_t *queue = malloc(n * sizeof *queue);
    unsigned char *seen = calloc(n, 1);
    size_t i, qh = 0, qt = 0;
    int rc = PHC_OK;
    if (!adj_start || !adj || !queue || !seen) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    for (i = 0; i < m; ++i) {
        ++adj_start[r->edge_a[i] + 1];
        ++adj_start[r->edge_b[i] + 1];
    }
    for (i = 0; i < n; ++i)
        adj_start[i + 1] += adj_start[i];
    memcpy(fill, adj_start, n * sizeof *fill);
    for (i = 0; i < m; ++i) {
        adj[fill[r->edge_a[i]]++] = r->edge_b[i];
        adj[fill[r->edge_b[i]]++] = r->edge_a[i];
    }
    queue[qt++] = root;
    seen[root] = 1;
    g->parent[root] = PHC_PLANT_NO_PARENT;
    while (qh < qt) {
        const size_t u = queue[qh++];
        size_t e;
        for (e = adj_start[u]; e < adj_start[u + 1]; ++e) {
            const size_t v = adj[e];
            if (seen[v])
                continue;
            seen[v] = 1;
            g->parent[v] = u;
            queue[qt++] = v;
        }
    }
    if (qt < n) {
        const size_t count_out = n - qt;
        for (i = 0; i < n && seen[i]; ++i)
            ;
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: segment %zu is not connected to the root (segment %zu, "
                           "the tail nearest the origin): %zu segment%s unreachable",
                           path, r->lines[i], i, root, count_out,
                           count_out == 1 ? " is" : "s are");
        goto done;
    }
    for (i = 0; i < n; ++i) {
        const size_t u = queue[i];
        const size_t p = g->parent[u];
        int k;
        for (k = 0; k < 3; ++k)
            g->head[3 * u + k] = p == PHC_PLANT_NO_PARENT ? 0.0 : g->tail[3 * p + k];
        g->length[u] = phc_plant_io_distance3(g->tail + 3 * u, g->head + 3 * u);
        if (g->length[u] > 0 && isfinite(g->length[u]))
            continue;
        if (p == PHC_PLANT_NO_PARENT)
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %zu: zero-length segment: the root's tail is at "
                               "the origin, where its head is",
                               path, r->lines[u], u);
        else
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %zu: zero-length segment: its tail equals the "
                               "tail of its parent, segment %zu (line %zu)",
                               path, r->lines[u], u, p, r->lines[p]);
        goto done;
    }
done:
    free(adj_start);
    free(adj);
    free(queue);
    free(seen);
    return rc;
}

int phc_plant_io_read_paper(const char *path, char *text, size_t length, double unit,
                            phc_plant_graph **out, phc_error *err)
{
    paper_reader r = {.path = path, .length = length, .cur = {text, text + length, 1}};
    size_t number = 0, *scratch = NULL;
    long count;
    char *line;
    int rc;

    if (!phc_plant_io_next_line(&r.cur, &line, &number, 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: expected 'verts N', found an empty file",
                             path);
    if ((rc = parse_count_line(path, line, number, "verts", "on the first line", &count, err)))
        return rc;
    if (count == 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: 'verts 0': a plant needs at least one segment", path,
                             number);
    if ((unsigned long)count > (size_t)-1 / 64 || (double)count > (double)length)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: 'verts %ld' announces more vertex lines than the file "
                             "can hold",
                             path, number, count);
    r.n = (size_t)count;
    r.g = phc_plant_graph_new(r.n);
    r.lines = calloc(r.n, sizeof *r.lines);
    scratch = malloc(r.n * sizeof *scratch);
    if (!r.g || !r.lines || !scratch)
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    else if (!(rc = read_vertices(&r, unit, err)) && !(rc = read_edges(&r, scratch, err)) &&
             !(rc = orient_from_root(&r, scratch, err)) &&
             !(rc = phc_plant_graph_finish(r.g, path, err))) {
        *out = r.g;
        r.g = NULL;
    }
    phc_plant_graph_free(r.g);
    free(r.lines);
    free(scratch);
    free(r.edge_line);
    free(r.edge_a);
    free(r.edge_b);
    return rc;
}

/* ---- writer ------------------------------------------------------------- */

static int paper_body(FILE *f, const phc_plant_graph *g, const void *ctx)
{
    (void)ctx;
    size_t i;
    if (fprintf(f, "verts %zu\n", g->n) < 0)
        return -1;
    for (i = 0; i < g->n; ++i) {
        const double *t = g->tail + 3 * i;
        if (fprintf(f, "%zu,%.17g,%.17g,%.17g,%.17g,%d\n", i, t[0], t[1], t[2], g->radius[i],
                    g->leaf[i] ? 1 : 0) < 0)
            return -1;
    }
    if (fprintf(f, "edges %zu\n", g->n - 1) < 0)
        return -1;
    /* breadth-first, parent first, like the published files */
    for (i = 1; i < g->n; ++i) {
        const size_t u = g->order[i];
        if (fprintf(f, "%zu,%zu\n", g->parent[u], u) < 0)
            return -1;
    }
    return 0;
}

int phc_plant_io_write_paper(const char *path, const phc_plant_graph *g, phc_error *err)
{
    size_t i;
    double d_root;
    int rc;
    if ((rc = phc_plant_io_check_writable("phc_plant_io_write_paper", path, g, err)))
        return rc;
    /* The reader takes as root the tail nearest the origin (first on a
     * tie): refuse a graph that would come back with another root. */
    d_root = g->tail[3 * g->root] * g->tail[3 * g->root] +
             g->tail[3 * g->root + 1] * g->tail[3 * g->root + 1] +
             g->tail[3 * g->root + 2] * g->tail[3 * g->root + 2];
    for (i = 0; i < g->n; ++i) {
        const double *t = g->tail + 3 * i;
        const double d = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
        if (i != g->root && (d < d_root || (d == d_root && i < g->root)))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: cannot write in the paper format: segment %ld's tail is "
                                 "nearer the origin than the root's (segment %ld), so a reader "
                                 "would take it as the root; translate the plant so that the "
                                 "root's tail is nearest the origin",
                                 path, g->source_id[i], g->source_id[g->root]);
    }
    return phc_plant_io_write_atomically(path, g, paper_body, NULL, err);
}
