/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 5: one plant
 * under three stiffness laws at the same gravity.
 *
 * The paper's setting: its Fig. 5 compares Young's moduli inversely
 * proportional to topological depth, proportional to radius, and from water
 * (eq. 9 on the segment's absolute water, in their cm/g units and stiffness
 * scale, quirks in model/segment_stiffness.h), and finds the water law the
 * most natural droop.
 *
 * Ours (wilting_shape.h for the common setting): plant000, the same rods and
 * gravity for all three laws, every law scaled so that the strongest
 * segment has E_base = 1e9 Pa:
 *   depth   E = 1e9 / (1 + d)         (d = joints from the root, up to 123)
 *   radius  E = 1e9 r / r_max
 *   water   E = 5e6 + 1e9 sigma(kappa (theta - chi0)) on the segment's
 *           ABSOLUTE water theta (g, the paper's reading), at t = 6 h of
 *           drying (delta chosen so that the plant holds 70% of its water
 *           then), chi0 = the median theta over the segments at that time and
 *           kappa = 4 / chi0: a segment with half the median water gets
 *           5e6 + 1e9 sigma(-2), one with twice the median 5e6 + 1e9 sigma(4).
 *           Relative water content would give every segment the same modulus
 *           here (theta/V is nearly uniform, printed), so Fig. 5's water panel
 *           uses the absolute law, as the paper does.
 * The water's mass is carried in all three (same loads).
 *
 * Prints per law: the modulus range, the drop of the highest tip, the mean
 * height change, and the mean drop of the deep segments (depth above the
 * median) and of the shallow ones, and the time of each static solve.
 * Checks (exit 1 when one fails):
 *   - every law converges and deep segments drop more than shallow ones
 *     (displacements add up outwards along the tree);
 *   - ordering argued from the laws: the depth law makes every deep segment
 *     soft, the main stem included (E <= 1e9/96 Pa beyond plant000's median
 *     depth 94), while the radius and water laws keep the thick stem stiff whatever
 *     its depth; so the law with the smallest median modulus over the deep
 *     segments droops the outer part most: largest mean drop of the deep
 *     segments and largest ratio of deep to shallow drop;
 *   - the static solves take <= 20 s in all.
 * Writes wilting_fig5_stiffness_laws.png (three panels, colour log10 E) and
 * wilting_fig5_stiffness_laws.md.
 *
 * Usage: notebook_wilting_fig5_stiffness_laws OUTPUT_DIR */
#include "wilting_shape.h"

#include "notebook_plot.h"

#define NLAW 3
#define E_BASE 1e9
#define T_DRY (6.0 * 3600.0)
#ifndef KAPPA_CHI0
#define KAPPA_CHI0 8.0 /* kappa chi0 */
#endif

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
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
    double *theta = malloc(2 * n * sizeof *theta), *rwc = malloc(n * sizeof *rwc), *tmp = malloc(n * sizeof *tmp);
    double *E[NLAW], *logE[NLAW], *head[NLAW], *tail[NLAW];
    for (int l = 0; l < NLAW; ++l) {
        E[l] = malloc(n * sizeof(double)), logE[l] = malloc(n * sizeof(double));
        head[l] = malloc(3 * n * sizeof(double)), tail[l] = malloc(3 * n * sizeof(double));
    }

    /* water after T_DRY */
    double delta = ws_delta_for(g, 0.7, T_DRY);
    phc_water_params wp = ws_water_params(g, delta);
    double times[2] = {0.0, T_DRY};
    if (ws_water(g, &wp, times, 2, theta, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const double *th = theta + n;
    double lo, hi, W = 0.0;
    ws_rwc(g, th, rwc, &lo, &hi);
    for (size_t i = 0; i < n; ++i)
        W += th[i];
    memcpy(tmp, th, n * sizeof *tmp);
    qsort(tmp, n, sizeof *tmp, cmp_double);
    double chi0 = tmp[n / 2];

    /* the three laws */
    if (phc_segment_stiffness_depth(g, E_BASE, E[0], NULL, &err) ||
        phc_segment_stiffness_radius(g, E_BASE, E[1], NULL, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    phc_segment_stiffness_params sp = ws_stiffness(KAPPA_CHI0 / chi0, chi0);
    sp.content = PHC_STIFFNESS_ABSOLUTE;
    sp.logistic.e_max = E_BASE;
    if (phc_segment_stiffness_water(g, &sp, th, E[2], NULL, NULL, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    static const char *name[NLAW] = {"depth: 1e9/(1+d)", "radius: 1e9 r/r_max", "water: eq. 9 on absolute water"};

    /* deep vs shallow: depth above / at most the median depth */
    for (size_t i = 0; i < n; ++i)
        tmp[i] = (double)g->depth[i];
    qsort(tmp, n, sizeof *tmp, cmp_double);
    double dmed = tmp[n / 2];

    phc_rod *rod = ws_rod(g, E[0], &err);
    if (!rod) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    size_t top = ws_highest(g);
    double secs[NLAW] = {0}, height[NLAW], tip_drop[NLAW], mean_dz[NLAW], deep_drop[NLAW], shallow_drop[NLAW];
    double emin[NLAW], emax[NLAW], e_deep_med[NLAW];
    int its[NLAW], ok_conv = 1;
    double total_secs = 0.0;
    for (int l = 0; l < NLAW; ++l) {
        phc_rod_reset(rod);
        if (ws_solve(rod, E[l], th, &secs[l], &its[l], &err) != PHC_OK) {
            printf("%s: static solve failed: %s\n", name[l], err.message);
            ok_conv = 0;
            continue;
        }
        total_secs += secs[l];
        height[l] = ws_shape(rod, head[l], tail[l]);
        tip_drop[l] = g->tail[3 * top + 2] - tail[l][3 * top + 2];
        mean_dz[l] = ws_mean_dz(g, tail[l]);
        double dd = 0, ds = 0;
        size_t nd = 0, ns = 0;
        emin[l] = INFINITY, emax[l] = 0;
        for (size_t i = 0; i < n; ++i) {
            double drop = g->tail[3 * i + 2] - tail[l][3 * i + 2];
            emin[l] = fmin(emin[l], E[l][i]), emax[l] = fmax(emax[l], E[l][i]);
            logE[l][i] = log10(E[l][i]);
            if ((double)g->depth[i] > dmed)
                dd += drop, ++nd;
            else
                ds += drop, ++ns;
        }
        deep_drop[l] = dd / (double)nd, shallow_drop[l] = ds / (double)ns;
        size_t m = 0;
        for (size_t i = 0; i < n; ++i)
            if ((double)g->depth[i] > dmed)
                tmp[m++] = E[l][i];
        qsort(tmp, m, sizeof *tmp, cmp_double);
        e_deep_med[l] = tmp[m / 2];
    }
    if (!ok_conv)
        return 1;

    printf("plant000: %zu segments, rest height %.4f m; water after %.0f h at delta = %.4e 1/(cm^2 s): %.4f g of "
           "%.4f g (theta/V %.6f .. %.6f, spread (max - min)/min %.1e)\n",
           n, g->tail[3 * top + 2], T_DRY / 3600.0, delta, W, wp.initial_water, lo, hi, (hi - lo) / lo);
    printf("water law: absolute water, chi0 = median theta = %.4e g, kappa = %g/chi0 = %.4e 1/g\n", chi0, KAPPA_CHI0, KAPPA_CHI0 / chi0);
    printf("deep segments: depth > %.0f (median depth)\n", dmed);
    printf("%-32s %10s %10s %13s %9s %12s %12s %12s %11s %8s %5s\n", "law", "E min (Pa)", "E max (Pa)",
           "med. E deep", "height", "tip drop", "mean dz", "deep drop", "shal. drop", "solve s", "its");
    int order_ok = 1, deep_ok = 1;
    int softest = 0, droopiest = 0, ratio_top = 0;
    for (int l = 0; l < NLAW; ++l) {
        printf("%-32s %10.3e %10.3e %13.4e %9.4f %12.4e %12.4e %12.4e %11.4e %8.3f %5d\n", name[l], emin[l], emax[l],
               e_deep_med[l], height[l], tip_drop[l], mean_dz[l], deep_drop[l], shallow_drop[l], secs[l], its[l]);
        deep_ok &= deep_drop[l] > shallow_drop[l];
        if (e_deep_med[l] < e_deep_med[softest])
            softest = l;
        if (deep_drop[l] > deep_drop[droopiest])
            droopiest = l;
        if (deep_drop[l] / shallow_drop[l] > deep_drop[ratio_top] / shallow_drop[ratio_top])
            ratio_top = l;
    }
    order_ok = softest == droopiest && softest == ratio_top;
    printf("deep segments drop more than shallow ones under every law: %s\n", deep_ok ? "yes" : "no");
    printf("smallest median E of the deep segments: %s; largest deep drop: %s; largest deep/shallow drop ratio: %s "
           "(%.3f); the same law: %s\n",
           name[softest], name[droopiest], name[ratio_top], deep_drop[ratio_top] / shallow_drop[ratio_top],
           order_ok ? "yes" : "no");
    printf("static solves: %.3f s in all (bound 20 s)\n", total_secs);
    int ok_time = total_secs <= 20.0;

    /* figure */
    phc_shape_panel pan[NLAW];
    char title[NLAW][128];
    for (int l = 0; l < NLAW; ++l) {
        snprintf(title[l], sizeof title[l], "%s: height %.1f cm", name[l], 100.0 * height[l]);
        pan[l] = (phc_shape_panel){n, head[l], tail[l], g->radius, logE[l], title[l], 0, NULL, NULL};
    }
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.title = "Wilting Fig. 5: three stiffness laws, plant000, same gravity";
    po.value_label = "log10 Young's modulus (Pa)";
    po.columns = NLAW;
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig5_stiffness_laws.png", out);
    if (phc_shape_plot(png, pan, NLAW, &po, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig5_stiffness_laws.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Wilting paper, Fig. 5: three stiffness laws\n\n"
            "plant000 under the same gravity with Young's moduli by depth (1e9/(1+d) Pa), by radius\n"
            "(1e9 r/r_max Pa) and from water (eq. 9 on the absolute water after 6 h of drying). See the header\n"
            "of `notebooks_c/wilting_fig5_stiffness_laws.c` for every setting.\n\n"
            "![three laws](wilting_fig5_stiffness_laws.png)\n\n"
            "| law | median E deep (Pa) | height (m) | tip drop (m) | mean dz (m) | deep drop (m) | shallow drop (m) |\n"
            "|---|---:|---:|---:|---:|---:|---:|\n");
    for (int l = 0; l < NLAW; ++l)
        fprintf(f, "| %s | %.3e | %.4f | %.4e | %.4e | %.4e | %.4e |\n", name[l], e_deep_med[l], height[l], tip_drop[l],
                mean_dz[l], deep_drop[l], shallow_drop[l]);
    fprintf(f, "\nChecks: deep segments drop more under every law %s; the softest outer part droops most %s; solves "
               "%.3f s %s.\n",
            deep_ok ? "(pass)" : "(**FAIL**)", order_ok ? "(pass)" : "(**FAIL**)", total_secs,
            ok_time ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    phc_rod_free(rod);
    for (int l = 0; l < NLAW; ++l)
        free(E[l]), free(logE[l]), free(head[l]), free(tail[l]);
    free(theta), free(rwc), free(tmp);
    phc_plant_graph_free(g);
    int fail = !(deep_ok && order_ok && ok_time);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
