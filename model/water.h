/* Water in a plant graph: the linear model of the wilting paper
 * (Maggioli et al., SIGGRAPH Asia 2023, §3-4; DESIGN §5).
 *
 * Nodes are the segments of a phc_plant_graph (graph units: metres; this
 * model works in cm, g of water (1 g = 1 cm^3) and s).  For segment i with
 * radius r_i and length h_i (cm):
 *     V_i = pi r_i^2 h_i                 volume, cm^3
 *     A_i = r_i h_i                      the paper's transpiring-area proxy, cm^2
 *     l_i = delta * A_i                  leaf loss, 1/s (0 on stem segments and
 *                                        on segments masked by no_loss)
 *     g_i = pi r_i^4 / (8 mu h_i)        per-segment Poiseuille term
 * and the water theta (g per segment) obeys (paper eq. 5-6)
 *     theta' = S theta,   S = R D^-1 - D_l,   theta(0) = W0 V / sum(V)
 * where R is the weighted Laplacian of the tree (R_ij = w_ij for tree
 * neighbours, R_ii = -sum_j w_ij), D = diag(d) with d_i = V_i / K the water
 * "capacity" (pressure P_i = theta_i / d_i = K theta_i / V_i: the pressure
 * constant K multiplies, in every mode), and D_l = diag(l).
 *
 * Edge weights (phc_water_weights):
 *   PHC_WATER_POISEUILLE (default, the physical reading).  The two half
 *     segments in series: the hydraulic resistance of the edge (i, j) is
 *     8 mu (h_i/2) / (pi r_i^4) + 8 mu (h_j/2) / (pi r_j^4), so
 *     w_ij = 2 g_i g_j / (g_i + g_j)  [cm^3 / (s Ba)], mu in poise.
 *     Pressure P = K theta / V with K = R T / M_w at T = 298.15 K
 *     (8.314462618 J/(mol K) * 298.15 K / 18.01528 g/mol = 137.6 J/g
 *     = 1.376e9 Ba cm^3/g): the van 't Hoff pressure of water as a solution
 *     of 55.5 mol/L, the reading of the authors' constant with T in kelvin.
 *     Flux (cm^3/s = g/s) = w * pressure difference (Ba): every unit is
 *     consistent, which is why this is the physical default.  The system is
 *     very stiff (pressure equalises in far less than a second): use BDF6 or
 *     the exact evaluator with care (see phc_water_exact_stiffness).
 *     Note: DESIGN §5 says the authors' 2024 code uses the arithmetic mean of
 *     g as a conductance and calls that the physical reading; Poiseuille in
 *     series gives the harmonic form above, which is our default.
 *   PHC_WATER_MEAN_CONDUCTANCE: w_ij = (g_i + g_j) / 2 (the 2024 code's
 *     arithmetic mean used as a conductance), same units as the default.
 *   PHC_WATER_PAPER: the paper's formula, g called a resistance and
 *     w_ij = 1 / ((g_i + g_j) / 2).  Dimensionally inconsistent; offered to
 *     compare with the paper.  K as in the default.
 *   PHC_WATER_REFERENCE: the authors' public C++ code
 *     (filthynobleman/plant-water-diffusion, src/watermodel/watermodel.cpp)
 *     as it was in 2023 (commits up to 827aab6): FlowRes_i = 1e6 pi r^4 /
 *     (8 * 0.9 * L) with r, L in cm, w = 1 / (0.5 (FlowRes_i + FlowRes_j)),
 *     S = PC * Adj * diag(V)^-1 - diag(loss * Area): the pressure is
 *     PC theta / V, so d = V / PC.  PC = 11.538249539485484 (R T / M_w with
 *     T = 25 taken in degrees Celsius), Area = L r, Volume = pi r^2 L, graph
 *     metres * 100.  tests/realdata/test_water_reference checks W and theta
 *     against their code on plant000 and plant002.
 *   PHC_WATER_REFERENCE_2024: their current code (commit 583c49a, August
 *     2024, drops the inversion): w = 0.5 (FlowRes_i + FlowRes_j), the mean
 *     used as a conductance; otherwise as PHC_WATER_REFERENCE.
 *   Both reference modes are stiff too (fastest rate of S 1.4e6 to 2.7e8
 *     1/s on plant000 and plant002): use BDF6 or mind the exact evaluator's
 *     accuracy there.
 *
 * Options: mu (mPa s; 0 = default 0.89 for water at 25 C, 0.9 in the
 * reference modes), per-edge conductance factors (paper Fig. 10: 0 = cut,
 * (0,1) = damaged) and a per-segment no-loss mask.
 *
 * Evaluators share one system (phc_water_system):
 *   exact  (phc_water_exact_*): A = D^-1/2 R D^-1/2 - D_l is symmetric and
 *          S = D^1/2 A D^-1/2, so theta(t) = D^1/2 Q exp(L t) Q^T D^-1/2 theta0
 *          by divide and conquer on the tree (model/tree_eigen.h), the
 *          eigenvalues refined without cancellation; W(t) = sum_i a_i b_i
 *          exp(lambda_i t).
 *   BDF6   (phc_water_bdf6_*): paper eq. 8 with a fixed step, factorised once
 *          by elimination over the tree (O(n)); accurate start; dense output.
 * All functions are pure: no I/O, no globals. */
