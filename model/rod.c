/* Elastic rods on the plant graph: see rod.h (model), rod_joint.h (the joint
 * constraints and their derivatives), rod_tree_solver.h (the direct solver),
 * rod_gauss_seidel.c (the authors' reference scheme), rod_internal.h (the
 * struct and the helpers they share). */
#include "model/rod.h"

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include <lapacke.h>

#include "model/quaternion.h"
#include "model/rod_internal.h"
#include "model/rod_joint.h"
#include "model/rod_tree_solver.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif


void phc_rod_options_default(phc_rod_options *o)
{
    o->density = 1000.0;
    o->poisson = 0.5;
    o->gravity[0] = 0.0;
    o->gravity[1] = 0.0;
    o->gravity[2] = -9.81;
    o->tolerance = 1e-10;
    o->max_iterations = 200;
    o->damping = 0.0;
    o->scheme = PHC_ROD_DIRECT;
    o->substeps = 1;
    o->gs_iterations = 1;
    o->max_rotation = 0.5;
}

size_t phc_rod_segment_count(const phc_rod *rod) { return rod->n; }

static int check_options(const phc_rod_options *o, phc_error *err)
{
    if (!(o->density > 0.0) || !isfinite(o->density))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "rod: density must be positive and finite, found %g kg/m^3", o->density);
    if (!(o->poisson > -1.0 && o->poisson <= 0.5))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "rod: Poisson ratio must be in (-1, 0.5], found %g", o->poisson);
    for (int k = 0; k < 3; ++k)
        if (!isfinite(o->gravity[k]))
            return phc_error_set(err, PHC_ERR_INPUT, "rod: gravity[%d] is not finite", k);
    if (!(o->tolerance > 0.0) || !isfinite(o->tolerance))
        return phc_error_set(err, PHC_ERR_INPUT, "rod: tolerance must be positive, found %g",
                             o->tolerance);
    if (o->max_iterations < 1 || o->substeps < 1 || o->gs_iterations < 1)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "rod: max_iterations, substeps and gs_iterations must be >= 1 "
                             "(found %d, %d, %d)",
                             o->max_iterations, o->substeps, o->gs_iterations);
    if (!(o->damping >= 0.0) || !isfinite(o->damping))
        return phc_error_set(err, PHC_ERR_INPUT, "rod: damping must be >= 0, found %g s^-1",
                             o->damping);
    if (!(o->max_rotation > 0.0) || !isfinite(o->max_rotation))
        return phc_error_set(err, PHC_ERR_INPUT, "rod: max_rotation must be positive, found %g",
                             o->max_rotation);
    if (o->scheme != PHC_ROD_DIRECT && o->scheme != PHC_ROD_GAUSS_SEIDEL)
        return phc_error_set(err, PHC_ERR_INPUT, "rod: unknown scheme %d", (int)o->scheme);
    return PHC_OK;
}

/* mass and inertia of a solid cylinder (+ the extra mass, spread alike) */
static void update_mass(phc_rod *rod)
{
    const phc_plant_graph *g = rod->g;
    for (size_t i = 0; i < rod->n; ++i) {
        const double r = g->radius[i], h = g->length[i];
        const double m = rod->opt.density * M_PI * r * r * h + rod->extra[i];
        rod->mass[i] = m;
        rod->inertia[3 * i] = rod->inertia[3 * i + 1] = m * (3.0 * r * r + h * h) / 12.0;
        rod->inertia[3 * i + 2] = 0.5 * m * r * r;
    }
}

/* ℓK per joint, before the factor: the child's radius, the length-weighted
 * harmonic mean of the two moduli (rod.h). */
static void update_stiffness(phc_rod *rod)
{
    const phc_plant_graph *g = rod->g;
    for (size_t c = 0; c < rod->n; ++c) {
        const size_t p = g->parent[c];
        if (p == PHC_PLANT_NO_PARENT)
            continue;
        const double ell = rod->joint[c].ell;
        const double e = ell / (0.5 * g->length[p] / rod->young[p] + 0.5 * g->length[c] / rod->young[c]);
        const double r = g->radius[c], area_moment = M_PI * r * r * r * r / 4.0;
        const double G = e / (2.0 * (1.0 + rod->opt.poisson));
        rod->stiff[3 * c] = ell * e * area_moment;
        rod->stiff[3 * c + 1] = ell * e * area_moment;
        rod->stiff[3 * c + 2] = ell * G * 2.0 * area_moment;
    }
}

void phc_rod_free(phc_rod *rod)
{
    if (!rod)
        return;
    void *p[] = {rod->young, rod->extra, rod->mass, rod->inertia, rod->fixed, rod->factor,
                 rod->load, rod->joint, rod->stiff, rod->x, rod->q, rod->v, rod->w,
                 rod->lambda, rod->x0, rod->q0, rod->xs, rod->qs, rod->ls, rod->xo, rod->qo,
                 rod->xp, rod->qp, rod->res, rod->rhs, rod->sol, rod->ejoint,
                 rod->jnode, rod->anchors, rod->queue, rod->mark, rod->schur, rod->schur_piv,
                 rod->jdeg, rod->jleft};
    for (size_t k = 0; k < sizeof p / sizeof p[0]; ++k)
        free(p[k]);
    phc_rod_tree_free(rod->tree);
    free(rod);
}

