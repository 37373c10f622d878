/* Run directories: see run_dir.h. */
#define _GNU_SOURCE /* realpath, syncfs */
#include "fit/run_dir.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fit/fit_plots.h"
#include "fit/report.h"
#include "fit/result_json.h"
#include "measurements/atomic_file.h"

#define MAX_PLOTS 512

#define MANIFEST_VERSION 1

/* ---- walking a directory ------------------------------------------------------------ */

/* Calls visit(rel, is_dir, ctx) for every entry below root (rel is the path
 * relative to root), parents before children; symbolic links are reported as
 * files and not followed.  Stops at the first non-zero return. */
typedef int (*visit_fn)(const char *rel, int is_dir, void *ctx);

static int walk(const char *root, const char *rel, visit_fn visit, void *ctx)
{
    char path[8192];
    snprintf(path, sizeof path, "%s%s%s", root, rel[0] ? "/" : "", rel);
    DIR *d = opendir(path);
    if (!d)
        return -1;
    int rc = 0;
    struct dirent *e;
    while (!rc && (e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        char sub[4096], full[8192];
        if ((size_t)snprintf(sub, sizeof sub, "%s%s%s", rel, rel[0] ? "/" : "", e->d_name) >= sizeof sub)
            continue; /* deeper than any path phytocal writes */
        snprintf(full, sizeof full, "%s/%s", root, sub);
        struct stat st;
        const int is_dir = lstat(full, &st) == 0 && S_ISDIR(st.st_mode);
        rc = visit(sub, is_dir, ctx);
        if (!rc && is_dir)
            rc = walk(root, sub, visit, ctx);
    }
    closedir(d);
    return rc;
}

/* Removes a directory that phytocal created itself (a temporary one). */
static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        char full[8192];
        snprintf(full, sizeof full, "%s/%s", path, e->d_name);
        struct stat st;
        if (lstat(full, &st) == 0 && S_ISDIR(st.st_mode))
            remove_tree(full);
        else
            unlink(full);
    }
    closedir(d);
    rmdir(path);
}

/* ---- the manifest ------------------------------------------------------------------- */

/* The entries a manifest lists: relative paths, directories flagged. */
typedef struct entry_list {
    char **paths;
    int *is_dir;
    size_t n, cap;
} entry_list;

static void entries_free(entry_list *l)
{
    for (size_t i = 0; i < l->n; ++i)
        free(l->paths[i]);
    free(l->paths);
    free(l->is_dir);
    memset(l, 0, sizeof *l);
}

static int entries_add(const char *rel, int is_dir, void *ctx)
{
    entry_list *l = ctx;
    if (l->n == l->cap) {
        const size_t cap = l->cap ? 2 * l->cap : 32;
        char **p = realloc(l->paths, cap * sizeof *p);
        if (p)
            l->paths = p;
        int *d = realloc(l->is_dir, cap * sizeof *d);
        if (d)
            l->is_dir = d;
        if (!p || !d)
            return -1;
        l->cap = cap;
    }
    if (!(l->paths[l->n] = strdup(rel)))
        return -1;
    l->is_dir[l->n++] = is_dir;
    return 0;
}

