/* Unit test of the shape outputs: the side-view PNG (fit/shape_plots.h) and
 * the legacy VTK writer (measurements/plant_io.h, phc_plant_io_write_vtk).
 *
 * The PNG is read back: a panel of dry segments shows the dry end of the
 * colour scale and no wet colour, a panel of wet segments the opposite, a
 * thick segment covers more pixels than a thin one of the same length, the
 * markers are drawn.  Bad input gives an error naming the panel and
 * segment and leaves an earlier file untouched.  The VTK file is read back
 * and its counts, points, lines and fields compared with the graph.
 * PHC_KEEP_PLOTS=1 keeps the files (their directory is printed). */
#include "fit/shape_plots.h"
#include "measurements/photo.h"
#include "measurements/plant_io.h"
#include "model/plant_graph.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"

static const double DRY[3] = {140 / 255.0, 81 / 255.0, 10 / 255.0};
static const double WET[3] = {27 / 255.0, 120 / 255.0, 55 / 255.0};
static const double MARKER[3] = {200 / 255.0, 30 / 255.0, 30 / 255.0};

static size_t count_colour(const phc_image *img, const double rgb[3], size_t x0, size_t x1)
{
    size_t n = 0;
    for (size_t y = 0; y < img->height; ++y)
        for (size_t x = x0; x < x1 && x < img->width; ++x) {
            const double *p = img->data + 3 * (x + img->width * y);
            if (fabs(p[0] - rgb[0]) < 0.03 && fabs(p[1] - rgb[1]) < 0.03 &&
                fabs(p[2] - rgb[2]) < 0.03)
                ++n;
        }
    return n;
}

