/* The plant-graph readers' line and field tokenizer (internal to
 * measurements/plant_io*.c; not installed, not part of plant_io.h).
 *
 * Text is cut in place: lines end at LF, CRLF or CR; fields are split on a
 * delimiter or on runs of blanks; numbers must consume the whole field and
 * are parsed by strtod/strtol (callers hold a C-locale scope,
 * measurements/c_number.h). */
#ifndef PHC_PLANT_IO_TEXT_H
#define PHC_PLANT_IO_TEXT_H

#include <stddef.h>

#include "model/status.h"

/* Longest excerpt of a field shown in a message (characters). */
#define PHC_PLANT_IO_SHOW_MAX 40

typedef struct phc_plant_io_cursor {
    char *p, *end;
    size_t next_line; /* number of the line p starts */
} phc_plant_io_cursor;

/* A printable copy of s for messages, cut after PHC_PLANT_IO_SHOW_MAX
 * characters ("..."); returns out. */
const char *phc_plant_io_shorten(const char *s, char *out, size_t size);
/* 1 for a space or a tab. */
int phc_plant_io_is_blank(char c);
/* s without leading and trailing blanks (cut in place). */
char *phc_plant_io_trim(char *s);
/* Next line that is not blank (and, when skip_hash, not a `#` comment),
 * trimmed, with its 1-based number; 0 at the end of the text. */
int phc_plant_io_next_line(phc_plant_io_cursor *c, char **line, size_t *number, int skip_hash);
/* Splits in place: delim ',' (fields trimmed) or 0 (runs of blanks).
 * Returns the number of fields found (may exceed max; only max stored). */
int phc_plant_io_split_fields(char *s, char delim, char **fields, int max);
/* The whole field as a number: 0, or -1 when it is empty or not all used
 * (strtol: also on overflow). */
int phc_plant_io_parse_double(const char *s, double *x);
int phc_plant_io_parse_long(const char *s, long *x);
/* Fields first..last-1 as numbers into v[first..last-1]; PHC_ERR_INPUT
 * "FILE:LINE: field 'x': expected a number, found 'abc'". */
int phc_plant_io_parse_number_fields(const char *path, size_t number, char *const *f,
                                     const char *const *names, int first, int last, double *v,
                                     phc_error *err);

#endif /* PHC_PLANT_IO_TEXT_H */