static int check_modulus(const phc_plant_graph *g, const double *young, phc_error *err)
{
    for (size_t i = 0; i < g->n; ++i)
        if (!(young[i] > 0.0) || !isfinite(young[i]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "rod: segment %ld: Young's modulus must be positive and finite, "
                                 "found %g Pa",
                                 g->source_id[i], young[i]);
    return PHC_OK;
}

int phc_rod_new(const phc_plant_graph *g, const double *young, const phc_rod_options *options,
                phc_rod **out, phc_error *err)
{
    phc_rod_options def;
    int rc;
    *out = NULL;
    if (!g || !young || !g->order)
        return phc_error_set(err, PHC_ERR_INVALID, "rod: no graph or moduli (graph finished?)");
    if (!options) {
        phc_rod_options_default(&def);
        options = &def;
    }
    if ((rc = check_options(options, err)) != PHC_OK)
        return rc;
    for (size_t i = 0; i < g->n; ++i) {
        if (!(g->radius[i] > 0.0) || !isfinite(g->radius[i]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "rod: segment %ld: radius must be positive and finite, found %g m",
                                 g->source_id[i], g->radius[i]);
        if (!(g->length[i] > 0.0) || !isfinite(g->length[i]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "rod: segment %ld: length must be positive and finite, found %g m",
                                 g->source_id[i], g->length[i]);
        for (int k = 0; k < 3; ++k)
            if (!isfinite(g->head[3 * i + k]) || !isfinite(g->tail[3 * i + k]))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "rod: segment %ld: head/tail coordinate %c is not finite",
                                     g->source_id[i], "xyz"[k]);
        const double dx = g->tail[3 * i] - g->head[3 * i], dy = g->tail[3 * i + 1] - g->head[3 * i + 1],
                     dz = g->tail[3 * i + 2] - g->head[3 * i + 2];
        if (!(sqrt(dx * dx + dy * dy + dz * dz) > 0.0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "rod: segment %ld: head and tail coincide (no axis)",
                                 g->source_id[i]);
    }
    if ((rc = check_modulus(g, young, err)) != PHC_OK)
        return rc;
    if (g->n < 2)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "rod: every segment is fixed (the plant is its root segment %ld "
                             "alone): nothing can move",
                             g->source_id[g->root]);

    const size_t n = g->n;
    phc_rod *rod = calloc(1, sizeof *rod);
    if (!rod)
        return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory");
    rod->g = g;
    rod->n = n;
    rod->opt = *options;
    rod->load_scale = 1.0;
#define ALLOC(f, count) (rod->f = calloc((count), sizeof *rod->f)) == NULL
    if (ALLOC(young, n) || ALLOC(extra, n) || ALLOC(mass, n) || ALLOC(inertia, 3 * n) ||
        ALLOC(fixed, n) || ALLOC(factor, n) || ALLOC(load, 3 * n) || ALLOC(joint, n) ||
        ALLOC(stiff, 3 * n) || ALLOC(x, 3 * n) || ALLOC(q, 4 * n) || ALLOC(v, 3 * n) ||
        ALLOC(w, 3 * n) || ALLOC(lambda, 6 * n) || ALLOC(x0, 3 * n) || ALLOC(q0, 4 * n) ||
        ALLOC(xs, 3 * n) || ALLOC(qs, 4 * n) || ALLOC(ls, 6 * n) || ALLOC(xo, 3 * n) ||
        ALLOC(qo, 4 * n) || ALLOC(xp, 3 * n) || ALLOC(qp, 4 * n) || ALLOC(res, 12 * n) ||
        ALLOC(rhs, 12 * n) || ALLOC(sol, 12 * n) || ALLOC(ejoint, n) ||
        ALLOC(jnode, n) || ALLOC(anchors, n) || ALLOC(queue, n) || ALLOC(mark, n) ||
        ALLOC(jdeg, n) || ALLOC(jleft, n) ||
        (rod->tree = phc_rod_tree_new(n)) == NULL) {
        phc_rod_free(rod);
        return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory for %zu segments", n);
    }
#undef ALLOC
    memcpy(rod->young, young, n * sizeof *young);
    for (size_t i = 0; i < n; ++i) {
        rod->fixed[i] = (unsigned char)(g->fixed[i] || i == g->root);
        rod->factor[i] = 1.0;
    }
    /* rest frames, parents first (g->order): parallel transport */
    for (size_t o = 0; o < n; ++o) {
        const size_t i = g->order[o], p = g->parent[i];
        double axis[3], pa[3], tq[4];
        for (int k = 0; k < 3; ++k) {
            axis[k] = (g->tail[3 * i + k] - g->head[3 * i + k]);
            rod->x0[3 * i + k] = 0.5 * (g->tail[3 * i + k] + g->head[3 * i + k]);
        }
        const double len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
        for (int k = 0; k < 3; ++k)
            axis[k] /= len;
        if (p == PHC_PLANT_NO_PARENT) {
            const double ez[3] = {0.0, 0.0, 1.0};
            phc_quat_from_two_vectors(ez, axis, rod->q0 + 4 * i);
        } else {
            const double ez[3] = {0.0, 0.0, 1.0};
            phc_quat_rotate(rod->q0 + 4 * p, ez, pa);
            phc_quat_from_two_vectors(pa, axis, tq);
            phc_quat_mul(tq, rod->q0 + 4 * p, rod->q0 + 4 * i);
            phc_quat_normalize(rod->q0 + 4 * i);
        }
    }
    for (size_t c = 0; c < n; ++c) {
        const size_t p = g->parent[c];
        if (p == PHC_PLANT_NO_PARENT)
            continue;
        phc_rod_joint_geometry *j = rod->joint + c;
        double d[3];
        for (int k = 0; k < 3; ++k)
            d[k] = g->head[3 * c + k] - rod->x0[3 * p + k];
        phc_quat_rotate_inverse(rod->q0 + 4 * p, d, j->a);
        for (int k = 0; k < 3; ++k)
            d[k] = g->head[3 * c + k] - rod->x0[3 * c + k];
        phc_quat_rotate_inverse(rod->q0 + 4 * c, d, j->b);
        j->ell = 0.5 * (g->length[p] + g->length[c]);
        phc_rod_darboux(rod->q0 + 4 * p, rod->q0 + 4 * c, j->ell, j->omega0);
    }
    /* reach: the longest root-to-tail path */
    {
        double *dist = rod->sol; /* scratch */
        rod->reach = 0.0;
        for (size_t o = 0; o < n; ++o) {
            const size_t i = g->order[o], p = g->parent[i];
            dist[i] = g->length[i] + (p == PHC_PLANT_NO_PARENT ? 0.0 : dist[p]);
            if (dist[i] > rod->reach)
                rod->reach = dist[i];
        }
    }
    update_mass(rod);
    update_stiffness(rod);
    phc_rod_reset(rod);
    *out = rod;
    return PHC_OK;
}

int phc_rod_set_options(phc_rod *rod, const phc_rod_options *o, phc_error *err)
{
    int rc = check_options(o, err);
    if (rc != PHC_OK)
        return rc;
    rod->opt = *o;
    update_mass(rod);
    update_stiffness(rod);
    return PHC_OK;
}

int phc_rod_set_modulus(phc_rod *rod, const double *young, phc_error *err)
{
    int rc = check_modulus(rod->g, young, err);
    if (rc != PHC_OK)
        return rc;
    memcpy(rod->young, young, rod->n * sizeof *young);
    update_stiffness(rod);
    return PHC_OK;
}

int phc_rod_set_extra_mass(phc_rod *rod, const double *mass, phc_error *err)
{
    for (size_t i = 0; i < rod->n; ++i)
        if (!(mass[i] >= 0.0) || !isfinite(mass[i]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "rod: segment %ld: extra mass must be >= 0 and finite, found %g kg",
                                 rod->g->source_id[i], mass[i]);
    memcpy(rod->extra, mass, rod->n * sizeof *mass);
    update_mass(rod);
    return PHC_OK;
}

static int check_segment(const phc_rod *rod, size_t s, const char *what, phc_error *err)
{
    if (s >= rod->n)
        return phc_error_set(err, PHC_ERR_INPUT, "rod: %s: segment index %zu out of range (%zu segments)",
                             what, s, rod->n);
    return PHC_OK;
}

int phc_rod_set_fixed(phc_rod *rod, size_t s, int fixed, phc_error *err)
{
    int rc = check_segment(rod, s, "support", err);
    if (rc != PHC_OK)
        return rc;
    if (s == rod->g->root && !fixed)
        return phc_error_set(err, PHC_ERR_INPUT, "rod: segment %ld is the root: it is always fixed",
                             rod->g->source_id[s]);
    rod->fixed[s] = (unsigned char)(fixed != 0);
    return PHC_OK;
}

int phc_rod_set_joint_factor(phc_rod *rod, size_t s, double f, phc_error *err)
{
    int rc = check_segment(rod, s, "joint", err);
    if (rc != PHC_OK)
        return rc;
    if (s == rod->g->root)
        return phc_error_set(err, PHC_ERR_INPUT, "rod: segment %ld is the root: it has no joint",
                             rod->g->source_id[s]);
    if (!(f >= 0.0 && f <= 1.0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "rod: segment %ld: joint factor must be 0 (cut) or in (0, 1], found %g",
                             rod->g->source_id[s], f);
    rod->factor[s] = f;
    return PHC_OK;
}

int phc_rod_set_load(phc_rod *rod, size_t s, const double force[3], phc_error *err)
{
    int rc = check_segment(rod, s, "load", err);
    if (rc != PHC_OK)
        return rc;
    for (int k = 0; k < 3; ++k)
        if (!isfinite(force[k]))
            return phc_error_set(err, PHC_ERR_INPUT, "rod: segment %ld: load %c is not finite",
                                 rod->g->source_id[s], "xyz"[k]);
    memcpy(rod->load + 3 * s, force, 3 * sizeof *force);
    return PHC_OK;
}

void phc_rod_reset(phc_rod *rod)
{
    memcpy(rod->x, rod->x0, 3 * rod->n * sizeof *rod->x);
    memcpy(rod->q, rod->q0, 4 * rod->n * sizeof *rod->q);
    memset(rod->v, 0, 3 * rod->n * sizeof *rod->v);
    memset(rod->w, 0, 3 * rod->n * sizeof *rod->w);
    memset(rod->lambda, 0, 6 * rod->n * sizeof *rod->lambda);
}

void phc_rod_internal_tail_offset(const phc_rod *rod, size_t i, double u[3])
{
    const double e[3] = {0.0, 0.0, 0.5 * rod->g->length[i]};
    phc_quat_rotate(rod->q + 4 * i, e, u);
}

void phc_rod_head(const phc_rod *rod, size_t i, double out[3])
{
    double u[3];
    phc_rod_internal_tail_offset(rod, i, u);
    for (int k = 0; k < 3; ++k)
        out[k] = rod->x[3 * i + k] - u[k];
}

void phc_rod_tail(const phc_rod *rod, size_t i, double out[3])
{
    double u[3];
    phc_rod_internal_tail_offset(rod, i, u);
    for (int k = 0; k < 3; ++k)
        out[k] = rod->x[3 * i + k] + u[k];
}

void phc_rod_tip_deflection(const phc_rod *rod, size_t i, double out[3])
{
    double t[3];
    phc_rod_tail(rod, i, t);
    for (int k = 0; k < 3; ++k)
        out[k] = t[k] - rod->g->tail[3 * i + k];
}

double phc_rod_mass(const phc_rod *rod, size_t i) { return rod->mass[i]; }

/* world inertia R diag(I) Rᵀ (3x3) */
void phc_rod_internal_world_inertia(const phc_rod *rod, size_t i, double out[9], int inverse)
{
    double r[9];
    phc_quat_to_matrix(rod->q + 4 * i, r);
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double s = 0.0;
            for (int k = 0; k < 3; ++k) {
                const double m = rod->inertia[3 * i + k];
                s += r[a * 3 + k] * r[b * 3 + k] * (inverse ? 1.0 / m : m);
            }
            out[a * 3 + b] = s;
        }
}

double phc_rod_kinetic_energy(const phc_rod *rod)
{
    double e = 0.0, iw[9];
    for (size_t i = 0; i < rod->n; ++i) {
        const double *v = rod->v + 3 * i, *w = rod->w + 3 * i;
        e += 0.5 * rod->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        phc_rod_internal_world_inertia(rod, i, iw, 0);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                e += 0.5 * w[a] * iw[a * 3 + b] * w[b];
    }
    return e;
}

/* ---- the elimination tree ---------------------------------------------- */

/* Components of the bodies joined by intact (factor > 0) joints; each is
 * rooted at a fixed segment (the first one met breadth-first), or, in
 * dynamics, at its top segment when it has none.  Every other body is paired
 * with the joint towards its component root. */
static int build_tree(phc_rod *rod, int statics, phc_error *err)
{
    const phc_plant_graph *g = rod->g;
    phc_rod_tree *t = rod->tree;
    const size_t n = rod->n;
    size_t nfree = 0;
    memset(rod->mark, 0, n);
    rod->n_anchors = 0;
    for (size_t i = 0; i < n; ++i) {
        t->parent[i] = PHC_TREE_NONE;
        rod->jnode[i] = PHC_TREE_NONE;
        if (!rod->fixed[i])
            ++nfree;
    }
    if (nfree == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "rod: every segment is fixed: nothing can move");
#define ACTIVE(c) (g->parent[c] != PHC_PLANT_NO_PARENT && rod->factor[c] > 0.0)
    for (size_t o = 0; o < n; ++o) {
        const size_t top = g->order[o];
        if (rod->mark[top])
            continue;
        /* collect the component breadth-first from its top */
        size_t head = 0, tail = 0, root = PHC_TREE_NONE;
        rod->queue[tail++] = top;
        rod->mark[top] = 1;
        while (head < tail) {
            const size_t i = rod->queue[head++];
            if (rod->fixed[i] && root == PHC_TREE_NONE)
                root = i;
            const size_t p = g->parent[i];
            if (ACTIVE(i) && !rod->mark[p]) {
                rod->mark[p] = 1;
                rod->queue[tail++] = p;
            }
            for (size_t k = g->child_start[i]; k < g->child_start[i + 1]; ++k) {
                const size_t c = g->child[k];
                if (ACTIVE(c) && !rod->mark[c]) {
                    rod->mark[c] = 1;
                    rod->queue[tail++] = c;
                }
            }
        }
        if (root == PHC_TREE_NONE) {
            if (statics)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "rod: segment %ld: the part of the plant cut off at this "
                                     "segment's joint has no fixed segment (support), so it has no "
                                     "static equilibrium (it falls freely)",
                                     g->source_id[top]);
            root = top;
        }
        /* re-root at `root`: breadth-first again, marking with 2 */
        head = tail = 0;
        rod->queue[tail++] = root;
        rod->mark[root] = 2;
        t->dim[root] = rod->fixed[root] ? 0 : 6;
        while (head < tail) {
            const size_t i = rod->queue[head++];
            const size_t p = g->parent[i];
            if (ACTIVE(i) && rod->mark[p] != 2) {
                rod->mark[p] = 2;
                rod->queue[tail++] = p;
                t->parent[p] = i;
                t->dim[p] = 12;
                rod->ejoint[p] = i; /* the joint of segment i joins p and i */
                rod->jnode[i] = p;
                if (rod->fixed[p])
                    rod->anchors[rod->n_anchors++] = p;
            }
            for (size_t k = g->child_start[i]; k < g->child_start[i + 1]; ++k) {
                const size_t c = g->child[k];
                if (ACTIVE(c) && rod->mark[c] != 2) {
                    rod->mark[c] = 2;
                    rod->queue[tail++] = c;
                    t->parent[c] = i;
                    t->dim[c] = 12;
                    rod->ejoint[c] = c;
                    rod->jnode[c] = c;
                    if (rod->fixed[c])
                        rod->anchors[rod->n_anchors++] = c;
                }
            }
        }
    }
#undef ACTIVE
    /* the assembled joints touching each body (assemble counts them down) */
    memset(rod->jdeg, 0, n * sizeof *rod->jdeg);
    for (size_t c = 0; c < n; ++c)
        if (rod->jnode[c] != PHC_TREE_NONE) {
            ++rod->jdeg[c];
            ++rod->jdeg[g->parent[c]];
        }
    if (phc_rod_tree_set_order(t) != 0)
        return phc_error_set(err, PHC_ERR_INTERNAL, "rod: elimination tree has a cycle");
    free(rod->schur);
    free(rod->schur_piv);
    rod->schur = NULL;
    rod->schur_piv = NULL;
    if (rod->n_anchors) {
        const size_t m = 6 * rod->n_anchors;
        rod->schur = malloc(m * m * sizeof *rod->schur);
        rod->schur_piv = malloc(m * sizeof *rod->schur_piv);
        if (!rod->schur || !rod->schur_piv)
            return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory for %zu supports",
                                 rod->n_anchors);
    }
    return PHC_OK;
}

/* ---- assembly ------------------------------------------------------------ */

typedef struct step_params {
    int dynamic;
    double h, c;        /* sub-step (s), damping (s⁻¹) */
} step_params;

typedef struct residual_norm {
    double force, torque, stretch, bend, max; /* max norms of the scaled residual */
    double sq;                                /* its sum of squares (line-search merit) */
} residual_norm;

static void add_block(double *dst, int stride, const double *src6, double s)
{
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
            dst[r * stride + c] += s * src6[r * 6 + c];
}

static double load_total(const phc_rod *rod)
{
    const double *gv = rod->opt.gravity;
    const double gn = sqrt(gv[0] * gv[0] + gv[1] * gv[1] + gv[2] * gv[2]);
    double f = 0.0;
    for (size_t i = 0; i < rod->n; ++i) {
        const double *l = rod->load + 3 * i;
        if (rod->fixed[i])
            continue;
        f += rod->mass[i] * gn + sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    }
    return f * rod->load_scale;
}

/* The residual's rotation rows are gradients with respect to an increment
 * at the CURRENT orientation (a moving chart): their exact derivative is
 * the pullback Hessian plus −½[r_θ]× (from exp(ε)exp(δ) =
 * exp(δ + ε + ½ ε×δ + …)), r_θ the body's rotation residual.  It vanishes
 * at equilibrium; with it the Newton matrix is the exact Jacobian of the
 * residual map, so Newton converges quadratically from farther away and
 * the line search on the residual is consistent.  (The block is no longer
 * symmetric: the tree solver does not assume it is.)  Added to body i's
 * block once its residual is complete (assemble: after its last joint,
 * while the block is still in the cache). */
static inline void moving_chart_term(phc_rod_tree *t, const double *res, size_t i)
{
    const double *g = res + 12 * i + 3;
    double *D = t->diag + 144 * i + 3 * 12 + 3;
    D[0 * 12 + 1] += 0.5 * g[2];
    D[0 * 12 + 2] -= 0.5 * g[1];
    D[1 * 12 + 0] -= 0.5 * g[2];
    D[1 * 12 + 2] += 0.5 * g[0];
    D[2 * 12 + 0] += 0.5 * g[1];
    D[2 * 12 + 1] -= 0.5 * g[0];
}

/* assemble()'s `matrix`: MATRIX_NEWTON the exact Jacobian of the residual
 * (with the moving-chart term), MATRIX_SYMMETRIC the KKT matrix without it:
 * the Hessian of the Lagrangian E + λ·C − ½λᵀαλ in the chart centred at the
 * current state, symmetric by construction (the sensitivities use it). */
#define MATRIX_NEWTON 1
#define MATRIX_SYMMETRIC 2

/* Residual (rod->res) and, when `matrix`, the Newton matrix in rod->tree.
 * Body rows: ∇E + Σ Jᵀλ (+ inertia); joint rows: C − Aλ. */
static void assemble(phc_rod *rod, const step_params *sp, int matrix)
{
    const phc_plant_graph *g = rod->g;
    phc_rod_tree *t = rod->tree;
    const size_t n = rod->n;
    if (matrix)
        memcpy(rod->jleft, rod->jdeg, n * sizeof *rod->jleft);
    for (size_t i = 0; i < n; ++i) {
        double *r = rod->res + 12 * i, *D = t->diag + 144 * i;
        memset(r + 6, 0, 6 * sizeof *r);
        if (matrix)
            /* Only what is accumulated or not written below is zeroed: the
             * body block (rows and columns 0..5) and the multipliers' block
             * (6..11, where only the diagonal −α is written).  The joint
             * blocks of a 12-node and its whole coupling block are assigned
             * below; a 6-node has no coupling.  Zeroed here, in the pass
             * that writes the block next, not in a pass of its own. */
            for (int a = 0; a < 6; ++a) {
                memset(D + a * 12, 0, 6 * sizeof *D);
                memset(D + (6 + a) * 12 + 6, 0, 6 * sizeof *D);
            }
        const double m = rod->mass[i], ts = rod->load_scale;
        const double F[3] = {ts * rod->load[3 * i], ts * rod->load[3 * i + 1],
                             ts * rod->load[3 * i + 2]};
        double u[3];
        phc_rod_internal_tail_offset(rod, i, u);
        for (int k = 0; k < 3; ++k)
            r[k] = -m * ts * rod->opt.gravity[k] - F[k];
        /* torque of the tail load: ∇_θ(−F·(x + Ru)) = −u × F */
        r[3] = -(u[1] * F[2] - u[2] * F[1]);
        r[4] = -(u[2] * F[0] - u[0] * F[2]);
        r[5] = -(u[0] * F[1] - u[1] * F[0]);
        if (matrix) {
            const double fu = F[0] * u[0] + F[1] * u[1] + F[2] * u[2];
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    D[(3 + a) * 12 + 3 + b] -= 0.5 * (F[a] * u[b] + u[a] * F[b]) - (a == b ? fu : 0.0);
        }
        if (sp->dynamic && !rod->fixed[i]) {
            const double s2 = 1.0 / (sp->h * sp->h), s1 = sp->c / sp->h;
            double iw[9], qc[4], rel[4], th_p[3], th_o[3];
            for (int k = 0; k < 3; ++k)
                r[k] += m * ((rod->x[3 * i + k] - rod->xp[3 * i + k]) * s2 +
                             (rod->x[3 * i + k] - rod->xo[3 * i + k]) * s1);
            phc_rod_internal_world_inertia(rod, i, iw, 0);
            phc_quat_conj(rod->qp + 4 * i, qc);
            phc_quat_mul(rod->q + 4 * i, qc, rel);
            phc_quat_log(rel, th_p);
            phc_quat_conj(rod->qo + 4 * i, qc);
            phc_quat_mul(rod->q + 4 * i, qc, rel);
            phc_quat_log(rel, th_o);
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    r[3 + a] += iw[a * 3 + b] * (th_p[b] * s2 + th_o[b] * s1);
            if (matrix) {
                for (int k = 0; k < 3; ++k)
                    D[k * 12 + k] += m * (s2 + s1);
                for (int a = 0; a < 3; ++a)
                    for (int b = 0; b < 3; ++b)
                        D[(3 + a) * 12 + 3 + b] += iw[a * 3 + b] * (s2 + s1);
            }
        }
        if (matrix == MATRIX_NEWTON && rod->jleft[i] == 0) /* no joint: its residual is complete */
            moving_chart_term(t, rod->res, i);
    }
    for (size_t c = 0; c < n; ++c) {
        const size_t k = rod->jnode[c];
        if (k == PHC_TREE_NONE)
            continue; /* root or cut */
        const size_t p = g->parent[c];
        const phc_rod_joint_geometry *jg = rod->joint + c;
        const double *lam = rod->lambda + 6 * c;
        double C[6], Jp[36], Jc[36], Hpp[36], Hpc[36], Hcc[36];
        phc_rod_joint_eval(jg, rod->x + 3 * p, rod->q + 4 * p, rod->x + 3 * c, rod->q + 4 * c, C,
                           Jp, Jc);
        double *rp = rod->res + 12 * p, *rc = rod->res + 12 * c, *rk = rod->res + 12 * k + 6;
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 6; ++b) {
                rp[a] += Jp[b * 6 + a] * lam[b];
                rc[a] += Jc[b * 6 + a] * lam[b];
            }
        double alpha[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        for (int a = 0; a < 3; ++a)
            alpha[3 + a] = 1.0 / (rod->factor[c] * rod->stiff[3 * c + a]);
        for (int a = 0; a < 6; ++a)
            rk[a] = C[a] - alpha[a] * lam[a];
        if (!matrix)
            continue;
        phc_rod_joint_hessian(jg, rod->q + 4 * p, rod->q + 4 * c, lam, Hpp, Hpc, Hcc);
        add_block(t->diag + 144 * p, 12, Hpp, 1.0);
        add_block(t->diag + 144 * c, 12, Hcc, 1.0);
        const double *Jk = (k == c) ? Jc : Jp, *Jo = (k == c) ? Jp : Jc;
        double *D = t->diag + 144 * k, *A = t->coup + 72 * k;
        for (int a = 0; a < 6; ++a) {
            for (int b = 0; b < 6; ++b) {
                D[(6 + a) * 12 + b] = Jk[a * 6 + b];
                D[b * 12 + 6 + a] = Jk[a * 6 + b];
                /* coupling rows 0..5: H[k body, other body]; rows 6..11: J_other */
                A[a * 6 + b] = (k == p) ? Hpc[a * 6 + b] : Hpc[b * 6 + a];
                A[(6 + a) * 6 + b] = Jo[a * 6 + b];
            }
            D[(6 + a) * 12 + 6 + a] = -alpha[a];
        }
        /* a body whose last joint this was has its residual complete */
        if (--rod->jleft[p] == 0 && matrix == MATRIX_NEWTON)
            moving_chart_term(t, rod->res, p);
        if (--rod->jleft[c] == 0 && matrix == MATRIX_NEWTON)
            moving_chart_term(t, rod->res, c);
    }
}

/* The force scale of the scaled residual: the total load, and in dynamics
 * also the momentum change Σ m |v_old| / h of a sub-step and the largest
 * joint force |λ_s| (so that a free vibration without gravity or loads has
 * a scale too). */
static residual_norm residual_measure(const phc_rod *rod, const step_params *sp)
{
    residual_norm rn = {0, 0, 0, 0, 0, 0};
    const double L = rod->reach;
    double F = load_total(rod), lmax = 0.0;
    if (sp->dynamic)
        for (size_t i = 0; i < rod->n; ++i)
            if (!rod->fixed[i]) {
                const double *v = rod->v + 3 * i;
                const double *l = rod->lambda + 6 * i;
                F += rod->mass[i] * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / sp->h;
                lmax = fmax(lmax, sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]));
            }
    F += lmax;
    if (!(F > 0.0))
        F = 1e-300;
    for (size_t i = 0; i < rod->n; ++i) {
        const double *r = rod->res + 12 * i;
        if (!rod->fixed[i])
            for (int k = 0; k < 3; ++k) {
                const double a = fabs(r[k]) / F, b = fabs(r[3 + k]) / (F * L);
                rn.force = fmax(rn.force, a);
                rn.torque = fmax(rn.torque, b);
                rn.sq += a * a + b * b;
            }
        if (rod->tree->dim[i] == 12) {
            const size_t c = rod->ejoint[i];
            for (int k = 0; k < 3; ++k) {
                /* (C − αλ)·f ℓK: a moment × length, N m² */
                const double a = fabs(r[6 + k]) / L,
                             b = fabs(r[9 + k]) * rod->factor[c] * rod->stiff[3 * c + k] / (F * L * L);
                rn.stretch = fmax(rn.stretch, a);
                rn.bend = fmax(rn.bend, b);
                rn.sq += a * a + b * b;
            }
        }
    }
    rn.max = fmax(fmax(rn.force, rn.torque), fmax(rn.stretch, rn.bend));
    if (!isfinite(rn.max) || !isfinite(rn.sq))
        rn.max = rn.sq = INFINITY;
    return rn;
}

