/* Unit tests for measurements/baad.c with BAAD's config/ folder (as in the
 * whole database: baad/config/variableDefinitions.csv and
 * variableConversion.csv beside the study folders): every conversion
 * expression form BAAD uses, exactly (x/1000, 1/x, 10/x, x*10^-6,
 * x/(10^6), x*14e-6) and R's precedence; d.ba from a.stba; m.rt from m.rf +
 * m.rc; trimmed names; dataImportOptions.csv (skip, na.strings) with the
 * file's line numbers kept; empty and repeated header names; and the
 * errors: a conversion BAAD does not define, an expression that cannot be
 * read; phc_baad_lacks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "measurements/baad.h"

static char tmp_dir[] = "/tmp/phc_test_baad_config_XXXXXX";
static char tmp_paths[64][512];
static int n_tmp_paths = 0;

static int remember(const char *path)
{
    if (n_tmp_paths >= 64)
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

static const char *make_dir(const char *name)
{
    static char dirs[16][512];
    static int n = 0;
    char *d = dirs[n++ % 16];
    snprintf(d, sizeof dirs[0], "%s/%s", tmp_dir, name);
    if (mkdir(d, 0700) != 0 || remember(d) != 0)
        return NULL;
    return d;
}

static void remove_all(void)
{
    int i;
    for (i = n_tmp_paths - 1; i >= 0; --i)
        remove(tmp_paths[i]);
    rmdir(tmp_dir);
}

static const char *defs_csv =
    "variable,units,group,type,has_methods,essential,label,minValue,maxValue,allowableValues,"
    "description\n"
    "species,NA,species,character,FALSE,TRUE,species,NA,NA,NA,latin name\n"
    "age,yr,tree,numeric,TRUE,FALSE,age,1e-20,1000,NA,age\n"
    "a.stba,m2,tree,numeric,TRUE,FALSE,stem area at base,1e-20,100,NA,stem area\n"
    "h.t,m,tree,numeric,TRUE,FALSE,height,1e-20,150,NA,height\n"
    "d.ba,m,tree,numeric,TRUE,FALSE,basal diameter,1e-20,25,NA,basal diameter\n"
    "m.lf,kg,tree,numeric,TRUE,FALSE,leaf mass,1e-20,10000,NA,leaf mass\n"
    "m.st,kg,tree,numeric,TRUE,FALSE,total stem mass,1e-20,1e+07,NA,stem mass\n"
    "m.so,kg,tree,numeric,TRUE,FALSE,aboveground mass,1e-20,1e+07,NA,shoot mass\n"
    "m.rf,kg,tree,numeric,TRUE,FALSE,fine root mass,1e-20,1e+07,NA,fine roots\n"
    "m.rc,kg,tree,numeric,TRUE,FALSE,coarse root mass,1e-20,1e+07,NA,coarse roots\n"
    "m.rt,kg,tree,numeric,TRUE,FALSE,total root mass,1e-20,1e+07,NA,total root mass (=m.rf+m.rc)\n"
    "ma.ilf,kg/m2,tree,numeric,TRUE,FALSE,leaf mass per area,1e-20,10,NA,lma\n"
    "n.lf,kg/kg,tree,numeric,TRUE,FALSE,leaf nitrogen,1e-20,1,NA,n\n";

/* BAAD's own rows, plus "hm,m" to test R's precedence (-2^2 is -4). */
static const char *conv_csv = "unit_in,unit_out,conversion\n"
                              "g,kg,x/1000\n"
                              "mm,m,x/1000\n"
                              "m2/kg,kg/m2,1/x\n"
                              "cm2/g,kg/m2,10/x\n"
                              "mg,kg,x*10^-6\n"
                              "mm2,m2,x/(10^6)\n"
                              "mmol/N.kg,kg/kg,x*14e-6\n"
                              "months,yr,x/12\n"
                              "hm,m,-2^2*x + x*8\n"
                              "bad,kg/kg,x**\n";

/* Two lines before the header (skip 2), an empty header name and a repeated
 * one, a species with a trailing blank (quoted, so kept by the CSV reader),
 * "?" for not measured (na.strings), rows without d.ba but with a.stba. */
