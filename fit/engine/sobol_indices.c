/* Sobol indices from a Saltelli design: see sobol_indices.h. */
#include "fit/engine/sobol_indices.h"

#include <gsl/gsl_qrng.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

struct phc_saltelli_design {
    size_t k, f, n, block; /* columns, factors, base samples, rows per base sample */
    size_t *group_of;      /* k */
    double *base;          /* n x 2k: A_j = base[j][0..k-1], B_j = base[j][k..2k-1] */
    phc_saltelli_options o;
};

phc_saltelli_options phc_saltelli_options_default(void)
{
    phc_saltelli_options o = {1024, 0, 0, 1, 1000, 0.95};
    return o;
}

int phc_saltelli_design_new(size_t k, const size_t *group_of, size_t n_factors, const phc_saltelli_options *o,
                            phc_saltelli_design **out, phc_error *err)
{
    *out = NULL;
    if (k == 0 || n_factors == 0 || n_factors > k)
        return phc_error_set(err, PHC_ERR_INPUT, "a sensitivity study needs at least one factor to vary "
                             "(found %zu parameters in %zu factors)", k, n_factors);
    if (!group_of && n_factors != k)
        return phc_error_set(err, PHC_ERR_INVALID, "without groups every parameter is its own factor");
    const size_t n_min = o->second_order ? 16 : 8;
    if (o->n < n_min)
        return phc_error_set(err, PHC_ERR_INPUT, "samples: N = %zu is too small for %s indices: use at least %zu "
                             "(a few hundred for useful intervals)", o->n,
                             o->second_order ? "second-order" : "first-order and total", n_min);
    if (o->n > (size_t)1 << 30)
        return phc_error_set(err, PHC_ERR_INPUT, "samples: N = %zu is beyond 2^30", o->n);
    if (o->bootstrap < 100 || !(o->level > 0 && o->level < 1))
        return phc_error_set(err, PHC_ERR_INPUT, "bootstrap: needs >= 100 resamples and a level in (0, 1), "
                             "found %zu and %g", o->bootstrap, o->level);
    if (!o->randomised && 2 * k > 40)
        return phc_error_set(err, PHC_ERR_INPUT, "%zu parameters need %zu Sobol dimensions; GSL's sequence has 40: "
                             "use the randomised design (phytocal sensitivity --design random)", k, 2 * k);
    phc_saltelli_design *d = calloc(1, sizeof *d);
    if (!d)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    d->k = k;
    d->f = n_factors;
    d->n = o->n;
    d->o = *o;
    d->block = o->second_order ? 2 * n_factors + 2 : n_factors + 2;
    d->group_of = malloc(k * sizeof *d->group_of);
    d->base = malloc(o->n * 2 * k * sizeof *d->base);
    size_t *count = calloc(n_factors, sizeof *count);
    int rc = PHC_OK;
    if (!d->group_of || !d->base || !count) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t c = 0; c < k; ++c) {
        d->group_of[c] = group_of ? group_of[c] : c;
        if (d->group_of[c] >= n_factors) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "column %zu: factor %zu of %zu", c, d->group_of[c], n_factors);
            goto fail;
        }
        count[d->group_of[c]]++;
    }
    for (size_t g = 0; g < n_factors; ++g)
        if (!count[g]) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "factor %zu holds no parameter", g + 1);
            goto fail;
        }
    if (o->randomised) {
        gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
        if (!r) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        gsl_rng_set(r, o->seed);
        for (size_t i = 0; i < o->n * 2 * k; ++i)
            d->base[i] = gsl_rng_uniform_pos(r); /* (0, 1): unbounded priors stay finite */
        gsl_rng_free(r);
    } else {
        gsl_qrng *q = gsl_qrng_alloc(gsl_qrng_sobol, (unsigned)(2 * k));
        if (!q) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        double skip[40];
        gsl_qrng_get(q, skip); /* the centre: A_0 = B_0 (header) */
        for (size_t j = 0; j < o->n; ++j)
            gsl_qrng_get(q, d->base + j * 2 * k);
        gsl_qrng_free(q);
    }
    free(count);
    *out = d;
    return PHC_OK;
fail:
    free(count);
    phc_saltelli_design_free(d);
    return rc;
}

void phc_saltelli_design_free(phc_saltelli_design *d)
{
    if (!d)
        return;
    free(d->group_of);
    free(d->base);
    free(d);
}

size_t phc_saltelli_design_rows(const phc_saltelli_design *d)
{
    return d->n * d->block;
}

size_t phc_saltelli_design_factors(const phc_saltelli_design *d)
{
    return d->f;
}

