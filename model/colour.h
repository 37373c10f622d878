/* Leaf colour from fluid: Silva et al. §3, eqs. 8-9 (DESIGN §5), and the
 * colour arithmetic the calibration needs (CIELAB, colour differences,
 * quantiles).
 *
 * Colours are triplets stored interleaved (pixel i has components
 * c[3i], c[3i+1], c[3i+2]) in one of two spaces:
 *   PHC_COLOUR_RGB  sRGB, gamma-encoded, each component in [0, 1] (what a
 *                   photo file holds; the paper matches in RGB)
 *   PHC_COLOUR_LAB  CIELAB (D65 white, 2° observer): L* in [0, 100],
 *                   a*, b* roughly in [-128, 127]
 * Matching in CIELAB separates lightness from the two chroma axes, which
 * are close to the independent directions in which a leaf yellows (a*
 * green -> red, b* blue -> yellow); per-channel matching in RGB mixes them,
 * because a leaf's R, G and B are strongly correlated.  RGB is the paper's
 * choice and the default; LAB is offered for that reason.
 *
 * Histogram matching (eq. 8): each channel of the leaf's pixels is mapped
 * through its own empirical CDF onto the reference's quantile function,
 *   m = Q_ref(F_leaf(c)),
 * with mid-ranks for ties: a value c found at the 0-based sorted positions
 * a..b of the n_leaf values (a = #{< c}, b = #{<= c} - 1) has
 * F_leaf(c) = ((a + b)/2 + 1/2)/n_leaf, and Q_ref interpolates linearly
 * between the reference order statistics placed at probabilities
 * (j + 1/2)/n_ref, j = 0..n_ref-1, constant beyond the first and last.
 * Hence equal inputs give equal outputs, the map is monotone, its values
 * stay within the reference range, matching a set of colours to itself is
 * exactly the identity, and with n_leaf == n_ref an increasing affine change
 * of the colours is recovered exactly.  Only the pixels inside the masks
 * take part (the caller passes them packed).
 *
 * Blending (eq. 9): a pixel with fluid y shows
 *   colour = g(y) original + (1 - g(y)) matched,
 * with the transfer function g a smooth step between two fluid levels:
 *   g(y) = 0 for y <= y_lo, 1 for y >= y_hi, and
 *   g(y) = s^2 (3 - 2 s), s = (y - y_lo)/(y_hi - y_lo), in between
 * (C^1, so calibration sees a smooth objective).  y_hi > y_lo is required.
 * The blend is done in the matching space and converted to sRGB after.
 *
 * No I/O, no globals. */
#ifndef PHC_COLOUR_H
#define PHC_COLOUR_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum phc_colour_space { PHC_COLOUR_RGB = 0, PHC_COLOUR_LAB = 1 } phc_colour_space;

/* The IEC 61966-2-1 sRGB transfer function of one component: decode takes
 * a gamma-encoded value to linear light, encode takes it back.  Neither
 * clips: the linear segment near 0 extends to negative values (an
 * out-of-gamut colour such as the ColorChecker's cyan has a negative linear
 * red), and encode inverts decode to rounding on the whole line (the
 * standard's two thresholds disagree by ~1e-8; see colour.c). */
double phc_colour_srgb_decode(double c);
double phc_colour_srgb_encode(double v);

/* sRGB (gamma-encoded, [0,1]) <-> CIELAB (D65).  lab_to_srgb does not
 * clip: out-of-gamut colours give components outside [0, 1]. */
void phc_colour_srgb_to_lab(const double rgb[3], double lab[3]);
void phc_colour_lab_to_srgb(const double lab[3], double rgb[3]);
/* n interleaved colours from one space to the other (in == out allowed). */
void phc_colour_convert(size_t n, const double *in, phc_colour_space from, phc_colour_space to,
                        double *out);

/* CIE 1976 ΔE*ab: Euclidean distance in CIELAB. */
double phc_colour_de76(const double lab1[3], const double lab2[3]);
/* CIEDE2000 ΔE00 (kL = kC = kH = 1), as specified by Sharma, Wu and Dalal,
 * Color Res. Appl. 30:21-30 (2005), which gives the test data. */
double phc_colour_de2000(const double lab1[3], const double lab2[3]);

/* Per-channel histogram matching (eq. 8) of n_src colours onto n_ref
 * reference colours, both interleaved in the same space; writes n_src
 * matched colours.  PHC_ERR_INPUT when n_src or n_ref is 0 or a value is
 * not finite. */
int phc_colour_match_histograms(size_t n_src, const double *src, size_t n_ref, const double *ref,
                                double *matched, phc_error *err);

typedef struct phc_colour_transfer {
    double y_lo; /* fluid at and below which a pixel shows its matched colour */
    double y_hi; /* fluid at and above which it shows its original colour */
} phc_colour_transfer;

/* g(y) of eq. 9 and, when non-NULL, dg/dy, dg/dy_lo, dg/dy_hi.
 * Requires y_hi > y_lo (not checked here; see phc_colour_transfer_check). */
double phc_colour_transfer_weight(phc_colour_transfer tf, double y, double *dg_dy,
                                  double *dg_dlo, double *dg_dhi);
/* PHC_ERR_INPUT unless y_lo and y_hi are finite and y_hi > y_lo. */
int phc_colour_transfer_check(phc_colour_transfer tf, phc_error *err);

/* out_i = g(y_i) original_i + (1 - g(y_i)) matched_i for n colours (any
 * space; the caller converts after). */
void phc_colour_blend(size_t n, const double *original, const double *matched,
                      const double *fluid, phc_colour_transfer tf, double *out);

/* The nq quantiles at probabilities (k + 1/2)/nq, k = 0..nq-1, of channel
 * `channel` (0..2) of n interleaved colours, by linear interpolation
 * between order statistics.  `scratch` holds n doubles.  Used for the
 * histogram distance: the L2 distance between quantile functions is the
 * 2-Wasserstein distance between the two histograms. */
int phc_colour_quantiles(size_t n, const double *colours, int channel, size_t nq, double *scratch,
                         double *q, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_COLOUR_H */
