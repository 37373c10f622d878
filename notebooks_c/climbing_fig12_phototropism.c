/* Climbing plants (Hädrich, Benes, Deussen, Pirk, CGF 36(2) 2017), Fig. 12:
 * (a) phototropism with light from one side, (b) high against low
 * stiffness of a shoot that grows over the edge of a support.
 *
 * (a) One seed (12) at the origin growing up, light from the side
 * ℓ ∝ (1, 0, 0.3) (toward the light), 60 s of kinematic growth in steps of
 * 0.25 s, BP 0.3, orders up to 2, for phototropism rates η = 0, 0.02,
 * 0.05 and 0.1 s⁻¹ (eq. 7; the figure's values were not available to us).
 * Prints the mean angle between the particles' directions and ℓ, and
 * checks that it falls as η rises (the shoots bend toward the light).
 *
 * (b) A shoot (no branching) seeded on a table top (a support mesh: the
 * square x ∈ [−0.5, 0], y ∈ [−0.25, 0.25] at z = 0, normal up) 1 cm from
 * its edge, growing toward +x, for 40 s in steps of 0.05 s with dynamics
 * (5 substeps per step, gravity −9.81 m s⁻², no surface adaption, so it
 * grows straight over the edge; anchors on the table).  Stiffness s = max(s_min, min(1, age/t_m)) (model/climbing_
 * growth.h): high = (t_m 2 s, s_min 0.9), low = (t_m 50 s, s_min 0.3).
 * Each link hangs from a joint on its parent, an angular spring
 * (particles.follow_parent, on for climbing plants): a mature link (s = 1)
 * keeps its rest angle, a younger one bends down by its load (T =
 * stiffness_step).  Prints the tip's height, the tip segment's angle below
 * the horizontal and their quasi-static predictions (the joints' balance
 * φ_i − φ_u = c_i cos φ_i from the last anchored particle on, see
 * run_stiffness), and checks that the stiff tip stays within 1 cm of the
 * table top, that the soft tip hangs at least 5 cm lower (the paper's soft
 * shoot droops over the edge, the stiff one stays straight), and that both
 * lie within 1 cm of the prediction.
 *
 * (b) with beams: the same two shoots with dynamics.bending: beam
 * (model/particles.h, "Shoots that bend like beams"; E_1/2 = 1e7 Pa, see
 * E_HALF).  Prints their tips against the beam's quasi-static balance
 * (beam_balance) and the soft shoots' joint bends from the edge on, and
 * checks that the stiff beam tip stays within 1 cm of the table top and the
 * soft one hangs at least 5 cm lower, that both lie within 0.2 cm of the
 * balance, and that the soft beam bends most near the edge (its half of
 * the joints nearest the edge carry more than half its bend, the
 * own-weight shoot's less than half; its last joint bends less than 0.1 of
 * the larger of its first two).
 *
 * Writes climbing_fig12_phototropism.png (side views x–z),
 * climbing_fig12_phototropism_front.png (front views y–z),
 * climbing_fig12_beam.png ((b)'s four shoots side by side, the soft
 * shoots' joint bends), one VTK file per plant (climbing_fig12_<tag>.vtk)
 * and climbing_fig12_phototropism.md.
 * Exit 1 when a check fails.
 *
 * Usage: notebook_climbing_fig12_phototropism OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/grow.h"
#include "fit/shape_plots.h"
#include "measurements/plant_io.h"
#include "measurements/support_mesh.h"
#include "model/climbing_growth.h"
#include "model/climbing_tropism.h"

#include "notebook_plot.h"

#define NETA 4
#define NPLANT (NETA + 4) /* (a) the NETA plants, (b) stiff, soft, then the same two as beams */
#define NJOINT 64             /* (b): joint bends kept per shoot */
static const double PI = 3.14159265358979323846;
static const double ETA[NETA] = {0, 0.02, 0.05, 0.1};

