/* The soil shared by the soil data sets (soil_probe, infiltration,
 * root_shoot): the grid, layers, boundaries, rain and sources of a
 * Rhizomorph soil (model/soil.h), which of its numbers are fitted, and
 * building the soil and its tangent directions at given parameter values.
 *
 * Built in C with phc_soil_setup_new from phc_soil_setup_options; a data
 * set's `soil:` block in a config is translated into the same options by
 * fit/config/soil_setup_yaml.c (`phytocal help soil` lists its keys):
 *
 *   soil:
 *     grid: {nx: 1, ny: 1, nz: 60, dx: 0.02}     # voxels, m
 *     dt: 0.01                 # h, the step (sub-stepped over the stability limit)
 *     substep: true            # false: refuse a dt over the limit instead
 *     max_substeps: 100        # more sub-steps per dt (a fit's trial point making the
 *                              # soil far too fast for the grid) is refused; 0 = no limit
 *     f_diff: 1                # m; f_grav: 1; f_nutrient: 1
 *     boundaries: {sides: periodic, bottom: absorb, top: block}
 *                              # or x_min, x_max, y_min, y_max; block | absorb | periodic
 *     absorb: {form: code, width: 5}            # code (default) | paper
 *     layers:                  # from the surface down
 *       - {soil: silt_loam, thickness: 0.3, fill: 0.001}
 *       - {c: 10, p: 0.0015, fill: 0.002}       # the last one reaches the bottom
 *     rocks: {seed: 7, scale: 0.1, fraction: 0.1}
 *     nutrient_pockets: {seed: 3, scale: 0.2, fraction: 0.05, amount: 1}
 *     rain: [{start: 0, end: 2, rate: 0.005, nutrient: 0}]   # h, h, m/h, units/m^3
 *     sources: [{x: 0.5, y: 0.5, depth: 0.2, radius: 0.05, water_rate: 1e-4,
 *                nutrient_rate: 0, start: 0, end: 1}]          # m, m^3/h, h
 *     geo_origin: {lat: "43.6481 N", lon: "79.3832 W", height: 0}
 *                              # the grid's west-south corner at the surface
 *
 * A layer's initial water is `fill` (w/c) or `water` (w, m^3/m^3).
 *
 * Fitted numbers are the parameter slots below, present when is_parameter
 * says so (in a config: the problem has a parameter of that name, or the
 * data set binds the slot):
 *   p_<L>, c_<L>   permeability (m/h) and capacity (1) of layer L (1-based)
 *   p, c           the same for every layer without its own slot
 *   f_diff, f_grav the diffusion (m) and gravity (1) forces
 * (the units are declared on the data set's slots, so a parameter's `unit:`
 * such as "cm/d" is converted; phc_soil_setup_declare_units)
 * Otherwise the values of the options are used. */
#ifndef PHC_COSTS_SOIL_SETUP_H
#define PHC_COSTS_SOIL_SETUP_H

#include <stddef.h>
#include <stdint.h>

#include "fit/costs/origin.h"
#include "fit/engine/dataset.h"
#include "measurements/geo.h"
#include "model/soil.h"
#include "model/status.h"

/* One layer, from the surface down. */
typedef struct phc_soil_setup_layer {
    const char *soil;      /* a preset (clay, clay_loam, sandy_clay_loam, sandy_loam, silt_loam,
                              silt: phc_soil_preset) giving c and p, or NULL */
    double c, p;           /* capacity (dimensionless) and permeability (m/h); NAN: the preset's */
    double d;              /* growth resistance, >= 0; default 1 */
    double thickness;      /* m, > 0; not used for the last layer, which reaches the bottom */
    double fill;           /* initial fill level w/c, >= 0; NAN: not given */
    double water;          /* initial water w, m^3/m^3, >= 0; NAN: not given (neither: 0) */
    double nutrient;       /* initial nutrients, units/m^3, >= 0; default 0 */
} phc_soil_setup_layer;

/* NAN c, p, fill and water, d = 1, the rest 0. */
phc_soil_setup_layer phc_soil_setup_layer_default(void);

/* Seeded 3-D noise: rocks (p = 0) or nutrient pockets (phc_soil_add_rocks,
 * phc_soil_add_nutrient_pockets). */
