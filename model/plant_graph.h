/* The plant graph: one type for every model in phytocal.
 *
 * A plant is a rooted tree of segments (wilting paper §3: "nodes are
 * segments").  Segment i is a cylinder of radius radius[i] and length
 * length[i] running from head (the end nearer the root) to tail (the far
 * end); its parent is parent[i], PHC_PLANT_NO_PARENT for the single root.
 *
 * Units: lengths, radii and positions in metres (SI, as the files give them).
 * Models that work in other units (the water model works in cm) convert.
 *
 * The struct is caller-visible (GeographicLib style): readers in
 * measurements/plant_io fill it, models read it.  After filling parent[],
 * call phc_plant_graph_finish(), which validates and builds the derived
 * arrays (children, order).  A finished graph is never modified by a model. */
#ifndef PHC_PLANT_GRAPH_H
#define PHC_PLANT_GRAPH_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PHC_PLANT_NO_PARENT ((size_t)-1)

typedef struct phc_plant_graph {
    size_t n;               /* segments */
    size_t *parent;         /* n: parent index, PHC_PLANT_NO_PARENT for the root */
    double *radius;         /* n: m, > 0 */
    double *length;         /* n: m, > 0 */
    double *head;           /* 3n: x,y,z of the end nearer the root, m */
    double *tail;           /* 3n: x,y,z of the far end, m */
    unsigned char *leaf;    /* n: 1 for leaf (venation) segments, which lose water */
    unsigned char *fixed;   /* n: 1 for anchored segments (shape models pin them) */
    long *source_id;        /* n: the id the segment had in its file (for messages) */

    /* Derived by phc_plant_graph_finish: */
    size_t root;            /* the index whose parent is PHC_PLANT_NO_PARENT */
    size_t *order;          /* n: breadth-first from the root; parents before children */
    size_t *child_start;    /* n+1: children of i are child[child_start[i] .. child_start[i+1]-1] */
    size_t *child;          /* n-1 */
    size_t *depth;          /* n: edges from the root */
} phc_plant_graph;

/* Allocates a graph of n segments: every array allocated, parent[] set to
 * PHC_PLANT_NO_PARENT, numbers zeroed, source_id[i] = i.  NULL when out of
 * memory or n == 0. */
phc_plant_graph *phc_plant_graph_new(size_t n);
void phc_plant_graph_free(phc_plant_graph *g); /* accepts NULL */

/* Validates and derives: exactly one root; parents in range; no self edges;
 * no cycles (so the graph is connected: n - 1 edges reach every segment from
 * the root); radii and lengths positive and finite; coordinates finite.
 * Messages name the offending segment by its source_id, prefixed by `where`
 * (a file name, or "" for none):
 *     "plant.txt: segment 17: radius must be positive and finite, found -0.002"
 * Returns PHC_OK or PHC_ERR_INPUT. */
int phc_plant_graph_finish(phc_plant_graph *g, const char *where, phc_error *err);

/* Deep copy of a finished graph, or NULL when out of memory. */
phc_plant_graph *phc_plant_graph_copy(const phc_plant_graph *g);

/* Totals over segments: volume sum(pi r^2 h) in m^3, leaf count. */
double phc_plant_graph_volume(const phc_plant_graph *g);
size_t phc_plant_graph_leaf_count(const phc_plant_graph *g);

/* A random tree of n segments for benchmarks and tests (seeded, deterministic):
 * a main stem with branches, radii tapering by the pipe model, segments beyond
 * depth `leaf_depth` (or the outermost 80%) flagged as leaf.  Finished. */
phc_plant_graph *phc_plant_graph_random(size_t n, unsigned long seed);

/* A leaf as a venation chain from its measured area (used to model detached
 * leaves weighed on a balance, which come with an area but no geometry):
 * a midrib of `segments` segments of length L/segments, L = sqrt(area * 2)
 * (a leaf of aspect 2:1 whose midrib spans its length), with radius
 * `vein_radius`; segment 0 is the petiole (root, not leaf), the rest are leaf.
 * area in m^2, vein_radius in m.  Finished.  NULL on bad arguments or memory. */
phc_plant_graph *phc_plant_graph_leaf_chain(double area, size_t segments,
                                            double vein_radius);

#ifdef __cplusplus
}
#endif

#endif /* PHC_PLANT_GRAPH_H */
