/* A plain C interface to Ceres Solver's nonlinear least squares.
 *
 * Why not ceres/c_api.h: it has no bounds, no solver options, no summary and
 * no covariance.  This bridge is the only file that touches Ceres
 * (fit/engine/ceres_bridge.cc); no C++ type appears here.
 *
 * The problem minimises  1/2 sum_b sum_i rho_b(r_bi(x)^2)  over x in R^n,
 * where each residual block b is a caller callback returning m_b residuals
 * from the k_b parameters it depends on, and rho_b is the block's robust loss
 * (applied to every residual separately, not to the block's squared norm).
 * Residuals are expected already weighted (r = (y - f) / sigma).
 *
 * Life cycle (SUNDIALS style): phc_nls_new -> phc_nls_set_parameter for each
 * parameter -> phc_nls_add_block for each data set -> phc_nls_solve (any
 * number of times, e.g. from several starts) -> phc_nls_evaluate at the
 * optimum -> phc_nls_free.
 *
 * Scaling: the solver works on u = x / scale, so parameters of very different
 * magnitude (5e-4 and 240) look alike to the trust region, to the relative
 * steps of numerical derivatives and to the parameter tolerance.  Callers
 * give `scale` (default: |start|, or 1 when the start is 0).
 *
 * Threads: with num_threads > 1 Ceres may evaluate blocks concurrently, so
 * residual callbacks must be safe to call from several threads on different
 * blocks.  One block is never evaluated concurrently with itself. */
#ifndef PHC_CERES_BRIDGE_H
#define PHC_CERES_BRIDGE_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Residual callback of one block.
 *   params:   the k parameter values of this block, in the order given to
 *             phc_nls_add_block (unscaled, physical units);
 *   residuals: m outputs;
 *   jacobian: NULL, or m x k row-major d residual_i / d param_j to fill.
 * Returns 0 on success, > 0 when the parameters are outside the model's
 * domain (the solver rejects the step and shrinks its trust region), < 0 on a
 * fatal error (the solve stops with status "failed").  Non-finite residuals
 * are treated like a return value > 0. */
typedef int (*phc_residual_fn)(const double *params, double *residuals,
                               double *jacobian, void *user_data);

typedef enum phc_loss_kind {
    PHC_LOSS_NONE,    /* rho(s) = s (plain least squares) */
    PHC_LOSS_HUBER,   /* rho(s) = s for s <= a^2, 2 a sqrt(s) - a^2 beyond */
    PHC_LOSS_CAUCHY,  /* rho(s) = a^2 log(1 + s / a^2) */
    PHC_LOSS_SOFT_L1, /* rho(s) = 2 a^2 (sqrt(1 + s / a^2) - 1) */
    PHC_LOSS_ARCTAN   /* rho(s) = a^2 atan(s / a^2) */
} phc_loss_kind;       /* a = scale, in units of the weighted residual */

typedef enum phc_derivatives {
    PHC_DERIV_ANALYTIC, /* the callback fills the Jacobian */
    PHC_DERIV_CENTRAL,  /* central differences, step 1e-6 |u| (scaled u) */
    PHC_DERIV_RIDDERS   /* Ridders' extrapolated central differences: about
                           5-10 times the evaluations, ~1e-12 relative accuracy */
} phc_derivatives;

typedef enum phc_trust_region {
    PHC_LEVENBERG_MARQUARDT,
    PHC_DOGLEG
} phc_trust_region;

typedef struct phc_nls_options {
    int max_iterations;        /* per solve; default 1000 */
    double function_tolerance; /* |d cost| / cost; default 1e-15 */
    double gradient_tolerance; /* default 1e-15 */
    double parameter_tolerance;/* |du| / (|u| + tol); default 1e-15 */
    phc_trust_region method;   /* default Levenberg–Marquardt */
    int num_threads;           /* default 1 */
    /* Called after every iteration with the iteration number and the cost
     * (1/2 sum rho(r^2)); return non-zero to stop the solve (its outcome is
     * then PHC_NLS_FAILED with "cancelled").  Default NULL. */
    int (*on_iteration)(int iteration, double cost, void *user_data);
    void *on_iteration_data;
} phc_nls_options;

phc_nls_options phc_nls_options_default(void);

typedef enum phc_nls_outcome {
    PHC_NLS_CONVERGED,     /* a tolerance was met */
    PHC_NLS_NOT_CONVERGED, /* iteration or time limit */
    PHC_NLS_FAILED         /* the solver or a callback failed */
} phc_nls_outcome;

typedef struct phc_nls_summary {
    phc_nls_outcome outcome;
    char termination[256];   /* Ceres's message, e.g. "Function tolerance reached. ..." */
    int iterations;          /* successful + unsuccessful steps */
    double initial_cost;     /* 1/2 sum rho(r^2) at the start */
    double final_cost;       /* at the returned x */
    int residual_evaluations;
    int jacobian_evaluations;
    double wall_time;        /* seconds */
} phc_nls_summary;

typedef struct phc_nls phc_nls;

/* A problem with n_params parameters (all start at 0, unbounded, free, scale 1). */
phc_nls *phc_nls_new(size_t n_params);
/* Why phc_nls_new returned NULL: PHC_ERR_IO "PATH: cannot load the Ceres
 * module ..." when Ceres (phytocal_ceres.so beside the library, opened on
 * the first phc_nls_new) could not be loaded, else PHC_ERR_NOMEM "WHAT: out
 * of memory". */
int phc_nls_new_error(const char *what, phc_error *err);
void phc_nls_free(phc_nls *nls); /* accepts NULL */

/* Bounds may be -INFINITY / INFINITY.  Requires lower < upper (lower <= upper
 * when fixed), scale > 0 and finite.  A fixed parameter stays at the value
 * passed to phc_nls_solve. */
int phc_nls_set_parameter(phc_nls *nls, size_t index, double lower,
                          double upper, int fixed, double scale,
                          phc_error *err);

/* Adds a residual block of m residuals depending on the k distinct
 * parameters param_index[0..k-1].  user_data must outlive the problem. */
int phc_nls_add_block(phc_nls *nls, size_t m, const size_t *param_index,
                      size_t k, phc_residual_fn fn, phc_derivatives derivs,
                      phc_loss_kind loss, double loss_scale, void *user_data,
                      phc_error *err);

/* Total number of residuals over all blocks. */
size_t phc_nls_residual_count(const phc_nls *nls);

/* Solves from x (n values, inside the bounds); on return x holds the best
 * point found.  Returns PHC_OK whenever the solver ran (look at
 * summary->outcome), an error code when the problem is ill-posed (no blocks,
 * start outside bounds, a fatal callback error, an exception in Ceres). */
int phc_nls_solve(phc_nls *nls, const phc_nls_options *options, double *x,
                  phc_nls_summary *summary, phc_error *err);

/* Evaluates all blocks at x: residuals (total m, blocks in order added; may
 * be NULL) and the dense m x n row-major Jacobian d r / d x in physical
 * units (may be NULL), including columns of fixed parameters.  Derivatives
 * come from the same method as in the solve.  Robust losses are NOT applied:
 * these are the plain weighted residuals.  *cost (may be NULL) receives
 * 1/2 sum rho(r^2) with losses applied. */
int phc_nls_evaluate(phc_nls *nls, const double *x, double *residuals,
                     double *jacobian, double *cost, phc_error *err);

/* Ceres's version string, e.g. "2.1.0-eigen-(3.4.0)-lapack-suitesparse-...". */
const char *phc_nls_version(void);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CERES_BRIDGE_H */
