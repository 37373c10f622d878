/* Support meshes for climbing plants (Hädrich, Benes, Deussen, Pirk,
 * "Interactive Modeling and Authoring of Climbing Plants", CGF 36(2) 2017,
 * §4.2: shoots adapt to and anchor on the closest point of a support).
 *
 * A support is a triangle mesh: read from an OBJ or PLY file (assimp), or
 * given as vertex and triangle arrays.  Closest-point queries use CGAL's
 * AABB tree over the triangles (exact closest point on a triangle in double
 * precision; Simple_cartesian<double> kernel).  Both libraries live in
 * measurements/support_mesh_bridge.cc only; this header is plain C.
 *
 * phc_support_mesh_closest has the signature of phc_climbing_closest_fn
 * (model/climbing_growth.h), so a mesh plugs into the growth model as
 *   opts.closest = phc_support_mesh_closest; opts.closest_user = mesh;
 * and model/ stays free of any mesh library.
 *
 * Units: coordinates as in the file, taken as metres. */
#ifndef PHC_SUPPORT_MESH_H
#define PHC_SUPPORT_MESH_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_support_mesh phc_support_mesh;

/* Reads every triangle of an OBJ or PLY file (polygons are triangulated,
 * node transforms applied; points and lines are ignored).  Errors (NULL,
 * err filled, PHC_ERR_INPUT): the file does not parse ("PATH: assimp: ..."
 * with assimp's reason, which names the line where the format gives one),
 * the file has no triangles ("PATH: no triangles ..."), a non-finite
 * vertex ("PATH: mesh 0 vertex 12: coordinate is not finite"); PHC_ERR_IO
 * when it cannot be opened. */
phc_support_mesh *phc_support_mesh_read(const char *path, phc_error *err);

/* A mesh from arrays: vertices 3·nv (m), triangles 3·nt vertex indices.
 * Errors: nt == 0, an index >= nv, a non-finite vertex (messages name
 * `where` and the triangle or vertex). */
phc_support_mesh *phc_support_mesh_from_arrays(const double *vertices, size_t nv,
                                               const size_t *triangles, size_t nt,
                                               const char *where, phc_error *err);

void phc_support_mesh_free(phc_support_mesh *m); /* accepts NULL */

size_t phc_support_mesh_triangle_count(const phc_support_mesh *m);
size_t phc_support_mesh_vertex_count(const phc_support_mesh *m);
/* Axis-aligned bounding box: lo[3], hi[3] (m). */
void phc_support_mesh_bounds(const phc_support_mesh *m, double lo[3], double hi[3]);
/* Vertex i (3 doubles) and triangle t (3 indices), for drawing. */
void phc_support_mesh_vertex(const phc_support_mesh *m, size_t i, double v[3]);
void phc_support_mesh_triangle(const phc_support_mesh *m, size_t t, size_t idx[3]);

/* Copies of all vertices (*vertices: 3·nv doubles, m) and triangles
 * (*triangles: 3·nt vertex indices), malloc'd, for a caller that needs the
 * mesh as arrays (the light grid's shadows: phc_climbing_set_shadow_triangles).
 * Returns 0, or PHC_ERR_NOMEM (err filled, nothing allocated). */
int phc_support_mesh_arrays(const phc_support_mesh *m, double **vertices, size_t *nv, size_t **triangles,
                            size_t *nt, phc_error *err);

/* Closest point c (m) on the mesh to x (m), and the unit normal n of the
 * triangle it lies on (right-hand rule over the triangle's vertex order;
 * (0,0,0) for a degenerate triangle).  `mesh` is a phc_support_mesh *.
 * Returns 0, or -1 when x is not finite (c, n untouched).  Safe to call
 * from several threads at once.
 *
 * Certified answers (ours; exact): a query answered by the AABB tree at
 * x₀, closest triangle T at distance d₀, every other triangle at d₂ or
 * farther, certifies T for any x with |x − x₀| < (d₂ − d₀)/2 − 1e-9·(1 +
 * |x₀|∞) m (the distance is 1-Lipschitz: T stays the closest, by more than
 * rounding).  Such an x is answered by projecting it on T alone, the
 * projection the tree itself ends with: the same c and n bit for bit.
 * The certificates are kept per thread, one per cell of edge 1/256 of the
 * mesh's bounding-box diagonal (the last query's there), and d₂ is sought
 * among the triangles within d₀ + 1/32 of the diagonal.  A point that
 * moves little between queries (a particle in the collision pass of
 * model/particles.h) is then answered at the cost of one projection. */
int phc_support_mesh_closest(void *mesh, const double x[3], double c[3], double n[3]);

/* The deepest point of segment a b (m) against the mesh, for the exact
 * segment push of model/particles.h (phc_particles_set_segment_collider;
 * the signature of phc_particles_segment_fn).  Candidates: the ends and,
 * for every edge of every triangle whose box meets the segment's box
 * grown by `reach` (CGAL AABB tree), the segment's point closest to that
 * edge (Ericson 2005 §5.1.9); each is given its signed distance δ
 * (phc_support_mesh_closest, negative behind the face), and the smallest
 * wins: *t in [0, 1] its parameter, *depth its δ (m).  A segment that
 * meets no triangle (CGAL do_intersect) skips the edges reach or farther
 * from it: its points' δ are their distances to the mesh, smallest at an
 * end or at a point closest to an edge, so a skipped edge cannot give one
 * below reach.  A straight segment whose ends lie out can only dip below
 * a convex edge, and its point closest to that edge is then among the
 * candidates.  Returns 1 when that δ < reach (exact up to rounding), 0
 * when no point of the segment lies within reach (*depth then some δ >=
 * reach), -1 when a, b or reach is not finite.  Thread-safe. */
int phc_support_mesh_segment_deepest(void *mesh, const double a[3], const double b[3], double reach, double *t,
                                     double *depth);

/* on = 0: every query goes through the AABB tree (for tests comparing the
 * two); 1 (default): certified answers are used.  Not while queries run. */
void phc_support_mesh_certificates(phc_support_mesh *m, int on);
/* Queries of m answered by the AABB tree since it was made (all threads;
 * the others were answered by a certificate). */
size_t phc_support_mesh_tree_queries(const phc_support_mesh *m);

#ifdef __cplusplus
}
#endif

#endif /* PHC_SUPPORT_MESH_H */
