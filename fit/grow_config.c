/* The configuration of `phytocal grow`: see grow_config.h. */
#include "fit/grow_config.h"

#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/yaml_keys.h"
#include "measurements/yaml_doc.h"

typedef enum key_type { K_NUM, K_SIZE, K_UINT, K_U64, K_VEC, K_BOOL, K_WORD } key_type;


/* One key: where it goes (offset into phc_grow_config), its range
 * [lo, hi] (open ends where said), unit and meaning. */
typedef struct key_spec {
    const char *section; /* NULL: top level */
    const char *key;
    key_type type;
    size_t offset;
    double lo, hi;
    int lo_open, hi_open;
    const char *unit, *help;
} key_spec;

#define OPT(f) (offsetof(phc_grow_config, options) + offsetof(phc_climbing_options, f))
#define CFG(f) offsetof(phc_grow_config, f)
#define INF HUGE_VAL

static const key_spec KEYS[] = {
    {NULL, "seed", K_U64, OPT(seed), 0, 9.2e18, 0, 0, "", "random seed: the same seed gives the same plant"},
    {NULL, "duration", K_NUM, CFG(duration), 0, INF, 1, 1, "s", "time grown"},
    {NULL, "time_step", K_NUM, CFG(time_step), 0, INF, 1, 1, "s",
     "growth step; growth_rate*time_step < 1 - bud_fraction"},
    {NULL, "frame_interval", K_NUM, CFG(frame_interval), 0, INF, 1, 1, "s",
     "time between the frames written (frame 0 is the seed; the last frame is at duration)"},
    {"plant", "position", K_VEC, CFG(position), -INF, INF, 1, 1, "m", "base of the seed particle"},
    {"plant", "direction", K_VEC, CFG(direction), -INF, INF, 1, 1, "",
     "its growth direction (any non-zero length)"},
    {"growth", "max_length", K_NUM, OPT(max_length), 0, INF, 1, 1, "m", "L_max: length of a grown internode"},
    {"growth", "bud_fraction", K_NUM, OPT(bud_fraction), 0, 1, 1, 1, "", "sigma_0: size of a new internode / L_max"},
    {"growth", "growth_rate", K_NUM, OPT(growth_rate), 0, INF, 0, 1, "s-1", "r: d(sigma)/dt in full light (sec. 4.2)"},
    {"growth", "apical_dominance", K_NUM, OPT(apical_dominance), 0, 1, 1, 0, "",
     "a: a tip of branch order k grows at growth_rate*a^k (1: no dominance)"},
    {"growth", "radius", K_NUM, OPT(radius), 0, INF, 1, 1, "m", "radius of the main axis"},
    {"growth", "max_particles", K_SIZE, OPT(max_particles), 1, 1e8, 0, 0, "", "growth stops at this many"},
    {"branching", "probability", K_NUM, OPT(branch_probability), 0, 1, 0, 0, "",
     "BP: chance that a lateral bud becomes a shoot (sec. 4.3)"},
    {"branching", "buds", K_UINT, OPT(max_buds), 0, 64, 0, 0, "", "B: lateral buds per node"},
    {"branching", "variance", K_NUM, OPT(direction_variance), 0, 1, 0, 0, "",
     "V: laterals leave their parent at up to V*90 degrees"},
    {"branching", "thickness_falloff", K_NUM, OPT(thickness_falloff), 0, 1, 1, 0, "",
     "f: a lateral's radius is f times its parent's"},
    {"branching", "max_order", K_UINT, OPT(max_order), 0, 1000, 0, 0, "", "nodes of this order bear no laterals"},
    {"light", "direction", K_VEC, OPT(light.direction), -INF, INF, 1, 1, "",
     "toward the light (any non-zero length); also phototropism's target"},
    {"light", "extinction", K_NUM, OPT(light.extinction), 0, INF, 0, 1, "m-1",
     "lambda: Beer-Lambert extinction per unit volume fraction of plant (0: no self-shading)"},
    {"light", "cell", K_NUM, OPT(light.cell), 0, INF, 1, 1, "m", "edge of a light-grid cell"},
    {"light", "origin", K_VEC, OPT(light.origin), -INF, INF, 1, 1, "m",
     "lowest corner of the light grid (with size; default: the support's box widened by 0.25 m)"},
    {"light", "size", K_VEC, CFG(light_size), 0, INF, 1, 1, "m", "extent of the light grid (with origin)"},
    {"light", "ambient", K_NUM, OPT(light.ambient), 0, 1, 0, 0, "",
     "a: diffuse share of the light that reaches shadowed points too (I = a + (1-a) T)"},
    {"light", "spread", K_NUM, OPT(light_spread_deg), 0, 89, 0, 0, "deg",
     "with seek_light: the light field's sky is the light direction and six directions this far from it"},
    {"light", "supports_cast_shadows", K_BOOL, CFG(shadows), 0, 1, 0, 0, "",
     "the support mesh blocks the direct light (exact ray/triangle test)"},
    {"leaves", "step", K_UINT, OPT(leaf_step), 0, 1000, 0, 0, "",
     "every step-th node of a shoot bears a leaf (0: no leaves)"},
    {"leaves", "angle", K_NUM, OPT(leaf_angle_deg), 0, 360, 0, 0, "deg",
     "alpha: divergence angle between successive leaves (137.5: golden angle)"},
    {"leaves", "size", K_NUM, OPT(leaf_size), 0, INF, 1, 1, "m", "s: side of the square blade"},
    {"leaves", "thickness", K_NUM, OPT(leaf_thickness), 0, INF, 0, 1, "m",
     "a leaf shades the light grid as a volume s^2*thickness (0: leaves cast no shade)"},
    {"leaves", "response", K_NUM, OPT(leaf_response), 0, 1, 0, 0, "",
     "omega: a blade in light I turns by omega*I toward the light direction"},
    {"leaves", "max_angle", K_NUM, OPT(leaf_max_angle_deg), 0, 180, 0, 0, "deg",
     "largest turn of a blade from its default normal (the stem direction)"},
    {"cambium", "rate", K_NUM, OPT(cambium_rate), 0, INF, 0, 1, "s-1",
     "kappa: radii relax toward the pipe model's at this rate (0: no secondary growth)"},
    {"cambium", "leaf_area", K_NUM, OPT(leaf_pipe_area), 0, INF, 0, 1, "m2",
     "a_L: cross-section each leaf adds to the stem below it"},
    {"tropisms", "phototropism", K_NUM, OPT(phototropism), 0, INF, 0, 1, "s-1",
     "eta: turning rate of tips toward the light (eq. 7)"},
    {"tropisms", "seek_light", K_BOOL, OPT(seek_light), 0, 1, 0, 0, "",
     "phototropism turns toward the gradient of the light field (around obstacles, toward gaps) "
     "instead of the fixed light direction"},
    {"tropisms", "light_gradient_threshold", K_NUM, OPT(light_gradient_threshold), 0, INF, 0, 1, "",
     "with seek_light: a change of the light below this over one cell counts as no direction"},
    {"tropisms", "surface_adaption", K_NUM, OPT(surface_adaption), 0, INF, 0, 1, "s-1",
     "tau: turning rate of tips toward / along the closest support (eq. 6)"},
    {"tropisms", "adaption_radius", K_NUM, OPT(adaption_radius), 0, INF, 0, 1, "m",
     "supports farther from a tip do not attract it"},
    {"tropisms", "contact_distance", K_NUM, OPT(contact_distance), 0, INF, 0, 1, "m",
     "within it a tip crawls along the support"},
    {"tropisms", "keep_outside", K_BOOL, OPT(keep_outside), 0, 1, 0, 0, "",
     "a tip behind its closest support face turns out of it (no growth through a wall's edges)"},
    {"anchors", "attach_distance", K_NUM, OPT(attach_distance), 0, INF, 0, 1, "m",
     "a particle this close to a support anchors (eq. 5; 0: no anchors)"},
    {"anchors", "release_distance", K_NUM, OPT(release_distance), 0, INF, 1, 1, "m",
     "an anchor lets go beyond it; > attach_distance"},
    {"anchors", "strength", K_NUM, OPT(anchor_strength), 0, 1, 1, 0, "", "k_max: full anchor strength"},
    {"anchors", "time", K_NUM, OPT(anchor_time), 0, INF, 1, 1, "s", "time for an anchor to reach full strength"},
    {"dynamics", "substeps", K_SIZE, OPT(dynamics_substeps), 0, 1000, 0, 0, "",
     "particle-dynamics steps per growth step (0: kinematic, no gravity)"},
    {"dynamics", "maturity_age", K_NUM, OPT(particles.maturity_age), 0, INF, 1, 1, "s",
     "t_m: stiffness s = min(1, age/t_m) rises with age"},
    {"dynamics", "min_stiffness", K_NUM, OPT(min_stiffness), 0, 1, 0, 0, "", "s_min: floor of the stiffness"},
    {"dynamics", "gravity", K_VEC, OPT(particles.gravity), -INF, INF, 1, 1, "m s-2", "gravity"},
    {"dynamics", "iterations", K_SIZE, OPT(particles.iterations), 1, 1000, 0, 0, "",
     "shape-matching projections per substep"},
    {"dynamics", "damping", K_NUM, OPT(particles.damping), 0, 1, 0, 1, "", "fraction of velocity removed per substep"},
    {"dynamics", "collide", K_BOOL, OPT(collide), 0, 1, 0, 0, "",
     "every particle (but the seed's) is pushed out of the support to its radius along the surface normal, "
     "in each dynamics substep or, kinematic, after each growth step (no effect without a support)"},
    {"dynamics", "collide_ends", K_BOOL, OPT(collide_ends), 0, 1, 0, 0, "",
     "with collide, kinematic plants (substeps 0) only: each segment's two ends are pushed out too and its centre and "
     "direction rebuilt from them (whole segments out of the support)"},
    {"dynamics", "collide_segments", K_BOOL, OPT(collide_segments), 0, 1, 0, 0, "",
     "with collide and substeps: each segment in contact is also pushed off at its deepest point (its point closest "
     "to a support edge), so no straight segment cuts a convex edge between its pushed ends (model/particles.h)"},
    {"dynamics", "supports_closed", K_BOOL, OPT(supports_closed), 0, 1, 0, 0, "",
     "the support is a closed surface with outward faces (a solid's boundary): with collide and substeps, a point "
     "farther from the support than its radius plus how far it moved since its last query is not queried (exact; "
     "wrong on an open sheet, whose back side reads as inside; model/particles.h)"},
    {"dynamics", "follow_parent", K_BOOL, OPT(particles.follow_parent), 0, 1, 0, 0, "",
     "after the projections every particle hangs from a joint on its parent, an angular spring: s = 1 keeps the rest "
     "shape, s < 1 lets a link bend down under its load (model/particles.h)"},
    {"dynamics", "stiffness_step", K_NUM, OPT(particles.stiffness_step), 0, INF, 1, 1, "s",
     "T: the substep at which follow_parent's joint turns by the fraction s toward its rest angle"},
    {"dynamics", "bending", K_WORD, OPT(particles.bending), 0, 0, 0, 0, "",
     "follow_parent's load: own_weight (each link turns under its own weight, creeping to rest) or beam (each "
     "link under the moment of its whole subtree, on a spring of stiffness E I / L, swinging; model/particles.h)"},
    {"dynamics", "beam_modulus", K_NUM, OPT(particles.beam_modulus), 0, INF, 1, 1, "Pa",
     "E_1/2: with bending beam, the Young's modulus of a link of stiffness s = 1/2 (E = E_1/2 s/(1 - s))"},
    {"dynamics", "break_threshold", K_NUM, OPT(particles.break_threshold), 0, INF, 0, 1, "",
     "a link whose group stress (the misfit to its best rigid motion) passes it breaks and the shoot below falls "
     "(0: no breaking; model/climbing_breaking.h)"},
    {"dynamics", "break_stress", K_NUM, OPT(particles.break_stress), 0, INF, 0, 1, "Pa",
     "with bending beam: a link whose joint's bending stress 4M/(pi r^3) (M its spring's moment) passes this "
     "modulus of rupture breaks and the shoot below falls (0: off; not with break_threshold; model/particles.h)"},
    {"dynamics", "anchors_carry_moment", K_BOOL, OPT(particles.anchors_carry_moment), 0, 1, 0, 0, "",
     "with bending beam: an anchored particle is held by its support and carries the moment of what lies beyond "
     "it (its joint to its parent carries none; model/particles.h)"},
    {"dynamics", "fall_time", K_NUM, OPT(fall_time), 0, INF, 0, 1, "s",
     "a broken piece falls this long as free particles, then leaves the plant"},
    {"dynamics", "resprout_delay", K_NUM, OPT(resprout_delay), 0, INF, 0, 1, "s",
     "a stump left without a shoot by a break grows a new tip at its top this long after the break (inf, the "
     "default: never; model/climbing_breaking.h)"},
};
#define N_KEYS (sizeof KEYS / sizeof KEYS[0])

