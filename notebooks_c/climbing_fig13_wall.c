/* Climbing plants (Hädrich, Benes, Deussen, Pirk, CGF 36(2) 2017), Fig. 13:
 * a vine with leaves covering a house wall.
 *
 * The scene (measurements/examples/climbing/wall_window.obj): a wall 1.2 m
 * × 1.2 m, face y = 0 toward +y, with a window (x ∈ [−0.2, 0.2], z ∈
 * [0.5, 0.9] m) whose pane sits 4 cm back in a recess, and a ledge 8 cm
 * deep above it (z ∈ [0.92, 0.96] m).  One seed 2 cm in front of the wall's foot at x = −0.1 m
 * grows up for 240 s in steps of 0.25 s (kinematic), light from the front
 * and above, ℓ ∝ (0, 1, 1.5), through a 5 cm light grid (extinction 40/m,
 * ambient share 0.2); the wall and the ledge cast shadows (exact ray/
 * triangle test, model/climbing_light.h); surface adaption and anchors hold
 * the shoots on the wall, and tips that pass behind a face at an edge turn
 * back out (keep_outside); a leaf at every node (divergence 137.5°, blade
 * 3 cm, turned toward the light, model/climbing_leaves.h); secondary growth
 * by the pipe model (model/climbing_cambium.h).  The figure's own values
 * were not available to us; these are ours.
 *
 * Prints and checks the figure's claims:
 *   - the leaves face the light: mean cos(leaf normal, ℓ) > 0.8;
 *   - most particles are anchored to the wall: attached fraction > 0.8;
 *   - the plant covers the wall: the area of 1 cm cells of the wall plane
 *     (x–z) that a stem or a blade covers, seen along y, > 0.1 m²;
 *   - nothing grows through the wall: the smallest signed distance of a
 *     particle's centre to its closest support face (along that face's
 *     outward normal) is ≥ 0; printed beside it, the segments whose
 *     straight line clips a convex edge (a segment–triangle test against
 *     every triangle: a 2 cm internode rounding the window's sill cuts its
 *     corner although its centre is outside);
 *   - collisions (option collide, every particle pushed out of the
 *     supports to its radius): the smallest signed distance of a centre
 *     minus its radius, over all particles, is >= -1e-12 m;
 *   - whole segments (option collide_ends: the segments' two ends pushed
 *     out too): the smallest signed distance of a segment end minus its
 *     radius (seed excluded) is larger than with the centre push alone,
 *     and the centres stay out (>= -1e-12 m);
 *   - the ledge shades: leaves within 30 cm under it get less light on
 *     average than the others;
 *   - with dynamics: the same seed grown again with 25 substeps of 0.01 s
 *     per step (Fig. 12's substep), gravity and anchors, once with each
 *     joint pass (dynamics.bending own_weight, and beam with Fig. 12's
 *     E_1/2 = 1e7 Pa), without collide (see main); printed: the CPU time,
 *     particles, attached fraction, smallest signed distances, segments
 *     clipping, and the free tips' sag (free_tip_sag); checked: attached
 *     fraction > 0.8 and the free tips hang below their rest shape;
 *   - with dynamics and collisions: the plant of
 *     measurements/examples/climbing/wall_window_collide.yaml (the same
 *     seed and values, dynamics.collide, collide_segments and supports_closed on
 *     wall_window_closed.obj, the wall as a closed solid) grown as
 *     `phytocal grow` grows it, then with the beam pass; printed: the CPU
 *     time, particles, attached fraction, smallest signed distance minus
 *     radius of a centre and of a segment end, segments clipping, and the
 *     collision pass's closest-point queries (made, answered by the mesh's
 *     tree or by a certificate, skipped); checked: every centre at least
 *     its radius off the wall (>= -1e-12 m), no segment clipping and
 *     attached fraction > 0.8.
 *
 * Writes climbing_fig13_wall_front.png (the wall face, x–z),
 * climbing_fig13_wall_side.png (y–z: the plant's depth off the wall),
 * climbing_fig13_wall_collide_side.png (y–z, the two plants grown with
 * collisions on the closed wall),
 * climbing_fig13_wall.obj (stems as tubes, leaves as squares, the wall)
 * and climbing_fig13_wall.md.  Exit 1 when a check fails.
 *
 * Usage: notebook_climbing_fig13_wall OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <omp.h>

#include "fit/grow.h"
#include "fit/grow_config.h"
#include "fit/grow_mesh.h"
#include "fit/shape_plots.h"
#include "measurements/support_mesh.h"
#include "model/climbing_growth.h"

#include "notebook_plot.h"

#define CELL 0.01 /* m: coverage cells */

/* 1 when the segment from b to t crosses the triangle (p, q, r): the ray
 * from b toward t and the ray from t toward b both meet it. */
