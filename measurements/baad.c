/* BAAD study folders (see baad.h). */
#include "measurements/baad.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "measurements/c_number.h"
#include "measurements/geo.h"
#include "measurements/table.h"
#include "measurements/units.h"

/* One BAAD variable of the study: its values for every row. */
typedef struct baad_var {
    char *name;        /* BAAD name, e.g. "d.ba" */
    int numeric;
    char *unit;        /* canonical unit (BAAD spelling) of numeric variables, or NULL */
    long column;       /* data.csv column it was mapped from, or -1 */
    double *num;       /* numeric values in `unit` (NAN = absent), or NULL */
    const char **text; /* current text per row (NULL = absent) */
} baad_var;

struct phc_baad_study {
    char *name;
    phc_table *data;
    size_t n;
    phc_baad_row *rows;
    baad_var *vars;
    size_t n_vars, cap_vars;
    char **strings; /* owned strings (dataNew values, flag reasons) */
    size_t n_strings, cap_strings;
    const char **species;
    size_t n_species;
    phc_baad_change *changes;
    size_t n_changes;
    double site_shift;
    char *inputs[6]; /* the files read, as opened (phc_baad_inputs) */
    size_t n_inputs;
    char *na[8];           /* dataImportOptions.csv na.strings (R's read.csv) */
    size_t n_na;
    const char **warnings; /* into strings */
    size_t n_warnings, cap_warnings;
    phc_baad_counts counts;
};

/* ---- small helpers ------------------------------------------------------ */

static int is_na(const char *t)
{
    return !t || !*t || !strcmp(t, "NA");
}

/* Absent: empty, "NA" or one of the study's na.strings. */
static int is_absent(const phc_baad_study *s, const char *t)
{
    size_t k;
    if (is_na(t))
        return 1;
    for (k = 0; k < s->n_na; ++k)
        if (!strcmp(t, s->na[k]))
            return 1;
    return 0;
}

/* A whole cell as a number in C syntax; 0 on success. */
static int parse_number(const char *t, double *v)
{
    char *end = NULL;
    if (is_na(t))
        return -1;
    *v = phc_strtod_c(t, &end);
    if (end == t)
        return -1;
    while (*end && isspace((unsigned char)*end))
        ++end;
    return *end ? -1 : 0;
}

/* Copies text into the study's string pool; NULL for NULL or out of memory
 * (callers check *oom). */
static const char *keep(phc_baad_study *s, const char *text, int *oom)
{
    char *c;
    if (!text)
        return NULL;
    if (s->n_strings == s->cap_strings) {
        size_t cap = s->cap_strings ? 2 * s->cap_strings : 64;
        char **p = realloc(s->strings, cap * sizeof *p);
        if (!p) {
            *oom = 1;
            return NULL;
        }
        s->strings = p;
        s->cap_strings = cap;
    }
    c = malloc(strlen(text) + 1);
    if (!c) {
        *oom = 1;
        return NULL;
    }
    strcpy(c, text);
    s->strings[s->n_strings++] = c;
    return c;
}

static char *dup_str(const char *t)
{
    char *c = malloc(strlen(t) + 1);
    if (c)
        strcpy(c, t);
    return c;
}

/* A warning sentence, kept in the study's pool. */
static int warn(phc_baad_study *s, const char *text)
{
    int oom = 0;
    const char *w;
    if (s->n_warnings == s->cap_warnings) {
        size_t cap = s->cap_warnings ? 2 * s->cap_warnings : 8;
        const char **p = realloc(s->warnings, cap * sizeof *p);
        if (!p)
            return PHC_ERR_NOMEM;
        s->warnings = p;
        s->cap_warnings = cap;
    }
    w = keep(s, text, &oom);
    if (oom)
        return PHC_ERR_NOMEM;
    s->warnings[s->n_warnings++] = w;
    return PHC_OK;
}

/* `t` without leading and trailing blanks: t itself when it has none, else
 * a pooled copy (counted in counts.trimmed).  NULL stays NULL. */
static const char *trimmed(phc_baad_study *s, const char *t, int *oom)
{
    size_t a = 0, b;
    char buf[1024];
    if (!t)
        return NULL;
    b = strlen(t);
    while (a < b && isspace((unsigned char)t[a]))
        ++a;
    while (b > a && isspace((unsigned char)t[b - 1]))
        --b;
    if (a == 0 && t[b] == '\0')
        return t;
    s->counts.trimmed++;
    if (b - a < sizeof buf) {
        memcpy(buf, t + a, b - a);
        buf[b - a] = '\0';
        return keep(s, buf, oom);
    }
    {
        char *c = malloc(b - a + 1);
        const char *k;
        if (!c) {
            *oom = 1;
            return NULL;
        }
        memcpy(c, t + a, b - a);
        c[b - a] = '\0';
        k = keep(s, c, oom);
        free(c);
        return k;
    }
}

/* ---- BAAD's conversion expressions ---------------------------------------
 * config/variableConversion.csv gives each conversion as an R expression in
 * x: "x/1000", "1/x", "10/x", "x*10^-6", "x/(10^6)", "x*14e-6".  The
 * grammar read here (R's precedence: ^ binds tighter than unary minus, and
 * is right-associative):
 *   expr  = term {('+'|'-') term}      term  = unary {('*'|'/') unary}
 *   unary = '-' unary | power          power = atom ['^' unary]
 *   atom  = number | 'x' | '(' expr ')'
 * Each parser returns 0 and advances *p, or -1 on a syntax error. */
static int conv_expr(const char **p, double x, double *v);

static void conv_blanks(const char **p)
{
    while (**p == ' ' || **p == '\t')
        ++*p;
}

static int conv_atom(const char **p, double x, double *v)
{
    char *end = NULL;
    conv_blanks(p);
    if (**p == 'x') {
        ++*p;
        *v = x;
        return 0;
    }
    if (**p == '(') {
        ++*p;
        if (conv_expr(p, x, v))
            return -1;
        conv_blanks(p);
        if (**p != ')')
            return -1;
        ++*p;
        return 0;
    }
    if (!isdigit((unsigned char)**p) && **p != '.')
        return -1;
    *v = phc_strtod_c(*p, &end);
    if (end == *p)
        return -1;
    *p = end;
    return 0;
}

static int conv_unary(const char **p, double x, double *v);

static int conv_power(const char **p, double x, double *v)
{
    double e;
    if (conv_atom(p, x, v))
        return -1;
    conv_blanks(p);
    if (**p != '^')
        return 0;
    ++*p;
    if (conv_unary(p, x, &e))
        return -1;
    *v = pow(*v, e);
    return 0;
}

static int conv_unary(const char **p, double x, double *v)
{
    conv_blanks(p);
    if (**p == '-') {
        ++*p;
        if (conv_unary(p, x, v))
            return -1;
        *v = -*v;
        return 0;
    }
    return conv_power(p, x, v);
}

static int conv_term(const char **p, double x, double *v)
{
    double r;
    if (conv_unary(p, x, v))
        return -1;
    for (;;) {
        char op;
        conv_blanks(p);
        op = **p;
        if (op != '*' && op != '/')
            return 0;
        ++*p;
        if (conv_unary(p, x, &r))
            return -1;
        *v = op == '*' ? *v * r : *v / r;
    }
}

static int conv_expr(const char **p, double x, double *v)
{
    double r;
    if (conv_term(p, x, v))
        return -1;
    for (;;) {
        char op;
        conv_blanks(p);
        op = **p;
        if (op != '+' && op != '-')
            return 0;
        ++*p;
        if (conv_term(p, x, &r))
            return -1;
        *v = op == '+' ? *v + r : *v - r;
    }
}

