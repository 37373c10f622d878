/* The residual report: see report.h. */
#include "fit/report.h"
#include "fit/engine/provenance.h"
#include "measurements/atomic_file.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int phc_report_all_passed(const phc_fit_result *res)
{
    return res->n_warnings == 0;
}

/* %g that prints "—" for NAN and "inf" plainly. */
static const char *fmt_num(char *buf, size_t size, double v)
{
    if (isnan(v))
        snprintf(buf, size, "—");
    else
        snprintf(buf, size, "%.6g", v);
    return buf;
}

static const char *fmt_p(char *buf, size_t size, double p)
{
    if (isnan(p))
        snprintf(buf, size, "—");
    else if (p < 1e-4)
        snprintf(buf, size, "%.1e", p);
    else
        snprintf(buf, size, "%.4f", p);
    return buf;
}

static void print_parameters_md(const phc_fit_result *res, FILE *f)
{
    char a[32], b[32], c[32], d[32], e[32], g[32];
    fprintf(f, "| parameter | value | std. error | 95%% interval | unit | note | sensitivity L1 | L2 |\n");
    fprintf(f, "|---|---:|---:|---|---|---|---:|---:|\n");
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *p = &res->params[i];
        const char *note = p->fixed ? "fixed" : p->at_bound < 0 ? "at lower bound" : p->at_bound > 0 ? "at upper bound"
                                            : isnan(p->stderr_)  ? "not determined"
                                                                 : "";
        fprintf(f, "| %s | %s | %s | [%s, %s] | %s | %s | %s | %s |\n", p->name, fmt_num(a, sizeof a, p->value),
                fmt_num(b, sizeof b, p->stderr_), fmt_num(c, sizeof c, p->ci_lo), fmt_num(d, sizeof d, p->ci_hi),
                p->unit ? p->unit : "", note, fmt_num(e, sizeof e, p->sens_l1), fmt_num(g, sizeof g, p->sens_l2));
    }
}

static void print_checks_md(const phc_dataset_result *d, double level, FILE *f)
{
    char a[32], b[32];
    fprintf(f, "| check | tests for | statistic | p-value | result (level %g) |\n", level);
    fprintf(f, "|---|---|---:|---:|---|\n");
    for (size_t c = 0; c < PHC_CHECK_COUNT; ++c) {
        const phc_check_result *ck = &d->checks[c];
        const char *na = c == PHC_CHECK_DAILY_CYCLE ? "n/a (needs a time series over ≥ 1.5 days)" : "n/a (too few points)";
        fprintf(f, "| %s | %s | %s | %s | %s |\n", ck->name, ck->what, fmt_num(a, sizeof a, ck->statistic),
                fmt_p(b, sizeof b, ck->p_value), !ck->applicable ? na : ck->pass ? "pass" : "**FAIL**");
    }
    /* time series: what the periodogram and the time-lag ACF saw */
    const phc_check_result *dc = &d->checks[PHC_CHECK_DAILY_CYCLE];
    char e[32];
    if (dc->applicable) {
        fprintf(f, "\nDaily cycle: the Lomb–Scargle periodogram of the standardised residuals (a line in time "
                   "removed) peaks at %s h within 22–26 h (normalised power %s, p = %s",
                fmt_num(a, sizeof a, d->cycle_period_h), fmt_num(b, sizeof b, dc->statistic),
                fmt_p(e, sizeof e, dc->p_value));
        if (isfinite(d->cycle_peak_hour))
            fprintf(f, "; a 24 h sinusoid fitted against the local clock peaks at %02d:%02d",
                    (int)lround(d->cycle_peak_hour * 60.0) % 1440 / 60, (int)lround(d->cycle_peak_hour * 60.0) % 60);
        fprintf(f, ").");
        if (isfinite(d->peak_period_h))
            fprintf(f, " Highest peak over all periods from %s h to the span: %s h (false-alarm probability %s, "
                       "Baluev 2008).",
                    fmt_num(a, sizeof a, 2.0 * d->acf_time_bin_h), fmt_num(b, sizeof b, d->peak_period_h),
                    fmt_p(e, sizeof e, d->peak_fap));
        fprintf(f, "\n");
    }
}

/* "converged", or "converged, not identifiable (rank 1 of 4)" when the
 * Jacobian is rank-deficient. */
static const char *status_text(const phc_fit_result *res, char *buf, size_t size)
{
    if (res->n_free && res->rank < res->n_free)
        snprintf(buf, size, "%s, not identifiable (rank %zu of %zu)", phc_fit_status_name(res->summary.outcome),
                 res->rank, res->n_free);
    else
        snprintf(buf, size, "%s", phc_fit_status_name(res->summary.outcome));
    return buf;
}

