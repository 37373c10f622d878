/* Pressure–volume (PV) curve analysis: the classic water-relations
 * parameters of a leaf from its balance-and-pressure-chamber dehydration
 * series (Tyree & Hammel 1972, J. Exp. Bot. 23:267; Koide et al. 2000 in
 * Pearcy et al., Plant Physiological Ecology; Sack & Pasquet-Kok,
 * PrometheusWiki "Leaf pressure–volume curve parameters"; Bartlett, Scoffoni &
 * Sack 2012, Ecol. Lett. 15:393).
 *
 * Quantities and units (as in the literature):
 *   ψ     leaf (balance) water potential, MPa, ≤ 0 (must be < 0 here: 1/ψ)
 *   RWC   relative water content = (FW − DW)/(SW − DW), dimensionless:
 *         FW fresh mass, DW dry mass, SW saturated (turgid) mass, all g
 *   π     osmotic potential, MPa;  P = ψ − π turgor pressure, MPa
 *
 * Method (phc_pv_analyse):
 *  1. Points are sorted by decreasing RWC (wettest first).
 *  2. Beyond the turgor loss point (tlp) turgor is zero and π obeys the
 *     Boyle–van 't Hoff relation: −1/ψ = −1/π is linear in RWC,
 *         −1/ψ = a + b·RWC          (a, b in MPa⁻¹)
 *     fitted by ordinary least squares to the m driest points.
 *  3. The osmotic line gives π(RWC) = −1/(a + b·RWC) at every point, and the
 *     turgor P_i = ψ_i − π(RWC_i).  Above the breakpoint P is fitted by a
 *     straight line P = c + e·RWC (c, e in MPa): the constant bulk modulus of
 *     the standard analysis.
 *  4. Breakpoint (which points are "linear"): PHC_PV_BREAK_MIN_RSS (default)
 *     tries every split with at least min_points (3) on each side and keeps
 *     the one whose two-part model ψ̂ = π(RWC) + P̂(RWC) (P̂ = 0 on the dry
 *     side) has the smallest residual sum of squares in ψ (MPa²): every split
 *     explains all n points with the same 4 parameters, so the RSS values are
 *     comparable and no R² threshold has to be chosen.  PHC_PV_BREAK_MAX_R2 is
 *     the rule of the R package photosynthesis (fit_PV_curve, C. Muir): the set
 *     of final points with the largest R² of −1/ψ against RWC.
 *     PHC_PV_BREAK_FIXED takes n_osmotic from the options.
 *  5. Parameters:
 *       π_o   = −1/(a + b)            osmotic potential at full turgor (RWC = 1)
 *       a_f   = −a/b                  apoplastic fraction: RWC where −1/ψ = 0
 *                                     (x-intercept; the water that no osmotic
 *                                     dilution reaches)
 *       RWC_tlp = −c/e                where P̂ reaches zero, i.e. where the
 *                                     osmotic line meets the measured curve
 *       ψ_tlp = π(RWC_tlp)            water potential at the tlp (= π_tlp)
 *       ε     = e = dP/dRWC           bulk modulus on TOTAL RWC, MPa: the
 *                                     convention of the R packages
 *                                     photosynthesis and pvldcurve (slope of
 *                                     P against RWC above the tlp)
 *       ε_sym = e·(1 − a_f)           the same on SYMPLASTIC RWC,
 *                                     RWC_sym = (RWC − a_f)/(1 − a_f)
 *       C_FT, C_TLP                   capacitances: slopes of RWC against ψ
 *                                     (MPa⁻¹) above and below the cut point
 *     Conventions (options): the tlp fitted from the turgor line, or the
 *     measured point at the cut; ε from the points above the osmotic region,
 *     or from the points down to and including the cut; the cut at the
 *     osmotic region's wettest point, or where photosynthesis puts it.
 *     photosynthesis: max_r2 over its candidates, measured tlp, shared
 *     break, its cut (phc_pv_options_photosynthesis).  pvldcurve (R, read
 *     from R/TurgorLossPoint.R and R/ModElasticity.R): the tlp where an
 *     exponential and a linear part of one nls fit of −1/ψ against the
 *     relative water deficit meet (a fitted tlp, from another model than
 *     ours), ε from the points before it plus the point (tlp, P = 0) in
 *     bar per % deficit.
 *     Standard errors: (a, b) from the osmotic regression (s² = RSS/(m − 2));
 *     (c, e) from the turgor regression plus the propagation of (a, b) into
 *     the P_i (the two point sets are disjoint, so their noises are
 *     independent); derived quantities by the delta method on the joint
 *     4 × 4 covariance.  RWC is taken as exact (the saturated mass's own
 *     uncertainty, e.g. from phc_pv_extrapolate_saturation, is not
 *     propagated).
 *  6. Pointwise modulus series (what the logistic elasticity of
 *     model/elasticity.h is fitted to): finite differences of P against RWC
 *     between consecutive points, ε_j = (P_j − P_{j+1})/(RWC_j − RWC_{j+1}) at
 *     the midpoint RWC, n − 1 values over the whole curve (≈ 0 below the tlp,
 *     ≈ ε above).  Consecutive values share a point and are correlated.
 *
 * Pure C, no I/O.  Points must be finite, ψ < 0, RWC > 0, RWC distinct. */
