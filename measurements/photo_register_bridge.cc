/* measurements/photo_register_bridge.cc: ECC registration, the correlation
 * it maximises, and affine warps (measurements/photo.h; OpenCV video and
 * imgproc).  What the photo bridge files share is in photo_bridge.h. */
#include "measurements/photo_bridge.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

using namespace phc_photo;

/* Grey levels (Rec. 601 luma of the encoded values), CV_32F. */
static cv::Mat grey_of(const phc_image *img)
{
    cv::Mat f, g;
    mat_of(img).convertTo(f, CV_32F);
    cv::cvtColor(f, g, cv::COLOR_RGB2GRAY);
    return g;
}

extern "C" int phc_photo_correlation(const phc_image *a, const phc_image *b,
                                     const unsigned char *mask, double *correlation,
                                     phc_error *err)
{
    if (!correlation)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_correlation: no output");
    int rc;
    if ((rc = check_image(a, "phc_photo_correlation", err)) ||
        (rc = check_image(b, "phc_photo_correlation", err)))
        return rc;
    if (a->width != b->width || a->height != b->height)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_correlation: images are %zux%zu and %zux%zu", a->width,
                             a->height, b->width, b->height);
    try {
        cv::Mat m;
        if (mask)
            m = mat_of_mask(mask, a->width, a->height);
        *correlation = cv::computeECC(grey_of(a), grey_of(b), mask ? m : cv::noArray());
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_correlation")
}

/* The moving-image pixels ECC may use at one level: the caller's mask (or
 * all) without a 3-pixel frame.  OpenCV blurs (5x5) and differentiates
 * (3x3 Sobel) with reflected borders, so the values at an image's edge are
 * not those of the same scene point inside the other image; keeping them
 * biases the warp (by ~0.03 px in scale and shift on a 220x180 test). */
static cv::Mat ecc_mask(const cv::Mat &mask, cv::Size size)
{
    cv::Mat m = mask.empty() ? cv::Mat(size, CV_8U, cv::Scalar(255)) : mask.clone();
    const int f = 3;
    if (size.width > 2 * f && size.height > 2 * f) {
        m.rowRange(0, f).setTo(0);
        m.rowRange(size.height - f, size.height).setTo(0);
        m.colRange(0, f).setTo(0);
        m.colRange(size.width - f, size.width).setTo(0);
    }
    return m;
}

/* ECC (Evangelidis and Psarakis 2008) coarse to fine on a Gaussian pyramid
 * (pyrDown; the coarsest level keeps a short side of at least 64 px).  A
 * coarse level that does not converge passes its starting warp on; only the
 * finest level must converge.  `mask` (may be empty) is in moving-image
 * pixels, as cv::findTransformECC's inputMask. */
static int ecc_pyramid(const cv::Mat &ref, const cv::Mat &mov, const cv::Mat &mask,
                       const phc_register_options &o, cv::Mat &warp, std::string &why)
{
    std::vector<cv::Mat> pr{ref}, pm{mov}, pk{mask};
    while ((int)pr.size() < o.max_levels && std::min(pr.back().rows, pr.back().cols) >= 128) {
        cv::Mat r, m, k;
        cv::pyrDown(pr.back(), r);
        cv::pyrDown(pm.back(), m);
        if (!mask.empty()) { /* a coarse pixel takes part when all of its area does */
            cv::resize(pk.back(), k, m.size(), 0, 0, cv::INTER_AREA);
            k = k == 255;
        }
        pr.push_back(r);
        pm.push_back(m);
        pk.push_back(k);
    }
    const int motion = o.motion == PHC_MOTION_TRANSLATION ? cv::MOTION_TRANSLATION
                       : o.motion == PHC_MOTION_EUCLIDEAN ? cv::MOTION_EUCLIDEAN
                                                          : cv::MOTION_AFFINE;
    warp = cv::Mat::eye(2, 3, CV_32F);
    const cv::TermCriteria crit(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, o.iterations,
                                o.epsilon);
    for (int lev = (int)pr.size() - 1; lev >= 0; --lev) {
        if (lev < (int)pr.size() - 1) { /* x_fine = 2 x_coarse for pyrDown */
            warp.at<float>(0, 2) *= 2;
            warp.at<float>(1, 2) *= 2;
        }
        try {
            cv::findTransformECC(pr[lev], pm[lev], warp, motion, crit,
                                 ecc_mask(pk[lev], pm[lev].size()), 5);
        } catch (const cv::Exception &e) {
            if (e.code != cv::Error::StsNoConv)
                throw;
            if (lev == 0) {
                why = e.err;
                return 0;
            }
        }
    }
    return 1;
}

