/* Climbing plants that grow (Hädrich, Benes, Deussen, Pirk, "Interactive
 * Modeling and Authoring of Climbing Plants", CGF 36(2) 2017, §4.2–4.3):
 * apical growth, lateral branching, phototropism, surface adaption and
 * anchors, on top of the oriented particles of model/particles.h.
 *
 * State.  A plant is a tree of particles, one per internode (segment), as
 * in model/particles.h: particle i has a parent (the particle whose tip it
 * grows from; NONE for the seed's), a branch order (0 for the main axis,
 * +1 per lateral branch), a size σ_i ∈ (0, 1] (its length is L_i = σ_i
 * L_max), a radius, an age, a current centre and direction (unit, from its
 * base toward its tip) and a rest centre and direction.
 *
 * One step of Δt seconds (phc_climbing_step), in this order:
 *  1. light (model/climbing_light.h) at every particle, I ∈ (0, 1];
 *  2. tropisms of the apical (growing) particles (model/climbing_tropism.h):
 *     phototropism toward the light direction (eq. 7, rate η), then
 *     surface adaption toward the closest support point (eq. 6, rate τ),
 *     each turning the current and the rest direction alike (eqs. 8–10);
 *     a tip within the contact distance that heads into the support loses
 *     the inward part of its direction (a collision rule of ours);
 *  3. apical growth (§4.2): dσ/dt = r·a^k·I (r the growth rate, s⁻¹; a^k
 *     the apical dominance over a tip of branch order k, 1 by default).  When σ
 *     reaches 1 the particle stops growing and spawns a successor at its
 *     tip, same direction, order and radius, of size σ₀ (bud_fraction)
 *     plus the excess σ − 1 (no growth is lost: Σσ = n σ₀ + r∫I dt, and a
 *     shoot in full light holds exactly 1 + ⌊r t / (1 − σ₀)⌋ particles);
 *  4. branching (§4.3, Fig. 5), at that same node: each of B lateral buds
 *     (max_buds) independently becomes a lateral shoot with probability BP
 *     (branch_probability), unless the node's order is already max_order.
 *     A lateral's direction makes the angle θ = u·V·90° with its parent's
 *     (u uniform on [0, 1), V = direction_variance ∈ [0, 1]) at a uniform
 *     azimuth; its radius is t_c = t_p·f (thickness_falloff f) and its
 *     size σ₀.  (The paper's V is a normalised variance with 1 ↔ 90°; the
 *     uniform law is our choice.)
 *  5. the rest shape is rebuilt from the rest directions (each rest centre
 *     at its parent's rest tip plus L_i/2 along its direction; the seed's
 *     base is fixed);
 *  6. dynamics, when dynamics_substeps > 0: one phc_particles system lives
 *     across the steps (made from the rest shape at the first dynamic
 *     step); each step hands it the new particles (appended at their
 *     current place, at rest), the rest segments that changed, the current
 *     place of particles the growth moved (velocities kept), the ages and
 *     the anchors; it is stepped dynamics_substeps times by Δt/substeps
 *     (stiffness s = max(s_min, min(1, t_l/t_m)) from the particles'
 *     maturity age t_m, passed to model/particles as the age
 *     max(t_l, s_min·t_m); the seed particle is clamped; the particles'
 *     joint pass, particles.follow_parent, holds a mature particle at its
 *     rest angle to its parent and lets a young one bend about its joint),
 *     and the current centres and directions are
 *     read back.  Velocities and the groups'
 *     rotations carry over from one growth step to the next.  Switching
 *     the dynamics off, or a failed dynamics step, drops the system (the
 *     next dynamic step starts afresh, at rest).  With collide, every
 *     particle is pushed out of the supports (see the option).  With
 *     dynamics_substeps = 0 the plant is kinematic: current = rest.
 *     With particles.break_threshold > 0 (the group stress) or
 *     particles.break_stress > 0 (the beam pass's bending stress in Pa,
 *     model/particles.h) a substep may break a link: the subtree below it
 *     falls as free particles for fall_time and then leaves the plant
 *     (model/climbing_breaking.h; indices close up).
 *  7. anchors (eq. 5): a particle without an anchor whose closest support
 *     point lies within attach_distance is anchored there; its strength
 *     k = k_max·σ_i·min(1, (t − t_anchor)/anchor_time) rises with the
 *     anchor's age and is ∝ the particle's size, so a growing tip holds
 *     weakly and lets its elongation win; an anchor is released when the
 *     particle is farther than release_distance from it.
 *
 *  8. leaves (model/climbing_leaves.h): every leaf_step-th node of a shoot
 *     bears a leaf when its particle is grown (σ = 1); each step its blade
 *     is placed at its node along the phyllotactic petiole and turned toward
 *     the light it received in step 1 (leaves are light-grid points too, and
 *     shade it as volumes s²·leaf_thickness).
 *  9. secondary growth (model/climbing_cambium.h), after step 4 when
 *     cambium_rate > 0: every radius relaxes toward the pipe model's
 *     √(Σ children's areas + leaf share)/π); the dynamics see the thicker
 *     particle as stiffer: its age is passed as max(t_l, s_min·t_m)·(r/r0)⁴
 *     (bending stiffness E·πr⁴/4 grows as r⁴; the mapping onto the
 *     particles' age law is ours), r0 its primary radius.
 * With seek_light, step 1 also builds the light field of
 * model/climbing_light_field.h (only when the light varies: extinction > 0
 * or shadows) at the nodes around the apical tips, and step 2's
 * phototropism turns toward its gradient there.
 * Supports may cast shadows (phc_climbing_set_shadow_triangles: the mesh
 * rasterised into the light grid's opaque mask, model/climbing_light.h).
 *
 * Random numbers: model/climbing_rng.h, state in the plant; the same seed
 * and options give the same plant, bit for bit, on any number of OpenMP
 * threads: the light, the tropisms (step 2), the anchors (step 7) and the
 * leaves (step 8) run over the particles in parallel from 4096 particles
 * (16,384 light points) on, each particle's result its own; the
 * growth and branching (steps 3–4, which draw the random numbers) run in
 * index order after all tropisms, as before.
 *
 * Supports enter only as a closest-point callback (phc_climbing_closest_fn),
 * so model/ needs no mesh library (measurements/support_mesh.h provides one).
 *
 * The paper's text of eqs. 5–10 was not available to us, only descriptions
 * of the model; the forms here are our readings, and our own choices are
 * marked "ours".
 *
 * Units: SI.  Lengths m, time s, rates s⁻¹, angles rad unless named _deg. */
