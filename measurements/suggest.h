/* "Did you mean ...?" suggestions for misspelt keys and column names. */
#ifndef PHC_SUGGEST_H
#define PHC_SUGGEST_H

#include <stddef.h>

/* Levenshtein edit distance between two strings, byte-wise, case-sensitive.
 * NULL counts as "".  Returns SIZE_MAX if memory for a long string (over 63
 * bytes) cannot be had, so that phc_suggest then offers nothing. */
size_t phc_edit_distance(const char *a, const char *b);

/* The candidate nearest to `word` by edit distance (ties: the first), or NULL
 * when the best distance exceeds max(2, strlen(word) / 3) or n is 0. */
const char *phc_suggest(const char *word, const char *const *candidates, size_t n);

#endif /* PHC_SUGGEST_H */
