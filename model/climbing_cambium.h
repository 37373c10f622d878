/* Secondary (cambial) growth of a climbing plant by the pipe model
 * (Shinozaki, Yoda, Hozumi, Kira, "A quantitative analysis of plant form —
 * the pipe model theory I", Jpn. J. Ecol. 14, 1964: a stem's cross-section
 * carries the pipes of every leaf above it; da Vinci's rule
 * r_parent² = Σ r_child² at a branching; used for thickening in Hädrich et
 * al., CGF 36(2) 2017, §4.3, whose formula we could not read: the law and
 * the rate below are ours).
 *
 * Target area of particle i (m²):
 *   A*_i = Σ_{children c} π r_c² + a_L·[i bears a leaf]   (i has children)
 *   A*_i = π r0_i² + a_L·[i bears a leaf]                  (i has none)
 * r0_i the primary radius (from growth and thickness falloff), a_L the
 * pipe area of one leaf (m², >= 0).  The radius relaxes toward
 * r*_i = √(A*_i/π) at the cambium rate κ (s⁻¹) and never shrinks:
 *   dr/dt = κ (r* − r) for r < r*, 0 otherwise,
 * integrated exactly for a constant target over a step Δt:
 *   r ← r + (1 − e^{−κΔt}) (r* − r).
 * At steady state r_i² = Σ r_c² + a_L/π·[leaf] at every branching. */
#ifndef PHC_CLIMBING_CAMBIUM_H
#define PHC_CLIMBING_CAMBIUM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Target areas A* (n, m²) of a tree whose parents precede their children
 * (parent[i] < i, parent[0] = (size_t)-1), radii r (m), primary radii r0
 * (m), leaf flags (NULL: none) and leaf pipe area a_leaf (m²).  has_child
 * is scratch of n bytes. */
void phc_climbing_pipe_targets(size_t n, const size_t *parent, const double *r,
                               const double *r0, const unsigned char *leaf, double a_leaf,
                               unsigned char *has_child, double *target);

/* One step of dt (s) at rate kappa (s⁻¹) toward the target area (m²):
 * returns the new radius (m), never below r. */
double phc_climbing_cambium_step(double r, double target_area, double kappa, double dt);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_CAMBIUM_H */
