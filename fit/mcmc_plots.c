/* Trace and pair plots of an MCMC run: see mcmc_plots.h.  As in
 * fit/sensitivity_plots.c, what PLplot could fail on (the device, the file,
 * an empty axis range) is checked before PLplot sees it. */
#include "fit/mcmc_plots.h"

#include <math.h>
#include <plplot.h>
#include <stdlib.h>
#include <string.h>

#include "fit/plot_file.h"

enum { COL_BG = 0, COL_FG = 1, COL_GRID = 2, COL_BURN = 3, COL_FILL = 4, COL_CHAIN0 = 5, N_CHAIN_COLOURS = 8 };
static const PLINT palette[COL_CHAIN0 + N_CHAIN_COLOURS][3] = {
    {255, 255, 255}, {0, 0, 0},     {221, 221, 221}, {235, 235, 235}, {31, 100, 190},
    {31, 119, 180},  {255, 127, 14}, {44, 160, 44},   {214, 39, 40},   {148, 103, 189},
    {140, 86, 75},   {227, 119, 194}, {127, 127, 127}};

/* Opens a PLplot stream writing to af's temporary file, in the palette. */
static int begin(const char *path, int w, int h, phc_atomic_file **af, int *old, phc_error *err)
{
    int rc = phc_plot_begin(path, w, h, af, old, err);
    if (rc)
        return rc;
    /* Lines and points without anti-aliasing (Cairo's ANTIALIAS_NONE; the
       text keeps it): a trace is thousands of overlapping strokes and a pair
       plot thousands of symbols: Cairo's anti-aliased stroking was 15% of
       `phytocal mcmc --method stretch`'s samples on Misra1a (perf, 32
       walkers x 6000 steps; CPU of the whole command, best of 5: 0.44 s
       -> 0.37 s). */
    plsetopt("drvopt", "graphics_anti_aliasing=1");
    plscmap0n(16);
    for (int i = 0; i < COL_CHAIN0 + N_CHAIN_COLOURS; ++i)
        plscol0(i, palette[i][0], palette[i][1], palette[i][2]);
    plinit();
    plsetopt("drvopt", "graphics_anti_aliasing=0"); /* the next stream's default again */
    pladv(0);
    plsxax(10, 0); /* plain numbers (up to 10 digits): no exponent label to collide with a neighbour */
    plsyax(10, 0);
    return PHC_OK;
}

static void range(const double *v, size_t n, size_t stride, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        const double x = v[i * stride];
        if (isfinite(x)) {
            *lo = x < *lo ? x : *lo;
            *hi = x > *hi ? x : *hi;
        }
    }
    if (!(*hi > *lo)) { /* one value (or none): a range around it */
        const double c = isfinite(*lo) ? *lo : 0, w = fabs(c) > 0 ? 0.01 * fabs(c) : 1;
        *lo = c - w;
        *hi = c + w;
    } else {
        const double pad = 0.04 * (*hi - *lo);
        *lo -= pad;
        *hi += pad;
    }
}

/* A chain's n values v[t * stride] as a line `px` pixels wide: with more
 * than two steps per pixel, each run of b = ceil(n / px) steps is drawn
 * through its lowest and its highest value in the order they occur (the
 * envelope a line through every step covers at that width, at a fraction
 * of the segments to stroke); otherwise every step.  Returns the points
 * written to xs, ys (at most n). */
static size_t trace_points(const double *v, size_t n, size_t stride, size_t px, PLFLT *xs, PLFLT *ys)
{
    size_t k = 0;
    if (n <= 2 * px) {
        for (size_t t = 0; t < n; ++t, ++k) {
            xs[k] = (double)t;
            ys[k] = v[t * stride];
        }
        return k;
    }
    const size_t b = (n + px - 1) / px;
    for (size_t t0 = 0; t0 < n; t0 += b) {
        const size_t t1 = t0 + b < n ? t0 + b : n;
        size_t lo = t0, hi = t0;
        for (size_t t = t0 + 1; t < t1; ++t) {
            if (v[t * stride] < v[lo * stride])
                lo = t;
            if (v[t * stride] > v[hi * stride])
                hi = t;
        }
        const size_t first = lo < hi ? lo : hi, second = lo < hi ? hi : lo;
        xs[k] = (double)first;
        ys[k++] = v[first * stride];
        if (second != first) {
            xs[k] = (double)second;
            ys[k++] = v[second * stride];
        }
    }
    return k;
}

