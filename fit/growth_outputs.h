/* Files describing a grown plant (model/growth.h): the root system as RSML,
 * the whole plant as a plant graph for the water model, and a side view
 * as a PNG.  Used by the root_shoot data set's simulate and fit outputs and
 * by the Rhizomorph notebooks. */
#ifndef PHC_GROWTH_OUTPUTS_H
#define PHC_GROWTH_OUTPUTS_H

#include "model/growth.h"
#include "model/status.h"

/* The root system as RSML 1.0 (unit m, 3-D): one plant, one root per
 * branch (phc_growth_branches), diameters on every point.  Written to a
 * temporary name and renamed into place. */
int phc_growth_write_rsml(const phc_growth *g, const char *path, phc_error *err);

/* The whole plant in phytocal's native plant-graph format
 * (measurements/plant_io.h), lengths in m. */
int phc_growth_write_plant_graph(const phc_growth *g, const char *path, phc_error *err);

/* Side view (x horizontal, z vertical, m) of one or more plants as panels
 * of one PNG: shoots green above the soil surface, roots brown below, line
 * width growing with segment radius, the soil surface and box outline
 * (soil_top, box_x0, box_x1 in m; box_x1 <= box_x0 for none).  titles[i]
 * is panel i's title. */
int phc_growth_plot_side(const char *path, const phc_growth *const *plants,
                         const char *const *titles, size_t n, double soil_top, double box_x0,
                         double box_x1, phc_error *err);

#endif /* PHC_GROWTH_OUTPUTS_H */
