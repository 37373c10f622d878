/* Every BAAD study folder in ../shared/data/baad (Falster et al. 2015,
 * Ecology 96:1445; data CC0): each is read with phc_baad_read as BAAD's own
 * build would for the variables root:shoot needs (config/variableConversion.csv,
 * mapping rows made by dataManipulate.R skipped with a warning, names
 * trimmed, d.ba from a.stba, ages).
 *
 * Printed, one line per study: rows read; rows usable for root:shoot (a
 * root mass, a shoot mass (m.so, or m.st + m.lf) and a basal diameter, all
 * > 0 and finite); rows with an age; flags: conversions applied (mapped
 * columns), mapping rows skipped, diameters derived from a.stba, root and
 * shoot masses derived from their parts, text cells trimmed; or the error.
 * Then a summary: studies loaded, studies that cannot give root:shoot with
 * phc_baad_lacks' message, errors.
 *
 * Checked: no study fails with an error; every study either has usable
 * rows, or no usable row and a clear phc_baad_lacks message, or has the
 * variables but no row with all three (listed); the known loads: Baltzer2007
 * keeps its 80 Quercus rubra rows; the whole loop takes <= 60 s.  Skipped
 * (exit 77) when ../shared/data/baad is absent. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "check.h"
#include "measurements/baad.h"

#define MAX_STUDIES 400

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The warning with the data folder's path cut to "Study/file:line". */
static const char *short_path(const char *w, const char *root)
{
    size_t n = strlen(root);
    return !strncmp(w, root, n) && w[n] == '/' ? w + n + 1 : w;
}

static int usable(const phc_baad_row *r)
{
    return isfinite(r->d_ba) && r->d_ba > 0 && isfinite(r->m_rt) && r->m_rt > 0 &&
           isfinite(r->m_so) && r->m_so > 0;
}

