/* The traced-shoot recovery set-up shared by
 * tests/regression/test_shoot_traces_recovery.c and
 * notebooks_c/shoot_traces_coverage.c (README "Fitting growth to traced
 * shoots"): the climbing model (model/climbing_growth.h) at BP 0.3, V 0.6,
 * η 0.02 s⁻¹, τ 0.5 s⁻¹, r 0.15 s⁻¹ (the truth), apical dominance 0.6,
 * branch orders up to 2, a wall y = 0 3 cm behind the seed, light from
 * (0, 1, 2), steps of 0.5 s; the fit's starts 30–50% off and its bounds. */
#ifndef PHC_TESTS_SHOOT_TRACES_WALL_PLANT_H
#define PHC_TESTS_SHOOT_TRACES_WALL_PLANT_H

#include <stdint.h>

#include "fit/costs/shoot_traces.h"

/* BP, V, η (s⁻¹), τ (s⁻¹), r (s⁻¹), in the kind's slot order. */
static const double shoot_traces_wall_truth[5] = {0.3, 0.6, 0.02, 0.5, 0.15};
static const double shoot_traces_wall_start[5] = {0.45, 0.4, 0.03, 0.3, 0.1};
static const double shoot_traces_wall_lower[5] = {0.02, 0.05, 0, 0.01, 0.05};
static const double shoot_traces_wall_upper[5] = {0.9, 1, 0.5, 3, 0.5};

/* The wall y = 0 (normal +y) above the ground z = 0: c = x projected onto it. */
static inline int shoot_traces_wall_closest(void *user, const double x[3], double c[3], double n[3])
{
    (void)user;
    c[0] = x[0]; c[1] = 0; c[2] = x[2] < 0 ? 0 : x[2];
    n[0] = 0; n[1] = 1; n[2] = 0;
    return 0;
}

/* BP, V, η, τ, r of p set to v (5 values, the order above). */
static inline void shoot_traces_wall_set(phc_climbing_options *p, const double v[5])
{
    p->branch_probability = v[0];
    p->direction_variance = v[1];
    p->phototropism = v[2];
    p->surface_adaption = v[3];
    p->growth_rate = v[4];
}

/* The kind's default options with the plant above at the truth, grown
 * with seed `seed`. */
static inline phc_shoot_traces_options shoot_traces_wall_options(uint64_t seed)
{
    phc_shoot_traces_options o = phc_shoot_traces_options_default();
    shoot_traces_wall_set(&o.plant, shoot_traces_wall_truth);
    o.plant.apical_dominance = 0.6;
    o.plant.max_order = 2;
    o.plant.light.direction[0] = 0;
    o.plant.light.direction[1] = 1;
    o.plant.light.direction[2] = 2;
    o.plant.closest = shoot_traces_wall_closest;
    o.position[1] = 0.03;
    o.time_step = 0.5;
    o.plant.seed = seed;
    return o;
}

#endif /* PHC_TESTS_SHOOT_TRACES_WALL_PLANT_H */
