/* Real RSML files (../shared/data/rsml, Apache-2.0, from the RSML project):
 * two openalea Arabidopsis tracings (unit pixel, 3-D points with z = 0), a
 * SmartRoot lupin tracing with diameters (unit inch, resolution 300, 2-D)
 * and a SmartRoot topology-only file (no geometry at all).  Each is read,
 * checked, printed, written and read back.
 * Skips (77) when the shared data folder is absent. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "measurements/rsml.h"

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif

#define RSML_DIR PHC_SHARED_DATA "/rsml"

typedef struct summary {
    size_t plants, roots, primary, lateral, with_geometry, with_diameter, max_order, points;
    double length;
} summary;

static summary summarise(const phc_rsml *r)
{
    summary s;
    size_t i;
    memset(&s, 0, sizeof s);
    s.plants = r->n_plants;
    s.roots = r->n_roots;
    for (i = 0; i < r->n_roots; ++i) {
        const phc_rsml_root *root = &r->roots[i];
        const size_t order = phc_rsml_order(r, i);
        if (root->parent == PHC_RSML_NO_PARENT)
            ++s.primary;
        else
            ++s.lateral;
        if (root->n_points)
            ++s.with_geometry;
        if (root->diameter)
            ++s.with_diameter;
        if (order > s.max_order)
            s.max_order = order;
        s.points += root->n_points;
    }
    s.length = phc_rsml_total_length(r);
    return s;
}

/* Invariants of every document the reader returns. */
static void check_document(const char *name, const phc_rsml *r)
{
    size_t i, bad_parent = 0, bad_plant = 0, bad_order = 0, bad_diameter = 0, bad_points = 0;
    for (i = 0; i < r->n_roots; ++i) {
        const phc_rsml_root *root = &r->roots[i];
        size_t j;
        if (root->parent != PHC_RSML_NO_PARENT) {
            /* Every lateral's parent exists, comes earlier, on the same plant. */
            if (root->parent >= i)
                ++bad_parent;
            else if (r->roots[root->parent].plant != root->plant)
                ++bad_plant;
            else if (phc_rsml_order(r, i) != phc_rsml_order(r, root->parent) + 1)
                ++bad_order;
        }
        if (root->plant >= r->n_plants)
            ++bad_plant;
        for (j = 0; j < root->n_points; ++j) {
            const double *p = root->xyz + 3 * j;
            if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]) ||
                (r->dimension == 2 && p[2] != 0.0))
                ++bad_points;
            if (root->diameter && !(root->diameter[j] >= 0.0))
                ++bad_diameter;
        }
        if (root->source_line == 0)
            ++bad_points;
    }
    CHECK(bad_parent == 0);
    CHECK(bad_plant == 0);
    CHECK(bad_order == 0);
    CHECK(bad_points == 0);
    CHECK(bad_diameter == 0);
    if (bad_parent || bad_plant || bad_order || bad_points || bad_diameter)
        fprintf(stderr, "%s: %zu bad parents, %zu bad plants, %zu bad orders, %zu bad points, "
                        "%zu bad diameters\n",
                name, bad_parent, bad_plant, bad_order, bad_points, bad_diameter);
}

/* What we know of each file from reading it by eye (grep of the XML). */
typedef struct expected {
    const char *name;
    size_t roots;       /* <root elements */
    size_t points;      /* <point elements inside polylines */
    int dimension;
    const char *unit;
    int topology_only;  /* no <geometry> at all */
    size_t diameters;   /* roots with a diameter function */
} expected;

static const expected known[] = {
    {"AR570_2012_11_19.rsml", 25, 761, 3, "pixel", 0, 0},
    {"AR570_2012_11_25.rsml", 114, 2884, 3, "pixel", 0, 0},
    {"lupin_aero.rsml", 57, 1143, 2, "inch", 0, 57},
    {"root_ramifie.rsml", 22, 0, 2, "inch", 1, 0},
};

static const expected *lookup(const char *name)
{
    size_t i;
    for (i = 0; i < sizeof known / sizeof known[0]; ++i)
        if (!strcmp(known[i].name, name))
            return &known[i];
    return NULL;
}

