/* Rhizomorph (Li et al., ACM TOG 2023), Fig. 16: split-root.  The same
 * plant in soils that differ only in nutrients: low everywhere, high
 * everywhere, and split (one half high, the other low).  The paper shows
 * the roots proliferating on the nutrient-rich side at the expense of the
 * poor side.
 *
 * Two nutrient responses of model/growth.h act: eq. 24's root branching
 * factor (1 + nutrient_branching v) at each new root segment, and the
 * nutrient-weighted allocation of root vigor (nutrient_allocation = 1: a
 * root tip's weight in the propagation is its requirement times v, the
 * authors' code, TreeModel.cpp), so vigor flows to the tips in rich soil.
 *
 * Set-up: the oak preset, nutrient_branching 1 m^3/unit (the preset's),
 * nutrient_allocation 1, STOCHASTIC with seeds 1-6, grown 120 days in
 * 1-day steps, seeded at the centre of the surface.  Soil: a pot of 0.60 x
 * 0.60 x 0.50 m, 12 x 12 x 10 voxels of dx = 0.05 m, clay (phc_soil_preset:
 * c = 10, p = 0.0015 m/h; its slow flow keeps the nutrient split sharp:
 * the nutrients ride on the water flux), d = 0.25, w = 6 m^3/m^3 (fill
 * 0.6), 20 mm of rain in the first hour of every day (nutrient-free), all
 * faces BLOCK, the upwind gravity flux (soil.h).  Nutrients v (units/m^3)
 * set in s->v after the layers: LOW = 0.2, HIGH = 3.  Soil dt 1 h,
 * sub-stepped; one OpenMP thread (a tiny grid).
 *
 * The measure.  One plant's two halves differ by chance alone: in a pot
 * with the same nutrients everywhere a single plant's root length on its
 * left and right halves differs up to threefold, because a few laterals
 * and the wandering taproot carry most of it.  So every seed grows in both
 * mirror images of the split pot (rich on the left, rich on the right),
 * and the check pools the root length on the rich halves over all of them
 * against that on the poor halves: rich / poor >= 1.5 (exit 1 otherwise).
 * A root segment belongs to the half holding its centre.  The same split
 * pots with nutrient_allocation 0 (eq. 24 alone) and the uniform pots
 * (left / right, pooled: the chance asymmetry) are printed beside it.
 *
 * Output (OUTPUT_DIR): rhizomorph_fig16_split_root.png (four side views of
 * seed 3, x-z projection), rhizomorph_fig16_split_root.csv (per case, seed
 * and half: root length, tips, segments) and rhizomorph_fig16_split_root.md.
 *
 * Usage: notebook_rhizomorph_fig16_split_root OUTPUT_DIR */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fit/growth_outputs.h"
#include "model/growth.h"
#include "model/soil.h"

#include "notebook_plot.h"
#include "rhizomorph_pot.h"

#define NCASE 4 /* low, high, rich left, rich right */
#define NSEED 6
#define PLOT_SEED 3
#define DAYS 120
#define DX 0.05
#define NX 12
#define NY 12
#define NZ 10
#define W0 6.0          /* m^3/m^3, the same in every soil */
#define RAIN_DEPTH 0.02 /* m per day, in the first hour */
#define SOIL_D 0.25     /* growth resistance */
#define V_LOW 0.2
#define V_HIGH 3.0
#define ALLOCATION 1.0  /* nutrient_allocation */

enum { LOW = 0, HIGH = 1, RICH_LEFT = 2, RICH_RIGHT = 3 };
static const char *case_key[NCASE] = {"low", "high", "rich_left", "rich_right"};

typedef struct result {
    rz_pot pot;
    double half_len[2]; /* root length (m) with centre at x < centre [0] and >= [1] */
    size_t half_tips[2], half_seg[2];
} result;

/* Nutrients of case q: low, high, or high on one half and low on the other. */
static void set_nutrients(phc_soil *s, void *user)
{
    int q = *(const int *)user;
    for (size_t k = 0; k < NZ; ++k)
        for (size_t j = 0; j < NY; ++j)
            for (size_t i = 0; i < NX; ++i) {
                int left = i < NX / 2, rich = q == HIGH || (q == RICH_LEFT && left) || (q == RICH_RIGHT && !left);
                s->v[i + NX * (j + NY * k)] = rich ? V_HIGH : V_LOW;
            }
}

