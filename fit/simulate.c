/* Simulation at the start values: see simulate.h. */
#include "fit/simulate.h"

#include <stdio.h>
#include <stdlib.h>

#include "fit/plots.h"
#include "fit/run_dir.h"
#include "measurements/atomic_file.h"

static int simulate_dataset(const phc_problem *pb, phc_dataset *ds, const char *tmpdir, phc_error *err)
{
    double *x = calloc(pb->n_params ? pb->n_params : 1, sizeof *x);
    double *p = calloc(ds->k ? ds->k : 1, sizeof *p), *yhat = calloc(ds->n ? ds->n : 1, sizeof *yhat);
    char base[256], path[8192], title[512];
    int rc = PHC_OK;
    if (!x || !p || !yhat) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < pb->n_params; ++i)
        x[i] = pb->params[i].value;
    /* names the data file and line of the first non-finite prediction */
    if ((rc = phc_dataset_check_start(ds, x, err)))
        goto done;
    for (size_t j = 0; j < ds->k; ++j)
        p[j] = x[ds->param_index[j]];
    if (ds->ops->predict(ds, p, yhat, NULL) != 0) {
        rc = phc_error_set(err, PHC_ERR_DOMAIN, "data set '%s': the model cannot be evaluated at the start values",
                           ds->name);
        goto done;
    }
    phc_run_dir_safe_name(ds->name, base, sizeof base);
    snprintf(path, sizeof path, "%s/%s_simulated.csv", tmpdir, base);
    phc_atomic_file *af = NULL;
    if ((rc = phc_atomic_file_open(path, &af, err)))
        goto done;
    FILE *f = phc_atomic_file_stream(af);
    fprintf(f, "x,observed,model\n");
    for (size_t i = 0; i < ds->n; ++i)
        fprintf(f, "%.17g,%.17g,%.17g\n", ds->x[i], ds->y[i], yhat[i]);
    if ((rc = phc_atomic_file_commit(af, err)))
        goto done;
    snprintf(title, sizeof title, "%s: model at the start values", ds->name);
    phc_plot_labels lab = {title, ds->x_label, ds->y_label, "model at start values"};
    snprintf(path, sizeof path, "%s/%s_simulated.png", tmpdir, base);
    /* the model through the observations in x order, one line (and colour)
       per series when the observations form several (probes, leaves, ...) */
    const phc_plot_groups groups = {ds->n_series, ds->series, (const char *const *)ds->series_names,
                                    ds->series_title};
    if ((rc = phc_plot_fit_groups(path, &lab, ds->x, ds->y, ds->sigma, ds->n,
                                  ds->series && ds->n_series > 1 ? &groups : NULL, yhat, NULL, NULL, 0, err)))
        goto done;
    if (ds->ops->simulate_outputs)
        rc = ds->ops->simulate_outputs(ds, p, tmpdir, base, err);
done:
    free(x);
    free(p);
    free(yhat);
    return rc;
}

int phc_simulate_write(const phc_problem *pb, const phc_provenance *pv, const char *dir, int force,
                       phc_error *err)
{
    char tmpdir[4096];
    int rc;
    if ((rc = phc_run_dir_begin(dir, force, pb, tmpdir, sizeof tmpdir, err)))
        return rc;
    for (size_t d = 0; d < pb->n_datasets; ++d)
        if ((rc = simulate_dataset(pb, pb->datasets[d], tmpdir, err))) {
            phc_run_dir_discard(tmpdir);
            return rc;
        }
    return phc_run_dir_commit(tmpdir, dir, pv, err);
}
