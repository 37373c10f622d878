/* Slice plots of the soil model's 3-D fields: see soil_plots.h.
 *
 * Safety as in fit/plots.c (whose helpers are static there): PLplot's fatal
 * errors exit the process, so everything PLplot could reject is checked
 * first (the pngcairo device exists, the output file can be created, every
 * range is finite and non-empty); each call makes and ends its own stream
 * and restores the caller's; the PNG goes to a temporary file that is
 * checked for a complete PNG and renamed into place. */
#include "fit/soil_plots.h"
#include "fit/plot_file.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <plplot.h>

enum { PAGE_W = 1000, PAGE_H = 700 };

enum { COL_BG = 0, COL_FG = 1, COL_NODATA = 2, COL_COUNT = 3 };

static const double CHAR_SCALE = 1.1;
static const double TITLE_SCALE = 1.2;
/* Largest width/depth (or depth/width) ratio drawn at equal scale. */
static const double MAX_ASPECT = 6.0;

/* ColorBrewer "Blues", 9 classes (Brewer 2003), light to dark. */
static const unsigned char BLUES[9][3] = {
    {247, 251, 255}, {222, 235, 247}, {198, 219, 239},
    {158, 202, 225}, {107, 174, 214}, {66, 146, 198},
    {33, 113, 181},  {8, 81, 156},    {8, 48, 107}};





/* The slice as PLplot wants it: img[h][r], h along the horizontal axis,
 * r = 0 the top (surface) layer.  Non-finite values become `nodata`, which
 * lies below the plotted z range so plimagefr leaves those cells out (the
 * grey background shows); finite ones are limited to [lo, hi] so the end
 * colours mark saturation (the colour bar caps say so). */
static PLFLT **slice_image(const double *f, size_t nx, size_t ny, size_t nz,
                           char axis, size_t index, size_t nh, double lo,
                           double hi, double nodata)
{
    PLFLT **img = malloc(nh * sizeof *img);
    PLFLT *data = malloc(nh * nz * sizeof *data);
    if (!img || !data) {
        free(img);
        free(data);
        return NULL;
    }
    for (size_t h = 0; h < nh; ++h) {
        img[h] = data + h * nz;
        for (size_t r = 0; r < nz; ++r) {
            size_t k = nz - 1 - r;
            size_t i = axis == 'x' ? h : index;
            size_t j = axis == 'x' ? index : h;
            double v = f[i + nx * (j + ny * k)];
            img[h][r] = !isfinite(v) ? nodata : v < lo ? lo : v > hi ? hi : v;
        }
    }
    return img;
}

