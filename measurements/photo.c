/* measurements/photo.h in libphytocal: the functions that need no OpenCV
 * (images and segmentations in memory, option defaults), and the ones that
 * do, forwarded to the photos module phytocal_photo.so, opened on first use
 * (measurements/module_internal.h).  The OpenCV code is in
 * measurements/photo_*_bridge.cc, compiled into the module only. */
#define _DEFAULT_SOURCE /* madvise, MADV_HUGEPAGE (Linux) */
#include "measurements/photo.h"

#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "measurements/module_internal.h"
#include "measurements/photo_module_internal.h"

static phc_module photo_module = {PHC_PHOTO_MODULE_FILE, PHC_PHOTO_MODULE_ENTRY, PHC_PHOTO_MODULE_ABI,
                                  "photos (OpenCV)", NULL, 0};

#define PHC_PHOTO_FORWARD(name, params, args)                                                  \
    int name params                                                                            \
    {                                                                                          \
        const phc_photo_module_table *t = phc_module_table(&photo_module, err);                \
        return t ? t->name args : PHC_ERR_IO;                                                  \
    }
PHC_PHOTO_MODULE_FUNCTIONS(PHC_PHOTO_FORWARD)

/* ---- images ---------------------------------------------------------------- */

/* A zeroed buffer of `bytes`, freed by free().  A photo's double buffer is
 * tens to hundreds of MiB, written once right after allocation: with 4 KiB
 * pages that is one page fault per 4 KiB, which in this virtual machine cost
 * more CPU than the decoding (about a quarter of the leaf photo tests).  From
 * 2 MiB up the buffer is aligned to 2 MiB and advised as transparent huge
 * pages (Linux, where the system allows them on madvise): 512 times fewer
 * faults.  Measured on 288 MB written 10 times: 12.5 s of CPU with calloc,
 * 1.4 s so (busy 2-core machine).  Elsewhere, or if that fails, calloc. */
static double *zeroed_buffer(size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t huge = (size_t)2 << 20;
    if (bytes >= huge && bytes <= SIZE_MAX - huge) {
        const size_t rounded = (bytes + huge - 1) / huge * huge;
        void *p = NULL;
        if (posix_memalign(&p, huge, rounded) == 0) {
            (void)madvise(p, rounded, MADV_HUGEPAGE); /* advice: a refusal only costs speed */
            memset(p, 0, rounded);
            return p;
        }
    }
#endif
    return calloc(bytes, 1);
}

int phc_image_alloc(phc_image *img, size_t width, size_t height, phc_error *err)
{
    if (!img)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_image_alloc: no image");
    memset(img, 0, sizeof *img);
    /* a size OpenCV can index (cv::Mat dimensions are int) whose 3-channel
       double buffer does not overflow size_t (photo_bridge.h's size_ok) */
    if (width == 0 || height == 0 || width > (size_t)INT_MAX || height > (size_t)INT_MAX ||
        width > SIZE_MAX / 3 / sizeof(double) / height)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_image_alloc: invalid size %zux%zu", width, height);
    img->data = zeroed_buffer(3 * width * height * sizeof(double));
    if (!img->data)
        return phc_error_set(err, PHC_ERR_NOMEM, "phc_image_alloc: out of memory (%zux%zu)", width, height);
    img->width = width;
    img->height = height;
    img->bit_depth = 8;
    return PHC_OK;
}

void phc_image_free(phc_image *img)
{
    if (!img)
        return;
    free(img->data);
    memset(img, 0, sizeof *img);
}

void phc_segmentation_free(phc_segmentation *seg)
{
    if (!seg)
        return;
    free(seg->labels);
    free(seg->leaf);
    memset(seg, 0, sizeof *seg);
}

/* ---- option defaults (photo.h documents each) -------------------------------- */

phc_segment_options phc_segment_options_default(void)
{
    phc_segment_options o;
    o.min_area_fraction = 0.05;
    o.grabcut = 1;
    o.grabcut_iterations = 3;
    o.downscale_to = 1200;
    return o;
}

phc_register_options phc_register_options_default(void)
{
    phc_register_options o;
    o.motion = PHC_MOTION_AFFINE;
    o.max_levels = 5;
    o.iterations = 200;
    o.epsilon = 1e-6;
    return o;
}

phc_vein_options phc_vein_options_default(void)
{
    phc_vein_options o;
    o.sigma_min = 1;
    o.sigma_max = 4;
    o.scales = 4;
    o.dark_veins = -1;
    return o;
}
