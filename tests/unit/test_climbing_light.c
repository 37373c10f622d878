/* Unit test of the climbing plant's light grid (model/climbing_light.h):
 * the fast computation for light along a grid axis (the depth of a ray
 * summed once per cell, points near a cell face marched) against the
 * model's definition, a ray marched from every point (the code before the
 * fast path, copied below as the reference), bit for bit.
 *  1. Five directions (+z, −z, +x, −y along the axes; one oblique), a grid
 *     of odd sizes (9×7×11, cell 0.037 m, origin (−0.13, 0.21, −0.05) m),
 *     16000 random points (some outside the grid, random volumes), 600
 *     points on and within 3 ulps of cell faces (where rounding decides the
 *     cells a ray meets) and the 693 cell centres: every light equal to
 *     the reference's (==), and the number of reference rays whose cells
 *     are not the regular sequence j0 ± 1, j0 ± 2, … is printed and must
 *     be > 0 (the faces' points do reach the marching fallback).
 *  2. The same with an ambient share 0.3 and an opaque wall (two
 *     triangles and their mask) across the grid: equal to the reference.
 *  3. One and two OpenMP threads give the same bits (17,293 points: above
 *     the count from which the light runs in parallel).
 *  3b. phc_climbing_light_shaded_zeroed on a grid all zero at the start
 *     (calloc), for every case of 1.–3.: the same light bit for bit, and
 *     the grid all zero after each call.
 *  4. Limits: λ = 0 and no occluders gives 1 everywhere, and so does a
 *     grid with no cells (dims 0, outside the preconditions); a single column
 *     of 3 cells with φ = 0.2 per cell in the two upper cells gives the
 *     bottom point exp(−λ·0.4 h) (λ = 10, h = 0.1). */
#include "model/climbing_light.h"

#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* --- the reference: the model's definition as the code computed it before
 *     the fast path (floor of the quotient per sample) --- */
static size_t ref_cell_of(const phc_climbing_light_grid *g, const double x[3], size_t c[3])
{
    for (int k = 0; k < 3; ++k) {
        const double u = floor((x[k] - g->origin[k]) / g->cell);
        if (!(u >= 0) || u >= (double)g->dims[k])
            return (size_t)-1;
        c[k] = (size_t)u;
    }
    return (c[2] * g->dims[1] + c[1]) * g->dims[0] + c[0];
}

static int ref_occluded(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                        const double x[3])
{
    for (size_t t = 0; t < occ->nt; ++t) {
        const size_t *v = occ->triangles + 3 * t;
        if (phc_climbing_ray_hits_triangle(x, g->direction, 0.02 * g->cell,
                                           occ->vertices + 3 * v[0], occ->vertices + 3 * v[1],
                                           occ->vertices + 3 * v[2]))
            return 1;
    }
    return 0;
}

/* Light at the n points; *irregular counts the rays (along an axis a) whose
 * cells are not j0 + s, j0 + 2s, … */
static void ref_light(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                      const double *x, const double *vol, size_t n, double *phi, double *light,
                      size_t *irregular)
{
    const unsigned char *opaque = occ && occ->nt ? occ->mask : NULL;
    const size_t cells = g->dims[0] * g->dims[1] * g->dims[2];
    const int absorb = g->extinction > 0;
    int axis = -1;
    for (int d = 0; d < 3; ++d)
        if (g->direction[d] != 0)
            axis = axis == -1 ? d : 3;
    memset(phi, 0, cells * sizeof *phi);
    const double h3 = g->cell * g->cell * g->cell;
    size_t cc[3];
    for (size_t i = 0; i < n; ++i) {
        const size_t c = ref_cell_of(g, x + 3 * i, cc);
        if (c != (size_t)-1 && absorb)
            phi[c] += vol[i] / h3;
    }
    const size_t kmax = g->dims[0] + g->dims[1] + g->dims[2];
    for (size_t i = 0; i < n; ++i) {
        double depth = 0;
        int blocked = 0, tested = 0;
        size_t own3[3];
        const size_t own = ref_cell_of(g, x + 3 * i, own3);
        if (own == (size_t)-1) {
            light[i] = 1;
            continue;
        }
        if (opaque && opaque[own]) {
            tested = 1;
            blocked = ref_occluded(g, occ, x + 3 * i);
        }
        int regular = 1;
        size_t k = 1;
        for (; k <= kmax && !blocked; ++k) {
            double p[3];
            for (int d = 0; d < 3; ++d)
                p[d] = x[3 * i + d] + (double)k * g->cell * g->direction[d];
            const size_t c = ref_cell_of(g, p, cc);
            if (c == (size_t)-1)
                break;
            if (axis >= 0 && axis < 3 &&
                (double)cc[axis] != (double)own3[axis] + (double)k * g->direction[axis])
                regular = 0;
            if (opaque && opaque[c] && !tested) {
                tested = 1;
                if (ref_occluded(g, occ, x + 3 * i)) {
                    blocked = 1;
                    break;
                }
            }
            if (absorb)
                depth += phi[c] * g->cell;
        }
        /* the regular ray leaves at the face: k = dims − j0 (+), j0 + 1 (−) */
        if (axis >= 0 && axis < 3 && !blocked) {
            const size_t want = g->direction[axis] > 0 ? g->dims[axis] - own3[axis] : own3[axis] + 1;
            if (k != want)
                regular = 0;
        }
        *irregular += !regular;
        const double t = blocked ? 0 : absorb ? exp(-g->extinction * depth) : 1;
        light[i] = g->ambient == 0 ? t : g->ambient + (1 - g->ambient) * t;
    }
}

