/* fit/engine/ceres_module_internal.h: the table of the Ceres module,
 * phytocal_ceres.so (Ceres Solver with SuiteSparse, glog, gflags:
 * fit/engine/ceres_bridge.cc; see measurements/module_internal.h).
 * libphytocal's ceres_bridge.h functions forward to it
 * (fit/engine/ceres_module.c), so that a command that fits nothing
 * (version, help, report) never loads Ceres.  C and C++; internal. */
#ifndef PHC_CERES_MODULE_INTERNAL_H
#define PHC_CERES_MODULE_INTERNAL_H

#include "fit/engine/ceres_bridge.h"

/* Bumped whenever a member below changes. */
#define PHC_CERES_MODULE_ABI 1
#define PHC_CERES_MODULE_ENTRY "phc_ceres_module_entry"
#define PHC_CERES_MODULE_FILE "phytocal_ceres.so"

/* One member per ceres_bridge.h function that needs Ceres, same signature. */
typedef struct phc_ceres_module_table {
    phc_nls *(*nls_new)(size_t n_params);
    void (*nls_free)(phc_nls *nls);
    int (*set_parameter)(phc_nls *nls, size_t index, double lower, double upper, int fixed, double scale,
                         phc_error *err);
    int (*add_block)(phc_nls *nls, size_t m, const size_t *param_index, size_t k, phc_residual_fn fn,
                     phc_derivatives derivs, phc_loss_kind loss, double loss_scale, void *user_data,
                     phc_error *err);
    size_t (*residual_count)(const phc_nls *nls);
    int (*solve)(phc_nls *nls, const phc_nls_options *options, double *x, phc_nls_summary *summary,
                 phc_error *err);
    int (*evaluate)(phc_nls *nls, const double *x, double *residuals, double *jacobian, double *cost,
                    phc_error *err);
} phc_ceres_module_table;

#endif
