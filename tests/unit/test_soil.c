/* Unit tests of the soil water and nutrient model (model/soil.h): exact
 * solutions and limits of the finite-volume discretisation documented in
 * soil.h.  One line per check with the measured numbers.  4b: time
 * blocking (several sub-steps per sweep) gives the numbers of one sub-step
 * per sweep, bit for bit, for 1-3 threads; 4c: on a random field, k
 * steps in one run (blocked sweeps) equal k runs of one step and a plain
 * one-voxel-at-a-time stencil, bit for bit, both gravity schemes, 1 and 2
 * threads. */
#include "check.h"

#include <omp.h>
#include <stdint.h>
#include <stdlib.h>

#include "model/soil.h"

static phc_soil *new_soil(size_t nx, size_t ny, size_t nz, double dx)
{
    phc_soil *s = phc_soil_new(nx, ny, nz, dx);
    if (!s) {
        fprintf(stderr, "phc_soil_new failed\n");
        exit(2);
    }
    return s;
}

static void must(int rc, const phc_error *err, const char *what)
{
    if (rc) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(2);
    }
}

static double maxv(const double *f, size_t n)
{
    double m = -INFINITY;
    for (size_t i = 0; i < n; ++i)
        m = f[i] > m ? f[i] : m;
    return m;
}

static double minv(const double *f, size_t n)
{
    double m = INFINITY;
    for (size_t i = 0; i < n; ++i)
        m = f[i] < m ? f[i] : m;
    return m;
}

static double *copy_of(const double *f, size_t n)
{
    double *c = malloc(n * sizeof *c);
    if (!c)
        exit(2);
    memcpy(c, f, n * sizeof *c);
    return c;
}

/* ---- 1. 1-D diffusion against erfc ---------------------------------------- */

/* Step w = 1 for x < 0.5 m on a column along x; returns max |w - erfc solution|
 * at T with sqrt(D T) = 0.05 m and D dt / dx^2 = 0.1 (fixed ratio, so the
 * total error is O(dx^2)). */
static double diffusion_error(size_t nx, double dx)
{
    phc_soil *s = new_soil(nx, 1, 1, dx);
    phc_error err;
    const double c = 2.0, p = 0.01, D = 1.0 * p / c, T = 0.05 * 0.05 / D;
    s->params.f_grav = 0;
    s->params.f_diff = 1;
    for (size_t i = 0; i < nx; ++i) {
        s->c[i] = c;
        s->p[i] = p;
        s->w[i] = (i + 0.5) * dx < 0.5 ? 1.0 : 0.0;
    }
    double limit = phc_soil_stable_dt(s, NULL), expect = c * dx * dx / (2 * p);
    s->params.dt = 0.1 * dx * dx / D;
    s->params.substep = 0;
    printf("  diffusion nx=%zu dx=%g: stable_dt %.9g h (c dx^2/(2 f_diff p) = %.9g), dt %.3g h = %.2f limit, "
           "T %.3g h\n",
           nx, dx, limit, expect, s->params.dt, s->params.dt / limit, T);
    CHECK_NEAR(limit, expect, 0, 1e-14);
    must(phc_soil_run(s, T, &err), &err, "diffusion run");
    double e = 0, sq = 2 * sqrt(D * T);
    for (size_t i = 0; i < nx; ++i) {
        double x = (i + 0.5) * dx, ex = 0.5 * erfc((x - 0.5) / sq);
        double d = fabs(s->w[i] - ex);
        e = d > e ? d : e;
    }
    phc_soil_free(s);
    return e;
}

static void test_diffusion_erfc(void)
{
    double e1 = diffusion_error(200, 0.005), e2 = diffusion_error(400, 0.0025);
    printf("1. diffusion vs 0.5 erfc: max err dx=0.005 %.3e, dx=0.0025 %.3e, ratio %.3f (second order: 4)\n", e1,
           e2, e1 / e2);
    CHECK(e1 < 2e-4);
    CHECK(e1 / e2 > 3.0 && e1 / e2 < 5.0);
}

/* ---- 2. gravity-advected Gaussian pulse ------------------------------------ */

static void test_gravity_pulse(void)
{
    const size_t nz = 400;
    const double dx = 0.005, p = 0.2, z0 = 1.5, sig = 0.05, T = 2.0, fg = 1.0;
    phc_soil *s = new_soil(1, 1, nz, dx);
    phc_error err;
    s->params.f_diff = 0;
    s->params.f_grav = fg;
    for (size_t k = 0; k < nz; ++k) {
        double z = (k + 0.5) * dx;
        s->p[k] = p;
        s->w[k] = exp(-(z - z0) * (z - z0) / (2 * sig * sig));
    }
    double limit = phc_soil_stable_dt(s, NULL);
    CHECK_NEAR(limit, dx / (fg * p), 0, 1e-14);
    s->params.dt = 0.4 * limit; /* Courant number 0.4 */
    s->params.substep = 0;
    double m0 = 0, m1 = 0;
    for (size_t k = 0; k < nz; ++k) {
        m0 += s->w[k];
        m1 += (k + 0.5) * dx * s->w[k];
    }
    double zc0 = m1 / m0;
    must(phc_soil_run(s, T, &err), &err, "pulse run");
    double n0 = 0, n1 = 0, emax = 0;
    for (size_t k = 0; k < nz; ++k) {
        double z = (k + 0.5) * dx, zc = z0 - fg * p * T;
        n0 += s->w[k];
        n1 += z * s->w[k];
        double d = fabs(s->w[k] - exp(-(z - zc) * (z - zc) / (2 * sig * sig)));
        emax = d > emax ? d : emax;
    }
    double shift = n1 / n0 - zc0, expect = -fg * p * T;
    printf("2. gravity pulse (Courant 0.4, %zu steps): centroid shift %.15f m (exact %.15f, rel err %.2e), "
           "mass rel change %.2e, max shape err %.4f of the peak\n",
           s->budget.steps, shift, expect, fabs(shift / expect - 1), fabs(n0 / m0 - 1), emax);
    CHECK_NEAR(shift, expect, 0, 1e-9);
    CHECK_NEAR(n0, m0, 0, 1e-13);
    CHECK(emax < 0.03);
    phc_soil_free(s);
}

/* ---- 3./4. conservation with blocking walls, threads ----------------------- */

/* 12x10x14, two layers, rocks, nutrient pockets; dt = 0.5 limit. */
static phc_soil *mixed_soil(size_t *rocks)
{
    phc_soil *s = new_soil(12, 10, 14, 0.01);
    phc_error err;
    phc_soil_layer L[2] = {
        {.thickness = 0.06, .c = 5, .p = 0.05, .d = 1, .water = 0, .fill = 0.3, .nutrient = 2},
        {.thickness = 0, .c = 10, .p = 0.02, .d = 2, .water = 0, .fill = 0.6, .nutrient = 0.5}};
    must(phc_soil_set_layers(s, L, 2, &err), &err, "layers");
    size_t r = phc_soil_add_rocks(s, 42, 0.03, 0.15);
    if (rocks)
        *rocks = r;
    phc_soil_add_nutrient_pockets(s, 7, 0.02, 0.1, 5.0);
    /* some structure in w too, so both directions carry flux */
    for (size_t q = 0; q < s->n; ++q)
        s->w[q] *= 0.5 + phc_soil_noise(11, 0.025, (q % 12 + 0.5) * 0.01, (q / 12 % 10 + 0.5) * 0.01,
                                        (q / 120 + 0.5) * 0.01);
    s->params.f_diff = 1;
    s->params.f_grav = 1;
    s->params.dt = 0.5 * phc_soil_stable_dt(s, NULL);
    s->params.substep = 0;
    return s;
}

