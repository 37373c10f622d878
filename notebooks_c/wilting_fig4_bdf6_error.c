/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 4: relative
 * error of BDF6 against the exact solution, for the four plants shipped with
 * the authors' code (300, 617, 711 and 1964 segments), 1000 steps at
 * h = 1, 10 and 100 s, in the reference setting (PHC_WATER_REFERENCE, loss
 * rate 6e-3, initial water 8 g).
 *
 * Truth: exp(tS) theta(0) by a contour integral with tree solves
 * (contour_total below; the same method reproduces the authors' matrix to
 * 1e-11 in tests/realdata/test_water_reference).  The library's eigenvalue
 * evaluators are not used as truth: these systems are stiff (fastest rate
 * 4.5e6 to 2.7e8 1/s) and their error, about 1e-16 x stiffness x t, reaches
 * 1e-6 here; the notebook reports it.  Two BDF6 runs per plant and step:
 *   - phytocal's (phc_water_bdf6: accurate start by extrapolated implicit
 *     Euler, DESIGN §5);
 *   - the authors' crude start, re-implemented here: the six history slots
 *     all hold theta(0) and BDF6 (paper eq. 8) runs from step 1.  The same
 *     S is rebuilt from the graph with the reference constants, and the
 *     re-implementation is checked against phc_water_bdf6 by seeding it with
 *     six of the library's states and comparing the next step.
 *
 * Checks (exit 1 when one fails): the re-implemented step matches the
 * library's to 1e-12; phytocal's BDF6 stays within 1e-6 of the exact total
 * on every plant, step size and step; the crude start is at least ten times
 * worse; the library's W-only exact evaluator agrees with the truth within
 * its documented accuracy (1e-9 + 1e-16 x stiffness x t).
 *
 * Usage: notebook_wilting_fig4_bdf6_error OUTPUT_DIR */
#include <complex.h>
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

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define NSTEP 1000
#define NPLANT 4
#define NH 3
#define LOSS 6e-3
#define W0 8.0
/* The authors' code itself (filthynobleman/plant-water-diffusion, 827aab6,
 * built and run on this machine): WaterModel::Evaluate at t = 10, 20, ...,
 * 1e4 s on plant000 (loss 6e-3, W0 8 g) gives W(1e4 s) = 7.2116695319 g
 * against the exact 7.2113032118 g: relative error 5.08e-5. */
#define AUTHORS_CRUDE_1E4 5.08e-5

/* ---- the authors' BDF6 with the crude start ------------------------------ */
/* S = R D^-1 - D_l in the reference constants of model/water.h
 * (PHC_WATER_REFERENCE), on the tree in breadth-first order. */
typedef struct crude {
    size_t n;
    size_t *perm, *par;   /* perm[k] = graph index of row k; par[k] row of its parent */
    double *w, *d, *ell;  /* edge weight to the parent, d = V / PC, leaf loss */
    double *l, *u, *ip;   /* factorisation of I - c S */
    double *ring;         /* 6 x n history */
    size_t steps;
} crude;

static const double beta[6] = {-10.0 / 147, 72.0 / 147, -225.0 / 147,
                               400.0 / 147, -450.0 / 147, 360.0 / 147};
#define ALPHA (60.0 / 147.0)

static crude *crude_new(const phc_plant_graph *g, double loss)
{
    size_t n = g->n;
    crude *c = calloc(1, sizeof *c);
    size_t *pos = malloc(n * sizeof *pos);
    double *gi = malloc(n * sizeof *gi);
    c->n = n;
    c->perm = malloc(n * sizeof *c->perm);
    c->par = calloc(n, sizeof *c->par);
    c->w = calloc(n, sizeof *c->w);
    c->d = malloc(n * sizeof *c->d);
    c->ell = malloc(n * sizeof *c->ell);
    c->l = calloc(n, sizeof *c->l);
    c->u = calloc(n, sizeof *c->u);
    c->ip = calloc(n, sizeof *c->ip);
    c->ring = calloc(6 * n, sizeof *c->ring);
    for (size_t k = 0; k < n; ++k) {
        size_t i = g->order[k];
        c->perm[k] = i;
        pos[i] = k;
        double r = 100.0 * g->radius[i], h = 100.0 * g->length[i];   /* m -> cm */
        double vol = M_PI * r * r * h;
        c->d[k] = vol / PHC_WATER_REFERENCE_PRESS_CONST;             /* S = PC R diag(V)^-1 */
        c->ell[k] = g->leaf[i] ? loss * r * h : 0.0;                 /* LossRate * Area */
        gi[k] = 1e6 * M_PI * r * r * r * r / (8.0 * 0.9 * h);        /* FlowRes */
    }
    for (size_t k = 1; k < n; ++k) {
        c->par[k] = pos[g->parent[c->perm[k]]];
        c->w[k] = 1.0 / (0.5 * (gi[k] + gi[c->par[k]]));
    }
    free(pos);
    free(gi);
    return c;
}

