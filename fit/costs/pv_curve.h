/* `pv_curve` data sets: raw pressure–volume data of one or more leaves
 * (water potential and mass along a bench dehydration), analysed with
 * model/pressure_volume.h, then the logistic elasticity (model/elasticity.h,
 * slots kappa, chi0, e_min, e_max) fitted to the pointwise bulk modulus
 * against relative water content.
 *
 * Built in C with phc_pv_curve_new from a table (measurements/table.h: read
 * from a CSV file, or phc_table_from_columns for arrays) and options; the
 * config's `kind: pv_curve` mapping is translated into the same options by
 * fit/config/pv_curve_yaml.c.
 *
 * Slots: kappa, chi0, e_min, e_max (one logistic for the leaves), or
 * kappa_<id>, chi0_<id>, e_min_<id>, e_max_<id> per leaf with leaf "each".
 *
 * Observations are the moduli ΔP/ΔRWC between consecutive points (n − 1 per
 * leaf); each is attributed to the CSV line of the wetter point of its pair.
 * RWC = (fresh − bag − dry)/(saturated − dry). */
#ifndef PHC_COSTS_PV_CURVE_H
#define PHC_COSTS_PV_CURVE_H

#include <stddef.h>

#include "fit/costs/origin.h"
#include "fit/engine/dataset.h"
#include "measurements/table.h"
#include "model/pressure_volume.h"
#include "model/status.h"

/* A mass: a column of the table, or one number for every row.  Neither
 * (column NULL and value NaN) is "not given". */
typedef struct phc_pv_mass {
    const char *column; /* column of masses, g, or NULL */
    double value;       /* without a column: the mass, g (>= 0); NaN = not given */
} phc_pv_mass;

typedef struct phc_pv_curve_options {
    const char *psi;        /* column of water potentials (required); every value must be
                               < 0 (pressure-chamber balance pressures with a minus sign) */
    const char *psi_unit;   /* "MPa" (NULL means MPa), "bar" (x 0.1) or "kPa" (x 0.001);
                               case ignored */
    const char *fresh_mass; /* column of weighed masses, g (required): the leaf, or the
                               leaf in its bag when bag_mass is given */
    phc_pv_mass bag_mass;   /* optional: subtracted from fresh_mass (the bagged-leaf
                               protocol of the R package photosynthesis) */
    phc_pv_mass dry_mass;   /* required, g, below every leaf mass */
    phc_pv_mass saturated_mass; /* the turgid leaf mass, g: required unless
                                   extrapolate_saturation */
    int extrapolate_saturation; /* 1: the saturated water mass is extrapolated from psi
                                   against leaf water to psi = 0 over the wettest 3-5 points
                                   (photosynthesis::fit_PV_curve's rule); saturated_mass
                                   must then be unset */
    const char *group;      /* column of leaf ids, or NULL: the table is one leaf */
    const char *leaf;       /* with group: one id (that leaf), "each" (one logistic per leaf)
                               or "pooled" (one logistic for all leaves' moduli; every leaf
                               still gets its own PV analysis); NULL only when the group
                               column holds one id */
    phc_pv_options analysis; /* the breakpoint rule and the conventions (tlp, modulus
                                points, cut; model/pressure_volume.h); default min_rss,
                                fitted tlp, modulus above the break.
                                phc_pv_options_photosynthesis() reproduces
                                photosynthesis::fit_PV_curve */
    phc_pv_mass leaf_area;  /* optional: the leaf's area, cm², a column (first row of a
                               leaf) or a number (> 0); gives C*_FT, the capacitance at full
                               turgor per leaf area, mol m⁻² MPa⁻¹ */
    double sigma;           /* > 0: standard deviation of the moduli, MPa; 0 = unweighted */
    const phc_origin *origin; /* where the options came from, for messages; NULL */
} phc_pv_curve_options;

/* Nothing given but the defaults: psi in MPa, no masses (value NaN), one
 * leaf, phc_pv_options_default(), unweighted, no origin. */
phc_pv_curve_options phc_pv_curve_options_default(void);

/* Analyses every leaf of `table` (at least 2 x analysis.min_points rows per
 * leaf) and builds the elasticity data set over their moduli; the table may
 * be freed afterwards.  Parameter indices are left to phc_problem binding
 * (phc_problem_bind_by_name).  Errors name the option (and the config line
 * when options.origin is set), or the table's source, line and column:
 * PHC_ERR_INPUT for a missing option, an unknown column or leaf id, a value
 * that is not a number, a water potential that is not negative, a leaf mass
 * not above the dry mass, too few points in a leaf, two points of one leaf
 * with the same relative water content, or an analysis that fails. */
int phc_pv_curve_new(const phc_table *table, const phc_pv_curve_options *options, phc_dataset **out,
                     phc_error *err);

/* The operations of pv_curve data sets (ops->kind is "pv_curve"). */
extern const phc_dataset_ops phc_pv_curve_ops;

/* The per-leaf PV analyses of a pv_curve data set (NULL / 0 for other kinds). */
size_t phc_pv_curve_leaf_count(const phc_dataset *ds);
const phc_pv_result *phc_pv_curve_leaf(const phc_dataset *ds, size_t i, const char **label);

/* A markdown section: one table row per leaf with π_o, ψ_tlp (MPa), RWC_tlp,
 * ε and ε_sym (MPa), apoplastic fraction, each "value ± standard error", the
 * linear-region size and R²; a second table with the cut point, C_FT and
 * C_TLP (MPa⁻¹) and RWC_tlp in percent; then the warnings.  labels[i] names
 * results[i].
 * *out is malloc'd (free it).  `title` may be NULL. */
int phc_pv_markdown_table(const phc_pv_result *const *results, const char *const *labels, size_t count,
                          const char *title, char **out, phc_error *err);

/* The same for every leaf of a pv_curve data set (PHC_ERR_INVALID for other
 * kinds); adds how the saturated mass was obtained, the saturated water
 * content per dry mass SWC (g g⁻¹) and, with a leaf area, C*_FT
 * (mol m⁻² MPa⁻¹). */
int phc_pv_curve_markdown(const phc_dataset *ds, char **out, phc_error *err);

/* Every leaf's parameters as a JSON object in text (full precision, null
 * where undefined): {"conventions": {...}, "leaves": {"<id>": {"pi_o":
 * {"value": v, "stderr": s, "unit": "MPa"}, ...}}}.  *out is malloc'd. */
int phc_pv_curve_values_json(const phc_dataset *ds, char **out, phc_error *err);

#endif /* PHC_COSTS_PV_CURVE_H */
