/* Climbing plants (Hädrich, Benes, Deussen, Pirk, CGF 36(2) 2017, §4.3):
 * a shoot that breaks while it grows (model/climbing_breaking.h).
 *
 * The plant of measurements/examples/climbing/break.yaml, read by the grow
 * config's own reader (fit/grow_config.h): a seed at (−0.25, 0, 0) m grows sideways
 * (+x) without support, growth rate 0.2 s⁻¹, BP 0.5, V 0.5, laterals of
 * order 1 only, dynamics with 10 substeps of 0.025 s per growth step of
 * 0.25 s, s_min 0.3, break threshold 0.048, fall_time 1 s.  Its young links
 * sag under their weight; the first link whose group stress passes the
 * threshold breaks and the piece below falls.
 *
 * Prints the growth step of the first break, the largest linked stress of
 * the step before and of the break, the piece, how far its centre of mass
 * (weights r²L) fell from the end of the break's step to the last step
 * before it left the plant against the particles' damped free fall from
 * rest over the same substeps (the piece was already falling for part of
 * the break's step, so it must fall at least that far), and the plant at
 * the end.  Checks (exit 1 when one fails): the break's stress is above
 * the threshold and the previous step's largest is not; the piece fell at
 * least the free fall from rest; it left the plant fall_time after the
 * break; the plant grew on (more particles and tips at the end than after
 * the drop).  Then the same plant with resprout_delay 2 s (break.yaml's
 * seed 3; the example break_resprout.yaml is seed 6): checks that the first break's stump sprouts
 * exactly 2 s (8 steps) after the break and that its new axis, 4 s later,
 * has the particles and length of the README's growth rule.  Writes
 * climbing_breaking_growth.png (four side views: the
 * step before the break, the step of the break with the piece falling,
 * after the piece left, at 120 s; colour = group stress, the falling
 * piece marked) and climbing_breaking_growth.md.
 *
 * Usage: notebook_climbing_breaking_growth OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/grow_config.h"
#include "fit/shape_plots.h"
#include "model/climbing_growth.h"
#include "tests/climbing_breaking_measures.h"

#include "notebook_plot.h"

/* break.yaml, loaded by main */
static phc_grow_config *cfg;
#define DT (cfg->time_step)                          /* s: growth step */
#define SUBSTEPS ((int)cfg->options.dynamics_substeps)
#define THRESHOLD (cfg->options.particles.break_threshold)
#define FALL_TIME (cfg->options.fall_time)          /* s */
#define DURATION (cfg->duration)                    /* s */
#define NPANEL 4

typedef struct snapshot {
    size_t n, nfall;
    double *head, *tail, *radius, *stress, *mark;
    char title[96];
} snapshot;

static int take(const phc_climbing *c, snapshot *s, const char *what)
{
    const size_t n = phc_climbing_count(c);
    s->n = n;
    s->nfall = 0;
    s->head = malloc(3 * n * sizeof *s->head);
    s->tail = malloc(3 * n * sizeof *s->tail);
    s->radius = malloc(n * sizeof *s->radius);
    s->stress = malloc(n * sizeof *s->stress);
    s->mark = malloc(3 * n * sizeof *s->mark);
    if (!s->head || !s->tail || !s->radius || !s->stress || !s->mark)
        return -1;
    for (size_t i = 0; i < n; ++i) {
        phc_climbing_segment(c, i, s->head + 3 * i, s->tail + 3 * i);
        s->radius[i] = phc_climbing_radius(c, i);
        s->stress[i] = fmin(phc_climbing_stress(c, i), THRESHOLD);
        if (phc_climbing_is_falling(c, i))
            phc_climbing_position(c, i, s->mark + 3 * s->nfall++);
    }
    phc_climbing_stats st;
    phc_climbing_get_stats(c, &st);
    snprintf(s->title, sizeof s->title, "%s: %.2f s, %zu particles", what, st.time, n);
    return 0;
}

