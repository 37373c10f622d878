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
#include "fit/engine/prior.h"
#include "fit/engine/sobol_indices.h"
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
    double *p, *yhat; /* the largest data set's slots and observations */
};

/* Output layout: 0 the cost; then per data set its cost (only when there
 * are several: with one it is the cost) and its mean prediction. */
static size_t per_dataset(const phc_problem *pb)
{
    return pb->n_datasets > 1 ? 2 : 1;
}

size_t phc_study_outputs(const phc_problem *pb)
{
    return 1 + per_dataset(pb) * pb->n_datasets;
}

void phc_study_output_name(const phc_problem *pb, size_t j, char *buf, size_t size)
{
    const size_t m = per_dataset(pb);
    if (j == 0) {
        snprintf(buf, size, "cost");
        return;
    }
    const size_t d = (j - 1) / m;
    const char *what = m == 2 && (j - 1) % 2 == 0 ? "cost" : "mean";
    if (pb->datasets[d]->name)
        snprintf(buf, size, "%s.%s", pb->datasets[d]->name, what);
    else /* a data set built in C may have no name */
        snprintf(buf, size, "dataset-%zu.%s", d + 1, what);
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
    if (!w->p || !w->yhat) {
        phc_study_eval_free(w);
        return NULL;
    }
    return w;
}

void phc_study_eval_free(phc_study_eval *w)
{
    if (!w)
        return;
    free(w->p);
    free(w->yhat);
    free(w);
}

