/* The soil NetCDF writer (measurements/soil_netcdf.h), read back with the
 * netCDF C API, and the soil slice plot (fit/soil_plots.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <netcdf.h>

#include "check.h"
#include "fit/soil_plots.h"
#include "measurements/soil_netcdf.h"

enum { NX = 4, NY = 3, NZ = 5, NT = 3, N = NX * NY * NZ };

static size_t idx(size_t i, size_t j, size_t k)
{
    return i + NX * (j + NY * k);
}

/* The value written at frame t, voxel (i, j, k): distinct everywhere. */
static double water_value(int t, size_t i, size_t j, size_t k)
{
    return 0.1 + 0.01 * (double)t + 1e-3 * (double)i + 1e-4 * (double)j +
           1e-5 * (double)k;
}

static int att_text_equals(int ncid, int varid, const char *name,
                           const char *expect)
{
    size_t len = 0;
    if (nc_inq_attlen(ncid, varid, name, &len) != NC_NOERR)
        return 0;
    char *buf = calloc(len + 1, 1);
    int ok = buf && nc_get_att_text(ncid, varid, name, buf) == NC_NOERR &&
             strcmp(buf, expect) == 0;
    if (!ok)
        fprintf(stderr, "attribute %s: found '%s', expected '%s'\n", name,
                buf ? buf : "?", expect);
    free(buf);
    return ok;
}

