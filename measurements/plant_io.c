/* Reading and writing plant graphs: see plant_io.h.
 *
 * Conventions shared by every reader:
 *   - every message names the file and the line ("plant.txt:12: ...");
 *   - numbers are parsed in the C locale, and a field must be consumed whole;
 *   - per-segment problems (bad radius, zero length, NaN position) are
 *     reported at the line that defines the segment; structural problems
 *     (two roots, cycles) at the line of a segment involved;
 *   - the graph is finished (phc_plant_graph_finish) before it is returned.
 *
 * One file a format: plant_io_paper.c (the wilting paper's files, reader
 * and writer), plant_io_treeqsm.c, plant_io_swc.c, plant_io_native.c
 * (phytocal's CSV, reader and writer); each describes its format.  This
 * file holds the format names and detection, phc_plant_io_read, the checks
 * and id lookup the readers share and the writers' plumbing
 * (plant_io_internal.h); plant_io_text.c the tokenizer. */
#include "measurements/plant_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "measurements/atomic_file.h"
#include "measurements/c_number.h"
#include "measurements/plant_io_internal.h"
#include "measurements/plant_io_text.h"
#include "measurements/text_file.h"

/* ---- id lookup (ids are arbitrary longs in SWC and native files) ------- */

static int cmp_id_entry(const void *a, const void *b)
{
    const phc_plant_io_id_entry *x = a, *y = b;
    if (x->id != y->id)
        return x->id < y->id ? -1 : 1;
    return x->index < y->index ? -1 : (x->index > y->index);
}

size_t phc_plant_io_find_id(const phc_plant_io_id_entry *map, size_t n, long id)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (map[mid].id < id)
            lo = mid + 1;
        else
            hi = mid;
    }
    return (lo < n && map[lo].id == id) ? map[lo].index : (size_t)-1;
}

/* Sorts ids[] (n entries) into a lookup map; a repeated id is an error at
 * the line of its second occurrence. */
int phc_plant_io_build_id_map(const char *path, const long *ids, const size_t *lines, size_t n,
                              const char *what, phc_plant_io_id_entry **out, phc_error *err)
{
    phc_plant_io_id_entry *map = malloc((n ? n : 1) * sizeof *map);
    size_t i;
    *out = NULL;
    if (!map)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    for (i = 0; i < n; ++i) {
        map[i].id = ids[i];
        map[i].index = i;
    }
    qsort(map, n, sizeof *map, cmp_id_entry);
    for (i = 1; i < n; ++i)
        if (map[i].id == map[i - 1].id) {
            int rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s id %ld repeats line %zu",
                                   path, lines[map[i].index], what, map[i].id,
                                   lines[map[i - 1].index]);
            free(map);
            return rc;
        }
    *out = map;
    return PHC_OK;
}

/* ---- checks shared by the readers -------------------------------------- */

int phc_plant_io_check_radius(const char *path, size_t line, long id, double r, phc_error *err)
{
    if (!(isfinite(r) && r > 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: segment %ld: radius must be positive and finite, found %g",
                             path, line, id, r);
    return PHC_OK;
}

int phc_plant_io_check_point(const char *path, size_t line, long id, const char *what,
                             const double *x, phc_error *err)
{
    static const char axis[3] = {'x', 'y', 'z'};
    int k;
    for (k = 0; k < 3; ++k)
        if (!isfinite(x[k]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: segment %ld: %s%c must be finite, found %g",
                                 path, line, id, what, axis[k], x[k]);
    return PHC_OK;
}

double phc_plant_io_distance3(const double *a, const double *b)
{
    const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Structure of a parent[] array filled by a reader, with the line of each
 * segment: exactly one root, and no cycles (a segment whose parent chain
 * never reaches the root).  O(n).  Parents are already in range and not
 * self-references (the readers check those where they parse them). */
int phc_plant_io_check_structure(const char *path, const phc_plant_graph *g, const size_t *lines,
                                 phc_error *err)
{
    size_t n = g->n, i, root = PHC_PLANT_NO_PARENT;
    unsigned char *state;
    int rc = PHC_OK;
    for (i = 0; i < n; ++i)
        if (g->parent[i] == PHC_PLANT_NO_PARENT) {
            if (root != PHC_PLANT_NO_PARENT)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: two roots: segments %ld and %ld "
                                     "(line %zu); exactly one segment may have no parent",
                                     path, lines[i], g->source_id[root], g->source_id[i],
                                     lines[root]);
            root = i;
        }
    if (root == PHC_PLANT_NO_PARENT)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: no root: every segment has a parent, so the parents "
                             "form a cycle (segment %ld is on it or leads to it)",
                             path, lines[0], g->source_id[0]);
    /* state: 0 unknown, 1 on the current walk, 2 reaches the root */
    state = calloc(n, 1);
    if (!state)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    state[root] = 2;
    for (i = 0; i < n && rc == PHC_OK; ++i) {
        size_t u = i;
        while (state[u] == 0) {
            state[u] = 1;
            u = g->parent[u];
        }
        if (state[u] == 1) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: cycle: segment %ld is its own ancestor (its parent "
                               "chain never reaches the root, segment %ld)",
                               path, lines[u], g->source_id[u], g->source_id[root]);
            break;
        }
        for (u = i; state[u] == 1; u = g->parent[u])
            state[u] = 2;
    }
    free(state);
    return rc;
}

