/* Unit test of the climbing-plant statistics (model/climbing_statistics.h)
 * and of the traced-shoot reader (measurements/shoot_traces.h).
 *  1. Exact values on a hand-made plant: an L-shaped main axis (0.3 m up,
 *     0.1 m along x) with one lateral leaving at 60° (0.1 m): lengths,
 *     height, light cosine (light from +z: (0.3 + 0.1·cos 60°)/0.5), the
 *     attached fraction to the plane y = 0 (every segment within 5 mm but
 *     the lateral), one order-1 shoot, angle 60° with sd 0.
 *  2. The same plant written as a traces CSV and read back gives the same
 *     statistics at the last time, and at an earlier time only the points
 *     traced so far (no lateral yet: angle NAN, count 0).
 *  3. A shoot grown straight by the model (no branching, full light) has
 *     total length L_max(n σ₀ + r t), as model/climbing_growth.h says, and
 *     light cosine 1; the mean of summaries pools the angles.
 *  4. Bad traces are refused with file:line: unknown parent, time going
 *     backwards, a non-numeric cell, a shoot with one point. */
#include "measurements/shoot_traces.h"
#include "model/climbing_growth.h"
#include "model/climbing_statistics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../check.h"

#define PHC_STAT_PI 3.14159265358979323846

static int plane_y0(void *user, const double x[3], double c[3], double n[3])
{
    (void)user;
    c[0] = x[0]; c[1] = 0; c[2] = x[2];
    n[0] = 0; n[1] = 1; n[2] = 0;
    return 0;
}

static const char *write_tmp(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp", name);
    FILE *f = fopen(path, "w");
    if (!f) return NULL;
    fputs(text, f);
    fclose(f);
    return path;
}