/* newton_direction: solves the Newton system for −res into rod->sol.
 * kkt_solve and it return PHC_TREE_NONE, the singular node, or
 * DIRECTION_NOMEM. */
#define DIRECTION_NOMEM ((size_t)-2)

/* Solves the assembled system A u = rod->sol in place (12 per node),
 * supports by Schur complement.  factorise: 1 factorises rod->tree first,
 * 0 uses the factors already there.  Returns as newton_direction. */
static size_t kkt_solve(phc_rod *rod, int factorise)
{
    phc_rod_tree *t = rod->tree;
    const size_t n = rod->n, na = rod->n_anchors, m = 6 * na;
    if (na == 0) { /* factorisation and solve in one sweep */
        if (factorise)
            return phc_rod_tree_factor_solve(t, rod->sol);
        phc_rod_tree_solve(t, rod->sol);
        return PHC_TREE_NONE;
    }
    if (factorise) {
        const size_t bad = phc_rod_tree_factor(t);
        if (bad != PHC_TREE_NONE)
            return bad;
    }
    /* u0 = K⁻¹(−r); S = G K⁻¹ Gᵀ; μ = S⁻¹ G u0; u = K⁻¹(−r − Gᵀ μ) */
    double *mu = malloc(m * sizeof *mu);
    if (!mu)
        return DIRECTION_NOMEM;
    memcpy(rod->rhs, rod->sol, 12 * n * sizeof *rod->rhs);
    phc_rod_tree_solve(t, rod->rhs);
    for (size_t a = 0; a < na; ++a)
        for (int k = 0; k < 6; ++k)
            mu[6 * a + k] = rod->rhs[12 * rod->anchors[a] + k];
    for (size_t col = 0; col < m; ++col) {
        memset(rod->rhs, 0, 12 * n * sizeof *rod->rhs);
        rod->rhs[12 * rod->anchors[col / 6] + col % 6] = 1.0;
        phc_rod_tree_solve(t, rod->rhs);
        for (size_t a = 0; a < na; ++a)
            for (int k = 0; k < 6; ++k)
                rod->schur[(6 * a + k) * m + col] = rod->rhs[12 * rod->anchors[a] + k];
    }
    /* S may be singular: an inextensible span between two supports leaves
     * its axial force undetermined (the multipliers, not the positions).  It
     * is not symmetric either (the −½[r]× term).  Pseudo-inverse by SVD, in
     * units where rotations are scaled by the reach (every entry m/N),
     * dropping singular values below 1e-10 of the largest. */
    {
        const double L = rod->reach;
        double *sv = malloc(m * sizeof *sv), *tmp = malloc(m * sizeof *tmp);
        double *U = malloc(m * m * sizeof *U), *VT = malloc(m * m * sizeof *VT);
        double *superb = malloc((m > 1 ? m : 2) * sizeof *superb);
        const int nomem = !sv || !tmp || !U || !VT || !superb;
        int bad = nomem;
        if (!bad) {
            for (size_t r = 0; r < m; ++r) {
                const double sr = (r % 6 >= 3) ? L : 1.0;
                mu[r] *= sr;
                for (size_t c = 0; c < m; ++c)
                    rod->schur[r * m + c] *= sr * ((c % 6 >= 3) ? L : 1.0);
            }
            bad = LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'A', 'A', (lapack_int)m, (lapack_int)m,
                                 rod->schur, (lapack_int)m, sv, U, (lapack_int)m, VT,
                                 (lapack_int)m, superb) != 0;
        }
        if (!bad) {
            const double smax = sv[0]; /* descending */
            for (size_t k = 0; k < m; ++k) {
                double d = 0.0;
                for (size_t r = 0; r < m; ++r)
                    d += U[r * m + k] * mu[r];
                tmp[k] = (sv[k] > 1e-10 * smax) ? d / sv[k] : 0.0;
            }
            for (size_t r = 0; r < m; ++r) {
                double d = 0.0;
                for (size_t k = 0; k < m; ++k)
                    d += VT[k * m + r] * tmp[k];
                mu[r] = d * ((r % 6 >= 3) ? L : 1.0);
            }
        }
        free(sv);
        free(tmp);
        free(U);
        free(VT);
        free(superb);
        if (bad) {
            free(mu);
            return nomem ? DIRECTION_NOMEM : rod->anchors[0];
        }
    }
    for (size_t a = 0; a < na; ++a)
        for (int k = 0; k < 6; ++k)
            rod->sol[12 * rod->anchors[a] + k] -= mu[6 * a + k];
    phc_rod_tree_solve(t, rod->sol);
    /* the supports' own rows are exactly zero up to rounding: make them so */
    for (size_t a = 0; a < na; ++a)
        for (int k = 0; k < 6; ++k)
            rod->sol[12 * rod->anchors[a] + k] = 0.0;
    free(mu);
    return PHC_TREE_NONE;
}

