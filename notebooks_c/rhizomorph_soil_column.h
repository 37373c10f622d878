/* Shared by the soil notebooks (rhizomorph_soil_identifiability,
 * rhizomorph_soil_profiles): the infiltration column of the identifiability
 * study, its per-soil plan, the data-generating run, the data files with
 * seeded noise and the problem of one (soil, design) built through the C
 * API.  Header-only (static functions) because ctest builds each notebook
 * from its own .c file. */
#ifndef PHC_RHIZOMORPH_SOIL_COLUMN_H
#define PHC_RHIZOMORPH_SOIL_COLUMN_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/infiltration.h"
#include "fit/costs/soil_probe.h"
#include "fit/costs/soil_setup.h"
#include "fit/engine/problem.h"
#include "measurements/soil_probes.h"
#include "measurements/table.h"
#include "model/soil.h"


#define NSOIL 6
#define NDES 3
#define NPROBE 4
#define RAIN_RATE 0.01 /* m/h */
#define RAIN_END 2.0   /* h */
#define W0 1e-4        /* initial w at the true c: fill = W0 / c */
#define Z_TARGET 2.0   /* m: the window ends when the water could reach this deep */
#define T_MIN 6.0
#define T_MAX 120.0
#define NOISE_FRAC 0.02 /* probe noise sd: 2% of the noiseless signal range */
#define SIGMA_DEPTH 0.01 /* m */
#define START_FACTOR 3.0
#define REL_SE_OK 0.10
#define GAMMA_OK 20.0
#define CORR_OK 0.95
#define MAX_T 512

__attribute__((unused)) static const double probe_frac[NPROBE] = {0.1, 0.25, 0.45, 0.7};
__attribute__((unused)) static const char *const des_name[NDES] = {"A: probes w", "B: probes w/c", "C: 80% depth"};
__attribute__((unused)) static const char des_tag[NDES] = {'A', 'B', 'C'};

