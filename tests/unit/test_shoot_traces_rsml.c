/* Traced shoots read from RSML (measurements/shoot_traces.h, reading
 * through measurements/rsml.h).  Every checked number is printed.
 *  1. measurements/examples/climbing/traces.rsml (written by
 *     tests/climbing/shoot_traces_generator.py --rsml beside traces.csv)
 *     gives the same shoots, parents, orders, times and coordinates as
 *     traces.csv, and the same traced segments at several times.
 *  2. Units: the same shoot in mm with resolution 2 (pixels per mm) gives
 *     coordinates / 2 / 1000 m.
 *  3. Bad RSML: no time function, time going backwards, a time function
 *     with too few samples, a unit that is not a length, two roots with one
 *     id: refused naming the file and the line.
 *  4. The real RSML files of ../shared/data/rsml as they come: what happens
 *     (they are root systems without time: refused naming the function). */
#include "measurements/shoot_traces.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"

static long find(const phc_shoot_traces *tr, const char *name)
{
    for (size_t s = 0; s < tr->n_shoots; ++s)
        if (!strcmp(tr->names[s], name)) return (long)s;
    return -1;
}

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

static const char *HEAD = "<?xml version=\"1.0\"?>\n<rsml>\n<metadata><version>1</version><unit>%s</unit>"
                          "<resolution>%s</resolution></metadata>\n<scene><plant id=\"1\">\n";

/* A document: HEAD (unit, resolution) then body. */
static int write_rsml(const char *path, const char *unit, const char *res, const char *body)
{
    char buf[4096];
    int n = snprintf(buf, sizeof buf, HEAD, unit, res);
    snprintf(buf + n, sizeof buf - (size_t)n, "%s</plant></scene>\n</rsml>\n", body);
    return write_file(path, buf);
}

static const char *tmp_dir = "";

static void expect_error(const char *what, const char *path, const char *needle)
{
    phc_shoot_traces *tr = NULL;
    phc_error err;
    memset(&err, 0, sizeof err);
    const int rc = phc_shoot_traces_read(path, &tr, &err);
    /* the message without the folder of the file */
    const char *dir = strncmp(err.message, tmp_dir, strlen(tmp_dir)) == 0 ? tmp_dir : PHC_SHARED_DATA "/rsml";
    const char *msg = strncmp(err.message, dir, strlen(dir)) == 0 ? err.message + strlen(dir) + 1 : err.message;
    printf("%s: rc %d: %s\n", what, rc, msg);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(tr == NULL);
    CHECK(strstr(err.message, needle) != NULL);
    phc_shoot_traces_free(tr);
}

