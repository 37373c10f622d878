/* Benchmark of the leaf sap-flow step (model/leaf.h, phc_leaf_step with
 * h = dt, the cached factorisation): prints `name: value unit` lines, then
 * a summary block.
 *
 * Leaf (N x N, N = 128, 256, 512, 1024), u, v the pixel centre in [-1, 1]:
 *   mask   ellipse u^2/0.98^2 + v^2/0.975^2 < 1 (75% of the square)
 *   β      1 on the veins, 0.05 on the lamina; veins: a midrib |u| < w_m
 *          (w_m = max(2, N/128) px wide) and 8 laterals, 4 per side, the
 *          lines v = v_k - 0.6 |u| (v_k = -0.6, -0.2, 0.2, 0.6) of
 *          max(1.5, N/256) px half-width (measured perpendicular)
 *   O      1 on the leaf;  I = β
 *   params phc_leaf_params_default() (s_β 50, s_O 0.1, s_I 0.05, dt 0.1);
 *   y = 1 on the leaf at the start of every timing (phc_leaf_reset).
 *
 * Timings (omp_set_num_threads 1 and 2): STEPS_TARGET seconds' worth of
 * steps per timing, REPEAT timings, each from the initial state; the BEST
 * (shortest) time per step is reported and the median printed beside it.
 * Every timing line gives the CPUs other processes kept busy meanwhile
 * (/proc/stat minus this process's getrusage): the machine is shared.
 *
 * Peers in the same run:
 *   (a) Silva et al., Table 1: 118-174 ms per step at 1024^2 on a GeForce
 *       9400M; the speed-up is against the fastest, 118 ms.
 *   (b) tests/bench/leaf_peer.py, run with Debian's /usr/bin/python3: the
 *       same step in NumPy/SciPy (transpiration floor, inflow, then the
 *       column and row implicit solves with scipy.linalg.solve_banded, one
 *       call per line run), on the same maps, which this program writes to
 *       a raw binary file (mask uint8, then β, O, I float64, each N^2 in
 *       the element order x + N y).  Both sides print the checksum
 *       sum(y wt), wt = 1 + (i mod 97) + row, after the peer's step count;
 *       they must agree to 1e-9 relative.  The peer also times a batched
 *       variant (one solve_banded over all the runs of a half-step,
 *       concatenated: the same systems), printed for information.
 *
 * Targets: <= 10 ms per step at 1024^2 on one thread; >= 10 x the SciPy
 * peer (one call per run) at every size on one thread. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bench_machine.h"
#include "model/leaf.h"

#ifndef PHC_SOURCE_DIR
#define PHC_SOURCE_DIR "."
#endif

#define PEER_PY "/usr/bin/python3"
#define PEER_SCRIPT PHC_SOURCE_DIR "/tests/bench/leaf_peer.py"

#define NSIZES 4
#define REPEAT 5
#define STEPS_TARGET 0.25 /* seconds per timing */
#define PAPER_MS 118.0    /* Silva et al., Table 1, fastest at 1024^2 */
#define TARGET_MS_1024 10.0
#define TARGET_PEER 10.0
#define PEER_TOL 1e-9

static void print_loadavg(const char *when)
{
    char buf[128] = "";
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (!fgets(buf, sizeof buf, f))
            buf[0] = '\0';
        fclose(f);
    }
    buf[strcspn(buf, "\n")] = '\0';
    printf("machine_loadavg_%s: %s (1, 5, 15 min; %d CPUs)\n", when, buf, omp_get_num_procs());
}