/* The whole expression at x; 0 on success. */
static int conv_eval(const char *expr, double x, double *v)
{
    const char *p = expr;
    if (conv_expr(&p, x, v))
        return -1;
    conv_blanks(&p);
    return *p ? -1 : 0;
}

static long var_find(const phc_baad_study *s, const char *name)
{
    size_t k;
    for (k = 0; k < s->n_vars; ++k)
        if (!strcmp(s->vars[k].name, name))
            return (long)k;
    return -1;
}

/* Adds an empty variable (all values absent); returns its index or -1. */
static long var_add(phc_baad_study *s, const char *name, int numeric, const char *unit)
{
    baad_var *v;
    size_t i;
    if (s->n_vars == s->cap_vars) {
        size_t cap = s->cap_vars ? 2 * s->cap_vars : 16;
        baad_var *p = realloc(s->vars, cap * sizeof *p);
        if (!p)
            return -1;
        s->vars = p;
        s->cap_vars = cap;
    }
    v = &s->vars[s->n_vars];
    memset(v, 0, sizeof *v);
    v->column = -1;
    v->numeric = numeric;
    v->name = dup_str(name);
    v->unit = unit ? dup_str(unit) : NULL;
    v->text = calloc(s->n ? s->n : 1, sizeof *v->text);
    v->num = numeric ? malloc((s->n ? s->n : 1) * sizeof *v->num) : NULL;
    if (!v->name || (unit && !v->unit) || !v->text || (numeric && !v->num)) {
        free(v->name);
        free(v->unit);
        free(v->text);
        free(v->num);
        return -1;
    }
    for (i = 0; numeric && i < s->n; ++i)
        v->num[i] = NAN;
    return (long)s->n_vars++;
}

/* The units of the phc_baad_row fields are fixed by baad.h whatever
 * variableDefinitions.csv says (they agree for BAAD's own file). */
static const char *fixed_unit(const char *name)
{
    static const char *const table[][2] = {
        {"d.ba", "m"},  {"h.t", "m"},   {"m.rt", "kg"},      {"m.st", "kg"},
        {"m.lf", "kg"}, {"m.so", "kg"}, {"age", "yr"},       {"latitude", "deg"},
        {"longitude", "deg"},
    };
    size_t k;
    for (k = 0; k < sizeof table / sizeof table[0]; ++k)
        if (!strcmp(table[k][0], name))
            return table[k][1];
    return NULL;
}

/* BAAD's unit spelling -> UDUNITS-2's.  UDUNITS-2 accepts plurals
 * ("months", "years") and BAAD's mm, cm, g, kg, cm2, g/cm2, m2/m2, kg/m3 as
 * they are; the one BAAD symbol it lacks is "deg", which BAAD uses for
 * angles (latitude, longitude) and for mean annual temperature (mat, degC). */
static const char *udunits_spelling(const char *unit, const char *variable)
{
    if (!strcmp(unit, "deg"))
        return !strcmp(variable, "mat") ? "degC" : "arc_degree";
    return unit;
}

static int is_coordinate(const char *name, phc_geo_axis *axis)
{
    if (!strcmp(name, "latitude")) {
        *axis = PHC_GEO_LATITUDE;
        return 1;
    }
    if (!strcmp(name, "longitude")) {
        *axis = PHC_GEO_LONGITUDE;
        return 1;
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of v[0..n-1] (n >= 1); reorders v. */
static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Robust spread 1.4826 * MAD of v about m, floored; `work` has n slots. */
static double robust_spread(const double *v, size_t n, double m, double *work)
{
    size_t i;
    double s;
    for (i = 0; i < n; ++i)
        work[i] = fabs(v[i] - m);
    s = 1.4826 * median(work, n);
    return s > PHC_BAAD_SPREAD_FLOOR ? s : PHC_BAAD_SPREAD_FLOOR;
}

/* Appends a reason to row i (joined by "; ") and raises its flag. */
static int add_flag(phc_baad_study *s, size_t i, int flag, const char *reason)
{
    phc_baad_row *r = &s->rows[i];
    int oom = 0;
    if (r->flag_reason) {
        size_t len = strlen(r->flag_reason) + strlen(reason) + 3;
        char *b = malloc(len);
        if (!b)
            return PHC_ERR_NOMEM;
        snprintf(b, len, "%s; %s", r->flag_reason, reason);
        r->flag_reason = keep(s, b, &oom);
        free(b);
    } else {
        r->flag_reason = keep(s, reason, &oom);
    }
    if (oom)
        return PHC_ERR_NOMEM;
    if (flag > r->flag)
        r->flag = flag;
    return PHC_OK;
}

/* ---- the steps of phc_baad_read ----------------------------------------- */

/* Reads one CSV of the folder; `optional` files that do not exist give
 * *t = NULL and success.  A file read is added to s->inputs. */
static int read_csv(phc_baad_study *s, const char *dir, const char *file, int optional,
                    phc_table **t, phc_error *err)
{
    char path[4096];
    FILE *f;
    *t = NULL;
    if ((size_t)snprintf(path, sizeof path, "%s/%s", dir, file) >= sizeof path)
        return phc_error_set(err, PHC_ERR_INPUT, "%s/%s: path too long", dir, file);
    if (optional) {
        f = fopen(path, "rb");
        if (!f)
            return PHC_OK;
        fclose(f);
    }
    int rc = phc_table_read(path, t, err);
    if (rc)
        return rc;
    if (s->n_inputs >= sizeof s->inputs / sizeof s->inputs[0] ||
        !(s->inputs[s->n_inputs] = dup_str(path)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    s->n_inputs++;
    return PHC_OK;
}

/* Adds path to the files read. */
static int add_input(phc_baad_study *s, const char *path, phc_error *err)
{
    if (s->n_inputs >= sizeof s->inputs / sizeof s->inputs[0] ||
        !(s->inputs[s->n_inputs] = dup_str(path)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    s->n_inputs++;
    return PHC_OK;
}

/* dataImportOptions.csv (optional): the options BAAD's build passes to R's
 * read.csv for data.csv.  Its first line is a header ("name","data.csv");
 * then one option a line: header (TRUE), skip (lines before the header),
 * na.strings (a cell text that means "absent", any number of lines).
 * name must be data.csv and header TRUE (every BAAD study); *skip out. */
static int read_import_options(phc_baad_study *s, const char *dir, size_t *skip, phc_error *err)
{
    phc_table *t = NULL;
    size_t r;
    int rc;
    *skip = 0;
    if ((rc = read_csv(s, dir, "dataImportOptions.csv", 1, &t, err)) || !t)
        return rc;
    if (phc_table_columns(t) != 2 || strcmp(phc_table_column_name(t, 0), "name") ||
        strcmp(phc_table_column_name(t, 1), "data.csv")) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:1: expected the header \"name\",\"data.csv\" (BAAD reads data.csv)",
                           phc_table_source(t));
        goto done;
    }
    for (r = 0; r < phc_table_rows(t); ++r) {
        const char *key = phc_table_cell(t, r, 0), *val = phc_table_cell(t, r, 1);
        size_t line = phc_table_row_line(t, r);
        double x;
        if (!strcmp(key, "skip")) {
            if (parse_number(val, &x) || x < 0 || x > 1e6 || x != floor(x)) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: skip must be a whole number of lines, found '%s'",
                                   phc_table_source(t), line, val);
                goto done;
            }
            *skip = (size_t)x;
        } else if (!strcmp(key, "header")) {
            if (strcmp(val, "TRUE")) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: header '%s': only data.csv files with a header "
                                   "line (TRUE) are read",
                                   phc_table_source(t), line, val);
                goto done;
            }
        } else if (!strcmp(key, "na.strings")) {
            if (s->n_na < sizeof s->na / sizeof s->na[0]) {
                if (!(s->na[s->n_na] = dup_str(val))) {
                    rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                    goto done;
                }
                s->n_na++;
            }
        }
        /* other read.csv options do not change what is read here */
    }
done:
    phc_table_free(t);
    return rc;
}

