/* `phytocal profile`: see profile_study.h. */
#include "fit/profile_study.h"

#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/engine/fit.h"
#include "fit/json_file_internal.h"
#include "fit/plot_file.h"
#include "fit/profile_plots.h"
#include "fit/run_dir.h"
#include "fit/study_dist.h"
#include "measurements/atomic_file.h"

phc_profile_study_options phc_profile_study_options_default(void)
{
    phc_profile_study_options o;
    memset(&o, 0, sizeof o);
    o.level = 0.95;
    o.points = 12;
    return o;
}

void phc_profile_summary_clear(phc_profile_summary *s)
{
    if (!s)
        return;
    free(s->table);
    free(s->verdict);
    memset(s, 0, sizeof *s);
}

static int append(char **buf, const char *fmt, ...)
{
    va_list ap, ap2;
    va_start(ap, fmt);
    va_copy(ap2, ap);
    const int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0) {
        va_end(ap2);
        return -1;
    }
    const size_t old = *buf ? strlen(*buf) : 0;
    char *grown = realloc(*buf, old + (size_t)n + 1);
    if (!grown) {
        va_end(ap2);
        return -1;
    }
    vsnprintf(grown + old, (size_t)n + 1, fmt, ap2);
    va_end(ap2);
    *buf = grown;
    return 0;
}

/* One parameter's profile in the user's unit, and its verdict. */
typedef struct row {
    const char *name, *unit;
    double value, wald_lo, wald_hi;
    double lo, hi;                 /* profile ends (user unit) */
    phc_profile_end lo_end, hi_end;
    int flat, disagree;
    double *theta;                 /* n, user unit, ascending */
    const double *delta;
    size_t n, inner_fits, failed_fits;
    double min_delta;
} row;

static const char *end_name(phc_profile_end e)
{
    return e == PHC_PROFILE_CROSSED ? "crossed" : e == PHC_PROFILE_AT_BOUND ? "at_bound" : "open";
}

static void verdict_of(const row *r, char *buf, size_t size)
{
    if (r->flat)
        snprintf(buf, size, "practically non-identifiable (flat profile)");
    else if (r->lo_end != PHC_PROFILE_CROSSED || r->hi_end != PHC_PROFILE_CROSSED) {
        const char *lo = r->lo_end == PHC_PROFILE_AT_BOUND ? "open to the lower bound"
                         : r->lo_end == PHC_PROFILE_OPEN   ? "open below"
                                                           : NULL;
        const char *hi = r->hi_end == PHC_PROFILE_AT_BOUND ? "open to the upper bound"
                         : r->hi_end == PHC_PROFILE_OPEN   ? "open above"
                                                           : NULL;
        snprintf(buf, size, "%s%s%s", lo ? lo : "", lo && hi ? ", " : "", hi ? hi : "");
    } else if (!isfinite(r->wald_lo) || !isfinite(r->wald_hi))
        snprintf(buf, size, "Wald interval not determined (rank-deficient fit); the profile interval is finite");
    else if (r->disagree)
        snprintf(buf, size, "profile and Wald intervals disagree");
    else
        snprintf(buf, size, "profile and Wald intervals agree");
}

static int disagrees(const row *r)
{
    if (r->lo_end != PHC_PROFILE_CROSSED || r->hi_end != PHC_PROFILE_CROSSED)
        return 1;
    if (!isfinite(r->wald_lo) || !isfinite(r->wald_hi))
        return 1;
    const double wl = r->value - r->wald_lo, wh = r->wald_hi - r->value;
    return fabs(r->lo - r->wald_lo) > PHC_PROFILE_DISAGREE * wl || fabs(r->hi - r->wald_hi) > PHC_PROFILE_DISAGREE * wh;
}

static json_t *jnum(double v) { return isfinite(v) ? json_real(v) : json_null(); }

static json_t *jarray(const double *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; i < n; ++i)
        json_array_append_new(a, jnum(v[i]));
    return a;
}

static int write_text(const char *path, const char *text, phc_error *err)
{
    phc_atomic_file *af = NULL;
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc == PHC_OK) {
        fputs(text, phc_atomic_file_stream(af));
        rc = phc_atomic_file_commit(af, err);
    }
    return rc;
}

