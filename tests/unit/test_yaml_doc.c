/* Unit tests for measurements/yaml_doc.c: the YAML tree, its positions and
 * its messages. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "measurements/yaml_doc.h"

/* Every test file lives in one mkdtemp() directory, removed at the end. */
static char tmp_dir[] = "/tmp/phc_test_yaml_XXXXXX";
static char tmp_files[16][256];
static int n_tmp_files = 0;

static const char *write_file(const char *name, const char *text)
{
    char *path;
    FILE *f;
    if (n_tmp_files >= 16)
        return NULL;
    path = tmp_files[n_tmp_files++];
    snprintf(path, sizeof tmp_files[0], "%s/%s", tmp_dir, name);
    f = fopen(path, "wb");
    if (!f)
        return NULL;
    fputs(text, f);
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

static phc_yaml_doc *parse(const char *text, phc_error *err)
{
    phc_yaml_doc *doc = NULL;
    int rc = phc_yaml_parse(text, strlen(text), "cfg.yaml", &doc, err);
    if (rc)
        fprintf(stderr, "unexpected parse failure: %s\n", err->message);
    CHECK(rc == 0);
    return doc;
}

/* Parses text that must fail; returns the status. */
static int parse_fails(const char *text, phc_error *err)
{
    phc_yaml_doc *doc = (phc_yaml_doc *)err; /* must come back NULL */
    int rc = phc_yaml_parse(text, strlen(text), "cfg.yaml", &doc, err);
    CHECK(doc == NULL);
    phc_yaml_free(doc == (phc_yaml_doc *)err ? NULL : doc);
    return rc;
}

static int scalar_is(const phc_yaml_node *n, const char *want)
{
    return n && n->kind == PHC_YAML_SCALAR && !strcmp(n->scalar, want);
}

static void test_tree(void)
{
    phc_error err;
    const char *path = write_file("tree.yaml",
                                  "# a configuration\n"
                                  "name: misra1a\n"
                                  "parameters:\n"
                                  "  b1: {value: 500}\n"
                                  "  b2: {value: 1.0e-4, lower: 0}\n"
                                  "datasets:\n"
                                  "  - kind: curve\n"
                                  "    file: 'misra1a.csv'   # comment\n"
                                  "    columns: [x, \"y\"]\n"
                                  "  - kind: weight_curve\n"
                                  "    time: {column: t, unit: h}\n"
                                  "    note: |\n"
                                  "      two\n"
                                  "      lines\n");
    phc_yaml_doc *doc = NULL;
    const phc_yaml_node *root, *params, *b2, *sets, *first, *cols, *second;
    int rc = phc_yaml_load(path, &doc, &err);
    CHECK(rc == 0);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(!strcmp(doc->path, path));
    root = doc->root;
    CHECK(root && root->kind == PHC_YAML_MAPPING);
    if (!root)
        goto done;
    CHECK(root->count == 3);
    CHECK(root->line == 2 && root->column == 1);
    CHECK(!strcmp(root->keys[0], "name") && root->key_lines[0] == 2);
    CHECK(!strcmp(root->keys[2], "datasets") && root->key_lines[2] == 6);
    CHECK(scalar_is(phc_yaml_get(root, "name"), "misra1a"));
    CHECK(phc_yaml_get(root, "nope") == NULL);
    CHECK(phc_yaml_get(NULL, "name") == NULL);
    CHECK(phc_yaml_get(root, NULL) == NULL);

    params = phc_yaml_get(root, "parameters");
    CHECK(params && params->kind == PHC_YAML_MAPPING && params->count == 2);
    CHECK(params && params->line == 4 && params->column == 3);
    b2 = phc_yaml_get(params, "b2");
    CHECK(b2 && b2->kind == PHC_YAML_MAPPING && b2->count == 2);
    /* Flow mapping: it starts at its '{' (line 5, column 7). */
    CHECK(b2 && b2->line == 5 && b2->column == 7);
    CHECK(phc_yaml_get(b2, "lower") && phc_yaml_get(b2, "lower")->line == 5 &&
          phc_yaml_get(b2, "lower")->column == 30);
    /* phc_yaml_get on a scalar is NULL, not a crash. */
    CHECK(phc_yaml_get(phc_yaml_get(root, "name"), "x") == NULL);

    sets = phc_yaml_get(root, "datasets");
    CHECK(sets && sets->kind == PHC_YAML_SEQUENCE && sets->count == 2);
    if (!sets || sets->count != 2)
        goto done;
    CHECK(sets->line == 7 && sets->column == 3);
    first = sets->items[0];
    CHECK(first->kind == PHC_YAML_MAPPING && first->line == 7 && first->column == 5);
    CHECK(scalar_is(phc_yaml_get(first, "file"), "misra1a.csv"));
    CHECK(phc_yaml_get(first, "file")->quoted == 1);
    CHECK(phc_yaml_get(first, "kind")->quoted == 0);
    cols = phc_yaml_get(first, "columns");
    CHECK(cols && cols->kind == PHC_YAML_SEQUENCE && cols->count == 2);
    if (cols && cols->count == 2) {
        CHECK(scalar_is(cols->items[0], "x") && !cols->items[0]->quoted);
        CHECK(scalar_is(cols->items[1], "y") && cols->items[1]->quoted);
        CHECK(cols->items[1]->line == 9 && cols->items[1]->column == 18);
    }
    second = sets->items[1];
    CHECK(scalar_is(phc_yaml_get(phc_yaml_get(second, "time"), "unit"), "h"));
    CHECK(scalar_is(phc_yaml_get(second, "note"), "two\nlines\n"));
    CHECK(second->key_lines[2] == 12);
done:
    phc_yaml_free(doc);
    phc_yaml_free(NULL);
}

static void test_documents(void)
{
    phc_error err;
    phc_yaml_doc *doc;
    int rc;

    /* Empty input, comments only and an explicit empty document: NULL root. */
    doc = parse("", &err);
    CHECK(doc && doc->root == NULL);
    phc_yaml_free(doc);
    doc = parse("# nothing here\n\n", &err);
    CHECK(doc && doc->root == NULL);
    phc_yaml_free(doc);
    doc = parse("---\n...\n", &err);
    CHECK(doc && doc->root == NULL);
    phc_yaml_free(doc);

    /* A bare scalar is a document too; accessors on it must not crash. */
    doc = parse("just words\n", &err);
    CHECK(doc && scalar_is(doc->root, "just words"));
    if (doc) {
        double x = 7;
        CHECK(phc_yaml_get(doc->root, "name") == NULL);
        rc = phc_yaml_map_number(doc, doc->root, "value", 0, "the configuration", &x, &err);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cfg.yaml:1:1: the configuration: expected a mapping (key: value), found a scalar");
        rc = phc_yaml_check_keys(doc, doc->root, (const char *const[]){"a", NULL}, "the configuration", &err);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK(x == 7);
    }
    phc_yaml_free(doc);

    /* Only the first document is read; a broken second one does not matter. */
    doc = parse("a: 1\n---\nb: [\n", &err);
    CHECK(doc && doc->root && doc->root->count == 1);
    phc_yaml_free(doc);

    /* Anchors and aliases: the alias is a full copy. */
    doc = parse("base: &base {lower: 0, upper: 10}\n"
                "b1: *base\n"
                "&k key: v\n"
                "other: *k\n",
                &err);
    if (doc && doc->root) {
        const phc_yaml_node *b1 = phc_yaml_get(doc->root, "b1");
        CHECK(b1 && b1->kind == PHC_YAML_MAPPING && b1->count == 2);
        CHECK(b1 != phc_yaml_get(doc->root, "base"));
        CHECK(scalar_is(phc_yaml_get(b1, "upper"), "10"));
        CHECK(scalar_is(phc_yaml_get(doc->root, "other"), "key"));
    }
    phc_yaml_free(doc);

    /* Tags are ignored. */
    doc = parse("a: !!str 12\n", &err);
    CHECK(doc && scalar_is(phc_yaml_get(doc->root, "a"), "12"));
    phc_yaml_free(doc);

    /* NULL error pointer and bad arguments. */
    CHECK(phc_yaml_parse("a: [", 4, "x", &doc, NULL) == PHC_ERR_INPUT);
    CHECK(phc_yaml_parse("a", 1, "x", NULL, &err) == PHC_ERR_INVALID);
    CHECK(phc_yaml_load(NULL, &doc, &err) == PHC_ERR_INVALID);
}

static void test_errors(void)
{
    phc_error err;
    phc_yaml_doc *doc = NULL;
    char path[300];
    int rc;

    rc = parse_fails("parameters:\n  b1: [1, 2\n  b2: 3\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(err.status == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:3:5: YAML syntax error: did not find expected ',' or ']'");
    CHECK_STR_CONTAINS(err.message, "line 2, column 7");

    rc = parse_fails("a: 1\n b: 2\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:2:3: YAML syntax error: mapping values are not allowed");

    rc = parse_fails("a: \"open\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "YAML syntax error: found unexpected end of stream");

    /* Invalid UTF-8: libyaml reports an offset, we report line and column. */
    rc = parse_fails("a: 1\nb: \xff\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:2:4: YAML syntax error: invalid leading UTF-8 octet");

    rc = parse_fails("parameters:\n  b1:\n    value: 1\n    value: 2\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:4:5: duplicate key 'value' (first on line 3)");

    rc = parse_fails("{a: 1, b: 2, a: 3}\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:1:14: duplicate key 'a' (first on line 1)");

    rc = parse_fails("? [a, b]\n: 1\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:1:3: a mapping key must be a scalar, found a sequence");

    rc = parse_fails("a: *nowhere\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:1:4: alias '*nowhere'");

    /* A node containing an alias to itself cannot be copied. */
    rc = parse_fails("a: &x [1, *x]\n", &err);
    CHECK(rc == PHC_ERR_INPUT);

    rc = parse_fails("a: \"x\\0y\"\n", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "NUL");

    snprintf(path, sizeof path, "%s/absent.yaml", tmp_dir);
    rc = phc_yaml_load(path, &doc, &err);
    CHECK(rc == PHC_ERR_IO);
    CHECK(doc == NULL);
    CHECK_STR_CONTAINS(err.message, "absent.yaml: cannot open: No such file or directory");
    rc = phc_yaml_load(tmp_dir, &doc, &err);
    CHECK(rc == PHC_ERR_IO);
    CHECK(doc == NULL);
}

static void test_check_keys(void)
{
    static const char *const allowed[] = {"value", "lower", "upper", "unit", NULL};
    phc_error err;
    phc_yaml_doc *doc = parse("parameters:\n"
                              "  b1:\n"
                              "    value: 500\n"
                              "    lowr: 0\n"
                              "  b2:\n"
                              "    value: 1\n"
                              "    colour: red\n"
                              "  b3: {value: 1, upper: 2}\n",
                              &err);
    const phc_yaml_node *params;
    int rc;
    if (!doc)
        return;
    params = phc_yaml_get(doc->root, "parameters");
    rc = phc_yaml_check_keys(doc, phc_yaml_get(params, "b1"), allowed, "parameter 'b1'", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:4: unknown key 'lowr' in parameter 'b1'; did you mean 'lower'?");
    rc = phc_yaml_check_keys(doc, phc_yaml_get(params, "b2"), allowed, "parameter 'b2'", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:7: unknown key 'colour' in parameter 'b2'; allowed keys: value, lower, upper, unit");
    CHECK(strstr(err.message, "did you mean") == NULL);
    rc = phc_yaml_check_keys(doc, phc_yaml_get(params, "b3"), allowed, "parameter 'b3'", &err);
    CHECK(rc == 0);
    /* Absent map: nothing to check. */
    CHECK(phc_yaml_check_keys(doc, NULL, allowed, "x", &err) == 0);
    /* A scalar where a mapping belongs. */
    rc = phc_yaml_check_keys(doc, phc_yaml_get(phc_yaml_get(params, "b1"), "value"), allowed,
                             "parameter 'b1'", &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:3:12: parameter 'b1': expected a mapping");
    phc_yaml_free(doc);
}

static void test_accessors(void)
{
    phc_error err;
    phc_yaml_doc *doc = parse("value: 1.0e-4\n"           /* 1 */
                              "int: 500\n"                /* 2 */
                              "neg: -3.5\n"               /* 3 */
                              "quoted: \"2.5\"\n"         /* 4 */
                              "inf: .inf\n"               /* 5 */
                              "minf: -.Inf\n"             /* 6 */
                              "nan: .nan\n"               /* 7 */
                              "cinf: inf\n"               /* 8 */
                              "text: abc\n"               /* 9 */
                              "empty:\n"                  /* 10 */
                              "map: {a: 1}\n"             /* 11 */
                              "list: [1, 2]\n"            /* 12 */
                              "big: 99999999999999999999\n" /* 13 */
                              "thousand: 1e3\n"           /* 14 */
                              "half: 5.5\n"               /* 15 */
                              "yes: yes\n"                /* 16 */
                              "off: Off\n"                /* 17 */
                              "t: true\n"                 /* 18 */
                              "maybe: maybe\n"            /* 19 */
                              "name: \"tomato dry-down\"\n" /* 20 */
                              "huge: 1e999\n"             /* 21 */
                              "tilde: ~\n",               /* 22 */
                              &err);
    const phc_yaml_node *r;
    double x;
    long n;
    int b;
    const char *s;
    int rc;
    if (!doc)
        return;
    r = doc->root;

    /* Numbers. */
    x = 0;
    CHECK(phc_yaml_map_number(doc, r, "value", 1, "test", &x, &err) == 0);
    CHECK_NEAR(x, 1.0e-4, 0, 0);
    CHECK(phc_yaml_map_number(doc, r, "int", 1, "test", &x, &err) == 0);
    CHECK_NEAR(x, 500, 0, 0);
    CHECK(phc_yaml_map_number(doc, r, "neg", 1, "test", &x, &err) == 0);
    CHECK_NEAR(x, -3.5, 0, 0);
    CHECK(phc_yaml_map_number(doc, r, "quoted", 1, "test", &x, &err) == 0);
    CHECK_NEAR(x, 2.5, 0, 0);
    x = 42;
    rc = phc_yaml_map_number(doc, r, "inf", 1, "test", &x, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(x == 42);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:5:6: key 'inf': expected a finite number, found '.inf'");
    CHECK(phc_yaml_map_number(doc, r, "minf", 1, "test", &x, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "found '-.Inf'");
    CHECK(phc_yaml_map_number(doc, r, "nan", 1, "test", &x, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "expected a finite number, found '.nan'");
    CHECK(phc_yaml_map_number(doc, r, "cinf", 1, "test", &x, &err) == PHC_ERR_INPUT);
    CHECK(phc_yaml_map_number(doc, r, "huge", 1, "test", &x, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "expected a finite number, found '1e999'");
    rc = phc_yaml_map_number(doc, r, "text", 1, "test", &x, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:9:7: key 'text': expected a number, found 'abc'");
    CHECK(phc_yaml_map_number(doc, r, "empty", 1, "test", &x, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "key 'empty': expected a number, found an empty (null) value");
    CHECK(phc_yaml_map_number(doc, r, "tilde", 1, "test", &x, &err) == PHC_ERR_INPUT);
    CHECK(phc_yaml_map_number(doc, r, "map", 1, "test", &x, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:11:6: key 'map': expected a number, found a mapping");
    CHECK(phc_yaml_number(doc, phc_yaml_get(r, "list"), "list", &x, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "found a sequence");
    CHECK(x == 42);
    /* A sequence item has no key. */
    CHECK(phc_yaml_number(doc, phc_yaml_get(r, "list")->items[1], NULL, &x, &err) == 0);
    CHECK_NEAR(x, 2, 0, 0);
    CHECK(phc_yaml_number(doc, phc_yaml_get(r, "map"), NULL, &x, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:11:6: expected a number, found a mapping");

    /* Absent keys: optional keeps the default, required is an error. */
    x = 3.25;
    CHECK(phc_yaml_map_number(doc, r, "absent", 0, "parameter 'b1'", &x, &err) == 0);
    CHECK(x == 3.25);
    CHECK(phc_yaml_number(doc, NULL, "absent", &x, &err) == 0);
    CHECK(x == 3.25);
    rc = phc_yaml_map_number(doc, r, "absent", 1, "parameter 'b1'", &x, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:1: parameter 'b1': missing key 'absent'");
    rc = phc_yaml_map_string(doc, NULL, "file", 1, "data set 1", &s, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml: data set 1: missing key 'file'");
    CHECK(phc_yaml_map_string(doc, NULL, "file", 0, "data set 1", &s, &err) == 0);

    /* Integers. */
    n = 0;
    CHECK(phc_yaml_map_integer(doc, r, "int", 1, "test", &n, &err) == 0);
    CHECK(n == 500);
    CHECK(phc_yaml_map_integer(doc, r, "thousand", 1, "test", &n, &err) == 0);
    CHECK(n == 1000);
    n = 9;
    CHECK(phc_yaml_map_integer(doc, r, "half", 1, "test", &n, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:15:7: key 'half': expected an integer, found '5.5'");
    CHECK(phc_yaml_map_integer(doc, r, "big", 1, "test", &n, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "key 'big': expected an integer in the range of a long, found '99999999999999999999'");
    CHECK(phc_yaml_map_integer(doc, r, "text", 1, "test", &n, &err) == PHC_ERR_INPUT);
    CHECK(phc_yaml_map_integer(doc, r, "inf", 1, "test", &n, &err) == PHC_ERR_INPUT);
    CHECK(n == 9);

    /* Booleans. */
    b = -1;
    CHECK(phc_yaml_map_boolean(doc, r, "yes", 1, "test", &b, &err) == 0);
    CHECK(b == 1);
    CHECK(phc_yaml_map_boolean(doc, r, "off", 1, "test", &b, &err) == 0);
    CHECK(b == 0);
    CHECK(phc_yaml_map_boolean(doc, r, "t", 1, "test", &b, &err) == 0);
    CHECK(b == 1);
    CHECK(phc_yaml_map_boolean(doc, r, "maybe", 1, "test", &b, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:19:8: key 'maybe': expected a boolean (true or false), found 'maybe'");
    CHECK(phc_yaml_map_boolean(doc, r, "int", 1, "test", &b, &err) == PHC_ERR_INPUT);
    CHECK(b == 1);

    /* Strings: any scalar, pointing into the document. */
    s = NULL;
    CHECK(phc_yaml_map_string(doc, r, "name", 1, "test", &s, &err) == 0);
    CHECK(s && !strcmp(s, "tomato dry-down"));
    CHECK(phc_yaml_map_string(doc, r, "int", 1, "test", &s, &err) == 0);
    CHECK(s && !strcmp(s, "500"));
    CHECK(phc_yaml_map_string(doc, r, "list", 1, "test", &s, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:12:7: key 'list': expected a string, found a sequence");
    CHECK(phc_yaml_map_string(doc, r, "empty", 1, "test", &s, &err) == PHC_ERR_INPUT);
    CHECK(s && !strcmp(s, "500"));

    /* NULL error pointer: the status still comes back. */
    CHECK(phc_yaml_map_number(doc, r, "text", 1, "test", &x, NULL) == PHC_ERR_INPUT);
    phc_yaml_free(doc);
}

static void test_hostile(void)
{
    phc_error err;
    phc_yaml_doc *doc = NULL;
    size_t depth = 5000, i;
    char *deep = malloc(2 * depth + 2);
    char *junk = malloc(4096);
    int rc, round;

    /* Deep nesting: refused, no stack overflow. */
    CHECK(deep != NULL);
    if (deep) {
        for (i = 0; i < depth; ++i) {
            deep[i] = '[';
            deep[depth + i] = ']';
        }
        deep[2 * depth] = '\0';
        rc = parse_fails(deep, &err);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "nested levels");
        free(deep);
    }

    /* "Billion laughs": aliases expanding exponentially. */
    rc = parse_fails("a: &a [x, x, x, x, x, x, x, x, x, x]\n"
                     "b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
                     "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]\n"
                     "d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
                     "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d, *d]\n"
                     "f: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e, *e]\n"
                     "g: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f, *f]\n",
                     &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "YAML nodes");

    /* Random bytes, and random YAML punctuation: any result but a crash. */
    CHECK(junk != NULL);
    if (!junk)
        return;
    {
        static const char alphabet[] = "ab1 :-[]{},&*!#'\"\n\t?|>";
        unsigned x = 2024;
        for (round = 0; round < 200; ++round) {
            size_t n = 64 + (size_t)round * 16;
            for (i = 0; i < n; ++i) {
                x = x * 1103515245u + 12345u;
                junk[i] = round % 2 ? alphabet[(x >> 16) % (sizeof alphabet - 1)]
                                    : (char)(x >> 16);
            }
            doc = NULL;
            rc = phc_yaml_parse(junk, n, "junk", &doc, &err);
            CHECK(rc == 0 || rc == PHC_ERR_INPUT);
            CHECK((rc == 0) == (doc != NULL));
            phc_yaml_free(doc);
        }
    }
    free(junk);
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_tree();
    test_documents();
    test_errors();
    test_check_keys();
    test_accessors();
    test_hostile();
    remove_files();
    return check_finish("test_yaml_doc");
}
