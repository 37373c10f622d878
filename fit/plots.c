/* Diagnostic plots of a fit with PLplot's pngcairo driver: see plots.h.
 *
 * How each call stays self-contained and safe:
 * - It makes its own PLplot stream (plmkstrm) and ends it (plend1), then
 *   restores the caller's current stream, so nothing survives the call and
 *   a program that draws its own PLplot figures is not disturbed.
 * - PLplot's fatal errors call plexit(), which prints to stderr and calls
 *   exit() even when a plsexit() handler is installed (PLplot 5.15
 *   src/plctrl.c: the handler only chooses the exit status; escaping needs a
 *   longjmp out of PLplot, which leaves the library in an undefined state).
 *   So everything that could make PLplot fail is checked before PLplot sees
 *   it: the device exists (an unknown device makes plinit prompt on stdin),
 *   the output file can be created (an unopenable file makes PLplot ask for a
 *   new name on stdout), every axis range is finite and non-empty (plwind
 *   and plbox reject empty windows).
 * - The PNG is written to a temporary file next to `path` (created by us
 *   with O_EXCL, so the directory is known to be writable), checked for the
 *   PNG signature and renamed into place (DESIGN.md §3).
 *
 * Caller text is plain text: PLplot's escape character '#' is doubled so a
 * label such as "run #3" prints as written; UTF-8 (±, σ, µ, °) renders
 * through cairo/pango. */
#include "fit/plots.h"
#include "fit/plot_file.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gsl/gsl_cdf.h>
#include <plplot.h>

/* Output size in pixels (plots.h). */
enum { PAGE_W = 1000, PAGE_H = 700 };

/* Colour map 0 slots used here. */
enum {
    COL_BG = 0,    /* white background */
    COL_FG = 1,    /* black axes, text */
    COL_GRID = 2,  /* light grey grid */
    COL_DATA = 3,  /* blue data markers, bars */
    COL_FIT = 4,   /* red fit line / reference lines */
    COL_REF = 5,   /* dark grey zero line */
    COL_BAND = 6,  /* orange-red dashed bands */
    COL_EBAR = 7,  /* lighter blue error bars */
    COL_COUNT = 8
};

/* Character height scale (PLplot's default ~ 10 px is too small on a
 * 1000-pixel-wide image). */
static const double CHAR_SCALE = 1.1;
static const double TITLE_SCALE = 1.2;   /* relative to CHAR_SCALE */
static const double MARKER_SCALE = 0.6;  /* marker glyph, relative */
/* Filled circle marker (U+25CF), drawn with plstring so the legend can use
 * the very same glyph. */
static const char MARKER[] = "\xe2\x97\x8f";

#define MAX_LEGEND 4

typedef struct plot_window {
    double xmin, xmax, ymin, ymax;
} plot_window;

/* Tick spacing and label format of one axis. */
typedef struct axis_ticks {
    double step;   /* major tick interval (1, 2 or 5 x 10^k), world units */
    PLINT nsub;    /* minor intervals per major one */
    double maxabs; /* largest |value| on the axis, chooses the format */
} axis_ticks;

typedef struct plot_axes {
    axis_ticks x, y;
} plot_axes;

/* One legend entry. */
typedef struct legend_entry {
    PLINT opt;          /* PL_LEGEND_LINE / _SYMBOL / _COLOR_BOX */
    const char *text;   /* already PLplot-escaped */
    PLINT color;
    PLINT line_style;   /* pllsty number */
    double line_width;
} legend_entry;

typedef struct legend_spec {
    int n;
    legend_entry e[MAX_LEGEND];
} legend_spec;

/* Legend placement: score the four inside corners by how many plotted
 * elements fall into a box of the legend's estimated size there. */
typedef struct legend_boxes {
    double w, h;      /* legend size in viewport fractions, with padding */
    long hits[4];     /* 0 top-right, 1 top-left, 2 bottom-right, 3 bottom-left */
} legend_boxes;

/* ------------------------------------------------------------------ */
/* Small helpers                                                        */

static void legend_add(legend_spec *lg, PLINT opt, const char *text,
                       PLINT color, PLINT line_style, double line_width)
{
    if (lg->n >= MAX_LEGEND)
        return;
    legend_entry *e = &lg->e[lg->n++];
    e->opt = opt;
    e->text = text;
    e->color = color;
    e->line_style = line_style;
    e->line_width = line_width;
}


/* Number of characters (UTF-8 code points) in s, for width estimates. */
static size_t utf8_length(const char *s)
{
    size_t n = 0;
    for (; *s; ++s)
        n += ((unsigned char)*s & 0xC0) != 0x80;
    return n;
}

static void range_add(double *lo, double *hi, double v)
{
    if (!isfinite(v))
        return;
    if (v < *lo)
        *lo = v;
    if (v > *hi)
        *hi = v;
}

/* Pads [lo, hi] by `frac` of its width on each side; widens a degenerate
 * range (one value, or values equal to ~12 digits) around its centre.
 * Returns 0, or -1 when no finite value was seen or the result overflows. */
