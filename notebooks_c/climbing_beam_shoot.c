/* A soft shoot that bends like a beam and swings (model/particles.h,
 * "Shoots that bend like beams"; issue 20), next to the own-weight joint
 * pass that climbing plants use by default (Fig. 12 b's soft shoot).
 *
 * A horizontal shoot of 22 links of 1 cm (r = 3 mm, ρ = 1000 kg m⁻³, the
 * size of Fig. 12 b's), clamped at its base (a pinned 1 cm segment),
 * released straight from rest under gravity, with follow_parent and
 * bending = own_weight (T = 0.01 s) or beam (E = E_1/2 s/(1 − s)).
 *
 * Soft (s = 0.5, E_1/2 = 1e7 Pa: E I_a = 6.4e-4 N m²), 6 s in substeps of
 * 0.01 s (Fig. 12's) with damping 0.01: the shapes, the tip's height in
 * time (the beam swings below its final height and back, the own-weight
 * pass creeps down), the joint bends at the base and the tip.
 * Small load (beam: s = 0.5, E_1/2 = 1e9 Pa; own weight: s = 0.999), the
 * curvature θ_k / ℓ̄_k along the shoot (own weight: θ_k / ℓ): the beam's follows Euler–
 * Bernoulli's M(x) / (E I_a) = q (L − x)² / (2 E I_a) (largest at the
 * base), the own-weight pass's is the same at every joint; the beam's tip
 * deflection against q L⁴ / (8 E I_a) times 1 + 1/n² (the links' exact
 * small-angle answer, tests/unit/test_particles_beam.c); undamped in 1 ms
 * substeps, its tip's swing period against the cantilever's first mode
 * 2π / (1.8751² sqrt(E I_a / (ρ A L⁴))).
 *
 * Checks: soft beam base bend > 10 x its tip bend; small load: own-weight
 * bends equal within 1%, beam base bend > 100 x tip bend; the soft beam
 * tip swings > 1 cm below its final height and climbs back > 1 cm; the
 * own-weight tip never rises by more than 1e-9 m in a step; the small-load
 * tip within 0.1% of q L⁴ / (8 E I_a) (1 + 1/n²); the swing period within
 * 2% of the first mode's.
 *
 * Writes climbing_beam_shoot.png (the soft shapes, the tip height in time,
 * the small-load curvature along the shoot) and climbing_beam_shoot.md.
 * Exit 1 when a check fails.
 *
 * Usage: notebook_climbing_beam_shoot OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/particles.h"
#include "model/plant_graph.h"
#include "model/quaternion.h"

#include "notebook_plot.h"

#define NLINK 22
#define NSTEP 600
static const double PI = 3.14159265358979323846;
static const double ELL = 0.01, RADIUS = 0.003, S = 0.5, DT = 0.01, RHO = 1000, G = 9.81;

typedef struct run {
    double tip_z[NSTEP + 1], t[NSTEP + 1];      /* m, s */
    double x[NLINK + 2], z[NLINK + 2];          /* the final joints and tip (m) */
    double xlow[NLINK + 2], zlow[NLINK + 2];    /* at the tip's lowest (m) */
    double angle[NLINK], along[NLINK];          /* joint bends (deg), their distance (cm) */
    double lowest, rise, final_z;               /* m */
} run;

/* The shoot: the pinned clamp segment then NLINK links along +x. */
static phc_particles *shoot(const phc_particles_options *o)
{
    phc_plant_graph *g = phc_plant_graph_new(1);
    if (!g)
        return NULL;
    g->tail[0] = ELL;
    g->radius[0] = RADIUS;
    g->length[0] = ELL;
    g->parent[0] = PHC_PLANT_NO_PARENT;
    g->fixed[0] = 1;
    phc_error err;
    phc_particles *p = NULL;
    if (phc_plant_graph_finish(g, "clamp", &err) == 0)
        p = phc_particles_new(g, o, &err);
    phc_plant_graph_free(g);
    for (size_t k = 1; p && k <= NLINK; ++k) {
        const double h[3] = {ELL * (double)k, 0, 0}, t[3] = {ELL * (double)(k + 1), 0, 0};
        if (phc_particles_append(p, k - 1, h, t, RADIUS, NULL, &err)) {
            phc_particles_free(p);
            p = NULL;
        }
    }
    if (!p)
        fprintf(stderr, "%s\n", err.message);
    return p;
}

