/* The summary table of a batch of fits: see batch_summary.h. */
#include "fit/batch_summary.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/atomic_file.h"

static char *dup_or_null(const char *s)
{
    return s ? strdup(s) : NULL;
}

int phc_batch_row_set_result(phc_batch_row *row, const phc_fit_result *res)
{
    row->has_result = 1;
    row->cost = res->cost;
    row->n_obs = res->n_obs;
    row->n_datasets = res->n_datasets;
    row->n_params = res->n_params;
    row->dataset_names = calloc(res->n_datasets ? res->n_datasets : 1, sizeof *row->dataset_names);
    row->r2 = calloc(res->n_datasets ? res->n_datasets : 1, sizeof *row->r2);
    row->params = calloc(res->n_params ? res->n_params : 1, sizeof *row->params);
    if (!row->dataset_names || !row->r2 || !row->params)
        return PHC_ERR_NOMEM;
    for (size_t d = 0; d < res->n_datasets; ++d) {
        if (!(row->dataset_names[d] = strdup(res->datasets[d].name)))
            return PHC_ERR_NOMEM;
        row->r2[d] = res->datasets[d].goodness.r2;
    }
    for (size_t j = 0; j < res->n_params; ++j) {
        const phc_param_result *p = &res->params[j];
        if (!(row->params[j].name = strdup(p->name)))
            return PHC_ERR_NOMEM;
        row->params[j].value = p->value;
        row->params[j].stderr_ = p->fixed ? NAN : p->stderr_;
    }
    char verdict[64];
    if (res->n_warnings)
        snprintf(verdict, sizeof verdict, "%zu warning%s", res->n_warnings, res->n_warnings == 1 ? "" : "s");
    else
        snprintf(verdict, sizeof verdict, "no problems found");
    free(row->verdict);
    return (row->verdict = dup_or_null(verdict)) ? PHC_OK : PHC_ERR_NOMEM;
}

void phc_batch_row_clear(phc_batch_row *row)
{
    free(row->fit);
    free(row->group);
    free(row->config);
    free(row->dir);
    free(row->status);
    free(row->verdict);
    free(row->message);
    for (size_t d = 0; row->dataset_names && d < row->n_datasets; ++d)
        free(row->dataset_names[d]);
    free(row->dataset_names);
    free(row->r2);
    for (size_t j = 0; row->params && j < row->n_params; ++j)
        free(row->params[j].name);
    free(row->params);
    memset(row, 0, sizeof *row);
}

/* Names met over the rows, in order of first appearance. */
typedef struct name_list {
    const char **names;
    size_t n;
} name_list;

static int add_name(name_list *l, const char *name)
{
    for (size_t i = 0; i < l->n; ++i)
        if (strcmp(l->names[i], name) == 0)
            return 0;
    const char **grown = realloc(l->names, (l->n + 1) * sizeof *grown);
    if (!grown)
        return -1;
    l->names = grown;
    l->names[l->n++] = name;
    return 0;
}

/* A text cell: tabs and line breaks as spaces. */
static void put_text(FILE *f, const char *s, int markdown)
{
    for (; s && *s; ++s) {
        if (*s == '\t' || *s == '\n' || *s == '\r')
            fputc(' ', f);
        else if (markdown && *s == '|')
            fputs("\\|", f);
        else
            fputc(*s, f);
    }
}

static void put_number(FILE *f, double v, const char *format)
{
    if (isfinite(v))
        fprintf(f, format, v);
}

static const phc_batch_param *find_param(const phc_batch_row *r, const char *name)
{
    for (size_t j = 0; r->has_result && j < r->n_params; ++j)
        if (strcmp(r->params[j].name, name) == 0)
            return &r->params[j];
    return NULL;
}

static const double *find_r2(const phc_batch_row *r, const char *name)
{
    for (size_t d = 0; r->has_result && d < r->n_datasets; ++d)
        if (strcmp(r->dataset_names[d], name) == 0)
            return &r->r2[d];
    return NULL;
}

static void write_tsv(FILE *f, const char *group_column, const phc_batch_row *rows, size_t n, const name_list *ds,
                      const name_list *ps)
{
    fputs("fit\t", f);
    if (group_column) {
        put_text(f, group_column, 0);
        fputc('\t', f);
    }
    fputs("config\tdir\tstatus\texit\tverdict\tcost\tn_obs", f);
    for (size_t d = 0; d < ds->n; ++d) {
        fputs("\tr2_", f);
        put_text(f, ds->names[d], 0);
    }
    for (size_t j = 0; j < ps->n; ++j) {
        fputc('\t', f);
        put_text(f, ps->names[j], 0);
        fputc('\t', f);
        put_text(f, ps->names[j], 0);
        fputs("_se", f);
    }
    fputs("\tmessage\n", f);
    for (size_t i = 0; i < n; ++i) {
        const phc_batch_row *r = &rows[i];
        put_text(f, r->fit, 0);
        fputc('\t', f);
        if (group_column) {
            put_text(f, r->group, 0);
            fputc('\t', f);
        }
        put_text(f, r->config, 0);
        fputc('\t', f);
        put_text(f, r->dir, 0);
        fputc('\t', f);
        put_text(f, r->status, 0);
        fprintf(f, "\t%d\t", r->exit_code);
        put_text(f, r->verdict, 0);
        fputc('\t', f);
        if (r->has_result) {
            put_number(f, r->cost, "%.17g");
            fprintf(f, "\t%zu", r->n_obs);
        } else {
            fputc('\t', f);
        }
        for (size_t d = 0; d < ds->n; ++d) {
            fputc('\t', f);
            const double *v = find_r2(r, ds->names[d]);
            if (v)
                put_number(f, *v, "%.17g");
        }
        for (size_t j = 0; j < ps->n; ++j) {
            const phc_batch_param *p = find_param(r, ps->names[j]);
            fputc('\t', f);
            if (p)
                put_number(f, p->value, "%.17g");
            fputc('\t', f);
            if (p)
                put_number(f, p->stderr_, "%.17g");
        }
        fputc('\t', f);
        put_text(f, r->message, 0);
        fputc('\n', f);
    }
}