static int range_pad(double *lo, double *hi, double frac)
{
    double a = *lo, b = *hi;
    if (!(a <= b) || !isfinite(a) || !isfinite(b))
        return -1;
    double mag = fmax(fabs(a), fabs(b));
    double span = b - a;
    if (!isfinite(span))
        return -1;
    if (span <= 1e-12 * mag || span == 0.0) {
        double c = 0.5 * a + 0.5 * b;
        double half = fabs(c) > 0.0 ? 0.1 * fabs(c) : 1.0;
        a = c - half;
        b = c + half;
        span = b - a;
    }
    a -= frac * span;
    b += frac * span;
    if (!isfinite(a) || !isfinite(b) || !(b > a))
        return -1;
    *lo = a;
    *hi = b;
    return 0;
}

/* Liang–Barsky: does the segment (x0,y0)-(x1,y1) meet the box? */
static int segment_hits_box(double x0, double y0, double x1, double y1,
                            double bx0, double bx1, double by0, double by1)
{
    double t0 = 0.0, t1 = 1.0;
    double dx = x1 - x0, dy = y1 - y0;
    double p[4] = {-dx, dx, -dy, dy};
    double q[4] = {x0 - bx0, bx1 - x0, y0 - by0, by1 - y0};
    for (int i = 0; i < 4; ++i) {
        if (p[i] == 0.0) {
            if (q[i] < 0.0)
                return 0;
        } else {
            double t = q[i] / p[i];
            if (p[i] < 0.0) {
                if (t > t1)
                    return 0;
                if (t > t0)
                    t0 = t;
            } else {
                if (t < t0)
                    return 0;
                if (t < t1)
                    t1 = t;
            }
        }
    }
    return 1;
}

/* Scores a segment in world coordinates against the four corner boxes. */
static void legend_score_segment(legend_boxes *lb, const plot_window *w,
                                 double x0, double y0, double x1, double y1)
{
    if (!isfinite(x0) || !isfinite(y0) || !isfinite(x1) || !isfinite(y1))
        return;
    double sx = w->xmax - w->xmin, sy = w->ymax - w->ymin;
    double fx0 = (x0 - w->xmin) / sx, fx1 = (x1 - w->xmin) / sx;
    double fy0 = (y0 - w->ymin) / sy, fy1 = (y1 - w->ymin) / sy;
    for (int c = 0; c < 4; ++c) {
        double bx0 = (c == 0 || c == 2) ? 1.0 - lb->w : 0.0;
        double by0 = (c < 2) ? 1.0 - lb->h : 0.0;
        if (segment_hits_box(fx0, fy0, fx1, fy1, bx0, bx0 + lb->w, by0,
                             by0 + lb->h))
            ++lb->hits[c];
    }
}

static void legend_score_point(legend_boxes *lb, const plot_window *w,
                               double x, double y)
{
    legend_score_segment(lb, w, x, y, x, y);
}

/* ------------------------------------------------------------------ */
/* Stream set-up and tear-down                                          */

typedef struct plot_ctx {
    PLINT old_stream;
    PLINT stream;        /* -1 when none was made */
    char *tmp_path;      /* temporary output file, NULL when none */
    double page_fx, page_fy; /* one character height as a page fraction */
    double ch_fx, ch_fy;     /* ... and as a viewport fraction */
    double ylab_disp;        /* y label distance from the frame (chars) */
} plot_ctx;



/* Opens a PLplot stream writing a PNG of PAGE_W x PAGE_H pixels to a
 * temporary file; on success ctx->page_f* hold the character height as a
 * fraction of the page.  The viewport is set later by plot_layout(). */
static int plot_begin(plot_ctx *ctx, const char *path, phc_error *err)
{
    ctx->stream = -1;
    ctx->tmp_path = NULL;
    plgstrm(&ctx->old_stream);

    int dev = phc_plot_device_available("pngcairo");
    if (dev < 0)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    if (dev == 0)
        return phc_error_set(err, PHC_ERR_INTERNAL,
                             "%s: PLplot has no 'pngcairo' device "
                             "(install plplot-driver-cairo)", path);

    int status = phc_plot_temp_file(path, &ctx->tmp_path, err);
    if (status)
        return status;

    PLINT strm = -1;
    plmkstrm(&strm);
    if (strm < 0) {
        plsstrm(ctx->old_stream);
        unlink(ctx->tmp_path);
        free(ctx->tmp_path);
        ctx->tmp_path = NULL;
        return phc_error_set(err, PHC_ERR_INTERNAL,
                             "%s: no free PLplot stream", path);
    }
    ctx->stream = strm;

    plsdev("pngcairo");
    plsfnam(ctx->tmp_path);
    plspage(0.0, 0.0, PAGE_W, PAGE_H, 0, 0);
    plsfam(0, 0, 0);

    /* White background, black foreground (PLplot defaults to black). */
    static const PLINT rgb[COL_COUNT][3] = {
        {255, 255, 255}, /* COL_BG */
        {0, 0, 0},       /* COL_FG */
        {221, 221, 221}, /* COL_GRID */
        {31, 100, 190},  /* COL_DATA */
        {214, 39, 40},   /* COL_FIT */
        {90, 90, 90},    /* COL_REF */
        {230, 97, 1},    /* COL_BAND */
        {120, 160, 215}, /* COL_EBAR */
    };
    plscmap0n(16);
    for (int i = 0; i < COL_COUNT; ++i)
        plscol0(i, rgb[i][0], rgb[i][1], rgb[i][2]);

    plinit();
    pladv(0);
    plschr(0.0, CHAR_SCALE);

    PLFLT def, ht, sx0, sx1, sy0, sy1;
    plgchr(&def, &ht);
    plgspa(&sx0, &sx1, &sy0, &sy1);
    ctx->page_fx = (sx1 > sx0) ? ht / (sx1 - sx0) : 0.02;
    ctx->page_fy = (sy1 > sy0) ? ht / (sy1 - sy0) : 0.03;
    return PHC_OK;
}

