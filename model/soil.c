/* Soil water and nutrients (Rhizomorph §6): see soil.h. */
#include "model/soil.h"

#include "model/big_array.h"

#include <ctype.h>
#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <stdlib.h>
#include <string.h>

/* Grids smaller than this run their loops on one thread.  Measured on an
 * idle 2-core machine: the soil_probe example (3000 voxels) fits in 2.55 s
 * with parallel loops against 4.5 s serial, while the Fig. 7 notebook's
 * 200-voxel columns take 0.12 s parallel against 0.10 s serial.  (With
 * other processes busy on the cores, parallel regions on small grids were
 * far slower: that example's fit once took 39 s.) */
#ifndef PHC_SOIL_PARALLEL_MIN
#define PHC_SOIL_PARALLEL_MIN 2048
#endif

/* Most water-only sub-steps one sweep over the grid takes when nothing
 * else acts between them (params.block_steps = 0: see block_levels). */
#ifndef PHC_SOIL_BLOCK_STEPS
#define PHC_SOIL_BLOCK_STEPS 4
#endif
/* The same when every plane is swept from w alone (block_levels). */
#ifndef PHC_SOIL_BLOCK_STEPS_FROM_W
#define PHC_SOIL_BLOCK_STEPS_FROM_W 8
#endif

/* The bytes of cache a sweep's planes should fit in (block_levels): 3/4 of
 * the 1 MiB L2 cache per core of the machine the bench runs on. */
#ifndef PHC_SOIL_CACHE_BYTES
#define PHC_SOIL_CACHE_BYTES (768.0 * 1024.0)
#endif

/* GCC function multiversioning for the water sweep's row loops: the build
 * targets baseline x86-64 (SSE2, 2 doubles per instruction); on x86-64 an
 * AVX2 copy (4 doubles) is compiled beside it and chosen at load time by
 * the CPU.  AVX2 does not imply FMA and the C11 build does not contract
 * a * b + c, so both copies round every operation alike: the same numbers
 * to the last bit.  An AVX-512F copy (8 doubles) of these loops measured
 * the same as AVX2 on the bench's machine (AMD EPYC, 1 thread, CPU time, 3
 * alternating runs, load average 5.9 on 2 CPUs: 64^3 5.2e8-6.0e8 voxel
 * updates/s against 5.3e8-6.5e8, 128^3 4.7e8-4.8e8 against 4.6e8-4.9e8)
 * and is not built for them.  The loops of the planes swept from w alone
 * (water_plane_from_w) stream two fields instead of ten and are bound by
 * arithmetic, not by the caches: they have an AVX-512F copy too
 * (PHC_SOIL_CLONES_512; AVX-512F does not bring FMA either).  Measured on
 * the same machine (1 thread, CPU time, 3 alternating runs, the bench
 * soil): 64^3 1.84e9-1.93e9 voxel updates/s against 1.05e9-1.09e9 with
 * AVX2, 128^3 1.20e9-1.24e9 against 8.8e8-9.0e8. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(PHC_SOIL_NO_CLONES)
#define PHC_SOIL_CLONES __attribute__((target_clones("avx2", "default")))
#define PHC_SOIL_CLONES_512 __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define PHC_SOIL_CLONES
#define PHC_SOIL_CLONES_512
#endif

struct phc_soil_work {
    double *w_new, *v_new;     /* next state */
    double *ic;                /* 1 / c */
    double *kx, *ky, *kz;      /* face permeability (harmonic mean) to the +x, +y, +z
                                  neighbour (wrapped); 0 across closed box faces */
    double *sink_w, *sink_v;   /* sink hook buffers */
    double *ring;              /* transport_water's plane rings, ring_per_thread each */
    size_t ring_per_thread, ring_threads;
    double *plane;             /* nz partial sums (or minima) */
    size_t *plane_at;          /* nz: the voxel of each plane's minimum (stable_dt_prepared) */
    unsigned char *uniform;    /* nz: 1 when plane k has one 1/c, one p and one permeability per
                                  face direction (plane_uniform) */
    double *uniform_of;        /* 5 nz: those values of plane k: 1/c, p, kx, ky, kz */
    unsigned char *layer;      /* nz: 1 when plane k has one 1/c and p in {0, one value} (plane_layer) */
    double *layer_of;          /* 4 nz: 1/c, the nonzero p (or 0), harmonic(p, p) and the +z face
                                  permeability between two such voxels (0 across a closed face) */
    unsigned char *from_w;     /* nz: 1 when plane k and both its neighbours are uniform, 2 when they are
                                  layer planes and not all uniform; x faces closed, ny >= 2: its water
                                  sub-steps take w (and p for 2) alone (water_plane_from_w) */
    unsigned char *fill;       /* nz: 1 when a neighbour or plane k itself is not from_w: the sweep
                                  makes plane k's fill l and g (fill_plane) */
    long *top;                 /* nx ny: highest permeable k of each column, -1 none */
    double *damp_x, *damp_y, *damp_z; /* absorbing factor per index at the current h */
    double damp_h;             /* h the damping factors were raised for */
    int damp_xy_one;           /* 1 when every damp_x and damp_y factor is 1 */
    double *src_w;             /* per source: normalised weights over its voxels */
    size_t *src_idx, *src_first, src_total;
    int nutrients;             /* 1 when nutrients move */
    int all_from_w;            /* 1 when every plane is from_w */
};

static size_t idx3(const phc_soil *s, size_t i, size_t j, size_t k)
{
    return i + s->nx * (j + s->ny * k);
}

phc_soil_params phc_soil_params_default(void)
{
    phc_soil_params p;
    memset(&p, 0, sizeof p);
    p.f_diff = 1.0;
    p.f_grav = 1.0;
    p.f_nutrient = 1.0;
    for (int f = 0; f < PHC_SOIL_FACES; ++f)
        p.boundary[f] = PHC_SOIL_BLOCK;
    p.absorb_form = PHC_SOIL_ABSORB_CODE;
    p.absorb_width = 5;
    p.dt = 0.001; /* h: SoilParameters::m_deltaTime */
    p.substep = 1;
    p.safety = 0.9;
    p.gravity = PHC_SOIL_GRAVITY_LAX_WENDROFF;
    return p;
}

static void work_free(phc_soil_work *wk)
{
    if (!wk)
        return;
    free(wk->w_new);
    free(wk->v_new);
    free(wk->ic);
    free(wk->kx);
    free(wk->ky);
    free(wk->kz);
    free(wk->sink_w);
    free(wk->sink_v);
    free(wk->ring);
    free(wk->plane);
    free(wk->plane_at);
    free(wk->uniform);
    free(wk->uniform_of);
    free(wk->from_w);
    free(wk->layer);
    free(wk->layer_of);
    free(wk->fill);
    free(wk->top);
    free(wk->damp_x);
    free(wk->damp_y);
    free(wk->damp_z);
    free(wk->src_w);
    free(wk->src_idx);
    free(wk->src_first);
    free(wk);
}

/* Bytes a voxel field's start is aligned to: a cache line, so that the
 * water sweep's vector loads of a row run (water_plane) do not each
 * straddle two lines.  Measured on the bench's machine (AMD EPYC, AVX2
 * copy of water_rows, 1 thread, CPU time, 3 runs, arrays in L1 cache):
 * 1.25e9-1.32e9 voxel updates/s with the loads aligned against
 * 1.02e9-1.13e9 with them 8 or 16 bytes off (fill_plane: 8.1e9-9.2e9
 * against 5.4e9-5.5e9). */
#define PHC_SOIL_ALIGN 64

/* n doubles starting on a PHC_SOIL_ALIGN boundary (zeroed with `zero`),
 * freed by free(); NULL when out of memory.  From 2 MiB up in transparent
 * huge pages where the system allows them (phc_big_array_grow, aligned to
 * 2 MiB): the 128^3 bench soil's fields and rings span 130 MB, 33000 pages
 * of 4 KiB, and a sweep streams eight of them side by side.  Measured, 1
 * thread, CPU time, 3 alternating runs each (load average 5 on 2 CPUs):
 * 128^3 5.05e8-5.30e8 voxel updates/s in huge pages against 4.62e8-4.77e8
 * without; 64^3 (14 MB) 5.9e8-7.3e8 against 5.6e8-7.2e8. */
static double *field_alloc(size_t n, int zero)
{
    const size_t a = PHC_SOIL_ALIGN / sizeof(double);
    if (n > SIZE_MAX / sizeof(double) - a)
        return NULL;
    const size_t bytes = (n + a - 1) / a * a * sizeof(double);
    double *f = bytes >= ((size_t)2 << 20) ? phc_big_array_grow(NULL, 0, bytes)
                                           : aligned_alloc(PHC_SOIL_ALIGN, bytes ? bytes : PHC_SOIL_ALIGN);
    if (f && zero)
        memset(f, 0, bytes);
    return f;
}

phc_soil *phc_soil_new(size_t nx, size_t ny, size_t nz, double dx)
{
    if (!nx || !ny || !nz || !(dx > 0) || !isfinite(dx) || nx > SIZE_MAX / ny / nz)
        return NULL;
    phc_soil *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->nx = nx;
    s->ny = ny;
    s->nz = nz;
    s->n = nx * ny * nz;
    s->dx = dx;
    s->params = phc_soil_params_default();
    size_t n = s->n;
    s->w = field_alloc(n, 1);
    s->v = field_alloc(n, 1);
    s->c = field_alloc(n, 0);
    s->p = field_alloc(n, 1);
    s->d = field_alloc(n, 0);
    s->work = calloc(1, sizeof *s->work);
    phc_soil_work *wk = s->work;
    if (!s->w || !s->v || !s->c || !s->p || !s->d || !wk) {
        phc_soil_free(s);
        return NULL;
    }
    wk->w_new = field_alloc(n, 0);
    wk->v_new = field_alloc(n, 0);
    wk->ic = field_alloc(n, 0);
    wk->kx = field_alloc(n, 0);
    wk->ky = field_alloc(n, 0);
    wk->kz = field_alloc(n, 0);
    wk->plane = malloc(nz * sizeof(double));
    wk->plane_at = malloc(nz * sizeof(size_t));
    wk->uniform = malloc(nz);
    wk->uniform_of = malloc(5 * nz * sizeof(double));
    wk->from_w = malloc(nz);
    wk->layer = malloc(nz);
    wk->layer_of = malloc(4 * nz * sizeof(double));
    wk->fill = malloc(nz);
    wk->top = malloc(nx * ny * sizeof(long));
    wk->damp_x = malloc(nx * sizeof(double));
    wk->damp_y = malloc(ny * sizeof(double));
    wk->damp_z = malloc(nz * sizeof(double));
    if (!wk->w_new || !wk->v_new || !wk->ic || !wk->kx || !wk->ky || !wk->kz || !wk->plane || !wk->plane_at ||
        !wk->uniform || !wk->uniform_of || !wk->from_w || !wk->layer || !wk->layer_of || !wk->fill || !wk->top || !wk->damp_x || !wk->damp_y || !wk->damp_z) {
        phc_soil_free(s);
        return NULL;
    }
    for (size_t i = 0; i < n; ++i) {
        s->c[i] = 1.0;
        s->d[i] = 1.0;
    }
    return s;
}

void phc_soil_free(phc_soil *s)
{
    if (!s)
        return;
    free(s->w);
    free(s->v);
    free(s->c);
    free(s->p);
    free(s->d);
    free(s->rain);
    free(s->sources);
    work_free(s->work);
    free(s);
}

/* ---- presets ----------------------------------------------------------- */

/* Rhizomorph Fig. 7 (quoted in shared/data/README.md): capacity, permeability. */
static const struct { const char *name; double c, p; } presets[] = {
    {"clay", 10, 0.0015},           {"clay_loam", 5, 0.0015},  {"sandy_clay_loam", 75, 0.033},
    {"sandy_loam", 150, 0.5},       {"silt_loam", 100, 0.5},   {"silt", 50, 0.033},
};
#define N_PRESETS (sizeof presets / sizeof presets[0])

const char *phc_soil_preset_name(size_t i)
{
    return i < N_PRESETS ? presets[i].name : NULL;
}

int phc_soil_preset(const char *name, double *c, double *p)
{
    char key[64];
    size_t m = 0;
    for (; name && name[m] && m + 1 < sizeof key; ++m) {
        char ch = (char)tolower((unsigned char)name[m]);
        key[m] = (ch == ' ' || ch == '-') ? '_' : ch;
    }
    key[m] = '\0';
    for (size_t i = 0; i < N_PRESETS; ++i)
        if (!strcmp(key, presets[i].name)) {
            *c = presets[i].c;
            *p = presets[i].p;
            return PHC_OK;
        }
    return PHC_ERR_INPUT;
}

/* ---- layers ------------------------------------------------------------ */

void phc_soil_layer_of_planes(const phc_soil *s, const phc_soil_layer *layers, size_t n,
                              size_t *layer_of_k)
{
    for (size_t k = 0; k < s->nz; ++k) {
        double depth = ((double)(s->nz - 1 - k) + 0.5) * s->dx; /* centre below the top */
        double bottom = 0;
        size_t L = 0;
        for (; L < n; ++L) {
            if (layers[L].thickness <= 0 || L + 1 == n)
                break;
            bottom += layers[L].thickness;
            if (depth < bottom)
                break;
        }
        layer_of_k[k] = L < n ? L : n - 1;
    }
}

