/* RSML 1.0 reader and writer with libxml2: see rsml.h. */
#include "measurements/rsml.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlerror.h>
#include <libxml/xmlwriter.h>

#include "measurements/atomic_file.h"
#include "measurements/c_number.h"
#include "measurements/lazy_library_internal.h"

/* ---- the in-memory document ---------------------------------------------- */

static char *copy_string(const char *s)
{
    char *c;
    size_t n;
    if (!s)
        return NULL;
    n = strlen(s) + 1;
    c = malloc(n);
    if (c)
        memcpy(c, s, n);
    return c;
}

static void root_clear(phc_rsml_root *root)
{
    free(root->id);
    free(root->label);
    free(root->xyz);
    free(root->diameter);
    free(root->time);
    free(root->time_line);
    memset(root, 0, sizeof *root);
}

phc_rsml *phc_rsml_new(const char *unit, int dimension)
{
    phc_rsml *r;
    if (dimension != 2 && dimension != 3)
        return NULL;
    r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->resolution = 1.0;
    r->dimension = dimension;
    if (unit) {
        r->unit = copy_string(unit);
        if (!r->unit) {
            free(r);
            return NULL;
        }
    }
    return r;
}

void phc_rsml_free(phc_rsml *r)
{
    size_t i;
    if (!r)
        return;
    for (i = 0; i < r->n_plants; ++i)
        free(r->plant_ids[i]);
    free(r->plant_ids);
    for (i = 0; i < r->n_roots; ++i)
        root_clear(&r->roots[i]);
    free(r->roots);
    free(r->unit);
    free(r->software);
    free(r);
}

/* Appends a plant, taking ownership of id (may be NULL). */
static int push_plant(phc_rsml *r, char *id, size_t *index)
{
    char **grown = realloc(r->plant_ids, (r->n_plants + 1) * sizeof *grown);
    if (!grown)
        return PHC_ERR_NOMEM;
    r->plant_ids = grown;
    r->plant_ids[r->n_plants] = id;
    if (index)
        *index = r->n_plants;
    ++r->n_plants;
    return PHC_OK;
}

/* Appends a root, taking ownership of its pointers on success only.  The
 * array grows by one (realloc) so that a document whose arrays were built
 * by hand with malloc stays valid. */
static int push_root(phc_rsml *r, const phc_rsml_root *root, size_t *index)
{
    phc_rsml_root *grown;
    if (r->n_roots >= ((size_t)-1) / sizeof *grown - 1)
        return PHC_ERR_NOMEM;
    grown = realloc(r->roots, (r->n_roots + 1) * sizeof *grown);
    if (!grown)
        return PHC_ERR_NOMEM;
    r->roots = grown;
    r->roots[r->n_roots] = *root;
    if (index)
        *index = r->n_roots;
    ++r->n_roots;
    return PHC_OK;
}

int phc_rsml_add_plant(phc_rsml *r, const char *id, size_t *index, phc_error *err)
{
    char *c = NULL;
    if (!r)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_add_plant: document is NULL");
    if (id && !(c = copy_string(id)))
        return phc_error_set(err, PHC_ERR_NOMEM, "phc_rsml_add_plant: out of memory");
    if (push_plant(r, c, index)) {
        free(c);
        return phc_error_set(err, PHC_ERR_NOMEM, "phc_rsml_add_plant: out of memory");
    }
    return PHC_OK;
}

int phc_rsml_add_root(phc_rsml *r, size_t plant, size_t parent, const char *id, size_t n_points,
                      const double *xyz, const double *diameter, size_t *index, phc_error *err)
{
    phc_rsml_root root;
    size_t i;
    int rc;
    memset(&root, 0, sizeof root);
    if (!r)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_add_root: document is NULL");
    if (plant >= r->n_plants)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_rsml_add_root: plant index %zu out of range (%zu plants)",
                             plant, r->n_plants);
    if (parent != PHC_RSML_NO_PARENT) {
        if (parent >= r->n_roots)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_add_root: parent index %zu is not an earlier root "
                                 "(%zu roots so far)",
                                 parent, r->n_roots);
        if (r->roots[parent].plant != plant)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_add_root: parent root %zu belongs to plant %zu, "
                                 "not to plant %zu",
                                 parent, r->roots[parent].plant, plant);
    }
    if (n_points == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_rsml_add_root: a root needs at least 1 point, got 0");
    if (!xyz)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_add_root: xyz is NULL");
    if (n_points > ((size_t)-1) / (3 * sizeof(double)))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_add_root: n_points %zu too large",
                             n_points);
    for (i = 0; i < n_points; ++i) {
        int k;
        for (k = 0; k < 3; ++k)
            if (!isfinite(xyz[3 * i + k]))
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "phc_rsml_add_root: point %zu: %c = %g is not finite", i,
                                     "xyz"[k], xyz[3 * i + k]);
        if (r->dimension == 2 && xyz[3 * i + 2] != 0.0)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_add_root: point %zu: z = %g in a 2-D document "
                                 "(z must be 0)",
                                 i, xyz[3 * i + 2]);
        if (diameter && !(isfinite(diameter[i]) && diameter[i] >= 0.0))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_add_root: diameter %zu = %g: expected a finite "
                                 "number >= 0",
                                 i, diameter[i]);
    }
    root.plant = plant;
    root.parent = parent;
    root.n_points = n_points;
    if (id && !(root.id = copy_string(id)))
        goto nomem;
    root.xyz = malloc(3 * n_points * sizeof *root.xyz);
    if (!root.xyz)
        goto nomem;
    memcpy(root.xyz, xyz, 3 * n_points * sizeof *root.xyz);
    if (diameter) {
        root.diameter = malloc(n_points * sizeof *root.diameter);
        if (!root.diameter)
            goto nomem;
        memcpy(root.diameter, diameter, n_points * sizeof *root.diameter);
    }
    rc = push_root(r, &root, index);
    if (rc)
        goto nomem;
    return PHC_OK;
