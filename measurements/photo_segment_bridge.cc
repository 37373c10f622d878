/* measurements/photo_segment_bridge.cc: leaf segmentation and cropping
 * (measurements/photo.h; OpenCV imgproc).  The leaf feature is computed in
 * CIELAB with model/colour.h.  What the photo bridge files share is in
 * photo_bridge.h. */
#include "measurements/photo_bridge.h"

#include "model/colour.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

using namespace phc_photo;

/* Background (paper) colour: per-channel median of a frame of border pixels
 * (1 % of the short side, at least 2 px), in the work image (CV_32FC3). */
static cv::Vec3f background_colour(const cv::Mat &rgb)
{
    const int b = std::max(2, std::min(rgb.rows, rgb.cols) / 100);
    std::vector<float> ch[3];
    for (int y = 0; y < rgb.rows; ++y)
        for (int x = 0; x < rgb.cols; ++x)
            if (y < b || y >= rgb.rows - b || x < b || x >= rgb.cols - b) {
                const cv::Vec3f &p = rgb.at<cv::Vec3f>(y, x);
                for (int c = 0; c < 3; ++c)
                    ch[c].push_back(p[c]);
            }
    cv::Vec3f med;
    for (int c = 0; c < 3; ++c) {
        std::nth_element(ch[c].begin(), ch[c].begin() + ch[c].size() / 2, ch[c].end());
        med[c] = ch[c][ch[c].size() / 2];
    }
    return med;
}

/* Leaf feature: CIELAB chroma relative to the background colour, counted
 * only on the yellow side (b* above the background's), in ΔE*ab units
 * (phc_colour_de76 of the a*, b* components; L* is left out).
 * Chlorophylls, carotenoids and the brown products of senescence all absorb
 * blue light, so green, yellow and brown lamina lie at b* above white paper,
 * while grey rules, shadows and blue-black ink do not.  CIELAB is
 * model/colour.h's (exact IEC 61966-2-1 and CIE 15 formulas, in double). */
static cv::Mat leaf_feature(const cv::Mat &rgb, const cv::Vec3f &bg)
{
    const double bg_rgb[3] = {bg[0], bg[1], bg[2]};
    double ref[3];
    phc_colour_srgb_to_lab(bg_rgb, ref);
    ref[0] = 0;
    cv::Mat f(rgb.size(), CV_32F);
    f.forEach<float>([&](float &o, const int *pos) {
        const cv::Vec3f &p = rgb.at<cv::Vec3f>(pos[0], pos[1]);
        const double c[3] = {p[0], p[1], p[2]};
        double lab[3];
        phc_colour_srgb_to_lab(c, lab);
        lab[0] = 0;
        o = lab[2] > ref[2] ? (float)phc_colour_de76(lab, ref) : 0.0f;
    });
    return f;
}