static const char *const SECTIONS[] = {"plant", "growth", "branching", "light", "tropisms", "anchors", "dynamics",
                                       "leaves", "cambium", NULL};
static const char *const TOP_KEYS[] = {"name",   "support", "seed",      "duration", "time_step", "frame_interval",
                                       "plant",  "growth",  "branching", "light",    "tropisms",  "anchors",
                                       "dynamics", "leaves", "cambium", NULL};

/* The words of a K_WORD key (its value is stored as the word's index, an
 * int), NULL-ended. */
static const char *const BENDING_WORDS[] = {"own_weight", "beam", NULL}; /* PHC_PARTICLES_OWN_WEIGHT, _BEAM */
static const struct {
    size_t offset;
    const char *const *words;
} WORD_KEYS[] = {{OPT(particles.bending), BENDING_WORDS}};

static const char *const *key_words(const key_spec *k)
{
    for (size_t i = 0; i < sizeof WORD_KEYS / sizeof WORD_KEYS[0]; ++i)
        if (WORD_KEYS[i].offset == k->offset)
            return WORD_KEYS[i].words;
    return NULL;
}

static void range_text(const key_spec *k, char *buf, size_t size)
{
    char lo[24], hi[24];
    if (k->type == K_BOOL) {
        snprintf(buf, size, "true or false");
        return;
    }
    if (k->type == K_WORD) {
        const char *const *words = key_words(k);
        size_t used = 0;
        buf[0] = 0;
        for (size_t w = 0; words[w] && used < size; ++w)
            used += (size_t)snprintf(buf + used, size - used, "%s%s", w ? (words[w + 1] ? ", " : " or ") : "",
                                     words[w]);
        return;
    }
    if (isinf(k->lo))
        snprintf(lo, sizeof lo, "-inf");
    else
        snprintf(lo, sizeof lo, "%g", k->lo);
    if (isinf(k->hi))
        snprintf(hi, sizeof hi, "inf");
    else
        snprintf(hi, sizeof hi, "%g", k->hi);
    snprintf(buf, size, "%c%s, %s%c", k->lo_open ? '(' : '[', lo, hi, k->hi_open ? ')' : ']');
}

