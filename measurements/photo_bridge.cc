/* measurements/photo_bridge.cc: the OpenCV bridge of measurements/photo.h.
 *
 * The only file of phytocal that touches OpenCV (DESIGN §2).  Every
 * extern "C" function catches every exception (PHOTO_CATCH below) and turns
 * it into a status and a one-line message; sizes are validated before any
 * OpenCV call; nothing is printed and nothing keeps state between calls.
 *
 * Internally images are cv::Mat in R G B order (not OpenCV's usual BGR):
 * CV_64FC3 headers over phc_image data, CV_32F copies where OpenCV needs
 * single precision (ECC, GrabCut's 8-bit input is made explicitly). */
#include "measurements/photo.h"

#include "model/colour.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/mcc.hpp>
#include <opencv2/mcc/ccm.hpp>
#include <opencv2/video/tracking.hpp>

#include <fcntl.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

/* ---- errors -------------------------------------------------------------------- */

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

/* A size OpenCV can index (cv::Mat dimensions are int) whose 3-channel
 * double buffer does not overflow size_t. */
static bool size_ok(size_t w, size_t h)
{
    return w > 0 && h > 0 && w <= (size_t)INT_MAX && h <= (size_t)INT_MAX &&
           w <= SIZE_MAX / 3 / sizeof(double) / h;
}

static int check_image(const phc_image *img, const char *what, phc_error *err)
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
static cv::Mat mat_of(const phc_image *img)
{
    return cv::Mat((int)img->height, (int)img->width, CV_64FC3, (void *)img->data);
}

static int mat_of_mask(const unsigned char *mask, size_t w, size_t h, cv::Mat &out)
{
    out = cv::Mat((int)h, (int)w, CV_8U, (void *)mask);
    return PHC_OK;
}

/* ---- sRGB transfer function (IEC 61966-2-1) and CIELAB (D65) ------------------ */