static int crosses(const double b[3], const double t[3], const double p[3], const double q[3], const double r[3])
{
    const double d[3] = {t[0] - b[0], t[1] - b[1], t[2] - b[2]}, e[3] = {-d[0], -d[1], -d[2]};
    return phc_climbing_ray_hits_triangle(b, d, 0, p, q, r) && phc_climbing_ray_hits_triangle(t, e, 0, p, q, r);
}

/* Whether particle i's segment (head to tail) crosses one of the wall's
 * ntri triangles. */
static int segment_clips(const phc_climbing *c, size_t i, const phc_support_mesh *wall, size_t ntri)
{
    double b[3], t[3];
    phc_climbing_segment(c, i, b, t);
    for (size_t k = 0; k < ntri; ++k) {
        size_t id[3];
        double p0[3], p1[3], p2[3];
        phc_support_mesh_triangle(wall, k, id);
        phc_support_mesh_vertex(wall, id[0], p0);
        phc_support_mesh_vertex(wall, id[1], p1);
        phc_support_mesh_vertex(wall, id[2], p2);
        if (crosses(b, t, p0, p1, p2))
            return 1;
    }
    return 0;
}

/* The plant of the figure: options o, the wall casting shadows, `steps`
 * steps of dt seconds; NULL (message printed) on failure. */
static phc_climbing *grow_wall(const phc_climbing_options *o, phc_support_mesh *wall, const double seed[3],
                               const double up[3], size_t steps, double dt)
{
    phc_error err;
    phc_climbing *c = phc_climbing_new(seed, up, o, &err);
    if (!c) {
        fprintf(stderr, "%s\n", err.message);
        return NULL;
    }
    const size_t nv = phc_support_mesh_vertex_count(wall), nt = phc_support_mesh_triangle_count(wall);
    double *v = malloc(3 * nv * sizeof *v);
    size_t *t = malloc(3 * nt * sizeof *t);
    int bad = !v || !t;
    for (size_t i = 0; !bad && i < nv; ++i)
        phc_support_mesh_vertex(wall, i, v + 3 * i);
    for (size_t i = 0; !bad && i < nt; ++i)
        phc_support_mesh_triangle(wall, i, t + 3 * i);
    if (!bad && phc_climbing_set_shadow_triangles(c, v, nv, t, nt, &err)) {
        fprintf(stderr, "%s\n", err.message);
        bad = 1;
    }
    free(v);
    free(t);
    for (size_t k = 0; !bad && k < steps; ++k)
        if (phc_climbing_step(c, dt, &err)) {
            fprintf(stderr, "%s\n", err.message);
            bad = 1;
        }
    if (bad) {
        phc_climbing_free(c);
        return NULL;
    }
    return c;
}

/* Over all particles: the smallest signed distance δ − r (δ = ±|x − c| to
 * the closest support point c, − behind its face; r the radius, m) and
 * the segments whose straight line crosses a triangle of the wall. */
static double smallest_depth(const phc_climbing *c, phc_support_mesh *wall, size_t *crossing)
{
    double m = INFINITY;
    *crossing = 0;
    const size_t ntri = phc_support_mesh_triangle_count(wall);
    for (size_t i = 0; i < phc_climbing_count(c); ++i) {
        double x[3], cp[3], nf[3];
        phc_climbing_position(c, i, x);
        if (phc_support_mesh_closest(wall, x, cp, nf) == 0) {
            const double e[3] = {x[0] - cp[0], x[1] - cp[1], x[2] - cp[2]};
            const double dist = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            const double delta = e[0] * nf[0] + e[1] * nf[1] + e[2] * nf[2] >= 0 ? dist : -dist;
            m = fmin(m, delta - phc_climbing_radius(c, i));
        }
        const int clips = segment_clips(c, i, wall, ntri);
        *crossing += (size_t)clips;
    }
    return m;
}

/* Over all particles but the seed's (collisions leave it alone): the
 * smallest signed distance δ − r of a segment's two ends (m). */
static double smallest_end_depth(const phc_climbing *c, phc_support_mesh *wall)
{
    double m = INFINITY;
    for (size_t i = 1; i < phc_climbing_count(c); ++i) {
        double ends[6];
        phc_climbing_segment(c, i, ends, ends + 3);
        for (int j = 0; j < 2; ++j) {
            const double *x = ends + 3 * j;
            double cp[3], nf[3];
            if (phc_support_mesh_closest(wall, x, cp, nf))
                continue;
            const double e[3] = {x[0] - cp[0], x[1] - cp[1], x[2] - cp[2]};
            const double dist = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            const double delta = e[0] * nf[0] + e[1] * nf[1] + e[2] * nf[2] >= 0 ? dist : -dist;
            m = fmin(m, delta - phc_climbing_radius(c, i));
        }
    }
    return m;
}