static void release(snapshot *s)
{
    free(s->head);
    free(s->tail);
    free(s->radius);
    free(s->stress);
    free(s->mark);
}

/* The options of break.yaml. */
static phc_climbing_options plant_options(void) { return cfg->options; }

/* The same plant with resprout_delay RESPROUT s (break.yaml's seed): the
 * step of the first resprout after the first break and the new axis
 * AXIS_TIME s later against the growth rule (README, growth step 3: a shoot
 * t s old in full light holds 1 + ⌊r t/(1 − σ₀)⌋ particles and is
 * L(σ₀ + r t + σ₀⌊r t/(1 − σ₀)⌋) long).  Prints them; returns 1 when a
 * check fails, 2 on an error. */
#define RESPROUT 2.0   /* s */
#define AXIS_TIME 4.0  /* s (before the plant's next break, 4.75 s after the sprout) */
static int resprout_run(size_t first_break_step)
{
    phc_climbing_options o = plant_options();
    o.resprout_delay = RESPROUT;
    const double *base = cfg->position, *east = cfg->direction;
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, east, &o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return 2;
    }
    size_t sprout_step = 0, breaks_then = 0, kid = 0, grown_steps = 0;
    const size_t axis_steps = (size_t)llround(AXIS_TIME / DT);
    phc_climbing_stats st;
    for (size_t k = 1; k <= (size_t)llround(DURATION / DT); ++k) {
        if (phc_climbing_step(c, DT, &err)) {
            fprintf(stderr, "step %zu: %s\n", k, err.message);
            phc_climbing_free(c);
            return 2;
        }
        phc_climbing_get_stats(c, &st);
        if (!sprout_step && st.resprouts > 0) {
            sprout_step = k;
            breaks_then = st.breaks;
            kid = st.last_resprout_id;
        } else if (sprout_step) {
            if (st.breaks != breaks_then)
                break; /* (another break: the axis is not measured, the check fails) */
            if (++grown_steps == axis_steps)
                break;
        }
    }
    size_t k = PHC_CLIMBING_NONE, m = 0;
    for (size_t i = 0; sprout_step && i < phc_climbing_count(c); ++i)
        if (phc_climbing_id(c, i) == kid)
            k = i;
    const double t = (double)grown_steps * DT, r = o.growth_rate, s0 = o.bud_fraction,
                 L = o.max_length;
    const double length = k != PHC_CLIMBING_NONE ? climbing_axis_length(c, k, &m) : 0;
    const double q = floor(r * t / (1 - s0));
    const double want = L * (s0 + r * t + s0 * q);
    const int ok_when = sprout_step == first_break_step + (size_t)llround(RESPROUT / DT);
    const int ok_axis = k != PHC_CLIMBING_NONE && grown_steps == axis_steps &&
                        m == 1 + (size_t)q && fabs(length - want) < 1e-12;
    printf("resprout_delay %.1f s: the first break's stump sprouted at step %zu (%.2f s after the "
           "break); %.2f s later its new axis: %zu particles, %.6f m; the growth rule %zu, %.6f m\n",
           RESPROUT, sprout_step, (double)(sprout_step - first_break_step) * DT, t, m, length,
           1 + (size_t)q, want);
    printf("then (%.2f s): %zu particles, %zu growing tips; breaks %zu, resprouts %zu\n",
           st.time, phc_climbing_count(c), st.apical, st.breaks, st.resprouts);
    printf("check: the stump sprouted resprout_delay after the break: %s\n",
           ok_when ? "pass" : "FAIL");
    printf("check: the new axis grew by the growth rule: %s\n", ok_axis ? "pass" : "FAIL");
    phc_climbing_free(c);
    return !(ok_when && ok_axis);
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    const int started = nb_begin(argc, argv, NULL, &out);
    if (started != 0)
        return started;
    phc_error err;
    if (phc_grow_config_load(PHC_SOURCE_DIR "/measurements/examples/climbing/break.yaml", &cfg,
                             &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const phc_climbing_options o = plant_options();
    const double *base = cfg->position, *east = cfg->direction;
    phc_climbing *c = phc_climbing_new(base, east, &o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const size_t steps = (size_t)llround(DURATION / DT);
    snapshot snap[NPANEL], prev_snap;
    memset(snap, 0, sizeof snap);
    memset(&prev_snap, 0, sizeof prev_snap);
    double prev_max = 0, before = 0, at_break = 0, t_break = 0, z_start = NAN, z_last = NAN;
    size_t break_step = 0, drop_step = 0, piece = 0, last_step_falling = 0, n_after_drop = 0,
           tips_after_drop = 0, n_before = 0;
    int broke = 0, dropped = 0, bad = 0;
    for (size_t k = 1; k <= steps && !bad; ++k) {
        if (phc_climbing_step(c, DT, &err)) {
            fprintf(stderr, "step %zu: %s\n", k, err.message);
            return 1;
        }
        phc_climbing_stats st;
        phc_climbing_get_stats(c, &st);
        size_t m;
        const double z = climbing_falling_centre_z(c, &m);
        if (!broke && st.breaks > 0) {
            broke = 1;
            break_step = k;
            before = prev_max;
            at_break = st.last_break_stress;
            t_break = st.time;
            z_start = z;
            piece = m;
            n_before = phc_climbing_count(c);
            snap[0] = prev_snap; /* the step before the break */
            memset(&prev_snap, 0, sizeof prev_snap);
            bad |= take(c, &snap[1], "breaks");
        } else if (broke && !dropped) {
            if (m > 0 && st.pieces_dropped == 0) {
                z_last = z;
                last_step_falling = k;
            }
            if (st.pieces_dropped > 0) {
                dropped = 1;
                drop_step = k;
                n_after_drop = phc_climbing_count(c) - st.falling;
                tips_after_drop = st.apical;
                bad |= take(c, &snap[2], "piece gone");
            }
        }
        if (!broke) { /* keep the last step's shape for the panel before the break */
            release(&prev_snap);
            bad |= take(c, &prev_snap, "before the break");
        }
        prev_max = climbing_max_linked_stress(c, NULL);
    }
    release(&prev_snap);
    if (bad || !broke || !dropped) {
        fprintf(stderr, "%s\n", bad ? "out of memory" : "no break, or the piece never left");
        return 1;
    }
    if (take(c, &snap[3], "grown on") != 0)
        return 1;
    phc_climbing_stats st;
    phc_climbing_get_stats(c, &st);
    /* the particles' damped free fall from rest over the substeps from the
       end of the break's step to the end of the last step it fell */
    const double h = DT / SUBSTEPS, g = 9.81, d = o.particles.damping;
    const size_t fall_substeps = (last_step_falling - break_step) * SUBSTEPS;
    double v = 0, free_fall = 0;
    for (size_t k = 0; k < fall_substeps; ++k) {
        free_fall += h * (v + g * h);
        v = (v + g * h) * (1 - d);
    }
    const double fell = z_start - z_last;
    const int ok_break = at_break > THRESHOLD && before <= THRESHOLD;
    const int ok_fall = fell >= free_fall * (1 - 1e-9);
    const int ok_drop = fabs((double)(drop_step - break_step) * DT - FALL_TIME) < 1e-9;
    const int ok_grow = phc_climbing_count(c) > n_after_drop && st.apical > 0;
    printf("climbing, breaking during growth: seed %llu grown sideways, %d substeps of %.3f s per "
           "step of %.2f s, s_min %.1f, threshold %.3f, fall_time %.1f s\n",
           (unsigned long long)o.seed, SUBSTEPS, h, DT, o.min_stiffness, THRESHOLD, FALL_TIME);
    printf("first break: step %zu (t = %.2f s), stress %.6f; the step before: largest linked "
           "stress %.6f\n",
           break_step, t_break, at_break, before);
    printf("piece: %zu of %zu particles; its centre of mass fell %.4f m in the %zu substeps after "
           "the break's step; damped free fall from rest over them %.4f m\n",
           piece, n_before, fell, fall_substeps, free_fall);
    printf("left the plant at step %zu (%.2f s after the break): %zu particles, %zu growing tips\n",
           drop_step, (double)(drop_step - break_step) * DT, n_after_drop, tips_after_drop);
    printf("at %.0f s: %zu particles, %zu growing tips; breaks %zu, pieces dropped %zu (%zu "
           "particles)\n",
           st.time, phc_climbing_count(c), st.apical, st.breaks, st.pieces_dropped,
           st.particles_dropped);
    printf("check: break above the threshold, the step before not: %s\n", ok_break ? "pass" : "FAIL");
    printf("check: the piece fell at least the free fall from rest: %s\n", ok_fall ? "pass" : "FAIL");
    printf("check: it left the plant fall_time after the break: %s\n", ok_drop ? "pass" : "FAIL");
    printf("check: the plant grew on: %s\n", ok_grow ? "pass" : "FAIL");
    const int resprout = resprout_run(break_step);
    if (resprout == 2)
        return 1;

    phc_shape_panel pan[NPANEL];
    for (int k = 0; k < NPANEL; ++k) {
        pan[k].n = snap[k].n;
        pan[k].head = snap[k].head;
        pan[k].tail = snap[k].tail;
        pan[k].radius = snap[k].radius;
        pan[k].value = snap[k].stress;
        pan[k].title = snap[k].title;
        pan[k].markers = snap[k].nfall;
        pan[k].marker = snap[k].mark;
        pan[k].marker_label = "falling piece (particle centres)";
    }
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.title = "A shoot breaks while the plant grows (threshold 0.048)";
    po.value_label = "group stress (1; capped at the threshold)";
    po.value_min = 0.0;
    po.value_max = THRESHOLD;
    po.columns = 2;
    po.max_line_width = 5;
    char png[1024];
    snprintf(png, sizeof png, "%s/climbing_breaking_growth.png", out);
    if (phc_shape_plot(png, pan, NPANEL, &po, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "climbing_breaking_growth.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Climbing plants: a shoot breaks while the plant grows\n\n"
            "**The paper** (Hädrich et al., CGF 2017, §4.3): branches break when their deformation\n"
            "exceeds a threshold. **What we computed**: the plant of\n"
            "`measurements/examples/climbing/break.yaml`, grown sideways without support with\n"
            "dynamics (%d substeps of %.3f s), break threshold %.3f, fall_time %.1f s\n"
            "(`model/climbing_breaking.h`).\n\n"
            "![four side views](climbing_breaking_growth.png)\n\n"
            "The first link broke at t = %.2f s at stress %.6f (the step before: %.6f). The piece of\n"
            "%zu particles fell %.4f m (centre of mass) in the %zu substeps after the break's step,\n"
            "at least the damped free fall from rest over them (%.4f m) %s; it left the plant %.2f s\n"
            "after the break %s; the plant grew on from %zu to %zu particles %s.\n",
            SUBSTEPS, h, THRESHOLD, FALL_TIME, t_break, at_break, before, piece, fell,
            fall_substeps, free_fall, ok_fall ? "(pass)" : "(**FAIL**)",
            (double)(drop_step - break_step) * DT, ok_drop ? "(pass)" : "(**FAIL**)", n_after_drop,
            phc_climbing_count(c), ok_grow ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    for (int k = 0; k < NPANEL; ++k)
        release(&snap[k]);
    phc_climbing_free(c);
    const int fail = !(ok_break && ok_fall && ok_drop && ok_grow) || resprout != 0;
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    phc_grow_config_free(cfg);
    return fail;
}
