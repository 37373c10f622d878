/* Climbing-plant growth (Hädrich et al., CGF 36(2) 2017, §4.2–4.3): see
 * model/climbing_growth.h for the model, its equations and units. */
#include "model/climbing_growth.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "model/climbing_breaking.h"
#include "model/climbing_cambium.h"
#include "model/climbing_leaves.h"
#include "model/climbing_light_field.h"
#include "model/climbing_rng.h"
#include "model/climbing_tropism.h"
#include "model/plant_graph.h"
#include "model/quaternion.h"

static const double PI = 3.14159265358979323846;

/* Loops over this many particles or more run on the OpenMP threads (each
 * particle's work is its own, so the results do not depend on the thread
 * count; below it waking the threads costs more than it saves); inside an
 * outer parallel region they stay on its thread. */
#define PHC_CLIMBING_PARALLEL_MIN 4096
static int team(size_t n) { return n >= PHC_CLIMBING_PARALLEL_MIN && omp_get_level() == 0; }

struct phc_climbing {
    phc_climbing_options o;
    phc_climbing_rng rng;
    double base[3];          /* the seed particle's base, m (fixed) */
    size_t n, cap;
    size_t *parent;
    unsigned *order;
    unsigned char *apical, *lateral, *anchored;
    double *sigma, *radius, *age, *light;
    double *x, *d;           /* 3n current centre (m), direction (unit) */
    double *xr, *dr;         /* 3n rest centre, rest direction */
    double *anchor_at;       /* 3n, m */
    double *anchor_t0;       /* n, s: when the anchor was made */
    double *vol;             /* n: particle volumes π r² L, m^3 (kept: made again when σ or r
                                changes, in add_particle, step 5 and step 9) */
    double *phi;             /* light grid scratch, all zero between the light steps */
    phc_climbing_stats stats;
    /* leaves, secondary growth, shadows of the supports */
    unsigned *node_k;        /* n: node index along the shoot */
    unsigned char *has_leaf; /* n */
    double *leaf_c, *leaf_n, *leaf_p; /* 3n: blade centre (m), normal, petiole */
    double *leaf_light;      /* n: I at the blade, last step */
    double *r0;              /* n: primary radius, m */
    unsigned char *has_child;/* n scratch */
    double *target;          /* n scratch: pipe-model target areas, m^2 */
    double *excess;          /* n scratch: a tip's growth beyond σ = 1 this step (1), −1 below */
    size_t *grown;           /* n scratch: the tips of this step (step 5 rebuilds their rest) */
    double *sx, *sv, *sI;    /* 6n, 2n, 2n scratch: light points, volumes, light */
    unsigned char *opaque;   /* light-grid cells holding occluders, NULL: none */
    double *occ_v;           /* occluding triangles' vertices, m (3 per vertex) */
    size_t *occ_t;           /* and their indices (3 per triangle) */
    size_t occ_nv, occ_nt;
    size_t opaque_cells;
    size_t leaves;
    phc_climbing_light_field field; /* seek_light: where the light is */
    int field_ready;         /* 1 once the field holds a step's light */
    /* dynamics (step 6): one particle system kept across the steps, and
     * per particle what was last handed to it or read from it (14 doubles:
     * rest centre, rest direction, radius, σ, current centre, direction) */
    phc_particles *sys;
    double *sys_seen;
    size_t sys_seen_cap;
    int handed, sync_all;    /* the last step handed its growth to c->sys; else (sync_all)
                                this step's hand-over compares every particle */
    size_t pushed;           /* collisions of the last step (option collide) */
    double depth;            /* smallest δ − r before the pushes, m */
    /* breaking (model/climbing_breaking.h) */
    unsigned char *falling;  /* n: 1 in a broken piece that still falls */
    unsigned char *cut;      /* n: 1 when its link to its parent broke */
    double *fell_at;         /* n: when its piece broke, s; -1 while attached */
    size_t *id;              /* n: stable id (birth number) */
    size_t born;             /* particles made since the seed */
    phc_climbing_stumps stumps; /* waiting to resprout (resprout_delay) */
    int stumps_lost;         /* a stump could not be remembered (out of memory) */
};

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

phc_climbing_options phc_climbing_options_default(void)
{
    phc_climbing_options o;
    memset(&o, 0, sizeof o);
    o.seed = 1;
    o.max_length = 0.02;
    o.bud_fraction = 0.25;
    o.growth_rate = 0.1;
    o.apical_dominance = 1;
    o.radius = 0.002;
    o.max_particles = 20000;
    o.branch_probability = 0.3;
    o.max_buds = 1;
    o.direction_variance = 0.5;
    o.thickness_falloff = 0.7;
    o.max_order = 3;
    o.light.cell = 0.05;
    o.light.dims[0] = o.light.dims[1] = o.light.dims[2] = 1;
    o.light.extinction = 0;
    o.light.direction[2] = 1;
    o.phototropism = 0;
    o.seek_light = 0;
    o.light_spread_deg = 30;
    o.light_gradient_threshold = 1e-3;
    o.surface_adaption = 0;
    o.adaption_radius = 0.1;
    o.contact_distance = 0.004;
    o.attach_distance = 0.005;
    o.release_distance = 0.02;
    o.anchor_strength = 0.5;
    o.anchor_time = 10;
    o.dynamics_substeps = 0;
    o.min_stiffness = 0.1;
    o.particles = phc_particles_options_default();
    o.particles.maturity_age = 50;
    o.particles.follow_parent = 1; /* mature shoots hold their shape (Fig. 12 b) */
    o.leaf_step = 0;
    o.leaf_angle_deg = 137.5;
    o.leaf_size = 0.03;
    o.leaf_thickness = 3e-4;
    o.leaf_response = 1;
    o.leaf_max_angle_deg = 80;
    o.cambium_rate = 0;
    o.leaf_pipe_area = 0;
    o.fall_time = 1;
    o.resprout_delay = INFINITY; /* never */
    return o;
}

void phc_climbing_free(phc_climbing *c)
{
    if (!c)
        return;
    phc_climbing_stumps_free(&c->stumps);
    free(c->parent);
    free(c->order);
    free(c->apical);
    free(c->lateral);
    free(c->anchored);
    free(c->sigma);
    free(c->radius);
    free(c->age);
    free(c->light);
    free(c->x);
    free(c->d);
    free(c->xr);
    free(c->dr);
    free(c->anchor_at);
    free(c->anchor_t0);
    free(c->vol);
    free(c->phi);
    free(c->node_k);
    free(c->has_leaf);
    free(c->leaf_c);
    free(c->leaf_n);
    free(c->leaf_p);
    free(c->leaf_light);
    free(c->r0);
    free(c->has_child);
    free(c->target);
    free(c->excess);
    free(c->grown);
    phc_climbing_light_field_free(&c->field);
    free(c->sx);
    free(c->sv);
    free(c->sI);
    free(c->opaque);
    free(c->occ_v);
    free(c->occ_t);
    phc_particles_free(c->sys);
    free(c->sys_seen);
    free(c->falling);
    free(c->cut);
    free(c->fell_at);
    free(c->id);
    free(c);
}

/* Grows every array to hold `want` particles; 0 or -1 (out of memory). */
static int reserve(phc_climbing *c, size_t want)
{
    if (want <= c->cap)
        return 0;
    size_t cap = c->cap ? c->cap : 64;
    while (cap < want)
        cap *= 2;
#define GROW(field, per)                                                    \
    do {                                                                    \
        void *q = realloc(c->field, (cap) * (per) * sizeof *c->field);      \
        if (!q)                                                             \
            return -1;                                                      \
        c->field = q;                                                       \
    } while (0)
    GROW(parent, 1);
    GROW(order, 1);
    GROW(apical, 1);
    GROW(lateral, 1);
    GROW(anchored, 1);
    GROW(sigma, 1);
    GROW(radius, 1);
    GROW(age, 1);
    GROW(light, 1);
    GROW(x, 3);
    GROW(d, 3);
    GROW(xr, 3);
    GROW(dr, 3);
    GROW(anchor_at, 3);
    GROW(anchor_t0, 1);
    GROW(vol, 1);
    GROW(node_k, 1);
    GROW(has_leaf, 1);
    GROW(leaf_c, 3);
    GROW(leaf_n, 3);
    GROW(leaf_p, 3);
    GROW(leaf_light, 1);
    GROW(r0, 1);
    GROW(has_child, 1);
    GROW(target, 1);
    GROW(excess, 1);
    GROW(grown, 1);
    GROW(sx, 6);
    GROW(sv, 2);
    GROW(sI, 2);
    GROW(falling, 1);
    GROW(cut, 1);
    GROW(fell_at, 1);
    GROW(id, 1);
#undef GROW
    c->cap = cap;
    return 0;
}

static int bad(phc_error *err, const char *key, double v, const char *range)
{
    return phc_error_set(err, PHC_ERR_INVALID, "climbing: %s = %g is outside %s", key, v, range);
}

