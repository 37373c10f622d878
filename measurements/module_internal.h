/* measurements/module_internal.h: optional modules, opened on first use.
 *
 * The heavy third-party libraries (OpenCV for photos, assimp + CGAL for
 * support meshes, NetCDF/HDF5 for gridded output) are not linked into
 * libphytocal: each sits in a module, phytocal_<name>.so, built beside the
 * library (build tree and install tree alike) and opened with dlopen
 * (RTLD_NOW | RTLD_LOCAL) the first time a function that needs it is called.
 * A run that never touches photos, meshes or NetCDF never loads them: the
 * command starts in a few milliseconds instead of loading ~175 libraries.
 *
 * A module exports one function, ENTRY(abi), returning a const table of
 * function pointers (one struct per module, measurements/<name>_module.h);
 * libphytocal's public functions forward to it.  Internal: not installed.
 *
 * The same loader suits any module of phytocal (the MPI one, for example,
 * with `global` set).  The folder is the one libphytocal.so was loaded from (dladdr), or
 * $PHYTOCAL_MODULE_DIR when set (tests; relocated installs).  Loading is
 * thread-safe; a failed load is retried at the next call. */
#ifndef PHC_MODULE_INTERNAL_H
#define PHC_MODULE_INTERNAL_H

#include <stdatomic.h>

#include "model/status.h"

typedef struct phc_module {
    const char *file;                 /* "phytocal_photo.so" */
    const char *entry;                /* "phc_photo_module_entry" */
    int abi;                          /* the table's version, checked by the entry */
    const char *what;                 /* "photos (OpenCV)": for the error message */
    _Atomic(const void *) table;      /* set once loaded */
    int global;                       /* 1: RTLD_GLOBAL instead of RTLD_LOCAL, for a module
                                         whose libraries dlopen components that need their
                                         symbols (Open MPI's) */
} phc_module;

/* The module's table (loading it on the first call), or NULL with err set:
 * PHC_ERR_IO "PATH: cannot load the photos (OpenCV) module: <dlerror>". */
const void *phc_module_table(phc_module *m, phc_error *err);

/* The table of a module already loaded (NULL if not): for functions whose
 * argument exists only once the module is loaded (a mesh), so no error. */
static inline const void *phc_module_loaded(phc_module *m)
{
    return atomic_load_explicit(&m->table, memory_order_acquire);
}

#endif
