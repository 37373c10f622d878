/* The PLplot functions libphytocal draws with (fit/plots.c, plot_file.c,
 * shape_plots.c, soil_plots.c, growth_outputs.c, sensitivity_plots.c,
 * profile_plots.c, mcmc_plots.c), forwarded to libplplot opened on the first
 * plot (measurements/lazy_library_internal.h; phc_plot_library_open opens it and
 * reports when it cannot): a run without plots never loads PLplot, its
 * freetype, qhull, shapelib and csiro libraries.  Prototypes: plplot.h. */
#include <plplot.h>

#include "measurements/lazy_library_internal.h"

#define L phc_lazy_plplot

PHC_LAZY_FORWARD_VOID(L, plgDevs, (PLCHAR_VECTOR **menu, PLCHAR_VECTOR **names, int *n), (menu, names, n))
PHC_LAZY_FORWARD_VOID(L, c_pladv, (PLINT page), (page))
PHC_LAZY_FORWARD_VOID(L, c_plbox,
                      (PLCHAR_VECTOR xopt, PLFLT xtick, PLINT nxsub, PLCHAR_VECTOR yopt, PLFLT ytick, PLINT nysub),
                      (xopt, xtick, nxsub, yopt, ytick, nysub))
PHC_LAZY_FORWARD_VOID(L, c_plcol0, (PLINT icol0), (icol0))
PHC_LAZY_FORWARD_VOID(L, c_plcol1, (PLFLT col1), (col1))
PHC_LAZY_FORWARD_VOID(L, c_plcolorbar,
                      (PLFLT_NC_SCALAR w, PLFLT_NC_SCALAR h, PLINT opt, PLINT position, PLFLT x, PLFLT y,
                       PLFLT x_length, PLFLT y_length, PLINT bg_color, PLINT bb_color, PLINT bb_style,
                       PLFLT low_cap_color, PLFLT high_cap_color, PLINT cont_color, PLFLT cont_width,
                       PLINT n_labels, PLINT_VECTOR label_opts, PLCHAR_MATRIX labels, PLINT n_axes,
                       PLCHAR_MATRIX axis_opts, PLFLT_VECTOR ticks, PLINT_VECTOR sub_ticks,
                       PLINT_VECTOR n_values, PLFLT_MATRIX values),
                      (w, h, opt, position, x, y, x_length, y_length, bg_color, bb_color, bb_style,
                       low_cap_color, high_cap_color, cont_color, cont_width, n_labels, label_opts, labels,
                       n_axes, axis_opts, ticks, sub_ticks, n_values, values))
PHC_LAZY_FORWARD_VOID(L, c_plend1, (void), ())
PHC_LAZY_FORWARD_VOID(L, c_plerry, (PLINT n, PLFLT_VECTOR x, PLFLT_VECTOR ymin, PLFLT_VECTOR ymax),
                      (n, x, ymin, ymax))
PHC_LAZY_FORWARD_VOID(L, c_plfill, (PLINT n, PLFLT_VECTOR x, PLFLT_VECTOR y), (n, x, y))
PHC_LAZY_FORWARD_VOID(L, c_plgchr, (PLFLT_NC_SCALAR def, PLFLT_NC_SCALAR ht), (def, ht))
PHC_LAZY_FORWARD_VOID(L, c_plgspa,
                      (PLFLT_NC_SCALAR xmin, PLFLT_NC_SCALAR xmax, PLFLT_NC_SCALAR ymin, PLFLT_NC_SCALAR ymax),
                      (xmin, xmax, ymin, ymax))
PHC_LAZY_FORWARD_VOID(L, c_plgstrm, (PLINT_NC_SCALAR strm), (strm))
PHC_LAZY_FORWARD_VOID(L, c_plgvpd,
                      (PLFLT_NC_SCALAR xmin, PLFLT_NC_SCALAR xmax, PLFLT_NC_SCALAR ymin, PLFLT_NC_SCALAR ymax),
                      (xmin, xmax, ymin, ymax))
PHC_LAZY_FORWARD_VOID(L, c_plimagefr,
                      (PLFLT_MATRIX idata, PLINT nx, PLINT ny, PLFLT xmin, PLFLT xmax, PLFLT ymin, PLFLT ymax,
                       PLFLT zmin, PLFLT zmax, PLFLT valuemin, PLFLT valuemax, PLTRANSFORM_callback pltr,
                       PLPointer pltr_data),
                      (idata, nx, ny, xmin, xmax, ymin, ymax, zmin, zmax, valuemin, valuemax, pltr, pltr_data))
PHC_LAZY_FORWARD_VOID(L, c_plinit, (void), ())
PHC_LAZY_FORWARD_VOID(L, c_pljoin, (PLFLT x1, PLFLT y1, PLFLT x2, PLFLT y2), (x1, y1, x2, y2))
PHC_LAZY_FORWARD_VOID(L, c_pllegend,
                      (PLFLT_NC_SCALAR w, PLFLT_NC_SCALAR h, PLINT opt, PLINT position, PLFLT x, PLFLT y,
                       PLFLT plot_width, PLINT bg_color, PLINT bb_color, PLINT bb_style, PLINT nrow,
                       PLINT ncolumn, PLINT nlegend, PLINT_VECTOR opt_array, PLFLT text_offset,
                       PLFLT text_scale, PLFLT text_spacing, PLFLT text_justification,
                       PLINT_VECTOR text_colors, PLCHAR_MATRIX text, PLINT_VECTOR box_colors,
                       PLINT_VECTOR box_patterns, PLFLT_VECTOR box_scales, PLFLT_VECTOR box_line_widths,
                       PLINT_VECTOR line_colors, PLINT_VECTOR line_styles, PLFLT_VECTOR line_widths,
                       PLINT_VECTOR symbol_colors, PLFLT_VECTOR symbol_scales, PLINT_VECTOR symbol_numbers,
                       PLCHAR_MATRIX symbols),
                      (w, h, opt, position, x, y, plot_width, bg_color, bb_color, bb_style, nrow, ncolumn,
                       nlegend, opt_array, text_offset, text_scale, text_spacing, text_justification,
                       text_colors, text, box_colors, box_patterns, box_scales, box_line_widths, line_colors,
                       line_styles, line_widths, symbol_colors, symbol_scales, symbol_numbers, symbols))