static int check_options(const phc_climbing_options *o, phc_error *err)
{
#define NEED(cond, key, v, range) \
    if (!(cond)) return bad(err, key, (double)(v), range)
    NEED(o->max_length > 0 && isfinite(o->max_length), "max_length", o->max_length, "(0, inf) m");
    NEED(o->bud_fraction > 0 && o->bud_fraction < 1, "bud_fraction", o->bud_fraction, "(0, 1)");
    NEED(o->apical_dominance > 0 && o->apical_dominance <= 1, "apical_dominance", o->apical_dominance,
         "(0, 1]");
    NEED(o->growth_rate >= 0 && isfinite(o->growth_rate), "growth_rate", o->growth_rate,
         "[0, inf) 1/s");
    NEED(o->radius > 0 && isfinite(o->radius), "radius", o->radius, "(0, inf) m");
    NEED(o->max_particles >= 1, "max_particles", o->max_particles, "[1, inf)");
    NEED(o->branch_probability >= 0 && o->branch_probability <= 1, "branch_probability",
         o->branch_probability, "[0, 1]");
    NEED(o->direction_variance >= 0 && o->direction_variance <= 1, "direction_variance",
         o->direction_variance, "[0, 1] (1 = 90 degrees)");
    NEED(o->thickness_falloff > 0 && o->thickness_falloff <= 1, "thickness_falloff",
         o->thickness_falloff, "(0, 1]");
    NEED(o->light.cell > 0 && isfinite(o->light.cell), "light.cell", o->light.cell, "(0, inf) m");
    for (int k = 0; k < 3; ++k) {
        NEED(o->light.dims[k] >= 1, "light.dims", o->light.dims[k], "[1, inf)");
        NEED(isfinite(o->light.origin[k]), "light.origin", o->light.origin[k], "finite numbers");
    }
    NEED(o->light.extinction >= 0 && isfinite(o->light.extinction), "light.extinction",
         o->light.extinction, "[0, inf) 1/m");
    const double ll = sqrt(dot(o->light.direction, o->light.direction));
    NEED(ll > 0 && isfinite(ll), "|light.direction|", ll, "(0, inf)");
    NEED(o->phototropism >= 0 && isfinite(o->phototropism), "phototropism", o->phototropism,
         "[0, inf) 1/s");
    NEED(o->light_spread_deg >= 0 && o->light_spread_deg <= 89, "light_spread_deg",
         o->light_spread_deg, "[0, 89] degrees");
    NEED(o->light_gradient_threshold >= 0 && isfinite(o->light_gradient_threshold),
         "light_gradient_threshold", o->light_gradient_threshold, "[0, inf)");
    NEED(o->surface_adaption >= 0 && isfinite(o->surface_adaption), "surface_adaption",
         o->surface_adaption, "[0, inf) 1/s");
    NEED(o->adaption_radius >= 0 && isfinite(o->adaption_radius), "adaption_radius",
         o->adaption_radius, "[0, inf) m");
    NEED(o->contact_distance >= 0 && isfinite(o->contact_distance), "contact_distance",
         o->contact_distance, "[0, inf) m");
    NEED(o->attach_distance >= 0 && isfinite(o->attach_distance), "attach_distance",
         o->attach_distance, "[0, inf) m");
    NEED(o->release_distance > o->attach_distance && isfinite(o->release_distance),
         "release_distance", o->release_distance, "(attach_distance, inf) m");
    NEED(o->anchor_strength > 0 && o->anchor_strength <= 1, "anchor_strength",
         o->anchor_strength, "(0, 1]");
    NEED(o->min_stiffness >= 0 && o->min_stiffness <= 1, "min_stiffness", o->min_stiffness,
         "[0, 1]");
    NEED(o->particles.maturity_age > 0 || o->dynamics_substeps == 0, "particles.maturity_age",
         o->particles.maturity_age, "(0, inf) s when dynamics_substeps > 0");
    NEED(o->anchor_time > 0 && isfinite(o->anchor_time), "anchor_time", o->anchor_time,
         "(0, inf) s");
    NEED(o->light.ambient >= 0 && o->light.ambient <= 1, "light.ambient", o->light.ambient,
         "[0, 1]");
    NEED(isfinite(o->leaf_angle_deg), "leaf_angle_deg", o->leaf_angle_deg, "finite degrees");
    NEED(o->leaf_size > 0 && isfinite(o->leaf_size), "leaf_size", o->leaf_size, "(0, inf) m");
    NEED(o->leaf_thickness >= 0 && isfinite(o->leaf_thickness), "leaf_thickness",
         o->leaf_thickness, "[0, inf) m");
    NEED(o->leaf_response >= 0 && o->leaf_response <= 1, "leaf_response", o->leaf_response,
         "[0, 1]");
    NEED(o->leaf_max_angle_deg >= 0 && o->leaf_max_angle_deg <= 180, "leaf_max_angle_deg",
         o->leaf_max_angle_deg, "[0, 180] degrees");
    NEED(o->cambium_rate >= 0 && isfinite(o->cambium_rate), "cambium_rate", o->cambium_rate,
         "[0, inf) 1/s");
    NEED(o->leaf_pipe_area >= 0 && isfinite(o->leaf_pipe_area), "leaf_pipe_area",
         o->leaf_pipe_area, "[0, inf) m^2");
    NEED(o->fall_time >= 0 && isfinite(o->fall_time), "fall_time", o->fall_time, "[0, inf) s");
    NEED(o->resprout_delay >= 0, "resprout_delay", o->resprout_delay, "[0, inf] s (inf: never)");
    const phc_particles_options *po = &o->particles;
    const int beam = po->follow_parent && po->bending == PHC_PARTICLES_BEAM;
    NEED(po->break_stress >= 0 && isfinite(po->break_stress), "particles.break_stress", po->break_stress,
         "[0, inf) Pa");
    NEED(!(po->break_stress > 0) || beam, "particles.break_stress", po->break_stress,
         "0 (off) unless follow_parent with bending beam (the own-weight pass has no bending moment)");
    NEED(!(po->break_stress > 0 && po->break_threshold > 0), "particles.break_stress", po->break_stress,
         "0 (off) when break_threshold > 0 (one rule of breaking at a time)");
    NEED(!po->anchors_carry_moment || beam, "particles.anchors_carry_moment", po->anchors_carry_moment,
         "0 (off) unless follow_parent with bending beam");
#undef NEED
    return 0;
}

static int unit(const double v[3], double u[3])
{
    const double l = sqrt(dot(v, v));
    if (!(l > 0) || !isfinite(l))
        return -1;
    for (int k = 0; k < 3; ++k)
        u[k] = v[k] / l;
    return 0;
}

/* Particle i's volume π r² L (m³), a light-grid point's shading volume. */
static void volume_at(phc_climbing *c, size_t i)
{
    const double L = c->sigma[i] * c->o.max_length;
    c->vol[i] = PI * c->radius[i] * c->radius[i] * L;
}

/* Appends a particle of size sigma whose base is at b along direction dir
 * (current and rest alike); returns its index or NONE (out of memory). */
static size_t add_particle(phc_climbing *c, size_t parent, unsigned order, int lateral,
                           double sigma, double radius, const double b[3],
                           const double dir[3], const double brest[3])
{
    if (reserve(c, c->n + 1))
        return PHC_CLIMBING_NONE;
    const size_t i = c->n++;
    c->parent[i] = parent;
    c->order[i] = order;
    c->apical[i] = 1;
    c->lateral[i] = (unsigned char)lateral;
    c->anchored[i] = 0;
    c->sigma[i] = sigma;
    c->radius[i] = radius;
    c->age[i] = 0;
    c->light[i] = 1;
    c->anchor_t0[i] = 0;
    c->node_k[i] = 0;
    c->has_leaf[i] = 0;
    c->leaf_light[i] = 0;
    c->r0[i] = radius;
    c->falling[i] = 0;
    c->cut[i] = 0;
    c->fell_at[i] = -1; /* attached */
    c->id[i] = c->born++;
    volume_at(c, i);
    const double h = 0.5 * sigma * c->o.max_length;
    for (int k = 0; k < 3; ++k) {
        c->d[3 * i + k] = c->dr[3 * i + k] = dir[k];
        c->x[3 * i + k] = b[k] + h * dir[k];
        c->xr[3 * i + k] = brest[k] + h * dir[k];
        c->anchor_at[3 * i + k] = 0;
    }
    return i;
}

phc_climbing *phc_climbing_new(const double base[3], const double direction[3],
                               const phc_climbing_options *options, phc_error *err)
{
    const phc_climbing_options o = options ? *options : phc_climbing_options_default();
    if (check_options(&o, err))
        return NULL;
    double dir[3];
    if (!base || !isfinite(base[0]) || !isfinite(base[1]) || !isfinite(base[2])) {
        phc_error_set(err, PHC_ERR_INVALID, "climbing: the seed position is not finite");
        return NULL;
    }
    if (!direction || unit(direction, dir)) {
        phc_error_set(err, PHC_ERR_INVALID,
                      "climbing: the seed direction must be a finite, non-zero vector");
        return NULL;
    }
    if (o.closest) {
        /* a seed behind a support face (inside a closed support, or on the
           back of an open one; the face's front is where its right-hand
           normal points) cannot grow out of it */
        double cp[3], nf[3];
        if (o.closest(o.closest_user, base, cp, nf) == 0) {
            const double r[3] = {base[0] - cp[0], base[1] - cp[1], base[2] - cp[2]};
            const double side = dot(r, nf);
            if (side < -1e-9 * (1 + sqrt(dot(base, base)))) {
                phc_error_set(err, PHC_ERR_INPUT,
                              "climbing: the seed (%g, %g, %g) m lies behind the support face "
                              "at (%g, %g, %g) m (%g m inside); a seed must be outside every "
                              "support",
                              base[0], base[1], base[2], cp[0], cp[1], cp[2], -side);
                return NULL;
            }
        }
    }
    phc_climbing *c = calloc(1, sizeof *c);
    if (!c)
        goto nomem;
    c->o = o;
    unit(o.light.direction, c->o.light.direction);
    phc_climbing_rng_seed(&c->rng, o.seed);
    memcpy(c->base, base, sizeof c->base);
    if (o.light.extinction > 0) {
        /* all zero, and kept so by the light step (phc_climbing_light_shaded_zeroed) */
        c->phi = calloc(phc_climbing_light_cells(&o.light), sizeof *c->phi);
        if (!c->phi)
            goto nomem;
    }
    if (o.seek_light && o.phototropism > 0 &&
        phc_climbing_light_field_init(&c->field, &c->o.light, o.light_spread_deg))
        goto nomem;
    if (add_particle(c, PHC_CLIMBING_NONE, 0, 0, o.bud_fraction, o.radius, base, dir, base) ==
        PHC_CLIMBING_NONE)
        goto nomem;
    c->stats.particles = 1;
    c->stats.apical = 1;
    c->stats.first_break_time = NAN;
    for (int k = 0; k < 3; ++k)
        c->stats.first_break_joint[k] = NAN;
    return c;
nomem:
    phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory");
    phc_climbing_free(c);
    return NULL;
}