typedef struct phc_soil_setup_noise {
    uint64_t seed;         /* the noise's seed (a config's default: 1) */
    double scale;          /* the noise's length, m, > 0 */
    double fraction;       /* the share of the soil they fill, 0 <= fraction < 1 */
    double amount;         /* pockets only: extra nutrients, units/m^3, >= 0 */
} phc_soil_setup_noise;

/* A point source (negative rates: a sink), placed by depth below the
 * surface (model/soil.h's phc_soil_source has the height instead). */
typedef struct phc_soil_setup_source {
    double x, y;           /* m from the grid's west-south corner, inside the grid */
    double depth;          /* m below the surface, 0 <= depth < nz dx */
    double radius;         /* m, >= 0: the spread (0: one voxel) */
    double water_rate;     /* m^3/h */
    double nutrient_rate;  /* units/h */
    double start, end;     /* h, start <= end; INFINITY = never ends */
} phc_soil_setup_source;

/* x, y, depth and rates 0, start 0, end INFINITY. */
phc_soil_setup_source phc_soil_setup_source_default(void);

/* Everything a `soil:` block can say. */
typedef struct phc_soil_setup_options {
    size_t nx, ny, nz;     /* voxels along x (east), y (north) (default 1 each) and z
                              (required); at most 5e8 voxels */
    double dx;             /* voxel side, m, > 0 (required; NAN until set) */
    phc_soil_params params; /* dt (h, > 0; default 0.01), substep (default 1),
                              max_substeps (default 100; 0 = no limit), f_diff (m), f_grav,
                              f_nutrient (>= 0, default 1), boundary[] per face (block, absorb
                              or periodic in pairs; default block), absorb_form, absorb_width
                              (1..1000 voxel layers, default 5): model/soil.h */
    const phc_soil_setup_layer *layers; /* n_layers >= 1, surface first */
    size_t n_layers;
    const phc_soil_setup_noise *rocks;            /* NULL: none */
    const phc_soil_setup_noise *nutrient_pockets; /* NULL: none */
    const phc_soil_rain *rain; /* n_rain spells (model/soil.h): rate >= 0 m/h, nutrient >= 0,
                                  start <= end h; may be NULL when n_rain is 0 */
    size_t n_rain;
    const phc_soil_setup_source *sources; /* n_sources; may be NULL when 0 */
    size_t n_sources;
    const phc_geo_frame *geo_origin; /* the grid's west-south corner at the surface (degrees,
                                        m); NULL: not georeferenced */
    /* Where the options came from, for messages; NULL from C.  Besides its
     * keys (dt, grid, absorb, ...) the kind asks for the places of list
     * items as "layers[0]", "layers[0].soil", "rain[2]", "sources[1]"
     * (0-based). */
    const phc_origin *origin;
} phc_soil_setup_options;

/* nx = ny = 1, nz = 0, dx NAN (both to be set), the model's parameters with
 * dt = 0.01 h and max_substeps = 100, no layers, rain, sources, noise or
 * geographic origin. */
phc_soil_setup_options phc_soil_setup_options_default(void);

typedef struct phc_soil_setup {
    size_t nx, ny, nz;
    double dx;                   /* m */
    phc_soil_params params;
    phc_soil_layer *layers;      /* surface first */
    char **layer_names;          /* preset name or "custom" */
    size_t n_layers;
    size_t *layer_of_k;          /* nz */
    unsigned char *rock;         /* n, 1 = rock (p = 0); NULL = none */
    double *pocket;              /* n, extra nutrients; NULL = none */
    phc_soil_rain *rain;
    size_t n_rain;
    phc_soil_source *sources;
    size_t n_sources;
    int has_geo;
    phc_geo_frame geo;
    /* slots: index among the set-up's k slots, or -1 when fixed */
    int *slot_p, *slot_c;        /* per layer */
    int slot_fd, slot_fg;
    size_t k;
    char **slot_names;           /* k names */
    size_t line;                 /* config line of the soil block (0 without an origin) */
} phc_soil_setup;

