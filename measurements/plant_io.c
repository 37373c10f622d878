/* Reading and writing plant graphs: see plant_io.h.
 *
 * Conventions shared by every reader:
 *   - every message names the file and the line ("plant.txt:12: ...");
 *   - numbers are parsed in the C locale, and a field must be consumed whole;
 *   - per-segment problems (bad radius, zero length, NaN position) are
 *     reported at the line that defines the segment; structural problems
 *     (two roots, cycles) at the line of a segment involved;
 *   - the graph is finished (phc_plant_graph_finish) before it is returned.
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
 *     trip).
 *
 * PAPER: see plant_io.h.  Vertex ids must be 0..N-1, each once, in any order;
 *   segment i of the graph is vertex id i.  The root is the vertex whose tail
 *   is nearest the origin (the first in file order on a tie, as in the
 *   authors' reader); on_leaf is 0 or 1.  Blank lines are skipped, CRLF is
 *   accepted.  The writer stores only tails: heads are rebuilt on reading
 *   (the root's head at the origin), so a graph whose heads are not its
 *   parents' tails does not survive the trip.  The writer refuses a graph
 *   whose root's tail is not the one nearest the origin, because reading it
 *   back would pick another root.
 *
 * TREEQSM: one cylinder a line, 15 columns (aRchi's export) or 16 (some
 *   TreeQSM versions append one more; it is ignored), separated by tabs or
 *   blanks.  Cylinder k (1-based line order among non-blank lines) is segment
 *   k-1 with source_id k.  head = start, tail = start + length * axis (the
 *   axis must be a unit vector to 1%; it is normalised).  TreeQSM has no
 *   leaves: every segment has leaf = 0.
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
#include "measurements/plant_io.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "measurements/atomic_file.h"
#include "measurements/c_number.h"
#include "measurements/table.h"
#include "measurements/text_file.h"

#define SHOW_MAX 40

/* ---- small text helpers ------------------------------------------------ */

/* A printable, shortened copy of s for messages. */
static const char *shorten(const char *s, char *out, size_t size)
{
    size_t i = 0;
    for (; s[i] && i + 4 < size && i < SHOW_MAX; ++i)
        out[i] = (unsigned char)s[i] < 32 ? '?' : s[i];
    if (s[i]) {
        out[i++] = '.';
        out[i++] = '.';
        out[i++] = '.';
    }
    out[i] = '\0';
    return out;
}

typedef struct line_cursor {
    char *p, *end;
    size_t next_line; /* number of the line p starts */
} line_cursor;

static int is_blank(char c)
{
    return c == ' ' || c == '\t';
}

/* Cuts the next line (LF, CRLF or CR ends) out of the buffer in place.
 * Returns 0 at the end of the text. */
static int next_raw_line(line_cursor *c, char **line, size_t *number)
{
    char *s, *q;
    if (c->p >= c->end)
        return 0;
    s = c->p;
    q = s;
    while (q < c->end && *q != '\n' && *q != '\r')
        ++q;
    if (q < c->end) {
        if (*q == '\r' && q + 1 < c->end && q[1] == '\n') {
            *q = '\0';
            c->p = q + 2;
        } else {
            *q = '\0';
            c->p = q + 1;
        }
    } else {
        c->p = c->end; /* the buffer's terminating NUL ends the line */
    }
    *line = s;
    *number = c->next_line++;
    return 1;
}

static char *trim(char *s)
{
    char *e;
    while (is_blank(*s))
        ++s;
    e = s + strlen(s);
    while (e > s && is_blank(e[-1]))
        *--e = '\0';
    return s;
}

/* Next line that is not blank (and, when skip_hash, not a `#` comment). */
static int next_line(line_cursor *c, char **line, size_t *number, int skip_hash)
{
    char *s;
    while (next_raw_line(c, &s, number)) {
        s = trim(s);
        if (!*s || (skip_hash && *s == '#'))
            continue;
        *line = s;
        return 1;
    }
    return 0;
}

/* Splits in place: delim ',' (fields trimmed) or 0 (runs of blanks).
 * Returns the number of fields found (may exceed max; only max stored). */
