/* Growable arrays of many MiB that are written soon after they grow (the
 * growth model's nodes: a 30-day step of the bench plant writes 29 MiB of
 * new nodes).
 *
 * With 4 KiB pages each newly written page costs a page fault, and in this
 * project's virtual machine a fault costs about 25 us (measured: 40 MiB of
 * fresh anonymous memory, one byte written per page, 0.24-0.28 s; the same
 * with transparent huge pages, once the memory had been used before, 0.0025
 * s).  From 2 MiB up an array is therefore aligned to 2 MiB and advised as
 * transparent huge pages (Linux, where the system allows them on madvise):
 * 512 times fewer faults.  Elsewhere, or below 2 MiB, plain realloc.
 * measurements/photo.c does the same for photo buffers.
 *
 * No I/O, no globals. */
#ifndef PHC_BIG_ARRAY_H
#define PHC_BIG_ARRAY_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* A buffer of at least `bytes` whose first `keep` bytes (keep <= the
 * bytes p holds, and keep <= bytes) are those of p; p (may be NULL, then
 * keep must be 0) is released.  NULL when out of memory: p is then
 * untouched and still owned by the caller.  Release with free(). */
void *phc_big_array_grow(void *p, size_t keep, size_t bytes);

#ifdef __cplusplus
}
#endif

#endif
