/* `leaf_photos` data sets: photographs of aging leaves against the leaf
 * colour aging model of Silva et al. §3 (model/leaf.h, model/colour.h,
 * fit/costs/leaf_setup.h), to fit the scales of the venation, stomata and
 * inflow maps, the time scale and the colour transfer.
 *
 *   - kind: leaf_photos
 *     file: leaves.csv              # one row per photographed leaf
 *     image: scan.jpg               # the photo of every row, or {column: NAME}
 *                                   # (a file per row, relative to the config)
 *     leaf: leaf                    # column: the leaf's number in its photo
 *                                   # (reading order; default 1 for every row)
 *     id: leaf                      # column naming rows (default: the leaf column,
 *                                   # else the line number)
 *     stage: {column: spad, direction: decreasing}
 *                                   # the stage of each photo: a time (direction
 *                                   # increasing, the default) or a measured stage
 *                                   # such as SPAD chlorophyll (decreasing)
 *     initial: 9                    # id of the fresh leaf the model ages
 *                                   # (default: the earliest stage)
 *     reference: 1                  # id of the senescent reference (eq. 8), or
 *                                   # {image: FILE, leaf: N}
 *     residual: pixels              # pixels | histogram
 *     difference: de76              # pixels: de76 (3 residuals ΔL*, Δa*, Δb* per
 *                                   # cell, whose sum of squares is ΔE*ab²) | ciede2000
 *     grid: 24                      # pixels: cells on the long side of the leaf
 *     quantiles: 16                 # histogram: quantiles per CIELAB channel
 *     sigma: 2                      # per residual, ΔE units (default 2)
 *     colour_space: rgb             # rgb (the paper's) | lab: matching space
 *     colour_correction: none       # none | gray_world | colorchecker
 *     register: true                # pixels: align each photo to the fresh one (ECC)
 *     model_size: 128               # simulation grid, px on the long side
 *     dt: 0.1                       # model step, time units
 *     veins: auto                   # auto (ridge map of the fresh photo) | uniform | FILE
 *     vein_floor: 0.05              # β on the lamina between veins
 *     stomata: uniform              # uniform | FILE
 *     inflow: veins                 # veins | uniform | none | FILE
 *     cross_validate: false         # leave-one-out prediction of each row's stage
 *
 * Parameter slots (each present only when a parameter of that name exists
 * or is bound; otherwise the default in brackets is used):
 *   beta_scale [50] px²/time, stomata_scale [0.1] /time, inflow_scale [0.05]
 *   /time, time_scale [1] model time per stage unit, y_lo [0.2], y_hi [0.8].
 * A row's model time is t = time_scale |stage - stage(initial)|; a stage on
 * the wrong side of the initial one is an error naming the row.
 *
 * Residuals.  pixels: the photo (aligned to the fresh leaf by ECC on the
 * two silhouettes when `register`: aging changes the colours) and the
 * simulated leaf, both in CIELAB, averaged over each
 * cell of a coarse grid where at least half of the cell is leaf in both.
 * histogram: the quantiles of L*, a*, b* over the leaf (the L2 distance of
 * quantile functions is the 2-Wasserstein distance between histograms), for
 * photos of different leaves or that cannot be registered.
 * The Jacobian is by central differences (the model's steps make it a
 * piecewise-smooth function of the scales).
 *
 * cross_validate (after the fit, in the report): each row but the initial
 * and the reference is left out in turn, the data set's free slots are
 * refitted on the others, and the row's stage is predicted by finding the
 * model time whose colours are closest to its photo; beside it, a baseline
 * predicts the stage by a straight line in the leaf's mean chromatic
 * greenness G/(R+G+B), fitted on the same rows.  Both RMSEs are reported in
 * stage units. */
#ifndef PHC_COSTS_LEAF_PHOTOS_H
#define PHC_COSTS_LEAF_PHOTOS_H

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"

extern const char *const phc_leaf_photos_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_leaf_photos_help[];

int phc_leaf_photos_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                         phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err);

/* Leave-one-out prediction of each row's stage (see above), at the fitted
 * slot values p, with the free slots and their bounds taken from the data
 * set's problem.  Fills n_rows values each (NAN for the initial and
 * reference rows): observed stage, model prediction, baseline prediction;
 * rmse[0] model, rmse[1] baseline, over the predicted rows.  Arrays are
 * malloc'd.  Used by the report and by tests. */
int phc_leaf_photos_cross_validate(phc_dataset *ds, const double *p, size_t *n_rows, char ***ids,
                                   double **stage, double **model, double **baseline, double rmse[2],
                                   phc_error *err);

#endif /* PHC_COSTS_LEAF_PHOTOS_H */
