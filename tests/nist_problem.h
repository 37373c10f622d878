/* NIST StRD nonlinear regression problems as phytocal test cases.
 *
 * Header-only (every function is static) so that a test and a benchmark
 * program can both include it without a library.  It
 *   - reads a NIST .dat file (nist_load),
 *   - knows each model as a phytocal `curve` expression (nist_expression),
 *   - writes a CSV + YAML config pair that `phytocal fit` can run
 *     (nist_write_case),
 *   - scores a fitted value against the certified one by log relative error
 *     (nist_lre, as in Ceres examples/nist.cc).
 *
 * The .dat files are NIST's (https://www.itl.nist.gov/div898/strd/nls/),
 * kept in ../shared/data/nist; they are read in place and never copied into
 * this repository.  Layout relied on (see ../shared/data/README.md):
 *   - header line "Data  (lines A to B)" under "File Format:" gives the data
 *     lines (default: from line 61 to the end of the file);
 *   - "Model:" block, whose equation starts with "y =" or, for Nelson,
 *     "log[y] =";
 *   - rows "bN = start1 start2 certified certified_sd" (from line 41);
 *   - "Residual Sum of Squares:" and "Number of Observations:" lines;
 *   - data rows "y x" or, for Nelson, "y x1 x2".
 *
 * Response: for every problem except Nelson the fitted response is y.  Nelson
 * models log(y) = b1 - b2*x1*exp(-b3*x2), so nist_problem.response holds
 * log(y) and the CSV written by nist_write_case has a column `y` that holds
 * log(y), not the raw y of the .dat file (nist_problem.y keeps the raw
 * values).  The certified RSS of Nelson is on the log scale.
 *
 * Columns in the CSV and names in the expressions: `x` (one predictor) or
 * `x1`, `x2` (Nelson), and `y`.  Parameters are b1..bK as in NIST.  `pi` is
 * the constant defined by phytocal's expression parser (muparser's own name
 * for it is `_pi`).  Expressions are written so that no unary minus is
 * followed directly by `^` (muparser reads -a^b as -(a^b), as mathematics
 * does, but not every parser agrees), and NIST's `**` is `^`, `[..]` is
 * `(..)`, `arctan` is `atan`.
 *
 * Error reporting: functions return 0 on success, nonzero on failure with a
 * message "FILE:LINE: what" (or "FILE: what") in msg. */
#ifndef PHC_TESTS_NIST_PROBLEM_H
#define PHC_TESTS_NIST_PROBLEM_H

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
#define NIST_FUNC static __attribute__((unused))
#else
#define NIST_FUNC static
#endif

#define NIST_MAX_PARAMS 9   /* ENSO has the most: b1..b9 */
#define NIST_MAX_OBS 512    /* Gauss1-3 have the most: 250 */
#define NIST_NAME_SIZE 64

typedef struct nist_problem {
    char name[NIST_NAME_SIZE];     /* file stem as NIST spells it: "Misra1a" */
    char lower_name[NIST_NAME_SIZE]; /* lowercase stem, used for file names */
    char model[512];               /* the model equation lines, as in the file */
    int k;                         /* number of parameters */
    int n;                         /* number of observations */
    int nx;                        /* predictor columns: 1 (x) or 2 (x1, x2) */
    int response_log;              /* 1 when the model is for log(y) (Nelson) */
    double starts[2][NIST_MAX_PARAMS]; /* starting values: Start 1, Start 2 */
    double certified[NIST_MAX_PARAMS];
    double certified_sd[NIST_MAX_PARAMS];
    double certified_rss;          /* on the response scale (log y for Nelson) */
    double y[NIST_MAX_OBS];        /* y as in the file */
    double response[NIST_MAX_OBS]; /* fitted response: y, or log(y) for Nelson */
    double x[NIST_MAX_OBS];        /* x, or x1 for Nelson */
    double x2[NIST_MAX_OBS];       /* x2 for Nelson, else 0 */
} nist_problem;

/* ---- the 22 models ---------------------------------------------------------
 * Checked against the "Model:" text of each .dat file and, by
 * tests/unit/test_nist_problem.c, by evaluating the expression at the
 * certified values and comparing the residual sum of squares with NIST's. */
