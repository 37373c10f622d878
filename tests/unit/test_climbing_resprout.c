/* A broken shoot's stump sprouts again (model/climbing_breaking.h,
 * "Resprouting"; option resprout_delay).
 *
 *  1. A single axis (max_order 0: no laterals) grown horizontally (+x) 60 s
 *     kinematically, then with dynamics (one substep of 0.025 s per growth
 *     step) and break threshold 0.07: its link breaks and the plant has no
 *     growing tip.  With resprout_delay 2 s the stump (the broken link's
 *     parent) grows a new tip at the end of exactly the 80th step after
 *     the break's step (2 s / 0.025 s), none before; the new tip is the
 *     stump's child, of the stump's order, of size σ₀, its base at the
 *     stump's tip.
 *  2. It grows at the model's rate: in full light the shoot from the stump
 *     is L(σ₀ + r t) long t s after it sprouted (each tip grows dσ = r dt
 *     per step, step 3 of model/climbing_growth.h), as the same plant grew
 *     r L per s before the break (measured over its last kinematic second).
 *  3. Off (resprout_delay ∞, the default): no tip after the break, no
 *     resprout; and a delay no run reaches (1e9 s) gives the same plant bit
 *     for bit as ∞ (remembering a stump draws nothing).  Delay 0: the tip
 *     appears at the end of the break's own step.
 *  4. A bushy plant (2000 particles, then 20 dynamic steps with breaking,
 *     past 4096: the parallel loops) that breaks and resprouts on 1 and
 *     2 OpenMP threads: the same plant bit for bit.
 *  5. Bad options: resprout_delay < 0 or NaN refused, naming the key. */
#include "model/climbing_breaking.h"
#include "model/climbing_growth.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "climbing_breaking_measures.h"
#include "climbing_bushy_plant.h"

#define THRESHOLD 0.07
#define DT 0.025 /* s: one substep per growth step */
#define DELAY 2.0 /* s */

/* README, growth step 3: a shoot t s old in full light holds
 * 1 + ⌊r t/(1 − σ₀)⌋ particles and is L(σ₀ + r t + σ₀⌊r t/(1 − σ₀)⌋) long.
 * Returns 0 at a t where r t/(1 − σ₀) is within 1e-9 of a whole number (a
 * rounding apart from a new internode: not compared). */
static int shoot_rule(double r, double t, double L, double sigma0, size_t *m, double *length)
{
    const double q = r * t / (1 - sigma0), f = floor(q + 0.5);
    if (fabs(q - f) < 1e-9)
        return 0;
    *m = 1 + (size_t)floor(q);
    *length = L * (sigma0 + r * t + sigma0 * floor(q));
    return 1;
}

/* The horizontal shoot of test_climbing_breaking (laterals of order 1):
 * 60 s kinematic, then dynamics with one substep. */
static phc_climbing *shoot(double delay, phc_error *err, double *l_main, size_t *m_main)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.branch_probability = 0.5;
    o.max_order = 1;
    o.growth_rate = 0.2;
    o.particles.break_threshold = THRESHOLD;
    o.resprout_delay = delay;
    const double base[3] = {0, 0, 0}, east[3] = {1, 0, 0};
    phc_climbing *c = phc_climbing_new(base, east, &o, err);
    if (!c)
        return NULL;
    for (int s = 0; s < 240; ++s) {
        if (phc_climbing_step(c, 0.25, err))
            goto fail;
        if (s == 238 && l_main) /* 59.75 s (60 s is a new internode's time) */
            *l_main = climbing_axis_length(c, 0, m_main);
    }
    if (phc_climbing_set_dynamics_substeps(c, 1, err) == 0)
        return c;
fail:
    phc_climbing_free(c);
    return NULL;
}

/* Index of stable id `id`, or PHC_CLIMBING_NONE. */
static size_t index_of(const phc_climbing *c, size_t id)
{
    for (size_t i = 0; i < phc_climbing_count(c); ++i)
        if (phc_climbing_id(c, i) == id)
            return i;
    return PHC_CLIMBING_NONE;
}