static int by_path(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Sorts a list by path (the manifest lists files in a stable order). */
static void entries_sort(entry_list *l)
{
    /* sort the paths with their flags: flags ride along as a suffix-free pair */
    for (size_t i = 0; i < l->n; ++i) /* directories are few: mark them in the path */
        if (l->is_dir[i]) {
            char *marked = malloc(strlen(l->paths[i]) + 2);
            if (!marked)
                return;
            sprintf(marked, "%s/", l->paths[i]);
            free(l->paths[i]);
            l->paths[i] = marked;
        }
    if (l->n > 1) /* an empty list has no array (qsort wants one) */
        qsort(l->paths, l->n, sizeof *l->paths, by_path);
    for (size_t i = 0; i < l->n; ++i) {
        const size_t len = strlen(l->paths[i]);
        l->is_dir[i] = len > 0 && l->paths[i][len - 1] == '/';
        if (l->is_dir[i])
            l->paths[i][len - 1] = '\0';
    }
}

static int entries_has(const entry_list *l, const char *rel, int is_dir)
{
    for (size_t i = 0; i < l->n; ++i)
        if (l->is_dir[i] == is_dir && strcmp(l->paths[i], rel) == 0)
            return 1;
    return 0;
}

/* Reads DIR/phytocal-run.json into the list of what phytocal wrote there.
 * PHC_ERR_EXISTS with a message saying why the directory is not one of
 * ours. */
static int read_manifest(const char *dir, entry_list *l, phc_error *err)
{
    char path[8192];
    snprintf(path, sizeof path, "%s/%s", dir, PHC_RUN_MANIFEST);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root)
        return phc_error_set(err, PHC_ERR_EXISTS,
                             "%s: exists and is not a phytocal run directory (it has no readable %s); "
                             "--force replaces only directories that phytocal wrote: choose another -o, "
                             "or move or remove it yourself", dir, PHC_RUN_MANIFEST);
    int rc = PHC_OK;
    const json_t *version = json_object_get(root, "phytocal_run_directory");
    const json_t *files = json_object_get(root, "files");
    const json_t *dirs = json_object_get(root, "directories");
    if (!json_is_integer(version) || !json_is_array(files) || (dirs && !json_is_array(dirs))) {
        rc = phc_error_set(err, PHC_ERR_EXISTS,
                           "%s: its %s is not a phytocal run manifest (needs phytocal_run_directory, files); "
                           "--force will not touch it", dir, PHC_RUN_MANIFEST);
        goto done;
    }
    for (int pass = 0; pass < 2; ++pass) {
        const json_t *arr = pass ? dirs : files;
        for (size_t i = 0; arr && i < json_array_size(arr); ++i) {
            const json_t *e = json_array_get(arr, i);
            const json_t *p = json_is_object(e) ? json_object_get(e, "path") : e;
            const char *rel = json_string_value(p);
            /* a manifest that names a path outside the directory is not ours */
            if (!rel || !rel[0] || rel[0] == '/' || strstr(rel, "..")) {
                rc = phc_error_set(err, PHC_ERR_EXISTS, "%s: %s lists an invalid path; --force will not touch it",
                                   dir, PHC_RUN_MANIFEST);
                goto done;
            }
            if (entries_add(rel, pass, l)) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto done;
            }
        }
    }
done:
    json_decref(root);
    return rc;
}

/* Collects the entries of a directory that its manifest does not list. */
typedef struct foreign_scan {
    const entry_list *listed;
    char names[512];
    size_t count;
} foreign_scan;

static int note_foreign(const char *rel, int is_dir, void *ctx)
{
    foreign_scan *f = ctx;
    if (strcmp(rel, PHC_RUN_MANIFEST) == 0 || entries_has(f->listed, rel, is_dir))
        return 0;
    if (f->count < 5) {
        const size_t used = strlen(f->names);
        snprintf(f->names + used, sizeof f->names - used, "%s%s%s", f->count ? ", " : "", rel, is_dir ? "/" : "");
    }
    f->count++;
    return 0;
}

