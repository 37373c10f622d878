/* Shoots that break while a climbing plant grows (model/climbing_breaking.h).
 *
 *  1. A plant grown horizontally (+x) from its seed, 60 s kinematic, then
 *     with dynamics (one substep of 0.025 s per growth step, gravity
 *     −9.81 m/s², damping 0.01) and break threshold 0.07: the first link
 *     breaks in the step in which the largest stress of a linked group
 *     first passes the threshold (checked against the stresses read after
 *     every step: all ≤ 0.07 before, the broken group's stress > 0.07 and
 *     the largest of the step); the piece is the subtree below the link,
 *     has no growing tip and no anchor.
 *  2. The piece falls: its centre of mass (mass ∝ r²L) drops over the
 *     fall time (1 s, 40 substeps) as the particles' damped free fall from
 *     rest, Σ_k h (v_{k−1} + g h), v_k = (v_{k−1} + g h)(1 − d), within 1%
 *     (its speed at the break and its own links' pull are the difference).
 *  3. After fall_time it leaves the plant: the count drops by its size at
 *     t_break + 1 s, the parents stay in index order, the ids increase; the
 *     plant grows on from its other tips; a shoot tracer that looked at the
 *     plant all along gives valid traces.
 *  3b. Dynamics switched off while a piece falls: it leaves at once, the
 *     plant grows on kinematically and with dynamics again; fall_time 0:
 *     the piece leaves at the end of the step that broke it.
 *  4. Threshold 0: no break, and the plant is the same bit for bit as with
 *     a threshold no stress reaches (1e9).
 *  5. A bushy plant of > 2000 particles with breaking on 1 and 2 OpenMP
 *     threads: the same breaks and the same plant bit for bit.
 *  6. Bad options: fall_time < 0 or not finite refused, naming the key. */
#include "model/climbing_breaking.h"
#include "model/climbing_growth.h"
#include "fit/costs/shoot_tracer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "climbing_breaking_measures.h"
#include "climbing_bushy_plant.h"

#define THRESHOLD 0.07
#define DT 0.025 /* s: one substep per growth step */

static phc_climbing_options shoot_options(double threshold)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.branch_probability = 0.5;
    o.max_order = 1;
    o.growth_rate = 0.2;
    o.particles.break_threshold = threshold;
    return o; /* fall_time: the default 1 s; damping 0.01; gravity -9.81 z */
}

/* The horizontal plant: 60 s kinematic, then dynamics with one substep. */
static phc_climbing *shoot(double threshold, phc_error *err)
{
    const phc_climbing_options o = shoot_options(threshold);
    const double base[3] = {0, 0, 0}, east[3] = {1, 0, 0};
    phc_climbing *c = phc_climbing_new(base, east, &o, err);
    if (!c)
        return NULL;
    for (int s = 0; s < 240; ++s)
        if (phc_climbing_step(c, 0.25, err))
            goto fail;
    if (phc_climbing_set_dynamics_substeps(c, 1, err) == 0)
        return c;
fail:
    phc_climbing_free(c);
    return NULL;
}

