/* The file side of a PLplot figure, shared by fit/plots.c,
 * fit/soil_plots.c and fit/growth_outputs.c: text escaping, the cairo
 * device check, the PNG encoder of plots.c's memcairo pages, the check
 * that a complete PNG was written, and committing the temporary output file
 * (measurements/atomic_file.h). */
#ifndef PHC_PLOT_FILE_H
#define PHC_PLOT_FILE_H

#include "measurements/atomic_file.h"
#include "model/status.h"

/* s with PLplot's escape character '#' doubled (malloc'd; NULL when out of
 * memory; NULL s gives ""). */
char *phc_plot_escape(const char *s);
/* 1 when PLplot has the device `name`, 0 when not, -1 when it cannot tell.
 * Opens PLplot (measurements/lazy_library_internal.h): call phc_plot_library_open
 * first where a failure can be reported. */
int phc_plot_device_available(const char *name);
/* Opens PLplot if not yet open (libphytocal loads it on the first plot, not
 * at start-up): PHC_OK or PHC_ERR_IO "PATH: cannot load the plotting
 * (PLplot) library libplplot.so.N: <dlerror>".  Every plot calls it before
 * its first PLplot call. */
int phc_plot_library_open(const char *path, phc_error *err);
/* The PNG goes to the temporary file of a phc_atomic_file (PLplot writes it
 * by name: plsfnam(phc_atomic_file_temp_path(af))).  Finishing it: when
 * status is PHC_OK and the file is a complete PNG, commits it to its path;
 * otherwise removes it (af may be NULL).  Returns the final status;
 * PHC_ERR_IO "PATH: PLplot did not write a complete PNG file (disk full?)"
 * or the commit's message. */
int phc_plot_file_finish(phc_atomic_file *af, int status, phc_error *err);
/* Starts a w x h px PNG for path: checks the pngcairo device, opens path's
 * temporary file (*af) and a new PLplot stream writing it, remembering the
 * caller's stream in *old_stream.  The caller then sets its colours, calls
 * plinit() and draws.  PHC_ERR_INTERNAL (no device, no free stream) or the
 * file's error; nothing is left open on failure. */
int phc_plot_begin(const char *path, int w, int h, phc_atomic_file **af, int *old_stream, phc_error *err);
/* Ends what phc_plot_begin started (plend1, back to *old_stream) and
 * finishes the file as phc_plot_file_finish does with status. */
int phc_plot_end(phc_atomic_file *af, int old_stream, int status, phc_error *err);
/* Encodes an RGBA page (w x h, rows top to bottom, as PLplot's memcairo
 * device leaves it) as an 8-bit RGB PNG into af's stream and flushes it.
 * zlib level 1 with the Sub filter: plots are mostly flat colour, and this
 * is several times faster than cairo's own PNG writer (default level, every
 * filter tried per row) for files about as large.  PHC_ERR_IO / NOMEM. */
int phc_plot_png_write(phc_atomic_file *af, const unsigned char *rgba, int w, int h, phc_error *err);
/* 1 when file starts with the PNG signature and ends with the IEND chunk
 * (cairo reports no write errors through PLplot: a full disk shows as a
 * truncated file). */
int phc_plot_png_complete(const char *file);

/* Tick interval 1, 2 or 5 x 10^k giving about `target` intervals over
 * `span` (both > 0). */
double phc_plot_nice_step(double span, double target);

#endif /* PHC_PLOT_FILE_H */