/* Declared in photo_bridge.h (vein maps use it too). */
double phc_photo::otsu_threshold(const cv::Mat &f32, const cv::Mat &mask, double fmax)
{
    std::vector<unsigned char> v;
    for (int y = 0; y < f32.rows; ++y) {
        const float *p = f32.ptr<float>(y);
        const unsigned char *m = mask.empty() ? nullptr : mask.ptr<unsigned char>(y);
        for (int x = 0; x < f32.cols; ++x)
            if (!m || m[x]) {
                const double t = std::min(1.0, std::max(0.0, p[x] / fmax));
                v.push_back((unsigned char)std::lround(255 * t));
            }
    }
    if (v.empty())
        return fmax;
    cv::Mat row(1, (int)v.size(), CV_8U, v.data()), dummy;
    const double t8 = cv::threshold(row, dummy, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
    return (t8 + 0.5) / 255.0 * fmax; /* pixels above bin t8 are foreground */
}

/* Fills the holes of a 0/255 mask: background not reachable from outside. */
static cv::Mat fill_holes(const cv::Mat &bin)
{
    cv::Mat pad;
    cv::copyMakeBorder(bin, pad, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
    cv::Mat reach = pad.clone();
    cv::floodFill(reach, cv::Point(0, 0), 255);
    cv::Mat holes = reach == 0;
    return bin | holes(cv::Rect(1, 1, bin.cols, bin.rows));
}

/* GrabCut (Rother, Kolmogorov and Blake 2004) on one leaf of the work image:
 * the leaf's eroded mask is certain foreground, the rest of it and a ring
 * around it probable, pixels farther out and the other leaves certain
 * background.  Returns the refined 0/255 mask of the leaf (whole-image size),
 * or the input mask when GrabCut collapses or explodes (area outside
 * [1/2, 2] times the input): the colour model then failed, not the leaf. */
static cv::Mat grabcut_leaf(const cv::Mat &bgr8, const cv::Mat &labels, int label, int iterations)
{
    cv::Mat own = labels == label;
    const cv::Rect box = cv::boundingRect(own);
    const int ring = std::max(3, std::max(box.width, box.height) / 40);
    const int margin = 2 * ring + 2;
    const cv::Rect roi = (box + cv::Size(2 * margin, 2 * margin) - cv::Point(margin, margin)) &
                         cv::Rect(0, 0, labels.cols, labels.rows);
    cv::Mat o = own(roi), others = (labels(roi) != label) & (labels(roi) != 0);
    cv::Mat grown, core;
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * ring + 1, 2 * ring + 1));
    cv::dilate(o, grown, k);
    cv::erode(o, core, k);
    cv::Mat gc(roi.size(), CV_8U, cv::Scalar(cv::GC_BGD));
    gc.setTo(cv::GC_PR_BGD, grown);
    gc.setTo(cv::GC_PR_FGD, o);
    gc.setTo(cv::GC_FGD, core);
    gc.setTo(cv::GC_BGD, others);
    const int n_in = cv::countNonZero(o);
    cv::Mat out = cv::Mat::zeros(labels.size(), CV_8U);
    if (cv::countNonZero(gc == cv::GC_BGD) == 0 || n_in < 16) {
        o.copyTo(out(roi));
        return out;
    }
    cv::theRNG().state = 0x5eed1234u; /* GrabCut's k-means: same input, same output */
    cv::Mat bgd, fgd;
    cv::grabCut(bgr8(roi), gc, cv::Rect(), bgd, fgd, iterations, cv::GC_INIT_WITH_MASK);
    cv::Mat fg = (gc == cv::GC_FGD) | (gc == cv::GC_PR_FGD);
    /* keep the component holding the certain core (or the largest) */
    cv::Mat cc, stats, cent;
    const int n = cv::connectedComponentsWithStats(fg, cc, stats, cent, 8, CV_32S);
    int best = 0, best_area = 0;
    for (int i = 1; i < n; ++i) {
        const int a = stats.at<int>(i, cv::CC_STAT_AREA);
        if (a > best_area) {
            best = i;
            best_area = a;
        }
    }
    if (best == 0 || best_area < n_in / 2 || best_area > 2 * n_in) {
        o.copyTo(out(roi));
        return out;
    }
    fill_holes(cc == best).copyTo(out(roi));
    return out;
}

struct leaf_rec {
    int label;                   /* in the work image */
    double x0, y0, x1, y1, cx;   /* work-image box and centroid x */
};

/* Reading order (see photo.h): rows by vertical extent, then left to right. */
static std::vector<int> reading_order(std::vector<leaf_rec> leaves)
{
    std::sort(leaves.begin(), leaves.end(),
              [](const leaf_rec &a, const leaf_rec &b) { return a.y0 < b.y0; });
    std::vector<std::vector<leaf_rec>> rows;
    for (const leaf_rec &l : leaves) {
        if (!rows.empty()) {
            const leaf_rec &first = rows.back().front();
            if (l.y0 <= first.y1 - 0.5 * (first.y1 - first.y0)) {
                rows.back().push_back(l);
                continue;
            }
        }
        rows.push_back({l});
    }
    std::vector<int> order;
    for (auto &r : rows) {
        std::sort(r.begin(), r.end(), [](const leaf_rec &a, const leaf_rec &b) { return a.cx < b.cx; });
        for (const leaf_rec &l : r)
            order.push_back(l.label);
    }
    return order;
}

