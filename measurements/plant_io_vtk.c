/* Legacy VTK polydata of a plant graph's shape (plant_io.h): what ParaView
 * and Blender (through its VTK importers) open.
 *
 * The legacy format is plain text (VTK File Formats, Kitware, "Simple Legacy
 * Formats"):
 *
 *     # vtk DataFile Version 3.0
 *     TITLE (one line, at most 255 characters)
 *     ASCII
 *     DATASET POLYDATA
 *     POINTS 2n double          head and tail of each segment, m
 *     LINES n 3n                one 2-point line per segment
 *     POINT_DATA 2n             radius at both ends (ParaView's Tube filter
 *                               varies its radius by this point array)
 *     CELL_DATA n               segment_id (the file's ids), leaf, fixed and
 *                               the caller's fields, one value per segment
 *
 * Each segment gets its own two points (heads need not coincide with their
 * parent's tails), so a series of frames written with the same graph keeps
 * point i meaning the same end of the same segment.  Numbers with 17
 * significant digits; a non-finite field value is written as nan, which
 * ParaView reads. */
#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "measurements/plant_io.h"
#include "measurements/plant_io_internal.h"

typedef struct vtk_ctx {
    const char *title;
    const phc_plant_field *fields;
    size_t count;
} vtk_ctx;

static int vtk_body(FILE *f, const phc_plant_graph *g, const void *context)
{
    const vtk_ctx *c = context;
    const size_t n = g->n;
    size_t i, k;
    char title[256];
    /* the title is one line: no line breaks, at most 255 characters */
    snprintf(title, sizeof title, "%s", c->title && *c->title ? c->title : "phytocal plant shape");
    for (i = 0; title[i]; ++i)
        if (title[i] == '\n' || title[i] == '\r')
            title[i] = ' ';
    if (fprintf(f, "# vtk DataFile Version 3.0\n%s\nASCII\nDATASET POLYDATA\nPOINTS %zu double\n",
                title, 2 * n) < 0)
        return -1;
    for (i = 0; i < n; ++i) {
        const double *h = g->head + 3 * i, *t = g->tail + 3 * i;
        if (fprintf(f, "%.17g %.17g %.17g\n%.17g %.17g %.17g\n", h[0], h[1], h[2], t[0], t[1],
                    t[2]) < 0)
            return -1;
    }
    if (fprintf(f, "LINES %zu %zu\n", n, 3 * n) < 0)
        return -1;
    for (i = 0; i < n; ++i)
        if (fprintf(f, "2 %zu %zu\n", 2 * i, 2 * i + 1) < 0)
            return -1;
    if (fprintf(f, "POINT_DATA %zu\nSCALARS radius double 1\nLOOKUP_TABLE default\n", 2 * n) < 0)
        return -1;
    for (i = 0; i < n; ++i)
        if (fprintf(f, "%.17g\n%.17g\n", g->radius[i], g->radius[i]) < 0)
            return -1;
    if (fprintf(f, "CELL_DATA %zu\nSCALARS segment_id long 1\nLOOKUP_TABLE default\n", n) < 0)
        return -1;
    for (i = 0; i < n; ++i)
        if (fprintf(f, "%ld\n", g->source_id[i]) < 0)
            return -1;
    if (fprintf(f, "SCALARS leaf int 1\nLOOKUP_TABLE default\n") < 0)
        return -1;
    for (i = 0; i < n; ++i)
        if (fprintf(f, "%d\n", g->leaf[i] ? 1 : 0) < 0)
            return -1;
    if (fprintf(f, "SCALARS fixed int 1\nLOOKUP_TABLE default\n") < 0)
        return -1;
    for (i = 0; i < n; ++i)
        if (fprintf(f, "%d\n", g->fixed[i] ? 1 : 0) < 0)
            return -1;
    for (k = 0; k < c->count; ++k) {
        if (fprintf(f, "SCALARS %s double 1\nLOOKUP_TABLE default\n", c->fields[k].name) < 0)
            return -1;
        for (i = 0; i < n; ++i)
            if (fprintf(f, "%.17g\n", c->fields[k].value[i]) < 0)
                return -1;
    }
    return 0;
}

/* A VTK array name: letters, digits and '_' (no spaces), not empty, not
 * one of the arrays always written. */
static int field_name_ok(const char *name)
{
    static const char *const taken[] = {"radius", "segment_id", "leaf", "fixed"};
    size_t i;
    if (!name || !*name || strlen(name) > 64)
        return 0;
    for (i = 0; name[i]; ++i)
        if (!(isalnum((unsigned char)name[i]) || name[i] == '_'))
            return 0;
    for (i = 0; i < sizeof taken / sizeof *taken; ++i)
        if (strcmp(name, taken[i]) == 0)
            return 0;
    return 1;
}

int phc_plant_io_write_vtk(const char *path, const phc_plant_graph *g, const char *title,
                           const phc_plant_field *fields, size_t count, phc_error *err)
{
    vtk_ctx c = {title, fields, count};
    size_t k, j;
    int rc;
    if ((rc = phc_plant_io_check_writable("phc_plant_io_write_vtk", path, g, err)))
        return rc;
    if (count && !fields)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: %zu fields but no field array", path,
                             count);
    for (k = 0; k < count; ++k) {
        if (!field_name_ok(fields[k].name))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: field %zu: name '%s' must be 1 to 64 letters, digits or "
                                 "'_' and not radius, segment_id, leaf or fixed",
                                 path, k + 1, fields[k].name ? fields[k].name : "(null)");
        if (!fields[k].value)
            return phc_error_set(err, PHC_ERR_INVALID, "%s: field '%s' has no values", path,
                                 fields[k].name);
        for (j = 0; j < k; ++j)
            if (strcmp(fields[j].name, fields[k].name) == 0)
                return phc_error_set(err, PHC_ERR_INVALID, "%s: field '%s' is given twice",
                                     path, fields[k].name);
    }
    return phc_plant_io_write_atomically(path, g, vtk_body, &c, err);
}
