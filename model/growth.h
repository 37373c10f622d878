/* Shoot-root coordination: Rhizomorph §5 (Li et al., ACM TOG 42(4) 2023,
 * eqs. 1-24; DESIGN §5), coupled to the soil of model/soil.h.
 *
 * The plant is a hierarchical graph (§5.2):
 *   segment  one node: an internode of the shoot or a root node, a cylinder
 *            from `head` along `dir` of `length` and `radius`;
 *   branch   a chain of segments joined by apical (continuation) edges,
 *            from a lateral bud (or the base) to its tip;
 *   system   the shoot system (node 0 and below) and the root system
 *            (node 1 and below), each a tree of branches;
 *   plant    both systems joined at the root collar, the seed position.
 * Nodes are stored parents-first (a child is always appended after its
 * parent and compaction keeps the order), so a forward loop is top-down and
 * a backward loop bottom-up: every pass is O(nodes).
 *
 * Equation numbers follow the list of the paper's equations we worked from
 * (signals 1-9, vigor 10-12, propagation 13-15, potentials 16-17, pruning
 * 18, elongation 19/22, buds 20-21, roots 23-24); the paper's own formulas
 * were not at hand, so each form below is ours, written to the paper's
 * description and the authors' code (TreeModel.cpp: vigor = min of the two
 * fluxes, maintenance before development, root flux summed over root nodes).
 *
 * One step of dt days (phc_growth_step):
 *  1. organ state (eqs. 1-4): maintenance requirement M = mu * tissue volume
 *     per segment (vigor/d); growth requirement G = g per growing tip;
 *     apical-dominance inhibitor I (the shoot-competition signal, eq. 4),
 *     summed from each tip with decay exp(-distance / inhibition_distance);
 *  2. shoot flux S_F (eqs. 5-6): leaf area at every segment within
 *     leaf_distance of a shoot tip, times its light, times light_use.
 *     Light model (ours, documented): the shoot's leaf area is binned on a
 *     coarse voxel grid of light_voxel m; a segment receives
 *     light * exp(-k * (leaf area above it in its column) / voxel area),
 *     a vertical beam with self-occlusion.  The paper uses a radial bounding
 *     volume (shadow accumulated in sectors around the trunk axis) that
 *     lets light in from the sides; the column model shades more inside a
 *     dense crown and nothing from the side;
 *  3. root flux R_F (eqs. 7-9): each root segment asks for
 *     water_uptake * length * fill (m^3/d), fill = w/c of the soil at its
 *     centre; the root competition signal shares each voxel: when the
 *     segments in a voxel ask for more than uptake_cap of its water per day
 *     they get it pro rata.  R_F = water_use * sum(uptake) (vigor/d).  With
 *     uptake PHYSICAL the water is removed from the soil through its sink
 *     hook while the soil runs for the step; with NONE it is not (the
 *     authors' code reads the water and leaves it);
 *  4. plant vigor (eq. 10) V = min(R_F, S_F) + reserve release (seed
 *     reserves: reserve_rate of the remaining reserve per day);
 *  5. split (eqs. 11-12): maintenance of both systems first (pro rata when
 *     V < M, the deficit feeding pruning); the rest V_G goes to roots with
 *     weight phi_RG G_R S_F and to shoots with (1 - phi_RG) G_S R_F: the
 *     system whose resource is scarcer is fed more (functional balance),
 *     phi_RG the species' root preference; each capped at its requirement
 *     and the excess given to the other;
 *  6. propagation (eqs. 13-15): within a system, each node hands its vigor
 *     to its children in proportion to lambda * (requirement below the
 *     child), lambda = apical_dominance for the apical child and
 *     1 - apical_dominance for laterals.  With nutrient_allocation = a > 0
 *     a root tip counts in these weights as g_R * v^a, v the nutrients of
 *     the soil at it (its potential is still its vigor over g_R): root
 *     vigor flows to the tips in rich soil.  This is the authors' code
 *     (TreeModel.cpp, CalculateVigorRequirement for roots: a root tip's
 *     vigor requirement weight is its sampled nitrite times its growth
 *     potential; "more nitrite, more vigor"), with a = 1; a tip in soil
 *     without nutrients then gets no vigor, as there.  The total the root
 *     system receives does not change (the authors sum the unweighted
 *     potentials for it, so "the overall nitrite will not affect the root
 *     growth"); a = 0 is the unweighted law;
 *  7. growth potential (eqs. 16-17) P = min(1, vigor at the tip / g);
 *  8. pruning (eq. 18): a lateral shoot branch whose leaves earn less than
 *     prune_ratio times its maintenance is cut (roots are not pruned);
 *  9. elongation (eqs. 19, 22): shoot tips grow P * shoot_elongation * dt,
 *     root tips P * root_elongation * dt / (1 + root_resistance * d),
 *     d the soil's growth resistance at the tip; past a segment's length a
 *     new segment is appended;
 * 10. bud numbers (eq. 21): each new internode gets lateral_buds * P buds;
 *     bud activation (eq. 20): each dormant bud flushes with probability
 *     bud_flush * light * exp(-I) per day;
 * 11. root tropism (eq. 23): new root segments turn toward gravity (weight
 *     gravitropism_root, divided by 1 + order - 1 for laterals, which bend
 *     toward the horizontal instead) while the fill is above tropism_switch,
 *     and toward the fill gradient (hydrotropism) below it;
 *     root branching (eq. 24): each new root segment starts a lateral root
 *     with probability root_branching * P * min(1, fill) *
 *     (1 + nutrient_branching * v), v the soil nutrients there (so roots
 *     proliferate in rich patches: the split-root response of Fig. 16);
 * 12. radii (pipe model, Shinozaki 1964): r_i^a = sum over the segments j
 *     at and above i of r_tip^a * length_j / segment length, a =
 *     pipe_exponent: each segment adds a pipe, so stems thicken as the plant
 *     above them grows, continuously in time; radii never shrink (pipes of
 *     pruned branches stay).  Root tips stop at the faces of the soil box
 *     (a step's growth is cut to the tip's distance to the face).
 *
 * Randomness: STOCHASTIC draws angles, bud flushes and root branching from
 * a seeded xoshiro256** generator (same seed => same plant).  EXPECTED
 * replaces every draw by its expectation: angular noise is 0, the roll of
 * each new branch follows the golden angle (137.5 deg per bud), and events
 * accumulate their probabilities and happen when the sum reaches 1.  The
 * expected plant changes smoothly with the parameters, which is what a
 * least-squares calibration needs.
 *
 * Units: lengths m, time d (the soil runs in h: 24 h per day), angles deg,
 * vigor in arbitrary vigor units per day (vigor/d), masses g (dry), leaf
 * area m^2.  Coordinates are the soil's grid frame (z up).  No I/O. */
