/* Sap ("fluid") flow over a leaf blade: the leaf colour aging model of
 * Silva et al. §3, eqs. 1-7 (DESIGN §5).
 *
 * The leaf is a W x H pixel grid with a mask M (1 = leaf).  Per pixel:
 *   y  fluid amount (dimensionless; 1 = a fresh, fully supplied leaf)
 *   β  venation map (dimensionless, >= 0; large on veins, small or 0 on the
 *      lamina between them)
 *   O  stomata map (dimensionless, >= 0): where fluid transpires
 *   I  inflow map (dimensionless, >= 0): where sap enters (veins, petiole)
 * Scales, all >= 0 (the calibrated parameters):
 *   s_β  diffusivity per unit venation   [px^2 / time unit]
 *   s_O  transpiration per unit of O     [fluid / time unit]
 *   s_I  inflow per unit of I            [fluid / time unit]
 * The time unit is the caller's (days in phytocal's configs).
 *
 * One step of length h (eq. 1, operator splitting in the paper's order):
 *   1. transpiration (eq. 2):  y <- max(y - h s_O O, 0)
 *      A pixel cannot lose fluid it does not hold: the floor at 0 is part of
 *      the model (the paper's fluid is an amount), not a clamp of bad input.
 *   2. inflow (eq. 3):         y <- y + h s_I I
 *   3. implicit diffusion (eqs. 4-6), split into columns then rows:
 *        (1 + h L_col) y' = y,   then   (1 + h L_row) y'' = y'
 *      with L the 1-D finite-volume operator of the face conductances
 *        k_f = s_β (β_a + β_b) / 2           (a, b the two pixels of face f)
 *      and k_f = 0 when a or b is outside the mask or the image
 *      (zero-flux borders, eq. 7).  Each line of a half-step is a symmetric
 *      tridiagonal system
 *        -h k_{i-1/2} y'_{i-1} + (1 + h k_{i-1/2} + h k_{i+1/2}) y'_i
 *        - h k_{i+1/2} y'_{i+1} = y_i
 *      solved by Crout factorisation (L U with unit-diagonal U), factorised
 *      once per step length and reused.  Its columns sum to 1, so the
 *      half-steps conserve the total fluid exactly (to round-off); pixels
 *      outside the mask are never written (they stay 0; a sweep may read one
 *      but always multiplies it by an exact 0).
 * Implicit diffusion is unconditionally stable: any h > 0 is allowed.
 *
 * Orientation: a transposed leaf (maps transposed) gives the transposed
 * result up to the order of the split (columns-then-rows becomes
 * rows-then-columns): the splitting error, O(h^2) per step.  A 180° rotation
 * gives the rotated result to round-off.
 *
 * Layout: pixel (x, y) is element x + W y (row-major, row 0 at the top).
 * Threads: lines are independent; the half-steps run with OpenMP and give
 * bit-identical results for any thread count.
 *
 * No I/O, no globals. */
#ifndef PHC_LEAF_H
#define PHC_LEAF_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_leaf_params {
    double beta_scale;    /* s_β  [px^2 / time unit], >= 0 */
    double stomata_scale; /* s_O  [fluid / time unit], >= 0 */
    double inflow_scale;  /* s_I  [fluid / time unit], >= 0 */
    double dt;            /* step length [time unit], > 0 */
} phc_leaf_params;

/* s_β 50, s_O 0.1, s_I 0.05, dt 0.1. */
phc_leaf_params phc_leaf_params_default(void);

typedef struct phc_leaf phc_leaf; /* opaque */

/* A leaf on a width x height grid.  mask (W*H bytes, nonzero = leaf) is
 * required; beta, stomata, inflow (W*H doubles each) may be NULL, meaning 1
 * everywhere on the leaf (beta), 1 (stomata) and 0 (inflow).  The maps are
 * copied.  The fluid starts at y = 1 on the leaf, 0 elsewhere.
 * Errors: PHC_ERR_INVALID (NULL, zero size), PHC_ERR_INPUT (empty mask, a
 * negative or non-finite map value, with its pixel "(x, y)" in the message;
 * invalid params as phc_leaf_set_params), PHC_ERR_NOMEM. */
int phc_leaf_new(size_t width, size_t height, const unsigned char *mask, const double *beta,
                 const double *stomata, const double *inflow, phc_leaf_params params,
                 phc_leaf **out, phc_error *err);
void phc_leaf_free(phc_leaf *leaf); /* accepts NULL */

size_t phc_leaf_width(const phc_leaf *leaf);
size_t phc_leaf_height(const phc_leaf *leaf);
size_t phc_leaf_cells(const phc_leaf *leaf); /* pixels in the mask */
const unsigned char *phc_leaf_mask(const phc_leaf *leaf);

/* New scales and step (factorisations are redone lazily).  PHC_ERR_INPUT
 * when a scale is negative or non-finite or dt <= 0, naming the field. */
int phc_leaf_set_params(phc_leaf *leaf, phc_leaf_params params, phc_error *err);
phc_leaf_params phc_leaf_get_params(const phc_leaf *leaf);

/* y = y0 on the leaf, 0 elsewhere (y0 >= 0), and the clock to 0. */
void phc_leaf_reset(phc_leaf *leaf, double y0);
/* Copies a whole fluid map in (W*H; values off the mask are ignored and set
 * to 0).  PHC_ERR_INPUT for a negative or non-finite value on the leaf. */
int phc_leaf_set_fluid(phc_leaf *leaf, const double *y, phc_error *err);
const double *phc_leaf_fluid(const phc_leaf *leaf); /* W*H, 0 off the leaf */
double phc_leaf_time(const phc_leaf *leaf);         /* time advanced since reset */
double phc_leaf_total(const phc_leaf *leaf);        /* sum of y over the leaf */

/* One full step (transpiration, inflow, columns, rows) of length h > 0.
 * h == params.dt reuses the cached factorisation. */
int phc_leaf_step(phc_leaf *leaf, double h);

/* Advances by t >= 0: floor(t/dt) steps of dt, then one step of the
 * remainder (if > 1e-12 dt), so the state is a continuous function of t. */
int phc_leaf_advance(phc_leaf *leaf, double t);

/* The pieces of a step, for tests and for users who compose their own:
 * the sources (transpiration then inflow) and one implicit half-step along
 * an axis (PHC_LEAF_COLUMNS: each column x solved over y; PHC_LEAF_ROWS). */
typedef enum { PHC_LEAF_COLUMNS = 0, PHC_LEAF_ROWS = 1 } phc_leaf_axis;
void phc_leaf_sources(phc_leaf *leaf, double h);
int phc_leaf_diffuse(phc_leaf *leaf, double h, phc_leaf_axis axis);

/* Face conductance k_f [px^2 / time unit] between pixel (x, y) and its
 * neighbour (x+1, y) (axis ROWS) or (x, y+1) (axis COLUMNS); 0 across the
 * mask or image border.  For tests that build the dense system. */
double phc_leaf_face_conductance(const phc_leaf *leaf, size_t x, size_t y, phc_leaf_axis axis);

#ifdef __cplusplus
}
#endif

#endif /* PHC_LEAF_H */
