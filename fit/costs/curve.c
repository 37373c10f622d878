/* `curve` data sets through muparser's C API: see curve.h.
 *
 * muparser's bulk mode offsets every variable by the row index, including
 * scalar parameters (checked with muparser 2.3.3), so rows are evaluated one
 * at a time with scalar variables; the expression's byte code is compiled
 * once and reused. */
#include "fit/costs/curve.h"
#include "fit/engine/baseline.h"

#include <math.h>
#include <muParserDLL.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/expression.h"
#include "fit/costs/source_file.h"
#include "measurements/suggest.h"
#include "measurements/table.h"

/* Most columns an expression evaluated in blocks of rows may use (more:
 * row by row). */
#define PHC_CURVE_MAX_BLOCK_COLS 64

typedef struct curve_impl {
    muParserHandle_t parser;
    phc_expr *tape;       /* exact derivatives; NULL = muparser + numerical */
    size_t n_cols;        /* columns used by the expression */
    double **cols;        /* n_cols arrays of n values */
    char **col_names;     /* n_cols names */
    double *row;          /* n_cols current values (muparser variables) */
    double *slots;        /* k current parameter values (muparser variables) */
    long x_col;           /* index into cols of the x column, -1 if unused */
    int other_cols;       /* expression uses columns other than x */
} curve_impl;

static void curve_free(void *p)
{
    curve_impl *c = p;
    if (!c)
        return;
    if (c->parser)
        mupRelease(c->parser);
    phc_expr_free(c->tape);
    for (size_t j = 0; j < c->n_cols; ++j) {
        free(c->cols[j]);
        free(c->col_names[j]);
    }
    free(c->cols);
    free(c->col_names);
    free(c->row);
    free(c->slots);
    free(c);
}

static int curve_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    curve_impl *c = ds->impl;
    if (c->tape) {
        /* blocks of rows of the data bound to the tape (bind_tape): a
         * fraction of the interpreter's overhead of one row at a time, and
         * the parts of the expression without parameters computed once;
         * the same numbers */
        for (size_t i0 = 0; i0 < ds->n; i0 += PHC_EXPR_ROWS) {
            const size_t nr = ds->n - i0 < PHC_EXPR_ROWS ? ds->n - i0 : PHC_EXPR_ROWS;
            if (phc_expr_eval_data(c->tape, p, i0, nr, yhat + i0, jac ? jac + i0 * ds->k : NULL, ds->k) != PHC_OK)
                return -1; /* the tape holds the data set's n rows: cannot happen */
            for (size_t r = 0; r < nr; ++r)
                if (!isfinite(yhat[i0 + r]))
                    return 1; /* outside the expression's domain: reject the step */
        }
        return 0;
    }
    memcpy(c->slots, p, ds->k * sizeof *p);
    for (size_t i = 0; i < ds->n; ++i) {
        for (size_t j = 0; j < c->n_cols; ++j)
            c->row[j] = c->cols[j][i];
        yhat[i] = mupEval(c->parser);
        if (mupError(c->parser)) {
            mupErrorReset(c->parser);
            return -1;
        }
        if (!isfinite(yhat[i]))
            return 1; /* outside the expression's domain: reject the step */
    }
    return 0;
}

static int curve_predict_at(phc_dataset *ds, const double *p, const double *x,
                            size_t m, double *y)
{
    curve_impl *c = ds->impl;
    if (c->other_cols)
        return 1; /* depends on more than x: no single curve */
    memcpy(c->slots, p, ds->k * sizeof *p);
    if (c->tape && c->n_cols <= PHC_CURVE_MAX_BLOCK_COLS) {
        /* x is the only column the expression reads (other_cols is 0) */
        const double *block_cols[PHC_CURVE_MAX_BLOCK_COLS];
        for (size_t done = 0; done < m; done += PHC_EXPR_ROWS) {
            const size_t nr = m - done < PHC_EXPR_ROWS ? m - done : PHC_EXPR_ROWS;
            for (size_t j = 0; j < c->n_cols; ++j)
                block_cols[j] = x + done;
            if (phc_expr_eval_rows(c->tape, p, block_cols, nr, y + done, NULL, 0) != PHC_OK)
                return -1; /* a prepared tape takes PHC_EXPR_ROWS rows: cannot happen */
        }
        return 0;
    }
    for (size_t i = 0; i < m; ++i) {
        if (c->x_col >= 0)
            c->row[c->x_col] = x[i];
        if (c->tape) {
            y[i] = phc_expr_eval(c->tape, p, c->row, NULL);
            continue;
        }
        y[i] = mupEval(c->parser);
        if (mupError(c->parser)) {
            mupErrorReset(c->parser);
            return -1;
        }
    }
    return 0;
}