static void crude_free(crude *c)
{
    if (!c)
        return;
    free(c->perm), free(c->par), free(c->w), free(c->d), free(c->ell);
    free(c->l), free(c->u), free(c->ip), free(c->ring);
    free(c);
}

/* I - c S by elimination from the leaves of the tree; pivots from running
 * column sums (no cancellation), as in model/water.c. */
static void crude_factor(crude *c, double cc)
{
    size_t n = c->n;
    double *sig = c->ip;
    for (size_t k = 0; k < n; ++k)
        sig[k] = 1.0 + cc * c->ell[k];
    for (size_t k = n - 1; k >= 1; --k) {
        size_t p = c->par[k];
        double akp = cc * c->w[k] / c->d[p], apk = cc * c->w[k] / c->d[k];
        double piv = sig[k] + apk;
        c->l[k] = -apk / piv;
        c->u[k] = -akp;
        sig[p] += akp * sig[k] / piv;
        sig[k] = 1.0 / piv;
    }
    sig[0] = 1.0 / sig[0];
}

static void crude_solve(const crude *c, double *y)
{
    for (size_t k = c->n - 1; k >= 1; --k)
        y[c->par[k]] -= c->l[k] * y[k];
    y[0] *= c->ip[0];
    for (size_t k = 1; k < c->n; ++k)
        y[k] = (y[k] - c->u[k] * y[c->par[k]]) * c->ip[k];
}

/* Fills the history with x (graph order), as the authors' code does. */
static void crude_start(crude *c, const double *x, double h)
{
    for (int j = 0; j < 6; ++j)
        for (size_t k = 0; k < c->n; ++k)
            c->ring[j * c->n + k] = x[c->perm[k]];
    c->steps = 5; /* slot m % 6 holds x_m; x_0 .. x_5 all = x */
    crude_factor(c, ALPHA * h);
}

/* One BDF6 step; returns the new total. */
static double crude_step(crude *c)
{
    size_t n = c->n, cur = c->steps;
    double *out = c->ring + ((cur + 1) % 6) * n;
    const double *hs[6];
    for (int j = 0; j < 6; ++j)
        hs[j] = c->ring + ((cur + 1 + j) % 6) * n; /* x_{n-5} .. x_n */
    double tmp[6];
    for (size_t k = 0; k < n; ++k) {
        for (int j = 0; j < 6; ++j)
            tmp[j] = hs[j][k];
        double acc = 0.0;
        for (int j = 0; j < 6; ++j)
            acc += beta[j] * tmp[j];
        out[k] = acc;
    }
    crude_solve(c, out);
    c->steps = cur + 1;
    double W = 0.0;
    for (size_t k = 0; k < n; ++k)
        W += out[k];
    return W;
}

/* Seeds the history with six consecutive states (graph order) x_{m-5}..x_m. */
static void crude_seed(crude *c, double *const states[6], double h)
{
    for (int j = 0; j < 6; ++j)
        for (size_t k = 0; k < c->n; ++k)
            c->ring[j * c->n + k] = states[j][c->perm[k]];
    c->steps = 5;
    crude_factor(c, ALPHA * h);
}

