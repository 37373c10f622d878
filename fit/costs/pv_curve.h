/* `pv_curve` data sets: raw pressure–volume data of one or more leaves
 * (water potential and mass along a bench dehydration), analysed with
 * model/pressure_volume.h, then the logistic elasticity (model/elasticity.h,
 * slots kappa, chi0, e_min, e_max) fitted to the pointwise bulk modulus
 * against relative water content.
 *
 * Config keys (besides the common data-set keys of fit/config.h):
 *   file:           CSV file, relative to the config file
 *   psi:            column of water potentials (balance pressure with a minus
 *                   sign); every value must be < 0 — a positive value is an
 *                   error naming file and line (enter chamber pressures as
 *                   negative potentials)
 *   psi_unit:       MPa (default) | bar (× 0.1) | kPa (× 0.001)
 *   fresh_mass:     column of weighed masses, g (the leaf, or the leaf in its
 *                   bag when bag_mass is given)
 *   bag_mass:       optional: column or number, g, subtracted from fresh_mass
 *                   (the bagged-leaf protocol of the R package photosynthesis)
 *   dry_mass:       column or number, g (required)
 *   saturated_mass: column or number, g: the turgid leaf mass (required); or
 *                   `extrapolate`: the saturated water mass is found by
 *                   extrapolating ψ against leaf water to ψ = 0 over the
 *                   wettest 3–5 points (photosynthesis::fit_PV_curve's rule)
 *   group:          optional column of leaf ids
 *   leaf:           with group: one id (fit that leaf), `each` (one logistic
 *                   per leaf; slots kappa_<id>, chi0_<id>, e_min_<id>,
 *                   e_max_<id>) or `pooled` (one logistic for all leaves'
 *                   moduli; every leaf still gets its own PV analysis).
 *                   Required when the group column holds more than one id.
 *   breakpoint:     min_rss (default) | max_r2 | a whole number of driest
 *                   points in the linear region (see pressure_volume.h)
 *   sigma:          optional positive number, MPa (modulus units)
 *
 * Observations are the moduli ΔP/ΔRWC between consecutive points (n − 1 per
 * leaf); each is attributed to the CSV line of the wetter point of its pair.
 * RWC = (fresh − bag − dry)/(saturated − dry). */
#ifndef PHC_COSTS_PV_CURVE_H
#define PHC_COSTS_PV_CURVE_H

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"
#include "model/pressure_volume.h"
#include "model/status.h"

extern const char *const phc_pv_curve_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_pv_curve_help[];

int phc_pv_curve_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                      phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out,
                      phc_error *err);

/* The per-leaf PV analyses of a pv_curve data set (NULL / 0 for other kinds). */
size_t phc_pv_curve_leaf_count(const phc_dataset *ds);
const phc_pv_result *phc_pv_curve_leaf(const phc_dataset *ds, size_t i, const char **label);

/* A markdown section: one table row per leaf with π_o, ψ_tlp (MPa), RWC_tlp,
 * ε and ε_sym (MPa), apoplastic fraction, each "value ± standard error", the
 * linear-region size and R², then the warnings.  labels[i] names results[i].
 * *out is malloc'd (free it).  `title` may be NULL. */
int phc_pv_markdown_table(const phc_pv_result *const *results, const char *const *labels, size_t count,
                          const char *title, char **out, phc_error *err);

/* The same for every leaf of a pv_curve data set (PHC_ERR_INVALID for other
 * kinds); adds how the saturated mass was obtained. */
int phc_pv_curve_markdown(const phc_dataset *ds, char **out, phc_error *err);

#endif /* PHC_COSTS_PV_CURVE_H */
