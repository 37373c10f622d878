/* `soil_probe` data sets: soil-moisture probe readings against the
 * Rhizomorph soil model (model/soil.h), to fit permeability p and capacity c
 * (globally or per layer) and optionally f_diff, f_grav.
 *
 *   - kind: soil_probe
 *     file: readings.csv            # time, probe, value (in time order)
 *     time: {column: t, unit: h}    # any UDUNITS-2 time unit or "hours since ..."
 *     probe: probe                  # column of probe ids
 *     value: theta                  # column of readings
 *     quantity: water               # water (w, m^3/m^3, default) | fill (w/c)
 *     start: 0                      # the reading time of model t = 0, in the time
 *                                   # unit (default 0; required for timestamps)
 *     probes: {file: probes.csv, id: id, x: x, y: y, depth: depth, sigma: sigma}
 *                                   # or lat: and lon: instead of x: and y:
 *     sigma: 0.005                  # a scalar when the probe table has none
 *     soil: {...}                   # fit/costs/soil_setup.h
 *
 * The model value is the trilinear interpolation of w (or w/c) between voxel
 * centres at the probe's position.  Analytic Jacobians come from the soil's
 * forward sensitivities (the tangent of the same discrete steps).
 * A probe outside the grid is an error naming the probe and its line. */
#ifndef PHC_COSTS_SOIL_PROBE_H
#define PHC_COSTS_SOIL_PROBE_H

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"

extern const char *const phc_soil_probe_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_soil_probe_help[];

int phc_soil_probe_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                        phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err);

#endif /* PHC_COSTS_SOIL_PROBE_H */
