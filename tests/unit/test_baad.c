/* Unit tests for measurements/baad.c: BAAD study folders built in a temporary
 * directory (a small variableDefinitions.csv in the parent, one folder per
 * case), checking mapping, unit conversion, dataNew, coordinates, derived
 * masses, flags and the error messages of bad inputs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "measurements/baad.h"
#include "measurements/geo.h"

static char tmp_dir[] = "/tmp/phc_test_baad_XXXXXX";
static char tmp_paths[128][512]; /* files, then folders, removed in reverse order */
static int n_tmp_paths = 0;

static int remember(const char *path)
{
    if (n_tmp_paths >= 128)
        return -1;
    snprintf(tmp_paths[n_tmp_paths++], sizeof tmp_paths[0], "%s", path);
    return 0;
}

static int write_file(const char *dir, const char *name, const char *text)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f)
        return -1;
    fputs(text, f);
    fclose(f);
    return remember(path);
}

static void remove_all(void)
{
    int i;
    for (i = n_tmp_paths - 1; i >= 0; --i)
        remove(tmp_paths[i]); /* remove() deletes empty folders too */
    rmdir(tmp_dir);
}

/* A subset of BAAD's variableDefinitions.csv (same columns). */
static const char *defs_csv =
    "variable,units,group,type,has_methods,essential,label,minValue,maxValue,allowableValues,"
    "description\n"
    "latitude,deg,site,numeric,FALSE,TRUE,latitude,-90,90,NA,latitude\n"
    "longitude,deg,site,numeric,FALSE,TRUE,longitude,-180,180,NA,longitude\n"
    "species,NA,species,character,FALSE,TRUE,species,NA,NA,NA,latin name\n"
    "growingCondition,NA,tree,character,FALSE,TRUE,growing environment,NA,NA,\"FW,GH\",env\n"
    "age,yr,tree,numeric,TRUE,FALSE,age,1e-20,1000,NA,age\n"
    "a.lf,m2,tree,numeric,TRUE,FALSE,leaf area,1e-20,10000,NA,leaf area\n"
    "h.t,m,tree,numeric,TRUE,FALSE,height,1e-20,150,NA,height\n"
    "d.ba,m,tree,numeric,TRUE,FALSE,basal diameter,1e-20,25,NA,basal diameter\n"
    "h.bh,m,tree,numeric,FALSE,FALSE,height of d.bh,1e-20,50,NA,h.bh\n"
    "m.lf,kg,tree,numeric,TRUE,FALSE,leaf mass,1e-20,10000,NA,leaf mass\n"
    "m.st,kg,tree,numeric,TRUE,FALSE,total stem mass,1e-20,1e+07,NA,stem mass\n"
    "m.so,kg,tree,numeric,TRUE,FALSE,aboveground mass,1e-20,1e+07,NA,shoot mass\n"
    "m.rt,kg,tree,numeric,TRUE,FALSE,total root mass,1e-20,1e+07,NA,root mass\n"
    "ma.ilf,kg/m2,tree,numeric,TRUE,FALSE,leaf mass per area,1e-20,10,NA,lma\n";

/* The good study: species codes AA, BB, CC; AA has 6 plants of 3 months on
 * one allometry (m = 0.01 g * (d/mm)^2.5; leaf 40 %, stem 60 %, root 50 %)
 * and one 25.0 mm diameter with a 2.0 mm plant's masses (line 8). */