typedef struct nist_model {
    const char *name;       /* NIST's file stem */
    int k;                  /* parameters b1..bk */
    int nx;                 /* 1: column x; 2: columns x1, x2 */
    int response_log;       /* response column y holds log(y) */
    const char *expression; /* phytocal/muparser syntax */
} nist_model;

static const nist_model nist_models[] = {
    /* y = b1*(1-exp[-b2*x]) */
    {"BoxBOD", 2, 1, 0, "b1*(1-exp(-b2*x))"},
    /* y = exp[-b1*x]/(b2+b3*x) */
    {"Chwirut1", 3, 1, 0, "exp(-b1*x)/(b2+b3*x)"},
    {"Chwirut2", 3, 1, 0, "exp(-b1*x)/(b2+b3*x)"},
    /* y = b1*x**b2 */
    {"DanWood", 2, 1, 0, "b1*x^b2"},
    /* y = b1 + b2*cos(2*pi*x/12) + b3*sin(2*pi*x/12)
     *        + b5*cos(2*pi*x/b4) + b6*sin(2*pi*x/b4)
     *        + b8*cos(2*pi*x/b7) + b9*sin(2*pi*x/b7) */
    {"ENSO", 9, 1, 0,
     "b1 + b2*cos(2*pi*x/12) + b3*sin(2*pi*x/12)"
     " + b5*cos(2*pi*x/b4) + b6*sin(2*pi*x/b4)"
     " + b8*cos(2*pi*x/b7) + b9*sin(2*pi*x/b7)"},
    /* y = b1*exp(-b2*x) + b3*exp(-(x-b4)**2/b5**2) + b6*exp(-(x-b7)**2/b8**2) */
    {"Gauss1", 8, 1, 0,
     "b1*exp(-b2*x) + b3*exp(-((x-b4)^2)/b5^2) + b6*exp(-((x-b7)^2)/b8^2)"},
    {"Gauss2", 8, 1, 0,
     "b1*exp(-b2*x) + b3*exp(-((x-b4)^2)/b5^2) + b6*exp(-((x-b7)^2)/b8^2)"},
    {"Gauss3", 8, 1, 0,
     "b1*exp(-b2*x) + b3*exp(-((x-b4)^2)/b5^2) + b6*exp(-((x-b7)^2)/b8^2)"},
    /* y = (b1+b2*x+b3*x**2+b4*x**3) / (1+b5*x+b6*x**2+b7*x**3) */
    {"Hahn1", 7, 1, 0,
     "(b1 + b2*x + b3*x^2 + b4*x^3)/(1 + b5*x + b6*x^2 + b7*x^3)"},
    /* y = (b1 + b2*x + b3*x**2) / (1 + b4*x + b5*x**2) */
    {"Kirby2", 5, 1, 0, "(b1 + b2*x + b3*x^2)/(1 + b4*x + b5*x^2)"},
    /* y = b1*exp(-b2*x) + b3*exp(-b4*x) + b5*exp(-b6*x) */
    {"Lanczos1", 6, 1, 0, "b1*exp(-b2*x) + b3*exp(-b4*x) + b5*exp(-b6*x)"},
    {"Lanczos2", 6, 1, 0, "b1*exp(-b2*x) + b3*exp(-b4*x) + b5*exp(-b6*x)"},
    {"Lanczos3", 6, 1, 0, "b1*exp(-b2*x) + b3*exp(-b4*x) + b5*exp(-b6*x)"},
    /* y = b1*(x**2+x*b2) / (x**2+x*b3+b4) */
    {"MGH09", 4, 1, 0, "b1*(x^2 + x*b2)/(x^2 + x*b3 + b4)"},
    /* y = b1 + b2*exp[-x*b4] + b3*exp[-x*b5] */
    {"MGH17", 5, 1, 0, "b1 + b2*exp(-x*b4) + b3*exp(-x*b5)"},
    /* y = b1*(1-exp[-b2*x]) */
    {"Misra1a", 2, 1, 0, "b1*(1-exp(-b2*x))"},
    /* y = b1 * (1-(1+b2*x/2)**(-2)) */
    {"Misra1b", 2, 1, 0, "b1*(1-(1+b2*x/2)^(-2))"},
    /* y = b1 * (1-(1+2*b2*x)**(-.5)) */
    {"Misra1c", 2, 1, 0, "b1*(1-(1+2*b2*x)^(-0.5))"},
    /* y = b1*b2*x*((1+b2*x)**(-1)) */
    {"Misra1d", 2, 1, 0, "b1*b2*x*((1+b2*x)^(-1))"},
    /* log[y] = b1 - b2*x1 * exp[-b3*x2]   (response column y holds log(y)) */
    {"Nelson", 3, 2, 1, "b1 - b2*x1*exp(-b3*x2)"},
    /* y = b1 / (1+exp[b2-b3*x]) */
    {"Rat42", 3, 1, 0, "b1/(1+exp(b2-b3*x))"},
    /* y = b1 - b2*x - arctan[b3/(x-b4)]/pi */
    {"Roszman1", 4, 1, 0, "b1 - b2*x - atan(b3/(x-b4))/pi"},
};