static double srgb_decode(double v)
{
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

static double srgb_encode(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

/* Linear sRGB -> CIELAB (D65, 2°): IEC 61966-2-1 matrix, CIE 15 Lab.  Kept
 * on linear values (not phc_colour_srgb_to_lab) because the ColorChecker's
 * cyan patch lies slightly outside the sRGB gamut (negative linear red),
 * which the gamma encoding cannot represent. */
static void linear_to_lab(const double rgb[3], double lab[3])
{
    const double X = 0.4124564 * rgb[0] + 0.3575761 * rgb[1] + 0.1804375 * rgb[2];
    const double Y = 0.2126729 * rgb[0] + 0.7151522 * rgb[1] + 0.0721750 * rgb[2];
    const double Z = 0.0193339 * rgb[0] + 0.1191920 * rgb[1] + 0.9503041 * rgb[2];
    const double wx = 0.95047, wy = 1.0, wz = 1.08883;
    auto f = [](double t) {
        const double d = 6.0 / 29.0;
        return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29.0;
    };
    const double fx = f(X / wx), fy = f(Y / wy), fz = f(Z / wz);
    lab[0] = 116 * fy - 16;
    lab[1] = 500 * (fx - fy);
    lab[2] = 200 * (fy - fz);
}

/* ---- files ------------------------------------------------------------------------ */

static const char *base_name(const char *path)
{
    const char *s = std::strrchr(path, '/');
    return s ? s + 1 : path;
}

/* Reads the whole file: PHC_ERR_IO "cannot open" when it cannot be opened. */
static int slurp(const char *path, std::vector<unsigned char> &bytes, phc_error *err)
{
    FILE *f = std::fopen(path, "rb");
    if (!f)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open: %s", path, std::strerror(errno));
    unsigned char chunk[1 << 16];
    size_t n;
    while ((n = std::fread(chunk, 1, sizeof chunk, f)) > 0)
        bytes.insert(bytes.end(), chunk, chunk + n);
    const bool bad = std::ferror(f);
    const int e = errno;
    std::fclose(f);
    if (bad)
        return phc_error_set(err, PHC_ERR_IO, "%s: read error: %s", path, std::strerror(e));
    if (bytes.empty())
        return phc_error_set(err, PHC_ERR_INPUT, "%s: empty file", path);
    return PHC_OK;
}

enum file_kind { KIND_UNKNOWN, KIND_JPEG, KIND_PNG, KIND_TIFF };

static file_kind sniff(const std::vector<unsigned char> &b)
{
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF)
        return KIND_JPEG;
    if (b.size() >= 8 && !std::memcmp(b.data(), png, 8))
        return KIND_PNG;
    if (b.size() >= 4 && ((b[0] == 'I' && b[1] == 'I' && b[2] == 42 && b[3] == 0) ||
                          (b[0] == 'M' && b[1] == 'M' && b[2] == 0 && b[3] == 42)))
        return KIND_TIFF;
    return KIND_UNKNOWN;
}

/* True when a JPEG's marker structure (ITU-T T.81 Annex B) reaches its
 * end-of-image marker FFD9.  Segments are skipped by their length (so an
 * EXIF thumbnail's own FFD9 does not count), entropy-coded data after each
 * start-of-scan is scanned for the next marker (FF00 is a stuffed byte,
 * FFD0-FFD7 restart markers).  Bytes after EOI (padding, vendor trailers)
 * are allowed.  Junk between segments is skipped as libjpeg does. */
static bool jpeg_complete(const std::vector<unsigned char> &b)
{
    const size_t n = b.size();
    size_t i = 2; /* after SOI */
    while (i < n) {
        while (i < n && b[i] != 0xFF) /* junk before a marker */
            ++i;
        while (i < n && b[i] == 0xFF) /* fill bytes */
            ++i;
        if (i >= n)
            return false;
        const unsigned m = b[i++];
        if (m == 0xD9)
            return true;
        if (m == 0x01 || (m >= 0xD0 && m <= 0xD8)) /* standalone markers */
            continue;
        if (i + 2 > n)
            return false;
        const size_t len = ((size_t)b[i] << 8) | b[i + 1];
        if (len < 2 || len > n - i)
            return false;
        i += len;
        if (m == 0xDA) { /* start of scan: skip the entropy-coded data */
            while (i + 1 < n && !(b[i] == 0xFF && b[i + 1] != 0x00 && b[i + 1] != 0xFF &&
                                  !(b[i + 1] >= 0xD0 && b[i + 1] <= 0xD7)))
                ++i;
            if (i + 1 >= n)
                return false;
        }
    }
    return false;
}

/* True when a PNG's chunk list (PNG spec. §5.3) reaches its IEND chunk. */
static bool png_complete(const std::vector<unsigned char> &b)
{
    const size_t n = b.size();
    size_t i = 8;
    while (i + 8 <= n) {
        const size_t len = ((size_t)b[i] << 24) | ((size_t)b[i + 1] << 16) |
                           ((size_t)b[i + 2] << 8) | b[i + 3];
        if (!std::memcmp(&b[i + 4], "IEND", 4))
            return true;
        if (len > n - i - 8)
            return false;
        i += 12 + len; /* length, type, data, CRC */
    }
    return false;
}

/* Reads, checks and decodes a file into an 8- or 16-bit cv::Mat with 1 to 4
 * channels (OpenCV's channel order).  libjpeg and libpng would decode a
 * truncated file into a partly grey picture with only a warning on stderr,
 * hence the structural checks before decoding. */
static int decode_file(const char *path, cv::Mat &m, phc_error *err)
{
    std::vector<unsigned char> bytes;
    int rc = slurp(path, bytes, err);
    if (rc)
        return rc;
    if (bytes.size() > (size_t)INT_MAX)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: file larger than 2 GiB", path);
    const file_kind kind = sniff(bytes);
    if (kind == KIND_JPEG && !jpeg_complete(bytes))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: truncated JPEG (no end-of-image marker)",
                             path);
    if (kind == KIND_PNG && !png_complete(bytes))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: truncated PNG (no IEND chunk)", path);
    /* IMREAD_UNCHANGED (= -1) keeps the bit depth (IMREAD_ANYDEPTH), the
     * channel count (IMREAD_ANYCOLOR) and alpha, and ignores EXIF
     * orientation.  imdecode on the bytes already read avoids reading the
     * file twice. */
    m = cv::imdecode(cv::Mat(1, (int)bytes.size(), CV_8U, bytes.data()), cv::IMREAD_UNCHANGED);
    if (m.empty())
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s", path,
                             kind == KIND_UNKNOWN ? "not a PNG, JPEG or TIFF image"
                                                  : "cannot be decoded (corrupt image data)");
    if (m.dims != 2 || m.channels() > 4)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %d channels, 1 to 4 expected", path,
                             m.channels());
    if (m.depth() != CV_8U && m.depth() != CV_16U)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: %s samples, 8- or 16-bit unsigned integers expected", path,
                             m.depth() == CV_32F || m.depth() == CV_64F ? "floating-point"
                                                                        : "unsupported");
    return PHC_OK;
}