typedef struct plant_out {
    char tag[32], title[128];
    size_t n;
    double *head, *tail, *radius, *order;
    double mean_angle; /* rad, (a) */
    double tip_z;      /* m, (b) */
    double tip_z_qs;   /* m, (b): the quasi-static tip height (model/particles.h) */
    double bend;       /* rad, (b): the tip segment's angle below the horizontal */
    double bend_qs;    /* rad, (b): the same, quasi-static */
    size_t held;       /* (b): the last particle held by an anchor */
    size_t joints;     /* (b): joints past the held particle (held + 1 .. n - 1) */
    double joint_bend[NJOINT];  /* rad, (b): each of them, φ_i − φ_u − (φ̄_i − φ̄_u), down positive */
    double joint_x[NJOINT];     /* m, (b): their x (the table edge at x = 0) */
} plant_out;

/* Copies the plant's segments for the plots and writes its VTK file. */
static int keep(const phc_climbing *c, const char *out, plant_out *p)
{
    phc_error err;
    phc_plant_graph *g = phc_grow_plant_graph(c, &err);
    if (!g) {
        fprintf(stderr, "%s\n", err.message);
        return -1;
    }
    const size_t n = g->n;
    p->n = n;
    p->head = malloc(3 * n * sizeof *p->head);
    p->tail = malloc(3 * n * sizeof *p->tail);
    p->radius = malloc(n * sizeof *p->radius);
    p->order = malloc(n * sizeof *p->order);
    if (!p->head || !p->tail || !p->radius || !p->order) {
        phc_plant_graph_free(g);
        return -1;
    }
    memcpy(p->head, g->head, 3 * n * sizeof *p->head);
    memcpy(p->tail, g->tail, 3 * n * sizeof *p->tail);
    memcpy(p->radius, g->radius, n * sizeof *p->radius);
    for (size_t i = 0; i < n; ++i)
        p->order[i] = phc_climbing_order(c, i);
    char vtk[1024];
    snprintf(vtk, sizeof vtk, "%s/climbing_fig12_%s.vtk", out, p->tag);
    const phc_plant_field f = {"branch_order", p->order};
    const int rc = phc_plant_io_write_vtk(vtk, g, p->title, &f, 1, &err);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    phc_plant_graph_free(g);
    return rc ? -1 : 0;
}

static int run_phototropism(double eta, const char *out, plant_out *p)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.seed = 12;
    o.growth_rate = 0.2;
    o.radius = 0.004;
    o.branch_probability = 0.3;
    o.max_order = 2;
    o.light.direction[0] = 1;
    o.light.direction[1] = 0;
    o.light.direction[2] = 0.3;
    o.phototropism = eta;
    const double base[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, up, &o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return -1;
    }
    for (int k = 0; k < 240; ++k)
        if (phc_climbing_step(c, 0.25, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return -1;
        }
    const double l = sqrt(1 + 0.09), light[3] = {1 / l, 0, 0.3 / l};
    double sum = 0;
    const size_t n = phc_climbing_count(c);
    for (size_t i = 0; i < n; ++i) {
        double d[3];
        phc_climbing_direction(c, i, d);
        sum += phc_climbing_angle(d, light);
    }
    p->mean_angle = sum / (double)n;
    snprintf(p->tag, sizeof p->tag, "eta%g", eta);
    snprintf(p->title, sizeof p->title, "(a) eta = %g/s: %.1f deg to light", eta, p->mean_angle * 180 / PI);
    const int rc = keep(c, out, p);
    phc_climbing_free(c);
    return rc;
}

/* E_1/2 (Pa) of the beam shoots: with s from 0.3 to 0.8 the soft shoot's
 * E = E_1/2 s/(1 − s) runs from 4.3 to 40 MPa, the stiff one's young links
 * (s >= 0.9) have >= 90 MPa: a young green shoot between the few MPa of
 * turgid parenchyma and the GPa of lignified tissue (Niklas, "Plant
 * Biomechanics", U. Chicago Press 1992; a dry mature maize rind 6–16 GPa,
 * Al-Zube et al., Plant Methods 14:2, 2018).  Ours, not calibrated. */
static const double E_HALF = 1e7;

/* Link i's stiffness s = max(s_min, min(1, age / t_m)) (model/climbing_growth.h). */
static double link_stiffness(const phc_climbing *c, const phc_climbing_options *o, size_t i)
{
    return fmax(o->min_stiffness, fmin(1, phc_climbing_age(c, i) / o->particles.maturity_age));
}

