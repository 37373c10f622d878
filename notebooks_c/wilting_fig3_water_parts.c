/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 3 in spirit:
 * the water held by the parts of a plant (stem, each leaf) over time.
 *
 * Plant: plant002 of the authors' code (300 segments, 263 of them leaf
 * venation), read as their code reads it.  Model: the reference mode
 * (PHC_WATER_REFERENCE: the authors' 2023 C++ code, loss rate 6e-3, initial
 * water 8 g), evaluated exactly (eigen-decomposition, phc_water_exact_state).
 * Parts: the stem (every non-leaf segment) and each leaf, a leaf being a
 * connected component of leaf segments, numbered by the height of its base.
 *
 * Checks (exit 1 when one fails): the parts add up to the total, the total
 * agrees with the W-only exact evaluator and with BDF6, the total decreases
 * strictly and no part ever gains water.
 *
 * Usage: notebook_wilting_fig3_water_parts OUTPUT_DIR */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <plplot.h>

#include "measurements/plant_io.h"
#include "model/water.h"

#include "notebook_plot.h"

#define NT 241          /* time samples */
#define T_END 5.0e4     /* s (about 14 h: the plant keeps ~1/8 of its water) */
#define MAX_PARTS 12

int main(int argc, char **argv)
{
    const char *plant = PHC_SHARED_DATA "/plants/plant002.txt";
    const char *out = NULL;
    int started = nb_begin(argc, argv, plant, &out);
    if (started)
        return started;
    phc_error err;
    phc_error_clear(&err);
    phc_plant_graph *g = NULL;
    if (phc_plant_io_read(plant, PHC_PLANT_FORMAT_PAPER, 0, &g, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    size_t n = g->n;

    /* Parts: 0 = stem; leaves are the connected components of leaf segments
     * (breadth-first order: a parent is labelled before its children). */
    int *part = malloc(n * sizeof *part);
    int ncomp = 0;
    double base_z[MAX_PARTS];
    for (size_t k = 0; k < n; ++k) {
        size_t i = g->order[k], p = g->parent[i];
        if (!g->leaf[i]) {
            part[i] = 0;
        } else if (p != PHC_PLANT_NO_PARENT && g->leaf[p]) {
            part[i] = part[p];
        } else {
            if (ncomp + 1 >= MAX_PARTS) {
                fprintf(stderr, "%s: more than %d leaves\n", plant, MAX_PARTS - 1);
                return 1;
            }
            part[i] = ++ncomp;
            base_z[ncomp] = g->head[3 * i + 2];
        }
    }
    /* number the leaves from the lowest base up */
    int rank[MAX_PARTS];
    rank[0] = 0;
    for (int a = 1; a <= ncomp; ++a) {
        rank[a] = 1;
        for (int b = 1; b <= ncomp; ++b)
            rank[a] += base_z[b] < base_z[a] || (base_z[b] == base_z[a] && b < a);
    }
    for (size_t i = 0; i < n; ++i)
        part[i] = rank[part[i]];
    int np = ncomp + 1;
    size_t segs[MAX_PARTS] = {0};
    for (size_t i = 0; i < n; ++i)
        ++segs[part[i]];

    phc_water_params prm = phc_water_params_default();
    prm.weights = PHC_WATER_REFERENCE;
    prm.loss_rate = 6e-3;
    prm.initial_water = 8.0;
    phc_water_system *s = NULL;
    phc_water_exact *full = NULL, *tot = NULL;
    phc_water_bdf6 *bdf = NULL;
    if (phc_water_system_new(g, &prm, &s, &err) || phc_water_exact_new(s, PHC_WATER_EXACT_FULL, &full, &err) ||
        phc_water_exact_new(s, PHC_WATER_EXACT_TOTAL_ONLY, &tot, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }

    static double t_h[NT], W[NT], Wexact[NT], water[MAX_PARTS][NT], frac[MAX_PARTS][NT];
    double *theta = malloc(n * sizeof *theta);
    double worst_sum = 0.0, worst_total = 0.0, worst_gain = 0.0;
    int total_monotone = 1;
    for (int k = 0; k < NT; ++k) {
        double t = T_END * k / (NT - 1);
        t_h[k] = t / 3600.0;
        if (phc_water_exact_state(full, t, theta, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        double sum = 0.0;
        for (int q = 0; q < np; ++q)
            water[q][k] = 0.0;
        for (size_t i = 0; i < n; ++i) {
            water[part[i]][k] += theta[i];
            sum += theta[i];
        }
        double parts = 0.0;
        for (int q = 0; q < np; ++q)
            parts += water[q][k];
        W[k] = sum;
        Wexact[k] = phc_water_exact_total(tot, t);
        worst_sum = fmax(worst_sum, fabs(parts - sum) / sum);
        worst_total = fmax(worst_total, fabs(sum - Wexact[k]) / Wexact[k]);
        if (k > 0) {
            total_monotone &= W[k] < W[k - 1];
            for (int q = 0; q < np; ++q)
                worst_gain = fmax(worst_gain, water[q][k] - water[q][k - 1]);
        }
    }
    for (int q = 0; q < np; ++q)
        for (int k = 0; k < NT; ++k)
            frac[q][k] = water[q][k] / water[q][0];

    /* BDF6 (accurate start, h = 10 s) against the exact per-part water at T_END. */
    double bdf_part[MAX_PARTS] = {0}, worst_bdf = 0.0;
    if (phc_water_bdf6_new(s, 10.0, 0, &bdf, &err) || phc_water_bdf6_advance(bdf, T_END, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    phc_water_bdf6_state(bdf, theta, NULL);
    for (size_t i = 0; i < n; ++i)
        bdf_part[part[i]] += theta[i];
    for (int q = 0; q < np; ++q)
        worst_bdf = fmax(worst_bdf, fabs(bdf_part[q] - water[q][NT - 1]) / water[q][NT - 1]);

    /* The physical default (Poiseuille in series, K = R T / M_w with T in
     * kelvin) at the same loss rate and initial water: BDF6, h = 50 s (the
     * exact evaluator would lose ~1e-16 * stiffness * t ~ 10%% there). */
    double phys_frac[MAX_PARTS] = {0}, phys_part0[MAX_PARTS] = {0}, phys_W = 0.0;
    {
        phc_water_params pp = phc_water_params_default();
        pp.loss_rate = prm.loss_rate;
        pp.initial_water = prm.initial_water;
        phc_water_system *sp = NULL;
        phc_water_bdf6 *bp = NULL;
        if (phc_water_system_new(g, &pp, &sp, &err) || phc_water_bdf6_new(sp, 50.0, 0, &bp, &err) ||
            phc_water_bdf6_advance(bp, T_END, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        phc_water_system_theta0(sp, theta);
        for (size_t i = 0; i < n; ++i)
            phys_part0[part[i]] += theta[i];
        phc_water_bdf6_state(bp, theta, NULL);
        for (size_t i = 0; i < n; ++i) {
            phys_frac[part[i]] += theta[i];
            phys_W += theta[i];
        }
        for (int q = 0; q < np; ++q)
            phys_frac[q] /= phys_part0[q];
        phc_water_bdf6_free(bp);
        phc_water_system_free(sp);
    }
    double rf_lo = INFINITY, rf_hi = -INFINITY, pf_lo = INFINITY, pf_hi = -INFINITY;
    for (int q = 0; q < np; ++q) {
        rf_lo = fmin(rf_lo, frac[q][NT - 1]), rf_hi = fmax(rf_hi, frac[q][NT - 1]);
        pf_lo = fmin(pf_lo, phys_frac[q]), pf_hi = fmax(pf_hi, phys_frac[q]);
    }
    /* how far any part's fraction strays from the whole plant's, and when:
     * on the plot's samples and on a fine grid over the first 20 minutes
     * (t = 0.1 s * 1.1^j), where the pressure settles; late_dev: the
     * largest deviation after the first hour */
    double dev = 0.0, dev_t = 0.0, late_dev = 0.0;
    int dev_q = 0;
    for (int k = 0; k < NT; ++k)
        for (int q = 0; q < np; ++q) {
            double d = fabs(frac[q][k] - W[k] / W[0]);
            if (d > dev)
                dev = d, dev_t = t_h[k] * 3600.0, dev_q = q;
            if (t_h[k] >= 1.0)
                late_dev = fmax(late_dev, d);
        }
    for (double t = 0.1; t < 1200.0; t *= 1.1) {
        double part_w[MAX_PARTS] = {0}, sum = 0.0;
        if (phc_water_exact_state(full, t, theta, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        for (size_t i = 0; i < n; ++i) {
            part_w[part[i]] += theta[i];
            sum += theta[i];
        }
        for (int q = 0; q < np; ++q) {
            double d = fabs(part_w[q] / water[q][0] - sum / W[0]);
            if (d > dev)
                dev = d, dev_t = t, dev_q = q;
        }
    }

    /* per-part numbers: water at 0 and T_END, half-life of each part */
    double half[MAX_PARTS];
    for (int q = 0; q < np; ++q) {
        half[q] = NAN;
        for (int k = 1; k < NT; ++k)
            if (frac[q][k] <= 0.5 && frac[q][k - 1] > 0.5) {
                double a = (frac[q][k - 1] - 0.5) / (frac[q][k - 1] - frac[q][k]);
                half[q] = t_h[k - 1] + a * (t_h[k] - t_h[k - 1]);
                break;
            }
    }
    char names[MAX_PARTS][48];
    snprintf(names[0], sizeof names[0], "stem (%zu segments)", segs[0]);
    for (int q = 1; q < np; ++q)
        snprintf(names[q], sizeof names[q], "leaf %d (%zu segments)", q, segs[q]);

    printf("plant002: %zu segments, stem and %d leaves; reference mode, loss 6e-3, W0 = 8 g\n", n, ncomp);
    printf("%-26s %10s %12s %14s\n", "part", "W(0) (g)", "W(14 h) (g)", "half-life (h)");
    for (int q = 0; q < np; ++q)
        printf("%-26s %10.4f %12.4f %14.2f\n", names[q], water[q][0], water[q][NT - 1], half[q]);
    printf("total: %.4f g -> %.4f g at t = %.0f s\n", W[0], W[NT - 1], T_END);
    printf("max |sum of parts - total| / total: %.2e\n", worst_sum);
    printf("max |FULL total - W-only exact| / W: %.2e\n", worst_total);
    printf("max per-part |BDF6 (h = 10 s) - exact| / exact at %.0f s: %.2e\n", T_END, worst_bdf);
    printf("largest gain of any part between samples: %.2e g\n", worst_gain);
    printf("fraction of initial water left at %.0f s: reference mode %.5f-%.5f across parts, "
           "physical default %.5f-%.5f (total %.4f g)\n", T_END, rf_lo, rf_hi, pf_lo, pf_hi, phys_W);
    printf("largest |part fraction - whole-plant fraction|: %.1e (%s, at %.0f s); after 1 h: %.1e\n", dev,
           dev_q ? names[dev_q] : "stem", dev_t, late_dev);

    /* Plot: water per part (g) and the fraction of each part's initial water. */
    static const int colours[MAX_PARTS] = {NB_BROWN, NB_GREEN, NB_BLUE, NB_ORANGE, NB_PURPLE, NB_RED,
                                           NB_CYAN, NB_PINK, NB_OLIVE, NB_GREY, NB_BLACK, NB_BLUE};
    nb_series sa[MAX_PARTS + 1], sb[MAX_PARTS];
    for (int q = 0; q < np; ++q) {
        sa[q] = (nb_series){t_h, water[q], NT, names[q], colours[q], 0, 0, 2.5};
        sb[q] = (nb_series){t_h, frac[q], NT, names[q], colours[q], 0, 0, 2.5};
    }
    sa[np] = (nb_series){t_h, W, NT, "whole plant", NB_BLACK, 1, 0, 2.0};
    nb_panel pa[2] = {
        {"plant002: water per part", "time (h)", "water (g)", 0, 0.0, 0.0, 1, sa, (size_t)np + 1},
        {"fraction of each part's initial water", "time (h)", "water / initial water (1)", 0, 0.0,
         1.05, 1, sb, (size_t)np}};
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig3_water_parts.png", out);
    if (nb_plot(png, 1400, 620, 2, 1, pa, 2) != 0) {
        fprintf(stderr, "%s: cannot write the plot\n", png);
        return 1;
    }

    int ok_sum = worst_sum < 1e-12, ok_total = worst_total < 1e-6, ok_bdf = worst_bdf < 1e-6;
    int ok_gain = worst_gain <= 1e-12 * prm.initial_water;

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig3_water_parts.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Wilting paper, Fig. 3: water in the parts of a plant\n\n"
            "**The paper's figure** (Maggioli et al., SIGGRAPH Asia 2023, Fig. 3) follows the water held by\n"
            "the parts of a plant while it dries: the leaves, which transpire, empty first; the stem, which\n"
            "loses nothing itself, empties only by feeding the leaves.\n\n"
            "**What we computed.** `plant002` of the authors' code (%zu segments: %zu stem and %d leaves, a\n"
            "leaf being a connected group of leaf segments, numbered from the lowest base up), in the\n"
            "**reference mode** (`PHC_WATER_REFERENCE`: the authors' 2023 code with their constants, loss\n"
            "rate 6e-3, initial water 8 g spread in proportion to segment volume), solved exactly\n"
            "(eigen-decomposition, `phc_water_exact_state`) at %d times over %.0f s (%.1f h).\n\n"
            "![water per part](wilting_fig3_water_parts.png)\n\n"
            "| part | segments | water at 0 (g) | water at %.1f h (g) | half-life (h) |\n|---|---:|---:|---:|---:|\n",
            n, segs[0], ncomp, NT, T_END, T_END / 3600.0, T_END / 3600.0);
    for (int q = 0; q < np; ++q)
        fprintf(f, "| %s | %zu | %.4f | %.4f | %.2f |\n", q ? names[q] : "stem", segs[q], water[q][0],
                water[q][NT - 1], half[q]);
    fprintf(f, "| whole plant | %zu | %.4f | %.4f | |\n\n", n, W[0], W[NT - 1]);
    fprintf(f,
            "**Checks** (the notebook fails when one does not hold):\n\n"
            "- the parts add up to the total: largest relative difference %.1e (bound 1e-12) %s;\n"
            "- the total of the full exact state agrees with the W-only exact evaluator: %.1e (bound 1e-6) %s;\n"
            "- BDF6 with h = 10 s (accurate start) gives the same water per part at %.0f s: %.1e (bound 1e-6) %s;\n"
            "- the total decreases strictly at every sample %s, and no part ever gains water (largest gain\n"
            "  between samples %.1e g) %s.\n\n",
            worst_sum, ok_sum ? "(pass)" : "(**FAIL**)", worst_total, ok_total ? "(pass)" : "(**FAIL**)",
            T_END, worst_bdf, ok_bdf ? "(pass)" : "(**FAIL**)", total_monotone ? "(pass)" : "(**FAIL**)",
            worst_gain, ok_gain ? "(pass)" : "(**FAIL**)");
    fprintf(f,
            "**What the curves say.** Every part decreases, and all parts empty at the same relative rate:\n"
            "at %.1f h they keep %.5f to %.5f of their initial water, so the curves of the right panel lie\n"
            "on top of each other. A part's fraction never differs from the whole plant's by more than\n"
            "%.1e (%s, at %.0f s): within the first minute the pressure settles into the small gradient\n"
            "that carries water from the stem to the transpiring leaves, and that offset stays (%.1e after\n"
            "the first hour). The reason is the reference constants: the authors' code multiplies by its\n"
            "pressure constant, diffusion is fast (S is stiff: its rates are bounded by %.2g 1/s) and the leaf loss\n"
            "slow, so the pressure stays nearly equal across the plant and it dries as one reservoir. In\n"
            "the physical default (`PHC_WATER_POISEUILLE`, pressure constant R T / M_w with T in kelvin)\n"
            "the same holds: with the same loss rate and initial water, BDF6 (h = 50 s) leaves %.5f to\n"
            "%.5f of each part's water at %.1f h (total %.4f g).\n\n",
            T_END / 3600.0, rf_lo, rf_hi, dev, dev_q ? names[dev_q] : "the stem", dev_t, late_dev,
            phc_water_system_stiffness(s), pf_lo, pf_hi, T_END / 3600.0, phys_W);
    fprintf(f,
            "**How ours differs.** The paper's figure is drawn for its own example plant and settings, which\n"
            "the paper does not give in full; we use a plant shipped with the authors' code and the constants\n"
            "of that code, so the comparison is in kind (every part decreasing, the leaves barely ahead of\n"
            "the stem), not number for number. Water here is what the model calls water: the proxy volume\n"
            "π r² h of every segment, scaled so the plant starts with 8 g; most of it sits in the stem\n"
            "(%.2f g of 8), whose segments are thicker. If the paper's figure shows leaves emptying well\n"
            "before the stem, that needs a much weaker stem-to-leaf conductance than these constants give.\n",
            water[0][0]);
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }

    phc_water_bdf6_free(bdf);
    phc_water_exact_free(full);
    phc_water_exact_free(tot);
    phc_water_system_free(s);
    phc_plant_graph_free(g);
    free(theta);
    free(part);
    int fail = !(ok_sum && ok_total && ok_bdf && total_monotone && ok_gain);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
