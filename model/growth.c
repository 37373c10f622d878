/* Shoot-root coordination, Rhizomorph §5: see growth.h for the equations,
 * the units and the two randomness modes. */
#include "model/growth.h"

#include "model/big_array.h"

#include <ctype.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define DEG (3.14159265358979323846 / 180.0)
#define GOLDEN_ANGLE 137.50776405003785 /* deg: 360 (1 - 1/phi) */
#define PRUNE_MIN_AGE 30.0              /* d: a lateral branch is judged after a month */
#define LIGHT_GRID_MAX 96               /* voxels per axis of the light grid */

/* ---- parameters by name ---------------------------------------------------- */

#define P(name) {#name, offsetof(phc_growth_params, name)}
static const struct { const char *name; size_t offset; } param_table[] = {
    P(internode_length), P(shoot_elongation), P(apical_angle), P(branching_angle),
    P(angle_sd), P(apical_dominance), P(lateral_buds), P(bud_flush), P(apical_inhibition),
    P(inhibition_distance), P(phototropism), P(prune_ratio), P(leaf_area), P(leaf_distance),
    P(lma), P(light_extinction), P(light_voxel), P(light), P(light_use),
    P(root_node_length), P(root_elongation), P(root_apical_angle), P(root_branching_angle),
    P(root_apical_dominance), P(root_branching), P(gravitropism_root), P(hydrotropism),
    P(tropism_switch), P(nutrient_branching), P(nutrient_allocation), P(water_uptake), P(uptake_cap), P(water_use), P(root_resistance),
    P(soil_fill), P(tip_radius_shoot), P(tip_radius_root), P(pipe_exponent),
    P(maintenance_shoot), P(maintenance_root), P(growth_shoot), P(growth_root), P(phi_rg),
    P(wood_density), P(root_density), P(seed_reserve), P(reserve_rate),
};
#undef P
#define N_PARAMS (sizeof param_table / sizeof param_table[0])

size_t phc_growth_param_count(void) { return N_PARAMS; }

const char *phc_growth_param_name(size_t i)
{
    return i < N_PARAMS ? param_table[i].name : NULL;
}

double *phc_growth_param_ref(phc_growth_params *p, size_t i)
{
    return (p && i < N_PARAMS) ? (double *)((char *)p + param_table[i].offset) : NULL;
}

long phc_growth_param_find(const char *name)
{
    for (size_t i = 0; name && i < N_PARAMS; i++)
        if (strcmp(param_table[i].name, name) == 0) return (long)i;
    return -1;
}

/* Domain of each parameter: lower bound, upper bound (inf = none), and
 * whether the lower bound is excluded. */
typedef struct { const char *name; double lo, hi; int open_lo; } domain;
static const domain domains[] = {
    {"internode_length", 0, INFINITY, 1}, {"inhibition_distance", 0, INFINITY, 1},
    {"light_voxel", 0, INFINITY, 1},      {"root_node_length", 0, INFINITY, 1},
    {"tip_radius_shoot", 0, INFINITY, 1}, {"tip_radius_root", 0, INFINITY, 1},
    {"pipe_exponent", 0, INFINITY, 1},    {"growth_shoot", 0, INFINITY, 1},
    {"growth_root", 0, INFINITY, 1},      {"uptake_cap", 0, 1, 1},
    {"apical_dominance", 0, 1, 0},        {"root_apical_dominance", 0, 1, 0},
    {"phototropism", 0, 1, 0},            {"gravitropism_root", 0, 1, 0},
    {"hydrotropism", 0, 1, 0},            {"light", 0, 1, 0},
    {"phi_rg", 0, 1, 0},                  {"reserve_rate", 0, 1, 0},
};

int phc_growth_check(const phc_growth_params *p, phc_error *err)
{
    if (!p) return phc_error_set(err, PHC_ERR_INVALID, "growth parameters: NULL");
    phc_growth_params copy = *p;
    for (size_t i = 0; i < N_PARAMS; i++) {
        double v = *phc_growth_param_ref(&copy, i);
        const char *name = param_table[i].name;
        double lo = 0, hi = INFINITY;
        int open_lo = 0;
        for (size_t k = 0; k < sizeof domains / sizeof domains[0]; k++)
            if (strcmp(domains[k].name, name) == 0) {
                lo = domains[k].lo;
                hi = domains[k].hi;
                open_lo = domains[k].open_lo;
            }
        int bad = !isfinite(v) || v < lo || v > hi || (open_lo && v == lo);
        if (bad) {
            if (isinf(hi))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "growth parameter '%s': must be finite and %s 0, found %g",
                                     name, open_lo ? ">" : ">=", v);
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "growth parameter '%s': must be in %s%g, %g], found %g", name,
                                 open_lo ? "(" : "[", lo, hi, v);
        }
    }
    return PHC_OK;
}

/* ---- species presets -------------------------------------------------------
 * The five species of Rhizomorph Table 4.  The paper's table was not at
 * hand, so every number here is ours: the species differ in apical
 * dominance, branching angles, internode lengths, bud counts, phi_RG, seed
 * reserve and densities in the directions the species are known for, and
 * the shared numbers (uptake, light use, maintenance) are chosen so that
 * oak seedlings reach the sizes of greenhouse harvests (Baltzer & Thomas
 * 2007) in one season.  Calibrate them (root_shoot) before trusting them. */
static phc_growth_params preset_oak(void)
{
    phc_growth_params p = {
        .internode_length = 0.02, .shoot_elongation = 0.004, .apical_angle = 3,
        .branching_angle = 45, .angle_sd = 4, .apical_dominance = 0.8, .lateral_buds = 2,
        .bud_flush = 0.05, .apical_inhibition = 2, .inhibition_distance = 0.1,
        .phototropism = 0.05, .prune_ratio = 0.5, .leaf_area = 0.0025, .leaf_distance = 0.06,
        .lma = 60, .light_extinction = 0.5, .light_voxel = 0.05, .light = 1,
        .light_use = 100,
        .root_node_length = 0.02, .root_elongation = 0.012, .root_apical_angle = 3,
        .root_branching_angle = 60, .root_apical_dominance = 0.85, .root_branching = 1.0,
        .gravitropism_root = 0.3, .hydrotropism = 0.3, .tropism_switch = 0.2,
        .nutrient_branching = 1, .nutrient_allocation = 0,
        .water_uptake = 4e-5, .uptake_cap = 0.5, .water_use = 5e4, .root_resistance = 1,
        .soil_fill = 0.5,
        .tip_radius_shoot = 0.0005, .tip_radius_root = 0.0006, .pipe_exponent = 2,
        .maintenance_shoot = 2e4, .maintenance_root = 1e4, .growth_shoot = 0.05,
        .growth_root = 0.03, .phi_rg = 0.6, .wood_density = 6e5, .root_density = 5e5,
        .seed_reserve = 3, .reserve_rate = 0.05,
    };
    return p;
}

static int preset_index(const char *name)
{
    static const char *names[] = {"oak", "cherry", "apple", "poplar", "maple"};
    for (int i = 0; i < 5; i++)
        if (name && strcasecmp(name, names[i]) == 0) return i;
    return -1;
}