#ifndef PHC_CLIMBING_GROWTH_H
#define PHC_CLIMBING_GROWTH_H

#include <stddef.h>
#include <stdint.h>

#include "model/climbing_light.h"
#include "model/particles.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PHC_CLIMBING_NONE ((size_t)-1)

/* Closest point c (m) on the supports to x (m) and the unit face normal n
 * there; returns 0, or nonzero when there is none (no support).  It may be
 * called from several OpenMP threads at once (the tropisms, anchors and
 * leaves of a step run over the particles in parallel), so it must only read
 * shared state, as measurements/support_mesh.h's query does. */
typedef int (*phc_climbing_closest_fn)(void *user, const double x[3], double c[3],
                                       double n[3]);

typedef struct phc_climbing_options {
    uint64_t seed;              /* random seed; default 1 */
    /* growth (§4.2) */
    double max_length;          /* L_max, m, > 0: length of a grown particle; default 0.02 */
    double bud_fraction;        /* σ₀ ∈ (0, 1): size of a new particle / L_max; default 0.25 */
    double growth_rate;         /* r, s^-1, >= 0: dσ/dt in full light; default 0.1 */
    double apical_dominance;    /* a ∈ (0, 1]: a tip of branch order k grows at r·a^k, so
                                   laterals grow slower than the axis that bears them
                                   (apical control as in Palubicki et al., "Self-organizing
                                   tree models for image synthesis", SIGGRAPH 2009, §4;
                                   the power law is ours, the climbing paper gives none);
                                   default 1 (no dominance) */
    double radius;              /* m, > 0: radius of the main axis; default 0.002 */
    size_t max_particles;       /* growth stops when reached (>= 1); default 20000 */
    /* branching (§4.3, Fig. 5) */
    double branch_probability;  /* BP ∈ [0, 1]; default 0.3 */
    unsigned max_buds;          /* B: lateral buds per node; default 1 */
    double direction_variance;  /* V ∈ [0, 1]: lateral angle up to V·90°; default 0.5 */
    double thickness_falloff;   /* f ∈ (0, 1]: t_child = t_parent·f; default 0.7 */
    unsigned max_order;         /* nodes of this order bear no laterals; default 3 */
    /* light (model/climbing_light.h); its direction is also phototropism's */
    phc_climbing_light_grid light; /* default: no shading (λ = 0), ℓ = (0, 0, 1) */
    /* tropisms (eqs. 6–10) */
    double phototropism;        /* η, s^-1, >= 0; default 0 */
    double surface_adaption;    /* τ, s^-1, >= 0; default 0 */
    double adaption_radius;     /* m: supports farther from a tip do not attract; default 0.1 */
    double contact_distance;    /* m: within it a tip crawls along the support; default 0.004 */
    /* phototropism toward where the light is (model/climbing_light_field.h) */
    int seek_light;             /* 1: eq. 7's target is the gradient of the light field at
                                   the tip, ∇F/|∇F| (the direction of most light, −∇O),
                                   falling back to ℓ where |∇F|·h < light_gradient_threshold,
                                   so a shoot in a wall's shade turns toward a gap.  0
                                   (default): the fixed direction ℓ — the old model bit for
                                   bit, and no field to compute (it costs 1 + 6 ray marches
                                   per grid cell and step) */
    double light_spread_deg;    /* ψ ∈ [0, 89] degrees: the field's sky is ℓ and six
                                   directions ψ from it (a penumbra of width ≈ 2H tan ψ at
                                   depth H below an edge); default 30 */
    double light_gradient_threshold; /* >= 0: smallest change of light over one cell that
                                   counts as a direction; default 1e-3 */
    /* anchors (eq. 5) */
    double attach_distance;     /* m, >= 0 (0: no anchors); default 0.005 */
    double release_distance;    /* m, > attach_distance; default 0.02 */
    double anchor_strength;     /* k_max ∈ (0, 1]; default 0.5 */
    double anchor_time;         /* s, > 0: time for an anchor to reach full strength; default 10 */
    /* dynamics (model/particles.h) */
    size_t dynamics_substeps;   /* 0: kinematic (default) */
    double min_stiffness;       /* s_min ∈ [0, 1]: s = max(s_min, min(1, t_l/t_m)); default 0.1
                                   (ours: with s = 0 a newborn particle has no
                                   link to the plant and falls free) */
    phc_particles_options particles; /* its maturity_age is t_m; default
                                        phc_particles_options_default() with
                                        maturity_age 50 s and follow_parent 1
                                        (mature shoots keep their shape) */
    /* supports */
    phc_climbing_closest_fn closest; /* NULL: no supports */
    void *closest_user;
    phc_particles_segment_fn closest_segment; /* deepest point of a segment against the same
                                   supports (measurements/support_mesh.h
                                   phc_support_mesh_segment_deepest; user closest_user),
                                   for collide_segments; NULL: none */
    /* leaves (§4.3; model/climbing_leaves.h) */
    unsigned leaf_step;         /* every leaf_step-th node of a shoot bears a leaf (its
                                   first node, 0, included); 0: no leaves (default) */
    double leaf_angle_deg;      /* α, degrees, finite: divergence angle; default 137.5 */
    double leaf_size;           /* s, m, > 0: side of the square blade; default 0.03 */
    double leaf_thickness;      /* m, >= 0: a leaf shades the light grid as a volume
                                   s²·thickness (Beer–Lambert, like the stems); default 3e-4 */
    double leaf_response;       /* ω ∈ [0, 1]: how far a lit blade turns toward ℓ; default 1 */
    double leaf_max_angle_deg;  /* θ_max ∈ [0, 180]: largest turn from the default normal;
                                   default 80 */
    /* secondary growth (pipe model; model/climbing_cambium.h) */
    double cambium_rate;        /* κ, s^-1, >= 0: 0 = no secondary growth (default) */
    double leaf_pipe_area;      /* a_L, m², >= 0: cross-section one leaf adds below it;
                                   default 0 */
    /* supports: keep the tips outside (ours) */
    int keep_outside;           /* 1: a growing tip whose end or centre lies behind the face
                                   of its closest support point (outward normal n) is turned,
                                   about its base, to the unit bisector of its tangential
                                   part and n (45° off the face, outward), so the shoot
                                   does not grow through a wall at an edge or corner; new
                                   laterals are checked at birth.  0 (default): off */
    int collide;                /* 1: collisions of every particle with the supports (ours;
                                   model/particles.h phc_particles_set_collider): a particle
                                   whose centre lies closer than its radius to the supports, or
                                   behind a face, is pushed out to its radius along the surface
                                   normal, inside each dynamics step (before the velocities; there
                                   the segment's two ends too: the particle is a capsule) or,
                                   kinematic, after current = rest; the seed particle is left
                                   alone.  0 (default): off */
    int collide_ends;           /* with collide, kinematic plants only (ours): after the centre
                                   push, the segment's two ends x ∓ (L/2)d are pushed out to the
                                   radius as well, and the centre and direction are rebuilt from
                                   the pushed ends (centre their midpoint, direction base → tip,
                                   length kept), up to 16 rounds per particle, the centre pushed
                                   again after each; a straight internode rounding a convex edge
                                   then cuts less of its corner.  The current shape's segments
                                   need not join (as with the centre push alone).  Not needed
                                   with dynamics (collide pushes the ends there).  0 (default):
                                   off */
    int collide_segments;       /* with collide and dynamics (ours): each particle in contact
                                   is also pushed off at its segment's deepest point
                                   (closest_segment; model/particles.h
                                   phc_particles_set_segment_collider), so no straight
                                   segment cuts a convex edge between its pushed centre and
                                   ends.  0 (default): off, bit for bit as before */
    int collide_all;            /* with collide and dynamics, for tests: 1 makes every
                                   closest-point query of the collision pass, none skipped
                                   (model/particles.h phc_particles_collide_all; the same
                                   numbers, bit for bit).  0 (default) */
    int supports_closed;        /* 1: the supports behind `closest` are closed surfaces with
                                   outward faces, so the dynamics' collision pass may skip the
                                   queries of points too far off them to be pushed
                                   (model/particles.h phc_particles_supports_closed; wrong
                                   pushes on open sheets).  0 (default): only repeated points */
    /* breaking (§4.3; model/climbing_breaking.h): with dynamics and
       particles.break_threshold > 0 (default 0: off) a link whose group
       stress passes the threshold breaks and the subtree below it falls;
       or, with bending beam, particles.break_stress > 0 (Pa; one rule at
       a time): a link whose joint's bending stress passes it */
    double fall_time;           /* s, >= 0: a broken piece falls this long as free particles,
                                   then leaves the plant; default 1 */
    double resprout_delay;      /* s, >= 0: a stump left without a shoot by a break grows a
                                   new tip at its top this long after the break (Cline 1991;
                                   model/climbing_breaking.h "Resprouting"); default INFINITY:
                                   never */
} phc_climbing_options;

