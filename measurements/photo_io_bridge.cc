/* measurements/photo_io_bridge.cc: images in memory, reading and writing
 * image files, resizing (measurements/photo.h; OpenCV imgcodecs and
 * imgproc).  What the photo bridge files share is in photo_bridge.h.
 *
 * Files are read whole and checked for truncation before decoding; every
 * file written here goes through phc_atomic_file (measurements/atomic_file.h:
 * a temporary name renamed into place). */
#include "measurements/photo_bridge.h"

#include "measurements/atomic_file.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <strings.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace phc_photo;

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

/* Writes bytes to path through measurements/atomic_file.h (a temporary
 * DIR/NAME.tmp-XXXXXX renamed into place once written and synced, like every
 * other writer); the destination is untouched on any failure. */
static int write_atomic(const char *path, const std::vector<unsigned char> &buf, phc_error *err)
{
    phc_atomic_file *af = NULL;
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc)
        return rc;
    FILE *f = phc_atomic_file_stream(af);
    if (!buf.empty() && std::fwrite(buf.data(), 1, buf.size(), f) != buf.size()) {
        const int e = errno;
        phc_atomic_file_abort(af);
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write: %s", path, std::strerror(e));
    }
    return phc_atomic_file_commit(af, err);
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
            pic.setTo(cv::Scalar::all(255), mat_of_mask(mask, width, height) == 0);
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
        cv::Mat bin = mat_of_mask(mask, width, height) != 0, res; /* 0/255 */
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
