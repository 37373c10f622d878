/* Progress of long work, reported through a callback (DESIGN.md §3: the
 * library never prints; the command line draws what it is told here). */
#ifndef PHC_PROGRESS_H
#define PHC_PROGRESS_H

#include <stddef.h>

typedef struct phc_progress {
    const char *stage;  /* what is being done: "start", "uncertainty", "leave-one-out", ... */
    size_t step, steps; /* step k (1-based) of steps; steps = 0 when there is no count */
    int iteration;      /* the solver's iteration within the step, or -1 */
    double cost;        /* the solver's cost (1/2 sum of squared weighted residuals) at
                           that iteration, or NAN */
    const char *detail; /* free text (a data set's name), or NULL */
} phc_progress;

/* Returns non-zero to cancel the work.  user_data is the caller's. */
typedef int (*phc_progress_fn)(const phc_progress *p, void *user_data);

/* Calls fn (when not NULL) with the fields above; -1 / NAN where unknown. */
int phc_progress_report(phc_progress_fn fn, void *user_data, const char *stage, size_t step,
                        size_t steps, int iteration, double cost, const char *detail);

/* Passes a solver's iterations on (phc_nls_options.on_iteration with this
 * struct as its data) as progress of `stage` step `step` of `steps`; a
 * cancel sets `cancelled` and stops the solve. */
typedef struct phc_progress_relay {
    phc_progress_fn progress;
    void *user_data;
    const char *stage, *detail;
    size_t step, steps;
    int cancelled;
} phc_progress_relay;

int phc_progress_relay_iteration(int iteration, double cost, void *relay);

#endif /* PHC_PROGRESS_H */