/* ---- the truth: W(t) = 1^T exp(tS) theta(0) by a contour integral --------
 * exp(tS) v = (1/2 pi i) \int e^z (zI - tS)^-1 v dz on the parabola
 * z(u) = N (0.1309 - 0.1194 u^2 + 0.25 i u) (Weideman and Trefethen, Math.
 * Comp. 76, 2007), midpoint rule on 0 < u < 3 with N points and the mirror
 * image.  Each resolvent is a tree solve: with x = d y,
 * (z d + t ell d + t L) y = v, L the Laplacian of the edge weights,
 * eliminated from the leaves with the excess sigma_k = c_k + sum over
 * children of a sigma_c / (sigma_c + a): no cancellation however stiff S is,
 * so the result does not lose accuracy with stiffness x t as eigenvalues do
 * (tests/realdata/test_water_reference checks the same method against the
 * authors' code to 1e-11).  theta0 in row order. */
#define CONTOUR_N 24
static double contour_total(const crude *c, const double *theta0, double t, double complex *x,
                            double complex *sig, double complex *piv)
{
    size_t n = c->n;
    const int N = CONTOUR_N;
    const double h = 3.0 / N;
    double W = 0.0;
    for (int k = 0; k < N; ++k) {
        double u = (k + 0.5) * h;
        double complex z = N * (0.1309 - 0.1194 * u * u + 0.25 * I * u);
        double complex dz = N * (-0.2388 * u + 0.25 * I);
        for (size_t i = 0; i < n; ++i) {
            x[i] = theta0[i];
            sig[i] = (z + t * c->ell[i]) * c->d[i];
        }
        for (size_t i = n - 1; i >= 1; --i) {
            size_t p = c->par[i];
            double a = t * c->w[i];
            piv[i] = sig[i] + a;
            sig[p] += a * sig[i] / piv[i];
            x[p] += a / piv[i] * x[i];
        }
        x[0] /= sig[0];
        double complex sum = x[0] * c->d[0];
        for (size_t i = 1; i < n; ++i) {
            x[i] = (x[i] + t * c->w[i] * x[c->par[i]]) / piv[i];
            sum += x[i] * c->d[i];
        }
        W += 2.0 * creal(cexp(z) * dz * h / (2.0 * M_PI * I) * sum);
    }
    return W;
}

