/* A soft plant's static equilibrium (model/rod.h, issue 19): plant000
 * (../shared/data/plants/plant000.txt, 1964 segments; skipped when absent)
 * with every segment at E = 1e6 Pa flops over under its own weight.  From
 * rest, Newton and the load continuation stall on it (rotations of 20–170
 * rad proposed, line-search steps of 1e-3); phc_rod_solve_static then
 * falls back on pseudo-transient continuation (rod.c).  Checked:
 *   - the solve converges, to the statics' tolerance;
 *   - a fresh solve from the result needs no iteration (its residual,
 *     assembled anew, is within the tolerance) and every joint is closed
 *     (a child's head on its parent's tail);
 *   - the equilibrium is a stable rest state of the time-stepped dynamics:
 *     2% more mass moves the plant to a nearby equilibrium; with the mass
 *     back, the damped implicit dynamics (phc_rod_step, default direct
 *     scheme) run from there at rest settles back, and a static solve from
 *     where it settled lands on the first equilibrium again;
 *   - with too small an iteration budget the solve refuses, names both
 *     stages and keeps the state it started from. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "check.h"
#include "measurements/plant_io.h"
#include "model/plant_graph.h"
#include "model/rod.h"

#ifndef PHC_SHARED_DATA
#define PHC_SHARED_DATA "../shared/data"
#endif
#define PLANT000 PHC_SHARED_DATA "/plants/plant000.txt"
#define E_SOFT 1e6   /* Pa, every segment */
#define TOL 1e-10    /* the default scaled tolerance */
#define MORE_MASS 0.02
#define DAMPING 10.0 /* s⁻¹ */
#define DT 0.01      /* s */
#define T_END 4.0    /* s */

/* largest |tail_i − ref_i| over the segments, m */
static double tail_distance(const phc_rod *rod, const double *ref)
{
    double e = 0.0;
    for (size_t i = 0; i < phc_rod_segment_count(rod); ++i) {
        double t[3];
        phc_rod_tail(rod, i, t);
        e = fmax(e, sqrt((t[0] - ref[3 * i]) * (t[0] - ref[3 * i]) +
                         (t[1] - ref[3 * i + 1]) * (t[1] - ref[3 * i + 1]) +
                         (t[2] - ref[3 * i + 2]) * (t[2] - ref[3 * i + 2])));
    }
    return e;
}

static void tails(const phc_rod *rod, double *out)
{
    for (size_t i = 0; i < phc_rod_segment_count(rod); ++i)
        phc_rod_tail(rod, i, out + 3 * i);
}

