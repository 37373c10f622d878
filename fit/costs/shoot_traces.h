/* `shoot_traces` data sets: traced shoots of a climbing plant
 * (measurements/shoot_traces.h) against the climbing-plant growth model
 * (model/climbing_growth.h; Hädrich et al., CGF 36(2) 2017), compared by
 * summary statistics (model/climbing_statistics.h) averaged over K seeds.
 *
 * Observations: at each observation time t_j (s) the traced plant's
 * total_length, main_length, height, attached_fraction and light_cosine;
 * at the last time also the lateral-shoot count of every branch order
 * 1 .. max_order and, when the traces hold at least 2 laterals, the
 * branching angle's mean and standard deviation.
 * Model: the plant grown from the grow config's seed, support and light
 * (fit/grow_config.h) with each of the seeds first_seed .. first_seed+K-1
 * (common random numbers: the same K seeds at every parameter value),
 * looked at by a tracer at the traces' frames (fit/costs/shoot_tracer.h:
 * new nodes and every apex where they are at each frame, as a time-lapse
 * tracer records them; frames every frame_interval s, or the traces'
 * distinct point times), the statistics of that traced record at t_j
 * computed exactly as the traces' (phc_shoot_traces_segments), averaged
 * (phc_climbing_summary_mean: the angles pooled over all laterals).
 * Residuals: L⁻¹(traced − model), Σ = L Lᵀ the statistics' covariance (a
 * synthetic likelihood, Wood, Nature 466, 2010): the data set holds the
 * whitened traced statistics with σ = 1 (phc_shoot_traces_traced gives
 * them as traced).
 *
 * Σ = diag(σ_given²) + (1 + 1/K)·C_g.  σ_given per statistic: lengths and
 * height max(σ_rel·value, σ_len) (defaults 0.1 and 0.01 m), attached
 * fraction and light cosine 0.05, counts sqrt(max(1, count)) (Poisson),
 * angles 5°.  C is the covariance of the statistics between M =
 * max(K, covariance_seeds) model plants at the start options (the grow
 * config's values; phc_shoot_traces_covariance_at recomputes it
 * elsewhere, and with covariance_at_fitted the fit recomputes it at its
 * fitted values in rounds, phc_dataset_ops.reweight), C_g its diagonal plus `correlation` (g, default 0.5) times
 * its off-diagonal part; (1 + 1/K) because the traced plant is one draw of
 * the random process (C) and the model value a mean over K (C/K).
 *
 * Slots (the grow config's values are the start of the ones not fitted):
 * branch_probability, direction_variance, phototropism (s-1),
 * surface_adaption (s-1), growth_rate (s-1), apical_dominance,
 * thickness_falloff, min_stiffness, anchor_strength.
 *
 * Derivatives: central differences with a relative step fd_step (default
 * 0.2 of the value, or 0.2 of the slot's scale when the value is 0): the
 * averaged statistics are piecewise constant in BP, V, η, ... with fixed
 * seeds (a bud flips at a threshold of its uniform draw), so steps of 1e-6
 * would see zero or a jump; a wide step spans many flips over K plants and
 * gives the slope of the trend.  5% (the old default) still saw single
 * jumps of a shoot's path (the attached fraction of a recovery plant moved
 * by 3σ between τ = 0.525 and 0.55 s⁻¹), which made the Jacobian steep and
 * the intervals far too narrow (README "Fitting growth to traced shoots").  A step that leaves the model's domain
 * (BP + h > 1) falls back to the one-sided difference. */
#ifndef PHC_COSTS_SHOOT_TRACES_H
#define PHC_COSTS_SHOOT_TRACES_H

#include <stdint.h>

#include "fit/engine/dataset.h"
#include "measurements/shoot_traces.h"
#include "model/climbing_growth.h"
#include "model/status.h"

typedef struct phc_shoot_traces_options {
    phc_climbing_options plant;  /* the growth options (closest/closest_user: the support) */
    double position[3];          /* m: the seed's base */
    double direction[3];         /* its growth direction */
    double time_step;            /* s, > 0 */
    size_t seeds;                /* K >= 1; default 8 */
    uint64_t first_seed;         /* default: plant.seed */
    const double *times;         /* observation times, s, increasing, > 0, <= the traces' end;
                                    NULL: 4 evenly spaced up to the traces' last time */
    size_t n_times;
    double sigma_rel, sigma_length; /* default 0.1, 0.01 m */
    double sigma_fraction, sigma_cosine, sigma_angle; /* default 0.05, 0.05, 5° */
    double fd_step;              /* relative, default 0.2 */
    size_t covariance_seeds;     /* M: plants the statistics' covariance is estimated from
                                    (max(K, M) plants; default 64) */
    double correlation;          /* g in [0, 1]: the weight of the estimated correlations
                                    between statistics (0: independent sigmas; default 0.5) */
    int covariance_at_fitted;    /* 0 (default): Σ at the start values for the whole fit;
                                    1: after each solve Σ is recomputed at the fitted values
                                    and the fit solved again (phc_dataset_ops.reweight), until
                                    the estimates move by at most covariance_tolerance or
                                    covariance_rounds recomputations were made */
    size_t covariance_rounds;    /* >= 1; default 5 */
    double covariance_tolerance; /* > 0: largest relative change |p - p_Σ| / max(|p_Σ|, scale)
                                    of an estimate from the values Σ was computed at; 0.02 */
    double frame_interval;       /* s, >= 0: the tracer looked at the plant every frame_interval;
                                    0 (default): at every distinct point time of the traces */
    /* Supports that cast shadows (the grow config's light.supports_cast_shadows):
     * triangles rasterised into every grown plant's light grid with
     * phc_climbing_set_shadow_triangles, as `phytocal grow` does; vertices
     * 3·n (m), triangles 3·n indices; borrowed (kept alive by the support
     * owner); 0 triangles: no shadows. */
    const double *shadow_vertices;
    size_t shadow_vertex_count;
    const size_t *shadow_triangles;
    size_t shadow_triangle_count;
    phc_is_parameter_fn is_parameter; /* which slots are fitted (NULL: branch_probability) */
    void *user_data;
    void *support_owner;         /* freed with support_free when the data set is freed */
    void (*support_free)(void *);
} phc_shoot_traces_options;

