/* Sheets of leaf images: see leaf_images.h. */
#include "fit/leaf_images.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Caption band height, px. */
#define CAPTION_HEIGHT 22

int phc_leaf_sheet(const phc_image *const *tiles, const char *const *captions, size_t n, size_t columns,
                   size_t gap, phc_image *out, phc_error *err)
{
    if (!n || !columns)
        return phc_error_set(err, PHC_ERR_INVALID, "a sheet needs at least one tile and one column");
    size_t tw = 0, th = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!tiles[i])
            continue; /* an empty cell */
        tw = tiles[i]->width > tw ? tiles[i]->width : tw;
        th = tiles[i]->height > th ? tiles[i]->height : th;
    }
    if (!tw || !th)
        return phc_error_set(err, PHC_ERR_INVALID, "a sheet needs at least one tile");
    const size_t cols = n < columns ? n : columns, rows = (n + columns - 1) / columns;
    const size_t cap = captions ? CAPTION_HEIGHT : 0;
    const size_t W = gap + cols * (tw + gap), H = gap + rows * (th + cap + gap);
    int rc;
    if ((rc = phc_image_alloc(out, W, H, err)))
        return rc;
    for (size_t i = 0; i < 3 * W * H; ++i)
        out->data[i] = 1; /* white paper */
    for (size_t i = 0; i < n; ++i) {
        const phc_image *t = tiles[i];
        if (!t)
            continue;
        const size_t ox = gap + (i % columns) * (tw + gap) + (tw - t->width) / 2;
        const size_t oy = gap + (i / columns) * (th + cap + gap) + cap + (th - t->height) / 2;
        for (size_t y = 0; y < t->height; ++y)
            memcpy(out->data + 3 * (ox + W * (oy + y)), t->data + 3 * t->width * y, 3 * t->width * sizeof(double));
        if (captions && captions[i]) {
            const size_t cx = gap + (i % columns) * (tw + gap), cy = gap + (i / columns) * (th + cap + gap);
            if ((rc = phc_photo_draw_text(out, captions[i], cx + 2, cy + cap - 6, 0.5, err))) {
                phc_image_free(out);
                return rc;
            }
        }
    }
    return PHC_OK;
}

int phc_leaf_map_image(size_t width, size_t height, const double *values, const unsigned char *mask,
                       double lo, double hi, phc_image *out, phc_error *err)
{
    double lut[3 * 256];
    int rc;
    if ((rc = phc_photo_viridis(lut, err)) || (rc = phc_image_alloc(out, width, height, err)))
        return rc;
    for (size_t i = 0; i < width * height; ++i) {
        double *o = out->data + 3 * i;
        if (mask && !mask[i]) {
            o[0] = o[1] = o[2] = 1;
            continue;
        }
        const double u = hi > lo ? (values[i] - lo) / (hi - lo) : 0.5;
        const size_t k = (size_t)lround(255 * fmin(fmax(u, 0), 1));
        memcpy(o, lut + 3 * k, 3 * sizeof(double));
    }
    return PHC_OK;
}

int phc_leaf_enlarge(const phc_image *img, size_t factor, phc_image *out, phc_error *err)
{
    int rc;
    if (!factor)
        factor = 1;
    if ((rc = phc_image_alloc(out, img->width * factor, img->height * factor, err)))
        return rc;
    for (size_t y = 0; y < out->height; ++y)
        for (size_t x = 0; x < out->width; ++x)
            memcpy(out->data + 3 * (x + out->width * y), img->data + 3 * (x / factor + img->width * (y / factor)),
                   3 * sizeof(double));
    return PHC_OK;
}

/* The colour bar: see leaf_images.h. */
int phc_leaf_colour_bar(size_t height, double lo, double hi, const char *title, phc_image *out, phc_error *err)
{
    if (height < 60)
        return phc_error_set(err, PHC_ERR_INVALID, "colour bar: height %zu px is below 60", height);
    const size_t W = 150, x0 = 12, x1 = 42, y0 = 24, y1 = height - 14;
    double lut[3 * 256];
    int rc;
    if ((rc = phc_photo_viridis(lut, err)) || (rc = phc_image_alloc(out, W, height, err)))
        return rc;
    for (size_t i = 0; i < 3 * W * height; ++i)
        out->data[i] = 1;
    for (size_t y = y0; y <= y1; ++y) {
        const size_t k = (size_t)lround(255.0 * (double)(y1 - y) / (double)(y1 - y0));
        for (size_t x = x0; x <= x1; ++x)
            memcpy(out->data + 3 * (x + W * y), lut + 3 * k, 3 * sizeof(double));
    }
    for (int q = 0; q <= 4; ++q) {
        char lab[32];
        const double v = lo + (hi - lo) * q / 4.0;
        const size_t y = y1 - (size_t)lround((double)(y1 - y0) * q / 4.0);
        for (size_t x = x1 + 1; x <= x1 + 5; ++x)
            for (int c = 0; c < 3; ++c)
                out->data[3 * (x + W * y) + c] = 0;
        snprintf(lab, sizeof lab, "%.2g", v);
        if ((rc = phc_photo_draw_text(out, lab, x1 + 9, y + 5, 0.45, err)))
            return rc;
    }
    return phc_photo_draw_text(out, title, 4, 14, 0.45, err);
}
