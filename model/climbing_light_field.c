/* Light field for phototropism toward the light: see model/climbing_light_field.h. */
#include "model/climbing_light_field.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

int phc_climbing_light_field_init(phc_climbing_light_field *f, const phc_climbing_light_grid *g,
                                  double spread_deg)
{
    memset(f, 0, sizeof *f);
    f->grid = *g;
    f->spread = spread_deg * PI / 180;
    const size_t cells = phc_climbing_light_cells(g);
    f->value = malloc(cells * sizeof *f->value);
    f->phi = malloc(cells * sizeof *f->phi);
    f->sum = malloc(cells * sizeof *f->sum);
    f->probe = malloc(cells * sizeof *f->probe);
    f->wanted = malloc(cells);
    if (!f->value || !f->phi || !f->sum || !f->probe || !f->wanted) {
        phc_climbing_light_field_free(f);
        return -1;
    }
    for (size_t c = 0; c < cells; ++c)
        f->value[c] = 1;
    return 0;
}

void phc_climbing_light_field_free(phc_climbing_light_field *f)
{
    free(f->value);
    free(f->phi);
    free(f->px);
    free(f->pv);
    free(f->pl);
    free(f->sum);
    free(f->probe);
    free(f->wanted);
    free(f->sites);
    memset(f, 0, sizeof *f);
}

static int reserve(phc_climbing_light_field *f, size_t m)
{
    if (m <= f->cap)
        return 0;
    size_t cap = f->cap ? f->cap : 64;
    while (cap < m)
        cap *= 2;
    double *px = realloc(f->px, 3 * cap * sizeof *px);
    if (!px)
        return -1;
    f->px = px;
    double *pv = realloc(f->pv, cap * sizeof *pv);
    if (!pv)
        return -1;
    f->pv = pv;
    double *pl = realloc(f->pl, cap * sizeof *pl);
    if (!pl)
        return -1;
    f->pl = pl;
    f->cap = cap;
    return 0;
}

/* The sky's directions: ℓ, and with ψ > 0 six more at ψ from it. */
static size_t sky(const phc_climbing_light_field *f, double dirs[7][3])
{
    const double *l = f->grid.direction;
    memcpy(dirs[0], l, 3 * sizeof *l);
    if (!(f->spread > 0))
        return 1;
    int m = 0;
    for (int k = 1; k < 3; ++k)
        if (fabs(l[k]) < fabs(l[m]))
            m = k;
    const double e[3] = {m == 0, m == 1, m == 2};
    double e1[3] = {l[1] * e[2] - l[2] * e[1], l[2] * e[0] - l[0] * e[2], l[0] * e[1] - l[1] * e[0]};
    const double n1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int k = 0; k < 3; ++k)
        e1[k] /= n1;
    const double e2[3] = {l[1] * e1[2] - l[2] * e1[1], l[2] * e1[0] - l[0] * e1[2],
                          l[0] * e1[1] - l[1] * e1[0]};
    const double cs = cos(f->spread), sn = sin(f->spread);
    for (int j = 0; j < 6; ++j) {
        const double a = j * PI / 3, ca = cos(a), sa = sin(a);
        for (int k = 0; k < 3; ++k)
            dirs[1 + j][k] = cs * l[k] + sn * (ca * e1[k] + sa * e2[k]);
    }
    return 7;
}

/* The lowest of the nodes the trilinear interpolation at x reads
 * (i0[d] .. i0[d] + 1 along each axis, clamped onto the grid), its
 * fractions s and whether each axis is free (not clamped, more than one
 * layer of nodes): the gradient along a clamped axis is 0. */
static void corner_of(const phc_climbing_light_grid *g, const double x[3], size_t i0[3],
                      double s[3], int free_axis[3])
{
    for (int d = 0; d < 3; ++d) {
        const double top = (double)g->dims[d] - 1;
        double u = (x[d] - g->origin[d]) / g->cell - 0.5;
        free_axis[d] = g->dims[d] > 1 && u >= 0 && u <= top;
        if (!(u >= 0)) /* NaN too */
            u = 0;
        if (u > top)
            u = top;
        double fl = floor(u);
        if (fl > top - 1)
            fl = top - 1;
        if (fl < 0)
            fl = 0;
        i0[d] = (size_t)fl;
        s[d] = g->dims[d] > 1 ? u - fl : 0;
    }
}

/* Marks in f->wanted the (up to 8) nodes read at each of the ns sites;
 * returns how many cells are marked. */
static size_t mark_sites(phc_climbing_light_field *f, const double *sites, size_t ns)
{
    const phc_climbing_light_grid *g = &f->grid;
    const size_t nx = g->dims[0], ny = g->dims[1];
    memset(f->wanted, 0, phc_climbing_light_cells(g));
    size_t marked = 0;
    for (size_t t = 0; t < ns; ++t) {
        size_t i0[3];
        double s[3];
        int free_axis[3];
        corner_of(g, sites + 3 * t, i0, s, free_axis);
        for (int c = 0; c < 8; ++c) {
            const size_t id[3] = {i0[0] + (size_t)(c & 1), i0[1] + (size_t)((c >> 1) & 1),
                                  i0[2] + (size_t)((c >> 2) & 1)};
            if (id[0] >= nx || id[1] >= ny || id[2] >= g->dims[2])
                continue;
            unsigned char *w = f->wanted + (id[2] * ny + id[1]) * nx + id[0];
            marked += !*w;
            *w = 1;
        }
    }
    return marked;
}

