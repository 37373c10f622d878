/* Order statistics of an array of doubles: the values a full sort would put
 * at a few chosen positions, without sorting.
 *
 * Histogram matching and colour quantiles (Silva et al., leaf colour aging
 * §3.3; model/colour.c) read a dozen order statistics of every leaf's
 * pixels at every trial point of a fit, which made selection the largest
 * part of a leaf calibration.  phc_order_statistics_select puts them in
 * place in O(n) (a bucket pass over the value range, then exact selection
 * inside the few buckets that hold a wanted position), so the values read
 * are exactly those of a sort. */
#ifndef PHC_MODEL_ORDER_STATISTICS_H
#define PHC_MODEL_ORDER_STATISTICS_H

#include <stddef.h>

/* Rearranges a[0..n) so that a[pos[i]] is, for every i < n_pos, the value a
 * sort into ascending order would put at position pos[i].  pos must be
 * ascending, distinct and < n.  The other entries are a permutation of the
 * rest of the input in no stated order.  The values must be comparable
 * (no NaN).  Returns 0, or -1 when memory ran out, in which case a[] is a
 * permutation of the input with the same guarantee (a slower selection in
 * place was used). */
int phc_order_statistics_select(double *a, size_t n, const size_t *pos, size_t n_pos);

#endif
