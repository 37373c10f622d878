/* `phytocal grow`: see grow.h. */
#include "fit/grow.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/grow_mesh.h"
#include "fit/json_file_internal.h"
#include "fit/run_dir.h"
#include "fit/shape_plots.h"
#include "measurements/atomic_file.h"
#include "measurements/plant_io.h"
#include "measurements/support_mesh.h"

void phc_grow_inputs_init(phc_grow_inputs *in, const phc_grow_config *c)
{
    memset(in, 0, sizeof *in);
    in->pb.name = c->name;
    in->pb.source = c->source;
    in->seeds[0] = c->seed_text;
    in->pb.seeds = in->seeds;
    in->pb.n_seeds = 1;
    in->pb.options.nls.num_threads = 1;
    if (c->support) {
        in->inputs[0] = c->support;
        in->ds.inputs = in->inputs;
        in->ds.n_inputs = 1;
        in->ds.name = c->name;
        in->dsp = &in->ds;
        in->pb.datasets = &in->dsp;
        in->pb.n_datasets = 1;
    }
}

void phc_grow_summarise(const phc_climbing *c, const double seed_base[3], phc_grow_summary *s)
{
    const size_t frames = s->frames;
    memset(s, 0, sizeof *s);
    s->frames = frames;
    phc_climbing_stats st;
    phc_climbing_get_stats(c, &st);
    s->time = st.time;
    s->particles = st.particles;
    s->apical = st.apical;
    s->laterals = st.laterals;
    s->bud_trials = st.bud_trials;
    s->max_order = st.max_order;
    s->anchored = st.anchored;
    s->anchors_made = st.anchors_made;
    s->anchors_released = st.anchors_released;
    /* broken pieces that still fall are not the plant (model/climbing_breaking.h) */
    s->breaks = st.breaks;
    s->falling = st.falling;
    s->pieces_dropped = st.pieces_dropped;
    s->particles_dropped = st.particles_dropped;
    s->resprouts = st.resprouts;
    s->first_break_time = st.first_break_time;
    s->first_break_stress = st.first_break_bend_stress;
    memcpy(s->first_break_joint, st.first_break_joint, sizeof s->first_break_joint);
    s->first_break_parent_anchored = st.first_break_parent_anchored;
    s->particles = st.particles - st.falling;
    s->attached_fraction = s->particles ? (double)st.anchored / (double)s->particles : 0;
    double top = seed_base[2];
    for (size_t i = 0; i < st.particles; ++i) {
        double b[3], t[3];
        if (st.falling && phc_climbing_is_falling(c, i))
            continue;
        phc_climbing_segment(c, i, b, t);
        top = fmax(top, fmax(b[2], t[2]));
        s->total_length += phc_climbing_length(c, i);
        if (phc_climbing_is_lateral(c, i)) {
            const unsigned o = phc_climbing_order(c, i);
            s->laterals_per_order[o < 8 ? o : 7]++;
        }
    }
    s->height = top - seed_base[2];
    /* leaves and secondary growth */
    double ell[3];
    phc_climbing_light_direction(c, ell);
    double sum_cos = 0;
    for (size_t i = 0; i < st.particles; ++i) {
        double nrm[3];
        if (st.falling && phc_climbing_is_falling(c, i))
            continue;
        s->max_radius = fmax(s->max_radius, phc_climbing_radius(c, i));
        if (phc_climbing_leaf(c, i, NULL, nrm, NULL)) {
            s->leaves++;
            sum_cos += nrm[0] * ell[0] + nrm[1] * ell[1] + nrm[2] * ell[2];
        }
    }
    s->mean_leaf_cos = s->leaves ? sum_cos / (double)s->leaves : 0;
}

