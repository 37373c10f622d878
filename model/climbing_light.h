/* Light at the particles of a climbing plant (Hädrich et al., CGF 36(2)
 * 2017, §4.2: the growth rate of a particle depends on the light it
 * receives, occlusion O from a light grid).
 *
 * This slice's light model (a simple one, chosen here; the paper gives no
 * formula): a uniform voxel grid (origin, cubic cell h, dims) holds the
 * plant's volume fraction φ per cell (Σ π r² L of the particles whose
 * centre lies in it, over h³).  Light comes as parallel rays from the unit
 * direction ℓ (toward the light).  A particle at x receives
 *   I(x) = exp(−λ Σ_{k=1..K} φ(x + k h ℓ) h)          (Beer–Lambert)
 * summing the cells met at steps of h toward the light until the ray
 * leaves the grid (its own cell, k = 0, is not counted).  λ (m⁻¹ per unit
 * volume fraction) is the extinction; λ = 0 gives I = 1.  A particle
 * outside the grid receives full light (I = 1).
 *
 * Supports cast shadows (ours; the paper's light grid holds occlusion from
 * the plant and the scene alike): a support mesh's triangles are rasterised
 * into an opaque mask over the same cells (phc_climbing_light_mark_triangle).
 * When the point's own cell or a cell the march meets is masked, the ray x + t ℓ (t > 0) is
 * tested exactly against every occluding triangle (Möller & Trumbore, "Fast,
 * minimum storage ray/triangle intersection", J. Graphics Tools 2(1) 1997);
 * a hit blocks the direct light.  The exact test keeps a shoot lying on a
 * wall lit when the light runs along the wall (its ray passes the wall's
 * cells without crossing a face), and a masked cell only costs the test.
 * A diffuse share a (ambient ∈ [0, 1], sky light reaching every point) gives
 *   I(x) = a + (1 − a)·T(x),  T = 0 when blocked, else exp(−λ Σ φ h),
 * so a shoot behind a wall grows at the rate r·a.  a = 0 and no occluders
 * is the pure Beer–Lambert law above, bit for bit.  A face is an occluder
 * from both sides; hits closer than h/50 along the ray do not count (ours:
 * a shoot pressed onto a wall, its centre a hair behind the face after a
 * tropism step, is not shadowed by the wall it lies on).
 *
 * Computation (ours; the numbers are those of the march above, bit for
 * bit).  φ is summed in the points' order.  When ℓ is a grid axis (±e_x,
 * ±e_y or ±e_z exactly, as the default light from above), every point of
 * a cell whose samples fall, rounding included, in the cells j0 ± 1,
 * j0 ± 2, … to the grid's face receives the same depth, summed in the
 * march's order once per cell along the cell's line (empty cells add exact
 * zeros and are skipped) with one exponential per distinct depth.  Which
 * points qualify is decided from a bound on the rounding of the samples'
 * quotients (climbing_light.c, ray_is_regular): a point within about
 * 1e-13 cells of a face, or with an opaque cell on its way to the light
 * (its own cell included), marches as above.  Other directions march every
 * point.  From 16,384 points on, the points and lines run on the OpenMP
 * threads (the same numbers on any count).  For a bushy plant of 29,569
 * particles in an 80×80×40 grid this is about 0.4 ms per step on one core
 * against 10 ms for the march. */
#ifndef PHC_CLIMBING_LIGHT_H
#define PHC_CLIMBING_LIGHT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_climbing_light_grid {
    double origin[3];   /* m: the grid's lowest corner */
    double cell;        /* h, m, > 0 */
    size_t dims[3];     /* cells along x, y, z, each >= 1 */
    double extinction;  /* λ, m^-1, >= 0 */
    double direction[3];/* ℓ, unit, toward the light */
    double ambient;     /* a ∈ [0, 1]: diffuse share that reaches shadowed points; default 0 */
} phc_climbing_light_grid;

/* Cells of the grid (dims[0]·dims[1]·dims[2]). */
size_t phc_climbing_light_cells(const phc_climbing_light_grid *g);

/* Light I in (0, 1] at n points x (3n, m) that carry the volumes vol (n, m³).
 * phi is scratch of phc_climbing_light_cells(g) doubles. */
void phc_climbing_light(const phc_climbing_light_grid *g, const double *x, const double *vol,
                        size_t n, double *phi, double *light);

/* Marks in opaque (phc_climbing_light_cells(g) bytes, 1 = opaque) every
 * cell that holds a sample of the triangle (a, b, c) (m): barycentric
 * samples at spacing at most h/4 along both edges from a, so every cell the
 * triangle covers by more than a sliver is marked.  Returns the number of
 * cells newly marked; parts outside the grid are ignored. */
size_t phc_climbing_light_mark_triangle(const phc_climbing_light_grid *g, const double a[3],
                                        const double b[3], const double c[3],
                                        unsigned char *opaque);

/* Occluding triangles: nt × 3 indices into nv × 3 vertices (m), and their
 * mask over the grid's cells (phc_climbing_light_mark_triangle of each). */
typedef struct phc_climbing_occluders {
    const double *vertices;
    size_t nv;
    const size_t *triangles;
    size_t nt;
    const unsigned char *mask;
} phc_climbing_occluders;

/* 1 when the ray x + t ℓ, t in (t_min, inf), crosses the triangle (a, b,
 * c) (m), else 0 (Möller–Trumbore; a ray in the triangle's plane misses). */
int phc_climbing_ray_hits_triangle(const double x[3], const double l[3], double t_min,
                                   const double a[3], const double b[3], const double c[3]);

/* phc_climbing_light with occluders (NULL: none) and the ambient share a:
 * I = a + (1 − a)·T as above.  With no occluders and a = 0 it equals
 * phc_climbing_light. */
void phc_climbing_light_shaded(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                               const double *x, const double *vol, size_t n, double *phi,
                               double *light);

/* phc_climbing_light_shaded with phi all zero on entry (calloc), left all
 * zero on return: the grid is not cleared first, only the cells written
 * are cleared after (a plant that fills few of the grid's columns, as a
 * climbing plant's light step each frame, skips a pass over every cell).
 * The same light, bit for bit. */
void phc_climbing_light_shaded_zeroed(const phc_climbing_light_grid *g,
                                      const phc_climbing_occluders *occ, const double *x,
                                      const double *vol, size_t n, double *phi, double *light);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_LIGHT_H */