void phc_saltelli_design_point(const phc_saltelli_design *d, size_t row, double *u)
{
    const size_t j = row / d->block, s = row % d->block, k = d->k;
    const double *a = d->base + j * 2 * k, *b = a + k;
    if (s == 0) {
        memcpy(u, a, k * sizeof *u);
    } else if (s == 1) {
        memcpy(u, b, k * sizeof *u);
    } else if (s < 2 + d->f) { /* A_B^i: A with factor i from B */
        const size_t i = s - 2;
        for (size_t c = 0; c < k; ++c)
            u[c] = d->group_of[c] == i ? b[c] : a[c];
    } else { /* B_A^i: B with factor i from A */
        const size_t i = s - 2 - d->f;
        for (size_t c = 0; c < k; ++c)
            u[c] = d->group_of[c] == i ? a[c] : b[c];
    }
}

void phc_sobol_indices_clear(phc_sobol_indices *s)
{
    if (!s)
        return;
    free(s->s1);
    free(s->st);
    free(s->s2);
    memset(s, 0, sizeof *s);
}

/* The indices from the base samples idx[0..m-1] (repeats allowed), with y
 * centred on its own mean over A and B of those samples (two passes: a cost
 * of 1e6 varying by 1 keeps its digits).  s1, st: f values; s2: f*f or NULL.
 * acc: scratch of 2f + f*f values.  The third pass accumulates every factor's
 * sums at once, each in the order of t (the same sums, term by term, as one
 * pass per factor: the results do not depend on the loop order). */
static void estimate(const phc_saltelli_design *d, const double *y, const size_t *idx, size_t m, double *s1,
                     double *st, double *s2, double *acc)
{
    const size_t f = d->f, bl = d->block;
    double sum = 0, sum2 = 0;
    for (size_t t = 0; t < m; ++t)
        sum += y[idx[t] * bl] + y[idx[t] * bl + 1];
    const double mean = sum / (double)(2 * m);
    for (size_t t = 0; t < m; ++t) {
        const double a = y[idx[t] * bl] - mean, b = y[idx[t] * bl + 1] - mean;
        sum2 += a * a + b * b;
    }
    const double var = sum2 / (double)(2 * m);
    double *a1 = acc, *at = acc + f, *a2 = acc + 2 * f;
    memset(acc, 0, (s2 ? 2 * f + f * f : 2 * f) * sizeof *acc);
    for (size_t t = 0; t < m; ++t) {
        const double *yb = y + idx[t] * bl;
        const double fa = yb[0] - mean, fb = yb[1] - mean;
        for (size_t i = 0; i < f; ++i) {
            const double fab = yb[2 + i] - mean;
            a1[i] += fb * (fab - fa);
            at[i] += (fa - fab) * (fa - fab);
        }
        if (s2)
            for (size_t i = 0; i < f; ++i) {
                const double fba_i = yb[2 + f + i] - mean;
                for (size_t j = i + 1; j < f; ++j) {
                    const double fab_j = yb[2 + j] - mean;
                    a2[i * f + j] += fba_i * fab_j - fa * fb;
                }
            }
    }
    for (size_t i = 0; i < f; ++i) {
        s1[i] = var > 0 ? a1[i] / (double)m / var : NAN;
        st[i] = var > 0 ? at[i] / (2.0 * (double)m) / var : NAN;
    }
    if (!s2)
        return;
    for (size_t i = 0; i < f; ++i)
        for (size_t j = 0; j < f; ++j)
            s2[i * f + j] = j <= i ? NAN : var > 0 ? a2[i * f + j] / (double)m / var - s1[i] - s1[j] : NAN;
}

enum { GROUP = 4 }; /* resamples per kernel call (the lanes of a vector) */

/* ---- the bootstrap kernel: GROUP resamples x several outputs per pass ----------------
 * The raw sums of estimate (without second order) and estimate_aggregate,
 * whose sums per output are the same, for GROUP resamples of nc outputs at once, the
 * GROUP resamples in the lanes of one vector (GCC's vector extension; SSE2
 * splits it in two, the AVX2 clone does it in one).  Lane q's sums are taken
 * term by term as estimate takes resample q's (the same terms, the same
 * order, the same expressions; vector lanes round as the scalar operations
 * do, and no clone has FMA to contract them), so the results are the same
 * bits.  The outputs of one base sample lie together when rs > cs (a study's
 * row-major y), so one index fetches them all instead of one per output.
 * Value of output c at design row r: y[r rs + c cs].  idx: GROUP x m base
 * samples (resample q at idx + q m).  sums: nc x (2 + 2f) vectors per
 * output c: the mean, the summed squares (divisor still to apply), the f
 * first-order and the f total numerators. */
typedef double v4d __attribute__((vector_size(GROUP * sizeof(double))));

#define PHC_KERNEL_CLONES __attribute__((target_clones("avx2", "default")))

