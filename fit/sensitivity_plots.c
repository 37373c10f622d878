/* Bar plots of sensitivity studies: see sensitivity_plots.h.  As in
 * fit/plots.c, everything PLplot could fail on (the device, the file, an
 * empty axis range) is checked before PLplot sees it, since its fatal errors
 * exit the process. */
#include "fit/sensitivity_plots.h"

#include <math.h>
#include <plplot.h>
#include <stdlib.h>
#include <string.h>

#include "fit/plot_file.h"

enum { PAGE_W = 1000, PAGE_H = 700 };
enum { COL_BG = 0, COL_FG = 1, COL_GRID = 2, COL_S0 = 3, COL_S1 = 4, COL_WHISKER = 5, COL_N = 6 };

int phc_plot_bars(const char *path, const char *title, const char *y_label, const char *const *factors,
                  size_t n_factors, const phc_bar_series *series, size_t n_series, phc_error *err)
{
    if (n_factors == 0 || n_series == 0 || n_series > 2)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: %zu factors, %zu series", path, n_factors, n_series);
    double lo = 0, hi = 0;
    for (size_t s = 0; s < n_series; ++s)
        for (size_t i = 0; i < n_factors; ++i) {
            const double v[3] = {series[s].value[i], series[s].lo ? series[s].lo[i] : NAN,
                                 series[s].hi ? series[s].hi[i] : NAN};
            for (int q = 0; q < 3; ++q)
                if (isfinite(v[q])) {
                    lo = v[q] < lo ? v[q] : lo;
                    hi = v[q] > hi ? v[q] : hi;
                }
        }
    if (!(hi > lo))
        hi = lo + 1;
    const double pad = 0.08 * (hi - lo);
    hi += 0.40 * (hi - lo); /* headroom: the legend sits above the tallest bar */
    if (lo < 0)
        lo -= pad;
    char *etitle = phc_plot_escape(title), *ey = phc_plot_escape(y_label);
    char **enames = calloc(n_factors, sizeof *enames);
    char *elabel[2] = {NULL, NULL};
    int rc = PHC_OK;
    if (!etitle || !ey || !enames) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n_factors; ++i)
        if (!(enames[i] = phc_plot_escape(factors[i]))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    for (size_t s = 0; s < n_series; ++s)
        if (!(elabel[s] = phc_plot_escape(series[s].label))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    phc_atomic_file *af = NULL;
    int old = 0;
    if ((rc = phc_plot_begin(path, PAGE_W, PAGE_H, &af, &old, err)))
        goto done;
    static const PLINT rgb[COL_N][3] = {{255, 255, 255}, {0, 0, 0},      {221, 221, 221},
                                        {31, 100, 190},  {230, 97, 1},   {40, 40, 40}};
    plscmap0n(16);
    for (int i = 0; i < COL_N; ++i)
        plscol0(i, rgb[i][0], rgb[i][1], rgb[i][2]);
    plinit();
    pladv(0);
    plschr(0.0, 1.1);
    /* room below for the factor names, written at 45 degrees when many */
    const int slanted = n_factors > 6;
    plvpor(0.12, 0.97, slanted ? 0.26 : 0.16, 0.90);
    plwind(-0.6, (double)n_factors - 0.4, lo, hi);
    plcol0(COL_GRID);
    plbox("", 0, 0, "g", 0, 0);
    plcol0(COL_FG);
    plbox("bc", 0, 0, "bcnstv", 0, 0);
    if (lo < 0)
        pljoin(-0.6, 0, (double)n_factors - 0.4, 0);
    const double width = 0.8 / (double)n_series;
    for (size_t s = 0; s < n_series; ++s) {
        for (size_t i = 0; i < n_factors; ++i) {
            const double x0 = (double)i - 0.4 + width * (double)s, x1 = x0 + width * 0.92;
            const double v = series[s].value[i];
            if (isfinite(v)) {
                PLFLT px[4] = {x0, x1, x1, x0}, py[4] = {0, 0, v, v};
                plcol0(s ? COL_S1 : COL_S0);
                plfill(4, px, py);
            }
            if (series[s].lo && series[s].hi && isfinite(series[s].lo[i]) && isfinite(series[s].hi[i])) {
                const double xm = 0.5 * (x0 + x1), cap = 0.15 * width;
                plcol0(COL_WHISKER);
                plwidth(2.0);
                pljoin(xm, series[s].lo[i], xm, series[s].hi[i]);
                pljoin(xm - cap, series[s].lo[i], xm + cap, series[s].lo[i]);
                pljoin(xm - cap, series[s].hi[i], xm + cap, series[s].hi[i]);
                plwidth(1.0);
            }
        }
    }
    plcol0(COL_FG);
    for (size_t i = 0; i < n_factors; ++i) {
        /* names under their bars: across when few, upright when many */
        const double pos = ((double)i + 0.6) / (double)n_factors;
        if (slanted)
            plmtex("bv", 0.8, pos, 1.0, enames[i]);
        else
            plmtex("b", 1.6, pos, 0.5, enames[i]);
    }
    plmtex("t", 1.5, 0.5, 0.5, etitle);
    plmtex("l", 5.5, 0.5, 0.5, ey);
    plmtex("b", slanted ? 11.0 : 3.6, 0.5, 0.5, "factor");
    /* legend: filled boxes; the whiskers are the 95% intervals */
    PLINT opt[3], colours[3], fill_styles[3] = {0, 0, 0}, lcol[3] = {COL_FG, COL_FG, COL_FG},
          lsty[3] = {1, 1, 1};
    PLFLT fscale[3] = {1, 1, 1}, lw[3] = {1, 1, 1};
    PLINT tcol[3] = {COL_FG, COL_FG, COL_FG};
    const char *texts[3];
    PLFLT lwidth, lheight;
    size_t nl = 0;
    for (size_t s = 0; s < n_series; ++s, ++nl) {
        opt[nl] = PL_LEGEND_COLOR_BOX;
        colours[nl] = s ? COL_S1 : COL_S0;
        texts[nl] = elabel[s];
    }
    opt[nl] = PL_LEGEND_LINE;
    colours[nl] = COL_WHISKER;
    lcol[nl] = COL_WHISKER;
    lw[nl] = 2;
    texts[nl] = "95% bootstrap interval";
    ++nl;
    pllegend(&lwidth, &lheight, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             PL_POSITION_TOP | PL_POSITION_RIGHT | PL_POSITION_INSIDE, 0.02, 0.02, 0.1, COL_BG, COL_FG, 1, 0, 0,
             (PLINT)nl, opt, 1.0, 1.0, 2.0, 0.0, tcol, (const char *const *)texts, colours, fill_styles, fscale,
             lw, lcol, lsty, lw, NULL, NULL, NULL, NULL);
    rc = phc_plot_end(af, old, PHC_OK, err);
done:
    free(etitle);
    free(ey);
    if (enames)
        for (size_t i = 0; i < n_factors; ++i)
            free(enames[i]);
    free(enames);
    free(elabel[0]);
    free(elabel[1]);
    return rc;
}

/* ---- indices against x ---------------------------------------------------------------------------- */

enum { LCOL_BG = 0, LCOL_FG = 1, LCOL_GRID = 2, LCOL_LINE0 = 3, N_LINE_COLOURS = 8 };

int phc_plot_index_lines(const char *path, const char *title, const char *x_label, const double *x, size_t n,
                         const char *const *y_labels, size_t n_panels, const phc_band_line *lines, size_t n_lines,
                         phc_error *err)
{
    if (n == 0 || n_lines == 0 || n_panels == 0 || n_panels > 2)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: %zu points, %zu lines, %zu panels", path, n, n_lines,
                             n_panels);
    double x0 = INFINITY, x1 = -INFINITY;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(x[i])) {
            x0 = x[i] < x0 ? x[i] : x0;
            x1 = x[i] > x1 ? x[i] : x1;
        }
    if (!(x1 >= x0))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: no finite x", path);
    if (!(x1 > x0)) {
        x0 -= 0.5;
        x1 += 0.5;
    }
    char *etitle = phc_plot_escape(title), *ex = phc_plot_escape(x_label);
    char *ey[2] = {NULL, NULL};
    char **enames = calloc(n_lines, sizeof *enames);
    int rc = PHC_OK;
    if (!etitle || !ex || !enames) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t q = 0; q < n_panels; ++q)
        if (!(ey[q] = phc_plot_escape(y_labels[q]))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    for (size_t i = 0; i < n_lines; ++i)
        if (!(enames[i] = phc_plot_escape(lines[i].label))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    phc_atomic_file *af = NULL;
    int old = 0;
    if ((rc = phc_plot_begin(path, 1100, n_panels == 2 ? 900 : PAGE_H, &af, &old, err)))
        goto done;
    /* colour-blind-safe line colours (Okabe & Ito 2008), in 0 .. 15 with a
       translucent copy of each for its band at +8 */
    static const PLINT rgb[N_LINE_COLOURS][3] = {{0, 114, 178}, {213, 94, 0},   {0, 158, 115}, {204, 121, 167},
                                                 {230, 159, 0}, {86, 180, 233}, {0, 0, 0},     {240, 228, 66}};
    plscmap0n(3 + 2 * N_LINE_COLOURS);
    plscol0(LCOL_BG, 255, 255, 255);
    plscol0(LCOL_FG, 0, 0, 0);
    plscol0(LCOL_GRID, 221, 221, 221);
    for (int i = 0; i < N_LINE_COLOURS; ++i) {
        plscol0(LCOL_LINE0 + i, rgb[i][0], rgb[i][1], rgb[i][2]);
        plscol0a(LCOL_LINE0 + N_LINE_COLOURS + i, rgb[i][0], rgb[i][1], rgb[i][2], 0.18);
    }
    plinit();
    pladv(0);
    plschr(0.0, 1.0);
    const double top = 0.90, bottom = 0.10, gap = 0.07, right = 0.78;
    const double h = (top - bottom - gap * (double)(n_panels - 1)) / (double)n_panels;
    for (size_t q = 0; q < n_panels; ++q) {
        const double ytop = top - (double)q * (h + gap);
        double lo = 0, hi = 1; /* indices: 0 .. 1 unless the estimates leave it */
        for (size_t i = 0; i < n_lines; ++i) {
            const phc_band_line *L = &lines[q * n_lines + i];
            for (size_t t = 0; t < n; ++t) {
                const double v[3] = {L->value[t], L->lo ? L->lo[t] : NAN, L->hi ? L->hi[t] : NAN};
                for (int k = 0; k < 3; ++k)
                    if (isfinite(v[k])) {
                        lo = v[k] < lo ? v[k] : lo;
                        hi = v[k] > hi ? v[k] : hi;
                    }
            }
        }
        const double pad = 0.04 * (hi - lo);
        plvpor(0.09, right, ytop - h, ytop);
        plwind(x0, x1, lo - (lo < 0 ? pad : 0), hi + pad);
        plcol0(LCOL_GRID);
        plbox("g", 0, 0, "g", 0, 0);
        plcol0(LCOL_FG);
        plbox("bcnst", 0, 0, "bcnstv", 0, 0);
        if (lo < 0)
            pljoin(x0, 0, x1, 0);
        for (size_t i = 0; i < n_lines; ++i) {
            const phc_band_line *L = &lines[q * n_lines + i];
            const int colour = (int)(i % N_LINE_COLOURS);
            /* runs of finite points with increasing x: one band and one line each */
            for (size_t a = 0; a < n;) {
                size_t b = a;
                while (b < n && isfinite(L->value[b]) && isfinite(x[b]) && (b == a || x[b] >= x[b - 1]))
                    ++b;
                if (b == a) {
                    ++a;
                    continue;
                }
                const size_t len = b - a;
                PLFLT *px = malloc(2 * len * sizeof *px), *py = malloc(2 * len * sizeof *py);
                if (px && py) {
                    int band = L->lo && L->hi;
                    for (size_t t = a; t < b && band; ++t)
                        band = isfinite(L->lo[t]) && isfinite(L->hi[t]);
                    if (band && len > 1) {
                        for (size_t t = 0; t < len; ++t) {
                            px[t] = x[a + t];
                            py[t] = L->hi[a + t];
                            px[2 * len - 1 - t] = x[a + t];
                            py[2 * len - 1 - t] = L->lo[a + t];
                        }
                        plcol0(LCOL_LINE0 + N_LINE_COLOURS + colour);
                        plfill((PLINT)(2 * len), px, py);
                    }
                    for (size_t t = 0; t < len; ++t) {
                        px[t] = x[a + t];
                        py[t] = L->value[a + t];
                    }
                    plcol0(LCOL_LINE0 + colour);
                    plwidth(2.0);
                    if (len > 1)
                        plline((PLINT)len, px, py);
                    else
                        plsym(1, px, py, 904);
                    plwidth(1.0);
                }
                free(px);
                free(py);
                a = b;
            }
        }
        plcol0(LCOL_FG);
        plmtex("l", 4.0, 0.5, 0.5, ey[q]);
        if (q + 1 == n_panels)
            plmtex("b", 3.0, 0.5, 0.5, ex);
    }
    /* legend: one entry per factor, right of the panels */
    PLINT *opt = malloc(n_lines * sizeof *opt), *lcol = malloc(n_lines * sizeof *lcol),
          *lsty = malloc(n_lines * sizeof *lsty), *tcol = malloc(n_lines * sizeof *tcol),
          *bcol = malloc(n_lines * sizeof *bcol), *bpat = malloc(n_lines * sizeof *bpat);
    PLFLT *lw = malloc(n_lines * sizeof *lw), *bscale = malloc(n_lines * sizeof *bscale);
    if (opt && lcol && lsty && tcol && bcol && bpat && lw && bscale) {
        for (size_t i = 0; i < n_lines; ++i) {
            opt[i] = PL_LEGEND_LINE;
            lcol[i] = LCOL_LINE0 + (PLINT)(i % N_LINE_COLOURS);
            lsty[i] = 1;
            tcol[i] = LCOL_FG;
            bcol[i] = lcol[i];
            bpat[i] = 0;
            lw[i] = 3;
            bscale[i] = 1;
        }
        PLFLT lwidth, lheight;
        plvpor(right + 0.02, 0.99, bottom, top);
        plwind(0, 1, 0, 1);
        pllegend(&lwidth, &lheight, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
                 PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.0, 0.0, 0.1, LCOL_BG, LCOL_FG, 1, 0,
                 0, (PLINT)n_lines, opt, 1.0, 1.0, 2.0, 0.0, tcol, (const char *const *)enames, bcol, bpat, bscale,
                 lw, lcol, lsty, lw, NULL, NULL, NULL, NULL);
        plcol0(LCOL_FG);
        plschr(0.0, 0.8);
        plptex(0.02, 1.0 - lheight - 0.04, 1, 0, 0, "shaded: 95%");
        plptex(0.02, 1.0 - lheight - 0.08, 1, 0, 0, "bootstrap interval");
    }
    free(opt);
    free(lcol);
    free(lsty);
    free(tcol);
    free(bcol);
    free(bpat);
    free(lw);
    free(bscale);
    /* the title across the page */
    plvpor(0.02, 0.98, top, 0.99);
    plwind(0, 1, 0, 1);
    plcol0(LCOL_FG);
    plschr(0.0, 0.9);
    plptex(0.5, 0.45, 1, 0, 0.5, etitle);
    rc = phc_plot_end(af, old, PHC_OK, err);
done:
    free(etitle);
    free(ex);
    free(ey[0]);
    free(ey[1]);
    if (enames)
        for (size_t i = 0; i < n_lines; ++i)
            free(enames[i]);
    free(enames);
    return rc;
}