/* Writes bytes to path through a temporary name in the same directory,
 * renamed into place (atomic on POSIX); created with mode 0666 & ~umask. */
static int write_atomic(const char *path, const std::vector<unsigned char> &buf, phc_error *err)
{
    std::string tmp;
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        tmp = std::string(path) + ".tmp." + std::to_string((long)getpid()) + "." +
              std::to_string(attempt);
        fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0666);
        if (fd < 0 && errno != EEXIST)
            break;
    }
    if (fd < 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot create %s: %s", path, tmp.c_str(),
                             std::strerror(errno));
    size_t done = 0;
    while (done < buf.size()) {
        const ssize_t k = write(fd, buf.data() + done, buf.size() - done);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            const int e = errno;
            close(fd);
            unlink(tmp.c_str());
            return phc_error_set(err, PHC_ERR_IO, "%s: write error: %s", path, std::strerror(e));
        }
        done += (size_t)k;
    }
    if (close(fd) != 0 || std::rename(tmp.c_str(), path) != 0) {
        const int e = errno;
        unlink(tmp.c_str());
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write: %s", path, std::strerror(e));
    }
    return PHC_OK;
}

/* The encoder's extension from the path: ".png", ".tif" or ".jpg". */
static int encoder_for(const char *path, int bit_depth, std::string &ext, phc_error *err)
{
    const char *dot = std::strrchr(base_name(path), '.');
    std::string e = dot ? dot : "";
    for (char &c : e)
        c = (char)std::tolower((unsigned char)c);
    if (e == ".png")
        ext = ".png";
    else if (e == ".tif" || e == ".tiff")
        ext = ".tiff";
    else if (e == ".jpg" || e == ".jpeg")
        ext = ".jpg";
    else
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: unknown image extension '%s' (.png, .tif, .tiff, .jpg expected)",
                             path, e.c_str());
    if (bit_depth != 8 && bit_depth != 16)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: bit depth %d (8 or 16 expected)", path,
                             bit_depth);
    if (bit_depth == 16 && ext == ".jpg")
        return phc_error_set(err, PHC_ERR_INVALID, "%s: JPEG holds 8-bit samples only", path);
    return PHC_OK;
}

/* ---- images -------------------------------------------------------------------------- */

extern "C" int phc_image_alloc(phc_image *img, size_t width, size_t height, phc_error *err)
{
    if (!img)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_image_alloc: no image");
    std::memset(img, 0, sizeof *img);
    if (!size_ok(width, height))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_image_alloc: invalid size %zux%zu", width,
                             height);
    img->data = (double *)std::calloc(3 * width * height, sizeof(double));
    if (!img->data)
        return phc_error_set(err, PHC_ERR_NOMEM, "phc_image_alloc: out of memory (%zux%zu)",
                             width, height);
    img->width = width;
    img->height = height;
    img->bit_depth = 8;
    return PHC_OK;
}

extern "C" void phc_image_free(phc_image *img)
{
    if (!img)
        return;
    std::free(img->data);
    std::memset(img, 0, sizeof *img);
}

/* 8- or 16-bit cv::Mat (OpenCV channel order, 1-4 channels) -> phc_image. */
static int image_from_mat(const cv::Mat &m, const char *what, phc_image *out, phc_error *err)
{
    cv::Mat rgb;
    switch (m.channels()) {
    case 1: cv::cvtColor(m, rgb, cv::COLOR_GRAY2RGB); break;
    case 2: { /* grey + alpha */
        cv::Mat g;
        cv::extractChannel(m, g, 0);
        cv::cvtColor(g, rgb, cv::COLOR_GRAY2RGB);
        break;
    }
    case 3: cv::cvtColor(m, rgb, cv::COLOR_BGR2RGB); break;
    default: cv::cvtColor(m, rgb, cv::COLOR_BGRA2RGB); break;
    }
    (void)what;
    int rc = phc_image_alloc(out, (size_t)m.cols, (size_t)m.rows, err);
    if (rc)
        return rc;
    const int depth = m.depth() == CV_16U ? 16 : 8;
    cv::Mat dst = mat_of(out);
    rgb.convertTo(dst, CV_64F, 1.0 / (depth == 16 ? 65535.0 : 255.0));
    out->bit_depth = depth;
    return PHC_OK;
}

