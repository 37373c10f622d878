/* Distinct observation times: see unique_times.h. */
#include "fit/costs/unique_times.h"

#include <stdlib.h>
#include <string.h>

static int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int phc_unique_times(const double *t, size_t n, double **unique, size_t *m, size_t **at, phc_error *err)
{
    double *u = malloc((n ? n : 1) * sizeof *u);
    size_t *idx = malloc((n ? n : 1) * sizeof *idx);
    if (!u || !idx) {
        free(u);
        free(idx);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    memcpy(u, t, n * sizeof *u);
    qsort(u, n, sizeof *u, by_value);
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        if (k == 0 || u[i] != u[k - 1])
            u[k++] = u[i];
    for (size_t i = 0; i < n; ++i) {
        size_t lo = 0, hi = k; /* first index with u >= t[i] */
        while (lo < hi) {
            const size_t mid = lo + (hi - lo) / 2;
            if (u[mid] < t[i])
                lo = mid + 1;
            else
                hi = mid;
        }
        idx[i] = lo;
    }
    *unique = u;
    *m = k;
    *at = idx;
    return PHC_OK;
}