static inline double seg_half(const phc_climbing *c, size_t i)
{
    return 0.5 * c->sigma[i] * c->o.max_length;
}

/* Base of i's current (rest when rest != 0) segment. */
static inline void seg_base(const phc_climbing *c, size_t i, int rest, double b[3])
{
    const double *x = rest ? c->xr : c->x, *d = rest ? c->dr : c->d;
    const double h = seg_half(c, i);
    for (int k = 0; k < 3; ++k)
        b[k] = x[3 * i + k] - h * d[3 * i + k];
}

static inline void seg_tip(const phc_climbing *c, size_t i, int rest, double t[3])
{
    const double *x = rest ? c->xr : c->x, *d = rest ? c->dr : c->d;
    const double h = seg_half(c, i);
    for (int k = 0; k < 3; ++k)
        t[k] = x[3 * i + k] + h * d[3 * i + k];
}

/* A unit vector at angle theta from the unit d, at azimuth phi. */
static void cone_direction(const double d[3], double theta, double phi, double out[3])
{
    int m = 0;
    for (int k = 1; k < 3; ++k)
        if (fabs(d[k]) < fabs(d[m]))
            m = k;
    double e[3] = {m == 0, m == 1, m == 2};
    double e1[3] = {d[1] * e[2] - d[2] * e[1], d[2] * e[0] - d[0] * e[2],
                    d[0] * e[1] - d[1] * e[0]};
    unit(e1, e1);
    const double e2[3] = {d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2],
                          d[0] * e1[1] - d[1] * e1[0]};
    const double ct = cos(theta), st = sin(theta), cp = cos(phi), sp = sin(phi);
    for (int k = 0; k < 3; ++k)
        out[k] = ct * d[k] + st * (cp * e1[k] + sp * e2[k]);
    unit(out, out);
}

/* Step 2: tropisms of apical particle i (eqs. 6–10). */
static void tropisms(phc_climbing *c, size_t i, double dt)
{
    const phc_climbing_options *o = &c->o;
    double b[3];
    seg_base(c, i, 0, b);
    double *d = c->d + 3 * i, *dr = c->dr + 3 * i;
    if (o->phototropism > 0) { /* eq. 7 */
        double t[3];
        memcpy(t, o->light.direction, sizeof t);
        if (c->field_ready) { /* toward where the light is */
            double tip[3];
            seg_tip(c, i, 0, tip);
            phc_climbing_light_field_target(&c->field, tip, o->light_gradient_threshold, t);
        }
        phc_climbing_turn(d, dr, t, o->phototropism * dt);
    }
    if (o->closest && (o->surface_adaption > 0 || o->contact_distance > 0)) { /* eq. 6 */
        double tip[3], cp[3], nf[3], t[3];
        seg_tip(c, i, 0, tip);
        if (o->closest(o->closest_user, tip, cp, nf) == 0) {
            const double r[3] = {tip[0] - cp[0], tip[1] - cp[1], tip[2] - cp[2]};
            const double delta = sqrt(dot(r, r));
            if (delta <= o->adaption_radius && o->surface_adaption > 0 &&
                phc_climbing_surface_target(tip, cp, nf, d, o->contact_distance, t))
                phc_climbing_turn(d, dr, t, o->surface_adaption * dt);
            /* collision rule (ours): a tip in contact keeps no inward part */
            if (delta <= o->contact_distance) {
                double n[3];
                if (delta > 0)
                    for (int k = 0; k < 3; ++k)
                        n[k] = r[k] / delta;
                else
                    memcpy(n, nf, sizeof n);
                const double dn = dot(d, n);
                if (dn < 0) {
                    double nd[3] = {d[0] - dn * n[0], d[1] - dn * n[1], d[2] - dn * n[2]};
                    if (unit(nd, nd) == 0)
                        phc_climbing_turn(d, dr, nd, 1);
                }
            }
        }
    }
    /* the base stays where it was: the segment turns about it */
    const double h = seg_half(c, i);
    for (int k = 0; k < 3; ++k)
        c->x[3 * i + k] = b[k] + h * d[k];
}

/* keep_outside (ours): turns apical i out when its tip or its centre is
 * behind the face of its closest support point. */
static void keep_outside(phc_climbing *c, size_t i)
{
    const phc_climbing_options *o = &c->o;
    if (!o->keep_outside || !o->closest)
        return;
    double tip[3], cp[3], nf[3], b[3];
    seg_tip(c, i, 0, tip);
    /* the tip, then the centre (a segment that cuts a convex edge has both
       ends outside and its middle inside) */
    int behind = 0;
    for (int pass = 0; pass < 2 && !behind; ++pass) {
        const double *p = pass ? c->x + 3 * i : tip;
        if (o->closest(o->closest_user, p, cp, nf))
            return;
        const double r[3] = {p[0] - cp[0], p[1] - cp[1], p[2] - cp[2]};
        behind = dot(r, nf) < 0;
    }
    if (!behind)
        return;
    double *d = c->d + 3 * i;
    const double dn = dot(d, nf);
    double t[3] = {d[0] - dn * nf[0], d[1] - dn * nf[1], d[2] - dn * nf[2]};
    if (unit(t, t) == 0)
        for (int k = 0; k < 3; ++k)
            t[k] += nf[k];
    else
        memcpy(t, nf, sizeof t);
    if (unit(t, t))
        return;
    seg_base(c, i, 0, b);
    phc_climbing_turn(d, c->dr + 3 * i, t, 1);
    const double h = seg_half(c, i);
    for (int k = 0; k < 3; ++k)
        c->x[3 * i + k] = b[k] + h * d[k];
}

/* Step 2 for particle i when it is a tip: tropisms, then keep_outside. */
static void turn_tip(phc_climbing *c, size_t i, double dt)
{
    if (!c->apical[i])
        return;
    tropisms(c, i, dt);
    keep_outside(c, i);
}

static void lengthen(phc_climbing *c, size_t i, double dt);
static void rest_at(phc_climbing *c, size_t i);

/* 1 when a tip's rest centre and volume can be set as it lengthens: no
 * later change of its direction (keep_outside's second pass) or radius
 * (secondary growth) before step 5.  (branch changes neither: it only
 * appends, and a tip's parent is no tip, so its rest tip is final.) */
static int rest_with_growth(const phc_climbing *c)
{
    return !c->o.keep_outside && !(c->o.cambium_rate > 0);
}

/* Steps 2, 3 and, with rest_with_growth, 5 for tip i (nothing for the
 * others): tropisms, lengthen, its rest centre and volume.  Touches only
 * particle i. */
static void tip_step(phc_climbing *c, size_t i, double dt, int rest)
{
    if (!c->apical[i])
        return;
    turn_tip(c, i, dt);
    lengthen(c, i, dt);
    if (rest) {
        rest_at(c, i);
        volume_at(c, i);
    }
}

/* Step 3 for apical i (§4.2): its size grows by dσ = r·a^k·I·Δt (r the
 * growth rate, s⁻¹; a^k the apical dominance, ours; I its light) to at
 * most 1, about its base; the growth beyond 1 into c->excess[i] (−1 when
 * below 1).  Touches only particle i, so the tips lengthen on the
 * threads, in the tropisms' loop. */
static void lengthen(phc_climbing *c, size_t i, double dt)
{
    const phc_climbing_options *o = &c->o;
    /* apical dominance (ours): a tip of order k grows at r·a^k */
    const double dominance = o->apical_dominance == 1 ? 1 : pow(o->apical_dominance, (double)c->order[i]);
    const double dsig = o->growth_rate * dominance * c->light[i] * dt;
    double b[3];
    seg_base(c, i, 0, b);
    double s = c->sigma[i] + dsig;
    double excess = -1;
    if (s >= 1) {
        excess = s - 1;
        s = 1;
    }
    c->sigma[i] = s;
    c->excess[i] = excess;
    const double h = seg_half(c, i);
    for (int k = 0; k < 3; ++k)
        c->x[3 * i + k] = b[k] + h * c->d[3 * i + k];
    /* the rest centre: rebuilt in step 5 */
}

/* Steps 3–4 for apical i after lengthen: when it reached σ = 1, it stops
 * growing and spawns its successor and laterals (the random numbers: in
 * index order).  Returns 0 or -1 (out of memory). */
static int branch(phc_climbing *c, size_t i)
{
    const phc_climbing_options *o = &c->o;
    const double excess = c->excess[i];
    if (!(excess >= 0))
        return 0;
    const double h = seg_half(c, i);
    c->apical[i] = 0;
    if (c->n >= o->max_particles)
        return 0;
    double tip[3], tipr[3], dir[3];
    seg_tip(c, i, 0, tip);
    /* rest tip: the rest base is rebuilt later, a provisional one suffices */
    for (int k = 0; k < 3; ++k)
        tipr[k] = c->xr[3 * i + k] + h * c->dr[3 * i + k];
    memcpy(dir, c->d + 3 * i, sizeof dir);
    double dirr[3];
    memcpy(dirr, c->dr + 3 * i, sizeof dirr);
    const unsigned order = c->order[i];
    const double radius = c->radius[i];
    size_t j = add_particle(c, i, order, 0, o->bud_fraction + excess, radius, tip, dir, tipr);
    if (j == PHC_CLIMBING_NONE)
        return -1;
    memcpy(c->dr + 3 * j, dirr, sizeof dirr);
    c->node_k[j] = c->node_k[i] + 1;
    if (order >= o->max_order)
        return 0;
    for (unsigned bud = 0; bud < o->max_buds && c->n < o->max_particles; ++bud) {
        c->stats.bud_trials++;
        const double u = phc_climbing_rng_uniform(&c->rng);
        const double theta = phc_climbing_rng_uniform(&c->rng) * o->direction_variance * 0.5 * PI;
        const double phi = 2 * PI * phc_climbing_rng_uniform(&c->rng);
        if (!(u < o->branch_probability))
            continue;
        double ld[3], ldr[3];
        cone_direction(dir, theta, phi, ld);
        cone_direction(dirr, theta, phi, ldr);
        const size_t k = add_particle(c, i, order + 1, 1, o->bud_fraction,
                                      radius * o->thickness_falloff, tip, ld, tipr);
        if (k == PHC_CLIMBING_NONE)
            return -1;
        memcpy(c->dr + 3 * k, ldr, sizeof ldr);
        keep_outside(c, k);
        c->stats.laterals++;
        if (order + 1 > c->stats.max_order)
            c->stats.max_order = order + 1;
    }
    return 0;
}

