/* Oriented particles with generalized shape matching on a plant graph
 * (climbing plants: Hädrich, Benes, Deussen, Pirk, "Interactive Modeling
 * and Authoring of Climbing Plants", CGF 36(2) 2017, §4.1 and §4.3; the
 * particle model of Müller & Chentanez, "Solid simulation with oriented
 * particles", SIGGRAPH 2011).
 *
 * Representation (decided here, see README "Oriented particles"):
 *   one particle per SEGMENT of a phc_plant_graph, at the segment's centre
 *   (head + tail)/2.  Its ellipsoid has radii (r, r, L/2) along the
 *   particle's local x, y, z, and the local z axis points from head to tail
 *   in the rest pose, so a particle IS its segment: the segment's ends are
 *   centre -/+ R(q)·(0, 0, L/2) (phc_particles_segment_ends draws them).
 *   Mass m = density·π r² L (the segment's cylinder; the ellipsoid only
 *   supplies the second-moment term below).
 *
 * Groups (climbing §4.1): every particle k owns the group
 *   G_k = {k} ∪ {parent(k), if linked} ∪ {linked children of k}.
 * A particle i belongs to its own group, to its parent's group and to each
 * child's group.  Blending weights (this module's reading of the paper's
 * parent-weighted blend): raw weight w_p (parent_weight, >= 1) for the group
 * owned by i's parent, 1 for every other group of i; normalised,
 * ω_ik = w_ik / Σ_k' w_ik'.  The goal of i is x_g,i = Σ_k ω_ik g_i^k.
 * Each group matches with the member masses μ_ik = ω_ik m_i (the share of
 * i's mass lent to group k, as Rivers & James's lattice shape matching
 * divides a particle's mass among its regions), so that Σ_k μ_ik = m_i and
 * the blended projection conserves total linear momentum exactly when the
 * stiffness s is the same for all particles.
 *
 * Moment matrix of group k (Müller & Chentanez eq. 9, centred form):
 *   A_k = Σ_j μ_jk (x_j − c_k)(x̄_j − c̄_k)ᵀ + Σ_j (μ_jk/5) R_j D_j R̄_jᵀ,
 *   D_j = diag(r², r², (L/2)²) (kg m²), R_j current, R̄_j rest orientation.
 * With R̄ = I this is the paper's Σ m x x̄ᵀ − M c c̄ᵀ + Σ (1/5) m R diag(a²,b²,c²).
 * The ellipsoid term makes A_k of full rank for a single particle or a
 * straight chain, so the rotation is defined.  R_k = rotational factor of
 * the polar decomposition A_k = R_k S_k (Newton steps warm-started from
 * the group's last rotation, phc_particles_polar_rotation_warm; the Müller,
 * Bender, Chentanez, Macklin 2016 iteration with its certificate and
 * LAPACK SVD fallback when they do not converge).  Goals
 * g_j^k = R_k (x̄_j − c̄_k) + c_k.
 *
 * Stiffness blend (climbing §4.1): x ← x_p + s_i (x_g − x_p).  s_i is the
 * particle's own stiffness (phc_particles_set_stiffness) or, when
 * maturity_age t_m > 0, the age-dependent s_i = min(1, t_l / t_m) with t_l
 * the particle's age (young shoots are soft, mature ones stiff; the clamp
 * at 1 is ours: a particle older than t_m is as stiff as the model allows).
 * Orientation: q_i ← quat(R_i) ⊗ q̄_i, the rotation of i's own group
 * applied to its rest orientation (Müller & Chentanez §4.2).
 *
 * Anchors (climbing eq. 5): an anchored particle is pulled to its anchor
 * point a after every projection, x ← x + k_a (a − x), 0 < k_a <= 1
 * (k_a = 1 pins it: x = a exactly); optionally its orientation is held
 * too (a clamp).  phc_particles_attach applies the paper's rule: a free
 * particle attaches to its closest support point when that point is
 * within the attach distance.
 *
 * Time step (position-based dynamics): predict v += Δt (g + f/m),
 * x_p = x + Δt v, q_p = exp(ω Δt) q; N iterations of {all groups' goals
 * from the current x_p (Jacobi), blend, stiffness, anchors}; with
 * follow_parent, the joint pass below; with a collider, one
 * collision pass (phc_particles_set_collider); update v = (x_p − x)/Δt,
 * ω from q_p q⁻¹, both times (1 − damping); age += Δt.
 *
 * Shoots that bend (follow_parent; ours).  The Jacobi projections above
 * move a shape only by one group per iteration, so a long chain with s = 1
 * still bends under a sustained load: a 22 cm shoot clamped at one end
 * hangs nearly vertical after 4000 substeps of 0.01 s (climbing Fig. 12 b),
 * and how far it hangs depends on the time step and the iteration count
 * (README "Effective stiffness").  With follow_parent, after the N
 * iterations every linked particle i, parents u before children, hangs
 * from a joint on its parent (an angular spring, one XPBD step per
 * substep: Macklin, Müller, Chentanez, "XPBD", MIG 2016, eq. 18; the
 * segment follow-the-leader of Müller, Kim, Chentanez, "Fast simulation of
 * inextensible hair and fur", VRIPHYS 2012, §3):
 *   J   = x_u + R(q_u) R(q̄_u)ᵀ (h̄_i − x̄_u)      the joint: i's rest head
 *         h̄_i = x̄_i − R(q̄_i)(0, 0, L_i/2) held in u's frame (m);
 *   q_f = rot(h → h + a Δt²) q_i,  h = R(q_i)(0, 0, L_i/2)   the free turn:
 *         the last orientation turned by the load a = g + f/m (m s⁻²)
 *         moving the centre from rest for one substep;
 *   q*  = q_u q̄_u⁻¹ q̄_i                            the rest angle to u;
 *   q_i ← exp(k log(q* q_f⁻¹)) q_f,  k = s Δt² / (s Δt² + (1 − s) T²),
 *   x_i ← J + R(q_i)(0, 0, L_i/2),
 * then i's anchor.  k is XPBD's answer for the angular constraint
 * C = log(q* q_f⁻¹) with compliance α̃ = (1 − s) T² / (s Δt²) per unit
 * inverse inertia and its multiplier reset each substep (so it does not
 * depend on N); T = stiffness_step.  s = 1 gives k = 1: a tree clamped at
 * its root keeps its rest shape exactly, whatever the substep.  The centre
 * follows the orientation, so the joints stay connected and a soft shoot
 * BENDS.  Static balance (Δt → 0, a link at angle φ below the horizontal,
 * its parent at φ_u, rest angle 0 between them):
 *   φ − φ_u = c cos φ,   c = 2 g T² (1 − s) / (s L)  (rad),
 * the same for every Δt in that limit; each link carries its own weight
 * only (not the moment of its subtree: bending = BEAM below does).  The pass reads the last
 * orientation and the load, not the velocity, so a soft link relaxes to
 * its balance in geometric steps of 1 − k without overshoot (a version
 * predicting with x + vΔt whipped a 0.5 m cantilever to 19 m/s).  The pass
 * does not conserve momentum (a parent does not feel its children): meant
 * for plants held at their root.  A particle with s = 0 is not held.
 *
 * Shoots that bend like beams (follow_parent with bending = BEAM; ours).
 * The linked particles are rigid links of an articulated tree: a BALL
 * joint (0 < s_i < 1) at i's head J_i (as above) with a spring, a WELD
 * (s_i = 1: i held at its rest angle, part of its parent's body), and the
 * particles without a hold (roots, broken links, s = 0) are bases whose
 * motion the projections give.  The bend of a BALL joint is θ_i = log(q_i
 * q*_i⁻¹) (rad, a rotation vector in world axes) about the rest turn q*_i
 * above; its spring
 *   κ_i = E(s_i) π r_i⁴ / (4 ℓ̄_i)  (N m rad⁻¹), E(s) = E_1/2 s / (1 − s),
 * the Euler–Bernoulli bending moment M = E I_a ∂φ/∂x (I_a = π r⁴/4, the
 * circular section's second moment of area, m⁴) lumped over the joint's
 * share of the bending links, ℓ̄_i = (L_i + L_u)/2, or L_i/2 when the
 * parent does not bend (a base or a WELD): the Voronoi length of discrete
 * elastic rods (Bergou, Wardetzky, Robinson, Audoly, Grinspun, SIGGRAPH
 * 2008, bending energy Σ E I_a θ² / (2 ℓ̄)).  s = 1/2 gives E_1/2 (the
 * option beam_modulus), s → 1 rigid, s → 0 free.  The stiffness comes from
 * E I_a, not from T, so that refining the links leaves the shape alone.
 * One step, from the state at its start (x, q, ω; the joints' J, θ and
 * ω_rel = ω_i − ω_u), is semi-implicit Euler in the joint angles with the
 * spring implicit:
 *   (H + Δt² K) α = Q_g + Q_f − K (θ + Δt ω_rel),  ω⁺ = ω_rel + Δt α,
 *   θ⁺ = θ + Δt ω⁺,  q_i ← exp(θ⁺_i) q*_i,  x_i ← J_i + R(q_i)(0, 0, L_i/2)
 * (q* and J from the parent's final state, parents first, then i's
 * anchor), H the tree's joint-space mass matrix (each link a cylinder: m
 * r²/2 about its axis, m (3r² + L²)/12 across), K = diag(κ_i), Q_g and Q_f
 * the moments of gravity and of the external forces on each joint's whole
 * subtree.  α comes from Featherstone's articulated-body algorithm
 * (Featherstone, "Rigid Body Dynamics Algorithms", Springer 2008, ch. 7:
 * spatial vectors in world axes about one point, gravity as the bases'
 * acceleration −g, the implicit spring's Δt² κ as the joint's armature),
 * O(n): one sweep children before parents (articulated inertias and
 * biases), one parents first, both on the joint pass's order (subtrees on
 * threads; the same numbers for any thread count).  The
 * velocity-product (Coriolis) terms and the bases' own accelerations are
 * left out (slow shoots on held bases).  Velocities then come from the
 * positions, damped by (1 − damping) as every velocity.
 * Statics: K θ = Q at every joint, the exact balance of the links on
 * their springs: a uniform cantilever bends most at its base, and its
 * small-angle tip deflection is the trapezoid rule of Euler–Bernoulli's:
 * q L⁴ / (8 E I_a) (1 + 1/n²) for n equal links.  Dynamics: exact for the
 * linearised tree (with the implicit spring's numerical damping, O(Δt));
 * one link on a held parent swings with period 2π / sqrt((κ + m g L/2)/I)
 * hanging down, an 8-link chain with the period of its linearised first
 * eigenmode to 3e-4 (tests/unit/test_particles_beam.c), a 22-link
 * cantilever within 0.5% of its first Euler–Bernoulli mode
 * (notebooks_c/climbing_beam_shoot.c).  The anchors' reactions are not in
 * Q (an anchor still pulls its particle after the joint places it).
 * A WELD (s = 1) is placed as in the own-weight pass with k = 1: the same
 * numbers.

 * Breaking (climbing §4.3; our definition of the stress): after the step,
 * each group's stress is its relative RMS misfit to the best rigid motion,
 *   σ_k = sqrt( Σ_j μ_jk |x_j − g_j^k|² / Σ_j μ_jk |x̄_j − c̄_k|² )
 * (dimensionless, 0 for any rigid motion; 0 for a group of one particle).
 * If the largest σ_k over groups with a linked parent exceeds the break
 * threshold, the link k–parent(k) is removed: the subtree rooted at k
 * becomes free.  At most one link breaks per step (the most stressed); the
 * others are judged again at the next step with the new topology.
 *
 * Breaking under a bending stress (ours, on the beam pass; the break of
 * climbing §4.3 with a stress in Pa).  With bending = BEAM the moment a
 * BALL joint carries is its spring's, M_i = κ_i |θ_i| (N m), and the
 * largest bending stress of the circular section there, at its surface,
 * is Euler–Bernoulli's σ_i = M_i r_i / I_a = 4 M_i / (π r_i³) =
 * E(s_i) r_i |θ_i| / ℓ̄_i (Pa; the flexure formula σ = M y / I of
 * Euler–Bernoulli beams, e.g. Gere & Timoshenko, "Mechanics of
 * Materials"; used for stems in Niklas 1992, "Plant Biomechanics"), r_i
 * the radius of the link below the joint.  phc_particles_bend_stress
 * reads σ_i of the current state (θ from the orientations after the step,
 * anchors and collisions included; at rest κ θ = Q, the moment of the
 * loads beyond the joint).  A link breaks when σ passes the modulus of
 * rupture σ_R, the bending stress at which a stem fails (break_stress;
 * e.g. medians of 35.0 to 49.8 MPa for the stems of young trees in
 * "Mechanical properties of 'flexure wood'", Ann. For. Sci. 2020,
 * doi:10.1007/s13595-020-0926-8, Table 2; young climbing shoots: not
 * known to us, an example's value is an assumption): with break_stress
 * > 0, after each step the linked particle whose σ_i is largest breaks
 * its parent link when σ_i > break_stress (so the one that passes it by
 * the most; at most one per step, as the group-stress rule).  A WELD (s =
 * 1) is rigid, has no bend and reads 0: it does not break by this rule;
 * nor does a link whose parent is not held (a BASE).  The two rules
 * cannot be combined: break_stress > 0 with break_threshold > 0 is
 * refused, and so is break_stress > 0 without follow_parent and bending =
 * BEAM (the own-weight pass carries no moment).  break_stress = 0 (the
 * default): nothing measured, the same numbers as before it, bit for bit.
 *
 * Anchors that carry the moment (anchors_carry_moment; ours, beam pass
 * only).  By default the beam pass places an anchored particle by its
 * joint like any other and the anchor then pulls its centre only: the
 * anchors' reactions are not in Q, so the moment of every link beyond an
 * anchored stretch turns the stretch's orientations about the joints
 * behind it (a shoot on a board with an overhang: each anchored joint
 * bends, the most at the board's far end, and the overhang hangs down
 * from orientations that no longer follow the anchored centres).  With
 * anchors_carry_moment, an anchored particle is a BASE: it is not placed
 * by a joint, its centre is the projections' and its anchor's (as a
 * root's), its orientation is kept from the step's start (the joint pass
 * sets it back after the projections), its children hang from it, and
 * nothing of its subtree folds into its parent: the support takes the
 * load through the anchor, as a board carries a shoot lying on it.  The joint from an anchored particle to a
 * free child is then a clamp (ℓ̄ = L/2), the overhang a cantilever
 * clamped at the last anchor, and a joint between two anchored particles
 * carries nothing (σ 0).  The projections are computed for the anchored
 * particles (slower with many anchors).  Off by default: the same numbers
 * as before it.
 *
 * Units: SI.  Positions m, time s, mass kg, density kg m⁻³, force N,
 * gravity m s⁻², angular velocity rad s⁻¹, stiffness and stress
 * dimensionless.  Quaternions (w, x, y, z), unit norm. */
