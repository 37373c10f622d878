/* Automatic differentiation of curve expressions: see expression.h.
 *
 * The expression becomes a list of nodes in evaluation order (children
 * before parents).  A forward sweep computes each node's value and its
 * local partial derivatives; a reverse sweep accumulates adjoints from the
 * root to the parameter slots (reverse-mode AD), skipping nodes that depend
 * on no slot (data columns, constants). */
/* sincos (glibc): see sin_cos below */
#define _GNU_SOURCE
#include "fit/costs/expression.h"

#include <ctype.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/c_number.h"

typedef enum op {
    OP_CONST, OP_NAME, OP_NEG, OP_ADD, OP_SUB, OP_MUL, OP_DIV, OP_POW,
    OP_EXP, OP_LOG, OP_SQRT, OP_SIN, OP_COS, OP_TAN, OP_ATAN, OP_ABS
} op;

typedef struct node {
    op op;
    size_t a, b;      /* children (node indices) */
    double value;     /* OP_CONST */
    size_t name;      /* OP_NAME: index into names */
    int active;       /* depends on a slot */
    /* with the data bound (phc_expr_bind_data): */
    int hoisted;      /* the root of a largest subtree that depends on no
                         slot and is more than a constant or a column: its
                         values are computed once per row (pre) */
    int inside;       /* below a hoisted node: not evaluated */
    size_t pre;       /* hoisted: its row in pre */
} node;

struct phc_expr {
    node *nodes;
    size_t n_nodes, cap;
    char **names;
    size_t n_names;
    int *is_slot;     /* per name */
    size_t *index;    /* per name: slot or column */
    int *bound;
    size_t n_slots;
    double *rows;     /* 4 x n_nodes x PHC_EXPR_ROWS: values, partials to
                         child a and b, adjoints per node and row (prepare) */
    const double **row_cols; /* n_cols: phc_expr_eval's one row as columns */
    size_t n_cols;    /* 1 + the largest column a name is bound to (0: none) */
    /* the bound data (phc_expr_bind_data): n_cols columns of data_n rows and
     * the hoisted nodes' values, n_hoisted x data_n */
    const double **data_cols;
    size_t data_n, n_hoisted;
    double *pre;
};

typedef struct parser {
    const char *s;
    size_t pos;
    phc_expr *e;
    phc_error *err;
    size_t err_pos;
    int failed;
    int depth;  /* nesting of parse_unary: parentheses, function calls, signs, powers */
} parser;

/* Deeper nesting is refused: the recursive descent would otherwise run out
 * of stack (about 6,000 nested parentheses under a 2 MiB stack). */
#define PHC_EXPR_MAX_DEPTH 200

static const struct {
    const char *name;
    op op;
} functions[] = {{"exp", OP_EXP}, {"log", OP_LOG}, {"ln", OP_LOG}, {"sqrt", OP_SQRT}, {"sin", OP_SIN},
                 {"cos", OP_COS}, {"tan", OP_TAN}, {"atan", OP_ATAN}, {"abs", OP_ABS}};

static int fail_at(parser *p, size_t pos, const char *what)
{
    if (!p->failed) {
        p->failed = 1;
        p->err_pos = pos;
        phc_error_set(p->err, PHC_ERR_INPUT, "%s at character %zu", what, pos + 1);
    }
    return -1;
}

static long add_node(parser *p, node n)
{
    phc_expr *e = p->e;
    if (e->n_nodes == e->cap) {
        size_t cap = e->cap ? 2 * e->cap : 32;
        node *grown = realloc(e->nodes, cap * sizeof *grown);
        if (!grown) {
            p->failed = 1;
            phc_error_set(p->err, PHC_ERR_NOMEM, "out of memory");
            return -1;
        }
        e->nodes = grown;
        e->cap = cap;
    }
    e->nodes[e->n_nodes] = n;
    return (long)e->n_nodes++;
}

static void skip_space(parser *p)
{
    while (isspace((unsigned char)p->s[p->pos]))
        p->pos++;
}

