/* Unit tests of fit/costs/expression.c: the compiler of `curve` expressions
 * into a reverse-mode automatic-differentiation tape.
 *
 * (a) values against the same formula written in C (operators, precedence,
 *     unary signs, every function, pi, number forms);
 * (b) every analytic gradient against numerical derivatives at several
 *     points, including the 22 NIST StRD models of tests/nist_problem.h;
 * (c) syntax errors and unsupported functions: status, 0-based position and
 *     the "at character N" (1-based) message;
 * (d) the x^2 and x^3 fast paths against pow() and the general power rule;
 * (e) phc_expr_eval_rows (blocks of rows) against phc_expr_eval row by row:
 *     bitwise the same values and gradients for every expression above on
 *     rows that include zeros, negative values and points outside the
 *     domain (NaN, inf), for 1, 7 and PHC_EXPR_ROWS rows, and the grad
 *     stride (nothing written between rows' gradients);
 * (f) phc_expr_eval_data (data bound to the tape, its parameter-free parts
 *     computed once) against phc_expr_eval row by row: bitwise the same.
 *
 * Numerical derivatives: central differences with Richardson extrapolation
 * (Ridders' method, Numerical Recipes 3rd ed. §5.7), whose error is ~1e-12
 * relative for smooth functions, so that a 1e-7 relative tolerance tests the
 * tape and not the reference.  The relative error of component j is
 * |g_ad - g_fd| / max(|g_fd|, 1e-6 F / |p_j|), F = max(|f|, max_i |g_i p_i|):
 * the plain relative error, except for a component whose effect |g_j p_j|
 * is below 1e-6 of the function's scale F (e.g. a Gaussian term far from
 * its centre), where no difference quotient of f resolves 7 digits; such a
 * component is compared in units of 1e-6 F instead.  So that no derivative
 * escapes the plain test, every slot of every expression must also meet the
 * plain relative criterion at one point at least (checked). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/expression.h"
#include "nist_problem.h"

static const double PI = 3.14159265358979323846;

/* ---- helpers ---------------------------------------------------------------- */

/* Compiles `text`, binds slot names (slots[i] -> slot i) and column names
 * (cols[i] -> column i); NULL on any failure (reported as a failed check). */
static phc_expr *build(const char *text, const char *const *slots, size_t n_slots,
                       const char *const *cols, size_t n_cols)
{
    phc_expr *e = NULL;
    phc_error err;
    size_t pos = 0;
    phc_error_clear(&err);
    int rc = phc_expr_compile(text, &e, &pos, &err);
    if (rc != PHC_OK) {
        fprintf(stderr, "compile \"%s\": %s\n", text, err.message);
        CHECK(rc == PHC_OK);
        return NULL;
    }
    for (size_t i = 0; i < phc_expr_name_count(e); ++i) {
        const char *name = phc_expr_name(e, i);
        int bound = 0;
        for (size_t j = 0; j < n_slots && !bound; ++j)
            if (strcmp(slots[j], name) == 0)
                bound = phc_expr_bind(e, i, 1, j) == PHC_OK;
        for (size_t j = 0; j < n_cols && !bound; ++j)
            if (strcmp(cols[j], name) == 0)
                bound = phc_expr_bind(e, i, 0, j) == PHC_OK;
        if (!bound) {
            fprintf(stderr, "\"%s\": name '%s' not bound\n", text, name);
            CHECK(bound);
            phc_expr_free(e);
            return NULL;
        }
    }
    rc = phc_expr_prepare(e, n_slots, &err);
    CHECK(rc == PHC_OK);
    if (rc != PHC_OK) {
        phc_expr_free(e);
        return NULL;
    }
    return e;
}

typedef struct fd_ctx {
    phc_expr *e;
    double *p;
    const double *row;
    size_t j;
} fd_ctx;

static double f_at(fd_ctx *c, double v)
{
    const double keep = c->p[c->j];
    c->p[c->j] = v;
    const double f = phc_expr_eval(c->e, c->p, c->row, NULL);
    c->p[c->j] = keep;
    return f;
}

/* Ridders' extrapolated central difference of slot j, initial step h. */
static double ridders(fd_ctx *c, double h, double *err_out)
{
    enum { NTAB = 12 };
    const double con = 1.4, con2 = con * con, safe = 2.0;
    double a[NTAB][NTAB];
    const double x = c->p[c->j];
    double err = INFINITY, ans = NAN;
    a[0][0] = (f_at(c, x + h) - f_at(c, x - h)) / (2 * h);
    for (int i = 1; i < NTAB; ++i) {
        h /= con;
        a[0][i] = (f_at(c, x + h) - f_at(c, x - h)) / (2 * h);
        double fac = con2;
        for (int j = 1; j <= i; ++j) {
            a[j][i] = (a[j - 1][i] * fac - a[j - 1][i - 1]) / (fac - 1);
            fac *= con2;
            const double errt = fmax(fabs(a[j][i] - a[j - 1][i]), fabs(a[j][i] - a[j - 1][i - 1]));
            if (errt <= err) {
                err = errt;
                ans = a[j][i];
            }
        }
        if (fabs(a[i][i] - a[i - 1][i - 1]) >= safe * err)
            break;
    }
    if (err_out)
        *err_out = err;
    return ans;
}

/* Checks every slot derivative of e at (p, row) against Ridders; returns the
 * worst relative error (as defined at the top of the file).  strict[j] (may
 * be NULL) is set when slot j was held to the plain relative error. */