/* Ends the stream, checks the file and renames it to `path` when status is
 * PHC_OK; removes the temporary file otherwise.  Returns the final status. */
static int plot_end(plot_ctx *ctx, const char *path, int status,
                    phc_error *err)
{
    if (ctx->stream >= 0) {
        plsstrm(ctx->stream);
        plend1();
        plsstrm(ctx->old_stream);
        ctx->stream = -1;
    }
    if (!ctx->tmp_path)
        return status;
    if (status == PHC_OK) {
        int ok = phc_plot_png_complete(ctx->tmp_path);
        if (!ok)
            status = phc_error_set(err, PHC_ERR_IO,
                                   "%s: PLplot did not write a complete PNG "
                                   "file (disk full?)", path);
        else if (rename(ctx->tmp_path, path) != 0)
            status = phc_error_set(err, PHC_ERR_IO, "%s: cannot rename "
                                   "the temporary plot file into place: %s",
                                   path, strerror(errno));
    }
    if (status != PHC_OK)
        unlink(ctx->tmp_path);
    free(ctx->tmp_path);
    ctx->tmp_path = NULL;
    return status;
}

/* ------------------------------------------------------------------ */
/* Ticks and tick labels                                                */

/* A major tick interval of 1, 2 or 5 x 10^k giving about 6 intervals over
 * [lo, hi]; min_step > 0 imposes a floor (integer lags). */
static axis_ticks ticks_make(double lo, double hi, double min_step)
{
    axis_ticks t;
    double raw = (hi - lo) / 6.0;
    double p = pow(10.0, floor(log10(raw)));
    double f = raw / p;
    double m = f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0;
    if (m == 10.0) {
        m = 1.0;
        p *= 10.0;
    }
    t.step = m * p;
    t.nsub = m == 2.0 ? 4 : 5;
    if (min_step > 0.0 && t.step <= min_step) {
        t.step = min_step;
        t.nsub = 1;
    } else if (min_step > 0.0 && m == 2.0 && p == min_step) {
        t.nsub = 2;
    }
    t.maxabs = fmax(fabs(lo), fabs(hi));
    return t;
}

/* PLplot label callback ("o" axis option): plain decimals with as many
 * places as the tick interval needs, e.g. "0.25", "−3", "1200"; for very
 * large or small numbers a common power of ten written as "1.5×10⁻⁶"
 * (PLplot's own "(x10^n)" axis note is placed above the frame, where the
 * title is, and gets clipped). */
static void label_number(PLINT axis, PLFLT value, char *label, PLINT length,
                         PLPointer data)
{
    const plot_axes *ax = data;
    const axis_ticks *t = axis == PL_Y_AXIS ? &ax->y : &ax->x;
    if (length <= 0)
        return;
    /* A tick at zero computed as 1e-17 must read "0". */
    if (fabs(value) < 1e-6 * t->step || value == 0.0) {
        snprintf(label, (size_t)length, "0");
        return;
    }
    int e_step = (int)floor(log10(t->step) + 1e-9);
    int e_max = t->maxabs > 0.0 ? (int)floor(log10(t->maxabs) + 1e-9) : 0;
    /* Negative numbers get a real minus sign (U+2212): the hyphen is short
     * and easy to miss next to a tick. */
    const char *sign = value < 0.0 ? "\xe2\x88\x92" : "";
    double mag = fabs(value);
    if (e_step >= -4 && e_max < 6) {
        int dec = e_step < 0 ? -e_step : 0;
        snprintf(label, (size_t)length, "%s%.*f", sign, dec, mag);
        return;
    }
    static const char *const sup[10] = {
        "\xe2\x81\xb0", "\xc2\xb9", "\xc2\xb2", "\xc2\xb3", "\xe2\x81\xb4",
        "\xe2\x81\xb5", "\xe2\x81\xb6", "\xe2\x81\xb7", "\xe2\x81\xb8",
        "\xe2\x81\xb9"};
    int prec = e_max - e_step;
    prec = prec < 0 ? 0 : prec > 12 ? 12 : prec;
    char exp_text[64] = "";
    char digits[16];
    int e = e_max < 0 ? -e_max : e_max;
    snprintf(digits, sizeof digits, "%d", e);
    if (e_max < 0)
        strcat(exp_text, "\xe2\x81\xbb"); /* superscript minus */
    for (const char *d = digits; *d; ++d)
        strcat(exp_text, sup[*d - '0']);
    snprintf(label, (size_t)length, "%s%.*f\xc3\x97" "10%s", sign, prec,
             mag / pow(10.0, e_max), exp_text);
}

static plot_axes axes_make(const plot_window *w, double x_min_step)
{
    plot_axes ax;
    ax.x = ticks_make(w->xmin, w->xmax, x_min_step);
    ax.y = ticks_make(w->ymin, w->ymax, 0.0);
    return ax;
}

/* Width of a tick label in character heights.  Advance widths of DejaVu
 * Sans (the default sans font) in em: digits 0.636, '.' 0.318, U+2212 and
 * U+00D7 0.838, superscripts ~0.40; with the cairo driver one em is ~1.26
 * PLplot character heights (measured: 18.7 px character height, 15 px per
 * digit). */