/* The synthetic leaf of the header comment. */
static void make_maps(size_t N, unsigned char *m, double *beta, double *O, double *I)
{
    double px = 2.0 / (double)N; /* one pixel in u, v units */
    double mid = fmax(2.0, (double)N / 128.0) * 0.5 * px;
    double lat = fmax(1.5, (double)N / 256.0) * px;
    static const double vk[4] = {-0.6, -0.2, 0.2, 0.6};
    for (size_t y = 0; y < N; ++y)
        for (size_t x = 0; x < N; ++x) {
            size_t i = x + N * y;
            double u = ((double)x + 0.5) * px - 1, v = ((double)y + 0.5) * px - 1;
            int in = u * u / (0.98 * 0.98) + v * v / (0.975 * 0.975) < 1;
            int vein = fabs(u) < mid;
            for (int k = 0; k < 4 && !vein; ++k)
                vein = fabs(v - (vk[k] - 0.6 * fabs(u))) / sqrt(1 + 0.36) < lat;
            m[i] = (unsigned char)in;
            beta[i] = in ? (vein ? 1.0 : 0.05) : 0.0;
            O[i] = in ? 1.0 : 0.0;
            I[i] = beta[i];
        }
}

/* sum(y wt), wt = 1 + (i mod 97) + row, in long double. */
static double checksum(const phc_leaf *L)
{
    size_t W = phc_leaf_width(L), n = W * phc_leaf_height(L);
    const double *y = phc_leaf_fluid(L);
    long double s = 0;
    for (size_t i = 0; i < n; ++i)
        s += (long double)(y[i] * (double)(1 + i % 97 + i / W));
    return (double)s;
}

typedef struct result {
    double best, median, other;
    size_t steps;
} result;

/* ms per step: best and median of REPEAT timings. */
static result measure(phc_leaf *L, int threads)
{
    result r = {NAN, NAN, NAN, 0};
    omp_set_num_threads(threads);
    double dt = phc_leaf_get_params(L).dt;
    phc_leaf_reset(L, 1.0);
    if (phc_leaf_step(L, dt)) /* factorise; warm up */
        return r;
    phc_leaf_reset(L, 1.0);
    double t0 = now();
    size_t trial = 0;
    while (now() - t0 < 0.05 && trial < 1000) {
        phc_leaf_step(L, dt);
        ++trial;
    }
    double per = (now() - t0) / (double)trial;
    size_t steps = (size_t)ceil(STEPS_TARGET / per);
    if (steps < 5)
        steps = 5;
    double t[REPEAT];
    cpu_mark m0 = cpu_now();
    for (int k = 0; k < REPEAT; ++k) {
        phc_leaf_reset(L, 1.0);
        double a = now();
        for (size_t s = 0; s < steps; ++s)
            phc_leaf_step(L, dt);
        t[k] = (now() - a) / (double)steps * 1e3;
    }
    r.other = other_load(m0, cpu_now());
    qsort(t, REPEAT, sizeof t[0], cmp_double);
    r.best = t[0];
    r.median = t[REPEAT / 2];
    r.steps = steps;
    phc_leaf_reset(L, 1.0);
    return r;
}

typedef struct peer_out {
    int ok;
    double ms, ms_median, cs, bms, bcs;
} peer_out;

static peer_out run_peer(size_t N, size_t steps, const char *maps)
{
    peer_out o = {0, NAN, NAN, NAN, NAN, NAN};
    struct stat st;
    if (stat(PEER_PY, &st) != 0 || access(PEER_PY, X_OK) != 0) {
        printf("scipy_peer_%zu: skipped (%s is missing)\n", N, PEER_PY);
        return o;
    }
    char cmd[2048];
    snprintf(cmd, sizeof cmd, PEER_PY " '" PEER_SCRIPT "' %zu %zu '%s' --repeat 3", N, steps, maps);
    FILE *p = popen(cmd, "r");
    if (!p) {
        printf("scipy_peer_%zu: cannot run %s\n", N, PEER_PY);
        return o;
    }
    char line[1024], key[128];
    while (fgets(line, sizeof line, p)) {
        fputs(line, stdout);
        char *colon = strchr(line, ':');
        if (!colon)
            continue;
        char *end;
        double val = strtod(colon + 1, &end);
        snprintf(key, sizeof key, "scipy_ms_per_step_%zu:", N);
        if (!strncmp(line, key, strlen(key))) {
            o.ms = val;
            char *med = strstr(end, "median ");
            if (med)
                o.ms_median = strtod(med + 7, NULL);
        }
        snprintf(key, sizeof key, "scipy_checksum_%zu:", N);
        if (!strncmp(line, key, strlen(key)))
            o.cs = val;
        snprintf(key, sizeof key, "scipy_batched_ms_per_step_%zu:", N);
        if (!strncmp(line, key, strlen(key)))
            o.bms = val;
        snprintf(key, sizeof key, "scipy_batched_checksum_%zu:", N);
        if (!strncmp(line, key, strlen(key)))
            o.bcs = val;
    }
    int rc = pclose(p);
    if (rc != 0)
        printf("scipy_peer_%zu: exited with status %d (are numpy and scipy installed for %s?)\n", N, rc,
               PEER_PY);
    o.ok = rc == 0 && isfinite(o.ms) && isfinite(o.cs);
    return o;
}