static void test_conservation(void)
{
    size_t rocks = 0;
    phc_soil *s = mixed_soil(&rocks);
    phc_error err;
    double W0 = phc_soil_water_total(s), V0 = phc_soil_nutrient_total(s);
    double *w0 = copy_of(s->w, s->n), *v0 = copy_of(s->v, s->n);
    phc_soil_budget_reset(s);
    must(phc_soil_run(s, 300 * s->params.dt, &err), &err, "conservation run");
    double W1 = phc_soil_water_total(s), V1 = phc_soil_nutrient_total(s);
    size_t nrock = 0, rock_same = 0, moved = 0;
    for (size_t q = 0; q < s->n; ++q) {
        if (s->p[q] == 0) {
            ++nrock;
            rock_same += s->w[q] == w0[q] && s->v[q] == v0[q];
        } else
            moved += s->w[q] != w0[q];
    }
    const phc_soil_budget *b = &s->budget;
    printf("3. conservation (%zu rocks, %zu steps, dt %.3g h): water rel change %.2e, nutrients %.2e; "
           "closing water %.2e, nutrients %.2e (rel); rocks unchanged %zu/%zu; soil voxels changed %zu/%zu\n",
           rocks, b->steps, s->params.dt, fabs(W1 / W0 - 1), fabs(V1 / V0 - 1), fabs(b->water_closing) / W0,
           fabs(b->nutrient_closing) / V0, rock_same, nrock, moved, s->n - nrock);
    CHECK(b->steps == 300 && b->substeps == 300);
    CHECK(rocks == nrock && nrock > 0);
    CHECK_NEAR(W1, W0, 0, 1e-12);
    CHECK_NEAR(V1, V0, 0, 1e-12);
    CHECK(fabs(b->water_closing) < 1e-12 * W0);
    CHECK(fabs(b->nutrient_closing) < 1e-12 * V0);
    CHECK(b->water_in == 0 && b->water_absorbed == 0 && b->water_sunk == 0);
    CHECK(rock_same == nrock);
    CHECK(moved > (s->n - nrock) / 2);
    free(w0);
    free(v0);
    phc_soil_free(s);
}

static void test_threads(void)
{
    phc_error err;
    phc_soil *s[3];
    const int threads[3] = {1, 2, 3};
    int saved = omp_get_max_threads();
    for (int r = 0; r < 3; ++r) {
        omp_set_num_threads(threads[r]);
        s[r] = mixed_soil(NULL);
        phc_soil_budget_reset(s[r]);
        must(phc_soil_run(s[r], 300 * s[r]->params.dt, &err), &err, "thread run");
    }
    omp_set_num_threads(saved);
    for (int r = 1; r < 3; ++r) {
        size_t n = s[0]->n;
        int same_w = !memcmp(s[0]->w, s[r]->w, n * sizeof(double));
        int same_v = !memcmp(s[0]->v, s[r]->v, n * sizeof(double));
        const phc_soil_budget *a = &s[0]->budget, *b = &s[r]->budget;
        int same_b = a->water_stored == b->water_stored && a->water_closing == b->water_closing &&
                     a->nutrient_stored == b->nutrient_stored && a->nutrient_closing == b->nutrient_closing &&
                     a->water_initial == b->water_initial && a->steps == b->steps && a->substeps == b->substeps;
        printf("4. threads 1 vs %d: w bit-identical %s, v %s, budget %s (closing %.3e vs %.3e)\n", threads[r],
               same_w ? "yes" : "NO", same_v ? "yes" : "NO", same_b ? "yes" : "NO", a->water_closing,
               b->water_closing);
        CHECK(same_w);
        CHECK(same_v);
        CHECK(same_b);
    }
    for (int r = 0; r < 3; ++r)
        phc_soil_free(s[r]);
}

/* ---- 4b. time blocking: bit-identical to one sub-step per sweep ------------- */

/* A water-only soil (no nutrients) of nx x ny x nz voxels: two layers,
 * rocks (none with `layers_only`: every z-plane uniform), w from noise. */
static phc_soil *water_soil(size_t nx, size_t ny, size_t nz, int layers_only)
{
    phc_soil *s = new_soil(nx, ny, nz, 0.01);
    phc_error err;
    phc_soil_layer L[2] = {{.thickness = 0.01 * (double)(nz / 2), .c = 5, .p = 0.05, .d = 1, .fill = 0.3},
                           {.thickness = 0, .c = 10, .p = 0.02, .d = 2, .fill = 0.6}};
    must(phc_soil_set_layers(s, L, 2, &err), &err, "layers");
    if (!layers_only)
        phc_soil_add_rocks(s, 42, 0.03, 0.15);
    for (size_t q = 0; q < s->n; ++q)
        s->w[q] *= 0.5 + phc_soil_noise(11, 0.025, (q % nx + 0.5) * 0.01, (q / nx % ny + 0.5) * 0.01,
                                        (q / (nx * ny) + 0.5) * 0.01);
    s->params.f_diff = 1;
    s->params.f_grav = 1;
    return s;
}

static void test_blocking(void)
{
    /* cases: sizes (nz 40: 4 sub-steps per sweep; 16: 2; 9: 1), faces,
       gravity scheme, sub-stepping with a shortened last step, and rain
       over part of the run (sweeps stop at its start and resume after) */
    static const struct { size_t nx, ny, nz; int periodic, upwind, substep, rain, layers_only; } C[] = {
        {24, 20, 40, 0, 0, 0, 0, 0}, {24, 20, 40, 1, 0, 0, 0, 0}, {24, 20, 40, 0, 1, 0, 0, 0},
        {24, 20, 40, 0, 0, 1, 1, 0}, {33, 17, 16, 1, 1, 1, 0, 0}, {40, 30, 9, 0, 0, 0, 1, 0},
        {24, 20, 40, 0, 0, 0, 0, 1}, {33, 17, 40, 0, 1, 1, 1, 1}, {24, 20, 40, 1, 0, 0, 0, 1}};
    const int threads[4] = {1, 1, 2, 3};
    const size_t block[4] = {1, 0, 0, 3};
    int saved = omp_get_max_threads();
    for (size_t c = 0; c < sizeof C / sizeof C[0]; ++c) {
        phc_soil *s[4];
        for (int r = 0; r < 4; ++r) {
            omp_set_num_threads(threads[r]);
            s[r] = water_soil(C[c].nx, C[c].ny, C[c].nz, C[c].layers_only);
            phc_soil *x = s[r];
            if (C[c].periodic)
                for (int f = 0; f < PHC_SOIL_FACES; f += 1)
                    if (f != PHC_SOIL_YMIN && f != PHC_SOIL_YMAX)
                        x->params.boundary[f] = PHC_SOIL_PERIODIC;
            x->params.gravity = C[c].upwind ? PHC_SOIL_GRAVITY_UPWIND : PHC_SOIL_GRAVITY_LAX_WENDROFF;
            double lim = phc_soil_stable_dt(x, NULL);
            x->params.dt = C[c].substep ? 2.5 * lim : 0.5 * lim;
            x->params.substep = C[c].substep;
            x->params.block_steps = block[r];
            phc_error err;
            if (C[c].rain) {
                phc_soil_rain rn = {.start = 20 * x->params.dt, .end = 23.5 * x->params.dt, .rate = 1e-4};
                must(phc_soil_set_rain(x, &rn, 1, &err), &err, "rain");
            }
            phc_soil_budget_reset(x);
            must(phc_soil_run(x, 61.3 * x->params.dt, &err), &err, "blocking run");
        }
        for (int r = 1; r < 4; ++r) {
            const phc_soil_budget *a = &s[0]->budget, *b = &s[r]->budget;
            int same_w = !memcmp(s[0]->w, s[r]->w, s[0]->n * sizeof(double));
            int same_b = a->water_stored == b->water_stored && a->water_in == b->water_in &&
                         a->water_closing == b->water_closing && a->steps == b->steps &&
                         a->substeps == b->substeps && s[0]->t == s[r]->t;
            double dmax = 0;
            for (size_t q = 0; q < s[0]->n; ++q)
                dmax = fmax(dmax, fabs(s[0]->w[q] - s[r]->w[q]));
            printf("4b. blocking %zux%zux%zu%s%s%s%s%s: block_steps %zu (%zu per sweep), %d thread%s vs 1 sub-step per sweep, 1 "
                   "thread: w bit-identical %s (max |dw| %.1e), budget and t %s (%zu steps, %zu sub-steps, water "
                   "in %.3e m^3)\n", C[c].nx, C[c].ny, C[c].nz, C[c].periodic ? ", x z periodic" : "",
                   C[c].upwind ? ", upwind" : "", C[c].substep ? ", sub-stepped" : "", C[c].rain ? ", rain" : "",
                   C[c].layers_only ? ", layers only" : "", block[r], phc_soil_block_steps(s[r]), threads[r], threads[r] > 1 ? "s" : "", same_w ? "yes" : "NO", dmax,
                   same_b ? "yes" : "NO", b->steps, b->substeps, b->water_in);
            CHECK(same_w);
            CHECK(same_b);
        }
        CHECK(!C[c].rain || s[0]->budget.water_in > 0);
        for (int r = 0; r < 4; ++r)
            phc_soil_free(s[r]);
    }
    omp_set_num_threads(saved);
}