/* ---- small seeded RNG: splitmix64 + Box-Muller ---- */
static uint64_t rng_state;
__attribute__((unused)) static uint64_t splitmix64(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
__attribute__((unused)) static double uniform01(void) { return ((splitmix64() >> 11) + 0.5) * (1.0 / 9007199254740992.0); }
__attribute__((unused)) static double gauss(void)
{
    double u = uniform01(), v = uniform01();
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

/* ---- the per-soil design ---- */
typedef struct plan {
    double T, dt_obs, dx, dt, ell, limit, G;
    size_t nz, nt;
    double depth[NPROBE];
} plan;

__attribute__((unused)) static double reach(double p, double D, double T) { return p * T + 2.0 * sqrt(D * T); }

__attribute__((unused)) static void plan_for(double c, double p, plan *pl)
{
    const double D = p / c;
    double lo = 1e-3, hi = 1e4;
    for (int i = 0; i < 200; ++i) { /* reach is increasing in T */
        double mid = sqrt(lo * hi);
        if (reach(p, D, mid) < Z_TARGET)
            lo = mid;
        else
            hi = mid;
    }
    double T = fmin(fmax(hi, T_MIN), T_MAX);
    double dto = 0.25 * fmax(1.0, (double)lround(T / 48.0 / 0.25));
    pl->dt_obs = dto;
    pl->nt = (size_t)ceil(T / dto - 1e-9);
    pl->T = dto * (double)pl->nt;
    pl->ell = reach(p, D, pl->T);
    pl->dx = fmin(fmax(0.01 * round(100.0 * pl->ell / 40.0), 0.02), 0.05);
    pl->nz = (size_t)ceil(1.25 * pl->ell / pl->dx);
    for (int k = 0; k < NPROBE; ++k)
        pl->depth[k] = 0.01 * round(100.0 * probe_frac[k] * pl->ell);
    pl->G = p * pl->T / sqrt(2.0 * D * pl->T); /* gravity displacement / diffusion length */
}

__attribute__((unused)) static phc_soil *build(const plan *pl, double c, double p, phc_error *err)
{
    phc_soil *s = phc_soil_new(1, 1, pl->nz, pl->dx);
    if (!s) {
        phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        return NULL;
    }
    s->params.boundary[PHC_SOIL_XMIN] = s->params.boundary[PHC_SOIL_XMAX] = PHC_SOIL_PERIODIC;
    s->params.boundary[PHC_SOIL_YMIN] = s->params.boundary[PHC_SOIL_YMAX] = PHC_SOIL_PERIODIC;
    s->params.boundary[PHC_SOIL_ZMIN] = s->params.boundary[PHC_SOIL_ZMAX] = PHC_SOIL_BLOCK;
    s->params.substep = 0; /* as the configs: a step over the limit is refused, not sub-stepped */
    phc_soil_layer layer = {0.0, c, p, 1.0, 0.0, W0 / c, 0.0};
    phc_soil_rain rain = {0.0, RAIN_END, RAIN_RATE, 0.0, 0.0, 0.0, 0.0, 0.0};
    if (phc_soil_set_layers(s, &layer, 1, err) || phc_soil_set_rain(s, &rain, 1, err)) {
        phc_soil_free(s);
        return NULL;
    }
    phc_soil_budget_reset(s);
    return s;
}

/* The noiseless observations of the three designs at the truth:
 * w[k][i], f[k][i] (probe i at time k) and d[k]. */
__attribute__((unused)) static int simulate(const plan *pl, double c, double p, double (*w)[NPROBE], double (*f)[NPROBE], double *d,
                    double *closing, phc_error *err)
{
    phc_soil *s = build(pl, c, p, err);
    if (!s)
        return 1;
    s->params.dt = pl->dt;
    double *w_ref = malloc(s->n * sizeof *w_ref);
    if (!w_ref) {
        phc_soil_free(s);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    memcpy(w_ref, s->w, s->n * sizeof *w_ref);
    const double top = (double)pl->nz * pl->dx;
    int rc = phc_soil_run(s, 0.0, err); /* as the infiltration data set does: t = 0 first */
    for (size_t k = 0; !rc && k < pl->nt; ++k) {
        if ((rc = phc_soil_run(s, pl->dt_obs * (double)(k + 1), err)))
            break;
        for (int i = 0; i < NPROBE; ++i) {
            double wts[8], val;
            size_t idx[8];
            if ((rc = phc_soil_sample(s, s->w, 0.5 * pl->dx, 0.5 * pl->dx, top - pl->depth[i], &val, wts, idx))) {
                phc_error_set(err, rc, "probe %d outside the grid", i + 1);
                break;
            }
            double fv = 0;
            for (int q = 0; q < 8; ++q)
                fv += wts[q] * s->w[idx[q]] / s->c[idx[q]];
            w[k][i] = val;
            f[k][i] = fv;
        }
        d[k] = phc_soil_infiltration_depth(s, w_ref, 0.8, s->budget.water_in, NULL, NULL);
    }
    *closing = fabs(s->budget.water_closing) / s->budget.water_in;
    free(w_ref);
    phc_soil_free(s);
    return rc;
}

/* ---- the problems, built through the C API ---- */

/* The column's soil (model/soil.h through fit/costs/soil_setup.h): 1 x 1 x
 * nz voxels of dx m, sides periodic, top and bottom BLOCK, the plan's fixed
 * step without sub-stepping, one layer of the true c and p starting at fill
 * W0 / c, rain RAIN_RATE m/h from 0 to RAIN_END h over the whole surface.
 * layer and rain are the caller's (options point at them). */
__attribute__((unused)) static phc_soil_setup_options column_soil(const plan *pl, double c, double p, phc_soil_setup_layer *layer,
                                          phc_soil_rain *rain)
{
    phc_soil_setup_options so = phc_soil_setup_options_default();
    so.nx = so.ny = 1;
    so.nz = pl->nz;
    so.dx = pl->dx;
    so.params.dt = pl->dt;
    so.params.substep = 0;
    so.params.boundary[PHC_SOIL_XMIN] = so.params.boundary[PHC_SOIL_XMAX] = PHC_SOIL_PERIODIC;
    so.params.boundary[PHC_SOIL_YMIN] = so.params.boundary[PHC_SOIL_YMAX] = PHC_SOIL_PERIODIC;
    so.params.boundary[PHC_SOIL_ZMIN] = so.params.boundary[PHC_SOIL_ZMAX] = PHC_SOIL_BLOCK;
    *layer = phc_soil_setup_layer_default();
    layer->c = c;
    layer->p = p;
    layer->fill = W0 / c;
    so.layers = layer;
    so.n_layers = 1;
    memset(rain, 0, sizeof *rain);
    rain->start = 0;
    rain->end = RAIN_END;
    rain->rate = RAIN_RATE;
    so.rain = rain;
    so.n_rain = 1;
    return so;
}

/* Design des's data set over the files the notebook wrote (data_file; the
 * probe table probe_file for A and B): soil_probe reading w (A) or w/c (B)
 * with times in h, or infiltration (C) of the 80% depth in m; sigma the
 * noise sd.  NULL with err set on failure. */
__attribute__((unused)) static phc_dataset *design_dataset(int des, const phc_soil_setup_options *so, double sigma, const char *data_file,
                                   const char *probe_file, phc_error *err)
{
    phc_dataset *ds = NULL;
    if (des < 2) {
        const phc_probe_columns pc = {.id = "id", .x = "x", .y = "y", .depth = "depth"};
        const phc_unit_conversion hours = {1.0, 0.0}; /* the readings' times are in h */
        phc_probe_table *probes = NULL;
        phc_probe_series *ser = NULL;
        phc_soil_probe_options o = phc_soil_probe_options_default();
        o.quantity = des == 0 ? PHC_SOIL_PROBE_WATER : PHC_SOIL_PROBE_FILL;
        o.sigma = sigma;
        o.soil = so;
        if (!phc_probe_table_read(probe_file, &pc, NULL, &probes, err) &&
            !phc_probe_series_read(data_file, "t", hours, "probe", "value", probes, &ser, err))
            phc_soil_probe_new(probes, ser, &o, &ds, err);
        phc_probe_series_free(ser);
        phc_probe_table_free(probes);
    } else {
        phc_table *t = NULL;
        phc_infiltration_options o = phc_infiltration_options_default();
        o.time = "t";
        o.time_unit = "h";
        o.depth = "d80";
        o.depth_unit = "m";
        o.fraction = 0.8;
        o.sigma = sigma;
        o.soil = so;
        if (!phc_table_read(data_file, &t, err))
            phc_infiltration_new(t, &o, &ds, err);
        phc_table_free(t);
    }
    if (ds && !(ds->name = strdup(des == 0 ? "probes-w" : des == 1 ? "probes-fill" : "depth80"))) {
        phc_dataset_free(ds);
        phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        return NULL;
    }
    return ds;
}

/* The fit of p and c for (soil, design) from the start (p0, c0): p in m/h
 * and c in their boxes [1e-6, 100 x truth], the column of the true soil,
 * the design's data set bound by name; units converted, stopping
 * tolerances kept above the model's accuracy and the problem checked, as
 * phc_config_load does for a config. */
__attribute__((unused)) static phc_problem *build_problem(const char *soil, int des, const plan *pl, double c, double p, double c0,
                                  double p0, double sigma, const char *data_file, const char *probe_file,
                                  phc_error *err)
{
    char name[128];
    snprintf(name, sizeof name, "ident-%s-%c%s", soil, des_tag[des], p0 == p && c0 == c ? "-from-truth" : "");
    phc_problem *pb = phc_problem_new(name);
    if (!pb) {
        phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        return NULL;
    }
    size_t ip = 0, ic = 0;
    int rc = phc_problem_add_parameter(pb, "p", p0, &ip, err);
    if (!rc && !(rc = phc_problem_add_parameter(pb, "c", c0, &ic, err))) {
        pb->params[ip].lower = pb->params[ic].lower = 1.0e-6;
        pb->params[ip].upper = 100.0 * p;
        pb->params[ic].upper = 100.0 * c;
        if (!(pb->params[ip].unit = strdup("m/h")))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    phc_soil_setup_layer layer;
    phc_soil_rain rain;
    const phc_soil_setup_options so = column_soil(pl, c, p, &layer, &rain);
    phc_dataset *ds = rc ? NULL : design_dataset(des, &so, sigma, data_file, probe_file, err);
    if (!rc && !ds)
        rc = err->status ? err->status : PHC_ERR_INPUT;
    if (!rc && !(rc = phc_problem_bind_by_name(pb, ds, err))) {
        rc = phc_problem_add_dataset(pb, ds, err);
        ds = NULL;
    }
    phc_dataset_free(ds);
    if (!rc)
        rc = phc_problem_finish(pb, 0, err);
    if (rc) {
        phc_problem_free(pb);
        return NULL;
    }
    return pb;
}

__attribute__((unused)) static double range_of(const double (*v)[NPROBE], size_t nt)
{
    double lo = INFINITY, hi = -INFINITY;
    for (size_t k = 0; k < nt; ++k)
        for (int i = 0; i < NPROBE; ++i)
            lo = fmin(lo, v[k][i]), hi = fmax(hi, v[k][i]);
    return hi - lo;
}

__attribute__((unused)) static int write_readings(const char *path, const plan *pl, const double (*v)[NPROBE], double sigma,
                          const char *what)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "# %s with Gaussian noise sd %.6g (seeded), written by the notebook\nt,probe,value\n", what, sigma);
    for (size_t k = 0; k < pl->nt; ++k)
        for (int i = 0; i < NPROBE; ++i)
            fprintf(f, "%.17g,P%d,%.17g\n", pl->dt_obs * (double)(k + 1), i + 1, v[k][i] + sigma * gauss());
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    return bad ? -1 : 0;
}

__attribute__((unused)) static int write_depths(const char *path, const plan *pl, const double *d, double sigma)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "# 80%% infiltration depth (m) with Gaussian noise sd %g m (seeded), written by the notebook\nt,d80\n",
            sigma);
    for (size_t k = 0; k < pl->nt; ++k)
        fprintf(f, "%.17g,%.17g\n", pl->dt_obs * (double)(k + 1), fmax(0.0, d[k] + sigma * gauss()));
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    return bad ? -1 : 0;
}

__attribute__((unused)) static int write_probes(const char *path, const plan *pl)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "# probes of the 1 x 1 column (grid metres), depth below the surface (m)\nid,x,y,depth\n");
    for (int i = 0; i < NPROBE; ++i)
        fprintf(f, "P%d,%.17g,%.17g,%.17g\n", i + 1, 0.5 * pl->dx, 0.5 * pl->dx, pl->depth[i]);
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    return bad ? -1 : 0;
}

#endif /* PHC_RHIZOMORPH_SOIL_COLUMN_H */
