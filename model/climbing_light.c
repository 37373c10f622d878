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

void phc_climbing_light_shaded(const phc_climbing_light_grid *g, const unsigned char *opaque,
                               const double *x, const double *vol, size_t n, double *phi,
                               double *light)
{
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
        int blocked = 0;
        if (cell_of(g, x + 3 * i) == (size_t)-1) { /* outside the grid: full light */
            light[i] = 1;
            continue;
        }
        for (size_t k = 1; k <= kmax; ++k) {
            double p[3];
            for (int d = 0; d < 3; ++d)
                p[d] = x[3 * i + d] + (double)k * g->cell * g->direction[d];
            const size_t c = cell_of(g, p);
            if (c == (size_t)-1)
                break;
            if (opaque && opaque[c]) {
                blocked = 1;
                break;
            }
            if (absorb)
                depth += phi[c] * g->cell;
        }
        const double t = blocked ? 0 : absorb ? exp(-g->extinction * depth) : 1;
        light[i] = a == 0 ? t : a + (1 - a) * t;
    }
}
