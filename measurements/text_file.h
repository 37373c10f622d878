/* Reading a whole text file into memory, with messages that name the file. */
#ifndef PHC_TEXT_FILE_H
#define PHC_TEXT_FILE_H

#include <stddef.h>

#include "model/status.h"

/* Reads all of `path` (pipes too: no ftell) into a malloc'd buffer of
 * *length bytes plus a terminating NUL.  PHC_ERR_IO with
 * "PATH: cannot open: <reason>" or "PATH: cannot read: <reason>" (a
 * directory gives "Is a directory"). */
int phc_read_text_file(const char *path, char **text, size_t *length, phc_error *err);

#endif /* PHC_TEXT_FILE_H */