static int write_json(const phc_problem *pb, const phc_fit_result *fr, const phc_profile_result *pr, const row *rows,
                      const char *path, phc_error *err)
{
    json_t *root = json_object();
    json_object_set_new(root, "command", json_string("profile"));
    json_object_set_new(root, "name", json_string(pb->name ? pb->name : ""));
    json_object_set_new(root, "level", json_real(pr->level));
    json_object_set_new(root, "absolute_sigma", json_boolean(pr->absolute_sigma));
    json_object_set_new(root, "n_obs", json_integer((json_int_t)pr->n_obs));
    json_object_set_new(root, "n_free", json_integer((json_int_t)pr->n_free));
    json_object_set_new(root, "best_cost", json_real(pr->best_cost));
    json_object_set_new(root, "threshold_delta_cost", jnum(pr->threshold));
    json_object_set_new(root, "threshold_rule",
                        json_string(pr->absolute_sigma ? "chi2_1(level) / 2" : "cost F_{1,n-p}(level) / (n - p)"));
    json_object_set_new(root, "fit_status", json_string(phc_fit_status_name(fr->summary.outcome)));
    json_t *params = json_array();
    for (size_t k = 0; k < pr->n_profiles; ++k) {
        const row *r = &rows[k];
        char v[128];
        verdict_of(r, v, sizeof v);
        json_t *o = json_object();
        json_object_set_new(o, "name", json_string(r->name));
        json_object_set_new(o, "unit", r->unit ? json_string(r->unit) : json_null());
        json_object_set_new(o, "value", jnum(r->value));
        json_object_set_new(o, "wald_ci", json_pack("[o, o]", jnum(r->wald_lo), jnum(r->wald_hi)));
        json_object_set_new(o, "profile_ci", json_pack("[o, o]", r->lo_end == PHC_PROFILE_CROSSED ? jnum(r->lo)
                                                                                                    : json_null(),
                                                       r->hi_end == PHC_PROFILE_CROSSED ? jnum(r->hi) : json_null()));
        json_object_set_new(o, "reached", json_pack("[o, o]", jnum(r->lo), jnum(r->hi)));
        json_object_set_new(o, "lower_end", json_string(end_name(r->lo_end)));
        json_object_set_new(o, "upper_end", json_string(end_name(r->hi_end)));
        json_object_set_new(o, "flat", json_boolean(r->flat));
        json_object_set_new(o, "disagrees_with_wald", json_boolean(r->disagree));
        json_object_set_new(o, "verdict", json_string(v));
        json_object_set_new(o, "inner_fits", json_integer((json_int_t)r->inner_fits));
        json_object_set_new(o, "failed_inner_fits", json_integer((json_int_t)r->failed_fits));
        json_object_set_new(o, "theta", jarray(r->theta, r->n));
        json_object_set_new(o, "delta_cost", jarray(r->delta, r->n));
        json_array_append_new(params, o);
    }
    json_object_set_new(root, "parameters", params);
    int rc = phc_json_file_write(root, path, err);
    json_decref(root);
    return rc;
}

