/* Unit tests of model/big_array.h: growing keeps the bytes asked for, from
 * NULL, across the 2 MiB switch to huge-page arrays and between two of
 * them; keep = 0 copies nothing; arrays from 2 MiB up are 2 MiB-aligned
 * on Linux.  (Out of memory, NULL with the array untouched, is not
 * tested: the sanitizer build aborts on an impossible size.) */
#define _DEFAULT_SOURCE /* MADV_HUGEPAGE in sys/mman.h (Linux) */
#include "check.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "model/big_array.h"

static void fill(unsigned char *p, size_t from, size_t to)
{
    for (size_t i = from; i < to; ++i)
        p[i] = (unsigned char)(i * 2654435761u >> 13);
}

/* the first byte (from `from`) below `to` that fill() did not write, or `to` */
static size_t first_wrong(const unsigned char *p, size_t from, size_t to)
{
    for (size_t i = from; i < to; ++i)
        if (p[i] != (unsigned char)(i * 2654435761u >> 13))
            return i;
    return to;
}

int main(void)
{
    const size_t mib = (size_t)1 << 20, small = 1000, big1 = 3 * mib + 12345, big2 = 9 * mib + 7;
    unsigned char *p = phc_big_array_grow(NULL, 0, small);
    CHECK(p != NULL);
    if (!p)
        return check_finish("test_big_array");
    fill(p, 0, small);

    /* below 2 MiB -> above: the bytes kept */
    unsigned char *q = phc_big_array_grow(p, small, big1);
    CHECK(q != NULL);
    if (!q) {
        free(p);
        return check_finish("test_big_array");
    }
    p = q;
    size_t bad1 = first_wrong(p, 0, small);
    CHECK(bad1 == small);
    fill(p, small, big1); /* the new part is writable */

    int huge = 0;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    huge = 1;
    CHECK((uintptr_t)p % (2 * mib) == 0);
#endif

    /* huge -> larger huge, keeping all but the last 100 bytes */
    q = phc_big_array_grow(p, big1 - 100, big2);
    CHECK(q != NULL);
    if (!q) {
        free(p);
        return check_finish("test_big_array");
    }
    p = q;
    size_t bad2 = first_wrong(p, 0, big1 - 100);
    CHECK(bad2 == big1 - 100);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    CHECK((uintptr_t)p % (2 * mib) == 0);
#endif
    fill(p, 0, big2);

    size_t bad3 = first_wrong(p, 0, big2);
    CHECK(bad3 == big2);

    /* keep 0: a fresh array of the size asked, the old one released */
    q = phc_big_array_grow(p, 0, big1);
    CHECK(q != NULL);
    if (q) {
        p = q;
        fill(p, 0, big1);
        CHECK(first_wrong(p, 0, big1) == big1);
    }
    free(p);

    /* keep larger than the new size is cut to it (a shrink keeps what fits) */
    p = phc_big_array_grow(NULL, 0, 64);
    CHECK(p != NULL);
    if (p) {
        fill(p, 0, 64);
        q = phc_big_array_grow(p, 64, 32);
        CHECK(q != NULL);
        if (q) {
            p = q;
            CHECK(first_wrong(p, 0, 32) == 32);
        }
        free(p);
    }
    printf("  big_array: 1000 B -> %zu B -> %zu B kept the first %zu and %zu bytes; 2 MiB-aligned: %s; "
           "rewritten whole: %zu bytes checked\n",
           big1, big2, bad1, bad2, huge ? "checked" : "not on this system", bad3);
    return check_finish("test_big_array");
}
