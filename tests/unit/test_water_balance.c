/* Unit tests of a plant on a balance (model/water_balance.h): a loss that
 * changes between day and night and the pot's soil store.  Checked against
 * the time-invariant model of model/water.h, a closed form in the limit of
 * fast mixing, conservation, exact against BDF6, and every sensitivity
 * against central finite differences. */
#include "check.h"

#include <stdlib.h>

#include "model/plant_graph.h"
#include "model/water.h"
#include "model/water_balance.h"

static phc_water_system *make_system(const phc_plant_graph *g, phc_water_weights mode, double delta,
                                     double w0, double mu)
{
    phc_water_params p = phc_water_params_default();
    p.weights = mode;
    p.loss_rate = delta;
    p.initial_water = w0;
    p.viscosity = mu;
    phc_water_system *s = NULL;
    phc_error err;
    if (phc_water_system_new(g, &p, &s, &err)) {
        fprintf(stderr, "system: %s\n", err.message);
        exit(2);
    }
    return s;
}

/* Day 07:00-23:00 (g = 1), night g = f, over 3 days from t = 0 at 09:00. */
typedef struct schedule {
    double start[8], g[8], dg[8];
    phc_water_loss_pattern p;
} schedule;

static void make_schedule(schedule *sc, double f)
{
    const double h = 3600.0;
    /* 09:00 day, 23:00 night, 07:00 day, ... */
    double t = 0.0;
    for (int k = 0; k < 7; ++k) {
        int night = k % 2 == 1;
        sc->start[k] = t;
        sc->g[k] = night ? f : 1.0;
        sc->dg[k] = night ? 1.0 : 0.0;
        t += k == 0 ? 14 * h : (night ? 8 * h : 16 * h);
    }
    sc->p.n = 7;
    sc->p.start = sc->start;
    sc->p.g = sc->g;
    sc->p.n_coef = 1;
    sc->p.dg = sc->dg;
}

/* G(t) = integral of g from 0 to t. */
static double schedule_integral(const schedule *sc, double t)
{
    double G = 0.0;
    for (size_t k = 0; k < sc->p.n; ++k) {
        double a = sc->start[k], b = k + 1 < sc->p.n ? sc->start[k + 1] : INFINITY;
        if (t <= a)
            break;
        G += sc->g[k] * (fmin(t, b) - a);
    }
    return G;
}

static double curve1(const phc_water_system *s, const phc_water_pot *pot,
                     const phc_water_loss_pattern *loss, phc_water_method m, double t)
{
    double W = NAN;
    phc_error err;
    if (phc_water_balance_curve(s, pot, loss, 0.0, m, 0.0, &t, 1, &W, NULL, &err))
        fprintf(stderr, "curve: %s\n", err.message);
    return W;
}

