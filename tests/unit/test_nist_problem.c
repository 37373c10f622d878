/* tests/nist_problem.h: reading the 22 NIST StRD nonlinear regression files,
 * the model expressions, the CSV + YAML case files and the LRE score.
 *
 * The models are checked twice against NIST's certified residual sum of
 * squares: once re-coded in plain C here, and once by evaluating the
 * expression strings of nist_expression() with a small evaluator of the
 * expression syntax (+ - * / ^, parentheses, exp log sqrt sin cos tan atan
 * abs, pi).  The evaluator refuses a unary minus followed directly by ^
 * ("-a^b"), which parsers read differently, so the expressions stay
 * unambiguous.  Skips (77) when ../shared/data/nist is absent. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "nist_problem.h"

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif

static const double PI = 3.141592653589793238462643383279;

/* ---- the 22 models in C ----------------------------------------------------- */

static double model_c(const char *name, const double *b, double x, double x2)
{
    if (!strcmp(name, "BoxBOD") || !strcmp(name, "Misra1a"))
        return b[0] * (1 - exp(-b[1] * x));
    if (!strcmp(name, "Chwirut1") || !strcmp(name, "Chwirut2"))
        return exp(-b[0] * x) / (b[1] + b[2] * x);
    if (!strcmp(name, "DanWood"))
        return b[0] * pow(x, b[1]);
    if (!strcmp(name, "ENSO")) {
        double w = 2 * PI * x;
        return b[0] + b[1] * cos(w / 12) + b[2] * sin(w / 12) + b[4] * cos(w / b[3]) +
               b[5] * sin(w / b[3]) + b[7] * cos(w / b[6]) + b[8] * sin(w / b[6]);
    }
    if (!strncmp(name, "Gauss", 5))
        return b[0] * exp(-b[1] * x) +
               b[2] * exp(-(x - b[3]) * (x - b[3]) / (b[4] * b[4])) +
               b[5] * exp(-(x - b[6]) * (x - b[6]) / (b[7] * b[7]));
    if (!strcmp(name, "Hahn1"))
        return (b[0] + b[1] * x + b[2] * x * x + b[3] * x * x * x) /
               (1 + b[4] * x + b[5] * x * x + b[6] * x * x * x);
    if (!strcmp(name, "Kirby2"))
        return (b[0] + b[1] * x + b[2] * x * x) / (1 + b[3] * x + b[4] * x * x);
    if (!strncmp(name, "Lanczos", 7))
        return b[0] * exp(-b[1] * x) + b[2] * exp(-b[3] * x) + b[4] * exp(-b[5] * x);
    if (!strcmp(name, "MGH09"))
        return b[0] * (x * x + x * b[1]) / (x * x + x * b[2] + b[3]);
    if (!strcmp(name, "MGH17"))
        return b[0] + b[1] * exp(-x * b[3]) + b[2] * exp(-x * b[4]);
    if (!strcmp(name, "Misra1b"))
        return b[0] * (1 - pow(1 + b[1] * x / 2, -2));
    if (!strcmp(name, "Misra1c"))
        return b[0] * (1 - pow(1 + 2 * b[1] * x, -0.5));
    if (!strcmp(name, "Misra1d"))
        return b[0] * b[1] * x / (1 + b[1] * x);
    if (!strcmp(name, "Nelson"))
        return b[0] - b[1] * x * exp(-b[2] * x2);
    if (!strcmp(name, "Rat42"))
        return b[0] / (1 + exp(b[1] - b[2] * x));
    if (!strcmp(name, "Roszman1"))
        return b[0] - b[1] * x - atan(b[2] / (x - b[3])) / PI;
    return NAN;
}

/* ---- a small evaluator of the expression syntax ---------------------------- */

typedef struct {
    const char *s;
    const double *b;
    int k;
    double x, x1, x2;
    int nx;
    const char *error;
} ev;

static double ev_expr(ev *e);

static void ev_space(ev *e)
{
    while (isspace((unsigned char)*e->s))
        ++e->s;
}