phc_plant_graph *phc_grow_plant_graph(const phc_climbing *c, phc_error *err)
{
    const size_t n = phc_climbing_count(c);
    phc_plant_graph *g = phc_plant_graph_new(n);
    if (!g) {
        phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        return NULL;
    }
    for (size_t i = 0; i < n; ++i) {
        phc_climbing_segment(c, i, g->head + 3 * i, g->tail + 3 * i);
        g->radius[i] = phc_climbing_radius(c, i);
        g->length[i] = phc_climbing_length(c, i);
        const size_t p = phc_climbing_parent(c, i);
        g->parent[i] = p == PHC_CLIMBING_NONE ? PHC_PLANT_NO_PARENT : p;
        g->source_id[i] = (long)i;
    }
    g->fixed[0] = 1;
    if (phc_plant_graph_finish(g, "climbing plant", err)) {
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

/* One frame: the plant as VTK with its per-segment fields. */
static int write_frame(const phc_climbing *c, const char *path, double t, phc_error *err)
{
    phc_plant_graph *g = phc_grow_plant_graph(c, err);
    if (!g)
        return err->status;
    const size_t n = g->n;
    double *order = malloc(n * sizeof *order), *light = malloc(n * sizeof *light),
           *anch = malloc(n * sizeof *anch);
    int rc = PHC_OK;
    if (!order || !light || !anch) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        double a[3];
        order[i] = phc_climbing_order(c, i);
        light[i] = phc_climbing_light_at(c, i);
        anch[i] = phc_climbing_anchor(c, i, a);
    }
    char title[128];
    snprintf(title, sizeof title, "phytocal grow: climbing plant at t = %g s", t);
    const phc_plant_field fields[3] = {{"branch_order", order}, {"light", light}, {"anchored", anch}};
    rc = phc_plant_io_write_vtk(path, g, title, fields, 3, err);
done:
    free(order);
    free(light);
    free(anch);
    phc_plant_graph_free(g);
    return rc;
}

/* The leaves of one frame as legacy VTK polydata: one quad per blade, with
 * its light and its normal's cosine to the light direction as cell data. */
static int write_leaves_vtk(const phc_climbing *c, const double light_dir[3], const char *path, double t,
                            phc_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
    const double ll = sqrt(light_dir[0] * light_dir[0] + light_dir[1] * light_dir[1] + light_dir[2] * light_dir[2]);
    const size_t n = phc_climbing_count(c), nl = phc_climbing_leaf_count(c);
    fprintf(f, "# vtk DataFile Version 3.0\nphytocal grow: leaves at t = %g s\nASCII\nDATASET POLYDATA\n", t);
    fprintf(f, "POINTS %zu double\n", 4 * nl);
    for (size_t i = 0; i < n; ++i) {
        double q[12];
        if (phc_climbing_leaf_quad(c, i, q))
            for (int j = 0; j < 4; ++j)
                fprintf(f, "%.17g %.17g %.17g\n", q[3 * j], q[3 * j + 1], q[3 * j + 2]);
    }
    fprintf(f, "POLYGONS %zu %zu\n", nl, 5 * nl);
    for (size_t j = 0; j < nl; ++j)
        fprintf(f, "4 %zu %zu %zu %zu\n", 4 * j, 4 * j + 1, 4 * j + 2, 4 * j + 3);
    if (nl) {
        fprintf(f, "CELL_DATA %zu\nSCALARS light double 1\nLOOKUP_TABLE default\n", nl);
        for (size_t i = 0; i < n; ++i)
            if (phc_climbing_leaf(c, i, NULL, NULL, NULL))
                fprintf(f, "%.10g\n", phc_climbing_leaf_light(c, i));
        fprintf(f, "SCALARS cos_normal_light double 1\nLOOKUP_TABLE default\n");
        for (size_t i = 0; i < n; ++i) {
            double nrm[3];
            if (phc_climbing_leaf(c, i, NULL, nrm, NULL))
                fprintf(f, "%.10g\n", (nrm[0] * light_dir[0] + nrm[1] * light_dir[1] + nrm[2] * light_dir[2]) / ll);
        }
    }
    const int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
    return PHC_OK;
}

/* The support mesh as legacy VTK polydata (triangles). */
static int write_support_vtk(const phc_support_mesh *m, const char *path, phc_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
    const size_t nv = phc_support_mesh_vertex_count(m), nt = phc_support_mesh_triangle_count(m);
    fprintf(f, "# vtk DataFile Version 3.0\nphytocal grow: support mesh\nASCII\nDATASET POLYDATA\n");
    fprintf(f, "POINTS %zu double\n", nv);
    for (size_t i = 0; i < nv; ++i) {
        double v[3];
        phc_support_mesh_vertex(m, i, v);
        fprintf(f, "%.17g %.17g %.17g\n", v[0], v[1], v[2]);
    }
    fprintf(f, "POLYGONS %zu %zu\n", nt, 4 * nt);
    for (size_t t = 0; t < nt; ++t) {
        size_t idx[3];
        phc_support_mesh_triangle(m, t, idx);
        fprintf(f, "3 %zu %zu %zu\n", idx[0], idx[1], idx[2]);
    }
    if (fclose(f) != 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
    return PHC_OK;
}

/* Side (x-z) and front (y-z) views of the final plant. */
static int write_views(const phc_climbing *c, const phc_support_mesh *m, const char *tmpdir, const char *name,
                       phc_error *err)
{
    phc_plant_graph *g = phc_grow_plant_graph(c, err);
    if (!g)
        return err->status;
    const size_t n = g->n, nv = m ? phc_support_mesh_vertex_count(m) : 0, nl = phc_climbing_leaf_count(c);
    const size_t ns = n + nl;
    double *order = malloc(ns * sizeof *order), *mk = malloc((nv ? 3 * nv : 1) * sizeof *mk);
    double *head = malloc(3 * ns * sizeof *head), *tail = malloc(3 * ns * sizeof *tail),
           *rad = malloc(ns * sizeof *rad);
    int rc = PHC_OK;
    if (!order || !mk || !head || !tail || !rad) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    unsigned top = 0;
    double rmax = 0;
    for (size_t i = 0; i < n; ++i) {
        order[i] = phc_climbing_order(c, i);
        top = order[i] > top ? (unsigned)order[i] : top;
        rmax = fmax(rmax, g->radius[i]);
    }
    memcpy(head, g->head, 3 * n * sizeof *head);
    memcpy(tail, g->tail, 3 * n * sizeof *tail);
    memcpy(rad, g->radius, n * sizeof *rad);
    /* leaves: a stroke across each blade (its midline along the petiole),
       as wide as the thickest stem, coloured one past the highest order */
    for (size_t i = 0, j = n; i < n; ++i) {
        double q[12];
        if (!phc_climbing_leaf_quad(c, i, q))
            continue;
        for (int k = 0; k < 3; ++k) {
            head[3 * j + k] = 0.5 * (q[k] + q[9 + k]);
            tail[3 * j + k] = 0.5 * (q[3 + k] + q[6 + k]);
        }
        rad[j] = rmax;
        order[j++] = top + 1;
    }
    for (size_t i = 0; i < nv; ++i)
        phc_support_mesh_vertex(m, i, mk + 3 * i);
    char title[256], path[4200];
    phc_climbing_stats st;
    phc_climbing_get_stats(c, &st);
    snprintf(title, sizeof title, "%s: %zu particles after %g s", name, n, st.time);
    phc_shape_panel p = {ns, head, tail, rad, order, title, nv, nv ? mk : NULL, "support vertices"};
    phc_shape_plot_options po = phc_shape_plot_options_default();
    char vlabel[96];
    if (nl)
        snprintf(vlabel, sizeof vlabel, "branch order (0 = main axis; %u = leaves)", top + 1);
    po.value_label = nl ? vlabel : "branch order (0 = main axis)";
    po.value_min = 0;
    po.value_max = nl ? top + 1 : top > 0 ? top : 1;
    po.max_line_width = 5;
    const char *views[2] = {"plant_side.png", "plant_front.png"};
    const char *titles[2] = {"side view (x-z)", "front view (y-z)"};
    for (int v = 0; v < 2 && rc == PHC_OK; ++v) {
        po.across_axis = v;
        po.title = titles[v];
        snprintf(path, sizeof path, "%s/%s", tmpdir, views[v]);
        rc = phc_shape_plot(path, &p, 1, &po, err);
    }
done:
    free(order);
    free(mk);
    free(head);
    free(tail);
    free(rad);
    phc_plant_graph_free(g);
    return rc;
}

static json_t *summary_json(const phc_grow_summary *s)
{
    json_t *per = json_array();
    for (size_t o = 1; o <= s->max_order && o < 8; ++o)
        json_array_append_new(per, json_integer((json_int_t)s->laterals_per_order[o]));
    return json_pack("{s:f, s:I, s:I, s:I, s:I, s:o, s:I, s:f, s:f, s:I, s:f, s:I, s:I}", "time_s", s->time,
                     "particles", (json_int_t)s->particles, "growing_tips", (json_int_t)s->apical, "bud_trials",
                     (json_int_t)s->bud_trials, "laterals", (json_int_t)s->laterals, "laterals_per_order", per,
                     "max_order", (json_int_t)s->max_order, "height_m", s->height, "total_length_m", s->total_length,
                     "anchored", (json_int_t)s->anchored, "attached_fraction", s->attached_fraction,
                     "anchors_made", (json_int_t)s->anchors_made, "anchors_released",
                     (json_int_t)s->anchors_released);
}

static json_t *summary_json_full(const phc_grow_summary *s)
{
    json_t *o = summary_json(s);
    if (o) {
        json_object_set_new(o, "leaves", json_integer((json_int_t)s->leaves));
        json_object_set_new(o, "mean_cos_leaf_normal_light", json_real(s->mean_leaf_cos));
        json_object_set_new(o, "max_radius_m", json_real(s->max_radius));
    }
    return o;
}

static int write_result(const phc_grow_config *cfg, const phc_grow_summary *s, const phc_provenance *pv,
                        json_t *frames, const char *tmpdir, phc_error *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/result.json", tmpdir);
    json_t *root = json_pack("{s:s, s:s, s:s?, s:I, s:f, s:f, s:f, s:o, s:O}", "command", "grow", "name", cfg->name,
                             "support", cfg->support, "seed", (json_int_t)cfg->options.seed, "duration_s",
                             cfg->duration, "time_step_s", cfg->time_step, "frame_interval_s", cfg->frame_interval,
                             "plant", summary_json_full(s), "frames", frames);
    if (!root)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (cfg->options.particles.break_threshold > 0 || cfg->options.particles.break_stress > 0) { /* what broke */
        json_t *plant = json_object_get(root, "plant");
        json_object_set_new(plant, "breaks", json_integer((json_int_t)s->breaks));
        json_object_set_new(plant, "falling_particles", json_integer((json_int_t)s->falling));
        json_object_set_new(plant, "pieces_dropped", json_integer((json_int_t)s->pieces_dropped));
        json_object_set_new(plant, "particles_dropped", json_integer((json_int_t)s->particles_dropped));
        if (isfinite(cfg->options.resprout_delay))
            json_object_set_new(plant, "resprouts", json_integer((json_int_t)s->resprouts));
        if (cfg->options.particles.break_stress > 0 && s->breaks) {
            json_t *at = json_pack("[f, f, f]", s->first_break_joint[0], s->first_break_joint[1],
                                   s->first_break_joint[2]);
            json_object_set_new(plant, "first_break",
                                json_pack("{s:f, s:f, s:o, s:b}", "time_s", s->first_break_time, "bending_stress_Pa",
                                          s->first_break_stress, "joint_m", at, "parent_anchored",
                                          s->first_break_parent_anchored));
        }
    }
    if (pv)
        json_object_set_new(root, "provenance", phc_provenance_to_json(pv));
    int rc = phc_json_file_write(root, path, err);
    json_decref(root);
    return rc;
}

/* The light grid, when the plant needs one (grow.h). */
void phc_grow_light_grid(const phc_grow_config *cfg, const phc_support_mesh *m, phc_climbing_options *o)
{
    if (!(o->light.extinction > 0 || cfg->light_grid_given || (m && cfg->shadows)))
        return;
    double lo[3], hi[3];
    if (cfg->light_grid_given) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = o->light.origin[k];
            hi[k] = lo[k] + cfg->light_size[k];
        }
    } else {
        if (m) {
            phc_support_mesh_bounds(m, lo, hi);
        } else {
            for (int k = 0; k < 3; ++k) {
                lo[k] = cfg->position[k] - 0.5;
                hi[k] = cfg->position[k] + 0.5;
            }
            lo[2] = cfg->position[2];
            hi[2] = cfg->position[2] + 1;
        }
        for (int k = 0; k < 3; ++k) {
            lo[k] = fmin(lo[k], cfg->position[k]) - 0.25;
            hi[k] = fmax(hi[k], cfg->position[k]) + 0.25;
        }
    }
    for (int k = 0; k < 3; ++k) {
        o->light.origin[k] = lo[k];
        const double cells = ceil((hi[k] - lo[k]) / o->light.cell);
        o->light.dims[k] = cells < 1 ? 1 : cells > 4096 ? 4096 : (size_t)cells;
    }
}