static int split_fields(char *s, char delim, char **fields, int max)
{
    int n = 0;
    if (delim) {
        for (;;) {
            char *d = strchr(s, delim);
            if (d)
                *d = '\0';
            if (n < max)
                fields[n] = trim(s);
            ++n;
            if (!d)
                break;
            s = d + 1;
        }
    } else {
        while (*s) {
            while (is_blank(*s))
                ++s;
            if (!*s)
                break;
            if (n < max)
                fields[n] = s;
            ++n;
            while (*s && !is_blank(*s))
                ++s;
            if (*s)
                *s++ = '\0';
        }
    }
    return n;
}

/* strtod on the whole field (the caller holds a C-locale scope).  NaN and
 * infinities parse; callers check finiteness with a precise message. */
static int parse_double(const char *s, double *x)
{
    char *end;
    if (!*s)
        return -1;
    errno = 0;
    *x = strtod(s, &end);
    return (end == s || *end) ? -1 : 0;
}

static int parse_long(const char *s, long *x)
{
    char *end;
    if (!*s)
        return -1;
    errno = 0;
    *x = strtol(s, &end, 10);
    return (end == s || *end || errno == ERANGE) ? -1 : 0;
}

/* Fields first..last-1 as numbers into v[first..last-1]; the message names
 * the field: "FILE:LINE: field 'x': expected a number, found 'abc'". */
static int parse_number_fields(const char *path, size_t number, char *const *f,
                               const char *const *names, int first, int last, double *v,
                               phc_error *err)
{
    char shown[SHOW_MAX + 8];
    int k;
    for (k = first; k < last; ++k)
        if (parse_double(f[k], &v[k]) != 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: field '%s': expected a number, found '%s'", path,
                                 number, names[k], shorten(f[k], shown, sizeof shown));
    return PHC_OK;
}

/* ---- id lookup (ids are arbitrary longs in SWC and native files) ------- */

typedef struct id_entry {
    long id;
    size_t index;
} id_entry;

static int cmp_id_entry(const void *a, const void *b)
{
    const id_entry *x = a, *y = b;
    if (x->id != y->id)
        return x->id < y->id ? -1 : 1;
    return x->index < y->index ? -1 : (x->index > y->index);
}

static size_t find_id(const id_entry *map, size_t n, long id)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (map[mid].id < id)
            lo = mid + 1;
        else
            hi = mid;
    }
    return (lo < n && map[lo].id == id) ? map[lo].index : (size_t)-1;
}

/* Sorts ids[] (n entries) into a lookup map; a repeated id is an error at
 * the line of its second occurrence. */
static int build_id_map(const char *path, const long *ids, const size_t *lines, size_t n,
                        const char *what, id_entry **out, phc_error *err)
{
    id_entry *map = malloc((n ? n : 1) * sizeof *map);
    size_t i;
    *out = NULL;
    if (!map)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    for (i = 0; i < n; ++i) {
        map[i].id = ids[i];
        map[i].index = i;
    }
    qsort(map, n, sizeof *map, cmp_id_entry);
    for (i = 1; i < n; ++i)
        if (map[i].id == map[i - 1].id) {
            int rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s id %ld repeats line %zu",
                                   path, lines[map[i].index], what, map[i].id,
                                   lines[map[i - 1].index]);
            free(map);
            return rc;
        }
    *out = map;
    return PHC_OK;
}

/* ---- checks shared by the readers -------------------------------------- */

