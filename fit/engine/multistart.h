/* Starting points for multi-start fits: a Sobol sequence (GSL's quasi-random
 * generator, deterministic) spread over each free parameter's search box.
 *
 * Box of a free parameter: `range` when given; else the bounds when both are
 * finite; else a decade on each side of the start value (|v|/10 .. 10|v|,
 * with the start's sign, clipped to a finite bound), or [-scale, scale] for a
 * start of 0.  Positive boxes wider than a factor of 100 are sampled
 * log-uniformly, so every decade gets its share of points. */
#ifndef PHC_MULTISTART_H
#define PHC_MULTISTART_H

#include <stddef.h>

#include "fit/engine/problem.h"

/* Fills x (n_params values) with start number `index` (1-based among the
 * extra starts: start 0 is the configured one).  Fixed parameters keep
 * their values.  Points are drawn from one Sobol sequence of dimension
 * n_free; `gen_state` is opaque and created by phc_multistart_new. */
typedef struct phc_multistart phc_multistart;
phc_multistart *phc_multistart_new(const phc_problem *pb);
void phc_multistart_free(phc_multistart *ms);
int phc_multistart_next(phc_multistart *ms, double *x);

#endif /* PHC_MULTISTART_H */
