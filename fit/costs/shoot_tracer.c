/* A tracer of a time-lapse watching a grown plant: see shoot_tracer.h. */
#include "fit/costs/shoot_tracer.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void phc_shoot_tracer_init(phc_shoot_tracer *tr) { memset(tr, 0, sizeof *tr); }

void phc_shoot_tracer_clear(phc_shoot_tracer *tr)
{
    free(tr->t);
    free(tr->x);
    free(tr->shoot);
    free(tr->shoot_of);
    free(tr->written);
    free(tr->seen);
    free(tr->parent_shoot);
    phc_shoot_tracer_init(tr);
}

static int push(phc_shoot_tracer *tr, double t, const double x[3], size_t shoot)
{
    if (tr->n == tr->cap) {
        const size_t cap = tr->cap ? 2 * tr->cap : 256;
        double *a = realloc(tr->t, cap * sizeof *a);
        if (a) tr->t = a;
        double *b = realloc(tr->x, 3 * cap * sizeof *b);
        if (b) tr->x = b;
        size_t *c = realloc(tr->shoot, cap * sizeof *c);
        if (c) tr->shoot = c;
        if (!a || !b || !c) return -1;
        tr->cap = cap;
    }
    tr->t[tr->n] = t;
    memcpy(tr->x + 3 * tr->n, x, 3 * sizeof *x);
    tr->shoot[tr->n++] = shoot;
    return 0;
}

static int grow_particle_arrays(phc_shoot_tracer *tr, size_t n)
{
    if (n <= tr->particles_cap) return 0;
    size_t *a = realloc(tr->shoot_of, n * sizeof *a);
    if (a) tr->shoot_of = a;
    size_t *b = realloc(tr->written, n * sizeof *b);
    if (b) tr->written = b;
    size_t *c = realloc(tr->seen, n * sizeof *c);
    if (c) tr->seen = c;
    size_t *d = realloc(tr->parent_shoot, n * sizeof *d);
    if (d) tr->parent_shoot = d;
    if (!a || !b || !c || !d) return -1;
    for (size_t i = tr->particles_cap; i < n; ++i) tr->written[i] = 0;
    tr->particles_cap = n;
    return 0;
}

int phc_shoot_tracer_look(phc_shoot_tracer *tr, const phc_climbing *c, double time, phc_error *err)
{
    const size_t n = phc_climbing_count(c);
    /* particles and shoots by their stable ids (phc_climbing_id: the indices close up when a broken
       piece leaves the plant; ids increase with the index); pieces that fall are not traced */
    if (grow_particle_arrays(tr, n ? phc_climbing_id(c, n - 1) + 1 : 0))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    /* particles of one shoot come in chain order (a successor or lateral is appended after its parent) */
    for (size_t i = 0; i < n; ++i) {
        if (phc_climbing_is_falling(c, i)) continue;
        const size_t p = phc_climbing_parent(c, i), id = phc_climbing_id(c, i);
        const size_t pid = p == PHC_CLIMBING_NONE ? PHC_CLIMBING_NONE : phc_climbing_id(c, p);
        const int starts = p == PHC_CLIMBING_NONE || phc_climbing_is_lateral(c, i);
        tr->shoot_of[id] = starts ? id : tr->shoot_of[pid];
        if (starts) tr->parent_shoot[id] = p == PHC_CLIMBING_NONE ? PHC_CLIMBING_NONE : tr->shoot_of[pid];
        tr->seen[id] = 0;
    }
    for (size_t i = 0; i < n; ++i) {
        if (phc_climbing_is_falling(c, i)) continue;
        const size_t s = tr->shoot_of[phc_climbing_id(c, i)], pos = tr->seen[s]++;
        double base[3], tip[3];
        phc_climbing_segment(c, i, base, tip);
        int bad = 0;
        if (pos == 0 && tr->written[s] == 0) { /* the shoot's base, the first time it is seen */
            bad |= push(tr, time, base, s);
            tr->written[s] = 1;
        }
        if (phc_climbing_is_apical(c, i)) {
            bad |= push(tr, time, tip, s); /* the apex, every frame */
        } else if (tr->written[s] == pos + 1) { /* a node not seen before */
            bad |= push(tr, time, tip, s);
            tr->written[s] = pos + 2;
        }
        if (bad) return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    return PHC_OK;
}

int phc_shoot_tracer_traces(const phc_shoot_tracer *tr, const char *name, phc_shoot_traces **out,
                            phc_error *err)
{
    *out = NULL;
    const size_t n = tr->n, m = tr->particles_cap;
    char(*names)[24] = malloc((m ? m : 1) * sizeof *names);
    const char **shoot = malloc((n ? n : 1) * sizeof *shoot), **parent = malloc((n ? n : 1) * sizeof *parent);
    double *x = malloc((n ? n : 1) * sizeof *x), *y = malloc((n ? n : 1) * sizeof *y),
           *z = malloc((n ? n : 1) * sizeof *z);
    int rc;
    if (!names || !shoot || !parent || !x || !y || !z) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    } else {
        for (size_t s = 0; s < m; ++s) snprintf(names[s], sizeof names[s], "s%zu", s);
        for (size_t i = 0; i < n; ++i) {
            const size_t s = tr->shoot[i], p = tr->parent_shoot[s];
            shoot[i] = names[s];
            parent[i] = p == PHC_CLIMBING_NONE ? "" : names[p];
            x[i] = tr->x[3 * i];
            y[i] = tr->x[3 * i + 1];
            z[i] = tr->x[3 * i + 2];
        }
        rc = phc_shoot_traces_from_rows(name, n, tr->t, shoot, x, y, z, parent, out, err);
    }
    free(names);
    free(shoot);
    free(parent);
    free(x);
    free(y);
    free(z);
    return rc;
}