/* Step 5 for particle i: its rest centre at its parent's rest tip (the
 * seed's at the base) plus L_i/2 along its rest direction. */
static void rest_at(phc_climbing *c, size_t i)
{
    double b[3];
    if (c->parent[i] == PHC_CLIMBING_NONE)
        memcpy(b, c->base, sizeof b);
    else
        seg_tip(c, c->parent[i], 1, b);
    const double h = seg_half(c, i);
    for (int k = 0; k < 3; ++k)
        c->xr[3 * i + k] = b[k] + h * c->dr[3 * i + k];
}

/* Step 5: the rest centres (and volumes) that can have changed: those of
 * this step's tips (grown[0 .. ngrown), the tips at its start: only they
 * turn, by their tropisms and keep_outside, and change size), then of the
 * new particles n0 .. n−1 in index order (each after its parent, an old
 * tip or a new particle).  Every other particle has a rest direction and
 * size it had before and a parent that is no tip (a particle with
 * children stopped growing), so its rest centre, computed alike, is the
 * one it has. */
static void rebuild_rest(phc_climbing *c, size_t ngrown, size_t n0)
{
    if (rest_with_growth(c))
        ngrown = 0; /* (the tips' rests were set as they lengthened) */
    for (size_t t = 0; t < ngrown; ++t) {
        rest_at(c, c->grown[t]);
        volume_at(c, c->grown[t]);
    }
    for (size_t i = n0; i < c->n; ++i)
        rest_at(c, i);
}

/* fmin(1, x) for every x (NaN gives 1, −0 stays −0), without libm's call
 * (which GCC makes when NaNs may occur). */
static inline double at_most_1(double x) { return x < 1 ? x : 1; }

/* glibc's fmax(x, m) bit for bit (equal operands give x, so −0 and +0
 * keep x's sign; a NaN gives the other operand, two NaNs m: checked
 * against it for ±0, ±1, ±∞, ±NaN and subnormals), without the call. */
static inline double at_least(double x, double m) { return (x >= m || (m != m && x == x)) ? x : m; }

/* Anchor strength of i now (eq. 5), 0 when not anchored (here, so that
 * the hand-over inlines it). */
static inline double anchor_strength(const phc_climbing *c, size_t i)
{
    if (!c->anchored[i])
        return 0;
    const double ramp = at_most_1((c->stats.time - c->anchor_t0[i]) / c->o.anchor_time);
    return c->o.anchor_strength * c->sigma[i] * ramp;
}

double phc_climbing_anchor_strength(const phc_climbing *c, size_t i)
{
    return anchor_strength(c, i);
}

/* Step 9's stiffening: (r/r0)^4, 1 without secondary growth. */
static double thickness_factor(const phc_climbing *c, size_t i)
{
    const double q = c->radius[i] / c->r0[i];
    return q == 1 ? 1 : q * q * q * q;
}

/* Step 6: the particles' dynamics on the grown shape.
 *
 * One phc_particles system lives across the steps (c->sys): it is made
 * from the rest shape at the first dynamic step; afterwards each step
 * hands it only what changed: the rest segment of a particle whose rest
 * centre, rest direction, radius or size changed (phc_particles_set_rest),
 * the current centre and direction of a particle the growth code moved (a
 * growing or turned tip: phc_particles_place, velocities kept), the new
 * particles (phc_particles_append, at their current place, at rest), the
 * ages and the anchors.  Velocities and the groups' rotations therefore
 * carry over from one step to the next. */

#define SEEN 14 /* doubles per particle in c->sys_seen */

/* What particle i's rest and current state are now, in c->sys_seen's
 * layout. */
static void seen_now(const phc_climbing *c, size_t i, double out[SEEN])
{
    memcpy(out, c->xr + 3 * i, 3 * sizeof(double));
    memcpy(out + 3, c->dr + 3 * i, 3 * sizeof(double));
    out[6] = c->radius[i];
    out[7] = c->sigma[i];
    memcpy(out + 8, c->x + 3 * i, 3 * sizeof(double));
    memcpy(out + 11, c->d + 3 * i, 3 * sizeof(double));
}

/* 1 when the k doubles a and b hold the same bits (memcmp's equality,
 * without the call). */
static inline int same_bits(const double *a, const double *b, int k)
{
    for (int j = 0; j < k; ++j) {
        uint64_t u, v;
        memcpy(&u, a + j, sizeof u);
        memcpy(&v, b + j, sizeof v);
        if (u != v)
            return 0;
    }
    return 1;
}

static void rest_segment(const phc_climbing *c, size_t i, double head[3], double tail[3])
{
    const double h = seg_half(c, i);
    for (int k = 0; k < 3; ++k) {
        head[k] = c->xr[3 * i + k] - h * c->dr[3 * i + k];
        tail[k] = c->xr[3 * i + k] + h * c->dr[3 * i + k];
    }
}

/* The first dynamic step: the system from the rest shape, given the
 * current centres and directions (at rest). */
static phc_particles *dynamics_new(phc_climbing *c, phc_error *err)
{
    const size_t n = c->n;
    phc_plant_graph *g = phc_plant_graph_new(n);
    phc_particles *p = NULL;
    if (!g) {
        phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for %zu particles", n);
        return NULL;
    }
    for (size_t i = 0; i < n; ++i) {
        rest_segment(c, i, g->head + 3 * i, g->tail + 3 * i);
        g->radius[i] = c->radius[i];
        g->length[i] = 2 * seg_half(c, i);
        g->parent[i] = c->parent[i] == PHC_CLIMBING_NONE ? PHC_PLANT_NO_PARENT : c->parent[i];
    }
    g->fixed[0] = 1; /* the seed is in the ground */
    if (phc_plant_graph_finish(g, "climbing", err) == 0)
        p = phc_particles_new(g, &c->o.particles, err);
    phc_plant_graph_free(g);
    if (!p)
        return NULL;
    for (size_t i = 1; i < n; ++i) {
        double q[4];
        phc_quat_from_z(c->d + 3 * i, q);
        if (phc_particles_set_position(p, i, c->x + 3 * i, err) ||
            phc_particles_set_orientation(p, i, q, err)) {
            phc_particles_free(p);
            return NULL;
        }
    }
    return p;
}

/* Particle i's changes for the hand-over (i < the system's count): its
 * rest segment when its rest changed, its current place when the growth
 * moved it (velocities kept), as the record of what the system holds
 * tells.  Touches only particle i (in the plant's record and in the
 * system). */
static int hand_change(phc_climbing *c, size_t i, phc_error *err)
{
    phc_particles *p = c->sys;
    double head[3], tail[3];
    double *was = c->sys_seen + SEEN * i;
    const int rest = !same_bits(was, c->xr + 3 * i, 3) || !same_bits(was + 3, c->dr + 3 * i, 3) ||
                     !same_bits(was + 6, c->radius + i, 1) || !same_bits(was + 7, c->sigma + i, 1);
    const int moved = !same_bits(was + 8, c->x + 3 * i, 3) || !same_bits(was + 11, c->d + 3 * i, 3);
    if (!rest && !moved)
        return 0;
    const int place = i > 0 && moved; /* (the seed stays clamped) */
    if (rest)
        rest_segment(c, i, head, tail);
    if (phc_particles_set_rest_place(p, i, rest ? head : NULL, rest ? tail : NULL, c->radius[i],
                                     place ? c->x + 3 * i : NULL, c->d + 3 * i, err))
        return -1;
    seen_now(c, i, was);
    return 0;
}

/* The age particle i is handed over with (s): its own, at least that of
 * the least stiffness (min_stiffness of the maturity age), times its
 * thickening's (r/r0)^4. */
static inline double hand_age(const phc_climbing *c, size_t i)
{
    return at_least(c->age[i], c->o.min_stiffness * c->o.particles.maturity_age) * thickness_factor(c, i);
}

/* Particle i's age and anchor for the hand-over; the seed clamped at its
 * rest place and orientation.  Touches only particle i. */
static int hand_age_anchor(phc_climbing *c, size_t i, phc_error *err)
{
    phc_particles *p = c->sys;
    if (i == 0) {
        double q[4];
        phc_quat_from_z(c->dr, q);
        return phc_particles_set_position(p, 0, c->xr, err) ||
               phc_particles_set_orientation(p, 0, q, err) || phc_particles_release(p, 0, err) ||
               phc_particles_anchor(p, 0, c->xr, 1, 1, err);
    }
    const double k = anchor_strength(c, i);
    return phc_particles_set_age_anchor(p, i, hand_age(c, i), c->anchor_at + 3 * i,
                                        k > 0 ? at_most_1(k) : 0, err);
}

#define HAND_BLOCK 256 /* particles per call of phc_particles_set_ages_anchors */

