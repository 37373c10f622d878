/* Diagnostic plots of a fit with PLplot's memcairo driver: see plots.h.
 * PLplot draws with cairo into a page in memory (the same rendering as its
 * pngcairo driver: the images are pixel for pixel those pngcairo made) and
 * phc_plot_png_write encodes it, at zlib level 1, several times faster than
 * cairo's PNG writer (which was most of a small fit's time in a batch:
 * issue 16, README "Speed").
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
 *   first, measurements/atomic_file.h, so the directory is known to be
 *   writable; PLplot never opens a file), checked for the PNG signature
 *   and IEND chunk and renamed
 *   into place (DESIGN.md §3).
 *
 * Caller text is plain text: PLplot's escape character '#' is doubled so a
 * label such as "run #3" prints as written; UTF-8 (±, σ, µ, °) renders
 * through cairo/pango. */
#include "fit/plots.h"
#include "fit/plot_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <gsl/gsl_cdf.h>
#include <plplot.h>

#include "measurements/photo.h"

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
    COL_COUNT = 8,
    COL_GROUP0 = COL_COUNT /* group g's colour is slot COL_GROUP0 + group_slot(g) */
};

/* Distinct group colours up to this many groups (matplotlib's "tab10"),
 * a viridis ramp beyond; at most MAX_GROUP_COLOURS slots of the ramp. */
#define TAB10_COUNT 10
#define MAX_GROUP_COLOURS 256
static const unsigned char TAB10[TAB10_COUNT][3] = {
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},  {148, 103, 189},
    {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}};
/* The ramp stops before viridis's light yellow end, which is hard to see on
 * white paper. */
static const double RAMP_END = 0.88;
/* Longest group name shown in a key (longer ones are cut with an ellipsis). */
#define KEY_NAME_MAX 28

/* Character height scale (PLplot's default ~ 10 px is too small on a
 * 1000-pixel-wide image). */
static const double CHAR_SCALE = 1.1;
static const double TITLE_SCALE = 1.2;   /* relative to CHAR_SCALE */
static const double MARKER_SCALE = 0.6;  /* marker glyph, relative */
/* Filled circle marker (U+25CF), drawn with plstring so the legend can use
 * the very same glyph. */
static const char MARKER[] = "\xe2\x97\x8f";
/* Diamonds (U+25C6 filled, U+25C7 outline) for points to point out. */
static const char DIAMOND[] = "\xe2\x97\x86";
static const char DIAMOND_EDGE[] = "\xe2\x97\x87";
static const double DIAMOND_SCALE = 1.3; /* relative to CHAR_SCALE */

#define MAX_LEGEND 8

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
    const char *symbol; /* glyph of PL_LEGEND_SYMBOL entries */
    double symbol_scale;
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
    e->symbol = MARKER;
    e->symbol_scale = MARKER_SCALE;
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
    phc_atomic_file *af; /* the output file until committed, NULL when none */
    unsigned char *pixels; /* PAGE_W x PAGE_H RGBA, PLplot's memcairo page */
    double page_fx, page_fy; /* one character height as a page fraction */
    double ch_fx, ch_fy;     /* ... and as a viewport fraction */
    double ylab_disp;        /* y label distance from the frame (chars) */
    size_t groups;           /* groups with a colour each (0: none) */
    double key_w;            /* page width kept right of the axes for a key */
    double vx0, vx1, vy0, vy1; /* the axes' viewport (page fractions) */
} plot_ctx;

/* Colour map 0 slot of group g of `count`. */
static PLINT group_colour(size_t count, size_t g)
{
    const size_t slot = count <= MAX_GROUP_COLOURS ? g : g * MAX_GROUP_COLOURS / count;
    return (PLINT)(COL_GROUP0 + slot);
}

/* Sets the colours of `count` groups into colour map 0 (which has room for
 * them); lut is viridis (phc_photo_viridis), used beyond TAB10_COUNT. */
static void set_group_colours(size_t count, const double *lut)
{
    if (count <= TAB10_COUNT) {
        for (size_t g = 0; g < count; ++g)
            plscol0((PLINT)(COL_GROUP0 + g), TAB10[g][0], TAB10[g][1], TAB10[g][2]);
        return;
    }
    const size_t slots = count < MAX_GROUP_COLOURS ? count : MAX_GROUP_COLOURS;
    for (size_t k = 0; k < slots; ++k) {
        const size_t i = (size_t)lround(255.0 * RAMP_END * (double)k / (double)(slots - 1));
        plscol0((PLINT)(COL_GROUP0 + k), (PLINT)lround(255 * lut[3 * i]),
                (PLINT)lround(255 * lut[3 * i + 1]), (PLINT)lround(255 * lut[3 * i + 2]));
    }
}

/* Opens a PLplot stream writing a PNG of PAGE_W x PAGE_H pixels to a
 * temporary file; on success ctx->page_f* hold the character height as a
 * fraction of the page.  The viewport is set later by plot_layout(). */
