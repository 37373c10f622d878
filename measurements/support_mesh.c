/* measurements/support_mesh.h in libphytocal: forwards to the support-mesh
 * module phytocal_mesh.so (assimp + CGAL, measurements/support_mesh_bridge.cc),
 * opened by the first phc_support_mesh_read or _from_arrays call
 * (measurements/module_internal.h).  A mesh exists only once the module is
 * loaded, so the functions that take one use the loaded table. */
#include "measurements/support_mesh.h"

#include <stdlib.h>

#include "measurements/module_internal.h"
#include "measurements/support_mesh_module_internal.h"

static phc_module mesh_module = {PHC_MESH_MODULE_FILE, PHC_MESH_MODULE_ENTRY, PHC_MESH_MODULE_ABI,
                                 "support meshes (assimp, CGAL)", NULL, 0};

static const phc_mesh_module_table *loaded(void)
{
    return phc_module_loaded(&mesh_module);
}

phc_support_mesh *phc_support_mesh_read(const char *path, phc_error *err)
{
    const phc_mesh_module_table *t = phc_module_table(&mesh_module, err);
    return t ? t->read(path, err) : NULL;
}

phc_support_mesh *phc_support_mesh_from_arrays(const double *vertices, size_t nv, const size_t *triangles,
                                               size_t nt, const char *where, phc_error *err)
{
    const phc_mesh_module_table *t = phc_module_table(&mesh_module, err);
    return t ? t->from_arrays(vertices, nv, triangles, nt, where, err) : NULL;
}

void phc_support_mesh_free(phc_support_mesh *m)
{
    if (m)
        loaded()->free_mesh(m);
}

size_t phc_support_mesh_triangle_count(const phc_support_mesh *m)
{
    return m ? loaded()->triangle_count(m) : 0;
}

size_t phc_support_mesh_vertex_count(const phc_support_mesh *m)
{
    return m ? loaded()->vertex_count(m) : 0;
}

void phc_support_mesh_bounds(const phc_support_mesh *m, double lo[3], double hi[3])
{
    loaded()->bounds(m, lo, hi);
}

void phc_support_mesh_vertex(const phc_support_mesh *m, size_t i, double v[3])
{
    loaded()->vertex(m, i, v);
}

void phc_support_mesh_triangle(const phc_support_mesh *m, size_t t, size_t idx[3])
{
    loaded()->triangle(m, t, idx);
}

int phc_support_mesh_closest(void *mesh, const double x[3], double c[3], double n[3])
{
    return mesh ? loaded()->closest(mesh, x, c, n) : -1;
}

int phc_support_mesh_segment_deepest(void *mesh, const double a[3], const double b[3], double reach, double *t,
                                     double *depth)
{
    return mesh ? loaded()->segment_deepest(mesh, a, b, reach, t, depth) : -1;
}

void phc_support_mesh_certificates(phc_support_mesh *m, int on)
{
    if (m)
        loaded()->certificates(m, on);
}

size_t phc_support_mesh_tree_queries(const phc_support_mesh *m)
{
    return m ? loaded()->tree_queries(m) : 0;
}

int phc_support_mesh_arrays(const phc_support_mesh *m, double **vertices, size_t *nv, size_t **triangles,
                            size_t *nt, phc_error *err)
{
    const size_t v = phc_support_mesh_vertex_count(m), t = phc_support_mesh_triangle_count(m);
    double *vs = malloc((v ? 3 * v : 1) * sizeof *vs);
    size_t *ts = malloc((t ? 3 * t : 1) * sizeof *ts);
    if (!vs || !ts) {
        free(vs);
        free(ts);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; i < v; ++i)
        phc_support_mesh_vertex(m, i, vs + 3 * i);
    for (size_t i = 0; i < t; ++i)
        phc_support_mesh_triangle(m, i, ts + 3 * i);
    *vertices = vs;
    *nv = v;
    *triangles = ts;
    *nt = t;
    return PHC_OK;
}