PHC_KERNEL_CLONES
static void group_sums(size_t f, size_t bl, const double *y, size_t rs, size_t cs, size_t nc, const uint32_t *idx,
                       size_t m, v4d *sums)
{
    const size_t per = 2 + 2 * f, ab = bl * rs;
    const uint32_t *i0 = idx, *i1 = idx + m, *i2 = idx + 2 * m, *i3 = idx + 3 * m;
    const double two_m = (double)(2 * m);
    for (size_t c = 0; c < nc; ++c)
        for (size_t k = 0; k < per; ++k)
            sums[c * per + k] = (v4d){0, 0, 0, 0};
    for (size_t t = 0; t < m; ++t) {
        const double *p0 = y + i0[t] * ab, *p1 = y + i1[t] * ab, *p2 = y + i2[t] * ab, *p3 = y + i3[t] * ab;
        for (size_t c = 0; c < nc; ++c) {
            const size_t o = c * cs;
            const v4d a = {p0[o], p1[o], p2[o], p3[o]}, b = {p0[o + rs], p1[o + rs], p2[o + rs], p3[o + rs]};
            sums[c * per] += a + b;
        }
    }
    for (size_t c = 0; c < nc; ++c)
        sums[c * per] = sums[c * per] / two_m;
    for (size_t t = 0; t < m; ++t) {
        const double *p0 = y + i0[t] * ab, *p1 = y + i1[t] * ab, *p2 = y + i2[t] * ab, *p3 = y + i3[t] * ab;
        for (size_t c = 0; c < nc; ++c) {
            const size_t o = c * cs;
            const v4d mean = sums[c * per];
            const v4d a = (v4d){p0[o], p1[o], p2[o], p3[o]} - mean,
                      b = (v4d){p0[o + rs], p1[o + rs], p2[o + rs], p3[o + rs]} - mean;
            sums[c * per + 1] += a * a + b * b;
        }
    }
    for (size_t t = 0; t < m; ++t) {
        const double *p0 = y + i0[t] * ab, *p1 = y + i1[t] * ab, *p2 = y + i2[t] * ab, *p3 = y + i3[t] * ab;
        for (size_t c = 0; c < nc; ++c) {
            const size_t o = c * cs;
            v4d *sc = sums + c * per;
            const v4d mean = sc[0];
            const v4d fa = (v4d){p0[o], p1[o], p2[o], p3[o]} - mean,
                      fb = (v4d){p0[o + rs], p1[o + rs], p2[o + rs], p3[o + rs]} - mean;
            for (size_t i = 0; i < f; ++i) {
                const size_t oi = o + (2 + i) * rs;
                const v4d fab = (v4d){p0[oi], p1[oi], p2[oi], p3[oi]} - mean;
                sc[2 + i] += fb * (fab - fa);
                sc[2 + f + i] += (fa - fab) * (fa - fab);
            }
        }
    }
}

/* Outputs per kernel call: their accumulators stay in the L1 cache. */
enum { KERNEL_OUTPUTS = 8 };

/* Indices drawn per round before the threads share the round's resamples
 * out (at most 16 MB; fewer rounds, fewer waits at their ends). */
enum { DRAWS_PER_ROUND = 1 << 22 };

/* Percentile interval of the R values v (sorted here) at coverage level. */
static void percentile(double *v, size_t r, double level, double *lo, double *hi)
{
    gsl_sort(v, 1, r);
    *lo = gsl_stats_quantile_from_sorted_data(v, 1, r, 0.5 * (1 - level));
    *hi = gsl_stats_quantile_from_sorted_data(v, 1, r, 1 - 0.5 * (1 - level));
}

/* The base samples whose whole block is finite in y (stride between a
 * row's values: ys); returns their count. */
static size_t usable(const phc_saltelli_design *d, const double *y, size_t ys, size_t *used)
{
    size_t m = 0;
    for (size_t j = 0; j < d->n; ++j) {
        int ok = 1;
        for (size_t s = 0; s < d->block; ++s)
            ok &= isfinite(y[(j * d->block + s) * ys]) != 0;
        if (ok)
            used[m++] = j;
    }
    return m;
}

/* ---- the bootstrap's random base samples, drawn fast --------------------------------
 * The resamples draw m R indices with gsl_rng_uniform_int on GSL's
 * gsl_rng_mt19937; through GSL each costs a call through the generator's
 * function pointer and a 64-bit division.  `draws` makes the same numbers:
 * the Mersenne Twister (Matsumoto & Nishimura 1998, ACM TOMACS 8, 3) run on
 * a copy of the seeded GSL state, 624 words at a time, and GSL's
 * k = x / scale (scale = (2^32 - 1) / m, rejected while k >= m) taken in
 * double precision, exact here: with x = k scale + r, 0 <= r < scale, the
 * quotient lies at least 1/scale below k + 1 and (k + 1) scale <= 2^33 < 2^53,
 * so the rounded quotient stays below k + 1 and its floor is k.  The copy is
 * checked against GSL's own draws (1300 numbers, across a refill of the
 * state) when made; if they differ (another GSL's layout), GSL draws. */
enum { MT_N = 624, MT_M = 397 };

typedef struct draws {
    gsl_rng *rng;           /* seeded; used itself when !fast */
    int fast;               /* the copy below matches GSL's numbers */
    uint32_t mt[MT_N];
    size_t mti;
} draws;