/* ---- 4c. blocked sweeps = one step at a time = the plain stencil ------------- */

/* The water-only step written one voxel at a time, as soil.h states it
 * (voxel_faces' terms, face permeabilities as prepare_fields makes them),
 * without planes, rings or shared faces: k steps of h on w (n values). */
static double ref_harmonic(double a, double b)
{
    return (a > 0 && b > 0) ? 2 * a * b / (a + b) : 0;
}

static void ref_steps(const phc_soil *s, double *w, double h, size_t steps)
{
    const size_t nx = s->nx, ny = s->ny, nz = s->nz, P = nx * ny, n = s->n;
    const phc_soil_boundary *b = s->params.boundary;
    const int per[3] = {b[PHC_SOIL_XMIN] == PHC_SOIL_PERIODIC, b[PHC_SOIL_YMIN] == PHC_SOIL_PERIODIC,
                        b[PHC_SOIL_ZMIN] == PHC_SOIL_PERIODIC};
    double *kx = malloc(n * sizeof *kx), *ky = malloc(n * sizeof *ky), *kz = malloc(n * sizeof *kz),
           *ic = malloc(n * sizeof *ic), *wn = malloc(n * sizeof *wn);
    if (!kx || !ky || !kz || !ic || !wn) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    for (size_t k = 0; k < nz; ++k)
        for (size_t j = 0; j < ny; ++j)
            for (size_t i = 0; i < nx; ++i) {
                size_t q = i + nx * (j + ny * k);
                ic[q] = 1.0 / s->c[q];
                kx[q] = (i + 1 < nx || per[0]) ? ref_harmonic(s->p[q], s->p[i + 1 < nx ? q + 1 : q + 1 - nx]) : 0;
                ky[q] = (j + 1 < ny || per[1]) ? ref_harmonic(s->p[q], s->p[j + 1 < ny ? q + nx : q + nx - P]) : 0;
                kz[q] = (k + 1 < nz || per[2]) ? ref_harmonic(s->p[q], s->p[k + 1 < nz ? q + P : q + P - n]) : 0;
            }
    const double dx = s->dx, fd = s->params.f_diff, a = s->params.f_grav, *p = s->p;
    const double cd = h * fd / (dx * dx), cg = h / dx, lw = h * a / (2 * dx);
    const int up = s->params.gravity == PHC_SOIL_GRAVITY_UPWIND;
    for (size_t st = 0; st < steps; ++st) {
        for (size_t k = 0; k < nz; ++k)
            for (size_t j = 0; j < ny; ++j)
                for (size_t i = 0; i < nx; ++i) {
                    const size_t q = i + nx * (j + ny * k);
                    const size_t qe = i + 1 < nx ? q + 1 : q + 1 - nx, qw = i > 0 ? q - 1 : q + nx - 1;
                    const size_t qn = j + 1 < ny ? q + nx : q + nx - P, qs = j > 0 ? q - nx : q + P - nx;
                    const size_t qu = k + 1 < nz ? q + P : q + P - n, qd = k > 0 ? q - P : q + n - P;
                    const double l0 = w[q] * ic[q];
                    const double f0 = kx[q] * (w[qe] * ic[qe] - l0), f1 = kx[qw] * (w[qw] * ic[qw] - l0);
                    const double f2 = ky[q] * (w[qn] * ic[qn] - l0), f3 = ky[qs] * (w[qs] * ic[qs] - l0);
                    const double f4 = kz[q] * (w[qu] * ic[qu] - l0), f5 = kz[qd] * (w[qd] * ic[qd] - l0);
                    const double q0 = a * p[q] * w[q], qU = a * p[qu] * w[qu], qD = a * p[qd] * w[qd];
                    const double f6 = kz[q] > 0 ? 0.5 * (qU + q0) - (up ? 0.5 : lw * kz[q]) * (q0 - qU) : 0;
                    const double f7 = kz[qd] > 0 ? 0.5 * (q0 + qD) - (up ? 0.5 : lw * kz[qd]) * (qD - q0) : 0;
                    wn[q] = w[q] + cd * (f0 + f1 + f2 + f3 + f4 + f5) + cg * (f6 - f7);
                }
        memcpy(w, wn, n * sizeof *w);
    }
    free(kx);
    free(ky);
    free(kz);
    free(ic);
    free(wn);
}

/* A random water-only field: c and p per voxel from a seeded generator,
 * about 1 voxel in 8 rock (p = 0) and 1 in 16 dry (w = 0).  With
 * `layered`, c and p are drawn per z-plane instead (random layers: the
 * planes the sweep takes as uniform, soil.c plane_uniform), every seventh
 * is rock throughout, and with layered = 1 every fourth plane has rocks
 * (p = 0 in about 1 voxel in 8: not uniform). */
static phc_soil *random_soil(size_t nx, size_t ny, size_t nz, uint64_t seed, int layered)
{
    phc_soil *s = new_soil(nx, ny, nz, 0.01);
    uint64_t x = seed;
    const size_t P = nx * ny;
    double ck = 0, pk = 0;
    for (size_t q = 0; q < s->n; ++q) {
        double u[4];
        for (int e = 0; e < 4; ++e) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            u[e] = (double)(x >> 11) * 0x1.0p-53;
        }
        if (!layered) {
            s->c[q] = 2 + 18 * u[0];
            s->p[q] = u[1] < 0.125 ? 0 : 0.005 + 0.1 * u[2];
        } else {
            const size_t k = q / P;
            if (q % P == 0) {
                ck = 2 + 18 * u[0];
                pk = k % 7 == 5 ? 0 : 0.005 + 0.1 * u[2];
            }
            s->c[q] = ck;
            s->p[q] = layered == 1 && k % 4 == 3 && u[1] < 0.125 ? 0 : pk;
        }
        s->w[q] = u[3] < 0.0625 ? 0 : s->c[q] * u[3];
    }
    s->params.f_diff = 1;
    s->params.f_grav = 1;
    return s;
}

