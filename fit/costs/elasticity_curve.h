/* `elasticity_curve` data sets: the logistic elasticity of the wilting paper
 * (eq. 9, model/elasticity.h) fitted to bulk moduli measured against water
 * content:  E(θ) = e_min + e_max · σ(kappa · (θ − chi0)).
 *
 * Config keys (besides the common data-set keys of fit/config.h):
 *   file:          CSV file, relative to the config file
 *   water:         column of water contents θ
 *   water_content: rwc | absolute — what the water column holds: relative
 *                  water content as a fraction (0..1; values above 1.5 are
 *                  refused as probably percent) or absolute water (any unit,
 *                  ≥ 0; chi0 then has that unit and kappa its inverse)
 *   modulus:       column of bulk moduli, MPa
 *   sigma:         a positive number (MPa) or a column of per-point sigmas;
 *                  absent = unweighted
 *   x_label, y_label: axis labels (defaults name the quantity and unit)
 *
 * Parameter slots: kappa, chi0, e_min, e_max, bound by default to the global
 * parameters of the same names.  Derivatives are analytic.
 *
 * The pressure–volume kind (pv_curve.h) builds its data sets with the same
 * model through phc_elasticity_dataset_new below. */
#ifndef PHC_COSTS_ELASTICITY_CURVE_H
#define PHC_COSTS_ELASTICITY_CURVE_H

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"

extern const char *const phc_elasticity_curve_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_elasticity_curve_help[];

int phc_elasticity_curve_load(const phc_yaml_doc *doc, const phc_yaml_node *node,
                              const char *base_dir, phc_is_parameter_fn is_parameter,
                              void *user_data, phc_dataset **out, phc_error *err);

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
 * not NULL, kappa_<suffix[b]> ... for block b.  ops must use
 * phc_elasticity_predict and phc_elasticity_predict_at and a free_impl that
 * calls phc_elasticity_impl_free. */
int phc_elasticity_dataset_new(const phc_dataset_ops *ops, size_t n, size_t n_blocks,
                               const char *const *suffixes, phc_dataset **out, phc_error *err);
int phc_elasticity_predict(phc_dataset *ds, const double *p, double *yhat, double *jac);
int phc_elasticity_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m,
                              double *y);
void phc_elasticity_impl_free(void *impl);

#endif /* PHC_COSTS_ELASTICITY_CURVE_H */