static const char *good_data =
    "species,age (months),diam (mm),height (cm),leaf (g),stem (g),root (g),lma (g/cm2),"
    "Lat,Long,Light,cond\n"
    "AA,3,2.0,4.5,0.022627,0.033941,0.028284,0.004,10.5 S,20.25 E,L,GH\n"   /* line 2 */
    "AA,3,2.1,4.6,0.025563,0.038344,0.031953,,10.5 S,20.25 E,L,GH\n"        /* 3 */
    "AA,3,1.9,4.4,0.019904,0.029856,0.02488,,10.5 S,20.25 E,S,GH\n"         /* 4 */
    "AA,3,2.2,4.9,0.028716,0.043073,0.035894,,10.5 S,20.25 E,S,GH\n"        /* 5 */
    "AA,3,1.8,4.1,0.017388,0.026081,0.021735,,10.5 S,20.25 E,L,GH\n"        /* 6 */
    "AA,3,2.0,4.5,0.022627,0.033941,0.028284,,10.5 S,20.25 E,L,GH\n"        /* 7 */
    "AA,3,25.0,4.5,0.022627,0.033941,0.028284,,10.5 S,20.25 E,L,GH\n"       /* 8: outlier */
    "BB,6,3.5,7.0,0.05,0.07,0.04,,10.5 S,20.25 E,L,GH\n"                    /* 9 */
    "BB,6,3.0,6.0,0.04,0.06,0,,10.5 S,20.25 E,L,GH\n"                       /* 10: root 0 */
    "CC,12,-,NA,0.1,,0.2,,10.5 S,20.25 E,S,GH\n";                           /* 11: no d.ba */

static const char *good_match =
    "\"var_in\",\"method\",\"unit_in\",\"var_out\",\"notes\"\n"
    "\"species\",NA,NA,\"species\",NA\n"
    "\"age (months)\",\"k3\",\"months\",\"age\",NA\n"
    "\"diam (mm)\",\"d1\",\"mm\",\"d.ba\",NA\n"
    "\"height (cm)\",\"d7\",\"cm\",\"h.t\",NA\n"
    "\"leaf (g)\",\"m3\",\"g\",\"m.lf\",NA\n"
    "\"stem (g)\",\"m3\",\"g\",\"m.st\",NA\n"
    "\"root (g)\",\"m3\",\"g\",\"m.rt\",NA\n"
    "\"lma (g/cm2)\",\"m3\",\"g/cm2\",\"ma.ilf\",NA\n"
    "\"Lat\",NA,NA,NA,NA\n"
    "\"Long\",NA,NA,NA,NA\n"
    "\"Light\",NA,NA,NA,NA\n"
    "\"cond\",NA,NA,\"growingCondition\",NA\n";

static const char *good_new =
    "\"lookupVariable\",\"lookupValue\",\"newVariable\",\"newValue\",\"source\"\n"
    "\"species\",\"AA\",\"species\",\"Alpha alpha\",\"paper\"\n"
    "\"species\",\"BB\",\"species\",\"Beta beta\",\"paper\"\n"
    "\"species\",\"CC\",\"species\",\"Gamma gamma\",\"paper\"\n"
    "\"species\",\"ZZ\",\"species\",\"Nowhere\",\"paper\"\n"
    "\"\",\"\",\"latitude\",\"-10.6\",\"corrected\"\n"
    "NA,NA,\"h.bh\",1.3,\"default\"\n";

/* Makes tmp_dir/NAME with the given files (NULL: not written); returns the
 * folder's path in a static slot. */
static const char *make_study(const char *name, const char *data, const char *match,
                              const char *nw)
{
    static char dirs[32][512];
    static int n_dirs = 0;
    char *dir = dirs[n_dirs++ % 32];
    snprintf(dir, sizeof dirs[0], "%s/%s", tmp_dir, name);
    if (mkdir(dir, 0700) != 0 || remember(dir) != 0)
        return NULL;
    if ((data && write_file(dir, "data.csv", data)) ||
        (match && write_file(dir, "dataMatchColumns.csv", match)) ||
        (nw && write_file(dir, "dataNew.csv", nw)))
        return NULL;
    return dir;
}

/* Replaces the first occurrence of `from` in `text` by `to` (static buffer). */
static const char *edit(const char *text, const char *from, const char *to)
{
    static char buf[8][4096];
    static int slot = 0;
    char *b = buf[slot++ % 8];
    const char *p = strstr(text, from);
    if (!p)
        return NULL;
    snprintf(b, sizeof buf[0], "%.*s%s%s", (int)(p - text), text, to, p + strlen(from));
    return b;
}

