/* Shoots that break while a climbing plant grows: see climbing_breaking.h. */
#include "model/climbing_breaking.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/plant_graph.h"

#define NONE ((size_t)-1)

size_t phc_climbing_subtree_tag(const size_t *parent, size_t n, size_t k, unsigned char *tag,
                                unsigned char value)
{
    if (k >= n)
        return 0;
    size_t count = 1;
    tag[k] = value;
    /* a descendant comes after its parent: one pass from k */
    for (size_t i = k + 1; i < n; ++i) {
        const size_t p = parent[i];
        if (p != NONE && p >= k && tag[p] == value) {
            tag[i] = value;
            ++count;
        }
    }
    return count;
}

size_t phc_climbing_compact(void *a, size_t size, const unsigned char *drop, size_t n)
{
    unsigned char *b = a;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        if (drop[i])
            continue;
        if (m != i)
            memmove(b + m * size, b + i * size, size);
        ++m;
    }
    return m;
}

size_t phc_climbing_keep_map(const unsigned char *drop, size_t n, size_t *map)
{
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        map[i] = drop[i] ? NONE : m++;
    return m;
}

phc_particles *phc_climbing_system_rebuild(const phc_particles *old,
                                           const phc_particles_options *options, size_t m,
                                           const size_t *from, const size_t *parent,
                                           const double *head, const double *tail,
                                           const double *radius, phc_error *err)
{
    if (m == 0 || from[0] != 0) {
        phc_error_set(err, PHC_ERR_INVALID, "climbing: a rebuilt system needs the seed first");
        return NULL;
    }
    /* the seed alone, clamped, then every other particle appended (a
       particle without parent becomes a free root: a finished plant graph
       has one root only) */
    phc_plant_graph *g = phc_plant_graph_new(1);
    phc_particles *p = NULL;
    if (!g) {
        phc_error_set(err, PHC_ERR_NOMEM, "climbing: out of memory");
        return NULL;
    }
    memcpy(g->head, head, 3 * sizeof *head);
    memcpy(g->tail, tail, 3 * sizeof *tail);
    g->radius[0] = radius[0];
    double l2 = 0;
    for (int k = 0; k < 3; ++k)
        l2 += (tail[k] - head[k]) * (tail[k] - head[k]);
    g->length[0] = sqrt(l2);
    g->parent[0] = PHC_PLANT_NO_PARENT;
    g->fixed[0] = 1;
    if (phc_plant_graph_finish(g, "climbing", err) == 0)
        p = phc_particles_new(g, options, err);
    phc_plant_graph_free(g);
    if (!p)
        return NULL;
    for (size_t j = 1; j < m; ++j)
        if (phc_particles_append(p, parent[j], head + 3 * j, tail + 3 * j, radius[j], NULL, err))
            goto fail;
    for (size_t j = 0; j < m; ++j) {
        double x[3], q[4], v[3], w[3];
        phc_particles_position(old, from[j], x);
        phc_particles_orientation(old, from[j], q);
        phc_particles_velocity(old, from[j], v);
        phc_particles_angular_velocity(old, from[j], w);
        if (phc_particles_set_position(p, j, x, err) || phc_particles_set_orientation(p, j, q, err) ||
            phc_particles_set_velocities(p, j, v, w, err))
            goto fail;
    }
    return p;
fail:
    phc_particles_free(p);
    return NULL;
}

int phc_climbing_stumps_add(phc_climbing_stumps *s, size_t id, double t)
{
    if (s->n == s->cap) {
        const size_t cap = s->cap ? 2 * s->cap : 8;
        size_t *ids = realloc(s->id, cap * sizeof *ids);
        if (!ids)
            return -1;
        s->id = ids;
        double *at = realloc(s->broke_at, cap * sizeof *at);
        if (!at)
            return -1;
        s->broke_at = at;
        s->cap = cap;
    }
    s->id[s->n] = id;
    s->broke_at[s->n] = t;
    s->n++;
    return 0;
}

size_t phc_climbing_stumps_take_due(phc_climbing_stumps *s, double now, double delay, size_t *due)
{
    size_t m = 0, kept = 0;
    for (size_t i = 0; i < s->n; ++i) {
        if (now - s->broke_at[i] >= delay * (1 - 1e-12)) {
            due[m++] = s->id[i];
        } else {
            s->id[kept] = s->id[i];
            s->broke_at[kept] = s->broke_at[i];
            ++kept;
        }
    }
    s->n = kept;
    return m;
}

void phc_climbing_stumps_free(phc_climbing_stumps *s)
{
    free(s->id);
    free(s->broke_at);
    memset(s, 0, sizeof *s);
}

size_t phc_climbing_find_id(const size_t *ids, size_t n, size_t id)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (ids[mid] < id)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && ids[lo] == id ? lo : NONE;
}

int phc_climbing_has_attached_successor(const size_t *parent, const unsigned char *lateral,
                                        const unsigned char *falling, size_t n, size_t p)
{
    for (size_t i = p + 1; i < n; ++i)
        if (parent[i] == p && !lateral[i] && !falling[i])
            return 1;
    return 0;
}
