/* Side views of plant shapes: see shape_plots.h.
 *
 * Safety as in fit/plots.c: PLplot's fatal errors exit the process, so
 * everything it could reject is checked first (the device exists, the file
 * can be created, every coordinate is finite); the call makes and ends its
 * own stream and restores the caller's; the PNG goes through
 * phc_plot_file_finish (complete-PNG check, rename into place). */
#include "fit/shape_plots.h"
#include "fit/plot_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <plplot.h>

enum { COL_BG = 0, COL_FG, COL_MARKER, COL_PLAIN, COL_COUNT };

static const double CHAR_SCALE = 1.0;
static const double M_TO_CM = 100.0;

/* Dry to wet: ColorBrewer BrBG's brown end and PRGn's green end (Brewer
 * 2003), every stop dark enough to show on white. */
static const unsigned char DRY_WET[5][3] = {
    {140, 81, 10}, {191, 129, 45}, {214, 180, 100}, {90, 174, 97}, {27, 120, 55}};

phc_shape_plot_options phc_shape_plot_options_default(void)
{
    phc_shape_plot_options o = {0};
    o.value_label = "relative water content (1)";
    o.across_axis = 0;
    o.up_axis = 2;
    o.max_line_width = 7.0;
    return o;
}

static int check_panels(const char *path, const phc_shape_panel *panels, size_t count,
                        phc_error *err)
{
    for (size_t p = 0; p < count; ++p) {
        const phc_shape_panel *s = panels + p;
        if (s->n == 0 || !s->head || !s->tail || !s->radius)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: shape panel %zu: no segments or a NULL array", path, p + 1);
        if (s->markers && !s->marker)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: shape panel %zu: %zu markers but no coordinates", path,
                                 p + 1, s->markers);
        for (size_t i = 0; i < s->n; ++i) {
            for (int k = 0; k < 3; ++k)
                if (!isfinite(s->head[3 * i + k]) || !isfinite(s->tail[3 * i + k]))
                    return phc_error_set(err, PHC_ERR_INVALID,
                                         "%s: shape panel %zu, segment %zu: coordinate %c is "
                                         "not finite",
                                         path, p + 1, i, "xyz"[k]);
            if (!(s->radius[i] > 0) || !isfinite(s->radius[i]))
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "%s: shape panel %zu, segment %zu: radius %g is not "
                                     "positive and finite",
                                     path, p + 1, i, s->radius[i]);
        }
        for (size_t i = 0; i < 3 * s->markers; ++i)
            if (!isfinite(s->marker[i]))
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "%s: shape panel %zu, marker %zu: not finite", path, p + 1,
                                     i / 3 + 1);
    }
    return PHC_OK;
}

/* Limits shared by every panel (cm), the colour range and the largest radius. */
typedef struct frame {
    double a0, a1, u0, u1; /* across and up limits, cm */
    double lo, hi;         /* colour range */
    double r_max;          /* m */
    int any_value;
    double chr;            /* character scale of the figure */
} frame;

static frame common_frame(const phc_shape_panel *panels, size_t count,
                          const phc_shape_plot_options *o)
{
    frame f = {INFINITY, -INFINITY, INFINITY, -INFINITY, INFINITY, -INFINITY, 0.0, 0, CHAR_SCALE};
    const int a = o->across_axis, u = o->up_axis;
    for (size_t p = 0; p < count; ++p) {
        const phc_shape_panel *s = panels + p;
        for (size_t i = 0; i < s->n; ++i) {
            const double *ends[2] = {s->head + 3 * i, s->tail + 3 * i};
            for (int e = 0; e < 2; ++e) {
                f.a0 = fmin(f.a0, ends[e][a] * M_TO_CM);
                f.a1 = fmax(f.a1, ends[e][a] * M_TO_CM);
                f.u0 = fmin(f.u0, ends[e][u] * M_TO_CM);
                f.u1 = fmax(f.u1, ends[e][u] * M_TO_CM);
            }
            f.r_max = fmax(f.r_max, s->radius[i]);
            if (s->value && isfinite(s->value[i])) {
                f.lo = fmin(f.lo, s->value[i]);
                f.hi = fmax(f.hi, s->value[i]);
                f.any_value = 1;
            }
        }
        for (size_t k = 0; k < s->markers; ++k) {
            f.a0 = fmin(f.a0, s->marker[3 * k + a] * M_TO_CM);
            f.a1 = fmax(f.a1, s->marker[3 * k + a] * M_TO_CM);
            f.u0 = fmin(f.u0, s->marker[3 * k + u] * M_TO_CM);
            f.u1 = fmax(f.u1, s->marker[3 * k + u] * M_TO_CM);
        }
    }
    if (o->value_max > o->value_min) {
        f.lo = o->value_min;
        f.hi = o->value_max;
    } else if (!f.any_value || !(f.hi > f.lo)) {
        const double mid = f.any_value ? f.lo : 0.5;
        f.lo = mid - 0.5;
        f.hi = mid + 0.5;
    }
    /* a margin of 6% of the larger extent (at least 1 mm) on every side */
    const double pad = fmax(0.1, 0.06 * fmax(f.a1 - f.a0, f.u1 - f.u0));
    f.a0 -= pad;
    f.a1 += pad;
    f.u0 -= pad;
    f.u1 += pad;
    return f;
}