static int check_radius(const char *path, size_t line, long id, double r, phc_error *err)
{
    if (!(isfinite(r) && r > 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: segment %ld: radius must be positive and finite, found %g",
                             path, line, id, r);
    return PHC_OK;
}

static int check_point(const char *path, size_t line, long id, const char *what,
                       const double *x, phc_error *err)
{
    static const char axis[3] = {'x', 'y', 'z'};
    int k;
    for (k = 0; k < 3; ++k)
        if (!isfinite(x[k]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: segment %ld: %s%c must be finite, found %g",
                                 path, line, id, what, axis[k], x[k]);
    return PHC_OK;
}

static double distance3(const double *a, const double *b)
{
    const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Structure of a parent[] array filled by a reader, with the line of each
 * segment: exactly one root, and no cycles (a segment whose parent chain
 * never reaches the root).  O(n).  Parents are already in range and not
 * self-references (the readers check those where they parse them). */
static int check_structure(const char *path, const phc_plant_graph *g, const size_t *lines,
                           phc_error *err)
{
    size_t n = g->n, i, root = PHC_PLANT_NO_PARENT;
    unsigned char *state;
    int rc = PHC_OK;
    for (i = 0; i < n; ++i)
        if (g->parent[i] == PHC_PLANT_NO_PARENT) {
            if (root != PHC_PLANT_NO_PARENT)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: two roots: segments %ld and %ld "
                                     "(line %zu); exactly one segment may have no parent",
                                     path, lines[i], g->source_id[root], g->source_id[i],
                                     lines[root]);
            root = i;
        }
    if (root == PHC_PLANT_NO_PARENT)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: no root: every segment has a parent, so the parents "
                             "form a cycle (segment %ld is on it or leads to it)",
                             path, lines[0], g->source_id[0]);
    /* state: 0 unknown, 1 on the current walk, 2 reaches the root */
    state = calloc(n, 1);
    if (!state)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    state[root] = 2;
    for (i = 0; i < n && rc == PHC_OK; ++i) {
        size_t u = i;
        while (state[u] == 0) {
            state[u] = 1;
            u = g->parent[u];
        }
        if (state[u] == 1) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: cycle: segment %ld is its own ancestor (its parent "
                               "chain never reaches the root, segment %ld)",
                               path, lines[u], g->source_id[u], g->source_id[root]);
            break;
        }
        for (u = i; state[u] == 1; u = g->parent[u])
            state[u] = 2;
    }
    free(state);
    return rc;
}

static int check_unit(const char *path, double unit_to_m, phc_error *err)
{
    if (!(isfinite(unit_to_m) && unit_to_m >= 0))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: unit_to_m must be positive and finite (0 for the format's "
                             "default), found %g",
                             path, unit_to_m);
    return PHC_OK;
}

/* ---- the wilting paper's format ---------------------------------------- */

static int parse_count_line(const char *path, char *line, size_t number, const char *keyword,
                            const char *expect_where, long *count, phc_error *err)
{
    char shown[SHOW_MAX + 8];
    size_t kl = strlen(keyword);
    char *rest;
    if (strncmp(line, keyword, kl) != 0 || !is_blank(line[kl]))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: expected '%s N' %s, found '%s'",
                             path, number, keyword, expect_where,
                             shorten(line, shown, sizeof shown));
    rest = trim(line + kl);
    if (parse_long(rest, count) != 0 || *count < 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: '%s': expected a count (a whole number >= 0) after '%s', "
                             "found '%s'",
                             path, number, keyword, keyword, shorten(rest, shown, sizeof shown));
    return PHC_OK;
}

