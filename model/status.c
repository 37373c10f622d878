/* phytocal status codes: see status.h. */
#include "status.h"

#include <stdarg.h>
#include <stdio.h>

static const char *const status_text[] = {
#define PHC_STATUS_TEXT(name, text) text,
    PHC_STATUS_LIST(PHC_STATUS_TEXT)
#undef PHC_STATUS_TEXT
};

const char *phc_strerror(int status)
{
    if (status < 0 || status >= PHC_STATUS_COUNT)
        return "unknown status";
    return status_text[status];
}

void phc_error_clear(phc_error *err)
{
    if (!err)
        return;
    err->status = PHC_OK;
    err->message[0] = '\0';
}

int phc_error_set(phc_error *err, int status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}
