/* The leaf colour aging set-up (Silva et al. §3): a fresh leaf cut out of a
 * photo, a senescent reference leaf, the venation, stomata and inflow maps,
 * the fluid model on a coarse grid, and the leaf's colours at any time.
 * Shared by `leaf_photos` data sets (leaf_photos.h), their simulate and fit
 * outputs, the notebooks and the tests.
 *
 * Pipeline (every step in measurements/photo.h or model/):
 *   photo --read--> colour correction --segment--> leaf number n (reading
 *   order) --crop--> resize so the long side is model_size px --> mask,
 *   colours.  The venation map is computed on the full-resolution crop and
 *   averaged down to the model grid.  Histogram matching (eq. 8) of the
 *   fresh leaf's colours onto the reference leaf's, in the matching space,
 *   is done once.  At time t the model's fluid y blends each pixel between
 *   its original and matched colour (eq. 9, model/colour.h). */
#ifndef PHC_COSTS_LEAF_SETUP_H
#define PHC_COSTS_LEAF_SETUP_H

#include <stddef.h>

#include "measurements/photo.h"
#include "model/colour.h"
#include "model/leaf.h"
#include "model/status.h"

/* One leaf cut out of a photo (after colour correction). */
typedef struct phc_leaf_photo {
    char *path;          /* the photo file (or the name of an image given in memory) */
    size_t number;       /* leaf number in the photo (reading order, 1-based) */
    size_t leaves;       /* leaves found in the photo */
    phc_image crop;      /* full-resolution crop around the leaf */
    unsigned char *mask; /* crop size, 1 on this leaf */
    size_t area;         /* leaf pixels at full resolution */
    size_t x0, y0;       /* the crop's top-left corner in the photo, px */
    size_t photo_width, photo_height;
    phc_colour_correction correction;
} phc_leaf_photo;

/* Photos already read and segmented, so a scan holding 15 leaves is read
 * once.  Owns its images. */
typedef struct phc_photo_cache phc_photo_cache;
phc_photo_cache *phc_photo_cache_new(void);
void phc_photo_cache_free(phc_photo_cache *c); /* accepts NULL */

/* Puts an image already in memory (measurements/photo.h: sRGB in [0, 1])
 * into the cache under `name`, as phc_photo_cache_read does a file: copied,
 * colour corrected by `correction` and segmented, once (a name already
 * cached with that correction is kept).  phc_leaf_photo_load(cache, name,
 * ...) then cuts its leaves out without reading any file; `name` stands for
 * the image in messages and reports.  Errors as phc_photo_cache_read's
 * ("no leaf found"); PHC_ERR_INVALID without a name or an image. */
int phc_photo_cache_add(phc_photo_cache *cache, const char *name, const phc_image *img,
                        phc_colour_correction_method correction, const char *where, phc_error *err);

/* Cuts leaf `number` (1-based, reading order) out of photo `path`, colour
 * corrected by `correction` (measured over the whole photo for gray world).
 * Errors name the file: unreadable or truncated photo, no leaf found, a
 * leaf number beyond the leaves found ("photo.jpg: leaf 16 requested, 15
 * leaves found").  `where` (config file:line) prefixes the message; may be
 * NULL. */
int phc_leaf_photo_load(phc_photo_cache *cache, const char *path, size_t number,
                        phc_colour_correction_method correction, const char *where,
                        phc_leaf_photo *out, phc_error *err);
void phc_leaf_photo_free(phc_leaf_photo *p); /* the contents; accepts NULL */

/* Reads, colour corrects and segments photo `path` into the cache (once),
 * without cutting out a leaf: for callers that place errors about the file
 * (unreadable, not an image, no leaf found) apart from errors about a leaf
 * number.  `where` as for phc_leaf_photo_load. */
int phc_photo_cache_read(phc_photo_cache *cache, const char *path, phc_colour_correction_method correction,
                         const char *where, phc_error *err);

/* The leaf's pixels on a grid whose long side is `size` px (aspect kept):
 * *img (sRGB), *mask (malloc'd).  Pixels off the resized mask are black. */
