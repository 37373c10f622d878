/* Unit tests for measurements/plant_io*.c: the four formats, their error
 * messages (file, line, problem), the writers and round trips. */
#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "measurements/plant_io.h"
#include "model/plant_graph.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static char tmp_dir[] = "/tmp/phc_test_plant_io_XXXXXX";

static const char *tmp_path(const char *name)
{
    static char slots[8][512];
    static int next = 0;
    char *p = slots[next++ % 8];
    snprintf(p, sizeof slots[0], "%s/%s", tmp_dir, name);
    return p;
}

static const char *write_file(const char *name, const char *text)
{
    const char *path = tmp_path(name);
    FILE *f = fopen(path, "wb");
    if (!f)
        return path;
    fputs(text, f);
    fclose(f);
    return path;
}

static int exists(const char *path)
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

/* Reads a file that must be valid; NULL (and a failed check) otherwise. */
static phc_plant_graph *read_ok(const char *path, phc_plant_format format, double unit)
{
    phc_plant_graph *g = NULL;
    phc_error err;
    const int rc = phc_plant_io_read(path, format, unit, &g, &err);
    CHECK(rc == PHC_OK);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    return g;
}

/* Every segment's fields equal (exactly, or to rel for the coordinates). */
static void check_same_graph(const phc_plant_graph *a, const phc_plant_graph *b, int with_fixed,
                             double rel)
{
    size_t i, bad = 0;
    int k;
    CHECK(a && b);
    if (!a || !b)
        return;
    CHECK(a->n == b->n);
    if (a->n != b->n)
        return;
    CHECK(a->root == b->root);
    for (i = 0; i < a->n; ++i) {
        if (a->parent[i] != b->parent[i] || a->leaf[i] != b->leaf[i] ||
            (with_fixed && a->fixed[i] != b->fixed[i]) || a->radius[i] != b->radius[i] ||
            fabs(a->length[i] - b->length[i]) > rel * a->length[i] ||
            a->depth[i] != b->depth[i] || a->order[i] != b->order[i])
            ++bad;
        for (k = 0; k < 3; ++k)
            if (fabs(a->head[3 * i + k] - b->head[3 * i + k]) > rel ||
                a->tail[3 * i + k] != b->tail[3 * i + k])
                ++bad;
    }
    CHECK(bad == 0);
}