static void test_good(void)
{
    const char *dir = make_study("Good2020", good_data, good_match, good_new);
    phc_baad_study *s = NULL;
    phc_error err;
    const char **species;
    const phc_baad_change *ch;
    const phc_baad_row *r;
    double shift;
    size_t i;
    int rc;
    CHECK(dir != NULL);
    rc = phc_baad_read(dir, &s, &err);
    CHECK(rc == 0);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(!strcmp(phc_baad_name(s), "Good2020"));
    CHECK(phc_baad_rows(s) == 10);
    CHECK(phc_baad_species(s, &species) == 3);
    CHECK(!strcmp(species[0], "Alpha alpha") && !strcmp(species[1], "Beta beta") &&
          !strcmp(species[2], "Gamma gamma"));

    /* line 2: conversions.  mm -> m and g -> kg are exact scalings by 1e-3. */
    r = phc_baad_row_at(s, 0);
    CHECK(r->line == 2);
    CHECK(r->d_ba == 0.001 * 2.0);
    CHECK(r->h_t == 0.01 * 4.5);
    CHECK(r->m_lf == 0.001 * 0.022627);
    CHECK(r->m_st == 0.001 * 0.033941);
    CHECK(r->m_rt == 0.001 * 0.028284);
    CHECK_NEAR(r->age, 0.25, 1e-15, 0);                      /* 3 months */
    CHECK_NEAR(phc_baad_value(s, 0, "ma.ilf"), 0.04, 1e-17, 0); /* g/cm2 -> kg/m2: x10 */
    CHECK(!strcmp(phc_baad_unit(s, "ma.ilf"), "kg/m2"));
    CHECK(!strcmp(phc_baad_unit(s, "d.ba"), "m"));
    CHECK(phc_baad_unit(s, "species") == NULL);
    /* derived shoot mass and root:shoot */
    CHECK(r->m_so_derived == 1);
    CHECK(r->m_so == r->m_st + r->m_lf);
    CHECK(r->root_shoot == r->m_rt / r->m_so);
    CHECK(!strcmp(r->species, "Alpha alpha"));
    CHECK(!strcmp(r->growing_condition, "GH"));
    CHECK(!strcmp(phc_baad_raw(s, 0, "Light"), "L"));
    CHECK(!strcmp(phc_baad_raw(s, 0, "Lat"), "10.5 S"));
    CHECK(phc_baad_raw(s, 0, "nope") == NULL);
    CHECK(phc_baad_raw(s, 99, "Light") == NULL);
    CHECK(phc_baad_value(s, 5, "h.bh") == 1.3);
    /* coordinates: dataNew's latitude, raw longitude; shift = raw -> corrected */
    CHECK(r->latitude == -10.6);
    CHECK(r->longitude == 20.25);
    CHECK(phc_geo_distance(-10.5, 20.25, -10.6, 20.25, &shift, NULL) == 0);
    CHECK(phc_baad_site_shift(s) == shift);
    CHECK_NEAR(phc_baad_site_shift(s), 11060, 20, 0); /* 0.1 deg of latitude */

    /* flags: the 25 mm diameter (line 8), the zero root (line 10) */
    for (i = 0; i < phc_baad_rows(s); ++i) {
        r = phc_baad_row_at(s, i);
        if (r->line == 8) {
            CHECK(r->flag == PHC_BAAD_SUSPICIOUS);
            CHECK_STR_CONTAINS(r->flag_reason, "d.ba 25 mm");
            CHECK_STR_CONTAINS(r->flag_reason, "7 Alpha alpha rows of age 0.25 yr");
            CHECK_STR_CONTAINS(r->flag_reason, "allometry");
        } else if (r->line == 10) {
            CHECK(r->flag == PHC_BAAD_INVALID);
            CHECK_STR_CONTAINS(r->flag_reason, "m.rt '0'");
            CHECK_STR_CONTAINS(r->flag_reason, "root (g)");
        } else {
            CHECK(r->flag == PHC_BAAD_OK);
            CHECK(r->flag_reason == NULL);
        }
    }
    CHECK(phc_baad_flagged(s, PHC_BAAD_SUSPICIOUS) == 1);
    CHECK(phc_baad_flagged(s, PHC_BAAD_INVALID) == 1);
    /* line 11: '-' diameter and NA height are absent, not errors */
    r = phc_baad_row_at(s, 9);
    CHECK(isnan(r->d_ba) && isnan(r->h_t) && isnan(r->m_st) && isnan(r->m_so));
    CHECK(r->m_so_derived == 0 && isnan(r->root_shoot));
    CHECK(r->age == 1.0 || fabs(r->age - 1.0) < 1e-15);

    /* dataNew counts */
    CHECK(phc_baad_changes(s, &ch) == 6);
    CHECK(ch[0].line == 2 && ch[0].rows_matched == 7 && ch[0].rows_changed == 7);
    CHECK(!strcmp(ch[0].lookup_value, "AA") && !strcmp(ch[0].new_value, "Alpha alpha"));
    CHECK(ch[2].rows_matched == 1);
    CHECK(ch[3].rows_matched == 0); /* ZZ: no such code; reported, not an error */
    CHECK(ch[4].lookup_variable == NULL && ch[4].rows_matched == 10 && ch[4].rows_changed == 10);
    CHECK(ch[5].line == 7 && !strcmp(ch[5].new_variable, "h.bh"));
    phc_baad_free(s);
}

