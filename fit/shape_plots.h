/* Side views of plant shapes (wilting paper Figs. 1, 5, 7, 9, 10; climbing
 * plants Fig. 6): one PNG with one panel per shape, drawn with PLplot's
 * cairo driver.
 *
 * Each panel is an orthographic projection of a plant graph's segments onto
 * two of its axes (default x across, z up: the wilting paper's graph files
 * have z up), every panel at the same scale and with the same limits so
 * shapes can be compared by eye.  A segment is a line from its head to its
 * tail, its width proportional to its radius (the thickest segment of the
 * whole figure gets `max_line_width`), coloured by a value per segment
 * (relative water content by default) on a dry-brown to wet-green scale with
 * a labelled colour bar.  Axes in cm.  Optional markers (tracked points of a
 * time-lapse, supports) are drawn on top.
 *
 * White background, labelled axes with units, a title per panel; the file
 * is written to a temporary name and renamed into place
 * (measurements/atomic_file.h), so an earlier figure survives a failed
 * call. */
#ifndef PHC_SHAPE_PLOTS_H
#define PHC_SHAPE_PLOTS_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_shape_panel {
    size_t n;              /* segments, >= 1 */
    const double *head;    /* 3n: x,y,z of each segment's root end, m */
    const double *tail;    /* 3n: x,y,z of each segment's far end, m */
    const double *radius;  /* n: m, > 0 (line width) */
    const double *value;   /* n: colour value (e.g. relative water content, 1);
                              NULL: every segment in the middle colour */
    const char *title;     /* panel title (NULL: none) */
    size_t markers;        /* points drawn on top, may be 0 */
    const double *marker;  /* 3·markers: x,y,z, m */
    const char *marker_label; /* key text of the markers (NULL: "marker") */
} phc_shape_panel;

typedef struct phc_shape_plot_options {
    const char *title;        /* figure title (NULL: none) */
    const char *value_label;  /* colour bar label with unit
                                 (default "relative water content (1)") */
    double value_min, value_max; /* colour range; value_max <= value_min:
                                    the range of the values drawn */
    int across_axis;          /* 0, 1, 2 = x, y, z; default 0 */
    int up_axis;              /* default 2 */
    size_t columns;           /* panels per row; 0: ceil(sqrt(count)) */
    double max_line_width;    /* PLplot pen width of the thickest segment, default 7 */
    int page_width, page_height; /* pixels; 0: 560 per column + 200, 520 per row + 120 */
} phc_shape_plot_options;

/* The defaults described above. */
phc_shape_plot_options phc_shape_plot_options_default(void);

/* Draws `count` panels (1..64) into the PNG at `path`.  PHC_ERR_INVALID when
 * a panel has no segments, a NULL array, a non-finite coordinate or a radius
 * that is not positive (the message names the panel and segment), or the
 * axes are not two different ones of 0..2; PHC_ERR_IO when the file cannot
 * be written; PHC_ERR_INTERNAL when PLplot lacks the pngcairo device. */
int phc_shape_plot(const char *path, const phc_shape_panel *panels, size_t count,
                   const phc_shape_plot_options *options, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_SHAPE_PLOTS_H */