const char *phc_growth_preset_name(size_t i)
{
    static const char *names[] = {"oak", "cherry", "apple", "poplar", "maple"};
    return i < 5 ? names[i] : NULL;
}

int phc_growth_preset(const char *name, phc_growth_params *p, phc_error *err)
{
    int k = preset_index(name);
    if (!p) return phc_error_set(err, PHC_ERR_INVALID, "growth preset: NULL output");
    if (k < 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "unknown species preset '%s' (known: oak, cherry, apple, poplar, "
                             "maple)",
                             name ? name : "(null)");
    phc_growth_params q = preset_oak();
    switch (k) {
    case 0: /* oak: strong apical control, deep taproot, slow shoot */
        break;
    case 1: /* cherry: fast, strong apical dominance, sparse roots */
        q.internode_length = 0.03; q.shoot_elongation = 0.008; q.apical_dominance = 0.9;
        q.branching_angle = 40; q.lateral_buds = 1; q.phi_rg = 0.45;
        q.root_branching = 0.2; q.root_apical_dominance = 0.8; q.seed_reserve = 0.5;
        q.wood_density = 5.5e5;
        break;
    case 2: /* apple: short internodes, wide angles, many buds */
        q.internode_length = 0.015; q.shoot_elongation = 0.005; q.apical_dominance = 0.6;
        q.branching_angle = 60; q.lateral_buds = 3; q.phi_rg = 0.5;
        q.root_branching = 0.35; q.seed_reserve = 0.3; q.wood_density = 6.5e5;
        break;
    case 3: /* poplar: long internodes, fast growth, shallow spreading roots */
        q.internode_length = 0.04; q.shoot_elongation = 0.012; q.apical_dominance = 0.85;
        q.branching_angle = 35; q.lateral_buds = 2; q.phi_rg = 0.4;
        q.gravitropism_root = 0.1; q.root_branching = 0.4; q.seed_reserve = 0.1;
        q.wood_density = 4e5; q.root_density = 3.5e5;
        break;
    case 4: /* maple: opposite buds, moderate dominance */
        q.internode_length = 0.025; q.shoot_elongation = 0.006; q.apical_dominance = 0.7;
        q.branching_angle = 50; q.lateral_buds = 2; q.phi_rg = 0.5;
        q.root_branching = 0.3; q.seed_reserve = 0.3; q.wood_density = 5.5e5;
        break;
    }
    *p = q;
    return PHC_OK;
}

const char *phc_growth_preset_for_species(const char *species, const char **group)
{
    static const struct { const char *genus, *preset; } described[] = {
        {"Quercus", "oak"}, {"Prunus", "cherry"}, {"Malus", "apple"},
        {"Populus", "poplar"}, {"Acer", "maple"},
    };
    static const char *const conifers[] = {
        "Pinus", "Picea", "Abies", "Pseudotsuga", "Larix", "Tsuga", "Cedrus",
        "Chamaecyparis", "Cryptomeria", "Cupressus", "Juniperus", "Thuja", "Sequoia",
        "Taxodium", "Metasequoia", "Taxus", "Podocarpus", "Agathis", "Araucaria",
    };
    if (group) *group = "other";
    if (!species) return NULL;
    while (*species == ' ') species++;
    size_t len = strcspn(species, " ");
    for (size_t i = 0; i < sizeof described / sizeof described[0]; i++)
        if (strlen(described[i].genus) == len && strncasecmp(species, described[i].genus, len) == 0) {
            if (group) *group = described[i].genus;
            return described[i].preset;
        }
    for (size_t i = 0; i < sizeof conifers / sizeof conifers[0]; i++)
        if (strlen(conifers[i]) == len && strncasecmp(species, conifers[i], len) == 0) {
            if (group) *group = "conifer";
            return NULL;
        }
    return NULL;
}

phc_growth_options phc_growth_options_default(void)
{
    phc_growth_options o;
    memset(&o, 0, sizeof o);
    o.mode = PHC_GROWTH_EXPECTED;
    o.seed = 1;
    o.uptake = PHC_GROWTH_UPTAKE_PHYSICAL;
    o.long_step = 7.0;
    return o;
}

/* ---- the plant -------------------------------------------------------------- */

struct phc_growth {
    phc_growth_params p;
    phc_growth_options o;
    phc_soil *soil;
    phc_growth_node *node;
    size_t n, cap;
    double age, reserve;
    uint64_t rng[4];
    size_t buds_made;         /* golden-angle roll counter */
    size_t pruned;
    double shoot_flux, root_flux, vigor, maintenance, uptake_total;
    /* scratch, grown with the nodes */
    double *a, *b, *c;        /* per node */
    size_t *voxel;            /* per node: soil voxel of a root segment */
    size_t scratch_cap;
    double *sink_rate;        /* per soil voxel: m^3/m^3/h taken by the roots */
    size_t *sink_voxels;      /* the voxels whose sink_rate is > 0, ascending */
    size_t n_sink_voxels;
    double *light_grid;
    size_t light_cap;
};