#ifndef PHC_GROWTH_H
#define PHC_GROWTH_H

#include <stddef.h>
#include <stdint.h>

#include "model/plant_graph.h"
#include "model/soil.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PHC_GROWTH_NONE ((size_t)-1)

typedef enum phc_growth_system { PHC_GROWTH_SHOOT = 0, PHC_GROWTH_ROOT = 1 } phc_growth_system;
typedef enum phc_growth_mode { PHC_GROWTH_EXPECTED = 0, PHC_GROWTH_STOCHASTIC } phc_growth_mode;
typedef enum phc_growth_uptake { PHC_GROWTH_UPTAKE_PHYSICAL = 0, PHC_GROWTH_UPTAKE_NONE } phc_growth_uptake;

/* Species parameters (the presets hold our values for the species of
 * Table 4; see growth.c).  Every number
 * must be finite; phc_growth_check names the first one out of range. */
typedef struct phc_growth_params {
    /* shoot */
    double internode_length;    /* m, > 0 */
    double shoot_elongation;    /* m/d at P = 1, >= 0 */
    double apical_angle;        /* deg, mean turn of an apical child, >= 0 */
    double branching_angle;     /* deg, lateral bud angle, >= 0 */
    double angle_sd;            /* deg, random angular noise (STOCHASTIC), >= 0 */
    double apical_dominance;    /* lambda in [0, 1] (eqs. 13-15) */
    double lateral_buds;        /* buds per new internode at P = 1 (eq. 21), >= 0 */
    double bud_flush;           /* 1/d, flush probability in full light (eq. 20), >= 0 */
    double apical_inhibition;   /* inhibitor of one tip (eq. 4), >= 0 */
    double inhibition_distance; /* m, > 0 */
    double phototropism;        /* [0, 1], turn toward up per segment */
    double prune_ratio;         /* eq. 18, >= 0 (0 = never prune) */
    double leaf_area;           /* m^2 per leaf-bearing internode, >= 0 */
    double leaf_distance;       /* m from a shoot tip within which internodes bear leaves, >= 0 */
    double lma;                 /* g/m^2 leaf mass per area, >= 0 */
    double light_extinction;    /* k, dimensionless, >= 0 */
    double light_voxel;         /* m, > 0 */
    double light;               /* relative irradiance, [0, 1] */
    double light_use;           /* vigor per m^2 leaf per day in full light, >= 0 */
    /* root */
    double root_node_length;    /* m, > 0 */
    double root_elongation;     /* m/d at P = 1, >= 0 */
    double root_apical_angle;   /* deg, >= 0 */
    double root_branching_angle;/* deg, >= 0 */
    double root_apical_dominance; /* [0, 1] */
    double root_branching;      /* eq. 24 probability scale per new segment, >= 0 */
    double gravitropism_root;   /* [0, 1] turn toward down per segment (main root) */
    double hydrotropism;        /* [0, 1] turn toward wetter soil below the switch */
    double tropism_switch;      /* fill w/c below which roots follow water (eq. 23), >= 0 */
    double nutrient_branching;  /* eq. 24: branching x (1 + this * v), v the soil nutrients
                                   (units/m^3) at the segment; m^3/unit, >= 0 */
    double nutrient_allocation; /* step 6: a root tip's weight in the propagation is its
                                   requirement x v^this (v its soil nutrients); 0 = off
                                   (the presets), 1 = the authors' code; >= 0 */
    double water_uptake;        /* m^3 water per m root per day at fill 1, >= 0 */
    double uptake_cap;          /* fraction of a voxel's water taken per day at most, (0, 1] */
    double water_use;           /* vigor per m^3 water, >= 0 */
    double root_resistance;     /* multiplies the soil's growth resistance d (eq. 22), >= 0 */
    double soil_fill;           /* fill w/c used when the plant has no soil, >= 0 */
    /* both systems */
    double tip_radius_shoot;    /* m, > 0 */
    double tip_radius_root;     /* m, > 0 */
    double pipe_exponent;       /* a, > 0 (2 = da Vinci) */
    double maintenance_shoot;   /* vigor per m^3 tissue per day, >= 0 */
    double maintenance_root;    /* vigor per m^3 tissue per day, >= 0 */
    double growth_shoot;        /* g: vigor a shoot tip needs per day at P = 1, > 0 */
    double growth_root;         /* vigor a root tip needs per day at P = 1, > 0 */
    double phi_rg;              /* phi_RG, root growth preference, [0, 1] (eq. 12) */
    double wood_density;        /* g/m^3 dry stem tissue, >= 0 */
    double root_density;        /* g/m^3 dry root tissue, >= 0 */
    double seed_reserve;        /* vigor in the seed at t = 0, >= 0 */
    double reserve_rate;        /* 1/d, fraction of the remaining reserve released daily, [0, 1] */
} phc_growth_params;

