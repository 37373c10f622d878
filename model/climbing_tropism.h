/* Tropisms of climbing-plant shoots (Hädrich, Benes, Deussen, Pirk, CGF
 * 36(2) 2017, §4.2, eqs. 6–10).
 *
 * Both tropisms turn the growth direction d of an apical particle toward a
 * target direction t:
 *   phototropism (eq. 7): t = the unit direction toward the light, strength η;
 *   surface adaption (eq. 6): t from the closest support point c, strength τ
 *     (phc_climbing_surface_target below).
 * Our reading of the integration (eqs. 8–10; the paper blends orientations
 * with a strength per step): in a step of Δt seconds the direction turns
 * by the fraction φ = min(1, strength·Δt) of its angle α = ∠(d, t), about
 * the axis d × t:  α ← (1 − φ) α.  Strengths are rates (s⁻¹), so the
 * result does not depend on the step size in the limit Δt → 0 (α decays
 * as exp(−strength·t)).  The SAME rotation is applied to the current
 * direction and to the rest direction (eqs. 8–10: the tropism changes
 * the plant's rest shape, so a bent shoot stays bent when its stiffness
 * rises).  Directions are unit 3-vectors (dimensionless). */
#ifndef PHC_CLIMBING_TROPISM_H
#define PHC_CLIMBING_TROPISM_H

#ifdef __cplusplus
extern "C" {
#endif

/* Turns d (and rest, when not NULL) by the fraction `fraction` in [0, 1]
 * of the angle from d to the unit target t, about d × t.  For t opposite
 * to d the axis is any direction perpendicular to d (the smallest
 * component's axis crossed with d).  Returns the angle turned (rad). */
double phc_climbing_turn(double d[3], double rest[3], const double t[3], double fraction);

/* Target direction of surface adaption (eq. 6; the contact rule is ours):
 * x is the shoot tip (m), c its closest support point (m), nf the support's
 * face normal there (unit; used only when x lies on the support).  With
 * δ = |x − c| and the outward normal n = (x − c)/δ (nf when δ = 0):
 *   δ >  contact:  t = −n          (grow toward the support)
 *   δ <= contact:  t = d − (d·n) n, normalised (crawl along it; when d is
 *                  along n, t = 0 and the function returns 0).
 * Returns 1 with t set, 0 when there is no target. */
int phc_climbing_surface_target(const double x[3], const double c[3], const double nf[3],
                                const double d[3], double contact, double t[3]);

/* Angle between unit vectors a and b, rad, in [0, π] (atan2 of |a×b| and
 * a·b: accurate near 0 and π). */
double phc_climbing_angle(const double a[3], const double b[3]);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_TROPISM_H */