static int run_case(int q, uint64_t seed, double allocation, result *R, phc_error *err)
{
    memset(R, 0, sizeof *R);
    const rz_pot_setup u = {.nx = NX, .ny = NY, .nz = NZ, .dx = DX, .d = SOIL_D, .w0 = W0,
                            .rain_depth = RAIN_DEPTH, .days = DAYS, .seed = seed, .fields = set_nutrients,
                            .user = &q, .upwind = 1, .nutrient_allocation = allocation};
    int rc = rz_pot_run(&u, "clay", &R->pot, err);
    if (rc)
        return rc;
    const double centre = 0.5 * NX * DX;
    size_t n;
    const phc_growth_node *N = phc_growth_nodes(R->pot.g, &n);
    for (size_t i = 0; i < n; ++i) {
        const phc_growth_node *m = &N[i];
        if (m->length <= 0 || m->system != PHC_GROWTH_ROOT)
            continue;
        int hc = m->head[0] + 0.5 * m->length * m->dir[0] < centre ? 0 : 1;
        int ht = m->head[0] + m->length * m->dir[0] < centre ? 0 : 1;
        R->half_len[hc] += m->length;
        R->half_seg[hc]++;
        if (m->tip)
            R->half_tips[ht]++;
    }
    return 0;
}

/* The rich half of case q (0 left, 1 right; uniform pots: left). */
static int rich_half(int q) { return q == RICH_RIGHT ? 1 : 0; }

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started)
        return started;
    omp_set_num_threads(1);
    phc_error err;
    phc_error_clear(&err);
    static result R[NSEED][NCASE], R0[NSEED][2]; /* R0: split pots with nutrient_allocation 0 */
    double t0 = rz_now();
    for (int k = 0; k < NSEED; ++k) {
        for (int q = 0; q < NCASE; ++q)
            if (run_case(q, (uint64_t)(k + 1), ALLOCATION, &R[k][q], &err)) {
                fprintf(stderr, "%s, seed %d: %s\n", case_key[q], k + 1, err.message);
                return 1;
            }
        for (int m = 0; m < 2; ++m) {
            if (run_case(RICH_LEFT + m, (uint64_t)(k + 1), 0.0, &R0[k][m], &err)) {
                fprintf(stderr, "%s, seed %d, nutrient_allocation 0: %s\n", case_key[RICH_LEFT + m], k + 1,
                        err.message);
                return 1;
            }
            if (k + 1 != PLOT_SEED)
                rz_pot_free(&R0[k][m].pot);
        }
        if (k + 1 != PLOT_SEED)
            for (int q = 0; q < NCASE; ++q)
                rz_pot_free(&R[k][q].pot);
    }
    double seconds = rz_now() - t0;

    /* ---- the table ---- */
    printf("oak, STOCHASTIC seeds 1-%d, nutrient_branching 1 m^3/unit, nutrient_allocation %g, %d days; clay pot "
           "%.2f x %.2f x %.2f m, dx = %g m; w0 = %g m^3/m^3; v low %g, high %g units/m^3; upwind gravity flux\n",
           NSEED, ALLOCATION, DAYS, NX * DX, NY * DX, NZ * DX, DX, W0, V_LOW, V_HIGH);
    printf("%-10s %4s %8s %8s %8s %9s %6s | %10s %10s %9s %9s\n", "case", "seed", "root_g", "shoot_g", "depth_m",
           "length_m", "tips", "len_left", "len_right", "tips_left", "tips_right");
    double pool[NCASE][2] = {{0}}, pool0[2] = {0, 0}, min_shoot = INFINITY;
    for (int k = 0; k < NSEED; ++k) {
        for (int q = 0; q < NCASE; ++q) {
            const result *r = &R[k][q];
            printf("%-10s %4d %8.3g %8.3g %8.3f %9.4g %6zu | %10.4g %10.4g %9zu %9zu\n", case_key[q], k + 1,
                   r->pot.S.root_mass, r->pot.S.shoot_mass, r->pot.S.rooting_depth, r->pot.S.root_length,
                   r->pot.S.root_tips, r->half_len[0], r->half_len[1], r->half_tips[0], r->half_tips[1]);
            int h = rich_half(q);
            pool[q][0] += r->half_len[h];     /* rich (or left) */
            pool[q][1] += r->half_len[1 - h]; /* poor (or right) */
            min_shoot = fmin(min_shoot, r->pot.S.shoot_mass);
        }
        for (int m = 0; m < 2; ++m) {
            int h = rich_half(RICH_LEFT + m);
            pool0[0] += R0[k][m].half_len[h];
            pool0[1] += R0[k][m].half_len[1 - h];
        }
    }
    double rich = pool[RICH_LEFT][0] + pool[RICH_RIGHT][0], poor = pool[RICH_LEFT][1] + pool[RICH_RIGHT][1];
    double ratio = rich / poor, ratio0 = pool0[0] / pool0[1];
    double lr_low = pool[LOW][0] / pool[LOW][1], lr_high = pool[HIGH][0] / pool[HIGH][1];
    int ok = ratio >= 1.5;
    char checks[2048];
    snprintf(checks, sizeof checks,
             "split pots, both mirror images, %d seeds pooled: root length %.4g m on the rich halves, %.4g m on the "
             "poor halves\n"
             "check, roots proliferate on the rich side: rich / poor = %.3f >= 1.5: %s\n"
             "beside it: the same pots with nutrient_allocation 0 (eq. 24 alone) %.3f; uniform pots left / right "
             "(chance alone, pooled) low %.3f, high %.3f; smallest shoot %.3g g\n",
             NSEED, rich, poor, ratio, ok ? "PASS" : "FAIL", ratio0, lr_low, lr_high, min_shoot);
    printf("%s", checks);
    printf("growth of the %d plants with their soils: %.1f s\n", NSEED * (NCASE + 2), seconds);

    /* ---- CSV ---- */
    char csv[1024], csvtmp[1040];
    snprintf(csv, sizeof csv, "%s/rhizomorph_fig16_split_root.csv", out);
    snprintf(csvtmp, sizeof csvtmp, "%s.tmp", csv);
    FILE *f = fopen(csvtmp, "w");
    if (!f) {
        fprintf(stderr, "%s: cannot write\n", csvtmp);
        return 1;
    }
    fprintf(f, "case,nutrient_allocation,seed,half,nutrients_units_per_m3,days,root_length_m,root_tips,root_segments\n");
    for (int k = 0; k < NSEED; ++k)
        for (int q = 0; q < NCASE + 2; ++q)
            for (int h = 0; h < 2; ++h) {
                const result *r = q < NCASE ? &R[k][q] : &R0[k][q - NCASE];
                int c = q < NCASE ? q : RICH_LEFT + q - NCASE;
                int left = h == 0, rich = c == HIGH || (c == RICH_LEFT && left) || (c == RICH_RIGHT && !left);
                fprintf(f, "%s,%g,%d,%s,%g,%d,%.6g,%zu,%zu\n", case_key[c], q < NCASE ? ALLOCATION : 0.0, k + 1,
                        left ? "left" : "right", rich ? V_HIGH : V_LOW, DAYS, r->half_len[h], r->half_tips[h],
                        r->half_seg[h]);
            }
    if (nb_close_md(f, csv, csvtmp) != 0) {
        fprintf(stderr, "%s: cannot write\n", csv);
        return 1;
    }

    /* ---- PNG ---- */
    char png[1024];
    snprintf(png, sizeof png, "%s/rhizomorph_fig16_split_root.png", out);
    char title[NCASE][160];
    const char *titles[NCASE];
    const phc_growth *plants[NCASE];
    for (int q = 0; q < NCASE; ++q) {
        if (q < 2)
            snprintf(title[q], sizeof title[q], "%s: v = %g units/m^3", case_key[q], q == HIGH ? V_HIGH : V_LOW);
        else
            snprintf(title[q], sizeof title[q], "split: v = %g left | %g right", q == RICH_LEFT ? V_HIGH : V_LOW,
                     q == RICH_LEFT ? V_LOW : V_HIGH);
        titles[q] = title[q], plants[q] = R[PLOT_SEED - 1][q].pot.g;
    }
    int png_rc = phc_growth_plot_side(png, plants, titles, NCASE, NZ * DX, 0.0, NX * DX, &err);
    for (int q = 0; q < NCASE; ++q)
        rz_pot_free(&R[PLOT_SEED - 1][q].pot);
    for (int m = 0; m < 2; ++m)
        rz_pot_free(&R0[PLOT_SEED - 1][m].pot);
    if (png_rc != 0) {
        fprintf(stderr, "%s: cannot write the plot: %s\n", png, err.message);
        return 1;
    }

    /* ---- markdown ---- */
    char md[1024], mdtmp[1024];
    f = nb_open_md(out, "rhizomorph_fig16_split_root.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Rhizomorph, Fig. 16: split-root\n\n"
            "The oak preset (`model/growth.h`, nutrient_branching 1 m³/unit, nutrient_allocation %g), STOCHASTIC with\n"
            "seeds 1-%d, grown %d days in a clay pot of %.2f × %.2f × %.2f m (dx = %g m), w = %g m³/m³, daily rain,\n"
            "with nutrients v = %g (low) or %g (high) units/m³ everywhere, or high on one half and low on the other\n"
            "(both mirror images). The side views show seed %d.\n\n"
            "![side views](rhizomorph_fig16_split_root.png)\n\n"
            "| case | seed | root length (m) | root tips | left half (m) | right half (m) | tips left | tips right |\n"
            "|---|---:|---:|---:|---:|---:|---:|---:|\n",
            ALLOCATION, NSEED, DAYS, NX * DX, NY * DX, NZ * DX, DX, W0, V_LOW, V_HIGH, PLOT_SEED);
    for (int k = 0; k < NSEED; ++k)
        for (int q = 0; q < NCASE; ++q) {
            const result *r = &R[k][q];
            fprintf(f, "| %s | %d | %.4g | %zu | %.4g | %.4g | %zu | %zu |\n", case_key[q], k + 1, r->pot.S.root_length,
                    r->pot.S.root_tips, r->half_len[0], r->half_len[1], r->half_tips[0], r->half_tips[1]);
        }
    fprintf(f, "\n```\n%s```\n", checks);
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    printf("%s: %s\n", ok ? "ok" : "FAIL", png);
    return ok ? 0 : 1;
}
