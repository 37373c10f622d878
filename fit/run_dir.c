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

#include "fit/fit_plots.h"
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
    if ((rc = phc_fit_plots_write(res, tmpdir, names, &n_names, MAX_PLOTS, err)) ||
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