/* xoshiro256** (Blackman & Vigna 2018), seeded by splitmix64. */
static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
static uint64_t rng_next(uint64_t s[4])
{
    uint64_t r = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0]; s[3] ^= s[1]; s[1] ^= s[2]; s[0] ^= s[3];
    s[2] ^= t; s[3] = rotl(s[3], 45);
    return r;
}
static double rng_uniform(phc_growth *g) { return (rng_next(g->rng) >> 11) * 0x1.0p-53; }
static double rng_normal(phc_growth *g)
{
    double u = rng_uniform(g), v = rng_uniform(g);
    return sqrt(-2 * log(u > 0 ? u : 1e-300)) * cos(2 * 3.14159265358979323846 * v);
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
static void normalize3(double v[3])
{
    double l = norm3(v);
    if (l > 0) { v[0] /= l; v[1] /= l; v[2] /= l; }
}

/* d turned by `angle` deg away from itself, in the direction given by
 * `roll` deg around it (roll 0 = toward the horizontal axis the basis
 * picks deterministically from d). */
static void turn(const double d[3], double angle, double roll, double out[3])
{
    double helper[3] = {0, 0, 1};
    if (fabs(d[2]) > 0.9) { helper[0] = 1; helper[2] = 0; }
    double u[3] = {d[1] * helper[2] - d[2] * helper[1], d[2] * helper[0] - d[0] * helper[2],
                   d[0] * helper[1] - d[1] * helper[0]};
    normalize3(u);
    double v[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
    double ca = cos(angle * DEG), sa = sin(angle * DEG), cr = cos(roll * DEG), sr = sin(roll * DEG);
    for (int k = 0; k < 3; k++) out[k] = ca * d[k] + sa * (cr * u[k] + sr * v[k]);
    normalize3(out);
}

/* Bends d toward target by weight w in [0, 1] (a blend of unit vectors). */
static void bend(double d[3], const double target[3], double w)
{
    if (w <= 0) return;
    for (int k = 0; k < 3; k++) d[k] = (1 - w) * d[k] + w * target[k];
    if (norm3(d) < 1e-12) { d[0] = target[0]; d[1] = target[1]; d[2] = target[2]; }
    normalize3(d);
}

/* The most nodes the plant may have (options.max_nodes; 0 = 10 million). */
static size_t node_limit(const phc_growth *g) { return g->o.max_nodes ? g->o.max_nodes : 10000000; }

static int reserve_nodes(phc_growth *g, size_t need, phc_error *err)
{
    size_t limit = node_limit(g);
    if (need > limit)
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "the plant would grow past %zu nodes (max_nodes) at day %g", limit,
                             g->age);
    if (need <= g->cap) return PHC_OK;
    size_t cap = g->cap ? g->cap : 64;
    while (cap < need) cap *= 2;
    /* huge pages from 2 MiB up (big_array.h): a month step writes tens of
       MiB of new nodes, and 4 KiB pages cost a fault each */
    phc_growth_node *nn = cap <= SIZE_MAX / sizeof *nn
                              ? phc_big_array_grow(g->node, g->n * sizeof *nn, cap * sizeof *nn)
                              : NULL;
    if (!nn) return phc_error_set(err, PHC_ERR_NOMEM, "growth: out of memory for %zu nodes", cap);
    g->node = nn;
    g->cap = cap;
    return PHC_OK;
}

static int reserve_scratch(phc_growth *g, phc_error *err)
{
    if (g->scratch_cap >= g->cap) return PHC_OK;
    size_t cap = g->cap;
    /* scratch: every pass writes before it reads, so nothing is kept */
    double *a = phc_big_array_grow(g->a, 0, cap * sizeof *a);
    if (a) g->a = a;
    double *b = phc_big_array_grow(g->b, 0, cap * sizeof *b);
    if (b) g->b = b;
    double *c = phc_big_array_grow(g->c, 0, cap * sizeof *c);
    if (c) g->c = c;
    size_t *v = phc_big_array_grow(g->voxel, 0, cap * sizeof *v);
    if (v) g->voxel = v;
    if (!a || !b || !c || !v) return phc_error_set(err, PHC_ERR_NOMEM, "growth: out of memory");
    g->scratch_cap = cap;
    return PHC_OK;
}

/* Appends a segment below `parent` heading along dir; returns its index. */
static size_t add_node(phc_growth *g, size_t parent, int system, int apical, const double dir[3],
                       double length, double roll)
{
    phc_growth_node *n = &g->node[g->n];
    memset(n, 0, sizeof *n);
    n->parent = parent;
    n->apical_child = PHC_GROWTH_NONE;
    n->system = (unsigned char)system;
    n->tip = 1;
    n->dir[0] = dir[0]; n->dir[1] = dir[1]; n->dir[2] = dir[2];
    n->length = length;
    n->birth = g->age;
    n->roll = roll;
    n->light = 1;
    n->fill = g->p.soil_fill;
    if (parent == PHC_GROWTH_NONE) {
        n->order = 1;
        memcpy(n->head, g->o.base, sizeof n->head);
        n->branch_length = length;
    } else {
        phc_growth_node *q = &g->node[parent];
        n->order = (unsigned short)(q->order + (apical ? 0 : 1));
        for (int k = 0; k < 3; k++) n->head[k] = q->head[k] + q->dir[k] * q->length;
        n->branch_length = (apical ? q->branch_length : 0) + length;
        if (apical) { q->apical_child = g->n; q->tip = 0; }
    }
    return g->n++;
}

static int soil_sink(void *user, double t, double h, const double *w, const double *v,
                     double *water, double *nutrient)
{
    (void)t; (void)v; (void)nutrient;
    phc_growth *g = user;
    const double *rate = g->sink_rate;
    /* the voxels with roots (a few of a pot's), not every voxel: the soil
       calls this on every sub-step */
    for (size_t k = 0; k < g->n_sink_voxels; k++) {
        const size_t i = g->sink_voxels[k];
        water[i] = fmin(rate[i] * h, w[i]);
    }
    return 0;
}

int phc_growth_new(const phc_growth_params *p, const phc_growth_options *o, phc_soil *soil,
                   phc_growth **out, phc_error *err)
{
    if (!p || !out) return phc_error_set(err, PHC_ERR_INVALID, "growth: NULL argument");
    *out = NULL;
    int rc = phc_growth_check(p, err);
    if (rc) return rc;
    phc_growth_options opt = o ? *o : phc_growth_options_default();
    for (int k = 0; k < 3; k++)
        if (!isfinite(opt.base[k]))
            return phc_error_set(err, PHC_ERR_INPUT, "the plant's seed position is not finite");
    if (!(opt.long_step >= 0) || !isfinite(opt.long_step))
        return phc_error_set(err, PHC_ERR_INPUT, "growth options: long_step must be finite and >= 0 d, found %g",
                             opt.long_step);
    if (soil) {
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) lo[k] = soil->origin[k];
        hi[0] = lo[0] + soil->nx * soil->dx;
        hi[1] = lo[1] + soil->ny * soil->dx;
        hi[2] = lo[2] + soil->nz * soil->dx;
        for (int k = 0; k < 3; k++)
            if (opt.base[k] < lo[k] || opt.base[k] > hi[k])
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "the plant is seeded at (%g, %g, %g) m, outside the soil grid "
                                     "[%g, %g] x [%g, %g] x [%g, %g] m",
                                     opt.base[0], opt.base[1], opt.base[2], lo[0], hi[0], lo[1],
                                     hi[1], lo[2], hi[2]);
        if (soil->sink && opt.uptake == PHC_GROWTH_UPTAKE_PHYSICAL)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "growth: the soil already has a sink hook (one plant per soil)");
    }
    phc_growth *g = calloc(1, sizeof *g);
    if (!g) return phc_error_set(err, PHC_ERR_NOMEM, "growth: out of memory");
    g->p = *p;
    g->o = opt;
    g->soil = soil;
    g->reserve = p->seed_reserve;
    uint64_t x = opt.seed;
    for (int k = 0; k < 4; k++) { /* splitmix64 */
        uint64_t z = (x += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        g->rng[k] = z ^ (z >> 31);
    }
    /* the two bases, room for 64 nodes unless max_nodes is smaller */
    if ((rc = reserve_nodes(g, node_limit(g) < 64 ? (node_limit(g) < 2 ? 2 : node_limit(g)) : 64, err)) ||
        (rc = reserve_scratch(g, err)))
        goto fail;
    if (soil) {
        g->sink_rate = calloc(soil->n, sizeof *g->sink_rate);
        g->sink_voxels = malloc(soil->n * sizeof *g->sink_voxels);
        if (!g->sink_rate || !g->sink_voxels) { rc = phc_error_set(err, PHC_ERR_NOMEM, "growth: out of memory"); goto fail; }
        if (opt.uptake == PHC_GROWTH_UPTAKE_PHYSICAL) {
            soil->sink = soil_sink;
            soil->sink_user = g;
        }
    }
    const double up[3] = {0, 0, 1}, down[3] = {0, 0, -1};
    add_node(g, PHC_GROWTH_NONE, PHC_GROWTH_SHOOT, 0, up, 0.1 * p->internode_length, 0);
    add_node(g, PHC_GROWTH_NONE, PHC_GROWTH_ROOT, 0, down, 0.1 * p->root_node_length, 0);
    *out = g;
    return PHC_OK;
fail:
    phc_growth_free(g);
    return rc;
}

