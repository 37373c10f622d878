/* Benchmark of batch fits (issue 16, "a batch mode for many small fits in
 * one process, >= 10x faster than one process per fit"): N small fits one
 * `phytocal fit` process each against one batch call, each side once with
 * the plots (the default) and once with `--plots none`, beside SciPy one
 * Python process per fit and all in one.
 *
 *   build/bench_bench_batch [GROUPS]     (GROUPS: runs of the generated table, default 120)
 *
 * Workloads:
 *  (a) ten small NIST StRD problems (../shared/data/nist, Start 1): the
 *      eight of lower difficulty (Misra1a, Chwirut2, Chwirut1, Lanczos3,
 *      Gauss1, Gauss2, DanWood, Misra1b) and Misra1c, Misra1d (average
 *      difficulty, the same two-parameter model family), written as `curve`
 *      configs by nist_write_case (tests/nist_problem.h);
 *        phytocal, one process per fit:  `phytocal fit CASE.yaml -o DIR -q [--plots none]` x 10
 *        phytocal, one call:             `phytocal fit CASE1.yaml ... CASE10.yaml -o DIR -q [--plots none]`
 *        SciPy, a process per fit:       `python3 batch_peer.py NAME=CSV=DAT` x 10
 *        SciPy, one process:             `python3 batch_peer.py` with all ten
 *      (phytocal writes each fit's run directory: result.json, report.md,
 *      the plots unless --plots none, manifest; SciPy fits and computes the
 *      covariance only).  Ten fits bound any ratio of the first two by 10;
 *  (b) the bundled example measurements/examples/enzyme_kinetics/
 *      enzyme_runs.yaml: twelve runs in one table, `--each run` against twelve
 *      processes, each fitting a config whose table holds one run's rows;
 *  (c) the same config on a table of GROUPS runs written by the committed
 *      generator (enzyme_kinetics/generate_runs.py GROUPS, the same model and
 *      noise), `--each run` against GROUPS processes: many fits, so that the
 *      ratio is not capped by N.  The target line is
 *      plate_batch_speedup_no_plots (--plots none on both sides).
 * The split (CPU times): `phytocal version` (start-up alone), and per fit
 * the batch call's CPU less one start-up, / N (the work a process per fit
 * does besides start-up); and the ratio a batch can reach at best.
 *
 * Each timing is the minimum wall time of 2 rounds (the machine is shared;
 * the load of other processes during the rounds is printed); child CPU time
 * (user + system, getrusage) beside it.  Every round writes into a folder of
 * its own, all removed at the end: on a file system without a journal (this
 * machine's ext4) creating a file right after thousands were deleted makes
 * the kernel scan the recently deleted inodes, which would charge the
 * previous round's clean-up to the next.  The phytocal binary is the one
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
#define N_RUNS 12
#define DEFAULT_GROUPS 120

static const char *const NIST_CASES[] = {"Misra1a", "Chwirut2", "Chwirut1", "Lanczos3", "Gauss1",
                                         "Gauss2",  "DanWood",  "Misra1b",  "Misra1c",  "Misra1d"};
#define N_NIST (sizeof NIST_CASES / sizeof NIST_CASES[0])

static char scratch[PATH_MAX];

static double child_cpu(void)
{
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    return ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
}

/* Runs argv (no shell) in folder cwd, output to /dev/null (stdout to
 * `out` when given); returns its exit code, -1 when it could not run. */
static int run_in(const char *cwd, char *const argv[], const char *out)
{
    const pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        const int fd = open("/dev/null", O_WRONLY);
        const int fo = out ? open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644) : fd;
        if (fd >= 0 && fo >= 0) {
            dup2(fo, STDOUT_FILENO);
            dup2(fd, STDERR_FILENO);
        }
        if (cwd && chdir(cwd) != 0)
            _exit(126);
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
    char *const argv[] = {"/bin/rm", "-rf", (char *)dir, NULL};
    if (run_in(NULL, argv, NULL) != 0)
        fprintf(stderr, "bench_batch: could not remove %s\n", dir);
}

static void *checked(void *p)
{
    if (!p) {
        fprintf(stderr, "bench_batch: out of memory\n");
        exit(1);
    }
    return p;
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
    return checked(s);
}

/* A list of command lines, run one after another: one round.  Output
 * folders are relative: each round runs in a new folder of its own. */
typedef struct job_list {
    char ***argv; /* NULL-terminated argument lists */
    size_t n;
    int failures;
} job_list;

