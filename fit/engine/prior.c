/* Priors of sensitivity studies: see prior.h. */
#include "fit/engine/prior.h"

#include <gsl/gsl_cdf.h>
#include <math.h>
#include <string.h>

const char *phc_prior_kind_name(phc_prior_kind kind)
{
    switch (kind) {
    case PHC_PRIOR_UNIFORM: return "uniform";
    case PHC_PRIOR_LOG_UNIFORM: return "log-uniform";
    case PHC_PRIOR_NORMAL: return "normal";
    case PHC_PRIOR_LOG_NORMAL: return "log-normal";
    default: return "none";
    }
}

int phc_prior_kind_parse(const char *name)
{
    if (!name)
        return -1;
    if (strcmp(name, "uniform") == 0)
        return PHC_PRIOR_UNIFORM;
    if (strcmp(name, "log-uniform") == 0 || strcmp(name, "loguniform") == 0)
        return PHC_PRIOR_LOG_UNIFORM;
    if (strcmp(name, "normal") == 0)
        return PHC_PRIOR_NORMAL;
    if (strcmp(name, "log-normal") == 0 || strcmp(name, "lognormal") == 0)
        return PHC_PRIOR_LOG_NORMAL;
    return -1;
}

/* Standard-normal probabilities of the truncation interval of a (log-)normal
 * prior, in the variable z = (x - mean)/sd or (ln x - meanlog)/sdlog. */
static void normal_window(const phc_prior *p, double *plo, double *phi)
{
    double zlo = -INFINITY, zhi = INFINITY;
    if (p->kind == PHC_PRIOR_NORMAL) {
        zlo = (p->lower - p->a) / p->b;
        zhi = (p->upper - p->a) / p->b;
    } else {
        if (p->lower > 0)
            zlo = (log(p->lower) - p->a) / p->b;
        if (isfinite(p->upper))
            zhi = p->upper > 0 ? (log(p->upper) - p->a) / p->b : -INFINITY;
    }
    *plo = isfinite(zlo) ? gsl_cdf_ugaussian_P(zlo) : (zlo < 0 ? 0.0 : 1.0);
    *phi = isfinite(zhi) ? gsl_cdf_ugaussian_P(zhi) : (zhi < 0 ? 0.0 : 1.0);
}

int phc_prior_resolve(const phc_prior *p, double lower, double upper, const char *what, phc_prior *out,
                      phc_error *err)
{
    phc_prior r = *p;
    r.lower = lower;
    r.upper = upper;
    switch (p->kind) {
    case PHC_PRIOR_NONE:
        if (!isfinite(lower) || !isfinite(upper))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: a sensitivity study needs finite bounds (lower and upper) or a prior "
                                 "(prior: {dist: normal, mean: .., sd: ..} and the like); found [%g, %g]",
                                 what, lower, upper);
        if (!(lower < upper))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: the bounds [%g, %g] hold no range to sample",
                                 what, lower, upper);
        r.kind = PHC_PRIOR_UNIFORM;
        r.a = lower;
        r.b = upper;
        break;
    case PHC_PRIOR_UNIFORM:
    case PHC_PRIOR_LOG_UNIFORM:
        if (!isfinite(p->a) || !isfinite(p->b) || !(p->a < p->b))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: prior %s: expected lower < upper (finite), found [%g, %g]",
                                 what, phc_prior_kind_name(p->kind), p->a, p->b);
        if (p->kind == PHC_PRIOR_LOG_UNIFORM && !(p->a > 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: prior log-uniform: lower must be positive, found %g",
                                 what, p->a);
        /* 1e-12 relative: bounds converted to a slot's unit and back may have
           moved by round-off */
        if (p->a < lower - 1e-12 * fabs(lower) || p->b > upper + 1e-12 * fabs(upper))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: prior %s [%g, %g] reaches outside the bounds [%g, %g]",
                                 what, phc_prior_kind_name(p->kind), p->a, p->b, lower, upper);
        break;
    case PHC_PRIOR_NORMAL:
    case PHC_PRIOR_LOG_NORMAL: {
        if (!isfinite(p->a) || !isfinite(p->b) || !(p->b > 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: prior %s: the %s must be finite and the %s positive, "
                                 "found %g and %g", what, phc_prior_kind_name(p->kind),
                                 p->kind == PHC_PRIOR_NORMAL ? "mean" : "meanlog",
                                 p->kind == PHC_PRIOR_NORMAL ? "sd" : "sdlog", p->a, p->b);
        double plo, phi;
        normal_window(&r, &plo, &phi);
        /* below ~1e-12 of probability the inverse CDF has no digits left */
        if (!(phi - plo > 1e-12))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: prior %s (%g, %g) puts no probability inside the "
                                 "bounds [%g, %g]", what, phc_prior_kind_name(p->kind), p->a, p->b, lower, upper);
        break;
    }
    default:
        return phc_error_set(err, PHC_ERR_INPUT, "%s: unknown prior kind %d", what, (int)p->kind);
    }
    *out = r;
    return PHC_OK;
}

double phc_prior_quantile(const phc_prior *p, double u)
{
    if (!(u >= 0 && u <= 1))
        return NAN;
    switch (p->kind) {
    case PHC_PRIOR_UNIFORM:
        return p->a + u * (p->b - p->a);
    case PHC_PRIOR_LOG_UNIFORM:
        return exp(log(p->a) + u * (log(p->b) - log(p->a)));
    case PHC_PRIOR_NORMAL:
    case PHC_PRIOR_LOG_NORMAL: {
        if (u <= 0 || u >= 1)
            return NAN;
        double plo, phi;
        normal_window(p, &plo, &phi);
        /* truncated normal: z = Phi^-1(Phi(zlo) + u (Phi(zhi) - Phi(zlo))); for
           the upper half use the complementary form, which keeps digits in the
           right tail (Phi near 1) */
        const double q = plo + u * (phi - plo);
        double z;
        if (q < 0.5)
            z = gsl_cdf_ugaussian_Pinv(q);
        else
            z = -gsl_cdf_ugaussian_Pinv((1.0 - phi) + (1.0 - u) * (phi - plo));
        const double x = p->kind == PHC_PRIOR_NORMAL ? p->a + p->b * z : exp(p->a + p->b * z);
        /* Phi and its inverse round: a draw from the truncated distribution can
           land a few ulps beyond a bound, which the model must never see; that
           round-off (and only that: q lies inside the window) goes on the bound */
        if (x < p->lower)
            return p->lower;
        if (x > p->upper)
            return p->upper;
        return x;
    }
    default:
        return NAN;
    }
}

double phc_prior_median(const phc_prior *p)
{
    return phc_prior_quantile(p, 0.5);
}

double phc_prior_log_density(const phc_prior *p, double x)
{
    if (!(x >= p->lower && x <= p->upper))
        return -INFINITY;
    switch (p->kind) {
    case PHC_PRIOR_NONE:
    case PHC_PRIOR_UNIFORM:
        return 0;
    case PHC_PRIOR_LOG_UNIFORM:
        return x > 0 ? -log(x) : -INFINITY;
    case PHC_PRIOR_NORMAL: {
        const double z = (x - p->a) / p->b;
        return -0.5 * z * z;
    }
    case PHC_PRIOR_LOG_NORMAL: {
        if (!(x > 0))
            return -INFINITY;
        const double z = (log(x) - p->a) / p->b;
        return -log(x) - 0.5 * z * z;
    }
    }
    return -INFINITY;
}
