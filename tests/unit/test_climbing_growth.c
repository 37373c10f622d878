/* Unit test of climbing-plant growth (model/climbing_growth.h; Hädrich et
 * al., CGF 36(2) 2017, §4.2–4.3, eqs. 5–10).  Every checked number is
 * printed.
 *  1. Determinism: the same seed gives the same plant bit for bit; another
 *     seed gives another plant.
 *  1b. Growth on the OpenMP threads: a bushy plant on a floor under a
 *     light grid (the bench's settings, seed 3, but the light from the
 *     side, +x, so that the flat plant shades itself) grown kinematically to
 *     20,000 particles with a leaf every 3rd node (the light's, the
 *     tropisms', the anchors' and the leaves' loops then run in parallel)
 *     on 1 and 2 threads: the same plant bit for bit (centres, directions,
 *     light, anchors, leaf centres and normals).
 *  2. Apical growth without branching: after k steps of Δt in full light a
 *     shoot holds exactly 1 + ⌊r k Δt / (1 − σ₀)⌋ particles (every k up to
 *     400), its length is L_max(n σ₀ + r k Δt) and its tip lies on the
 *     straight line.
 *  3. Branching frequency: over 300 seeds the laterals made out of the buds
 *     drawn lie within 4 binomial standard deviations of BP·trials for
 *     BP = 0.1, 0.3, 0.7; BP = 0 makes none and BP = 1 makes one per bud.
 *  4. Direction variance: every lateral leaves its parent at an angle in
 *     [0, V·90°] and the largest angle seen comes near V·90°; V = 0 gives 0;
 *     thickness t_c = t_p·f exactly.
 *  5. Phototropism (eq. 7): a horizontal shoot, light from above: the tip's
 *     angle to the light falls at every step, as θ₀(1 − ηΔt)^k.
 *  6. Surface adaption (eq. 6) and anchors (eq. 5): a shoot grown level
 *     5 cm above a plane support bends down onto it, crawls along it and
 *     anchors, each anchor's strength k_max·σ·min(1, age/t_a) at every
 *     step; with τ = 0 it never comes near.  Release: a shoot anchored on
 *     a floor (dynamics, no gravity), then turned upside down: weak
 *     anchors (k_max 0.01) let go, strong ones (1) hold, and no anchored
 *     particle is ever beyond the release distance.
 *  7. Light: the Beer–Lambert sum on a 1×1×3 grid exactly; a vine hanging
 *     down shades itself: full light at the seed, less below, monotone,
 *     and it grows fewer particles than in full light.
 *  8. Dynamics (model/particles.h) under gravity, 0.01 s dynamics steps:
 *     the young shoot sags below its rest shape, its links stretch less
 *     than 25%, the seed particle stays.
 *  8b. One particle system across the steps: 1 vs 2 OpenMP threads and the
 *     same seed twice give the same > 1024-particle plant bit for bit.
 *  9. The generator against reference outputs; a seed behind a support
 *     face and bad options are refused naming the option. */
#include "model/climbing_growth.h"
#include "model/climbing_light.h"
#include "model/climbing_rng.h"
#include "model/climbing_tropism.h"
#include "measurements/support_mesh.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "climbing_same_state.h"
#include "climbing_bushy_plant.h"

static const double PI = 3.14159265358979323846;

static phc_climbing *grow(const phc_climbing_options *o, const double base[3],
                          const double dir[3], size_t steps, double dt)
{
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, dir, o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return NULL;
    }
    for (size_t k = 0; k < steps; ++k)
        if (phc_climbing_step(c, dt, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return NULL;
        }
    return c;
}

static size_t apical_tip(const phc_climbing *c)
{
    for (size_t i = phc_climbing_count(c); i-- > 0;)
        if (phc_climbing_is_apical(c, i))
            return i;
    return PHC_CLIMBING_NONE;
}

/* An axis-aligned box [-0.05, 0.05] x [-0.05, 0.05] x [-1, 0.2] m as a
 * support: the exact closest point on its surface and the outward normal
 * of the face it lies on (outside: the clamped point; inside: the nearest
 * face). */
static int box_closest(void *user, const double x[3], double c[3], double n[3])
{
    (void)user;
    const double lo[3] = {-0.05, -0.05, -1}, hi[3] = {0.05, 0.05, 0.2};
    int inside = 1;
    for (int k = 0; k < 3; ++k) {
        c[k] = fmin(hi[k], fmax(lo[k], x[k]));
        inside &= x[k] > lo[k] && x[k] < hi[k];
    }
    double best = INFINITY;
    int bk = 2, side = 1;
    for (int k = 0; k < 3; ++k) /* the face nearest to c */
        for (int sd = -1; sd <= 1; sd += 2) {
            const double d = sd > 0 ? hi[k] - c[k] : c[k] - lo[k];
            if (d < best) {
                best = d;
                bk = k;
                side = sd;
            }
        }
    if (inside)
        c[bk] = side > 0 ? hi[bk] : lo[bk];
    n[0] = n[1] = n[2] = 0;
    n[bk] = side;
    return 0;
}

/* Smallest signed distance minus radius to the box of any segment end and
 * of any centre of plant c (seed excluded), folded into *ends_min and
 * *centre_min. */
static void box_depths(const phc_climbing *c, double *ends_min, double *centre_min)
{
    for (size_t i = 1; i < phc_climbing_count(c); ++i) {
        double pts[9];
        phc_climbing_segment(c, i, pts, pts + 3);
        phc_climbing_position(c, i, pts + 6);
        for (int j = 0; j < 3; ++j) {
            double cp[3], nf[3];
            const double *x = pts + 3 * j;
            box_closest(NULL, x, cp, nf);
            const double e[3] = {x[0] - cp[0], x[1] - cp[1], x[2] - cp[2]};
            const double dist = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            const double delta =
                (e[0] * nf[0] + e[1] * nf[1] + e[2] * nf[2] >= 0 ? dist : -dist) - phc_climbing_radius(c, i);
            if (j < 2)
                *ends_min = fmin(*ends_min, delta);
            else
                *centre_min = fmin(*centre_min, delta);
        }
    }
}