static int read_paper(const char *path, char *text, size_t length, double unit,
                      phc_plant_graph **out, phc_error *err)
{
    static const char *const names[6] = {"id", "x", "y", "z", "radius", "on_leaf"};
    line_cursor cur = {text, text + length, 1};
    phc_plant_graph *g = NULL;
    size_t *lines = NULL, *adj_start = NULL, *adj = NULL, *uf = NULL, *queue = NULL;
    size_t *edge_line = NULL, *edge_a = NULL, *edge_b = NULL;
    unsigned char *seen = NULL;
    size_t n, m, i, number = 0, root = 0;
    double best = INFINITY;
    long count;
    char *line;
    char shown[SHOW_MAX + 8];
    int rc;

    if (!next_line(&cur, &line, &number, 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: expected 'verts N', found an empty file",
                             path);
    if ((rc = parse_count_line(path, line, number, "verts", "on the first line", &count, err)))
        return rc;
    if (count == 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: 'verts 0': a plant needs at least one segment", path,
                             number);
    n = (size_t)count;
    if ((unsigned long)count > (size_t)-1 / 64 || (double)count > (double)length)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: 'verts %ld' announces more vertex lines than the file "
                             "can hold",
                             path, number, count);
    g = phc_plant_graph_new(n);
    lines = calloc(n, sizeof *lines);
    if (!g || !lines) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }

    /* vertex lines */
    for (i = 0; i < n; ++i) {
        char *f[6];
        double v[6];
        long id;
        int nf, k;
        const int got = next_line(&cur, &line, &number, 0);
        if (!got || strncmp(line, "edges", 5) == 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: expected %zu vertex lines after 'verts %zu', found %zu "
                               "before %s",
                               path, got ? number : cur.next_line - 1, n, n, i,
                               got ? "'edges'" : "the end of the file");
            goto fail;
        }
        nf = split_fields(line, ',', f, 6);
        if (nf != 6) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: expected 6 comma-separated fields "
                               "(id,x,y,z,radius,on_leaf), found %d",
                               path, number, nf);
            goto fail;
        }
        if (parse_long(f[0], &id) != 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: field 'id': expected a whole number, found '%s'", path,
                               number, shorten(f[0], shown, sizeof shown));
            goto fail;
        }
        if ((rc = parse_number_fields(path, number, f, names, 1, 6, v, err)))
            goto fail;
        if (id < 0 || (unsigned long)id >= n) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: vertex id %ld out of range 0..%zu", path, number, id,
                               n - 1);
            goto fail;
        }
        if (lines[id]) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: vertex id %ld repeats line %zu",
                               path, number, id, lines[id]);
            goto fail;
        }
        lines[id] = number;
        if ((rc = check_point(path, number, id, "coordinate ", v + 1, err)))
            goto fail;
        if ((rc = check_radius(path, number, id, v[4], err)))
            goto fail;
        if (!(v[5] == 0.0 || v[5] == 1.0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: field 'on_leaf': expected 0 or 1, found '%s'", path,
                               number, shorten(f[5], shown, sizeof shown));
            goto fail;
        }
        for (k = 0; k < 3; ++k)
            g->tail[3 * id + k] = v[1 + k] * unit;
        g->radius[id] = v[4] * unit;
        g->leaf[id] = v[5] != 0.0;
        g->source_id[id] = id;
        /* root: tail nearest the origin, first in file order on a tie
         * (the authors' reader compares with a strict '<') */
        {
            const double d2 = v[1] * v[1] + v[2] * v[2] + v[3] * v[3];
            if (d2 < best) {
                best = d2;
                root = (size_t)id;
            }
        }
    }

    /* edges header */
    if (!next_line(&cur, &line, &number, 0)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: expected 'edges M' after the %zu vertex lines, found the "
                           "end of the file",
                           path, cur.next_line - 1, n);
        goto fail;
    }
    if ((rc = parse_count_line(path, line, number, "edges",
                               "after the vertex lines (more vertex lines than 'verts' says?)",
                               &count, err)))
        goto fail;
    if ((unsigned long)count > (size_t)-1 / 64 || (double)count > (double)length) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: 'edges %ld' announces more edge lines than the file can "
                           "hold",
                           path, number, count);
        goto fail;
    }
    m = (size_t)count;
    edge_a = malloc((m ? m : 1) * sizeof *edge_a);
    edge_b = malloc((m ? m : 1) * sizeof *edge_b);
    edge_line = malloc((m ? m : 1) * sizeof *edge_line);
    uf = malloc(n * sizeof *uf);
    if (!edge_a || !edge_b || !edge_line || !uf) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    for (i = 0; i < n; ++i)
        uf[i] = i;

    /* edge lines: union-find in file order, so the first edge that closes a
     * loop is the one reported */
    for (i = 0; i < m; ++i) {
        char *f[2];
        long a, b;
        size_t ra, rb;
        int nf;
        if (!next_line(&cur, &line, &number, 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: expected %zu edge lines after 'edges %zu', found %zu "
                               "before the end of the file",
                               path, cur.next_line - 1, m, m, i);
            goto fail;
        }
        nf = split_fields(line, ',', f, 2);
        if (nf != 2) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: expected 2 comma-separated fields (id1,id2), found %d",
                               path, number, nf);
            goto fail;
        }
        if (parse_long(f[0], &a) != 0 || parse_long(f[1], &b) != 0) {
            const char *bad = parse_long(f[0], &a) != 0 ? f[0] : f[1];
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: edge: expected a whole-number segment id, found '%s'",
                               path, number, shorten(bad, shown, sizeof shown));
            goto fail;
        }
        if (a < 0 || (unsigned long)a >= n || b < 0 || (unsigned long)b >= n) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: edge %ld,%ld: segment id %ld out of range 0..%zu", path,
                               number, a, b, (a < 0 || (unsigned long)a >= n) ? a : b, n - 1);
            goto fail;
        }
        if (a == b) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: edge %ld,%ld: a segment cannot be its own neighbour",
                               path, number, a, b);
            goto fail;
        }
        /* find with path halving */
        for (ra = (size_t)a; uf[ra] != ra; ra = uf[ra])
            uf[ra] = uf[uf[ra]];
        for (rb = (size_t)b; uf[rb] != rb; rb = uf[rb])
            uf[rb] = uf[uf[rb]];
        if (ra == rb) {
            size_t j;
            for (j = 0; j < i; ++j)
                if ((edge_a[j] == (size_t)a && edge_b[j] == (size_t)b) ||
                    (edge_a[j] == (size_t)b && edge_b[j] == (size_t)a)) {
                    rc = phc_error_set(err, PHC_ERR_INPUT,
                                       "%s:%zu: edge %ld,%ld repeats the edge of line %zu", path,
                                       number, a, b, edge_line[j]);
                    goto fail;
                }
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: edge %ld,%ld closes a cycle: segments %ld and %ld are "
                               "already connected by earlier edges",
                               path, number, a, b, a, b);
            goto fail;
        }
        uf[ra] = rb;
        edge_a[i] = (size_t)a;
        edge_b[i] = (size_t)b;
        edge_line[i] = number;
    }
    if (next_line(&cur, &line, &number, 0)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: unexpected line after the %zu edges that 'edges %zu' "
                           "announced: '%s'",
                           path, number, m, m, shorten(line, shown, sizeof shown));
        goto fail;
    }

    /* adjacency (CSR) and breadth-first parents from the root */
    adj_start = calloc(n + 1, sizeof *adj_start);
    adj = malloc((m ? 2 * m : 1) * sizeof *adj);
    queue = malloc(n * sizeof *queue);
    seen = calloc(n, 1);
    if (!adj_start || !adj || !queue || !seen) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    for (i = 0; i < m; ++i) {
        ++adj_start[edge_a[i] + 1];
        ++adj_start[edge_b[i] + 1];
    }
    for (i = 0; i < n; ++i)
        adj_start[i + 1] += adj_start[i];
    memcpy(uf, adj_start, n * sizeof *uf); /* uf reused as fill pointers */
    for (i = 0; i < m; ++i) {
        adj[uf[edge_a[i]]++] = edge_b[i];
        adj[uf[edge_b[i]]++] = edge_a[i];
    }
    {
        size_t qh = 0, qt = 0;
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
            size_t count_out = n - qt;
            for (i = 0; i < n && seen[i]; ++i)
                ;
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %zu is not connected to the root (segment %zu, "
                               "the tail nearest the origin): %zu segment%s unreachable",
                               path, lines[i], i, root, count_out, count_out == 1 ? " is" : "s are");
            goto fail;
        }
        /* heads and lengths in breadth-first order (parents first) */
        for (i = 0; i < n; ++i) {
            const size_t u = queue[i];
            const size_t p = g->parent[u];
            int k;
            for (k = 0; k < 3; ++k)
                g->head[3 * u + k] = p == PHC_PLANT_NO_PARENT ? 0.0 : g->tail[3 * p + k];
            g->length[u] = distance3(g->tail + 3 * u, g->head + 3 * u);
            if (!(g->length[u] > 0) || !isfinite(g->length[u])) {
                if (p == PHC_PLANT_NO_PARENT)
                    rc = phc_error_set(err, PHC_ERR_INPUT,
                                       "%s:%zu: segment %zu: zero-length segment: the root's "
                                       "tail is at the origin, where its head is",
                                       path, lines[u], u);
                else
                    rc = phc_error_set(err, PHC_ERR_INPUT,
                                       "%s:%zu: segment %zu: zero-length segment: its tail "
                                       "equals the tail of its parent, segment %zu (line %zu)",
                                       path, lines[u], u, p, lines[p]);
                goto fail;
            }
        }
    }
    if ((rc = phc_plant_graph_finish(g, path, err)))
        goto fail;
    *out = g;
    g = NULL;
    rc = PHC_OK;