int main(void)
{
    phc_error err;
    phc_plant_graph *tree = phc_plant_graph_random(30, 7);
    phc_plant_graph *leaf = phc_plant_graph_leaf_chain(40e-4, 20, 0.5e-3);
    CHECK(tree && leaf);
    const double day = 86400.0;

    /* 1. Without pot and with g = 1 it is the model of water.h (exact and
     *    BDF6, values and d/d delta, d/d W0, d/d mu). */
    {
        phc_water_system *s = make_system(tree, PHC_WATER_REFERENCE_2024, 2e-3, 8.0, 1e3);
        double t[4] = {0, 3e3, 1e4, 5e4}, W0[4], dW0[12], W[4], dW[4 * PHC_WB_COEF];
        CHECK(phc_water_system_total_curve(s, PHC_WATER_EXACT, 0, t, 4, W0, dW0, &err) == 0);
        for (int m = 0; m < 2; ++m) {
            phc_water_method meth = m ? PHC_WATER_BDF6 : PHC_WATER_EXACT;
            CHECK(phc_water_balance_curve(s, NULL, NULL, 0.0, meth, 20.0, t, 4, W, dW, &err) == 0);
            for (int i = 0; i < 4; ++i) {
                CHECK_NEAR(W[i], W0[i], 0, 1e-9);
                CHECK_NEAR(dW[i * PHC_WB_COEF + PHC_WB_DELTA], dW0[3 * i], 1e-9 * fabs(dW0[3]), 1e-7);
                CHECK_NEAR(dW[i * PHC_WB_COEF + PHC_WB_W0], dW0[3 * i + 1], 0, 1e-9);
                CHECK_NEAR(dW[i * PHC_WB_COEF + PHC_WB_MU], dW0[3 * i + 2], 1e-9 * fabs(dW0[11]), 1e-7);
            }
        }
        phc_water_system_free(s);
    }

    /* 2. Conservation: no loss, a pot and a schedule: W stays W0. */
    {
        phc_water_system *s = make_system(tree, PHC_WATER_REFERENCE_2024, 0.0, 8.0, 1e3);
        schedule sc;
        make_schedule(&sc, 0.1);
        phc_water_pot pot = {200.0, 0.05};
        for (int m = 0; m < 2; ++m)
            CHECK_NEAR(curve1(s, &pot, &sc.p, m ? PHC_WATER_BDF6 : PHC_WATER_EXACT, 2.5 * day), 8.0, 0,
                       1e-9);
        phc_water_system_free(s);
    }

    /* 3. Fast mixing (physical conductances, a pot joined by a large k):
     *    plant and soil keep one relative fill, so
     *    W(t) = W0 exp(-delta sum(A V) / (sum V + C) G(t)). */
    {
        const double delta = 3e-5, C = 50.0, W0 = 60.0;
        phc_water_system *s = make_system(leaf, PHC_WATER_POISEUILLE, delta, W0, 0.0);
        schedule sc;
        make_schedule(&sc, 0.15);
        phc_water_pot pot = {C, 1e3};
        const size_t n = phc_water_system_size(s);
        double *v = malloc(n * sizeof *v), av = 0, vs = 0;
        phc_water_system_volume(s, v);
        for (size_t i = 0; i < n; ++i) {
            double r = 100 * leaf->radius[i], h = 100 * leaf->length[i];
            vs += v[i];
            if (leaf->leaf[i])
                av += r * h * v[i];
        }
        free(v);
        double t[5] = {0.3 * day, 0.7 * day, 1.0 * day, 1.6 * day, 2.9 * day}, W[5];
        CHECK(phc_water_balance_curve(s, &pot, &sc.p, 0.0, PHC_WATER_BDF6, 60.0, t, 5, W, NULL, &err) == 0);
        for (int i = 0; i < 5; ++i)
            CHECK_NEAR(W[i], W0 * exp(-delta * av / (vs + C) * schedule_integral(&sc, t[i])), 0, 1e-6);
        /* the night is slower: over 8 h of night the plant loses less than over 8 h of day */
        double tn[2] = {14 * 3600.0, 22 * 3600.0}, td[2] = {30 * 3600.0, 38 * 3600.0}, Wn[2], Wd[2];
        CHECK(phc_water_balance_curve(s, &pot, &sc.p, 0.0, PHC_WATER_BDF6, 60.0, tn, 2, Wn, NULL, &err) == 0);
        CHECK(phc_water_balance_curve(s, &pot, &sc.p, 0.0, PHC_WATER_BDF6, 60.0, td, 2, Wd, NULL, &err) == 0);
        CHECK_NEAR(log(Wn[0] / Wn[1]) / log(Wd[0] / Wd[1]), 0.15, 0, 1e-5);
        phc_water_system_free(s);
    }

    /* 4. A pot with k = 0 keeps its water: W = soil share + plant alone. */
    {
        phc_water_system *s = make_system(tree, PHC_WATER_REFERENCE_2024, 2e-3, 8.0, 1e3);
        const size_t n = phc_water_system_size(s);
        double *v = malloc(n * sizeof *v), vs = 0;
        phc_water_system_volume(s, v);
        for (size_t i = 0; i < n; ++i)
            vs += v[i];
        free(v);
        const double C = 30.0, share = vs / (vs + C);
        phc_water_pot pot = {C, 0.0};
        phc_water_system *s2 = make_system(tree, PHC_WATER_REFERENCE_2024, 2e-3, 8.0 * share, 1e3);
        double t = 2e4, Wp = NAN;
        CHECK(phc_water_system_total_curve(s2, PHC_WATER_EXACT, 0, &t, 1, &Wp, NULL, &err) == 0);
        CHECK_NEAR(curve1(s, &pot, NULL, PHC_WATER_EXACT, t), 8.0 * (1 - share) + Wp, 0, 1e-10);
        phc_water_system_free(s);
        phc_water_system_free(s2);
    }

    /* 5. Exact against BDF6 and every sensitivity against central
     *    differences, with a pot and a day/night schedule, curve starting
     *    mid-interval. */
    {
        const double delta = 4e-3, W0 = 9.0, mu = 1e5, C = 120.0, k = 5e-4, f = 0.2;
        phc_water_system *s = make_system(tree, PHC_WATER_REFERENCE_2024, delta, W0, mu);
        schedule sc;
        make_schedule(&sc, f);
        phc_water_pot pot = {C, k};
        const double t0 = 0.2 * day;
        double t[6] = {t0, 0.4 * day, 0.65 * day, 1.0 * day, 1.3 * day, 2.0 * day};
        enum { NW = PHC_WB_COEF + 1 };
        double We[6], Wb[6], dWe[6 * NW], dWb[6 * NW];
        CHECK(phc_water_balance_curve(s, &pot, &sc.p, t0, PHC_WATER_EXACT, 0, t, 6, We, dWe, &err) == 0);
        CHECK(phc_water_balance_curve(s, &pot, &sc.p, t0, PHC_WATER_BDF6, 30.0, t, 6, Wb, dWb, &err) == 0);
        for (int i = 0; i < 6; ++i) {
            CHECK_NEAR(Wb[i], We[i], 0, 1e-9);
            for (int c = 0; c < NW; ++c)
                CHECK_NEAR(dWb[i * NW + c], dWe[i * NW + c], 1e-9 * fabs(dWe[5 * NW + c]) + 1e-14, 1e-6);
        }
        CHECK(We[5] < We[1] && We[1] < W0);
        /* central differences of the exact curve, Richardson-extrapolated
         * (steps 1% and 0.5%: W is accurate to ~1e-11 only, so smaller
         * steps drown in round-off) */
        for (int c = 0; c < NW; ++c) {
            double D[2][6];
            for (int q = 0; q < 2; ++q) {
                double Wpm[2][6], hstep = 0;
                for (int sgn = 0; sgn < 2; ++sgn) {
                    double dl = delta, w0 = W0, m = mu, cc = C, kk = k, ff = f;
                    double *val[NW] = {&dl, &w0, &m, &cc, &kk, &ff};
                    hstep = (q ? 0.5e-2 : 1e-2) * *val[c];
                    *val[c] += (sgn ? 1 : -1) * hstep;
                    phc_water_system *sp = make_system(tree, PHC_WATER_REFERENCE_2024, dl, w0, m);
                    schedule sp_sc;
                    make_schedule(&sp_sc, ff);
                    phc_water_pot pp = {cc, kk};
                    CHECK(phc_water_balance_curve(sp, &pp, &sp_sc.p, t0, PHC_WATER_EXACT, 0, t, 6,
                                                  Wpm[sgn], NULL, &err) == 0);
                    phc_water_system_free(sp);
                }
                for (int i = 0; i < 6; ++i)
                    D[q][i] = (Wpm[1][i] - Wpm[0][i]) / (2 * hstep);
            }
            for (int i = 0; i < 6; ++i)
                CHECK_NEAR(dWe[i * NW + c], (4 * D[1][i] - D[0][i]) / 3,
                           1e-6 * fabs(dWe[5 * NW + c]) + 1e-12, 1e-5);
        }
        phc_water_system_free(s);
    }

    /* 6. Bad arguments. */
    {
        phc_water_system *s = make_system(tree, PHC_WATER_REFERENCE_2024, 2e-3, 8.0, 1e3);
        double t = 10.0, W;
        phc_water_pot bad = {0.0, 1.0};
        CHECK(phc_water_balance_curve(s, &bad, NULL, 0.0, PHC_WATER_EXACT, 0, &t, 1, &W, NULL, &err) ==
              PHC_ERR_DOMAIN);
        CHECK_STR_CONTAINS(err.message, "capacity > 0");
        double st = 0.0, g = -1.0;
        phc_water_loss_pattern neg = {1, &st, &g, 0, NULL};
        CHECK(phc_water_balance_curve(s, NULL, &neg, 0.0, PHC_WATER_EXACT, 0, &t, 1, &W, NULL, &err) ==
              PHC_ERR_DOMAIN);
        CHECK(phc_water_balance_curve(s, NULL, NULL, 20.0, PHC_WATER_EXACT, 0, &t, 1, &W, NULL, &err) ==
              PHC_ERR_INVALID);
        phc_water_system_free(s);
    }

    phc_plant_graph_free(tree);
    phc_plant_graph_free(leaf);
    return check_finish("test_water_balance");
}
