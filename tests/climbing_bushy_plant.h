/* The bushy climbing plant shared by test_climbing_growth and the climbing
 * bench (tests/bench/bench_climbing.c): growth 0.2 s⁻¹, BP 0.9, B 2, V 0.8,
 * orders up to 6 (model/climbing_growth.h), the floor plane z = 0 as its
 * support's closest-point query, and the bench's scene around it. */
#ifndef PHC_TESTS_CLIMBING_BUSHY_PLANT_H
#define PHC_TESTS_CLIMBING_BUSHY_PLANT_H

#include <stdint.h>

#include "model/climbing_growth.h"

/* The plane z = 0 (normal +z): c = x projected onto it. */
static inline int climbing_floor_closest(void *user, const double x[3], double c[3], double n[3])
{
    (void)user;
    c[0] = x[0];
    c[1] = x[1];
    c[2] = 0;
    n[0] = n[1] = 0;
    n[2] = 1;
    return 0;
}

static inline phc_climbing_options climbing_bushy_options(uint64_t seed)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.seed = seed;
    o.growth_rate = 0.2;
    o.branch_probability = 0.9;
    o.max_buds = 2;
    o.direction_variance = 0.8;
    o.max_order = 6;
    return o;
}

/* The bench's scene for it (tests/bench/bench_climbing.c): a light grid of
 * 80 x 80 x 40 cells of 5 cm from (-2, -2, 0) m with extinction 40 m⁻¹
 * (light from above unless the caller turns it), surface adaption 0.2 s⁻¹
 * toward the floor z = 0. */
static inline void climbing_floor_scene(phc_climbing_options *o)
{
    o->light.origin[0] = o->light.origin[1] = -2;
    o->light.origin[2] = 0;
    o->light.cell = 0.05;
    o->light.dims[0] = o->light.dims[1] = 80;
    o->light.dims[2] = 40;
    o->light.extinction = 40;
    o->surface_adaption = 0.2;
    o->closest = climbing_floor_closest;
}

#endif
