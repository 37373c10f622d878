/* `shape_series` data sets: see shape_series.h. */
#include "fit/costs/shape_series.h"

#include <math.h>

#define PHC_SS_PI 3.14159265358979323846
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/shape_water.h"
#include "fit/run_dir.h"
#include "fit/shape_plots.h"
#include "measurements/plant_io.h"
#include "model/elasticity.h"
#include "model/particles.h"
#include "model/plant_graph.h"
#include "model/rod.h"

#define CLAMP_FRACTION 1e-3

enum { SLOT_KAPPA = 0, SLOT_CHI0, SLOT_E_MAX, SLOT_DELTA, N_SHARED };

typedef struct stalk {
    char *id;
    phc_plant_graph *g; /* segment 0: the clamp (root), 1..n free */
    phc_rod *rod;       /* rods only */
    double *young;      /* g->n moduli, Pa (work) */
    double *force;      /* particles: 3 g->n external forces, N (the tip masses' weight);
                           the data set's plant_force when shared */
    double *head, *tail;/* particles: 3 g->n segment ends of the last solve, m (work) */
    double rest_length; /* particles: shortest free segment, m (the rest test's scale) */
    double beta;        /* base angle, rad */
    double tip_mass;    /* kg */
    long offset_slot;   /* slot of offset_<id>, or -1 */
    size_t seg;         /* the segment whose direction is the angle */
    int shared;         /* 1: g and rod are the data set's plant (not owned) */
    double *sens;       /* rods: 8 g->n work for the sensitivities: dz or the
                           angle's gradient (6n), a direction (n), dangle/dE_i (n) */
} stalk;

typedef struct shape_impl {
    size_t n_stalks;
    stalk *stalks;
    size_t *stalk_of;   /* [n] stalk of each observation */
    double *t;          /* [n] s */
    double t0, rwc0, e_min, fd_step; /* fd_step: particles only */
    long e_min_slot;    /* slot of e_min, or -1 */
    size_t frames;
    phc_plant_graph *plant; /* options.plant's copy, or NULL */
    phc_rod *plant_rod;     /* rods with a plant */
    double *plant_force;    /* particles with a plant: 3n forces, N */
    int dynamics;           /* phc_shape_dynamics */
    phc_particles_options popt; /* particles: density, iterations, damping, parent weight */
    double pdt;             /* particles: time step, s */
    size_t psteps;          /* particles: step cap */
    size_t last_steps;      /* particles: steps of the last relaxation */
    phc_shape_water *water; /* options.water_model: the water model on the plant, or NULL */
    double *x, *dx;         /* plant->n: relative water content, d x / d δ (work) */
    double *grad_e;         /* k x plant->n: d E_i / d slot (work) */
} shape_impl;

static void impl_free(void *p)
{
    shape_impl *m = p;
    if (!m)
        return;
    for (size_t s = 0; s < m->n_stalks; ++s) {
        if (!m->stalks[s].shared) {
            phc_rod_free(m->stalks[s].rod);
            phc_plant_graph_free(m->stalks[s].g);
            free(m->stalks[s].force);
        }
        free(m->stalks[s].head);
        free(m->stalks[s].tail);
        free(m->stalks[s].sens);
        free(m->stalks[s].young);
        free(m->stalks[s].id);
    }
    free(m->stalks);
    phc_rod_free(m->plant_rod);
    free(m->plant_force);
    phc_plant_graph_free(m->plant);
    phc_shape_water_free(m->water);
    free(m->x);
    free(m->dx);
    free(m->grad_e);
    free(m->stalk_of);
    free(m->t);
    free(m);
}

phc_shape_series_options phc_shape_series_options_default(void)
{
    phc_shape_series_options o = {0};
    o.rwc0 = 1.0;
    o.t0 = NAN;
    o.e_min = 1e4;
    o.density = 1000.0;
    o.every = 1;
    o.fd_step = 1e-4;
    o.frames = 6;
    o.dynamics = PHC_SHAPE_RODS;
    o.particle_iterations = 16;
    o.particle_time_step = 5e-4;
    o.particle_steps = 20000;
    o.particle_damping = 0.1;
    o.parent_weight = 2.0;
    return o;
}

/* E(t) = E_min + E_max σ(κ (RWC(t) − χ0)), RWC(t) = RWC0 exp(−δ (t − t0))
 * (wilting eq. 9 with a single compartment); grad (optional, k entries,
 * zeroed by the caller): d E / d slot. */
static double modulus(const phc_dataset *ds, const double *p, double t, double *rwc_out, double *grad)
{
    const shape_impl *m = ds->impl;
    const double kappa = p[SLOT_KAPPA], chi0 = p[SLOT_CHI0], e_max = p[SLOT_E_MAX], delta = p[SLOT_DELTA];
    const double e_min = m->e_min_slot >= 0 ? p[m->e_min_slot] : m->e_min;
    const double dt = t - m->t0;
    const double rwc = m->rwc0 * exp(-delta * dt);
    const double s = phc_elasticity_sigmoid(kappa * (rwc - chi0));
    const double ds_du = s * (1.0 - s);
    if (rwc_out)
        *rwc_out = rwc;
    if (grad) {
        grad[SLOT_KAPPA] = e_max * ds_du * (rwc - chi0);
        grad[SLOT_CHI0] = -e_max * ds_du * kappa;
        grad[SLOT_E_MAX] = s;
        grad[SLOT_DELTA] = e_max * ds_du * kappa * (-dt * rwc);
        if (m->e_min_slot >= 0)
            grad[m->e_min_slot] = 1.0;
    }
    return e_min + e_max * s;
}

int phc_shape_series_modulus(const phc_dataset *ds, const double *p, double t, double *young, double *rwc)
{
    if (((const shape_impl *)ds->impl)->water)
        return 1; /* a modulus per segment */
    *young = modulus(ds, p, t, rwc, NULL);
    return isfinite(*young) && *young > 0 ? 0 : 1;
}

/* The scalar the angle depends on: E(t) (Pa) with rods, s(t) = E(t) /
 * (E_min + E_max) with particles; grad (optional, zeroed by the caller) its
 * derivative in every slot. */
static double driver(const phc_dataset *ds, const double *p, double t, double *grad)
{
    const shape_impl *m = ds->impl;
    const double E = modulus(ds, p, t, NULL, grad);
    if (m->dynamics != PHC_SHAPE_PARTICLES)
        return E;
    const double e_min = m->e_min_slot >= 0 ? p[m->e_min_slot] : m->e_min;
    const double D = e_min + p[SLOT_E_MAX], s = E / D;
    if (grad) {
        for (size_t j = 0; j < ds->k; ++j)
            grad[j] /= D;
        grad[SLOT_E_MAX] -= s / D;
        if (m->e_min_slot >= 0)
            grad[m->e_min_slot] -= s / D;
    }
    return s;
}