/* Each bad study must fail with `status` and a message holding all needles. */
static void expect_error(const char *name, const char *data, const char *match, const char *nw,
                         int status, const char *needle1, const char *needle2)
{
    const char *dir = make_study(name, data, match, nw);
    phc_baad_study *s = (phc_baad_study *)&s; /* must be reset to NULL */
    phc_error err;
    int rc;
    CHECK(dir != NULL);
    if (!dir)
        return;
    rc = phc_baad_read(dir, &s, &err);
    CHECK(rc == status);
    CHECK(s == NULL);
    CHECK(err.status == status);
    CHECK_STR_CONTAINS(err.message, needle1);
    if (needle2)
        CHECK_STR_CONTAINS(err.message, needle2);
    printf("  %s: %s\n", name, err.message);
}

static void test_bad(void)
{
    /* unknown unit, line 4 of dataMatchColumns.csv */
    expect_error("BadUnit", good_data, edit(good_match, "\"mm\"", "\"furlongz\""), good_new,
                 PHC_ERR_INPUT, "dataMatchColumns.csv:4:", "'furlongz' is not a unit");
    /* a unit of the wrong dimension */
    expect_error("WrongDim", good_data, edit(good_match, "\"g\",\"m.lf\"", "\"cm\",\"m.lf\""),
                 good_new, PHC_ERR_INPUT, "dataMatchColumns.csv:6:", "'cm' cannot be converted");
    /* var_out BAAD does not define */
    expect_error("BadVarOut", good_data, edit(good_match, "\"h.t\"", "\"h.tt\""), good_new,
                 PHC_ERR_INPUT, "dataMatchColumns.csv:5:", "var_out 'h.tt'");
    /* a numeric variable without unit_in */
    expect_error("NoUnit", good_data, edit(good_match, "\"cm\",\"h.t\"", "NA,\"h.t\""), good_new,
                 PHC_ERR_INPUT, "dataMatchColumns.csv:5:", "no unit_in");
    /* dataNew: a newValue that is not a number for a numeric variable */
    expect_error("BadNewValue", good_data, good_match, edit(good_new, "1.3", "tall"),
                 PHC_ERR_INPUT, "dataNew.csv:7:", "found 'tall'");
    /* dataNew: a lookupVariable that names nothing */
    expect_error("BadLookup", good_data, good_match, edit(good_new, "\"species\",\"BB\"", "\"spp\",\"BB\""),
                 PHC_ERR_INPUT, "dataNew.csv:3:", "'spp'");
    /* no data.csv: the table reader's I/O error names the file */
    expect_error("NoData", NULL, good_match, good_new, PHC_ERR_IO, "data.csv", NULL);
    /* no dataMatchColumns.csv */
    expect_error("NoMatch", good_data, NULL, good_new, PHC_ERR_IO, "dataMatchColumns.csv", NULL);
}

