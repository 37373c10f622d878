/* measurements/photo_colour_bridge.cc: colour correction of photos, gray
 * world and ColorChecker (measurements/photo.h; OpenCV core and contrib's
 * mcc).  The sRGB transfer function, CIELAB and ΔE00 are model/colour.h's.
 * What the photo bridge files share is in photo_bridge.h. */
#include "measurements/photo_bridge.h"

#include "model/colour.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/mcc.hpp>
#include <opencv2/mcc/ccm.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace phc_photo;

/* Linear-light copy (IEC 61966-2-1 decoding) of a phc_image, CV_64FC3.
 * An 8-bit photo holds only the 256 values k/255: their decodings are
 * tabulated once per call (the values k * (1/255) and k / 255, which differ
 * in the last bit for some k), and a component equal to its table key
 * takes the tabulated value, the very double phc_colour_srgb_decode returns
 * (a pow per component otherwise; anything else, e.g. a 16-bit photo, still
 * calls it). */
static cv::Mat linear_copy(const phc_image *img)
{
    struct table {
        double key[2][256], val[2][256];
    } t;
    for (int k = 0; k < 256; ++k) {
        t.key[0][k] = (double)k * (1.0 / 255.0);
        t.key[1][k] = (double)k / 255.0;
        for (int v = 0; v < 2; ++v)
            t.val[v][k] = phc_colour_srgb_decode(t.key[v][k]);
    }
    cv::Mat lin = mat_of(img).clone();
    lin.forEach<cv::Vec3d>([&t](cv::Vec3d &p, const int *) {
        for (int c = 0; c < 3; ++c) {
            const double x = std::max(0.0, p[c]);
            const double r = x * 255.0 + 0.5;
            const int k = r < 256.0 ? (int)r : 0;
            if (x == t.key[0][k])
                p[c] = t.val[0][k];
            else if (x == t.key[1][k])
                p[c] = t.val[1][k];
            else
                p[c] = phc_colour_srgb_decode(x);
        }
    });
    return lin;
}

/* Writes linear values back into img, clipped to [0, 1] and encoded;
 * returns the fraction of pixels with a clipped component. */
static double store_linear(const cv::Mat &lin, phc_image *img)
{
    size_t clipped = 0;
    const size_t n = img->width * img->height;
    const double *src = (const double *)lin.data;
    for (size_t i = 0; i < n; ++i) {
        bool clip = false;
        for (int c = 0; c < 3; ++c) {
            double v = src[3 * i + c];
            if (v < 0 || v > 1) {
                clip = true;
                v = std::min(1.0, std::max(0.0, v));
            }
            img->data[3 * i + c] = phc_colour_srgb_encode(v);
        }
        clipped += clip;
    }
    return n ? (double)clipped / n : 0;
}

/* Gray world (Buchsbaum 1980): per-channel gains on linear light making the
 * three channel means over the mask equal to their average. */
static int gray_world(phc_image *img, const unsigned char *mask, phc_colour_correction *rep,
                      phc_error *err)
{
    cv::Mat lin = linear_copy(img);
    double sum[3] = {0, 0, 0};
    size_t n = 0;
    const double *p = (const double *)lin.data;
    for (size_t i = 0; i < img->width * img->height; ++i)
        if (!mask || mask[i]) {
            for (int c = 0; c < 3; ++c)
                sum[c] += p[3 * i + c];
            ++n;
        }
    if (n == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "gray world: the mask is empty");
    const double mean = (sum[0] + sum[1] + sum[2]) / 3;
    for (int c = 0; c < 3; ++c) {
        if (!(sum[c] > 0))
            return phc_error_set(err, PHC_ERR_INPUT, "gray world: the %s channel is black",
                                 c == 0 ? "red" : c == 1 ? "green" : "blue");
        rep->gains[c] = mean / sum[c];
    }
    const cv::Scalar g(rep->gains[0], rep->gains[1], rep->gains[2]);
    cv::multiply(lin, g, lin);
    rep->clipped_fraction = store_linear(lin, img);
    rep->method = PHC_CC_GRAY_WORLD;
    return PHC_OK;
}