void phc_growth_free(phc_growth *g)
{
    if (!g) return;
    if (g->soil && g->soil->sink == soil_sink && g->soil->sink_user == g) {
        g->soil->sink = NULL;
        g->soil->sink_user = NULL;
    }
    free(g->node);
    free(g->a);
    free(g->b);
    free(g->c);
    free(g->voxel);
    free(g->sink_rate);
    free(g->sink_voxels);
    free(g->light_grid);
    free(g);
}

const phc_growth_node *phc_growth_nodes(const phc_growth *g, size_t *n)
{
    if (n) *n = g ? g->n : 0;
    return g ? g->node : NULL;
}

const phc_growth_params *phc_growth_parameters(const phc_growth *g) { return g ? &g->p : NULL; }

static double seg_length(const phc_growth *g, int system)
{
    return system == PHC_GROWTH_SHOOT ? g->p.internode_length : g->p.root_node_length;
}

/* ---- the step ---------------------------------------------------------------- */

/* Positions (top-down): heads from the parents' tails, branch lengths.
 * Growing tips move the laterals they carry, so this ends every step. */
static void place(phc_growth *g)
{
    for (size_t i = 0; i < g->n; i++) {
        phc_growth_node *n = &g->node[i];
        if (n->parent != PHC_GROWTH_NONE) {
            const phc_growth_node *q = &g->node[n->parent];
            for (int k = 0; k < 3; k++) n->head[k] = q->head[k] + q->dir[k] * q->length;
            n->branch_length = (q->apical_child == i ? q->branch_length : 0) + n->length;
        } else {
            n->branch_length = n->length;
        }
    }
}

/* The soil under each root segment: fill, growth resistance, nutrients and
 * the voxel (positions must be current: place() ends every step). */
static void sample_soil(phc_growth *g)
{
    phc_soil *s = g->soil;
    for (size_t i = 0; i < g->n; i++) {
        phc_growth_node *n = &g->node[i];
        g->voxel[i] = PHC_GROWTH_NONE;
        if (n->system != PHC_GROWTH_ROOT) continue;
        if (!s) { n->fill = g->p.soil_fill; n->resistance = 0; n->nutrient = 0; continue; }
        double c[3];
        for (int k = 0; k < 3; k++) c[k] = n->head[k] + 0.5 * n->length * n->dir[k];
        double ijk[3];
        size_t dim[3] = {s->nx, s->ny, s->nz};
        int inside = 1;
        for (int k = 0; k < 3; k++) {
            ijk[k] = floor((c[k] - s->origin[k]) / s->dx);
            if (ijk[k] < 0 || ijk[k] >= (double)dim[k]) inside = 0;
        }
        if (!inside) { n->fill = 0; n->resistance = 0; n->nutrient = 0; continue; }
        size_t v = (size_t)ijk[0] + s->nx * ((size_t)ijk[1] + s->ny * (size_t)ijk[2]);
        g->voxel[i] = v;
        double w = 0;
        phc_soil_sample(s, s->w, c[0], c[1], c[2], &w, NULL, NULL);
        n->fill = s->c[v] > 0 ? w / s->c[v] : 0;
        if (n->fill < 0) n->fill = 0;
        n->resistance = s->d[v];
        n->nutrient = s->v[v];
    }
}

/* Leaf area (eq. 5) from each internode's distance to the nearest shoot tip,
 * then light through the column model and the shoot flux S_F. */
static int shoot_flux(phc_growth *g, phc_error *err)
{
    const phc_growth_params *p = &g->p;
    double *tipdist = g->a;
    for (size_t i = 0; i < g->n; i++) tipdist[i] = g->node[i].tip ? 0 : INFINITY;
    for (size_t i = g->n; i-- > 0;) {
        const phc_growth_node *n = &g->node[i];
        if (n->parent != PHC_GROWTH_NONE && n->system == PHC_GROWTH_SHOOT) {
            double d = tipdist[i] + n->length;
            if (d < tipdist[n->parent]) tipdist[n->parent] = d;
        }
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double total_area = 0;
    for (size_t i = 0; i < g->n; i++) {
        phc_growth_node *n = &g->node[i];
        if (n->system != PHC_GROWTH_SHOOT) continue;
        double f = (p->leaf_distance + p->internode_length - tipdist[i]) / p->internode_length;
        f = f < 0 ? 0 : f > 1 ? 1 : f;
        double grown = n->length / p->internode_length;
        n->leaf_area = p->leaf_area * f * (grown > 1 ? 1 : grown);
        total_area += n->leaf_area;
        for (int k = 0; k < 3; k++) {
            double c = n->head[k] + 0.5 * n->length * n->dir[k];
            if (c < lo[k]) lo[k] = c;
            if (c > hi[k]) hi[k] = c;
        }
    }
    g->shoot_flux = 0;
    if (total_area <= 0) return PHC_OK;
    double vox = p->light_voxel;
    size_t dim[3];
    for (;;) {
        int ok = 1;
        for (int k = 0; k < 3; k++) {
            dim[k] = (size_t)floor((hi[k] - lo[k]) / vox) + 1;
            if (dim[k] > LIGHT_GRID_MAX) ok = 0;
        }
        if (ok) break;
        vox *= 2;
    }
    size_t cells = dim[0] * dim[1] * dim[2];
    if (cells > g->light_cap) {
        double *lg = realloc(g->light_grid, cells * sizeof *lg);
        if (!lg) return phc_error_set(err, PHC_ERR_NOMEM, "growth: out of memory (light grid)");
        g->light_grid = lg;
        g->light_cap = cells;
    }
    double *grid = g->light_grid;
    memset(grid, 0, cells * sizeof *grid);
    size_t *cell = g->voxel; /* root voxels are not needed here: shoots only */
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        if (n->system != PHC_GROWTH_SHOOT) continue;
        size_t ix[3];
        for (int k = 0; k < 3; k++) {
            double c = n->head[k] + 0.5 * n->length * n->dir[k];
            ix[k] = (size_t)floor((c - lo[k]) / vox);
            if (ix[k] >= dim[k]) ix[k] = dim[k] - 1;
        }
        cell[i] = ix[0] + dim[0] * (ix[1] + dim[1] * ix[2]);
        grid[cell[i]] += n->leaf_area;
    }
    /* Column sums from the top: grid holds, per cell, the leaf area strictly
     * above plus half its own (self-shading inside the cell). */
    size_t plane = dim[0] * dim[1];
    for (size_t col = 0; col < plane; col++) {
        double above = 0;
        for (size_t z = dim[2]; z-- > 0;) {
            double own = grid[col + plane * z];
            grid[col + plane * z] = above + 0.5 * own;
            above += own;
        }
    }
    double sf = 0, area = vox * vox;
    for (size_t i = 0; i < g->n; i++) {
        phc_growth_node *n = &g->node[i];
        if (n->system != PHC_GROWTH_SHOOT) continue;
        n->light = p->light * exp(-p->light_extinction * grid[cell[i]] / area);
        sf += n->leaf_area * n->light;
    }
    g->shoot_flux = p->light_use * sf;
    return PHC_OK;
}