/* The free shoots' sag: for every tip (a particle without children) that
 * holds no anchor, the drop of its centre below where its rest shape puts
 * it relative to its closest anchored ancestor a, (z̄_tip − z̄_a) − (z_tip −
 * z_a) (m; the kinematic plant, current = rest, has 0).  Their count, mean
 * and largest drop and the mean number of links from a. */
static void free_tip_sag(const phc_climbing *c, size_t *count, double *mean, double *largest, double *links)
{
    const size_t n = phc_climbing_count(c);
    unsigned char *has_child = calloc(n ? n : 1, 1);
    *count = 0;
    *mean = *largest = *links = 0;
    if (!has_child)
        return;
    for (size_t i = 0; i < n; ++i)
        if (phc_climbing_parent(c, i) != PHC_CLIMBING_NONE)
            has_child[phc_climbing_parent(c, i)] = 1;
    for (size_t i = 0; i < n; ++i) {
        double an[3];
        if (has_child[i] || phc_climbing_anchor(c, i, an))
            continue;
        size_t a = i, hops = 0;
        while (phc_climbing_parent(c, a) != PHC_CLIMBING_NONE && !phc_climbing_anchor(c, a, an)) {
            a = phc_climbing_parent(c, a);
            ++hops;
        }
        double x[3], xa[3], r[3], ra[3];
        phc_climbing_position(c, i, x);
        phc_climbing_position(c, a, xa);
        phc_climbing_rest_position(c, i, r);
        phc_climbing_rest_position(c, a, ra);
        const double drop = (r[2] - ra[2]) - (x[2] - xa[2]);
        *mean += drop;
        *largest = fmax(*largest, drop);
        *links += (double)hops;
        ++*count;
    }
    if (*count) {
        *mean /= (double)*count;
        *links /= (double)*count;
    }
    free(has_child);
}

/* How a plant is drawn: its stems coloured by branch order, its leaves as
 * strokes across their blades (colour 3, half the thickest radius wide). */
typedef struct strokes {
    size_t n;                       /* stems + leaves */
    double *head, *tail, *rad, *val; /* 3n, 3n, n (m), n */
} strokes;

static void strokes_free(strokes *s)
{
    free(s->head);
    free(s->tail);
    free(s->rad);
    free(s->val);
}

/* The strokes of plant c; 0, or -1 when out of memory (s freed). */
static int plant_strokes(const phc_climbing *c, strokes *s)
{
    const size_t n = phc_climbing_count(c), ns = n + phc_climbing_leaf_count(c);
    s->n = ns;
    s->head = malloc(3 * ns * sizeof *s->head);
    s->tail = malloc(3 * ns * sizeof *s->tail);
    s->rad = malloc(ns * sizeof *s->rad);
    s->val = malloc(ns * sizeof *s->val);
    if (!s->head || !s->tail || !s->rad || !s->val) {
        strokes_free(s);
        return -1;
    }
    double rmax = 0;
    for (size_t i = 0; i < n; ++i)
        rmax = fmax(rmax, phc_climbing_radius(c, i));
    for (size_t i = 0, j = n; i < n; ++i) {
        phc_climbing_segment(c, i, s->head + 3 * i, s->tail + 3 * i);
        s->rad[i] = phc_climbing_radius(c, i);
        s->val[i] = phc_climbing_order(c, i);
        double q[12];
        if (!phc_climbing_leaf_quad(c, i, q))
            continue;
        for (int k = 0; k < 3; ++k) {
            s->head[3 * j + k] = 0.5 * (q[k] + q[9 + k]);
            s->tail[3 * j + k] = 0.5 * (q[3 + k] + q[6 + k]);
        }
        s->rad[j] = 0.5 * rmax;
        s->val[j++] = 3;
    }
    return 0;
}

/* The views' options: colour = branch order 0-2, 3 for the leaves. */
static phc_shape_plot_options order_plot_options(void)
{
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.value_label = "branch order 0-2 (3 = leaves)";
    po.value_min = 0;
    po.value_max = 3;
    po.max_line_width = 6;
    return po;
}

/* A plant grown with dynamics and the numbers printed of it. */
typedef struct dynamic_run {
    double cpu, wall;             /* s: the growth's process CPU time (all threads) and wall time */
    size_t n, anchored, clips, free_tips;
    size_t queries, skipped, tree; /* collisions: closest-point queries made, skipped; made ones the mesh's tree answered */
    double min_sd, depth, end_depth; /* m: smallest signed distance of a centre; minus the radius; of an end */
    double sag_mean, sag_max, links; /* m, m, links (free_tip_sag) */
} dynamic_run;

