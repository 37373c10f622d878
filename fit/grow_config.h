/* The configuration of `phytocal grow`: one climbing plant (Hädrich,
 * Benes, Deussen, Pirk, "Interactive Modeling and Authoring of Climbing
 * Plants", CGF 36(2) 2017; model/climbing_growth.h) grown from a seed on a
 * support mesh, read from YAML.
 *
 * A grow config is not a calibration problem (no parameters to fit, no
 * observations), so it has its own small schema instead of a data-set kind:
 *
 *   name: ivy-wall              # run name (default: the file's stem)
 *   support: wall.obj           # OBJ or PLY, relative to the config; optional
 *   seed: 7                     # random seed
 *   duration: 120               # s
 *   time_step: 0.25             # s
 *   frame_interval: 30          # s between written frames
 *   plant:     {position: [x, y, z], direction: [x, y, z]}      # m, any length
 *   growth:    {max_length, bud_fraction, growth_rate, apical_dominance, radius,
 *               max_particles}
 *   branching: {probability, buds, variance, thickness_falloff, max_order}
 *   light:     {direction, extinction, cell, origin, size, ambient, supports_cast_shadows}
 *   tropisms:  {phototropism, surface_adaption, adaption_radius, contact_distance, keep_outside}
 *   anchors:   {attach_distance, release_distance, strength, time}
 *   dynamics:  {substeps, maturity_age, min_stiffness, gravity, iterations, damping}
 *   leaves:    {step, angle, size, thickness, response, max_angle}   (model/climbing_leaves.h)
 *   cambium:   {rate, leaf_area}                                     (model/climbing_cambium.h)
 *
 * Every key is optional except plant.position; the defaults are
 * phc_climbing_options_default()'s.  Every number is checked against its
 * range here, so a bad one names the config's file, line and key
 * ("wall.yaml:12: branching.probability = 1.5 is outside [0, 1]").
 * phc_grow_config_help writes the key table. */
#ifndef PHC_GROW_CONFIG_H
#define PHC_GROW_CONFIG_H

#include <stdio.h>

#include "model/climbing_growth.h"
#include "model/status.h"

typedef struct phc_grow_config {
    char *name;            /* run name */
    char *source;          /* the config's path as given */
    char *support;         /* the mesh's path (config directory + file), NULL: none */
    size_t support_line;   /* line of `support:` */
    size_t position_line;  /* line of `plant.position` */
    char *seed_text;       /* "seed: 7", for provenance */
    double position[3];    /* m: the seed's base */
    double direction[3];   /* its growth direction (unit) */
    double duration;       /* s, > 0 */
    double time_step;      /* s, > 0 */
    double frame_interval; /* s, > 0 */
    int light_grid_given;  /* light.origin and light.size were given */
    double light_size[3];  /* m, when given */
    int shadows;           /* light.supports_cast_shadows: 1 (default) or 0 */
    phc_climbing_options options; /* closest/closest_user left NULL */
} phc_grow_config;

/* Reads and checks a grow config.  Errors (PHC_ERR_INPUT, "FILE:LINE: ..."):
 * YAML syntax, unknown keys (with a suggestion), a value of the wrong type,
 * a number outside its range, time_step with growth_rate·time_step ≥ 1 −
 * bud_fraction, release_distance ≤ attach_distance; PHC_ERR_IO when the
 * file cannot be read, or the support file cannot be opened (PHC_ERR_IO at
 * the line of `support:`; it is parsed by phc_grow_write). */
int phc_grow_config_load(const char *path, phc_grow_config **out, phc_error *err);
void phc_grow_config_free(phc_grow_config *c); /* accepts NULL */

/* The keys with their ranges, defaults and meaning (`phytocal help grow`). */
void phc_grow_config_help(FILE *out);

#endif /* PHC_GROW_CONFIG_H */