int phc_shape_series_stiffness(const phc_dataset *ds, const double *p, double t, double *stiffness)
{
    const shape_impl *m = ds->impl;
    const double e_min = m->e_min_slot >= 0 ? p[m->e_min_slot] : m->e_min;
    *stiffness = modulus(ds, p, t, NULL, NULL) / (e_min + p[SLOT_E_MAX]);
    return isfinite(*stiffness) && *stiffness >= 0 && *stiffness <= 1 ? 0 : 1;
}

/* The direction of segment seg (head h → tail t) in the x–z plane, within π
 * of β. */
static double direction(const stalk *st, const double h[3], const double t[3])
{
    const double a = atan2(t[2] - h[2], t[0] - h[0]);
    return st->beta + remainder(a - st->beta, 2.0 * PHC_SS_PI);
}

/* The gradients of direction() with respect to the tail (g_tail) and the
 * head (g_head = −g_tail), rad/m: a = atan2(d_z, d_x), d = t − h, so
 * ∂a/∂t = (−d_z, 0, d_x) / (d_x² + d_z²). */
static void direction_gradient(const double h[3], const double t[3], double g_head[3], double g_tail[3])
{
    const double dx = t[0] - h[0], dz = t[2] - h[2], r2 = dx * dx + dz * dz;
    g_tail[0] = -dz / r2;
    g_tail[1] = 0.0;
    g_tail[2] = dx / r2;
    for (int k = 0; k < 3; ++k)
        g_head[k] = -g_tail[k];
}

/* Rods, after a successful rod_solve: d angle / dE with every segment at
 * the same E (rad/Pa), exact: one sensitivity solve of the equilibrium
 * (phc_rod_static_sensitivity along dE_i = 1) and the angle's analytic
 * gradient in the segment's head and tail. */
static int rod_angle_derivative(stalk *st, double *da_dE, phc_error *err)
{
    const size_t n = st->g->n;
    double *dz = st->sens, *dir = st->sens + 6 * n;
    for (size_t i = 0; i < n; ++i)
        dir[i] = 1.0;
    int rc = phc_rod_static_sensitivity(st->rod, 1, dir, dz, err);
    if (rc)
        return rc;
    double h[3], t[3], gh[3], gt[3], dh[3], dt[3];
    phc_rod_head(st->rod, st->seg, h);
    phc_rod_tail(st->rod, st->seg, t);
    direction_gradient(h, t, gh, gt);
    phc_rod_end_sensitivity(st->rod, st->seg, dz, dh, dt);
    *da_dE = 0.0;
    for (int k = 0; k < 3; ++k)
        *da_dE += gh[k] * dh[k] + gt[k] * dt[k];
    return isfinite(*da_dE) ? 0 : phc_error_set(err, PHC_ERR_NUMERIC, "series '%s': d angle / dE is not finite", st->id);
}

/* Rods with a modulus per segment, after a successful rod_solve_young:
 * d angle / dE_i for every segment i (st->sens + 7n, rad/Pa), exact: one
 * adjoint solve (phc_rod_static_adjoint) of the angle's gradient. */
static int rod_angle_adjoint(stalk *st, const double **da_dE, phc_error *err)
{
    const size_t n = st->g->n;
    double *gz = st->sens, *out = st->sens + 7 * n;
    double h[3], t[3], gh[3], gt[3];
    memset(gz, 0, 6 * n * sizeof *gz);
    phc_rod_head(st->rod, st->seg, h);
    phc_rod_tail(st->rod, st->seg, t);
    direction_gradient(h, t, gh, gt);
    phc_rod_end_gradient(st->rod, st->seg, gh, gt, gz + 6 * st->seg);
    int rc = phc_rod_static_adjoint(st->rod, gz, out, err);
    *da_dE = out;
    return rc;
}

/* Particles at stiffness s relaxed from the rest pose to rest (see the
 * header); the segment ends are left in st->head, st->tail. */
static int particles_solve(shape_impl *m, stalk *st, double s, double *angle, phc_error *err)
{
    if (!(s >= 0 && s <= 1))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "series '%s': particle stiffness s = E/(E_min + E_max) = %g is outside [0, 1] "
                             "(E_max or E_min negative?)", st->id, s);
    phc_particles_options po = m->popt;
    po.stiffness = s;
    phc_particles *p = phc_particles_new(st->g, &po, err);
    if (!p)
        return err ? err->status : PHC_ERR_INPUT;
    const size_t n = st->g->n;
    int rc = PHC_OK;
    for (size_t i = 0; i < n && !rc; ++i)
        if (st->force[3 * i] != 0 || st->force[3 * i + 1] != 0 || st->force[3 * i + 2] != 0)
            rc = phc_particles_set_force(p, i, st->force + 3 * i, err);
    const double tol = PHC_SHAPE_REST_FRACTION * st->rest_length / m->pdt; /* m s^-1 */
    double vmax = INFINITY;
    size_t k = 0, settle = 0, at_rest = 0;
    /* to rest (vmax < tol), then a quarter as many steps again: the step
     * count to rest changes in jumps with s, and the settling steps shrink
     * the angle's jump there by the decay over k/4 steps (about 6 more
     * decades), so that the angle is smooth in s to the differences'
     * accuracy */
    while (!rc && (at_rest ? settle < at_rest / 4 : k < m->psteps)) {
        if ((rc = phc_particles_step(p, m->pdt, NULL, err)))
            break;
        ++k;
        vmax = 0;
        for (size_t i = 0; i < n; ++i) {
            double v[3];
            phc_particles_velocity(p, i, v);
            vmax = fmax(vmax, sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
        }
        if (!isfinite(vmax))
            rc = phc_error_set(err, PHC_ERR_DOMAIN, "series '%s': the particles' speed is not finite after %zu steps",
                               st->id, k);
        else if (at_rest)
            ++settle;
        else if (vmax < tol)
            at_rest = k;
    }
    m->last_steps = k;
    /* after settling the speed may have risen above tol again (the decay
     * oscillates), not by orders of magnitude */
    if (!rc && (!at_rest || !(vmax < 1e3 * tol)))
        rc = phc_error_set(err, PHC_ERR_DOMAIN,
                           "series '%s': the particles are not at rest after particle_steps = %zu steps of %g s "
                           "(stiffness s = %g, largest speed %.3g m/s, at rest below %.3g m/s): raise particle_steps "
                           "or particle_damping",
                           st->id, m->psteps, m->pdt, s, vmax, tol);
    if (!rc) {
        phc_particles_segment_ends(p, st->head, st->tail);
        *angle = direction(st, st->head + 3 * st->seg, st->tail + 3 * st->seg);
        if (!isfinite(*angle))
            rc = phc_error_set(err, PHC_ERR_DOMAIN, "series '%s': the angle at rest is not finite", st->id);
    }
    phc_particles_free(p);
    return rc;
}