static double ev_primary(ev *e)
{
    ev_space(e);
    if (e->error)
        return NAN;
    if (*e->s == '(') {
        ++e->s;
        double v = ev_expr(e);
        ev_space(e);
        if (*e->s != ')') {
            e->error = "expected ')'";
            return NAN;
        }
        ++e->s;
        return v;
    }
    if (isdigit((unsigned char)*e->s) || *e->s == '.') {
        char *end;
        double v = strtod(e->s, &end);
        e->s = end;
        return v;
    }
    if (isalpha((unsigned char)*e->s) || *e->s == '_') {
        char id[32];
        size_t n = 0;
        while ((isalnum((unsigned char)*e->s) || *e->s == '_') && n < sizeof id - 1)
            id[n++] = *e->s++;
        id[n] = '\0';
        ev_space(e);
        if (*e->s == '(') {
            static const char *const fn[] = {"exp", "log", "sqrt", "sin", "cos",
                                             "tan", "atan", "abs"};
            int which = -1;
            for (int i = 0; i < 8; ++i)
                if (!strcmp(id, fn[i]))
                    which = i;
            if (which < 0) {
                e->error = "unknown function";
                return NAN;
            }
            double a = ev_primary(e);
            switch (which) {
            case 0: return exp(a);
            case 1: return log(a);
            case 2: return sqrt(a);
            case 3: return sin(a);
            case 4: return cos(a);
            case 5: return tan(a);
            case 6: return atan(a);
            default: return fabs(a);
            }
        }
        if (!strcmp(id, "pi"))
            return PI;
        if (e->nx == 1 && !strcmp(id, "x"))
            return e->x;
        if (e->nx == 2 && !strcmp(id, "x1"))
            return e->x1;
        if (e->nx == 2 && !strcmp(id, "x2"))
            return e->x2;
        if (id[0] == 'b' && id[1] >= '1' && id[1] <= '9' && id[2] == '\0' &&
            id[1] - '0' <= e->k)
            return e->b[id[1] - '1'];
        e->error = "unknown name";
        return NAN;
    }
    e->error = "unexpected character";
    return NAN;
}

static double ev_unary(ev *e);

/* power := primary ('^' unary)?  (right-associative) */
static double ev_power(ev *e, int *used_power)
{
    double v = ev_primary(e);
    ev_space(e);
    if (*e->s == '^') {
        ++e->s;
        *used_power = 1;
        return pow(v, ev_unary(e));
    }
    return v;
}

static double ev_unary(ev *e)
{
    ev_space(e);
    if (*e->s == '-' || *e->s == '+') {
        int neg = *e->s == '-';
        ++e->s;
        int used_power = 0;
        ev_space(e);
        double v = (*e->s == '-' || *e->s == '+') ? ev_unary(e) : ev_power(e, &used_power);
        if (used_power && !e->error)
            e->error = "unary minus before ^ is ambiguous: write -(a^b)";
        return neg ? -v : v;
    }
    int used_power = 0;
    return ev_power(e, &used_power);
}

static double ev_term(ev *e)
{
    double v = ev_unary(e);
    for (;;) {
        ev_space(e);
        if (*e->s == '*') {
            ++e->s;
            v *= ev_unary(e);
        } else if (*e->s == '/') {
            ++e->s;
            v /= ev_unary(e);
        } else {
            return v;
        }
    }
}

static double ev_expr(ev *e)
{
    double v = ev_term(e);
    for (;;) {
        ev_space(e);
        if (*e->s == '+') {
            ++e->s;
            v += ev_term(e);
        } else if (*e->s == '-') {
            ++e->s;
            v -= ev_term(e);
        } else {
            return v;
        }
    }
}

static double eval_expression(const char *text, const nist_problem *p, const double *b,
                              int i, const char **error)
{
    ev e = {text, b, p->k, p->x[i], p->x[i], p->x2[i], p->nx, NULL};
    double v = ev_expr(&e);
    ev_space(&e);
    if (!e.error && *e.s)
        e.error = "text after the expression";
    *error = e.error;
    return v;
}

/* ---- expected shapes -------------------------------------------------------- */

