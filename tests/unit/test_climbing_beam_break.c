/* Unit test of breaking under a bending stress while a climbing plant
 * grows (model/climbing_growth.h with particles.break_stress and
 * anchors_carry_moment; model/particles.h, "Breaking under a bending
 * stress").  Every checked number is printed.
 *
 *  1. The shelf of measurements/examples/climbing/shelf.yaml through the C
 *     API (a board x ∈ [−0.05, 0.25] m, its top z = 0, a shoot grown along
 *     it toward the edge with beam bending, collisions and anchors that
 *     carry the moment): the first break is at the board's edge (its joint
 *     within one internode of x = 0.25 m, the particle above it anchored,
 *     the one below not), at a bending stress above break_stress that the
 *     plant's reading gave no joint the substep before; the overhang grew
 *     before it broke.
 *  2. break_stress 0 (off) gives the same plant bit for bit as a value no
 *     joint reaches (1e30 Pa).
 *  3. A bushy plant of > 2000 particles with breaking under a bending
 *     stress on 1 and 2 OpenMP threads: the same plant bit for bit.
 *  4. Bad options are refused naming the option. */
#include "model/climbing_growth.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "climbing_breaking_measures.h"
#include "climbing_bushy_plant.h"
#include "climbing_same_state.h"

/* The board of shelf.obj: a box [−0.05, 0.25] × [−0.1, 0.1] × [−0.02, 0] m. */
static const double BOX_LO[3] = {-0.05, -0.1, -0.02}, BOX_HI[3] = {0.25, 0.1, 0.0};
static const double EDGE = 0.25; /* m: its front edge, x */

/* Closest point on the box's surface and the outward normal of its face. */
static int box_closest(void *user, const double x[3], double c[3], double n[3])
{
    (void)user;
    int inside = 1;
    for (int k = 0; k < 3; ++k) {
        c[k] = fmin(fmax(x[k], BOX_LO[k]), BOX_HI[k]);
        inside = inside && c[k] == x[k];
        n[k] = 0;
    }
    int axis = 0;
    double side = 1;
    if (inside) { /* the nearest face */
        double best = INFINITY;
        for (int k = 0; k < 3; ++k) {
            if (x[k] - BOX_LO[k] < best) {
                best = x[k] - BOX_LO[k];
                axis = k;
                side = -1;
            }
            if (BOX_HI[k] - x[k] < best) {
                best = BOX_HI[k] - x[k];
                axis = k;
                side = 1;
            }
        }
        c[axis] = side > 0 ? BOX_HI[axis] : BOX_LO[axis];
    } else { /* the face of the largest way out */
        double best = -1;
        for (int k = 0; k < 3; ++k)
            if (fabs(x[k] - c[k]) > best) {
                best = fabs(x[k] - c[k]);
                axis = k;
                side = x[k] > c[k] ? 1 : -1;
            }
    }
    n[axis] = side;
    return 0;
}

static phc_climbing_options shelf_options(double break_stress)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.seed = 1;
    o.growth_rate = 0.2;
    o.radius = 0.003;
    o.branch_probability = 0;
    o.closest = box_closest;
    o.dynamics_substeps = 10;
    o.collide = 1;
    o.anchor_strength = 0.5;
    o.particles.maturity_age = 1000;
    o.min_stiffness = 0.5;
    o.particles.bending = PHC_PARTICLES_BEAM;
    o.particles.beam_modulus = 1e8;
    o.particles.anchors_carry_moment = 1;
    o.particles.break_stress = break_stress;
    return o;
}

static void test_shelf(void)
{
    const double sigma_r = 3e5, base[3] = {0, 0, 0.003}, east[3] = {1, 0, 0};
    phc_climbing_options o = shelf_options(sigma_r);
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, east, &o, &err);
    CHECK(c != NULL);
    if (!c)
        return;
    phc_climbing_stats st = {0};
    double before = 0, reach = 0;
    int steps = 0;
    for (; steps < 480 && st.breaks == 0; ++steps) {
        before = 0; /* the largest joint σ of the plant after the last step */
        for (size_t i = 0; i < phc_climbing_count(c); ++i) {
            before = fmax(before, phc_climbing_bend_stress(c, i));
            double x[3];
            phc_climbing_position(c, i, x);
            reach = fmax(reach, x[0]);
        }
        CHECK(phc_climbing_step(c, 0.25, &err) == 0);
        phc_climbing_get_stats(c, &st);
    }
    const double *J = st.first_break_joint;
    printf("climbing beam break, shelf: first break at %.2f s (step %d), bending stress %.6g Pa (break_stress %g "
           "Pa; the largest joint's %.6g Pa after the step before), joint (%.4f, %.4f, %.4f) m, the edge at x = %.2f m, "
           "the particle above %s; the shoot reached x = %.4f m before it\n",
           st.first_break_time, steps, st.first_break_bend_stress, sigma_r, before, J[0], J[1], J[2], EDGE,
           st.first_break_parent_anchored ? "anchored" : "free", reach);
    CHECK(st.breaks == 1);
    CHECK(st.first_break_bend_stress > sigma_r);
    CHECK(fabs(J[0] - EDGE) < o.max_length && fabs(J[2]) < o.max_length);
    CHECK(st.first_break_parent_anchored);
    CHECK(reach > EDGE + 0.1); /* an overhang of 10 cm or more grew first */
    phc_climbing_free(c);
}

