/* libFuzzer harness: `curve` expressions (fit/costs/expression.h).
 * The input is the expression's text (up to its first NUL).  An expression
 * that compiles has its names bound alternately to parameter slots and data
 * columns, is prepared and evaluated at a few points with and without the
 * gradient; the value must not depend on whether the gradient is asked for. */
#include "fuzz_common.h"

#include <math.h>

#include "fit/costs/expression.h"

#define MAX_NAMES 64

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = phc_fuzz_string(data, size);
    phc_expr *e = NULL;
    phc_error err;
    size_t pos = 0;
    int rc = phc_expr_compile(text, &e, &pos, &err);
    phc_fuzz_check_error(rc, &err, NULL);
    if (rc != 0) {
        if (e)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        free(text);
        return 0;
    }
    size_t names = phc_expr_name_count(e), n_slots = 0, n_cols = 0;
    for (size_t i = 0; i < names; ++i) {
        if (!phc_expr_name(e, i))
            phc_fuzz_fail("a name in range is NULL", NULL);
        if (phc_expr_bind(e, i, (int)(i % 2 == 0), i % 2 == 0 ? n_slots++ : n_cols++) != 0)
            phc_fuzz_fail("binding a name in range failed", NULL);
    }
    if (names <= MAX_NAMES && phc_expr_prepare(e, n_slots, &err) == 0) {
        double slots[MAX_NAMES], row[MAX_NAMES], grad[MAX_NAMES];
        static const double points[] = {0.0, 1.5, -2.25, 1e-3, 40.0};
        for (size_t k = 0; k < sizeof points / sizeof points[0]; ++k) {
            for (size_t i = 0; i < MAX_NAMES; ++i) {
                slots[i] = points[k] + 0.5 * (double)i;
                row[i] = points[k] - 0.25 * (double)i;
            }
            double v = phc_expr_eval(e, slots, row, NULL);
            double w = phc_expr_eval(e, slots, row, grad);
            if (!(v == w || (isnan(v) && isnan(w))))
                phc_fuzz_fail("the gradient sweep changed the value", NULL);
        }
    }
    phc_expr_free(e);
    free(text);
    return 0;
}
