/* Root System Markup Language (RSML 1.0) reader and writer.
 *
 * RSML (Lobet et al. 2015, Plant Physiology 167:617-627) stores root system
 * architectures as XML:
 *     <rsml><metadata>version, unit, resolution, last-modified, software ...
 *     </metadata><scene><plant id=..><root id=.. label=..><geometry><polyline>
 *     <point x= y= [z=]/>...</polyline></geometry><functions><function
 *     name="diameter" domain="polyline"><sample>v</sample>...</function>
 *     </functions><root>...lateral roots, nested...</root></root></plant>
 *     </scene></rsml>
 *
 * What is kept: the metadata unit, resolution and software, the plants and
 * their ids, every root's id, label, parent, polyline and its diameter and
 * time functions (time: per-point time stamps of traced shoots,
 * measurements/shoot_traces.h).  Other properties, functions and annotations are not kept.
 *
 * Reading accepts what the published tools write: element names are matched
 * on their local name (any namespace prefix); root ids come from `id` or
 * (SmartRoot) `ID`; points are `<point x=".." y=".." [z=".."]/>` or
 * `<point><x>..</x><y>..</y>[<z>..</z>]</point>`; samples are
 * `<sample>v</sample>` or `<sample value="v"/>`.  Numbers are read in the C
 * locale whatever LC_NUMERIC the program set.  Every input error names the
 * file and the line of the offending element:
 *     roots.rsml:42: point 3 of root 'r7': attribute 'x' is not a finite number: 'abc'
 *
 * Units.  Coordinates and lengths (phc_rsml_root_length ...) are returned as
 * written in the file, "in the file's unit" in the sense of RSML's
 * <unit>/<resolution> pair.  Tools differ in what the coordinates are:
 * RSML's reference R package (rsml, Lobet: rsmlToPlant) and SmartRoot treat
 * coordinates as image pixels with <resolution> pixels per <unit>
 * (SmartRoot writes unit "inch", resolution 300); openalea writes unit
 * "pixel", resolution 1.  phc_rsml_length_in_unit() applies that
 * convention (coordinate length / resolution). */
#ifndef PHC_RSML_H
#define PHC_RSML_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PHC_RSML_NO_PARENT ((size_t)-1)

typedef struct phc_rsml_root {
    char *id;            /* the root's id attribute (generated "r<k>", k its index, on write if NULL) */
    char *label;         /* label attribute or NULL */
    size_t plant;        /* index into plant_ids */
    size_t parent;       /* index of the parent root in roots[], PHC_RSML_NO_PARENT for a primary root */
    size_t n_points;     /* >= 1; 0 only for a root read without <geometry> (see allow_no_geometry) */
    double *xyz;         /* 3*n_points (file units); z = 0 for 2-D files (dimension 2); NULL when n_points = 0 */
    double *diameter;    /* n_points or NULL: the <function name="diameter"> values on the polyline
                            (domain polyline), file units, >= 0; else NULL */
    size_t source_line;  /* line of the <root> element in the file (0 when built in memory) */
    double *time;        /* n_points or NULL: the <function name="time"> (domain polyline) values,
                            one per point, finite (traced shoots: seconds; read only, not
                            written by phc_rsml_write) */
    size_t *time_line;   /* n_points or NULL: the line of each time <sample> */
    size_t time_function_line; /* line of that <function>, 0 without one */
} phc_rsml_root;

typedef struct phc_rsml {
    char *unit;          /* metadata <unit>, e.g. "cm", "mm", "pixel", "inch"; NULL = "m" on write */
    double resolution;   /* metadata <resolution> (finite, > 0), 1 when absent */
    int dimension;       /* 2 or 3 (on read: z attributes present => 3) */
    char *software;      /* metadata <software> or NULL (written as "phytocal") */
    size_t n_plants;
    char **plant_ids;    /* n_plants entries; an entry is NULL for a plant without id
                            (generated "p<k>" on write) */
    size_t n_roots;
    phc_rsml_root *roots; /* parents always before children */
} phc_rsml;

/* An empty document: unit copied (NULL allowed: "m" on write), resolution 1,
 * dimension 2 or 3.  NULL when dimension is neither or memory runs out. */
phc_rsml *phc_rsml_new(const char *unit, int dimension);