/* Root flux (eqs. 7-9) with the per-voxel competition; fills sink rates. */
static void root_flux(phc_growth *g)
{
    const phc_growth_params *p = &g->p;
    phc_soil *s = g->soil;
    double total = 0;
    if (s) memset(g->sink_rate, 0, s->n * sizeof *g->sink_rate);
    for (size_t i = 0; i < g->n; i++) {
        phc_growth_node *n = &g->node[i];
        if (n->system != PHC_GROWTH_ROOT) continue;
        n->uptake = p->water_uptake * n->length * n->fill;
        if (s && g->voxel[i] != PHC_GROWTH_NONE) g->sink_rate[g->voxel[i]] += n->uptake;
    }
    if (s) {
        double vol = s->dx * s->dx * s->dx;
        /* sink_rate holds the demand (m^3/d) per voxel: scale to the cap */
        for (size_t i = 0; i < g->n; i++) {
            phc_growth_node *n = &g->node[i];
            if (n->system != PHC_GROWTH_ROOT) continue;
            size_t v = g->voxel[i];
            if (v == PHC_GROWTH_NONE) { n->uptake = 0; continue; }
            double cap = p->uptake_cap * s->w[v] * vol;
            double demand = g->sink_rate[v];
            if (demand > cap && demand > 0) n->uptake *= cap / demand;
        }
        memset(g->sink_rate, 0, s->n * sizeof *g->sink_rate);
        for (size_t i = 0; i < g->n; i++) {
            const phc_growth_node *n = &g->node[i];
            if (n->system == PHC_GROWTH_ROOT && g->voxel[i] != PHC_GROWTH_NONE)
                g->sink_rate[g->voxel[i]] += n->uptake / (24.0 * vol); /* m^3/m^3/h */
        }
        g->n_sink_voxels = 0;
        for (size_t v = 0; v < s->n; v++)
            if (g->sink_rate[v] > 0) g->sink_voxels[g->n_sink_voxels++] = v;
    }
    for (size_t i = 0; i < g->n; i++)
        if (g->node[i].system == PHC_GROWTH_ROOT) total += g->node[i].uptake;
    g->uptake_total = total;
    g->root_flux = p->water_use * total;
}

/* Whether a segment's tail is inside the soil box: root tips stop at the
 * box's faces (a pot's walls and bottom). */
static int inside_soil(const phc_soil *s, const phc_growth_node *n)
{
    double hi[3] = {s->origin[0] + s->nx * s->dx, s->origin[1] + s->ny * s->dx,
                    s->origin[2] + s->nz * s->dx};
    for (int k = 0; k < 3; k++) {
        double t = n->head[k] + n->length * n->dir[k];
        if (t < s->origin[k] || t > hi[k]) return 0;
    }
    return 1;
}

/* Requirements bottom-up, the split (eqs. 10-12), propagation top-down
 * (eqs. 13-15) and the growth potentials (eqs. 16-17). */
static void allocate(phc_growth *g, double dt)
{
    const phc_growth_params *p = &g->p;
    /* own: a tip's requirement; wown, wreq: its weight and the subtree's in
     * the propagation (= own and requirement unless nutrient_allocation) */
    double *wsum = g->b, *own = g->c, *wreq = g->a;
    double m_sys[2] = {0, 0}, g_sys[2] = {0, 0};
    const double na = p->nutrient_allocation;
    for (size_t i = 0; i < g->n; i++) {
        phc_growth_node *n = &g->node[i];
        double vol = 3.14159265358979323846 * n->radius * n->radius * n->length;
        m_sys[n->system] += vol * (n->system == PHC_GROWTH_SHOOT ? p->maintenance_shoot
                                                                  : p->maintenance_root);
        own[i] = n->tip ? (n->system == PHC_GROWTH_SHOOT ? p->growth_shoot : p->growth_root) : 0;
        if (n->tip && n->system == PHC_GROWTH_ROOT && g->soil && !inside_soil(g->soil, n))
            own[i] = 0; /* a tip at the pot wall asks for nothing */
        g_sys[n->system] += own[i];
        n->requirement = 0;
        wsum[i] = 0;
        wreq[i] = 0;
    }
    for (size_t i = g->n; i-- > 0;) {
        phc_growth_node *n = &g->node[i];
        double lam = n->system == PHC_GROWTH_SHOOT ? p->apical_dominance : p->root_apical_dominance;
        double wown = own[i];
        if (na > 0 && n->system == PHC_GROWTH_ROOT && own[i] > 0)
            wown *= pow(n->nutrient > 0 ? n->nutrient : 0, na);
        n->requirement += own[i];
        wreq[i] += wown;
        wsum[i] += lam * wown;
        if (n->parent != PHC_GROWTH_NONE) {
            phc_growth_node *q = &g->node[n->parent];
            q->requirement += n->requirement;
            wreq[n->parent] += wreq[i];
            wsum[n->parent] += (q->apical_child == i ? lam : 1 - lam) * wreq[i];
        }
    }
    double release = dt > 0 ? g->reserve * (1 - pow(1 - p->reserve_rate, dt)) / dt : 0;
    g->reserve -= release * dt;
    double v = fmin(g->root_flux, g->shoot_flux) + release;
    double m = m_sys[0] + m_sys[1];
    g->vigor = v;
    g->maintenance = m;
    double vg = v > m ? v - m : 0;
    double sf = g->shoot_flux + 1e-12, rf = g->root_flux + 1e-12;
    double w_root = p->phi_rg * g_sys[PHC_GROWTH_ROOT] * sf;
    double w_shoot = (1 - p->phi_rg) * g_sys[PHC_GROWTH_SHOOT] * rf;
    double to_root = (w_root + w_shoot) > 0 ? vg * w_root / (w_root + w_shoot) : 0;
    double to_shoot = vg - to_root;
    if (to_root > g_sys[PHC_GROWTH_ROOT]) {
        to_shoot += to_root - g_sys[PHC_GROWTH_ROOT];
        to_root = g_sys[PHC_GROWTH_ROOT];
    }
    if (to_shoot > g_sys[PHC_GROWTH_SHOOT]) {
        double spill = to_shoot - g_sys[PHC_GROWTH_SHOOT];
        to_shoot = g_sys[PHC_GROWTH_SHOOT];
        to_root = fmin(g_sys[PHC_GROWTH_ROOT], to_root + spill);
    }
    for (size_t i = 0; i < g->n; i++) {
        phc_growth_node *n = &g->node[i];
        if (n->parent == PHC_GROWTH_NONE) {
            n->vigor = n->system == PHC_GROWTH_SHOOT ? to_shoot : to_root;
        } else {
            const phc_growth_node *q = &g->node[n->parent];
            double lam =
                n->system == PHC_GROWTH_SHOOT ? p->apical_dominance : p->root_apical_dominance;
            double w = (q->apical_child == i ? lam : 1 - lam) * wreq[i];
            n->vigor = wsum[n->parent] > 0 ? q->vigor * w / wsum[n->parent] : 0;
        }
        n->potential = 0;
        if (n->tip && own[i] > 0 && wsum[i] > 0) {
            double lam =
                n->system == PHC_GROWTH_SHOOT ? p->apical_dominance : p->root_apical_dominance;
            double wown = own[i];
            if (na > 0 && n->system == PHC_GROWTH_ROOT)
                wown *= pow(n->nutrient > 0 ? n->nutrient : 0, na);
            double mine = n->vigor * lam * wown / wsum[i];
            n->potential = fmin(1.0, mine / own[i]);
        }
    }
}

