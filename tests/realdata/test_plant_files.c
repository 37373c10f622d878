/* Real plant graphs (../shared/data): the wilting paper's four plants and a
 * TreeQSM tree read, finished and checked; total volumes printed.
 * Skips (77) when the shared data folder is absent. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "measurements/plant_io.h"
#include "model/plant_graph.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif

/* The invariants every finished graph must satisfy. */
static void check_graph(const phc_plant_graph *g, int heads_at_parent_tails)
{
    size_t i, k, roots = 0, bad_order = 0, bad_depth = 0, bad_head = 0, bad_len = 0;
    size_t *pos = malloc(g->n * sizeof *pos);
    CHECK(pos != NULL);
    if (!pos)
        return;
    for (i = 0; i < g->n; ++i)
        pos[g->order[i]] = i;
    for (i = 0; i < g->n; ++i) {
        const size_t p = g->parent[i];
        if (p == PHC_PLANT_NO_PARENT) {
            ++roots;
            continue;
        }
        if (pos[p] >= pos[i])
            ++bad_order;
        if (g->depth[i] != g->depth[p] + 1)
            ++bad_depth;
        if (heads_at_parent_tails)
            for (k = 0; k < 3; ++k)
                if (g->head[3 * i + k] != g->tail[3 * p + k])
                    ++bad_head;
        {
            const double dx = g->tail[3 * i] - g->head[3 * i];
            const double dy = g->tail[3 * i + 1] - g->head[3 * i + 1];
            const double dz = g->tail[3 * i + 2] - g->head[3 * i + 2];
            if (fabs(sqrt(dx * dx + dy * dy + dz * dz) - g->length[i]) > 1e-6 * g->length[i])
                ++bad_len;
        }
        if (!(g->radius[i] > 0 && g->length[i] > 0))
            ++bad_len;
    }
    CHECK(roots == 1);
    CHECK(g->parent[g->root] == PHC_PLANT_NO_PARENT);
    CHECK(g->order[0] == g->root);
    CHECK(g->child_start[g->n] == g->n - 1);
    CHECK(bad_order == 0);
    CHECK(bad_depth == 0);
    CHECK(bad_head == 0);
    CHECK(bad_len == 0);
    free(pos);
}

int main(void)
{
    static const struct {
        const char *file;
        size_t n;
    } plants[] = {{"plant000.txt", 1964}, {"plant001.txt", 617}, {"plant002.txt", 300},
                  {"plant003.txt", 711}};
    struct stat st;
    char path[1024];
    size_t i;
    if (stat(PHC_SHARED_DATA "/plants", &st) != 0 || stat(PHC_SHARED_DATA "/treeqsm", &st) != 0) {
        printf("test_plant_files: skipped: shared data folder %s (plants/, treeqsm/) is absent\n",
               PHC_SHARED_DATA);
        return 77;
    }
    for (i = 0; i < sizeof plants / sizeof plants[0]; ++i) {
        phc_plant_graph *g = NULL;
        phc_error err;
        int rc;
        snprintf(path, sizeof path, "%s/plants/%s", PHC_SHARED_DATA, plants[i].file);
        rc = phc_plant_io_read(path, PHC_PLANT_FORMAT_AUTO, 0, &g, &err);
        CHECK(rc == PHC_OK);
        if (rc) {
            fprintf(stderr, "%s\n", err.message);
            continue;
        }
        CHECK(g->n == plants[i].n);
        check_graph(g, 1);
        /* the root's head is the origin (authors' reader) */
        CHECK(g->head[3 * g->root] == 0 && g->head[3 * g->root + 1] == 0 &&
              g->head[3 * g->root + 2] == 0);
        if (i == 0) {
            CHECK(phc_plant_graph_leaf_count(g) == 1692);
            CHECK(g->n - phc_plant_graph_leaf_count(g) == 272);
        }
        printf("%s: %zu segments, %zu leaf, root %ld, max depth %zu, volume %.6g m^3\n",
               plants[i].file, g->n, phc_plant_graph_leaf_count(g), g->source_id[g->root],
               g->depth[g->order[g->n - 1]], phc_plant_graph_volume(g));
        phc_plant_graph_free(g);
    }
    {
        phc_plant_graph *g = NULL;
        phc_error err;
        int rc;
        snprintf(path, sizeof path, "%s/treeqsm/Tree_1_TreeQSM.txt", PHC_SHARED_DATA);
        rc = phc_plant_io_read(path, PHC_PLANT_FORMAT_AUTO, 0, &g, &err);
        CHECK(rc == PHC_OK);
        if (rc) {
            fprintf(stderr, "%s\n", err.message);
        } else {
            double v_file = 0;
            CHECK(g->n == 2271);
            check_graph(g, 0);
            CHECK(phc_plant_graph_leaf_count(g) == 0);
            CHECK(g->source_id[g->root] == 1);
            for (i = 0; i < g->n; ++i)
                v_file += M_PI * g->radius[i] * g->radius[i] * g->length[i];
            CHECK_NEAR(phc_plant_graph_volume(g), v_file, 0, 1e-12);
            printf("Tree_1_TreeQSM.txt: %zu cylinders, root %ld, max depth %zu, volume %.6g m^3\n",
                   g->n, g->source_id[g->root], g->depth[g->order[g->n - 1]],
                   phc_plant_graph_volume(g));
            phc_plant_graph_free(g);
        }
    }
    return check_finish("test_plant_files");
}
