/* Shared by the notebooks_c programs (one figure each): a small multi-panel
 * line plot with PLplot's pngcairo driver in the style of fit/plots.c (white
 * background, grid, labelled axes with units, legends), and writing the
 * figure's markdown page through a temporary name.  Header-only (static
 * functions) because ctest builds each notebook as its own program. */
#ifndef PHC_NOTEBOOK_PLOT_H
#define PHC_NOTEBOOK_PLOT_H

#include <errno.h>
#include <math.h>
#include <plplot.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- a small multi-panel line plot with PLplot (pngcairo), in the style of
 * fit/plots.c: white background, black frame, light grid, labelled axes with
 * units, a legend, readable fonts.  Local to this notebook (fit/plots.h draws
 * one data set per figure; these figures need several curves per panel). */
enum {
    NB_BG, NB_FG, NB_GRID, NB_BLUE, NB_RED, NB_GREEN, NB_ORANGE, NB_PURPLE,
    NB_BROWN, NB_PINK, NB_GREY, NB_OLIVE, NB_CYAN, NB_BLACK, NB_NCOL
};
#define NB_MAX_SERIES 16
#define NB_CHR 0.85 /* character height scale */
#define NB_LOGX 2   /* flag in nb_panel.logy: log10 x axis (non-positive x skipped) */
#define NB_LOG2X 4  /* flag in nb_panel.logy: log2 x axis fitted to the data, ticks at powers of
                       two (grid sizes 128, 256, ...; non-positive x skipped) */

typedef struct nb_series {
    const double *x, *y;  /* n points; non-finite (or <= 0 on a log axis) skipped */
    size_t n;
    const char *label;    /* legend text; NULL = not in the legend (n = 0: legend only) */
    int color;            /* NB_BLUE ... */
    int dashed;           /* 0 solid, 1 dashed, 2 dotted */
    int markers;          /* 1: markers instead of a line */
    double width;         /* line width (0 = 2.5) */
} nb_series;

typedef struct nb_panel {
    const char *title, *xlab, *ylab;
    int logy;             /* 1: log10 y axis; | NB_LOGX: log10 x axis as well (NB_LOGX alone: x only) */
    double ymin, ymax;    /* both 0: automatic */
    int legend;           /* 0 none, 1 top right, 2 top left, 3 bottom right, 4 bottom left,
                             5 right middle, 6 left middle */
    const nb_series *s;
    size_t ns;
} nb_panel;

static void nb_colours(void)
{
    static const int rgb[NB_NCOL][3] = {
        {255, 255, 255}, {0, 0, 0}, {221, 221, 221}, {31, 100, 190}, {214, 39, 40},
        {44, 160, 44}, {230, 120, 0}, {148, 103, 189}, {140, 86, 75}, {227, 119, 194},
        {110, 110, 110}, {150, 150, 30}, {23, 170, 190}, {0, 0, 0}};
    plscmap0n(16);
    for (int i = 0; i < NB_NCOL; ++i)
        plscol0(i, rgb[i][0], rgb[i][1], rgb[i][2]);
}

static int nb_ok(double v, int logy) { return isfinite(v) && (!logy || v > 0.0); }
static int nb_log2x(const nb_panel *p) { return (p->logy & NB_LOG2X) != 0; }
static int nb_logx(const nb_panel *p) { return (p->logy & (NB_LOGX | NB_LOG2X)) != 0; }
static int nb_logy(const nb_panel *p) { return (p->logy & 1) != 0; }
static double nb_tx(const nb_panel *p, double x) { return nb_log2x(p) ? log2(x) : nb_logx(p) ? log10(x) : x; }

/* Log-axis tick labels (custom labels, so the step can be chosen): y as 10
 * with a superscript exponent; x as the value at the tick (data: the panel). */
static void nb_log_label(PLINT axis, PLFLT value, char *label, PLINT length, PLPointer data)
{
    const nb_panel *p = data;
    if (axis == PL_Y_AXIS)
        snprintf(label, (size_t)length, "10#u%d#d", (int)lround(value));
    else /* only called for a log x axis */
        snprintf(label, (size_t)length, "%g", pow(nb_log2x(p) ? 2.0 : 10.0, value));
}

