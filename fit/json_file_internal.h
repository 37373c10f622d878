/* fit/json_file_internal.h: writing a JSON document as a file.
 *
 * Every result.json (fit, sensitivity, profile, MCMC, grow) is written the
 * same way: indented by 2, numbers with 17 significant digits (so a double
 * reads back to the same bits), through measurements/atomic_file (a
 * temporary beside the destination, renamed into place only when whole).
 * Internal: jansson's json_t is not part of the installed API. */
#ifndef PHC_JSON_FILE_INTERNAL_H
#define PHC_JSON_FILE_INTERNAL_H

#include <jansson.h>

#include "model/status.h"

/* Writes root to path; root stays the caller's.  PHC_ERR_IO names the path
 * (and the system's reason when there is one). */
int phc_json_file_write(const json_t *root, const char *path, phc_error *err);

#endif
