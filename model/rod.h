/* Elastic rods on the plant graph: statics and dynamics of a plant's shape
 * (wilting paper, Maggioli et al. 2023, §4.3; Deul, Kugelstadt, Weiler,
 * Bender 2018, "Direct position-based solver for stiff rods").
 *
 * Units: SI throughout.  Positions and lengths m, masses kg, densities
 * kg m⁻³, Young's moduli Pa, forces N, gravity m s⁻², times s.
 *
 * Model.  Every segment of a finished phc_plant_graph is a rigid body:
 * centre at the midpoint of head–tail, orientation quaternion whose third
 * director d3 is the segment axis (head → tail); d1, d2 are parallel-
 * transported from the parent's frame (minimal rotation between the two
 * axes), so the rest shape is twist-free.  Mass ρπr²h (+ a per-segment extra
 * mass the caller may set, e.g. water), inertia of a solid cylinder
 * (m(3r² + h²)/12 about d1, d2; mr²/2 about d3).
 * Every parent–child joint attaches the child's head to the parent at the
 * same point (rod_joint.h): a zero-stretch constraint (3 rows, hard) and a
 * bend–twist constraint on the discrete Darboux vector Ω against its rest
 * value Ω0, with energy ½ ℓ (Ω − Ω0)ᵀ K (Ω − Ω0), ℓ = (h_p + h_c)/2,
 *     K = f · diag(E I, E I, G J),  I = π r⁴/4, J = 2I, G = E/(2(1+ν)).
 * The joint's r is the child's radius; its E is the length-weighted harmonic
 * mean ℓ / (h_p/(2E_p) + h_c/(2E_c)) (the two half-segments the joint spans
 * act as springs in series).  f is the joint factor: 1 intact, (0,1)
 * weakened, 0 cut (no attachment and no stiffness: the subtree is loose).
 * The root is always fixed, as are segments with graph->fixed[i] and those
 * the caller fixes (supports): fixed segments keep their rest pose.
 *
 * Solvers.  Newton on the KKT system of (energy + hard stretch constraints),
 * bending written in compliant form (multiplier λ_b = ℓK(Ω − Ω0), compliance
 * (ℓK)⁻¹), solved per iteration by the direct tree solver of
 * rod_tree_solver.h in O(n): bodies and joints form a tree, each body paired
 * with the joint towards a fixed segment.  Supports beyond one per connected
 * part are imposed exactly by a small Schur complement (6 rows each).
 *   phc_rod_solve_static: equilibrium under gravity and loads, with the exact
 *     Hessian (geometric stiffness) and a backtracking line search on the
 *     scaled residual; converged when every scaled residual is ≤ tolerance
 *     (forces / total load, torques / (total load × reach), stretch / reach,
 *     bending / (load × reach²); reach = longest root-to-tip path), or when
 *     the step is ≤ 1e-12·reach with the residual within 1e3 × tolerance
 *     (rounding).  When Newton from the current state fails: load
 *     continuation from the rest shape; when that fails too (a soft plant
 *     that flops over, e.g. plant000 at 1e6 Pa), pseudo-transient
 *     continuation: implicit pseudo-time steps of the plant released at
 *     rest from the start shape, then Newton (rod.c; its own budget of
 *     4 × max_iterations).  Converged means within the tolerance, always.
 *   phc_rod_step, scheme PHC_ROD_DIRECT (default): the implicit (backward
 *     Euler) step in XPBD's compliant form: multipliers accumulated over the
 *     Newton iterations of each sub-step, each iteration one direct solve,
 *     iterated to the same tolerance, so the stiffness does not depend on
 *     iteration counts or sub-steps.  Damping: mass-proportional drag
 *     c (s⁻¹), force −c m v (and −c I ω).
 *   phc_rod_step, scheme PHC_ROD_GAUSS_SEIDEL: the authors' reference scheme
 *     (PBD/XPBD Gauss–Seidel sweep over the joints, multipliers reset each
 *     sub-step, default 1 iteration × 5 sub-steps as in their PlantDemo).
 *     Its stiffness depends on the iteration count and the sub-steps: a
 *     stiff rod sags far more than it should.  Never the default.
 * Pure C, no I/O, no globals. */
