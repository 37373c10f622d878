/* Unit tests for measurements/rsml.c: building, writing and reading RSML,
 * lengths and orders, and the messages of malformed files. */
#include <fcntl.h>
#include <glob.h>
#include <locale.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "measurements/rsml.h"

/* Every test file lives in one mkdtemp() directory, removed at the end. */
static char tmp_dir[] = "/tmp/phc_test_rsml_XXXXXX";
static char tmp_files[64][256];
static int n_tmp_files = 0;

static const char *tmp_path(const char *name)
{
    char *path;
    if (n_tmp_files >= 64)
        return NULL;
    path = tmp_files[n_tmp_files++];
    snprintf(path, sizeof tmp_files[0], "%s/%s", tmp_dir, name);
    return path;
}

static const char *write_file(const char *name, const char *text)
{
    const char *path = tmp_path(name);
    FILE *f;
    if (!path || !(f = fopen(path, "wb")))
        return NULL;
    fputs(text, f);
    fclose(f);
    return path;
}

static void remove_files(void)
{
    int i;
    for (i = 0; i < n_tmp_files; ++i) {
        char tmp[sizeof tmp_files[0] + 8];
        remove(tmp_files[i]);
        snprintf(tmp, sizeof tmp, "%.255s.tmp", tmp_files[i]);
        remove(tmp);
    }
    rmdir(tmp_dir);
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* 1 when a writer left a temporary file for path (PATH.tmp-XXXXXX). */
static int temp_left(const char *path)
{
    char pattern[600];
    glob_t gl;
    int found;
    snprintf(pattern, sizeof pattern, "%s.tmp*", path);
    found = glob(pattern, 0, NULL, &gl) == 0 && gl.gl_pathc > 0;
    globfree(&gl);
    return found;
}

static int same_bits(const double *a, const double *b, size_t n)
{
    if (!a || !b)
        return a == b;
    return memcmp(a, b, n * sizeof *a) == 0;
}

static int same_string(const char *a, const char *b)
{
    if (!a || !b)
        return a == b;
    return strcmp(a, b) == 0;
}

/* Two documents equal field by field, coordinates to the bit. */
static void check_equal(const phc_rsml *a, const phc_rsml *b)
{
    size_t i;
    CHECK(same_string(a->unit, b->unit));
    CHECK(memcmp(&a->resolution, &b->resolution, sizeof a->resolution) == 0);
    CHECK(a->dimension == b->dimension);
    CHECK(a->n_plants == b->n_plants);
    for (i = 0; i < a->n_plants && i < b->n_plants; ++i)
        CHECK(same_string(a->plant_ids[i], b->plant_ids[i]));
    CHECK(a->n_roots == b->n_roots);
    for (i = 0; i < a->n_roots && i < b->n_roots; ++i) {
        const phc_rsml_root *x = &a->roots[i], *y = &b->roots[i];
        CHECK(same_string(x->id, y->id));
        CHECK(same_string(x->label, y->label));
        CHECK(x->plant == y->plant);
        CHECK(x->parent == y->parent);
        CHECK(x->n_points == y->n_points);
        if (x->n_points == y->n_points) {
            CHECK(same_bits(x->xyz, y->xyz, 3 * x->n_points));
            CHECK((x->diameter == NULL) == (y->diameter == NULL));
            if (x->diameter && y->diameter)
                CHECK(same_bits(x->diameter, y->diameter, x->n_points));
        }
    }
}

/* Two plants, laterals to order 3, diameters on some roots, awkward
 * numbers, ids that need escaping; built in document (pre-)order. */
static phc_rsml *build_document(void)
{
    phc_error err;
    phc_rsml *r = phc_rsml_new("cm", 3);
    size_t pa, pb, r0, r1, r2, r3, r4, k;
    const double xyz0[] = {0.1, 0.2, 0.30000000000000004, 1.0 / 3.0, -2.0 / 3.0, 1e-310,
                           6.02214076e23, -0.0, 4.9e-324, 1.7976931348623157e308, 12.5, -7};
    const double d0[] = {0.5, 1.0 / 7.0, 0.0, 2.2250738585072014e-308};
    const double xyz1[] = {1, 1, 1, 2, 2, 2, 3.14159265358979, 2.718281828459045, 1.4142135623730951};
    const double xyz2[] = {5, 5, 5};
    const double d2[] = {0.125};
    const double xyz3[] = {0, 0, 0, 3, 4, 0};
    const double xyz4[] = {-1, -2, -3, -1.5, -2.5, -3.5};
    const double d4[] = {1e-3, 9.999999999999999e-4};
    if (!r)
        return NULL;
    r->resolution = 1.0 / 3.0;
    CHECK(phc_rsml_add_plant(r, "plant A", &pa, &err) == 0);
    CHECK(phc_rsml_add_root(r, pa, PHC_RSML_NO_PARENT, "a&<b>\"'", 4, xyz0, d0, &r0, &err) == 0);
    CHECK(phc_rsml_add_root(r, pa, r0, NULL, 3, xyz1, NULL, &r1, &err) == 0);
    CHECK(phc_rsml_add_root(r, pa, r1, "tertiary", 1, xyz2, d2, &r2, &err) == 0);
    CHECK(phc_rsml_add_root(r, pa, PHC_RSML_NO_PARENT, "second primary", 2, xyz3, NULL, &r3,
                            &err) == 0);
    CHECK(phc_rsml_add_plant(r, "B", &pb, &err) == 0);
    CHECK(phc_rsml_add_root(r, pb, PHC_RSML_NO_PARENT, "b0", 2, xyz4, d4, &r4, &err) == 0);
    CHECK(phc_rsml_add_root(r, pb, r4, "b1", 2, xyz3, NULL, &k, &err) == 0);
    CHECK(r0 == 0 && r1 == 1 && r2 == 2 && r3 == 3 && r4 == 4 && k == 5);
    CHECK(r->n_roots == 6 && r->n_plants == 2);
    /* A label with non-ASCII UTF-8. */
    r->roots[r1].label = malloc(16);
    if (r->roots[r1].label)
        strcpy(r->roots[r1].label, "racine \xc3\xa9");
    return r;
}

static void test_roundtrip(void)
{
    phc_error err;
    phc_rsml *r = build_document(), *back = NULL;
    const char *path = tmp_path("two_plants.rsml");
    int rc;
    CHECK(r != NULL);
    if (!r)
        return;
    rc = phc_rsml_write(r, path, &err);
    CHECK(rc == 0);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    CHECK(!temp_left(path));
    rc = phc_rsml_read(path, &back, &err);
    CHECK(rc == 0);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    if (back) {
        /* The writer names an id-less root "r<index>". */
        CHECK(same_string(back->roots[1].id, "r1"));
        free(r->roots[1].id);
        r->roots[1].id = malloc(3);
        if (r->roots[1].id)
            strcpy(r->roots[1].id, "r1");
        check_equal(r, back);
        CHECK(same_string(back->software, "phytocal"));
        CHECK(back->roots[0].source_line > 0);
        CHECK(back->roots[1].source_line > back->roots[0].source_line);
        CHECK(phc_rsml_order(back, 2) == 3);
        /* Writing what was read gives the same document again. */
        rc = phc_rsml_write(back, path, &err);
        CHECK(rc == 0);
        phc_rsml_free(r);
        r = NULL;
        CHECK(phc_rsml_read(path, &r, &err) == 0);
        if (r)
            check_equal(back, r);
    }
    phc_rsml_free(back);
    phc_rsml_free(r);
}

/* Laterals added after other roots are written nested under their parent
 * and read back in document order (parents before children). */
static void test_reordered(void)
{
    phc_error err;
    phc_rsml *r = phc_rsml_new(NULL, 2), *back = NULL;
    const char *path = tmp_path("reordered.rsml");
    const double a[] = {0, 0, 0, 0, 10, 0}, b[] = {1, 1, 0, 2, 2, 0}, c[] = {7, 7, 0};
    size_t i;
    CHECK(r != NULL);
    if (!r)
        return;
    CHECK(phc_rsml_add_plant(r, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, PHC_RSML_NO_PARENT, "p1", 2, a, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, PHC_RSML_NO_PARENT, "p2", 2, b, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, 0, "lat of p1", 1, c, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_write(r, path, &err) == 0);
    CHECK(phc_rsml_read(path, &back, &err) == 0);
    if (back) {
        const char *want[] = {"p1", "lat of p1", "p2"};
        CHECK(back->n_roots == 3);
        CHECK(same_string(back->unit, "m")); /* the default unit */
        CHECK(back->dimension == 2);
        CHECK(same_string(back->plant_ids[0], "p0"));
        for (i = 0; i < 3 && i < back->n_roots; ++i)
            CHECK(same_string(back->roots[i].id, want[i]));
        if (back->n_roots == 3) {
            CHECK(back->roots[1].parent == 0);
            CHECK(back->roots[2].parent == PHC_RSML_NO_PARENT);
            CHECK(same_bits(back->roots[1].xyz, c, 3));
            CHECK(same_bits(back->roots[2].xyz, b, 6));
        }
    }
    phc_rsml_free(back);
    phc_rsml_free(r);
}

static void test_lengths_and_order(void)
{
    phc_error err;
    phc_rsml *r = phc_rsml_new("mm", 3);
    const double seg345[] = {0, 0, 0, 3, 4, 0};
    const double path3d[] = {0, 0, 0, 1, 2, 2, 1, 2, 6};
    const double one[] = {9, 9, 9};
    size_t i;
    CHECK(r != NULL);
    if (!r)
        return;
    CHECK(phc_rsml_add_plant(r, "p", NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, PHC_RSML_NO_PARENT, "a", 2, seg345, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, 0, "b", 3, path3d, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, 1, "c", 1, one, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, 2, "d", 2, seg345, NULL, NULL, &err) == 0);
    CHECK(phc_rsml_root_length(&r->roots[0]) == 5.0);
    CHECK(phc_rsml_root_length(&r->roots[1]) == 7.0);
    CHECK(phc_rsml_root_length(&r->roots[2]) == 0.0);
    CHECK(phc_rsml_root_length(NULL) == 0.0);
    CHECK(phc_rsml_total_length(r) == 17.0);
    CHECK(phc_rsml_total_length(NULL) == 0.0);
    r->resolution = 4.0;
    CHECK(phc_rsml_length_in_unit(r, 17.0) == 4.25);
    for (i = 0; i < 4; ++i)
        CHECK(phc_rsml_order(r, i) == i + 1);
    CHECK(phc_rsml_order(r, 4) == 0);
    CHECK(phc_rsml_order(NULL, 0) == 0);
    phc_rsml_free(r);
}

static void test_bad_arguments(void)
{
    phc_error err;
    phc_rsml *r2 = phc_rsml_new("cm", 2);
    const double p[] = {0, 0, 0, 1, 1, 0}, pz[] = {0, 0, 1};
    const double bad_d[] = {1, -0.5}, nan_p[] = {0, NAN, 0};
    size_t idx = 99;
    CHECK(phc_rsml_new("cm", 1) == NULL);
    CHECK(phc_rsml_new("cm", 4) == NULL);
    phc_rsml_free(NULL);
    CHECK(r2 != NULL);
    if (!r2)
        return;
    CHECK(phc_rsml_add_plant(NULL, "x", NULL, &err) == PHC_ERR_INVALID);
    /* No plant yet. */
    CHECK(phc_rsml_add_root(r2, 0, PHC_RSML_NO_PARENT, "x", 2, p, NULL, &idx, &err) ==
          PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "plant index 0 out of range");
    CHECK(idx == 99);
    CHECK(phc_rsml_add_plant(r2, "p0", NULL, &err) == 0);
    CHECK(phc_rsml_add_plant(r2, "p1", NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r2, 0, PHC_RSML_NO_PARENT, "x", 2, p, NULL, &idx, &err) == 0);
    CHECK(idx == 0);
    CHECK(phc_rsml_add_root(r2, 2, PHC_RSML_NO_PARENT, "x", 2, p, NULL, NULL, &err) ==
          PHC_ERR_INVALID);
    /* Parent out of range, and a parent that is not earlier (itself). */
    CHECK(phc_rsml_add_root(r2, 0, 5, "x", 2, p, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "parent index 5");
    CHECK(phc_rsml_add_root(r2, 0, 1, "x", 2, p, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "not an earlier root");
    /* Parent on another plant. */
    CHECK(phc_rsml_add_root(r2, 1, 0, "x", 2, p, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "belongs to plant 0");
    CHECK(phc_rsml_add_root(r2, 0, 0, "x", 0, p, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "at least 1 point");
    CHECK(phc_rsml_add_root(r2, 0, 0, "x", 1, NULL, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK(phc_rsml_add_root(r2, 0, 0, "x", 1, pz, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "2-D document");
    CHECK(phc_rsml_add_root(r2, 0, 0, "x", 1, nan_p, NULL, NULL, &err) == PHC_ERR_INVALID);
    CHECK(phc_rsml_add_root(r2, 0, 0, "x", 2, p, bad_d, NULL, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "diameter 1");
    CHECK(r2->n_roots == 1);

    /* Writing an inconsistent document fails before touching the file. */
    {
        const char *path = write_file("keep.rsml", "previous content\n");
        char buf[64] = "";
        FILE *f;
        r2->roots[0].parent = 0; /* its own parent */
        CHECK(phc_rsml_write(r2, path, &err) == PHC_ERR_INVALID);
        r2->roots[0].parent = PHC_RSML_NO_PARENT;
        f = path ? fopen(path, "rb") : NULL;
        if (f) {
            CHECK(fgets(buf, sizeof buf, f) != NULL);
            fclose(f);
        }
        CHECK(!strcmp(buf, "previous content\n"));
        /* A directory that does not exist: an I/O error, nothing left. */
        CHECK(phc_rsml_write(r2, "/nonexistent_dir_phc/x.rsml", &err) == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "/nonexistent_dir_phc/x.rsml: cannot open for writing");
    }
    phc_rsml_free(r2);
}

/* Reads text written to NAME and expects PHC_ERR_INPUT with a message that
 * starts with the file's path and ":LINE:" and contains `needle`. */
static void expect_input_error(const char *name, const char *text, int line, const char *needle,
                               const phc_rsml_read_options *options)
{
    phc_error err;
    phc_rsml *r = (phc_rsml *)&err; /* must be reset to NULL */
    const char *path = write_file(name, text);
    char where[320];
    int rc;
    CHECK(path != NULL);
    if (!path)
        return;
    rc = phc_rsml_read_with(path, options, &r, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(r == NULL);
    snprintf(where, sizeof where, "%s:%d: ", path, line);
    CHECK(!strncmp(err.message, where, strlen(where)));
    CHECK_STR_CONTAINS(err.message, needle);
    CHECK(strchr(err.message, '\n') == NULL); /* one line */
    if (rc != PHC_ERR_INPUT || strncmp(err.message, where, strlen(where)) ||
        !strstr(err.message, needle))
        fprintf(stderr, "  %s: got '%s'\n", name, err.message);
}

#define HEAD "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<rsml>\n"  /* lines 1-2 */
#define META "<metadata><version>1</version><unit>cm</unit></metadata>\n" /* line 3 */

static void test_malformed(void)
{
    phc_rsml_read_options lenient = phc_rsml_read_options_default();
    int saved_stderr = dup(2), quiet = -1;
    const char *stderr_path = tmp_path("stderr.txt");
    struct stat st;
    lenient.allow_no_geometry = 1;

    /* libxml2 must not print: capture fd 2 while reading bad files. */
    fflush(stderr);
    if (stderr_path)
        quiet = open(stderr_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (quiet >= 0 && saved_stderr >= 0)
        dup2(quiet, 2);

    expect_input_error("truncated.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"a\">\n"
                       "<geometry><polyline><point x=\"1\" y=\"2\"/>\n"
                       "<point x=\"1\" y=",
                       6, "truncated.rsml:6: ", NULL);
    expect_input_error("unclosed.rsml",
                       HEAD META
                       "<scene><plant id=\"1\">\n"
                       "<root id=\"a\"><geometry><polyline><point x=\"1\" y=\"2\"/></polyline>"
                       "</geometry></root>\n",
                       6, "Premature end of data", NULL);
    expect_input_error("not_rsml.rsml",
                       "<?xml version=\"1.0\"?>\n\n<svg><rsml/></svg>\n", 3,
                       "the document element is <svg>, expected <rsml>", NULL);
    expect_input_error("no_polyline.rsml",
                       HEAD META
                       "<scene><plant id=\"1\">\n"
                       "<root id=\"lonely\" label=\"x\">\n"
                       "</root></plant></scene></rsml>\n",
                       5, "root 'lonely' has no <geometry><polyline>", NULL);
    expect_input_error("geometry_no_polyline.rsml",
                       HEAD META
                       "<scene><plant id=\"1\">\n"
                       "<root id=\"g\">\n"
                       "<geometry/>\n"
                       "</root></plant></scene></rsml>\n",
                       6, "root 'g': <geometry> has no <polyline>", &lenient);
    expect_input_error("no_points.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"e\"><geometry>\n"
                       "<polyline>\n"
                       "</polyline></geometry></root></plant></scene></rsml>\n",
                       5, "root 'e': <polyline> has no <point>", NULL);
    expect_input_error("x_abc.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"r7\"><geometry><polyline>\n"
                       "<point x=\"0\" y=\"0\"/>\n"
                       "<point x=\"1\" y=\"1\"/>\n"
                       "<point x=\"abc\" y=\"2\"/>\n"
                       "</polyline></geometry></root></plant></scene></rsml>\n",
                       7, "point 3 of root 'r7': attribute 'x' is not a finite number: 'abc'",
                       NULL);
    expect_input_error("y_inf.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"r\"><geometry><polyline>\n"
                       "<point>\n<x>1</x>\n<y>inf</y>\n</point>\n"
                       "</polyline></geometry></root></plant></scene></rsml>\n",
                       7, "element 'y' is not a finite number: 'inf'", NULL);
    expect_input_error("no_y.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"r\"><geometry><polyline>\n"
                       "<point x=\"1\"/>\n"
                       "</polyline></geometry></root></plant></scene></rsml>\n",
                       5, "has no 'y'", NULL);
    expect_input_error("mixed_dimension.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"r\"><geometry><polyline>\n"
                       "<point x=\"1\" y=\"1\" z=\"1\"/>\n"
                       "<point x=\"1\" y=\"2\"/>\n"
                       "</polyline></geometry></root></plant></scene></rsml>\n",
                       6, "2-D and 3-D points mixed", NULL);
    expect_input_error("diameter_count.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"d\"><geometry><polyline>\n"
                       "<point x=\"0\" y=\"0\"/><point x=\"0\" y=\"1\"/><point x=\"0\" y=\"2\"/>\n"
                       "</polyline></geometry><functions>\n"
                       "<function name=\"diameter\" domain=\"polyline\">\n"
                       "<sample>1</sample><sample>2</sample>\n"
                       "</function></functions></root></plant></scene></rsml>\n",
                       7, "diameter function has 2 samples, expected one per polyline point (3)",
                       NULL);
    expect_input_error("diameter_negative.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"d\"><geometry><polyline>\n"
                       "<point x=\"0\" y=\"0\"/><point x=\"0\" y=\"1\"/>\n"
                       "</polyline></geometry><functions>\n"
                       "<function name=\"diameter\" domain=\"polyline\">\n"
                       "<sample>1</sample>\n"
                       "<sample value=\"-0.5\"/>\n"
                       "</function></functions></root></plant></scene></rsml>\n",
                       9, "diameter sample 2: expected a finite number >= 0, found '-0.5'", NULL);
    expect_input_error("diameter_domain.rsml",
                       HEAD META
                       "<scene><plant id=\"1\"><root id=\"d\"><geometry><polyline>\n"
                       "<point x=\"0\" y=\"0\"/>\n"
                       "</polyline></geometry><functions>\n"
                       "<function name=\"diameter\" domain=\"length\">\n"
                       "<sample>1</sample>\n"
                       "</function></functions></root></plant></scene></rsml>\n",
                       7, "domain 'length'", NULL);
    expect_input_error("no_unit.rsml",
                       HEAD
                       "<metadata>\n"
                       "<version>1</version><resolution>1</resolution>\n"
                       "</metadata>\n"
                       "<scene/></rsml>\n",
                       3, "<metadata> has no <unit>", NULL);
    expect_input_error("no_metadata.rsml", HEAD "<scene/>\n</rsml>\n", 2, "has no <metadata>",
                       NULL);
    expect_input_error("bad_resolution.rsml",
                       HEAD "<metadata><unit>cm</unit>\n<resolution>0</resolution>\n"
                            "</metadata><scene/></rsml>\n",
                       4, "<resolution>: expected a finite number > 0, found '0'", NULL);
    expect_input_error("no_scene.rsml", HEAD META "</rsml>\n", 2, "has no <scene>", NULL);
    /* a fuzzing find: libxml2's message for a byte that is not UTF-8 has a
     * second line ("Bytes: 0x8A 0x65 ..."); the message keeps the first */
    {
        static const char text[] = HEAD "<metadata><unit>cm</unit>\n<\x8a" "esolution>1</resolution>\n"
                                        "</metadata><scene/></rsml>\n";
        const char *path = write_file("not_utf8.rsml", text);
        phc_rsml *r = NULL;
        phc_error err;
        const char *tail = ":4: Input is not proper UTF-8, indicate encoding !";
        CHECK(path && phc_rsml_read(path, &r, &err) == PHC_ERR_INPUT && r == NULL);
        CHECK(path && !strncmp(err.message, path, strlen(path)) &&
              !strcmp(err.message + strlen(path), tail));
    }

    fflush(stderr);
    if (quiet >= 0 && saved_stderr >= 0) {
        dup2(saved_stderr, 2);
        close(quiet);
    }
    if (saved_stderr >= 0)
        close(saved_stderr);
    CHECK(stderr_path && stat(stderr_path, &st) == 0 && st.st_size == 0);
    if (stderr_path && stat(stderr_path, &st) == 0 && st.st_size != 0)
        fprintf(stderr, "libxml2 printed %lld bytes while reading bad files\n",
                (long long)st.st_size);
}

/* Tolerated variants: namespace prefixes, ID attributes, <point><x>...,
 * <sample value=...>, topology-only roots with the lenient option. */
static void test_variants(void)
{
    phc_error err;
    phc_rsml *r = NULL, *back = NULL;
    phc_rsml_read_options lenient = phc_rsml_read_options_default();
    const char *path = write_file(
        "variants.rsml",
        "<?xml version='1.0'?>\n"
        "<r:rsml xmlns:r='urn:example:rsml' xmlns:po='urn:po'>\n"
        "<r:metadata><r:unit> mm </r:unit><r:resolution>2.5</r:resolution>"
        "<r:software>smartroot</r:software></r:metadata>\n"
        "<r:scene><r:plant>\n"
        "<r:root ID='big' label='primary' po:accession='PO:0009005'>\n"
        "<r:geometry><r:polyline>\n"
        "<r:point><r:x>0</r:x><r:y> 0 </r:y><r:z>0</r:z></r:point>\n"
        "<r:point x='0' y='3' z='4'/>\n"
        "</r:polyline></r:geometry>\n"
        "<r:functions><r:function name='length'><r:sample>7</r:sample></r:function>\n"
        "<r:function name='diameter'><r:sample value='0.5'/><r:sample>0.25</r:sample>"
        "</r:function></r:functions>\n"
        "<r:root ID='topology only'/>\n"
        "</r:root></r:plant></r:scene></r:rsml>\n");
    lenient.allow_no_geometry = 1;
    CHECK(path != NULL);
    if (!path)
        return;
    /* Strict by default: the topology-only lateral (line 12) is an error. */
    CHECK(phc_rsml_read(path, &r, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "variants.rsml:12: root 'topology only' has no <geometry>");
    CHECK(phc_rsml_read_with(path, &lenient, &r, &err) == 0);
    if (!r) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(same_string(r->unit, "mm"));
    CHECK(r->resolution == 2.5);
    CHECK(same_string(r->software, "smartroot"));
    CHECK(r->dimension == 3);
    CHECK(r->n_plants == 1 && r->plant_ids[0] == NULL);
    CHECK(r->n_roots == 2);
    if (r->n_roots == 2) {
        CHECK(same_string(r->roots[0].id, "big"));
        CHECK(same_string(r->roots[0].label, "primary"));
        CHECK(r->roots[0].source_line == 5);
        CHECK(r->roots[0].n_points == 2);
        CHECK(phc_rsml_root_length(&r->roots[0]) == 5.0);
        CHECK(phc_rsml_length_in_unit(r, 5.0) == 2.0);
        CHECK(r->roots[0].diameter && r->roots[0].diameter[0] == 0.5 &&
              r->roots[0].diameter[1] == 0.25);
        CHECK(r->roots[1].n_points == 0 && r->roots[1].xyz == NULL);
        CHECK(r->roots[1].parent == 0);
        CHECK(phc_rsml_order(r, 1) == 2);
        /* The topology-only root survives a write and a lenient read. */
        path = tmp_path("variants_out.rsml");
        CHECK(phc_rsml_write(r, path, &err) == 0);
        CHECK(phc_rsml_read_with(path, &lenient, &back, &err) == 0);
        if (back) {
            CHECK(same_string(back->plant_ids[0], "p0"));
            free(back->plant_ids[0]);
            back->plant_ids[0] = NULL;
            check_equal(r, back);
        }
    }
    {
        phc_rsml *none = (phc_rsml *)&err;
        CHECK(phc_rsml_read(tmp_path("does_not_exist.rsml"), &none, &err) == PHC_ERR_IO);
        CHECK(none == NULL);
        CHECK_STR_CONTAINS(err.message, "does_not_exist.rsml: cannot open");
    }
    phc_rsml_free(back);
    phc_rsml_free(r);
}

/* Invalid UTF-8 in an id would make an unreadable file: refused. */
static void test_invalid_utf8(void)
{
    phc_error err;
    phc_rsml *r = phc_rsml_new("cm", 2);
    const double p[] = {0, 0, 0};
    const char *path = tmp_path("bad_utf8.rsml");
    CHECK(r != NULL);
    if (!r)
        return;
    CHECK(phc_rsml_add_plant(r, "p", NULL, &err) == 0);
    CHECK(phc_rsml_add_root(r, 0, PHC_RSML_NO_PARENT, "bad\xff\xfe", 1, p, NULL, NULL, &err) ==
          0);
    CHECK(phc_rsml_write(r, path, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "not valid UTF-8");
    CHECK(!file_exists(path));
    phc_rsml_free(r);
}

/* Numbers are written and read with a '.' whatever LC_NUMERIC says
 * (checked only where such a locale is installed). */
static void test_locale(void)
{
    static const char *const names[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", NULL};
    phc_error err;
    phc_rsml *r, *back = NULL;
    const char *path = tmp_path("locale.rsml");
    size_t i;
    for (i = 0; names[i]; ++i)
        if (setlocale(LC_NUMERIC, names[i]))
            break;
    if (!names[i]) {
        printf("test_rsml: no decimal-comma locale installed: locale test skipped\n");
        return;
    }
    r = build_document();
    CHECK(r != NULL);
    if (r && phc_rsml_write(r, path, &err) == 0 && phc_rsml_read(path, &back, &err) == 0) {
        free(r->roots[1].id);
        r->roots[1].id = NULL;
        free(back->roots[1].id);
        back->roots[1].id = NULL;
        check_equal(r, back);
    } else {
        CHECK(0);
    }
    phc_rsml_free(back);
    phc_rsml_free(r);
    setlocale(LC_NUMERIC, "C");
}

/* A document with no plant is written without undefined behaviour (issue 15:
 * UBSan found an offset applied to a null pointer) and reads back empty. */
static void test_empty_document(void)
{
    phc_error err;
    phc_rsml *r = phc_rsml_new(NULL, 3), *back = NULL;
    const char *path = tmp_path("empty.rsml");
    CHECK(r != NULL);
    if (!r)
        return;
    const int rc = phc_rsml_write(r, path, &err);
    CHECK(rc == 0);
    if (rc == 0 && phc_rsml_read(path, &back, &err) == 0) {
        CHECK(back->n_plants == 0 && back->n_roots == 0);
        phc_rsml_free(back);
    }
    phc_rsml_free(r);
    remove(path);
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_empty_document();
    test_roundtrip();
    test_reordered();
    test_lengths_and_order();
    test_bad_arguments();
    test_malformed();
    test_variants();
    test_invalid_utf8();
    test_locale();
    remove_files();
    return check_finish("test_rsml");
}
