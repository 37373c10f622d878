/* Unit test of the beam joint pass (model/particles.h, "Shoots that bend
 * like beams": follow_parent with bending = PHC_PARTICLES_BEAM).  Every
 * checked number is printed.
 *
 *  1. Statics of a horizontal cantilever of n equal links clamped at one
 *     end: each joint's angle against the exact discrete balance
 *     κ θ_k = M_k (the moment of the links beyond joint k), in its
 *     small-angle closed form q ℓ² n_k² / (2 κ) and in the full nonlinear
 *     form solved by Newton here; the base bends most.
 *  2. Euler–Bernoulli: the tip deflection of a lightly loaded cantilever
 *     against q L⁴ / (8 E I_a) as the links are refined (n = 4 .. 64): the
 *     convergence order (2) printed, the error 1/n² of the trapezoid rule.
 *  3. One link hanging on its joint: small oscillation period against
 *     2π sqrt(I / (κ + m g L/2)) and against the scheme's exact discrete
 *     answer (the eigenvalue of its linear step), and the amplitude decay
 *     with damping 0 and 0.002 against the same eigenvalue.
 *  3b. A chain of 8 links clamped horizontal and let go: the tip's swing
 *     period against the first eigenmode of the linearised chain, K v =
 *     ω² H v (H its joint-space mass matrix, K the joint springs; LAPACK
 *     dsygv), which tests the articulated-body dynamics of the whole tree.
 *  4. Limits: s = 1 keeps the rest shape exactly and gives the own-weight
 *     pass's numbers bit for bit; s = 0 does not hold.
 *  5. A branched 3-D plant of 1365 particles (the threaded path): 1 and 2
 *     threads give the same numbers bit for bit.
 *  6. Bad options name the option. */
#include "model/particles.h"
#include "model/plant_graph.h"
#include "model/quaternion.h"

#include <lapacke.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static const double PI = 3.14159265358979323846;
static const double RHO = 1000, G = 9.81;

/* A system of one pinned segment from `origin` along `dir` (unit) of
 * length ell and radius r, then n links continuing it (each the next's
 * parent). */
