/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 7: a grid of
 * wilted shapes over the loss rate delta and the steepness kappa of eq. 9.
 *
 * The paper's setting: its Fig. 7 varies delta (how fast the leaves lose
 * water) and kappa (how sharply stiffness falls around chi0) on one plant
 * and shows each after the same simulated time, in its cm/g units with
 * eq. 9 on absolute water and its stiffness scale (model/segment_stiffness.h).
 *
 * Ours (wilting_shape.h for the common setting): plant000, physical water
 * model, 3 x 3 runs, each after T = 6 h of water loss: water model (BDF6) ->
 * relative water content theta/V per segment -> E = 5e6 + 1e8 sigma(kappa
 * (theta/V - 0.8)) Pa -> static equilibrium with the water's mass.
 * delta is chosen so that the plant holds 90%, 75% and 60% of its water
 * after 6 h (printed in 1/(cm^2 s)); kappa = 5, 20, 80.  Relative water
 * content is used (our default): it is nearly uniform over the plant
 * (printed), so a run's moduli are nearly the same in every segment and the
 * grid shows how eq. 9 maps the plant's water to stiffness.
 *
 * Prints the plant height (max z of the tails) for every run and the static
 * solve times.  Checks (exit 1 when one fails):
 *   - more delta -> lower plant, for every kappa (less water, lower E);
 *   - kappa: above chi0 (theta/V = 0.9) a steeper logistic is nearer E_max,
 *     so larger kappa -> higher plant; below chi0 (0.75, 0.6) it is nearer
 *     E_min, so larger kappa -> lower plant.  The direction is predicted from
 *     the sign of theta/V - chi0 of each row and checked;
 *   - static solves <= 20 s in all.
 * Writes wilting_fig7_wilting_grid.png (3 x 3 panels coloured by relative
 * water content) and wilting_fig7_wilting_grid.md.
 *
 * Usage: notebook_wilting_fig7_wilting_grid OUTPUT_DIR */
#include "wilting_shape.h"

#include "notebook_plot.h"

