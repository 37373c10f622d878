/* Unit test of the climbing plant's supports that cast shadows, leaves and
 * secondary growth (model/climbing_light.h, model/climbing_leaves.h,
 * model/climbing_cambium.h, model/climbing_growth.h; Hädrich et al., CGF
 * 36(2) 2017, §4.2–4.3).  Every checked number is printed.
 *  1. Shadows: an opaque wall between the light and a point leaves only the
 *     ambient share a there (exactly), a point on the light's side gets 1;
 *     without a mask and with a = 0 the shaded light equals the plain
 *     Beer–Lambert law bit for bit; a wall plane across a 20×10×10 grid
 *     marks exactly its 200 cells.
 *  2. A shoot under a wall grows at r·a: after k steps it holds exactly
 *     1 + ⌊r a k Δt/(1 − σ₀)⌋ particles (every k), against 1 + ⌊r k Δt/(1 −
 *     σ₀)⌋ without the wall.
 *  3. Leaves: on a straight shoot the divergence between successive leaves
 *     is α to round-off (137.5° and 90°); every leaf_step-th node bears
 *     one; blade centres at s/2 from their node along the petiole ⊥ stem.
 *  4. Leaf normal limits: ω = 0, I = 0 or ℓ = n0 give n0 exactly; ω = I = 1
 *     within the clamp gives ℓ; beyond it the angle is θ_max exactly in the
 *     plane of n0 and ℓ; w = 1/2 gives the bisector.  In a plant: light
 *     across the stem turns every blade by θ_max; behind a wall (a = 0)
 *     every blade keeps n0; leaves shade the stem below them.
 *  5. Secondary growth: the relaxation against r* − (r* − r0) e^{−κt}; no
 *     shrinking; a branching plant at steady state meets r_p² = Σ r_c²
 *     (+ a_L/π with leaves) at every node; a thickened plant sags less. */
#include "model/climbing_cambium.h"
#include "model/climbing_growth.h"
#include "model/climbing_leaves.h"
#include "model/climbing_light.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static const double PI = 3.14159265358979323846;

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double angle_deg(const double a[3], const double b[3])
{
    return acos(fmax(-1, fmin(1, dot3(a, b) / sqrt(dot3(a, a) * dot3(b, b))))) * 180 / PI;
}

/* A horizontal square wall z = z0 over [x0, x1] × [y0, y1] (two triangles,
 * normals up). */
static void wall_z(double z0, double x0, double x1, double y0, double y1, double v[12],
                   size_t t[6])
{
    const double vv[12] = {x0, y0, z0, x1, y0, z0, x1, y1, z0, x0, y1, z0};
    const size_t tt[6] = {0, 1, 2, 0, 2, 3};
    memcpy(v, vv, sizeof vv);
    memcpy(t, tt, sizeof tt);
}

