/* Unit test of fit/plots.c: each plot writes a PNG of the requested size,
 * bad input gives an error with a message and leaves no file behind.
 * Grouped plots (probes, leaves, quantiles) are read back: every group has
 * its own colour in the axes and in the key beside them, and no colour is
 * left over; the pressure-volume plot of fit/pv_plots.h colours its leaves.
 * Set PHC_KEEP_PLOTS=1 to keep the PNGs (their directory is printed on
 * stderr) for looking at them. */
#include "fit/plots.h"
#include "fit/plot_file.h"
#include "fit/pv_plots.h"
#include "measurements/photo.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"

enum { N = 40, CURVE_N = 400, MAX_LAG = 15 };

/* Reads the PNG signature and the IHDR width/height; 0 on success. */
static int png_size(const char *path, unsigned long *w, unsigned long *h)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G',
                                         '\r', '\n', 0x1a, '\n'};
    unsigned char b[24];
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t got = fread(b, 1, sizeof b, f);
    fclose(f);
    if (got != sizeof b || memcmp(b, sig, 8) != 0 || memcmp(b + 12, "IHDR", 4))
        return -1;
    *w = (unsigned long)b[16] << 24 | (unsigned long)b[17] << 16 |
         (unsigned long)b[18] << 8 | b[19];
    *h = (unsigned long)b[20] << 24 | (unsigned long)b[21] << 16 |
         (unsigned long)b[22] << 8 | b[23];
    return 0;
}

static void check_png(const char *path)
{
    unsigned long w = 0, h = 0;
    CHECK(png_size(path, &w, &h) == 0);
    CHECK(w == 1000);
    CHECK(h == 700);
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* True when dir holds nothing but . and .. (no temporary files left). */
static int dir_is_empty(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int empty = 1;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            empty = 0;
    closedir(d);
    return empty;
}

/* The first colours of groups (fit/plots.c: matplotlib's tab10), 8 bit. */
static const unsigned char TAB10[8][3] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40},
                                          {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127}};

/* Pixels of exactly colour rgb in the columns [x0, x1) of img. */
static size_t count_colour(const phc_image *img, const unsigned char rgb[3], size_t x0, size_t x1)
{
    size_t n = 0;
    for (size_t y = 0; y < img->height; ++y)
        for (size_t x = x0; x < x1 && x < img->width; ++x) {
            const double *p = img->data + 3 * (x + img->width * y);
            n += lround(255 * p[0]) == rgb[0] && lround(255 * p[1]) == rgb[1] && lround(255 * p[2]) == rgb[2];
        }
    return n;
}

/* How many of viridis's 256 colours (the ramp of many groups) cover at
 * least min_px pixels of the columns [x0, x1) of img. */
static size_t viridis_colours(const phc_image *img, size_t x0, size_t x1, size_t min_px)
{
    double lut[3 * 256];
    phc_error err;
    if (phc_photo_viridis(lut, &err) != PHC_OK)
        return 0;
    size_t found = 0;
    for (int k = 0; k < 256; ++k) {
        if (k > 0 && lround(255 * lut[3 * k]) == lround(255 * lut[3 * k - 3]) &&
            lround(255 * lut[3 * k + 1]) == lround(255 * lut[3 * k - 2]) &&
            lround(255 * lut[3 * k + 2]) == lround(255 * lut[3 * k - 1]))
            continue; /* the same 8-bit colour as the previous entry */
        const unsigned char rgb[3] = {(unsigned char)lround(255 * lut[3 * k]),
                                      (unsigned char)lround(255 * lut[3 * k + 1]),
                                      (unsigned char)lround(255 * lut[3 * k + 2])};
        found += count_colour(img, rgb, x0, x1) >= min_px;
    }
    return found;
}

/* Soil-probe-like readings of `groups` probes, each a bump at its own time,
 * drawn grouped: the fit plot and the residual plot. */