static job_list *jobs_new(size_t n)
{
    job_list *j = checked(calloc(1, sizeof *j));
    j->argv = checked(calloc(n, sizeof *j->argv));
    j->n = n;
    return j;
}

/* job k: the arguments given, then "-q" and, when no_plots, "--plots none" */
static void job_set(job_list *j, size_t k, int no_plots, char **args, size_t n_args)
{
    char **a = checked(calloc(n_args + 4, sizeof *a));
    memcpy(a, args, n_args * sizeof *a);
    a[n_args] = "-q";
    if (no_plots) {
        a[n_args + 1] = "--plots";
        a[n_args + 2] = "none";
    }
    j->argv[k] = a;
}

typedef struct timing {
    double wall, cpu, load;
} timing;

static timing time_rounds(job_list *jobs, const char *label)
{
    timing best = {1e300, 0, 0};
    for (int r = 0; r < bench_repeats(ROUNDS); ++r) {
        char *dir = str("%s/out_%s_%d", scratch, label, r);
        mkdir(dir, 0777);
        const cpu_mark a = cpu_now();
        const double c0 = child_cpu();
        for (size_t j = 0; j < jobs->n; ++j)
            jobs->failures += run_in(dir, jobs->argv[j], NULL) != 0;
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
        free(dir);
    }
    return best;
}

static void print_timing(const char *name, size_t n, timing t, const job_list *jobs)
{
    printf("%s: %.3f s wall, %.3f s CPU for %zu fits (%.2f ms per fit; other load %.1f CPUs)%s\n", name, t.wall,
           t.cpu, n, 1e3 * t.wall / (double)n, t.load, jobs->failures ? "  SOME RUNS FAILED" : "");
}

static void print_ratio(const char *name, timing each, timing batch, const char *what)
{
    printf("%s: %.1f x (wall; CPU %.1f x; %s)\n", name, each.wall / batch.wall, each.cpu / batch.cpu, what);
}

/* Copies src's lines to dst: the comments, the header, and the rows whose
 * first cell is run_id. */
static int write_run_table(const char *src, const char *dst, const char *run_id)
{
    FILE *in = fopen(src, "r");
    FILE *out = in ? fopen(dst, "w") : NULL;
    if (!out) {
        if (in)
            fclose(in);
        return -1;
    }
    char line[1024];
    int header_seen = 0;
    const size_t len = strlen(run_id);
    while (fgets(line, sizeof line, in)) {
        if (line[0] == '#' || !header_seen || (strncmp(line, run_id, len) == 0 && line[len] == ','))
            fputs(line, out);
        header_seen |= line[0] != '#';
    }
    fclose(in);
    return fclose(out) == 0 ? 0 : -1;
}

static int copy_file(const char *src, const char *dst)
{
    char *const argv[] = {"/bin/cp", (char *)src, (char *)dst, NULL};
    return run_in(NULL, argv, NULL) == 0 ? 0 : -1;
}

/* The runs of a table whose first column is the run: r01..r12 or r001.. */
static char *run_id(size_t k, size_t n)
{
    return n < 100 ? str("r%02zu", k + 1) : str("r%0*zu", (int)snprintf(NULL, 0, "%zu", n), k + 1);
}

/* A --each workload: `phytocal fit DIR/enzyme_runs.yaml --each run` over the
 * table DIR/enzyme_runs.csv of n runs, against n processes each fitting a
 * copy of the config beside a table of one run's rows; with and without
 * plots.  Prints the four timings and the two ratios. */