static void write_md(FILE *f, const char *group_column, const phc_batch_row *rows, size_t n, const name_list *ds,
                     const name_list *ps)
{
    size_t ok = 0;
    for (size_t i = 0; i < n; ++i)
        ok += rows[i].exit_code == 0;
    fprintf(f, "# Batch of %zu fit%s", n, n == 1 ? "" : "s");
    if (group_column) {
        fputs(" (one per value of column `", f);
        put_text(f, group_column, 1);
        fputs("`)", f);
    }
    fprintf(f, "\n\n%zu of %zu fitted and converged. Each fit's run directory holds its result.json, "
               "report.md and plots; summary.tsv holds these numbers with 17 digits.\n\n", ok, n);
    fputs("| fit | status | verdict | cost |", f);
    for (size_t d = 0; d < ds->n; ++d) {
        fputs(" R² ", f);
        put_text(f, ds->names[d], 1);
        fputs(" |", f);
    }
    for (size_t j = 0; j < ps->n; ++j) {
        fputc(' ', f);
        put_text(f, ps->names[j], 1);
        fputs(" ± s.e. |", f);
    }
    fputs("\n|---|---|---|---:|", f);
    for (size_t k = 0; k < ds->n + ps->n; ++k)
        fputs("---:|", f);
    fputc('\n', f);
    for (size_t i = 0; i < n; ++i) {
        const phc_batch_row *r = &rows[i];
        fputs("| ", f);
        if (r->dir)
            fprintf(f, "[%s](%s/report.md)", r->fit, r->dir);
        else
            put_text(f, r->fit, 1);
        fputs(" | ", f);
        put_text(f, r->status, 1);
        fputs(" | ", f);
        put_text(f, r->verdict, 1);
        fputs(" | ", f);
        if (r->has_result)
            put_number(f, r->cost, "%.6g");
        fputs(" |", f);
        for (size_t d = 0; d < ds->n; ++d) {
            const double *v = find_r2(r, ds->names[d]);
            fputc(' ', f);
            if (v)
                put_number(f, *v, "%.6g");
            fputs(" |", f);
        }
        for (size_t j = 0; j < ps->n; ++j) {
            const phc_batch_param *p = find_param(r, ps->names[j]);
            fputc(' ', f);
            if (p) {
                put_number(f, p->value, "%.6g");
                if (isfinite(p->stderr_))
                    fprintf(f, " ± %.3g", p->stderr_);
            }
            fputs(" |", f);
        }
        fputc('\n', f);
    }
    size_t failed = n - ok;
    if (failed) {
        fprintf(f, "\n## %zu fit%s with a non-zero exit code\n\n", failed, failed == 1 ? "" : "s");
        for (size_t i = 0; i < n; ++i)
            if (rows[i].exit_code) {
                fputs("- ", f);
                put_text(f, rows[i].fit, 1);
                fprintf(f, " (%s, exit %d): ", rows[i].status, rows[i].exit_code);
                put_text(f, rows[i].message, 1);
                fputc('\n', f);
            }
    }
}

int phc_batch_summary_write(const char *dir, const char *group_column, const phc_batch_row *rows, size_t n,
                            phc_error *err)
{
    name_list ds = {0}, ps = {0};
    int rc = PHC_OK;
    for (size_t i = 0; i < n && rc == PHC_OK; ++i) {
        for (size_t d = 0; rows[i].has_result && d < rows[i].n_datasets; ++d)
            if (add_name(&ds, rows[i].dataset_names[d]))
                rc = PHC_ERR_NOMEM;
        for (size_t j = 0; rows[i].has_result && j < rows[i].n_params; ++j)
            if (add_name(&ps, rows[i].params[j].name))
                rc = PHC_ERR_NOMEM;
    }
    if (rc) {
        rc = phc_error_set(err, rc, "out of memory");
        goto done;
    }
    for (int md = 0; md < 2 && rc == PHC_OK; ++md) {
        char path[8192];
        snprintf(path, sizeof path, "%s/%s", dir, md ? "summary.md" : "summary.tsv");
        phc_atomic_file *af = NULL;
        if ((rc = phc_atomic_file_open(path, &af, err)))
            break;
        if (md)
            write_md(phc_atomic_file_stream(af), group_column, rows, n, &ds, &ps);
        else
            write_tsv(phc_atomic_file_stream(af), group_column, rows, n, &ds, &ps);
        rc = phc_atomic_file_commit(af, err);
    }
done:
    free(ds.names);
    free(ps.names);
    return rc;
}
