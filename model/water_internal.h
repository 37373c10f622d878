/* Internals shared by the water model's files (model/water*.c only; not
 * installed, not for callers): the system's arrays and the elimination over
 * the tree.  See model/water.h for the model. */
#ifndef PHC_WATER_INTERNAL_H
#define PHC_WATER_INTERNAL_H

#include <stddef.h>

#include "model/water.h"

/* Segments renumbered breadth-first (parents before children, position 0 is
 * the root); units as in water.h. */
struct phc_water_system {
    size_t n;
    size_t *perm;        /* n: graph index of position k */
    size_t *par;         /* n: parent position (par[0] unused) */
    double *w;           /* n: weight of edge (k, par[k]), w[0] = 0 */
    double *wsum;        /* n: sum of the weights at k */
    double *d;           /* n: capacity, theta / pressure (cm^3 per pressure unit) */
    double *vol;         /* n: V, cm^3 */
    double *area;        /* n: A (masked: 0 on stem and no-loss segments), cm^2 */
    double *ell;         /* n: delta * area, 1/s */
    double *theta0;      /* n: g */
    double delta, w0, mu, mu_power; /* R is proportional to mu^mu_power */
    phc_water_weights weights;
};

/* Factorises M = I - c S (S = R D^-1 - D_l, R the weighted Laplacian of the
 * tree given by par and the edge weights w, D = diag(d), D_l = diag(ell)) by
 * elimination leaves first: row k (after its children) holds only M_kk and
 * M_k,par, so there is no fill-in.  M is column diagonally dominant (column
 * sums 1 + c ell_k), so no pivoting is needed; the pivots are computed
 * GTH-style (Grassmann, Taksar & Heyman 1985) from the running column sums
 * of the Schur complement, which involves no cancellation: stiff systems
 * (c w / d ~ 1e15 in the physical mode) stay exactly conservative.
 * Outputs l, u, ipiv (n each; ipiv holds inverse pivots). */
void phc_water_tree_factor(size_t n, const size_t *par, const double *w, const double *d,
                           const double *ell, double c, double *l, double *u, double *ipiv);
/* y <- M^-1 y with a factorisation from phc_water_tree_factor. */
void phc_water_tree_solve(size_t n, const size_t *par, const double *l, const double *u,
                          const double *ipiv, double *y);
/* Divided difference of exp(. t) at lambda_i, lambda_j with E = exp(lambda t)
 * (the Frechet derivative of the matrix exponential in an eigenbasis):
 * (E_i - E_j)/(l_i - l_j), t E on the diagonal; written with expm1 around
 * the larger eigenvalue. */
double phc_water_expm_divided_difference(double li, double lj, double Ei, double Ej, double t);

/* The start of BDF6 (both evaluators): one interval of length H from x
 * (len values) by extrapolated implicit Euler, harmonic sequence n_j = j,
 * j = 1..PHC_WATER_START_ORDERS, Aitken-Neville in h (Deuflhard 1985).
 * factor(ctx, c) prepares the implicit step (I - c S) y_new = y_old, and
 * step(ctx, y) takes it in place.  T: PHC_WATER_START_ORDERS * len
 * workspace, y: len. */
#define PHC_WATER_START_ORDERS 8
void phc_water_extrapolated_euler(size_t len, double H, double *x, double *T, double *y,
                                  void (*factor)(void *ctx, double c),
                                  void (*step)(void *ctx, double *y), void *ctx);

/* BDF6 (paper eq. 8): (I - alpha h S) x_{n+1} = sum_j beta_j x_{n-5+j}. */
#define PHC_WATER_BDF6_ALPHA (60.0 / 147.0)
extern const double phc_water_bdf6_beta[6];

#endif /* PHC_WATER_INTERNAL_H */
