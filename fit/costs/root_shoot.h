/* `root_shoot` data sets: harvested plants (basal diameter, root mass, shoot
 * mass = stem + leaves, optionally age) against the Rhizomorph shoot-root
 * model (model/growth.h) growing in a Rhizomorph soil (model/soil.h), to
 * fit soil permeability and capacity jointly with growth parameters such
 * as phi_rg.
 *
 *   - kind: root_shoot
 *     file: harvest.csv             # a table ...
 *     diameter: {column: d, unit: mm}
 *     root_mass: {column: root, unit: g}
 *     shoot_mass: {column: shoot, unit: g}   # or leaf_mass: and stem_mass: (summed)
 *     age: {column: age, unit: month}        # optional: compared in the report
 *     # ... or a BAAD study folder (measurements/baad.h) instead of file:
 *     baad: ../shared/data/baad/Baltzer2007
 *     species: Quercus rubra        # BAAD species (after dataNew.csv)
 *     suspicious: exclude           # exclude (default; listed in the report) | keep
 *     select: {column: Light, equals: L}     # optional row filter (a table column
 *                                   # or a raw BAAD column)
 *     sigma: 0.3                    # standard deviation of ln(root:shoot)
 *     preset: oak                   # growth preset: oak cherry apple poplar maple
 *     growth: {phi_rg: 0.6}         # overrides of growth parameters
 *     mode: expected                # expected (default, smooth) | stochastic
 *     seed: 1                       # stochastic mode
 *     uptake: physical              # physical (default) | none (the authors' code)
 *     days: 365                     # longest simulated age, d
 *     step: 1                       # growth step, d
 *     plant: {x: 0.15, y: 0.15, depth: 0}   # m in the soil grid; default the
 *                                   # centre of the surface
 *     soil: {...}                   # fit/costs/soil_setup.h (a pot)
 *
 * Residual of harvested plant i: (ln(root:shoot)_i - ln(root:shoot)_model(D_i))
 * / sigma, where the model value is taken when the simulated plant's basal
 * diameter first reaches D_i (linear in diameter between daily states).
 * A plant that never reaches D_i within `days` gives a non-finite model
 * value (the fit rejects such trial points; at the start values it is an
 * error naming the row).
 *
 * Slots: the soil set-up's (p, c, p_<L>, c_<L>, f_diff, f_grav) and every
 * growth parameter (model/growth.h names) that is a problem parameter.
 * Derivatives: central differences with steps of 2% of each parameter
 * (the model is a simulation whose events fall on daily steps). */
#ifndef PHC_COSTS_ROOT_SHOOT_H
#define PHC_COSTS_ROOT_SHOOT_H

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"

extern const char *const phc_root_shoot_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_root_shoot_help[];

int phc_root_shoot_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                        phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out,
                        phc_error *err);

#endif /* PHC_COSTS_ROOT_SHOOT_H */
