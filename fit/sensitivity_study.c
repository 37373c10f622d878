/* Global sensitivity studies: see sensitivity_study.h. */
#include "fit/sensitivity_study.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fit/engine/morris.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/prior.h"
#include "fit/engine/sobol_indices.h"
#include "fit/json_file_internal.h"
#include "fit/run_dir.h"
#include "fit/run_ledger.h"
#include "fit/sensitivity_plots.h"
#include "fit/study_dist.h"
#include "measurements/atomic_file.h"

/* Verdict thresholds (Saltelli et al. 2008 use 0.05 as the usual cut for a
 * factor whose total effect is worth fixing attention on); Morris: mu*
 * relative to the largest mu* of the output. */
#define ST_MATTERS 0.05
#define MU_STAR_MATTERS 0.10

phc_study_options phc_study_options_default(void)
{
    phc_study_options o;
    memset(&o, 0, sizeof o);
    o.method = PHC_STUDY_SOBOL;
    o.seed = 1;
    o.levels = 4;
    return o;
}

void phc_study_summary_clear(phc_study_summary *s)
{
    if (!s)
        return;
    free(s->verdict);
    memset(s, 0, sizeof *s);
}

/* ---- evaluation ------------------------------------------------------------------------- */

struct phc_study_eval {
    const phc_problem *pb;
    double *p, *yhat;   /* the largest data set's slots and observations */
    size_t *interp_i;   /* per named output at an x without predict_at: yhat[i] (1 - w) + yhat[i + 1] w */
    double *interp_w;
};

/* Output layout: 0 the cost; then per data set its cost (only when there
 * are several: with one it is the cost) and its mean prediction; then the
 * named outputs; then per data set its predictions at the observations of
 * phc_study_series_observation. */
static size_t per_dataset(const phc_problem *pb)
{
    return pb->n_datasets > 1 ? 2 : 1;
}

static void dataset_label(const phc_problem *pb, size_t d, char *buf, size_t size)
{
    if (pb->datasets[d]->name)
        snprintf(buf, size, "%s", pb->datasets[d]->name);
    else /* a data set built in C may have no name */
        snprintf(buf, size, "dataset-%zu", d + 1);
}

size_t phc_study_scalar_outputs(const phc_problem *pb)
{
    return 1 + per_dataset(pb) * pb->n_datasets + pb->n_outputs;
}

size_t phc_study_series_points(const phc_problem *pb, size_t d)
{
    const size_t n = pb->datasets[d]->n, cap = pb->series_points;
    return n < cap ? n : cap;
}

size_t phc_study_series_observation(const phc_problem *pb, size_t d, size_t t)
{
    const size_t n = pb->datasets[d]->n, T = phc_study_series_points(pb, d);
    if (T == n)
        return t;
    if (T == 1)
        return (n - 1) / 2;
    /* evenly spaced by index, first and last included: round(t (n - 1) / (T - 1)) */
    return (t * (n - 1) + (T - 1) / 2) / (T - 1);
}

size_t phc_study_outputs(const phc_problem *pb)
{
    size_t n = phc_study_scalar_outputs(pb);
    for (size_t d = 0; d < pb->n_datasets; ++d)
        n += phc_study_series_points(pb, d);
    return n;
}

void phc_study_output_name(const phc_problem *pb, size_t j, char *buf, size_t size)
{
    const size_t m = per_dataset(pb), fixed = 1 + m * pb->n_datasets;
    char label[512];
    if (j == 0) {
        snprintf(buf, size, "cost");
        return;
    }
    if (j < fixed) {
        const size_t d = (j - 1) / m;
        const char *what = m == 2 && (j - 1) % 2 == 0 ? "cost" : "mean";
        dataset_label(pb, d, label, sizeof label);
        snprintf(buf, size, "%s.%s", label, what);
        return;
    }
    if (j < fixed + pb->n_outputs) {
        snprintf(buf, size, "%s", pb->outputs[j - fixed].name);
        return;
    }
    j -= fixed + pb->n_outputs;
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        const size_t T = phc_study_series_points(pb, d);
        if (j < T) {
            dataset_label(pb, d, label, sizeof label);
            snprintf(buf, size, "%s@%zu", label, phc_study_series_observation(pb, d, j) + 1);
            return;
        }
        j -= T;
    }
    snprintf(buf, size, "?");
}

phc_study_eval *phc_study_eval_new(const phc_problem *pb)
{
    size_t kmax = 1, nmax = 1;
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        kmax = pb->datasets[d]->k > kmax ? pb->datasets[d]->k : kmax;
        nmax = pb->datasets[d]->n > nmax ? pb->datasets[d]->n : nmax;
    }
    phc_study_eval *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    w->pb = pb;
    w->p = malloc(kmax * sizeof *w->p);
    w->yhat = malloc(nmax * sizeof *w->yhat);
    w->interp_i = calloc(pb->n_outputs ? pb->n_outputs : 1, sizeof *w->interp_i);
    w->interp_w = calloc(pb->n_outputs ? pb->n_outputs : 1, sizeof *w->interp_w);
    if (!w->p || !w->yhat || !w->interp_i || !w->interp_w) {
        phc_study_eval_free(w);
        return NULL;
    }
    /* a named output at an x the kind cannot predict at: linear between the
       observations around it (phc_problem_add_output checked that x
       increases and brackets it) */
    for (size_t o = 0; o < pb->n_outputs; ++o) {
        const phc_named_output *no = &pb->outputs[o];
        const phc_dataset *ds = pb->datasets[no->dataset];
        if (no->observation || ds->ops->predict_at)
            continue;
        size_t i = 0;
        while (i + 2 < ds->n && ds->x[i + 1] <= no->at)
            ++i;
        const double span = ds->n > 1 ? ds->x[i + 1] - ds->x[i] : 0;
        w->interp_i[o] = i;
        w->interp_w[o] = span > 0 ? (no->at - ds->x[i]) / span : 0;
        if (w->interp_w[o] > 1) /* at equals the last x */
            w->interp_w[o] = 1;
    }
    return w;
}

void phc_study_eval_free(phc_study_eval *w)
{
    if (!w)
        return;
    free(w->p);
    free(w->yhat);
    free(w->interp_i);
    free(w->interp_w);
    free(w);
}

/* Data set d's predictions at x into w->yhat (its slots into w->p), its
 * cost 1/2 sum r^2 into *cost and the sum of its predictions into *sum.
 * Nonzero when the model cannot be evaluated there. */
static int predict_dataset(phc_study_eval *w, size_t d, const double *x, double *cost, double *sum)
{
    phc_dataset *ds = w->pb->datasets[d];
    for (size_t j = 0; j < ds->k; ++j)
        w->p[j] = x[ds->param_index[j]];
    if (ds->ops->predict(ds, w->p, w->yhat, NULL) != 0)
        return 1;
    double c = 0, s = 0;
    for (size_t i = 0; i < ds->n; ++i) {
        const double r = (ds->y[i] - w->yhat[i]) / (ds->sigma ? ds->sigma[i] : 1.0);
        c += 0.5 * r * r;
        s += w->yhat[i];
    }
    *cost = c;
    *sum = s;
    return 0;
}

int phc_study_cost(phc_study_eval *w, const double *x, double *cost)
{
    double total = 0;
    for (size_t d = 0; d < w->pb->n_datasets; ++d) {
        double c, s;
        if (predict_dataset(w, d, x, &c, &s) != 0) {
            *cost = NAN;
            return 1;
        }
        total += c;
    }
    *cost = total;
    return isfinite(total) ? 0 : 1;
}