static double check_gradient(const char *what, phc_expr *e, double *p, size_t k, const double *row,
                             int *strict)
{
    double g[16], fd[16];
    const double f = phc_expr_eval(e, p, row, g);
    const double f2 = phc_expr_eval(e, p, row, NULL);
    CHECK(f == f2); /* the gradient sweep does not change the value */
    CHECK(isfinite(f));
    double effect_max = fabs(f);
    for (size_t j = 0; j < k; ++j) {
        fd_ctx c = {e, p, row, j};
        const double h = p[j] != 0 ? 0.05 * fabs(p[j]) : 0.05;
        fd[j] = ridders(&c, h, NULL);
        effect_max = fmax(effect_max, fabs(fd[j]) * (p[j] != 0 ? fabs(p[j]) : 1.0));
    }
    double worst = 0;
    for (size_t j = 0; j < k; ++j) {
        const double pj = p[j] != 0 ? fabs(p[j]) : 1.0;
        const double floor = 1e-6 * effect_max / pj;
        const double den = fmax(fabs(fd[j]), floor);
        if (strict && fabs(fd[j]) >= floor)
            strict[j] = 1;
        const double rel = den > 0 ? fabs(g[j] - fd[j]) / den : fabs(g[j] - fd[j]);
        if (!(rel < 1e-7))
            fprintf(stderr, "%s: d/dslot%zu analytic %.17g, numerical %.17g (rel %.3g)\n", what, j, g[j],
                    fd[j], rel);
        CHECK(rel < 1e-7);
        if (rel > worst || isnan(rel))
            worst = rel;
    }
    return worst;
}

/* ---- (a) values and (b) gradients of hand-picked expressions ----------------- */

typedef double (*cfun)(const double *p, const double *r);
/* slots a b c = p[0..2]; columns x t = r[0..1] */
#define A p[0]
#define B p[1]
#define C p[2]
#define X r[0]
#define T r[1]
static double c01(const double *p, const double *r) { return A + B * X; }
static double c02(const double *p, const double *r) { return A - B / X; }
static double c03(const double *p, const double *r) { return A * X * X + B * X * X * X; }
static double c04(const double *p, const double *r) { (void)r; return -(A * A); }
static double c05(const double *p, const double *r) { (void)r; return pow(A, B); }
static double c06(const double *p, const double *r) { return pow(X, B); }
static double c07(const double *p, const double *r) { return exp(-B * X) * A; }
static double c08(const double *p, const double *r) { return log(A * X) + sqrt(B); }
static double c09(const double *p, const double *r) { return sin(A * X) + cos(B) - tan(C * X); }
static double c10(const double *p, const double *r) { return atan(A / (X - B)) / PI; }
static double c11(const double *p, const double *r) { return fabs(A - B) * X; }
static double c12(const double *p, const double *r) { (void)r; return A + B; }          /* +a - -b */
static double c13(const double *p, const double *r) { (void)r; return (A / B) / C; }
static double c14(const double *p, const double *r) { (void)r; return (A - B) - C; }
static double c15(const double *p, const double *r) { (void)r; return pow(A, pow(2, B)); }
static double c16(const double *p, const double *r) { (void)r; return 2 * (1 / A); }
static double c17(const double *p, const double *r) { (void)r; return exp(log(sqrt(A * A + B * B))); }
static double c18(const double *p, const double *r) { (void)r; return 1e-3 * A + 0.5 * B + 250 * C; }
static double c19(const double *p, const double *r) { return (A + B) * (A - B) / (1 + X * X); }
static double c20(const double *p, const double *r) { return A * T + B * X; }
static double c21(const double *p, const double *r) { (void)r; return -pow(A + B, 3); }
static double c22(const double *p, const double *r) { (void)r; return pow(fabs(sin(A)), 0.5); }
static double c23(const double *p, const double *r) { return A * pow(2, X); }
static double c24(const double *p, const double *r) { (void)r; return sqrt(fabs(A)) * tan(atan(B)); }
static double c25(const double *p, const double *r) { return A - B * X * T / C + A * B * C; }
static double c26(const double *p, const double *r) { return -A * X - -B; }             /* unary binds tighter than * */
static double c27(const double *p, const double *r) { return 2 * A * (X + T) - B / 2 * C; } /* / then * left to right */
static double c28(const double *p, const double *r) { (void)r; return -pow(A, -B); }   /* -a^-b */
static double c29(const double *p, const double *r) { return pow(A, T * T) + pow(B, X); }
static double c30(const double *p, const double *r) { return log(exp(A * X) + exp(B)) + PI * C; }
static double c31(const double *p, const double *r) { return A / (B + C * X) * exp(-A * X); }
static double c32(const double *p, const double *r) { (void)r; return atan(A) * atan(B) * atan(C); }
#undef A
#undef B
#undef C
#undef X
#undef T

static const struct {
    const char *text;
    cfun f;
} cases[] = {
    {"a + b*x", c01},
    {"a - b/x", c02},
    {"a*x^2 + b*x^3", c03},
    {"-a^2", c04},
    {"a^b", c05},
    {"x^b", c06},
    {"exp(-b*x)*a", c07},
    {"log(a*x)+sqrt(b)", c08},
    {"sin(a*x)+cos(b)-tan(c*x)", c09},
    {"atan(a/(x-b))/pi", c10},
    {"abs(a-b)*x", c11},
    {"+a - -b", c12},
    {"a/b/c", c13},
    {"a-b-c", c14},
    {"a^2^b", c15},
    {"2*a^-1", c16},
    {"exp(log(sqrt(a*a+b*b)))", c17},
    {"1e-3*a + .5*b + 2.5E+2*c", c18},
    {"(a+b)*(a-b)/(1+x^2)", c19},
    {"a*t + b*x", c20},
    {"-(a+b)^3", c21},
    {"abs(sin(a))^0.5", c22},
    {"a * 2 ^ x", c23},
    {"sqrt(abs(a)) * tan(atan(b))", c24},
    {"a - b*x*t/c + a*b*c", c25},
    {"-a*x - -b", c26},
    {"2*a*(x + t) - b/2*c", c27},
    {"-a^-b", c28},
    {"a^(t*t) + b^x", c29},
    {"  log( exp(a*x) + exp(b) )\t+ pi*c ", c30},
    {"a/(b + c*x)*exp(-a*x)", c31},
    {"atan(a)*atan(b)*atan(c)", c32},
};