/* The straight line in x (fit/engine/baseline.h): what a curve must beat. */
static int curve_baseline(const phc_dataset *ds, phc_baseline *out)
{
    char what[128];
    snprintf(what, sizeof what, "a straight line in %s", ds->x_label ? ds->x_label : "x");
    return phc_baseline_line(ds->x, ds->y, ds->sigma, ds->n, "line", what, out);
}

const phc_dataset_ops phc_curve_ops = {.kind = "curve", .predict = curve_predict,
                                       .predict_at = curve_predict_at, .free_impl = curve_free,
                                       .baseline = curve_baseline};

/* Compiles the derivative tape, binds its names to the slots and to the
 * columns muparser registered (same names, same order as c->cols) and
 * binds the columns' n_rows rows as its data (phc_expr_bind_data). */
static int bind_tape(curve_impl *c, const char *expr, const char *const *slot_names, size_t n_slots,
                     size_t n_rows, phc_error *err)
{
    phc_error tape_err;
    size_t pos = 0;
    phc_error_clear(&tape_err);
    if (phc_expr_compile(expr, &c->tape, &pos, &tape_err) != PHC_OK) {
        c->tape = NULL; /* unsupported construct: numerical derivatives */
        return tape_err.status == PHC_ERR_NOMEM ? phc_error_set(err, PHC_ERR_NOMEM, "out of memory") : PHC_OK;
    }
    for (size_t i = 0; i < phc_expr_name_count(c->tape); ++i) {
        const char *name = phc_expr_name(c->tape, i);
        int bound = 0;
        for (size_t j = 0; j < n_slots && !bound; ++j)
            if (strcmp(slot_names[j], name) == 0)
                bound = phc_expr_bind(c->tape, i, 1, j) == PHC_OK;
        for (size_t j = 0; j < c->n_cols && !bound; ++j)
            if (strcmp(c->col_names[j], name) == 0)
                bound = phc_expr_bind(c->tape, i, 0, j) == PHC_OK;
        if (!bound) { /* the two parsers disagree: trust muparser */
            phc_expr_free(c->tape);
            c->tape = NULL;
            return PHC_OK;
        }
    }
    if (phc_expr_prepare(c->tape, n_slots, err) != PHC_OK ||
        phc_expr_bind_data(c->tape, (const double *const *)c->cols, n_rows, err) != PHC_OK) {
        phc_expr_free(c->tape);
        c->tape = NULL;
        return err->status == PHC_ERR_NOMEM ? PHC_ERR_NOMEM : PHC_OK;
    }
    return PHC_OK;
}

/* The functions muparser 2.3.3 defines (muParser.cpp, Parser::InitFun; all
 * checked by tests/unit/test_curve_messages.c): named in the message about an
 * unknown function. */
