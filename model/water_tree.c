/* Elimination over a tree and the exponential's divided difference, shared
 * by the water model's evaluators (model/water_internal.h).  Pure C. */
#include <math.h>
#include <string.h>

#include "model/water_internal.h"

void phc_water_tree_factor(size_t n, const size_t *par, const double *w, const double *d,
                           const double *ell, double c, double *l, double *u, double *ipiv)
{
    double *sig = ipiv;
    for (size_t k = 0; k < n; ++k)
        sig[k] = 1.0 + c * ell[k];
    for (size_t k = n - 1; k >= 1; --k) {
        size_t pk = par[k];
        double akp = c * w[k] / d[pk]; /* -M(k, par) */
        double apk = c * w[k] / d[k];  /* -M(par, k) */
        double piv = sig[k] + apk;
        l[k] = -apk / piv;
        u[k] = -akp;
        sig[pk] += akp * sig[k] / piv;
        sig[k] = 1.0 / piv;
    }
    sig[0] = 1.0 / sig[0];
}

void phc_water_tree_solve(size_t n, const size_t *restrict par, const double *restrict l,
                          const double *restrict u, const double *restrict ip, double *restrict y)
{
    for (size_t k = n - 1; k >= 1; --k)
        y[par[k]] -= l[k] * y[k];
    y[0] *= ip[0];
    for (size_t k = 1; k < n; ++k)
        y[k] = (y[k] - u[k] * y[par[k]]) * ip[k];
}

double phc_water_expm_divided_difference(double li, double lj, double Ei, double Ej, double t)
{
    if (li > lj) {
        double tmp = li;
        li = lj;
        lj = tmp;
        tmp = Ei;
        Ei = Ej;
        Ej = tmp;
    }
    double dl = li - lj; /* <= 0 */
    if (dl == 0.0)
        return t * Ej;
    double x = dl * t;
    if (fabs(x) < 1e-300)
        return t * Ej;
    return Ej * expm1(x) / dl;
}

const double phc_water_bdf6_beta[6] = {-10.0 / 147, 72.0 / 147, -225.0 / 147,
                                       400.0 / 147, -450.0 / 147, 360.0 / 147};

void phc_water_extrapolated_euler(size_t len, double H, double *x, double *T, double *y,
                                  void (*factor)(void *ctx, double c),
                                  void (*step)(void *ctx, double *y), void *ctx)
{
    for (int j = 0; j < PHC_WATER_START_ORDERS; ++j) {
        int nj = j + 1;
        factor(ctx, H / nj);
        memcpy(y, x, len * sizeof *y);
        for (int r = 0; r < nj; ++r)
            step(ctx, y);
        for (int k = 1; k <= j; ++k) {
            double f = (double)nj / (double)(nj - k) - 1.0;
            double *Tk = T + (size_t)(k - 1) * len;
            for (size_t q = 0; q < len; ++q) {
                double cur = y[q];
                y[q] = cur + (cur - Tk[q]) / f;
                Tk[q] = cur;
            }
        }
        memcpy(T + (size_t)j * len, y, len * sizeof *y);
    }
    memcpy(x, T + (size_t)(PHC_WATER_START_ORDERS - 1) * len, len * sizeof *x);
}
