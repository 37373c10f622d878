/* Unit tests of measurements/photo.h on synthetic images written to a
 * temporary directory (removed at the end): file round trips and errors,
 * leaf segmentation and reading order, gray world, ECC registration, vein
 * maps and their scores, resizing. */
#include "measurements/photo.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"

static char dir[64];
static char *path_in(const char *name)
{
    static char buf[8][256];
    static int k = 0;
    char *p = buf[k++ % 8];
    snprintf(p, 256, "%s/%s", dir, name);
    return p;
}

/* Deterministic uniform numbers in [0, 1) (a 64-bit LCG, Knuth's MMIX). */
static unsigned long long rng_state = 12345;
static double uniform(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

static void set_px(phc_image *img, size_t x, size_t y, double r, double g, double b)
{
    double *p = img->data + 3 * (x + img->width * y);
    p[0] = r;
    p[1] = g;
    p[2] = b;
}

/* Copies the first half of a file into another. */
static void truncate_copy(const char *from, const char *to)
{
    FILE *f = fopen(from, "rb");
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    char *buf = malloc((size_t)n);
    size_t got = fread(buf, 1, (size_t)n, f);
    fclose(f);
    FILE *g = fopen(to, "wb");
    fwrite(buf, 1, got / 2, g);
    fclose(g);
    free(buf);
}

static void append_zeros(const char *path, int n)
{
    FILE *f = fopen(path, "ab");
    for (int i = 0; i < n; ++i)
        fputc(0, f);
    fclose(f);
}

/* ---- file round trips and errors ---------------------------------------------- */

static void round_trip(const char *name, int depth)
{
    phc_error err;
    phc_image img, back;
    const double q = depth == 16 ? 65535.0 : 255.0;
    phc_image_alloc(&img, 37, 23, &err);
    for (size_t i = 0; i < 3 * 37 * 23; ++i)
        img.data[i] = (double)((i * 7919) % (size_t)(q + 1)) / q;
    int rc = depth == 8 && strstr(name, ".png") ? phc_photo_write_png(path_in(name), &img, &err)
                                                : phc_photo_write(path_in(name), &img, depth, &err);
    CHECK(rc == PHC_OK);
    rc = phc_photo_read(path_in(name), &back, &err);
    CHECK(rc == PHC_OK);
    if (rc == PHC_OK) {
        CHECK(back.width == 37 && back.height == 23);
        CHECK(back.bit_depth == depth);
        double worst = 0;
        for (size_t i = 0; i < 3 * 37 * 23; ++i)
            worst = fmax(worst, fabs(back.data[i] - img.data[i]));
        CHECK(worst < 1e-12);
    }
    phc_image_free(&img);
    phc_image_free(&back);
    remove(path_in(name));
}

static void test_files(void)
{
    phc_error err;
    phc_image img, back;
    round_trip("a8.png", 8);
    round_trip("a16.png", 16);
    round_trip("a8.tif", 8);
    round_trip("a16.tiff", 16);

    /* JPEG (lossy): close, and 16 bits refused */
    phc_image_alloc(&img, 64, 48, &err);
    for (size_t y = 0; y < 48; ++y)
        for (size_t x = 0; x < 64; ++x)
            set_px(&img, x, y, 0.3 + 0.4 * x / 64.0, 0.5, 0.7 - 0.4 * y / 48.0);
    CHECK(phc_photo_write(path_in("a.jpg"), &img, 8, &err) == PHC_OK);
    CHECK(phc_photo_write(path_in("b.jpg"), &img, 16, &err) == PHC_ERR_INVALID);
    CHECK(phc_photo_read(path_in("a.jpg"), &back, &err) == PHC_OK);
    CHECK(back.width == 64 && back.height == 48 && back.bit_depth == 8);
    CHECK_NEAR(back.data[3 * (10 + 64 * 20) + 0], img.data[3 * (10 + 64 * 20) + 0], 0.03, 0);
    phc_image_free(&back);

    /* trailing padding after the JPEG's end-of-image marker is allowed */
    append_zeros(path_in("a.jpg"), 100);
    CHECK(phc_photo_read(path_in("a.jpg"), &back, &err) == PHC_OK);
    phc_image_free(&back);

    /* truncated JPEG and PNG */
    truncate_copy(path_in("a.jpg"), path_in("cut.jpg"));
    CHECK(phc_photo_read(path_in("cut.jpg"), &back, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "truncated JPEG");
    CHECK_STR_CONTAINS(err.message, "cut.jpg");
    CHECK(back.data == NULL);
    CHECK(phc_photo_write_png(path_in("a.png"), &img, &err) == PHC_OK);
    truncate_copy(path_in("a.png"), path_in("cut.png"));
    CHECK(phc_photo_read(path_in("cut.png"), &back, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "truncated PNG");
    CHECK_STR_CONTAINS(err.message, "cut.png");

    /* not an image; missing file; bad names and values on writing */
    FILE *f = fopen(path_in("notes.txt"), "w");
    fputs("leaf 1, SPAD 42\n", f);
    fclose(f);
    CHECK(phc_photo_read(path_in("notes.txt"), &back, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "notes.txt: not a PNG, JPEG or TIFF image");
    CHECK(phc_photo_read(path_in("missing.png"), &back, &err) == PHC_ERR_IO);
    CHECK_STR_CONTAINS(err.message, "missing.png: cannot open");
    CHECK(phc_photo_write_png(path_in("x.txt"), &img, &err) == PHC_ERR_INVALID);
    img.data[5] = NAN;
    CHECK(phc_photo_write_png(path_in("nan.png"), &img, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "not finite");
    phc_image_free(&img);

    /* a grey (1-channel) PNG reads as three equal channels; read_map */
    double map[20 * 10];
    for (size_t i = 0; i < 200; ++i)
        map[i] = (double)(i % 20) / 19.0;
    CHECK(phc_photo_write_map_png(path_in("grey.png"), 20, 10, map, NULL, 0, 1, 0, &err) == PHC_OK);
    CHECK(phc_photo_read(path_in("grey.png"), &back, &err) == PHC_OK);
    if (back.data) {
        CHECK(back.width == 20 && back.height == 10);
        CHECK_NEAR(back.data[3 * 5 + 0], 5 / 19.0, 0.5 / 255, 0);
        CHECK(back.data[3 * 7 + 0] == back.data[3 * 7 + 1] && back.data[3 * 7 + 1] == back.data[3 * 7 + 2]);
    }
    phc_image_free(&back);
    double *v = NULL;
    CHECK(phc_photo_read_map(path_in("grey.png"), 30, 15, 0, &v, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "20x10");
    CHECK_STR_CONTAINS(err.message, "30x15");
    CHECK(v == NULL);
    CHECK(phc_photo_read_map(path_in("grey.png"), 20, 10, 0, &v, &err) == PHC_OK);
    if (v)
        CHECK_NEAR(v[19 + 20 * 3], 1.0, 1e-12, 0);
    free(v);
    CHECK(phc_photo_read_map(path_in("grey.png"), 10, 5, 1, &v, &err) == PHC_OK);
    if (v) /* area averaging of columns 0 and 1 */
        CHECK_NEAR(v[0], 0.5 / 19.0, 1.0 / 255, 0);
    free(v);
    unsigned char m[200];
    for (size_t i = 0; i < 200; ++i)
        m[i] = i % 20 < 10;
    CHECK(phc_photo_write_map_png(path_in("viridis.png"), 20, 10, map, m, 0, 1, 1, &err) == PHC_OK);
    CHECK(phc_photo_read(path_in("viridis.png"), &back, &err) == PHC_OK);
    if (back.data) /* masked-out pixels white */
        CHECK(back.data[3 * 15] == 1.0 && back.data[3 * 15 + 2] == 1.0);
    phc_image_free(&back);
    CHECK(phc_photo_write_map_png(path_in("bad.png"), 20, 10, map, NULL, 1, 1, 1, &err) == PHC_ERR_INVALID);

    const char *made[] = {"a.jpg", "cut.jpg", "a.png", "cut.png", "notes.txt", "grey.png", "viridis.png"};
    for (size_t i = 0; i < sizeof made / sizeof *made; ++i)
        remove(path_in(made[i]));
}

static void test_resize(void)
{
    phc_error err;
    phc_image img, out;
    phc_image_alloc(&img, 37, 23, &err);
    for (size_t i = 0; i < 3 * 37 * 23; ++i)
        img.data[i] = 0.3;
    CHECK(phc_photo_resize(&img, 74, 46, &out, &err) == PHC_OK);
    CHECK(out.width == 74 && out.height == 46);
    CHECK_NEAR(out.data[3 * 100 + 1], 0.3, 1e-6, 0); /* OpenCV resizes in float */
    phc_image_free(&out);
    CHECK(phc_photo_resize(&img, 10, 7, &out, &err) == PHC_OK);
    CHECK(out.width == 10 && out.height == 7);
    CHECK_NEAR(out.data[3 * 12 + 2], 0.3, 1e-6, 0);
    phc_image_free(&out);
    CHECK(phc_photo_resize(&img, 0, 7, &out, &err) == PHC_ERR_INVALID);
    phc_image_free(&img);

    unsigned char mask[100], *small = NULL, *big = NULL;
    for (size_t i = 0; i < 100; ++i)
        mask[i] = i % 10 < 5; /* left half */
    CHECK(phc_photo_resize_mask(mask, 10, 10, 5, 5, &small, &err) == PHC_OK);
    if (small) {
        /* column 2 covers x = 4 (leaf) and 5 (not): half, so leaf */
        CHECK(small[0] == 1 && small[1] == 1 && small[2] == 1 && small[3] == 0 && small[4] == 0);
        CHECK(small[5 * 4 + 2] == 1);
        CHECK(phc_photo_resize_mask(small, 5, 5, 10, 10, &big, &err) == PHC_OK);
        if (big)
            CHECK(big[5] == 1 && big[6] == 0 && big[99] == 0);
    }
    free(small);
    free(big);
}

/* ---- segmentation ---------------------------------------------------------------- */

typedef struct {
    double cx, cy, a, b, r, g, bl;
} ellipse;

static void test_segmentation(void)
{
    phc_error err;
    phc_image img;
    const size_t W = 600, H = 400;
    /* two rows of three, tops not aligned; one yellow, one dark green */
    const ellipse e[6] = {{100, 100, 70, 45, 0.20, 0.50, 0.15}, {300, 112, 60, 55, 0.85, 0.75, 0.15},
                          {495, 92, 75, 40, 0.10, 0.25, 0.08},  {110, 295, 65, 50, 0.30, 0.55, 0.20},
                          {305, 290, 70, 60, 0.25, 0.45, 0.12}, {490, 305, 55, 45, 0.45, 0.55, 0.15}};
    size_t box[6][4], area[6] = {0};
    phc_image_alloc(&img, W, H, &err);
    for (int k = 0; k < 6; ++k)
        box[k][0] = box[k][1] = (size_t)-1, box[k][2] = box[k][3] = 0;
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            double c[3] = {0.96, 0.96, 0.95}; /* paper */
            for (int k = 0; k < 6; ++k) {
                const double dx = (x - e[k].cx) / e[k].a, dy = (y - e[k].cy) / e[k].b;
                if (dx * dx + dy * dy <= 1) {
                    c[0] = e[k].r, c[1] = e[k].g, c[2] = e[k].bl;
                    if (x < box[k][0]) box[k][0] = x;
                    if (y < box[k][1]) box[k][1] = y;
                    if (x + 1 > box[k][2]) box[k][2] = x + 1;
                    if (y + 1 > box[k][3]) box[k][3] = y + 1;
                    area[k]++;
                }
            }
            for (int i = 0; i < 3; ++i)
                c[i] += 0.02 * (uniform() - 0.5); /* sensor noise */
            set_px(&img, x, y, c[0], c[1], c[2]);
        }
    /* handwriting: dark grey strokes beside the leaves must not be leaves */
    for (size_t y = 180; y < 215; ++y)
        for (size_t x = 200; x < 204; ++x)
            set_px(&img, x, y, 0.25, 0.25, 0.3);
    for (size_t x = 560; x < 590; ++x)
        for (size_t y = 200; y < 203; ++y)
            set_px(&img, x, y, 0.2, 0.2, 0.25);

    phc_segmentation seg;
    phc_segment_options so = phc_segment_options_default();
    int rc = phc_photo_segment_leaves(&img, &so, &seg, &err);
    CHECK(rc == PHC_OK);
    CHECK(seg.count == 6);
    if (rc == PHC_OK && seg.count == 6) {
        CHECK(seg.width == W && seg.height == H);
        for (int k = 0; k < 6; ++k) {
            const phc_leaf_box *b = &seg.leaf[k];
            CHECK_NEAR(b->cx, e[k].cx, 1.0, 0);
            CHECK_NEAR(b->cy, e[k].cy, 1.0, 0);
            CHECK_NEAR((double)b->x0, (double)box[k][0], 2, 0);
            CHECK_NEAR((double)b->y0, (double)box[k][1], 2, 0);
            CHECK_NEAR((double)b->x1, (double)box[k][2], 2, 0);
            CHECK_NEAR((double)b->y1, (double)box[k][3], 2, 0);
            CHECK_NEAR((double)b->area, (double)area[k], 0, 0.03);
        }
        CHECK(seg.labels[(size_t)e[1].cx + W * (size_t)e[1].cy] == 2); /* the yellow one */
        CHECK(seg.labels[201 + W * 190] == 0);                          /* the stroke */
        /* crop of leaf 5 with a margin */
        phc_image crop;
        unsigned char *mask = NULL;
        CHECK(phc_photo_crop_leaf(&img, &seg, 5, 3, &crop, &mask, &err) == PHC_OK);
        if (mask) {
            CHECK(crop.width == seg.leaf[4].x1 - seg.leaf[4].x0 + 6);
            size_t n = 0;
            for (size_t i = 0; i < crop.width * crop.height; ++i)
                n += mask[i];
            CHECK(n == seg.leaf[4].area);
        }
        phc_image_free(&crop);
        free(mask);
        CHECK(phc_photo_crop_leaf(&img, &seg, 7, 0, &crop, &mask, &err) == PHC_ERR_INVALID);
    }
    phc_segmentation_free(&seg);

    /* the same at a reduced working size (upscaled masks) */
    so.downscale_to = 300;
    rc = phc_photo_segment_leaves(&img, &so, &seg, &err);
    CHECK(rc == PHC_OK && seg.count == 6);
    if (rc == PHC_OK && seg.count == 6)
        for (int k = 0; k < 6; ++k)
            CHECK_NEAR((double)seg.leaf[k].area, (double)area[k], 0, 0.05);
    phc_segmentation_free(&seg);

    /* blank paper */
    for (size_t i = 0; i < 3 * W * H; ++i)
        img.data[i] = 0.97;
    CHECK(phc_photo_segment_leaves(&img, NULL, &seg, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "no leaf found");
    CHECK(seg.labels == NULL && seg.count == 0);
    phc_image_free(&img);
}

/* ---- colour correction ----------------------------------------------------------- */

static double dec(double v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }
static double enc(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055; }

static void test_gray_world(void)
{
    phc_error err;
    phc_image img;
    const double tint[3] = {1.2, 1.0, 0.7}; /* linear-light gains of a warm cast */
    phc_image_alloc(&img, 200, 150, &err);
    for (size_t i = 0; i < 200 * 150; ++i) {
        const double grey = 0.05 + 0.7 * uniform(); /* linear, neutral scene */
        for (int c = 0; c < 3; ++c)
            img.data[3 * i + c] = enc(grey * tint[c]);
    }
    phc_colour_correction rep;
    CHECK(phc_photo_colour_correct(&img, NULL, PHC_CC_GRAY_WORLD, &rep, &err) == PHC_OK);
    CHECK(rep.method == PHC_CC_GRAY_WORLD);
    CHECK_NEAR(rep.gains[0] / rep.gains[1], tint[1] / tint[0], 1e-9, 0);
    CHECK_NEAR(rep.gains[2] / rep.gains[1], tint[1] / tint[2], 1e-9, 0);
    CHECK(rep.clipped_fraction == 0);
    double worst = 0;
    for (size_t i = 0; i < 200 * 150; ++i)
        worst = fmax(worst, fabs(dec(img.data[3 * i]) - dec(img.data[3 * i + 2])));
    CHECK(worst < 1e-9); /* neutral again */

    /* asking for a ColorChecker where there is none falls back, saying so */
    for (size_t i = 0; i < 200 * 150; ++i)
        img.data[3 * i] = enc(dec(img.data[3 * i]) * 1.1);
    CHECK(phc_photo_colour_correct(&img, NULL, PHC_CC_COLORCHECKER, &rep, &err) == PHC_OK);
    CHECK(rep.method == PHC_CC_GRAY_WORLD);
    CHECK_STR_CONTAINS(rep.note, "gray world");
    CHECK_NEAR(rep.gains[0] / rep.gains[1], 1 / 1.1, 1e-9, 0);

    /* NONE leaves the image alone; a black channel is an error */
    const double before = img.data[7];
    CHECK(phc_photo_colour_correct(&img, NULL, PHC_CC_NONE, &rep, &err) == PHC_OK);
    CHECK(img.data[7] == before && rep.method == PHC_CC_NONE);
    for (size_t i = 0; i < 200 * 150; ++i)
        img.data[3 * i + 2] = 0;
    CHECK(phc_photo_colour_correct(&img, NULL, PHC_CC_GRAY_WORLD, &rep, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "blue");
    phc_image_free(&img);
}

/* ---- registration ------------------------------------------------------------------- */

/* A non-periodic texture (incommensurate waves of 15-40 px and two blobs):
 * enough gradient everywhere for ECC to be well conditioned; a smoother
 * one (waves of 30-120 px) leaves the warp uncertain by ~0.1 px, because
 * OpenCV's ECC works in single precision. */
static double texture(double x, double y)
{
    double v = 0.5 + 0.12 * sin(0.313 * x + 0.171 * y) + 0.10 * cos(0.152 * x - 0.331 * y) +
               0.08 * sin(0.417 * x) * cos(0.373 * y + 0.4) + 0.06 * sin(0.05 * x * (1 + 0.003 * y));
    v += 0.15 * exp(-((x - 60) * (x - 60) + (y - 50) * (y - 50)) / 300.0);
    v -= 0.12 * exp(-((x - 140) * (x - 140) + (y - 110) * (y - 110)) / 500.0);
    return v;
}

static void test_registration(void)
{
    phc_error err;
    const size_t W = 220, H = 180;
    const double th = 1.0 * 3.14159265358979323846 / 180, tx = 3.5, ty = -2.0;
    /* true warp: reference pixel p -> moving pixel R p + t */
    const double wt[6] = {cos(th), -sin(th), tx, sin(th), cos(th), ty};
    phc_image ref, mov, out;
    phc_image_alloc(&ref, W, H, &err);
    phc_image_alloc(&mov, W, H, &err);
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            const double r = texture(x, y);
            set_px(&ref, x, y, r, 0.9 * r, 0.8 * r);
            /* moving(q) = ref(W^-1 q): W^-1 q = R^T (q - t) */
            const double qx = x - tx, qy = y - ty;
            const double px = wt[0] * qx + wt[3] * qy, py = wt[1] * qx + wt[4] * qy;
            const double m = texture(px, py);
            set_px(&mov, x, y, m, 0.9 * m, 0.8 * m);
        }
    double w[6], cc = 0, c0 = 0;
    CHECK(phc_photo_correlation(&ref, &mov, NULL, &c0, &err) == PHC_OK);
    int rc = phc_photo_register(&ref, &mov, NULL, NULL, &out, w, &cc, &err);
    CHECK(rc == PHC_OK);
    if (rc == PHC_OK) {
        /* the warps agree within 0.05 px at the corners and the centre */
        const double pts[5][2] = {{0, 0}, {W - 1, 0}, {0, H - 1}, {W - 1, H - 1}, {W / 2.0, H / 2.0}};
        double worst = 0;
        for (int k = 0; k < 5; ++k) {
            const double x = pts[k][0], y = pts[k][1];
            const double dx = (w[0] - wt[0]) * x + (w[1] - wt[1]) * y + (w[2] - wt[2]);
            const double dy = (w[3] - wt[3]) * x + (w[4] - wt[4]) * y + (w[5] - wt[5]);
            worst = fmax(worst, hypot(dx, dy));
        }
        printf("ECC: warp error %.4f px, correlation %.5f (before %.4f); warp %.5f %.5f %.4f / %.5f %.5f %.4f\n", worst, cc, c0, w[0], w[1], w[2], w[3], w[4], w[5]);
        CHECK(worst < 0.05);
        CHECK(cc > 0.99);
        CHECK(cc > c0);
        CHECK(out.width == W && out.height == H);
        /* the warped image matches the reference inside */
        CHECK_NEAR(out.data[3 * (110 + W * 90)], ref.data[3 * (110 + W * 90)], 0.01, 0);
        /* pure translation model */
        phc_register_options o = phc_register_options_default();
        o.motion = PHC_MOTION_TRANSLATION;
        phc_image_free(&out);
        CHECK(phc_photo_register(&ref, &mov, NULL, &o, &out, w, &cc, &err) == PHC_OK);
        CHECK(w[0] == 1 && w[1] == 0 && w[3] == 0 && w[4] == 1);
    }
    phc_image_free(&out);
    /* size mismatch */
    phc_image small;
    phc_image_alloc(&small, W - 1, H, &err);
    CHECK(phc_photo_register(&ref, &small, NULL, NULL, &out, w, &cc, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "219x180");
    phc_image_free(&small);
    /* unrelated images: ECC does not converge, or converges to a poor fit */
    for (size_t i = 0; i < 3 * W * H; ++i)
        mov.data[i] = uniform();
    rc = phc_photo_register(&ref, &mov, NULL, NULL, &out, w, &cc, &err);
    CHECK(rc == PHC_ERR_NOT_CONVERGED || (rc == PHC_OK && cc < 0.5));
    if (rc == PHC_ERR_NOT_CONVERGED)
        CHECK_STR_CONTAINS(err.message, "ECC");
    phc_image_free(&out);
    phc_image_free(&ref);
    phc_image_free(&mov);
}

/* ---- veins ------------------------------------------------------------------------------ */

static void test_veins(void)
{
    phc_error err;
    const size_t W = 160, H = 160;
    phc_image img;
    unsigned char truth[160 * 160], *bin = NULL;
    phc_image_alloc(&img, W, H, &err);
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            /* three-pixel dark lines: two horizontal, one vertical, a diagonal */
            const int line = (y >= 39 && y <= 41) || (y >= 109 && y <= 111) || (x >= 59 && x <= 61) ||
                             fabs((double)x - (double)y * 0.7 - 20) <= 1.2;
            truth[x + W * y] = (unsigned char)line;
            const double n = 0.02 * (uniform() - 0.5);
            if (line)
                set_px(&img, x, y, 0.10 + n, 0.28 + n, 0.08 + n);
            else
                set_px(&img, x, y, 0.20 + n, 0.50 + n, 0.15 + n);
        }
    double *v = NULL, p = 0, r = 0;
    phc_vein_options vo = phc_vein_options_default();
    CHECK(phc_photo_vein_map(&img, NULL, &vo, &v, &err) == PHC_OK);
    CHECK(phc_photo_vein_binary(W, H, v, NULL, &bin, &err) == PHC_OK);
    if (bin) {
        CHECK(phc_photo_vein_scores(W, H, bin, truth, 2, &p, &r, &err) == PHC_OK);
        printf("synthetic veins: precision %.3f recall %.3f (tolerance 2 px)\n", p, r);
        CHECK(p > 0.9);
        CHECK(r > 0.9);
        double maxv = 0;
        for (size_t i = 0; i < W * H; ++i)
            maxv = fmax(maxv, v[i]);
        CHECK(maxv <= 1 && v[100 + W * 40] > 0.5);
    }
    free(bin);
    free(v);
    /* a mask: zero outside */
    unsigned char mask[160 * 160];
    for (size_t i = 0; i < W * H; ++i)
        mask[i] = i % W < 120;
    CHECK(phc_photo_vein_map(&img, mask, NULL, &v, &err) == PHC_OK);
    if (v)
        CHECK(v[130 + W * 40] == 0);
    free(v);
    /* scores by hand: a prediction shifted by 2 px is right at tolerance 2, wrong at 1 */
    unsigned char a[100] = {0}, b[100] = {0};
    for (size_t x = 0; x < 10; ++x)
        a[x + 10 * 3] = 1, b[x + 10 * 5] = 1;
    CHECK(phc_photo_vein_scores(10, 10, a, b, 2, &p, &r, &err) == PHC_OK);
    CHECK(p == 1 && r == 1);
    CHECK(phc_photo_vein_scores(10, 10, a, b, 1, &p, &r, &err) == PHC_OK);
    CHECK(p == 0 && r == 0);
    memset(b, 0, sizeof b);
    CHECK(phc_photo_vein_scores(10, 10, a, b, 1, &p, &r, &err) == PHC_ERR_INPUT);
    vo.sigma_min = 0;
    CHECK(phc_photo_vein_map(&img, NULL, &vo, &v, &err) == PHC_ERR_INVALID);
    phc_image_free(&img);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/phc_test_photo_XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_files();
    test_resize();
    test_segmentation();
    test_gray_world();
    test_registration();
    test_veins();
    /* every file written was removed by name: a leftover temporary file
     * would make rmdir fail */
    CHECK(rmdir(dir) == 0);
    return check_finish("test_photo");
}
