/* Growable arrays in transparent huge pages: see big_array.h. */
#define _DEFAULT_SOURCE /* madvise, MADV_HUGEPAGE (Linux) */
#include "model/big_array.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

void *phc_big_array_grow(void *p, size_t keep, size_t bytes)
{
    if (bytes == 0) bytes = 1;
    if (keep > bytes) keep = bytes;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t huge = (size_t)2 << 20;
    if (bytes >= huge && bytes <= SIZE_MAX - huge) {
        const size_t rounded = (bytes + huge - 1) / huge * huge;
        void *q = NULL;
        if (posix_memalign(&q, huge, rounded) == 0) {
            (void)madvise(q, rounded, MADV_HUGEPAGE); /* advice: a refusal only costs speed */
            if (keep) memcpy(q, p, keep);
            free(p);
            return q;
        }
    }
#endif
    if (keep == 0) { /* nothing to keep: no copy */
        void *q = malloc(bytes);
        if (q) free(p);
        return q;
    }
    return realloc(p, bytes);
}
