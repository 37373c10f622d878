/* Reading a calibration problem from a YAML configuration (DESIGN.md §4).
 *
 * Top-level keys:
 *   name:        run name (default: the config file's stem)
 *   parameters:  mapping name -> {value, lower, upper, fixed, unit, scale,
 *                range: [lo, hi]} or name -> number (the start value)
 *   datasets:    sequence of data sets; each has `kind` and the kind's keys,
 *                plus the common keys:
 *                  name        (default "<kind>-<index>")
 *                  parameters  mapping slot -> global parameter name
 *                              (default: the slot's own name)
 *                  loss        none | huber | cauchy | soft_l1 | arctan
 *                  loss_scale  positive, in units of the weighted residual (1)
 *                  derivatives central | ridders (numerical Jacobians) or
 *                              analytic (kinds that provide it)
 *   solver:      method (levenberg_marquardt | dogleg), max_iterations,
 *                function_tolerance, gradient_tolerance, parameter_tolerance,
 *                threads, starts (multi-start count, Sobol points)
 *   report:      level (0.05), absolute_sigma (false),
 *                collinearity_threshold (20), correlation_threshold (0.95)
 *
 * Every error names the config file and the line, and for unknown keys the
 * nearest valid key.  The keys and what they mean are also described by the
 * registry below, from the tables the loader checks (config_help.h). */
#ifndef PHC_CONFIG_H
#define PHC_CONFIG_H

#include <stddef.h>

#include "fit/config_help.h"
#include "fit/engine/problem.h"
#include "model/status.h"

/* Loads and validates (phc_problem_validate) a configuration file. */
int phc_config_load(const char *path, phc_problem **out, phc_error *err);

/* Groups of rows (`phytocal fit --each COLUMN`): every data set's table is
 * split by the text of its column COLUMN; only kinds whose table is one of
 * rows can be split (phc_kind.each: curve, pv_curve, weight_curve), any
 * other kind in the config is PHC_ERR_INPUT naming it and the kinds that
 * can.  A table without the column is PHC_ERR_INPUT naming the file and the
 * column (and the columns it has).
 *
 * group_values: the distinct cells of COLUMN over the config's tables, in
 * order of first appearance; the config is loaded and validated with the
 * first group's rows (all groups' rows together need not be one valid data
 * set) and handed back in *whole when whole is not NULL; *values is
 * malloc'd, free with phc_config_group_values_free.
 * load_group: the config with each table cut to the rows whose COLUMN cell
 * equals value (rows keep their file lines for messages); a table with no
 * such row is PHC_ERR_INPUT. */
int phc_config_group_values(const char *path, const char *column, char ***values, size_t *n, phc_problem **whole,
                            phc_error *err);
void phc_config_group_values_free(char **values, size_t n);
int phc_config_load_group(const char *path, const char *column, const char *value, phc_problem **out,
                          phc_error *err);

/* The tables of a batch, read once: given the same cache, group_values and
 * load_group read and parse each table file the first time it is named and
 * reuse it for every later group (without one, a table of G groups is read
 * and parsed G + 1 times).  What was read is kept: a file changed during
 * the batch is not read again, so every group is cut from the bytes the
 * first read saw.  The cache holds the tables until freed. */
typedef struct phc_config_table_cache phc_config_table_cache;
phc_config_table_cache *phc_config_table_cache_new(void); /* NULL: out of memory */
void phc_config_table_cache_free(phc_config_table_cache *cache); /* accepts NULL */
int phc_config_group_values_cached(const char *path, const char *column, phc_config_table_cache *cache,
                                   char ***values, size_t *n, phc_problem **whole, phc_error *err);
int phc_config_load_group_cached(const char *path, const char *column, const char *value,
                                 phc_config_table_cache *cache, phc_problem **out, phc_error *err);

/* A set of configuration keys: a data-set kind, or a block of the file. */
typedef struct phc_config_section {
    const char *name;          /* the kind ("weight_curve") or block ("solver") */
    const char *summary;       /* one line: what it is (a kind: what it fits) */
    const char *const *keys;   /* the keys the loader accepts, NULL-terminated */
    const phc_key_help *help;  /* one entry per key, {NULL, NULL}-terminated */
} phc_config_section;

/* The data-set kinds this build knows, in the registry's (alphabetical)
 * order; a kind's keys are those besides the common data-set keys. */
size_t phc_config_kind_count(void);
const phc_config_section *phc_config_kind_at(size_t i);          /* NULL past the end */
const phc_config_section *phc_config_kind_find(const char *name); /* NULL when unknown */

/* The blocks of a configuration file. */
typedef enum phc_config_block_id {
    PHC_CONFIG_TOP,        /* the top-level mapping */
    PHC_CONFIG_PARAMETER,  /* one entry of `parameters:` */
    PHC_CONFIG_DATASET,    /* the keys common to every entry of `datasets:` */
    PHC_CONFIG_SOLVER,     /* `solver:` */
    PHC_CONFIG_REPORT,     /* `report:` */
    PHC_CONFIG_SOIL,       /* a data set's `soil:` (fit/costs/soil_setup.h) */
    PHC_CONFIG_N_BLOCKS
} phc_config_block_id;
const phc_config_section *phc_config_block(phc_config_block_id id); /* NULL when out of range */

#endif /* PHC_CONFIG_H */