#ifndef PHC_PRESSURE_VOLUME_H
#define PHC_PRESSURE_VOLUME_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum phc_pv_breakpoint_rule {
    PHC_PV_BREAK_MIN_RSS, /* smallest two-part RSS in ψ (default) */
    PHC_PV_BREAK_MAX_R2,  /* largest R² of the osmotic line (R photosynthesis) */
    PHC_PV_BREAK_FIXED    /* options.n_osmotic driest points */
} phc_pv_breakpoint_rule;

/* Where the turgor loss point is read (item 5). */
typedef enum phc_pv_tlp {
    PHC_PV_TLP_FITTED = 0, /* where the turgor line P = c + e·RWC reaches 0 (default) */
    PHC_PV_TLP_MEASURED    /* the measured point at the cut (ψ and RWC of that point;
                              no standard error): the R package photosynthesis */
} phc_pv_tlp;

/* Which points the bulk modulus ε (and the turgor line) is fitted to. */
typedef enum phc_pv_modulus_points {
    PHC_PV_MODULUS_ABOVE_BREAK = 0, /* the points above the osmotic region only (default) */
    PHC_PV_MODULUS_SHARED_BREAK     /* the wettest points down to and including the cut point
                                       (photosynthesis: lm(psi_p ~ RWC) on rows 1..cut) */
} phc_pv_modulus_points;

/* The cut: the point that separates "full turgor" from "after the turgor
 * loss point" for a measured tlp, a shared-break modulus and the
 * capacitances. */
typedef enum phc_pv_cut {
    PHC_PV_CUT_REGION_START = 0, /* the wettest point of the osmotic region (default) */
    PHC_PV_CUT_PHOTOSYNTHESIS    /* photosynthesis::fit_PV_curve's row: its loop variable i
                                    (rows (n−i):n are the osmotic region, m = i + 1 points),
                                    used as a row index from the wettest point, i.e. the
                                    (m − 1)-th point; the region's first point only when
                                    n = 2i.  Offered to reproduce the package's numbers. */
} phc_pv_cut;

typedef struct phc_pv_options {
    phc_pv_breakpoint_rule rule;
    size_t min_points; /* per region, ≥ 3 (one residual degree of freedom); not used by
                          PHC_PV_BREAK_MAX_R2, whose candidates are the package's */
    size_t n_osmotic;  /* PHC_PV_BREAK_FIXED only */
    phc_pv_tlp tlp;
    phc_pv_modulus_points modulus_points;
    phc_pv_cut cut;
} phc_pv_options;

phc_pv_options phc_pv_options_default(void); /* MIN_RSS, 3, 0, fitted, above_break, region start */

/* The conventions of photosynthesis::fit_PV_curve (C. Muir, CRAN, read from
 * R/fit_PV_curve.R): MAX_R2 over the last 4 .. n − 1 points (ties: the
 * larger region), the tlp measured at its cut row, the modulus over the
 * rows down to the cut, the cut as the package takes it. */
phc_pv_options phc_pv_options_photosynthesis(void);

typedef struct phc_pv_estimate {
    double value;
    double stderr_; /* NaN when undefined */
} phc_pv_estimate;

/* Warnings (bits of phc_pv_result.warnings); phc_pv_warning_text() explains. */
enum {
    PHC_PV_WARN_NOT_MONOTONE = 1u << 0,   /* ψ rises while RWC falls somewhere */
    PHC_PV_WARN_APOPLAST_RANGE = 1u << 1, /* a_f outside [0, 1) */
    PHC_PV_WARN_TLP_OUTSIDE = 1u << 2,    /* RWC_tlp outside the measured RWC range */
    PHC_PV_WARN_EPSILON = 1u << 3,        /* ε ≤ 0: turgor does not fall with RWC */
    PHC_PV_WARN_OSMOTIC_LINE = 1u << 4,   /* b ≤ 0 or a + b ≤ 0: no physical π */
    PHC_PV_WARN_RWC_ABOVE_ONE = 1u << 5   /* some RWC > 1.05 (saturated mass too low?) */
};
#define PHC_PV_WARN_COUNT 6
const char *phc_pv_warning_text(unsigned bit); /* "" for an unknown bit */

