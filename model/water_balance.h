/* A plant on a balance: the water model of model/water.h with a loss that
 * changes with time (day and night) and, optionally, the water store of the
 * pot's soil (issue 17; the plant model is Maggioli et al. 2023, §3-4).
 *
 * Loss.  Leaf segment i loses l_i(t) = g(t) delta A_i (1/s): the paper's
 * constant rate delta A_i times a dimensionless multiplier g(t) >= 0 that is
 * piecewise constant: g = g_k on [start_k, start_{k+1}).  A light schedule
 * gives g = 1 by day and g = night_factor by night; covariates (PAR, VPD,
 * ...) give g_k = 1 + sum_j c_j x_jk.  g is linear in its fitted
 * coefficients c_j, with d g_k / d c_j given per interval.
 *
 * Pot.  One more node, the soil, joined to the plant's root segment (graph
 * root, position 0).  Its water theta_s (g) has the pressure K theta_s / C,
 * C the pot's capacity (g: the soil water at which the soil's pressure
 * equals that of a plant segment full to its volume), and exchanges
 *     q = k (theta_s / C - theta_root / V_root)     (g/s)
 * with the root segment, k the root-soil conductance (g/s per unit
 * difference of relative fill; as an edge weight w_s = k / K, so that water
 * moves down the pressure difference like every other edge).  The soil
 * loses nothing directly (a covered pot).  At the start plant and soil are
 * in equilibrium (the same relative fill), so the initial water W0 (g, the
 * system's initial water) is split: plant sum V / (sum V + C), soil
 * C / (sum V + C).  The balance then reads dry mass + W(t), W = plant water
 * + soil water.
 *
 * Evaluators.  BDF6 (paper eq. 8) restarted at every change of g with the
 * extrapolated implicit Euler start of model/water.c, so no step straddles a
 * jump of g; sensitivities integrated alongside (staggered, same
 * factorisation).  Exact: on each interval theta(t) = exp(S_k (t - start_k))
 * theta(start_k) through the eigen-decomposition of the symmetric form of
 * S_k (one per distinct g_k), and sensitivities through the Frechet
 * derivative of the exponential (divided differences in the eigenbasis).
 * Pure C: no I/O, no globals. */
#ifndef PHC_WATER_BALANCE_H
#define PHC_WATER_BALANCE_H

#include <stddef.h>

#include "model/status.h"
#include "model/water.h"

#ifdef __cplusplus
extern "C" {
#endif

/* g(t), piecewise constant.  Interval k covers [start[k], start[k+1]) and
 * the last one [start[n-1], infinity); times before start[0] use g[0]. */
typedef struct phc_water_loss_pattern {
    size_t n;            /* intervals, >= 1 */
    const double *start; /* n ascending interval starts, s (the curve's clock) */
    const double *g;     /* n multipliers, >= 0 and finite */
    size_t n_coef;       /* fitted coefficients of g (0 = none) */
    const double *dg;    /* n x n_coef row-major: d g_k / d c_j (NULL when n_coef = 0) */
} phc_water_loss_pattern;

typedef struct phc_water_pot {
    double capacity;     /* C, g, > 0 */
    double conductance;  /* k, g/s, >= 0 */
} phc_water_pot;

/* Columns of the sensitivities dW (m x (PHC_WB_COEF + n_coef), row-major). */
enum {
    PHC_WB_DELTA = 0,    /* d W / d delta, g cm^2 s */
    PHC_WB_W0,           /* d W / d W0, 1 */
    PHC_WB_MU,           /* d W / d mu, g / (mPa s) */
    PHC_WB_CAPACITY,     /* d W / d C, 1 (0 without a pot) */
    PHC_WB_CONDUCTANCE,  /* d W / d k, s (0 without a pot) */
    PHC_WB_COEF          /* d W / d c_j at PHC_WB_COEF + j, g */
};

/* Total water W (g: plant + soil) at m sorted times t (s, >= t_start) of a
 * curve that starts at t_start with total water phc_water_system_initial_water(s)
 * in equilibrium.  pot NULL = no pot; loss NULL = g = 1.  method: AUTO
 * (exact when the system is small and not stiff, else BDF6), EXACT or BDF6;
 * step_or_0: BDF6 step (s), 0 = (t_max - t_start) / 1000 (shortened so that
 * every interval of g holds a whole number of steps, at least 6).  dW NULL
 * or m x (PHC_WB_COEF + n_coef).  Errors: PHC_ERR_INVALID (arguments),
 * PHC_ERR_DOMAIN (a negative g, a pot with C <= 0 or k < 0), PHC_ERR_NOMEM. */
int phc_water_balance_curve(const phc_water_system *s, const phc_water_pot *pot,
                            const phc_water_loss_pattern *loss, double t_start,
                            phc_water_method method, double step_or_0, const double *t,
                            size_t m, double *W, double *dW, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_WATER_BALANCE_H */
