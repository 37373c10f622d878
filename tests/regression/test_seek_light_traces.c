/* Traces of phototropism toward where the light is (seek_light; Hädrich et
 * al., CGF 36(2) 2017, §4.2, eq. 7) for a fit of η: the model plant of
 * measurements/examples/climbing/overhang.yaml (a seed under a plate 0.3 m
 * up whose edge is 0.1 m away, light from above, ambient 0.5, BP 0.3, r
 * 0.3 s⁻¹, η 0.08 s⁻¹, 60 s in steps of 0.25 s) traced by the model itself.
 *  1. The plant with the config's seed (101), traced every 10 s
 *     (phc_shoot_traces_from_model, as the shoot_traces kind traces its
 *     model plants), written as CSV, is exactly the committed
 *     measurements/examples/climbing/seek_light_traces.csv (`--write PATH`
 *     writes it).
 *  2. The statistics over η: the kind's model (seeds 1..8, as the example
 *     fit seek_light.yaml) at η = 0.02 .. 0.2 s⁻¹ with r at its truth; the
 *     statistics at 60 s and the fit's cost (the sum of the squared
 *     whitened residuals, Σ from 8 plants at the truth) are printed.  Checked: the height at 60 s falls with η at every step
 *     (the shoots turn sideways toward the plate's edge sooner), and the
 *     fit's cost (the kind's whitened residuals) falls to its smallest
 *     value at the truth and rises after it up to 1.5 times the truth.
 *   test_seek_light_traces [--write PATH] */
#include "fit/costs/shoot_traces.h"
#include "fit/grow.h"
#include "fit/grow_config.h"
#include "measurements/shoot_traces.h"
#include "measurements/support_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#define EXAMPLE PHC_SOURCE_DIR "/measurements/examples/climbing/"

static int is_eta(const char *name, void *user)
{
    (void)user;
    return !strcmp(name, "phototropism");
}

/* The traces as CSV text (malloc'd): time, shoot, x, y, z, parent. */
static char *traces_csv(const phc_shoot_traces *tr)
{
    size_t cap = 256 + 128 * tr->n_points, len = 0;
    char *s = malloc(cap);
    if (!s)
        return NULL;
    len += (size_t)snprintf(s + len, cap - len,
                            "# SYNTHETIC: the model's own traces of overhang.yaml (seed 101, every 10 s),\n"
                            "# written by tests/regression/test_seek_light_traces.c --write\n"
                            "time,shoot,x,y,z,parent\n");
    for (size_t k = 0; k < tr->n_shoots; ++k)
        for (size_t p = tr->start[k]; p < tr->start[k + 1]; ++p)
            len += (size_t)snprintf(s + len, cap - len, "%.6g,%s,%.9g,%.9g,%.9g,%s\n", tr->t[p], tr->names[k],
                                    tr->x[3 * p], tr->x[3 * p + 1], tr->x[3 * p + 2],
                                    tr->parent[k] == PHC_SHOOT_NONE ? "" : tr->names[tr->parent[k]]);
    return s;
}

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = 0;
    fclose(f);
    return s;
}

