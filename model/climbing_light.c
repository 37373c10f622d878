/* Light grid of a climbing plant: see model/climbing_light.h. */
#include "model/climbing_light.h"

#include <math.h>
#include <string.h>

size_t phc_climbing_light_cells(const phc_climbing_light_grid *g)
{
    return g->dims[0] * g->dims[1] * g->dims[2];
}

/* Cell index of x, or (size_t)-1 outside the grid. */
static size_t cell_of(const phc_climbing_light_grid *g, const double x[3])
{
    size_t c[3];
    for (int k = 0; k < 3; ++k) {
        const double u = floor((x[k] - g->origin[k]) / g->cell);
        if (!(u >= 0) || u >= (double)g->dims[k])
            return (size_t)-1;
        c[k] = (size_t)u;
    }
    return (c[2] * g->dims[1] + c[1]) * g->dims[0] + c[0];
}

void phc_climbing_light(const phc_climbing_light_grid *g, const double *x, const double *vol,
                        size_t n, double *phi, double *light)
{
    phc_climbing_light_grid g0 = *g;
    g0.ambient = 0;
    phc_climbing_light_shaded(&g0, NULL, x, vol, n, phi, light);
}

size_t phc_climbing_light_mark_triangle(const phc_climbing_light_grid *g, const double a[3],
                                        const double b[3], const double c[3],
                                        unsigned char *opaque)
{
    double e1 = 0, e2 = 0;
    for (int k = 0; k < 3; ++k) {
        e1 += (b[k] - a[k]) * (b[k] - a[k]);
        e2 += (c[k] - a[k]) * (c[k] - a[k]);
    }
    const double lmax = fmax(sqrt(e1), sqrt(e2));
    if (!isfinite(lmax))
        return 0;
    /* samples at spacing <= h/4 along both edges */
    const double want = ceil(4 * lmax / g->cell);
    const size_t m = want < 1 ? 1 : want > 1e5 ? 100000 : (size_t)want;
    size_t marked = 0;
    for (size_t i = 0; i <= m; ++i)
        for (size_t j = 0; i + j <= m; ++j) {
            const double u = (double)i / (double)m, v = (double)j / (double)m;
            double p[3];
            for (int k = 0; k < 3; ++k)
                p[k] = a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]);
            const size_t cell = cell_of(g, p);
            if (cell != (size_t)-1 && !opaque[cell]) {
                opaque[cell] = 1;
                ++marked;
            }
        }
    return marked;
}

int phc_climbing_ray_hits_triangle(const double x[3], const double l[3], double t_min,
                                   const double a[3], const double b[3], const double c[3])
{
    double e1[3], e2[3], s[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = b[k] - a[k];
        e2[k] = c[k] - a[k];
        s[k] = x[k] - a[k];
    }
    const double p[3] = {l[1] * e2[2] - l[2] * e2[1], l[2] * e2[0] - l[0] * e2[2],
                         l[0] * e2[1] - l[1] * e2[0]};
    const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (det == 0)
        return 0;
    const double inv = 1 / det;
    const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    if (u < 0 || u > 1)
        return 0;
    const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                         s[0] * e1[1] - s[1] * e1[0]};
    const double v = (l[0] * q[0] + l[1] * q[1] + l[2] * q[2]) * inv;
    if (v < 0 || u + v > 1)
        return 0;
    const double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    return t > t_min;
}

/* 1 when the ray from x toward the light crosses an occluding triangle. */
static int occluded(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                    const double x[3])
{
    /* a skin of h/50: a shoot pressed onto a face (its centre a hair behind
       it after a tropism step) is not shadowed by the face it lies on */
    const double t_min = 0.02 * g->cell;
    for (size_t t = 0; t < occ->nt; ++t) {
        const size_t *v = occ->triangles + 3 * t;
        if (phc_climbing_ray_hits_triangle(x, g->direction, t_min, occ->vertices + 3 * v[0],
                                           occ->vertices + 3 * v[1], occ->vertices + 3 * v[2]))
            return 1;
    }
    return 0;
}

void phc_climbing_light_shaded(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                               const double *x, const double *vol, size_t n, double *phi,
                               double *light)
{
    const unsigned char *opaque = occ && occ->nt ? occ->mask : NULL;
    const double a = g->ambient;
    const int absorb = g->extinction > 0;
    if (!absorb && !opaque) {
        for (size_t i = 0; i < n; ++i)
            light[i] = 1;
        return;
    }
    const size_t cells = phc_climbing_light_cells(g);
    if (absorb) {
        memset(phi, 0, cells * sizeof *phi);
        const double h3 = g->cell * g->cell * g->cell;
        for (size_t i = 0; i < n; ++i) {
            const size_t c = cell_of(g, x + 3 * i);
            if (c != (size_t)-1)
                phi[c] += vol[i] / h3;
        }
    }
    /* a ray crosses the grid in at most the sum of its dims steps of h */
    const size_t kmax = g->dims[0] + g->dims[1] + g->dims[2];
    for (size_t i = 0; i < n; ++i) {
        double depth = 0;
        int blocked = 0, tested = 0;
        const size_t own = cell_of(g, x + 3 * i);
        if (own == (size_t)-1) { /* outside the grid: full light */
            light[i] = 1;
            continue;
        }
        /* an occluder in the point's own cell may lie between it and the light */
        if (opaque && opaque[own]) {
            tested = 1;
            blocked = occluded(g, occ, x + 3 * i);
        }
        for (size_t k = 1; k <= kmax && !blocked; ++k) {
            double p[3];
            for (int d = 0; d < 3; ++d)
                p[d] = x[3 * i + d] + (double)k * g->cell * g->direction[d];
            const size_t c = cell_of(g, p);
            if (c == (size_t)-1)
                break;
            if (opaque && opaque[c] && !tested) {
                tested = 1; /* one exact test per ray */
                if (occluded(g, occ, x + 3 * i)) {
                    blocked = 1;
                    break;
                }
            }
            if (absorb)
                depth += phi[c] * g->cell;
        }
        const double t = blocked ? 0 : absorb ? exp(-g->extinction * depth) : 1;
        light[i] = a == 0 ? t : a + (1 - a) * t;
    }
}
