/* Speed of the climbing-plant model (model/climbing_growth.h; Hädrich,
 * Benes, Deussen, Pirk, CGF 36(2) 2017): time per frame of dynamics +
 * growth for plants of about 5k, 10k and 25k particles, on one and two
 * OpenMP threads.
 *
 * A plant is grown kinematically from one seed (seed 3, BP 0.9, B 2, orders
 * up to 6, growth rate 0.2 s⁻¹, steps of 0.25 s, light from above through a
 * 5 cm grid with extinction 40 m⁻¹, on a floor plane support z = 0 with
 * surface adaption and anchors) until it holds N particles; then frames
 * are timed on two plants grown alike (same seed), one kept kinematic
 * (growth only: light, tropisms, growth, branching, rest shape, anchors)
 * and one switched to one dynamics substep per frame
 * (phc_climbing_set_dynamics_substeps: the same plus the shape-matching
 * particles of model/particles.h, maturity age 20 s, s_min 0.3).
 * Physics = (dynamics frame) − (kinematic frame).  Its particles' part
 * alone: a phc_particles system made from the kinematic plant after its
 * timed frames (rest segments, current centres and directions, the seed
 * pinned, ages max(age, s_min t_m) and anchors as the climbing step hands
 * them over), then FRAMES steps of 0.25 s timed (median).
 * A frame is one phc_climbing_step of 0.25 s; the plant keeps growing
 * while it is timed (max_particles is lifted), so the count printed is the
 * mean over the timed frames.
 *
 * Peer: the paper's Table 1, 25k particles in 51.76 ms per frame on a
 * GeForce GTX 970 (physics 39.51%, growth 48.33%).  Target: ≤ 5 ms per
 * frame at 25k on this 2-core machine, linear in particles.
 *
 * Prints `name: value unit (details)`. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench_machine.h"
#include "climbing_bushy_plant.h"
#include "model/climbing_growth.h"
#include "model/particles.h"
#include "model/plant_graph.h"
#include "model/quaternion.h"

#define FRAMES 5
#define DT 0.25

static phc_climbing_options options(size_t substeps)
{
    phc_climbing_options o = climbing_bushy_options(3);
    o.max_particles = 1000000;
    climbing_floor_scene(&o);
    o.dynamics_substeps = substeps;
    o.particles.maturity_age = 20;
    o.min_stiffness = 0.3;
    return o;
}

/* A plant grown kinematically to at least `target` particles, then
 * FRAMES frames timed with `substeps` dynamics substeps per frame; for the
 * kinematic plant (substeps 0) also the particles' step alone (step_ms). */
typedef struct timing {
    double ms, particles, step_ms;
    size_t step_particles;
} timing;

/* Median time of FRAMES phc_particles_step calls of DT on a system made
 * from plant c as the climbing step makes and syncs its own (the options
 * o->particles, the seed pinned at its rest place, every other particle at
 * its current centre and direction with age max(age, s_min t_m) and its
 * anchor).  ms or -1 on an error (printed). */
static double time_particles_step(const phc_climbing *c, const phc_climbing_options *o)
{
    const size_t n = phc_climbing_count(c);
    phc_error err;
    phc_plant_graph *g = phc_plant_graph_new(n);
    phc_particles *p = NULL;
    double ms = -1;
    if (!g)
        return -1;
    for (size_t i = 0; i < n; ++i) {
        double xr[3], dr[3];
        const double L = phc_climbing_length(c, i);
        phc_climbing_rest_position(c, i, xr);
        phc_climbing_rest_direction(c, i, dr);
        for (int k = 0; k < 3; ++k) {
            g->head[3 * i + k] = xr[k] - 0.5 * L * dr[k];
            g->tail[3 * i + k] = xr[k] + 0.5 * L * dr[k];
        }
        g->radius[i] = phc_climbing_radius(c, i);
        g->length[i] = L;
        const size_t u = phc_climbing_parent(c, i);
        g->parent[i] = u == PHC_CLIMBING_NONE ? PHC_PLANT_NO_PARENT : u;
    }
    g->fixed[0] = 1;
    if (phc_plant_graph_finish(g, "bench", &err) || !(p = phc_particles_new(g, &o->particles, &err)))
        goto done;
    phc_particles_measure_stress(p, 0);
    for (size_t i = 1; i < n; ++i) {
        double x[3], d[3], q[4], a[3];
        phc_climbing_position(c, i, x);
        phc_climbing_direction(c, i, d);
        phc_quat_from_z(d, q);
        const double age = fmax(phc_climbing_age(c, i), o->min_stiffness * o->particles.maturity_age);
        const double k = phc_climbing_anchor(c, i, a) ? phc_climbing_anchor_strength(c, i) : 0;
        if (phc_particles_set_position(p, i, x, &err) || phc_particles_set_orientation(p, i, q, &err) ||
            phc_particles_set_age(p, i, age, &err) ||
            (k > 0 && phc_particles_anchor(p, i, a, fmin(1, k), 0, &err)))
            goto done;
    }
    double times[FRAMES];
    for (int k = 0; k < FRAMES; ++k) {
        const double t0 = now();
        if (phc_particles_step(p, DT, NULL, &err))
            goto done;
        times[k] = now() - t0;
    }
    qsort(times, FRAMES, sizeof times[0], cmp_double);
    ms = 1e3 * times[FRAMES / 2];
done:
    if (ms < 0)
        fprintf(stderr, "%s\n", err.message);
    phc_particles_free(p);
    phc_plant_graph_free(g);
    return ms;
}