static void mt_refill(uint32_t *mt)
{
    size_t kk;
    for (kk = 0; kk < MT_N - MT_M; ++kk) {
        const uint32_t y = (mt[kk] & 0x80000000u) | (mt[kk + 1] & 0x7fffffffu);
        mt[kk] = mt[kk + MT_M] ^ (y >> 1) ^ ((y & 1u) ? 0x9908b0dfu : 0u);
    }
    for (; kk < MT_N - 1; ++kk) {
        const uint32_t y = (mt[kk] & 0x80000000u) | (mt[kk + 1] & 0x7fffffffu);
        mt[kk] = mt[kk + MT_M - MT_N] ^ (y >> 1) ^ ((y & 1u) ? 0x9908b0dfu : 0u);
    }
    const uint32_t y = (mt[MT_N - 1] & 0x80000000u) | (mt[0] & 0x7fffffffu);
    mt[MT_N - 1] = mt[MT_M - 1] ^ (y >> 1) ^ ((y & 1u) ? 0x9908b0dfu : 0u);
}

static inline uint32_t mt_next(draws *g)
{
    if (g->mti >= MT_N) {
        mt_refill(g->mt);
        g->mti = 0;
    }
    uint32_t k = g->mt[g->mti++];
    k ^= k >> 11;
    k ^= (k << 7) & 0x9d2c5680u;
    k ^= (k << 15) & 0xefc60000u;
    k ^= k >> 18;
    return k;
}

/* Seeds GSL's generator with seed and copies its state (GSL's mt_state_t:
 * 624 unsigned longs, then the int position), checked as said above. */
static int draws_init(draws *g, unsigned long seed)
{
    memset(g, 0, sizeof *g);
    if (!(g->rng = gsl_rng_alloc(gsl_rng_mt19937)))
        return -1;
    gsl_rng_set(g->rng, seed);
    if (gsl_rng_size(g->rng) < MT_N * sizeof(unsigned long) + sizeof(int) || gsl_rng_max(g->rng) != 0xffffffffUL ||
        gsl_rng_min(g->rng) != 0)
        return 0;
    const unsigned long *st = gsl_rng_state(g->rng);
    int mti;
    memcpy(&mti, st + MT_N, sizeof mti);
    if (mti < 0 || mti > MT_N)
        return 0;
    for (size_t i = 0; i < MT_N; ++i)
        g->mt[i] = (uint32_t)st[i];
    g->mti = (size_t)mti;
    gsl_rng *check = gsl_rng_clone(g->rng);
    if (!check)
        return -1;
    draws copy = *g;
    int same = 1;
    for (int i = 0; i < 1300 && same; ++i)
        same = mt_next(&copy) == (uint32_t)gsl_rng_get(check);
    gsl_rng_free(check);
    g->fast = same;
    return 0;
}

/* count x m draws of used[gsl_rng_uniform_int(rng, m)], in GSL's order. */
static void draws_take(draws *g, const size_t *used, size_t m, size_t count, uint32_t *out)
{
    if (!g->fast || m > 0xffffffffUL) {
        for (size_t i = 0; i < count * m; ++i)
            out[i] = (uint32_t)used[gsl_rng_uniform_int(g->rng, m)];
        return;
    }
    const uint32_t scale = (uint32_t)(0xffffffffUL / m);
    const double ds = (double)scale;
    for (size_t i = 0; i < count * m; ++i) {
        uint32_t k;
        do
            k = (uint32_t)((double)mt_next(g) / ds);
        while (k >= m);
        out[i] = (uint32_t)used[k];
    }
}

/* Values per resample and output in the raw bootstrap sums: the summed
 * squares (divisor 2m still to apply), f first-order and f total numerators. */
#define RAW_PER(f) (1 + 2 * (f))

/* The bootstrap's raw sums: R resamples of the base samples used[0..m-1]
 * (the generator seeded with the design's seed, drawn in turn, resample by
 * resample, as the estimators always drew them) for nc outputs (value of
 * output c at design row r: rows[r rs + c cs]); raw[(c R + r) RAW_PER(f) ..].
 * A round's resamples are drawn, then shared out to the threads GROUP at a time;
 * each resample's sums land in their own place and are taken the same way
 * by any thread, so the results do not depend on the number of threads.
 * The last R mod GROUP resamples go through the kernel with their lanes
 * filled by copies (their sums dropped). */