/* One CSV field of the header line at *p (stops at ',' or the line end);
 * writes the unquoted text to out (cap bytes).  Returns 0, or -1 when a
 * quoted field does not close on this line. */
static int header_field(const char **p, char *out, size_t cap)
{
    const char *q = *p;
    size_t n = 0;
    while (*q == ' ' || *q == '\t')
        ++q;
    if (*q == '"') {
        ++q;
        for (;;) {
            if (!*q || *q == '\n' || *q == '\r')
                return -1;
            if (*q == '"') {
                if (q[1] == '"') {
                    if (n + 1 < cap)
                        out[n++] = '"';
                    q += 2;
                    continue;
                }
                ++q;
                break;
            }
            if (n + 1 < cap)
                out[n++] = *q;
            ++q;
        }
        while (*q && *q != ',' && *q != '\n' && *q != '\r')
            ++q;
    } else {
        while (*q && *q != ',' && *q != '\n' && *q != '\r') {
            if (n + 1 < cap)
                out[n++] = *q;
            ++q;
        }
        while (n && (out[n - 1] == ' ' || out[n - 1] == '\t'))
            --n;
    }
    out[n] = '\0';
    *p = q;
    return 0;
}

/* data.csv as BAAD's build reads it (R's read.csv with the study's
 * dataImportOptions.csv, check.names = FALSE): the first `skip` lines are
 * not read (each becomes a '#' comment line here, so line numbers stay the
 * file's), and a header with empty or repeated names (R keeps them; a
 * mapping finds the first) gets unique names for the columns no mapping can
 * name: "(column N)" for an empty name, "NAME (column N)" for a repeat. */
static int read_data(phc_baad_study *s, const char *dir, size_t skip, phc_error *err)
{
    char path[4096];
    FILE *f;
    char *buf = NULL, *fixed = NULL;
    size_t len = 0, cap = 0, pos = 0, line, hdr, hdr_end;
    int rc, changed = 0;
    if ((size_t)snprintf(path, sizeof path, "%s/data.csv", dir) >= sizeof path)
        return phc_error_set(err, PHC_ERR_INPUT, "%s/data.csv: path too long", dir);
    if (!(f = fopen(path, "rb")))
        return phc_table_read(path, &s->data, err); /* its message names the path */
    for (;;) {
        size_t got;
        if (cap - len < 65536) {
            char *b = realloc(buf, cap + 65536 + 1);
            if (!b) {
                fclose(f);
                free(buf);
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", path);
            }
            buf = b;
            cap += 65536;
        }
        got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0)
            break;
    }
    fclose(f);
    buf[len] = '\0';
    /* the skipped lines become comments */
    for (line = 0; line < skip && pos < len; ++line) {
        if (buf[pos] != '\n' && buf[pos] != '\r')
            buf[pos] = '#';
        while (pos < len && buf[pos] != '\n' && buf[pos] != '\r')
            ++pos;
        if (pos < len && buf[pos] == '\r' && pos + 1 < len && buf[pos + 1] == '\n')
            ++pos;
        if (pos < len)
            ++pos;
    }
    /* the header: the next line that is neither blank nor a comment */
    hdr = pos;
    for (;;) {
        size_t b = hdr;
        while (b < len && (buf[b] == ' ' || buf[b] == '\t'))
            ++b;
        if (b < len && buf[b] != '#' && buf[b] != '\n' && buf[b] != '\r')
            break;
        while (hdr < len && buf[hdr] != '\n')
            ++hdr;
        if (hdr >= len)
            break;
        ++hdr;
    }
    hdr_end = hdr;
    while (hdr_end < len && buf[hdr_end] != '\n' && buf[hdr_end] != '\r')
        ++hdr_end;
    if (hdr < len && memchr(buf + hdr, ',', hdr_end - hdr)) {
        /* rebuild the header with unique, non-empty names */
        size_t ncap = 4 * (hdr_end - hdr) + 4096, nlen = 0, ncol = 0;
        char **names = NULL;
        const char *p = buf + hdr;
        int ok = 1;
        if (hdr == 0 && len >= 3 && !memcmp(buf, "\xEF\xBB\xBF", 3))
            p += 3;
        fixed = malloc(ncap);
        names = malloc(((hdr_end - hdr) + 2) * sizeof *names);
        if (!fixed || !names) {
            free(fixed);
            free(names);
            free(buf);
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", path);
        }
        for (;;) {
            char field[1024], name[1200];
            size_t k;
            if (header_field(&p, field, sizeof field)) {
                ok = 0;
                break;
            }
            if (!*field) {
                snprintf(name, sizeof name, "(column %zu)", ncol + 1);
                changed = 1;
            } else {
                snprintf(name, sizeof name, "%s", field);
                for (k = 0; k < ncol; ++k)
                    if (!strcmp(names[k], field))
                        break;
                if (k < ncol) {
                    snprintf(name, sizeof name, "%s (column %zu)", field, ncol + 1);
                    changed = 1;
                }
            }
            if (nlen + 2 * strlen(name) + 4 >= ncap || !(names[ncol] = dup_str(field))) {
                ok = 0;
                break;
            }
            fixed[nlen++] = '"';
            for (k = 0; name[k]; ++k) {
                if (name[k] == '"')
                    fixed[nlen++] = '"';
                fixed[nlen++] = name[k];
            }
            fixed[nlen++] = '"';
            fixed[nlen] = '\0';
            ++ncol;
            if (*p != ',')
                break;
            fixed[nlen++] = ',';
            ++p;
        }
        while (ncol)
            free(names[--ncol]);
        free(names);
        if (ok && changed) {
            char *b = malloc(hdr + nlen + (len - hdr_end) + 1);
            if (!b) {
                free(fixed);
                free(buf);
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", path);
            }
            memcpy(b, buf, hdr);
            memcpy(b + hdr, fixed, nlen);
            memcpy(b + hdr + nlen, buf + hdr_end, len - hdr_end);
            len = hdr + nlen + (len - hdr_end);
            b[len] = '\0';
            free(buf);
            buf = b;
        }
        free(fixed);
    }
    rc = phc_table_parse(buf, len, path, &s->data, err);
    free(buf);
    if (rc)
        return rc;
    return add_input(s, path, err);
}

static int need_column(const phc_table *t, const char *name, long *col, phc_error *err)
{
    *col = phc_table_find(t, name);
    if (*col < 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: no column '%s' in the header",
                             phc_table_source(t), name);
    return PHC_OK;
}

/* Row index in variableDefinitions.csv of a BAAD variable, or -1. */
static long def_find(const phc_table *defs, long c_var, const char *name)
{
    size_t r;
    for (r = 0; r < phc_table_rows(defs); ++r)
        if (!strcmp(phc_table_cell(defs, r, (size_t)c_var), name))
            return (long)r;
    return -1;
}

/* Fills a numeric variable from data.csv column `col` through BAAD's
 * expression `expr` (variableConversion.csv) when not NULL, else through the
 * linear conversion c; coordinates go through phc_geo_parse_angle. */
