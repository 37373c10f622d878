/* Rhizomorph (Li et al., ACM TOG 2023) §8.2.1: the root:shoot ratio of a
 * growing plant against its basal diameter.  The simulated oak (growth
 * preset `oak`, model/growth.h, expected mode, physical uptake) grows for
 * 300 d in the pot soil of the example config
 * measurements/examples/root_shoot/quercus_rubra.yaml, built here with
 * model/soil.h directly: 10 x 10 x 10 voxels of 0.03 m, one layer c = 10,
 * p = 0.0015 m/h, w = 3 m^3/m^3, growth resistance 1, closed box (BLOCK on
 * every face), rain 1e-4 m/h all the time, soil step 1 h (sub-stepped),
 * the plant at the centre of the surface.  Three curves: the preset's
 * phi_rg and phi_rg = 0.3 and 0.9 (the root growth preference, eq. 12).
 *
 * Against it: the red oak (Quercus rubra) seedlings of Baltzer & Thomas
 * (2007), BAAD study Baltzer2007 (read with phc_baad_read), grown in a
 * greenhouse in high light (raw column Light = "L", filled circles) and low
 * light ("S", filled triangles); rows that measurements/baad.h flags as
 * suspicious are hollow and labelled with their data.csv line.  When the
 * real-data folder is absent only the model is drawn.
 *
 * Outputs into OUTPUT_DIR: rhizomorph_root_shoot_vs_diameter.png (log-log:
 * diameter in mm, root:shoot) and rhizomorph_root_shoot_vs_diameter.csv
 * (the model curves: phi_rg, age, diameter, root:shoot, daily).  Prints the
 * model's root:shoot at a few diameters per phi_rg and the data's median
 * root:shoot per diameter bin and light (suspicious rows left out).
 *
 * Usage: notebook_rhizomorph_root_shoot_vs_diameter OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "measurements/baad.h"
#include "model/growth.h"
#include "model/soil.h"

#include "notebook_plot.h"

#define NAME "rhizomorph_root_shoot_vs_diameter"
#define DAYS 300
#define NPHI 3
#define MAXROWS 1024

typedef struct curve {
    double phi;
    size_t m;                 /* states: day 0 .. DAYS */
    double age[DAYS + 1], d_mm[DAYS + 1], rs[DAYS + 1];
} curve;

/* Grows the preset oak with root preference phi in the example's pot. */
static int grow(double phi, curve *cv, phc_error *err)
{
    phc_growth_params gp;
    if (phc_growth_preset("oak", &gp, err))
        return -1;
    if (phi > 0)
        gp.phi_rg = phi;
    cv->phi = gp.phi_rg;
    phc_soil *s = phc_soil_new(10, 10, 10, 0.03);
    if (!s)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    s->params.dt = 1.0;
    s->params.max_substeps = 100;
    phc_soil_layer layer = {0.0, 10.0, 0.0015, 1.0, 3.0, -1.0, 0.0};
    phc_soil_rain rain = {0.0, 1.0e6, 1.0e-4, 0.0, 0.0, 0.0, 0.0, 0.0};
    if (phc_soil_set_layers(s, &layer, 1, err) || phc_soil_set_rain(s, &rain, 1, err) || phc_soil_check(s, err)) {
        phc_soil_free(s);
        return -1;
    }
    phc_soil_budget_reset(s);
    phc_growth_options o = phc_growth_options_default();
    o.base[0] = o.base[1] = 0.5 * 10 * 0.03;
    o.base[2] = 10 * 0.03;
    phc_growth *g = NULL;
    if (phc_growth_new(&gp, &o, s, &g, err)) {
        phc_soil_free(s);
        return -1;
    }
    phc_growth_summary sm;
    int rc = 0;
    cv->m = 0;
    for (int day = 0; day <= DAYS; ++day) {
        if (day > 0 && (rc = phc_growth_step(g, 1.0, err)))
            break;
        phc_growth_summarize(g, &sm);
        cv->age[cv->m] = sm.age;
        cv->d_mm[cv->m] = sm.basal_diameter * 1e3;
        cv->rs[cv->m] = sm.root_mass > 0 && sm.shoot_mass > 0 ? sm.root_shoot : NAN;
        cv->m++;
    }
    phc_growth_free(g);
    phc_soil_free(s);
    return rc;
}

/* root:shoot when the diameter first reaches d (linear in diameter between
 * daily states, as the root_shoot data set does); NAN if never. */
