/* Unit test of breaking under a bending stress (model/particles.h,
 * "Breaking under a bending stress": the beam pass's joint moment
 * M = κ|θ| read as σ = 4M/(πr³), Pa, and break_stress).  Every checked
 * number is printed.
 *
 *  1. A horizontal cantilever loaded quasi-statically (gravity ramped up,
 *     then held): σ at every joint against 4M/(πr³) with M the exact
 *     static moment of the links beyond it (Σ m g × lever arm from their
 *     current centres); the base carries the largest σ; with break_stress
 *     just below the base's σ the base link breaks, just above nothing.
 *  2. A shelf: the first links of a shoot pinned by anchors on a board,
 *     the rest overhanging its edge: the bending rule breaks at the edge,
 *     the group-stress rule on the same scene tears an anchored link.
 *  3. break_stress 0 gives the same numbers bit for bit as a value no
 *     joint reaches; 1 and 2 threads the same breaks and numbers.
 *  4. Bad options (negative, NaN, with the own-weight pass, with
 *     break_threshold) are refused naming the option. */
#include "model/particles.h"
#include "model/plant_graph.h"
#include "model/quaternion.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static const double PI = 3.14159265358979323846;
/* the scenes' links (m), gravity (m s^-2), step (s), and the load: gravity
   ramped from 0 over RAMP steps, then held for HOLD */
static const double ELL = 0.02, R = 0.002, G = 9.81, DT = 0.002;
enum { RAMP = 3000, HOLD = 2000 };

/* One clamped segment from the origin along +x of length ell, radius r
 * (a finished graph; NULL on failure). */