static int plot_begin(plot_ctx *ctx, const char *path, size_t groups, phc_error *err)
{
    ctx->stream = -1;
    ctx->af = NULL;
    ctx->pixels = NULL;
    ctx->groups = groups;
    ctx->key_w = 0.0;
    const int lib = phc_plot_library_open(path, err); /* PLplot: opened on the first plot */
    if (lib)
        return lib;
    plgstrm(&ctx->old_stream);

    double lut[3 * 256] = {0};
    if (groups > TAB10_COUNT) {
        const int rc = phc_photo_viridis(lut, err);
        if (rc)
            return rc;
    }

    int dev = phc_plot_device_available("memcairo");
    if (dev < 0)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    if (dev == 0)
        return phc_error_set(err, PHC_ERR_INTERNAL,
                             "%s: PLplot has no 'memcairo' device "
                             "(install plplot-driver-cairo)", path);

    int status = phc_atomic_file_open(path, &ctx->af, err);
    if (status)
        return status;
    /* the page: white, drawn on by memcairo, encoded by plot_end */
    if (!(ctx->pixels = malloc((size_t)PAGE_W * PAGE_H * 4))) {
        phc_atomic_file_abort(ctx->af);
        ctx->af = NULL;
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }
    memset(ctx->pixels, 255, (size_t)PAGE_W * PAGE_H * 4);

    PLINT strm = -1;
    plmkstrm(&strm);
    if (strm < 0) {
        plsstrm(ctx->old_stream);
        phc_atomic_file_abort(ctx->af);
        ctx->af = NULL;
        free(ctx->pixels);
        ctx->pixels = NULL;
        return phc_error_set(err, PHC_ERR_INTERNAL,
                             "%s: no free PLplot stream", path);
    }
    ctx->stream = strm;

    plsdev("memcairo");
    plsmema(PAGE_W, PAGE_H, ctx->pixels);
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
    const size_t slots = groups < MAX_GROUP_COLOURS ? groups : MAX_GROUP_COLOURS;
    plscmap0n(COL_COUNT + (PLINT)slots > 16 ? COL_COUNT + (PLINT)slots : 16);
    for (int i = 0; i < COL_COUNT; ++i)
        plscol0(i, rgb[i][0], rgb[i][1], rgb[i][2]);
    set_group_colours(groups, lut);

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

/* Ends the stream, checks the file and commits it to its path when status is
 * PHC_OK; removes the temporary file otherwise.  Returns the final status. */
static int plot_end(plot_ctx *ctx, int status, phc_error *err)
{
    if (ctx->stream >= 0) {
        plsstrm(ctx->stream);
        plend1();
        plsstrm(ctx->old_stream);
        ctx->stream = -1;
    }
    if (status == PHC_OK && ctx->af && ctx->pixels)
        status = phc_plot_png_write(ctx->af, ctx->pixels, PAGE_W, PAGE_H, err);
    free(ctx->pixels);
    ctx->pixels = NULL;
    status = phc_plot_file_finish(ctx->af, status, err);
    ctx->af = NULL;
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
    double vx0 = left * ctx->page_fx, vx1 = 1.0 - right * ctx->page_fx - ctx->key_w;
    double vy0 = 4.8 * ctx->page_fy, vy1 = 1.0 - 3.4 * ctx->page_fy;
    if (vx0 > 0.4)
        vx0 = 0.4;
    plvpor(vx0, vx1, vy0, vy1);
    ctx->vx0 = vx0;
    ctx->vx1 = vx1;
    ctx->vy0 = vy0;
    ctx->vy1 = vy1;
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
        sym_scales[i] = CHAR_SCALE * e->symbol_scale; /* as plotted (pllegend: plschr(0, scale)) */
        symbols[i] = e->symbol;
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

/* ------------------------------------------------------------------ */
/* Layers                                                               */

static PLINT layer_colour(int colour, size_t groups)
{
    switch (colour) {
    case PHC_COLOUR_DATA: return COL_DATA;
    case PHC_COLOUR_FIT: return COL_FIT;
    case PHC_COLOUR_REF: return COL_REF;
    case PHC_COLOUR_BAND: return COL_BAND;
    case PHC_COLOUR_BLACK: return COL_FG;
    default: return group_colour(groups, (size_t)colour);
    }
}

static double layer_width(const phc_plot_layer *l)
{
    switch (l->colour) {
    case PHC_COLOUR_FIT: return 3.0;
    case PHC_COLOUR_REF: return 1.5;
    case PHC_COLOUR_BLACK: return 2.5;
    default: return 2.0;
    }
}

static int mark_is_line(phc_plot_mark m)
{
    return m == PHC_MARK_LINE || m == PHC_MARK_DASHED || m == PHC_MARK_HLINE || m == PHC_MARK_HDASHED;
}

static PLINT mark_style(phc_plot_mark m)
{
    return m == PHC_MARK_DASHED || m == PHC_MARK_HDASHED ? 3 : 1;
}

/* A glyph at each finite point. */
static void draw_glyphs(const double *x, const double *y, size_t n, const char *glyph, double scale)
{
    plschr(0.0, CHAR_SCALE * scale);
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(x[i]) || !isfinite(y[i]))
            continue;
        PLFLT px = x[i], py = y[i];
        plstring(1, &px, &py, glyph);
    }
    plschr(0.0, CHAR_SCALE);
}

/* A line through the points, broken at non-finite ones; a lone finite
 * point is drawn as a marker. */
static void draw_polyline(const double *x, const double *y, size_t n)
{
    for (size_t j = 0; j < n;) {
        while (j < n && (!isfinite(x[j]) || !isfinite(y[j])))
            ++j;
        size_t start = j;
        while (j < n && isfinite(x[j]) && isfinite(y[j]))
            ++j;
        size_t len = j - start;
        if (len >= 2)
            plline((PLINT)len, x + start, y + start);
        else if (len == 1)
            draw_glyphs(x + start, y + start, 1, MARKER, MARKER_SCALE);
    }
}