extern "C" int phc_photo_read(const char *path, phc_image *out, phc_error *err)
{
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_read: no output");
    std::memset(out, 0, sizeof *out);
    if (!path)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_read: no path");
    try {
        cv::Mat m;
        int rc = decode_file(path, m, err);
        if (rc)
            return rc;
        return image_from_mat(m, path, out, err);
    }
    PHOTO_CATCH(err, path)
}

/* The image as 8- or 16-bit BGR for the encoders: values clipped to [0, 1]
 * and rounded.  Non-finite values are an error, not a silent 0. */
static int to_integer_bgr(const phc_image *img, int bit_depth, const char *what, cv::Mat &bgr,
                          phc_error *err)
{
    const size_t n = 3 * img->width * img->height;
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(img->data[i])) {
            const size_t p = i / 3;
            return phc_error_set(err, PHC_ERR_INVALID, "%s: pixel (%zu, %zu) is not finite", what,
                                 p % img->width, p / img->width);
        }
    cv::Mat rgb;
    const double scale = bit_depth == 16 ? 65535.0 : 255.0;
    mat_of(img).convertTo(rgb, bit_depth == 16 ? CV_16U : CV_8U, scale); /* saturates */
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    return PHC_OK;
}

extern "C" int phc_photo_write(const char *path, const phc_image *img, int bit_depth,
                               phc_error *err)
{
    if (!path)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_write: no path");
    int rc = check_image(img, path, err);
    if (rc)
        return rc;
    try {
        std::string ext;
        if ((rc = encoder_for(path, bit_depth, ext, err)))
            return rc;
        cv::Mat bgr;
        if ((rc = to_integer_bgr(img, bit_depth, path, bgr, err)))
            return rc;
        std::vector<unsigned char> buf;
        std::vector<int> params;
        if (ext == ".jpg")
            params = {cv::IMWRITE_JPEG_QUALITY, 95};
        if (!cv::imencode(ext, bgr, buf, params))
            return phc_error_set(err, PHC_ERR_INTERNAL, "%s: OpenCV could not encode %s", path,
                                 ext.c_str());
        return write_atomic(path, buf, err);
    }
    PHOTO_CATCH(err, path)
}

extern "C" int phc_photo_write_png(const char *path, const phc_image *img, phc_error *err)
{
    if (!path)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_write_png: no path");
    const char *dot = std::strrchr(base_name(path), '.');
    if (!dot || strcasecmp(dot, ".png") != 0)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: a PNG file name (.png) expected", path);
    return phc_photo_write(path, img, 8, err);
}

extern "C" int phc_photo_write_map_png(const char *path, size_t width, size_t height,
                                       const double *values, const unsigned char *mask, double lo,
                                       double hi, int colour_map, phc_error *err)
{
    if (!path || !values)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_write_map_png: no %s",
                             path ? "values" : "path");
    if (!size_ok(width, height))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: invalid map size %zux%zu", path, width,
                             height);
    if (!(std::isfinite(lo) && std::isfinite(hi) && hi > lo))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: colour range [%g, %g] is empty", path, lo,
                             hi);
    try {
        cv::Mat grey((int)height, (int)width, CV_8U);
        for (size_t i = 0; i < width * height; ++i) {
            const double v = values[i];
            if ((!mask || mask[i]) && !std::isfinite(v))
                return phc_error_set(err, PHC_ERR_INVALID, "%s: value at (%zu, %zu) is not finite",
                                     path, i % width, i / width);
            const double t = std::isfinite(v) ? (v - lo) / (hi - lo) : 0;
            grey.data[i] = (unsigned char)std::lround(255 * std::min(1.0, std::max(0.0, t)));
        }
        cv::Mat pic; /* grey levels: a 1-channel PNG; viridis: BGR */
        if (colour_map)
            cv::applyColorMap(grey, pic, cv::COLORMAP_VIRIDIS);
        else
            pic = grey;
        if (mask) {
            cv::Mat off;
            mat_of_mask(mask, width, height, off);
            pic.setTo(cv::Scalar::all(255), off == 0);
        }
        std::vector<unsigned char> buf;
        if (!cv::imencode(".png", pic, buf))
            return phc_error_set(err, PHC_ERR_INTERNAL, "%s: OpenCV could not encode PNG", path);
        return write_atomic(path, buf, err);
    }
    PHOTO_CATCH(err, path)
}