/* PHC_OK when DIR holds nothing but what its manifest lists (*listed filled). */
static int check_only_ours(const char *dir, entry_list *listed, phc_error *err)
{
    int rc;
    if ((rc = read_manifest(dir, listed, err)))
        return rc;
    foreign_scan scan = {listed, "", 0};
    if (walk(dir, "", note_foreign, &scan) < 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot list: %s", dir, strerror(errno));
    if (scan.count)
        return phc_error_set(err, PHC_ERR_EXISTS,
                             "%s: holds %zu file%s that phytocal did not write (%s%s); --force replaces only "
                             "what phytocal wrote: move %s or choose another -o", dir, scan.count,
                             scan.count == 1 ? "" : "s", scan.names, scan.count > 5 ? ", ..." : "",
                             scan.count == 1 ? "it" : "them");
    return PHC_OK;
}

/* The run's own config and data files must never be inside what a run
 * directory may replace. */
static int check_inputs_outside(const char *dir, const phc_problem *pb, phc_error *err)
{
    char rdir[PATH_MAX];
    if (!pb || !realpath(dir, rdir))
        return PHC_OK; /* nothing there yet: nothing of the user's inside */
    const size_t len = strlen(rdir);
    for (size_t d = 0; d <= pb->n_datasets; ++d) { /* d = 0: the config; then data set d - 1 */
        const size_t n = d == 0 ? 1 : pb->datasets[d - 1]->n_inputs;
        for (size_t i = 0; i < n; ++i) {
            const char *in = d == 0 ? pb->source : pb->datasets[d - 1]->inputs[i];
            char rin[PATH_MAX];
            if (!in || !realpath(in, rin))
                continue;
            if (strncmp(rin, rdir, len) == 0 && (rin[len] == '/' || rin[len] == '\0' || len == 1))
                return phc_error_set(err, PHC_ERR_EXISTS,
                                     "%s: holds %s '%s', an input of this run; phytocal never writes "
                                     "over its inputs: choose another -o", dir,
                                     d == 0 ? "the config" : "the data file", in);
        }
    }
    return PHC_OK;
}

int phc_run_dir_check(const char *dir, int force, const phc_problem *pb, phc_error *err)
{
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (!S_ISDIR(st.st_mode))
            return phc_error_set(err, PHC_ERR_EXISTS, "%s: exists and is not a directory", dir);
        int rc;
        if ((rc = check_inputs_outside(dir, pb, err)))
            return rc;
        if (!force)
            return phc_error_set(err, PHC_ERR_EXISTS,
                                 "%s: output directory exists; use --force to replace it or -o to choose another", dir);
        entry_list listed = {0};
        rc = check_only_ours(dir, &listed, err);
        entries_free(&listed);
        if (rc)
            return rc;
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

int phc_run_dir_make_parents(const char *dir, phc_error *err)
{
    char buf[4400];
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf)
        return phc_error_set(err, PHC_ERR_IO, "%.200s...: path too long", dir);
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

/* Run directories this thread has begun and not yet committed or
 * discarded, and the thread's deferred-sync setting before the first of
 * them (atomic_file.h): while one is open the thread's files are written
 * without an fsync each, and commit syncs the whole run once. */
static _Thread_local int open_runs, sync_setting_before;

static void open_run(void)
{
    if (open_runs++ == 0)
        sync_setting_before = phc_atomic_file_defer_sync(1);
}

static void close_run(void)
{
    if (open_runs > 0 && --open_runs == 0)
        phc_atomic_file_defer_sync(sync_setting_before);
}

int phc_run_dir_begin(const char *dir, int force, const phc_problem *pb, char *tmpdir, size_t size,
                      phc_error *err)
{
    int rc;
    if ((rc = phc_run_dir_check(dir, force, pb, err)) || (rc = phc_run_dir_make_parents(dir, err)))
        return rc;
    if ((size_t)snprintf(tmpdir, size, "%s.tmp-XXXXXX", dir) >= size)
        return phc_error_set(err, PHC_ERR_IO, "%s: output path too long", dir);
    if (!mkdtemp(tmpdir))
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot create a temporary directory: %s", tmpdir, strerror(errno));
    open_run();
    return PHC_OK;
}

void phc_run_dir_discard(const char *tmpdir)
{
    remove_tree(tmpdir);
    close_run();
}

/* Writes tmpdir's manifest: every file (with its SHA-256) and directory in
 * it, and the provenance. */
static int write_manifest(const char *tmpdir, const phc_provenance *pv, phc_error *err)
{
    entry_list l = {0};
    json_t *root = NULL;
    int rc = PHC_OK;
    if (walk(tmpdir, "", entries_add, &l) < 0) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot list the new run", tmpdir);
        goto done;
    }
    entries_sort(&l);
    root = json_object();
    json_t *files = json_array(), *dirs = json_array();
    json_object_set_new(root, "phytocal_run_directory", json_integer(MANIFEST_VERSION));
    json_object_set_new(root, "about", json_string("the files phytocal wrote here; `phytocal fit --force` "
                                                   "replaces this directory only while it holds nothing else"));
    json_object_set_new(root, "files", files);
    json_object_set_new(root, "directories", dirs);
    for (size_t i = 0; i < l.n; ++i) {
        if (l.is_dir[i]) {
            json_array_append_new(dirs, json_string(l.paths[i]));
            continue;
        }
        char path[8192], hex[65];
        long long bytes = 0;
        snprintf(path, sizeof path, "%s/%s", tmpdir, l.paths[i]);
        if ((rc = phc_file_sha256(path, hex, &bytes, err)))
            goto done;
        json_t *f = json_object();
        json_object_set_new(f, "path", json_string(l.paths[i]));
        json_object_set_new(f, "sha256", json_string(hex));
        json_object_set_new(f, "bytes", json_integer(bytes));
        json_array_append_new(files, f);
    }
    if (pv)
        json_object_set_new(root, "provenance", phc_provenance_to_json(pv));
    char path[8192];
    snprintf(path, sizeof path, "%s/%s", tmpdir, PHC_RUN_MANIFEST);
    phc_atomic_file *af = NULL;
    if ((rc = phc_atomic_file_open(path, &af, err)))
        goto done;
    errno = 0;
    if (json_dumpf(root, phc_atomic_file_stream(af), JSON_INDENT(2)) != 0) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write: %s", path, strerror(errno ? errno : EIO));
        phc_atomic_file_abort(af);
    } else {
        rc = phc_atomic_file_commit(af, err);
    }
done:
    json_decref(root);
    entries_free(&l);
    return rc;
}