int phc_study_evaluate(phc_study_eval *w, const double *x, double *out)
{
    const phc_problem *pb = w->pb;
    const size_t n_out = phc_study_outputs(pb);
    out[0] = 0;
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        phc_dataset *ds = pb->datasets[d];
        for (size_t j = 0; j < ds->k; ++j)
            w->p[j] = x[ds->param_index[j]];
        if (ds->ops->predict(ds, w->p, w->yhat, NULL) != 0)
            goto failed;
        double cost = 0, sum = 0;
        for (size_t i = 0; i < ds->n; ++i) {
            const double r = (ds->y[i] - w->yhat[i]) / (ds->sigma ? ds->sigma[i] : 1.0);
            cost += 0.5 * r * r;
            sum += w->yhat[i];
        }
        const size_t m = per_dataset(pb);
        if (m == 2)
            out[1 + 2 * d] = cost;
        out[1 + m * d + (m - 1)] = ds->n ? sum / (double)ds->n : NAN;
        out[0] += cost;
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
    char **out_names;
    phc_saltelli_design *saltelli;
    phc_morris_design *morris;
    size_t rows;
    double *y;           /* rows x n_out */
    unsigned char *state;
    phc_sobol_indices *sobol;   /* n_out */
    phc_morris_effects *effects; /* n_out */
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
        double lo = p->lower, hi = p->upper;
        if (p->unit_scale != 1.0 || p->unit_offset != 0.0) {
            lo = (p->lower - p->unit_offset) / p->unit_scale;
            hi = (p->upper - p->unit_offset) / p->unit_scale;
            if (lo > hi) {
                const double t = lo;
                lo = hi;
                hi = t;
            }
        }
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

/* What identifies the study in its ledger: the config and data (SHA-256),
 * the method and design, the factors, priors and outputs. */
static int study_identity(study *s, const phc_provenance *pv)
{
    const phc_study_options *o = s->o;
    int bad = 0;
    bad |= add_key(s, "config-sha256", "%s", pv && pv->config ? pv->config->sha256 : "none");
    char *inputs = NULL;
    if (pv)
        for (size_t i = 0; i < pv->n_inputs; ++i)
            bad |= append(&inputs, "%s%s", i ? "," : "", pv->inputs[i].sha256);
    bad |= add_key(s, "data-sha256", "%s", inputs ? inputs : "none");
    free(inputs);
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
    for (size_t j = 0; j < s->n_out; ++j)
        bad |= append(&text, "%s%s", j ? "," : "", s->out_names[j]);
    bad |= add_key(s, "outputs", "%s", text ? text : "");
    free(text);
    return bad ? -1 : 0;
}

/* mkdir -p of the folder holding path. */
static int make_parents(const char *path, phc_error *err)
{
    char buf[4400];
    snprintf(buf, sizeof buf, "%s", path);
    char *slash = strrchr(buf, '/');
    if (!slash || slash == buf)
        return PHC_OK;
    *slash = '\0';
    for (char *c = buf + 1; *c; ++c)
        if (*c == '/') {
            *c = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return phc_error_set(err, PHC_ERR_IO, "%s: cannot create: %s", buf, strerror(errno));
            *c = '/';
        }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot create: %s", buf, strerror(errno));
    return PHC_OK;
}

static json_t *jnum(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

static json_t *jinterval(double lo, double hi)
{
    return json_pack("[o, o]", jnum(lo), jnum(hi));
}

/* Verdict of factor g over the outputs: 2 matters (in some output),
 * 0 does not matter (in every output), 1 unclear; `where` lists the
 * outputs where it matters. */
static int factor_verdict(const study *s, size_t g, char **where)
{
    int matters = 0, all_below = 1;
    for (size_t j = 0; j < s->n_out; ++j) {
        if (s->sobol) {
            const phc_sobol_indices *r = &s->sobol[j];
            if (!isfinite(r->st[g]))
                continue;
            if (r->st[g] >= ST_MATTERS) {
                matters = 1;
                append(where, "%s%s (ST %.2f)", *where ? ", " : "", s->out_names[j], r->st[g]);
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
    for (size_t j = 0; j < s->n_out; ++j) {
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
    json_t *verdict = json_array();
    for (size_t g = 0; g < s->n_factors; ++g) {
        char *where = NULL;
        const int v = factor_verdict(s, g, &where);
        json_array_append_new(verdict, json_pack("{s:s, s:s}", "factor", s->factor_names[g], "verdict",
                                                 v == 2 ? "matters" : v == 0 ? "does not matter" : "unclear"));
        free(where);
    }
    json_object_set_new(root, "verdict", verdict);
    phc_atomic_file *af = NULL;
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc == PHC_OK) {
        if (json_dumpf(root, phc_atomic_file_stream(af), JSON_INDENT(2) | JSON_REAL_PRECISION(17)) != 0) {
            phc_atomic_file_abort(af);
            rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
        } else {
            rc = phc_atomic_file_commit(af, err);
        }
    }
    json_decref(root);
    return rc;
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
    for (size_t j = 0; j < s->n_out; ++j) {
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

static int write_plots(const study *s, const char *tmpdir, phc_error *err)
{
    for (size_t j = 0; j < s->n_out; ++j) {
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
       few seconds rather than one per evaluation */
    char count[96];
    snprintf(count, sizeof count, "%zu of %zu evaluations", done, s->rows);
    if (l->summary->computed % l->report_every == 0 || done == s->rows)
        if (phc_progress_report(o->progress, o->progress_data, "evaluating", 0, 0, -1, NAN, count))
            return phc_error_set(err, PHC_ERR_INTERNAL, "cancelled; %s holds the finished evaluations: --resume "
                                 "continues", l->ledger_path);
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
    phc_run_ledger *ledger = NULL;
    phc_study_eval *w = NULL;
    phc_dist *dist = o.dist;
    int agreed = 0; /* with dist: every rank agrees once (study_dist.h), here or at done */
    double *x = NULL, *u = NULL, *out = NULL;
    char ledger_path[4200], tmpdir[4096] = "";
    int rc;
    if ((rc = study_factors(&s, err)))
        goto done;
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
    if ((rc = make_parents(ledger_path, err)) ||
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
    for (size_t j = 0; j < s.n_out && rc == PHC_OK; ++j) {
        for (size_t r = 0; r < s.rows; ++r)
            col[r] = s.y[r * s.n_out + j];
        rc = s.saltelli ? phc_sobol_indices_estimate(s.saltelli, col, &s.sobol[j], err)
                        : phc_morris_estimate(s.morris, col, &s.effects[j], err);
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
