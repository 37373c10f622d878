/* The bundled balance-logger example: measurements/examples/weight_curve/
 * logger.yaml on logger_ivy.csv, made by generate_logger.py (a detached ivy
 * leaf, fast-mixing limit of the water model, delta = 4.0e-4 s-1 cm-2,
 * water 1.20 g, dry mass 0.42 g, noise 0.5 mg; Python's zoneinfo wrote the
 * local times of Europe/Berlin).
 *
 * 1. The logger file is read as written: 360 rows, 8 unstable (select
 *    {Status: ST}), the tare reading of line 6 dropped, so 351 weighings;
 *    x in hours from 2024-10-25 16:00 CEST (14:00 UTC): 02:00 local on
 *    2024-10-27 is 34 h (CEST) and, the hour repeated, 35 h (CET); the last
 *    stable reading, 28/10 09:50 CET, is 66 h 50 min.  The local clock of
 *    every weighing (ds->time_of_day) reads what the file says.
 * 2. The report names the tare line and the 7.5 h the logger was off.
 * 3. The fit recovers every generating value inside its 95% interval. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

/* index of the weighing at x (h), or -1 */
static long at_x(const phc_dataset *ds, double x)
{
    for (size_t i = 0; i < ds->n; ++i)
        if (fabs(ds->x[i] - x) < 1e-9)
            return (long)i;
    return -1;
}

int main(void)
{
    const char *config = PHC_SOURCE_DIR "/measurements/examples/weight_curve/logger.yaml";
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = NULL;
    CHECK(phc_config_load(config, &pb, &err) == PHC_OK);
    if (!pb) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    phc_dataset *ds = pb->datasets[0];
    CHECK(ds->n == 351);
    CHECK(ds->x_seconds == 3600);
    CHECK(ds->time_of_day != NULL);
    CHECK_STR_CONTAINS(ds->x_label, "time since the first weighing (h)");
    CHECK(ds->data_lines[0] == 7); /* line 6 is the tare reading */
    const long summer = at_x(ds, 34.0), winter = at_x(ds, 35.0), last = (long)ds->n - 1;
    CHECK(summer >= 0 && winter == summer + 6); /* six readings 02:00-02:50, then 02:00 again */
    CHECK_NEAR(ds->x[last], 66 + 50 / 60.0, 1e-9, 0);
    if (ds->time_of_day && summer >= 0 && winter >= 0) {
        CHECK_NEAR(ds->time_of_day[0], 16.0, 1e-9, 0);
        CHECK_NEAR(ds->time_of_day[summer], 2.0, 1e-9, 0);
        CHECK_NEAR(ds->time_of_day[winter], 2.0, 1e-9, 0);
        CHECK_NEAR(ds->time_of_day[last], 9 + 50 / 60.0, 1e-9, 0);
    }

    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (!res) {
        fprintf(stderr, "%s\n", err.message);
        phc_problem_free(pb);
        return check_finish("test_weight_curve_logger");
    }
    double p[3];
    const char *names[3] = {"delta", "initial_water", "dry_mass"};
    const double want[3] = {4.0e-4, 1.20, 0.42};
    for (int i = 0; i < 3; ++i) {
        const phc_param_result *r = param(res, names[i]);
        CHECK(r != NULL);
        if (!r)
            continue;
        p[i] = r->value;
        printf("%-14s %.6g ± %.3g  95%% [%.6g, %.6g]  truth %g\n", names[i], r->value, r->stderr_,
               r->ci_lo, r->ci_hi, want[i]);
        CHECK(r->ci_lo < want[i] && want[i] < r->ci_hi);
    }
    char *md = NULL;
    CHECK(ds->ops->report_section(ds, p, &md, &err) == PHC_OK); /* slots: delta, water, dry */
    CHECK_STR_CONTAINS(md, "| clock | Europe/Berlin; time 0 (the first weighing kept) is 2024-10-25T16:00:00+02:00 |");
    CHECK_STR_CONTAINS(md, "| tare readings dropped | 1 (line 6) |");
    CHECK_STR_CONTAINS(md, "| logger gaps longer than 6 h | 1: 7.5 h after line 68 |");
    free(md);
    phc_fit_result_free(res);
    phc_problem_free(pb);
    return check_finish("test_weight_curve_logger");
}
