/* Benchmark: `phytocal sensitivity` on the demo's weight-curve seedling
 * (measurements/examples/weight_curve/seedling_sensitivity.yaml, Sobol)
 * in one process and under `mpirun -np 2` (fit/study_dist.h: the master
 * evaluates rows too), timed as whole commands (fork + exec, wall clock,
 * the minimum of R runs).  The fixed part of each (loading the config,
 * MPI start-up under mpirun, the estimates, the files) is timed by the
 * same study resumed from its complete ledger, which evaluates nothing;
 * the evaluation rate is the evaluations over the time minus that part.
 * Issue 14's target: >= 1.8x the evaluation rate with 2 ranks on 2 cores.
 * It also checks that both runs wrote the same result.json, byte for byte.
 *
 * Then `phytocal mcmc --method stretch` on the same config (32 walkers, its
 * posterior: about 1 ms per model evaluation), in one process and under
 * `mpirun -np 2` (mcmc_study.h: every rank runs the ensemble and evaluates
 * its half of each half-step's proposals), at S and at S0 = S / 2 sweeps;
 * the sampling rate is the extra proposals over the extra time (the fit,
 * diagnostics, files and MPI start-up, the same at S and S0, drop out).
 * The same target, >= 1.8x with 2 ranks.  CPU time of the commands
 * (children's user + system, the ranks included) and the other processes'
 * load are printed beside the wall times; result.json of one process and
 * of 2 ranks must be identical.
 *
 *   build/bench_bench_study_mpi [N [R [S]]] (N base samples, default 1024;
 *                                            R runs, default 3, 1 under
 *                                            PHC_BENCH_QUICK=1; S sweeps of
 *                                            the stretch run, default 200)
 *   build/bench_bench_study_mpi stretch [R [S]]   (the stretch part alone)
 * Prints `name: value unit` lines.  Needs mpirun (Debian: openmpi-bin). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_machine.h"

static char phytocal[4096], config[4096], tmp[4096];

/* CPU seconds used by the machine and by this process's children so far. */
typedef struct mark {
    double wall, machine, children;
} mark;

static mark mark_now(void)
{
    cpu_mark c = cpu_now();
    struct rusage ru;
    mark m = {c.wall, c.machine, NAN};
    if (getrusage(RUSAGE_CHILDREN, &ru) == 0)
        m.children = ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
    return m;
}

/* Runs argv with stdout and stderr to /dev/null; its exit status or -1. */
static int run(char *const argv[])
{
    const pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))
            _exit(127);
        execvp(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* phytocal ARGS... (ARGS NULL-terminated, at most 16), under mpirun -np 2
 * when mpi; its wall time in seconds, or -1 when it failed (the message
 * names WHAT and DIR).  *cpu (may be NULL): the command's CPU seconds (user
 * + system of it and its descendants); *load: CPUs kept busy by other
 * processes meanwhile. */
static double timed_phytocal(int mpi, char *const *args, const char *what, const char *dir, double *cpu,
                             double *load)
{
    char *argv[24];
    int n = 0;
    if (mpi) {
        argv[n++] = "mpirun";
        argv[n++] = "-np";
        argv[n++] = "2";
    }
    argv[n++] = phytocal;
    for (int i = 0; args[i] && n < 23; ++i)
        argv[n++] = args[i];
    argv[n] = NULL;
    const mark a = mark_now();
    const int rc = run(argv);
    const mark b = mark_now();
    const double used = b.children - a.children;
    if (cpu)
        *cpu = used;
    const double other = ((b.machine - a.machine) - used) / (b.wall - a.wall);
    *load = other < 0 ? 0 : other;
    if (rc != 0) {
        fprintf(stderr, "bench_study_mpi: %s%s %s ... -o %s: exit %d\n", mpi ? "mpirun -np 2 " : "", phytocal,
                what, dir, rc);
        return -1;
    }
    return b.wall - a.wall;
}

/* One study into TMP/OUT (mpi: under mpirun -np 2; resume: from OUT.ledger);
 * its wall time in seconds, or -1 when it failed.  *load: CPUs kept busy
 * by other processes meanwhile. */
