/* Unit test of the support meshes (measurements/support_mesh.h: assimp
 * reads, CGAL's AABB tree answers closest-point queries).
 *  1. A plane (two triangles of a square, z = 0): the closest point of any
 *     point above the square's inside is its foot (x, y, 0), normal (0,0,1),
 *     to 1e-12; beyond an edge, the edge's nearest point.
 *  2. A sphere mesh (octahedron subdivided 3 times, vertices on the unit
 *     sphere): a point 2·v on a vertex's ray has the vertex as its closest
 *     point (the sphere is convex: the vertex is nearest), and a point a
 *     height h above a face's centroid along its normal has the centroid;
 *     both to 1e-12.
 *  3. Files: an OBJ square and an ASCII PLY tetrahedron read with the right
 *     triangle counts; a file that is not a mesh, an OBJ with vertices but
 *     no faces and a missing file are refused with the file named.
 *  4. Certified answers (phc_support_mesh_certificates): points that walk
 *     near Fig. 13's wall (measurements/examples/climbing/wall_window.obj)
 *     and near the sphere of 2., in steps from 1 nm to 5 mm (some
 *     repeated, some on the bisector of a convex edge, where two triangles
 *     tie), asked of one mesh with certificates and of a copy without:
 *     the same closest point and normal bit for bit at every point, and
 *     most answers certified (the tree answers fewer than half).
 *  5. The closed wall (wall_window_closed.obj, for the climbing option
 *     supports_closed): at random points around it the side of the
 *     closest face, (x − c)·n < 0, says inside exactly where the solid's
 *     own description (the slab minus the window's recess, plus the
 *     ledge) does; and before its face (y > 0 off the ledge) its closest
 *     points are those of the open wall_window.obj. */
#include "measurements/support_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(1);
    }
    fputs(text, f);
    fclose(f);
}

static void normalize(double v[3])
{
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k)
        v[k] /= l;
}

/* Octahedron subdivided `levels` times, vertices pushed onto the unit
 * sphere; arrays malloc'ed. */