static double down_angle(const phc_particles *p, size_t i)
{
    double q[4], R[9];
    phc_particles_orientation(p, i, q);
    phc_quat_to_matrix(q, R);
    return atan2(-R[8], R[2]);
}

static void joints(const phc_particles *p, double *x, double *z)
{
    double head[3 * (NLINK + 1)], tail[3 * (NLINK + 1)];
    phc_particles_segment_ends(p, head, tail);
    for (size_t i = 0; i <= NLINK; ++i) {
        x[i] = head[3 * i];
        z[i] = head[3 * i + 2];
    }
    x[NLINK + 1] = tail[3 * NLINK];
    z[NLINK + 1] = tail[3 * NLINK + 2];
}

static int simulate(int bending, double s, double e_half, double dt, size_t steps, run *r)
{
    phc_particles_options o = phc_particles_options_default();
    o.follow_parent = 1;
    o.bending = bending;
    o.beam_modulus = e_half;
    o.stiffness = s;
    phc_particles *p = shoot(&o);
    if (!p)
        return -1;
    phc_error err;
    r->lowest = 0;
    r->rise = 0;
    double prev = 0;
    for (size_t st = 0; st <= steps; ++st) {
        if (st > 0 && phc_particles_step(p, dt, NULL, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_particles_free(p);
            return -1;
        }
        double x[NLINK + 2], z[NLINK + 2];
        joints(p, x, z);
        const double zt = z[NLINK + 1];
        if (st <= NSTEP) {
            r->tip_z[st] = zt;
            r->t[st] = dt * (double)st;
        }
        if (zt < r->lowest) {
            r->lowest = zt;
            memcpy(r->xlow, x, sizeof x);
            memcpy(r->zlow, z, sizeof z);
        }
        if (st > 0)
            r->rise = fmax(r->rise, zt - prev);
        prev = zt;
    }
    joints(p, r->x, r->z);
    r->final_z = r->z[NLINK + 1];
    double before = down_angle(p, 0);
    for (size_t k = 0; k < NLINK; ++k) {
        const double a = down_angle(p, k + 1);
        r->angle[k] = (a - before) * 180 / PI;
        r->along[k] = 100 * ELL * (double)k;
        before = a;
    }
    phc_particles_free(p);
    return 0;
}

/* Mean period (s) of the tip's swing from its successive local minima. */
static double swing_period(const double *z, size_t n, double dt, int *count)
{
    double first = NAN, last = NAN;
    int c = 0;
    for (size_t i = 1; i + 1 < n; ++i)
        if (z[i] < z[i - 1] && z[i] <= z[i + 1]) {
            /* the parabola through the three samples: its vertex */
            const double den = z[i - 1] - 2 * z[i] + z[i + 1];
            const double t = (double)i + (den > 0 ? 0.5 * (z[i - 1] - z[i + 1]) / den : 0.0);
            if (isnan(first))
                first = t;
            last = t;
            ++c;
        }
    *count = c - 1;
    return c > 1 ? dt * (last - first) / (c - 1) : NAN;
}

int main(int argc, char **argv)
{
    const char *out;
    const int rc = nb_begin(argc, argv, NULL, &out);
    if (rc)
        return rc;
    static run own, beam, own_small, beam_small;
    if (simulate(PHC_PARTICLES_OWN_WEIGHT, S, 1e7, DT, NSTEP, &own) ||
        simulate(PHC_PARTICLES_BEAM, S, 1e7, DT, NSTEP, &beam) ||
        simulate(PHC_PARTICLES_OWN_WEIGHT, 0.999, 1e7, DT, NSTEP, &own_small) ||
        simulate(PHC_PARTICLES_BEAM, S, 1e9, DT, NSTEP, &beam_small))
        return 1;
    /* the small load's swing: undamped, 1 ms substeps */
    const double dt_swing = 0.001;
    const size_t n_swing = 3000;
    static double z_swing[3001];
    {
        phc_particles_options o = phc_particles_options_default();
        o.follow_parent = 1;
        o.bending = PHC_PARTICLES_BEAM;
        o.beam_modulus = 1e9;
        o.stiffness = S;
        o.damping = 0;
        phc_particles *p = shoot(&o);
        if (!p)
            return 1;
        phc_error err;
        for (size_t st = 0; st <= n_swing; ++st) {
            if (st > 0 && phc_particles_step(p, dt_swing, NULL, &err)) {
                fprintf(stderr, "%s\n", err.message);
                phc_particles_free(p);
                return 1;
            }
            double x[NLINK + 2], z[NLINK + 2];
            joints(p, x, z);
            z_swing[st] = z[NLINK + 1];
        }
        phc_particles_free(p);
    }

    const double L = ELL * NLINK, area = PI * RADIUS * RADIUS, Ia = PI * pow(RADIUS, 4) / 4;
    const double q = RHO * area * G, e_stiff = 1e9 * S / (1 - S);
    const double eb = q * pow(L, 4) / (8 * e_stiff * Ia);
    const double eb_links = eb * (1 + 1.0 / (NLINK * NLINK));
    int cycles;
    const double period = swing_period(z_swing, n_swing + 1, dt_swing, &cycles);
    const double period_eb = 2 * PI / (1.8751 * 1.8751 * sqrt(e_stiff * Ia / (RHO * area * pow(L, 4))));
    /* the curvature θ_k / ℓ̄_k (1/m; ℓ̄ = ℓ/2 at the clamp) and Euler–Bernoulli's
     * q (L − x)² / (2 E I_a) at the joints */
    static double kx[NLINK], k_own[NLINK], k_beam[NLINK], k_eb[NLINK];
    for (size_t k = 0; k < NLINK; ++k) {
        const double lbar = k == 0 ? ELL / 2 : ELL, xk = ELL * (double)k;
        kx[k] = 100 * xk;
        k_own[k] = own_small.angle[k] * PI / 180 / ELL; /* (its own link's length) */
        k_beam[k] = beam_small.angle[k] * PI / 180 / lbar;
        k_eb[k] = q * (L - xk) * (L - xk) / (2 * e_stiff * Ia);
    }
    double worst_k = 0;
    for (size_t k = 0; k < NLINK; ++k)
        worst_k = fmax(worst_k, fabs(k_beam[k] / k_eb[k] - 1));

    printf("climbing beam shoot: %d links of %g cm, r %g mm, clamped horizontal, released from rest\n", NLINK,
           100 * ELL, 1e3 * RADIUS);
    printf("soft, s %g, %d substeps of %g s, damping %g:\n", S, NSTEP, DT, phc_particles_options_default().damping);
    const run *rs[2] = {&own, &beam};
    const char *names[2] = {"own_weight (T 0.01 s)", "beam (E_1/2 1e7 Pa)"};
    for (int m = 0; m < 2; ++m)
        printf("  %-22s base bend %6.2f deg, tip bend %6.3f deg (ratio %7.2f); tip z: lowest %7.2f cm, "
               "final %7.2f cm, largest rise in a step %.3g m\n",
               names[m], rs[m]->angle[0], rs[m]->angle[NLINK - 1], rs[m]->angle[0] / rs[m]->angle[NLINK - 1],
               100 * rs[m]->lowest, 100 * rs[m]->final_z, rs[m]->rise);
    printf("small load:\n");
    printf("  own_weight (s 0.999)   base bend %.5f deg, tip bend %.5f deg (ratio %.5f)\n", own_small.angle[0],
           own_small.angle[NLINK - 1], own_small.angle[0] / own_small.angle[NLINK - 1]);
    printf("  beam (E_1/2 1e9 Pa)    base bend %.5f deg, tip bend %.5f deg (ratio %.2f); curvature against q (L - "
           "x)^2/(2 E I): largest |ratio - 1| %.3g (each joint carries the moment of the links beyond)\n",
           beam_small.angle[0], beam_small.angle[NLINK - 1], beam_small.angle[0] / beam_small.angle[NLINK - 1],
           worst_k);
    printf("  beam tip deflection %.5f mm; Euler-Bernoulli q L^4/(8 E I) %.5f mm (ratio %.5f), times 1 + 1/n^2 "
           "%.5f mm\n",
           -1e3 * beam_small.final_z, 1e3 * eb, -beam_small.final_z / eb, 1e3 * eb_links);
    printf("  beam, undamped, 1 ms substeps: tip swing period %.4f s over %d cycles; the cantilever's first mode "
           "2 pi/(1.8751^2 sqrt(E I/(rho A L^4))) %.4f s (ratio %.4f)\n",
           period, cycles, period_eb, period / period_eb);

    double climb = 0; /* the soft beam tip's largest climb after its lowest point */
    {
        size_t ilow = 0;
        for (size_t st = 0; st <= NSTEP; ++st)
            if (beam.tip_z[st] < beam.tip_z[ilow])
                ilow = st;
        for (size_t st = ilow; st <= NSTEP; ++st)
            climb = fmax(climb, beam.tip_z[st] - beam.tip_z[ilow]);
    }
    const double own_ratio = own_small.angle[0] / own_small.angle[NLINK - 1];
    const double beam_ratio = beam_small.angle[0] / beam_small.angle[NLINK - 1];
    const int c1 = beam.angle[0] > 10 * beam.angle[NLINK - 1];
    const int c2 = fabs(own_ratio - 1) < 0.01 && beam_ratio > 100;
    const int c3 = beam.final_z - beam.lowest > 0.01 && climb > 0.01;
    const int c4 = own.rise < 1e-9;
    const int c5 = fabs(-beam_small.final_z / eb_links - 1) < 1e-3;
    const int c6 = fabs(period / period_eb - 1) < 0.02;
    printf("check: soft beam base bend > 10 x its tip bend (%.1f x): %s\n", beam.angle[0] / beam.angle[NLINK - 1],
           c1 ? "pass" : "FAIL");
    printf("check: small load, own-weight bends equal within 1%% (base/tip %.5f), beam base bend > 100 x tip "
           "bend (%.1f x): %s\n",
           own_ratio, beam_ratio, c2 ? "pass" : "FAIL");
    printf("check: the soft beam tip swings > 1 cm below its final height (%.2f cm) and climbs back > 1 cm "
           "(%.2f cm): %s\n",
           100 * (beam.final_z - beam.lowest), 100 * climb, c3 ? "pass" : "FAIL");
    printf("check: the soft own-weight tip never rises (largest rise in a step %.3g m): %s\n", own.rise,
           c4 ? "pass" : "FAIL");
    printf("check: the small-load tip within 0.1%% of q L^4/(8 E I) (1 + 1/n^2) (%.2g): %s\n",
           -beam_small.final_z / eb_links - 1, c5 ? "pass" : "FAIL");
    printf("check: the swing period within 2%% of the first mode's (%.4f): %s\n", period / period_eb - 1,
           c6 ? "pass" : "FAIL");
    const int ok = c1 && c2 && c3 && c4 && c5 && c6;

    /* the figure */
    static double rx[NLINK + 2], rz[NLINK + 2], ox[NLINK + 2], oz[NLINK + 2], bx[NLINK + 2], bz[NLINK + 2],
        lx[NLINK + 2], lz[NLINK + 2];
    for (size_t i = 0; i < NLINK + 2; ++i) {
        rx[i] = 100 * ELL * (double)i;
        rz[i] = 0;
        ox[i] = 100 * own.x[i];
        oz[i] = 100 * own.z[i];
        bx[i] = 100 * beam.x[i];
        bz[i] = 100 * beam.z[i];
        lx[i] = 100 * beam.xlow[i];
        lz[i] = 100 * beam.zlow[i];
    }
    static double tz_own[NSTEP + 1], tz_beam[NSTEP + 1];
    for (size_t st = 0; st <= NSTEP; ++st) {
        tz_own[st] = 100 * own.tip_z[st];
        tz_beam[st] = 100 * beam.tip_z[st];
    }
    const nb_series shapes[4] = {
        {rx, rz, NLINK + 2, "rest", NB_GREY, 1, 0, 0},
        {ox, oz, NLINK + 2, "own weight, after 6 s", NB_BLUE, 0, 0, 0},
        {bx, bz, NLINK + 2, "beam, after 6 s", NB_RED, 0, 0, 0},
        {lx, lz, NLINK + 2, "beam, lowest swing", NB_ORANGE, 2, 0, 0},
    };
    const nb_series tips[2] = {
        {own.t, tz_own, NSTEP + 1, "own weight", NB_BLUE, 0, 0, 0},
        {beam.t, tz_beam, NSTEP + 1, "beam", NB_RED, 0, 0, 0},
    };
    const nb_series curv[3] = {
        {kx, k_eb, NLINK, "Euler-Bernoulli q(L-x)^2/(2EI)", NB_BLACK, 1, 0, 0},
        {kx, k_beam, NLINK, "beam (E_1/2 1e9 Pa)", NB_RED, 0, 1, 0},
        {kx, k_own, NLINK, "own weight (s 0.999)", NB_BLUE, 0, 1, 0},
    };
    const nb_panel panels[3] = {
        {"(a) soft shoot (s 0.5), side view", "x (cm)", "z (cm)", 0, -34, 2, 3, shapes, 4},
        {"(b) soft shoot: tip height after release", "time (s)", "tip z (cm)", 0, 0, 0, 1, tips, 2},
        {"(c) small load: curvature", "joint distance from the clamp (cm)", "joint bend / length (1/m)",
         0, 0, 0.16, 1, curv, 3},
    };
    char png[1024];
    snprintf(png, sizeof png, "%s/climbing_beam_shoot.png", out);
    if (nb_plot(png, 1650, 520, 3, 1, panels, 3)) {
        fprintf(stderr, "%s: cannot write the figure\n", png);
        return 1;
    }
    char md[1040], tmp[1040];
    FILE *f = nb_open_md(out, "climbing_beam_shoot.md", md, tmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# A soft shoot that bends like a beam and swings\n\n"
            "![shapes, tip height and curvature](climbing_beam_shoot.png)\n\n"
            "%d links of %g cm (r %g mm) clamped horizontal, released from rest; soft: s %g, %g s substeps.\n\n"
            "| joint pass | base bend (deg) | tip bend (deg) | lowest tip z (cm) | tip z after 6 s (cm) |\n"
            "|---|---|---|---|---|\n",
            NLINK, 100 * ELL, 1e3 * RADIUS, S, DT);
    for (int m = 0; m < 2; ++m)
        fprintf(f, "| %s | %.2f | %.3f | %.2f | %.2f |\n", names[m], rs[m]->angle[0], rs[m]->angle[NLINK - 1],
                100 * rs[m]->lowest, 100 * rs[m]->final_z);
    fprintf(f,
            "\nSmall load, beam: tip %.5f mm against q L⁴/(8 E I) (1 + 1/n²) = %.5f mm; swing period %.4f s "
            "against the first cantilever mode's %.4f s.\n\n**Checks**: %s.\n",
            -1e3 * beam_small.final_z, 1e3 * eb_links, period, period_eb, ok ? "all pass" : "FAILED");
    if (nb_close_md(f, md, tmp)) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    printf("%s: %s\n", ok ? "ok" : "FAIL", out);
    return ok ? 0 : 1;
}