static void test_values_and_gradients(void)
{
    static const char *const slots[] = {"a", "b", "c"};
    static const char *const cols[] = {"x", "t"};
    static const double points[][5] = {
        /* a, b, c, x, t */
        {0.7, 0.4, 0.3, 0.5, 3.0},
        {1.3, 1.9, 0.6, 1.7, -1.2},
        {2.1, 0.8, 1.1, 2.4, 0.25},
        {0.45, 1.25, 0.9, 3.1, 1.5},
    };
    double worst = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        phc_expr *e = build(cases[c].text, slots, 3, cols, 2);
        if (!e)
            continue;
        int strict[3] = {0, 0, 0};
        for (size_t q = 0; q < sizeof points / sizeof points[0]; ++q) {
            double p[3] = {points[q][0], points[q][1], points[q][2]};
            const double row[2] = {points[q][3], points[q][4]};
            const double want = cases[c].f(p, row);
            const double got = phc_expr_eval(e, p, row, NULL);
            if (!(fabs(got - want) <= 1e-14 * fabs(want) + 1e-300))
                fprintf(stderr, "\"%s\" at point %zu: %.17g, C gives %.17g\n", cases[c].text, q, got, want);
            CHECK_NEAR(got, want, 1e-300, 1e-14);
            char what[128];
            snprintf(what, sizeof what, "\"%s\" point %zu", cases[c].text, q);
            const double w = check_gradient(what, e, p, 3, row, strict);
            worst = fmax(worst, w);
        }
        /* every slot the expression uses was held to the plain relative error */
        for (size_t i = 0; i < phc_expr_name_count(e); ++i)
            for (size_t j = 0; j < 3; ++j)
                if (strcmp(phc_expr_name(e, i), slots[j]) == 0) {
                    if (!strict[j])
                        fprintf(stderr, "\"%s\": slot %s never checked strictly\n", cases[c].text, slots[j]);
                    CHECK(strict[j]);
                }
        phc_expr_free(e);
    }
    printf("hand-picked expressions: worst gradient relative error %.3g\n", worst);
}

/* The gradient has exactly n_slots entries; slots the expression does not
 * use get 0, and columns never appear in it. */
static void test_gradient_layout(void)
{
    static const char *const slots[] = {"a", "b", "unused", "c"};
    static const char *const cols[] = {"x"};
    phc_expr *e = build("a*x + c", slots, 4, cols, 1);
    if (!e)
        return;
    double p[4] = {2, 3, 5, 7};
    const double row[1] = {11};
    double g[5] = {-1, -1, -1, -1, 12345};
    CHECK_NEAR(phc_expr_eval(e, p, row, g), 2 * 11 + 7, 0, 0);
    CHECK(g[0] == 11 && g[1] == 0 && g[2] == 0 && g[3] == 1);
    CHECK(g[4] == 12345); /* no write beyond n_slots */
    phc_expr_free(e);

    /* a slot used twice accumulates both paths: d/da (a*a*x + a) = 2ax + 1 */
    static const char *const s1[] = {"a"};
    e = build("a*a*x + a", s1, 1, cols, 1);
    if (e) {
        double pa[1] = {1.5}, ga[1];
        CHECK_NEAR(phc_expr_eval(e, pa, row, ga), 1.5 * 1.5 * 11 + 1.5, 0, 1e-15);
        CHECK_NEAR(ga[0], 2 * 1.5 * 11 + 1, 0, 1e-15);
        phc_expr_free(e);
    }
}

/* x^b at x = 0 (a data column starting at zero, e.g. DanWood-like b1*x^b2):
 * the value is 0 for every b > 0, so d/db = 0 exactly; a NaN here would
 * make the bridge reject every step. */
static void test_power_at_zero_base(void)
{
    static const char *const slots[] = {"b1", "b2"};
    static const char *const cols[] = {"x"};
    phc_expr *e = build("b1*x^b2", slots, 2, cols, 1);
    if (!e)
        return;
    double p[2] = {0.77, 3.86}, g[2] = {NAN, NAN};
    const double row0[1] = {0.0};
    CHECK(phc_expr_eval(e, p, row0, g) == 0.0);
    CHECK(g[0] == 0.0);
    CHECK(g[1] == 0.0);
    const double row1[1] = {1.5};
    check_gradient("b1*x^b2 at x=1.5", e, p, 2, row1, NULL);
    phc_expr_free(e);
}

/* ---- constants: precedence, associativity, number forms ---------------------- */

static double eval_const(const char *text)
{
    phc_expr *e = NULL;
    phc_error err;
    size_t pos = 0;
    if (phc_expr_compile(text, &e, &pos, &err) != PHC_OK) {
        fprintf(stderr, "compile \"%s\": %s\n", text, err.message);
        return NAN;
    }
    double v = NAN;
    if (phc_expr_name_count(e) == 0 && phc_expr_prepare(e, 0, &err) == PHC_OK)
        v = phc_expr_eval(e, NULL, NULL, NULL);
    phc_expr_free(e);
    return v;
}