/* Ages and anchors of particles lo .. hi − 1 (hi − lo <= HAND_BLOCK, none
 * the seed) in one call, as hand_age_anchor sets each; the failing index
 * into *bad. */
static int hand_ages_anchors(phc_climbing *c, size_t lo, size_t hi, size_t *bad, phc_error *err)
{
    double age[HAND_BLOCK], k[HAND_BLOCK];
    for (size_t i = lo; i < hi; ++i) {
        const double ki = anchor_strength(c, i);
        age[i - lo] = hand_age(c, i);
        k[i - lo] = ki > 0 ? at_most_1(ki) : 0;
    }
    return phc_particles_set_ages_anchors(c->sys, lo, hi - lo, age, c->anchor_at + 3 * lo, k, bad,
                                          err);
}

/* The particles whose rest or place the growth can have changed since the
 * last hand-over: this step's tips (grown[0 .. ngrown): only they turn and
 * change size), or all of them when secondary growth changes every radius
 * or the last step stopped (an error) between its growth and its
 * hand-over. */
static int compare_all(const phc_climbing *c) { return c->o.cambium_rate > 0 || c->sync_all; }

static size_t changed_count(const phc_climbing *c, size_t ngrown, size_t known)
{
    return compare_all(c) ? known : ngrown;
}

static size_t changed_at(const phc_climbing *c, size_t t)
{
    return compare_all(c) ? t : c->grown[t];
}

/* Records the smallest failing index i and its error (any thread). */
static void first_error(size_t i, const phc_error *mine, size_t *first_bad, phc_error *err)
{
#pragma omp critical(phc_climbing_sync)
    if (i < *first_bad) {
        *first_bad = i;
        if (err)
            *err = *mine;
    }
}

/* Hands the grown plant to c->sys (made at the first call): the new
 * particles appended in index order (each after its parent), the changes
 * of the particles the growth can have changed (hand_change), then every
 * particle's age and anchor (hand_age_anchor); on the threads for a large
 * plant (the error reported is that of the smallest failing index). */
static int dynamics_sync(phc_climbing *c, size_t ngrown, phc_error *err)
{
    const size_t n = c->n;
    if (n > c->sys_seen_cap) { /* amortised: doubling */
        size_t cap = c->sys_seen_cap ? c->sys_seen_cap : 64;
        while (cap < n)
            cap *= 2;
        double *t = realloc(c->sys_seen, SEEN * cap * sizeof *t);
        if (!t)
            return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for %zu particles",
                                 n);
        c->sys_seen = t;
        c->sys_seen_cap = cap;
    }
    size_t known = 0, nchanged = 0;
    if (!c->sys) {
        if (!(c->sys = dynamics_new(c, err)))
            return -1;
        phc_particles_measure_stress(c->sys, 0); /* nothing reads it here */
        known = n;
        for (size_t i = 0; i < n; ++i)
            seen_now(c, i, c->sys_seen + SEEN * i); /* made as it is: nothing changed */
    } else {
        known = phc_particles_count(c->sys);
        nchanged = changed_count(c, ngrown, known);
    }
    phc_particles *p = c->sys;
    if (phc_particles_set_gravity(p, c->o.particles.gravity, err)) /* may have been changed */
        return -1;
    phc_particles_set_collider(p, c->o.collide ? c->o.closest : NULL, c->o.closest_user);
    phc_particles_set_segment_collider(p, c->o.collide && c->o.collide_segments ? c->o.closest_segment : NULL,
                                       c->o.closest_user);
    phc_particles_collide_all(p, c->o.collide_all);
    phc_particles_supports_closed(p, c->o.supports_closed);
    for (size_t i = known; i < n; ++i) { /* new: at its current place, at rest */
        double head[3], tail[3], q[4];
        rest_segment(c, i, head, tail);
        phc_quat_from_z(c->d + 3 * i, q);
        if (phc_particles_append(p, c->parent[i], head, tail, c->radius[i], NULL, err) ||
            phc_particles_set_position(p, i, c->x + 3 * i, err) ||
            phc_particles_set_orientation(p, i, q, err))
            return -1;
        seen_now(c, i, c->sys_seen + SEEN * i); /* handed over as it is now */
    }
    if (!team(n)) { /* (each particle's change before its age: as in index order) */
        for (size_t t = 0; t < nchanged; ++t)
            if (hand_change(c, changed_at(c, t), err))
                return -1;
        for (size_t i = 0; i < n; ++i)
            if (hand_age_anchor(c, i, err))
                return -1;
        return 0;
    }
    size_t first_bad = n;
#pragma omp parallel
    {
        phc_error mine;
        /* (no barrier between the loops: a particle's change and its age
           and anchor touch different fields of it, except the seed's,
           whose orientation is set from its rest after the region) */
#pragma omp for schedule(dynamic, 256) nowait
        for (size_t t = 0; t < nchanged; ++t) {
            const size_t i = changed_at(c, t);
            if (hand_change(c, i, &mine))
                first_error(i, &mine, &first_bad, err);
        }
        const size_t blocks = (n - 1 + HAND_BLOCK - 1) / HAND_BLOCK; /* (the seed's after) */
#pragma omp for schedule(static)
        for (size_t b = 0; b < blocks; ++b) {
            const size_t lo = 1 + b * HAND_BLOCK, hi = lo + HAND_BLOCK < n ? lo + HAND_BLOCK : n;
            size_t bad;
            if (hand_ages_anchors(c, lo, hi, &bad, &mine))
                first_error(bad, &mine, &first_bad, err);
        }
    }
    phc_error seed_err;
    if (hand_age_anchor(c, 0, &seed_err))
        first_error(0, &seed_err, &first_bad, err);
    return first_bad < n ? -1 : 0;
}

/* Kinematic collisions (option collide): current centres pushed out of
 * the supports (the seed's left alone). */
static void collide_kinematic(phc_climbing *c)
{
    c->pushed = 0;
    c->depth = INFINITY;
    if (!c->o.collide || !c->o.closest)
        return;
    for (size_t i = 1; i < c->n; ++i) {
        double d;
        const double r = c->radius[i];
        double *x = c->x + 3 * i, *dir = c->d + 3 * i;
        if (!c->o.collide_ends) {
            c->pushed += (size_t)phc_particles_push_out(c->o.closest, c->o.closest_user, r, x, &d);
            c->depth = fmin(c->depth, d - r);
            continue;
        }
        /* the two ends too (ours): pushed out, centre and direction rebuilt
           from them with the length kept, centre again, up to 16 rounds */
        c->pushed += (size_t)phc_particles_push_segment_out(c->o.closest, c->o.closest_user, r,
                                                            seg_half(c, i), 16, x, dir, &d);
        c->depth = fmin(c->depth, d);
    }
}

void phc_climbing_collisions(const phc_climbing *c, size_t *pushed, double *depth)
{
    if (pushed)
        *pushed = c->pushed;
    if (depth)
        *depth = c->depth;
}

void phc_climbing_collision_queries(const phc_climbing *c, size_t *queries, size_t *skipped)
{
    phc_particles_collision_queries(c ? c->sys : NULL, queries, skipped);
}

/* Particle i's current direction from its orientation q in c->sys (its
 * centre is in c->x already), and both into the record of what the system
 * holds. */
static void read_back(phc_climbing *c, size_t i, const double q[4])
{
    double R[9];
    /* direction = R(q)·z: the third column of R */
    const double w = q[0], a = q[1], b = q[2], cc = q[3];
    R[2] = 2 * (a * cc + w * b);
    R[5] = 2 * (b * cc - w * a);
    R[8] = 1 - 2 * (a * a + b * b);
    const double dz[3] = {R[2], R[5], R[8]};
    unit(dz, c->d + 3 * i);
    memcpy(c->sys_seen + SEEN * i + 8, c->x + 3 * i, 3 * sizeof(double));
    memcpy(c->sys_seen + SEEN * i + 11, c->d + 3 * i, 3 * sizeof(double));
}

static void break_link(phc_climbing *c, const phc_particles_report *rep);
static int drop_fallen(phc_climbing *c, int all, phc_error *err);
static int resprout(phc_climbing *c, phc_error *err);

/* Step 6: the hand-over and the substeps (the shape is read back in step
 * 7's loop, anchors()). */
static int dynamics(phc_climbing *c, double dt, size_t ngrown, phc_error *err)
{
    if (dynamics_sync(c, ngrown, err))
        goto fail;
    c->handed = 1;
    phc_particles *p = c->sys;
    const double h = dt / (double)c->o.dynamics_substeps;
    c->pushed = 0;
    c->depth = INFINITY;
    const int breaking = c->o.particles.break_threshold > 0 || c->o.particles.break_stress > 0;
    for (size_t s = 0; s < c->o.dynamics_substeps; ++s) {
        phc_particles_report rep;
        if (phc_particles_step(p, h, breaking ? &rep : NULL, err))
            goto fail;
        if (breaking && rep.broken)
            break_link(c, &rep);
        size_t pushed;
        double depth;
        phc_particles_collisions(p, &pushed, &depth);
        c->pushed += pushed;
        c->depth = fmin(c->depth, depth);
    }
    return 0;
fail: /* the next dynamic step starts a fresh system from the plant */
    phc_particles_free(c->sys);
    c->sys = NULL;
    if (c->stats.falling) /* (without the system its pieces cannot fall) */
        drop_fallen(c, 1, NULL);
    return -1;
}

/* Step 7: anchor of particle i (eq. 5); counts the anchors made and
 * released. */
