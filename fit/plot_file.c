/* The file side of a PLplot figure: see plot_file.h. */
#include "fit/plot_file.h"

#include <plplot.h>
#include <png.h>
#include <setjmp.h>
#include <zlib.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/lazy_library_internal.h"

/* Copy of s with PLplot's escape character doubled; "" for NULL. */
char *phc_plot_escape(const char *s)
{
    if (!s)
        s = "";
    size_t len = strlen(s), extra = 0;
    for (size_t i = 0; i < len; ++i)
        extra += s[i] == '#';
    char *out = malloc(len + extra + 1);
    if (!out)
        return NULL;
    char *p = out;
    for (size_t i = 0; i < len; ++i) {
        *p++ = s[i];
        if (s[i] == '#')
            *p++ = '#';
    }
    *p = '\0';
    return out;
}

int phc_plot_library_open(const char *path, phc_error *err)
{
    return phc_lazy_library_open(&phc_lazy_plplot, path, err);
}

int phc_plot_device_available(const char *name)
{
    enum { MAX_DEVS = 256 };
    const char **menu = malloc(MAX_DEVS * sizeof *menu);
    const char **names = malloc(MAX_DEVS * sizeof *names);
    int found = -1;
    if (menu && names) {
        int ndev = MAX_DEVS;
        plgDevs(&menu, &names, &ndev);
        found = 0;
        for (int i = 0; i < ndev && i < MAX_DEVS; ++i)
            if (names[i] && strcmp(names[i], name) == 0)
                found = 1;
    }
    free(menu);
    free(names);
    return found;
}

/* Checks the PNG signature and the final IEND chunk (cairo reports no
 * write errors through PLplot: a full disk shows as a truncated file). */
int phc_plot_png_complete(const char *file)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G',
                                         '\r', '\n', 0x1a, '\n'};
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D',
                                           0xae, 0x42, 0x60, 0x82};
    unsigned char head[8] = {0}, tail[12] = {0};
    int ok = 0;
    FILE *f = fopen(file, "rb");
    if (f) {
        ok = fread(head, 1, sizeof head, f) == sizeof head &&
             memcmp(head, sig, sizeof sig) == 0 &&
             fseek(f, -(long)sizeof tail, SEEK_END) == 0 &&
             fread(tail, 1, sizeof tail, f) == sizeof tail &&
             memcmp(tail, iend, sizeof iend) == 0;
        fclose(f);
    }
    return ok;
}

int phc_plot_begin(const char *path, int w, int h, phc_atomic_file **af, int *old_stream, phc_error *err)
{
    *af = NULL;
    const int lib = phc_plot_library_open(path, err);
    if (lib)
        return lib;
    const int dev = phc_plot_device_available("pngcairo");
    if (dev <= 0)
        return phc_error_set(err, dev < 0 ? PHC_ERR_NOMEM : PHC_ERR_INTERNAL,
                             "%s: PLplot has no 'pngcairo' device (install plplot-driver-cairo)", path);
    int rc = phc_atomic_file_open(path, af, err);
    if (rc)
        return rc;
    PLINT old = 0, strm = -1;
    plgstrm(&old);
    plmkstrm(&strm);
    if (strm < 0) {
        plsstrm(old);
        phc_atomic_file_abort(*af);
        *af = NULL;
        return phc_error_set(err, PHC_ERR_INTERNAL, "%s: no free PLplot stream", path);
    }
    *old_stream = (int)old;
    plsdev("pngcairo");
    plsfnam(phc_atomic_file_temp_path(*af));
    plspage(0.0, 0.0, w, h, 0, 0);
    plsfam(0, 0, 0);
    return PHC_OK;
}

int phc_plot_end(phc_atomic_file *af, int old_stream, int status, phc_error *err)
{
    plend1();
    plsstrm(old_stream);
    return phc_plot_file_finish(af, status, err);
}

int phc_plot_file_finish(phc_atomic_file *af, int status, phc_error *err)
{
    if (!af)
        return status;
    if (status == PHC_OK && !phc_plot_png_complete(phc_atomic_file_temp_path(af)))
        status = phc_error_set(err, PHC_ERR_IO, "%s: PLplot did not write a complete PNG file (disk full?)",
                               phc_atomic_file_path(af));
    if (status != PHC_OK) {
        phc_atomic_file_abort(af);
        return status;
    }
    return phc_atomic_file_commit(af, err);
}

double phc_plot_nice_step(double span, double target)
{
    const double raw = span / target;
    const double p = pow(10.0, floor(log10(raw)));
    const double m = raw / p;
    return (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * p;
}

int phc_plot_png_write(phc_atomic_file *af, const unsigned char *rgba, int w, int h, phc_error *err)
{
    FILE *f = phc_atomic_file_stream(af);
    unsigned char *row = malloc((size_t)w * 3);
    png_structp png = row ? png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL) : NULL;
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        free(row);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", phc_atomic_file_path(af));
    }
    if (setjmp(png_jmpbuf(png))) { /* libpng reports its errors by longjmp */
        png_destroy_write_struct(&png, &info);
        free(row);
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write the PNG", phc_atomic_file_path(af));
    }
    png_init_io(png, f);
    png_set_compression_level(png, Z_BEST_SPEED);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
    png_write_info(png, info);
    for (int y = 0; y < h; ++y) {
        const unsigned char *src = rgba + (size_t)y * (size_t)w * 4;
        for (int x = 0; x < w; ++x) {
            row[3 * x] = src[4 * x];
            row[3 * x + 1] = src[4 * x + 1];
            row[3 * x + 2] = src[4 * x + 2];
        }
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(row);
    if (fflush(f) != 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write the PNG", phc_atomic_file_path(af));
    return PHC_OK;
}
