/* Where the light is: a smooth light field over the light grid, for
 * phototropism toward the light around obstacles (Hädrich et al., CGF
 * 36(2) 2017, §4.2, eq. 7: the growth direction turns toward the light;
 * the paper's light grid holds occlusion O, so the direction of most light
 * at a tip is −∇O = ∇I there).
 *
 * Field (ours): node values F at the centres of the light grid's cells
 * (model/climbing_light.h), each the light I = a + (1 − a)·T that a point
 * there would receive (occluders and the plant's Beer–Lambert shade
 * counted), averaged over a small sky of directions: ℓ itself and, when
 * the spread ψ > 0, six more at the angle ψ from ℓ (azimuths 0°, 60°, …,
 * 300°), all seven weighted 1/7.  The spread gives the shadow of a wall a
 * penumbra of width ≈ 2·H·tan ψ at a depth H below its edge, so a shoot
 * in the shade feels the light of a gap before it reaches the gap's own
 * column of light.  Between the nodes F is trilinear; outside the nodes'
 * hull (within half a cell of the grid's faces, or beyond) x is clamped
 * onto the hull, and the gradient along a clamped axis is 0.
 *
 * The target direction of phototropism (phc_climbing_light_field_target)
 * is ∇F/|∇F| at the tip when |∇F|·h ≥ the threshold (a change of the light
 * by at least that much over one cell), else the fixed light direction ℓ.
 * In uniform light (no occluders, no shade) ∇F = 0 exactly, so the target
 * is ℓ exactly: the fixed-direction model.
 *
 * Units: m, light dimensionless in [0, 1], gradients m⁻¹. */
#ifndef PHC_CLIMBING_LIGHT_FIELD_H
#define PHC_CLIMBING_LIGHT_FIELD_H

#include <stddef.h>

#include "model/climbing_light.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_climbing_light_field {
    phc_climbing_light_grid grid; /* the grid the field was built on (its ℓ, cell, dims) */
    double spread;                /* ψ, rad, in [0, π/2) */
    double *value;                /* F at the cell centres, phc_climbing_light_cells(&grid) */
    double *px, *pv, *pl, *phi;   /* scratch: points, volumes, light, grid */
    size_t cap;                   /* points the scratch holds */
    double *sum;                  /* scratch per cell: a probe's light summed over the sky */
    size_t *probe;                /* scratch per cell: the cell of each probe */
    unsigned char *wanted;        /* scratch per cell: 1 = a node read at a site */
    double *sites;                /* phc_climbing_light_field_sites: 3·sites_cap, m */
    size_t sites_cap;
} phc_climbing_light_field;

/* Initialises f for grid g and spread ψ (degrees, [0, 89]); values all 1.
 * Returns 0, or −1 out of memory (f then holds nothing to free). */
int phc_climbing_light_field_init(phc_climbing_light_field *f, const phc_climbing_light_grid *g,
                                  double spread_deg);
void phc_climbing_light_field_free(phc_climbing_light_field *f); /* accepts a zeroed f */

/* Recomputes F at every node from the n shading points x (3n, m) of
 * volumes vol (n, m³) and the occluders occ (NULL: none); the points enter
 * only through their shade, so with extinction 0 they are not used.
 * Returns 0, or −1 out of memory (F unchanged). */
int phc_climbing_light_field_update(phc_climbing_light_field *f, const phc_climbing_occluders *occ,
                                    const double *x, const double *vol, size_t n);

/* As phc_climbing_light_field_update, at the nodes the trilinear
 * interpolation reads at the ns sites (3·ns, m; up to 8 nodes each, the
 * clamping of phc_climbing_light_field_at included) only; every other node
 * is NAN.  The nodes computed hold the same numbers, bit for bit, as the
 * full update gives them (each probe's light depends on the plant's points
 * and the occluders only, not on the other probes).  Phototropism reads
 * the field at the tips only, so with the tips as sites a step of a few
 * shoots computes a few dozen nodes instead of the whole grid. */
int phc_climbing_light_field_update_near(phc_climbing_light_field *f,
                                         const phc_climbing_occluders *occ, const double *x,
                                         const double *vol, size_t n, const double *sites,
                                         size_t ns);

/* Scratch for ns sites (3·ns doubles, m) that f owns (freed with it), or
 * NULL out of memory. */
double *phc_climbing_light_field_sites(phc_climbing_light_field *f, size_t ns);

/* F at x (m), trilinear, and its exact gradient (m⁻¹; NULL: not wanted). */
double phc_climbing_light_field_at(const phc_climbing_light_field *f, const double x[3],
                                   double grad[3]);

/* Phototropism's target t (unit) at x: ∇F/|∇F| when |∇F|·h >= threshold,
 * else ℓ.  Returns 1 when the gradient was used, 0 for ℓ. */
int phc_climbing_light_field_target(const phc_climbing_light_field *f, const double x[3],
                                    double threshold, double t[3]);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_LIGHT_FIELD_H */