int phc_soil_layer_check(const phc_soil_layer *l, size_t index, int last, phc_error *err)
{
    if (!isfinite(l->thickness) || !isfinite(l->c) || !isfinite(l->p) || !isfinite(l->d) || !isfinite(l->water) ||
        !isfinite(l->fill) || !isfinite(l->nutrient))
        return phc_error_set(err, PHC_ERR_INPUT, "soil layer %zu: a value is not finite", index);
    if (!(l->c > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "soil layer %zu: the capacity must be c > 0, found %g", index, l->c);
    if (l->p < 0)
        return phc_error_set(err, PHC_ERR_INPUT, "soil layer %zu: the permeability must be p >= 0 (m/h), found %g", index,
                             l->p);
    if (l->d < 0)
        return phc_error_set(err, PHC_ERR_INPUT, "soil layer %zu: growth resistance d must be >= 0, found %g",
                             index, l->d);
    if ((l->fill < 0 && l->water < 0) || l->nutrient < 0)
        return phc_error_set(err, PHC_ERR_INPUT, "soil layer %zu: initial water and nutrients must be >= 0", index);
    if (l->thickness <= 0 && !last)
        return phc_error_set(err, PHC_ERR_INPUT, "soil layer %zu: only the last layer may have no thickness", index);
    return PHC_OK;
}

int phc_soil_set_layers(phc_soil *s, const phc_soil_layer *layers, size_t n, phc_error *err)
{
    if (!n)
        return phc_error_set(err, PHC_ERR_INPUT, "soil: no layers given");
    for (size_t L = 0; L < n; ++L) {
        int rc = phc_soil_layer_check(&layers[L], L + 1, L + 1 == n, err);
        if (rc)
            return rc;
    }
    size_t *of_k = malloc(s->nz * sizeof *of_k);
    if (!of_k)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    phc_soil_layer_of_planes(s, layers, n, of_k);
    size_t plane = s->nx * s->ny;
    for (size_t k = 0; k < s->nz; ++k) {
        const phc_soil_layer *l = &layers[of_k[k]];
        double w0 = l->fill >= 0 ? l->fill * l->c : l->water;
        for (size_t q = 0; q < plane; ++q) {
            size_t i = q + plane * k;
            s->c[i] = l->c;
            s->p[i] = l->p;
            s->d[i] = l->d;
            s->w[i] = w0;
            s->v[i] = l->nutrient;
        }
    }
    free(of_k);
    return PHC_OK;
}

/* ---- noise ------------------------------------------------------------- */

static uint64_t splitmix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

static double lattice(uint64_t seed, long ix, long iy, long iz)
{
    uint64_t h = splitmix64(seed);
    h = splitmix64(h ^ (uint64_t)ix);
    h = splitmix64(h ^ (uint64_t)iy);
    h = splitmix64(h ^ (uint64_t)iz);
    return (double)(h >> 11) * 0x1.0p-53;
}

double phc_soil_noise(uint64_t seed, double scale, double x, double y, double z)
{
    double fx = x / scale, fy = y / scale, fz = z / scale;
    double x0 = floor(fx), y0 = floor(fy), z0 = floor(fz);
    double tx = fx - x0, ty = fy - y0, tz = fz - z0;
    long ix = (long)x0, iy = (long)y0, iz = (long)z0;
    double r = 0;
    for (int c = 0; c < 8; ++c) {
        int a = c & 1, b = (c >> 1) & 1, e = (c >> 2) & 1;
        double wgt = (a ? tx : 1 - tx) * (b ? ty : 1 - ty) * (e ? tz : 1 - tz);
        r += wgt * lattice(seed, ix + a, iy + b, iz + e);
    }
    return r;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Marks the `fraction` of voxels with the highest noise: returns a threshold
 * and fills vals (n) with the noise of every voxel centre. */
static double noise_threshold(const phc_soil *s, uint64_t seed, double scale, double fraction,
                              double *vals, double *sorted)
{
    for (size_t k = 0; k < s->nz; ++k)
        for (size_t j = 0; j < s->ny; ++j)
            for (size_t i = 0; i < s->nx; ++i)
                vals[idx3(s, i, j, k)] = phc_soil_noise(seed, scale, (i + 0.5) * s->dx,
                                                        (j + 0.5) * s->dx, (k + 0.5) * s->dx);
    memcpy(sorted, vals, s->n * sizeof *vals);
    qsort(sorted, s->n, sizeof *sorted, cmp_double);
    size_t keep = (size_t)llround((1.0 - fraction) * (double)s->n);
    return keep >= s->n ? INFINITY : sorted[keep];
}

static size_t noise_apply(phc_soil *s, uint64_t seed, double scale, double fraction, int rocks,
                          double amount)
{
    if (!(fraction > 0) || !(scale > 0))
        return 0;
    double *vals = malloc(s->n * sizeof *vals), *sorted = malloc(s->n * sizeof *sorted);
    size_t count = 0;
    if (vals && sorted) {
        double thr = noise_threshold(s, seed, scale, fraction > 1 ? 1 : fraction, vals, sorted);
        for (size_t i = 0; i < s->n; ++i)
            if (vals[i] >= thr) {
                if (rocks)
                    s->p[i] = 0;
                else
                    s->v[i] += amount;
                ++count;
            }
    }
    free(vals);
    free(sorted);
    return count;
}

size_t phc_soil_add_rocks(phc_soil *s, uint64_t seed, double scale, double fraction)
{
    return noise_apply(s, seed, scale, fraction, 1, 0);
}

size_t phc_soil_add_nutrient_pockets(phc_soil *s, uint64_t seed, double scale, double fraction,
                                     double amount)
{
    return noise_apply(s, seed, scale, fraction, 0, amount);
}

/* ---- sources ----------------------------------------------------------- */

/* A malloc'd copy of n items of `size` bytes (NULL for n = 0); *ok = 0
 * when out of memory. */
static void *copy_items(const void *src, size_t n, size_t size, int *ok)
{
    void *copy = n ? malloc(n * size) : NULL;
    *ok = !n || copy;
    if (copy)
        memcpy(copy, src, n * size);
    return copy;
}

int phc_soil_set_rain(phc_soil *s, const phc_soil_rain *rain, size_t n, phc_error *err)
{
    for (size_t r = 0; r < n; ++r)
        if (!(rain[r].rate >= 0) || !(rain[r].end >= rain[r].start) || !(rain[r].nutrient >= 0) ||
            !isfinite(rain[r].rate) || !isfinite(rain[r].start) || !isfinite(rain[r].end))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "rain %zu: needs rate >= 0, nutrient >= 0 and start <= end (found rate %g, "
                                 "start %g h, end %g h)", r + 1, rain[r].rate, rain[r].start, rain[r].end);
    int ok;
    phc_soil_rain *copy = copy_items(rain, n, sizeof *rain, &ok);
    if (!ok)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    free(s->rain);
    s->rain = copy;
    s->n_rain = n;
    return PHC_OK;
}

int phc_soil_set_sources(phc_soil *s, const phc_soil_source *src, size_t n, phc_error *err)
{
    double ext[3] = {s->nx * s->dx, s->ny * s->dx, s->nz * s->dx};
    for (size_t q = 0; q < n; ++q) {
        const double pos[3] = {src[q].x, src[q].y, src[q].z};
        for (int a = 0; a < 3; ++a)
            if (!(pos[a] >= 0 && pos[a] < ext[a]))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "source %zu: (%g, %g, %g) m is outside the soil box "
                                     "[0, %g) x [0, %g) x [0, %g) m", q + 1, pos[0], pos[1], pos[2],
                                     ext[0], ext[1], ext[2]);
        if (!(src[q].radius >= 0) || !(src[q].end >= src[q].start) || !isfinite(src[q].water_rate) ||
            !isfinite(src[q].nutrient_rate))
            return phc_error_set(err, PHC_ERR_INPUT, "source %zu: needs radius >= 0, start <= end and "
                                 "finite rates", q + 1);
    }
    int ok;
    phc_soil_source *copy = copy_items(src, n, sizeof *src, &ok);
    if (!ok)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    free(s->sources);
    s->sources = copy;
    s->n_sources = n;
    return PHC_OK;
}

/* Voxels and normalised weights of every source (Gaussian, sigma = radius/3,
 * cut at the radius; the voxel holding the point when radius < dx/2). */
static int prepare_sources(phc_soil *s)
{
    phc_soil_work *wk = s->work;
    free(wk->src_w);
    free(wk->src_idx);
    free(wk->src_first);
    wk->src_w = NULL;
    wk->src_idx = NULL;
    wk->src_first = calloc(s->n_sources + 1, sizeof *wk->src_first);
    if (!wk->src_first)
        return PHC_ERR_NOMEM;
    size_t total = 0, cap = 0;
    for (size_t q = 0; q < s->n_sources; ++q) {
        const phc_soil_source *src = &s->sources[q];
        double rad = src->radius < 0.5 * s->dx ? 0 : src->radius;
        long c[3] = {(long)(src->x / s->dx), (long)(src->y / s->dx), (long)(src->z / s->dx)};
        long r = (long)ceil(rad / s->dx);
        long lo[3], hi[3], lim[3] = {(long)s->nx, (long)s->ny, (long)s->nz};
        for (int a = 0; a < 3; ++a) {
            lo[a] = c[a] - r < 0 ? 0 : c[a] - r;
            hi[a] = c[a] + r >= lim[a] ? lim[a] - 1 : c[a] + r;
        }
        size_t first = total;
        double sum = 0, sig = rad / 3.0;
        for (long k = lo[2]; k <= hi[2]; ++k)
            for (long j = lo[1]; j <= hi[1]; ++j)
                for (long i = lo[0]; i <= hi[0]; ++i) {
                    double ddx = (i + 0.5) * s->dx - src->x, ddy = (j + 0.5) * s->dx - src->y,
                           ddz = (k + 0.5) * s->dx - src->z;
                    double r2 = ddx * ddx + ddy * ddy + ddz * ddz;
                    double wgt = rad == 0 ? 1.0 : (r2 <= rad * rad ? exp(-r2 / (2 * sig * sig)) : 0);
                    if (wgt <= 0)
                        continue;
                    if (total == cap) {
                        cap = cap ? 2 * cap : 64;
                        double *nw = realloc(wk->src_w, cap * sizeof *nw);
                        if (!nw)
                            return PHC_ERR_NOMEM;
                        wk->src_w = nw;
                        size_t *ni = realloc(wk->src_idx, cap * sizeof *ni);
                        if (!ni)
                            return PHC_ERR_NOMEM;
                        wk->src_idx = ni;
                    }
                    wk->src_w[total] = wgt;
                    wk->src_idx[total] = idx3(s, (size_t)i, (size_t)j, (size_t)k);
                    sum += wgt;
                    ++total;
                }
        for (size_t e = first; e < total; ++e)
            wk->src_w[e] /= sum;
        wk->src_first[q + 1] = total;
    }
    wk->src_total = total;
    return PHC_OK;
}

/* Length of the overlap of [a, b) with [c, d). */
static double overlap(double a, double b, double c, double d)
{
    double lo = a > c ? a : c, hi = b < d ? b : d;
    return hi > lo ? hi - lo : 0;
}

/* ---- checks and set-up ------------------------------------------------- */

/* 1 when every voxel passes check_impl's tests (c finite and > 0, p
 * finite and >= 0, w and v finite, and >= 0 when `strict`): one pass
 * without branches per plane, so that it vectorises; check_impl looks for
 * the voxel to name only when one fails.  (x - x is 0 for finite x and NaN
 * for an infinity or NaN, so x - x == 0 tests finiteness.) */
PHC_SOIL_CLONES_512
static int plane_valid(size_t m, const double *restrict c, const double *restrict p, const double *restrict w,
                       const double *restrict v, int strict)
{
    /* w and v compared with 0 only when strict: lo = -inf accepts any
       finite value */
    const double lo = strict ? 0.0 : -INFINITY;
    long bad = 0;
    for (size_t q = 0; q < m; ++q)
        bad += !(c[q] > 0) | !(c[q] - c[q] == 0) | !(p[q] >= 0) | !(p[q] - p[q] == 0) | !(w[q] - w[q] == 0) |
               !(v[q] - v[q] == 0) | !(w[q] >= lo) | !(v[q] >= lo);
    return bad == 0;
}

static int fields_valid(const phc_soil *s, int strict)
{
    const size_t plane = s->nx * s->ny;
    int bad = 0;
#pragma omp parallel for schedule(static) reduction(| : bad) if (s->n >= PHC_SOIL_PARALLEL_MIN)
    for (size_t k = 0; k < s->nz; ++k)
        bad |= !plane_valid(plane, s->c + plane * k, s->p + plane * k, s->w + plane * k, s->v + plane * k, strict);
    return !bad;
}

