/* Profile-likelihood plots: see profile_plots.h.  As in fit/plots.c,
 * everything PLplot could fail on is checked before it sees it. */
#include "fit/profile_plots.h"

#include <math.h>
#include <plplot.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/plot_file.h"

enum { PAGE_W = 1000, PAGE_H = 700 };
enum { COL_BG = 0, COL_FG = 1, COL_GRID = 2, COL_PROF = 3, COL_WALD = 4, COL_THR = 5, COL_EST = 6, COL_N = 7 };

static void widen(double v, double *lo, double *hi)
{
    if (isfinite(v)) {
        *lo = v < *lo ? v : *lo;
        *hi = v > *hi ? v : *hi;
    }
}

int phc_plot_profile(const char *path, const phc_profile_plot *p, phc_error *err)
{
    if (p->n < 2)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: a profile needs 2 points, found %zu", path, p->n);
    double xlo = INFINITY, xhi = -INFINITY, ylo = 0.0, yhi = 1.25 * p->threshold;
    for (size_t i = 0; i < p->n; ++i) {
        widen(p->theta[i], &xlo, &xhi);
        widen(p->delta[i], &ylo, &yhi);
    }
    widen(p->wald_lo, &xlo, &xhi);
    widen(p->wald_hi, &xlo, &xhi);
    if (yhi > 4.0 * p->threshold && p->threshold > 0)
        yhi = 4.0 * p->threshold; /* steep sides: keep the threshold region readable */
    if (!(xhi > xlo)) {
        const double d = fabs(xlo) > 0 ? 0.1 * fabs(xlo) : 1.0;
        xlo -= d;
        xhi += d;
    }
    if (!(yhi > ylo))
        yhi = ylo + 1.0;
    const double xpad = 0.04 * (xhi - xlo), ypad = 0.04 * (yhi - ylo);
    xlo -= xpad;
    xhi += xpad;
    yhi += 0.30 * (yhi - ylo); /* headroom for the legend */
    ylo -= ypad;
    char xlabel[512], title[512];
    snprintf(xlabel, sizeof xlabel, "%s%s%s%s", p->param, p->unit && *p->unit ? " (" : "",
             p->unit && *p->unit ? p->unit : "", p->unit && *p->unit ? ")" : "");
    snprintf(title, sizeof title, "profile likelihood of %s", p->param);
    char *ex = phc_plot_escape(xlabel), *et = phc_plot_escape(title);
    double *xs = malloc(p->n * sizeof *xs), *ys = malloc(p->n * sizeof *ys);
    int rc = PHC_OK;
    if (!ex || !et || !xs || !ys) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    size_t m = 0;
    for (size_t i = 0; i < p->n; ++i)
        if (isfinite(p->theta[i]) && isfinite(p->delta[i])) {
            xs[m] = p->theta[i];
            ys[m] = p->delta[i] < yhi ? p->delta[i] : yhi; /* clip at the frame */
            ++m;
        }
    phc_atomic_file *af = NULL;
    int old = 0;
    if ((rc = phc_plot_begin(path, PAGE_W, PAGE_H, &af, &old, err)))
        goto done;
    static const PLINT rgb[COL_N][3] = {{255, 255, 255}, {0, 0, 0},   {221, 221, 221}, {31, 100, 190},
                                        {230, 97, 1},    {180, 0, 0}, {90, 90, 90}};
    plscmap0n(16);
    for (int i = 0; i < COL_N; ++i)
        plscol0(i, rgb[i][0], rgb[i][1], rgb[i][2]);
    plinit();
    pladv(0);
    plschr(0.0, 1.1);
    plvpor(0.12, 0.97, 0.14, 0.90);
    plwind(xlo, xhi, ylo, yhi);
    plcol0(COL_GRID);
    plbox("g", 0, 0, "g", 0, 0);
    plcol0(COL_FG);
    plbox("bcnst", 0, 0, "bcnstv", 0, 0);
    /* threshold */
    plcol0(COL_THR);
    plwidth(2.0);
    pllsty(2);
    pljoin(xlo, p->threshold, xhi, p->threshold);
    /* Wald interval (dashed orange), profile interval (solid blue) */
    plcol0(COL_WALD);
    pllsty(3);
    if (isfinite(p->wald_lo))
        pljoin(p->wald_lo, ylo, p->wald_lo, yhi);
    if (isfinite(p->wald_hi))
        pljoin(p->wald_hi, ylo, p->wald_hi, yhi);
    pllsty(1);
    plcol0(COL_PROF);
    if (isfinite(p->prof_lo))
        pljoin(p->prof_lo, ylo, p->prof_lo, yhi);
    if (isfinite(p->prof_hi))
        pljoin(p->prof_hi, ylo, p->prof_hi, yhi);
    plcol0(COL_EST);
    plwidth(1.0);
    pllsty(4);
    pljoin(p->estimate, ylo, p->estimate, yhi);
    pllsty(1);
    /* the profile: line and points */
    plcol0(COL_FG);
    plwidth(2.0);
    plline((PLINT)m, xs, ys);
    plwidth(1.0);
    plssym(0.0, 0.8);
    plpoin((PLINT)m, xs, ys, 17);
    plmtex("t", 1.5, 0.5, 0.5, et);
    plmtex("l", 5.5, 0.5, 0.5, "#gD cost = profile cost - best cost");
    plmtex("b", 3.2, 0.5, 0.5, ex);
    char thr_text[128], prof_text[128], wald_text[128];
    snprintf(thr_text, sizeof thr_text, "threshold %.4g (%.0f%% level)", p->threshold, 100.0 * p->level);
    snprintf(prof_text, sizeof prof_text, "profile interval");
    snprintf(wald_text, sizeof wald_text, "%s",
             isfinite(p->wald_lo) && isfinite(p->wald_hi) ? "Wald interval (fit)" : "Wald interval: not determined");
    PLINT opt[5] = {PL_LEGEND_LINE | PL_LEGEND_SYMBOL, PL_LEGEND_LINE, PL_LEGEND_LINE, PL_LEGEND_LINE,
                    PL_LEGEND_LINE};
    PLINT lcol[5] = {COL_FG, COL_THR, COL_PROF, COL_WALD, COL_EST}, lsty[5] = {1, 2, 1, 3, 4};
    PLFLT lw[5] = {2, 2, 2, 2, 1}, ssc[5] = {0.8, 1, 1, 1, 1};
    PLINT scol[5] = {COL_FG, COL_FG, COL_FG, COL_FG, COL_FG}, snum[5] = {1, 1, 1, 1, 1};
    PLINT tcol[5] = {COL_FG, COL_FG, COL_FG, COL_FG, COL_FG};
    const char *syms[5] = {"#(850)", "", "", "", ""};
    const char *texts[5] = {"profile (others re-optimised)", thr_text, prof_text, wald_text, "estimate"};
    PLFLT lwidth, lheight;
    pllegend(&lwidth, &lheight, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             PL_POSITION_TOP | PL_POSITION_RIGHT | PL_POSITION_INSIDE, 0.02, 0.02, 0.1, COL_BG, COL_FG, 1, 0, 0, 5,
             opt, 1.0, 1.0, 2.0, 0.0, tcol, texts, NULL, NULL, NULL, NULL, lcol, lsty, lw, scol, ssc, snum, syms);
    rc = phc_plot_end(af, old, PHC_OK, err);
done:
    free(ex);
    free(et);
    free(xs);
    free(ys);
    return rc;
}
