/* YAML configuration documents as a tree of nodes that remember where they
 * came from, so every message can name the file, line and column or the key.
 *
 * Built on libyaml.  Only the YAML subset a configuration needs: block and
 * flow mappings and sequences, plain and quoted scalars, comments.  Anchors
 * and aliases are accepted (an alias node is a copy of its anchor, keeping the
 * anchor's positions; expansion is capped at 10^6 nodes and nesting at 256
 * levels).  Tags are ignored.  Duplicate keys in one mapping are an error. */
#ifndef PHC_YAML_DOC_H
#define PHC_YAML_DOC_H

#include <stddef.h>

#include "model/status.h"

typedef enum phc_yaml_kind {
    PHC_YAML_SCALAR,
    PHC_YAML_SEQUENCE,
    PHC_YAML_MAPPING
} phc_yaml_kind;

typedef struct phc_yaml_node phc_yaml_node;
struct phc_yaml_node {
    phc_yaml_kind kind;
    size_t line, column;        /* 1-based position of the node's start */
    char *scalar;               /* PHC_YAML_SCALAR: the value text (NUL-terminated) */
    int quoted;                 /* scalar was single- or double-quoted */
    size_t count;               /* sequence items or mapping pairs */
    phc_yaml_node **items;      /* PHC_YAML_SEQUENCE: count items */
    char **keys;                /* PHC_YAML_MAPPING: count keys ... */
    size_t *key_lines;          /*   ... their 1-based lines ... */
    phc_yaml_node **values;     /*   ... and values */
};

typedef struct phc_yaml_doc {
    char *path;                 /* as given to phc_yaml_load */
    phc_yaml_node *root;        /* NULL for an empty document (including "---"
                                   with nothing after it) */
} phc_yaml_doc;

/* Loads the first document of a file.  Syntax errors are PHC_ERR_INPUT:
 * "FILE:LINE:COL: YAML syntax error: <libyaml's problem>".  Unreadable file:
 * PHC_ERR_IO "FILE: cannot open: <strerror>".  Non-scalar mapping keys and
 * duplicate keys are PHC_ERR_INPUT with their position. */
int phc_yaml_load(const char *path, phc_yaml_doc **out, phc_error *err);
/* Same from a buffer; `name` stands for the path in messages. */
int phc_yaml_parse(const char *text, size_t length, const char *name,
                   phc_yaml_doc **out, phc_error *err);
void phc_yaml_free(phc_yaml_doc *doc); /* accepts NULL */

/* Value of `key` in a mapping node, or NULL if absent (or node not a mapping). */
const phc_yaml_node *phc_yaml_get(const phc_yaml_node *map, const char *key);

/* Checks that every key of `map` is in the NULL-terminated list `allowed`.
 * An unknown key is PHC_ERR_INPUT:
 *   "FILE:LINE: unknown key 'lowr' in <context>; did you mean 'lower'?"
 * (the suggestion comes from phc_suggest in suggest.h; without one the message lists the
 * allowed keys).  `context` is a phrase such as "parameter 'b1'". */
int phc_yaml_check_keys(const phc_yaml_doc *doc, const phc_yaml_node *map,
                        const char *const *allowed, const char *context,
                        phc_error *err);

/* Typed accessors.  Each returns 0 on success; when the node is NULL they
 * return 0 and leave *out unchanged (absent key = keep the default) unless
 * the _required variant is used.  Type errors are PHC_ERR_INPUT:
 *   "FILE:LINE:COL: key 'lower': expected a number, found 'abc'".
 * Numbers: finite doubles in C or YAML syntax (.inf/.nan are rejected).
 * Integers: whole numbers within long range (1e3 and 100.0 count).
 * Booleans: true/false/yes/no/on/off, any case.
 * The scalar's text is read whether or not it was quoted ("2.5" is 2.5).  A
 * YAML null (an empty value, ~, null) is a type error for every accessor,
 * strings included: it is a value the user left empty, not an absent key. */
int phc_yaml_number(const phc_yaml_doc *doc, const phc_yaml_node *node,
                    const char *key, double *out, phc_error *err);
int phc_yaml_integer(const phc_yaml_doc *doc, const phc_yaml_node *node,
                     const char *key, long *out, phc_error *err);
int phc_yaml_boolean(const phc_yaml_doc *doc, const phc_yaml_node *node,
                     const char *key, int *out, phc_error *err);
/* *out points into the document (do not free). */
int phc_yaml_string(const phc_yaml_doc *doc, const phc_yaml_node *node,
                    const char *key, const char **out, phc_error *err);

/* The same, for `key` looked up in `map`; if the key is missing and
 * `required` is non-zero: PHC_ERR_INPUT "FILE:LINE: <context>: missing key 'KEY'"
 * (LINE is the mapping's; "FILE: <context>: ..." when map is NULL).  A map
 * that is not a mapping is PHC_ERR_INPUT even for an optional key. */
int phc_yaml_map_number(const phc_yaml_doc *doc, const phc_yaml_node *map,
                        const char *key, int required, const char *context,
                        double *out, phc_error *err);
int phc_yaml_map_integer(const phc_yaml_doc *doc, const phc_yaml_node *map,
                         const char *key, int required, const char *context,
                         long *out, phc_error *err);
int phc_yaml_map_boolean(const phc_yaml_doc *doc, const phc_yaml_node *map,
                         const char *key, int required, const char *context,
                         int *out, phc_error *err);
int phc_yaml_map_string(const phc_yaml_doc *doc, const phc_yaml_node *map,
                        const char *key, int required, const char *context,
                        const char **out, phc_error *err);

#endif /* PHC_YAML_DOC_H */
