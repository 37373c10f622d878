/* measurements/lazy_library_internal.h: system libraries opened on first use.
 *
 * libphytocal calls a few functions of some large system libraries that most
 * runs never need: PLplot (plots; with its freetype, qhull, shapelib, ...),
 * LAPACKE + OpenBLAS (eigen- and singular-value problems; with the reference
 * LAPACK, gfortran and quadmath) and libxml2 (RSML files; with ICU and
 * lzma).  Linking them costs every process their loading and relocation
 * (about half of `phytocal version`'s start-up, README "Speed").  Instead
 * libphytocal defines each function it uses itself, with the library
 * header's own prototype (so the compiler checks it), as a forwarder
 * (PHC_LAZY_FORWARD below) that opens the library on its first call
 * (dlopen of its SONAME, RTLD_NOW | RTLD_GLOBAL: the same scope a linked
 * library has, so PLplot's drivers and a program that also links the
 * library share one copy) and calls the real function.  The forwarders
 * are internal (cmake/libphytocal.map exports phc_* only), so a program
 * that links the library itself binds its own calls directly.
 *
 * The SONAMEs come from the libraries found at configure time
 * (CMakeLists.txt: PHC_SONAME_*).  Entry points that can report an error
 * (the plot files, the RSML reader and writer) call
 * phc_lazy_library_open first; a forwarder that still cannot reach its
 * function (the library or the symbol vanished after the build) writes
 * "phytocal: cannot load FUNCTION from the WHAT library SONAME: <dlerror>"
 * to stderr and aborts, as the dynamic loader would have refused to start
 * the program (exit 127) had the library been linked.  Internal: not
 * installed. */
#ifndef PHC_LAZY_LIBRARY_INTERNAL_H
#define PHC_LAZY_LIBRARY_INTERNAL_H

#include <stdatomic.h>

#include "model/status.h"

typedef struct phc_lazy_library {
    const char *soname;           /* "libplplot.so.17" */
    const char *what;             /* "plotting (PLplot)": for messages */
    _Atomic(void *) handle;       /* set once opened; never closed */
} phc_lazy_library;

/* The four libraries (measurements/lazy_library.c). */
extern phc_lazy_library phc_lazy_plplot, phc_lazy_lapack, phc_lazy_blas, phc_lazy_xml;

/* Opens lib if not yet open: PHC_OK, or PHC_ERR_IO
 * "WHERE: cannot load the WHAT library SONAME: <dlerror>" (where may be
 * NULL).  Thread-safe; a failed open is retried at the next call. */
int phc_lazy_library_open(phc_lazy_library *lib, const char *where, phc_error *err);

/* The address of function `name` in lib (opening lib; cached in *slot), or,
 * when that fails, the message above on stderr and abort(). */
void *phc_lazy_library_function(phc_lazy_library *lib, const char *name, _Atomic(void *) *slot);

/* Defines `ret name params` forwarding `args` to the library's own `name`;
 * PHC_LAZY_FORWARD_VOID for functions returning void.  params and args are
 * parenthesised lists: PHC_LAZY_FORWARD(phc_lazy_blas, double, cblas_ddot,
 * (const int n, const double *x, ...), (n, x, ...)). */
#define PHC_LAZY_FORWARD(lib, ret, name, params, args)                        \
    ret name params                                                           \
    {                                                                         \
        static _Atomic(void *) slot;                                          \
        ret (*f) params;                                                      \
        *(void **)&f = phc_lazy_library_function(&(lib), #name, &slot);      \
        return f args;                                                        \
    }
#define PHC_LAZY_FORWARD_VOID(lib, name, params, args)                       \
    void name params                                                          \
    {                                                                         \
        static _Atomic(void *) slot;                                          \
        void (*f) params;                                                     \
        *(void **)&f = phc_lazy_library_function(&(lib), #name, &slot);      \
        f args;                                                               \
    }

#endif