int main(void)
{
    char root[4096], *names[MAX_STUDIES], with_list[4096] = "", empty_list[2048] = "";
    size_t n_names = 0, i;
    size_t loaded = 0, errors = 0, with_rows = 0, lacking = 0, empty = 0;
    size_t total_rows = 0, total_usable = 0, total_aged = 0, total_conv = 0, total_skipped = 0;
    size_t total_derived_d = 0, total_derived_rt = 0, total_trimmed = 0, q_rubra = 0;
    size_t lack_root = 0, lack_shoot = 0, lack_diameter = 0, total_warnings = 0, total_nan = 0;
    struct timespec t0, t1;
    struct stat st;
    DIR *d;
    struct dirent *e;
    double seconds;

    snprintf(root, sizeof root, "%s/baad", PHC_SHARED_DATA);
    d = opendir(root);
    if (!d) {
        printf("# skip: %s is absent (the whole BAAD database goes there)\n", root);
        return 77;
    }
    while ((e = readdir(d)) != NULL) {
        char path[4400];
        if (e->d_name[0] == '.' || !strcmp(e->d_name, "config"))
            continue;
        snprintf(path, sizeof path, "%s/%s", root, e->d_name);
        if (stat(path, &st) || !S_ISDIR(st.st_mode))
            continue;
        if (n_names < MAX_STUDIES)
            names[n_names++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(names, n_names, sizeof *names, cmp_str);

    printf("%-22s %6s %6s %6s  %s\n", "study", "rows", "usable", "aged", "flags / message");
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (i = 0; i < n_names; ++i) {
        char path[4400];
        phc_baad_study *s = NULL;
        phc_error err;
        phc_baad_counts c;
        const char *lacks;
        size_t n, j, use = 0;
        snprintf(path, sizeof path, "%s/%s", root, names[i]);
        if (phc_baad_read(path, &s, &err)) {
            printf("%-22s ERROR %s\n", names[i], err.message);
            ++errors;
            continue;
        }
        ++loaded;
        n = phc_baad_rows(s);
        for (j = 0; j < n; ++j) {
            const phc_baad_row *r = phc_baad_row_at(s, j);
            use += (size_t)usable(r);
            if (!strcmp(names[i], "Baltzer2007") && r->species &&
                !strcmp(r->species, "Quercus rubra"))
                ++q_rubra;
        }
        c = phc_baad_count(s);
        lacks = phc_baad_lacks(s);
        printf("%-22s %6zu %6zu %6zu  conv %zu, skipped %zu, d<-a.stba %zu, rt<-parts %zu, "
               "so<-parts %zu, trimmed %zu, not numbers %zu%s%s\n",
               names[i], n, use, c.ages, c.conversions, c.skipped_mappings, c.derived_diameters,
               c.derived_roots, c.derived_shoots, c.trimmed, c.not_numbers, lacks ? "; " : "",
               lacks ? lacks : "");
        {
            const char *const *w = NULL;
            size_t nw = phc_baad_warnings(s, &w);
            for (j = 0; j < nw; ++j)
                printf("    warning: %s\n", strrchr(w[j], '/') ? short_path(w[j], root) : w[j]);
            total_warnings += nw;
        }
        if (!strcmp(names[i], "Markesteijn2009")) {
            /* data.csv:2: a.stba 6.651 mm2 and no diameter: d = 2 sqrt(a/pi) */
            const phc_baad_row *r = phc_baad_row_at(s, 0);
            CHECK(r->d_ba_derived == 1);
            CHECK_NEAR(r->d_ba, 2.0 * sqrt(6.651e-6 / 3.14159265358979323846), 0, 1e-15);
            printf("    check: data.csv:2 d.ba = %.6g mm from a.stba 6.651 mm2\n", 1e3 * r->d_ba);
        }
        if (!strcmp(names[i], "Aspinwall2013")) {
            /* data.csv:2: SLA 38.96222495 cm2/g -> ma.ilf kg/m2 by BAAD's 10/x */
            double v = phc_baad_value(s, 0, "ma.ilf");
            CHECK_NEAR(v, 10.0 / 38.96222495, 0, 1e-15);
            printf("    check: data.csv:2 ma.ilf = %.9g kg/m2 from SLA 38.96222495 cm2/g (10/x)\n", v);
        }
        total_rows += n;
        total_usable += use;
        total_aged += c.ages;
        total_conv += c.conversions;
        total_skipped += c.skipped_mappings;
        total_derived_d += c.derived_diameters;
        total_derived_rt += c.derived_roots;
        total_trimmed += c.trimmed;
        total_nan += c.not_numbers;
        if (use) {
            ++with_rows;
            snprintf(with_list + strlen(with_list), sizeof with_list - strlen(with_list), "%s%s (%zu)",
                     *with_list ? ", " : "", names[i], use);
        } else if (lacks) {
            ++lacking;
            lack_root += !strncmp(lacks, "no root", 7);
            lack_shoot += !strncmp(lacks, "no shoot", 8);
            lack_diameter += !strncmp(lacks, "no basal", 8);
        } else {
            ++empty;
            snprintf(empty_list + strlen(empty_list), sizeof empty_list - strlen(empty_list), "%s%s",
                     *empty_list ? ", " : "", names[i]);
        }
        /* a study with usable rows has the three variables */
        CHECK(!use || !lacks);
        phc_baad_free(s);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);

    printf("\nsummary: %zu study folders, %zu loaded, %zu errors, %.1f s\n", n_names, loaded,
           errors, seconds);
    printf("  rows read %zu, usable for root:shoot %zu, with an age %zu\n", total_rows,
           total_usable, total_aged);
    printf("  columns converted by variableConversion.csv %zu, mapping rows skipped %zu, "
           "diameters from a.stba %zu, root masses from m.rf + m.rc %zu, text cells trimmed %zu, "
           "cells not numbers (read as absent) %zu, warnings %zu\n",
           total_conv, total_skipped, total_derived_d, total_derived_rt, total_trimmed, total_nan,
           total_warnings);
    printf("  studies with usable root:shoot rows %zu; lacking a variable %zu (no root mass %zu, "
           "no shoot mass %zu, no basal diameter %zu); variables present but no row with all "
           "three %zu\n",
           with_rows, lacking, lack_root, lack_shoot, lack_diameter, empty);
    printf("  with usable rows: %s\n", with_list);
    printf("  variables present, no row with all three: %s\n", empty_list);
    printf("  Baltzer2007 Quercus rubra rows %zu\n", q_rubra);

    CHECK(n_names > 0);
    CHECK(errors == 0);
    CHECK(loaded == n_names);
    CHECK(with_rows + lacking + empty == loaded);
    CHECK(q_rubra == 80);
    CHECK(total_skipped > 0 && total_derived_d > 0); /* the new rules were exercised */
    CHECK(seconds <= 60.0);
    for (i = 0; i < n_names; ++i)
        free(names[i]);
    return check_finish("test_baad_all");
}
