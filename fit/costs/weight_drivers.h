/* What drives a plant on a balance besides its own water model: a light
 * schedule or covariate readings that change the loss rate over the day, and
 * a pot whose soil feeds the plant (options.day, weighings.covariates and
 * options.pot of a weight_curve data set, fit/costs/weight_curve.h;
 * model/water_balance.h).
 *
 *   day (phc_weight_day): start 07:00, end 23:00, night_factor 0.1
 *       g(t) = 1 by day, night_factor by night (a fitted slot `night_factor`
 *       when it is NAN).  Clock times are local; on a calendar (logger
 *       timestamps) the day's start and end are placed through the time zone
 *       (daylight saving moves them), otherwise `clock` gives the local time
 *       of the first weighing.
 *   covariates (columns PAR, VPD; the linear law)
 *       g = 1 + sum_j loss_<column_j> x_j, x_j the mean of the column's two
 *       readings around each interval between weighings; one fitted slot
 *       loss_<column> per column.
 *   pot (phc_weight_pot): capacity 300 g, conductance 0.01 g/s
 *       the soil store; a value left NAN is a fitted slot (pot_capacity, g;
 *       pot_conductance, g/s).
 * No YAML here: the config's `day`, `covariates` and `pot` keys are read by
 * fit/config/weight_curve_yaml.c. */
#ifndef PHC_WEIGHT_DRIVERS_H
#define PHC_WEIGHT_DRIVERS_H

#include <stddef.h>

#include "fit/costs/origin.h"
#include "model/status.h"
#include "model/water_balance.h"

/* A light schedule: leaves lose night_factor times the day's rate by night. */
typedef struct phc_weight_day {
    int on;
    double start, end;    /* local clock, s since midnight, start < end (07:00 = 25200) */
    double night_factor;  /* >= 0, or NAN: a fitted slot night_factor */
    double clock;         /* without a calendar: the local clock time of the first
                             weighing kept, s since midnight; NAN on a calendar */
} phc_weight_day;

/* The pot's soil as a water store joined to the plant's root segment; plant
 * and soil start in equilibrium, sharing initial_water. */
typedef struct phc_weight_pot {
    int on;
    double capacity;      /* g > 0: the soil water at which its pressure equals that of a
                             full plant segment; NAN: a fitted slot pot_capacity */
    double conductance;   /* g/s >= 0: the exchange per unit difference of relative fill;
                             NAN: a fitted slot pot_conductance */
} phc_weight_pot;

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

/* Sets up the drivers of n_rows kept weighings at times t (s since the
 * first): the schedule `day` (NULL or day->on 0: none), the covariates
 * (n_rows x n_cov readings, row-major, finite; names: their columns) and the
 * pot (NULL or pot->on 0: none).  t0_posix / timezone: the first weighing's
 * POSIX time and zone (NAN / NULL without a calendar).  Errors name the
 * option through `origin` ("day.start", "pot.capacity", ...; the kind
 * "weight_curve" without one). */
int phc_weight_drivers_init(const phc_weight_day *day, const phc_weight_pot *pot,
                            const double *covariates, const char *const *names, size_t n_cov,
                            const double *t, size_t n_rows, double t0_posix, const char *timezone,
                            const phc_origin *origin, phc_weight_drivers *d, phc_error *err);
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