static size_t newton_direction(phc_rod *rod)
{
    const phc_rod_tree *t = rod->tree;
    for (size_t i = 0; i < rod->n; ++i)
        for (int k = 0; k < 12; ++k)
            rod->sol[12 * i + k] = (k < t->dim[i]) ? -rod->res[12 * i + k] : 0.0;
    return kkt_solve(rod, 1);
}

static void save_state(phc_rod *rod)
{
    memcpy(rod->xs, rod->x, 3 * rod->n * sizeof *rod->x);
    memcpy(rod->qs, rod->q, 4 * rod->n * sizeof *rod->q);
    memcpy(rod->ls, rod->lambda, 6 * rod->n * sizeof *rod->lambda);
}

static void restore_state(phc_rod *rod)
{
    memcpy(rod->x, rod->xs, 3 * rod->n * sizeof *rod->x);
    memcpy(rod->q, rod->qs, 4 * rod->n * sizeof *rod->q);
    memcpy(rod->lambda, rod->ls, 6 * rod->n * sizeof *rod->lambda);
}

/* state = saved + s · sol */
static void apply_step(phc_rod *rod, double s)
{
    for (size_t i = 0; i < rod->n; ++i) {
        const double *u = rod->sol + 12 * i;
        const int d = rod->tree->dim[i];
        memcpy(rod->x + 3 * i, rod->xs + 3 * i, 3 * sizeof *rod->x);
        memcpy(rod->q + 4 * i, rod->qs + 4 * i, 4 * sizeof *rod->q);
        if (d >= 6) {
            double dth[3] = {s * u[3], s * u[4], s * u[5]}, e[4];
            for (int k = 0; k < 3; ++k)
                rod->x[3 * i + k] += s * u[k];
            phc_quat_exp(dth, e);
            phc_quat_mul(e, rod->qs + 4 * i, rod->q + 4 * i);
            phc_quat_normalize(rod->q + 4 * i);
        }
        if (d == 12) {
            const size_t c = rod->ejoint[i];
            for (int k = 0; k < 6; ++k)
                rod->lambda[6 * c + k] = rod->ls[6 * c + k] + s * u[6 + k];
        }
    }
}