#ifndef PHC_PARTICLES_H
#define PHC_PARTICLES_H

#include <stddef.h>

#include "model/plant_graph.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PHC_PARTICLES_NONE ((size_t)-1)

typedef struct phc_particles_options {
    double density;        /* kg m^-3, > 0; default 1000 (fresh green stem) */
    double gravity[3];     /* m s^-2; default (0, 0, -9.81) (plant graphs have z up) */
    double stiffness;      /* s in [0, 1] for every particle (used when
                              maturity_age == 0); default 1 */
    double maturity_age;   /* t_m, s, >= 0; > 0: s_i = min(1, age_i / t_m) */
    double parent_weight;  /* w_p >= 1: weight of the parent's group in a
                              particle's goal blend; default 2; 1 = plain mean */
    size_t iterations;     /* projection iterations per step, >= 1; default 4 */
    double damping;        /* fraction of velocity removed per step, [0, 1); default 0.01 */
    double break_threshold;/* group stress above which the parent link breaks;
                              <= 0: no breaking (default 0) */
    int follow_parent;     /* 1: the joint pass after the projections
                              (see "Shoots that bend" above); default 0 */
    double stiffness_step; /* T, s, > 0: the time step at which the joint
                              pass turns by the fraction s; default 0.01 */
    int bending;           /* the joint pass's load (see "Shoots that bend
                              like beams"): PHC_PARTICLES_OWN_WEIGHT (each
                              link its own weight; default) or
                              PHC_PARTICLES_BEAM */
    double beam_modulus;   /* E_1/2, Pa, > 0: with PHC_PARTICLES_BEAM, the
                              Young's modulus of a link with s = 1/2;
                              default 1e7 */
    int anchors_carry_moment; /* 1: with PHC_PARTICLES_BEAM, an anchored
                              particle is a base of the beam pass, held by
                              its support (see "Anchors that carry the
                              moment"); default 0 */
    double break_stress;   /* σ_R, Pa, >= 0: with PHC_PARTICLES_BEAM, a link
                              whose joint's bending stress passes it breaks
                              (see "Breaking under a bending stress");
                              0: off (default) */
} phc_particles_options;