phc_climbing_options phc_climbing_options_default(void);

typedef struct phc_climbing phc_climbing;

/* A seed: one particle of size σ₀ whose base is at `base` (m) and which
 * grows along `direction` (any non-zero length; normalised here).  Errors
 * (NULL, err filled, PHC_ERR_INVALID, message naming the option as in
 * "climbing: branch_probability = 1.5 is outside [0, 1]"): any option out
 * of its range above, a non-finite or zero vector, the light grid's cell
 * or dims; PHC_ERR_INPUT for a seed behind the face of its closest support
 * point (inside a closed support whose normals point out, or behind an
 * open one: the front of a face is where its right-hand normal points);
 * out of memory. */
phc_climbing *phc_climbing_new(const double base[3], const double direction[3],
                               const phc_climbing_options *options, phc_error *err);
void phc_climbing_free(phc_climbing *c); /* accepts NULL */

/* One growth step of dt seconds (> 0, with r·dt < 1 − σ₀ so that one step
 * spawns at most one successor per tip).  Errors: a bad dt (PHC_ERR_INVALID,
 * nothing changed); a dynamics failure (its message: the step's growth is
 * kept, the current shape is the one before the dynamics, anchors are not
 * updated); out of memory (the tips grown so far in the step are kept). */
int phc_climbing_step(phc_climbing *c, double dt, phc_error *err);