/* beam_balance's shooting step: links 1 .. nk (lengths L, masses m, springs
 * kappa, INFINITY for a weld, rest angles to the parent drest; g m s⁻²),
 * the tip link at angle `tip` (rad below the horizontal); each joint k,
 * tip first, gives its parent's angle φ_{k−1} = φ_k − drest_k − M_k/κ_k
 * from the moment M_k of the links beyond it.  Fills phi[0 .. nk] and
 * returns phi[0], the held particle's angle that balances this tip. */
static double chain_from_tip(size_t nk, const double *L, const double *m, const double *kappa, const double *drest,
                             double g, double tip, double *phi)
{
    phi[nk] = tip;
    for (size_t k = nk; k >= 1; --k) {
        double moment = 0, reach = 0; /* Σ m_j g (x_j − x_Jk) (N m); reach = x_Jj − x_Jk (m) */
        for (size_t j = k; j <= nk; ++j) {
            moment += m[j] * g * (reach + 0.5 * L[j] * cos(phi[j]));
            reach += L[j] * cos(phi[j]);
        }
        phi[k - 1] = phi[k] - drest[k] - (isfinite(kappa[k]) ? moment / kappa[k] : 0.0);
    }
    return phi[0];
}

/* The beam shoot's quasi-static balance (model/particles.h, "Shoots that
 * bend like beams": K θ = Q at every joint) in the x–z plane, from the
 * held particle (at its angle phi_held below the horizontal, its centre
 * z_held) to the tip of the chain held + 1 .. n − 1 (each link's parent the
 * one before): joint i bends by θ_i = φ_i − φ_u − (φ̄_i − φ̄_u) (rad, down
 * positive) with
 *   κ_i θ_i = g Σ_{j >= i} m_j (x_j − x_Ji)   (N m; m_j = ρ π r_j² L_j kg,
 *   x_j − x_Ji = Σ_{i <= k < j} L_k cos φ_k + L_j/2 cos φ_j, m),
 * κ_i = E_1/2 s_i/(1 − s_i) π r_i⁴/(4 ℓ̄_i), ℓ̄_i = L_i/2 (+ L_u/2 when the
 * parent bends too), and a mature link (s = 1) at its rest angle.  Solved
 * by shooting from the tip: a tip angle gives, joint by joint toward the
 * base, its parent's angle φ_u = φ_i − (φ̄_i − φ̄_u) − M_i/κ_i; bisection
 * on the tip angle until φ_held is met.  Returns the tip's height (m) and
 * the tip link's angle in *tip_phi; NAN when the chain branches or no
 * tip angle meets φ_held. */
static double beam_balance(const phc_climbing *c, const phc_climbing_options *o, size_t held, double phi_held,
                           double z_held, double *tip_phi)
{
    const size_t n = phc_climbing_count(c);
    if (n - held - 1 > NJOINT)
        return NAN;
    const double g = -o->particles.gravity[2], rho = o->particles.density;
    double L[NJOINT + 1], m[NJOINT + 1], kappa[NJOINT + 1], drest[NJOINT + 1], rphi_prev;
    {
        double rd[3];
        phc_climbing_rest_direction(c, held, rd);
        rphi_prev = atan2(-rd[2], rd[0]);
    }
    L[0] = phc_climbing_length(c, held);
    for (size_t k = 1; held + k < n; ++k) {
        const size_t i = held + k, u = i - 1;
        if (phc_climbing_parent(c, i) != u)
            return NAN;
        const double r = phc_climbing_radius(c, i), s = link_stiffness(c, o, i), su = link_stiffness(c, o, u);
        const int parent_bends = phc_climbing_parent(c, u) != PHC_CLIMBING_NONE && su > 0 && su < 1;
        L[k] = phc_climbing_length(c, i);
        m[k] = rho * PI * r * r * L[k];
        const double lbar = 0.5 * L[k] + (parent_bends ? 0.5 * L[k - 1] : 0.0);
        kappa[k] = s < 1 ? E_HALF * s / (1 - s) * PI * r * r * r * r / (4 * lbar) : INFINITY;
        double rd[3];
        phc_climbing_rest_direction(c, i, rd);
        const double rphi = atan2(-rd[2], rd[0]);
        drest[k] = rphi - rphi_prev;
        rphi_prev = rphi;
    }
    const size_t nk = n - held - 1; /* joints 1 .. nk */
    double phi[NJOINT + 1];
    const int steps = 4000;
    double lo = NAN, hi = NAN, prev_tip = -PI / 2;
    double prev_miss = chain_from_tip(nk, L, m, kappa, drest, g, prev_tip, phi) - phi_held;
    for (int k = 1; k <= steps && isnan(lo); ++k) {
        const double tip = -PI / 2 + PI * k / steps;
        const double miss = chain_from_tip(nk, L, m, kappa, drest, g, tip, phi) - phi_held;
        if ((miss > 0) != (prev_miss > 0)) {
            lo = prev_tip;
            hi = tip;
        }
        prev_tip = tip;
        prev_miss = miss;
    }
    if (isnan(lo))
        return NAN;
    const int lo_positive = chain_from_tip(nk, L, m, kappa, drest, g, lo, phi) - phi_held > 0;
    for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        if ((chain_from_tip(nk, L, m, kappa, drest, g, mid, phi) - phi_held > 0) == lo_positive)
            lo = mid;
        else
            hi = mid;
    }
    chain_from_tip(nk, L, m, kappa, drest, g, 0.5 * (lo + hi), phi);
    double z = z_held - 0.5 * L[0] * sin(phi_held);
    for (size_t k = 1; k <= nk; ++k)
        z -= L[k] * sin(phi[k]);
    *tip_phi = phi[nk];
    return z;
}