enum { PHC_PARTICLES_OWN_WEIGHT = 0, PHC_PARTICLES_BEAM = 1 };

phc_particles_options phc_particles_options_default(void);

typedef struct phc_particles phc_particles;

/* One particle per segment of a finished graph, at rest (positions from the
 * graph, zero velocity, age 0).  Segments with g->fixed[i] set are anchored
 * (k_a = 1, orientation held) at their rest centre.  Errors (NULL returned,
 * err filled): bad options (density, stiffness outside [0,1], parent
 * weight < 1, iterations 0, damping outside [0,1)), a radius or length not
 * positive and finite, a non-finite coordinate ("particle 3 (segment 17):
 * ..."), out of memory. */
phc_particles *phc_particles_new(const phc_plant_graph *g,
                                 const phc_particles_options *options,
                                 phc_error *err);
void phc_particles_free(phc_particles *p); /* accepts NULL */

size_t phc_particles_count(const phc_particles *p);

/* Growing a system in place (climbing plants: one system for the whole
 * growth, so that the groups' rotations warm-start the polar
 * decompositions and velocities carry over from frame to frame).
 *
 * phc_particles_append adds a particle for the segment head → tail (m) of
 * radius r (m) as a child of `parent` (linked; PHC_PARTICLES_NONE: a new
 * root), at rest: current = rest, zero velocities, age 0, no anchor, the
 * options' stiffness, mass ρπr²L.  Its index (the old count) goes to
 * *index (may be NULL).  The children and group slots are rebuilt once at
 * the next step (O(n), no allocation); the arrays grow by doubling.
 * Errors: parent out of range, a bad segment (as phc_particles_new), out
 * of memory (the system is unchanged and still valid). */
