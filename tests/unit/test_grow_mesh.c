/* Unit test of the climbing plant's mesh file (fit/grow_mesh.h) and the
 * grow config's keys for leaves, secondary growth and shadows
 * (fit/grow_config.h).  Every checked number is printed.
 *  1. A vine with leaves grown on a wall (phc_support_mesh_from_arrays) is
 *     written as OBJ and read back with assimp (phc_support_mesh_read, the
 *     support-mesh reader): its triangle count is the stems' 2·sides per
 *     segment + 2 per leaf + the wall's, it holds three vertices per
 *     triangle (assimp's OBJ importer does not share them) and the bounding
 *     box written (to 1e-7 m: assimp holds single-precision floats), and
 *     every tube vertex lies at its segment's radius from the axis.
 *     Every blade centre of the vine lies in front of the wall.
 *  2. A grow config with leaves:, cambium: and light.ambient /
 *     supports_cast_shadows is read into the options; `phytocal help grow`'s
 *     table lists the keys. */
#include "fit/grow_config.h"
#include "fit/grow_mesh.h"
#include "measurements/support_mesh.h"
#include "model/climbing_growth.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"

int main(void)
{
    phc_error err;
    char dir[] = "/tmp/phc_test_grow_mesh_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256];

    /* 1. OBJ round trip */
    {
        const double wv[12] = {-0.5, 0, 0, 0.5, 0, 0, 0.5, 0, 1, -0.5, 0, 1};
        const size_t wt[6] = {0, 2, 1, 0, 3, 2}; /* normals toward +y */
        phc_support_mesh *wall = phc_support_mesh_from_arrays(wv, 4, wt, 2, "wall", &err);
        CHECK(wall != NULL);
        phc_climbing_options o = phc_climbing_options_default();
        o.closest = phc_support_mesh_closest;
        o.closest_user = wall;
        o.surface_adaption = 0.5;
        o.branch_probability = 0.3;
        o.leaf_step = 1;
        o.cambium_rate = 0.1;
        o.light.direction[1] = 1;
        const double seed[3] = {0, 0.01, 0}, up[3] = {0, 0, 1};
        phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
        CHECK(c != NULL);
        if (!c) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        for (int k = 0; c && k < 200; ++k)
            phc_climbing_step(c, 0.5, &err);
        /* blades of a vine on a wall stay in front of it (petioles mirrored) */
        double min_leaf_y = INFINITY, min_stem_y = INFINITY;
        for (size_t i = 0; i < phc_climbing_count(c); ++i) {
            double ctr[3], x[3];
            phc_climbing_position(c, i, x);
            min_stem_y = fmin(min_stem_y, x[1]);
            if (phc_climbing_leaf(c, i, ctr, NULL, NULL))
                min_leaf_y = fmin(min_leaf_y, ctr[1]);
        }
        printf("obj: vine on the wall y = 0: smallest y of a blade centre %.3g m, of a particle centre "
               "%.3g m\n",
               min_leaf_y, min_stem_y);
        CHECK(min_leaf_y >= 0);
        snprintf(path, sizeof path, "%s/plant.obj", dir);
        phc_grow_obj_counts k;
        memset(&k, 0, sizeof k);
        const unsigned sides = 6;
        CHECK(phc_grow_write_obj(c, wall, sides, path, &k, &err) == PHC_OK);
        const size_t n = phc_climbing_count(c), nl = phc_climbing_leaf_count(c);
        /* the box of what was written */
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        FILE *f = fopen(path, "r");
        char line[256];
        size_t verts = 0;
        double worst_r = 0;
        while (f && fgets(line, sizeof line, f)) {
            double v[3];
            if (sscanf(line, "v %lf %lf %lf", &v[0], &v[1], &v[2]) != 3)
                continue;
            for (int j = 0; j < 3; ++j) {
                lo[j] = fmin(lo[j], v[j]);
                hi[j] = fmax(hi[j], v[j]);
            }
            if (verts < 2 * sides * n) { /* a tube vertex: distance to its axis */
                const size_t i = verts / (2 * sides);
                double b[3], t[3], d[3];
                phc_climbing_segment(c, i, b, t);
                phc_climbing_direction(c, i, d);
                const double *p = (verts % (2 * sides)) < sides ? b : t;
                double r[3] = {v[0] - p[0], v[1] - p[1], v[2] - p[2]};
                const double along = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
                for (int j = 0; j < 3; ++j)
                    r[j] -= along * d[j];
                worst_r = fmax(worst_r, fabs(sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) -
                                             phc_climbing_radius(c, i)) +
                                            fabs(along));
            }
            ++verts;
        }
        if (f)
            fclose(f);
        phc_support_mesh *back = phc_support_mesh_read(path, &err);
        CHECK(back != NULL);
        if (back) {
            double blo[3], bhi[3];
            phc_support_mesh_bounds(back, blo, bhi);
            double box = 0;
            for (int j = 0; j < 3; ++j)
                box = fmax(box, fmax(fabs(blo[j] - lo[j]), fabs(bhi[j] - hi[j])));
            const size_t expect = 2 * sides * n + 2 * nl + 2;
            printf("obj: %zu segments, %zu leaves, wall 2 triangles: wrote %zu triangles (expected "
                   "%zu), %zu vertices; assimp read back %zu triangles, %zu vertices; box differs "
                   "by %.3g m; tube vertices off their radius by at most %.3g m\n",
                   n, nl, k.triangles, expect, k.vertices, phc_support_mesh_triangle_count(back),
                   phc_support_mesh_vertex_count(back), box, worst_r);
            CHECK(n > 20 && nl > 10);
            CHECK(k.triangles == expect && k.leaf_triangles == 2 * nl && k.support_triangles == 2);
            CHECK(phc_support_mesh_triangle_count(back) == expect);
            /* assimp's OBJ importer gives every face its own three vertices
               and holds coordinates as single-precision floats (ai_real) */
            CHECK(phc_support_mesh_vertex_count(back) == 3 * expect && verts == k.vertices);
            CHECK(box <= 1e-7);
            CHECK(worst_r < 1e-15);
        }
        CHECK(phc_grow_write_obj(c, wall, 2, path, NULL, &err) == PHC_ERR_INVALID);
        CHECK_STR_CONTAINS(err.message, "tube sides = 2");
        CHECK(phc_grow_write_obj(c, NULL, 6, "/nonexistent-dir/plant.obj", NULL, &err) == PHC_ERR_IO);
        printf("obj: errors: %s\n", err.message);
        phc_support_mesh_free(back);
        phc_climbing_free(c);
        phc_support_mesh_free(wall);
        unlink(path);
    }

    /* 2. the config's new keys */
    {
        snprintf(path, sizeof path, "%s/leafy.yaml", dir);
        FILE *f = fopen(path, "w");
        fprintf(f, "plant:\n  position: [0, 0.01, 0]\nlight:\n  ambient: 0.2\n"
                   "  supports_cast_shadows: false\nleaves:\n  step: 2\n  angle: 120\n  size: 0.04\n"
                   "  thickness: 0.0005\n  response: 0.7\n  max_angle: 60\ncambium:\n  rate: 0.05\n"
                   "  leaf_area: 1e-6\ndynamics:\n  collide: true\n  collide_ends: true\n  supports_closed: true\n");
        fclose(f);
        phc_grow_config *cfg = NULL;
        CHECK(phc_grow_config_load(path, &cfg, &err) == PHC_OK);
        if (cfg) {
            const phc_climbing_options *o = &cfg->options;
            printf("config: ambient %g, shadows %d, leaves step %u angle %g size %g thickness %g "
                   "response %g max_angle %g, cambium rate %g leaf_area %g\n",
                   o->light.ambient, cfg->shadows, o->leaf_step, o->leaf_angle_deg, o->leaf_size,
                   o->leaf_thickness, o->leaf_response, o->leaf_max_angle_deg, o->cambium_rate,
                   o->leaf_pipe_area);
            CHECK(o->light.ambient == 0.2 && cfg->shadows == 0 && o->leaf_step == 2);
            CHECK(o->leaf_angle_deg == 120 && o->leaf_size == 0.04 && o->leaf_thickness == 0.0005);
            CHECK(o->leaf_response == 0.7 && o->leaf_max_angle_deg == 60);
            CHECK(o->cambium_rate == 0.05 && o->leaf_pipe_area == 1e-6);
            printf("config: dynamics.collide %d, collide_ends %d, supports_closed %d\n", o->collide, o->collide_ends,
                   o->supports_closed);
            CHECK(o->collide == 1 && o->collide_ends == 1 && o->supports_closed == 1);
        }
        phc_grow_config_free(cfg);
        /* defaults: shadows on, no leaves, no secondary growth */
        f = fopen(path, "w");
        fprintf(f, "plant:\n  position: [0, 0.01, 0]\n");
        fclose(f);
        CHECK(phc_grow_config_load(path, &cfg, &err) == PHC_OK);
        if (cfg) {
            printf("config defaults: shadows %d, leaves step %u, cambium rate %g, collide %d\n", cfg->shadows,
                   cfg->options.leaf_step, cfg->options.cambium_rate, cfg->options.collide);
            CHECK(cfg->shadows == 1 && cfg->options.leaf_step == 0 && cfg->options.cambium_rate == 0);
            CHECK(cfg->options.collide == 0 && cfg->options.collide_ends == 0 && cfg->options.supports_closed == 0);
        }
        phc_grow_config_free(cfg);
        unlink(path);
        char *buf = NULL;
        size_t len = 0;
        FILE *h = open_memstream(&buf, &len);
        phc_grow_config_help(h);
        fclose(h);
        CHECK_STR_CONTAINS(buf, "leaves.angle");
        CHECK_STR_CONTAINS(buf, "cambium.rate");
        CHECK_STR_CONTAINS(buf, "light.supports_cast_shadows");
        CHECK_STR_CONTAINS(buf, "dynamics.collide");
        CHECK_STR_CONTAINS(buf, "true or false, default true");
        free(buf);
    }
    rmdir(dir);
    return check_finish("test_grow_mesh");
}
