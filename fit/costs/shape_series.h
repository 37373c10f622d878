/* `shape_series` data sets (issue 19, Calibration): tracked organ angles over
 * time against the droop of an elastic stalk whose stiffness follows its
 * water (wilting paper, Maggioli et al. 2023, eq. 9, and §4.3's rods).
 *
 * Organ model (one per tracked series), a "stalk": a rod (model/rod.h) of
 * `segments` equal segments of total length L (m) and radius r (m), tissue
 * density ρ (kg m⁻³), carrying a terminal mass m_tip (kg, a dead load m_tip·g
 * at the tip), clamped at its base in the direction β (the base angle) in
 * the vertical x–z plane (x right, z up, gravity −z).  The clamp is the rod's
 * fixed root segment, a short segment (1e-3 · L/segments) pointing along β
 * (it carries no load and does not move).  Every segment has the same
 * Young's modulus
 *     E(t) = E_min + E_max · σ(κ (RWC(t) − χ0))        Pa      (eq. 9)
 * with the relative water content of a single compartment losing water at
 * the rate δ (s⁻¹) from RWC0 at t0:
 *     RWC(t) = RWC0 · exp(−δ (t − t0)).
 * (The water model on the stalk's graph is not used: a stalk's segments
 * would all dry alike, and the data carry no water measurement.)
 * The model angle at time t is the direction of the stalk's last segment,
 * head → tail, in the x–z plane, counter-clockwise from +x (rad), from the
 * static equilibrium (phc_rod_solve_static, Newton to the rod's tolerance),
 * taken within π of β; plus the series' angle offset when it has one.
 *
 * With options.plant, the organ model is the plant itself: one rod over the
 * whole graph (its root fixed), every segment at the same E(t), each series
 * the direction of one segment (named by its source id) in the x–z plane,
 * β that segment's rest direction; tip masses hang at those segments' tails.
 *
 * With options.plant and options.water_model, the water is the wilting
 * paper's water model on that plant (fit/costs/shape_water.h): each segment
 * i has its own relative water content x_i(t) = θ_i(t)/V_i from θ(t0) =
 * RWC0·V with the leaf loss δ·A_i, so δ is in s⁻¹ cm⁻² and means what it
 * means in a `weight_curve` on the same plant (a joint fit shares it by
 * name), and its own modulus E_i(t) = E_min + E_max σ(κ (x_i − χ0)).
 * Observations before t0 are refused (the water runs forward from t0).
 * (Not with particles: a particle's stiffness is one scalar s(t); water: plant
 * with dynamics: particles is refused.)
 *
 * Dynamics (options.dynamics): PHC_SHAPE_RODS (default) as above, or
 * PHC_SHAPE_PARTICLES: the same graph (stalk or plant) as oriented particles
 * (model/particles.h, climbing plants §4.1, one particle per segment).  The
 * model angle at time t is then the direction of the series' segment
 * (phc_particles_segment_ends, head → tail) after relaxing the particle
 * system under gravity to rest:
 *   - every solve starts from the rest pose (a new system per solve, so the
 *     result does not depend on the order of evaluations or on a warm start);
 *   - the anchored particles are the graph's fixed segments and its roots,
 *     held in place with their orientation (a clamp);
 *   - steps of particle_time_step seconds, each with particle_iterations
 *     projections and particle_damping, until the largest particle speed
 *     times the time step falls below PHC_SHAPE_REST_FRACTION of the
 *     shortest free segment's length, then a quarter as many steps again
 *     (the step count to rest jumps with s; the settling steps shrink the
 *     angle's jump there below what central differences resolve); a system
 *     not at rest after particle_steps steps (settling not counted), or
 *     whose speed rose 1000-fold during the settling, is refused
 *     (PHC_ERR_DOMAIN, naming the series, the stiffness and the speed
 *     left), never a NaN;
 *   - the stalk's clamp is one free segment long (not 1/1000 of one as for
 *     rods): a particle's group matches with the masses of its members, so a
 *     tiny clamp particle would hold the first free particle's rotation by
 *     almost nothing, a hinge instead of a clamp.  It then continues the
 *     chain behind the base, as a fixed neighbour;
 *   - the tip mass is an external force m_tip·g on the series' particle,
 *     applied at its centre (particles carry no torque).
 * The particles' stiffness s ∈ [0, 1] is not a modulus.  Eq. 9 is mapped to
 * it by
 *     s(t) = E(t) / (E_min + E_max)
 * (1 only in the limit σ → 1, turgid ≈ 1, fully wilted E_min/(E_min + E_max)):
 * the same logistic in water, scaled so that s stays in [0, 1] for any
 * parameters.  E_max's scale is then identified only through E_min/E_max,
 * and the fitted κ, χ0 are those of a stiffness whose effect depends on the
 * iteration count and time step (README "Effective stiffness").
 *
 * Observations: the tracks of measurements/shape_series.h of kind
 * PHC_SHAPE_ANGLE, in rad, counter-clockwise with y up (read image angles
 * with y_down, which negates them: an image angle measured clockwise on
 * screen, 0 = right, 90° = down, becomes the model's counter-clockwise
 * angle with z up).  Each track is moved by the multiple of 2π that brings
 * its first sample within π of β, so the observed and model angles are on
 * the same branch.  Residual = observed − model angle (rad), divided by
 * sigma when given.
 *
 * Parameter slots (bound by name; phc_problem_bind_by_name or a config's
 * `parameters:`), with the units the model works in:
 *   kappa   κ, 1 (RWC is a fraction)
 *   chi0    χ0, 1
 *   e_max   E_max, Pa
 *   delta   δ, s⁻¹ with one compartment; s⁻¹ cm⁻² with water_model (the
 *           water model's leaf loss per unit of area proxy, as weight_curve's
 *           δ: only then can a joint fit share it by name; the slot units
 *           differ otherwise and the engine refuses the binding)
 *   e_min   E_min, Pa: a slot only when options.e_min_slot, else fixed at
 *           options.e_min
 *   offset_<series>  rad, per stalk with `offset`: added to its model angle
 *           (what the camera's view and the unknown base angle add)
 *
 * Derivatives ("analytic" to the engine): the model angle depends on the
 * shared slots only through the scalar E(t), so d angle / d p = (d angle /
 * d E) · (d E / d p) with d E / d p exact; d angle / d offset = 1.
 * With rods d angle / d E is exact too: implicit differentiation of the
 * converged equilibrium (phc_rod_static_sensitivity along dE_i = 1: one
 * factorisation and one solve of the KKT matrix, no further static solve)
 * chained with the angle's analytic gradient in the segment's head and
 * tail (a = atan2(d_z, d_x), d = tail − head).  With water_model the moduli
 * form a vector E(t): d E_i / d p is exact per segment (d x / d δ from the
 * water model's BDF6 sensitivities) and d angle / d E_i for every segment
 * comes from one adjoint solve (phc_rod_static_adjoint), so every slot
 * costs one dot product.  options.fd_step is used by particles only: there
 * the scalar is s(t) (d s / d p exact, including the E_max and E_min slots
 * in its denominator) and d angle / d s a central difference with step
 * fd_step·s, or the second-order backward difference (3 a(s) − 4 a(s − h)
 * + a(s − 2h)) / 2h when s + h > 1; each of the two or three solves relaxes
 * from rest.  tests/unit/test_shape_series_new.c and test_shape_water.c
 * check the Jacobian against central differences of the whole model in
 * every slot.
 *
 * Errors (PHC_ERR_INPUT) say what and where: a stalk naming a series that
 * is not in the tracks (with the list), a track that is not an angle,
 * a length, radius, density, tip mass, segment count, RWC0, sigma or fd_step
 * out of range (zero/negative radius, ...), a non-finite observation (data
 * file and line).  Places are the stalk's `where` (e.g. "cfg.yaml:14") or
 * the options' origin, else "shape_series". */