int phc_study_evaluate(phc_study_eval *w, const double *x, double *out)
{
    const phc_problem *pb = w->pb;
    const size_t n_out = phc_study_outputs(pb), m = per_dataset(pb), named = 1 + m * pb->n_datasets;
    size_t series = named + pb->n_outputs;
    out[0] = 0;
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        phc_dataset *ds = pb->datasets[d];
        double cost, sum;
        if (predict_dataset(w, d, x, &cost, &sum) != 0)
            goto failed;
        if (m == 2)
            out[1 + 2 * d] = cost;
        out[1 + m * d + (m - 1)] = ds->n ? sum / (double)ds->n : NAN;
        out[0] += cost;
        for (size_t o = 0; o < pb->n_outputs; ++o) {
            const phc_named_output *no = &pb->outputs[o];
            if (no->dataset != d)
                continue;
            double v;
            if (no->observation) {
                v = w->yhat[no->observation - 1];
            } else if (ds->ops->predict_at) {
                if (ds->ops->predict_at(ds, w->p, &no->at, 1, &v) != 0)
                    goto failed;
            } else {
                const size_t i = w->interp_i[o];
                const double f = w->interp_w[o];
                v = f > 0 ? (1 - f) * w->yhat[i] + f * w->yhat[i + 1] : w->yhat[i];
            }
            out[named + o] = v;
        }
        const size_t T = phc_study_series_points(pb, d);
        for (size_t t = 0; t < T; ++t)
            out[series++] = w->yhat[phc_study_series_observation(pb, d, t)];
    }
    for (size_t j = 0; j < n_out; ++j)
        if (!isfinite(out[j]))
            goto failed;
    return 0;
failed:
    for (size_t j = 0; j < n_out; ++j)
        out[j] = NAN;
    return 1;
}

/* ---- the study -------------------------------------------------------------------------- */

typedef struct study {
    const phc_problem *pb;
    const phc_study_options *o;
    size_t k;            /* columns: the free parameters */
    size_t *col_param;   /* k parameter indices */
    size_t *group_of;    /* k factor indices */
    size_t n_factors;
    char **factor_names; /* n_factors */
    phc_prior *prior;    /* k, resolved, in the user's unit */
    size_t n_out;
    size_t n_scalar;     /* outputs 0 .. n_scalar-1 are scalar; the rest the series */
    size_t *series_first; /* per data set: its first series output */
    char **out_names;
    phc_saltelli_design *saltelli;
    phc_morris_design *morris;
    size_t rows;
    double *y;           /* rows x n_out */
    unsigned char *state;
    phc_sobol_indices *sobol;   /* n_out */
    phc_morris_effects *effects; /* n_out */
    phc_sobol_indices *summary; /* Sobol: per data set, the aggregated indices of its series (n_series 0: none) */
    char **keys, **values;       /* ledger identity */
    size_t n_keys;
} study;

static void study_free(study *s)
{
    free(s->col_param);
    free(s->group_of);
    if (s->factor_names)
        for (size_t g = 0; g < s->n_factors; ++g)
            free(s->factor_names[g]);
    free(s->factor_names);
    free(s->prior);
    if (s->out_names)
        for (size_t j = 0; j < s->n_out; ++j)
            free(s->out_names[j]);
    free(s->out_names);
    phc_saltelli_design_free(s->saltelli);
    phc_morris_design_free(s->morris);
    free(s->y);
    free(s->state);
    if (s->sobol)
        for (size_t j = 0; j < s->n_out; ++j)
            phc_sobol_indices_clear(&s->sobol[j]);
    free(s->sobol);
    if (s->effects)
        for (size_t j = 0; j < s->n_out; ++j)
            phc_morris_effects_clear(&s->effects[j]);
    free(s->effects);
    if (s->summary)
        for (size_t d = 0; d < s->pb->n_datasets; ++d)
            phc_sobol_indices_clear(&s->summary[d]);
    free(s->summary);
    free(s->series_first);
    for (size_t i = 0; i < s->n_keys; ++i) {
        free(s->keys[i]);
        free(s->values[i]);
    }
    free(s->keys);
    free(s->values);
}

/* "cfg.yaml:12: parameter 'k'" (or without the place when built by hand). */
static void param_place(const phc_problem *pb, const phc_parameter *p, size_t line, char *buf, size_t size)
{
    if (pb->source && line)
        snprintf(buf, size, "%s:%zu: parameter '%s'", pb->source, line, p->name);
    else
        snprintf(buf, size, "parameter '%s'", p->name);
}

/* Columns, factors and priors. */
static int study_factors(study *s, phc_error *err)
{
    const phc_problem *pb = s->pb;
    s->col_param = malloc((pb->n_params ? pb->n_params : 1) * sizeof *s->col_param);
    s->group_of = malloc((pb->n_params ? pb->n_params : 1) * sizeof *s->group_of);
    s->factor_names = calloc(pb->n_params ? pb->n_params : 1, sizeof *s->factor_names);
    s->prior = calloc(pb->n_params ? pb->n_params : 1, sizeof *s->prior);
    size_t *group_factor = malloc((pb->n_groups ? pb->n_groups : 1) * sizeof *group_factor);
    int rc = PHC_OK;
    if (!s->col_param || !s->group_of || !s->factor_names || !s->prior || !group_factor) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t g = 0; g < pb->n_groups; ++g) {
        group_factor[g] = (size_t)-1;
        for (size_t m = 0; m < pb->groups[g].n_members; ++m) {
            const phc_parameter *p = &pb->params[pb->groups[g].members[m]];
            if (p->fixed) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: groups: group '%s': parameter '%s' is fixed; a "
                                   "study varies only free parameters", pb->source ? pb->source : "config",
                                   pb->groups[g].config_line, pb->groups[g].name, p->name);
                goto done;
            }
        }
    }
    for (size_t i = 0; i < pb->n_params; ++i) {
        const phc_parameter *p = &pb->params[i];
        if (p->fixed)
            continue;
        const size_t c = s->k++;
        s->col_param[c] = i;
        long grp = -1;
        for (size_t g = 0; g < pb->n_groups && grp < 0; ++g)
            for (size_t m = 0; m < pb->groups[g].n_members; ++m)
                if (pb->groups[g].members[m] == i)
                    grp = (long)g;
        if (grp >= 0 && group_factor[grp] != (size_t)-1) {
            s->group_of[c] = group_factor[grp];
        } else {
            const size_t f = s->n_factors++;
            s->group_of[c] = f;
            if (grp >= 0)
                group_factor[grp] = f;
            if (!(s->factor_names[f] = strdup(grp >= 0 ? pb->groups[grp].name : p->name))) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto done;
            }
        }
        /* the prior is in the user's unit: so are the bounds it is truncated to */
        double lo, hi;
        phc_parameter_user_bounds(p, &lo, &hi);
        char what[600];
        param_place(pb, p, p->prior_line ? p->prior_line : p->config_line, what, sizeof what);
        if ((rc = phc_prior_resolve(&p->prior, lo, hi, what, &s->prior[c], err)))
            goto done;
    }
    if (s->k == 0)
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: every parameter is fixed: a sensitivity study has nothing to "
                           "vary", pb->source ? pb->source : "problem");