typedef struct phc_pv_result {
    size_t n;           /* points */
    size_t *order;      /* [n] input index of each sorted point (wettest first) */
    double *rwc;        /* [n] sorted RWC */
    double *psi;        /* [n] sorted ψ, MPa */
    double *inv_psi;    /* [n] −1/ψ, MPa⁻¹ */
    double *osmotic;    /* [n] π(RWC_i) from the osmotic line, MPa */
    double *turgor;     /* [n] P_i = ψ_i − π_i, MPa */
    size_t n_turgor;    /* the first n_turgor sorted points: above the breakpoint */
    size_t n_osmotic;   /* the last n_osmotic: the linear (osmotic) region */
    double coef[4];     /* a, b (MPa⁻¹); c, e (MPa) */
    double cov[16];     /* their joint covariance, row-major */
    double rss_osmotic; /* of −1/ψ, MPa⁻² */
    double r2_osmotic;  /* R² of −1/ψ against RWC over the osmotic region */
    double rss_turgor;  /* of P, MPa² */
    double rss_psi;     /* two-part model in ψ, MPa² (the MIN_RSS criterion) */
    phc_pv_estimate pi_o;      /* MPa */
    phc_pv_estimate psi_tlp;   /* MPa */
    phc_pv_estimate rwc_tlp;   /* dimensionless */
    phc_pv_estimate apoplastic_fraction; /* dimensionless */
    phc_pv_estimate epsilon;   /* MPa per unit total RWC */
    phc_pv_estimate epsilon_sym; /* MPa per unit symplastic RWC */
    size_t cut;          /* the cut point (sorted index, options.cut) */
    phc_pv_estimate capacitance_ft;  /* C_FT: slope of RWC on ψ over the points from the
                                        wettest down to the cut, MPa⁻¹ (Sack et al. 2003;
                                        OLS standard error) */
    phc_pv_estimate capacitance_tlp; /* C_TLP: the same over the cut and the drier points */
    size_t n_modulus;   /* n − 1 */
    double *modulus_rwc; /* [n − 1] midpoints, RWC */
    double *modulus;     /* [n − 1] ΔP/ΔRWC, MPa */
    unsigned warnings;   /* PHC_PV_WARN_* bits */
} phc_pv_result;

/* RWC = (fresh − dry)/(saturated − dry) (all in one mass unit).  NaN when
 * saturated ≤ dry. */
double phc_pv_rwc(double fresh, double dry, double saturated);

/* Saturated water mass by extrapolation (for data without a measured turgid
 * mass, e.g. the R package photosynthesis): ψ against leaf water mass over the
 * k = 3, 4, 5 wettest points (ψ closest to 0), the k with the largest R², and
 * its water mass at ψ = 0 (the rule of photosynthesis::fit_PV_curve).
 * water: leaf water mass (fresh − dry), any mass unit; ψ in MPa.  Returns the
 * saturated water mass, its delta-method standard error (from the k − 2
 * residual degrees of freedom of the chosen regression) and k.  PHC_ERR_INPUT with fewer than 3
 * points or a non-negative slope (ψ must rise with water). */
int phc_pv_extrapolate_saturation(const double *psi, const double *water, size_t n,
                                  double *water_sat, double *stderr_, size_t *used,
                                  phc_error *err);

/* The analysis above on n points (any order).  *out is allocated (free with
 * phc_pv_result_free).  PHC_ERR_INPUT (message names the 0-based input point)
 * for ψ ≥ 0, non-finite values, RWC ≤ 0, duplicate RWC, or fewer than
 * 2·min_points points; PHC_ERR_INVALID for bad options; PHC_ERR_NUMERIC when
 * no split gives a usable regression. */
int phc_pv_analyse(const double *psi, const double *rwc, size_t n, const phc_pv_options *options,
                   phc_pv_result **out, phc_error *err);

void phc_pv_result_free(phc_pv_result *r); /* accepts NULL */

#ifdef __cplusplus
}
#endif

#endif /* PHC_PRESSURE_VOLUME_H */
