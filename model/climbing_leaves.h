/* Leaves of a climbing plant (Hädrich et al., "Interactive Modeling and
 * Authoring of Climbing Plants", CGF 36(2) 2017, §4.3: leaves sit at the
 * nodes of a shoot and turn toward the light; the paper's text of that
 * section was not available to us, so the laws below are ours, built from
 * what is common in plant modelling):
 *
 *  - Phyllotaxis: every `step`-th node of a shoot bears one leaf; the m-th
 *    leaf of a shoot (m = 0, 1, ...) leaves the stem at the azimuth m·α
 *    about the stem direction d (α the divergence angle, 137.5° the golden
 *    angle of spiral phyllotaxis; Prusinkiewicz & Lindenmayer, "The
 *    Algorithmic Beauty of Plants", 1990, §4.1).  The azimuth is measured
 *    in the frame (e1, e2) = R(d)·(x, y), R(d) the shortest-arc rotation
 *    taking z to d (model/quaternion.h phc_quat_from_z), so along a
 *    straight shoot successive leaves differ by exactly α.
 *  - The petiole direction p = cos(mα) e1 + sin(mα) e2 (⊥ d); the blade is
 *    a square of side s (leaf size, m) whose centre lies at the node plus
 *    p·s/2.
 *    Near a support (model/climbing_growth.c, ours): a petiole that points
 *    into the face of the closest support point of its node, within a
 *    blade's reach, is mirrored in that face (and made ⊥ d again), so the
 *    blades of a vine on a wall stay in front of it; the divergence angle
 *    then holds only away from supports.
 *  - Orientation: the blade's default normal is n0 = d (the blade spread
 *    across the stem).  In light I ∈ [0, 1] it turns toward the light
 *    direction ℓ: n = unit((1 − w) n0 + w ℓ), w = ω·I (ω ∈ [0, 1] the
 *    leaf's light response; I the light reaching the leaf, 1 − occlusion),
 *    then the angle between n and n0 is clamped to θ_max (a petiole bends
 *    only so far).  No light (I = 0), ω = 0 or ℓ = n0 give n = n0.
 *
 * Units: lengths m, angles rad. */
#ifndef PHC_CLIMBING_LEAVES_H
#define PHC_CLIMBING_LEAVES_H

#ifdef __cplusplus
extern "C" {
#endif

/* The phyllotaxis frame (e1, e2) ⊥ the unit stem direction d. */
void phc_climbing_leaf_frame(const double d[3], double e1[3], double e2[3]);

/* The petiole direction of the leaf of phyllotactic index m (azimuth
 * m·alpha, rad) on a stem along the unit d. */
void phc_climbing_leaf_petiole(const double d[3], double m, double alpha, double p[3]);

/* The blade normal: n = unit((1 − w) n0 + w ℓ), w = omega·light, its angle
 * to n0 clamped to max_angle (rad, [0, π]).  n0 and ell unit.  When the
 * blend vanishes (ℓ = −n0, w = 1/2) n = n0. */
void phc_climbing_leaf_normal(const double n0[3], const double ell[3], double omega,
                              double light, double max_angle, double n[3]);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_LEAVES_H */