int phc_grow_write(const phc_grow_config *cfg, phc_provenance *pv, const char *dir, int force,
                   phc_grow_summary *summary, phc_error *err)
{
    phc_support_mesh *mesh = NULL;
    phc_climbing *plant = NULL;
    json_t *frames = NULL;
    FILE *csv = NULL;
    char tmpdir[4096] = "", path[4200];
    int rc = PHC_OK;
    phc_grow_inputs in;
    phc_grow_summary s;
    memset(&s, 0, sizeof s);
    const size_t steps = (size_t)llround(cfg->duration / cfg->time_step);
    const size_t per_frame = (size_t)fmax(1, llround(cfg->frame_interval / cfg->time_step));
    if (cfg->support) {
        phc_error e;
        phc_error_clear(&e);
        if (!(mesh = phc_support_mesh_read(cfg->support, &e)))
            return phc_error_set(err, e.status == PHC_ERR_NOMEM ? PHC_ERR_NOMEM : PHC_ERR_INPUT, "%s:%zu: support: %s",
                                 cfg->source, cfg->support_line, e.message);
    }
    phc_climbing_options o = cfg->options;
    phc_grow_light_grid(cfg, mesh, &o);
    if (mesh) {
        o.closest = phc_support_mesh_closest;
        o.closest_user = mesh;
        o.closest_segment = phc_support_mesh_segment_deepest;
    }
    {
        phc_error e;
        phc_error_clear(&e);
        if (!(plant = phc_climbing_new(cfg->position, cfg->direction, &o, &e))) {
            rc = phc_error_set(err, e.status == PHC_ERR_NOMEM ? PHC_ERR_NOMEM : PHC_ERR_INPUT, "%s:%zu: plant.position: %s",
                               cfg->source, cfg->position_line, e.message);
            goto done;
        }
    }
    if (mesh && cfg->shadows) { /* the support blocks the direct light */
        double *v = NULL;
        size_t *t = NULL, nv = 0, nt = 0;
        phc_error e;
        phc_error_clear(&e);
        int src = phc_support_mesh_arrays(mesh, &v, &nv, &t, &nt, &e);
        if (!src)
            src = phc_climbing_set_shadow_triangles(plant, v, nv, t, nt, &e);
        free(v);
        free(t);
        if (src) {
            rc = phc_error_set(err, e.status == PHC_ERR_NOMEM ? PHC_ERR_NOMEM : PHC_ERR_INPUT,
                               "%s:%zu: support: %s", cfg->source, cfg->support_line, e.message);
            goto done;
        }
    }
    phc_grow_inputs_init(&in, cfg);
    if ((rc = phc_run_dir_begin(dir, force, &in.pb, tmpdir, sizeof tmpdir, err))) {
        tmpdir[0] = '\0';
        goto done;
    }
    if (mesh) {
        snprintf(path, sizeof path, "%s/support.vtk", tmpdir);
        if ((rc = write_support_vtk(mesh, path, err)))
            goto done;
    }
    snprintf(path, sizeof path, "%s/growth.csv", tmpdir);
    if (!(csv = fopen(path, "w")) || !(frames = json_array())) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
        goto done;
    }
    fprintf(csv, "time_s,particles,growing_tips,laterals,anchored,attached_fraction,height_m,total_length_m,frame\n");
    for (size_t k = 0;; ++k) {
        if (k % per_frame == 0 || k == steps) {
            char file[64];
            snprintf(file, sizeof file, "frame_%04zu.vtk", s.frames);
            snprintf(path, sizeof path, "%s/%s", tmpdir, file);
            phc_grow_summarise(plant, cfg->position, &s);
            if ((rc = write_frame(plant, path, s.time, err)))
                goto done;
            if (o.leaf_step > 0) {
                char lfile[64];
                snprintf(lfile, sizeof lfile, "leaves_%04zu.vtk", s.frames);
                snprintf(path, sizeof path, "%s/%s", tmpdir, lfile);
                if ((rc = write_leaves_vtk(plant, o.light.direction, path, s.time, err)))
                    goto done;
            }
            json_array_append_new(frames, json_pack("{s:f, s:s, s:I}", "time_s", s.time, "file", file, "particles",
                                                    (json_int_t)s.particles));
            fprintf(csv, "%.10g,%zu,%zu,%zu,%zu,%.10g,%.10g,%.10g,%s\n", s.time, s.particles, s.apical, s.laterals,
                    s.anchored, s.attached_fraction, s.height, s.total_length, file);
            s.frames++;
        }
        if (k == steps)
            break;
        phc_error e;
        phc_error_clear(&e);
        if (phc_climbing_step(plant, cfg->time_step, &e)) {
            rc = phc_error_set(err, e.status == PHC_ERR_NOMEM ? PHC_ERR_NOMEM : PHC_ERR_DOMAIN,
                               "%s: growth step at t = %g s failed: %s", cfg->source,
                               (double)k * cfg->time_step, e.message);
            goto done;
        }
    }
    if (fclose(csv) != 0) {
        csv = NULL;
        rc = phc_error_set(err, PHC_ERR_IO, "%s/growth.csv: cannot write", tmpdir);
        goto done;
    }
    csv = NULL;
    phc_grow_summarise(plant, cfg->position, &s);
    if ((rc = write_views(plant, mesh, tmpdir, cfg->name, err)))
        goto done;
    snprintf(path, sizeof path, "%s/plant.obj", tmpdir);
    if ((rc = phc_grow_write_obj(plant, mesh, 8, path, NULL, err)))
        goto done;
    if (pv)
        phc_provenance_end(pv);
    if ((rc = write_result(cfg, &s, pv, frames, tmpdir, err)))
        goto done;
    if (summary)
        *summary = s;
    rc = phc_run_dir_commit(tmpdir, dir, pv, err);
    tmpdir[0] = '\0';
done:
    if (csv)
        fclose(csv);
    if (rc && tmpdir[0])
        phc_run_dir_discard(tmpdir);
    json_decref(frames);
    phc_climbing_free(plant);
    phc_support_mesh_free(mesh);
    return rc;
}