static long parse_expr(parser *p);
static long parse_unary(parser *p);

static long binary(parser *p, op o, long a, long b)
{
    if (a < 0 || b < 0)
        return -1;
    node n = {o, (size_t)a, (size_t)b, 0, 0, 0, 0, 0, 0};
    return add_node(p, n);
}

static long unary_node(parser *p, op o, long a)
{
    if (a < 0)
        return -1;
    node n = {o, (size_t)a, 0, 0, 0, 0, 0, 0, 0};
    return add_node(p, n);
}

static long name_node(parser *p, const char *name, size_t len)
{
    phc_expr *e = p->e;
    size_t i;
    for (i = 0; i < e->n_names; ++i)
        if (strlen(e->names[i]) == len && strncmp(e->names[i], name, len) == 0)
            break;
    if (i == e->n_names) {
        char **grown = realloc(e->names, (e->n_names + 1) * sizeof *grown);
        if (!grown)
            return fail_at(p, p->pos, "out of memory");
        e->names = grown;
        e->names[e->n_names] = strndup(name, len);
        if (!e->names[e->n_names])
            return fail_at(p, p->pos, "out of memory");
        e->n_names++;
    }
    node n = {OP_NAME, 0, 0, 0, i, 0, 0, 0, 0};
    return add_node(p, n);
}

static long parse_primary(parser *p)
{
    skip_space(p);
    const char *s = p->s;
    const size_t start = p->pos;
    const char c = s[start];
    if (c == '(') {
        p->pos++;
        long inner = parse_expr(p);
        skip_space(p);
        if (inner < 0)
            return -1;
        if (s[p->pos] != ')')
            return fail_at(p, p->pos, "expected ')'");
        p->pos++;
        return inner;
    }
    if (isdigit((unsigned char)c) || (c == '.' && isdigit((unsigned char)s[start + 1]))) {
        size_t end = start;
        while (isdigit((unsigned char)s[end]))
            end++;
        if (s[end] == '.') { /* one decimal point: "1.2.3" is an error below */
            end++;
            while (isdigit((unsigned char)s[end]))
                end++;
        }
        if ((s[end] == 'e' || s[end] == 'E') &&
            (isdigit((unsigned char)s[end + 1]) ||
             ((s[end + 1] == '+' || s[end + 1] == '-') && isdigit((unsigned char)s[end + 2])))) {
            end += 2;
            while (isdigit((unsigned char)s[end]))
                end++;
        }
        char buf[64];
        if (end - start >= sizeof buf)
            return fail_at(p, start, "number too long");
        memcpy(buf, s + start, end - start);
        buf[end - start] = '\0';
        const double v = phc_strtod_c(buf, NULL);
        p->pos = end;
        node n = {OP_CONST, 0, 0, v, 0, 0, 0, 0, 0};
        return add_node(p, n);
    }
    if (isalpha((unsigned char)c) || c == '_') {
        size_t end = start;
        while (isalnum((unsigned char)s[end]) || s[end] == '_')
            end++;
        const size_t len = end - start;
        p->pos = end;
        skip_space(p);
        if (s[p->pos] == '(') {
            for (size_t f = 0; f < sizeof functions / sizeof functions[0]; ++f)
                if (strlen(functions[f].name) == len && strncmp(functions[f].name, s + start, len) == 0) {
                    p->pos++;
                    long arg = parse_expr(p);
                    skip_space(p);
                    if (arg < 0)
                        return -1;
                    if (s[p->pos] != ')')
                        return fail_at(p, p->pos, "expected ')' after the function argument");
                    p->pos++;
                    return unary_node(p, functions[f].op, arg);
                }
            return fail_at(p, start, "function not supported for exact derivatives");
        }
        if ((len == 2 && strncmp(s + start, "pi", 2) == 0) || (len == 3 && strncmp(s + start, "_pi", 3) == 0)) {
            node n = {OP_CONST, 0, 0, 3.14159265358979323846, 0, 0, 0, 0, 0};
            return add_node(p, n);
        }
        if (len == 2 && strncmp(s + start, "_e", 2) == 0) {
            node n = {OP_CONST, 0, 0, 2.71828182845904523536, 0, 0, 0, 0, 0};
            return add_node(p, n);
        }
        return name_node(p, s + start, len);
    }
    return fail_at(p, start, c ? "unexpected character" : "unexpected end of expression");
}