static int check_unit(const char *path, double unit_to_m, phc_error *err)
{
    if (!(isfinite(unit_to_m) && unit_to_m >= 0))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: unit_to_m must be positive and finite (0 for the format's "
                             "default), found %g",
                             path, unit_to_m);
    return PHC_OK;
}

/* ---- format names and detection ---------------------------------------- */

static const char *const format_names[] = {"auto", "paper", "treeqsm", "swc", "native"};

int phc_plant_format_from_name(const char *name)
{
    int i;
    if (!name)
        return -1;
    for (i = 0; i < 5; ++i)
        if (strcasecmp(name, format_names[i]) == 0)
            return i;
    return -1;
}

const char *phc_plant_format_name(phc_plant_format format)
{
    if ((int)format < 0 || (int)format >= 5)
        return "unknown";
    return format_names[format];
}

static int has_extension(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) && strcasecmp(dot + 1, ext) == 0;
}

static int detect_format(const char *path, const char *text, phc_plant_format *format,
                         phc_error *err)
{
    const char *s = text, *e;
    int fields = 0, in_field = 0;
    if (has_extension(path, "swc")) {
        *format = PHC_PLANT_FORMAT_SWC;
        return PHC_OK;
    }
    if (has_extension(path, "csv")) {
        *format = PHC_PLANT_FORMAT_NATIVE;
        return PHC_OK;
    }
    /* first non-blank line */
    while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n')
        ++s;
    if (strncmp(s, "verts", 5) == 0) {
        *format = PHC_PLANT_FORMAT_PAPER;
        return PHC_OK;
    }
    e = s + strcspn(s, "\r\n");
    for (; s < e; ++s) {
        if (phc_plant_io_is_blank(*s))
            in_field = 0;
        else if (!in_field) {
            in_field = 1;
            ++fields;
        }
    }
    if (fields == 15 || fields == 16) {
        *format = PHC_PLANT_FORMAT_TREEQSM;
        return PHC_OK;
    }
    return phc_error_set(err, PHC_ERR_INPUT,
                         "%s:1: cannot tell the plant format: not .swc or .csv, the first line "
                         "is not 'verts N' (wilting paper) and has %d fields, not the 15 or 16 "
                         "of TreeQSM; name the format (paper, treeqsm, swc, native)",
                         path, fields);
}

int phc_plant_io_read(const char *path, phc_plant_format format, double unit_to_m,
                      phc_plant_graph **out, phc_error *err)
{
    char *text = NULL;
    size_t length = 0;
    phc_c_numeric scope = {(locale_t)0, (locale_t)0};
    int rc;

    if (out)
        *out = NULL;
    if (!path || !out || (int)format < 0 || (int)format > PHC_PLANT_FORMAT_NATIVE)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_plant_io_read: invalid argument");
    if ((rc = check_unit(path, unit_to_m, err)))
        return rc;
    if ((rc = phc_read_text_file(path, &text, &length, err)))
        return rc;
    if (memchr(text, '\0', length)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s: contains a NUL byte: not a text plant file", path);
        goto done;
    }
    if (format == PHC_PLANT_FORMAT_AUTO && (rc = detect_format(path, text, &format, err)))
        goto done;
    phc_c_numeric_begin(&scope); /* on failure strtod keeps the current locale */
    switch (format) {
    case PHC_PLANT_FORMAT_PAPER:
        rc = phc_plant_io_read_paper(path, text, length, unit_to_m > 0 ? unit_to_m : 1.0, out, err);
        break;
    case PHC_PLANT_FORMAT_TREEQSM:
        rc = phc_plant_io_read_treeqsm(path, text, length, unit_to_m > 0 ? unit_to_m : 1.0, out,
                                       err);
        break;
    case PHC_PLANT_FORMAT_SWC:
        rc = phc_plant_io_read_swc(path, text, length, unit_to_m > 0 ? unit_to_m : 1e-6, out, err);
        break;
    case PHC_PLANT_FORMAT_NATIVE:
    default:
        rc = phc_plant_io_read_native(path, text, length, unit_to_m, out, err);
        break;
    }
    phc_c_numeric_end(&scope);
done:
    free(text);
    if (rc == PHC_OK)
        phc_error_clear(err);
    return rc;
}

/* ---- writers ------------------------------------------------------------ */

/* Writes through body() to a temporary file next to PATH, renamed into
 * place (atomic_file.h); the temporary file is removed on any failure. */
int phc_plant_io_write_atomically(const char *path, const phc_plant_graph *g,
                                  phc_plant_io_body_writer body, const void *ctx,
                                  phc_error *err)
{
    phc_atomic_file *af = NULL;
    phc_c_numeric scope = {(locale_t)0, (locale_t)0};
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc)
        return rc;
    phc_c_numeric_begin(&scope); /* '.' decimal points whatever the locale */
    errno = 0;
    const int failed = body(phc_atomic_file_stream(af), g, ctx) < 0;
    const int saved = errno;
    phc_c_numeric_end(&scope);
    if (failed) {
        phc_atomic_file_abort(af);
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write: %s", path,
                             strerror(saved ? saved : EIO));
    }
    if ((rc = phc_atomic_file_commit(af, err)))
        return rc;
    phc_error_clear(err);
    return PHC_OK;
}

int phc_plant_io_check_writable(const char *who, const char *path, const phc_plant_graph *g,
                                phc_error *err)
{
    if (!path || !g || g->n == 0 || !g->order || g->root >= g->n)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: invalid argument (a path and a finished graph are needed)",
                             who);
    return PHC_OK;
}