static void anchor(phc_climbing *c, size_t i, size_t *made, size_t *released)
{
    const phc_climbing_options *o = &c->o;
    const double *x = c->x + 3 * i;
    if (c->anchored[i]) {
        const double *a = c->anchor_at + 3 * i;
        const double r[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]};
        if (sqrt(dot(r, r)) > o->release_distance) {
            c->anchored[i] = 0;
            ++*released;
        }
        return;
    }
    if (!(o->attach_distance > 0))
        return;
    double cp[3], nf[3];
    if (o->closest(o->closest_user, x, cp, nf))
        return;
    const double r[3] = {x[0] - cp[0], x[1] - cp[1], x[2] - cp[2]};
    if (sqrt(dot(r, r)) <= o->attach_distance) {
        c->anchored[i] = 1;
        memcpy(c->anchor_at + 3 * i, cp, sizeof cp);
        c->anchor_t0[i] = c->stats.time;
        ++*made;
    }
}

/* Step 7 for particles lo .. hi − 1 (hi − lo <= HAND_BLOCK): with `read`,
 * first their current centres and orientations from the dynamics in one
 * call and each one's direction (read_back; the seed's shape is its rest),
 * then each one's anchor. */
static void read_and_anchor(phc_climbing *c, size_t lo, size_t hi, int read, size_t *made,
                            size_t *released)
{
    double q[4 * HAND_BLOCK];
    const size_t from = lo > 0 ? lo : 1;
    if (read && hi > from)
        phc_particles_poses(c->sys, from, hi - from, c->x + 3 * from, q + 4 * (from - lo));
    for (size_t i = lo; i < hi; ++i) {
        if (read && i > 0)
            read_back(c, i, q + 4 * (i - lo));
        if (c->o.closest && !(c->stats.falling && c->falling[i])) /* (none on a falling piece) */
            anchor(c, i, made, released);
    }
}

/* Step 7: anchors; each particle's anchor is its own.  With `read` (after
 * a dynamics step), each particle's current shape is read back from the
 * particles first, in the same loop (one pass, one parallel region). */
static void anchors(phc_climbing *c, int read)
{
    if (!c->o.closest && !read)
        return;
    size_t made = 0, released = 0;
    const size_t n = c->n, blocks = (n + HAND_BLOCK - 1) / HAND_BLOCK;
    if (team(n)) {
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : made, released)
        for (size_t b = 0; b < blocks; ++b)
            read_and_anchor(c, b * HAND_BLOCK, b + 1 < blocks ? (b + 1) * HAND_BLOCK : n, read,
                            &made, &released);
    } else {
        for (size_t b = 0; b < blocks; ++b)
            read_and_anchor(c, b * HAND_BLOCK, b + 1 < blocks ? (b + 1) * HAND_BLOCK : n, read,
                            &made, &released);
    }
    c->stats.anchors_made += made;
    c->stats.anchors_released += released;
}

/* The counters of the current state. */
static void count(phc_climbing *c)
{
    size_t apical = 0, anchored = 0;
    for (size_t i = 0; i < c->n; ++i) {
        apical += c->apical[i];
        anchored += c->anchored[i];
    }
    c->stats.particles = c->n;
    c->stats.apical = apical;
    c->stats.anchored = anchored;
    if (c->stats.falling) { /* (only after a break) */
        size_t falling = 0;
        for (size_t i = 0; i < c->n; ++i)
            falling += c->falling[i];
        c->stats.falling = falling;
    }
}

/* Step 1's shading point of particle i: its centre and volume. */
static void light_point(phc_climbing *c, size_t i)
{
    memcpy(c->sx + 3 * i, c->x + 3 * i, 3 * sizeof *c->sx);
    c->sv[i] = c->vol[i];
}

/* seek_light: the light field from the shading points, at the nodes
 * step 2 reads at the tips of the apical particles (their tips do not
 * move before step 2 reads them). */
static int field_update(phc_climbing *c, const phc_climbing_occluders *occ, const double *x,
                        const double *vol, size_t points, size_t n0)
{
    double *tips = phc_climbing_light_field_sites(&c->field, n0);
    if (!tips)
        return -1;
    size_t nt = 0;
    for (size_t i = 0; i < n0; ++i)
        if (c->apical[i])
            seg_tip(c, i, 0, tips + 3 * nt++);
    return phc_climbing_light_field_update_near(&c->field, occ, x, vol, points, tips, nt);
}

/* Step 1: light at the particles and the leaves (model/climbing_light.h);
 * leaves add their volumes s²·thickness to the grid. */
static int light_step(phc_climbing *c, size_t n0)
{
    const phc_climbing_options *o = &c->o;
    const phc_climbing_occluders occ = {c->occ_v, c->occ_nv, c->occ_t, c->occ_nt, c->opaque};
    if (o->leaf_step == 0) { /* no leaves: the points are the particles' centres, as they are */
        phc_climbing_light_shaded_zeroed(&o->light, c->opaque ? &occ : NULL, c->x, c->vol, n0,
                                         c->phi, c->light);
        if (c->field.value) { /* seek_light: the light field from the same points */
            if (field_update(c, c->opaque ? &occ : NULL, c->x, c->vol, n0, n0))
                return -1;
            c->field_ready = 1;
        }
        return 0;
    }
    /* the particles' points, then the leaves': point i is particle i */
    if (team(n0)) {
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n0; ++i)
            light_point(c, i);
    } else {
        for (size_t i = 0; i < n0; ++i)
            light_point(c, i);
    }
    size_t m = n0;
    const double leaf_vol = o->leaf_size * o->leaf_size * o->leaf_thickness;
    for (size_t i = 0; i < n0; ++i)
        if (c->has_leaf[i]) {
            memcpy(c->sx + 3 * m, c->leaf_c + 3 * i, 3 * sizeof *c->sx);
            c->sv[m++] = leaf_vol;
        }
    phc_climbing_light_shaded_zeroed(&o->light, c->opaque ? &occ : NULL, c->sx, c->sv, m, c->phi,
                                     c->sI);
    memcpy(c->light, c->sI, n0 * sizeof *c->light);
    const size_t points = m;
    m = n0;
    for (size_t i = 0; i < n0; ++i)
        if (c->has_leaf[i])
            c->leaf_light[i] = c->sI[m++];
    /* seek_light: the light field from the same shading points */
    if (c->field.value) {
        if (field_update(c, c->opaque ? &occ : NULL, c->sx, c->sv, points, n0))
            return -1;
        c->field_ready = 1;
    }
    return 0;
}

/* Step 9: secondary growth by the pipe model. */
static void cambium(phc_climbing *c, double dt)
{
    phc_climbing_pipe_targets(c->n, c->parent, c->radius, c->r0, c->has_leaf,
                              c->o.leaf_pipe_area, c->has_child, c->target);
    for (size_t i = 0; i < c->n; ++i) {
        c->radius[i] = phc_climbing_cambium_step(c->radius[i], c->target[i], c->o.cambium_rate, dt);
        volume_at(c, i);
    }
}

/* Step 8 for particle i: a new leaf when its node is grown and due one;
 * its blade placed and oriented.  Returns 1 when it bears a leaf. */
static int leaf_update(phc_climbing *c, size_t i, double alpha, double tmax)
{
    const phc_climbing_options *o = &c->o;
    if (!c->has_leaf[i]) {
        if (c->apical[i] || c->node_k[i] % o->leaf_step != 0 || c->falling[i])
            return 0;
        c->has_leaf[i] = 1; /* its first light: the stem's at the node */
        c->leaf_light[i] = c->light[i];
    }
    double tip[3];
    const double *d = c->d + 3 * i;
    seg_tip(c, i, 0, tip);
    double *p = c->leaf_p + 3 * i;
    phc_climbing_leaf_petiole(d, (double)(c->node_k[i] / o->leaf_step), alpha, p);
    /* a petiole that points into a support within a blade's reach is
       mirrored in the support's face (ours: blades stay in front of the
       wall the shoot climbs on), then made ⊥ the stem again */
    double cp[3], nf[3];
    if (o->closest && o->closest(o->closest_user, tip, cp, nf) == 0) {
        const double r[3] = {tip[0] - cp[0], tip[1] - cp[1], tip[2] - cp[2]};
        const double pn = dot(p, nf);
        if (sqrt(dot(r, r)) < o->leaf_size && pn < 0) {
            for (int k = 0; k < 3; ++k)
                p[k] -= 2 * pn * nf[k];
            const double pd = dot(p, d);
            double q[3] = {p[0] - pd * d[0], p[1] - pd * d[1], p[2] - pd * d[2]};
            if (unit(q, q) == 0)
                memcpy(p, q, sizeof q);
        }
    }
    for (int k = 0; k < 3; ++k)
        c->leaf_c[3 * i + k] = tip[k] + 0.5 * o->leaf_size * p[k];
    phc_climbing_leaf_normal(d, o->light.direction, o->leaf_response, c->leaf_light[i], tmax,
                             c->leaf_n + 3 * i);
    return 1;
}

/* Step 8: new leaves at grown nodes; every blade placed and oriented (each
 * particle's leaf its own). */
static void leaves_update(phc_climbing *c)
{
    const phc_climbing_options *o = &c->o;
    const double alpha = o->leaf_angle_deg * PI / 180, tmax = o->leaf_max_angle_deg * PI / 180;
    size_t count_leaves = 0;
    if (team(c->n)) {
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : count_leaves)
        for (size_t i = 0; i < c->n; ++i)
            count_leaves += (size_t)leaf_update(c, i, alpha, tmax);
    } else {
        for (size_t i = 0; i < c->n; ++i)
            count_leaves += (size_t)leaf_update(c, i, alpha, tmax);
    }
    c->leaves = count_leaves;
}

