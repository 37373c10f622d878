/* Unit test of the modules opened on first use (measurements/module_internal.h):
 *  1. At start nothing of the modules is mapped (this program links
 *     libphytocal only): no phytocal_*.so, no OpenCV, Ceres, NetCDF, assimp.
 *  2. PHYTOCAL_MODULE_DIR naming an empty folder: the photo, mesh, NetCDF
 *     and Ceres entry points fail with PHC_ERR_IO and a message naming the
 *     module and the path tried; phc_nls_new returns NULL and
 *     phc_nls_new_error says why; nothing crashes.
 *  3. A foreign file in the module's place (the photos module copied as
 *     phytocal_mesh.so): refused, "not a phytocal support meshes module
 *     (no phc_mesh_module_entry)".
 *  4. With the variable unset the same calls work (a failed load is
 *     retried): the viridis table, a mesh query, a least-squares problem;
 *     each of those modules is then mapped once, from the build folder (the
 *     NetCDF one, never asked for, is not), and a later
 *     PHYTOCAL_MODULE_DIR no longer matters (the table is kept). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/engine/ceres_bridge.h"
#include "measurements/photo.h"
#include "measurements/soil_netcdf.h"
#include "measurements/support_mesh.h"

/* How many lines of /proc/self/maps contain `what` (as mapped files). */
static int mapped(const char *what)
{
    FILE *f = fopen("/proc/self/maps", "r");
    char line[4096], last[4096] = "";
    int n = 0;
    while (f && fgets(line, sizeof line, f)) {
        const char *name = strchr(line, '/');
        if (name && strstr(name, what) && strcmp(name, last) != 0) {
            ++n; /* one object maps several segments: count distinct names in a row */
            snprintf(last, sizeof last, "%s", name);
        }
    }
    if (f)
        fclose(f);
    return n;
}

static const double tri_v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
static const size_t tri_t[3] = {0, 1, 2};

int main(void)
{
    /* 1. */
    const char *heavy[] = {"phytocal_", "libopencv", "libceres", "libnetcdf", "libassimp", "libhdf5"};
    for (size_t i = 0; i < sizeof heavy / sizeof heavy[0]; ++i) {
        CHECK(mapped(heavy[i]) == 0);
        if (mapped(heavy[i]))
            fprintf(stderr, "  mapped at start: %s\n", heavy[i]);
    }
    CHECK(mapped("libphytocal") == 1);

    /* 2. */
    char empty[] = "/tmp/phc_test_module_XXXXXX";
    CHECK(mkdtemp(empty) != NULL);
    setenv("PHYTOCAL_MODULE_DIR", empty, 1);
    char want[8400];
    phc_error err;
    double lut[3 * 256];
    int rc = phc_photo_viridis(lut, &err);
    CHECK(rc == PHC_ERR_IO && err.status == PHC_ERR_IO);
    snprintf(want, sizeof want, "%s/phytocal_photo.so: cannot load the photos (OpenCV) module", empty);
    CHECK_STR_CONTAINS(err.message, want);
    phc_error_clear(&err);
    phc_support_mesh *m = phc_support_mesh_from_arrays(tri_v, 3, tri_t, 1, "triangle", &err);
    CHECK(m == NULL && err.status == PHC_ERR_IO);
    snprintf(want, sizeof want, "%s/phytocal_mesh.so: cannot load the support meshes (assimp, CGAL) module", empty);
    CHECK_STR_CONTAINS(err.message, want);
    phc_soil_nc_grid g = {2, 2, 2, 0.01, {0, 0, 0}, 0, 0, 0, 0, 0};
    phc_soil_nc *nc = (phc_soil_nc *)&g; /* must be reset to NULL */
    snprintf(want, sizeof want, "%s/never.nc", empty);
    rc = phc_soil_nc_create(want, &g, "t", NULL, NULL, NULL, &nc, &err);
    CHECK(rc == PHC_ERR_IO && nc == NULL);
    CHECK_STR_CONTAINS(err.message, "phytocal_netcdf.so: cannot load the NetCDF output (NetCDF-C, HDF5) module");
    CHECK(phc_soil_nc_frames(NULL) == 0);
    CHECK(phc_soil_nc_close(NULL, &err) == PHC_OK);
    CHECK(access(want, F_OK) != 0);
    phc_nls *nls = phc_nls_new(2);
    CHECK(nls == NULL);
    rc = phc_nls_new_error("fit", &err);
    CHECK(rc == PHC_ERR_IO);
    snprintf(want, sizeof want, "%s/phytocal_ceres.so: cannot load the Ceres Solver module", empty);
    CHECK_STR_CONTAINS(err.message, want);
    CHECK(phc_nls_residual_count(NULL) == 0);
    CHECK(phc_nls_solve(NULL, NULL, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK(strlen(phc_nls_version()) > 0); /* compiled in: needs no module */
    phc_support_mesh_free(NULL);

    /* 3. */
    char src[4096], dst[4200], cmd[8600];
    snprintf(src, sizeof src, "%s/phytocal_photo.so", PHC_BINARY_DIR);
    snprintf(dst, sizeof dst, "%s/phytocal_mesh.so", empty);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", src, dst);
    CHECK(system(cmd) == 0);
    m = phc_support_mesh_from_arrays(tri_v, 3, tri_t, 1, "triangle", &err);
    CHECK(m == NULL && err.status == PHC_ERR_IO);
    snprintf(want, sizeof want, "%s: not a phytocal support meshes (assimp, CGAL) module (no phc_mesh_module_entry)",
             dst);
    CHECK_STR_CONTAINS(err.message, want);

    /* 4. */
    unsetenv("PHYTOCAL_MODULE_DIR");
    CHECK(phc_photo_viridis(lut, &err) == PHC_OK);
    CHECK(lut[0] > 0.2 && lut[0] < 0.3 && lut[3 * 255 + 1] > 0.85); /* viridis: dark purple to yellow */
    m = phc_support_mesh_from_arrays(tri_v, 3, tri_t, 1, "triangle", &err);
    CHECK(m != NULL);
    double c[3] = {0}, n[3] = {0};
    CHECK(m && phc_support_mesh_closest(m, (const double[]){0.25, 0.25, 1}, c, n) == 0);
    CHECK_NEAR(c[0], 0.25, 1e-15, 0);
    CHECK_NEAR(c[2], 0.0, 1e-15, 0);
    CHECK(phc_support_mesh_triangle_count(m) == 1);
    phc_support_mesh_free(m);
    nls = phc_nls_new(2);
    CHECK(nls != NULL);
    phc_nls_free(nls);
    const char *loaded[] = {"photo", "mesh", "ceres"};
    for (int i = 0; i < 3; ++i) {
        snprintf(want, sizeof want, "%s/phytocal_%s.so", PHC_BINARY_DIR, loaded[i]);
        CHECK(mapped(want) == 1);
    }
    CHECK(mapped("phytocal_netcdf.so") == 0); /* never asked for */
    setenv("PHYTOCAL_MODULE_DIR", empty, 1); /* loaded tables are kept */
    CHECK(phc_photo_viridis(lut, &err) == PHC_OK);
    unsetenv("PHYTOCAL_MODULE_DIR");

    snprintf(cmd, sizeof cmd, "rm -rf '%s'", empty);
    CHECK(system(cmd) == 0);
    return check_finish("test_module");
}