/* keep (may be NULL) gets the plant (the caller frees it). */
static int grow_dynamic(const phc_climbing_options *o, phc_support_mesh *wall, const double seed[3],
                        const double up[3], size_t steps, double dt, dynamic_run *r, phc_climbing **keep)
{
    const size_t tree0 = phc_support_mesh_tree_queries(wall);
    const clock_t cpu0 = clock();
    struct timespec w0, w1;
    clock_gettime(CLOCK_MONOTONIC, &w0);
    phc_climbing *c = grow_wall(o, wall, seed, up, steps, dt);
    clock_gettime(CLOCK_MONOTONIC, &w1);
    r->cpu = (double)(clock() - cpu0) / CLOCKS_PER_SEC;
    r->wall = (double)(w1.tv_sec - w0.tv_sec) + 1e-9 * (double)(w1.tv_nsec - w0.tv_nsec);
    if (!c)
        return -1;
    r->tree = phc_support_mesh_tree_queries(wall) - tree0;
    phc_climbing_collision_queries(c, &r->queries, &r->skipped);
    phc_climbing_stats st;
    phc_climbing_get_stats(c, &st);
    r->n = phc_climbing_count(c);
    r->anchored = st.anchored;
    r->depth = smallest_depth(c, wall, &r->clips);
    r->end_depth = smallest_end_depth(c, wall);
    r->min_sd = INFINITY;
    for (size_t i = 0; i < r->n; ++i) {
        double x[3], cp[3], nf[3];
        phc_climbing_position(c, i, x);
        if (phc_support_mesh_closest(wall, x, cp, nf) == 0)
            r->min_sd = fmin(r->min_sd, (x[0] - cp[0]) * nf[0] + (x[1] - cp[1]) * nf[1] + (x[2] - cp[2]) * nf[2]);
    }
    free_tip_sag(c, &r->free_tips, &r->sag_mean, &r->sag_max, &r->links);
    if (keep)
        *keep = c;
    else
        phc_climbing_free(c);
    return 0;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started)
        return started;
    phc_error err;
    const char *mesh_path = PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window.obj";
    phc_support_mesh *wall = phc_support_mesh_read(mesh_path, &err);
    if (!wall) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    phc_climbing_options o = phc_climbing_options_default();
    o.seed = 13;
    o.growth_rate = 0.2;
    o.apical_dominance = 0.6;
    o.radius = 0.003;
    o.branch_probability = 0.35;
    o.direction_variance = 0.6;
    o.max_order = 2;
    o.light.direction[0] = 0;
    o.light.direction[1] = 1 / sqrt(3.25);
    o.light.direction[2] = 1.5 / sqrt(3.25);
    o.light.extinction = 40;
    o.light.ambient = 0.2;
    o.light.cell = 0.05;
    o.light.origin[0] = -0.85;
    o.light.origin[1] = -0.25;
    o.light.origin[2] = -0.25;
    o.light.dims[0] = 34;
    o.light.dims[1] = 12;
    o.light.dims[2] = 34;
    o.phototropism = 0.02;
    o.surface_adaption = 0.5;
    o.keep_outside = 1;
    o.leaf_step = 1;
    o.leaf_size = 0.03;
    o.cambium_rate = 0.02;
    o.leaf_pipe_area = 1e-6;
    o.closest = phc_support_mesh_closest;
    o.closest_user = wall;
    const double seed[3] = {-0.1, 0.02, 0}, up[3] = {0, 0, 1};
    const double duration = 240, dt = 0.25;
    const size_t steps = (size_t)llround(duration / dt);
    phc_climbing *c = grow_wall(&o, wall, seed, up, steps, dt);
    if (!c)
        return 1;

    /* the checks' numbers */
    const size_t n = phc_climbing_count(c), nl = phc_climbing_leaf_count(c);
    phc_climbing_stats st;
    phc_climbing_get_stats(c, &st);
    double top = 0;
    size_t crossing = 0;
    const size_t ntri = phc_support_mesh_triangle_count(wall);
    double sum_cos = 0, min_sd = INFINITY, light_under = 0, light_else = 0;
    size_t n_under = 0, n_else = 0;
    /* coverage of the wall plane x ∈ [−0.6, 0.6], z ∈ [0, 1.2] in 1 cm cells */
    enum { NX = 120, NZ = 120 };
    static unsigned char cov[NX * NZ];
    memset(cov, 0, sizeof cov);