done:
    free(group_factor);
    return rc;
}

/* Global parameter values (slot units) of unit-cube point u. */
static void point_values(const study *s, const double *u, double *x)
{
    const phc_problem *pb = s->pb;
    for (size_t i = 0; i < pb->n_params; ++i)
        x[i] = pb->params[i].value;
    for (size_t c = 0; c < s->k; ++c) {
        const phc_parameter *p = &pb->params[s->col_param[c]];
        x[s->col_param[c]] = p->unit_scale * phc_prior_quantile(&s->prior[c], u[c]) + p->unit_offset;
    }
}

/* A malloc'd formatted string (NULL when out of memory). */
static char *vformat(const char *fmt, va_list ap)
{
    va_list ap2;
    va_copy(ap2, ap);
    const int n = vsnprintf(NULL, 0, fmt, ap2);
    va_end(ap2);
    char *text = n < 0 ? NULL : malloc((size_t)n + 1);
    if (text)
        vsnprintf(text, (size_t)n + 1, fmt, ap);
    return text;
}

static int add_key(study *s, const char *key, const char *fmt, ...)
{
    char **k = realloc(s->keys, (s->n_keys + 1) * sizeof *k);
    if (!k)
        return -1;
    s->keys = k;
    char **v = realloc(s->values, (s->n_keys + 1) * sizeof *v);
    if (!v)
        return -1;
    s->values = v;
    va_list ap;
    va_start(ap, fmt);
    char *text = vformat(fmt, ap);
    va_end(ap);
    if (!text)
        return -1;
    for (char *c = text; *c; ++c)
        if (*c == '\t' || *c == '\n')
            *c = ' ';
    s->keys[s->n_keys] = strdup(key);
    s->values[s->n_keys] = text;
    if (!s->keys[s->n_keys])
        return -1;
    s->n_keys++;
    return 0;
}

/* Appends text to *buf (malloc'd, grown). */
static int append(char **buf, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *more = vformat(fmt, ap);
    va_end(ap);
    if (!more)
        return -1;
    const size_t n = strlen(more);
    const size_t old = *buf ? strlen(*buf) : 0;
    char *grown = realloc(*buf, old + n + 1);
    if (!grown) {
        free(more);
        return -1;
    }
    memcpy(grown + old, more, n + 1);
    free(more);
    *buf = grown;
    return 0;
}

/* What identifies the study in its ledger: the method and design, the
 * factors, priors and outputs, the config and data (SHA-256). */
static int study_identity(study *s, const phc_provenance *pv)
{
    const phc_study_options *o = s->o;
    int bad = 0;
    bad |= add_key(s, "method", "%s", o->method == PHC_STUDY_MORRIS ? "morris" : "sobol");
    if (o->method == PHC_STUDY_MORRIS)
        bad |= add_key(s, "design", "morris-1991 levels=%u", o->levels);
    else
        bad |= add_key(s, "design", "saltelli %s second-order=%d", o->randomised ? "mt19937" : "gsl-sobol",
                       o->second_order);
    bad |= add_key(s, "samples", "%zu", o->samples);
    bad |= add_key(s, "seed", "%lu", o->seed);
    bad |= add_key(s, "rows", "%zu", s->rows);
    char *text = NULL;
    for (size_t c = 0; c < s->k; ++c) {
        const phc_prior *p = &s->prior[c];
        bad |= append(&text, "%s%s=%s(%.17g,%.17g)[%.17g,%.17g]@%s", c ? "," : "",
                      s->pb->params[s->col_param[c]].name, phc_prior_kind_name(p->kind), p->a, p->b, p->lower,
                      p->upper, s->factor_names[s->group_of[c]]);
    }
    bad |= add_key(s, "factors", "%s", text ? text : "");
    free(text);
    text = NULL;
    /* the scalar outputs by name (a named one with where it is), then per
       data set how many of its observations are outputs: a line that says
       what differs when another config's ledger is refused */
    for (size_t j = 0; j < s->n_scalar; ++j) {
        bad |= append(&text, "%s%s", j ? "," : "", s->out_names[j]);
        const size_t named = s->n_scalar - s->pb->n_outputs;
        if (j >= named) {
            const phc_named_output *no = &s->pb->outputs[j - named];
            char label[512];
            dataset_label(s->pb, no->dataset, label, sizeof label);
            if (no->observation)
                bad |= append(&text, "=%s@%zu", label, no->observation);
            else
                bad |= append(&text, "=%s(x=%.17g)", label, no->at);
        }
    }
    for (size_t d = 0; d < s->pb->n_datasets; ++d) {
        char label[512];
        dataset_label(s->pb, d, label, sizeof label);
        bad |= append(&text, ",%s@[%zu of %zu observations]", label, phc_study_series_points(s->pb, d),
                      s->pb->datasets[d]->n);
    }
    bad |= add_key(s, "outputs", "%s", text ? text : "");
    free(text);
    /* last: a refused ledger names the setting that differs before the
       config's hash, which differs with any edit */
    bad |= add_key(s, "config-sha256", "%s", pv && pv->config ? pv->config->sha256 : "none");
    char *inputs = NULL;
    if (pv)
        for (size_t i = 0; i < pv->n_inputs; ++i)
            bad |= append(&inputs, "%s%s", i ? "," : "", pv->inputs[i].sha256);
    bad |= add_key(s, "data-sha256", "%s", inputs ? inputs : "none");
    free(inputs);

    return bad ? -1 : 0;
}