nomem:
    root_clear(&root);
    return phc_error_set(err, PHC_ERR_NOMEM, "phc_rsml_add_root: out of memory");
}

/* ---- measures -------------------------------------------------------------- */

double phc_rsml_root_length(const phc_rsml_root *root)
{
    double length = 0.0;
    size_t i;
    if (!root || !root->xyz)
        return 0.0;
    for (i = 1; i < root->n_points; ++i) {
        const double *a = root->xyz + 3 * (i - 1), *b = root->xyz + 3 * i;
        const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
        length += sqrt(dx * dx + dy * dy + dz * dz);
    }
    return length;
}

double phc_rsml_total_length(const phc_rsml *r)
{
    double total = 0.0;
    size_t i;
    if (!r)
        return 0.0;
    for (i = 0; i < r->n_roots; ++i)
        total += phc_rsml_root_length(&r->roots[i]);
    return total;
}

double phc_rsml_length_in_unit(const phc_rsml *r, double coordinate_length)
{
    if (!r || !(r->resolution > 0.0))
        return NAN;
    return coordinate_length / r->resolution;
}

size_t phc_rsml_order(const phc_rsml *r, size_t root)
{
    size_t order = 1, steps = 0;
    if (!r || root >= r->n_roots)
        return 0;
    while (r->roots[root].parent != PHC_RSML_NO_PARENT) {
        const size_t parent = r->roots[root].parent;
        /* Parents come before children: a chain that does not go down in
         * index (or is longer than the document) is broken. */
        if (parent >= root || ++steps > r->n_roots)
            return 0;
        root = parent;
        ++order;
    }
    return order;
}

/* ---- reading ---------------------------------------------------------------- */

phc_rsml_read_options phc_rsml_read_options_default(void)
{
    phc_rsml_read_options o;
    o.allow_no_geometry = 0;
    return o;
}

/* The first libxml2 error of one parse (per-context handler, no globals). */
typedef struct xml_capture {
    int have; /* 0 none, 1 an error, 2 a fatal error */
    int line;
    char message[512];
} xml_capture;

#if LIBXML_VERSION >= 21200
static void capture_error(void *data, const xmlError *e)
#else
static void capture_error(void *data, xmlErrorPtr e)
#endif
{
    xmlParserCtxtPtr ctxt = data;
    xml_capture *cap = ctxt ? ctxt->_private : NULL;
    size_t n;
    /* Keep the first fatal error (what stopped the parse); before one
     * arrives, the first error (e.g. an undeclared namespace prefix). */
    if (!cap || !e || e->level < XML_ERR_ERROR || cap->have == 2 ||
        (cap->have == 1 && e->level != XML_ERR_FATAL))
        return;
    cap->have = e->level == XML_ERR_FATAL ? 2 : 1;
    cap->line = e->line;
    snprintf(cap->message, sizeof cap->message, "%s", e->message ? e->message : "XML error");
    /* libxml2 adds detail lines ("...indicate encoding !\nBytes: 0x8A ..."):
     * a message is one line, so keep the first */
    n = strcspn(cap->message, "\n");
    cap->message[n] = '\0';
    while (n && (cap->message[n - 1] == '\n' || cap->message[n - 1] == ' '))
        cap->message[--n] = '\0';
}

typedef struct reader {
    const char *path;
    const phc_rsml_read_options *options;
    phc_rsml *doc;
    int dimension;  /* 0 until the first point */
    phc_error *err;
} reader;

/* Local name of an element or attribute: after any prefix. */
static const char *local_name(const xmlChar *name)
{
    const char *s = (const char *)name, *colon;
    if (!s)
        return "";
    colon = strrchr(s, ':');
    return colon ? colon + 1 : s;
}

