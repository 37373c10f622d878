/* Progress reports: see progress.h. */
#include "fit/engine/progress.h"

int phc_progress_report(phc_progress_fn fn, void *user_data, const char *stage, size_t step,
                        size_t steps, int iteration, double cost, const char *detail)
{
    if (!fn)
        return 0;
    const phc_progress p = {stage, step, steps, iteration, cost, detail};
    return fn(&p, user_data);
}

int phc_progress_relay_iteration(int iteration, double cost, void *relay)
{
    phc_progress_relay *r = relay;
    if (phc_progress_report(r->progress, r->user_data, r->stage, r->step, r->steps, iteration, cost, r->detail))
        r->cancelled = 1;
    return r->cancelled;
}