int main(void)
{
    phc_error err;

    /* 1.–3. the horizontal plant */
    {
        phc_climbing *c = shoot(THRESHOLD, &err);
        CHECK(c != NULL);
        if (!c)
            return check_finish("climbing_breaking");
        phc_shoot_tracer tr;
        phc_shoot_tracer_init(&tr);
        double before = 0, at_break = 0, largest_at_break = 0, t_break = 0, z0 = 0, z_end = NAN;
        double worst_before = 0;
        size_t step_break = 0, piece = 0, n_before = 0, piece_tips = 0, piece_anchored = 0,
               piece_open = 0, n_after_drop = 0, tips_after_drop = 0, step_drop = 0;
        int broke = 0, dropped = 0, tracer_ok = 1;
        size_t last_falling = 0;
        for (size_t s = 1; s <= 2000; ++s) {
            size_t at;
            const double prev = climbing_max_linked_stress(c, &at);
            if (phc_climbing_step(c, DT, &err)) {
                CHECK(0);
                break;
            }
            phc_climbing_stats st;
            phc_climbing_get_stats(c, &st);
            if (!broke && st.breaks == 0)
                worst_before = fmax(worst_before, climbing_max_linked_stress(c, &at));
            if (!broke && st.breaks > 0) {
                broke = 1;
                step_break = s;
                before = prev;
                at_break = st.last_break_stress;
                t_break = st.time;
                size_t k_at = 0;
                /* the broken group's stress is the largest of the step */
                for (size_t i = 1; i < phc_climbing_count(c); ++i)
                    if (phc_climbing_stress(c, i) > largest_at_break) {
                        largest_at_break = phc_climbing_stress(c, i);
                        k_at = i;
                    }
                CHECK(phc_climbing_id(c, k_at) == st.last_break_id);
                n_before = phc_climbing_count(c);
                z0 = climbing_falling_centre_z(c, &piece);
                /* the piece: a whole subtree, no tips, no anchors */
                for (size_t i = 0; i < n_before; ++i) {
                    if (!phc_climbing_is_falling(c, i))
                        continue;
                    piece_tips += (size_t)phc_climbing_is_apical(c, i);
                    double a[3];
                    piece_anchored += (size_t)phc_climbing_anchor(c, i, a);
                    const size_t p = phc_climbing_parent(c, i);
                    piece_open += phc_climbing_id(c, i) != st.last_break_id && !phc_climbing_is_falling(c, p);
                }
                for (size_t i = 0; i < n_before; ++i) /* every descendant of a piece particle falls */
                    if (phc_climbing_parent(c, i) != PHC_CLIMBING_NONE &&
                        phc_climbing_is_falling(c, phc_climbing_parent(c, i)))
                        piece_open += !phc_climbing_is_falling(c, i);
            }
            if (broke && !dropped) {
                size_t m;
                const double z = climbing_falling_centre_z(c, &m);
                if (m > 0) {
                    z_end = z;
                    last_falling = m;
                }
                if (st.pieces_dropped > 0) {
                    dropped = 1;
                    step_drop = s;
                    n_after_drop = phc_climbing_count(c);
                    tips_after_drop = st.apical;
                }
            }
            if (s % 40 == 0)
                tracer_ok &= phc_shoot_tracer_look(&tr, c, s * DT, &err) == 0;
        }
        phc_climbing_stats st;
        phc_climbing_get_stats(c, &st);
        /* the damped free fall of the particles from rest over the fall
           steps (one substep h each, the break's step excluded) */
        const double h = DT, g = 9.81, d = 0.01;
        const size_t fall_steps = step_drop - step_break - 1;
        double v = 0, drop_free = 0;
        for (size_t k = 0; k < fall_steps; ++k) {
            drop_free += h * (v + g * h);
            v = (v + g * h) * (1 - d);
        }
        const double drop = z0 - z_end;
        printf("break: threshold %.3f; largest linked stress before the break step %.6f (all steps "
               "before: %.6f), at it %.6f (the broken group, id %zu; largest of the step %.6f) at "
               "step %zu (t = %.3f s)\n",
               THRESHOLD, before, worst_before, at_break, st.last_break_id, largest_at_break,
               step_break, t_break);
        printf("piece: %zu particles, %zu growing tips, %zu anchored, %zu outside the subtree; "
               "fell %.4f m in %zu steps of %.3f s; damped free fall from rest %.4f m (ratio %.4f)\n",
               piece, piece_tips, piece_anchored, piece_open, drop, fall_steps, h, drop_free,
               drop / drop_free);
        printf("drop: at step %zu (%.3f s after the break): %zu -> %zu particles, %zu tips; after "
               "%zu steps: %zu particles, %zu tips, breaks %zu, pieces dropped %zu (%zu particles)\n",
               step_drop, (double)(step_drop - step_break) * DT, n_before, n_after_drop,
               tips_after_drop, (size_t)2000, phc_climbing_count(c), st.apical, st.breaks,
               st.pieces_dropped, st.particles_dropped);
        CHECK(broke);
        CHECK(before <= THRESHOLD && worst_before <= THRESHOLD);
        CHECK(at_break > THRESHOLD);
        CHECK(at_break == largest_at_break);
        CHECK(piece >= 1 && piece_tips == 0 && piece_anchored == 0 && piece_open == 0);
        CHECK(last_falling == piece);
        CHECK(fabs(drop / drop_free - 1) < 0.01);
        CHECK(dropped && n_after_drop == n_before - piece);
        CHECK(fabs((double)(step_drop - step_break) * DT - 1.0) < 1e-9);
        CHECK(st.particles_dropped >= piece && st.pieces_dropped >= 1);
        CHECK(phc_climbing_count(c) > n_after_drop + 50); /* it grows on */
        CHECK(st.apical > 0);
        int order_ok = 1;
        for (size_t i = 1; i < phc_climbing_count(c); ++i) {
            const size_t p = phc_climbing_parent(c, i);
            order_ok &= p != PHC_CLIMBING_NONE && p < i && phc_climbing_id(c, i) > phc_climbing_id(c, i - 1);
        }
        CHECK(order_ok);
        phc_shoot_traces *traces = NULL;
        CHECK(tracer_ok);
        CHECK(phc_shoot_tracer_traces(&tr, "broken", &traces, &err) == 0);
        printf("tracer: %zu shoots, %zu points over %.3f s\n", traces ? traces->n_shoots : 0,
               traces ? traces->n_points : 0, traces ? traces->t_end : 0.0);
        CHECK(traces && traces->n_shoots > 1);
        phc_shoot_traces_free(traces);
        phc_shoot_tracer_clear(&tr);
        phc_climbing_free(c);
    }

    /* 3b. the dynamics switched off while a piece falls drop it at once;
       fall_time 0 drops a piece at the end of the step that broke it */
    {
        phc_climbing *c = shoot(THRESHOLD, &err);
        phc_climbing_stats st = {0};
        size_t n_broken = 0, n_off = 0, n_on = 0;
        for (int s = 0; c && s < 100 && st.breaks == 0; ++s) {
            CHECK(phc_climbing_step(c, DT, &err) == 0);
            phc_climbing_get_stats(c, &st);
        }
        const size_t falling = st.falling;
        if (c) {
            n_broken = phc_climbing_count(c);
            CHECK(phc_climbing_set_dynamics_substeps(c, 0, &err) == 0);
            phc_climbing_get_stats(c, &st);
            n_off = phc_climbing_count(c);
            CHECK(st.falling == 0 && n_off == n_broken - falling && st.particles_dropped == falling);
            for (int s = 0; s < 40; ++s)
                CHECK(phc_climbing_step(c, DT, &err) == 0);
            CHECK(phc_climbing_set_dynamics_substeps(c, 1, &err) == 0);
            for (int s = 0; s < 40; ++s)
                CHECK(phc_climbing_step(c, DT, &err) == 0);
            n_on = phc_climbing_count(c);
        }
        printf("dynamics off while %zu particles fall: %zu -> %zu particles, then 40 kinematic and "
               "40 dynamic steps: %zu\n",
               falling, n_broken, n_off, n_on);
        CHECK(falling > 0 && n_on >= n_off);
        phc_climbing_free(c);

        phc_climbing_options o = shoot_options(THRESHOLD);
        o.fall_time = 0;
        const double base[3] = {0, 0, 0}, east[3] = {1, 0, 0};
        c = phc_climbing_new(base, east, &o, &err);
        for (int s = 0; c && s < 240; ++s)
            CHECK(phc_climbing_step(c, 0.25, &err) == 0);
        CHECK(c && phc_climbing_set_dynamics_substeps(c, 1, &err) == 0);
        memset(&st, 0, sizeof st);
        for (int s = 0; c && s < 100 && st.breaks == 0; ++s) {
            CHECK(phc_climbing_step(c, DT, &err) == 0);
            phc_climbing_get_stats(c, &st);
        }
        printf("fall_time 0: breaks %zu, falling after the step %zu, dropped %zu\n", st.breaks,
               st.falling, st.particles_dropped);
        CHECK(st.breaks == 1 && st.falling == 0 && st.particles_dropped > 0);
        phc_climbing_free(c);
    }

    /* 4. threshold 0: no breaking, the same plant as with 1e9 */
    {
        phc_climbing *a = shoot(0, &err), *b = shoot(1e9, &err);
        CHECK(a && b);
        for (int s = 0; a && b && s < 400; ++s) {
            CHECK(phc_climbing_step(a, DT, &err) == 0);
            CHECK(phc_climbing_step(b, DT, &err) == 0);
        }
        size_t differ = 0, n = a ? phc_climbing_count(a) : 0;
        phc_climbing_stats sa = {0}, sb = {0};
        if (a && b) {
            phc_climbing_get_stats(a, &sa);
            phc_climbing_get_stats(b, &sb);
            CHECK(n == phc_climbing_count(b));
            for (size_t i = 0; n == phc_climbing_count(b) && i < n; ++i) {
                double x[3], y[3];
                phc_climbing_position(a, i, x);
                phc_climbing_position(b, i, y);
                differ += memcmp(x, y, sizeof x) != 0;
            }
        }
        printf("threshold 0: %zu particles, breaks %zu; against threshold 1e9 (breaks %zu): %zu "
               "positions differ\n",
               n, sa.breaks, sb.breaks, differ);
        CHECK(sa.breaks == 0 && sb.breaks == 0 && differ == 0);
        phc_climbing_free(a);
        phc_climbing_free(b);
    }

    /* 5. 1 and 2 threads with breaking */
    {
        phc_climbing_options o = climbing_bushy_options(5);
        o.particles.maturity_age = 20;
        o.min_stiffness = 0.3;
        o.particles.break_threshold = 0.0195;
        o.fall_time = 0.5;
        size_t ns[2] = {0, 0}, numbers;
        phc_climbing_stats st[2];
        const size_t differ = climbing_threads_compare(&o, 12, ns, st, &numbers);
        printf("threads: bushy plant, 12 dynamic steps with threshold 0.0195: 1 thread %zu "
               "particles, %zu breaks, %zu falling, %zu dropped; 2 threads %zu, %zu, %zu, %zu; "
               "%zu of %zu numbers differ\n",
               ns[0], st[0].breaks, st[0].falling, st[0].particles_dropped, ns[1], st[1].breaks,
               st[1].falling, st[1].particles_dropped, differ, numbers);
        CHECK(ns[0] == ns[1] && st[0].breaks >= 1 && st[0].breaks == st[1].breaks);
        CHECK(st[0].particles_dropped >= 1 && st[0].particles_dropped == st[1].particles_dropped);
        CHECK(differ == 0);
    }

    /* 6. bad options */
    {
        const double base[3] = {0, 0, 0}, up[3] = {0, 0, 1};
        phc_climbing_options o = phc_climbing_options_default();
        o.fall_time = -1;
        CHECK(phc_climbing_new(base, up, &o, &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "fall_time");
        o.fall_time = NAN;
        CHECK(phc_climbing_new(base, up, &o, &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "fall_time");
        printf("bad options: %s\n", err.message);
    }

    /* the index helpers on their own */
    {
        /* 0 ← 1 ← 2, 1 ← 3 ← 4, 0 ← 5 */
        const size_t parent[6] = {(size_t)-1, 0, 1, 1, 3, 0};
        unsigned char tag[6] = {0, 0, 0, 1, 0, 0};
        const size_t m = phc_climbing_subtree_tag(parent, 6, 1, tag, 2);
        CHECK(m == 4 && tag[0] == 0 && tag[1] == 2 && tag[2] == 2 && tag[3] == 2 && tag[4] == 2 &&
              tag[5] == 0);
        unsigned char drop[6] = {0, 0, 1, 0, 1, 0};
        size_t map[6];
        double a[6] = {0, 1, 2, 3, 4, 5};
        CHECK(phc_climbing_keep_map(drop, 6, map) == 4);
        CHECK(map[0] == 0 && map[1] == 1 && map[2] == (size_t)-1 && map[3] == 2 && map[5] == 3);
        CHECK(phc_climbing_compact(a, sizeof *a, drop, 6) == 4);
        CHECK(a[0] == 0 && a[1] == 1 && a[2] == 3 && a[3] == 5);
    }
    return check_finish("climbing_breaking");
}