/* Apical-dominance inhibitor (eq. 4), bottom-up, felt at each tail. */
static void inhibitor(phc_growth *g)
{
    const phc_growth_params *p = &g->p;
    for (size_t i = 0; i < g->n; i++)
        g->node[i].inhibitor = g->node[i].tip ? p->apical_inhibition : 0;
    for (size_t i = g->n; i-- > 0;) {
        const phc_growth_node *n = &g->node[i];
        if (n->parent == PHC_GROWTH_NONE || n->system != PHC_GROWTH_SHOOT) continue;
        g->node[n->parent].inhibitor += n->inhibitor * exp(-n->length / p->inhibition_distance);
    }
}

/* Pruning (eq. 18): lateral shoot branches older than PRUNE_MIN_AGE whose
 * leaves earn less than prune_ratio x their maintenance.  Compacts. */
static void prune(phc_growth *g)
{
    const phc_growth_params *p = &g->p;
    if (p->prune_ratio <= 0) return;
    double *earn = g->a, *cost = g->b;
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        earn[i] = p->light_use * n->leaf_area * n->light;
        cost[i] = 3.14159265358979323846 * n->radius * n->radius * n->length *
                  (n->system == PHC_GROWTH_SHOOT ? p->maintenance_shoot : p->maintenance_root);
    }
    for (size_t i = g->n; i-- > 0;) {
        size_t q = g->node[i].parent;
        if (q != PHC_GROWTH_NONE) { earn[q] += earn[i]; cost[q] += cost[i]; }
    }
    size_t *newidx = g->voxel; /* reused: remap */
    int any = 0;
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        int dead = 0;
        if (n->parent != PHC_GROWTH_NONE) {
            if (newidx[n->parent] == PHC_GROWTH_NONE) dead = 1;
            else if (n->system == PHC_GROWTH_SHOOT && g->node[n->parent].apical_child != i &&
                     g->age - n->birth > PRUNE_MIN_AGE && cost[i] > 0 &&
                     earn[i] < p->prune_ratio * cost[i])
                dead = 1;
        }
        newidx[i] = dead ? PHC_GROWTH_NONE : 0;
        if (dead) any = 1;
    }
    if (!any) return;
    size_t m = 0;
    for (size_t i = 0; i < g->n; i++) {
        if (newidx[i] == PHC_GROWTH_NONE) { g->pruned++; continue; }
        newidx[i] = m;
        g->node[m++] = g->node[i];
    }
    for (size_t i = 0; i < m; i++) {
        phc_growth_node *n = &g->node[i];
        if (n->parent != PHC_GROWTH_NONE) n->parent = newidx[n->parent];
        if (n->apical_child != PHC_GROWTH_NONE) n->apical_child = newidx[n->apical_child];
    }
    g->n = m;
}

/* Direction of a new segment continuing `q` (eqs. 19, 23). */
static void continue_dir(phc_growth *g, const phc_growth_node *q, double d[3])
{
    const phc_growth_params *p = &g->p;
    int shoot = q->system == PHC_GROWTH_SHOOT;
    double angle = shoot ? p->apical_angle : p->root_apical_angle;
    if (g->o.mode == PHC_GROWTH_STOCHASTIC) {
        double a = fabs(angle + p->angle_sd * rng_normal(g));
        turn(q->dir, a, 360 * rng_uniform(g), d);
    } else {
        memcpy(d, q->dir, 3 * sizeof *d);
    }
    if (shoot) {
        const double up[3] = {0, 0, 1};
        bend(d, up, p->phototropism);
        return;
    }
    /* eq. 23: gravitropism (main roots) or plagiotropism (laterals, toward
     * the horizontal) above the switch fill; hydrotropism below it. */
    if (q->fill >= p->tropism_switch || !g->soil) {
        if (q->order <= 1) {
            const double down[3] = {0, 0, -1};
            bend(d, down, p->gravitropism_root);
        } else {
            double h[3] = {d[0], d[1], 0};
            if (norm3(h) > 1e-9) {
                normalize3(h);
                bend(d, h, p->gravitropism_root / q->order);
            }
        }
    } else {
        phc_soil *s = g->soil;
        double c[3], grad[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++) c[k] = q->head[k] + q->length * q->dir[k];
        for (int k = 0; k < 3; k++) {
            double a[3] = {c[0], c[1], c[2]}, b[3] = {c[0], c[1], c[2]}, wa = 0, wb = 0;
            a[k] -= s->dx;
            b[k] += s->dx;
            if (phc_soil_sample(s, s->w, a[0], a[1], a[2], &wa, NULL, NULL) == 0 &&
                phc_soil_sample(s, s->w, b[0], b[1], b[2], &wb, NULL, NULL) == 0)
                grad[k] = wb - wa;
        }
        if (norm3(grad) > 0) {
            normalize3(grad);
            bend(d, grad, p->hydrotropism);
        }
    }
}

/* A lateral child at node i (a flushed bud or a root branch). */
static void add_lateral(phc_growth *g, size_t i)
{
    const phc_growth_params *p = &g->p;
    const phc_growth_node *q = &g->node[i];
    int shoot = q->system == PHC_GROWTH_SHOOT;
    double angle = shoot ? p->branching_angle : p->root_branching_angle, roll, d[3];
    if (g->o.mode == PHC_GROWTH_STOCHASTIC) {
        angle = fabs(angle + p->angle_sd * rng_normal(g));
        roll = 360 * rng_uniform(g);
    } else {
        roll = fmod(GOLDEN_ANGLE * (double)g->buds_made, 360.0);
    }
    g->buds_made++;
    turn(q->dir, angle, roll, d);
    add_node(g, i, q->system, 0, d, 0, roll);
}

/* Events: how many happen for a probability `prob` (may exceed 1). */
static size_t events(phc_growth *g, double prob, double *sum)
{
    if (prob <= 0) return 0;
    if (g->o.mode == PHC_GROWTH_STOCHASTIC) {
        size_t k = (size_t)floor(prob);
        return k + (rng_uniform(g) < prob - (double)k ? 1 : 0);
    }
    *sum += prob;
    size_t k = (size_t)floor(*sum);
    *sum -= (double)k;
    return k;
}

/* How far (m) a root tip may grow along its direction before its tail
 * reaches a face of the soil box (new segments of a step keep roughly the
 * tip's direction, so this bounds the whole step's growth). */
static double room_in_soil(const phc_soil *s, const phc_growth_node *n)
{
    double hi[3] = {s->origin[0] + s->nx * s->dx, s->origin[1] + s->ny * s->dx,
                    s->origin[2] + s->nz * s->dx}, room = INFINITY;
    for (int k = 0; k < 3; k++) {
        double t = n->head[k] + n->length * n->dir[k];
        if (n->dir[k] > 1e-12) room = fmin(room, (hi[k] - t) / n->dir[k]);
        else if (n->dir[k] < -1e-12) room = fmin(room, (s->origin[k] - t) / n->dir[k]);
    }
    return room > 0 ? room : 0;
}