int phc_particles_append(phc_particles *p, size_t parent, const double head[3],
                         const double tail[3], double radius, size_t *index, phc_error *err);
/* New rest state of particle i from its segment head → tail (m) and radius
 * (m): rest centre, rest orientation, radii and mass ρπr²L (replacing a
 * mass set by phc_particles_set_mass).  The current state, velocities,
 * age, anchor and its group's rotation (the polar warm start) are kept. */
int phc_particles_set_rest(phc_particles *p, size_t i, const double head[3], const double tail[3],
                           double radius, phc_error *err);
/* Moves particle i to x (m) turned to the unit quaternion q (normalised
 * here) WITHOUT touching its velocities (a kinematic displacement, e.g. a
 * growing tip whose centre moves along its axis); phc_particles_set_position
 * and _set_orientation zero them instead. */
int phc_particles_place(phc_particles *p, size_t i, const double x[3], const double q[4],
                        phc_error *err);
/* A growing tip's hand-over in one call (ours; the climbing step's): with
 * head and tail, particle i's rest segment as phc_particles_set_rest; with
 * x, then phc_particles_place at x turned to phc_quat_from_z(dz) (dz unit:
 * the direction of its z axis).  The same checks, messages and numbers as
 * those calls; head, tail or x NULL leaves that part out. */