/* The shoot of the collision tests: no laterals, r = 3 mm, surface
 * adaption toward the box, collisions on or off; with dynamics 10
 * substeps, t_m = 20 s, s_min = 0.3. */
static phc_climbing_options box_shoot_options(int collide, int dynamics)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.branch_probability = 0;
    o.growth_rate = 0.2;
    o.radius = 0.003;
    o.surface_adaption = 0.5;
    o.closest = box_closest;
    o.collide = collide;
    if (dynamics) {
        o.dynamics_substeps = 10;
        o.particles.maturity_age = 20;
        o.min_stiffness = 0.3;
    }
    return o;
}

int main(void)
{
    const double origin[3] = {0, 0, 0}, up[3] = {0, 0, 1}, east[3] = {1, 0, 0};
    phc_error err;

    /* 1. determinism */
    {
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 0.5;
        o.max_buds = 2;
        o.seed = 42;
        phc_climbing *a = grow(&o, origin, up, 300, 0.5);
        phc_climbing *b = grow(&o, origin, up, 300, 0.5);
        o.seed = 43;
        phc_climbing *c = grow(&o, origin, up, 300, 0.5);
        CHECK(a && b && c);
        const size_t n = phc_climbing_count(a);
        int same = n == phc_climbing_count(b), differ = n != phc_climbing_count(c);
        for (size_t i = 0; same && i < n; ++i) {
            double x[3], y[3];
            phc_climbing_position(a, i, x);
            phc_climbing_position(b, i, y);
            same = memcmp(x, y, sizeof x) == 0 && phc_climbing_parent(a, i) == phc_climbing_parent(b, i);
        }
        for (size_t i = 0; !differ && i < n; ++i) {
            double x[3], y[3];
            phc_climbing_position(a, i, x);
            phc_climbing_position(c, i, y);
            differ = memcmp(x, y, sizeof x) != 0;
        }
        printf("determinism: seed 42 twice: %zu and %zu particles, identical: %d; seed 43: %zu "
               "particles, differs: %d\n",
               n, phc_climbing_count(b), same, phc_climbing_count(c), differ);
        CHECK(same);
        CHECK(differ);
        phc_climbing_free(a);
        phc_climbing_free(b);
        phc_climbing_free(c);
    }

    /* 1b. the same plant on 1 and 2 threads */
    {
        phc_climbing_options o = climbing_bushy_options(3);
        o.max_particles = 20000;
        climbing_floor_scene(&o);
        o.light.direction[0] = 1; /* from the side: the flat plant shades itself */
        o.light.direction[2] = 0;
        o.leaf_step = 3;
        const double seed[3] = {0, 0, 0.01};
        const int keep = omp_get_max_threads();
        double *state[2] = {NULL, NULL};
        size_t ns[2] = {0, 0}, steps[2] = {0, 0}, leaves[2] = {0, 0};
        for (int run = 0; run < 2; ++run) {
            omp_set_num_threads(run + 1);
            phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
            CHECK(c != NULL);
            if (!c)
                break;
            /* up to the cap, then 4 steps more (tips still turn, anchors form) */
            size_t after = 0;
            while (after < 4 && steps[run] < 400) {
                if (phc_climbing_step(c, 0.25, &err))
                    break;
                ++steps[run];
                after += phc_climbing_count(c) >= o.max_particles;
            }
            ns[run] = phc_climbing_count(c);
            state[run] = malloc(16 * ns[run] * sizeof(double));
            for (size_t i = 0; state[run] && i < ns[run]; ++i) {
                double *s = state[run] + 16 * i;
                phc_climbing_position(c, i, s);
                phc_climbing_direction(c, i, s + 3);
                s[6] = phc_climbing_light_at(c, i);
                for (int k = 7; k < 16; ++k)
                    s[k] = -1;
                phc_climbing_anchor(c, i, s + 7);
                phc_climbing_leaf(c, i, s + 10, s + 13, NULL);
            }
            leaves[run] = phc_climbing_leaf_count(c);
            phc_climbing_free(c);
        }
        omp_set_num_threads(keep);
        size_t differ = 0, anchored = 0;
        double darkest = 1;
        CHECK(ns[0] == ns[1] && ns[0] == o.max_particles && steps[0] == steps[1]);
        CHECK(leaves[0] == leaves[1]);
        if (state[0] && state[1] && ns[0] == ns[1])
            for (size_t k = 0; k < 16 * ns[0]; ++k) {
                differ += memcmp(state[0] + k, state[1] + k, sizeof(double)) != 0;
                if (k % 16 == 6)
                    darkest = fmin(darkest, state[0][k]);
                anchored += k % 16 == 7 && state[0][k] != -1;
            }
        printf("threads: bushy plant on a floor, %zu particles, %zu leaves after %zu steps; 1 vs 2 "
               "threads: %zu of %zu numbers differ; smallest light %.4f, %zu anchored\n",
               ns[0], leaves[0], steps[0], differ, 16 * ns[0], darkest, anchored);
        CHECK(differ == 0);
        CHECK(darkest < 0.9);
        CHECK(anchored > 0);
        CHECK(leaves[0] > 0);
        free(state[0]);
        free(state[1]);
    }

    /* 2. exact particle count of one apical shoot */
    {
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 0;
        o.growth_rate = 0.2;
        o.bud_fraction = 0.25;
        const double dt = 0.1;
        phc_climbing *c = phc_climbing_new(origin, east, &o, &err);
        CHECK(c != NULL);
        size_t wrong = 0;
        double worst_len = 0, worst_line = 0;
        for (size_t k = 1; k <= 400; ++k) {
            phc_climbing_step(c, dt, &err);
            /* r Δt / (1 − σ₀) = 0.02 / 0.75: a successor every 37.5 steps */
            const size_t expect = 1 + (size_t)floor(0.2 * (double)k * dt / 0.75);
            if (phc_climbing_count(c) != expect)
                ++wrong;
            double total = 0;
            for (size_t i = 0; i < phc_climbing_count(c); ++i)
                total += phc_climbing_length(c, i);
            /* every particle starts at sigma0 and the growth r t is shared out */
            const double n = (double)phc_climbing_count(c);
            worst_len = fmax(worst_len, fabs(total - o.max_length * (0.25 * n + 0.2 * (double)k * dt)));
            double base[3], tip[3];
            phc_climbing_segment(c, phc_climbing_count(c) - 1, base, tip);
            worst_line = fmax(worst_line, fmax(fabs(tip[0] - total), fmax(fabs(tip[1]), fabs(tip[2]))));
        }
        printf("apical growth: %zu particles after 40 s (expected 1 + floor(0.2*40/0.75) = 11), "
               "steps with a wrong count: %zu of 400, max |total length - L_max(n s0 + r t)| = %.3g m, "
               "max tip off the line = %.3g m\n",
               phc_climbing_count(c), wrong, worst_len, worst_line);
        CHECK(phc_climbing_count(c) == 11);
        CHECK(wrong == 0);
        CHECK(worst_len < 1e-12);
        CHECK(worst_line < 1e-12);
        phc_climbing_free(c);
    }

    /* 3. branching frequency */
    {
        const double bps[5] = {0, 0.1, 0.3, 0.7, 1};
        for (int b = 0; b < 5; ++b) {
            size_t trials = 0, laterals = 0, nodes_ok = 1;
            for (unsigned seed = 1; seed <= 300; ++seed) {
                phc_climbing_options o = phc_climbing_options_default();
                o.branch_probability = bps[b];
                o.max_buds = 2;
                o.max_order = 1;
                o.seed = seed;
                o.max_particles = 200;
                phc_climbing *c = grow(&o, origin, up, 60, 0.5);
                if (!c) {
                    CHECK(c != NULL);
                    break;
                }
                phc_climbing_stats s;
                phc_climbing_get_stats(c, &s);
                trials += s.bud_trials;
                laterals += s.laterals;
                /* laterals counted by the model = lateral particles present */
                size_t lat = 0;
                for (size_t i = 0; i < phc_climbing_count(c); ++i)
                    lat += (size_t)phc_climbing_is_lateral(c, i);
                nodes_ok &= lat == s.laterals;
                phc_climbing_free(c);
            }
            const double p = bps[b], mean = p * (double)trials;
            const double sd = sqrt((double)trials * p * (1 - p));
            printf("branching BP = %.1f: %zu laterals of %zu buds (expected %.1f +- %.1f, z = %.2f)\n",
                   p, laterals, trials, mean, sd, sd > 0 ? ((double)laterals - mean) / sd : 0.0);
            CHECK(trials > 1000);
            CHECK(fabs((double)laterals - mean) <= 4 * sd);
            CHECK(nodes_ok);
        }
    }

    /* 4. direction variance and thickness */
    {
        const double vs[3] = {0, 0.3, 1};
        for (int v = 0; v < 3; ++v) {
            double largest = 0, worst_thick = 0;
            size_t count = 0;
            for (unsigned seed = 1; seed <= 40; ++seed) {
                phc_climbing_options o = phc_climbing_options_default();
                o.branch_probability = 0.5;
                o.max_buds = 2;
                o.direction_variance = vs[v];
                o.thickness_falloff = 0.6;
                o.seed = seed;
                o.max_particles = 300;
                phc_climbing *c = grow(&o, origin, up, 60, 0.5);
                CHECK(c != NULL);
                if (!c)
                    break;
                for (size_t i = 0; i < phc_climbing_count(c); ++i) {
                    if (!phc_climbing_is_lateral(c, i))
                        continue;
                    const size_t p = phc_climbing_parent(c, i);
                    double di[3], dp[3];
                    phc_climbing_direction(c, i, di);
                    phc_climbing_direction(c, p, dp);
                    largest = fmax(largest, phc_climbing_angle(di, dp));
                    worst_thick = fmax(worst_thick, fabs(phc_climbing_radius(c, i) -
                                                         0.6 * phc_climbing_radius(c, p)));
                    ++count;
                }
                phc_climbing_free(c);
            }
            const double bound = vs[v] * 0.5 * PI;
            printf("direction variance V = %.1f: %zu laterals, largest angle to the parent %.4f "
                   "deg (bound %.1f deg); max |t_c - 0.6 t_p| = %.3g m\n",
                   vs[v], count, largest * 180 / PI, bound * 180 / PI, worst_thick);
            CHECK(count > 100);
            CHECK(largest <= bound + 1e-12);
            if (vs[v] > 0)
                CHECK(largest >= 0.95 * bound);
            CHECK(worst_thick <= 1e-18);
        }
    }

    /* 5. phototropism */
    {
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 0;
        o.phototropism = 0.5;
        const double dt = 0.1;
        phc_climbing *c = phc_climbing_new(origin, east, &o, &err);
        CHECK(c != NULL);
        double prev = PI / 2, worst = 0;
        int monotone = 1;
        for (int k = 1; k <= 100; ++k) {
            phc_climbing_step(c, dt, &err);
            double d[3];
            phc_climbing_direction(c, apical_tip(c), d);
            const double th = phc_climbing_angle(d, up);
            monotone &= th < prev;
            prev = th;
            const double expect = 0.5 * PI * pow(1 - 0.5 * dt, k);
            worst = fmax(worst, fabs(th - expect) / expect);
        }
        printf("phototropism eta = 0.5/s: tip angle to the light after 10 s %.6f rad "
               "(theta0 (1 - eta dt)^100 = %.6f), falls at every step: %d, max relative "
               "error %.3g\n",
               prev, 0.5 * PI * pow(0.95, 100), monotone, worst);
        CHECK(monotone);
        CHECK(worst < 1e-12);
        /* the rest shape is bent too (eqs. 8-10): rest = current, kinematic */
        double d[3], dr[3];
        phc_climbing_direction(c, apical_tip(c), d);
        phc_climbing_rest_direction(c, apical_tip(c), dr);
        CHECK(phc_climbing_angle(d, dr) < 1e-12);
        phc_climbing_free(c);
    }

    /* 6. surface adaption and anchors on a plane support */
    {
        const double V[12] = {-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0};
        const size_t F[6] = {0, 1, 2, 0, 2, 3};
        phc_support_mesh *m = phc_support_mesh_from_arrays(V, 4, F, 2, "plane", &err);
        CHECK(m != NULL);
        const double seed[3] = {0, 0, 0.05};
        for (int on = 0; on < 2; ++on) {
            phc_climbing_options o = phc_climbing_options_default();
            o.branch_probability = 0;
            o.surface_adaption = on ? 0.5 : 0;
            o.closest = phc_support_mesh_closest;
            o.closest_user = m;
            phc_climbing *c = phc_climbing_new(seed, east, &o, &err);
            CHECK(c != NULL);
            if (!c)
                continue;
            /* eq. 5 strength k_max sigma min(1, (t - t_made)/t_a), checked at
               every step against the time the test saw each anchor appear */
            double made_at[64], worst_k = 0;
            for (size_t i = 0; i < 64; ++i)
                made_at[i] = -1;
            for (int k = 1; k <= 600; ++k) {
                phc_climbing_step(c, 0.2, &err);
                const double t = 0.2 * k;
                for (size_t i = 0; i < phc_climbing_count(c) && i < 64; ++i) {
                    double a[3];
                    if (!phc_climbing_anchor(c, i, a))
                        continue;
                    if (made_at[i] < 0)
                        made_at[i] = t;
                    const double expect = o.anchor_strength * phc_climbing_size(c, i) *
                                          fmin(1, (t - made_at[i]) / o.anchor_time);
                    worst_k = fmax(worst_k, fabs(phc_climbing_anchor_strength(c, i) - expect));
                }
            }
            if (on) {
                printf("anchor strength: max |k - k_max sigma min(1, age/t_a)| over the run = %.3g\n",
                       worst_k);
                CHECK(worst_k < 1e-12);
            }
            double base[3], tip[3], lowest = 1;
            phc_climbing_segment(c, apical_tip(c), base, tip);
            for (size_t i = 0; i < phc_climbing_count(c); ++i) {
                double x[3];
                phc_climbing_position(c, i, x);
                lowest = fmin(lowest, x[2]);
            }
            phc_climbing_stats s;
            phc_climbing_get_stats(c, &s);
            size_t far = 0;
            for (size_t i = 0; i < phc_climbing_count(c); ++i) {
                double a[3], x[3];
                if (phc_climbing_anchor(c, i, a)) {
                    phc_climbing_position(c, i, x);
                    far += hypot(hypot(x[0] - a[0], x[1] - a[1]), x[2] - a[2]) > o.release_distance;
                }
            }
            printf("surface adaption tau = %.1f/s: %zu particles, tip height %.5f m, lowest "
                   "centre %.5f m, anchored %zu (made %zu), anchored beyond the release distance: %zu\n",
                   o.surface_adaption, s.particles, tip[2], lowest, s.anchored, s.anchors_made, far);
            if (on) {
                CHECK(tip[2] <= o.contact_distance + 1e-12);
                CHECK(lowest >= -1e-12); /* never through the support */
                CHECK(s.anchored >= 5);
                CHECK(far == 0);
                /* the tip crawls along the plane: direction nearly level */
                double d[3];
                phc_climbing_direction(c, apical_tip(c), d);
                CHECK(fabs(d[2]) < 0.05);
            } else {
                CHECK_NEAR(tip[2], 0.05, 1e-12, 0);
                CHECK(s.anchored == 0);
            }
            phc_climbing_free(c);
        }
        phc_support_mesh_free(m);
    }

    /* 6b. release: a shoot anchored on a floor without gravity, then the
       scene turned upside down (gravity +z): weak anchors let go beyond
       the release distance, strong ones hold.  Without the joint
       pass (particles.follow_parent = 0: the paper's shape matching alone,
       which yields under the load): with it the shoot held at its clamped
       seed particle keeps its shape and hardly pulls on its anchors */
    {
        const double V[12] = {-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0};
        const size_t F[6] = {0, 1, 2, 0, 2, 3};
        phc_support_mesh *m = phc_support_mesh_from_arrays(V, 4, F, 2, "floor", &err);
        const double seed[3] = {0, 0, 0.003}, flip[3] = {0, 0, 9.81};
        const double strengths[2] = {0.01, 1};
        size_t released[2] = {0, 0}, held[2] = {0, 0}, beyond[2] = {0, 0};
        for (int w = 0; w < 2; ++w) {
            phc_climbing_options o = phc_climbing_options_default();
            o.branch_probability = 0;
            o.growth_rate = 0.2;
            o.surface_adaption = 0.5;
            o.closest = phc_support_mesh_closest;
            o.closest_user = m;
            o.dynamics_substeps = 20;
            o.particles.maturity_age = 5;
            o.particles.follow_parent = 0;
            o.min_stiffness = 0.3;
            o.particles.gravity[2] = 0;
            o.anchor_strength = strengths[w];
            o.anchor_time = 1;
            phc_climbing *c = phc_climbing_new(seed, east, &o, &err);
            CHECK(c != NULL);
            if (!c)
                continue;
            size_t before = 0;
            for (int k = 0; k < 300; ++k) {
                if (k == 200) {
                    phc_climbing_stats s;
                    phc_climbing_get_stats(c, &s);
                    before = s.anchored;
                    CHECK(phc_climbing_set_gravity(c, flip, &err) == 0);
                }
                CHECK(phc_climbing_step(c, 0.2, &err) == 0);
            }
            phc_climbing_stats s;
            phc_climbing_get_stats(c, &s);
            released[w] = s.anchors_released;
            held[w] = s.anchored;
            /* no particle still anchored lies beyond the release distance */
            for (size_t i = 0; i < phc_climbing_count(c); ++i) {
                double a[3], x[3];
                if (phc_climbing_anchor(c, i, a)) {
                    phc_climbing_position(c, i, x);
                    beyond[w] += hypot(hypot(x[0] - a[0], x[1] - a[1]), x[2] - a[2]) > o.release_distance;
                }
            }
            printf("upside down, k_max = %.2f: %zu anchors before the flip, %zu released, %zu held, "
                   "held beyond the release distance: %zu\n",
                   strengths[w], before, released[w], held[w], beyond[w]);
            CHECK(before >= 8);
            CHECK(beyond[w] == 0);
            phc_climbing_free(c);
        }
        CHECK(released[0] >= 8); /* weak: all but the clamped seed particle let go */
        CHECK(released[1] == 0);
        phc_support_mesh_free(m);
        const double bad[3] = {0, NAN, 0};
        phc_climbing *c = phc_climbing_new(seed, east, NULL, &err);
        CHECK(phc_climbing_set_gravity(c, bad, &err) != 0);
        CHECK_STR_CONTAINS(err.message, "gravity y is not finite");
        phc_climbing_free(c);
    }

    /* 7. light */
    {
        phc_climbing_light_grid g;
        memset(&g, 0, sizeof g);
        g.cell = 1;
        g.dims[0] = g.dims[1] = 1;
        g.dims[2] = 3;
        g.extinction = 2;
        g.direction[2] = 1;
        const double x[6] = {0.5, 0.5, 0.5, 0.5, 0.5, 2.5};
        const double vol[2] = {0.5, 0.2};
        double phi[3], light[2];
        phc_climbing_light(&g, x, vol, 2, phi, light);
        printf("light grid 1x1x3: I(bottom) = %.15f (exp(-2*0.2) = %.15f), I(top) = %g\n",
               light[0], exp(-0.4), light[1]);
        CHECK_NEAR(light[0], exp(-0.4), 1e-15, 0);
        CHECK(light[1] == 1);

        /* a vine hanging from z = 0.95 m into its own shade, light from above */
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 0;
        o.radius = 0.01;
        o.light.origin[0] = o.light.origin[1] = -0.05;
        o.light.cell = 0.1;
        o.light.dims[0] = o.light.dims[1] = 1;
        o.light.dims[2] = 10;
        o.light.extinction = 200;
        const double top[3] = {0, 0, 0.95}, down[3] = {0, 0, -1};
        phc_climbing *c = grow(&o, top, down, 400, 0.2);
        CHECK(c != NULL);
        /* the light of the last step, from the seed down (the newest
           particle, spawned in that step, has not been lit yet) */
        int monotone = 1;
        const size_t n = phc_climbing_count(c);
        for (size_t i = 1; i + 1 < n; ++i)
            monotone &= phc_climbing_light_at(c, i) <= phc_climbing_light_at(c, i - 1);
        printf("hanging vine, self-shaded: %zu particles, I(seed) = %.4f, I(lowest lit) = %.4f, "
               "falls downward: %d\n",
               n, phc_climbing_light_at(c, 0), phc_climbing_light_at(c, n - 2), monotone);
        CHECK(monotone);
        CHECK(phc_climbing_light_at(c, 0) == 1); /* nothing above its cell */
        CHECK(phc_climbing_light_at(c, n - 2) < 0.9);
        /* shading slows growth: fewer particles than in full light */
        o.light.extinction = 0;
        phc_climbing *full = grow(&o, top, down, 400, 0.2);
        printf("  the same vine in full light: %zu particles\n", phc_climbing_count(full));
        CHECK(phc_climbing_count(full) > n);
        phc_climbing_free(c);
        phc_climbing_free(full);
    }

    /* 8. dynamics */
    {
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 0;
        o.growth_rate = 0.2;
        o.dynamics_substeps = 20; /* 0.01 s dynamics steps */
        o.particles.maturity_age = 5;
        o.min_stiffness = 0.3;
        const double seed[3] = {0, 0, 1};
        phc_climbing *c = grow(&o, seed, east, 100, 0.2);
        CHECK(c != NULL);
        if (c) {
            const size_t t = phc_climbing_count(c) - 1;
            double x[3], xr[3], x0[3], x0r[3];
            phc_climbing_position(c, t, x);
            phc_climbing_rest_position(c, t, xr);
            phc_climbing_position(c, 0, x0);
            phc_climbing_rest_position(c, 0, x0r);
            printf("dynamics: %zu particles, tip centre z = %.5f m against rest %.5f m; seed "
                   "particle moved %.3g m\n",
                   t + 1, x[2], xr[2], fabs(x0[2] - x0r[2]) + fabs(x0[0] - x0r[0]));
            /* links stretch little: centre spacing against rest spacing */
            double worst = 0;
            for (size_t i = 1; i <= t; ++i) {
                double a[3], b[3], ar[3], br[3];
                phc_climbing_position(c, i, a);
                phc_climbing_position(c, i - 1, b);
                phc_climbing_rest_position(c, i, ar);
                phc_climbing_rest_position(c, i - 1, br);
                const double d = hypot(hypot(a[0] - b[0], a[1] - b[1]), a[2] - b[2]);
                const double dr = hypot(hypot(ar[0] - br[0], ar[1] - br[1]), ar[2] - br[2]);
                worst = fmax(worst, d / dr);
            }
            printf("  largest centre spacing / rest spacing: %.3f\n", worst);
            CHECK(worst < 1.25);
            CHECK(x[2] < xr[2] - 1e-4);
            CHECK(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]));
            CHECK(fabs(x0[2] - x0r[2]) + fabs(x0[0] - x0r[0]) < 1e-12);
        }
        phc_climbing_free(c);
    }

    /* 8b. apical dominance: a tip of order k grows at r·a^k (full light).
     * Over each step, per order k: Σσ_k grows by r·a^k·Δt per tip of
     * order k, plus σ₀ per particle born (successors carry the excess). */
    {
        phc_climbing_options o = phc_climbing_options_default();
        o.seed = 5;
        o.growth_rate = 0.2;
        o.branch_probability = 1;
        o.max_buds = 1;
        o.max_order = 2;
        o.apical_dominance = 0.5;
        phc_climbing *c = phc_climbing_new(origin, up, &o, &err);
        CHECK(c != NULL);
        const double dt = 0.25;
        double worst = 0, len[3] = {0, 0, 0};
        for (int k = 0; c && k < 200; ++k) {
            double sum0[3] = {0, 0, 0};
            size_t tips[3] = {0, 0, 0}, n0[3] = {0, 0, 0}, n1[3] = {0, 0, 0};
            const size_t n = phc_climbing_count(c);
            for (size_t i = 0; i < n; ++i) {
                const unsigned ord = phc_climbing_order(c, i);
                sum0[ord] += phc_climbing_size(c, i);
                n0[ord]++;
                tips[ord] += (size_t)phc_climbing_is_apical(c, i);
            }
            CHECK(phc_climbing_step(c, dt, &err) == 0);
            double sum1[3] = {0, 0, 0};
            for (size_t i = 0; i < phc_climbing_count(c); ++i) {
                sum1[phc_climbing_order(c, i)] += phc_climbing_size(c, i);
                n1[phc_climbing_order(c, i)]++;
            }
            for (int ord = 0; ord < 3; ++ord) {
                const double want = o.growth_rate * pow(o.apical_dominance, ord) * dt * (double)tips[ord] +
                                    o.bud_fraction * (double)(n1[ord] - n0[ord]);
                worst = fmax(worst, fabs(sum1[ord] - sum0[ord] - want));
            }
        }
        for (size_t i = 0; c && i < phc_climbing_count(c); ++i)
            len[phc_climbing_order(c, i)] += phc_climbing_length(c, i);
        size_t shoots[3] = {1, 0, 0};
        for (size_t i = 0; c && i < phc_climbing_count(c); ++i)
            shoots[phc_climbing_order(c, i)] += (size_t)phc_climbing_is_lateral(c, i);
        printf("apical dominance a = 0.5: max |step growth of sum sigma per order - (r a^k dt tips + s0 born)| "
               "= %.1e (bound 1e-12); mean shoot length by order 0, 1, 2: %.3f, %.3f, %.3f m\n",
               worst, len[0] / (double)shoots[0], shoots[1] ? len[1] / (double)shoots[1] : 0.0,
               shoots[2] ? len[2] / (double)shoots[2] : 0.0);
        CHECK(worst < 1e-12);
        CHECK(shoots[1] > 0 && shoots[2] > 0);
        CHECK(len[0] / (double)shoots[0] > len[1] / (double)shoots[1]);
        CHECK(len[1] / (double)shoots[1] > len[2] / (double)shoots[2]);
        phc_climbing_free(c);
    }

    /* 9. bad options */
    {
        /* the plant's generator: xoshiro256** seeded by splitmix64, against
           an independent Python transcription of the published algorithms */
        phc_climbing_rng r;
        phc_climbing_rng_seed(&r, 42);
        const uint64_t expect[5] = {0x15780b2e0c2ec716ULL, 0x6104d9866d113a7eULL,
                                    0xae17533239e499a1ULL, 0xecb8ad4703b360a1ULL,
                                    0xfde6dc7fe2ec5e64ULL};
        int same = 1;
        for (int k = 0; k < 5; ++k)
            same &= phc_climbing_rng_next(&r) == expect[k];
        printf("xoshiro256** seed 42: first five outputs as the reference: %d\n", same);
        CHECK(same);
        /* a seed below a floor whose normal points up */
        const double V[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
        const size_t F[6] = {0, 1, 2, 0, 2, 3};
        phc_support_mesh *m = phc_support_mesh_from_arrays(V, 4, F, 2, "floor", &err);
        phc_climbing_options so = phc_climbing_options_default();
        so.closest = phc_support_mesh_closest;
        so.closest_user = m;
        const double under[3] = {0.1, 0.2, -0.01}, over[3] = {0.1, 0.2, 0.01};
        CHECK(phc_climbing_new(under, up, &so, &err) == NULL);
        printf("seed under the floor: %s\n", err.message);
        CHECK_STR_CONTAINS(err.message, "climbing: the seed (0.1, 0.2, -0.01) m lies behind the support face");
        phc_climbing *ok = phc_climbing_new(over, up, &so, &err);
        CHECK(ok != NULL);
        phc_climbing_free(ok);
        phc_support_mesh_free(m);
    }
    {
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 1.5;
        CHECK(phc_climbing_new(origin, up, &o, &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "climbing: branch_probability = 1.5 is outside [0, 1]");
        o = phc_climbing_options_default();
        o.direction_variance = 1.2;
        CHECK(phc_climbing_new(origin, up, &o, &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "direction_variance = 1.2");
        o = phc_climbing_options_default();
        const double zero[3] = {0, 0, 0};
        CHECK(phc_climbing_new(origin, zero, &o, &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "seed direction");
        phc_climbing *c = phc_climbing_new(origin, up, &o, &err);
        CHECK(phc_climbing_step(c, 10, &err) != 0); /* r dt = 1 > 1 - sigma0 */
        CHECK_STR_CONTAINS(err.message, "growth_rate * dt");
        phc_climbing_free(c);
    }
    /* 8b. One particle system kept across the steps (model/particles.h
       grown in place): a branching plant of > 1024 particles (the
       particles' group loops then run in parallel), grown kinematically,
       then 6 dynamic steps; 1 and 2 OpenMP threads, and the same seed
       twice, give the same plant bit for bit. */
    {
        phc_climbing_options o = climbing_bushy_options(5);
        o.particles.maturity_age = 20;
        o.min_stiffness = 0.3;
        const double seed[3] = {0, 0, 0.01}, up[3] = {0, 0, 1};
        const int keep = omp_get_max_threads();
        double *xs[3] = {NULL, NULL, NULL};
        size_t ns[3] = {0, 0, 0};
        for (int run = 0; run < 3; ++run) {
            omp_set_num_threads(run == 1 ? 2 : 1);
            phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
            CHECK(c != NULL);
            if (!c)
                break;
            while (phc_climbing_count(c) < 1100)
                if (phc_climbing_step(c, 0.25, &err))
                    break;
            CHECK(phc_climbing_set_dynamics_substeps(c, 2, &err) == 0);
            for (int k = 0; k < 6; ++k)
                CHECK(phc_climbing_step(c, 0.25, &err) == 0);
            ns[run] = phc_climbing_count(c);
            xs[run] = malloc(6 * ns[run] * sizeof(double));
            for (size_t i = 0; xs[run] && i < ns[run]; ++i) {
                phc_climbing_position(c, i, xs[run] + 6 * i);
                phc_climbing_direction(c, i, xs[run] + 6 * i + 3);
            }
            phc_climbing_free(c);
        }
        omp_set_num_threads(keep);
        size_t differ_threads = 0, differ_again = 0;
        CHECK(ns[0] == ns[1] && ns[0] == ns[2] && ns[0] >= 1100);
        if (xs[0] && xs[1] && xs[2] && ns[0] == ns[1] && ns[0] == ns[2])
            for (size_t k = 0; k < 6 * ns[0]; ++k) {
                differ_threads += xs[0][k] != xs[1][k];
                differ_again += xs[0][k] != xs[2][k];
            }
        printf("persistent dynamics: %zu particles after 6 dynamic steps; 1 vs 2 threads: %zu of "
               "%zu coordinates differ; the same seed again: %zu differ\n",
               ns[0], differ_threads, 6 * ns[0], differ_again);
        CHECK(differ_threads == 0);
        CHECK(differ_again == 0);
        for (int run = 0; run < 3; ++run)
            free(xs[run]);
    }

    /* 8c. Collisions with supports (option collide): a shoot grown up the
       side y = 0.05 of a box and over its top edge (z = 0.2), kinematic
       and with dynamics; with collisions no particle centre ends closer
       than its radius to the box (tolerance 1e-12 m), without them the
       internodes rounding the edge cut into it. */
    for (int dyn = 0; dyn < 2; ++dyn) {
        double worst[2] = {0, 0};
        size_t pushed_total[2] = {0, 0}, count_end[2] = {0, 0};
        for (int on = 0; on < 2; ++on) {
            phc_climbing_options o = box_shoot_options(on, dyn);
            const double seed[3] = {0, 0.055, 0.1}, up[3] = {0, 0, 1};
            phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
            CHECK(c != NULL);
            if (!c)
                continue;
            for (int k = 0; k < 120; ++k) {
                CHECK(phc_climbing_step(c, 0.25, &err) == 0);
                size_t pushed;
                phc_climbing_collisions(c, &pushed, NULL);
                pushed_total[on] += pushed;
            }
            /* the smallest δ − r over the particles at the end */
            double w = INFINITY;
            for (size_t i = 1; i < phc_climbing_count(c); ++i) {
                double x[3], cp[3], nf[3];
                phc_climbing_position(c, i, x);
                box_closest(NULL, x, cp, nf);
                const double e[3] = {x[0] - cp[0], x[1] - cp[1], x[2] - cp[2]};
                const double dist = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
                const double delta = e[0] * nf[0] + e[1] * nf[1] + e[2] * nf[2] >= 0 ? dist : -dist;
                w = fmin(w, delta - phc_climbing_radius(c, i));
            }
            worst[on] = w;
            count_end[on] = phc_climbing_count(c);
            double tipx[3];
            phc_climbing_position(c, phc_climbing_count(c) - 1, tipx);
            printf("collisions %s, %s: %zu particles, tip centre (%.3f, %.3f, %.3f) m, smallest "
                   "signed distance - radius %.3g m, pushes over the run %zu\n",
                   dyn ? "dynamic" : "kinematic", on ? "on" : "off", count_end[on], tipx[0],
                   tipx[1], tipx[2], w, pushed_total[on]);
            phc_climbing_free(c);
        }
        CHECK(worst[1] >= -1e-12);
        CHECK(worst[0] < -1e-4); /* without them a particle does cut in */
        CHECK(pushed_total[1] > 0 && pushed_total[0] == 0);
    }

    /* 8d. Whole segments (option collide_ends, kinematic): the same shoot
       over the box's edge; with the ends pushed out too, the smallest
       signed distance minus radius of any segment end (seed excluded)
       rises to >= -1e-9 m, against the centre push alone; the centres
       stay out (>= -1e-12 m). */
    {
        double ends_min[2] = {INFINITY, INFINITY}, centre_min[2] = {INFINITY, INFINITY};
        size_t count_end[2] = {0, 0};
        for (int ends = 0; ends < 2; ++ends) {
            phc_climbing_options o = box_shoot_options(1, 0);
            o.collide_ends = ends;
            const double seed[3] = {0, 0.055, 0.1}, up[3] = {0, 0, 1};
            phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
            CHECK(c != NULL);
            if (!c)
                continue;
            for (int k = 0; k < 120; ++k)
                CHECK(phc_climbing_step(c, 0.25, &err) == 0);
            count_end[ends] = phc_climbing_count(c);
            box_depths(c, &ends_min[ends], &centre_min[ends]);
            phc_climbing_free(c);
        }
        printf("collide_ends, kinematic: %zu / %zu particles; smallest signed distance - radius of a segment end: "
               "centres pushed %.3g m, centres and ends pushed %.3g m; of a centre: %.3g m, %.3g m\n",
               count_end[0], count_end[1], ends_min[0], ends_min[1], centre_min[0], centre_min[1]);
        CHECK(ends_min[0] < -1e-5); /* without: an end cuts in (21 µm here; 5 mm in Fig. 13) */
        CHECK(ends_min[1] >= -1e-9);
        CHECK(centre_min[0] >= -1e-12 && centre_min[1] >= -1e-12);
    }

    /* 8e. Whole segments inside the dynamics (option collide with
       dynamics: the collision pass pushes each particle's centre and its
       segment's two ends, model/particles.h): the shoot of 8c grown for
       120 s (33 particles) up the box's side, over its top edge and along
       its top.  After every growth step: the smallest signed distance
       minus radius of any segment end and of any centre (seed excluded);
       the largest centre speed between growth steps in the last 60 s (no
       explosion: it stays at the growth's own pace, mm/s).  Without
       collisions the ends cut into the box. */
    {
        double ends_min[2] = {INFINITY, INFINITY}, centre_min[2] = {INFINITY, INFINITY};
        double vmax_late[2] = {0, 0};
        size_t count_end[2] = {0, 0};
        for (int on = 0; on < 2; ++on) {
            phc_climbing_options o = box_shoot_options(on, 1);
            const double seed[3] = {0, 0.055, 0.1}, up[3] = {0, 0, 1};
            phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
            CHECK(c != NULL);
            if (!c)
                continue;
            double *prev = NULL;
            size_t nprev = 0;
            for (int k = 0; k < 480; ++k) {
                CHECK(phc_climbing_step(c, 0.25, &err) == 0);
                const size_t n = phc_climbing_count(c);
                box_depths(c, &ends_min[on], &centre_min[on]);
                for (size_t i = 1; k >= 240 && i < nprev; ++i) {
                    if (phc_climbing_is_apical(c, i))
                        continue;
                    double b[3];
                    const double *a = prev + 3 * i;
                    phc_climbing_position(c, i, b);
                    const double v = hypot(hypot(b[0] - a[0], b[1] - a[1]), b[2] - a[2]) / 0.25;
                    vmax_late[on] = fmax(vmax_late[on], v);
                }
                double *t = realloc(prev, 3 * n * sizeof *t);
                CHECK(t != NULL);
                if (!t)
                    break;
                prev = t;
                nprev = n;
                for (size_t i = 0; i < n; ++i)
                    phc_climbing_position(c, i, prev + 3 * i);
            }
            count_end[on] = phc_climbing_count(c);
            free(prev);
            phc_climbing_free(c);
        }
        printf("collisions of whole segments, dynamics, 120 s: off: %zu particles, smallest signed distance - "
               "radius over the run of an end %.3g m, of a centre %.3g m; on: %zu particles, %.3g m, %.3g m; "
               "largest speed of a grown centre in the last 60 s: off %.3g m/s, on %.3g m/s\n",
               count_end[0], ends_min[0], centre_min[0], count_end[1], ends_min[1], centre_min[1],
               vmax_late[0], vmax_late[1]);
        CHECK(ends_min[0] < -1e-4); /* without collisions the ends cut in */
        CHECK(ends_min[1] >= -1e-12 && centre_min[1] >= -1e-12);
        CHECK(vmax_late[1] < 0.01 && isfinite(vmax_late[1]));
    }

    /* 8f. The collision pass's skipped queries (model/particles.h
       phc_particles_collide_all): the shoot of 8e grown for 120 s with
       dynamics and collide three times: every query made; repeated points
       answered from memory; and with the box declared closed
       (supports_closed), points too far off it skipped too.  After every
       growth step the positions, segment ends, pushes and the smallest
       δ − r are the same bit for bit.  The query counts are printed; each
       memory must save some. */
    {
        enum { RUNS = 3 };
        phc_climbing *c2[RUNS];
        size_t queries[RUNS] = {0}, skipped[RUNS] = {0}, differ = 0, pushes = 0;
        for (int run = 0; run < RUNS; ++run) {
            phc_climbing_options o = box_shoot_options(1, 1);
            o.collide_all = run == 0;
            o.supports_closed = run == 2;
            const double seed[3] = {0, 0.055, 0.1}, up[3] = {0, 0, 1};
            c2[run] = phc_climbing_new(seed, up, &o, &err);
            CHECK(c2[run] != NULL);
        }
        for (int k = 0; c2[0] && c2[1] && c2[2] && k < 480; ++k) {
            for (int run = 0; run < RUNS; ++run)
                CHECK(phc_climbing_step(c2[run], 0.25, &err) == 0);
            size_t pushed;
            phc_climbing_collisions(c2[0], &pushed, NULL);
            pushes += pushed;
            for (int run = 1; run < RUNS; ++run)
                differ += climbing_state_differs(c2[0], c2[run]);
        }
        for (int run = 0; run < RUNS; ++run) {
            phc_climbing_collision_queries(c2[run], &queries[run], &skipped[run]);
            phc_climbing_free(c2[run]);
        }
        printf("collision queries, dynamics, 120 s: every query %zu made, %zu skipped; repeated points from memory "
               "%zu made, %zu skipped; closed box %zu made, %zu skipped; pushes %zu; growth steps or particles "
               "that differ: %zu\n",
               queries[0], skipped[0], queries[1], skipped[1], queries[2], skipped[2], pushes, differ);
        CHECK(differ == 0);
        CHECK(pushes > 0);
        CHECK(skipped[0] == 0 && queries[1] < queries[0] && queries[2] < queries[1]);
        CHECK(queries[1] + skipped[1] == queries[0]); /* (no skip by distance: one answer per point) */
    }

    return check_finish("test_climbing_growth");
}