static int fill_numeric(phc_baad_study *s, long k, size_t col, phc_unit_conversion c,
                        const char *expr, phc_error *err)
{
    baad_var *v = &s->vars[k];
    const char *src = phc_table_source(s->data);
    const char *var_in = phc_table_column_name(s->data, col);
    phc_geo_axis axis = PHC_GEO_LATITUDE;
    int coord = is_coordinate(v->name, &axis);
    size_t i, n_bad = 0;
    char first[1024] = "";
    v->column = (long)col;
    for (i = 0; i < s->n; ++i) {
        const char *t = phc_table_cell(s->data, i, col);
        size_t line = phc_table_row_line(s->data, i);
        double x;
        /* A lone dash marks a value not measured (Baltzer2007 data.csv:398,
         * d.ba '-'); R's as.numeric makes it NA in BAAD's build too. */
        int absent = is_absent(s, t) || !strcmp(t, "-");
        v->text[i] = absent ? NULL : t;
        if (absent)
            continue;
        if (coord) {
            char where[512];
            phc_error e2;
            int rc;
            snprintf(where, sizeof where, "%s:%zu: column '%s' (%s)", src, line, var_in,
                     v->name);
            rc = phc_geo_parse_angle(t, axis, where, &x, &e2);
            if (rc == PHC_ERR_INPUT) {
                /* BAAD's build (R's as.numeric) makes it NA; dataNew.csv
                 * usually gives the site */
                if (!n_bad++)
                    snprintf(first, sizeof first, "%s", e2.message);
                v->text[i] = NULL;
                continue;
            }
            if (rc) {
                if (err)
                    *err = e2;
                return phc_error_prefix(err, rc, "%s", src);
            }
        } else if (parse_number(t, &x)) {
            /* '#N/A', '#NULL!', '?', '24_5': R's as.numeric in BAAD's build
             * makes such a cell NA; so does this reader, with a warning */
            if (!n_bad++)
                snprintf(first, sizeof first, "%s:%zu: column '%s' (%s): '%s' is not a number",
                         src, line, var_in, v->name, t);
            v->text[i] = NULL;
            continue;
        }
        if (expr) {
            double y;
            if (conv_eval(expr, x, &y)) /* checked at x = 1 before: cannot fail */
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': cannot convert '%s' by '%s'",
                                     src, line, var_in, t, expr);
            v->num[i] = y;
        } else {
            v->num[i] = phc_unit_apply(c, x);
        }
    }
    if (n_bad) {
        char w[1400];
        if (n_bad > 1)
            snprintf(w, sizeof w, "%s; read as absent, as are %zu more such cells of the column",
                     first, n_bad - 1);
        else
            snprintf(w, sizeof w, "%s; read as absent", first);
        s->counts.not_numbers += n_bad;
        if (warn(s, w))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", src);
    }
    return PHC_OK;
}

/* The expression of BAAD's conversion from unit_in to unit (a row of
 * variableConversion.csv, checked at x = 1), or an error naming the mapping
 * line.  `where` is "dataMatchColumns.csv:LINE: ...". */
static int find_conversion(const phc_table *conv, const char *unit_in, const char *unit,
                           const char *where, const char **expr, phc_error *err)
{
    const char *csrc = phc_table_source(conv);
    long c_in, c_out, c_ex;
    size_t r;
    int rc;
    *expr = NULL;
    if ((rc = need_column(conv, "unit_in", &c_in, err)) ||
        (rc = need_column(conv, "unit_out", &c_out, err)) ||
        (rc = need_column(conv, "conversion", &c_ex, err)))
        return rc;
    for (r = 0; r < phc_table_rows(conv); ++r) {
        const char *ex = phc_table_cell(conv, r, (size_t)c_ex);
        double y;
        if (strcmp(phc_table_cell(conv, r, (size_t)c_in), unit_in) ||
            strcmp(phc_table_cell(conv, r, (size_t)c_out), unit))
            continue;
        if (conv_eval(ex, 1.0, &y))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: conversion '%s' (%s -> %s) is not an expression in x "
                                 "this reader knows (numbers, x, + - * / ^ and parentheses)",
                                 csrc, phc_table_row_line(conv, r), ex, unit_in, unit);
        *expr = ex;
        return PHC_OK;
    }
    return phc_error_set(err, PHC_ERR_INPUT,
                         "%s: no conversion from '%s' to '%s' is defined in %s (BAAD converts "
                         "only the unit pairs listed there)",
                         where, unit_in, unit, csrc);
}

/* Step 1: dataMatchColumns.csv.  conv: BAAD's variableConversion.csv, or
 * NULL for UDUNITS-2. */
static int map_columns(phc_baad_study *s, const phc_table *match, const phc_table *defs,
                       const phc_table *conv, phc_units *units, phc_error *err)
{
    const char *msrc = phc_table_source(match), *dsrc = phc_table_source(defs);
    long c_in, c_unit, c_out, c_var, c_units, c_type;
    size_t r;
    int rc, oom = 0;
    if ((rc = need_column(match, "var_in", &c_in, err)) ||
        (rc = need_column(match, "unit_in", &c_unit, err)) ||
        (rc = need_column(match, "var_out", &c_out, err)) ||
        (rc = need_column(defs, "variable", &c_var, err)) ||
        (rc = need_column(defs, "units", &c_units, err)) ||
        (rc = need_column(defs, "type", &c_type, err)))
        return rc;
    for (r = 0; r < phc_table_rows(match); ++r) {
        size_t line = phc_table_row_line(match, r);
        const char *var_in = phc_table_cell(match, r, (size_t)c_in);
        const char *unit_in = phc_table_cell(match, r, (size_t)c_unit);
        const char *var_out = phc_table_cell(match, r, (size_t)c_out);
        long col = phc_table_find(s->data, var_in), def, k;
        const char *unit, *type, *expr = NULL;
        int numeric;
        phc_unit_conversion lin = {1.0, 0.0};
        if (is_na(var_out))
            continue; /* not used by BAAD either */
        if (col < 0) {
            /* BAAD's build runs the study's dataManipulate.R first, which
             * makes such columns; it is not run here */
            char w[1024];
            snprintf(w, sizeof w,
                     "%s:%zu: var_in '%s' (var_out %s) is not a column of data.csv (the study's "
                     "dataManipulate.R makes it; not run here): mapping skipped",
                     msrc, line, var_in, var_out);
            s->counts.skipped_mappings++;
            if (warn(s, w))
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", msrc);
            continue;
        }
        def = def_find(defs, c_var, var_out);
        if (def < 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: var_out '%s' (for '%s') is not a variable of %s", msrc,
                                 line, var_out, var_in, dsrc);
        if (var_find(s, var_out) >= 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: var_out '%s' (for '%s') is mapped twice", msrc, line,
                                 var_out, var_in);
        type = phc_table_cell(defs, (size_t)def, (size_t)c_type);
        numeric = !strcmp(type, "numeric");
        unit = phc_table_cell(defs, (size_t)def, (size_t)c_units);
        if (fixed_unit(var_out))
            unit = fixed_unit(var_out);
        if (is_na(unit))
            unit = NULL;
        k = var_add(s, var_out, numeric, numeric ? unit : NULL);
        if (k < 0)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", msrc);
        if (!numeric) {
            size_t i;
            s->vars[k].column = col;
            for (i = 0; i < s->n; ++i) {
                const char *t = phc_table_cell(s->data, i, (size_t)col);
                s->vars[k].text[i] = is_absent(s, t) ? NULL : trimmed(s, t, &oom);
            }
            if (oom)
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", msrc);
            continue;
        }
        if (unit) {
            char where[512];
            if (is_na(unit_in))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: numeric variable '%s' (column '%s') has no unit_in; "
                                     "expected a unit convertible to '%s'",
                                     msrc, line, var_out, var_in, unit);
            snprintf(where, sizeof where, "%s:%zu: unit_in of '%s' (%s)", msrc, line, var_in,
                     var_out);
            if (strcmp(unit_in, unit)) {
                if (conv)
                    rc = find_conversion(conv, unit_in, unit, where, &expr, err);
                else
                    rc = phc_units_conversion(units, udunits_spelling(unit_in, var_out),
                                              udunits_spelling(unit, var_out), where, &lin, err);
                if (rc)
                    return rc;
                s->counts.conversions++;
            }
        }
        if ((rc = fill_numeric(s, k, (size_t)col, lin, expr, err)))
            return rc;
    }
    return PHC_OK;
}

