/* `phytocal simulate`: every data set's model at the configured start values,
 * written as a run directory with <name>_simulated.csv (x, observed, model)
 * and <name>_simulated.png per data set, so start values can be checked
 * before a fit.  The directory is written like a fit's (run_dir.h): whole or
 * not at all, an earlier one replaced only with force. */
#ifndef PHC_SIMULATE_H
#define PHC_SIMULATE_H

#include "fit/engine/problem.h"
#include "fit/engine/provenance.h"
#include "model/status.h"

/* pv (may be NULL) goes into the directory's manifest (run_dir.h). */
int phc_simulate_write(const phc_problem *pb, const phc_provenance *pv, const char *dir, int force,
                       phc_error *err);

#endif /* PHC_SIMULATE_H */
