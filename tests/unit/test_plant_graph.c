/* Unit tests for model/plant_graph.c: finish() and its messages, copy,
 * volume, the random tree and the leaf chain. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "model/plant_graph.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* A valid chain 0 <- 1 <- 2 <- ... along +z, radius 1 mm, length 1 cm. */
static phc_plant_graph *chain(size_t n)
{
    phc_plant_graph *g = phc_plant_graph_new(n);
    size_t i;
    if (!g)
        return NULL;
    for (i = 0; i < n; ++i) {
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = 1e-3;
        g->length[i] = 1e-2;
        g->head[3 * i + 2] = 1e-2 * (double)i;
        g->tail[3 * i + 2] = 1e-2 * (double)(i + 1);
        g->source_id[i] = (long)(100 + i);
    }
    return g;
}

static void test_new(void)
{
    phc_plant_graph *g = phc_plant_graph_new(5);
    size_t i;
    CHECK(g != NULL);
    CHECK(phc_plant_graph_new(0) == NULL);
    for (i = 0; i < 5; ++i) {
        CHECK(g->parent[i] == PHC_PLANT_NO_PARENT);
        CHECK(g->source_id[i] == (long)i);
        CHECK(g->radius[i] == 0 && g->leaf[i] == 0 && g->tail[3 * i] == 0);
    }
    CHECK(g->order == NULL);
    phc_plant_graph_free(g);
    phc_plant_graph_free(NULL);
}