static double rel(double a, double b) { return fabs(a - b) / fabs(b); }

int main(void)
{
    static const size_t sizes[NSIZES] = {128, 256, 512, 1024};
    static const size_t peer_steps[NSIZES] = {20, 10, 5, 3};
    static const int threads[2] = {1, 2};
    double t_start = now();
    double ms[NSIZES][2], peer_ms[NSIZES], peer_bms[NSIZES];
    int agree_all = 1, peer_all = 1;
    double min_speedup = INFINITY;

    print_loadavg("start");
    printf("leaf_threads_available: %d\n", omp_get_num_procs());
    phc_leaf_params prm = phc_leaf_params_default();
    printf("leaf_params: s_beta %g, s_O %g, s_I %g, dt %g\n", prm.beta_scale, prm.stomata_scale,
           prm.inflow_scale, prm.dt);

    for (int g = 0; g < NSIZES; ++g) {
        size_t N = sizes[g], n = N * N;
        unsigned char *m = malloc(n);
        double *beta = malloc(n * sizeof *beta), *O = malloc(n * sizeof *O), *I = malloc(n * sizeof *I);
        if (!m || !beta || !O || !I) {
            printf("leaf_%zu: out of memory\n", N);
            return 1;
        }
        make_maps(N, m, beta, O, I);
        phc_leaf *L = NULL;
        phc_error err;
        if (phc_leaf_new(N, N, m, beta, O, I, prm, &L, &err)) {
            printf("leaf_%zu: %s\n", N, err.message);
            return 1;
        }
        size_t veins = 0;
        for (size_t i = 0; i < n; ++i)
            veins += m[i] && beta[i] == 1.0;
        printf("leaf_cells_%zu: %zu px (%.1f%% of the square; %.1f%% of the leaf on veins)\n", N,
               phc_leaf_cells(L), 100.0 * (double)phc_leaf_cells(L) / (double)n,
               100.0 * (double)veins / (double)phc_leaf_cells(L));

        for (int th = 0; th < 2; ++th) {
            result r = measure(L, threads[th]);
            ms[g][th] = r.best;
            printf("leaf_ms_per_step_%zu_%dt: %.3f ms (best of %d timings of %zu steps; median %.3f)\n", N,
                   threads[th], r.best, REPEAT, r.steps, r.median);
            printf("leaf_mpix_per_s_%zu_%dt: %.1f Mpx/s (leaf pixels)\n", N, threads[th],
                   (double)phc_leaf_cells(L) / (r.best * 1e-3) * 1e-6);
            printf("machine_other_load_%zu_%dt: %.2f CPUs (busy with other processes during the "
                   "timings, of %d)\n", N, threads[th], r.other, omp_get_num_procs());
        }
        printf("leaf_thread_speedup_%zu: %.2f x (2t vs 1t)\n", N, ms[g][0] / ms[g][1]);

        /* the C checksum after the peer's step count */
        omp_set_num_threads(1);
        phc_leaf_reset(L, 1.0);
        for (size_t s = 0; s < peer_steps[g]; ++s)
            phc_leaf_step(L, prm.dt);
        double cs = checksum(L);
        printf("leaf_checksum_%zu: %.17g 1 (after %zu steps)\n", N, cs, peer_steps[g]);

        /* the maps for the peer */
        char path[] = "/tmp/phc_leaf_bench_XXXXXX";
        int fd = mkstemp(path);
        FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
        int wrote = f && fwrite(m, 1, n, f) == n && fwrite(beta, sizeof(double), n, f) == n &&
                    fwrite(O, sizeof(double), n, f) == n && fwrite(I, sizeof(double), n, f) == n;
        if (f)
            wrote &= fclose(f) == 0;
        peer_out po = {0, NAN, NAN, NAN, NAN, NAN};
        if (wrote)
            po = run_peer(N, peer_steps[g], path);
        else
            printf("scipy_peer_%zu: cannot write the maps to %s\n", N, path);
        if (fd >= 0)
            unlink(path);
        peer_ms[g] = po.ms;
        peer_bms[g] = po.bms;
        if (po.ok) {
            double r1 = rel(po.cs, cs);
            int ag = r1 <= PEER_TOL;
            printf("leaf_peer_checksum_rel_diff_%zu: %.2e 1\n", N, r1);
            if (isfinite(po.bcs)) {
                double r2 = rel(po.bcs, cs);
                printf("leaf_peer_batched_checksum_rel_diff_%zu: %.2e 1\n", N, r2);
                ag &= r2 <= PEER_TOL;
            }
            printf("leaf_peer_agrees_%zu: %s (tolerance %.0e relative)\n", N, ag ? "yes" : "no", PEER_TOL);
            agree_all &= ag;
            double sp = po.ms / ms[g][0];
            if (sp < min_speedup)
                min_speedup = sp;
            printf("leaf_speedup_vs_scipy_%zu_1t: %.1f x (median vs median %.1f x)\n", N, sp,
                   po.ms_median / ms[g][0]);
            printf("leaf_speedup_vs_scipy_%zu_2t: %.1f x\n", N, po.ms / ms[g][1]);
            if (isfinite(po.bms))
                printf("leaf_speedup_vs_scipy_batched_%zu_1t: %.1f x (one solve_banded per half-step)\n", N,
                       po.bms / ms[g][0]);
        } else {
            printf("leaf_peer_agrees_%zu: not run\n", N);
            peer_all = 0;
            agree_all = 0;
        }
        phc_leaf_free(L);
        free(m);
        free(beta);
        free(O);
        free(I);
    }

    printf("leaf_speedup_vs_paper_1024_1t: %.1f x (Silva et al. Table 1: 118-174 ms on a GeForce 9400M; "
           "vs 118 ms)\n", PAPER_MS / ms[NSIZES - 1][0]);
    printf("leaf_speedup_vs_paper_1024_2t: %.1f x\n", PAPER_MS / ms[NSIZES - 1][1]);
    printf("leaf_peer_agrees: %s\n", agree_all ? "yes" : "no");
    printf("---- summary ----\n");
    for (int g = 0; g < NSIZES; ++g)
        printf("leaf_ms_per_step_%zu: %.3f ms (1t), %.3f ms (2t); scipy %.1f ms per run-by-run step, "
               "%.1f ms batched\n", sizes[g], ms[g][0], ms[g][1], peer_ms[g], peer_bms[g]);
    printf("leaf_target_1024_1t_10ms: %s (%.3f ms)\n", ms[NSIZES - 1][0] <= TARGET_MS_1024 ? "met" : "missed",
           ms[NSIZES - 1][0]);
    printf("leaf_target_10x_scipy: %s (smallest 1-thread speed-up over the sizes: %.1f x%s)\n",
           peer_all && agree_all && min_speedup >= TARGET_PEER ? "met" : "missed", min_speedup,
           peer_all ? "" : "; peer not run at every size");
    print_loadavg("end");
    printf("bench_total_time: %.1f s\n", now() - t_start);
    return 0;
}
