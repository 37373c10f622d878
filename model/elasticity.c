/* Logistic elasticity (wilting paper eq. 9, authors' scaled form): see elasticity.h. */
#include "model/elasticity.h"

#include <math.h>

#include "model/status.h"

double phc_elasticity_sigmoid(double z)
{
    /* Only e^(−|z|) is formed, so nothing overflows: 1/(1+e^(−z)) for z ≥ 0,
     * e^z/(1+e^z) for z < 0 (the naive form gives 1/(1+inf) = 0 correctly
     * but e^(−z) overflows to inf and raises FE_OVERFLOW). */
    if (z >= 0)
        return 1.0 / (1.0 + exp(-z));
    const double e = exp(z);
    return e / (1.0 + e);
}

double phc_elasticity_sigmoid_derivative(double z)
{
    /* σ(z)(1 − σ(z)) loses every digit once σ rounds to 1 (z > 37); the
     * product σ(z)σ(−z) keeps the relative accuracy: ≈ e^(−|z|) far out. */
    const double e = exp(-fabs(z));
    return e / ((1.0 + e) * (1.0 + e));
}

double phc_elasticity_eval(const phc_elasticity_params *p, double theta, double grad[4],
                           double *dtheta)
{
    const double d = theta - p->chi0;
    const double z = p->kappa * d;
    const double s = phc_elasticity_sigmoid(z);
    if (grad || dtheta) {
        const double ds = phc_elasticity_sigmoid_derivative(z);
        if (grad) {
            grad[PHC_ELASTICITY_KAPPA] = p->e_max * ds * d;
            grad[PHC_ELASTICITY_CHI0] = -p->e_max * ds * p->kappa;
            grad[PHC_ELASTICITY_E_MIN] = 1.0;
            grad[PHC_ELASTICITY_E_MAX] = s;
        }
        if (dtheta)
            *dtheta = p->e_max * ds * p->kappa;
    }
    return p->e_min + p->e_max * s;
}

int phc_elasticity_to_absolute(const phc_elasticity_params *rwc, double volume,
                               phc_elasticity_params *absolute)
{
    if (!(volume > 0) || !isfinite(volume))
        return PHC_ERR_INVALID;
    absolute->kappa = rwc->kappa / volume;
    absolute->chi0 = rwc->chi0 * volume;
    absolute->e_min = rwc->e_min;
    absolute->e_max = rwc->e_max;
    return PHC_OK;
}