static void test_grouped(const char *dir)
{
    enum { G = 6, T = 25 };
    static double x[G * T], y[G * T], yhat[G * T], r[G * T], sig[G * T];
    static size_t id[G * T];
    static const char *const names[G] = {"P1, 0.10 m deep", "P2, 0.30 m deep", "P3, 0.55 m deep",
                                         "P4, 0.90 m deep", "P5, 0.30 m deep", "P6, 0.20 m deep"};
    /* readings in time order, the probes interleaved (as a logger writes them) */
    for (int t = 0, i = 0; t < T; ++t)
        for (int g = 0; g < G; ++g, ++i) {
            x[i] = t;
            yhat[i] = 0.03 + 0.05 * exp(-0.5 * pow((t - 3.0 - 4.0 * g) / 3.0, 2));
            r[i] = 0.002 * sin(1.3 * i);
            y[i] = yhat[i] + r[i];
            sig[i] = 0.002;
            id[i] = (size_t)g;
        }
    char path[512];
    phc_error err;
    const phc_plot_labels lab = {"plot-A: data and fit", "time since start (h)", "water content w (m\xc2\xb3/m\xc2\xb3)",
                                 "fit"};
    const phc_plot_groups groups = {G, id, names, "probe"};
    phc_image img = {0};

    snprintf(path, sizeof path, "%s/grouped_fit.png", dir);
    CHECK(phc_plot_fit_groups(path, &lab, x, y, sig, G * T, &groups, yhat, NULL, NULL, 0, &err) == PHC_OK);
    check_png(path);
    CHECK(phc_plot_png_complete(path));
    CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
    if (img.data) {
        /* each probe's colour in the axes (markers, line) and in the key at
           the right (its sample); the colour after them nowhere */
        const size_t key_x = (size_t)(0.78 * (double)img.width);
        for (int g = 0; g < G; ++g) {
            CHECK(count_colour(&img, TAB10[g], 0, key_x) > 200);
            CHECK(count_colour(&img, TAB10[g], key_x, img.width) > 20);
        }
        CHECK(count_colour(&img, TAB10[G], 0, img.width) == 0);
        phc_image_free(&img);
    }

    snprintf(path, sizeof path, "%s/grouped_residuals.png", dir);
    const phc_plot_labels rl = {"plot-A: residuals", "time since start (h)", "residual (m\xc2\xb3/m\xc2\xb3)", NULL};
    CHECK(phc_plot_residuals_groups(path, &rl, x, r, G * T, 0.002, &groups, &err) == PHC_OK);
    check_png(path);
    CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
    if (img.data) {
        for (int g = 0; g < G; ++g)
            CHECK(count_colour(&img, TAB10[g], 0, img.width) > 50);
        phc_image_free(&img);
    }

    /* every reading in one group: the first group colour and no other */
    static size_t zero_id[G * T];
    const phc_plot_groups one = {1, zero_id, NULL, NULL};
    snprintf(path, sizeof path, "%s/one_group.png", dir);
    CHECK(phc_plot_fit_groups(path, &lab, x, y, NULL, G * T, &one, yhat, NULL, NULL, 0, &err) == PHC_OK);
    CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
    if (img.data) {
        CHECK(count_colour(&img, TAB10[0], 0, img.width) > 200);
        CHECK(count_colour(&img, TAB10[1], 0, img.width) == 0);
        phc_image_free(&img);
    }

    /* a bad group id: an error naming it, no file */
    id[7] = G;
    snprintf(path, sizeof path, "%s/bad_group.png", dir);
    CHECK(phc_plot_fit_groups(path, &lab, x, y, sig, G * T, &groups, yhat, NULL, NULL, 0, &err) ==
          PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "id[7]");
    CHECK(!file_exists(path));
    id[7] = 1;
}

/* Many groups: 36 quantile curves (a colour ramp, names in columns) and
 * 300 series (a colour bar with every k-th name): one colour per group. */