/* A step below 1e-12 of the reach (and 1e-12 rad) ends the iteration as
 * converged only when the residual is within this factor of the tolerance
 * (rounding can keep it just above); otherwise it is a stall. */
#define STEP_RESIDUAL 1e3

/* Newton with backtracking on the scaled residual.  0 converged, otherwise
 * PHC_ERR_NOT_CONVERGED / PHC_ERR_NUMERIC with the message set. */
static int newton(phc_rod *rod, const step_params *sp, int cap, phc_rod_report *rep,
                  phc_error *err)
{
    const phc_plant_graph *g = rod->g;
    const double tol = rod->opt.tolerance, L = rod->reach;
    assemble(rod, sp, MATRIX_NEWTON);
    residual_norm rn = residual_measure(rod, sp);
    rep->iterations = 0;
    rep->residual = rn.max;
    for (int it = 0; it < cap; ++it) {
        if (rn.max <= tol)
            return PHC_OK;
        const size_t bad = newton_direction(rod);
        if (bad == DIRECTION_NOMEM)
            return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory for the supports' system");
        if (bad != PHC_TREE_NONE)
            return phc_error_set(err, PHC_ERR_NUMERIC,
                                 "rod: segment %ld: the Newton system is singular at iteration %d "
                                 "(a loose part, or a segment whose joint has no stiffness)",
                                 g->source_id[bad], it + 1);
        /* step length: cap rotations at 1 rad per iteration */
        double maxrot = 0.0, maxdx = 0.0, s = 1.0;
        for (size_t i = 0; i < rod->n; ++i) {
            const double *u = rod->sol + 12 * i;
            maxdx = fmax(maxdx, fmax(fabs(u[0]), fmax(fabs(u[1]), fabs(u[2]))));
            maxrot = fmax(maxrot, sqrt(u[3] * u[3] + u[4] * u[4] + u[5] * u[5]));
        }
        if (!isfinite(maxdx) || !isfinite(maxrot))
            return phc_error_set(err, PHC_ERR_NUMERIC,
                                 "rod: the Newton step is not finite at iteration %d", it + 1);
        if (maxrot > 1.0)
            s = 1.0 / maxrot;
        save_state(rod);
        const double phi0 = rn.sq;
        residual_norm trial = rn;
        int accepted = 0, have_matrix = 0;
        for (int ls = 0; ls < 30; ++ls, s *= 0.5) {
            apply_step(rod, s);
            /* the first trial (almost always accepted) assembles the matrix
             * too: the next iteration's, then not assembled again */
            assemble(rod, sp, ls == 0 ? MATRIX_NEWTON : 0);
            trial = residual_measure(rod, sp);
            if (trial.sq < (1.0 - 1e-4 * s) * phi0 || trial.max <= tol) {
                accepted = 1;
                have_matrix = ls == 0;
                break;
            }
        }
        rep->iterations = it + 1;
        if (!accepted) {
            /* no decrease: converged to rounding if the step is tiny */
            restore_state(rod);
            assemble(rod, sp, 0);
            if (maxdx * s <= 1e-12 * L && maxrot * s <= 1e-12 && rn.max <= STEP_RESIDUAL * tol)
                return PHC_OK;
            return phc_error_set(err, PHC_ERR_NOT_CONVERGED,
                                 "rod: Newton iteration %d: no step decreases the residual "
                                 "(scaled residual %.3g, tolerance %.3g)",
                                 it + 1, rn.max, tol);
        }
        rn = trial;
        rep->residual = rn.max;
        if (rn.max <= tol) /* rod->res is this state's: no matrix needed */
            return PHC_OK;
        if (maxdx * s <= 1e-12 * L && maxrot * s <= 1e-12 && s == 1.0 &&
            rn.max <= STEP_RESIDUAL * tol)
            return PHC_OK;
        if (!have_matrix)
            assemble(rod, sp, MATRIX_NEWTON);
    }
    if (rn.max <= tol)
        return PHC_OK;
    return phc_error_set(err, PHC_ERR_NOT_CONVERGED,
                         "rod: no convergence in %d Newton iterations (scaled residual %.3g: "
                         "force %.3g, torque %.3g, stretch %.3g, bending %.3g; tolerance %.3g)",
                         cap, rn.max, rn.force, rn.torque, rn.stretch, rn.bend,
                         tol);
}

/* ---- pseudo-transient continuation (the statics' last resort) ----------
 *
 * Kelley & Keyes 1998, "Convergence analysis of pseudo-transient
 * continuation" (SIAM J. Numer. Anal. 35(2), 508–523): implicit steps of a
 * pseudo-time h of the motion released at rest from the current shape,
 *     r(x) + M (x − x_k)/h² = 0,   rotations: r_θ + I_w log(q q̄_k)/h² = 0
 * (the dynamics' backward-Euler residual with zero velocity and no damping;
 * M the masses, I_w the world inertia).  A step is a proximal step on the
 * potential energy in the mass metric: the plant moves downhill towards a
 * stable equilibrium instead of taking the huge, rotation-wrapping Newton
 * steps of a soft plant released from rest (on plant000 at E = 1e6 Pa,
 * Newton and the load continuation stall there: line-search steps of 1e-3
 * of the Newton step, rotations of 20–170 rad proposed).  Each step is
 * solved loosely (scaled residual PT_INNER_TOL, at most PT_INNER_CAP Newton
 * iterations; Kelley & Keyes take one): h doubles after a step solved in
 * PT_EASY iterations or fewer, stays after PT_HARD or fewer, halves after
 * more.  A step not solved within PT_INNER_CAP is kept (Newton only
 * accepts iterates that decrease its residual: an inexact proximal step)
 * and h halves; a singular one is undone.  After every step the static residual
 * is measured (done when within the tolerance), and when a step moved no
 * segment by more than PT_REST × reach, a static Newton from there is tried
 * (undone when it fails).  So the result always meets the statics'
 * tolerance.  Where a plant has several stable equilibria, the one reached
 * depends on the path: plant000 at 1e6 Pa settles with a largest tail
 * displacement of 0.501 m this way (and when each step is solved to 1e-8),
 * 0.469 m when each step is solved to 1e-3 in at most 4 iterations (both
 * within the tolerance). */
#define PT_INNER_CAP 6    /* Newton iterations per pseudo-time step */
#define PT_INNER_TOL 1e-3 /* their scaled tolerance (loose: one step is no answer) */
#define PT_EASY 2         /* h doubles after a step that took this many or fewer, */
#define PT_HARD 4         /* stays after one that took this many or fewer, else halves */
#define PT_SHRINK 0.5
#define PT_INNER_REL 1e-2 /* and this times the static residual before the step */
#define PT_POLISH_CAP 12  /* Newton iterations of a static attempt */
#define PT_REST 1e-3      /* a step this short (× reach): try the statics */
#define PT_H_MIN 1e-9     /* s: below this the pseudo-time stalls */
#define PT_BUDGET 4       /* its Newton iterations: this × options.max_iterations */