#ifndef PHC_COSTS_SHAPE_SERIES_H
#define PHC_COSTS_SHAPE_SERIES_H

#include <stddef.h>

#include "fit/costs/origin.h"
#include "fit/engine/dataset.h"
#include "measurements/shape_series.h"
#include "model/plant_graph.h"
#include "model/status.h"
#include "model/water.h"

/* One tracked series mapped to a stalk. */
typedef struct phc_shape_stalk {
    const char *series;  /* id of a track in the phc_shape_series (an angle track) */
    double length;       /* L, m, > 0: the free stalk */
    double radius;       /* r, m, > 0 */
    size_t segments;     /* free segments, >= 1 (default 8) */
    double tip_mass;     /* kg, >= 0: the flower */
    double base_angle;   /* β, rad, counter-clockwise from +x with z up; NaN: the
                            first observed angle (the stalk starts where the organ
                            pointed at the first sample), taken in [−π, π] */
    int offset;          /* 1: a slot offset_<series> (rad) added to the model angle */
    long segment;        /* with options.plant: the source id of the plant's segment
                            whose direction is the series' angle (length, radius,
                            segments and base_angle are then unused; base_angle must
                            be NaN); tip_mass hangs at its tail */
    const char *where;   /* for messages (e.g. "cfg.yaml:14"); may be NULL */
} phc_shape_stalk;

