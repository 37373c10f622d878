/* Delimited text tables: see table.h.
 *
 * A small reader of our own rather than libcsv: libcsv does not detect the
 * delimiter, knows nothing of comment lines or whitespace-separated columns,
 * and reports no line numbers, which every message here must carry. */
#include "measurements/table.h"

#include <ctype.h>
#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/c_number.h"
#include "measurements/suggest.h"
#include "measurements/text_file.h"

/* Cells quoted in messages are cut to this many bytes so that one long cell
 * cannot push the file and line out of the fixed-size message. */
#define TABLE_SHOW_MAX 60

/* Delimiter value meaning "runs of spaces and tabs". */
#define TABLE_WHITESPACE '\0'

struct phc_table {
    char *source;      /* path or name, for messages */
    char *text;        /* every header name and cell, each NUL-terminated */
    char **names;      /* ncols pointers into text */
    char **cells;      /* nrows * ncols pointers into text, row-major */
    size_t *lines;     /* nrows 1-based source lines */
    size_t header_line;
    size_t nrows, ncols;
};

/* Parser state: the input, the position, and the growing outputs.  Fields
 * are stored as offsets while the text buffer may still move. */
struct parser {
    const char *in;
    size_t len, pos, line;
    const char *name;
    char delim;
    char *buf;
    size_t buf_len, buf_cap;
    size_t *offs;      /* start of every field in buf */
    size_t n_offs, offs_cap;
    size_t *lines;     /* start line of every data row */
    size_t n_lines, lines_cap;
    phc_error *err;
};

/* Returns `p` grown to at least `need` elements of `size` bytes (capacity
 * doubling, *cap updated), or NULL with `p` untouched when out of memory.
 * Returning the pointer, rather than writing through a void **, keeps the
 * callers' typed pointers free of aliasing casts. */
static void *grow(void *p, size_t *cap, size_t need, size_t size)
{
    size_t n = *cap ? *cap : 16;
    void *q;
    if (need <= *cap)
        return p;
    while (n < need) {
        if (n > SIZE_MAX / 2)
            return NULL;
        n *= 2;
    }
    if (n > SIZE_MAX / size)
        return NULL;
    q = realloc(p, n * size);
    if (q)
        *cap = n;
    return q;
}

static int is_blank(char c)
{
    return c == ' ' || c == '\t';
}

static int is_eol(char c)
{
    return c == '\n' || c == '\r';
}

/* Copies s into out for a message: cut after TABLE_SHOW_MAX bytes (marked
 * "...") and control characters (a quoted line break) turned into blanks, so
 * that the message stays one short line. */
static const char *shorten(const char *s, char *out, size_t size)
{
    size_t n = 0;
    for (; *s && n + 4 < size && n < TABLE_SHOW_MAX; ++s)
        out[n++] = (unsigned char)*s < 32 ? ' ' : *s;
    if (*s && n + 4 <= size) {
        memcpy(out + n, "...", 3);
        n += 3;
    }
    out[n] = '\0';
    return out;
}

static int push_char(struct parser *ps, char c)
{
    char *q = grow(ps->buf, &ps->buf_cap, ps->buf_len + 1, 1);
    if (!q)
        return phc_error_set(ps->err, PHC_ERR_NOMEM, "%s: out of memory", ps->name);
    ps->buf = q;
    ps->buf[ps->buf_len++] = c;
    return 0;
}

static int start_field(struct parser *ps)
{
    size_t *q = grow(ps->offs, &ps->offs_cap, ps->n_offs + 1, sizeof *ps->offs);
    if (!q)
        return phc_error_set(ps->err, PHC_ERR_NOMEM, "%s: out of memory", ps->name);
    ps->offs = q;
    ps->offs[ps->n_offs++] = ps->buf_len;
    return 0;
}

/* Consumes one line end (LF, CRLF or a lone CR) at ps->pos, if any. */
static void skip_eol(struct parser *ps)
{
    if (ps->pos < ps->len && ps->in[ps->pos] == '\r')
        ++ps->pos;
    if (ps->pos < ps->len && ps->in[ps->pos] == '\n')
        ++ps->pos;
    ++ps->line;
}

