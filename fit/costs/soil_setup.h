/* The `soil:` block shared by the soil data sets (soil_probe, infiltration):
 * the grid, layers, boundaries, rain and sources of a Rhizomorph soil
 * (model/soil.h), which of its numbers are fitted, and building the soil
 * and its tangent directions at given parameter values.
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
 * Fitted numbers are the parameter slots below, present when the problem
 * has a parameter of that name (or the data set binds the slot):
 *   p_<L>, c_<L>   permeability (m/h) and capacity of layer L (1-based)
 *   p, c           the same for every layer without its own slot
 *   f_diff, f_grav the diffusion and gravity forces
 * Otherwise the values in the config are used. */
#ifndef PHC_COSTS_SOIL_SETUP_H
#define PHC_COSTS_SOIL_SETUP_H

#include <stddef.h>

#include "fit/config_help.h"
#include "fit/costs/curve.h"
#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until the soil kinds are YAML-free */
#include "fit/dataset.h"
#include "measurements/geo.h"
#include "measurements/yaml_doc.h"
#include "model/soil.h"
#include "model/status.h"

extern const char *const phc_soil_setup_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_soil_setup_help[];

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
    size_t line;                 /* config line of the soil block */
} phc_soil_setup;

/* Reads the `soil:` mapping.  Errors name the config file and line. */
int phc_soil_setup_parse(const phc_yaml_doc *doc, const phc_yaml_node *soil,
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

/* A markdown description of the set-up at p and of the run's budget
 * (s after a run); malloc'd. */
char *phc_soil_setup_markdown(const phc_soil_setup *su, const double *p, const phc_soil *s);

/* The same after running the set-up at p from 0 to t_end h (the kinds'
 * report sections): *markdown malloc'd; errors of the run. */
int phc_soil_setup_report(const phc_soil_setup *su, const double *p, double t_end, char **markdown,
                          phc_error *err);

#endif /* PHC_COSTS_SOIL_SETUP_H */