int phc_plot_soil_slice(const char *path, const char *title,
                        const char *colorbar_label, const double *f,
                        size_t nx, size_t ny, size_t nz, double dx, char axis,
                        size_t index, double vmin, double vmax,
                        phc_error *err)
{
    phc_error_clear(err);
    if (!path || !*path)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "soil slice plot: no output path given");
    if (!f)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil slice plot: field is NULL", path);
    if (nx == 0 || ny == 0 || nz == 0 || ny > SIZE_MAX / nx ||
        nz > SIZE_MAX / (nx * ny) || nx > INT32_MAX || ny > INT32_MAX ||
        nz > INT32_MAX)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil slice plot: expected a grid of at "
                             "least 1 x 1 x 1 voxels, found %zu x %zu x %zu",
                             path, nx, ny, nz);
    if (!(dx > 0.0) || !isfinite(dx) || !isfinite(dx * (double)nx) ||
        !isfinite(dx * (double)ny) || !isfinite(dx * (double)nz))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil slice plot: expected a voxel size "
                             "dx > 0 m, found %g", path, dx);
    if (axis != 'x' && axis != 'y')
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil slice plot: axis: expected 'x' (x-z "
                             "slice at row j) or 'y' (y-z slice at column "
                             "i), found '%c'", path, axis);
    size_t limit = axis == 'x' ? ny : nx;
    if (index >= limit)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil slice plot: %s = %zu outside the grid "
                             "(expected < %zu)", path,
                             axis == 'x' ? "row j" : "column i", index, limit);
    int auto_range = isnan(vmin) && isnan(vmax);
    if (!auto_range && !(isfinite(vmin) && isfinite(vmax) && vmin < vmax))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil slice plot: colour range: expected "
                             "finite vmin < vmax or NAN, NAN, found [%g, %g]",
                             path, vmin, vmax);

    size_t nh = axis == 'x' ? nx : ny;
    /* Range of the slice's finite values and whether any lie outside the
     * given range or are missing. */
    double lo = INFINITY, hi = -INFINITY;
    size_t missing = 0;
    for (size_t h = 0; h < nh; ++h)
        for (size_t k = 0; k < nz; ++k) {
            size_t i = axis == 'x' ? h : index;
            size_t j = axis == 'x' ? index : h;
            double v = f[i + nx * (j + ny * k)];
            if (!isfinite(v)) {
                ++missing;
                continue;
            }
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
    PLINT caps = 0;
    if (auto_range) {
        if (missing == nh * nz)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: soil slice plot: no finite value in "
                                 "the slice (%s = %zu)", path,
                                 axis == 'x' ? "j" : "i", index);
        vmin = lo;
        vmax = hi;
        double mag = fmax(fabs(lo), fabs(hi));
        if (!isfinite(vmax - vmin))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: soil slice plot: values too large to "
                                 "plot", path);
        if (vmax - vmin <= 1e-12 * mag) {
            /* A uniform slice: centre its colour in a small range. */
            double half = mag > 0.0 ? 0.05 * mag : 1.0;
            vmin = lo - half;
            vmax = hi + half;
        }
    } else {
        if (lo < vmin)
            caps |= PL_COLORBAR_CAP_LOW;
        if (hi > vmax)
            caps |= PL_COLORBAR_CAP_HIGH;
    }
    double nodata = vmin - (vmax - vmin) - 1.0;
    if (!isfinite(nodata))
        nodata = -HUGE_VAL;

    const int lib = phc_plot_library_open(path, err);
    if (lib)
        return lib;
    char *t_title = phc_plot_escape(title), *t_bar = phc_plot_escape(colorbar_label);
    char sub[160];
    double pos = ((double)index + 0.5) * dx;
    snprintf(sub, sizeof sub, "slice at %s = %zu (%s = %.4g m)",
             axis == 'x' ? "row j" : "column i", index,
             axis == 'x' ? "y" : "x", pos);
    PLFLT **img = slice_image(f, nx, ny, nz, axis, index, nh, vmin, vmax,
                              nodata);
    if (!t_title || !t_bar || !img) {
        free(t_title);
        free(t_bar);
        if (img)
            free(img[0]);
        free(img);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }

    int status = PHC_OK;
    phc_atomic_file *af = NULL;
    PLINT old_stream, strm = -1;
    plgstrm(&old_stream);
    int dev = phc_plot_device_available("pngcairo");
    if (dev <= 0) {
        status = dev < 0 ? phc_error_set(err, PHC_ERR_NOMEM,
                                         "%s: out of memory", path)
                         : phc_error_set(err, PHC_ERR_INTERNAL,
                                         "%s: PLplot has no 'pngcairo' "
                                         "device (install "
                                         "plplot-driver-cairo)", path);
        goto done;
    }
    status = phc_atomic_file_open(path, &af, err);
    if (status)
        goto done;
    plmkstrm(&strm);
    if (strm < 0) {
        plsstrm(old_stream);
        status = phc_error_set(err, PHC_ERR_INTERNAL,
                               "%s: no free PLplot stream", path);
        goto done;
    }

    plsdev("pngcairo");
    plsfnam(phc_atomic_file_temp_path(af));
    plspage(0.0, 0.0, PAGE_W, PAGE_H, 0, 0);
    plsfam(0, 0, 0);
    plscmap0n(16);
    plscol0(COL_BG, 255, 255, 255);
    plscol0(COL_FG, 0, 0, 0);
    plscol0(COL_NODATA, 170, 170, 170);
    {
        PLFLT pos_[9], r[9], g[9], b[9];
        for (int c = 0; c < 9; ++c) {
            pos_[c] = c / 8.0;
            r[c] = BLUES[c][0] / 255.0;
            g[c] = BLUES[c][1] / 255.0;
            b[c] = BLUES[c][2] / 255.0;
        }
        plscmap1n(256);
        plscmap1l(1, 9, pos_, r, g, b, NULL);
    }
    plinit();
    pladv(0);
    plschr(0.0, CHAR_SCALE);

    /* Viewport: margins in character heights (page fractions); then the
     * largest box of the slice's aspect ratio inside them. */
    PLFLT def, ht, sx0, sx1, sy0, sy1;
    plgchr(&def, &ht);
    plgspa(&sx0, &sx1, &sy0, &sy1);
    double cfx = ht / (sx1 - sx0), cfy = ht / (sy1 - sy0);
    double width = (double)nh * dx, depth = (double)nz * dx;
    double aspect = depth / width;
    if (aspect > MAX_ASPECT)
        aspect = MAX_ASPECT;
    if (aspect < 1.0 / MAX_ASPECT)
        aspect = 1.0 / MAX_ASPECT;
    /* Left: y tick labels (~4 characters) and the axis label.  Right: the
     * colour bar (0.02 gap + 0.035 of the page), its tick labels and its
     * label. */
    double left = 8.0 * cfx, right = 0.035 + 0.02 + 8.5 * cfx;
    double bottom = 4.8 * cfy, top = 5.2 * cfy;
    plvpas(left, 1.0 - right, bottom, 1.0 - top, aspect);

    plwind(0.0, width, depth, 0.0);  /* depth grows downwards */
    PLFLT vx0, vx1, vy0, vy1;
    plgvpd(&vx0, &vx1, &vy0, &vy1);

    /* Grey under the image shows missing (non-finite) voxels. */
    if (missing) {
        PLFLT bx[4] = {0.0, width, width, 0.0};
        PLFLT by[4] = {0.0, 0.0, depth, depth};
        plcol0(COL_NODATA);
        plfill(4, bx, by);
    }
    plimagefr((PLFLT_MATRIX)img, (PLINT)nh, (PLINT)nz, 0.0, width, 0.0,
              depth, vmin, vmax, vmin, vmax, NULL, NULL);

    /* about one x tick label per 0.1 of the page, so narrow slices stay readable */
    double xticks = 10.0 * (vx1 - vx0) < 2.0 ? 2.0 : 10.0 * (vx1 - vx0) > 6.0 ? 6.0 : 10.0 * (vx1 - vx0);
    double xstep = phc_plot_nice_step(width, xticks), ystep = phc_plot_nice_step(depth, 6.0);
    plcol0(COL_FG);
    plwidth(1.2);
    plbox("bcnst", xstep, 0, "bcnstv", ystep, 0);
    plmtex("b", 3.0, 0.5, 0.5, axis == 'x' ? "x (m)" : "y (m)");
    plmtex("l", 5.2, 0.5, 0.5, "depth (m)");
    if (*t_title) {
        plschr(0.0, CHAR_SCALE * TITLE_SCALE);
        plmtex("t", 2.6, 0.5, 0.5, t_title);
        plschr(0.0, CHAR_SCALE);
    }
    plschr(0.0, CHAR_SCALE * 0.85);
    plmtex("t", 0.8, 0.5, 0.5, sub);
    if (missing)
        plmtex("b", 3.2, 1.0, 1.0, "grey: no value (NaN)");
    plschr(0.0, CHAR_SCALE);

    {
        /* Colour bar right of the plot, as tall as the plot. */
        PLFLT cb_w, cb_h;
        PLINT label_opts[1] = {PL_COLORBAR_LABEL_RIGHT};
        const char *labels[1] = {t_bar};
        const char *axis_opts[1] = {"bcvmtif"}; /* f: fixed-point labels, no separate exponent */
        PLFLT ticks[1] = {0.0};
        PLINT sub_ticks[1] = {0};
        PLINT n_values[1] = {2};
        PLFLT vals[2] = {vmin, vmax};
        const PLFLT *values[1] = {vals};
        plcol0(COL_FG);
        plcolorbar(&cb_w, &cb_h,
                   PL_COLORBAR_IMAGE | caps,
                   PL_POSITION_RIGHT | PL_POSITION_OUTSIDE |
                       PL_POSITION_VIEWPORT,
                   0.02, 0.0, 0.035 / (vx1 - vx0), 1.0, COL_BG, COL_FG, 1,
                   0.0, 1.0, 0, 0.0, 1, label_opts, labels, 1, axis_opts,
                   ticks, sub_ticks, n_values, values);
    }

done:
    if (strm >= 0) {
        plsstrm(strm);
        plend1();
        plsstrm(old_stream);
    }
    status = phc_plot_file_finish(af, status, err);
    free(img[0]);
    free(img);
    free(t_title);
    free(t_bar);
    return status;
}
