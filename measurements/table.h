/* Delimited text tables (CSV) with line-and-column error messages.
 *
 * A table is read whole into strings; numeric columns are converted on
 * request, so a bad cell in a column nobody uses is not an error, and a bad
 * cell in a used column is reported with its file, line and column name:
 *     weights.csv:17: column 'mass_g': expected a number, found 'n/a'
 *
 * Format: the first non-comment, non-blank line is the header.  The delimiter
 * is detected from the header line: ',' then ';' then tab; if none of these
 * occurs, runs of spaces/tabs separate fields.  Fields may be quoted with
 * double quotes (RFC 4180, "" inside quotes is a quote).  Lines whose first
 * non-blank character is '#' and blank lines are skipped.  Leading and
 * trailing blanks of unquoted fields are trimmed.  A UTF-8 byte-order mark is
 * ignored.  CRLF line ends are accepted (and lone CR).
 *
 * Details the rules above leave open: a quoted field may span lines (its
 * line breaks are stored as '\n'; the row's line is where it starts); a '"'
 * inside an unquoted field is kept literally (3" long); text after a closing
 * quote other than blanks and the delimiter is an error; a delimiter at the
 * end of a line starts one more (empty) field; a NUL byte is an error. */
#ifndef PHC_TABLE_H
#define PHC_TABLE_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_table phc_table;

/* Reads `path`.  Errors (PHC_ERR_IO, PHC_ERR_INPUT) name the file and line:
 * unreadable file, no header, empty or duplicate column names, a row whose
 * number of fields differs from the header ("ragged row": says found/expected),
 * an unterminated quote.  A table with a header and no rows is valid (0 rows).
 * On success *out owns everything; free with phc_table_free. */
int phc_table_read(const char *path, phc_table **out, phc_error *err);

/* Same, from a buffer in memory; `name` is used in messages in place of a path. */
int phc_table_parse(const char *text, size_t length, const char *name,
                    phc_table **out, phc_error *err);

/* A table from C arrays, for programs that build data sets without a file:
 * n_columns columns named names[j] holding columns[j][0..n_rows-1].  Values
 * are kept with 17 significant digits (they convert back exactly); a NaN or
 * infinity is kept and refused when a data set converts that column.  Row i
 * is reported as line i + 2 of `name` (the header being line 1). */
int phc_table_from_columns(const char *name, size_t n_columns, const char *const *names,
                           const double *const *columns, size_t n_rows, phc_table **out,
                           phc_error *err);

void phc_table_free(phc_table *t); /* accepts NULL */

/* A new table holding the rows rows[0..n_rows-1] of t (0-based, in the
 * order given) under the same header and source name; each row keeps its
 * source line, so messages about the subset still point into the file.
 * Used to split one table into groups (phytocal fit --each). */
int phc_table_select_rows(const phc_table *t, const size_t *rows, size_t n_rows, phc_table **out,
                          phc_error *err);


const char *phc_table_source(const phc_table *t);   /* path or name given */
size_t phc_table_rows(const phc_table *t);
size_t phc_table_columns(const phc_table *t);
const char *phc_table_column_name(const phc_table *t, size_t column);
/* Index of the column with this exact name, or -1. */
long phc_table_find(const phc_table *t, const char *name);
/* The raw text of a cell (trimmed, unquoted). */
const char *phc_table_cell(const phc_table *t, size_t row, size_t column);
/* 1-based line number in the source file where the row starts. */
size_t phc_table_row_line(const phc_table *t, size_t row);

/* Converts the named column to doubles into a new malloc'd array of
 * phc_table_rows() values (*values is NULL for 0 rows).  Every cell must be a
 * finite number in C syntax (strtod, whole cell consumed); an empty cell,
 * text, "nan" or "inf" is PHC_ERR_INPUT with a message
 *     FILE:LINE: column 'NAME': expected a finite number, found 'CELL'
 * (for an empty cell: found an empty cell).  An unknown column name is
 * PHC_ERR_INPUT naming the columns that exist and the nearest match. */
int phc_table_column_numbers(const phc_table *t, const char *name,
                             double **values, phc_error *err);
/* The same for the rows rows[0..n_rows-1] only (0-based row indices, in the
 * order given); *values has n_rows entries. */
int phc_table_column_numbers_rows(const phc_table *t, const char *name, const size_t *rows,
                                  size_t n_rows, double **values, phc_error *err);

#endif /* PHC_TABLE_H */