fail:
    phc_plant_graph_free(g);
    free(lines);
    free(adj_start);
    free(adj);
    free(uf);
    free(queue);
    free(edge_line);
    free(edge_a);
    free(edge_b);
    free(seen);
    return rc;
}

/* ---- TreeQSM cylinders ------------------------------------------------- */

static int count_treeqsm_lines(char *text, size_t length)
{
    /* non-blank lines; used to size the graph before parsing */
    size_t i, count = 0;
    int in_line = 0;
    for (i = 0; i < length; ++i) {
        const char c = text[i];
        if (c == '\n' || c == '\r')
            in_line = 0;
        else if (!is_blank(c) && !in_line) {
            in_line = 1;
            ++count;
        }
    }
    return count > INT_MAX ? -1 : (int)count;
}

static int read_treeqsm(const char *path, char *text, size_t length, double unit,
                        phc_plant_graph **out, phc_error *err)
{
    static const char *const names[9] = {"radius", "length", "start x", "start y", "start z",
                                         "axis x", "axis y", "axis z", "parent"};
    line_cursor cur = {text, text + length, 1};
    phc_plant_graph *g = NULL;
    size_t *lines = NULL, n, i, number = 0;
    int counted = count_treeqsm_lines(text, length), rc;
    char *line;
    char shown[SHOW_MAX + 8];

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
    for (i = 0; i < n && next_line(&cur, &line, &number, 0); ++i) {
        char *f[16];
        double v[9], axis_norm;
        long parent;
        int nf = split_fields(line, 0, f, 16), k;
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
            if (parse_double(f[k], &v[k]) != 0) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column %d (%s): expected a number, found '%s'", path,
                                   number, k + 1, names[k], shorten(f[k], shown, sizeof shown));
                goto fail;
            }
        if (parse_long(f[8], &parent) != 0) {
            /* TreeQSM writes integers; accept "3.0" but not "3.5" */
            double pv;
            if (parse_double(f[8], &pv) != 0 || pv != floor(pv) || fabs(pv) > 1e15) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column 9 (parent): expected a whole number, found "
                                   "'%s'",
                                   path, number, shorten(f[8], shown, sizeof shown));
                goto fail;
            }
            parent = (long)pv;
        }
        if ((rc = check_radius(path, number, id, v[0], err)))
            goto fail;
        if (!(isfinite(v[1]) && v[1] > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: length must be positive and finite, found %g",
                               path, number, id, v[1]);
            goto fail;
        }
        if ((rc = check_point(path, number, id, "start ", v + 2, err)) ||
            (rc = check_point(path, number, id, "axis ", v + 5, err)))
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
        g->source_id[i] = id;
    }
    if ((rc = check_structure(path, g, lines, err)) || (rc = phc_plant_graph_finish(g, path, err)))
        goto fail;
    *out = g;
    g = NULL;
