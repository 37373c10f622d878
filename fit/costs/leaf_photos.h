/* `leaf_photos` data sets: photographs of aging leaves against the leaf
 * colour aging model of Silva et al. §3 (model/leaf.h, model/colour.h,
 * fit/costs/leaf_setup.h), to fit the scales of the venation, stomata and
 * inflow maps, the time scale and the colour transfer.
 *
 * Built in C with phc_leaf_photos_new from rows (one per photographed leaf:
 * its photo, as a file or an image in memory, its number in that photo and
 * its stage) and options; the config's `kind: leaf_photos` mapping is
 * translated into the same rows and options by fit/config/leaf_photos_yaml.c:
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
 *   /time, time_scale [1] model time per stage unit, y_lo [0.2], y_hi [0.8]
 *   (fluid levels, dimensionless: their slots declare the unit "1"; the
 *   model's time unit is the user's, so the scales declare none).
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
 * cross_validate (after the fit, in the report; run by the engine,
 * fit/engine/cross_validation.h, from the kind's plan): each row but the initial
 * and the reference is left out in turn, the data set's free slots are
 * refitted on the others, and the row's stage is predicted by finding the
 * model time whose colours are closest to its photo; beside it, a baseline
 * predicts the stage by a straight line in the leaf's mean chromatic
 * greenness G/(R+G+B), fitted on the same rows.  Both RMSEs are reported in
 * stage units. */
#ifndef PHC_COSTS_LEAF_PHOTOS_H
#define PHC_COSTS_LEAF_PHOTOS_H

#include <stddef.h>

#include "fit/costs/leaf_setup.h"
#include "fit/costs/origin.h"
#include "fit/engine/dataset.h"
#include "measurements/photo.h"
#include "model/colour.h"
#include "model/status.h"

/* One photographed leaf. */
typedef struct phc_leaf_photos_row {
    double stage;            /* its stage: a time, or a measured stage such as SPAD
                                chlorophyll (options.direction), in stage units */
    const char *image;       /* its photo: a PNG, JPEG or TIFF file (measurements/photo.h),
                                or, with `pixels`, the name that stands for it in messages
                                and the report (NULL: "rows[i].pixels") */
    const phc_image *pixels; /* the photo already in memory (sRGB in [0, 1]), or NULL to
                                read `image`; rows may share one (a scan of many leaves):
                                it is segmented once per name */
    size_t leaf;             /* the leaf's number in its photo, reading order, >= 1; 0 = 1 */
    const char *id;          /* names the row (options.initial and .reference, the report);
                                NULL: its line when given, else its 1-based position */
    size_t line;             /* its line in options.rows_source, for messages; 0 = none */
} phc_leaf_photos_row;

typedef enum phc_leaf_residual {
    PHC_LEAF_RESIDUAL_PIXELS = 0, /* CIELAB means over grid cells of photo and simulation */
    PHC_LEAF_RESIDUAL_HISTOGRAM   /* quantiles of L*, a*, b* over the leaf */
} phc_leaf_residual;

typedef enum phc_leaf_difference {
    PHC_LEAF_DE76 = 0,   /* pixels: 3 residuals per cell, ΔL*, Δa*, Δb* */
    PHC_LEAF_CIEDE2000   /* pixels: one residual per cell, ΔE00 */
} phc_leaf_difference;