/* The ColorChecker Classic's reference colours in linear sRGB (D65): OpenCV
 * 4.6 cv::ccm's COLORCHECKER_Macbeth data (CIELAB D50 values of the X-Rite
 * chart, converted by ccm to sRGB with Bradford adaptation to D65).  They
 * agree within about 2/255 with X-Rite's post-2014 sRGB values (patch 1,
 * dark skin: 115.5 80.9 67.4 here, 115 82 68 published).  ccm exposes them
 * only through a fitted model: a model of a flat grey chart (nothing
 * saturated, one solver iteration) is built to read them. */
static void macbeth_reference(double ref[24][3])
{
    cv::Mat flat(24, 1, CV_64FC3, cv::Scalar(0.5, 0.5, 0.5));
    cv::ccm::ColorCorrectionModel model(flat, cv::ccm::COLORCHECKER_Macbeth);
    model.setMaxCount(1);
    model.run();
    const cv::Mat d = model.get_dst_rgbl();
    CV_Assert(d.rows == 24 && d.type() == CV_64FC3);
    for (int i = 0; i < 24; ++i)
        for (int c = 0; c < 3; ++c)
            ref[i][c] = d.at<cv::Vec3d>(i)[c];
}

/* Patch means of the best MCC24 chart found (Marrero Fernández et al.'s mcc
 * detector) in an 8-bit copy whose long side is at most 1600 px (patch means
 * survive area averaging; detection at full size of a 12-Mpx photo is slow).
 * Returns false, with the reason, when there is no credible chart. */
static bool find_checker(const phc_image *img, double meas[24][3], std::string &why)
{
    cv::Mat bgr8;
    mat_of(img).convertTo(bgr8, CV_8U, 255);
    cv::cvtColor(bgr8, bgr8, cv::COLOR_RGB2BGR);
    const double longest = (double)std::max(img->width, img->height);
    if (longest > 1600)
        cv::resize(bgr8, bgr8, cv::Size(), 1600 / longest, 1600 / longest, cv::INTER_AREA);
    cv::Ptr<cv::mcc::CCheckerDetector> det = cv::mcc::CCheckerDetector::create();
    if (!det->process(bgr8, cv::mcc::MCC24, 1)) {
        why = "no ColorChecker found";
        return false;
    }
    const cv::Ptr<cv::mcc::CChecker> best = det->getBestColorChecker();
    const cv::Mat charts = best->getChartsRGB(); /* rows 3 i + c (R G B), column 1: mean */
    if (charts.rows != 72 || charts.cols < 2 || charts.type() != CV_64F) {
        why = "ColorChecker detector returned an unexpected patch table";
        return false;
    }
    for (int i = 0; i < 24; ++i)
        for (int c = 0; c < 3; ++c)
            meas[i][c] = charts.at<double>(3 * i + c, 1) / 255.0;
    /* Credibility: the six neutral patches (19 white .. 24 black) must get
     * darker in order; a false detection in a leaf scan does not. */
    for (int i = 19; i < 24; ++i) {
        const double a = meas[i - 1][0] + meas[i - 1][1] + meas[i - 1][2];
        const double b = meas[i][0] + meas[i][1] + meas[i][2];
        if (!(b < a)) {
            why = "ColorChecker candidate rejected (its neutral patches are not ordered "
                  "white to black)";
            return false;
        }
    }
    return true;
}

/* CIELAB of a linear-light colour: encoded without clipping, then
 * phc_colour_srgb_to_lab.  The ColorChecker's cyan patch lies slightly
 * outside the sRGB gamut (negative linear red); the transfer function's
 * linear segment carries such values through exactly (colour.h). */
static void linear_to_lab(const double lin[3], double lab[3])
{
    const double rgb[3] = {phc_colour_srgb_encode(lin[0]), phc_colour_srgb_encode(lin[1]),
                           phc_colour_srgb_encode(lin[2])};
    phc_colour_srgb_to_lab(rgb, lab);
}

/* Least-squares 3x3 matrix, linear RGB, measured -> reference, over the
 * patches with no clipped component (a clipped patch's mean is not its
 * colour).  ΔE00 (Sharma et al. 2005, phc_colour_de2000) before and after,
 * over the same patches. */