/* How far (m) tip i grows in a step of dt days (eqs. 19, 22); < 0 when it
 * does not grow (not a tip, no potential, or a root tip at the pot wall). */
static double tip_growth(const phc_growth *g, size_t i, double dt)
{
    const phc_growth_params *p = &g->p;
    const phc_growth_node *n = &g->node[i];
    if (!n->tip || n->potential <= 0) return -1;
    int shoot = n->system == PHC_GROWTH_SHOOT;
    double P = n->potential;
    if (!shoot && g->soil && !inside_soil(g->soil, n)) return -1; /* pot wall */
    double dl = shoot ? P * p->shoot_elongation * dt
                      : P * p->root_elongation * dt / (1 + p->root_resistance * n->resistance);
    if (!shoot && g->soil) dl = fmin(dl, room_in_soil(g->soil, n));
    return dl;
}

/* At least as many nodes as elongate() and flush_buds() add in a step of dt
 * days (potentials set by allocate()).  phc_growth_step reserves them up
 * front, so the node array grows once per step, before the new nodes are
 * written, instead of being copied to ever larger arrays during a long step
 * (a 30-day step of the bench plant grows it from 41k to 174k nodes).
 *   elongate: a tip of length l growing dl appends at most ceil((l + dl) /
 *   L) segments (L the segment length); each new root segment starts at
 *   most floor(prob) + 1 laterals (events(): prob the branching probability
 *   of its parent's soil, which the new segments inherit), each new shoot
 *   segment gets at most ceil(lateral_buds * P) buds;
 *   flush_buds: at most ceil(buds) laterals per shoot node, new or old. */
static size_t step_nodes_bound(const phc_growth *g, double dt)
{
    const phc_growth_params *p = &g->p;
    double add = 0;
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        if (n->system == PHC_GROWTH_SHOOT && n->buds > 0) add += ceil(n->buds);
        double dl = tip_growth(g, i, dt);
        if (dl < 0) continue;
        double segs = ceil((n->length + dl) / seg_length(g, n->system));
        if (n->system == PHC_GROWTH_SHOOT) {
            add += segs * (1 + ceil(p->lateral_buds * n->potential));
        } else {
            double prob = p->root_branching * n->potential * fmin(1.0, n->fill) *
                          (1 + p->nutrient_branching * n->nutrient);
            add += segs * (2 + floor(prob > 0 ? prob : 0));
        }
    }
    return add < 1e15 ? (size_t)add + 2 : (size_t)-1 / 2;
}

/* Elongation (eqs. 19, 22), bud numbers (eq. 21) and root branching (eq. 24). */
static int elongate(phc_growth *g, double dt, phc_error *err)
{
    const phc_growth_params *p = &g->p;
    size_t n0 = g->n;
    for (size_t i = 0; i < n0; i++) {
        double dl = tip_growth(g, i, dt);
        if (dl < 0) continue;
        int shoot = g->node[i].system == PHC_GROWTH_SHOOT;
        double P = g->node[i].potential;
        double L = seg_length(g, g->node[i].system);
        size_t cur = i;
        g->node[cur].length += dl;
        while (g->node[cur].length > L) {
            double excess = g->node[cur].length - L;
            g->node[cur].length = L;
            int rc = reserve_nodes(g, g->n + 2, err);
            if (rc) return rc;
            double d[3];
            continue_dir(g, &g->node[cur], d);
            /* a length beyond L is split again by the loop */
            size_t nw = add_node(g, cur, g->node[cur].system, 1, d, excess, g->node[cur].roll);
            g->node[nw].fill = g->node[cur].fill;
            g->node[nw].resistance = g->node[cur].resistance;
            g->node[nw].nutrient = g->node[cur].nutrient;
            if (shoot) {
                double b = p->lateral_buds * P;
                if (g->o.mode == PHC_GROWTH_STOCHASTIC) {
                    double k = floor(b);
                    b = k + (rng_uniform(g) < b - k ? 1 : 0);
                }
                g->node[nw].buds = b;
            } else {
                double prob = p->root_branching * P * fmin(1.0, g->node[cur].fill) *
                              (1 + p->nutrient_branching * g->node[cur].nutrient);
                g->node[nw].branch_sum = g->node[cur].branch_sum; /* carried along the branch */
                size_t k = events(g, prob, &g->node[nw].branch_sum);
                for (size_t b = 0; b < k; b++) {
                    if ((rc = reserve_nodes(g, g->n + 1, err))) return rc;
                    add_lateral(g, nw);
                }
            }
            cur = nw;
        }
    }
    return PHC_OK;
}

/* Bud activation (eq. 20). */
static int flush_buds(phc_growth *g, double dt, phc_error *err)
{
    const phc_growth_params *p = &g->p;
    size_t n0 = g->n;
    for (size_t i = 0; i < n0; i++) {
        phc_growth_node *n = &g->node[i];
        if (n->system != PHC_GROWTH_SHOOT || n->buds <= 0) continue;
        double rate = p->bud_flush * n->light * exp(-n->inhibitor);
        double prob = 1 - exp(-rate * dt);
        size_t k;
        if (g->o.mode == PHC_GROWTH_STOCHASTIC) {
            k = 0;
            for (size_t b = 0; b < (size_t)n->buds; b++)
                if (rng_uniform(g) < prob) k++;
        } else {
            k = events(g, prob * n->buds, &n->flush_sum);
        }
        if (k > (size_t)ceil(n->buds)) k = (size_t)ceil(n->buds);
        for (size_t b = 0; b < k; b++) {
            int rc = reserve_nodes(g, g->n + 1, err);
            if (rc) return rc;
            n = &g->node[i];
            n->buds = n->buds >= 1 ? n->buds - 1 : 0;
            add_lateral(g, i);
        }
    }
    return PHC_OK;
}

/* Pipe-model radii (Shinozaki et al. 1964), bottom-up: every segment adds
 * a pipe of the tip's cross-section, in proportion to its length, to
 * itself and everything below it, so a stem thickens as the plant above
 * it grows even without branching, and continuously in time.  Pipes of
 * pruned branches stay (radii never shrink). */
static void thicken(phc_growth *g)
{
    const phc_growth_params *p = &g->p;
    double a = p->pipe_exponent, *s = g->a;
    /* r_tip^a of each system, once per step (the same pow() per node before) */
    const double pipe[2] = {pow(p->tip_radius_shoot, a), pow(p->tip_radius_root, a)};
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        s[i] = pipe[n->system == PHC_GROWTH_SHOOT ? 0 : 1] * n->length / seg_length(g, n->system);
    }
    for (size_t i = g->n; i-- > 0;) {
        phc_growth_node *n = &g->node[i];
        double r = s[i] > 0 ? pow(s[i], 1 / a) : 0;
        if (r > n->radius) n->radius = r;
        if (n->parent != PHC_GROWTH_NONE) s[n->parent] += s[i];
    }
}

