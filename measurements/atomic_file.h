/* Writing a file all at once: every phytocal writer goes through this
 * (DESIGN.md §3, "output files are written to a temporary name and renamed
 * into place").
 *
 * phc_atomic_file_open creates a temporary file next to the destination,
 * in the same directory (so the final rename never crosses a file system),
 * named
 *
 *     DIR/NAME.tmp-XXXXXX        (X: six random letters or digits)
 *
 * the same scheme as a run directory's temporary sibling (DIR.tmp-XXXXXX,
 * fit/run_dir.h), so a leftover of a killed process is easy to spot.  It is
 * claimed with O_EXCL and mode 0666 less the umask (what fopen(path, "w")
 * gives), so two writers never share one, and a file of someone else's is
 * never opened.
 *
 * The caller writes either through phc_atomic_file_stream (a stdio stream)
 * or, for libraries that write by file name (PLplot, NetCDF, libxml2,
 * OpenCV), to phc_atomic_file_temp_path.  phc_atomic_file_commit then checks
 * the stream for write errors, flushes the file to disk (fsync) and renames
 * it over the destination; phc_atomic_file_abort removes it.  Until commit
 * succeeds the destination is untouched: an earlier file there survives any
 * failed write, and no reader ever sees a half-written one.
 *
 * Messages name the destination and the reason ("out/x.csv: cannot open for
 * writing: No such file or directory"), never only the temporary name.
 *
 * Deferred sync: a writer that makes a whole folder of files visible at once
 * (a run directory is written into a temporary sibling and renamed into
 * place, fit/run_dir.h) gets the same durability from one sync of that
 * folder's file system before its rename as from an fsync per file, at a
 * fraction of the wait (ext4 commits its journal once per fsync).  It calls
 * phc_atomic_file_defer_sync(1) around its writes and syncs the folder
 * itself; commit then skips the fsync.  The setting belongs to the calling
 * thread (other threads keep syncing every file).
 *
 * Not thread-safe per object; different objects may be used from different
 * threads. */
#ifndef PHC_ATOMIC_FILE_H
#define PHC_ATOMIC_FILE_H

#include <stdio.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_atomic_file phc_atomic_file;

/* Creates the temporary file for `path` and its stream (binary: no newline
 * translation).  PHC_ERR_IO "PATH: cannot open for writing: REASON" when the
 * directory is missing or not writable; PHC_ERR_INVALID for a NULL or empty
 * path; PHC_ERR_NOMEM.  *out is NULL on failure. */
int phc_atomic_file_open(const char *path, phc_atomic_file **out, phc_error *err);

/* The stream to write to; owned by af (do not fclose it). */
FILE *phc_atomic_file_stream(phc_atomic_file *af);

/* The temporary file's name, for libraries that open files by name; they
 * may truncate and rewrite it.  Valid until commit or abort. */
const char *phc_atomic_file_temp_path(const phc_atomic_file *af);

/* The destination, as given to open. */
const char *phc_atomic_file_path(const phc_atomic_file *af);

/* Finishes the file: flushes and closes the stream (any write error seen by
 * the stream, such as a full disk, fails here), fsyncs the file, then renames
 * it to the destination, replacing an earlier file there.  Frees af whatever
 * happens; on failure removes the temporary file and leaves the destination
 * as it was.  PHC_ERR_IO "PATH: cannot write: REASON" or "PATH: cannot rename
 * into place: REASON" (for instance when PATH is a directory). */
int phc_atomic_file_commit(phc_atomic_file *af, phc_error *err);

/* defer = 1: phc_atomic_file_commit in this thread no longer fsyncs (the
 * caller promises to sync what it wrote before relying on it, see above);
 * defer = 0: every commit fsyncs again (the default).  Returns the previous
 * setting, so a caller can restore it. */
int phc_atomic_file_defer_sync(int defer);

/* Closes the stream, removes the temporary file and frees af; the
 * destination is untouched.  Accepts NULL. */
void phc_atomic_file_abort(phc_atomic_file *af);

/* Closes the stream and frees af but leaves the temporary file where it is,
 * for a writer that promises to keep a file its library failed to finish for
 * inspection (the caller has named it in its message first).  Accepts
 * NULL. */
void phc_atomic_file_leave(phc_atomic_file *af);

#ifdef __cplusplus
}
#endif

#endif /* PHC_ATOMIC_FILE_H */
