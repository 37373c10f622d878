/* The version of the phytocal library (semantic versioning: MAJOR.MINOR.PATCH).
 *
 * phc_version() is the version of the library actually loaded, which may
 * differ from the headers a program was compiled with; the umbrella header
 * phytocal/phytocal.h carries the compile-time PHC_VERSION_STRING and
 * PHC_VERSION_MAJOR/MINOR/PATCH. */
#ifndef PHC_VERSION_H
#define PHC_VERSION_H

#ifdef __cplusplus
extern "C" {
#endif

/* "0.1.0" (the CMake project version); a static string, never NULL. */
const char *phc_version(void);

#ifdef __cplusplus
}
#endif

#endif /* PHC_VERSION_H */