static void test_round_trips(void)
{
    phc_plant_graph *g = phc_plant_graph_random(3000, 11), *h = NULL;
    phc_error err;
    const char *native = tmp_path("random.csv"), *paper = tmp_path("random.txt");
    size_t i;
    CHECK(g != NULL);
    if (!g)
        return;
    for (i = 0; i < g->n; i += 7)
        g->fixed[i] = 1;

    CHECK(phc_plant_io_write_native(native, g, &err) == PHC_OK);
    CHECK(!temp_left(native));
    CHECK(phc_plant_io_read(native, PHC_PLANT_FORMAT_AUTO, 0, &h, &err) == PHC_OK);
    check_same_graph(g, h, 1, 0);
    if (h) {
        CHECK(memcmp(g->length, h->length, g->n * sizeof *g->length) == 0);
        CHECK(memcmp(g->source_id, h->source_id, g->n * sizeof *g->source_id) == 0);
        CHECK(phc_plant_graph_volume(h) == phc_plant_graph_volume(g));
    }
    phc_plant_graph_free(h);
    h = NULL;

    CHECK(phc_plant_io_write_paper(paper, g, &err) == PHC_OK);
    CHECK(!temp_left(paper));
    CHECK(phc_plant_io_read(paper, PHC_PLANT_FORMAT_AUTO, 0, &h, &err) == PHC_OK);
    if (!h)
        fprintf(stderr, "%s\n", err.message);
    /* the paper format recomputes lengths from the tails: equal to rounding */
    check_same_graph(g, h, 0, 1e-12);
    if (h)
        CHECK_NEAR(phc_plant_graph_volume(h), phc_plant_graph_volume(g), 0, 1e-12);
    phc_plant_graph_free(h);
    h = NULL;

    /* a second read of a paper file written from a read is identical */
    {
        phc_plant_graph *a = NULL, *b = NULL;
        const char *again = tmp_path("again.txt");
        CHECK(phc_plant_io_read(paper, PHC_PLANT_FORMAT_PAPER, 0, &a, &err) == PHC_OK);
        CHECK(a && phc_plant_io_write_paper(again, a, &err) == PHC_OK);
        CHECK(phc_plant_io_read(again, PHC_PLANT_FORMAT_PAPER, 0, &b, &err) == PHC_OK);
        check_same_graph(a, b, 0, 0);
        phc_plant_graph_free(a);
        phc_plant_graph_free(b);
    }

    /* the leaf chain survives both formats */
    {
        phc_plant_graph *c = phc_plant_graph_leaf_chain(30e-4, 6, 1e-4), *d = NULL;
        CHECK(c && phc_plant_io_write_native(native, c, &err) == PHC_OK);
        CHECK(phc_plant_io_read(native, PHC_PLANT_FORMAT_NATIVE, 0, &d, &err) == PHC_OK);
        check_same_graph(c, d, 1, 0);
        phc_plant_graph_free(d);
        phc_plant_graph_free(c);
    }

    /* the paper writer refuses a plant whose root is not nearest the origin */
    for (i = 0; i < 3 * g->n; ++i) {
        g->head[i] -= 0.05 * (i % 3 == 2);
        g->tail[i] -= 0.05 * (i % 3 == 2);
    }
    CHECK(phc_plant_io_write_paper(tmp_path("refused.txt"), g, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "refused.txt: cannot write in the paper format");
    CHECK_STR_CONTAINS(err.message, "nearer the origin than the root's");
    CHECK(!exists(tmp_path("refused.txt")) && !temp_left(tmp_path("refused.txt")));

    /* a writer that cannot write leaves nothing behind */
    CHECK(phc_plant_io_write_native(tmp_path("no/such/dir.csv"), g, &err) == PHC_ERR_IO);
    CHECK_STR_CONTAINS(err.message, "no/such/dir.csv: cannot open for writing");
    CHECK(phc_plant_io_write_native(NULL, g, &err) == PHC_ERR_INVALID);
    phc_plant_graph_free(g);
}

static void test_paper_reading(void)
{
    /* The root is the tail nearest the origin even when it is not vertex 0;
     * heads are parents' tails; lengths |tail - head|; unit scales all. */
    const char *path = write_file("p.txt",
                                  "verts 3\r\n"
                                  "0,0,0,0.05,0.002,1\r\n"
                                  "1,0,0,0.03,0.003,0\r\n"
                                  "2,0.01,0,0.03,0.001,1\r\n"
                                  "edges 2\r\n"
                                  "0,1\r\n"
                                  "2,1\r\n");
    phc_plant_graph *g = NULL;
    phc_error err;
    CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_AUTO, 0, &g, &err) == PHC_OK);
    if (g) {
        CHECK(g->root == 1);
        CHECK(g->parent[0] == 1 && g->parent[2] == 1);
        CHECK(g->head[3] == 0 && g->head[4] == 0 && g->head[5] == 0);
        CHECK(g->head[2] == 0.03 && g->head[8] == 0.03);
        CHECK_NEAR(g->length[1], 0.03, 0, 1e-15);
        CHECK_NEAR(g->length[0], 0.02, 0, 1e-12);
        CHECK_NEAR(g->length[2], 0.01, 0, 1e-12);
        CHECK(g->leaf[0] == 1 && g->leaf[1] == 0 && g->leaf[2] == 1);
        CHECK(g->radius[1] == 0.003);
    }
    phc_plant_graph_free(g);
    g = NULL;
    /* the authors' code works in cm: unit_to_m = 100 reproduces it */
    CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_PAPER, 100, &g, &err) == PHC_OK);
    if (g) {
        CHECK_NEAR(g->length[1], 3.0, 0, 1e-14);
        CHECK_NEAR(g->radius[1], 0.3, 0, 1e-14);
    }
    phc_plant_graph_free(g);
    g = (phc_plant_graph *)1;
    CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_PAPER, -1, &g, &err) == PHC_ERR_INVALID);
    CHECK(g == NULL);
    CHECK_STR_CONTAINS(err.message, "unit_to_m must be positive");
    /* a tie for nearest: the first in file order, as the authors' '<' does */
    path = write_file("tie.txt",
                      "verts 2\n1,0,0,0.01,0.001,0\n0,0,0.01,0,0.001,0\nedges 1\n0,1\n");
    CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_AUTO, 0, &g, &err) == PHC_OK);
    if (g)
        CHECK(g->root == 1 && g->source_id[1] == 1);
    phc_plant_graph_free(g);
    /* a single segment */
    path = write_file("one.txt", "verts 1\n0,0,0,0.01,0.001,0\nedges 0\n");
    CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_AUTO, 0, &g, &err) == PHC_OK);
    CHECK(g && g->n == 1 && g->root == 0);
    phc_plant_graph_free(g);
}

