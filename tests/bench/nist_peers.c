/* NIST StRD benchmark: phytocal against SciPy least_squares and lmfit
 * (issue 2, "Benchmark").  Not a test: built as build/bench_nist_peers, never
 * run by ctest.
 *
 *   bench_nist_peers [DATA_DIR] [--repeat R] [--derivatives D] [--no-peers] [--table]
 *
 * DATA_DIR holds NIST's *.dat files (default PHC_SHARED_DATA "/nist").
 *
 * phytocal side: every problem from Start 1 and Start 2 goes through the
 * user's config path (nist_run_case: config + CSV written to a temporary
 * directory, phc_config_load, phc_fit_run), R times (default 5).  Per fit the
 * MINIMUM time over the R runs is kept; total_time is the sum of these minima
 * (wall time; cpu_time likewise from the thread's CPU clock, which a busy
 * machine inflates less: the other load is printed as load_average).
 * Score: minimum LRE over the parameters (the lowest seen over the R runs);
 * "solved" means that minimum is >= 4 (Ceres's kMinNumMatchingDigits);
 * average_lre is the mean over all fits.
 *
 * Peers: /usr/bin/python3 PHC_SOURCE_DIR/tests/bench/nist_peers.py DATA_DIR
 * --repeat R, run in the same process run after the phytocal fits; its stdout
 * lines are re-printed unchanged and its *_total_time values give the speed
 * ratios (peer total time / phytocal total time).
 *
 * WHAT IS TIMED (so that the ratio is read honestly):
 *   phytocal: phc_fit_run in-process, i.e. the Ceres solve PLUS everything a
 *     user's fit does afterwards: covariance and standard errors,
 *     sensitivities, collinearity indices, goodness of fit and residual
 *     checks.  Loading the config and reading the CSV (phc_config_load) are
 *     outside the timing.
 *   peers: the least_squares / lmfit.minimize call only (Python timer
 *     around that call; lmfit's own post-fit covariance is inside it, SciPy's
 *     least_squares computes none).  Building the residual closure and the
 *     lmfit Parameters, interpreter start-up and imports are outside.
 * So phytocal is timed doing more work per fit than SciPy.
 *
 * speed_target says whether issue 16's target, SciPy's total time >= 10 x
 * phytocal's total time (fit plus full analysis) with every fit solved, is
 * met in this run.
 *
 * Profiling only phytocal's part: --no-peers (e.g. under perf record -g or
 * valgrind --tool=callgrind --toggle-collect=phc_fit_run).
 *
 * Exit status: 0 when everything ran, 77 when the data directory is missing or
 * holds no .dat files, 1 on any other failure (unreadable .dat file, peers'
 * script failed). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "nist_runner.h"

#define PYTHON "/usr/bin/python3"
#define PEERS_SCRIPT PHC_SOURCE_DIR "/tests/bench/nist_peers.py"
#define DEFAULT_REPEAT 5
#define MAX_FITS 256
#define SPEED_TARGET 10.0 /* issue 16: >= 10 x SciPy end to end */

/* The 1-, 5- and 15-minute load averages (/proc/loadavg) into buf, or "unknown". */
static void load_average(char *buf, size_t size)
{
    double a = 0, b = 0, c = 0;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f && fscanf(f, "%lf %lf %lf", &a, &b, &c) == 3)
        snprintf(buf, size, "%.2f %.2f %.2f", a, b, c);
    else
        snprintf(buf, size, "unknown");
    if (f)
        fclose(f);
}

static void usage(FILE *f)
{
    fprintf(f, "usage: bench_nist_peers [DATA_DIR] [--repeat R] [--derivatives D] [--no-peers] [--table]\n"
               "  DATA_DIR    NIST StRD *.dat files (default %s)\n"
               "  --repeat R  runs per fit, the minimum time is kept (default %d)\n"
               "  --derivatives D  central or ridders instead of the exact Jacobian\n"
               "  --no-peers  do not run the SciPy / lmfit peers\n"
               "  --table     print a per-fit table (peers' table goes to stderr)\n",
            PHC_SHARED_DATA "/nist", DEFAULT_REPEAT);
}