static void test_many_groups(const char *dir)
{
    enum { NQ = 36, NB = 300, T = 12 };
    static double x[NB * T], y[NB * T], yhat[NB * T];
    static size_t id[NB * T];
    static char name_buf[NB][32];
    static const char *names[NB];
    for (int g = 0; g < NB; ++g) {
        snprintf(name_buf[g], sizeof name_buf[g], "%s, %.3g %%", g / 12 % 3 == 0 ? "L*" : g / 12 % 3 == 1 ? "a*" : "b*",
                 100.0 * (g % 12 + 0.5) / 12);
        names[g] = name_buf[g];
        for (int t = 0; t < T; ++t) {
            const int i = g * T + t;
            x[i] = 14 + 4 * t;
            yhat[i] = g + 0.1 * t;
            y[i] = yhat[i] + 0.3 * sin(i);
            id[i] = (size_t)g;
        }
    }
    char path[512];
    phc_error err;
    const phc_plot_labels lab = {"ivy: data and fit", "SPAD", "CIELAB quantile", "fit"};
    phc_image img = {0};

    const phc_plot_groups q = {NQ, id, names, "quantile"};
    snprintf(path, sizeof path, "%s/quantiles.png", dir);
    CHECK(phc_plot_fit_groups(path, &lab, x, y, NULL, NQ * T, &q, yhat, NULL, NULL, 0, &err) == PHC_OK);
    check_png(path);
    CHECK(phc_plot_png_complete(path));
    CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
    if (img.data) {
        /* the key (right of 0.6 of the width): a sample of every quantile,
           each in its own colour of the ramp */
        CHECK(viridis_colours(&img, (size_t)(0.6 * (double)img.width), img.width, 30) >= NQ);
        phc_image_free(&img);
    }

    const phc_plot_groups b = {NB, id, names, "series"};
    snprintf(path, sizeof path, "%s/bar.png", dir);
    CHECK(phc_plot_fit_groups(path, &lab, x, y, NULL, NB * T, &b, yhat, NULL, NULL, 0, &err) == PHC_OK);
    check_png(path);
    CHECK(phc_plot_png_complete(path));
    CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
    if (img.data) {
        /* the bar has a cell of each colour of the ramp (256 at most) */
        CHECK(viridis_colours(&img, (size_t)(0.75 * (double)img.width), img.width, 5) >= 200);
        phc_image_free(&img);
    }
}

/* Two synthetic pressure-volume curves (Boyle-van 't Hoff osmotic potential,
 * linear turgor above the turgor loss point) in the classic plot. */
static void test_pv_plot(const char *dir)
{
    enum { N = 11 };
    static const double rwc[N] = {1.0, 0.98, 0.96, 0.94, 0.92, 0.90, 0.86, 0.82, 0.78, 0.74, 0.70};
    const double pi_o[2] = {-1.5, -1.2}, tlp[2] = {0.88, 0.9};
    phc_pv_result *res[2] = {NULL, NULL};
    phc_error err;
    for (int L = 0; L < 2; ++L) {
        double psi[N];
        for (int i = 0; i < N; ++i)
            psi[i] = pi_o[L] * 0.8 / (rwc[i] - 0.2) + (rwc[i] > tlp[L] ? 10.0 * (rwc[i] - tlp[L]) : 0.0);
        CHECK(phc_pv_analyse(psi, rwc, N, NULL, &res[L], &err) == PHC_OK);
    }
    if (res[0] && res[1]) {
        static const char *const labels[2] = {"A", "B"};
        char path[512];
        CHECK(phc_pv_plot_write("leaves", (const phc_pv_result *const *)res, labels, 2, dir, "pv", &err) == PHC_OK);
        snprintf(path, sizeof path, "%s/pv_pv_curve.png", dir);
        check_png(path);
        CHECK(phc_plot_png_complete(path));
        phc_image img = {0};
        CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
        if (img.data) {
            CHECK(count_colour(&img, TAB10[0], 0, img.width) > 100);
            CHECK(count_colour(&img, TAB10[1], 0, img.width) > 100);
            CHECK(count_colour(&img, TAB10[2], 0, img.width) == 0);
            phc_image_free(&img);
        }
    }
    phc_pv_result_free(res[0]);
    phc_pv_result_free(res[1]);
}