#define NIST_MODEL_COUNT ((int)(sizeof nist_models / sizeof nist_models[0]))

NIST_FUNC int nist_strcaseeq(const char *a, const char *b)
{
    for (; *a && *b; ++a, ++b)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return 0;
    return *a == *b;
}

/* The model entry for a problem name (case-insensitive: "misra1a" works), or
 * NULL for a name that is not one of the 22. */
NIST_FUNC const nist_model *nist_find_model(const char *name)
{
    for (int i = 0; i < NIST_MODEL_COUNT; ++i)
        if (nist_strcaseeq(nist_models[i].name, name))
            return &nist_models[i];
    return NULL;
}

/* The model of problem `name` in phytocal's expression syntax, or NULL. */
NIST_FUNC const char *nist_expression(const char *name)
{
    const nist_model *m = nist_find_model(name);
    return m ? m->expression : NULL;
}

/* Nonzero when the CSV column `y` of problem `name` holds log(y) (Nelson). */
NIST_FUNC int nist_response_is_log(const char *name)
{
    const nist_model *m = nist_find_model(name);
    return m ? m->response_log : 0;
}

/* ---- reading a .dat file -------------------------------------------------- */

NIST_FUNC void nist_msg(char *msg, size_t size, const char *fmt, ...)
{
    if (!msg || size == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, size, fmt, ap);
    va_end(ap);
}

/* Parses up to `max` whitespace-separated numbers from s; returns how many,
 * or -1 when a field is not a finite number. */
NIST_FUNC int nist_numbers(const char *s, double *out, int max)
{
    int count = 0;
    for (;;) {
        while (isspace((unsigned char)*s))
            ++s;
        if (!*s)
            return count;
        if (count == max)
            return -1;
        char *end;
        errno = 0;
        double v = strtod(s, &end);
        if (end == s || errno == ERANGE || !isfinite(v) ||
            (*end && !isspace((unsigned char)*end)))
            return -1;
        out[count++] = v;
        s = end;
    }
}

NIST_FUNC int nist_blank(const char *s)
{
    while (isspace((unsigned char)*s))
        ++s;
    return *s == '\0';
}

/* Reads the NIST .dat file at dat_path into *p.  Checks: the parameters are
 * b1..bK in order with 4 numbers each; the data rows are all 2 or all 3
 * numbers; their count equals "Number of Observations"; the RSS line exists;
 * K matches "N Parameters" of the model block; the name is one of the 22 and
 * K and the number of predictors agree with nist_models; log(y) needs y > 0. */
