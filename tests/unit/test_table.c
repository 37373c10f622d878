/* Unit tests for measurements/table.c: the CSV reader and its messages. */
#include <locale.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "measurements/table.h"

/* Every test file lives in one mkdtemp() directory, removed at the end. */
static char tmp_dir[] = "/tmp/phc_test_table_XXXXXX";
static char tmp_files[64][256];
static int n_tmp_files = 0;

/* Writes `length` bytes (or strlen when length is (size_t)-1) to a file
 * named `name` in the temporary directory; returns its path (static slot). */
static const char *write_file(const char *name, const char *text, size_t length)
{
    char *path;
    FILE *f;
    if (length == (size_t)-1)
        length = strlen(text);
    if (n_tmp_files >= 64)
        return NULL;
    path = tmp_files[n_tmp_files++];
    snprintf(path, sizeof tmp_files[0], "%s/%s", tmp_dir, name);
    f = fopen(path, "wb");
    if (!f)
        return NULL;
    if (length)
        fwrite(text, 1, length, f);
    fclose(f);
    return path;
}

static void remove_files(void)
{
    int i;
    for (i = 0; i < n_tmp_files; ++i)
        remove(tmp_files[i]);
    rmdir(tmp_dir);
}

/* Reads a table from a string through a real file. */
static int read_text(const char *name, const char *text, phc_table **t, phc_error *err)
{
    const char *path = write_file(name, text, (size_t)-1);
    if (!path)
        return -1;
    return phc_table_read(path, t, err);
}

static int cell_is(const phc_table *t, size_t r, size_t c, const char *want)
{
    const char *got = phc_table_cell(t, r, c);
    if (got && !strcmp(got, want))
        return 1;
    fprintf(stderr, "cell (%zu, %zu) = '%s', expected '%s'\n", r, c, got ? got : "(null)",
            want);
    return 0;
}

static void test_normal(void)
{
    phc_table *t = NULL;
    phc_error err;
    double *v = NULL;
    int rc = read_text("normal.csv",
                       "# balance export\n"
                       "\n"
                       "t, mass_g ,note\n"
                       "0,10.5,start\n"
                       "   # a comment between rows\n"
                       "1.5, 9.25 ,\n"
                       "3,8e0,end",  /* no final newline */
                       &t, &err);
    CHECK(rc == 0);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(strstr(phc_table_source(t), "normal.csv") != NULL);
    CHECK(phc_table_rows(t) == 3);
    CHECK(phc_table_columns(t) == 3);
    CHECK(!strcmp(phc_table_column_name(t, 1), "mass_g"));
    CHECK(phc_table_column_name(t, 3) == NULL);
    CHECK(phc_table_find(t, "note") == 2);
    CHECK(phc_table_find(t, "Note") == -1);
    CHECK(phc_table_find(t, NULL) == -1);
    CHECK(cell_is(t, 0, 2, "start"));
    CHECK(cell_is(t, 1, 1, "9.25"));
    CHECK(cell_is(t, 1, 2, ""));
    CHECK(cell_is(t, 2, 2, "end"));
    CHECK(phc_table_cell(t, 3, 0) == NULL);
    CHECK(phc_table_cell(t, 0, 3) == NULL);
    CHECK(phc_table_row_line(t, 0) == 4);
    CHECK(phc_table_row_line(t, 1) == 6);
    CHECK(phc_table_row_line(t, 2) == 7);
    CHECK(phc_table_row_line(t, 3) == 0);
    rc = phc_table_column_numbers(t, "mass_g", &v, &err);
    CHECK(rc == 0);
    CHECK(v != NULL);
    if (v) {
        CHECK_NEAR(v[0], 10.5, 0, 0);
        CHECK_NEAR(v[1], 9.25, 0, 0);
        CHECK_NEAR(v[2], 8.0, 0, 0);
    }
    free(v);
    v = NULL;
    /* The note column has text and an empty cell: an error only when asked. */
    rc = phc_table_column_numbers(t, "note", &v, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(v == NULL);
    CHECK_STR_CONTAINS(err.message, "normal.csv:4: column 'note': expected a finite number, found 'start'");
    phc_table_free(t);
    phc_table_free(NULL);
}

static void test_delimiters(void)
{
    static const struct {
        const char *name, *text;
    } cases[] = {
        {"comma.csv", "a,b\n1,2\n3,4\n"},
        {"semicolon.csv", "a;b\n1;2\n3;4\n"},
        {"tab.tsv", "a\tb\n1\t2\n3\t4\n"},
        {"spaces.txt", "  a    b  \n1 \t 2\n\t3   4\t\n"},
        {"tab_spaces.tsv", "a \t b\n 1 \t 2 \n3\t4\n"},
    };
    size_t i;
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        phc_table *t = NULL;
        phc_error err;
        double *v = NULL;
        int rc = read_text(cases[i].name, cases[i].text, &t, &err);
        CHECK(rc == 0);
        if (rc) {
            fprintf(stderr, "%s: %s\n", cases[i].name, err.message);
            continue;
        }
        CHECK(phc_table_columns(t) == 2);
        CHECK(phc_table_rows(t) == 2);
        CHECK(cell_is(t, 0, 0, "1"));
        CHECK(cell_is(t, 1, 1, "4"));
        CHECK(phc_table_find(t, "b") == 1);
        CHECK(phc_table_column_numbers(t, "b", &v, &err) == 0);
        if (v)
            CHECK_NEAR(v[1], 4.0, 0, 0);
        free(v);
        phc_table_free(t);
    }
    {
        /* ',' wins over ';' on the header line; ';' then stays data. */
        phc_table *t = NULL;
        phc_error err;
        int rc = read_text("priority.csv", "a;x,b\n1;2,3\n", &t, &err);
        CHECK(rc == 0);
        if (!rc) {
            CHECK(phc_table_columns(t) == 2);
            CHECK(!strcmp(phc_table_column_name(t, 0), "a;x"));
            CHECK(cell_is(t, 0, 0, "1;2"));
        }
        phc_table_free(t);
    }
    {
        /* A single column: no delimiter at all. */
        phc_table *t = NULL;
        phc_error err;
        int rc = read_text("single.csv", "mass\n1\n2\n", &t, &err);
        CHECK(rc == 0);
        if (!rc) {
            CHECK(phc_table_columns(t) == 1);
            CHECK(phc_table_rows(t) == 2);
        }
        phc_table_free(t);
    }
}

