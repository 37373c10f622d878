/* measurements/photo_bridge.h: what the OpenCV bridge files of
 * measurements/photo.h share.  C++ only, internal: included by the
 * measurements/photo_*_bridge.cc files and nothing else (DESIGN §2: no C++
 * type in a header a C file sees; the public interface is photo.h).
 *
 * The bridge is split by concern:
 *   photo_io_bridge.cc        images in memory, reading and writing files, resizing
 *   photo_segment_bridge.cc   leaf segmentation and cropping
 *   photo_colour_bridge.cc    colour correction (gray world, ColorChecker)
 *   photo_register_bridge.cc  ECC registration, correlation, warping
 *   photo_veins_bridge.cc     ridge (vein) maps and their scores
 *   photo_draw_bridge.cc      text and the viridis colour map
 * Colour arithmetic (sRGB transfer function, CIELAB, ΔE) is model/colour.h's.
 * These files (with photo_module_bridge.cc, the entry point) make the module
 * phytocal_photo.so, opened on first use; libphytocal's measurements/photo.c
 * holds images in memory and the option defaults, and forwards the rest
 * (measurements/module_internal.h).
 *
 * Every extern "C" function catches every exception (PHOTO_CATCH below) and
 * turns it into a status and a one-line message; sizes are validated before
 * any OpenCV call; nothing is printed and nothing keeps state between calls.
 *
 * Internally images are cv::Mat in R G B order (not OpenCV's usual BGR):
 * CV_64FC3 headers over phc_image data, CV_32F copies where OpenCV needs
 * single precision (ECC, GrabCut's 8-bit input is made explicitly). */
#ifndef PHC_PHOTO_BRIDGE_H
#define PHC_PHOTO_BRIDGE_H

#ifndef __cplusplus
#error "measurements/photo_bridge.h is C++, for the photo_*_bridge.cc files only; C code includes photo.h"
#endif

#include "measurements/photo.h"

#include <opencv2/core.hpp>

#include <climits>
#include <cstdint>
#include <new>

/* The catch clauses every extern "C" body ends with.  `what` names the file
 * or the operation.  OpenCV reports allocation failures as cv::Exception
 * with code StsNoMem. */
#define PHOTO_CATCH(err, what)                                                                   \
    catch (const cv::Exception &e) {                                                             \
        if (e.code == cv::Error::StsNoMem)                                                       \
            return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory (OpenCV)", what);        \
        return phc_error_set(err, PHC_ERR_INTERNAL, "%s: OpenCV error in %s: %s", what,          \
                             e.func.c_str(), e.err.c_str());                                     \
    }                                                                                            \
    catch (const std::bad_alloc &) {                                                             \
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", what);                     \
    }                                                                                            \
    catch (...) {                                                                                \
        return phc_error_set(err, PHC_ERR_INTERNAL, "%s: unexpected C++ exception", what);       \
    }

namespace phc_photo {

/* A size OpenCV can index (cv::Mat dimensions are int) whose 3-channel
 * double buffer does not overflow size_t. */
inline bool size_ok(size_t w, size_t h)
{
    return w > 0 && h > 0 && w <= (size_t)INT_MAX && h <= (size_t)INT_MAX &&
           w <= SIZE_MAX / 3 / sizeof(double) / h;
}

inline int check_image(const phc_image *img, const char *what, phc_error *err)
{
    if (!img || !img->data)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: no image", what);
    if (!size_ok(img->width, img->height))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: invalid image size %zux%zu", what,
                             img->width, img->height);
    return PHC_OK;
}

/* CV_64FC3 header over a phc_image (no copy; OpenCV does not write through
 * it unless the caller does). */
inline cv::Mat mat_of(const phc_image *img)
{
    return cv::Mat((int)img->height, (int)img->width, CV_64FC3, (void *)img->data);
}

/* CV_8U header over a w x h mask (no copy). */
inline cv::Mat mat_of_mask(const unsigned char *mask, size_t w, size_t h)
{
    return cv::Mat((int)h, (int)w, CV_8U, (void *)mask);
}

/* Otsu (1979) threshold of a CV_32F feature map over `mask` (all pixels
 * when empty): values quantised to 256 bins over [0, fmax], cv::threshold's
 * THRESH_OTSU on the 8-bit copy.  Used by segmentation and vein maps;
 * defined in photo_segment_bridge.cc. */
double otsu_threshold(const cv::Mat &f32, const cv::Mat &mask, double fmax);

} // namespace phc_photo

#endif /* PHC_PHOTO_BRIDGE_H */