static int in_range(const key_spec *k, double v)
{
    return isfinite(v) && (k->lo_open ? v > k->lo : v >= k->lo) && (k->hi_open ? v < k->hi : v <= k->hi);
}

static void full_name(const key_spec *k, char *buf, size_t size)
{
    if (k->section)
        snprintf(buf, size, "%s.%s", k->section, k->key);
    else
        snprintf(buf, size, "%s", k->key);
}

/* Reads one key's value from its mapping into c. */
static int read_key(const phc_yaml_doc *doc, const phc_yaml_node *map, const key_spec *k, phc_grow_config *c,
                    phc_error *err)
{
    const phc_yaml_node *v = phc_yaml_get(map, k->key);
    if (!v)
        return PHC_OK;
    char name[64], range[96];
    full_name(k, name, sizeof name);
    range_text(k, range, sizeof range);
    const size_t line = phc_key_line(map, k->key);
    char *field = (char *)c + k->offset;
    int rc;
    if (k->type == K_VEC) {
        if (v->kind != PHC_YAML_SEQUENCE || v->count != 3)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: expected a list of three numbers [x, y, z]%s%s",
                                 doc->path, line, name, k->unit[0] ? ", in " : "", k->unit);
        double x[3];
        for (int i = 0; i < 3; ++i) {
            if ((rc = phc_yaml_number(doc, v->items[i], name, &x[i], err)))
                return rc;
            if (!in_range(k, x[i]))
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: component %d = %g is outside %s%s%s", doc->path,
                                     line, name, i + 1, x[i], range, k->unit[0] ? " " : "", k->unit);
        }
        memcpy(field, x, sizeof x);
        return PHC_OK;
    }
    if (k->type == K_BOOL) {
        int b;
        if ((rc = phc_yaml_boolean(doc, v, name, &b, err)))
            return rc;
        *(int *)field = b;
        return PHC_OK;
    }
    if (k->type == K_WORD) {
        const char *word;
        if ((rc = phc_yaml_string(doc, v, name, &word, err)))
            return rc;
        const char *const *words = key_words(k);
        for (int w = 0; words[w]; ++w)
            if (strcmp(word, words[w]) == 0) {
                *(int *)field = w;
                return PHC_OK;
            }
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: '%s' is not one of %s", doc->path, line, name, word,
                             range);
    }
    double x;
    if (k->type == K_NUM) {
        if ((rc = phc_yaml_number(doc, v, name, &x, err)))
            return rc;
    } else {
        long n;
        if ((rc = phc_yaml_integer(doc, v, name, &n, err)))
            return rc;
        x = (double)n;
    }
    if (!in_range(k, x))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s = %g is outside %s%s%s%s", doc->path, line, name, x,
                             range, k->unit[0] ? " " : "", k->unit,
                             strcmp(name, "branching.variance") == 0 ? " (1 means 90 degrees)" : "");
    switch (k->type) {
    case K_NUM: *(double *)field = x; break;
    case K_SIZE: *(size_t *)field = (size_t)x; break;
    case K_UINT: *(unsigned *)field = (unsigned)x; break;
    case K_U64: *(uint64_t *)field = (uint64_t)x; break;
    case K_VEC:
    case K_BOOL:
    case K_WORD: break;
    }
    return PHC_OK;
}