/* Work-image labels (0 background, 1..n) -> full-size labels: each leaf's
 * mask is enlarged bilinearly on its own box and thresholded at 1/2, which
 * gives smooth outlines instead of nearest-neighbour blocks. */
static void upscale_labels(const cv::Mat &small, int n, cv::Mat &full)
{
    const double sx = (double)full.cols / small.cols, sy = (double)full.rows / small.rows;
    for (int lab = 1; lab <= n; ++lab) {
        cv::Mat own = small == lab;
        cv::Rect b = cv::boundingRect(own);
        b = (b + cv::Size(4, 4) - cv::Point(2, 2)) & cv::Rect(0, 0, small.cols, small.rows);
        const int X0 = (int)std::floor(b.x * sx), Y0 = (int)std::floor(b.y * sy);
        const int X1 = std::min(full.cols, (int)std::ceil((b.x + b.width) * sx));
        const int Y1 = std::min(full.rows, (int)std::ceil((b.y + b.height) * sy));
        cv::Mat f, big;
        own(b).convertTo(f, CV_32F, 1.0 / 255);
        /* exact geometric mapping of the box, pixel centres aligned */
        cv::Mat A = (cv::Mat_<double>(2, 3) << 1 / sx, 0, 0.5 / sx - 0.5 + X0 / sx - b.x, 0, 1 / sy,
                     0.5 / sy - 0.5 + Y0 / sy - b.y);
        cv::warpAffine(f, big, A, cv::Size(X1 - X0, Y1 - Y0), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                       cv::BORDER_CONSTANT, 0);
        cv::Mat dst = full(cv::Rect(X0, Y0, X1 - X0, Y1 - Y0));
        cv::Mat take = (big >= 0.5f) & (dst == 0);
        dst.setTo(lab, take);
    }
}

/* Boxes, areas and centroids from full-size labels. */
static void measure_leaves(const cv::Mat &labels, size_t n, phc_leaf_box *leaf)
{
    std::vector<double> sx(n, 0), sy(n, 0);
    for (size_t i = 0; i < n; ++i) {
        leaf[i].x0 = leaf[i].y0 = SIZE_MAX;
        leaf[i].x1 = leaf[i].y1 = leaf[i].area = 0;
    }
    for (int y = 0; y < labels.rows; ++y) {
        const int *p = labels.ptr<int>(y);
        for (int x = 0; x < labels.cols; ++x)
            if (p[x] > 0) {
                phc_leaf_box &b = leaf[p[x] - 1];
                b.x0 = std::min(b.x0, (size_t)x);
                b.y0 = std::min(b.y0, (size_t)y);
                b.x1 = std::max(b.x1, (size_t)x + 1);
                b.y1 = std::max(b.y1, (size_t)y + 1);
                b.area++;
                sx[p[x] - 1] += x;
                sy[p[x] - 1] += y;
            }
    }
    for (size_t i = 0; i < n; ++i) {
        if (!leaf[i].area)
            leaf[i].x0 = leaf[i].y0 = 0;
        leaf[i].cx = leaf[i].area ? sx[i] / leaf[i].area : 0;
        leaf[i].cy = leaf[i].area ? sy[i] / leaf[i].area : 0;
    }
}

/* Hysteresis thresholding (as in Canny 1986): the connected regions above
 * `low` that contain a pixel above `high`.  Otsu's threshold on the chroma
 * falls between the paper and the typical leaf; the darkest green leaves
 * (L* ~ 25, chroma ~ 15-20 on the ivy scan) straddle it and are recovered
 * down to half of it, which the paper (chroma < 3) never reaches. */
static cv::Mat hysteresis(const cv::Mat &f, double high, double low)
{
    cv::Mat lo = f > low, cc;
    const int n = cv::connectedComponents(lo, cc, 8, CV_32S);
    std::vector<unsigned char> seeded(n, 0);
    for (int y = 0; y < f.rows; ++y) {
        const float *p = f.ptr<float>(y);
        const int *c = cc.ptr<int>(y);
        for (int x = 0; x < f.cols; ++x)
            if (p[x] > high)
                seeded[c[x]] = 1;
    }
    cv::Mat out(f.size(), CV_8U);
    for (int y = 0; y < f.rows; ++y) {
        const int *c = cc.ptr<int>(y);
        unsigned char *o = out.ptr<unsigned char>(y);
        for (int x = 0; x < f.cols; ++x)
            o[x] = c[x] > 0 && seeded[c[x]] ? 255 : 0;
    }
    return out;
}