static int run_stiffness(int stiff, int beam, const phc_support_mesh *table, const char *out, plant_out *p)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.seed = 1;
    o.growth_rate = 0.2;
    o.radius = 0.003;
    o.branch_probability = 0;
    o.surface_adaption = 0; /* straight over the edge: gravity and stiffness decide */
    o.closest = phc_support_mesh_closest;
    o.closest_user = (void *)table;
    o.dynamics_substeps = 5;
    o.particles.maturity_age = stiff ? 2 : 50;
    o.min_stiffness = stiff ? 0.9 : 0.3;
    if (beam) {
        o.particles.bending = PHC_PARTICLES_BEAM;
        o.particles.beam_modulus = E_HALF;
    }
    const double base[3] = {-0.01, 0, 0.003}, east[3] = {1, 0, 0};
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, east, &o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return -1;
    }
    for (int k = 0; k < 800; ++k)
        if (phc_climbing_step(c, 0.05, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return -1;
        }
    /* the tip: the end of the last particle of the main axis */
    const size_t n = phc_climbing_count(c);
    double b[3], t[3];
    phc_climbing_segment(c, n - 1, b, t);
    p->tip_z = t[2];
    /* quasi-static (model/particles.h, "Shoots that bend", the limit
       Δt -> 0): from the last particle held by an anchor on, each link i
       turns down from its rest angle to its parent by c_i cos φ_i,
       φ_i = φ_u + (φ̄_i − φ̄_u) + c_i cos φ_i, c_i = 2 g T² (1 − s_i)/(s_i L_i),
       s_i = max(s_min, min(1, age / t_m)) (model/climbing_growth.h); φ the
       angle below the horizontal in the x–z plane (Newton per link). */
    const double T = o.particles.stiffness_step, g = -o.particles.gravity[2];
    size_t held = 0;
    for (size_t i = 0; i < n; ++i) {
        double a[3];
        if (phc_climbing_anchor(c, i, a))
            held = i;
    }
    double d[3], rd[3], x[3];
    phc_climbing_direction(c, held, d);
    phc_climbing_rest_direction(c, held, rd);
    phc_climbing_position(c, held, x);
    double phi = atan2(-d[2], d[0]), rphi = atan2(-rd[2], rd[0]);
    p->tip_z_qs = x[2] - 0.5 * phc_climbing_length(c, held) * sin(phi);
    for (size_t i = held + 1; i < n; ++i) {
        const double si = link_stiffness(c, &o, i);
        const double Li = phc_climbing_length(c, i), ci = 2 * g * T * T * (1 - si) / (si * Li);
        phc_climbing_rest_direction(c, i, rd);
        const double rphi_i = atan2(-rd[2], rd[0]), pu = phi + (rphi_i - rphi);
        for (int it = 0; it < 100; ++it) /* φ − pu − c cos φ = 0 */
            phi -= (phi - pu - ci * cos(phi)) / (1 + ci * sin(phi));
        rphi = rphi_i;
        p->tip_z_qs -= Li * sin(phi);
    }
    p->bend_qs = phi;
    if (beam) {
        phc_climbing_direction(c, held, d);
        p->tip_z_qs = beam_balance(c, &o, held, atan2(-d[2], d[0]), x[2], &p->bend_qs);
    }
    phc_climbing_direction(c, n - 1, d);
    p->bend = atan2(-d[2], d[0]); /* the tip segment's angle below the horizontal */
    p->held = held;
    /* the joints' bends from their rest angles */
    p->joints = 0;
    phc_climbing_direction(c, held, d);
    phc_climbing_rest_direction(c, held, rd);
    double prev = atan2(-d[2], d[0]), rprev = atan2(-rd[2], rd[0]);
    for (size_t i = held + 1; i < n && p->joints < NJOINT; ++i) {
        phc_climbing_direction(c, i, d);
        phc_climbing_rest_direction(c, i, rd);
        const double a = atan2(-d[2], d[0]), ra = atan2(-rd[2], rd[0]);
        phc_climbing_segment(c, i, b, t);
        p->joint_x[p->joints] = b[0];
        p->joint_bend[p->joints++] = (a - prev) - (ra - rprev);
        prev = a;
        rprev = ra;
    }
    snprintf(p->tag, sizeof p->tag, "%s%s", beam ? "beam_" : "", stiff ? "stiff" : "soft");
    if (beam)
        snprintf(p->title, sizeof p->title, "(b) beam, %s: tip z = %.1f cm", stiff ? "high" : "low", 100 * p->tip_z);
    else
        snprintf(p->title, sizeof p->title, "(b) %s stiffness: tip z = %.1f cm", stiff ? "high" : "low",
                 100 * p->tip_z);
    const int rc = keep(c, out, p);
    phc_climbing_free(c);
    return rc;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started)
        return started;
    plant_out pl[NPLANT];
    memset(pl, 0, sizeof pl);
    for (int k = 0; k < NETA; ++k)
        if (run_phototropism(ETA[k], out, &pl[k]))
            return 1;
    const double tv[12] = {-0.5, -0.25, 0, 0, -0.25, 0, 0, 0.25, 0, -0.5, 0.25, 0};
    const size_t tt[6] = {0, 1, 2, 0, 2, 3};
    phc_error err;
    phc_support_mesh *table = phc_support_mesh_from_arrays(tv, 4, tt, 2, "table top", &err);
    if (!table) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    if (run_stiffness(1, 0, table, out, &pl[NETA]) || run_stiffness(0, 0, table, out, &pl[NETA + 1]) ||
        run_stiffness(1, 1, table, out, &pl[NETA + 2]) || run_stiffness(0, 1, table, out, &pl[NETA + 3]))
        return 1;
    double marker[12];
    for (int i = 0; i < 4; ++i)
        memcpy(marker + 3 * i, tv + 3 * i, 3 * sizeof(double));

    phc_shape_panel pan[NPLANT];
    for (int k = 0; k < NPLANT; ++k) {
        pan[k] = (phc_shape_panel){pl[k].n, pl[k].head, pl[k].tail, pl[k].radius, pl[k].order, pl[k].title,
                                   k >= NETA ? 4 : 0, k >= NETA ? marker : NULL, "table corners"};
    }
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.value_label = "branch order (0 = main axis)";
    po.value_min = 0;
    po.value_max = 2;
    po.columns = 2;
    po.max_line_width = 5;
    char png[1024];
    po.title = "Fig. 12: (a) light from +x, (b) over an edge; side";
    snprintf(png, sizeof png, "%s/climbing_fig12_phototropism.png", out);
    if (phc_shape_plot(png, pan, NPLANT, &po, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    po.title = "Fig. 12: front views (y-z)";
    po.across_axis = 1;
    snprintf(png, sizeof png, "%s/climbing_fig12_phototropism_front.png", out);
    if (phc_shape_plot(png, pan, NPLANT, &po, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }

    printf("climbing Fig. 12 (a): seed 12, 60 s in steps of 0.25 s, BP 0.3, orders <= 2, light toward (1, 0, 0.3)\n");
    int falls = 1;
    for (int k = 0; k < NETA; ++k) {
        printf("  eta %.2f/s: %4zu particles, mean angle of the particles' directions to the light %6.2f deg\n", ETA[k],
               pl[k].n, pl[k].mean_angle * 180 / PI);
        if (k > 0)
            falls &= pl[k].mean_angle < pl[k - 1].mean_angle;
    }
    printf("check: the mean angle falls as eta rises: %s\n", falls ? "pass" : "FAIL");
    const double z_stiff = pl[NETA].tip_z, z_soft = pl[NETA + 1].tip_z;
    printf("climbing Fig. 12 (b): a shoot grown 40 s toward +x from 1 cm before a table edge (top z = 0), dynamics in "
           "0.01 s substeps\n");
    for (int k = NETA; k < NETA + 2; ++k)
        printf("  %s stiffness (t_m %s s, s_min %s): %2zu particles, %2zu held on the table, tip z = %7.2f cm "
               "(quasi-static %7.2f cm), tip segment %5.1f deg below the horizontal (quasi-static %5.1f deg)\n",
               k == NETA ? "high" : "low", k == NETA ? "2" : "50", k == NETA ? "0.90" : "0.30", pl[k].n,
               pl[k].held + 1, 100 * pl[k].tip_z, 100 * pl[k].tip_z_qs, pl[k].bend * 180 / PI,
               pl[k].bend_qs * 180 / PI);
    const int level = fabs(z_stiff) < 0.01;
    printf("check: the stiff tip stays within 1 cm of the table top, %.2f cm: %s\n", 100 * z_stiff,
           level ? "pass" : "FAIL");
    const int hangs = z_soft < z_stiff - 0.05;
    printf("check: the soft tip hangs at least 5 cm lower, by %.2f cm: %s\n", 100 * (z_stiff - z_soft),
           hangs ? "pass" : "FAIL");
    const double qs_off = fmax(fabs(z_stiff - pl[NETA].tip_z_qs), fabs(z_soft - pl[NETA + 1].tip_z_qs));
    const int qs = qs_off < 0.01;
    printf("check: both tips within 1 cm of the quasi-static height, largest difference %.3f cm: %s\n",
           100 * qs_off, qs ? "pass" : "FAIL");
    /* the same two shoots as beams */
    const plant_out *bs = &pl[NETA + 2], *bw = &pl[NETA + 3], *ow = &pl[NETA + 1];
    double inner_share[2]; /* the share of the soft shoots' total bend in the half of the joints nearest the edge */
    printf("the same shoots with dynamics.bending: beam (E_1/2 %.0e Pa: E = E_1/2 s/(1 - s), %.1f to %.0f MPa for "
           "the soft shoot's s 0.3 to 0.8):\n",
           E_HALF, 1e-6 * E_HALF * 0.3 / 0.7, 1e-6 * E_HALF * 0.8 / 0.2);
    for (int k = NETA + 2; k < NETA + 4; ++k)
        printf("  %s stiffness, beam: %2zu particles, %2zu held on the table, tip z = %7.2f cm (quasi-static beam "
               "balance %7.2f cm), tip segment %5.1f deg below the horizontal (quasi-static %5.1f deg)\n",
               k == NETA + 2 ? "high" : "low", pl[k].n, pl[k].held + 1, 100 * pl[k].tip_z, 100 * pl[k].tip_z_qs,
               pl[k].bend * 180 / PI, pl[k].bend_qs * 180 / PI);
    for (int k = 0; k < 2; ++k) {
        const plant_out *q = k ? bw : ow;
        size_t big = 0;
        for (size_t j = 0; j < q->joints; ++j)
            if (q->joint_bend[j] > q->joint_bend[big])
                big = j;
        printf("  low stiffness, %-10s joint bends (deg) from the edge on:", k ? "beam:" : "own weight:");
        for (size_t j = 0; j < q->joints; ++j)
            printf(" %.1f", q->joint_bend[j] * 180 / PI);
        double inner = 0, total = 0;
        for (size_t j = 0; j < q->joints; ++j) {
            total += q->joint_bend[j];
            inner += j < q->joints / 2 ? q->joint_bend[j] : 0.0;
        }
        inner_share[k] = inner / total;
        printf("; largest at joint %zu (x = %.1f cm), first/last %.1f, the %zu joints nearest the edge %.0f%% of "
               "the total %.1f deg\n",
               big + 1, 100 * q->joint_x[big], q->joint_bend[0] / q->joint_bend[q->joints - 1], q->joints / 2,
               100 * inner_share[k], total * 180 / PI);
    }
    const int b_level = fabs(bs->tip_z) < 0.01, b_hangs = bw->tip_z < bs->tip_z - 0.05;
    printf("check: beam: the stiff tip stays within 1 cm of the table top, %.2f cm, and the soft tip hangs at least "
           "5 cm lower, by %.2f cm: %s\n",
           100 * bs->tip_z, 100 * (bs->tip_z - bw->tip_z), b_level && b_hangs ? "pass" : "FAIL");
    const double b_off = fmax(fabs(bs->tip_z - bs->tip_z_qs), fabs(bw->tip_z - bw->tip_z_qs));
    const int b_qs = b_off < 0.002;
    printf("check: beam: both tips within 0.2 cm of the quasi-static beam balance, largest difference %.3f cm: %s\n",
           100 * b_off, b_qs ? "pass" : "FAIL");
    const double last_of_largest = bw->joint_bend[bw->joints - 1] / fmax(bw->joint_bend[0], bw->joint_bend[1]);
    const int b_where = inner_share[1] > 0.5 && inner_share[0] < 0.5 && last_of_largest < 0.1;
    printf("check: the soft beam bends most near the edge: its half of the joints nearest the edge carry %.0f%% > "
           "50%% of its bend (own weight %.0f%% < 50%%), its last joint bends %.3f < 0.1 of its first two's "
           "largest: %s\n",
           100 * inner_share[1], 100 * inner_share[0], last_of_largest, b_where ? "pass" : "FAIL");
    const int ok = falls && level && hangs && qs && b_level && b_hangs && b_qs && b_where;

    /* (b)'s four shoots side by side (x–z, cm) and the soft ones' joint bends */
    static double sx[4][NJOINT + 2], sz[4][NJOINT + 2], jx[2][NJOINT], jb[2][NJOINT];
    size_t sn[4];
    for (int k = 0; k < 4; ++k) {
        const plant_out *q = &pl[NETA + k];
        sn[k] = q->n + 1 <= NJOINT + 2 ? q->n + 1 : NJOINT + 2;
        for (size_t i = 0; i + 1 < sn[k]; ++i) {
            sx[k][i] = 100 * q->head[3 * i];
            sz[k][i] = 100 * q->head[3 * i + 2];
        }
        sx[k][sn[k] - 1] = 100 * q->tail[3 * (sn[k] - 2)];
        sz[k][sn[k] - 1] = 100 * q->tail[3 * (sn[k] - 2) + 2];
    }
    for (int k = 0; k < 2; ++k) {
        const plant_out *q = k ? bw : ow;
        for (size_t j = 0; j < q->joints; ++j) {
            jx[k][j] = 100 * q->joint_x[j];
            jb[k][j] = q->joint_bend[j] * 180 / PI;
        }
    }
    static const double table_x[2] = {-4, 0}, table_z[2] = {0, 0};
    const nb_series side[5] = {
        {table_x, table_z, 2, "table top (edge at x = 0)", NB_BLACK, 0, 0, 4},
        {sx[0], sz[0], sn[0], "high stiffness, own weight", NB_BLUE, 0, 0, 0},
        {sx[1], sz[1], sn[1], "low stiffness, own weight", NB_RED, 0, 0, 0},
        {sx[2], sz[2], sn[2], "high stiffness, beam (on the own-weight line)", NB_ORANGE, 1, 0, 0},
        {sx[3], sz[3], sn[3], "low stiffness, beam", NB_PURPLE, 1, 0, 0},
    };
    const nb_series bends[2] = {
        {jx[0], jb[0], ow->joints, "low stiffness, own weight", NB_RED, 0, 0, 0},
        {jx[1], jb[1], bw->joints, "low stiffness, beam", NB_PURPLE, 1, 0, 0},
    };
    const nb_panel bpan[2] = {
        {"(b) over the edge after 40 s, side view", "x (cm)", "z (cm)", 0, -14, 1, 4, side, 5},
        {"(b) soft shoots: bend of each joint", "joint x (cm; the edge at 0)", "bend from rest (deg)", 0, 0, 0, 2,
         bends, 2},
    };
    snprintf(png, sizeof png, "%s/climbing_fig12_beam.png", out);
    if (nb_plot(png, 1200, 520, 2, 1, bpan, 2)) {
        fprintf(stderr, "%s: cannot write the figure\n", png);
        return 1;
    }

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "climbing_fig12_phototropism.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Climbing plants, Fig. 12: phototropism and stiffness\n\n"
            "**The paper's figure** (Hädrich et al., CGF 2017, Fig. 12): plants bend toward light from\n"
            "one side (phototropism, eq. 7), and stiff shoots keep their shape where soft ones hang.\n\n"
            "**What we computed** (`model/climbing_growth.h`): (a) one seed, light toward (1, 0, 0.3),\n"
            "η = 0, 0.02, 0.05, 0.1 /s, kinematic growth for 60 s; (b) a shoot grown over the edge of a\n"
            "table-top support mesh with dynamics, stiffness high (t_m 2 s, s_min 0.9) and low (t_m\n"
            "50 s, s_min 0.3), with the own-weight joint pass and again as beams (dynamics.bending:\n"
            "beam, E_1/2 1e7 Pa). The values are ours (the figure's were not available to us).\n\n"
            "![side views](climbing_fig12_phototropism.png)\n\n"
            "![(b) own weight against beam](climbing_fig12_beam.png)\n\n"
            "![front views](climbing_fig12_phototropism_front.png)\n\n"
            "| plant | particles | mean angle to the light (deg) | tip z (cm) |\n|---|---|---|---|\n");
    for (int k = 0; k < NPLANT; ++k)
        if (k < NETA)
            fprintf(f, "| η = %g /s | %zu | %.2f | |\n", ETA[k], pl[k].n, pl[k].mean_angle * 180 / PI);
        else
            fprintf(f, "| %s | %zu | | %.2f |\n", pl[k].tag, pl[k].n, 100 * pl[k].tip_z);
    fprintf(f, "\n**Checks**: %s.\n\nThe meshes `climbing_fig12_*.vtk` open in ParaView.\n\n"
               "**How ours differs.** As in the paper, the stiff shoot keeps its shape over the edge (its\n"
               "links older than t_m = 2 s have s = 1 and are held exactly at their rest angles) and the\n"
               "soft one bends down over it (each young link turns about its joint until its own weight\n"
               "and its angular spring balance, c cos φ with c = 2 g T^2 (1 - s)/(s L), T = 0.01 s). A link\n"
               "carries its own weight only, not the moment of the shoot beyond it, and the soft shoot\n"
               "creeps down without swinging. As beams (each joint on a spring E(s) pi r^4/(4 l) under the\n"
               "moment of the shoot beyond it) the stiff shoot keeps its shape as well and the soft one\n"
               "bends over the edge less (tip %.2f cm against %.2f cm), most in the joints nearest the\n"
               "edge (%.0f%% of its bend in the half nearest the edge; own weight %.0f%%) and hardly at the\n"
               "tip, at its quasi-static beam balance (%.2f cm).\n",
            ok ? "all pass" : "**some FAIL** (see the program's output)", 100 * bw->tip_z, 100 * ow->tip_z,
            100 * inner_share[1], 100 * inner_share[0], 100 * bw->tip_z_qs);
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    for (int k = 0; k < NPLANT; ++k) {
        free(pl[k].head);
        free(pl[k].tail);
        free(pl[k].radius);
        free(pl[k].order);
    }
    phc_support_mesh_free(table);
    printf("%s: %s\n", ok ? "ok" : "FAIL", out);
    return !ok;
}
