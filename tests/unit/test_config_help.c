/* Unit tests for fit/config_help.c and the key registry of fit/config.c:
 * the help tables must pair one to one with the key tables the loader
 * checks, so that `phytocal help` cannot drift from what a config may say.
 *
 *   test_config_help              runs the checks
 *   test_config_help --print [K]  writes the help (overview, or kind K) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/config.h"
#include "fit/config_help.h"

/* Every key has exactly one help entry with a non-empty text that says
 * whether the key is required or what its default is, and every help entry
 * names a key of the table. */
static void check_section(const phc_config_section *s)
{
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK(s->name && s->name[0]);
    CHECK(s->summary && s->summary[0]);
    CHECK(s->keys && s->help);
    if (!s->keys || !s->help)
        return;
    size_t n_keys = 0;
    for (size_t i = 0; s->keys[i]; ++i, ++n_keys) {
        size_t entries = 0;
        for (size_t j = 0; s->help[j].key; ++j)
            entries += strcmp(s->help[j].key, s->keys[i]) == 0;
        if (entries != 1)
            fprintf(stderr, "%s: key '%s' has %zu help entries\n", s->name, s->keys[i], entries);
        CHECK(entries == 1);
        for (size_t j = 0; j < i; ++j)
            if (strcmp(s->keys[j], s->keys[i]) == 0) {
                fprintf(stderr, "%s: key '%s' is listed twice\n", s->name, s->keys[i]);
                CHECK(0);
            }
    }
    size_t n_help = 0;
    for (size_t j = 0; s->help[j].key; ++j, ++n_help) {
        int found = 0;
        for (size_t i = 0; s->keys[i] && !found; ++i)
            found = strcmp(s->keys[i], s->help[j].key) == 0;
        if (!found)
            fprintf(stderr, "%s: help entry '%s' names no key of the table\n", s->name, s->help[j].key);
        CHECK(found);
        const char *h = s->help[j].help;
        CHECK(h && h[0]);
        if (h && !strstr(h, "Required") && !strstr(h, "required") && !strstr(h, "Default") &&
            !strstr(h, "Optional") && !strstr(h, "Give exactly one")) {
            fprintf(stderr, "%s: help of '%s' says neither that it is required nor its default\n",
                    s->name, s->help[j].key);
            CHECK(0);
        }
    }
    CHECK(s->help[n_help].help == NULL);
    CHECK(n_keys == n_help);
    CHECK(phc_key_help_find(s->help, s->keys[0]) != NULL);
    CHECK(phc_key_help_find(s->help, "no such key") == NULL);
}

/* The help for `kind` (NULL: the overview) as a string; *rc its status. */
static char *help_text(const char *kind, int *rc, phc_error *err)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    CHECK(f != NULL);
    if (!f)
        return NULL;
    *rc = phc_config_write_help(f, kind, err);
    fclose(f);
    return buf;
}

/* `key` starts a line of the key list: "\n  key " or "\n  key\n". */
static int lists_key(const char *text, const char *key)
{
    char a[128], b[128];
    snprintf(a, sizeof a, "\n  %s ", key);
    snprintf(b, sizeof b, "\n  %s\n", key);
    return strstr(text, a) || strstr(text, b);
}

/* No line is wider than 79 columns (UTF-8 code points). */
static int fits_80_columns(const char *text)
{
    size_t col = 0, widest = 0;
    for (const char *p = text; *p; ++p) {
        if (*p == '\n') {
            col = 0;
            continue;
        }
        col += ((unsigned char)*p & 0xC0) != 0x80;
        widest = col > widest ? col : widest;
    }
    return widest <= 79;
}

static void check_section_written(const char *text, const phc_config_section *s)
{
    for (size_t i = 0; s->keys[i]; ++i) {
        if (!lists_key(text, s->keys[i]))
            fprintf(stderr, "help of %s does not list key '%s'\n", s->name, s->keys[i]);
        CHECK(lists_key(text, s->keys[i]));
    }
}