#ifndef PHC_WATER_H
#define PHC_WATER_H

#include <stddef.h>

#include "model/plant_graph.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum phc_water_weights {
    PHC_WATER_POISEUILLE = 0,
    PHC_WATER_MEAN_CONDUCTANCE,
    PHC_WATER_PAPER,
    PHC_WATER_REFERENCE,
    PHC_WATER_REFERENCE_2024
} phc_water_weights;

typedef enum phc_water_method {
    PHC_WATER_AUTO = 0,  /* exact below PHC_WATER_AUTO_EXACT_MAX segments when not stiff, else BDF6 */
    PHC_WATER_EXACT,
    PHC_WATER_BDF6
} phc_water_method;

#define PHC_WATER_AUTO_EXACT_MAX 400

/* Gas constant, J/(mol K); molar mass of water, g/mol; 25 C in K. */
#define PHC_WATER_GAS_CONSTANT 8.314462618
#define PHC_WATER_MOLAR_MASS 18.01528
#define PHC_WATER_TEMPERATURE 298.15
/* The authors' PRESS_CONST: R * 25 / M_w (T in Celsius); pressure = PC * theta / V. */
#define PHC_WATER_REFERENCE_PRESS_CONST 11.538249539485484

typedef struct phc_water_params {
    phc_water_weights weights;        /* default PHC_WATER_POISEUILLE */
    double loss_rate;                 /* delta, 1/(cm^2 s), >= 0 (reference modes: their LossRate) */
    double initial_water;             /* W0, g, > 0 */
    double viscosity;                 /* mu, mPa s, > 0; 0 = mode default (0.89, reference 0.9) */
    const double *edge_factor;        /* NULL or n: factor in [0,1] on the conductance of the
                                         edge between segment i and its parent (0 = cut);
                                         the root's entry is ignored */
    const unsigned char *no_loss;     /* NULL or n: 1 = this segment never loses water */
} phc_water_params;

phc_water_params phc_water_params_default(void);

/* ---- the system: graph-dependent set-up, reusable across delta ---------- */
typedef struct phc_water_system phc_water_system;

/* Builds S for a finished graph.  The graph may be freed afterwards.
 * Errors (PHC_ERR_INVALID / PHC_ERR_DOMAIN) name the offending option. */
int phc_water_system_new(const phc_plant_graph *g, const phc_water_params *p,
                         phc_water_system **out, phc_error *err);
void phc_water_system_free(phc_water_system *s);
/* Changes delta (1/(cm^2 s), >= 0) or W0 (g, > 0) in place: O(n). */
int phc_water_system_set_loss_rate(phc_water_system *s, double delta, phc_error *err);
int phc_water_system_set_initial_water(phc_water_system *s, double w0, phc_error *err);
size_t phc_water_system_size(const phc_water_system *s);
double phc_water_system_loss_rate(const phc_water_system *s);
double phc_water_system_initial_water(const phc_water_system *s);
double phc_water_system_viscosity(const phc_water_system *s);   /* mPa s */
/* Per-segment quantities in the graph's segment order (cm^3, cm^2, g). */
void phc_water_system_volume(const phc_water_system *s, double *v);
void phc_water_system_theta0(const phc_water_system *s, double *theta0);
/* An upper bound of |lambda| for the largest rate of S (1/s): the stiffness. */
double phc_water_system_stiffness(const phc_water_system *s);

/* ---- exact evaluator (eigen-decomposition) ------------------------------ */
typedef struct phc_water_exact phc_water_exact;

typedef enum phc_water_exact_kind {
    PHC_WATER_EXACT_TOTAL_ONLY = 0, /* W(t) only: eigenvalues and a_i b_i */
    PHC_WATER_EXACT_FULL,           /* eigenvectors kept: theta(t) too */
    PHC_WATER_EXACT_SENSITIVITY     /* FULL + Q^T D_a Q for d/d delta, d/d mu (O(n^3)) */
} phc_water_exact_kind;

/* Decomposes the system as it is now (later set_loss_rate calls do not
 * affect an existing evaluator).  Accuracy: a plain eigensolver's absolute
 * eigenvalue errors are about 1e-16 * stiffness, which would cost W(t)
 * about 1e-16 * stiffness * t relative; the eigenvalues are refined as
 * cancellation-free Rayleigh quotients (model/water.c, refine_modes), and
 * W(t) agrees with BDF6 to ~1e-10 on the paper's plants in every mode
 * (stiffness up to 1e11 1/s).  Cost: O(n^2) memory, O(n^3) at worst, far
 * less when the tree's eigenvectors are local (plant000: 0.05 s). */