static const char *conv_data =
    "Study of conversions\n"
    "units: see dataMatchColumns\n"
    ",sp,d,a,h,root_f,root_c,shoot,sla,lma2,n,age,d\n"
    "1,\"Acer rubrum \",2.0,3.5,0.25,120,30,1.5,250,0.004,1.5,6,9\n"   /* line 4 */
    "2,Acer rubrum,,3.1415926535897932,0.5,100,?,2.0,200,0.005,2.0,18,9\n" /* line 5 */
    "3,Betula,?,,1,80,20,?,100,0.01,1,3,9\n";                          /* line 6 */

static const char *conv_match = "var_in,method,unit_in,var_out,notes\n"
                                "sp,NA,NA,species,NA\n"
                                "d,d1,mm,d.ba,NA\n"
                                "a,d1,mm2,a.stba,NA\n"
                                "h,d1,hm,h.t,NA\n"
                                "root_f,m1,mg,m.rf,NA\n"
                                "root_c,m1,mg,m.rc,NA\n"
                                "shoot,m1,g,m.so,NA\n"
                                "sla,m1,cm2/g,ma.ilf,NA\n"
                                "lma2,m1,m2/kg,n.lf,NA\n" /* removed in test_conversions */
                                "n,m1,mmol/N.kg,n.lf,NA\n"
                                "age,a1,months,age,NA\n"
                                "made_by_R,m1,g,m.lf,NA\n";

static const char *conv_new = "lookupVariable,lookupValue,newVariable,newValue,source\n"
                              "species,\"Acer rubrum  \",species,Acer rubrum L.,paper\n";

static const char *imports = "\"name\",\"data.csv\"\n"
                             "\"header\",\"TRUE\"\n"
                             "\"skip\",\"2\"\n"
                             "\"na.strings\",\"?\"\n";

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

static const char *study(const char *name, const char *data, const char *match, const char *nw,
                         const char *imp)
{
    const char *d = make_dir(name);
    if (!d || (data && write_file(d, "data.csv", data)) ||
        (match && write_file(d, "dataMatchColumns.csv", match)) ||
        (nw && write_file(d, "dataNew.csv", nw)) ||
        (imp && write_file(d, "dataImportOptions.csv", imp)))
        return NULL;
    return d;
}

