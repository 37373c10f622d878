/* The soil shared by the soil data sets: see soil_setup.h. */
#include "fit/costs/soil_setup.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

phc_soil_setup_layer phc_soil_setup_layer_default(void)
{
    phc_soil_setup_layer l = {.c = NAN, .p = NAN, .d = 1, .fill = NAN, .water = NAN};
    return l;
}

phc_soil_setup_source phc_soil_setup_source_default(void)
{
    phc_soil_setup_source s = {.end = INFINITY};
    return s;
}

phc_soil_setup_options phc_soil_setup_options_default(void)
{
    phc_soil_setup_options o = {.nx = 1, .ny = 1, .dx = NAN};
    o.params = phc_soil_params_default();
    o.params.dt = 0.01;
    o.params.max_substeps = 100; /* a fit's trial point 100x too fast for dt is refused, not run */
    return o;
}

void phc_soil_setup_free(phc_soil_setup *su)
{
    if (!su)
        return;
    for (size_t L = 0; su->layer_names && L < su->n_layers; ++L)
        free(su->layer_names[L]);
    for (size_t q = 0; su->slot_names && q < su->k; ++q)
        free(su->slot_names[q]);
    free(su->layer_names);
    free(su->slot_names);
    free(su->layers);
    free(su->layer_of_k);
    free(su->rock);
    free(su->pocket);
    free(su->rain);
    free(su->sources);
    free(su->slot_p);
    free(su->slot_c);
    free(su);
}

/* The place of a message about `key` of the options (a printf format:
 * "layers[2]"): "cfg.yaml:12" from a config, else the kind's name. */
typedef struct place {
    const phc_origin *origin;
    const char *kind;
} place;

static phc_where at(const place *pl, const char *key_fmt, ...)
{
    char key[96];
    if (key_fmt) {
        va_list ap;
        va_start(ap, key_fmt);
        vsnprintf(key, sizeof key, key_fmt, ap);
        va_end(ap);
    }
    return phc_origin_key(pl->origin, pl->kind, key_fmt ? key : NULL);
}

static int add_slot(phc_soil_setup *su, const char *name, int *slot)
{
    for (size_t q = 0; q < su->k; ++q)
        if (!strcmp(su->slot_names[q], name)) {
            *slot = (int)q;
            return PHC_OK;
        }
    char **names = realloc(su->slot_names, (su->k + 1) * sizeof *names);
    if (!names)
        return PHC_ERR_NOMEM;
    su->slot_names = names;
    if (!(names[su->k] = strdup(name)))
        return PHC_ERR_NOMEM;
    *slot = (int)su->k++;
    return PHC_OK;
}

/* The grid, the step and the forces. */
static int setup_grid(phc_soil_setup *su, const phc_soil_setup_options *o, const place *pl, phc_error *err)
{
    if (o->nx < 1 || o->ny < 1 || o->nz < 1 || !(o->dx > 0) || (double)o->nx * o->ny * o->nz > 5e8)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: soil grid: needs nx, ny, nz >= 1 (at most 5e8 voxels) and "
                             "dx > 0 m", at(pl, "grid").text);
    su->nx = o->nx;
    su->ny = o->ny;
    su->nz = o->nz;
    su->dx = o->dx;
    const phc_soil_params *pr = &o->params;
    if (!(pr->dt > 0) || !(pr->f_diff >= 0) || !(pr->f_grav >= 0) || !(pr->f_nutrient >= 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: soil: needs dt > 0 h and f_diff, f_grav, f_nutrient >= 0",
                             at(pl, NULL).text);
    su->params = *pr;
    return PHC_OK;
}

