/* Start-up and small-fit benchmark (issue 16): what a user waits for when a
 * shell loop calls phytocal once per leaf or plant.
 *
 *   build/bench_bench_startup [RUNS [OTHER_PHYTOCAL]]     (RUNS default 10)
 *
 * Runs, each RUNS times, as separate processes (posix_spawn, output to
 * /dev/null), and prints the best wall time and the best CPU time (user +
 * system of the child, wait4):
 *   phytocal_version          build/phytocal version
 *   curve_fit_end_to_end      build/phytocal fit enzyme.yaml -o DIR (a new
 *                             DIR each run): 14 points, 8 starts, report.md,
 *                             result.json and four PNG plots
 *   python_import_scipy       /usr/bin/python3 -c 'import scipy.optimize'
 *   scipy_curve_fit_end_to_end  /usr/bin/python3 tests/bench/startup_peer.py:
 *                             the same data and model with curve_fit and a
 *                             report (no plots), in one process
 * then the ratios peer / phytocal.  With OTHER_PHYTOCAL (another build's
 * command, e.g. one before the modules), its version and fit are timed in
 * the same run too (other_phytocal_version, other_curve_fit_end_to_end).  The phytocal command is the one beside
 * this program (build/).  How busy other processes kept the machine is
 * printed too: on this shared 2-core machine wall times grow with it, CPU
 * times much less. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_machine.h"

extern char **environ;

static double children_cpu; /* CPU seconds of every child run, s */

typedef struct timing {
    double wall, cpu; /* best of the runs, s */
} timing;

/* Runs argv once; wall and CPU time of the child.  Exit status must be 0. */
static int run_once(char *const argv[], double *wall, double *cpu)
{
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
    const double t0 = now();
    pid_t pid;
    int rc = posix_spawn(&pid, argv[0], &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc) {
        fprintf(stderr, "bench_startup: cannot start %s: %s\n", argv[0], strerror(rc));
        return -1;
    }
    int status;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid) {
        perror("bench_startup: wait4");
        return -1;
    }
    *wall = now() - t0;
    *cpu = ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
    children_cpu += *cpu;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fprintf(stderr, "bench_startup: %s %s failed (status %d)\n", argv[0], argv[1] ? argv[1] : "", status);
        return -1;
    }
    return 0;
}

/* Best of `runs`; argv[out_slot] (when >= 0) is replaced by a new folder
 * under tmp for each run (the fit refuses an existing one). */
static int time_command(char **argv, int out_slot, const char *tmp, int runs, timing *best)
{
    best->wall = best->cpu = 1e300;
    char dir[4096];
    for (int i = 0; i < runs; ++i) {
        if (out_slot >= 0) {
            static int serial; /* one new folder per run, over all commands */
            snprintf(dir, sizeof dir, "%s/run%d", tmp, serial++);
            argv[out_slot] = dir;
            if (strstr(argv[0], "python") && mkdir(dir, 0700) != 0) {
                perror(dir);
                return -1;
            }
        }
        double w, c;
        if (run_once(argv, &w, &c))
            return -1;
        if (w < best->wall)
            best->wall = w;
        if (c < best->cpu)
            best->cpu = c;
    }
    return 0;
}

static void print_timing(const char *name, timing t)
{
    printf("%s: %.1f ms (CPU %.1f ms)\n", name, 1e3 * t.wall, 1e3 * t.cpu);
}

int main(int argc, char **argv)
{
    const int runs = argc > 1 ? atoi(argv[1]) : 10;
    if (runs < 1) {
        fprintf(stderr, "usage: bench_bench_startup [RUNS >= 1 [OTHER_PHYTOCAL]]\n");
        return 1;
    }
    char self[4096], phytocal[4200], yaml[4096], csv[4096], peer[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) {
        perror("bench_startup: /proc/self/exe");
        return 1;
    }
    self[n] = '\0';
    *strrchr(self, '/') = '\0';
    snprintf(phytocal, sizeof phytocal, "%s/phytocal", self);
    snprintf(yaml, sizeof yaml, "%s/measurements/examples/enzyme_kinetics/enzyme.yaml", PHC_SOURCE_DIR);
    snprintf(csv, sizeof csv, "%s/measurements/examples/enzyme_kinetics/enzyme.csv", PHC_SOURCE_DIR);
    snprintf(peer, sizeof peer, "%s/tests/bench/startup_peer.py", PHC_SOURCE_DIR);
    char tmp_ours[] = "/tmp/phc_bench_startup_XXXXXX", tmp_peer[] = "/tmp/phc_bench_startup_XXXXXX";
    if (!mkdtemp(tmp_ours) || !mkdtemp(tmp_peer)) {
        perror("bench_startup: mkdtemp");
        return 1;
    }

    char *version[] = {phytocal, "version", NULL};
    char *fit[] = {phytocal, "fit", yaml, "-o", NULL, NULL};
    char *import[] = {"/usr/bin/python3", "-c", "import scipy.optimize", NULL};
    char *scipy_fit[] = {"/usr/bin/python3", peer, csv, NULL, NULL};
    char *other = argc > 2 ? argv[2] : NULL;
    char *other_version[] = {other, "version", NULL};
    char *other_fit[] = {other, "fit", yaml, "-o", NULL, NULL};
    timing tv, tf, ti, ts, ov = {0, 0}, of = {0, 0};
    const cpu_mark a = cpu_now();
    int rc = time_command(version, -1, NULL, runs, &tv) || time_command(fit, 4, tmp_ours, runs, &tf) ||
             time_command(import, -1, NULL, runs, &ti) || time_command(scipy_fit, 3, tmp_peer, runs, &ts) ||
             (other && (time_command(other_version, -1, NULL, runs, &ov) ||
                        time_command(other_fit, 4, tmp_ours, runs, &of)));
    const cpu_mark b = cpu_now();
    char cleanup[8300];
    snprintf(cleanup, sizeof cleanup, "rm -rf '%s' '%s'", tmp_ours, tmp_peer);
    if (system(cleanup) != 0)
        fprintf(stderr, "bench_startup: could not remove %s, %s\n", tmp_ours, tmp_peer);
    if (rc)
        return 1;

    printf("runs: %d of each (best wall time, best CPU time = user + system of the process)\n", runs);
    print_timing("phytocal_version", tv);
    print_timing("curve_fit_end_to_end", tf);
    print_timing("python_import_scipy", ti);
    print_timing("scipy_curve_fit_end_to_end", ts);
    if (other) {
        print_timing("other_phytocal_version", ov);
        print_timing("other_curve_fit_end_to_end", of);
    }
    printf("ratio_import_scipy_over_version: %.1f x (wall; CPU %.1f x)\n", ti.wall / tv.wall, ti.cpu / tv.cpu);
    printf("ratio_scipy_fit_over_ours: %.1f x (wall; CPU %.1f x; ours also draws 4 plots)\n", ts.wall / tf.wall,
           ts.cpu / tf.cpu);
    /* other_load counts the children as others: take their CPU time off */
    const double others = other_load(a, b) - children_cpu / (b.wall - a.wall);
    printf("other_load: %.1f CPUs busy elsewhere during the runs\n", others < 0 ? 0 : others);
    return 0;
}