int phc_particles_set_rest_place(phc_particles *p, size_t i, const double head[3],
                                 const double tail[3], double radius, const double x[3],
                                 const double dz[3], phc_error *err);

/* Gravity of a system from the next step (m s^-2, finite; e.g. a scene
 * turned while a persistent system lives on). */
int phc_particles_set_gravity(phc_particles *p, const double g[3], phc_error *err);

/* on = 0: a step without breaking (break_threshold <= 0) skips the stress
 * pass after it (one shape matching of every group of five with the
 * default 4 iterations): phc_particles_stress keeps the last measured
 * values and the report's max_stress stays 0 (group NONE).  Default on. */
void phc_particles_measure_stress(phc_particles *p, int on);

/* Projections that cannot change the result are skipped (ours; exact):
 * with follow_parent, the joint pass sets the final state of every linked
 * particle with s > 0 from its parent's final state and its own last
 * orientation, and a pinned particle (anchor strength 1, orientation
 * held) ends at its anchor, so the N projections are computed only where
 * they reach the other particles (roots, broken links, s = 0): the groups
 * within two links per remaining iteration.  on = 1: every group is
 * projected anyway (for tests comparing the two; the state differs by
 * rounding only, through the polar warm starts).  Default off. */
void phc_particles_project_all(phc_particles *p, int on);

/* The own-weight joint pass places up to four links of one depth (in the
 * top of the tree or in a subtree handed to a thread) in one instruction
 * stream (ours; the same operations per link, so the same numbers bit for
 * bit: a shoot's links otherwise run one after another, each waiting for
 * its parent).  on = 0: one link at a time, in the pass's order (for tests
 * comparing the two).  Default on. */
void phc_particles_joint_lanes(phc_particles *p, int on);

/* Collisions with supports (ours; the climbing paper's particles only
 * attach to them).  fn gives the closest support point c (m) to x and the
 * unit outward face normal n there (0; nonzero: no support).  With a
 * collider set, every step ends its projection with one collision pass
 * over the predicted positions x_p and orientations q_p, before the
 * velocities are derived from them (position-based dynamics: the inward
 * velocity goes too).  A point's signed distance is δ = |x − c| when
 * (x − c)·n >= 0 (in front of the face) and −|x − c| otherwise; when
 * δ < r (the particle's radius) it is moved to c + r·u, u = (x − c)/|x −
 * c| in front (the surface normal at c, also round an edge or a corner),
 * u = n behind or on the face.  Each particle is a capsule (its segment
 * with radius r, ours): its centre is pushed, then its segment's two
 * ends x_p ∓ R(q_p)(0, 0, L/2); when an end moved, the centre becomes the
 * pushed ends' midpoint and the axis their direction (length kept: q_p
 * turned by the shortest rotation from the old axis to the new), the
 * centre is pushed again, up to 64 rounds; a round that starts from the
 * state (centre, axis) of one of the last four, bit for bit, would repeat
 * the rounds between to the last, so their pushes are counted without
 * being made (the same state and count).  (A straight segment across a
 * convex edge with both ends and its centre outside is not seen.)
 * Particles whose orientation is held (clamped) are left alone.  The
 * callback is called from one thread, particles in index order.  fn =
 * NULL: no collisions (default). */