static void each_workload(const char *phytocal, const char *label, const char *dir, size_t n,
                          const char *what_no_plots, int *failures)
{
    job_list *each[2], *call[2];
    char *yaml = str("%s/enzyme_runs.yaml", dir), *csv = str("%s/enzyme_runs.csv", dir);
    for (int np = 0; np < 2; ++np) {
        each[np] = jobs_new(n);
        call[np] = jobs_new(1);
    }
    for (size_t k = 0; k < n; ++k) {
        char *id = run_id(k, n), *case_dir = str("%s/cases_%s/%s", scratch, label, id);
        char *parent = str("%s/cases_%s", scratch, label);
        mkdir(parent, 0777);
        mkdir(case_dir, 0777);
        char *case_csv = str("%s/enzyme_runs.csv", case_dir), *case_yaml = str("%s/enzyme_runs.yaml", case_dir);
        if (write_run_table(csv, case_csv, id) || copy_file(yaml, case_yaml)) {
            fprintf(stderr, "bench_batch: cannot write the case of run %s in %s\n", id, case_dir);
            exit(1);
        }
        for (int np = 0; np < 2; ++np) {
            char *args[] = {(char *)phytocal, "fit", case_yaml, "-o", id};
            job_set(each[np], k, np, args, 5);
        }
        free(case_dir);
        free(parent);
        free(case_csv);
    }
    for (int np = 0; np < 2; ++np) {
        char *args[] = {(char *)phytocal, "fit", yaml, "--each", "run", "-o", "each"};
        job_set(call[np], 0, np, args, 7);
    }
    timing t_each[2], t_call[2];
    for (int np = 0; np < 2; ++np) {
        t_each[np] = time_rounds(each[np], str("%s_each_%d", label, np));
        t_call[np] = time_rounds(call[np], str("%s_call_%d", label, np));
    }
    for (int np = 0; np < 2; ++np) {
        const char *suffix = np ? "_no_plots" : "";
        print_timing(str("%s_process_per_fit%s", label, suffix), n, t_each[np], each[np]);
        print_timing(str("%s_each_call%s", label, suffix), n, t_call[np], call[np]);
        print_ratio(str("%s_batch_speedup%s", label, suffix), t_each[np], t_call[np],
                    np ? what_no_plots : "with plots on both sides: one process per run / one --each call");
        *failures += each[np]->failures + call[np]->failures;
    }
}

