/* The library's version: see version.h.  CMakeLists.txt passes the project
 * version as PHC_LIBRARY_VERSION when it compiles this file. */
#include "fit/version.h"

#ifndef PHC_LIBRARY_VERSION
#error "PHC_LIBRARY_VERSION must be defined by the build (CMakeLists.txt)"
#endif

const char *phc_version(void)
{
    return PHC_LIBRARY_VERSION;
}