static void draw_layer(const phc_plot_layer *l, const plot_window *w, size_t groups)
{
    if (l->n == 0)
        return;
    const PLINT col = layer_colour(l->colour, groups);
    switch (l->mark) {
    case PHC_MARK_DOTS:
        if (l->sigma) { /* error bars under the markers */
            plcol0(l->colour == PHC_COLOUR_DATA ? COL_EBAR : col);
            plwidth(l->colour == PHC_COLOUR_DATA ? 1.5 : 1.0);
            for (size_t i = 0; i < l->n; ++i) {
                if (!isfinite(l->x[i]) || !isfinite(l->y[i]) || !isfinite(l->sigma[i]) || l->sigma[i] <= 0.0)
                    continue;
                PLFLT px = l->x[i], lo = l->y[i] - l->sigma[i], hi = l->y[i] + l->sigma[i];
                plerry(1, &px, &lo, &hi);
            }
        }
        plcol0(col);
        draw_glyphs(l->x, l->y, l->n, MARKER, MARKER_SCALE);
        break;
    case PHC_MARK_DIAMONDS:
        plcol0(col);
        draw_glyphs(l->x, l->y, l->n, DIAMOND, DIAMOND_SCALE);
        plcol0(COL_FG);
        draw_glyphs(l->x, l->y, l->n, DIAMOND_EDGE, DIAMOND_SCALE);
        break;
    default:
        plcol0(col);
        plwidth(layer_width(l));
        pllsty(mark_style(l->mark));
        if (l->mark == PHC_MARK_HLINE || l->mark == PHC_MARK_HDASHED) {
            if (isfinite(l->y[0]))
                draw_segment(w->xmin, l->y[0], w->xmax, l->y[0]);
        } else {
            draw_polyline(l->x, l->y, l->n);
        }
        pllsty(1);
        break;
    }
}

/* Scores what a layer draws against the legend's corner boxes. */
static void legend_score_layer(legend_boxes *lb, const plot_window *w, const phc_plot_layer *l)
{
    if (l->n == 0)
        return;
    if (l->mark == PHC_MARK_HLINE || l->mark == PHC_MARK_HDASHED) {
        legend_score_segment(lb, w, w->xmin, l->y[0], w->xmax, l->y[0]);
        return;
    }
    for (size_t i = 0; i < l->n; ++i) {
        if (mark_is_line(l->mark)) {
            if (i > 0)
                legend_score_segment(lb, w, l->x[i - 1], l->y[i - 1], l->x[i], l->y[i]);
        } else if (l->sigma && isfinite(l->sigma[i])) {
            legend_score_segment(lb, w, l->x[i], l->y[i] - l->sigma[i], l->x[i], l->y[i] + l->sigma[i]);
        } else {
            legend_score_point(lb, w, l->x[i], l->y[i]);
        }
    }
}

/* ------------------------------------------------------------------ */
/* The key beside the axes of a grouped plot                            */

/* Vertical space of a row of the key, in character heights. */
static const double KEY_ROW = 1.5;
/* A sample line in the key, and the gap before its text (chars). */
static const double KEY_SAMPLE = 2.4, KEY_GAP = 0.6, KEY_PAD = 0.6;
/* Width of one character (average advance, DejaVu Sans), in heights. */
static const double CHAR_ADVANCE = 0.69;
/* The key takes at most this much of the page width; its text is smaller
 * than the axes' by KEY_SCALE. */
static const double KEY_MAX_WIDTH = 0.38, KEY_SCALE = 0.85;

typedef struct key_plan {
    double s;          /* character scale of the group names, relative */
    size_t cols, rows; /* list of names: columns and rows */
    size_t step;       /* > 0: a colour bar with every step-th name */
    double col_w;      /* page width of one column of names */
    double width;      /* page width of the key */
    double top_h;      /* page height of the labelled layers and the heading */
} key_plan;

/* Characters shown of a group name (cut to KEY_NAME_MAX). */
static size_t key_chars(const char *s)
{
    const size_t n = utf8_length(s);
    return n > KEY_NAME_MAX ? KEY_NAME_MAX : n;
}

/* A copy of s cut to KEY_NAME_MAX characters with an ellipsis, escaped for
 * PLplot; NULL when out of memory. */
static char *key_text(const char *s)
{
    char buf[4 * KEY_NAME_MAX + 8];
    size_t chars = 0, i = 0;
    for (; s[i] && i + 4 < sizeof buf - 4; ++i) {
        if (((unsigned char)s[i] & 0xC0) != 0x80 && ++chars > KEY_NAME_MAX - 1 && utf8_length(s) > KEY_NAME_MAX)
            break;
        buf[i] = s[i];
    }
    buf[i] = '\0';
    if (s[i])
        strcat(buf, "\xe2\x80\xa6"); /* … */
    return phc_plot_escape(buf);
}

/* Plans the key: the group names in up to three columns at a scale that
 * fits the height of the axes, else a colour bar labelled every k-th cell;
 * sets ctx->key_w. */
static void key_plan_make(key_plan *kp, plot_ctx *ctx, size_t entry_chars, size_t n_entries, size_t count,
                          size_t name_chars)
{
    const double fx = ctx->page_fx, fy = ctx->page_fy, ks = KEY_SCALE;
    const double height = 1.0 - 8.2 * fy; /* the axes' height (plot_layout) */
    kp->top_h = (KEY_PAD + KEY_ROW * (double)(n_entries + 1) + (n_entries ? 0.5 : 0.0)) * ks * fy;
    const double room = height - kp->top_h - KEY_PAD * fy;
    const double entries_w = (3 * KEY_PAD + KEY_SAMPLE + KEY_GAP + CHAR_ADVANCE * (double)entry_chars) * ks * fx;
    static const double scales[3] = {KEY_SCALE, 0.75, 0.65};
    double names_w = INFINITY;
    for (int k = 0; k < 3 && !(names_w <= KEY_MAX_WIDTH); ++k) {
        const double s = scales[k];
        const size_t fit_rows = (size_t)floor(room / (KEY_ROW * s * fy));
        if (fit_rows < 1)
            continue;
        const size_t cols = (count + fit_rows - 1) / fit_rows;
        if (cols > 3)
            continue;
        kp->s = s;
        kp->cols = cols;
        kp->rows = (count + cols - 1) / cols;
        kp->step = 0;
        kp->col_w = (KEY_SAMPLE + KEY_GAP + CHAR_ADVANCE * (double)name_chars + 1.0) * s * fx;
        names_w = 3 * KEY_PAD * ks * fx + (double)cols * kp->col_w;
    }
    if (!(names_w <= KEY_MAX_WIDTH)) {
        /* a colour bar: every cell, a name every step cells */
        kp->s = ks;
        const size_t fit_rows = (size_t)fmax(1.0, floor(room / (KEY_ROW * kp->s * fy) - 0.3));
        kp->cols = 1;
        kp->rows = fit_rows;
        kp->step = (count + fit_rows - 1) / fit_rows;
        kp->col_w = (1.6 + 0.8 + CHAR_ADVANCE * (double)name_chars) * kp->s * fx;
        names_w = 3 * KEY_PAD * ks * fx + kp->col_w;
    }
    kp->width = fmin(fmax(entries_w, names_w), KEY_MAX_WIDTH);
    ctx->key_w = kp->width;
}