static void test_blocked_vs_steps(void)
{
    /* nz 40: 4 sub-steps per sweep (the default); 13 x 11 rows, so no row
       is a multiple of a vector; x periodic in some cases, y periodic in
       one; planes of one row or one column and of two rows, where every
       voxel is at a row's end or in the first or last row (water_plane
       computes those apart from the rest) */
    static const struct { int upwind, periodic, yperiodic; size_t nx, ny; int layered, zperiodic; } C[] = {
        {0, 0, 0, 13, 11, 0, 0}, {1, 0, 0, 13, 11, 0, 0}, {0, 1, 0, 13, 11, 0, 0}, {1, 1, 0, 13, 11, 0, 0},
        {0, 1, 1, 13, 11, 0, 0}, {0, 0, 1, 1, 9, 0, 0},   {1, 1, 0, 7, 1, 0, 0},   {0, 1, 1, 6, 2, 0, 0},
        {0, 0, 0, 13, 11, 1, 0}, {1, 0, 0, 13, 11, 1, 0}, {0, 1, 0, 13, 11, 1, 0}, {1, 1, 1, 13, 11, 1, 0},
        {0, 0, 1, 1, 9, 1, 0},   {0, 1, 1, 6, 3, 1, 0},   {0, 0, 0, 13, 11, 2, 0}, {1, 0, 1, 13, 11, 2, 0},
        {0, 0, 0, 1, 2, 2, 0},   {0, 0, 0, 13, 11, 2, 1}, {1, 0, 1, 13, 11, 1, 1}};
    const size_t nz = 40, K = 23;
    int saved = omp_get_max_threads();
    for (size_t c = 0; c < sizeof C / sizeof C[0]; ++c)
        for (int th = 1; th <= 2; ++th) {
            omp_set_num_threads(th);
            const size_t nx = C[c].nx, ny = C[c].ny;
            phc_soil *s[2];
            for (int r = 0; r < 2; ++r) {
                s[r] = random_soil(nx, ny, nz, 2026 + c, C[c].layered);
                s[r]->params.gravity = C[c].upwind ? PHC_SOIL_GRAVITY_UPWIND : PHC_SOIL_GRAVITY_LAX_WENDROFF;
                if (C[c].periodic)
                    s[r]->params.boundary[PHC_SOIL_XMIN] = s[r]->params.boundary[PHC_SOIL_XMAX] = PHC_SOIL_PERIODIC;
                if (C[c].yperiodic)
                    s[r]->params.boundary[PHC_SOIL_YMIN] = s[r]->params.boundary[PHC_SOIL_YMAX] = PHC_SOIL_PERIODIC;
                if (C[c].zperiodic)
                    s[r]->params.boundary[PHC_SOIL_ZMIN] = s[r]->params.boundary[PHC_SOIL_ZMAX] = PHC_SOIL_PERIODIC;
                s[r]->params.substep = 0;
            }
            /* a power of 2 below half the limit: the times k h, and their
               differences, are exact, so every step of either run is h */
            const double h = exp2(floor(log2(0.5 * phc_soil_stable_dt(s[0], NULL))));
            double *ref = malloc(s[0]->n * sizeof *ref), *w0 = malloc(s[0]->n * sizeof *w0);
            if (!ref || !w0)
                exit(2);
            memcpy(w0, s[0]->w, s[0]->n * sizeof *w0);
            memcpy(ref, s[0]->w, s[0]->n * sizeof *ref);
            double moved = 0;
            ref_steps(s[0], ref, h, K);
            phc_error err;
            /* s[0]: one run of K steps (blocked sweeps); s[1]: K runs of one step */
            s[0]->params.dt = s[1]->params.dt = h;
            must(phc_soil_run(s[0], (double)K * h, &err), &err, "blocked run");
            for (size_t k = 1; k <= K; ++k)
                must(phc_soil_run(s[1], s[1]->t + h, &err), &err, "single step");
            int same_steps = !memcmp(s[0]->w, s[1]->w, s[0]->n * sizeof(double));
            int same_ref = !memcmp(s[0]->w, ref, s[0]->n * sizeof(double));
            double d1 = 0, d2 = 0;
            for (size_t q = 0; q < s[0]->n; ++q) {
                d1 = fmax(d1, fabs(s[0]->w[q] - s[1]->w[q]));
                d2 = fmax(d2, fabs(s[0]->w[q] - ref[q]));
                moved = fmax(moved, fabs(s[0]->w[q] - w0[q]));
            }
            const size_t T = phc_soil_block_steps(s[0]);
            printf("4c. random%s %zux%zux%zu%s%s%s, %d thread%s: %zu steps in one run (%zu per sweep) vs %zu runs of "
                   "one step: bit-identical %s (max |dw| %.1e); vs the plain one-voxel stencil: bit-identical %s "
                   "(max |dw| %.1e); sub-steps %zu vs %zu; largest change of w %.3g\n",
                   C[c].layered == 2 ? " layers only" : C[c].layered ? " layers" : "", nx, ny, nz, C[c].upwind ? ", upwind" : "", C[c].periodic ? ", x periodic" : "",
                   C[c].yperiodic ? (C[c].zperiodic ? ", y z periodic" : ", y periodic")
                                  : C[c].zperiodic ? ", z periodic" : "",
                   th,
                   th > 1 ? "s" : "", K, T, K, same_steps ? "yes" : "NO", d1, same_ref ? "yes" : "NO", d2,
                   s[0]->budget.substeps, s[1]->budget.substeps, moved);
            CHECK(same_steps);
            CHECK(same_ref);
            CHECK(s[0]->budget.substeps == K);
            CHECK(moved > 1e-3);
            /* the blocked path is the one tested (2 sub-steps per sweep when
               every plane is swept from w: layers, with or without rocks,
               x faces closed; soil.c block_levels) */
            CHECK(T == (C[c].layered && !C[c].periodic && ny >= 2 ? 2u : 4u));
            free(ref);
            free(w0);
            for (int r = 0; r < 2; ++r)
                phc_soil_free(s[r]);
        }
    omp_set_num_threads(saved);
}

/* ---- 5. stability ----------------------------------------------------------- */

/* 8x8x8 pure diffusion (f_grav = 0), two layers of permeability, rocks,
 * fill w/c from noise; capacity uniform when c2 == c1. */
static phc_soil *diffusion_soil(double c1, double c2)
{
    phc_soil *s = new_soil(8, 8, 8, 0.01);
    phc_error err;
    phc_soil_layer L[2] = {{.thickness = 0.04, .c = c1, .p = 0.05, .d = 1, .fill = 0.5},
                           {.thickness = 0, .c = c2, .p = 0.01, .d = 1, .fill = 0.5}};
    must(phc_soil_set_layers(s, L, 2, &err), &err, "layers");
    phc_soil_add_rocks(s, 5, 0.03, 0.1);
    for (size_t k = 0; k < 8; ++k)
        for (size_t j = 0; j < 8; ++j)
            for (size_t i = 0; i < 8; ++i) {
                size_t q = i + 8 * (j + 8 * k);
                s->w[q] = s->c[q] * phc_soil_noise(99, 0.02, (i + 0.5) * 0.01, (j + 0.5) * 0.01, (k + 0.5) * 0.01);
            }
    s->params.f_grav = 0;
    s->params.f_diff = 1;
    return s;
}

static void test_stability(void)
{
    phc_error err;
    phc_soil *s = diffusion_soil(4, 4);
    size_t at = 0;
    double limit = phc_soil_stable_dt(s, &at);
    double *w0 = copy_of(s->w, s->n);
    s->params.dt = 3 * limit;
    s->params.substep = 0;
    phc_error_clear(&err);
    int rc = phc_soil_run(s, 10 * s->params.dt, &err);
    printf("5. stability: limit %.4g h (voxel %zu), dt = 3 limit, substep 0 -> rc %d: \"%s\"\n", limit, at, rc,
           err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "stability limit");
    CHECK(s->t == 0 && !memcmp(s->w, w0, s->n * sizeof(double)));
    /* a step needing 4 sub-steps with max_substeps 3 is refused before it runs */
    s->params.substep = 1;
    s->params.max_substeps = 3;
    phc_error_clear(&err);
    rc = phc_soil_run(s, 10 * s->params.dt, &err);
    printf("   substep 1, max_substeps 3 -> rc %d: \"%s\"\n", rc, err.message);
    CHECK(rc == PHC_ERR_DOMAIN);
    CHECK_STR_CONTAINS(err.message, "max_substeps");
    CHECK(s->t == 0 && !memcmp(s->w, w0, s->n * sizeof(double)));
    s->params.max_substeps = 4;
    rc = phc_soil_run(s, 10 * s->params.dt, &err);
    double mx0 = maxv(w0, s->n), mn0 = minv(w0, s->n), mx = maxv(s->w, s->n), mn = minv(s->w, s->n);
    printf("   substep 1: rc %d, steps %zu, substeps %zu; w in [%.6f, %.6f] vs initial [%.6f, %.6f]\n", rc,
           s->budget.steps, s->budget.substeps, mn, mx, mn0, mx0);
    CHECK(rc == PHC_OK);
    CHECK(s->budget.steps == 10 && s->budget.substeps > s->budget.steps);
    CHECK(s->budget.substeps == 10 * (size_t)ceil(3.0 / 0.9));
    CHECK(mx <= mx0 && mn >= mn0);
    CHECK(mx < mx0); /* it did diffuse */
    free(w0);
    phc_soil_free(s);

    /* capacities differ: the maximum principle holds for the fill w/c */
    s = diffusion_soil(4, 12);
    size_t n = s->n;
    double *l = malloc(n * sizeof *l);
    for (size_t q = 0; q < n; ++q)
        l[q] = s->w[q] / s->c[q];
    double lmx0 = maxv(l, n), lmn0 = minv(l, n);
    s->params.dt = 3 * phc_soil_stable_dt(s, NULL);
    CHECK(phc_soil_run(s, 10 * s->params.dt, &err) == PHC_OK);
    for (size_t q = 0; q < n; ++q)
        l[q] = s->w[q] / s->c[q];
    printf("   c = 4 | 12: fill w/c in [%.6f, %.6f] vs initial [%.6f, %.6f], substeps %zu\n", minv(l, n),
           maxv(l, n), lmn0, lmx0, s->budget.substeps);
    CHECK(maxv(l, n) <= lmx0 && minv(l, n) >= lmn0);
    free(l);
    phc_soil_free(s);
}

