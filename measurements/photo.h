/* Leaf photographs: reading, segmentation, colour correction, registration
 * and venation maps, turning real photos into the inputs of the leaf colour
 * aging model (model/leaf.h, model/colour.h; Silva et al. §3).
 *
 * A plain C interface to OpenCV 4.6 (+ contrib: mcc, ximgproc).  Only the
 * measurements/photo_*_bridge.cc files touch OpenCV (photo_bridge.h lists
 * them); no C++ type appears here.
 * Every function returns PHC_OK (0) or a positive enum phc_status and fills
 * `err` (may be NULL) with a message naming the file (when there is one) and
 * the reason.  Nothing keeps global state.
 *
 * Images are phc_image: width x height pixels, three interleaved channels,
 * R G B order (not OpenCV's BGR), gamma-encoded sRGB scaled to [0, 1]
 * (8-bit files divide by 255, 16-bit by 65535).  Pixel (x, y) channel c is
 * data[3 (x + width y) + c]; row 0 is the top of the picture. */
#ifndef PHC_PHOTO_H
#define PHC_PHOTO_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_image {
    size_t width, height;
    int bit_depth; /* of the file read (8 or 16); 8 for images made in memory */
    double *data;  /* 3 * width * height, malloc'd */
} phc_image;

/* Allocates a black image (data zeroed).  PHC_ERR_INVALID for a zero size. */
int phc_image_alloc(phc_image *img, size_t width, size_t height, phc_error *err);
void phc_image_free(phc_image *img); /* frees data, zeroes the struct; NULL ok */

/* Reads PNG, JPEG or TIFF (other formats OpenCV decodes, e.g. BMP, are
 * accepted too), 8 or 16 bit, gray (copied to the three channels), gray +
 * alpha, RGB or RGBA (alpha dropped).  The file is read once and decoded
 * from memory (cv::imdecode, IMREAD_UNCHANGED: depth and channels kept,
 * EXIF orientation ignored).  Errors, each naming the file:
 *   - PHC_ERR_IO "cannot open" (missing, no permission) or "read error";
 *   - PHC_ERR_INPUT "empty file", "not a PNG, JPEG or TIFF image" (unknown
 *     signature and OpenCV cannot decode it), "cannot be decoded";
 *   - PHC_ERR_INPUT "truncated JPEG (no end-of-image marker)" -- the marker
 *     segments are walked, so padding or vendor data after FFD9 is fine --
 *     and "truncated PNG (no IEND chunk)" (libjpeg and libpng would
 *     otherwise return a partly grey picture with only a warning);
 *   - PHC_ERR_INPUT for bit depths other than 8 and 16 and float images. */
int phc_photo_read(const char *path, phc_image *out, phc_error *err);

/* Writes an 8-bit RGB PNG (values clipped to [0, 1] and rounded), through a
 * temporary file renamed into place.  PHC_ERR_INVALID unless the name ends
 * in .png or a value is not finite. */
int phc_photo_write_png(const char *path, const phc_image *img, phc_error *err);

/* Writes an RGB image in the format its extension names (.png, .tif/.tiff,
 * .jpg/.jpeg; case ignored) with bit_depth 8 or 16 bits per sample (16:
 * PNG and TIFF only; JPEG quality 95), values clipped to [0, 1] and
 * rounded, through a temporary file renamed into place. */
int phc_photo_write(const char *path, const phc_image *img, int bit_depth, phc_error *err);

/* Writes a scalar map (width*height values) as an 8-bit PNG: an RGB PNG
 * with the viridis colour map from lo to hi when `colour_map` is nonzero, a
 * 1-channel grey PNG otherwise (values clipped to [lo, hi]); pixels with
 * mask == 0 (mask may be NULL) are white.  PHC_ERR_INVALID unless hi > lo
 * or when a value inside the mask is not finite. */
int phc_photo_write_map_png(const char *path, size_t width, size_t height, const double *values,
                            const unsigned char *mask, double lo, double hi, int colour_map,
                            phc_error *err);