/* Frees the document and everything it owns; r may be NULL. */
void phc_rsml_free(phc_rsml *r);

/* Appends a plant (id copied; NULL allowed) and stores its index in *index
 * (index may be NULL).  PHC_ERR_INVALID when r is NULL, PHC_ERR_NOMEM. */
int phc_rsml_add_plant(phc_rsml *r, const char *id, size_t *index, phc_error *err);

/* Appends a root to plant `plant` with parent `parent` (an earlier root of
 * the same plant, or PHC_RSML_NO_PARENT for a primary root).  id is copied
 * (NULL allowed); xyz holds 3*n_points finite coordinates (file units; z must
 * be 0 in a 2-D document); diameter (may be NULL) n_points finite values
 * >= 0.  The new root's index goes to *index (may be NULL).  Errors
 * (PHC_ERR_INVALID, message says which argument): plant out of range, parent
 * out of range or on another plant, n_points 0, xyz NULL, a non-finite
 * coordinate, non-zero z in 2-D, a negative or non-finite diameter. */
int phc_rsml_add_root(phc_rsml *r, size_t plant, size_t parent, const char *id, size_t n_points,
                      const double *xyz, const double *diameter, size_t *index, phc_error *err);

/* Reading options, from phc_rsml_read_options_default(). */
typedef struct phc_rsml_read_options {
    /* 0 (default): a <root> without <geometry> is an input error.
     * 1: it is read as a topology-only root (n_points 0, xyz NULL, length 0):
     * SmartRoot exports such files (properties and annotations only).
     * A <geometry> without <polyline>, or a <polyline> without points, is an
     * error either way. */
    int allow_no_geometry;
} phc_rsml_read_options;

phc_rsml_read_options phc_rsml_read_options_default(void);

/* Reads an RSML file.  On success *out is a document owned by the caller;
 * on failure *out is NULL and err names the file and line.  PHC_ERR_IO when
 * the file cannot be opened; PHC_ERR_INPUT for malformed XML (libxml2's
 * message and line), a document element other than <rsml>, no <metadata>
 * or no <unit> (required by RSML 1.0), a resolution that is not a finite
 * positive number, no <scene>, a root without a polyline (see the options)
 * or with 0 points, a coordinate that is not a finite number, points with
 * and without z in one file, a diameter function whose sample count differs
 * from the point count or with a negative or non-finite sample, a diameter
 * function on another domain than "polyline". */
int phc_rsml_read(const char *path, phc_rsml **out, phc_error *err);

/* Same with options (NULL = defaults). */
int phc_rsml_read_with(const char *path, const phc_rsml_read_options *options, phc_rsml **out,
                       phc_error *err);

/* Writes RSML 1.0 (metadata version 1, unit, resolution, last-modified as
 * UTC ISO 8601 time, software "phytocal"; one <plant> per plant; laterals
 * nested in their parent; numbers as the shortest decimal that reads back
 * to the same double; a diameter function when diameter != NULL).  Writes
 * a temporary file next to PATH, then renames it to PATH (atomic_file.h):
 * never leaves a partial file at PATH.
 * PHC_ERR_INVALID for an inconsistent document (parent not earlier or on
 * another plant, plant out of range, dimension not 2 or 3, resolution not
 * finite and positive), PHC_ERR_IO when writing fails. */
int phc_rsml_write(const phc_rsml *r, const char *path, phc_error *err);

/* Polyline length (sum of the segment lengths) in file coordinate units;
 * 0 for a root with fewer than 2 points or NULL. */
double phc_rsml_root_length(const phc_rsml_root *root);

/* Sum of phc_rsml_root_length over all roots; 0 for NULL. */
double phc_rsml_total_length(const phc_rsml *r);

/* A coordinate length converted to the metadata <unit>: length / resolution
 * (RSML's pixels-per-unit convention, see the top of this header). */
double phc_rsml_length_in_unit(const phc_rsml *r, double coordinate_length);

/* Branching order: 1 for a primary root, its parent's order + 1 otherwise;
 * 0 when r is NULL, root is out of range or the parent chain is broken. */
size_t phc_rsml_order(const phc_rsml *r, size_t root);

#ifdef __cplusplus
}
#endif

#endif /* PHC_RSML_H */