/* power := primary ('^' unary)?  -- right-associative, binds tighter than unary minus */
static long parse_power(parser *p)
{
    long base = parse_primary(p);
    if (base < 0)
        return -1;
    skip_space(p);
    if (p->s[p->pos] == '^') {
        p->pos++;
        long expo = parse_unary(p);
        return binary(p, OP_POW, base, expo);
    }
    return base;
}

static long parse_unary_nested(parser *p)
{
    skip_space(p);
    const char c = p->s[p->pos];
    if (c == '-') {
        p->pos++;
        return unary_node(p, OP_NEG, parse_unary(p));
    }
    if (c == '+') {
        p->pos++;
        return parse_unary(p);
    }
    return parse_power(p);
}

static long parse_unary(parser *p)
{
    if (p->depth >= PHC_EXPR_MAX_DEPTH) {
        fail_at(p, p->pos, "nested more than 200 levels deep (parentheses, function calls, "
                           "signs and powers together); split it or simplify it");
        if (p->err)
            p->err->status = PHC_ERR_DOMAIN; /* a limit, not a syntax error (expression.h) */
        return -1;
    }
    p->depth++;
    const long r = parse_unary_nested(p);
    p->depth--;
    return r;
}

static long parse_term(parser *p)
{
    long left = parse_unary(p);
    for (;;) {
        if (left < 0)
            return -1;
        skip_space(p);
        const char c = p->s[p->pos];
        if (c != '*' && c != '/')
            return left;
        p->pos++;
        left = binary(p, c == '*' ? OP_MUL : OP_DIV, left, parse_unary(p));
    }
}

static long parse_expr(parser *p)
{
    long left = parse_term(p);
    for (;;) {
        if (left < 0)
            return -1;
        skip_space(p);
        const char c = p->s[p->pos];
        if (c != '+' && c != '-')
            return left;
        p->pos++;
        left = binary(p, c == '+' ? OP_ADD : OP_SUB, left, parse_term(p));
    }
}

void phc_expr_free(phc_expr *e)
{
    if (!e)
        return;
    for (size_t i = 0; i < e->n_names; ++i)
        free(e->names[i]);
    free(e->names);
    free(e->nodes);
    free(e->is_slot);
    free(e->index);
    free(e->bound);
    free(e->rows);
    free(e->row_cols);
    free(e->data_cols);
    free(e->pre);
    free(e);
}