static double label_width(const char *s)
{
    double em = 0.0;
    for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
        if ((*p & 0xC0) == 0x80)
            continue; /* UTF-8 continuation byte */
        if (*p >= '0' && *p <= '9')
            em += 0.636;
        else if (*p == '.')
            em += 0.318;
        else if (*p == 0xC3 || (*p == 0xE2 && p[1] == 0x88))
            em += 0.838; /* multiplication and minus signs */
        else
            em += *p < 0x80 ? 0.636 : 0.40; /* superscripts */
    }
    return 1.26 * em;
}

/* Width in character heights of the widest tick label of an axis. */
static double ticks_label_width(const plot_axes *ax, PLINT axis, double lo,
                                double hi)
{
    const axis_ticks *t = axis == PL_Y_AXIS ? &ax->y : &ax->x;
    double k0 = ceil(lo / t->step - 1e-9), k1 = floor(hi / t->step + 1e-9);
    double widest = 1.0;
    for (double k = k0; k <= k1 && k - k0 < 100.0; k += 1.0) {
        char buf[64];
        label_number(axis, k * t->step, buf, (PLINT)sizeof buf,
                     (PLPointer)ax);
        widest = fmax(widest, label_width(buf));
    }
    return widest;
}

/* Chooses the ticks for window w and sets the viewport so that the tick
 * labels and the axis labels fit: margins in character heights, the left
 * one from the widest y tick label (the numbers are horizontal), the right
 * one from half the widest x tick label, which may sit on the right edge.
 * May be called again after the window changed. */
static void plot_layout(plot_ctx *ctx, const plot_window *w, plot_axes *ax,
                        double x_min_step)
{
    *ax = axes_make(w, x_min_step);
    double ywidth = ticks_label_width(ax, PL_Y_AXIS, w->ymin, w->ymax);
    double xwidth = ticks_label_width(ax, PL_X_AXIS, w->xmin, w->xmax);
    /* PLplot puts "v" numbers ~0.6 character heights left of the frame;
     * plmtex's disp is measured to the middle of the rotated label. */
    ctx->ylab_disp = 0.6 + ywidth + 1.5;
    double left = ctx->ylab_disp + 1.0;
    double right = fmax(2.0, 0.5 * xwidth + 0.6);
    double vx0 = left * ctx->page_fx, vx1 = 1.0 - right * ctx->page_fx;
    double vy0 = 4.8 * ctx->page_fy, vy1 = 1.0 - 3.4 * ctx->page_fy;
    if (vx0 > 0.4)
        vx0 = 0.4;
    plvpor(vx0, vx1, vy0, vy1);
    ctx->ch_fx = ctx->page_fx / (vx1 - vx0);
    ctx->ch_fy = ctx->page_fy / (vy1 - vy0);
}

/* ------------------------------------------------------------------ */
/* Drawing pieces                                                       */

/* Sets up the estimated legend size (viewport fractions) for `lg`. */
static void legend_boxes_init(legend_boxes *lb, const plot_ctx *ctx,
                              const legend_spec *lg)
{
    size_t chars = 0;
    for (int i = 0; i < lg->n; ++i) {
        size_t c = utf8_length(lg->e[i].text);
        if (c > chars)
            chars = c;
    }
    /* Calibrated against the sizes pllegend reports for the arguments used
     * in draw_legend(): plot_width 0.05 + ~2.5 character heights of offset
     * and frame + ~0.69 character heights per character (DejaVu Sans), rows
     * 1.7 character heights apart; plus the legend's offset from the axes
     * (0.02, 0.03) and a small gap. */
    lb->w = 0.05 + (2.5 + 0.69 * (double)chars) * ctx->ch_fx + 0.035;
    lb->h = 1.7 * lg->n * ctx->ch_fy + 0.045;
    for (int c = 0; c < 4; ++c)
        lb->hits[c] = 0;
}

/* Picks the corner with the fewest hits; when even the best one would
 * cover something, raises the top of the window so the legend sits above
 * everything that was scored.  Returns the pllegend position flags. */
static PLINT legend_place(const legend_boxes *lb, plot_window *w)
{
    static const PLINT pos[4] = {
        PL_POSITION_TOP | PL_POSITION_RIGHT,
        PL_POSITION_TOP | PL_POSITION_LEFT,
        PL_POSITION_BOTTOM | PL_POSITION_RIGHT,
        PL_POSITION_BOTTOM | PL_POSITION_LEFT,
    };
    int best = 0;
    for (int c = 1; c < 4; ++c)
        if (lb->hits[c] < lb->hits[best])
            best = c;
    if (lb->hits[best] == 0)
        return pos[best] | PL_POSITION_INSIDE | PL_POSITION_VIEWPORT;
    double keep = 1.0 - lb->h;
    if (keep < 0.5)
        keep = 0.5;
    double top = w->ymin + (w->ymax - w->ymin) / keep;
    if (isfinite(top))
        w->ymax = top;
    return pos[0] | PL_POSITION_INSIDE | PL_POSITION_VIEWPORT;
}