/* Skips the line at ps->pos if it is blank or a comment; returns 1 if so. */
static int skip_ignorable_line(struct parser *ps)
{
    size_t p = ps->pos;
    while (p < ps->len && is_blank(ps->in[p]))
        ++p;
    if (p < ps->len && ps->in[p] == '#') {
        while (p < ps->len && !is_eol(ps->in[p]))
            ++p;
    } else if (p < ps->len && !is_eol(ps->in[p])) {
        return 0;
    }
    ps->pos = p;
    if (p < ps->len)
        skip_eol(ps);
    return 1;
}

/* The delimiter of the header line at ps->pos: ',' then ';' then tab, looking
 * only outside quotes so that a quoted "mass, g" does not decide it. */
static char detect_delimiter(const struct parser *ps)
{
    int quoted = 0, comma = 0, semicolon = 0, tab = 0;
    size_t p;
    for (p = ps->pos; p < ps->len; ++p) {
        char c = ps->in[p];
        if (c == '"')
            quoted = !quoted;
        else if (quoted)
            continue;
        else if (is_eol(c))
            break;
        else if (c == ',')
            comma = 1;
        else if (c == ';')
            semicolon = 1;
        else if (c == '\t')
            tab = 1;
    }
    return comma ? ',' : semicolon ? ';' : tab ? '\t' : TABLE_WHITESPACE;
}

/* Blanks that may be trimmed: spaces and tabs, unless tab is the delimiter. */
static int is_trimmable(const struct parser *ps, char c)
{
    return c == ' ' || (c == '\t' && ps->delim != '\t');
}

static int is_delim(const struct parser *ps, char c)
{
    return ps->delim == TABLE_WHITESPACE ? is_blank(c) : c == ps->delim;
}

static int nul_byte(struct parser *ps)
{
    return phc_error_set(ps->err, PHC_ERR_INPUT,
                         "%s:%zu: unexpected NUL byte (not a text file?)", ps->name,
                         ps->line);
}

/* The body of a quoted field, ps->pos just after the opening quote. */
static int read_quoted(struct parser *ps)
{
    size_t open_line = ps->line;
    int rc;
    for (;;) {
        char c;
        if (ps->pos >= ps->len)
            return phc_error_set(ps->err, PHC_ERR_INPUT,
                                 "%s:%zu: unterminated quoted field (no closing '\"')",
                                 ps->name, open_line);
        c = ps->in[ps->pos];
        if (c == '"') {
            if (ps->pos + 1 < ps->len && ps->in[ps->pos + 1] == '"') {
                if ((rc = push_char(ps, '"')))
                    return rc;
                ps->pos += 2;
                continue;
            }
            ++ps->pos;
            return 0;
        }
        if (c == '\0')
            return nul_byte(ps);
        if (is_eol(c)) {
            /* A line break inside quotes is data; store it as '\n' whatever
             * the file's line ends, and keep counting lines. */
            skip_eol(ps);
            if ((rc = push_char(ps, '\n')))
                return rc;
            continue;
        }
        if ((rc = push_char(ps, c)))
            return rc;
        ++ps->pos;
    }
}

/* One record (header or row) starting at ps->pos, which is not blank or a
 * comment.  Appends its fields and counts them in *nfields; leaves ps->pos
 * after the record's line end. */
