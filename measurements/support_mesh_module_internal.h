/* measurements/support_mesh_module_internal.h: the table of the support-mesh
 * module, phytocal_mesh.so (assimp + CGAL, measurements/support_mesh_bridge.cc;
 * see module_internal.h).  libphytocal's support_mesh.h functions forward to
 * it (measurements/support_mesh.c).  C and C++; internal. */
#ifndef PHC_SUPPORT_MESH_MODULE_INTERNAL_H
#define PHC_SUPPORT_MESH_MODULE_INTERNAL_H

#include "measurements/support_mesh.h"

/* Bumped whenever a member below changes. */
#define PHC_MESH_MODULE_ABI 3
#define PHC_MESH_MODULE_ENTRY "phc_mesh_module_entry"
#define PHC_MESH_MODULE_FILE "phytocal_mesh.so"

/* One member per support_mesh.h function, same signature. */
typedef struct phc_mesh_module_table {
    phc_support_mesh *(*read)(const char *path, phc_error *err);
    phc_support_mesh *(*from_arrays)(const double *vertices, size_t nv, const size_t *triangles, size_t nt,
                                     const char *where, phc_error *err);
    void (*free_mesh)(phc_support_mesh *m);
    size_t (*triangle_count)(const phc_support_mesh *m);
    size_t (*vertex_count)(const phc_support_mesh *m);
    void (*bounds)(const phc_support_mesh *m, double lo[3], double hi[3]);
    void (*vertex)(const phc_support_mesh *m, size_t i, double v[3]);
    void (*triangle)(const phc_support_mesh *m, size_t t, size_t idx[3]);
    int (*closest)(void *mesh, const double x[3], double c[3], double n[3]);
    void (*certificates)(phc_support_mesh *m, int on);
    size_t (*tree_queries)(const phc_support_mesh *m);
    int (*segment_deepest)(void *mesh, const double a[3], const double b[3], double reach, double *t, double *depth);
} phc_mesh_module_table;

#endif
