/* The distinct times of a data set's observations: kinds whose model runs
 * forward in time (weight_curve, soil_probe) evaluate it once per distinct
 * time, in order, and map every observation onto its time. */
#ifndef PHC_COSTS_UNIQUE_TIMES_H
#define PHC_COSTS_UNIQUE_TIMES_H

#include <stddef.h>

#include "model/status.h"

/* unique (malloc'd, *m values): the sorted distinct values of t[0..n-1];
 * at (malloc'd, n values): the index in unique of every t[i].  On failure
 * (PHC_ERR_NOMEM, with err set) nothing is allocated. */
int phc_unique_times(const double *t, size_t n, double **unique, size_t *m, size_t **at, phc_error *err);

#endif /* PHC_COSTS_UNIQUE_TIMES_H */
