/* The plant graph: allocation, validation, derived arrays, generators.
 * See plant_graph.h.  Pure C: no I/O, no printing, no globals. */
#include "model/plant_graph.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void free_derived(phc_plant_graph *g)
{
    free(g->order);
    free(g->child_start);
    free(g->child);
    free(g->depth);
    g->order = g->child_start = g->child = g->depth = NULL;
}

void phc_plant_graph_free(phc_plant_graph *g)
{
    if (!g)
        return;
    free(g->parent);
    free(g->radius);
    free(g->length);
    free(g->head);
    free(g->tail);
    free(g->leaf);
    free(g->fixed);
    free(g->source_id);
    free_derived(g);
    free(g);
}

phc_plant_graph *phc_plant_graph_new(size_t n)
{
    phc_plant_graph *g;
    size_t i;
    if (n == 0 || n > ((size_t)-1) / (3 * sizeof(double)) - 1)
        return NULL;
    g = calloc(1, sizeof *g);
    if (!g)
        return NULL;
    g->n = n;
    g->root = PHC_PLANT_NO_PARENT;
    g->parent = malloc(n * sizeof *g->parent);
    g->radius = calloc(n, sizeof *g->radius);
    g->length = calloc(n, sizeof *g->length);
    g->head = calloc(3 * n, sizeof *g->head);
    g->tail = calloc(3 * n, sizeof *g->tail);
    g->leaf = calloc(n, sizeof *g->leaf);
    g->fixed = calloc(n, sizeof *g->fixed);
    g->source_id = malloc(n * sizeof *g->source_id);
    if (!g->parent || !g->radius || !g->length || !g->head || !g->tail ||
        !g->leaf || !g->fixed || !g->source_id)
        goto fail;
    for (i = 0; i < n; ++i) {
        g->parent[i] = PHC_PLANT_NO_PARENT;
        g->source_id[i] = (long)i;
    }
    return g;
fail:
    phc_plant_graph_free(g);
    return NULL;
}

/* "where: " or "" */
#define WHERE_FMT "%s%s"
#define WHERE_ARGS(w) ((w) && *(w) ? (w) : ""), ((w) && *(w) ? ": " : "")