/* Area averaging when shrinking both ways, bilinear otherwise. */
static int interpolation_for(size_t w, size_t h, size_t nw, size_t nh)
{
    return nw <= w && nh <= h ? cv::INTER_AREA : cv::INTER_LINEAR;
}

extern "C" int phc_photo_read_map(const char *path, size_t width, size_t height, int resize,
                                  double **values, phc_error *err)
{
    if (!values)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_read_map: no output");
    *values = NULL;
    if (!path)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_read_map: no path");
    if (!size_ok(width, height))
        return phc_error_set(err, PHC_ERR_INVALID, "%s: invalid map size %zux%zu requested", path,
                             width, height);
    try {
        cv::Mat m, grey;
        int rc = decode_file(path, m, err);
        if (rc)
            return rc;
        switch (m.channels()) {
        case 1: grey = m; break;
        case 2: cv::extractChannel(m, grey, 0); break;
        case 3: cv::cvtColor(m, grey, cv::COLOR_BGR2GRAY); break;
        default: cv::cvtColor(m, grey, cv::COLOR_BGRA2GRAY); break;
        }
        const size_t mw = (size_t)grey.cols, mh = (size_t)grey.rows;
        if ((mw != width || mh != height) && !resize)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: map is %zux%zu pixels, expected %zux%zu",
                                 path, mw, mh, width, height);
        cv::Mat g64;
        grey.convertTo(g64, CV_64F, 1.0 / (grey.depth() == CV_16U ? 65535.0 : 255.0));
        double *v = (double *)std::malloc(width * height * sizeof *v);
        if (!v)
            return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        cv::Mat dst((int)height, (int)width, CV_64F, v);
        if (mw != width || mh != height)
            cv::resize(g64, dst, dst.size(), 0, 0, interpolation_for(mw, mh, width, height));
        else
            g64.copyTo(dst);
        *values = v;
        return PHC_OK;
    }
    PHOTO_CATCH(err, path)
}

extern "C" int phc_photo_resize(const phc_image *img, size_t width, size_t height, phc_image *out,
                                phc_error *err)
{
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_resize: no output");
    std::memset(out, 0, sizeof *out);
    int rc = check_image(img, "phc_photo_resize", err);
    if (rc)
        return rc;
    if (!size_ok(width, height))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_resize: invalid size %zux%zu", width,
                             height);
    try {
        if ((rc = phc_image_alloc(out, width, height, err)))
            return rc;
        cv::Mat dst = mat_of(out);
        cv::resize(mat_of(img), dst, dst.size(), 0, 0,
                   interpolation_for(img->width, img->height, width, height));
        out->bit_depth = img->bit_depth;
        return PHC_OK;
    }
    catch (...) {
        phc_image_free(out);
        try {
            throw;
        }
        PHOTO_CATCH(err, "phc_photo_resize")
    }
}

extern "C" int phc_photo_resize_mask(const unsigned char *mask, size_t width, size_t height,
                                     size_t new_width, size_t new_height, unsigned char **out,
                                     phc_error *err)
{
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_resize_mask: no output");
    *out = NULL;
    if (!mask)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_photo_resize_mask: no mask");
    if (!size_ok(width, height) || !size_ok(new_width, new_height))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_photo_resize_mask: invalid size %zux%zu -> %zux%zu", width,
                             height, new_width, new_height);
    try {
        cv::Mat src;
        mat_of_mask(mask, width, height, src);
        cv::Mat bin = src != 0, res; /* 0/255 */
        const bool shrink = new_width <= width && new_height <= height;
        cv::Mat f, r;
        if (shrink) {
            /* leaf fraction of the area each new pixel covers, then >= 1/2 */
            bin.convertTo(f, CV_32F, 1.0 / 255);
            cv::resize(f, r, cv::Size((int)new_width, (int)new_height), 0, 0, cv::INTER_AREA);
            res = r >= 0.5f;
        } else {
            cv::resize(bin, res, cv::Size((int)new_width, (int)new_height), 0, 0,
                       cv::INTER_NEAREST);
        }
        unsigned char *o = (unsigned char *)std::malloc(new_width * new_height);
        if (!o)
            return phc_error_set(err, PHC_ERR_NOMEM, "phc_photo_resize_mask: out of memory");
        for (size_t y = 0; y < new_height; ++y) {
            const unsigned char *row = res.ptr<unsigned char>((int)y);
            for (size_t x = 0; x < new_width; ++x)
                o[x + new_width * y] = row[x] ? 1 : 0;
        }
        *out = o;
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_resize_mask")
}