/* Reads a single-channel map (PNG/TIFF/JPEG, 8 or 16 bit; colour files are
 * converted to grey) scaled to [0, 1], and resizes it to width x height
 * (area averaging) when its size differs and `resize` is nonzero;
 * otherwise a size mismatch is PHC_ERR_INPUT naming both sizes.
 * *values is malloc'd (width*height). */
int phc_photo_read_map(const char *path, size_t width, size_t height, int resize, double **values,
                       phc_error *err);

/* Resized copy (area averaging when shrinking, bilinear when enlarging). */
int phc_photo_resize(const phc_image *img, size_t width, size_t height, phc_image *out,
                     phc_error *err);
/* Resized mask (any nonzero input is leaf; output 0/1).  Shrinking: a new
 * pixel is leaf when at least half of the area it covers is leaf;
 * enlarging: nearest neighbour.  *out malloc'd (new_width*new_height). */
int phc_photo_resize_mask(const unsigned char *mask, size_t width, size_t height, size_t new_width,
                          size_t new_height, unsigned char **out, phc_error *err);

/* ---- leaf segmentation --------------------------------------------------- */

typedef struct phc_segment_options {
    double min_area_fraction; /* components smaller than this fraction of the
                                 largest one are noise (default 0.05) */
    int grabcut;              /* refine each leaf's mask with GrabCut (default 1) */
    int grabcut_iterations;   /* default 3 */
    double downscale_to;      /* work on a copy whose long side is at most this
                                 many pixels (default 1200; 0 = full size) */
} phc_segment_options;
phc_segment_options phc_segment_options_default(void);

typedef struct phc_leaf_box {
    size_t x0, y0, x1, y1; /* bounding box, x1 and y1 exclusive, image pixels */
    size_t area;           /* pixels in the leaf's mask */
    double cx, cy;         /* centroid, pixels */
} phc_leaf_box;

typedef struct phc_segmentation {
    size_t width, height;
    int *labels;        /* width*height: 0 background, 1..count leaf number */
    size_t count;
    phc_leaf_box *leaf; /* count boxes; leaf[i] has label i + 1 */
    double threshold;   /* the Otsu threshold on the leaf chroma found
                           (CIELAB ΔC*ab units, see below) */
} phc_segmentation;

/* Finds the leaves on a light background (a scan or a photo).  The
 * background colour is the per-channel median of a border frame (1 % of
 * the short side); the leaf feature is the CIELAB chroma distance from it
 * counted only where b* exceeds the background's (0 elsewhere).
 * Chlorophylls, carotenoids and the brown products of senescence all absorb
 * blue, so green, yellow and brown lamina score high while grey rules,
 * shadows and blue-black handwriting score 0.  The feature is thresholded
 * by Otsu (1979), opened (3x3), holes filled, components below
 * min_area_fraction of the largest dropped, and each leaf refined by
 * GrabCut (Rother et al. 2004; certain foreground: the eroded mask;
 * certain background: beyond a ring around it and the other leaves; a
 * result outside 1/2..2 times the initial area is discarded).  The work is
 * done on a copy at most downscale_to pixels long; each leaf's mask is
 * enlarged back bilinearly and thresholded at 1/2.  Deterministic (GrabCut's
 * k-means uses a fixed seed).  Leaves are numbered in reading order: sorted into
 * rows by their vertical extent (a leaf starts a new row when its top is
 * below the bottom of the current row's first leaf minus half its height),
 * then left to right.  PHC_ERR_INPUT "no leaf found" when nothing remains. */
int phc_photo_segment_leaves(const phc_image *img, const phc_segment_options *opt,
                             phc_segmentation *out, phc_error *err);
void phc_segmentation_free(phc_segmentation *seg);

/* Crops leaf `number` (1-based) with `margin` pixels around its box:
 * *leaf_img is the crop, *mask (malloc'd, crop size) is 1 on that leaf only. */
int phc_photo_crop_leaf(const phc_image *img, const phc_segmentation *seg, size_t number,
                        size_t margin, phc_image *leaf_img, unsigned char **mask, phc_error *err);

/* ---- colour correction ---------------------------------------------------- */

