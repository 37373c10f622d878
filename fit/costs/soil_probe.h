/* `soil_probe` data sets: soil-moisture probe readings against the
 * Rhizomorph soil model (model/soil.h), to fit permeability p and capacity c
 * (globally or per layer) and optionally f_diff, f_grav.
 *
 * Built in C with phc_soil_probe_new from a probe table and its readings
 * (measurements/soil_probes.h: read from CSV files, or filled from arrays)
 * and options; the config's `kind: soil_probe` mapping is translated into
 * the same by fit/config/soil_probe_yaml.c:
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

#include "fit/costs/origin.h"
#include "fit/costs/soil_setup.h"
#include "fit/engine/dataset.h"
#include "measurements/soil_probes.h"
#include "model/status.h"

/* What the probes read. */
typedef enum phc_soil_probe_quantity {
    PHC_SOIL_PROBE_WATER = 0, /* the water content w, m^3/m^3 */
    PHC_SOIL_PROBE_FILL       /* the fill level w/c */
} phc_soil_probe_quantity;

typedef struct phc_soil_probe_options {
    phc_soil_probe_quantity quantity; /* default water */
    double start;           /* h on the readings' clock: the model's t = 0; no reading may be
                               earlier.  NAN (default): the readings' times are the model's,
                               unchecked (a config without `start:`) */
    double sigma;           /* standard deviation of a reading (its unit), > 0, for probes
                               whose sigma is NAN; NAN (default): every probe has one */
    const phc_soil_setup_options *soil; /* the soil (required) */
    const char *x_label, *y_label; /* NULL: "time since start (h)" and the quantity's name */
    phc_is_parameter_fn is_parameter; /* which soil slots are fitted; NULL: p and c */
    void *user_data;                  /* passed to is_parameter */
    const phc_origin *origin;         /* where the options came from, for messages; NULL */
} phc_soil_probe_options;

/* Water readings, no start, no sigma, no soil yet, no labels, no origin. */
phc_soil_probe_options phc_soil_probe_options_default(void);

/* Builds a soil_probe data set over the readings (copied with the probes;
 * both may be freed afterwards).  readings->t are hours, readings->probe
 * index probes->probes; readings->line may be NULL (reading r is then line
 * r + 2 of readings->path, as a table with a header), and a NULL path is
 * "readings" ("probes" for the table).  Probes are placed in the grid's
 * frame (x east, y north, depth below the surface, m).  Slot names are the
 * soil's (phc_soil_setup_new); parameter indices are left to the caller.
 * Errors (PHC_ERR_INPUT) name the option (and the config line when
 * options.origin is set), or the readings' or probe table's file and line. */
int phc_soil_probe_new(const phc_probe_table *probes, const phc_probe_series *readings,
                       const phc_soil_probe_options *options, phc_dataset **out, phc_error *err);

/* The operations of soil_probe data sets (ops->kind is "soil_probe"). */
extern const phc_dataset_ops phc_soil_probe_ops;

#endif /* PHC_COSTS_SOIL_PROBE_H */