static void draw_legend(const legend_spec *lg, PLINT position)
{
    PLINT opt_array[MAX_LEGEND], text_colors[MAX_LEGEND];
    PLINT box_colors[MAX_LEGEND], box_patterns[MAX_LEGEND];
    PLFLT box_scales[MAX_LEGEND], box_widths[MAX_LEGEND];
    PLINT line_colors[MAX_LEGEND], line_styles[MAX_LEGEND];
    PLFLT line_widths[MAX_LEGEND];
    PLINT sym_colors[MAX_LEGEND], sym_numbers[MAX_LEGEND];
    PLFLT sym_scales[MAX_LEGEND];
    const char *text[MAX_LEGEND], *symbols[MAX_LEGEND];
    for (int i = 0; i < lg->n; ++i) {
        const legend_entry *e = &lg->e[i];
        opt_array[i] = e->opt;
        text_colors[i] = COL_FG;
        text[i] = e->text;
        box_colors[i] = e->color;
        box_patterns[i] = 0;
        box_scales[i] = 0.8;
        box_widths[i] = 1.0;
        line_colors[i] = e->color;
        line_styles[i] = e->line_style;
        line_widths[i] = e->line_width;
        sym_colors[i] = e->color;
        sym_numbers[i] = 1;
        sym_scales[i] = MARKER_SCALE;
        symbols[i] = MARKER;
    }
    PLFLT lw, lh;
    pllsty(1);
    plwidth(1.0);
    pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             position, 0.02, 0.03, 0.05, COL_BG, COL_FG, 1, 0, 0, lg->n,
             opt_array, 0.7, CHAR_SCALE, 1.7, 0.0, text_colors,
             (const char *const *)text, box_colors, box_patterns, box_scales,
             box_widths, line_colors, line_styles, line_widths, sym_colors,
             sym_scales, sym_numbers, (const char *const *)symbols);
}

/* Window, grid, axes and labels.  The grid is drawn first so data cover it;
 * call draw_frame_axes() after the data to put the black frame on top.
 * `ax` must stay alive until the stream ends (PLplot keeps the pointer for
 * the label callback). */
static void draw_frame_grid(const plot_window *w, plot_axes *ax)
{
    plwind(w->xmin, w->xmax, w->ymin, w->ymax);
    plslabelfunc(label_number, ax);
    plcol0(COL_GRID);
    pllsty(1);
    plwidth(1.0);
    plbox("g", ax->x.step, ax->x.nsub, "g", ax->y.step, ax->y.nsub);
}

static void draw_frame_axes(const plot_ctx *ctx, const plot_axes *ax,
                            const char *title, const char *xlab,
                            const char *ylab)
{
    plcol0(COL_FG);
    pllsty(1);
    plwidth(1.2);
    plbox("bcnsto", ax->x.step, ax->x.nsub, "bcnstvo", ax->y.step,
          ax->y.nsub);
    plmtex("b", 3.2, 0.5, 0.5, xlab);
    plmtex("l", ctx->ylab_disp, 0.5, 0.5, ylab);
    if (title && *title) {
        plschr(0.0, CHAR_SCALE * TITLE_SCALE);
        plmtex("t", 1.1, 0.5, 0.5, title);
        plschr(0.0, CHAR_SCALE);
    }
}

/* Markers at the finite points. */
static void draw_markers(const double *x, const double *y, size_t n,
                         PLINT color)
{
    plcol0(color);
    plschr(0.0, CHAR_SCALE * MARKER_SCALE);
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(x[i]) || !isfinite(y[i]))
            continue;
        PLFLT px = x[i], py = y[i];
        plstring(1, &px, &py, MARKER);
    }
    plschr(0.0, CHAR_SCALE);
}

static void draw_segment(double x0, double y0, double x1, double y1)
{
    PLFLT px[2] = {x0, x1}, py[2] = {y0, y1};
    plline(2, px, py);
}

/* Labels: escaped copies of the caller's text (or defaults). */
typedef struct plot_text {
    char *title, *x, *y;
} plot_text;

static int text_make(plot_text *t, const phc_plot_labels *labels,
                     const char *def_x, const char *def_y)
{
    const char *ti = labels ? labels->title : NULL;
    const char *xl = labels && labels->x_label ? labels->x_label : def_x;
    const char *yl = labels && labels->y_label ? labels->y_label : def_y;
    t->title = phc_plot_escape(ti);
    t->x = phc_plot_escape(xl);
    t->y = phc_plot_escape(yl);
    return t->title && t->x && t->y ? PHC_OK : PHC_ERR_NOMEM;
}

static void text_free(plot_text *t)
{
    free(t->title);
    free(t->x);
    free(t->y);
}

static int check_path(const char *path, phc_error *err)
{
    if (!path || !*path)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "plot: no output path given");
    return PHC_OK;
}

/* ------------------------------------------------------------------ */
/* Public functions                                                     */