typedef enum phc_colour_correction_method {
    PHC_CC_NONE = 0,
    PHC_CC_GRAY_WORLD,   /* per-channel gains making the mean grey */
    PHC_CC_COLORCHECKER  /* a 24-patch ColorChecker Classic found in the frame */
} phc_colour_correction_method;

typedef struct phc_colour_correction {
    phc_colour_correction_method method;
    size_t patches;         /* ColorChecker patches used (24) */
    double mean_de_before;  /* mean CIEDE2000 of the patches to their reference
                               values before correction (ColorChecker only) */
    double mean_de;         /* ... after correction */
    double max_de;          /* largest patch ΔE00 after correction */
    double gains[3];        /* gray world: the per-channel gains */
    double matrix[9];       /* ColorChecker: linear-RGB 3x3 correction matrix,
                               row-major (out = M in) */
    double clipped_fraction; /* pixels with a component pushed outside [0, 1]
                                by the correction and clipped */
    char note[256];         /* why the ColorChecker was not used, when it
                               was asked for; empty otherwise */
} phc_colour_correction;

/* Corrects img in place.  want = PHC_CC_COLORCHECKER tries to detect a
 * ColorChecker Classic (OpenCV mcc CCheckerDetector, MCC24, on a copy at
 * most 1600 px long) and fits, by least squares in linear RGB, a 3x3 matrix
 * from the patch means to the reference colours: OpenCV 4.6 cv::ccm's
 * COLORCHECKER_Macbeth values (CIELAB D50, adapted by ccm to sRGB D65 with
 * Bradford; within ~2/255 of X-Rite's post-2014 sRGB values).  Patches with
 * a component at 0-2 or 253-255 (clipped) are left out of the fit and of
 * the ΔE00 means; at least 6 must remain.  A detection is accepted only
 * when the six neutral patches darken in order.  When no credible chart is
 * found it falls back to gray world and says why in report->note.
 * want = PHC_CC_GRAY_WORLD uses gray world (Buchsbaum 1980: linear-light
 * gains making the three channel means over `mask` -- the whole image when
 * NULL -- equal to their average); PHC_CC_NONE leaves the image unchanged.
 * Corrections act on linear light (IEC 61966-2-1 decoding); results are
 * clipped to [0, 1] (counted in clipped_fraction).  report->method says
 * what was done; report may be NULL. */
int phc_photo_colour_correct(phc_image *img, const unsigned char *mask,
                             phc_colour_correction_method want, phc_colour_correction *report,
                             phc_error *err);

/* ---- registration ----------------------------------------------------------- */

typedef enum phc_motion {
    PHC_MOTION_TRANSLATION = 0, /* 2 parameters */
    PHC_MOTION_EUCLIDEAN,       /* rotation + translation, 3 */
    PHC_MOTION_AFFINE           /* 6 */
} phc_motion;

typedef struct phc_register_options {
    phc_motion motion;  /* default PHC_MOTION_AFFINE */
    int max_levels;     /* pyramid levels (1 = no pyramid); halving stops
                           before the short side drops below 64 px (default 5) */
    int iterations;     /* ECC iterations per level (default 200) */
    double epsilon;     /* ECC stops when the correlation gains less (1e-6) */
} phc_register_options;
phc_register_options phc_register_options_default(void);

/* Aligns `moving` to `reference` (same size) with OpenCV's ECC maximisation
 * (Evangelidis and Psarakis 2008; cv::findTransformECC with a 5x5 Gaussian
 * prefilter) on grey levels, coarse to fine on a Gaussian pyramid, and
 * writes the warped image to *out (same size as reference; uncovered pixels
 * black; cv::warpAffine, bilinear, WARP_INVERSE_MAP) and the 2x3 warp
 * (row-major; reference pixel (x, y) -> moving pixel (w0 x + w1 y + w2,
 * w3 x + w4 y + w5)) to warp.  `mask` (NULL: all; moving-image pixels,
 * as findTransformECC's inputMask) selects the moving image's pixels that
 * may take part, e.g. to leave out a black frame; a 3-pixel frame at the
 * image edge is always left out (blur and derivatives there see reflected
 * borders, which biases the warp).  opt NULL: defaults.  *correlation is
 * the enhanced correlation coefficient achieved (1 = identical up to
 * brightness and contrast), computed at full resolution without the
 * prefilter over the reference pixels that land inside the moving image
 * (and its mask).  A coarse level that does not converge
 * passes its starting warp on; PHC_ERR_NOT_CONVERGED when the finest level
 * fails, with ECC's reason. */