int main(int argc, char **argv)
{
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
    size_t groups = DEFAULT_GROUPS;
    if (argc > 1) {
        char *end = NULL;
        const unsigned long v = strtoul(argv[1], &end, 10);
        if (!*argv[1] || *end || v < 2 || v > 100000) {
            fprintf(stderr, "usage: bench_bench_batch [GROUPS]   (runs of the generated table, 2 to 100000; "
                            "default %d)\n", DEFAULT_GROUPS);
            return 2;
        }
        groups = v;
    }
    const char *python = "/usr/bin/python3";
    char *peer = str("%s/tests/bench/batch_peer.py", PHC_SOURCE_DIR);
    snprintf(scratch, sizeof scratch, "%s/phc_bench_batch.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(scratch)) {
        fprintf(stderr, "bench_batch: cannot make a scratch directory\n");
        return 1;
    }
    char *cases = str("%s/cases", scratch);
    mkdir(cases, 0777);
    int failures = 0;

    /* (a) NIST */
    char *configs[N_NIST], *peer_args[N_NIST];
    for (size_t i = 0; i < N_NIST; ++i) {
        nist_problem *p = checked(malloc(sizeof *p));
        char msg[512], cfg[PATH_MAX];
        char *dat = str("%s/nist/%s.dat", PHC_SHARED_DATA, NIST_CASES[i]);
        if (nist_load(dat, p, msg, sizeof msg) || nist_write_case(p, 1, cases, cfg, sizeof cfg, msg, sizeof msg)) {
            fprintf(stderr, "bench_batch: %s\n", msg);
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
    job_list *one_each[2], *batch[2];
    job_list *py_each = jobs_new(N_NIST), *py_all = jobs_new(1), *version = jobs_new(N_NIST);
    char **batch_args = checked(calloc(N_NIST + 4, sizeof *batch_args));
    char **py_all_args = checked(calloc(N_NIST + 3, sizeof *py_all_args));
    size_t b = 0, pa = 0;
    batch_args[b++] = phytocal;
    batch_args[b++] = "fit";
    py_all_args[pa++] = (char *)python;
    py_all_args[pa++] = peer;
    for (size_t i = 0; i < N_NIST; ++i) {
        batch_args[b++] = configs[i];
        py_all_args[pa++] = peer_args[i];
        char *py[] = {(char *)python, peer, peer_args[i], NULL};
        py_each->argv[i] = checked(calloc(4, sizeof(char *)));
        memcpy(py_each->argv[i], py, sizeof py);
        char *v[] = {phytocal, "version", NULL};
        version->argv[i] = checked(calloc(3, sizeof(char *)));
        memcpy(version->argv[i], v, sizeof v);
    }
    py_all->argv[0] = py_all_args;
    batch_args[b++] = "-o";
    batch_args[b++] = "batch";
    for (int np = 0; np < 2; ++np) {
        one_each[np] = jobs_new(N_NIST);
        batch[np] = jobs_new(1);
        for (size_t i = 0; i < N_NIST; ++i) {
            char *one[] = {phytocal, "fit", configs[i], "-o", str("fit%zu", i)};
            job_set(one_each[np], i, np, one, 5);
        }
        job_set(batch[np], 0, np, batch_args, b);
    }

    const timing t_version = time_rounds(version, "version");
    timing t_each[2], t_batch[2];
    for (int np = 0; np < 2; ++np) {
        t_each[np] = time_rounds(one_each[np], np ? "nist_each_np" : "nist_each");
        t_batch[np] = time_rounds(batch[np], np ? "nist_batch_np" : "nist_batch");
    }
    const timing t_py_each = time_rounds(py_each, "py_each");
    const timing t_py_all = time_rounds(py_all, "py_all");
    print_timing("nist_phytocal_process_per_fit", N_NIST, t_each[0], one_each[0]);
    print_timing("nist_phytocal_one_call", N_NIST, t_batch[0], batch[0]);
    print_timing("nist_scipy_process_per_fit", N_NIST, t_py_each, py_each);
    print_timing("nist_scipy_one_process", N_NIST, t_py_all, py_all);
    print_ratio("nist_batch_speedup", t_each[0], t_batch[0],
                "with plots on both sides: phytocal one process per fit / one call; 10 fits cap it near 10");
    printf("nist_batch_vs_scipy_process_per_fit: %.1f x\n", t_py_each.wall / t_batch[0].wall);
    printf("nist_batch_vs_scipy_one_process: %.1f x\n", t_py_all.wall / t_batch[0].wall);
    print_timing("nist_phytocal_process_per_fit_no_plots", N_NIST, t_each[1], one_each[1]);
    print_timing("nist_phytocal_one_call_no_plots", N_NIST, t_batch[1], batch[1]);
    print_ratio("nist_batch_speedup_no_plots", t_each[1], t_batch[1],
                "--plots none on both sides; 10 fits cap it near 10");
    printf("nist_no_plots_vs_scipy_one_process: %.1f x (SciPy all in one process / phytocal one call, --plots "
           "none)\n", t_py_all.wall / t_batch[1].wall);
    printf("startup_phytocal_version: %.1f ms wall per process (%.1f ms CPU)\n", 1e3 * t_version.wall / N_NIST,
           1e3 * t_version.cpu / N_NIST);
    /* CPU times: steadier than wall times on a shared machine */
    const double start_cpu = t_version.cpu / N_NIST;
    for (int np = 0; np < 2; ++np) {
        const double fit_cpu = (t_batch[np].cpu - start_cpu) / N_NIST, each_cpu = t_each[np].cpu / N_NIST;
        printf("split_process_per_fit%s: %.1f ms CPU per fit = start-up (phytocal version) %.1f ms + fit, report, "
               "%sfiles %.1f ms (the one call's CPU less one start-up, per fit) + %.1f ms other "
               "once-per-process costs\n", np ? "_no_plots" : "", 1e3 * each_cpu, 1e3 * start_cpu,
               np ? "" : "plots and ", 1e3 * fit_cpu, 1e3 * (each_cpu - start_cpu - fit_cpu));
        printf("batch_speedup_limit%s: %.1f x for many fits (CPU of a process per fit / CPU per fit in one call)\n",
               np ? "_no_plots" : "", each_cpu / fit_cpu);
    }
    failures += one_each[0]->failures + one_each[1]->failures + batch[0]->failures + batch[1]->failures +
                py_each->failures + py_all->failures;

    /* (b) the bundled example, --each run */
    char *src = str("%s/measurements/examples/enzyme_kinetics", PHC_SOURCE_DIR);
    each_workload(phytocal, "enzyme_runs", src, N_RUNS, "--plots none on both sides; 12 fits cap it near 12",
                  &failures);

    /* (c) a generated table of `groups` runs */
    char *plate = str("%s/plate", scratch);
    mkdir(plate, 0777);
    char *gen = str("%s/generate_runs.py", src), *plate_csv = str("%s/enzyme_runs.csv", plate);
    char *n_text = str("%zu", groups);
    char *gen_argv[] = {(char *)python, gen, n_text, NULL};
    if (run_in(NULL, gen_argv, plate_csv) != 0 || copy_file(str("%s/enzyme_runs.yaml", src), plate)) {
        fprintf(stderr, "bench_batch: cannot generate the table of %zu runs in %s\n", groups, plate);
        return 1;
    }
    printf("workload_plate: %zu runs of 14 points (enzyme_kinetics/generate_runs.py %zu), one config\n", groups,
           groups);
    each_workload(phytocal, "plate", plate, groups,
                  "--plots none on both sides: THE TARGET LINE, >= 10", &failures);
    remove_dir(scratch);
    return failures ? 1 : 0;
}