static int is_element(const xmlNode *node, const char *name)
{
    return node && node->type == XML_ELEMENT_NODE && !strcmp(local_name(node->name), name);
}

static xmlNode *first_child(const xmlNode *node, const char *name)
{
    xmlNode *c;
    for (c = node->children; c; c = c->next)
        if (is_element(c, name))
            return c;
    return NULL;
}

static size_t count_children(const xmlNode *node, const char *name)
{
    const xmlNode *c;
    size_t n = 0;
    for (c = node->children; c; c = c->next)
        if (is_element(c, name))
            ++n;
    return n;
}

static long line_of(const xmlNode *node)
{
    return node ? xmlGetLineNo(node) : 0;
}

/* Value of the attribute with this local name, as a malloc'd string; NULL when
 * absent.  *nomem is set when the copy failed. */
static char *attribute(const xmlNode *node, const char *name, int *nomem)
{
    const xmlAttr *a;
    for (a = node->properties; a; a = a->next) {
        if (!strcmp(local_name(a->name), name)) {
            xmlChar *v = xmlNodeListGetString(node->doc, a->children, 1);
            char *c = copy_string(v ? (const char *)v : "");
            if (v)
                xmlFree(v);
            if (!c)
                *nomem = 1;
            return c;
        }
    }
    return NULL;
}

/* Text content of an element, without leading and trailing white space,
 * as a malloc'd string (NULL and *nomem = 1 when out of memory). */
static char *text_of(const xmlNode *node, int *nomem)
{
    xmlChar *v = xmlNodeGetContent(node);
    const char *s = v ? (const char *)v : "";
    size_t n;
    char *c;
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r')
        ++s;
    n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n' || s[n - 1] == '\r'))
        --n;
    c = malloc(n + 1);
    if (c) {
        memcpy(c, s, n);
        c[n] = '\0';
    } else {
        *nomem = 1;
    }
    if (v)
        xmlFree(v);
    return c;
}