int phc_water_exact_new(const phc_water_system *s, phc_water_exact_kind kind,
                        phc_water_exact **out, phc_error *err);
void phc_water_exact_free(phc_water_exact *e);
/* Total water W(t) (g) at t >= 0 (s): O(n). */
double phc_water_exact_total(const phc_water_exact *e, double t);
/* theta(t) (g, graph segment order); FULL or SENSITIVITY evaluators only. */
int phc_water_exact_state(const phc_water_exact *e, double t, double *theta, phc_error *err);
/* dW[0] = dW/d delta (g cm^2 s), dW[1] = dW/dW0 (1), dW[2] = dW/d mu (g/(mPa s));
 * dtheta_ddelta (n, graph order) may be NULL.  SENSITIVITY evaluators only.
 * O(n^2) per call (Frechet derivative of exp with divided differences). */
int phc_water_exact_sensitivity(const phc_water_exact *e, double t, double *dW,
                                double *dtheta_ddelta, phc_error *err);

/* ---- BDF6 (paper eq. 8) ------------------------------------------------ */
typedef struct phc_water_bdf6 phc_water_bdf6;

/* Sensitivities integrated alongside theta (staggered, same factorisation
 * of I - alpha h S: one more back substitution per step and vector). */
enum {
    PHC_WATER_SENS_NONE = 0,
    PHC_WATER_SENS_ALL = 1,   /* d theta / d delta and d theta / d mu */
    PHC_WATER_SENS_DELTA = 2  /* d theta / d delta only (mu fixed: 2/3 of the work of ALL) */
};

/* Creates an integrator with fixed step h (s) from theta(0) and computes
 * the start (theta at h..5h) by extrapolated implicit Euler (harmonic
 * sequence 1..8, Aitken-Neville; Deuflhard) on sub-steps, which reaches
 * ~1e-10 relative accuracy; sensitivities: PHC_WATER_SENS_* above.  theta
 * does not depend on the choice (the same operations, bit for bit).
 * Memory O(n) plus one double (two, three with sensitivities) per step. */
int phc_water_bdf6_new(const phc_water_system *s, double h, int sensitivities,
                       phc_water_bdf6 **out, phc_error *err);
void phc_water_bdf6_free(phc_water_bdf6 *b);
/* Integrates until t_end (s) is covered for dense output. */
int phc_water_bdf6_advance(phc_water_bdf6 *b, double t_end, phc_error *err);
/* Steps taken so far and the time of the current state (s). */
size_t phc_water_bdf6_steps(const phc_water_bdf6 *b);
double phc_water_bdf6_time(const phc_water_bdf6 *b);
/* Current state (g, graph segment order) and, with sensitivities,
 * d theta/d delta; dtheta may be NULL. */
void phc_water_bdf6_state(const phc_water_bdf6 *b, double *theta, double *dtheta_ddelta);
/* The state (g, graph segment order) and, with sensitivities, d theta /
 * d delta (may be NULL) at a time t (s) within the last five steps,
 * [time() - 5h, time()], by 6-point Lagrange interpolation (degree 5, the
 * order of the method) of the stored states: dense output for times that
 * are not multiples of h.  A new integrator covers [0, 5h]; advance to
 * cover a later t first (only when t > time(): advancing moves the window
 * on).  PHC_ERR_DOMAIN outside the window. */
int phc_water_bdf6_state_at(const phc_water_bdf6 *b, double t, double *theta, double *dtheta_ddelta,
                            phc_error *err);
/* W at t (s) within [0, time()] by 6th-order Lagrange interpolation of the
 * stored step totals; dW (3, may be NULL; needs sensitivities) as in
 * phc_water_exact_sensitivity (dW[2] = NAN with PHC_WATER_SENS_DELTA). */
int phc_water_bdf6_total(const phc_water_bdf6 *b, double t, double *W, double *dW,
                         phc_error *err);

/* ---- weight curves (what a fit calls) ---------------------------------- */
/* W at m sorted times t (s, t >= 0, t = 0 is the initial state); dW NULL or
 * m x 3 row-major (d/d delta, d/d W0, d/d mu).  step_or_0: BDF6 step (s);
 * 0 = t_max / 1000.  AUTO: exact when n <= 400 and the system is not stiff
 * for t_max, otherwise BDF6. */
int phc_water_system_total_curve(const phc_water_system *s, phc_water_method method,
                                 double step_or_0, const double *t, size_t m, double *W,
                                 double *dW, phc_error *err);
/* The evaluator phc_water_system_total_curve uses for `method` up to tmax
 * (s): EXACT or BDF6 (AUTO resolved), and its BDF6 step (s) in *h. */
phc_water_method phc_water_system_curve_method(const phc_water_system *s, phc_water_method method,
                                               double step_or_0, double tmax, double *h);
int phc_water_total_curve(const phc_plant_graph *g, const phc_water_params *p,
                          phc_water_method method, double step_or_0, const double *t,
                          size_t m, double *W, double *dW, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_WATER_H */