static void test_constants(void)
{
    const struct { /* not static: some values are computed */
        const char *text;
        double want;
    } k[] = {
        {"-2^2", -4},          /* ^ binds tighter than unary minus */
        {"2^3^2", 512},        /* right-associative */
        {"(2^3)^2", 64},
        {"2^-1", 0.5},
        {"2^-2^2", 0.0625},    /* 2^(-(2^2)) */
        {"-2^-2", -0.25},
        {"(-2)^2", 4},
        {"(-2)^3", -8},
        {"2^+3", 8},
        {"+3", 3},
        {"--3", 3},
        {"-+-3", 3},
        {"2*3+4", 10},
        {"2+3*4", 14},
        {"(2+3)*4", 20},
        {"10/2/5", 1},
        {"10-2-5", 3},
        {"10-2+5", 13},
        {"12/3*2", 8},
        {"2*-3", -6},
        {"3 - -2^2", 7},
        {"pi", 3.14159265358979323846},
        {"_pi", 3.14159265358979323846},
        {"_e", 2.71828182845904523536},
        {"2*pi", 6.28318530717958647692},
        {"1e-3", 1e-3},
        {".5", 0.5},
        {"5.", 5.0},
        {"2.5E+2", 250},
        {"2.5e2", 250},
        {"1E3", 1000},
        {"0.125e-2", 0.00125},
        {"6.02214076e23", 6.02214076e23},
        {"exp(1)", 2.71828182845904523536},
        {"ln(exp(2))", 2},     /* muparser's alias of log */
        {"log(1)", 0},
        {"sqrt(16)", 4},
        {"sin(pi/6)", sin(PI / 6)},
        {"cos(0)", 1},
        {"tan(pi/4)", tan(PI / 4)},
        {"atan(1)*4", 4 * atan(1.0)},
        {"abs(-2.5)", 2.5},
        {"abs(3-5)^2", 4},
        {"sqrt(abs(-9))+exp(log(3))", 6},
        {" ( 1 + 2 ) * 3 ", 9},
    };
    for (size_t i = 0; i < sizeof k / sizeof k[0]; ++i) {
        const double v = eval_const(k[i].text);
        if (!(fabs(v - k[i].want) <= 1e-15 * fabs(k[i].want) + 1e-15))
            fprintf(stderr, "\"%s\" = %.17g, expected %.17g\n", k[i].text, v, k[i].want);
        CHECK_NEAR(v, k[i].want, 1e-15, 1e-15);
    }
    /* exact for the ones that are exact in binary */
    CHECK(eval_const("-2^2") == -4.0);
    CHECK(eval_const("2^3^2") == 512.0);
    CHECK(eval_const("2^-1") == 0.5);
    /* non-finite results are returned as they are */
    CHECK(isnan(eval_const("log(-1)")));
    CHECK(isnan(eval_const("sqrt(-1)")));
    CHECK(isinf(eval_const("1/0")));
    CHECK(isinf(eval_const("log(0)")) && eval_const("log(0)") < 0);
}

/* ---- names and binding ------------------------------------------------------ */

static void test_names_and_binding(void)
{
    phc_expr *e = NULL;
    phc_error err;
    size_t pos = 0;
    CHECK(phc_expr_compile("a*x + a*b_2 + x - pi*_pi + x1", &e, &pos, &err) == PHC_OK);
    if (!e)
        return;
    /* distinct names, first-use order, pi excluded */
    CHECK(phc_expr_name_count(e) == 4);
    CHECK_STR_CONTAINS(phc_expr_name(e, 0), "a");
    CHECK(phc_expr_name(e, 0) && strcmp(phc_expr_name(e, 0), "a") == 0);
    CHECK(phc_expr_name(e, 1) && strcmp(phc_expr_name(e, 1), "x") == 0);
    CHECK(phc_expr_name(e, 2) && strcmp(phc_expr_name(e, 2), "b_2") == 0);
    CHECK(phc_expr_name(e, 3) && strcmp(phc_expr_name(e, 3), "x1") == 0);
    CHECK(phc_expr_name(e, 4) == NULL);
    /* binding errors */
    CHECK(phc_expr_bind(e, 4, 1, 0) != PHC_OK);
    CHECK(phc_expr_bind(e, 0, 1, 0) == PHC_OK);
    CHECK(phc_expr_bind(e, 1, 0, 1) == PHC_OK);
    phc_error_clear(&err);
    CHECK(phc_expr_prepare(e, 2, &err) != PHC_OK); /* b_2 and x1 unbound */
    CHECK_STR_CONTAINS(err.message, "b_2");
    CHECK(phc_expr_bind(e, 2, 1, 5) == PHC_OK);
    CHECK(phc_expr_bind(e, 3, 0, 0) == PHC_OK);
    phc_error_clear(&err);
    CHECK(phc_expr_prepare(e, 2, &err) != PHC_OK); /* slot 5 >= 2 */
    CHECK_STR_CONTAINS(err.message, "5");
    CHECK(phc_expr_bind(e, 2, 1, 1) == PHC_OK);
    CHECK(phc_expr_prepare(e, 2, &err) == PHC_OK);
    /* a -> slot 0, b_2 -> slot 1, x -> column 1, x1 -> column 0 */
    double p[2] = {3, 5}, g[2];
    const double row[2] = {7, 11};
    const double want = 3 * 11 + 3 * 5 + 11 - PI * PI + 7;
    CHECK_NEAR(phc_expr_eval(e, p, row, g), want, 0, 1e-15);
    CHECK_NEAR(g[0], 11 + 5, 0, 0);
    CHECK_NEAR(g[1], 3, 0, 0);
    /* re-binding and preparing again works (a column becomes a slot) */
    CHECK(phc_expr_bind(e, 1, 1, 2) == PHC_OK);
    CHECK(phc_expr_prepare(e, 3, &err) == PHC_OK);
    double p3[3] = {3, 5, 11}, g3[3];
    CHECK_NEAR(phc_expr_eval(e, p3, row, g3), want, 0, 1e-15);
    CHECK_NEAR(g3[2], 3 + 1, 0, 0);
    phc_expr_free(e);
    phc_expr_free(NULL);
}

/* ---- (c) syntax errors --------------------------------------------------------- */

