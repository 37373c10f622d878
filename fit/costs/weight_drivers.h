/* What drives a plant on a balance besides its own water model: a light
 * schedule or covariate columns that change the loss rate over the day, and
 * a pot whose soil feeds the plant (the `day`, `covariates` and `pot` keys
 * of a weight_curve data set; model/water_balance.h).
 *
 *   day: {start: "07:00", end: "23:00", night_factor: 0.1, clock: "09:30"}
 *       g(t) = 1 by day, night_factor by night (a fitted slot `night_factor`
 *       when no number is given).  Clock times are local; with logger
 *       timestamps the day's start and end are placed through the time zone
 *       (daylight saving moves them), otherwise `clock` gives the local time
 *       of the first weighing.
 *   covariates: {columns: [PAR, VPD], law: linear}
 *       g = 1 + sum_j loss_<column_j> x_j, x_j the mean of the column's two
 *       readings around each interval between weighings; one fitted slot
 *       loss_<column> per column.
 *   pot: {capacity: 300, conductance: 0.01}
 *       the soil store; a key left out is a fitted slot (pot_capacity, g;
 *       pot_conductance, g/s).  `pot: {}` fits both. */
#ifndef PHC_WEIGHT_DRIVERS_H
#define PHC_WEIGHT_DRIVERS_H

#include <stddef.h>

#include "measurements/table.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"
#include "model/water_balance.h"

typedef struct phc_weight_drivers {
    /* loss pattern: intervals start[k] (s since the first weighing) */
    size_t n;
    double *start;
    unsigned char *night;  /* n (schedule) */
    size_t n_cov;
    char **cov_names;      /* n_cov column names */
    double *cov_x;         /* n x n_cov interval means (covariates) */
    int schedule;          /* day: given */
    double night_factor;   /* fixed, or NAN = a slot */
    double day_start, day_end; /* s since local midnight */
    double *g, *dg;        /* workspace: n, n x n_coef */
    /* pot */
    int pot;
    double capacity, conductance; /* fixed, or NAN = a slot */
} phc_weight_drivers;

/* Reads `day`, `covariates` and `pot` from the data set's node.  t: the
 * n_rows kept weighings' times (s since the first), rows: their table rows
 * (for covariate cells), t0_posix / timezone: the first weighing's POSIX
 * time and zone (NAN / NULL when the time column is a plain number).
 * Errors name the config line or the data file's line and column. */
int phc_weight_drivers_load(const phc_yaml_doc *doc, const phc_yaml_node *node,
                            const phc_table *table, const size_t *rows, const double *t,
                            size_t n_rows, double t0_posix, const char *timezone,
                            phc_weight_drivers *d, phc_error *err);
void phc_weight_drivers_free(phc_weight_drivers *d);

/* Does the loss change with time (a schedule or covariates)? */
int phc_weight_drivers_time_varying(const phc_weight_drivers *d);
/* The fitted slots the drivers add, in order: night_factor, loss_<col>...,
 * pot_capacity, pot_conductance (those not fixed).  names[i] is malloc'd. */
size_t phc_weight_drivers_slot_count(const phc_weight_drivers *d);
int phc_weight_drivers_slot_names(const phc_weight_drivers *d, char **names);
/* Number of coefficients of g (columns PHC_WB_COEF + j of the model's
 * sensitivities): 1 for a fitted night factor, n_cov for covariates. */
size_t phc_weight_drivers_coef_count(const phc_weight_drivers *d);

/* The model's loss pattern and pot at the drivers' slot values v (in the
 * order of phc_weight_drivers_slot_names).  *loss / *pot are set to NULL
 * when there is none. */
void phc_weight_drivers_model(phc_weight_drivers *d, const double *v,
                              const phc_water_loss_pattern **loss, phc_water_loss_pattern *loss_buf,
                              const phc_water_pot **pot, phc_water_pot *pot_buf);

#endif /* PHC_WEIGHT_DRIVERS_H */