/* Step 2: raw site coordinates from unmapped Lat/Long columns, for each
 * axis that no column was mapped to. */
static int site_coordinates(phc_baad_study *s, const phc_table *match, phc_error *err)
{
    static const char *const lat_names[] = {"lat", "latitude", NULL};
    static const char *const lon_names[] = {"long", "lon", "longitude", NULL};
    const char *const *names[2] = {lat_names, lon_names};
    const char *var[2] = {"latitude", "longitude"};
    long c_in = phc_table_find(match, "var_in"), c_out = phc_table_find(match, "var_out");
    int a, rc;
    for (a = 0; a < 2; ++a) {
        size_t c;
        if (var_find(s, var[a]) >= 0)
            continue;
        for (c = 0; c < phc_table_columns(s->data); ++c) {
            const char *name = phc_table_column_name(s->data, c);
            int hit = 0, mapped = 0;
            size_t k, r;
            long v;
            phc_unit_conversion id = {1.0, 0.0};
            for (k = 0; names[a][k]; ++k)
                hit |= !strcasecmp(name, names[a][k]);
            if (!hit)
                continue;
            /* only a column that dataMatchColumns leaves unmapped */
            for (r = 0; r < phc_table_rows(match); ++r)
                if (!strcmp(phc_table_cell(match, r, (size_t)c_in), name) &&
                    !is_na(phc_table_cell(match, r, (size_t)c_out)))
                    mapped = 1;
            if (mapped)
                continue;
            v = var_add(s, var[a], 1, "deg");
            if (v < 0)
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            if ((rc = fill_numeric(s, v, c, id, NULL, err)))
                return rc;
            break;
        }
    }
    return PHC_OK;
}

/* Text equal up to leading and trailing blanks. */
static int same_trimmed(const char *a, const char *b)
{
    size_t la, lb;
    while (isspace((unsigned char)*a))
        ++a;
    while (isspace((unsigned char)*b))
        ++b;
    la = strlen(a);
    lb = strlen(b);
    while (la && isspace((unsigned char)a[la - 1]))
        --la;
    while (lb && isspace((unsigned char)b[lb - 1]))
        --lb;
    return la == lb && !memcmp(a, b, la);
}

static int lookup_matches(const char *have, const char *want)
{
    double a, b;
    if (is_na(have) || is_na(want))
        return is_na(have) && is_na(want);
    if (same_trimmed(have, want))
        return 1;
    return !parse_number(have, &a) && !parse_number(want, &b) && a == b;
}

/* Step 3: dataNew.csv.  *coords_set tells whether it set a coordinate. */
static int apply_new(phc_baad_study *s, const phc_table *nw, const phc_table *defs,
                     int *coords_set, phc_error *err)
{
    const char *src = phc_table_source(nw), *dsrc = phc_table_source(defs);
    long c_lv, c_lval, c_nv, c_nval, c_var, c_units, c_type;
    size_t r, i;
    int rc, oom = 0;
    *coords_set = 0;
    if ((rc = need_column(nw, "lookupVariable", &c_lv, err)) ||
        (rc = need_column(nw, "lookupValue", &c_lval, err)) ||
        (rc = need_column(nw, "newVariable", &c_nv, err)) ||
        (rc = need_column(nw, "newValue", &c_nval, err)))
        return rc;
    c_var = phc_table_find(defs, "variable");
    c_units = phc_table_find(defs, "units");
    c_type = phc_table_find(defs, "type");
    s->changes = calloc(phc_table_rows(nw) ? phc_table_rows(nw) : 1, sizeof *s->changes);
    if (!s->changes)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", src);
    for (r = 0; r < phc_table_rows(nw); ++r) {
        size_t line = phc_table_row_line(nw, r);
        const char *lv = trimmed(s, phc_table_cell(nw, r, (size_t)c_lv), &oom);
        const char *lval = trimmed(s, phc_table_cell(nw, r, (size_t)c_lval), &oom);
        const char *nv = trimmed(s, phc_table_cell(nw, r, (size_t)c_nv), &oom);
        const char *nval = trimmed(s, phc_table_cell(nw, r, (size_t)c_nval), &oom);
        phc_baad_change *ch = &s->changes[s->n_changes];
        long def, k, lk = -1, lcol = -1;
        double x = NAN;
        phc_geo_axis axis;
        const char *kept;
        if (oom)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", src);
        if (is_na(nv))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: newVariable is empty", src, line);
        def = def_find(defs, c_var, nv);
        if (def < 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: newVariable '%s' is not a variable of %s", src, line,
                                 nv, dsrc);
        k = var_find(s, nv);
        if (k < 0) {
            const char *unit = phc_table_cell(defs, (size_t)def, (size_t)c_units);
            int numeric = !strcmp(phc_table_cell(defs, (size_t)def, (size_t)c_type), "numeric");
            if (fixed_unit(nv))
                unit = fixed_unit(nv);
            k = var_add(s, nv, numeric, numeric && !is_na(unit) ? unit : NULL);
            if (k < 0)
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", src);
        }
        /* new values of numeric variables are in the canonical unit */
        if (s->vars[k].numeric && !is_na(nval)) {
            if (is_coordinate(nv, &axis)) {
                char where[512];
                snprintf(where, sizeof where, "%s:%zu: newValue of '%s'", src, line, nv);
                if ((rc = phc_geo_parse_angle(nval, axis, where, &x, err)))
                    return rc;
            } else if (parse_number(nval, &x)) {
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: newValue of '%s': expected a number, found '%s'",
                                     src, line, nv, nval);
            }
        }
        if (is_coordinate(nv, &axis))
            *coords_set = 1;
        if (!is_na(lv)) {
            lk = var_find(s, lv);
            if (lk < 0)
                lcol = phc_table_find(s->data, lv);
            if (lk < 0 && lcol < 0)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: lookupVariable '%s' is neither a variable of the "
                                     "study nor a column of %s",
                                     src, line, lv, phc_table_source(s->data));
        }
        kept = is_na(nval) ? NULL : keep(s, nval, &oom);
        ch->line = line;
        ch->lookup_variable = is_na(lv) ? NULL : keep(s, lv, &oom);
        ch->lookup_value = is_na(lv) || is_na(lval) ? NULL : keep(s, lval, &oom);
        ch->new_variable = keep(s, nv, &oom);
        ch->new_value = kept;
        if (oom)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", src);
        for (i = 0; i < s->n; ++i) {
            baad_var *v = &s->vars[k];
            int changed;
            if (lk >= 0 && !lookup_matches(s->vars[lk].text[i], lval))
                continue;
            if (lcol >= 0 && !lookup_matches(phc_table_cell(s->data, i, (size_t)lcol), lval))
                continue;
            ++ch->rows_matched;
            if (v->numeric)
                changed = !(v->num[i] == x || (isnan(v->num[i]) && isnan(x)));
            else
                changed = !((!v->text[i] && !kept) ||
                            (v->text[i] && kept && !strcmp(v->text[i], kept)));
            ch->rows_changed += (size_t)changed;
            v->text[i] = kept;
            if (v->numeric)
                v->num[i] = x;
        }
        ++s->n_changes;
    }
    return PHC_OK;
}

static double value_of(const phc_baad_study *s, long k, size_t i)
{
    return k >= 0 && s->vars[k].numeric ? s->vars[k].num[i] : NAN;
}

