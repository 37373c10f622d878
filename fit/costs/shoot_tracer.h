/* A tracer of a time-lapse watching a plant grown by the climbing model
 * (model/climbing_growth.h): the traced representation the shoot_traces
 * kind compares (measurements/shoot_traces.h), made from the model.
 *
 * At each frame (a time at which the tracer looks at the plant) it records,
 * for every shoot, the points it has not seen before, where they are then:
 * the shoot's base (the first time the shoot is seen; a lateral's base is
 * its branch point on the parent), every node laid down since the last
 * frame (the tip of a particle that stopped growing), and the apex (the
 * tip of the growing particle) at every frame.  A shoot is the particle
 * chain from a particle without parent or a lateral start to its apex;
 * its name is "s<stable id of its first particle>" (phc_climbing_id: its
 * index while no piece broke off), its parent the shoot of the particle it
 * leaves.  A point's time is the frame's.
 *
 * So the traces record where an apex was at each frame and where each node
 * was when first seen, not the plant's final shape: a growing internode
 * that tropisms turn about its base after a frame leaves its old apex point
 * off the final shape.  The model's statistics are computed on this same
 * representation (fit/costs/shoot_traces.c), so traces and model agree by
 * construction for traces recorded the same way.  A tracer that stamps each
 * node with the time it was laid down and records apexes every frame (as
 * tests/climbing/shoot_traces_generator.py) gives the same polylines at
 * every frame time in a kinematic plant (a grown particle neither turns
 * nor moves).  A piece that broke off (model/climbing_breaking.h) is not
 * traced while it falls; what was recorded of it before stays. */
#ifndef PHC_COSTS_SHOOT_TRACER_H
#define PHC_COSTS_SHOOT_TRACER_H

#include <stddef.h>

#include "measurements/shoot_traces.h"
#include "model/climbing_growth.h"
#include "model/status.h"

typedef struct phc_shoot_tracer {
    size_t n, cap;           /* recorded points */
    double *t, *x;           /* s; m, 3 per point */
    size_t *shoot;           /* shoot of each point: index of its first particle */
    size_t *shoot_of;        /* per particle (by its stable id, phc_climbing_id): its shoot */
    size_t *written;         /* per shoot (by its first particle): points recorded so far */
    size_t *seen;            /* per shoot: particles met in the current frame */
    size_t *parent_shoot;    /* per shoot: the shoot it leaves, or PHC_CLIMBING_NONE */
    size_t particles_cap;
} phc_shoot_tracer;

/* An empty tracer (all zero). */
void phc_shoot_tracer_init(phc_shoot_tracer *tr);
void phc_shoot_tracer_clear(phc_shoot_tracer *tr); /* frees; the tracer is empty again */

/* One frame at time `time` (s): records the new points of plant c.
 * PHC_OK or PHC_ERR_NOMEM (err set). */
int phc_shoot_tracer_look(phc_shoot_tracer *tr, const phc_climbing *c, double time, phc_error *err);

/* The recorded points as traces (phc_shoot_traces_from_rows, `name` in
 * messages). */
int phc_shoot_tracer_traces(const phc_shoot_tracer *tr, const char *name, phc_shoot_traces **out,
                            phc_error *err);

#endif /* PHC_COSTS_SHOOT_TRACER_H */