int phc_plot_fit(const char *path, const phc_plot_labels *labels,
                 const double *x, const double *y, const double *sigma,
                 size_t n, const double *curve_x, const double *curve_y,
                 size_t curve_n, phc_error *err)
{
    phc_error_clear(err);
    int status = check_path(path, err);
    if (status)
        return status;
    if (n == 0 || !x || !y)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: fit plot: expected n >= 1 data points "
                             "with x and y, found n = %zu%s", path, n,
                             (n && (!x || !y)) ? " and a NULL array" : "");
    if (curve_n > 0 && (!curve_x || !curve_y))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: fit plot: curve_n = %zu but curve_x or "
                             "curve_y is NULL", path, curve_n);

    plot_window w = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    size_t finite = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(x[i]) || !isfinite(y[i]))
            continue;
        if (sigma && isfinite(sigma[i]) && sigma[i] < 0.0)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: fit plot: sigma[%zu]: expected a "
                                 "value >= 0, found %g", path, i, sigma[i]);
        ++finite;
        range_add(&w.xmin, &w.xmax, x[i]);
        range_add(&w.ymin, &w.ymax, y[i]);
        if (sigma && isfinite(sigma[i])) {
            range_add(&w.ymin, &w.ymax, y[i] - sigma[i]);
            range_add(&w.ymin, &w.ymax, y[i] + sigma[i]);
        }
    }
    size_t curve_finite = 0;
    for (size_t j = 0; j < curve_n; ++j) {
        if (!isfinite(curve_x[j]) || !isfinite(curve_y[j]))
            continue;
        ++curve_finite;
        range_add(&w.xmin, &w.xmax, curve_x[j]);
        range_add(&w.ymin, &w.ymax, curve_y[j]);
    }
    if (finite == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: fit plot: expected at least one finite "
                             "data point, found none of %zu", path, n);
    if (range_pad(&w.xmin, &w.xmax, 0.04) || range_pad(&w.ymin, &w.ymax, 0.06))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: fit plot: values too large to plot", path);

    plot_text t = {0};
    const char *leg_data = sigma ? "data (\xc2\xb1" "1 \xcf\x83)" : "data";
    if (text_make(&t, labels, "x", "y")) {
        text_free(&t);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }
    legend_spec lg = {0};
    legend_add(&lg, PL_LEGEND_SYMBOL, leg_data, COL_DATA, 1, 1.0);
    if (curve_finite > 0)
        legend_add(&lg, PL_LEGEND_LINE, "fit", COL_FIT, 1, 3.0);

    plot_ctx ctx;
    status = plot_begin(&ctx, path, err);
    if (status) {
        text_free(&t);
        return status;
    }

    plot_axes ax;
    plot_layout(&ctx, &w, &ax, 0.0);
    legend_boxes lb;
    legend_boxes_init(&lb, &ctx, &lg);
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(x[i]) || !isfinite(y[i]))
            continue;
        if (sigma && isfinite(sigma[i]))
            legend_score_segment(&lb, &w, x[i], y[i] - sigma[i], x[i],
                                 y[i] + sigma[i]);
        else
            legend_score_point(&lb, &w, x[i], y[i]);
    }
    for (size_t j = 1; j < curve_n; ++j)
        legend_score_segment(&lb, &w, curve_x[j - 1], curve_y[j - 1],
                             curve_x[j], curve_y[j]);
    if (curve_finite == 1)
        for (size_t j = 0; j < curve_n; ++j)
            legend_score_point(&lb, &w, curve_x[j], curve_y[j]);
    PLINT pos = legend_place(&lb, &w);

    plot_layout(&ctx, &w, &ax, 0.0);
    draw_frame_grid(&w, &ax);

    /* Error bars under the markers. */
    if (sigma) {
        plcol0(COL_EBAR);
        plwidth(1.5);
        for (size_t i = 0; i < n; ++i) {
            if (!isfinite(x[i]) || !isfinite(y[i]) || !isfinite(sigma[i]) ||
                sigma[i] <= 0.0)
                continue;
            PLFLT px = x[i], lo = y[i] - sigma[i], hi = y[i] + sigma[i];
            plerry(1, &px, &lo, &hi);
        }
    }
    draw_markers(x, y, n, COL_DATA);

    /* Fit line over the markers, broken at non-finite values. */
    plcol0(COL_FIT);
    plwidth(3.0);
    for (size_t j = 0; j < curve_n;) {
        while (j < curve_n && (!isfinite(curve_x[j]) || !isfinite(curve_y[j])))
            ++j;
        size_t start = j;
        while (j < curve_n && isfinite(curve_x[j]) && isfinite(curve_y[j]))
            ++j;
        size_t len = j - start;
        if (len >= 2) {
            plline((PLINT)len, curve_x + start, curve_y + start);
        } else if (len == 1) {
            PLFLT px = curve_x[start], py = curve_y[start];
            plschr(0.0, CHAR_SCALE * MARKER_SCALE);
            plstring(1, &px, &py, MARKER);
            plschr(0.0, CHAR_SCALE);
        }
    }

    draw_frame_axes(&ctx, &ax, t.title, t.x, t.y);
    draw_legend(&lg, pos);

    status = plot_end(&ctx, path, PHC_OK, err);
    text_free(&t);
    return status;
}

