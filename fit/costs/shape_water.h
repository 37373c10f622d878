/* The water that drives a `shape_series` plant (issue 19, "the water as the
 * latent driver"): the wilting paper's water model (Maggioli et al. 2023,
 * §3–4, eq. 5–8; model/water.h) on the plant graph, read as the relative
 * water content of every segment over time,
 *     x_i(t) = θ_i(t) / V_i        (g / cm³ = 1: water per segment volume),
 * with θ(0) = rwc0 · V (every segment at rwc0), the leaf loss ℓ_i = δ·A_i
 * (δ in s⁻¹ cm⁻², the same δ as a `weight_curve` on that plant), and
 * d x_i / d δ.  BDF6 with a fixed step (the water model is stiff: pressure
 * equalises in well under a second), read between steps by
 * phc_water_bdf6_state_at (degree-5 interpolation of the stored states).
 *
 * Use: phc_shape_water_start(δ, rwc0) once per pass over the times, then
 * phc_shape_water_at(t) at non-decreasing t (s since the start).  A later
 * start begins a new pass (a new series, or new parameter values). */
#ifndef PHC_COSTS_SHAPE_WATER_H
#define PHC_COSTS_SHAPE_WATER_H

#include <stddef.h>

#include "model/plant_graph.h"
#include "model/status.h"
#include "model/water.h"

typedef struct phc_shape_water phc_shape_water;

/* For a finished graph (copied as the water model needs it).  weights: the
 * edge weights of model/water.h; viscosity mPa s (0 = the mode's default);
 * step: BDF6 step, s, > 0. */
int phc_shape_water_new(const phc_plant_graph *g, phc_water_weights weights, double viscosity,
                        double step, phc_shape_water **out, phc_error *err);
void phc_shape_water_free(phc_shape_water *w);

/* A new pass from t = 0 with loss rate δ (s⁻¹ cm⁻², >= 0) and initial
 * relative water content rwc0 (> 0); sensitivities: 1 to compute d x / d δ. */
int phc_shape_water_start(phc_shape_water *w, double delta, double rwc0, int sensitivities,
                          phc_error *err);

/* x (n, graph order) and, when dx_ddelta is not NULL (needs
 * sensitivities), d x / d δ (cm² s) at t >= 0 s, not before the pass's
 * previous time. */
int phc_shape_water_at(phc_shape_water *w, double t, double *x, double *dx_ddelta, phc_error *err);

/* Segment volumes, cm³ (n, graph order). */
const double *phc_shape_water_volume(const phc_shape_water *w);

#endif /* PHC_COSTS_SHAPE_WATER_H */
