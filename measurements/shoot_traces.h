/* Traced shoots of a climbing plant: time-lapse positions of every shoot's
 * apex (or of points along it), read from a CSV table, for fitting the
 * climbing-plant model (model/climbing_growth.h; README "Fitting growth to
 * traced shoots").
 *
 * Format (measurements/table.h rules: header line, ',' ';' or tab, '#'
 * comments), one row per traced point:
 *     time, shoot, x, y, z [, parent]
 *   time    s (seconds since the seed started growing), finite
 *   shoot   a name (any text, not empty): the points of one shoot in the
 *           order they were traced, base first; rows of different shoots
 *           may be interleaved
 *   x y z   m, finite; z is up (the model's light and height use z)
 *   parent  optional column: the shoot this one branches from (a name of
 *           the table); empty for the main axis.  Every row of a shoot
 *           names the same parent.  Without the column every shoot is a
 *           main axis (order 0).
 * A shoot's polyline at time t is its points with time <= t, joined in
 * order; a lateral's first point is its branch point on the parent.
 *
 * RSML (a file whose name ends in .rsml; Lobet et al. 2015, read by
 * measurements/rsml.h): every <root> polyline is a shoot named by its id
 * (root<k> without one), base first; its parent is the <root> it is nested
 * in (laterals nest in their parent shoot, so a parent is always known);
 * each point's time (s) is its <sample> of the root's per-point function
 * named "time" (<functions><function name="time" domain="polyline">, one
 * sample per point).  RSML 1.0 itself has no per-point time (its metadata
 * <time-sequence> numbers whole files of a series), so the function is our
 * convention.  Coordinates are converted to m by the metadata: coordinate /
 * <resolution> is in <unit> (m, cm, mm, um or inch).  Errors, naming the
 * file and the line of the element: a root without a time function (the
 * first such root is named, before any other check), a time sample count
 * other than the point count, time going backwards along a root, a unit
 * that is not a length (e.g. "pixel"), two roots with one id; then the
 * table's checks below (a shoot with fewer than 2 points ...).
 *
 * Errors (PHC_ERR_INPUT, "FILE:LINE: column 'NAME': ..."): a missing
 * column, a non-numeric or non-finite cell, an empty shoot name, time going
 * backwards within a shoot, a parent that is not a shoot of the table, a
 * parent that differs between rows of one shoot, a shoot that is its own
 * ancestor, a shoot with fewer than 2 points; PHC_ERR_IO when the file
 * cannot be read. */
#ifndef PHC_SHOOT_TRACES_H
#define PHC_SHOOT_TRACES_H

#include <stddef.h>

#include "model/climbing_statistics.h"
#include "model/status.h"

#define PHC_SHOOT_NONE ((size_t)-1)

typedef struct phc_shoot_traces {
    char *source;          /* path as given */
    size_t n_shoots;
    char **names;          /* shoot names, in order of first appearance */
    size_t *parent;        /* parent shoot index or PHC_SHOOT_NONE */
    unsigned *order;       /* 0 for a shoot without parent, parent's + 1 */
    size_t *first_line;    /* line of each shoot's first row */
    size_t *start;         /* n_shoots + 1: shoot s owns points start[s] .. start[s+1]-1 */
    size_t n_points;
    double *t;             /* s, per point (grouped by shoot, traced order kept) */
    double *x;             /* m, 3 per point */
    double t_end;          /* s, the latest time */
} phc_shoot_traces;

int phc_shoot_traces_read(const char *path, phc_shoot_traces **out, phc_error *err);

/* Builds traces from arrays (rows as in the file; parent NULL: no parent
 * column, or parent[i] NULL / "" for no parent); `name` stands for the
 * file in messages, and row i is its line i + 2. */
int phc_shoot_traces_from_rows(const char *name, size_t n, const double *t, const char *const *shoot,
                               const double *x, const double *y, const double *z,
                               const char *const *parent, phc_shoot_traces **out, phc_error *err);

void phc_shoot_traces_free(phc_shoot_traces *tr); /* accepts NULL */

/* The traced plant at time t as segments (model/climbing_statistics.h):
 * every pair of consecutive points of a shoot with times <= t; the first
 * segment of a lateral carries the direction of its parent's segment
 * closest to the branch point (of the parent's segments at time t; none
 * when the parent has none yet: then it is not counted as lateral).
 * *seg is malloc'd (NULL when there are none), *n its count. */
int phc_shoot_traces_segments(const phc_shoot_traces *tr, double t, phc_shoot_segment **seg, size_t *n,
                              phc_error *err);

#endif /* PHC_SHOOT_TRACES_H */
