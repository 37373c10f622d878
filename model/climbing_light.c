/* Light grid of a climbing plant: see model/climbing_light.h. */
#include "model/climbing_light.h"

#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

size_t phc_climbing_light_cells(const phc_climbing_light_grid *g)
{
    return g->dims[0] * g->dims[1] * g->dims[2];
}

/* Cell coordinate of the coordinate xk along axis k, floor((xk − o_k)/h),
 * or (size_t)-1 outside the grid.  For a quotient q in [0, dims) the floor
 * is the truncation, so no call to floor() is needed. */
static size_t axis_cell(const phc_climbing_light_grid *g, int k, double xk)
{
    const double q = (xk - g->origin[k]) / g->cell;
    if (!(q >= 0) || q >= (double)g->dims[k])
        return (size_t)-1;
    return (size_t)q;
}

static size_t cell_index(const phc_climbing_light_grid *g, const size_t c[3])
{
    return (c[2] * g->dims[1] + c[1]) * g->dims[0] + c[0];
}

/* Cell index of x, or (size_t)-1 outside the grid. */
static size_t cell_of(const phc_climbing_light_grid *g, const double x[3])
{
    size_t c[3];
    for (int k = 0; k < 3; ++k)
        if ((c[k] = axis_cell(g, k, x[k])) == (size_t)-1)
            return (size_t)-1;
    return cell_index(g, c);
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

/* I = a + (1 − a)·T from the ray's fate: T = 0 when blocked, else the
 * Beer–Lambert transmission exp(−λ·depth) (1 without extinction). */
static double light_of(const phc_climbing_light_grid *g, int blocked, double depth)
{
    const double a = g->ambient;
    const double t = blocked ? 0 : g->extinction > 0 ? exp(-g->extinction * depth) : 1;
    return a == 0 ? t : a + (1 - a) * t;
}

/* Light at the point x of cell own by the model's definition: samples
 * x + k h ℓ, k = 1, 2, … (at most the sum of the dims) until the ray leaves
 * the grid, depth = Σ φ h over the cells they fall in, in that order. */
static double light_marched(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                            const unsigned char *opaque, const double *phi, const double x[3],
                            size_t own)
{
    const int absorb = g->extinction > 0;
    double depth = 0;
    int blocked = 0, tested = 0;
    /* an occluder in the point's own cell may lie between it and the light */
    if (opaque && opaque[own]) {
        tested = 1;
        blocked = occluded(g, occ, x);
    }
    /* along an axis with ℓ_d = ±0 a sample keeps x's coordinate
       (x_d + k h·0 = x_d exactly), hence x's cell coordinate */
    size_t fixed[3];
    for (int d = 0; d < 3; ++d)
        fixed[d] = g->direction[d] == 0 ? axis_cell(g, d, x[d]) : (size_t)-1;
    /* a ray crosses the grid in at most the sum of its dims steps of h */
    const size_t kmax = g->dims[0] + g->dims[1] + g->dims[2];
    for (size_t k = 1; k <= kmax && !blocked; ++k) {
        size_t cc[3];
        int inside = 1;
        for (int d = 0; d < 3 && inside; ++d) {
            cc[d] = g->direction[d] == 0
                        ? fixed[d]
                        : axis_cell(g, d, x[d] + (double)k * g->cell * g->direction[d]);
            inside = cc[d] != (size_t)-1;
        }
        if (!inside)
            break;
        const size_t c = cell_index(g, cc);
        if (opaque && opaque[c] && !tested) {
            tested = 1; /* one exact test per ray */
            if (occluded(g, occ, x)) {
                blocked = 1;
                break;
            }
        }
        if (absorb)
            depth += phi[c] * g->cell;
    }
    return light_of(g, blocked, depth);
}

/* The axis a when ℓ = ±e_a exactly (the default, light from above, is
 * +e_z), else -1. */
static int light_axis(const phc_climbing_light_grid *g)
{
    int a = -1;
    for (int d = 0; d < 3; ++d) {
        if (g->direction[d] == 0)
            continue;
        if (a >= 0 || fabs(g->direction[d]) != 1)
            return -1;
        a = d;
    }
    return a;
}

/* 1 when the model's samples of the ray from a point whose coordinate
 * along the light's axis a is xa fall, rounding included, in exactly the
 * cells j0 ± 1, j0 ± 2, … up to the grid's face (j0 the point's own cell
 * coordinate), so that the ray's depth is that of every other such point
 * of its cell.  The computed quotient q_k = fl(fl(fl(xa ± fl(k h)) − o)/h)
 * of sample k (k <= dims + 1) differs from the exact (xa − o)/h ± k by at
 * most 5.02 u M/h + u (dims + 1) (u = 2⁻⁵³ the unit round-off, M = |xa| +
 * |o| + (dims + 1) h; four correctly rounded operations, the one of q_0
 * included), so a point whose computed fraction f = q_0 − j0 keeps the
 * margin δ = 16 u (M/h + dims + 1) from 0 and from 1 has every sample in
 * the cell its exact quotient is in (Higham, "Accuracy and Stability of
 * Numerical Algorithms", 2nd ed. 2002, §2.2, the standard model).  Points
 * closer than δ (about 1e-13 of a cell here) to a face march. */
static int ray_is_regular(const phc_climbing_light_grid *g, int a, double xa)
{
    const double o = g->origin[a], h = g->cell, dims = (double)g->dims[a];
    const double q = (xa - o) / h;
    const double f = q - (double)(size_t)q; /* exact: 0 <= q < dims */
    const double u = DBL_EPSILON / 2;
    const double M = fabs(xa) + fabs(o) + (dims + 1) * h;
    const double delta = 16 * u * (M / h + dims + 1);
    return f > delta && f < 1 - delta;
}

/* The grid's lines of cells along the light's axis a (ℓ = ±e_a): a ray
 * from a cell runs along its line toward the light. */
typedef struct light_lines {
    int axis;
    int toward_plus; /* ℓ = +e_a: the ray runs toward higher cell coordinates */
    size_t n;        /* cells per line: dims[a] */
    size_t stride;   /* index step between neighbours along a */
    size_t count;    /* lines: cells / n */
} light_lines;

static light_lines lines_of(const phc_climbing_light_grid *g, int a)
{
    light_lines L = {a, g->direction[a] > 0, g->dims[a], 1, 0};
    for (int d = 0; d < a; ++d)
        L.stride *= g->dims[d];
    L.count = phc_climbing_light_cells(g) / L.n;
    return L;
}

/* The line through cell c. */
static size_t line_of(const light_lines *L, size_t c)
{
    return c % L->stride + c / (L->stride * L->n) * L->stride;
}

/* Cell of line `line` at step t of the march (t = 0 the cell farthest from
 * the light, t = n − 1 the one nearest to it). */
static size_t line_cell(const light_lines *L, size_t line, size_t t)
{
    const size_t z = L->toward_plus ? t : L->n - 1 - t;
    return line % L->stride + line / L->stride * L->stride * L->n + z * L->stride;
}

/* Replaces φ along one line of cells by the light a regular ray from each
 * cell receives, light_of(D(t)) with the depth D(t) = Σ_{t' > t} φ(t') h
 * summed in the march's order (t + 1 first) as light_marched sums it, so
 * the light is bit for bit the marched one.  Empty cells add exact zeros
 * and are skipped: with m filled cells the line costs O(m² + n) additions
 * and m + 1 exponentials.  phi_line, nonzero (n each) and partial (n + 1)
 * are scratch. */
static void line_light(const phc_climbing_light_grid *g, const light_lines *L, size_t line,
                       double *phi, double *phi_line, size_t *nonzero, double *partial)
{
    size_t m = 0;
    for (size_t t = 0; t < L->n; ++t) {
        phi_line[t] = phi[line_cell(L, line, t)];
        if (phi_line[t] != 0)
            nonzero[m++] = t;
    }
    /* partial[j]: the light behind the filled cells nonzero[j..m-1] */
    for (size_t j = 0; j <= m; ++j) {
        double depth = 0;
        for (size_t r = j; r < m; ++r)
            depth += phi_line[nonzero[r]] * g->cell;
        partial[j] = light_of(g, 0, depth);
    }
    size_t j = 0; /* the first filled cell beyond t */
    for (size_t t = 0; t < L->n; ++t) {
        while (j < m && nonzero[j] <= t)
            ++j;
        phi[line_cell(L, line, t)] = partial[j];
    }
}

/* Below this many points the light runs on one thread: a parallel region
 * (a few tens of µs to wake a sleeping thread, more when other programs
 * hold the cores) costs more than it saves. */
#define PHC_CLIMBING_LIGHT_PARALLEL_MIN 16384

/* While the light is computed, light[i] < 0 holds point i's own cell c as
 * −1 − c (exact below 2⁵³) until its light replaces it. */
static double pending(size_t c) { return -1 - (double)c; }
static size_t pending_cell(double v) { return (size_t)(-1 - v); }

/* One light computation: its inputs and, for light along the grid axis
 * axis (−1: another direction, every point marches), the lines, the lines
 * to process and per thread a line's φ and partial sums (2n + 1) and its
 * filled cells (n). */
typedef struct light_run {
    const phc_climbing_light_grid *g;
    const phc_climbing_occluders *occ;
    const unsigned char *opaque;
    const double *x, *vol;
    size_t n;
    double *phi, *light;
    int axis;
    light_lines L;
    unsigned char *wanted;
    double *sums;
    size_t *filled;
    int keep_zero;          /* φ is all zero on entry and is left so (not cleared first) */
    unsigned char *touched; /* with keep_zero: the lines holding a point that marched */
} light_run;

/* Point i of a light along the axis, before the lines: a point near a face
 * or in a shadowed line marches (φ still the volume fractions); the others
 * mark their line. */
static void classify_point(const light_run *r, size_t i)
{
    if (!(r->light[i] < 0))
        return;
    const light_lines *L = &r->L;
    const double *xi = r->x + 3 * i;
    const size_t c = pending_cell(r->light[i]), line = line_of(L, c);
    int march = !ray_is_regular(r->g, r->axis, xi[r->axis]);
    if (!march && r->opaque) { /* an opaque cell on the way: the exact test */
        const size_t z = c / L->stride % L->n;
        for (size_t t = L->toward_plus ? z : L->n - 1 - z; t < L->n && !march; ++t)
            march = r->opaque[line_cell(L, line, t)];
    }
    if (march) {
        r->light[i] = light_marched(r->g, r->occ, r->opaque, r->phi, xi, c);
        if (r->touched) {
#pragma omp atomic write
            r->touched[line] = 1;
        }
        return;
    }
#pragma omp atomic write
    r->wanted[line] = 1;
}

/* φ = 0 in every cell, in blocks shared by the team (a worksharing loop,
 * as light_passes' loops). */
static void clear_grid(const phc_climbing_light_grid *g, double *phi)
{
    const size_t cells = phc_climbing_light_cells(g), block = 4096;
#pragma omp for schedule(static)
    for (size_t b = 0; b < cells; b += block)
        memset(phi + b, 0, (cells - b < block ? cells - b : block) * sizeof *phi);
}

/* The passes of one light computation.  Its loops are OpenMP worksharing
 * loops: inside a parallel region the team shares them (each point's and
 * each line's result its own, the deposit into φ on one thread in the
 * points' order), outside one the calling thread runs them all. */
static void light_passes(const light_run *r)
{
    const phc_climbing_light_grid *g = r->g;
    const int absorb = g->extinction > 0;
    const size_t n = r->n;
    double *light = r->light, *phi = r->phi;
    /* own cells (outside the grid: full light) */
#pragma omp for schedule(static)
    for (size_t i = 0; i < n; ++i) {
        const size_t c = cell_of(g, r->x + 3 * i);
        light[i] = c == (size_t)-1 ? 1 : pending(c);
    }
    if (absorb) { /* φ: in the points' order, so the sums are reproducible */
        if (!r->keep_zero)
            clear_grid(g, phi);
#pragma omp single
        {
            const double h3 = g->cell * g->cell * g->cell;
            for (size_t i = 0; i < n; ++i)
                if (light[i] < 0)
                    phi[pending_cell(light[i])] += r->vol[i] / h3;
        }
    }
    if (r->axis < 0) { /* every point marches */
#pragma omp for schedule(dynamic, 256)
        for (size_t i = 0; i < n; ++i)
            if (light[i] < 0)
                light[i] = light_marched(g, r->occ, r->opaque, phi, r->x + 3 * i,
                                         pending_cell(light[i]));
        if (absorb && r->keep_zero)
            clear_grid(g, phi);
        return;
    }
    /* along the axis: 1. the points that march, the lines wanted */
#pragma omp for schedule(static)
    for (size_t i = 0; i < n; ++i)
        classify_point(r, i);
    /* 2. the light along the lines that hold a regular point */
    if (absorb) {
        const size_t tid = (size_t)omp_get_thread_num(), len = r->L.n;
        double *phi_line = r->sums + tid * (2 * len + 1), *partial = phi_line + len;
        size_t *nonzero = r->filled + tid * len;
#pragma omp for schedule(dynamic, 64)
        for (size_t line = 0; line < r->L.count; ++line)
            if (r->wanted[line])
                line_light(g, &r->L, line, phi, phi_line, nonzero, partial);
    }
    /* 3. the regular points: their line's light */
    const double unshaded = light_of(g, 0, 0);
#pragma omp for schedule(static)
    for (size_t i = 0; i < n; ++i)
        if (light[i] < 0)
            light[i] = absorb ? phi[pending_cell(light[i])] : unshaded;
    /* 4. φ left all zero: only the lines written (a point's deposit, the
       light of a wanted line) hold non-zeros */
    if (absorb && r->keep_zero) {
#pragma omp for schedule(static)
        for (size_t line = 0; line < r->L.count; ++line)
            if (r->wanted[line] || r->touched[line])
                for (size_t t = 0; t < r->L.n; ++t)
                    phi[line_cell(&r->L, line, t)] = 0;
    }
}

static void light_shaded(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                         const double *x, const double *vol, size_t n, double *phi, double *light,
                         int keep_zero)
{
    const unsigned char *opaque = occ && occ->nt ? occ->mask : NULL;
    if (!(g->extinction > 0) && !opaque) {
        for (size_t i = 0; i < n; ++i)
            light[i] = 1;
        return;
    }
    light_run r = {g, occ, opaque, x, vol, n, phi, light, light_axis(g), {0}, NULL, NULL, NULL,
                   keep_zero, NULL};
    if (!(g->cell > 0) || phc_climbing_light_cells(g) == 0)
        r.axis = -1; /* outside the header's preconditions: march as the definition does */
    if (r.axis >= 0) { /* its scratch; without it every point marches */
        const size_t threads = (size_t)omp_get_max_threads();
        r.L = lines_of(g, r.axis);
        r.wanted = calloc(r.L.count, 1);
        r.sums = malloc(threads * (2 * r.L.n + 1) * sizeof *r.sums);
        r.filled = malloc(threads * r.L.n * sizeof *r.filled);
        if (keep_zero)
            r.touched = calloc(r.L.count, 1);
        if (!r.wanted || !r.sums || !r.filled || (keep_zero && !r.touched))
            r.axis = -1;
    }
    /* a parallel region only for enough points: waking the threads costs
       tens of µs */
    if (n >= PHC_CLIMBING_LIGHT_PARALLEL_MIN && omp_get_level() == 0) {
#pragma omp parallel
        light_passes(&r);
    } else {
        light_passes(&r);
    }
    free(r.wanted);
    free(r.sums);
    free(r.filled);
    free(r.touched);
}

void phc_climbing_light_shaded(const phc_climbing_light_grid *g, const phc_climbing_occluders *occ,
                               const double *x, const double *vol, size_t n, double *phi,
                               double *light)
{
    light_shaded(g, occ, x, vol, n, phi, light, 0);
}

void phc_climbing_light_shaded_zeroed(const phc_climbing_light_grid *g,
                                      const phc_climbing_occluders *occ, const double *x,
                                      const double *vol, size_t n, double *phi, double *light)
{
    light_shaded(g, occ, x, vol, n, phi, light, 1);
}
