/* Benchmark of the two bundled root:shoot fits
 * (measurements/examples/root_shoot/quercus_rubra.yaml and
 * acer_rubrum.yaml: Baltzer & Thomas 2007 seedlings from BAAD, a 30 cm pot,
 * four parameters): prints `name: value unit` lines.
 *
 * Each config is loaded (phc_config_load) and fitted (phc_fit_run) REPEAT
 * times; the wall time of the load + fit (best and median), the process's
 * CPU time over that fit, how busy other processes kept the machine meanwhile
 * (other_load, in CPUs), and the work of the fit: the solver's residual
 * and Jacobian evaluations, the plant trajectories the data set was asked
 * for, how many of them a kept trajectory answered, the plants grown, the
 * simulated days and soil sub-steps (phc_root_shoot_counts), and the fitted
 * cost, which must be the same in every repeat (the fit is deterministic;
 * the bench fails otherwise).  Target: each fit <= 30 s (issue 18).
 *
 * Usage: bench_root_shoot [REPEAT] (default 3).  Needs ../shared/data
 * (exit 77 without it).  Threads: OMP_NUM_THREADS as set (a Jacobian's
 * plants grow in parallel). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bench_machine.h"
#include "fit/config.h"
#include "fit/costs/root_shoot.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"

#define TARGET_S 30.0

/* One config, repeat times; 0, or 1 when a fit failed or was not repeatable. */
static int bench(const char *name, const char *config, int repeat)
{
    double wall[16], cost0 = NAN;
    int bad = 0;
    for (int r = 0; r < repeat; ++r) {
        phc_problem *pb = NULL;
        phc_fit_result *res = NULL;
        phc_error err;
        phc_error_clear(&err);
        const cpu_mark t0 = cpu_now();
        int rc = phc_config_load(config, &pb, &err);
        if (!rc)
            rc = phc_fit_run(pb, NULL, NULL, &res, &err);
        const cpu_mark t1 = cpu_now();
        if (rc) {
            fprintf(stderr, "%s: %s\n", name, err.message);
            phc_problem_free(pb);
            return 1;
        }
        wall[r] = t1.wall - t0.wall;
        phc_root_shoot_counts c = {0};
        for (size_t d = 0; d < pb->n_datasets; ++d)
            phc_root_shoot_counts_get(pb->datasets[d], &c);
        printf("%s_run%d_wall: %.2f s (cpu %.2f s, other_load %.2f CPUs)\n", name, r + 1, wall[r],
               t1.self - t0.self, other_load(t0, t1));
        if (r == 0) {
            cost0 = res->cost;
            printf("%s_cost: %.17g\n", name, res->cost);
            printf("%s_solver: %d residual and %d Jacobian evaluations, %d iterations\n", name,
                   res->summary.residual_evaluations, res->summary.jacobian_evaluations,
                   res->summary.iterations);
            printf("%s_trajectories: %lu asked, %lu from kept ones, %lu plants grown, %.0f days, %lu soil "
                   "sub-steps\n",
                   name, c.requested, c.reused, c.simulated, c.days, c.soil_substeps);
        } else if (memcmp(&res->cost, &cost0, sizeof cost0)) {
            printf("%s_cost_run%d: %.17g differs from the first run's\n", name, r + 1, res->cost);
            bad = 1;
        }
        phc_fit_result_free(res);
        phc_problem_free(pb);
    }
    qsort(wall, (size_t)repeat, sizeof *wall, cmp_double);
    printf("%s_best: %.2f s\n%s_median: %.2f s\n", name, wall[0], name, wall[repeat / 2]);
    printf("%s_target: %s (best %.2f s, target <= %.0f s)\n", name, wall[0] <= TARGET_S ? "met" : "missed",
           wall[0], TARGET_S);
    return bad;
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* each line as it is measured */
    int repeat = argc > 1 ? atoi(argv[1]) : 3;
    if (repeat < 1 || repeat > 16) {
        fprintf(stderr, "bench_root_shoot: REPEAT must be 1 to 16, found '%s'\n", argv[1]);
        return 2;
    }
    struct stat st;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/baad/Baltzer2007", PHC_SHARED_DATA);
    if (stat(dir, &st) != 0) {
        printf("# skip - no %s\n", dir);
        return 77;
    }
    char q[1024], a[1024];
    snprintf(q, sizeof q, "%s/measurements/examples/root_shoot/quercus_rubra.yaml", PHC_SOURCE_DIR);
    snprintf(a, sizeof a, "%s/measurements/examples/root_shoot/acer_rubrum.yaml", PHC_SOURCE_DIR);
    int bad = bench("quercus_rubra", q, repeat);
    bad |= bench("acer_rubrum", a, repeat);
    return bad;
}