#ifndef PHC_ROD_H
#define PHC_ROD_H

#include <stddef.h>

#include "model/plant_graph.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum phc_rod_scheme {
    PHC_ROD_DIRECT = 0,       /* implicit step, direct tree solver (default) */
    PHC_ROD_GAUSS_SEIDEL = 1  /* the authors' PBD Gauss–Seidel sweep */
} phc_rod_scheme;

typedef struct phc_rod_options {
    double density;         /* kg m⁻³ (> 0); default 1000 */
    double poisson;         /* ν in (−1, 0.5]; default 0.5 */
    double gravity[3];      /* m s⁻²; default (0, 0, −9.81) */
    double tolerance;       /* scaled residual; default 1e-10 */
    int max_iterations;     /* Newton iterations per static solve (all load
                               stages; the pseudo-transient fallback has
                               4 × this of its own) or per sub-step;
                               default 200 */
    double damping;         /* c, s⁻¹ (>= 0); default 0 */
    phc_rod_scheme scheme;  /* for phc_rod_step; default PHC_ROD_DIRECT */
    int substeps;           /* sub-steps per phc_rod_step; default 1 */
    int gs_iterations;      /* Gauss–Seidel sweeps per sub-step; default 1 */
    double max_rotation;    /* rad a segment may turn in one sub-step (> 0);
                               default 0.5; beyond it a step is refused */
} phc_rod_options;

void phc_rod_options_default(phc_rod_options *o);

typedef struct phc_rod phc_rod;

typedef struct phc_rod_report {
    int iterations;   /* Newton iterations (the last sub-step for phc_rod_step) */
    int total_iterations; /* summed over sub-steps */
    double residual;  /* final scaled residual (max norm) */
} phc_rod_report;

/* Builds the rods of a finished graph (kept by pointer, not copied: it
 * must outlive the rod and not change).  young: n Young's moduli in Pa (> 0,
 * finite).  options may be NULL (defaults).  Errors (PHC_ERR_INPUT) name the
 * segment by source_id: zero/negative/NaN radius, length, modulus, density;
 * NaN coordinates; a graph of one segment (every segment fixed). */
int phc_rod_new(const phc_plant_graph *g, const double *young, const phc_rod_options *options,
                phc_rod **out, phc_error *err);
void phc_rod_free(phc_rod *rod); /* accepts NULL */

size_t phc_rod_segment_count(const phc_rod *rod);
int phc_rod_set_options(phc_rod *rod, const phc_rod_options *options, phc_error *err);

/* Per-segment Young's modulus (Pa, n values > 0): may change between solves. */
int phc_rod_set_modulus(phc_rod *rod, const double *young, phc_error *err);
/* Extra mass per segment (kg, n values >= 0; e.g. water), added to ρπr²h. */
int phc_rod_set_extra_mass(phc_rod *rod, const double *mass, phc_error *err);
/* Fix (1) or free (0) a segment (a support).  The root cannot be freed. */
int phc_rod_set_fixed(phc_rod *rod, size_t segment, int fixed, phc_error *err);
/* The joint between `segment` and its parent: factor 1 intact, (0,1)
 * weakened, 0 cut.  Not for the root. */
int phc_rod_set_joint_factor(phc_rod *rod, size_t segment, double factor, phc_error *err);
/* A point force (N) at the segment's tail (dead load); zero to remove. */
int phc_rod_set_load(phc_rod *rod, size_t segment, const double force[3], phc_error *err);

/* Back to the rest shape, at rest, multipliers cleared. */
void phc_rod_reset(phc_rod *rod);

/* Static equilibrium (Newton, direct solver) from the current state.  On
 * failure (not converged, singular: a cut part without support) the state is
 * restored and an error returned; no NaN is ever stored. */
