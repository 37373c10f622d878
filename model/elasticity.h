/* Logistic elasticity of plant tissue (wilting paper, Maggioli et al. 2023, eq. 9).
 *
 *     E(θ) = E_min + E_max · σ(κ (θ − χ0)),     σ(z) = 1 / (1 + e^(−z))
 *
 * The paper prints the bare logistic σ(κ(θ − χ0)); the authors' code scales
 * it as above, which is the form fitted here (E_min = 0, E_max = 1 gives the
 * paper's form).  E is a bulk modulus of elasticity: the change of turgor
 * pressure per unit change of relative water content, in MPa when fitted to
 * pressure–volume data (E_min, E_max in MPa).
 *
 * What θ is.  In the paper θ is the ABSOLUTE water content of a node of the
 * plant graph (cm³ of water, the θ of P = θ/V whose initial value is the
 * node volume V, θ(0) = V), and χ0 is an absolute water amount too.  A
 * pressure–volume curve measures one detached leaf, not graph nodes: its
 * natural water coordinate is the RELATIVE water content RWC = water /
 * water at saturation (dimensionless, 0..1, slightly above 1 for
 * over-saturated tissue).  phytocal therefore fits the logistic on RWC
 * (θ = RWC, χ0 an RWC, κ per unit RWC) and converts for the water model:
 * a node at full hydration holds θ = V, so RWC = θ/V and
 *     κ_abs = κ_rwc / V   (cm⁻³),     χ0_abs = χ0_rwc · V   (cm³),
 * which is phc_elasticity_to_absolute().  Fitting on RWC makes one fitted
 * curve serve every node size and lets leaves of different mass be pooled.
 *
 * Numerics: σ is evaluated without overflow for any finite z (e^(−|z|)
 * only), and σ'(z) = σ(z)·σ(−z) without the cancellation of σ(1 − σ).
 * For κ → 0, E → E_min + E_max/2 exactly.  Pure C, no I/O. */
#ifndef PHC_ELASTICITY_H
#define PHC_ELASTICITY_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Parameter order of phc_elasticity_eval's gradient and of the data-set
 * slots (fit/costs/elasticity_curve.h). */
enum {
    PHC_ELASTICITY_KAPPA = 0, /* steepness κ, per unit of θ (RWC: dimensionless) */
    PHC_ELASTICITY_CHI0 = 1,  /* midpoint χ0, in units of θ */
    PHC_ELASTICITY_E_MIN = 2, /* modulus at very low water content, MPa */
    PHC_ELASTICITY_E_MAX = 3, /* modulus range E(∞) − E(−∞), MPa */
    PHC_ELASTICITY_NPARAMS = 4
};

typedef struct phc_elasticity_params {
    double kappa; /* 1 / (unit of θ) */
    double chi0;  /* unit of θ */
    double e_min; /* MPa */
    double e_max; /* MPa */
} phc_elasticity_params;

/* The logistic σ(z) = 1/(1 + e^(−z)), safe for every finite z (σ(±∞) = 1, 0). */
double phc_elasticity_sigmoid(double z);

/* σ'(z) = σ(z)σ(−z), safe for every finite z (0 far out, never negative). */
double phc_elasticity_sigmoid_derivative(double z);

/* E(θ).  When grad is not NULL, grad[0..3] receives ∂E/∂κ, ∂E/∂χ0, ∂E/∂E_min,
 * ∂E/∂E_max (the PHC_ELASTICITY_* order); when dtheta is not NULL it receives
 * ∂E/∂θ. */
double phc_elasticity_eval(const phc_elasticity_params *p, double theta, double grad[4],
                           double *dtheta);

/* Converts parameters fitted on RWC into the absolute form of the water model
 * for a node of volume `volume` (cm³, > 0; θ(0) = volume is RWC 1):
 * κ/volume, χ0·volume; E_min and E_max unchanged.  Returns 0, or
 * PHC_ERR_INVALID (model/status.h) when volume is not positive and finite. */
int phc_elasticity_to_absolute(const phc_elasticity_params *rwc, double volume,
                               phc_elasticity_params *absolute);

#ifdef __cplusplus
}
#endif

#endif /* PHC_ELASTICITY_H */