/* Appends s to buf single-quoted for /bin/sh; returns 0, or 1 if it does not fit. */
static int shell_quote(char *buf, size_t size, const char *s)
{
    size_t len = strlen(buf);
    if (len + 1 >= size)
        return 1;
    buf[len++] = '\'';
    for (; *s; ++s) {
        const char *piece = *s == '\'' ? "'\\''" : NULL;
        size_t plen = piece ? strlen(piece) : 1;
        if (len + plen + 2 >= size)
            return 1;
        if (piece) {
            memcpy(buf + len, piece, plen);
            len += plen;
        } else {
            buf[len++] = *s;
        }
    }
    buf[len++] = '\'';
    buf[len] = '\0';
    return 0;
}

/* 1 when /usr/bin/python3 can import the given modules. */
static int python_has(const char *modules)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "%s -c 'import %s' >/dev/null 2>&1", PYTHON, modules);
    int rc = system(cmd);
    return rc != -1 && WIFEXITED(rc) && WEXITSTATUS(rc) == 0;
}

/* Removes the files nist_run_case wrote into dir, then dir itself. */
static void remove_work_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d))) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            char path[4096];
            int w = snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            if (w > 0 && (size_t)w < sizeof path)
                unlink(path);
        }
        closedir(d);
    }
    if (rmdir(dir) != 0)
        fprintf(stderr, "warning: could not remove %s: %s\n", dir, strerror(errno));
}

typedef struct peer_total {
    const char *name;
    int available;
    int have_time;
    double time;
    int errors;
} peer_total;

/* Runs the peers' script; re-prints its stdout lines (dropping lines of a
 * peer that is not available) and parses <peer>_total_time / <peer>_errors.
 * Returns 0 when the script ran and exited 0. */
