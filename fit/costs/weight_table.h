/* Weighings from a table (a balance logger's CSV file, or a phc_table made
 * from arrays): the rows of one plant, their times (numbers in a unit, or
 * logger date-and-time stamps in a time zone), masses and balance sigmas,
 * the tare readings at the start, the pauses of the logger, the windows to
 * leave out and the covariate columns.  The result is the phc_weighings of
 * fit/costs/weight_curve.h, ready for phc_weight_curve_new.
 *
 *     phc_table *t = NULL;
 *     phc_table_read("logger.csv", &t, &err);
 *     phc_weight_curve_read_options ro = phc_weight_curve_read_options_default();
 *     ro.time_column = "Date";
 *     ro.time_column_2 = "Time";
 *     ro.timestamps = 1;
 *     ro.time_format = "%d/%m/%Y %H:%M:%S";
 *     ro.timezone = "Europe/Berlin";
 *     ro.mass_column = "Weight";
 *     phc_weighings w;
 *     phc_weight_curve_read_table(t, &ro, &w, &err);
 *     ... phc_weight_curve_new(graph, &w, &options, &ds, &err) ...
 *     phc_weighings_release(&w);
 *
 * No YAML: the config's `file`, `time`, `mass`, `select`, `sigma`, `tare`,
 * `max_gap`, `exclude` and `covariates` keys are translated into these
 * options by fit/config/weight_curve_yaml.c. */
#ifndef PHC_COSTS_WEIGHT_TABLE_H
#define PHC_COSTS_WEIGHT_TABLE_H

#include <stddef.h>

#include "fit/costs/origin.h"
#include "fit/costs/weight_curve.h"
#include "measurements/table.h"
#include "measurements/units.h"
#include "model/status.h"

/* The readings at the start of a plant's rows that are not the plant: the
 * empty balance, a pot without its plant. */
typedef enum phc_weight_tare {
    PHC_WEIGHT_TARE_AUTO = 0, /* drop the leading readings below 50% of the median of the
                                 10 after each (at least 2 rows stay); the report lists them */
    PHC_WEIGHT_TARE_KEEP      /* keep every row */
} phc_weight_tare;

typedef struct phc_weight_curve_read_options {
    const char *time_column;   /* required: the times (numbers), or the stamps' first column */
    const char *time_column_2; /* stamps written in two columns (DATE, TIME, joined by a
                                  space), or NULL */
    int timestamps;            /* 1: the time cells are dates and times (time_format); the
                                  weighings' time unit is then h since the first selected
                                  row, on the calendar */
    const char *time_format;   /* strptime(3) format of the stamps (a fraction after %S is
                                  accepted); NULL = ISO 8601 (measurements/logger_time.h) */
    const char *time_unit;     /* numeric times: a UDUNITS-2 time unit, NULL = "s"; an
                                  absolute one ("seconds since 1970-01-01") puts them on the
                                  calendar.  Must be NULL with timestamps */
    const char *timezone;      /* IANA zone of the logger's clock (daylight-saving steps
                                  handled); NULL = UTC, times as written.  With numeric
                                  times only for an absolute unit: it sets the local clock */
    const char *mass_column;   /* required: the masses, > 0 */
    const char *mass_unit;     /* a UDUNITS-2 mass unit, NULL = "g" */
    const char *sigma_column;  /* per-weighing balance sigmas in the mass unit, or NULL */
    size_t n_select;           /* keep only the rows whose select_columns[i] cell equals
                                  select_values[i] for every i (text, or equal numbers:
                                  "1" matches "1.0"); 0 = every row */
    const char *const *select_columns;
    const char *const *select_values;
    phc_weight_tare tare;
    double max_gap;            /* longest expected pause between weighings, > 0, in
                                  max_gap_unit; NAN = 6 h, or 3 times the median step when
                                  the weighings are sparser.  Longer pauses are listed */
    const char *max_gap_unit;  /* NULL = the time unit (h with timestamps) */
    size_t n_exclude;          /* windows to leave out of the fit (weighings.skip) */
    const double *exclude;     /* n_exclude pairs [from, to], from < to, in the time unit,
                                  counted from the first weighing kept after the tare */
    size_t n_covariates;       /* columns that drive the loss rate (weight_drivers.h), read
                                  at every weighing not left out */
    const char *const *covariates;
    phc_units *units;          /* a UDUNITS-2 system to use, or NULL: one of its own */
    const phc_origin *origin;  /* where the options came from, for messages; NULL */
} phc_weight_curve_read_options;

/* Every field zero or NULL, max_gap NAN (its default). */
phc_weight_curve_read_options phc_weight_curve_read_options_default(void);

/* Reads the weighings of one plant from `table` into *out, whose arrays
 * and strings belong to it (phc_weighings_release frees them; the table may
 * be freed first).  out->rows are the table rows of the weighings, after the
 * tare; out->t are in the time unit (h since the first selected row for
 * timestamps), out->mass and out->sigma in the mass unit.  Time order and
 * positive masses are checked by phc_weight_curve_new.  Errors name the
 * option (and the config line when options.origin is set) or the table's
 * source, line and column:
 *     "logger.csv:17: columns 'Date' and 'Time': '31/02/2024 10:00:00' does
 *      not match the format '%d/%m/%Y %H:%M:%S' (day 31 of month 2 does not
 *      exist)"
 *     "weight_curve: key 'select': no row of logger.csv matches" */
int phc_weight_curve_read_table(const phc_table *table, const phc_weight_curve_read_options *options,
                                phc_weighings *out, phc_error *err);

/* The rows of `table` that options.select keeps (all rows without one), in
 * order: *rows malloc'd (*n of them, at least 1).  Errors as above. */
int phc_weight_curve_select_rows(const phc_table *table, const phc_weight_curve_read_options *options,
                                 size_t **rows, size_t *n, phc_error *err);

/* Frees what phc_weight_curve_read_table allocated and zeroes *w; weighings
 * of your own arrays (w->storage NULL) are left alone.  Accepts NULL. */
void phc_weighings_release(phc_weighings *w);

#endif /* PHC_COSTS_WEIGHT_TABLE_H */