int main(void)
{
    struct stat st;
    if (stat(PLANT000, &st) != 0) {
        printf("skipped: no %s\n", PLANT000);
        return 77;
    }
    phc_plant_graph *g = NULL;
    phc_error err;
    if (phc_plant_io_read(PLANT000, PHC_PLANT_FORMAT_PAPER, 0, &g, &err) != PHC_OK) {
        printf("%s\n", err.message);
        return 1;
    }
    const size_t n = g->n;
    double *young = malloc(n * sizeof *young), *extra = calloc(n, sizeof *extra);
    double *eq = malloc(3 * n * sizeof *eq), *eq2 = malloc(3 * n * sizeof *eq2);
    CHECK(young && extra && eq && eq2);
    if (!young || !extra || !eq || !eq2)
        return check_finish("test_rod_soft");
    for (size_t i = 0; i < n; ++i)
        young[i] = E_SOFT;
    phc_rod *rod = NULL;
    CHECK(phc_rod_new(g, young, NULL, &rod, &err) == PHC_OK);
    if (!rod)
        return check_finish("test_rod_soft");

    /* from rest */
    phc_rod_report rep;
    int rc = phc_rod_solve_static(rod, &rep, &err);
    double droop = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double d[3];
        phc_rod_tip_deflection(rod, i, d);
        droop = fmax(droop, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    printf("plant000, %zu segments, E = %g Pa: static solve from rest: %s; %d Newton iterations, "
           "scaled residual %.3g (tolerance %g), largest tail displacement %.4f m\n",
           n, E_SOFT, rc == PHC_OK ? "converged" : err.message, rep.iterations, rep.residual, TOL,
           droop);
    CHECK(rc == PHC_OK);
    CHECK(rep.residual <= TOL);
    CHECK(droop > 0.1); /* it flops over: the 25 cm plant's tails move by decimetres */
    tails(rod, eq);

    /* the residual again, assembled anew; the joints closed */
    rc = phc_rod_solve_static(rod, &rep, &err);
    double gap = 0.0;
    for (size_t c = 0; c < n; ++c) {
        if (g->parent[c] == PHC_PLANT_NO_PARENT)
            continue;
        double h[3], t[3];
        phc_rod_head(rod, c, h);
        phc_rod_tail(rod, g->parent[c], t);
        gap = fmax(gap, sqrt((h[0] - t[0]) * (h[0] - t[0]) + (h[1] - t[1]) * (h[1] - t[1]) +
                             (h[2] - t[2]) * (h[2] - t[2])));
    }
    printf("  solved again from there: %d iterations, scaled residual %.3g; largest joint gap "
           "%.2e m\n",
           rep.iterations, rep.residual, gap);
    CHECK(rc == PHC_OK);
    CHECK(rep.iterations == 0);
    CHECK(gap <= 1e-9);

    /* stability: 2% more mass, then back, the damped dynamics from there */
    for (size_t i = 0; i < n; ++i)
        extra[i] = MORE_MASS * phc_rod_mass(rod, i);
    CHECK(phc_rod_set_extra_mass(rod, extra, &err) == PHC_OK);
    rc = phc_rod_solve_static(rod, &rep, &err);
    CHECK(rc == PHC_OK);
    const int its_mass = rep.iterations;
    tails(rod, eq2);
    const double moved = tail_distance(rod, eq);
    for (size_t i = 0; i < n; ++i)
        extra[i] = 0.0;
    CHECK(phc_rod_set_extra_mass(rod, extra, &err) == PHC_OK);
    phc_rod_options o;
    phc_rod_options_default(&o);
    o.damping = DAMPING;
    CHECK(phc_rod_set_options(rod, &o, &err) == PHC_OK);
    int steps = 0, its = 0;
    for (; steps < (int)lround(T_END / DT); ++steps) {
        rc = phc_rod_step(rod, DT, &rep, &err);
        if (rc != PHC_OK) {
            printf("  dynamics refused at step %d: %s\n", steps, err.message);
            break;
        }
        its += rep.total_iterations;
    }
    CHECK(rc == PHC_OK);
    const double settled = tail_distance(rod, eq), ke = phc_rod_kinetic_energy(rod);
    printf("  with %.0f%% more mass the tails move by %.3e m (%d Newton iterations); with the mass "
           "back, %d implicit steps of %g s (damping %g 1/s, %d Newton iterations) settle %.3e m "
           "from the equilibrium (%.2e of that move), kinetic energy %.2e J\n",
           100.0 * MORE_MASS, moved, its_mass, steps, DT, DAMPING, its, settled,
           settled / moved, ke);
    CHECK(moved > 1e-4);        /* the mass moved the plant measurably */
    CHECK(settled <= 1e-2 * moved); /* and the dynamics brought it back */
    phc_rod_options_default(&o);
    CHECK(phc_rod_set_options(rod, &o, &err) == PHC_OK);
    rc = phc_rod_solve_static(rod, &rep, &err);
    const double back = tail_distance(rod, eq);
    printf("  the static solve from where the dynamics settled: %d iterations, %.3e m from the "
           "equilibrium (%.2e of the largest tail displacement)\n",
           rep.iterations, back, back / droop);
    CHECK(rc == PHC_OK);
    CHECK(back <= 1e-6 * droop);

    /* too small a budget: refused, both stages named, the start state kept */
    phc_rod_reset(rod);
    o.max_iterations = 5;
    CHECK(phc_rod_set_options(rod, &o, &err) == PHC_OK);
    rc = phc_rod_solve_static(rod, &rep, &err);
    double still = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double d[3];
        phc_rod_tip_deflection(rod, i, d);
        still = fmax(still, fabs(d[0]) + fabs(d[1]) + fabs(d[2]));
    }
    printf("  max_iterations 5 -> %d: %s; tails moved %.1e m\n", rc, err.message, still);
    CHECK(rc == PHC_ERR_NOT_CONVERGED);
    CHECK_STR_CONTAINS(err.message, "load continuation");
    CHECK_STR_CONTAINS(err.message, "pseudo-time");
    CHECK(still <= 1e-15);

    phc_rod_free(rod);
    phc_plant_graph_free(g);
    free(young);
    free(extra);
    free(eq);
    free(eq2);
    return check_finish("test_rod_soft");
}