static int read_record(struct parser *ps, size_t *nfields)
{
    int rc;
    *nfields = 0;
    for (;;) {
        char c;
        while (ps->pos < ps->len && is_trimmable(ps, ps->in[ps->pos]))
            ++ps->pos;
        if ((rc = start_field(ps)))
            return rc;
        ++*nfields;
        if (ps->pos < ps->len && ps->in[ps->pos] == '"') {
            size_t after;
            ++ps->pos;
            if ((rc = read_quoted(ps)))
                return rc;
            after = ps->pos;
            while (ps->pos < ps->len && is_trimmable(ps, ps->in[ps->pos]))
                ++ps->pos;
            c = ps->pos < ps->len ? ps->in[ps->pos] : '\n';
            /* In whitespace mode the blanks just skipped were the delimiter. */
            if (ps->delim == TABLE_WHITESPACE && ps->pos > after && !is_eol(c))
                c = ' ';
            if (!is_eol(c) && !is_delim(ps, c))
                return phc_error_set(ps->err, PHC_ERR_INPUT,
                                     "%s:%zu: unexpected '%c' after a closing quote "
                                     "(expected a delimiter or the end of the line)",
                                     ps->name, ps->line, c >= 32 && c < 127 ? c : '?');
        } else {
            /* Unquoted: up to the delimiter or line end; a quote inside is
             * kept literally (e.g. 3" for inches). */
            size_t end;
            while (ps->pos < ps->len && !is_eol(ps->in[ps->pos]) &&
                   !is_delim(ps, ps->in[ps->pos])) {
                if (ps->in[ps->pos] == '\0')
                    return nul_byte(ps);
                if ((rc = push_char(ps, ps->in[ps->pos])))
                    return rc;
                ++ps->pos;
            }
            end = ps->buf_len;
            while (end > ps->offs[ps->n_offs - 1] && is_trimmable(ps, ps->buf[end - 1]))
                --end;
            ps->buf_len = end;
        }
        if ((rc = push_char(ps, '\0')))
            return rc;
        /* Now at a delimiter, a line end or the end of input. */
        if (ps->pos >= ps->len)
            return 0;
        c = ps->in[ps->pos];
        if (is_eol(c)) {
            skip_eol(ps);
            return 0;
        }
        if (ps->delim == TABLE_WHITESPACE) {
            while (ps->pos < ps->len && is_blank(ps->in[ps->pos]))
                ++ps->pos;
            /* Trailing blanks end the line, they do not start a field. */
            if (ps->pos >= ps->len)
                return 0;
            if (is_eol(ps->in[ps->pos])) {
                skip_eol(ps);
                return 0;
            }
        } else {
            ++ps->pos;
        }
    }
}

/* Header names must be non-empty and distinct: a column is found by name. */
static int check_header(struct parser *ps, size_t ncols, size_t line)
{
    size_t i, j;
    for (i = 0; i < ncols; ++i) {
        const char *a = ps->buf + ps->offs[i];
        char shown[TABLE_SHOW_MAX + 8];
        if (!*a)
            return phc_error_set(ps->err, PHC_ERR_INPUT,
                                 "%s:%zu: header: column %zu has an empty name",
                                 ps->name, line, i + 1);
        for (j = 0; j < i; ++j)
            if (!strcmp(a, ps->buf + ps->offs[j]))
                return phc_error_set(ps->err, PHC_ERR_INPUT,
                                     "%s:%zu: header: duplicate column name '%s' "
                                     "(columns %zu and %zu)",
                                     ps->name, line, shorten(a, shown, sizeof shown),
                                     j + 1, i + 1);
    }
    return 0;
}

static int parse_all(struct parser *ps, size_t *ncols_out, size_t *header_line)
{
    size_t ncols = 0, n;
    int rc, have_header = 0;

    /* A UTF-8 byte-order mark, as spreadsheet programs write it. */
    if (ps->len >= 3 && !memcmp(ps->in, "\xEF\xBB\xBF", 3))
        ps->pos = 3;
    while (ps->pos < ps->len) {
        size_t line;
        if (skip_ignorable_line(ps))
            continue;
        line = ps->line;
        if (!have_header)
            ps->delim = detect_delimiter(ps);
        if ((rc = read_record(ps, &n)))
            return rc;
        if (!have_header) {
            if ((rc = check_header(ps, n, line)))
                return rc;
            ncols = n;
            *header_line = line;
            have_header = 1;
            continue;
        }
        if (n != ncols)
            return phc_error_set(ps->err, PHC_ERR_INPUT,
                                 "%s:%zu: ragged row: found %zu field%s, expected %zu "
                                 "(as in the header on line %zu)",
                                 ps->name, line, n, n == 1 ? "" : "s", ncols,
                                 *header_line);
        size_t *q = grow(ps->lines, &ps->lines_cap, ps->n_lines + 1, sizeof *ps->lines);
        if (!q)
            return phc_error_set(ps->err, PHC_ERR_NOMEM, "%s: out of memory", ps->name);
        ps->lines = q;
        ps->lines[ps->n_lines++] = line;
    }
    if (!have_header)
        return phc_error_set(ps->err, PHC_ERR_INPUT,
                             "%s:%zu: no header line (the file is empty or holds only "
                             "comments and blank lines)",
                             ps->name, ps->line);
    *ncols_out = ncols;
    return 0;
}