/* The parameters' names in struct order, for configs and messages; the
 * offsets let a caller set a parameter by name. */
size_t phc_growth_param_count(void);
const char *phc_growth_param_name(size_t i);
double *phc_growth_param_ref(phc_growth_params *p, size_t i);
/* Index of a parameter by name, or -1. */
long phc_growth_param_find(const char *name);

/* Species presets (the species of Rhizomorph Table 4, with our values): "oak", "cherry", "apple",
 * "poplar", "maple".  Case is ignored.  PHC_ERR_INPUT naming the known
 * presets for another name. */
int phc_growth_preset(const char *name, phc_growth_params *p, phc_error *err);
const char *phc_growth_preset_name(size_t i); /* NULL past the end */

/* Which preset describes a species, by its genus (the first word of the
 * name, case ignored): Quercus "oak", Prunus "cherry", Malus "apple",
 * Populus "poplar", Acer "maple"; NULL for every other genus.  *group (may
 * be NULL) gets a word for the genus: the preset's genus, "conifer" for the
 * conifer genera no preset describes (Pinaceae: Pinus, Picea, Abies,
 * Pseudotsuga, Larix, Tsuga, Cedrus; Cupressaceae: Chamaecyparis,
 * Cryptomeria, Cupressus, Juniperus, Thuja, Sequoia, Taxodium,
 * Metasequoia; Taxaceae: Taxus; Podocarpaceae: Podocarpus; Araucariaceae:
 * Agathis, Araucaria), or "other".  A genus is not called tropical: that
 * is a property of where a plant grows, not of its name. */