int phc_rod_solve_static(phc_rod *rod, phc_rod_report *report, phc_error *err);

/* Advances the dynamics by dt seconds (options.substeps sub-steps of the
 * chosen scheme).  Refuses (PHC_ERR_DOMAIN, state unchanged) a dt at which a
 * sub-step would turn a segment by more than options.max_rotation or at
 * which the implicit step does not converge, and says which segment. */
int phc_rod_step(phc_rod *rod, double dt, phc_rod_report *report, phc_error *err);

/* Sensitivities of the static equilibrium with respect to the segments'
 * Young's moduli, by implicit differentiation at the converged point
 * (F(z, λ; E) = 0  ⇒  A dz/dE = −∂F/∂E, A the KKT matrix of the Newton
 * solve, assembled at the solution without the moving-chart term, which
 * vanishes there: symmetric, factorised once per call by the direct tree
 * solver).  Only the joints' bend–twist rows depend on E, through their
 * compliance α = 1/(f ℓK), K ∝ e the joint's harmonic-mean modulus (above):
 * ∂α/∂E_s = −α e h_s / (2 ℓ E_s²) for its two segments s (rod.c).
 * The rod must be at a static equilibrium (phc_rod_solve_static returned
 * PHC_OK and nothing changed since): otherwise PHC_ERR_DOMAIN.  A singular
 * KKT matrix (a buckling point) is PHC_ERR_NUMERIC.  Both leave the state
 * unchanged.
 *
 * phc_rod_static_sensitivity: n_dir directions dE (n_dir × n, Pa per unit of
 * the direction's parameter); writes dz (n_dir × 6n): per segment i the
 * derivative of its centre (m) and its world-frame rotation vector (rad,
 * the increment δθ of q ← exp(δθ) q) along each direction (zero for fixed
 * segments).  One forward/back substitution per direction. */
int phc_rod_static_sensitivity(phc_rod *rod, size_t n_dir, const double *dE, double *dz,
                               phc_error *err);

/* phc_rod_static_adjoint: for a scalar g of the state with gradient dg_dz
 * (6n: per segment ∂g/∂centre, 1/m units of g, then ∂g/∂δθ, per rad; the
 * entries of fixed segments are ignored), writes dg_dE (n: ∂g/∂E_i, per Pa)
 * for every segment: one solve (A is symmetric, so A⁻ᵀ = A⁻¹). */
int phc_rod_static_adjoint(phc_rod *rod, const double *dg_dz, double *dg_dE, phc_error *err);

/* The derivatives of segment i's head and tail (m per unit) along one
 * sensitivity dz (6n, as written by phc_rod_static_sensitivity): d tail =
 * dx + δθ × u, d head = dx − δθ × u, u = R(q)(0, 0, h/2).  Either output may
 * be NULL. */
void phc_rod_end_sensitivity(const phc_rod *rod, size_t i, const double *dz, double dhead[3],
                             double dtail[3]);
/* The gradient g_z (6: centre, rotation) of segment i for a function of
 * its head and tail with gradients g_head, g_tail (the chain rule of the
 * above: g_x = g_t + g_h, g_θ = u × (g_t − g_h)), for phc_rod_static_adjoint. */
void phc_rod_end_gradient(const phc_rod *rod, size_t i, const double g_head[3],
                          const double g_tail[3], double g_z[6]);

/* Current positions of segment i's head and tail, m. */
void phc_rod_head(const phc_rod *rod, size_t i, double out[3]);
void phc_rod_tail(const phc_rod *rod, size_t i, double out[3]);
/* Tail displacement from the rest shape, m. */
void phc_rod_tip_deflection(const phc_rod *rod, size_t i, double out[3]);
/* Kinetic energy, J (to watch dynamics come to rest). */
double phc_rod_kinetic_energy(const phc_rod *rod);
/* Mass of segment i, kg. */
double phc_rod_mass(const phc_rod *rod, size_t i);

#ifdef __cplusplus
}
#endif

#endif /* PHC_ROD_H */