int phc_table_parse(const char *text, size_t length, const char *name,
                    phc_table **out, phc_error *err)
{
    struct parser ps;
    phc_table *t = NULL;
    size_t ncols = 0, header_line = 0, i;
    int rc;

    if (out)
        *out = NULL;
    if (!out || (!text && length))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_table_parse: invalid argument");
    if (!name)
        name = "<table>";
    memset(&ps, 0, sizeof ps);
    ps.in = text ? text : "";
    ps.len = length;
    ps.line = 1;
    ps.name = name;
    ps.err = err;

    if ((rc = parse_all(&ps, &ncols, &header_line)))
        goto fail;

    rc = PHC_ERR_NOMEM;
    t = calloc(1, sizeof *t);
    if (!t)
        goto fail;
    t->source = malloc(strlen(name) + 1);
    if (!t->source)
        goto fail;
    strcpy(t->source, name);
    t->ncols = ncols;
    t->nrows = ps.n_lines;
    t->header_line = header_line;
    /* The header and every row together made n_offs = (nrows + 1) * ncols
     * fields, so the pointer array below cannot overflow. */
    t->names = malloc((ps.n_offs ? ps.n_offs : 1) * sizeof *t->names);
    if (!t->names)
        goto fail;
    t->text = ps.buf;
    ps.buf = NULL;
    for (i = 0; i < ps.n_offs; ++i)
        t->names[i] = t->text + ps.offs[i];
    t->cells = t->names + ncols;
    t->lines = ps.lines;
    ps.lines = NULL;
    free(ps.offs);
    *out = t;
    phc_error_clear(err);
    return 0;

fail:
    if (rc == PHC_ERR_NOMEM)
        phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", name);
    free(ps.buf);
    free(ps.offs);
    free(ps.lines);
    phc_table_free(t);
    return rc;
}