NIST_FUNC int nist_load(const char *dat_path, nist_problem *p, char *msg,
                        size_t msg_size)
{
    memset(p, 0, sizeof *p);
    nist_msg(msg, msg_size, "%s", "");

    /* name: file stem */
    const char *base = strrchr(dat_path, '/');
    base = base ? base + 1 : dat_path;
    size_t len = strcspn(base, ".");
    if (len == 0 || len >= NIST_NAME_SIZE) {
        nist_msg(msg, msg_size, "%s: cannot take a problem name from the file name",
                 dat_path);
        return 1;
    }
    memcpy(p->name, base, len);
    p->name[len] = '\0';
    for (size_t i = 0; i <= len; ++i)
        p->lower_name[i] = (char)tolower((unsigned char)p->name[i]);
    const nist_model *model = nist_find_model(p->name);
    if (!model) {
        nist_msg(msg, msg_size, "%s: '%s' is not one of the 22 NIST problems known "
                 "to nist_problem.h", dat_path, p->name);
        return 1;
    }

    FILE *f = fopen(dat_path, "r");
    if (!f) {
        nist_msg(msg, msg_size, "%s: cannot open: %s", dat_path, strerror(errno));
        return 1;
    }

    char line[1024];
    long lineno = 0;
    long data_first = 61, data_last = -1; /* from "Data (lines A to B)" */
    long n_declared = -1, k_declared = -1;
    int have_rss = 0, in_model = 0, ncols = 0, status = 0;

    while (fgets(line, sizeof line, f)) {
        ++lineno;
        size_t l = strlen(line);
        if (l == sizeof line - 1 && line[l - 1] != '\n') {
            nist_msg(msg, msg_size, "%s:%ld: line too long", dat_path, lineno);
            status = 1;
            break;
        }
        while (l > 0 && (line[l - 1] == '\n' || line[l - 1] == '\r'))
            line[--l] = '\0';

        if (lineno < data_first) {
            const char *s = line;
            while (isspace((unsigned char)*s))
                ++s;
            long a, b;
            const char *q;
            if (lineno < 20 && strncmp(s, "Data", 4) == 0 &&
                (q = strstr(s, "(lines")) && sscanf(q, "(lines %ld to %ld)", &a, &b) == 2) {
                data_first = a;
                data_last = b;
            } else if (strncmp(s, "Model:", 6) == 0) {
                /* "Model:  Exponential Class", then "2 Parameters (b1 and b2)",
                 * then the equation lines up to "Starting values" */
                in_model = 1;
            } else if (in_model) {
                if (k_declared < 0 && strstr(s, "Parameters"))
                    sscanf(s, "%ld Parameters", &k_declared);
                else if (strncmp(s, "Starting", 8) == 0)
                    in_model = 0;
                else if (!nist_blank(s) && !strstr(s, "Parameters")) {
                    size_t used = strlen(p->model), add = strlen(s);
                    if (used + add + 2 < sizeof p->model) {
                        if (used)
                            p->model[used++] = '\n';
                        memcpy(p->model + used, s, add + 1);
                    }
                    if (strncmp(s, "log[y]", 6) == 0)
                        p->response_log = 1;
                }
            } else if (s[0] == 'b' && isdigit((unsigned char)s[1])) {
                char *end;
                long idx = strtol(s + 1, &end, 10);
                while (isspace((unsigned char)*end))
                    ++end;
                if (*end != '=') {
                    nist_msg(msg, msg_size, "%s:%ld: expected 'bN = ...'", dat_path, lineno);
                    status = 1;
                    break;
                }
                double v[4];
                if (idx != p->k + 1 || idx > NIST_MAX_PARAMS ||
                    nist_numbers(end + 1, v, 4) != 4) {
                    nist_msg(msg, msg_size, "%s:%ld: expected 'b%d = start1 start2 "
                             "certified certified_sd'", dat_path, lineno, p->k + 1);
                    status = 1;
                    break;
                }
                p->starts[0][p->k] = v[0];
                p->starts[1][p->k] = v[1];
                p->certified[p->k] = v[2];
                p->certified_sd[p->k] = v[3];
                ++p->k;
            } else if (strncmp(s, "Residual Sum of Squares:", 24) == 0) {
                double v;
                if (nist_numbers(s + 24, &v, 1) != 1) {
                    nist_msg(msg, msg_size, "%s:%ld: expected a number after "
                             "'Residual Sum of Squares:'", dat_path, lineno);
                    status = 1;
                    break;
                }
                p->certified_rss = v;
                have_rss = 1;
            } else if (strncmp(s, "Number of Observations:", 23) == 0) {
                n_declared = strtol(s + 23, NULL, 10);
            }
            continue;
        }
        if (data_last > 0 && lineno > data_last) {
            if (!nist_blank(line)) {
                nist_msg(msg, msg_size, "%s:%ld: text after the data lines %ld to %ld",
                         dat_path, lineno, data_first, data_last);
                status = 1;
                break;
            }
            continue;
        }
        if (nist_blank(line))
            continue;
        double v[3];
        int c = nist_numbers(line, v, 3);
        if (c < 2 || (ncols && c != ncols)) {
            nist_msg(msg, msg_size, "%s:%ld: expected %s numbers, found '%s'", dat_path,
                     lineno, ncols == 3 ? "3" : ncols == 2 ? "2" : "2 or 3", line);
            status = 1;
            break;
        }
        ncols = c;
        if (p->n == NIST_MAX_OBS) {
            nist_msg(msg, msg_size, "%s:%ld: more than NIST_MAX_OBS = %d data rows",
                     dat_path, lineno, NIST_MAX_OBS);
            status = 1;
            break;
        }
        p->y[p->n] = v[0];
        p->x[p->n] = v[1];
        p->x2[p->n] = c == 3 ? v[2] : 0.0;
        ++p->n;
    }
    if (!status && ferror(f)) {
        nist_msg(msg, msg_size, "%s: read error: %s", dat_path, strerror(errno));
        status = 1;
    }
    fclose(f);
    if (status)
        return status;

    if (p->k == 0) {
        nist_msg(msg, msg_size, "%s: no 'bN = ...' parameter rows before line %ld",
                 dat_path, data_first);
        return 1;
    }
    if (k_declared >= 0 && k_declared != p->k) {
        nist_msg(msg, msg_size, "%s: the model declares %ld parameters, found %d rows",
                 dat_path, k_declared, p->k);
        return 1;
    }
    if (!have_rss) {
        nist_msg(msg, msg_size, "%s: no 'Residual Sum of Squares:' line", dat_path);
        return 1;
    }
    if (p->n == 0) {
        nist_msg(msg, msg_size, "%s: no data rows from line %ld", dat_path, data_first);
        return 1;
    }
    if (n_declared >= 0 && n_declared != p->n) {
        nist_msg(msg, msg_size, "%s: 'Number of Observations: %ld' but %d data rows",
                 dat_path, n_declared, p->n);
        return 1;
    }
    p->nx = ncols - 1;
    if (model->k != p->k || model->nx != p->nx || model->response_log != p->response_log) {
        nist_msg(msg, msg_size, "%s: file has %d parameters, %d predictors%s; "
                 "nist_models has %d, %d%s", dat_path, p->k, p->nx,
                 p->response_log ? ", log[y] response" : "", model->k, model->nx,
                 model->response_log ? ", log[y] response" : "");
        return 1;
    }
    for (int i = 0; i < p->n; ++i) {
        if (p->response_log) {
            if (!(p->y[i] > 0)) {
                nist_msg(msg, msg_size, "%s: data row %d: log[y] needs y > 0, found %g",
                         dat_path, i + 1, p->y[i]);
                return 1;
            }
            p->response[i] = log(p->y[i]);
        } else {
            p->response[i] = p->y[i];
        }
    }
    return 0;
}

