/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 10: a cut stem.
 * The paper cuts (conductance 0) or damages (reduced conductance) an edge
 * of the plant graph and shows the part beyond it wilting on its own.
 *
 * Plant: plant002 of the authors' code, reference mode (PHC_WATER_REFERENCE,
 * loss 6e-3, initial water 8 g), BDF6 with h = 10 s (the exact evaluator's
 * error, about 1e-16 x stiffness x t, reaches 1e-6 here).  The main stem is cut
 * half way up (edge_factor 0 between that stem segment and its parent), or
 * damaged (factor 0.1); we follow the water above the cut and in the rest.
 * A second cut isolates the largest piece of the plant that holds no leaf.
 *
 * Checks (exit 1 when one fails): parts add up to the total in every run;
 * the isolated leafless piece keeps its water; with the cut, the water above
 * it equals that of the same subtree simulated as a plant of its own; the
 * damaged edge lies between intact and cut.
 *
 * Usage: notebook_wilting_fig10_cut_stem OUTPUT_DIR */
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

#define NT 201
#define T_END 5.0e4
#define H_BDF6 10.0 /* s; T_END / (NT - 1) = 250 s is a multiple */
#define NRUN 3 /* intact, damaged (0.1), cut (0); a 4th run isolates a leafless piece */

/* in_sub[i] = 1 for the segments of the subtree rooted at r */
static void mark_subtree(const phc_plant_graph *g, size_t r, unsigned char *in_sub)
{
    memset(in_sub, 0, g->n);
    in_sub[r] = 1;
    for (size_t k = 0; k < g->n; ++k) { /* parents before children */
        size_t i = g->order[k];
        if (g->parent[i] != PHC_PLANT_NO_PARENT && in_sub[g->parent[i]])
            in_sub[i] = 1;
    }
}

