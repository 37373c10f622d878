/* Benchmark of batch fits (issue 16, "a batch mode for many small fits in
 * one process"): N small fits one `phytocal fit` process each against one
 * batch call, beside SciPy one Python process per fit and all in one.
 *
 * Workloads:
 *  (a) ten small NIST StRD problems (../shared/data/nist, Start 1): the
 *      eight of lower difficulty (Misra1a, Chwirut2, Chwirut1, Lanczos3,
 *      Gauss1, Gauss2, DanWood, Misra1b) and Misra1c, Misra1d (average
 *      difficulty, the same two-parameter model family), written as `curve`
 *      configs by nist_write_case (tests/nist_problem.h);
 *        phytocal, one process per fit:  `phytocal fit CASE.yaml -o DIR -q` x 10
 *        phytocal, one call:             `phytocal fit CASE1.yaml ... CASE10.yaml -o DIR -q`
 *        SciPy, a process per fit:       `python3 batch_peer.py NAME=CSV=DAT` x 10
 *        SciPy, one process:             `python3 batch_peer.py` with all ten
 *      (phytocal writes each fit's run directory: result.json, report.md,
 *      four plots, manifest; SciPy fits and computes the covariance only);
 *  (b) the bundled example measurements/examples/enzyme_kinetics/
 *      enzyme_runs.yaml: twelve runs in one table, `--each run` against twelve
 *      processes, each fitting a config whose table holds one run's rows.
 * The split (CPU times): `phytocal version` (start-up alone), and per fit
 * the batch call's CPU less one start-up, / N (the work a process per fit
 * does besides start-up); and the ratio a batch can reach at best.
 *
 * Each timing is the minimum wall time of 2 rounds (the machine is shared;
 * the load of other processes during the rounds is printed); child CPU time
 * (user + system, getrusage) beside it.  The phytocal binary is the one
 * beside this program (build/phytocal); python is /usr/bin/python3.
 * Prints `name: value unit` lines. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench/bench_machine.h"
#include "nist_problem.h"

#define ROUNDS 2
#define MAX_ARGS 64

static const char *const NIST_CASES[] = {"Misra1a", "Chwirut2", "Chwirut1", "Lanczos3", "Gauss1",
                                         "Gauss2",  "DanWood",  "Misra1b",  "Misra1c",  "Misra1d"};
#define N_NIST (sizeof NIST_CASES / sizeof NIST_CASES[0])
#define N_RUNS 12

static char scratch[PATH_MAX];

static double child_cpu(void)
{
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    return ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
}

/* Runs argv (no shell), output to /dev/null; returns its exit code, -1 when it could not run. */
static int run(char *const argv[])
{
    const pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        const int fd = open("/dev/null", O_WRONLY);
        if (fd >= 0) {
            dup2(fd, STDOUT_FILENO);
            dup2(fd, STDERR_FILENO);
        }
        execv(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static void remove_dir(const char *dir)
{
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "bench_batch: could not remove %s\n", dir);
}

/* A list of command lines, run one after another: one round. */
typedef struct job_list {
    char *argv[N_RUNS + 2][MAX_ARGS];
    size_t n;
    int failures;
} job_list;

typedef struct timing {
    double wall, cpu, load;
} timing;

static timing time_rounds(job_list *jobs, const char *out_root)
{
    timing best = {1e300, 0, 0};
    for (int r = 0; r < ROUNDS; ++r) {
        remove_dir(out_root);
        mkdir(out_root, 0777);
        const cpu_mark a = cpu_now();
        const double c0 = child_cpu();
        for (size_t j = 0; j < jobs->n; ++j)
            jobs->failures += run(jobs->argv[j]) != 0;
        const double c1 = child_cpu();
        const cpu_mark b = cpu_now();
        if (b.wall - a.wall < best.wall) {
            best.wall = b.wall - a.wall;
            best.cpu = c1 - c0;
            /* other processes: the machine's busy CPUs minus ours and our children's */
            best.load = ((b.machine - a.machine) - (c1 - c0) - (b.self - a.self)) / (b.wall - a.wall);
            if (best.load < 0)
                best.load = 0;
        }
    }
    return best;
}

static char *str(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static char *str(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *s = NULL;
    if (vasprintf(&s, fmt, ap) < 0)
        s = NULL;
    va_end(ap);
    if (!s) {
        fprintf(stderr, "bench_batch: out of memory\n");
        exit(1);
    }
    return s;
}

static void print_timing(const char *name, size_t n, timing t, const job_list *jobs)
{
    printf("%s: %.3f s wall, %.3f s CPU for %zu fits (%.1f ms per fit; other load %.1f CPUs)%s\n", name, t.wall,
           t.cpu, n, 1e3 * t.wall / (double)n, t.load, jobs->failures ? "  SOME RUNS FAILED" : "");
}

/* Writes a copy of the enzyme runs' config whose table holds only run `run`. */
static int write_run_case(const char *src_dir, const char *dir, const char *run_id)
{
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/enzyme_runs.csv", src_dir);
    FILE *in = fopen(path, "r");
    snprintf(path, sizeof path, "%s/enzyme_runs.csv", dir);
    FILE *out = in ? fopen(path, "w") : NULL;
    if (!out) {
        if (in)
            fclose(in);
        return -1;
    }
    char line[1024];
    int header_seen = 0;
    while (fgets(line, sizeof line, in)) {
        const size_t len = strlen(run_id);
        if (line[0] == '#' || !header_seen || (strncmp(line, run_id, len) == 0 && line[len] == ','))
            fputs(line, out);
        header_seen |= line[0] != '#';
    }
    fclose(in);
    fclose(out);
    snprintf(path, sizeof path, "cp '%s/enzyme_runs.yaml' '%s/'", src_dir, dir);
    return system(path) == 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    (void)argc;
    char self[PATH_MAX], phytocal[PATH_MAX + 16];
    const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0) {
        fprintf(stderr, "bench_batch: cannot find myself\n");
        return 1;
    }
    self[len] = '\0';
    snprintf(phytocal, sizeof phytocal, "%s/phytocal", dirname(self));
    if (access(phytocal, X_OK) != 0) {
        fprintf(stderr, "bench_batch: %s: not found (build the phytocal target)\n", phytocal);
        return 1;
    }
    (void)argv;
    const char *python = "/usr/bin/python3";
    char *peer = str("%s/tests/bench/batch_peer.py", PHC_SOURCE_DIR);
    snprintf(scratch, sizeof scratch, "%s/phc_bench_batch.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(scratch)) {
        fprintf(stderr, "bench_batch: cannot make a scratch directory\n");
        return 1;
    }
    char *cases = str("%s/cases", scratch);
    mkdir(cases, 0777);

    /* (a) NIST */
    char *configs[N_NIST], *peer_args[N_NIST];
    for (size_t i = 0; i < N_NIST; ++i) {
        nist_problem *p = malloc(sizeof *p);
        char msg[512], cfg[PATH_MAX];
        char *dat = str("%s/nist/%s.dat", PHC_SHARED_DATA, NIST_CASES[i]);
        if (!p || nist_load(dat, p, msg, sizeof msg) || nist_write_case(p, 1, cases, cfg, sizeof cfg, msg, sizeof msg)) {
            fprintf(stderr, "bench_batch: %s\n", p ? msg : "out of memory");
            return 1;
        }
        configs[i] = str("%s", cfg);
        peer_args[i] = str("%s=%s/%s.csv=%s", NIST_CASES[i], cases, p->lower_name, dat);
        free(dat);
        free(p);
    }
    printf("workload_nist: %zu NIST StRD problems (Start 1): ", N_NIST);
    for (size_t i = 0; i < N_NIST; ++i)
        printf("%s%s", NIST_CASES[i], i + 1 < N_NIST ? ", " : "\n");
    char *out = str("%s/out", scratch);
    job_list *one_each = calloc(1, sizeof *one_each), *batch = calloc(1, sizeof *batch),
             *py_each = calloc(1, sizeof *py_each), *py_all = calloc(1, sizeof *py_all),
             *version = calloc(1, sizeof *version);
    if (!one_each || !batch || !py_each || !py_all || !version)
        return 1;
    batch->n = py_all->n = 1;
    size_t b = 0, pa = 0;
    batch->argv[0][b++] = phytocal;
    batch->argv[0][b++] = "fit";
    py_all->argv[0][pa++] = (char *)python;
    py_all->argv[0][pa++] = peer;
    for (size_t i = 0; i < N_NIST; ++i) {
        char *const one[] = {phytocal, "fit", configs[i], "-o", str("%s/%zu", out, i), "-q", NULL};
        memcpy(one_each->argv[i], one, sizeof one);
        char *const py[] = {(char *)python, peer, peer_args[i], NULL};
        memcpy(py_each->argv[i], py, sizeof py);
        char *const v[] = {phytocal, "version", NULL};
        memcpy(version->argv[i], v, sizeof v);
        batch->argv[0][b++] = configs[i];
        py_all->argv[0][pa++] = peer_args[i];
    }
    one_each->n = py_each->n = version->n = N_NIST;
    batch->argv[0][b++] = "-o";
    batch->argv[0][b++] = str("%s/batch", out);
    batch->argv[0][b++] = "-q";

    const timing t_version = time_rounds(version, out);
    const timing t_each = time_rounds(one_each, out);
    const timing t_batch = time_rounds(batch, out);
    const timing t_py_each = time_rounds(py_each, out);
    const timing t_py_all = time_rounds(py_all, out);
    print_timing("nist_phytocal_process_per_fit", N_NIST, t_each, one_each);
    print_timing("nist_phytocal_one_call", N_NIST, t_batch, batch);
    print_timing("nist_scipy_process_per_fit", N_NIST, t_py_each, py_each);
    print_timing("nist_scipy_one_process", N_NIST, t_py_all, py_all);
    printf("nist_batch_speedup: %.1f x (phytocal one process per fit / one call; target >= 10)\n",
           t_each.wall / t_batch.wall);
    printf("nist_batch_vs_scipy_process_per_fit: %.1f x\n", t_py_each.wall / t_batch.wall);
    printf("nist_batch_vs_scipy_one_process: %.1f x\n", t_py_all.wall / t_batch.wall);
    printf("startup_phytocal_version: %.1f ms wall per process (%.1f ms CPU)\n", 1e3 * t_version.wall / N_NIST,
           1e3 * t_version.cpu / N_NIST);
    /* CPU times: steadier than wall times on a shared machine */
    const double start_cpu = t_version.cpu / N_NIST, fit_cpu = (t_batch.cpu - start_cpu) / N_NIST;
    const double each_cpu = t_each.cpu / N_NIST;
    printf("split_process_per_fit: %.1f ms CPU per fit = start-up (phytocal version) %.1f ms + fit, report, plots "
           "and files %.1f ms (the one call's CPU less one start-up, per fit) + %.1f ms other once-per-process "
           "costs\n", 1e3 * each_cpu, 1e3 * start_cpu, 1e3 * fit_cpu, 1e3 * (each_cpu - start_cpu - fit_cpu));
    printf("batch_speedup_limit: %.1f x for many fits (CPU of a process per fit / CPU per fit in one call)\n",
           each_cpu / fit_cpu);

    /* (b) the bundled example, --each run */
    job_list *runs_each = calloc(1, sizeof *runs_each), *runs_batch = calloc(1, sizeof *runs_batch);
    if (!runs_each || !runs_batch)
        return 1;
    char *src = str("%s/measurements/examples/enzyme_kinetics", PHC_SOURCE_DIR);
    for (size_t k = 0; k < N_RUNS; ++k) {
        char id[8];
        snprintf(id, sizeof id, "r%02zu", k + 1);
        char *dir = str("%s/%s", scratch, id);
        mkdir(dir, 0777);
        if (write_run_case(src, dir, id)) {
            fprintf(stderr, "bench_batch: cannot write the case of run %s in %s\n", id, dir);
            return 1;
        }
        char *const one[] = {phytocal, "fit", str("%s/enzyme_runs.yaml", dir), "-o", str("%s/%s", out, id), "-q",
                             NULL};
        memcpy(runs_each->argv[k], one, sizeof one);
    }
    runs_each->n = N_RUNS;
    char *const each[] = {phytocal, "fit", str("%s/enzyme_runs.yaml", src), "--each", "run", "-o",
                          str("%s/each", out), "-q", NULL};
    memcpy(runs_batch->argv[0], each, sizeof each);
    runs_batch->n = 1;
    const timing t_runs_each = time_rounds(runs_each, out);
    const timing t_runs_batch = time_rounds(runs_batch, out);
    print_timing("enzyme_runs_process_per_fit", N_RUNS, t_runs_each, runs_each);
    print_timing("enzyme_runs_each_call", N_RUNS, t_runs_batch, runs_batch);
    printf("enzyme_runs_batch_speedup: %.1f x (one process per run / one --each call; target >= 10)\n",
           t_runs_each.wall / t_runs_batch.wall);
    remove_dir(scratch);
    return one_each->failures || batch->failures || py_each->failures || py_all->failures || runs_each->failures ||
                   runs_batch->failures
               ? 1
               : 0;
}