static void test_tables(void)
{
    const size_t n = phc_config_kind_count();
    CHECK(n >= 8);
    for (size_t i = 0; i < n; ++i) {
        const phc_config_section *k = phc_config_kind_at(i);
        check_section(k);
        CHECK(phc_config_kind_find(k->name) == k);
        /* A kind's keys do not repeat the common ones (the loader allows
         * the union, so a repeated key would have two meanings). */
        const phc_config_section *common = phc_config_block(PHC_CONFIG_DATASET);
        for (size_t a = 0; k->keys[a]; ++a)
            for (size_t b = 0; common->keys[b]; ++b)
                CHECK(strcmp(k->keys[a], common->keys[b]) != 0);
    }
    CHECK(phc_config_kind_at(n) == NULL);
    CHECK(phc_config_kind_find("weight_curv") == NULL);
    CHECK(phc_config_kind_find(NULL) == NULL);
    static const char *const expected[] = {"curve", "elasticity_curve", "infiltration", "leaf_photos",
                                           "pv_curve", "root_shoot", "shape_series", "soil_probe", "weight_curve"};
    for (size_t i = 0; i < sizeof expected / sizeof expected[0]; ++i)
        CHECK(phc_config_kind_find(expected[i]) != NULL);
    for (int b = 0; b < PHC_CONFIG_N_BLOCKS; ++b)
        check_section(phc_config_block((phc_config_block_id)b));
    CHECK(phc_config_block(PHC_CONFIG_N_BLOCKS) == NULL);
    CHECK(strcmp(phc_config_block(PHC_CONFIG_SOLVER)->name, "solver") == 0);
    CHECK(strcmp(phc_config_block(PHC_CONFIG_SOIL)->name, "soil") == 0);
}

static void test_overview(void)
{
    phc_error err = {0};
    int rc = -1;
    char *text = help_text(NULL, &rc, &err);
    CHECK(rc == PHC_OK);
    CHECK(text != NULL);
    if (!text)
        return;
    static const phc_config_block_id blocks[] = {PHC_CONFIG_TOP, PHC_CONFIG_PARAMETER, PHC_CONFIG_DATASET,
                                                 PHC_CONFIG_SOLVER, PHC_CONFIG_REPORT};
    for (size_t b = 0; b < sizeof blocks / sizeof blocks[0]; ++b)
        check_section_written(text, phc_config_block(blocks[b]));
    for (size_t i = 0; i < phc_config_kind_count(); ++i)
        CHECK(lists_key(text, phc_config_kind_at(i)->name));
    CHECK_STR_CONTAINS(text, "solver: ");
    CHECK(fits_80_columns(text));
    free(text);
}

static void test_kinds(void)
{
    for (size_t i = 0; i < phc_config_kind_count(); ++i) {
        const phc_config_section *k = phc_config_kind_at(i);
        phc_error err = {0};
        int rc = -1;
        char *text = help_text(k->name, &rc, &err);
        CHECK(rc == PHC_OK);
        CHECK(text != NULL);
        if (!text)
            continue;
        CHECK(strncmp(text, k->name, strlen(k->name)) == 0);
        check_section_written(text, k);
        int soil = 0;
        for (size_t j = 0; k->keys[j]; ++j)
            soil |= strcmp(k->keys[j], "soil") == 0;
        if (soil)
            check_section_written(text, phc_config_block(PHC_CONFIG_SOIL));
        else
            CHECK(!lists_key(text, "geo_origin"));
        CHECK(fits_80_columns(text));
        free(text);
    }
    /* A block by its name. */
    phc_error err = {0};
    int rc = -1;
    char *text = help_text("soil", &rc, &err);
    CHECK(rc == PHC_OK);
    if (text)
        check_section_written(text, phc_config_block(PHC_CONFIG_SOIL));
    free(text);
}

static void test_unknown(void)
{
    phc_error err = {0};
    int rc = -1;
    char *text = help_text("weight_curv", &rc, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(err.status == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "unknown kind 'weight_curv'");
    CHECK_STR_CONTAINS(err.message, "did you mean 'weight_curve'?");
    CHECK_STR_CONTAINS(err.message, "pv_curve");
    CHECK(text && text[0] == '\0'); /* nothing written */
    free(text);

    phc_error_clear(&err);
    text = help_text("zzzzzzzzzz", &rc, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(!strstr(err.message, "did you mean"));
    CHECK_STR_CONTAINS(err.message, "kinds: curve, elasticity_curve");
    free(text);

    CHECK(phc_config_write_help(NULL, NULL, &err) == PHC_ERR_INVALID);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--print") == 0) {
        phc_error err = {0};
        int rc = phc_config_write_help(stdout, argc > 2 ? argv[2] : NULL, &err);
        if (rc)
            fprintf(stderr, "%s\n", err.message);
        return rc ? 1 : 0;
    }
    test_tables();
    test_overview();
    test_kinds();
    test_unknown();
    return check_finish("test_config_help");
}