int phc_plot_residuals(const char *path, const phc_plot_labels *labels,
                       const double *x, const double *r, size_t n, double s,
                       phc_error *err)
{
    phc_error_clear(err);
    int status = check_path(path, err);
    if (status)
        return status;
    if (n == 0 || !x || !r)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: residual plot: expected n >= 1 residuals "
                             "with x and r, found n = %zu%s", path, n,
                             (n && (!x || !r)) ? " and a NULL array" : "");

    plot_window w = {INFINITY, -INFINITY, 0.0, 0.0}; /* y range holds 0 */
    size_t finite = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(x[i]) || !isfinite(r[i]))
            continue;
        ++finite;
        range_add(&w.xmin, &w.xmax, x[i]);
        range_add(&w.ymin, &w.ymax, r[i]);
    }
    if (finite == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: residual plot: expected at least one "
                             "finite residual, found none of %zu", path, n);
    int band = isfinite(s) && s > 0.0;
    if (band) {
        range_add(&w.ymin, &w.ymax, -2.0 * s);
        range_add(&w.ymin, &w.ymax, 2.0 * s);
    }
    if (range_pad(&w.xmin, &w.xmax, 0.04) || range_pad(&w.ymin, &w.ymax, 0.08))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: residual plot: values too large to plot",
                             path);

    plot_text t = {0};
    if (text_make(&t, labels, "x", "residual")) {
        text_free(&t);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }
    legend_spec lg = {0};
    legend_add(&lg, PL_LEGEND_SYMBOL, "residual", COL_DATA, 1, 1.0);
    legend_add(&lg, PL_LEGEND_LINE, "0", COL_REF, 1, 1.5);
    if (band)
        legend_add(&lg, PL_LEGEND_LINE, "\xc2\xb1" "2 s", COL_BAND, 3, 2.0);

    plot_ctx ctx;
    status = plot_begin(&ctx, path, err);
    if (status) {
        text_free(&t);
        return status;
    }

    plot_axes ax;
    plot_layout(&ctx, &w, &ax, 0.0);
    legend_boxes lb;
    legend_boxes_init(&lb, &ctx, &lg);
    for (size_t i = 0; i < n; ++i)
        legend_score_point(&lb, &w, x[i], r[i]);
    /* The horizontal lines run across the whole plot. */
    legend_score_segment(&lb, &w, w.xmin, 0.0, w.xmax, 0.0);
    if (band) {
        legend_score_segment(&lb, &w, w.xmin, 2.0 * s, w.xmax, 2.0 * s);
        legend_score_segment(&lb, &w, w.xmin, -2.0 * s, w.xmax, -2.0 * s);
    }
    PLINT pos = legend_place(&lb, &w);

    plot_layout(&ctx, &w, &ax, 0.0);
    draw_frame_grid(&w, &ax);
    plcol0(COL_REF);
    plwidth(1.5);
    draw_segment(w.xmin, 0.0, w.xmax, 0.0);
    if (band) {
        plcol0(COL_BAND);
        plwidth(2.0);
        pllsty(3);
        draw_segment(w.xmin, 2.0 * s, w.xmax, 2.0 * s);
        draw_segment(w.xmin, -2.0 * s, w.xmax, -2.0 * s);
        pllsty(1);
    }
    draw_markers(x, r, n, COL_DATA);
    draw_frame_axes(&ctx, &ax, t.title, t.x, t.y);
    draw_legend(&lg, pos);

    status = plot_end(&ctx, path, PHC_OK, err);
    text_free(&t);
    return status;
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int phc_plot_qq(const char *path, const phc_plot_labels *labels,
                const double *r, size_t n, phc_error *err)
{
    phc_error_clear(err);
    int status = check_path(path, err);
    if (status)
        return status;
    if (n == 0 || !r)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: QQ plot: expected n >= 1 residuals, "
                             "found n = %zu%s", path, n,
                             (n && !r) ? " and a NULL array" : "");

    double *z = malloc(n * sizeof *z);
    double *q = malloc(n * sizeof *q);
    if (!z || !q) {
        free(z);
        free(q);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(r[i]))
            z[m++] = r[i];
    if (m == 0) {
        free(z);
        free(q);
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: QQ plot: expected at least one finite "
                             "residual, found none of %zu", path, n);
    }
    /* Standardise: (r - mean) / sd with the n - 1 sample sd, so that the
     * reference line is y = x whatever the residuals' unit.  A single value
     * or a constant sample has no spread: it is only centred. */
    double mean = 0.0, ss = 0.0;
    for (size_t i = 0; i < m; ++i)
        mean += (z[i] - mean) / (double)(i + 1);
    for (size_t i = 0; i < m; ++i)
        ss += (z[i] - mean) * (z[i] - mean);
    double sd = m > 1 ? sqrt(ss / (double)(m - 1)) : 0.0;
    for (size_t i = 0; i < m; ++i)
        z[i] = (sd > 0.0 && isfinite(sd)) ? (z[i] - mean) / sd : z[i] - mean;
    qsort(z, m, sizeof *z, compare_double);
    /* Blom plotting positions (i - 3/8) / (m + 1/4), i = 1..m. */
    for (size_t i = 0; i < m; ++i)
        q[i] = gsl_cdf_ugaussian_Pinv(((double)(i + 1) - 0.375) /
                                      ((double)m + 0.25));

    plot_window w = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    for (size_t i = 0; i < m; ++i) {
        range_add(&w.xmin, &w.xmax, q[i]);
        range_add(&w.ymin, &w.ymax, z[i]);
        range_add(&w.ymin, &w.ymax, q[i]); /* keep y = x in view */
    }
    if (range_pad(&w.xmin, &w.xmax, 0.05) || range_pad(&w.ymin, &w.ymax, 0.06)) {
        free(z);
        free(q);
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: QQ plot: values too large to plot", path);
    }

    plot_text t = {0};
    if (text_make(&t, labels, "normal quantile", "standardised residual")) {
        text_free(&t);
        free(z);
        free(q);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }
    legend_spec lg = {0};
    legend_add(&lg, PL_LEGEND_SYMBOL, "standardised residual", COL_DATA, 1,
               1.0);
    legend_add(&lg, PL_LEGEND_LINE, "y = x (normal)", COL_FIT, 1, 2.0);

    plot_ctx ctx;
    status = plot_begin(&ctx, path, err);
    if (status) {
        text_free(&t);
        free(z);
        free(q);
        return status;
    }

    double lo = fmin(w.xmin, w.ymin), hi = fmax(w.xmax, w.ymax);
    plot_axes ax;
    plot_layout(&ctx, &w, &ax, 0.0);
    legend_boxes lb;
    legend_boxes_init(&lb, &ctx, &lg);
    for (size_t i = 0; i < m; ++i)
        legend_score_point(&lb, &w, q[i], z[i]);
    legend_score_segment(&lb, &w, lo, lo, hi, hi);
    PLINT pos = legend_place(&lb, &w);
    hi = fmax(hi, w.ymax);

    plot_layout(&ctx, &w, &ax, 0.0);
    draw_frame_grid(&w, &ax);
    plcol0(COL_FIT);
    plwidth(2.0);
    draw_segment(lo, lo, hi, hi); /* clipped to the viewport by PLplot */
    draw_markers(q, z, m, COL_DATA);
    draw_frame_axes(&ctx, &ax, t.title, t.x, t.y);
    draw_legend(&lg, pos);

    status = plot_end(&ctx, path, PHC_OK, err);
    text_free(&t);
    free(z);
    free(q);
    return status;
}

