/* Gridded outputs of the soil data sets for `phytocal simulate`: the water
 * and nutrient fields over time as CF NetCDF (measurements/soil_netcdf.h),
 * vertical slices of the water as PNG (fit/soil_plots.h) and the set-up
 * with its mass budget as markdown. */
#ifndef PHC_COSTS_SOIL_FIELDS_H
#define PHC_COSTS_SOIL_FIELDS_H

#include <stddef.h>

#include "fit/costs/soil_setup.h"
#include "model/status.h"

/* Runs the set-up at slot values p from 0 to t_end h and writes into dir:
 *   <base>_fields.nc        `frames` + 1 frames at equal spacing (t = 0 included)
 *   <base>_water_<i>.png    x-z slices through the middle row at t = 0, t_end/2, t_end,
 *                           on one colour scale
 *   <base>_budget.md        the set-up, the stability limit and the budget
 * `name` titles the plots. */
int phc_soil_write_fields(const phc_soil_setup *su, const double *p, double t_end, size_t frames,
                          const char *dir, const char *base, const char *name, phc_error *err);

#endif /* PHC_COSTS_SOIL_FIELDS_H */