static int time_frames(size_t target, size_t substeps, int threads, timing *t)
{
    phc_climbing_options o = options(0);
    const double base[3] = {0, 0, 0.01}, up[3] = {0, 0, 1};
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, up, &o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return -1;
    }
    while (phc_climbing_count(c) < target)
        if (phc_climbing_step(c, DT, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return -1;
        }
    /* switch dynamics on for the timed frames (the options live in the plant) */
    if (substeps && phc_climbing_set_dynamics_substeps(c, substeps, &err)) {
        fprintf(stderr, "%s\n", err.message);
        phc_climbing_free(c);
        return -1;
    }
    omp_set_num_threads(threads);
    double times[FRAMES], count = 0;
    for (int k = 0; k < FRAMES; ++k) {
        const double t0 = now();
        if (phc_climbing_step(c, DT, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return -1;
        }
        times[k] = now() - t0;
        count += (double)phc_climbing_count(c);
    }
    qsort(times, FRAMES, sizeof times[0], cmp_double);
    t->ms = 1e3 * times[FRAMES / 2];
    t->particles = count / FRAMES;
    t->step_particles = phc_climbing_count(c);
    t->step_ms = substeps ? 0 : time_particles_step(c, &o);
    phc_climbing_free(c);
    return t->step_ms < 0 ? -1 : 0;
}

int main(void)
{
    const size_t sizes[3] = {5000, 10000, 25000};
    const char *names[3] = {"5k", "10k", "25k"};
    double total25[3] = {0, 0, 0}, per_particle[2][3];
    printf("plant: seed 3, BP 0.9, B 2, orders <= 6, 0.25 s frames, light grid 80x80x40, floor support; median of %d "
           "frames; OpenMP max threads %d\n",
           FRAMES, omp_get_max_threads());
    for (int th = 1; th <= 2; ++th)
        for (int s = 0; s < 3; ++s) {
            timing kin, dyn;
            const cpu_mark a = cpu_now();
            if (time_frames(sizes[s], 0, th, &kin) || time_frames(sizes[s], 1, th, &dyn))
                return 1;
            const cpu_mark b = cpu_now();
            const double physics = dyn.ms - kin.ms;
            printf("frame_ms_%s_%dthread%s: %.3f ms (%.0f particles; growth %.3f ms, physics %.3f ms = %.1f%%; "
                   "%.3f us per particle; other load %.2f CPUs)\n",
                   names[s], th, th > 1 ? "s" : "", dyn.ms, dyn.particles, kin.ms, physics,
                   100 * physics / dyn.ms, 1e3 * dyn.ms / dyn.particles, other_load(a, b));
            printf("particles_step_ms_%s_%dthread%s: %.3f ms (phc_particles_step alone, one %.2f s step "
                   "of the kinematic plant's %zu particles; %.3f us per particle)\n",
                   names[s], th, th > 1 ? "s" : "", kin.step_ms, DT, kin.step_particles,
                   1e3 * kin.step_ms / (double)kin.step_particles);
            per_particle[th - 1][s] = dyn.ms / dyn.particles;
            if (s == 2)
                total25[th] = dyn.ms;
        }
    for (int th = 1; th <= 2; ++th)
        printf("linearity_%dthread%s: %.2f (time per particle at 25k over at 5k; 1 = linear)\n", th,
               th > 1 ? "s" : "", per_particle[th - 1][2] / per_particle[th - 1][0]);
    printf("peer_table1_25k: 51.76 ms per frame (GeForce GTX 970; physics 39.51%%, growth 48.33%%)\n");
    printf("ratio_ours_over_peer_25k_1thread: %.1f x\n", total25[1] / 51.76);
    printf("ratio_ours_over_peer_25k_2threads: %.1f x\n", total25[2] / 51.76);
    printf("target_25k: %s (<= 5 ms per frame: %.3f ms on 1 thread, %.3f ms on 2)\n",
           total25[1] <= 5 || total25[2] <= 5 ? "met" : "NOT met", total25[1], total25[2]);
    return 0;
}