int phc_climbing_set_shadow_triangles(phc_climbing *c, const double *vertices, size_t nv,
                                      const size_t *triangles, size_t nt, phc_error *err)
{
    const size_t cells = phc_climbing_light_cells(&c->o.light);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const size_t v = triangles[3 * t + k];
            if (v >= nv)
                return phc_error_set(err, PHC_ERR_INVALID,
                                     "climbing: shadow triangle %zu: vertex index %zu >= %zu "
                                     "vertices",
                                     t, v, nv);
            for (int j = 0; j < 3; ++j)
                if (!isfinite(vertices[3 * v + j]))
                    return phc_error_set(err, PHC_ERR_INVALID,
                                         "climbing: shadow triangle %zu: vertex %zu is not finite",
                                         t, v);
        }
    if (!c->opaque) {
        c->opaque = calloc(cells, 1);
        if (!c->opaque)
            return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for %zu light cells",
                                 cells);
    }
    if (!c->phi) {
        c->phi = malloc(cells * sizeof *c->phi);
        if (!c->phi)
            return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for %zu light cells",
                                 cells);
    }
    double *nv_ = realloc(c->occ_v, 3 * (c->occ_nv + nv) * sizeof *nv_);
    if (nv_)
        c->occ_v = nv_;
    size_t *nt_ = nv_ ? realloc(c->occ_t, 3 * (c->occ_nt + nt) * sizeof *nt_) : NULL;
    if (!nv_ || !nt_)
        return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for %zu shadow triangles",
                             nt);
    c->occ_t = nt_;
    memcpy(c->occ_v + 3 * c->occ_nv, vertices, 3 * nv * sizeof *vertices);
    for (size_t t = 0; t < 3 * nt; ++t)
        c->occ_t[3 * c->occ_nt + t] = c->occ_nv + triangles[t];
    c->occ_nv += nv;
    c->occ_nt += nt;
    for (size_t t = 0; t < nt; ++t) {
        const size_t *v = triangles + 3 * t;
        c->opaque_cells += phc_climbing_light_mark_triangle(
            &c->o.light, vertices + 3 * v[0], vertices + 3 * v[1], vertices + 3 * v[2], c->opaque);
    }
    return 0;
}

size_t phc_climbing_opaque_cells(const phc_climbing *c) { return c->opaque_cells; }

int phc_climbing_leaf(const phc_climbing *c, size_t i, double centre[3], double normal[3],
                      double petiole[3])
{
    if (!c->has_leaf[i])
        return 0;
    if (centre)
        memcpy(centre, c->leaf_c + 3 * i, 3 * sizeof *centre);
    if (normal)
        memcpy(normal, c->leaf_n + 3 * i, 3 * sizeof *normal);
    if (petiole)
        memcpy(petiole, c->leaf_p + 3 * i, 3 * sizeof *petiole);
    return 1;
}

double phc_climbing_leaf_light(const phc_climbing *c, size_t i)
{
    return c->has_leaf[i] ? c->leaf_light[i] : 0;
}

int phc_climbing_leaf_quad(const phc_climbing *c, size_t i, double corners[12])
{
    if (!c->has_leaf[i])
        return 0;
    const double *n = c->leaf_n + 3 * i, *p = c->leaf_p + 3 * i, *x = c->leaf_c + 3 * i;
    /* blade axes: u = petiole made ⊥ n, v = n × u */
    const double pn = dot(p, n);
    double u[3] = {p[0] - pn * n[0], p[1] - pn * n[1], p[2] - pn * n[2]};
    if (unit(u, u)) { /* petiole along the normal: any u ⊥ n */
        double e2[3];
        phc_climbing_leaf_frame(n, u, e2);
    }
    const double v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2],
                         n[0] * u[1] - n[1] * u[0]};
    const double h = 0.5 * c->o.leaf_size;
    static const double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
    for (int q = 0; q < 4; ++q)
        for (int k = 0; k < 3; ++k)
            corners[3 * q + k] = x[k] + h * (su[q] * u[k] + sv[q] * v[k]);
    return 1;
}

size_t phc_climbing_leaf_count(const phc_climbing *c) { return c->leaves; }
void phc_climbing_light_direction(const phc_climbing *c, double l[3])
{
    memcpy(l, c->o.light.direction, 3 * sizeof *l);
}
unsigned phc_climbing_node_index(const phc_climbing *c, size_t i) { return c->node_k[i]; }
double phc_climbing_primary_radius(const phc_climbing *c, size_t i) { return c->r0[i]; }

int phc_climbing_step(phc_climbing *c, double dt, phc_error *err)
{
    const phc_climbing_options *o = &c->o;
    if (!(dt > 0) || !isfinite(dt))
        return phc_error_set(err, PHC_ERR_INVALID, "climbing: time step dt = %g s must be > 0",
                             dt);
    if (!(o->growth_rate * dt < 1 - o->bud_fraction))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "climbing: growth_rate * dt = %g must be below 1 - bud_fraction = "
                             "%g (one successor per tip and step)",
                             o->growth_rate * dt, 1 - o->bud_fraction);
    c->sync_all = !c->handed; /* (an error below leaves handed 0) */
    c->handed = 0;
    c->stats.time += dt;
    const size_t n0 = c->n;
    for (size_t i = 0; i < n0; ++i)
        c->age[i] += dt;
    /* 1. light */
    if ((o->light.extinction > 0 || c->opaque) && light_step(c, n0))
        return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for the light field");
    /* 2.–3. tropisms and lengthening of the tips present at the start
       (with their rest shape when rest_with_growth): each changes only its
       own particle, so all at once (before any growth appends) */
    const int rest = rest_with_growth(c);
    if (team(n0)) {
#pragma omp parallel for schedule(dynamic, 256)
        for (size_t i = 0; i < n0; ++i)
            tip_step(c, i, dt, rest);
    } else {
        for (size_t i = 0; i < n0; ++i)
            tip_step(c, i, dt, rest);
    }
    /* 3.–4. the tips that reached full size branch, in index order (the
       random numbers) */
    size_t ngrown = 0;
    for (size_t i = 0; i < n0; ++i) {
        if (!c->apical[i])
            continue;
        c->grown[ngrown++] = i; /* (c->grown may move as branch appends) */
        if (branch(c, i)) {
            count(c);
            return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory at %zu particles",
                                 c->n);
        }
    }
    /* keep_outside (ours) once more on the grown tips, the new ones included */
    if (o->keep_outside)
        for (size_t i = 0; i < c->n; ++i)
            if (c->apical[i])
                keep_outside(c, i);
    /* 9. secondary growth */
    if (o->cambium_rate > 0)
        cambium(c, dt);
    /* 5. rest shape */
    rebuild_rest(c, ngrown, n0);
    /* 6. dynamics, or kinematic: current = rest */
    if (o->dynamics_substeps > 0) {
        if (dynamics(c, dt, ngrown, err)) {
            count(c);
            return -1;
        }
    } else {
        memcpy(c->x, c->xr, 3 * c->n * sizeof *c->x);
        memcpy(c->d, c->dr, 3 * c->n * sizeof *c->d);
        collide_kinematic(c);
    }
    /* 7. anchors (after a dynamics step, with the read-back of the shape) */
    anchors(c, o->dynamics_substeps > 0);
    /* broken pieces that fell long enough leave the plant */
    if (c->stats.falling && drop_fallen(c, 0, err)) {
        count(c);
        return -1;
    }
    /* stumps whose resprout_delay is over grow a new tip */
    if ((c->stumps.n || c->stumps_lost) && resprout(c, err)) {
        count(c);
        return -1;
    }
    /* 8. leaves */
    if (o->leaf_step > 0)
        leaves_update(c);
    count(c);
    return 0;
}

int phc_climbing_set_gravity(phc_climbing *c, const double g[3], phc_error *err)
{
    for (int k = 0; k < 3; ++k)
        if (!isfinite(g[k]))
            return phc_error_set(err, PHC_ERR_INVALID, "climbing: gravity %c is not finite",
                                 "xyz"[k]);
    memcpy(c->o.particles.gravity, g, sizeof c->o.particles.gravity);
    return 0;
}

int phc_climbing_set_dynamics_substeps(phc_climbing *c, size_t substeps, phc_error *err)
{
    if (substeps > 0 && !(c->o.particles.maturity_age > 0))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "climbing: dynamics need particles.maturity_age > 0 (it is %g s)",
                             c->o.particles.maturity_age);
    if (substeps == 0 && c->stats.falling && drop_fallen(c, 1, err))
        return -1;
    c->o.dynamics_substeps = substeps;
    if (substeps == 0) { /* kinematic from now on: a later dynamic step starts afresh */
        phc_particles_free(c->sys);
        c->sys = NULL;
    }
    return 0;
}

void phc_climbing_get_stats(const phc_climbing *c, phc_climbing_stats *s) { *s = c->stats; }
size_t phc_climbing_count(const phc_climbing *c) { return c ? c->n : 0; }
size_t phc_climbing_parent(const phc_climbing *c, size_t i) { return c->parent[i]; }
unsigned phc_climbing_order(const phc_climbing *c, size_t i) { return c->order[i]; }
int phc_climbing_is_apical(const phc_climbing *c, size_t i) { return c->apical[i]; }
int phc_climbing_is_lateral(const phc_climbing *c, size_t i) { return c->lateral[i]; }
double phc_climbing_size(const phc_climbing *c, size_t i) { return c->sigma[i]; }
double phc_climbing_length(const phc_climbing *c, size_t i)
{
    return c->sigma[i] * c->o.max_length;
}
double phc_climbing_radius(const phc_climbing *c, size_t i) { return c->radius[i]; }
double phc_climbing_age(const phc_climbing *c, size_t i) { return c->age[i]; }
double phc_climbing_light_at(const phc_climbing *c, size_t i) { return c->light[i]; }
void phc_climbing_position(const phc_climbing *c, size_t i, double x[3])
{
    memcpy(x, c->x + 3 * i, 3 * sizeof *x);
}
void phc_climbing_direction(const phc_climbing *c, size_t i, double d[3])
{
    memcpy(d, c->d + 3 * i, 3 * sizeof *d);
}
void phc_climbing_rest_position(const phc_climbing *c, size_t i, double x[3])
{
    memcpy(x, c->xr + 3 * i, 3 * sizeof *x);
}
void phc_climbing_rest_direction(const phc_climbing *c, size_t i, double d[3])
{
    memcpy(d, c->dr + 3 * i, 3 * sizeof *d);
}
void phc_climbing_segment(const phc_climbing *c, size_t i, double base[3], double tip[3])
{
    seg_base(c, i, 0, base);
    seg_tip(c, i, 0, tip);
}
int phc_climbing_anchor(const phc_climbing *c, size_t i, double a[3])
{
    if (!c->anchored[i])
        return 0;
    memcpy(a, c->anchor_at + 3 * i, 3 * sizeof *a);
    return 1;
}

