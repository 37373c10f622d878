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
 *   build/bench_bench_study_mpi [N [R]]     (N base samples, default 1024;
 *                                            R runs, default 3, 1 under
 *                                            PHC_BENCH_QUICK=1)
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

/* One study into TMP/OUT (mpi: under mpirun -np 2; resume: from OUT.ledger);
 * its wall time in seconds, or -1 when it failed.  *load: CPUs kept busy
 * by other processes meanwhile. */
static double study(int mpi, const char *out, const char *samples, int resume, double *load)
{
    char dir[4200];
    snprintf(dir, sizeof dir, "%s/%s", tmp, out);
    char *argv[20];
    int n = 0;
    if (mpi) {
        argv[n++] = "mpirun";
        argv[n++] = "-np";
        argv[n++] = "2";
    }
    argv[n++] = phytocal;
    argv[n++] = "sensitivity";
    argv[n++] = config;
    argv[n++] = "-o";
    argv[n++] = dir;
    argv[n++] = "--samples";
    argv[n++] = (char *)samples;
    argv[n++] = "--force";
    argv[n++] = "-q";
    if (resume)
        argv[n++] = "--resume";
    argv[n] = NULL;
    const mark a = mark_now();
    const int rc = run(argv);
    const mark b = mark_now();
    const double other = ((b.machine - a.machine) - (b.children - a.children)) / (b.wall - a.wall);
    *load = other < 0 ? 0 : other;
    if (rc != 0) {
        fprintf(stderr, "bench_study_mpi: %s%s sensitivity ... -o %s: exit %d\n", mpi ? "mpirun -np 2 " : "",
                phytocal, dir, rc);
        return -1;
    }
    return b.wall - a.wall;
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

int main(int argc, char **argv)
{
    const char *samples = argc > 1 ? argv[1] : "1024";
    const int reps = argc > 2 ? atoi(argv[2]) : bench_repeats(3);
    const long n_base = strtol(samples, NULL, 10);
    if (n_base < 8 || reps < 1) {
        fprintf(stderr, "usage: bench_bench_study_mpi [N >= 8 [R >= 1]]\n");
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
    if (system(cmd) != 0)
        fprintf(stderr, "bench_study_mpi: could not remove %s\n", tmp);
    if (!ok)
        return 1;
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
    return identical ? 0 : 1;
}