int phc_expr_compile(const char *text, phc_expr **out, size_t *pos, phc_error *err)
{
    *out = NULL;
    phc_expr *e = calloc(1, sizeof *e);
    if (!e)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    parser p = {text, 0, e, err, 0, 0, 0};
    long root = parse_expr(&p);
    skip_space(&p);
    if (root >= 0 && text[p.pos] != '\0')
        fail_at(&p, p.pos, "unexpected text after the expression");
    if (p.failed || root < 0 || (size_t)root != e->n_nodes - 1) {
        if (pos)
            *pos = p.err_pos;
        if (!p.failed)
            phc_error_set(err, PHC_ERR_INPUT, "cannot compile the expression");
        int status = err ? err->status : PHC_ERR_INPUT;
        phc_expr_free(e);
        return status ? status : PHC_ERR_INPUT;
    }
    e->is_slot = calloc(e->n_names + 1, sizeof *e->is_slot);
    e->index = calloc(e->n_names + 1, sizeof *e->index);
    e->bound = calloc(e->n_names + 1, sizeof *e->bound);
    if (!e->is_slot || !e->index || !e->bound) {
        phc_expr_free(e);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *out = e;
    return PHC_OK;
}

size_t phc_expr_name_count(const phc_expr *e)
{
    return e->n_names;
}

const char *phc_expr_name(const phc_expr *e, size_t i)
{
    return i < e->n_names ? e->names[i] : NULL;
}

int phc_expr_bind(phc_expr *e, size_t i, int is_slot, size_t index)
{
    if (i >= e->n_names)
        return PHC_ERR_INVALID;
    e->is_slot[i] = is_slot;
    e->index[i] = index;
    e->bound[i] = 1;
    return PHC_OK;
}

int phc_expr_prepare(phc_expr *e, size_t n_slots, phc_error *err)
{
    for (size_t i = 0; i < e->n_names; ++i) {
        if (!e->bound[i])
            return phc_error_set(err, PHC_ERR_INVALID, "expression name '%s' is not bound", e->names[i]);
        if (e->is_slot[i] && e->index[i] >= n_slots)
            return phc_error_set(err, PHC_ERR_INVALID, "slot %zu out of range", e->index[i]);
    }
    e->n_slots = n_slots;
    e->n_cols = 0;
    for (size_t i = 0; i < e->n_names; ++i)
        if (!e->is_slot[i] && e->index[i] + 1 > e->n_cols)
            e->n_cols = e->index[i] + 1;
    free(e->rows);
    free(e->row_cols);
    free(e->data_cols);
    free(e->pre);
    e->data_cols = NULL;
    e->pre = NULL;
    e->data_n = e->n_hoisted = 0;
    e->rows = malloc(4 * e->n_nodes * PHC_EXPR_ROWS * sizeof *e->rows);
    e->row_cols = malloc((e->n_cols ? e->n_cols : 1) * sizeof *e->row_cols);
    if (!e->rows || !e->row_cols)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < e->n_nodes; ++i) {
        node *n = &e->nodes[i];
        switch (n->op) {
        case OP_CONST: n->active = 0; break;
        case OP_NAME: n->active = e->is_slot[n->name]; break;
        case OP_ADD:
        case OP_SUB:
        case OP_MUL:
        case OP_DIV:
        case OP_POW: n->active = e->nodes[n->a].active || e->nodes[n->b].active; break;
        default: n->active = e->nodes[n->a].active; break;
        }
    }
    return PHC_OK;
}

double phc_expr_eval(phc_expr *e, const double *slots, const double *row, double *grad)
{
    /* one row is a block of one: the same code, so the same numbers as in
     * blocks by construction */
    for (size_t c = 0; c < e->n_cols; ++c)
        e->row_cols[c] = row + c;
    double value;
    if (phc_expr_eval_rows(e, slots, e->row_cols, 1, &value, grad, e->n_slots) != PHC_OK)
        return NAN;
    return value;
}

/* sin(a) and cos(a) bitwise as sin() and cos() give them.  glibc's sincos
 * (since 2.26 the range reduction and polynomials of its sin and cos,
 * sysdeps/ieee754/dbl-64/s_sincos.c) reduces the argument and sets the
 * rounding mode once for both; checked against sin and cos on 4e7
 * arguments (random bit patterns, |a| < 4, 100 and 5e5): no bit differs. */
static void sin_cos(double a, double *s, double *c)
{
#ifdef __GLIBC__
    sincos(a, s, c);
#else
    *s = sin(a);
    *c = cos(a);
#endif
}

/* The forward sweep at node i over a block of n_rows rows: its value into
 * V (e->rows), and with_partials its local partials towards its active
 * children into PA and PB when the node is active (only what the reverse
 * sweep reads: nothing for a value alone).  Slots and columns as for
 * phc_expr_eval_rows; slots may be NULL for a node that depends on none. */
/* inlined into its three callers: their node loops then keep the work
 * space's pointers in registers instead of a call per node and block */
