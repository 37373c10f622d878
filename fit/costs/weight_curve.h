/* `weight_curve` data sets: a plant (or a detached leaf) weighed on a balance
 * while it dries, against the wilting paper's water model (model/water.h):
 *
 *     mass(t) = dry_mass + W(t),   W(t) = 1ᵀ exp(S t) θ(0),   Σ θ(0) = initial_water
 *
 * with S = R·D_V⁻¹ − D_ℓ built from the plant graph (wilting §3–4, eq. 4–7)
 * and the leaf loss ℓ_i = δ·A_i.
 *
 * Parameter slots (bound to parameters by name: phc_problem_bind_by_name, or
 * a config's `parameters:`):
 *   delta          δ, leaf water-loss rate per unit of segment area proxy
 *                  A = r·h: s⁻¹·cm⁻² (the model's units; ℓ = δ·A in s⁻¹)
 *   initial_water  water in the plant at the first weighing, g
 *   initial_water_2, _3, ...  with jumps = split, the water at the start of
 *                  each later piece of the curve, g
 *   dry_mass       g; absent as a slot when options.dry_mass is given
 *                  (then fixed at the measurement)
 *   viscosity      μ of the sap, mPa·s; a slot only when options.is_parameter
 *                  says "viscosity" is a parameter, otherwise fixed at
 *                  options.viscosity
 *   night_factor, loss_<covariate>..., pot_capacity, pot_conductance: the
 *                  drivers' (fit/costs/weight_drivers.h), when not fixed
 * The slots declare these units (night_factor "1", pot_capacity g,
 * pot_conductance g s-1; a covariate's coefficient none), so a parameter's
 * `unit:` (δ in h-1 cm-2, water in kg ...) is converted into them and the
 * results come back in it (fit/parameter_units.h).
 * Observations are in g; time is measured in s from the first weighing kept.
 *
 * Built in C with phc_weight_curve_new from a plant graph (built in memory,
 * read with measurements/plant_io.h, or phc_plant_graph_leaf_chain for a
 * detached leaf), the weighings (arrays of times and masses, below) and
 * options.  A balance logger's table becomes weighings through
 * phc_weight_curve_read_table (fit/costs/weight_table.h: row selection,
 * logger time stamps and zones, units, tare, gaps, excluded windows).  The
 * config's `kind: weight_curve` mapping is translated into the same calls by
 * fit/config/weight_curve_yaml.c (`phytocal help weight_curve` lists its
 * keys).
 *
 * Messages name the config file and line of the key at fault when the
 * options carry an origin (fit/costs/origin.h), else the kind: "weight_curve:
 * key 'sigma': must be positive, found -1".  Keys inside keys are named with
 * dots and list items by index ("day.start", "exclude.1", "covariates.columns.0",
 * "select.2"); a measurement's place is the weighings' source and line. */
#ifndef PHC_COSTS_WEIGHT_CURVE_H
#define PHC_COSTS_WEIGHT_CURVE_H

#include <stddef.h>

#include "fit/costs/origin.h"
#include "fit/costs/weight_drivers.h"
#include "fit/engine/dataset.h"
#include "model/plant_graph.h"
#include "model/status.h"
#include "model/water.h"

/* The weighings of one plant, in time order.  Arrays are the caller's (read,
 * not kept: the data set copies what it needs).  Zero-initialised fields take
 * the defaults named; phc_weighings_default() gives exactly those. */