int phc_plot_acf(const char *path, const phc_plot_labels *labels,
                 const double *acf, size_t max_lag, size_t n, phc_error *err)
{
    phc_error_clear(err);
    int status = check_path(path, err);
    if (status)
        return status;
    if (!acf)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: ACF plot: acf is NULL", path);
    if (n == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: ACF plot: expected the number of "
                             "residuals n >= 1, found 0", path);
    if (max_lag >= (size_t)1 << 24)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: ACF plot: max_lag = %zu is too large to "
                             "plot", path, max_lag);

    double bound = 1.96 / sqrt((double)n);
    plot_window w = {-0.5, (double)max_lag + 0.5, -bound, bound};
    w.ymax = fmax(w.ymax, 0.0);
    size_t finite = 0;
    for (size_t h = 0; h <= max_lag; ++h) {
        if (!isfinite(acf[h]))
            continue;
        ++finite;
        range_add(&w.ymin, &w.ymax, acf[h]);
    }
    if (finite == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: ACF plot: expected at least one finite "
                             "autocorrelation, found none of %zu", path,
                             max_lag + 1);
    if (range_pad(&w.xmin, &w.xmax, 0.02) || range_pad(&w.ymin, &w.ymax, 0.06))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: ACF plot: values too large to plot", path);

    plot_text t = {0};
    if (text_make(&t, labels, "lag", "autocorrelation")) {
        text_free(&t);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }
    legend_spec lg = {0};
    legend_add(&lg, PL_LEGEND_COLOR_BOX, "autocorrelation", COL_DATA, 1, 1.0);
    legend_add(&lg, PL_LEGEND_LINE,
               "\xc2\xb1" "1.96/\xe2\x88\x9an (white noise, 95 %)", COL_BAND,
               2, 2.0);

    plot_ctx ctx;
    status = plot_begin(&ctx, path, err);
    if (status) {
        text_free(&t);
        return status;
    }

    const double half = 0.3; /* bar half-width in lags */
    plot_axes ax;
    plot_layout(&ctx, &w, &ax, 1.0); /* integer lags */
    legend_boxes lb;
    legend_boxes_init(&lb, &ctx, &lg);
    for (size_t h = 0; h <= max_lag; ++h) {
        if (!isfinite(acf[h]))
            continue;
        double hx = (double)h;
        legend_score_segment(&lb, &w, hx - half, acf[h], hx + half, acf[h]);
        legend_score_segment(&lb, &w, hx - half, 0.0, hx - half, acf[h]);
        legend_score_segment(&lb, &w, hx + half, 0.0, hx + half, acf[h]);
    }
    legend_score_segment(&lb, &w, w.xmin, bound, w.xmax, bound);
    legend_score_segment(&lb, &w, w.xmin, -bound, w.xmax, -bound);
    PLINT pos = legend_place(&lb, &w);

    plot_layout(&ctx, &w, &ax, 1.0); /* integer lags */
    draw_frame_grid(&w, &ax);

    plcol0(COL_DATA);
    for (size_t h = 0; h <= max_lag; ++h) {
        if (!isfinite(acf[h]) || acf[h] == 0.0)
            continue;
        double hx = (double)h;
        PLFLT bx[4] = {hx - half, hx + half, hx + half, hx - half};
        PLFLT by[4] = {0.0, 0.0, acf[h], acf[h]};
        plfill(4, bx, by);
    }
    plcol0(COL_FG);
    plwidth(1.2);
    draw_segment(w.xmin, 0.0, w.xmax, 0.0);
    plcol0(COL_BAND);
    plwidth(2.0);
    pllsty(3);
    draw_segment(w.xmin, bound, w.xmax, bound);
    draw_segment(w.xmin, -bound, w.xmax, -bound);
    pllsty(1);

    draw_frame_axes(&ctx, &ax, t.title, t.x, t.y);
    draw_legend(&lg, pos);

    status = plot_end(&ctx, path, PHC_OK, err);
    text_free(&t);
    return status;
}
