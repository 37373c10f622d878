/* Run directories: see run_dir.h. */
#define _XOPEN_SOURCE 700 /* nftw */
#include "fit/run_dir.h"

#include <errno.h>
#include <ftw.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fit/plots.h"
#include "fit/report.h"
#include "fit/result_json.h"

#define MAX_PLOTS 512

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb;
    (void)flag;
    (void)ftw;
    return remove(path);
}

static void remove_tree(const char *path)
{
    nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

int phc_run_dir_check(const char *dir, int force, phc_error *err)
{
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (!S_ISDIR(st.st_mode))
            return phc_error_set(err, PHC_ERR_EXISTS, "%s: exists and is not a directory", dir);
        if (!force)
            return phc_error_set(err, PHC_ERR_EXISTS,
                                 "%s: output directory exists; use --force to replace it or -o to choose another", dir);
    }
    /* The nearest existing ancestor must be a writable directory, so that a
     * long fit is not wasted on an output path that cannot be created. */
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", dir);
    for (;;) {
        char *slash = strrchr(buf, '/');
        if (!slash) {
            snprintf(buf, sizeof buf, ".");
        } else if (slash == buf) {
            buf[1] = '\0';
        } else {
            *slash = '\0';
        }
        if (stat(buf, &st) == 0) {
            if (!S_ISDIR(st.st_mode))
                return phc_error_set(err, PHC_ERR_IO, "%s: cannot create the output directory: '%s' is not a directory",
                                     dir, buf);
            if (access(buf, W_OK | X_OK) != 0)
                return phc_error_set(err, PHC_ERR_IO, "%s: cannot create the output directory: '%s' is not writable",
                                     dir, buf);
            return PHC_OK;
        }
        if (strcmp(buf, ".") == 0 || strcmp(buf, "/") == 0)
            return PHC_OK;
    }
}

/* mkdir -p for the parent of dir. */
static int make_parents(const char *dir, phc_error *err)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", dir);
    for (char *p = buf + 1; *p; ++p) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return phc_error_set(err, PHC_ERR_IO, "%s: cannot create directory: %s", buf, strerror(errno));
        *p = '/';
    }
    return PHC_OK;
}

static int add_plot(char **names, size_t *n, const char *name)
{
    if (*n + 1 >= MAX_PLOTS)
        return PHC_OK;
    names[*n] = strdup(name);
    if (!names[*n])
        return PHC_ERR_NOMEM;
    (*n)++;
    return PHC_OK;
}

void phc_run_dir_safe_name(const char *in, char *out, size_t size)
{
    size_t j = 0;
    for (size_t i = 0; in[i] && j + 1 < size; ++i) {
        const char c = in[i];
        out[j++] = ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                    c == '_' || c == '.')
                       ? c
                       : '_';
    }
    out[j] = '\0';
}

static int write_plots(const phc_fit_result *res, const char *tmpdir, char **names, size_t *n_names,
                       phc_error *err)
{
    char path[8192], file[512], title[512], label[512];
    int rc;
    for (size_t d = 0; d < res->n_datasets; ++d) {
        const phc_dataset_result *ds = &res->datasets[d];
        char base[256];
        phc_run_dir_safe_name(ds->name, base, sizeof base);
        /* the report links plots by data-set name; keep names consistent */
        snprintf(title, sizeof title, "%s: data and fit", ds->name);
        phc_plot_labels lab = {title, ds->x_label, ds->y_label};
        snprintf(file, sizeof file, "%s_fit.png", base);
        snprintf(path, sizeof path, "%s/%s", tmpdir, file);
        const double *cx = ds->curve_x, *cy = ds->curve_y;
        size_t cn = ds->curve_n;
        double *sx = NULL, *sy = NULL;
        if (!cx) {
            /* no dense curve: connect the predictions in x order */
            sx = malloc(ds->n * sizeof *sx);
            sy = malloc(ds->n * sizeof *sy);
            if (!sx || !sy) {
                free(sx);
                free(sy);
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            }
            for (size_t i = 0; i < ds->n; ++i) {
                sx[i] = ds->x[i];
                sy[i] = ds->yhat[i];
            }
            for (size_t i = 1; i < ds->n; ++i) /* insertion sort: plots are small */
                for (size_t j = i; j > 0 && sx[j - 1] > sx[j]; --j) {
                    double t = sx[j];
                    sx[j] = sx[j - 1];
                    sx[j - 1] = t;
                    t = sy[j];
                    sy[j] = sy[j - 1];
                    sy[j - 1] = t;
                }
            cx = sx;
            cy = sy;
            cn = ds->n;
        }
        rc = phc_plot_fit(path, &lab, ds->x, ds->y, ds->sigma, ds->n, cx, cy, cn, err);
        free(sx);
        free(sy);
        if (rc || (rc = add_plot(names, n_names, file)))
            return rc;

        double s = 0;
        for (size_t i = 0; i < ds->n; ++i)
            s += ds->residual[i] * ds->residual[i];
        s = ds->n > ds->k ? sqrt(s / (double)(ds->n - ds->k)) : NAN;
        snprintf(title, sizeof title, "%s: residuals", ds->name);
        snprintf(label, sizeof label, "residual: %s", ds->y_label);
        phc_plot_labels rl = {title, ds->x_label, label};
        snprintf(file, sizeof file, "%s_residuals.png", base);
        snprintf(path, sizeof path, "%s/%s", tmpdir, file);
        if ((rc = phc_plot_residuals(path, &rl, ds->x, ds->residual, ds->n, s, err)) ||
            (rc = add_plot(names, n_names, file)))
            return rc;

        snprintf(title, sizeof title, "%s: normal QQ plot of residuals", ds->name);
        phc_plot_labels ql = {title, NULL, NULL};
        snprintf(file, sizeof file, "%s_qq.png", base);
        snprintf(path, sizeof path, "%s/%s", tmpdir, file);
        if ((rc = phc_plot_qq(path, &ql, ds->std_residual, ds->n, err)) || (rc = add_plot(names, n_names, file)))
            return rc;

        if (ds->acf_lags > 0) {
            snprintf(title, sizeof title, "%s: residual autocorrelation (ordered by x)", ds->name);
            phc_plot_labels al = {title, "lag (observations)", "autocorrelation"};
            snprintf(file, sizeof file, "%s_acf.png", base);
            snprintf(path, sizeof path, "%s/%s", tmpdir, file);
            if ((rc = phc_plot_acf(path, &al, ds->acf, ds->acf_lags, ds->n, err)) ||
                (rc = add_plot(names, n_names, file)))
                return rc;
        }
    }
    return PHC_OK;
}

