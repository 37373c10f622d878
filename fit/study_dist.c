/* Loading the MPI module: see study_dist.h. */
#define _GNU_SOURCE /* dladdr */
#include "fit/study_dist.h"

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The module's file name, in the folder of libphytocal.so (build tree and
 * install tree alike: CMakeLists.txt puts it there). */
#define MODULE_FILE "phytocal_mpi.so"

int phc_dist_launched(void)
{
    /* Open MPI's mpirun sets OMPI_COMM_WORLD_SIZE; a PMIx launcher (Slurm's
       srun --mpi=pmix, prterun) PMIX_RANK; a PMI-1/2 launcher PMI_RANK. */
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; ++i) {
        const char *v = getenv(vars[i]);
        if (v && *v)
            return 1;
    }
    return 0;
}

int phc_dist_launched_rank(void)
{
    static const char *const vars[] = {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; ++i) {
        const char *v = getenv(vars[i]);
        char *end = NULL;
        const long r = v && *v ? strtol(v, &end, 10) : -1;
        if (v && *v && *end == '\0' && r >= 0 && r <= 0x7fffffffL)
            return (int)r;
    }
    return 0;
}

/* PATH of the module: the folder of the object that holds this function. */
static int module_path(char *buf, size_t size, phc_error *err)
{
    Dl_info info;
    if (!dladdr((void *)&phc_dist_open, &info) || !info.dli_fname || !*info.dli_fname)
        return phc_error_set(err, PHC_ERR_IO, "cannot find the folder of libphytocal (dladdr failed), so not "
                             "the MPI module %s either", MODULE_FILE);
    const char *slash = strrchr(info.dli_fname, '/');
    const int n = slash ? snprintf(buf, size, "%.*s/%s", (int)(slash - info.dli_fname), info.dli_fname, MODULE_FILE)
                        : snprintf(buf, size, "./%s", MODULE_FILE);
    if (n < 0 || (size_t)n >= size)
        return phc_error_set(err, PHC_ERR_IO, "%s: the MPI module's path is too long", info.dli_fname);
    return PHC_OK;
}

int phc_dist_open(phc_dist **out, phc_error *err)
{
    *out = NULL;
    if (!phc_dist_launched())
        return PHC_OK;
    char path[4096];
    int rc = module_path(path, sizeof path, err);
    if (rc)
        return rc;
    /* RTLD_GLOBAL: Open MPI loads its own components with dlopen, and they
       need libmpi's and libopen-pal's symbols in the global scope. */
    void *h = dlopen(path, RTLD_NOW | RTLD_GLOBAL);
    if (!h)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot load the MPI module (built with Open MPI's "
                             "libopenmpi-dev; started by mpirun or srun): %s", path, dlerror());
    phc_dist_module_open_fn open_fn;
    /* POSIX: the object pointer dlsym returns converts to a function pointer */
    *(void **)&open_fn = dlsym(h, PHC_DIST_MODULE_ENTRY);
    if (!open_fn) {
        rc = phc_error_set(err, PHC_ERR_IO, "%s: not a phytocal MPI module (no %s)", path, PHC_DIST_MODULE_ENTRY);
        dlclose(h);
        return rc;
    }
    phc_dist *d = calloc(1, sizeof *d);
    if (!d) {
        dlclose(h);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    d->handle = h;
    if ((rc = open_fn(PHC_DIST_ABI, d, err))) {
        /* MPI, once initialised, stays loaded until the process exits (the
           module has finalised it); only the struct goes */
        free(d);
        return rc;
    }
    *out = d;
    return PHC_OK;
}

void phc_dist_close(phc_dist *d)
{
    if (!d)
        return;
    if (d->finish)
        d->finish(d);
    /* no dlclose: Open MPI's libraries keep atexit handlers and threads of
       their own, which must not outlive the code they run */
    free(d);
}
