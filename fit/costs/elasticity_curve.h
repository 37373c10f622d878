/* `elasticity_curve` data sets: the logistic elasticity of the wilting paper
 * (eq. 9, model/elasticity.h) fitted to bulk moduli measured against water
 * content:  E(θ) = e_min + e_max · σ(kappa · (θ − chi0)).
 *
 * Built in C with phc_elasticity_curve_new from a table (measurements/
 * table.h: read from a CSV file, or phc_table_from_columns for arrays) and
 * options; the config's `kind: elasticity_curve` mapping is translated into
 * the same options by fit/config/elasticity_curve_yaml.c.
 *
 * Parameter slots: kappa, chi0, e_min, e_max, bound by default to the global
 * parameters of the same names; e_min and e_max are in MPa, kappa and chi0
 * dimensionless ("1") on relative water content (declared units: a
 * parameter's `unit:` such as kPa is converted).  Derivatives are analytic.
 *
 * The pressure–volume kind (pv_curve.h) builds its data sets with the same
 * model through phc_elasticity_dataset_new below. */
#ifndef PHC_COSTS_ELASTICITY_CURVE_H
#define PHC_COSTS_ELASTICITY_CURVE_H

#include "fit/costs/origin.h"
#include "fit/engine/dataset.h"
#include "measurements/table.h"
#include "model/status.h"

/* What the water column holds. */
typedef enum phc_water_content {
    PHC_WATER_CONTENT_UNSET = 0, /* not given: an error (the two read very differently) */
    PHC_WATER_CONTENT_RWC,       /* relative water content, a fraction 0..1 (values
                                    above 1.5 are refused as probably percent) */
    PHC_WATER_CONTENT_ABSOLUTE   /* absolute water in any unit, >= 0; chi0 then has
                                    that unit and kappa its inverse */
} phc_water_content;

typedef struct phc_elasticity_curve_options {
    const char *water;               /* column of water contents θ (required) */
    phc_water_content water_content; /* what that column holds (required) */
    const char *modulus;             /* column of bulk moduli, MPa (required) */
    double sigma;                    /* > 0: one standard deviation for every point, MPa */
    const char *sigma_column;        /* or a column of per-point standard deviations, MPa;
                                        neither = unweighted */
    const char *x_label;             /* NULL: "relative water content (RWC)" or
                                        "water content (<water>)" */
    const char *y_label;             /* NULL: "bulk modulus of elasticity (MPa)" */
    const phc_origin *origin;        /* where the options came from, for messages; NULL */
} phc_elasticity_curve_options;

/* Everything unset: water_content PHC_WATER_CONTENT_UNSET, no sigma, no
 * labels, no origin. */
phc_elasticity_curve_options phc_elasticity_curve_options_default(void);

/* Builds an elasticity_curve data set over the rows of `table` (copied; the
 * table may be freed afterwards): x the water contents, y the moduli, slots
 * kappa, chi0, e_min, e_max; parameter indices are left to phc_problem
 * binding (phc_problem_bind_by_name).  Errors name the option (and the
 * config line when options.origin is set), or the table's source, line and
 * column: PHC_ERR_INPUT for a missing option, an unknown column, a value that
 * is not a number, a relative water content outside [0, 1.5], a negative
 * absolute water content or a sigma that is not positive. */
int phc_elasticity_curve_new(const phc_table *table, const phc_elasticity_curve_options *options,
                             phc_dataset **out, phc_error *err);

/* The operations of elasticity_curve data sets (ops->kind is
 * "elasticity_curve"). */
extern const phc_dataset_ops phc_elasticity_curve_ops;

/* Shared with pv_curve: the implementation behind a logistic-elasticity data
 * set.  Observations belong to blocks of 4 slots (kappa, chi0, e_min, e_max
 * of one leaf); block[i] says which. */
typedef struct phc_elasticity_impl {
    size_t n_blocks;
    size_t *block;               /* [n] slot block of each observation */
    void *extra;                 /* kind-specific data (pv_curve: PV results) */
    void (*free_extra)(void *extra);
} phc_elasticity_impl;

/* A data set with n observations (x, y, data_lines allocated, to be filled)
 * and 4·n_blocks slots named kappa, chi0, e_min, e_max — or, when suffixes is
 * not NULL, kappa_<suffix[b]> ... for block b.  The slots declare their
 * units (model/elasticity.h): e_min, e_max MPa; with rwc nonzero (θ a
 * relative water content) kappa and chi0 are dimensionless, "1"; otherwise
 * they follow the water column's unit and declare none.  ops must use
 * phc_elasticity_predict and phc_elasticity_predict_at and a free_impl that
 * calls phc_elasticity_impl_free. */
int phc_elasticity_dataset_new(const phc_dataset_ops *ops, size_t n, size_t n_blocks,
                               const char *const *suffixes, int rwc, phc_dataset **out, phc_error *err);
int phc_elasticity_predict(phc_dataset *ds, const double *p, double *yhat, double *jac);
int phc_elasticity_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m,
                              double *y);
void phc_elasticity_impl_free(void *impl);

#endif /* PHC_COSTS_ELASTICITY_CURVE_H */
