/* Unit test of the own-weight joint pass on four links at once
 * (model/particles_joint_lanes.h, phc_particles_joint_lanes).  Every
 * checked number is printed.
 *
 *  1. The lanes alone against exact answers: a link held at its rest
 *     angle (k = 1) hangs from its joint, x = J + (0, 0, L/2); a link
 *     whose load lies along its axis turns by the fraction k of its rest
 *     turn about x (the slerp, below and above π/4); a lane's numbers do
 *     not depend on its neighbours; the cases follow_one takes another
 *     path for (no load direction, a half turn, a turn below 1e-8, a
 *     rest turn not of unit length) are left to it.
 *  2. A random plant stepped with the lanes and with one link at a time
 *     (follow_one): the same bits after 1 and 30 steps, on one and two
 *     threads, with every case in it: links held (s = 1), free (s = 0)
 *     and between, anchored (k_a = 1 holding q, k_a = 0.5), unloaded
 *     (f = −m g), pulled against their axis (a half turn), at rest
 *     (turns below 1e-8 at the first step). */
#include "model/particles_joint_lanes.h"
#include "model/particles.h"
#include "model/plant_graph.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* Lane l of `in` set to one link: q_u, x_u, j_i, q̄_u⁻¹ q̄_i, q_i, a_i, L/2, k. */
static void set_lane(phc_joint_lanes_in *in, int l, const double qu[4], const double xu[3],
                     const double ju[3], const double rel[4], const double qt[4],
                     const double acc[3], double half, double k)
{
    for (int d = 0; d < 4; ++d) {
        in->qu[d][l] = qu[d];
        in->rel[d][l] = rel[d];
        in->qt[d][l] = qt[d];
    }
    for (int d = 0; d < 3; ++d) {
        in->xu[d][l] = xu[d];
        in->ju[d][l] = ju[d];
        in->acc[d][l] = acc[d];
    }
    in->half[l] = half;
    in->k[l] = k;
}

/* |q − (cos(θ/2), sin(θ/2), 0, 0)|∞ for lane l */
static double off_x_turn(const phc_joint_lanes_out *out, int l, double theta)
{
    const double want[4] = {cos(theta / 2), sin(theta / 2), 0, 0};
    double e = 0;
    for (int d = 0; d < 4; ++d)
        e = fmax(e, fabs(out->q[d][l] - want[d]));
    return e;
}

static void test_lanes_alone(void)
{
    const double one[4] = {1, 0, 0, 0}, xu[3] = {1, 2, 3}, ju[3] = {0, 0, 0.1};
    const double half = 0.05, dt2 = 0.25;
    const double along[3] = {0, 0, 5};          /* the load along the axis: q_f = q_i */
    const double none[3] = {0, 0, -0.2};        /* d = L/2 ẑ + Δt² a = 0 exactly */
    const double against[3] = {0, 0, -10};      /* d = −2.45 ẑ: a half turn */
    const double t1 = 0.6, t2 = 2.4;            /* rest turns about x (rad) */
    const double r1[4] = {cos(t1 / 2), sin(t1 / 2), 0, 0}, r2[4] = {cos(t2 / 2), sin(t2 / 2), 0, 0};
    const double big[4] = {1.001, 0, 0, 0};     /* |q_u| = 1.001 */
    phc_joint_lanes_in in;
    phc_joint_lanes_out a, b;
    /* call 1: a slerp by k = 0.5 of 0.6 rad; no load direction; a half
     * turn; q* = q_f (no turn) */
    set_lane(&in, 0, one, xu, ju, r1, one, along, half, 0.5);
    set_lane(&in, 1, one, xu, ju, one, one, none, half, 0.5);
    set_lane(&in, 2, one, xu, ju, one, one, against, half, 0.5);
    set_lane(&in, 3, one, xu, ju, one, one, along, half, 0.5);
    const int m1 = phc_joint_lanes(&in, dt2, &a);
    /* call 2: held (k = 1) with no load direction; |q*| = 1.001; a slerp
     * by k = 0.75 of 2.4 rad (φ = 1.2 > π/4, kφ = 0.9 > π/4); call 1's
     * lane 0 again */
    set_lane(&in, 0, one, xu, ju, one, one, none, half, 1.0);
    set_lane(&in, 1, big, xu, ju, r1, one, along, half, 0.5);
    set_lane(&in, 2, one, xu, ju, r2, one, along, half, 0.75);
    set_lane(&in, 3, one, xu, ju, r1, one, along, half, 0.5);
    const int m2 = phc_joint_lanes(&in, dt2, &b);
    const double e1 = off_x_turn(&a, 0, 0.5 * t1), e2 = off_x_turn(&b, 2, 0.75 * t2);
    const double eh = off_x_turn(&b, 0, 0.0);
    /* x = J + R(q)(0, 0, L/2), J = x_u + j_i (q_u = 1) */
    const double xh = fmax(fmax(fabs(b.x[0][0] - 1), fabs(b.x[1][0] - 2)), fabs(b.x[2][0] - 3.15));
    const double xs = fmax(fabs(a.x[1][0] - (2 - half * sin(0.5 * t1))),
                           fabs(a.x[2][0] - (3.1 + half * cos(0.5 * t1))));
    int same = 1;
    for (int d = 0; d < 4; ++d)
        same &= memcmp(&a.q[d][0], &b.q[d][3], sizeof(double)) == 0;
    for (int d = 0; d < 3; ++d)
        same &= memcmp(&a.x[d][0], &b.x[d][3], sizeof(double)) == 0;
    printf("lanes alone: placed lanes 0x%x (want 0x1: slerp; no load direction, half turn, no "
           "turn left to follow_one) and 0x%x (want 0xd: held, slerp above pi/4, again; |q*| = "
           "1.001 left); slerp off the exact turn by %.3g (0.3 rad) and %.3g (1.8 rad), held by "
           "%.3g; centre off by %.3g (held), %.3g (slerp); a lane's bits in another lane with "
           "other neighbours: %s\n",
           (unsigned)m1, (unsigned)m2, e1, e2, eh, xh, xs, same ? "same" : "DIFFERENT");
    CHECK(m1 == 0x1 && m2 == 0xd);
    CHECK(e1 < 1e-15 && e2 < 1e-15 && eh == 0 && xh < 1e-15 && xs < 1e-15);
    CHECK(same);
}

