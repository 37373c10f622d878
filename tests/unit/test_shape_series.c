/* Tracked motion reader (measurements/shape_series.h) on small files written
 * to a temporary directory: units (time, length, pixels with a scale and
 * y down, degrees and radians), angle unwrapping across
 * 360 -> 0 both ways, CRLF, and every refusal with its file:line or spec
 * location. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "measurements/shape_series.h"
#include "measurements/units.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static char dir[256];

static const char *write_file(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f)
        return NULL;
    fputs(text, f);
    fclose(f);
    return path;
}

static const double deg = M_PI / 180.0;

/* Reads `text` as file `name` with one angle series over column `col`. */
static int read_angle(phc_units *u, const char *name, const char *text, const char *tunit,
                      const char *col, const char *aunit, phc_shape_series **out, phc_error *err)
{
    phc_shape_series_spec s = {0};
    s.id = "flower";
    s.kind = PHC_SHAPE_ANGLE;
    s.angle = col;
    s.angle_unit = aunit;
    s.where = "cfg.yaml:7";
    phc_shape_spec spec = {"Time (s)", tunit, "cfg.yaml:5", 1, &s};
    const char *path = write_file(name, text);
    return phc_shape_series_read(path, &spec, u, out, err);
}

int main(void)
{
    phc_error err;
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/phc_shape_series_XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    phc_units *u = phc_units_new(&err);
    CHECK(u != NULL);
    if (!u) {
        fprintf(stderr, "%s\n", err.message);
        return check_finish("test_shape_series");
    }

    /* ---- unwrap itself: steps of at most pi, 2 pi multiples added */
    {
        double a[6] = {350 * deg, 355 * deg, 2 * deg, 10 * deg, 350 * deg, 5 * deg};
        phc_angle_unwrap(a, 6);
        const double want[6] = {350, 355, 362, 370, 350, 365};
        for (int i = 0; i < 6; ++i)
            CHECK_NEAR(a[i] / deg, want[i], 1e-9, 0);
        /* several turns in one step are not guessed: 10 -> 730 deg is a 0 deg step */
        double b[2] = {10 * deg, 730 * deg};
        phc_angle_unwrap(b, 2);
        CHECK_NEAR(b[1] / deg, 10, 1e-9, 0);
        /* backwards across 0: 5 -> 355 is -10 */
        double c[3] = {5 * deg, 355 * deg, 340 * deg};
        phc_angle_unwrap(c, 3);
        CHECK_NEAR(c[1] / deg, -5, 1e-9, 0);
        CHECK_NEAR(c[2] / deg, -20, 1e-9, 0);
        phc_angle_unwrap(c, 0); /* no samples: nothing happens */
        phc_angle_unwrap(c, 1);
        CHECK_NEAR(c[0] / deg, 5, 1e-12, 0);
    }

    /* ---- angles in degrees, CRLF, a Frame column ignored, wrap 360 -> 0 */
    {
        phc_shape_series *s = NULL;
        const char *text = "Frame,Time (s),Flower 1 Angle (deg)\r\n"
                           "1,10,350.5\r\n2,20,359\r\n3,30,1.5\r\n4,40,48\r\n";
        CHECK(read_angle(u, "a.csv", text, "s", "Flower 1 Angle (deg)", "deg", &s, &err) == PHC_OK);
        if (s) {
            CHECK(s->n_times == 4 && s->n_tracks == 1 && s->tracks[0].dim == 1);
            CHECK_NEAR(s->t[0], 10, 0, 0);
            CHECK_NEAR(s->t[3], 40, 0, 0);
            CHECK(s->line[0] == 2 && s->line[3] == 5);
            CHECK_NEAR(s->tracks[0].value[2] / deg, 361.5, 1e-9, 0);
            CHECK_NEAR(s->tracks[0].value[3] / deg, 408, 1e-9, 0);
            CHECK(phc_shape_series_find(s, "flower") == 0);
            CHECK(phc_shape_series_find(s, "leaf") == -1);
            printf("deg, wrapped 350.5 359 1.5 48 -> unwrapped %.6g %.6g %.6g %.6g deg\n",
                   s->tracks[0].value[0] / deg, s->tracks[0].value[1] / deg,
                   s->tracks[0].value[2] / deg, s->tracks[0].value[3] / deg);
            phc_shape_series_free(s);
        }
        /* keep_wrapped and y_down (image axes: clockwise, negated) */
        phc_shape_series_spec sp = {0};
        sp.id = "f";
        sp.kind = PHC_SHAPE_ANGLE;
        sp.angle = "Flower 1 Angle (deg)";
        sp.angle_unit = "degrees";
        sp.keep_wrapped = 1;
        phc_shape_spec spec = {"Time (s)", "s", NULL, 1, &sp};
        CHECK(phc_shape_series_parse(text, strlen(text), "mem.csv", &spec, u, &s, &err) == PHC_OK);
        if (s) {
            CHECK_NEAR(s->tracks[0].value[2] / deg, 1.5, 1e-12, 0);
            phc_shape_series_free(s);
        }
        sp.keep_wrapped = 0;
        sp.y_down = 1;
        CHECK(phc_shape_series_parse(text, strlen(text), "mem.csv", &spec, u, &s, &err) == PHC_OK);
        if (s) {
            /* -350.5, -359, -361.5, -408 */
            CHECK_NEAR(s->tracks[0].value[0] / deg, -350.5, 1e-9, 0);
            CHECK_NEAR(s->tracks[0].value[3] / deg, -408, 1e-9, 0);
            phc_shape_series_free(s);
        }
    }

    /* ---- radians, time in minutes, the UDUNITS-2 name arc_degree */
    {
        phc_shape_series *s = NULL;
        const char *text = "Time (s),A\n0.5,3.0\n1.0,-3.0\n1.5,3.1\n";
        CHECK(read_angle(u, "r.csv", text, "min", "A", "rad", &s, &err) == PHC_OK);
        if (s) {
            CHECK_NEAR(s->t[0], 30, 0, 1e-15);
            CHECK_NEAR(s->t[2], 90, 0, 1e-15);
            /* 3.0 -> -3.0 is +0.283 (across pi), then -> 3.1 is -0.183 */
            CHECK_NEAR(s->tracks[0].value[1], 2 * M_PI - 3.0, 1e-12, 0);
            CHECK_NEAR(s->tracks[0].value[2], 3.1, 1e-12, 0);
            phc_shape_series_free(s);
        }
        const char *t2 = "Time (s),A\n1,90\n2,180\n";
        CHECK(read_angle(u, "u.csv", t2, "h", "A", "arc_degree", &s, &err) == PHC_OK);
        if (s) {
            CHECK_NEAR(s->t[1], 7200, 0, 1e-15);
            CHECK_NEAR(s->tracks[0].value[0], M_PI / 2, 0, 1e-14);
            CHECK_NEAR(s->tracks[0].value[1], M_PI, 0, 1e-14);
            phc_shape_series_free(s);
        } else {
            fprintf(stderr, "%s\n", err.message);
        }
    }

    /* ---- points: pixels with a scale and y down (2-D), mm with z (3-D) */
    {
        const char *text = "Time (s),P1 (x),P1 (y),Q x,Q y,Q z\n"
                           "10,100,200,1,2,3\n20,101,198,4,5,6\n";
        phc_shape_series_spec sp[2] = {{0}, {0}};
        sp[0].id = "p1";
        sp[0].kind = PHC_SHAPE_POINT;
        sp[0].x = "P1 (x)";
        sp[0].y = "P1 (y)";
        sp[0].length_unit = "px";
        sp[0].metres_per_pixel = 2e-4;
        sp[0].y_down = 1;
        sp[1].id = "q";
        sp[1].kind = PHC_SHAPE_POINT;
        sp[1].x = "Q x";
        sp[1].y = "Q y";
        sp[1].z = "Q z";
        sp[1].length_unit = "mm";
        phc_shape_spec spec = {"Time (s)", "s", NULL, 2, sp};
        phc_shape_series *s = NULL;
        CHECK(phc_shape_series_read(write_file("p.csv", text), &spec, u, &s, &err) == PHC_OK);
        if (s) {
            CHECK(s->n_tracks == 2 && s->tracks[0].dim == 2 && s->tracks[1].dim == 3);
            CHECK_NEAR(s->tracks[0].value[0], 0.02, 0, 1e-15);
            CHECK_NEAR(s->tracks[0].value[1], -0.04, 0, 1e-15);
            CHECK_NEAR(s->tracks[0].value[3], -0.0396, 0, 1e-15);
            CHECK_NEAR(s->tracks[1].value[2], 0.003, 0, 1e-15);
            CHECK_NEAR(s->tracks[1].value[3], 0.004, 0, 1e-15);
            CHECK_NEAR(s->tracks[1].value[5], 0.006, 0, 1e-15);
            printf("px (2e-4 m/px, y down): (100, 200) px -> (%.6g, %.6g) m; mm: z 3 -> %.6g m\n",
                   s->tracks[0].value[0], s->tracks[0].value[1], s->tracks[1].value[2]);
            phc_shape_series_free(s);
        } else {
            fprintf(stderr, "%s\n", err.message);
        }

        /* refusals of the spec: pixels without a scale, unknown length unit,
         * a duration as a length, duplicate ids, unknown columns (did you mean) */
        sp[0].metres_per_pixel = 0;
        CHECK(phc_shape_series_read(write_file("p.csv", text), &spec, u, &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "series 'p1': coordinates in pixels need a scale in m/px");
        CHECK(s == NULL);
        sp[0].metres_per_pixel = 2e-4;
        sp[1].length_unit = "furlongz";
        sp[1].where = "cfg.yaml:22";
        CHECK(phc_shape_series_read(write_file("p.csv", text), &spec, u, &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cfg.yaml:22: series 'q': length unit");
        CHECK_STR_CONTAINS(err.message, "furlongz");
        printf("unknown unit: %s\n", err.message);
        sp[1].length_unit = "s";
        CHECK(phc_shape_series_read(write_file("p.csv", text), &spec, u, &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cannot be converted");
        sp[1].length_unit = "mm";
        sp[1].id = "p1";
        CHECK(phc_shape_series_read(write_file("p.csv", text), &spec, u, &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "series id 'p1' is used twice");
        sp[1].id = "q";
        sp[1].z = "Qz";
        CHECK(phc_shape_series_read(write_file("p.csv", text), &spec, u, &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cfg.yaml:22: series 'q'");
        CHECK_STR_CONTAINS(err.message, "p.csv:1: unknown column 'Qz'; did you mean 'Q z'?");
        printf("unknown column: %s\n", err.message);
        sp[1].z = NULL;
        sp[1].y = NULL;
        CHECK(phc_shape_series_read(write_file("p.csv", text), &spec, u, &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "a point needs x and y columns");
    }

    /* ---- refusals of the data: time order, NaN and empty cells, header only */
    {
        phc_shape_series *s = NULL;
        CHECK(read_angle(u, "eq.csv", "Time (s),A\n10,1\n20,2\n20,3\n", "s", "A", "deg", &s,
                         &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "eq.csv:4: column 'Time (s)': time 20 s is not after the "
                                        "previous row's 20 s (line 3)");
        CHECK(s == NULL);
        printf("equal times: %s\n", err.message);
        CHECK(read_angle(u, "back.csv", "Time (s),A\n# comment\n10,1\n20,2\n15,3\n", "min", "A",
                         "deg", &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "back.csv:5: column 'Time (s)': time 15 min is not after "
                                        "the previous row's 20 min (line 4)");
        CHECK(read_angle(u, "nan.csv", "Time (s),A\n10,1\n20,nan\n", "s", "A", "deg", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "nan.csv:3: column 'A': expected a finite number, found 'nan'");
        printf("NaN cell: %s\n", err.message);
        CHECK(read_angle(u, "empty.csv", "Time (s),A\n10,1\n20,\n", "s", "A", "deg", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "empty.csv:3: column 'A'");
        CHECK(read_angle(u, "tnan.csv", "Time (s),A\nx,1\n", "s", "A", "deg", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "tnan.csv:2: column 'Time (s)'");
        CHECK(read_angle(u, "hdr.csv", "Time (s),A\n", "s", "A", "deg", &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "hdr.csv: no data rows");
        /* spec errors on the time and angle columns */
        CHECK(read_angle(u, "ok.csv", "Time (s),A\n10,1\n", "s", "Flower 1 Angle", "deg", &s,
                         &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cfg.yaml:7: series 'flower': ");
        CHECK_STR_CONTAINS(err.message, "ok.csv:1: unknown column 'Flower 1 Angle'");
        CHECK(read_angle(u, "ok.csv", "Time(s),A\n10,1\n", "s", "A", "deg", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cfg.yaml:5: time column: ");
        CHECK_STR_CONTAINS(err.message, "ok.csv:1: unknown column 'Time (s)'; did you mean 'Time(s)'?");
        CHECK(read_angle(u, "ok.csv", "Time (s),A\n10,1\n", "fortnightz", "A", "deg", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cfg.yaml:5: time unit");
        CHECK(read_angle(u, "ok.csv", "Time (s),A\n10,1\n", "m", "A", "deg", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cannot be converted to 's'");
        CHECK(read_angle(u, "ok.csv", "Time (s),A\n10,1\n", "s", "A", "degs", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "cfg.yaml:7: series 'flower': angle unit 'degs' is not");
        printf("unknown angle unit: %s\n", err.message);
        CHECK(read_angle(u, "ok.csv", "Time (s),A\n10,1\n", "s", "A", "kg", &s, &err) ==
              PHC_ERR_INPUT);
        /* dimensionless units are not angles, though UDUNITS-2 converts them to radians */
        CHECK(read_angle(u, "ok.csv", "Time (s),A\n10,1\n", "s", "A", "percent", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "angle unit 'percent' is not one phytocal reads");
        CHECK(read_angle(u, "ok.csv", "Time (s),A\n10,1\n", "s", "A", "", &s, &err) ==
              PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "no angle unit");
        CHECK(phc_shape_series_read(dir, NULL, u, &s, &err) == PHC_ERR_INVALID);
        phc_shape_spec none = {"Time (s)", "s", NULL, 0, NULL};
        CHECK(phc_shape_series_read("x.csv", &none, u, &s, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "no series named");
        /* a missing file */
        phc_shape_series_spec sp = {0};
        sp.id = "a";
        sp.kind = PHC_SHAPE_ANGLE;
        sp.angle = "A";
        sp.angle_unit = "deg";
        phc_shape_spec one = {"Time (s)", "s", NULL, 1, &sp};
        char missing[600];
        snprintf(missing, sizeof missing, "%s/missing.csv", dir);
        CHECK(phc_shape_series_read(missing, &one, NULL, &s, &err) == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "missing.csv");
        /* the units database loaded by the reader itself (units NULL) */
        const char *ok = write_file("ok2.csv", "Time (s),A\n10,1\n");
        CHECK(phc_shape_series_read(ok, &one, NULL, &s, &err) == PHC_OK);
        phc_shape_series_free(s);
    }

    phc_units_free(u);
    /* remove the temporary files */
    const char *names[] = {"a.csv", "r.csv", "u.csv", "p.csv", "eq.csv", "back.csv", "nan.csv",
                           "empty.csv", "tnan.csv", "hdr.csv", "ok.csv", "ok2.csv"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        char p[600];
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        unlink(p);
    }
    rmdir(dir);
    return check_finish("test_shape_series");
}