int main(int argc, char **argv)
{
    /* the four plants by size */
    static const char *names[NPLANT] = {"plant002", "plant001", "plant003", "plant000"};
    static const double hs[NH] = {1.0, 10.0, 100.0};
    char path[NPLANT][512];
    const char *out = NULL;
    for (int p = 0; p < NPLANT; ++p) {
        snprintf(path[p], sizeof path[p], "%s/plants/%s.txt", PHC_SHARED_DATA, names[p]);
        int started = nb_begin(argc, argv, path[p], &out);
        if (started)
            return started;
    }
    phc_error err;
    phc_error_clear(&err);

    static double step_idx[NSTEP], err_acc[NH][NPLANT][NSTEP], err_crude[NH][NPLANT][NSTEP];
    double max_acc[NH][NPLANT], max_crude[NH][NPLANT], end_crude[NH][NPLANT], end_acc[NH][NPLANT];
    double worst_seed = 0.0, crude_1e4 = NAN, stiff[NPLANT], bdf_vs_bdf = 0.0, bdf_vs_exact = 0.0;
    double lib_vs_truth[NPLANT], lib_vs_truth_ratio = 0.0, lib_1e5 = 0.0;
    size_t nseg[NPLANT];
    for (int k = 0; k < NSTEP; ++k)
        step_idx[k] = k + 1;

    for (int p = 0; p < NPLANT; ++p) {
        phc_plant_graph *g = NULL;
        if (phc_plant_io_read(path[p], PHC_PLANT_FORMAT_PAPER, 0, &g, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        nseg[p] = g->n;
        phc_water_params prm = phc_water_params_default();
        prm.weights = PHC_WATER_REFERENCE;
        prm.loss_rate = LOSS;
        prm.initial_water = W0;
        phc_water_system *s = NULL;
        phc_water_exact *e = NULL;
        if (phc_water_system_new(g, &prm, &s, &err) ||
            phc_water_exact_new(s, PHC_WATER_EXACT_TOTAL_ONLY, &e, &err)) {
            fprintf(stderr, "%s: %s\n", names[p], err.message);
            return 1;
        }
        stiff[p] = phc_water_system_stiffness(s);
        size_t n = g->n;
        double *theta0 = malloc(n * sizeof *theta0);
        double *hist[7];
        for (int j = 0; j < 7; ++j)
            hist[j] = malloc(n * sizeof **hist);
        phc_water_system_theta0(s, theta0);
        crude *c = crude_new(g, LOSS);
        double *th0row = malloc(n * sizeof *th0row);
        double complex *cx = malloc(n * sizeof *cx), *csig = malloc(n * sizeof *csig),
                       *cpiv = malloc(n * sizeof *cpiv);
        for (size_t k = 0; k < n; ++k)
            th0row[k] = theta0[c->perm[k]];
        lib_vs_truth[p] = 0.0;
        for (int q = 0; q < NH; ++q) {
            double h = hs[q];
            phc_water_bdf6 *b = NULL;
            if (phc_water_bdf6_new(s, h, 0, &b, &err) || phc_water_bdf6_advance(b, NSTEP * h, &err)) {
                fprintf(stderr, "%s: %s\n", names[p], err.message);
                return 1;
            }
            crude_start(c, theta0, h);
            max_acc[q][p] = max_crude[q][p] = 0.0;
            for (int k = 0; k < NSTEP; ++k) {
                double t = (k + 1) * h, Wb;
                double We = contour_total(c, th0row, t, cx, csig, cpiv);
                /* the library's W-only exact evaluator against the truth,
                 * relative to its documented accuracy 1e-16 x stiffness x t */
                double dl = fabs(phc_water_exact_total(e, t) - We) / We;
                lib_vs_truth[p] = fmax(lib_vs_truth[p], dl);
                lib_vs_truth_ratio = fmax(lib_vs_truth_ratio, dl / (1e-9 + 1e-16 * stiff[p] * t));
                phc_water_bdf6_total(b, t, &Wb, NULL, &err);
                double Wc = crude_step(c);
                err_acc[q][p][k] = fabs(Wb - We) / We;
                err_crude[q][p][k] = fabs(Wc - We) / We;
                max_acc[q][p] = fmax(max_acc[q][p], err_acc[q][p][k]);
                max_crude[q][p] = fmax(max_crude[q][p], err_crude[q][p][k]);
            }
            end_acc[q][p] = err_acc[q][p][NSTEP - 1];
            end_crude[q][p] = err_crude[q][p][NSTEP - 1];
            if (p == NPLANT - 1 && h == 10.0)
                crude_1e4 = end_crude[q][p];
            phc_water_bdf6_free(b);

            /* the re-implementation against the library: six library states
             * (steps 5..10) in, step 11 out */
            if (phc_water_bdf6_new(s, h, 0, &b, &err)) {
                fprintf(stderr, "%s: %s\n", names[p], err.message);
                return 1;
            }
            for (int j = 0; j < 7; ++j) {
                if (j > 0)
                    phc_water_bdf6_advance(b, (5 + j) * h, &err);
                phc_water_bdf6_state(b, hist[j], NULL);
            }
            crude_seed(c, hist, h);
            crude_step(c);
            const double *mine = c->ring + (c->steps % 6) * n;
            double dmax = 0.0, xmax = 0.0;
            for (size_t k = 0; k < n; ++k) {
                dmax = fmax(dmax, fabs(mine[k] - hist[6][c->perm[k]]));
                xmax = fmax(xmax, fabs(hist[6][c->perm[k]]));
            }
            worst_seed = fmax(worst_seed, dmax / xmax);
            phc_water_bdf6_free(b);
        }
        if (p == NPLANT - 1) {
            /* Whose error grows at h = 100 s: BDF6 at h = 10 s and h = 100 s
             * against each other and against the exact total, t <= 1e5 s. */
            phc_water_bdf6 *b10 = NULL, *b100 = NULL;
            if (phc_water_bdf6_new(s, 10.0, 0, &b10, &err) || phc_water_bdf6_advance(b10, 1e5, &err) ||
                phc_water_bdf6_new(s, 100.0, 0, &b100, &err) || phc_water_bdf6_advance(b100, 1e5, &err)) {
                fprintf(stderr, "%s: %s\n", names[p], err.message);
                return 1;
            }
            for (int k = 100; k <= 1000; ++k) {
                double t = 100.0 * k, W10, W100, We = contour_total(c, th0row, t, cx, csig, cpiv);
                phc_water_bdf6_total(b10, t, &W10, NULL, &err);
                phc_water_bdf6_total(b100, t, &W100, NULL, &err);
                bdf_vs_bdf = fmax(bdf_vs_bdf, fabs(W10 - W100) / W10);
                bdf_vs_exact = fmax(bdf_vs_exact, fabs(W10 - We) / W10);
                lib_1e5 = fmax(lib_1e5, fabs(phc_water_exact_total(e, t) - We) / We);
            }
            phc_water_bdf6_free(b10);
            phc_water_bdf6_free(b100);
        }
        crude_free(c);
        free(th0row), free(cx), free(csig), free(cpiv);
        for (int j = 0; j < 7; ++j)
            free(hist[j]);
        free(theta0);
        phc_water_exact_free(e);
        phc_water_system_free(s);
        phc_plant_graph_free(g);
    }

    printf("relative error of W(t) against the exact solution (contour integral), max over 1000 "
           "steps (value at step 1000)\n");
    printf("%-9s %6s %6s %24s %24s\n", "plant", "n", "h (s)", "phytocal BDF6", "crude start");
    int ok_acc = 1, ok_worse = 1;
    double acc_hi[NH] = {0}, ratio_lo = INFINITY, ratio_hi = 0.0, acc_end = 0.0;
    for (int p = 0; p < NPLANT; ++p)
        for (int q = 0; q < NH; ++q) {
            printf("%-9s %6zu %6.0f %11.2e (%9.2e) %11.2e (%9.2e)\n", names[p], nseg[p], hs[q],
                   max_acc[q][p], end_acc[q][p], max_crude[q][p], end_crude[q][p]);
            ok_acc &= max_acc[q][p] < 1e-6;
            ok_worse &= max_crude[q][p] > 10.0 * max_acc[q][p];
            acc_hi[q] = fmax(acc_hi[q], max_acc[q][p]);
            acc_end = fmax(acc_end, end_acc[q][p]);
            ratio_lo = fmin(ratio_lo, max_crude[q][p] / max_acc[q][p]);
            ratio_hi = fmax(ratio_hi, max_crude[q][p] / max_acc[q][p]);
        }
    printf("crude start, plant000, h = 10 s, t = 1e4 s: %.2e (the authors' code: %.2e)\n", crude_1e4,
           AUTHORS_CRUDE_1E4);
    printf("re-implemented BDF6 step vs phc_water_bdf6 (max relative, all runs): %.2e\n", worst_seed);
    printf("plant000, 1e4 s <= t <= 1e5 s: BDF6 h = 10 s vs h = 100 s %.2e; BDF6 h = 10 s vs exact %.2e\n",
           bdf_vs_bdf, bdf_vs_exact);
    printf("library W-only exact evaluator vs exact, max over the figure's times: plant002 %.1e, plant001 %.1e, "
           "plant003 %.1e, plant000 %.1e (plant000, 1e4 s <= t <= 1e5 s: %.1e); at most %.1e of its documented "
           "accuracy\n",
           lib_vs_truth[0], lib_vs_truth[1], lib_vs_truth[2], lib_vs_truth[3], lib_1e5, lib_vs_truth_ratio);
    int ok_seed = worst_seed < 1e-12, ok_lib = lib_vs_truth_ratio <= 1.0;

    /* Plot: one panel per step size, error against step index, log scale. */
    static const int col[NPLANT] = {NB_BLUE, NB_GREEN, NB_ORANGE, NB_RED};
    static char lab_p[NPLANT][64], titles[NH][64];
    nb_series ser[NH][2 * NPLANT + NPLANT + 2];
    nb_panel pan[NH];
    double lo = INFINITY, hi = 0.0;
    for (int q = 0; q < NH; ++q)
        for (int p = 0; p < NPLANT; ++p)
            for (int k = 0; k < NSTEP; ++k) {
                if (err_acc[q][p][k] > 0)
                    lo = fmin(lo, err_acc[q][p][k]);
                hi = fmax(hi, err_crude[q][p][k]);
            }
    lo = fmax(1e-16, pow(10.0, floor(log10(lo)) - 2.0)); /* room for the legend */
    hi = pow(10.0, ceil(log10(hi)) + 1.0);
    for (int p = 0; p < NPLANT; ++p)
        snprintf(lab_p[p], sizeof lab_p[p], "%s, %zu segments", names[p], nseg[p]);
    static const char *sup[NH] = {"10\xc2\xb3", "10\xe2\x81\xb4", "10\xe2\x81\xb5"};
    for (int q = 0; q < NH; ++q) {
        size_t m = 0;
        for (int p = 0; p < NPLANT; ++p) {
            ser[q][m++] = (nb_series){step_idx, err_crude[q][p], NSTEP, NULL, col[p], 1, 0, 2.0};
            ser[q][m++] = (nb_series){step_idx, err_acc[q][p], NSTEP, NULL, col[p], 0, 0, 1.6};
        }
        if (q == 0) { /* legend: colours = plants, line styles = starts */
            for (int p = 0; p < NPLANT; ++p)
                ser[q][m++] = (nb_series){NULL, NULL, 0, lab_p[p], col[p], 0, 0, 3.0};
            ser[q][m++] = (nb_series){NULL, NULL, 0, "crude start (authors')", NB_BLACK, 1, 0, 2.0};
            ser[q][m++] = (nb_series){NULL, NULL, 0, "accurate start (phytocal)", NB_BLACK, 0, 0, 1.6};
        }
        snprintf(titles[q], sizeof titles[q], "h = %.0f s, 1000 steps (t \xe2\x89\xa4 %s s)", hs[q],
                 sup[q]);
        pan[q] = (nb_panel){titles[q], "step", "relative error of W (1)", 1, lo, hi, q == 0 ? 5 : 0,
                            ser[q], m};
    }
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig4_bdf6_error.png", out);
    if (nb_plot(png, 1800, 640, 3, 1, pan, NH) != 0) {
        fprintf(stderr, "%s: cannot write the plot\n", png);
        return 1;
    }

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig4_bdf6_error.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Wilting paper, Fig. 4: accuracy of BDF6\n\n"
            "**The paper's figure** (Maggioli et al., SIGGRAPH Asia 2023, Fig. 4) plots the relative error of\n"
            "the water computed with BDF6 against the exact solution exp(St)θ(0) for plants of 300 to 2000\n"
            "segments over 1000 steps; the errors lie around 1e-3 to 1e-2 and grow with the number of steps.\n"
            "The paper does not say how BDF6 is started; the authors' code fills the six history slots with\n"
            "the initial state. Built and run here with that code's settings (h = 10 s), plant000 (1964\n"
            "segments) has a relative error of %.2e at t = 1e4 s.\n\n"
            "**What we computed.** The four plants of the authors' code (%zu, %zu, %zu and %zu segments) in\n"
            "the reference setting (`PHC_WATER_REFERENCE`, loss rate 6e-3, initial water 8 g), 1000 steps\n"
            "at h = 1, 10 and 100 s. The truth is exp(St)θ(0) by a contour integral (Weideman and\n"
            "Trefethen's parabola, 24 points, each a tree solve without cancellation), the method that\n"
            "reproduces the authors' matrix to 1e-11 in `tests/realdata/test_water_reference`.\n"
            "Solid lines: phytocal's BDF6 (`phc_water_bdf6`, accurate start by extrapolated implicit Euler).\n"
            "Dashed lines: the authors' crude start, re-implemented in this notebook on the same S (checked:\n"
            "seeded with six states of `phc_water_bdf6`, its next step agrees to %.1e).\n\n"
            "![relative error of BDF6](wilting_fig4_bdf6_error.png)\n\n"
            "| plant | segments | h (s) | accurate start: max | at step 1000 | crude start: max | at step 1000 |\n"
            "|---|---:|---:|---:|---:|---:|---:|\n",
            AUTHORS_CRUDE_1E4, nseg[0], nseg[1], nseg[2], nseg[3], worst_seed);
    for (int p = 0; p < NPLANT; ++p)
        for (int q = 0; q < NH; ++q)
            fprintf(f, "| %s | %zu | %.0f | %.2e | %.2e | %.2e | %.2e |\n", names[p], nseg[p], hs[q],
                    max_acc[q][p], end_acc[q][p], max_crude[q][p], end_crude[q][p]);
    fprintf(f,
            "\nCrude start on plant000 at h = 10 s, t = 1e4 s: **%.2e** (the authors' code: %.2e).\n\n"
            "**Checks** (the notebook fails when one does not hold): the re-implemented step agrees with\n"
            "the library's (%.1e, bound 1e-12) %s; phytocal's BDF6 stays within 1e-6 of the exact total on\n"
            "every plant, step size and step %s; the crude start is at least ten times worse everywhere %s;\n"
            "the library's W-only exact evaluator (`PHC_WATER_EXACT_TOTAL_ONLY`) agrees with the truth\n"
            "within its documented accuracy 1e-9 + 1e-16 × stiffness × t (at most %.1e of it) %s.\n\n",
            crude_1e4, AUTHORS_CRUDE_1E4, worst_seed, ok_seed ? "(pass)" : "(**FAIL**)",
            ok_acc ? "(pass)" : "(**FAIL**)", ok_worse ? "(pass)" : "(**FAIL**)", lib_vs_truth_ratio,
            ok_lib ? "(pass)" : "(**FAIL**)");
    fprintf(f,
            "**What the curves say.** The error of BDF6 comes almost entirely from its start. With the\n"
            "history filled with θ(0), the first step is an implicit Euler-like step with a wrong history;\n"
            "its error (proportional to h: %.1e, %.1e, %.1e on plant000 for h = 1, 10, 100 s) is carried\n"
            "along at nearly constant relative size, because the slow modes of S that hold it decay no\n"
            "faster than W itself. With an accurate start, BDF6's own truncation error is tiny at these\n"
            "steps: at most %.1e at h = 1 s, %.1e at h = 10 s and %.1e at h = 100 s over all plants,\n"
            "largest in the first steps (the fast transient of the first minutes is under-resolved) and at\n"
            "most %.1e at step 1000. On plant000 between 1e4 and 1e5 s, BDF6 at h = 10 s and at h = 100 s\n"
            "agree to %.1e and the former is within %.1e of the exact total. The library's eigenvalue-based\n"
            "W-only evaluator is off by up to %.1e there (%.1e on plant002), in line with its documented\n"
            "accuracy of about 1e-16 × stiffness × t (stiffness %.2g 1/s on plant000, %.2g on plant002):\n"
            "with the authors' constants these systems are stiff.\n\n",
            max_crude[0][NPLANT - 1], max_crude[1][NPLANT - 1], max_crude[2][NPLANT - 1], acc_hi[0], acc_hi[1],
            acc_hi[2], acc_end, bdf_vs_bdf, bdf_vs_exact, lib_1e5, lib_vs_truth[0], stiff[NPLANT - 1], stiff[0]);
    fprintf(f,
            "**How ours differs from the paper.** The paper shows 1e-3 to 1e-2, growing with the number of\n"
            "steps. Our crude-start curves reach 1e-3 only at h = 100 s on plant002 and plant003 and stay\n"
            "flat or fall slowly with the steps; the accurate start is %.1e to %.1e times better (largest\n"
            "errors compared). The paper does not state the plants' parameters, the step size or the\n"
            "reference solution of its figure, so the remaining gap cannot be traced; our crude start on\n"
            "plant000 at t = 1e4 s (%.2e) matches the %.2e of the authors' code run there, which shows the\n"
            "re-implementation (and the reference mode's matrix) is theirs.\n",
            ratio_lo, ratio_hi, crude_1e4, AUTHORS_CRUDE_1E4);
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    int fail = !(ok_seed && ok_acc && ok_worse && ok_lib);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
