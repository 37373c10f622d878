/* Data sets: see dataset.h. */
#include "fit/dataset.h"

#include <stdlib.h>

phc_dataset *phc_dataset_new(const phc_dataset_ops *ops, size_t k)
{
    phc_dataset *ds = calloc(1, sizeof *ds);
    if (!ds)
        return NULL;
    ds->ops = ops;
    ds->k = k;
    ds->derivatives = PHC_DERIV_CENTRAL;
    ds->loss = PHC_LOSS_NONE;
    ds->loss_scale = 1.0;
    if (k > 0) {
        ds->slot_names = calloc(k, sizeof *ds->slot_names);
        ds->param_index = calloc(k, sizeof *ds->param_index);
        if (!ds->slot_names || !ds->param_index) {
            phc_dataset_free(ds);
            return NULL;
        }
    }
    return ds;
}

void phc_dataset_free(phc_dataset *ds)
{
    if (!ds)
        return;
    if (ds->ops && ds->ops->free_impl)
        ds->ops->free_impl(ds->impl);
    if (ds->slot_names)
        for (size_t j = 0; j < ds->k; ++j)
            free(ds->slot_names[j]);
    free(ds->slot_names);
    free(ds->param_index);
    free(ds->name);
    free(ds->x);
    free(ds->y);
    free(ds->sigma);
    free(ds->x_label);
    free(ds->y_label);
    free(ds);
}

int phc_dataset_residuals(const double *p, double *r, double *jac, void *user_data)
{
    phc_dataset *ds = user_data;
    /* r holds yhat first, then is turned into residuals in place. */
    int rc = ds->ops->predict(ds, p, r, jac);
    if (rc)
        return rc;
    for (size_t i = 0; i < ds->n; ++i) {
        const double w = ds->sigma ? 1.0 / ds->sigma[i] : 1.0;
        r[i] = (ds->y[i] - r[i]) * w;
        if (jac)
            for (size_t j = 0; j < ds->k; ++j)
                jac[i * ds->k + j] *= -w;
    }
    return 0;
}
