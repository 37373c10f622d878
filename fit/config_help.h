/* Help on the configuration keys (`phytocal help [KIND]`), written from the
 * same key tables the loader checks, so that it cannot drift from them:
 *
 *   - each data-set kind has, in fit/costs/<kind>.c, its key table
 *     phc_<kind>_keys (what phc_config_load accepts) and next to it a help
 *     table phc_<kind>_help with one entry per key;
 *   - the top-level, parameter, common data-set, solver and report keys
 *     have theirs in fit/config.c, the nested `soil:` block in
 *     fit/config/soil_setup_yaml.c;
 *   - fit/config.h's registry (phc_config_kind_at, phc_config_block) pairs
 *     each key table with its help table and a one-line summary.
 *
 * tests/unit/test_config_help.c fails when a key has no help entry, two, or
 * a help entry names no key. */
#ifndef PHC_CONFIG_HELP_H
#define PHC_CONFIG_HELP_H

#include <stdio.h>

#include "model/status.h"

/* One configuration key and what it means: what it is, its form and
 * accepted values, units, and its default or that it is required.  A table
 * is an array ending with {NULL, NULL}. */
typedef struct phc_key_help {
    const char *key;
    const char *help;
} phc_key_help;

/* The help text of `key` in `table` (the first entry), or NULL. */
const char *phc_key_help_find(const phc_key_help *table, const char *key);

/* Writes help to `out`, wrapped for an 80-column terminal:
 *   kind NULL:      the overview: top-level, parameter, common data-set,
 *                   solver and report keys, and the data-set kinds with
 *                   their summaries;
 *   a kind's name:  its summary and keys (and the `soil:` block's keys for
 *                   kinds that have a `soil:` key);
 *   a block's name  ("soil", "parameters", "datasets", "solver", "report"):
 *                   that block's keys.
 * An unknown name is PHC_ERR_INPUT ("unknown kind 'x'; did you mean 'y'?"
 * and the list of kinds), with nothing written; a failed write PHC_ERR_IO. */
int phc_config_write_help(FILE *out, const char *kind, phc_error *err);

#endif /* PHC_CONFIG_HELP_H */