/* Removes from an earlier run (moved aside to `old`) exactly the entries
 * its manifest lists, deepest first, then the manifest and the directory.
 * Anything else found there stays (and so does the directory). */
static void remove_listed(const char *old, const entry_list *l)
{
    char path[8192];
    for (size_t i = 0; i < l->n; ++i)
        if (!l->is_dir[i]) {
            snprintf(path, sizeof path, "%s/%s", old, l->paths[i]);
            unlink(path);
        }
    for (size_t pass = 0; pass < l->n; ++pass) { /* directories, longest path first */
        size_t best = l->n, best_len = 0;
        for (size_t i = 0; i < l->n; ++i)
            if (l->is_dir[i] && l->paths[i][0] && strlen(l->paths[i]) >= best_len) {
                best = i;
                best_len = strlen(l->paths[i]);
            }
        if (best == l->n)
            break;
        snprintf(path, sizeof path, "%s/%s", old, l->paths[best]);
        rmdir(path);
        l->paths[best][0] = '\0';
    }
    snprintf(path, sizeof path, "%s/%s", old, PHC_RUN_MANIFEST);
    unlink(path);
    rmdir(old);
}

/* One sync for a whole new run: syncfs(2) of the file system that holds
 * tmpdir writes back every file written there (and the directories'
 * entries) and commits the journal once, where an fsync per file commits it
 * once per file.  It also writes back other processes' dirty data on that
 * file system, which is a cost, not a risk. */