static void test_write_read(const char *dir)
{
    char path[512];
    snprintf(path, sizeof path, "%s/soil.nc", dir);

    double cap[N], perm[N], water[N], nut[N];
    for (size_t k = 0; k < NZ; ++k)
        for (size_t j = 0; j < NY; ++j)
            for (size_t i = 0; i < NX; ++i) {
                cap[idx(i, j, k)] = 0.4 + 0.01 * (double)k;
                perm[idx(i, j, k)] = k == 0 ? 0.0 : 0.02;
            }

    phc_soil_nc_grid g = {0};
    g.nx = NX;
    g.ny = NY;
    g.nz = NZ;
    g.dx = 0.1;
    g.origin[0] = -0.2;
    g.origin[1] = 1.0;
    g.origin[2] = -0.5;
    g.has_geo = 1;
    g.lat0 = 52.5;
    g.lon0 = 13.4;
    g.h0 = 34.0;
    g.with_nutrient = 1;

    phc_error err;
    phc_soil_nc *nc = NULL;
    int rc = phc_soil_nc_create(path, &g, "unit test", "2026-05-01T00:00:00Z",
                                cap, perm, &nc, &err);
    CHECK(rc == PHC_OK);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    for (int t = 0; t < NT; ++t) {
        for (size_t k = 0; k < NZ; ++k)
            for (size_t j = 0; j < NY; ++j)
                for (size_t i = 0; i < NX; ++i) {
                    water[idx(i, j, k)] = water_value(t, i, j, k);
                    nut[idx(i, j, k)] = 10.0 * t + (double)idx(i, j, k);
                }
        rc = phc_soil_nc_append(nc, 0.5 * t, water, nut, &err);
        CHECK(rc == PHC_OK);
    }
    /* Time must increase; nutrients must be given (created with them). */
    CHECK(phc_soil_nc_append(nc, 0.5, water, nut, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "time must increase");
    CHECK(phc_soil_nc_append(nc, 9.0, water, NULL, &err) == PHC_ERR_INVALID);
    CHECK(phc_soil_nc_frames(nc) == NT);
    /* Until close the data live under the temporary name only. */
    CHECK(access(path, F_OK) != 0);
    rc = phc_soil_nc_close(nc, &err);
    CHECK(rc == PHC_OK);
    CHECK(access(path, F_OK) == 0);
    CHECK(phc_soil_nc_close(NULL, &err) == PHC_OK);

    int ncid;
    rc = nc_open(path, NC_NOWRITE, &ncid);
    CHECK(rc == NC_NOERR);
    if (rc != NC_NOERR)
        return;

    /* Dimensions. */
    int dim;
    size_t len;
    const char *dnames[4] = {"time", "z", "y", "x"};
    size_t dlens[4] = {NT, NZ, NY, NX};
    for (int d = 0; d < 4; ++d) {
        CHECK(nc_inq_dimid(ncid, dnames[d], &dim) == NC_NOERR &&
              nc_inq_dimlen(ncid, dim, &len) == NC_NOERR && len == dlens[d]);
    }
    int unlimited = -1;
    CHECK(nc_inq_unlimdim(ncid, &unlimited) == NC_NOERR);
    CHECK(nc_inq_dimid(ncid, "time", &dim) == NC_NOERR && dim == unlimited);

    /* Coordinates: voxel centres origin + (i + 1/2) dx. */
    int vx, vy, vz, vt, vw, vn, vc;
    double x[NX], y[NY], z[NZ], t[NT];
    CHECK(nc_inq_varid(ncid, "x", &vx) == NC_NOERR &&
          nc_get_var_double(ncid, vx, x) == NC_NOERR);
    CHECK(nc_inq_varid(ncid, "y", &vy) == NC_NOERR &&
          nc_get_var_double(ncid, vy, y) == NC_NOERR);
    CHECK(nc_inq_varid(ncid, "z", &vz) == NC_NOERR &&
          nc_get_var_double(ncid, vz, z) == NC_NOERR);
    CHECK(nc_inq_varid(ncid, "time", &vt) == NC_NOERR &&
          nc_get_var_double(ncid, vt, t) == NC_NOERR);
    CHECK_NEAR(x[0], -0.15, 1e-12, 0);
    CHECK_NEAR(x[3], 0.15, 1e-12, 0);
    CHECK_NEAR(y[2], 1.25, 1e-12, 0);
    CHECK_NEAR(z[0], -0.45, 1e-12, 0);
    CHECK_NEAR(z[4], -0.05, 1e-12, 0);
    CHECK_NEAR(t[2], 1.0, 0, 0);

    /* Attributes. */
    CHECK(att_text_equals(ncid, NC_GLOBAL, "Conventions", "CF-1.8"));
    CHECK(att_text_equals(ncid, NC_GLOBAL, "title", "unit test"));
    CHECK(att_text_equals(ncid, vx, "units", "m"));
    CHECK(att_text_equals(ncid, vx, "axis", "X"));
    CHECK(att_text_equals(ncid, vz, "positive", "up"));
    CHECK(att_text_equals(ncid, vt, "units",
                          "hours since 2026-05-01T00:00:00Z"));
    CHECK(att_text_equals(ncid, vt, "axis", "T"));
    CHECK(nc_inq_varid(ncid, "water", &vw) == NC_NOERR);
    CHECK(att_text_equals(ncid, vw, "units", "m3 m-3"));
    CHECK(att_text_equals(ncid, vw, "long_name", "volumetric water content"));
    CHECK(att_text_equals(ncid, vw, "grid_mapping", "crs"));
    CHECK(nc_inq_varid(ncid, "permeability", &vc) == NC_NOERR);
    CHECK(att_text_equals(ncid, vc, "units", "m h-1"));
    double lat = 0.0;
    CHECK(nc_get_att_double(ncid, NC_GLOBAL, "geospatial_lat_origin", &lat) ==
              NC_NOERR &&
          lat == 52.5);

    /* Water at (t = 2, k = 4, j = 1, i = 3): C order (time, z, y, x). */
    size_t at[4] = {2, 4, 1, 3};
    double w = -1.0;
    CHECK(nc_get_var1_double(ncid, vw, at, &w) == NC_NOERR);
    CHECK(w == water_value(2, 3, 1, 4));
    /* A whole frame equals the array as written (layout i + nx (j + ny k)). */
    double frame[N];
    size_t start[4] = {1, 0, 0, 0}, count[4] = {1, NZ, NY, NX};
    CHECK(nc_get_vara_double(ncid, vw, start, count, frame) == NC_NOERR);
    int same = 1;
    for (size_t k = 0; k < NZ; ++k)
        for (size_t j = 0; j < NY; ++j)
            for (size_t i = 0; i < NX; ++i)
                same &= frame[idx(i, j, k)] == water_value(1, i, j, k);
    CHECK(same);
    CHECK(nc_inq_varid(ncid, "nutrient", &vn) == NC_NOERR);
    double v = -1.0;
    CHECK(nc_get_var1_double(ncid, vn, at, &v) == NC_NOERR);
    CHECK(v == 20.0 + (double)idx(3, 1, 4));
    double c = -1.0;
    size_t at3[3] = {4, 1, 3};
    CHECK(nc_get_var1_double(ncid, vc, at3, &c) == NC_NOERR && c == 0.02);
    nc_close(ncid);

    /* Without a start date or nutrients. */
    g.has_geo = 0;
    g.with_nutrient = 0;
    rc = phc_soil_nc_create(path, &g, NULL, NULL, cap, perm, &nc, &err);
    CHECK(rc == PHC_OK);
    if (rc == PHC_OK) {
        CHECK(phc_soil_nc_append(nc, 0.0, water, nut, &err) ==
              PHC_ERR_INVALID);
        CHECK(phc_soil_nc_append(nc, 0.0, water, NULL, &err) == PHC_OK);
        CHECK(phc_soil_nc_close(nc, &err) == PHC_OK);
        CHECK(nc_open(path, NC_NOWRITE, &ncid) == NC_NOERR);
        CHECK(nc_inq_varid(ncid, "nutrient", &vn) == NC_ENOTVAR);
        CHECK(nc_inq_varid(ncid, "time", &vt) == NC_NOERR);
        CHECK(att_text_equals(ncid, vt, "units",
                              "hours since 0001-01-01 00:00:00"));
        nc_close(ncid);
    }
    unlink(path);

    /* Bad start date. */
    rc = phc_soil_nc_create(path, &g, NULL, "May 1st", cap, perm, &nc, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(nc == NULL);
    CHECK_STR_CONTAINS(err.message, "May 1st");
}

static void test_missing_dir(const char *dir)
{
    char path[512];
    snprintf(path, sizeof path, "%s/no/such/dir/soil.nc", dir);
    double cap[N] = {0}, perm[N] = {0};
    phc_soil_nc_grid g = {0};
    g.nx = NX;
    g.ny = NY;
    g.nz = NZ;
    g.dx = 0.1;
    phc_error err;
    phc_soil_nc *nc = (phc_soil_nc *)&g; /* must be reset to NULL */
    int rc = phc_soil_nc_create(path, &g, NULL, NULL, cap, perm, &nc, &err);
    CHECK(rc == PHC_ERR_IO);
    CHECK(err.status == PHC_ERR_IO);
    CHECK(nc == NULL);
    CHECK_STR_CONTAINS(err.message, path);
    printf("missing directory: %s\n", err.message);
}

static void test_plot(const char *dir)
{
    enum { PX = 40, PY = 30, PZ = 25 };
    const double dx = 0.02;
    double *f = malloc(sizeof(double) * PX * PY * PZ);
    if (!f) {
        CHECK(f != NULL);
        return;
    }
    /* A wet blob below the surface on a dry background. */
    for (size_t k = 0; k < PZ; ++k)
        for (size_t j = 0; j < PY; ++j)
            for (size_t i = 0; i < PX; ++i) {
                double x = (i + 0.5) * dx - 0.3, y = (j + 0.5) * dx - 0.3;
                double z = (k + 0.5) * dx - 0.3;
                f[i + PX * (j + PY * k)] =
                    0.05 + 0.35 * exp(-(x * x + y * y + z * z) / 0.02);
            }
    char path[512];
    snprintf(path, sizeof path, "%s/soil_slice.png", PHC_BINARY_DIR);
    phc_error err;
    int rc = phc_plot_soil_slice(path, "Soil water after 24 h",
                                 "water w (m\xc2\xb3/m\xc2\xb3)", f, PX, PY,
                                 PZ, dx, 'x', PY / 2, NAN, NAN, &err);
    CHECK(rc == PHC_OK);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    struct stat st;
    CHECK(stat(path, &st) == 0 && st.st_size > 1000);
    printf("slice plot: %s\n", path);

    /* y-z slice with a fixed range (saturating) and a missing voxel. */
    f[PX / 2 + PX * (0 + PY * (PZ - 1))] = NAN;
    snprintf(path, sizeof path, "%s/soil_slice_y.png", PHC_BINARY_DIR);
    rc = phc_plot_soil_slice(path, "Soil water #2, y-z slice",
                             "water w (m\xc2\xb3/m\xc2\xb3)", f, PX, PY, PZ,
                             dx, 'y', PX / 2, 0.1, 0.3, &err);
    CHECK(rc == PHC_OK);
    CHECK(stat(path, &st) == 0 && st.st_size > 1000);
    printf("slice plot: %s\n", path);

    /* Argument errors, caught before PLplot sees them. */
    snprintf(path, sizeof path, "%s/bad.png", dir);
    CHECK(phc_plot_soil_slice(path, NULL, "w", f, PX, PY, PZ, dx, 'x', PY,
                              NAN, NAN, &err) == PHC_ERR_INVALID);
    CHECK(phc_plot_soil_slice(path, NULL, "w", f, PX, PY, PZ, dx, 'z', 0,
                              NAN, NAN, &err) == PHC_ERR_INVALID);
    CHECK(phc_plot_soil_slice(path, NULL, "w", f, PX, PY, PZ, dx, 'x', 0,
                              0.3, 0.1, &err) == PHC_ERR_INVALID);
    CHECK(access(path, F_OK) != 0);
    free(f);
}

int main(void)
{
    char dir[] = "/tmp/phc_soil_nc_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_write_read(dir);
    test_missing_dir(dir);
    test_plot(dir);
    rmdir(dir);
    return check_finish("test_soil_netcdf");
}