static void sphere(int levels, double **V, size_t *nv, size_t **F, size_t *nf)
{
    size_t cv = 6, cf = 8;
    double *v = malloc(3 * 6 * sizeof *v);
    size_t *f = malloc(3 * 8 * sizeof *f);
    const double v0[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    const size_t f0[24] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    memcpy(v, v0, sizeof v0);
    memcpy(f, f0, sizeof f0);
    for (int l = 0; l < levels; ++l) {
        /* each triangle -> 4, midpoints duplicated (harmless for queries) */
        double *v2 = malloc(3 * (cv + 3 * cf) * sizeof *v2);
        size_t *f2 = malloc(3 * 4 * cf * sizeof *f2);
        memcpy(v2, v, 3 * cv * sizeof *v);
        size_t nv2 = cv;
        for (size_t t = 0; t < cf; ++t) {
            size_t m[3];
            for (int e = 0; e < 3; ++e) {
                const double *a = v + 3 * f[3 * t + e], *b = v + 3 * f[3 * t + (e + 1) % 3];
                double *p = v2 + 3 * nv2;
                for (int k = 0; k < 3; ++k)
                    p[k] = 0.5 * (a[k] + b[k]);
                normalize(p);
                m[e] = nv2++;
            }
            const size_t a = f[3 * t], b = f[3 * t + 1], c = f[3 * t + 2];
            const size_t quad[12] = {a, m[0], m[2], m[0], b, m[1], m[2], m[1], c, m[0], m[1], m[2]};
            memcpy(f2 + 12 * t, quad, sizeof quad);
        }
        free(v);
        free(f);
        v = v2;
        f = f2;
        cv = nv2;
        cf *= 4;
    }
    *V = v;
    *nv = cv;
    *F = f;
    *nf = cf;
}

int main(void)
{
    phc_error err;
    /* 1. plane */
    {
        const double V[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
        const size_t F[6] = {0, 1, 2, 0, 2, 3};
        phc_support_mesh *m = phc_support_mesh_from_arrays(V, 4, F, 2, "plane", &err);
        CHECK(m != NULL);
        CHECK(phc_support_mesh_triangle_count(m) == 2);
        double worst = 0;
        unsigned long long s = 12345;
        for (int q = 0; q < 1000; ++q) {
            double x[3];
            for (int k = 0; k < 3; ++k) {
                s = s * 6364136223846793005ULL + 1442695040888963407ULL;
                x[k] = ((double)(s >> 11) * 0x1.0p-53) * 1.8 - 0.9;
            }
            double c[3], n[3];
            CHECK(phc_support_mesh_closest(m, x, c, n) == 0);
            worst = fmax(worst, fmax(fabs(c[0] - x[0]), fmax(fabs(c[1] - x[1]), fabs(c[2]))));
            CHECK_NEAR(n[2], 1.0, 1e-15, 0);
        }
        printf("plane: max |c - (x, y, 0)| over 1000 points = %.3g m\n", worst);
        CHECK(worst <= 1e-12);
        /* beyond the edge x = 1: nearest point on the edge */
        const double x[3] = {3, 0.25, 2};
        double c[3], n[3];
        phc_support_mesh_closest(m, x, c, n);
        CHECK_NEAR(c[0], 1, 1e-12, 0);
        CHECK_NEAR(c[1], 0.25, 1e-12, 0);
        CHECK_NEAR(c[2], 0, 1e-12, 0);
        const double bad[3] = {NAN, 0, 0};
        CHECK(phc_support_mesh_closest(m, bad, c, n) == -1);
        phc_support_mesh_free(m);
        /* bad arrays */
        const size_t Fbad[3] = {0, 1, 7};
        CHECK(phc_support_mesh_from_arrays(V, 4, Fbad, 1, "plane", &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "plane: triangle 0: vertex index 7 out of range");
        CHECK(phc_support_mesh_from_arrays(V, 4, F, 0, "plane", &err) == NULL);
        CHECK_STR_CONTAINS(err.message, "plane: no triangles");
    }
    /* 2. sphere */
    {
        double *V;
        size_t *F, nv, nf;
        sphere(3, &V, &nv, &F, &nf);
        phc_support_mesh *m = phc_support_mesh_from_arrays(V, nv, F, nf, "sphere", &err);
        CHECK(m != NULL);
        double worst_v = 0, worst_f = 0;
        for (size_t i = 0; i < nv; i += 7) {
            const double x[3] = {2 * V[3 * i], 2 * V[3 * i + 1], 2 * V[3 * i + 2]};
            double c[3], n[3];
            phc_support_mesh_closest(m, x, c, n);
            for (int k = 0; k < 3; ++k)
                worst_v = fmax(worst_v, fabs(c[k] - V[3 * i + k]));
        }
        for (size_t t = 0; t < nf; t += 5) {
            const double *a = V + 3 * F[3 * t], *b = V + 3 * F[3 * t + 1], *cc = V + 3 * F[3 * t + 2];
            double g[3], u[3], w[3], nn[3];
            for (int k = 0; k < 3; ++k) {
                g[k] = (a[k] + b[k] + cc[k]) / 3;
                u[k] = b[k] - a[k];
                w[k] = cc[k] - a[k];
            }
            nn[0] = u[1] * w[2] - u[2] * w[1];
            nn[1] = u[2] * w[0] - u[0] * w[2];
            nn[2] = u[0] * w[1] - u[1] * w[0];
            normalize(nn);
            if (nn[0] * g[0] + nn[1] * g[1] + nn[2] * g[2] < 0)
                for (int k = 0; k < 3; ++k)
                    nn[k] = -nn[k];
            const double x[3] = {g[0] + 0.01 * nn[0], g[1] + 0.01 * nn[1], g[2] + 0.01 * nn[2]};
            double c[3], n[3];
            phc_support_mesh_closest(m, x, c, n);
            for (int k = 0; k < 3; ++k)
                worst_f = fmax(worst_f, fabs(c[k] - g[k]));
        }
        printf("sphere (%zu triangles): max error at vertices %.3g m, at face centroids %.3g m\n",
               nf, worst_v, worst_f);
        CHECK(worst_v <= 1e-12);
        CHECK(worst_f <= 1e-12);
        phc_support_mesh_free(m);
        free(V);
        free(F);
    }
    /* 3. files */
    {
        const char *obj = PHC_BINARY_DIR "/test_support_square.obj";
        write_file(obj, "# a unit square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
        phc_support_mesh *m = phc_support_mesh_read(obj, &err);
        CHECK(m != NULL);
        CHECK(phc_support_mesh_triangle_count(m) == 2);
        if (m) {
            const double x[3] = {0.3, 0.6, 0.5};
            double c[3], n[3];
            phc_support_mesh_closest(m, x, c, n);
            CHECK_NEAR(c[0], 0.3, 1e-12, 0);
            CHECK_NEAR(c[1], 0.6, 1e-12, 0);
            CHECK_NEAR(c[2], 0, 1e-12, 0);
        }
        phc_support_mesh_free(m);
        const char *ply = PHC_BINARY_DIR "/test_support_tetra.ply";
        write_file(ply, "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                        "property float y\nproperty float z\nelement face 4\n"
                        "property list uchar int vertex_indices\nend_header\n"
                        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
        m = phc_support_mesh_read(ply, &err);
        CHECK(m != NULL);
        CHECK(phc_support_mesh_triangle_count(m) == 4);
        phc_support_mesh_free(m);
        const char *junk = PHC_BINARY_DIR "/test_support_junk.ply";
        write_file(junk, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n"
                         "zero one two\n");
        CHECK(phc_support_mesh_read(junk, &err) == NULL);
        printf("junk PLY: %s\n", err.message);
        CHECK_STR_CONTAINS(err.message, junk);
        CHECK(err.status == PHC_ERR_INPUT);
        const char *pts = PHC_BINARY_DIR "/test_support_points.obj";
        write_file(pts, "v 0 0 0\nv 1 0 0\nv 1 1 0\n");
        CHECK(phc_support_mesh_read(pts, &err) == NULL);
        printf("points only: %s\n", err.message);
        CHECK_STR_CONTAINS(err.message, pts);
        CHECK_STR_CONTAINS(err.message, "no triangles");
        CHECK(phc_support_mesh_read(PHC_BINARY_DIR "/no_such_mesh.obj", &err) == NULL);
        CHECK(err.status == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "no_such_mesh.obj: cannot open");
        remove(obj);
        remove(ply);
        remove(junk);
        remove(pts);
    }
    /* 4. certified answers against the tree's */
    {
        phc_support_mesh *m[2][2] = {{NULL, NULL}, {NULL, NULL}};
        for (int j = 0; j < 2; ++j)
            m[0][j] = phc_support_mesh_read(PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window.obj", &err);
        double *V;
        size_t *F, nv, nf;
        sphere(3, &V, &nv, &F, &nf);
        for (int j = 0; j < 2; ++j)
            m[1][j] = phc_support_mesh_from_arrays(V, nv, F, nf, "sphere", &err);
        free(V);
        free(F);
        CHECK(m[0][0] && m[0][1] && m[1][0] && m[1][1]);
        const char *name[2] = {"wall with a window and a ledge", "sphere"};
        /* walks start here (m): before the wall's face, in the window's
           recess, under the ledge; just outside the sphere */
        const double start[2][3][3] = {{{-0.1, 0.004, 0.3}, {0.0, -0.02, 0.7}, {0.1, 0.01, 0.9}},
                                       {{1.003, 0, 0}, {0, 0.6, 0.803}, {-0.58, -0.58, 0.58}}};
        unsigned long long s = 2026;
        for (int w = 0; w < 2 && m[w][0] && m[w][1]; ++w) {
            phc_support_mesh_certificates(m[w][1], 0);
            const size_t before = phc_support_mesh_tree_queries(m[w][0]);
            size_t asked = 0, differ = 0;
            for (int walk = 0; walk < 3; ++walk) {
                double x[3] = {start[w][walk][0], start[w][walk][1], start[w][walk][2]};
                for (int q = 0; q < 20000; ++q) {
                    double u[4];
                    for (int k = 0; k < 4; ++k) {
                        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
                        u[k] = (double)(s >> 11) * 0x1.0p-53;
                    }
                    /* a step of 1 nm .. 5 mm (log-uniform), every 8th none */
                    const double step = q % 8 == 7 ? 0 : 1e-9 * pow(5e6, u[3]);
                    for (int k = 0; k < 3; ++k)
                        x[k] += step * (2 * u[k] - 1);
                    if (w == 0 && q % 16 == 3) { /* on the bisector of the reveal's convex edge x = -0.2, y = 0 */
                        x[0] = -0.2 + 0.5 * u[0] * 0.01;
                        x[1] = x[0] + 0.2;
                    }
                    double c[2][3], n[2][3];
                    const int r0 = phc_support_mesh_closest(m[w][0], x, c[0], n[0]);
                    const int r1 = phc_support_mesh_closest(m[w][1], x, c[1], n[1]);
                    ++asked;
                    differ += r0 != 0 || r1 != 0 || memcmp(c[0], c[1], sizeof c[0]) || memcmp(n[0], n[1], sizeof n[0]);
                    /* keep the walk near the surface: back onto its closest point plus 0..8 mm */
                    const double e[3] = {x[0] - c[0][0], x[1] - c[0][1], x[2] - c[0][2]};
                    const double d = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
                    if (d > 0.008)
                        for (int k = 0; k < 3; ++k)
                            x[k] = c[0][k] + 0.008 * u[k] * (e[k] / d);
                }
            }
            const size_t tree = phc_support_mesh_tree_queries(m[w][0]) - before;
            printf("certified answers, %s: %zu points asked, %zu answered by the tree, %zu by a certificate; "
                   "answers that differ from the tree's: %zu\n",
                   name[w], asked, tree, asked - tree, differ);
            CHECK(differ == 0);
            CHECK(2 * tree < asked);
            CHECK(phc_support_mesh_tree_queries(m[w][1]) == asked);
        }
        for (int w = 0; w < 2; ++w)
            for (int j = 0; j < 2; ++j)
                phc_support_mesh_free(m[w][j]);
    }
    /* 5. the closed wall: inside and outside by the closest face's side */
    {
        phc_support_mesh *closed =
            phc_support_mesh_read(PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window_closed.obj", &err);
        phc_support_mesh *open =
            phc_support_mesh_read(PHC_SOURCE_DIR "/measurements/examples/climbing/wall_window.obj", &err);
        CHECK(closed != NULL && open != NULL);
        size_t asked = 0, inside = 0, wrong = 0, front = 0, front_differ = 0;
        unsigned long long s = 13;
        for (int q = 0; closed && open && q < 20000; ++q) {
            double u[3], x[3], c[3], n[3];
            for (int k = 0; k < 3; ++k) {
                s = s * 6364136223846793005ULL + 1442695040888963407ULL;
                u[k] = (double)(s >> 11) * 0x1.0p-53;
            }
            x[0] = -0.7 + 1.4 * u[0];
            x[1] = -0.3 + 0.45 * u[1];
            x[2] = -0.1 + 1.4 * u[2];
            const int slab = x[0] > -0.6 && x[0] < 0.6 && x[1] > -0.2 && x[1] < 0 && x[2] > 0 && x[2] < 1.2;
            const int recess = x[0] > -0.2 && x[0] < 0.2 && x[1] > -0.04 && x[2] > 0.5 && x[2] < 0.9;
            const int ledge = x[0] > -0.3 && x[0] < 0.3 && x[1] >= 0 && x[1] < 0.08 && x[2] > 0.92 && x[2] < 0.96;
            const int in = (slab && !recess) || ledge;
            CHECK(phc_support_mesh_closest(closed, x, c, n) == 0);
            const int behind = (x[0] - c[0]) * n[0] + (x[1] - c[1]) * n[1] + (x[2] - c[2]) * n[2] < 0;
            ++asked;
            inside += (size_t)in;
            wrong += (size_t)(behind != in);
            if (x[1] > 0 && fabs(x[0]) < 0.6 && x[2] > 0 && x[2] < 1.2 && !(fabs(x[0]) < 0.3 && x[2] > 0.92 && x[2] < 0.96)) {
                double co[3], no[3];
                phc_support_mesh_closest(open, x, co, no);
                const double e[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]}, eo[3] = {x[0] - co[0], x[1] - co[1], x[2] - co[2]};
                ++front;
                front_differ += fabs(sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) -
                                     sqrt(eo[0] * eo[0] + eo[1] * eo[1] + eo[2] * eo[2])) > 1e-12;
            }
        }
        printf("closed wall (%zu triangles): %zu points, %zu inside the solid, %zu on the wrong side of their closest "
               "face; %zu before the face off the ledge, %zu whose distance differs from the open wall's\n",
               phc_support_mesh_triangle_count(closed), asked, inside, wrong, front, front_differ);
        CHECK(wrong == 0 && inside > 1000);
        CHECK(front > 1000 && front_differ == 0);
        phc_support_mesh_free(closed);
        phc_support_mesh_free(open);
    }
    return check_finish("test_support_mesh");
}