/* A var_in that data.csv lacks (BAAD's dataManipulate.R would make it):
 * the mapping row is skipped with a warning naming the file and line. */
static void test_missing_var_in(void)
{
    const char *dir = make_study("MissingVarIn", good_data,
                                 edit(good_match, "\"height (cm)\"", "\"height (in)\""), good_new);
    phc_baad_study *s = NULL;
    phc_error err;
    const char *const *w = NULL;
    CHECK(dir != NULL);
    CHECK(phc_baad_read(dir, &s, &err) == 0);
    if (!s)
        return;
    CHECK(phc_baad_warnings(s, &w) == 1);
    CHECK_STR_CONTAINS(w[0], "dataMatchColumns.csv:5: var_in 'height (in)' (var_out h.t)");
    CHECK_STR_CONTAINS(w[0], "mapping skipped");
    CHECK(phc_baad_count(s).skipped_mappings == 1);
    CHECK(isnan(phc_baad_row_at(s, 0)->h_t));
    CHECK(phc_baad_row_at(s, 0)->d_ba == 0.002);
    printf("  MissingVarIn: %s\n", w[0]);
    phc_baad_free(s);
}

/* A cell that is not a number, a latitude that cannot be read: absent, as
 * R's as.numeric makes them in BAAD's build, with a warning naming the
 * file, line and column. */
static void test_not_numbers(void)
{
    const char *data = edit(edit(good_data, "AA,3,1.9,", "AA,3,1.9mm,"),
                            "2.1,4.6,0.025563,0.038344,0.031953,,10.5 S",
                            "2.1,4.6,0.025563,0.038344,0.031953,,10.5 E");
    const char *dir = make_study("NotANumber", data, good_match, good_new);
    phc_baad_study *s = NULL;
    phc_error err;
    const char *const *w = NULL;
    size_t n;
    CHECK(dir != NULL);
    CHECK(phc_baad_read(dir, &s, &err) == 0);
    if (!s)
        return;
    n = phc_baad_warnings(s, &w);
    CHECK(n == 2);
    if (n == 2) {
        CHECK_STR_CONTAINS(w[0], "data.csv:4: column 'diam (mm)' (d.ba): '1.9mm' is not a number");
        CHECK_STR_CONTAINS(w[1], "data.csv:3: column 'Lat' (latitude)");
        CHECK_STR_CONTAINS(w[1], "10.5 E");
        printf("  NotANumber: %s\n  NotANumber: %s\n", w[0], w[1]);
    }
    CHECK(phc_baad_count(s).not_numbers == 2);
    CHECK(isnan(phc_baad_row_at(s, 2)->d_ba));
    CHECK(phc_baad_text(s, 2, "d.ba") == NULL);
    CHECK(phc_baad_row_at(s, 3)->d_ba == 0.0022);
    phc_baad_free(s);
}

static void test_optional_and_free(void)
{
    /* dataNew.csv is optional; without it the codes stay and no shift exists */
    const char *dir = make_study("NoNew", good_data, good_match, NULL);
    phc_baad_study *s = NULL;
    phc_error err;
    CHECK(phc_baad_read(dir, &s, &err) == 0);
    if (s) {
        CHECK(!strcmp(phc_baad_row_at(s, 0)->species, "AA"));
        CHECK(phc_baad_row_at(s, 0)->latitude == -10.5); /* "10.5 S" */
        CHECK(isnan(phc_baad_site_shift(s)));
        CHECK(phc_baad_changes(s, NULL) == 0);
        CHECK(phc_baad_row_at(s, 10) == NULL);
    }
    phc_baad_free(s);
    phc_baad_free(NULL);
    CHECK(phc_baad_read(NULL, &s, &err) == PHC_ERR_INVALID);
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    if (write_file(tmp_dir, "variableDefinitions.csv", defs_csv)) {
        remove_all();
        return 1;
    }
    test_good();
    test_bad();
    test_missing_var_in();
    test_not_numbers();
    test_optional_and_free();
    remove_all();
    return check_finish("test_baad");
}
