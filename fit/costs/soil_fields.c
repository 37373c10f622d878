/* Gridded outputs of the soil data sets: see soil_fields.h. */
#include "fit/costs/soil_fields.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "fit/soil_plots.h"
#include "measurements/soil_netcdf.h"

typedef struct fields_ctx {
    phc_soil_nc *nc;
    const phc_soil_setup *su;
    const char *dir, *base, *name;
    size_t frames;
    double vmax;
    phc_error *err;
    int rc;
} fields_ctx;

static int slice_png(fields_ctx *c, const phc_soil *s, size_t i)
{
    char path[8192], title[512];
    snprintf(path, sizeof path, "%s/%s_water_%zu.png", c->dir, c->base, i);
    snprintf(title, sizeof title, "%s: water at t = %.3g h (x-z slice, y row %zu)", c->name, s->t, s->ny / 2);
    return phc_plot_soil_slice(path, title, "water w (m³/m³)", s->w, s->nx, s->ny, s->nz, s->dx, 'y', s->ny / 2,
                               0, c->vmax, c->err);
}

static int visit(void *user, const phc_soil *s, size_t i, double *const *sw)
{
    (void)sw;
    fields_ctx *c = user;
    if ((c->rc = phc_soil_nc_append(c->nc, s->t, s->w, s->v, c->err)))
        return 1;
    if (i == 0 || i == c->frames / 2 || i == c->frames) {
        if (i == 0) { /* one colour scale for every slice: up to the wettest voxel at t = 0 or after rain */
            double m = 0;
            for (size_t q = 0; q < s->n; ++q)
                m = fmax(m, s->w[q]);
            c->vmax = m > 0 ? m : 1;
        }
        if ((c->rc = slice_png(c, s, i == 0 ? 0 : i == c->frames ? 2 : 1)))
            return 1;
    }
    return 0;
}

int phc_soil_write_fields(const phc_soil_setup *su, const double *p, double t_end, size_t frames,
                          const char *dir, const char *base, const char *name, phc_error *err)
{
    phc_soil *s = NULL;
    int rc = phc_soil_setup_build(su, p, &s, err);
    if (rc)
        return rc;
    char path[8192];
    snprintf(path, sizeof path, "%s/%s_fields.nc", dir, base);
    phc_soil_nc_grid g = {su->nx, su->ny, su->nz, su->dx, {0, 0, 0}, su->has_geo, su->geo.lat0, su->geo.lon0,
                          su->geo.h0, 1};
    fields_ctx c = {NULL, su, dir, base, name, frames ? frames : 1, 0, err, 0};
    rc = phc_soil_nc_create(path, &g, name, NULL, s->c, s->p, &c.nc, err);
    /* the capacity and permeability at p; the run below builds its own soil */
    phc_soil_free(s);
    s = NULL;
    if (rc)
        return rc;
    double *t = malloc((c.frames + 1) * sizeof *t);
    if (!t) {
        phc_soil_nc_close(c.nc, NULL);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; i <= c.frames; ++i)
        t[i] = t_end * (double)i / (double)c.frames;
    /* t[0] = 0 is visited before any step: the initial state */
    rc = phc_soil_setup_run(su, p, t, c.frames + 1, 0, visit, &c, &s, err);
    free(t);
    if (c.rc)
        rc = c.rc;
    int rc2 = phc_soil_nc_close(c.nc, rc ? NULL : err);
    if (!rc)
        rc = rc2;
    if (!rc) {
        char *md = phc_soil_setup_markdown(su, p, s);
        snprintf(path, sizeof path, "%s/%s_budget.md", dir, base);
        FILE *f = md ? fopen(path, "w") : NULL;
        if (!md)
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        else if (!f)
            rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
        else {
            fprintf(f, "# %s: soil set-up and water budget\n\n%s", name, md);
            if (ferror(f) | (fclose(f) != 0))
                rc = phc_error_set(err, PHC_ERR_IO, "%s: write failed", path);
        }
        free(md);
    }
    phc_soil_free(s);
    return rc;
}