/* A finite number, white space allowed around it (the C locale is in force). */
static int parse_finite(const char *s, double *value)
{
    char *end;
    double v;
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r')
        ++s;
    if (!*s)
        return -1;
    errno = 0;
    v = strtod(s, &end);
    if (end == s)
        return -1;
    while (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r')
        ++end;
    if (*end || !isfinite(v))
        return -1;
    *value = v;
    return 0;
}

static int nomem_error(reader *rd)
{
    return phc_error_set(rd->err, PHC_ERR_NOMEM, "%s: out of memory", rd->path);
}

/* Value of a point coordinate: attribute `name`, else child element <name>.
 * Returns 0 and sets *present; a non-zero status on error. */
static int point_coordinate(reader *rd, const xmlNode *point, size_t index, const char *root_name,
                            const char *name, double *value, int *present)
{
    int nomem = 0, from_element = 0;
    char *s = attribute(point, name, &nomem);
    const xmlNode *child = NULL;
    if (nomem)
        return nomem_error(rd);
    if (!s) {
        child = first_child(point, name);
        if (child) {
            s = text_of(child, &nomem);
            if (nomem)
                return nomem_error(rd);
            from_element = 1;
        }
    }
    *present = s != NULL;
    if (!s)
        return PHC_OK;
    if (parse_finite(s, value)) {
        int rc = phc_error_set(rd->err, PHC_ERR_INPUT,
                               "%s:%ld: point %zu of root %s: %s '%s' is not a finite number: "
                               "'%s'",
                               rd->path, line_of(from_element ? child : point), index + 1,
                               root_name, from_element ? "element" : "attribute", name, s);
        free(s);
        return rc;
    }
    free(s);
    return PHC_OK;
}

/* Reads the <polyline> points into root->xyz (root->n_points set). */
static int read_polyline(reader *rd, const xmlNode *polyline, const char *root_name,
                         phc_rsml_root *root)
{
    const xmlNode *c;
    size_t n = count_children(polyline, "point"), i = 0;
    if (n == 0)
        return phc_error_set(rd->err, PHC_ERR_INPUT,
                             "%s:%ld: root %s: <polyline> has no <point> (at least 1 expected)",
                             rd->path, line_of(polyline), root_name);
    root->xyz = calloc(3 * n, sizeof *root->xyz);
    if (!root->xyz)
        return nomem_error(rd);
    root->n_points = n;
    for (c = polyline->children; c; c = c->next) {
        double *p;
        int present[3], k, rc, dim;
        if (!is_element(c, "point"))
            continue;
        p = root->xyz + 3 * i;
        for (k = 0; k < 3; ++k) {
            const char name[2] = {"xyz"[k], '\0'};
            rc = point_coordinate(rd, c, i, root_name, name, &p[k], &present[k]);
            if (rc)
                return rc;
            if (k < 2 && !present[k])
                return phc_error_set(rd->err, PHC_ERR_INPUT,
                                     "%s:%ld: point %zu of root %s has no '%s' (attribute or "
                                     "element)",
                                     rd->path, line_of(c), i + 1, root_name, name);
        }
        if (!present[2])
            p[2] = 0.0;
        dim = present[2] ? 3 : 2;
        if (rd->dimension == 0) {
            rd->dimension = dim;
        } else if (rd->dimension != dim) {
            return phc_error_set(rd->err, PHC_ERR_INPUT,
                                 "%s:%ld: point %zu of root %s %s 'z' but the file's earlier "
                                 "points %s (2-D and 3-D points mixed)",
                                 rd->path, line_of(c), i + 1, root_name,
                                 dim == 3 ? "has" : "has no", dim == 3 ? "have none" : "have one");
        }
        ++i;
    }
    return PHC_OK;
}

/* Reads the samples of a per-point function `what` (domain polyline, one
 * <sample> per polyline point) into *values (and each sample's line into
 * *lines when lines != NULL); nonneg: samples must be >= 0. */
static int read_samples(reader *rd, const xmlNode *function, const char *root_name,
                        const char *what, int nonneg, size_t n_points, double **values,
                        size_t **lines)
{
    const xmlNode *c;
    int nomem = 0;
    size_t n = count_children(function, "sample"), i = 0;
    char *domain = attribute(function, "domain", &nomem);
    if (nomem)
        return nomem_error(rd);
    if (domain && strcmp(domain, "polyline")) {
        int rc = phc_error_set(rd->err, PHC_ERR_INPUT,
                               "%s:%ld: root %s: %s function on domain '%s': only "
                               "domain 'polyline' is supported",
                               rd->path, line_of(function), root_name, what, domain);
        free(domain);
        return rc;
    }
    free(domain);
    if (*values)
        return phc_error_set(rd->err, PHC_ERR_INPUT,
                             "%s:%ld: root %s has a second %s function", rd->path,
                             line_of(function), root_name, what);
    if (n != n_points)
        return phc_error_set(rd->err, PHC_ERR_INPUT,
                             "%s:%ld: root %s: %s function has %zu samples, expected one "
                             "per polyline point (%zu)",
                             rd->path, line_of(function), root_name, what, n, n_points);
    if (n == 0)
        return PHC_OK;
    *values = malloc(n * sizeof **values);
    if (!*values)
        return nomem_error(rd);
    if (lines && !(*lines = malloc(n * sizeof **lines)))
        return nomem_error(rd);
    for (c = function->children; c; c = c->next) {
        char *s;
        double v;
        if (!is_element(c, "sample"))
            continue;
        s = attribute(c, "value", &nomem);
        if (!s && !nomem)
            s = text_of(c, &nomem);
        if (nomem)
            return nomem_error(rd);
        if (parse_finite(s, &v) || (nonneg && v < 0.0)) {
            int rc = phc_error_set(rd->err, PHC_ERR_INPUT,
                                   "%s:%ld: root %s: %s sample %zu: expected a finite "
                                   "number%s, found '%s'",
                                   rd->path, line_of(c), root_name, what, i + 1,
                                   nonneg ? " >= 0" : "", s);
            free(s);
            return rc;
        }
        free(s);
        if (lines)
            (*lines)[i] = (size_t)line_of(c);
        (*values)[i++] = v;
    }
    return PHC_OK;
}

/* Reads a <root> element and, depth first, its lateral roots.  Recursion is
 * bounded by libxml2's element depth limit (256 without XML_PARSE_HUGE). */
static int read_root(reader *rd, const xmlNode *node, size_t plant, size_t parent)
{
    phc_rsml_root root;
    const xmlNode *geometry, *c;
    char root_name[160];
    size_t index;
    int nomem = 0, rc;

    memset(&root, 0, sizeof root);
    root.plant = plant;
    root.parent = parent;
    root.source_line = (size_t)line_of(node);
    root.id = attribute(node, "id", &nomem);
    if (!root.id && !nomem)
        root.id = attribute(node, "ID", &nomem); /* SmartRoot */
    if (!nomem)
        root.label = attribute(node, "label", &nomem);
    if (nomem) {
        rc = nomem_error(rd);
        goto fail;
    }
    if (root.id)
        snprintf(root_name, sizeof root_name, "'%.150s'", root.id);
    else
        snprintf(root_name, sizeof root_name, "#%zu (no id)", rd->doc->n_roots + 1);

    geometry = first_child(node, "geometry");
    if (geometry) {
        const xmlNode *polyline = first_child(geometry, "polyline");
        if (!polyline) {
            rc = phc_error_set(rd->err, PHC_ERR_INPUT,
                               "%s:%ld: root %s: <geometry> has no <polyline>", rd->path,
                               line_of(geometry), root_name);
            goto fail;
        }
        rc = read_polyline(rd, polyline, root_name, &root);
        if (rc)
            goto fail;
    } else if (!rd->options->allow_no_geometry) {
        rc = phc_error_set(rd->err, PHC_ERR_INPUT,
                           "%s:%ld: root %s has no <geometry><polyline> (a topology-only root; "
                           "read with allow_no_geometry to accept it)",
                           rd->path, line_of(node), root_name);
        goto fail;
    }

    for (c = node->children; c; c = c->next) {
        const xmlNode *f;
        if (!is_element(c, "functions"))
            continue;
        for (f = c->children; f; f = f->next) {
            char *name;
            int is_diameter, is_time;
            if (!is_element(f, "function"))
                continue;
            name = attribute(f, "name", &nomem);
            if (nomem) {
                rc = nomem_error(rd);
                goto fail;
            }
            is_diameter = name && !strcmp(name, "diameter");
            is_time = name && !strcmp(name, "time");
            free(name);
            if (is_diameter && (rc = read_samples(rd, f, root_name, "diameter", 1, root.n_points,
                                                  &root.diameter, NULL)))
                goto fail;
            if (is_time) {
                root.time_function_line = (size_t)line_of(f);
                if ((rc = read_samples(rd, f, root_name, "time", 0, root.n_points, &root.time,
                                       &root.time_line)))
                    goto fail;
            }
        }
    }

    rc = push_root(rd->doc, &root, &index);
    if (rc) {
        rc = nomem_error(rd);
        goto fail;
    }
    /* root's pointers now belong to the document. */
    for (c = node->children; c; c = c->next)
        if (is_element(c, "root") && (rc = read_root(rd, c, plant, index)))
            return rc;
    return PHC_OK;
fail:
    root_clear(&root);
    return rc;
}

static int read_metadata(reader *rd, const xmlNode *rsml)
{
    const xmlNode *meta = first_child(rsml, "metadata"), *node;
    int nomem = 0;
    char *s;
    phc_rsml *doc = rd->doc;
    if (!meta)
        return phc_error_set(rd->err, PHC_ERR_INPUT,
                             "%s:%ld: <rsml> has no <metadata> (RSML 1.0 requires it, with "
                             "<unit>)",
                             rd->path, line_of(rsml));
    node = first_child(meta, "unit");
    if (node) {
        doc->unit = text_of(node, &nomem);
        if (nomem)
            return nomem_error(rd);
    }
    if (!doc->unit || !doc->unit[0])
        return phc_error_set(rd->err, PHC_ERR_INPUT,
                             "%s:%ld: <metadata> has no <unit> (RSML 1.0 requires the unit of "
                             "the coordinates, e.g. <unit>cm</unit>)",
                             rd->path, line_of(node ? node : meta));
    node = first_child(meta, "resolution");
    if (node) {
        double v;
        s = text_of(node, &nomem);
        if (nomem)
            return nomem_error(rd);
        if (parse_finite(s, &v) || !(v > 0.0)) {
            int rc = phc_error_set(rd->err, PHC_ERR_INPUT,
                                   "%s:%ld: <resolution>: expected a finite number > 0, found "
                                   "'%s'",
                                   rd->path, line_of(node), s);
            free(s);
            return rc;
        }
        free(s);
        doc->resolution = v;
    }
    node = first_child(meta, "software");
    if (node) {
        s = text_of(node, &nomem);
        if (nomem)
            return nomem_error(rd);
        if (s[0])
            doc->software = s;
        else
            free(s);
    }
    return PHC_OK;
}

static int read_document(reader *rd, const xmlNode *rsml)
{
    const xmlNode *scene, *plant, *c;
    int rc, have_scene = 0, nomem = 0;
    if (!is_element(rsml, "rsml"))
        return phc_error_set(rd->err, PHC_ERR_INPUT,
                             "%s:%ld: the document element is <%s>, expected <rsml>", rd->path,
                             line_of(rsml), rsml ? local_name(rsml->name) : "(none)");
    rc = read_metadata(rd, rsml);
    if (rc)
        return rc;
    for (scene = rsml->children; scene; scene = scene->next) {
        if (!is_element(scene, "scene"))
            continue;
        have_scene = 1;
        for (plant = scene->children; plant; plant = plant->next) {
            size_t p;
            char *id;
            if (!is_element(plant, "plant"))
                continue;
            id = attribute(plant, "id", &nomem);
            if (!id && !nomem)
                id = attribute(plant, "ID", &nomem);
            if (nomem || push_plant(rd->doc, id, &p)) {
                free(id);
                return nomem_error(rd);
            }
            for (c = plant->children; c; c = c->next)
                if (is_element(c, "root") && (rc = read_root(rd, c, p, PHC_RSML_NO_PARENT)))
                    return rc;
        }
    }
    if (!have_scene)
        return phc_error_set(rd->err, PHC_ERR_INPUT, "%s:%ld: <rsml> has no <scene>", rd->path,
                             line_of(rsml));
    /* A file without any point (empty scene, or topology only): 2-D. */
    rd->doc->dimension = rd->dimension ? rd->dimension : 2;
    return PHC_OK;
}

int phc_rsml_read_with(const char *path, const phc_rsml_read_options *options, phc_rsml **out,
                       phc_error *err)
{
    phc_rsml_read_options defaults = phc_rsml_read_options_default();
    xmlParserCtxtPtr ctxt = NULL;
    xmlDocPtr xml = NULL;
    xml_capture cap;
    phc_c_numeric numeric;
    int numeric_on = 0, rc;
    reader rd;
    FILE *probe;

    if (out)
        *out = NULL;
    if (!path || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_read: path and out are required");
    memset(&cap, 0, sizeof cap);
    memset(&rd, 0, sizeof rd);
    rd.path = path;
    rd.options = options ? options : &defaults;
    rd.err = err;

    /* An unreadable file is an I/O error, not an XML one. */
    probe = fopen(path, "rb");
    if (!probe)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    fclose(probe);

    int lib = phc_lazy_library_open(&phc_lazy_xml, path, err); /* libxml2, opened on first use */
    if (lib)
        return lib;
    xmlInitParser();
    ctxt = xmlNewParserCtxt();
    if (!ctxt) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    /* Per-context structured handler: messages come here, not to stderr,
     * and no global handler of the embedding program is touched. */
    ctxt->_private = &cap;
    ctxt->sax->serror = capture_error;
    xml = xmlCtxtReadFile(ctxt, path, NULL,
                          XML_PARSE_NONET | XML_PARSE_NOBLANKS | XML_PARSE_BIG_LINES);
    if (!xml || !ctxt->wellFormed) {
        if (cap.have)
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%d: %s", path, cap.line, cap.message);
        else
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s: not well-formed XML", path);
        goto fail;
    }

    rd.doc = phc_rsml_new(NULL, 2);
    if (!rd.doc) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    numeric_on = phc_c_numeric_begin(&numeric) == 0;
    rc = read_document(&rd, xmlDocGetRootElement(xml));
    if (numeric_on)
        phc_c_numeric_end(&numeric);
    if (rc)
        goto fail;

    xmlFreeDoc(xml);
    xmlFreeParserCtxt(ctxt);
    *out = rd.doc;
    return PHC_OK;
fail:
    phc_rsml_free(rd.doc);
    if (xml)
        xmlFreeDoc(xml);
    if (ctxt)
        xmlFreeParserCtxt(ctxt);
    return rc;
}

int phc_rsml_read(const char *path, phc_rsml **out, phc_error *err)
{
    return phc_rsml_read_with(path, NULL, out, err);
}

/* ---- writing ---------------------------------------------------------------- */

/* Shortest of %.15g, %.16g, %.17g that reads back to the same double (the C
 * locale is in force). */
static void format_double(double v, char *buf, size_t size)
{
    int precision;
    for (precision = 15; precision <= 17; ++precision) {
        snprintf(buf, size, "%.*g", precision, v);
        if (strtod(buf, NULL) == v)
            return;
    }
}

static int utf8_or_null(const char *s)
{
    return !s || xmlCheckUTF8((const unsigned char *)s);
}

static int check_document(const phc_rsml *r, phc_error *err)
{
    size_t i, j;
    if (r->dimension != 2 && r->dimension != 3)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_write: dimension %d (expected 2 or 3)",
                             r->dimension);
    if (!(isfinite(r->resolution) && r->resolution > 0.0))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_rsml_write: resolution %g (expected a finite number > 0)",
                             r->resolution);
    if (r->n_roots && !r->roots)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_write: roots is NULL");
    if (r->n_plants && !r->plant_ids)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_write: plant_ids is NULL");
    /* libxml2's writer copies bytes as they are: invalid UTF-8 would make a
     * file that no XML parser reads back. */
    if (!utf8_or_null(r->unit))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_write: unit is not valid UTF-8");
    for (i = 0; i < r->n_plants; ++i)
        if (!utf8_or_null(r->plant_ids[i]))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_write: plant %zu: id is not valid UTF-8", i);
    for (i = 0; i < r->n_roots; ++i) {
        const phc_rsml_root *root = &r->roots[i];
        if (root->plant >= r->n_plants)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_write: root %zu: plant %zu out of range (%zu plants)",
                                 i, root->plant, r->n_plants);
        if (root->parent != PHC_RSML_NO_PARENT &&
            (root->parent >= i || r->roots[root->parent].plant != root->plant))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_write: root %zu: parent %zu is not an earlier root "
                                 "of the same plant",
                                 i, root->parent);
        if (!utf8_or_null(root->id) || !utf8_or_null(root->label))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "phc_rsml_write: root %zu: id or label is not valid UTF-8", i);
        if (root->n_points && !root->xyz)
            return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_write: root %zu: xyz is NULL",
                                 i);
        for (j = 0; j < root->n_points; ++j) {
            const double *p = root->xyz + 3 * j;
            if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "phc_rsml_write: root %zu, point %zu: a coordinate is not "
                                     "finite",
                                     i, j);
            if (r->dimension == 2 && p[2] != 0.0)
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "phc_rsml_write: root %zu, point %zu: z = %g in a 2-D "
                                     "document",
                                     i, j, p[2]);
            if (root->diameter && !(isfinite(root->diameter[j]) && root->diameter[j] >= 0.0))
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "phc_rsml_write: root %zu, diameter %zu = %g: expected a "
                                     "finite number >= 0",
                                     i, j, root->diameter[j]);
        }
    }
    return PHC_OK;
}

