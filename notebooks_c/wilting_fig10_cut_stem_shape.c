/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 10: a cut stem,
 * the shape (wilting_fig10_cut_stem.c follows the water alone).
 *
 * The paper's setting: its Fig. 10 cuts (zero conductance) an edge of the
 * plant graph; the part beyond the cut loses water on its own and droops,
 * in its cm/g units with eq. 9 on absolute water.
 *
 * Ours (wilting_shape.h for the common setting): plant000, the water cut
 * (edge_factor 0: no flow) on one edge, the stem mechanically intact (the
 * joint keeps its stiffness: a cut of the xylem, not of the stem).  The
 * model has no roots, so the part above a cut only dries faster than the
 * intact plant when it loses more water for the water it holds: with theta/V
 * uniform within a part its rate is delta sum(A_i V_i over its leaves) /
 * sum(V_i over the part).  We cut the branch with the highest such rate
 * among the branches that leave the main axis and hold at least 5% of the
 * plant's volume, and say which (a branch whose rate is lower than the
 * plant's would stay turgid longer when cut: the water-only notebook shows
 * that case on plant002).  6 h at the delta that leaves the intact plant 70%
 * of its water; E = 5e6 + 1e8 sigma(20 (theta/V - 0.8)) Pa.
 *
 * Prints the water above the cut and in the rest, intact and cut, the
 * branch's mean and lowest tail height in both, and the solve times.
 * Checks (exit 1 when one fails):
 *   - the cut part's theta/V is lower than in the intact plant (its own
 *     leaves drain it and nothing refills it) and the rest's is higher;
 *   - the part above the cut ends lower than in the intact plant (mean z of
 *     its tails);
 *   - static solves <= 20 s in all.
 * Writes wilting_fig10_cut_stem_shape.png (intact, cut; the cut marked) and
 * wilting_fig10_cut_stem_shape.md.
 *
 * Usage: notebook_wilting_fig10_cut_stem_shape OUTPUT_DIR */
#include "wilting_shape.h"

#include "notebook_plot.h"

#define T_DRY (6.0 * 3600.0)
#define MAXPATH 4096

