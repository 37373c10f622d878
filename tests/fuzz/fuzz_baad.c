/* libFuzzer harness: BAAD study folders (measurements/baad.h).
 * The input holds the folder's files, split at "%% NAME" lines (fuzz_common.h):
 * the first, unnamed part is data.csv; parts named dataMatchColumns.csv,
 * dataNew.csv and data.csv go into the study folder, variableDefinitions.csv
 * into its parent; parts with other names are ignored and a file without a
 * part is absent.  Example:
 *     species,diam (mm)
 *     AA,2.0
 *     %% dataMatchColumns.csv
 *     var_in,method,unit_in,var_out,notes
 *     ...
 *     %% variableDefinitions.csv
 *     variable,units,group,type,...
 * A study that reads is queried through every accessor. */
#include "fuzz_common.h"

#include <math.h>

#include "measurements/baad.h"

static const char *const variables[] = {"species", "age",  "d.ba", "h.t",  "m.rt", "m.st",
                                        "m.lf",    "m.so", "a.lf", "h.bh", "latitude",
                                        "longitude", "growingCondition", "ma.ilf", "nothing"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    phc_fuzz_part parts[PHC_FUZZ_MAX_PARTS];
    char path[4200], study[4200];
    phc_error err;
    phc_baad_study *s = NULL;
    size_t n = phc_fuzz_split(data, size, parts);
    phc_fuzz_clear();
    phc_fuzz_mkdir("Study2000", study, sizeof study);
    for (size_t i = 0; i < n; ++i) {
        const char *name = i == 0 ? "data.csv" : parts[i].name;
        char rel[128];
        if (!strcmp(name, "variableDefinitions.csv"))
            snprintf(rel, sizeof rel, "%s", name);
        else if (!strcmp(name, "data.csv") || !strcmp(name, "dataMatchColumns.csv") ||
                 !strcmp(name, "dataNew.csv"))
            snprintf(rel, sizeof rel, "Study2000/%s", name);
        else
            continue;
        phc_fuzz_write(rel, parts[i].data, parts[i].size, path, sizeof path);
    }
    int rc = phc_baad_read(study, &s, &err);
    phc_fuzz_check_error(rc, &err, phc_fuzz_dir());
    if (rc != 0) {
        if (s)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        return 0;
    }
    double sum = 0;
    const char *const *inputs = NULL;
    const char **species = NULL;
    const phc_baad_change *changes = NULL;
    sum += (double)phc_baad_inputs(s, &inputs) + (double)strlen(phc_baad_name(s));
    size_t n_species = phc_baad_species(s, &species);
    for (size_t i = 0; i < n_species; ++i)
        sum += (double)strlen(species[i]);
    size_t n_changes = phc_baad_changes(s, &changes);
    for (size_t i = 0; i < n_changes; ++i)
        sum += (double)(changes[i].rows_matched + changes[i].rows_changed);
    sum += (double)(phc_baad_flagged(s, PHC_BAAD_SUSPICIOUS) + phc_baad_flagged(s, PHC_BAAD_INVALID));
    double shift = phc_baad_site_shift(s);
    if (!isnan(shift))
        sum += shift;
    size_t rows = phc_baad_rows(s);
    if (phc_baad_row_at(s, rows) != NULL)
        phc_fuzz_fail("out of range is NULL", NULL);
    for (size_t i = 0; i < rows && i < 1024; ++i) {
        const phc_baad_row *row = phc_baad_row_at(s, i);
        if (!row)
            phc_fuzz_fail("a row in range is NULL", NULL);
        sum += (double)row->line + (row->species ? (double)strlen(row->species) : 0.0) +
               (row->flag_reason ? (double)strlen(row->flag_reason) : 0.0);
        const char *raw = phc_baad_raw(s, i, "species");
        sum += raw ? (double)strlen(raw) : 0.0;
        for (size_t v = 0; v < sizeof variables / sizeof variables[0]; ++v) {
            const char *text = phc_baad_text(s, i, variables[v]);
            const char *unit = phc_baad_unit(s, variables[v]);
            double value = phc_baad_value(s, i, variables[v]);
            sum += (text ? (double)strlen(text) : 0.0) + (unit ? (double)strlen(unit) : 0.0) +
                   (isnan(value) ? 0.0 : 1.0);
        }
    }
    (void)sum;
    phc_baad_free(s);
    return 0;
}
