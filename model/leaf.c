/* Leaf sap ("fluid") flow: Silva et al. §3, eqs. 1-7 (DESIGN §5); see
 * leaf.h for the model and the contract.
 *
 * Solver.  Each line of a half-step is the symmetric tridiagonal system
 * (Silva et al. §3, eqs. 4-6; a_i = h k_{i+1/2}, dimensionless)
 *   -a_{i-1} y'_{i-1} + d_i y'_i - a_i y'_{i+1} = y_i,  d_i = 1 + a_{i-1} + a_i,
 * with a = 0 across the mask or image border, so a line falls apart into
 * independent runs of consecutive leaf pixels.  Crout (A = L U, U unit upper
 * bidiagonal) gives
 *   λ_0 = d_0,  λ_i = d_i - a_{i-1} b_{i-1},  r_i = 1/λ_i,  b_i = a_i r_i,
 * and, with w_i = λ_i z_i (L z = y scaled by the pivots),
 *   forward  w_i = y_i + b_{i-1} w_{i-1}
 *   back     y'_i = r_i w_i + b_i y'_{i+1}.
 * Only r and b are stored (0 off the leaf): a solve is one multiply-add per
 * pixel each way.  λ_i >= 1 + a_i (diagonal dominance), so r is in (0, 1]
 * and b in [0, 1): no pivoting is needed and nothing overflows.
 * Where a run starts, b_{i-1} = 0 and the forward step adds exactly
 * 0 * 0; where it ends, b_i = 0: the arithmetic of every run is exactly
 * that of solving the run alone, whatever the line around it.
 *
 * Layout of the work:
 *   columns  vectorised across x: the sweeps go over the rows of a chunk of
 *            columns (contiguous in memory), forward top to bottom (fused
 *            with the sources, eqs. 2-3) then back bottom to top.  One
 *            chunk per thread; long contiguous rows keep the prefetchers
 *            streaming (measured faster, at 1024^2, than strips narrow
 *            enough to stay in L2 between the two sweeps).
 *   rows     blocks of ROW_BLOCK rows: the recurrences run over x with
 *            ROW_BLOCK independent lanes (vectorised across the lanes);
 *            w goes to an x-major buffer (ROW_BLOCK lanes per x), the back
 *            sweep runs there and the result is copied back onto the runs.
 *            The row factors are stored in that blocked layout.  Blocks
 *            run in parallel.
 * Every pixel's arithmetic is independent of the chunk / block partition
 * among threads, so the results are bit-identical for any thread count.
 * Pixels off the leaf are never written (they hold 0).  The sweeps may load
 * one (the neighbour across a run's end, or a hole inside a row block's x
 * range), but always with a factor 0, so it never contributes: each run is
 * solved exactly as if alone.
 *
 * Factorisations are cached for h == params.dt (slot 0) and for up to
 * OTHER_SLOTS other h (the remainder steps of phc_leaf_advance: a fit to
 * photos at many stage times has one per interval, the same at every
 * evaluation), as many as fit in OTHER_BYTES (one for a 1024² leaf, 16 for
 * a 96² one), replaced round-robin; they are kept when only s_O, s_I or dt
 * change (those do not enter the matrix).
 *
 * No I/O, no globals. */
#include "model/leaf.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

/* Rows solved together in the row half-step: independent lanes of the
 * recurrence (vectorised across the lanes).  Measured at 1024^2 on one core
 * (Xeon, SSE2 code): 4 rows 1.15 ms, 8 rows 1.34 ms per row half-step; the
 * sweep is memory-bound, so more lanes only cost cache. */
#define ROW_BLOCK 4
/* Leaves with fewer pixels than this run on one thread. */
#ifndef PHC_LEAF_PARALLEL_MIN
#define PHC_LEAF_PARALLEL_MIN 16384
#endif

/* Cache of factorisations for steps h != dt: at most this many, and at
 * most this many bytes (about 32 bytes per pixel each). */
#define OTHER_SLOTS 16
#define OTHER_BYTES ((size_t)64 << 20)