int phc_growth_step(phc_growth *g, double dt, phc_error *err)
{
    if (!g) return phc_error_set(err, PHC_ERR_INVALID, "growth: NULL plant");
    if (!(dt > 0) || !isfinite(dt))
        return phc_error_set(err, PHC_ERR_INVALID, "growth: the step must be > 0 d, found %g", dt);
    int rc = reserve_scratch(g, err);
    if (rc) return rc;
    sample_soil(g);
    if ((rc = shoot_flux(g, err))) return rc;
    root_flux(g);
    allocate(g, dt);
    inhibitor(g);
    {   /* room for the step's new nodes, up to max_nodes (reserve_nodes
           names the limit if the plant really grows past it) */
        size_t limit = node_limit(g), add = step_nodes_bound(g, dt);
        if ((rc = reserve_nodes(g, add < limit - g->n ? g->n + add : limit, err))) return rc;
    }
    if ((rc = elongate(g, dt, err))) return rc;
    if ((rc = flush_buds(g, dt, err))) return rc;
    if ((rc = reserve_scratch(g, err))) return rc;
    place(g); /* laterals on grown tips move with them */
    prune(g);
    thicken(g);
    if (g->soil) {
        if (g->o.uptake != PHC_GROWTH_UPTAKE_PHYSICAL) {
            memset(g->sink_rate, 0, g->soil->n * sizeof *g->sink_rate);
            g->n_sink_voxels = 0;
        }
        /* a long step: the soil at its stability limit (times the safety
           factor), not at params.dt, when that is longer */
        phc_soil *s = g->soil;
        const double dt_soil = s->params.dt, absorb_dt = s->params.absorb_dt;
        if (g->o.long_step > 0 && dt >= g->o.long_step) {
            double coarse = s->params.safety * phc_soil_stable_dt(s, NULL);
            if (isfinite(coarse) && coarse > dt_soil) {
                s->params.dt = coarse;
                if (!(absorb_dt > 0)) s->params.absorb_dt = dt_soil; /* the same loss per hour */
            }
        }
        rc = phc_soil_run(s, s->t + 24.0 * dt, err);
        s->params.dt = dt_soil;
        s->params.absorb_dt = absorb_dt;
        if (rc) return phc_error_prefix(err, rc, "growth at day %g", g->age);
    }
    g->age += dt;
    return PHC_OK;
}

/* ---- outputs ------------------------------------------------------------------ */

void phc_growth_summarize(const phc_growth *g, phc_growth_summary *s)
{
    memset(s, 0, sizeof *s);
    if (!g) return;
    const phc_growth_params *p = &g->p;
    const double pi = 3.14159265358979323846;
    const double *b = g->o.base;
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        double vol = pi * n->radius * n->radius * n->length, tail[3];
        for (int k = 0; k < 3; k++) tail[k] = n->head[k] + n->length * n->dir[k];
        if (n->system == PHC_GROWTH_SHOOT) {
            s->stem_mass += p->wood_density * vol;
            s->leaf_area += n->leaf_area;
            s->shoot_nodes++;
            s->shoot_tips += n->tip;
            if (tail[2] - b[2] > s->height) s->height = tail[2] - b[2];
        } else {
            s->root_mass += p->root_density * vol;
            s->root_length += n->length;
            s->root_nodes++;
            s->root_tips += n->tip;
            if (b[2] - tail[2] > s->rooting_depth) s->rooting_depth = b[2] - tail[2];
            double h = hypot(tail[0] - b[0], tail[1] - b[1]);
            if (h > s->root_spread) s->root_spread = h;
        }
    }
    s->age = g->age;
    s->leaf_mass = p->lma * s->leaf_area;
    s->shoot_mass = s->stem_mass + s->leaf_mass;
    s->root_shoot = s->shoot_mass > 0 ? s->root_mass / s->shoot_mass : NAN;
    s->basal_diameter = g->n ? 2 * g->node[0].radius : 0;
    s->shoot_flux = g->shoot_flux;
    s->root_flux = g->root_flux;
    s->vigor = g->vigor;
    s->maintenance = g->maintenance;
    s->water_uptake = g->uptake_total;
    s->reserve = g->reserve;
    s->pruned = g->pruned;
}

phc_plant_graph *phc_growth_plant_graph(const phc_growth *g, phc_error *err)
{
    if (!g || g->n == 0) {
        phc_error_set(err, PHC_ERR_INVALID, "growth: no plant to export");
        return NULL;
    }
    size_t *map = malloc(g->n * sizeof *map), m = 0;
    if (!map) goto nomem;
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        if (n->length > 0) map[i] = m++;
        else map[i] = n->parent != PHC_GROWTH_NONE ? map[n->parent] : PHC_GROWTH_NONE;
    }
    if (m == 0 || g->node[0].length <= 0) {
        free(map);
        phc_error_set(err, PHC_ERR_INVALID, "growth: the plant has no grown segment yet");
        return NULL;
    }
    phc_plant_graph *pg = phc_plant_graph_new(m);
    if (!pg) { free(map); goto nomem; }
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        if (n->length <= 0) continue;
        size_t j = map[i];
        if (n->parent != PHC_GROWTH_NONE) pg->parent[j] = map[n->parent];
        else if (n->system == PHC_GROWTH_ROOT) pg->parent[j] = map[0];
        pg->radius[j] = n->radius > 0 ? n->radius : 1e-6;
        pg->length[j] = n->length;
        for (int k = 0; k < 3; k++) {
            pg->head[3 * j + k] = n->head[k];
            pg->tail[3 * j + k] = n->head[k] + n->length * n->dir[k];
        }
        pg->leaf[j] = n->system == PHC_GROWTH_SHOOT && n->leaf_area > 0;
        pg->source_id[j] = (long)i;
    }
    free(map);
    if (phc_plant_graph_finish(pg, "growth", err)) {
        phc_plant_graph_free(pg);
        return NULL;
    }
    return pg;
nomem:
    phc_error_set(err, PHC_ERR_NOMEM, "growth: out of memory exporting the plant graph");
    return NULL;
}

size_t phc_growth_branches(const phc_growth *g, phc_growth_system system, size_t **first,
                           size_t **parent)
{
    *first = *parent = NULL;
    if (!g || g->n == 0) return 0;
    size_t *branch = malloc(g->n * sizeof *branch);
    size_t *f = malloc(g->n * sizeof *f), *pa = malloc(g->n * sizeof *pa), nb = 0;
    if (!branch || !f || !pa) {
        free(branch); free(f); free(pa);
        return 0;
    }
    for (size_t i = 0; i < g->n; i++) {
        const phc_growth_node *n = &g->node[i];
        branch[i] = PHC_GROWTH_NONE;
        if (n->system != (unsigned char)system) continue;
        if (n->parent != PHC_GROWTH_NONE && g->node[n->parent].apical_child == i) {
            branch[i] = branch[n->parent];
            continue;
        }
        f[nb] = i;
        pa[nb] = n->parent != PHC_GROWTH_NONE ? branch[n->parent] : PHC_GROWTH_NONE;
        branch[i] = nb++;
    }
    free(branch);
    *first = f;
    *parent = pa;
    return nb;
}