/* Builds a set-up from the options (copied: they may be freed afterwards).
 * The slots are the names is_parameter accepts (NULL: p and c).  `kind`
 * names the data set's kind in messages when the options have no origin
 * (NULL: "soil"): "soil_probe: soil layer 1: unknown soil 'peat' (known:
 * ...)"; with an origin they name the config file and line.  Errors:
 * PHC_ERR_INPUT for values outside their ranges, PHC_ERR_NOMEM. */
int phc_soil_setup_new(const phc_soil_setup_options *options, const char *kind,
                       phc_is_parameter_fn is_parameter, void *user_data, phc_soil_setup **out,
                       phc_error *err);
void phc_soil_setup_free(phc_soil_setup *su);

/* A new soil with the set-up's fields at slot values p (k values, from
 * `first` on in the data set's slot vector; NULL = the config's values),
 * at t = 0 with the budget reset.  PHC_ERR_DOMAIN for slot values outside
 * the model's domain (p < 0, c <= 0, ...). */
int phc_soil_setup_build(const phc_soil_setup *su, const double *p, phc_soil **out, phc_error *err);

/* Tangent directions of the k slots for a soil built at p: dp[q], dinv_c[q]
 * (n each, zeroed and filled), dfd[q], dfg[q], and the initial sensitivity
 * sw[q] (n; nonzero for capacity slots of layers that start at a fill
 * level). */
void phc_soil_setup_tangent(const phc_soil_setup *su, const phc_soil *s, double **dp, double **dinv_c,
                            double *dfd, double *dfg, double **sw);

/* Builds a soil at slot values p and runs it through the sorted times
 * t[0..m-1] (h, >= 0), calling visit(user, s, i, tan) on reaching t[i];
 * when `tangents` is nonzero tan holds the k slots' directions (dp,
 * dinv_c, dfd, dfg) and sensitivity fields sw = d w / d slot, else it is
 * NULL.  visit returns 0 to go on.  With keep, the soil at t[m-1]
 * is handed to the caller (free with phc_soil_free).  Errors: those of
 * build and phc_soil_run (PHC_ERR_DOMAIN over max_substeps), and
 * PHC_ERR_DOMAIN when visit stops. */
typedef int (*phc_soil_visit_fn)(void *user, const phc_soil *s, size_t i, const phc_soil_tangent *tan);
int phc_soil_setup_run(const phc_soil_setup *su, const double *p, const double *t, size_t m, int tangents,
                       phc_soil_visit_fn visit, void *user, phc_soil **keep, phc_error *err);

/* The value of layer L's permeability and capacity at slot values p. */
double phc_soil_setup_p(const phc_soil_setup *su, size_t layer, const double *p);
double phc_soil_setup_c(const phc_soil_setup *su, size_t layer, const double *p);

/* A new data set of kind `ops` with the set-up's k slots (names copied)
 * and room for n observations: x, y, sigma, data_lines allocated, and
 * data_file = path.  NULL when out of memory. */
phc_dataset *phc_soil_setup_dataset(const phc_soil_setup *su, const phc_dataset_ops *ops, size_t n,
                                    const char *path);

/* Declares the units of the set-up's slots in ds, which has slots of the
 * same names (model/soil.h, Rhizomorph eqs. 25-28): p, p_<L> m/h; c, c_<L>
 * and f_grav dimensionless ("1"); f_diff m.  A parameter's `unit:` is then
 * converted into these (fit/parameter_units.h).  phc_soil_setup_dataset
 * does it; a kind that names its slots itself calls it.  PHC_ERR_NOMEM, or
 * PHC_ERR_INVALID when ds lacks one of the slots. */
int phc_soil_setup_declare_units(const phc_soil_setup *su, phc_dataset *ds);

/* A markdown description of the set-up at p and of the run's budget
 * (s after a run); malloc'd. */
char *phc_soil_setup_markdown(const phc_soil_setup *su, const double *p, const phc_soil *s);

/* The same after running the set-up at p from 0 to t_end h (the kinds'
 * report sections): *markdown malloc'd; errors of the run. */
int phc_soil_setup_report(const phc_soil_setup *su, const double *p, double t_end, char **markdown,
                          phc_error *err);

#endif /* PHC_COSTS_SOIL_SETUP_H */
