/* "Did you mean ...?" suggestions: see suggest.h. */
#include "measurements/suggest.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Keys and column names are short; a row of this many cells on the stack
 * avoids a malloc for every candidate in the common case. */
#define SUGGEST_STACK_ROW 64

size_t phc_edit_distance(const char *a, const char *b)
{
    size_t stack_row[SUGGEST_STACK_ROW];
    size_t *row = stack_row;
    size_t la, lb, i, j, result;

    if (!a)
        a = "";
    if (!b)
        b = "";
    la = strlen(a);
    lb = strlen(b);
    /* Keep the row over the shorter string: memory O(min(la, lb)). */
    if (lb > la) {
        const char *t = a;
        size_t lt = la;
        a = b;
        b = t;
        la = lb;
        lb = lt;
    }
    if (lb == 0)
        return la;
    if (lb + 1 > SUGGEST_STACK_ROW) {
        if (lb + 1 > SIZE_MAX / sizeof *row)
            return SIZE_MAX;
        row = malloc((lb + 1) * sizeof *row);
        /* No memory: report "infinitely far" so that phc_suggest simply
         * offers nothing instead of failing. */
        if (!row)
            return SIZE_MAX;
    }
    for (j = 0; j <= lb; ++j)
        row[j] = j;
    for (i = 1; i <= la; ++i) {
        size_t diagonal = row[0]; /* d[i-1][j-1] */
        row[0] = i;
        for (j = 1; j <= lb; ++j) {
            size_t above = row[j]; /* d[i-1][j] */
            size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            size_t best = diagonal + cost;
            if (above + 1 < best)
                best = above + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            row[j] = best;
            diagonal = above;
        }
    }
    result = row[lb];
    if (row != stack_row)
        free(row);
    return result;
}

const char *phc_suggest(const char *word, const char *const *candidates, size_t n)
{
    const char *best = NULL;
    size_t best_distance = SIZE_MAX;
    size_t limit, i;

    if (!word || !candidates || n == 0)
        return NULL;
    /* A third of the word's length, but at least 2 so that short keys
     * ("lowr" for "lower") still get a suggestion. */
    limit = strlen(word) / 3;
    if (limit < 2)
        limit = 2;
    for (i = 0; i < n; ++i) {
        size_t d;
        if (!candidates[i])
            continue;
        d = phc_edit_distance(word, candidates[i]);
        if (d < best_distance) { /* strict: ties keep the first */
            best_distance = d;
            best = candidates[i];
        }
    }
    return best_distance <= limit ? best : NULL;
}