/* A key row's sample: a line, a marker or both. */
static void key_sample(phc_plot_mark mark, PLINT col, PLINT style, double width, int line, int dot, double x0,
                       double x1, double y)
{
    plcol0(col);
    if (line) {
        plwidth(width);
        pllsty(style);
        draw_segment(x0, y, x1, y);
        pllsty(1);
    }
    if (dot) {
        PLFLT px = 0.5 * (x0 + x1), py = y;
        if (mark == PHC_MARK_DIAMONDS) {
            plschr(0.0, CHAR_SCALE * DIAMOND_SCALE);
            plstring(1, &px, &py, DIAMOND);
            plcol0(COL_FG);
            plstring(1, &px, &py, DIAMOND_EDGE);
        } else {
            plschr(0.0, CHAR_SCALE * MARKER_SCALE);
            plstring(1, &px, &py, MARKER);
        }
        plschr(0.0, CHAR_SCALE);
    }
}

/* Draws the key right of the axes in page coordinates: the labelled
 * layers, the heading, the group names (or the colour bar). */
static void draw_key(const plot_ctx *ctx, const key_plan *kp, const phc_plot_layer *layers, size_t n_layers,
                     char *const *layer_text, size_t count, char *const *names, const char *heading)
{
    /* a group's sample shows what the groups are drawn with */
    int group_line = 0, group_dot = 0;
    for (size_t i = 0; i < n_layers; ++i)
        if (layers[i].colour >= 0 && layers[i].n) {
            group_line |= mark_is_line(layers[i].mark);
            group_dot |= layers[i].mark == PHC_MARK_DOTS;
        }
    if (!group_line && !group_dot)
        group_dot = 1;
    const double fx = ctx->page_fx, fy = ctx->page_fy, ks = KEY_SCALE;
    const double x0 = 1.0 - kp->width + 0.5 * KEY_PAD * fx, top = ctx->vy1;
    plvpor(0.0, 1.0, 0.0, 1.0);
    plwind(0.0, 1.0, 0.0, 1.0);
    plschr(0.0, CHAR_SCALE * ks);
    double y = top - KEY_PAD * ks * fy;
    /* what markers and lines mean */
    for (size_t i = 0; i < n_layers; ++i) {
        const phc_plot_layer *l = &layers[i];
        if (!layer_text[i])
            continue;
        y -= 0.5 * KEY_ROW * ks * fy;
        const double sx = x0 + KEY_PAD * ks * fx;
        key_sample(l->mark, layer_colour(l->colour, count), mark_style(l->mark), layer_width(l),
                   mark_is_line(l->mark), !mark_is_line(l->mark), sx, sx + KEY_SAMPLE * ks * fx, y);
        plschr(0.0, CHAR_SCALE * ks);
        plcol0(COL_FG);
        plptex(sx + (KEY_SAMPLE + KEY_GAP) * ks * fx, y, 1.0, 0.0, 0.0, layer_text[i]);
        y -= 0.5 * KEY_ROW * ks * fy;
    }
    if (y < top - KEY_PAD * ks * fy)
        y -= 0.5 * ks * fy;
    /* heading */
    y -= 0.5 * KEY_ROW * ks * fy;
    plcol0(COL_FG);
    plptex(x0 + KEY_PAD * ks * fx, y, 1.0, 0.0, 0.0, heading);
    y -= 0.5 * KEY_ROW * ks * fy;
    const double row = KEY_ROW * kp->s * fy;
    plschr(0.0, CHAR_SCALE * kp->s);
    double bottom = y;
    if (kp->step == 0) {
        for (size_t g = 0; g < count; ++g) {
            const size_t c = g / kp->rows, r = g % kp->rows;
            const double sx = x0 + KEY_PAD * ks * fx + (double)c * kp->col_w, sy = y - ((double)r + 0.5) * row;
            key_sample(PHC_MARK_DOTS, group_colour(count, g), 1, 2.0, group_line, group_dot, sx,
                       sx + KEY_SAMPLE * kp->s * fx, sy);
            plschr(0.0, CHAR_SCALE * kp->s);
            plcol0(COL_FG);
            plptex(sx + (KEY_SAMPLE + KEY_GAP) * kp->s * fx, sy, 1.0, 0.0, 0.0, names[g]);
        }
        bottom = y - (double)kp->rows * row;
    } else {
        y -= 0.3 * row; /* clear of the heading */
        const double bar_h = (double)kp->rows * row, cell = bar_h / (double)count;
        const double bx0 = x0 + KEY_PAD * ks * fx, bx1 = bx0 + 1.6 * kp->s * fx;
        for (size_t g = 0; g < count; ++g) {
            PLFLT cx[4] = {bx0, bx1, bx1, bx0};
            PLFLT cy[4] = {y - (double)(g + 1) * cell, y - (double)(g + 1) * cell, y - (double)g * cell,
                           y - (double)g * cell};
            plcol0(group_colour(count, g));
            plfill(4, cx, cy);
        }
        plcol0(COL_FG);
        plwidth(1.0);
        for (size_t g = 0; g < count; g += kp->step) {
            const double cy = y - ((double)g + 0.5) * cell;
            draw_segment(bx1, cy, bx1 + 0.4 * kp->s * fx, cy);
            plptex(bx1 + 0.8 * kp->s * fx, cy, 1.0, 0.0, 0.0, names[g]);
        }
        bottom = y - bar_h;
    }
    plschr(0.0, CHAR_SCALE);
    /* a frame like the legend's */
    const double fb = bottom - 0.5 * KEY_PAD * fy, fr = fmin(1.0 - 0.3 * KEY_PAD * fx, x0 + kp->width - KEY_PAD * fx);
    PLFLT bx[5] = {x0, fr, fr, x0, x0}, by[5] = {top, top, fb, fb, top};
    plcol0(COL_FG);
    plwidth(1.0);
    plline(5, bx, by);
}

