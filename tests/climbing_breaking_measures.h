/* Measures of a growing plant that breaks (model/climbing_breaking.h),
 * shared by tests/unit/test_climbing_breaking.c and
 * notebooks_c/climbing_breaking_growth.c. */
#ifndef PHC_TESTS_CLIMBING_BREAKING_MEASURES_H
#define PHC_TESTS_CLIMBING_BREAKING_MEASURES_H

#include <math.h>

#include "model/climbing_growth.h"

/* Largest group stress of the last substep over the plant's particles that
 * do not fall (1); *at (may be NULL) gets its particle, 0 when none. */
static inline double climbing_max_linked_stress(const phc_climbing *c, size_t *at)
{
    double m = 0;
    if (at)
        *at = 0;
    for (size_t i = 1; i < phc_climbing_count(c); ++i)
        if (!phc_climbing_is_falling(c, i) && phc_climbing_stress(c, i) > m) {
            m = phc_climbing_stress(c, i);
            if (at)
                *at = i;
        }
    return m;
}

/* Height (m) of the centre of mass of the falling particles (masses ∝ r²L,
 * one density); NAN when none falls.  *count gets how many fall. */
static inline double climbing_falling_centre_z(const phc_climbing *c, size_t *count)
{
    double w = 0, z = 0;
    *count = 0;
    for (size_t i = 0; i < phc_climbing_count(c); ++i)
        if (phc_climbing_is_falling(c, i)) {
            double x[3];
            phc_climbing_position(c, i, x);
            const double r = phc_climbing_radius(c, i), m = r * r * phc_climbing_length(c, i);
            w += m;
            z += m * x[2];
            ++*count;
        }
    return w > 0 ? z / w : NAN;
}

#endif /* PHC_TESTS_CLIMBING_BREAKING_MEASURES_H */