static int nonzero(const double v[3])
{
    return v[0] != 0 || v[1] != 0 || v[2] != 0;
}

void phc_grow_config_free(phc_grow_config *c)
{
    if (!c)
        return;
    free(c->name);
    free(c->source);
    free(c->support);
    free(c->seed_text);
    free(c);
}

static char *stem_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *b = slash ? slash + 1 : path;
    const char *dot = strrchr(b, '.');
    const size_t n = dot && dot != b ? (size_t)(dot - b) : strlen(b);
    char *s = malloc(n + 1);
    if (s) {
        memcpy(s, b, n);
        s[n] = '\0';
    }
    return s;
}

static int plain_name(const char *name)
{
    size_t len = strlen(name);
    int ok = len > 0 && len <= 100 && name[0] != '.';
    for (size_t i = 0; ok && i < len; ++i) {
        const char ch = name[i];
        ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '.' ||
             ch == '-' || ch == '_';
    }
    return ok;
}

int phc_grow_config_load(const char *path, phc_grow_config **out, phc_error *err)
{
    *out = NULL;
    phc_yaml_doc *doc = NULL;
    int rc = phc_yaml_load(path, &doc, err);
    if (rc)
        return rc;
    phc_grow_config *c = calloc(1, sizeof *c);
    char *dir_copy = strdup(path);
    if (!c || !dir_copy || !(c->source = strdup(path))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    const phc_yaml_node *root = doc->root;
    if (!root || root->kind != PHC_YAML_MAPPING) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: a grow config is a mapping of keys (name, support, plant, ...)",
                           path, root ? root->line : (size_t)1);
        goto fail;
    }
    if ((rc = phc_yaml_check_keys(doc, root, TOP_KEYS, "grow config", err)))
        goto fail;
    c->options = phc_climbing_options_default();
    c->direction[2] = 1;
    c->duration = 60;
    c->time_step = 0.25;
    c->frame_interval = 10;
    c->shadows = 1;
    /* name */
    const char *name = NULL;
    if ((rc = phc_yaml_map_string(doc, root, "name", 0, "grow config", &name, err)))
        goto fail;
    if (name && !plain_name(name)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: name: '%s' is not a plain name: it names the folder runs/<name>/, so use 1 to 100 "
                           "letters, digits, '.', '-' and '_', not starting with '.' (or give -o DIR)",
                           path, phc_key_line(root, "name"), name);
        goto fail;
    }
    if (!(c->name = name ? strdup(name) : stem_of(path))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    /* support, relative to the config's folder */
    const char *support = NULL;
    if ((rc = phc_yaml_map_string(doc, root, "support", 0, "grow config", &support, err)))
        goto fail;
    if (support) {
        const char *base = dirname(dir_copy);
        const size_t n = strlen(base) + strlen(support) + 2;
        if (!(c->support = malloc(n))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        if (support[0] == '/' || strcmp(base, ".") == 0)
            snprintf(c->support, n, "%s", support);
        else
            snprintf(c->support, n, "%s/%s", base, support);
        c->support_line = phc_key_line(root, "support");
        FILE *f = fopen(c->support, "rb");
        if (!f) {
            rc = phc_error_set(err, PHC_ERR_IO, "%s:%zu: support: %s: cannot open: %s", path, c->support_line,
                               c->support, strerror(errno));
            goto fail;
        }
        fclose(f);
    }
    /* sections: each a mapping of known keys */
    for (size_t s = 0; SECTIONS[s]; ++s) {
        const phc_yaml_node *sec = phc_yaml_get(root, SECTIONS[s]);
        if (!sec)
            continue;
        if (sec->kind != PHC_YAML_MAPPING) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: expected a mapping of keys", path,
                               phc_key_line(root, SECTIONS[s]), SECTIONS[s]);
            goto fail;
        }
        const char *allowed[N_KEYS + 1]; /* (a section may hold every key) */
        size_t na = 0;
        for (size_t i = 0; i < N_KEYS; ++i)
            if (KEYS[i].section && strcmp(KEYS[i].section, SECTIONS[s]) == 0)
                allowed[na++] = KEYS[i].key;
        allowed[na] = NULL;
        if ((rc = phc_yaml_check_keys(doc, sec, allowed, SECTIONS[s], err)))
            goto fail;
    }
    for (size_t i = 0; i < N_KEYS; ++i) {
        const phc_yaml_node *map = KEYS[i].section ? phc_yaml_get(root, KEYS[i].section) : root;
        if (map && (rc = read_key(doc, map, &KEYS[i], c, err)))
            goto fail;
    }
    /* cross-key checks, each at the line of the key it names */
    const phc_yaml_node *plant = phc_yaml_get(root, "plant");
    if (!plant || !phc_yaml_get(plant, "position")) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: plant: missing key 'position' (the seed's base [x, y, z], m)",
                           path, plant ? plant->line : root->line);
        goto fail;
    }
    c->position_line = phc_key_line(plant, "position");
    if (!nonzero(c->direction)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: plant.direction: must not be (0, 0, 0)", path,
                           phc_key_line(plant, "direction"));
        goto fail;
    }
    const phc_yaml_node *light = phc_yaml_get(root, "light");
    if (!nonzero(c->options.light.direction)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: light.direction: must not be (0, 0, 0)", path,
                           phc_key_line(light, "direction"));
        goto fail;
    }
    const int has_origin = light && phc_yaml_get(light, "origin"), has_size = light && phc_yaml_get(light, "size");
    if (has_origin != has_size) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: light: give both 'origin' and 'size' of the light grid, or "
                           "neither", path, light->line);
        goto fail;
    }
    c->light_grid_given = has_origin;
    const phc_climbing_options *o = &c->options;
    if (!(o->growth_rate * c->time_step < 1 - o->bud_fraction)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: time_step: growth_rate * time_step = %g must be below 1 - bud_fraction = %g "
                           "(a tip may spawn at most one internode per step)",
                           path, phc_key_line(root, "time_step"), o->growth_rate * c->time_step, 1 - o->bud_fraction);
        goto fail;
    }
    if (!(o->release_distance > o->attach_distance)) {
        const phc_yaml_node *an = phc_yaml_get(root, "anchors");
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: anchors.release_distance = %g m must exceed attach_distance = %g m", path,
                           !an ? root->line
                           : phc_yaml_get(an, "release_distance") ? phc_key_line(an, "release_distance")
                                                                  : phc_key_line(an, "attach_distance"), o->release_distance,
                           o->attach_distance);
        goto fail;
    }
    const phc_yaml_node *dyn = phc_yaml_get(root, "dynamics");
    const int beam = o->particles.follow_parent && o->particles.bending == PHC_PARTICLES_BEAM;
    if (o->particles.break_stress > 0 && !beam) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: dynamics.break_stress = %g Pa needs dynamics.bending: beam with follow_parent "
                           "(the %s pass has no bending moment)",
                           path, phc_key_line(dyn, "break_stress"), o->particles.break_stress,
                           o->particles.follow_parent ? "own_weight" : "no joint");
        goto fail;
    }
    if (o->particles.break_stress > 0 && o->particles.break_threshold > 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: dynamics.break_stress = %g Pa and dynamics.break_threshold = %g are two rules "
                           "of breaking: give one",
                           path, phc_key_line(dyn, "break_stress"), o->particles.break_stress,
                           o->particles.break_threshold);
        goto fail;
    }
    if (o->particles.anchors_carry_moment && !beam) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: dynamics.anchors_carry_moment needs dynamics.bending: beam with follow_parent",
                           path, phc_key_line(dyn, "anchors_carry_moment"));
        goto fail;
    }
    if (c->duration / c->time_step > 1e8) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: duration / time_step = %g steps is more than 1e8", path,
                           phc_key_line(root, "duration"), c->duration / c->time_step);
        goto fail;
    }
    char seed[64];
    snprintf(seed, sizeof seed, "seed: %llu", (unsigned long long)o->seed);
    if (!(c->seed_text = strdup(seed))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    *out = c;
    c = NULL;
fail:
    phc_grow_config_free(c);
    phc_yaml_free(doc);
    free(dir_copy);
    return rc;
}

