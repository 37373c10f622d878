/* Shared by the data-set kinds: finding a data file named in a config, and
 * saying which columns exist when a config names one that does not. */
#ifndef PHC_COSTS_SOURCE_FILE_H
#define PHC_COSTS_SOURCE_FILE_H

#include <stddef.h>

#include "measurements/table.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"

/* `file` relative to `dir` (the config file's directory) unless absolute
 * (or dir is "."); malloc'd, NULL when out of memory. */
char *phc_join_path(const char *dir, const char *file);

/* PHC_ERR_INPUT for a column name that is not in the table, at config line
 * `line`: "cfg.yaml:7: mass column 'mas' is not a column of data.csv; did you
 * mean 'mass'?" (or the list of columns when nothing is close). */
int phc_unknown_column(const phc_yaml_doc *doc, size_t line, const char *what, const char *name,
                       const phc_table *t, phc_error *err);

/* PHC_OK when column `name` (named by config key `key` of `node`) is in the
 * table, else phc_unknown_column's message at that key's line. */
int phc_need_column(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                    const char *name, const phc_table *t, phc_error *err);

/* A `{column: NAME, unit: UNIT}` mapping (or a bare column name) under
 * `key` of the data-set mapping `node`; *unit is default_unit when not
 * given.  A missing key is PHC_ERR_INPUT "cfg.yaml:7: <context>: missing key
 * 'time' ({column: NAME, unit: UNIT})". */
int phc_column_spec(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                    const char *context, const char *default_unit, const char **column,
                    const char **unit, phc_error *err);

/* The line of `key` in a YAML mapping (the mapping's own line when absent). */
size_t phc_key_line(const phc_yaml_node *map, const char *key);

#endif /* PHC_COSTS_SOURCE_FILE_H */
