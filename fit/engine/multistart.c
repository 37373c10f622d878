/* Sobol starting points: see multistart.h. */
#include "fit/engine/multistart.h"

#include <gsl/gsl_qrng.h>
#include <math.h>
#include <stdlib.h>

struct phc_multistart {
    const phc_problem *pb;
    gsl_qrng *q;
    size_t n_free;
    double *lo, *hi;  /* box per parameter (NAN for fixed) */
    int *logscale;
    double *u;        /* one Sobol point */
};

static void box_of(const phc_problem *pb, size_t i, double *lo, double *hi)
{
    const phc_parameter *p = &pb->params[i];
    if (isfinite(p->range_lo) && isfinite(p->range_hi)) {
        *lo = p->range_lo;
        *hi = p->range_hi;
    } else if (isfinite(p->lower) && isfinite(p->upper)) {
        *lo = p->lower;
        *hi = p->upper;
    } else if (p->value != 0) {
        const double a = fabs(p->value) / 10, b = fabs(p->value) * 10;
        *lo = p->value > 0 ? a : -b;
        *hi = p->value > 0 ? b : -a;
    } else {
        const double s = phc_problem_scale(pb, i);
        *lo = -s;
        *hi = s;
    }
    if (*lo < p->lower)
        *lo = p->lower;
    if (*hi > p->upper)
        *hi = p->upper;
}

phc_multistart *phc_multistart_new(const phc_problem *pb)
{
    phc_multistart *ms = calloc(1, sizeof *ms);
    if (!ms)
        return NULL;
    ms->pb = pb;
    for (size_t i = 0; i < pb->n_params; ++i)
        ms->n_free += !pb->params[i].fixed;
    ms->lo = calloc(pb->n_params, sizeof *ms->lo);
    ms->hi = calloc(pb->n_params, sizeof *ms->hi);
    ms->logscale = calloc(pb->n_params, sizeof *ms->logscale);
    ms->u = calloc(ms->n_free ? ms->n_free : 1, sizeof *ms->u);
    /* GSL's Sobol generator supports up to 40 dimensions; beyond that use
     * Halton (up to 1229) -- both are low-discrepancy sequences. */
    const gsl_qrng_type *type = ms->n_free <= 40 ? gsl_qrng_sobol : gsl_qrng_halton;
    if (ms->n_free > 0 && ms->n_free <= 1229)
        ms->q = gsl_qrng_alloc(type, (unsigned)ms->n_free);
    if (!ms->lo || !ms->hi || !ms->logscale || !ms->u || (ms->n_free && !ms->q)) {
        phc_multistart_free(ms);
        return NULL;
    }
    for (size_t i = 0; i < pb->n_params; ++i) {
        if (pb->params[i].fixed)
            continue;
        box_of(pb, i, &ms->lo[i], &ms->hi[i]);
        ms->logscale[i] = ms->lo[i] > 0 && ms->hi[i] / ms->lo[i] > 100;
    }
    /* skip the first Sobol point (the box's corner) */
    if (ms->q)
        gsl_qrng_get(ms->q, ms->u);
    return ms;
}

void phc_multistart_free(phc_multistart *ms)
{
    if (!ms)
        return;
    if (ms->q)
        gsl_qrng_free(ms->q);
    free(ms->lo);
    free(ms->hi);
    free(ms->logscale);
    free(ms->u);
    free(ms);
}

int phc_multistart_next(phc_multistart *ms, double *x)
{
    const phc_problem *pb = ms->pb;
    if (ms->q && gsl_qrng_get(ms->q, ms->u) != 0)
        return PHC_ERR_NUMERIC;
    size_t d = 0;
    for (size_t i = 0; i < pb->n_params; ++i) {
        if (pb->params[i].fixed) {
            x[i] = pb->params[i].value;
            continue;
        }
        const double u = ms->u[d++];
        if (ms->logscale[i])
            x[i] = exp(log(ms->lo[i]) + u * (log(ms->hi[i]) - log(ms->lo[i])));
        else
            x[i] = ms->lo[i] + u * (ms->hi[i] - ms->lo[i]);
        if (x[i] < pb->params[i].lower)
            x[i] = pb->params[i].lower;
        if (x[i] > pb->params[i].upper)
            x[i] = pb->params[i].upper;
    }
    return PHC_OK;
}