#define MARK(px, pz)                                                                \
    do {                                                                            \
        const double ux_ = floor(((px) + 0.6) / CELL), uz_ = floor((pz) / CELL);    \
        if (ux_ >= 0 && ux_ < NX && uz_ >= 0 && uz_ < NZ)                           \
            cov[(size_t)uz_ * NX + (size_t)ux_] = 1;                                \
    } while (0)
    for (size_t i = 0; i < n; ++i) {
        double x[3], cp[3], nf[3], b[3], t[3];
        phc_climbing_position(c, i, x);
        if (phc_support_mesh_closest(wall, x, cp, nf) == 0) {
            const double sd = (x[0] - cp[0]) * nf[0] + (x[1] - cp[1]) * nf[1] + (x[2] - cp[2]) * nf[2];
            min_sd = fmin(min_sd, sd);

        }
        top = fmax(top, x[2]);
        /* a stem covers the cells along its axis, sampled every 2 mm */
        phc_climbing_segment(c, i, b, t);
        const int clips = segment_clips(c, i, wall, ntri);
        crossing += clips;
        for (int s = 0; s <= 10; ++s) {
            const double u = s / 10.0;
            MARK(b[0] + u * (t[0] - b[0]), b[2] + u * (t[2] - b[2]));
        }
        double q[12], nrm[3], ctr[3];
        if (!phc_climbing_leaf(c, i, ctr, nrm, NULL))
            continue;
        sum_cos += nrm[0] * o.light.direction[0] + nrm[1] * o.light.direction[1] + nrm[2] * o.light.direction[2];
        const double li = phc_climbing_leaf_light(c, i);
        if (fabs(ctr[0]) < 0.3 && ctr[2] < 0.92 && ctr[2] > 0.62) {
            light_under += li;
            ++n_under;
        } else {
            light_else += li;
            ++n_else;
        }
        /* a blade covers its projection: sampled on a 7 x 7 grid */
        phc_climbing_leaf_quad(c, i, q);
        for (int a = 0; a <= 6; ++a)
            for (int bb = 0; bb <= 6; ++bb) {
                const double u = a / 6.0, v = bb / 6.0;
                double p[3];
                for (int k = 0; k < 3; ++k)
                    p[k] = q[k] + u * (q[3 + k] - q[k]) + v * (q[9 + k] - q[k]);
                MARK(p[0], p[2]);
            }
    }