fail:
    phc_plant_graph_free(g);
    free(lines);
    return rc;
}

/* ---- SWC ---------------------------------------------------------------- */

static int read_swc(const char *path, char *text, size_t length, double unit,
                    phc_plant_graph **out, phc_error *err)
{
    static const char *const names[7] = {"id", "type", "x", "y", "z", "radius", "parent"};
    line_cursor cur = {text, text + length, 1};
    phc_plant_graph *g = NULL;
    id_entry *map = NULL;
    long *ids = NULL, *parents = NULL;
    double *pos = NULL, *rad = NULL;
    size_t *lines = NULL, *seg_of = NULL, *seg_lines = NULL;
    size_t cap = 0, m = 0, i, number = 0, root_sample = (size_t)-1, first_child = (size_t)-1;
    size_t nseg, s;
    char *line;
    char shown[SHOW_MAX + 8];
    int rc;

    while (next_line(&cur, &line, &number, 1)) {
        char *f[7];
        double v[7];
        int nf = split_fields(line, 0, f, 7), k;
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
        if (parse_long(f[0], &ids[m]) != 0 || parse_long(f[6], &parents[m]) != 0) {
            const int bad = parse_long(f[0], &ids[m]) != 0 ? 0 : 6;
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: field '%s': expected a whole number, found '%s'", path,
                               number, names[bad], shorten(f[bad], shown, sizeof shown));
            goto fail;
        }
        if ((rc = parse_number_fields(path, number, f, names, 1, 6, v, err)))
            goto fail;
        if ((rc = check_point(path, number, ids[m], "coordinate ", v + 2, err)))
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
    if ((rc = build_id_map(path, ids, lines, m, "sample", &map, err)))
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
        p = find_id(map, m, parents[i]);
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
        g->length[seg] = distance3(pos + 3 * i, pos + 3 * p);
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
    if ((rc = check_structure(path, g, seg_lines, err)) ||
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

/* ---- native CSV -------------------------------------------------------- */

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
        while (p < e && is_blank(*p))
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
        while (p < e && is_blank(*p))
            ++p;
        if ((size_t)(e - p) >= 5 && strncasecmp(p, "unit:", 5) == 0) {
            char word[32];
            size_t len;
            p += 5;
            while (p < e && is_blank(*p))
                ++p;
            len = (size_t)(e - p);
            while (len && is_blank(p[len - 1]))
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
                        while (p < e && is_blank(*p))
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
    char shown[SHOW_MAX + 8];
    if (parse_long(cell, x) != 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: column '%s': expected a whole number, found '%s'",
                             phc_table_source(t), phc_table_row_line(t, row), name,
                             *cell ? shorten(cell, shown, sizeof shown) : "an empty cell");
    return PHC_OK;
}

static int read_native(const char *path, char *text, size_t length, double unit,
                       phc_plant_graph **out, phc_error *err)
{
    phc_table *t = NULL;
    phc_plant_graph *g = NULL;
    double *col[12] = {NULL};
    long *ids = NULL;
    size_t *lines = NULL;
    id_entry *map = NULL;
    long ci[12];
    size_t n, i, header_line;
    double file_unit;
    int rc, c;
    char shown[SHOW_MAX + 8];

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
    if ((rc = build_id_map(path, ids, lines, n, "segment", &map, err)))
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
                                   *cell ? shorten(cell, shown, sizeof shown) : "an empty cell");
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
            const size_t p = find_id(map, n, parent);
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
        if ((rc = check_radius(path, lines[i], ids[i], col[2][i], err)))
            goto fail;
        if (!(col[3][i] > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: length must be positive and finite, found %g",
                               path, lines[i], ids[i], col[3][i]);
            goto fail;
        }
        len_geom = distance3(g->tail + 3 * i, g->head + 3 * i);
        if (!(fabs(len_geom - g->length[i]) <= 1e-4 * g->length[i])) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: segment %ld: length %.9g does not match |tail - head| = "
                               "%.9g (file units)",
                               path, lines[i], ids[i], col[3][i], len_geom / unit);
            goto fail;
        }
    }
    if ((rc = check_structure(path, g, lines, err)) || (rc = phc_plant_graph_finish(g, path, err)))
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