/* ---- 6. absorbing boundaries and rain -------------------------------------- */

/* absorb_dt: with nothing moving (f_diff = f_grav = 0), a voxel i layers
 * from an absorbing face keeps w0 a(i)^(T / absorb_dt) after T hours, for
 * any dt (the growth model's long steps lengthen dt and keep absorb_dt). */
static void test_absorb_dt(void)
{
    const double dts[3] = {0.5, 1.0, 2.0 / 3.0};
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
        phc_soil *s = new_soil(1, 1, 12, 0.01);
        for (size_t k = 0; k < 12; ++k)
            s->w[k] = 1.0 + 0.1 * (double)k;
        s->params.f_diff = 0;
        s->params.f_grav = 0;
        s->params.boundary[PHC_SOIL_ZMIN] = PHC_SOIL_ABSORB;
        s->params.dt = dts[c];
        s->params.absorb_dt = 2.0;
        phc_error err;
        must(phc_soil_run(s, 4.0, &err), &err, "absorb_dt run");
        for (size_t k = 0; k < 12; ++k) {
            double a = k < 5 ? 1.0 - exp(-(double)(k * k) / (0.2 * 25)) : 1.0;
            double exact = (1.0 + 0.1 * (double)k) * pow(a, 4.0 / 2.0);
            worst = fmax(worst, exact > 0 ? fabs(s->w[k] / exact - 1) : fabs(s->w[k]));
        }
        phc_soil_free(s);
    }
    phc_soil *s = new_soil(1, 1, 12, 0.01);
    s->params.absorb_dt = -1;
    phc_error err;
    int rc = phc_soil_run(s, 1.0, &err);
    printf("6b. absorb_dt 2 h, dt 0.5, 1 and 2/3 h, 4 h without transport: w = w0 a(i)^2 to %.1e (rel); "
           "absorb_dt -1: rc %d \"%s\"\n", worst, rc, rc ? err.message : "");
    CHECK(worst < 1e-14);
    CHECK(rc == PHC_ERR_INPUT && strstr(err.message, "absorb_dt"));
    phc_soil_free(s);
}

static void test_absorb_rain(void)
{
    phc_error err;
    const size_t nz = 60;
    const double dx = 0.01;
    phc_soil *s = new_soil(1, 1, nz, dx);
    for (size_t k = 0; k < nz; ++k) {
        s->c[k] = 10;
        s->p[k] = 0.5;
    }
    s->params.boundary[PHC_SOIL_ZMIN] = PHC_SOIL_ABSORB;
    phc_soil_rain rain = {.start = 0, .end = 1, .rate = 0.01, .nutrient = 3};
    must(phc_soil_set_rain(s, &rain, 1, &err), &err, "rain");
    phc_soil_budget_reset(s);
    must(phc_soil_run(s, 1.0, &err), &err, "rain run");
    const double in = 0.01 * 1.0 * dx * dx;
    double absorbed1 = s->budget.water_absorbed;
    printf("6. rain 0.01 m/h for 1 h on 1x1x60: water_in %.15e m^3 (exact %.15e, rel %.1e), nutrient_in %.6e "
           "(exact %.6e), steps %zu substeps %zu, absorbed by 1 h %.3e\n",
           s->budget.water_in, in, fabs(s->budget.water_in / in - 1), s->budget.nutrient_in, 3 * in,
           s->budget.steps, s->budget.substeps, absorbed1);
    CHECK_NEAR(s->budget.water_in, in, 0, 1e-12);
    CHECK_NEAR(s->budget.nutrient_in, 3 * in, 0, 1e-12);
    must(phc_soil_run(s, 4.0, &err), &err, "drain run");
    const phc_soil_budget *b = &s->budget;
    printf("   at 4 h: absorbed %.6e m^3 (%.1f%% of the rain), stored %.6e, closing water %.2e, nutrients %.2e "
           "(rel to input)\n",
           b->water_absorbed, 100 * b->water_absorbed / in, b->water_stored, b->water_closing / in,
           b->nutrient_closing / (3 * in));
    CHECK_NEAR(b->water_in, in, 0, 1e-12); /* no rain after 1 h */
    CHECK(b->water_absorbed > 0.1 * in);
    CHECK(b->nutrient_absorbed > 0);
    CHECK(fabs(b->water_closing) < 1e-12 * in);
    CHECK(fabs(b->nutrient_closing) < 1e-12 * 3 * in);
    phc_soil_free(s);

    /* the damping factors: nothing moves (p = 0), w = v = 1, one step of dt */
    for (int form = 0; form < 2; ++form)
        for (int face = PHC_SOIL_ZMIN; face <= PHC_SOIL_ZMAX; ++face) {
            const size_t n = 12;
            s = new_soil(1, 1, n, dx);
            s->params.boundary[face] = PHC_SOIL_ABSORB;
            s->params.absorb_form = form ? PHC_SOIL_ABSORB_PAPER : PHC_SOIL_ABSORB_CODE;
            const int W = s->params.absorb_width;
            for (size_t k = 0; k < n; ++k)
                s->w[k] = s->v[k] = 1.0;
            phc_soil_budget_reset(s);
            must(phc_soil_run(s, s->params.dt, &err), &err, "damp run");
            double emax = 0, lost = 0;
            for (size_t k = 0; k < n; ++k) {
                size_t i = face == PHC_SOIL_ZMIN ? k : n - 1 - k; /* layers in from the face */
                double x = form ? (double)i : (double)(i * i);
                double a = i < (size_t)W ? 1.0 - exp(-x / (0.2 * W * W)) : 1.0;
                emax = fmax(emax, fabs(s->w[k] - a));
                emax = fmax(emax, fabs(s->v[k] - a));
                lost += 1.0 - a;
            }
            size_t k0 = face == PHC_SOIL_ZMIN ? 0 : n - 1, k1 = face == PHC_SOIL_ZMIN ? 1 : n - 2,
                   k2 = face == PHC_SOIL_ZMIN ? 2 : n - 3;
            printf("   %s %s W=%d: one step a(0) %.3g, a(1) %.15f (1-exp(-1/5) = %.15f), a(2) %.15f "
                   "(%s = %.15f), max err %.1e, absorbed %.6e (exact %.6e)\n",
                   form ? "PAPER" : "CODE ", face == PHC_SOIL_ZMIN ? "bottom" : "top   ", W, s->w[k0], s->w[k1],
                   1 - exp(-0.2), s->w[k2], form ? "1-exp(-2/5)" : "1-exp(-4/5)",
                   form ? 1 - exp(-0.4) : 1 - exp(-0.8), emax, s->budget.water_absorbed, lost * dx * dx * dx);
            CHECK(s->w[k0] == 0 && s->v[k0] == 0);
            CHECK(emax < 1e-15);
            CHECK_NEAR(s->budget.water_absorbed, lost * dx * dx * dx, 0, 1e-14);
            CHECK(s->budget.water_closing == s->budget.water_closing &&
                  fabs(s->budget.water_closing) < 1e-15 * n * dx * dx * dx);
            /* 2.5 steps (the last one half a step): damping a^(h/dt) per step */
            for (size_t k = 0; k < n; ++k)
                s->w[k] = 1.0;
            s->t = 0;
            must(phc_soil_run(s, 2.5 * s->params.dt, &err), &err, "damp run 2.5");
            emax = 0;
            for (size_t k = 0; k < n; ++k) {
                size_t i = face == PHC_SOIL_ZMIN ? k : n - 1 - k;
                double x = form ? (double)i : (double)(i * i);
                double a = i < (size_t)W ? 1.0 - exp(-x / (0.2 * W * W)) : 1.0;
                emax = fmax(emax, fabs(s->w[k] - pow(a, 2.5)));
            }
            printf("      2.5 dt: max |w - a^2.5| %.1e\n", emax);
            CHECK(emax < 1e-12);
            phc_soil_free(s);
        }
}

