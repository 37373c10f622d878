/* phc_order_statistics_select against a full sort: on random values, on
 * values with many ties, on a tiny range near 1 (buckets of a few ulps), on
 * a range spanning 600 decades, on sorted and reversed input, for sizes on
 * both sides of the small-array path; every wanted position must hold
 * exactly the sorted value, and the array must stay a permutation. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "model/order_statistics.h"

static uint64_t state = 0x9E3779B97F4A7C15ull;
static double uniform(void)
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return (double)(state >> 11) / 9007199254740992.0;
}

static int cmp(const void *pa, const void *pb)
{
    const double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

enum { RANDOM, TIES, TINY_RANGE, HUGE_RANGE, SORTED, REVERSED, N_KINDS };
static const char *kind_name[N_KINDS] = {"random", "ties", "tiny range", "huge range", "sorted", "reversed"};

static double value(int kind, size_t i, size_t n)
{
    switch (kind) {
    case TIES: return floor(uniform() * 7.0) - 3.0;
    case TINY_RANGE: return 1.0 + ldexp(floor(uniform() * 40.0), -52);
    case HUGE_RANGE: return (uniform() < 0.5 ? -1 : 1) * pow(10.0, 600.0 * uniform() - 300.0);
    case SORTED: return (double)i;
    case REVERSED: return (double)(n - i);
    default: return uniform() * 100.0 - 50.0;
    }
}

int main(void)
{
    const size_t sizes[] = {1, 2, 3, 17, 255, 256, 257, 1000, 9216, 100003};
    size_t cases = 0, wrong = 0, not_permutation = 0;
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; ++si) {
        const size_t n = sizes[si];
        double *a = malloc(n * sizeof *a), *sorted = malloc(n * sizeof *sorted), *back = malloc(n * sizeof *back);
        size_t *pos = malloc(n * sizeof *pos);
        for (int kind = 0; kind < N_KINDS; ++kind) {
            for (int npos_kind = 0; npos_kind < 3; ++npos_kind) {
                for (size_t i = 0; i < n; ++i)
                    a[i] = value(kind, i, n);
                memcpy(sorted, a, n * sizeof *a);
                qsort(sorted, n, sizeof *sorted, cmp);
                /* wanted positions: the ends, 24 spread ones, or every one */
                size_t np = 0;
                if (npos_kind == 0) {
                    pos[np++] = 0;
                    if (n > 1)
                        pos[np++] = n - 1;
                } else if (npos_kind == 1) {
                    for (size_t k = 0; k < 24; ++k) {
                        const size_t p = (size_t)((2 * k + 1) * (double)n / 48.0);
                        if (p < n && (np == 0 || p > pos[np - 1]))
                            pos[np++] = p;
                    }
                } else {
                    for (size_t k = 0; k < n; ++k)
                        pos[np++] = k;
                }
                CHECK(phc_order_statistics_select(a, n, pos, np) == 0);
                size_t bad = 0;
                for (size_t k = 0; k < np; ++k)
                    bad += a[pos[k]] != sorted[pos[k]];
                memcpy(back, a, n * sizeof *a);
                qsort(back, n, sizeof *back, cmp);
                const int perm = memcmp(back, sorted, n * sizeof *a) == 0;
                if (bad || !perm)
                    printf("n %zu, %s, %zu positions: %zu wrong, permutation %s\n", n, kind_name[kind], np, bad,
                           perm ? "yes" : "no");
                wrong += bad;
                not_permutation += !perm;
                ++cases;
            }
        }
        free(a);
        free(sorted);
        free(back);
        free(pos);
    }
    printf("order statistics: %zu cases, %zu wrong positions, %zu not permutations\n", cases, wrong,
           not_permutation);
    CHECK(cases == 10 * N_KINDS * 3);
    CHECK(wrong == 0);
    CHECK(not_permutation == 0);
    return check_finish("test_order_statistics");
}