/* The text read for variable k in row i, NULL when absent. */
static const char *text_of(const phc_baad_study *s, long k, size_t i)
{
    return k >= 0 && s->vars[k].text ? s->vars[k].text[i] : NULL;
}

/* Variable k of row i is numeric and absent from the file (no text was
 * read there), so a derived value may fill it.  A variable the study maps
 * but never fills may have no arrays at all. */
static int fillable(const phc_baad_study *s, long k, size_t i)
{
    return k >= 0 && s->vars[k].numeric && s->vars[k].num && isnan(s->vars[k].num[i]) &&
           !(s->vars[k].text && s->vars[k].text[i]);
}

/* Step 5a: invalid sizes.  A value present in the file (text not NULL) must
 * be finite and positive. */
static int flag_invalid(phc_baad_study *s)
{
    static const char *const names[] = {"d.ba", "h.t", "m.rt", "m.st", "m.lf", "m.so"};
    size_t i, a;
    for (a = 0; a < sizeof names / sizeof names[0]; ++a) {
        long k = var_find(s, names[a]);
        if (k < 0 || !s->vars[k].numeric)
            continue;
        for (i = 0; i < s->n; ++i) {
            baad_var *v = &s->vars[k];
            double x = v->num[i];
            char reason[512];
            int rc;
            if (!v->text[i] && isnan(x))
                continue;
            if (isfinite(x) && x > 0)
                continue;
            if (v->column >= 0)
                snprintf(reason, sizeof reason,
                         "%s '%s' (column '%s') is %s: a size must be positive and finite",
                         names[a], v->text[i] ? v->text[i] : "", 
                         phc_table_column_name(s->data, (size_t)v->column),
                         isfinite(x) ? "not positive" : "not finite");
            else
                snprintf(reason, sizeof reason,
                         "%s = %g %s is %s: a size must be positive and finite", names[a], x,
                         v->unit ? v->unit : "", isfinite(x) ? "not positive" : "not finite");
            if ((rc = add_flag(s, i, PHC_BAAD_INVALID, reason)))
                return rc;
        }
    }
    return PHC_OK;
}

static int usable(const phc_baad_row *r)
{
    return r->flag != PHC_BAAD_INVALID && r->species;
}

/* Sort key for the diameter rule: species, then age (absent last). */
typedef struct group_key {
    const char *species;
    double age;
    size_t row;
} group_key;

static int cmp_group(const void *a, const void *b)
{
    const group_key *x = a, *y = b;
    int c = strcmp(x->species, y->species);
    if (c)
        return c;
    if (isnan(x->age) || isnan(y->age))
        return isnan(x->age) - isnan(y->age);
    if (x->age != y->age)
        return (x->age > y->age) - (x->age < y->age);
    return (x->row > y->row) - (x->row < y->row);
}

static int same_group(const group_key *x, const group_key *y)
{
    return !strcmp(x->species, y->species) &&
           (x->age == y->age || (isnan(x->age) && isnan(y->age)));
}

/* Step 5b: the diameter rule within species x age groups. */
static int flag_diameter(phc_baad_study *s, const double *za, double *lx, double *work)
{
    size_t m = 0, g0, g1, j;
    int rc = PHC_OK;
    group_key *key = malloc((s->n + 1) * sizeof *key);
    if (!key)
        return PHC_ERR_NOMEM;
    for (j = 0; j < s->n; ++j)
        if (usable(&s->rows[j]) && isfinite(s->rows[j].d_ba) && s->rows[j].d_ba > 0) {
            key[m].species = s->rows[j].species;
            key[m].age = s->rows[j].age;
            key[m++].row = j;
        }
    qsort(key, m, sizeof *key, cmp_group);
    for (g0 = 0; g0 < m && !rc; g0 = g1) {
        const phc_baad_row *first = &s->rows[key[g0].row];
        double med, spread;
        size_t n;
        for (g1 = g0 + 1; g1 < m && same_group(&key[g0], &key[g1]); ++g1)
            ;
        n = g1 - g0;
        if (n < PHC_BAAD_MIN_GROUP)
            continue;
        for (j = 0; j < n; ++j)
            lx[j] = log(s->rows[key[g0 + j].row].d_ba);
        memcpy(work, lx, n * sizeof *work);
        med = median(work, n);
        spread = robust_spread(lx, n, med, work);
        for (j = 0; j < n && !rc; ++j) {
            double z = (lx[j] - med) / spread;
            char reason[512], age[64];
            if (fabs(z) <= PHC_BAAD_ROBUST_Z)
                continue;
            /* in line with the plant's own mass: a big (small) plant, not a typo */
            if (fabs(za[key[g0 + j].row]) <= PHC_BAAD_CONSISTENT_Z)
                continue;
            if (isnan(first->age))
                snprintf(age, sizeof age, "unknown age");
            else
                snprintf(age, sizeof age, "age %.3g yr", first->age);
            snprintf(reason, sizeof reason,
                     "d.ba %.4g mm is %.1f robust SDs %s the median of the %zu %s rows of %s "
                     "(median %.3g mm, robust SD %.3f in log units)",
                     1e3 * s->rows[key[g0 + j].row].d_ba, fabs(z), z > 0 ? "above" : "below",
                     n, first->species, age, 1e3 * exp(med), spread);
            rc = add_flag(s, key[g0 + j].row, PHC_BAAD_SUSPICIOUS, reason);
        }
    }
    free(key);
    return rc;
}

/* Step 5c: the allometry rule, per species: residuals of log m.so about a
 * Theil-Sen line in log d.ba (robust to the outliers it looks for). */
static int flag_allometry(phc_baad_study *s, size_t *idx, double *lx, double *work, double *za,
                          char **reasons)
{
    size_t sp;
    int rc;
    for (sp = 0; sp < s->n_species; ++sp) {
        const char *name = s->species[sp];
        size_t n = 0, j, l, np = 0;
        double *ly, *slopes, b, a, med, spread;
        for (j = 0; j < s->n; ++j) {
            const phc_baad_row *r = &s->rows[j];
            if (usable(r) && !strcmp(r->species, name) && isfinite(r->d_ba) && r->d_ba > 0 &&
                isfinite(r->m_so) && r->m_so > 0)
                idx[n++] = j;
        }
        if (n < PHC_BAAD_MIN_GROUP)
            continue;
        ly = malloc(n * sizeof *ly);
        slopes = malloc((n * (n - 1) / 2 + 1) * sizeof *slopes);
        if (!ly || !slopes) {
            free(ly);
            free(slopes);
            return PHC_ERR_NOMEM;
        }
        for (j = 0; j < n; ++j) {
            lx[j] = log(s->rows[idx[j]].d_ba);
            ly[j] = log(s->rows[idx[j]].m_so);
        }
        for (j = 0; j < n; ++j)
            for (l = j + 1; l < n; ++l)
                if (lx[l] != lx[j])
                    slopes[np++] = (ly[l] - ly[j]) / (lx[l] - lx[j]);
        if (np == 0) {
            free(ly);
            free(slopes);
            continue;
        }
        b = median(slopes, np);
        for (j = 0; j < n; ++j)
            work[j] = ly[j] - b * lx[j];
        a = median(work, n);
        for (j = 0; j < n; ++j)
            ly[j] -= a + b * lx[j]; /* residuals */
        memcpy(work, ly, n * sizeof *work);
        med = median(work, n);
        spread = robust_spread(ly, n, med, work);
        rc = PHC_OK;
        for (j = 0; j < n && !rc; ++j) {
            const phc_baad_row *r = &s->rows[idx[j]];
            double z = (ly[j] - med) / spread;
            char reason[512];
            za[idx[j]] = z;
            if (fabs(z) <= PHC_BAAD_ROBUST_Z)
                continue;
            snprintf(reason, sizeof reason,
                     "m.so %.4g g is %.1f robust SDs %s the %s allometry log m.so = %.2f + "
                     "%.2f log d.ba over %zu rows (d.ba %.4g mm predicts %.3g g; robust SD "
                     "%.3f in log units)",
                     1e3 * r->m_so, fabs(z), z > 0 ? "above" : "below", name, a, b, n,
                     1e3 * r->d_ba, 1e3 * exp(a + b * lx[j]), spread);
            reasons[idx[j]] = dup_str(reason);
            if (!reasons[idx[j]])
                rc = PHC_ERR_NOMEM;
        }
        free(ly);
        free(slopes);
        if (rc)
            return rc;
    }
    return PHC_OK;
}

