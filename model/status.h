/* phytocal status codes and error messages.
 *
 * Every fallible function in phytocal returns an int: 0 (PHC_OK) on success,
 * a positive enum phc_status otherwise.  Functions that can fail on user input
 * also fill a caller-owned phc_error with a one-line message that names the
 * file, the line and column or the key, what was found and what was expected:
 *     weights.csv:17: column 'mass_g': expected a number, found 'n/a'
 * The library never prints; callers decide what to do with the message. */
#ifndef PHC_STATUS_H
#define PHC_STATUS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* X-macro list: name, short description.  Order fixes the numeric codes. */
#define PHC_STATUS_LIST(X)                                                  \
    X(PHC_OK, "success")                                                    \
    X(PHC_ERR_NOMEM, "out of memory")                                       \
    X(PHC_ERR_INVALID, "invalid argument")                                  \
    X(PHC_ERR_INPUT, "bad input")                                           \
    X(PHC_ERR_IO, "input/output error")                                     \
    X(PHC_ERR_DOMAIN, "value outside the model's domain")                   \
    X(PHC_ERR_NOT_CONVERGED, "the solver did not converge")                 \
    X(PHC_ERR_NUMERIC, "numerical failure")                                 \
    X(PHC_ERR_EXISTS, "output already exists")                              \
    X(PHC_ERR_INTERNAL, "internal error")

enum phc_status {
#define PHC_STATUS_ENUM(name, text) name,
    PHC_STATUS_LIST(PHC_STATUS_ENUM)
#undef PHC_STATUS_ENUM
    PHC_STATUS_COUNT
};

/* Short description of a status code; never NULL. */
const char *phc_strerror(int status);

/* Room for a message such as "file:line:col: key 'x': expected ..., found ...". */
#define PHC_ERROR_MESSAGE_SIZE 1024

typedef struct phc_error {
    int status;                            /* enum phc_status */
    char message[PHC_ERROR_MESSAGE_SIZE];  /* one line, no trailing newline */
} phc_error;

/* Clears an error (status 0, empty message).  err may be NULL. */
void phc_error_clear(phc_error *err);

/* Sets status and a printf-style message and returns status, so that callers
 * can write `return phc_error_set(err, PHC_ERR_INPUT, "%s:%d: ...", ...);`.
 * err may be NULL (the status is still returned). */
int phc_error_set(phc_error *err, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Puts a printf-style place before the message already in err ("where:
 * message"), sets the status and returns it: for callers that add the file
 * and line to an error raised below them.  err may be NULL. */
int phc_error_prefix(phc_error *err, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#ifdef __cplusplus
}
#endif

#endif /* PHC_STATUS_H */