static phc_particles *straight_chain(size_t n, const double origin[3], const double dir[3],
                                     double ell, double r, const phc_particles_options *o)
{
    phc_plant_graph *g = phc_plant_graph_new(1);
    if (!g)
        return NULL;
    for (int d = 0; d < 3; ++d) {
        g->head[d] = origin[d];
        g->tail[d] = origin[d] + ell * dir[d];
    }
    g->radius[0] = r;
    g->length[0] = ell;
    g->parent[0] = PHC_PLANT_NO_PARENT;
    g->source_id[0] = 0;
    g->fixed[0] = 1;
    phc_error err;
    phc_particles *p = NULL;
    if (!phc_plant_graph_finish(g, "clamp", &err))
        p = phc_particles_new(g, o, &err);
    phc_plant_graph_free(g);
    for (size_t k = 1; p && k <= n; ++k) {
        double h[3], t[3];
        for (int d = 0; d < 3; ++d) {
            h[d] = origin[d] + ell * (double)k * dir[d];
            t[d] = h[d] + ell * dir[d];
        }
        if (phc_particles_append(p, k - 1, h, t, r, NULL, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_particles_free(p);
            return NULL;
        }
    }
    if (!p)
        fprintf(stderr, "%s\n", err.message);
    return p;
}

/* The options of a beam pass: follow_parent, bending = beam, E_1/2 (Pa),
 * stiffness s and damping for every particle. */
static phc_particles_options beam_options(double e_half, double s, double damping)
{
    phc_particles_options o = phc_particles_options_default();
    o.follow_parent = 1;
    o.bending = PHC_PARTICLES_BEAM;
    o.beam_modulus = e_half;
    o.stiffness = s;
    o.damping = damping;
    return o;
}

/* Steps until every speed is below vtol (or cap steps); returns the steps. */
static size_t settle(phc_particles *p, double dt, double vtol, size_t cap)
{
    phc_error err;
    const size_t n = phc_particles_count(p);
    for (size_t st = 1; st <= cap; ++st) {
        if (phc_particles_step(p, dt, NULL, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 0;
        }
        double vmax = 0;
        for (size_t i = 0; i < n; ++i) {
            double v[3];
            phc_particles_velocity(p, i, v);
            vmax = fmax(vmax, sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
        }
        if (vmax < vtol)
            return st;
    }
    return cap;
}

/* Angle of particle i's axis below the horizontal +x (rad), x–z plane. */
static double down_angle(const phc_particles *p, size_t i)
{
    double q[4], R[9];
    phc_particles_orientation(p, i, q);
    phc_quat_to_matrix(q, R);
    return atan2(-R[8], R[2]); /* axis R(0, 0, 1) = (R[2], R[5], R[8]) */
}

/* The exact balance of n links of length ell, weight w = m g each, on
 * joints of stiffness kappa (2 kappa at the clamp, whose ℓ̄ is ℓ/2), the
 * first joint clamped horizontal: κ_k θ_k =
 * Σ_{j >= k} w (x_j − J_k), x the centres' and J the joints' horizontal
 * places from the absolute angles φ_k = θ_1 + ... + θ_k.  Newton from the
 * small-angle answer, the Jacobian by central differences (n <= 64). */
static void balance_residual(size_t n, double ell, double w, double kappa, const double *th,
                             double *res)
{
    double phi = 0, J = 0, xs[64], Js[64];
    for (size_t k = 0; k < n; ++k) {
        phi += th[k];
        Js[k] = J;
        xs[k] = J + 0.5 * ell * cos(phi);
        J += ell * cos(phi);
    }
    for (size_t k = 0; k < n; ++k) {
        double M = 0;
        for (size_t j = k; j < n; ++j)
            M += w * (xs[j] - Js[k]);
        res[k] = (k == 0 ? 2 * kappa : kappa) * th[k] - M; /* the clamp's joint: ℓ̄ = ℓ/2 */
    }
}

static int newton_balance(size_t n, double ell, double w, double kappa, double *th)
{
    double r[64], rp[64], rm[64], Jm[64 * 64];
    for (int it = 0; it < 50; ++it) {
        if (it == 49)
            return -1;
        balance_residual(n, ell, w, kappa, th, r);
        double rn = 0;
        for (size_t k = 0; k < n; ++k)
            rn = fmax(rn, fabs(r[k]));
        if (rn < 1e-15 * w * ell * (double)(n * n))
            return it;
        for (size_t c = 0; c < n; ++c) {
            const double h = 1e-7, keep = th[c];
            th[c] = keep + h;
            balance_residual(n, ell, w, kappa, th, rp);
            th[c] = keep - h;
            balance_residual(n, ell, w, kappa, th, rm);
            th[c] = keep;
            for (size_t k = 0; k < n; ++k)
                Jm[k * n + c] = (rp[k] - rm[k]) / (2 * h);
        }
        /* Jm d = −r (LAPACK) */
        lapack_int piv[64];
        for (size_t k = 0; k < n; ++k)
            r[k] = -r[k];
        if (LAPACKE_dgesv(LAPACK_ROW_MAJOR, (lapack_int)n, 1, Jm, (lapack_int)n, piv, r, 1) != 0)
            return -1;
        for (size_t k = 0; k < n; ++k)
            th[k] += r[k];
    }
    return -1;
}

/* The balance under the load w, by continuation: Newton from the
 * small-angle answer at w/20, then at 2w/20, ... w.  Returns the largest
 * Newton iteration count, −1 when one did not converge. */
static int balance(size_t n, double ell, double w, double kappa, double *th)
{
    int most = 0;
    for (size_t k = 0; k < n; ++k) {
        const double nk = (double)(n - k);
        th[k] = w / 20 * ell * nk * nk / (2 * (k == 0 ? 2 * kappa : kappa));
    }
    for (int c = 1; c <= 20; ++c) {
        const int its = newton_balance(n, ell, w * c / 20, kappa, th);
        if (its < 0)
            return -1;
        most = its > most ? its : most;
    }
    return most;
}

/* κ of a joint (particles.h): E(s) π r⁴ / (4 ℓ̄), E(s) = E_1/2 s / (1 − s),
 * ℓ̄ its share of the bending links (m). */
static double joint_kappa(double e_half, double s, double r, double lbar)
{
    return e_half * s / (1 - s) * PI * r * r * r * r / (4 * lbar);
}

static void test_statics(void)
{
    const size_t n = 8;
    const double ell = 0.05, r = 0.004, s = 0.5, o[3] = {0, 0, 0}, dx[3] = {1, 0, 0};
    const double m = RHO * PI * r * r * ell, w = m * G;
    /* two loads: E_1/2 = 1e9 Pa (tip ~ 1 mm: small angles) and 2e6 Pa (large) */
    const double moduli[2] = {1e9, 2e6};
    for (int c = 0; c < 2; ++c) {
        const phc_particles_options opt = beam_options(moduli[c], s, 0.05);
        phc_particles *p = straight_chain(n, o, dx, ell, r, &opt);
        CHECK(p != NULL);
        if (!p)
            return;
        const size_t steps = settle(p, 0.01, 1e-10, 200000);
        const double kappa = joint_kappa(moduli[c], s, r, ell);
        double th[64], th_small[64];
        for (size_t k = 0; k < n; ++k) {
            const double nk = (double)(n - k);
            th_small[k] = w * ell * nk * nk / (2 * (k == 0 ? 2 * kappa : kappa));
        }
        const int its = balance(n, ell, w, kappa, th);
        CHECK(its >= 0);
        printf("beam statics: %zu links of %g m, r %g m, s %g, E_1/2 %g Pa (kappa %.4g N m/rad, "
               "twice at the clamp), "
               "settled after %zu steps of 0.01 s (damping 0.05), Newton at most %d iterations per load (20 loads)\n",
               n, ell, r, s, moduli[c], kappa, steps, its);
        printf("  %5s %16s %16s %16s %12s\n", "joint", "theta (rad)", "Newton (rad)",
               "small-angle", "|diff|");
        double worst = 0, worst_small = 0, prev = down_angle(p, 0);
        double base = 0, tip = 0;
        for (size_t k = 0; k < n; ++k) {
            const double a = down_angle(p, k + 1), t = a - prev;
            prev = a;
            worst = fmax(worst, fabs(t - th[k]));
            worst_small = fmax(worst_small, fabs(t - th_small[k]) / th_small[k]);
            if (k == 0)
                base = t;
            tip = t;
            printf("  %5zu %16.10f %16.10f %16.10f %12.3g\n", k + 1, t, th[k], th_small[k],
                   fabs(t - th[k]));
        }
        printf("beam statics: largest |theta - Newton| = %.3g rad, largest |theta / small-angle - "
               "1| = %.3g, base / tip joint angle = %.2f (n^2 / 2 = %zu for small angles)\n",
               worst, worst_small, base / tip, n * n / 2);
        CHECK(worst < 1e-8);
        CHECK(base > 10 * tip);
        if (c == 0)
            CHECK(worst_small < 1e-3);
        else
            CHECK(worst_small > 1e-2); /* measured: large angles leave the linear answer */
        phc_particles_free(p);
    }
}

static void test_euler_bernoulli(void)
{
    const double L = 0.5, r = 0.004, s = 0.5, e_half = 2e11, o[3] = {0, 0, 0}, dx[3] = {1, 0, 0};
    const double E = e_half * s / (1 - s), Ia = PI * r * r * r * r / 4;
    const double q = RHO * PI * r * r * G; /* N/m */
    const double want = q * L * L * L * L / (8 * E * Ia);
    const size_t ns[5] = {4, 8, 16, 32, 64};
    double err[5];
    printf("beam vs Euler-Bernoulli: L %g m, r %g m, E %g Pa, q %.5g N/m: q L^4/(8 E I) = %.6g mm\n",
           L, r, E, q, 1e3 * want);
    printf("  %4s %14s %12s %8s %7s\n", "n", "tip (mm)", "rel. error", "order", "steps");
    for (int a = 0; a < 5; ++a) {
        const phc_particles_options opt = beam_options(e_half, s, 0.05);
        const double ell = L / (double)ns[a];
        phc_particles *p = straight_chain(ns[a], o, dx, ell, r, &opt);
        CHECK(p != NULL);
        if (!p)
            return;
        const size_t steps = settle(p, 0.002, 1e-12, 400000);
        double *head = malloc(3 * (ns[a] + 1) * sizeof *head);
        double *tail = malloc(3 * (ns[a] + 1) * sizeof *tail);
        phc_particles_segment_ends(p, head, tail);
        const double tip = -tail[3 * ns[a] + 2];
        err[a] = tip / want - 1;
        const double order = a ? log2(fabs(err[a - 1] / err[a])) : NAN;
        printf("  %4zu %14.6g %12.4g %8.3f %7zu\n", ns[a], 1e3 * tip, err[a], order, steps);
        free(head);
        free(tail);
        phc_particles_free(p);
    }
    const double order = log2(fabs(err[3] / err[4]));
    /* the small-angle tip deflection is the trapezoid rule of ∫ M (L − x) / (E I) dx
     * (ℓ̄ = ℓ/2 at the clamp, ℓ between links), M = q (L − x)²/2: its error is
     * (ℓ/L)² = 1/n² of q L⁴ / (8 E I) exactly (the cubic's trapezoid error) */
    double worst_n2 = 0;
    for (int a = 0; a < 5; ++a)
        worst_n2 = fmax(worst_n2, fabs(err[a] * (double)(ns[a] * ns[a]) - 1));
    printf("beam vs Euler-Bernoulli: error at n = 64 %.3g, order from 32 to 64 %.3f; the trapezoid "
           "rule's 1/n^2: largest |error n^2 - 1| = %.3g\n",
           err[4], order, worst_n2);
    CHECK(worst_n2 < 1e-3);
    CHECK(fabs(err[4]) < 1e-3); /* second order in the link length (the trapezoid rule) */
    CHECK(fabs(order - 2) < 0.1);
    for (int a = 1; a < 5; ++a)
        CHECK(fabs(err[a]) < fabs(err[a - 1]));
}

/* One link hanging down from a pinned segment, tilted by th0 about y and
 * let go: the angle below its rest (rad) over `steps` steps. */
static void swing(double dt, double damping, double th0, size_t steps, double *theta,
                  double *period_formula, double *period_discrete, double *rho_period)
{
    const double ell = 0.1, r = 0.002, s = 0.5, e_half = 1e7;
    const double o[3] = {0, 0, 0}, down[3] = {0, 0, -1};
    const phc_particles_options opt = beam_options(e_half, s, damping);
    phc_particles *p = straight_chain(1, o, down, ell, r, &opt);
    CHECK(p != NULL);
    if (!p)
        return;
    /* tilt link 1 about its joint (0, 0, −ell) by th0 about y */
    phc_error err;
    double q[4], q1[4], x[3];
    const double rv[3] = {0, th0, 0};
    phc_particles_orientation(p, 1, q1);
    phc_quat_exp(rv, q);
    double qn[4];
    phc_quat_mul(q, q1, qn);
    x[0] = -0.5 * ell * sin(th0); /* R_y(th0) (0, 0, −ell/2) */
    x[1] = 0;
    x[2] = -ell - 0.5 * ell * cos(th0);
    CHECK(phc_particles_set_orientation(p, 1, qn, &err) == 0);
    CHECK(phc_particles_set_position(p, 1, x, &err) == 0);
    for (size_t st = 0; st < steps; ++st) {
        if (phc_particles_step(p, dt, NULL, &err)) {
            fprintf(stderr, "%s\n", err.message);
            break;
        }
        double c[3];
        phc_particles_position(p, 1, c);
        theta[st] = atan2(-c[0], -(c[2] + ell)); /* the centre's angle about the joint */
    }
    phc_particles_free(p);
    const double m = RHO * PI * r * r * ell;
    const double Ij = m * (r * r / 4 + ell * ell / 3); /* about the joint, across */
    const double kappa = joint_kappa(e_half, s, r, ell / 2), K = kappa + m * G * ell / 2; /* ℓ̄ = ℓ/2: the clamp does not bend */
    /* the damped oscillator θ'' + 2γ θ' + (K/I) θ = 0 (I = Ij), the velocity losing
     * the fraction d per step: e^{−2γ Δt} = 1 − d */
    const double gamma = -log(1 - damping) / (2 * dt) + 0.0; /* (+0 for d = 0) */
    *period_formula = 2 * PI / sqrt(K / Ij - gamma * gamma);
    /* the scheme's linear step on (θ, ω): ω̃ = (I ω − Δt K θ)/(I + Δt² κ),
     * θ⁺ = θ + Δt ω̃, ω⁺ = (1 − d) ω̃ */
    const double den = Ij + dt * dt * kappa;
    const double a11 = 1 - dt * dt * K / den, a12 = dt * Ij / den;
    const double a21 = -(1 - damping) * dt * K / den, a22 = (1 - damping) * Ij / den;
    const double tr = a11 + a22, det = a11 * a22 - a12 * a21;
    const double psi = atan2(sqrt(det - tr * tr / 4), tr / 2); /* complex pair ρ e^{±iψ} */
    *period_discrete = 2 * PI * dt / psi;
    *rho_period = pow(sqrt(det), 2 * PI / psi);
}

/* Mean period (s) from the upward zero crossings of theta (linear
 * interpolation), and the amplitude ratio per period from the first and
 * last full cycles' largest |theta|. */
static void measure(const double *theta, size_t steps, double dt, double *period, double *ratio,
                    int *cycles)
{
    double first = NAN, last = NAN;
    size_t idx[4096];
    int nc = 0;
    for (size_t st = 1; st < steps && nc < 4096; ++st)
        if (theta[st - 1] < 0 && theta[st] >= 0) {
            const double t = (double)st - theta[st] / (theta[st] - theta[st - 1]);
            if (isnan(first))
                first = t;
            last = t;
            idx[nc++] = st;
        }
    *cycles = nc - 1;
    *period = dt * (last - first) / (nc - 1);
    double a0 = 0, a1 = 0;
    for (size_t st = idx[0]; st < idx[1]; ++st)
        a0 = fmax(a0, fabs(theta[st]));
    for (size_t st = idx[nc - 2]; st < idx[nc - 1]; ++st)
        a1 = fmax(a1, fabs(theta[st]));
    *ratio = pow(a1 / a0, 1.0 / (nc - 2));
}

static void test_swing(void)
{
    const double dt = 2e-4, th0 = 1e-3;
    const size_t steps = 20000;
    double *theta = malloc(steps * sizeof *theta);
    const double damps[2] = {0, 0.002};
    for (int c = 0; c < 2; ++c) {
        double pf, pd, rho, per, ratio;
        int cyc;
        swing(dt, damps[c], th0, steps, theta, &pf, &pd, &rho);
        measure(theta, steps, dt, &per, &ratio, &cyc);
        const double gamma = -log(1 - damps[c]) / (2 * dt) + 0.0, decay = exp(-gamma * pf);
        printf("beam swing: one link of 0.1 m hanging, tilted %g rad, dt %g s, damping %g "
               "(gamma %.4g /s): period %.6f s over %d cycles, 2 pi / sqrt((kappa + m g L/2)/I - "
               "gamma^2) = %.6f s, the scheme's eigenvalue %.6f s; amplitude per period %.5f, "
               "eigenvalue %.5f, exp(-gamma P) %.5f\n",
               th0, dt, damps[c], gamma, per, cyc, pf, pd, ratio, rho, decay);
        CHECK(fabs(per / pd - 1) < 1e-4);
        CHECK(fabs(per / pf - 1) < 5e-4); /* measured 9e-6 undamped, 9e-5 damped */
        CHECK(fabs(ratio / rho - 1) < 1e-4);
        CHECK(fabs(ratio / decay - 1) < 0.015); /* the implicit spring's own loss: 0.9% */
        CHECK(cyc >= 10);
        if (c == 1)
            CHECK(ratio < 0.9);
    }
    free(theta);
}


/* 3b. The chain's first mode.  For a straight horizontal chain of n links
 * (length ℓ, mass m, inertia I_c = m (3r² + ℓ²)/12 across) on joints at
 * x_i = i ℓ, a turn of joint i moves link b >= i's centre c_b = (b + ½) ℓ
 * by (c_b − x_i) θ_i and turns it by θ_i, so the kinetic energy is ½ θ̇ᵀ H θ̇
 * with H_ij = Σ_{b >= max(i,j)} [m (c_b − x_i)(c_b − x_j) + I_c]; the
 * springs give K = diag(κ_i) (2κ at the clamp).  Gravity adds nothing to
 * the stiffness of the straight horizontal chain (z = −Σ ℓ sin φ has no
 * curvature at φ = 0); the static sag here is 1e-4 rad. */
static void test_chain_mode(void)
{
    enum { NL = 8 };
    const double ell = 0.05, r = 0.004, s = 0.5, e_half = 1e9, o[3] = {0, 0, 0}, dx[3] = {1, 0, 0};
    const double m = RHO * PI * r * r * ell, Ic = m * (3 * r * r + ell * ell) / 12;
    const double kappa = joint_kappa(e_half, s, r, ell);
    double H[NL * NL], K[NL * NL] = {0}, w2[NL];
    for (int i = 0; i < NL; ++i)
        for (int j = 0; j < NL; ++j) {
            double h = 0;
            for (int b = i > j ? i : j; b < NL; ++b)
                h += m * ((b + 0.5) * ell - i * ell) * ((b + 0.5) * ell - j * ell) + Ic;
            H[i * NL + j] = h;
        }
    for (int i = 0; i < NL; ++i)
        K[i * NL + i] = i == 0 ? 2 * kappa : kappa;
    const lapack_int info = LAPACKE_dsygv(LAPACK_ROW_MAJOR, 1, 'N', 'U', NL, K, NL, H, NL, w2);
    CHECK(info == 0);
    const double period_mode = 2 * PI / sqrt(w2[0]);
    /* the simulation: released straight, undamped, dt = period / 2000 */
    const phc_particles_options opt = beam_options(e_half, s, 0);
    phc_particles *p = straight_chain(NL, o, dx, ell, r, &opt);
    CHECK(p != NULL);
    if (!p)
        return;
    const double dt = period_mode / 2000;
    const size_t steps = 12 * 2000;
    double *z = malloc(steps * sizeof *z), head[3 * (NL + 1)], tail[3 * (NL + 1)];
    phc_error err;
    int failed = 0;
    for (size_t st = 0; st < steps; ++st) {
        failed += phc_particles_step(p, dt, NULL, &err) != 0;
        phc_particles_segment_ends(p, head, tail);
        z[st] = tail[3 * NL + 2];
    }
    CHECK(failed == 0);
    phc_particles_free(p);
    /* the period from the tip's local minima (parabolic vertices) after
     * the first two, when the higher modes have died out (the implicit
     * spring damps a mode by ω² Δt / 2 per unit time) */
    double first = NAN, last = NAN;
    int count = 0, seen = 0;
    for (size_t st = 1; st + 1 < steps; ++st)
        if (z[st] < z[st - 1] && z[st] <= z[st + 1] && ++seen > 2) {
            const double den = z[st - 1] - 2 * z[st] + z[st + 1];
            const double t = (double)st + 0.5 * (z[st - 1] - z[st + 1]) / den;
            if (isnan(first))
                first = t;
            last = t;
            ++count;
        }
    const double period = dt * (last - first) / (count - 1);
    const double L = ell * NL, E = e_half * s / (1 - s), Ia = PI * r * r * r * r / 4;
    const double period_eb = 2 * PI / (1.8751 * 1.8751 * sqrt(E * Ia / (RHO * PI * r * r * L * L * L * L)));
    printf("beam chain: %d links of %g m clamped horizontal, released straight, undamped, dt = %.4g s: tip "
           "period %.7f s over %d cycles; the linearised chain's first mode (K v = w^2 H v, dsygv) %.7f s "
           "(ratio %.6f); the continuous cantilever's %.7f s\n",
           NL, ell, dt, period, count - 1, period_mode, period / period_mode, period_eb);
    CHECK(count >= 8);
    CHECK(fabs(period / period_mode - 1) < 1e-3);
    free(z);
}

static void test_limits(void)
{
    const size_t n = 10;
    const double ell = 0.05, r = 0.003, o[3] = {0.1, 0.2, 0.3}, dx[3] = {0.6, 0, 0.8};
    double *x[2];
    for (int mode = 0; mode < 2; ++mode) {
        phc_particles_options opt = phc_particles_options_default();
        opt.follow_parent = 1;
        opt.bending = mode ? PHC_PARTICLES_BEAM : PHC_PARTICLES_OWN_WEIGHT;
        opt.stiffness = 1;
        phc_particles *p = straight_chain(n, o, dx, ell, r, &opt);
        CHECK(p != NULL);
        if (!p)
            return;
        x[mode] = malloc(7 * (n + 1) * sizeof(double));
        phc_error err;
        double dev = 0;
        for (int st = 0; st < 500; ++st)
            CHECK(phc_particles_step(p, 0.01, NULL, &err) == 0);
        for (size_t i = 0; i <= n; ++i) {
            double xi[3];
            phc_particles_position(p, i, xi);
            for (int d = 0; d < 3; ++d)
                dev = fmax(dev, fabs(xi[d] - (o[d] + ell * ((double)i + 0.5) * dx[d])));
            memcpy(x[mode] + 7 * i, xi, sizeof xi);
            phc_particles_orientation(p, i, x[mode] + 7 * i + 3);
        }
        printf("beam limits: s = 1, %s, 500 steps: largest distance from the rest shape %.3g m\n",
               mode ? "beam" : "own weight", dev);
        CHECK(dev < 1e-12);
        phc_particles_free(p);
    }
    const int same = memcmp(x[0], x[1], 7 * (n + 1) * sizeof(double)) == 0;
    printf("beam limits: s = 1: beam and own-weight states bit-identical: %s\n", same ? "yes" : "no");
    CHECK(same);
    free(x[0]);
    free(x[1]);
    /* s = 0: not held, the link falls freely (its centre drops g t²/2) */
    phc_particles_options opt = phc_particles_options_default();
    opt.follow_parent = 1;
    opt.bending = PHC_PARTICLES_BEAM;
    opt.stiffness = 0;
    opt.damping = 0;
    phc_particles *p = straight_chain(1, o, dx, ell, r, &opt);
    phc_error err;
    CHECK(phc_particles_set_stiffness(p, 0, 1, &err) == 0);
    for (int st = 0; st < 10; ++st)
        CHECK(phc_particles_step(p, 0.01, NULL, &err) == 0);
    double xc[3];
    phc_particles_position(p, 1, xc);
    const double drop = o[2] + 1.5 * ell * dx[2] - xc[2];
    printf("beam limits: s = 0 (the clamp s = 1), 10 steps of 0.01 s: the link's centre dropped "
           "%.8f m; free fall in symplectic Euler, 55 g dt^2 = %.8f m\n",
           drop, 55 * G * 1e-4);
    CHECK_NEAR(drop, 55 * G * 1e-4, 1e-12, 0);
    phc_particles_free(p);
}

/* A branched 3-D plant: a stem of `stem` links up, from each of its nodes
 * a side shoot of `side` links out and up, turning about z node by node. */
static phc_particles *branched(size_t stem, size_t side, const phc_particles_options *o)
{
    const double org[3] = {0, 0, 0}, up[3] = {0, 0, 1}, ell = 0.02, r = 0.002;
    phc_particles *p = straight_chain(stem, org, up, ell, r, o);
    phc_error err;
    for (size_t k = 1; p && k <= stem; ++k) {
        const double a = 2.4 * (double)k;
        const double d[3] = {0.8 * cos(a), 0.8 * sin(a), 0.6};
        double h[3] = {0, 0, ell * (double)(k + 1)}, t[3];
        size_t parent = k, idx;
        for (size_t j = 0; j < side; ++j) {
            for (int c = 0; c < 3; ++c)
                t[c] = h[c] + ell * d[c];
            if (phc_particles_append(p, parent, h, t, r * 0.8, &idx, &err)) {
                phc_particles_free(p);
                return NULL;
            }
            parent = idx;
            memcpy(h, t, sizeof h);
        }
    }
    return p;
}

static void test_threads(void)
{
    const size_t stem = 64, side = 20;
    double *st[2];
    size_t n = 0;
    for (int th = 1; th <= 2; ++th) {
        omp_set_num_threads(th);
        phc_particles_options opt = phc_particles_options_default();
        opt.follow_parent = 1;
        opt.bending = PHC_PARTICLES_BEAM;
        opt.maturity_age = 2; /* s from 0 (new) to 1 over 2 s: every kind of joint */
        phc_particles *p = branched(stem, side, &opt);
        CHECK(p != NULL);
        if (!p)
            return;
        n = phc_particles_count(p);
        phc_error err;
        for (size_t i = 0; i < n; ++i)
            CHECK(phc_particles_set_age(p, i, 0.1 + 1.9 * (double)(i % 7) / 7, &err) == 0);
        const double f[3] = {0.001, -0.002, 0};
        CHECK(phc_particles_set_force(p, n - 1, f, &err) == 0);
        for (int k = 0; k < 50; ++k)
            CHECK(phc_particles_step(p, 0.01, NULL, &err) == 0);
        st[th - 1] = malloc(7 * n * sizeof(double));
        for (size_t i = 0; i < n; ++i) {
            phc_particles_position(p, i, st[th - 1] + 7 * i);
            phc_particles_orientation(p, i, st[th - 1] + 7 * i + 3);
        }
        phc_particles_free(p);
    }
    omp_set_num_threads(omp_get_num_procs());
    const int same = memcmp(st[0], st[1], 7 * n * sizeof(double)) == 0;
    double tip = 0;
    for (size_t i = 0; i < n; ++i)
        tip = fmax(tip, fabs(st[0][7 * i + 2] - st[1][7 * i + 2]));
    printf("beam threads: %zu particles, 50 steps, 1 and 2 threads bit-identical: %s (largest "
           "|dz| %.3g m)\n",
           n, same ? "yes" : "no", tip);
    CHECK(n >= 1024); /* the threaded path (PHC_PARTICLES_PARALLEL_MIN) */
    CHECK(same);
    free(st[0]);
    free(st[1]);
}

static void test_bad_options(void)
{
    phc_plant_graph *g = phc_plant_graph_new(1);
    g->tail[2] = 0.1;
    g->radius[0] = 0.01;
    g->length[0] = 0.1;
    g->parent[0] = PHC_PLANT_NO_PARENT;
    phc_error err;
    CHECK(phc_plant_graph_finish(g, "one", &err) == 0);
    phc_particles_options opt = phc_particles_options_default();
    CHECK(opt.bending == PHC_PARTICLES_OWN_WEIGHT);
    opt.bending = 7;
    phc_particles *p = phc_particles_new(g, &opt, &err);
    CHECK(p == NULL);
    printf("beam bad options: bending 7: %s\n", err.message);
    CHECK_STR_CONTAINS(err.message, "bending");
    opt.bending = PHC_PARTICLES_BEAM;
    opt.beam_modulus = -1;
    p = phc_particles_new(g, &opt, &err);
    CHECK(p == NULL);
    printf("beam bad options: beam_modulus -1: %s\n", err.message);
    CHECK_STR_CONTAINS(err.message, "beam modulus");
    phc_plant_graph_free(g);
}

int main(void)
{
    test_statics();
    test_euler_bernoulli();
    test_swing();
    test_chain_mode();
    test_limits();
    test_threads();
    test_bad_options();
    return check_finish("test_particles_beam");
}