/* Default group names "1", "2", ... when the caller gives none. */
static const char *group_name(const phc_plot_groups *g, size_t i, char *buf, size_t size)
{
    if (g->names && g->names[i])
        return g->names[i];
    snprintf(buf, size, "%zu", i + 1);
    return buf;
}

int phc_plot_layers(const char *path, const phc_plot_labels *labels, const phc_plot_layer *layers,
                    size_t n_layers, const phc_plot_groups *groups, phc_error *err)
{
    phc_error_clear(err);
    int status = check_path(path, err);
    if (status)
        return status;
    if (!layers || n_layers == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: plot: no layers to draw", path);
    if (groups && groups->count == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: plot: groups: expected count >= 1, found 0", path);
    const size_t count = groups ? groups->count : 0;
    plot_window w = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    size_t finite = 0;
    for (size_t k = 0; k < n_layers; ++k) {
        const phc_plot_layer *l = &layers[k];
        const int hline = l->mark == PHC_MARK_HLINE || l->mark == PHC_MARK_HDASHED;
        if (l->colour >= 0 ? (size_t)l->colour >= count : l->colour < PHC_COLOUR_BLACK)
            return phc_error_set(err, PHC_ERR_INVALID, "%s: plot: layer %zu: colour %d is neither a group (of %zu) "
                                 "nor a PHC_COLOUR_ constant", path, k, l->colour, count);
        if (l->n && (!l->y || (!hline && !l->x)))
            return phc_error_set(err, PHC_ERR_INVALID, "%s: plot: layer %zu: %zu points but a NULL array", path, k,
                                 l->n);
        if (hline) {
            if (l->n)
                range_add(&w.ymin, &w.ymax, l->y[0]);
            continue;
        }
        for (size_t i = 0; i < l->n; ++i) {
            if (!isfinite(l->x[i]) || !isfinite(l->y[i]))
                continue;
            const double sg = l->mark == PHC_MARK_DOTS && l->sigma ? l->sigma[i] : NAN;
            if (sg < 0.0)
                return phc_error_set(err, PHC_ERR_INVALID, "%s: plot: layer %zu: sigma[%zu]: expected a value >= 0, "
                                     "found %g", path, k, i, sg);
            ++finite;
            range_add(&w.xmin, &w.xmax, l->x[i]);
            range_add(&w.ymin, &w.ymax, l->y[i]);
            if (isfinite(sg)) {
                range_add(&w.ymin, &w.ymax, l->y[i] - sg);
                range_add(&w.ymin, &w.ymax, l->y[i] + sg);
            }
        }
    }
    if (finite == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: plot: expected at least one finite point, found none",
                             path);
    if (range_pad(&w.xmin, &w.xmax, 0.04) || range_pad(&w.ymin, &w.ymax, 0.06))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: plot: values too large to plot", path);

    /* escaped texts: the layers' labels, then the group names and heading */
    plot_text t = {0};
    char **text = calloc(n_layers + count + 1, sizeof *text);
    int nomem = !text || text_make(&t, labels, "x", "y");
    size_t entry_chars = 0, name_chars = 1, n_entries = 0;
    for (size_t k = 0; !nomem && k < n_layers; ++k)
        if (layers[k].label) {
            nomem = !(text[k] = phc_plot_escape(layers[k].label));
            entry_chars = fmax(entry_chars, utf8_length(layers[k].label));
            ++n_entries;
        }
    for (size_t g = 0; !nomem && g < count; ++g) {
        char buf[32];
        const char *nm = group_name(groups, g, buf, sizeof buf);
        nomem = !(text[n_layers + g] = key_text(nm));
        name_chars = fmax(name_chars, key_chars(nm));
    }
    if (!nomem && groups) {
        const char *heading = groups->title && *groups->title ? groups->title : "group";
        nomem = !(text[n_layers + count] = phc_plot_escape(heading));
        entry_chars = fmax(entry_chars, utf8_length(heading));
    }
    legend_spec lg = {0};
    for (size_t k = 0; !nomem && !groups && k < n_layers; ++k) {
        const phc_plot_layer *l = &layers[k];
        if (!text[k])
            continue;
        if (mark_is_line(l->mark)) {
            legend_add(&lg, PL_LEGEND_LINE, text[k], layer_colour(l->colour, 0), mark_style(l->mark),
                       layer_width(l));
        } else {
            legend_add(&lg, PL_LEGEND_SYMBOL, text[k], layer_colour(l->colour, 0), 1, 1.0);
            if (l->mark == PHC_MARK_DIAMONDS) {
                lg.e[lg.n - 1].symbol = DIAMOND;
                lg.e[lg.n - 1].symbol_scale = DIAMOND_SCALE;
            }
        }
    }
    if (nomem) {
        status = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }

    plot_ctx ctx;
    if ((status = plot_begin(&ctx, path, count, err)))
        goto done;
    key_plan kp = {0};
    if (groups)
        key_plan_make(&kp, &ctx, entry_chars, n_entries, count, name_chars);
    plot_axes ax;
    plot_layout(&ctx, &w, &ax, 0.0);
    PLINT pos = 0;
    if (lg.n) {
        legend_boxes lb;
        legend_boxes_init(&lb, &ctx, &lg);
        for (size_t k = 0; k < n_layers; ++k)
            legend_score_layer(&lb, &w, &layers[k]);
        pos = legend_place(&lb, &w);
        plot_layout(&ctx, &w, &ax, 0.0);
    }
    draw_frame_grid(&w, &ax);
    for (size_t k = 0; k < n_layers; ++k)
        draw_layer(&layers[k], &w, count);
    draw_frame_axes(&ctx, &ax, t.title, t.x, t.y);
    if (lg.n)
        draw_legend(&lg, pos);
    if (groups)
        draw_key(&ctx, &kp, layers, n_layers, text, count, text + n_layers, text[n_layers + count]);
    status = plot_end(&ctx, PHC_OK, err);
done:
    for (size_t i = 0; text && i < n_layers + count + 1; ++i)
        free(text[i]);
    free(text);
    text_free(&t);
    return status;
}

/* ------------------------------------------------------------------ */
/* Fit and residual plots                                               */

typedef struct ordered {
    size_t group;
    double x;
    size_t index;
} ordered;

static int compare_ordered(const void *a, const void *b)
{
    const ordered *p = a, *q = b;
    if (p->group != q->group)
        return p->group < q->group ? -1 : 1;
    /* non-finite x last within a group */
    const int fp = isfinite(p->x), fq = isfinite(q->x);
    if (fp != fq)
        return fq - fp;
    if (fp && p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return (p->index > q->index) - (p->index < q->index);
}

/* The observations sorted by group, then x: order[0..n-1] (malloc'd) and
 * start[0..count] (group g is order[start[g] .. start[g+1]-1]). */
static int group_order(const double *x, size_t n, const phc_plot_groups *g, size_t count, size_t **order,
                       size_t **start)
{
    ordered *o = malloc(n * sizeof *o);
    *order = malloc(n * sizeof **order);
    *start = calloc(count + 1, sizeof **start);
    if (!o || !*order || !*start) {
        free(o);
        free(*order);
        free(*start);
        *order = *start = NULL;
        return PHC_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; ++i)
        o[i] = (ordered){g ? g->id[i] : 0, x[i], i};
    qsort(o, n, sizeof *o, compare_ordered);
    for (size_t i = 0; i < n; ++i) {
        (*order)[i] = o[i].index;
        (*start)[o[i].group + 1]++;
    }
    for (size_t k = 0; k < count; ++k)
        (*start)[k + 1] += (*start)[k];
    free(o);
    return PHC_OK;
}

/* Checks the ids of groups (NULL is fine) against n observations. */
static int check_groups(const char *path, const char *what, const phc_plot_groups *g, size_t n, phc_error *err)
{
    if (!g)
        return PHC_OK;
    if (g->count == 0 || !g->id)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: %s: groups need count >= 1 and ids", path, what);
    for (size_t i = 0; i < n; ++i)
        if (g->id[i] >= g->count)
            return phc_error_set(err, PHC_ERR_INVALID, "%s: %s: group id[%zu] = %zu: expected below %zu", path, what,
                                 i, g->id[i], g->count);
    return PHC_OK;
}

/* The working memory of a grouped plot: `arrays` arrays of n values, room
 * for `max_layers` layers, and the observations in group order. */
typedef struct group_work {
    double *buf;
    phc_plot_layer *layers;
    size_t *order, *start;
} group_work;

static void group_work_free(group_work *gp)
{
    free(gp->buf);
    free(gp->layers);
    free(gp->order);
    free(gp->start);
}

static int group_work_make(group_work *gp, const double *x, size_t n, const phc_plot_groups *groups, size_t count,
                        size_t arrays, size_t max_layers)
{
    *gp = (group_work){0};
    gp->buf = malloc(arrays * n * sizeof *gp->buf);
    gp->layers = calloc(max_layers, sizeof *gp->layers);
    if (!gp->buf || !gp->layers || group_order(x, n, groups, count, &gp->order, &gp->start)) {
        group_work_free(gp);
        return PHC_ERR_NOMEM;
    }
    return PHC_OK;
}

int phc_plot_fit_groups(const char *path, const phc_plot_labels *labels, const double *x, const double *y,
                        const double *sigma, size_t n, const phc_plot_groups *groups, const double *yhat,
                        const double *curve_x, const double *curve_y, size_t curve_n, phc_error *err)
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
    if ((status = check_groups(path, "fit plot", groups, n, err)))
        return status;
    size_t finite = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(x[i]) || !isfinite(y[i]))
            continue;
        if (sigma && isfinite(sigma[i]) && sigma[i] < 0.0)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: fit plot: sigma[%zu]: expected a "
                                 "value >= 0, found %g", path, i, sigma[i]);
        ++finite;
    }
    if (finite == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: fit plot: expected at least one finite "
                             "data point, found none of %zu", path, n);

    const size_t count = groups ? groups->count : 1;
    const char *model = labels && labels->model ? labels->model : "fit";
    const char *data = sigma ? "data (\xc2\xb1" "1 \xcf\x83)" : "data";
    group_work gp;
    if (group_work_make(&gp, x, n, groups, count, 4, 2 * count + 3))
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    const size_t *order = gp.order, *start = gp.start;
    phc_plot_layer *layers = gp.layers;
    double *ox = gp.buf, *oy = gp.buf + n, *os = gp.buf + 2 * n, *om = gp.buf + 3 * n;
    for (size_t i = 0; i < n; ++i) {
        const size_t j = order[i];
        ox[i] = x[j];
        oy[i] = y[j];
        os[i] = sigma ? sigma[j] : NAN;
        om[i] = yhat ? yhat[j] : NAN;
    }
    size_t nl = 0;
    const int grouped = groups != NULL;
    if (grouped) { /* the key: what markers and lines are */
        layers[nl++] = (phc_plot_layer){PHC_MARK_DOTS, PHC_COLOUR_REF, NULL, NULL, 0, NULL, data};
        if (yhat && !curve_n)
            layers[nl++] = (phc_plot_layer){PHC_MARK_LINE, PHC_COLOUR_REF, NULL, NULL, 0, NULL, model};
    }
    for (size_t g = 0; g < count; ++g) {
        const size_t a = start[g], m = start[g + 1] - a;
        layers[nl++] = (phc_plot_layer){PHC_MARK_DOTS, grouped ? (int)g : PHC_COLOUR_DATA, ox + a, oy + a, m,
                                        sigma ? os + a : NULL, grouped ? NULL : data};
    }
    char shared[256]; /* one model line for every group */
    snprintf(shared, sizeof shared, "%s (shared)", model);
    if (curve_n > 0)
        layers[nl++] = (phc_plot_layer){PHC_MARK_LINE, grouped ? PHC_COLOUR_BLACK : PHC_COLOUR_FIT, curve_x,
                                        curve_y, curve_n, NULL, grouped ? shared : model};
    else if (yhat)
        for (size_t g = 0; g < count; ++g)
            layers[nl++] = (phc_plot_layer){PHC_MARK_LINE, grouped ? (int)g : PHC_COLOUR_FIT, ox + start[g],
                                            om + start[g], start[g + 1] - start[g], NULL, grouped ? NULL : model};
    status = phc_plot_layers(path, labels, layers, nl, groups, err);
    group_work_free(&gp);
    return status;
}

