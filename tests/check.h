/* Minimal test macros shared by the test programs.  A test program returns
 * check_finish(): 0 when every check passed, 1 otherwise; 77 means skipped
 * (ctest SKIP_RETURN_CODE), used when ../shared/data is absent. */
#ifndef PHC_TEST_CHECK_H
#define PHC_TEST_CHECK_H

#include <math.h>
#include <stdio.h>
#include <string.h>

static int check_failures = 0;
static int check_count = 0;

#define CHECK(cond)                                                          \
    do {                                                                     \
        ++check_count;                                                       \
        if (!(cond)) {                                                       \
            ++check_failures;                                                \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, \
                    #cond);                                                  \
        }                                                                    \
    } while (0)

/* |a - b| <= tol_abs + tol_rel * |b| */
#define CHECK_NEAR(a, b, tol_abs, tol_rel)                                   \
    do {                                                                     \
        double check_a_ = (a), check_b_ = (b);                               \
        ++check_count;                                                       \
        if (!(fabs(check_a_ - check_b_) <=                                   \
              (tol_abs) + (tol_rel) * fabs(check_b_))) {                     \
            ++check_failures;                                                \
            fprintf(stderr, "%s:%d: check failed: %s = %.17g, expected %s = %.17g\n", \
                    __FILE__, __LINE__, #a, check_a_, #b, check_b_);         \
        }                                                                    \
    } while (0)

#define CHECK_STR_CONTAINS(haystack, needle)                                 \
    do {                                                                     \
        const char *check_h_ = (haystack);                                   \
        ++check_count;                                                       \
        if (!check_h_ || !strstr(check_h_, (needle))) {                      \
            ++check_failures;                                                \
            fprintf(stderr, "%s:%d: check failed: '%s' does not contain '%s'\n", \
                    __FILE__, __LINE__, check_h_ ? check_h_ : "(null)", (needle)); \
        }                                                                    \
    } while (0)

static int check_finish(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, check_count, check_failures);
    return check_failures ? 1 : 0;
}

#endif /* PHC_TEST_CHECK_H */