static int pseudo_transient(phc_rod *rod, int budget, double *save, phc_rod_report *rep,
                            phc_error *err)
{
    const size_t n = rod->n;
    const double tol = rod->opt.tolerance, L = rod->reach;
    const double *gv = rod->opt.gravity;
    const double gn = sqrt(gv[0] * gv[0] + gv[1] * gv[1] + gv[2] * gv[2]);
    /* a tenth of the free-fall time over the reach, s */
    double h = gn > 0.0 ? 0.1 * sqrt(L / gn) : 1e-3;
    double *xk = save, *qk = save + 3 * n, *lk = save + 7 * n;
    step_params dyn = {1, h, 0.0}, sta = {0, 0.0, 0.0};
    phc_rod_report stage;
    int steps = 0;
    rep->iterations = 0;
    rep->residual = INFINITY;
    memset(rod->v, 0, 3 * n * sizeof *rod->v);
    memset(rod->w, 0, 3 * n * sizeof *rod->w);
    assemble(rod, &sta, 0);
    rep->residual = residual_measure(rod, &sta).max;
    while (rep->iterations < budget) {
        if (h < PT_H_MIN)
            return phc_error_set(err, PHC_ERR_NOT_CONVERGED,
                                 "rod: no static equilibrium: the pseudo-time steps of the plant "
                                 "released at rest shrank below %g s after %d steps (scaled "
                                 "residual %.3g, tolerance %.3g)",
                                 PT_H_MIN, steps, rep->residual, tol);
        memcpy(xk, rod->x, 3 * n * sizeof *xk);
        memcpy(qk, rod->q, 4 * n * sizeof *qk);
        memcpy(lk, rod->lambda, 6 * n * sizeof *lk);
        dyn.h = h;
        phc_rod_internal_predict(rod, h); /* v = ω = 0: xo = xp = x, qo = qp = q */
        /* relative to the static residual: the dynamics' measure has a
         * larger force scale (it adds the largest joint force), so a fixed
         * tolerance could pass a step with no iteration at all */
        rod->opt.tolerance = fmax(tol, fmin(PT_INNER_TOL, PT_INNER_REL * rep->residual));
        const int left = budget - rep->iterations;
        int rc = newton(rod, &dyn, left < PT_INNER_CAP ? left : PT_INNER_CAP, &stage, err);
        rod->opt.tolerance = tol;
        rep->iterations += stage.iterations;
        if (rc == PHC_ERR_NOMEM)
            return rc;
        if (rc != PHC_OK && rc != PHC_ERR_NOT_CONVERGED) { /* singular, not finite */
            memcpy(rod->x, xk, 3 * n * sizeof *xk);
            memcpy(rod->q, qk, 4 * n * sizeof *qk);
            memcpy(rod->lambda, lk, 6 * n * sizeof *lk);
            h *= PT_SHRINK;
            continue;
        }
        if (rc != PHC_OK) /* not solved, but its residual decreased: kept, h halves */
            stage.iterations = PT_INNER_CAP + 1;
        ++steps;
        double moved = 0.0;
        for (size_t i = 0; i < n; ++i) {
            double d = 0.0;
            for (int k = 0; k < 3; ++k)
                d += (rod->x[3 * i + k] - xk[3 * i + k]) * (rod->x[3 * i + k] - xk[3 * i + k]);
            moved = fmax(moved, sqrt(d));
        }
        h *= stage.iterations <= PT_EASY ? 2.0 : (stage.iterations <= PT_HARD ? 1.0 : PT_SHRINK);
        assemble(rod, &sta, 0);
        rep->residual = residual_measure(rod, &sta).max;
        if (rep->residual <= tol)
            return PHC_OK;
        if (moved > PT_REST * L || rep->iterations >= budget)
            continue;
        /* near rest: the statics from here */
        memcpy(xk, rod->x, 3 * n * sizeof *xk);
        memcpy(qk, rod->q, 4 * n * sizeof *qk);
        memcpy(lk, rod->lambda, 6 * n * sizeof *lk);
        const int left2 = budget - rep->iterations;
        rc = newton(rod, &sta, left2 < PT_POLISH_CAP ? left2 : PT_POLISH_CAP, &stage, err);
        rep->iterations += stage.iterations;
        if (rc == PHC_OK) {
            rep->residual = stage.residual;
            return PHC_OK;
        }
        if (rc == PHC_ERR_NOMEM)
            return rc;
        memcpy(rod->x, xk, 3 * n * sizeof *xk);
        memcpy(rod->q, qk, 4 * n * sizeof *qk);
        memcpy(rod->lambda, lk, 6 * n * sizeof *lk);
    }
    return phc_error_set(err, PHC_ERR_NOT_CONVERGED,
                         "rod: no static equilibrium within %d Newton iterations of pseudo-time "
                         "steps (%d steps, the last of %g s; scaled residual %.3g, tolerance %.3g)",
                         budget, steps, h, rep->residual, tol);
}

/* Newton at load factor 1 from the current state; when that fails, load
 * continuation from the rest shape (the equilibrium at load factor 0): the
 * factor grows by doubling increments, an increment halves when its Newton
 * solve fails.  Each stage at most STAGE_CAP iterations; all stages share
 * options.max_iterations. */
#define STAGE_CAP 40

int phc_rod_solve_static(phc_rod *rod, phc_rod_report *report, phc_error *err)
{
    phc_rod_report local, stage;
    phc_rod_report *rep = report ? report : &local;
    step_params sp = {0, 0.0, 0.0};
    const size_t n = rod->n;
    int rc = build_tree(rod, 1, err);
    memset(rep, 0, sizeof *rep);
    if (rc != PHC_OK)
        return rc;
    /* the start (restored on failure) and the last converged stage */
    double *keep = malloc(32 * n * sizeof *keep);
    if (!keep)
        return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory");
    double *x = keep, *q = keep + 3 * n, *l = keep + 7 * n;
    double *xg = keep + 13 * n, *qg = keep + 16 * n, *lg = keep + 20 * n;
    memcpy(x, rod->x, 3 * n * sizeof *x);
    memcpy(q, rod->q, 4 * n * sizeof *q);
    memcpy(l, rod->lambda, 6 * n * sizeof *l);
    memcpy(keep + 26 * n, rod->v, 3 * n * sizeof *keep);
    memcpy(keep + 29 * n, rod->w, 3 * n * sizeof *keep);
    const int budget = rod->opt.max_iterations;
    const int cap = budget < STAGE_CAP ? budget : STAGE_CAP;
    rod->load_scale = 1.0;
    rc = newton(rod, &sp, cap, &stage, err);
    rep->total_iterations = stage.iterations;
    rep->residual = stage.residual;
    if (rc != PHC_OK && rc != PHC_ERR_NOMEM) {
        double t = 0.0, dt = 0.5;
        phc_rod_reset(rod);
        memcpy(xg, rod->x, 3 * n * sizeof *x);
        memcpy(qg, rod->q, 4 * n * sizeof *q);
        memcpy(lg, rod->lambda, 6 * n * sizeof *l);
        while (t < 1.0) {
            if (rep->total_iterations >= budget) {
                rc = phc_error_set(err, PHC_ERR_NOT_CONVERGED,
                                   "rod: no static equilibrium within %d Newton iterations "
                                   "(load continuation reached %.3g of the load; scaled residual "
                                   "%.3g, tolerance %.3g)",
                                   budget, t, stage.residual, rod->opt.tolerance);
                break;
            }
            if (dt < 1e-6) {
                rc = phc_error_set(err, PHC_ERR_NOT_CONVERGED,
                                   "rod: no static equilibrium: load continuation stalled at %.6g "
                                   "of the load (%s)",
                                   t, err ? err->message : "");
                break;
            }
            const double tt = fmin(1.0, t + dt);
            rod->load_scale = tt;
            int left = budget - rep->total_iterations;
            rc = newton(rod, &sp, left < cap ? left : cap, &stage, err);
            rep->total_iterations += stage.iterations;
            rep->residual = stage.residual;
            if (rc == PHC_ERR_NOMEM)
                break;
            if (rc == PHC_OK) {
                t = tt;
                dt = fmin(2.0 * dt, 1.0);
                memcpy(xg, rod->x, 3 * n * sizeof *x);
                memcpy(qg, rod->q, 4 * n * sizeof *q);
                memcpy(lg, rod->lambda, 6 * n * sizeof *l);
            } else {
                dt *= 0.5;
                memcpy(rod->x, xg, 3 * n * sizeof *x);
                memcpy(rod->q, qg, 4 * n * sizeof *q);
                memcpy(rod->lambda, lg, 6 * n * sizeof *l);
            }
        }
        if (t >= 1.0)
            rc = PHC_OK;
    }
    rod->load_scale = 1.0;
    if (rc != PHC_OK && rc != PHC_ERR_NOMEM) {
        /* the plant released at rest from the start shape, in pseudo-time,
         * with a budget of its own (PT_BUDGET × max_iterations) */
        char first[PHC_ERROR_MESSAGE_SIZE];
        snprintf(first, sizeof first, "%s", err ? err->message : "");
        memcpy(rod->x, x, 3 * n * sizeof *x);
        memcpy(rod->q, q, 4 * n * sizeof *q);
        memcpy(rod->lambda, l, 6 * n * sizeof *l);
        rc = pseudo_transient(rod, PT_BUDGET * budget, xg, &stage, err);
        rep->total_iterations += stage.iterations;
        rep->residual = stage.residual;
        if (rc != PHC_OK && rc != PHC_ERR_NOMEM && err)
            phc_error_prefix(err, PHC_ERR_NOT_CONVERGED, "%s; then", first);
    }
    rep->iterations = rep->total_iterations;
    if (rc != PHC_OK) {
        memcpy(rod->x, x, 3 * n * sizeof *x);
        memcpy(rod->q, q, 4 * n * sizeof *q);
        memcpy(rod->lambda, l, 6 * n * sizeof *l);
        memcpy(rod->v, keep + 26 * n, 3 * n * sizeof *keep);
        memcpy(rod->w, keep + 29 * n, 3 * n * sizeof *keep);
    } else {
        memset(rod->v, 0, 3 * n * sizeof *rod->v);
        memset(rod->w, 0, 3 * n * sizeof *rod->w);
        phc_error_clear(err);
    }
    free(keep);
    return rc;
}