static void nb_draw_panel(const nb_panel *p, double vx0, double vx1, double vy0, double vy1)
{
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t k = 0; k < p->ns; ++k)
        for (size_t i = 0; i < p->s[k].n; ++i) {
            double x = p->s[k].x[i], y = p->s[k].y[i];
            if (!nb_ok(x, nb_logx(p)) || !nb_ok(y, nb_logy(p)))
                continue;
            x = nb_tx(p, x);
            y = nb_logy(p) ? log10(y) : y;
            xmin = fmin(xmin, x), xmax = fmax(xmax, x);
            ymin = fmin(ymin, y), ymax = fmax(ymax, y);
        }
    int markers = 0;
    for (size_t k = 0; k < p->ns; ++k)
        markers |= p->s[k].markers && p->s[k].n > 0;
    if (!(xmin < xmax))
        xmin -= 1.0, xmax += 1.0;
    if (nb_log2x(p)) {
        /* the powers of two of the data, and room for markers at the ends */
        xmin = floor(xmin + 1e-9) - 0.3, xmax = ceil(xmax - 1e-9) + 0.3;
    } else if (nb_logx(p)) {
        xmin = floor(xmin), xmax = ceil(xmax);
    } else if (markers) {
        /* markers at the first and last x stay whole inside the frame */
        double pad = 0.025 * (xmax - xmin);
        xmin -= pad, xmax += pad;
    }
    if (p->ymin != 0.0 || p->ymax != 0.0) {
        ymin = nb_logy(p) ? log10(p->ymin) : p->ymin;
        ymax = nb_logy(p) ? log10(p->ymax) : p->ymax;
    } else if (nb_logy(p)) {
        ymin = floor(ymin), ymax = ceil(ymax);
        if (ymin == ymax)
            ymin -= 1.0;
    } else {
        if (!(ymin < ymax))
            ymin -= 1.0, ymax += 1.0;
        double pad = 0.05 * (ymax - ymin);
        ymin -= pad, ymax += pad;
    }
    plvpor(vx0, vx1, vy0, vy1);
    plwind(xmin, xmax, ymin, ymax);
    plcol0(NB_GRID);
    plwidth(1.0);
    pllsty(1);
    double ystep = nb_logy(p) ? (ymax - ymin > 8.0 ? 2.0 : 1.0) : 0.0;
    plbox("g", nb_logx(p) ? 1.0 : 0.0, nb_log2x(p) ? 1 : 0, "g", ystep, 0);
    const char *lab[NB_MAX_SERIES];
    PLINT opt[NB_MAX_SERIES], col[NB_MAX_SERIES], sty[NB_MAX_SERIES], tcol[NB_MAX_SERIES];
    PLINT snum[NB_MAX_SERIES];
    PLFLT wid[NB_MAX_SERIES], ssc[NB_MAX_SERIES];
    const char *sym[NB_MAX_SERIES];
    int nl = 0;
    for (size_t k = 0; k < p->ns; ++k) {
        const nb_series *s = &p->s[k];
        PLINT style = s->dashed == 1 ? 3 : s->dashed == 2 ? 2 : 1;
        double w = s->width > 0.0 ? s->width : 2.5;
        plcol0(s->color);
        pllsty(style);
        plwidth(w);
        PLFLT *px = malloc((s->n + 1) * sizeof *px), *py = malloc((s->n + 1) * sizeof *py);
        if (!px || !py) {
            free(px), free(py);
            continue;
        }
        size_t m = 0;
        for (size_t i = 0; i <= s->n; ++i) {
            int good = i < s->n && nb_ok(s->x[i], nb_logx(p)) && nb_ok(s->y[i], nb_logy(p));
            if (good) {
                px[m] = nb_tx(p, s->x[i]);
                py[m] = nb_logy(p) ? log10(s->y[i]) : s->y[i];
                ++m;
            }
            if ((!good || i == s->n) && m > 0) {
                if (s->markers) {
                    plschr(0.0, 0.7 * NB_CHR);
                    plstring((PLINT)m, px, py, "\xe2\x97\x8f");
                    plschr(0.0, NB_CHR);
                } else if (m > 1) {
                    plline((PLINT)m, px, py);
                }
                m = 0;
            }
        }
        free(px), free(py);
        if (s->label && nl < NB_MAX_SERIES) {
            lab[nl] = s->label;
            opt[nl] = s->markers ? PL_LEGEND_SYMBOL : PL_LEGEND_LINE;
            col[nl] = s->color;
            tcol[nl] = NB_FG;
            sty[nl] = style;
            wid[nl] = w;
            ssc[nl] = 0.7 * NB_CHR; /* as plotted: pllegend sizes symbols by plschr(0, ssc) */
            snum[nl] = 1;
            sym[nl] = "\xe2\x97\x8f";
            ++nl;
        }
    }
    pllsty(1);
    plwidth(1.2);
    plcol0(NB_FG);
    if (p->logy)
        plslabelfunc(nb_log_label, (PLPointer)p);
    plbox(nb_log2x(p) ? "bcnsto" : nb_logx(p) ? "bcnstlo" : "bcnst", nb_logx(p) ? 1.0 : 0.0, nb_log2x(p) ? 1 : 0,
          nb_logy(p) ? "bcnstvo" : "bcnstv", ystep, nb_logy(p) ? (int)ystep : 0);
    plslabelfunc(NULL, NULL);
    plmtex("b", 3.0, 0.5, 0.5, p->xlab);
    plmtex("l", nb_logy(p) ? 4.6 : 4.2, 0.5, 0.5, p->ylab);
    if (p->title) {
        plschr(0.0, 1.1 * NB_CHR);
        plmtex("t", 2.0, 0.5, 0.5, p->title);
        plschr(0.0, NB_CHR);
    }
    if (p->legend && nl > 0) {
        static const PLINT where[7] = {0, PL_POSITION_TOP | PL_POSITION_RIGHT,
                                       PL_POSITION_TOP | PL_POSITION_LEFT,
                                       PL_POSITION_BOTTOM | PL_POSITION_RIGHT,
                                       PL_POSITION_BOTTOM | PL_POSITION_LEFT,
                                       PL_POSITION_RIGHT, PL_POSITION_LEFT};
        PLFLT lw, lh;
        PLINT zero[NB_MAX_SERIES] = {0};
        PLFLT one[NB_MAX_SERIES];
        for (int i = 0; i < nl; ++i)
            one[i] = 1.0;
        pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
                 where[p->legend] | PL_POSITION_INSIDE | PL_POSITION_VIEWPORT, 0.02, 0.03, 0.06,
                 NB_BG, NB_FG, 1, 0, 0, nl, opt, 0.7, 0.7, 1.5, 0.0, tcol, lab, col, zero, one,
                 one, col, sty, wid, col, ssc, snum, sym);
    }
}