#define W(call)               \
    do {                      \
        if ((call) < 0)       \
            goto write_error; \
    } while (0)

static int write_number_attribute(xmlTextWriterPtr w, const char *name, double v)
{
    char buf[40];
    format_double(v, buf, sizeof buf);
    return xmlTextWriterWriteAttribute(w, BAD_CAST name, BAD_CAST buf);
}

/* Opens <root ...> and writes its geometry and diameter function; the
 * caller closes it after the laterals. */
static int write_root_open(xmlTextWriterPtr w, const phc_rsml *r, size_t k)
{
    const phc_rsml_root *root = &r->roots[k];
    char buf[40];
    size_t i;
    W(xmlTextWriterStartElement(w, BAD_CAST "root"));
    if (root->id) {
        W(xmlTextWriterWriteAttribute(w, BAD_CAST "id", BAD_CAST root->id));
    } else {
        snprintf(buf, sizeof buf, "r%zu", k);
        W(xmlTextWriterWriteAttribute(w, BAD_CAST "id", BAD_CAST buf));
    }
    if (root->label)
        W(xmlTextWriterWriteAttribute(w, BAD_CAST "label", BAD_CAST root->label));
    if (root->n_points) {
        W(xmlTextWriterStartElement(w, BAD_CAST "geometry"));
        W(xmlTextWriterStartElement(w, BAD_CAST "polyline"));
        for (i = 0; i < root->n_points; ++i) {
            const double *p = root->xyz + 3 * i;
            W(xmlTextWriterStartElement(w, BAD_CAST "point"));
            W(write_number_attribute(w, "x", p[0]));
            W(write_number_attribute(w, "y", p[1]));
            if (r->dimension == 3)
                W(write_number_attribute(w, "z", p[2]));
            W(xmlTextWriterEndElement(w));
        }
        W(xmlTextWriterEndElement(w)); /* polyline */
        W(xmlTextWriterEndElement(w)); /* geometry */
        if (root->diameter) {
            W(xmlTextWriterStartElement(w, BAD_CAST "functions"));
            W(xmlTextWriterStartElement(w, BAD_CAST "function"));
            W(xmlTextWriterWriteAttribute(w, BAD_CAST "name", BAD_CAST "diameter"));
            W(xmlTextWriterWriteAttribute(w, BAD_CAST "domain", BAD_CAST "polyline"));
            for (i = 0; i < root->n_points; ++i) {
                format_double(root->diameter[i], buf, sizeof buf);
                W(xmlTextWriterWriteElement(w, BAD_CAST "sample", BAD_CAST buf));
            }
            W(xmlTextWriterEndElement(w)); /* function */
            W(xmlTextWriterEndElement(w)); /* functions */
        }
    }
    return 0;
write_error:
    return -1;
}

