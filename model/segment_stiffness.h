/* Young's modulus of each segment of a plant graph, for the shape models
 * (wilting paper, Maggioli et al., SIGGRAPH Asia 2023, eq. 9 and Fig. 5;
 * issue 19 "Water -> stiffness").  Pure C, no I/O.
 *
 * Units.  The graph is in metres (model/plant_graph.h); the water state
 * theta is what the water model gives (model/water.h): g of water per
 * segment, 1 g = 1 cm^3, with segment volumes V_i = pi r_i^2 h_i in cm^3
 * (r, h converted from m to cm).  Moduli are Young's moduli in Pa.
 *
 * ---- the three laws of wilting Fig. 5 (phytocal's physical mappings) ----
 *
 * PHC_STIFFNESS_WATER (default), eq. 9 with the authors' scaling:
 *     E_i = E_min + E_max * sigma(kappa (x_i - chi0)),  sigma(z) = 1/(1+e^-z)
 *   x_i = theta_i / V_i, the segment's relative water content
 *         (PHC_STIFFNESS_RELATIVE, default: dimensionless, 1 at theta = V,
 *         chi0 dimensionless, kappa per unit RWC), or
 *   x_i = theta_i, the absolute water of the segment (PHC_STIFFNESS_ABSOLUTE,
 *         the paper's: chi0 in g, kappa per g).
 *   Relative content is the default because one (kappa, chi0) then means the
 *   same thing for a thin twig and a thick stem; with absolute water a small
 *   segment is soft whatever its hydration.  The logistic is
 *   phc_elasticity_eval (model/elasticity.h); there E_min, E_max are the
 *   pressure-volume bulk modulus in MPa, here the same form gives a Young's
 *   modulus in Pa for the rod's bending stiffness E*I.
 *   Derivatives (phc_segment_stiffness_water): per segment
 *     dE_i/dkappa = E_max sigma'(z_i) (x_i - chi0),
 *     dE_i/dchi0  = -E_max sigma'(z_i) kappa,
 *     dE_i/dE_min = 1,  dE_i/dE_max = sigma(z_i),
 *     dE_i/dtheta_i = E_max sigma'(z_i) kappa dx_i/dtheta_i  (1/V_i relative,
 *       1 absolute; E_i depends on theta_i only, so the Jacobian is diagonal).
 *   Limits: kappa -> 0+ gives E_min + E_max/2 for every segment;
 *   x -> +inf gives E_min + E_max, x -> -inf gives E_min.
 *
 * PHC_STIFFNESS_DEPTH (Fig. 5, "inversely proportional to depth"):
 *     E_i = E_base / (1 + d_i),  d_i = g->depth[i], edges from the root.
 *   The root has E_base; a segment ten joints out has E_base / 11.
 *
 * PHC_STIFFNESS_RADIUS (Fig. 5, "proportional to radius"):
 *     E_i = E_base * r_i / r_max,  r_max = the largest radius of the graph.
 *   Scale: the thickest segment (usually the root) has E_base, so both
 *   non-water laws give E_base where the plant is strongest.  (E * I with
 *   I = pi r^4 / 4 then grows as r^5.)
 *
 * ---- the authors' published demo (PHC_STIFFNESS_REFERENCE) ------------------
 *
 * filthynobleman/plant-wilting-simulation, commit 7ababca (2024-08-01),
 * Demos/PlantDemo/PlantDemo.cpp ("PlantDemo.cpp:N" below), defaults in
 * Demos/Common/DemoBase.h:51-60, graph and water from the submodule
 * filthynobleman/plant-water-diffusion at 8308f91 ("pwd").  Each quirk, and
 * the physical default beside it:
 *  1. Per joint, not per segment.  The modulus lives on the
 *     stretch-bending-twisting constraint between a segment N and its child
 *     C (PlantDemo.cpp:215-236), and uses the mean absolute water of the two
 *     (PlantDemo.cpp:226-228):  w = (theta_N + theta_C) / 2  (g),
 *         E = Emin + Emax / (1 + exp(-s (w - mid)))    (PlantDemo.cpp:229-230)
 *     defaults Emin 1, Emax 1e10, s 1e3 per g, mid 1.5e-2 g (DemoBase.h:55-58).
 *     Physical default: per segment, relative water content (above).
 *  2. Torsion modulus G = E (PlantDemo.cpp:231), so the twisting stiffness
 *     2 G I = 2 E I (PlantDemo.cpp:234): an isotropic material has
 *     G = E / (2 (1 + nu)), i.e. a torsion stiffness E I / (1 + nu), about
 *     2.6x smaller for nu = 0.3.  Stiffness vector K = (E I, 2 G I, E I) with
 *     I = pi rbar^4 / 4 (PlantDemo.cpp:232-235, as PositionBasedDynamics/
 *     PositionBasedElasticRods.cpp:1165-1168 does at creation).
 *  3. The joint "radius" (PlantDemo.cpp:321-327):
 *         RN = LN * rN,  RC = LC * rN   (both with the PARENT's radius rN),
 *         rbar = (RN LN + RC LC) / (LN + LC) = rN (LN^2 + LC^2) / (LN + LC)
 *     which has units of length^2 (cm^2 in their cm graph), ignores the
 *     child's radius and grows with segment length: the "radius computed as
 *     length x parent radius" of issue 19.  The evident intent, and the
 *     physical default, is the length-weighted mean radius
 *     (rN LN + rC LC) / (LN + LC).  rbar^4 enters E I, so this changes the
 *     bending stiffness by (rbar_quirk / rbar_intended)^4.
 *  4. Joint length Lbar = (LN + LC) / 2 (PlantDemo.cpp:328); the compliance
 *     is 1 / (K Lbar dt^2) (PositionBasedElasticRods.cpp:1196-1200).
 *  5. Units: the graph file's metres are multiplied by 100 (pwd
 *     src/graph/graph.cpp:153), so lengths, radii and positions are cm,
 *     volumes cm^3 (pwd src/graph/node.cpp:55), water g; gravity stays
 *     -9.81 (PlantDemo.cpp:111), in m/s^2.  Physical default: SI.
 *  6. Mass per segment, every frame (PlantDemo.cpp:198-212):
 *         m = (V rho + theta) * mass_scale,  rho = leaf_density (2) on leaf
 *         segments, density (1) otherwise, mass_scale 1e-3 (DemoBase.h:52-54)
 *     0 (fixed) for the root, and for latched segments when latches are on
 *     (PlantDemo.cpp:208).  With rho in g/cm^3 and theta in g, the 1e-3 is
 *     g -> kg.  Physical default: the same sum in kg, one dry density.
 *  7. Mass at build time, used for the first frame's steps (PlantDemo.cpp:
 *     297-300): m = density * V + theta0 (g), WITHOUT mass_scale (1000x the
 *     later masses) and without leaf density; latches are not applied then
 *     (only the root is fixed).
 *  8. Modulus at build time, used for the first frame's steps: the
 *     constraints are created with E = G = Emax (PlantDemo.cpp:339-340);
 *     water-dependent moduli apply from the first frame update on.
 *  9. Time: each frame advances the water model by m_timestep = 10 s
 *     (DemoBase.h:62, DemoBase.cpp:1323) but the mechanics by numSteps (8,
 *     DemoBase.cpp:64) x 0.0025 s (PlantDemo.cpp:109) = 0.02 s: water time
 *     runs 500x faster than mechanical time; velocities are multiplied by
 *     the damping 0.99 after every step (PlantDemo.cpp:182-186); moduli and
 *     masses are updated after the frame's steps, so they lag one frame.
 *     (Dynamics quirks, for the rod solver; listed here for completeness.)
 * phc_stiffness_reference_joints and phc_stiffness_reference_masses compute
 * items 1-4 and 6-8 exactly as their code does (in their cm units), so that
 * a comparison with their demo can be made.  Joint arrays are indexed by the
 * child segment: entry i belongs to the joint between parent[i] and i (their
 * constraints come in breadth-first order with the graph file's adjacency
 * order; indexing by child makes the result independent of that order); the
 * root has no joint and its entry is set to 0. */
