/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 9: a wilted
 * plant tied to a support at several nodes.
 *
 * The paper's setting: its Fig. 9 (a greenhouse tomato graph of 1954
 * segments) latches chosen segments to a stake (their mass set to 0, i.e.
 * fixed, in the authors' PlantDemo with `uselatches`) and shows that the
 * tied plant keeps its height while the free parts droop.
 *
 * Ours (wilting_shape.h for the common setting): plant000 after 6 h of water
 * loss at the delta that leaves 60% of its water, kappa 20, chi0 0.8
 * (E = 6.8e6 Pa nearly everywhere, the wilted plant of Fig. 7's row 3), at
 * static equilibrium with 0, 1, 2 and 3 supports.  The supports are segments
 * of the main axis (from the root, always into the child with the largest
 * subtree) at 50%, then also 75%, then also 25% of its length (nested sets),
 * each fixed in its rest pose with phc_rod_set_fixed (a clamp: position and
 * orientation, as a latch with zero mass is in the authors' code).
 *
 * Prints per run the plant height, the largest displacement of a supported
 * segment, the mean drop of the unsupported segments and of the main axis,
 * and the solve times.  Checks (exit 1 when one fails):
 *   - supported segments do not move (heads and tails within 1e-12 m);
 *   - with any supports the unsupported segments drop less on average than
 *     without, and the plant is higher;
 *   - static solves <= 20 s in all.
 * Writes wilting_fig9_support.png (four panels, supports as markers) and
 * wilting_fig9_support.md.
 *
 * Usage: notebook_wilting_fig9_support OUTPUT_DIR */
#include "wilting_shape.h"

#include "notebook_plot.h"

#define NRUN 4
#define T_DRY (6.0 * 3600.0)
#define MAXPATH 4096

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

    /* water and moduli of the wilted plant */
    double delta = ws_delta_for(g, 0.6, T_DRY);
    phc_water_params wp = ws_water_params(g, delta);
    double times[2] = {0.0, T_DRY};
    double *theta = malloc(2 * n * sizeof *theta), *rwc = malloc(n * sizeof *rwc), *E = malloc(n * sizeof *E);
    if (ws_water(g, &wp, times, 2, theta, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const double *th = theta + n;
    double lo, hi;
    ws_rwc(g, th, rwc, &lo, &hi);
    phc_segment_stiffness_params sp = ws_stiffness(WS_KAPPA, WS_CHI0);
    if (phc_segment_stiffness_water(g, &sp, th, E, NULL, NULL, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }

    /* the main axis: subtree sizes, then from the root into the largest child */
    size_t *size = calloc(n, sizeof *size), path[MAXPATH], len = 0;
    for (size_t k = n; k-- > 0;) {
        size_t i = g->order[k];
        size[i] += 1;
        if (g->parent[i] != PHC_PLANT_NO_PARENT)
            size[g->parent[i]] += size[i];
    }
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
    static const double frac[3] = {0.5, 0.75, 0.25};
    size_t support[3];
    for (int s = 0; s < 3; ++s)
        support[s] = path[(size_t)(frac[s] * (double)(len - 1))];

    phc_rod *rod = ws_rod(g, E, &err);
    if (!rod) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    double *head[NRUN], *tail[NRUN], height[NRUN], moved[NRUN], free_drop[NRUN], axis_drop[NRUN], secs = 0.0;
    double marker[NRUN][9];
    int its[NRUN];
    unsigned char *fixed = calloc(n, 1);
    for (int r = 0; r < NRUN; ++r) {
        if (r > 0 && phc_rod_set_fixed(rod, support[r - 1], 1, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        if (r > 0)
            fixed[support[r - 1]] = 1;
        phc_rod_reset(rod);
        if (ws_solve(rod, E, th, &secs, &its[r], &err) != PHC_OK) {
            fprintf(stderr, "%d supports: %s\n", r, err.message);
            return 1;
        }
        head[r] = malloc(3 * n * sizeof(double)), tail[r] = malloc(3 * n * sizeof(double));
        height[r] = ws_shape(rod, head[r], tail[r]);
        double mv = 0, fd = 0, ad = 0;
        size_t nf = 0;
        for (size_t i = 0; i < n; ++i) {
            double drop = g->tail[3 * i + 2] - tail[r][3 * i + 2];
            if (fixed[i]) {
                for (int d = 0; d < 3; ++d)
                    mv = fmax(mv, fmax(fabs(head[r][3 * i + d] - g->head[3 * i + d]),
                                       fabs(tail[r][3 * i + d] - g->tail[3 * i + d])));
            } else {
                fd += drop, ++nf;
            }
        }
        for (size_t j = 0; j < len; ++j)
            ad += g->tail[3 * path[j] + 2] - tail[r][3 * path[j] + 2];
        moved[r] = mv, free_drop[r] = fd / (double)nf, axis_drop[r] = ad / (double)len;
        for (int s = 0; s < r; ++s)
            memcpy(marker[r] + 3 * s, g->tail + 3 * support[s], 3 * sizeof(double));
    }

    printf("plant000: %zu segments, rest height %.4f m; 6 h at delta = %.4e 1/(cm^2 s): theta/V %.6f..%.6f, E %.4e "
           "Pa (root segment)\n",
           n, g->tail[3 * ws_highest(g) + 2], delta, lo, hi, E[0]);
    printf("main axis: %zu segments; supports at 50%%, 75%%, 25%% of it: segments %ld, %ld, %ld (z %.4f, %.4f, %.4f "
           "m)\n",
           len, g->source_id[support[0]], g->source_id[support[1]], g->source_id[support[2]],
           g->tail[3 * support[0] + 2], g->tail[3 * support[1] + 2], g->tail[3 * support[2] + 2]);
    printf("%-10s %10s %16s %20s %18s %6s\n", "supports", "height", "support moved", "mean drop, free", "mean drop, axis",
           "its");
    int ok_fixed = 1, ok_less = 1;
    for (int r = 0; r < NRUN; ++r) {
        printf("%-10d %10.4f %16.3e %20.4e %18.4e %6d\n", r, height[r], moved[r], free_drop[r], axis_drop[r], its[r]);
        if (r > 0) {
            ok_fixed &= moved[r] <= 1e-12;
            ok_less &= free_drop[r] < free_drop[0] && height[r] > height[0];
        }
    }
    printf("supported segments do not move (<= 1e-12 m): %s\n", ok_fixed ? "yes" : "no");
    printf("with supports the free segments drop less and the plant is higher: %s\n", ok_less ? "yes" : "no");
    int ok_time = secs <= 20.0;
    printf("static solves: %d in %.3f s (bound 20 s)\n", NRUN, secs);

    phc_shape_panel pan[NRUN];
    char title[NRUN][96];
    for (int r = 0; r < NRUN; ++r) {
        snprintf(title[r], sizeof title[r], "%d support%s: %.1f cm", r, r == 1 ? "" : "s", 100.0 * height[r]);
        pan[r] = (phc_shape_panel){n, head[r], tail[r], g->radius, rwc, title[r], (size_t)r, marker[r], "support"};
    }
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.title = "Fig. 9: wilted plant000 tied to a support";
    po.columns = NRUN;
    po.value_min = 0.5, po.value_max = 1.0;
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig9_support.png", out);
    if (phc_shape_plot(png, pan, NRUN, &po, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig9_support.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Wilting paper, Fig. 9: supports\n\n"
               "plant000 wilted (theta/V 0.6, E 6.8e6 Pa), fixed at 0-3 segments of its main axis.\n\n"
               "![supports](wilting_fig9_support.png)\n\n"
               "| supports | height (m) | support moved (m) | mean drop of free segments (m) |\n|---:|---:|---:|---:|\n");
    for (int r = 0; r < NRUN; ++r)
        fprintf(f, "| %d | %.4f | %.1e | %.4e |\n", r, height[r], moved[r], free_drop[r]);
    fprintf(f, "\nChecks: supports do not move %s; free segments drop less with supports %s; solves %.3f s %s.\n",
            ok_fixed ? "(pass)" : "(**FAIL**)", ok_less ? "(pass)" : "(**FAIL**)", secs,
            ok_time ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    for (int r = 0; r < NRUN; ++r)
        free(head[r]), free(tail[r]);
    phc_rod_free(rod);
    free(theta), free(rwc), free(E), free(size), free(on_axis), free(fixed);
    phc_plant_graph_free(g);
    int fail = !(ok_fixed && ok_less && ok_time);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