/* Changes the gravity of the dynamics (m s^-2, finite), e.g. when the scene
 * is turned or tilted while the plant grows. */
int phc_climbing_set_gravity(phc_climbing *c, const double g[3], phc_error *err);

/* Switches the dynamics on (substeps > 0) or off (0) from the next step,
 * e.g. to grow a plant kinematically and then let it settle.  Error: substeps
 * > 0 with particles.maturity_age = 0 (PHC_ERR_INVALID, nothing changed). */
int phc_climbing_set_dynamics_substeps(phc_climbing *c, size_t substeps, phc_error *err);

/* Collisions of the last step (option collide): points pushed out and the
 * smallest δ − r (m) before the pushes (+INFINITY when none measured; δ:
 * signed distance to the supports of a centre, and with dynamics or
 * collide_ends of a segment end too, model/particles.h). */
void phc_climbing_collisions(const phc_climbing *c, size_t *pushed, double *depth);
/* Closest-point queries the dynamics' collision passes made and skipped
 * since the plant's particle system was made (it is made again after a
 * break, or when the dynamics are switched off and on; 0, 0 without
 * one; model/particles.h phc_particles_collision_queries). */
void phc_climbing_collision_queries(const phc_climbing *c, size_t *queries, size_t *skipped);

/* Counters since the seed. */
typedef struct phc_climbing_stats {
    double time;            /* s */
    size_t particles;
    size_t apical;          /* growing tips */
    size_t bud_trials;      /* lateral buds drawn (B per node of order < max_order) */
    size_t laterals;        /* of which became shoots */
    size_t anchored;        /* particles holding an anchor now */
    size_t anchors_made;    /* anchors created */
    size_t anchors_released;
    size_t max_order;       /* highest branch order present */
    /* breaking (model/climbing_breaking.h) */
    size_t breaks;          /* links of the plant broken (each one a piece) */
    size_t falling;         /* particles falling now (counted in particles) */
    size_t pieces_dropped;  /* pieces that left the plant */
    size_t particles_dropped; /* their particles */
    size_t last_break_id;   /* stable id (phc_climbing_id) of the child of the last broken link */
    double last_break_stress; /* its group stress when it broke (1; 0 with break_stress) */
    double last_break_bend_stress; /* with particles.break_stress: its joint's bending stress (Pa) */
    double first_break_time;  /* s: the plant's first break (NaN before it) */
    double first_break_bend_stress; /* its joint's bending stress (Pa; 0 with break_threshold) */
    double first_break_joint[3]; /* its joint, the broken child's head (m) */
    int first_break_parent_anchored; /* 1: the particle above the broken link held an anchor */
    size_t resprouts;       /* stumps that grew a new tip (resprout_delay) */
    size_t last_resprout_id; /* stable id of the last such new tip */
} phc_climbing_stats;