static void test_errors(void)
{
    static const struct {
        const char *text;
        size_t pos;          /* 0-based */
        const char *message; /* substring */
    } bad[] = {
        {"b1*(x+", 6, "unexpected end"},
        {"2**3", 2, "unexpected character"},
        {"foo(x)", 0, "not supported"},
        {"sinh(x)", 0, "not supported"},
        {"a + min(a, b)", 4, "not supported"},
        {"(a+b", 4, "expected ')'"},
        {"exp(a", 5, "expected ')'"},
        {"exp(a, b)", 5, "expected ')'"},
        {"a+", 2, "unexpected end"},
        {"", 0, "unexpected end"},
        {"   ", 3, "unexpected end"},
        {"a b", 2, "unexpected text"},
        {"3x", 1, "unexpected text"},
        {"a+)", 2, "unexpected character"},
        {"a $ b", 2, "unexpected text"},
        {"a*#", 2, "unexpected character"},
        {"()", 1, "unexpected character"},
        {"a^", 2, "unexpected end"},
        {"1.2.3", 3, "unexpected text"},
        {"1..5", 2, "unexpected text"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        phc_expr *e = (phc_expr *)&e; /* must be reset to NULL */
        phc_error err;
        size_t pos = 999;
        phc_error_clear(&err);
        const int rc = phc_expr_compile(bad[i].text, &e, &pos, &err);
        if (rc != PHC_ERR_INPUT || pos != bad[i].pos || !strstr(err.message, bad[i].message))
            fprintf(stderr, "\"%s\": rc %d pos %zu message '%s' (expected pos %zu, '%s')\n", bad[i].text, rc,
                    pos, err.message, bad[i].pos, bad[i].message);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK(err.status == PHC_ERR_INPUT);
        CHECK(e == NULL);
        CHECK(pos == bad[i].pos);
        CHECK_STR_CONTAINS(err.message, bad[i].message);
        char at[32];
        snprintf(at, sizeof at, "at character %zu", bad[i].pos + 1);
        CHECK_STR_CONTAINS(err.message, at);
        if (rc == PHC_OK)
            phc_expr_free(e);
    }
    /* pos and err may be NULL */
    phc_expr *e = NULL;
    CHECK(phc_expr_compile("2**3", &e, NULL, NULL) == PHC_ERR_INPUT);
    CHECK(e == NULL);
}

/* ---- (d) fast paths of x^2 and x^3 ----------------------------------------------- */

static void test_power_fast_paths(void)
{
    static const char *const slots[] = {"a", "b"};
    phc_expr *sq = build("a^2", slots, 1, NULL, 0);
    phc_expr *cu = build("a^3", slots, 1, NULL, 0);
    phc_expr *gen = build("a^b", slots, 2, NULL, 0); /* active exponent: the general rule */
    if (!sq || !cu || !gen) {
        phc_expr_free(sq);
        phc_expr_free(cu);
        phc_expr_free(gen);
        return;
    }
    static const double as[] = {0.0, 1.0, -1.0, 0.3, -1.7, 2.5, 1e-5, -3e4, 123.456, 1e100};
    for (size_t i = 0; i < sizeof as / sizeof as[0]; ++i) {
        const double a = as[i];
        double g[2];
        double p1[1] = {a};
        CHECK_NEAR(phc_expr_eval(sq, p1, NULL, g), pow(a, 2), 0, 2.3e-16);
        CHECK_NEAR(g[0], 2 * a, 0, 0);
        CHECK_NEAR(phc_expr_eval(cu, p1, NULL, g), pow(a, 3), 0, 4.5e-16);
        CHECK_NEAR(g[0], 3 * a * a, 0, 2.3e-16);
        double p2[2] = {a, 2}, gg[2];
        double v2 = phc_expr_eval(gen, p2, NULL, gg);
        CHECK_NEAR(v2, a * a, 0, 2.3e-16);
        CHECK_NEAR(gg[0], 2 * a, 0, 4.5e-16);
        if (a > 0)
            CHECK_NEAR(gg[1], a * a * log(a), 1e-300, 1e-15);
        if (a == 0)
            CHECK(gg[1] == 0.0); /* d/db 0^b = 0 for b > 0 */
        p2[1] = 3;
        v2 = phc_expr_eval(gen, p2, NULL, gg);
        CHECK_NEAR(v2, a * a * a, 0, 4.5e-16);
        CHECK_NEAR(gg[0], 3 * a * a, 0, 6.7e-16);
    }
    /* a column exponent equal to 2 or 3 (not a slot) takes the same paths */
    static const char *const cols[] = {"x"};
    phc_expr *col = build("a^x", slots, 1, cols, 1);
    if (col) {
        double p[1] = {-1.7}, g[1];
        const double r2[1] = {2}, r3[1] = {3}, r25[1] = {2.5};
        CHECK_NEAR(phc_expr_eval(col, p, r2, g), pow(-1.7, 2), 0, 2.3e-16);
        CHECK_NEAR(g[0], -3.4, 0, 1e-15);
        CHECK_NEAR(phc_expr_eval(col, p, r3, g), pow(-1.7, 3), 0, 4.5e-16);
        CHECK_NEAR(g[0], 3 * 1.7 * 1.7, 0, 1e-15);
        CHECK(isnan(phc_expr_eval(col, p, r25, g))); /* negative base, fractional power */
        p[0] = 1.7;
        CHECK_NEAR(phc_expr_eval(col, p, r25, g), pow(1.7, 2.5), 0, 1e-15);
        CHECK_NEAR(g[0], 2.5 * pow(1.7, 1.5), 0, 1e-15);
        phc_expr_free(col);
    }
    phc_expr_free(sq);
    phc_expr_free(cu);
    phc_expr_free(gen);
}

/* ---- the 22 NIST StRD models ---------------------------------------------------- */

static double nist_c(const char *name, const double *b, double x, double x2)
{
    if (!strcmp(name, "BoxBOD") || !strcmp(name, "Misra1a"))
        return b[0] * (1 - exp(-b[1] * x));
    if (!strncmp(name, "Chwirut", 7))
        return exp(-b[0] * x) / (b[1] + b[2] * x);
    if (!strcmp(name, "DanWood"))
        return b[0] * pow(x, b[1]);
    if (!strcmp(name, "ENSO")) {
        const double w = 2 * PI * x;
        return b[0] + b[1] * cos(w / 12) + b[2] * sin(w / 12) + b[4] * cos(w / b[3]) + b[5] * sin(w / b[3]) +
               b[7] * cos(w / b[6]) + b[8] * sin(w / b[6]);
    }
    if (!strncmp(name, "Gauss", 5))
        return b[0] * exp(-b[1] * x) + b[2] * exp(-(x - b[3]) * (x - b[3]) / (b[4] * b[4])) +
               b[5] * exp(-(x - b[6]) * (x - b[6]) / (b[7] * b[7]));
    if (!strcmp(name, "Hahn1"))
        return (b[0] + b[1] * x + b[2] * x * x + b[3] * x * x * x) / (1 + b[4] * x + b[5] * x * x + b[6] * x * x * x);
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

/* Certified values and NIST's Start 1 (from the .dat files), and four
 * abscissae inside each problem's data range (Nelson: x1, then x2); for
 * Gauss1-3 two of them sit near the peaks, where the peak parameters act. */
#define NIST_NX 4
static const struct {
    const char *name;
    double certified[9];
    double start1[9];
    double x[NIST_NX];
    double x2[NIST_NX];
} nist_points[] = {
    {"BoxBOD", {213.80940889, 0.54723748542}, {1, 1}, {1, 3.7, 6.2, 10}, {0}},
    {"Chwirut1", {0.1902781837, 0.0061314004477, 0.010530908399}, {0.1, 0.01, 0.02}, {0.5, 1.2, 2.9, 6}, {0}},
    {"Chwirut2", {0.16657666537, 0.0051653291286, 0.012150007096}, {0.1, 0.01, 0.02}, {0.5, 1.2, 2.9, 6}, {0}},
    {"DanWood", {0.76886226176, 3.8604055871}, {1, 5}, {1.309, 1.4, 1.5, 1.68}, {0}},
    {"ENSO",
     {10.510749193, 3.0762128085, 0.53280138227, 44.3110887, -1.6231428586, 0.52554493756, 26.88761444,
      0.21232288488, 1.4966870418},
     {11, 3, 0.5, 40, -0.7, -1.3, 25, -0.3, 1.4},
     {1.5, 37.3, 88.1, 161.7},
     {0}},
    {"Gauss1",
     {98.778210871, 0.010497276517, 100.48990633, 67.481111276, 23.12977336, 71.994503004, 178.99805021,
      18.389389025},
     {97, 0.009, 100, 65, 20, 70, 178, 16.5},
     {1, 67.5, 179, 250},
     {0}},
    {"Gauss2",
     {99.018328406, 0.010994945399, 101.88022528, 107.03095519, 23.578584029, 72.045589471, 153.27010194,
      19.525972636},
     {96, 0.009, 103, 106, 18, 72, 151, 18},
     {1, 107, 153.3, 250},
     {0}},
    {"Gauss3",
     {98.94036897, 0.010945879335, 100.69553078, 111.63619459, 23.300500029, 73.705031418, 147.76164251,
      19.66822123},
     {94.9, 0.009, 90.1, 113, 20, 73.8, 140, 20},
     {1, 111.6, 147.8, 250},
     {0}},
    {"Hahn1",
     {1.0776351733, -0.12269296921, 0.004086375061, -1.4262662514e-06, -0.0057609940901, 0.00024053735503,
      -1.2314450199e-07},
     {10, -1, 0.05, -1e-05, -0.05, 0.001, -1e-06},
     {14.13, 60.2, 300.5, 851.61},
     {0}},
    {"Kirby2",
     {1.6745063063, -0.13927397867, 0.0025961181191, -0.001724181187, 2.1664802578e-05},
     {2, -0.1, 0.003, -0.001, 1e-05},
     {9.65, 60.4, 150.2, 371.3},
     {0}},
    {"Lanczos1", {0.095100000027, 1.0000000001, 0.86070000013, 3.0000000002, 1.5575999998, 5.0000000001},
     {1.2, 0.3, 5.6, 5.5, 6.5, 7.6}, {0, 0.2, 0.55, 1.15}, {0}},
    {"Lanczos2", {0.096251029939, 1.0057332849, 0.86424689056, 3.0078283915, 1.5529016879, 5.00287981},
     {1.2, 0.3, 5.6, 5.5, 6.5, 7.6}, {0, 0.2, 0.55, 1.15}, {0}},
    {"Lanczos3", {0.086816414977, 0.95498101505, 0.84400777463, 2.9515951832, 1.5825685901, 4.9863565084},
     {1.2, 0.3, 5.6, 5.5, 6.5, 7.6}, {0, 0.2, 0.55, 1.15}, {0}},
    {"MGH09", {0.19280693458, 0.19128232873, 0.12305650693, 0.13606233068}, {25, 39, 41.5, 39},
     {0.0625, 0.25, 0.5, 4}, {0}},
    {"MGH17", {0.37541005211, 1.9358469127, -1.4646871366, 0.01286753464, 0.022122699662},
     {50, 150, -100, 1, 2}, {0, 10, 100, 320}, {0}},
    {"Misra1a", {238.94212918, 0.00055015643181}, {500, 0.0001}, {77.6, 200, 400, 760}, {0}},
    {"Misra1b", {337.99746163, 0.00039039091287}, {500, 0.0001}, {77.6, 200, 400, 760}, {0}},
    {"Misra1c", {636.42725809, 0.00020813627256}, {500, 0.0001}, {77.6, 200, 400, 760}, {0}},
    {"Misra1d", {437.36970754, 0.00030227324449}, {500, 0.0001}, {77.6, 200, 400, 760}, {0}},
    {"Nelson", {2.5906836021, 5.6177717026e-09, -0.057701013174}, {2, 0.0001, -0.01}, {1, 4, 16, 64},
     {180, 250, 225, 275}},
    {"Rat42", {72.462237576, 2.6180768402, 0.067359200066}, {100, 1, 0.1}, {9, 20, 30, 79}, {0}},
    {"Roszman1", {0.20196866396, -6.1953516256e-06, 1204.4556708, -181.34269537}, {0.1, -1e-05, 1000, -100},
     {-4868.68, -3000, -2000, -464.17}, {0}},
};

static void test_nist_models(void)
{
    CHECK(NIST_MODEL_COUNT == 22);
    CHECK(sizeof nist_points / sizeof nist_points[0] == 22);
    double worst = 0;
    for (int m = 0; m < NIST_MODEL_COUNT; ++m) {
        const nist_model *nm = &nist_models[m];
        size_t q = 0;
        while (q < sizeof nist_points / sizeof nist_points[0] && strcmp(nist_points[q].name, nm->name) != 0)
            ++q;
        CHECK(q < sizeof nist_points / sizeof nist_points[0]);
        if (q == sizeof nist_points / sizeof nist_points[0])
            continue;
        static const char *const slots[] = {"b1", "b2", "b3", "b4", "b5", "b6", "b7", "b8", "b9"};
        static const char *const cols1[] = {"x"};
        static const char *const cols2[] = {"x1", "x2"};
        phc_expr *e = build(nm->expression, slots, (size_t)nm->k, nm->nx == 2 ? cols2 : cols1, (size_t)nm->nx);
        if (!e)
            continue;
        CHECK(phc_expr_name_count(e) == (size_t)(nm->k + nm->nx)); /* every b and column appears */
        double model_worst = 0;
        int strict[9] = {0};
        for (int which = 0; which < 2; ++which) {
            const double *src = which == 0 ? nist_points[q].certified : nist_points[q].start1;
            for (int i = 0; i < NIST_NX; ++i) {
                double p[9];
                memcpy(p, src, sizeof p);
                const double row[2] = {nist_points[q].x[i], nist_points[q].x2[i]};
                const double want = nist_c(nm->name, p, row[0], row[1]);
                const double got = phc_expr_eval(e, p, row, NULL);
                if (!(fabs(got - want) <= 1e-13 * fabs(want) + 1e-300))
                    fprintf(stderr, "%s at x=%g: %.17g, C gives %.17g\n", nm->name, row[0], got, want);
                CHECK_NEAR(got, want, 1e-300, 1e-13);
                char what[96];
                snprintf(what, sizeof what, "%s (%s, x=%g)", nm->name, which ? "start 1" : "certified", row[0]);
                model_worst = fmax(model_worst, check_gradient(what, e, p, (size_t)nm->k, row, strict));
            }
        }
        for (int j = 0; j < nm->k; ++j) {
            if (!strict[j])
                fprintf(stderr, "%s: d/db%d never checked strictly\n", nm->name, j + 1);
            CHECK(strict[j]);
        }
        worst = fmax(worst, model_worst);
        phc_expr_free(e);
    }
    printf("NIST models: worst gradient relative error %.3g\n", worst);
}

/* Nesting deeper than 200 levels is refused with PHC_ERR_DOMAIN instead of
 * overflowing the stack (issue 15: 9,970 nested parentheses crashed). */
static void test_depth_limit(void)
{
    const size_t deep[] = {150, 250, 9970, 100000};
    for (size_t k = 0; k < sizeof deep / sizeof deep[0]; ++k) {
        for (int form = 0; form < 3; ++form) { /* parentheses, minus signs, function calls */
            const size_t n = deep[k];
            char *text = malloc(6 * n + 8);
            size_t len = 0;
            for (size_t i = 0; i < n; ++i) {
                const char *open = form == 0 ? "(" : form == 1 ? "-" : "exp(";
                memcpy(text + len, open, strlen(open));
                len += strlen(open);
            }
            text[len++] = 'a';
            for (size_t i = 0; form != 1 && i < n; ++i)
                text[len++] = ')';
            text[len] = '\0';
            phc_expr *e = NULL;
            size_t pos = 0;
            phc_error err;
            phc_error_clear(&err);
            const int rc = phc_expr_compile(text, &e, &pos, &err);
            if (n <= 150) {
                CHECK(rc == PHC_OK);
            } else {
                CHECK(rc == PHC_ERR_DOMAIN);
                CHECK_STR_CONTAINS(err.message, "nested more than 200 levels deep");
                CHECK(pos == (form == 2 ? 800u : form == 1 ? 200u : 200u));
            }
            phc_expr_free(e);
            free(text);
        }
    }
}

/* 1 when a and b are the same bits (NaN with NaN of the same payload) */
static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static void test_rows(void)
{
    static const char *const slots[] = {"a", "b", "c"};
    static const char *const cols[] = {"x", "t"};
    double x[PHC_EXPR_ROWS], t[PHC_EXPR_ROWS];
    for (size_t r = 0; r < PHC_EXPR_ROWS; ++r) { /* zeros, negatives, 2, 3 */
        x[r] = r % 8 == 0 ? 0.0 : (r % 5 == 0 ? 2.0 : -1.5 + 0.37 * (double)r);
        t[r] = r % 7 == 0 ? 3.0 : (r % 6 == 0 ? 0.0 : 2.2 - 0.29 * (double)r);
    }
    const double params[][3] = {{0.7, 0.4, 0.3}, {1.3, 2.0, 0.6}, {-2.1, 3.0, 1.1}, {0.0, 1.25, -0.9}};
    const size_t counts[] = {1, 7, PHC_EXPR_ROWS};
    const size_t stride = 5; /* 3 slots and 2 guard values per row */
    long compared = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        phc_expr *e = build(cases[c].text, slots, 3, cols, 2);
        if (!e)
            continue;
        for (size_t q = 0; q < sizeof params / sizeof params[0]; ++q)
            for (size_t k = 0; k < sizeof counts / sizeof counts[0]; ++k) {
                const size_t n = counts[k];
                const double *colp[2] = {x, t};
                double v[PHC_EXPR_ROWS], g[PHC_EXPR_ROWS * 5], v1[PHC_EXPR_ROWS];
                for (size_t i = 0; i < n * stride; ++i)
                    g[i] = 12345;
                CHECK(phc_expr_eval_rows(e, params[q], colp, n, v, g, stride) == PHC_OK);
                CHECK(phc_expr_eval_rows(e, params[q], colp, n, v1, NULL, 0) == PHC_OK);
                for (size_t r = 0; r < n; ++r) {
                    const double row[2] = {x[r], t[r]};
                    double g1[3];
                    const double want = phc_expr_eval(e, params[q], row, g1);
                    int ok = same_bits(v[r], want) && same_bits(v1[r], want);
                    for (size_t j = 0; j < 3; ++j)
                        ok &= same_bits(g[r * stride + j], g1[j]);
                    ok &= g[r * stride + 3] == 12345 && g[r * stride + 4] == 12345;
                    if (!ok)
                        fprintf(stderr, "\"%s\" rows %zu, row %zu: %.17g (%.17g %.17g %.17g), row by row %.17g "
                                "(%.17g %.17g %.17g)\n", cases[c].text, n, r, v[r], g[r * stride],
                                g[r * stride + 1], g[r * stride + 2], want, g1[0], g1[1], g1[2]);
                    CHECK(ok);
                    ++compared;
                }
            }
        phc_expr_free(e);
    }
    phc_expr *e = build("a + b*x", slots, 3, cols, 2);
    if (e) {
        const double *colp[2] = {x, t};
        double v[PHC_EXPR_ROWS + 1];
        CHECK(phc_expr_eval_rows(e, params[0], colp, PHC_EXPR_ROWS + 1, v, NULL, 0) == PHC_ERR_INVALID);
        phc_expr_free(e);
    }
    printf("blocks of rows: %ld rows bitwise equal to row-by-row evaluation\n", compared);
}

/* phc_expr_eval_data (the data bound to the tape, the parts without
 * parameters computed once at binding) against phc_expr_eval row by row:
 * bitwise the same values and gradients, for every expression above and
 * some whose parameter-free parts are larger (cos(2*pi*x/12), x^2, t*t,
 * log(x) outside its domain), over blocks at several offsets; rows outside
 * the data and a tape prepared again (which drops the data) are refused. */
static void test_bound_data(void)
{
    static const char *const slots[] = {"a", "b", "c"};
    static const char *const cols[] = {"x", "t"};
    static const char *const more[] = {"b*cos(2*pi*x/12) + c*sin(2*pi*x/a) + a",
                                       "a*exp(-(x-b)^2/c^2) + log(x)*c + sqrt(abs(t))*b",
                                       "a*(x^2 + x*b)/(x^2 + x*c + t*t)",
                                       "-(x*t) + a", "exp(-x)*(a + b*atan(t/3))"};
    enum { N = 2 * PHC_EXPR_ROWS + 9 };
    double x[N], t[N];
    for (size_t r = 0; r < N; ++r) { /* zeros, negatives, 2, 3 */
        x[r] = r % 8 == 0 ? 0.0 : (r % 5 == 0 ? 2.0 : -1.5 + 0.37 * (double)r);
        t[r] = r % 7 == 0 ? 3.0 : (r % 6 == 0 ? 0.0 : 2.2 - 0.29 * (double)r);
    }
    const double *colp[2] = {x, t};
    const double params[][3] = {{0.7, 0.4, 0.3}, {1.3, 2.0, 0.6}, {-2.1, 3.0, 1.1}};
    const size_t blocks[][2] = {{0, PHC_EXPR_ROWS}, {PHC_EXPR_ROWS, PHC_EXPR_ROWS}, {2 * PHC_EXPR_ROWS, 9},
                                {5, 7}, {N - 1, 1}, {0, 1}};
    const size_t n_cases = sizeof cases / sizeof cases[0], n_more = sizeof more / sizeof more[0];
    long compared = 0;
    for (size_t c = 0; c < n_cases + n_more; ++c) {
        const char *text = c < n_cases ? cases[c].text : more[c - n_cases];
        phc_expr *e = build(text, slots, 3, cols, 2);
        phc_error err;
        phc_error_clear(&err);
        if (!e || phc_expr_bind_data(e, colp, N, &err) != PHC_OK) {
            fprintf(stderr, "\"%s\": cannot bind the data: %s\n", text, err.message);
            CHECK(0);
            phc_expr_free(e);
            continue;
        }
        for (size_t q = 0; q < sizeof params / sizeof params[0]; ++q)
            for (size_t k = 0; k < sizeof blocks / sizeof blocks[0]; ++k) {
                const size_t row0 = blocks[k][0], n = blocks[k][1];
                double v[PHC_EXPR_ROWS], g[PHC_EXPR_ROWS * 3], v1[PHC_EXPR_ROWS];
                CHECK(phc_expr_eval_data(e, params[q], row0, n, v, g, 3) == PHC_OK);
                CHECK(phc_expr_eval_data(e, params[q], row0, n, v1, NULL, 0) == PHC_OK);
                for (size_t r = 0; r < n; ++r) {
                    const double row[2] = {x[row0 + r], t[row0 + r]};
                    double g1[3];
                    const double want = phc_expr_eval(e, params[q], row, g1);
                    int ok = same_bits(v[r], want) && same_bits(v1[r], want);
                    for (size_t j = 0; j < 3; ++j)
                        ok &= same_bits(g[r * 3 + j], g1[j]);
                    if (!ok)
                        fprintf(stderr, "\"%s\" bound data, row %zu: %.17g (%.17g %.17g %.17g), row by row "
                                "%.17g (%.17g %.17g %.17g)\n", text, row0 + r, v[r], g[r * 3], g[r * 3 + 1],
                                g[r * 3 + 2], want, g1[0], g1[1], g1[2]);
                    CHECK(ok);
                    ++compared;
                }
            }
        double v[PHC_EXPR_ROWS + 1];
        CHECK(phc_expr_eval_data(e, params[0], N - 3, 4, v, NULL, 0) == PHC_ERR_INVALID);
        CHECK(phc_expr_eval_data(e, params[0], 0, PHC_EXPR_ROWS + 1, v, NULL, 0) == PHC_ERR_INVALID);
        CHECK(phc_expr_prepare(e, 3, &err) == PHC_OK);
        CHECK(phc_expr_eval_data(e, params[0], 0, 1, v, NULL, 0) == PHC_ERR_INVALID);
        phc_expr_free(e);
    }
    printf("bound data: %ld rows bitwise equal to row-by-row evaluation\n", compared);
}

int main(void)
{
    test_values_and_gradients();
    test_rows();
    test_bound_data();
    test_gradient_layout();
    test_power_at_zero_base();
    test_constants();
    test_names_and_binding();
    test_errors();
    test_depth_limit();
    test_power_fast_paths();
    test_nist_models();
    return check_finish("test_expression");
}