/* Absorbing faces fit into the grid; periodic faces come in pairs. */
static int setup_boundaries(const phc_soil_setup *su, const place *pl, phc_error *err)
{
    const phc_soil_params *pr = &su->params;
    if (pr->absorb_width < 1 || pr->absorb_width > 1000)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: soil absorb width must be 1..1000 voxels",
                             at(pl, "absorb").text);
    size_t dims[3] = {su->nx, su->ny, su->nz};
    static const char *face[] = {"x_min", "x_max", "y_min", "y_max", "bottom", "top"};
    for (int f = 0; f < PHC_SOIL_FACES; ++f) {
        if ((unsigned)pr->boundary[f] > PHC_SOIL_PERIODIC)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: soil boundary %s: %d is not one of block, absorb, "
                                 "periodic", at(pl, "boundaries").text, face[f], (int)pr->boundary[f]);
        if (pr->boundary[f] == PHC_SOIL_ABSORB && (size_t)pr->absorb_width > dims[f / 2])
            return phc_error_set(err, PHC_ERR_INPUT, "%s: soil boundary %s absorbs over %d layers but the grid "
                                 "has %zu voxels along that axis", at(pl, "boundaries").text, face[f],
                                 pr->absorb_width, dims[f / 2]);
        if ((pr->boundary[f] == PHC_SOIL_PERIODIC) != (pr->boundary[f ^ 1] == PHC_SOIL_PERIODIC))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: soil boundaries: %s is periodic but %s is not; "
                                 "periodic faces come in pairs", at(pl, "boundaries").text, face[f & ~1],
                                 face[f | 1]);
    }
    return PHC_OK;
}

