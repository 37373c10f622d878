/* Where a data set's options came from, so that a kind's messages can name
 * the config file and the line of the key at fault
 *     cfg.yaml:12: key 'x': 'tme' is not a column of data.csv; did you mean 'time'?
 * without the kind knowing anything about YAML.  The YAML translation of a
 * kind (fit/config/<kind>_yaml.c) fills one in; a program that builds a
 * data set in C passes NULL, and the messages then name the kind instead:
 *     curve: key 'x': 'tme' is not a column of data.csv; ... */
#ifndef PHC_COSTS_ORIGIN_H
#define PHC_COSTS_ORIGIN_H

#include <stddef.h>

/* The line of `key` in the mapping `map` (the mapping's own line when the
 * key is absent). */
typedef size_t (*phc_key_line_fn)(const void *map, const char *key);

typedef struct phc_origin {
    const char *path;         /* the config file */
    const void *map;          /* the data set's mapping, passed to key_line */
    phc_key_line_fn key_line; /* NULL: every key is at `line` */
    size_t line;              /* the data set's own line */
} phc_origin;

/* A place for a message, as text: "cfg.yaml:12" (the line of `key`, or the
 * data set's line when key is NULL) when o is given, else `kind`. */
typedef struct phc_where {
    char text[4200];
} phc_where;
phc_where phc_origin_key(const phc_origin *o, const char *kind, const char *key);

/* The 1-based line of `key` (0 without an origin). */
size_t phc_origin_line(const phc_origin *o, const char *key);

#endif /* PHC_COSTS_ORIGIN_H */