/* A stem of 3 segments up z, and one side branch from its top along +x. */
static phc_plant_graph *small_plant(void)
{
    phc_plant_graph *g = phc_plant_graph_new(4);
    const double pts[5][3] = {{0, 0, 0}, {0, 0, 0.05}, {0, 0, 0.10}, {0, 0, 0.15}, {0.08, 0, 0.12}};
    if (!g)
        return NULL;
    for (size_t i = 0; i < 4; ++i) {
        const size_t from = i < 3 ? i : 3, to = i + 1;
        memcpy(g->head + 3 * i, pts[from], sizeof pts[0]);
        memcpy(g->tail + 3 * i, pts[to], sizeof pts[0]);
        g->parent[i] = i == 0 ? PHC_PLANT_NO_PARENT : (i < 3 ? i - 1 : 2);
        g->radius[i] = i < 3 ? 0.004 : 0.001;
        g->length[i] = sqrt(pow(pts[to][0] - pts[from][0], 2) + pow(pts[to][2] - pts[from][2], 2));
        g->leaf[i] = i == 3;
        g->source_id[i] = 10 + (long)i;
    }
    g->fixed[0] = 1;
    if (phc_plant_graph_finish(g, "small plant", NULL)) {
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

static void test_plot(const char *dir, const phc_plant_graph *g)
{
    char path[512];
    phc_error err;
    phc_image img = {0};
    const double dry[4] = {0.2, 0.2, 0.2, 0.2}, wet[4] = {1, 1, 1, 1};
    const double marker[3] = {0.08, 0, 0.12};
    phc_shape_panel panels[2] = {
        {g->n, g->head, g->tail, g->radius, dry, "dry (RWC 0.2)", 0, NULL, NULL},
        {g->n, g->head, g->tail, g->radius, wet, "wet (RWC 1)", 1, marker, "tracked tip"}};
    phc_shape_plot_options o = phc_shape_plot_options_default();
    o.value_min = 0.2;
    o.value_max = 1.0;
    o.title = "test: two panels";
    o.columns = 2;
    snprintf(path, sizeof path, "%s/shape.png", dir);
    CHECK(phc_shape_plot(path, panels, 2, &o, &err) == PHC_OK);
    CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
    if (img.data) {
        const size_t half = (size_t)(0.43 * (double)img.width); /* panels end at 0.86 */
        const size_t dry_left = count_colour(&img, DRY, 0, half);
        const size_t wet_left = count_colour(&img, WET, 0, half);
        const size_t dry_right = count_colour(&img, DRY, half, (size_t)(0.86 * img.width));
        const size_t wet_right = count_colour(&img, WET, half, (size_t)(0.86 * img.width));
        const size_t red = count_colour(&img, MARKER, 0, img.width);
        printf("shape.png %zux%zu: dry panel %zu dry / %zu wet px, wet panel %zu dry / %zu wet px, "
               "marker %zu px\n",
               img.width, img.height, dry_left, wet_left, dry_right, wet_right, red);
        CHECK(img.width == 560 * 2 + 200 && img.height == 520 + 120);
        CHECK(dry_left > 200 && wet_left == 0);
        CHECK(wet_right > 200 && dry_right == 0);
        CHECK(red > 10);
        phc_image_free(&img);
    }

    /* width grows with radius: the stem (r 4 mm, 15 cm) against the branch
       (r 1 mm, 8.5 cm) in one colour each */
    {
        const double v[4] = {1, 1, 1, 0.2};
        phc_shape_panel one = {g->n, g->head, g->tail, g->radius, v, NULL, 0, NULL, NULL};
        snprintf(path, sizeof path, "%s/width.png", dir);
        CHECK(phc_shape_plot(path, &one, 1, &o, &err) == PHC_OK);
        CHECK(phc_photo_read(path, &img, &err) == PHC_OK);
        if (img.data) {
            const double stem = (double)count_colour(&img, WET, 0, img.width) / 15.0;
            const double branch = (double)count_colour(&img, DRY, 0, img.width) / 8.5;
            printf("width.png: pixels per cm, stem %.1f, branch %.1f\n", stem, branch);
            CHECK(stem > 2.0 * branch);
            phc_image_free(&img);
        }
    }

    /* bad input: an error naming panel and segment, the earlier file kept */
    {
        struct stat before, after;
        double head[12], radius[4];
        memcpy(head, g->head, sizeof head);
        memcpy(radius, g->radius, sizeof radius);
        snprintf(path, sizeof path, "%s/shape.png", dir);
        CHECK(stat(path, &before) == 0);
        head[3 * 2 + 1] = NAN;
        phc_shape_panel bad = {g->n, head, g->tail, g->radius, NULL, NULL, 0, NULL, NULL};
        CHECK(phc_shape_plot(path, &bad, 1, &o, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "panel 1, segment 2: coordinate y is not finite");
        head[3 * 2 + 1] = 0;
        radius[1] = 0;
        bad.radius = radius;
        CHECK(phc_shape_plot(path, &bad, 1, &o, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "segment 1: radius 0 is not positive");
        o.up_axis = 0;
        CHECK(phc_shape_plot(path, panels, 1, &o, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "two different axes");
        o.up_axis = 2;
        CHECK(phc_shape_plot(path, panels, 0, &o, &err) == PHC_ERR_INVALID);
        CHECK(stat(path, &after) == 0 && after.st_size == before.st_size &&
              after.st_mtime == before.st_mtime);
        snprintf(path, sizeof path, "%s/no/such/dir/shape.png", dir);
        CHECK(phc_shape_plot(path, panels, 1, &o, &err) == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "no/such/dir/shape.png");
    }
}

static void test_vtk(const char *dir, const phc_plant_graph *g)
{
    char path[512], line[256];
    phc_error err;
    const double rwc[4] = {1.0, 0.9, 0.8, NAN};
    const phc_plant_field fields[1] = {{"relative_water", rwc}};
    snprintf(path, sizeof path, "%s/plant.vtk", dir);
    CHECK(phc_plant_io_write_vtk(path, g, "frame 0\nsecond line", fields, 1, &err) == PHC_OK);
    FILE *f = fopen(path, "r");
    CHECK(f != NULL);
    if (!f)
        return;
    size_t lines = 0, n_points = 0, n_lines = 0, n_cells = 0, n_pointdata = 0;
    int title_ok = 0, have_rwc = 0, have_id = 0;
    double p[3], first_tail_z = NAN;
    while (fgets(line, sizeof line, f)) {
        ++lines;
        if (lines == 2)
            title_ok = strcmp(line, "frame 0 second line\n") == 0;
        if (sscanf(line, "POINTS %zu double", &n_points) == 1) {
            /* segment 0: head then tail */
            if (fgets(line, sizeof line, f) && fgets(line, sizeof line, f) &&
                sscanf(line, "%lf %lf %lf", p, p + 1, p + 2) == 3)
                first_tail_z = p[2];
            lines += 2;
        }
        sscanf(line, "LINES %zu", &n_lines);
        sscanf(line, "CELL_DATA %zu", &n_cells);
        sscanf(line, "POINT_DATA %zu", &n_pointdata);
        if (strcmp(line, "SCALARS segment_id long 1\n") == 0) {
            long id = -1;
            if (fgets(line, sizeof line, f) && fgets(line, sizeof line, f) &&
                sscanf(line, "%ld", &id) == 1)
                have_id = id == 10;
            lines += 2;
        }
        if (strcmp(line, "SCALARS relative_water double 1\n") == 0) {
            double v[4];
            char w[4][32];
            int ok = fgets(line, sizeof line, f) != NULL; /* LOOKUP_TABLE */
            for (int i = 0; i < 4 && ok; ++i)
                ok = fgets(w[i], sizeof w[i], f) != NULL;
            lines += 5;
            if (ok) {
                for (int i = 0; i < 3; ++i)
                    v[i] = strtod(w[i], NULL);
                have_rwc = v[0] == 1.0 && v[1] == 0.9 && v[2] == 0.8 && strncmp(w[3], "nan", 3) == 0;
            }
        }
    }
    fclose(f);
    printf("plant.vtk: %zu lines, %zu points, %zu lines, %zu cells\n", lines, n_points, n_lines,
           n_cells);
    CHECK(title_ok);
    CHECK(n_points == 8 && n_lines == 4 && n_cells == 4 && n_pointdata == 8);
    CHECK(first_tail_z == 0.05);
    CHECK(have_id);
    CHECK(have_rwc);

    const phc_plant_field bad_name[1] = {{"relative water", rwc}};
    CHECK(phc_plant_io_write_vtk(path, g, NULL, bad_name, 1, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "'relative water'");
    const phc_plant_field taken[1] = {{"radius", rwc}};
    CHECK(phc_plant_io_write_vtk(path, g, NULL, taken, 1, &err) == PHC_ERR_INVALID);
    const phc_plant_field twice[2] = {{"a", rwc}, {"a", rwc}};
    CHECK(phc_plant_io_write_vtk(path, g, NULL, twice, 2, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "given twice");
}

int main(void)
{
    char dir[] = "/tmp/phc_shape_output_XXXXXX";
    phc_plant_graph *g = small_plant();
    CHECK(g != NULL);
    if (!g || !mkdtemp(dir))
        return check_finish("test_shape_output");
    test_plot(dir, g);
    test_vtk(dir, g);
    phc_plant_graph_free(g);
    if (getenv("PHC_KEEP_PLOTS"))
        fprintf(stderr, "test_shape_output: files kept in %s\n", dir);
    else {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "test_shape_output: could not remove %s\n", dir);
    }
    return check_finish("test_shape_output");
}