static int bootstrap_raw(const phc_saltelli_design *d, const double *rows, size_t rs, size_t cs, size_t nc,
                         const size_t *used, size_t m, double *raw)
{
    const size_t f = d->f, bl = d->block, R = d->o.bootstrap, rp = RAW_PER(f);
    const size_t threads = (size_t)omp_get_max_threads(), kper = KERNEL_OUTPUTS * (2 + 2 * f);
    /* resamples per round: a multiple of GROUP, all R if they fit */
    size_t chunk = DRAWS_PER_ROUND / m / GROUP * GROUP, r_up = (R + GROUP - 1) / GROUP * GROUP;
    chunk = chunk < GROUP ? GROUP : chunk > r_up ? r_up : chunk;
    uint32_t *draw = malloc(chunk * m * sizeof *draw);
    v4d *scratch = aligned_alloc(sizeof(v4d), threads * kper * sizeof *scratch); /* vectors: their alignment */
    draws *gen = malloc(sizeof *gen);
    /* a fixed stream: results do not depend on other outputs */
    if (!draw || !scratch || !gen || draws_init(gen, d->o.seed ^ 0x5deece66dUL)) {
        free(draw);
        free(scratch);
        if (gen)
            gsl_rng_free(gen->rng);
        free(gen);
        return -1;
    }
    for (size_t r0 = 0; r0 < R; r0 += chunk) {
        const size_t nr = R - r0 < chunk ? R - r0 : chunk, ng = (nr + GROUP - 1) / GROUP;
        draws_take(gen, used, m, nr, draw);
        for (size_t q = nr; q < ng * GROUP; ++q) /* the last group's spare lanes */
            memcpy(draw + q * m, draw, m * sizeof *draw);
#pragma omp parallel for schedule(dynamic, 1) if (ng > 1)
        for (long g = 0; g < (long)ng; ++g) { /* dynamic: a thread slowed by other processes takes fewer */
            v4d *sums = scratch + (size_t)omp_get_thread_num() * kper;
            const size_t rg = r0 + (size_t)g * GROUP, lanes = R - rg < GROUP ? R - rg : GROUP;
            for (size_t c0 = 0; c0 < nc; c0 += KERNEL_OUTPUTS) {
                const size_t k = nc - c0 < KERNEL_OUTPUTS ? nc - c0 : KERNEL_OUTPUTS;
                group_sums(f, bl, rows + c0 * cs, rs, cs, k, draw + (size_t)g * GROUP * m, m, sums);
                for (size_t c = 0; c < k; ++c) {
                    const v4d *sc = sums + c * (2 + 2 * f);
                    for (size_t q = 0; q < lanes; ++q) {
                        double *o = raw + ((c0 + c) * R + rg + q) * rp;
                        for (size_t i = 0; i < rp; ++i)
                            o[i] = sc[1 + i][q];
                    }
                }
            }
        }
    }
    free(draw);
    free(scratch);
    gsl_rng_free(gen->rng);
    free(gen);
    return 0;
}

/* Fills out's intervals from its R bootstrap values per index,
 * boot[r stride + i] for i < per (s1, st, then s2); tmp: R values. */
static void intervals(const phc_saltelli_design *d, const double *boot, size_t stride, size_t per, double *tmp,
                      phc_sobol_indices *out)
{
    const size_t f = d->f, R = d->o.bootstrap;
    for (size_t i = 0; i < per; ++i) {
        size_t cnt = 0;
        for (size_t r = 0; r < R; ++r) {
            const double v = boot[r * stride + i];
            if (isfinite(v))
                tmp[cnt++] = v;
        }
        double lo = NAN, hi = NAN;
        if (cnt >= R / 2)
            percentile(tmp, cnt, d->o.level, &lo, &hi);
        if (i < f) {
            out->s1_lo[i] = lo;
            out->s1_hi[i] = hi;
        } else if (i < 2 * f) {
            out->st_lo[i - f] = lo;
            out->st_hi[i - f] = hi;
        } else {
            out->s2_lo[i - 2 * f] = lo;
            out->s2_hi[i - 2 * f] = hi;
        }
    }
}

/* The indices of n_out outputs (columns cols[c M ..], contiguous; the same
 * values also at rows[r rs + c cs] for the kernel) that share the usable
 * base samples used[0..m-1]: every output's bootstrap draws the same
 * resamples (the generator is seeded the same for every output, so each
 * output's result is what estimating it alone gives), drawn once.  raw
 * (without second order; n_out R RAW_PER(f) values, or NULL): receives the
 * bootstrap's raw sums, for the aggregated indices of the same outputs. */