int main(void)
{
    phc_error err;
    /* 1. CSV and RSML of the same traces */
    {
        phc_shoot_traces *a = NULL, *b = NULL;
        const int ra = phc_shoot_traces_read(PHC_SOURCE_DIR "/measurements/examples/climbing/traces.csv", &a, &err);
        if (ra) fprintf(stderr, "%s\n", err.message);
        const int rb = phc_shoot_traces_read(PHC_SOURCE_DIR "/measurements/examples/climbing/traces.rsml", &b, &err);
        if (rb) fprintf(stderr, "%s\n", err.message);
        CHECK(ra == 0 && rb == 0);
        if (!ra && !rb) {
            size_t topo = 0, diff_pts = 0;
            double worst = 0;
            for (size_t s = 0; s < a->n_shoots; ++s) {
                const long q = find(b, a->names[s]);
                if (q < 0) { ++topo; continue; }
                const size_t pa = a->parent[s], pb = b->parent[q];
                if ((pa == PHC_SHOOT_NONE) != (pb == PHC_SHOOT_NONE) ||
                    (pa != PHC_SHOOT_NONE && strcmp(a->names[pa], b->names[pb])) || a->order[s] != b->order[q])
                    ++topo;
                const size_t na = a->start[s + 1] - a->start[s], nb = b->start[q + 1] - b->start[q];
                if (na != nb) { ++diff_pts; continue; }
                for (size_t j = 0; j < na; ++j) {
                    const size_t ja = a->start[s] + j, jb = b->start[q] + j;
                    worst = fmax(worst, fabs(a->t[ja] - b->t[jb]));
                    for (int k = 0; k < 3; ++k) worst = fmax(worst, fabs(a->x[3 * ja + k] - b->x[3 * jb + k]));
                }
            }
            printf("csv vs rsml: %zu and %zu shoots, %zu and %zu points, t_end %g and %g s; shoots with another "
                   "parent or order: %zu, with another point count: %zu, max |difference| of t, x, y, z: %g\n",
                   a->n_shoots, b->n_shoots, a->n_points, b->n_points, a->t_end, b->t_end, topo, diff_pts, worst);
            CHECK(a->n_shoots == b->n_shoots && a->n_points == b->n_points && a->t_end == b->t_end);
            CHECK(a->n_shoots > 5);
            CHECK(topo == 0 && diff_pts == 0 && worst == 0);
            /* the traced segments at several times: same multiset of (order, length) */
            const double times[4] = {30, 60, 90, 120};
            size_t seg_off = 0;
            for (int k = 0; k < 4; ++k) {
                phc_shoot_segment *sa = NULL, *sb = NULL;
                size_t na = 0, nb = 0;
                CHECK(phc_shoot_traces_segments(a, times[k], &sa, &na, &err) == 0);
                CHECK(phc_shoot_traces_segments(b, times[k], &sb, &nb, &err) == 0);
                double la = 0, lb = 0;
                size_t lat_a = 0, lat_b = 0;
                for (size_t i = 0; i < na; ++i) {
                    double d2 = 0;
                    for (int c = 0; c < 3; ++c) d2 += (sa[i].tip[c] - sa[i].base[c]) * (sa[i].tip[c] - sa[i].base[c]);
                    la += sqrt(d2) * (1 + sa[i].order);
                    lat_a += sa[i].lateral_start;
                }
                for (size_t i = 0; i < nb; ++i) {
                    double d2 = 0;
                    for (int c = 0; c < 3; ++c) d2 += (sb[i].tip[c] - sb[i].base[c]) * (sb[i].tip[c] - sb[i].base[c]);
                    lb += sqrt(d2) * (1 + sb[i].order);
                    lat_b += sb[i].lateral_start;
                }
                printf("  t = %g s: %zu and %zu segments, order-weighted length %.12g and %.12g m, lateral starts %zu "
                       "and %zu\n", times[k], na, nb, la, lb, lat_a, lat_b);
                seg_off += na != nb || fabs(la - lb) > 1e-12 * la || lat_a != lat_b;
                free(sa);
                free(sb);
            }
            CHECK(seg_off == 0);
        }
        phc_shoot_traces_free(a);
        phc_shoot_traces_free(b);
    }
    char dir[] = "/tmp/phc_st_rsml.XXXXXX";
    if (!mkdtemp(dir)) return 1;
    tmp_dir = dir;
    char path[256];
    /* 2. units: mm, 2 coordinate units per mm */
    {
        snprintf(path, sizeof path, "%s/mm.rsml", dir);
        write_rsml(path, "mm", "2",
                   "<root id=\"a\"><geometry><polyline><point x=\"0\" y=\"0\" z=\"0\"/><point x=\"10\" y=\"4\" "
                   "z=\"20\"/></polyline></geometry><functions><function name=\"time\" domain=\"polyline\">"
                   "<sample>0</sample><sample>5</sample></function></functions>\n"
                   "<root id=\"b\"><geometry><polyline><point x=\"10\" y=\"4\" z=\"20\"/><point x=\"30\" y=\"4\" "
                   "z=\"20\"/></polyline></geometry><functions><function name=\"time\" domain=\"polyline\">"
                   "<sample value=\"5\"/><sample value=\"9\"/></function></functions></root></root>\n");
        phc_shoot_traces *tr = NULL;
        const int rc = phc_shoot_traces_read(path, &tr, &err);
        if (rc) fprintf(stderr, "%s\n", err.message);
        CHECK(rc == 0);
        if (!rc) {
            printf("mm, resolution 2: %zu shoots, b's parent '%s' (order %u), a's tip (%g, %g, %g) m at %g s\n",
                   tr->n_shoots, tr->names[tr->parent[1]], tr->order[1], tr->x[3], tr->x[4], tr->x[5], tr->t[1]);
            CHECK(tr->n_shoots == 2 && tr->parent[1] == 0 && tr->order[1] == 1);
            CHECK(tr->x[3] == 0.005 && tr->x[4] == 0.002 && tr->x[5] == 0.01 && tr->t[1] == 5 && tr->t_end == 9);
        }
        phc_shoot_traces_free(tr);
    }
    /* 3. bad RSML */
    {
        snprintf(path, sizeof path, "%s/notime.rsml", dir);
        write_rsml(path, "m", "1",
                   "<root id=\"a\"><geometry><polyline><point x=\"0\" y=\"0\" z=\"0\"/><point x=\"0\" y=\"0\" "
                   "z=\"1\"/></polyline></geometry></root>\n");
        expect_error("no time", path, "notime.rsml:5: root 'a': no per-point function named 'time'");
        snprintf(path, sizeof path, "%s/back.rsml", dir);
        write_rsml(path, "m", "1",
                   "<root id=\"a\"><geometry><polyline><point x=\"0\" y=\"0\" z=\"0\"/><point x=\"0\" y=\"0\" "
                   "z=\"1\"/><point x=\"0\" y=\"0\" z=\"2\"/></polyline></geometry>\n<functions>\n"
                   "<function name=\"time\" domain=\"polyline\">\n<sample>0</sample>\n<sample>8</sample>\n"
                   "<sample>4</sample>\n</function></functions></root>\n");
        expect_error("backwards", path, "back.rsml:10: root 'a': time goes backwards");
        snprintf(path, sizeof path, "%s/few.rsml", dir);
        write_rsml(path, "m", "1",
                   "<root id=\"a\"><geometry><polyline><point x=\"0\" y=\"0\" z=\"0\"/><point x=\"0\" y=\"0\" "
                   "z=\"1\"/></polyline></geometry>\n<functions><function name=\"time\" domain=\"polyline\">"
                   "<sample>0</sample></function></functions></root>\n");
        expect_error("too few samples", path, "few.rsml:6: root 'a': time function has 1 samples");
        snprintf(path, sizeof path, "%s/pixel.rsml", dir);
        write_rsml(path, "pixel", "1",
                   "<root id=\"a\"><geometry><polyline><point x=\"0\" y=\"0\" z=\"0\"/><point x=\"0\" y=\"0\" "
                   "z=\"1\"/></polyline></geometry><functions><function name=\"time\" domain=\"polyline\">"
                   "<sample>0</sample><sample>1</sample></function></functions></root>\n");
        expect_error("pixel unit", path, "pixel.rsml: metadata <unit> 'pixel' is not a length");
        snprintf(path, sizeof path, "%s/dup.rsml", dir);
        write_rsml(path, "m", "1",
                   "<root id=\"a\"><geometry><polyline><point x=\"0\" y=\"0\" z=\"0\"/><point x=\"0\" y=\"0\" "
                   "z=\"1\"/></polyline></geometry><functions><function name=\"time\" domain=\"polyline\">"
                   "<sample>0</sample><sample>1</sample></function></functions></root>\n"
                   "<root id=\"a\"><geometry><polyline><point x=\"1\" y=\"0\" z=\"0\"/><point x=\"1\" y=\"0\" "
                   "z=\"1\"/></polyline></geometry><functions><function name=\"time\" domain=\"polyline\">"
                   "<sample>0</sample><sample>1</sample></function></functions></root>\n");
        expect_error("one id twice", path, "dup.rsml:6: root 'a': the id is used by the root at line 5 too");
        const char *names[] = {"notime", "back", "few", "pixel", "dup", "mm"};
        for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k) {
            snprintf(path, sizeof path, "%s/%s.rsml", dir, names[k]);
            remove(path);
        }
        rmdir(dir);
    }
    /* 4. real RSML files as they come */
    {
        const char *files[] = {"root_ramifie.rsml", "lupin_aero.rsml", "AR570_2012_11_19.rsml",
                               "AR570_2012_11_25.rsml"};
        /* root_ramifie (SmartRoot) has topology-only roots: the RSML reader
           refuses them before the time is looked for */
        const char *needles[] = {"has no <geometry><polyline>", "no per-point function named 'time'",
                                 "no per-point function named 'time'", "no per-point function named 'time'"};
        for (size_t k = 0; k < 4; ++k) {
            snprintf(path, sizeof path, "%s/rsml/%s", PHC_SHARED_DATA, files[k]);
            FILE *f = fopen(path, "r");
            if (!f) {
                printf("real %s: absent\n", files[k]);
                continue;
            }
            fclose(f);
            expect_error("real", path, needles[k]);
        }
    }
    return check_finish("test_shoot_traces_rsml");
}