extern "C" int phc_photo_register(const phc_image *reference, const phc_image *moving,
                                  const unsigned char *mask, const phc_register_options *opt,
                                  phc_image *out, double warp[6], double *correlation,
                                  phc_error *err)
{
    if (!out || !warp || !correlation)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_register: no output");
    std::memset(out, 0, sizeof *out);
    const double identity[6] = {1, 0, 0, 0, 1, 0}; /* what a failure leaves */
    std::memcpy(warp, identity, sizeof identity);
    *correlation = 0;
    int rc;
    if ((rc = check_image(reference, "phc_photo_register: reference", err)) ||
        (rc = check_image(moving, "phc_photo_register: moving image", err)))
        return rc;
    if (reference->width != moving->width || reference->height != moving->height)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_register: reference is %zux%zu, moving image %zux%zu "
                             "(same size expected)", reference->width, reference->height,
                             moving->width, moving->height);
    if (reference->width < 16 || reference->height < 16)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_register: %zux%zu is too small (16x16 at least)",
                             reference->width, reference->height);
    const phc_register_options o = opt ? *opt : phc_register_options_default();
    if ((o.motion != PHC_MOTION_TRANSLATION && o.motion != PHC_MOTION_EUCLIDEAN &&
         o.motion != PHC_MOTION_AFFINE) || o.max_levels < 1 || o.max_levels > 16 ||
        o.iterations < 1 || !(o.epsilon >= 0))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_register: invalid options (motion %d, max_levels %d in "
                             "1..16, iterations %d >= 1, epsilon %g >= 0)", (int)o.motion,
                             o.max_levels, o.iterations, o.epsilon);
    try {
        const cv::Mat gr = grey_of(reference), gm = grey_of(moving);
        cv::Mat m;
        if (mask) {
            m = mat_of_mask(mask, reference->width, reference->height) != 0;
            if (cv::countNonZero(m) < 16)
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "phc_photo_register: the mask has fewer than 16 pixels");
        }
        cv::Mat w;
        std::string why;
        if (!ecc_pyramid(gr, gm, m, o, w, why))
            return phc_error_set(err, PHC_ERR_NOT_CONVERGED, "ECC registration: %s", why.c_str());
        cv::Mat w64;
        w.convertTo(w64, CV_64F);
        if ((rc = phc_image_alloc(out, reference->width, reference->height, err)))
            return rc;
        cv::Mat dst = mat_of(out);
        /* WARP_INVERSE_MAP: out(x) = moving(W x), W maps reference -> moving */
        cv::warpAffine(mat_of(moving), dst, w64, dst.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                       cv::BORDER_CONSTANT, cv::Scalar::all(0));
        out->bit_depth = moving->bit_depth;
        /* correlation on the reference pixels that land inside the moving
         * image (and its mask), eroded by one pixel so that their bilinear
         * neighbours are all inside */
        cv::Mat valid = m.empty() ? cv::Mat(gm.size(), CV_8U, cv::Scalar(255)) : m, cover, gw;
        cv::warpAffine(valid, cover, w64, valid.size(), cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                       cv::BORDER_CONSTANT, 0);
        cv::erode(cover, cover, cv::Mat(), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, 0);
        cv::warpAffine(gm, gw, w64, gm.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
        *correlation = cv::countNonZero(cover) > 0 ? cv::computeECC(gr, gw, cover) : 0;
        for (int i = 0; i < 6; ++i)
            warp[i] = w64.at<double>(i / 3, i % 3);
        return PHC_OK;
    }
    catch (...) {
        phc_image_free(out);
        try {
            throw;
        }
        PHOTO_CATCH(err, "phc_photo_register")
    }
}

extern "C" int phc_photo_warp(const phc_image *moving, const double warp[6], size_t width, size_t height,
                              phc_image *out, phc_error *err)
{
    if (!out || !warp)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_warp: no warp or output");
    std::memset(out, 0, sizeof *out);
    int rc;
    if ((rc = check_image(moving, "phc_photo_warp", err)))
        return rc;
    if (!size_ok(width, height))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_warp: invalid size %zux%zu", width, height);
    for (int i = 0; i < 6; ++i)
        if (!std::isfinite(warp[i]))
            return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_warp: warp[%d] is not finite", i);
    try {
        cv::Mat w(2, 3, CV_64F);
        for (int i = 0; i < 6; ++i)
            w.at<double>(i / 3, i % 3) = warp[i];
        if ((rc = phc_image_alloc(out, width, height, err)))
            return rc;
        cv::Mat dst = mat_of(out);
        /* same convention as phc_photo_register: out(x) = moving(W x) */
        cv::warpAffine(mat_of(moving), dst, w, dst.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                       cv::BORDER_CONSTANT, cv::Scalar::all(0));
        out->bit_depth = moving->bit_depth;
        return PHC_OK;
    }
    catch (...) {
        phc_image_free(out);
        try {
            throw;
        }
        PHOTO_CATCH(err, "phc_photo_warp")
    }
}