int phc_plot_fit(const char *path, const phc_plot_labels *labels, const double *x, const double *y,
                 const double *sigma, size_t n, const double *curve_x, const double *curve_y, size_t curve_n,
                 phc_error *err)
{
    return phc_plot_fit_groups(path, labels, x, y, sigma, n, NULL, NULL, curve_x, curve_y, curve_n, err);
}

int phc_plot_residuals_groups(const char *path, const phc_plot_labels *labels, const double *x, const double *r,
                              size_t n, double s, const phc_plot_groups *groups, phc_error *err)
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
    if ((status = check_groups(path, "residual plot", groups, n, err)))
        return status;
    size_t finite = 0;
    for (size_t i = 0; i < n; ++i)
        finite += isfinite(x[i]) && isfinite(r[i]);
    if (finite == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: residual plot: expected at least one "
                             "finite residual, found none of %zu", path, n);
    const size_t count = groups ? groups->count : 1;
    const int band = isfinite(s) && s > 0.0, grouped = groups != NULL;
    const double zero = 0.0, up = 2.0 * s, down = -2.0 * s;
    group_work gp;
    if (group_work_make(&gp, x, n, groups, count, 2, count + 4))
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    const size_t *order = gp.order, *start = gp.start;
    phc_plot_layer *layers = gp.layers;
    double *ox = gp.buf, *orr = gp.buf + n;
    for (size_t i = 0; i < n; ++i) {
        ox[i] = x[order[i]];
        orr[i] = r[order[i]];
    }
    /* the key's order: residual, 0, +-2 s; the lines under the markers */
    size_t nl = 0;
    layers[nl++] = (phc_plot_layer){PHC_MARK_DOTS, grouped ? PHC_COLOUR_REF : PHC_COLOUR_DATA, NULL, NULL, 0,
                                    NULL, "residual"};
    layers[nl++] = (phc_plot_layer){PHC_MARK_HLINE, PHC_COLOUR_REF, NULL, &zero, 1, NULL, "0"};
    if (band) {
        layers[nl++] = (phc_plot_layer){PHC_MARK_HDASHED, PHC_COLOUR_BAND, NULL, &up, 1, NULL, "\xc2\xb1" "2 s"};
        layers[nl++] = (phc_plot_layer){PHC_MARK_HDASHED, PHC_COLOUR_BAND, NULL, &down, 1, NULL, NULL};
    }
    for (size_t g = 0; g < count; ++g)
        layers[nl++] = (phc_plot_layer){PHC_MARK_DOTS, grouped ? (int)g : PHC_COLOUR_DATA, ox + start[g],
                                        orr + start[g], start[g + 1] - start[g], NULL, NULL};
    status = phc_plot_layers(path, labels, layers, nl, groups, err);
    group_work_free(&gp);
    return status;
}