/* ---- leaf segmentation ---------------------------------------------------------------- */

extern "C" phc_segment_options phc_segment_options_default(void)
{
    phc_segment_options o;
    o.min_area_fraction = 0.05;
    o.grabcut = 1;
    o.grabcut_iterations = 3;
    o.downscale_to = 1200;
    return o;
}

extern "C" void phc_segmentation_free(phc_segmentation *seg)
{
    if (!seg)
        return;
    std::free(seg->labels);
    std::free(seg->leaf);
    std::memset(seg, 0, sizeof *seg);
}

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
 * only on the yellow side (b* above the background's), in ΔE*ab units.
 * Chlorophylls, carotenoids and the brown products of senescence all absorb
 * blue light, so green, yellow and brown lamina lie at b* above white paper,
 * while grey rules, shadows and blue-black ink do not. */
static cv::Mat leaf_feature(const cv::Mat &rgb, const cv::Vec3f &bg)
{
    cv::Mat lab, bglab;
    cv::cvtColor(rgb, lab, cv::COLOR_RGB2Lab); /* sRGB-encoded float input, D65 */
    cv::Mat bgm(1, 1, CV_32FC3, cv::Scalar(bg[0], bg[1], bg[2]));
    cv::cvtColor(bgm, bglab, cv::COLOR_RGB2Lab);
    const cv::Vec3f ref = bglab.at<cv::Vec3f>(0, 0);
    cv::Mat f(rgb.size(), CV_32F);
    for (int y = 0; y < rgb.rows; ++y) {
        const cv::Vec3f *l = lab.ptr<cv::Vec3f>(y);
        float *o = f.ptr<float>(y);
        for (int x = 0; x < rgb.cols; ++x) {
            const float da = l[x][1] - ref[1], db = l[x][2] - ref[2];
            o[x] = db > 0 ? std::sqrt(da * da + db * db) : 0.0f;
        }
    }
    return f;
}

/* Otsu (1979) threshold of a feature map: values quantised to 256 bins over
 * [0, fmax], cv::threshold's THRESH_OTSU on the 8-bit copy. */
static double otsu_threshold(const cv::Mat &f32, const cv::Mat &mask, double fmax)
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

/* ---- colour correction ----------------------------------------------------------- */

/* Linear-light copy (IEC 61966-2-1 decoding) of a phc_image, CV_64FC3. */
static cv::Mat linear_copy(const phc_image *img)
{
    cv::Mat lin = mat_of(img).clone();
    lin.forEach<cv::Vec3d>([](cv::Vec3d &p, const int *) {
        for (int c = 0; c < 3; ++c)
            p[c] = srgb_decode(std::max(0.0, p[c]));
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
            img->data[3 * i + c] = srgb_encode(v);
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
            A.at<double>(k, c) = srgb_decode(meas[use[k]][c]);
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
        linear_to_lab(lin, lab_m);
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

/* ---- registration ---------------------------------------------------------------------- */

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
            mat_of_mask(mask, a->width, a->height, m);
        *correlation = cv::computeECC(grey_of(a), grey_of(b), mask ? m : cv::noArray());
        return PHC_OK;
    }
    PHOTO_CATCH(err, "phc_photo_correlation")
}

extern "C" phc_register_options phc_register_options_default(void)
{
    phc_register_options o;
    o.motion = PHC_MOTION_AFFINE;
    o.max_levels = 5;
    o.iterations = 200;
    o.epsilon = 1e-6;
    return o;
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
            mat_of_mask(mask, reference->width, reference->height, m);
            m = m != 0;
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

/* ---- venation map ---------------------------------------------------------------------- */

extern "C" phc_vein_options phc_vein_options_default(void)
{
    phc_vein_options o;
    o.sigma_min = 1;
    o.sigma_max = 4;
    o.scales = 4;
    o.dark_veins = -1;
    return o;
}

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
            mat_of_mask(mask, img->width, img->height, m);
            m = m != 0;
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
            mat_of_mask(mask, width, height, m);
            m = m != 0;
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
        cv::Mat p, t;
        mat_of_mask(predicted, width, height, p);
        mat_of_mask(truth, width, height, t);
        p = p != 0;
        t = t != 0;
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

/* ---- drawing and warping ------------------------------------------------------------------ */

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