void phc_climbing_get_stats(const phc_climbing *c, phc_climbing_stats *s);

/* Accessors (i < count). */
size_t phc_climbing_count(const phc_climbing *c);
size_t phc_climbing_parent(const phc_climbing *c, size_t i);
unsigned phc_climbing_order(const phc_climbing *c, size_t i);
int phc_climbing_is_apical(const phc_climbing *c, size_t i);
/* 1 when i starts a lateral shoot (its order exceeds its parent's). */
int phc_climbing_is_lateral(const phc_climbing *c, size_t i);
double phc_climbing_size(const phc_climbing *c, size_t i);    /* σ, 1 */
double phc_climbing_length(const phc_climbing *c, size_t i);  /* m */
double phc_climbing_radius(const phc_climbing *c, size_t i);  /* m */
double phc_climbing_age(const phc_climbing *c, size_t i);     /* s */
double phc_climbing_light_at(const phc_climbing *c, size_t i);/* I, last step */
void phc_climbing_position(const phc_climbing *c, size_t i, double x[3]);      /* centre, m */
void phc_climbing_direction(const phc_climbing *c, size_t i, double d[3]);     /* unit */
void phc_climbing_rest_position(const phc_climbing *c, size_t i, double x[3]); /* m */
void phc_climbing_rest_direction(const phc_climbing *c, size_t i, double d[3]);
/* Base and tip of the current segment: centre ∓ L/2·direction (m). */
void phc_climbing_segment(const phc_climbing *c, size_t i, double base[3], double tip[3]);
/* 1 and the anchor point a (m) when i is anchored; else 0. */
int phc_climbing_anchor(const phc_climbing *c, size_t i, double a[3]);
/* The anchor's strength now (eq. 5), 0 when not anchored. */
double phc_climbing_anchor_strength(const phc_climbing *c, size_t i);