/* ---- breaking (model/climbing_breaking.h) ------------------------------- */

int phc_climbing_is_falling(const phc_climbing *c, size_t i) { return c->falling[i]; }
size_t phc_climbing_id(const phc_climbing *c, size_t i) { return c->id[i]; }

double phc_climbing_stress(const phc_climbing *c, size_t i)
{
    return c->sys && i < phc_particles_count(c->sys) ? phc_particles_stress(c->sys, i) : 0;
}

double phc_climbing_bend_stress(const phc_climbing *c, size_t i)
{
    return c->sys && i < phc_particles_count(c->sys) ? phc_particles_bend_stress(c->sys, i) : 0;
}

/* The particles broke the link of k = rep->broken_particle to its parent
 * in a substep (rep: its group stress or bending stress and joint): k's
 * subtree falls from now on, its tips stop, its anchors let go at once
 * (also in the system, for the rest of the step).  A link inside a piece
 * that already falls only splits it. */
static void break_link(phc_climbing *c, const phc_particles_report *rep)
{
    const size_t k = rep->broken_particle;
    c->cut[k] = 1;
    if (c->falling[k])
        return;
    if (c->stats.breaks == 0) { /* the first break of the plant, where and how */
        c->stats.first_break_time = c->stats.time;
        c->stats.first_break_bend_stress = rep->broken_bend_stress;
        memcpy(c->stats.first_break_joint, rep->broken_joint, sizeof c->stats.first_break_joint);
        const size_t u = c->parent[k];
        c->stats.first_break_parent_anchored = u != PHC_CLIMBING_NONE && c->anchored[u];
    }
    phc_climbing_subtree_tag(c->parent, c->n, k, c->falling, 2);
    size_t m = 0;
    for (size_t i = k; i < c->n; ++i) {
        if (c->falling[i] != 2)
            continue;
        if (c->fell_at[i] < 0) { /* (an older piece below k keeps its time) */
            c->fell_at[i] = c->stats.time;
            ++m;
        }
        c->falling[i] = 1;
        c->apical[i] = 0;
        if (c->anchored[i]) {
            c->anchored[i] = 0;
            c->stats.anchors_released++;
            phc_particles_release(c->sys, i, NULL);
        }
    }
    c->stats.breaks++;
    c->stats.falling += m;
    c->stats.last_break_id = c->id[k];
    c->stats.last_break_stress = rep->broken_stress;
    c->stats.last_break_bend_stress = rep->broken_bend_stress;
    const size_t p = c->parent[k]; /* the stump: remembered when k continued its axis */
    if (isfinite(c->o.resprout_delay) && p != PHC_CLIMBING_NONE && !c->lateral[k] &&
        phc_climbing_stumps_add(&c->stumps, c->id[p], c->stats.time))
        c->stumps_lost = 1;
}

/* The stumps due (resprout_delay after their break) that are still in the
 * plant, not falling and without an attached successor grow a new tip at
 * their top: model/climbing_breaking.h, "Resprouting". */
static int resprout(phc_climbing *c, phc_error *err)
{
    const phc_climbing_options *o = &c->o;
    if (c->stumps_lost)
        return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for a stump");
    size_t *due = malloc(c->stumps.n * sizeof *due);
    if (!due)
        return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for a stump");
    const size_t m = phc_climbing_stumps_take_due(&c->stumps, c->stats.time, o->resprout_delay, due);
    for (size_t t = 0; t < m; ++t) {
        /* the draws of a lateral bud, made whether or not it sprouts */
        const double theta = phc_climbing_rng_uniform(&c->rng) * o->direction_variance * 0.5 * PI;
        const double phi = 2 * PI * phc_climbing_rng_uniform(&c->rng);
        const size_t p = phc_climbing_find_id(c->id, c->n, due[t]);
        if (p == PHC_CLIMBING_NONE || c->falling[p] || c->apical[p] || c->n >= o->max_particles ||
            phc_climbing_has_attached_successor(c->parent, c->lateral, c->falling, c->n, p))
            continue;
        double tip[3], tipr[3], dir[3], dirr[3];
        seg_tip(c, p, 0, tip);
        seg_tip(c, p, 1, tipr);
        cone_direction(c->d + 3 * p, theta, phi, dir);
        cone_direction(c->dr + 3 * p, theta, phi, dirr);
        /* the axis goes on (not a lateral): p's order and radius */
        const size_t k = add_particle(c, p, c->order[p], 0, o->bud_fraction, c->radius[p], tip,
                                      dir, tipr);
        if (k == PHC_CLIMBING_NONE) {
            free(due);
            return phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory at %zu particles",
                                 c->n);
        }
        memcpy(c->dr + 3 * k, dirr, sizeof dirr);
        rest_at(c, k);
        c->node_k[k] = c->node_k[p] + 1;
        keep_outside(c, k);
        c->stats.resprouts++;
        c->stats.last_resprout_id = c->id[k];
    }
    free(due);
    return 0;
}

/* Drops the falling pieces whose fall_time is over (all of them with
 * `all`): the plant's arrays close up (parents renumbered), the system is
 * rebuilt from the rest with its state carried over. */
static int drop_fallen(phc_climbing *c, int all, phc_error *err)
{
    const size_t n = c->n;
    unsigned char *drop = c->has_child; /* (scratch, n) */
    size_t *map = c->grown;             /* (scratch, n; the step's tips are done with) */
    size_t pieces = 0, dropped = 0;
    for (size_t i = 0; i < n; ++i) {
        drop[i] = c->falling[i] &&
                  (all || c->stats.time - c->fell_at[i] >= c->o.fall_time * (1 - 1e-12));
        dropped += drop[i];
        pieces += drop[i] && (c->parent[i] == PHC_CLIMBING_NONE || !drop[c->parent[i]]);
    }
    if (!dropped)
        return 0;
    const size_t m = phc_climbing_keep_map(drop, n, map);
    phc_particles *sys = NULL;
    if (c->sys) { /* the new system first: on failure nothing changed */
        size_t *from = malloc(m * sizeof *from), *par = malloc(m * sizeof *par);
        double *head = malloc(3 * m * sizeof *head), *tail = malloc(3 * m * sizeof *tail),
               *rad = malloc(m * sizeof *rad);
        if (from && par && head && tail && rad) {
            for (size_t i = 0; i < n; ++i) {
                const size_t j = map[i];
                if (j == PHC_CLIMBING_NONE)
                    continue;
                from[j] = i;
                par[j] = c->parent[i] == PHC_CLIMBING_NONE || c->cut[i] ? PHC_PARTICLES_NONE
                                                                         : map[c->parent[i]];
                rest_segment(c, i, head + 3 * j, tail + 3 * j);
                rad[j] = c->radius[i];
            }
            sys = phc_climbing_system_rebuild(c->sys, &c->o.particles, m, from, par, head, tail,
                                              rad, err);
        } else {
            phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory for %zu particles", m);
        }
        free(from);
        free(par);
        free(head);
        free(tail);
        free(rad);
        if (!sys)
            return -1;
        phc_particles_measure_stress(sys, 0);
        phc_particles_free(c->sys);
        c->sys = sys;
    }
    for (size_t i = 0; i < n; ++i) /* parents renumbered (kept: a piece is a whole subtree) */
        if (!drop[i] && c->parent[i] != PHC_CLIMBING_NONE)
            c->parent[i] = map[c->parent[i]];
#define CLOSE_UP(field, per) phc_climbing_compact(c->field, (per) * sizeof *c->field, drop, n)
    CLOSE_UP(parent, 1);
    CLOSE_UP(order, 1);
    CLOSE_UP(apical, 1);
    CLOSE_UP(lateral, 1);
    CLOSE_UP(anchored, 1);
    CLOSE_UP(sigma, 1);
    CLOSE_UP(radius, 1);
    CLOSE_UP(age, 1);
    CLOSE_UP(light, 1);
    CLOSE_UP(x, 3);
    CLOSE_UP(d, 3);
    CLOSE_UP(xr, 3);
    CLOSE_UP(dr, 3);
    CLOSE_UP(anchor_at, 3);
    CLOSE_UP(anchor_t0, 1);
    CLOSE_UP(vol, 1);
    CLOSE_UP(node_k, 1);
    CLOSE_UP(has_leaf, 1);
    CLOSE_UP(leaf_c, 3);
    CLOSE_UP(leaf_n, 3);
    CLOSE_UP(leaf_p, 3);
    CLOSE_UP(leaf_light, 1);
    CLOSE_UP(r0, 1);
    CLOSE_UP(falling, 1);
    CLOSE_UP(cut, 1);
    CLOSE_UP(fell_at, 1);
    CLOSE_UP(id, 1); /* (last: drop is c->has_child, scratch, not closed up) */
#undef CLOSE_UP
    c->n = m;
    if (c->sys) /* what the system holds: the plant as it is now */
        for (size_t j = 0; j < m; ++j)
            seen_now(c, j, c->sys_seen + SEEN * j);
    size_t leaves = 0;
    for (size_t j = 0; j < m; ++j)
        leaves += c->has_leaf[j];
    c->leaves = leaves;
    c->stats.pieces_dropped += pieces;
    c->stats.particles_dropped += dropped;
    c->stats.falling -= dropped;
    return 0;
}
