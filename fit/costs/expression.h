/* Exact derivatives of `curve` expressions by automatic differentiation
 * (reverse mode: one backward sweep per row gives every parameter's
 * derivative).
 *
 * Why this exists beside muparser: muparser parses, validates and evaluates
 * the user's expression (it gives the error messages with positions), but it
 * cannot differentiate.  Central differences cost 2k evaluations per
 * Jacobian and are accurate to about 1e-10 relative: on the NIST StRD set
 * they give 10.13 digits on average in 3.9 times the solve time of exact
 * derivatives, which give 10.55 (tests/bench/nist_peers --derivatives
 * central).  This compiles the same grammar
 * (DESIGN.md §4: numbers, names, + - * / ^, parentheses, unary minus,
 * exp log sqrt sin cos tan atan abs, pi) into a tape that yields the value
 * and all parameter derivatives in two sweeps.  Expressions using anything
 * else muparser knows (sinh, min, ...) are refused here, and the data set
 * falls back to muparser with numerical derivatives.
 *
 * Precedence as in muparser: ^ binds tighter than unary minus (-2^2 = -4)
 * and is right-associative (2^3^2 = 512). */
#ifndef PHC_COSTS_EXPRESSION_H
#define PHC_COSTS_EXPRESSION_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_expr phc_expr;

/* Compiles text.  On a syntax error or an unsupported construct returns
 * PHC_ERR_INPUT with a message and the 0-based character position in *pos;
 * PHC_ERR_DOMAIN when the expression is nested more than 200 levels deep
 * (parentheses, function calls, signs and powers together), which the
 * recursive descent refuses instead of overflowing the stack. */
int phc_expr_compile(const char *text, phc_expr **out, size_t *pos,
                     phc_error *err);
void phc_expr_free(phc_expr *e); /* accepts NULL */

/* Distinct names used by the expression (excluding pi), in first-use order. */
size_t phc_expr_name_count(const phc_expr *e);
const char *phc_expr_name(const phc_expr *e, size_t i);

/* Binds name i to parameter slot `index` (is_slot = 1) or to column `index`
 * of the row vector passed to phc_expr_eval (is_slot = 0).  Every name must
 * be bound before evaluation; n_slots is the length of the gradient. */
int phc_expr_bind(phc_expr *e, size_t i, int is_slot, size_t index);
int phc_expr_prepare(phc_expr *e, size_t n_slots, phc_error *err);

/* Value and, when grad is non-NULL, the n_slots partial derivatives with
 * respect to the slots.  Not thread-safe for one phc_expr (it owns its
 * workspace).  Non-finite results are returned as they are. */
double phc_expr_eval(phc_expr *e, const double *slots, const double *row,
                     double *grad);

/* Most rows phc_expr_eval_rows takes at once. */
#define PHC_EXPR_ROWS 32

/* n_rows (<= PHC_EXPR_ROWS) rows at once, bitwise the numbers phc_expr_eval
 * gives row by row: column c of row r is cols[c][r] (the columns the names
 * are bound to with is_slot = 0), the value into value[r] and, when grad is
 * non-NULL, the n_slots derivatives into grad + r * grad_stride.
 * phc_expr_eval is this with one row.  PHC_OK, or PHC_ERR_INVALID for
 * too many rows or a tape not prepared (its work space, 4 x nodes x
 * PHC_EXPR_ROWS doubles, is allocated by phc_expr_prepare).  Not
 * thread-safe for one phc_expr. */
int phc_expr_eval_rows(phc_expr *e, const double *slots, const double *const *cols, size_t n_rows,
                       double *value, double *grad, size_t grad_stride);

/* Binds the data the tape will be evaluated on: column c (the index a name
 * is bound to with is_slot = 0) is cols[c][0 .. n-1]; the arrays must stay
 * valid and unchanged while the tape uses them.  The values of every
 * largest subtree that depends on no slot (beyond a single constant or
 * column: cos(2*pi*x/12), x^2, ...) are computed here once per row instead
 * of at every evaluation.  After phc_expr_prepare (which drops a binding);
 * PHC_OK, PHC_ERR_NOMEM, or PHC_ERR_INVALID when not prepared. */
int phc_expr_bind_data(phc_expr *e, const double *const *cols, size_t n, phc_error *err);

/* phc_expr_eval_rows on rows row0 .. row0 + n_rows - 1 (n_rows <=
 * PHC_EXPR_ROWS) of the bound data: bitwise the same values and
 * derivatives (the hoisted subtrees' values were computed by the same
 * operations).  PHC_ERR_INVALID without bound data or for rows outside it. */
int phc_expr_eval_data(phc_expr *e, const double *slots, size_t row0, size_t n_rows, double *value, double *grad,
                       size_t grad_stride);

#endif /* PHC_COSTS_EXPRESSION_H */