static int estimate_outputs(const phc_saltelli_design *d, const double *cols, const double *rows, size_t rs,
                            size_t cs, size_t n_out, const size_t *used, size_t m, phc_sobol_indices *outs,
                            double *raw, phc_error *err)
{
    const size_t f = d->f, bl = d->block, n = d->n, R = d->o.bootstrap, nf2 = d->o.second_order ? f * f : 0;
    const size_t M = n * bl, per = 2 * f + nf2, rp = RAW_PER(f);
    size_t *draw = malloc(n * sizeof *draw);
    double *boot = malloc(n_out * R * per * sizeof *boot), *tmp = malloc((R > 1 ? R : 1) * sizeof *tmp);
    double *acc = malloc((2 * f + f * f) * sizeof *acc);
    double *own = !nf2 && !raw ? malloc(n_out * R * rp * sizeof *own) : NULL;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = PHC_OK;
    if (!nf2 && !raw)
        raw = own;
    for (size_t c = 0; c < n_out; ++c) {
        phc_sobol_indices *out = &outs[c];
        memset(out, 0, sizeof *out);
        out->n_factors = f;
        out->s1 = malloc(3 * f * sizeof *out->s1);
        out->st = malloc(3 * f * sizeof *out->st);
        out->s2 = nf2 ? malloc(3 * nf2 * sizeof *out->s2) : NULL;
        if (!out->s1 || !out->st || (nf2 && !out->s2))
            rc = PHC_ERR_NOMEM;
    }
    if (rc || !draw || !boot || !tmp || !acc || (!nf2 && !raw) || !rng) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t c = 0; c < n_out; ++c) {
        phc_sobol_indices *out = &outs[c];
        const double *y = cols + c * M;
        out->s1_lo = out->s1 + f;
        out->s1_hi = out->s1 + 2 * f;
        out->st_lo = out->st + f;
        out->st_hi = out->st + 2 * f;
        if (nf2) {
            out->s2_lo = out->s2 + nf2;
            out->s2_hi = out->s2 + 2 * nf2;
        }
        out->n_used = m;
        out->n_failed = n - m;
        if (m < 4) {
            rc = phc_error_set(err, PHC_ERR_NUMERIC, "only %zu of %zu base samples have every evaluation finished; "
                               "the indices need at least 4", m, n);
            goto done;
        }
        double sum = 0, sum2 = 0;
        for (size_t t = 0; t < m; ++t) {
            sum += y[used[t] * bl] + y[used[t] * bl + 1];
        }
        out->mean = sum / (double)(2 * m);
        for (size_t t = 0; t < m; ++t) {
            const double a = y[used[t] * bl] - out->mean, b = y[used[t] * bl + 1] - out->mean;
            sum2 += a * a + b * b;
        }
        out->variance = sum2 / (double)(2 * m);
        estimate(d, y, used, m, out->s1, out->st, out->s2, acc);
    }
    if (!nf2) {
        /* the kernel's sums, finished as estimate finishes them */
        if (bootstrap_raw(d, rows, rs, cs, n_out, used, m, raw)) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        for (size_t c = 0; c < n_out; ++c)
            for (size_t r = 0; r < R; ++r) {
                const double *w = raw + (c * R + r) * rp;
                double *b = boot + (c * R + r) * per;
                const double var = w[0] / (double)(2 * m);
                for (size_t i = 0; i < f; ++i) {
                    b[i] = var > 0 ? w[1 + i] / (double)m / var : NAN;
                    b[f + i] = var > 0 ? w[1 + f + i] / (2.0 * (double)m) / var : NAN;
                }
            }
    } else {
        /* second order: one resample at a time, all outputs on the same draws */
        gsl_rng_set(rng, d->o.seed ^ 0x5deece66dUL);
        for (size_t r = 0; r < R; ++r) {
            for (size_t t = 0; t < m; ++t)
                draw[t] = used[gsl_rng_uniform_int(rng, m)];
            for (size_t c = 0; c < n_out; ++c) {
                double *b = boot + (c * R + r) * per;
                estimate(d, cols + c * M, draw, m, b, b + f, b + 2 * f, acc);
            }
        }
    }
    for (size_t c = 0; c < n_out; ++c)
        intervals(d, boot + c * R * per, per, per, tmp, &outs[c]);
done:
    gsl_rng_free(rng);
    free(draw);
    free(boot);
    free(tmp);
    free(acc);
    free(own);
    if (rc)
        for (size_t c = 0; c < n_out; ++c)
            phc_sobol_indices_clear(&outs[c]);
    return rc;
}

