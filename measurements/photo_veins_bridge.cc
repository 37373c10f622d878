/* measurements/photo_veins_bridge.cc: venation (ridge) maps, their binary
 * masks and their scores against a ground truth (measurements/photo.h;
 * OpenCV imgproc).  What the photo bridge files share is in
 * photo_bridge.h. */
#include "measurements/photo_bridge.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

using namespace phc_photo;

/* Eigenvalues of the scale-normalised Hessian (σ² H, Lindeberg 1998) of
 * the blurred green channel at scale σ: the ridge response of one polarity,
 * lam_hi = max(larger eigenvalue, 0) for dark lines (valleys: the intensity
 * curves upward across them), lam_lo = max(-smaller eigenvalue, 0) for
 * light lines (Frangi et al. 1998 use the same eigen-analysis). */
static void hessian_response(const cv::Mat &g, double sigma, cv::Mat &dark, cv::Mat &light)
{
    cv::Mat b, dxx, dyy, dxy;
    cv::GaussianBlur(g, b, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
    cv::Sobel(b, dxx, CV_32F, 2, 0, 3, 1, 0, cv::BORDER_REFLECT);
    cv::Sobel(b, dyy, CV_32F, 0, 2, 3, 1, 0, cv::BORDER_REFLECT);
    cv::Sobel(b, dxy, CV_32F, 1, 1, 3, 0.25, 0, cv::BORDER_REFLECT); /* Sobel 1,1 is 4 d²/dxdy */
    dark.create(g.size(), CV_32F);
    light.create(g.size(), CV_32F);
    const float s2 = (float)(sigma * sigma);
    for (int y = 0; y < g.rows; ++y) {
        const float *a = dxx.ptr<float>(y), *c = dyy.ptr<float>(y), *bb = dxy.ptr<float>(y);
        float *d = dark.ptr<float>(y), *l = light.ptr<float>(y);
        for (int x = 0; x < g.cols; ++x) {
            const float half = 0.5f * (a[x] + c[x]);
            const float r = std::sqrt(0.25f * (a[x] - c[x]) * (a[x] - c[x]) + bb[x] * bb[x]);
            d[x] = s2 * std::max(half + r, 0.0f);
            l[x] = s2 * std::max(r - half, 0.0f);
        }
    }
}

/* q-quantile of the values of f inside the mask (all when mask is empty). */
static double masked_quantile(const cv::Mat &f, const cv::Mat &mask, double q)
{
    std::vector<float> v;
    v.reserve(f.total());
    for (int y = 0; y < f.rows; ++y) {
        const float *p = f.ptr<float>(y);
        const unsigned char *m = mask.empty() ? nullptr : mask.ptr<unsigned char>(y);
        for (int x = 0; x < f.cols; ++x)
            if (!m || m[x])
                v.push_back(p[x]);
    }
    if (v.empty())
        return 0;
    const size_t k = std::min(v.size() - 1, (size_t)(q * (v.size() - 1)));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[k];
}

extern "C" int phc_photo_vein_map(const phc_image *img, const unsigned char *mask,
                                  const phc_vein_options *opt, double **veins, phc_error *err)
{
    if (!veins)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_vein_map: no output");
    *veins = NULL;
    int rc = check_image(img, "phc_photo_vein_map", err);
    if (rc)
        return rc;
    const phc_vein_options o = opt ? *opt : phc_vein_options_default();
    if (!(o.sigma_min > 0 && o.sigma_max >= o.sigma_min && o.sigma_max <= 256) || o.scales < 1 ||
        o.scales > 64 || o.dark_veins < -1 || o.dark_veins > 1)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_vein_map: invalid options (0 < sigma_min %g <= sigma_max "
                             "%g <= 256, 1 <= scales %d <= 64, dark_veins %d in -1..1)",
                             o.sigma_min, o.sigma_max, o.scales, o.dark_veins);
    try {
        const int w = (int)img->width, h = (int)img->height;
        cv::Mat m;
        if (mask) {
            m = mat_of_mask(mask, img->width, img->height) != 0;
            if (cv::countNonZero(m) == 0)
                return phc_error_set(err, PHC_ERR_INPUT, "phc_photo_vein_map: the mask is empty");
        }
        cv::Mat g;
        cv::extractChannel(mat_of(img), g, 1);
        g.convertTo(g, CV_32F);
        /* Off-mask pixels take the lamina's median, so that the leaf's
         * outline against the background is not a ridge. */
        if (!m.empty())
            g.setTo(masked_quantile(g, m, 0.5), m == 0);
        cv::Mat dark = cv::Mat::zeros(h, w, CV_32F), light = cv::Mat::zeros(h, w, CV_32F), d, l;
        for (int k = 0; k < o.scales; ++k) {
            const double t = o.scales == 1 ? 0 : (double)k / (o.scales - 1);
            const double sigma = o.sigma_min * std::pow(o.sigma_max / o.sigma_min, t); /* geometric */
            hessian_response(g, sigma, d, l);
            dark = cv::max(dark, d);
            light = cv::max(light, l);
        }
        /* polarity: the one whose strongest responses (99.5th percentile)
         * are larger; a line's own polarity beats its flanks' */
        int dv = o.dark_veins;
        if (dv < 0)
            dv = masked_quantile(dark, m, 0.995) >= masked_quantile(light, m, 0.995);
        cv::Mat r = dv ? dark : light;
        const double p99 = masked_quantile(r, m, 0.99);
        double *v = (double *)std::malloc(img->width * img->height * sizeof *v);
        if (!v)
            return phc_error_set(err, PHC_ERR_NOMEM, "phc_photo_vein_map: out of memory");
        for (int y = 0; y < h; ++y) {
            const float *p = r.ptr<float>(y);
            const unsigned char *mm = m.empty() ? nullptr : m.ptr<unsigned char>(y);
            for (int x = 0; x < w; ++x) {
                const double t = p99 > 0 ? p[x] / p99 : 0;
                v[x + (size_t)w * y] = (mm && !mm[x]) ? 0 : std::min(1.0, t);
            }
        }
        *veins = v;
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_vein_map")
}

extern "C" int phc_photo_vein_binary(size_t width, size_t height, const double *veins,
                                     const unsigned char *mask, unsigned char **binary,
                                     phc_error *err)
{
    if (!binary)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_vein_binary: no output");
    *binary = NULL;
    if (!veins)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_vein_binary: no ridge map");
    if (!size_ok(width, height))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_vein_binary: invalid size %zux%zu",
                             width, height);
    try {
        cv::Mat f((int)height, (int)width, CV_32F), m;
        for (size_t i = 0; i < width * height; ++i) {
            const double v = veins[i];
            if ((!mask || mask[i]) && !std::isfinite(v))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "phc_photo_vein_binary: ridge value at (%zu, %zu) is not finite",
                                     i % width, i / width);
            ((float *)f.data)[i] = std::isfinite(v) ? (float)v : 0.0f;
        }
        if (mask) {
            m = mat_of_mask(mask, width, height) != 0;
        }
        const double t = otsu_threshold(f, m, 1.0);
        unsigned char *b = (unsigned char *)std::malloc(width * height);
        if (!b)
            return phc_error_set(err, PHC_ERR_NOMEM, "phc_photo_vein_binary: out of memory");
        for (size_t i = 0; i < width * height; ++i)
            b[i] = (!mask || mask[i]) && ((float *)f.data)[i] > t;
        *binary = b;
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_vein_binary")
}

extern "C" int phc_photo_vein_scores(size_t width, size_t height, const unsigned char *predicted,
                                     const unsigned char *truth, double tolerance,
                                     double *precision, double *recall, phc_error *err)
{
    if (!precision || !recall)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_vein_scores: no output");
    if (!predicted || !truth)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_vein_scores: no %s",
                             predicted ? "ground truth" : "prediction");
    if (!size_ok(width, height))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_vein_scores: invalid size %zux%zu",
                             width, height);
    if (!(tolerance >= 0 && tolerance <= 1000))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_vein_scores: tolerance %g px outside [0, 1000]", tolerance);
    try {
        const cv::Mat p = mat_of_mask(predicted, width, height) != 0,
                      t = mat_of_mask(truth, width, height) != 0;
        const int np = cv::countNonZero(p), nt = cv::countNonZero(t);
        if (nt == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "phc_photo_vein_scores: the ground truth is empty");
        /* disk of radius `tolerance`: offsets with dx² + dy² <= r² */
        const int r = (int)std::floor(tolerance);
        cv::Mat disk(2 * r + 1, 2 * r + 1, CV_8U);
        for (int y = -r; y <= r; ++y)
            for (int x = -r; x <= r; ++x)
                disk.at<unsigned char>(y + r, x + r) = x * x + y * y <= tolerance * tolerance;
        cv::Mat pd, td;
        cv::dilate(p, pd, disk, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, 0);
        cv::dilate(t, td, disk, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, 0);
        *precision = np ? (double)cv::countNonZero(p & td) / np : 0;
        *recall = (double)cv::countNonZero(t & pd) / nt;
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_vein_scores")
}