/* ---- format names and detection ---------------------------------------- */

static const char *const format_names[] = {"auto", "paper", "treeqsm", "swc", "native"};

int phc_plant_format_from_name(const char *name)
{
    int i;
    if (!name)
        return -1;
    for (i = 0; i < 5; ++i)
        if (strcasecmp(name, format_names[i]) == 0)
            return i;
    return -1;
}

const char *phc_plant_format_name(phc_plant_format format)
{
    if ((int)format < 0 || (int)format >= 5)
        return "unknown";
    return format_names[format];
}

static int has_extension(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) && strcasecmp(dot + 1, ext) == 0;
}

static int detect_format(const char *path, const char *text, phc_plant_format *format,
                         phc_error *err)
{
    const char *s = text, *e;
    int fields = 0, in_field = 0;
    if (has_extension(path, "swc")) {
        *format = PHC_PLANT_FORMAT_SWC;
        return PHC_OK;
    }
    if (has_extension(path, "csv")) {
        *format = PHC_PLANT_FORMAT_NATIVE;
        return PHC_OK;
    }
    /* first non-blank line */
    while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n')
        ++s;
    if (strncmp(s, "verts", 5) == 0) {
        *format = PHC_PLANT_FORMAT_PAPER;
        return PHC_OK;
    }
    e = s + strcspn(s, "\r\n");
    for (; s < e; ++s) {
        if (is_blank(*s))
            in_field = 0;
        else if (!in_field) {
            in_field = 1;
            ++fields;
        }
    }
    if (fields == 15 || fields == 16) {
        *format = PHC_PLANT_FORMAT_TREEQSM;
        return PHC_OK;
    }
    return phc_error_set(err, PHC_ERR_INPUT,
                         "%s:1: cannot tell the plant format: not .swc or .csv, the first line "
                         "is not 'verts N' (wilting paper) and has %d fields, not the 15 or 16 "
                         "of TreeQSM; name the format (paper, treeqsm, swc, native)",
                         path, fields);
}

