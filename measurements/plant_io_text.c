/* The plant-graph readers' tokenizer: see plant_io_text.h. */
#include "measurements/plant_io_text.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* A printable, shortened copy of s for messages. */
const char *phc_plant_io_shorten(const char *s, char *out, size_t size)
{
    size_t i = 0;
    for (; s[i] && i + 4 < size && i < PHC_PLANT_IO_SHOW_MAX; ++i)
        out[i] = (unsigned char)s[i] < 32 ? '?' : s[i];
    if (s[i]) {
        out[i++] = '.';
        out[i++] = '.';
        out[i++] = '.';
    }
    out[i] = '\0';
    return out;
}

int phc_plant_io_is_blank(char c)
{
    return c == ' ' || c == '\t';
}

/* Cuts the next line (LF, CRLF or CR ends) out of the buffer in place.
 * Returns 0 at the end of the text. */
static int next_raw_line(phc_plant_io_cursor *c, char **line, size_t *number)
{
    char *s, *q;
    if (c->p >= c->end)
        return 0;
    s = c->p;
    q = s;
    while (q < c->end && *q != '\n' && *q != '\r')
        ++q;
    if (q < c->end) {
        if (*q == '\r' && q + 1 < c->end && q[1] == '\n') {
            *q = '\0';
            c->p = q + 2;
        } else {
            *q = '\0';
            c->p = q + 1;
        }
    } else {
        c->p = c->end; /* the buffer's terminating NUL ends the line */
    }
    *line = s;
    *number = c->next_line++;
    return 1;
}

char *phc_plant_io_trim(char *s)
{
    char *e;
    while (phc_plant_io_is_blank(*s))
        ++s;
    e = s + strlen(s);
    while (e > s && phc_plant_io_is_blank(e[-1]))
        *--e = '\0';
    return s;
}

/* Next line that is not blank (and, when skip_hash, not a `#` comment). */
int phc_plant_io_next_line(phc_plant_io_cursor *c, char **line, size_t *number, int skip_hash)
{
    char *s;
    while (next_raw_line(c, &s, number)) {
        s = phc_plant_io_trim(s);
        if (!*s || (skip_hash && *s == '#'))
            continue;
        *line = s;
        return 1;
    }
    return 0;
}

/* Splits in place: delim ',' (fields trimmed) or 0 (runs of blanks).
 * Returns the number of fields found (may exceed max; only max stored). */
int phc_plant_io_split_fields(char *s, char delim, char **fields, int max)
{
    int n = 0;
    if (delim) {
        for (;;) {
            char *d = strchr(s, delim);
            if (d)
                *d = '\0';
            if (n < max)
                fields[n] = phc_plant_io_trim(s);
            ++n;
            if (!d)
                break;
            s = d + 1;
        }
    } else {
        while (*s) {
            while (phc_plant_io_is_blank(*s))
                ++s;
            if (!*s)
                break;
            if (n < max)
                fields[n] = s;
            ++n;
            while (*s && !phc_plant_io_is_blank(*s))
                ++s;
            if (*s)
                *s++ = '\0';
        }
    }
    return n;
}

/* strtod on the whole field (the caller holds a C-locale scope).  NaN and
 * infinities parse; callers check finiteness with a precise message. */
int phc_plant_io_parse_double(const char *s, double *x)
{
    char *end;
    if (!*s)
        return -1;
    errno = 0;
    *x = strtod(s, &end);
    return (end == s || *end) ? -1 : 0;
}

int phc_plant_io_parse_long(const char *s, long *x)
{
    char *end;
    if (!*s)
        return -1;
    errno = 0;
    *x = strtol(s, &end, 10);
    return (end == s || *end || errno == ERANGE) ? -1 : 0;
}

/* Fields first..last-1 as numbers into v[first..last-1]; the message names
 * the field: "FILE:LINE: field 'x': expected a number, found 'abc'". */
int phc_plant_io_parse_number_fields(const char *path, size_t number, char *const *f,
                                     const char *const *names, int first, int last, double *v,
                                     phc_error *err)
{
    char shown[PHC_PLANT_IO_SHOW_MAX + 8];
    int k;
    for (k = first; k < last; ++k)
        if (phc_plant_io_parse_double(f[k], &v[k]) != 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: field '%s': expected a number, found '%s'", path,
                                 number, names[k], phc_plant_io_shorten(f[k], shown, sizeof shown));
    return PHC_OK;
}
