/* Unit test of phototropism toward where the light is
 * (model/climbing_light_field.h; Hädrich et al., CGF 36(2) 2017, §4.2,
 * eq. 7).  Every checked number is printed.
 *  1. Trilinear field: a field linear in x is reproduced exactly (value and
 *     gradient); on random node values the analytic gradient agrees with
 *     central differences at random points inside the nodes' hull.
 *  2. Limit case, no occluder: the field is 1 everywhere, its gradient 0
 *     exactly, the target is ℓ; a shoot grown with seek_light (a shadow
 *     triangle outside the grid, so the field is built every step) has the
 *     very directions of the fixed-direction model at every step.
 *  3. A shoot under an opaque plate with a gap, light from above: with
 *     seek_light it turns toward the gap and crosses the plate's plane in
 *     it; with the fixed direction it grows straight into the plate.
 *  4. The field at the nodes read at some sites only
 *     (phc_climbing_light_field_update_near, what a growth step uses):
 *     under the plate with 400 shading points (extinction 30 m⁻¹), oblique
 *     light and a spread of 20°, those nodes equal the full update's bit
 *     for bit, every other node is NAN, and the value and gradient at each
 *     site are the full field's exactly; with extinction 0 too. */
#include "model/climbing_growth.h"
#include "model/climbing_light.h"
#include "model/climbing_light_field.h"
#include "model/climbing_rng.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static size_t apical_tip(const phc_climbing *c)
{
    for (size_t i = phc_climbing_count(c); i-- > 0;)
        if (phc_climbing_is_apical(c, i))
            return i;
    return PHC_CLIMBING_NONE;
}

/* The plate z = 0.4 m over x in [-0.6, 0.6], y in [-0.4, 0.4], with the gap
 * x in [0.2, 0.3]: two rectangles, four triangles. */
static const double PLATE_V[8 * 3] = {-0.6, -0.4, 0.4, 0.2, -0.4, 0.4, 0.2, 0.4, 0.4, -0.6, 0.4, 0.4,
                                      0.3,  -0.4, 0.4, 0.6, -0.4, 0.4, 0.6, 0.4, 0.4, 0.3,  0.4, 0.4};
static const size_t PLATE_T[4 * 3] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};

typedef struct run_result {
    double cross_x;    /* x where the tip first reached z = 0.4 m (NAN: never) */
    double gap_dist;   /* tip's final distance to the gap centre, m */
    double final_tip[3];
    size_t particles;
} run_result;