static inline __attribute__((always_inline)) void forward_node(const phc_expr *e, size_t i, const double *slots,
                                                              const double *const *cols, size_t n_rows,
                                                              int with_partials)
{
    enum { B = PHC_EXPR_ROWS };
    const size_t nn = e->n_nodes;
    const node *nodes = e->nodes, *n = &nodes[i];
    double *V = e->rows, *PA = V + nn * B, *PB = PA + nn * B;
    double *v = V + i * B, *pa = PA + i * B, *pb = PB + i * B;
    const double *va = V + n->a * B, *vb = V + n->b * B;
    /* the partials towards child a and b are wanted */
    const int da = with_partials && n->active && nodes[n->a].active;
    const int db = with_partials && n->active && nodes[n->b].active;
    switch (n->op) {
    case OP_CONST:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = n->value;
        break;
    case OP_NAME:
        if (e->is_slot[n->name]) {
            const double x = slots[e->index[n->name]];
            for (size_t r = 0; r < n_rows; ++r)
                v[r] = x;
        } else {
            const double *col = cols[e->index[n->name]];
            for (size_t r = 0; r < n_rows; ++r)
                v[r] = col[r];
        }
        break;
    case OP_NEG:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = -va[r];
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = -1;
        break;
    case OP_ADD:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = va[r] + vb[r];
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = 1;
        if (db)
            for (size_t r = 0; r < n_rows; ++r)
                pb[r] = 1;
        break;
    case OP_SUB:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = va[r] - vb[r];
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = 1;
        if (db)
            for (size_t r = 0; r < n_rows; ++r)
                pb[r] = -1;
        break;
    case OP_MUL:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = va[r] * vb[r];
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = vb[r];
        if (db)
            for (size_t r = 0; r < n_rows; ++r)
                pb[r] = va[r];
        break;
    case OP_DIV:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = va[r] / vb[r];
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = 1 / vb[r];
        if (db)
            for (size_t r = 0; r < n_rows; ++r)
                pb[r] = -v[r] / vb[r];
        break;
    case OP_POW: {
        const int b_active = nodes[n->b].active;
        for (size_t r = 0; r < n_rows; ++r) {
            const double a = va[r], b = vb[r];
            double q, dqa = 0, dqb = 0;
            if (!b_active && b == 2) {
                q = a * a;
                dqa = 2 * a;
            } else if (!b_active && b == 3) {
                q = a * a * a;
                dqa = 3 * a * a;
            } else {
                q = pow(a, b);
                if (da)
                    dqa = b == 0 ? 0 : (a != 0 ? b * q / a : b * pow(a, b - 1));
                if (db)
                    dqb = a == 0 && b > 0 ? 0 : q * log(a);
            }
            v[r] = q;
            if (da)
                pa[r] = dqa;
            if (db)
                pb[r] = dqb;
        }
        break;
    }
    case OP_EXP:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = exp(va[r]);
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = v[r];
        break;
    case OP_LOG:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = log(va[r]);
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = 1 / va[r];
        break;
    case OP_SQRT:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = sqrt(va[r]);
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = 0.5 / v[r];
        break;
    case OP_SIN:
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                sin_cos(va[r], &v[r], &pa[r]);
        else
            for (size_t r = 0; r < n_rows; ++r)
                v[r] = sin(va[r]);
        break;
    case OP_COS:
        if (da)
            for (size_t r = 0; r < n_rows; ++r) {
                double sn;
                sin_cos(va[r], &sn, &v[r]);
                pa[r] = -sn;
            }
        else
            for (size_t r = 0; r < n_rows; ++r)
                v[r] = cos(va[r]);
        break;
    case OP_TAN:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = tan(va[r]);
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = 1 + v[r] * v[r];
        break;
    case OP_ATAN:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = atan(va[r]);
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = 1 / (1 + va[r] * va[r]);
        break;
    case OP_ABS:
        for (size_t r = 0; r < n_rows; ++r)
            v[r] = fabs(va[r]);
        if (da)
            for (size_t r = 0; r < n_rows; ++r)
                pa[r] = va[r] > 0 ? 1 : (va[r] < 0 ? -1 : 0);
        break;
    }
}

