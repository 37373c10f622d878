/* Order statistics without sorting (see order_statistics.h). */
#include "model/order_statistics.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Hoare quickselect: rearranges a[lo..hi) so that a[k] is the value a sort
 * would put there, everything before it <= a[k] and everything after >=.
 * The median of three is moved to a[lo] and used as the pivot, so Hoare's
 * partition always splits into two non-empty parts (lo <= j < hi - 1). */
static void quickselect(double *a, size_t lo, size_t hi, size_t k)
{
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2, last = hi - 1;
        size_t med = (a[lo] < a[mid]) == (a[mid] < a[last]) ? mid
                     : (a[mid] < a[lo]) == (a[lo] < a[last]) ? lo
                                                              : last;
        double t = a[lo];
        a[lo] = a[med];
        a[med] = t;
        const double pivot = a[lo];
        ptrdiff_t i = (ptrdiff_t)lo - 1, j = (ptrdiff_t)hi;
        for (;;) {
            do
                ++i;
            while (a[i] < pivot);
            do
                --j;
            while (a[j] > pivot);
            if (i >= j)
                break;
            t = a[i];
            a[i] = a[j];
            a[j] = t;
        }
        /* a[lo..j] <= pivot <= a[j+1..hi) */
        if (k <= (size_t)j)
            hi = (size_t)j + 1;
        else
            lo = (size_t)j + 1;
    }
}

/* Puts the order statistics at the ascending distinct positions ks[0..nk)
 * (all in [lo, hi)) in place: select the middle one, then recurse on the
 * two sides with the positions that fall there. */
static void multiselect(double *a, size_t lo, size_t hi, const size_t *ks, size_t nk)
{
    while (nk > 0 && hi - lo > 1) {
        const size_t m = nk / 2, k = ks[m];
        quickselect(a, lo, hi, k);
        multiselect(a, lo, k, ks, m);
        lo = k + 1;
        ks += m + 1;
        nk -= m + 1;
    }
}

/* Below this size the quickselect's branches cost less than the bucket
 * pass's three sweeps and its allocation. */
#define SMALL_N 256

int phc_order_statistics_select(double *a, size_t n, const size_t *pos, size_t n_pos)
{
    if (n_pos == 0 || n < 2)
        return 0;
    if (n < SMALL_N) {
        multiselect(a, 0, n, pos, n_pos);
        return 0;
    }
    double lo = a[0], hi = a[0];
    for (size_t i = 1; i < n; ++i) {
        lo = a[i] < lo ? a[i] : lo;
        hi = a[i] > hi ? a[i] : hi;
    }
    if (!(hi > lo))
        return 0; /* all equal: every position already holds its value */
    /* Buckets by value: b(v) = floor((v - lo) * scale), clamped to the last
     * bucket.  Subtraction and multiplication by a positive number round
     * monotonically, so v <= w gives b(v) <= b(w): the buckets are in value
     * order and a position's bucket holds its order statistic. */
    size_t nb = n / 4;
    nb = nb > 65536 ? 65536 : nb;
    const double range = hi - lo, scale = (double)nb / range;
    if (!isfinite(range) || !isfinite(scale)) {
        multiselect(a, 0, n, pos, n_pos);
        return 0;
    }
    uint32_t *bucket = malloc(n * sizeof *bucket);
    size_t *start = calloc(nb + 1, sizeof *start);
    double *out = malloc(n * sizeof *out);
    if (!bucket || !start || !out) {
        free(bucket);
        free(start);
        free(out);
        multiselect(a, 0, n, pos, n_pos);
        return -1;
    }
    for (size_t i = 0; i < n; ++i) {
        size_t b = (size_t)((a[i] - lo) * scale);
        b = b < nb ? b : nb - 1;
        bucket[i] = (uint32_t)b;
        ++start[b + 1];
    }
    for (size_t b = 0; b < nb; ++b)
        start[b + 1] += start[b];
    /* scatter into bucket order (counting sort by bucket); start[b] moves
     * to the end of bucket b, so afterwards bucket b is [start[b-1], start[b]) */
    for (size_t i = 0; i < n; ++i)
        out[start[bucket[i]]++] = a[i];
    /* exact selection inside each bucket that holds wanted positions */
    size_t i = 0;
    while (i < n_pos) {
        /* the bucket holding pos[i]: the first b with start[b] > pos[i] */
        size_t l = 0, r = nb - 1;
        while (l < r) {
            const size_t m = l + (r - l) / 2;
            if (start[m] > pos[i])
                r = m;
            else
                l = m + 1;
        }
        const size_t b_lo = l == 0 ? 0 : start[l - 1], b_hi = start[l];
        size_t j = i;
        while (j < n_pos && pos[j] < b_hi)
            ++j;
        multiselect(out, b_lo, b_hi, pos + i, j - i);
        i = j;
    }
    memcpy(a, out, n * sizeof *a);
    free(bucket);
    free(start);
    free(out);
    return 0;
}