/* Rasterises the triangles (nt × 3 vertex indices into vertices, nv × 3,
 * m) into the light grid's opaque mask: from the next step they block the
 * direct light (model/climbing_light.h).  May be called more than once
 * (masks add up).  Errors: an index >= nv or a non-finite vertex
 * (PHC_ERR_INVALID naming the triangle); out of memory. */
int phc_climbing_set_shadow_triangles(phc_climbing *c, const double *vertices, size_t nv,
                                      const size_t *triangles, size_t nt, phc_error *err);
/* Opaque cells of the light grid (0 without shadows). */
size_t phc_climbing_opaque_cells(const phc_climbing *c);

/* Leaves: 1 when particle i bears one, with its blade's centre (m), unit
 * normal and unit petiole direction (any of them may be NULL); else 0. */
int phc_climbing_leaf(const phc_climbing *c, size_t i, double centre[3], double normal[3],
                      double petiole[3]);
/* The light I its leaf received in the last step (0 without a leaf). */
double phc_climbing_leaf_light(const phc_climbing *c, size_t i);
/* The four corners (m, counter-clockwise seen from the normal's side) of
 * i's blade, a square of side leaf_size; 0 without a leaf. */
int phc_climbing_leaf_quad(const phc_climbing *c, size_t i, double corners[12]);
/* Leaves on the plant. */
size_t phc_climbing_leaf_count(const phc_climbing *c);
/* The unit light direction ℓ in use. */
void phc_climbing_light_direction(const phc_climbing *c, double l[3]);
/* Node index of i along its shoot (0 for a shoot's first particle). */
unsigned phc_climbing_node_index(const phc_climbing *c, size_t i);
/* The primary radius r0 (m) i was born with (phc_climbing_radius is the
 * radius now, after secondary growth). */
double phc_climbing_primary_radius(const phc_climbing *c, size_t i);
/* 1 when i belongs to a broken piece that still falls (model/climbing_breaking.h). */
int phc_climbing_is_falling(const phc_climbing *c, size_t i);
/* i's stable id: its birth number (the index it had when it was made),
 * kept when broken pieces leave the plant and the indices close up. */
size_t phc_climbing_id(const phc_climbing *c, size_t i);
/* Group stress of i in the last dynamics substep (model/particles.h,
 * measured with particles.break_threshold > 0; else 0). */
double phc_climbing_stress(const phc_climbing *c, size_t i);
/* Bending stress (Pa) at i's head joint after the last dynamics substep
 * (model/particles.h phc_particles_bend_stress: the beam pass's; 0
 * without dynamics or bending beam). */
double phc_climbing_bend_stress(const phc_climbing *c, size_t i);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_GROWTH_H */