static int run_peers(const char *data_dir, int repeat, int table, peer_total *peers, int n_peers)
{
    char cmd[8192] = PYTHON " ";
    if (shell_quote(cmd, sizeof cmd, PEERS_SCRIPT) || strlen(cmd) + 2 >= sizeof cmd) {
        fprintf(stderr, "peers: command too long\n");
        return 1;
    }
    strcat(cmd, " ");
    if (shell_quote(cmd, sizeof cmd, data_dir)) {
        fprintf(stderr, "peers: command too long\n");
        return 1;
    }
    char tail[64];
    snprintf(tail, sizeof tail, " --repeat %d%s", repeat, table ? " --table" : "");
    if (strlen(cmd) + strlen(tail) >= sizeof cmd) {
        fprintf(stderr, "peers: command too long\n");
        return 1;
    }
    strcat(cmd, tail);

    fflush(stdout);
    FILE *p = popen(cmd, "r");
    if (!p) {
        fprintf(stderr, "peers: cannot run %s: %s\n", PYTHON, strerror(errno));
        return 1;
    }
    char line[1024];
    while (fgets(line, sizeof line, p)) {
        int keep = 1;
        for (int i = 0; i < n_peers; ++i) {
            size_t nl = strlen(peers[i].name);
            if (strncmp(line, peers[i].name, nl) != 0 || line[nl] != '_')
                continue;
            if (!peers[i].available) {
                keep = 0;
                break;
            }
            const char *rest = line + nl + 1;
            char *end;
            if (strncmp(rest, "total_time:", 11) == 0) {
                double v = strtod(rest + 11, &end);
                if (end != rest + 11) {
                    peers[i].time = v;
                    peers[i].have_time = 1;
                }
            } else if (strncmp(rest, "errors:", 7) == 0) {
                peers[i].errors = (int)strtol(rest + 7, &end, 10);
            }
        }
        if (keep)
            fputs(line, stdout);
    }
    int st = pclose(p);
    if (st == -1 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        printf("peers: %s failed (%s %d); no speed ratios\n", PEERS_SCRIPT,
               st != -1 && WIFSIGNALED(st) ? "signal" : "exit status",
               st == -1 ? -1 : WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st));
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *data_dir = PHC_SHARED_DATA "/nist";
    int repeat = DEFAULT_REPEAT, peers_wanted = 1, table = 0, have_dir = 0;
    const char *derivatives = NULL;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            char *end;
            long r = strtol(argv[++i], &end, 10);
            if (*end || end == argv[i] || r < 1 || r > 1000) {
                fprintf(stderr, "bench_nist_peers: --repeat wants an integer from 1 to 1000, not '%s'\n",
                        argv[i]);
                return 2;
            }
            repeat = (int)r;
        } else if (strcmp(argv[i], "--derivatives") == 0 && i + 1 < argc) {
            derivatives = argv[++i]; /* central | ridders: instead of the exact (AD) Jacobian */
        } else if (strcmp(argv[i], "--no-peers") == 0) {
            peers_wanted = 0;
        } else if (strcmp(argv[i], "--table") == 0) {
            table = 1;
        } else if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            return 0;
        } else if (argv[i][0] != '-' && !have_dir) {
            data_dir = argv[i];
            have_dir = 1;
        } else {
            fprintf(stderr, "bench_nist_peers: unexpected argument '%s'\n", argv[i]);
            usage(stderr);
            return 2;
        }
    }

    struct stat sb;
    if (stat(data_dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
        printf("SKIP: NIST data directory %s not found (%s); the StRD .dat files live in "
               "../shared/data/nist, or pass DATA_DIR\n",
               data_dir, stat(data_dir, &sb) != 0 ? strerror(errno) : "not a directory");
        return 77;
    }
    char **paths = NULL;
    size_t n_files = nist_list(data_dir, &paths);
    if (n_files == 0) {
        printf("SKIP: no NIST .dat files in %s\n", data_dir);
        return 77;
    }

    char work[] = "/tmp/phc-nist-bench-XXXXXX";
    if (!mkdtemp(work)) {
        perror("mkdtemp");
        return 1;
    }

    static nist_outcome best[MAX_FITS];
    size_t n_fits = 0, solved = 0, errors = 0;
    double sum_lre = 0, total_time = 0, solve_time = 0, cpu_time = 0;
    char load_start[64];
    load_average(load_start, sizeof load_start);
    int failed = 0;
    for (size_t i = 0; i < n_files; ++i) {
        static nist_problem p;
        char msg[256];
        if (nist_load(paths[i], &p, msg, sizeof msg) != 0) {
            fprintf(stderr, "bench_nist_peers: %s\n", msg);
            failed = 1;
            free(paths[i]);
            continue;
        }
        free(paths[i]);
        for (int start = 1; start <= 2 && n_fits < MAX_FITS; ++start) {
            nist_outcome *b = &best[n_fits++];
            for (int r = 0; r < repeat; ++r) {
                nist_outcome o;
                nist_run_case(&p, start, work, derivatives, &o);
                /* nist_run_case leaves 99 when no fitted parameter matched a
                 * b<j>: score that as nothing matched */
                if (o.ok && o.lre_param > 11)
                    o.lre_param = 0;
                if (r == 0) {
                    *b = o;
                    continue;
                }
                if (!o.ok && b->ok) { /* keep the failure, it is what counts */
                    *b = o;
                    continue;
                }
                if (o.ok && o.seconds < b->seconds)
                    b->seconds = o.seconds;
                if (o.ok && o.cpu_seconds < b->cpu_seconds)
                    b->cpu_seconds = o.cpu_seconds;
                if (o.ok && o.solve_seconds < b->solve_seconds)
                    b->solve_seconds = o.solve_seconds;
                if (o.lre_param < b->lre_param)
                    b->lre_param = o.lre_param;
            }
            sum_lre += b->lre_param;
            solved += b->ok && b->lre_param >= 4;
            if (b->ok) {
                total_time += b->seconds;
                solve_time += b->solve_seconds;
                cpu_time += b->cpu_seconds;
            }
            else
                ++errors;
        }
    }
    free(paths);
    remove_work_dir(work);
    if (n_fits == 0) {
        fprintf(stderr, "bench_nist_peers: no problem in %s could be loaded\n", data_dir);
        return 1;
    }

    if (table) {
        printf("%-10s %5s %-13s %8s %10s  %s\n", "problem", "start", "status", "minLRE", "ms", "note");
        for (size_t i = 0; i < n_fits; ++i)
            printf("%-10s %5d %-13s %8.2f %10.3f  %s\n", best[i].name, best[i].start,
                   best[i].ok ? best[i].status : "error", best[i].lre_param,
                   best[i].seconds * 1e3, best[i].message);
    }

    printf("timed_phytocal: phc_fit_run in-process (Ceres solve + covariance, sensitivities, "
           "collinearity, goodness and residual checks; config load excluded), min of %d runs per fit\n",
           repeat);
    printf("phytocal_derivatives: %s\n", derivatives ? derivatives : "exact (reverse-mode AD of the expression)");
    printf("phytocal_solved: %zu of %zu (min parameter LRE >= 4)\n", solved, n_fits);
    printf("phytocal_average_lre: %.2f digits\n", sum_lre / (double)n_fits);
    printf("phytocal_total_time: %.4f s\n", total_time);
    printf("phytocal_solve_time: %.4f s (the Ceres solves alone, the part comparable to the peers' call)\n",
           solve_time);
    printf("phytocal_cpu_time: %.4f s (thread CPU time of phc_fit_run, min of %d runs per fit)\n", cpu_time, repeat);
    char load_end[64];
    load_average(load_end, sizeof load_end);
    printf("load_average: %s at the start, %s after phytocal's fits (1, 5, 15 min; %ld CPUs)\n", load_start,
           load_end, sysconf(_SC_NPROCESSORS_ONLN));
    if (errors)
        printf("phytocal_errors: %zu fits (scored LRE 0, not timed)\n", errors);

    if (!peers_wanted) {
        printf("peers: skipped (--no-peers)\n");
        return failed;
    }
    if (access(PYTHON, X_OK) != 0 || access(PEERS_SCRIPT, R_OK) != 0) {
        printf("scipy: not available (%s or %s missing)\n", PYTHON, PEERS_SCRIPT);
        printf("speed_target: not measured (no SciPy)\n");
        return failed;
    }
    /* lmfit needs SciPy, so without SciPy there are no peers at all */
    if (!python_has("numpy, scipy.optimize")) {
        printf("scipy: not available (install python3-scipy)\n");
        printf("speed_target: not measured (no SciPy)\n");
        return failed;
    }
    peer_total peers[2] = {{"scipy", 1, 0, 0, 0}, {"lmfit", 1, 0, 0, 0}};
    if (!python_has("lmfit")) {
        printf("lmfit: not available (install python3-lmfit)\n");
        peers[1].available = 0;
    }
    printf("timed_peers: the least_squares / lmfit.minimize call only, min of %d runs per fit\n", repeat);
    if (run_peers(data_dir, repeat, table, peers, 2) != 0)
        return 1;

    for (int i = 0; i < 2; ++i) {
        if (!peers[i].available)
            continue;
        if (!peers[i].have_time || !(total_time > 0)) {
            printf("speed_ratio_vs_%s: not available (no total time parsed)\n", peers[i].name);
            continue;
        }
        const char *caveat = peers[i].errors || errors ? "; fits that raised are left out of a total" : "";
        printf("speed_ratio_vs_%s: %.1f x (%s total time / phytocal total time, fit plus full analysis%s)\n",
               peers[i].name, peers[i].time / total_time, peers[i].name, caveat);
        if (solve_time > 0)
            printf("solve_speed_ratio_vs_%s: %.1f x (%s total time / phytocal solve time%s)\n", peers[i].name,
                   peers[i].time / solve_time, peers[i].name, caveat);
    }
    if (peers[0].have_time && total_time > 0) {
        const double ratio = peers[0].time / total_time;
        printf("speed_target: %s (scipy total time / phytocal total time %.1f x, target >= %.0f x; "
               "%zu of %zu fits solved)\n",
               ratio >= SPEED_TARGET && solved == n_fits ? "met" : "not met", ratio, SPEED_TARGET, solved, n_fits);
    } else {
        printf("speed_target: not measured (no SciPy total time)\n");
    }
    return failed;
}