/* ---- dynamics ------------------------------------------------------------ */

/* rotation vector taking qa to qb: log(qb q̄a) */
static void rotation_between(const double qa[4], const double qb[4], double v[3])
{
    double c[4], r[4];
    phc_quat_conj(qa, c);
    phc_quat_mul(qb, c, r);
    phc_quat_log(r, v);
}

/* after a sub-step from (xo, qo): velocities; refuse large rotations */
int phc_rod_internal_finish_substep(phc_rod *rod, double h, phc_error *err)
{
    for (size_t i = 0; i < rod->n; ++i) {
        double th[3];
        rotation_between(rod->qo + 4 * i, rod->q + 4 * i, th);
        const double a = sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]);
        if (!(a <= rod->opt.max_rotation))
            return phc_error_set(err, PHC_ERR_DOMAIN,
                                 "rod: segment %ld turns %.3g rad in one sub-step of %g s (limit "
                                 "%g rad): the time step is too large for this stiffness and load; "
                                 "use a smaller step or more sub-steps",
                                 rod->g->source_id[i], a, h, rod->opt.max_rotation);
        for (int k = 0; k < 3; ++k) {
            rod->v[3 * i + k] = (rod->x[3 * i + k] - rod->xo[3 * i + k]) / h;
            rod->w[3 * i + k] = th[k] / h;
        }
    }
    return PHC_OK;
}

void phc_rod_internal_predict(phc_rod *rod, double h)
{
    for (size_t i = 0; i < rod->n; ++i) {
        memcpy(rod->xo + 3 * i, rod->x + 3 * i, 3 * sizeof *rod->x);
        memcpy(rod->qo + 4 * i, rod->q + 4 * i, 4 * sizeof *rod->q);
        double e[4], dth[3];
        for (int k = 0; k < 3; ++k) {
            rod->xp[3 * i + k] = rod->x[3 * i + k] + h * rod->v[3 * i + k];
            dth[k] = h * rod->w[3 * i + k];
        }
        phc_quat_exp(dth, e);
        phc_quat_mul(e, rod->q + 4 * i, rod->qp + 4 * i);
        phc_quat_normalize(rod->qp + 4 * i);
    }
}

static int substep_direct(phc_rod *rod, double h, phc_rod_report *rep, phc_error *err)
{
    step_params sp = {1, h, rod->opt.damping};
    phc_rod_internal_predict(rod, h);
    /* start from the prediction (fixed bodies stay) */
    for (size_t i = 0; i < rod->n; ++i)
        if (!rod->fixed[i]) {
            memcpy(rod->x + 3 * i, rod->xp + 3 * i, 3 * sizeof *rod->x);
            memcpy(rod->q + 4 * i, rod->qp + 4 * i, 4 * sizeof *rod->q);
        }
    int rc = newton(rod, &sp, rod->opt.max_iterations, rep, err);
    if (rc != PHC_OK)
        return phc_error_prefix(err, PHC_ERR_DOMAIN,
                                "rod: the implicit step of %g s did not converge (time step too "
                                "large?)",
                                h);
    return phc_rod_internal_finish_substep(rod, h, err);
}

int phc_rod_step(phc_rod *rod, double dt, phc_rod_report *report, phc_error *err)
{
    phc_rod_report local;
    phc_rod_report *rep = report ? report : &local;
    memset(rep, 0, sizeof *rep);
    if (!(dt > 0.0) || !isfinite(dt))
        return phc_error_set(err, PHC_ERR_DOMAIN, "rod: time step must be positive and finite, found %g s",
                             dt);
    int rc = build_tree(rod, 0, err);
    if (rc != PHC_OK)
        return rc;
    const size_t n = rod->n;
    /* keep the frame's start to restore on refusal */
    double *keep = malloc(16 * n * sizeof *keep);
    if (!keep)
        return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory");
    memcpy(keep, rod->x, 3 * n * sizeof *keep);
    memcpy(keep + 3 * n, rod->q, 4 * n * sizeof *keep);
    memcpy(keep + 7 * n, rod->v, 3 * n * sizeof *keep);
    memcpy(keep + 10 * n, rod->lambda, 6 * n * sizeof *keep);
    double *wkeep = malloc(3 * n * sizeof *wkeep);
    if (!wkeep) {
        free(keep);
        return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory");
    }
    memcpy(wkeep, rod->w, 3 * n * sizeof *wkeep);
    const double h = dt / rod->opt.substeps;
    for (int s = 0; s < rod->opt.substeps && rc == PHC_OK; ++s) {
        if (rod->opt.scheme == PHC_ROD_GAUSS_SEIDEL) {
            rc = phc_rod_internal_gauss_seidel_substep(rod, h, err);
            rep->iterations = rod->opt.gs_iterations;
        } else {
            rc = substep_direct(rod, h, rep, err);
        }
        rep->total_iterations += rep->iterations;
    }
    if (rc != PHC_OK) {
        memcpy(rod->x, keep, 3 * n * sizeof *keep);
        memcpy(rod->q, keep + 3 * n, 4 * n * sizeof *keep);
        memcpy(rod->v, keep + 7 * n, 3 * n * sizeof *keep);
        memcpy(rod->lambda, keep + 10 * n, 6 * n * sizeof *keep);
        memcpy(rod->w, wkeep, 3 * n * sizeof *wkeep);
    }
    free(keep);
    free(wkeep);
    return rc;
}

/* ---- sensitivities of the static equilibrium (rod.h) -------------------
 *
 * At the equilibrium F(z, λ; E) = 0 of phc_rod_solve_static (body rows
 * ∇E_pot + Σ Jᵀλ, joint rows C − αλ: Deul et al. 2018 §3, eq. 5 and 7, in
 * the compliant form of rod.h, λ_b = f ℓK (Ω − Ω0), α = (f ℓK)⁻¹) only the
 * bend–twist rows of the joints depend on the moduli, through α:
 *     α_a = 1 / (f ℓ K_a),  K_a ∝ e (E I or G J, G = e / (2(1 + ν))),
 *     e = ℓ / (h_p/(2E_p) + h_c/(2E_c))                     (rod.h)
 *     ∂α_a/∂E_s = −α_a e h_s / (2 ℓ E_s²)          s ∈ {p, c}   (α per Pa)
 * so ∂F_a/∂E_s = −(∂α_a/∂E_s) λ_a = β_a w_s with β_a = α_a λ_a (the bending
 * strain Ω − Ω0 at equilibrium, 1/m) and w_s = e h_s / (2 ℓ E_s²) (1/Pa).
 * Implicit differentiation: A dz/dE = −∂F/∂E, A the KKT matrix at the
 * solution.  A is assembled without the moving-chart term (MATRIX_SYMMETRIC:
 * the Hessian of the Lagrangian in the chart centred at the solution,
 * symmetric; the Newton matrix differs from it by −½[r_θ]×, which vanishes
 * at equilibrium), so the adjoint A⁻ᵀ g is the same solve A⁻¹ g.
 * Supports (more than one fixed segment per part) by the same Schur
 * complement as the Newton steps (kkt_solve). */

/* w_s of joint c for s = p (ws[0]) and s = c (ws[1]), 1/Pa */
static void modulus_weights(const phc_rod *rod, size_t c, double ws[2])
{
    const phc_plant_graph *g = rod->g;
    const size_t p = g->parent[c];
    const double ell = rod->joint[c].ell, Ep = rod->young[p], Ec = rod->young[c];
    const double e = ell / (0.5 * g->length[p] / Ep + 0.5 * g->length[c] / Ec);
    ws[0] = e * g->length[p] / (2.0 * ell * Ep * Ep);
    ws[1] = e * g->length[c] / (2.0 * ell * Ec * Ec);
}

/* β_a = α_a λ_a of joint c (its bend–twist rows), 1/m */
static void bending_strain(const phc_rod *rod, size_t c, double beta[3])
{
    for (int a = 0; a < 3; ++a)
        beta[a] = rod->lambda[6 * c + 3 + a] / (rod->factor[c] * rod->stiff[3 * c + a]);
}

/* The symmetric KKT matrix at the current state, factorised; refuses a
 * state that is not a static equilibrium. */
static int sensitivity_prepare(phc_rod *rod, const char *what, phc_error *err)
{
    const step_params sp = {0, 0.0, 0.0};
    int rc = build_tree(rod, 1, err);
    if (rc != PHC_OK)
        return rc;
    rod->load_scale = 1.0;
    assemble(rod, &sp, MATRIX_SYMMETRIC);
    const residual_norm rn = residual_measure(rod, &sp);
    if (!(rn.max <= STEP_RESIDUAL * rod->opt.tolerance))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "rod: %s: the rod is not at a static equilibrium (scaled residual "
                             "%.3g, more than %g x the tolerance %.3g): call phc_rod_solve_static "
                             "first, after the last change of moduli, loads or supports",
                             what, rn.max, STEP_RESIDUAL, rod->opt.tolerance);
    const size_t bad = phc_rod_tree_factor(rod->tree);
    if (bad != PHC_TREE_NONE)
        return phc_error_set(err, PHC_ERR_NUMERIC,
                             "rod: %s: segment %ld: the equilibrium's KKT matrix is singular (a "
                             "buckling point, or a joint without stiffness)",
                             what, rod->g->source_id[bad]);
    return PHC_OK;
}

