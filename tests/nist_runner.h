/* Runs the NIST StRD problems through the same path a user's `curve` config
 * takes (config file + CSV -> phc_config_load -> phc_fit_run) and scores
 * them by log relative error (LRE).  Shared by tests/realdata/test_nist.c
 * and tests/bench/nist_peers.c. */
#ifndef PHC_TEST_NIST_RUNNER_H
#define PHC_TEST_NIST_RUNNER_H

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fit/config.h"
#include "fit/engine/fit.h"
#include "nist_problem.h"

typedef struct nist_outcome {
    char name[NIST_NAME_SIZE];
    int start;
    int ok;              /* the config loaded and the fit ran */
    char status[32];
    double lre_param;    /* min over parameters */
    double lre_sd;       /* min over standard errors vs certified sd */
    double lre_rss;
    double seconds;      /* phc_fit_run wall time */
    double cpu_seconds;  /* phc_fit_run CPU time of the calling thread */
    double solve_seconds;/* of which the Ceres solves (all starts) */
    char message[1100];
} nist_outcome;

static double nist_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double nist_thread_cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int nist_name_cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Sorted list of .dat paths in dir; returns the count (0 if none). */
static size_t nist_list(const char *dir, char ***paths_out)
{
    DIR *d = opendir(dir);
    *paths_out = NULL;
    if (!d)
        return 0;
    char **paths = NULL;
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".dat") != 0)
            continue;
        char **grown = realloc(paths, (n + 1) * sizeof *paths);
        if (!grown)
            break;
        paths = grown;
        size_t sz = strlen(dir) + len + 2;
        paths[n] = malloc(sz);
        snprintf(paths[n], sz, "%s/%s", dir, e->d_name);
        ++n;
    }
    closedir(d);
    qsort(paths, n, sizeof *paths, nist_name_cmp);
    *paths_out = paths;
    return n;
}

/* Fits one problem from one start; work_dir receives the config and CSV.
 * derivatives: NULL for the default, or a value of the data set's
 * `derivatives:` key ("central", "ridders") appended to the config. */
static void nist_run_case(const nist_problem *p, int start, const char *work_dir, const char *derivatives,
                          nist_outcome *o)
{
    memset(o, 0, sizeof *o);
    snprintf(o->name, sizeof o->name, "%s", p->name);
    o->start = start;
    char config[4096], msg[1024];
    if (nist_write_case(p, start, work_dir, config, sizeof config, msg, sizeof msg) != 0) {
        snprintf(o->message, sizeof o->message, "cannot write case: %s", msg);
        return;
    }
    if (derivatives) { /* the data set is the config's last mapping */
        FILE *f = fopen(config, "a");
        if (!f || fprintf(f, "    derivatives: %s\n", derivatives) < 0 || fclose(f) != 0) {
            snprintf(o->message, sizeof o->message, "cannot append to the config of %s", p->name);
            return;
        }
    }
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = NULL;
    if (phc_config_load(config, &pb, &err) != PHC_OK) {
        snprintf(o->message, sizeof o->message, "%s", err.message);
        return;
    }
    phc_fit_result *res = NULL;
    const double c0 = nist_thread_cpu(), t0 = nist_now();
    int rc = phc_fit_run(pb, NULL, NULL, &res, &err);
    o->seconds = nist_now() - t0;
    o->cpu_seconds = nist_thread_cpu() - c0;
    phc_problem_free(pb);
    if (rc != PHC_OK) {
        snprintf(o->message, sizeof o->message, "%s", err.message);
        return;
    }
    o->ok = 1;
    o->solve_seconds = res->total_time;
    snprintf(o->status, sizeof o->status, "%s", phc_fit_status_name(res->summary.outcome));
    o->lre_param = 99;
    o->lre_sd = 99;
    for (int j = 0; j < p->k; ++j) {
        char name[16];
        snprintf(name, sizeof name, "b%d", j + 1);
        for (size_t i = 0; i < res->n_params; ++i)
            if (strcmp(res->params[i].name, name) == 0) {
                double l = nist_lre(res->params[i].value, p->certified[j]);
                double s = isnan(res->params[i].stderr_) ? 0 : nist_lre(res->params[i].stderr_, p->certified_sd[j]);
                if (l < o->lre_param)
                    o->lre_param = l;
                if (s < o->lre_sd)
                    o->lre_sd = s;
            }
    }
    o->lre_rss = nist_lre(res->rss, p->certified_rss);
    phc_fit_result_free(res);
}

#endif /* PHC_TEST_NIST_RUNNER_H */