static const struct {
    const char *name;
    int n, k;
} expected[] = {
    {"BoxBOD", 6, 2},    {"Chwirut1", 214, 3}, {"Chwirut2", 54, 3}, {"DanWood", 6, 2},
    {"ENSO", 168, 9},    {"Gauss1", 250, 8},   {"Gauss2", 250, 8},  {"Gauss3", 250, 8},
    {"Hahn1", 236, 7},   {"Kirby2", 151, 5},   {"Lanczos1", 24, 6}, {"Lanczos2", 24, 6},
    {"Lanczos3", 24, 6}, {"MGH09", 11, 4},     {"MGH17", 33, 5},    {"Misra1a", 14, 2},
    {"Misra1b", 14, 2},  {"Misra1c", 14, 2},   {"Misra1d", 14, 2},  {"Nelson", 128, 3},
    {"Rat42", 9, 3},     {"Roszman1", 25, 4},
};
#define N_EXPECTED ((int)(sizeof expected / sizeof expected[0]))

static nist_problem problems[N_EXPECTED];

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    static char buf[65536];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return buf;
}

static void test_write_case(const char *dir)
{
    char cfg[4096], msg[512];
    const nist_problem *misra = &problems[15], *nelson = &problems[19];
    CHECK(!strcmp(misra->name, "Misra1a") && !strcmp(nelson->name, "Nelson"));

    CHECK(nist_write_case(misra, 1, dir, cfg, sizeof cfg, msg, sizeof msg) == 0);
    char want_path[4200];
    snprintf(want_path, sizeof want_path, "%s/misra1a-start1.yaml", dir);
    CHECK(!strcmp(cfg, want_path));
    const char *yaml = slurp(cfg);
    CHECK(yaml != NULL);
    if (yaml)
        CHECK(!strcmp(yaml, "name: misra1a-start1\n"
                            "parameters:\n"
                            "  b1: {value: 500}\n"
                            "  b2: {value: 0.0001}\n"
                            "datasets:\n"
                            "  - kind: curve\n"
                            "    file: misra1a.csv\n"
                            "    x: x\n"
                            "    y: y\n"
                            "    expression: \"b1*(1-exp(-b2*x))\"\n"));
    CHECK(nist_write_case(misra, 2, dir, cfg, sizeof cfg, msg, sizeof msg) == 0);
    yaml = slurp(cfg);
    CHECK_STR_CONTAINS(yaml, "name: misra1a-start2\n");
    CHECK_STR_CONTAINS(yaml, "  b1: {value: 250}\n  b2: {value: 0.00050000000000000001}\n");

    /* the CSV reads back exactly */
    char csv[4200];
    snprintf(csv, sizeof csv, "%s/misra1a.csv", dir);
    FILE *f = fopen(csv, "r");
    CHECK(f != NULL);
    if (f) {
        char line[256];
        CHECK(fgets(line, sizeof line, f) && !strcmp(line, "x,y\n"));
        int rows = 0, exact = 1;
        double x, y;
        while (fscanf(f, "%lf,%lf", &x, &y) == 2) {
            if (rows >= misra->n || x != misra->x[rows] || y != misra->y[rows])
                exact = 0;
            ++rows;
        }
        fclose(f);
        CHECK(rows == misra->n);
        CHECK(exact);
    }

    /* Nelson: columns x1, x2 and y = log(y) */
    CHECK(nist_write_case(nelson, 1, dir, cfg, sizeof cfg, msg, sizeof msg) == 0);
    yaml = slurp(cfg);
    CHECK_STR_CONTAINS(yaml, "    x: x1\n");
    CHECK_STR_CONTAINS(yaml, "    expression: \"b1 - b2*x1*exp(-b3*x2)\"\n");
    snprintf(csv, sizeof csv, "%s/nelson.csv", dir);
    f = fopen(csv, "r");
    CHECK(f != NULL);
    if (f) {
        char line[256];
        CHECK(fgets(line, sizeof line, f) && !strcmp(line, "x1,x2,y\n"));
        double x1, x2, y;
        CHECK(fscanf(f, "%lf,%lf,%lf", &x1, &x2, &y) == 3);
        CHECK(x1 == 1 && x2 == 180 && y == log(15.0));
        fclose(f);
    }

    CHECK(nist_write_case(misra, 3, dir, cfg, sizeof cfg, msg, sizeof msg) != 0);
    CHECK_STR_CONTAINS(msg, "start must be 1 or 2");
    char small[8];
    CHECK(nist_write_case(misra, 1, dir, small, sizeof small, msg, sizeof msg) != 0);

    /* all 44 configs: start values read back exactly, expression as in the table */
    for (int t = 0; t < N_EXPECTED; ++t) {
        const nist_problem *p = &problems[t];
        for (int start = 1; start <= 2; ++start) {
            int rc = nist_write_case(p, start, dir, cfg, sizeof cfg, msg, sizeof msg);
            CHECK(rc == 0);
            if (rc) {
                fprintf(stderr, "%s\n", msg);
                continue;
            }
            yaml = slurp(cfg);
            CHECK(yaml != NULL);
            if (!yaml)
                continue;
            int exact = 1;
            for (int j = 0; j < p->k; ++j) {
                char key[32];
                snprintf(key, sizeof key, "\n  b%d: {value: ", j + 1);
                const char *at = strstr(yaml, key);
                if (!at || strtod(at + strlen(key), NULL) != p->starts[start - 1][j])
                    exact = 0;
            }
            CHECK(exact);
            char want[600];
            snprintf(want, sizeof want, "    expression: \"%s\"\n", nist_expression(p->name));
            CHECK_STR_CONTAINS(yaml, want);
            CHECK(unlink(cfg) == 0);
        }
        char path[4200];
        snprintf(path, sizeof path, "%s/%s.csv", dir, p->lower_name);
        CHECK(unlink(path) == 0);
    }
}