static const char *const known_functions[] = {
    "exp", "log", "ln", "log2", "log10", "sqrt", "abs", "sign", "rint", "sin", "cos", "tan", "asin", "acos",
    "atan", "atan2", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh", "min", "max", "sum", "avg"};
#define N_KNOWN_FUNCTIONS (sizeof known_functions / sizeof known_functions[0])
/* mu::ecUNEXPECTED_PARENS of muParserDef.h (C++ only): a "(" where no
 * function name precedes it */
#define MUP_ERR_UNEXPECTED_PARENS 7

static int is_name_char(char c)
{
    return c == '_' || (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

/* 1-based character of the first whole-word use of `name` in expr, 0 if none. */
static int name_column(const char *expr, const char *name)
{
    const size_t len = strlen(name);
    for (const char *p = strstr(expr, name); p && len; p = strstr(p + 1, name))
        if ((p == expr || !is_name_char(p[-1])) && !is_name_char(p[len]))
            return (int)(p - expr) + 1;
    return 0;
}

/* The expression as a message shows it: whole when short, else the 60
 * characters around character pos (0-based; -1 = the start) between
 * ellipses, so that a long expression does not push the reason out of the
 * message (PHC_ERROR_MESSAGE_SIZE). */
#define EXPR_SHOWN_MAX 80
static const char *expr_shown(const char *expr, int pos, char *buf, size_t size)
{
    const int len = (int)strlen(expr);
    if (len <= EXPR_SHOWN_MAX)
        return expr;
    int from = pos < 0 ? 0 : pos - 30;
    if (from < 0)
        from = 0;
    if (from > len - 60)
        from = len - 60;
    snprintf(buf, size, "%s%.60s%s (%d characters)", from > 0 ? "..." : "", expr + from,
             from + 60 < len ? "..." : "", len);
    return buf;
}

/* muparser's message about an expression it cannot parse, at the config
 * line of `expression:` and the character in the expression.  A name
 * followed by "(" that is not a function is reported as such, with the
 * functions there are (muparser itself says only "Unexpected parenthesis"). */
static int expression_error(const char *where, const char *expr,
                            muParserHandle_t parser, phc_is_parameter_fn is_parameter, void *user_data,
                            phc_error *err)
{
    const int len = (int)strlen(expr);
    int pos = (int)mupGetErrorPos(parser);
    if (pos > len)
        pos = len; /* muparser may point past the end */
    char shown_buf[EXPR_SHOWN_MAX + 64];
    const char *shown = expr_shown(expr, pos, shown_buf, sizeof shown_buf);
    if (pos >= 0 && pos < len && expr[pos] == '(' && mupGetErrorCode(parser) == MUP_ERR_UNEXPECTED_PARENS) {
        int end = pos, start;
        while (end > 0 && expr[end - 1] == ' ')
            --end;
        for (start = end; start > 0 && is_name_char(expr[start - 1]); --start)
            ;
        if (start < end && !(expr[start] >= '0' && expr[start] <= '9')) {
            char name[128];
            snprintf(name, sizeof name, "%.*s", end - start, expr + start);
            char known[512] = "";
            for (size_t i = 0; i < N_KNOWN_FUNCTIONS; ++i) {
                const size_t used = strlen(known);
                snprintf(known + used, sizeof known - used, "%s%s", i ? " " : "", known_functions[i]);
            }
            if (is_parameter && is_parameter(name, user_data))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s: expression \"%s\": '%s' at character %d is a parameter, not a "
                                     "function (write '*' for a product); known functions: %s",
                                     where, shown, name, start + 1, known);
            const char *near = phc_suggest(name, known_functions, N_KNOWN_FUNCTIONS);
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: expression \"%s\": unknown function '%s' at character %d;%s%s%s "
                                 "known functions: %s",
                                 where, shown, name, start + 1, near ? " did you mean '" : "",
                                 near ? near : "", near ? "'?" : "", known);
        }
    }
    return phc_error_set(err, PHC_ERR_INPUT, "%s: expression \"%s\": %s (character %d)", where, shown,
                         mupGetErrorMsg(parser), pos + 1);
}

static char *label_or(const char *given, const char *fallback)
{
    return strdup(given ? given : fallback);
}

phc_curve_options phc_curve_options_default(void)
{
    phc_curve_options o = {0};
    return o;
}

/* Is an expression name a parameter slot?  The options' rule, or every name
 * that is not a column. */
static int names_parameter(const phc_curve_options *o, const phc_table *table, const char *name)
{
    return o->is_parameter ? o->is_parameter(name, o->user_data) : phc_table_find(table, name) < 0;
}

#define WHERE(key) phc_origin_key(opt->origin, "curve", key).text

/* The options phc_curve_new needs before it reads anything (a config has
 * checked them already): x, y and expression given, a table with rows, and
 * sigma a positive number or a column, not both. */
static int check_options(const phc_table *table, const phc_curve_options *opt, phc_error *err)
{
    static const char *const names[] = {"x", "y", "expression"};
    const char *const given[] = {opt->x, opt->y, opt->expression};
    for (int i = 0; i < 3; ++i)
        if (!given[i] || !given[i][0])
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s' is required", WHERE(NULL), names[i]);
    if (phc_table_rows(table) == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one",
                             phc_table_source(table));
    if (opt->sigma_column && opt->sigma != 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': give a number or a column, not both",
                             WHERE("sigma"));
    if (!opt->sigma_column && !(opt->sigma >= 0 && isfinite(opt->sigma)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': must be positive, found %g",
                             WHERE("sigma"), opt->sigma);
    return PHC_OK;
}

/* The error "expression uses no parameters", at the expression's key. */
static int no_parameters(const phc_curve_options *opt, phc_error *err)
{
    char shown_buf[EXPR_SHOWN_MAX + 64];
    return phc_error_set(err, PHC_ERR_INPUT, "%s: expression \"%s\" uses no parameters", WHERE("expression"),
                         expr_shown(opt->expression, -1, shown_buf, sizeof shown_buf));
}

/* Creates c's muparser parser for opt->expression (with the constant pi)
 * and sets *n_vars to the number of names it uses.  Nesting too deep for
 * either parser's stack (phc_expr_compile says PHC_ERR_DOMAIN) is refused
 * before muparser sees it; a parse error is muparser's message
 * (expression_error); an expression without names uses no parameters. */
static int parse_expression(curve_impl *c, const phc_curve_options *opt, int *n_vars, phc_error *err)
{
    const char *expr = opt->expression;
    c->parser = mupCreate(muBASETYPE_FLOAT);
    if (!c->parser)
        return phc_error_set(err, PHC_ERR_NOMEM, "cannot create an expression parser");
    mupDefineConst(c->parser, "pi", 3.14159265358979323846);
    phc_expr *probe = NULL;
    size_t probe_pos = 0;
    phc_error probe_err;
    phc_error_clear(&probe_err);
    const int probe_rc = phc_expr_compile(expr, &probe, &probe_pos, &probe_err);
    phc_expr_free(probe);
    if (probe_rc == PHC_ERR_DOMAIN) {
        char shown_buf[EXPR_SHOWN_MAX + 64];
        return phc_error_set(err, PHC_ERR_INPUT, "%s: expression \"%s\": %s", WHERE("expression"),
                             expr_shown(expr, (int)probe_pos, shown_buf, sizeof shown_buf), probe_err.message);
    }
    mupSetExpr(c->parser, expr);
    *n_vars = mupGetExprVarNum(c->parser);
    if (mupError(c->parser))
        return expression_error(WHERE("expression"), expr, c->parser, opt->is_parameter, opt->user_data, err);
    return *n_vars <= 0 ? no_parameters(opt, err) : PHC_OK;
}

/* One name of the expression: a parameter becomes slot *n_slots (its name
 * stored in slot_names, bound to c->slots), a column of the table is read
 * into c->cols and bound to c->row (the x column noted in c->x_col); a name
 * that is both, or neither, is an error naming the character it stands at. */
static int bind_name(curve_impl *c, const phc_table *table, const phc_curve_options *opt, const char *name,
                     char **slot_names, size_t *n_slots, phc_error *err)
{
    const int is_param = names_parameter(opt, table, name);
    const long col = phc_table_find(table, name);
    int rc = PHC_OK;
    if (is_param && col >= 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: expression name '%s' (character %d) is both a parameter and a column of %s; "
                             "rename one",
                             WHERE("expression"), name, name_column(opt->expression, name),
                             phc_table_source(table));
    if (is_param) {
        if (!(slot_names[*n_slots] = strdup(name)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        mupDefineVar(c->parser, name, &c->slots[(*n_slots)++]);
        return PHC_OK;
    }
    if (col < 0) {
        char what[64];
        snprintf(what, sizeof what, "expression (character %d): name", name_column(opt->expression, name));
        rc = phc_unknown_column_at(WHERE("expression"), what, name, table, err);
        if (rc == PHC_ERR_INPUT)
            strncat(err->message, " (not a parameter either)", sizeof err->message - strlen(err->message) - 1);
        return rc;
    }
    if ((rc = phc_table_column_numbers(table, name, &c->cols[c->n_cols], err)))
        return rc;
    if (!(c->col_names[c->n_cols] = strdup(name))) {
        free(c->cols[c->n_cols]);
        c->cols[c->n_cols] = NULL;
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    if (strcmp(name, opt->x) == 0)
        c->x_col = (long)c->n_cols;
    else
        c->other_cols = 1;
    mupDefineVar(c->parser, name, &c->row[c->n_cols++]);
    return PHC_OK;
}

/* Splits the n_vars names of c's expression into parameter slots (their
 * names into slot_names, n_vars long; *n_slots counts them) and columns
 * (bind_name); an expression with no parameter among them is an error. */
static int bind_names(curve_impl *c, const phc_table *table, const phc_curve_options *opt, int n_vars,
                      char **slot_names, size_t *n_slots, phc_error *err)
{
    c->cols = calloc((size_t)n_vars, sizeof *c->cols);
    c->col_names = calloc((size_t)n_vars, sizeof *c->col_names);
    c->row = calloc((size_t)n_vars, sizeof *c->row);
    c->slots = calloc((size_t)n_vars, sizeof *c->slots);
    char **var_names = calloc((size_t)n_vars, sizeof *var_names);
    if (!c->cols || !c->col_names || !c->row || !c->slots || !var_names) {
        free(var_names);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    /* copies of muparser's names, taken before any variable is defined */
    for (int v = 0; v < n_vars; ++v) {
        const char *name = NULL;
        double *ptr = NULL;
        mupGetExprVar(c->parser, (unsigned)v, &name, &ptr);
        var_names[v] = strdup(name ? name : "");
    }
    int rc = PHC_OK;
    for (int v = 0; v < n_vars && !rc; ++v)
        rc = bind_name(c, table, opt, var_names[v], slot_names, n_slots, err);
    for (int v = 0; v < n_vars; ++v)
        free(var_names[v]);
    free(var_names);
    if (!rc && *n_slots == 0)
        rc = no_parameters(opt, err);
    return rc;
}

/* ds->sigma from the options: a column (every value positive, else an
 * error at its file line), one number for every row, or none (NULL). */
static int read_sigma(phc_dataset *ds, const phc_table *table, const phc_curve_options *opt, phc_error *err)
{
    int rc;
    if (opt->sigma_column) {
        if (phc_table_find(table, opt->sigma_column) < 0)
            return phc_unknown_column_at(WHERE("sigma"), "sigma", opt->sigma_column, table, err);
        if ((rc = phc_table_column_numbers(table, opt->sigma_column, &ds->sigma, err)))
            return rc;
        for (size_t i = 0; i < ds->n; ++i)
            if (!(ds->sigma[i] > 0))
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': sigma must be positive, found %g",
                                     phc_table_source(table), phc_table_row_line(table, i), opt->sigma_column,
                                     ds->sigma[i]);
    } else if (opt->sigma > 0) {
        if (!(ds->sigma = malloc(ds->n * sizeof *ds->sigma)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t i = 0; i < ds->n; ++i)
            ds->sigma[i] = opt->sigma;
    }
    return PHC_OK;
}

/* The data set's observations from the table: n, x and y (the columns the
 * options name), sigma (read_sigma), each row's file and line, and the axis
 * labels (the column names unless the options give labels). */
static int read_observations(phc_dataset *ds, const phc_table *table, const phc_curve_options *opt,
                             phc_error *err)
{
    int rc;
    ds->n = phc_table_rows(table);
    if (phc_table_find(table, opt->x) < 0)
        return phc_unknown_column_at(WHERE("x"), "x", opt->x, table, err);
    if (phc_table_find(table, opt->y) < 0)
        return phc_unknown_column_at(WHERE("y"), "y", opt->y, table, err);
    if ((rc = phc_table_column_numbers(table, opt->x, &ds->x, err)) ||
        (rc = phc_table_column_numbers(table, opt->y, &ds->y, err)) || (rc = read_sigma(ds, table, opt, err)))
        return rc;
    ds->data_file = strdup(phc_table_source(table));
    ds->data_lines = malloc(ds->n * sizeof *ds->data_lines);
    if (!ds->data_file || !ds->data_lines)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < ds->n; ++i)
        ds->data_lines[i] = phc_table_row_line(table, i);
    ds->x_label = label_or(opt->x_label, opt->x);
    ds->y_label = label_or(opt->y_label, opt->y);
    if (!ds->x_label || !ds->y_label)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

int phc_curve_new(const phc_table *table, const phc_curve_options *opt,
                  phc_dataset **out, phc_error *err)
{
    phc_dataset *ds = NULL;
    curve_impl *c = NULL;
    char **slot_names = NULL;
    size_t n_slots = 0;
    int n_vars = 0;
    int rc;

    *out = NULL;
    if ((rc = check_options(table, opt, err)))
        return rc;
    if (!(c = calloc(1, sizeof *c))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    c->x_col = -1;
    if ((rc = parse_expression(c, opt, &n_vars, err)))
        goto fail;
    if (!(slot_names = calloc((size_t)n_vars, sizeof *slot_names))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    /* Exact derivatives when the expression stays within DESIGN.md's
     * grammar; otherwise muparser with numerical derivatives. */
    if ((rc = bind_names(c, table, opt, n_vars, slot_names, &n_slots, err)) ||
        (rc = bind_tape(c, opt->expression, (const char *const *)slot_names, n_slots, phc_table_rows(table),
                         err)))
        goto fail;
    if (!(ds = phc_dataset_new(&phc_curve_ops, n_slots))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->derivatives = c->tape ? PHC_DERIV_ANALYTIC : PHC_DERIV_CENTRAL;
    for (size_t j = 0; j < n_slots; ++j) {
        ds->slot_names[j] = slot_names[j];
        slot_names[j] = NULL;
    }
    if ((rc = read_observations(ds, table, opt, err)))
        goto fail;
    ds->impl = c;
    c = NULL;
    ds->config_line = phc_origin_line(opt->origin, NULL);
    *out = ds;
    ds = NULL;
fail:
    if (slot_names)
        for (size_t j = 0; j < n_slots; ++j)
            free(slot_names[j]);
    free(slot_names);
    phc_dataset_free(ds);
    curve_free(c);
    return rc;
}
