/* Plots of the 3-D soil model's fields (model/soil.h), drawn with PLplot's
 * cairo PNG driver (pngcairo) in the style of fit/plots.h: white background,
 * labelled axes with units, 1000 x 700 pixels, no state kept between calls.
 *
 * Layout of a field f: voxel (i, j, k) is f[i + nx (j + ny k)], x east,
 * y north, z up, k = nz - 1 the surface layer; voxels are cubes of edge dx
 * (m). */
#ifndef PHC_SOIL_PLOTS_H
#define PHC_SOIL_PLOTS_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A vertical slice of f as a colour map of the voxels (one flat cell per
 * voxel, no interpolation) with a labelled colour bar, written to `path`
 * (PNG; written to a temporary name and renamed into place).
 *
 * axis 'x': the x-z slice at row j = index (index < ny), horizontal axis
 *           "x (m)";
 * axis 'y': the y-z slice at column i = index (index < nx), horizontal axis
 *           "y (m)".
 * The horizontal axis runs from 0 at the grid's corner to n dx; the vertical
 * axis is "depth (m)", 0 at the top of the surface layer, increasing
 * downwards to nz dx.  Both axes have the same scale (voxels are square)
 * unless the slice is more than 6 times wider than deep or vice versa.
 *
 * title: the plot title (NULL or "": none); colorbar_label: the quantity
 * with its unit, e.g. "water w (m³/m³)".  Text is plain UTF-8 ('#' prints
 * as '#').
 * vmin, vmax: colour range; NAN, NAN for the finite range of the slice.
 * With a given range, values outside it take the end colours and the colour
 * bar gets a pointed cap at that end, so saturation is visible.
 * Non-finite values are drawn grey and are not part of the automatic range.
 * The colour map is ColorBrewer's sequential "Blues" (light = low, dark =
 * high; monotone in lightness, readable in grey print and by colour-blind
 * readers).
 *
 * Returns PHC_OK, PHC_ERR_INVALID (bad arguments: the message says which),
 * PHC_ERR_IO (cannot write `path`), PHC_ERR_NOMEM or PHC_ERR_INTERNAL (no
 * pngcairo device). */
int phc_plot_soil_slice(const char *path, const char *title,
                        const char *colorbar_label, const double *f,
                        size_t nx, size_t ny, size_t nz, double dx, char axis,
                        size_t index, double vmin, double vmax,
                        phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_SOIL_PLOTS_H */