/* Equilibrium from the rod's current state at modulus E; the last
 * segment's direction within π of β. */
static int rod_solve_young(stalk *st, const double *young, double *angle, phc_error *err);

static int rod_solve(stalk *st, double young, double *angle, phc_error *err)
{
    if (!(young > 0) || !isfinite(young))
        return phc_error_set(err, PHC_ERR_DOMAIN, "series '%s': the modulus E = %g Pa is not positive", st->id,
                             young);
    for (size_t i = 0; i < st->g->n; ++i)
        st->young[i] = young;
    return rod_solve_young(st, st->young, angle, err);
}

/* The same with a modulus per segment (Pa, g->n; may be st->young). */
static int rod_solve_young(stalk *st, const double *young, double *angle, phc_error *err)
{
    for (size_t i = 0; i < st->g->n; ++i)
        if (!(young[i] > 0) || !isfinite(young[i]))
            return phc_error_set(err, PHC_ERR_DOMAIN, "series '%s': the modulus of segment %zu is %g Pa, not positive",
                                 st->id, i, young[i]);
    phc_rod_report rep;
    int rc;
    if ((rc = phc_rod_set_modulus(st->rod, young, err)) || (rc = phc_rod_solve_static(st->rod, &rep, err)))
        return rc;
    double h[3], t[3];
    phc_rod_head(st->rod, st->seg, h);
    phc_rod_tail(st->rod, st->seg, t);
    *angle = direction(st, h, t);
    return isfinite(*angle) ? 0 : phc_error_set(err, PHC_ERR_DOMAIN, "series '%s': the angle is not finite", st->id);
}

/* The angle at the driver z (E with rods, s with particles). */
static int solve_angle(shape_impl *m, stalk *st, double z, double *angle, phc_error *err)
{
    return m->dynamics == PHC_SHAPE_PARTICLES ? particles_solve(m, st, z, angle, err) : rod_solve(st, z, angle, err);
}

size_t phc_shape_series_particle_steps(const phc_dataset *ds)
{
    const shape_impl *m = ds->impl;
    return m->last_steps;
}

int phc_shape_series_stalk_angle(phc_dataset *ds, size_t s, double z, double *angle, phc_error *err)
{
    shape_impl *m = ds->impl;
    if (s >= m->n_stalks)
        return phc_error_set(err, PHC_ERR_INVALID, "shape_series: no stalk %zu", s);
    if (m->dynamics != PHC_SHAPE_PARTICLES)
        phc_rod_reset(m->stalks[s].rod);
    return solve_angle(m, &m->stalks[s], z, angle, err);
}

/* With the water model: every segment's relative water content x_i(t)
 * (m->x) and modulus E_i (young, Pa), and with grad the exact d E_i / d slot
 * (m->grad_e, k x n).  The pass over the times must be started first. */
static int segment_moduli(const phc_dataset *ds, const double *p, double t, double *young, int grad)
{
    shape_impl *m = ds->impl;
    const double kappa = p[SLOT_KAPPA], chi0 = p[SLOT_CHI0], e_max = p[SLOT_E_MAX];
    const double e_min = m->e_min_slot >= 0 ? p[m->e_min_slot] : m->e_min;
    phc_error e;
    if (!(t >= m->t0) || phc_shape_water_at(m->water, t - m->t0, m->x, grad ? m->dx : NULL, &e))
        return 1;
    const size_t n = m->plant->n;
    if (grad)
        memset(m->grad_e, 0, ds->k * n * sizeof *m->grad_e);
    for (size_t i = 0; i < n; ++i) {
        const double s = phc_elasticity_sigmoid(kappa * (m->x[i] - chi0)), ds_du = s * (1.0 - s);
        young[i] = e_min + e_max * s;
        if (!grad)
            continue;
        m->grad_e[SLOT_KAPPA * n + i] = e_max * ds_du * (m->x[i] - chi0);
        m->grad_e[SLOT_CHI0 * n + i] = -e_max * ds_du * kappa;
        m->grad_e[SLOT_E_MAX * n + i] = s;
        m->grad_e[SLOT_DELTA * n + i] = e_max * ds_du * kappa * m->dx[i];
        if (m->e_min_slot >= 0)
            m->grad_e[(size_t)m->e_min_slot * n + i] = 1.0;
    }
    return 0;
}

/* predict with the water model: one pass of the water per series. */
static int predict_water(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    shape_impl *m = ds->impl;
    const size_t n = m->plant->n;
    if (jac)
        memset(jac, 0, ds->n * ds->k * sizeof *jac);
    size_t prev = (size_t)-1;
    phc_error e;
    for (size_t i = 0; i < ds->n; ++i) {
        stalk *st = &m->stalks[m->stalk_of[i]];
        if (m->stalk_of[i] != prev) { /* a new series: from the rest shape and t0 */
            phc_rod_reset(st->rod);
            if (phc_shape_water_start(m->water, p[SLOT_DELTA], m->rwc0, jac != NULL, &e))
                return 1;
            prev = m->stalk_of[i];
        }
        double a;
        if (segment_moduli(ds, p, m->t[i], st->young, jac != NULL) || rod_solve_young(st, st->young, &a, &e))
            return 1;
        yhat[i] = a + (st->offset_slot >= 0 ? p[st->offset_slot] : 0.0);
        if (!jac)
            continue;
        /* d angle / d slot = Σ_q (d angle / dE_q) (dE_q / d slot): the first
         * factor for every segment by one adjoint solve, the second exact */
        const double *da_dE;
        if (rod_angle_adjoint(st, &da_dE, &e))
            return 1;
        double *row = jac + i * ds->k;
        for (size_t j = 0; j < ds->k; ++j) {
            const double *d = m->grad_e + j * n;
            double sum = 0.0;
            for (size_t q = 0; q < n; ++q)
                sum += da_dE[q] * d[q];
            row[j] = sum; /* 0 for offsets (grad_e zero there), set below */
        }
        if (st->offset_slot >= 0)
            row[st->offset_slot] = 1.0;
    }
    return 0;
}

/* Series s of predict() (no water model): its observations in order, the
 * rod reset where the previous observation belongs to another series (as
 * one pass over all observations would).  On failure *bad is the failing
 * observation (yhat NAN there) and the status is returned. */