/* --- points --- */
static uint64_t rng_state = 0x9e3779b97f4a7c15ULL;
static double uniform(void) /* splitmix64 → [0, 1) */
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1p-53;
}

#define N_RANDOM 16000
#define N_FACE 600

/* Random points (10% beyond the grid), points on and near faces, centres. */
static size_t make_points(const phc_climbing_light_grid *g, double *x, double *vol)
{
    size_t n = 0;
    for (size_t i = 0; i < N_RANDOM; ++i, ++n) {
        for (int d = 0; d < 3; ++d)
            x[3 * n + d] = g->origin[d] + (uniform() * 1.1 - 0.05) * (double)g->dims[d] * g->cell;
        vol[n] = 2.5e-6 * uniform();
    }
    for (size_t i = 0; i < N_FACE; ++i, ++n) {
        for (int d = 0; d < 3; ++d)
            x[3 * n + d] = g->origin[d] + (uniform() * 0.98 + 0.01) * (double)g->dims[d] * g->cell;
        /* one coordinate onto a face o + j h, then up to 3 ulps off it */
        const int d = (int)(uniform() * 3);
        const double j = floor(uniform() * (double)g->dims[d]);
        double v = g->origin[d] + j * g->cell;
        for (int s = (int)(uniform() * 7) - 3; s != 0; s += s > 0 ? -1 : 1)
            v = nextafter(v, s > 0 ? INFINITY : -INFINITY);
        x[3 * n + d] = v;
        vol[n] = 2.5e-6 * uniform();
    }
    for (size_t k = 0; k < g->dims[2]; ++k)
        for (size_t j = 0; j < g->dims[1]; ++j)
            for (size_t i = 0; i < g->dims[0]; ++i, ++n) {
                const size_t idx[3] = {i, j, k};
                for (int d = 0; d < 3; ++d)
                    x[3 * n + d] = g->origin[d] + ((double)idx[d] + 0.5) * g->cell;
                vol[n] = 0;
            }
    return n;
}

static size_t mismatches(const double *a, const double *b, size_t n)
{
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        m += !(a[i] == b[i]);
    return m;
}

/* 3b: the light of phc_climbing_light_shaded_zeroed on phi_zero (all zero
 * on entry) into scratch, its differences from want and the cells it left
 * non-zero added to *differ and *left. */
static void zeroed_check(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                         const double *x, const double *vol, size_t n, double *phi_zero,
                         const double *want, double *scratch, size_t *calls, size_t *differ,
                         size_t *left)
{
    phc_climbing_light_shaded_zeroed(g, occ, x, vol, n, phi_zero, scratch);
    ++*calls;
    *differ += mismatches(scratch, want, n);
    const size_t cells = phc_climbing_light_cells(g);
    for (size_t c = 0; c < cells; ++c)
        *left += phi_zero[c] != 0;
    memset(phi_zero, 0, cells * sizeof *phi_zero); /* a failure here does not carry on */
}

