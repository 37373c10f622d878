/* Cross-validation by the engine: see cross_validation.h. */
#include "fit/engine/cross_validation.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/engine/ceres_bridge.h"

void phc_cv_plan_clear(phc_cv_plan *plan)
{
    if (!plan)
        return;
    for (size_t g = 0; plan->names && g < plan->n_groups; ++g)
        free(plan->names[g]);
    free(plan->names);
    free(plan->group);
    free(plan->observed);
    memset(plan, 0, sizeof *plan);
}

void phc_cv_result_free(phc_cv_result *res)
{
    if (!res)
        return;
    for (size_t g = 0; res->names && g < res->n_groups; ++g)
        free(res->names[g]);
    free(res->names);
    free(res->observed);
    free(res->predicted);
    free(res->quantity);
    free(res->group_title);
    free(res->how);
    free(res->note);
    for (size_t k = 0; k < PHC_CV_MAX_PREDICTIONS; ++k)
        free(res->labels[k]);
    free(res);
}

static char *dup_or_null(const char *s, int *failed)
{
    char *d = s ? strdup(s) : NULL;
    if (s && !d)
        *failed = 1;
    return d;
}

/* An empty result shaped by the plan: names, observed values and texts
 * copied, predictions NAN. */
static phc_cv_result *result_new(const phc_cv_plan *plan)
{
    phc_cv_result *res = calloc(1, sizeof *res);
    if (!res)
        return NULL;
    const size_t ng = plan->n_groups, np = plan->n_predictions;
    int failed = 0;
    res->n_groups = ng;
    res->n_predictions = np;
    res->names = calloc(ng, sizeof *res->names);
    res->observed = malloc(ng * sizeof *res->observed);
    res->predicted = malloc(ng * np * sizeof *res->predicted);
    res->quantity = dup_or_null(plan->quantity ? plan->quantity : "the quantity", &failed);
    res->group_title = dup_or_null(plan->group_title ? plan->group_title : "group", &failed);
    res->how = dup_or_null(plan->how, &failed);
    res->note = dup_or_null(plan->note, &failed);
    for (size_t k = 0; k < np; ++k)
        res->labels[k] = dup_or_null(plan->labels[k] ? plan->labels[k] : k ? "baseline" : "model", &failed);
    if (failed || !res->names || !res->observed || !res->predicted) {
        phc_cv_result_free(res);
        return NULL;
    }
    for (size_t g = 0; g < ng; ++g) {
        if (!(res->names[g] = strdup(plan->names[g]))) {
            phc_cv_result_free(res);
            return NULL;
        }
        res->observed[g] = plan->observed[g];
    }
    for (size_t i = 0; i < ng * np; ++i)
        res->predicted[i] = NAN;
    return res;
}

/* The data set's residuals with those of the left-out group set to zero
 * (and their Jacobian rows, when given). */
typedef struct fold {
    phc_dataset *ds;
    const size_t *group;
    size_t left_out;
} fold;

static int fold_residuals(const double *p, double *r, double *jac, void *user)
{
    const fold *f = user;
    const phc_dataset *ds = f->ds;
    const int rc = phc_dataset_residuals(p, r, jac, f->ds);
    if (rc == 0)
        for (size_t i = 0; i < ds->n; ++i)
            if (f->group[i] == f->left_out) {
                r[i] = 0;
                if (jac)
                    memset(jac + i * ds->k, 0, ds->k * sizeof *jac);
            }
    return rc;
}

/* Refits the data set's slots without group g, from p (overwritten by the
 * refitted values); the solver's iterations relayed as step `step` of
 * `steps`. */
static int refit_without(const phc_problem *pb, phc_dataset *ds, const phc_cv_plan *plan, size_t g, double *p,
                         phc_progress_fn progress, void *user_data, size_t step, size_t steps, phc_error *err)
{
    phc_nls *nls = phc_nls_new(ds->k);
    size_t *idx = malloc((ds->k ? ds->k : 1) * sizeof *idx);
    fold f = {ds, plan->group, g};
    int rc = PHC_OK;
    if (!nls || !idx) {
        rc = nls ? phc_error_set(err, PHC_ERR_NOMEM, "out of memory") : phc_nls_new_error("cross-validation", err);
        goto done;
    }
    for (size_t q = 0; q < ds->k; ++q) {
        const phc_parameter *par = &pb->params[ds->param_index[q]];
        idx[q] = q;
        const double lo = par->lower, hi = par->upper;
        if (p[q] < lo || p[q] > hi)
            p[q] = fmin(fmax(p[q], lo), hi);
        if ((rc = phc_nls_set_parameter(nls, q, lo, hi, par->fixed, phc_problem_scale(pb, ds->param_index[q]), err)))
            goto done;
    }
    if ((rc = phc_nls_add_block(nls, ds->n, idx, ds->k, fold_residuals, ds->derivatives, ds->loss, ds->loss_scale, &f,
                                err)))
        goto done;
    phc_nls_options opt = pb->options.nls;
    phc_progress_relay relay = {progress, user_data, "leave-one-out", ds->name, step, steps, 0};
    if (progress) {
        opt.on_iteration = phc_progress_relay_iteration;
        opt.on_iteration_data = &relay;
    }
    phc_nls_summary sum;
    rc = phc_nls_solve(nls, &opt, p, &sum, err);
    if (rc == PHC_OK && relay.cancelled)
        rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
done:
    phc_nls_free(nls);
    free(idx);
    return rc;
}