static int predict_series(phc_dataset *ds, const double *p, size_t s, double *yhat, double *jac, size_t *bad)
{
    shape_impl *m = ds->impl;
    stalk *st = &m->stalks[s];
    double *grad = calloc(ds->k, sizeof *grad);
    if (!grad) {
        for (size_t i = 0; i < ds->n; ++i)
            if (m->stalk_of[i] == s) {
                *bad = i;
                break;
            }
        return PHC_ERR_NOMEM;
    }
    int rc = 0;
    for (size_t i = 0; i < ds->n && !rc; ++i) {
        if (m->stalk_of[i] != s)
            continue;
        if ((i == 0 || m->stalk_of[i - 1] != s) && m->dynamics != PHC_SHAPE_PARTICLES)
            phc_rod_reset(st->rod); /* a new run of this series: from the rest shape */
        memset(grad, 0, ds->k * sizeof *grad);
        const double z = driver(ds, p, m->t[i], jac ? grad : NULL);
        double a;
        if ((rc = solve_angle(m, st, z, &a, NULL))) {
            yhat[i] = NAN; /* phc_dataset_check_start names this observation's line */
            *bad = i;
            break;
        }
        yhat[i] = a + (st->offset_slot >= 0 ? p[st->offset_slot] : 0.0);
        if (!jac)
            continue;
        /* d angle / dz: rods exact (one sensitivity solve); particles by a
         * central difference in z (each from rest, backward when z + h > 1) */
        const double h = m->fd_step * z;
        double ap, am, da_dE;
        if (m->dynamics != PHC_SHAPE_PARTICLES) {
            if ((rc = rod_angle_derivative(st, &da_dE, NULL))) {
                *bad = i;
                break;
            }
        } else if (z + h > 1.0) {
            if ((rc = solve_angle(m, st, z - h, &am, NULL)) || (rc = solve_angle(m, st, z - 2.0 * h, &ap, NULL))) {
                *bad = i;
                break;
            }
            da_dE = (3.0 * a - 4.0 * am + ap) / (2.0 * h);
        } else {
            if ((rc = solve_angle(m, st, z + h, &ap, NULL)) || (rc = solve_angle(m, st, z - h, &am, NULL))) {
                *bad = i;
                break;
            }
            da_dE = (ap - am) / (2.0 * h);
        }
        double *row = jac + i * ds->k;
        for (size_t j = 0; j < ds->k; ++j)
            row[j] = da_dE * grad[j];
        if (st->offset_slot >= 0)
            row[st->offset_slot] = 1.0;
    }
    free(grad);
    return rc;
}

static int predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    shape_impl *m = ds->impl;
    if (m->water)
        return predict_water(ds, p, yhat, jac);
    if (jac)
        memset(jac, 0, ds->n * ds->k * sizeof *jac);
    /* The stalks are independent (a rod each), so with rods they are
     * solved side by side; each walks its own observations in order with
     * the same warm starts as one thread, so the result is the same to the
     * bit.  The series of a plant share its one rod, and particles share
     * the data set's step counter: one at a time. */
    const int side_by_side = m->dynamics != PHC_SHAPE_PARTICLES && !m->plant && m->n_stalks > 1;
    size_t first_bad = ds->n;
    int bad_rc = 0;
#pragma omp parallel for schedule(dynamic, 1) if (side_by_side)
    for (size_t s = 0; s < m->n_stalks; ++s) {
        size_t bad = ds->n;
        const int rc = predict_series(ds, p, s, yhat, jac, &bad);
        if (rc) {
#pragma omp critical(phc_shape_series_first_bad)
            if (bad < first_bad) {
                first_bad = bad;
                bad_rc = rc;
            }
        }
    }
    return bad_rc == PHC_ERR_NOMEM ? -1 : bad_rc ? 1 : 0;
}

/* A frame: the stalk's equilibrium at time t as a graph copy (head, tail
 * updated) plus the per-segment values; *out owned by the caller. */
/* young: NULL, or a modulus per segment (rods with the water model; z unused). */
static int frame_graph(shape_impl *m, stalk *st, double z, const double *young, phc_plant_graph **out,
                       phc_error *err)
{
    double a;
    int rc;
    *out = NULL;
    if (m->dynamics != PHC_SHAPE_PARTICLES)
        phc_rod_reset(st->rod);
    if ((rc = young ? rod_solve_young(st, young, &a, err) : solve_angle(m, st, z, &a, err)))
        return rc;
    phc_plant_graph *c = phc_plant_graph_copy(st->g);
    if (!c)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (m->dynamics == PHC_SHAPE_PARTICLES) {
        memcpy(c->head, st->head, 3 * c->n * sizeof *c->head);
        memcpy(c->tail, st->tail, 3 * c->n * sizeof *c->tail);
    } else {
        for (size_t i = 0; i < c->n; ++i) {
            phc_rod_head(st->rod, i, c->head + 3 * i);
            phc_rod_tail(st->rod, i, c->tail + 3 * i);
        }
    }
    *out = c;
    return 0;
}

/* Side views (one PNG per stalk, one panel per frame), the graph of every
 * frame in the native format and as legacy VTK. */