int phc_plant_io_read(const char *path, phc_plant_format format, double unit_to_m,
                      phc_plant_graph **out, phc_error *err)
{
    char *text = NULL;
    size_t length = 0;
    phc_c_numeric scope = {(locale_t)0, (locale_t)0};
    int rc;

    if (out)
        *out = NULL;
    if (!path || !out || (int)format < 0 || (int)format > PHC_PLANT_FORMAT_NATIVE)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_plant_io_read: invalid argument");
    if ((rc = check_unit(path, unit_to_m, err)))
        return rc;
    if ((rc = phc_read_text_file(path, &text, &length, err)))
        return rc;
    if (memchr(text, '\0', length)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s: contains a NUL byte: not a text plant file", path);
        goto done;
    }
    if (format == PHC_PLANT_FORMAT_AUTO && (rc = detect_format(path, text, &format, err)))
        goto done;
    phc_c_numeric_begin(&scope); /* on failure strtod keeps the current locale */
    switch (format) {
    case PHC_PLANT_FORMAT_PAPER:
        rc = read_paper(path, text, length, unit_to_m > 0 ? unit_to_m : 1.0, out, err);
        break;
    case PHC_PLANT_FORMAT_TREEQSM:
        rc = read_treeqsm(path, text, length, unit_to_m > 0 ? unit_to_m : 1.0, out, err);
        break;
    case PHC_PLANT_FORMAT_SWC:
        rc = read_swc(path, text, length, unit_to_m > 0 ? unit_to_m : 1e-6, out, err);
        break;
    case PHC_PLANT_FORMAT_NATIVE:
    default:
        rc = read_native(path, text, length, unit_to_m, out, err);
        break;
    }
    phc_c_numeric_end(&scope);
done:
    free(text);
    if (rc == PHC_OK)
        phc_error_clear(err);
    return rc;
}

/* ---- writers ------------------------------------------------------------ */

typedef int (*body_writer)(FILE *f, const phc_plant_graph *g);

/* Writes through body() to a temporary file next to PATH, renamed into
 * place (atomic_file.h); the temporary file is removed on any failure. */
static int write_atomically(const char *path, const phc_plant_graph *g, body_writer body,
                            phc_error *err)
{
    phc_atomic_file *af = NULL;
    phc_c_numeric scope = {(locale_t)0, (locale_t)0};
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc)
        return rc;
    phc_c_numeric_begin(&scope); /* '.' decimal points whatever the locale */
    errno = 0;
    const int failed = body(phc_atomic_file_stream(af), g) < 0;
    const int saved = errno;
    phc_c_numeric_end(&scope);
    if (failed) {
        phc_atomic_file_abort(af);
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write: %s", path,
                             strerror(saved ? saved : EIO));
    }
    if ((rc = phc_atomic_file_commit(af, err)))
        return rc;
    phc_error_clear(err);
    return PHC_OK;
}

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

static int native_body_keep(FILE *f, const phc_plant_graph *g)
{
    return native_body_ids(f, g, 1);
}

static int native_body_index(FILE *f, const phc_plant_graph *g)
{
    return native_body_ids(f, g, 0);
}

static int check_writable(const char *who, const char *path, const phc_plant_graph *g,
                          phc_error *err)
{
    if (!path || !g || g->n == 0 || !g->order || g->root >= g->n)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: invalid argument (a path and a finished graph are needed)",
                             who);
    return PHC_OK;
}

int phc_plant_io_write_native(const char *path, const phc_plant_graph *g, phc_error *err)
{
    int rc, keep;
    if ((rc = check_writable("phc_plant_io_write_native", path, g, err)))
        return rc;
    keep = source_ids_usable(g);
    if (keep < 0)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    return write_atomically(path, g, keep ? native_body_keep : native_body_index, err);
}

static int paper_body(FILE *f, const phc_plant_graph *g)
{
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
    if ((rc = check_writable("phc_plant_io_write_paper", path, g, err)))
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
    return write_atomically(path, g, paper_body, err);
}
