/* The classic pressure–volume plot of pv_curve data sets (Tyree & Hammel
 * 1972, J. Exp. Bot. 23:267): the inverse water potential −1/ψ (MPa⁻¹)
 * against the relative water deficit 1 − RWC, the field's convention (the
 * leaf dries from left to right; R package pvldcurve draws the same axes in
 * per cent).  For every leaf, in its own colour (fit/plots.h, groups):
 *   - the measured points;
 *   - the fitted two-part model of model/pressure_volume.h as one line:
 *     ψ̂ = π(RWC) + P̂(RWC) above the turgor loss point (π from the osmotic
 *     line, P̂ = c + e·RWC), ψ̂ = π(RWC) below it, where −1/ψ̂ = a + b·RWC is
 *     the straight osmotic line over the driest points;
 *   - the osmotic line extended (dashed) to full turgor, RWC = 1, where it
 *     meets the y axis at −1/π_o;
 *   - the turgor loss point (1 − RWC_tlp, −1/ψ_tlp) as a diamond.
 * A key names the leaves. */
#ifndef PHC_PV_PLOTS_H
#define PHC_PV_PLOTS_H

#include <stddef.h>

#include "model/pressure_volume.h"
#include "model/status.h"

/* Writes dir/<base>_pv_curve.png for `count` leaves (res[i] analysed by
 * phc_pv_analyse, labels[i] its name); `name` titles the plot (the data
 * set).  PHC_OK or the error of fit/plots.h. */
int phc_pv_plot_write(const char *name, const phc_pv_result *const *res, const char *const *labels, size_t count,
                      const char *dir, const char *base, phc_error *err);

#endif /* PHC_PV_PLOTS_H */