/* ---- 7. tangent vs central differences ------------------------------------- */

enum { T_NX = 6, T_NY = 5, T_NZ = 12, T_STEPS = 40 };
static const double T_DX = 0.01;
static int t_upwind = 0; /* 1: the tangent soils use the upwind gravity flux */

/* direction 0: p of layer 1 (soil voxels); 1: 1/c of layer 2; 2: f_diff; 3: f_grav. */
static phc_soil *tangent_soil(int dir, double eps, double *dt, size_t *layer_of_k)
{
    phc_soil *s = new_soil(T_NX, T_NY, T_NZ, T_DX);
    phc_error err;
    phc_soil_layer L[2] = {{.thickness = 0.05, .c = 3, .p = 0.04, .d = 1, .fill = 0.4, .nutrient = 1},
                           {.thickness = 0, .c = 8, .p = 0.015, .d = 1, .fill = 0.2, .nutrient = 0}};
    must(phc_soil_set_layers(s, L, 2, &err), &err, "layers");
    phc_soil_layer_of_planes(s, L, 2, layer_of_k);
    phc_soil_add_rocks(s, 3, 0.02, 0.1);
    phc_soil_source src = {.x = 0.032, .y = 0.027, .z = 0.064, .radius = 0.02, .water_rate = 2e-6,
                           .nutrient_rate = 1e-6, .start = 0, .end = 1};
    must(phc_soil_set_sources(s, &src, 1, &err), &err, "source");
    s->params.f_diff = 0.7;
    s->params.f_grav = 1.3;
    s->params.substep = 0;
    if (t_upwind)
        s->params.gravity = PHC_SOIL_GRAVITY_UPWIND;
    if (*dt <= 0)
        *dt = 0.5 * phc_soil_stable_dt(s, NULL);
    s->params.dt = *dt;
    size_t plane = T_NX * T_NY;
    for (size_t q = 0; q < s->n; ++q) {
        size_t L_ = layer_of_k[q / plane];
        if (dir == 0 && L_ == 0 && s->p[q] > 0)
            s->p[q] += eps;
        if (dir == 1 && L_ == 1)
            s->c[q] = 1.0 / (1.0 / s->c[q] + eps);
    }
    if (dir == 2)
        s->params.f_diff += eps;
    if (dir == 3)
        s->params.f_grav += eps;
    return s;
}

static void test_tangent(void)
{
    phc_error err;
    size_t lk[T_NZ];
    double dt = 0;
    phc_soil *s = tangent_soil(-1, 0, &dt, lk);
    const size_t n = s->n, plane = T_NX * T_NY;
    double *dp0 = calloc(n, sizeof(double)), *dic1 = calloc(n, sizeof(double));
    for (size_t q = 0; q < n; ++q) {
        dp0[q] = lk[q / plane] == 0 && s->p[q] > 0 ? 1.0 : 0.0;
        dic1[q] = lk[q / plane] == 1 ? 1.0 : 0.0;
    }
    const double *dp[4] = {dp0, NULL, NULL, NULL}, *dic[4] = {NULL, dic1, NULL, NULL};
    const double dfd[4] = {0, 0, 1, 0}, dfg[4] = {0, 0, 0, 1};
    double *sw[4], *sw_orig[4];
    for (int m = 0; m < 4; ++m)
        sw[m] = sw_orig[m] = calloc(n, sizeof(double));
    phc_soil_tangent tan = {.m = 4, .dp = dp, .dinv_c = dic, .dfd = dfd, .dfg = dfg, .sw = sw};
    must(phc_soil_run_tangent(s, T_STEPS * dt, &tan, &err), &err, "tangent run");
    size_t steps = s->budget.steps, subs = s->budget.substeps;
    /* the same w as phc_soil_run */
    double dt2 = dt;
    phc_soil *r = tangent_soil(-1, 0, &dt2, lk);
    must(phc_soil_run(r, T_STEPS * dt, &err), &err, "plain run");
    int same = !memcmp(r->w, s->w, n * sizeof(double)) && !memcmp(r->v, s->v, n * sizeof(double));
    printf("7. tangent (6x5x12, f_diff 0.7, f_grav 1.3, dt %.4g h = 0.5 limit, %zu steps, %zu substeps): "
           "w and v bit-identical to phc_soil_run: %s\n",
           dt, steps, subs, same ? "yes" : "NO");
    CHECK(same);
    CHECK(steps == T_STEPS && subs == T_STEPS);
    phc_soil_free(r);
    const char *names[4] = {"p of layer 1", "1/c of layer 2", "f_diff", "f_grav"};
    const double base[4] = {0.04, 1.0 / 8, 0.7, 1.3};
    for (int m = 0; m < 4; ++m) {
        double eps = 1e-6 * base[m], d1 = dt, d2 = dt;
        phc_soil *a = tangent_soil(m, eps, &d1, lk), *b = tangent_soil(m, -eps, &d2, lk);
        must(phc_soil_run(a, T_STEPS * dt, &err), &err, "fd+ run");
        must(phc_soil_run(b, T_STEPS * dt, &err), &err, "fd- run");
        CHECK(a->budget.substeps == T_STEPS && b->budget.substeps == T_STEPS);
        double emax = 0, smax = 0;
        for (size_t q = 0; q < n; ++q) {
            double fd = (a->w[q] - b->w[q]) / (2 * eps);
            emax = fmax(emax, fabs(tan.sw[m][q] - fd));
            smax = fmax(smax, fabs(tan.sw[m][q]));
        }
        printf("   d w / d %-15s: max |sw| %.6e, max |tangent - central FD| %.3e = %.2e of max |sw|\n", names[m],
               smax, emax, emax / smax);
        CHECK(smax > 0);
        CHECK(emax < 1e-6 * smax);
        phc_soil_free(a);
        phc_soil_free(b);
    }
    /* the caller's sensitivity buffers stay the caller's (odd and even step counts) */
    must(phc_soil_run_tangent(s, (T_STEPS + 1) * dt, &tan, &err), &err, "tangent run (odd)");
    int kept = 1;
    for (int m = 0; m < 4; ++m)
        kept &= tan.sw[m] == sw_orig[m];
    /* the same 41 steps in one call with the four sw arrays in one block */
    double d3 = dt;
    phc_soil *s2 = tangent_soil(-1, 0, &d3, lk);
    double *block = calloc(4 * n, sizeof(double)), *sw2[4];
    for (int m = 0; m < 4; ++m)
        sw2[m] = block + m * n;
    phc_soil_tangent tan2 = tan;
    tan2.sw = sw2;
    must(phc_soil_run_tangent(s2, (T_STEPS + 1) * dt, &tan2, &err), &err, "tangent run (block)");
    double e41 = 0, s41 = 0;
    for (int m = 0; m < 4; ++m) {
        kept &= tan2.sw[m] == block + m * n;
        for (size_t q = 0; q < n; ++q) {
            e41 = fmax(e41, fabs(block[m * n + q] - tan.sw[m][q]));
            s41 = fmax(s41, fabs(tan.sw[m][q]));
        }
    }
    printf("   after an odd number of steps (41) the sw arrays are still the caller's buffers: %s; "
           "41 steps in one call (sw in one block) vs 40 + 1: max diff %.2e of max |sw|\n",
           kept ? "yes" : "NO", e41 / s41);
    CHECK(kept);
    CHECK(e41 < 1e-12 * s41);
    free(block);
    phc_soil_free(s2);
    for (int m = 0; m < 4; ++m)
        free(tan.sw[m]);
    free(dp0);
    free(dic1);
    phc_soil_free(s);
}


/* ---- 7c. the upwind gravity flux ---------------------------------------------- */

