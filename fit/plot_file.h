/* The file side of a PLplot figure, shared by fit/plots.c and
 * fit/soil_plots.c: text escaping, the pngcairo device check, a temporary
 * output file next to the final path, and the check that cairo wrote a
 * complete PNG. */
#ifndef PHC_PLOT_FILE_H
#define PHC_PLOT_FILE_H

#include "model/status.h"

/* s with PLplot's escape character '#' doubled (malloc'd; NULL when out of
 * memory; NULL s gives ""). */
char *phc_plot_escape(const char *s);
/* 1 when PLplot has the device `name`, 0 when not, -1 when it cannot tell. */
int phc_plot_device_available(const char *name);
/* Creates path.<pid>.<i>.tmp with O_EXCL (mode 0666 less the umask) and
 * stores its malloc'd name in *out; PHC_ERR_IO names path and the reason. */
int phc_plot_temp_file(const char *path, char **out, phc_error *err);
/* 1 when file starts with the PNG signature and ends with the IEND chunk
 * (cairo reports no write errors through PLplot: a full disk shows as a
 * truncated file). */
int phc_plot_png_complete(const char *file);

#endif /* PHC_PLOT_FILE_H */
