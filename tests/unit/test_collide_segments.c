/* Unit test of the exact segment push (model/particles.h
 * phc_particles_push_segment_deepest, phc_particles_set_segment_collider;
 * measurements/support_mesh.h phc_support_mesh_segment_deepest; climbing
 * option collide_segments).  Every checked number is printed.
 *  1. A unit box and a segment of radius r = 1 cm in the plane y = 0.5
 *     along x + z = 1.99, from u = −0.2 to u = 0.1 ((1 − u, 0.99 + u)):
 *     its ends and centre lie 0.05–0.2 m off the box, its middle
 *     (0 <= u <= 0.01) cuts the edge x = z = 1 (the segment query finds
 *     a negative δ).  The capsule push moves nothing and leaves it
 *     0.01/√2 m < r from the edge; the segment push moves
 *     it off so that its distance to the edge is >= r − 1e-12 (exact: the
 *     move is along the common perpendicular), and the segment query then
 *     finds nothing within r.
 *  2. Fig. 13's seed on the closed wall (wall_window_closed.obj) grown
 *     30 s with dynamics and collide: collide_segments off with the query
 *     given is the plant without it, bit for bit, after every step; on,
 *     one thread and two give the same plant bit for bit. */
#include "measurements/support_mesh.h"
#include "model/climbing_growth.h"
#include "model/particles.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "climbing_fig13_options.h"
#include "climbing_same_state.h"

/* Distance (m) of segment a b to the line x = z = 1 (the box's edge; y
 * free): the distance in the x–z plane of the segment's projection to
 * the point (1, 1), exact for a segment in a plane y = const. */
static double distance_to_edge(const double a[3], const double b[3])
{
    const double d[2] = {b[0] - a[0], b[2] - a[2]}, e[2] = {1 - a[0], 1 - a[2]};
    double s = (d[0] * e[0] + d[1] * e[1]) / (d[0] * d[0] + d[1] * d[1]);
    s = fmin(1, fmax(0, s));
    return hypot(a[0] + s * d[0] - 1, a[2] + s * d[1] - 1);
}

/* The ends a, b of the segment with centre x, unit axis and half length h (m). */
static void segment_ends(const double x[3], const double axis[3], double h, double a[3], double b[3])
{
    for (int k = 0; k < 3; ++k) {
        a[k] = x[k] - h * axis[k];
        b[k] = x[k] + h * axis[k];
    }
}

int main(void)
{
    phc_error err;
    /* 1. the box's edge */
    const double v[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    const size_t t[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                          1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    phc_support_mesh *box = phc_support_mesh_from_arrays(v, 8, t, 12, "box", &err);
    CHECK(box != NULL);
    if (!box)
        return check_finish("test_collide_segments");
    const double r = 0.01, a0[3] = {1.2, 0.5, 0.79}, b0[3] = {0.9, 0.5, 1.09};
    double x[3], axis[3], h, sa[3], sb[3];
    for (int k = 0; k < 3; ++k) {
        x[k] = 0.5 * (a0[k] + b0[k]);
        axis[k] = b0[k] - a0[k];
    }
    h = 0.5 * sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (int k = 0; k < 3; ++k)
        axis[k] /= 2 * h;
    double depth, xc[3], ac[3];
    memcpy(xc, x, sizeof xc);
    memcpy(ac, axis, sizeof ac);
    const int capsule = phc_particles_push_segment_out(phc_support_mesh_closest, box, r, h, 64, xc, ac, &depth);
    segment_ends(xc, ac, h, sa, sb);
    const double before = distance_to_edge(sa, sb);
    double t0, d0;
    const int cut = phc_support_mesh_segment_deepest(box, sa, sb, r, &t0, &d0);
    printf("box edge, r = %.3g m: the capsule push moves %d points (smallest delta - r of centre and ends %.4g m); "
           "distance of the segment to the edge %.6g m; the segment query: deepest delta %.6g m at t = %.4g\n",
           r, capsule, depth, before, d0, t0);
    CHECK(capsule == 0 && depth > 0 && before < r && cut == 1 && d0 < 0);
    const int rounds = phc_particles_push_segment_deepest(phc_support_mesh_closest, box,
                                                          phc_support_mesh_segment_deepest, box, r, h, x, axis);
    segment_ends(x, axis, h, sa, sb);
    const double after = distance_to_edge(sa, sb);
    double tq, dq;
    const int still = phc_support_mesh_segment_deepest(box, sa, sb, r, &tq, &dq);
    printf("  the segment push: %d rounds; distance to the edge %.17g m (r - 1e-12 = %.17g); the segment query: "
           "deepest delta %.17g m at t = %.4g, within r: %d; length kept %.3g m\n",
           rounds, after, r - 1e-12, dq, tq, still, fabs(hypot(hypot(sb[0] - sa[0], sb[1] - sa[1]), sb[2] - sa[2]) - 2 * h));
    CHECK(rounds >= 1 && after >= r - 1e-12 && still == 0 && dq >= r - 1e-12);
    phc_support_mesh_free(box);

    /* 2. Fig. 13's seed on the closed wall: off = without, on: 1 = 2 threads */
    phc_support_mesh *solid =
        phc_support_mesh_read(PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window_closed.obj", &err);
    CHECK(solid != NULL);
    if (!solid)
        return check_finish("test_collide_segments");
    enum { RUNS = 4 };
    const int threads[RUNS] = {1, 1, 1, 2}, on[RUNS] = {0, 0, 1, 1}, query[RUNS] = {0, 1, 1, 1};
    phc_climbing *c[RUNS];
    const double seed[3] = {-0.1, 0.02, 0}, up[3] = {0, 0, 1};
    int made = 1;
    for (int run = 0; run < RUNS; ++run) {
        phc_climbing_options o = fig13_options(solid);
        o.supports_closed = 1;
        o.collide_segments = on[run];
        o.closest_segment = query[run] ? phc_support_mesh_segment_deepest : NULL;
        made &= (c[run] = phc_climbing_new(seed, up, &o, &err)) != NULL;
    }
    CHECK(made);
    size_t off_differ = 0, threads_differ = 0, steps = 0, pushed_off = 0, pushed_on = 0;
    const int max_threads = omp_get_max_threads();
    for (int k = 0; made && k < 120; ++k) {
        for (int run = 0; run < RUNS; ++run) {
            omp_set_num_threads(threads[run]);
            CHECK(phc_climbing_step(c[run], 0.25, &err) == 0);
        }
        ++steps;
        size_t p0, p2;
        phc_climbing_collisions(c[0], &p0, NULL);
        phc_climbing_collisions(c[2], &p2, NULL);
        pushed_off += p0;
        pushed_on += p2;
        off_differ += climbing_state_differs(c[0], c[1]);
        threads_differ += climbing_state_differs(c[2], c[3]);
    }
    omp_set_num_threads(max_threads);
    const size_t n_off = made ? phc_climbing_count(c[0]) : 0, n_on = made ? phc_climbing_count(c[2]) : 0;
    printf("Fig. 13's closed wall, %zu steps of 0.25 s: off %zu particles, %zu points pushed; on %zu particles, %zu "
           "pushes; growth steps or particles that differ: off vs without the query %zu, on 1 vs 2 threads %zu\n",
           steps, n_off, pushed_off, n_on, pushed_on, off_differ, threads_differ);
    CHECK(steps == 120 && off_differ == 0 && threads_differ == 0 && pushed_on > 0);
    for (int run = 0; run < RUNS; ++run)
        phc_climbing_free(c[run]);
    phc_support_mesh_free(solid);
    return check_finish("test_collide_segments");
}