static void draw_panel(const phc_shape_panel *s, const frame *f, const phc_shape_plot_options *o)
{
    const int a = o->across_axis, u = o->up_axis;
    const char axis_name[3] = {'x', 'y', 'z'};
    char label[64];
    plwind(f->a0, f->a1, f->u0, f->u1);
    for (size_t i = 0; i < s->n; ++i) {
        PLFLT lx[2] = {s->head[3 * i + a] * M_TO_CM, s->tail[3 * i + a] * M_TO_CM};
        PLFLT ly[2] = {s->head[3 * i + u] * M_TO_CM, s->tail[3 * i + u] * M_TO_CM};
        const double w = o->max_line_width * s->radius[i] / f->r_max;
        if (s->value && isfinite(s->value[i])) {
            double c = (s->value[i] - f->lo) / (f->hi - f->lo);
            plcol1(c < 0 ? 0 : c > 1 ? 1 : c);
        } else {
            plcol0(COL_PLAIN);
        }
        plwidth(w < 0.6 ? 0.6 : w);
        plline(2, lx, ly);
    }
    if (s->markers) {
        plcol0(COL_MARKER);
        plwidth(1.5);
        for (size_t k = 0; k < s->markers; ++k) {
            PLFLT mx = s->marker[3 * k + a] * M_TO_CM, my = s->marker[3 * k + u] * M_TO_CM;
            plpoin(1, &mx, &my, 4); /* open circle */
        }
    }
    plwidth(1.0);
    plcol0(COL_FG);
    plbox("bcnst", phc_plot_nice_step(f->a1 - f->a0, 4), 0, "bcnstv",
          phc_plot_nice_step(f->u1 - f->u0, 5), 0);
    snprintf(label, sizeof label, "%c (cm)", axis_name[a]);
    plmtex("b", 2.8, 0.5, 0.5, label);
    snprintf(label, sizeof label, "height %c (cm)", axis_name[u]);
    plmtex("l", 3.6, 0.5, 0.5, label);
    if (s->title && *s->title) {
        char *t = phc_plot_escape(s->title);
        if (t) {
            plschr(0.0, 0.9 * f->chr);
            plmtex("t", 1.2, 0.5, 0.5, t);
            plschr(0.0, f->chr);
        }
        free(t);
    }
}

static void draw_colour_bar(const frame *f, const char *label, double vx0, double vx1,
                            double vy0, double vy1)
{
    PLFLT cb_w, cb_h;
    PLINT label_opts[1] = {PL_COLORBAR_LABEL_RIGHT};
    const char *labels[1] = {label};
    const char *axis_opts[1] = {"bcvmtf"};
    PLFLT ticks[1] = {0.0};
    PLINT sub_ticks[1] = {0};
    PLINT n_values[1] = {2};
    PLFLT vals[2] = {f->lo, f->hi};
    const PLFLT *values[1] = {vals};
    plvpor(vx0, vx1, vy0, vy1);
    plwind(0, 1, 0, 1);
    plcol0(COL_FG);
    plcolorbar(&cb_w, &cb_h, PL_COLORBAR_GRADIENT,
               PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.015, 0.0,
               0.022 / (vx1 - vx0), 0.8, COL_BG, COL_FG, 1, 0.0, 1.0, 0, 0.0, 1, label_opts,
               labels, 1, axis_opts, ticks, sub_ticks, n_values, values);
}

