/* `phytocal grow`: grows one climbing plant from a grow config
 * (fit/grow_config.h; model/climbing_growth.h, Hädrich et al., CGF 36(2)
 * 2017) and writes a run directory:
 *   frame_NNNN.vtk   legacy VTK polydata of the plant every frame_interval
 *                    (radius; branch_order, light, anchored per segment)
 *   leaves_NNNN.vtk  the leaves at the same times (one quad per blade; light
 *                    and cos(normal, light direction) per blade), when
 *                    leaves.step > 0
 *   plant.obj        the final plant as a mesh (fit/grow_mesh.h: stems as
 *                    tubes, leaves as squares, the support)
 *   growth.csv       per frame: time, particles, tips, laterals, anchored,
 *                    attached fraction, height, total length
 *   plant_side.png, plant_front.png   the final plant seen along y and along
 *                    x (colour = branch order, leaves one colour past it;
 *                    support vertices as markers)
 *   support.vtk      the support mesh (when there is one)
 *   result.json      the final summary (below) and the provenance
 *   phytocal-run.json  the manifest (fit/run_dir.h: --force rules)
 *
 * Why a command and not a data-set kind of `simulate`: a calibration
 * problem (fit/engine/problem.h) is parameters plus data sets with
 * observations, and every tool on it (fit, simulate's x/observed/model
 * table, the report) needs observations; a plant grown from a seed has
 * none, and its outputs are frames, not a curve. */
#ifndef PHC_GROW_H
#define PHC_GROW_H

#include "fit/engine/dataset.h"
#include "fit/engine/problem.h"
#include "fit/engine/provenance.h"
#include "fit/grow_config.h"
#include "model/climbing_growth.h"
#include "model/plant_graph.h"
#include "model/status.h"

/* Summary of a plant (also result.json's "plant"). */
typedef struct phc_grow_summary {
    double time;               /* s */
    size_t particles, apical, laterals, bud_trials;
    size_t laterals_per_order[8]; /* lateral shoots starting at order 1..7 (index = order; [0] unused) */
    size_t max_order;
    size_t anchored, anchors_made, anchors_released;
    double attached_fraction;  /* anchored / particles */
    double height;             /* m: highest segment end above the seed's base (z) */
    double total_length;       /* m */
    size_t frames;             /* frames written */
    size_t leaves;             /* leaves on the plant */
    double mean_leaf_cos;      /* mean cosine between leaf normals and the light direction */
    double max_radius;         /* m: thickest particle (after secondary growth) */
    /* breaking (dynamics.break_threshold or break_stress > 0): the counts above are of the plant
       without its falling pieces */
    size_t breaks;             /* links broken since the seed (one piece each) */
    size_t falling;            /* particles of broken pieces still falling */
    size_t pieces_dropped, particles_dropped; /* pieces that left the plant, their particles */
    size_t resprouts;          /* stumps that grew a new tip (dynamics.resprout_delay) */
    /* the first break (NaN before one): its time (s), its joint's bending
       stress (Pa, with dynamics.break_stress; else 0), the joint (m) and
       whether the particle above it held an anchor */
    double first_break_time, first_break_stress, first_break_joint[3];
    int first_break_parent_anchored;
} phc_grow_summary;

/* Sets up o's light grid (origin and dims) when the plant needs one: light
 * extinction (self-shading), a grid given in the config, or a support m that
 * casts shadows (light.supports_cast_shadows); otherwise leaves o alone.
 * The grid: with light.origin and light.size given, their box; else the
 * support's box (or, with no support, a 1 m box over the seed) widened by
 * 0.25 m on every side.  `phytocal grow` and the shoot_traces kind both
 * set up their plants' light through it. */
struct phc_support_mesh;
void phc_grow_light_grid(const phc_grow_config *cfg, const struct phc_support_mesh *m, phc_climbing_options *o);

void phc_grow_summarise(const phc_climbing *c, const double seed_base[3], phc_grow_summary *s);

/* The plant's current shape as a finished plant graph (segment base =
 * head, tip = tail; the seed particle fixed), for VTK files and plots. */
phc_plant_graph *phc_grow_plant_graph(const phc_climbing *c, phc_error *err);

/* A problem shell that only names the run's inputs (the config and the
 * mesh) and its seed, so the run-directory checks and the provenance of
 * fit/run_dir.h and fit/engine/provenance.h apply to grow runs too.
 * Valid while the config lives; nothing to free. */
typedef struct phc_grow_inputs {
    phc_problem pb;
    phc_dataset ds;
    phc_dataset *dsp;
    char *inputs[1];
    char *seeds[1];
} phc_grow_inputs;
void phc_grow_inputs_init(phc_grow_inputs *in, const phc_grow_config *c);

/* Grows the plant and writes the run directory DIR (force as in
 * fit/run_dir.h); *summary (may be NULL) gets the final plant.  Errors,
 * with the config's file and line: the mesh does not parse or has no
 * triangles ("wall.yaml:3: support: wall.obj: ..."; PHC_ERR_INPUT), the seed
 * lies inside a support (PHC_ERR_INPUT at plant.position's line), a growth
 * step fails (its message and the time); DIR refused (PHC_ERR_EXISTS).
 * pv (may be NULL) gets its end time when the plant is grown. */
int phc_grow_write(const phc_grow_config *c, phc_provenance *pv, const char *dir, int force,
                   phc_grow_summary *summary, phc_error *err);

#endif /* PHC_GROW_H */