static int check_impl(const phc_soil *s, int strict, phc_error *err)
{
    const phc_soil_params *pr = &s->params;
    if (!(pr->f_diff >= 0) || !isfinite(pr->f_diff))
        return phc_error_set(err, PHC_ERR_INPUT, "soil: f_diff must be finite and >= 0, found %g", pr->f_diff);
    if (!(pr->f_grav >= 0) || !isfinite(pr->f_grav))
        return phc_error_set(err, PHC_ERR_INPUT, "soil: f_grav must be finite and >= 0, found %g", pr->f_grav);
    if (!(pr->f_nutrient >= 0) || !isfinite(pr->f_nutrient))
        return phc_error_set(err, PHC_ERR_INPUT, "soil: f_nutrient must be finite and >= 0, found %g",
                             pr->f_nutrient);
    if (!(pr->dt > 0) || !isfinite(pr->dt))
        return phc_error_set(err, PHC_ERR_INPUT, "soil: the time step dt must be > 0, found %g h", pr->dt);
    if (pr->gravity != PHC_SOIL_GRAVITY_LAX_WENDROFF && pr->gravity != PHC_SOIL_GRAVITY_UPWIND)
        return phc_error_set(err, PHC_ERR_INPUT, "soil: unknown gravity scheme %d (0 Lax-Wendroff, 1 upwind)",
                             (int)pr->gravity);
    if (!(pr->absorb_dt >= 0) || !isfinite(pr->absorb_dt))
        return phc_error_set(err, PHC_ERR_INPUT, "soil: absorb_dt must be finite and >= 0 h, found %g",
                             pr->absorb_dt);
    if (!(pr->safety > 0 && pr->safety <= 1))
        return phc_error_set(err, PHC_ERR_INPUT, "soil: safety must be in (0, 1], found %g", pr->safety);
    size_t dims[3] = {s->nx, s->ny, s->nz};
    static const char *axis = "xyz";
    for (int f = 0; f < PHC_SOIL_FACES; ++f)
        if (pr->boundary[f] == PHC_SOIL_ABSORB &&
            (pr->absorb_width < 1 || (size_t)pr->absorb_width > dims[f / 2]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "soil: absorbing width %d does not fit the %zu voxels along %c",
                                 pr->absorb_width, dims[f / 2], axis[f / 2]);
    for (int a = 0; a < 3; ++a)
        if ((pr->boundary[2 * a] == PHC_SOIL_PERIODIC) != (pr->boundary[2 * a + 1] == PHC_SOIL_PERIODIC))
            return phc_error_set(err, PHC_ERR_INPUT, "soil: periodic boundaries come in pairs: both %c faces "
                                 "or neither", axis[a]);
    if (fields_valid(s, strict))
        return PHC_OK;
    for (size_t k = 0; k < s->nz; ++k)
        for (size_t j = 0; j < s->ny; ++j)
            for (size_t i = 0; i < s->nx; ++i) {
                size_t q = idx3(s, i, j, k);
                const char *what = NULL;
                double val = 0;
                if (!(s->c[q] > 0) || !isfinite(s->c[q]))
                    what = "capacity c must be finite and > 0", val = s->c[q];
                else if (!(s->p[q] >= 0) || !isfinite(s->p[q]))
                    what = "permeability p must be finite and >= 0", val = s->p[q];
                else if (!isfinite(s->w[q]) || (strict && !(s->w[q] >= 0)))
                    what = "water w must be finite and >= 0", val = s->w[q];
                else if (!isfinite(s->v[q]) || (strict && !(s->v[q] >= 0)))
                    what = "nutrients v must be finite and >= 0", val = s->v[q];
                if (what)
                    return phc_error_set(err, PHC_ERR_INPUT, "soil voxel (%zu, %zu, %zu): %s, found %g", i, j,
                                         k, what, val);
            }
    return PHC_OK;
}

int phc_soil_check(const phc_soil *s, phc_error *err)
{
    return check_impl(s, 1, err);
}

static double harmonic(double a, double b)
{
    return (a > 0 && b > 0) ? 2 * a * b / (a + b) : 0;
}

/* k = the face permeabilities harmonic(a, b) of m faces, or 0 when the
 * faces are closed (not `open`). */
static void face_permeabilities(size_t m, const double *restrict a, const double *restrict b, int open,
                                double *restrict k)
{
    if (open)
        for (size_t i = 0; i < m; ++i)
            k[i] = harmonic(a[i], b[i]);
    else
        for (size_t i = 0; i < m; ++i)
            k[i] = 0;
}

/* 1 when the doubles a[0..m) all have the bits of *v (m = 0: yes); one
 * pass without branches, so that it vectorises. */
static inline int all_bits(const double *restrict a, size_t m, const double *restrict v)
{
    uint64_t x, diff = 0;
    memcpy(&x, v, sizeof x);
    for (size_t i = 0; i < m; ++i) {
        uint64_t y;
        memcpy(&y, a + i, sizeof y);
        diff |= y ^ x;
    }
    return diff == 0;
}

/* Whether z-plane k (its 1/c, p and face permeabilities prepared) is
 * uniform: one 1/c and one p over the plane, one kx over the faces
 * inside its rows (not the +x face of a row's last voxel), one ky over
 * the faces between its rows (not the +y faces of the last row) and one
 * kz over the plane; those values in u (1/c, p, kx, ky, kz).  A soil made
 * of horizontal layers (phc_soil_set_layers) has only uniform planes; the
 * water sweep then takes these five numbers instead of streaming five
 * planes of them (water_rows_uniform). */
PHC_SOIL_CLONES_512
static int plane_uniform(const phc_soil *s, size_t k, double u[5])
{
    const phc_soil_work *wk = s->work;
    const size_t nx = s->nx, ny = s->ny, kq = nx * ny * k;
    u[0] = wk->ic[kq];
    u[1] = s->p[kq];
    u[2] = wk->kx[kq];
    u[3] = wk->ky[kq];
    u[4] = wk->kz[kq];
    if (!all_bits(wk->ic + kq, nx * ny, u) || !all_bits(s->p + kq, nx * ny, u + 1) ||
        !all_bits(wk->kz + kq, nx * ny, u + 4) || !all_bits(wk->ky + kq, nx * (ny - 1), u + 3))
        return 0;
    for (size_t j = 0; j < ny; ++j)
        if (!all_bits(wk->kx + kq + nx * j, nx - 1, u + 2))
            return 0;
    return 1;
}

/* Whether z-plane k is a layer plane: one 1/c (the bits of the first
 * voxel's) and p either 0 or one value pu (a layer with rocks,
 * phc_soil_add_rocks); then u[0] = 1/c, u[1] = pu (0 when the plane is
 * all rock) and u[2] = harmonic(pu, pu), the permeability of every face
 * between two of its voxels that are not rock (prepare_fields makes the
 * faces from the same harmonic on the same numbers, 0 where either voxel
 * is rock). */
PHC_SOIL_CLONES_512
static int plane_layer(const phc_soil *s, size_t k, double u[4])
{
    const size_t m = s->nx * s->ny, kq = m * k;
    const double *restrict p = s->p + kq;
    double pu = 0;
    for (size_t q = 0; q < m && pu == 0; ++q)
        pu = p[q];
    u[0] = s->work->ic[kq];
    u[1] = pu;
    u[2] = harmonic(pu, pu);
    long bad = 0;
    for (size_t q = 0; q < m; ++q)
        bad += p[q] != 0 && p[q] != pu;
    /* (pu > 0, so p == pu means the same bits; a rock's p may be -0, which
       every use treats as 0: harmonic, and f_grav p w only across faces
       with kz > 0) */
    return bad == 0 && all_bits(s->work->ic + kq, m, u);
}

/* 1/c and the face permeabilities of one z-plane (c, p, ic, kx, ky, kz
 * at its first voxel; p_up at the first voxel of the plane above,
 * wrapped): the +x faces of a row's last voxel, the +y faces of the last
 * row and the +z faces lead to the first voxel, row or plane (wrapped) and
 * are 0 unless that axis is periodic (xper, yper) or the z face open
 * (zopen).  By rows and planes, so that the divisions vectorise; with an
 * AVX-512F copy (PHC_SOIL_CLONES_512: run_call overhead, see
 * stable_dt_prepared). */
PHC_SOIL_CLONES_512
static void plane_fields(size_t nx, size_t ny, const double *restrict c, const double *restrict p,
                         const double *restrict p_up, int xper, int yper, int zopen, double *restrict ic,
                         double *restrict kx, double *restrict ky, double *restrict kz)
{
    const size_t plane = nx * ny;
    for (size_t q = 0; q < plane; ++q)
        ic[q] = 1.0 / c[q];
    for (size_t j = 0; j < ny; ++j) {
        const size_t r = nx * j, last = r + nx - 1;
        face_permeabilities(nx - 1, p + r, p + r + 1, 1, kx + r);
        kx[last] = xper ? harmonic(p[last], p[r]) : 0;
        face_permeabilities(nx, p + r, p + (j + 1 < ny ? r + nx : 0), j + 1 < ny || yper, ky + r);
    }
    face_permeabilities(plane, p, p_up, zopen, kz);
}

/* 1/c, face permeabilities, surface voxels of every column. */
static void prepare_fields(phc_soil *s)
{
    phc_soil_work *wk = s->work;
    const size_t nx = s->nx, ny = s->ny, nz = s->nz, plane = nx * ny;
    const phc_soil_boundary *b = s->params.boundary;
    int per[3] = {b[PHC_SOIL_XMIN] == PHC_SOIL_PERIODIC, b[PHC_SOIL_YMIN] == PHC_SOIL_PERIODIC,
                  b[PHC_SOIL_ZMIN] == PHC_SOIL_PERIODIC};
    const double *p = s->p;
#pragma omp parallel for schedule(static) if (s->n >= PHC_SOIL_PARALLEL_MIN)
    for (size_t k = 0; k < nz; ++k) {
        const size_t kq = plane * k;
        plane_fields(nx, ny, s->c + kq, p + kq, p + (k + 1 < nz ? kq + plane : 0), per[0], per[1],
                     k + 1 < nz || per[2], wk->ic + kq, wk->kx + kq, wk->ky + kq, wk->kz + kq);
        wk->uniform[k] = (unsigned char)plane_uniform(s, k, wk->uniform_of + 5 * k);
    }
    for (size_t k = 0; k < nz; ++k)
        wk->layer[k] = (unsigned char)plane_layer(s, k, wk->layer_of + 4 * k);
    for (size_t k = 0; k < nz; ++k) {
        double *lo = wk->layer_of + 4 * k;
        lo[3] = k + 1 < nz || per[2] ? harmonic(lo[1], wk->layer_of[4 * ((k + 1) % nz) + 1]) : 0;
    }
    for (size_t k = 0; k < nz; ++k) {
        const size_t kd = (k + nz - 1) % nz, ku = (k + 1) % nz;
        const int xy = !per[0] && ny >= 2;
        wk->from_w[k] = xy && wk->uniform[k] && wk->uniform[kd] && wk->uniform[ku]     ? 1
                        : xy && wk->layer[k] && wk->layer[kd] && wk->layer[ku] ? 2
                                                                                : 0;
    }
    wk->all_from_w = 1;
    for (size_t k = 0; k < nz; ++k) {
        wk->fill[k] = !wk->from_w[k] || !wk->from_w[(k + nz - 1) % nz] || !wk->from_w[(k + 1) % nz];
        wk->all_from_w &= wk->from_w[k] != 0;
    }
    for (size_t q = 0; q < plane; ++q) {
        long top = -1;
        for (long k = (long)nz - 1; k >= 0; --k)
            if (s->p[q + plane * (size_t)k] > 0) {
                top = k;
                break;
            }
        wk->top[q] = top;
    }
    int nut = 0;
    for (size_t r = 0; r < s->n_rain; ++r)
        nut |= s->rain[r].nutrient > 0;
    for (size_t q = 0; q < s->n_sources; ++q)
        nut |= s->sources[q].nutrient_rate != 0;
    for (size_t q = 0; q < s->n && !nut; ++q)
        nut |= s->v[q] > 0;
    wk->nutrients = nut;
    wk->damp_h = -1;
}

/* The stability limit of voxel q (p its permeability, ic its 1/c, sum
 * the sum of its six faces' permeabilities): the positive root of
 * a h^2 + b h = 1 with b = f_diff sum / (c dx^2), a = (f_grav p / dx)^2
 * (Lax-Wendroff), or 1 / (b + f_grav p / dx) with the upwind flux; +inf
 * where p = 0 or nothing moves. */
static inline double voxel_stable_dt(double p, double ic, double sum, double fd, double fg, double dx, double dx2,
                                     int up)
{
    const double bb = fd * sum * ic / dx2;
    const double g = fg * p / dx, a = g * g;
    const double h = up ? ((g > 0 || bb > 0) ? 1.0 / (bb + g) : INFINITY)
                        : ((a > 0 || bb > 0) ? 2.0 / (bb + sqrt(bb * bb + 4 * a)) : INFINITY);
    return p > 0 ? h : INFINITY;
}

/* The smallest stability limit of z-plane k and its first voxel (*at):
 * the limits of up to 256 voxels of a row at a time into a buffer, in a
 * loop that vectorises (the first voxel of a row, whose -x neighbour
 * wraps, on its own), then the first smallest.  The -x, -y, -z faces are
 * the +faces of the wrapped neighbours (0 across closed box faces).  With
 * an AVX-512F copy: 128^3 bench soil, a zero-length phc_soil_run (set-up:
 * check, plane_fields, this) 1 thread, best of 5: see README. */
PHC_SOIL_CLONES_512
static double plane_stable_dt(const phc_soil *s, size_t k, size_t *at)
{
    double h[256];
    const phc_soil_work *wk = s->work;
    const size_t nx = s->nx, ny = s->ny, plane = nx * ny, kq = plane * k;
    const double *restrict kx = wk->kx, *restrict ky = wk->ky, *restrict kz = wk->kz, *restrict ic = wk->ic,
                           *restrict p = s->p;
    const double fd = s->params.f_diff, fg = s->params.f_grav, dx = s->dx, dx2 = dx * dx;
    const int up = s->params.gravity == PHC_SOIL_GRAVITY_UPWIND;
    double best = INFINITY;
    *at = kq;
    for (size_t j = 0; j < ny; ++j) {
        const size_t r = kq + nx * j, rs = j > 0 ? r - nx : r + plane - nx;
        const size_t rd = k > 0 ? r - plane : r + s->n - plane;
        for (size_t i0 = 0; i0 < nx; i0 += 256) {
            const size_t i1 = nx - i0 < 256 ? nx : i0 + 256;
            size_t i = i0;
            if (i0 == 0) {
                h[0] = voxel_stable_dt(p[r], ic[r], kx[r] + kx[r + nx - 1] + ky[r] + ky[rs] + kz[r] + kz[rd], fd, fg,
                                       dx, dx2, up);
                i = 1;
            }
#pragma omp simd
            for (size_t e = i; e < i1; ++e)
                h[e - i0] = voxel_stable_dt(p[r + e], ic[r + e],
                                            kx[r + e] + kx[r + e - 1] + ky[r + e] + ky[rs + e] + kz[r + e] +
                                                kz[rd + e],
                                            fd, fg, dx, dx2, up);
            for (size_t e = i0; e < i1; ++e)
                if (h[e - i0] < best) {
                    best = h[e - i0];
                    *at = r + e;
                }
        }
    }
    return best;
}

/* The stability limit from the prepared face permeabilities and 1/c
 * (voxel_stable_dt), and the voxel that sets it: the smallest limit of
 * each z-plane and its first voxel, in parallel; then the first plane
 * holding the smallest: the voxel a scan in index order finds. */
static double stable_dt_prepared(const phc_soil *s, size_t *voxel)
{
    phc_soil_work *wk = s->work;
    const size_t nz = s->nz;
#pragma omp parallel for schedule(static) if (s->n >= PHC_SOIL_PARALLEL_MIN)
    for (size_t k = 0; k < nz; ++k)
        wk->plane[k] = plane_stable_dt(s, k, &wk->plane_at[k]);
    double best = INFINITY;
    size_t at = 0;
    for (size_t k = 0; k < nz; ++k)
        if (wk->plane[k] < best) {
            best = wk->plane[k];
            at = wk->plane_at[k];
        }
    if (voxel)
        *voxel = at;
    return best;
}

double phc_soil_stable_dt(const phc_soil *s, size_t *voxel)
{
    /* the work arrays are scratch, not state: filling them leaves s as it was */
    prepare_fields((phc_soil *)s);
    return stable_dt_prepared(s, voxel);
}

/* ---- the step ------------------------------------------------------------ */

/* The nutrient flux riding on water face flux F (from voxel a to voxel b,
 * m/h): Lax-Wendroff face concentration, or the donor's with `up`. */
static double nutrient_face_flux(double F, double wa, double wb, double va, double vb, double h,
                                 double dx, int up)
{
    if (F == 0)
        return 0;
    double ua = wa > 0 ? va / wa : 0, ub = wb > 0 ? vb / wb : 0;
    if (up)
        return F * (F > 0 ? ua : ub);
    double wm = 0.5 * (wa + wb);
    double nu = wm > 0 ? F * h / (dx * wm) : 0;
    return F * (0.5 * (ua + ub) - 0.5 * nu * (ub - ua));
}

/* The face terms of voxel q: f[0..5] = k_f (l_j - l_q) towards the east,
 * west, north, south, up and down neighbours (l = w/c), f[6] the downward
 * gravity flux through the top face and f[7] through the bottom face
 * (Lax-Wendroff, or the upwind flux of the voxel above with `up`: the same
 * form with the correction coefficient 1/2; 0 across a closed face).  One
 * definition for the water update and for the nutrients riding on the same
 * fluxes. */
static inline void voxel_faces(const double *restrict w, const double *restrict ic,
                               const double *restrict p, const double *restrict kx,
                               const double *restrict ky, const double *restrict kz, size_t q,
                               size_t qe, size_t qw, size_t qn, size_t qs, size_t qu, size_t qd,
                               double a, double lw, int up, double f[8])
{
    const double l0 = w[q] * ic[q];
    f[0] = kx[q] * (w[qe] * ic[qe] - l0);
    f[1] = kx[qw] * (w[qw] * ic[qw] - l0);
    f[2] = ky[q] * (w[qn] * ic[qn] - l0);
    f[3] = ky[qs] * (w[qs] * ic[qs] - l0);
    f[4] = kz[q] * (w[qu] * ic[qu] - l0);
    f[5] = kz[qd] * (w[qd] * ic[qd] - l0);
    const double q0 = a * p[q] * w[q], qU = a * p[qu] * w[qu], qD = a * p[qd] * w[qd];
    f[6] = kz[q] > 0 ? 0.5 * (qU + q0) - (up ? 0.5 : lw * kz[q]) * (q0 - qU) : 0;
    f[7] = kz[qd] > 0 ? 0.5 * (q0 + qD) - (up ? 0.5 : lw * kz[qd]) * (qD - q0) : 0;
}

/* The water update of voxel r of a z-plane, voxel_faces' terms summed as
 * transport() sums them, from the fill l = w/c and gravity flux
 * g = f_grav p w of the plane below (ld, gd), the plane itself (lc, gc) and
 * the plane above (lu, gu), computed once per plane and sub-step instead of
 * once for each of a voxel's 7 stencil entries: the same products, the
 * same sums in the same order, so the same numbers to the last bit.  kx,
 * ky, kzc are the voxel's face permeabilities to its +x, +y, +z
 * neighbours, kzd[r] the +z face of the voxel below; ln[r], ls[r] and
 * kys[r] are the fill of the +y and -y neighbours and the -y neighbour's
 * ky; re and rw index the x neighbours' fill in lc. */
static inline double gravity_face(double lower, double upper, double kz, double lw, int up);

/* water_voxel_pre with the gravity fluxes through the voxel's top (f6)
 * and bottom (f7) faces given. */
static inline double water_voxel_faces(const double *restrict wc, const double *restrict ld,
                                       const double *restrict lc, const double *restrict lu,
                                       const double *restrict ln, const double *restrict ls,
                                       const double *restrict kx, const double *restrict ky,
                                       const double *restrict kys, const double *restrict kzc,
                                       const double *restrict kzd, size_t r, size_t re, size_t rw, double cd,
                                       double cg, double f6, double f7)
{
    const double l0 = lc[r];
    const double f0 = kx[r] * (lc[re] - l0), f1 = kx[rw] * (lc[rw] - l0);
    const double f2 = ky[r] * (ln[r] - l0), f3 = kys[r] * (ls[r] - l0);
    const double f4 = kzc[r] * (lu[r] - l0), f5 = kzd[r] * (ld[r] - l0);
    return wc[r] + cd * (f0 + f1 + f2 + f3 + f4 + f5) + cg * (f6 - f7);
}

static inline double water_voxel_pre(const double *restrict wc, const double *restrict ld,
                                     const double *restrict lc, const double *restrict lu,
                                     const double *restrict ln, const double *restrict ls,
                                     const double *restrict gd, const double *restrict gc,
                                     const double *restrict gu, const double *restrict kx,
                                     const double *restrict ky, const double *restrict kys,
                                     const double *restrict kzc, const double *restrict kzd, size_t r,
                                     size_t re, size_t rw, double cd, double cg, double lw, int up)
{
    return water_voxel_faces(wc, ld, lc, lu, ln, ls, kx, ky, kys, kzc, kzd, r, re, rw, cd, cg,
                             gravity_face(gc[r], gu[r], kzc[r], lw, up), gravity_face(gd[r], gc[r], kzd[r], lw, up));
}

/* The downward gravity flux through a z face (voxel_faces' f[6] and f[7]):
 * g = f_grav p w of the voxel below (`lower`) and above (`upper`), kz the
 * face permeability; the upwind form when `up`. */
static inline double gravity_face(double lower, double upper, double kz, double lw, int up)
{
    return kz > 0 ? 0.5 * (upper + lower) - (up ? 0.5 : lw * kz) * (lower - upper) : 0;
}

/* The first and last voxel of each of the m / nx rows of water_rows,
 * computed again with the x neighbour wrapped around the row. */
static inline void water_row_ends(size_t nx, size_t m, const double *restrict wc, const double *restrict ld,
                                  const double *restrict lc, const double *restrict lu, const double *restrict ln,
                                  const double *restrict ls, const double *restrict gd, const double *restrict gc,
                                  const double *restrict gu, const double *restrict kx, const double *restrict ky,
                                  const double *restrict kys, const double *restrict kzc,
                                  const double *restrict kzd, double *restrict gf, double *restrict out, double cd,
                                  double cg, double lw, int up)
{
    for (size_t row = 0; row < m; row += nx) {
        const size_t last = row + nx - 1;
        out[row] = water_voxel_pre(wc, ld, lc, lu, ln, ls, gd, gc, gu, kx, ky, kys, kzc, kzd, row,
                                   nx > 1 ? row + 1 : row, last, cd, cg, lw, up);
        gf[row] = gravity_face(gc[row], gu[row], kzc[row], lw, up);
        if (nx > 1) {
            out[last] = water_voxel_pre(wc, ld, lc, lu, ln, ls, gd, gc, gu, kx, ky, kys, kzc, kzd, last, row,
                                        last - 1, cd, cg, lw, up);
            gf[last] = gravity_face(gc[last], gu[last], kzc[last], lw, up);
        }
    }
}

/* `rows` consecutive full rows (nx voxels each) of a z-plane's water
 * sub-step into `out`.  Every pointer points at the first row's first
 * voxel; ln and ls at the fill of the rows' +y and -y neighbours, kys at
 * the ky of the -y neighbours.  The rows run as one loop over the flat
 * index, r - 1 and r + 1 the x neighbours: no wrap-around and no branches,
 * so the compiler vectorises it over all the rows at once (row by row,
 * each row had its own short vector loop and scalar remainder).  That
 * loop gives the first and last voxel of every row the voxel across the
 * row end as x neighbour; those voxels are then computed again with the x
 * neighbour wrapped around the row, as the one-voxel stencil has it, so
 * every voxel gets that stencil's value to the last bit.  With
 * `inner` (rows with a row before and after them in the plane) the loop
 * takes every voxel, reading the voxel before the first and after the
 * last, which are in the plane, and its loads start on a cache line when
 * the plane's rows do; otherwise it skips the first and last voxel.
 *
 * gf holds the gravity flux through each voxel's bottom face (f7 of
 * water_voxel_pre) on entry and through its top face (f6) on return: the
 * top face of plane k is the bottom face of plane k + 1, so each face's
 * flux is computed once per sub-step instead of twice, by the same
 * expression on the same numbers (gravity_face).  The row ends, computed
 * again, take f7 from gd and kzd as water_voxel_pre does. */
PHC_SOIL_CLONES
static void water_rows(size_t nx, size_t rows, const double *restrict wc, const double *restrict ld,
                       const double *restrict lc, const double *restrict lu, const double *restrict ln,
                       const double *restrict ls, const double *restrict gd, const double *restrict gc,
                       const double *restrict gu, const double *restrict kx, const double *restrict ky,
                       const double *restrict kys, const double *restrict kzc, const double *restrict kzd,
                       double *restrict gf, double *restrict out, double cd, double cg, double lw, int up,
                       int inner)
{
    const size_t m = nx * rows, first = inner ? 0 : 1, end = inner ? m : m > 0 ? m - 1 : 0;
#pragma omp simd
    for (size_t r = first; r < end; ++r) {
        const double f6 = gravity_face(gc[r], gu[r], kzc[r], lw, up);
        out[r] = water_voxel_faces(wc, ld, lc, lu, ln, ls, kx, ky, kys, kzc, kzd, r, r + 1, r - 1, cd, cg, f6, gf[r]);
        gf[r] = f6;
    }
    water_row_ends(nx, m, wc, ld, lc, lu, ln, ls, gd, gc, gu, kx, ky, kys, kzc, kzd, gf, out, cd, cg, lw, up);
}

/* water_rows for `rows` (>= 1) inner rows of a uniform plane
 * (plane_uniform) over a uniform plane: the face permeabilities are the
 * numbers kyu, kzu (the plane's) and kzdu (the plane below's) instead of
 * arrays, the same numbers, so the same results, with five streams fewer.
 * Along x, every row of the plane has the faces of the first row given
 * (kx): kx[i] to the east neighbour, kx[i - 1] to the west one (kx[-1],
 * the previous row's last face, is the face across the row's ends).  With
 * closed x faces (not `xper`) that face is 0, and the loop, row by row,
 * gives a row's first and last voxel their values without computing them
 * again: the neighbour across the row end (the previous or next row's
 * voxel instead of the wrapped one) is multiplied by 0.  (The term is then
 * a zero of either sign, and the sum the same number; only a voxel whose
 * w is -0 with all its other terms zero could come out +0 instead.)  With
 * periodic x faces the rows run as one loop with kxu, and the row ends are
 * computed again with the wrapped neighbour, as in water_rows. */
PHC_SOIL_CLONES
static void water_rows_uniform(size_t nx, size_t rows, const double *restrict wc, const double *restrict ld,
                               const double *restrict lc, const double *restrict lu, const double *restrict ln,
                               const double *restrict ls, const double *restrict gd, const double *restrict gc,
                               const double *restrict gu, const double *restrict kx, const double *restrict ky,
                               const double *restrict kys, const double *restrict kzc, const double *restrict kzd,
                               double kxu, double kyu, double kzu, double kzdu, double *restrict gf,
                               double *restrict out, double cd, double cg, double lw, int up, int xper)
{
    const size_t m = nx * rows;
    if (!xper) {
        for (size_t row = 0; row < m; row += nx) {
#pragma omp simd
            for (size_t i = 0; i < nx; ++i) {
                const size_t r = row + i;
                const double l0 = lc[r];
                const double f0 = kx[i] * (lc[r + 1] - l0), f1 = kx[i - 1] * (lc[r - 1] - l0);
                const double f2 = kyu * (ln[r] - l0), f3 = kyu * (ls[r] - l0);
                const double f4 = kzu * (lu[r] - l0), f5 = kzdu * (ld[r] - l0);
                const double f6 = gravity_face(gc[r], gu[r], kzu, lw, up);
                out[r] = wc[r] + cd * (f0 + f1 + f2 + f3 + f4 + f5) + cg * (f6 - gf[r]);
                gf[r] = f6;
            }
        }
        return;
    }
#pragma omp simd
    for (size_t r = 0; r < m; ++r) {
        const double l0 = lc[r];
        const double f0 = kxu * (lc[r + 1] - l0), f1 = kxu * (lc[r - 1] - l0);
        const double f2 = kyu * (ln[r] - l0), f3 = kyu * (ls[r] - l0);
        const double f4 = kzu * (lu[r] - l0), f5 = kzdu * (ld[r] - l0);
        const double f6 = gravity_face(gc[r], gu[r], kzu, lw, up);
        out[r] = wc[r] + cd * (f0 + f1 + f2 + f3 + f4 + f5) + cg * (f6 - gf[r]);
        gf[r] = f6;
    }
    water_row_ends(nx, m, wc, ld, lc, lu, ln, ls, gd, gc, gu, kx, ky, kys, kzc, kzd, gf, out, cd, cg, lw, up);
}

/* The water update of a voxel of a from_w plane (see water_plane_from_w)
 * from w: wc, we, ww, wn, ws its own and its east, west, north and south
 * neighbours' (in the plane, of 1/c icc), wu and wd above and below (1/c
 * icu, icd), apc and apu f_grav p of the plane and the plane above; kxe,
 * kxw, kyn, kys, kzu, kzd the face permeabilities; gf the gravity flux
 * through the bottom face on entry, through the top face on return.  The
 * fill l = w/c and g = f_grav p w are the products fill_plane forms, and
 * the rest is water_voxel_faces: the same numbers. */
static inline double water_voxel_from_w(double wc, double we, double ww, double wn, double ws, double wu,
                                        double wd, double icc, double icu, double icd, double apc, double apu,
                                        double kxe, double kxw, double kyn, double kys, double kzu, double kzd,
                                        double *gf, double cd, double cg, double lw, int up)
{
    const double l0 = wc * icc;
    const double f0 = kxe * (we * icc - l0), f1 = kxw * (ww * icc - l0);
    const double f2 = kyn * (wn * icc - l0), f3 = kys * (ws * icc - l0);
    const double f4 = kzu * (wu * icu - l0), f5 = kzd * (wd * icd - l0);
    const double f6 = gravity_face(apc * wc, apu * wu, kzu, lw, up);
    const double r = wc + cd * (f0 + f1 + f2 + f3 + f4 + f5) + cg * (f6 - *gf);
    *gf = f6;
    return r;
}

/* Voxels i0 .. i1 - 1 of a row of a from_w plane (water_voxel_from_w):
 * pointers at the row's first voxel (wn, ws: the rows north and south,
 * wrapped around the plane), kx the x faces of the plane's second row
 * (kx[i] east of voxel i; kx[i - 1] west, kx[-1] across the row's ends,
 * 0 as x faces are closed).  A voxel at a row end reads the voxel across
 * the row end, in the previous or next row, and multiplies its term by
 * that 0 (a zero of either sign: the sum is the same number; only a voxel
 * whose w is -0 with all its other terms zero could come out +0); the
 * caller keeps i0 .. i1 inside the plane's voxels. */
static inline void water_row_from_w(size_t i0, size_t i1, const double *restrict wc, const double *restrict wn,
                             const double *restrict ws, const double *restrict wu, const double *restrict wd,
                             const double *restrict kx, const double *restrict u, const double *restrict uu,
                             const double *restrict ud, double kyn, double kys, double *restrict gf,
                             double *restrict out, double a, double cd, double cg, double lw, int up)
{
    const double icc = u[0], icu = uu[0], icd = ud[0], apc = a * u[1], apu = a * uu[1], kzu = u[4], kzd = ud[4];
#pragma omp simd
    for (size_t i = i0; i < i1; ++i)
        out[i] = water_voxel_from_w(wc[i], wc[i + 1], wc[i - 1], wn[i], ws[i], wu[i], wd[i], icc, icu, icd, apc, apu,
                                    kx[i], kx[i - 1], kyn, kys, kzu, kzd, gf + i, cd, cg, lw, up);
}

/* One z-plane of a water-only sub-step of a from_w plane (prepare_fields:
 * it and the planes above and below uniform, closed x faces, ny >= 2)
 * from w alone: wc, wu, wd the planes of w, u, uu, ud the uniform values
 * (plane_uniform) of the plane, the plane above and below, kx and ky the
 * plane's faces; gf and out as in water_plane.  The fill l = w/c and the
 * gravity flux g = f_grav p w are formed where they are used (2 + 7
 * multiplications a voxel instead of a pass over the plane that writes
 * two planes and seven loads of them).  Rows one at a time, north and
 * south wrapped as the one-voxel stencil has them; the plane's first and
 * last voxel, whose neighbours across the row end lie outside the plane,
 * on their own with the wrapped neighbour. */
PHC_SOIL_CLONES_512
static void water_plane_from_w(size_t nx, size_t ny, const double *wc, const double *wu, const double *wd,
                               const double *u, const double *uu, const double *ud, const double *kx,
                               const double *ky, double *gf, double *out, double a, double cd, double cg,
                               double lw, int up)
{
    const double *kxr = kx + nx; /* the second row's x faces; kxr[-1] the first row's last */
    for (size_t j = 0; j < ny; ++j) {
        const size_t o = nx * j, on = j + 1 < ny ? o + nx : 0, os = j > 0 ? o - nx : nx * (ny - 1);
        const size_t i0 = j == 0, i1 = j + 1 == ny ? nx - 1 : nx;
        if (i1 > i0)
            water_row_from_w(i0, i1, wc + o, wc + on, wc + os, wu + o, wd + o, kxr, u, uu, ud, ky[o], ky[os], gf + o,
                             out + o, a, cd, cg, lw, up);
    }
    /* the first voxel (west neighbour wrapped to the end of row 0) and the
       last (east neighbour wrapped to the start of the last row) */
    const size_t e0 = nx > 1 ? 1 : 0, L = nx * ny - 1, Lr = nx * (ny - 1), Le = nx > 1 ? L - 1 : L;
    out[0] = water_voxel_from_w(wc[0], wc[e0], wc[nx - 1], wc[nx], wc[Lr], wu[0], wd[0], u[0], uu[0], ud[0],
                                a * u[1], a * uu[1], kx[0], kx[nx - 1], ky[0], ky[Lr], u[4], ud[4], gf, cd, cg, lw,
                                up);
    if (L > 0)
        out[L] = water_voxel_from_w(wc[L], wc[Lr], wc[Le], wc[nx - 1], wc[L - nx], wu[L], wd[L], u[0], uu[0], ud[0],
                                    a * u[1], a * uu[1], kx[L], kx[Le], ky[L], ky[L - nx], u[4], ud[4], gf + L, cd,
                                    cg, lw, up);
}

/* The water update of voxel q of a plane swept from w and p
 * (water_plane_from_w_rocks): wc, wu, wd the planes of w, pc, pu, pd of p
 * (this plane, above, below); qe, qw, qn, qs the x and y neighbours in
 * the plane; the face permeabilities are the *_pair values (a layer
 * plane's, plane_layer, or 0 across a closed face) where both voxels are
 * not rock and 0 where either is, which are the numbers prepare_fields
 * makes; f_grav p w is formed as fill_plane forms it.  Then
 * water_voxel_from_w. */
static inline double water_voxel_rocks(const double *restrict wc, const double *restrict wu,
                                       const double *restrict wd, const double *restrict pc,
                                       const double *restrict pu, const double *restrict pd, size_t q, size_t qe,
                                       size_t qw, size_t qn, size_t qs, double kxe_pair, double kxw_pair,
                                       double kyn_pair, double kys_pair, double kzu_pair, double kzd_pair,
                                       double icc, double icu, double icd, double a, double *gf, double cd,
                                       double cg, double lw, int up)
{
    const double p0 = pc[q];
    const int in = p0 > 0;
    const double kxe = in & (pc[qe] > 0) ? kxe_pair : 0, kxw = (pc[qw] > 0) & in ? kxw_pair : 0;
    const double kyn = in & (pc[qn] > 0) ? kyn_pair : 0, kys = (pc[qs] > 0) & in ? kys_pair : 0;
    const double kzu = in & (pu[q] > 0) ? kzu_pair : 0, kzd = (pd[q] > 0) & in ? kzd_pair : 0;
    return water_voxel_from_w(wc[q], wc[qe], wc[qw], wc[qn], wc[qs], wu[q], wd[q], icc, icu, icd, a * p0, a * pu[q],
                              kxe, kxw, kyn, kys, kzu, kzd, gf + q, cd, cg, lw, up);
}

/* water_plane_from_w for a plane whose planes k - 1, k, k + 1 are layer
 * planes (plane_layer: one 1/c, p either 0 or one value; a layer with
 * rocks), not all uniform: the same sweep, with p read to tell rock from
 * soil (water_voxel_rocks); the plane's first and last voxel on their
 * own with the wrapped neighbours.  lc, lu, ld: layer_of of the plane,
 * the plane above and below; yper: periodic y faces. */
PHC_SOIL_CLONES_512
static void water_plane_from_w_rocks(size_t nx, size_t ny, const double *wc, const double *wu, const double *wd,
                                     const double *pc, const double *pu, const double *pd, const double *lc,
                                     const double *lu, const double *ld, int yper, double *gf, double *out,
                                     double a, double cd, double cg, double lw, int up)
{
    const double kxy = lc[2], icc = lc[0], icu = lu[0], icd = ld[0], kzu = lc[3], kzd = ld[3];
    for (size_t j = 0; j < ny; ++j) {
        const size_t o = nx * j, on = j + 1 < ny ? o + nx : 0, os = j > 0 ? o - nx : nx * (ny - 1);
        const size_t i0 = j == 0, i1 = j + 1 == ny ? nx - 1 : nx;
        const double kyn = j + 1 < ny || yper ? kxy : 0, kys = j > 0 || yper ? kxy : 0;
#pragma omp simd
        for (size_t i = i0; i < i1; ++i)
            out[o + i] = water_voxel_rocks(wc, wu, wd, pc, pu, pd, o + i, o + i + 1, o + i - 1, on + i, os + i,
                                           i + 1 < nx ? kxy : 0, i > 0 ? kxy : 0, kyn, kys, kzu, kzd, icc, icu,
                                           icd, a, gf, cd, cg, lw, up);
    }
    const size_t e0 = nx > 1 ? 1 : 0, L = nx * ny - 1, Lr = nx * (ny - 1), Le = nx > 1 ? L - 1 : L;
    out[0] = water_voxel_rocks(wc, wu, wd, pc, pu, pd, 0, e0, nx - 1, nx, Lr, nx > 1 ? kxy : 0, 0, kxy,
                               yper ? kxy : 0, kzu, kzd, icc, icu, icd, a, gf, cd, cg, lw, up);
    out[L] = water_voxel_rocks(wc, wu, wd, pc, pu, pd, L, Lr, Le, nx - 1, L - nx, 0, nx > 1 ? kxy : 0,
                               yper ? kxy : 0, kxy, kzu, kzd, icc, icu, icd, a, gf, cd, cg, lw, up);
}

/* gravity_faces_from_w for a plane of water_plane_from_w_rocks: the face
 * permeability kz between two voxels that are not rock, 0 where either
 * is; f_grav p w as fill_plane forms it. */
PHC_SOIL_CLONES_512
static void gravity_faces_rocks(size_t m, const double *restrict lower, const double *restrict upper,
                                const double *restrict pl, const double *restrict pu, double a, double kz, double lw,
                                int up, double *restrict gf)
{
    for (size_t q = 0; q < m; ++q)
        gf[q] = gravity_face((a * pl[q]) * lower[q], (a * pu[q]) * upper[q], (pl[q] > 0) & (pu[q] > 0) ? kz : 0,
                             lw, up);
}

/* gravity_faces of a from_w plane over the plane below, from w: g of
 * each formed as fill_plane forms it. */
PHC_SOIL_CLONES_512
static void gravity_faces_from_w(size_t m, const double *restrict lower, const double *restrict upper, double apl,
                                 double apu, double kz, double lw, int up, double *restrict gf)
{
    for (size_t q = 0; q < m; ++q)
        gf[q] = gravity_face(apl * lower[q], apu * upper[q], kz, lw, up);
}

/* gf = the gravity fluxes through the z faces between two planes (g of
 * the lower and upper plane, kz of the lower): the face below a sweep's
 * first plane, water_rows' f7 there. */
PHC_SOIL_CLONES
static void gravity_faces(size_t m, const double *restrict lower, const double *restrict upper,
                          const double *restrict kz, double lw, int up, double *restrict gf)
{
    for (size_t q = 0; q < m; ++q)
        gf[q] = gravity_face(lower[q], upper[q], kz[q], lw, up);
}

/* One z-plane of a water-only sub-step into `out` (pointers at the
 * plane's first voxel; ld, gd of the plane below, lu, gu of the plane
 * above, kzd the +z faces of the plane below): the rows 1 .. ny - 2 as
 * one run of water_rows (water_rows_uniform when uc and ud, the
 * plane_uniform values of this plane and the plane below, are given), whose -y and +y neighbours are the rows before
 * and after in memory, then rows 0 and ny - 1, whose -y or +y neighbour
 * wraps around the plane (as the one-voxel stencil has it: across a
 * closed face the face permeability is 0 and the wrapped value is
 * multiplied by it). */
static void water_plane(size_t nx, size_t ny, const double *wc, const double *ld, const double *lc,
                        const double *lu, const double *gd, const double *gc, const double *gu,
                        const double *kx, const double *ky, const double *kzc, const double *kzd, double *gf,
                        double *out, double cd, double cg, double lw, int up, const double *uc, const double *ud,
                        int xper)
{
    if (ny > 2 && uc && ud)
        water_rows_uniform(nx, ny - 2, wc + nx, ld + nx, lc + nx, lu + nx, lc + 2 * nx, lc, gd + nx, gc + nx,
                           gu + nx, kx + nx, ky + nx, ky, kzc + nx, kzd + nx, uc[2], uc[3], uc[4], ud[4], gf + nx,
                           out + nx, cd, cg, lw, up, xper);
    else if (ny > 2)
        water_rows(nx, ny - 2, wc + nx, ld + nx, lc + nx, lu + nx, lc + 2 * nx, lc, gd + nx, gc + nx, gu + nx,
                   kx + nx, ky + nx, ky, kzc + nx, kzd + nx, gf + nx, out + nx, cd, cg, lw, up, 1);
    for (size_t j = 0; j < ny; j += ny > 1 ? ny - 1 : 1) {
        const size_t o = nx * j, on = j + 1 < ny ? o + nx : 0, os = j > 0 ? o - nx : nx * (ny - 1);
        water_rows(nx, 1, wc + o, ld + o, lc + o, lu + o, lc + on, lc + os, gd + o, gc + o, gu + o, kx + o,
                   ky + o, ky + os, kzc + o, kzd + o, gf + o, out + o, cd, cg, lw, up, 0);
    }
}

/* The fill l = w/c (as w times 1/c) and gravity flux g = f_grav p w of m
 * voxels. */
PHC_SOIL_CLONES
static void fill_plane(size_t m, const double *restrict w, const double *restrict ic, const double *restrict p,
                       double a, double *restrict l, double *restrict g)
{
    for (size_t q = 0; q < m; ++q) {
        l[q] = w[q] * ic[q];
        g[q] = a * p[q] * w[q];
    }
}

/* fill_plane for a plane of one 1/c (icu) and one p (pu): the same
 * products, so the same numbers. */
PHC_SOIL_CLONES
static void fill_plane_uniform(size_t m, const double *restrict w, double icu, double pu, double a,
                               double *restrict l, double *restrict g)
{
    const double ap = a * pu;
    for (size_t q = 0; q < m; ++q) {
        l[q] = w[q] * icu;
        g[q] = ap * w[q];
    }
}

/* The fill of plane k (at offset km) of w into l and g, uniform or not. */
static void fill_plane_of(const phc_soil *s, size_t k, size_t km, const double *w, double a, double *l, double *g)
{
    const phc_soil_work *wk = s->work;
    const size_t P = s->nx * s->ny;
    if (wk->uniform[k])
        fill_plane_uniform(P, w, wk->uniform_of[5 * k], wk->uniform_of[5 * k + 1], a, l, g);
    else
        fill_plane(P, w, wk->ic + km, s->p + km, a, l, g);
}

/* The stride of the ring's planes of P voxels (doubles): P rounded up to
 * whole cache lines, so every plane starts on one as the fields do
 * (field_alloc), and one line more, so that planes of 2^k voxels do not all
 * start at the same offset in a 4 KiB page (they would compete for the
 * same sets of the L1 cache). */
static size_t ring_stride(size_t P)
{
    const size_t a = PHC_SOIL_ALIGN / sizeof(double);
    return (P + a - 1) / a * a + a;
}

/* The z-plane of unwrapped index k (k < 0 or >= nz wrap around). */
static size_t wrap_plane(long k, long nz)
{
    return (size_t)(((k % nz) + nz) % nz);
}

/* T water-only sub-steps of h (time blocking, a wavefront in z): the planes
 * [k0, k1) of w_new from w.  Sub-step t's plane k needs sub-step t-1's
 * planes k-1, k and k+1, so the planes are swept once: at plane m, the fill
 * of w's plane m, then sub-step t's plane m - t for t = 1..T.  Sub-step t
 * runs over [k0 - (T - t), k1 + (T - t)): the planes next to the chunk are
 * recomputed by the thread that needs them, with the same arithmetic, so
 * the result does not depend on the chunks (nor the thread count).  Each
 * intermediate sub-step keeps 3 planes of w, l and g in `ring` (T x 3 x 3
 * planes), and every sub-step a plane of the gravity fluxes through the
 * faces below its current plane (water_rows' gf: T planes after those,
 * filled for the sub-step's first plane by gravity_faces); the face
 * permeabilities, 1/c and p stream from memory once per
 * T sub-steps instead of once per sub-step.  (Outside the box the planes
 * wrap around as the one-step stencil does: across a closed z face the
 * face permeability is 0 and the wrapped values are multiplied by it.)
 * Planes swept from w (prepare_fields' from_w: 1 uniform, 2 layer planes
 * with rocks) read w (and p) of the ring's or the state's planes and no
 * fill; a plane's fill is made only where it or a neighbour is not swept
 * so (prepare_fields' fill). */
static void sweep_chunk(const phc_soil *s, double h, size_t T, long k0, long k1, double *ring)
{
    const phc_soil_work *wk = s->work;
    const size_t nx = s->nx, ny = s->ny, P = nx * ny;
    const long nz = (long)s->nz, base = k0 - (long)T;
    const size_t S = ring_stride(P);
    const double dx = s->dx, fd = s->params.f_diff, a = s->params.f_grav;
    const double cd = h * fd / (dx * dx), cg = h / dx, lw = h * a / (2 * dx);
    const int up = s->params.gravity == PHC_SOIL_GRAVITY_UPWIND;
    const int xper = s->params.boundary[PHC_SOIL_XMIN] == PHC_SOIL_PERIODIC;
    const int yper = s->params.boundary[PHC_SOIL_YMIN] == PHC_SOIL_PERIODIC;
#define RING(t, k, arr) (ring + (((size_t)(t) * 3 + (size_t)(((k) - base) % 3)) * 3 + (arr)) * S)
/* w after sub-step t (0: the state s->w) of plane k */
#define WPLANE(t, k) ((t) == 0 ? s->w + wrap_plane(k, nz) * P : RING(t, k, 0))
    for (long m = base; m < k1 + (long)T; ++m) {
        const size_t km = wrap_plane(m, nz) * P;
        if (wk->fill[wrap_plane(m, nz)])
            fill_plane_of(s, wrap_plane(m, nz), km, s->w + km, a, RING(0, m, 1), RING(0, m, 2));
        for (size_t t = 1; t <= T; ++t) {
            const long k = m - (long)t;
            if (k < k0 - (long)(T - t))
                break; /* and so for every later t */
            const size_t ik = wrap_plane(k, nz), id = wrap_plane(k - 1, nz), kk = ik * P, kd = id * P;
            const int uni = wk->uniform[ik] && wk->uniform[id];
            const double *wc = WPLANE(t - 1, k);
            double *out = t == T ? wk->w_new + kk : RING(t, k, 0);
            double *gf = ring + (9 * T + t - 1) * S; /* sub-step t's gravity fluxes through the faces below */
            const double *u = wk->uniform_of + 5 * ik, *ud = wk->uniform_of + 5 * id;
            if (wk->from_w[ik] == 2) {
                const size_t iu = wrap_plane(k + 1, nz);
                if (k == k0 - (long)(T - t))
                    gravity_faces_rocks(P, WPLANE(t - 1, k - 1), wc, s->p + kd, s->p + kk, a, wk->layer_of[4 * id + 3],
                                        lw, up, gf);
                water_plane_from_w_rocks(nx, ny, wc, WPLANE(t - 1, k + 1), WPLANE(t - 1, k - 1), s->p + kk,
                                         s->p + iu * P, s->p + kd, wk->layer_of + 4 * ik, wk->layer_of + 4 * iu,
                                         wk->layer_of + 4 * id, yper, gf, out, a, cd, cg, lw, up);
                if (t < T && wk->fill[ik])
                    fill_plane_of(s, ik, kk, out, a, RING(t, k, 1), RING(t, k, 2));
                continue;
            }
            if (wk->from_w[ik]) {
                const double *uu = wk->uniform_of + 5 * wrap_plane(k + 1, nz);
                if (k == k0 - (long)(T - t))
                    gravity_faces_from_w(P, WPLANE(t - 1, k - 1), wc, a * ud[1], a * u[1], ud[4], lw, up, gf);
                water_plane_from_w(nx, ny, wc, WPLANE(t - 1, k + 1), WPLANE(t - 1, k - 1), u, uu, ud, wk->kx + kk,
                                   wk->ky + kk, gf, out, a, cd, cg, lw, up);
                if (t < T && wk->fill[ik])
                    fill_plane_of(s, ik, kk, out, a, RING(t, k, 1), RING(t, k, 2));
                continue;
            }
            if (k == k0 - (long)(T - t))
                gravity_faces(P, RING(t - 1, k - 1, 2), RING(t - 1, k, 2), wk->kz + kd, lw, up, gf);
            water_plane(nx, ny, wc, RING(t - 1, k - 1, 1), RING(t - 1, k, 1), RING(t - 1, k + 1, 1),
                        RING(t - 1, k - 1, 2), RING(t - 1, k, 2), RING(t - 1, k + 1, 2), wk->kx + kk,
                        wk->ky + kk, wk->kz + kk, wk->kz + kd, gf, out, cd, cg, lw, up,
                        uni ? u : NULL, uni ? ud : NULL, xper);
            if (t < T)
                fill_plane_of(s, ik, kk, out, a, RING(t, k, 1), RING(t, k, 2));
        }
    }
#undef WPLANE
#undef RING
}

/* Water only (no nutrients move), T sub-steps of h in one sweep; each
 * thread takes a contiguous range of z-planes (static, so the planes a
 * thread writes are the ones it first touched).  A small grid does not
 * enter an OpenMP region at all (an `if` clause still calls into libgomp
 * on every sub-step: a tenth of a small pot's run time, more inside
 * another parallel region, as when a root:shoot Jacobian grows its plants
 * in parallel). */
static void transport_water(phc_soil *s, double h, size_t T)
{
    phc_soil_work *wk = s->work;
    const long nz = (long)s->nz;
    if (s->n >= PHC_SOIL_PARALLEL_MIN && wk->ring_threads > 1) {
#pragma omp parallel num_threads((int)wk->ring_threads)
        {
#ifdef _OPENMP
            const long nth = omp_get_num_threads(), id = omp_get_thread_num();
#else
            const long nth = 1, id = 0;
#endif
            const long k0 = nz * id / nth, k1 = nz * (id + 1) / nth;
            if (k1 > k0)
                sweep_chunk(s, h, T, k0, k1, wk->ring + (size_t)id * wk->ring_per_thread);
        }
    } else {
        sweep_chunk(s, h, T, 0, nz, wk->ring);
    }
}

/* The sub-steps one sweep may take: params.block_steps, or with 0 (the
 * default) the most, up to PHC_SOIL_BLOCK_STEPS, whose planes fit in
 * PHC_SOIL_CACHE_BYTES: a sweep with T sub-steps works on 10 T planes of
 * rings (prepare_ring), the face permeabilities, 1/c and p of T + 1
 * planes and a plane of w and of w_new, (15 T + 7) planes in all.  Where
 * they fit a core's cache the sub-steps run from it; where even T = 1
 * does not fit, the planes come from memory anyway and PHC_SOIL_BLOCK_STEPS
 * sub-steps per sweep read them once for all.  Measured on the bench soil,
 * 1 thread, voxel updates per CPU-second, best of 6 alternating runs (busy
 * machine, load average 4.3 on 2 CPUs): 64^3 3.95e8 with 1 sub-step per
 * sweep, 3.70e8 with 2, 3.49e8 with 4; 128^3 2.27e8 with 1, 2.85e8 with 2,
 * 3.06e8 with 4.  Again after the aligned row runs of water_rows and the
 * huge pages (same measure, 2 runs each, load average 5.8 on 2 CPUs):
 * 64^3 6.1e8-6.7e8 with 1, 6.2e8-6.5e8 with 2, 5.2e8-5.6e8 with 4;
 * 128^3 4.3e8-4.4e8 with 2, 5.0e8-5.1e8 with 4, 5.3e8 with 6, 5.1e8-5.2e8
 * with 8: the rule stands.  When every plane is swept from w (and p)
 * (prepare_fields' all_from_w: layers, with or without rocks, closed x
 * faces) a sub-step works on
 * 4 planes of rings (w of three planes and the gravity fluxes) and the
 * sweep on (4 T + 2) planes: 2 sub-steps per sweep where their 10 planes
 * fit in PHC_SOIL_CACHE_BYTES, else PHC_SOIL_BLOCK_STEPS_FROM_W (8).
 * Measured on the bench soil (AVX-512 copy, CPU time, 2 runs each, load
 * average 1.2-1.8 on 2 CPUs): 64^3 1.87e9-1.89e9 voxel updates/s with 1
 * sub-step per sweep, 1.82e9-1.94e9 with 2, 1.84e9-1.92e9 with 4,
 * 1.56e9-1.71e9 with 8 (with 2 threads, wall clock: 2.9e9-3.6e9,
 * 3.2e9-3.7e9, 2.8e9-3.5e9, 2.3e9-3.0e9); 128^3 9.7e8-1.0e9 with 2,
 * 1.22e9-1.23e9 with 4, 1.27e9-1.52e9 with 6, 1.52e9-1.54e9 with 8,
 * 1.55e9-1.56e9 with 16 (2 threads: 2.37e9-2.42e9 with 4, 2.36e9-2.79e9
 * with 6, 1.6e9-2.83e9 with 8, 2.73e9-2.77e9 with 12, 2.57e9-2.63e9 with
 * 16).  With 10% rocks (layer planes swept from w and p, 1 thread, 2
 * runs): 64^3 1.25e9-1.28e9 with 1, 1.22e9-1.24e9 with 2, 1.21e9-1.23e9
 * with 4; 128^3 7.1e8-7.2e8 with 2, 8.4e8-8.5e8 with 4, 9.9e8-1.02e9 with
 * 8.  At
 * most nz / 8 either way (the planes each thread recomputes next to its
 * range grow with T) and at least 1.  The numbers do not depend on T.
 * Needs prepare_fields. */
static size_t block_levels(const phc_soil *s)
{
    size_t T = s->params.block_steps;
    if (!T && s->work->all_from_w) {
        const double plane = (double)(s->nx * s->ny) * sizeof(double);
        T = (4.0 * 2 + 2) * plane <= PHC_SOIL_CACHE_BYTES ? 2 : PHC_SOIL_BLOCK_STEPS_FROM_W;
    } else if (!T) {
        const double plane = (double)(s->nx * s->ny) * sizeof(double);
        T = PHC_SOIL_BLOCK_STEPS;
        if ((15.0 + 7.0) * plane <= PHC_SOIL_CACHE_BYTES)
            while (T > 1 && (15.0 * (double)T + 7.0) * plane > PHC_SOIL_CACHE_BYTES)
                --T;
    }
    if (T > s->nz / 8)
        T = s->nz / 8;
    return T ? T : 1;
}

size_t phc_soil_block_steps(const phc_soil *s)
{
    /* the work arrays are scratch, not state (as in phc_soil_stable_dt) */
    prepare_fields((phc_soil *)s);
    return block_levels(s);
}

/* The rings of transport_water for T sub-steps per sweep and the threads
 * a run may use; PHC_ERR_NOMEM. */
static int prepare_ring(phc_soil *s, size_t T)
{
    phc_soil_work *wk = s->work;
    size_t threads = 1;
#ifdef _OPENMP
    if (s->n >= PHC_SOIL_PARALLEL_MIN && !omp_in_parallel())
        threads = (size_t)omp_get_max_threads();
#endif
    const size_t per = T * 10 * ring_stride(s->nx * s->ny);
    if (wk->ring && wk->ring_per_thread >= per && wk->ring_threads == threads)
        return PHC_OK;
    free(wk->ring);
    wk->ring = field_alloc(threads * per, 0);
    wk->ring_threads = wk->ring ? threads : 0;
    wk->ring_per_thread = per;
    return wk->ring ? PHC_OK : PHC_ERR_NOMEM;
}

/* Transport over one sub-step h: w_new (and v_new) from w (and v). */
static void transport(phc_soil *s, double h)
{
    if (!s->work->nutrients) {
        transport_water(s, h, 1); /* v is left as it is: run_impl does not swap it */
        return;
    }
    phc_soil_work *wk = s->work;
    const size_t nx = s->nx, ny = s->ny, nz = s->nz, plane = nx * ny, n = s->n;
    const double *w = s->w, *v = s->v, *ic = wk->ic, *p = s->p;
    const double *kx = wk->kx, *ky = wk->ky, *kz = wk->kz;
    double *wn = wk->w_new, *vn = wk->v_new;
    const double dx = s->dx, fd = s->params.f_diff, a = s->params.f_grav;
    const double cd = h * fd / (dx * dx), cg = h / dx, lw = h * a / (2 * dx);
    const double fn = s->params.f_nutrient;
    const int up = s->params.gravity == PHC_SOIL_GRAVITY_UPWIND;
#pragma omp parallel for schedule(static) if (s->n >= PHC_SOIL_PARALLEL_MIN)
    for (size_t k = 0; k < nz; ++k) {
        const size_t kup = k + 1 < nz ? plane : plane - n, kdn = k > 0 ? plane : plane - n;
        for (size_t j = 0; j < ny; ++j) {
            const size_t jn = j + 1 < ny ? nx : nx - plane, js = j > 0 ? nx : nx - plane;
            const size_t row = nx * (j + ny * k);
            for (size_t i = 0; i < nx; ++i) {
                const size_t q = row + i;
                const size_t qe = i + 1 < nx ? q + 1 : q + 1 - nx, qw = i > 0 ? q - 1 : q + nx - 1;
                const size_t qn = q + jn, qs = q - js, qu = q + kup, qd = q - kdn;
                double f[8];
                voxel_faces(w, ic, p, kx, ky, kz, q, qe, qw, qn, qs, qu, qd, a, lw, up, f);
                wn[q] = w[q] + cd * (f[0] + f[1] + f[2] + f[3] + f[4] + f[5]) + cg * (f[6] - f[7]);
                /* the water face fluxes out of q (m/h), then nutrients ride on them */
                const double dd = fd / dx;
                const size_t nb[6] = {qe, qw, qn, qs, qu, qd};
                const double out[6] = {-dd * f[0], -dd * f[1], -dd * f[2], -dd * f[3], -dd * f[4] - f[6],
                                       -dd * f[5] + f[7]};
                double acc = 0;
                for (int e = 0; e < 6; ++e)
                    acc -= nutrient_face_flux(out[e], w[q], w[nb[e]], v[q], v[nb[e]], h, dx, up);
                vn[q] = v[q] + fn * cg * acc;
            }
        }
    }
}

/* Rain, point sources and the sink hook on w_new / v_new; budget terms. */
static int sources_and_sinks(phc_soil *s, double t, double h, phc_soil_budget *bud)
{
    phc_soil_work *wk = s->work;
    const double vol = s->dx * s->dx * s->dx;
    double *wn = wk->w_new, *vn = wk->nutrients ? wk->v_new : s->v;
    for (size_t r = 0; r < s->n_rain; ++r) {
        const phc_soil_rain *rn = &s->rain[r];
        double len = overlap(t, t + h, rn->start, rn->end);
        if (len <= 0 || rn->rate <= 0)
            continue;
        double dw = rn->rate * len / s->dx; /* m^3/m^3 added to the surface voxel */
        int whole = !(rn->x1 > rn->x0 && rn->y1 > rn->y0);
        for (size_t j = 0; j < s->ny; ++j)
            for (size_t i = 0; i < s->nx; ++i) {
                double xc = (i + 0.5) * s->dx, yc = (j + 0.5) * s->dx;
                if (!whole && !(xc >= rn->x0 && xc < rn->x1 && yc >= rn->y0 && yc < rn->y1))
                    continue;
                long k = wk->top[i + s->nx * j];
                if (k < 0)
                    continue;
                size_t q = idx3(s, i, j, (size_t)k);
                wn[q] += dw;
                vn[q] += dw * rn->nutrient;
                bud->water_in += dw * vol;
                bud->nutrient_in += dw * rn->nutrient * vol;
            }
    }
    for (size_t q = 0; q < s->n_sources; ++q) {
        const phc_soil_source *src = &s->sources[q];
        double len = overlap(t, t + h, src->start, src->end);
        if (len <= 0)
            continue;
        for (size_t e = wk->src_first[q]; e < wk->src_first[q + 1]; ++e) {
            size_t i = wk->src_idx[e];
            double dw = src->water_rate * len * wk->src_w[e] / vol;
            double dv = src->nutrient_rate * len * wk->src_w[e] / vol;
            if (dw >= 0)
                bud->water_in += dw * vol;
            else {
                dw = -dw > fmax(wn[i], 0.0) ? -fmax(wn[i], 0.0) : dw; /* never below what is there */
                bud->water_sunk -= dw * vol;
            }
            if (dv >= 0)
                bud->nutrient_in += dv * vol;
            else {
                dv = -dv > fmax(vn[i], 0.0) ? -fmax(vn[i], 0.0) : dv;
                bud->nutrient_sunk -= dv * vol;
            }
            wn[i] += dw;
            vn[i] += dv;
        }
    }
    if (s->sink) {
        if (!wk->sink_w) {
            wk->sink_w = malloc(s->n * sizeof(double));
            wk->sink_v = malloc(s->n * sizeof(double));
            if (!wk->sink_w || !wk->sink_v)
                return PHC_ERR_NOMEM;
        }
        memset(wk->sink_w, 0, s->n * sizeof(double));
        memset(wk->sink_v, 0, s->n * sizeof(double));
        if (s->sink(s->sink_user, t, h, wn, vn, wk->sink_w, wk->sink_v) != 0)
            return PHC_ERR_DOMAIN;
        /* Only the voxels a sink takes from are touched: the sums see the
           same non-zero terms in the same order as a sum over every voxel
           (adding +0 changes nothing), without a chain of additions through
           every voxel (a plant's roots sit in a few of them). */
        double sw = 0, sv = 0;
        for (size_t i = 0; i < s->n; ++i) {
            if (wk->sink_w[i] > 0) {
                double a = fmin(wk->sink_w[i], fmax(wn[i], 0.0));
                wn[i] -= a;
                sw += a;
            }
            if (wk->sink_v[i] > 0) {
                double b = fmin(wk->sink_v[i], fmax(vn[i], 0.0));
                vn[i] -= b;
                sv += b;
            }
        }
        bud->water_sunk += sw * vol;
        bud->nutrient_sunk += sv * vol;
    }
    return PHC_OK;
}

/* Absorbing factor of the voxel `i` layers in from an absorbing face. */
static double absorb_factor(phc_soil_absorb_form form, int width, int i)
{
    double x = form == PHC_SOIL_ABSORB_CODE ? (double)i * i : (double)i;
    return 1.0 - exp(-x / (0.2 * width * width));
}

/* Per-axis damping factors a^(h/dt), products of the two faces' factors. */
static void prepare_damping(phc_soil *s, double h)
{
    phc_soil_work *wk = s->work;
    if (wk->damp_h == h)
        return;
    wk->damp_h = h;
    size_t dims[3] = {s->nx, s->ny, s->nz};
    double *out[3] = {wk->damp_x, wk->damp_y, wk->damp_z};
    int W = s->params.absorb_width;
    double e = h / (s->params.absorb_dt > 0 ? s->params.absorb_dt : s->params.dt);
    for (int a = 0; a < 3; ++a)
        for (size_t i = 0; i < dims[a]; ++i) {
            double f = 1.0;
            if (s->params.boundary[2 * a] == PHC_SOIL_ABSORB && i < (size_t)W)
                f *= pow(absorb_factor(s->params.absorb_form, W, (int)i), e);
            size_t from_max = dims[a] - 1 - i;
            if (s->params.boundary[2 * a + 1] == PHC_SOIL_ABSORB && from_max < (size_t)W)
                f *= pow(absorb_factor(s->params.absorb_form, W, (int)from_max), e);
            out[a][i] = f;
        }
    wk->damp_xy_one = 1;
    for (size_t i = 0; i < s->nx; ++i)
        wk->damp_xy_one &= wk->damp_x[i] == 1.0;
    for (size_t j = 0; j < s->ny; ++j)
        wk->damp_xy_one &= wk->damp_y[j] == 1.0;
}

static int any_absorb(const phc_soil *s)
{
    for (int f = 0; f < PHC_SOIL_FACES; ++f)
        if (s->params.boundary[f] == PHC_SOIL_ABSORB)
            return 1;
    return 0;
}

/* Damps the field f in the absorbing layers; returns the amount removed
 * (sum over voxels, per-plane partials in a fixed order).  With g (or NULL)
 * a second field is damped the same way (no sum). */
static double damp(phc_soil *s, double *f, double *g)
{
    phc_soil_work *wk = s->work;
    const size_t nx = s->nx, ny = s->ny, nz = s->nz;
#pragma omp parallel for schedule(static) if (s->n >= PHC_SOIL_PARALLEL_MIN)
    for (size_t k = 0; k < nz; ++k) {
        double part = 0, fz = wk->damp_z[k];
        /* a plane whose every factor is 1 (an absorbing bottom only: all
           but its W planes) has nothing to damp */
        for (size_t j = 0; j < ny && !(fz == 1.0 && wk->damp_xy_one); ++j) {
            double fyz = fz * wk->damp_y[j];
            for (size_t i = 0; i < nx; ++i) {
                double fac = fyz * wk->damp_x[i];
                if (fac == 1.0)
                    continue;
                size_t q = i + nx * (j + ny * k);
                part += (1.0 - fac) * f[q];
                f[q] *= fac;
                if (g)
                    g[q] *= fac;
            }
        }
        wk->plane[k] = part;
    }
    double sum = 0;
    for (size_t k = 0; k < nz; ++k)
        sum += wk->plane[k];
    return sum;
}

static double field_total(const phc_soil *s, const double *f)
{
    phc_soil_work *wk = s->work;
    const size_t plane = s->nx * s->ny;
#pragma omp parallel for schedule(static) if (s->n >= PHC_SOIL_PARALLEL_MIN)
    for (size_t k = 0; k < s->nz; ++k) {
        double part = 0;
        for (size_t q = 0; q < plane; ++q)
            part += f[q + plane * k];
        wk->plane[k] = part;
    }
    double sum = 0;
    for (size_t k = 0; k < s->nz; ++k)
        sum += wk->plane[k];
    return sum * s->dx * s->dx * s->dx;
}

double phc_soil_water_total(const phc_soil *s)
{
    return field_total(s, s->w);
}

double phc_soil_nutrient_total(const phc_soil *s)
{
    return field_total(s, s->v);
}

void phc_soil_budget_reset(phc_soil *s)
{
    memset(&s->budget, 0, sizeof s->budget);
    s->budget.water_initial = s->budget.water_stored = phc_soil_water_total(s);
    s->budget.nutrient_initial = s->budget.nutrient_stored = phc_soil_nutrient_total(s);
}

/* ---- the tangent ----------------------------------------------------------- */

/* d harmonic(a, b) in the direction (da, db). */
static double harmonic_dir(double a, double b, double da, double db)
{
    if (!(a > 0 && b > 0))
        return 0;
    double sab = a + b;
    return 2 * (b * b * da + a * a * db) / (sab * sab);
}

/* One tangent sub-step for parameter q: sw_new = sw + h (L sw + dL w),
 * written to out.  Uses the state w before the step. */
static void tangent_step(phc_soil *s, double h, const phc_soil_tangent *tan, size_t m, double *out)
{
    phc_soil_work *wk = s->work;
    const size_t nx = s->nx, ny = s->ny, nz = s->nz, plane = nx * ny, n = s->n;
    const double *w = s->w, *ic = wk->ic, *p = s->p, *kz = wk->kz, *kx = wk->kx, *ky = wk->ky;
    const double *sw = tan->sw[m];
    const double *dp = tan->dp ? tan->dp[m] : NULL, *dic = tan->dinv_c ? tan->dinv_c[m] : NULL;
    const double dfd = tan->dfd ? tan->dfd[m] : 0, dfg = tan->dfg ? tan->dfg[m] : 0;
    const double dx = s->dx, fd = s->params.f_diff, a = s->params.f_grav;
    const double cd = h / (dx * dx), cg = h / dx, lw = h / (2 * dx);
    const int upwind = s->params.gravity == PHC_SOIL_GRAVITY_UPWIND;
#pragma omp parallel for schedule(static) if (s->n >= PHC_SOIL_PARALLEL_MIN)
    for (size_t k = 0; k < nz; ++k) {
        const size_t kup = k + 1 < nz ? plane : plane - n, kdn = k > 0 ? plane : plane - n;
        for (size_t j = 0; j < ny; ++j) {
            const size_t jn = j + 1 < ny ? nx : nx - plane, js = j > 0 ? nx : nx - plane;
            for (size_t i = 0; i < nx; ++i) {
                const size_t q = i + nx * (j + ny * k);
                const size_t nb[6] = {i + 1 < nx ? q + 1 : q + 1 - nx, i > 0 ? q - 1 : q + nx - 1,
                                      q + jn, q - js, q + kup, q - kdn};
                const double kf[6] = {kx[q], kx[nb[1]], ky[q], ky[nb[3]], kz[q], kz[nb[5]]};
                const double l0 = w[q] * ic[q], ls0 = sw[q] * ic[q];
                const double dl0 = dic ? w[q] * dic[q] : 0;
                double diff = 0;
                for (int f = 0; f < 6; ++f) {
                    size_t r = nb[f];
                    if (kf[f] == 0)
                        continue;
                    double dk = dp ? harmonic_dir(p[q], p[r], dp[q], dp[r]) : 0;
                    double lr = w[r] * ic[r], dlr = dic ? w[r] * dic[r] : 0;
                    diff += fd * kf[f] * (sw[r] * ic[r] - ls0)               /* L sw */
                          + dfd * kf[f] * (lr - l0) + fd * dk * (lr - l0)    /* dL w */
                          + fd * kf[f] * (dlr - dl0);
                }
                /* gravity faces: top (from nb[4] down into q), bottom (q down to nb[5]) */
                double grav = 0;
                for (int f = 0; f < 2; ++f) {
                    size_t up = f == 0 ? nb[4] : q, lo = f == 0 ? q : nb[5];
                    double k_f = f == 0 ? kz[q] : kz[nb[5]];
                    if (!(k_f > 0))
                        continue;
                    double dk = dp ? harmonic_dir(p[up], p[lo], dp[up], dp[lo]) : 0;
                    double qu = a * p[up] * w[up], ql = a * p[lo] * w[lo];
                    double squ = a * p[up] * sw[up], sql = a * p[lo] * sw[lo];
                    double dqu = dfg * p[up] * w[up] + (dp ? a * dp[up] * w[up] : 0);
                    double dql = dfg * p[lo] * w[lo] + (dp ? a * dp[lo] * w[lo] : 0);
                    double G = upwind ? squ + dqu /* F = q_up */
                                      : 0.5 * (squ + sql) - lw * a * k_f * (sql - squ) + 0.5 * (dqu + dql) -
                                            lw * ((dfg * k_f + a * dk) * (ql - qu) + a * k_f * (dql - dqu));
                    grav += f == 0 ? G : -G;
                }
                out[q] = sw[q] + cd * diff + cg * grav;
            }
        }
    }
}

/* ---- running --------------------------------------------------------------- */

/* The step of phc_soil_run that starts at t: its length *h (params.dt, the
 * last one shortened to land on t_end) and its sub-steps *nsub.  Returns 0
 * when t_end is reached, -1 when the step exceeds the stability limit and
 * sub-stepping is off, 1 otherwise. */
static int plan_step(const phc_soil *s, double t, double t_end, double eps, double limit, double *h,
                     size_t *nsub)
{
    if (!(t_end - t > eps))
        return 0;
    const double dt = s->params.dt;
    *h = t_end - t < dt ? t_end - t : dt;
    *nsub = 1;
    if (*h > limit) {
        if (!s->params.substep)
            return -1;
        *nsub = (size_t)ceil(*h / (s->params.safety * limit));
    }
    return 1;
}

/* Whether rain or a source changes w during the sub-step [t, t + h) (as
 * sources_and_sinks tests them). */
static int sources_act(const phc_soil *s, double t, double h)
{
    for (size_t r = 0; r < s->n_rain; ++r)
        if (s->rain[r].rate > 0 && overlap(t, t + h, s->rain[r].start, s->rain[r].end) > 0)
            return 1;
    for (size_t q = 0; q < s->n_sources; ++q)
        if (overlap(t, t + h, s->sources[q].start, s->sources[q].end) > 0)
            return 1;
    return 0;
}

static int run_impl(phc_soil *s, double t_end, const phc_soil_tangent *tan, phc_error *err)
{
    int rc;
    /* Lax-Wendroff may leave round-off undershoots below 0 between runs:
       the sign is checked on input (phc_soil_check), not here */
    if ((rc = check_impl(s, 0, err)))
        return rc;
    if (!(t_end >= s->t) || !isfinite(t_end))
        return phc_error_set(err, PHC_ERR_INPUT, "soil: cannot run from t = %g h back to %g h", s->t, t_end);
    prepare_fields(s);
    if (prepare_sources(s))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    double **tmp = NULL;
    size_t swaps = 0; /* sub-steps done: tan->sw[m] and tmp[m] trade places on each */
    if (tan && tan->m) {
        tmp = calloc(tan->m, sizeof *tmp);
        if (!tmp)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t m = 0; m < tan->m; ++m)
            if (!(tmp[m] = malloc(s->n * sizeof(double)))) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto done;
            }
    }
    size_t at = 0;
    const double limit = stable_dt_prepared(s, &at), dt = s->params.dt;
    const double eps = 1e-12 * (fabs(t_end) > 1 ? fabs(t_end) : 1);
    if (s->params.substep && s->params.max_substeps && t_end - s->t > eps) {
        double first = fmin(dt, t_end - s->t), need = ceil(first / (s->params.safety * limit));
        if (first > limit && need > (double)s->params.max_substeps) {
            rc = phc_error_set(err, PHC_ERR_DOMAIN,
                               "soil: a step of %g h would need %.0f sub-steps (stability limit %.3g h), more than "
                               "max_substeps = %zu: the soil is too fast for the grid at these parameters",
                               first, need, limit, s->params.max_substeps);
            goto done;
        }
    }
    const int absorb = any_absorb(s);
    phc_soil_work *wk = s->work;
    /* several sub-steps per sweep only when nothing but transport acts */
    const size_t fuse_max = (!tan && !wk->nutrients && !absorb && !s->sink) ? block_levels(s) : 1;
    if (prepare_ring(s, fuse_max)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    double h = 0, hs = 0;
    size_t nsub = 0, sub = 0; /* the current step's sub-steps, and those done */
    for (;;) {
        if (sub == nsub) {
            int pl = plan_step(s, s->t, t_end, eps, limit, &h, &nsub);
            if (pl == 0)
                break;
            if (pl < 0) {
                size_t i = at % s->nx, j = (at / s->nx) % s->ny, k = at / (s->nx * s->ny);
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "soil: the time step dt = %g h exceeds the stability limit %g h set by voxel "
                                   "(%zu, %zu, %zu) (p = %g m/h, c = %g); lower dt or allow sub-stepping",
                                   h, limit, i, j, k, s->p[at], s->c[at]);
                goto done;
            }
            hs = h / (double)nsub;
            sub = 0;
            if (absorb)
                prepare_damping(s, hs);
        }
        double t0 = s->t;
        /* the sub-steps of the same length h ahead with no rain or source
           acting, up to fuse_max, across steps of dt: one sweep takes them */
        size_t F = 1;
        if (fuse_max > 1 && !sources_act(s, t0, hs)) {
            double t = t0 + hs;
            size_t sb = sub + 1, ns = nsub;
            while (F < fuse_max) {
                if (sb == ns) {
                    double h2;
                    if (plan_step(s, t, t_end, eps, limit, &h2, &ns) != 1 || h2 / (double)ns != hs)
                        break;
                    sb = 0;
                }
                if (sources_act(s, t, hs))
                    break;
                ++F;
                t = t + hs;
                ++sb;
            }
        }
        if (F > 1) {
            transport_water(s, hs, F);
            double *swap = s->w;
            s->w = wk->w_new;
            wk->w_new = swap;
            for (size_t f = 0; f < F; ++f) {
                s->t = s->t + hs;
                if (++sub == nsub) {
                    s->budget.steps++;
                    s->budget.substeps += nsub;
                    if (f + 1 < F) {
                        plan_step(s, s->t, t_end, eps, limit, &h, &nsub);
                        sub = 0;
                    }
                }
            }
            continue;
        }
        if (tan)
            for (size_t m = 0; m < tan->m; ++m)
                tangent_step(s, hs, tan, m, tmp[m]);
        transport(s, hs);
        if ((rc = sources_and_sinks(s, t0, hs, &s->budget))) {
            rc = phc_error_set(err, rc, rc == PHC_ERR_NOMEM ? "out of memory"
                                                            : "soil: the sink hook stopped the run at t = %g h",
                               t0);
            goto done;
        }
        if (absorb) {
            double vol = s->dx * s->dx * s->dx;
            s->budget.water_absorbed += damp(s, wk->w_new, NULL) * vol;
            s->budget.nutrient_absorbed += damp(s, wk->nutrients ? wk->v_new : s->v, NULL) * vol;
            if (tan)
                for (size_t m = 0; m < tan->m; ++m)
                    damp(s, tmp[m], NULL);
        }
        double *swap = s->w;
        s->w = wk->w_new;
        wk->w_new = swap;
        if (wk->nutrients) {
            swap = s->v;
            s->v = wk->v_new;
            wk->v_new = swap;
        }
        if (tan)
            for (size_t m = 0; m < tan->m; ++m) {
                swap = tan->sw[m];
                tan->sw[m] = tmp[m];
                tmp[m] = swap;
            }
        ++swaps;
        s->t = t0 + hs;
        if (++sub == nsub) {
            s->budget.steps++;
            s->budget.substeps += nsub;
        }
    }
    s->t = t_end;
    s->budget.water_stored = phc_soil_water_total(s);
    s->budget.nutrient_stored = phc_soil_nutrient_total(s);
    s->budget.water_closing = s->budget.water_stored - s->budget.water_initial - s->budget.water_in +
                              s->budget.water_absorbed + s->budget.water_sunk;
    s->budget.nutrient_closing = s->budget.nutrient_stored - s->budget.nutrient_initial -
                                 s->budget.nutrient_in + s->budget.nutrient_absorbed + s->budget.nutrient_sunk;
    if (!isfinite(s->budget.water_stored) || !isfinite(s->budget.nutrient_stored))
        rc = phc_error_set(err, PHC_ERR_DOMAIN, "soil: the state is no longer finite at t = %g h", s->t);