const char *phc_growth_preset_for_species(const char *species, const char **group);

/* Domain checks: PHC_ERR_INPUT "growth parameter 'x': must be ..., found v". */
int phc_growth_check(const phc_growth_params *p, phc_error *err);

typedef struct phc_growth_options {
    phc_growth_mode mode;       /* default EXPECTED */
    uint64_t seed;              /* STOCHASTIC only; default 1 */
    phc_growth_uptake uptake;   /* default PHYSICAL */
    double base[3];             /* m, seed position in the soil frame; default (0, 0, 0) */
    size_t max_nodes;           /* refuse to grow past this many nodes; 0 = 10 million */
    double long_step;           /* d: a step this long or longer runs its soil at soil.params.safety x
                                   the soil's stability limit when that exceeds soil.params.dt
                                   (phc_growth_step); 0 = never; default 7 */
} phc_growth_options;
phc_growth_options phc_growth_options_default(void);

/* One segment (Table 1).  Read-only for callers. */
typedef struct phc_growth_node {
    size_t parent;              /* PHC_GROWTH_NONE for the two system bases */
    size_t apical_child;        /* the continuation, or PHC_GROWTH_NONE */
    unsigned char system;       /* phc_growth_system */
    unsigned char tip;          /* 1: a growing apex (no apical child yet) */
    unsigned short order;       /* branch order: 1 for the main axis */
    double head[3];             /* m, start (the end nearer the collar) */
    double dir[3];              /* unit direction head -> tail */
    double length;              /* m */
    double radius;              /* m */
    double birth;               /* d, when the segment appeared */
    double branch_length;       /* m, from the start of its branch to its tail */
    double roll;                /* deg, the branch's roll around its parent */
    double buds;                /* dormant lateral buds (fractional in EXPECTED mode) */
    double flush_sum;           /* EXPECTED: accumulated flush probability */
    double branch_sum;          /* EXPECTED: accumulated root branching probability */
    double light;               /* relative light at the segment, [0, 1] */
    double fill;                /* soil fill w/c at a root segment */
    double resistance;          /* soil growth resistance d at a root segment */
    double nutrient;            /* soil nutrients v at a root segment, units/m^3 */
    double uptake;              /* m^3/d of water taken (root) */
    double leaf_area;           /* m^2 (shoot) */
    double inhibitor;           /* apical-dominance signal I */
    double requirement;         /* growth requirement of the subtree, vigor/d */
    double vigor;               /* growth vigor received this step, vigor/d */
    double potential;           /* P at a tip, in [0, 1] */
} phc_growth_node;

