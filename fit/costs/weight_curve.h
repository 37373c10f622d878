/* `weight_curve` data sets: a plant (or a detached leaf) weighed on a balance
 * while it dries, against the wilting paper's water model (model/water.h):
 *
 *     mass(t) = dry_mass + W(t),   W(t) = 1ᵀ exp(S t) θ(0),   Σ θ(0) = initial_water
 *
 * with S = R·D_V⁻¹ − D_ℓ built from the plant graph (wilting §3–4, eq. 4–7)
 * and the leaf loss ℓ_i = δ·A_i.
 *
 * Parameter slots (bound to global parameters by name, see config.h):
 *   delta          δ, leaf water-loss rate per unit of segment area proxy
 *                  A = r·h: s⁻¹·cm⁻² (the model's units; ℓ = δ·A in s⁻¹)
 *   initial_water  water in the plant at the first weighing, g
 *   initial_water_2, _3, ...  with `jumps: split`, the water at the start of
 *                  each later piece of the curve, g
 *   dry_mass       g; absent as a slot when the data set gives a measured
 *                  `dry_mass:` (then fixed at the measurement)
 *   viscosity      μ of the sap, mPa·s; a slot only when the problem has a
 *                  parameter of that name or the data set binds it,
 *                  otherwise fixed at `viscosity:` (default 0.89, water at 25 °C)
 * Observations are in g; time is measured in s from the first weighing kept.
 *
 * Config keys (besides the common data-set keys):
 *   file:            CSV file of weighings, relative to the config file
 *   time:            {column: NAME, unit: UNIT}  (any UDUNITS-2 time unit, also
 *                    "seconds since 1970-01-01" for POSIX times; default s)
 *   mass:            {column: NAME, unit: UNIT}  (any mass unit; default g)
 *   select:          {COLUMN: VALUE, ...} keep only the rows matching all
 *                    (one plant out of a long table)
 *   plant:           a plant-graph file (measurements/plant_io.h), or
 *   leaf_area:       {value: A | column: NAME, unit: UNIT (default cm2)}: a
 *                    detached leaf, modelled as a venation chain
 *                    (phc_plant_graph_leaf_chain) of `chain_segments` (20)
 *                    segments of radius `vein_radius` (mm, default 0.5)
 *   plant_format, plant_unit: format name and length unit of `plant:`
 *   dry_mass:        measured dry mass {value: | column:, unit:} (optional)
 *   sigma:           balance standard deviation (in the mass unit) or a column
 *   exclude:         [[from, to], ...] time windows to drop, in the time unit,
 *                    measured from the first selected row
 *   jumps:           what a rise of the mass by more than `jump_threshold`
 *                    between weighings (an irrigation) does: `error`
 *                    (default: stop and name the line), `split` (the curve
 *                    restarts there: piece k = 2, 3, ... gets its own slot
 *                    `initial_water_<k>`, the water right after watering,
 *                    while delta and the dry mass are shared) or `keep`
 *   jump_threshold:  in the mass unit (default max(5σ, 0.5% of the largest mass))
 *   conductance:     poiseuille (default) | mean | paper | reference |
 *                    reference_2024 (model/water.h)
 *   method:          auto (default) | exact | bdf6
 *   step:            BDF6 time step in the time unit (default: chosen from the
 *                    time span)
 *   viscosity:       μ when it is not a fitted parameter (mPa·s)
 *   x_label, y_label: axis labels */
#ifndef PHC_COSTS_WEIGHT_CURVE_H
#define PHC_COSTS_WEIGHT_CURVE_H

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"

extern const char *const phc_weight_curve_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_weight_curve_help[];

int phc_weight_curve_load(const phc_yaml_doc *doc, const phc_yaml_node *node,
                          const char *base_dir, phc_is_parameter_fn is_parameter,
                          void *user_data, phc_dataset **out, phc_error *err);

#endif /* PHC_COSTS_WEIGHT_CURVE_H */