/* RMSE of each prediction over the groups the model predicted. */
static void result_rmse(phc_cv_result *res)
{
    const size_t np = res->n_predictions;
    double s2[PHC_CV_MAX_PREDICTIONS] = {0};
    size_t m = 0;
    for (size_t g = 0; g < res->n_groups; ++g) {
        const double *v = res->predicted + g * np;
        if (isnan(v[0]))
            continue;
        for (size_t k = 0; k < np; ++k)
            s2[k] += pow(v[k] - res->observed[g], 2);
        ++m;
    }
    for (size_t k = 0; k < PHC_CV_MAX_PREDICTIONS; ++k)
        res->rmse[k] = m && k < np ? sqrt(s2[k] / (double)m) : NAN;
}

/* A plan the engine can run: groups, names, predictions within bounds. */
static int check_plan(const phc_dataset *ds, const phc_cv_plan *plan, phc_error *err)
{
    const char *name = ds->name ? ds->name : ds->ops->kind;
    if (!plan->predict || !plan->group || !plan->names || !plan->observed || plan->n_predictions < 1 ||
        plan->n_predictions > PHC_CV_MAX_PREDICTIONS)
        return phc_error_set(err, PHC_ERR_INVALID, "data set '%s': an incomplete cross-validation plan", name);
    for (size_t i = 0; i < ds->n; ++i)
        if (plan->group[i] != PHC_CV_NO_GROUP && plan->group[i] >= plan->n_groups)
            return phc_error_set(err, PHC_ERR_INVALID, "data set '%s': cross-validation group %zu of observation "
                                 "%zu is not below %zu", name, plan->group[i], i, plan->n_groups);
    return PHC_OK;
}

int phc_cross_validate_plan(const phc_problem *pb, phc_dataset *ds, const phc_cv_plan *plan, const double *p,
                            phc_progress_fn progress, void *user_data, phc_cv_result **out, phc_error *err)
{
    phc_cv_result *res = NULL;
    double *pg = NULL;
    int rc;
    *out = NULL;
    if (!plan->n_groups)
        return PHC_OK;
    if (!pb)
        return phc_error_set(err, PHC_ERR_INVALID, "data set '%s': cross-validation needs the data set's problem",
                             ds->name);
    if ((rc = check_plan(ds, plan, err)))
        return rc;
    const size_t ng = plan->n_groups, np = plan->n_predictions;
    pg = malloc((ds->k ? ds->k : 1) * sizeof *pg);
    if (!pg || !(res = result_new(plan))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t g = 0; g < ng; ++g) {
        /* the model: refit without group g, then its prediction there */
        memcpy(pg, p, ds->k * sizeof *pg);
        if (phc_progress_report(progress, user_data, "leave-one-out", g + 1, ng, -1, NAN, ds->name)) {
            rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
            goto done;
        }
        if ((rc = refit_without(pb, ds, plan, g, pg, progress, user_data, g + 1, ng, err)) ||
            (rc = plan->predict(ds, pg, g, res->predicted + g * np, err)))
            goto done;
    }
    result_rmse(res);
    /* leave the data set's model at the fitted values */
    double *yh = malloc((ds->n ? ds->n : 1) * sizeof *yh);
    if (yh)
        ds->ops->predict(ds, p, yh, NULL);
    free(yh);
    *out = res;
    res = NULL;
done:
    free(pg);
    phc_cv_result_free(res);
    return rc;
}

int phc_cross_validate(const phc_problem *pb, phc_dataset *ds, const double *p, phc_progress_fn progress,
                       void *user_data, phc_cv_result **out, phc_error *err)
{
    phc_cv_plan plan;
    int rc;
    *out = NULL;
    if (!ds->ops->cross_validation)
        return PHC_OK;
    memset(&plan, 0, sizeof plan);
    if ((rc = ds->ops->cross_validation(ds, &plan, err)) == PHC_OK)
        rc = phc_cross_validate_plan(pb, ds, &plan, p, progress, user_data, out, err);
    phc_cv_plan_clear(&plan);
    return rc;
}

int phc_cv_result_markdown(const phc_cv_result *res, char **markdown, phc_error *err)
{
    char *out = NULL;
    size_t len = 0;
    const size_t np = res->n_predictions;
    *markdown = NULL;
    FILE *f = open_memstream(&out, &len);
    if (!f)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    fprintf(f, "\n**Leave-one-out prediction of %s** (each %s left out in turn; the free parameters refitted on the "
               "others%s%s).%s%s\n\n| %s | measured |",
            res->quantity, res->group_title, res->how ? "; " : "", res->how ? res->how : "", res->note ? "  " : "",
            res->note ? res->note : "", res->group_title);
    for (size_t k = 0; k < np; ++k)
        fprintf(f, " %s |", res->labels[k]);
    fprintf(f, "\n|---|---|");
    for (size_t k = 0; k < np; ++k)
        fprintf(f, "---|");
    fputc('\n', f);
    for (size_t g = 0; g < res->n_groups; ++g) {
        const double *v = res->predicted + g * np;
        if (isnan(v[0]))
            continue;
        fprintf(f, "| %s | %g |", res->names[g], res->observed[g]);
        for (size_t k = 0; k < np; ++k)
            fprintf(f, " %.2f |", v[k]);
        fputc('\n', f);
    }
    fprintf(f, "\nRMSE of the prediction (%s units):", res->quantity);
    for (size_t k = 0; k < np; ++k)
        fprintf(f, "%s %s **%.3g**", k ? "," : "", res->labels[k], res->rmse[k]);
    fprintf(f, ".\n");
    if (ferror(f) | (fclose(f) != 0)) {
        free(out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *markdown = out;
    return PHC_OK;
}
