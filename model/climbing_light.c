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
    if (!(g->extinction > 0)) {
        for (size_t i = 0; i < n; ++i)
            light[i] = 1;
        return;
    }
    const size_t cells = phc_climbing_light_cells(g);
    memset(phi, 0, cells * sizeof *phi);
    const double h3 = g->cell * g->cell * g->cell;
    for (size_t i = 0; i < n; ++i) {
        const size_t c = cell_of(g, x + 3 * i);
        if (c != (size_t)-1)
            phi[c] += vol[i] / h3;
    }
    /* a ray crosses the grid in at most the sum of its dims steps of h */
    const size_t kmax = g->dims[0] + g->dims[1] + g->dims[2];
    for (size_t i = 0; i < n; ++i) {
        double depth = 0;
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
            depth += phi[c] * g->cell;
        }
        light[i] = exp(-g->extinction * depth);
    }
}