/* Candidate leaves of the work image: Otsu on the leaf feature, opening,
 * holes filled, components below min_area_fraction of the largest dropped.
 * Returns the number of leaves; labels are 1..n in no particular order. */
static int candidate_leaves(const cv::Mat &rgb, double min_area_fraction, cv::Mat &labels,
                            double *threshold)
{
    const cv::Vec3f bg = background_colour(rgb);
    cv::Mat f = leaf_feature(rgb, bg);
    double fmax;
    cv::minMaxLoc(f, nullptr, &fmax);
    fmax = std::max(fmax, 1.0);
    *threshold = otsu_threshold(f, cv::Mat(), fmax);
    cv::Mat bin = hysteresis(f, *threshold, 0.5 * *threshold);
    cv::morphologyEx(bin, bin, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
    bin = fill_holes(bin);
    cv::Mat cc, stats, cent;
    const int n = cv::connectedComponentsWithStats(bin, cc, stats, cent, 8, CV_32S);
    int amax = 0;
    for (int i = 1; i < n; ++i)
        amax = std::max(amax, stats.at<int>(i, cv::CC_STAT_AREA));
    std::vector<int> lut(n, 0);
    int kept = 0;
    for (int i = 1; i < n; ++i)
        if (stats.at<int>(i, cv::CC_STAT_AREA) >= min_area_fraction * amax &&
            stats.at<int>(i, cv::CC_STAT_AREA) >= 4)
            lut[i] = ++kept;
    labels = cc;
    for (int y = 0; y < labels.rows; ++y) {
        int *p = labels.ptr<int>(y);
        for (int x = 0; x < labels.cols; ++x)
            p[x] = lut[p[x]];
    }
    return kept;
}

extern "C" int phc_photo_segment_leaves(const phc_image *img, const phc_segment_options *opt,
                                        phc_segmentation *out, phc_error *err)
{
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_segment_leaves: no output");
    std::memset(out, 0, sizeof *out);
    int rc = check_image(img, "phc_photo_segment_leaves", err);
    if (rc)
        return rc;
    const phc_segment_options o = opt ? *opt : phc_segment_options_default();
    if (!(o.min_area_fraction >= 0 && o.min_area_fraction <= 1) || o.grabcut_iterations < 0 ||
        !(o.downscale_to >= 0) || (o.downscale_to > 0 && o.downscale_to < 16))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_segment_leaves: invalid options (min_area_fraction %g in "
                             "[0, 1], grabcut_iterations %d >= 0, downscale_to %g: 0 or >= 16)",
                             o.min_area_fraction, o.grabcut_iterations, o.downscale_to);
    try {
        /* work copy: float RGB, long side at most downscale_to */
        const double longest = (double)std::max(img->width, img->height);
        const double s = o.downscale_to > 0 && longest > o.downscale_to ? o.downscale_to / longest : 1;
        cv::Mat rgb;
        mat_of(img).convertTo(rgb, CV_32F);
        if (s < 1)
            cv::resize(rgb, rgb,
                       cv::Size(std::max(1, (int)std::lround(img->width * s)),
                                std::max(1, (int)std::lround(img->height * s))),
                       0, 0, cv::INTER_AREA);
        cv::Mat labels;
        const int n = candidate_leaves(rgb, o.min_area_fraction, labels, &out->threshold);
        if (n == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "no leaf found (Otsu threshold %.3g on the "
                                 "leaf chroma)", out->threshold);
        if (o.grabcut && o.grabcut_iterations > 0) {
            cv::Mat bgr8, refined = cv::Mat::zeros(labels.size(), CV_32S);
            rgb.convertTo(bgr8, CV_8U, 255);
            cv::cvtColor(bgr8, bgr8, cv::COLOR_RGB2BGR);
            for (int lab = 1; lab <= n; ++lab) {
                cv::Mat m = grabcut_leaf(bgr8, labels, lab, o.grabcut_iterations);
                refined.setTo(lab, m & (refined == 0));
            }
            labels = refined;
        }
        std::vector<leaf_rec> recs;
        for (int lab = 1; lab <= n; ++lab) {
            cv::Mat own = labels == lab;
            const cv::Rect b = cv::boundingRect(own);
            const cv::Moments mo = cv::moments(own, true);
            if (mo.m00 > 0)
                recs.push_back({lab, (double)b.x, (double)b.y, (double)(b.x + b.width),
                                (double)(b.y + b.height), mo.m10 / mo.m00});
        }
        const std::vector<int> order = reading_order(recs);
        std::vector<int> lut(n + 1, 0);
        for (size_t i = 0; i < order.size(); ++i)
            lut[order[i]] = (int)i + 1;
        for (int y = 0; y < labels.rows; ++y) {
            int *p = labels.ptr<int>(y);
            for (int x = 0; x < labels.cols; ++x)
                p[x] = lut[p[x]];
        }
        const size_t count = order.size(), w = img->width, h = img->height;
        out->labels = (int *)std::calloc(w * h, sizeof(int));
        out->leaf = (phc_leaf_box *)std::calloc(count, sizeof(phc_leaf_box));
        if (!out->labels || !out->leaf) {
            phc_segmentation_free(out);
            return phc_error_set(err, PHC_ERR_NOMEM, "phc_photo_segment_leaves: out of memory");
        }
        out->width = w;
        out->height = h;
        out->count = count;
        cv::Mat full((int)h, (int)w, CV_32S, out->labels);
        if (s < 1)
            upscale_labels(labels, (int)count, full);
        else
            labels.copyTo(full);
        measure_leaves(full, count, out->leaf);
        return PHC_OK;
    }
    catch (...) {
        phc_segmentation_free(out);
        try {
            throw;
        }
        PHOTO_CATCH(err, "phc_photo_segment_leaves")
    }
}

extern "C" int phc_photo_crop_leaf(const phc_image *img, const phc_segmentation *seg,
                                   size_t number, size_t margin, phc_image *leaf_img,
                                   unsigned char **mask, phc_error *err)
{
    if (!leaf_img || !mask)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_crop_leaf: no output");
    std::memset(leaf_img, 0, sizeof *leaf_img);
    *mask = NULL;
    int rc = check_image(img, "phc_photo_crop_leaf", err);
    if (rc)
        return rc;
    if (!seg || !seg->labels || seg->width != img->width || seg->height != img->height)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_crop_leaf: segmentation (%zux%zu) does not match the "
                             "image (%zux%zu)", seg ? seg->width : 0, seg ? seg->height : 0,
                             img->width, img->height);
    if (number < 1 || number > seg->count)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_crop_leaf: leaf %zu of %zu", number,
                             seg->count);
    const phc_leaf_box &b = seg->leaf[number - 1];
    if (b.area == 0 || b.x1 <= b.x0 || b.y1 <= b.y0)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_crop_leaf: leaf %zu is empty", number);
    const size_t x0 = b.x0 > margin ? b.x0 - margin : 0, y0 = b.y0 > margin ? b.y0 - margin : 0;
    const size_t x1 = std::min(img->width, b.x1 + margin), y1 = std::min(img->height, b.y1 + margin);
    const size_t cw = x1 - x0, ch = y1 - y0;
    if ((rc = phc_image_alloc(leaf_img, cw, ch, err)))
        return rc;
    unsigned char *m = (unsigned char *)std::malloc(cw * ch);
    if (!m) {
        phc_image_free(leaf_img);
        return phc_error_set(err, PHC_ERR_NOMEM, "phc_photo_crop_leaf: out of memory");
    }
    for (size_t y = 0; y < ch; ++y)
        for (size_t x = 0; x < cw; ++x) {
            const size_t src = (x0 + x) + img->width * (y0 + y), dst = x + cw * y;
            std::memcpy(leaf_img->data + 3 * dst, img->data + 3 * src, 3 * sizeof(double));
            m[dst] = seg->labels[src] == (int)number;
        }
    leaf_img->bit_depth = img->bit_depth;
    *mask = m;
    return PHC_OK;
}