/* The organ model's dynamics (options.dynamics, config `dynamics:`). */
typedef enum phc_shape_dynamics {
    PHC_SHAPE_RODS = 0,     /* elastic rods, static equilibrium (model/rod.h) */
    PHC_SHAPE_PARTICLES = 1 /* oriented particles relaxed to rest (model/particles.h) */
} phc_shape_dynamics;

/* With particles: at rest when max |v|·Δt < this fraction of the shortest
 * free segment's length (per step, the particles then move by less than
 * 1e-12 of a segment). */
#define PHC_SHAPE_REST_FRACTION 1e-12

typedef struct phc_shape_series_options {
    size_t n_stalks;               /* >= 1 */
    const phc_shape_stalk *stalks;
    double rwc0;                   /* RWC at t0, in (0, 1.5]; default 1 */
    double t0;                     /* s; NaN (default): the first sample's time */
    double e_min;                  /* Pa, > 0, when not a slot; default 1e4 */
    int e_min_slot;                /* 1: e_min is a slot */
    double density;                /* ρ, kg m⁻³, > 0; default 1000 */
    double sigma;                  /* rad, > 0; 0 (default): unweighted */
    size_t every;                  /* keep every k-th sample (>= 1, default 1) */
    double fd_step;                /* particles only: relative step in s for d angle/ds
                                      (rods use exact derivatives); default 1e-4 */
    size_t frames;                 /* simulate/fit outputs: frames (side views, graphs),
                                      evenly spaced over the data's times; default 6, 0 none */
    const phc_origin *origin;      /* where the options came from, for messages; NULL */
    int dynamics;                  /* phc_shape_dynamics; default PHC_SHAPE_RODS */
    size_t particle_iterations;    /* particles: projections per step, 1..1000; default 16 */
    double particle_time_step;     /* particles: Δt, s, in (0, 1]; default 5e-4 */
    size_t particle_steps;         /* particles: step cap of one relaxation, 1..10^7;
                                      default 20000 */
    double particle_damping;       /* particles: fraction of velocity removed per step,
                                      (0, 1); default 0.1 (it speeds up the relaxation and
                                      does not move the rest state) */
    double parent_weight;          /* particles: weight of the parent's group, >= 1;
                                      default 2 */
    const phc_plant_graph *plant;  /* NULL: one stalk per series (above); else a finished
                                      plant graph (m, z up; copied): one rod for the whole
                                      plant, every segment at E(t), each series the angle
                                      of its stalk's `segment`, β its rest direction */
    int water_model;               /* with plant: 1 drives every segment's modulus by the water
                                      model on the plant graph (fit/costs/shape_water.h), δ then
                                      in s⁻¹ cm⁻² as in weight_curve; 0 (default): one
                                      compartment, RWC0 exp(−δ t), δ in s⁻¹ */
    phc_water_weights conductance; /* water_model: edge weights (model/water.h); default
                                      Poiseuille */
    double viscosity;              /* water_model: sap viscosity, mPa s; 0 = the mode's default */
    double water_step;             /* water_model: BDF6 step, s, >= 0; 0 = a thousandth of the
                                      data's time span */
} phc_shape_series_options;

/* The defaults above (no stalks). */
phc_shape_series_options phc_shape_series_options_default(void);

/* Builds a shape_series data set from tracks (read with
 * phc_shape_series_read; copied, may be freed afterwards).  Slots are
 * named; parameter indices are left to binding.  Errors as above. */
int phc_shape_series_new(const phc_shape_series *tracks, const phc_shape_series_options *options,
                         phc_dataset **out, phc_error *err);

/* The modulus (Pa) and relative water content at time t (s) for slot
 * values p (the data set's slot order).  Non-zero with water_model (each
 * segment has its own). */
int phc_shape_series_modulus(const phc_dataset *ds, const double *p, double t, double *young,
                             double *rwc);

/* The particles' stiffness s(t) = E(t) / (E_min + E_max) in [0, 1] at time
 * t (s) for slot values p (any dynamics). */
int phc_shape_series_stiffness(const phc_dataset *ds, const double *p, double t, double *stiffness);

/* The equilibrium angle (rad, without offset) of stalk s, solved from the
 * rest shape, at `driver`: the modulus E (Pa) with rods, the stiffness
 * s in [0, 1] with particles.  0, or non-zero when the solve fails (err,
 * may be NULL, then says why). */
int phc_shape_series_stalk_angle(phc_dataset *ds, size_t s, double driver, double *angle, phc_error *err);

/* With particles: the time steps the last relaxation took (0 with rods). */
size_t phc_shape_series_particle_steps(const phc_dataset *ds);

extern const phc_dataset_ops phc_shape_series_ops;

#endif /* PHC_COSTS_SHAPE_SERIES_H */