static int build_texts(const phc_problem *pb, const phc_profile_result *pr, const row *rows,
                       const phc_provenance *pv, phc_profile_summary *sum, char **report, phc_error *err)
{
    int bad = 0;
    char *md = NULL;
    bad |= append(&md, "# Profile likelihood: %s\n\n", pb->name ? pb->name : "");
    bad |= append(&md,
                  "Each free parameter is fixed on a grid stepping away from the optimum while Ceres re-optimises "
                  "the others; the %.0f%% interval is where the profile cost rises by the likelihood-ratio "
                  "threshold %.6g (%s; %zu observations, %zu free parameters, best cost %.6g).  Wald intervals "
                  "are those of `fit` (estimate +- t se).\n\n",
                  100 * pr->level, pr->threshold,
                  pr->absolute_sigma ? "absolute sigmas: chi2_1 / 2"
                                     : "sigma estimated: F test as lmfit's conf_interval, cost F_{1,n-p} / (n - p)",
                  pr->n_obs, pr->n_free, pr->best_cost);
    bad |= append(&md, "## Verdict\n\n");
    for (size_t k = 0; k < pr->n_profiles; ++k) {
        char v[128];
        verdict_of(&rows[k], v, sizeof v);
        bad |= append(&sum->verdict, "%s: %s\n", rows[k].name, v);
        bad |= append(&md, "- %s: %s\n", rows[k].name, v);
        if (rows[k].min_delta < -1e-6 * pr->threshold) {
            bad |= append(&sum->verdict, "%s: its profile found a cost %.6g below the fit's optimum: the fit "
                                         "was not at the global minimum\n", rows[k].name, -rows[k].min_delta);
            bad |= append(&md, "- %s: its profile found a cost %.6g below the fit's optimum: the fit was not at "
                                "the global minimum\n", rows[k].name, -rows[k].min_delta);
        }
    }
    bad |= append(&md, "\nRule: the intervals disagree when an end differs by more than %.0f%% of the Wald "
                       "half-width on its side, or a side is open; a profile is flat (practically "
                       "non-identifiable) when it stays below 1%% of the threshold where it was traced.\n\n",
                  100 * PHC_PROFILE_DISAGREE);
    bad |= append(&md, "## Intervals\n\n| parameter | unit | estimate | Wald %.0f%% | profile %.0f%% | ends | points "
                       "(inner fits, failed) |\n|---|---|---|---|---|---|---|\n",
                  100 * pr->level, 100 * pr->level);
    bad |= append(&sum->table, "%-14s %12s  %-29s  %-29s  %s\n", "parameter", "estimate", "Wald interval",
                  "profile interval", "verdict");
    for (size_t k = 0; k < pr->n_profiles; ++k) {
        const row *r = &rows[k];
        char lo[40], hi[40], v[128];
        if (r->lo_end == PHC_PROFILE_CROSSED)
            snprintf(lo, sizeof lo, "%.6g", r->lo);
        else
            snprintf(lo, sizeof lo, "open (%.4g)", r->lo);
        if (r->hi_end == PHC_PROFILE_CROSSED)
            snprintf(hi, sizeof hi, "%.6g", r->hi);
        else
            snprintf(hi, sizeof hi, "open (%.4g)", r->hi);
        verdict_of(r, v, sizeof v);
        bad |= append(&md, "| %s | %s | %.6g | [%.6g, %.6g] | [%s, %s] | %s, %s | %zu (%zu, %zu) |\n", r->name,
                      r->unit ? r->unit : "", r->value, r->wald_lo, r->wald_hi, lo, hi, end_name(r->lo_end),
                      end_name(r->hi_end), r->n, r->inner_fits, r->failed_fits);
        char wald[64], prof[96];
        snprintf(wald, sizeof wald, "[%.6g, %.6g]", r->wald_lo, r->wald_hi);
        snprintf(prof, sizeof prof, "[%s, %s]", lo, hi);
        bad |= append(&sum->table, "%-14s %12.6g  %-29s  %-29s  %s\n", r->name, r->value, wald, prof, v);
    }
    bad |= append(&md, "\n");
    for (size_t k = 0; k < pr->n_profiles; ++k) {
        char base[256];
        phc_run_dir_safe_name(rows[k].name, base, sizeof base);
        bad |= append(&md, "![profile of %s](profile_%s.png)\n", rows[k].name, base);
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
    *report = md;
    return PHC_OK;
}

int phc_profile_study_run(phc_problem *pb, const phc_profile_study_options *o, phc_provenance *pv,
                          const char *dir, phc_profile_summary *summary, phc_error *err)
{
    memset(summary, 0, sizeof *summary);
    phc_fit_result *fr = NULL;
    phc_profile_result *pr = NULL;
    row *rows = NULL;
    double *x0 = NULL, *step = NULL;
    char *report = NULL;
    int rc = PHC_OK, before = 1; /* before phc_profile_run: under MPI this layer agrees on a failure */
    size_t n_free = 0;
    for (size_t i = 0; i < pb->n_params; ++i)
        n_free += !pb->params[i].fixed;
    if (o->points < 3)
        rc = phc_error_set(err, PHC_ERR_INPUT, "--points: %zu is too few; a profile needs at least 3 per side",
                           o->points);
    else if (!(o->level > 0.0 && o->level < 1.0))
        rc = phc_error_set(err, PHC_ERR_INPUT, "--level: %g is not between 0 and 1", o->level);
    else if (n_free == 0)
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: no free parameter to profile (every parameter is fixed)",
                           pb->source ? pb->source : pb->name);
    else
        rc = phc_fit_run(pb, o->progress, o->progress_data, &fr, err);
    if (rc)
        goto done;
    summary->fit_converged = fr->summary.outcome == PHC_NLS_CONVERGED;
    x0 = malloc(pb->n_params * sizeof *x0);
    step = malloc(pb->n_params * sizeof *step);
    if (!x0 || !step) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < pb->n_params; ++i) {
        const phc_param_result *p = &fr->params[i];
        x0[i] = p->unit_scale * p->value + p->unit_offset;
        step[i] = fabs(p->unit_scale) * p->stderr_;
    }
    phc_profile_options po = phc_profile_options_default();
    po.level = o->level;
    po.points = o->points;
    po.progress = o->progress;
    po.progress_data = o->progress_data;
    po.dist = o->dist;
    before = 0; /* phc_profile_run agrees, also when it fails */
    if ((rc = phc_profile_run(pb, x0, step, &po, &pr, err)))
        goto done;
    if (o->dist && o->dist->rank != 0) /* a worker: its profiles went to the master, which writes DIR */
        goto done;
    rows = calloc(pr->n_profiles, sizeof *rows);
    if (!rows) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    summary->n_params = pr->n_profiles;
    for (size_t k = 0; k < pr->n_profiles; ++k) {
        const phc_profile *p = &pr->profiles[k];
        const phc_param_result *q = &fr->params[p->param];
        row *r = &rows[k];
        const double a = q->unit_scale, b = q->unit_offset;
        r->name = q->name;
        r->unit = q->unit;
        r->value = (pr->best[p->param] - b) / a;
        r->wald_lo = q->ci_lo;
        r->wald_hi = q->ci_hi;
        r->delta = p->delta;
        r->n = p->n;
        r->inner_fits = p->inner_fits;
        r->failed_fits = p->failed_fits;
        r->min_delta = p->min_delta;
        r->flat = p->flat;
        if (!(r->theta = malloc((p->n ? p->n : 1) * sizeof *r->theta))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        for (size_t i = 0; i < p->n; ++i)
            r->theta[i] = (p->theta[i] - b) / a;
        r->lo = (p->lo - b) / a;
        r->hi = (p->hi - b) / a;
        r->lo_end = p->lo_end;
        r->hi_end = p->hi_end;
        r->disagree = disagrees(r);
        summary->n_disagree += r->disagree;
        summary->n_open += r->lo_end != PHC_PROFILE_CROSSED || r->hi_end != PHC_PROFILE_CROSSED;
        summary->n_flat += r->flat;
    }
    if (pv)
        phc_provenance_end(pv);
    if ((rc = build_texts(pb, pr, rows, pv, summary, &report, err)))
        goto done;
    phc_progress_report(o->progress, o->progress_data, "writing", 0, 0, -1, NAN, dir);
    char tmpdir[4200], path[8400];
    if ((rc = phc_run_dir_begin(dir, o->force, pb, tmpdir, sizeof tmpdir, err)))
        goto done;
    snprintf(path, sizeof path, "%s/result.json", tmpdir);
    if ((rc = write_json(pb, fr, pr, rows, path, err)))
        goto discard;
    snprintf(path, sizeof path, "%s/report.md", tmpdir);
    if ((rc = write_text(path, report, err)))
        goto discard;
    for (size_t k = 0; k < pr->n_profiles; ++k) {
        const row *r = &rows[k];
        char base[256];
        phc_run_dir_safe_name(r->name, base, sizeof base);
        snprintf(path, sizeof path, "%s/profile_%s.png", tmpdir, base);
        const phc_profile_plot pp = {r->name,
                                     r->unit,
                                     r->theta,
                                     r->delta,
                                     r->n,
                                     r->value,
                                     pr->threshold,
                                     pr->level,
                                     r->lo_end == PHC_PROFILE_CROSSED ? r->lo : NAN,
                                     r->hi_end == PHC_PROFILE_CROSSED ? r->hi : NAN,
                                     r->wald_lo,
                                     r->wald_hi};
        if ((rc = phc_plot_profile(path, &pp, err)))
            goto discard;
    }
    rc = phc_run_dir_commit(tmpdir, dir, pv, err);
    goto done;
discard:
    phc_run_dir_discard(tmpdir);
done:
    if (o->dist && before) /* failed before the profiles: the other ranks must not wait for this one */
        o->dist->agree(o->dist, rc, err);
    if (rows)
        for (size_t k = 0; pr && k < pr->n_profiles; ++k)
            free(rows[k].theta);
    free(rows);
    free(report);
    free(x0);
    free(step);
    phc_profile_result_free(pr);
    phc_fit_result_free(fr);
    return rc;
}