static double at_diameter(const curve *cv, double d)
{
    for (size_t i = 1; i < cv->m; ++i) {
        if (cv->d_mm[i] < d)
            continue;
        double d0 = cv->d_mm[i - 1], d1 = cv->d_mm[i];
        double w = d1 > d0 ? (d - d0) / (d1 - d0) : 1.0;
        if (w < 0)
            w = 0;
        double r0 = isfinite(cv->rs[i - 1]) ? cv->rs[i - 1] : cv->rs[i];
        return exp(log(r0) + w * (log(cv->rs[i]) - log(r0)));
    }
    return NAN;
}

typedef struct plant {
    double d_mm, rs, age_mo;
    int high;                 /* 1: Light = L, 0: S */
    int suspicious;
    size_t line;
} plant;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, size_t n)
{
    if (n == 0)
        return NAN;
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* log axis labels as plain numbers: 0.1, 1, 10 */
static void log_label(PLINT axis, PLFLT value, char *label, PLINT length, PLPointer data)
{
    (void)axis;
    (void)data;
    snprintf(label, (size_t)length, "%g", pow(10.0, value));
}

#define SYM_CIRCLE "\xe2\x97\x8f"   /* U+25CF filled circle */
#define SYM_TRIANGLE "\xe2\x96\xb2" /* U+25B2 filled triangle */
#define SYM_CIRCLE_O "\xe2\x97\x8b" /* U+25CB hollow circle */
#define SYM_TRIANGLE_O "\xe2\x96\xb3" /* U+25B3 hollow triangle */
#define SYM_SQUARE "\xe2\x96\xa0"     /* U+25A0 filled square */

static int plot(const char *path, const curve *cv, const plant *pl, size_t np, int have_data, const char *title)
{
    static const int line_col[NPHI] = {NB_BLACK, NB_GREEN, NB_PURPLE};
    static const PLINT line_sty[NPHI] = {1, 3, 2};
    const double xmin = 0.3, xmax = 30.0, ymin = 0.1, ymax = 20.0;
    char tmp[1040];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    PLINT old, strm;
    plgstrm(&old);
    plmkstrm(&strm);
    if (strm < 0)
        return -1;
    plsdev("pngcairo");
    plsfnam(tmp);
    plspage(0.0, 0.0, 1500, 850, 0, 0);
    nb_colours();
    plinit();
    pladv(0);
    plschr(0.0, NB_CHR);
    plvpor(0.075, 0.68, 0.10, 0.89);
    plwind(log10(xmin), log10(xmax), log10(ymin), log10(ymax));
    plcol0(NB_GRID);
    plwidth(1.0);
    plbox("ghl", 0, 0, "ghl", 0, 0);
    /* model curves */
    for (int k = 0; k < NPHI; ++k) {
        PLFLT x[DAYS + 1], y[DAYS + 1];
        PLINT m = 0;
        for (size_t i = 0; i < cv[k].m; ++i)
            if (cv[k].d_mm[i] > 0 && isfinite(cv[k].rs[i]) && cv[k].rs[i] > 0) {
                x[m] = log10(cv[k].d_mm[i]);
                y[m] = log10(fmin(fmax(cv[k].rs[i], 0.5 * ymin), 2 * ymax));
                ++m;
            }
        plcol0(line_col[k]);
        pllsty(line_sty[k]);
        plwidth(k == 0 ? 3.0 : 2.5);
        if (m > 1)
            plline(m, x, y);
        /* the end of the 300 d run */
        if (m > 0) {
            plschr(0.0, 0.6 * NB_CHR);
            plstring(1, &x[m - 1], &y[m - 1], SYM_SQUARE);
            plschr(0.0, NB_CHR);
        }
    }
    pllsty(1);
    /* data */
    for (size_t i = 0; i < np; ++i) {
        PLFLT x = log10(pl[i].d_mm), y = log10(pl[i].rs);
        plcol0(pl[i].high ? NB_ORANGE : NB_BLUE);
        const char *sym = pl[i].high ? (pl[i].suspicious ? SYM_CIRCLE_O : SYM_CIRCLE)
                                     : (pl[i].suspicious ? SYM_TRIANGLE_O : SYM_TRIANGLE);
        plschr(0.0, (pl[i].suspicious ? 1.1 : 0.75) * NB_CHR);
        plstring(1, &x, &y, sym);
        if (pl[i].suspicious) {
            /* two lines under the point, right-aligned at the frame for points near it */
            char lab[96];
            snprintf(lab, sizeof lab, "data.csv:%zu (%.4g mm, %g mo)", pl[i].line, pl[i].d_mm, pl[i].age_mo);
            plschr(0.0, 0.75 * NB_CHR);
            plcol0(NB_FG);
            double tx = fmin(x + 0.25, log10(xmax) - 0.015);
            plptex(tx, y - 0.09, 1.0, 0.0, 1.0, lab);
            plptex(tx, y - 0.16, 1.0, 0.0, 1.0, "flagged suspicious");
        }
        plschr(0.0, NB_CHR);
    }
    /* frame, labels */
    plcol0(NB_FG);
    plwidth(1.2);
    plslabelfunc(log_label, NULL);
    plbox("bcnstlo", 0, 0, "bcnstvlo", 0, 0);
    plslabelfunc(NULL, NULL);
    plmtex("b", 3.0, 0.5, 0.5, "basal stem diameter (mm)");
    plmtex("l", 4.2, 0.5, 0.5, "root:shoot ratio (root mass / shoot mass, g/g)");
    plschr(0.0, 1.05 * NB_CHR);
    plmtex("t", 2.6, 0.5, 0.5, "Root:shoot ratio against basal diameter (Rhizomorph \xc2\xa7" "8.2.1)");
    plschr(0.0, 0.85 * NB_CHR);
    plmtex("t", 1.0, 0.5, 0.5, title);
    plschr(0.0, NB_CHR);
    /* legend */
    enum { NL = NPHI + 6 };
    const char *lab[NL];
    char phil[NPHI][64];
    PLINT opt[NL], col[NL], sty[NL], tcol[NL], snum[NL];
    PLFLT wid[NL], ssc[NL];
    const char *sym[NL];
    int nl = 0;
    /* every marker as plotted: the same glyph, colour and size (pllegend
       sizes symbols by plschr(0, scale), so the scale is the plotted one) */
    for (int k = 0; k < NPHI; ++k) {
        snprintf(phil[k], sizeof phil[k], "model, #gf#dRG#u = %.2g%s", cv[k].phi, k == 0 ? " (oak preset)" : "");
        lab[nl] = phil[k], opt[nl] = PL_LEGEND_LINE | PL_LEGEND_SYMBOL, col[nl] = line_col[k],
        sty[nl] = line_sty[k], wid[nl] = k == 0 ? 3.0 : 2.5, sym[nl] = SYM_SQUARE, ssc[nl] = 0.6 * NB_CHR,
        snum[nl] = 1, ++nl;
    }
    lab[nl] = SYM_SQUARE " on a line: the model at 300 d", opt[nl] = PL_LEGEND_NONE, col[nl] = NB_FG,
    sty[nl] = 1, wid[nl] = 1, sym[nl] = "", ssc[nl] = 1, snum[nl] = 1, ++nl;
    if (have_data) {
        int flagged_high = 0, flagged_low = 0;
        for (size_t i = 0; i < np; ++i) {
            flagged_high |= pl[i].suspicious && pl[i].high;
            flagged_low |= pl[i].suspicious && !pl[i].high;
        }
        lab[nl] = "Q. rubra, high light (L)", opt[nl] = PL_LEGEND_SYMBOL, col[nl] = NB_ORANGE, sty[nl] = 1;
        wid[nl] = 1, sym[nl] = SYM_CIRCLE, ssc[nl] = 0.75 * NB_CHR, snum[nl] = 1, ++nl;
        lab[nl] = "Q. rubra, low light (S)", opt[nl] = PL_LEGEND_SYMBOL, col[nl] = NB_BLUE, sty[nl] = 1;
        wid[nl] = 1, sym[nl] = SYM_TRIANGLE, ssc[nl] = 0.75 * NB_CHR, snum[nl] = 1, ++nl;
        if (flagged_high) {
            lab[nl] = "high light, flagged suspicious", opt[nl] = PL_LEGEND_SYMBOL, col[nl] = NB_ORANGE;
            sty[nl] = 1, wid[nl] = 1, sym[nl] = SYM_CIRCLE_O, ssc[nl] = 1.1 * NB_CHR, snum[nl] = 1, ++nl;
        }
        if (flagged_low) {
            lab[nl] = "low light, flagged suspicious", opt[nl] = PL_LEGEND_SYMBOL, col[nl] = NB_BLUE;
            sty[nl] = 1, wid[nl] = 1, sym[nl] = SYM_TRIANGLE_O, ssc[nl] = 1.1 * NB_CHR, snum[nl] = 1, ++nl;
        }
    }
    for (int i = 0; i < nl; ++i)
        tcol[i] = NB_FG;
    PLINT zero[NL] = {0};
    PLFLT one[NL];
    for (int i = 0; i < NL; ++i)
        one[i] = 1.0;
    PLFLT lw, lh;
    pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.02, 0.0, 0.06,
             NB_BG, NB_FG, 1, 0, 0, nl, opt, 0.7, 0.7, 1.5, 0.0, tcol, lab, col, zero, one, one, col, sty, wid,
             col, ssc, snum, sym);
    plend1();
    plsstrm(old);
    if (rename(tmp, path) != 0) {
        unlink(tmp);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started)
        return started;
    clock_t c0 = clock();
    phc_error err;
    phc_error_clear(&err);

    /* ---- the model ---- */
    static curve cv[NPHI];
    const double phis[NPHI] = {0.0 /* the preset's */, 0.3, 0.9};
    for (int k = 0; k < NPHI; ++k)
        if (grow(phis[k], &cv[k], &err)) {
            fprintf(stderr, "growth (phi_rg %g): %s\n", phis[k], err.message);
            return 1;
        }
    printf("model: preset oak (phi_rg %.2g) in a 0.3 m pot (10x10x10 voxels of 0.03 m, c 10, p 0.0015 m/h, "
           "w 3, rain 1e-4 m/h), %d d\n",
           cv[0].phi, DAYS);
    for (int k = 0; k < NPHI; ++k)
        printf("  phi_rg %.2g: at %d d D = %.3f mm, root:shoot %.3f\n", cv[k].phi, DAYS, cv[k].d_mm[cv[k].m - 1],
               cv[k].rs[cv[k].m - 1]);

    /* ---- the data ---- */
    static plant pl[MAXROWS];
    size_t np = 0;
    int have_data = 0;
    const char *study_dir = PHC_SHARED_DATA "/baad/Baltzer2007";
    phc_baad_study *st = NULL;
    struct stat sb;
    if (stat(study_dir, &sb) != 0) {
        printf("data: %s is absent (the real-data folder ../shared/data is not here): drawing the model only\n",
               study_dir);
    } else if (phc_baad_read(study_dir, &st, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    } else {
        have_data = 1;
        size_t n_qr = 0, n_missing = 0;
        for (size_t i = 0; i < phc_baad_rows(st) && np < MAXROWS; ++i) {
            const phc_baad_row *r = phc_baad_row_at(st, i);
            if (!r->species || strcmp(r->species, "Quercus rubra"))
                continue;
            ++n_qr;
            const char *light = phc_baad_raw(st, i, "Light");
            if (!isfinite(r->d_ba) || !isfinite(r->root_shoot) || !light || (strcmp(light, "L") && strcmp(light, "S"))) {
                ++n_missing;
                continue;
            }
            plant *p = &pl[np++];
            p->d_mm = r->d_ba * 1e3;
            p->rs = r->root_shoot;
            p->age_mo = r->age * 12.0;
            p->high = !strcmp(light, "L");
            p->suspicious = r->flag != PHC_BAAD_OK;
            p->line = r->line;
            if (p->suspicious)
                printf("data: data.csv:%zu flagged (%s): %s\n", r->line,
                       r->flag == PHC_BAAD_SUSPICIOUS ? "suspicious" : "invalid",
                       r->flag_reason ? r->flag_reason : "");
        }
        size_t nh = 0, nflag = 0;
        for (size_t i = 0; i < np; ++i)
            nh += pl[i].high, nflag += pl[i].suspicious;
        printf("data: %s, Quercus rubra: %zu rows, %zu drawn (%zu high light, %zu low light, %zu flagged), %zu "
               "without a diameter or masses\n",
               phc_baad_name(st), n_qr, np, nh, np - nh, nflag, n_missing);
        phc_baad_free(st);
    }

    /* ---- tables ---- */
    static const double dq[] = {0.5, 1, 2, 3, 4, 5, 6, 8, 10, 15, 20};
    printf("\nmodel root:shoot when the stem reaches D ('-': not within %d d)\n%8s", DAYS, "D (mm)");
    for (int k = 0; k < NPHI; ++k)
        printf("   phi_rg=%-4.2g", cv[k].phi);
    printf("\n");
    for (size_t j = 0; j < sizeof dq / sizeof dq[0]; ++j) {
        printf("%8g", dq[j]);
        for (int k = 0; k < NPHI; ++k) {
            double v = at_diameter(&cv[k], dq[j]);
            if (isfinite(v))
                printf("   %11.3f", v);
            else
                printf("   %11s", "-");
        }
        printf("\n");
    }
    if (have_data) {
        static const double edges[] = {1.5, 2.5, 3.5, 4.5, 6.5, 30};
        const size_t nbins = sizeof edges / sizeof edges[0] - 1;
        printf("\ndata median root:shoot per diameter bin (flagged rows left out)\n%14s %18s %18s %18s\n",
               "D bin (mm)", "high light (L)", "low light (S)", "model phi_rg pre");
        for (size_t b = 0; b < nbins; ++b) {
            double vh[MAXROWS], vs[MAXROWS], dsum = 0;
            size_t nh = 0, ns = 0;
            for (size_t i = 0; i < np; ++i) {
                if (pl[i].suspicious || pl[i].d_mm < edges[b] || pl[i].d_mm >= edges[b + 1])
                    continue;
                if (pl[i].high)
                    vh[nh++] = pl[i].rs;
                else
                    vs[ns++] = pl[i].rs;
                dsum += pl[i].d_mm;
            }
            char a[32], c[32], m[32];
            snprintf(a, sizeof a, nh ? "%.3f (n=%zu)" : "- (n=0)", median(vh, nh), nh);
            snprintf(c, sizeof c, ns ? "%.3f (n=%zu)" : "- (n=0)", median(vs, ns), ns);
            double dmean = nh + ns ? dsum / (double)(nh + ns) : NAN;
            double mv = isfinite(dmean) ? at_diameter(&cv[0], dmean) : NAN;
            if (isfinite(mv))
                snprintf(m, sizeof m, "%.3f @%.2g mm", mv, dmean);
            else
                snprintf(m, sizeof m, "-");
            char bin[32];
            snprintf(bin, sizeof bin, "[%g, %g)", edges[b], edges[b + 1]);
            printf("%14s %18s %18s %18s\n", bin, a, c, m);
        }
        double vh[MAXROWS], vs[MAXROWS];
        size_t nh = 0, ns = 0;
        for (size_t i = 0; i < np; ++i)
            if (!pl[i].suspicious)
                (pl[i].high ? vh : vs)[pl[i].high ? nh++ : ns++] = pl[i].rs;
        printf("%14s %18.3f %18.3f\n", "all", median(vh, nh), median(vs, ns));
    }

    /* ---- outputs ---- */
    char csv[1024], csvtmp[1040], png[1024];
    snprintf(csv, sizeof csv, "%s/%s.csv", out, NAME);
    snprintf(csvtmp, sizeof csvtmp, "%s.tmp", csv);
    FILE *f = fopen(csvtmp, "w");
    if (!f) {
        fprintf(stderr, "%s: cannot write\n", csvtmp);
        return 1;
    }
    fprintf(f, "phi_rg,age_d,basal_diameter_mm,root_shoot\n");
    for (int k = 0; k < NPHI; ++k)
        for (size_t i = 0; i < cv[k].m; ++i)
            fprintf(f, "%.3g,%.6g,%.6g,%.6g\n", cv[k].phi, cv[k].age[i], cv[k].d_mm[i], cv[k].rs[i]);
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad || rename(csvtmp, csv) != 0) {
        fprintf(stderr, "%s: cannot write\n", csv);
        return 1;
    }
    snprintf(png, sizeof png, "%s/%s.png", out, NAME);
    char title[200];
    snprintf(title, sizeof title, "oak preset, 0.3 m pot, %d d%s", DAYS,
             have_data ? "; Q. rubra seedlings (Baltzer & Thomas 2007, BAAD)" : " (data absent: model only)");
    if (plot(png, cv, pl, np, have_data, title)) {
        fprintf(stderr, "%s: cannot write the plot\n", png);
        return 1;
    }
    printf("\nwrote %s\nwrote %s\nruntime: %.1f s\n", png, csv, (double)(clock() - c0) / CLOCKS_PER_SEC);
    return 0;
}
