/* Whole-file reading: see text_file.h. */
#include "measurements/text_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int phc_read_text_file(const char *path, char **text, size_t *length, phc_error *err)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t len = 0, cap = 0;
    int rc;
    if (!f)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    for (;;) {
        if (cap - len < 65536 + 1) {
            size_t want = cap ? 2 * cap : 65536 + 1;
            char *q = realloc(buf, want);
            if (!q) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
                goto fail;
            }
            buf = q;
            cap = want;
        }
        size_t got = fread(buf + len, 1, cap - len - 1, f);
        len += got;
        if (got == 0 || feof(f)) /* a short read at the end: no second, larger buffer */
            break;
    }
    if (ferror(f)) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
        goto fail;
    }
    fclose(f);
    buf[len] = '\0';
    *text = buf;
    *length = len;
    return PHC_OK;
fail:
    fclose(f);
    free(buf);
    return rc;
}
