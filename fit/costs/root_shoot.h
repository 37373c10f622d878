/* `root_shoot` data sets: harvested plants (basal diameter, root mass, shoot
 * mass = stem + leaves, optionally age) against the Rhizomorph shoot-root
 * model (model/growth.h) growing in a Rhizomorph soil (model/soil.h), to
 * fit soil permeability and capacity jointly with growth parameters such
 * as phi_rg.
 *
 * Built in C with phc_root_shoot_new from the harvested plants
 * (fit/costs/harvest.h: from arrays, a table or a BAAD study folder) and
 * options; the config's `kind: root_shoot` mapping is translated into the
 * same by fit/config/root_shoot_yaml.c:
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

#include <stdint.h>

#include "fit/costs/harvest.h"
#include "fit/costs/origin.h"
#include "fit/costs/soil_setup.h"
#include "fit/engine/dataset.h"
#include "model/growth.h"
#include "model/status.h"

typedef struct phc_root_shoot_options {
    double sigma;            /* standard deviation of ln(root mass / shoot mass), > 0
                                (required; NAN until set) */
    const char *preset;      /* growth preset: oak (default), cherry, apple, poplar, maple */
    const char *species;     /* the plants' species (e.g. BAAD's name), for the report, which
                                says whether the preset describes it; NULL: not given */
    const phc_growth_params *growth; /* the growth parameters (model/growth.h); NULL: the
                                        preset's */
    phc_growth_mode mode;    /* PHC_GROWTH_EXPECTED (default, smooth) or PHC_GROWTH_STOCHASTIC */
    uint64_t seed;           /* stochastic mode's seed; default 1 */
    phc_growth_uptake uptake; /* root water uptake: physical (default) or none (the authors'
                                 code) */
    double days;             /* longest simulated age, d, > 0; default 365 */
    double step;             /* growth step, d, 0 < step <= days; default 1 */
    double plant_x, plant_y; /* where the seed is planted, m in the soil grid; NAN (default):
                                the centre of the surface */
    double plant_depth;      /* m below the surface; default 0 */
    const phc_soil_setup_options *soil; /* the soil (a pot); NULL: none (the roots see the
                                           growth parameter soil_fill as fill level) */
    const char *x_label, *y_label; /* NULL: "basal diameter (mm)", "ln(root mass / shoot mass)" */
    phc_is_parameter_fn is_parameter; /* which soil slots and growth parameters are fitted;
                                         NULL: p and c (with a soil) and phi_rg */
    void *user_data;                  /* passed to is_parameter */
    const phc_origin *origin;         /* where the options came from, for messages; NULL */
} phc_root_shoot_options;

/* sigma NAN (to be given), preset oak, expected mode, seed 1, physical
 * uptake, 365 days in steps of 1 d, the plant at the centre of the
 * surface, no soil. */
phc_root_shoot_options phc_root_shoot_options_default(void);

/* Builds a root_shoot data set over the harvested plants (copied; they may
 * be freed afterwards; their input files are recorded as the data set's).
 * Slots: the soil's (phc_soil_setup_new) first, then the growth parameters
 * is_parameter accepts, in model/growth.h's order; parameter indices are
 * left to the caller.  Errors (PHC_ERR_INPUT) name the option (and the
 * config line when options.origin is set) or the plants' file and line. */
int phc_root_shoot_new(const phc_harvest *plants, const phc_root_shoot_options *options, phc_dataset **out,
                       phc_error *err);

/* What a root_shoot data set has simulated since it was built.  Each
 * request for model values at some slot values needs one trajectory (the
 * plant grown until its diameter passes the largest asked for); the data
 * set keeps its last 32 trajectories by their exact slot values, and a
 * request at the same values is answered from them (the plant is
 * deterministic: the answer is the same to the last bit). */
typedef struct phc_root_shoot_counts {
    unsigned long requested;     /* trajectories asked for (values, each Jacobian column twice) */
    unsigned long reused;        /* of those, answered by a kept trajectory */
    unsigned long simulated;     /* plants grown (the report and the outputs grow their own) */
    double days;                 /* simulated days over all grown plants */
    unsigned long soil_substeps; /* soil sub-steps over all grown plants */
} phc_root_shoot_counts;

/* The counts of ds (a root_shoot data set); PHC_ERR_INVALID otherwise. */
int phc_root_shoot_counts_get(const phc_dataset *ds, phc_root_shoot_counts *out);

/* The operations of root_shoot data sets (ops->kind is "root_shoot"). */
extern const phc_dataset_ops phc_root_shoot_ops;

#endif /* PHC_COSTS_ROOT_SHOOT_H */