static void mark_subtree(const phc_plant_graph *g, size_t r, unsigned char *in_sub)
{
    memset(in_sub, 0, g->n);
    in_sub[r] = 1;
    for (size_t k = 0; k < g->n; ++k) {
        size_t i = g->order[k];
        if (g->parent[i] != PHC_PLANT_NO_PARENT && in_sub[g->parent[i]])
            in_sub[i] = 1;
    }
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, WS_PLANT, &out);
    if (started)
        return started;
    phc_error err;
    phc_error_clear(&err);
    phc_plant_graph *g = ws_read(WS_PLANT);
    if (!g)
        return 1;
    size_t n = g->n;

    /* per subtree: volume and leaf sum(A V) (children after parents) */
    double *vol = calloc(n, sizeof *vol), *av = calloc(n, sizeof *av);
    size_t *size = calloc(n, sizeof *size);
    for (size_t k = n; k-- > 0;) {
        size_t i = g->order[k];
        double v = phc_segment_volume_cm3(g, i);
        vol[i] += v, size[i] += 1;
        if (g->leaf[i])
            av[i] += v * (g->radius[i] * 100.0) * (g->length[i] * 100.0);
        if (g->parent[i] != PHC_PLANT_NO_PARENT)
            vol[g->parent[i]] += vol[i], av[g->parent[i]] += av[i], size[g->parent[i]] += size[i];
    }
    /* the main axis and the branches leaving it */
    size_t path[MAXPATH], len = 0;
    unsigned char *on_axis = calloc(n, 1);
    for (size_t cur = g->root;;) {
        path[len++] = cur;
        on_axis[cur] = 1;
        size_t best = (size_t)-1;
        for (size_t c = g->child_start[cur]; c < g->child_start[cur + 1]; ++c)
            if (best == (size_t)-1 || size[g->child[c]] > size[best])
                best = g->child[c];
        if (best == (size_t)-1 || len >= MAXPATH)
            break;
        cur = best;
    }
    size_t root = g->root, cut = (size_t)-1, branches = 0;
    double rate_plant = av[root] / vol[root];
    for (size_t j = 0; j < len; ++j)
        for (size_t c = g->child_start[path[j]]; c < g->child_start[path[j] + 1]; ++c) {
            size_t ch = g->child[c];
            if (on_axis[ch] || vol[ch] < 0.05 * vol[root])
                continue;
            ++branches;
            if (cut == (size_t)-1 || av[ch] / vol[ch] > av[cut] / vol[cut])
                cut = ch;
        }
    if (cut == (size_t)-1) {
        fprintf(stderr, "plant000: no branch with 5%% of the volume leaves the main axis\n");
        return 1;
    }
    unsigned char *above = malloc(n);
    mark_subtree(g, cut, above);

    double delta = ws_delta_for(g, 0.7, T_DRY);
    double *theta = malloc(2 * n * sizeof *theta), *rwc[2], *E = malloc(n * sizeof *E), *ef = malloc(n * sizeof *ef);
    double *head[2], *tail[2], height[2], secs = 0.0, rwc_above[2], rwc_rest[2], mean_z[2], low_z[2];
    phc_rod *rod = NULL;
    static const char *run_name[2] = {"intact", "cut"};
    for (int r = 0; r < 2; ++r) {
        for (size_t i = 0; i < n; ++i)
            ef[i] = 1.0;
        if (r == 1)
            ef[cut] = 0.0;
        phc_water_params wp = ws_water_params(g, delta);
        wp.edge_factor = ef;
        double times[2] = {0.0, T_DRY}, lo, hi;
        if (ws_water(g, &wp, times, 2, theta, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        rwc[r] = malloc(n * sizeof(double));
        ws_rwc(g, theta + n, rwc[r], &lo, &hi);
        double wa = 0, va = 0, wr = 0, vr = 0;
        for (size_t i = 0; i < n; ++i) {
            double v = phc_segment_volume_cm3(g, i);
            if (above[i])
                wa += theta[n + i], va += v;
            else
                wr += theta[n + i], vr += v;
        }
        rwc_above[r] = wa / va, rwc_rest[r] = wr / vr;
        phc_segment_stiffness_params sp = ws_stiffness(WS_KAPPA, WS_CHI0);
        if (phc_segment_stiffness_water(g, &sp, theta + n, E, NULL, NULL, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        if (!rod && !(rod = ws_rod(g, E, &err))) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        phc_rod_reset(rod);
        if (ws_solve(rod, E, theta + n, &secs, NULL, &err) != PHC_OK) {
            fprintf(stderr, "%s: %s\n", run_name[r], err.message);
            return 1;
        }
        head[r] = malloc(3 * n * sizeof(double)), tail[r] = malloc(3 * n * sizeof(double));
        height[r] = ws_shape(rod, head[r], tail[r]);
        double s = 0;
        low_z[r] = INFINITY;
        for (size_t i = 0; i < n; ++i)
            if (above[i])
                s += tail[r][3 * i + 2], low_z[r] = fmin(low_z[r], tail[r][3 * i + 2]);
        mean_z[r] = s / (double)size[cut];
    }

    double rest_mean = 0;
    for (size_t i = 0; i < n; ++i)
        rest_mean += above[i] ? g->tail[3 * i + 2] : 0.0;
    rest_mean /= (double)size[cut];
    printf("plant000: %zu segments; %zu branches leave the main axis with >= 5%% of the volume; cut: the edge into "
           "segment %ld (depth %zu, z %.4f m): %zu segments, %.1f%% of the volume above\n",
           n, branches, g->source_id[cut], g->depth[cut], g->head[3 * cut + 2], size[cut],
           100.0 * vol[cut] / vol[root]);
    printf("loss per water (sum_leaf A V / sum V, cm^2): branch %.4e, whole plant %.4e (ratio %.3f); delta %.4e "
           "1/(cm^2 s), 6 h\n",
           av[cut] / vol[cut], rate_plant, av[cut] / vol[cut] / rate_plant, delta);
    printf("%-8s %14s %14s %12s %16s %16s\n", "run", "theta/V above", "theta/V rest", "height (m)", "branch mean z",
           "branch lowest z");
    for (int r = 0; r < 2; ++r)
        printf("%-8s %14.4f %14.4f %12.4f %16.4f %16.4f\n", run_name[r], rwc_above[r], rwc_rest[r], height[r],
               mean_z[r], low_z[r]);
    printf("branch mean z at rest: %.4f m\n", rest_mean);
    int ok_water = rwc_above[1] < rwc_above[0] && rwc_rest[1] > rwc_rest[0];
    int ok_lower = mean_z[1] < mean_z[0];
    int ok_time = secs <= 20.0;
    printf("cut part drier and the rest wetter than intact: %s\n", ok_water ? "yes" : "no");
    printf("the part above the cut ends lower than in the intact plant: %s (%.4f m vs %.4f m)\n",
           ok_lower ? "yes" : "no", mean_z[1], mean_z[0]);
    printf("static solves: 2 in %.3f s (bound 20 s)\n", secs);

    phc_shape_panel pan[2];
    char title[2][96];
    for (int r = 0; r < 2; ++r) {
        snprintf(title[r], sizeof title[r], "%s: branch mean height %.1f cm", run_name[r], 100.0 * mean_z[r]);
        pan[r] = (phc_shape_panel){n, head[r], tail[r], g->radius, rwc[r], title[r], 1, head[r] + 3 * cut, "cut"};
    }
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.title = "Fig. 10: plant000 after 6 h, intact and with a branch's water cut";
    po.columns = 2;
    po.value_min = 0.4, po.value_max = 1.0;
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig10_cut_stem_shape.png", out);
    if (phc_shape_plot(png, pan, 2, &po, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig10_cut_stem_shape.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Wilting paper, Fig. 10: a cut stem, the shape\n\n"
               "plant000 after 6 h, the water cut into the branch of segment %ld (settings in the program's header).\n\n"
               "![cut](wilting_fig10_cut_stem_shape.png)\n\n"
               "| run | theta/V above | theta/V rest | height (m) | branch mean z (m) |\n|---|---:|---:|---:|---:|\n",
            g->source_id[cut]);
    for (int r = 0; r < 2; ++r)
        fprintf(f, "| %s | %.4f | %.4f | %.4f | %.4f |\n", run_name[r], rwc_above[r], rwc_rest[r], height[r], mean_z[r]);
    fprintf(f, "\nChecks: cut part drier, rest wetter %s; cut part lower %s; solves %.3f s %s.\n",
            ok_water ? "(pass)" : "(**FAIL**)", ok_lower ? "(pass)" : "(**FAIL**)", secs,
            ok_time ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    for (int r = 0; r < 2; ++r)
        free(head[r]), free(tail[r]), free(rwc[r]);
    phc_rod_free(rod);
    free(vol), free(av), free(size), free(on_axis), free(above), free(theta), free(E), free(ef);
    phc_plant_graph_free(g);
    int fail = !(ok_water && ok_lower && ok_time);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