int phc_run_dir_begin(const char *dir, int force, char *tmpdir, size_t size, phc_error *err)
{
    int rc;
    if ((rc = phc_run_dir_check(dir, force, err)) || (rc = make_parents(dir, err)))
        return rc;
    if ((size_t)snprintf(tmpdir, size, "%s.tmp-XXXXXX", dir) >= size)
        return phc_error_set(err, PHC_ERR_IO, "%s: output path too long", dir);
    if (!mkdtemp(tmpdir))
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot create a temporary directory: %s", tmpdir, strerror(errno));
    return PHC_OK;
}

void phc_run_dir_discard(const char *tmpdir)
{
    remove_tree(tmpdir);
}

int phc_run_dir_commit(const char *tmpdir, const char *dir, phc_error *err)
{
    /* Swap into place: the old run (with --force) is removed only now. */
    char old[4096];
    struct stat st;
    old[0] = '\0';
    if (stat(dir, &st) == 0) {
        snprintf(old, sizeof old, "%s.old-XXXXXX", dir);
        if (!mkdtemp(old) || rmdir(old) != 0 || rename(dir, old) != 0) {
            const int rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot move the earlier run aside: %s", dir,
                                         strerror(errno));
            remove_tree(tmpdir);
            return rc;
        }
    }
    if (rename(tmpdir, dir) != 0) {
        const int rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot rename the new run into place: %s", dir,
                                     strerror(errno));
        if (old[0])
            rename(old, dir); /* put the earlier run back */
        remove_tree(tmpdir);
        return rc;
    }
    if (old[0])
        remove_tree(old);
    chmod(dir, 0755); /* mkdtemp made it private; results are for sharing */
    return PHC_OK;
}

/* The kinds' own files at the fitted values (dataset.h, fit_outputs). */
static int write_kind_outputs(const phc_fit_result *res, const phc_problem *pb, const char *tmpdir,
                              phc_error *err)
{
    for (size_t d = 0; pb && d < pb->n_datasets; ++d) {
        phc_dataset *ds = pb->datasets[d];
        if (!ds->ops->fit_outputs)
            continue;
        double *p = malloc((ds->k ? ds->k : 1) * sizeof *p);
        if (!p)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t j = 0; j < ds->k; ++j)
            p[j] = res->params[ds->param_index[j]].value;
        char base[256];
        phc_run_dir_safe_name(ds->name, base, sizeof base);
        const int rc = ds->ops->fit_outputs(ds, p, tmpdir, base, err);
        free(p);
        if (rc)
            return rc;
    }
    return PHC_OK;
}

int phc_run_dir_write(const phc_fit_result *res, const phc_problem *pb, const char *dir, int force,
                      phc_error *err)
{
    char tmpdir[4096], path[8192];
    int rc;
    if ((rc = phc_run_dir_begin(dir, force, tmpdir, sizeof tmpdir, err)))
        return rc;
    char *names[MAX_PLOTS] = {0};
    size_t n_names = 0;
    if ((rc = write_plots(res, tmpdir, names, &n_names, err)) ||
        (rc = write_kind_outputs(res, pb, tmpdir, err)))
        goto fail;
    snprintf(path, sizeof path, "%s/result.json", tmpdir);
    if ((rc = phc_result_write_json(res, path, err)))
        goto fail;
    snprintf(path, sizeof path, "%s/report.md", tmpdir);
    if ((rc = phc_report_write_markdown(res, path, (const char *const *)names, err)))
        goto fail;
    rc = phc_run_dir_commit(tmpdir, dir, err);
    for (size_t i = 0; i < n_names; ++i)
        free(names[i]);
    return rc;
fail:
    phc_run_dir_discard(tmpdir);
    for (size_t i = 0; i < n_names; ++i)
        free(names[i]);
    return rc;
}
