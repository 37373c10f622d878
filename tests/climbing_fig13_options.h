/* Fig. 13's seed and growth values (notebooks_c/climbing_fig13_wall.c) on
 * the support mesh m, with dynamics (25 substeps per step) and collide:
 * the plant of the collision-pass tests (test_collide_memory,
 * test_collide_segments). */
#ifndef PHC_TESTS_CLIMBING_FIG13_OPTIONS_H
#define PHC_TESTS_CLIMBING_FIG13_OPTIONS_H

#include "measurements/support_mesh.h"
#include "model/climbing_growth.h"

static inline phc_climbing_options fig13_options(phc_support_mesh *m)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.seed = 13;
    o.growth_rate = 0.2;
    o.apical_dominance = 0.6;
    o.radius = 0.003;
    o.branch_probability = 0.35;
    o.direction_variance = 0.6;
    o.max_order = 2;
    o.surface_adaption = 0.5;
    o.keep_outside = 1;
    o.closest = phc_support_mesh_closest;
    o.closest_user = m;
    o.dynamics_substeps = 25;
    o.collide = 1;
    return o;
}

#endif /* PHC_TESTS_CLIMBING_FIG13_OPTIONS_H */