/* The whole document through w.  first/next link each plant's primary
 * roots and each root's laterals in document order; the nesting is walked
 * with an explicit stack so a deep chain cannot overflow the C stack. */
static int write_body(xmlTextWriterPtr w, const phc_rsml *r, const size_t *plant_first,
                      const size_t *child_first, const size_t *next, size_t *cursor)
{
    char buf[64];
    time_t now = time(NULL);
    struct tm tm;
    size_t p;

    W(xmlTextWriterSetIndent(w, 1));
    W(xmlTextWriterSetIndentString(w, BAD_CAST "  "));
    W(xmlTextWriterStartDocument(w, "1.0", "UTF-8", NULL));
    W(xmlTextWriterStartElement(w, BAD_CAST "rsml"));
    W(xmlTextWriterStartElement(w, BAD_CAST "metadata"));
    W(xmlTextWriterWriteElement(w, BAD_CAST "version", BAD_CAST "1"));
    W(xmlTextWriterWriteElement(w, BAD_CAST "unit", BAD_CAST(r->unit ? r->unit : "m")));
    format_double(r->resolution, buf, sizeof buf);
    W(xmlTextWriterWriteElement(w, BAD_CAST "resolution", BAD_CAST buf));
    if (gmtime_r(&now, &tm) && strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm))
        W(xmlTextWriterWriteElement(w, BAD_CAST "last-modified", BAD_CAST buf));
    W(xmlTextWriterWriteElement(w, BAD_CAST "software", BAD_CAST "phytocal"));
    W(xmlTextWriterEndElement(w)); /* metadata */
    W(xmlTextWriterStartElement(w, BAD_CAST "scene"));
    for (p = 0; p < r->n_plants; ++p) {
        size_t primary;
        W(xmlTextWriterStartElement(w, BAD_CAST "plant"));
        if (r->plant_ids[p]) {
            W(xmlTextWriterWriteAttribute(w, BAD_CAST "id", BAD_CAST r->plant_ids[p]));
        } else {
            snprintf(buf, sizeof buf, "p%zu", p);
            W(xmlTextWriterWriteAttribute(w, BAD_CAST "id", BAD_CAST buf));
        }
        for (primary = plant_first[p]; primary != PHC_RSML_NO_PARENT; primary = next[primary]) {
            size_t depth = 1;
            cursor[0] = child_first[primary];
            W(write_root_open(w, r, primary));
            while (depth) {
                const size_t c = cursor[depth - 1];
                if (c == PHC_RSML_NO_PARENT) {
                    W(xmlTextWriterEndElement(w)); /* root */
                    --depth;
                    continue;
                }
                cursor[depth - 1] = next[c];
                W(write_root_open(w, r, c));
                cursor[depth] = child_first[c];
                ++depth;
            }
        }
        W(xmlTextWriterEndElement(w)); /* plant */
    }
    W(xmlTextWriterEndElement(w)); /* scene */
    W(xmlTextWriterEndElement(w)); /* rsml */
    W(xmlTextWriterEndDocument(w));
    return 0;