typedef struct leaf_factors {
    double h;        /* step length [time unit]; 0 = not computed */
    double *rc, *bc; /* columns: r, b at element x + W y */
    double *rr, *br; /* rows: r, b at element (q W + x) ROW_BLOCK + j, row q ROW_BLOCK + j */
} leaf_factors;

struct phc_leaf {
    size_t w, h, n, cells;
    unsigned char *mask; /* 0 / 1 */
    double *beta, *stomata, *inflow; /* 0 off the leaf */
    double beta_max;
    double *y;
    double t;
    phc_leaf_params p;
    /* runs of consecutive leaf pixels along each row: row y has runs
       run_first[y] .. run_first[y + 1] - 1, pixels [run_lo, run_hi) */
    size_t *run_first, *run_lo, *run_hi;
    size_t nblocks;          /* row blocks of ROW_BLOCK rows */
    size_t *blk_lo, *blk_hi; /* x range of each block's runs ([0, 0) if none) */
    leaf_factors fac[1 + OTHER_SLOTS]; /* [0]: h == params.dt; [1..n_other]: other h */
    size_t n_other, next_other;        /* slots in use for other h; the next to replace */
    double *buf;             /* a zero row (W), then per-thread row buffers (W ROW_BLOCK) */
    size_t buf_slots;
};

/* ---- parameters -------------------------------------------------------- */

phc_leaf_params phc_leaf_params_default(void)
{
    phc_leaf_params p;
    p.beta_scale = 50.0;
    p.stomata_scale = 0.1;
    p.inflow_scale = 0.05;
    p.dt = 0.1;
    return p;
}