/* Draws np panels on a cols x rows grid into a width x height PNG at path
 * (written to path.tmp, then renamed).  Returns 0 or -1. */
__attribute__((unused)) static int nb_plot(const char *path, int width, int height, int cols, int rows,
                   const nb_panel *panels, size_t np)
{
    char tmp[1040];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    PLINT old;
    plgstrm(&old);
    PLINT strm;
    plmkstrm(&strm);
    if (strm < 0)
        return -1;
    plsdev("pngcairo");
    plsfnam(tmp);
    plspage(0.0, 0.0, width, height, 0, 0);
    nb_colours();
    plinit();
    pladv(0);
    plschr(0.0, NB_CHR);
    /* one character height as a fraction of the page height: the margins
       above and below a panel hold its title and its x axis (tick labels,
       label) whatever the page size, so stacked panels do not collide */
    PLFLT def_ht, ch_ht, sx0, sx1, sy0, sy1;
    plgchr(&def_ht, &ch_ht);
    plgspa(&sx0, &sx1, &sy0, &sy1);
    const double chy = sy1 > sy0 ? ch_ht / (sy1 - sy0) : 0.03;
    for (size_t k = 0; k < np; ++k) {
        int c = (int)(k % (size_t)cols), r = (int)(k / (size_t)cols);
        double cw = 1.0 / cols, chh = 1.0 / rows;
        double x0 = c * cw, y1 = 1.0 - r * chh;
        /* margins: 120 px left for tick labels and the y label; the x
           label's centre is 3 character heights below the frame, the
           title's 2 above it */
        double vx0 = x0 + 120.0 / width, vx1 = x0 + cw - 35.0 / width;
        double vy0 = y1 - chh + fmax(80.0 / height, 4.3 * chy), vy1 = y1 - fmax(60.0 / height, 3.3 * chy);
        nb_draw_panel(&panels[k], vx0, vx1, vy0, vy1);
    }
    plend1();
    plsstrm(old);
    if (rename(tmp, path) != 0) {
        unlink(tmp);
        return -1;
    }
    return 0;
}
/* ---- end of the plot helper ---------------------------------------------- */
/* mkdir -p; 0 or -1. */
static int nb_mkdirs(const char *dir)
{
    char buf[1024];
    size_t len = strlen(dir);
    if (len == 0 || len >= sizeof buf)
        return -1;
    memcpy(buf, dir, len + 1);
    for (size_t i = 1; i <= len; ++i) {
        if (buf[i] == '/' || buf[i] == '\0') {
            char c = buf[i];
            buf[i] = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            buf[i] = c;
        }
    }
    return 0;
}

/* Opens dir/name for writing through a temporary name; nb_close_md renames it. */
__attribute__((unused)) static FILE *nb_open_md(const char *dir, const char *name, char *final, char *tmp, size_t cap)
{
    snprintf(final, cap, "%s/%s", dir, name);
    snprintf(tmp, cap, "%s/%s.tmp", dir, name);
    return fopen(tmp, "w");
}

__attribute__((unused)) static int nb_close_md(FILE *f, const char *final, const char *tmp)
{
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, final) != 0) {
        unlink(tmp);
        return -1;
    }
    return 0;
}

/* The notebooks' common start: the usage check, the skip (exit 77) when a
 * real-data file is absent, and the output directory argv[1] (created).
 * Returns 0 to go on with *out set, otherwise the exit code to return. */
static int nb_begin(int argc, char **argv, const char *data_file, const char **out)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
        return 2;
    }
    *out = argv[1];
    struct stat st;
    if (data_file && stat(data_file, &st) != 0) {
        printf("skipped: %s is absent (the real-data folder ../shared/data is not here)\n", data_file);
        return 77;
    }
    if (nb_mkdirs(*out) != 0) {
        fprintf(stderr, "%s: cannot create the output directory: %s\n", *out, strerror(errno));
        return 1;
    }
    return 0;
}

#endif /* PHC_NOTEBOOK_PLOT_H */