static void check_bad(const char *name, const char *text, const char *needle)
{
    phc_shoot_traces *tr = NULL;
    phc_error err;
    phc_error_clear(&err);
    const char *p = write_tmp(name, text);
    int rc = phc_shoot_traces_read(p, &tr, &err);
    printf("bad %s: %s\n", name, err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(tr == NULL);
    CHECK_STR_CONTAINS(err.message, needle);
}

int main(void)
{
    phc_error err;
    phc_error_clear(&err);
    const double s60 = sin(PHC_STAT_PI / 3), c60 = cos(PHC_STAT_PI / 3);
    /* 1. hand-made plant: main axis (0,0,0)->(0,0,0.3)->(0.1,0,0.3); the
     * lateral from (0,0,0.15) at 60° to +z, in the y direction (0.1 m) */
    phc_shoot_segment seg[3];
    memset(seg, 0, sizeof seg);
    double pts[4][3] = {{0, 0, 0}, {0, 0, 0.3}, {0.1, 0, 0.3}, {0, 0.1 * s60, 0.15 + 0.1 * c60}};
    memcpy(seg[0].base, pts[0], 24); memcpy(seg[0].tip, pts[1], 24);
    memcpy(seg[1].base, pts[1], 24); memcpy(seg[1].tip, pts[2], 24);
    seg[2].base[2] = 0.15; memcpy(seg[2].tip, pts[3], 24);
    seg[2].order = 1; seg[2].lateral_start = 1; seg[2].parent_dir[2] = 2;
    phc_climbing_stat_options o = {.light = {0, 0, 3}, .attach_distance = 0.005, .closest = plane_y0};
    phc_climbing_summary s;
    CHECK(phc_climbing_summarize_segments(seg, 3, &o, &s, &err) == PHC_OK);
    printf("exact: L %.15g main %.15g h %.15g att %.15g cos %.15g n1 %g angle %.15g sd %.3g\n",
           s.total_length, s.main_length, s.height, s.attached_fraction, s.light_cosine, s.shoots[1],
           s.angle_mean, s.angle_sd);
    CHECK_NEAR(s.total_length, 0.5, 1e-15, 0);
    CHECK_NEAR(s.main_length, 0.4, 1e-15, 0);
    CHECK_NEAR(s.height, 0.3, 1e-15, 0);
    CHECK_NEAR(s.attached_fraction, 0.4 / 0.5, 1e-15, 0);
    CHECK_NEAR(s.light_cosine, (0.3 + 0.1 * c60) / 0.5, 1e-14, 0);
    CHECK(s.shoots[1] == 1 && s.shoots[2] == 0);
    CHECK_NEAR(s.angle_mean, 60, 1e-9, 0);
    CHECK_NEAR(s.angle_sd, 0, 1e-6, 0);
    o.closest = NULL;
    CHECK(phc_climbing_summarize_segments(seg, 3, &o, &s, &err) == PHC_OK);
    CHECK(s.attached_fraction == 0);
    o.closest = plane_y0;
    /* 2. the same plant as a CSV; the lateral is traced from t = 20 s */
    char csv[1024];
    snprintf(csv, sizeof csv,
             "# traced by hand\ntime,shoot,x,y,z,parent\n0,main,0,0,0,\n10,main,0,0,0.3,\n"
             "20,side,0,0,0.15,main\n30,main,0.1,0,0.3,\n30,side,0,%.17g,%.17g,main\n",
             0.1 * s60, 0.15 + 0.1 * c60);
    phc_shoot_traces *tr = NULL;
    const char *path = write_tmp("phc_traces_ok.csv", csv);
    CHECK(phc_shoot_traces_read(path, &tr, &err) == PHC_OK);
    if (tr) {
        CHECK(tr->n_shoots == 2 && tr->order[1] == 1 && tr->parent[1] == 0 && tr->t_end == 30);
        phc_shoot_segment *g = NULL;
        size_t n = 0;
        phc_climbing_summary u;
        CHECK(phc_shoot_traces_segments(tr, 30, &g, &n, &err) == PHC_OK && n == 3);
        CHECK(phc_climbing_summarize_segments(g, n, &o, &u, &err) == PHC_OK);
        printf("traced at 30 s: L %.15g angle %.15g\n", u.total_length, u.angle_mean);
        CHECK_NEAR(u.total_length, s.total_length, 1e-15, 0);
        CHECK_NEAR(u.light_cosine, s.light_cosine, 1e-14, 0);
        CHECK_NEAR(u.attached_fraction, 0.8, 1e-15, 0);
        CHECK_NEAR(u.angle_mean, 60, 1e-9, 0);
        free(g);
        CHECK(phc_shoot_traces_segments(tr, 25, &g, &n, &err) == PHC_OK && n == 1);
        CHECK(phc_climbing_summarize_segments(g, n, &o, &u, &err) == PHC_OK);
        printf("traced at 25 s: L %.15g n1 %g angle %g\n", u.total_length, u.shoots[1], u.angle_mean);
        CHECK_NEAR(u.total_length, 0.3, 1e-15, 0);
        CHECK(u.shoots[1] == 0 && isnan(u.angle_mean) && u.angle_n == 0);
        free(g);
        phc_shoot_traces_free(tr);
    }
    /* 3. a straight shoot grown by the model */
    phc_climbing_options co = phc_climbing_options_default();
    co.branch_probability = 0;
    co.growth_rate = 0.1;
    const double base[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    phc_climbing *c = phc_climbing_new(base, up, &co, &err);
    CHECK(c != NULL);
    if (c) {
        for (int k = 0; k < 100; ++k) CHECK(phc_climbing_step(c, 0.5, &err) == PHC_OK);
        const size_t n = phc_climbing_count(c);
        phc_shoot_segment *g = calloc(n, sizeof *g);
        phc_climbing_segments(c, g);
        phc_climbing_summary u[2], mean;
        CHECK(phc_climbing_summarize_segments(g, n, &o, &u[0], &err) == PHC_OK);
        const double want = co.max_length * ((double)n * co.bud_fraction + co.growth_rate * 50);
        printf("grown: n %zu L %.15g expected %.15g cos %.15g height %.15g\n", n, u[0].total_length, want,
               u[0].light_cosine, u[0].height);
        CHECK_NEAR(u[0].total_length, want, 1e-12, 0);
        CHECK_NEAR(u[0].main_length, want, 1e-12, 0);
        CHECK_NEAR(u[0].height, want, 1e-12, 0);
        CHECK_NEAR(u[0].light_cosine, 1, 1e-12, 0);
        /* pooling: the hand-made plant (60°) and one with two laterals at 30° and 90° */
        CHECK(phc_climbing_summarize_segments(seg, 3, &o, &u[0], &err) == PHC_OK);
        u[1] = u[0];
        u[1].angle_n = 2;
        u[1].angle_sum = 120;
        u[1].angle_sum2 = 900 + 8100;
        phc_climbing_summary_mean(u, 2, &mean);
        printf("pooled: mean %.15g sd %.15g\n", mean.angle_mean, mean.angle_sd);
        CHECK_NEAR(mean.angle_mean, 60, 1e-12, 0);
        CHECK_NEAR(mean.angle_sd, sqrt((0 + 900 + 900) / 3.0), 1e-9, 0);
        CHECK_NEAR(mean.total_length, 0.5, 1e-15, 0);
        free(g);
        phc_climbing_free(c);
    }
    /* 4. bad traces */
    check_bad("phc_traces_parent.csv", "time,shoot,x,y,z,parent\n0,a,0,0,0,\n1,a,0,0,1,\n1,b,0,0,0.5,c\n2,b,0,1,1,c\n",
              "phc_traces_parent.csv:4: column 'parent': shoot 'b' names parent 'c'");
    check_bad("phc_traces_back.csv", "time,shoot,x,y,z\n0,a,0,0,0\n5,a,0,0,1\n4,a,0,0,2\n",
              "phc_traces_back.csv:4: column 'time': time goes backwards within shoot 'a'");
    check_bad("phc_traces_text.csv", "time,shoot,x,y,z\n0,a,0,0,0\n5,a,zero,0,1\n",
              "phc_traces_text.csv:3: column 'x'");
    check_bad("phc_traces_one.csv", "time,shoot,x,y,z\n0,a,0,0,0\n5,a,0,0,1\n6,b,0,0,1\n",
              "phc_traces_one.csv:4: column 'shoot': shoot 'b' has 1 point");
    check_bad("phc_traces_cycle.csv", "time,shoot,x,y,z,parent\n0,a,0,0,0,b\n1,a,0,0,1,b\n1,b,0,0,0.5,a\n2,b,0,1,1,a\n",
              "its own ancestor");
    return check_finish("test_climbing_statistics");
}