static void expect_error(phc_plant_graph *g, const char *where, const char *a, const char *b)
{
    phc_error err;
    int rc = phc_plant_graph_finish(g, where, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK(err.status == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, a);
    if (b)
        CHECK_STR_CONTAINS(err.message, b);
    CHECK(g->order == NULL && g->child == NULL);
}

static void test_finish_ok(void)
{
    phc_plant_graph *g = chain(4), *c;
    phc_error err;
    /* a branch: segment 3 hangs off segment 1 */
    g->parent[3] = 1;
    CHECK(phc_plant_graph_finish(g, "p.txt", &err) == PHC_OK);
    CHECK(g->root == 0);
    CHECK(g->order[0] == 0 && g->order[1] == 1);
    CHECK(g->depth[0] == 0 && g->depth[1] == 1 && g->depth[2] == 2 && g->depth[3] == 2);
    CHECK(g->child_start[0] == 0 && g->child_start[1] == 1 && g->child_start[2] == 3);
    CHECK(g->child_start[4] == 3);
    CHECK(g->child[0] == 1 && g->child[1] == 2 && g->child[2] == 3);
    /* finishing twice is fine */
    CHECK(phc_plant_graph_finish(g, "p.txt", &err) == PHC_OK);
    c = phc_plant_graph_copy(g);
    CHECK(c != NULL && c != g);
    if (c) {
        CHECK(c->n == g->n && c->root == g->root);
        CHECK(memcmp(c->parent, g->parent, 4 * sizeof *g->parent) == 0);
        CHECK(memcmp(c->tail, g->tail, 12 * sizeof *g->tail) == 0);
        CHECK(memcmp(c->order, g->order, 4 * sizeof *g->order) == 0);
        CHECK(memcmp(c->child, g->child, 3 * sizeof *g->child) == 0);
        CHECK(c->parent != g->parent);
    }
    CHECK_NEAR(phc_plant_graph_volume(g), 4 * M_PI * 1e-6 * 1e-2, 0, 1e-14);
    phc_plant_graph_free(c);
    phc_plant_graph_free(g);

    /* a single segment */
    g = chain(1);
    CHECK(phc_plant_graph_finish(g, "", &err) == PHC_OK);
    CHECK(g->root == 0 && g->child_start[1] == 0);
    phc_plant_graph_free(g);
}

static void test_finish_errors(void)
{
    phc_plant_graph *g;
    phc_error err;

    g = chain(10);
    g->parent[9] = PHC_PLANT_NO_PARENT;
    g->source_id[3] = 3;
    g->parent[3] = PHC_PLANT_NO_PARENT;
    g->parent[0] = 5;
    g->source_id[9] = 9;
    expect_error(g, "plant.txt", "plant.txt: two roots: segments 3 and 9", NULL);
    phc_plant_graph_free(g);

    g = chain(3);
    g->parent[2] = 7;
    expect_error(g, "a.csv", "a.csv: segment 102: parent index 7 out of range", "3 segments");
    phc_plant_graph_free(g);

    g = chain(3);
    g->parent[1] = 1;
    expect_error(g, "a.csv", "segment 101: a segment cannot be its own parent", NULL);
    phc_plant_graph_free(g);

    /* a cycle 2 -> 3 -> 4 -> 2 beside a valid root */
    g = chain(6);
    g->parent[2] = 4;
    expect_error(g, "cyc.csv", "cyc.csv: cycle", "loop of 3 segments");
    phc_plant_graph_free(g);

    /* no root at all */
    g = chain(3);
    g->parent[0] = 2;
    expect_error(g, "x", "no root", "cycle");
    phc_plant_graph_free(g);

    g = chain(3);
    g->radius[1] = -0.002;
    expect_error(g, "plant.txt", "plant.txt: segment 101: radius must be positive and finite, found -0.002",
                 NULL);
    phc_plant_graph_free(g);

    g = chain(3);
    g->radius[1] = NAN;
    expect_error(g, "", "segment 101: radius must be positive and finite, found nan", NULL);
    phc_plant_graph_free(g);

    g = chain(3);
    g->length[2] = 0;
    expect_error(g, "p", "segment 102: length must be positive and finite, found 0", NULL);
    phc_plant_graph_free(g);

    g = chain(3);
    g->length[2] = INFINITY;
    expect_error(g, "p", "segment 102: length must be positive and finite", NULL);
    phc_plant_graph_free(g);

    g = chain(3);
    g->tail[3 * 1 + 1] = NAN;
    expect_error(g, "p", "segment 101: tail y coordinate must be finite", NULL);
    phc_plant_graph_free(g);

    g = chain(3);
    g->head[3 * 2] = -INFINITY;
    expect_error(g, "p", "segment 102: head x coordinate must be finite", NULL);
    phc_plant_graph_free(g);

    /* "" gives no prefix */
    g = chain(2);
    g->radius[0] = 0;
    CHECK(phc_plant_graph_finish(g, "", &err) == PHC_ERR_INPUT);
    CHECK(strncmp(err.message, "segment 100:", 12) == 0);
    CHECK(phc_plant_graph_finish(g, NULL, &err) == PHC_ERR_INPUT);
    CHECK(strncmp(err.message, "segment 100:", 12) == 0);
    phc_plant_graph_free(g);

    CHECK(phc_plant_graph_finish(NULL, "", &err) == PHC_ERR_INVALID);
}

/* Invariants of a random tree. */
static void check_random(size_t n, unsigned long seed)
{
    phc_plant_graph *g = phc_plant_graph_random(n, seed), *h;
    size_t i, bad_head = 0, bad_len = 0, bad_pipe = 0, bad_above = 0, leaf_with_stem_child = 0;
    double d_root;
    CHECK(g != NULL);
    if (!g)
        return;
    CHECK(g->n == n);
    CHECK(g->order != NULL && g->root == 0);
    d_root = g->tail[2];
    for (i = 0; i < n; ++i) {
        const size_t p = g->parent[i];
        double sum_c = 0, dx, dy, dz;
        size_t c;
        if (p != PHC_PLANT_NO_PARENT) {
            if (memcmp(g->head + 3 * i, g->tail + 3 * p, 3 * sizeof(double)) != 0)
                ++bad_head;
            if (!(g->tail[3 * i + 2] > d_root))
                ++bad_above;
            if (!g->leaf[p] || g->leaf[i])
                ;
            else
                ++leaf_with_stem_child; /* leaves hang at the periphery */
        } else {
            if (g->head[0] != 0 || g->head[1] != 0 || g->head[2] != 0)
                ++bad_head;
        }
        dx = g->tail[3 * i] - g->head[3 * i];
        dy = g->tail[3 * i + 1] - g->head[3 * i + 1];
        dz = g->tail[3 * i + 2] - g->head[3 * i + 2];
        if (fabs(sqrt(dx * dx + dy * dy + dz * dz) - g->length[i]) > 1e-12 * g->length[i])
            ++bad_len;
        /* pipe model: r_parent^2 = sum of r_child^2 where there are children */
        for (c = g->child_start[i]; c < g->child_start[i + 1]; ++c)
            sum_c += g->radius[g->child[c]] * g->radius[g->child[c]];
        if (g->child_start[i + 1] > g->child_start[i] &&
            fabs(sum_c - g->radius[i] * g->radius[i]) > 1e-9 * sum_c)
            ++bad_pipe;
    }
    CHECK(bad_head == 0);
    CHECK(bad_len == 0);
    CHECK(bad_pipe == 0);
    CHECK(bad_above == 0);
    CHECK(leaf_with_stem_child == 0);
    CHECK(g->leaf[0] == 0);
    if (n >= 1000) {
        const double frac = (double)phc_plant_graph_leaf_count(g) / (double)n;
        CHECK(frac > 0.5 && frac <= 0.8);
    }
    /* deterministic: same seed, same tree; another seed, another tree */
    h = phc_plant_graph_random(n, seed);
    CHECK(h && memcmp(h->parent, g->parent, n * sizeof *g->parent) == 0 &&
          memcmp(h->tail, g->tail, 3 * n * sizeof *g->tail) == 0 &&
          memcmp(h->radius, g->radius, n * sizeof *g->radius) == 0);
    phc_plant_graph_free(h);
    if (n > 10) {
        h = phc_plant_graph_random(n, seed + 1);
        CHECK(h && memcmp(h->tail, g->tail, 3 * n * sizeof *g->tail) != 0);
        phc_plant_graph_free(h);
    }
    phc_plant_graph_free(g);
}

static void test_random(void)
{
    phc_plant_graph *g;
    check_random(1, 1);
    check_random(2, 7);
    check_random(50, 3);
    check_random(2000, 42);
    check_random(200000, 9);
    CHECK(phc_plant_graph_random(0, 1) == NULL);
    /* a million segments in O(n) */
    g = phc_plant_graph_random(1000000, 5);
    CHECK(g != NULL && g->n == 1000000);
    if (g) {
        const double frac = (double)phc_plant_graph_leaf_count(g) / 1e6;
        CHECK(frac > 0.5 && frac <= 0.8);
        CHECK(phc_plant_graph_volume(g) > 0);
    }
    phc_plant_graph_free(g);
}

static void test_leaf_chain(void)
{
    const double area = 50e-4, r = 2e-4; /* 50 cm^2, 0.2 mm */
    phc_plant_graph *g = phc_plant_graph_leaf_chain(area, 10, r);
    size_t i;
    double total = 0;
    CHECK(g != NULL);
    if (!g)
        return;
    CHECK(g->n == 10);
    CHECK(g->root == 0 && g->parent[0] == PHC_PLANT_NO_PARENT);
    CHECK(g->leaf[0] == 0);
    CHECK(phc_plant_graph_leaf_count(g) == 9);
    for (i = 1; i < 10; ++i) {
        CHECK(g->parent[i] == i - 1);
        CHECK(g->leaf[i] == 1);
        CHECK(g->depth[i] == i);
    }
    for (i = 0; i < 10; ++i) {
        CHECK(g->radius[i] == r);
        total += g->length[i];
    }
    CHECK_NEAR(total, sqrt(2 * area), 0, 1e-12);
    CHECK_NEAR(phc_plant_graph_volume(g), M_PI * r * r * sqrt(2 * area), 0, 1e-12);
    phc_plant_graph_free(g);

    CHECK(phc_plant_graph_leaf_chain(0, 10, r) == NULL);
    CHECK(phc_plant_graph_leaf_chain(-1, 10, r) == NULL);
    CHECK(phc_plant_graph_leaf_chain(NAN, 10, r) == NULL);
    CHECK(phc_plant_graph_leaf_chain(area, 1, r) == NULL);
    CHECK(phc_plant_graph_leaf_chain(area, 0, r) == NULL);
    CHECK(phc_plant_graph_leaf_chain(area, 10, 0) == NULL);
    CHECK(phc_plant_graph_leaf_chain(area, 10, INFINITY) == NULL);
}

int main(void)
{
    test_new();
    test_finish_ok();
    test_finish_errors();
    test_random();
    test_leaf_chain();
    return check_finish("test_plant_graph");
}
