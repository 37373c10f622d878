/* Writing a JSON document as a file: see json_file_internal.h. */
#include "fit/json_file_internal.h"

#include <errno.h>
#include <string.h>

#include "measurements/atomic_file.h"

int phc_json_file_write(const json_t *root, const char *path, phc_error *err)
{
    phc_atomic_file *af = NULL;
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc != PHC_OK)
        return rc;
    errno = 0;
    if (json_dumpf(root, phc_atomic_file_stream(af), JSON_INDENT(2) | JSON_REAL_PRECISION(17)) != 0) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write: %s", path, strerror(errno ? errno : EIO));
        phc_atomic_file_abort(af);
        return rc;
    }
    return phc_atomic_file_commit(af, err);
}