write_error:
    return -1;
}

int phc_rsml_write(const phc_rsml *r, const char *path, phc_error *err)
{
    size_t *links = NULL, *plant_first, *plant_last, *child_first, *child_last, *next, *cursor;
    size_t i, n_links;
    phc_atomic_file *af = NULL;
    FILE *f;
    xmlTextWriterPtr w = NULL;
    xmlOutputBufferPtr out;
    phc_c_numeric numeric;
    int numeric_on = 0, rc, body;

    if (!r || !path)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_rsml_write: document and path are required");
    rc = check_document(r, err);
    if (rc)
        return rc;

    /* plant_first/last, child_first/last, next, cursor in one block. */
    n_links = 2 * r->n_plants + 4 * r->n_roots;
    if (!(links = malloc((n_links ? n_links : 1) * sizeof *links))) { /* a document without plants too */
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    for (i = 0; i < n_links; ++i)
        links[i] = PHC_RSML_NO_PARENT;
    plant_first = links;
    plant_last = plant_first + r->n_plants;
    child_first = plant_last + r->n_plants;
    child_last = child_first + r->n_roots;
    next = child_last + r->n_roots;
    cursor = next + r->n_roots;
    for (i = 0; i < r->n_roots; ++i) {
        const size_t parent = r->roots[i].parent;
        size_t *first = parent == PHC_RSML_NO_PARENT ? &plant_first[r->roots[i].plant]
                                                     : &child_first[parent];
        size_t *last = parent == PHC_RSML_NO_PARENT ? &plant_last[r->roots[i].plant]
                                                    : &child_last[parent];
        if (*first == PHC_RSML_NO_PARENT)
            *first = i;
        else
            next[*last] = i;
        *last = i;
    }

    if ((rc = phc_lazy_library_open(&phc_lazy_xml, path, err))) /* libxml2, opened on first use */
        goto fail;
    if ((rc = phc_atomic_file_open(path, &af, err)))
        goto fail;
    f = phc_atomic_file_stream(af);
    xmlInitParser();
    out = xmlOutputBufferCreateFile(f, NULL); /* flushes f on close, does not fclose it */
    if (!out || !(w = xmlNewTextWriter(out))) {
        if (out)
            xmlOutputBufferClose(out);
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    errno = 0;
    numeric_on = phc_c_numeric_begin(&numeric) == 0;
    body = write_body(w, r, plant_first, child_first, next, cursor);
    if (numeric_on)
        phc_c_numeric_end(&numeric);
    xmlFreeTextWriter(w); /* flushes and closes the output buffer */
    w = NULL;
    if (body < 0) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: write failed: %s", path,
                           errno ? strerror(errno) : "libxml2 writer error");
        goto fail;
    }
    rc = phc_atomic_file_commit(af, err); /* stream errors, fsync, rename */
    af = NULL;
    if (rc)
        goto fail;
    free(links);
    return PHC_OK;
fail:
    if (w)
        xmlFreeTextWriter(w);
    phc_atomic_file_abort(af);
    free(links);
    return rc;
}