static void test_lre(void)
{
    CHECK_NEAR(nist_lre(1.0000001, 1.0), 7.0, 1e-6, 0);
    CHECK_NEAR(nist_lre(-2.0000002e-5, -2e-5), 7.0, 1e-6, 0);
    CHECK(nist_lre(3.5, 3.5) == 11.0);
    CHECK(nist_lre(1.0 + 1e-13, 1.0) == 11.0);
    CHECK(nist_lre(5.0, 1.0) == 0.0);
    CHECK(nist_lre(NAN, 1.0) == 0.0);
    CHECK_NEAR(nist_lre(1e-4, 0.0), 4.0, 1e-9, 0); /* absolute error */
}

static void test_bad_inputs(const char *dir)
{
    char path[4200], msg[512];
    static nist_problem p;
    CHECK(nist_load("/nonexistent/Misra1a.dat", &p, msg, sizeof msg) != 0);
    CHECK_STR_CONTAINS(msg, "cannot open");
    snprintf(path, sizeof path, "%s/Unknown.dat", dir);
    CHECK(nist_load(path, &p, msg, sizeof msg) != 0);
    CHECK_STR_CONTAINS(msg, "not one of the 22");

    /* a truncated Misra1a: observations missing */
    snprintf(path, sizeof path, "%s/Misra1a.dat", dir);
    FILE *in = fopen(PHC_SHARED_DATA "/nist/Misra1a.dat", "r");
    FILE *out = fopen(path, "w");
    CHECK(in && out);
    if (in && out) {
        char line[512];
        for (int i = 0; i < 70 && fgets(line, sizeof line, in); ++i)
            fputs(line, out);
    }
    if (in)
        fclose(in);
    if (out)
        fclose(out);
    CHECK(nist_load(path, &p, msg, sizeof msg) != 0);
    CHECK_STR_CONTAINS(msg, "Number of Observations: 14' but 10 data rows");
    CHECK(unlink(path) == 0);
}