int phc_sobol_indices_estimate(const phc_saltelli_design *d, const double *y, phc_sobol_indices *out,
                               phc_error *err)
{
    size_t *used = malloc(d->n * sizeof *used);
    if (!used) {
        memset(out, 0, sizeof *out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    const size_t m = usable(d, y, 1, used);
    const int rc = estimate_outputs(d, y, y, 1, d->n * d->block, 1, used, m, out, NULL, err);
    free(used);
    return rc;
}

/* The aggregated indices from the base samples idx[0..m-1] of the T
 * columns y + t M (M = n block). */
static void estimate_aggregate(const phc_saltelli_design *d, const double *y, size_t T, const size_t *idx, size_t m,
                               double *s1, double *st, double *num1, double *numt, double *var_out)
{
    const size_t f = d->f, bl = d->block, M = d->n * d->block;
    double var_sum = 0;
    for (size_t i = 0; i < f; ++i)
        num1[i] = numt[i] = 0;
    for (size_t t = 0; t < T; ++t) {
        const double *yt = y + t * M;
        double sum = 0, sum2 = 0;
        for (size_t q = 0; q < m; ++q)
            sum += yt[idx[q] * bl] + yt[idx[q] * bl + 1];
        const double mean = sum / (double)(2 * m);
        for (size_t q = 0; q < m; ++q) {
            const double a = yt[idx[q] * bl] - mean, b = yt[idx[q] * bl + 1] - mean;
            sum2 += a * a + b * b;
        }
        var_sum += sum2 / (double)(2 * m);
        for (size_t i = 0; i < f; ++i) {
            double a1 = 0, at = 0;
            for (size_t q = 0; q < m; ++q) {
                const double *yb = yt + idx[q] * bl;
                const double fa = yb[0] - mean, fb = yb[1] - mean, fab = yb[2 + i] - mean;
                a1 += fb * (fab - fa);
                at += (fa - fab) * (fa - fab);
            }
            num1[i] += a1 / (double)m;
            numt[i] += at / (2.0 * (double)m);
        }
    }
    for (size_t i = 0; i < f; ++i) {
        s1[i] = var_sum > 0 ? num1[i] / var_sum : NAN;
        st[i] = var_sum > 0 ? numt[i] / var_sum : NAN;
    }
    if (var_out)
        *var_out = var_sum;
}

/* The aggregated indices of the T columns y + t M from the bootstrap's raw
 * sums of those outputs (raw[(t R + r) RAW_PER(f) ..], all on the resamples
 * of used[0..m-1]), combined as estimate_aggregate combines them, in the
 * order of t. */
static int aggregate_from_raw(const phc_saltelli_design *d, const double *y, size_t T, const size_t *used, size_t m,
                              const double *raw, phc_sobol_indices *out, phc_error *err)
{
    const size_t f = d->f, bl = d->block, n = d->n, R = d->o.bootstrap, M = n * bl, rp = RAW_PER(f);
    double *boot = malloc(R * 2 * f * sizeof *boot), *tmp = malloc(R * sizeof *tmp);
    double *num = malloc(2 * f * sizeof *num);
    int rc = PHC_OK;
    if (!boot || !tmp || !num) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    double mean_sum = 0;
    for (size_t t = 0; t < T; ++t) {
        double sum = 0;
        for (size_t q = 0; q < m; ++q)
            sum += y[t * M + used[q] * bl] + y[t * M + used[q] * bl + 1];
        mean_sum += sum / (double)(2 * m);
    }
    out->mean = mean_sum / (double)T;
    estimate_aggregate(d, y, T, used, m, out->s1, out->st, num, num + f, &out->variance);
    for (size_t r = 0; r < R; ++r) {
        double var_sum = 0, *num1 = num, *numt = num + f;
        for (size_t i = 0; i < f; ++i)
            num1[i] = numt[i] = 0;
        for (size_t t = 0; t < T; ++t) {
            const double *w = raw + (t * R + r) * rp;
            var_sum += w[0] / (double)(2 * m);
            for (size_t i = 0; i < f; ++i) {
                num1[i] += w[1 + i] / (double)m;
                numt[i] += w[1 + f + i] / (2.0 * (double)m);
            }
        }
        for (size_t i = 0; i < f; ++i) {
            boot[r * 2 * f + i] = var_sum > 0 ? num1[i] / var_sum : NAN;
            boot[r * 2 * f + f + i] = var_sum > 0 ? numt[i] / var_sum : NAN;
        }
    }
    intervals(d, boot, 2 * f, 2 * f, tmp, out);
done:
    free(boot);
    free(tmp);
    free(num);
    return rc;
}

/* out's arrays for the aggregated indices (no second order). */
static int aggregate_alloc(const phc_saltelli_design *d, phc_sobol_indices *out)
{
    const size_t f = d->f;
    memset(out, 0, sizeof *out);
    out->n_factors = f;
    out->s1 = malloc(3 * f * sizeof *out->s1);
    out->st = malloc(3 * f * sizeof *out->st);
    if (!out->s1 || !out->st)
        return -1;
    out->s1_lo = out->s1 + f;
    out->s1_hi = out->s1 + 2 * f;
    out->st_lo = out->st + f;
    out->st_hi = out->st + 2 * f;
    return 0;
}

int phc_sobol_indices_estimate_aggregate(const phc_saltelli_design *d, const double *y, size_t n_outputs,
                                         phc_sobol_indices *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t f = d->f, bl = d->block, n = d->n, R = d->o.bootstrap, M = d->n * d->block;
    if (n_outputs == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "aggregated indices of no output");
    size_t *used = malloc(n * sizeof *used);
    double *raw = malloc(n_outputs * R * RAW_PER(f) * sizeof *raw);
    int rc = PHC_OK;
    if (!used || !raw || aggregate_alloc(d, out)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    size_t m = 0;
    for (size_t j = 0; j < n; ++j) {
        int ok = 1;
        for (size_t t = 0; t < n_outputs && ok; ++t)
            for (size_t s = 0; s < bl; ++s)
                ok &= isfinite(y[t * M + j * bl + s]) != 0;
        if (ok)
            used[m++] = j;
    }
    out->n_used = m;
    out->n_failed = n - m;
    if (m < 4) {
        rc = phc_error_set(err, PHC_ERR_NUMERIC, "only %zu of %zu base samples have every evaluation finished; "
                           "the indices need at least 4", m, n);
        goto done;
    }
    if (bootstrap_raw(d, y, 1, M, n_outputs, used, m, raw)) { /* the resamples of phc_sobol_indices_estimate */
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    rc = aggregate_from_raw(d, y, n_outputs, used, m, raw, out, err);
done:
    free(used);
    free(raw);
    if (rc)
        phc_sobol_indices_clear(out);
    return rc;
}

int phc_sobol_indices_estimate_outputs(const phc_saltelli_design *d, const double *y, size_t n_out,
                                       phc_sobol_indices *outs, phc_error *err)
{
    return phc_sobol_indices_estimate_study(d, y, n_out, outs, 0, NULL, NULL, NULL, err);
}

int phc_sobol_indices_estimate_study(const phc_saltelli_design *d, const double *y, size_t n_out,
                                     phc_sobol_indices *outs, size_t n_agg, const size_t *agg_first,
                                     const size_t *agg_count, phc_sobol_indices *aggs, phc_error *err)
{
    const size_t M = d->n * d->block, R = d->o.bootstrap, rp = RAW_PER(d->f);
    const int keep = n_agg > 0 && !d->o.second_order; /* raw sums kept for the aggregates */
    size_t *used = malloc(d->n * sizeof *used), *other = malloc(d->n * sizeof *other);
    size_t *run = malloc((n_out ? n_out : 1) * sizeof *run); /* first output of each output's run */
    double *cols = malloc((n_out ? n_out : 1) * M * sizeof *cols);
    double *raw = keep ? malloc(n_out * R * rp * sizeof *raw) : NULL;
    int rc = PHC_OK;
    for (size_t c = 0; c < n_out; ++c)
        memset(&outs[c], 0, sizeof outs[c]);
    for (size_t a = 0; a < n_agg; ++a)
        memset(&aggs[a], 0, sizeof aggs[a]);
    if (!used || !other || !run || !cols || (keep && !raw)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t a = 0; a < n_agg; ++a)
        if (agg_count[a] == 0 || agg_first[a] > n_out || agg_count[a] > n_out - agg_first[a]) {
            rc = phc_error_set(err, PHC_ERR_INVALID, "aggregate %zu: outputs %zu + %zu of %zu", a, agg_first[a],
                               agg_count[a], n_out);
            goto done;
        }
    for (size_t c = 0; c < n_out; ++c)
        for (size_t r = 0; r < M; ++r)
            cols[c * M + r] = y[r * n_out + c];
    /* runs of outputs with the same usable base samples share their
       resamples (a failed evaluation makes every output of its row NAN, so
       in a study all outputs are one run) */
    for (size_t c0 = 0; c0 < n_out && rc == PHC_OK;) {
        const size_t m = usable(d, cols + c0 * M, 1, used);
        size_t c1 = c0 + 1;
        while (c1 < n_out && usable(d, cols + c1 * M, 1, other) == m && memcmp(used, other, m * sizeof *used) == 0)
            ++c1;
        for (size_t c = c0; c < c1; ++c)
            run[c] = c0;
        rc = estimate_outputs(d, cols + c0 * M, y + c0, n_out, 1, c1 - c0, used, m, outs + c0,
                              keep ? raw + c0 * R * rp : NULL, err);
        c0 = c1;
    }
    /* an aggregate whose outputs are one run (its usable base samples are
       then the run's: the intersection of its outputs') has its bootstrap
       sums already; otherwise it is estimated on its own (the same result) */
    for (size_t a = 0; a < n_agg && rc == PHC_OK; ++a) {
        const size_t c0 = agg_first[a], T = agg_count[a];
        if (keep && run[c0] == run[c0 + T - 1]) {
            const size_t m = usable(d, cols + c0 * M, 1, used);
            if (aggregate_alloc(d, &aggs[a])) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                break;
            }
            aggs[a].n_used = m;
            aggs[a].n_failed = d->n - m;
            if (m < 4)
                rc = phc_error_set(err, PHC_ERR_NUMERIC, "only %zu of %zu base samples have every evaluation "
                                   "finished; the indices need at least 4", m, d->n);
            else
                rc = aggregate_from_raw(d, cols + c0 * M, T, used, m, raw + c0 * R * rp, &aggs[a], err);
        } else {
            rc = phc_sobol_indices_estimate_aggregate(d, cols + c0 * M, T, &aggs[a], err);
        }
    }
done:
    if (rc) {
        for (size_t c = 0; c < n_out; ++c)
            phc_sobol_indices_clear(&outs[c]);
        for (size_t a = 0; a < n_agg; ++a)
            phc_sobol_indices_clear(&aggs[a]);
    }
    free(used);
    free(other);
    free(run);
    free(cols);
    free(raw);
    return rc;
}
