/* measurements/photo_draw_bridge.cc: text on images and the viridis colour
 * map (measurements/photo.h; OpenCV imgproc).  What the photo bridge files
 * share is in photo_bridge.h. */
#include "measurements/photo_bridge.h"

#include <opencv2/imgproc.hpp>

using namespace phc_photo;

extern "C" int phc_photo_draw_text(phc_image *img, const char *text, size_t x, size_t y, double scale,
                                   phc_error *err)
{
    int rc;
    if (!text)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_draw_text: no text");
    if ((rc = check_image(img, "phc_photo_draw_text", err)))
        return rc;
    if (!(scale > 0 && scale < 100) || x > (size_t)INT_MAX || y > (size_t)INT_MAX)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_draw_text: invalid scale %g or position", scale);
    try {
        cv::Mat m = mat_of(img);
        /* anti-aliased Hershey simplex; thickness 1 stays readable at 0.5 */
        cv::putText(m, text, cv::Point((int)x, (int)y), cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar::all(0), 1,
                    cv::LINE_AA);
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_draw_text")
}

extern "C" int phc_photo_viridis(double lut[3 * 256], phc_error *err)
{
    if (!lut)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_viridis: no output");
    try {
        cv::Mat ramp(1, 256, CV_8U), bgr;
        for (int i = 0; i < 256; ++i)
            ramp.at<unsigned char>(0, i) = (unsigned char)i;
        cv::applyColorMap(ramp, bgr, cv::COLORMAP_VIRIDIS);
        for (int i = 0; i < 256; ++i) {
            const cv::Vec3b c = bgr.at<cv::Vec3b>(0, i);
            lut[3 * i] = c[2] / 255.0; /* R G B order */
            lut[3 * i + 1] = c[1] / 255.0;
            lut[3 * i + 2] = c[0] / 255.0;
        }
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_viridis")
}
