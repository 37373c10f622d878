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
 *     no faces and a missing file are refused with the file named. */
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
    return check_finish("test_support_mesh");
}
