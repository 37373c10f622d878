/* The diagnostic plots of a fit: see fit_plots.h. */
#include "fit/fit_plots.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/plots.h"
#include "fit/run_dir.h"

static int add_name(char **names, size_t *n, size_t max, const char *name)
{
    if (*n + 1 >= max)
        return PHC_OK;
    names[*n] = strdup(name);
    if (!names[*n])
        return PHC_ERR_NOMEM;
    (*n)++;
    return PHC_OK;
}

int phc_fit_plots_write(const phc_fit_result *res, const char *dir, char **names, size_t *n_names,
                        size_t max_names, phc_error *err)
{
    char path[8192], file[512], title[512], label[512];
    int rc;
    for (size_t d = 0; d < res->n_datasets; ++d) {
        const phc_dataset_result *ds = &res->datasets[d];
        char base[256];
        phc_run_dir_safe_name(ds->name, base, sizeof base);
        /* several series (probes, leaves, ...): one colour each and a key */
        const phc_plot_groups groups = {ds->n_series, ds->series, (const char *const *)ds->series_names,
                                        ds->series_title};
        const phc_plot_groups *grp = ds->series && ds->n_series > 1 ? &groups : NULL;
        /* the report links plots by data-set name; keep names consistent */
        snprintf(title, sizeof title, "%s: data and fit", ds->name);
        phc_plot_labels lab = {title, ds->x_label, ds->y_label, "fit"};
        snprintf(file, sizeof file, "%s_fit.png", base);
        snprintf(path, sizeof path, "%s/%s", dir, file);
        /* no dense curve for every observation: the predictions, connected
           in x order within each series */
        if ((rc = phc_plot_fit_groups(path, &lab, ds->x, ds->y, ds->sigma, ds->n, grp, ds->yhat, ds->curve_x,
                                      ds->curve_y, ds->curve_x ? ds->curve_n : 0, err)) ||
            (rc = add_name(names, n_names, max_names, file)))
            return rc;

        double s = 0;
        for (size_t i = 0; i < ds->n; ++i)
            s += ds->residual[i] * ds->residual[i];
        s = ds->n > ds->k ? sqrt(s / (double)(ds->n - ds->k)) : NAN;
        snprintf(title, sizeof title, "%s: residuals", ds->name);
        snprintf(label, sizeof label, "residual: %s", ds->y_label);
        phc_plot_labels rl = {title, ds->x_label, label, NULL};
        snprintf(file, sizeof file, "%s_residuals.png", base);
        snprintf(path, sizeof path, "%s/%s", dir, file);
        if ((rc = phc_plot_residuals_groups(path, &rl, ds->x, ds->residual, ds->n, s, grp, err)) ||
            (rc = add_name(names, n_names, max_names, file)))
            return rc;

        snprintf(title, sizeof title, "%s: normal QQ plot of residuals", ds->name);
        phc_plot_labels ql = {title, NULL, NULL, NULL};
        snprintf(file, sizeof file, "%s_qq.png", base);
        snprintf(path, sizeof path, "%s/%s", dir, file);
        if ((rc = phc_plot_qq(path, &ql, ds->std_residual, ds->n, err)) ||
            (rc = add_name(names, n_names, max_names, file)))
            return rc;

        if (ds->acf_time && ds->acf_time_bins > 1) {
            /* a time series over >= 1.5 days: correlation over time lags in hours */
            snprintf(title, sizeof title, "%s: residual autocorrelation over time lags", ds->name);
            phc_plot_labels al = {title, "lag (h)", "autocorrelation", NULL};
            snprintf(file, sizeof file, "%s_acf.png", base);
            snprintf(path, sizeof path, "%s/%s", dir, file);
            if ((rc = phc_plot_acf_time(path, &al, ds->acf_time, ds->acf_time_bins, ds->acf_time_bin_h, ds->n,
                                        err)) ||
                (rc = add_name(names, n_names, max_names, file)))
                return rc;
        } else if (ds->acf_lags > 0) {
            snprintf(title, sizeof title, "%s: residual autocorrelation (ordered by x)", ds->name);
            phc_plot_labels al = {title, "lag (observations)", "autocorrelation", NULL};
            snprintf(file, sizeof file, "%s_acf.png", base);
            snprintf(path, sizeof path, "%s/%s", dir, file);
            if ((rc = phc_plot_acf(path, &al, ds->acf, ds->acf_lags, ds->n, err)) ||
                (rc = add_name(names, n_names, max_names, file)))
                return rc;
        }
        if (ds->time_of_day) {
            snprintf(title, sizeof title, "%s: residuals by time of day", ds->name);
            phc_plot_labels tl = {title, "local clock time (h)", "standardised residual", NULL};
            snprintf(file, sizeof file, "%s_time_of_day.png", base);
            snprintf(path, sizeof path, "%s/%s", dir, file);
            if ((rc = phc_plot_time_of_day(path, &tl, ds->time_of_day, ds->std_residual, ds->n, err)) ||
                (rc = add_name(names, n_names, max_names, file)))
                return rc;
        }
    }
    return PHC_OK;
}