static void free_reasons(char **reasons, size_t n)
{
    size_t i;
    for (i = 0; reasons && i < n; ++i)
        free(reasons[i]);
    free(reasons);
}

/* ---- public ------------------------------------------------------------- */

int phc_baad_read(const char *study_dir, phc_baad_study **out, phc_error *err)
{
    phc_baad_study *s = NULL;
    phc_table *match = NULL, *nw = NULL, *defs = NULL, *conv = NULL;
    phc_units *units = NULL;
    double *raw_lat = NULL, *raw_lon = NULL, *lx = NULL, *work = NULL, *za = NULL;
    char **reasons = NULL;
    size_t *idx = NULL;
    char parent[4096];
    const char *base;
    size_t len, i;
    long k_lat, k_lon;
    int rc, coords_set = 0;

    if (out)
        *out = NULL;
    if (!study_dir || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_baad_read: NULL argument");
    s = calloc(1, sizeof *s);
    if (!s)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    s->site_shift = NAN;

    /* name = last path component; parent folder holds variableDefinitions */
    len = strlen(study_dir);
    while (len > 1 && study_dir[len - 1] == '/')
        --len;
    if (len >= sizeof parent) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: path too long", study_dir);
        goto fail;
    }
    memcpy(parent, study_dir, len);
    parent[len] = '\0';
    base = strrchr(parent, '/');
    s->name = dup_str(base ? base + 1 : parent);
    if (!s->name) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if (base == parent)
        parent[1] = '\0';
    else if (base)
        parent[base - parent] = '\0';
    else
        strcpy(parent, ".");

    {
        /* a study folder is one with dataMatchColumns.csv: say so plainly */
        char mpath[4096];
        FILE *f;
        snprintf(mpath, sizeof mpath, "%s/dataMatchColumns.csv", study_dir);
        if (!(f = fopen(mpath, "rb"))) {
            rc = phc_error_set(err, PHC_ERR_IO,
                               "%s: not a BAAD study folder: it has no dataMatchColumns.csv (the "
                               "table that maps data.csv's columns to BAAD variables)",
                               study_dir);
            goto fail;
        }
        fclose(f);
    }
    {
        /* BAAD's config/ beside the study folders; else the parent itself */
        char config[4200];
        snprintf(config, sizeof config, "%s/config", parent);
        size_t skip = 0;
        if ((rc = read_import_options(s, study_dir, &skip, err)) ||
            (rc = read_data(s, study_dir, skip, err)) ||
            (rc = read_csv(s, study_dir, "dataMatchColumns.csv", 0, &match, err)) ||
            (rc = read_csv(s, study_dir, "dataNew.csv", 1, &nw, err)) ||
            (rc = read_csv(s, config, "variableDefinitions.csv", 1, &defs, err)) ||
            (!defs && (rc = read_csv(s, parent, "variableDefinitions.csv", 0, &defs, err))) ||
            (rc = read_csv(s, config, "variableConversion.csv", 1, &conv, err)) ||
            (!conv && (rc = read_csv(s, parent, "variableConversion.csv", 1, &conv, err))))
            goto fail;
    }
    s->n = phc_table_rows(s->data);
    if (!conv && !(units = phc_units_new(err))) {
        rc = err ? err->status : PHC_ERR_IO;
        goto fail;
    }

    /* 1. mapped columns, converted */
    if ((rc = map_columns(s, match, defs, conv, units, err)))
        goto fail;
    /* 2. raw site coordinates */
    if ((rc = site_coordinates(s, match, err)))
        goto fail;
    raw_lat = malloc((s->n + 1) * sizeof *raw_lat);
    raw_lon = malloc((s->n + 1) * sizeof *raw_lon);
    if (!raw_lat || !raw_lon) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    k_lat = var_find(s, "latitude");
    k_lon = var_find(s, "longitude");
    for (i = 0; i < s->n; ++i) {
        raw_lat[i] = value_of(s, k_lat, i);
        raw_lon[i] = value_of(s, k_lon, i);
    }
    /* 3. dataNew */
    if (nw && (rc = apply_new(s, nw, defs, &coords_set, err)))
        goto fail;
    k_lat = var_find(s, "latitude");
    k_lon = var_find(s, "longitude");
    if (coords_set) {
        for (i = 0; i < s->n; ++i) {
            double lat = value_of(s, k_lat, i), lon = value_of(s, k_lon, i), d;
            if (!isfinite(raw_lat[i]) || !isfinite(raw_lon[i]) || !isfinite(lat) ||
                !isfinite(lon))
                continue;
            if ((rc = phc_geo_distance(raw_lat[i], raw_lon[i], lat, lon, &d, err))) {
                phc_error_prefix(err, rc, "%s:%zu: site coordinates",
                                 phc_table_source(s->data), phc_table_row_line(s->data, i));
                goto fail;
            }
            if (isnan(s->site_shift) || d > s->site_shift)
                s->site_shift = d;
        }
    }

    /* 4. rows and derived variables */
    s->rows = calloc(s->n ? s->n : 1, sizeof *s->rows);
    s->species = calloc(s->n ? s->n : 1, sizeof *s->species);
    if (!s->rows || !s->species) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    {
        long k_sp = var_find(s, "species"), k_gc = var_find(s, "growingCondition");
        long k_age = var_find(s, "age"), k_dba = var_find(s, "d.ba"), k_ht = var_find(s, "h.t");
        long k_rt = var_find(s, "m.rt"), k_st = var_find(s, "m.st"), k_lf = var_find(s, "m.lf");
        long k_so = var_find(s, "m.so"), k_stba = var_find(s, "a.stba");
        long k_rf = var_find(s, "m.rf"), k_rc = var_find(s, "m.rc");
        if (k_so < 0 && k_st >= 0 && k_lf >= 0)
            k_so = var_add(s, "m.so", 1, "kg");
        if (k_rt < 0 && k_rf >= 0 && k_rc >= 0)
            k_rt = var_add(s, "m.rt", 1, "kg");
        if (k_dba < 0 && k_stba >= 0)
            k_dba = var_add(s, "d.ba", 1, "m");
        if ((k_so < 0 && k_st >= 0 && k_lf >= 0) || (k_rt < 0 && k_rf >= 0 && k_rc >= 0) ||
            (k_dba < 0 && k_stba >= 0)) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        if (k_stba >= 0 && strcmp(s->vars[k_stba].unit ? s->vars[k_stba].unit : "", "m2")) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s: a.stba is in '%s', not m2: cannot derive d.ba from it",
                               phc_table_source(defs), s->vars[k_stba].unit ? s->vars[k_stba].unit : "");
            goto fail;
        }
        for (i = 0; i < s->n; ++i) {
            phc_baad_row *r = &s->rows[i];
            size_t j;
            r->line = phc_table_row_line(s->data, i);
            r->species = text_of(s, k_sp, i);
            r->growing_condition = text_of(s, k_gc, i);
            r->age = value_of(s, k_age, i);
            if (isfinite(r->age))
                s->counts.ages++;
            if (fillable(s, k_dba, i) &&
                isfinite(value_of(s, k_stba, i))) {
                /* d.ba = 2 sqrt(a.stba / pi): the stem's cross-section at
                 * its base taken as a circle; m from m2 */
                double a = value_of(s, k_stba, i);
                s->vars[k_dba].num[i] = a >= 0 ? 2.0 * sqrt(a / 3.14159265358979323846) : NAN;
                r->d_ba_derived = 1;
                s->counts.derived_diameters++;
            }
            if (fillable(s, k_rt, i) &&
                isfinite(value_of(s, k_rf, i)) && isfinite(value_of(s, k_rc, i))) {
                s->vars[k_rt].num[i] = value_of(s, k_rf, i) + value_of(s, k_rc, i);
                r->m_rt_derived = 1;
                s->counts.derived_roots++;
            }
            r->d_ba = value_of(s, k_dba, i);
            r->h_t = value_of(s, k_ht, i);
            r->m_rt = value_of(s, k_rt, i);
            r->m_st = value_of(s, k_st, i);
            r->m_lf = value_of(s, k_lf, i);
            r->m_so = value_of(s, k_so, i);
            r->latitude = value_of(s, k_lat, i);
            r->longitude = value_of(s, k_lon, i);
            if (fillable(s, k_so, i) &&
                isfinite(r->m_st) && isfinite(r->m_lf)) {
                r->m_so = r->m_st + r->m_lf; /* BAAD's fillDerivedVariables */
                r->m_so_derived = 1;
                s->vars[k_so].num[i] = r->m_so;
                s->counts.derived_shoots++;
            }
            r->root_shoot = isfinite(r->m_rt) && isfinite(r->m_so) && r->m_rt > 0 && r->m_so > 0
                                ? r->m_rt / r->m_so
                                : NAN;
            if (r->species) {
                for (j = 0; j < s->n_species && strcmp(s->species[j], r->species); ++j)
                    ;
                if (j == s->n_species)
                    s->species[s->n_species++] = r->species;
            }
        }
    }

    /* 5. flags */
    idx = malloc((s->n + 1) * sizeof *idx);
    lx = malloc((s->n + 1) * sizeof *lx);
    work = malloc((s->n + 1) * sizeof *work);
    za = malloc((s->n + 1) * sizeof *za);
    reasons = calloc(s->n + 1, sizeof *reasons);
    if (!idx || !lx || !work || !za || !reasons) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    /* the allometry residuals first: the diameter rule consults them */
    for (i = 0; i < s->n; ++i)
        za[i] = NAN;
    if ((rc = flag_invalid(s)) || (rc = flag_allometry(s, idx, lx, work, za, reasons)) ||
        (rc = flag_diameter(s, za, lx, work))) {
        phc_error_set(err, rc, "out of memory flagging rows");
        goto fail;
    }
    for (i = 0; i < s->n; ++i)
        if (reasons[i] && (rc = add_flag(s, i, PHC_BAAD_SUSPICIOUS, reasons[i]))) {
            phc_error_set(err, rc, "out of memory flagging rows");
            goto fail;
        }

    *out = s;
    rc = PHC_OK;
    free_reasons(reasons, s->n);
    reasons = NULL;
    s = NULL; /* the caller's now */