#undef MARK
    size_t covered = 0;
    for (size_t k = 0; k < (size_t)NX * NZ; ++k)
        covered += cov[k];
    const double area = (double)covered * CELL * CELL;
    const double mean_cos = nl ? sum_cos / (double)nl : 0;
    const double attached = (double)st.anchored / (double)n;
    const double lu = n_under ? light_under / (double)n_under : NAN, le = n_else ? light_else / (double)n_else : NAN;
    double rmax = 0;
    for (size_t i = 0; i < n; ++i)
        rmax = fmax(rmax, phc_climbing_radius(c, i));

    /* the OBJ */
    char path[1024];
    phc_grow_obj_counts oc;
    snprintf(path, sizeof path, "%s/climbing_fig13_wall.obj", out);
    if (phc_grow_write_obj(c, wall, 8, path, &oc, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }

    /* the views: stems coloured by branch order, leaves as strokes across
       their blades (colour 3), the wall's corners as markers */
    const size_t nv = phc_support_mesh_vertex_count(wall);
    strokes st0;
    double *mk = malloc(3 * nv * sizeof *mk);
    if (!mk || plant_strokes(c, &st0))
        return 1;
    for (size_t i = 0; i < nv; ++i)
        phc_support_mesh_vertex(wall, i, mk + 3 * i);
    char title[256];
    snprintf(title, sizeof title, "%zu particles, %zu leaves after %g s", n, nl, duration);
    phc_shape_panel pan = {st0.n, st0.head, st0.tail, st0.rad, st0.val, title, nv, mk, "wall, window and ledge corners"};
    phc_shape_plot_options po = order_plot_options();
    po.page_width = 900;
    po.page_height = 820;
    po.title = "Fig. 13: a vine on a wall, front view (x-z)";
    snprintf(path, sizeof path, "%s/climbing_fig13_wall_front.png", out);
    if (phc_shape_plot(path, &pan, 1, &po, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    po.title = "Fig. 13: side view (y-z; the wall at y = 0)";
    po.across_axis = 1;
    snprintf(path, sizeof path, "%s/climbing_fig13_wall_side.png", out);
    if (phc_shape_plot(path, &pan, 1, &po, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }

    printf("climbing Fig. 13: seed 13 at (-0.1, 0.02, 0) m, %g s in steps of %g s, a wall 1.2 x 1.2 m with a window "
           "and a ledge; light toward (0, 1, 1.5), ambient 0.2; a leaf at every node\n",
           duration, dt);
    printf("plant: %zu particles, %zu leaves, %zu laterals, highest centre %.3f m; thickest radius %.2f mm (primary %.1f mm); "
           "obj: %zu triangles\n",
           n, nl, st.laterals, top - seed[2], 1e3 * rmax, 1e3 * o.radius, oc.triangles);
    const int c1 = mean_cos > 0.8, c2 = attached > 0.8, c3 = area > 0.1, c4 = min_sd >= 0, c5 = lu < le;
    printf("check: leaves face the light, mean cos(normal, light) %.3f > 0.8: %s\n", mean_cos, c1 ? "pass" : "FAIL");
    printf("check: attached to the wall, %zu of %zu particles (%.3f) > 0.8: %s\n", st.anchored, n, attached,
           c2 ? "pass" : "FAIL");
    printf("check: covers %.3f m^2 of the wall (1 cm cells) > 0.1 m^2: %s\n", area, c3 ? "pass" : "FAIL");
    printf("check: nothing through the wall, smallest signed distance of a centre to its closest face %.3g m >= 0: %s\n",
           min_sd, c4 ? "pass" : "FAIL");
    printf("  segments whose straight line clips a convex edge of the wall (its centre outside): %zu of %zu\n",
           crossing, n);
    printf("check: the ledge shades, mean leaf light under it %.3f (%zu leaves) < elsewhere %.3f (%zu): %s\n", lu,
           n_under, le, n_else, c5 ? "pass" : "FAIL");
    /* the same plant with collisions (option collide): every particle
       pushed out of the wall to its radius */
    size_t cross0 = 0, cross1 = 0, pushed_last = 0;
    const double min_depth = smallest_depth(c, wall, &cross0);
    phc_climbing_options oc1 = o;
    oc1.collide = 1;
    phc_climbing *cwall = grow_wall(&oc1, wall, seed, up, steps, dt);
    if (!cwall)
        return 1;
    const double min_depth1 = smallest_depth(cwall, wall, &cross1);
    phc_climbing_collisions(cwall, &pushed_last, NULL);
    const int c6 = min_depth1 >= -1e-12;
    printf("  smallest signed distance of a centre minus its radius, all particles: %.3g m (%zu segments clip)\n",
           min_depth, cross0);
    printf("check: the same seed with collisions (option collide): %zu particles, smallest signed distance minus "
           "radius %.3g m >= -1e-12 m: %s (%zu pushed out in the last step; %zu segments clip)\n",
           phc_climbing_count(cwall), min_depth1, c6 ? "pass" : "FAIL", pushed_last, cross1);
    /* and with the segments' ends pushed out too (option collide_ends) */
    const double ends_before = smallest_end_depth(cwall, wall);
    phc_climbing_free(cwall);
    phc_climbing_options oc2 = oc1;
    oc2.collide_ends = 1;
    phc_climbing *cends = grow_wall(&oc2, wall, seed, up, steps, dt);
    if (!cends)
        return 1;
    size_t cross2 = 0;
    const double min_depth2 = smallest_depth(cends, wall, &cross2), ends_after = smallest_end_depth(cends, wall);
    printf("  smallest signed distance of a segment end minus its radius (seed excluded): centres pushed %.3g m, "
           "centres and ends pushed (option collide_ends) %.3g m\n",
           ends_before, ends_after);
    const int c7 = ends_after > ends_before && min_depth2 >= -1e-12;
    printf("check: with collide_ends (%zu particles) the ends keep farther out, %.3g m > %.3g m, and the centres stay "
           "out, %.3g m >= -1e-12 m: %s (%zu segments clip)\n",
           phc_climbing_count(cends), ends_after, ends_before, min_depth2, c7 ? "pass" : "FAIL", cross2);
    phc_climbing_free(cends);

    /* the same seed grown with dynamics, in Fig. 12's 0.01 s substeps, with
       each of the two joint passes; without collide (with collide see
       below).  On one thread: the particles' threads
       start at 1024 particles (model/particles.c), and at this plant's
       1200–1400 their barriers in each of the 24,000 substeps cost more
       than they save on a shared machine (the beam run took 36.8 s CPU on
       two threads under a load of 2.6, 1.5 s on one); the numbers are the
       same on any thread count (model/climbing_growth.h). */
    dynamic_run dyn[2];
    int c8 = 1;
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    for (int k = 0; k < 2; ++k) {
        phc_climbing_options od = o;
        od.dynamics_substeps = (size_t)llround(dt / 0.01);
        od.particles.bending = k ? PHC_PARTICLES_BEAM : PHC_PARTICLES_OWN_WEIGHT;
        od.particles.beam_modulus = 1e7; /* Fig. 12's E_1/2 */
        if (grow_dynamic(&od, wall, seed, up, steps, dt, &dyn[k], NULL))
            return 1;
        const dynamic_run *r = &dyn[k];
        printf("the same seed with dynamics (%zu substeps of %g s per step, gravity, anchors; bending %s%s): CPU "
               "%.1f s, wall %.1f s\n",
               od.dynamics_substeps, dt / (double)od.dynamics_substeps, k ? "beam" : "own_weight",
               k ? ", E_1/2 1e7 Pa" : "", r->cpu, r->wall);
        printf("  %zu particles, attached %zu (%.3f); smallest signed distance of a centre %.3g m, of a centre minus "
               "its radius %.3g m, of a segment end minus its radius %.3g m; %zu segments clip\n",
               r->n, r->anchored, (double)r->anchored / (double)r->n, r->min_sd, r->depth, r->end_depth, r->clips);
        printf("  free tips (no anchor, no child): %zu, %.1f links from their closest anchored ancestor on average; "
               "drop below their rest shape: mean %.2f cm, largest %.2f cm\n",
               r->free_tips, r->links, 100 * r->sag_mean, 100 * r->sag_max);
        c8 &= (double)r->anchored / (double)r->n > 0.8 && r->free_tips > 0 && r->sag_mean > 0;
    }
    omp_set_num_threads(threads);
    {
        size_t free_k;
        double k_mean, k_max, k_links;
        free_tip_sag(c, &free_k, &k_mean, &k_max, &k_links);
        printf("  kinematic plant above: %zu free tips, drop below their rest shape largest %.2g cm\n", free_k,
               100 * k_max);
    }
    printf("check: with dynamics (both passes) most particles stay attached (> 0.8) and the free tips hang below "
           "their rest shape (mean drop > 0): %s\n",
           c8 ? "pass" : "FAIL");

    /* the same seed with dynamics and collisions, grown as `phytocal grow
       measurements/examples/climbing/wall_window_collide.yaml` grows it
       (the config read by the grow config's own reader, its light grid,
       support and shadows set up as fit/grow.c does): the wall as a closed
       solid (wall_window_closed.obj, the same face, recess and ledge), so
       that supports_closed holds and the collision pass skips the points
       too far off it to be pushed; then the beam pass (the one key
       changed).  One thread, as above. */
    phc_grow_config *cfg = NULL;
    if (phc_grow_config_load(PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window_collide.yaml", &cfg, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    phc_support_mesh *solid = phc_support_mesh_read(cfg->support, &err);
    if (!solid) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    dynamic_run col[2];
    phc_climbing *collided[2] = {NULL, NULL};
    int c9 = 1;
    omp_set_num_threads(1);
    for (int k = 0; k < 2; ++k) {
        phc_climbing_options oc = cfg->options;
        phc_grow_light_grid(cfg, solid, &oc);
        oc.closest = phc_support_mesh_closest;
        oc.closest_user = solid;
        oc.closest_segment = phc_support_mesh_segment_deepest;
        if (k) {
            oc.particles.bending = PHC_PARTICLES_BEAM;
            oc.particles.beam_modulus = 1e7; /* Fig. 12's E_1/2 */
        }
        if (grow_dynamic(&oc, solid, cfg->position, cfg->direction, (size_t)llround(cfg->duration / cfg->time_step),
                         cfg->time_step, &col[k], &collided[k]))
            return 1;
        const dynamic_run *r = &col[k];
        printf("with collisions (wall_window_collide.yaml: the wall as a closed solid, dynamics.collide, "
               "collide_segments and supports_closed; bending %s%s): CPU %.1f s, wall %.1f s\n",
               k ? "beam" : "own_weight", k ? ", E_1/2 1e7 Pa" : "", r->cpu, r->wall);
        printf("  %zu particles, attached %zu (%.3f); smallest signed distance minus radius of a centre %.3g m, of a "
               "segment end %.3g m; %zu segments clip\n",
               r->n, r->anchored, (double)r->anchored / (double)r->n, r->depth, r->end_depth, r->clips);
        printf("  closest-point queries of the collision pass: %zu made (%zu by the mesh's tree, %zu by a "
               "certificate), %zu skipped\n",
               r->queries, r->tree, r->queries - r->tree, r->skipped);
        c9 &= r->depth >= -1e-12 && r->clips == 0 && (double)r->anchored / (double)r->n > 0.8;
    }
    omp_set_num_threads(threads);
    printf("check: with collisions (both passes) every centre keeps its radius off the wall (smallest signed distance "
           "minus radius >= -1e-12 m), no segment clips (collide_segments) and most particles stay attached (> 0.8): "
           "%s\n",
           c9 ? "pass" : "FAIL");
    /* their side views (y-z), the closed wall's corners as markers */
    {
        const size_t ncv = phc_support_mesh_vertex_count(solid);
        strokes sc[2];
        double *cmk = malloc(3 * ncv * sizeof *cmk);
        if (!cmk || plant_strokes(collided[0], &sc[0]) || plant_strokes(collided[1], &sc[1]))
            return 1;
        for (size_t i = 0; i < ncv; ++i)
            phc_support_mesh_vertex(solid, i, cmk + 3 * i);
        char ctitle[2][128];
        phc_shape_panel cpan[2];
        for (int k = 0; k < 2; ++k) {
            snprintf(ctitle[k], sizeof ctitle[k], "%s: %zu particles, %zu clip", k ? "beam" : "own weight",
                     phc_climbing_count(collided[k]), col[k].clips);
            cpan[k] = (phc_shape_panel){sc[k].n, sc[k].head, sc[k].tail, sc[k].rad, sc[k].val, ctitle[k], ncv, cmk,
                                        "closed wall's corners"};
        }
        phc_shape_plot_options cpo = order_plot_options();
        cpo.across_axis = 1;
        cpo.columns = 2;
        cpo.page_width = 1300;
        cpo.page_height = 1200; /* (tall: the narrow y axis then keeps its labels apart) */
        cpo.title = "Fig. 13 with collisions, side view (y-z; wall face at y = 0)";
        snprintf(path, sizeof path, "%s/climbing_fig13_wall_collide_side.png", out);
        if (phc_shape_plot(path, cpan, 2, &cpo, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        strokes_free(&sc[0]);
        strokes_free(&sc[1]);
        free(cmk);
        phc_climbing_free(collided[0]);
        phc_climbing_free(collided[1]);
    }
    const int ok = c1 && c2 && c3 && c4 && c5 && c6 && c7 && c8 && c9;

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "climbing_fig13_wall.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Climbing plants, Fig. 13: a vine with leaves on a wall\n\n"
            "**The paper's figure** (Hädrich et al., CGF 2017, Fig. 13): climbing plants cover a building's\n"
            "walls, their leaves turned to the light.\n\n"
            "**What we computed**: one seed before a wall with a window and a ledge, %g s of growth, leaves\n"
            "at every node, supports that cast shadows, secondary growth (values ours).\n\n"
            "![front](climbing_fig13_wall_front.png)\n\n![side](climbing_fig13_wall_side.png)\n\n"
            "| quantity | value |\n|---|---|\n| particles | %zu |\n| leaves | %zu |\n"
            "| mean cos(leaf normal, light) | %.3f |\n| attached fraction | %.3f |\n| covered area (m²) | %.3f |\n"
            "| smallest signed distance to the wall (m) | %.3g |\n| smallest signed distance − radius (m) | %.3g |\n| segments clipping a convex edge | %zu |\n| leaf light under the ledge / elsewhere | %.3f / %.3f |\n\n"
            "**With dynamics** (the same seed, 0.01 s substeps, gravity, anchors, no collisions):\n\n"
            "| joint pass | particles | attached fraction | smallest signed distance (m) | segments clipping | "
            "free tips | their mean / largest drop (cm) |\n|---|---|---|---|---|---|---|\n"
            "| own_weight | %zu | %.3f | %.3g | %zu | %zu | %.2f / %.2f |\n"
            "| beam (E_1/2 1e7 Pa) | %zu | %.3f | %.3g | %zu | %zu | %.2f / %.2f |\n\n"
            "**With dynamics and collisions** (`measurements/examples/climbing/wall_window_collide.yaml`: the wall as a "
            "closed solid, every centre and segment end pushed out in every substep):\n\n"
            "![collisions](climbing_fig13_wall_collide_side.png)\n\n"
            "| joint pass | particles | attached fraction | smallest signed distance − radius, centre / end (m) | "
            "segments clipping | CPU (s) |\n|---|---|---|---|---|---|\n"
            "| own_weight | %zu | %.3f | %.3g / %.3g | %zu | %.1f |\n"
            "| beam (E_1/2 1e7 Pa) | %zu | %.3f | %.3g / %.3g | %zu | %.1f |\n\n"
            "**Checks**: %s.  The mesh `climbing_fig13_wall.obj` opens in any viewer.\n",
            duration, n, nl, mean_cos, attached, area, min_sd, min_depth, crossing, lu, le, dyn[0].n,
            (double)dyn[0].anchored / (double)dyn[0].n, dyn[0].min_sd, dyn[0].clips, dyn[0].free_tips,
            100 * dyn[0].sag_mean, 100 * dyn[0].sag_max, dyn[1].n, (double)dyn[1].anchored / (double)dyn[1].n,
            dyn[1].min_sd, dyn[1].clips, dyn[1].free_tips, 100 * dyn[1].sag_mean, 100 * dyn[1].sag_max, col[0].n,
            (double)col[0].anchored / (double)col[0].n, col[0].depth, col[0].end_depth, col[0].clips, col[0].cpu,
            col[1].n, (double)col[1].anchored / (double)col[1].n, col[1].depth, col[1].end_depth, col[1].clips,
            col[1].cpu, ok ? "all pass" : "**some FAIL** (see the program's output)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    strokes_free(&st0);
    free(mk);
    phc_climbing_free(c);
    phc_support_mesh_free(wall);
    phc_support_mesh_free(solid);
    phc_grow_config_free(cfg);
    printf("%s: %s\n", ok ? "ok" : "FAIL", out);
    return !ok;
}
