/* Shared by the data-set kinds: finding a data file, and saying which
 * columns exist when the options name one that does not.  No YAML here: the
 * config's side of the same job is fit/config/yaml_keys.h. */
#ifndef PHC_COSTS_SOURCE_FILE_H
#define PHC_COSTS_SOURCE_FILE_H

#include <stddef.h>

#include "measurements/table.h"
#include "model/status.h"

/* `file` relative to `dir` (the config file's directory) unless absolute
 * (or dir is "."); malloc'd, NULL when out of memory. */
char *phc_join_path(const char *dir, const char *file);

/* PHC_ERR_INPUT for a column name that is not in the table, at the place
 * `where` ("cfg.yaml:7", or a kind's name; fit/costs/origin.h):
 * "cfg.yaml:7: mass column 'mas' is not a column of data.csv; did you mean
 * 'mass'?" (or the list of columns when nothing is close). */
int phc_unknown_column_at(const char *where, const char *what, const char *name,
                          const phc_table *t, phc_error *err);

#endif /* PHC_COSTS_SOURCE_FILE_H */
