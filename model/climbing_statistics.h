/* Summary statistics of a climbing plant's shape, computed the same way
 * from traced shoots (measurements/shoot_traces.h) and from a plant grown
 * by model/climbing_growth.h, so that the model can be fitted to traces by
 * comparing statistics rather than shoots point by point (a grown plant and
 * a traced one never share their random draws; statistics averaged over
 * seeds do not depend on the draw).
 *
 * A plant is given as segments: base and tip (m), branch order (0 main
 * axis), and for the first segment of a lateral shoot the direction of the
 * parent segment it leaves from.  Definitions (ℓ the unit light direction,
 * z up, |s| = |tip − base|):
 *   total_length      Σ |s| over all segments, m
 *   main_length       Σ |s| over the order-0 segments, m
 *   height            max z of every base and tip − z of the plant's
 *                     origin (the seed's base), m ("height on the support")
 *   attached_fraction Σ |s| of the segments whose midpoint lies within
 *                     attach_distance of the support (closest-point
 *                     callback) / total_length, 1 (0 without support)
 *   light_cosine      Σ |s| (ŝ·ℓ) / total_length: length-weighted mean
 *                     cosine between the segments' directions and ℓ, 1
 *                     (1: every segment grows toward the light)
 *   shoots[k]         lateral shoots of branch order k (k = 1 ..
 *                     PHC_CLIMBING_STAT_ORDERS − 1), count
 *   angle_mean, angle_sd  mean and (population) standard deviation of the
 *                     branching angle, the angle between a lateral's first
 *                     segment and its parent's segment, degrees; NAN when
 *                     there is no lateral (angle_n = 0)
 * Segments of zero length count in the lengths (0) and not in the
 * directions.  Pure C: no I/O, no globals. */
#ifndef PHC_CLIMBING_STATISTICS_H
#define PHC_CLIMBING_STATISTICS_H

#include <stddef.h>

#include "model/climbing_growth.h"
#include "model/status.h"

#define PHC_CLIMBING_STAT_ORDERS 8

typedef struct phc_shoot_segment {
    double base[3], tip[3];   /* m */
    unsigned order;           /* branch order, 0 = main axis */
    int lateral_start;        /* 1: the first segment of a lateral shoot */
    double parent_dir[3];     /* with lateral_start: its parent segment's direction (any length) */
} phc_shoot_segment;

typedef struct phc_climbing_stat_options {
    double origin[3];             /* m: the seed's base (height is measured from its z) */
    double light[3];              /* light direction ℓ (any non-zero length) */
    double attach_distance;       /* m, >= 0 */
    phc_climbing_closest_fn closest; /* NULL: no support (attached_fraction 0) */
    void *closest_user;
} phc_climbing_stat_options;

typedef struct phc_climbing_summary {
    double total_length, main_length, height; /* m */
    double attached_fraction, light_cosine;   /* 1 */
    double shoots[PHC_CLIMBING_STAT_ORDERS];  /* [0] unused (0); counts per order */
    double angle_mean, angle_sd;              /* degrees; NAN without laterals */
    size_t angle_n;                           /* laterals whose angle entered */
    double angle_sum, angle_sum2;             /* Σθ, Σθ² (deg, deg²), for pooling */
} phc_climbing_summary;

/* Statistics of n segments.  PHC_ERR_INVALID for a NULL argument with n >
 * 0, a non-finite coordinate or a zero light direction. */
int phc_climbing_summarize_segments(const phc_shoot_segment *seg, size_t n,
                                    const phc_climbing_stat_options *o, phc_climbing_summary *s,
                                    phc_error *err);

/* The current segments of a grown plant (phc_shoot_segment: base and
 * tip of each particle, lateral_start from phc_climbing_is_lateral, the
 * parent particle's direction).  seg must hold phc_climbing_count(c). */
void phc_climbing_segments(const phc_climbing *c, phc_shoot_segment *seg);

/* The mean of m summaries (averaged over seeds): every field is the mean,
 * except the angles, which are pooled over all laterals of all m (mean and
 * sd of the pooled angles; NAN when there are none). */
void phc_climbing_summary_mean(const phc_climbing_summary *s, size_t m, phc_climbing_summary *mean);

#endif /* PHC_CLIMBING_STATISTICS_H */