/* A child's adjoint from its parent's adjoint adj and the parent's partial
 * p towards it (see reverse_sweep): three different rows of the work
 * space, so the loop vectorises. */
static inline void child_adjoint(double *restrict out, const double *restrict p, const double *restrict adj,
                                 size_t n_rows)
{
    for (size_t r = 0; r < n_rows; ++r) {
        const double w = adj[r], t = p[r] * w; /* t unused when w is 0 */
        out[r] = 0.0 + (w != 0 ? t : -0.0);
    }
}

/* The reverse sweep over the block (forward_node with partials done for
 * every node the root depends on): the n_slots derivatives of each row
 * into grad + r * grad_stride.  Adjoints accumulate in reverse node order
 * (one pass gives all n_slots derivatives, so a Jacobian row costs about
 * twice a value); only active nodes (those that depend on a slot) take
 * part: a node's adjoint receives the same contributions in the same order
 * as if every partial were computed (an inactive child's adjoint is never
 * read). */
static void reverse_sweep(phc_expr *e, size_t n_rows, double *grad, size_t grad_stride)
{
    enum { B = PHC_EXPR_ROWS };
    const size_t nn = e->n_nodes, root = nn - 1;
    const node *nodes = e->nodes;
    double *PA = e->rows + nn * B, *PB = PA + nn * B, *ADJ = PB + nn * B;
    if (grad_stride == e->n_slots)
        memset(grad, 0, n_rows * e->n_slots * sizeof *grad);
    else
        for (size_t r = 0; r < n_rows; ++r)
            memset(grad + r * grad_stride, 0, e->n_slots * sizeof *grad);
    if (!nodes[root].active)
        return; /* depends on no slot */
    for (size_t r = 0; r < n_rows; ++r)
        ADJ[root * B + r] = 1.0;
    for (size_t i = root + 1; i-- > 0;) {
        const node *n = &nodes[i];
        if (!n->active)
            continue;
        const double *adj = ADJ + i * B, *pa = PA + i * B, *pb = PB + i * B;
        double *adja = ADJ + n->a * B, *adjb = ADJ + n->b * B;
        switch (n->op) {
        case OP_CONST: break;
        /* A zero adjoint adds nothing (not even 0 x inf = NaN from a
         * partial at a singular point): it adds -0.0, for which x + -0.0
         * is x for every x (signed zeros included), so the loops need no
         * branch and vectorise.  A node other than a name has one parent
         * (the parser never shares a node), so its adjoint receives exactly
         * one contribution, from its parent, before it is read: written as
         * 0 + contribution (the sum into an adjoint set to 0, a -0
         * contribution giving +0 as that sum does) instead of zeroing every
         * adjoint first. */
        case OP_NAME: {
            const size_t slot = e->index[n->name];
            for (size_t r = 0; r < n_rows; ++r) {
                const double w = adj[r];
                grad[r * grad_stride + slot] += w != 0 ? w : -0.0;
            }
            break;
        }
        case OP_ADD:
        case OP_SUB:
        case OP_MUL:
        case OP_DIV:
        case OP_POW:
            if (nodes[n->a].active)
                child_adjoint(adja, pa, adj, n_rows);
            if (nodes[n->b].active)
                child_adjoint(adjb, pb, adj, n_rows);
            break;
        default:
            child_adjoint(adja, pa, adj, n_rows);
            break;
        }
    }
}

/* Node by node over a block of rows: the interpreter's dispatch (switch,
 * child look-ups) is paid once per node and block instead of once per node
 * and row; each row sees the same operations in the same order whatever
 * the block, so the numbers do not depend on how the rows are blocked. */
int phc_expr_eval_rows(phc_expr *e, const double *slots, const double *const *cols, size_t n_rows, double *value,
                       double *grad, size_t grad_stride)
{
    enum { B = PHC_EXPR_ROWS };
    if (n_rows > B || !e->rows)
        return PHC_ERR_INVALID; /* too many rows, or not prepared */
    const size_t nn = e->n_nodes;
    for (size_t i = 0; i < nn; ++i)
        forward_node(e, i, slots, cols, n_rows, grad != NULL);
    memcpy(value, e->rows + (nn - 1) * B, n_rows * sizeof *value);
    if (grad)
        reverse_sweep(e, n_rows, grad, grad_stride);
    return PHC_OK;
}