static phc_plant_graph *clamp_graph(double ell, double r)
{
    phc_plant_graph *g = phc_plant_graph_new(1);
    if (!g)
        return NULL;
    g->tail[0] = ell;
    g->radius[0] = r;
    g->length[0] = ell;
    g->parent[0] = PHC_PLANT_NO_PARENT;
    g->fixed[0] = 1;
    phc_error err;
    if (phc_plant_graph_finish(g, "clamp", &err)) {
        fprintf(stderr, "%s\n", err.message);
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

/* The clamped segment, then n links continuing it (each the next's
 * parent). */
static phc_particles *cantilever(size_t n, double ell, double r, const phc_particles_options *o)
{
    phc_plant_graph *g = clamp_graph(ell, r);
    if (!g)
        return NULL;
    phc_error err;
    phc_particles *p = phc_particles_new(g, o, &err);
    phc_plant_graph_free(g);
    for (size_t k = 1; p && k <= n; ++k) {
        const double h[3] = {ell * (double)k, 0, 0}, t[3] = {ell * (double)(k + 1), 0, 0};
        if (phc_particles_append(p, k - 1, h, t, r, NULL, &err)) {
            phc_particles_free(p);
            p = NULL;
        }
    }
    if (!p)
        fprintf(stderr, "%s\n", err.message);
    return p;
}

static phc_particles_options beam_options(double e_half, double s, double damping, double break_stress)
{
    phc_particles_options o = phc_particles_options_default();
    o.follow_parent = 1;
    o.bending = PHC_PARTICLES_BEAM;
    o.beam_modulus = e_half;
    o.stiffness = s;
    o.damping = damping;
    o.break_stress = break_stress;
    return o;
}

/* The head joint of particle i (m): its centre minus R(q)(0, 0, L/2). */
static void head_of(const phc_particles *p, size_t i, double half, double J[3])
{
    double x[3], q[4], R[9];
    phc_particles_position(p, i, x);
    phc_particles_orientation(p, i, q);
    phc_quat_to_matrix(q, R);
    for (int d = 0; d < 3; ++d)
        J[d] = x[d] - half * R[3 * d + 2];
}

/* |Σ_{j in subtree of k} m_j (x_j − J_k) × g| (N m): the static moment about
 * joint k of the links beyond it (a chain: j = k .. n−1). */
static double static_moment(const phc_particles *p, size_t k, double half, double g)
{
    double J[3], M[3] = {0, 0, 0};
    head_of(p, k, half, J);
    const double gv[3] = {0, 0, -g};
    for (size_t j = k; j < phc_particles_count(p); ++j) {
        double x[3];
        phc_particles_position(p, j, x);
        const double m = phc_particles_mass(p, j), a[3] = {x[0] - J[0], x[1] - J[1], x[2] - J[2]};
        M[0] += m * (a[1] * gv[2] - a[2] * gv[1]);
        M[1] += m * (a[2] * gv[0] - a[0] * gv[2]);
        M[2] += m * (a[0] * gv[1] - a[1] * gv[0]);
    }
    return sqrt(M[0] * M[0] + M[1] * M[1] + M[2] * M[2]);
}

/* Gravity ramped from 0 to G over RAMP steps of DT, then held for HOLD
 * steps; returns the steps done (stops at the first break), the
 * break's particle to *broken (NONE without) and the largest reported
 * max_bend_stress to *peak. */
static size_t ramp_load(phc_particles *p, size_t *broken, double *peak)
{
    const double g = G, dt = DT;
    const size_t ramp = RAMP, hold = HOLD;
    phc_error err;
    *broken = PHC_PARTICLES_NONE;
    *peak = 0;
    for (size_t st = 1; st <= ramp + hold; ++st) {
        const double f = st < ramp ? (double)st / (double)ramp : 1.0;
        const double gv[3] = {0, 0, -g * f};
        phc_particles_report rep;
        if (phc_particles_set_gravity(p, gv, &err) || phc_particles_step(p, dt, &rep, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 0;
        }
        *peak = fmax(*peak, rep.max_bend_stress);
        if (rep.broken) {
            *broken = rep.broken_particle;
            return st;
        }
    }
    return ramp + hold;
}

static void test_cantilever(void)
{
    const size_t n = 10, ramp = RAMP, hold = HOLD;
    const double ell = ELL, r = R, g = G, dt = DT;
    phc_particles_options o = beam_options(2e7, 0.5, 0.02, 0);
    phc_particles *p = cantilever(n, ell, r, &o);
    CHECK(p != NULL);
    if (!p)
        return;
    size_t broken;
    double peak;
    ramp_load(p, &broken, &peak);
    double worst = 0, sig[16], tip[3];
    phc_particles_position(p, n, tip);
    size_t top = 0;
    printf("beam break, cantilever: %zu links of %g m, r %g m, E %g Pa, clamped horizontal, gravity ramped over "
           "%zu steps of %g s and held %zu; tip z %.4f mm\n",
           n, ell, r, o.beam_modulus, ramp, dt, hold, 1e3 * tip[2]);
    for (size_t k = 1; k <= n; ++k) {
        sig[k] = phc_particles_bend_stress(p, k);
        const double M = static_moment(p, k, ell / 2, g), exact = 4 * M / (PI * r * r * r);
        const double rel = fabs(sig[k] / exact - 1);
        worst = fmax(worst, rel);
        if (sig[k] > sig[top] || top == 0)
            top = k;
        printf("  joint %2zu: sigma %.6e Pa, 4M/(pi r^3) %.6e Pa (M %.6e N m), |ratio - 1| %.2e\n", k, sig[k], exact,
               M, rel);
    }
    printf("beam break, cantilever: largest |sigma/exact - 1| %.2e; largest sigma at joint %zu\n", worst, top);
    CHECK(worst < 1e-6);
    CHECK(top == 1);
    CHECK(phc_particles_bend_stress(p, 0) == 0); /* the clamp: no joint */
    const double base = 4 * static_moment(p, 1, ell / 2, g) / (PI * r * r * r);
    phc_particles_free(p);
    /* just below the base's σ: the base link breaks; just above: none */
    for (int side = -1; side <= 1; side += 2) {
        const double thr = base * (1 + 0.01 * side);
        o = beam_options(2e7, 0.5, 0.02, thr);
        p = cantilever(n, ell, r, &o);
        CHECK(p != NULL);
        if (!p)
            return;
        const size_t steps = ramp_load(p, &broken, &peak);
        printf("beam break, cantilever: break_stress %.6e Pa (%s the base's sigma by 1%%): %s", thr,
               side < 0 ? "below" : "above", broken == PHC_PARTICLES_NONE ? "no break" : "break");
        if (broken != PHC_PARTICLES_NONE)
            printf(" at joint %zu in step %zu (gravity %.4f of g)", broken, steps,
                   steps < ramp ? (double)steps / (double)ramp : 1.0);
        printf("; largest sigma seen %.6e Pa (%.4f of the static base's)\n", peak, peak / base);
        if (side < 0) {
            CHECK(broken == 1);
            CHECK(phc_particles_parent(p, 1) == PHC_PARTICLES_NONE);
        } else {
            CHECK(broken == PHC_PARTICLES_NONE);
        }
        phc_particles_free(p);
    }
}

/* The shelf: a shoot of n links from a clamped seed along +x, links 1 ..
 * na pinned by anchors at their rest centres (strength 1, orientation
 * free) on a board, links na + 1 .. n over its edge; gravity ramped and
 * held as in the cantilever.  carry: anchors_carry_moment; bend: break
 * stress (Pa, 0 off); group: break threshold (0 off). */
static phc_particles *shelf(size_t n, size_t na, double ell, double r, int carry, double bend, double group)
{
    phc_particles_options o = beam_options(2e7, 0.5, 0.02, bend);
    o.anchors_carry_moment = carry;
    o.break_threshold = group;
    phc_particles *p = cantilever(n, ell, r, &o);
    phc_error err;
    for (size_t i = 1; p && i <= na; ++i) {
        double x[3];
        phc_particles_position(p, i, x);
        if (phc_particles_anchor(p, i, x, 1.0, 0, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_particles_free(p);
            return NULL;
        }
    }
    return p;
}

static void test_shelf(void)
{
    const size_t n = 16, na = 8;
    const double ell = ELL, r = R, g = G;
    /* the loads at rest, nothing breaking: default anchors and anchors
       that carry the moment */
    double sig[2][17], grp[2][17];
    size_t top[2] = {0, 0}, gtop[2] = {0, 0};
    for (int carry = 0; carry <= 1; ++carry) {
        phc_particles *p = shelf(n, na, ell, r, carry, 0, 0);
        CHECK(p != NULL);
        if (!p)
            return;
        size_t broken;
        double peak;
        ramp_load(p, &broken, &peak);
        double worst = 0;
        for (size_t k = 1; k <= n; ++k) {
            sig[carry][k] = phc_particles_bend_stress(p, k);
            grp[carry][k] = phc_particles_stress(p, k);
            if (sig[carry][k] > sig[carry][top[carry]] || top[carry] == 0)
                top[carry] = k;
            if (grp[carry][k] > grp[carry][gtop[carry]] || gtop[carry] == 0)
                gtop[carry] = k;
            if (carry && k > na) { /* the overhang: a cantilever clamped at the last anchor */
                const double exact = 4 * static_moment(p, k, ell / 2, g) / (PI * r * r * r);
                worst = fmax(worst, fabs(sig[carry][k] / exact - 1));
            }
        }
        double tip[3];
        phc_particles_position(p, n, tip);
        printf("beam break, shelf (%zu links of %g m, r %g m, links 1-%zu anchored on the board, the edge at joint "
               "%zu), anchors_carry_moment %d: tip z %.2f mm; largest sigma %.4e Pa at joint %zu (%s), edge joint "
               "%.4e Pa; largest group stress %.5f at group %zu (%s)\n",
               n, ell, r, na, na + 1, carry, 1e3 * tip[2], sig[carry][top[carry]], top[carry],
               top[carry] <= na ? "anchored" : "overhang", sig[carry][na + 1], grp[carry][gtop[carry]], gtop[carry],
               gtop[carry] <= na ? "anchored" : "overhang");
        if (carry) {
            printf("beam break, shelf: the overhang's sigma against 4M/(pi r^3) of its static moment: largest "
                   "|ratio - 1| %.2e\n",
                   worst);
            CHECK(worst < 1e-6);
            for (size_t k = 1; k <= na; ++k)
                CHECK(sig[1][k] == 0); /* the support carries the anchored stretch */
        }
        phc_particles_free(p);
    }
    CHECK(top[1] == na + 1);    /* held anchors: the edge carries the most */
    CHECK(gtop[0] <= na);       /* the group stress: an anchored group */
    /* the rules, each just below its largest value of the scene */
    struct {
        int carry;
        double bend, group;
        const char *what;
    } runs[] = {{1, 0.99 * sig[1][top[1]], 0, "bending stress, anchors carry the moment"},
                {0, 0.99 * sig[0][top[0]], 0, "bending stress, default anchors"},
                {0, 0, 0.99 * grp[0][gtop[0]], "group stress, default anchors"}};
    size_t at[3];
    for (int k = 0; k < 3; ++k) {
        phc_particles *p = shelf(n, na, ell, r, runs[k].carry, runs[k].bend, runs[k].group);
        CHECK(p != NULL);
        if (!p)
            return;
        double peak;
        const size_t steps = ramp_load(p, &at[k], &peak);
        printf("beam break, shelf: %s, %s %.4g: ", runs[k].what, runs[k].bend > 0 ? "break_stress (Pa)" : "break_threshold",
               runs[k].bend > 0 ? runs[k].bend : runs[k].group);
        if (at[k] == PHC_PARTICLES_NONE)
            printf("no break\n");
        else
            printf("broke link %zu-%zu (%s) in step %zu\n", at[k], at[k] - 1,
                   at[k] <= na ? "anchored" : at[k] == na + 1 ? "at the edge" : "in the overhang", steps);
        phc_particles_free(p);
    }
    CHECK(at[0] == na + 1);                        /* the edge */
    CHECK(at[1] != PHC_PARTICLES_NONE && at[1] <= na); /* tears the anchored stretch */
    CHECK(at[2] != PHC_PARTICLES_NONE && at[2] <= na); /* tears the anchored stretch */
}

/* A comb of 64 stem links along +x from a clamped seed, each bearing a
 * side shoot of 16 links along +y (1089 particles: the threaded path),
 * stiffness rising with the age over 2 s (every kind of joint). */
static phc_particles *comb(double break_stress)
{
    phc_particles_options o = beam_options(1e7, 0.5, 0.02, break_stress);
    o.maturity_age = 2;
    const double ell = 0.01, r = 0.002;
    phc_particles *p = cantilever(64, ell, r, &o);
    phc_error err;
    for (size_t k = 1; p && k <= 64; ++k) {
        size_t parent = k, idx;
        for (size_t j = 0; j < 16; ++j) {
            const double h[3] = {ell * ((double)k + 0.5), ell * (double)j, 0};
            const double t[3] = {h[0], h[1] + ell, 0};
            if (phc_particles_append(p, parent, h, t, 0.8 * r, &idx, &err)) {
                phc_particles_free(p);
                return NULL;
            }
            parent = idx;
        }
    }
    const size_t n = p ? phc_particles_count(p) : 0;
    for (size_t i = 0; i < n; ++i)
        if (phc_particles_set_age(p, i, 0.1 + 1.9 * (double)(i % 7) / 7, &err)) {
            phc_particles_free(p);
            return NULL;
        }
    return p;
}

/* 60 steps of 0.01 s: the state (7 numbers a particle) to st, the broken
 * particle of each step (NONE) to br; returns the breaks. */
static size_t comb_run(double break_stress, int threads, double **st, size_t *br, size_t *n)
{
    omp_set_num_threads(threads);
    phc_particles *p = comb(break_stress);
    CHECK(p != NULL);
    if (!p)
        return 0;
    *n = phc_particles_count(p);
    size_t breaks = 0;
    phc_error err;
    for (int k = 0; k < 60; ++k) {
        phc_particles_report rep;
        CHECK(phc_particles_step(p, 0.01, &rep, &err) == 0);
        br[k] = rep.broken ? rep.broken_particle : PHC_PARTICLES_NONE;
        breaks += rep.broken;
    }
    *st = malloc(7 * *n * sizeof(double));
    for (size_t i = 0; i < *n; ++i) {
        phc_particles_position(p, i, *st + 7 * i);
        phc_particles_orientation(p, i, *st + 7 * i + 3);
    }
    phc_particles_free(p);
    omp_set_num_threads(omp_get_num_procs());
    return breaks;
}

static void test_off_and_threads(void)
{
    double *off, *high, *one, *two;
    size_t b_off[60], b_high[60], b_one[60], b_two[60], n = 0;
    const size_t k_off = comb_run(0, 1, &off, b_off, &n), k_high = comb_run(1e30, 1, &high, b_high, &n);
    const int same_off = memcmp(off, high, 7 * n * sizeof(double)) == 0;
    printf("beam break, comb of %zu particles, 60 steps of 0.01 s: break_stress 0 (off) and 1e30 Pa (never "
           "reached): %zu and %zu breaks, the same numbers bit for bit: %s\n",
           n, k_off, k_high, same_off ? "yes" : "no");
    CHECK(k_off == 0 && k_high == 0);
    CHECK(same_off);
    const double thr = 2e5;
    const size_t k1 = comb_run(thr, 1, &one, b_one, &n), k2 = comb_run(thr, 2, &two, b_two, &n);
    const int same = memcmp(one, two, 7 * n * sizeof(double)) == 0 && memcmp(b_one, b_two, sizeof b_one) == 0;
    size_t first = 0;
    while (first < 59 && b_one[first] == PHC_PARTICLES_NONE)
        ++first;
    printf("beam break, comb, break_stress %g Pa: %zu breaks on 1 thread, %zu on 2 (the first in step %zu, particle "
           "%zu), the same breaks and numbers bit for bit: %s\n",
           thr, k1, k2, first + 1, b_one[first], same ? "yes" : "no");
    CHECK(n >= 1024);
    CHECK(k1 >= 2);
    CHECK(same);
    free(off);
    free(high);
    free(one);
    free(two);
}

static void test_bad_options(void)
{
    phc_plant_graph *g = clamp_graph(0.1, 0.01);
    CHECK(g != NULL);
    if (!g)
        return;
    phc_error err;
    struct {
        double bend, group;
        int beam, carry;
        const char *what, *says;
    } bad[] = {{-1, 0, 1, 0, "break_stress -1", "break stress must be >= 0"},
               {NAN, 0, 1, 0, "break_stress NaN", "break stress must be >= 0"},
               {INFINITY, 0, 1, 0, "break_stress inf", "break stress must be >= 0"},
               {1e6, 0, 0, 0, "break_stress with own_weight", "needs follow_parent with bending beam"},
               {1e6, 0.05, 1, 0, "break_stress with break_threshold", "set one"},
               {0, 0, 0, 1, "anchors_carry_moment with own_weight", "anchors carry moment needs"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        phc_particles_options o = beam_options(1e7, 0.5, 0.01, bad[k].bend);
        o.break_threshold = bad[k].group;
        o.anchors_carry_moment = bad[k].carry;
        if (!bad[k].beam)
            o.bending = PHC_PARTICLES_OWN_WEIGHT;
        phc_particles *p = phc_particles_new(g, &o, &err);
        CHECK(p == NULL);
        phc_particles_free(p);
        printf("beam break, bad options: %s: %s\n", bad[k].what, err.message);
        CHECK_STR_CONTAINS(err.message, bad[k].says);
    }
    phc_plant_graph_free(g);
}

int main(void)
{
    test_cantilever();
    test_shelf();
    test_off_and_threads();
    test_bad_options();
    return check_finish("test_particles_beam_break");
}
