/* Unit test of fit/plots.c: each plot writes a PNG of the requested size,
 * bad input gives an error with a message and leaves no file behind.
 * Set PHC_KEEP_PLOTS=1 to keep the PNGs (their directory is printed on
 * stderr) for looking at them. */
#include "fit/plots.h"

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

    const char *keep = getenv("PHC_KEEP_PLOTS");
    if (keep && *keep && strcmp(keep, "0") != 0) {
        fprintf(stderr, "plots kept in %s\n", dir);
    } else {
        CHECK(unlink(p_fit) == 0);
        CHECK(unlink(p_fit2) == 0);
        CHECK(unlink(p_res) == 0);
        CHECK(unlink(p_qq) == 0);
        CHECK(unlink(p_acf) == 0);
        CHECK(dir_is_empty(dir));
        CHECK(rmdir(dir) == 0);
    }
    return check_finish("test_plots");
}