/* The shelf's shoot grown 100 s with break_stress a and b: the same plant? */
static void test_off(void)
{
    const double base[3] = {0, 0, 0.003}, east[3] = {1, 0, 0};
    phc_climbing_options oa = shelf_options(0), ob = shelf_options(1e30);
    phc_error err;
    phc_climbing *a = phc_climbing_new(base, east, &oa, &err), *b = phc_climbing_new(base, east, &ob, &err);
    CHECK(a && b);
    for (int s = 0; a && b && s < 400; ++s) {
        CHECK(phc_climbing_step(a, 0.25, &err) == 0);
        CHECK(phc_climbing_step(b, 0.25, &err) == 0);
    }
    if (a && b) {
        phc_climbing_stats sa, sb;
        phc_climbing_get_stats(a, &sa);
        phc_climbing_get_stats(b, &sb);
        const size_t differ = climbing_state_differs(a, b);
        printf("climbing beam break, off: the shelf's shoot after 100 s, break_stress 0: %zu particles, %zu breaks; "
               "1e30 Pa: %zu particles, %zu breaks; %zu differences\n",
               phc_climbing_count(a), sa.breaks, phc_climbing_count(b), sb.breaks, differ);
        CHECK(sa.breaks == 0 && sb.breaks == 0 && differ == 0);
    }
    phc_climbing_free(a);
    phc_climbing_free(b);
}

static void test_threads(void)
{
    phc_climbing_options o = climbing_bushy_options(5);
    o.particles.maturity_age = 20;
    o.min_stiffness = 0.3;
    o.particles.bending = PHC_PARTICLES_BEAM;
    o.particles.break_stress = 2e6;
    o.fall_time = 0.5;
    size_t ns[2] = {0, 0}, numbers;
    phc_climbing_stats st[2];
    const size_t differ = climbing_threads_compare(&o, 12, ns, st, &numbers);
    printf("climbing beam break, threads: bushy plant, 12 dynamic steps with break_stress %g Pa: 1 thread %zu "
           "particles, %zu breaks, %zu dropped; 2 threads %zu, %zu, %zu; %zu of %zu numbers differ\n",
           o.particles.break_stress, ns[0], st[0].breaks, st[0].particles_dropped, ns[1], st[1].breaks,
           st[1].particles_dropped, differ, numbers);
    CHECK(ns[0] == ns[1] && st[0].breaks >= 1 && st[0].breaks == st[1].breaks);
    CHECK(differ == 0);
}

static void test_bad_options(void)
{
    const double base[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    phc_error err;
    struct {
        double bend, group;
        int beam, carry;
        const char *says;
    } bad[] = {{-1, 0, 1, 0, "particles.break_stress"},
               {NAN, 0, 1, 0, "particles.break_stress"},
               {1e6, 0, 0, 0, "bending beam"},
               {1e6, 0.05, 1, 0, "one rule of breaking"},
               {0, 0, 0, 1, "particles.anchors_carry_moment"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        phc_climbing_options o = phc_climbing_options_default();
        o.particles.break_stress = bad[k].bend;
        o.particles.break_threshold = bad[k].group;
        o.particles.anchors_carry_moment = bad[k].carry;
        o.particles.bending = bad[k].beam ? PHC_PARTICLES_BEAM : PHC_PARTICLES_OWN_WEIGHT;
        phc_climbing *c = phc_climbing_new(base, up, &o, &err);
        CHECK(c == NULL);
        phc_climbing_free(c);
        printf("climbing beam break, bad options: %s\n", err.message);
        CHECK_STR_CONTAINS(err.message, bad[k].says);
    }
}

int main(void)
{
    test_shelf();
    test_off();
    test_threads();
    test_bad_options();
    return check_finish("test_climbing_beam_break");
}