static int write_frames(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err)
{
    shape_impl *m = ds->impl;
    if (m->frames == 0 || ds->n == 0)
        return PHC_OK;
    double t_lo = m->t[0], t_hi = m->t[0];
    for (size_t i = 0; i < ds->n; ++i) {
        t_lo = fmin(t_lo, m->t[i]);
        t_hi = fmax(t_hi, m->t[i]);
    }
    const size_t nf = m->frames > 64 ? 64 : m->frames;
    int rc = PHC_OK;
    for (size_t s = 0; s < m->n_stalks && !rc; ++s) {
        stalk *st = &m->stalks[s];
        const size_t ns = st->g->n;
        phc_shape_panel panels[64];
        phc_plant_graph *graphs[64] = {0};
        double *values = calloc(nf * ns, sizeof *values);
        double *young = calloc(nf * ns, sizeof *young);
        double *stiff = calloc(nf * ns, sizeof *stiff);
        char (*titles)[128] = calloc(nf, sizeof *titles);
        char sid[256], path[8192];
        phc_run_dir_safe_name(st->id, sid, sizeof sid);
        if (!values || !young || !stiff || !titles)
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        phc_error we;
        if (!rc && m->water && phc_shape_water_start(m->water, p[SLOT_DELTA], m->rwc0, 0, &we))
            rc = phc_error_set(err, PHC_ERR_DOMAIN, "data set '%s': the water model: %s", ds->name, we.message);
        for (size_t f = 0; f < nf && !rc; ++f) {
            const double t = nf > 1 ? t_lo + (t_hi - t_lo) * (double)f / (double)(nf - 1) : t_lo;
            double E = NAN, rwc = NAN, sp = NAN, *yf = young + f * ns;
            const int particles = m->dynamics == PHC_SHAPE_PARTICLES;
            phc_error why;
            why.message[0] = 0;
            int bad;
            if (m->water) { /* a modulus per segment */
                bad = segment_moduli(ds, p, t, yf, 0);
                if (!bad) {
                    E = yf[0], rwc = m->x[0];
                    for (size_t i = 0; i < ns; ++i) {
                        values[f * ns + i] = m->x[i];
                        stiff[f * ns + i] = NAN;
                        E = fmin(E, yf[i]);
                        rwc = fmin(rwc, m->x[i]);
                    }
                }
                bad = bad || frame_graph(m, st, NAN, yf, &graphs[f], &why);
            } else {
                bad = phc_shape_series_modulus(ds, p, t, &E, &rwc) ||
                      (particles && phc_shape_series_stiffness(ds, p, t, &sp)) ||
                      frame_graph(m, st, particles ? sp : E, NULL, &graphs[f], &why);
                for (size_t i = 0; i < ns && !bad; ++i) {
                    values[f * ns + i] = rwc;
                    yf[i] = E;
                    stiff[f * ns + i] = sp;
                }
            }
            if (bad) {
                rc = phc_error_set(err, PHC_ERR_DOMAIN,
                                   "data set '%s': series '%s': no %s at t = %g s (E = %g Pa%s%.6g)%s%s", ds->name,
                                   st->id, particles ? "rest state of the particles" : "static equilibrium", t, E,
                                   particles ? ", s = " : "", particles ? sp : 0.0, why.message[0] ? ": " : "",
                                   why.message);
                break;
            }
            if (particles)
                snprintf(titles[f], sizeof titles[f], "t = %.3g h, s = %.3g", t / 3600.0, sp);
            else if (m->water)
                snprintf(titles[f], sizeof titles[f], "t = %.3g h, E >= %.3g MPa, RWC >= %.3g", t / 3600.0,
                         E * 1e-6, rwc);
            else
                snprintf(titles[f], sizeof titles[f], "t = %.3g h, E = %.3g MPa", t / 3600.0, E * 1e-6);
            panels[f] = (phc_shape_panel){.n = ns,
                                          .head = graphs[f]->head,
                                          .tail = graphs[f]->tail,
                                          .radius = graphs[f]->radius,
                                          .value = values + f * ns,
                                          .title = titles[f]};
            const phc_plant_field fields[3] = {{"relative_water", values + f * ns},
                                               {"young_modulus_Pa", young + f * ns},
                                               {"particle_stiffness", stiff + f * ns}};
            snprintf(path, sizeof path, "%s/%s_%s_frame%02zu.csv", dir, base, sid, f);
            if ((rc = phc_plant_io_write_native(path, graphs[f], err)))
                break;
            snprintf(path, sizeof path, "%s/%s_%s_frame%02zu.vtk", dir, base, sid, f);
            char vtitle[256];
            snprintf(vtitle, sizeof vtitle, "phytocal shape_series %s %s", st->id, titles[f]);
            if ((rc = phc_plant_io_write_vtk(path, graphs[f], vtitle, fields, particles ? 3 : 2, err)))
                break;
        }
        if (!rc) {
            phc_shape_plot_options po = phc_shape_plot_options_default();
            char title[512];
            snprintf(title, sizeof title, "%s: series '%s', stalk side views", ds->name, st->id);
            po.title = title;
            po.value_min = 0.0;
            po.value_max = 1.0;
            snprintf(path, sizeof path, "%s/%s_%s_frames.png", dir, base, sid);
            rc = phc_shape_plot(path, panels, nf, &po, err);
        }
        for (size_t f = 0; f < nf; ++f)
            phc_plant_graph_free(graphs[f]);
        free(values);
        free(young);
        free(stiff);
        free(titles);
    }
    return rc;
}

static void name_of(const phc_dataset *ds, size_t g, char *buf, size_t size)
{
    const shape_impl *m = ds->impl;
    snprintf(buf, size, "%s", g < m->n_stalks ? m->stalks[g].id : "?");
}

static int name_series(phc_dataset *ds, phc_error *err)
{
    const shape_impl *m = ds->impl;
    return phc_dataset_name_series(ds, "series", m->n_stalks, name_of, err);
}

const phc_dataset_ops phc_shape_series_ops = {.kind = "shape_series",
                                              .predict = predict,
                                              .free_impl = impl_free,
                                              .simulate_outputs = write_frames,
                                              .fit_outputs = write_frames,
                                              .name_series = name_series};

/* ---- construction ---- */

static const char *where_of(const phc_shape_stalk *st, const phc_shape_series_options *o, char *buf,
                            size_t size)
{
    if (st && st->where)
        return st->where;
    snprintf(buf, size, "%s", phc_origin_key(o->origin, "shape_series", NULL).text);
    return buf;
}

