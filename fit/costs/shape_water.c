/* The relative water content of a plant's segments over time: see
 * shape_water.h. */
#include "fit/costs/shape_water.h"

#include <math.h>
#include <stdlib.h>

struct phc_shape_water {
    phc_water_system *sys;
    phc_water_bdf6 *bdf6;
    size_t n;
    double step;    /* s */
    double *volume; /* n, cm³ */
    double *theta;  /* n, g (work) */
    double *dtheta; /* n, g cm² s (work) */
    double last_t;  /* the pass's previous time, s */
    int sens;
};

void phc_shape_water_free(phc_shape_water *w)
{
    if (!w)
        return;
    phc_water_bdf6_free(w->bdf6);
    phc_water_system_free(w->sys);
    free(w->volume);
    free(w->theta);
    free(w->dtheta);
    free(w);
}

int phc_shape_water_new(const phc_plant_graph *g, phc_water_weights weights, double viscosity,
                        double step, phc_shape_water **out, phc_error *err)
{
    *out = NULL;
    if (!(step > 0) || !isfinite(step))
        return phc_error_set(err, PHC_ERR_DOMAIN, "water step must be > 0 s, found %g", step);
    phc_shape_water *w = calloc(1, sizeof *w);
    if (!w)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    w->n = g->n;
    w->step = step;
    w->last_t = INFINITY; /* no pass started */
    phc_water_params p = phc_water_params_default();
    p.weights = weights;
    p.viscosity = viscosity;
    p.initial_water = 1.0; /* set per pass */
    p.loss_rate = 0.0;
    int rc = phc_water_system_new(g, &p, &w->sys, err);
    if (rc) {
        phc_shape_water_free(w);
        return rc;
    }
    w->volume = malloc(w->n * sizeof *w->volume);
    w->theta = malloc(w->n * sizeof *w->theta);
    w->dtheta = malloc(w->n * sizeof *w->dtheta);
    if (!w->volume || !w->theta || !w->dtheta) {
        phc_shape_water_free(w);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    phc_water_system_volume(w->sys, w->volume);
    *out = w;
    return PHC_OK;
}

const double *phc_shape_water_volume(const phc_shape_water *w) { return w->volume; }

int phc_shape_water_start(phc_shape_water *w, double delta, double rwc0, int sensitivities,
                          phc_error *err)
{
    double total = 0.0;
    for (size_t i = 0; i < w->n; ++i)
        total += w->volume[i];
    int rc;
    if ((rc = phc_water_system_set_loss_rate(w->sys, delta, err)) ||
        (rc = phc_water_system_set_initial_water(w->sys, rwc0 * total, err)))
        return rc;
    phc_water_bdf6_free(w->bdf6);
    w->bdf6 = NULL;
    w->sens = sensitivities ? 1 : 0;
    w->last_t = 0.0;
    return phc_water_bdf6_new(w->sys, w->step, w->sens, &w->bdf6, err);
}

int phc_shape_water_at(phc_shape_water *w, double t, double *x, double *dx_ddelta, phc_error *err)
{
    if (!w->bdf6 || !(t >= w->last_t) || !isfinite(t))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "water: time %g s asked before the pass's previous time %g s (or no pass "
                             "started)",
                             t, w->last_t);
    if (dx_ddelta && !w->sens)
        return phc_error_set(err, PHC_ERR_INVALID, "water: d x / d delta needs a pass with sensitivities");
    int rc;
    if (t > phc_water_bdf6_time(w->bdf6) && (rc = phc_water_bdf6_advance(w->bdf6, t, err)))
        return rc;
    if ((rc = phc_water_bdf6_state_at(w->bdf6, t, w->theta, dx_ddelta ? w->dtheta : NULL, err)))
        return rc;
    w->last_t = t;
    for (size_t i = 0; i < w->n; ++i) {
        x[i] = w->theta[i] / w->volume[i];
        if (dx_ddelta)
            dx_ddelta[i] = w->dtheta[i] / w->volume[i];
    }
    return PHC_OK;
}