/* ---- writing a phytocal case ---------------------------------------------- */

/* Writes DIR/<name>.csv (header "x,y" or, for Nelson, "x1,x2,y"; y is the
 * response, log(y) for Nelson; numbers with %.17g so they read back exactly)
 * and DIR/<name>-start<start>.yaml, a `curve` config with the NIST starting
 * values (%.17g, no bounds).  <name> is the lowercase problem name.  For
 * Nelson the config says `x: x1` and its expression also names the column
 * x2 (the expression syntax accepts any column name).  DIR
 * must exist.  The path of the config is copied to config_path_out (when not
 * NULL).  start is 1 or 2. */
NIST_FUNC int nist_write_case(const nist_problem *p, int start, const char *dir,
                              char *config_path_out, size_t size, char *msg,
                              size_t msg_size)
{
    nist_msg(msg, msg_size, "%s", "");
    const char *expr = nist_expression(p->name);
    if (!expr) {
        nist_msg(msg, msg_size, "%s: no expression for this problem", p->name);
        return 1;
    }
    if (start != 1 && start != 2) {
        nist_msg(msg, msg_size, "%s: start must be 1 or 2, not %d", p->name, start);
        return 1;
    }
    char csv_path[4096], yaml_path[4096];
    int w1 = snprintf(csv_path, sizeof csv_path, "%s/%s.csv", dir, p->lower_name);
    int w2 = snprintf(yaml_path, sizeof yaml_path, "%s/%s-start%d.yaml", dir,
                      p->lower_name, start);
    if (w1 < 0 || w2 < 0 || (size_t)w1 >= sizeof csv_path ||
        (size_t)w2 >= sizeof yaml_path) {
        nist_msg(msg, msg_size, "%s: path too long", dir);
        return 1;
    }
    if (config_path_out && size > 0) {
        if ((size_t)w2 >= size) {
            nist_msg(msg, msg_size, "%s: config path does not fit in %zu bytes",
                     yaml_path, size);
            return 1;
        }
        memcpy(config_path_out, yaml_path, (size_t)w2 + 1);
    }

    FILE *f = fopen(csv_path, "w");
    if (!f) {
        nist_msg(msg, msg_size, "%s: cannot create: %s", csv_path, strerror(errno));
        return 1;
    }
    fputs(p->nx == 2 ? "x1,x2,y\n" : "x,y\n", f);
    for (int i = 0; i < p->n; ++i) {
        if (p->nx == 2)
            fprintf(f, "%.17g,%.17g,%.17g\n", p->x[i], p->x2[i], p->response[i]);
        else
            fprintf(f, "%.17g,%.17g\n", p->x[i], p->response[i]);
    }
    if (ferror(f) | fclose(f)) {
        nist_msg(msg, msg_size, "%s: write error: %s", csv_path, strerror(errno));
        return 1;
    }

    f = fopen(yaml_path, "w");
    if (!f) {
        nist_msg(msg, msg_size, "%s: cannot create: %s", yaml_path, strerror(errno));
        return 1;
    }
    fprintf(f, "name: %s-start%d\n", p->lower_name, start);
    fputs("parameters:\n", f);
    for (int j = 0; j < p->k; ++j)
        fprintf(f, "  b%d: {value: %.17g}\n", j + 1, p->starts[start - 1][j]);
    fputs("datasets:\n", f);
    fputs("  - kind: curve\n", f);
    fprintf(f, "    file: %s.csv\n", p->lower_name);
    fprintf(f, "    x: %s\n", p->nx == 2 ? "x1" : "x");
    fputs("    y: y\n", f);
    fprintf(f, "    expression: \"%s\"\n", expr);
    if (ferror(f) | fclose(f)) {
        nist_msg(msg, msg_size, "%s: write error: %s", yaml_path, strerror(errno));
        return 1;
    }
    return 0;
}

/* ---- scoring -------------------------------------------------------------- */

/* Log relative error (number of matching significant digits), as in Ceres
 * examples/nist.cc: -log10(|computed - certified| / |certified|), or the
 * absolute error -log10(|computed|) when certified is 0.  Capped to [0, 11]:
 * NIST certifies 11 digits, so an exact match scores 11; a NaN scores 0. */
NIST_FUNC double nist_lre(double computed, double certified)
{
    double err = fabs(computed - certified);
    if (certified != 0.0)
        err /= fabs(certified);
    if (isnan(err))
        return 0.0;
    if (err == 0.0)
        return 11.0;
    double lre = -log10(err);
    if (lre > 11.0)
        return 11.0;
    if (lre < 0.0)
        return 0.0;
    return lre;
}

/* The smallest nist_lre over the K parameters of p for the fitted values b. */
NIST_FUNC double nist_min_lre(const nist_problem *p, const double *b)
{
    double m = 11.0;
    for (int j = 0; j < p->k; ++j) {
        double l = nist_lre(b[j], p->certified[j]);
        if (l < m)
            m = l;
    }
    return m;
}

#endif /* PHC_TESTS_NIST_PROBLEM_H */