/* The subtree rooted at r as a plant of its own (finished), or NULL. */
static phc_plant_graph *subtree_graph(const phc_plant_graph *g, const unsigned char *in_sub, size_t r)
{
    size_t m = 0, *idx = malloc(g->n * sizeof *idx);
    for (size_t i = 0; i < g->n; ++i)
        idx[i] = in_sub[i] ? m++ : (size_t)-1;
    phc_plant_graph *s = phc_plant_graph_new(m);
    if (!s) {
        free(idx);
        return NULL;
    }
    for (size_t i = 0; i < g->n; ++i) {
        if (!in_sub[i])
            continue;
        size_t j = idx[i];
        s->parent[j] = i == r ? PHC_PLANT_NO_PARENT : idx[g->parent[i]];
        s->radius[j] = g->radius[i];
        s->length[j] = g->length[i];
        memcpy(s->head + 3 * j, g->head + 3 * i, 3 * sizeof(double));
        memcpy(s->tail + 3 * j, g->tail + 3 * i, 3 * sizeof(double));
        s->leaf[j] = g->leaf[i];
        s->source_id[j] = g->source_id[i];
    }
    free(idx);
    phc_error err;
    if (phc_plant_graph_finish(s, "subtree", &err) != PHC_OK) {
        phc_plant_graph_free(s);
        return NULL;
    }
    return s;
}

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

    /* leaf segments and stem segments in each subtree (children after parents) */
    size_t *leaves = calloc(n, sizeof *leaves), *size = calloc(n, sizeof *size);
    for (size_t k = n; k-- > 0;) {
        size_t i = g->order[k];
        leaves[i] += g->leaf[i];
        size[i] += 1;
        if (g->parent[i] != PHC_PLANT_NO_PARENT) {
            leaves[g->parent[i]] += leaves[i];
            size[g->parent[i]] += size[i];
        }
    }
    /* The main axis: from the root, always into the child with the largest
     * subtree (in these plants the stem runs on through the leaf-flagged
     * junction segments where leaflets attach); cut at its middle stem
     * segment. */
    size_t path[4096], len = 0, cur = g->root, stem_on_path = 0;
    for (;;) {
        path[len++] = cur;
        stem_on_path += !g->leaf[cur];
        size_t best = (size_t)-1;
        for (size_t c = g->child_start[cur]; c < g->child_start[cur + 1]; ++c) {
            size_t ch = g->child[c];
            if (best == (size_t)-1 || size[ch] > size[best])
                best = ch;
        }
        if (best == (size_t)-1 || len >= 4096)
            break;
        cur = best;
    }
    size_t cut = g->root;
    for (size_t j = 0, m = 0; j < len; ++j)
        if (!g->leaf[path[j]] && m++ == stem_on_path / 2) {
            cut = path[j];
            break;
        }
    /* None of the authors' plants has a subtree without leaf segments (every
     * stem tip carries a leaf), so the leafless piece is made: the largest
     * branch leaving the main axis below the cut, with its loss switched off
     * (no_loss mask: as if defoliated) and cut off. */
    unsigned char *above = malloc(n), *piece = malloc(n);
    mark_subtree(g, cut, above);
    size_t bare = (size_t)-1;
    for (size_t j = 0; j < len; ++j)
        for (size_t c = g->child_start[path[j]]; c < g->child_start[path[j] + 1]; ++c) {
            size_t ch = g->child[c];
            if ((j + 1 == len || ch != path[j + 1]) && !above[ch] && (bare == (size_t)-1 || size[ch] > size[bare]))
                bare = ch;
        }
    if (bare == (size_t)-1) {
        fprintf(stderr, "%s: no branch below the cut\n", plant);
        return 1;
    }
    mark_subtree(g, bare, piece);
    size_t above_n = size[cut], above_leaf = leaves[cut];

    static const double factor[NRUN] = {1.0, 0.1, 0.0};
    static const char *run_name[NRUN] = {"intact", "damaged (conductance \xc3\x97 0.1)", "cut"};
    static double t_h[NT], w_above[NRUN][NT], w_rest[NRUN][NT], w_total[NRUN][NT], w_piece[NT];
    double *ef = malloc(n * sizeof *ef), *theta = malloc(n * sizeof *theta);
    double worst_sum = 0.0, worst_piece = 0.0, piece0 = 0.0, piece_bdf = 0.0, piece_bound = 0.0;
    phc_water_params prm = phc_water_params_default();
    prm.weights = PHC_WATER_REFERENCE;
    prm.loss_rate = 6e-3;
    prm.initial_water = 8.0;
    for (int q = 0; q <= NRUN; ++q) {
        for (size_t i = 0; i < n; ++i)
            ef[i] = 1.0;
        if (q < NRUN)
            ef[cut] = factor[q];
        else
            ef[bare] = 0.0; /* the 4th run isolates the defoliated branch */
        prm.edge_factor = ef;
        prm.no_loss = q < NRUN ? NULL : piece;
        phc_water_system *s = NULL;
        phc_water_exact *e = NULL;
        phc_water_bdf6 *bs = NULL;
        if (phc_water_system_new(g, &prm, &s, &err) || phc_water_exact_new(s, PHC_WATER_EXACT_FULL, &e, &err) ||
            phc_water_bdf6_new(s, H_BDF6, 0, &bs, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        for (int k = 0; k < NT; ++k) {
            double t = T_END * k / (NT - 1);
            t_h[k] = t / 3600.0;
            /* the three runs by BDF6 (sample times are steps); the leafless
             * piece's run by the exact evaluator, checked against BDF6 below */
            if (q < NRUN ? (phc_water_bdf6_advance(bs, t, &err) != PHC_OK) :
                           (phc_water_exact_state(e, t, theta, &err) != PHC_OK)) {
                fprintf(stderr, "%s\n", err.message);
                return 1;
            }
            if (q < NRUN && k == 0) {
                phc_water_system_theta0(s, theta);
            } else if (q < NRUN) {
                if (fabs(phc_water_bdf6_time(bs) - t) > 1e-6) {
                    fprintf(stderr, "BDF6 sample at %g s is not a step\n", t);
                    return 1;
                }
                phc_water_bdf6_state(bs, theta, NULL);
            }
            double a = 0, rest = 0, tot = 0, pc = 0;
            for (size_t i = 0; i < n; ++i) {
                tot += theta[i];
                if (above[i])
                    a += theta[i];
                else
                    rest += theta[i];
                if (piece[i])
                    pc += theta[i];
            }
            worst_sum = fmax(worst_sum, fabs(a + rest - tot) / tot);
            if (q < NRUN) {
                w_above[q][k] = a, w_rest[q][k] = rest, w_total[q][k] = tot;
            } else {
                w_piece[k] = pc;
                if (k == 0)
                    piece0 = pc;
                worst_piece = fmax(worst_piece, fabs(pc - piece0) / piece0);
            }
        }
        /* BDF6 on the same system: the piece's water after T_END */
        if (q == NRUN) {
            phc_water_bdf6 *b = NULL;
            if (phc_water_bdf6_new(s, 10.0, 0, &b, &err) || phc_water_bdf6_advance(b, T_END, &err)) {
                fprintf(stderr, "%s\n", err.message);
                return 1;
            }
            phc_water_bdf6_state(b, theta, NULL);
            double pc = 0;
            for (size_t i = 0; i < n; ++i)
                pc += piece[i] ? theta[i] : 0.0;
            piece_bdf = fabs(pc - piece0) / piece0;
            piece_bound = 1e-15 * phc_water_system_stiffness(s) * T_END;
            phc_water_bdf6_free(b);
        }
        phc_water_bdf6_free(bs);
        phc_water_exact_free(e);
        phc_water_system_free(s);
    }
    prm.edge_factor = NULL;
    prm.no_loss = NULL;

    /* the part above the cut as a plant of its own, same initial water */
    phc_plant_graph *sub = subtree_graph(g, above, cut);
    if (!sub) {
        fprintf(stderr, "cannot build the subtree graph\n");
        return 1;
    }
    phc_water_params ps = prm;
    ps.initial_water = w_above[NRUN - 1][0];
    phc_water_system *ss = NULL;
    phc_water_bdf6 *es = NULL;
    if (phc_water_system_new(sub, &ps, &ss, &err) || phc_water_bdf6_new(ss, H_BDF6, 0, &es, &err) ||
        phc_water_bdf6_advance(es, T_END, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    double worst_sub = 0.0;
    for (int k = 0; k < NT; ++k) {
        double W;
        phc_water_bdf6_total(es, T_END * k / (NT - 1), &W, NULL, &err);
        worst_sub = fmax(worst_sub, fabs(W - w_above[NRUN - 1][k]) / W);
    }
    int between = 1;
    for (int k = 1; k < NT; ++k) {
        double lo = fmin(w_above[0][k], w_above[2][k]), hi = fmax(w_above[0][k], w_above[2][k]);
        between &= w_above[1][k] >= lo - 1e-9 && w_above[1][k] <= hi + 1e-9;
    }

    int K = NT - 1, mid = NT / 4;
    printf("plant002: cut between stem segment %ld (depth %zu; the main axis has %zu stem segments) and "
           "its parent: %zu segments above (%zu leaf), %zu below\n",
           g->source_id[cut], g->depth[cut], stem_on_path, above_n, above_leaf, n - above_n);
    printf("side branch cut off with its loss masked (4th run): segment %ld and %zu beyond it (%zu leaf segments "
           "masked), %.4f g\n", g->source_id[bare], size[bare] - 1, leaves[bare], piece0);
    printf("%-34s %12s %12s %12s %12s %12s\n", "run", "above @3.5h", "above @14h", "rest @3.5h",
           "rest @14h", "total @14h");
    for (int q = 0; q < NRUN; ++q)
        printf("%-34s %12.4f %12.4f %12.4f %12.4f %12.4f\n", run_name[q], w_above[q][mid], w_above[q][K],
               w_rest[q][mid], w_rest[q][K], w_total[q][K]);
    printf("max |above + rest - total| / total: %.2e\n", worst_sum);
    printf("cut branch without loss: max relative change, exact %.2e (bound 1e-15 * stiffness * t = %.1e), "
           "BDF6 h = 10 s %.2e\n", worst_piece, piece_bound, piece_bdf);
    printf("above the cut vs the subtree as its own plant: max relative difference %.2e\n", worst_sub);
    printf("damaged edge between intact and cut (above the cut): %s\n", between ? "yes" : "no");
    int ok_sum = worst_sum < 1e-12, ok_piece = worst_piece < piece_bound && piece_bdf < 1e-10, ok_sub = worst_sub < 1e-10;

    /* plot */
    static const int col[NRUN] = {NB_BLUE, NB_ORANGE, NB_RED};
    nb_series sa[NRUN + 1], sb[NRUN + 1];
    for (int q = 0; q < NRUN; ++q) {
        sa[q] = (nb_series){t_h, w_above[q], NT, run_name[q], col[q], q == 1, 0, 2.5};
        sb[q] = (nb_series){t_h, w_rest[q], NT, run_name[q], col[q], q == 1, 0, 2.5};
    }
    /* the leafless piece (its own run) in the panel of the side it lies on */
    nb_series piece_s = {t_h, w_piece, NT, "side branch, no loss, cut off (own run)", NB_GREY, 2, 0, 2.5};
    sa[NRUN] = sb[NRUN] = piece_s;
    char ta[96], tb[96];
    snprintf(ta, sizeof ta, "above the cut (%zu segments, %zu leaf)", above_n, above_leaf);
    snprintf(tb, sizeof tb, "the rest of the plant (%zu segments)", n - above_n);
    nb_panel pan[2] = {{ta, "time (h)", "water (g)", 0, 0.0, 1.15 * w_above[0][0], 1, sa, above[bare] ? NRUN + 1 : NRUN},
                       {tb, "time (h)", "water (g)", 0, 0.0, 1.35 * w_rest[0][0], 1, sb, above[bare] ? NRUN : NRUN + 1}};
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig10_cut_stem.png", out);
    if (nb_plot(png, 1400, 620, 2, 1, pan, 2) != 0) {
        fprintf(stderr, "%s: cannot write the plot\n", png);
        return 1;
    }

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig10_cut_stem.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Wilting paper, Fig. 10: a cut stem\n\n"
            "**The paper's figure** (Maggioli et al., SIGGRAPH Asia 2023, Fig. 10) cuts or damages a stem:\n"
            "the edge of the plant graph gets zero (cut) or reduced (damaged) conductance, and the part\n"
            "beyond it wilts while the rest of the plant stays turgid for longer.\n\n"
            "**What we computed.** `plant002` of the authors' code, reference mode (`PHC_WATER_REFERENCE`,\n"
            "loss rate 6e-3, initial water 8 g), BDF6 with h = 10 s. The main axis (the path from the root that\n"
            "always follows the largest subtree, %zu stem segments) is cut at its middle stem segment: `edge_factor` 0\n"
            "on the edge between segment %ld and its parent; %zu segments (%zu of them leaf) lie above. A\n"
            "damaged edge has factor 0.1. None of the four plants has a subtree without leaves (every stem\n"
            "tip carries a leaf), so for the leafless case a fourth run makes one: the largest branch leaving\n"
            "the main stem below the cut (segment %ld and the %zu segments beyond it, %zu of them leaf,\n"
            "%.4f g of water) is defoliated (its leaf segments masked with `no_loss`) and cut off.\n\n"
            "![water above the cut and in the rest](wilting_fig10_cut_stem.png)\n\n"
            "| run | above the cut at 3.5 h (g) | at 13.9 h (g) | rest at 3.5 h (g) | at 13.9 h (g) | whole plant at 13.9 h (g) |\n"
            "|---|---:|---:|---:|---:|---:|\n",
            stem_on_path, g->source_id[cut], above_n, above_leaf, g->source_id[bare], size[bare] - 1, leaves[bare],
            piece0);
    for (int q = 0; q < NRUN; ++q)
        fprintf(f, "| %s | %.4f | %.4f | %.4f | %.4f | %.4f |\n", run_name[q], w_above[q][mid], w_above[q][K],
                w_rest[q][mid], w_rest[q][K], w_total[q][K]);
    fprintf(f,
            "\n**What the model predicts, and what it cannot.** The model has no roots and no soil: the\n"
            "plant starts with its water and only loses it through the leaves. A cut therefore cannot make\n"
            "the part above it lose supply it never had; what it changes is *which reservoir feeds which\n"
            "leaves*. Intact, the whole plant drains as one reservoir: water flows across the edge towards\n"
            "whichever side loses faster for the water it holds. Cut, each side drains through its own leaves only: the side with more leaf\n"
            "area per volume of water empties faster, the other keeps its water longer. The total water of\n"
            "the plant changes only through that redistribution; a leafless piece cut off keeps its water\n"
            "for ever (it has nowhere to lose it), which is also what happens to a real cut stump without\n"
            "leaves in this model, though a real stump would dry through its bark and cut surface. A damaged\n"
            "edge gives curves between the two, here almost on the intact ones (above the cut at 13.9 h:\n"
            "%.4f g against %.4f g intact): a tenth of the reference mode's conductance still equalises\n"
            "the pressure across the edge far faster than the leaves lose water. Here the cut %s the part\n"
            "above it: at 13.9 h it holds\n"
            "%.4f g instead of %.4f g, while the rest holds %.4f g instead of %.4f g (the lowest leaf,\n"
            "the largest, sits below the cut and now drains the thick lower stem alone).\n"
            "What a real cut does and this model cannot show: the part\n"
            "below the cut still receives water from the roots (here it keeps only what it had), and the\n"
            "part above loses its supply entirely, so it wilts while the rest does not.\n\n",
            w_above[1][K], w_above[0][K], w_above[2][K] > w_above[0][K] ? "spares" : "dries", w_above[2][K],
            w_above[0][K], w_rest[2][K],
            w_rest[0][K]);
    fprintf(f,
            "**Checks** (the notebook fails when one does not hold):\n\n"
            "- above + rest = total in every run: %.1e (bound 1e-12) %s;\n"
            "- the cut-off branch without loss keeps its water: largest relative change %.1e with the exact\n"
            "  evaluator (bound 1e-15 × stiffness × t = %.1e, its documented accuracy), %.1e with BDF6 (bound\n"
            "  1e-10, rounding over 5000 steps) %s;\n"
            "- with the cut, the water above it equals that of the same subtree simulated as a plant of its\n"
            "  own with the same initial water (BDF6 both): %.1e (bound 1e-10) %s;\n"
            "- the damaged edge lies between intact and cut above the cut at every time %s.\n\n"
            "**How ours differs.** The paper shows the cut on its own plants, with the wilting shapes that\n"
            "the position-based dynamics draw; this notebook follows the water only, on a plant of the authors'\n"
            "code. The shape of a cut plant (water -> stiffness -> rods) is `wilting_fig10_cut_stem_shape`.\n",
            worst_sum, ok_sum ? "(pass)" : "(**FAIL**)", worst_piece, piece_bound, piece_bdf, ok_piece ? "(pass)" : "(**FAIL**)",
            worst_sub, ok_sub ? "(pass)" : "(**FAIL**)", between ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    phc_water_bdf6_free(es);
    phc_water_system_free(ss);
    phc_plant_graph_free(sub);
    phc_plant_graph_free(g);
    free(leaves), free(size), free(above), free(piece), free(ef), free(theta);
    int fail = !(ok_sum && ok_piece && ok_sub && between);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
