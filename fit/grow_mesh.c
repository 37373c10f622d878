/* The climbing plant as an OBJ mesh: see grow_mesh.h. */
#include "fit/grow_mesh.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model/climbing_leaves.h"

int phc_grow_write_obj(const phc_climbing *c, const phc_support_mesh *support, unsigned sides,
                       const char *path, phc_grow_obj_counts *counts, phc_error *err)
{
    if (sides < 3 || sides > 64)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: tube sides = %u is outside [3, 64]", path,
                             sides);
    FILE *f = fopen(path, "w");
    if (!f)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
    phc_grow_obj_counts k;
    memset(&k, 0, sizeof k);
    const double two_pi = 6.28318530717958647692;
    const size_t n = phc_climbing_count(c);
    fprintf(f, "# phytocal: climbing plant (stems as tubes, leaves as squares, the support), m\n");
    fprintf(f, "o stems\n");
    for (size_t i = 0; i < n; ++i) {
        double b[3], t[3], d[3], e1[3], e2[3];
        phc_climbing_segment(c, i, b, t);
        phc_climbing_direction(c, i, d);
        phc_climbing_leaf_frame(d, e1, e2);
        const double r = phc_climbing_radius(c, i);
        for (int end = 0; end < 2; ++end)
            for (unsigned s = 0; s < sides; ++s) {
                const double a = two_pi * s / sides, ca = cos(a), sa = sin(a);
                const double *p = end ? t : b;
                fprintf(f, "v %.17g %.17g %.17g\n", p[0] + r * (ca * e1[0] + sa * e2[0]),
                        p[1] + r * (ca * e1[1] + sa * e2[1]), p[2] + r * (ca * e1[2] + sa * e2[2]));
            }
        /* OBJ indices start at 1 */
        const size_t v0 = k.vertices + 1;
        for (unsigned s = 0; s < sides; ++s) {
            const size_t a = v0 + s, bb = v0 + (s + 1) % sides, ta = a + sides, tb = bb + sides;
            fprintf(f, "f %zu %zu %zu\nf %zu %zu %zu\n", a, bb, tb, a, tb, ta);
        }
        k.vertices += 2 * sides;
        k.stem_triangles += 2 * sides;
    }
    fprintf(f, "o leaves\n");
    for (size_t i = 0; i < n; ++i) {
        double q[12];
        if (!phc_climbing_leaf_quad(c, i, q))
            continue;
        for (int j = 0; j < 4; ++j)
            fprintf(f, "v %.17g %.17g %.17g\n", q[3 * j], q[3 * j + 1], q[3 * j + 2]);
        const size_t v0 = k.vertices + 1;
        fprintf(f, "f %zu %zu %zu\nf %zu %zu %zu\n", v0, v0 + 1, v0 + 2, v0, v0 + 2, v0 + 3);
        k.vertices += 4;
        k.leaf_triangles += 2;
    }
    if (support) {
        fprintf(f, "o support\n");
        const size_t nv = phc_support_mesh_vertex_count(support);
        const size_t nt = phc_support_mesh_triangle_count(support);
        for (size_t i = 0; i < nv; ++i) {
            double v[3];
            phc_support_mesh_vertex(support, i, v);
            fprintf(f, "v %.17g %.17g %.17g\n", v[0], v[1], v[2]);
        }
        const size_t v0 = k.vertices + 1;
        for (size_t t = 0; t < nt; ++t) {
            size_t idx[3];
            phc_support_mesh_triangle(support, t, idx);
            fprintf(f, "f %zu %zu %zu\n", v0 + idx[0], v0 + idx[1], v0 + idx[2]);
        }
        k.vertices += nv;
        k.support_triangles = nt;
    }
    k.triangles = k.stem_triangles + k.leaf_triangles + k.support_triangles;
    const int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot write", path);
    if (counts)
        *counts = k;
    return PHC_OK;
}