phc_shoot_traces_options phc_shoot_traces_options_default(void);

/* Builds the data set; takes the traces (freed with the data set, also on
 * error) and the support owner.  Errors (PHC_ERR_INPUT): bad options,
 * observation times after the traces' end, no slot to fit. */
int phc_shoot_traces_new(phc_shoot_traces *traces, const phc_shoot_traces_options *o, phc_dataset **out,
                         phc_error *err);

/* The averaged statistics of the model at slot values p at the data set's
 * observation times, in its observation order (n values), and their
 * seed-to-seed standard deviation (sd, n values, may be NULL).  0, > 0
 * (outside the model's domain), < 0 (memory). */
int phc_shoot_traces_model(phc_dataset *ds, const double *p, double *y, double *sd);

/* The K-seed means y (n) at slot values p and their central-difference
 * Jacobian (n x k row-major, may be NULL), not whitened; 0, > 0, < 0 as
 * phc_shoot_traces_model. */
int phc_shoot_traces_model_jacobian(phc_dataset *ds, const double *p, double *y, double *jac);

/* The traced statistics (n, in observation order; ds->y holds them
 * whitened). */
const double *phc_shoot_traces_traced(const phc_dataset *ds);

/* Recomputes the statistics' covariance at slot values p (e.g. the fitted
 * values, for a second fit): Σ = diag(σ_given²) + (1 + 1/K) C, C the
 * covariance of the statistics between M = max(K, covariance_seeds)
 * plants (seeds first_seed ..), its off-diagonal part times `correlation`;
 * the data set then holds the whitened traced statistics L⁻¹y (Σ = L Lᵀ)
 * with σ = 1, and predicts L⁻¹ŷ.  PHC_OK; PHC_ERR_DOMAIN (the model cannot
 * be grown at p: nothing changed), PHC_ERR_NOMEM. */
int phc_shoot_traces_covariance_at(phc_dataset *ds, const double *p, phc_error *err);

/* How Σ came to be where it is: the rounds of recomputation at fitted
 * values made (0: Σ at the start values), the largest relative change of
 * an estimate from the values Σ was last computed at, as seen by the last
 * phc_dataset_ops.reweight call (NAN before one), and whether the rounds
 * stopped on the tolerance (1) or on covariance_rounds (0). */
void phc_shoot_traces_covariance_rounds(const phc_dataset *ds, size_t *rounds, double *change, int *settled);

/* Traces of a plant grown by the model (for regression tests and
 * examples): the plant grown with o's options, looked at by the tracer of
 * fit/costs/shoot_tracer.h at every time of `times` (the frames), the same
 * record the data set makes of its model plants (so a data set with these
 * frames, seeds = 1 and first_seed = o->plant.seed gives the traced
 * statistics exactly at the same values). */
int phc_shoot_traces_from_model(const phc_shoot_traces_options *o, const double *times, size_t n_times,
                                phc_shoot_traces **out, phc_error *err);

/* Local identifiability at slot values p, from the data set's own
 * central-difference Jacobian J of the weighted residuals (σ as given, not
 * rescaled by the fit's residual variance): the normal matrix JᵀJ, its
 * eigenvalues (rank: those above 1e-8 of the largest), each slot's
 * standard deviation from the pseudo-inverse (INFINITY when the slot has a
 * part > 0.1 in a null direction), its sensitivity |J_j| and the largest
 * cosine between its column and another's (collinearity). */
#define PHC_SHOOT_TRACES_MAX_SLOTS 9
typedef struct phc_shoot_traces_ident {
    size_t rank;
    double condition;                               /* largest / smallest eigenvalue */
    double value[PHC_SHOOT_TRACES_MAX_SLOTS];
    double sd[PHC_SHOOT_TRACES_MAX_SLOTS];          /* slot units */
    double sensitivity[PHC_SHOOT_TRACES_MAX_SLOTS]; /* |column of J|, per slot unit */
    double max_corr[PHC_SHOOT_TRACES_MAX_SLOTS];    /* cosine with `partner`'s column */
    size_t partner[PHC_SHOOT_TRACES_MAX_SLOTS];     /* slot, or (size_t)-1 */
    int identifiable[PHC_SHOOT_TRACES_MAX_SLOTS];   /* 1 yes, 0 no (reason in why) */
    char why[PHC_SHOOT_TRACES_MAX_SLOTS][96];
} phc_shoot_traces_ident;
int phc_shoot_traces_identifiability(phc_dataset *ds, const double *p, phc_shoot_traces_ident *out,
                                     phc_error *err);

extern const phc_dataset_ops phc_shoot_traces_ops;

#endif /* PHC_COSTS_SHOOT_TRACES_H */