int phc_photo_register(const phc_image *reference, const phc_image *moving,
                       const unsigned char *mask, const phc_register_options *opt, phc_image *out,
                       double warp[6], double *correlation, phc_error *err);

/* The same criterion for two images of the same size as they are (the
 * identity warp): zero-mean normalised correlation of their grey levels over
 * `mask` (NULL: every pixel).  Lets callers see what registration gained. */
int phc_photo_correlation(const phc_image *a, const phc_image *b, const unsigned char *mask,
                          double *correlation, phc_error *err);

/* ---- venation map -------------------------------------------------------------- */

typedef struct phc_vein_options {
    double sigma_min, sigma_max; /* scales of the ridge filter, pixels (default
                                    1, 4; geometric steps between them) */
    int scales;                  /* default 4 */
    int dark_veins;              /* 1: veins darker than the lamina (reflective
                                    scans of many leaves); 0: lighter (backlit
                                    leaves, whose veins let more light through,
                                    as in the Zelkova photo); -1 (default):
                                    decide from the image */
} phc_vein_options;
phc_vein_options phc_vein_options_default(void);

/* Ridge strength in [0, 1] (0 off the mask): the multi-scale Hessian
 * measure (Frangi et al. 1998's eigen-analysis without the vesselness
 * ratios): the green channel, off-mask pixels replaced by the lamina's
 * median (so that the outline is no ridge), Gaussian-blurred at each scale
 * sigma, its Hessian by Sobel second derivatives scaled by sigma^2
 * (Lindeberg's normalisation); the response is max(larger eigenvalue, 0)
 * for dark veins or max(-smaller eigenvalue, 0) for light ones, maximised
 * over the scales and divided by its 99th percentile inside the mask
 * (values above it are 1).  With dark_veins = -1 the polarity whose 99.5th
 * percentile inside the mask is larger wins (a line's own polarity responds
 * more strongly than its flanks).  *veins malloc'd (width*height). */
int phc_photo_vein_map(const phc_image *img, const unsigned char *mask,
                       const phc_vein_options *opt, double **veins, phc_error *err);

/* Binary vein mask from a ridge map: Otsu threshold inside the mask. */
int phc_photo_vein_binary(size_t width, size_t height, const double *veins,
                          const unsigned char *mask, unsigned char **binary, phc_error *err);

/* Precision and recall of a binary vein map against a ground truth of the
 * same size, with a tolerance: a predicted pixel is correct when a truth
 * pixel lies within `tolerance` pixels, a truth pixel is found when a
 * predicted one does (the usual buffered scores for thin structures;
 * computed by dilating each map with a disk of radius `tolerance`).
 * Precision is 0 when nothing is predicted; an empty truth is
 * PHC_ERR_INPUT. */
int phc_photo_vein_scores(size_t width, size_t height, const unsigned char *predicted,
                          const unsigned char *truth, double tolerance, double *precision,
                          double *recall, phc_error *err);

/* ---- drawing and warping (for sheets and registration) ------------------------ */

/* Applies a 2x3 affine warp as returned by phc_photo_register (reference
 * pixel -> moving pixel) to `moving`, giving a width x height image
 * (bilinear; uncovered pixels black). */
int phc_photo_warp(const phc_image *moving, const double warp[6], size_t width, size_t height,
                   phc_image *out, phc_error *err);

/* Draws black text (Hershey simplex, OpenCV putText) with its baseline's
 * left end at (x, y) px; `scale` 0.5 gives letters about 10 px high.
 * Text leaving the image is clipped. */
int phc_photo_draw_text(phc_image *img, const char *text, size_t x, size_t y, double scale,
                        phc_error *err);

/* The viridis colour map as 256 sRGB triplets in [0, 1] (OpenCV's
 * COLORMAP_VIRIDIS). */
int phc_photo_viridis(double lut[3 * 256], phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_PHOTO_H */
