/* Writing a run directory: result.json, report.md, the diagnostic plots and
 * the manifest.
 *
 * Everything is written into a temporary sibling directory (DIR.tmp-XXXXXX)
 * that is renamed to DIR only when complete, so a failed run leaves no
 * partial output.
 *
 * Safety (nothing of the user's is ever removed):
 * - every run directory carries a manifest, phytocal-run.json, listing each
 *   file (with its SHA-256) and folder phytocal wrote there, and the run's
 *   provenance (provenance.h);
 * - an existing DIR is an error (PHC_ERR_EXISTS) unless `force` is set;
 * - with force, DIR is replaced only when it carries a manifest and holds
 *   nothing the manifest does not list (checked before the run and again just
 *   before replacing it); then only the listed entries are removed;
 * - DIR may never hold the run's config or any of its data files (force or
 *   not). */
#ifndef PHC_RUN_DIR_H
#define PHC_RUN_DIR_H

#include "fit/engine/fit.h"
#include "fit/engine/provenance.h"
#include "model/status.h"

#define PHC_RUN_MANIFEST "phytocal-run.json"

/* Checks up front that DIR can be written (absent, or force and a run
 * directory of phytocal's own holding nothing else, and not holding the
 * inputs of pb, which may be NULL), so a long fit is not wasted on a
 * directory that will be refused. */
int phc_run_dir_check(const char *dir, int force, const phc_problem *pb, phc_error *err);

/* Writes a fit's run directory (result.json, report.md, plots, manifest with
 * res->provenance when set) by the three steps below, with the default
 * options (all plots, synced) and `force`.  pb (may be NULL) is the problem
 * that was fitted: data sets whose kind writes its own files (dataset.h,
 * fit_outputs) add them, at the fitted values. */
int phc_run_dir_write(const phc_fit_result *res, const phc_problem *pb, const char *dir, int force,
                      phc_error *err);

/* Which pictures a fit's run directory gets (`phytocal fit --plots`). */
typedef enum phc_run_plots {
    PHC_RUN_PLOTS_ALL = 0, /* the diagnostic plots of every data set (fit_plots.h) and the kinds' own
                              outputs at the fitted values (dataset.h, fit_outputs) */
    PHC_RUN_PLOTS_NONE     /* neither: result.json, report.md (saying so) and the manifest only */
} phc_run_plots;

/* Parses "all" or "none"; -1 for anything else. */
int phc_run_plots_parse(const char *text, phc_run_plots *out);

typedef struct phc_run_dir_options {
    int force;           /* replace an earlier run directory (the rules above); default 0 */
    phc_run_plots plots; /* default PHC_RUN_PLOTS_ALL */
    /* 0 (default): a run directory of its own, made as above (checked,
     * written into a temporary sibling, renamed into place); when
     * phc_run_dir_write_with returns, its files are on disk: they are
     * written without an fsync each, then one syncfs of the file system
     * holding them precedes the rename, and the parent folder is fsynced
     * after it (phc_run_dir_commit).
     * 1: DIR is a new folder inside a folder that the caller created for
     * this work, will sync once and rename into place itself (a batch's
     * temporary folder, cmd_fit_batch): DIR is created directly, written and
     * given its manifest, with no checks, no temporary sibling and no sync;
     * DIR must not exist (PHC_ERR_EXISTS); on failure it is removed. */
    int nested;
} phc_run_dir_options;

phc_run_dir_options phc_run_dir_options_default(void);

int phc_run_dir_write_with(const phc_fit_result *res, const phc_problem *pb, const char *dir,
                           const phc_run_dir_options *opts, phc_error *err);

/* The steps, for any command that writes a run directory:
 * begin checks DIR (as phc_run_dir_check), creates its parents and a
 * temporary sibling, whose path goes to tmpdir (size bytes), and from then
 * on the calling thread writes files without an fsync each
 * (atomic_file.h, phc_atomic_file_defer_sync; other threads still fsync
 * theirs);
 * commit writes the manifest (with provenance pv, may be NULL), makes one
 * syncfs of the file system holding tmpdir, renames the temporary
 * directory to DIR (replacing an earlier run only now) and fsyncs DIR's
 * parent folder, so that DIR and all it holds are on disk when it returns;
 * on failure it removes the temporary directory and keeps the earlier run
 * (a crash before the rename leaves only the temporary folder);
 * discard removes the temporary directory after a failure.
 * Every begin that succeeded is followed by exactly one commit or discard
 * on the same thread, which restores the thread's per-file fsync (begins
 * may nest: the setting comes back after the last). */
int phc_run_dir_begin(const char *dir, int force, const phc_problem *pb, char *tmpdir, size_t size,
                      phc_error *err);
int phc_run_dir_commit(const char *tmpdir, const char *dir, const phc_provenance *pv, phc_error *err);
void phc_run_dir_discard(const char *tmpdir);

/* `phytocal report --check DIR`: each file the run read (its config and
 * data, from the manifest's provenance) and each file it wrote (from the
 * manifest), and whether it still has the bytes it had.  *items is
 * malloc'd (free with phc_run_dir_verify_free).  PHC_ERR_INPUT when DIR has
 * no readable manifest. */
typedef struct phc_run_dir_item {
    const char *role; /* "config", "data" or "output" */
    char *path;       /* as recorded; outputs relative to DIR */
    phc_file_state state;
} phc_run_dir_item;
int phc_run_dir_verify(const char *dir, phc_run_dir_item **items, size_t *n, phc_error *err);
void phc_run_dir_verify_free(phc_run_dir_item *items, size_t n);

/* mkdir -p of the folders that hold path (not path itself): a run
 * directory's or a ledger's parents.  PHC_ERR_IO names the folder. */
int phc_run_dir_make_parents(const char *path, phc_error *err);

/* A file-name-safe copy of a data-set name: characters other than letters,
 * digits, '-', '_' and '.' become '_'. */
void phc_run_dir_safe_name(const char *name, char *out, size_t size);

#endif /* PHC_RUN_DIR_H */