typedef struct phc_leaf_photos_options {
    int direction;           /* +1: the stage increases as the leaf ages (a time; the
                                default), -1: it decreases (SPAD) */
    const char *stage_name;  /* what the stage is, for the report, the x label and
                                messages (the stage column's name); NULL = "stage" */
    const char *initial;     /* id of the row of the fresh leaf the model ages;
                                NULL = the row with the earliest stage */
    /* The senescent reference leaf (eq. 8): a row (not the initial one) ... */
    const char *reference;   /* its id, or NULL for a separate photo: */
    const char *reference_image;       /* a file, or with reference_pixels its name
                                          (NULL: "reference_pixels") */
    const phc_image *reference_pixels; /* or an image in memory (NULL: read the file) */
    size_t reference_leaf;   /* the leaf's number in that photo; 0 = 1 */
    phc_leaf_residual residual;        /* PIXELS */
    phc_leaf_difference difference;    /* DE76 */
    size_t grid;             /* pixels: cells on the long side of the leaf, 2..512 (24) */
    size_t quantiles;        /* histogram: quantiles per CIELAB channel, 2..256 (16) */
    double sigma;            /* of each residual, ΔE units, > 0 (2) */
    phc_colour_correction_method colour_correction; /* of every photo (PHC_CC_NONE) */
    int register_photos;     /* pixels: align each photo to the fresh leaf's (1) */
    phc_leaf_setup_options setup; /* model grid (model_size 16..4096 px, 128), matching
                                space, dt (> 0, 0.1), vein_floor (0..1, 0.05) and the
                                venation, stomata and inflow maps (fit/costs/leaf_setup.h);
                                its *_where fields are filled from `origin` when NULL */
    int cross_validate;      /* leave-one-out prediction of each row's stage in the
                                report (0) */
    const char *x_label;     /* NULL: the stage name */
    const char *y_label;     /* NULL: names the residual ("CIELAB cell mean (L*, a*, b*)") */
    phc_is_parameter_fn is_parameter; /* which of the six slots are parameters; NULL:
                                         all six */
    void *user_data;                  /* passed to is_parameter */
    /* Where the rows and options came from, for messages (NULL: the messages
     * name the kind and rows[i]): */
    const char *rows_source;  /* the table the rows were read from ("leaves.csv"): a row's
                                 messages then start "leaves.csv:LINE" */
    const char *image_column; /* the table's columns named in those messages */
    const char *leaf_column;
    const phc_origin *origin; /* the data set's config mapping (fit/costs/origin.h) */
    const phc_origin *reference_origin; /* the `reference: {image, leaf}` mapping */
} phc_leaf_photos_options;

/* The defaults above: pixels, de76, grid 24, 16 quantiles, sigma 2, no
 * colour correction, registration on, phc_leaf_setup_options_default(),
 * direction +1, no reference (one must be given). */
phc_leaf_photos_options phc_leaf_photos_options_default(void);

/* Builds a leaf_photos data set over rows[0..n_rows-1] (at least two: the
 * fresh leaf and one more; copied, so rows and images may be freed
 * afterwards).  Reads each photo file once (rows may share one), colour
 * corrects and segments it, cuts each row's leaf out, builds the model
 * (fit/costs/leaf_setup.h) and the observations.  Slot names are the
 * slots is_parameter accepts (in the order beta_scale, stomata_scale,
 * inflow_scale, time_scale, y_lo, y_hi); parameter indices are left to
 * phc_problem binding.  The files read are not recorded as inputs
 * (phc_dataset_add_input): the caller knows them.  Errors name the option
 * (the config line with options.origin), the row (its table line with
 * options.rows_source) or the photo, and say what was expected. */
int phc_leaf_photos_new(const phc_leaf_photos_row *rows, size_t n_rows, const phc_leaf_photos_options *options,
                        phc_dataset **out, phc_error *err);

/* The operations of leaf_photos data sets (ops->kind is "leaf_photos"). */
extern const phc_dataset_ops phc_leaf_photos_ops;

/* Leave-one-out prediction of each row's stage (see above), at the fitted
 * slot values p, whether or not options.cross_validate asked for it: the
 * engine's phc_cross_validate_plan (fit/engine/cross_validation.h) on the data
 * set's plan, with the free slots, their bounds and the solver options of
 * the data set's problem (ds->problem; progress through ds->progress).
 * Fills n_rows values each (NAN for the initial and reference rows):
 * observed stage, model prediction, baseline prediction; rmse[0] model,
 * rmse[1] baseline, over the predicted rows.  Arrays are malloc'd.  The
 * report gets the same numbers from phc_fit_run. */
int phc_leaf_photos_cross_validate(phc_dataset *ds, const double *p, size_t *n_rows, char ***ids,
                                   double **stage, double **model, double **baseline, double rmse[2],
                                   phc_error *err);

#endif /* PHC_COSTS_LEAF_PHOTOS_H */