typedef struct phc_weighings {
    size_t n;                 /* weighings (at least 2 not skipped) */
    const double *t;          /* n times in the time unit, strictly increasing; any origin
                                 (the curve's x is the time since the first kept weighing) */
    const double *mass;       /* n masses in the mass unit, > 0 */
    const double *sigma;      /* n standard deviations of the balance in the mass unit, > 0,
                                 or NULL (then options.sigma) */
    const unsigned char *skip; /* n flags: 1 = left out of the fit (an excluded window; still
                                  checked against the dry mass), or NULL = none */
    size_t n_covariates;      /* readings that drive the loss rate (weight_drivers.h) */
    const char *const *covariate_names; /* n_covariates names: slots loss_<name> */
    const double *covariates; /* n x n_covariates, row-major: reading j at weighing i (finite
                                 at every weighing not skipped) */
    double seconds_per_unit;  /* the time unit in s (3600 for h); 0 = 1 (s) */
    const char *time_unit;    /* its name, for the axis label; NULL = "s" */
    double grams_per_unit;    /* the mass unit in g (1000 for kg); 0 = 1 (g) */
    const char *mass_unit;    /* its name, for messages; NULL = "g" */
    int calendar;             /* 1: t0_posix places the times on the calendar */
    double t0_posix;          /* with calendar: POSIX time (s) at t = 0 */
    const char *timezone;     /* IANA zone of the local clock (Europe/Berlin); NULL = UTC */
    /* Where the weighings came from, for messages and the report: */
    const char *source;       /* the file or a name; NULL = "weighings" */
    const size_t *lines;      /* n lines in source; NULL = 1, 2, ... n */
    const char *time_name, *mass_name; /* their columns; NULL = "time", "mass" */
    size_t tare_n, tare_line[2]; /* tare readings dropped before t[0]: count, first/last line */
    double max_gap;           /* s: pauses longer than this were listed (n_gaps) */
    size_t n_gaps;
    const double *gap_s;      /* n_gaps pause lengths, s */
    const size_t *gap_line;   /* n_gaps lines of the weighing before each pause */
    const size_t *rows;       /* n table rows (phc_weight_curve_read_table), or NULL */
    void *storage;            /* set by phc_weight_curve_read_table: the arrays it allocated,
                                 freed by phc_weighings_release; NULL for arrays of your own */
} phc_weighings;

/* Every field zero or NULL (the defaults above). */
phc_weighings phc_weighings_default(void);

/* What an irrigation (a rise of the mass above options.jump_threshold
 * between weighings) does. */
typedef enum phc_weight_jumps {
    PHC_WEIGHT_JUMPS_ERROR = 0, /* stop, naming the line */
    PHC_WEIGHT_JUMPS_SPLIT,     /* the curve restarts: piece k = 2, 3, ... gets its own slot
                                   initial_water_<k>; delta and the dry mass are shared */
    PHC_WEIGHT_JUMPS_KEEP       /* fit through it */
} phc_weight_jumps;

typedef struct phc_weight_curve_options {
    phc_water_weights conductance; /* edge weights (model/water.h); default Poiseuille */
    phc_water_method method;       /* evaluator; default auto */
    double step;                   /* BDF6 time step, s, >= 0; 0 = a thousandth of the span */
    double viscosity;              /* μ when not a slot, mPa·s > 0; NAN = 0.89 (water at
                                      25 °C), 0.9 with the reference weights */
    double dry_mass;               /* measured dry mass, g, > 0, below every mass: fixes the
                                      slot; NAN = dry_mass is a fitted slot */
    double sigma;                  /* one balance standard deviation, in the weighings' mass
                                      unit, > 0, when weighings.sigma is NULL; 0 = unweighted */
    phc_weight_jumps jumps;
    double jump_threshold;         /* the rise that counts as a jump, mass unit, > 0;
                                      NAN = max(5 sigma, 0.5% of the largest mass) */
    phc_weight_day day;            /* a light schedule (weight_drivers.h); not with covariates */
    phc_weight_pot pot;            /* a pot (weight_drivers.h) */
    const char *plant_name;        /* the plant graph's file, for messages; NULL = none */
    const char *x_label, *y_label; /* NULL = "time since the first weighing (<unit>)",
                                      "mass (g)" */
    phc_is_parameter_fn is_parameter; /* is "viscosity" a fitted slot?  NULL = no */
    void *user_data;                  /* passed to is_parameter */
    const phc_origin *origin;         /* where the options came from, for messages; NULL */
} phc_weight_curve_options;

/* Poiseuille weights, the automatic evaluator, viscosity, dry_mass,
 * jump_threshold and the night factor and pot values NAN (their defaults),
 * no sigma, no schedule, no pot, no origin. */
phc_weight_curve_options phc_weight_curve_options_default(void);

/* Builds a weight-curve data set from a finished plant graph (copied; it
 * must have leaf segments) and the weighings (copied).  Slot names as above;
 * parameter indices are left to phc_problem binding.  Errors name the option
 * (and the config line when options.origin is set) or the weighing's source
 * and line:
 *     "balance.csv:4: the mass rises by 2 g since line 3 (an irrigation?);
 *      set `jumps: split` or `exclude` the window" */
int phc_weight_curve_new(const phc_plant_graph *plant, const phc_weighings *weighings,
                         const phc_weight_curve_options *options, phc_dataset **out,
                         phc_error *err);

/* The operations of weight-curve data sets (ops->kind is "weight_curve"). */
extern const phc_dataset_ops phc_weight_curve_ops;

#endif /* PHC_COSTS_WEIGHT_CURVE_H */
