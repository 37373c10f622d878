/* The config's side of a data set's options: key lines, column names given
 * under keys, `{column: NAME, unit: UNIT}` specs.  Used by the YAML
 * translations of the kinds (fit/config/<kind>_yaml.c), never by a kind. */
#ifndef PHC_CONFIG_YAML_KEYS_H
#define PHC_CONFIG_YAML_KEYS_H

#include <stddef.h>

#include "fit/costs/origin.h"
#include "measurements/table.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"

/* The line of `key` in a YAML mapping (the mapping's own line when absent). */
size_t phc_key_line(const phc_yaml_node *map, const char *key);

/* The origin of a data set's options: the config file and its mapping, so
 * that the kind's messages name the line of each key. */
phc_origin phc_yaml_origin(const phc_yaml_doc *doc, const phc_yaml_node *map);

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

/* One of `names` (NULL-terminated) under `key` of `node`: *choice its
 * index; left alone when the key is absent.  PHC_ERR_INPUT otherwise:
 * "cfg.yaml:7: key 'method': 'bfd6' is not one of auto, exact, bdf6".
 * context names the mapping in the message of a value that is not a string. */
int phc_yaml_map_choice(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                        const char *context, const char *const *names, int *choice, phc_error *err);

#endif /* PHC_CONFIG_YAML_KEYS_H */
