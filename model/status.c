/* phytocal status codes: see status.h. */
#include "status.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

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

/* A message is one line (status.h), but it quotes the user's text, which may
 * hold line breaks, tabs or other control characters (a quoted CSV cell, a
 * YAML key, a unit string): they are shown escaped, C style ("a\nb",
 * "\x7f"), cut at the end of the buffer rather than in an escape. */
static void escape_controls(char *message, size_t size)
{
    char copy[PHC_ERROR_MESSAGE_SIZE];
    size_t at = 0;
    const char *c;
    for (c = message; *c; ++c)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            break;
    if (!*c)
        return;
    snprintf(copy, sizeof copy, "%s", message);
    for (c = copy; *c; ++c) {
        char esc[5];
        switch (*c) {
        case '\n': snprintf(esc, sizeof esc, "\\n"); break;
        case '\r': snprintf(esc, sizeof esc, "\\r"); break;
        case '\t': snprintf(esc, sizeof esc, "\\t"); break;
        default:
            if ((unsigned char)*c < 0x20 || *c == 0x7f)
                snprintf(esc, sizeof esc, "\\x%02x", (unsigned)(unsigned char)*c);
            else
                esc[0] = *c, esc[1] = '\0';
        }
        size_t n = strlen(esc);
        if (at + n + 1 > size)
            break;
        memcpy(message + at, esc, n);
        at += n;
    }
    message[at] = '\0';
}

int phc_error_set(phc_error *err, int status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        escape_controls(err->message, sizeof err->message);
        err->status = status;
    }
    return status;
}

int phc_error_prefix(phc_error *err, int status, const char *fmt, ...)
{
    if (err) {
        char msg[PHC_ERROR_MESSAGE_SIZE];
        snprintf(msg, sizeof msg, "%s", err->message);
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        /* the place, then ": " and the earlier message, truncated to fit */
        size_t at = k < 0 ? 0 : (size_t)k < sizeof err->message ? (size_t)k : sizeof err->message - 1;
        const char *parts[2] = {": ", msg};
        for (int q = 0; q < 2; ++q)
            for (const char *c = parts[q]; *c && at + 1 < sizeof err->message; ++c)
                err->message[at++] = *c;
        err->message[at] = '\0';
        escape_controls(err->message, sizeof err->message);
        err->status = status;
    }
    return status;
}