int phc_plot_residuals(const char *path, const phc_plot_labels *labels, const double *x, const double *r, size_t n,
                       double s, phc_error *err)
{
    return phc_plot_residuals_groups(path, labels, x, r, n, s, NULL, err);
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
    status = plot_begin(&ctx, path, 0, err);
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
    plcol0(COL_DATA);
    draw_glyphs(q, z, m, MARKER, MARKER_SCALE);
    draw_frame_axes(&ctx, &ax, t.title, t.x, t.y);
    draw_legend(&lg, pos);

    status = plot_end(&ctx, PHC_OK, err);
    text_free(&t);
    free(z);
    free(q);
    return status;
}

/* Bars acf[h] at lags h * step (h = 0..max_lag), the white-noise band, and
 * when mark is finite a dotted vertical line at lag `mark` labelled
 * mark_label.  hours = 0: integer lags (ticks never between them); 1: lags
 * in hours (ticks every 6 h when they reach 18-100 h). */
static int acf_plot(const char *path, const phc_plot_labels *labels, const double *acf, size_t max_lag,
                    size_t n, double step, int hours, double mark, const char *mark_label, phc_error *err)
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
    plot_window w = {-0.5 * step, ((double)max_lag + 0.5) * step, -bound, bound};
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
    const int marked = isfinite(mark);
    if (marked)
        legend_add(&lg, PL_LEGEND_LINE, mark_label, COL_FIT, 3, 2.0);

    plot_ctx ctx;
    status = plot_begin(&ctx, path, 0, err);
    if (status) {
        text_free(&t);
        return status;
    }

    const double half = 0.3 * step; /* bar half-width */
    plot_axes ax;
    plot_layout(&ctx, &w, &ax, hours ? 0.0 : 1.0); /* integer lags */
    legend_boxes lb;
    legend_boxes_init(&lb, &ctx, &lg);
    for (size_t h = 0; h <= max_lag; ++h) {
        if (!isfinite(acf[h]))
            continue;
        double hx = (double)h * step;
        legend_score_segment(&lb, &w, hx - half, acf[h], hx + half, acf[h]);
        legend_score_segment(&lb, &w, hx - half, 0.0, hx - half, acf[h]);
        legend_score_segment(&lb, &w, hx + half, 0.0, hx + half, acf[h]);
    }
    legend_score_segment(&lb, &w, w.xmin, bound, w.xmax, bound);
    legend_score_segment(&lb, &w, w.xmin, -bound, w.xmax, -bound);
    if (marked)
        legend_score_segment(&lb, &w, mark, w.ymin, mark, w.ymax);
    PLINT pos = legend_place(&lb, &w);

    plot_layout(&ctx, &w, &ax, hours ? 0.0 : 1.0); /* integer lags */
    if (hours && w.xmax - w.xmin > 18.0 && w.xmax - w.xmin < 100.0) {
        ax.x.step = 6.0; /* lags in hours: ticks every 6 h, minor every hour */
        ax.x.nsub = 6;
    }
    draw_frame_grid(&w, &ax);

    plcol0(COL_DATA);
    for (size_t h = 0; h <= max_lag; ++h) {
        if (!isfinite(acf[h]) || acf[h] == 0.0)
            continue;
        double hx = (double)h * step;
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
    if (marked) {
        plcol0(COL_FIT);
        pllsty(3);
        draw_segment(mark, w.ymin, mark, w.ymax);
        pllsty(1);
    }

    draw_frame_axes(&ctx, &ax, t.title, t.x, t.y);
    draw_legend(&lg, pos);

    status = plot_end(&ctx, PHC_OK, err);
    text_free(&t);
    return status;
}

