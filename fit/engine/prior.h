/* The distribution of one parameter over which a global sensitivity study
 * samples it (`prior:` in the config, or the parameter's bounds), and its
 * inverse cumulative distribution function, which maps a point u of the
 * unit interval to a parameter value (Saltelli et al. 2008, "Global
 * Sensitivity Analysis. The Primer", §1.2.3: inputs drawn in the unit
 * hypercube and transformed by their inverse CDFs).
 *
 * Kinds and their two numbers a, b (in the parameter's own unit):
 *   uniform      a = lower, b = upper            a < b, both finite
 *   log-uniform  a = lower, b = upper            0 < a < b: ln x uniform
 *   normal       a = mean, b = standard dev.     b > 0
 *   log-normal   a = meanlog, b = sdlog          b > 0: ln x ~ N(a, b^2)
 *                (R's dlnorm names: the mean and sd of ln x)
 * normal and log-normal are truncated to [lower, upper] (the parameter's
 * bounds, -inf/+inf when open): the study never draws a value the model is
 * not allowed to see (the inverse CDF's round-off, a few ulps beyond a
 * bound, is put on the bound).  Pure: no I/O. */
#ifndef PHC_PRIOR_H
#define PHC_PRIOR_H

#include "model/status.h"

typedef enum phc_prior_kind {
    PHC_PRIOR_NONE = 0, /* not given: the bounds make a uniform prior */
    PHC_PRIOR_UNIFORM,
    PHC_PRIOR_LOG_UNIFORM,
    PHC_PRIOR_NORMAL,
    PHC_PRIOR_LOG_NORMAL
} phc_prior_kind;

typedef struct phc_prior {
    phc_prior_kind kind;
    double a, b;         /* see the table above */
    double lower, upper; /* truncation of normal and log-normal; -INFINITY / INFINITY when open */
} phc_prior;

/* "uniform", "log-uniform", "normal", "log-normal" ("none" for NONE). */
const char *phc_prior_kind_name(phc_prior_kind kind);
/* The kind of a name above (also "loguniform", "lognormal"); -1 when unknown. */
int phc_prior_kind_parse(const char *name);

/* The prior a study uses for a parameter with prior p (kind may be NONE)
 * and bounds [lower, upper]: p itself with the bounds as truncation, or for
 * NONE the uniform distribution on the bounds.  Errors (PHC_ERR_INPUT, the
 * message starts with `what`, e.g. "cfg.yaml:4: parameter 'k'"): NONE with a
 * bound open ("needs finite bounds or a prior"), invalid numbers (see the
 * table), a uniform or log-uniform range outside the bounds, a truncation
 * interval holding (numerically) no probability. */
int phc_prior_resolve(const phc_prior *p, double lower, double upper, const char *what, phc_prior *out,
                      phc_error *err);

/* Inverse CDF of a resolved prior at u in (0, 1) (uniform kinds also accept
 * 0 and 1).  NAN for u outside. */
double phc_prior_quantile(const phc_prior *p, double u);

/* Median of a resolved prior (its quantile at 1/2). */
double phc_prior_median(const phc_prior *p);

/* Log density of a resolved prior at x, up to an additive constant (for an
 * MCMC posterior; the truncation's normalisation is a constant):
 *   uniform 0, log-uniform -ln x, normal -(x - a)^2 / (2 b^2),
 *   log-normal -ln x - (ln x - a)^2 / (2 b^2),
 * -INFINITY outside [lower, upper] (and for x <= 0 where ln x is taken). */
double phc_prior_log_density(const phc_prior *p, double x);

#endif /* PHC_PRIOR_H */