typedef int (*phc_particles_closest_fn)(void *user, const double x[3], double c[3], double n[3]);
void phc_particles_set_collider(phc_particles *p, phc_particles_closest_fn fn, void *user);
/* The push of the collision pass on one point x (m) for a particle of
 * radius r (m): returns 1 and moves x when δ < r, else 0 (also without a
 * support).  *delta (may be NULL) gets δ before the move (m; +INFINITY
 * without a support). */
int phc_particles_push_out(phc_particles_closest_fn fn, void *user, double r, double x[3],
                           double *delta);
/* The capsule push of the collision pass on one segment of radius r (m)
 * and half length h (m) with centre x and unit axis `axis`: the centre is
 * pushed, then the two ends x ∓ h·axis; when an end moved, x becomes the
 * pushed ends' midpoint and `axis` their direction, the centre is pushed
 * again, up to `rounds` rounds.  Returns the points pushed (centre pushes
 * and end pushes); *depth (may be NULL) gets the smallest δ − r of the
 * centre and of the two ends before their first push (+INFINITY without
 * a support). */
int phc_particles_push_segment_out(phc_particles_closest_fn fn, void *user, double r, double h,
                                   int rounds, double x[3], double axis[3], double *depth);
/* The exact segment push (ours; opt-in, default none).  fn(user, a, b, r,
 * &t, &depth) gives the deepest point a + t(b − a) of segment a b (m)
 * against the same supports as the collider and returns 1 when its
 * signed distance is below r, 0 when not, negative on an error
 * (measurements/support_mesh.h phc_support_mesh_segment_deepest).  With
 * it set (and a collider), a particle in contact after its capsule push
 * (a point was pushed, or the smallest δ − r of its centre and ends, or
 * its lower bound, is below L/4: farther than that, the 1-Lipschitz
 * distance keeps the whole segment beyond r) is asked for its deepest
 * point y; while there is one deeper than r − 1e-13·(1 + |x|∞) m (a point
 * pushed to r, less rounding, is left), y is pushed as a point (the push above)
 * and the whole segment moved by that push (both ends alike: length and
 * axis kept), up to 16 rounds, each counted as a point pushed.  A
 * straight segment whose centre and ends lie out but whose middle cuts a
 * convex edge is so moved off the edge (to distance r, rounding: the
 * move is along the common perpendicular of the segment and the edge).
 * fn = NULL: the capsule push alone, bit for bit as without. */
typedef int (*phc_particles_segment_fn)(void *user, const double a[3], const double b[3], double r, double *t,
                                        double *depth);
void phc_particles_set_segment_collider(phc_particles *p, phc_particles_segment_fn fn, void *user);
/* That push on one segment (centre x, unit axis, half length h, radius
 * r; m): returns the rounds that moved x (0 without fn or deepest). */
int phc_particles_push_segment_deepest(phc_particles_closest_fn fn, void *user, phc_particles_segment_fn deepest,
                                       void *deepest_user, double r, double h, double x[3], const double axis[3]);
/* Collisions of the last step: points pushed out (centres and ends) and
 * the smallest δ − r (m) of a centre or an end seen before its particle's
 * first push (+INFINITY when none was measured). */
void phc_particles_collisions(const phc_particles *p, size_t *pushed, double *depth);

/* Queries the collision pass skips (ours; exact).  The pass keeps, for
 * each particle's centre and two ends, the point of its last query and
 * the answer (c, n), those of the first round and of the later rounds
 * apart.
 *  - The same point again, bit for bit (a pinned or resting particle):
 *    the kept answer is used (fn must be a function of x).
 *  - With phc_particles_supports_closed(p, 1), also a point x within
 *    d₀ − r − 1e-9·(1 + |x₀|∞) m of a point x₀ whose query found it in
 *    front at distance d₀: the distance to the supports is 1-Lipschitz,
 *    so x is still farther than r, and on closed surfaces with outward
 *    faces (front = outside) still in front: its query would push nothing
 *    (the margin covers rounding).  The smallest δ − r of
 *    phc_particles_collisions is kept exact by querying, after the pass,
 *    the skipped points whose lower bound d₀ − |x − x₀| − r lies below
 *    the smallest measured.  Not on open surfaces: beyond a sheet's border
 *    the side (x − c)·n flips on the sheet's plane far from the sheet
 *    (Fig. 13's wall, open at its foot: points below it are behind).
 * So the state and the statistics are those of the pass without skips,
 * bit for bit.  What is kept are facts about points: set_position and the
 * like need no reset; a different collider (set_collider with another fn
 * or user) forgets them, and so does phc_particles_supports_moved (call it
 * when the supports behind the same fn and user change).  collide_all
 * on = 1: every point is queried (for tests comparing the two).  Default
 * off; supports_closed default off. */