int main(void)
{
    phc_climbing_light_grid g = {{-0.13, 0.21, -0.05}, 0.037, {9, 7, 11}, 25, {0, 0, 1}, 0};
    const size_t cells = phc_climbing_light_cells(&g);
    const size_t nmax = N_RANDOM + N_FACE + cells;
    double *x = malloc(3 * nmax * sizeof *x), *vol = malloc(nmax * sizeof *vol);
    double *phi = malloc(cells * sizeof *phi), *phi_ref = malloc(cells * sizeof *phi_ref);
    double *light = malloc(nmax * sizeof *light), *ref = malloc(nmax * sizeof *ref);
    double *light2 = malloc(nmax * sizeof *light2);
    unsigned char *mask = calloc(cells, 1);
    double *phi_zero = calloc(cells, sizeof *phi_zero);
    if (!x || !vol || !phi || !phi_ref || !light || !ref || !light2 || !mask || !phi_zero)
        return 1;
    size_t zeroed_calls = 0, zeroed_differ = 0, zeroed_left = 0;
    const size_t n = make_points(&g, x, vol);

    /* an opaque wall: the plane y = 0.35 m across the grid (two triangles) */
    const double wall_v[12] = {-1, 0.35, -1, 1, 0.35, -1, 1, 0.35, 1, -1, 0.35, 1};
    const size_t wall_t[6] = {0, 1, 2, 0, 2, 3};
    size_t marked = 0;
    for (int t = 0; t < 2; ++t)
        marked += phc_climbing_light_mark_triangle(&g, wall_v + 3 * wall_t[3 * t],
                                                   wall_v + 3 * wall_t[3 * t + 1],
                                                   wall_v + 3 * wall_t[3 * t + 2], mask);
    const phc_climbing_occluders wall = {wall_v, 4, wall_t, 2, mask};
    printf("grid 9x7x11, h = 0.037 m; %zu points (%d random, %d on or within 3 ulps of a face, "
           "%zu cell centres); wall marks %zu cells\n",
           n, N_RANDOM, N_FACE, cells, marked);
    CHECK(marked == 9 * 11);

    /* 1.–2. directions, without and with the wall and ambient light */
    const double dirs[5][3] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {0.48, -0.6, 0.64}};
    const char *names[5] = {"+z", "-z", "+x", "-y", "oblique"};
    for (int s = 0; s < 2; ++s)
        for (int k = 0; k < 5; ++k) {
            phc_climbing_light_grid gk = g;
            memcpy(gk.direction, dirs[k], sizeof gk.direction);
            gk.ambient = s ? 0.3 : 0;
            const phc_climbing_occluders *occ = s ? &wall : NULL;
            size_t irregular = 0;
            ref_light(&gk, occ, x, vol, n, phi_ref, ref, &irregular);
            phc_climbing_light_shaded(&gk, occ, x, vol, n, phi, light);
            const size_t bad = mismatches(light, ref, n);
            double lo = 1;
            for (size_t i = 0; i < n; ++i)
                lo = fmin(lo, light[i]);
            printf("light %-7s %-16s: %zu of %zu differ from the marched reference; %zu rays "
                   "irregular; smallest I %.6f\n",
                   names[k], s ? "wall, ambient 0.3" : "plain", bad, n, irregular, lo);
            CHECK(bad == 0);
            if (k < 4)
                CHECK(irregular > 0);
            CHECK(lo < 0.9); /* the shade is real */
            zeroed_check(&gk, occ, x, vol, n, phi_zero, light, light2, &zeroed_calls,
                         &zeroed_differ, &zeroed_left);
        }

    /* 3. one and two threads */
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    phc_climbing_light_shaded(&g, &wall, x, vol, n, phi, light);
    omp_set_num_threads(2);
    phc_climbing_light_shaded(&g, &wall, x, vol, n, phi, light2);
    const size_t bad12 = mismatches(light, light2, n);
    printf("one vs two threads: %zu of %zu differ\n", bad12, n);
    CHECK(bad12 == 0);
    for (int t = 1; t <= 2; ++t) {
        omp_set_num_threads(t);
        zeroed_check(&g, &wall, x, vol, n, phi_zero, light, light2, &zeroed_calls,
                     &zeroed_differ, &zeroed_left);
    }
    omp_set_num_threads(threads);
    printf("phc_climbing_light_shaded_zeroed, %zu calls on one grid: %zu lights differ, %zu cells "
           "left non-zero\n",
           zeroed_calls, zeroed_differ, zeroed_left);
    CHECK(zeroed_calls == 12);
    CHECK(zeroed_differ == 0);
    CHECK(zeroed_left == 0);

    /* 4. limits */
    phc_climbing_light_grid clear = g;
    clear.extinction = 0;
    phc_climbing_light_shaded(&clear, NULL, x, vol, n, phi, light);
    size_t not_one = 0;
    for (size_t i = 0; i < n; ++i)
        not_one += light[i] != 1;
    printf("no extinction, no occluders: %zu of %zu points not 1\n", not_one, n);
    CHECK(not_one == 0);
    phc_climbing_light_grid empty = g;
    empty.dims[2] = 0; /* outside the header's preconditions: every point outside, no crash */
    phc_climbing_light_shaded(&empty, NULL, x, vol, n, phi, light);
    size_t lit = 0;
    for (size_t i = 0; i < n; ++i)
        lit += light[i] == 1;
    printf("a grid with no cells: %zu of %zu points in full light\n", lit, n);
    CHECK(lit == n);
    const phc_climbing_light_grid column = {{0, 0, 0}, 0.1, {1, 1, 3}, 10, {0, 0, 1}, 0};
    const double cx[9] = {0.05, 0.05, 0.05, 0.05, 0.05, 0.15, 0.05, 0.05, 0.25};
    const double h3 = 1e-3, cv[3] = {0, 0.2 * h3, 0.2 * h3};
    double cphi[3], cl[3];
    phc_climbing_light_shaded(&column, NULL, cx, cv, 3, cphi, cl);
    printf("column of 3 cells: I(bottom) = %.15f (exp(-10*0.4*0.1) = %.15f), I(middle) = %.15f, "
           "I(top) = %.15f\n",
           cl[0], exp(-0.4), cl[1], cl[2]);
    CHECK_NEAR(cl[0], exp(-10 * 0.4 * 0.1), 0, 1e-14);
    CHECK_NEAR(cl[1], exp(-10 * 0.2 * 0.1), 0, 1e-14);
    CHECK(cl[2] == 1);

    free(x);
    free(vol);
    free(phi);
    free(phi_ref);
    free(light);
    free(ref);
    free(light2);
    free(mask);
    free(phi_zero);
    return check_finish("test_climbing_light");
}