void phc_grow_config_help(FILE *out)
{
    phc_grow_config d;
    memset(&d, 0, sizeof d);
    d.options = phc_climbing_options_default();
    d.direction[2] = 1;
    d.duration = 60;
    d.time_step = 0.25;
    d.frame_interval = 10;
    d.shadows = 1;
    fprintf(out, "keys of a grow config (all optional but plant.position):\n"
                 "  name                      run name (default: the config file's name)\n"
                 "  support                   support mesh, OBJ or PLY, relative to the config (default: none)\n");
    for (size_t i = 0; i < N_KEYS; ++i) {
        const key_spec *k = &KEYS[i];
        char name[64], range[96], def[96];
        full_name(k, name, sizeof name);
        range_text(k, range, sizeof range);
        const char *field = (const char *)&d + k->offset;
        switch (k->type) {
        case K_NUM: snprintf(def, sizeof def, "%g", *(const double *)field); break;
        case K_SIZE: snprintf(def, sizeof def, "%zu", *(const size_t *)field); break;
        case K_UINT: snprintf(def, sizeof def, "%u", *(const unsigned *)field); break;
        case K_U64: snprintf(def, sizeof def, "%llu", (unsigned long long)*(const uint64_t *)field); break;
        case K_BOOL: snprintf(def, sizeof def, "%s", *(const int *)field ? "true" : "false"); break;
        case K_WORD: snprintf(def, sizeof def, "%s", key_words(k)[*(const int *)field]); break;
        case K_VEC: {
            const double *v = (const double *)field;
            snprintf(def, sizeof def, "[%g, %g, %g]", v[0], v[1], v[2]);
            break;
        }
        }
        if (strcmp(name, "plant.position") == 0)
            snprintf(def, sizeof def, "required");
        else if (strcmp(name, "light.origin") == 0 || strcmp(name, "light.size") == 0)
            snprintf(def, sizeof def, "support box + 0.25 m");
        fprintf(out, "  %-25s %s; %s%s%s, default %s\n", name, k->help, range, k->unit[0] ? " " : "", k->unit, def);
    }
}
