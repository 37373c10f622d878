/* What the plant-graph format files share (internal to
 * measurements/plant_io*.c; not installed, not part of plant_io.h):
 * plant_io.c holds the checks, the id lookup and the writer's plumbing,
 * plant_io_<format>.c one format each. */
#ifndef PHC_PLANT_IO_INTERNAL_H
#define PHC_PLANT_IO_INTERNAL_H

#include <stddef.h>
#include <stdio.h>

#include "measurements/plant_io.h"
#include "model/plant_graph.h"
#include "model/status.h"

/* ---- the readers (plant_io_<format>.c), called by phc_plant_io_read ------
 * text is the whole file (NUL-terminated, length bytes, cut in place); unit
 * multiplies lengths to metres (native: 0 = the file's `# unit:` line). */
int phc_plant_io_read_paper(const char *path, char *text, size_t length, double unit,
                            phc_plant_graph **out, phc_error *err);
int phc_plant_io_read_treeqsm(const char *path, char *text, size_t length, double unit,
                              phc_plant_graph **out, phc_error *err);
int phc_plant_io_read_swc(const char *path, char *text, size_t length, double unit,
                          phc_plant_graph **out, phc_error *err);
int phc_plant_io_read_native(const char *path, char *text, size_t length, double unit,
                             phc_plant_graph **out, phc_error *err);

/* ---- checks shared by the readers (plant_io.c) --------------------------- */
/* "FILE:LINE: segment ID: radius must be positive and finite, found R" */
int phc_plant_io_check_radius(const char *path, size_t line, long id, double r, phc_error *err);
/* x[0..2] finite; the message names the coordinate: WHAT followed by x, y or z */
int phc_plant_io_check_point(const char *path, size_t line, long id, const char *what,
                             const double *x, phc_error *err);
double phc_plant_io_distance3(const double *a, const double *b);
/* Exactly one root and no cycles in g->parent (lines[i]: segment i's line). */
int phc_plant_io_check_structure(const char *path, const phc_plant_graph *g, const size_t *lines,
                                 phc_error *err);

/* ---- id lookup (ids are arbitrary longs in SWC and native files) --------- */
typedef struct phc_plant_io_id_entry {
    long id;
    size_t index;
} phc_plant_io_id_entry;

/* Sorts ids[] (n entries) into a lookup map (*out, malloc'd); a repeated id
 * is an error at the line of its second occurrence ("WHAT id ..."). */
int phc_plant_io_build_id_map(const char *path, const long *ids, const size_t *lines, size_t n,
                              const char *what, phc_plant_io_id_entry **out, phc_error *err);
/* The index of id in map, or (size_t)-1. */
size_t phc_plant_io_find_id(const phc_plant_io_id_entry *map, size_t n, long id);

/* ---- writers (plant_io.c) ------------------------------------------------ */
/* Writes the body of a file (ctx: the writer's own extra data, may be
 * NULL); < 0 on a stream error. */
typedef int (*phc_plant_io_body_writer)(FILE *f, const phc_plant_graph *g, const void *ctx);

/* Writes through body(f, g, ctx) (numbers in the C locale) to a temporary
 * file renamed to path on success (measurements/atomic_file.h). */
int phc_plant_io_write_atomically(const char *path, const phc_plant_graph *g,
                                  phc_plant_io_body_writer body, const void *ctx,
                                  phc_error *err);
/* PHC_ERR_INVALID naming `who` unless path and a finished graph are given. */
int phc_plant_io_check_writable(const char *who, const char *path, const phc_plant_graph *g,
                                phc_error *err);

#endif /* PHC_PLANT_IO_INTERNAL_H */
