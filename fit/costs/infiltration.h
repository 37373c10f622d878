/* `infiltration` data sets: how deep the rain goes.  An infiltration
 * experiment records, over time, the depth above which a fraction f of the
 * water applied so far lies (Rhizomorph Fig. 7 plots f = 80%), and the
 * Rhizomorph soil model (model/soil.h) predicts it:
 *
 *   depth_f(t): the depth d with  sum over planes above d of (w - w(0)) dx^3 = f W_in(t)
 *
 * (linear within a voxel plane; W_in the water that entered through rain and
 * sources up to t).  Fits p and c (globally or per layer) like soil_probe.
 *
 *   - kind: infiltration
 *     file: front.csv
 *     time: {column: t, unit: h}
 *     depth: {column: d80, unit: cm}   # any length unit; converted to m
 *     fraction: 0.8
 *     sigma: 0.01                      # m, or a column name (in the depth unit)
 *     soil: {...}                      # fit/costs/soil_setup.h (with rain)
 *
 * Analytic Jacobians through the soil's forward sensitivities and the
 * implicit-function derivative of the crossing.  A time at which less than
 * f of the applied water is in the box (it drained through an absorbing
 * bottom) has no depth: the model value is then not finite and the data set
 * says so at the start values. */
#ifndef PHC_COSTS_INFILTRATION_H
#define PHC_COSTS_INFILTRATION_H

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"

extern const char *const phc_infiltration_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_infiltration_help[];

int phc_infiltration_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                          phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err);

#endif /* PHC_COSTS_INFILTRATION_H */
