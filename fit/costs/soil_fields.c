/* Gridded outputs of the soil data sets: see soil_fields.h. */
#include "fit/costs/soil_fields.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/soil_plots.h"
#include "measurements/atomic_file.h"
#include "measurements/soil_netcdf.h"

typedef struct fields_ctx {
    phc_soil_nc *nc;
    const phc_soil_setup *su;
    const char *dir, *base, *name;
    const char *nc_path;
    size_t frames;
    double *snap[3];   /* w at t = 0, t_end/2, t_end for the slices */
    double t_snap[3];
    phc_error *err;
    int rc;
} fields_ctx;

static int visit(void *user, const phc_soil *s, size_t i, const phc_soil_tangent *tan)
{
    (void)tan;
    fields_ctx *c = user;
    if (!c->nc) { /* t = 0: the file takes this soil's capacity and permeability */
        const phc_soil_setup *su = c->su;
        phc_soil_nc_grid g = {su->nx, su->ny, su->nz, su->dx, {0, 0, 0}, su->has_geo, su->geo.lat0, su->geo.lon0,
                              su->geo.h0, 1};
        if ((c->rc = phc_soil_nc_create(c->nc_path, &g, c->name, NULL, s->c, s->p, &c->nc, c->err)))
            return 1;
    }
    if ((c->rc = phc_soil_nc_append(c->nc, s->t, s->w, s->v, c->err)))
        return 1;
    int which = i == 0 ? 0 : i == c->frames ? 2 : i == c->frames / 2 ? 1 : -1;
    if (which >= 0) {
        memcpy(c->snap[which], s->w, s->n * sizeof *s->w);
        c->t_snap[which] = s->t;
    }
    return 0;
}

/* The three slices on one colour scale (0 to the wettest voxel of the three). */
static int slices(fields_ctx *c, const phc_soil_setup *su)
{
    const size_t n = su->nx * su->ny * su->nz;
    double vmax = 0;
    for (int q = 0; q < 3; ++q)
        for (size_t i = 0; i < n; ++i)
            vmax = fmax(vmax, c->snap[q][i]);
    for (int q = 0; q < 3; ++q) {
        char path[8192], title[512];
        snprintf(path, sizeof path, "%s/%s_water_%d.png", c->dir, c->base, q);
        snprintf(title, sizeof title, "%s: water at t = %.3g h", c->name, c->t_snap[q]);
        int rc = phc_plot_soil_slice(path, title, "water w (m³/m³)", c->snap[q], su->nx, su->ny, su->nz, su->dx,
                                     'x', su->ny / 2, 0, vmax > 0 ? vmax : 1, c->err);
        if (rc)
            return rc;
    }
    return PHC_OK;
}

int phc_soil_write_fields(const phc_soil_setup *su, const double *p, double t_end, size_t frames,
                          const char *dir, const char *base, const char *name, phc_error *err)
{
    phc_soil *s = NULL;
    int rc = PHC_OK;
    char path[8192];
    snprintf(path, sizeof path, "%s/%s_fields.nc", dir, base);
    const size_t n = su->nx * su->ny * su->nz;
    fields_ctx c = {NULL, su, dir, base, name, path, frames ? frames : 1, {NULL, NULL, NULL}, {0, 0, 0}, err, 0};
    for (int q = 0; q < 3; ++q)
        if (!(c.snap[q] = malloc(n * sizeof(double)))) {
            for (int r = 0; r < q; ++r)
                free(c.snap[r]);
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        }
    double *t = malloc((c.frames + 1) * sizeof *t);
    if (!t) {
        for (int q = 0; q < 3; ++q)
            free(c.snap[q]);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; i <= c.frames; ++i)
        t[i] = t_end * (double)i / (double)c.frames;
    /* t[0] = 0 is visited before any step: the initial state */
    rc = phc_soil_setup_run(su, p, t, c.frames + 1, 0, visit, &c, &s, err);
    free(t);
    if (c.rc)
        rc = c.rc;
    int rc2 = c.nc ? phc_soil_nc_close(c.nc, rc ? NULL : err) : PHC_OK;
    if (!rc)
        rc = rc2;
    if (!rc)
        rc = slices(&c, su);
    for (int q = 0; q < 3; ++q)
        free(c.snap[q]);
    if (!rc) {
        char *md = phc_soil_setup_markdown(su, p, s);
        snprintf(path, sizeof path, "%s/%s_budget.md", dir, base);
        phc_atomic_file *af = NULL;
        if (!md)
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        else if (!(rc = phc_atomic_file_open(path, &af, err))) {
            fprintf(phc_atomic_file_stream(af), "# %s: soil set-up and water budget\n\n%s", name, md);
            rc = phc_atomic_file_commit(af, err);
        }
        free(md);
    }
    phc_soil_free(s);
    return rc;
}