/* Attached (not falling) children of the particle with stable id `id`. */
static size_t stump_children(const phc_climbing *c, size_t id)
{
    const size_t p = index_of(c, id);
    size_t m = 0;
    for (size_t i = 0; p != PHC_CLIMBING_NONE && i < phc_climbing_count(c); ++i)
        m += phc_climbing_parent(c, i) == p && !phc_climbing_is_falling(c, i);
    return m;
}

/* Grows the axis until its first break; returns the break's step (0: none
 * in 2000) and the stump's stable id. */
static size_t grow_to_break(phc_climbing *c, size_t *stump_id, phc_error *err)
{
    for (size_t s = 1; s <= 2000; ++s) {
        if (phc_climbing_step(c, DT, err))
            return 0;
        phc_climbing_stats st;
        phc_climbing_get_stats(c, &st);
        if (st.breaks == 0)
            continue;
        const size_t k = index_of(c, st.last_break_id);
        *stump_id = phc_climbing_id(c, phc_climbing_parent(c, k));
        return s;
    }
    return 0;
}

int main(void)
{
    phc_error err;
    const phc_climbing_options d = phc_climbing_options_default();
    const double L = d.max_length, sigma0 = d.bud_fraction, r = 0.2;

    /* 1.–2. the axis that breaks and resprouts after 2 s */
    {
        /* the main axis at 59.75 s, grown by the rule */
        size_t m_main = 0, m_rule = 0;
        double l_main = 0, l_rule = 0;
        phc_climbing *c = shoot(DELAY, &err, &l_main, &m_main);
        CHECK(c != NULL);
        if (!c)
            return check_finish("climbing_resprout");
        CHECK(shoot_rule(r, 59.75, L, sigma0, &m_rule, &l_rule));
        printf("main axis at 59.75 s: %zu particles, %.6f m; the rule 1 + floor(r t/(1 - sigma0)) = "
               "%zu, L(sigma0 + r t + sigma0 floor(...)) = %.6f m\n",
               m_main, l_main, m_rule, l_rule);
        CHECK(m_main == m_rule && fabs(l_main - l_rule) < 1e-12);
        size_t stump_id = 0;
        const size_t s_break = grow_to_break(c, &stump_id, &err);
        CHECK(s_break > 0);
        phc_climbing_stats st;
        phc_climbing_get_stats(c, &st);
        const double t_break = st.time;
        printf("axis: broke at step %zu of dynamics (t = %.3f s), stress %.6f, stump id %zu, "
               "its attached children after the break %zu\n",
               s_break, t_break, st.last_break_stress, stump_id, stump_children(c, stump_id));
        CHECK(stump_children(c, stump_id) == 0);
        size_t s_sprout = 0, early = 0;
        for (size_t s = 1; s <= 200 && !s_sprout; ++s) {
            CHECK(phc_climbing_step(c, DT, &err) == 0);
            phc_climbing_get_stats(c, &st);
            if (st.resprouts > 0)
                s_sprout = s;
            else
                early += stump_children(c, stump_id);
        }
        const size_t expect = (size_t)lround(DELAY / DT);
        printf("resprout: at the end of step %zu after the break's step (t = %.3f s, %.3f s after "
               "the break; expected step %zu), the stump's children before it %zu\n",
               s_sprout, st.time, st.time - t_break, expect, early);
        CHECK(s_sprout == expect);
        CHECK(early == 0);
        CHECK(st.resprouts == 1);
        const size_t k = index_of(c, st.last_resprout_id), p = index_of(c, stump_id);
        CHECK(k != PHC_CLIMBING_NONE && p != PHC_CLIMBING_NONE);
        if (k == PHC_CLIMBING_NONE || p == PHC_CLIMBING_NONE) {
            phc_climbing_free(c);
            return check_finish("climbing_resprout");
        }
        double kb[3], kt[3], pb[3], pt[3];
        phc_climbing_segment(c, k, kb, kt);
        phc_climbing_segment(c, p, pb, pt);
        const double gap = sqrt((kb[0] - pt[0]) * (kb[0] - pt[0]) +
                                (kb[1] - pt[1]) * (kb[1] - pt[1]) +
                                (kb[2] - pt[2]) * (kb[2] - pt[2]));
        printf("new tip: parent is the stump %d, order %u (stump %u), size %.3f, base %.3g m from "
               "the stump's tip\n",
               phc_climbing_parent(c, k) == p, phc_climbing_order(c, k), phc_climbing_order(c, p),
               phc_climbing_size(c, k), gap);
        CHECK(phc_climbing_parent(c, k) == p && phc_climbing_is_apical(c, k));
        CHECK(phc_climbing_order(c, k) == phc_climbing_order(c, p));
        CHECK(phc_climbing_size(c, k) == sigma0);
        CHECK(gap < 1e-12);
        /* 2. its growth over the next 5 s (200 steps: one new internode) */
        const size_t breaks = st.breaks;
        const size_t kid = st.last_resprout_id;
        double worst = 0, grown = 0, want = 0;
        size_t steps = 0, compared = 0, m_off = 0, m = 0, mw = 0;
        for (size_t s = 1; s <= 200; ++s) {
            CHECK(phc_climbing_step(c, DT, &err) == 0);
            phc_climbing_get_stats(c, &st);
            if (st.breaks != breaks) /* (the young shoot broke: stop measuring) */
                break;
            steps = s;
            grown = climbing_axis_length(c, index_of(c, kid), &m);
            if (!shoot_rule(r, (double)s * DT, L, sigma0, &mw, &want))
                continue;
            ++compared;
            worst = fmax(worst, fabs(grown - want) / want);
            m_off += m != mw;
        }
        printf("growth from the stump: %zu steps (%zu compared), at %.2f s %zu particles, %.6f m; "
               "the rule %zu, %.6f m; worst relative difference %.2g, particle counts off %zu\n",
               steps, compared, (double)steps * DT, m, grown, mw, want, worst, m_off);
        CHECK(steps == 200 && compared >= 190);
        CHECK(m == 2 && worst < 1e-12 && m_off == 0);
        phc_climbing_free(c);
    }

    /* 3. off (∞), a delay never reached (1e9 s), delay 0 */
    {
        double *xs[2] = {NULL, NULL};
        size_t ns[2] = {0, 0}, tips_after[2] = {0, 0}, resprouts[2] = {0, 0};
        const double delays[2] = {INFINITY, 1e9};
        for (int run = 0; run < 2; ++run) {
            phc_climbing *c = shoot(delays[run], &err, NULL, NULL);
            CHECK(c != NULL);
            if (!c)
                break;
            size_t stump_id = 0;
            CHECK(grow_to_break(c, &stump_id, &err) > 0);
            for (int s = 0; s < 200; ++s) {
                CHECK(phc_climbing_step(c, DT, &err) == 0);
                tips_after[run] += stump_children(c, stump_id);
            }
            phc_climbing_stats st;
            phc_climbing_get_stats(c, &st);
            resprouts[run] = st.resprouts;
            ns[run] = phc_climbing_count(c);
            xs[run] = malloc(6 * ns[run] * sizeof(double));
            for (size_t i = 0; xs[run] && i < ns[run]; ++i) {
                phc_climbing_position(c, i, xs[run] + 6 * i);
                phc_climbing_direction(c, i, xs[run] + 6 * i + 3);
            }
            phc_climbing_free(c);
        }
        size_t differ = 0;
        if (xs[0] && xs[1] && ns[0] == ns[1])
            for (size_t k = 0; k < 6 * ns[0]; ++k)
                differ += memcmp(xs[0] + k, xs[1] + k, sizeof(double)) != 0;
        printf("off: 200 steps after the break, the stump's children %zu, resprouts %zu; delay 1e9 s: %zu "
               "particles against %zu, %zu of %zu numbers differ\n",
               tips_after[0], resprouts[0], ns[1], ns[0], differ, 6 * ns[0]);
        CHECK(tips_after[0] == 0 && resprouts[0] == 0 && resprouts[1] == 0);
        CHECK(ns[0] == ns[1] && differ == 0);
        free(xs[0]);
        free(xs[1]);

        phc_climbing *c = shoot(0, &err, NULL, NULL);
        CHECK(c != NULL);
        if (c) {
            size_t stump_id = 0;
            CHECK(grow_to_break(c, &stump_id, &err) > 0);
            phc_climbing_stats st;
            phc_climbing_get_stats(c, &st);
            const size_t k = index_of(c, st.last_resprout_id);
            printf("delay 0: resprouts %zu at the end of the break's step, the new tip's parent is "
                   "the stump %d\n",
                   st.resprouts,
                   k != PHC_CLIMBING_NONE &&
                       phc_climbing_id(c, phc_climbing_parent(c, k)) == stump_id);
            CHECK(st.resprouts == 1 && stump_children(c, stump_id) == 1);
            CHECK(k != PHC_CLIMBING_NONE &&
                  phc_climbing_id(c, phc_climbing_parent(c, k)) == stump_id);
            phc_climbing_free(c);
        }
    }

    /* 4. 1 and 2 threads with breaking and resprouting */
    {
        phc_climbing_options o = climbing_bushy_options(5);
        o.particles.maturity_age = 20;
        o.min_stiffness = 0.3;
        o.particles.break_threshold = 0.0195;
        o.fall_time = 0.5;
        o.resprout_delay = 0.5;
        double *xs[2] = {NULL, NULL};
        size_t ns[2] = {0, 0};
        phc_climbing_stats st[2];
        memset(st, 0, sizeof st);
        for (int run = 0; run < 2; ++run) {
            xs[run] = climbing_threads_run(&o, 20, run + 1, &ns[run], &st[run]);
            CHECK(xs[run] != NULL);
        }
        size_t differ = 0;
        if (xs[0] && xs[1] && ns[0] == ns[1])
            for (size_t k = 0; k < 7 * ns[0]; ++k)
                differ += memcmp(xs[0] + k, xs[1] + k, sizeof(double)) != 0;
        printf("threads: bushy plant, 20 dynamic steps, resprout_delay 0.5 s: 1 thread %zu "
               "particles, %zu breaks, %zu resprouts; 2 threads %zu, %zu, %zu; %zu of %zu numbers "
               "differ\n",
               ns[0], st[0].breaks, st[0].resprouts, ns[1], st[1].breaks, st[1].resprouts, differ,
               7 * ns[0]);
        CHECK(ns[0] == ns[1] && ns[0] >= 4096 && st[0].resprouts >= 1 &&
              st[0].resprouts == st[1].resprouts && st[0].breaks == st[1].breaks);
        CHECK(differ == 0);
        free(xs[0]);
        free(xs[1]);
    }

    /* 5. bad options */
    {
        const double base[3] = {0, 0, 0}, up[3] = {0, 0, 1};
        phc_climbing_options o = phc_climbing_options_default();
        o.resprout_delay = -1;
        CHECK(phc_climbing_new(base, up, &o, &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "resprout_delay");
        o.resprout_delay = NAN;
        CHECK(phc_climbing_new(base, up, &o, &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "resprout_delay");
        printf("bad options: %s\n", err.message);
    }

    /* the stump list on its own */
    {
        phc_climbing_stumps s;
        memset(&s, 0, sizeof s);
        for (size_t i = 0; i < 10; ++i)
            CHECK(phc_climbing_stumps_add(&s, 100 + i, 0.5 * (double)i) == 0);
        size_t due[10];
        const size_t m = phc_climbing_stumps_take_due(&s, 3.0, 1.0, due); /* broke by 2 s */
        CHECK(m == 5 && s.n == 5 && due[0] == 100 && due[4] == 104 && s.id[0] == 105);
        phc_climbing_stumps_free(&s);
        const size_t ids[5] = {0, 3, 4, 9, 12};
        CHECK(phc_climbing_find_id(ids, 5, 9) == 3 && phc_climbing_find_id(ids, 5, 0) == 0);
        CHECK(phc_climbing_find_id(ids, 5, 5) == (size_t)-1 &&
              phc_climbing_find_id(ids, 5, 13) == (size_t)-1);
        const size_t parent[4] = {(size_t)-1, 0, 1, 1};
        const unsigned char lateral[4] = {0, 0, 1, 0}, falling[4] = {0, 0, 0, 0};
        CHECK(phc_climbing_has_attached_successor(parent, lateral, falling, 4, 1) == 1);
        const unsigned char falling2[4] = {0, 0, 0, 1}; /* the lateral 2 alone is left */
        CHECK(phc_climbing_has_attached_successor(parent, lateral, falling2, 4, 1) == 0);
    }
    return check_finish("climbing_resprout");
}
