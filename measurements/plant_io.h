/* Reading and writing plant graphs (model/plant_graph.h).
 *
 * Formats:
 *   PHC_PLANT_FORMAT_PAPER    the wilting paper's own graph files
 *                             (`verts N`, `id,x,y,z,radius,on_leaf`, `edges M`,
 *                             `id1,id2`; positions are segment tails, metres).
 *                             Read as the authors' code reads them: the root is
 *                             the segment whose tail is nearest the origin, its
 *                             head is the origin, every other head is its
 *                             parent's tail (breadth-first from the root).
 *   PHC_PLANT_FORMAT_TREEQSM  TreeQSM cylinder text (tab separated, no header:
 *                             radius, length, start xyz, axis xyz, parent,
 *                             extension, added, unmodified radius, branch,
 *                             branch order, position in branch; metres;
 *                             parent 0 = none, 1-based).
 *   PHC_PLANT_FORMAT_SWC      SWC skeletons (`id type x y z radius parent`,
 *                             parent -1 = root; a segment runs from the parent
 *                             sample to the sample; micrometres by default).
 *   PHC_PLANT_FORMAT_NATIVE   phytocal's documented CSV (see plant_io_native.c
 *                             and the README): header `id,parent,radius,length,
 *                             x_head,y_head,z_head,x_tail,y_tail,z_tail,leaf,
 *                             fixed`, optional first line `# unit: m` (or cm,
 *                             mm, um).
 *   PHC_PLANT_FORMAT_AUTO     by extension: .swc SWC, .csv native, a file whose
 *                             first line starts with `verts` paper, otherwise
 *                             TreeQSM when it has 15 or 16 tab-separated
 *                             columns (aRchi's TreeQSM export has 15).
 *
 * Every error names the file and line:
 *     "plant.txt:12: edge 4,4: a segment cannot be its own neighbour"
 * and the graph checks of phc_plant_graph_finish (one root, no cycles,
 * positive finite radii and lengths, finite coordinates, ids in range). */
#ifndef PHC_PLANT_IO_H
#define PHC_PLANT_IO_H

#include "model/plant_graph.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum phc_plant_format {
    PHC_PLANT_FORMAT_AUTO,
    PHC_PLANT_FORMAT_PAPER,
    PHC_PLANT_FORMAT_TREEQSM,
    PHC_PLANT_FORMAT_SWC,
    PHC_PLANT_FORMAT_NATIVE
} phc_plant_format;

/* Parses "auto", "paper", "treeqsm", "swc", "native"; -1 when unknown. */
int phc_plant_format_from_name(const char *name);
const char *phc_plant_format_name(phc_plant_format format);

/* Reads a plant graph.  unit_to_m multiplies the file's lengths to give
 * metres; 0 takes the format's default (paper and TreeQSM: 1; SWC: 1e-6;
 * native: its `# unit:` line, else 1).  On success *out is a finished graph
 * owned by the caller; on failure *out is NULL and err says why. */
int phc_plant_io_read(const char *path, phc_plant_format format, double unit_to_m,
                      phc_plant_graph **out, phc_error *err);

/* Writers (metres).  Written to a temporary name and renamed into place. */
int phc_plant_io_write_native(const char *path, const phc_plant_graph *g, phc_error *err);
int phc_plant_io_write_paper(const char *path, const phc_plant_graph *g, phc_error *err);

/* One value per segment, written beside the shape (e.g. "relative_water",
 * "young_modulus_Pa"); name: letters, digits and '_' only. */
typedef struct phc_plant_field {
    const char *name;
    const double *value; /* g->n values */
} phc_plant_field;

/* The graph's current shape (head and tail of every segment, m) as legacy
 * VTK polydata for ParaView or Blender: one line per segment, the radius as
 * point data (for a Tube filter), segment_id, leaf, fixed and the fields as
 * cell data (measurements/plant_io_vtk.c gives the layout).  title: the
 * file's title line (NULL: "phytocal plant shape").  Write-only: VTK is an
 * output format here, not read back. */
int phc_plant_io_write_vtk(const char *path, const phc_plant_graph *g, const char *title,
                           const phc_plant_field *fields, size_t count, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_PLANT_IO_H */