/* One layer's numbers: a preset's c and p unless given, the initial water. */
static int setup_layer(phc_soil_setup *su, size_t L, const phc_soil_setup_layer *in, const place *pl,
                       phc_error *err)
{
    const size_t count = su->n_layers;
    char ctx[48];
    snprintf(ctx, sizeof ctx, "soil layer %zu", L + 1);
    phc_soil_layer *l = &su->layers[L];
    l->c = NAN;
    l->p = NAN;
    if (in->soil && phc_soil_preset(in->soil, &l->c, &l->p)) {
        char list[256] = "";
        for (size_t i = 0; phc_soil_preset_name(i); ++i) {
            size_t used = strlen(list);
            snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", phc_soil_preset_name(i));
        }
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s: unknown soil '%s' (known: %s)",
                             at(pl, "layers[%zu].soil", L).text, ctx, in->soil, list);
    }
    if (!isnan(in->c))
        l->c = in->c;
    if (!isnan(in->p))
        l->p = in->p;
    l->d = in->d;
    l->thickness = in->thickness;
    l->nutrient = in->nutrient;
    l->fill = -1;
    l->water = -1;
    if (isnan(l->c) || isnan(l->p))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s: give `soil: NAME` or both c and p",
                             at(pl, "layers[%zu]", L).text, ctx);
    const int has_fill = !isnan(in->fill), has_water = !isnan(in->water);
    if (has_fill && has_water)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s: give the initial water as fill or water, not both",
                             at(pl, "layers[%zu]", L).text, ctx);
    if (has_fill)
        l->fill = in->fill;
    if (has_water)
        l->water = in->water;
    if (!has_fill && !has_water)
        l->water = 0;
    if ((has_fill && !(l->fill >= 0)) || (has_water && !(l->water >= 0)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s: the initial water must be >= 0",
                             at(pl, "layers[%zu]", L).text, ctx);
    if (L + 1 < count && !(l->thickness > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s: thickness must be > 0 m, found %g",
                             at(pl, "layers[%zu].thickness", L).text, ctx, l->thickness);
    phc_error model_err;
    if (phc_soil_layer_check(l, L + 1, L + 1 == count, &model_err)) /* the model's checks, with the line */
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s", at(pl, "layers[%zu]", L).text, model_err.message);
    if (!(su->layer_names[L] = strdup(in->soil ? in->soil : "custom")))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

/* The layers and the layer of each z-plane. */
static int setup_layers(phc_soil_setup *su, const phc_soil_setup_options *o, const place *pl, phc_error *err)
{
    int rc;
    if (!o->n_layers || !o->layers)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: soil layers: give at least one layer",
                             at(pl, "layers").text);
    su->n_layers = o->n_layers;
    su->layers = calloc(o->n_layers, sizeof *su->layers);
    su->layer_names = calloc(o->n_layers, sizeof *su->layer_names);
    if (!su->layers || !su->layer_names)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t L = 0; L < o->n_layers; ++L)
        if ((rc = setup_layer(su, L, &o->layers[L], pl, err)))
            return rc;
    if (!(su->layer_of_k = malloc(su->nz * sizeof *su->layer_of_k)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    phc_soil tmp = {.nx = su->nx, .ny = su->ny, .nz = su->nz, .dx = su->dx};
    phc_soil_layer_of_planes(&tmp, su->layers, su->n_layers, su->layer_of_k);
    return PHC_OK;
}

/* A noise block into a per-voxel mask (rocks) or amount (pockets). */
static int setup_noise(phc_soil_setup *su, const phc_soil_setup_noise *noise, int rocks, const place *pl,
                       phc_error *err)
{
    const char *what = rocks ? "soil rocks" : "soil nutrient_pockets";
    const double amount = rocks ? 1 : noise->amount;
    if (!(noise->scale > 0) || !(noise->fraction >= 0 && noise->fraction < 1) || !(amount >= 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s: needs scale > 0 m, 0 <= fraction < 1%s",
                             at(pl, rocks ? "rocks" : "nutrient_pockets").text, what,
                             rocks ? "" : " and amount >= 0");
    phc_soil *tmp = phc_soil_new(su->nx, su->ny, su->nz, su->dx);
    if (!tmp)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    size_t nvox = tmp->n;
    if (rocks) {
        for (size_t i = 0; i < nvox; ++i)
            tmp->p[i] = 1;
        phc_soil_add_rocks(tmp, noise->seed, noise->scale, noise->fraction);
        su->rock = malloc(nvox);
        if (su->rock)
            for (size_t i = 0; i < nvox; ++i)
                su->rock[i] = tmp->p[i] == 0;
    } else {
        phc_soil_add_nutrient_pockets(tmp, noise->seed, noise->scale, noise->fraction, amount);
        su->pocket = malloc(nvox * sizeof *su->pocket);
        if (su->pocket)
            memcpy(su->pocket, tmp->v, nvox * sizeof *su->pocket);
    }
    phc_soil_free(tmp);
    if (rocks ? !su->rock : !su->pocket)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

static int setup_rain(phc_soil_setup *su, const phc_soil_setup_options *o, const place *pl, phc_error *err)
{
    su->rain = calloc(o->n_rain ? o->n_rain : 1, sizeof *su->rain);
    if (!su->rain)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    su->n_rain = o->n_rain;
    for (size_t r = 0; r < o->n_rain; ++r) {
        const phc_soil_rain *rn = &o->rain[r];
        if (!(rn->rate >= 0) || !(rn->end >= rn->start) || !(rn->nutrient >= 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: rain %zu: needs rate >= 0 m/h, nutrient >= 0 and start <= end",
                                 at(pl, "rain[%zu]", r).text, r + 1);
        su->rain[r] = *rn;
    }
    return PHC_OK;
}

static int setup_sources(phc_soil_setup *su, const phc_soil_setup_options *o, const place *pl, phc_error *err)
{
    su->sources = calloc(o->n_sources ? o->n_sources : 1, sizeof *su->sources);
    if (!su->sources)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    su->n_sources = o->n_sources;
    const double top = su->nz * su->dx;
    for (size_t q = 0; q < o->n_sources; ++q) {
        const phc_soil_setup_source *in = &o->sources[q];
        phc_soil_source *src = &su->sources[q];
        *src = (phc_soil_source){.x = in->x, .y = in->y, .z = top - in->depth, .radius = in->radius,
                                 .water_rate = in->water_rate, .nutrient_rate = in->nutrient_rate,
                                 .start = in->start, .end = in->end};
        if (!(src->x >= 0 && src->x < su->nx * su->dx && src->y >= 0 && src->y < su->ny * su->dx &&
              in->depth >= 0 && in->depth < top))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: source %zu: (x %g m, y %g m, depth %g m) is outside the soil grid (%g x %g m, "
                                 "%g m deep)", at(pl, "sources[%zu]", q).text, q + 1, src->x, src->y, in->depth,
                                 su->nx * su->dx, su->ny * su->dx, top);
        if (!(src->radius >= 0) || !(src->end >= src->start))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: source %zu: needs radius >= 0 and start <= end",
                                 at(pl, "sources[%zu]", q).text, q + 1);
    }
    return PHC_OK;
}

/* Without sub-stepping, a step over the stability limit at the given soil
 * is refused here, with the limit (trial points of a fit that cross it are
 * rejected as outside the model's domain). */
static int setup_stability(const phc_soil_setup *su, const place *pl, phc_error *err)
{
    const phc_soil_params *pr = &su->params;
    if (pr->substep)
        return PHC_OK;
    phc_soil *tmp = NULL;
    int rc = phc_soil_setup_build(su, NULL, &tmp, err);
    if (rc)
        return rc;
    size_t at_voxel = 0;
    double lim = phc_soil_stable_dt(tmp, &at_voxel);
    if (pr->dt > lim) {
        size_t i = at_voxel % su->nx, j = (at_voxel / su->nx) % su->ny, k = at_voxel / (su->nx * su->ny);
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s: soil: dt = %g h exceeds the stability limit %g h of the explicit step "
                           "(set by voxel (%zu, %zu, %zu), p = %g m/h, c = %g) and substep is false; lower "
                           "dt or allow sub-stepping", at(pl, "dt").text, pr->dt, lim, i, j, k,
                           tmp->p[at_voxel], tmp->c[at_voxel]);
    }
    phc_soil_free(tmp);
    return rc;
}

static int default_is_parameter(const char *name, void *user_data)
{
    (void)user_data;
    return !strcmp(name, "p") || !strcmp(name, "c");
}

/* The fitted numbers: per-layer slots before the global p and c. */
static int setup_slots(phc_soil_setup *su, phc_is_parameter_fn is_parameter, void *user_data, phc_error *err)
{
    if (!is_parameter)
        is_parameter = default_is_parameter;
    su->slot_p = malloc(su->n_layers * sizeof *su->slot_p);
    su->slot_c = malloc(su->n_layers * sizeof *su->slot_c);
    if (!su->slot_p || !su->slot_c)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t L = 0; L < su->n_layers; ++L) {
        char name[32];
        su->slot_p[L] = su->slot_c[L] = -1;
        for (int which = 0; which < 2; ++which) {
            int *slot = which ? &su->slot_c[L] : &su->slot_p[L];
            const char *base = which ? "c" : "p";
            snprintf(name, sizeof name, "%s_%zu", base, L + 1);
            const char *use = is_parameter(name, user_data) ? name : is_parameter(base, user_data) ? base : NULL;
            if (use && add_slot(su, use, slot))
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        }
    }
    if ((is_parameter("f_diff", user_data) && add_slot(su, "f_diff", &su->slot_fd)) ||
        (is_parameter("f_grav", user_data) && add_slot(su, "f_grav", &su->slot_fg)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

int phc_soil_setup_new(const phc_soil_setup_options *o, const char *kind, phc_is_parameter_fn is_parameter,
                       void *user_data, phc_soil_setup **out, phc_error *err)
{
    const place pl = {o->origin, kind ? kind : "soil"};
    int rc;
    *out = NULL;
    phc_soil_setup *su = calloc(1, sizeof *su);
    if (!su)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    su->line = phc_origin_line(o->origin, NULL);
    su->slot_fd = su->slot_fg = -1;
    if ((rc = setup_grid(su, o, &pl, err)) || (rc = setup_boundaries(su, &pl, err)) ||
        (rc = setup_layers(su, o, &pl, err)) ||
        (o->rocks && (rc = setup_noise(su, o->rocks, 1, &pl, err))) ||
        (o->nutrient_pockets && (rc = setup_noise(su, o->nutrient_pockets, 0, &pl, err))) ||
        (rc = setup_rain(su, o, &pl, err)) || (rc = setup_sources(su, o, &pl, err)))
        goto fail;
    if (o->geo_origin) {
        su->geo = *o->geo_origin;
        su->has_geo = 1;
    }
    if ((rc = setup_stability(su, &pl, err)) || (rc = setup_slots(su, is_parameter, user_data, err)))
        goto fail;
    *out = su;
    return PHC_OK;
fail:
    phc_soil_setup_free(su);
    return rc;
}

double phc_soil_setup_p(const phc_soil_setup *su, size_t L, const double *p)
{
    return p && su->slot_p[L] >= 0 ? p[su->slot_p[L]] : su->layers[L].p;
}

double phc_soil_setup_c(const phc_soil_setup *su, size_t L, const double *p)
{
    return p && su->slot_c[L] >= 0 ? p[su->slot_c[L]] : su->layers[L].c;
}

int phc_soil_setup_build(const phc_soil_setup *su, const double *p, phc_soil **out, phc_error *err)
{
    int rc;
    *out = NULL;
    phc_soil_layer *layers = malloc(su->n_layers * sizeof *layers);
    phc_soil *s = phc_soil_new(su->nx, su->ny, su->nz, su->dx);
    if (!layers || !s) {
        free(layers);
        phc_soil_free(s);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    memcpy(layers, su->layers, su->n_layers * sizeof *layers);
    for (size_t L = 0; L < su->n_layers; ++L) {
        layers[L].p = phc_soil_setup_p(su, L, p);
        layers[L].c = phc_soil_setup_c(su, L, p);
    }
    s->params = su->params;
    if (p && su->slot_fd >= 0)
        s->params.f_diff = p[su->slot_fd];
    if (p && su->slot_fg >= 0)
        s->params.f_grav = p[su->slot_fg];
    rc = phc_soil_set_layers(s, layers, su->n_layers, err);
    free(layers);
    if (!rc && (!(s->params.f_diff >= 0) || !(s->params.f_grav >= 0)))
        rc = phc_error_set(err, PHC_ERR_DOMAIN, "soil: f_diff and f_grav must be >= 0");
    if (rc) {
        phc_soil_free(s);
        return rc == PHC_ERR_INPUT ? PHC_ERR_DOMAIN : rc;
    }
    for (size_t i = 0; i < s->n; ++i) {
        if (su->rock && su->rock[i])
            s->p[i] = 0;
        if (su->pocket)
            s->v[i] += su->pocket[i];
    }
    if ((rc = phc_soil_set_rain(s, su->rain, su->n_rain, err)) ||
        (rc = phc_soil_set_sources(s, su->sources, su->n_sources, err))) {
        phc_soil_free(s);
        return rc;
    }
    phc_soil_budget_reset(s);
    *out = s;
    return PHC_OK;
}

void phc_soil_setup_tangent(const phc_soil_setup *su, const phc_soil *s, double **dp, double **dinv_c,
                            double *dfd, double *dfg, double **sw)
{
    const size_t plane = s->nx * s->ny;
    for (size_t q = 0; q < su->k; ++q) {
        memset(dp[q], 0, s->n * sizeof(double));
        memset(dinv_c[q], 0, s->n * sizeof(double));
        memset(sw[q], 0, s->n * sizeof(double));
        dfd[q] = (int)q == su->slot_fd ? 1.0 : 0.0;
        dfg[q] = (int)q == su->slot_fg ? 1.0 : 0.0;
    }
    for (size_t k = 0; k < s->nz; ++k) {
        size_t L = su->layer_of_k[k];
        int sp = su->slot_p[L], sc = su->slot_c[L];
        for (size_t e = 0; e < plane; ++e) {
            size_t i = e + plane * k;
            if (sp >= 0 && !(su->rock && su->rock[i]))
                dp[sp][i] = 1.0;
            if (sc >= 0) {
                dinv_c[sc][i] = -1.0 / (s->c[i] * s->c[i]);
                if (su->layers[L].fill >= 0)
                    sw[sc][i] = su->layers[L].fill; /* w0 = fill c */
            }
        }
    }
}

int phc_soil_setup_run(const phc_soil_setup *su, const double *p, const double *t, size_t m, int tangents,
                       phc_soil_visit_fn visit, void *user, phc_soil **keep, phc_error *err)
{
    phc_soil *s = NULL;
    int rc = phc_soil_setup_build(su, p, &s, err);
    if (rc)
        return rc;
    const size_t k = tangents ? su->k : 0;
    double **dp = NULL, **dic = NULL, **sw = NULL, *dfd = NULL, *dfg = NULL;
    if (k) {
        dp = calloc(k, sizeof *dp);
        dic = calloc(k, sizeof *dic);
        sw = calloc(k, sizeof *sw);
        dfd = calloc(k, sizeof *dfd);
        dfg = calloc(k, sizeof *dfg);
        int bad = !dp || !dic || !sw || !dfd || !dfg;
        for (size_t q = 0; q < k && !bad; ++q)
            bad = !(dp[q] = malloc(s->n * sizeof(double))) || !(dic[q] = malloc(s->n * sizeof(double))) ||
                  !(sw[q] = malloc(s->n * sizeof(double)));
        if (bad) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        phc_soil_setup_tangent(su, s, dp, dic, dfd, dfg, sw);
    }
    phc_soil_tangent tan = {k, (const double *const *)dp, (const double *const *)dic, dfd, dfg, sw};
    for (size_t i = 0; i < m; ++i) {
        rc = k ? phc_soil_run_tangent(s, t[i], &tan, err) : phc_soil_run(s, t[i], err);
        if (rc)
            goto done;
        if (visit && visit(user, s, i, k ? &tan : NULL)) {
            rc = phc_error_set(err, PHC_ERR_DOMAIN, "soil: stopped at t = %g h", t[i]);
            goto done;
        }
    }
done:
    for (size_t q = 0; q < k; ++q) {
        if (dp) free(dp[q]);
        if (dic) free(dic[q]);
        if (sw) free(tan.sw[q]);
    }
    free(dp);
    free(dic);
    free(sw);
    free(dfd);
    free(dfg);
    if (!rc && keep)
        *keep = s;
    else
        phc_soil_free(s);
    return rc;
}

int phc_soil_setup_declare_units(const phc_soil_setup *su, phc_dataset *ds)
{
    int rc = PHC_OK;
    for (size_t L = 0; L < su->n_layers && !rc; ++L) {
        if (su->slot_p[L] >= 0)
            rc = phc_dataset_declare_unit(ds, su->slot_names[su->slot_p[L]], "m/h");
        if (!rc && su->slot_c[L] >= 0)
            rc = phc_dataset_declare_unit(ds, su->slot_names[su->slot_c[L]], "1");
    }
    if (!rc && su->slot_fd >= 0)
        rc = phc_dataset_declare_unit(ds, su->slot_names[su->slot_fd], "m");
    if (!rc && su->slot_fg >= 0)
        rc = phc_dataset_declare_unit(ds, su->slot_names[su->slot_fg], "1");
    return rc;
}

phc_dataset *phc_soil_setup_dataset(const phc_soil_setup *su, const phc_dataset_ops *ops, size_t n,
                                    const char *path)
{
    phc_dataset *ds = phc_dataset_new(ops, su->k);
    if (!ds)
        return NULL;
    int bad = 0;
    for (size_t q = 0; q < su->k && !bad; ++q)
        bad = !(ds->slot_names[q] = strdup(su->slot_names[q]));
    bad = bad || phc_soil_setup_declare_units(su, ds);
    ds->n = n;
    ds->x = malloc((n ? n : 1) * sizeof *ds->x);
    ds->y = malloc((n ? n : 1) * sizeof *ds->y);
    ds->sigma = malloc((n ? n : 1) * sizeof *ds->sigma);
    ds->data_lines = malloc((n ? n : 1) * sizeof *ds->data_lines);
    ds->data_file = strdup(path);
    if (bad || !ds->x || !ds->y || !ds->sigma || !ds->data_lines || !ds->data_file) {
        phc_dataset_free(ds);
        return NULL;
    }
    return ds;
}

char *phc_soil_setup_markdown(const phc_soil_setup *su, const double *p, const phc_soil *s)
{
    char *b = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&b, &len);
    if (!f)
        return NULL;
    static const char *bn[] = {"block", "absorb", "periodic"};
    const phc_soil_params *pr = &s->params;
    fprintf(f, "Soil (Rhizomorph §6): %zu x %zu x %zu voxels of %g m (%g x %g m, %g m deep); "
        "f_diff = %g m, f_grav = %g; dt = %g h, %s.\n\n", su->nx, su->ny, su->nz, su->dx, su->nx * su->dx,
        su->ny * su->dx, su->nz * su->dx, pr->f_diff, pr->f_grav, pr->dt,
        pr->substep ? "sub-stepped over the stability limit" : "no sub-stepping");
    fprintf(f, "Boundaries: x %s/%s, y %s/%s, bottom %s, top %s", bn[pr->boundary[0]], bn[pr->boundary[1]],
        bn[pr->boundary[2]], bn[pr->boundary[3]], bn[pr->boundary[4]], bn[pr->boundary[5]]);
    for (int face = 0; face < PHC_SOIL_FACES; ++face)
        if (pr->boundary[face] == PHC_SOIL_ABSORB) {
            fprintf(f, "; absorbing layers: %d, %s form", pr->absorb_width,
                pr->absorb_form == PHC_SOIL_ABSORB_CODE ? "the authors' code (i²)" : "the paper's eq. 31 (i)");
            break;
        }
    fprintf(f, ".\n\n| layer | soil | thickness (m) | c | p (m/h) | D = f_diff p/c (m²/h) | gravity velocity f_grav p (m/h) |\n|---|---|---|---|---|---|---|\n");
    for (size_t L = 0; L < su->n_layers; ++L) {
        double pv = phc_soil_setup_p(su, L, p), cv = phc_soil_setup_c(su, L, p);
        char thick[32];
        if (su->layers[L].thickness > 0 && L + 1 < su->n_layers)
            snprintf(thick, sizeof thick, "%g", su->layers[L].thickness);
        else
            snprintf(thick, sizeof thick, "to the bottom");
        fprintf(f, "| %zu | %s | %s | %.6g%s | %.6g%s | %.4g | %.4g |\n", L + 1, su->layer_names[L], thick, cv,
            su->slot_c[L] >= 0 ? " (fitted)" : "", pv, su->slot_p[L] >= 0 ? " (fitted)" : "", pr->f_diff * pv / cv,
            pr->f_grav * pv);
    }
    size_t at = 0;
    double lim = phc_soil_stable_dt(s, &at);
    fprintf(f, "\nStability limit of the explicit step: %.4g h (voxel %zu); %zu steps, %zu sub-steps.\n\n",
        lim, at, s->budget.steps, s->budget.substeps);
    const phc_soil_budget *bu = &s->budget;
    fprintf(f, "Water budget (m³) over the run to t = %g h: initial %.6g, in %.6g, absorbed %.6g, "
        "taken by sinks %.6g, stored %.6g; closing error %.3g (%.2g of the water moved).\n", s->t, bu->water_initial,
        bu->water_in, bu->water_absorbed, bu->water_sunk, bu->water_stored, bu->water_closing,
        fabs(bu->water_closing) / fmax(1e-300, bu->water_initial + bu->water_in));
    if (ferror(f) | (fclose(f) != 0)) {
        free(b);
        return NULL;
    }
    return b;
}

int phc_soil_setup_report(const phc_soil_setup *su, const double *p, double t_end, char **markdown,
                          phc_error *err)
{
    phc_soil *s = NULL;
    int rc = phc_soil_setup_run(su, p, &t_end, 1, 0, NULL, NULL, &s, err);
    if (rc)
        return rc;
    *markdown = phc_soil_setup_markdown(su, p, s);
    phc_soil_free(s);
    return *markdown ? PHC_OK : phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
}