static int sync_tree(const char *tmpdir, phc_error *err)
{
    const int fd = open(tmpdir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open to sync: %s", tmpdir, strerror(errno));
    int rc = syncfs(fd);
    const int saved = errno;
    close(fd);
    if (rc != 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write to disk: %s", tmpdir, strerror(saved));
    return PHC_OK;
}

/* fsync of the folder that holds dir, so that its new entry (the rename)
 * is on disk too.  File systems that cannot (EINVAL) are not an error. */
static int sync_parent(const char *dir, phc_error *err)
{
    char parent[4096];
    snprintf(parent, sizeof parent, "%s", dir);
    char *slash = strrchr(parent, '/');
    if (!slash)
        snprintf(parent, sizeof parent, ".");
    else if (slash == parent)
        parent[1] = '\0';
    else
        *slash = '\0';
    const int fd = open(parent, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open to sync: %s", parent, strerror(errno));
    const int rc = fsync(fd);
    const int saved = errno;
    close(fd);
    if (rc != 0 && saved != EINVAL && saved != ENOTSUP)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write to disk: %s", parent, strerror(saved));
    return PHC_OK;
}

/* The manifest, one sync of the new run, the swap into place and an fsync
 * of the parent folder (run_dir.h, phc_run_dir_commit). */
static int commit(const char *tmpdir, const char *dir, const phc_provenance *pv, phc_error *err)
{
    int rc;
    const int was = phc_atomic_file_defer_sync(1);
    rc = write_manifest(tmpdir, pv, err);
    phc_atomic_file_defer_sync(was);
    if (!rc)
        rc = sync_tree(tmpdir, err);
    if (rc) {
        remove_tree(tmpdir);
        return rc;
    }
    /* Swap into place: an earlier run (with --force) is looked at again now
     * (a fit takes time: the user may have added a file meanwhile) and
     * removed only now, and only what its manifest lists. */
    char old[4096];
    struct stat st;
    entry_list listed = {0};
    old[0] = '\0';
    if (stat(dir, &st) == 0) {
        if ((rc = check_only_ours(dir, &listed, err))) {
            entries_free(&listed);
            char msg[sizeof err->message];
            snprintf(msg, sizeof msg, "%s", err->message);
            remove_tree(tmpdir);
            return phc_error_set(err, rc, "%s (checked again before replacing it; the new run was discarded)",
                                 msg);
        }
        snprintf(old, sizeof old, "%s.old-XXXXXX", dir);
        if (!mkdtemp(old) || rmdir(old) != 0 || rename(dir, old) != 0) {
            rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot move the earlier run aside: %s", dir, strerror(errno));
            entries_free(&listed);
            remove_tree(tmpdir);
            return rc;
        }
    }
    if (rename(tmpdir, dir) != 0) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot rename the new run into place: %s", dir, strerror(errno));
        if (old[0])
            rename(old, dir); /* put the earlier run back */
        entries_free(&listed);
        remove_tree(tmpdir);
        return rc;
    }
    if (old[0])
        remove_listed(old, &listed);
    entries_free(&listed);
    chmod(dir, 0755); /* mkdtemp made it private; results are for sharing */
    return sync_parent(dir, err);
}

int phc_run_dir_commit(const char *tmpdir, const char *dir, const phc_provenance *pv, phc_error *err)
{
    const int rc = commit(tmpdir, dir, pv, err);
    close_run();
    return rc;
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
        { /* the model's unit */
            const phc_param_result *pr = &res->params[ds->param_index[j]];
            p[j] = pr->unit_scale * pr->value + pr->unit_offset;
        }
        char base[256];
        phc_run_dir_safe_name(ds->name, base, sizeof base);
        const int rc = ds->ops->fit_outputs(ds, p, tmpdir, base, err);
        free(p);
        if (rc)
            return rc;
    }
    return PHC_OK;
}

phc_run_dir_options phc_run_dir_options_default(void)
{
    phc_run_dir_options o = {.force = 0, .plots = PHC_RUN_PLOTS_ALL, .nested = 0};
    return o;
}

int phc_run_plots_parse(const char *text, phc_run_plots *out)
{
    if (text && strcmp(text, "all") == 0)
        *out = PHC_RUN_PLOTS_ALL;
    else if (text && strcmp(text, "none") == 0)
        *out = PHC_RUN_PLOTS_NONE;
    else
        return -1;
    return 0;
}

int phc_run_dir_write(const phc_fit_result *res, const phc_problem *pb, const char *dir, int force,
                      phc_error *err)
{
    phc_run_dir_options o = phc_run_dir_options_default();
    o.force = force;
    return phc_run_dir_write_with(res, pb, dir, &o, err);
}

/* The plots of a run: the standard ones, then the kinds' own outputs; the
 * kinds' PNG files are linked in the report too, after the standard ones.
 * names[] gets every PNG's name (malloc'd). */
static int write_plots(const phc_fit_result *res, const phc_problem *pb, const char *tmpdir, char **names,
                       size_t *n_names, phc_error *err)
{
    int rc;
    if ((rc = phc_fit_plots_write(res, tmpdir, names, n_names, MAX_PLOTS, err)) ||
        (rc = write_kind_outputs(res, pb, tmpdir, err)))
        return rc;
    entry_list extra = {0};
    if (walk(tmpdir, "", entries_add, &extra) < 0) {
        entries_free(&extra);
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot list the new run", tmpdir);
    }
    entries_sort(&extra);
    for (size_t i = 0; i < extra.n && *n_names + 1 < MAX_PLOTS; ++i) {
        const size_t len = strlen(extra.paths[i]);
        int known = extra.is_dir[i] || len < 4 || strcmp(extra.paths[i] + len - 4, ".png") != 0;
        for (size_t j = 0; j < *n_names && !known; ++j)
            known = strcmp(names[j], extra.paths[i]) == 0;
        if (!known && !(names[(*n_names)++] = strdup(extra.paths[i]))) {
            entries_free(&extra);
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        }
    }
    entries_free(&extra);
    return PHC_OK;
}

int phc_run_dir_write_with(const phc_fit_result *res, const phc_problem *pb, const char *dir,
                           const phc_run_dir_options *opts, phc_error *err)
{
    const phc_run_dir_options o = opts ? *opts : phc_run_dir_options_default();
    char tmpdir[4096], path[8192];
    int rc;
    if (o.nested) { /* the caller's new folder: written in place (run_dir.h) */
        if ((size_t)snprintf(tmpdir, sizeof tmpdir, "%s", dir) >= sizeof tmpdir)
            return phc_error_set(err, PHC_ERR_IO, "%s: output path too long", dir);
        if (mkdir(tmpdir, 0755) != 0)
            return phc_error_set(err, errno == EEXIST ? PHC_ERR_EXISTS : PHC_ERR_IO, "%s: cannot create: %s", dir,
                                 strerror(errno));
    } else if ((rc = phc_run_dir_begin(dir, o.force, pb, tmpdir, sizeof tmpdir, err))) {
        return rc;
    }
    /* no fsync per file: one sync of the whole run before its rename
       (phc_run_dir_begin turned that on for this thread), or none here,
       when the caller syncs the folder that holds it */
    const int was = o.nested ? phc_atomic_file_defer_sync(1) : 0;
    char *names[MAX_PLOTS] = {0};
    size_t n_names = 0;
    if (o.plots == PHC_RUN_PLOTS_ALL && (rc = write_plots(res, pb, tmpdir, names, &n_names, err)))
        goto fail;
    snprintf(path, sizeof path, "%s/result.json", tmpdir);
    if ((rc = phc_result_write_json(res, path, err)))
        goto fail;
    snprintf(path, sizeof path, "%s/report.md", tmpdir);
    if ((rc = phc_report_write_markdown(res, path, o.plots == PHC_RUN_PLOTS_ALL ? (const char *const *)names : NULL,
                                        err)))
        goto fail;
    if (o.nested) {
        if ((rc = write_manifest(tmpdir, res->provenance, err)))
            goto fail;
        phc_atomic_file_defer_sync(was);
    } else {
        rc = phc_run_dir_commit(tmpdir, dir, res->provenance, err);
    }
    for (size_t i = 0; i < n_names; ++i)
        free(names[i]);
    return rc;
fail:
    if (o.nested) {
        phc_atomic_file_defer_sync(was);
        remove_tree(tmpdir); /* not phc_run_dir_discard: the caller's run stays open */
    } else {
        phc_run_dir_discard(tmpdir);
    }
    for (size_t i = 0; i < n_names; ++i)
        free(names[i]);
    return rc;
}

/* ---- verifying ---------------------------------------------------------------------- */

static int add_item(phc_run_dir_item **items, size_t *n, const char *role, const char *path,
                    phc_file_state state)
{
    phc_run_dir_item *grown = realloc(*items, (*n + 1) * sizeof *grown);
    if (!grown)
        return PHC_ERR_NOMEM;
    *items = grown;
    grown[*n].role = role;
    grown[*n].state = state;
    if (!(grown[*n].path = strdup(path)))
        return PHC_ERR_NOMEM;
    (*n)++;
    return PHC_OK;
}

int phc_run_dir_verify(const char *dir, phc_run_dir_item **items, size_t *n, phc_error *err)
{
    char path[8192];
    *items = NULL;
    *n = 0;
    snprintf(path, sizeof path, "%s/%s", dir, PHC_RUN_MANIFEST);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: cannot read the run's manifest: %s (runs written before "
                             "phytocal recorded provenance have none)", path, jerr.text);
    int rc = PHC_OK;
    phc_provenance *pv = NULL;
    const json_t *prov = json_object_get(root, "provenance");
    if (prov && (rc = phc_provenance_from_json(prov, path, &pv, err)))
        goto done;
    for (size_t i = 0; pv && i <= pv->n_inputs; ++i) {
        const phc_provenance_file *f = i == 0 ? pv->config : &pv->inputs[i - 1];
        if (!f)
            continue;
        const char *found;
        if (add_item(items, n, i == 0 ? "config" : "data", f->path, phc_provenance_file_state(f, &found))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
    const json_t *files = json_object_get(root, "files");
    for (size_t i = 0; i < json_array_size(files); ++i) {
        phc_provenance_file f = {0};
        const json_t *e = json_array_get(files, i);
        const char *rel = json_string_value(json_object_get(e, "path"));
        const char *sha = json_string_value(json_object_get(e, "sha256"));
        if (!rel || !sha) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s: files[%zu]: expected {path, sha256}", path, i);
            goto done;
        }
        char full[8192];
        snprintf(full, sizeof full, "%s/%s", dir, rel);
        f.path = full;
        snprintf(f.sha256, sizeof f.sha256, "%s", sha);
        const char *found;
        if (add_item(items, n, "output", rel, phc_provenance_file_state(&f, &found))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
done:
    phc_provenance_free(pv);
    json_decref(root);
    if (rc) {
        phc_run_dir_verify_free(*items, *n);
        *items = NULL;
        *n = 0;
    }
    return rc;
}

void phc_run_dir_verify_free(phc_run_dir_item *items, size_t n)
{
    for (size_t i = 0; items && i < n; ++i)
        free(items[i].path);
    free(items);
}