int phc_table_read(const char *path, phc_table **out, phc_error *err)
{
    char *text = NULL;
    size_t length = 0;
    int rc;

    if (out)
        *out = NULL;
    if (!path || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_table_read: invalid argument");
    if ((rc = phc_read_text_file(path, &text, &length, err)))
        return rc;
    rc = phc_table_parse(text, length, path, out, err);
    free(text);
    return rc;
}

int phc_table_select_rows(const phc_table *t, const size_t *rows, size_t n_rows, phc_table **out, phc_error *err)
{
    if (out)
        *out = NULL;
    if (!t || !out || (n_rows && !rows))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_table_select_rows: invalid argument");
    for (size_t r = 0; r < n_rows; ++r)
        if (rows[r] >= t->nrows)
            return phc_error_set(err, PHC_ERR_INVALID, "phc_table_select_rows: row %zu of %zu", rows[r], t->nrows);
    /* one text buffer: the header names, then the selected cells */
    size_t bytes = 0;
    for (size_t j = 0; j < t->ncols; ++j)
        bytes += strlen(t->names[j]) + 1;
    for (size_t r = 0; r < n_rows; ++r)
        for (size_t j = 0; j < t->ncols; ++j)
            bytes += strlen(t->cells[rows[r] * t->ncols + j]) + 1;
    phc_table *s = calloc(1, sizeof *s);
    if (!s)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", t->source);
    s->source = malloc(strlen(t->source) + 1);
    s->text = malloc(bytes ? bytes : 1);
    const size_t n_names = (n_rows + 1) * t->ncols;
    s->names = malloc((n_names ? n_names : 1) * sizeof *s->names);
    s->lines = malloc((n_rows ? n_rows : 1) * sizeof *s->lines);
    if (!s->source || !s->text || !s->names || !s->lines) {
        phc_table_free(s);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", t->source);
    }
    strcpy(s->source, t->source);
    s->ncols = t->ncols;
    s->nrows = n_rows;
    s->header_line = t->header_line;
    s->cells = s->names + t->ncols;
    char *at = s->text;
    for (size_t k = 0; k < (n_rows + 1) * t->ncols; ++k) {
        const size_t r = k / t->ncols, j = k % t->ncols;
        const char *src = r == 0 ? t->names[j] : t->cells[rows[r - 1] * t->ncols + j];
        const size_t len = strlen(src) + 1;
        memcpy(at, src, len);
        s->names[k] = at;
        at += len;
    }
    for (size_t r = 0; r < n_rows; ++r)
        s->lines[r] = t->lines[rows[r]];
    *out = s;
    phc_error_clear(err);
    return PHC_OK;
}

void phc_table_free(phc_table *t)
{
    if (!t)
        return;
    free(t->source);
    free(t->text);
    free(t->names);
    free(t->lines);
    free(t);
}

const char *phc_table_source(const phc_table *t)
{
    return t ? t->source : NULL;
}

size_t phc_table_rows(const phc_table *t)
{
    return t ? t->nrows : 0;
}

size_t phc_table_columns(const phc_table *t)
{
    return t ? t->ncols : 0;
}

const char *phc_table_column_name(const phc_table *t, size_t column)
{
    return t && column < t->ncols ? t->names[column] : NULL;
}

long phc_table_find(const phc_table *t, const char *name)
{
    size_t i;
    if (!t || !name)
        return -1;
    for (i = 0; i < t->ncols; ++i)
        if (!strcmp(t->names[i], name))
            return (long)i;
    return -1;
}

const char *phc_table_cell(const phc_table *t, size_t row, size_t column)
{
    if (!t || row >= t->nrows || column >= t->ncols)
        return NULL;
    return t->cells[row * t->ncols + column];
}

size_t phc_table_row_line(const phc_table *t, size_t row)
{
    return t && row < t->nrows ? t->lines[row] : 0;
}

/* "unknown column 'x'; did you mean 'y'? columns: 'a', 'b'" */
static int unknown_column(const phc_table *t, const char *name, phc_error *err)
{
    char list[PHC_ERROR_MESSAGE_SIZE];
    char shown[TABLE_SHOW_MAX + 8], item[TABLE_SHOW_MAX + 8];
    size_t used = 0, i;
    const char *near = phc_suggest(name, (const char *const *)t->names, t->ncols);

    list[0] = '\0';
    for (i = 0; i < t->ncols && used < sizeof list; ++i) {
        int n = snprintf(list + used, sizeof list - used, "%s'%s'", i ? ", " : "",
                         shorten(t->names[i], item, sizeof item));
        if (n < 0)
            break;
        used += (size_t)n;
    }
    if (near)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: unknown column '%s'; did you mean '%s'? "
                             "(columns: %s)",
                             t->source, t->header_line, shorten(name, shown, sizeof shown),
                             shorten(near, item, sizeof item), list);
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: unknown column '%s' (columns: %s)",
                         t->source, t->header_line, shorten(name, shown, sizeof shown),
                         list);
}

int phc_table_column_numbers(const phc_table *t, const char *name,
                             double **values, phc_error *err)
{
    return phc_table_column_numbers_rows(t, name, NULL, t ? t->nrows : 0, values, err);
}