static json_t *jnum(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

static json_t *jinterval(double lo, double hi)
{
    return json_pack("[o, o]", jnum(lo), jnum(hi));
}

/* Verdict of factor g over the scalar outputs and (Sobol) the summaries
 * of the series: 2 matters (in some output), 0 does not matter (in every
 * output), 1 unclear; `where` lists the outputs where it matters. */
static int factor_verdict(const study *s, size_t g, char **where)
{
    int matters = 0, all_below = 1;
    const size_t n_summary = s->summary ? s->pb->n_datasets : 0;
    for (size_t j = 0; j < s->n_scalar + n_summary; ++j) {
        if (s->sobol) {
            const phc_sobol_indices *r = j < s->n_scalar ? &s->sobol[j] : &s->summary[j - s->n_scalar];
            if (!r->st || !isfinite(r->st[g]))
                continue;
            if (r->st[g] >= ST_MATTERS) {
                matters = 1;
                char label[512] = "";
                if (j >= s->n_scalar)
                    dataset_label(s->pb, j - s->n_scalar, label, sizeof label);
                append(where, "%s%s%s (ST %.2f)", *where ? ", " : "", j < s->n_scalar ? s->out_names[j] : label,
                       j < s->n_scalar ? "" : " over x", r->st[g]);
            }
            if (!(r->st_hi[g] < ST_MATTERS))
                all_below = 0;
        } else {
            const phc_morris_effects *e = &s->effects[j];
            double top = 0;
            for (size_t h = 0; h < s->n_factors; ++h)
                top = e->mu_star[h] > top ? e->mu_star[h] : top;
            if (!(top > 0))
                continue;
            if (e->mu_star[g] >= MU_STAR_MATTERS * top) {
                matters = 1;
                append(where, "%s%s (mu* %.3g of %.3g)", *where ? ", " : "", s->out_names[j], e->mu_star[g], top);
            }
            if (!(e->mu_star_hi[g] < MU_STAR_MATTERS * top))
                all_below = 0;
        }
    }
    return matters ? 2 : all_below ? 0 : 1;
}

static char *verdict_text(const study *s)
{
    char *text = NULL, *none = NULL, *unclear = NULL;
    for (size_t g = 0; g < s->n_factors; ++g) {
        char *where = NULL;
        const int v = factor_verdict(s, g, &where);
        if (v == 2)
            append(&text, "matters: %s, for %s\n", s->factor_names[g], where);
        else if (v == 0)
            append(&none, "%s%s", none ? ", " : "", s->factor_names[g]);
        else
            append(&unclear, "%s%s", unclear ? ", " : "", s->factor_names[g]);
        free(where);
    }
    if (none)
        append(&text, "does not matter: %s (%s below %g in every output)\n", none,
               s->sobol ? "ST's 95% interval" : "mu*'s 95% interval relative to the largest mu*",
               s->sobol ? ST_MATTERS : MU_STAR_MATTERS);
    if (unclear)
        append(&text, "unclear: %s (the interval reaches the threshold: more samples decide)\n", unclear);
    free(none);
    free(unclear);
    return text;
}

/* An array of the n values v[i * stride] (NAN as null). */
static json_t *jarray(const double *v, size_t n, size_t stride)
{
    json_t *a = json_array();
    for (size_t i = 0; i < n; ++i)
        json_array_append_new(a, jnum(v[i * stride]));
    return a;
}

/* Data set d's series: its observations, x, the mean and variance of the
 * prediction at each, per factor the indices at each as arrays, and (Sobol)
 * their summary over x. */
static json_t *json_series(const study *s, size_t d)
{
    const phc_problem *pb = s->pb;
    const phc_dataset *ds = pb->datasets[d];
    const size_t T = phc_study_series_points(pb, d), j0 = s->series_first[d], f = s->n_factors;
    char label[512];
    dataset_label(pb, d, label, sizeof label);
    json_t *obs = json_array(), *x = json_array(), *o = json_object(), *idx = json_object();
    double *v = malloc((T ? T : 1) * 2 * sizeof *v);
    for (size_t t = 0; t < T; ++t) {
        const size_t i = phc_study_series_observation(pb, d, t);
        json_array_append_new(obs, json_integer((json_int_t)i + 1));
        json_array_append_new(x, ds->x ? jnum(ds->x[i]) : json_integer((json_int_t)i + 1));
    }
    json_object_set_new(o, "dataset", json_string(label));
    json_object_set_new(o, "x_label", ds->x_label ? json_string(ds->x_label) : json_null());
    json_object_set_new(o, "observations", obs);
    json_object_set_new(o, "of_observations", json_integer((json_int_t)ds->n));
    json_object_set_new(o, "x", x);
    if (!v)
        return o;
    if (s->sobol) {
        for (size_t t = 0; t < T; ++t) {
            v[t] = s->sobol[j0 + t].mean;
            v[T + t] = s->sobol[j0 + t].variance;
        }
        json_object_set_new(o, "mean", jarray(v, T, 1));
        json_object_set_new(o, "variance", jarray(v + T, T, 1));
    }
    for (size_t g = 0; g < f; ++g) {
        json_t *fg = json_object();
        /* one array per key: the index at each of the T observations */
#define SERIES_FIELD(key, expr)                                                                                   \
    do {                                                                                                          \
        for (size_t t = 0; t < T; ++t)                                                                            \
            v[t] = (expr);                                                                                        \
        json_object_set_new(fg, key, jarray(v, T, 1));                                                            \
    } while (0)
        if (s->sobol) {
            SERIES_FIELD("S1", s->sobol[j0 + t].s1[g]);
            SERIES_FIELD("S1_ci95_lower", s->sobol[j0 + t].s1_lo[g]);
            SERIES_FIELD("S1_ci95_upper", s->sobol[j0 + t].s1_hi[g]);
            SERIES_FIELD("ST", s->sobol[j0 + t].st[g]);
            SERIES_FIELD("ST_ci95_lower", s->sobol[j0 + t].st_lo[g]);
            SERIES_FIELD("ST_ci95_upper", s->sobol[j0 + t].st_hi[g]);
        } else {
            SERIES_FIELD("mu_star", s->effects[j0 + t].mu_star[g]);
            SERIES_FIELD("mu_star_ci95_lower", s->effects[j0 + t].mu_star_lo[g]);
            SERIES_FIELD("mu_star_ci95_upper", s->effects[j0 + t].mu_star_hi[g]);
            SERIES_FIELD("mu", s->effects[j0 + t].mu[g]);
            SERIES_FIELD("sigma", s->effects[j0 + t].sigma[g]);
        }
#undef SERIES_FIELD
        json_object_set_new(idx, s->factor_names[g], fg);
    }
    free(v);
    json_object_set_new(o, "indices", idx);
    if (s->summary && s->summary[d].s1) {
        const phc_sobol_indices *r = &s->summary[d];
        json_t *sum = json_object(), *si = json_object();
        json_object_set_new(sum, "estimator", json_string("generalised indices sum_t V_t S_t / sum_t V_t (Lamboni "
                                                          "et al. 2011; Gamboa et al. 2013)"));
        json_object_set_new(sum, "total_variance", jnum(r->variance));
        for (size_t g = 0; g < f; ++g)
            json_object_set_new(si, s->factor_names[g],
                                json_pack("{s:o, s:o, s:o, s:o}", "S1", jnum(r->s1[g]), "S1_ci95",
                                          jinterval(r->s1_lo[g], r->s1_hi[g]), "ST", jnum(r->st[g]), "ST_ci95",
                                          jinterval(r->st_lo[g], r->st_hi[g])));
        json_object_set_new(sum, "indices", si);
        json_object_set_new(o, "summary", sum);
    }
    return o;
}

static int write_json(const study *s, const phc_study_summary *sum, const char *path, phc_error *err)
{
    const phc_study_options *o = s->o;
    json_t *root = json_object(), *factors = json_array(), *params = json_object(), *outs = json_array();
    json_object_set_new(root, "study",
                        json_pack("{s:s, s:s, s:I, s:I, s:b, s:I, s:I, s:I, s:f}", "method",
                                  o->method == PHC_STUDY_MORRIS ? "morris" : "sobol", "design",
                                  o->method == PHC_STUDY_MORRIS ? "morris-1991"
                                  : o->randomised              ? "saltelli-mt19937"
                                                               : "saltelli-gsl-sobol",
                                  "samples", (json_int_t)o->samples, "seed", (json_int_t)o->seed, "second_order",
                                  o->second_order, "levels", (json_int_t)o->levels, "evaluations",
                                  (json_int_t)sum->evaluations, "failed_evaluations", (json_int_t)sum->failed,
                                  "interval_level", 0.95));
    for (size_t g = 0; g < s->n_factors; ++g) {
        json_t *members = json_array();
        for (size_t c = 0; c < s->k; ++c)
            if (s->group_of[c] == g)
                json_array_append_new(members, json_string(s->pb->params[s->col_param[c]].name));
        json_array_append_new(factors, json_pack("{s:s, s:o}", "name", s->factor_names[g], "parameters", members));
    }
    for (size_t c = 0; c < s->k; ++c) {
        const phc_parameter *p = &s->pb->params[s->col_param[c]];
        const phc_prior *q = &s->prior[c];
        json_object_set_new(params, p->name,
                            json_pack("{s:o, s:{s:s, s:o, s:o, s:o, s:o}}", "unit",
                                      p->unit ? json_string(p->unit) : json_null(), "prior", "dist",
                                      phc_prior_kind_name(q->kind), "a", jnum(q->a), "b", jnum(q->b), "lower",
                                      jnum(q->lower), "upper", jnum(q->upper)));
    }
    for (size_t j = 0; j < s->n_scalar; ++j) {
        json_t *idx = json_object(), *o_j = json_object();
        json_object_set_new(o_j, "name", json_string(s->out_names[j]));
        if (s->sobol) {
            const phc_sobol_indices *r = &s->sobol[j];
            json_object_set_new(o_j, "mean", jnum(r->mean));
            json_object_set_new(o_j, "variance", jnum(r->variance));
            json_object_set_new(o_j, "base_samples_used", json_integer((json_int_t)r->n_used));
            json_object_set_new(o_j, "base_samples_failed", json_integer((json_int_t)r->n_failed));
            for (size_t g = 0; g < s->n_factors; ++g)
                json_object_set_new(idx, s->factor_names[g],
                                    json_pack("{s:o, s:o, s:o, s:o}", "S1", jnum(r->s1[g]), "S1_ci95",
                                              jinterval(r->s1_lo[g], r->s1_hi[g]), "ST", jnum(r->st[g]), "ST_ci95",
                                              jinterval(r->st_lo[g], r->st_hi[g])));
            if (r->s2) {
                json_t *s2 = json_object();
                const size_t f = s->n_factors;
                for (size_t a = 0; a < f; ++a)
                    for (size_t b = a + 1; b < f; ++b) {
                        char key[512];
                        snprintf(key, sizeof key, "%s|%s", s->factor_names[a], s->factor_names[b]);
                        json_object_set_new(s2, key, json_pack("{s:o, s:o}", "S2", jnum(r->s2[a * f + b]), "S2_ci95",
                                                               jinterval(r->s2_lo[a * f + b], r->s2_hi[a * f + b])));
                    }
                json_object_set_new(o_j, "second_order", s2);
            }
        } else if (s->effects) {
            const phc_morris_effects *e = &s->effects[j];
            json_object_set_new(o_j, "trajectories_used", json_integer((json_int_t)e->n_used));
            json_object_set_new(o_j, "trajectories_failed", json_integer((json_int_t)e->n_failed));
            for (size_t g = 0; g < s->n_factors; ++g)
                json_object_set_new(idx, s->factor_names[g],
                                    json_pack("{s:o, s:o, s:o, s:o, s:o, s:o}", "mu_star", jnum(e->mu_star[g]),
                                              "mu_star_ci95", jinterval(e->mu_star_lo[g], e->mu_star_hi[g]), "mu",
                                              jnum(e->mu[g]), "mu_ci95", jinterval(e->mu_lo[g], e->mu_hi[g]),
                                              "sigma", jnum(e->sigma[g]), "sigma_ci95",
                                              jinterval(e->sigma_lo[g], e->sigma_hi[g])));
        }
        json_object_set_new(o_j, "indices", idx);
        json_array_append_new(outs, o_j);
    }
    json_object_set_new(root, "factors", factors);
    json_object_set_new(root, "parameters", params);
    json_object_set_new(root, "outputs", outs);
    json_t *series = json_array();
    for (size_t d = 0; d < s->pb->n_datasets; ++d)
        if (phc_study_series_points(s->pb, d))
            json_array_append_new(series, json_series(s, d));
    json_object_set_new(root, "series", series);
    json_t *verdict = json_array();
    for (size_t g = 0; g < s->n_factors; ++g) {
        char *where = NULL;
        const int v = factor_verdict(s, g, &where);
        json_array_append_new(verdict, json_pack("{s:s, s:s}", "factor", s->factor_names[g], "verdict",
                                                 v == 2 ? "matters" : v == 0 ? "does not matter" : "unclear"));
        free(where);
    }
    json_object_set_new(root, "verdict", verdict);
    int rc = phc_json_file_write(root, path, err);
    json_decref(root);
    return rc;
}

/* The report's section on data set d's indices per observation. */
static int report_series(const study *s, size_t d, char **md)
{
    const phc_problem *pb = s->pb;
    const phc_dataset *ds = pb->datasets[d];
    const size_t T = phc_study_series_points(pb, d), j0 = s->series_first[d];
    if (T == 0)
        return 0;
    char label[512], base[256];
    dataset_label(pb, d, label, sizeof label);
    phc_run_dir_safe_name(label, base, sizeof base);
    const char *xl = ds->x_label ? ds->x_label : "x";
    int bad = 0;
    bad |= append(md, "\n## Over x: `%s`\n\nx: %s. Indices of the prediction at %s%zu observation%s%s, plotted "
                      "against x in `%s_over_x.png`; result.json holds them as arrays under `series`.",
                  label, xl, T == ds->n ? "each of the " : "", T, T == 1 ? "" : "s",
                  T == ds->n ? "" : " (evenly spaced among its observations)", base);
    if (T != ds->n)
        bad |= append(md, " The data set has %zu observations; `--points` sets how many are outputs.", ds->n);
    if (s->summary && s->summary[d].s1) {
        const phc_sobol_indices *r = &s->summary[d];
        bad |= append(md, " Over x: the generalised indices sum_t V_t S_t / sum_t V_t (Lamboni et al. 2011; "
                          "Gamboa et al. 2013), which weight each observation by the variance of its "
                          "prediction (summed variance %.6g).\n\n| factor | S1 over x | 95%% interval | ST over x | "
                          "95%% interval | largest ST | at x |\n|---|---|---|---|---|---|---|\n", r->variance);
        for (size_t g = 0; g < s->n_factors; ++g) {
            size_t best = 0;
            for (size_t t = 1; t < T; ++t)
                if (s->sobol[j0 + t].st[g] > s->sobol[j0 + best].st[g] || !isfinite(s->sobol[j0 + best].st[g]))
                    best = t;
            const size_t i = phc_study_series_observation(pb, d, best);
            bad |= append(md, "| %s | %.4f | [%.4f, %.4f] | %.4f | [%.4f, %.4f] | %.4f | %.6g |\n",
                          s->factor_names[g], r->s1[g], r->s1_lo[g], r->s1_hi[g], r->st[g], r->st_lo[g],
                          r->st_hi[g], s->sobol[j0 + best].st[g], ds->x ? ds->x[i] : (double)(i + 1));
        }
    } else if (s->effects) {
        bad |= append(md, "\n\n| factor | largest mu* | 95%% interval | at x |\n|---|---|---|---|\n");
        for (size_t g = 0; g < s->n_factors; ++g) {
            size_t best = 0;
            for (size_t t = 1; t < T; ++t)
                if (s->effects[j0 + t].mu_star[g] > s->effects[j0 + best].mu_star[g])
                    best = t;
            const size_t i = phc_study_series_observation(pb, d, best);
            const phc_morris_effects *e = &s->effects[j0 + best];
            bad |= append(md, "| %s | %.6g | [%.6g, %.6g] | %.6g |\n", s->factor_names[g], e->mu_star[g],
                          e->mu_star_lo[g], e->mu_star_hi[g], ds->x ? ds->x[i] : (double)(i + 1));
        }
    } else {
        bad |= append(md, "\n");
    }
    bad |= append(md, "\n![%s over x](%s_over_x.png)\n", label, base);
    return bad;
}

static int write_report(const study *s, const phc_study_summary *sum, const phc_provenance *pv, const char *path,
                        phc_error *err)
{
    const phc_study_options *o = s->o;
    char *md = NULL;
    int bad = 0;
    bad |= append(&md, "# Sensitivity study: %s\n\n", s->pb->name ? s->pb->name : "");
    if (o->method == PHC_STUDY_MORRIS)
        bad |= append(&md, "Method: Morris elementary effects (Morris 1991; mu* of Campolongo et al. 2007), "
                           "%zu trajectories on a %u-level grid, seed %lu.\n", o->samples, o->levels, o->seed);
    else
        bad |= append(&md, "Method: Sobol indices from a Saltelli design (first order: Saltelli 2010; total: Jansen "
                           "1999%s), N = %zu base samples from %s, bootstrap seed %lu.\n",
                      o->second_order ? "; second order: Saltelli 2002" : "", o->samples,
                      o->randomised ? "a Mersenne Twister" : "GSL's Sobol sequence", o->seed);
    bad |= append(&md, "\nEvaluations: %zu (%zu computed in this run, %zu from the ledger); failed after one retry: "
                       "%zu.\n\n", sum->evaluations, sum->computed, sum->reused, sum->failed);
    bad |= append(&md, "## Verdict\n\n");
    char *v = verdict_text(s);
    for (char *line = v; line && *line;) {
        char *nl = strchr(line, '\n');
        if (nl)
            *nl = '\0';
        bad |= append(&md, "- %s\n", line);
        line = nl ? nl + 1 : line + strlen(line);
    }
    free(v);
    bad |= append(&md, "\nRule: %s\n\n## Factors\n\n| factor | parameter | prior (user unit) | unit |\n|---|---|---|---|\n",
                  s->sobol ? "a factor matters when its total index ST is at least 0.05 for some output, and does "
                             "not matter when the 95% interval of ST stays below 0.05 for every output."
                           : "a factor matters when its mu* is at least 10% of the output's largest mu*, and does "
                             "not matter when the 95% interval of mu* stays below that for every output.");
    for (size_t c = 0; c < s->k; ++c) {
        const phc_parameter *p = &s->pb->params[s->col_param[c]];
        const phc_prior *q = &s->prior[c];
        bad |= append(&md, "| %s | %s | %s(%.6g, %.6g) on [%.6g, %.6g] | %s |\n", s->factor_names[s->group_of[c]],
                      p->name, phc_prior_kind_name(q->kind), q->a, q->b, q->lower, q->upper, p->unit ? p->unit : "");
    }
    for (size_t j = 0; j < s->n_scalar; ++j) {
        bad |= append(&md, "\n## Output `%s`\n\n", s->out_names[j]);
        if (s->sobol) {
            const phc_sobol_indices *r = &s->sobol[j];
            bad |= append(&md, "mean %.6g, variance %.6g over the design; %zu base samples used, %zu left out "
                               "(failed evaluations).\n\n| factor | S1 | 95%% interval | ST | 95%% interval |\n"
                               "|---|---|---|---|---|\n", r->mean, r->variance, r->n_used, r->n_failed);
            for (size_t g = 0; g < s->n_factors; ++g)
                bad |= append(&md, "| %s | %.4f | [%.4f, %.4f] | %.4f | [%.4f, %.4f] |\n", s->factor_names[g],
                              r->s1[g], r->s1_lo[g], r->s1_hi[g], r->st[g], r->st_lo[g], r->st_hi[g]);
            if (r->s2) {
                bad |= append(&md, "\n| pair | S2 | 95%% interval |\n|---|---|---|\n");
                const size_t f = s->n_factors;
                for (size_t a = 0; a < f; ++a)
                    for (size_t b = a + 1; b < f; ++b)
                        bad |= append(&md, "| %s, %s | %.4f | [%.4f, %.4f] |\n", s->factor_names[a], s->factor_names[b],
                                      r->s2[a * f + b], r->s2_lo[a * f + b], r->s2_hi[a * f + b]);
            }
        } else {
            const phc_morris_effects *e = &s->effects[j];
            bad |= append(&md, "%zu trajectories used, %zu left out (failed evaluations).\n\n"
                               "| factor | mu* | 95%% interval | mu | sigma |\n|---|---|---|---|---|\n",
                          e->n_used, e->n_failed);
            for (size_t g = 0; g < s->n_factors; ++g)
                bad |= append(&md, "| %s | %.6g | [%.6g, %.6g] | %.6g | %.6g |\n", s->factor_names[g], e->mu_star[g],
                              e->mu_star_lo[g], e->mu_star_hi[g], e->mu[g], e->sigma[g]);
        }
        char base[256];
        phc_run_dir_safe_name(s->out_names[j], base, sizeof base);
        bad |= append(&md, "\n![%s](%s_sensitivity.png)\n", s->out_names[j], base);
    }
    for (size_t d = 0; d < s->pb->n_datasets; ++d)
        bad |= report_series(s, d, &md);
    char *prov = NULL;
    if (pv && phc_provenance_markdown(pv, &prov, err) == PHC_OK && prov) {
        bad |= append(&md, "\n%s", prov);
        free(prov);
    }
    if (bad) {
        free(md);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    phc_atomic_file *af = NULL;
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc == PHC_OK) {
        fputs(md, phc_atomic_file_stream(af));
        rc = phc_atomic_file_commit(af, err);
    }
    free(md);
    return rc;
}

/* Data set d's indices against x: S1 and ST (Sobol) or mu* (Morris) per
 * factor with their bootstrap bands. */
static int plot_series(const study *s, size_t d, const char *tmpdir, phc_error *err)
{
    const phc_problem *pb = s->pb;
    const phc_dataset *ds = pb->datasets[d];
    const size_t T = phc_study_series_points(pb, d), j0 = s->series_first[d], f = s->n_factors;
    if (T == 0)
        return PHC_OK;
    char label[512], base[256], path[8192], title[700];
    dataset_label(pb, d, label, sizeof label);
    phc_run_dir_safe_name(label, base, sizeof base);
    snprintf(path, sizeof path, "%s/%s_over_x.png", tmpdir, base);
    const size_t panels = s->sobol ? 2 : 1, per = 3; /* value, lower and upper end per line */
    double *buf = malloc((T + panels * f * per * T) * sizeof *buf);
    phc_band_line *lines = malloc(panels * f * sizeof *lines);
    if (!buf || !lines) {
        free(buf);
        free(lines);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    double *xs = buf;
    for (size_t t = 0; t < T; ++t) {
        const size_t i = phc_study_series_observation(pb, d, t);
        xs[t] = ds->x ? ds->x[i] : (double)(i + 1);
    }
    for (size_t q = 0; q < panels; ++q)
        for (size_t g = 0; g < f; ++g) {
            double *v = buf + T + ((q * f + g) * per) * T, *lo = v + T, *hi = v + 2 * T;
            for (size_t t = 0; t < T; ++t) {
                if (s->sobol) {
                    const phc_sobol_indices *r = &s->sobol[j0 + t];
                    v[t] = q ? r->st[g] : r->s1[g];
                    lo[t] = q ? r->st_lo[g] : r->s1_lo[g];
                    hi[t] = q ? r->st_hi[g] : r->s1_hi[g];
                } else {
                    const phc_morris_effects *e = &s->effects[j0 + t];
                    v[t] = e->mu_star[g];
                    lo[t] = e->mu_star_lo[g];
                    hi[t] = e->mu_star_hi[g];
                }
            }
            lines[q * f + g] = (phc_band_line){s->factor_names[g], v, lo, hi};
        }
    const char *ylab_sobol[2] = {"first-order index S1", "total index ST"};
    const char *ylab_morris[1] = {"mu* (mean |elementary effect|)"};
    if (s->sobol)
        snprintf(title, sizeof title, "Sobol indices of %s's prediction (N = %zu, %zu of %zu observations)", label,
                 s->o->samples, T, ds->n);
    else
        snprintf(title, sizeof title, "Morris mu* of %s's prediction (r = %zu, %zu of %zu observations)", label,
                 s->o->samples, T, ds->n);
    const int rc = phc_plot_index_lines(path, title, ds->x_label ? ds->x_label : "observation", xs, T,
                                        s->sobol ? ylab_sobol : ylab_morris, panels, lines, f, err);
    free(buf);
    free(lines);
    return rc;
}

static int write_plots(const study *s, const char *tmpdir, phc_error *err)
{
    for (size_t d = 0; d < s->pb->n_datasets; ++d) {
        const int rc = plot_series(s, d, tmpdir, err);
        if (rc)
            return rc;
    }
    for (size_t j = 0; j < s->n_scalar; ++j) {
        char base[256], path[8192], title[512];
        phc_run_dir_safe_name(s->out_names[j], base, sizeof base);
        snprintf(path, sizeof path, "%s/%s_sensitivity.png", tmpdir, base);
        int rc;
        if (s->sobol) {
            const phc_sobol_indices *r = &s->sobol[j];
            const phc_bar_series series[2] = {{"first order S1", r->s1, r->s1_lo, r->s1_hi},
                                              {"total ST", r->st, r->st_lo, r->st_hi}};
            snprintf(title, sizeof title, "Sobol indices of %s (N = %zu)", s->out_names[j], s->o->samples);
            rc = phc_plot_bars(path, title, "Sobol index", (const char *const *)s->factor_names, s->n_factors, series,
                               2, err);
        } else {
            const phc_morris_effects *e = &s->effects[j];
            const phc_bar_series series[2] = {{"mu* (mean |EE|)", e->mu_star, e->mu_star_lo, e->mu_star_hi},
                                              {"sigma (sd of EE)", e->sigma, e->sigma_lo, e->sigma_hi}};
            snprintf(title, sizeof title, "Morris effects on %s (r = %zu)", s->out_names[j], s->o->samples);
            rc = phc_plot_bars(path, title, "elementary effect (per grid unit)",
                               (const char *const *)s->factor_names, s->n_factors, series, 2, err);
        }
        if (rc)
            return rc;
    }
    return PHC_OK;
}

/* Copies the ledger into the run directory. */
static int copy_file(const char *from, const char *to, phc_error *err)
{
    FILE *in = fopen(from, "rb");
    if (!in)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open: %s", from, strerror(errno));
    phc_atomic_file *af = NULL;
    int rc = phc_atomic_file_open(to, &af, err);
    if (rc) {
        fclose(in);
        return rc;
    }
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        fwrite(buf, 1, n, phc_atomic_file_stream(af));
    const int bad = ferror(in);
    fclose(in);
    if (bad) {
        phc_atomic_file_abort(af);
        return phc_error_set(err, PHC_ERR_IO, "%s: read error", from);
    }
    return phc_atomic_file_commit(af, err);
}

/* ---- the evaluation loop: one process, or distributed (study_dist.h) ----------------------- */

typedef struct loop {
    study *s;
    phc_study_eval *w;
    double *x, *u;
    phc_run_ledger *ledger;
    const char *ledger_path;
    phc_study_summary *summary;
    size_t found, report_every;
} loop;

/* Evaluates design row r into out; 1 when it failed twice. */
static int eval_row(void *ctx, size_t r, double *out)
{
    loop *l = ctx;
    if (l->s->saltelli)
        phc_saltelli_design_point(l->s->saltelli, r, l->u);
    else
        phc_morris_design_point(l->s->morris, r, l->u);
    point_values(l->s, l->u, l->x);
    int failed = phc_study_evaluate(l->w, l->x, out);
    if (failed) /* once more: a transient failure (none of today's models has one) gets a second chance */
        failed = phc_study_evaluate(l->w, l->x, out);
    return failed;
}

/* Records row r: the ledger, the outputs, progress; stops the study after
 * stop_after new evaluations (while rows remain) or when cancelled. */
static int record_row(void *ctx, size_t r, int failed, const double *out, phc_error *err)
{
    loop *l = ctx;
    study *s = l->s;
    const phc_study_options *o = s->o;
    int rc = phc_run_ledger_append(l->ledger, r, failed, out, err);
    if (rc)
        return rc;
    memcpy(s->y + r * s->n_out, out, s->n_out * sizeof *out);
    s->state[r] = failed ? PHC_LEDGER_FAILED : PHC_LEDGER_OK;
    const size_t done = l->found + ++l->summary->computed;
    /* the count goes in the detail, not as steps: a log gets a line every
       few seconds rather than one per evaluation (and is formatted only then) */
    if (l->summary->computed % l->report_every == 0 || done == s->rows) {
        char count[96];
        snprintf(count, sizeof count, "%zu of %zu evaluations", done, s->rows);
        if (phc_progress_report(o->progress, o->progress_data, "evaluating", 0, 0, -1, NAN, count))
            return phc_error_set(err, PHC_ERR_INTERNAL, "cancelled; %s holds the finished evaluations: --resume "
                                 "continues", l->ledger_path);
    }
    if (o->stop_after && l->summary->computed >= o->stop_after && done < s->rows)
        return phc_error_set(err, PHC_ERR_INTERNAL, "stopped after %zu new evaluations (stop_after); %s holds them: "
                             "--resume continues", l->summary->computed, l->ledger_path);
    return PHC_OK;
}

int phc_study_run(const phc_problem *pb, const phc_study_options *opts, const phc_provenance *pv, const char *dir,
                  phc_study_summary *summary, phc_error *err)
{
    memset(summary, 0, sizeof *summary);
    phc_study_options o = *opts;
    if (o.samples == 0)
        o.samples = o.method == PHC_STUDY_MORRIS ? 20 : 512;
    study s;
    memset(&s, 0, sizeof s);
    s.pb = pb;
    s.o = &o;
    s.n_out = phc_study_outputs(pb);
    s.n_scalar = phc_study_scalar_outputs(pb);
    phc_run_ledger *ledger = NULL;
    phc_study_eval *w = NULL;
    phc_dist *dist = o.dist;
    int agreed = 0; /* with dist: every rank agrees once (study_dist.h), here or at done */
    double *x = NULL, *u = NULL, *out = NULL;
    char ledger_path[4200], tmpdir[4096] = "";
    int rc;
    if ((rc = study_factors(&s, err)))
        goto done;
    if (!(s.series_first = malloc((pb->n_datasets ? pb->n_datasets : 1) * sizeof *s.series_first))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t d = 0, j = s.n_scalar; d < pb->n_datasets; ++d) {
        s.series_first[d] = j;
        j += phc_study_series_points(pb, d);
    }
    if (!(s.out_names = calloc(s.n_out, sizeof *s.out_names))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t j = 0; j < s.n_out; ++j) {
        char name[512];
        phc_study_output_name(pb, j, name, sizeof name);
        if (!(s.out_names[j] = strdup(name))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
    if (o.method == PHC_STUDY_MORRIS) {
        phc_morris_options mo = phc_morris_options_default();
        mo.trajectories = o.samples;
        mo.levels = o.levels;
        mo.seed = o.seed;
        if ((rc = phc_morris_design_new(s.k, s.group_of, s.n_factors, &mo, &s.morris, err)))
            goto done;
        s.rows = phc_morris_design_rows(s.morris);
    } else {
        phc_saltelli_options so = phc_saltelli_options_default();
        so.n = o.samples;
        so.second_order = o.second_order;
        so.randomised = o.randomised;
        so.seed = o.seed;
        if ((rc = phc_saltelli_design_new(s.k, s.group_of, s.n_factors, &so, &s.saltelli, err)))
            goto done;
        s.rows = phc_saltelli_design_rows(s.saltelli);
    }
    if (study_identity(&s, pv)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    s.y = malloc(s.rows * s.n_out * sizeof *s.y);
    s.state = malloc(s.rows);
    x = malloc((pb->n_params ? pb->n_params : 1) * sizeof *x);
    u = malloc(s.k * sizeof *u);
    out = malloc(s.n_out * sizeof *out);
    w = phc_study_eval_new(pb);
    if (!s.y || !s.state || !x || !u || !out || !w) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    snprintf(ledger_path, sizeof ledger_path, "%s.ledger", dir);
    summary->evaluations = s.rows;
    loop lp = {&s, w, x, u, NULL, ledger_path, summary, 0, s.rows / 200 ? s.rows / 200 : 1};
    if (dist && dist->rank != 0) { /* a worker: no ledger, no directory; evaluates what the master sends */
        agreed = 1;
        if ((rc = dist->agree(dist, PHC_OK, err)) == PHC_OK)
            rc = dist->run(dist, s.n_out, NULL, 0, eval_row, NULL, &lp, err);
        goto done;
    }
    if ((rc = phc_run_dir_make_parents(ledger_path, err)) ||
        (rc = phc_run_ledger_open(ledger_path, (const char *const *)s.keys, (const char *const *)s.values, s.n_keys,
                                  s.rows, s.n_out, o.resume, o.force, s.y, s.state, &lp.found, &ledger, err)))
        goto done;
    lp.ledger = ledger;
    summary->reused = lp.found;
    if (dist) {
        agreed = 1;
        size_t *pending = malloc((s.rows - lp.found ? s.rows - lp.found : 1) * sizeof *pending), n_pending = 0;
        rc = pending ? PHC_OK : phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t r = 0; pending && r < s.rows; ++r)
            if (s.state[r] == PHC_LEDGER_PENDING)
                pending[n_pending++] = r;
        if ((rc = dist->agree(dist, rc, err)) == PHC_OK)
            rc = dist->run(dist, s.n_out, pending, n_pending, eval_row, record_row, &lp, err);
        free(pending);
        if (rc)
            goto done;
    } else {
        for (size_t r = 0; r < s.rows; ++r)
            if (s.state[r] == PHC_LEDGER_PENDING && (rc = record_row(&lp, r, eval_row(&lp, r, out), out, err)))
                goto done;
    }
    if ((rc = phc_run_ledger_close(ledger, err))) {
        ledger = NULL;
        goto done;
    }
    ledger = NULL;
    for (size_t r = 0; r < s.rows; ++r)
        summary->failed += s.state[r] == PHC_LEDGER_FAILED;
    /* estimates: per output, from the column y[., j] */
    phc_progress_report(o.progress, o.progress_data, "estimating", 0, 0, -1, NAN, NULL);
    double *col = malloc(s.rows * sizeof *col);
    if (s.saltelli)
        s.sobol = calloc(s.n_out, sizeof *s.sobol);
    else
        s.effects = calloc(s.n_out, sizeof *s.effects);
    if (!col || (!s.sobol && !s.effects)) {
        free(col);
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* Sobol: all outputs at once, and per data set the summary of its series
       over x (aggregated indices), all on the same bootstrap resamples */
    if (s.saltelli && !(s.summary = calloc(pb->n_datasets ? pb->n_datasets : 1, sizeof *s.summary)))
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (s.saltelli && rc == PHC_OK) {
        size_t *first = malloc((pb->n_datasets ? pb->n_datasets : 1) * 2 * sizeof *first), n_agg = 0;
        if (!first) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        } else {
            size_t *count = first + (pb->n_datasets ? pb->n_datasets : 1);
            for (size_t d = 0; d < pb->n_datasets; ++d)
                if (phc_study_series_points(pb, d)) {
                    first[n_agg] = s.series_first[d];
                    count[n_agg++] = phc_study_series_points(pb, d);
                }
            phc_sobol_indices *agg = calloc(n_agg ? n_agg : 1, sizeof *agg);
            if (!agg)
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            else
                rc = phc_sobol_indices_estimate_study(s.saltelli, s.y, s.n_out, s.sobol, n_agg, first, count, agg,
                                                      err);
            for (size_t d = 0, a = 0; d < pb->n_datasets && agg; ++d)
                if (phc_study_series_points(pb, d))
                    s.summary[d] = agg[a++]; /* the arrays move to the summary */
            free(agg);
            free(first);
        }
    }
    for (size_t j = 0; j < s.n_out && rc == PHC_OK && !s.saltelli; ++j) {
        for (size_t r = 0; r < s.rows; ++r)
            col[r] = s.y[r * s.n_out + j];
        rc = phc_morris_estimate(s.morris, col, &s.effects[j], err);
    }
    free(col);
    if (rc)
        goto done;
    if (!(summary->verdict = verdict_text(&s))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    phc_progress_report(o.progress, o.progress_data, "writing", 0, 0, -1, NAN, dir);
    if ((rc = phc_run_dir_begin(dir, o.force, pb, tmpdir, sizeof tmpdir, err)))
        goto done;
    char path[8400];
    snprintf(path, sizeof path, "%s/result.json", tmpdir);
    if ((rc = write_json(&s, summary, path, err)))
        goto discard;
    snprintf(path, sizeof path, "%s/report.md", tmpdir);
    if ((rc = write_report(&s, summary, pv, path, err)))
        goto discard;
    if ((rc = write_plots(&s, tmpdir, err)))
        goto discard;
    snprintf(path, sizeof path, "%s/ledger.tsv", tmpdir);
    if ((rc = copy_file(ledger_path, path, err)))
        goto discard;
    if ((rc = phc_run_dir_commit(tmpdir, dir, pv, err)))
        goto done;
    unlink(ledger_path); /* its copy is in the run directory */
    goto done;
discard:
    phc_run_dir_discard(tmpdir);
done:
    if (dist && !agreed) /* failed before the loop: the other ranks must not wait for this one */
        dist->agree(dist, rc ? rc : phc_error_set(err, PHC_ERR_INTERNAL, "study ended before its loop"), err);
    if (ledger) {
        phc_error ignored;
        phc_run_ledger_close(ledger, &ignored);
    }
    phc_study_eval_free(w);
    free(x);
    free(u);
    free(out);
    study_free(&s);
    return rc;
}