/* Positions and orientations (7 per particle) after `steps` steps of
 * 0.01 s of the test plant, lanes on or off, on `threads` threads. */
static double *run_plant(const phc_plant_graph *g, int lanes, int threads, int steps)
{
    const size_t n = g->n;
    phc_error err;
    omp_set_num_threads(threads);
    phc_particles_options opt = phc_particles_options_default();
    opt.follow_parent = 1;
    opt.maturity_age = 0.5;
    phc_particles *p = phc_particles_new(g, &opt, &err);
    double *state = malloc(7 * n * sizeof *state);
    CHECK(p != NULL && state != NULL);
    if (!p || !state) {
        phc_particles_free(p);
        free(state);
        return NULL;
    }
    phc_particles_joint_lanes(p, lanes);
    double a[3];
    phc_particles_position(p, 0, a);
    CHECK(phc_particles_anchor(p, 0, a, 1, 1, &err) == 0); /* the root pinned */
    const double up[4] = {1, 0, 0, 0};
    for (size_t i = 1; i < n; ++i) {
        /* ages: held (s = 1), free (s = 0), between */
        const double age = i % 11 == 0 ? 0.7 : i % 13 == 1 ? 0.0 : 0.05 + 0.4 * (double)(i % 7) / 6;
        CHECK(phc_particles_set_age(p, i, age, &err) == 0);
        const double m = phc_particles_mass(p, i);
        if (i % 23 == 4) { /* unloaded: f = −m g */
            const double f[3] = {0, 0, 9.81 * m};
            CHECK(phc_particles_set_force(p, i, f, &err) == 0);
        } else if (i % 29 == 6) { /* along −z, the axis turned to +z: a half turn */
            const double f[3] = {0, 0, -1e6 * m};
            CHECK(phc_particles_set_orientation(p, i, up, &err) == 0);
            CHECK(phc_particles_set_force(p, i, f, &err) == 0);
        }
        double x[3];
        phc_particles_position(p, i, x);
        if (i % 97 == 3)
            CHECK(phc_particles_anchor(p, i, x, 1, 1, &err) == 0);
        else if (i % 89 == 7)
            CHECK(phc_particles_anchor(p, i, x, 0.5, 0, &err) == 0);
    }
    for (int s = 0; s < steps; ++s) {
        phc_particles_report rep;
        CHECK(phc_particles_step(p, 0.01, &rep, &err) == PHC_OK);
    }
    for (size_t i = 0; i < n; ++i) {
        phc_particles_position(p, i, state + 7 * i);
        phc_particles_orientation(p, i, state + 7 * i + 3);
    }
    phc_particles_free(p);
    return state;
}

static void test_lanes_match_follow_one(void)
{
    phc_plant_graph *g = phc_plant_graph_random(3000, 17);
    CHECK(g != NULL);
    if (!g)
        return;
    const size_t n = g->n;
    const int keep = omp_get_max_threads();
    const int steps[2] = {1, 30};
    for (int s = 0; s < 2; ++s)
        for (int th = 1; th <= 2; ++th) {
            double *on = run_plant(g, 1, th, steps[s]), *off = run_plant(g, 0, th, steps[s]);
            size_t differ = 0, finite = 0;
            for (size_t k = 0; on && off && k < 7 * n; ++k) {
                differ += memcmp(&on[k], &off[k], sizeof(double)) != 0;
                finite += isfinite(on[k]) != 0;
            }
            printf("lanes vs follow_one: %zu-particle random plant, %d step(s), %d thread(s): %zu "
                   "of %zu coordinates differ (%zu finite)\n",
                   n, steps[s], th, differ, 7 * n, finite);
            CHECK(on && off && differ == 0 && finite == 7 * n);
            free(on);
            free(off);
        }
    omp_set_num_threads(keep);
    phc_plant_graph_free(g);
}

int main(void)
{
    test_lanes_alone();
    test_lanes_match_follow_one();
    return check_finish("test_particles_joint_lanes");
}
