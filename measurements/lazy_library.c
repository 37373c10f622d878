/* System libraries opened on first use: see lazy_library_internal.h. */
#include "measurements/lazy_library_internal.h"

#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

/* PHC_SONAME_*: set by CMakeLists.txt from the libraries it found. */
phc_lazy_library phc_lazy_plplot = {PHC_SONAME_PLPLOT, "plotting (PLplot)", NULL};
phc_lazy_library phc_lazy_lapack = {PHC_SONAME_LAPACKE, "LAPACKE", NULL};
phc_lazy_library phc_lazy_blas = {PHC_SONAME_OPENBLAS, "BLAS (OpenBLAS)", NULL};
phc_lazy_library phc_lazy_xml = {PHC_SONAME_LIBXML2, "XML (libxml2)", NULL};

static pthread_mutex_t lazy_lock = PTHREAD_MUTEX_INITIALIZER;

/* The handle, or NULL with dlerror()'s text copied to msg. */
static void *lazy_open(phc_lazy_library *lib, char *msg, size_t size)
{
    void *h = atomic_load_explicit(&lib->handle, memory_order_acquire);
    if (h)
        return h;
    pthread_mutex_lock(&lazy_lock);
    h = atomic_load_explicit(&lib->handle, memory_order_acquire);
    if (!h) {
        /* RTLD_NOW: a missing symbol of the library's own dependencies shows
           here, not in the middle of a run */
        h = dlopen(lib->soname, RTLD_NOW | RTLD_GLOBAL);
        if (h) {
            atomic_store_explicit(&lib->handle, h, memory_order_release);
        } else {
            const char *e = dlerror();
            snprintf(msg, size, "%s", e ? e : "dlopen failed");
        }
    }
    pthread_mutex_unlock(&lazy_lock);
    return h;
}

int phc_lazy_library_open(phc_lazy_library *lib, const char *where, phc_error *err)
{
    char msg[512];
    if (lazy_open(lib, msg, sizeof msg))
        return PHC_OK;
    return phc_error_set(err, PHC_ERR_IO, "%s%scannot load the %s library %s: %s", where ? where : "",
                         where ? ": " : "", lib->what, lib->soname, msg);
}

void *phc_lazy_library_function(phc_lazy_library *lib, const char *name, _Atomic(void *) *slot)
{
    void *f = atomic_load_explicit(slot, memory_order_acquire);
    if (f)
        return f;
    char msg[512];
    void *h = lazy_open(lib, msg, sizeof msg);
    if (h) {
        dlerror();
        f = dlsym(h, name);
        if (!f) {
            const char *e = dlerror();
            snprintf(msg, sizeof msg, "%s", e ? e : "no such symbol");
        }
    }
    if (!f) {
        fprintf(stderr, "phytocal: cannot load %s from the %s library %s: %s\n", name, lib->what,
                lib->soname, msg);
        abort();
    }
    atomic_store_explicit(slot, f, memory_order_release);
    return f;
}