static int check_options(const phc_shape_series *tr, const phc_shape_series_options *o, phc_error *err)
{
    char wb[4200];
    const char *w = where_of(NULL, o, wb, sizeof wb);
    if (o->n_stalks == 0 || !o->stalks)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: shape_series: at least one series must be mapped to a stalk", w);
    if (!(o->rwc0 > 0 && o->rwc0 <= 1.5))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'rwc0': expected a relative water content in (0, 1.5], found %g",
                             phc_origin_key(o->origin, "shape_series", "rwc0").text, o->rwc0);
    if (!o->e_min_slot && !(o->e_min > 0 && isfinite(o->e_min)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'e_min': the modulus must be positive (Pa), found %g",
                             phc_origin_key(o->origin, "shape_series", "e_min").text, o->e_min);
    if (!(o->density > 0 && isfinite(o->density)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'density': must be positive (kg m-3), found %g",
                             phc_origin_key(o->origin, "shape_series", "density").text, o->density);
    if (!(o->sigma >= 0 && isfinite(o->sigma)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': must be positive (rad), found %g",
                             phc_origin_key(o->origin, "shape_series", "sigma").text, o->sigma);
    if (o->every < 1)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'every': must be at least 1",
                             phc_origin_key(o->origin, "shape_series", "every").text);
    if (!(o->fd_step > 1e-10 && o->fd_step < 0.1))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'fd_step': expected a relative step in (1e-10, 0.1), found %g",
                             phc_origin_key(o->origin, "shape_series", "fd_step").text, o->fd_step);
    if (!isnan(o->t0) && !isfinite(o->t0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 't0': must be finite", w);
    if (o->water_model && !o->plant)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: key 'water': the water model runs on a plant graph: give `plant:` too (a "
                             "stalk has one compartment)",
                             phc_origin_key(o->origin, "shape_series", "water").text);
    if (o->water_model && !(o->water_step >= 0 && isfinite(o->water_step)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'water_step': must be zero or positive (s), found %g",
                             phc_origin_key(o->origin, "shape_series", "water_step").text, o->water_step);
    if (o->water_model && !(o->viscosity >= 0 && isfinite(o->viscosity)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'viscosity': must be positive (mPa s), found %g",
                             phc_origin_key(o->origin, "shape_series", "viscosity").text, o->viscosity);
    if (o->dynamics != PHC_SHAPE_RODS && o->dynamics != PHC_SHAPE_PARTICLES)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'dynamics': expected rods or particles",
                             phc_origin_key(o->origin, "shape_series", "dynamics").text);
    if (o->dynamics == PHC_SHAPE_PARTICLES) {
        if (o->particle_iterations < 1 || o->particle_iterations > 1000)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'particle_iterations': expected 1 to 1000, found %zu",
                                 phc_origin_key(o->origin, "shape_series", "particle_iterations").text,
                                 o->particle_iterations);
        if (!(o->particle_time_step > 0 && o->particle_time_step <= 1))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'particle_time_step': expected a time step in (0, 1] s, "
                                 "found %g", phc_origin_key(o->origin, "shape_series", "particle_time_step").text,
                                 o->particle_time_step);
        if (o->particle_steps < 1 || o->particle_steps > 10000000)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'particle_steps': expected 1 to 10000000, found %zu",
                                 phc_origin_key(o->origin, "shape_series", "particle_steps").text, o->particle_steps);
        if (!(o->particle_damping > 0 && o->particle_damping < 1))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'particle_damping': expected a fraction in (0, 1), found %g",
                                 phc_origin_key(o->origin, "shape_series", "particle_damping").text, o->particle_damping);
        if (!(o->parent_weight >= 1 && isfinite(o->parent_weight)))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'parent_weight': expected a weight >= 1, found %g",
                                 phc_origin_key(o->origin, "shape_series", "parent_weight").text, o->parent_weight);
    }
    if (o->water_model && o->dynamics == PHC_SHAPE_PARTICLES)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: key 'water': water: plant needs dynamics: rods (a particle has one stiffness "
                             "s(t) for the whole plant, not one per segment)",
                             phc_origin_key(o->origin, "shape_series", "water").text);
    for (size_t s = 0; s < o->n_stalks; ++s) {
        const phc_shape_stalk *st = &o->stalks[s];
        const char *ws = where_of(st, o, wb, sizeof wb);
        if (!st->series || !st->series[0])
            return phc_error_set(err, PHC_ERR_INPUT, "%s: stalk %zu: key 'series' is required", ws, s + 1);
        const long k = phc_shape_series_find(tr, st->series);
        if (k < 0) {
            char known[2048] = "";
            size_t used = 0;
            for (size_t j = 0; j < tr->n_tracks && used < sizeof known - 1; ++j)
                used += (size_t)snprintf(known + used, sizeof known - used, "%s'%s'", j ? ", " : "", tr->tracks[j].id);
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'series': unknown series '%s' (series of %s: %s)", ws,
                                 st->series, tr->source ? tr->source : "the tracks", known);
        }
        if (tr->tracks[k].kind != PHC_SHAPE_ANGLE)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: series '%s': a stalk is fitted to an angle track, this one holds points", ws,
                                 st->series);
        for (size_t j = 0; j < s; ++j)
            if (strcmp(o->stalks[j].series, st->series) == 0)
                return phc_error_set(err, PHC_ERR_INPUT, "%s: series '%s' is mapped twice", ws, st->series);
        const struct {
            const char *key, *unit;
            double v;
            int zero_ok;
        } pos[] = {{"tip_mass", "kg", st->tip_mass, 1}, {"length", "m", st->length, 0}, {"radius", "m", st->radius, 0}};
        for (int q = 0; q < (o->plant ? 1 : 3); ++q)
            if (!(isfinite(pos[q].v) && (pos[q].v > 0 || (pos[q].zero_ok && pos[q].v == 0))))
                return phc_error_set(err, PHC_ERR_INPUT, "%s: series '%s': key '%s': must be %s (%s), found %g", ws,
                                     st->series, pos[q].key, pos[q].zero_ok ? "zero or positive" : "positive",
                                     pos[q].unit, pos[q].v);
        if (o->plant) {
            if (!isnan(st->base_angle))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s: series '%s': key 'base_angle': not with a plant (the segment's rest "
                                     "direction is the base angle)", ws, st->series);
            for (size_t j = 0; j < s; ++j)
                if (o->stalks[j].segment == st->segment)
                    return phc_error_set(err, PHC_ERR_INPUT, "%s: series '%s': key 'segment': segment %ld is already "
                                         "mapped to series '%s'", ws, st->series, st->segment, o->stalks[j].series);
            continue;
        }
        if (st->segments < 1 || st->segments > 10000)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: series '%s': key 'segments': expected 1 to 10000, found %zu", ws,
                                 st->series, st->segments);
        if (!isnan(st->base_angle) && !isfinite(st->base_angle))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: series '%s': key 'base_angle': must be finite", ws, st->series);
    }
    return PHC_OK;
}

/* A series mapped to segment spec->segment (a source id) of the data set's
 * plant: its rest direction in the x–z plane is β; the tip mass hangs at the
 * segment's tail. */
