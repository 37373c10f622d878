/* phc_harvest_read_baad (fit/costs/harvest.h) on BAAD studies that the
 * reader could not load before (../shared/data/baad; Falster et al. 2015,
 * data CC0):
 *  - Markesteijn2009, Gallesia integrifolia: no basal diameter in the study;
 *    every plant's diameter comes from its stem area at base, d.ba =
 *    2 sqrt(a.stba / pi) (data.csv:2: a.stba 6.651 mm2), and the notes say so;
 *  - Aspinwall2013, Pinus taeda: mapping rows for columns its
 *    dataManipulate.R makes are skipped and the warnings reach the notes;
 *    ages (3 yr) become days;
 *  - Abe1981, Abies sachalinensis: no root mass at all; the error says so.
 * Skipped (exit 77) when the shared data is absent. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "fit/costs/harvest.h"

static void study_path(char *out, size_t cap, const char *name)
{
    snprintf(out, cap, "%s/baad/%s", PHC_SHARED_DATA, name);
}

static void markesteijn(void)
{
    char dir[4096];
    phc_harvest *h = NULL;
    phc_error err;
    phc_harvest_baad_options b = {.species = "Gallesia integrifolia"};
    study_path(dir, sizeof dir, "Markesteijn2009");
    CHECK(phc_harvest_read_baad(dir, &b, &h, &err) == PHC_OK);
    if (!h) {
        printf("  error: %s\n", err.message);
        return;
    }
    printf("Markesteijn2009, Gallesia integrifolia: %zu plants; first at data.csv:%zu, d = %.6g mm\n",
           h->n, h->line ? h->line[0] : 0, 1e3 * h->diameter[0]);
    printf("%s", h->notes ? h->notes : "(no notes)\n");
    CHECK(h->n > 10);
    CHECK(h->line && h->line[0] == 2);
    CHECK_NEAR(h->diameter[0], 2.0 * sqrt(6.651e-6 / 3.14159265358979323846), 0, 1e-15);
    CHECK(h->notes != NULL);
    if (h->notes)
        CHECK_STR_CONTAINS(h->notes, "derived from the stem area at base, d.ba = 2 sqrt(a.stba / pi)");
    phc_harvest_free(h);
}

static void aspinwall(void)
{
    char dir[4096];
    phc_harvest *h = NULL;
    phc_error err;
    phc_harvest_baad_options b = {.species = "Pinus taeda"};
    study_path(dir, sizeof dir, "Aspinwall2013");
    CHECK(phc_harvest_read_baad(dir, &b, &h, &err) == PHC_OK);
    if (!h) {
        printf("  error: %s\n", err.message);
        return;
    }
    printf("Aspinwall2013, Pinus taeda: %zu plants, first age %.6g d\n", h->n,
           h->age ? h->age[0] : NAN);
    printf("%s", h->notes ? h->notes : "(no notes)\n");
    CHECK(h->n == 64);
    CHECK(h->age && h->age[0] == 3 * 365.25);
    if (h->notes) {
        CHECK_STR_CONTAINS(h->notes, "- Reading the study: ");
        CHECK_STR_CONTAINS(h->notes, "dataMatchColumns.csv:33: var_in 'totroot' (var_out m.rc)");
        CHECK_STR_CONTAINS(h->notes, "64 of the plants used have an age");
    }
    phc_harvest_free(h);
}

static void abe(void)
{
    char dir[4096];
    phc_harvest *h = NULL;
    phc_error err;
    phc_harvest_baad_options b = {.species = "Abies sachalinensis"};
    study_path(dir, sizeof dir, "Abe1981");
    CHECK(phc_harvest_read_baad(dir, &b, &h, &err) == PHC_ERR_INPUT);
    CHECK(h == NULL);
    CHECK_STR_CONTAINS(err.message, "Abe1981 cannot give root:shoot data: no root mass");
    printf("Abe1981: %s\n", err.message);
}

int main(void)
{
    char dir[4096];
    struct stat st;
    study_path(dir, sizeof dir, "Markesteijn2009");
    if (stat(dir, &st) != 0) {
        printf("# skip: %s is absent\n", dir);
        return 77;
    }
    markesteijn();
    aspinwall();
    abe();
    return check_finish("test_baad_harvest");
}
