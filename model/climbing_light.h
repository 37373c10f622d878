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
 * outside the grid receives full light (I = 1).  Supports cast no shadow
 * in this slice. */
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
} phc_climbing_light_grid;

/* Cells of the grid (dims[0]·dims[1]·dims[2]). */
size_t phc_climbing_light_cells(const phc_climbing_light_grid *g);

/* Light I in (0, 1] at n points x (3n, m) that carry the volumes vol (n, m³).
 * phi is scratch of phc_climbing_light_cells(g) doubles. */
void phc_climbing_light(const phc_climbing_light_grid *g, const double *x, const double *vol,
                        size_t n, double *phi, double *light);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_LIGHT_H */