int phc_plot_acf(const char *path, const phc_plot_labels *labels,
                 const double *acf, size_t max_lag, size_t n, phc_error *err)
{
    return acf_plot(path, labels, acf, max_lag, n, 1.0, 0, NAN, NULL, err);
}

int phc_plot_acf_time(const char *path, const phc_plot_labels *labels, const double *acf, size_t bins,
                      double bin_h, size_t n, phc_error *err)
{
    phc_error_clear(err);
    if (bins == 0 || !(bin_h > 0.0) || !isfinite(bin_h))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: time-lag ACF plot: expected bins >= 1 and a lag bin > 0 h, "
                             "found %zu bins of %g h", path ? path : "(null)", bins, bin_h);
    const phc_plot_labels def = {labels ? labels->title : NULL,
                                 labels && labels->x_label ? labels->x_label : "lag (h)",
                                 labels ? labels->y_label : NULL, NULL};
    const double last = (double)(bins - 1) * bin_h;
    return acf_plot(path, &def, acf, bins - 1, n, bin_h, 1, last >= 24.0 ? 24.0 : NAN, "24 h (one day)", err);
}

int phc_plot_time_of_day(const char *path, const phc_plot_labels *labels, const double *hour, const double *r,
                         size_t n, phc_error *err)
{
    phc_error_clear(err);
    int status = check_path(path, err);
    if (status)
        return status;
    if (n == 0 || !hour || !r)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: time-of-day plot: expected n >= 1 residuals with clock "
                             "times, found n = %zu%s", path, n, (n && (!hour || !r)) ? " and a NULL array" : "");
    /* hourly means at the bin centres, closed over midnight: the line runs
     * from 0 h to 24 h through the value midway between 23:30 and 00:30 */
    double sum[24] = {0}, mx[26], my[26];
    size_t cnt[24] = {0}, finite = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(hour[i]) || !isfinite(r[i]) || hour[i] < 0.0 || hour[i] >= 24.0)
            continue;
        const size_t b = (size_t)hour[i];
        sum[b] += r[i];
        cnt[b]++;
        ++finite;
    }
    if (finite == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: time-of-day plot: expected at least one finite residual "
                             "with a clock time in [0, 24), found none of %zu", path, n);
    for (size_t b = 0; b < 24; ++b) {
        mx[b + 1] = (double)b + 0.5;
        my[b + 1] = cnt[b] ? sum[b] / (double)cnt[b] : NAN;
    }
    const double wrap = cnt[0] && cnt[23] ? 0.5 * (my[1] + my[24]) : NAN;
    mx[0] = 0.0;
    my[0] = wrap;
    mx[25] = 24.0;
    my[25] = wrap;
    const double zero = 0.0, up = 2.0, down = -2.0;
    phc_plot_layer layers[] = {
        {PHC_MARK_DOTS, PHC_COLOUR_DATA, hour, r, n, NULL, "standardised residual"},
        {PHC_MARK_HLINE, PHC_COLOUR_REF, NULL, &zero, 1, NULL, "0"},
        {PHC_MARK_HDASHED, PHC_COLOUR_BAND, NULL, &up, 1, NULL, "\xc2\xb1" "2 (2 standard deviations)"},
        {PHC_MARK_HDASHED, PHC_COLOUR_BAND, NULL, &down, 1, NULL, NULL},
        {PHC_MARK_DOTS, PHC_COLOUR_FIT, mx + 1, my + 1, 24, NULL, NULL},
        {PHC_MARK_LINE, PHC_COLOUR_FIT, mx, my, 26, NULL, "mean of each clock hour"},
    };
    const phc_plot_labels def = {labels ? labels->title : NULL,
                                 labels && labels->x_label ? labels->x_label : "local clock time (h)",
                                 labels && labels->y_label ? labels->y_label : "standardised residual", NULL};
    return phc_plot_layers(path, &def, layers, sizeof layers / sizeof layers[0], NULL, err);
}
