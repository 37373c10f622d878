/* measurements/soil_netcdf_module_internal.h: the table of the NetCDF
 * module, phytocal_netcdf.so (NetCDF-C with HDF5, measurements/soil_netcdf.c;
 * see module_internal.h).  libphytocal's soil_netcdf.h functions forward to
 * it (measurements/soil_netcdf_module.c).  Internal. */
#ifndef PHC_SOIL_NETCDF_MODULE_INTERNAL_H
#define PHC_SOIL_NETCDF_MODULE_INTERNAL_H

#include "measurements/soil_netcdf.h"

/* Bumped whenever a member below changes. */
#define PHC_NETCDF_MODULE_ABI 1
#define PHC_NETCDF_MODULE_ENTRY "phc_netcdf_module_entry"
#define PHC_NETCDF_MODULE_FILE "phytocal_netcdf.so"

/* One member per soil_netcdf.h function, same signature. */
typedef struct phc_netcdf_module_table {
    int (*create)(const char *path, const phc_soil_nc_grid *g, const char *title, const char *start_iso,
                  const double *capacity, const double *permeability, phc_soil_nc **out, phc_error *err);
    int (*append)(phc_soil_nc *nc, double t_hours, const double *water, const double *nutrient, phc_error *err);
    size_t (*frames)(const phc_soil_nc *nc);
    int (*close)(phc_soil_nc *nc, phc_error *err);
} phc_netcdf_module_table;

/* The module's entry point (in phytocal_netcdf.so): the table for ABI, or
 * NULL for another version. */
const void *phc_netcdf_module_entry(int abi);

#endif