int main(void)
{
    char dir[] = "/tmp/phc_test_plots_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    char p_fit[256], p_fit2[256], p_res[256], p_qq[256], p_acf[256];
    char p_one[256], p_flat[256], p_bad[256], p_nodir[256], p_notdir[256];
    snprintf(p_fit, sizeof p_fit, "%s/fit.png", dir);
    snprintf(p_fit2, sizeof p_fit2, "%s/fit_nosigma.png", dir);
    snprintf(p_res, sizeof p_res, "%s/residuals.png", dir);
    snprintf(p_qq, sizeof p_qq, "%s/qq.png", dir);
    snprintf(p_acf, sizeof p_acf, "%s/acf.png", dir);
    snprintf(p_one, sizeof p_one, "%s/one_point.png", dir);
    snprintf(p_flat, sizeof p_flat, "%s/flat.png", dir);
    snprintf(p_bad, sizeof p_bad, "%s/bad.png", dir);
    snprintf(p_nodir, sizeof p_nodir, "%s/no/such/dir/plot.png", dir);
    snprintf(p_notdir, sizeof p_notdir, "%s/fit.png/plot.png", dir);

    /* Water loss of a cut shoot on a balance: m(t) = 12 exp(-0.15 t) + 3 g,
     * weighed every 0.5 h, with deterministic "noise" from a fixed formula
     * (sigma 0.15 g).  One reading is missing (NAN). */
    double t[N], m[N], sig[N], r[N], fitted[N];
    double ct[CURVE_N], cm[CURVE_N];
    const double a = 12.0, k = 0.15, c = 3.0;
    for (int i = 0; i < N; ++i) {
        t[i] = 0.5 * i;
        double noise = 0.15 * (sin(1.7 * i + 0.3) + 0.6 * cos(4.1 * i * i + 1.0));
        fitted[i] = a * exp(-k * t[i]) + c;
        m[i] = fitted[i] + noise;
        sig[i] = 0.15 + 0.02 * (i % 3);
        r[i] = m[i] - fitted[i];
    }
    m[17] = NAN;
    r[17] = NAN;
    for (int j = 0; j < CURVE_N; ++j) {
        ct[j] = 19.5 * j / (CURVE_N - 1);
        cm[j] = a * exp(-k * ct[j]) + c;
    }
    double mean = 0.0;
    int nr = 0;
    for (int i = 0; i < N; ++i)
        if (isfinite(r[i])) {
            mean += r[i];
            ++nr;
        }
    mean /= nr;
    double ss = 0.0;
    for (int i = 0; i < N; ++i)
        if (isfinite(r[i]))
            ss += (r[i] - mean) * (r[i] - mean);
    double s = sqrt(ss / (nr - 1));
    double acf[MAX_LAG + 1];
    double c0 = ss / nr;
    for (int h = 0; h <= MAX_LAG; ++h) {
        double sum = 0.0;
        for (int i = h; i < N; ++i)
            if (isfinite(r[i]) && isfinite(r[i - h]))
                sum += (r[i] - mean) * (r[i - h] - mean);
        acf[h] = sum / nr / c0;
    }

    phc_error err;
    phc_plot_labels lab = {"Shoot #3: water loss on the balance",
                           "time since cut (h)", "mass (g)", NULL};
    phc_plot_labels lab_res = {"Residuals of the exponential fit",
                               "time since cut (h)", "residual (g)", NULL};
    phc_plot_labels lab_qq = {"Normal QQ plot of the residuals", NULL, NULL, NULL};
    phc_plot_labels lab_acf = {"Autocorrelation of the residuals",
                               "lag (readings, 0.5 h apart)",
                               "autocorrelation (\xe2\x80\x93)", NULL};

    /* The four plots. */
    CHECK(phc_plot_fit(p_fit, &lab, t, m, sig, N, ct, cm, CURVE_N, &err) ==
          PHC_OK);
    CHECK(err.status == PHC_OK);
    check_png(p_fit);
    CHECK(phc_plot_fit(p_fit2, &lab, t, m, NULL, N, ct, cm, CURVE_N, &err) ==
          PHC_OK);
    check_png(p_fit2);
    CHECK(phc_plot_residuals(p_res, &lab_res, t, r, N, s, &err) == PHC_OK);
    check_png(p_res);
    CHECK(phc_plot_qq(p_qq, &lab_qq, r, N, &err) == PHC_OK);
    check_png(p_qq);
    CHECK(phc_plot_acf(p_acf, &lab_acf, acf, MAX_LAG, (size_t)nr, &err) ==
          PHC_OK);
    check_png(p_acf);

    /* Overwriting an existing plot works (no state left from the first). */
    CHECK(phc_plot_fit(p_fit, &lab, t, m, sig, N, ct, cm, CURVE_N, &err) ==
          PHC_OK);
    check_png(p_fit);

    /* Degenerate data: one point, all x equal, constant residuals, NULL
     * labels; each must still give a valid PNG. */
    double one_x = 2.0, one_y = 5.0;
    CHECK(phc_plot_fit(p_one, NULL, &one_x, &one_y, NULL, 1, NULL, NULL, 0,
                       &err) == PHC_OK);
    check_png(p_one);
    double same_x[4] = {1.0, 1.0, 1.0, 1.0}, zero[4] = {0.0, 0.0, 0.0, 0.0};
    CHECK(phc_plot_residuals(p_flat, NULL, same_x, zero, 4, 0.0, &err) ==
          PHC_OK);
    check_png(p_flat);
    CHECK(phc_plot_qq(p_flat, NULL, zero, 4, &err) == PHC_OK);
    check_png(p_flat);
    CHECK(phc_plot_qq(p_flat, NULL, &one_y, 1, &err) == PHC_OK);
    check_png(p_flat);
    CHECK(phc_plot_acf(p_flat, NULL, acf, 0, 1, &err) == PHC_OK);
    check_png(p_flat);
    CHECK(unlink(p_one) == 0);
    CHECK(unlink(p_flat) == 0);

    /* Invalid input: an error with a message, no crash, no file. */
    err.status = PHC_OK;
    err.message[0] = '\0';
    CHECK(phc_plot_fit(p_bad, &lab, t, m, sig, 0, ct, cm, CURVE_N, &err) ==
          PHC_ERR_INVALID);
    CHECK(err.status == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "n = 0");
    CHECK(!file_exists(p_bad));

    CHECK(phc_plot_fit(NULL, &lab, t, m, sig, N, ct, cm, CURVE_N, &err) ==
          PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');
    CHECK(phc_plot_residuals(NULL, &lab, t, r, N, s, &err) ==
          PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');
    CHECK(phc_plot_qq("", NULL, r, N, &err) == PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');
    CHECK(phc_plot_acf(NULL, NULL, acf, MAX_LAG, N, &err) == PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');

    CHECK(phc_plot_residuals(p_bad, &lab, t, r, 0, s, &err) ==
          PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "n = 0");
    CHECK(phc_plot_qq(p_bad, NULL, r, 0, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "n = 0");
    CHECK(phc_plot_acf(p_bad, NULL, acf, MAX_LAG, 0, &err) ==
          PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');
    CHECK(phc_plot_acf(p_bad, NULL, NULL, MAX_LAG, N, &err) ==
          PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');
    CHECK(phc_plot_fit(p_bad, &lab, t, NULL, NULL, N, NULL, NULL, 0, &err) ==
          PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');
    CHECK(phc_plot_fit(p_bad, &lab, t, m, NULL, N, ct, NULL, CURVE_N,
                       &err) == PHC_ERR_INVALID);
    CHECK(err.message[0] != '\0');
    double nans[3] = {NAN, INFINITY, NAN};
    CHECK(phc_plot_qq(p_bad, NULL, nans, 3, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "finite");
    double neg_sig[3] = {0.1, -0.1, 0.1};
    CHECK(phc_plot_fit(p_bad, NULL, t, m, neg_sig, 3, NULL, NULL, 0, &err) ==
          PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "sigma[1]");
    CHECK(!file_exists(p_bad));

    /* Unwritable destinations (the test may run as root, so use a missing
     * directory and a regular file in place of a directory). */
    CHECK(phc_plot_fit(p_nodir, &lab, t, m, sig, N, ct, cm, CURVE_N, &err) ==
          PHC_ERR_IO);
    CHECK(err.status == PHC_ERR_IO);
    CHECK_STR_CONTAINS(err.message, p_nodir);
    CHECK(phc_plot_residuals(p_notdir, &lab, t, r, N, s, &err) == PHC_ERR_IO);
    CHECK_STR_CONTAINS(err.message, p_notdir);
    CHECK(phc_plot_qq(p_nodir, NULL, r, N, &err) == PHC_ERR_IO);
    CHECK(err.message[0] != '\0');
    CHECK(phc_plot_acf(p_notdir, NULL, acf, MAX_LAG, N, &err) == PHC_ERR_IO);
    CHECK(err.message[0] != '\0');

    /* Still works after the failures (no stream left open). */
    CHECK(phc_plot_qq(p_qq, &lab_qq, r, N, &err) == PHC_OK);
    check_png(p_qq);

    /* Grouped data: one colour per group and a key. */
    test_grouped(dir);
    test_many_groups(dir);
    test_pv_plot(dir);

    const char *keep = getenv("PHC_KEEP_PLOTS");
    if (keep && *keep && strcmp(keep, "0") != 0) {
        fprintf(stderr, "plots kept in %s\n", dir);
    } else {
        CHECK(unlink(p_fit) == 0);
        CHECK(unlink(p_fit2) == 0);
        CHECK(unlink(p_res) == 0);
        CHECK(unlink(p_qq) == 0);
        CHECK(unlink(p_acf) == 0);
        static const char *const more[] = {"grouped_fit.png", "grouped_residuals.png", "one_group.png",
                                           "quantiles.png", "bar.png", "pv_pv_curve.png"};
        for (size_t i = 0; i < sizeof more / sizeof more[0]; ++i) {
            char path[512];
            snprintf(path, sizeof path, "%s/%s", dir, more[i]);
            CHECK(unlink(path) == 0);
        }
        CHECK(dir_is_empty(dir));
        CHECK(rmdir(dir) == 0);
    }
    return check_finish("test_plots");
}