static double study(int mpi, const char *out, const char *samples, int resume, double *load)
{
    char dir[4200];
    snprintf(dir, sizeof dir, "%s/%s", tmp, out);
    char *args[] = {"sensitivity", config, "-o", dir, "--samples", (char *)samples, "--force", "-q",
                    resume ? "--resume" : NULL, NULL};
    return timed_phytocal(mpi, args, "sensitivity", dir, NULL, load);
}

/* Copies TMP/FROM/ledger.tsv (a finished study's) to TMP/TO.ledger. */
static int restore_ledger(const char *from, const char *to)
{
    char src[4200], dst[4200];
    snprintf(src, sizeof src, "%s/%s/ledger.tsv", tmp, from);
    snprintf(dst, sizeof dst, "%s/%s.ledger", tmp, to);
    FILE *in = fopen(src, "rb"), *outf = in ? fopen(dst, "wb") : NULL;
    if (!in || !outf) {
        fprintf(stderr, "bench_study_mpi: cannot copy %s to %s: %s\n", src, dst, strerror(errno));
        if (in)
            fclose(in);
        return -1;
    }
    char buf[65536];
    size_t k;
    while ((k = fread(buf, 1, sizeof buf, in)) > 0)
        fwrite(buf, 1, k, outf);
    fclose(in);
    return fclose(outf) == 0 ? 0 : -1;
}