void phc_particles_supports_closed(phc_particles *p, int on);
void phc_particles_collide_all(phc_particles *p, int on);
void phc_particles_supports_moved(phc_particles *p);
/* Closest-point queries the collision passes made and skipped since the
 * system was made (counts). */
void phc_particles_collision_queries(const phc_particles *p, size_t *queries, size_t *skipped);

/* Setters; each validates and names the particle in its message. */
int phc_particles_set_mass(phc_particles *p, size_t i, double mass /* kg, > 0 */,
                           phc_error *err);
int phc_particles_set_stiffness(phc_particles *p, size_t i, double s /* [0,1] */,
                                phc_error *err);
int phc_particles_set_age(phc_particles *p, size_t i, double age /* s, >= 0 */,
                          phc_error *err);
/* Moves a particle (m; finite) and zeroes its velocity. */
int phc_particles_set_position(phc_particles *p, size_t i, const double x[3],
                               phc_error *err);
/* Turns a particle to the unit quaternion q (w,x,y,z; finite, not zero;
 * normalised here) and zeroes its angular velocity. */
int phc_particles_set_orientation(phc_particles *p, size_t i, const double q[4],
                                  phc_error *err);
/* External force on particle i, N (finite), held until changed. */
int phc_particles_set_force(phc_particles *p, size_t i, const double f[3],
                            phc_error *err);
/* Anchor (eq. 5) particle i at point a (m) with strength k in (0, 1];
 * hold_orientation != 0 also holds its current orientation.  A moving
 * anchor (a target point that drags the particle) is set again each step. */
int phc_particles_anchor(phc_particles *p, size_t i, const double a[3], double k,
                         int hold_orientation, phc_error *err);
int phc_particles_release(phc_particles *p, size_t i, phc_error *err);
/* Particle i's age (s) and anchor in one call (ours; the climbing step's
 * hand-over of every particle): phc_particles_set_age, then with k > 0
 * phc_particles_anchor(p, i, a, k, 0), else phc_particles_release; the same
 * checks and messages. */
int phc_particles_set_age_anchor(phc_particles *p, size_t i, double age, const double a[3],
                                 double k, phc_error *err);
/* The same for particles first .. first + count − 1 in one call: particle
 * first + j gets age[j], anchor point a[3j .. 3j + 2] and strength k[j].
 * On bad input it stops at the first bad particle, whose index goes to
 * *bad (may be NULL), and says what was wrong; the particles before it are
 * set. */
int phc_particles_set_ages_anchors(phc_particles *p, size_t first, size_t count,
                                   const double *age, const double *a, const double *k,
                                   size_t *bad, phc_error *err);
/* The paper's attachment rule: every particle without an anchor whose
 * closest support point (points: 3·count, m) lies within `distance` (m, > 0)
 * is anchored there with strength k.  *attached (may be NULL) counts them. */
int phc_particles_attach(phc_particles *p, const double *points, size_t count,
                         double distance, double k, size_t *attached,
                         phc_error *err);

typedef struct phc_particles_report {
    double max_stress;      /* largest group stress after the step (1) */
    size_t max_stress_group;/* its owner particle */
    size_t broken;          /* links broken this step: 0 or 1 */
    size_t broken_particle; /* the child whose parent link broke, else NONE */
    double broken_stress;   /* its group stress (1; 0 with break_stress) */
    double broken_bend_stress; /* with break_stress: its joint's σ (Pa) */
    double broken_joint[3]; /* the broken joint: the child's head (m), else NaN */
    double max_bend_stress; /* with break_stress: the largest joint σ (Pa) */
    size_t max_bend_particle; /* its particle (the joint's child), else NONE */
    size_t polar_total;     /* polar decompositions done in the step */
    size_t polar_fallbacks; /* of which the SVD fallback finished */
} phc_particles_report;

/* One time step of dt seconds (> 0, finite).  report may be NULL.  A state
 * that becomes non-finite is refused with PHC_ERR_NUMERIC naming the
 * particle (the step is then not applied: positions are kept). */