/* Totals after a step. */
typedef struct phc_growth_summary {
    double age;                 /* d */
    double shoot_mass;          /* g: stem + leaves */
    double stem_mass, leaf_mass, root_mass; /* g */
    double root_shoot;          /* root_mass / shoot_mass */
    double basal_diameter;      /* m, 2 r of the shoot base */
    double height;              /* m, highest shoot point above the base */
    double rooting_depth;       /* m, deepest root point below the base */
    double root_spread;         /* m, largest horizontal distance of a root point from the base */
    double leaf_area;           /* m^2 */
    double root_length;         /* m */
    double shoot_flux, root_flux, vigor; /* S_F, R_F, V (vigor/d) */
    double maintenance;         /* M_S + M_R (vigor/d) */
    double water_uptake;        /* m^3/d */
    double reserve;             /* vigor left in the seed */
    size_t shoot_nodes, root_nodes, shoot_tips, root_tips, pruned;
} phc_growth_summary;

typedef struct phc_growth phc_growth; /* opaque */

/* A seedling at opts->base: a shoot internode going up and a root segment
 * going down, each of a tenth of its segment length.  `soil` is borrowed
 * (may be NULL: fill = soil_fill, no resistance) and must outlive the
 * plant; with PHYSICAL uptake the plant installs its sink hook on it.
 * Errors: PHC_ERR_INPUT for parameters out of range (named) or a base
 * outside the soil grid ("the plant is seeded at (x, y, z) m, outside the
 * soil grid [x0, x1] x [y0, y1] x [z0, z1] m"). */
int phc_growth_new(const phc_growth_params *p, const phc_growth_options *o, phc_soil *soil,
                   phc_growth **out, phc_error *err);
void phc_growth_free(phc_growth *g); /* removes its sink hook; accepts NULL */

/* Advances dt days (> 0): the steps above, then the soil for 24 dt hours.
 * With dt >= options.long_step the soil's step is, for this call only,
 * params.safety (0.9) x its stability limit (phc_soil_stable_dt) when that
 * is longer than params.dt: a month-long step is then 5-7x faster on the
 * bench plant (README, Speed, "The growth model", for what it changes).
 * PHC_ERR_DOMAIN when max_nodes would be exceeded or the soil fails. */
int phc_growth_step(phc_growth *g, double dt, phc_error *err);

void phc_growth_summarize(const phc_growth *g, phc_growth_summary *s);
const phc_growth_node *phc_growth_nodes(const phc_growth *g, size_t *n);
const phc_growth_params *phc_growth_parameters(const phc_growth *g);

/* The whole plant as a plant graph (lengths in m): the first shoot segment
 * (whose head is the root collar) is the graph's root, the root system's
 * first segment hangs from it (sharing its head, the collar), leaf-bearing internodes are
 * flagged leaf.  Zero-length tips are left out.  NULL when out of memory
 * (err says so) or the plant is empty. */
phc_plant_graph *phc_growth_plant_graph(const phc_growth *g, phc_error *err);

/* Branch decomposition of one system, for RSML export and plots: branch b
 * runs through nodes first[b], its apical chain, to its tip; parent[b] is
 * the branch holding the start node's parent (PHC_GROWTH_NONE for the
 * system's main axis).  Arrays are malloc'd (free them); returns the count
 * or 0 with *first = *parent = NULL when out of memory. */
size_t phc_growth_branches(const phc_growth *g, phc_growth_system system, size_t **first,
                           size_t **parent);

#ifdef __cplusplus
}
#endif

#endif /* PHC_GROWTH_H */