static int same_file(const char *a, const char *b)
{
    char pa[4200], pb[4200];
    snprintf(pa, sizeof pa, "%s/%s", tmp, a);
    snprintf(pb, sizeof pb, "%s/%s", tmp, b);
    FILE *fa = fopen(pa, "rb"), *fb = fopen(pb, "rb");
    int same = fa && fb;
    while (same) {
        const int ca = fgetc(fa), cb = fgetc(fb);
        if (ca != cb)
            same = 0;
        if (ca == EOF || cb == EOF)
            break;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

/* One `phytocal mcmc --method stretch` of the config into TMP/OUT (mpi:
 * under mpirun -np 2) with `sweeps` sweeps of 32 walkers; its wall time in
 * seconds, or -1 when it failed; *cpu: the command's CPU seconds (user +
 * system of it and its descendants); *load: other processes' CPUs. */
static double stretch_run(int mpi, const char *out, const char *sweeps, double *cpu, double *load)
{
    char dir[4200];
    snprintf(dir, sizeof dir, "%s/%s", tmp, out);
    char *args[] = {"mcmc", config, "-o", dir, "--method", "stretch", "--samples", (char *)sweeps,
                    "--chains", "32", "--seed", "1", "--force", "-q", NULL};
    return timed_phytocal(mpi, args, "mcmc --method stretch", dir, cpu, load);
}

/* The count of model evaluations in TMP/DIR/report.md, or -1. */
static long report_evaluations(const char *dir)
{
    char path[4200], line[4096];
    snprintf(path, sizeof path, "%s/%s/report.md", tmp, dir);
    FILE *f = fopen(path, "r");
    long n = -1;
    while (f && n < 0 && fgets(line, sizeof line, f)) {
        const char *k = strstr(line, "Model evaluations in this run: ");
        if (k)
            n = strtol(k + strlen("Model evaluations in this run: "), NULL, 10);
    }
    if (f)
        fclose(f);
    return n;
}

typedef struct best {
    double wall, cpu, load;
} best;

static void keep_best(best *b, double wall, double cpu, double load)
{
    if (wall > 0 && wall < b->wall) {
        b->wall = wall;
        b->cpu = cpu;
        b->load = load;
    }
}

/* The stretch part: returns 0 when every run succeeded and the results are
 * identical, else 1. */
static int bench_stretch(int reps, long sweeps)
{
    char s_full[32], s_half[32];
    snprintf(s_full, sizeof s_full, "%ld", sweeps);
    snprintf(s_half, sizeof s_half, "%ld", sweeps / 2);
    best one = {INFINITY, 0, 0}, two = {INFINITY, 0, 0}, one0 = {INFINITY, 0, 0}, two0 = {INFINITY, 0, 0};
    int ok = 1;
    for (int r = 0; r < reps && ok; ++r) {
        double cpu, load, t;
        ok &= (t = stretch_run(0, "mcmc_one", s_full, &cpu, &load)) > 0;
        keep_best(&one, t, cpu, load);
        ok &= (t = stretch_run(1, "mcmc_two", s_full, &cpu, &load)) > 0;
        keep_best(&two, t, cpu, load);
        ok &= (t = stretch_run(0, "mcmc_one0", s_half, &cpu, &load)) > 0;
        keep_best(&one0, t, cpu, load);
        ok &= (t = stretch_run(1, "mcmc_two0", s_half, &cpu, &load)) > 0;
        keep_best(&two0, t, cpu, load);
    }
    if (!ok)
        return 1;
    const int identical = same_file("mcmc_one/result.json", "mcmc_two/result.json") &&
                          same_file("mcmc_one0/result.json", "mcmc_two0/result.json");
    const long e1 = report_evaluations("mcmc_one"), e2 = report_evaluations("mcmc_two");
    const long extra = 32 * (sweeps - 1 - (sweeps / 2 - 1)); /* proposals of the extra sweeps */
    printf("stretch: mcmc --method stretch on the weight-curve seedling (seedling_sensitivity.yaml), 32 walkers x "
           "%ld sweeps and x %ld (S0)\n", sweeps, sweeps / 2);
    printf("stretch_evaluations: %ld (report.md, one process), %ld (2 ranks, the ranks' counts summed)\n", e1, e2);
    printf("stretch_one_process_time: %.2f s (whole command, minimum of %d; CPU %.2f s; S0: %.2f s, CPU %.2f s)\n",
           one.wall, reps, one.cpu, one0.wall, one0.cpu);
    printf("stretch_mpi2_time: %.2f s (mpirun -np 2, whole command, minimum of %d; CPU %.2f s of both ranks; S0: "
           "%.2f s, CPU %.2f s)\n", two.wall, reps, two.cpu, two0.wall, two0.cpu);
    printf("stretch_one_process_proposals_per_s: %.0f (the %ld proposals of the extra sweeps / the extra time)\n",
           (double)extra / (one.wall - one0.wall), extra);
    printf("stretch_mpi2_proposals_per_s: %.0f\n", (double)extra / (two.wall - two0.wall));
    printf("stretch_mpi2_speedup: %.2f x (sampling rate, 2 ranks / 1 process; target >= 1.8)\n",
           (one.wall - one0.wall) / (two.wall - two0.wall));
    printf("stretch_mpi2_command_speedup: %.2f x (whole commands)\n", one.wall / two.wall);
    printf("stretch_other_load: %.2f CPUs during the fastest one-process run, %.2f during the fastest MPI run\n",
           one.load, two.load);
    printf("stretch_identical: %s (result.json of 1 process and 2 ranks, at S and S0; evaluations %s)\n",
           identical ? "yes" : "NO", e1 == e2 && e1 > 0 ? "equal" : "DIFFER");
    return identical && e1 == e2 && e1 > 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
    const int only_stretch = argc > 1 && strcmp(argv[1], "stretch") == 0;
    /* argv[1]: N or "stretch"; then R and S */
    const char *samples = !only_stretch && argc > 1 ? argv[1] : "1024";
    const int reps = argc > 2 ? atoi(argv[2]) : bench_repeats(3);
    const long sweeps = argc > 3 ? strtol(argv[3], NULL, 10) : 200;
    const long n_base = strtol(samples, NULL, 10);
    if (n_base < 8 || reps < 1 || sweeps < 2 * 100) {
        fprintf(stderr, "usage: bench_bench_study_mpi [N >= 8 [R >= 1 [S >= 200]]]\n"
                        "       bench_bench_study_mpi stretch [R >= 1 [S >= 200]]\n");
        return 2;
    }
    /* the phytocal command beside this program (both in the build folder) */
    char self[4000];
    const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0) {
        fprintf(stderr, "bench_study_mpi: cannot read /proc/self/exe\n");
        return 2;
    }
    self[len] = '\0';
    *strrchr(self, '/') = '\0';
    snprintf(phytocal, sizeof phytocal, "%s/phytocal", self);
    snprintf(config, sizeof config, "%s/measurements/examples/weight_curve/seedling_sensitivity.yaml", PHC_SOURCE_DIR);
    if (access(phytocal, X_OK) != 0) {
        fprintf(stderr, "bench_study_mpi: %s: not found (cmake --build build --target phytocal)\n", phytocal);
        return 2;
    }
    if (system("command -v mpirun >/dev/null 2>&1") != 0) {
        fprintf(stderr, "bench_study_mpi: mpirun not found (Debian: openmpi-bin)\n");
        return 77;
    }
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1); /* Open MPI refuses root without both */
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    snprintf(tmp, sizeof tmp, "%s/phc_bench_study_mpi.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmp)) {
        fprintf(stderr, "bench_study_mpi: mkdtemp: %s\n", strerror(errno));
        return 2;
    }
    if (only_stretch) {
        const int bad = bench_stretch(reps, sweeps);
        char cmd[4300];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
        if (system(cmd) != 0)
            fprintf(stderr, "bench_study_mpi: could not remove %s\n", tmp);
        return bad;
    }
    /* rows of the Saltelli design: N (k + 2) for the config's 3 factors */
    const long rows = n_base * 5;
    double t1 = INFINITY, t2 = INFINITY, f1 = INFINITY, f2 = INFINITY, load1 = 0, load2 = 0, l;
    int ok = 1;
    for (int r = 0; r < reps && ok; ++r) {
        double t = study(0, "one", samples, 0, &l);
        ok &= t > 0;
        if (t > 0 && t < t1) {
            t1 = t;
            load1 = l;
        }
        t = study(1, "two", samples, 0, &l);
        ok &= t > 0;
        if (t > 0 && t < t2) {
            t2 = t;
            load2 = l;
        }
        /* the fixed part: the same study with every evaluation in the ledger */
        ok &= restore_ledger("one", "fixed1") == 0 && restore_ledger("one", "fixed2") == 0;
        t = study(0, "fixed1", samples, 1, &l);
        ok &= t > 0;
        f1 = t > 0 && t < f1 ? t : f1;
        t = study(1, "fixed2", samples, 1, &l);
        ok &= t > 0;
        f2 = t > 0 && t < f2 ? t : f2;
    }
    const int identical = ok && same_file("one/result.json", "two/result.json") &&
                          same_file("one/result.json", "fixed2/result.json");
    char cmd[4300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
    if (!ok) {
        if (system(cmd) != 0)
            fprintf(stderr, "bench_study_mpi: could not remove %s\n", tmp);
        return 1;
    }
    printf("study: Sobol on the weight-curve seedling (seedling_sensitivity.yaml), N = %ld, %ld evaluations\n",
           n_base, rows);
    printf("one_process_time: %.2f s (whole command, minimum of %d)\n", t1, reps);
    printf("mpi2_time: %.2f s (mpirun -np 2, whole command, minimum of %d)\n", t2, reps);
    printf("one_process_fixed_time: %.2f s (the study resumed from its complete ledger: load, estimate, write)\n", f1);
    printf("mpi2_fixed_time: %.2f s (the same under mpirun -np 2: with MPI start-up)\n", f2);
    printf("one_process_evaluations_per_s: %.0f (evaluations / (time - fixed time))\n", rows / (t1 - f1));
    printf("mpi2_evaluations_per_s: %.0f\n", rows / (t2 - f2));
    printf("mpi2_speedup: %.2f x (evaluation rate, 2 ranks / 1 process; target >= 1.8)\n",
           (t1 - f1) / (t2 - f2));
    printf("mpi2_command_speedup: %.2f x (whole commands)\n", t1 / t2);
    printf("other_load: %.2f CPUs during the fastest one-process run, %.2f during the fastest MPI run\n", load1,
           load2);
    printf("identical: %s (result.json of 1 process, 2 ranks, 2 ranks resumed)\n", identical ? "yes" : "NO");
    fflush(stdout);
    const int stretch_bad = bench_stretch(reps, sweeps);
    if (system(cmd) != 0)
        fprintf(stderr, "bench_study_mpi: could not remove %s\n", tmp);
    return identical && !stretch_bad ? 0 : 1;
}
