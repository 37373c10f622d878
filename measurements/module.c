/* Opening optional modules: see module_internal.h. */
#define _GNU_SOURCE /* dladdr */
#include "measurements/module_internal.h"

#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static pthread_mutex_t module_lock = PTHREAD_MUTEX_INITIALIZER;

/* PATH of FILE: in $PHYTOCAL_MODULE_DIR, else in the folder of the object
 * that holds this function (libphytocal.so). */
static int module_path(const phc_module *m, char *buf, size_t size, phc_error *err)
{
    const char *dir = getenv("PHYTOCAL_MODULE_DIR");
    int n;
    if (dir && *dir) {
        n = snprintf(buf, size, "%s/%s", dir, m->file);
    } else {
        Dl_info info;
        if (!dladdr((void *)&phc_module_table, &info) || !info.dli_fname || !*info.dli_fname)
            return phc_error_set(err, PHC_ERR_IO, "cannot find the folder of libphytocal (dladdr failed), so "
                                 "not the %s module %s either", m->what, m->file);
        const char *slash = strrchr(info.dli_fname, '/');
        n = slash ? snprintf(buf, size, "%.*s/%s", (int)(slash - info.dli_fname), info.dli_fname, m->file)
                  : snprintf(buf, size, "./%s", m->file);
    }
    if (n < 0 || (size_t)n >= size)
        return phc_error_set(err, PHC_ERR_IO, "%s: the path of the %s module is too long", m->file, m->what);
    return PHC_OK;
}

typedef const void *(*entry_fn)(int abi);

const void *phc_module_table(phc_module *m, phc_error *err)
{
    const void *t = phc_module_loaded(m);
    if (t)
        return t;
    pthread_mutex_lock(&module_lock);
    t = phc_module_loaded(m);
    if (t) {
        pthread_mutex_unlock(&module_lock);
        return t;
    }
    char path[4096];
    if (module_path(m, path, sizeof path, err)) {
        pthread_mutex_unlock(&module_lock);
        return NULL;
    }
    /* RTLD_LOCAL: the module's libraries (OpenCV, assimp, HDF5, their C++
       runtime pieces) stay out of the global scope, so they cannot bind a
       program's own copies of the same libraries (unless the module asks
       for RTLD_GLOBAL); RTLD_NOW: a missing symbol
       is reported here, not as a crash in the middle of a run. */
    void *h = dlopen(path, RTLD_NOW | (m->global ? RTLD_GLOBAL : RTLD_LOCAL));
    if (!h) {
        phc_error_set(err, PHC_ERR_IO, "%s: cannot load the %s module (installed beside libphytocal; "
                      "PHYTOCAL_MODULE_DIR overrides the folder): %s", path, m->what, dlerror());
        pthread_mutex_unlock(&module_lock);
        return NULL;
    }
    entry_fn entry;
    /* POSIX: the object pointer dlsym returns converts to a function pointer */
    *(void **)&entry = dlsym(h, m->entry);
    t = entry ? entry(m->abi) : NULL;
    if (!t) {
        if (entry)
            phc_error_set(err, PHC_ERR_IO, "%s: the %s module is another version (no table version %d): rebuild "
                          "or reinstall phytocal", path, m->what, m->abi);
        else
            phc_error_set(err, PHC_ERR_IO, "%s: not a phytocal %s module (no %s)", path, m->what, m->entry);
        dlclose(h);
        pthread_mutex_unlock(&module_lock);
        return NULL;
    }
    /* never closed: tables and objects (meshes, open files) point into it */
    atomic_store_explicit(&m->table, t, memory_order_release);
    pthread_mutex_unlock(&module_lock);
    return t;
}