static int run_plate(int seek, run_result *r)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.branch_probability = 0;
    o.growth_rate = 0.5;
    o.phototropism = 0.2;
    o.seek_light = seek;
    o.light.cell = 0.05;
    o.light.origin[0] = -0.45;
    o.light.origin[1] = -0.3;
    o.light.origin[2] = -0.05;
    o.light.dims[0] = 19;
    o.light.dims[1] = 12;
    o.light.dims[2] = 11;
    o.light.ambient = 0.5;
    const double seed[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    phc_error err;
    phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
    if (!c || phc_climbing_set_shadow_triangles(c, PLATE_V, 8, PLATE_T, 4, &err)) {
        fprintf(stderr, "%s\n", err.message);
        phc_climbing_free(c);
        return -1;
    }
    r->cross_x = NAN;
    double tip[3] = {0, 0, 0};
    for (int k = 0; k < 1500; ++k) {
        if (phc_climbing_step(c, 0.1, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return -1;
        }
        double base[3];
        phc_climbing_segment(c, apical_tip(c), base, tip);
        if (isnan(r->cross_x) && tip[2] >= 0.4)
            r->cross_x = tip[0];
    }
    const double gap[3] = {0.25, 0, 0.4};
    r->gap_dist = sqrt((tip[0] - gap[0]) * (tip[0] - gap[0]) + (tip[1] - gap[1]) * (tip[1] - gap[1]) +
                       (tip[2] - gap[2]) * (tip[2] - gap[2]));
    memcpy(r->final_tip, tip, sizeof tip);
    r->particles = phc_climbing_count(c);
    phc_climbing_free(c);
    return 0;
}

int main(void)
{
    /* 1. the trilinear field and its gradient */
    {
        phc_climbing_light_grid g;
        memset(&g, 0, sizeof g);
        g.cell = 0.1;
        g.origin[0] = -0.2;
        g.origin[1] = 0.1;
        g.origin[2] = 0.3;
        g.dims[0] = 6;
        g.dims[1] = 5;
        g.dims[2] = 4;
        g.direction[2] = 1;
        phc_climbing_light_field f;
        CHECK(phc_climbing_light_field_init(&f, &g, 0) == 0);
        /* linear: F = 0.3 + 0.5 x - 0.25 y + 0.75 z at the cell centres */
        const double a[4] = {0.3, 0.5, -0.25, 0.75};
        for (size_t k = 0; k < g.dims[2]; ++k)
            for (size_t j = 0; j < g.dims[1]; ++j)
                for (size_t i = 0; i < g.dims[0]; ++i) {
                    const double x = g.origin[0] + (i + 0.5) * g.cell, y = g.origin[1] + (j + 0.5) * g.cell,
                                 z = g.origin[2] + (k + 0.5) * g.cell;
                    f.value[(k * g.dims[1] + j) * g.dims[0] + i] = a[0] + a[1] * x + a[2] * y + a[3] * z;
                }
        phc_climbing_rng rng;
        phc_climbing_rng_seed(&rng, 7);
        double worst_v = 0, worst_g = 0;
        for (int s = 0; s < 1000; ++s) {
            double x[3], gr[3];
            for (int d = 0; d < 3; ++d)
                x[d] = g.origin[d] + g.cell * (0.5 + phc_climbing_rng_uniform(&rng) * (double)(g.dims[d] - 1));
            const double v = phc_climbing_light_field_at(&f, x, gr);
            worst_v = fmax(worst_v, fabs(v - (a[0] + a[1] * x[0] + a[2] * x[1] + a[3] * x[2])));
            for (int d = 0; d < 3; ++d)
                worst_g = fmax(worst_g, fabs(gr[d] - a[1 + d]));
        }
        printf("trilinear field: linear F over 1000 points: max |F - exact| = %.3g, max |grad - exact| = %.3g 1/m\n",
               worst_v, worst_g);
        CHECK(worst_v < 1e-14);
        CHECK(worst_g < 1e-12);
        /* random node values: analytic gradient against central differences */
        const size_t cells = phc_climbing_light_cells(&g);
        for (size_t c = 0; c < cells; ++c)
            f.value[c] = phc_climbing_rng_uniform(&rng);
        double worst_rel = 0;
        int tested = 0;
        for (int s = 0; s < 1000; ++s) {
            double x[3], gr[3];
            int near_face = 0;
            for (int d = 0; d < 3; ++d) {
                const double u = 0.5 + phc_climbing_rng_uniform(&rng) * (double)(g.dims[d] - 1);
                near_face |= fabs(u - 0.5 - floor(u - 0.5 + 0.5)) < 1e-4; /* on a node plane: kink */
                x[d] = g.origin[d] + g.cell * u;
            }
            if (near_face)
                continue;
            phc_climbing_light_field_at(&f, x, gr);
            const double e = 1e-7;
            for (int d = 0; d < 3; ++d) {
                double xp[3], xm[3];
                memcpy(xp, x, sizeof xp);
                memcpy(xm, x, sizeof xm);
                xp[d] += e;
                xm[d] -= e;
                const double fd = (phc_climbing_light_field_at(&f, xp, NULL) - phc_climbing_light_field_at(&f, xm, NULL)) /
                                  (2 * e);
                worst_rel = fmax(worst_rel, fabs(gr[d] - fd) / fmax(1, fabs(fd)));
            }
            ++tested;
        }
        printf("trilinear field: random nodes, %d points: max |grad - central difference| / max(1, |cd|) = %.3g\n",
               tested, worst_rel);
        CHECK(tested > 900);
        CHECK(worst_rel < 1e-6);
        /* outside the nodes' hull: clamped, no gradient across */
        double gr[3];
        const double out[3] = {-1, 0.3, 0.5};
        phc_climbing_light_field_at(&f, out, gr);
        printf("trilinear field: a point beyond the x faces: d/dx = %g\n", gr[0]);
        CHECK(gr[0] == 0);

        /* 2a. no occluder, no shade: F = 1, gradient 0, target = l */
        const double probe[3] = {0.01, 0.02, 0.05};
        const double vol = 1e-6;
        CHECK(phc_climbing_light_field_update(&f, NULL, probe, &vol, 1) == 0);
        double maxdev = 0;
        for (size_t c = 0; c < cells; ++c)
            maxdev = fmax(maxdev, fabs(f.value[c] - 1));
        double t[3];
        const double x0[3] = {0.05, 0.3, 0.45};
        const int used = phc_climbing_light_field_target(&f, x0, 0, t);
        phc_climbing_light_field_at(&f, x0, gr);
        printf("no occluder: max |F - 1| = %g, |grad| = %g, target uses the gradient: %d, target = (%g, %g, %g)\n",
               maxdev, sqrt(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2]), used, t[0], t[1], t[2]);
        CHECK(maxdev == 0);
        CHECK(used == 0);
        CHECK(t[0] == 0 && t[1] == 0 && t[2] == 1);
        phc_climbing_light_field_free(&f);
    }

    /* 2b. a whole run: seek_light with a shadow triangle outside the grid
       (the field is built every step, and is uniform) against the fixed
       direction: the same directions at every step */
    {
        const double far_v[9] = {10, 10, 10, 11, 10, 10, 10, 11, 10};
        const size_t far_t[3] = {0, 1, 2};
        const double seed[3] = {0, 0, 0}, east[3] = {1, 0, 0.2};
        phc_climbing *cc[2];
        phc_error err;
        for (int s = 0; s < 2; ++s) {
            phc_climbing_options o = phc_climbing_options_default();
            o.branch_probability = 0.3;
            o.phototropism = 0.3;
            o.growth_rate = 0.3;
            o.seek_light = s;
            o.light.cell = 0.05;
            o.light.origin[0] = o.light.origin[1] = -0.5;
            o.light.dims[0] = o.light.dims[1] = 20;
            o.light.dims[2] = 10;
            o.light.ambient = 0.4;
            cc[s] = phc_climbing_new(seed, east, &o, &err);
            CHECK(cc[s] && phc_climbing_set_shadow_triangles(cc[s], far_v, 3, far_t, 1, &err) == 0);
        }
        double worst = 0;
        size_t steps_off = 0;
        for (int k = 0; k < 300 && cc[0] && cc[1]; ++k) {
            phc_climbing_step(cc[0], 0.1, &err);
            phc_climbing_step(cc[1], 0.1, &err);
            double step_worst = phc_climbing_count(cc[0]) == phc_climbing_count(cc[1]) ? 0 : INFINITY;
            for (size_t i = 0; i < phc_climbing_count(cc[0]) && isfinite(step_worst); ++i) {
                double d0[3], d1[3];
                phc_climbing_direction(cc[0], i, d0);
                phc_climbing_direction(cc[1], i, d1);
                for (int d = 0; d < 3; ++d)
                    step_worst = fmax(step_worst, fabs(d0[d] - d1[d]));
            }
            steps_off += step_worst > 0;
            worst = fmax(worst, step_worst);
        }
        printf("no occluder, whole run: %zu and %zu particles after 300 steps, max |d_seek - d_fixed| = %g, "
               "steps that differ: %zu\n",
               phc_climbing_count(cc[0]), phc_climbing_count(cc[1]), worst, steps_off);
        CHECK(phc_climbing_count(cc[0]) > 20);
        CHECK(worst <= 1e-15);
        phc_climbing_free(cc[0]);
        phc_climbing_free(cc[1]);
    }

    /* 3. the plate with a gap */
    {
        run_result fixed, seek;
        CHECK(run_plate(0, &fixed) == 0);
        CHECK(run_plate(1, &seek) == 0);
        printf("plate with a gap at x in [0.2, 0.3] m, z = 0.4 m, light from above, 150 s:\n");
        printf("  fixed direction: %zu particles, tip reaches z = 0.4 m at x = %.4f m, final tip (%.4f, %.4f, %.4f) m, "
               "%.4f m from the gap centre\n",
               fixed.particles, fixed.cross_x, fixed.final_tip[0], fixed.final_tip[1], fixed.final_tip[2],
               fixed.gap_dist);
        printf("  seek_light:      %zu particles, tip reaches z = 0.4 m at x = %.4f m, final tip (%.4f, %.4f, %.4f) m, "
               "%.4f m from the gap centre\n",
               seek.particles, seek.cross_x, seek.final_tip[0], seek.final_tip[1], seek.final_tip[2], seek.gap_dist);
        CHECK(fabs(fixed.cross_x) < 1e-9);
        CHECK(seek.cross_x >= 0.2 && seek.cross_x <= 0.3);
        CHECK(seek.gap_dist < fixed.gap_dist);
    }
    /* 4. the field near sites against the whole field */
    for (int ext = 0; ext < 2; ++ext) {
        phc_climbing_light_grid g = {{-0.45, -0.3, -0.05}, 0.05, {19, 12, 11}, ext ? 30 : 0, {0, 0, 0}, 0.5};
        const double l[3] = {0.3, -0.1, 1}, nl = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
        for (int d = 0; d < 3; ++d)
            g.direction[d] = l[d] / nl;
        const size_t cells = phc_climbing_light_cells(&g);
        unsigned char *mask = calloc(cells, 1);
        for (size_t t = 0; t < 4; ++t)
            phc_climbing_light_mark_triangle(&g, PLATE_V + 3 * PLATE_T[3 * t], PLATE_V + 3 * PLATE_T[3 * t + 1],
                                             PLATE_V + 3 * PLATE_T[3 * t + 2], mask);
        const phc_climbing_occluders occ = {PLATE_V, 8, PLATE_T, 4, mask};
        enum { NP = 400, NS = 12 };
        double x[3 * NP], vol[NP], sites[3 * NS];
        phc_climbing_rng rng;
        phc_climbing_rng_seed(&rng, 5);
        for (size_t i = 0; i < NP; ++i) {
            for (int d = 0; d < 3; ++d)
                x[3 * i + d] = g.origin[d] + phc_climbing_rng_uniform(&rng) * g.cell * (double)g.dims[d];
            vol[i] = 2e-5 * phc_climbing_rng_uniform(&rng);
        }
        for (size_t s = 0; s < NS; ++s) /* some beyond the grid's faces (clamped) */
            for (int d = 0; d < 3; ++d)
                sites[3 * s + d] = g.origin[d] + (1.4 * phc_climbing_rng_uniform(&rng) - 0.2) * g.cell * (double)g.dims[d];
        phc_climbing_light_field full, near;
        CHECK(phc_climbing_light_field_init(&full, &g, 20) == 0);
        CHECK(phc_climbing_light_field_init(&near, &g, 20) == 0);
        CHECK(phc_climbing_light_field_update(&full, &occ, x, vol, NP) == 0);
        CHECK(phc_climbing_light_field_update_near(&near, &occ, x, vol, NP, sites, NS) == 0);
        size_t computed = 0, differ = 0, shaded = 0;
        for (size_t c = 0; c < cells; ++c) {
            if (isnan(near.value[c]))
                continue;
            ++computed;
            differ += memcmp(&near.value[c], &full.value[c], sizeof(double)) != 0;
        }
        for (size_t c = 0; c < cells; ++c)
            shaded += full.value[c] < 1;
        size_t site_differ = 0;
        for (size_t s = 0; s < NS; ++s) {
            double g0[3], g1[3];
            const double v0 = phc_climbing_light_field_at(&full, sites + 3 * s, g0);
            const double v1 = phc_climbing_light_field_at(&near, sites + 3 * s, g1);
            site_differ += v0 != v1 || g0[0] != g1[0] || g0[1] != g1[1] || g0[2] != g1[2];
        }
        printf("field near %d sites, extinction %g 1/m: %zu of %zu nodes computed (%zu shaded in the whole field), "
               "nodes that differ from the whole field: %zu, sites whose value or gradient differ: %zu\n",
               NS, g.extinction, computed, cells, shaded, differ, site_differ);
        CHECK(computed > 0 && computed <= 8 * NS);
        CHECK(shaded > 0);
        CHECK(differ == 0);
        CHECK(site_differ == 0);
        phc_climbing_light_field_free(&full);
        phc_climbing_light_field_free(&near);
        free(mask);
    }
    return check_finish("test_climbing_light_field");
}
