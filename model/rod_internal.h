/* Test hooks of model/rod (not installed: *_internal.h). */
#ifndef PHC_ROD_INTERNAL_H
#define PHC_ROD_INTERNAL_H

#include "model/rod.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Compares the Newton matrix that phc_rod_solve_static assembles at the
 * rod's current state (every node block and coupling block) with central
 * differences (step eps) of the residual, over every unknown: centre
 * displacements, world rotation increments and joint multipliers.  Writes
 * the largest |difference| and the largest |entry|.  Returns PHC_OK, or the
 * error of building the elimination tree (message in err). */
int phc_rod_internal_jacobian_check(phc_rod *rod, double eps, double *max_error,
                                    double *max_entry, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_ROD_INTERNAL_H */