static phc_climbing *grow(const phc_climbing_options *o, const double base[3],
                          const double dir[3], size_t steps, double dt, const double *wv,
                          const size_t *wt)
{
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, dir, o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return NULL;
    }
    if (wv && phc_climbing_set_shadow_triangles(c, wv, 4, wt, 2, &err)) {
        fprintf(stderr, "%s\n", err.message);
        phc_climbing_free(c);
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

int main(void)
{
    phc_error err;
    const double up[3] = {0, 0, 1}, east[3] = {1, 0, 0};

    /* 1. shadows in the light grid */
    {
        phc_climbing_light_grid g;
        memset(&g, 0, sizeof g);
        g.cell = 0.1;
        g.dims[0] = g.dims[1] = 1;
        g.dims[2] = 4;
        g.direction[2] = 1;
        g.ambient = 0.3;
        unsigned char mask[4] = {0};
        double v[12];
        size_t t[6];
        wall_z(0.25, -1, 2, -1, 2, v, t);
        size_t marked = phc_climbing_light_mark_triangle(&g, v, v + 3, v + 6, mask);
        marked += phc_climbing_light_mark_triangle(&g, v, v + 6, v + 9, mask);
        const double x[6] = {0.05, 0.05, 0.05, 0.05, 0.05, 0.35}, vol[2] = {0, 0};
        double phi[4], I[2];
        const phc_climbing_occluders occ = {v, 4, t, 2, mask};
        phc_climbing_light_shaded(&g, &occ, x, vol, 2, phi, I);
        printf("shadow: 1x1x4 grid, wall in cell 2: %zu cell marked (%d %d %d %d); I below = %.17g "
               "(ambient 0.3), above = %.17g\n",
               marked, mask[0], mask[1], mask[2], mask[3], I[0], I[1]);
        CHECK(marked == 1 && mask[2] == 1);
        CHECK(I[0] == 0.3);
        CHECK(I[1] == 1);
        g.ambient = 0;
        phc_climbing_light_shaded(&g, &occ, x, vol, 2, phi, I);
        printf("shadow: ambient 0: I below = %g (opaque wall: no direct light)\n", I[0]);
        CHECK(I[0] == 0);
        /* a point 3 mm beside a vertical wall x = 0.1 inside the wall's cells,
           light along the wall: lit; light across it from behind: shadowed */
        {
            phc_climbing_light_grid w = g;
            w.dims[0] = 4;
            w.dims[2] = 4;
            w.ambient = 0;
            unsigned char wm[16] = {0};
            const double wv[12] = {0.1, -1, -1, 0.1, 2, -1, 0.1, 2, 2, 0.1, -1, 2};
            const size_t wt[6] = {0, 1, 2, 0, 2, 3};
            phc_climbing_light_mark_triangle(&w, wv, wv + 3, wv + 6, wm);
            phc_climbing_light_mark_triangle(&w, wv, wv + 6, wv + 9, wm);
            const phc_climbing_occluders wo = {wv, 4, wt, 2, wm};
            const double px[3] = {0.103, 0.05, 0.05}, pv[1] = {0};
            double along, across, front;
            phc_climbing_light_shaded(&w, &wo, px, pv, 1, phi, &along);
            w.direction[0] = -1; /* light from -x: the wall is between */
            w.direction[2] = 0;
            phc_climbing_light_shaded(&w, &wo, px, pv, 1, phi, &across);
            w.direction[0] = 1; /* light from +x: the wall is behind */
            phc_climbing_light_shaded(&w, &wo, px, pv, 1, phi, &front);
            printf("shadow: point 3 mm off a wall: light along the wall I = %g, from behind the "
                   "wall I = %g, from its front I = %g\n",
                   along, across, front);
            CHECK(along == 1 && across == 0 && front == 1);
            const double o0[3] = {0, 0, 0}, l[3] = {0, 0, 1}, a[3] = {-1, -1, 1}, b[3] = {1, -1, 1},
                         cc[3] = {0, 1, 1};
            CHECK(phc_climbing_ray_hits_triangle(o0, l, 0, a, b, cc) == 1);
            CHECK(phc_climbing_ray_hits_triangle(o0, l, 1.5, a, b, cc) == 0);
            const double lx[3] = {1, 0, 0};
            CHECK(phc_climbing_ray_hits_triangle(o0, lx, 0, a, b, cc) == 0);
        }
        /* no mask, a = 0: the plain law, bit for bit */
        g.extinction = 40;
        const double xs[9] = {0.05, 0.05, 0.05, 0.05, 0.05, 0.15, 0.05, 0.05, 0.38};
        const double vs[3] = {1e-4, 2e-4, 3e-4};
        double I1[3], I2[3];
        phc_climbing_light(&g, xs, vs, 3, phi, I1);
        phc_climbing_light_shaded(&g, NULL, xs, vs, 3, phi, I2);
        printf("shadow: no mask: I = %.17g %.17g %.17g, plain law identical: %d\n", I2[0], I2[1],
               I2[2], memcmp(I1, I2, sizeof I1) == 0);
        CHECK(memcmp(I1, I2, sizeof I1) == 0);
        /* exact: the point in cell 0 sees cells 1..3: φ = (2e-4 + 3e-4)/h³ */
        CHECK_NEAR(I2[0], exp(-40 * (5e-4 / 1e-3) * 0.1), 0, 1e-15);

        phc_climbing_options o = phc_climbing_options_default();
        o.light.cell = 0.1;
        o.light.dims[0] = 20;
        o.light.dims[1] = 10;
        o.light.dims[2] = 10;
        phc_climbing *c = phc_climbing_new((double[3]){0.05, 0.5, 0.1}, east, &o, &err);
        wall_z(0.55, -1, 3, -1, 2, v, t);
        CHECK(c && phc_climbing_set_shadow_triangles(c, v, 4, t, 2, &err) == 0);
        printf("shadow: wall z = 0.55 m across a 20x10x10 grid of 0.1 m: %zu opaque cells "
               "(expected 200)\n",
               phc_climbing_opaque_cells(c));
        CHECK(phc_climbing_opaque_cells(c) == 200);
        const size_t badt[6] = {0, 1, 7, 0, 2, 3};
        CHECK(phc_climbing_set_shadow_triangles(c, v, 4, badt, 2, &err) != 0);
        printf("shadow: bad index: %s\n", err.message);
        CHECK_STR_CONTAINS(err.message, "shadow triangle 0: vertex index 7");
        phc_climbing_free(c);
    }

    /* 2. a shoot under a wall grows at r·a */
    {
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 0;
        o.growth_rate = 0.2;
        o.bud_fraction = 0.25;
        o.light.cell = 0.1;
        o.light.dims[0] = 30;
        o.light.dims[1] = 10;
        o.light.dims[2] = 10;
        o.light.ambient = 0.3;
        const double base[3] = {0.05, 0.5, 0.1}, dt = 0.07;
        double v[12];
        size_t t[6];
        wall_z(0.55, -1, 4, -1, 2, v, t);
        phc_climbing *shade = phc_climbing_new(base, east, &o, &err);
        phc_climbing *open = phc_climbing_new(base, east, &o, &err);
        CHECK(shade && open && phc_climbing_set_shadow_triangles(shade, v, 4, t, 2, &err) == 0);
        size_t wrong = 0;
        const size_t steps = 1500;
        for (size_t k = 1; k <= steps; ++k) {
            phc_climbing_step(shade, dt, &err);
            phc_climbing_step(open, dt, &err);
            const size_t es = 1 + (size_t)floor(0.2 * 0.3 * (double)k * dt / 0.75);
            const size_t eo = 1 + (size_t)floor(0.2 * (double)k * dt / 0.75);
            /* a count within round-off of a boundary may fall either side */
            const size_t es1 = 1 + (size_t)floor(0.2 * 0.3 * (double)k * dt / 0.75 - 1e-9);
            const size_t eo1 = 1 + (size_t)floor(0.2 * (double)k * dt / 0.75 - 1e-9);
            const size_t ns = phc_climbing_count(shade), no = phc_climbing_count(open);
            if ((ns != es && ns != es1) || (no != eo && no != eo1))
                fprintf(stderr, "step %zu: shade %zu (expected %zu), open %zu (expected %zu)\n", k,
                        ns, es, no, eo);
            wrong += ns != es && ns != es1;
            wrong += no != eo && no != eo1;
        }
        printf("shadow: shoot under a wall (a = 0.3) after %zu steps of %g s: %zu particles, in the "
               "open %zu; steps with a count off 1 + floor(r a k dt/(1 - s0)) (+-1e-9): %zu\n",
               steps, dt, phc_climbing_count(shade), phc_climbing_count(open), wrong);
        CHECK(wrong == 0);
        CHECK(phc_climbing_count(shade) < phc_climbing_count(open));
        phc_climbing_free(shade);
        phc_climbing_free(open);
    }

    /* 3. phyllotaxis on a straight shoot */
    const double alphas[2] = {137.5, 90};
    for (int a = 0; a < 2; ++a) {
        for (unsigned step = 1; step <= 3; step += 2) {
            phc_climbing_options o = phc_climbing_options_default();
            o.branch_probability = 0;
            o.leaf_step = step;
            o.leaf_angle_deg = alphas[a];
            phc_climbing *c = grow(&o, (double[3]){0, 0, 0}, up, 600, 0.5, NULL, NULL);
            CHECK(c != NULL);
            if (!c)
                continue;
            const size_t n = phc_climbing_count(c);
            double worst = 0, worst_pos = 0, worst_perp = 0, prev[3];
            size_t leaves = 0, grown = 0, off_step = 0;
            for (size_t i = 0; i < n; ++i) {
                grown += !phc_climbing_is_apical(c, i);
                double centre[3], nrm[3], p[3], d[3], b[3], tip[3];
                if (!phc_climbing_leaf(c, i, centre, nrm, p))
                    continue;
                off_step += phc_climbing_node_index(c, i) % step != 0;
                phc_climbing_direction(c, i, d);
                phc_climbing_segment(c, i, b, tip);
                worst_perp = fmax(worst_perp, fabs(dot3(p, d)));
                double r[3] = {centre[0] - tip[0], centre[1] - tip[1], centre[2] - tip[2]};
                worst_pos = fmax(worst_pos, fabs(sqrt(dot3(r, r)) - 0.5 * o.leaf_size));
                if (leaves > 0) {
                    const double cr[3] = {prev[1] * p[2] - prev[2] * p[1],
                                          prev[2] * p[0] - prev[0] * p[2],
                                          prev[0] * p[1] - prev[1] * p[0]};
                    double div = atan2(dot3(cr, d), dot3(prev, p)) * 180 / PI;
                    if (div < 0)
                        div += 360;
                    worst = fmax(worst, fabs(div - alphas[a]));
                }
                memcpy(prev, p, sizeof prev);
                ++leaves;
            }
            const size_t expect = grown ? (grown - 1) / step + 1 : 0;
            printf("leaves: alpha %g deg, step %u: %zu grown nodes, %zu leaves (expected %zu), "
                   "max |divergence - alpha| = %.3g deg, max |centre - node| - s/2 = %.3g m, "
                   "max |p.d| = %.3g\n",
                   alphas[a], step, grown, leaves, expect, worst, worst_pos, worst_perp);
            CHECK(leaves == expect && leaves >= 10 && off_step == 0);
            CHECK(phc_climbing_leaf_count(c) == leaves);
            CHECK(worst < 1e-9);
            CHECK(worst_pos < 1e-15);
            CHECK(worst_perp < 1e-15);
            phc_climbing_free(c);
        }
    }

    /* 4. leaf normal limits */
    {
        const double n0[3] = {0, 0, 1}, l60[3] = {sin(PI / 3), 0, cos(PI / 3)};
        const double l90[3] = {0, 1, 0};
        double n[3];
        phc_climbing_leaf_normal(n0, l60, 0, 1, PI, n);
        CHECK(memcmp(n, n0, sizeof n) == 0);
        phc_climbing_leaf_normal(n0, l60, 1, 0, PI, n);
        CHECK(memcmp(n, n0, sizeof n) == 0);
        phc_climbing_leaf_normal(n0, n0, 1, 1, PI, n);
        CHECK(memcmp(n, n0, sizeof n) == 0);
        printf("leaf normal: omega 0, I 0, l = n0: the default normal exactly\n");
        phc_climbing_leaf_normal(n0, l60, 1, 1, 80 * PI / 180, n);
        const double e60 = fabs(n[0] - l60[0]) + fabs(n[1] - l60[1]) + fabs(n[2] - l60[2]);
        phc_climbing_leaf_normal(n0, l90, 1, 1, 80 * PI / 180, n);
        const double a90 = angle_deg(n, n0);
        const double c90[3] = {n0[1] * l90[2] - n0[2] * l90[1], n0[2] * l90[0] - n0[0] * l90[2],
                               n0[0] * l90[1] - n0[1] * l90[0]};
        const double plane = fabs(dot3(n, c90));
        phc_climbing_leaf_normal(n0, l60, 0.5, 1, PI, n);
        const double bis = fabs(angle_deg(n, n0) - 30) + fabs(angle_deg(n, l60) - 30);
        printf("leaf normal: l at 60 deg, clamp 80: |n - l|_1 = %.3g; l at 90 deg: angle %.15g deg "
               "(clamp 80), out of plane %.3g; w = 1/2: off the bisector by %.3g deg\n",
               e60, a90, plane, bis);
        CHECK(e60 < 1e-15);
        CHECK(fabs(a90 - 80) < 1e-12);
        CHECK(plane < 1e-15);
        CHECK(bis < 1e-12);

        /* in a plant: light across the stem */
        phc_climbing_options o = phc_climbing_options_default();
        o.branch_probability = 0;
        o.leaf_step = 1;
        o.light.direction[0] = 1;
        o.light.direction[2] = 0;
        o.light.cell = 0.1;
        o.light.dims[0] = o.light.dims[1] = o.light.dims[2] = 10;
        o.light.origin[0] = o.light.origin[1] = -0.5;
        o.light.origin[2] = -0.05;
        o.light.extinction = 0;
        phc_climbing *c = grow(&o, (double[3]){0, 0, 0}, up, 200, 0.5, NULL, NULL);
        /* the same behind a wall x = 0.25 (no ambient light) */
        const double wv[12] = {0.25, -1, -1, 0.25, 1, -1, 0.25, 1, 2, 0.25, -1, 2};
        const size_t wt[6] = {0, 1, 2, 0, 2, 3};
        phc_climbing *s = grow(&o, (double[3]){0, 0, 0}, up, 200, 0.5, wv, wt);
        CHECK(c && s);
        if (c && s) {
            double worst = 0, sumcos = 0, worst_dark = 0;
            size_t leaves = 0, dark = 0;
            for (size_t i = 0; i < phc_climbing_count(c); ++i) {
                double nrm[3], d[3];
                if (!phc_climbing_leaf(c, i, NULL, nrm, NULL))
                    continue;
                phc_climbing_direction(c, i, d);
                worst = fmax(worst, fabs(angle_deg(nrm, d) - 80));
                sumcos += dot3(nrm, o.light.direction);
                ++leaves;
            }
            for (size_t i = 0; i < phc_climbing_count(s); ++i) {
                double nrm[3], d[3];
                if (!phc_climbing_leaf(s, i, NULL, nrm, NULL))
                    continue;
                phc_climbing_direction(s, i, d);
                worst_dark = fmax(worst_dark, angle_deg(nrm, d));
                dark += phc_climbing_leaf_light(s, i) == 0;
            }
            printf("leaf normal in a plant: light across the stem: %zu leaves, max |angle - 80| = "
                   "%.3g deg, mean cos(n, l) = %.15g (cos 10 deg = %.15g); behind a wall: %zu of "
                   "%zu leaves in the dark, max angle to the stem %.3g deg\n",
                   leaves, worst, sumcos / (double)leaves, cos(10 * PI / 180), dark,
                   phc_climbing_leaf_count(s), worst_dark);
            CHECK(leaves >= 10 && worst < 1e-9);
            CHECK_NEAR(sumcos / (double)leaves, cos(10 * PI / 180), 1e-12, 0);
            CHECK(dark == phc_climbing_leaf_count(s) && dark >= 10);
            CHECK(worst_dark == 0);
        }
        phc_climbing_free(c);
        phc_climbing_free(s);

        /* leaves shade: a shoot hanging down, light from above */
        phc_climbing_options h = phc_climbing_options_default();
        h.branch_probability = 0;
        h.leaf_step = 1;
        h.leaf_size = 0.05;
        h.leaf_thickness = 1e-3;
        h.light.extinction = 200;
        h.light.cell = 0.05;
        h.light.dims[0] = h.light.dims[1] = 4;
        h.light.dims[2] = 20;
        h.light.origin[0] = h.light.origin[1] = -0.1;
        h.light.origin[2] = -0.95;
        const double down[3] = {0, 0, -1};
        phc_climbing *with = grow(&h, (double[3]){0, 0, 0}, down, 300, 0.5, NULL, NULL);
        h.leaf_thickness = 0;
        phc_climbing *without = grow(&h, (double[3]){0, 0, 0}, down, 300, 0.5, NULL, NULL);
        CHECK(with && without);
        if (with && without) {
            double lw = 0, lo = 0;
            for (size_t i = 0; i < phc_climbing_count(with); ++i)
                lw += phc_climbing_light_at(with, i) / (double)phc_climbing_count(with);
            for (size_t i = 0; i < phc_climbing_count(without); ++i)
                lo += phc_climbing_light_at(without, i) / (double)phc_climbing_count(without);
            printf("leaves shade: hanging shoot, mean light at the stem %.6f with leaves (%zu "
                   "particles), %.6f with transparent ones (%zu particles)\n",
                   lw, phc_climbing_count(with), lo, phc_climbing_count(without));
            CHECK(lw < lo);
            CHECK(phc_climbing_count(with) <= phc_climbing_count(without));
        }
        phc_climbing_free(with);
        phc_climbing_free(without);
    }

    /* 5. secondary growth */
    {
        const double r0 = 0.002, A = PI * 0.005 * 0.005, kappa = 0.3, dt = 0.25;
        double r = r0, worst = 0;
        for (int k = 1; k <= 200; ++k) {
            r = phc_climbing_cambium_step(r, A, kappa, dt);
            const double exact = 0.005 - (0.005 - r0) * exp(-kappa * dt * k);
            worst = fmax(worst, fabs(r - exact) / exact);
        }
        const double keep = phc_climbing_cambium_step(0.01, A, kappa, dt);
        printf("cambium: relaxation vs r* - (r* - r0) exp(-kappa t): max rel. error %.3g; r above "
               "its target stays: %g\n",
               worst, keep);
        CHECK(worst < 1e-14);
        CHECK(keep == 0.01);

        for (int leafy = 0; leafy < 2; ++leafy) {
            phc_climbing_options o = phc_climbing_options_default();
            o.branch_probability = 1;
            o.max_buds = 1;
            o.max_order = 2;
            o.max_particles = 40;
            o.cambium_rate = 0.5;
            o.leaf_step = leafy ? 2 : 0;
            o.leaf_pipe_area = leafy ? 3e-6 : 0;
            phc_climbing *c = grow(&o, (double[3]){0, 0, 0}, up, 3000, 0.5, NULL, NULL);
            CHECK(c != NULL);
            if (!c)
                continue;
            const size_t n = phc_climbing_count(c);
            double *sum = calloc(n, sizeof *sum);
            unsigned char *kids = calloc(n, 1);
            for (size_t i = 1; i < n; ++i) {
                const double rc = phc_climbing_radius(c, i);
                sum[phc_climbing_parent(c, i)] += rc * rc;
                kids[phc_climbing_parent(c, i)] = 1;
            }
            double err2 = 0, binary = 0;
            size_t nodes = 0, branchings = 0, below = 0;
            for (size_t i = 0; i < n; ++i) {
                below += phc_climbing_radius(c, i) < phc_climbing_primary_radius(c, i);
                if (!kids[i])
                    continue;
                const double ri = phc_climbing_radius(c, i);
                const double want = sum[i] + (phc_climbing_leaf(c, i, NULL, NULL, NULL)
                                                  ? o.leaf_pipe_area / PI
                                                  : 0);
                const double e = fabs(ri * ri - want) / want;
                err2 = fmax(err2, e);
                ++nodes;
                size_t nk = 0;
                for (size_t j = i + 1; j < n; ++j)
                    nk += phc_climbing_parent(c, j) == i;
                if (nk == 2) {
                    ++branchings;
                    binary = fmax(binary, e);
                }
            }
            printf("cambium: %s: %zu particles, %zu nodes with children (%zu binary), max "
                   "|r_p^2 - (sum r_c^2%s)|/that = %.3g (binary %.3g); seed radius %.4g m from "
                   "%.4g m; radii below primary: %zu\n",
                   leafy ? "leaves every 2nd node, a_L = 3e-6 m^2" : "no leaves", n, nodes,
                   branchings, leafy ? " + a_L/pi" : "", err2, binary, phc_climbing_radius(c, 0),
                   phc_climbing_primary_radius(c, 0), below);
            CHECK(n == 40 && branchings >= 3);
            CHECK(err2 < 1e-12);
            CHECK(below == 0);
            CHECK(phc_climbing_radius(c, 0) > 1.5 * phc_climbing_primary_radius(c, 0));
            free(sum);
            free(kids);
            phc_climbing_free(c);
        }

        /* a thickened shoot sags less under gravity */
        double sag[2];
        for (int thick = 0; thick < 2; ++thick) {
            phc_climbing_options o = phc_climbing_options_default();
            o.branch_probability = 0;
            o.growth_rate = 0.2;
            o.cambium_rate = thick ? 0.5 : 0;
            o.leaf_step = 1;
            o.leaf_pipe_area = 2e-5;
            o.dynamics_substeps = 20; /* 0.01 s dynamics steps */
            o.particles.maturity_age = 50;
            o.min_stiffness = 0.3;
            phc_climbing *c = grow(&o, (double[3]){0, 0, 1}, east, 100, 0.2, NULL, NULL);
            CHECK(c != NULL);
            sag[thick] = 0;
            if (!c)
                continue;
            const size_t t = phc_climbing_count(c) - 1;
            double x[3], xr[3];
            phc_climbing_position(c, t, x);
            phc_climbing_rest_position(c, t, xr);
            sag[thick] = xr[2] - x[2];
            phc_climbing_free(c);
        }
        printf("cambium: horizontal shoot under gravity (t_m 50 s, s_min 0.3), tip's sag below rest: %.4g m thin, "
               "%.4g m thickened\n",
               sag[0], sag[1]);
        CHECK(sag[0] > 1e-4 && sag[1] < sag[0]);
    }

    return check_finish("test_climbing_leaves");
}