/* A column of nz voxels, uniform c and p, blocked at both ends. */
static phc_soil *column(size_t nz, double dx, double c, double p, double w0, phc_soil_gravity g)
{
    phc_soil *s = new_soil(1, 1, nz, dx);
    for (size_t k = 0; k < nz; ++k)
        s->c[k] = c, s->p[k] = p, s->w[k] = w0;
    s->params.gravity = g;
    s->params.dt = 1.0;
    return s;
}

static void test_upwind(void)
{
    phc_error err;
    /* the bound h (b + g) = 1 of an interior voxel (two faces) */
    const double dx = 0.05, c = 2, p = 0.1, fd = 1, fg = 1;
    phc_soil *s = column(10, dx, c, p, 1.0, PHC_SOIL_GRAVITY_UPWIND);
    double lim = phc_soil_stable_dt(s, NULL), expect = 1.0 / (fd * 2 * p / (c * dx * dx) + fg * p / dx);
    printf("7c. upwind gravity: stability limit %.15g h (1 / (b + g) = %.15g)\n", lim, expect);
    CHECK_NEAR(lim, expect, 0, 1e-14);
    /* exact discrete steady state: no flux through any face when
       f_grav p w_up = f_diff p (l_low - l_up) / dx, i.e. the fill grows
       downward by the factor 1 + f_grav c dx / f_diff per voxel */
    double W0 = phc_soil_water_total(s);
    must(phc_soil_run(s, 200.0, &err), &err, "upwind column");
    double r = 1 + fg * c * dx / fd, emax = 0;
    for (size_t k = 0; k + 1 < 10; ++k)
        emax = fmax(emax, fabs(s->w[k] / s->w[k + 1] / r - 1));
    printf("    column at rest after 200 h (%zu sub-steps): w[k] / w[k+1] = %.12f (exact %.12f), max rel err %.2e; "
           "water rel change %.2e\n",
           s->budget.substeps, s->w[0] / s->w[1], r, emax, fabs(phc_soil_water_total(s) / W0 - 1));
    CHECK(emax < 1e-9);
    CHECK_NEAR(phc_soil_water_total(s), W0, 0, 1e-12);
    phc_soil_free(s);
    /* a sandy pot whose upper half the roots have dried (w = 0 over w = 6):
       Lax-Wendroff's nearly centred flux (q_up + q_low) / 2 at this small
       Courant number pulls water out of the dry voxels, which go negative;
       the upwind flux moves only what the voxel above holds */
    double wmin[2], wtot[2], wbot[2];
    for (int g = 0; g < 2; ++g) {
        phc_soil *t = column(10, dx, 75, 0.033, 6.0, g ? PHC_SOIL_GRAVITY_UPWIND : PHC_SOIL_GRAVITY_LAX_WENDROFF);
        for (size_t k = 5; k < 10; ++k)
            t->w[k] = 0;
        double Win = phc_soil_water_total(t);
        wmin[g] = INFINITY;
        for (int h = 1; h <= 480; ++h) { /* min every 0.05 h over the first 24 h */
            must(phc_soil_run(t, 0.05 * h, &err), &err, "pot");
            wmin[g] = fmin(wmin[g], minv(t->w, t->n));
        }
        wtot[g] = phc_soil_water_total(t) / Win - 1;
        wbot[g] = t->w[0] * dx * dx * dx / phc_soil_water_total(t);
        phc_soil_free(t);
    }
    printf("    sandy pot (c 75, p 0.033 m/h, w 0 over 6, 24 h, w seen every 0.05 h): lowest w Lax-Wendroff %.3g, upwind %.3g; "
           "water rel change %.1e and %.1e; bottom voxel holds %.3f and %.3f of it\n",
           wmin[0], wmin[1], wtot[0], wtot[1], wbot[0], wbot[1]);
    CHECK(wmin[0] < 0);
    CHECK(wmin[1] >= 0);
    CHECK(fabs(wtot[1]) < 1e-12);
    CHECK(wbot[1] > 0.7);
}

/* ---- 8. infiltration depth ----------------------------------------------------- */

static phc_soil *rain_column(double p, double *dt)
{
    phc_soil *s = new_soil(1, 1, 60, 0.01);
    phc_error err;
    for (size_t k = 0; k < 60; ++k) {
        s->c[k] = 10;
        s->p[k] = p;
    }
    phc_soil_rain rain = {.start = 0, .end = 1, .rate = 0.01};
    must(phc_soil_set_rain(s, &rain, 1, &err), &err, "rain");
    s->params.substep = 0;
    if (*dt <= 0)
        *dt = 0.5 * phc_soil_stable_dt(s, NULL);
    s->params.dt = *dt;
    return s;
}

static void test_infiltration(void)
{
    phc_error err;
    const double dx = 0.01, v3 = dx * dx * dx;
    phc_soil *s = new_soil(2, 1, 10, dx);
    for (size_t k = 6; k < 10; ++k)
        for (size_t i = 0; i < 2; ++i)
            s->w[i + 2 * k] = 0.5; /* excess 1 dx^3 per plane in the top 4 planes */
    double d = phc_soil_infiltration_depth(s, NULL, 0.5, 4 * v3, NULL, NULL);
    double d3 = phc_soil_infiltration_depth(s, NULL, 0.3, 4 * v3, NULL, NULL);
    double dn = phc_soil_infiltration_depth(s, NULL, 0.5, 10 * v3, NULL, NULL);
    double *ref = calloc(s->n, sizeof(double));
    for (size_t q = 0; q < s->n; ++q)
        ref[q] = 0.1;
    for (size_t q = 12; q < 20; ++q)
        s->w[q] += 0.1;
    double dr = phc_soil_infiltration_depth(s, ref, 0.5, 4 * v3, NULL, NULL);
    printf("8. infiltration depth, constructed profile: frac 0.5 -> %.15g dx (exact 2), frac 0.3 -> %.15g dx "
           "(exact 1.2), more than the box holds -> %g, with w_ref -> %.15g dx (exact 2)\n",
           d / dx, d3 / dx, dn, dr / dx);
    CHECK_NEAR(d, 2 * dx, 0, 1e-15);
    CHECK_NEAR(d3, 1.2 * dx, 0, 1e-13);
    CHECK(isnan(dn));
    CHECK_NEAR(dr, 2 * dx, 0, 1e-13);
    free(ref);
    phc_soil_free(s);

    /* d depth / d p from a real rain run: tangent vs central differences */
    const double p = 0.5, eps = 1e-6 * p, T = 1.5, in = 0.01 * dx * dx;
    double dt = 0;
    s = rain_column(p, &dt);
    double *dp = malloc(s->n * sizeof(double)), *sw = calloc(s->n, sizeof(double));
    for (size_t q = 0; q < s->n; ++q)
        dp[q] = 1.0;
    const double *dpp[1] = {dp};
    double *swp[1] = {sw};
    const double zero = 0;
    phc_soil_tangent tan = {.m = 1, .dp = dpp, .dinv_c = NULL, .dfd = &zero, .dfg = &zero, .sw = swp};
    must(phc_soil_run_tangent(s, T, &tan, &err), &err, "rain tangent");
    double dd = NAN, depth = phc_soil_infiltration_depth(s, NULL, 0.5, in, tan.sw[0], &dd);
    double d1 = dt, d2 = dt;
    phc_soil *a = rain_column(p + eps, &d1), *b = rain_column(p - eps, &d2);
    must(phc_soil_run(a, T, &err), &err, "rain +");
    must(phc_soil_run(b, T, &err), &err, "rain -");
    double fd = (phc_soil_infiltration_depth(a, NULL, 0.5, in, NULL, NULL) -
                 phc_soil_infiltration_depth(b, NULL, 0.5, in, NULL, NULL)) /
                (2 * eps);
    printf("   rain run (p %.2g, %zu steps to %.1f h): depth of half the rain %.6f m, d depth/dp tangent %.9f, "
           "central FD %.9f, rel diff %.2e\n",
           p, s->budget.steps, T, depth, dd, fd, fabs(dd / fd - 1));
    CHECK(depth > 0.05 && depth < 0.6);
    CHECK_NEAR(dd, fd, 0, 1e-6);
    free(tan.sw[0]); /* the buffer the run left in sw (the caller's) */
    free(dp);
    phc_soil_free(a);
    phc_soil_free(b);
    phc_soil_free(s);
}

