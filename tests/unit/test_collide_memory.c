/* Unit test of the collision pass's memory (model/particles.h
 * phc_particles_collide_all; climbing option collide_all): the answers of
 * repeated query points are reused, never changing the plant.  Every
 * checked number is printed.
 *  1. Fig. 13's wall (measurements/examples/climbing/wall_window.obj, open
 *     at its foot: no skips by distance), its seed and growth values, grown
 *     30 s with dynamics (25 substeps of 0.01 s per 0.25 s step, own-weight
 *     pass) and collide: every query made on one thread (and answered by
 *     the support mesh's AABB tree: a copy of the mesh without certified
 *     answers, measurements/support_mesh.h), the memory on one thread and
 *     on two (certified answers on).  After every growth step all particles' centres
 *     and segment ends, the pushes and the smallest δ − r are the same bit
 *     for bit; the query counts are printed and the memory must save some.
 *     (At this size, < 1024 particles, the particles' step runs on one
 *     thread anyway; the collision pass always does.)
 *  2. The same seed on the closed wall (wall_window_closed.obj, Fig. 13's
 *     wall as a solid), 30 s with the beam pass: every query made and
 *     answered by the AABB tree, against the supports declared closed
 *     (points too far off the wall to be pushed are not queried) with
 *     certified answers: the same plant bit for bit after every step, and
 *     fewer queries made. */
#include "measurements/support_mesh.h"
#include "model/climbing_growth.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "climbing_fig13_options.h"
#include "climbing_same_state.h"

int main(void)
{
    phc_error err;
    const char *mesh_path = PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window.obj";
    phc_support_mesh *wall = phc_support_mesh_read(mesh_path, &err),
                     *wall_tree = phc_support_mesh_read(mesh_path, &err);
    CHECK(wall != NULL && wall_tree != NULL);
    if (!wall || !wall_tree)
        return check_finish("test_collide_memory");
    phc_support_mesh_certificates(wall_tree, 0);

    /* 1. Fig. 13's wall: memory against every query, 1 and 2 threads */
    enum { RUNS = 3 };
    const int threads[RUNS] = {1, 1, 2}, all[RUNS] = {1, 0, 0};
    phc_climbing *c[RUNS];
    const double seed[3] = {-0.1, 0.02, 0}, up[3] = {0, 0, 1};
    for (int run = 0; run < RUNS; ++run) {
        phc_climbing_options o = fig13_options(all[run] ? wall_tree : wall);
        o.collide_all = all[run];
        c[run] = phc_climbing_new(seed, up, &o, &err);
        CHECK(c[run] != NULL);
    }
    size_t differ = 0, pushes = 0, steps = 0;
    const int max_threads = omp_get_max_threads();
    for (int k = 0; c[0] && c[1] && c[2] && k < 120; ++k) {
        for (int run = 0; run < RUNS; ++run) {
            omp_set_num_threads(threads[run]);
            CHECK(phc_climbing_step(c[run], 0.25, &err) == 0);
        }
        ++steps;
        size_t pushed;
        phc_climbing_collisions(c[0], &pushed, NULL);
        pushes += pushed;
        for (int run = 1; run < RUNS; ++run)
            differ += climbing_state_differs(c[0], c[run]);
    }
    omp_set_num_threads(max_threads);
    size_t queries[RUNS] = {0}, skipped[RUNS] = {0};
    const size_t n = c[0] ? phc_climbing_count(c[0]) : 0;
    for (int run = 0; run < RUNS; ++run) {
        phc_climbing_collision_queries(c[run], &queries[run], &skipped[run]);
        phc_climbing_free(c[run]);
    }
    printf("Fig. 13's wall, dynamics and collide, %zu steps of 0.25 s: %zu particles, %zu points pushed; queries: "
           "every query %zu made (%zu skipped); memory, 1 thread %zu made, %zu answered from memory; 2 threads "
           "%zu made, %zu from memory; growth steps or particles that differ: %zu\n",
           steps, n, pushes, queries[0], skipped[0], queries[1], skipped[1], queries[2], skipped[2], differ);
    const size_t tree = phc_support_mesh_tree_queries(wall);
    printf("  queries made with memory (both runs) answered by the mesh's AABB tree %zu, by a certificate %zu\n", tree,
           queries[1] + queries[2] - tree);
    CHECK(tree < queries[1] + queries[2]);
    CHECK(steps == 120 && differ == 0 && pushes > 0);
    CHECK(skipped[0] == 0 && skipped[1] > 0 && queries[1] + skipped[1] == queries[0]);
    CHECK(queries[2] == queries[1] && skipped[2] == skipped[1]);

    /* 2. the closed wall: supports_closed and certificates against every query by the tree */
    const char *closed_path = PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window_closed.obj";
    phc_support_mesh *solid = phc_support_mesh_read(closed_path, &err), *solid_tree = phc_support_mesh_read(closed_path, &err);
    CHECK(solid != NULL && solid_tree != NULL);
    if (solid && solid_tree) {
        phc_support_mesh_certificates(solid_tree, 0);
        phc_climbing *cc[2];
        for (int run = 0; run < 2; ++run) {
            phc_climbing_options o = fig13_options(run ? solid : solid_tree);
            o.particles.bending = PHC_PARTICLES_BEAM;
            o.particles.beam_modulus = 1e7;
            o.collide_all = !run;
            o.supports_closed = run;
            cc[run] = phc_climbing_new(seed, up, &o, &err);
            CHECK(cc[run] != NULL);
        }
        size_t differ2 = 0, steps2 = 0, pushes2 = 0;
        omp_set_num_threads(1);
        for (int k = 0; cc[0] && cc[1] && k < 120; ++k) {
            for (int run = 0; run < 2; ++run)
                CHECK(phc_climbing_step(cc[run], 0.25, &err) == 0);
            ++steps2;
            size_t pushed;
            phc_climbing_collisions(cc[0], &pushed, NULL);
            pushes2 += pushed;
            differ2 += climbing_state_differs(cc[0], cc[1]);
        }
        omp_set_num_threads(max_threads);
        size_t q2[2] = {0}, s2[2] = {0};
        for (int run = 0; run < 2; ++run) {
            phc_climbing_collision_queries(cc[run], &q2[run], &s2[run]);
            phc_climbing_free(cc[run]);
        }
        const size_t tree2 = phc_support_mesh_tree_queries(solid);
        printf("closed wall, beam pass, %zu steps: %zu points pushed; every query by the tree %zu; supports closed "
               "%zu made (%zu by the tree, %zu by a certificate), %zu skipped; growth steps or particles that "
               "differ: %zu\n",
               steps2, pushes2, q2[0], q2[1], tree2, q2[1] - tree2, s2[1], differ2);
        CHECK(steps2 == 120 && differ2 == 0 && pushes2 > 0);
        CHECK(s2[0] == 0 && q2[1] < q2[0] && tree2 < q2[1]);
    }
    phc_support_mesh_free(solid);
    phc_support_mesh_free(solid_tree);
    phc_support_mesh_free(wall);
    phc_support_mesh_free(wall_tree);
    return check_finish("test_collide_memory");
}
