/* Messages of `curve` expressions that muparser cannot read (fit/costs/curve.c):
 *
 * 1. an unknown function names itself, its character in the expression and
 *    the config line of `expression:`, suggests a near function, and lists
 *    the known functions -- each of which muparser must accept (called with
 *    one argument, or two for atan2), so that the list cannot promise what
 *    the parser does not have;
 * 2. a parameter used as a function is called a parameter;
 * 3. a name that is neither parameter nor column gives its character;
 * 4. other syntax errors keep muparser's reason with the character. */
#include <muParserDLL.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"

static char dir[] = "/tmp/phc_curve_msg_XXXXXX";

/* Writes a config with `expression` (line 10) over a small table and loads
 * it; returns the error message (static) or "" when it loaded. */
static const char *load_message(const char *expression)
{
    static phc_error err;
    char path[256], csv[256];
    snprintf(csv, sizeof csv, "%s/data.csv", dir);
    snprintf(path, sizeof path, "%s/cfg.yaml", dir);
    FILE *f = fopen(csv, "w");
    CHECK(f != NULL);
    if (!f)
        return "";
    fputs("x,y\n1,2\n2,4\n3,6\n", f);
    fclose(f);
    if (!(f = fopen(path, "w")))
        return "";
    fprintf(f, "name: t\n"
               "parameters:\n"
               "  a: {value: 1}\n"
               "  b: {value: 0}\n"
               "datasets:\n"
               "  - kind: curve\n"
               "    file: data.csv\n"
               "    x: x\n"
               "    y: y\n"
               "    expression: \"%s\"\n",
            expression);
    fclose(f);
    phc_problem *pb = NULL;
    phc_error_clear(&err);
    const int rc = phc_config_load(path, &pb, &err);
    phc_problem_free(pb);
    printf("%-22s -> %s\n", expression, rc ? err.message : "(loads)");
    return rc ? err.message : "";
}

/* muparser evaluates name(1) (name(1, 1) for atan2) without an error. */
static int muparser_knows(const char *name)
{
    char expr[96];
    snprintf(expr, sizeof expr, strcmp(name, "atan2") == 0 ? "%s(1, 1)" : "%s(1)", name);
    muParserHandle_t p = mupCreate(muBASETYPE_FLOAT);
    if (!p)
        return 0;
    mupSetExpr(p, expr);
    (void)mupEval(p);
    const int ok = !mupError(p);
    mupRelease(p);
    return ok;
}

static void test_unknown_function(void)
{
    const char *m = load_message("a * expp(x) + b");
    CHECK_STR_CONTAINS(m, "cfg.yaml:10: expression \"a * expp(x) + b\": unknown function 'expp' at character 5");
    CHECK_STR_CONTAINS(m, "did you mean 'exp'?");
    const char *list = strstr(m, "known functions: ");
    CHECK(list != NULL);
    if (!list)
        return;
    char names[512];
    snprintf(names, sizeof names, "%s", list + strlen("known functions: "));
    size_t n = 0;
    for (char *save = NULL, *w = strtok_r(names, " ", &save); w; w = strtok_r(NULL, " ", &save), ++n)
        if (!muparser_knows(w)) {
            fprintf(stderr, "the message lists '%s', which muparser does not accept\n", w);
            CHECK(0);
        }
    CHECK(n >= 10);
    CHECK(!muparser_knows("expp")); /* the probe itself can fail */
    const char *const must[] = {"exp", "log", "sqrt", "sin", "cos", "tan", "atan", "abs"};
    for (size_t i = 0; i < sizeof must / sizeof must[0]; ++i) {
        char word[16];
        snprintf(word, sizeof word, " %s ", must[i]);
        char padded[520];
        snprintf(padded, sizeof padded, " %s ", list + strlen("known functions: "));
        CHECK_STR_CONTAINS(padded, word);
    }
    /* a name muparser has no close function for: no suggestion */
    m = load_message("a * frobnicate(x)");
    CHECK_STR_CONTAINS(m, "unknown function 'frobnicate' at character 5;");
    CHECK(strstr(m, "did you mean") == NULL);
}

static void test_other_errors(void)
{
    const char *m = load_message("a(x) + b");
    CHECK_STR_CONTAINS(m, "cfg.yaml:10: expression \"a(x) + b\": 'a' at character 1 is a parameter, not a function");
    m = load_message("a*x + b + zeta");
    CHECK_STR_CONTAINS(m, "cfg.yaml:10: expression (character 11): name 'zeta' is not a column of");
    m = load_message("a*x + * b");
    CHECK_STR_CONTAINS(m, "cfg.yaml:10: expression \"a*x + * b\": ");
    CHECK_STR_CONTAINS(m, "(character 7)");
    m = load_message("a*(x + b");
    CHECK_STR_CONTAINS(m, "cfg.yaml:10: expression \"a*(x + b\": ");
    CHECK_STR_CONTAINS(m, "(character ");
    CHECK(load_message("a * exp(x) + b")[0] == '\0');
}

int main(void)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_unknown_function();
    test_other_errors();
    char path[256];
    snprintf(path, sizeof path, "%s/cfg.yaml", dir);
    remove(path);
    snprintf(path, sizeof path, "%s/data.csv", dir);
    remove(path);
    rmdir(dir);
    return check_finish("test_curve_messages");
}