int main(void)
{
    const char *nist_dir = PHC_SHARED_DATA "/nist";
    struct stat st;
    if (stat(nist_dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        printf("test_nist_problem: skipped, %s not found\n", nist_dir);
        return 77;
    }
    CHECK(NIST_MODEL_COUNT == N_EXPECTED);

    for (int t = 0; t < N_EXPECTED; ++t) {
        char path[4096], msg[512];
        snprintf(path, sizeof path, "%s/%s.dat", nist_dir, expected[t].name);
        nist_problem *p = &problems[t];
        int rc = nist_load(path, p, msg, sizeof msg);
        CHECK(rc == 0);
        if (rc) {
            fprintf(stderr, "%s\n", msg);
            continue;
        }
        CHECK(!strcmp(p->name, expected[t].name));
        CHECK(p->n == expected[t].n);
        CHECK(p->k == expected[t].k);
        CHECK(p->nx == (strcmp(p->name, "Nelson") ? 1 : 2));
        CHECK(p->response_log == !strcmp(p->name, "Nelson"));
        CHECK(nist_response_is_log(p->lower_name) == p->response_log);
        CHECK(p->certified_rss > 0);
        for (int j = 0; j < p->k; ++j)
            CHECK(p->certified_sd[j] > 0);

        const char *expr = nist_expression(p->name);
        CHECK(expr != NULL);
        CHECK(nist_expression(p->lower_name) == expr);
        if (!expr)
            continue;

        /* RSS at the certified values: C model, expression, and agreement */
        double rss_c = 0, rss_e = 0, worst = 0;
        const char *error = NULL;
        for (int i = 0; i < p->n; ++i) {
            double fc = model_c(p->name, p->certified, p->x[i], p->x2[i]);
            double fe = eval_expression(expr, p, p->certified, i, &error);
            if (error)
                break;
            rss_c += (p->response[i] - fc) * (p->response[i] - fc);
            rss_e += (p->response[i] - fe) * (p->response[i] - fe);
            double d = fabs(fc - fe) / (fabs(fc) + 1e-300);
            if (d > worst)
                worst = d;
        }
        if (error)
            fprintf(stderr, "%s: expression \"%s\": %s\n", p->name, expr, error);
        CHECK(error == NULL);
        CHECK(worst < 1e-10);
        if (!(worst < 1e-10))
            fprintf(stderr, "%s: C model and expression differ by %g (relative)\n",
                    p->name, worst);
        if (!strcmp(p->name, "Lanczos1")) {
            CHECK(rss_c < 1e-20);
            CHECK(rss_e < 1e-20);
        } else {
            CHECK_NEAR(rss_c, p->certified_rss, 0, 1e-6);
            CHECK_NEAR(rss_e, p->certified_rss, 0, 1e-6);
        }
        /* the certified values score 11 digits; the starts do not */
        CHECK(nist_min_lre(p, p->certified) == 11.0);
        CHECK(nist_min_lre(p, p->starts[0]) < 4.0);
    }

    /* a few values straight from the files */
    const nist_problem *misra = &problems[15];
    CHECK(misra->starts[0][0] == 500 && misra->starts[0][1] == 0.0001);
    CHECK(misra->starts[1][0] == 250 && misra->starts[1][1] == 0.0005);
    CHECK(misra->certified[0] == 2.3894212918E+02);
    CHECK(misra->certified_sd[1] == 7.2668688436E-06);
    CHECK(misra->certified_rss == 1.2455138894E-01);
    CHECK(misra->y[0] == 10.07 && misra->x[0] == 77.6);
    CHECK(misra->y[13] == 81.78 && misra->x[13] == 760.0);
    const nist_problem *nelson = &problems[19];
    CHECK(nelson->y[0] == 15.0 && nelson->x[0] == 1 && nelson->x2[0] == 180);
    CHECK(nelson->response[0] == log(15.0));
    CHECK(nelson->certified[1] == 5.6177717026E-09);
    CHECK(problems[21].certified[0] == 2.0196866396E-01); /* NIST's Roszman1 */
    CHECK(problems[10].certified_rss == 1.4307867721E-25);
    CHECK_STR_CONTAINS(problems[4].model, "b8*cos( 2*pi*x/b7 )");
    CHECK_STR_CONTAINS(nelson->model, "log[y] = b1 - b2*x1 * exp[-b3*x2]");

    test_lre();

    char dir[] = "/tmp/phc_nist_XXXXXX";
    if (mkdtemp(dir)) {
        test_write_case(dir);
        test_bad_inputs(dir);
        CHECK(rmdir(dir) == 0);
    } else {
        CHECK(!"mkdtemp failed");
    }
    return check_finish("test_nist_problem");
}