#define ND 3
#define NK 3
#define T_DRY (6.0 * 3600.0)

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
    static const double target[ND] = {0.9, 0.75, 0.6}, kappa[NK] = {5.0, 20.0, 80.0};
    double delta[ND], rwc_lo[ND], rwc_hi[ND], rwc_mean[ND];
    double *theta = malloc(2 * n * sizeof *theta), *rwc[ND], *E = malloc(n * sizeof *E);
    double *head[ND][NK], *tail[ND][NK], height[ND][NK], secs = 0.0, emod[ND][NK];
    int its[ND][NK];
    phc_rod *rod = NULL;
    for (int d = 0; d < ND; ++d) {
        rwc[d] = malloc(n * sizeof(double));
        delta[d] = ws_delta_for(g, target[d], T_DRY);
        phc_water_params wp = ws_water_params(g, delta[d]);
        double times[2] = {0.0, T_DRY};
        if (ws_water(g, &wp, times, 2, theta, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        ws_rwc(g, theta + n, rwc[d], &rwc_lo[d], &rwc_hi[d]);
        double W = 0;
        for (size_t i = 0; i < n; ++i)
            W += theta[n + i];
        rwc_mean[d] = W / wp.initial_water;
        for (int k = 0; k < NK; ++k) {
            phc_segment_stiffness_params sp = ws_stiffness(kappa[k], WS_CHI0);
            if (phc_segment_stiffness_water(g, &sp, theta + n, E, NULL, NULL, &err) != PHC_OK) {
                fprintf(stderr, "%s\n", err.message);
                return 1;
            }
            emod[d][k] = E[0];
            if (!rod && !(rod = ws_rod(g, E, &err))) {
                fprintf(stderr, "%s\n", err.message);
                return 1;
            }
            phc_rod_reset(rod);
            if (ws_solve(rod, E, theta + n, &secs, &its[d][k], &err) != PHC_OK) {
                fprintf(stderr, "delta %g, kappa %g: %s\n", delta[d], kappa[k], err.message);
                return 1;
            }
            head[d][k] = malloc(3 * n * sizeof(double)), tail[d][k] = malloc(3 * n * sizeof(double));
            height[d][k] = ws_shape(rod, head[d][k], tail[d][k]);
        }
    }

    size_t top = ws_highest(g);
    printf("plant000: %zu segments, rest height %.4f m; T = %.0f h; chi0 = %.2f, E = %.0e + %.0e sigma(kappa (x - "
           "chi0)) Pa\n",
           n, g->tail[3 * top + 2], T_DRY / 3600.0, WS_CHI0, WS_E_MIN, WS_E_MAX);
    printf("%-14s %-22s", "delta", "theta/V (min..max)");
    for (int k = 0; k < NK; ++k)
        printf("  height k=%-4g", kappa[k]);
    printf("   E of the root segment (Pa) for each kappa\n");
    for (int d = 0; d < ND; ++d) {
        printf("%-14.4e %.6f..%.6f    ", delta[d], rwc_lo[d], rwc_hi[d]);
        for (int k = 0; k < NK; ++k)
            printf("  %12.4f  ", height[d][k]);
        for (int k = 0; k < NK; ++k)
            printf(" %10.4e", emod[d][k]);
        printf("\n");
    }
    int ok_delta = 1, ok_kappa = 1;
    for (int k = 0; k < NK; ++k)
        for (int d = 1; d < ND; ++d)
            ok_delta &= height[d][k] < height[d - 1][k];
    for (int d = 0; d < ND; ++d) {
        int up = rwc_mean[d] > WS_CHI0; /* predicted: larger kappa -> higher when above chi0 */
        int good = 1;
        for (int k = 1; k < NK; ++k)
            good &= up ? height[d][k] > height[d][k - 1] : height[d][k] < height[d][k - 1];
        printf("delta %.4e: theta/V %.4f %s chi0: predicted larger kappa -> %s plant: %s\n", delta[d], rwc_mean[d],
               up ? "above" : "below", up ? "higher" : "lower", good ? "yes" : "no");
        ok_kappa &= good;
    }
    printf("more delta -> lower plant for every kappa: %s\n", ok_delta ? "yes" : "no");
    int ok_time = secs <= 20.0;
    printf("static solves: %d in %.3f s (bound 20 s)\n", ND * NK, secs);

    phc_shape_panel pan[ND * NK];
    char title[ND * NK][128];
    for (int d = 0; d < ND; ++d)
        for (int k = 0; k < NK; ++k) {
            int p = d * NK + k;
            snprintf(title[p], sizeof title[p], "\xce\xb4 %.1e, \xce\xba %g: %.1f cm", delta[d], kappa[k],
                     100.0 * height[d][k]);
            pan[p] = (phc_shape_panel){n, head[d][k], tail[d][k], g->radius, rwc[d], title[p], 0, NULL, NULL};
        }
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.title = "Fig. 7: plant000 after 6 h, \xce\xb4 (rows) \xc3\x97 \xce\xba (columns)";
    po.columns = NK;
    po.value_min = 0.5, po.value_max = 1.0;
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig7_wilting_grid.png", out);
    if (phc_shape_plot(png, pan, ND * NK, &po, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig7_wilting_grid.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Wilting paper, Fig. 7: delta x kappa\n\n"
               "plant000 after 6 h of water loss, heights in m (settings in the program's header).\n\n"
               "![grid](wilting_fig7_wilting_grid.png)\n\n| delta (1/(cm^2 s)) | theta/V |");
    for (int k = 0; k < NK; ++k)
        fprintf(f, " kappa %g |", kappa[k]);
    fprintf(f, "\n|---:|---:|---:|---:|---:|\n");
    for (int d = 0; d < ND; ++d) {
        fprintf(f, "| %.4e | %.4f |", delta[d], rwc_mean[d]);
        for (int k = 0; k < NK; ++k)
            fprintf(f, " %.4f |", height[d][k]);
        fprintf(f, "\n");
    }
    fprintf(f, "\nChecks: more delta lower %s; kappa direction from the sign of theta/V - chi0 %s; solves %.3f s %s.\n",
            ok_delta ? "(pass)" : "(**FAIL**)", ok_kappa ? "(pass)" : "(**FAIL**)", secs,
            ok_time ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    for (int d = 0; d < ND; ++d) {
        for (int k = 0; k < NK; ++k)
            free(head[d][k]), free(tail[d][k]);
        free(rwc[d]);
    }
    phc_rod_free(rod);
    free(theta), free(E);
    phc_plant_graph_free(g);
    int fail = !(ok_delta && ok_kappa && ok_time);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