static void test_file(const char *dir, const char *name, int *n_done)
{
    char path[1024], out_path[1024];
    phc_error err;
    phc_rsml *r = NULL, *back = NULL;
    phc_rsml_read_options lenient = phc_rsml_read_options_default();
    const expected *want = lookup(name);
    summary s, t;
    int rc;
    size_t i, length_mismatch = 0;

    lenient.allow_no_geometry = 1;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    rc = phc_rsml_read(path, &r, &err);
    if (want && want->topology_only) {
        /* Strict reading names the first root without geometry. */
        CHECK(rc == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "has no <geometry><polyline>");
        printf("%s: strict read: %s\n", name, err.message);
        rc = phc_rsml_read_with(path, &lenient, &r, &err);
    }
    CHECK(rc == 0);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    ++*n_done;
    check_document(name, r);
    s = summarise(r);
    printf("%s: %zu plant%s, %zu roots (%zu primary, %zu lateral), max order %zu, "
           "%zu with geometry (%zu points), %zu with diameters, %d-D, unit '%s', "
           "resolution %g, software '%s'\n",
           name, s.plants, s.plants == 1 ? "" : "s", s.roots, s.primary, s.lateral, s.max_order,
           s.with_geometry, s.points, s.with_diameter, r->dimension, r->unit, r->resolution,
           r->software ? r->software : "(none)");
    printf("%s: total length %.6g (coordinate units) = %.6g %s (coordinates / resolution)\n",
           name, s.length, phc_rsml_length_in_unit(r, s.length), r->unit);
    CHECK(s.primary + s.lateral == s.roots);
    CHECK(s.primary >= s.plants || s.roots == 0);
    if (want) {
        CHECK(s.roots == want->roots);
        CHECK(r->dimension == want->dimension);
        CHECK(!strcmp(r->unit, want->unit));
        CHECK(s.with_diameter == want->diameters);
        if (want->topology_only) {
            CHECK(s.with_geometry == 0);
            CHECK(s.length == 0.0);
        } else {
            CHECK(s.with_geometry == s.roots);
            CHECK(s.length > 0.0);
        }
        if (want->points)
            CHECK(s.points == want->points);
    }

    /* SmartRoot stores each root's length (cm) in <properties><length>;
     * the lupin's first root is 26.557196 cm.  Coordinates are pixels at
     * <resolution> 300 per inch, so the polyline gives it back. */
    if (!strcmp(name, "lupin_aero.rsml") && r->n_roots) {
        const double cm = phc_rsml_length_in_unit(r, phc_rsml_root_length(&r->roots[0])) * 2.54;
        printf("%s: root '%s' polyline %.6g cm, SmartRoot's <length> property 26.557196 cm\n",
               name, r->roots[0].label ? r->roots[0].label : "?", cm);
        CHECK_NEAR(cm, 26.557196, 0, 0.02);
    }

    /* Write, read back: same counts, same lengths. */
    snprintf(out_path, sizeof out_path, "%s", "/tmp/phc_rsml_real_XXXXXX");
    {
        int fd = mkstemp(out_path);
        CHECK(fd >= 0);
        if (fd < 0)
            goto done;
        close(fd);
    }
    rc = phc_rsml_write(r, out_path, &err);
    CHECK(rc == 0);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        goto done;
    }
    rc = phc_rsml_read_with(out_path, want && want->topology_only ? &lenient : NULL, &back, &err);
    CHECK(rc == 0);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        goto done;
    }
    check_document(name, back);
    t = summarise(back);
    CHECK(t.plants == s.plants);
    CHECK(t.roots == s.roots);
    CHECK(t.primary == s.primary);
    CHECK(t.lateral == s.lateral);
    CHECK(t.max_order == s.max_order);
    CHECK(t.points == s.points);
    CHECK(t.with_diameter == s.with_diameter);
    CHECK(back->dimension == r->dimension);
    CHECK(!strcmp(back->unit, r->unit));
    CHECK(back->resolution == r->resolution);
    CHECK_NEAR(t.length, s.length, 0, 1e-12);
    for (i = 0; i < r->n_roots && i < back->n_roots; ++i) {
        const double a = phc_rsml_root_length(&r->roots[i]);
        const double b = phc_rsml_root_length(&back->roots[i]);
        if (fabs(a - b) > 1e-12 * fabs(a) || back->roots[i].parent != r->roots[i].parent ||
            back->roots[i].n_points != r->roots[i].n_points)
            ++length_mismatch;
    }
    CHECK(length_mismatch == 0);
    printf("%s: written and read back: %zu roots, total length %.6g\n", name, t.roots, t.length);
done:
    remove(out_path);
    phc_rsml_free(back);
    phc_rsml_free(r);
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

int main(void)
{
    DIR *d = opendir(RSML_DIR);
    struct dirent *e;
    char *names[256];
    size_t n = 0, i;
    int done = 0;
    if (!d) {
        printf("test_rsml_real: %s is absent: skipped\n", RSML_DIR);
        return 77;
    }
    while ((e = readdir(d)) && n < 256) {
        const size_t len = strlen(e->d_name);
        if (len > 5 && !strcmp(e->d_name + len - 5, ".rsml"))
            names[n++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(names, n, sizeof *names, by_name);
    for (i = 0; i < n; ++i) {
        if (names[i])
            test_file(RSML_DIR, names[i], &done);
        free(names[i]);
    }
    CHECK(n >= 4);
    CHECK(done == (int)n);
    return check_finish("test_rsml_real");
}