int phc_shape_plot(const char *path, const phc_shape_panel *panels, size_t count,
                   const phc_shape_plot_options *options, phc_error *err)
{
    phc_shape_plot_options o = options ? *options : phc_shape_plot_options_default();
    if (!path || !*path)
        return phc_error_set(err, PHC_ERR_INVALID, "shape plot: no output path");
    if (!panels || count == 0 || count > 64)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: shape plot: 1 to 64 panels, got %zu",
                             path, count);
    if (o.across_axis < 0 || o.across_axis > 2 || o.up_axis < 0 || o.up_axis > 2 ||
        o.across_axis == o.up_axis)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: shape plot: across_axis %d and up_axis %d must be two "
                             "different axes among 0 (x), 1 (y), 2 (z)",
                             path, o.across_axis, o.up_axis);
    if (!(o.max_line_width > 0) || !isfinite(o.max_line_width))
        o.max_line_width = 7.0;
    int rc = check_panels(path, panels, count, err);
    if (rc)
        return rc;
    const size_t cols = o.columns ? (o.columns < count ? o.columns : count)
                                  : (size_t)ceil(sqrt((double)count));
    const size_t rows = (count + cols - 1) / cols;
    const int page_w = o.page_width > 0 ? o.page_width : (int)(560 * cols + 200);
    const int page_h = o.page_height > 0 ? o.page_height : (int)(520 * rows + 120);
    frame f = common_frame(panels, count, &o);
    f.chr = cols * rows > 2 ? 0.8 * CHAR_SCALE : CHAR_SCALE; /* smaller letters in grids */
    const int lib = phc_plot_library_open(path, err);
    if (lib)
        return lib;
    char *bar_label = phc_plot_escape(o.value_label ? o.value_label : "value");
    char *title = phc_plot_escape(o.title ? o.title : "");
    if (!bar_label || !title) {
        free(bar_label);
        free(title);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }

    phc_atomic_file *af = NULL;
    PLINT old_stream, strm = -1;
    int status = PHC_OK;
    plgstrm(&old_stream);
    const int dev = phc_plot_device_available("pngcairo");
    if (dev <= 0) {
        status = dev < 0 ? phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path)
                         : phc_error_set(err, PHC_ERR_INTERNAL,
                                         "%s: PLplot has no 'pngcairo' device (install "
                                         "plplot-driver-cairo)",
                                         path);
        goto done;
    }
    if ((status = phc_atomic_file_open(path, &af, err)))
        goto done;
    plmkstrm(&strm);
    if (strm < 0) {
        plsstrm(old_stream);
        status = phc_error_set(err, PHC_ERR_INTERNAL, "%s: no free PLplot stream", path);
        goto done;
    }
    plsdev("pngcairo");
    plsfnam(phc_atomic_file_temp_path(af));
    plspage(0.0, 0.0, page_w, page_h, 0, 0);
    plsfam(0, 0, 0);
    plscmap0n(COL_COUNT);
    plscol0(COL_BG, 255, 255, 255);
    plscol0(COL_FG, 0, 0, 0);
    plscol0(COL_MARKER, 200, 30, 30);
    plscol0(COL_PLAIN, 60, 110, 60);
    {
        PLFLT pos[5], r[5], g[5], b[5];
        for (int c = 0; c < 5; ++c) {
            pos[c] = c / 4.0;
            r[c] = DRY_WET[c][0] / 255.0;
            g[c] = DRY_WET[c][1] / 255.0;
            b[c] = DRY_WET[c][2] / 255.0;
        }
        plscmap1n(256);
        plscmap1l(1, 5, pos, r, g, b, NULL);
    }
    plinit();
    pladv(0);
    plschr(0.0, f.chr);
    {
        /* the panels fill [0.0, 0.86] of the page's width (the colour bar
         * and its label take the rest) and [0.02, 0.93] of its height */
        const double gx0 = 0.0, gx1 = f.any_value ? 0.86 : 0.98, gy0 = 0.02, gy1 = 0.93;
        const double cw = (gx1 - gx0) / (double)cols, ch = (gy1 - gy0) / (double)rows;
        const double aspect = (f.u1 - f.u0) / (f.a1 - f.a0);
        /* margins of each cell in character heights (page fractions): the
           y tick labels and axis label on the left, the x ones below, the
           panel title above */
        PLFLT def, ht, sx0, sx1, sy0, sy1;
        plgchr(&def, &ht);
        plgspa(&sx0, &sx1, &sy0, &sy1);
        const double cfx = ht / (sx1 - sx0), cfy = ht / (sy1 - sy0);
        const char *marker_label = NULL;
        for (size_t p = 0; p < count; ++p) {
            const size_t r = p / cols, c = p % cols;
            const double x0 = gx0 + c * cw, y1 = gy1 - r * ch;
            plvpas(x0 + 6.0 * cfx, x0 + cw - 1.0 * cfx, y1 - ch + 4.6 * cfy, y1 - 2.6 * cfy,
                   aspect);
            draw_panel(panels + p, &f, &o);
            if (panels[p].markers && !marker_label)
                marker_label = panels[p].marker_label ? panels[p].marker_label : "marker";
        }
        if (marker_label) { /* one key for the markers of every panel */
            char *t = phc_plot_escape(marker_label);
            char key[200];
            if (t) {
                snprintf(key, sizeof key, "o  %s", t);
                plvpor(0, 1, 0, 1);
                plwind(0, 1, 0, 1);
                plcol0(COL_MARKER);
                plptex(0.01, 0.03, 1, 0, 0.0, key);
                plcol0(COL_FG);
            }
            free(t);
        }
        if (*title) {
            plvpor(0, 1, 0, 1);
            plwind(0, 1, 0, 1);
            plschr(0.0, 1.25 * f.chr);
            plptex(0.5, 0.965, 1, 0, 0.5, title);
            plschr(0.0, f.chr);
        }
        if (f.any_value)
            draw_colour_bar(&f, bar_label, gx0, gx1, gy0 + 0.1, gy1 - 0.1);
    }
done:
    if (strm >= 0) {
        plsstrm(strm);
        plend1();
        plsstrm(old_stream);
    }
    status = phc_plot_file_finish(af, status, err);
    free(bar_label);
    free(title);
    return status;
}
