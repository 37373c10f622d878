/* A climbing plant as a mesh file a viewer opens (`phytocal grow`'s
 * plant.obj; notebooks_c/climbing_fig13_wall): Wavefront OBJ, metres, one
 * object per part:
 *   o stems    every segment (model/climbing_growth.h) as an open tube of
 *              `sides` quads from its base to its tip at its current radius,
 *              each quad as two triangles
 *   o leaves   every blade as one square (two triangles, counter-clockwise
 *              seen from its normal; phc_climbing_leaf_quad)
 *   o support  the support mesh's triangles, when given
 * Written with 17 significant digits. */
#ifndef PHC_GROW_MESH_H
#define PHC_GROW_MESH_H

#include <stddef.h>

#include "measurements/support_mesh.h"
#include "model/climbing_growth.h"
#include "model/status.h"

/* Counts of what phc_grow_write_obj writes. */
typedef struct phc_grow_obj_counts {
    size_t vertices, triangles;
    size_t stem_triangles, leaf_triangles, support_triangles;
} phc_grow_obj_counts;

/* Writes the OBJ to path (sides in 3..64; support may be NULL); *counts
 * (may be NULL) gets what was written.  Errors: sides out of range
 * (PHC_ERR_INVALID), the file cannot be written (PHC_ERR_IO, path named). */
int phc_grow_write_obj(const phc_climbing *c, const phc_support_mesh *support, unsigned sides,
                       const char *path, phc_grow_obj_counts *counts, phc_error *err);

#endif /* PHC_GROW_MESH_H */