/* The field at the cells wanted (NULL: every cell), NAN at the others.
 * The plant's points enter only through its shade φ: with extinction 0
 * they change no probe's light (a probe's ray is blocked by the occluders
 * or not, whatever other points there are), so they are left out. */
static int update_cells(phc_climbing_light_field *f, const phc_climbing_occluders *occ,
                        const double *x, const double *vol, size_t n, const unsigned char *wanted,
                        size_t nwanted)
{
    const phc_climbing_light_grid *g = &f->grid;
    const size_t cells = phc_climbing_light_cells(g);
    if (!(g->extinction > 0))
        n = 0;
    if (reserve(f, n + nwanted))
        return -1;
    memcpy(f->px, x, 3 * n * sizeof *x);
    memcpy(f->pv, vol, n * sizeof *vol);
    size_t m = n;
    for (size_t k = 0, c = 0; k < g->dims[2]; ++k)
        for (size_t j = 0; j < g->dims[1]; ++j)
            for (size_t i = 0; i < g->dims[0]; ++i, ++c) { /* cell (i, j, k) is number c */
                if (wanted && !wanted[c])
                    continue;
                const size_t idx[3] = {i, j, k};
                for (int d = 0; d < 3; ++d)
                    f->px[3 * m + d] = g->origin[d] + ((double)idx[d] + 0.5) * g->cell;
                f->pv[m] = 0; /* probes cast no shade */
                f->probe[m++ - n] = c;
            }
    const size_t probes = m - n;
    double dirs[7][3];
    const size_t nd = sky(f, dirs);
    double *sum = f->sum; /* per probe: the light summed over the sky */
    for (size_t p = 0; p < probes; ++p)
        sum[p] = 0;
    phc_climbing_light_grid gd = *g;
    for (size_t s = 0; s < nd; ++s) {
        memcpy(gd.direction, dirs[s], sizeof gd.direction);
        phc_climbing_light_shaded(&gd, occ, f->px, f->pv, m, f->phi, f->pl);
        for (size_t p = 0; p < probes; ++p)
            sum[p] += f->pl[n + p];
    }
    if (wanted)
        for (size_t c = 0; c < cells; ++c)
            f->value[c] = NAN;
    for (size_t p = 0; p < probes; ++p)
        f->value[f->probe[p]] = nd > 1 ? sum[p] / (double)nd : sum[p];
    return 0;
}

int phc_climbing_light_field_update(phc_climbing_light_field *f, const phc_climbing_occluders *occ,
                                    const double *x, const double *vol, size_t n)
{
    return update_cells(f, occ, x, vol, n, NULL, phc_climbing_light_cells(&f->grid));
}

int phc_climbing_light_field_update_near(phc_climbing_light_field *f,
                                         const phc_climbing_occluders *occ, const double *x,
                                         const double *vol, size_t n, const double *sites,
                                         size_t ns)
{
    return update_cells(f, occ, x, vol, n, f->wanted, mark_sites(f, sites, ns));
}

double *phc_climbing_light_field_sites(phc_climbing_light_field *f, size_t ns)
{
    if (ns < 1)
        ns = 1;
    if (ns > f->sites_cap) {
        double *q = realloc(f->sites, 3 * ns * sizeof *q);
        if (!q)
            return NULL;
        f->sites = q;
        f->sites_cap = ns;
    }
    return f->sites;
}

double phc_climbing_light_field_at(const phc_climbing_light_field *f, const double x[3],
                                   double grad[3])
{
    const phc_climbing_light_grid *g = &f->grid;
    size_t i0[3];
    double s[3];
    int free_axis[3]; /* 0: clamped (or a single layer of nodes): no gradient along it */
    corner_of(g, x, i0, s, free_axis);
    const size_t nx = g->dims[0], ny = g->dims[1];
    double v = 0, dv[3] = {0, 0, 0};
    for (int c = 0; c < 8; ++c) {
        const int b[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
        size_t id[3];
        double w[3];
        int skip = 0;
        for (int d = 0; d < 3; ++d) {
            id[d] = i0[d] + (size_t)b[d];
            if (id[d] >= g->dims[d])
                skip = 1; /* a single layer: its weight is 0 anyway */
            w[d] = b[d] ? s[d] : 1 - s[d];
        }
        if (skip)
            continue;
        const double F = f->value[(id[2] * ny + id[1]) * nx + id[0]];
        v += w[0] * w[1] * w[2] * F;
        /* d w_d / d u_d = ±1 */
        dv[0] += (b[0] ? 1 : -1) * w[1] * w[2] * F;
        dv[1] += w[0] * (b[1] ? 1 : -1) * w[2] * F;
        dv[2] += w[0] * w[1] * (b[2] ? 1 : -1) * F;
    }
    if (grad)
        for (int d = 0; d < 3; ++d)
            grad[d] = free_axis[d] ? dv[d] / g->cell : 0;
    return v;
}

int phc_climbing_light_field_target(const phc_climbing_light_field *f, const double x[3],
                                    double threshold, double t[3])
{
    double gr[3];
    phc_climbing_light_field_at(f, x, gr);
    const double len = sqrt(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2]);
    if (len > 0 && len * f->grid.cell >= threshold) {
        for (int d = 0; d < 3; ++d)
            t[d] = gr[d] / len;
        return 1;
    }
    memcpy(t, f->grid.direction, 3 * sizeof *t);
    return 0;
}