static void test_conversions(void)
{
    /* lma2 (m2/kg, the reciprocal 1/x) goes to ma.ilf in a second study, as
     * a study maps each variable once */
    const char *match = edit(conv_match, "lma2,m1,m2/kg,n.lf,NA\n", "");
    const char *dir = study("Conv2020", conv_data, match, conv_new, imports);
    phc_baad_study *s = NULL;
    phc_error err;
    const phc_baad_row *r;
    const char *const *w = NULL;
    phc_baad_counts c;
    const double pi = 3.14159265358979323846;
    CHECK(dir != NULL);
    CHECK(phc_baad_read(dir, &s, &err) == 0);
    if (!s) {
        printf("  error: %s\n", err.message);
        return;
    }
    CHECK(phc_baad_rows(s) == 3);
    r = phc_baad_row_at(s, 0);
    CHECK(r->line == 4); /* the file's line, after the 2 skipped lines and the header */
    CHECK(!strcmp(r->species, "Acer rubrum L.")); /* trimmed, then matched by dataNew */
    CHECK(r->d_ba == 2.0 / 1000);                  /* x/1000 */
    CHECK(r->d_ba_derived == 0);                   /* given: a.stba not used */
    CHECK(r->h_t == -4 * 0.25 + 0.25 * 8);        /* R: -2^2 = -4 */
    CHECK(r->m_rt == 120 * 1e-6 + 30 * 1e-6);     /* m.rf + m.rc, each x*10^-6 */
    CHECK(r->m_rt_derived == 1);
    CHECK(r->m_so == 1.5 / 1000);
    CHECK(r->age == 6.0 / 12);
    CHECK(phc_baad_value(s, 0, "ma.ilf") == 10 / 250.0);          /* 10/x */
    CHECK(phc_baad_value(s, 0, "a.stba") == 3.5 / 1e6);           /* x/(10^6) */
    CHECK(phc_baad_value(s, 0, "n.lf") == 1.5 * 14e-6);           /* x*14e-6 */
    /* line 5: no d.ba, a.stba = pi mm2 -> d = 2 sqrt(pi 1e-6 / pi) m = 2 mm */
    r = phc_baad_row_at(s, 1);
    CHECK(r->line == 5);
    CHECK(!strcmp(r->species, "Acer rubrum L."));
    CHECK(r->d_ba_derived == 1);
    CHECK_NEAR(r->d_ba, 2.0 * sqrt(3.1415926535897932e-6 / pi), 0, 1e-15);
    CHECK_NEAR(r->d_ba, 2e-3, 0, 1e-15);
    CHECK(isnan(r->m_rt)); /* m.rc '?' is absent (na.strings): no sum */
    CHECK(r->m_rt_derived == 0);
    CHECK(r->root_shoot != r->root_shoot);
    /* line 6: d '?' and no a.stba: no diameter; shoot '?' */
    r = phc_baad_row_at(s, 2);
    CHECK(isnan(r->d_ba) && r->d_ba_derived == 0 && isnan(r->m_so));
    c = phc_baad_count(s);
    CHECK(c.conversions == 9);
    CHECK(c.skipped_mappings == 1);
    CHECK(c.derived_diameters == 1);
    CHECK(c.derived_roots == 2);
    CHECK(c.ages == 3);
    CHECK(c.trimmed == 2); /* "Acer rubrum " in data.csv, "Acer rubrum  " in dataNew.csv */
    CHECK(c.not_numbers == 0);
    CHECK(phc_baad_warnings(s, &w) == 1);
    CHECK_STR_CONTAINS(w[0], "dataMatchColumns.csv:12: var_in 'made_by_R' (var_out m.lf)");
    CHECK(phc_baad_lacks(s) == NULL);
    /* the empty and the repeated header names got names no mapping uses */
    CHECK(!strcmp(phc_baad_raw(s, 0, "(column 1)"), "1"));
    CHECK(!strcmp(phc_baad_raw(s, 0, "d (column 13)"), "9"));
    CHECK(!strcmp(phc_baad_raw(s, 0, "d"), "2.0"));
    phc_baad_free(s);

    /* the reciprocal conversion m2/kg -> kg/m2 (1/x) */
    match = "var_in,method,unit_in,var_out,notes\nsp,NA,NA,species,NA\nlma2,m1,m2/kg,ma.ilf,NA\n";
    dir = study("Recip2020", conv_data, match, NULL, imports);
    CHECK(phc_baad_read(dir, &s, &err) == 0);
    if (s) {
        CHECK(phc_baad_value(s, 0, "ma.ilf") == 1 / 0.004);
        CHECK(phc_baad_value(s, 2, "ma.ilf") == 1 / 0.01);
        CHECK(!strcmp(phc_baad_lacks(s), "no root mass: no column of data.csv is mapped to m.rt "
                                         "(nor to both m.rf and m.rc)"));
        printf("  Recip2020 lacks: %s\n", phc_baad_lacks(s));
    }
    phc_baad_free(s);
}

static void expect_error(const char *name, const char *match, const char *needle1,
                         const char *needle2)
{
    const char *dir = study(name, conv_data, match, NULL, imports);
    phc_baad_study *s = NULL;
    phc_error err;
    CHECK(dir != NULL);
    CHECK(phc_baad_read(dir, &s, &err) == PHC_ERR_INPUT);
    CHECK(s == NULL);
    CHECK_STR_CONTAINS(err.message, needle1);
    CHECK_STR_CONTAINS(err.message, needle2);
    printf("  %s: %s\n", name, err.message);
}

static void test_errors(void)
{
    /* a conversion BAAD does not define: kg is not mm's target here */
    expect_error("Undefined2020",
                 "var_in,method,unit_in,var_out,notes\nsp,NA,NA,species,NA\nd,d1,cm,d.ba,NA\n",
                 "dataMatchColumns.csv:3: unit_in of 'd' (d.ba): no conversion from 'cm' to 'm'",
                 "config/variableConversion.csv");
    /* an expression this reader cannot evaluate, named by its line */
    expect_error("BadExpr2020",
                 "var_in,method,unit_in,var_out,notes\nsp,NA,NA,species,NA\nn,d1,bad,n.lf,NA\n",
                 "config/variableConversion.csv:11: conversion 'x**'", "bad -> kg/kg");
}

int main(void)
{
    const char *cfg;
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    cfg = make_dir("config");
    if (!cfg || write_file(cfg, "variableDefinitions.csv", defs_csv) ||
        write_file(cfg, "variableConversion.csv", conv_csv)) {
        remove_all();
        return 1;
    }
    test_conversions();
    test_errors();
    remove_all();
    return check_finish("test_baad_config");
}
