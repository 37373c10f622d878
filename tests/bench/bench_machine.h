/* Timing helpers shared by the benchmarks (tests/bench): a monotonic
 * clock, and how busy other processes kept the CPUs while a timing ran (the
 * machine is shared; /proc/stat minus this process's getrusage). */
#ifndef PHC_BENCH_MACHINE_H
#define PHC_BENCH_MACHINE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

static inline double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* CPU seconds used by the whole machine (/proc/stat, not idle) and by this
 * process, at a wall-clock time. */
typedef struct cpu_mark {
    double wall, machine, self;
} cpu_mark;

static inline cpu_mark cpu_now(void)
{
    cpu_mark m = {now(), NAN, NAN};
    FILE *f = fopen("/proc/stat", "r");
    if (f) {
        unsigned long long v[8] = {0};
        if (fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3], &v[4],
                   &v[5], &v[6], &v[7]) == 8) {
            unsigned long long busy = v[0] + v[1] + v[2] + v[5] + v[6] + v[7];
            m.machine = (double)busy / (double)sysconf(_SC_CLK_TCK);
        }
        fclose(f);
    }
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) == 0)
        m.self = ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec +
                 1e-6 * ru.ru_stime.tv_usec;
    return m;
}

/* CPUs kept busy by other processes (and steal) between a and b. */
static inline double other_load(cpu_mark a, cpu_mark b)
{
    double x = ((b.machine - a.machine) - (b.self - a.self)) / (b.wall - a.wall);
    return x < 0 ? 0 : x;
}

/* How many times to repeat a timing a benchmark takes the best or median
 * of: `full`, or 1 when PHC_BENCH_QUICK=1.  The README check
 * (tests/readme/check_readme.py) sets it: it compares a benchmark's keys and
 * its model values, which do not depend on the repeats, and masks every
 * measured value, so one repetition checks the same. */
static inline int bench_repeats(int full)
{
    const char *q = getenv("PHC_BENCH_QUICK");
    return q && strcmp(q, "1") == 0 ? 1 : full;
}

static inline int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#endif /* PHC_BENCH_MACHINE_H */
