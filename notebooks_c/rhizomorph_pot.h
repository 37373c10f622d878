/* The pot experiment of the Rhizomorph Fig. 15 and Fig. 16 notebooks: an
 * oak (STOCHASTIC, a fixed seed) grown in daily steps in a box of one soil
 * layer with blocked faces, watered for the first hour of every day, and
 * the root statistics both figures print.  A header of static functions,
 * like notebook_plot.h. */
#ifndef RHIZOMORPH_POT_H
#define RHIZOMORPH_POT_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "model/growth.h"
#include "model/soil.h"

typedef struct rz_pot {
    double c, p;          /* the soil's capacity and permeability (m/h) */
    phc_growth_summary S;
    double root_density;  /* m of root per m^3 of the voxels that hold root */
    double mean_depth;    /* m, root-length-weighted depth below the surface */
    double top_fraction;  /* fraction of root length in the top 0.1 m */
    size_t root_voxels;
    double min_w, mean_fill_top, mean_fill_bottom;
    size_t substeps;
    double seconds;       /* wall time of the growth */
    /* the grown plant and its soil, kept for the side view (rz_pot_free) */
    phc_growth *g;
    phc_soil *s;
} rz_pot;

/* The pot's size and watering. */
typedef struct rz_pot_setup {
    size_t nx, ny, nz;
    double dx;            /* m */
    double d;             /* soil growth resistance */
    double w0;            /* initial water, m^3/m^3 */
    double rain_depth;    /* m of water in the first hour of each day */
    int days;
    uint64_t seed;
    /* optional: edits the soil's fields after the layers (e.g. nutrients) */
    void (*fields)(phc_soil *s, void *user);
    void *user;
    /* optional (0 = off) */
    int upwind;                 /* 1: the upwind gravity flux (phc_soil_gravity) instead of Lax-Wendroff */
    double nutrient_allocation; /* the oak's nutrient_allocation (growth.h) */
    double seed_reserve;        /* > 0: replaces the oak preset's seed reserve (vigor) */
} rz_pot_setup;

static double rz_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void rz_pot_free(rz_pot *R)
{
    phc_growth_free(R->g); /* before the soil: it removes its sink hook */
    phc_soil_free(R->s);
    R->g = NULL;
    R->s = NULL;
}

/* Grows the oak in soil `preset` (phc_soil_preset) and fills R. */
static int rz_pot_run(const rz_pot_setup *u, const char *preset, rz_pot *R, phc_error *err)
{
    memset(R, 0, sizeof *R);
    if (phc_soil_preset(preset, &R->c, &R->p))
        return phc_error_set(err, PHC_ERR_INPUT, "unknown soil preset %s", preset);
    phc_soil *s = phc_soil_new(u->nx, u->ny, u->nz, u->dx);
    phc_soil_rain *rain = calloc((size_t)u->days, sizeof *rain);
    if (!s || !rain) {
        phc_soil_free(s);
        free(rain);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    phc_soil_layer L = {0.0, R->c, R->p, u->d, u->w0, -1.0, 0.0};
    for (int d = 0; d < u->days; ++d)
        rain[d] = (phc_soil_rain){24.0 * d, 24.0 * d + 1.0, u->rain_depth, 0.0, 0.0, 0.0, 0.0, 0.0};
    s->params.dt = 1.0;
    s->params.substep = 1;
    if (u->upwind)
        s->params.gravity = PHC_SOIL_GRAVITY_UPWIND;
    int rc = phc_soil_set_layers(s, &L, 1, err);
    if (!rc)
        rc = phc_soil_set_rain(s, rain, (size_t)u->days, err);
    free(rain);
    if (!rc && u->fields)
        u->fields(s, u->user);
    if (!rc)
        rc = phc_soil_check(s, err);
    phc_growth *g = NULL;
    phc_growth_params P;
    if (!rc)
        rc = phc_growth_preset("oak", &P, err);
    P.nutrient_allocation = u->nutrient_allocation;
    if (u->seed_reserve > 0)
        P.seed_reserve = u->seed_reserve;
    phc_growth_options o = phc_growth_options_default();
    o.mode = PHC_GROWTH_STOCHASTIC;
    o.seed = u->seed;
    o.base[0] = 0.5 * u->nx * u->dx, o.base[1] = 0.5 * u->ny * u->dx, o.base[2] = u->nz * u->dx;
    if (!rc)
        rc = phc_growth_new(&P, &o, s, &g, err);
    R->g = g;
    R->s = s;
    double t0 = rz_now();
    R->min_w = INFINITY;
    for (int d = 0; d < u->days && !rc; ++d) {
        rc = phc_growth_step(g, 1.0, err);
        for (size_t i = 0; i < s->n && !rc; ++i)
            R->min_w = fmin(R->min_w, s->w[i]);
    }
    R->seconds = rz_now() - t0;
    if (rc) {
        rz_pot_free(R);
        return rc;
    }
    R->substeps = s->budget.substeps;
    phc_growth_summarize(g, &R->S);
    /* fill of the top and bottom planes at the end */
    const size_t plane = u->nx * u->ny;
    double top = 0, bot = 0;
    for (size_t j = 0; j < plane; ++j) {
        top += s->w[j + plane * (u->nz - 1)] / s->c[j + plane * (u->nz - 1)];
        bot += s->w[j] / s->c[j];
    }
    R->mean_fill_top = top / plane, R->mean_fill_bottom = bot / plane;
    size_t n;
    const phc_growth_node *N = phc_growth_nodes(g, &n);
    unsigned char *has_root = calloc(s->n, 1);
    if (!has_root) {
        rz_pot_free(R);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    double len = 0, depth_sum = 0, top_len = 0;
    for (size_t i = 0; i < n; ++i) {
        const phc_growth_node *m = &N[i];
        if (m->length <= 0 || m->system != PHC_GROWTH_ROOT)
            continue;
        double c[3];
        for (int a = 0; a < 3; ++a)
            c[a] = m->head[a] + 0.5 * m->length * m->dir[a];
        double depth = o.base[2] - c[2];
        len += m->length, depth_sum += m->length * depth;
        if (depth < 0.1)
            top_len += m->length;
        long ix = (long)floor(c[0] / u->dx), iy = (long)floor(c[1] / u->dx),
             iz = (long)floor(c[2] / u->dx);
        if (ix >= 0 && iy >= 0 && iz >= 0 && ix < (long)u->nx && iy < (long)u->ny &&
            iz < (long)u->nz)
            has_root[ix + u->nx * (iy + u->ny * iz)] = 1;
    }
    for (size_t i = 0; i < s->n; ++i)
        R->root_voxels += has_root[i];
    free(has_root);
    R->mean_depth = len > 0 ? depth_sum / len : NAN;
    R->top_fraction = len > 0 ? top_len / len : NAN;
    R->root_density = R->root_voxels ? len / (R->root_voxels * u->dx * u->dx * u->dx) : NAN;
    return 0;
}

#endif /* RHIZOMORPH_POT_H */