static int checker_fit(const double meas[24][3], const double ref[24][3],
                       phc_colour_correction *rep, std::string &why)
{
    std::vector<int> use;
    for (int i = 0; i < 24; ++i) {
        bool ok = true;
        for (int c = 0; c < 3; ++c)
            ok = ok && meas[i][c] > 2.0 / 255 && meas[i][c] < 253.0 / 255;
        if (ok)
            use.push_back(i);
    }
    if (use.size() < 6) {
        why = "only " + std::to_string(use.size()) + " ColorChecker patches are unclipped (6 needed)";
        return 0;
    }
    const int n = (int)use.size();
    cv::Mat A(n, 3, CV_64F), B(n, 3, CV_64F), X;
    for (int k = 0; k < n; ++k)
        for (int c = 0; c < 3; ++c) {
            A.at<double>(k, c) = phc_colour_srgb_decode(meas[use[k]][c]);
            B.at<double>(k, c) = ref[use[k]][c];
        }
    if (!cv::solve(A, B, X, cv::DECOMP_SVD)) { /* B ≈ A X, so M = X^T */
        why = "the ColorChecker least-squares fit is singular";
        return 0;
    }
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            rep->matrix[3 * r + c] = X.at<double>(c, r);
    double sb = 0, sa = 0, mx = 0;
    for (int k = 0; k < n; ++k) {
        double lin[3], cor[3], lab_m[3], lab_c[3], lab_r[3];
        for (int c = 0; c < 3; ++c)
            lin[c] = A.at<double>(k, c);
        for (int r = 0; r < 3; ++r) {
            const double v = rep->matrix[3 * r] * lin[0] + rep->matrix[3 * r + 1] * lin[1] +
                             rep->matrix[3 * r + 2] * lin[2];
            cor[r] = std::min(1.0, std::max(0.0, v)); /* as the image will hold it */
        }
        phc_colour_srgb_to_lab(meas[use[k]], lab_m); /* as measured (encoded) */
        linear_to_lab(cor, lab_c);
        linear_to_lab(ref[use[k]], lab_r);
        const double before = phc_colour_de2000(lab_m, lab_r), after = phc_colour_de2000(lab_c, lab_r);
        sb += before;
        sa += after;
        mx = std::max(mx, after);
    }
    rep->patches = (size_t)n;
    rep->mean_de_before = sb / n;
    rep->mean_de = sa / n;
    rep->max_de = mx;
    return 1;
}

static int colour_checker(phc_image *img, phc_colour_correction *rep, std::string &why)
{
    double meas[24][3], ref[24][3];
    if (!find_checker(img, meas, why))
        return 0;
    macbeth_reference(ref);
    if (!checker_fit(meas, ref, rep, why))
        return 0;
    cv::Mat lin = linear_copy(img);
    cv::Mat M(3, 3, CV_64F, rep->matrix);
    cv::transform(lin, lin, M); /* out = M in, per pixel */
    rep->clipped_fraction = store_linear(lin, img);
    rep->method = PHC_CC_COLORCHECKER;
    return 1;
}

extern "C" int phc_photo_colour_correct(phc_image *img, const unsigned char *mask,
                                        phc_colour_correction_method want,
                                        phc_colour_correction *report, phc_error *err)
{
    phc_colour_correction dummy;
    phc_colour_correction *rep = report ? report : &dummy;
    std::memset(rep, 0, sizeof *rep);
    rep->method = PHC_CC_NONE;
    rep->gains[0] = rep->gains[1] = rep->gains[2] = 1;
    rep->matrix[0] = rep->matrix[4] = rep->matrix[8] = 1;
    int rc = check_image(img, "phc_photo_colour_correct", err);
    if (rc)
        return rc;
    if (want != PHC_CC_NONE && want != PHC_CC_GRAY_WORLD && want != PHC_CC_COLORCHECKER)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_colour_correct: unknown method %d",
                             (int)want);
    try {
        if (want == PHC_CC_NONE)
            return PHC_OK;
        if (want == PHC_CC_COLORCHECKER) {
            std::string why;
            try {
                if (colour_checker(img, rep, why))
                    return PHC_OK;
            } catch (const cv::Exception &e) { /* the detector's own failure */
                if (e.code == cv::Error::StsNoMem)
                    throw;
                why = std::string("ColorChecker detection failed (") + e.err + ")";
            }
            std::snprintf(rep->note, sizeof rep->note, "%s; gray world used instead", why.c_str());
        }
        return gray_world(img, mask, rep, err);
    }
    PHOTO_CATCH(err, "phc_photo_colour_correct")
}