#ifndef PHC_SEGMENT_STIFFNESS_H
#define PHC_SEGMENT_STIFFNESS_H

#include <stddef.h>

#include "model/elasticity.h"
#include "model/plant_graph.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum phc_stiffness_law {
    PHC_STIFFNESS_WATER = 0, /* logistic in water (eq. 9), default */
    PHC_STIFFNESS_DEPTH,     /* E_base / (1 + depth) */
    PHC_STIFFNESS_RADIUS     /* E_base * r / r_max */
} phc_stiffness_law;

typedef enum phc_stiffness_water_content {
    PHC_STIFFNESS_RELATIVE = 0, /* x = theta / V (default) */
    PHC_STIFFNESS_ABSOLUTE      /* x = theta, g (the paper's) */
} phc_stiffness_water_content;

typedef struct phc_segment_stiffness_params {
    phc_stiffness_law law;
    phc_stiffness_water_content content; /* law WATER */
    phc_elasticity_params logistic;      /* law WATER: kappa (> 0, per unit of x), chi0
                                            (unit of x), e_min (> 0, Pa), e_max (>= 0, Pa) */
    double e_base;                       /* laws DEPTH and RADIUS: Pa, > 0 */
} phc_segment_stiffness_params;

/* law WATER, relative content, kappa 20, chi0 0.7, E_min 1e6 Pa, E_max 1e9 Pa,
 * e_base 1e9 Pa: placeholders of the right magnitude for green stems (Young's
 * moduli of fresh plant stems are 1e8..1e10 Pa); fit or set them. */
phc_segment_stiffness_params phc_segment_stiffness_params_default(void);