static void test_quotes(void)
{
    phc_table *t = NULL;
    phc_error err;
    double *v = NULL;
    /* The comma inside the quoted header name must not pick ','; ';' does. */
    int rc = read_text("quoted.csv",
                       "\"mass, g\";\"say \"\"hi\"\"\";plain\n"
                       "\"1.5\";  \"a;b\"  ;it's 3\" long\n"
                       "2;\"two\nlines\";x\n"
                       "3;\"\";\"\"\n",
                       &t, &err);
    CHECK(rc == 0);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(phc_table_columns(t) == 3);
    CHECK(!strcmp(phc_table_column_name(t, 0), "mass, g"));
    CHECK(!strcmp(phc_table_column_name(t, 1), "say \"hi\""));
    CHECK(cell_is(t, 0, 0, "1.5"));
    CHECK(cell_is(t, 0, 1, "a;b"));
    CHECK(cell_is(t, 0, 2, "it's 3\" long"));
    CHECK(cell_is(t, 1, 1, "two\nlines"));
    CHECK(cell_is(t, 2, 1, ""));
    CHECK(cell_is(t, 2, 2, ""));
    CHECK(phc_table_row_line(t, 1) == 3);
    CHECK(phc_table_row_line(t, 2) == 5); /* after the two-line field */
    CHECK(phc_table_column_numbers(t, "mass, g", &v, &err) == 0);
    if (v)
        CHECK_NEAR(v[0], 1.5, 0, 0);
    free(v);
    v = NULL;
    /* A quoted empty cell is still empty. */
    rc = phc_table_column_numbers(t, "plain", &v, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "quoted.csv:2: column 'plain': expected a finite number, found 'it's 3\" long'");
    phc_table_free(t);

    /* Whitespace-separated with quoted names that contain blanks. */
    t = NULL;
    rc = read_text("ws_quoted.txt", "\"leaf area\" \"dry mass\"\n  1   \"2\"\n", &t, &err);
    CHECK(rc == 0);
    if (!rc) {
        CHECK(phc_table_find(t, "dry mass") == 1);
        CHECK(cell_is(t, 0, 1, "2"));
    }
    phc_table_free(t);

    /* Text glued to a closing quote. */
    t = NULL;
    rc = read_text("glued.csv", "a,b\n1,\"x\"y\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(t == NULL);
    CHECK_STR_CONTAINS(err.message, "glued.csv:2: unexpected 'y' after a closing quote");

    /* Unterminated: the message names the line where the quote opened. */
    rc = read_text("unterminated.csv", "a,b\n1,2\n3,\"open\n4,5\n6,7\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(t == NULL);
    CHECK_STR_CONTAINS(err.message, "unterminated.csv:3: unterminated quoted field");
}

static void test_line_ends_and_bom(void)
{
    phc_table *t = NULL;
    phc_error err;
    double *v = NULL;
    int rc = read_text("crlf.csv", "\xEF\xBB\xBFt,m\r\n# c\r\n0,1.5\r\n\r\n1,\"a\r\nb\"\r\n", &t,
                       &err);
    CHECK(rc == 0);
    if (!rc) {
        CHECK(!strcmp(phc_table_column_name(t, 0), "t")); /* no BOM in the name */
        CHECK(phc_table_rows(t) == 2);
        CHECK(cell_is(t, 0, 1, "1.5"));
        CHECK(cell_is(t, 1, 1, "a\nb"));
        CHECK(phc_table_row_line(t, 0) == 3);
        CHECK(phc_table_row_line(t, 1) == 5);
        CHECK(phc_table_column_numbers(t, "t", &v, &err) == 0);
        free(v);
        v = NULL;
        CHECK(phc_table_column_numbers(t, "m", &v, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "crlf.csv:5: column 'm': expected a finite number, found 'a b'");
    }
    phc_table_free(t);

    /* Old Mac line ends (lone CR). */
    t = NULL;
    rc = read_text("cr.csv", "a,b\r1,2\r3,4", &t, &err);
    CHECK(rc == 0);
    if (!rc) {
        CHECK(phc_table_rows(t) == 2);
        CHECK(phc_table_row_line(t, 1) == 3);
        CHECK(cell_is(t, 1, 1, "4"));
    }
    phc_table_free(t);
}

static void test_bad_numbers(void)
{
    char text[4096];
    size_t used = 0;
    int line;
    phc_table *t = NULL;
    phc_error err;
    double *v = (double *)&err; /* must be reset to NULL on failure */
    int rc;

    /* The design document's example: line 17 of weights.csv holds n/a. */
    used += (size_t)snprintf(text + used, sizeof text - used, "t,mass_g\n");
    for (line = 2; line <= 20; ++line)
        used += (size_t)snprintf(text + used, sizeof text - used, "%d,%s\n", line,
                                 line == 17 ? "n/a" : "12.5");
    rc = read_text("weights.csv", text, &t, &err);
    CHECK(rc == 0);
    if (!rc) {
        rc = phc_table_column_numbers(t, "mass_g", &v, &err);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK(err.status == PHC_ERR_INPUT);
        CHECK(v == NULL);
        CHECK_STR_CONTAINS(err.message, "weights.csv:17: column 'mass_g': expected a finite number, found 'n/a'");
        /* The other column is fine. */
        CHECK(phc_table_column_numbers(t, "t", &v, &err) == 0);
        if (v)
            CHECK_NEAR(v[18], 20.0, 0, 0);
        free(v);
    }
    phc_table_free(t);

    {
        static const struct {
            const char *cell, *message;
        } cases[] = {
            {"", "bad.csv:3: column 'x': expected a finite number, found an empty cell"},
            {"nan", "bad.csv:3: column 'x': expected a finite number, found 'nan'"},
            {"NaN", "bad.csv:3: column 'x': expected a finite number, found 'NaN'"},
            {"inf", "bad.csv:3: column 'x': expected a finite number, found 'inf'"},
            {"-Infinity", "found '-Infinity'"},
            {"1e999", "found '1e999'"},
            {"12abc", "found '12abc'"},
            {"1,5", NULL}, /* ragged instead: checked below */
            {"\" 7\"", "found ' 7'"},
            {"\"7 \"", "found '7 '"},
        };
        size_t i;
        for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
            char buf[256];
            if (!cases[i].message)
                continue;
            snprintf(buf, sizeof buf, "x,y\n1,2\n%s,3\n", cases[i].cell);
            t = NULL;
            rc = read_text("bad.csv", buf, &t, &err);
            CHECK(rc == 0);
            if (rc)
                continue;
            v = NULL;
            rc = phc_table_column_numbers(t, "x", &v, &err);
            CHECK(rc == PHC_ERR_INPUT);
            CHECK(v == NULL);
            CHECK_STR_CONTAINS(err.message, cases[i].message);
            phc_table_free(t);
        }
    }

    /* Good numbers in C syntax, with blanks trimmed around unquoted cells. */
    t = NULL;
    rc = read_text("good.csv", "x\n  -1.5e-3 \n+2\n0x10\n.5\n1e-320\n", &t, &err);
    CHECK(rc == 0);
    if (!rc) {
        v = NULL;
        CHECK(phc_table_column_numbers(t, "x", &v, &err) == 0);
        if (v) {
            CHECK_NEAR(v[0], -1.5e-3, 0, 0);
            CHECK_NEAR(v[1], 2.0, 0, 0);
            CHECK_NEAR(v[2], 16.0, 0, 0);
            CHECK_NEAR(v[3], 0.5, 0, 0);
            CHECK(v[4] > 0 && v[4] < 1e-300);
        }
        free(v);
    }
    phc_table_free(t);

    /* A very long cell is cut in the message, and the message keeps its head. */
    {
        size_t n = 5000, k;
        char *big = malloc(n + 32);
        CHECK(big != NULL);
        if (big) {
            strcpy(big, "x\n");
            for (k = 2; k < n; ++k)
                big[k] = 'z';
            strcpy(big + n, "\n");
            t = NULL;
            rc = read_text("longcell.csv", big, &t, &err);
            CHECK(rc == 0);
            if (!rc) {
                v = NULL;
                CHECK(phc_table_column_numbers(t, "x", &v, &err) == PHC_ERR_INPUT);
                CHECK_STR_CONTAINS(err.message, "longcell.csv:2: column 'x': expected a finite number, found 'zzzz");
                CHECK_STR_CONTAINS(err.message, "...'");
                CHECK(strlen(err.message) < 300);
            }
            phc_table_free(t);
            free(big);
        }
    }
}

static void test_unknown_column(void)
{
    phc_table *t = NULL;
    phc_error err;
    double *v = (double *)&err;
    int rc = read_text("cols.csv", "# units: h, g\ntime_h,mass_g,leaf_area\n1,2,3\n", &t, &err);
    CHECK(rc == 0);
    if (rc)
        return;
    rc = phc_table_column_numbers(t, "mass_gr", &v, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(v == NULL);
    CHECK_STR_CONTAINS(err.message, "cols.csv:2: unknown column 'mass_gr'; did you mean 'mass_g'?");
    CHECK_STR_CONTAINS(err.message, "'time_h', 'mass_g', 'leaf_area'");
    rc = phc_table_column_numbers(t, "temperature", &v, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(strstr(err.message, "did you mean") == NULL);
    CHECK_STR_CONTAINS(err.message, "cols.csv:2: unknown column 'temperature' (columns: 'time_h', 'mass_g', 'leaf_area')");
    CHECK(phc_table_column_numbers(t, NULL, &v, &err) == PHC_ERR_INVALID);
    CHECK(phc_table_column_numbers(NULL, "x", &v, &err) == PHC_ERR_INVALID);
    phc_table_free(t);
}

static void test_structure_errors(void)
{
    phc_table *t = NULL;
    phc_error err;
    int rc;

    rc = read_text("ragged.csv", "a,b\n1,2\n\n# skip\n1,2,3\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(t == NULL);
    CHECK_STR_CONTAINS(err.message, "ragged.csv:5: ragged row: found 3 fields, expected 2");

    rc = read_text("short.csv", "a,b,c\n1,2,3\n4\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "short.csv:3: ragged row: found 1 field, expected 3");

    /* A trailing delimiter is one more (empty) field. */
    rc = read_text("trailing.csv", "a,b\n1,2,\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "trailing.csv:2: ragged row: found 3 fields, expected 2");

    rc = read_text("dup.csv", "# header next\nt,mass,t\n1,2,3\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(t == NULL);
    CHECK_STR_CONTAINS(err.message, "dup.csv:2: header: duplicate column name 't' (columns 1 and 3)");

    rc = read_text("emptyname.csv", "t,,m\n1,2,3\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "emptyname.csv:1: header: column 2 has an empty name");

    rc = read_text("empty.csv", "", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(t == NULL);
    CHECK_STR_CONTAINS(err.message, "empty.csv:1: no header line");

    rc = read_text("comments.csv", "# only\n\n   \n# comments\n", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "comments.csv:5: no header line");

    rc = read_text("bomonly.csv", "\xEF\xBB\xBF", &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "no header line");

    /* Missing file and a directory: I/O errors naming the path. */
    {
        char path[300];
        snprintf(path, sizeof path, "%s/missing.csv", tmp_dir);
        rc = phc_table_read(path, &t, &err);
        CHECK(rc == PHC_ERR_IO);
        CHECK(t == NULL);
        CHECK_STR_CONTAINS(err.message, "missing.csv: cannot open: No such file or directory");
        rc = phc_table_read(tmp_dir, &t, &err);
        CHECK(rc == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "cannot read");
    }
    CHECK(phc_table_read(NULL, &t, &err) == PHC_ERR_INVALID);
    CHECK(phc_table_parse("a", 1, "x", NULL, &err) == PHC_ERR_INVALID);
    /* A NULL error pointer is allowed: the status still comes back. */
    CHECK(phc_table_parse("a,b\n1\n", 6, "x", &t, NULL) == PHC_ERR_INPUT);
}

static void test_zero_rows(void)
{
    phc_table *t = NULL;
    phc_error err;
    double *v = (double *)&err;
    int rc = read_text("header_only.csv", "t,mass_g\n# no data yet\n\n", &t, &err);
    CHECK(rc == 0);
    if (rc)
        return;
    CHECK(phc_table_rows(t) == 0);
    CHECK(phc_table_columns(t) == 2);
    CHECK(phc_table_cell(t, 0, 0) == NULL);
    CHECK(phc_table_column_numbers(t, "mass_g", &v, &err) == 0);
    CHECK(v == NULL);
    phc_table_free(t);

    /* From memory, without a final newline. */
    t = NULL;
    rc = phc_table_parse("a b c", 5, "inline", &t, &err);
    CHECK(rc == 0);
    if (!rc) {
        CHECK(phc_table_columns(t) == 3);
        CHECK(phc_table_rows(t) == 0);
        CHECK(!strcmp(phc_table_source(t), "inline"));
    }
    phc_table_free(t);
}

static void test_junk(void)
{
    phc_table *t = NULL;
    phc_error err;
    int rc;
    size_t i, n = 1 << 16;
    char *junk = malloc(n);
    const char *path;

    /* NUL bytes: refused with a message, not silently cut. */
    static const char with_nul[] = "a,b\n1,\0\n";
    path = write_file("nul.csv", with_nul, sizeof with_nul - 1);
    rc = phc_table_read(path, &t, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(t == NULL);
    CHECK_STR_CONTAINS(err.message, "nul.csv:2: unexpected NUL byte");

    /* Random bytes: any outcome but a crash or a leak. */
    CHECK(junk != NULL);
    if (!junk)
        return;
    {
        unsigned x = 12345;
        int round;
        for (round = 0; round < 50; ++round) {
            for (i = 0; i < n; ++i) {
                x = x * 1103515245u + 12345u;
                junk[i] = (char)(x >> 16);
                if (round % 2 && junk[i] == '\0')
                    junk[i] = ',';
            }
            t = NULL;
            rc = phc_table_parse(junk, n, "junk", &t, &err);
            CHECK(rc == 0 || rc == PHC_ERR_INPUT);
            CHECK((rc == 0) == (t != NULL));
            if (rc == 0) {
                double *v = NULL;
                phc_table_column_numbers(t, phc_table_column_name(t, 0), &v, &err);
                free(v);
            }
            phc_table_free(t);
        }
    }

    /* One very long line: a 1 MB header name and cell. */
    {
        size_t big = 1 << 20;
        char *text = malloc(2 * big + 8);
        CHECK(text != NULL);
        if (text) {
            memset(text, 'h', big);
            text[big] = '\n';
            memset(text + big + 1, '7', big);
            text[2 * big + 1] = '\n';
            t = NULL;
            rc = phc_table_parse(text, 2 * big + 2, "long", &t, &err);
            CHECK(rc == 0);
            if (!rc) {
                CHECK(strlen(phc_table_cell(t, 0, 0)) == big);
                CHECK(strlen(phc_table_column_name(t, 0)) == big);
            }
            phc_table_free(t);
            free(text);
        }
    }
    free(junk);
}

/* Numbers are C syntax even when the program chose a decimal-comma locale
 * (checked only where such a locale is installed). */
static void test_locale(void)
{
    static const char *const names[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", NULL};
    size_t i;
    phc_table *t = NULL;
    phc_error err;
    double *v = NULL;
    for (i = 0; names[i]; ++i)
        if (setlocale(LC_NUMERIC, names[i]))
            break;
    if (!names[i])
        return;
    CHECK(phc_table_parse("x\n1.5\n", 6, "locale", &t, &err) == 0);
    CHECK(phc_table_column_numbers(t, "x", &v, &err) == 0);
    if (v)
        CHECK_NEAR(v[0], 1.5, 0, 0);
    free(v);
    phc_table_free(t);
    setlocale(LC_NUMERIC, "C");
}

/* phc_table_select_rows (the groups of `fit --each`): the chosen rows in the
 * given order, the header and source kept, each row's file line kept (so a
 * bad cell of the subset is reported at its line of the file), 0 rows
 * allowed, an out-of-range row refused. */
static void test_select_rows(void)
{
    phc_error err;
    phc_table *t = NULL, *s = NULL;
    const char *text = "# groups\nleaf,x\nA,1\nB,2\nA,oops\nB,4\n";
    CHECK(phc_table_parse(text, strlen(text), "g.csv", &t, &err) == PHC_OK);
    const size_t rows[] = {3, 1};
    CHECK(phc_table_select_rows(t, rows, 2, &s, &err) == PHC_OK);
    if (s) {
        CHECK(phc_table_rows(s) == 2 && phc_table_columns(s) == 2);
        CHECK(strcmp(phc_table_source(s), "g.csv") == 0);
        CHECK(strcmp(phc_table_column_name(s, 0), "leaf") == 0 && strcmp(phc_table_column_name(s, 1), "x") == 0);
        CHECK(strcmp(phc_table_cell(s, 0, 0), "B") == 0 && strcmp(phc_table_cell(s, 0, 1), "4") == 0);
        CHECK(strcmp(phc_table_cell(s, 1, 0), "B") == 0 && strcmp(phc_table_cell(s, 1, 1), "2") == 0);
        CHECK(phc_table_row_line(s, 0) == 6 && phc_table_row_line(s, 1) == 4);
        double *v = NULL;
        CHECK(phc_table_column_numbers(s, "x", &v, &err) == PHC_OK && v && v[0] == 4.0 && v[1] == 2.0);
        free(v);
    }
    phc_table_free(s);
    s = NULL;
    const size_t group_a[] = {0, 2};
    CHECK(phc_table_select_rows(t, group_a, 2, &s, &err) == PHC_OK);
    double *v = NULL;
    CHECK(s && phc_table_column_numbers(s, "x", &v, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "g.csv:5: column 'x'");
    free(v);
    phc_table_free(s);
    s = NULL;
    CHECK(phc_table_select_rows(t, NULL, 0, &s, &err) == PHC_OK && s && phc_table_rows(s) == 0);
    phc_table_free(s);
    s = NULL;
    const size_t past[] = {4};
    CHECK(phc_table_select_rows(t, past, 1, &s, &err) == PHC_ERR_INVALID && s == NULL);
    phc_table_free(t);
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_normal();
    test_delimiters();
    test_quotes();
    test_line_ends_and_bom();
    test_bad_numbers();
    test_unknown_column();
    test_structure_errors();
    test_zero_rows();
    test_junk();
    test_locale();
    test_select_rows();
    remove_files();
    return check_finish("test_table");
}