fail:
    free_reasons(reasons, s ? s->n : 0);
    free(za);
    free(idx);
    free(lx);
    free(work);
    free(raw_lat);
    free(raw_lon);
    phc_units_free(units);
    phc_table_free(match);
    phc_table_free(nw);
    phc_table_free(defs);
    phc_table_free(conv);
    phc_baad_free(s);
    return rc;
}

void phc_baad_free(phc_baad_study *s)
{
    size_t k;
    if (!s)
        return;
    for (k = 0; k < s->n_vars; ++k) {
        free(s->vars[k].name);
        free(s->vars[k].unit);
        free(s->vars[k].num);
        free(s->vars[k].text);
    }
    free(s->vars);
    for (k = 0; k < s->n_strings; ++k)
        free(s->strings[k]);
    free(s->strings);
    free(s->rows);
    free(s->species);
    free(s->changes);
    free(s->warnings);
    for (k = 0; k < s->n_na; ++k)
        free(s->na[k]);
    phc_table_free(s->data);
    for (k = 0; k < s->n_inputs; ++k)
        free(s->inputs[k]);
    free(s->name);
    free(s);
}

size_t phc_baad_inputs(const phc_baad_study *s, const char *const **paths)
{
    if (paths)
        *paths = s ? (const char *const *)s->inputs : NULL;
    return s ? s->n_inputs : 0;
}

const char *phc_baad_name(const phc_baad_study *s)
{
    return s ? s->name : NULL;
}

size_t phc_baad_rows(const phc_baad_study *s)
{
    return s ? s->n : 0;
}

const phc_baad_row *phc_baad_row_at(const phc_baad_study *s, size_t i)
{
    return s && i < s->n ? &s->rows[i] : NULL;
}

const char *phc_baad_raw(const phc_baad_study *s, size_t i, const char *raw_column)
{
    long c;
    if (!s || !raw_column || i >= s->n)
        return NULL;
    c = phc_table_find(s->data, raw_column);
    return c < 0 ? NULL : phc_table_cell(s->data, i, (size_t)c);
}

size_t phc_baad_species(const phc_baad_study *s, const char ***names)
{
    if (names)
        *names = s ? s->species : NULL;
    return s ? s->n_species : 0;
}

double phc_baad_site_shift(const phc_baad_study *s)
{
    return s ? s->site_shift : NAN;
}

double phc_baad_value(const phc_baad_study *s, size_t i, const char *variable)
{
    long k;
    if (!s || !variable || i >= s->n)
        return NAN;
    k = var_find(s, variable);
    return value_of(s, k, i);
}

const char *phc_baad_text(const phc_baad_study *s, size_t i, const char *variable)
{
    long k;
    if (!s || !variable || i >= s->n)
        return NULL;
    k = var_find(s, variable);
    return text_of(s, k, i);
}

const char *phc_baad_unit(const phc_baad_study *s, const char *variable)
{
    long k;
    if (!s || !variable)
        return NULL;
    k = var_find(s, variable);
    return k < 0 ? NULL : s->vars[k].unit;
}

size_t phc_baad_changes(const phc_baad_study *s, const phc_baad_change **changes)
{
    if (changes)
        *changes = s ? s->changes : NULL;
    return s ? s->n_changes : 0;
}

phc_baad_counts phc_baad_count(const phc_baad_study *s)
{
    phc_baad_counts none = {0};
    return s ? s->counts : none;
}

size_t phc_baad_warnings(const phc_baad_study *s, const char *const **warnings)
{
    if (warnings)
        *warnings = s ? (const char *const *)s->warnings : NULL;
    return s ? s->n_warnings : 0;
}

const char *phc_baad_lacks(const phc_baad_study *s)
{
    if (!s)
        return NULL;
    if (var_find(s, "m.rt") < 0)
        return "no root mass: no column of data.csv is mapped to m.rt (nor to both m.rf and m.rc)";
    if (var_find(s, "m.so") < 0)
        return "no shoot mass: no column of data.csv is mapped to m.so (nor to both m.st and m.lf)";
    if (var_find(s, "d.ba") < 0)
        return "no basal diameter: no column of data.csv is mapped to d.ba (nor to a.stba)";
    return NULL;
}

size_t phc_baad_flagged(const phc_baad_study *s, int flag)
{
    size_t i, n = 0;
    for (i = 0; s && i < s->n; ++i)
        n += s->rows[i].flag == flag;
    return n;
}