int phc_particles_step(phc_particles *p, double dt, phc_particles_report *report,
                       phc_error *err);

/* Accessors. */
void phc_particles_position(const phc_particles *p, size_t i, double x[3]);        /* m */
void phc_particles_velocity(const phc_particles *p, size_t i, double v[3]);        /* m s^-1 */
void phc_particles_orientation(const phc_particles *p, size_t i, double q[4]);
/* Centres (3 per particle, m) and orientations (4 per particle) of
 * particles first .. first + count − 1 (all exist) in one call. */
void phc_particles_poses(const phc_particles *p, size_t first, size_t count, double *x,
                         double *q);
double phc_particles_mass(const phc_particles *p, size_t i);                      /* kg */
double phc_particles_stiffness(const phc_particles *p, size_t i);  /* s_i in effect */
double phc_particles_stress(const phc_particles *p, size_t i); /* group i, last step */
/* Bending stress σ (Pa) at the head joint of particle i in its current
 * state (see "Breaking under a bending stress"): 4 κ_i |θ_i| / (π r_i³)
 * for a BALL joint of the beam pass, 0 for a weld, an unlinked particle
 * or without bending = BEAM. */
double phc_particles_bend_stress(const phc_particles *p, size_t i);
size_t phc_particles_parent(const phc_particles *p, size_t i); /* linked parent or NONE */
/* Segment ends for drawing (fit/shape_plots.h): head/tail 3n each, m. */
void phc_particles_segment_ends(const phc_particles *p, double *head, double *tail);
/* Total linear momentum Σ m v, kg m s^-1. */
void phc_particles_momentum(const phc_particles *p, double P[3]);
/* Angular velocity of particle i (rad s^-1), and both velocities set at
 * once (m s^-1, rad s^-1; finite), e.g. to carry a state over into a
 * system rebuilt without some particles (model/climbing_breaking.h). */
void phc_particles_angular_velocity(const phc_particles *p, size_t i, double w[3]);
int phc_particles_set_velocities(phc_particles *p, size_t i, const double v[3], const double w[3],
                                 phc_error *err);

/* Goals of group k from the current positions and orientations: members
 * (up to cap) and their goal positions (3·cap), the rotation R (row-major
 * 3x3) and the stress.  Returns the member count (0 when k is out of range
 * or cap is too small).  Uses the system's scratch space: do not call it
 * concurrently with other calls on the same system. */
size_t phc_particles_group_goals(const phc_particles *p, size_t k, size_t cap,
                                 size_t *member, double *goal, double R[9],
                                 double *stress);

/* Rotational factor of the polar decomposition of a 3x3 matrix A
 * (row-major): the proper rotation R maximising tr(Rᵀ A).  q (w,x,y,z) is
 * the start on entry (e.g. the last step's rotation) and the result on
 * return.  Müller et al. 2016 ("A robust method to extract the rotational
 * part of deformations") iteration, with a Newton step where tr(B)I −
 * sym(B) is positive definite (cut to 1 rad when longer) and at most 16 of
 * Müller's own steps (then the SVD); its stationary point is certified a
 * maximum (tr(S)·I − S positive semidefinite, S = RᵀA, checked by its
 * principal minors), otherwise LAPACK
 * dgesvd gives R = U diag(1, 1, det(UVᵀ)) Vᵀ.  Returns 0 with the
 * iteration, 1 with the SVD fallback, -1 when A is not finite or zero. */
int phc_particles_polar_rotation(const double A[9], double q[4]);

/* The same rotation for a warm start (the time step's path, ours): only
 * the Newton steps of phc_particles_polar_rotation, ω = T⁻¹ g with
 * T = tr(B) I − sym(B) factored as L D Lᵀ (no square roots), each applied
 * as q ← (1, ω/2) ⊗ q normalised (a turn by 2 atan(|ω|/2) about ω: no sine
 * or cosine), until a step shorter than 1e-9 rad.  T positive definite at
 * the last step certifies the maximum (tr(Rᵀ A) has no other local
 * maximum on the rotations).  When T is not positive definite (far from
 * the maximum) or after 8 steps, phc_particles_polar_rotation finishes
 * from where the steps got.  R (row-major) gets R(q); *steps (may be NULL)
 * the Newton steps taken, −1 when the full routine finished.  Returns as
 * phc_particles_polar_rotation. */
int phc_particles_polar_rotation_warm(const double A[9], double q[4], double R[9], int *steps);

/* Quaternions to and from matrices: model/quaternion.h. */

#ifdef __cplusplus
}
#endif

#endif /* PHC_PARTICLES_H */
