/* A data-set kind as the config sees it: one descriptor per kind, exported
 * by its YAML translation (fit/config/<kind>_yaml.c) and listed once in the
 * registry of fit/config.c.  Adding a kind touches three places: its
 * YAML-free constructor in fit/costs/<kind>.{c,h}, its translation
 * fit/config/<kind>_yaml.c, and one line of the registry.
 *
 * The translation reads the config mapping (and the data files it names)
 * into the kind's C options and calls the kind's phc_<kind>_new; it knows
 * YAML, the kind does not. */
#ifndef PHC_CONFIG_KIND_H
#define PHC_CONFIG_KIND_H

#include "fit/config.h"
#include "fit/config_help.h"
#include "fit/engine/dataset.h"
#include "measurements/table.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"

/* Builds a data set of the kind from its config mapping `node`; base_dir is
 * the config file's directory (data files are relative to it).  Slot names
 * are filled; parameter indices are left to the caller (binding).  Errors
 * name the config file and line, or the data file, line and column.
 * user_data is the loader's context: pass it to is_parameter, and to
 * phc_kind_read_table when the kind reads its observations' table. */
typedef int (*phc_kind_yaml_fn)(const phc_yaml_doc *doc, const phc_yaml_node *node,
                                const char *base_dir, phc_is_parameter_fn is_parameter,
                                void *user_data, phc_dataset **out, phc_error *err);

typedef struct phc_kind {
    phc_config_section config;  /* name (the kind's, as ops->kind), summary, keys, help */
    const phc_dataset_ops *ops; /* what its data sets do */
    phc_kind_yaml_fn load_yaml;
    int each; /* its observations are the rows of one table read with
                 phc_kind_read_table, so `fit --each` can split them */
} phc_kind;

/* Reads a kind's table of observations: phc_table_read, then, when the
 * loader splits the config into groups (phc_config_load_group), only the
 * rows of the group.  user_data is the loader's context given to the kind's
 * load_yaml.  Errors as phc_table_read's, and the group's (config.h). */
int phc_kind_read_table(void *user_data, const char *path, phc_table **out, phc_error *err);

#endif /* PHC_CONFIG_KIND_H */