/* ---- 9. sampling ------------------------------------------------------------- */

static void test_sample(void)
{
    const size_t nx = 7, ny = 5, nz = 9;
    const double dx = 0.02;
    phc_soil *s = new_soil(nx, ny, nz, dx);
    double *f = malloc(s->n * sizeof(double));
    const double A = 0.3, B = 2.0, C = -1.5, Dz = 4.0;
    for (size_t k = 0; k < nz; ++k)
        for (size_t j = 0; j < ny; ++j)
            for (size_t i = 0; i < nx; ++i)
                f[i + nx * (j + ny * k)] = A + B * (i + 0.5) * dx + C * (j + 0.5) * dx + Dz * (k + 0.5) * dx;
    double emax = 0, wmax = 0;
    size_t bad_idx = 0;
    uint64_t st = 12345;
    for (int t = 0; t < 1000; ++t) {
        double pos[3];
        size_t dims[3] = {nx, ny, nz};
        for (int a = 0; a < 3; ++a) {
            st = st * 6364136223846793005ull + 1442695040888963407ull;
            double u = (double)(st >> 11) * 0x1.0p-53;
            pos[a] = (0.5 + u * (double)(dims[a] - 1)) * dx; /* between the outer centres */
        }
        if (t == 0) /* a voxel centre and the last centre exactly */
            pos[0] = 0.5 * dx, pos[1] = (ny - 0.5) * dx, pos[2] = (nz - 0.5) * dx;
        double val, w8[8], sum = 0;
        size_t id[8];
        CHECK(phc_soil_sample(s, f, pos[0], pos[1], pos[2], &val, w8, id) == PHC_OK);
        double ex = A + B * pos[0] + C * pos[1] + Dz * pos[2];
        emax = fmax(emax, fabs(val - ex));
        for (int c = 0; c < 8; ++c) {
            sum += w8[c];
            bad_idx += id[c] >= s->n || w8[c] < 0;
        }
        wmax = fmax(wmax, fabs(sum - 1));
    }
    /* in the band between the outer centre and the face: clamped (constant) */
    double vin, vface;
    CHECK(phc_soil_sample(s, f, 0.25 * dx, 2 * dx, 3 * dx, &vface, NULL, NULL) == PHC_OK);
    CHECK(phc_soil_sample(s, f, 0.5 * dx, 2 * dx, 3 * dx, &vin, NULL, NULL) == PHC_OK);
    double v;
    int r1 = phc_soil_sample(s, f, -1e-9, 0.05, 0.05, &v, NULL, NULL);
    int r2 = phc_soil_sample(s, f, 0.05, ny * dx + 1e-9, 0.05, &v, NULL, NULL);
    int r3 = phc_soil_sample(s, f, 0.05, 0.05, NAN, &v, NULL, NULL);
    int r4 = phc_soil_sample(s, f, nx * dx, 0, nz * dx, &v, NULL, NULL);
    printf("9. sample linear field (1000 points): max err %.2e, max |sum w - 1| %.2e, bad weights/indices %zu; "
           "edge band clamped %s; outside -> %d %d %d (DOMAIN %d), box corner -> %d\n",
           emax, wmax, bad_idx, vin == vface ? "yes" : "NO", r1, r2, r3, PHC_ERR_DOMAIN, r4);
    CHECK(emax < 1e-14);
    CHECK(wmax < 1e-15);
    CHECK(bad_idx == 0);
    CHECK(vin == vface);
    CHECK(r1 == PHC_ERR_DOMAIN && r2 == PHC_ERR_DOMAIN && r3 == PHC_ERR_DOMAIN);
    CHECK(r4 == PHC_OK);
    free(f);
    phc_soil_free(s);
}

/* ---- 10. presets, input checks, noise, rocks ---------------------------------- */

static void test_inputs(void)
{
    phc_error err;
    double c = 0, p = 0;
    int rc = phc_soil_preset("Silt Loam", &c, &p);
    printf("10. preset \"Silt Loam\" -> rc %d (c %g, p %g)", rc, c, p);
    CHECK(rc == PHC_OK && c == 100 && p == 0.5);
    rc = phc_soil_preset("sandy-clay LOAM", &c, &p);
    printf("; \"sandy-clay LOAM\" -> (%g, %g)", c, p);
    CHECK(rc == PHC_OK && c == 75 && p == 0.033);
    rc = phc_soil_preset("peat", &c, &p);
    printf("; \"peat\" -> rc %d\n", rc);
    CHECK(rc == PHC_ERR_INPUT);
    size_t np = 0;
    while (phc_soil_preset_name(np))
        ++np;
    CHECK(np == 6);

    phc_soil *s = new_soil(4, 3, 5, 0.01);
    phc_soil_layer L[2] = {{.thickness = 0.02, .c = 5, .p = 0.1, .d = 1, .fill = 0.5},
                           {.thickness = 0, .c = 5, .p = 0.1, .d = 1, .fill = 0.5}};
    const char *what[4] = {"c = 0", "c < 0", "p < 0", "NaN"};
    for (int t = 0; t < 4; ++t) {
        phc_soil_layer B[2] = {L[0], L[1]};
        if (t == 0) B[1].c = 0;
        if (t == 1) B[1].c = -2;
        if (t == 2) B[1].p = -0.1;
        if (t == 3) B[1].p = NAN;
        phc_error_clear(&err);
        rc = phc_soil_set_layers(s, B, 2, &err);
        printf("    set_layers with layer 2 %-5s -> rc %d \"%s\"\n", what[t], rc, err.message);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "layer 2");
    }
    CHECK(phc_soil_set_layers(s, L, 2, &err) == PHC_OK);
    CHECK(phc_soil_check(s, &err) == PHC_OK);
    s->c[2 + 4 * (1 + 3 * 4)] = -1.0; /* voxel (2, 1, 4) */
    phc_error_clear(&err);
    rc = phc_soil_check(s, &err);
    printf("    check with c < 0 at (2, 1, 4) -> rc %d \"%s\"\n", rc, err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "(2, 1, 4)");
    CHECK_STR_CONTAINS(err.message, "capacity");
    phc_soil_free(s);

    double n1 = phc_soil_noise(17, 0.05, 0.123, 0.456, 0.789), n2 = phc_soil_noise(17, 0.05, 0.123, 0.456, 0.789);
    double n3 = phc_soil_noise(18, 0.05, 0.123, 0.456, 0.789);
    double nmin = 1, nmax = 0;
    for (int i = 0; i < 1000; ++i) {
        double x = phc_soil_noise(17, 0.05, 0.001 * i, 0.0007 * i, 0.0003 * i);
        nmin = fmin(nmin, x);
        nmax = fmax(nmax, x);
    }
    printf("    noise seed 17: %.17g, again %.17g; seed 18: %.17g; range over 1000 points [%.4f, %.4f]\n", n1, n2,
           n3, nmin, nmax);
    CHECK(n1 == n2 && n1 != n3);
    CHECK(nmin >= 0 && nmax < 1);

    s = new_soil(12, 10, 14, 0.01);
    for (size_t q = 0; q < s->n; ++q)
        s->p[q] = 0.1;
    size_t r = phc_soil_add_rocks(s, 42, 0.03, 0.2), count = 0;
    for (size_t q = 0; q < s->n; ++q)
        count += s->p[q] == 0;
    printf("    add_rocks fraction 0.2 on %zu voxels: returned %zu, p == 0 in %zu, round(0.2 n) = %.0f\n", s->n,
           r, count, round(0.2 * s->n));
    CHECK(r == count && (double)count == round(0.2 * s->n));
    phc_soil_free(s);
}

int main(void)
{
    printf("OpenMP max threads %d\n", omp_get_max_threads());
    test_diffusion_erfc();
    test_gravity_pulse();
    test_conservation();
    test_threads();
    test_blocking();
    test_blocked_vs_steps();
    test_stability();
    test_absorb_rain();
    test_absorb_dt();
    test_tangent();
    t_upwind = 1;
    printf("7b. the tangent again with the upwind gravity flux:\n");
    test_tangent();
    t_upwind = 0;
    test_upwind();
    test_infiltration();
    test_sample();
    test_inputs();
    return check_finish("test_soil");
}