int phc_expr_bind_data(phc_expr *e, const double *const *cols, size_t n, phc_error *err)
{
    enum { B = PHC_EXPR_ROWS };
    if (!e->rows)
        return phc_error_set(err, PHC_ERR_INVALID, "expression: bind the data after phc_expr_prepare");
    const size_t nn = e->n_nodes, root = nn - 1;
    /* each node but the root has one parent (the parser never shares a node) */
    size_t *parent = malloc(nn * sizeof *parent);
    if (!parent)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < nn; ++i) {
        const node *n = &e->nodes[i];
        if (n->op == OP_CONST || n->op == OP_NAME)
            continue;
        parent[n->a] = i;
        if (n->op == OP_ADD || n->op == OP_SUB || n->op == OP_MUL || n->op == OP_DIV || n->op == OP_POW)
            parent[n->b] = i;
    }
    size_t hoisted = 0;
    for (size_t i = 0; i < nn; ++i) {
        node *n = &e->nodes[i];
        const int parent_active = i == root || e->nodes[parent[i]].active;
        n->inside = !n->active && !parent_active;
        n->hoisted = !n->active && parent_active && n->op != OP_CONST && n->op != OP_NAME;
        n->pre = n->hoisted ? hoisted++ : 0;
    }
    free(parent);
    free(e->data_cols);
    free(e->pre);
    e->data_cols = malloc((e->n_cols ? e->n_cols : 1) * sizeof *e->data_cols);
    e->pre = malloc((hoisted && n ? hoisted * n : 1) * sizeof *e->pre);
    e->data_n = e->n_hoisted = 0;
    if (!e->data_cols || !e->pre)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t c = 0; c < e->n_cols; ++c)
        e->data_cols[c] = cols[c];
    /* the hoisted nodes' values, block by block with the same code as
     * phc_expr_eval_rows (so the same numbers) */
    for (size_t r0 = 0; r0 < n && hoisted; r0 += B) {
        const size_t nr = n - r0 < B ? n - r0 : B;
        for (size_t c = 0; c < e->n_cols; ++c)
            e->row_cols[c] = cols[c] + r0;
        for (size_t i = 0; i < nn; ++i) {
            if (e->nodes[i].active)
                continue;
            forward_node(e, i, NULL, e->row_cols, nr, 0);
            if (e->nodes[i].hoisted)
                memcpy(e->pre + e->nodes[i].pre * n + r0, e->rows + i * B, nr * sizeof *e->pre);
        }
    }
    e->data_n = n;
    e->n_hoisted = hoisted;
    return PHC_OK;
}

int phc_expr_eval_data(phc_expr *e, const double *slots, size_t row0, size_t n_rows, double *value, double *grad,
                       size_t grad_stride)
{
    enum { B = PHC_EXPR_ROWS };
    if (n_rows > B || !e->rows || !e->data_cols || row0 > e->data_n || n_rows > e->data_n - row0)
        return PHC_ERR_INVALID;
    const size_t nn = e->n_nodes;
    for (size_t c = 0; c < e->n_cols; ++c)
        e->row_cols[c] = e->data_cols[c] + row0;
    for (size_t i = 0; i < nn; ++i) {
        const node *n = &e->nodes[i];
        if (n->inside)
            continue;
        if (n->hoisted)
            memcpy(e->rows + i * B, e->pre + n->pre * e->data_n + row0, n_rows * sizeof *e->pre);
        else
            forward_node(e, i, slots, e->row_cols, n_rows, grad != NULL);
    }
    memcpy(value, e->rows + (nn - 1) * B, n_rows * sizeof *value);
    if (grad)
        reverse_sweep(e, n_rows, grad, grad_stride);
    return PHC_OK;
}