PHC_LAZY_FORWARD_VOID(L, c_plline, (PLINT n, PLFLT_VECTOR x, PLFLT_VECTOR y), (n, x, y))
PHC_LAZY_FORWARD_VOID(L, c_pllsty, (PLINT lin), (lin))
PHC_LAZY_FORWARD_VOID(L, c_plmkstrm, (PLINT_NC_SCALAR strm), (strm))
PHC_LAZY_FORWARD_VOID(L, c_plmtex, (PLCHAR_VECTOR side, PLFLT disp, PLFLT pos, PLFLT just, PLCHAR_VECTOR text),
                      (side, disp, pos, just, text))
PHC_LAZY_FORWARD_VOID(L, c_plpoin, (PLINT n, PLFLT_VECTOR x, PLFLT_VECTOR y, PLINT code), (n, x, y, code))
PHC_LAZY_FORWARD_VOID(L, c_plptex, (PLFLT x, PLFLT y, PLFLT dx, PLFLT dy, PLFLT just, PLCHAR_VECTOR text),
                      (x, y, dx, dy, just, text))
PHC_LAZY_FORWARD_VOID(L, c_plschr, (PLFLT def, PLFLT scale), (def, scale))
PHC_LAZY_FORWARD_VOID(L, c_plscmap0n, (PLINT ncol0), (ncol0))
PHC_LAZY_FORWARD_VOID(L, c_plscmap1l,
                      (PLBOOL itype, PLINT npts, PLFLT_VECTOR intensity, PLFLT_VECTOR coord1,
                       PLFLT_VECTOR coord2, PLFLT_VECTOR coord3, PLBOOL_VECTOR alt_hue_path),
                      (itype, npts, intensity, coord1, coord2, coord3, alt_hue_path))
PHC_LAZY_FORWARD_VOID(L, c_plscmap1n, (PLINT ncol1), (ncol1))
PHC_LAZY_FORWARD_VOID(L, c_plscol0, (PLINT icol0, PLINT r, PLINT g, PLINT b), (icol0, r, g, b))
PHC_LAZY_FORWARD_VOID(L, c_plscol0a, (PLINT icol0, PLINT r, PLINT g, PLINT b, PLFLT alpha),
                      (icol0, r, g, b, alpha))
PHC_LAZY_FORWARD_VOID(L, c_plsdev, (PLCHAR_VECTOR devname), (devname))
PHC_LAZY_FORWARD(L, PLINT, c_plsetopt, (PLCHAR_VECTOR opt, PLCHAR_VECTOR optarg), (opt, optarg))
PHC_LAZY_FORWARD_VOID(L, c_plsfam, (PLINT fam, PLINT num, PLINT bmax), (fam, num, bmax))
PHC_LAZY_FORWARD_VOID(L, c_plsfnam, (PLCHAR_VECTOR fnam), (fnam))
PHC_LAZY_FORWARD_VOID(L, c_plslabelfunc, (PLLABEL_FUNC_callback label_func, PLPointer label_data),
                      (label_func, label_data))
PHC_LAZY_FORWARD_VOID(L, c_plsmema, (PLINT maxx, PLINT maxy, PLPointer plotmem), (maxx, maxy, plotmem))
PHC_LAZY_FORWARD_VOID(L, c_plspage, (PLFLT xp, PLFLT yp, PLINT xleng, PLINT yleng, PLINT xoff, PLINT yoff),
                      (xp, yp, xleng, yleng, xoff, yoff))
PHC_LAZY_FORWARD_VOID(L, c_plsstrm, (PLINT strm), (strm))
PHC_LAZY_FORWARD_VOID(L, c_plssym, (PLFLT def, PLFLT scale), (def, scale))
PHC_LAZY_FORWARD_VOID(L, c_plstring, (PLINT n, PLFLT_VECTOR x, PLFLT_VECTOR y, PLCHAR_VECTOR string),
                      (n, x, y, string))
PHC_LAZY_FORWARD_VOID(L, c_plsxax, (PLINT digmax, PLINT digits), (digmax, digits))
PHC_LAZY_FORWARD_VOID(L, c_plsyax, (PLINT digmax, PLINT digits), (digmax, digits))
PHC_LAZY_FORWARD_VOID(L, c_plsym, (PLINT n, PLFLT_VECTOR x, PLFLT_VECTOR y, PLINT code), (n, x, y, code))
PHC_LAZY_FORWARD_VOID(L, c_plvpas, (PLFLT xmin, PLFLT xmax, PLFLT ymin, PLFLT ymax, PLFLT aspect),
                      (xmin, xmax, ymin, ymax, aspect))
PHC_LAZY_FORWARD_VOID(L, c_plvpor, (PLFLT xmin, PLFLT xmax, PLFLT ymin, PLFLT ymax), (xmin, xmax, ymin, ymax))
PHC_LAZY_FORWARD_VOID(L, c_plwidth, (PLFLT width), (width))
PHC_LAZY_FORWARD_VOID(L, c_plwind, (PLFLT xmin, PLFLT xmax, PLFLT ymin, PLFLT ymax), (xmin, xmax, ymin, ymax))