int phc_table_column_numbers_rows(const phc_table *t, const char *name, const size_t *rows,
                                  size_t n_rows, double **values, phc_error *err)
{
    double *v = NULL;
    size_t i;
    long column;
    size_t r;
    int rc;
    phc_c_numeric c_numeric = {(locale_t)0, (locale_t)0}; /* data files use C syntax */
    char shown_name[TABLE_SHOW_MAX + 8];

    if (values)
        *values = NULL;
    if (!t || !name || !values)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_table_column_numbers: invalid argument");
    column = phc_table_find(t, name);
    if (column < 0)
        return unknown_column(t, name, err);
    for (i = 0; rows && i < n_rows; ++i)
        if (rows[i] >= t->nrows)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_table_column_numbers_rows: row %zu out of range", rows[i]);
    if (n_rows == 0) {
        phc_error_clear(err);
        return 0;
    }
    shorten(name, shown_name, sizeof shown_name);
    rc = PHC_ERR_NOMEM;
    if (n_rows > SIZE_MAX / sizeof *v)
        goto fail;
    v = malloc(n_rows * sizeof *v);
    if (!v)
        goto fail;
    if (phc_c_numeric_begin(&c_numeric) != 0)
        goto fail;
    for (i = 0; i < n_rows; ++i) {
        r = rows ? rows[i] : i;
        const char *cell = t->cells[r * t->ncols + (size_t)column];
        char shown[TABLE_SHOW_MAX + 8];
        char *end;
        double x;
        if (!*cell) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column '%s': expected a finite number, "
                               "found an empty cell",
                               t->source, t->lines[r], shown_name);
            goto fail;
        }
        errno = 0;
        x = strtod(cell, &end);
        /* Leading blanks can only come from a quoted cell; like trailing
         * ones (which strtod would not consume) they make it text. */
        if (end == cell || *end || isspace((unsigned char)cell[0]) || !isfinite(x)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column '%s': expected a finite number, found '%s'",
                               t->source, t->lines[r], shown_name,
                               shorten(cell, shown, sizeof shown));
            goto fail;
        }
        v[i] = x;
    }
    phc_c_numeric_end(&c_numeric);
    *values = v;
    phc_error_clear(err);
    return 0;

fail:
    if (rc == PHC_ERR_NOMEM)
        phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", t->source);
    phc_c_numeric_end(&c_numeric);
    free(v);
    return rc;
}

/* Appends text to a growing buffer; 0 when out of memory. */
static int append(char **buf, size_t *len, size_t *cap, const char *text, size_t n)
{
    if (*len + n + 1 > *cap) {
        size_t grown = *cap ? *cap : 256;
        while (*len + n + 1 > grown)
            grown *= 2;
        char *b = realloc(*buf, grown);
        if (!b)
            return 0;
        *buf = b;
        *cap = grown;
    }
    memcpy(*buf + *len, text, n);
    *len += n;
    (*buf)[*len] = '\0';
    return 1;
}

int phc_table_from_columns(const char *name, size_t n_columns, const char *const *names,
                           const double *const *columns, size_t n_rows, phc_table **out,
                           phc_error *err)
{
    *out = NULL;
    if (!name)
        name = "table";
    if (n_columns == 0 || !names || (n_rows > 0 && !columns))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: a table needs at least one named column", name);
    for (size_t j = 0; j < n_columns; ++j)
        if (!names[j] || !names[j][0] || (n_rows > 0 && !columns[j]))
            return phc_error_set(err, PHC_ERR_INVALID, "%s: column %zu has no %s", name, j + 1,
                                 !names[j] || !names[j][0] ? "name" : "values");
    /* Written as CSV text and parsed, so that a table built here behaves
     * exactly as one read from a file (names quoted, "" for a quote). */
    char *text = NULL;
    size_t len = 0, cap = 0;
    int ok = 1;
    for (size_t j = 0; j < n_columns && ok; ++j) {
        ok = append(&text, &len, &cap, j ? ",\"" : "\"", j ? 2 : 1);
        for (const char *c = names[j]; *c && ok; ++c)
            ok = append(&text, &len, &cap, *c == '"' ? "\"\"" : c, *c == '"' ? 2 : 1);
        ok = ok && append(&text, &len, &cap, "\"", 1);
    }
    ok = ok && append(&text, &len, &cap, "\n", 1);
    for (size_t i = 0; i < n_rows && ok; ++i)
        for (size_t j = 0; j < n_columns && ok; ++j) {
            char cell[40];
            const int n = snprintf(cell, sizeof cell, "%s%.17g%s", j ? "," : "", columns[j][i],
                                   j + 1 == n_columns ? "\n" : "");
            ok = append(&text, &len, &cap, cell, (size_t)n);
        }
    if (!ok) {
        free(text);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    const int rc = phc_table_parse(text, len, name, out, err);
    free(text);
    return rc;
}