/* "water", "depth", "radius" -> law; "relative", "absolute" -> content.
 * Return 0, or -1 for an unknown name. */
int phc_stiffness_law_from_name(const char *name, phc_stiffness_law *law);
int phc_stiffness_content_from_name(const char *name, phc_stiffness_water_content *content);
const char *phc_stiffness_law_name(phc_stiffness_law law);

/* Checks the parameters of p->law: PHC_OK, or PHC_ERR_INVALID with a message
 * naming the key ("segment stiffness: kappa must be positive and finite,
 * found -2").  kappa <= 0 is refused (the plant would stiffen as it dries);
 * E_min must be positive (a zero modulus has no bending stiffness). */
int phc_segment_stiffness_check(const phc_segment_stiffness_params *p, phc_error *err);

/* Law WATER for every segment of a finished graph.  theta: n, g.
 * E: n, Pa.  dE_dparams: NULL or n x 4 row-major in the PHC_ELASTICITY_*
 * order (dkappa, dchi0, dE_min, dE_max).  dE_dtheta: NULL or n (the diagonal
 * of dE/dtheta, Pa/g).  Errors (PHC_ERR_INVALID): bad parameters, a theta
 * that is not finite (naming the segment by its source id). */
int phc_segment_stiffness_water(const phc_plant_graph *g, const phc_segment_stiffness_params *p,
                                const double *theta, double *E, double *dE_dparams,
                                double *dE_dtheta, phc_error *err);

/* Laws DEPTH and RADIUS (no water): E (n, Pa).  dE_dbase: NULL or n
 * (dE_i/dE_base = E_i / E_base). */
int phc_segment_stiffness_depth(const phc_plant_graph *g, double e_base, double *E,
                                double *dE_dbase, phc_error *err);
int phc_segment_stiffness_radius(const phc_plant_graph *g, double e_base, double *E,
                                 double *dE_dbase, phc_error *err);

/* Dispatches on p->law; theta may be NULL for DEPTH and RADIUS. */
int phc_segment_stiffness(const phc_plant_graph *g, const phc_segment_stiffness_params *p,
                          const double *theta, double *E, phc_error *err);

/* ---- the authors' demo (see quirks 1-8 above) ---------------------------- */

typedef struct phc_stiffness_reference_params {
    double e_min;        /* yngmin, 1 */
    double e_max;        /* yngmax, 1e10 */
    double steepness;    /* yngsteep s, 1e3 per g */
    double midpoint;     /* yngmid, 1.5e-2 g */
    double density;      /* density of branches, 1 (g/cm^3) */
    double leaf_density; /* leafdensity, 2 (g/cm^3) */
    double mass_scale;   /* massscale, 1e-3 */
    int use_latches;     /* uselatches, 0; when 1, segments with g->fixed[i] get mass 0 */
} phc_stiffness_reference_params;

/* The defaults of DemoBase.h:51-60. */
phc_stiffness_reference_params phc_stiffness_reference_default(void);

/* Per-joint quantities of PlantDemo.cpp, indexed by child segment (root: 0).
 * theta: n, g, the water state of the frame; NULL = build time (quirk 8:
 * E = G = e_max).  Any output may be NULL:
 *   youngs   E (nominally Pa),
 *   torsion  G (= E, quirk 2),
 *   bending  K_bend = E I, twisting K_twist = 2 G I, I = pi rbar^4 / 4,
 *   radius   rbar (quirk 3, cm^2 numerically: their "radius"),
 *   length   Lbar = (LN + LC) / 2, cm,
 *   water    w = (theta_N + theta_C) / 2, g (0 when theta is NULL).
 * Errors (PHC_ERR_INVALID): parameters not finite, steepness or e_max or
 * e_min negative, theta not finite. */
int phc_stiffness_reference_joints(const phc_plant_graph *g,
                                   const phc_stiffness_reference_params *p, const double *theta,
                                   double *youngs, double *torsion, double *bending,
                                   double *twisting, double *radius, double *length,
                                   double *water, phc_error *err);

/* Segment masses of PlantDemo.cpp (quirks 6, 7): build != 0 gives the build
 * time masses from theta = theta0 (density * V + theta0, g, root 0); build
 * == 0 the per-frame masses (V rho + theta) * mass_scale, root and (with
 * use_latches) fixed segments 0.  V in cm^3.  mass: n. */
int phc_stiffness_reference_masses(const phc_plant_graph *g,
                                   const phc_stiffness_reference_params *p, const double *theta,
                                   int build, double *mass, phc_error *err);

/* Segment volume in cm^3 (pi r^2 h with r, h in cm), as the water model and
 * the authors' code (pwd src/graph/node.cpp:55) compute it. */
double phc_segment_volume_cm3(const phc_plant_graph *g, size_t i);

#ifdef __cplusplus
}
#endif

#endif /* PHC_SEGMENT_STIFFNESS_H */
