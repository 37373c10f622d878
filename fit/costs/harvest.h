/* Harvested plants for `root_shoot` data sets (fit/costs/root_shoot.h):
 * each plant's basal diameter, root mass and shoot mass (stem and leaves),
 * optionally its age.  A program fills a phc_harvest from its own arrays;
 * phc_harvest_from_table takes them from a table's columns (with units and
 * an optional row filter), phc_harvest_read_baad from a BAAD study folder
 * (measurements/baad.h).  No YAML here: a config's keys are translated by
 * fit/config/root_shoot_yaml.c. */
#ifndef PHC_COSTS_HARVEST_H
#define PHC_COSTS_HARVEST_H

#include <stddef.h>

#include "fit/costs/origin.h"
#include "measurements/table.h"
#include "model/status.h"

typedef struct phc_harvest {
    size_t n;            /* plants, >= 1 */
    double *diameter;    /* n basal diameters, m, > 0 */
    double *root_mass;   /* n root masses, g, > 0 */
    double *shoot_mass;  /* n shoot masses (stem and leaves), g, > 0 */
    double *age;         /* n ages, d, NAN when unknown; NULL: no ages */
    size_t *line;        /* n 1-based lines of the plants in `file`; NULL: plant i is line i + 2 */
    char *file;          /* the file they came from (reports, plots); NULL: "plants" */
    char *source;        /* a sentence naming the data for the report; NULL: "`FILE`, N harvested
                            plants" */
    char *notes;         /* a markdown list of the rows left out or kept with a flag; NULL: none */
    char **inputs;       /* n_inputs files read, recorded as the data set's inputs (provenance) */
    size_t n_inputs;
} phc_harvest;

/* Frees a harvest made by phc_harvest_from_table or phc_harvest_read_baad
 * (every pointer is malloc'd there); accepts NULL. */
void phc_harvest_free(phc_harvest *h);

/* PHC_ERR_INPUT for no plants, or the first plant with a diameter or mass
 * that is not a positive number: "harvest.csv:4: the root mass must be a
 * positive number, found -0.12". */
int phc_harvest_check(const phc_harvest *h, phc_error *err);

/* Column names in a table of harvested plants, and their units (any
 * UDUNITS-2 unit of the quantity; NULL: the default shown). */
typedef struct phc_harvest_columns {
    const char *diameter, *diameter_unit;     /* required; "mm" */
    const char *root_mass, *root_mass_unit;   /* required; "g" */
    const char *shoot_mass, *shoot_mass_unit; /* "g"; NULL: leaf_mass + stem_mass */
    const char *leaf_mass, *leaf_mass_unit;   /* "g"; both needed without shoot_mass */
    const char *stem_mass, *stem_mass_unit;   /* "g" */
    const char *age, *age_unit;               /* optional; "d" */
    const char *select_column;  /* optional: keep only the rows whose select_column ... */
    const char *select_value;   /* ... equals select_value (text) */
    const phc_origin *origin;   /* where the options came from (a data set's mapping, keys as
                                   above and "select"), for messages; NULL */
} phc_harvest_columns;

/* The plants of the table's selected rows, converted to m, g and d.
 * Errors (PHC_ERR_INPUT) name the option ("root_shoot: key 'diameter': 'd'
 * is not a column of t.csv; did you mean 'd_mm'?", or the config line when
 * columns.origin is set) or the table's source and line. */
int phc_harvest_from_table(const phc_table *table, const phc_harvest_columns *columns, phc_harvest **out,
                           phc_error *err);

typedef struct phc_harvest_baad_options {
    const char *species;        /* required: the species whose plants are used */
    int keep_suspicious;        /* 0 (default): leave out the rows BAAD flags as suspicious;
                                   either way they are listed in the notes */
    const char *select_column;  /* optional: keep only the rows whose column (a raw column of
                                   data.csv) equals select_value */
    const char *select_value;
    const phc_origin *origin;   /* keys baad, species, select, for messages; NULL */
} phc_harvest_baad_options;

/* The plants of one species in the BAAD study folder `dir` (basal
 * diameter, root and shoot mass, age in d from the study's age in yr), with
 * the files read as inputs.  The notes list the rows left out, how many
 * plants have a derived diameter (from a.stba), root mass (m.rf + m.rc) or
 * shoot mass (m.st + m.lf), how many have an age, and every warning of the
 * reader (mapping rows skipped, cells that are not numbers).  Errors name
 * the folder's files and lines, or the option; a study without root mass,
 * shoot mass or basal diameter says which (phc_baad_lacks). */
int phc_harvest_read_baad(const char *dir, const phc_harvest_baad_options *options, phc_harvest **out,
                          phc_error *err);

#endif /* PHC_COSTS_HARVEST_H */
