/* libFuzzer harness: a whole configuration load (fit/config.h), YAML to a
 * validated problem, through every data-set kind's loader and the readers
 * they call.
 * The input is config.yaml, optionally followed by the files it refers to,
 * split at "%% NAME" lines (fuzz_common.h; NAME a plain file name, up to 7
 * files).  Everything is written to a fresh folder; data.csv, a small curve
 * table (columns x, y), is always there unless the input brings its own:
 *     name: t
 *     parameters: {a: {value: 1}, b: 0.5}
 *     datasets:
 *       - {kind: curve, file: data.csv, x: x, y: y, expression: "a*x + b"}
 * The seed corpus (scripts/fuzz) is the bundled example configs with the
 * first lines of the files they name. */
#include "fuzz_common.h"

#include "fit/config.h"
#include "fit/engine/problem.h"

static const char data_csv[] = "x,y\n1,2.1\n2,3.9\n3,6.2\n4,8.0\n5,9.9\n6,12.1\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    phc_fuzz_part parts[PHC_FUZZ_MAX_PARTS];
    char path[4200], config[4200];
    phc_error err;
    phc_problem *pb = NULL;
    size_t n = phc_fuzz_split(data, size, parts);
    phc_fuzz_clear();
    phc_fuzz_write("data.csv", data_csv, sizeof data_csv - 1, path, sizeof path);
    for (size_t i = 1; i < n; ++i)
        if (phc_fuzz_plain_name(parts[i].name) && strcmp(parts[i].name, "config.yaml"))
            phc_fuzz_write(parts[i].name, parts[i].data, parts[i].size, path, sizeof path);
    phc_fuzz_write("config.yaml", parts[0].data, parts[0].size, config, sizeof config);
    int rc = phc_config_load(config, &pb, &err);
    phc_fuzz_check_error(rc, &err, phc_fuzz_dir());
    if (rc != 0) {
        if (pb)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        return 0;
    }
    phc_problem_free(pb);
    return 0;
}