static int check_params(phc_leaf_params p, phc_error *err)
{
    if (!(isfinite(p.beta_scale) && p.beta_scale >= 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "leaf params: beta_scale = %g: expected a finite value >= 0", p.beta_scale);
    if (!(isfinite(p.stomata_scale) && p.stomata_scale >= 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "leaf params: stomata_scale = %g: expected a finite value >= 0",
                             p.stomata_scale);
    if (!(isfinite(p.inflow_scale) && p.inflow_scale >= 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "leaf params: inflow_scale = %g: expected a finite value >= 0",
                             p.inflow_scale);
    if (!(isfinite(p.dt) && p.dt > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "leaf params: dt = %g: expected a finite value > 0",
                             p.dt);
    return PHC_OK;
}

/* ---- construction ------------------------------------------------------ */

static void factors_free(leaf_factors *f)
{
    free(f->rc);
    free(f->bc);
    free(f->rr);
    free(f->br);
    memset(f, 0, sizeof *f);
}

void phc_leaf_free(phc_leaf *leaf)
{
    if (!leaf)
        return;
    free(leaf->mask);
    free(leaf->beta);
    free(leaf->stomata);
    free(leaf->inflow);
    free(leaf->y);
    free(leaf->run_first);
    free(leaf->run_lo);
    free(leaf->run_hi);
    free(leaf->blk_lo);
    free(leaf->blk_hi);
    for (size_t k = 0; k < 1 + OTHER_SLOTS; ++k)
        factors_free(&leaf->fac[k]);
    free(leaf->buf);
    free(leaf);
}

/* Copies a map onto the leaf (0 off it); NULL means `fill`.  Values off the
 * leaf are ignored. */
static int copy_map(phc_leaf *L, const double *src, double fill, const char *name, double *dst,
                    phc_error *err)
{
    for (size_t y = 0; y < L->h; ++y)
        for (size_t x = 0; x < L->w; ++x) {
            size_t i = x + L->w * y;
            if (!L->mask[i]) {
                dst[i] = 0;
                continue;
            }
            double v = src ? src[i] : fill;
            if (!(isfinite(v) && v >= 0))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "leaf: %s at pixel (%zu, %zu) is %g: expected a finite value >= 0",
                                     name, x, y, v);
            dst[i] = v;
        }
    return PHC_OK;
}

/* Row runs and row blocks from the mask. */
static int build_runs(phc_leaf *L)
{
    size_t W = L->w, H = L->h, nruns = 0;
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x)
            if (L->mask[x + W * y] && (x == 0 || !L->mask[x - 1 + W * y]))
                ++nruns;
    L->run_first = malloc((H + 1) * sizeof *L->run_first);
    L->run_lo = malloc((nruns ? nruns : 1) * sizeof *L->run_lo);
    L->run_hi = malloc((nruns ? nruns : 1) * sizeof *L->run_hi);
    L->nblocks = (H + ROW_BLOCK - 1) / ROW_BLOCK;
    L->blk_lo = malloc(L->nblocks * sizeof *L->blk_lo);
    L->blk_hi = malloc(L->nblocks * sizeof *L->blk_hi);
    if (!L->run_first || !L->run_lo || !L->run_hi || !L->blk_lo || !L->blk_hi)
        return PHC_ERR_NOMEM;
    size_t k = 0;
    for (size_t y = 0; y < H; ++y) {
        L->run_first[y] = k;
        const unsigned char *m = L->mask + W * y;
        for (size_t x = 0; x < W;) {
            if (!m[x]) {
                ++x;
                continue;
            }
            size_t e = x;
            while (e < W && m[e])
                ++e;
            L->run_lo[k] = x;
            L->run_hi[k] = e;
            ++k;
            x = e;
        }
    }
    L->run_first[H] = k;
    for (size_t q = 0; q < L->nblocks; ++q) {
        size_t lo = W, hi = 0;
        for (size_t y = q * ROW_BLOCK; y < H && y < (q + 1) * ROW_BLOCK; ++y)
            for (size_t r = L->run_first[y]; r < L->run_first[y + 1]; ++r) {
                if (L->run_lo[r] < lo)
                    lo = L->run_lo[r];
                if (L->run_hi[r] > hi)
                    hi = L->run_hi[r];
            }
        L->blk_lo[q] = lo < hi ? lo : 0;
        L->blk_hi[q] = lo < hi ? hi : 0;
    }
    return PHC_OK;
}

int phc_leaf_new(size_t width, size_t height, const unsigned char *mask, const double *beta,
                 const double *stomata, const double *inflow, phc_leaf_params params,
                 phc_leaf **out, phc_error *err)
{
    int rc = PHC_OK;
    phc_leaf *L = NULL;
    if (out)
        *out = NULL;
    if (!mask || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_leaf_new: mask and out are required");
    if (width == 0 || height == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_leaf_new: empty grid %zu x %zu", width, height);
    if (width > SIZE_MAX / sizeof(double) / height ||
        height > SIZE_MAX / sizeof(double) / (width + ROW_BLOCK))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_leaf_new: grid %zu x %zu is too large", width,
                             height);
    if ((rc = check_params(params, err)))
        return rc;
    size_t n = width * height, cells = 0;
    for (size_t i = 0; i < n; ++i)
        cells += mask[i] != 0;
    if (cells == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "leaf: the mask (%zu x %zu) has no leaf pixel", width,
                             height);

    L = calloc(1, sizeof *L);
    if (!L)
        goto nomem;
    L->w = width;
    L->h = height;
    L->n = n;
    L->cells = cells;
    L->p = params;
    L->mask = malloc(n);
    L->beta = malloc(n * sizeof(double));
    L->stomata = malloc(n * sizeof(double));
    L->inflow = malloc(n * sizeof(double));
    L->y = malloc(n * sizeof(double));
    if (!L->mask || !L->beta || !L->stomata || !L->inflow || !L->y)
        goto nomem;
    for (size_t i = 0; i < n; ++i)
        L->mask[i] = mask[i] != 0;
    if ((rc = copy_map(L, beta, 1.0, "beta", L->beta, err)) ||
        (rc = copy_map(L, stomata, 1.0, "stomata", L->stomata, err)) ||
        (rc = copy_map(L, inflow, 0.0, "inflow", L->inflow, err)))
        goto fail;
    L->beta_max = 0;
    for (size_t i = 0; i < n; ++i)
        if (L->beta[i] > L->beta_max)
            L->beta_max = L->beta[i];
    if (build_runs(L))
        goto nomem;
    /* factorisation slots for other h: as many as fit in OTHER_BYTES, >= 1 */
    const size_t slot_bytes = (2 * n + 2 * L->nblocks * L->w * ROW_BLOCK) * sizeof(double);
    L->n_other = OTHER_BYTES / slot_bytes;
    L->n_other = L->n_other < 1 ? 1 : L->n_other > OTHER_SLOTS ? OTHER_SLOTS : L->n_other;
    phc_leaf_reset(L, 1.0);
    *out = L;
    return PHC_OK;

nomem:
    rc = phc_error_set(err, PHC_ERR_NOMEM, "phc_leaf_new: out of memory (%zu x %zu leaf)", width, height);
fail:
    phc_leaf_free(L);
    return rc;
}

/* ---- accessors --------------------------------------------------------- */

size_t phc_leaf_width(const phc_leaf *leaf) { return leaf->w; }
size_t phc_leaf_height(const phc_leaf *leaf) { return leaf->h; }
size_t phc_leaf_cells(const phc_leaf *leaf) { return leaf->cells; }
const unsigned char *phc_leaf_mask(const phc_leaf *leaf) { return leaf->mask; }
const double *phc_leaf_fluid(const phc_leaf *leaf) { return leaf->y; }
double phc_leaf_time(const phc_leaf *leaf) { return leaf->t; }
phc_leaf_params phc_leaf_get_params(const phc_leaf *leaf) { return leaf->p; }

int phc_leaf_set_params(phc_leaf *leaf, phc_leaf_params params, phc_error *err)
{
    if (!leaf)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_leaf_set_params: leaf is NULL");
    int rc = check_params(params, err);
    if (rc)
        return rc;
    /* the factorisations depend on h and s_beta only (eq. 6's conductances):
       a change of s_O, s_I or dt keeps them (slot 0 is keyed by its h) */
    if (params.beta_scale != leaf->p.beta_scale) {
        for (size_t k = 0; k < 1 + OTHER_SLOTS; ++k)
            leaf->fac[k].h = 0; /* refactorised on the next use */
    }
    leaf->p = params;
    return PHC_OK;
}

/* A negative or non-finite y0 leaves the fluid unchanged (the contract
 * asks for y0 >= 0); the clock is reset either way. */
void phc_leaf_reset(phc_leaf *leaf, double y0)
{
    leaf->t = 0;
    if (!(isfinite(y0) && y0 >= 0))
        return;
    for (size_t i = 0; i < leaf->n; ++i)
        leaf->y[i] = leaf->mask[i] ? y0 : 0.0;
}

int phc_leaf_set_fluid(phc_leaf *leaf, const double *y, phc_error *err)
{
    if (!leaf || !y)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_leaf_set_fluid: leaf and y are required");
    for (size_t i = 0; i < leaf->n; ++i)
        if (leaf->mask[i] && !(isfinite(y[i]) && y[i] >= 0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "leaf: fluid at pixel (%zu, %zu) is %g: expected a finite value >= 0",
                                 i % leaf->w, i / leaf->w, y[i]);
    for (size_t i = 0; i < leaf->n; ++i)
        leaf->y[i] = leaf->mask[i] ? y[i] : 0.0;
    return PHC_OK;
}

/* Sum of y over the leaf, compensated (Neumaier) in pixel order. */
double phc_leaf_total(const phc_leaf *leaf)
{
    double s = 0, c = 0;
    for (size_t i = 0; i < leaf->n; ++i) {
        double v = leaf->y[i], t = s + v;
        c += fabs(s) >= fabs(v) ? (s - t) + v : (v - t) + s;
        s = t;
    }
    return s + c;
}

/* ---- face conductances and factorisations ------------------------------ */

/* k_f = s_β (β_a + β_b) / 2 [px^2 / time unit]: Silva et al. §3, eq. 5. */
static inline double face_k(double s_beta, double ba, double bb)
{
    return s_beta * (0.5 * (ba + bb));
}

double phc_leaf_face_conductance(const phc_leaf *leaf, size_t x, size_t y, phc_leaf_axis axis)
{
    size_t W = leaf->w, H = leaf->h;
    if (x >= W || y >= H)
        return 0;
    size_t i = x + W * y, j;
    if (axis == PHC_LEAF_ROWS) {
        if (x + 1 >= W)
            return 0;
        j = i + 1;
    } else {
        if (y + 1 >= H)
            return 0;
        j = i + W;
    }
    if (!leaf->mask[i] || !leaf->mask[j])
        return 0; /* zero-flux border, eq. 7 */
    return face_k(leaf->p.beta_scale, leaf->beta[i], leaf->beta[j]);
}

/* Column factors for the columns [x0, x1): the recurrence runs down the
 * rows, vectorised across x.  a = h k (dimensionless). */
static void factor_columns(const phc_leaf *L, double h, double *rc, double *bc, size_t x0, size_t x1)
{
    size_t W = L->w, H = L->h;
    const unsigned char *m = L->mask;
    const double *beta = L->beta;
    double s = L->p.beta_scale;
    for (size_t y = 0; y < H; ++y) {
        size_t o = W * y;
        for (size_t x = x0; x < x1; ++x) {
            size_t i = o + x;
            if (!m[i]) {
                rc[i] = 0;
                bc[i] = 0;
                continue;
            }
            int up = y > 0 && m[i - W], down = y + 1 < H && m[i + W];
            double ap = up ? h * face_k(s, beta[i - W], beta[i]) : 0.0;
            double an = down ? h * face_k(s, beta[i], beta[i + W]) : 0.0;
            double lam = 1.0 + ap + an;
            if (up)
                lam -= ap * bc[i - W];
            double r = 1.0 / lam;
            rc[i] = r;
            bc[i] = an * r;
        }
    }
}

/* Row factors of row block q, in the blocked layout; rows past the image
 * get r = b = 0 (their lanes compute zeros). */
static void factor_rows(const phc_leaf *L, double h, double *rr, double *br, size_t q)
{
    size_t W = L->w, H = L->h;
    const unsigned char *m = L->mask;
    const double *beta = L->beta;
    double s = L->p.beta_scale;
    double *r0 = rr + q * W * ROW_BLOCK, *b0 = br + q * W * ROW_BLOCK;
    for (size_t j = 0; j < ROW_BLOCK; ++j) {
        size_t y = q * ROW_BLOCK + j;
        for (size_t x = 0; x < W; ++x) {
            size_t o = x * ROW_BLOCK + j, i = x + W * y;
            if (y >= H || !m[i]) {
                r0[o] = 0;
                b0[o] = 0;
                continue;
            }
            int left = x > 0 && m[i - 1], right = x + 1 < W && m[i + 1];
            double ap = left ? h * face_k(s, beta[i - 1], beta[i]) : 0.0;
            double an = right ? h * face_k(s, beta[i], beta[i + 1]) : 0.0;
            double lam = 1.0 + ap + an;
            if (left)
                lam -= ap * b0[o - ROW_BLOCK];
            double r = 1.0 / lam;
            r0[o] = r;
            b0[o] = an * r;
        }
    }
}

static int parallel(const phc_leaf *L) { return L->cells >= PHC_LEAF_PARALLEL_MIN; }

/* Columns [x0, x1) of thread tid of nt: contiguous chunks of a multiple of
 * 8 columns (whole cache lines when W is a multiple of 8). */
static void chunk(size_t W, size_t nt, size_t tid, size_t *x0, size_t *x1)
{
    size_t per = (W + nt - 1) / nt;
    per = (per + 7) / 8 * 8;
    size_t a = tid * per, b = a + per;
    *x0 = a < W ? a : W;
    *x1 = b < W ? b : W;
}

/* Checks h and returns the factorisation for it, computing it if needed;
 * NULL with *rc set on failure. */
static const leaf_factors *factors_for(phc_leaf *L, double h, int *rc)
{
    if (!(isfinite(h) && h > 0)) {
        *rc = PHC_ERR_INVALID;
        return NULL;
    }
    /* d = 1 + a_{i-1} + a_i must be finite */
    if (!isfinite(1.0 + 2.0 * h * L->p.beta_scale * L->beta_max)) {
        *rc = PHC_ERR_DOMAIN;
        return NULL;
    }
    leaf_factors *f = &L->fac[0];
    if (h != L->p.dt) {
        /* another h: a slot that holds it, else the next one round-robin */
        for (size_t k = 1; k <= L->n_other; ++k)
            if (L->fac[k].h == h && L->fac[k].rc)
                return &L->fac[k];
        f = &L->fac[1 + L->next_other];
        L->next_other = (L->next_other + 1) % L->n_other;
    }
    if (f->h == h && f->rc)
        return f;
    if (!f->rc) {
        size_t nb = L->nblocks * L->w * ROW_BLOCK;
        f->rc = malloc(L->n * sizeof(double));
        f->bc = malloc(L->n * sizeof(double));
        f->rr = malloc(nb * sizeof(double));
        f->br = malloc(nb * sizeof(double));
        if (!f->rc || !f->bc || !f->rr || !f->br) {
            factors_free(f);
            *rc = PHC_ERR_NOMEM;
            return NULL;
        }
    }
#pragma omp parallel if (parallel(L))
    {
        size_t nt = 1, tid = 0;
#ifdef _OPENMP
        nt = (size_t)omp_get_num_threads();
        tid = (size_t)omp_get_thread_num();
#endif
        size_t x0, x1;
        chunk(L->w, nt, tid, &x0, &x1);
        if (x0 < x1)
            factor_columns(L, h, f->rc, f->bc, x0, x1);
#pragma omp for schedule(static)
        for (size_t q = 0; q < L->nblocks; ++q)
            factor_rows(L, h, f->rr, f->br, q);
    }
    f->h = h;
    return f;
}

/* Row buffers for the threads a parallel region may use. */
static int ensure_buffers(phc_leaf *L)
{
    size_t nt = 1;
#ifdef _OPENMP
    if (parallel(L))
        nt = (size_t)omp_get_max_threads();
#endif
    if (nt <= L->buf_slots)
        return PHC_OK;
    /* a zero row, then one W x ROW_BLOCK buffer per thread */
    double *b = calloc((1 + nt * ROW_BLOCK) * L->w, sizeof(double));
    if (!b)
        return PHC_ERR_NOMEM;
    free(L->buf);
    L->buf = b;
    L->buf_slots = nt;
    return PHC_OK;
}

/* ---- the step ---------------------------------------------------------- */

/* Transpiration then inflow for one pixel (Silva et al. §3, eqs. 2-3):
 * max(y - h s_O O, 0) + h s_I I, with cO = h s_O, cI = h s_I [fluid]. */
static inline double source(double y, double o, double in, double cO, double cI)
{
    double v = y - cO * o;
    v = v > 0 ? v : 0.0;
    return v + cI * in;
}

void phc_leaf_sources(phc_leaf *leaf, double h)
{
    if (!(isfinite(h) && h > 0))
        return;
    phc_leaf *L = leaf;
    double cO = h * L->p.stomata_scale, cI = h * L->p.inflow_scale;
    size_t H = L->h, W = L->w;
#pragma omp parallel for schedule(static) if (parallel(L))
    for (size_t y = 0; y < H; ++y) {
        double *yr = L->y + W * y;
        const double *O = L->stomata + W * y, *I = L->inflow + W * y;
        for (size_t r = L->run_first[y]; r < L->run_first[y + 1]; ++r)
            for (size_t x = L->run_lo[r]; x < L->run_hi[r]; ++x)
                yr[x] = source(yr[x], O[x], I[x], cO, cI);
    }
}

/* Column half-step (Silva et al. §3, eq. 6, each column solved over y) on
 * the columns [x0, x1), with the sources fused into the forward sweep
 * (cO = cI = 0: none; then source() returns y unchanged, y >= 0). */
static void sweep_columns(phc_leaf *L, const leaf_factors *f, double cO, double cI, size_t x0,
                          size_t x1)
{
    size_t W = L->w, H = L->h;
    /* forward: w_y = src(y_y) + b_{y-1} w_{y-1} */
    for (size_t y = 0; y < H; ++y) {
        double *restrict yr = L->y + W * y;
        const double *restrict O = L->stomata + W * y;
        const double *restrict I = L->inflow + W * y;
        for (size_t r = L->run_first[y]; r < L->run_first[y + 1]; ++r) {
            size_t lo = L->run_lo[r] > x0 ? L->run_lo[r] : x0;
            size_t hi = L->run_hi[r] < x1 ? L->run_hi[r] : x1;
            if (y == 0) {
                for (size_t x = lo; x < hi; ++x)
                    yr[x] = source(yr[x], O[x], I[x], cO, cI);
            } else {
                const double *restrict wp = L->y + W * (y - 1);
                const double *restrict bp = f->bc + W * (y - 1);
                for (size_t x = lo; x < hi; ++x)
                    yr[x] = source(yr[x], O[x], I[x], cO, cI) + bp[x] * wp[x];
            }
        }
    }
    /* back: y'_y = r_y w_y + b_y y'_{y+1} */
    for (size_t y = H; y-- > 0;) {
        double *restrict yr = L->y + W * y;
        const double *restrict rr = f->rc + W * y;
        const double *restrict bb = f->bc + W * y;
        for (size_t r = L->run_first[y]; r < L->run_first[y + 1]; ++r) {
            size_t lo = L->run_lo[r] > x0 ? L->run_lo[r] : x0;
            size_t hi = L->run_hi[r] < x1 ? L->run_hi[r] : x1;
            if (y + 1 == H) {
                for (size_t x = lo; x < hi; ++x)
                    yr[x] = rr[x] * yr[x];
            } else {
                const double *restrict yn = L->y + W * (y + 1);
                for (size_t x = lo; x < hi; ++x)
                    yr[x] = rr[x] * yr[x] + bb[x] * yn[x];
            }
        }
    }
}

/* Row half-step (Silva et al. §3, eq. 6, each row solved over x) of row
 * block q.  The forward sweep reads the block's rows over the block's x
 * range (pixels off the leaf hold 0 and have b = 0, so they add exactly 0)
 * and writes w to the x-major buffer B (W ROW_BLOCK doubles); the back
 * sweep runs in B; the result is copied back onto the runs only.  Rows past
 * the image read the zero row Z (W doubles) and have r = b = 0. */
static void sweep_rows(phc_leaf *L, const leaf_factors *f, size_t q, double *restrict B,
                       const double *Z)
{
    size_t W = L->w, H = L->h, lo = L->blk_lo[q], hi = L->blk_hi[q];
    if (lo >= hi)
        return;
    const double *yr[ROW_BLOCK];
    for (size_t j = 0; j < ROW_BLOCK; ++j) {
        size_t y = q * ROW_BLOCK + j;
        yr[j] = y < H ? L->y + W * y : Z;
    }
    const double *restrict rf = f->rr + q * W * ROW_BLOCK;
    const double *restrict bf = f->br + q * W * ROW_BLOCK;
    /* forward: w_x = y_x + b_{x-1} w_{x-1}, ROW_BLOCK independent lanes */
    double acc[ROW_BLOCK];
    for (size_t j = 0; j < ROW_BLOCK; ++j)
        B[lo * ROW_BLOCK + j] = acc[j] = yr[j][lo];
    for (size_t x = lo + 1; x < hi; ++x) {
        const double *restrict bp = bf + (x - 1) * ROW_BLOCK;
        double *restrict bx = B + x * ROW_BLOCK;
        for (size_t j = 0; j < ROW_BLOCK; ++j) {
            acc[j] = yr[j][x] + bp[j] * acc[j];
            bx[j] = acc[j];
        }
    }
    /* back: y'_x = r_x w_x + b_x y'_{x+1} */
    for (size_t j = 0; j < ROW_BLOCK; ++j) {
        size_t o = (hi - 1) * ROW_BLOCK + j;
        acc[j] = rf[o] * B[o];
        B[o] = acc[j];
    }
    for (size_t x = hi - 1; x-- > lo;) {
        double *restrict bx = B + x * ROW_BLOCK;
        const double *restrict rx = rf + x * ROW_BLOCK;
        const double *restrict bb = bf + x * ROW_BLOCK;
        for (size_t j = 0; j < ROW_BLOCK; ++j) {
            acc[j] = rx[j] * bx[j] + bb[j] * acc[j];
            bx[j] = acc[j];
        }
    }
    /* copy back onto the runs only */
    for (size_t j = 0; j < ROW_BLOCK; ++j) {
        size_t y = q * ROW_BLOCK + j;
        if (y >= H)
            break;
        double *yw = L->y + W * y;
        for (size_t r = L->run_first[y]; r < L->run_first[y + 1]; ++r)
            for (size_t x = L->run_lo[r]; x < L->run_hi[r]; ++x)
                yw[x] = B[x * ROW_BLOCK + j];
    }
}

static void run_columns(phc_leaf *L, const leaf_factors *f, double cO, double cI)
{
#pragma omp parallel if (parallel(L))
    {
        size_t nt = 1, tid = 0;
#ifdef _OPENMP
        nt = (size_t)omp_get_num_threads();
        tid = (size_t)omp_get_thread_num();
#endif
        size_t x0, x1;
        chunk(L->w, nt, tid, &x0, &x1);
        if (x0 < x1)
            sweep_columns(L, f, cO, cI, x0, x1);
    }
}

static void run_rows(phc_leaf *L, const leaf_factors *f)
{
#pragma omp parallel if (parallel(L))
    {
        size_t tid = 0;
#ifdef _OPENMP
        tid = (size_t)omp_get_thread_num();
#endif
        double *B = L->buf + L->w + tid * L->w * ROW_BLOCK;
#pragma omp for schedule(static)
        for (size_t q = 0; q < L->nblocks; ++q)
            sweep_rows(L, f, q, B, L->buf);
    }
}

int phc_leaf_diffuse(phc_leaf *leaf, double h, phc_leaf_axis axis)
{
    if (!leaf)
        return PHC_ERR_INVALID;
    int rc = PHC_OK;
    const leaf_factors *f = factors_for(leaf, h, &rc);
    if (!f)
        return rc;
    if (axis == PHC_LEAF_COLUMNS) {
        run_columns(leaf, f, 0.0, 0.0);
    } else {
        if ((rc = ensure_buffers(leaf)))
            return rc;
        run_rows(leaf, f);
    }
    return PHC_OK;
}

/* One step (Silva et al. §3, eq. 1): sources (eqs. 2-3) fused into the
 * column half-step's forward sweep, then the row half-step.  Bit-identical
 * to phc_leaf_sources, phc_leaf_diffuse(COLUMNS), phc_leaf_diffuse(ROWS). */
int phc_leaf_step(phc_leaf *leaf, double h)
{
    if (!leaf)
        return PHC_ERR_INVALID;
    int rc = PHC_OK;
    const leaf_factors *f = factors_for(leaf, h, &rc);
    if (!f)
        return rc;
    if ((rc = ensure_buffers(leaf)))
        return rc;
    run_columns(leaf, f, h * leaf->p.stomata_scale, h * leaf->p.inflow_scale);
    run_rows(leaf, f);
    leaf->t += h;
    return PHC_OK;
}

int phc_leaf_advance(phc_leaf *leaf, double t)
{
    if (!leaf || !(isfinite(t) && t >= 0))
        return PHC_ERR_INVALID;
    double dt = leaf->p.dt, nf = floor(t / dt);
    if (nf > 1e15)
        return PHC_ERR_INVALID;
    size_t n = (size_t)nf;
    for (size_t k = 0; k < n; ++k) {
        int rc = phc_leaf_step(leaf, dt);
        if (rc)
            return rc;
    }
    double rem = t - nf * dt;
    if (rem > 1e-12 * dt)
        return phc_leaf_step(leaf, rem);
    return PHC_OK;
}
