/* measurements/photo_module_internal.h: the table of the photos module,
 * phytocal_photo.so (the OpenCV bridge, measurements/photo_*_bridge.cc; see
 * module_internal.h).  libphytocal's photo.h functions that need OpenCV
 * forward to it (measurements/photo.c).  C and C++; internal. */
#ifndef PHC_PHOTO_MODULE_INTERNAL_H
#define PHC_PHOTO_MODULE_INTERNAL_H

#include "measurements/photo.h"

/* Bumped whenever a signature below or their order changes. */
#define PHC_PHOTO_MODULE_ABI 1
#define PHC_PHOTO_MODULE_ENTRY "phc_photo_module_entry"
#define PHC_PHOTO_MODULE_FILE "phytocal_photo.so"

/* X(name, parameters, arguments): every photo.h function that needs OpenCV;
 * each returns a phc_status and takes phc_error *err last. */
#define PHC_PHOTO_MODULE_FUNCTIONS(X)                                                                  \
    X(phc_photo_read, (const char *path, phc_image *out, phc_error *err), (path, out, err))            \
    X(phc_photo_write_png, (const char *path, const phc_image *img, phc_error *err), (path, img, err)) \
    X(phc_photo_write, (const char *path, const phc_image *img, int bit_depth, phc_error *err),        \
      (path, img, bit_depth, err))                                                                     \
    X(phc_photo_write_map_png,                                                                         \
      (const char *path, size_t width, size_t height, const double *values, const unsigned char *mask, \
       double lo, double hi, int colour_map, phc_error *err),                                          \
      (path, width, height, values, mask, lo, hi, colour_map, err))                                    \
    X(phc_photo_read_map,                                                                              \
      (const char *path, size_t width, size_t height, int resize, double **values, phc_error *err),    \
      (path, width, height, resize, values, err))                                                      \
    X(phc_photo_resize, (const phc_image *img, size_t width, size_t height, phc_image *out, phc_error *err), \
      (img, width, height, out, err))                                                                  \
    X(phc_photo_resize_mask,                                                                           \
      (const unsigned char *mask, size_t width, size_t height, size_t new_width, size_t new_height,   \
       unsigned char **out, phc_error *err),                                                           \
      (mask, width, height, new_width, new_height, out, err))                                          \
    X(phc_photo_segment_leaves,                                                                        \
      (const phc_image *img, const phc_segment_options *opt, phc_segmentation *out, phc_error *err),   \
      (img, opt, out, err))                                                                            \
    X(phc_photo_crop_leaf,                                                                             \
      (const phc_image *img, const phc_segmentation *seg, size_t number, size_t margin,               \
       phc_image *leaf_img, unsigned char **mask, phc_error *err),                                     \
      (img, seg, number, margin, leaf_img, mask, err))                                                 \
    X(phc_photo_colour_correct,                                                                        \
      (phc_image *img, const unsigned char *mask, phc_colour_correction_method want,                  \
       phc_colour_correction *report, phc_error *err),                                                 \
      (img, mask, want, report, err))                                                                  \
    X(phc_photo_register,                                                                              \
      (const phc_image *reference, const phc_image *moving, const unsigned char *mask,                \
       const phc_register_options *opt, phc_image *out, double warp[6], double *correlation,          \
       phc_error *err),                                                                                \
      (reference, moving, mask, opt, out, warp, correlation, err))                                     \
    X(phc_photo_correlation,                                                                           \
      (const phc_image *a, const phc_image *b, const unsigned char *mask, double *correlation,        \
       phc_error *err),                                                                                \
      (a, b, mask, correlation, err))                                                                  \
    X(phc_photo_vein_map,                                                                              \
      (const phc_image *img, const unsigned char *mask, const phc_vein_options *opt, double **veins,  \
       phc_error *err),                                                                                \
      (img, mask, opt, veins, err))                                                                    \
    X(phc_photo_vein_binary,                                                                           \
      (size_t width, size_t height, const double *veins, const unsigned char *mask,                   \
       unsigned char **binary, phc_error *err),                                                        \
      (width, height, veins, mask, binary, err))                                                       \
    X(phc_photo_vein_scores,                                                                           \
      (size_t width, size_t height, const unsigned char *predicted, const unsigned char *truth,       \
       double tolerance, double *precision, double *recall, phc_error *err),                           \
      (width, height, predicted, truth, tolerance, precision, recall, err))                            \
    X(phc_photo_warp,                                                                                  \
      (const phc_image *moving, const double warp[6], size_t width, size_t height, phc_image *out,    \
       phc_error *err),                                                                                \
      (moving, warp, width, height, out, err))                                                         \
    X(phc_photo_draw_text,                                                                             \
      (phc_image *img, const char *text, size_t x, size_t y, double scale, phc_error *err),           \
      (img, text, x, y, scale, err))                                                                   \
    X(phc_photo_viridis, (double lut[3 * 256], phc_error *err), (lut, err))

#define PHC_PHOTO_MODULE_FIELD(name, params, args) int(*name) params;
typedef struct phc_photo_module_table {
    PHC_PHOTO_MODULE_FUNCTIONS(PHC_PHOTO_MODULE_FIELD)
} phc_photo_module_table;
#undef PHC_PHOTO_MODULE_FIELD

#endif
