/* libFuzzer harness: CSV tables (measurements/table.h).
 * The input is the file's text.  A table that parses is queried the way the
 * data-set kinds query it: every column (up to 64) by name, converted to
 * numbers for all rows and for a reversed subset of rows, and every cell read. */
#include "fuzz_common.h"

#include "measurements/table.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    phc_error err;
    phc_table *t = NULL;
    int rc = phc_table_parse((const char *)data, size, "fuzz.csv", &t, &err);
    phc_fuzz_check_error(rc, &err, "fuzz.csv");
    if (rc != 0) {
        if (t)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        return 0;
    }
    size_t rows = phc_table_rows(t), cols = phc_table_columns(t);
    size_t ncols = cols < 64 ? cols : 64;
    size_t subset[3] = {0, 0, 0}, n_subset = 0;
    for (size_t r = rows; r > 0 && n_subset < 3; --r)
        subset[n_subset++] = r - 1;
    for (size_t c = 0; c < ncols; ++c) {
        const char *name = phc_table_column_name(t, c);
        if (!name || phc_table_find(t, name) < 0)
            phc_fuzz_fail("a column must be found by its own name", NULL);
        double *v = NULL;
        rc = phc_table_column_numbers(t, name, &v, &err);
        phc_fuzz_check_error(rc, &err, "fuzz.csv");
        if (rc == 0 && rows && !v)
            phc_fuzz_fail("a column of a table with rows came back NULL", NULL);
        free(v);
        v = NULL;
        rc = phc_table_column_numbers_rows(t, name, subset, n_subset, &v, &err);
        phc_fuzz_check_error(rc, &err, "fuzz.csv");
        free(v);
    }
    double *v = NULL;
    rc = phc_table_column_numbers(t, "no such column", &v, &err); /* the "did you mean" path */
    phc_fuzz_check_error(rc, &err, "fuzz.csv");
    free(v);
    size_t sum = 0;
    for (size_t r = 0; r < rows && r < 4096; ++r) {
        sum += phc_table_row_line(t, r);
        for (size_t c = 0; c < ncols; ++c)
            sum += strlen(phc_table_cell(t, r, c));
    }
    (void)sum;
    phc_table_free(t);
    return 0;
}