int main(int argc, char **argv)
{
    const char *write = argc == 3 && !strcmp(argv[1], "--write") ? argv[2] : NULL;
    phc_error err;
    phc_error_clear(&err);
    phc_grow_config *cfg = NULL;
    if (phc_grow_config_load(EXAMPLE "overhang.yaml", &cfg, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    phc_support_mesh *mesh = phc_support_mesh_read(cfg->support, &err);
    double *v = NULL;
    size_t *t = NULL;
    phc_shoot_traces_options o = phc_shoot_traces_options_default();
    if (!mesh || phc_support_mesh_arrays(mesh, &v, &o.shadow_vertex_count, &t, &o.shadow_triangle_count, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    /* the plant as the shoot_traces kind sets it up (fit/config/shoot_traces_yaml.c) */
    o.plant = cfg->options;
    phc_grow_light_grid(cfg, mesh, &o.plant);
    o.plant.closest = phc_support_mesh_closest;
    o.plant.closest_user = mesh;
    o.shadow_vertices = v;
    o.shadow_triangles = t;
    memcpy(o.position, cfg->position, sizeof o.position);
    memcpy(o.direction, cfg->direction, sizeof o.direction);
    o.time_step = cfg->time_step;
    const double eta_true = o.plant.phototropism;
    double frames[6];
    for (int k = 0; k < 6; ++k)
        frames[k] = 10.0 * (k + 1);
    phc_shoot_traces *tr = NULL;
    CHECK(phc_shoot_traces_from_model(&o, frames, 6, &tr, &err) == PHC_OK);
    if (!tr)
        fprintf(stderr, "%s\n", err.message);
    char *csv = tr ? traces_csv(tr) : NULL;
    if (write) {
        FILE *f = fopen(write, "w");
        const int ok = f && csv && fputs(csv, f) >= 0;
        if (f)
            fclose(f);
        printf("%s %s\n", ok ? "wrote" : "could not write", write);
        return ok ? 0 : 1;
    }
    char *committed = read_all(EXAMPLE "seek_light_traces.csv");
    printf("traces of overhang.yaml (seed 101, eta %g 1/s, every 10 s): %zu shoots, %zu points; "
           "the committed seek_light_traces.csv is %s\n",
           eta_true, tr ? tr->n_shoots : 0, tr ? tr->n_points : 0,
           committed && csv && !strcmp(committed, csv) ? "the same" : "DIFFERENT");
    CHECK(committed && csv && !strcmp(committed, csv));
    free(committed);
    free(csv);

    /* 2. the statistics over eta, the kind's model with seeds 1..8 */
    o.seeds = 8;
    o.first_seed = 1;
    o.covariance_seeds = 8;
    o.is_parameter = is_eta;
    phc_dataset *ds = NULL;
    CHECK(phc_shoot_traces_new(tr, &o, &ds, &err) == PHC_OK); /* takes the traces */
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return check_finish("test_seek_light_traces");
    }
    const double etas[] = {0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.1, 0.11, 0.12, 0.14, 0.16, 0.2};
    const size_t ne = sizeof etas / sizeof etas[0], n = ds->n;
    const double *traced = phc_shoot_traces_traced(ds);
    double *y = malloc(n * sizeof *y), *sd = malloc(n * sizeof *sd), *yw = malloc(n * sizeof *yw);
    const size_t last = 15; /* observations 15..19: the statistics at the last of 4 times (60 s) */
    printf("traced at 60 s: total length %.4f m, height %.4f m, light cosine %.4f\n", traced[last],
           traced[last + 2], traced[last + 4]);
    printf("eta (1/s) | total length (m) | height (m) | light cosine | cost (whitened, as the fit)\n");
    double prev_height = INFINITY, best = INFINITY, best_eta = NAN, cost[sizeof etas / sizeof etas[0]];
    int falling = 1;
    for (size_t e = 0; e < ne && y && sd; ++e) {
        CHECK(phc_shoot_traces_model(ds, &etas[e], y, sd) == 0);
        double chi2 = 0; /* the fit's cost: whitened residuals, sigma 1 */
        CHECK(ds->ops->predict(ds, &etas[e], yw, NULL) == 0);
        for (size_t i = 0; i < n; ++i)
            chi2 += (ds->y[i] - yw[i]) * (ds->y[i] - yw[i]);
        printf("%9.3f | %16.4f | %10.4f | %12.4f | %.2f\n", etas[e], y[last], y[last + 2], y[last + 4], chi2);
        falling &= y[last + 2] < prev_height;
        prev_height = y[last + 2];
        cost[e] = chi2;
        if (chi2 < best) {
            best = chi2;
            best_eta = etas[e];
        }
    }
    /* one valley up to 1.5 times the truth: the cost falls to its smallest
       value and rises after it */
    int valley = 1;
    for (size_t e = 1; e < ne && etas[e] <= 1.5 * eta_true + 1e-12; ++e)
        valley &= etas[e] <= best_eta ? cost[e] < cost[e - 1] : cost[e] > cost[e - 1];
    printf("height at 60 s falls with eta at every step: %s; the cost has one valley up to 1.5 x the truth: %s, smallest at eta = %g 1/s "
           "(truth %g)\n",
           falling ? "yes" : "no", valley ? "yes" : "no", best_eta, eta_true);
    CHECK(falling);
    CHECK(valley);
    CHECK(best_eta == eta_true);
    free(y);
    free(sd);
    free(yw);
    phc_dataset_free(ds);
    free(v);
    free(t);
    phc_support_mesh_free(mesh);
    phc_grow_config_free(cfg);
    return check_finish("test_seek_light_traces");
}
