/* The tracked flower motion of ../shared/data/plant_motion (README there:
 * thaithanhtuan/VisualPlantResponse, a time-lapse during hydration stress)
 * through the shape-series reader (measurements/shape_series.h):
 *  - angles.csv: 4 flower angles in degrees, image axes, taken mod 360.
 *    Printed: rows, time span, each flower's unwrapped start and end.
 *    The README says flower 1 goes 218 -> 159 deg and flower 4 321 deg
 *    through 360 to 48 deg: unwrapped, flower 4 must end near 408 deg
 *    (continuous), flower 1 near 159 deg.
 *  - points.csv: 16 points in integer pixels (y down).  No scale exists in
 *    the data, so the test reads them at 1 m/px (values stay in pixels) with
 *    y_down off, recomputes each flower's angle as the README states
 *    (atan2 of v = (p1 - p3) + (p2 - p3), mod 360) and compares with
 *    angles.csv: the largest difference is printed (README: 5e-8 deg).
 * Skips (77) when the data folder is absent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "check.h"
#include "measurements/shape_series.h"
#include "measurements/units.h"

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif
#define MOTION_DIR PHC_SHARED_DATA "/plant_motion"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

int main(void)
{
    struct stat st;
    if (stat(MOTION_DIR "/angles.csv", &st) != 0 || stat(MOTION_DIR "/points.csv", &st) != 0) {
        printf("test_shape_series_real: %s is absent: skipped\n", MOTION_DIR);
        return 77;
    }
    phc_error err;
    phc_units *u = phc_units_new(&err);
    CHECK(u != NULL);
    if (!u) {
        fprintf(stderr, "%s\n", err.message);
        return check_finish("test_shape_series_real");
    }
    const double deg = 180.0 / M_PI;

    /* ---- angles.csv */
    char names[4][40], ids[4][16];
    phc_shape_series_spec as[4];
    for (int f = 0; f < 4; ++f) {
        snprintf(names[f], sizeof names[f], "Flower %d Angle (deg)", f + 1);
        snprintf(ids[f], sizeof ids[f], "flower%d", f + 1);
        as[f] = (phc_shape_series_spec){0};
        as[f].id = ids[f];
        as[f].kind = PHC_SHAPE_ANGLE;
        as[f].angle = names[f];
        as[f].angle_unit = "deg";
    }
    phc_shape_spec aspec = {"Time (s)", "s", NULL, 4, as};
    phc_shape_series *a = NULL;
    CHECK(phc_shape_series_read(MOTION_DIR "/angles.csv", &aspec, u, &a, &err) == PHC_OK);
    if (!a) {
        fprintf(stderr, "%s\n", err.message);
        phc_units_free(u);
        return check_finish("test_shape_series_real");
    }
    const size_t n = a->n_times;
    printf("angles.csv: %zu rows, time %g s .. %g s (%.3f h), lines %zu .. %zu\n", n, a->t[0],
           a->t[n - 1], (a->t[n - 1] - a->t[0]) / 3600, a->line[0], a->line[n - 1]);
    CHECK(n == 1022);
    CHECK_NEAR(a->t[0], 10, 0, 0);
    CHECK_NEAR(a->t[n - 1], 10220, 0, 0);
    double start[4], end[4], minv[4], maxv[4];
    for (int f = 0; f < 4; ++f) {
        const double *v = a->tracks[f].value;
        start[f] = v[0] * deg;
        end[f] = v[n - 1] * deg;
        minv[f] = maxv[f] = start[f];
        double maxstep = 0;
        for (size_t i = 0; i < n; ++i) {
            minv[f] = fmin(minv[f], v[i] * deg);
            maxv[f] = fmax(maxv[f], v[i] * deg);
            if (i)
                maxstep = fmax(maxstep, fabs(v[i] - v[i - 1]) * deg);
        }
        printf("  flower %d: unwrapped start %.4f deg, end %.4f deg (range %.4f .. %.4f, "
               "largest step %.4f deg)\n",
               f + 1, start[f], end[f], minv[f], maxv[f], maxstep);
        CHECK(maxstep < 180);
    }
    /* README: flower 1 218 -> 159, flower 2 316 -> 348, flower 3 312 -> 339,
     * flower 4 321 -> through 360 -> 48, i.e. 408 unwrapped */
    CHECK(fabs(start[0] - 218) < 1 && fabs(end[0] - 159) < 1);
    CHECK(fabs(start[1] - 316) < 1 && fabs(end[1] - 348) < 1);
    CHECK(fabs(start[2] - 312) < 1 && fabs(end[2] - 339) < 1);
    CHECK(fabs(start[3] - 321) < 1 && fabs(end[3] - 408) < 1);
    /* where flower 4 crosses 360 (README: between t = 7630 s and 7640 s) */
    for (size_t i = 1; i < n; ++i)
        if (a->tracks[3].value[i - 1] * deg < 360 && a->tracks[3].value[i] * deg >= 360) {
            printf("  flower 4 crosses 360 deg between t = %g s and %g s (lines %zu, %zu)\n",
                   a->t[i - 1], a->t[i], a->line[i - 1], a->line[i]);
            CHECK(a->t[i - 1] == 7630 && a->t[i] == 7640);
            break;
        }

    /* ---- points.csv: 16 points in px, image axes */
    char pn[16][2][24], pid[16][12];
    phc_shape_series_spec ps[16];
    for (int k = 0; k < 16; ++k) {
        snprintf(pn[k][0], sizeof pn[k][0], "Point %d (x)", k + 1);
        snprintf(pn[k][1], sizeof pn[k][1], "Point %d (y)", k + 1);
        snprintf(pid[k], sizeof pid[k], "point%d", k + 1);
        ps[k] = (phc_shape_series_spec){0};
        ps[k].id = pid[k];
        ps[k].kind = PHC_SHAPE_POINT;
        ps[k].x = pn[k][0];
        ps[k].y = pn[k][1];
        ps[k].length_unit = "px";
        ps[k].metres_per_pixel = 1.0; /* no scale in the data: keep pixels */
    }
    phc_shape_spec pspec = {"Time (s)", "s", NULL, 16, ps};
    phc_shape_series *p = NULL;
    CHECK(phc_shape_series_read(MOTION_DIR "/points.csv", &pspec, u, &p, &err) == PHC_OK);
    if (p) {
        printf("points.csv: %zu rows, time %g s .. %g s, %zu points\n", p->n_times, p->t[0],
               p->t[p->n_times - 1], p->n_tracks);
        CHECK(p->n_times == n);
        for (size_t i = 0; i < n && i < p->n_times; ++i)
            CHECK(p->t[i] == a->t[i]);
        double worst = 0;
        for (int f = 0; f < 4; ++f) {
            const double *p1 = p->tracks[3 * f].value, *p2 = p->tracks[3 * f + 1].value,
                         *p3 = p->tracks[3 * f + 2].value;
            for (size_t i = 0; i < n; ++i) {
                const double vx = (p1[2 * i] - p3[2 * i]) + (p2[2 * i] - p3[2 * i]);
                const double vy = (p1[2 * i + 1] - p3[2 * i + 1]) + (p2[2 * i + 1] - p3[2 * i + 1]);
                const double ang = fmod(atan2(vy, vx) * deg + 360.0, 360.0);
                /* angles.csv kept mod 360: compare on the circle */
                double d = fabs(ang - fmod(a->tracks[f].value[i] * deg + 720.0, 360.0));
                d = fmin(d, 360 - d);
                worst = fmax(worst, d);
            }
        }
        printf("  flower angles recomputed from points.csv vs angles.csv: largest difference "
               "%.3g deg\n",
               worst);
        CHECK(worst < 1e-6);
        const double *p1 = p->tracks[0].value;
        printf("  point 1 (flower 1 petal tip): start (%g, %g) px, end (%g, %g) px\n", p1[0],
               p1[1], p1[2 * (n - 1)], p1[2 * (n - 1) + 1]);
        phc_shape_series_free(p);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_shape_series_free(a);
    phc_units_free(u);
    return check_finish("test_shape_series_real");
}