int phc_plant_graph_finish(phc_plant_graph *g, const char *where, phc_error *err)
{
    size_t n, i, root = PHC_PLANT_NO_PARENT, head_q, tail_q;
    size_t *mark = NULL;
    int rc = PHC_OK;
    if (!g || g->n == 0 || !g->parent || !g->radius || !g->length || !g->head ||
        !g->tail || !g->leaf || !g->fixed || !g->source_id)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_plant_graph_finish: invalid argument (empty or incomplete graph)");
    n = g->n;
    free_derived(g);
    g->root = PHC_PLANT_NO_PARENT;

    /* Per-segment checks first, so that a bad number is reported before a
     * structural problem it may have caused upstream. */
    for (i = 0; i < n; ++i) {
        static const char axis[3] = {'x', 'y', 'z'};
        int k;
        const size_t p = g->parent[i];
        if (p == PHC_PLANT_NO_PARENT) {
            if (root != PHC_PLANT_NO_PARENT)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     WHERE_FMT "two roots: segments %ld and %ld "
                                     "(exactly one segment may have no parent)",
                                     WHERE_ARGS(where), g->source_id[root], g->source_id[i]);
            root = i;
        } else if (p >= n) {
            return phc_error_set(err, PHC_ERR_INPUT,
                                 WHERE_FMT "segment %ld: parent index %zu out of range "
                                 "(the graph has %zu segments)",
                                 WHERE_ARGS(where), g->source_id[i], p, n);
        } else if (p == i) {
            return phc_error_set(err, PHC_ERR_INPUT,
                                 WHERE_FMT "segment %ld: a segment cannot be its own parent",
                                 WHERE_ARGS(where), g->source_id[i]);
        }
        if (!(isfinite(g->radius[i]) && g->radius[i] > 0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 WHERE_FMT "segment %ld: radius must be positive and finite, found %g",
                                 WHERE_ARGS(where), g->source_id[i], g->radius[i]);
        if (!(isfinite(g->length[i]) && g->length[i] > 0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 WHERE_FMT "segment %ld: length must be positive and finite, found %g",
                                 WHERE_ARGS(where), g->source_id[i], g->length[i]);
        for (k = 0; k < 3; ++k) {
            if (!isfinite(g->head[3 * i + k]))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     WHERE_FMT "segment %ld: head %c coordinate must be finite, found %g",
                                     WHERE_ARGS(where), g->source_id[i], axis[k], g->head[3 * i + k]);
            if (!isfinite(g->tail[3 * i + k]))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     WHERE_FMT "segment %ld: tail %c coordinate must be finite, found %g",
                                     WHERE_ARGS(where), g->source_id[i], axis[k], g->tail[3 * i + k]);
        }
    }
    if (root == PHC_PLANT_NO_PARENT)
        return phc_error_set(err, PHC_ERR_INPUT,
                             WHERE_FMT "no root: every segment has a parent, so the parents form a cycle",
                             WHERE_ARGS(where));

    g->order = malloc(n * sizeof *g->order);
    g->child_start = calloc(n + 1, sizeof *g->child_start);
    g->child = malloc((n > 1 ? n - 1 : 1) * sizeof *g->child);
    g->depth = malloc(n * sizeof *g->depth);
    if (!g->order || !g->child_start || !g->child || !g->depth) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "phc_plant_graph_finish: out of memory");
        goto fail;
    }

    /* Children in CSR form (counting sort: children listed in index order). */
    for (i = 0; i < n; ++i)
        if (i != root)
            ++g->child_start[g->parent[i] + 1];
    for (i = 0; i < n; ++i)
        g->child_start[i + 1] += g->child_start[i];
    {
        size_t *fill = g->order; /* scratch, overwritten by the BFS below */
        memcpy(fill, g->child_start, n * sizeof *fill);
        for (i = 0; i < n; ++i)
            if (i != root)
                g->child[fill[g->parent[i]]++] = i;
    }

    /* Breadth-first from the root.  With one root and n - 1 in-range parent
     * links, the BFS reaches every segment exactly when there is no cycle. */
    head_q = 0;
    tail_q = 0;
    g->order[tail_q++] = root;
    g->depth[root] = 0;
    while (head_q < tail_q) {
        const size_t u = g->order[head_q++];
        size_t c;
        for (c = g->child_start[u]; c < g->child_start[u + 1]; ++c) {
            const size_t v = g->child[c];
            g->depth[v] = g->depth[u] + 1;
            g->order[tail_q++] = v;
        }
    }
    if (tail_q < n) {
        /* Some segment is unreachable: its parent chain must end in a cycle.
         * Walk it, stamping each step, until a segment repeats: that one is
         * on the cycle.  O(n). */
        size_t start = 0, u, len = 0;
        mark = calloc(n, sizeof *mark);
        if (!mark) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "phc_plant_graph_finish: out of memory");
            goto fail;
        }
        for (i = 0; i < tail_q; ++i)
            mark[g->order[i]] = 1; /* reachable */
        while (mark[start])
            ++start;
        u = start;
        while (!mark[u]) {
            mark[u] = 2;
            u = g->parent[u];
        }
        /* u is on the cycle: count its length for the message. */
        {
            size_t v = u;
            do {
                v = g->parent[v];
                ++len;
            } while (v != u);
        }
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           WHERE_FMT "cycle: segment %ld is its own ancestor (a loop of %zu "
                           "segments through segment %ld and its parent %ld never reaches the root %ld)",
                           WHERE_ARGS(where), g->source_id[u], len, g->source_id[u],
                           g->source_id[g->parent[u]], g->source_id[root]);
        goto fail;
    }
    g->root = root;
    return PHC_OK;
fail:
    free(mark);
    free_derived(g);
    g->root = PHC_PLANT_NO_PARENT;
    return rc;
}

static void *dup_array(const void *src, size_t bytes, int *bad)
{
    void *p;
    if (!src)
        return NULL;
    p = malloc(bytes ? bytes : 1);
    if (!p) {
        *bad = 1;
        return NULL;
    }
    memcpy(p, src, bytes);
    return p;
}

phc_plant_graph *phc_plant_graph_copy(const phc_plant_graph *g)
{
    phc_plant_graph *c;
    int bad = 0;
    size_t n;
    if (!g || g->n == 0)
        return NULL;
    n = g->n;
    c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->n = n;
    c->root = g->root;
    c->parent = dup_array(g->parent, n * sizeof *g->parent, &bad);
    c->radius = dup_array(g->radius, n * sizeof *g->radius, &bad);
    c->length = dup_array(g->length, n * sizeof *g->length, &bad);
    c->head = dup_array(g->head, 3 * n * sizeof *g->head, &bad);
    c->tail = dup_array(g->tail, 3 * n * sizeof *g->tail, &bad);
    c->leaf = dup_array(g->leaf, n * sizeof *g->leaf, &bad);
    c->fixed = dup_array(g->fixed, n * sizeof *g->fixed, &bad);
    c->source_id = dup_array(g->source_id, n * sizeof *g->source_id, &bad);
    c->order = dup_array(g->order, n * sizeof *g->order, &bad);
    c->child_start = dup_array(g->child_start, (n + 1) * sizeof *g->child_start, &bad);
    c->child = dup_array(g->child, (n > 1 ? n - 1 : 0) * sizeof *g->child, &bad);
    c->depth = dup_array(g->depth, n * sizeof *g->depth, &bad);
    if (bad) {
        phc_plant_graph_free(c);
        return NULL;
    }
    return c;
}

