/* Bit-for-bit comparison of two climbing plants after a growth step, shared
 * by the collision-memory tests (test_climbing_growth 8f,
 * test_collide_memory): particle count, the last step's collisions (points
 * pushed, smallest δ − r) and every particle's centre and segment ends. */
#ifndef PHC_TESTS_CLIMBING_SAME_STATE_H
#define PHC_TESTS_CLIMBING_SAME_STATE_H

#include <string.h>

#include "model/climbing_growth.h"

/* 0 when a and b are the same bit for bit, else the number of differences
 * (1 for the count or the collisions, 1 per particle that differs). */
static inline size_t climbing_state_differs(const phc_climbing *a, const phc_climbing *b)
{
    size_t pa, pb;
    double da, db;
    phc_climbing_collisions(a, &pa, &da);
    phc_climbing_collisions(b, &pb, &db);
    const size_t n = phc_climbing_count(a);
    if (n != phc_climbing_count(b))
        return 1;
    size_t differ = pa != pb || memcmp(&da, &db, sizeof da) != 0;
    for (size_t i = 0; i < n; ++i) {
        double u[9], v[9];
        phc_climbing_position(a, i, u);
        phc_climbing_segment(a, i, u + 3, u + 6);
        phc_climbing_position(b, i, v);
        phc_climbing_segment(b, i, v + 3, v + 6);
        differ += memcmp(u, v, sizeof u) != 0;
    }
    return differ;
}

#endif /* PHC_TESTS_CLIMBING_SAME_STATE_H */
