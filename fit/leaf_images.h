/* Sheets of leaf images for people: the aging sequence as a contact sheet,
 * observed photos beside simulated leaves.  Tiles sit on white paper in a
 * grid, each with a caption above it. */
#ifndef PHC_LEAF_IMAGES_H
#define PHC_LEAF_IMAGES_H

#include <stddef.h>

#include "measurements/photo.h"
#include "model/status.h"

/* Tiles n images (any sizes; each cell is as large as the largest tile)
 * `columns` per row with `gap` px of white between them and a caption
 * band above each tile (captions may be NULL, or single entries NULL).
 * A NULL tile leaves its cell white.
 * *out is allocated here. */
int phc_leaf_sheet(const phc_image *const *tiles, const char *const *captions, size_t n, size_t columns,
                   size_t gap, phc_image *out, phc_error *err);

/* An image of a scalar map (values in [lo, hi]; viridis) with white off the
 * mask, for sheets.  *out is allocated here. */
int phc_leaf_map_image(size_t width, size_t height, const double *values, const unsigned char *mask,
                       double lo, double hi, phc_image *out, phc_error *err);

/* Enlarges an image by an integer factor (nearest neighbour, so model
 * pixels stay visible as squares). */
int phc_leaf_enlarge(const phc_image *img, size_t factor, phc_image *out, phc_error *err);

/* A vertical viridis colour bar from lo (bottom) to hi (top), five labelled
 * ticks and a title, as a 150 px wide tile of height `height` (>= 60). */
int phc_leaf_colour_bar(size_t height, double lo, double hi, const char *title, phc_image *out,
                        phc_error *err);

#endif /* PHC_LEAF_IMAGES_H */