int phc_leaf_photo_grid(const phc_leaf_photo *p, size_t size, phc_image *img, unsigned char **mask,
                        phc_error *err);

typedef enum phc_leaf_map_source {
    PHC_LEAF_MAP_AUTO = 0, /* veins: ridge map of the fresh photo; stomata: uniform 1;
                              inflow: the venation map */
    PHC_LEAF_MAP_UNIFORM,  /* 1 on the leaf */
    PHC_LEAF_MAP_NONE,     /* 0 (inflow only) */
    PHC_LEAF_MAP_FILE      /* a grey image, resized to the model grid */
} phc_leaf_map_source;

typedef struct phc_leaf_setup_options {
    size_t model_size;         /* long side of the simulation grid, px (128) */
    phc_colour_space space;    /* histogram matching and blending space (RGB) */
    double vein_floor;         /* β on the lamina: β = floor + (1 - floor) ridge (0.05) */
    double vein_edge_taper;    /* auto veins: the ridge response is faded out linearly from
                                  1 to this many px (full-resolution crop) inside the
                                  leaf's edge, where the filter answers the step from the
                                  leaf to the background rather than a vein (9 = 2 sigma_max
                                  + 1 of the default ridge filter; 0 = no fade) */
    phc_leaf_map_source veins, stomata, inflow;
    const char *veins_file, *stomata_file, *inflow_file; /* for PHC_LEAF_MAP_FILE */
    const char *veins_where, *stomata_where, *inflow_where; /* where each file was named
                                  ("cfg.yaml:12: key 'veins'"), put before an error
                                  about that file; NULL = nothing */
    double dt;                 /* model step, time units (0.1) */
} phc_leaf_setup_options;
phc_leaf_setup_options phc_leaf_setup_options_default(void);

typedef struct phc_leaf_setup {
    size_t w, h, cells;        /* model grid and leaf pixels on it */
    unsigned char *mask;       /* w h */
    phc_image fresh;           /* the fresh leaf on the model grid (sRGB) */
    double *original;          /* 3 w h colours in `space` (0 off the leaf) */
    double *matched;           /* 3 w h matched colours in `space` */
    double *beta, *stomata, *inflow; /* w h maps given to the model */
    phc_colour_space space;
    phc_leaf *leaf;            /* the fluid model */
    double *blend;             /* 3 w h scratch (blend of the last call; where
                                  the Lab copies are used, maybe stale) */
    double *lab_original, *lab_matched; /* 3 w h CIELAB of original and matched
                                  when `space` is sRGB (else NULL): a pixel
                                  with g = 1 or 0 (eq. 9) shows exactly these */
} phc_leaf_setup;

/* Builds the set-up from a fresh and a reference leaf.  Map files are grey
 * images of the fresh leaf's whole photo (same size; cropped with the leaf);
 * another size is an error naming both sizes. */
int phc_leaf_setup_new(const phc_leaf_photo *fresh, const phc_leaf_photo *reference,
                       const phc_leaf_setup_options *opt, phc_leaf_setup **out, phc_error *err);
void phc_leaf_setup_free(phc_leaf_setup *s); /* accepts NULL */

/* The colours of the current fluid state: CIELAB (3 w h, 0 off the leaf)
 * and/or sRGB image (may be NULL; *srgb allocated here when non-NULL). */
int phc_leaf_setup_colours(phc_leaf_setup *s, phc_colour_transfer tf, double *lab, phc_image *srgb,
                           phc_error *err);

/* Chamfer (3-4) distance, px, from every pixel of a w x h grid to the
 * nearest pixel where src != 0 (1e9/3 when there is none). */
void phc_leaf_chamfer_distance(size_t w, size_t h, const unsigned char *src, double *d);

/* CIELAB colours (3 per pixel) of the leaf pixels of an sRGB image with a
 * mask, packed; *n pixels; *lab malloc'd. */
int phc_leaf_lab_pixels(const phc_image *img, const unsigned char *mask, double **lab, size_t *n,
                        phc_error *err);

#endif /* PHC_COSTS_LEAF_SETUP_H */