static int sensitivity_solve(phc_rod *rod, const char *what, phc_error *err)
{
    const size_t bad = kkt_solve(rod, 0);
    if (bad == DIRECTION_NOMEM)
        return phc_error_set(err, PHC_ERR_NOMEM, "rod: %s: out of memory for the supports' system", what);
    if (bad != PHC_TREE_NONE)
        return phc_error_set(err, PHC_ERR_NUMERIC, "rod: %s: segment %ld: the supports' system is singular",
                             what, rod->g->source_id[bad]);
    for (size_t i = 0; i < 12 * rod->n; ++i)
        if (!isfinite(rod->sol[i]))
            return phc_error_set(err, PHC_ERR_NUMERIC, "rod: %s: the solution is not finite (segment %ld)",
                                 what, rod->g->source_id[i / 12]);
    return PHC_OK;
}

int phc_rod_static_sensitivity(phc_rod *rod, size_t n_dir, const double *dE, double *dz, phc_error *err)
{
    static const char what[] = "sensitivity";
    const size_t n = rod->n;
    for (size_t i = 0; i < n_dir * n; ++i)
        if (!isfinite(dE[i]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "rod: %s: direction %zu: segment %ld: dE is not finite", what, i / n,
                                 rod->g->source_id[i % n]);
    int rc = sensitivity_prepare(rod, what, err);
    if (rc != PHC_OK)
        return rc;
    for (size_t d = 0; d < n_dir; ++d) {
        const double *de = dE + d * n;
        memset(rod->sol, 0, 12 * n * sizeof *rod->sol);
        for (size_t c = 0; c < n; ++c) {
            const size_t k = rod->jnode[c];
            if (k == PHC_TREE_NONE)
                continue;
            double ws[2], beta[3];
            modulus_weights(rod, c, ws);
            bending_strain(rod, c, beta);
            const double s = ws[0] * de[rod->g->parent[c]] + ws[1] * de[c];
            for (int a = 0; a < 3; ++a)
                rod->sol[12 * k + 9 + a] = -beta[a] * s;
        }
        if ((rc = sensitivity_solve(rod, what, err)) != PHC_OK)
            return rc;
        double *out = dz + d * 6 * n;
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < 6; ++k)
                out[6 * i + k] = (rod->tree->dim[i] >= 6 && !rod->fixed[i]) ? rod->sol[12 * i + k] : 0.0;
    }
    phc_error_clear(err);
    return PHC_OK;
}

int phc_rod_static_adjoint(phc_rod *rod, const double *dg_dz, double *dg_dE, phc_error *err)
{
    static const char what[] = "adjoint";
    const size_t n = rod->n;
    for (size_t i = 0; i < 6 * n; ++i)
        if (!isfinite(dg_dz[i]))
            return phc_error_set(err, PHC_ERR_INPUT, "rod: %s: segment %ld: dg/dz[%zu] is not finite", what,
                                 rod->g->source_id[i / 6], i % 6);
    int rc = sensitivity_prepare(rod, what, err);
    if (rc != PHC_OK)
        return rc;
    memset(rod->sol, 0, 12 * n * sizeof *rod->sol);
    for (size_t i = 0; i < n; ++i)
        if (rod->tree->dim[i] >= 6 && !rod->fixed[i])
            memcpy(rod->sol + 12 * i, dg_dz + 6 * i, 6 * sizeof *rod->sol);
    if ((rc = sensitivity_solve(rod, what, err)) != PHC_OK)
        return rc;
    memset(dg_dE, 0, n * sizeof *dg_dE);
    for (size_t c = 0; c < n; ++c) {
        const size_t k = rod->jnode[c];
        if (k == PHC_TREE_NONE)
            continue;
        double ws[2], beta[3], vb = 0.0;
        modulus_weights(rod, c, ws);
        bending_strain(rod, c, beta);
        for (int a = 0; a < 3; ++a)
            vb += rod->sol[12 * k + 9 + a] * beta[a];
        dg_dE[rod->g->parent[c]] -= vb * ws[0];
        dg_dE[c] -= vb * ws[1];
    }
    phc_error_clear(err);
    return PHC_OK;
}

void phc_rod_end_sensitivity(const phc_rod *rod, size_t i, const double *dz, double dhead[3], double dtail[3])
{
    double u[3];
    phc_rod_internal_tail_offset(rod, i, u);
    const double *dx = dz + 6 * i, *dth = dz + 6 * i + 3;
    const double w[3] = {dth[1] * u[2] - dth[2] * u[1], dth[2] * u[0] - dth[0] * u[2],
                         dth[0] * u[1] - dth[1] * u[0]};
    for (int k = 0; k < 3; ++k) {
        if (dhead)
            dhead[k] = dx[k] - w[k];
        if (dtail)
            dtail[k] = dx[k] + w[k];
    }
}

void phc_rod_end_gradient(const phc_rod *rod, size_t i, const double g_head[3], const double g_tail[3],
                          double g_z[6])
{
    double u[3], d[3];
    phc_rod_internal_tail_offset(rod, i, u);
    for (int k = 0; k < 3; ++k) {
        g_z[k] = g_tail[k] + g_head[k];
        d[k] = g_tail[k] - g_head[k];
    }
    g_z[3] = u[1] * d[2] - u[2] * d[1];
    g_z[4] = u[2] * d[0] - u[0] * d[2];
    g_z[5] = u[0] * d[1] - u[1] * d[0];
}

/* ---- test hooks (rod_internal.h) ----------------------------------------- */

int phc_rod_internal_prepare_static(phc_rod *rod, phc_error *err)
{
    return build_tree(rod, 1, err);
}

void phc_rod_internal_assemble_static(phc_rod *rod, int matrix)
{
    const step_params sp = {0, 0.0, 0.0};
    assemble(rod, &sp, matrix ? MATRIX_NEWTON : 0);
}

/* the matrix entry (row of node a, column of node b) as assembled */
static double matrix_entry(const phc_rod_tree *t, const double *diag, const double *coup, size_t a,
                           int r, size_t b, int c)
{
    if (a == b)
        return diag[144 * a + r * 12 + c];
    if (t->parent[a] == b && c < 6)
        return coup[72 * a + r * 6 + c];
    if (t->parent[b] == a && r < 6)
        return coup[72 * b + c * 6 + r];
    return 0.0;
}

int phc_rod_internal_jacobian_check(phc_rod *rod, double eps, double *max_error,
                                    double *max_entry, phc_error *err)
{
    const size_t n = rod->n;
    step_params sp = {0, 0.0, 0.0};
    int rc = build_tree(rod, 1, err);
    if (rc != PHC_OK)
        return rc;
    double *diag = malloc(144 * n * sizeof *diag), *coup = malloc(72 * n * sizeof *coup);
    double *rp = malloc(12 * n * sizeof *rp), *rm = malloc(12 * n * sizeof *rm);
    if (!diag || !coup || !rp || !rm) {
        free(diag);
        free(coup);
        free(rp);
        free(rm);
        return phc_error_set(err, PHC_ERR_NOMEM, "rod: out of memory");
    }
    assemble(rod, &sp, MATRIX_NEWTON);
    memcpy(diag, rod->tree->diag, 144 * n * sizeof *diag);
    memcpy(coup, rod->tree->coup, 72 * n * sizeof *coup);
    *max_error = *max_entry = 0.0;
    save_state(rod);
    for (size_t b = 0; b < n; ++b)
        for (int k = 0; k < rod->tree->dim[b]; ++k) {
            for (int sgn = -1; sgn <= 1; sgn += 2) {
                memset(rod->sol, 0, 12 * n * sizeof *rod->sol);
                rod->sol[12 * b + k] = sgn * eps;
                apply_step(rod, 1.0);
                assemble(rod, &sp, 0);
                memcpy(sgn > 0 ? rp : rm, rod->res, 12 * n * sizeof *rp);
                restore_state(rod);
            }
            for (size_t a = 0; a < n; ++a)
                for (int r = 0; r < rod->tree->dim[a]; ++r) {
                    const double fd = (rp[12 * a + r] - rm[12 * a + r]) / (2.0 * eps);
                    const double an = matrix_entry(rod->tree, diag, coup, a, r, b, k);
                    *max_error = fmax(*max_error, fabs(fd - an));
                    *max_entry = fmax(*max_entry, fabs(an));
                }
        }
    assemble(rod, &sp, 0);
    free(diag);
    free(coup);
    free(rp);
    free(rm);
    return PHC_OK;
}

int phc_rod_internal_symmetry_check(phc_rod *rod, double *max_asymmetry, double *max_entry, phc_error *err)
{
    const step_params sp = {0, 0.0, 0.0};
    int rc = build_tree(rod, 1, err);
    if (rc != PHC_OK)
        return rc;
    assemble(rod, &sp, MATRIX_SYMMETRIC);
    const phc_rod_tree *t = rod->tree;
    *max_asymmetry = *max_entry = 0.0;
    for (size_t a = 0; a < rod->n; ++a)
        for (size_t b = 0; b < rod->n; ++b) {
            if (a != b && t->parent[a] != b && t->parent[b] != a)
                continue; /* no block */
            for (int r = 0; r < t->dim[a]; ++r)
                for (int c = 0; c < t->dim[b]; ++c) {
                    const double x = matrix_entry(t, t->diag, t->coup, a, r, b, c);
                    const double y = matrix_entry(t, t->diag, t->coup, b, c, a, r);
                    *max_asymmetry = fmax(*max_asymmetry, fabs(x - y));
                    *max_entry = fmax(*max_entry, fabs(x));
                }
        }
    assemble(rod, &sp, 0);
    return PHC_OK;
}