static int plant_stalk(shape_impl *m, stalk *out, const phc_shape_stalk *spec, double *beta, phc_error *err)
{
    const phc_plant_graph *g = m->plant;
    size_t i = 0;
    while (i < g->n && g->source_id[i] != spec->segment)
        ++i;
    if (i == g->n)
        return phc_error_set(err, PHC_ERR_INPUT, "series '%s': key 'segment': the plant has no segment %ld",
                             spec->series, spec->segment);
    const double dx = g->tail[3 * i] - g->head[3 * i], dz = g->tail[3 * i + 2] - g->head[3 * i + 2];
    if (!(hypot(dx, dz) > 1e-9 * g->length[i]))
        return phc_error_set(err, PHC_ERR_INPUT, "series '%s': segment %ld lies along y: it has no angle in the x-z plane",
                             spec->series, spec->segment);
    out->shared = 1;
    out->g = m->plant;
    out->rod = m->plant_rod;
    out->seg = i;
    out->beta = *beta = atan2(dz, dx);
    out->tip_mass = spec->tip_mass;
    if (!(out->young = malloc(g->n * sizeof *out->young)) || !(out->id = strdup(spec->series)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    phc_rod_options ro;
    phc_rod_options_default(&ro);
    const double force[3] = {spec->tip_mass * ro.gravity[0], spec->tip_mass * ro.gravity[1],
                             spec->tip_mass * ro.gravity[2]};
    if (m->dynamics == PHC_SHAPE_PARTICLES) {
        out->force = m->plant_force;
        out->rest_length = INFINITY;
        for (size_t j = 0; j < g->n; ++j)
            if (!g->fixed[j])
                out->rest_length = fmin(out->rest_length, g->length[j]);
        if (!(out->head = malloc(3 * g->n * sizeof *out->head)) || !(out->tail = malloc(3 * g->n * sizeof *out->tail)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (int d = 0; d < 3; ++d)
            m->plant_force[3 * i + d] += force[d];
        return PHC_OK;
    }
    if (!(out->sens = malloc(8 * g->n * sizeof *out->sens)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return phc_rod_set_load(m->plant_rod, i, force, err);
}

/* The data set's plant: a copy of options.plant and its rod. */
static int plant_rod(shape_impl *m, const phc_shape_series_options *o, phc_error *err)
{
    if (!(m->plant = phc_plant_graph_copy(o->plant)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (o->dynamics == PHC_SHAPE_PARTICLES) {
        /* the roots are clamps (anchored, orientation held), as the rod's are fixed */
        size_t free_segments = 0;
        for (size_t i = 0; i < m->plant->n; ++i) {
            if (m->plant->parent[i] == PHC_PLANT_NO_PARENT)
                m->plant->fixed[i] = 1;
            free_segments += !m->plant->fixed[i];
        }
        if (free_segments == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'plant': every segment is fixed: nothing can droop",
                                 phc_origin_key(o->origin, "shape_series", "plant").text);
        if (!(m->plant_force = calloc(3 * m->plant->n, sizeof *m->plant_force)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        return PHC_OK;
    }
    double *young = malloc(m->plant->n * sizeof *young);
    if (!young)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < m->plant->n; ++i)
        young[i] = 1e6;
    phc_rod_options ro;
    phc_rod_options_default(&ro);
    ro.density = o->density;
    const int rc = phc_rod_new(m->plant, young, &ro, &m->plant_rod, err);
    free(young);
    return rc;
}

/* options.water_model: the water model on the data set's plant, its work
 * arrays, and no observation before t0. */
static int plant_water(shape_impl *m, const phc_shape_series_options *o, const phc_dataset *ds, phc_error *err)
{
    double t_hi = m->t0;
    for (size_t i = 0; i < ds->n; ++i) {
        if (m->t[i] < m->t0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: key 't0': the water model runs forward from t0 = %g s, but a sample "
                                 "(line %zu) is at %g s",
                                 phc_origin_key(o->origin, "shape_series", "t0").text, m->t0,
                                 ds->data_lines[i], m->t[i]);
        t_hi = fmax(t_hi, m->t[i]);
    }
    const double step = o->water_step > 0 ? o->water_step : (t_hi > m->t0 ? (t_hi - m->t0) / 1000.0 : 1.0);
    const size_t n = m->plant->n;
    int rc = phc_shape_water_new(m->plant, o->conductance, o->viscosity, step, &m->water, err);
    if (rc)
        return phc_error_prefix(err, rc, "%s: the water model", phc_origin_key(o->origin, "shape_series", "water").text);
    if (!(m->x = malloc(n * sizeof *m->x)) || !(m->dx = malloc(n * sizeof *m->dx)) ||
        !(m->grad_e = malloc(ds->k * n * sizeof *m->grad_e)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

/* The stalk's graph: a clamp segment and `segments` free ones along β. */
static int build_stalk(stalk *out, const phc_shape_stalk *spec, double beta, const phc_shape_series_options *o,
                       phc_error *err)
{
    const size_t n = spec->segments + 1;
    const double h = spec->length / (double)spec->segments, c = cos(beta), s = sin(beta);
    phc_plant_graph *g = phc_plant_graph_new(n);
    out->g = g; /* freed with the data set, whatever happens below */
    if (!g || !(out->young = malloc(n * sizeof *out->young)) || !(out->id = strdup(spec->series)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    out->beta = beta;
    out->tip_mass = spec->tip_mass;
    out->seg = n - 1;
    /* The clamp is short (CLAMP_FRACTION of a segment): the base joint then
     * spans half a free segment, as the base node of the continuum's
     * discretisation does (a clamp of a whole segment would lengthen the
     * beam by half a segment: tip slopes (1 + 1/(2n))² too large). */
    const int particles = o->dynamics == PHC_SHAPE_PARTICLES;
    const double hc = particles ? h : CLAMP_FRACTION * h; /* particles: see the header */
    for (size_t i = 0; i < n; ++i) {
        g->parent[i] = i ? i - 1 : PHC_PLANT_NO_PARENT;
        g->radius[i] = spec->radius;
        g->length[i] = i ? h : hc;
        const double a = i ? (double)(i - 1) * h : -hc, b = i ? a + h : 0.0;
        g->head[3 * i] = a * c;
        g->head[3 * i + 2] = a * s;
        g->tail[3 * i] = b * c;
        g->tail[3 * i + 2] = b * s;
        g->source_id[i] = (long)i;
        out->young[i] = 1e6;
    }
    g->fixed[0] = 1;
    char where[4200];
    snprintf(where, sizeof where, "series '%s'", spec->series);
    int rc;
    if ((rc = phc_plant_graph_finish(g, where, err)))
        return rc;
    phc_rod_options ro;
    phc_rod_options_default(&ro);
    ro.density = o->density;
    const double force[3] = {spec->tip_mass * ro.gravity[0], spec->tip_mass * ro.gravity[1],
                             spec->tip_mass * ro.gravity[2]};
    if (particles) {
        out->rest_length = h;
        if (!(out->force = calloc(3 * n, sizeof *out->force)) || !(out->head = malloc(3 * n * sizeof *out->head)) ||
            !(out->tail = malloc(3 * n * sizeof *out->tail)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        memcpy(out->force + 3 * (n - 1), force, sizeof force);
        return PHC_OK;
    }
    if (!(out->sens = malloc(8 * n * sizeof *out->sens)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_rod_new(g, out->young, &ro, &out->rod, err)))
        return rc;
    return phc_rod_set_load(out->rod, n - 1, force, err);
}

int phc_shape_series_new(const phc_shape_series *tr, const phc_shape_series_options *o, phc_dataset **out,
                         phc_error *err)
{
    *out = NULL;
    if (!tr || !o)
        return phc_error_set(err, PHC_ERR_INVALID, "shape_series: tracks and options are required");
    int rc;
    if ((rc = check_options(tr, o, err)))
        return rc;
    if (tr->n_times == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: no samples", tr->source ? tr->source : "shape_series");
    size_t n_offsets = 0;
    for (size_t s = 0; s < o->n_stalks; ++s)
        n_offsets += o->stalks[s].offset != 0;
    const size_t k = N_SHARED + (o->e_min_slot ? 1 : 0) + n_offsets;
    size_t per = 0;
    for (size_t i = 0; i < tr->n_times; i += o->every)
        ++per;
    const size_t n = per * o->n_stalks;
    phc_dataset *ds = phc_dataset_new(&phc_shape_series_ops, k);
    shape_impl *m = calloc(1, sizeof *m);
    if (!ds || !m) {
        free(m);
        phc_dataset_free(ds);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    ds->impl = m;
    ds->n = n;
    ds->derivatives = PHC_DERIV_ANALYTIC;
    /* particles: the rest state ends 1e-12 of a segment per step from rest
     * and settles further; angles are smooth in s to about 1e-10 rad (README
     * "Fitting with particles"), so the solver need not iterate below it */
    if (o->dynamics == PHC_SHAPE_PARTICLES)
        ds->model_tolerance = 1e-10;
    m->t0 = isnan(o->t0) ? tr->t[0] : o->t0;
    m->rwc0 = o->rwc0;
    m->e_min = o->e_min;
    m->fd_step = o->fd_step;
    m->frames = o->frames;
    m->dynamics = o->dynamics;
    m->popt = phc_particles_options_default();
    m->popt.density = o->density;
    m->popt.iterations = o->particle_iterations;
    m->popt.damping = o->particle_damping;
    m->popt.parent_weight = o->parent_weight;
    m->pdt = o->particle_time_step;
    m->psteps = o->particle_steps;
    m->e_min_slot = o->e_min_slot ? N_SHARED : -1;
    m->n_stalks = o->n_stalks;
    static const char *const shared[N_SHARED] = {"kappa", "chi0", "e_max", "delta"};
    const char *const shared_unit[N_SHARED] = {"1", "1", "Pa", o->water_model ? "s-1 cm-2" : "s-1"};
    if (!(m->stalks = calloc(o->n_stalks, sizeof *m->stalks)) || !(m->stalk_of = calloc(n, sizeof *m->stalk_of)) ||
        !(m->t = calloc(n, sizeof *m->t)) || !(ds->x = calloc(n, sizeof *ds->x)) ||
        !(ds->y = calloc(n, sizeof *ds->y)) || !(ds->data_lines = calloc(n, sizeof *ds->data_lines)) ||
        !(ds->series = calloc(n, sizeof *ds->series)))
        goto nomem;
    for (size_t j = 0; j < N_SHARED; ++j)
        if (!(ds->slot_names[j] = strdup(shared[j])))
            goto nomem;
    if (o->e_min_slot && !(ds->slot_names[N_SHARED] = strdup("e_min")))
        goto nomem;
    size_t slot = N_SHARED + (o->e_min_slot ? 1 : 0), obs = 0;
    if (o->plant && (rc = plant_rod(m, o, err))) {
        phc_dataset_free(ds);
        return rc;
    }
    char wb[4200];
    for (size_t s = 0; s < o->n_stalks; ++s) {
        const phc_shape_stalk *sp = &o->stalks[s];
        const phc_shape_track *track = &tr->tracks[phc_shape_series_find(tr, sp->series)];
        for (size_t i = 0; i < tr->n_times; ++i)
            if (!isfinite(track->value[i]))
                return phc_dataset_free(ds),
                       phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: series '%s': the angle is not a finite number",
                                     tr->source, tr->line[i], sp->series);
        const double first = track->value[0];
        double beta = isnan(sp->base_angle) ? remainder(first, 2.0 * PHC_SS_PI) : sp->base_angle;
        stalk *st = &m->stalks[s];
        st->offset_slot = -1;
        if ((rc = o->plant ? plant_stalk(m, st, sp, &beta, err) : build_stalk(st, sp, beta, o, err))) {
            phc_error_prefix(err, rc, "%s", where_of(sp, o, wb, sizeof wb));
            phc_dataset_free(ds);
            return rc;
        }
        const double shift = beta + remainder(first - beta, 2.0 * PHC_SS_PI) - first; /* a multiple of 2π */
        if (sp->offset) {
            char name[300];
            snprintf(name, sizeof name, "offset_%s", sp->series);
            for (char *c = name; *c; ++c)
                if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '_'))
                    *c = '_';
            st->offset_slot = (long)slot;
            if (!(ds->slot_names[slot++] = strdup(name)))
                goto nomem;
        }
        for (size_t i = 0; i < tr->n_times; i += o->every) {
            m->stalk_of[obs] = s;
            m->t[obs] = tr->t[i];
            ds->x[obs] = tr->t[i] / 3600.0;
            ds->y[obs] = track->value[i] + shift;
            ds->data_lines[obs] = tr->line[i];
            ds->series[obs] = s;
            ++obs;
        }
    }
    if (o->water_model && (rc = plant_water(m, o, ds, err))) {
        phc_dataset_free(ds);
        return rc;
    }
    for (size_t j = 0; j < N_SHARED; ++j)
        if (phc_dataset_declare_unit(ds, shared[j], shared_unit[j]))
            goto nomem;
    if (o->e_min_slot && phc_dataset_declare_unit(ds, "e_min", "Pa"))
        goto nomem;
    for (size_t s = 0; s < o->n_stalks; ++s)
        if (m->stalks[s].offset_slot >= 0 &&
            phc_dataset_declare_unit(ds, ds->slot_names[m->stalks[s].offset_slot], "rad"))
            goto nomem;
    if (o->sigma > 0) {
        if (!(ds->sigma = malloc(n * sizeof *ds->sigma)))
            goto nomem;
        for (size_t i = 0; i < n; ++i)
            ds->sigma[i] = o->sigma;
    }
    ds->x_seconds = 3600.0;
    if (!(ds->x_label = strdup("time (h)")) ||
        !(ds->y_label = strdup("organ angle (rad, counter-clockwise from +x, z up)")) ||
        (tr->source && !(ds->data_file = strdup(tr->source))))
        goto nomem;
    ds->config_line = phc_origin_line(o->origin, NULL);
    *out = ds;
    return PHC_OK;
nomem:
    phc_dataset_free(ds);
    return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
}
