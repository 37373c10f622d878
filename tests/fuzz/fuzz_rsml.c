/* libFuzzer harness: RSML files (measurements/rsml.h).
 * The input is the file's text, read with the default options and, when
 * that fails, again with allow_no_geometry (SmartRoot's topology-only
 * roots).  A document that reads is measured (lengths, branching orders),
 * written and read back with the same options, which must succeed with the
 * same number of plants and roots. */
#include "fuzz_common.h"

#include "measurements/rsml.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[4200], out[4200];
    phc_error err;
    phc_rsml *r = NULL, *back = NULL;
    phc_rsml_read_options opt = phc_rsml_read_options_default();
    phc_fuzz_clear();
    phc_fuzz_write("roots.rsml", data, size, path, sizeof path);
    int rc = phc_rsml_read_with(path, &opt, &r, &err);
    phc_fuzz_check_error(rc, &err, "roots.rsml");
    if (rc != 0) {
        if (r)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        opt.allow_no_geometry = 1;
        rc = phc_rsml_read_with(path, &opt, &r, &err);
        phc_fuzz_check_error(rc, &err, "roots.rsml");
        if (rc != 0) {
            if (r)
                phc_fuzz_fail("failure must leave *out NULL", NULL);
            return 0;
        }
    }
    double total = phc_rsml_total_length(r);
    for (size_t i = 0; i < r->n_roots; ++i) {
        if (phc_rsml_order(r, i) == 0)
            phc_fuzz_fail("parents come before children: every order is defined", NULL);
        total += phc_rsml_length_in_unit(r, phc_rsml_root_length(&r->roots[i]));
    }
    (void)total;
    snprintf(out, sizeof out, "%s/written.rsml", phc_fuzz_dir());
    if (phc_rsml_write(r, out, &err) == 0) {
        if (phc_rsml_read_with(out, &opt, &back, &err) != 0)
            phc_fuzz_fail("what the writer wrote does not read back", err.message);
        if (back->n_plants != r->n_plants || back->n_roots != r->n_roots)
            phc_fuzz_fail("what the writer wrote reads back with other plants or roots", NULL);
        phc_rsml_free(back);
    }
    phc_rsml_free(r);
    return 0;
}
