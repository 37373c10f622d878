/* measurements/soil_netcdf.h in libphytocal: forwards to the NetCDF module
 * phytocal_netcdf.so (measurements/soil_netcdf.c with NetCDF-C and HDF5),
 * opened by the first phc_soil_nc_create (measurements/module_internal.h).
 * A writer exists only once the module is loaded. */
#include "measurements/soil_netcdf.h"

#include "measurements/module_internal.h"
#include "measurements/soil_netcdf_module_internal.h"

static phc_module netcdf_module = {PHC_NETCDF_MODULE_FILE, PHC_NETCDF_MODULE_ENTRY, PHC_NETCDF_MODULE_ABI,
                                   "NetCDF output (NetCDF-C, HDF5)", NULL, 0};

int phc_soil_nc_create(const char *path, const phc_soil_nc_grid *g, const char *title, const char *start_iso,
                       const double *capacity, const double *permeability, phc_soil_nc **out, phc_error *err)
{
    if (out)
        *out = NULL;
    const phc_netcdf_module_table *t = phc_module_table(&netcdf_module, err);
    return t ? t->create(path, g, title, start_iso, capacity, permeability, out, err) : PHC_ERR_IO;
}

int phc_soil_nc_append(phc_soil_nc *nc, double t_hours, const double *water, const double *nutrient,
                       phc_error *err)
{
    if (!nc)
        return phc_error_set(err, PHC_ERR_INVALID, "soil NetCDF: append to a NULL writer");
    const phc_netcdf_module_table *t = phc_module_table(&netcdf_module, err);
    return t ? t->append(nc, t_hours, water, nutrient, err) : PHC_ERR_IO;
}

size_t phc_soil_nc_frames(const phc_soil_nc *nc)
{
    const phc_netcdf_module_table *t = phc_module_loaded(&netcdf_module);
    return nc && t ? t->frames(nc) : 0;
}

int phc_soil_nc_close(phc_soil_nc *nc, phc_error *err)
{
    if (!nc) {
        phc_error_clear(err);
        return PHC_OK;
    }
    const phc_netcdf_module_table *t = phc_module_table(&netcdf_module, err);
    return t ? t->close(nc, err) : PHC_ERR_IO;
}