done:
    if (tmp) {
        for (size_t m = 0; m < tan->m; ++m) {
            if (swaps % 2) {
                /* tmp[m] is the caller's buffer: give it back holding the result */
                memcpy(tmp[m], tan->sw[m], s->n * sizeof(double));
                double *swap = tan->sw[m];
                tan->sw[m] = tmp[m];
                tmp[m] = swap;
            }
            free(tmp[m]);
        }
        free(tmp);
    }
    return rc;
}

int phc_soil_run(phc_soil *s, double t_end, phc_error *err)
{
    return run_impl(s, t_end, NULL, err);
}

int phc_soil_run_tangent(phc_soil *s, double t_end, const phc_soil_tangent *tan, phc_error *err)
{
    return run_impl(s, t_end, tan, err);
}

/* ---- observations ------------------------------------------------------------ */

int phc_soil_sample(const phc_soil *s, const double *f, double x, double y, double z, double *value,
                    double wts[8], size_t idx[8])
{
    double pos[3] = {x, y, z};
    size_t dims[3] = {s->nx, s->ny, s->nz}, lo[3], hi[3];
    double t[3];
    for (int a = 0; a < 3; ++a) {
        double ext = dims[a] * s->dx;
        if (!(pos[a] >= 0 && pos[a] <= ext))
            return PHC_ERR_DOMAIN;
        double fi = pos[a] / s->dx - 0.5;
        if (fi < 0)
            fi = 0;
        if (fi > (double)(dims[a] - 1))
            fi = (double)(dims[a] - 1);
        lo[a] = (size_t)floor(fi);
        hi[a] = lo[a] + 1 < dims[a] ? lo[a] + 1 : lo[a];
        t[a] = fi - (double)lo[a];
    }
    double val = 0;
    for (int c = 0; c < 8; ++c) {
        int bx = c & 1, by = (c >> 1) & 1, bz = (c >> 2) & 1;
        double wgt = (bx ? t[0] : 1 - t[0]) * (by ? t[1] : 1 - t[1]) * (bz ? t[2] : 1 - t[2]);
        size_t q = idx3(s, bx ? hi[0] : lo[0], by ? hi[1] : lo[1], bz ? hi[2] : lo[2]);
        val += wgt * f[q];
        if (wts)
            wts[c] = wgt;
        if (idx)
            idx[c] = q;
    }
    *value = val;
    return PHC_OK;
}

double phc_soil_infiltration_depth(const phc_soil *s, const double *w_ref, double frac, double total,
                                   const double *ds, double *dd)
{
    const size_t plane = s->nx * s->ny;
    const double vol = s->dx * s->dx * s->dx, target = frac * total;
    double cum = 0, dcum = 0;
    if (dd)
        *dd = 0;
    for (size_t m = 0; m < s->nz; ++m) {
        size_t k = s->nz - 1 - m;
        double e = 0, de = 0;
        for (size_t q = 0; q < plane; ++q) {
            e += s->w[q + plane * k] - (w_ref ? w_ref[q + plane * k] : 0);
            if (ds)
                de += ds[q + plane * k];
        }
        e *= vol;
        de *= vol;
        if (e > 0 && cum + e >= target) {
            double rem = target - cum;
            if (dd && ds)
                *dd = s->dx * (-dcum * e - rem * de) / (e * e);
            return s->dx * ((double)m + rem / e);
        }
        cum += e;
        dcum += de;
    }
    return NAN;
}