int phc_plot_mcmc_trace(const char *path, const char *title, size_t d, const char *const *labels,
                        const double *draws, size_t chains, size_t n, size_t burn, phc_error *err)
{
    if (d == 0 || chains == 0 || n < 2)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: nothing to plot", path);
    char *etitle = phc_plot_escape(title);
    PLFLT *xs = malloc(n * sizeof *xs), *ys = malloc(n * sizeof *ys);
    if (!etitle || !xs || !ys) {
        free(etitle);
        free(xs);
        free(ys);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    phc_atomic_file *af = NULL;
    int old = 0;
    int h = (int)(170 * d + 130);
    h = h < 400 ? 400 : h;
    int rc = begin(path, 1100, h, &af, &old, err);
    if (rc) {
        free(etitle);
        free(xs);
        free(ys);
        return rc;
    }
    plschr(0.0, 0.9);
    const size_t shown = chains < N_CHAIN_COLOURS ? chains : N_CHAIN_COLOURS;
    /* margins in pixels: 45 above for the title, 75 below for the step axis and its label */
    const double top = 1 - 45.0 / h, bottom = 75.0 / h, gap = 0.02,
                 ph = (top - bottom - gap * (double)(d - 1)) / (double)d;
    for (size_t j = 0; j < d; ++j) {
        double lo, hi;
        range(draws + j, chains * n, d, &lo, &hi);
        const double y1 = top - (double)j * (ph + gap), y0 = y1 - ph;
        plvpor(0.12, 0.97, y0, y1);
        plwind(0, (double)(n - 1), lo, hi);
        PLFLT bx[4] = {0, (double)burn, (double)burn, 0}, by[4] = {lo, lo, hi, hi};
        plcol0(COL_BURN);
        plfill(4, bx, by);
        plcol0(COL_GRID);
        plbox("g", 0, 0, "g", 0, 0);
        for (size_t c = 0; c < shown; ++c) {
            /* the plot box is 0.85 of the 1100-pixel width */
            const size_t k = trace_points(draws + c * n * d + j, n, d, 935, xs, ys);
            plcol0(COL_CHAIN0 + (PLINT)c);
            plline((PLINT)k, xs, ys);
        }
        plcol0(COL_FG);
        plbox(j + 1 == d ? "bcnst" : "bcst", 0, 0, "bcnstv", 0, 0);
        char *el = phc_plot_escape(labels[j]);
        plmtex("l", 6.5, 0.5, 0.5, el ? el : "");
        free(el);
    }
    plcol0(COL_FG);
    char xl[160];
    snprintf(xl, sizeof xl, "step (%zu of %zu chains drawn)", shown, chains);
    plmtex("b", 3.2, 0.5, 0.5, xl);
    plvpor(0.12, 0.97, bottom, top);
    plmtex("t", 1.2, 0.5, 0.5, etitle);
    rc = phc_plot_end(af, old, PHC_OK, err);
    free(etitle);
    free(xs);
    free(ys);
    return rc;
}

int phc_plot_mcmc_pairs(const char *path, const char *title, size_t d, const char *const *labels,
                        const double *draws, size_t m, phc_error *err)
{
    if (d == 0 || m < 2)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: nothing to plot", path);
    enum { MAX_POINTS = 3000, BINS = 30 };
    const size_t step = m > MAX_POINTS ? (m + MAX_POINTS - 1) / MAX_POINTS : 1;
    char *etitle = phc_plot_escape(title);
    double *lo = malloc(d * sizeof *lo), *hi = malloc(d * sizeof *hi);
    PLFLT *xs = malloc(m * sizeof *xs), *ys = malloc(m * sizeof *ys);
    if (!etitle || !lo || !hi || !xs || !ys) {
        free(etitle);
        free(lo);
        free(hi);
        free(xs);
        free(ys);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t j = 0; j < d; ++j)
        range(draws + j, m, d, &lo[j], &hi[j]);
    const int side = (int)(260 * d + 160);
    phc_atomic_file *af = NULL;
    int old = 0;
    int rc = begin(path, side < 600 ? 600 : side, side < 600 ? 600 : side, &af, &old, err);
    if (rc)
        goto out;
    plschr(0.0, d > 2 ? 0.6 : 0.9);
    const double left = 0.12, right = 0.97, bottom = 0.10, top = 0.93;
    const double gap = 0.015, w = (right - left - gap * (double)(d - 1)) / (double)d,
                 hgt = (top - bottom - gap * (double)(d - 1)) / (double)d;
    for (size_t r = 0; r < d; ++r)
        for (size_t c = 0; c <= r; ++c) {
            const double x0 = left + (double)c * (w + gap), y1 = top - (double)r * (hgt + gap);
            plvpor(x0, x0 + w, y1 - hgt, y1);
            if (r == c) { /* histogram of parameter c */
                size_t count[BINS] = {0}, most = 1;
                const double bw = (hi[c] - lo[c]) / BINS;
                for (size_t i = 0; i < m; ++i) {
                    long b = (long)floor((draws[i * d + c] - lo[c]) / bw);
                    b = b < 0 ? 0 : b >= BINS ? BINS - 1 : b;
                    count[b]++;
                }
                for (int b = 0; b < BINS; ++b)
                    most = count[b] > most ? count[b] : most;
                plwind(lo[c], hi[c], 0, 1.1 * (double)most);
                plcol0(COL_FILL);
                for (int b = 0; b < BINS; ++b) {
                    PLFLT px[4] = {lo[c] + b * bw, lo[c] + (b + 1) * bw, lo[c] + (b + 1) * bw, lo[c] + b * bw};
                    PLFLT py[4] = {0, 0, (double)count[b], (double)count[b]};
                    plfill(4, px, py);
                }
                plcol0(COL_FG);
                plbox(r + 1 == d ? "bcnst" : "bcst", phc_plot_nice_step(hi[c] - lo[c], 2), 0, "bc", 0, 0);
                if (c == 0)
                    plmtex("l", 2.0, 0.5, 0.5, "count");
            } else { /* scatter of c (x) against r (y) */
                plwind(lo[c], hi[c], lo[r], hi[r]);
                size_t k = 0;
                for (size_t i = 0; i < m; i += step, ++k) {
                    xs[k] = draws[i * d + c];
                    ys[k] = draws[i * d + r];
                }
                plcol0(COL_FILL);
                plssym(0, 0.35);
                plpoin((PLINT)k, xs, ys, 17);
                plcol0(COL_FG);
                plbox(r + 1 == d ? "bcnst" : "bcst", phc_plot_nice_step(hi[c] - lo[c], 2), 0,
                      c == 0 ? "bcnstv" : "bcst", phc_plot_nice_step(hi[r] - lo[r], 4), 0);
                if (c == 0) {
                    char *el = phc_plot_escape(labels[r]);
                    plmtex("l", 6.0, 0.5, 0.5, el ? el : "");
                    free(el);
                }
            }
            if (r + 1 == d) {
                char *el = phc_plot_escape(labels[c]);
                plmtex("b", 3.0, 0.5, 0.5, el ? el : "");
                free(el);
            }
        }
    plvpor(left, right, bottom, top);
    plcol0(COL_FG);
    plmtex("t", 1.2, 0.5, 0.5, etitle);
    rc = phc_plot_end(af, old, PHC_OK, err);
out:
    free(etitle);
    free(lo);
    free(hi);
    free(xs);
    free(ys);
    return rc;
}
