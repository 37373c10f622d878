/* Unit tests for measurements/suggest.c: edit distance and "did you mean". */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "measurements/suggest.h"

static void test_distance(void)
{
    char *long_a, *long_b;
    size_t n = 300;

    CHECK(phc_edit_distance("", "") == 0);
    CHECK(phc_edit_distance("abc", "") == 3);
    CHECK(phc_edit_distance("", "abcd") == 4);
    CHECK(phc_edit_distance("kitten", "sitting") == 3);
    CHECK(phc_edit_distance("sitting", "kitten") == 3);
    CHECK(phc_edit_distance("flaw", "lawn") == 2);
    CHECK(phc_edit_distance("lowr", "lower") == 1);
    CHECK(phc_edit_distance("lower", "lower") == 0);
    /* Case-sensitive, byte-wise. */
    CHECK(phc_edit_distance("Mass", "mass") == 1);
    CHECK(phc_edit_distance("\xc3\xa9", "e") == 2);
    /* NULL is treated as the empty string rather than crashing. */
    CHECK(phc_edit_distance(NULL, "ab") == 2);

    /* Longer than the stack row: the heap path must agree. */
    long_a = malloc(n + 1);
    long_b = malloc(n + 1);
    CHECK(long_a && long_b);
    if (long_a && long_b) {
        memset(long_a, 'a', n);
        long_a[n] = '\0';
        memset(long_b, 'a', n);
        long_b[n] = '\0';
        long_b[10] = 'b';
        long_b[200] = 'c';
        CHECK(phc_edit_distance(long_a, long_b) == 2);
        long_b[n - 5] = '\0';
        CHECK(phc_edit_distance(long_a, long_b) == 7);
        CHECK(phc_edit_distance(long_b, long_a) == 7);
        CHECK(phc_edit_distance(long_a, "") == n);
    }
    free(long_a);
    free(long_b);
}

static void test_suggest(void)
{
    const char *const keys[] = {"value", "lower", "upper", "unit", "fixed"};
    const char *const ties[] = {"abx", "aby"};
    const char *const with_null[] = {NULL, "mass_g"};
    const char *s;

    s = phc_suggest("lowr", keys, 5);
    CHECK(s && !strcmp(s, "lower"));
    s = phc_suggest("uper", keys, 5);
    CHECK(s && !strcmp(s, "upper"));
    s = phc_suggest("Value", keys, 5);
    CHECK(s && !strcmp(s, "value"));
    s = phc_suggest("unit", keys, 5);
    CHECK(s && !strcmp(s, "unit"));
    /* Ties go to the first candidate. */
    s = phc_suggest("abz", ties, 2);
    CHECK(s && !strcmp(s, "abx"));
    /* Too far: max(2, strlen / 3) edits. */
    CHECK(phc_suggest("expression", keys, 5) == NULL);
    CHECK(phc_suggest("xyz", keys, 5) == NULL);
    /* "mass_gram" is 3 edits from "mass_g"; 9 / 3 = 3 allows it. */
    s = phc_suggest("mass_gram", with_null, 2);
    CHECK(s && !strcmp(s, "mass_g"));
    /* "mas" is 3 edits away, more than max(2, 1). */
    CHECK(phc_suggest("mas", with_null, 2) == NULL);
    CHECK(phc_suggest("lowr", keys, 0) == NULL);
    CHECK(phc_suggest("lowr", NULL, 3) == NULL);
    CHECK(phc_suggest(NULL, keys, 5) == NULL);
    /* An empty word is within 2 of short candidates. */
    s = phc_suggest("", ties, 2);
    CHECK(s == NULL);
}

int main(void)
{
    test_distance();
    test_suggest();
    return check_finish("test_suggest");
}
