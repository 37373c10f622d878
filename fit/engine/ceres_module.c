/* fit/engine/ceres_bridge.h in libphytocal: the option defaults and the
 * version (compiled in: Ceres's version.h is macros only), and the rest
 * forwarded to the Ceres module phytocal_ceres.so (fit/engine/ceres_bridge.cc
 * with Ceres, SuiteSparse, glog), opened by the first phc_nls_new
 * (measurements/module_internal.h).  A problem exists only once the module
 * is loaded, so the functions that take one use the loaded table. */
#include "fit/engine/ceres_bridge.h"

#include <ceres/version.h>

#include "fit/engine/ceres_module_internal.h"
#include "measurements/module_internal.h"

static phc_module ceres_module = {PHC_CERES_MODULE_FILE, PHC_CERES_MODULE_ENTRY, PHC_CERES_MODULE_ABI,
                                  "Ceres Solver", NULL, 0};

static const phc_ceres_module_table *loaded(void)
{
    return phc_module_loaded(&ceres_module);
}

phc_nls_options phc_nls_options_default(void)
{
    phc_nls_options o;
    o.max_iterations = 1000;
    o.function_tolerance = 1e-15;
    o.gradient_tolerance = 1e-15;
    o.parameter_tolerance = 1e-15;
    o.method = PHC_LEVENBERG_MARQUARDT;
    o.num_threads = 1;
    o.on_iteration = NULL;
    o.on_iteration_data = NULL;
    return o;
}

const char *phc_nls_version(void)
{
    return CERES_VERSION_STRING;
}

phc_nls *phc_nls_new(size_t n_params)
{
    const phc_ceres_module_table *t = phc_module_table(&ceres_module, NULL);
    return t ? t->nls_new(n_params) : NULL;
}

int phc_nls_new_error(const char *what, phc_error *err)
{
    phc_error load;
    if (!phc_module_table(&ceres_module, &load))
        return phc_error_set(err, load.status, "%s", load.message);
    return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", what ? what : "least squares");
}

void phc_nls_free(phc_nls *nls)
{
    if (nls)
        loaded()->nls_free(nls);
}

int phc_nls_set_parameter(phc_nls *nls, size_t index, double lower, double upper, int fixed, double scale,
                          phc_error *err)
{
    const phc_ceres_module_table *t = loaded();
    if (!t) /* no problem was made, so this one is not valid */
        return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_set_parameter: no problem");
    return t->set_parameter(nls, index, lower, upper, fixed, scale, err);
}

int phc_nls_add_block(phc_nls *nls, size_t m, const size_t *param_index, size_t k, phc_residual_fn fn,
                      phc_derivatives derivs, phc_loss_kind loss, double loss_scale, void *user_data,
                      phc_error *err)
{
    const phc_ceres_module_table *t = loaded();
    if (!t) /* no problem was made, so this one is not valid */
        return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_add_block: no problem");
    return t->add_block(nls, m, param_index, k, fn, derivs, loss, loss_scale, user_data, err);
}

size_t phc_nls_residual_count(const phc_nls *nls)
{
    const phc_ceres_module_table *t = loaded();
    return t ? t->residual_count(nls) : 0;
}

int phc_nls_solve(phc_nls *nls, const phc_nls_options *options, double *x, phc_nls_summary *summary,
                  phc_error *err)
{
    const phc_ceres_module_table *t = loaded();
    if (!t) /* no problem was made, so this one is not valid */
        return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_solve: no problem");
    return t->solve(nls, options, x, summary, err);
}

int phc_nls_evaluate(phc_nls *nls, const double *x, double *residuals, double *jacobian, double *cost,
                     phc_error *err)
{
    const phc_ceres_module_table *t = loaded();
    if (!t) /* no problem was made, so this one is not valid */
        return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_evaluate: no problem");
    return t->evaluate(nls, x, residuals, jacobian, cost, err);
}