static void test_treeqsm_reading(void)
{
    const char *path = write_file("tree.txt",
                                  "0.1\t1.0\t0\t0\t0\t0\t0\t1\t0\t2\t0\t0.1\t1\t0\t1\r\n"
                                  "0.05\t0.5\t0\t0\t1\t1\t0\t0\t1\t3\t0\t0.05\t1\t0\t2\r\n"
                                  "0.02\t0.5\t1\t0\t1\t0\t0\t1\t2\t0\t0\t0.02\t2\t1\t1\r\n");
    phc_plant_graph *g = read_ok(path, PHC_PLANT_FORMAT_AUTO, 0);
    if (!g)
        return;
    CHECK(g->n == 3 && g->root == 0);
    CHECK(g->parent[1] == 0 && g->parent[2] == 1);
    CHECK(g->source_id[0] == 1 && g->source_id[2] == 3);
    CHECK(g->tail[2] == 1.0 && g->tail[3] == 0.5 && g->tail[5] == 1.0);
    CHECK(g->tail[6] == 1.0 && g->tail[8] == 1.5);
    CHECK(phc_plant_graph_leaf_count(g) == 0);
    CHECK_NEAR(phc_plant_graph_volume(g), M_PI * (0.01 * 1.0 + 0.0025 * 0.5 + 0.0004 * 0.5), 0,
               1e-14);
    phc_plant_graph_free(g);
}

static void test_swc_reading(void)
{
    /* root sample 1 with two children (2 and 5): segment of sample 2 is the
     * root segment, segment of sample 5 hangs from it; micrometres. */
    const char *path = write_file("neuron.swc",
                                  "# comment\n"
                                  "1 1 0 0 0 5 -1\n"
                                  "2 3 0 0 10 2 1\n"
                                  "\n"
                                  "3 3 0 5 15 1 2\n"
                                  "4 3 5 0 15 1 2\n"
                                  "5 3 0 0 -10 3 1\n");
    phc_plant_graph *g = read_ok(path, PHC_PLANT_FORMAT_AUTO, 0);
    phc_error err;
    if (!g)
        return;
    CHECK(g->n == 4);
    CHECK(g->root == 0 && g->source_id[0] == 2);
    CHECK(g->parent[1] == 0 && g->parent[2] == 0 && g->parent[3] == 0);
    CHECK(g->source_id[3] == 5);
    CHECK_NEAR(g->radius[0], 2e-6, 0, 1e-15);
    CHECK_NEAR(g->length[0], 10e-6, 0, 1e-12);
    CHECK_NEAR(g->tail[3 * 3 + 2], -10e-6, 0, 1e-12);
    CHECK(g->head[3 * 3 + 2] == 0); /* from the root sample */
    phc_plant_graph_free(g);
    g = NULL;
    CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_SWC, 1e-3, &g, &err) == PHC_OK);
    if (g)
        CHECK_NEAR(g->length[0], 10e-3, 0, 1e-12);
    phc_plant_graph_free(g);
}

static void test_native_reading(void)
{
    /* cm, columns in another order, ids not 0..n-1, empty parent = root */
    const char *path = write_file("cm.csv",
                                  "# unit: cm\n"
                                  "parent,id,radius,length,x_head,y_head,z_head,x_tail,y_tail,"
                                  "z_tail,leaf,fixed,note\n"
                                  "20,30,0.2,1,0,0,2,1,0,2,1,0,twig\n"
                                  ",20,0.5,2,0,0,0,0,0,2,0,1,stem\n");
    phc_plant_graph *g = read_ok(path, PHC_PLANT_FORMAT_AUTO, 0);
    phc_error err;
    if (!g)
        return;
    CHECK(g->n == 2 && g->root == 1 && g->parent[0] == 1);
    CHECK(g->source_id[0] == 30 && g->source_id[1] == 20);
    CHECK_NEAR(g->radius[1], 0.005, 0, 1e-15);
    CHECK_NEAR(g->length[1], 0.02, 0, 1e-15);
    CHECK(g->leaf[0] == 1 && g->fixed[1] == 1);
    phc_plant_graph_free(g);
    g = NULL;
    /* an explicit unit overrides the file's */
    CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_NATIVE, 1, &g, &err) == PHC_OK);
    if (g)
        CHECK(g->length[1] == 2.0);
    phc_plant_graph_free(g);
}