/* The model beside its baselines (baseline.h), on the same data and weights. */
static void print_baselines_md(const phc_dataset_result *d, FILE *f)
{
    if (!d->n_baselines)
        return;
    char v[4][32];
    fprintf(f, "\nBaselines fitted to the same data and weights (the model should beat each; the verdict warns "
               "when it does not):\n\n");
    fprintf(f, "| | parameters | weighted RSS | R² | AICc |\n|---|---:|---:|---:|---:|\n");
    fprintf(f, "| the model | %zu | %s | %s | %s |\n", d->goodness.k, fmt_num(v[0], 32, d->goodness.wrss),
            fmt_num(v[1], 32, d->goodness.r2), fmt_num(v[2], 32, d->goodness.aicc));
    for (size_t b = 0; b < d->n_baselines; ++b) {
        const phc_goodness *g = &d->baselines[b].goodness;
        fprintf(f, "| %s | %zu | %s | %s | %s |\n", d->baselines[b].what, g->k, fmt_num(v[0], 32, g->wrss),
                fmt_num(v[1], 32, g->r2), fmt_num(v[2], 32, g->aicc));
    }
}

static void print_goodness_md(const phc_dataset_result *d, FILE *f)
{
    const phc_goodness *g = &d->goodness;
    char v[12][32];
    fprintf(f, "| n | k | RSS | RMSE | MAE | bias | R² | NSE | reduced χ² | AIC | AICc | BIC |\n");
    fprintf(f, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    fprintf(f, "| %zu | %zu | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", d->n, d->k,
            fmt_num(v[0], 32, g->rss), fmt_num(v[1], 32, g->rmse), fmt_num(v[2], 32, g->mae),
            fmt_num(v[3], 32, g->bias), fmt_num(v[4], 32, g->r2), fmt_num(v[5], 32, g->nse),
            fmt_num(v[6], 32, g->reduced_chi2), fmt_num(v[7], 32, g->aic), fmt_num(v[8], 32, g->aicc),
            fmt_num(v[9], 32, g->bic));
}

int phc_report_write_markdown(const phc_fit_result *res, const char *path, const char *const *plots,
                              phc_error *err)
{
    phc_atomic_file *af = NULL;
    int rc = phc_atomic_file_open(path, &af, err);
    if (rc)
        return rc;
    FILE *f = phc_atomic_file_stream(af);
    char a[32], b[32];
    fprintf(f, "# Fit report: %s\n\n", res->name);
    fprintf(f, "## Verdict\n\n");
    if (res->n_warnings == 0) {
        fprintf(f, "**No problems found**: the solver converged, every parameter is determined, no parameter is at "
                   "a bound and no interval crosses one, no strong correlation or collinearity, the model beats "
                   "its baselines, and every residual check passes at level %g.\n\n",
                res->level);
    } else {
        fprintf(f, "**%zu warning%s** — read these before trusting the parameters:\n\n", res->n_warnings,
                res->n_warnings == 1 ? "" : "s");
        for (size_t i = 0; i < res->n_warnings; ++i)
            fprintf(f, "- %s\n", res->warnings[i]);
        fprintf(f, "\n");
    }
    fprintf(f, "## Solver\n\n");
    char st[96];
    fprintf(f, "- status: **%s** (%s)\n", status_text(res, st, sizeof st), res->summary.termination);
    fprintf(f, "- iterations: %d; residual evaluations: %d; Jacobian evaluations: %d\n", res->summary.iterations,
            res->summary.residual_evaluations, res->summary.jacobian_evaluations);
    fprintf(f, "- cost: initial %s, final %s (½ Σ ρ(r²) of weighted residuals)\n",
            fmt_num(a, sizeof a, res->summary.initial_cost), fmt_num(b, sizeof b, res->cost));
    if (res->starts > 1)
        fprintf(f, "- starts: %zu (Sobol points in the search box); %zu reached the best cost\n", res->starts,
                res->starts_at_best);
    if (res->rescue_starts)
        fprintf(f, "- the first start stalled (not converged, or a parameter with no effect on the model); "
                   "%zu rescue starts were added%s\n", res->rescue_starts,
                res->rescue_stopped ? " and then stopped: each stalled on a plateau again without a lower cost, "
                                      "so some parameter has no effect wherever the box was sampled" : "");
    fprintf(f, "- observations: %zu; free parameters: %zu; degrees of freedom: %ld\n", res->n_obs, res->n_free,
            res->dof);
    fprintf(f, "- variance factor s² = %s (%s)\n", fmt_num(a, sizeof a, res->s2),
            res->absolute_sigma ? "sigmas are absolute: s² = 1" : "weighted RSS / dof");
    fprintf(f, "- wall time: %.3g s\n\n", res->total_time);

    fprintf(f, "## Parameters\n\n");
    print_parameters_md(res, f);
    fprintf(f, "\nIntervals are value ± t(0.975, dof) · std. error. Sensitivity L1/L2: mean absolute and "
               "root-mean-square of ∂ŷ/∂p · p/σ over all observations (FME's sensFun summaries; σ is the "
               "observation's sigma, or the residual standard deviation when none is given).\n\n");

    fprintf(f, "## Identifiability\n\n");
    fprintf(f, "- rank of the Jacobian: %zu of %zu", res->rank, res->n_free);
    if (isfinite(res->condition))
        fprintf(f, "; condition number (column-scaled): %.3g", res->condition);
    fprintf(f, "\n");
    for (size_t i = 0; i < res->n_undetermined; ++i)
        fprintf(f, "- not determined by the data: %s\n", res->undetermined[i]);
    int any = 0;
    for (size_t x = 0; x < res->n_free; ++x)
        for (size_t y = x + 1; y < res->n_free; ++y) {
            const double c = res->correlation[x * res->n_free + y];
            if (fabs(c) > res->correlation_threshold) {
                fprintf(f, "- strong correlation: %s and %s, r = %.4f\n", res->params[res->free_index[x]].name,
                        res->params[res->free_index[y]].name, c);
                any = 1;
            }
        }
    if (!any)
        fprintf(f, "- no correlation above |r| = %g\n", res->correlation_threshold);
    const phc_sensitivity *s = &res->sensitivity;
    if (s->n_sets) {
        fprintf(f, "\nCollinearity index of parameter subsets (Brun et al. 2001; above %g the subset is poorly "
                   "identifiable). Largest:\n\n| parameters | index |\n|---|---:|\n",
                res->collinearity_threshold);
        for (size_t i = 0; i < s->n_sets && i < 10; ++i) {
            fprintf(f, "| ");
            for (size_t k = 0; k < s->sets[i].size; ++k)
                fprintf(f, "%s%s", k ? ", " : "", res->params[res->free_index[s->sets[i].index[k]]].name);
            fprintf(f, " | %s%s |\n", fmt_num(a, sizeof a, s->sets[i].gamma),
                    s->sets[i].gamma > res->collinearity_threshold ? " **high**" : "");
        }
    }
    if (res->n_free > 1) {
        fprintf(f, "\nCorrelation matrix:\n\n|   |");
        for (size_t y = 0; y < res->n_free; ++y)
            fprintf(f, " %s |", res->params[res->free_index[y]].name);
        fprintf(f, "\n|---|");
        for (size_t y = 0; y < res->n_free; ++y)
            fprintf(f, "---:|");
        fprintf(f, "\n");
        for (size_t x = 0; x < res->n_free; ++x) {
            fprintf(f, "| %s |", res->params[res->free_index[x]].name);
            for (size_t y = 0; y < res->n_free; ++y) {
                const double c = res->correlation[x * res->n_free + y];
                if (isnan(c))
                    fprintf(f, " — |");
                else
                    fprintf(f, " %.3f |", c);
            }
            fprintf(f, "\n");
        }
    }
    fprintf(f, "\n## Data sets\n");
    if (!plots)
        fprintf(f, "\nNo plots were drawn for this run (`--plots none`).\n");
    for (size_t d = 0; d < res->n_datasets; ++d) {
        const phc_dataset_result *ds = &res->datasets[d];
        fprintf(f, "\n### %s (%s)\n\n", ds->name, ds->kind);
        print_goodness_md(ds, f);
        print_baselines_md(ds, f);
        fprintf(f, "\nResidual checks (residuals ordered by %s):\n\n", ds->x_label);
        print_checks_md(ds, res->level, f);
        fprintf(f, "\n");
        if (ds->extra_markdown)
            fprintf(f, "%s\n", ds->extra_markdown);
        for (size_t i = 0; plots && plots[i]; ++i) {
            size_t len = strlen(ds->name);
            if (strncmp(plots[i], ds->name, len) == 0 && plots[i][len] == '_')
                fprintf(f, "![%s](%s)\n", plots[i], plots[i]);
        }
    }
    fprintf(f, "\n## How to read the checks\n\n"
               "- **runs** (Wald–Wolfowitz): too few sign changes along x means the model misses a trend.\n"
               "- **durbin_watson**: d near 2 is fine; d well below 2 means neighbouring residuals move together.\n"
               "- **ljung_box**: autocorrelation over the first lags together.\n"
               "- **shapiro_wilk** / **anderson_darling**: residuals far from normal make the intervals unreliable.\n"
               "- **breusch_pagan**: residual variance that grows or shrinks with the fitted value; "
               "consider per-point sigmas.\n"
               "- **daily_cycle** (time series over at least 1.5 days): the highest peak of the Lomb–Scargle "
               "periodogram of the residuals (Lomb 1976, Scargle 1982) with a period of 22–26 h, after removing "
               "a straight line in time; p is Baluev's (2008) false-alarm probability over that band. A failure "
               "means the residuals follow a 24-hour rhythm: the model misses something that differs between day "
               "and night (transpiration, light, temperature). The autocorrelation plot of a time series is drawn "
               "over time lags in hours (±1.96/√n band, 24 h marked), and when the local clock time is known the "
               "residuals are also plotted by time of day.\n");
    if (res->provenance) {
        char *md = NULL;
        int prc = phc_provenance_markdown(res->provenance, &md, err);
        if (prc) {
            phc_atomic_file_abort(af);
            return prc;
        }
        fprintf(f, "\n%s", md);
        free(md);
    }
    return phc_atomic_file_commit(af, err);
}

void phc_report_print_summary(const phc_fit_result *res, FILE *out)
{
    char a[32], b[32], c[32], d[32], st[96];
    fprintf(out, "%s: %s after %d iterations (%s)\n", res->name, status_text(res, st, sizeof st),
            res->summary.iterations, res->summary.termination);
    if (res->starts > 1)
        fprintf(out, "starts: %zu%s, %zu reached the best cost\n", res->starts,
                res->rescue_stopped  ? " (first start stalled: rescue starts added, stopped when they stalled too)"
                : res->rescue_starts ? " (first start stalled: rescue starts added)"
                                     : "",
                res->starts_at_best);
    fprintf(out, "%-16s %15s %13s %29s  %s\n", "parameter", "value", "std. error", "95% interval", "unit");
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *p = &res->params[i];
        char interval[80];
        snprintf(interval, sizeof interval, "[%s, %s]", fmt_num(c, sizeof c, p->ci_lo), fmt_num(d, sizeof d, p->ci_hi));
        fprintf(out, "%-16s %15s %13s %29s  %s%s\n", p->name, fmt_num(a, sizeof a, p->value),
                fmt_num(b, sizeof b, p->stderr_), interval, p->unit ? p->unit : "",
                p->fixed ? " (fixed)" : p->at_bound ? " (at bound)" : "");
    }
    for (size_t k = 0; k < res->n_datasets; ++k) {
        const phc_dataset_result *ds = &res->datasets[k];
        fprintf(out, "data set %s: n=%zu RMSE=%s R²=%s AICc=%s", ds->name, ds->n,
                fmt_num(a, sizeof a, ds->goodness.rmse), fmt_num(b, sizeof b, ds->goodness.r2),
                fmt_num(c, sizeof c, ds->goodness.aicc));
        int failed = 0;
        for (size_t i = 0; i < PHC_CHECK_COUNT; ++i)
            if (ds->checks[i].applicable && !ds->checks[i].pass)
                fprintf(out, "%s%s", failed++ ? ", " : "; failed: ", ds->checks[i].name);
        fprintf(out, "%s\n", failed ? "" : "; all residual checks pass");
        for (size_t bl = 1; bl < ds->n_baselines; ++bl) /* the kind's; the mean is what R² measures */
            fprintf(out, "  baseline: %s: R²=%s AICc=%s\n", ds->baselines[bl].what,
                    fmt_num(a, sizeof a, ds->baselines[bl].goodness.r2),
                    fmt_num(b, sizeof b, ds->baselines[bl].goodness.aicc));
    }
    if (res->n_warnings == 0)
        fprintf(out, "verdict: no problems found\n");
    else {
        fprintf(out, "verdict: %zu warning%s\n", res->n_warnings, res->n_warnings == 1 ? "" : "s");
        for (size_t i = 0; i < res->n_warnings; ++i)
            fprintf(out, "  - %s\n", res->warnings[i]);
    }
}