double phc_plant_graph_volume(const phc_plant_graph *g)
{
    double v = 0.0;
    size_t i;
    if (!g)
        return 0.0;
    for (i = 0; i < g->n; ++i)
        v += M_PI * g->radius[i] * g->radius[i] * g->length[i];
    return v;
}

size_t phc_plant_graph_leaf_count(const phc_plant_graph *g)
{
    size_t c = 0, i;
    if (!g)
        return 0;
    for (i = 0; i < g->n; ++i)
        c += g->leaf[i] != 0;
    return c;
}

/* ---- random trees ------------------------------------------------------ */

/* splitmix64 (Steele, Lea & Flood 2014): small, fast, and good enough to
 * shape a test tree; the state lives on the caller's stack. */
static uint64_t splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* uniform in [0, 1) with 53 random bits */
static double uniform01(uint64_t *state)
{
    return (double)(splitmix64(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* uniform integer in [0, m), m > 0 (the modulo bias is below 2^-40 here) */
static size_t uniform_below(uint64_t *state, size_t m)
{
    return (size_t)(splitmix64(state) % (uint64_t)m);
}

static void normalize_upward(double d[3], double min_z)
{
    double norm;
    if (d[2] < min_z)
        d[2] = min_z;
    norm = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    d[0] /= norm;
    d[1] /= norm;
    d[2] /= norm;
}

/* Tree shape constants (metres). */
#define RANDOM_STEM_LENGTH 0.02   /* stem internode */
#define RANDOM_BRANCH_LENGTH 0.01 /* branch / vein segment, mean */
#define RANDOM_TIP_RADIUS 3.0e-4  /* pipe model: r = r_tip * sqrt(tips above) */
#define RANDOM_MAX_BRANCH 8       /* segments per branch, at most */
#define RANDOM_LEAF_FRACTION 0.8  /* outermost share of segments flagged leaf */

phc_plant_graph *phc_plant_graph_random(size_t n, unsigned long seed)
{
    phc_plant_graph *g = NULL;
    uint64_t state = (uint64_t)seed ^ 0x5DEECE66DULL;
    size_t *tips = NULL, *height = NULL, *hist = NULL;
    size_t i, stem, branch_left = 0, h_cut, below;
    double *dir = NULL;

    g = phc_plant_graph_new(n);
    if (!g)
        return NULL;
    tips = calloc(n, sizeof *tips);
    height = calloc(n, sizeof *height);
    hist = calloc(n + 1, sizeof *hist);
    dir = malloc(3 * n * sizeof *dir);
    if (!tips || !height || !hist || !dir)
        goto fail;

    /* Topology.  Segments 0..stem-1 form the main stem; every later segment
     * either continues the current branch (parent i - 1) or starts a new
     * branch on a uniformly chosen earlier segment.  Parents always have
     * smaller indices, so every pass below is a single O(n) sweep. */
    stem = (size_t)ceil(sqrt((double)n));
    if (stem > n)
        stem = n;
    for (i = 1; i < n; ++i) {
        if (i < stem) {
            g->parent[i] = i - 1;
        } else if (branch_left > 0) {
            g->parent[i] = i - 1;
            --branch_left;
        } else {
            g->parent[i] = uniform_below(&state, i);
            branch_left = uniform_below(&state, RANDOM_MAX_BRANCH);
        }
    }

    /* Geometry: the stem grows up (+z) with a slight wobble; a branch
     * leaves its parent at 30-70 degrees at a random azimuth; a branch
     * continuation bends slightly.  Every direction keeps z > 0, so each
     * tail is higher than the root's tail and the root's tail is the one
     * nearest the origin (the wilting paper's root rule). */
    for (i = 0; i < n; ++i) {
        double *d = dir + 3 * i, len;
        const size_t p = g->parent[i];
        if (i < stem) {
            d[0] = 0.08 * (uniform01(&state) - 0.5);
            d[1] = 0.08 * (uniform01(&state) - 0.5);
            d[2] = 1.0;
            normalize_upward(d, 0.5);
            len = RANDOM_STEM_LENGTH * (0.8 + 0.4 * uniform01(&state));
        } else if (p == i - 1 && p >= stem) {
            const double *pd = dir + 3 * p;
            d[0] = pd[0] + 0.3 * (uniform01(&state) - 0.5);
            d[1] = pd[1] + 0.3 * (uniform01(&state) - 0.5);
            d[2] = pd[2] + 0.3 * (uniform01(&state) - 0.5);
            normalize_upward(d, 0.05);
            len = RANDOM_BRANCH_LENGTH * (0.5 + uniform01(&state));
        } else {
            const double *pd = dir + 3 * p;
            const double angle = (30.0 + 40.0 * uniform01(&state)) * M_PI / 180.0;
            const double az = 2.0 * M_PI * uniform01(&state);
            /* an orthonormal pair perpendicular to pd */
            double a[3] = {1.0, 0.0, 0.0}, u[3], v[3], dot, nu;
            if (fabs(pd[0]) > 0.9) {
                a[0] = 0.0;
                a[1] = 1.0;
            }
            dot = a[0] * pd[0] + a[1] * pd[1] + a[2] * pd[2];
            u[0] = a[0] - dot * pd[0];
            u[1] = a[1] - dot * pd[1];
            u[2] = a[2] - dot * pd[2];
            nu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            u[0] /= nu;
            u[1] /= nu;
            u[2] /= nu;
            v[0] = pd[1] * u[2] - pd[2] * u[1];
            v[1] = pd[2] * u[0] - pd[0] * u[2];
            v[2] = pd[0] * u[1] - pd[1] * u[0];
            for (int k = 0; k < 3; ++k)
                d[k] = cos(angle) * pd[k] +
                       sin(angle) * (cos(az) * u[k] + sin(az) * v[k]);
            normalize_upward(d, 0.05);
            len = RANDOM_BRANCH_LENGTH * (0.5 + uniform01(&state));
        }
        for (int k = 0; k < 3; ++k) {
            g->head[3 * i + k] = (p == PHC_PLANT_NO_PARENT) ? 0.0 : g->tail[3 * p + k];
            g->tail[3 * i + k] = g->head[3 * i + k] + len * d[k];
        }
        /* length from the stored coordinates, so |tail - head| == length
         * as closely as floating point allows */
        {
            const double dx = g->tail[3 * i] - g->head[3 * i];
            const double dy = g->tail[3 * i + 1] - g->head[3 * i + 1];
            const double dz = g->tail[3 * i + 2] - g->head[3 * i + 2];
            g->length[i] = sqrt(dx * dx + dy * dy + dz * dz);
        }
    }

    /* Pipe model (Shinozaki et al. 1964): the cross-section of a segment is
     * proportional to the number of tips it supplies, r = r_tip sqrt(tips).
     * height = edges to the farthest tip above; both in one reverse sweep. */
    for (i = n; i-- > 0;) {
        if (tips[i] == 0)
            tips[i] = 1; /* a tip */
        if (i > 0) {
            const size_t p = g->parent[i];
            tips[p] += tips[i];
            if (height[i] + 1 > height[p])
                height[p] = height[i] + 1;
        }
    }
    for (i = 0; i < n; ++i) {
        g->radius[i] = RANDOM_TIP_RADIUS * sqrt((double)tips[i]);
        ++hist[height[i]];
    }

    /* Leaves: the outermost segments by height, as many whole height
     * classes as fit in RANDOM_LEAF_FRACTION of the segments (at least the
     * tips); never the main stem. */
    below = 0;
    for (h_cut = 0; h_cut <= n; ++h_cut) {
        if (h_cut > 0 && (double)(below + hist[h_cut]) > RANDOM_LEAF_FRACTION * (double)n)
            break;
        below += hist[h_cut];
    }
    for (i = stem; i < n; ++i)
        g->leaf[i] = height[i] < h_cut;

    free(tips);
    free(height);
    free(hist);
    free(dir);
    if (phc_plant_graph_finish(g, "", NULL) != PHC_OK) {
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
fail:
    free(tips);
    free(height);
    free(hist);
    free(dir);
    phc_plant_graph_free(g);
    return NULL;
}

phc_plant_graph *phc_plant_graph_leaf_chain(double area, size_t segments,
                                            double vein_radius)
{
    phc_plant_graph *g;
    double L, h;
    size_t i;
    if (!(isfinite(area) && area > 0) || !(isfinite(vein_radius) && vein_radius > 0) ||
        segments < 2)
        return NULL;
    L = sqrt(area * 2.0);
    h = L / (double)segments;
    if (!(h > 0) || !isfinite(h))
        return NULL;
    g = phc_plant_graph_new(segments);
    if (!g)
        return NULL;
    /* The midrib lies along +x from the origin; segment 0, the petiole, is
     * the root. */
    for (i = 0; i < segments; ++i) {
        g->parent[i] = i == 0 ? PHC_PLANT_NO_PARENT : i - 1;
        g->radius[i] = vein_radius;
        g->length[i] = h;
        g->head[3 * i] = (double)i * h;
        g->tail[3 * i] = (double)(i + 1) * h;
        g->leaf[i] = i > 0;
    }
    if (phc_plant_graph_finish(g, "", NULL) != PHC_OK) {
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}