static void test_misc(void)
{
    phc_plant_graph *g = (phc_plant_graph *)1;
    phc_error err;
    CHECK(phc_plant_format_from_name("paper") == PHC_PLANT_FORMAT_PAPER);
    CHECK(phc_plant_format_from_name("treeqsm") == PHC_PLANT_FORMAT_TREEQSM);
    CHECK(phc_plant_format_from_name("swc") == PHC_PLANT_FORMAT_SWC);
    CHECK(phc_plant_format_from_name("native") == PHC_PLANT_FORMAT_NATIVE);
    CHECK(phc_plant_format_from_name("auto") == PHC_PLANT_FORMAT_AUTO);
    CHECK(phc_plant_format_from_name("obj") == -1);
    CHECK(phc_plant_format_from_name(NULL) == -1);
    CHECK(strcmp(phc_plant_format_name(PHC_PLANT_FORMAT_SWC), "swc") == 0);
    CHECK(phc_plant_io_read(tmp_path("missing.txt"), PHC_PLANT_FORMAT_AUTO, 0, &g, &err) ==
          PHC_ERR_IO);
    CHECK(g == NULL);
    CHECK_STR_CONTAINS(err.message, "missing.txt: cannot open");
    {
        const char *path = tmp_path("nul.txt");
        FILE *f = fopen(path, "wb");
        fwrite("verts 1\n\0\n", 1, 10, f);
        fclose(f);
        CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_AUTO, 0, &g, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "nul.txt: contains a NUL byte");
    }
    /* a paper file read as native: the message still names file and line */
    {
        const char *path = write_file("wrong.txt", "verts 1\n0,0,0,0.01,0.001,0\nedges 0\n");
        CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_NATIVE, 0, &g, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "wrong.txt");
        CHECK(phc_plant_io_read(path, PHC_PLANT_FORMAT_SWC, 0, &g, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "wrong.txt:1: expected 7 SWC fields");
    }
}

/* tests/bad_inputs/plant_graphs: every file fails with its expected text,
 * and the message has FILE:LINE. */
static void test_bad_input_folder(void)
{
#ifdef PHC_SOURCE_DIR
    char list[1024], line[1024];
    FILE *f;
    int cases = 0;
    snprintf(list, sizeof list, "%s/tests/bad_inputs/plant_graphs/expected.txt", PHC_SOURCE_DIR);
    f = fopen(list, "r");
    CHECK(f != NULL);
    if (!f)
        return;
    while (fgets(line, sizeof line, f)) {
        char path[2048], *bar, *nl;
        phc_plant_graph *g = (phc_plant_graph *)1;
        phc_error err;
        int rc;
        if (line[0] == '#' || line[0] == '\n')
            continue;
        nl = strchr(line, '\n');
        if (nl)
            *nl = '\0';
        bar = strchr(line, '|');
        CHECK(bar != NULL);
        if (!bar)
            continue;
        *bar = '\0';
        snprintf(path, sizeof path, "%s/tests/bad_inputs/plant_graphs/%s", PHC_SOURCE_DIR, line);
        rc = phc_plant_io_read(path, PHC_PLANT_FORMAT_AUTO, 0, &g, &err);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK(g == NULL);
        CHECK_STR_CONTAINS(err.message, bar + 1);
        CHECK_STR_CONTAINS(err.message, line); /* names the file */
        CHECK(strchr(err.message, '\n') == NULL);
        ++cases;
    }
    fclose(f);
    CHECK(cases >= 60);
#else
    printf("test_plant_io: PHC_SOURCE_DIR not defined; bad-input folder not checked\n");
#endif
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_round_trips();
    test_paper_reading();
    test_treeqsm_reading();
    test_swc_reading();
    test_native_reading();
    test_misc();
    test_bad_input_folder();
    {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_dir);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", tmp_dir);
    }
    return check_finish("test_plant_io");
}
