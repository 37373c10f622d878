/* Speed of seek_light's light field (model/climbing_light_field.h;
 * phototropism toward where the light is, Hädrich et al., CGF 36(2) 2017,
 * §4.2, eq. 7) at the climbing bench's scale.
 *
 * The bushy plant of the climbing bench (tests/climbing_bushy_plant.h:
 * seed 3, BP 0.9, B 2, orders <= 6, 0.25 s steps, an 80 x 80 x 40 light
 * grid of 5 cm with extinction 40 m⁻¹, light from above) is grown
 * kinematically to at least 29,000 particles; then on one OpenMP thread
 * the field is built from its particles (centres and volumes), a sky of
 * seven directions (ℓ and six at the spread 30° from it):
 *   peer (our previous field): phc_climbing_light_field_update, every
 *     cell of the grid (256,000 probes, seven light computations each);
 *   ours: phc_climbing_light_field_update_near with the apical particles'
 *     tips as sites, the nodes phototropism reads at them (what a growth
 *     step now does).
 * Each is timed as the median of REPEATS calls; the ratio peer / ours is
 * printed, and the nodes ours computes are compared with the peer's bit
 * for bit (it exits 1 when one differs).  The other processes' load on the
 * machine is printed with each timing (the machine is shared).
 *
 * Prints `name: value unit (details)`. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench_machine.h"
#include "climbing_bushy_plant.h"
#include "model/climbing_growth.h"
#include "model/climbing_light_field.h"

#define TARGET 29000
#define DT 0.25

typedef int (*field_fn)(phc_climbing_light_field *f, const double *x, const double *vol, size_t n,
                        const double *sites, size_t ns);

static int full_update(phc_climbing_light_field *f, const double *x, const double *vol, size_t n,
                       const double *sites, size_t ns)
{
    (void)sites;
    (void)ns;
    return phc_climbing_light_field_update(f, NULL, x, vol, n);
}

static int near_update(phc_climbing_light_field *f, const double *x, const double *vol, size_t n,
                       const double *sites, size_t ns)
{
    return phc_climbing_light_field_update_near(f, NULL, x, vol, n, sites, ns);
}

/* Median ms of `repeats` calls of fn, and the other processes' load. */
static double time_field(field_fn fn, phc_climbing_light_field *f, const double *x, const double *vol,
                         size_t n, const double *sites, size_t ns, int repeats, double *load)
{
    double *t = malloc((size_t)repeats * sizeof *t);
    if (!t)
        return -1;
    const cpu_mark a = cpu_now();
    for (int k = 0; k < repeats; ++k) {
        const double t0 = now();
        if (fn(f, x, vol, n, sites, ns)) {
            free(t);
            return -1;
        }
        t[k] = now() - t0;
    }
    *load = other_load(a, cpu_now());
    qsort(t, (size_t)repeats, sizeof *t, cmp_double);
    const double ms = 1e3 * t[repeats / 2];
    free(t);
    return ms;
}

int main(void)
{
    omp_set_num_threads(1);
    phc_climbing_options o = climbing_bushy_options(3);
    o.max_particles = 1000000;
    climbing_floor_scene(&o);
    const double base[3] = {0, 0, 0.01}, up[3] = {0, 0, 1};
    phc_error err;
    phc_climbing *c = phc_climbing_new(base, up, &o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return 2;
    }
    while (phc_climbing_count(c) < TARGET)
        if (phc_climbing_step(c, DT, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return 2;
        }
    const size_t n = phc_climbing_count(c);
    double *x = malloc(3 * n * sizeof *x), *vol = malloc(n * sizeof *vol), *sites = malloc(3 * n * sizeof *sites);
    if (!x || !vol || !sites) {
        fprintf(stderr, "out of memory\n");
        return 2;
    }
    size_t ns = 0;
    for (size_t i = 0; i < n; ++i) {
        double b[3], t[3];
        const double r = phc_climbing_radius(c, i);
        phc_climbing_position(c, i, x + 3 * i);
        phc_climbing_segment(c, i, b, t);
        vol[i] = 3.14159265358979323846 * r * r * phc_climbing_length(c, i);
        if (phc_climbing_is_apical(c, i))
            memcpy(sites + 3 * ns++, t, sizeof t);
    }
    phc_climbing_free(c);
    phc_climbing_light_field full, near;
    if (phc_climbing_light_field_init(&full, &o.light, 30) || phc_climbing_light_field_init(&near, &o.light, 30)) {
        fprintf(stderr, "out of memory\n");
        return 2;
    }
    const size_t cells = phc_climbing_light_cells(&o.light);
    const int repeats = bench_repeats(5);
    double load_full, load_near;
    const double ms_full = time_field(full_update, &full, x, vol, n, sites, ns, repeats, &load_full);
    const double ms_near = time_field(near_update, &near, x, vol, n, sites, ns, repeats, &load_near);
    if (ms_full < 0 || ms_near < 0) {
        fprintf(stderr, "out of memory\n");
        return 2;
    }
    size_t computed = 0, differ = 0;
    for (size_t k = 0; k < cells; ++k)
        if (!isnan(near.value[k])) {
            ++computed;
            differ += memcmp(&near.value[k], &full.value[k], sizeof(double)) != 0;
        }
    printf("plant: seed 3, BP 0.9, B 2, orders <= 6, %zu particles, %zu tips; light grid 80x80x40 of 0.05 m, "
           "extinction 40 1/m, light from above, spread 30 deg (7 directions); 1 thread, the median of repeated calls\n",
           n, ns);
    printf("field_ms_every_cell: %.2f ms (peer: our previous field, %zu probes; other load %.2f CPUs)\n", ms_full,
           cells, load_full);
    printf("field_ms_near_tips: %.2f ms (ours: the nodes read at the tips, %zu probes; other load %.2f CPUs)\n",
           ms_near, computed, load_near);
    printf("ratio_every_cell_over_near_tips: %.1f x\n", ms_full / ms_near);
    printf("nodes_that_differ: %zu of %zu (bit for bit against the whole field)\n", differ, computed);
    phc_climbing_light_field_free(&full);
    phc_climbing_light_field_free(&near);
    free(x);
    free(vol);
    free(sites);
    return differ ? 1 : 0;
}
