/* The descriptors of the data-set kinds this build knows (fit/config/kind.h),
 * one per kind, each defined in its fit/config/<kind>_yaml.c. */
#ifndef PHC_CONFIG_KINDS_H
#define PHC_CONFIG_KINDS_H

#include "fit/config/kind.h"

extern const phc_kind phc_curve_kind;
extern const phc_kind phc_elasticity_curve_kind;
extern const phc_kind phc_infiltration_kind;
extern const phc_kind phc_leaf_photos_kind;
extern const phc_kind phc_pv_curve_kind;
extern const phc_kind phc_root_shoot_kind;
extern const phc_kind phc_shape_series_kind;
extern const phc_kind phc_shoot_traces_kind;
extern const phc_kind phc_soil_probe_kind;
extern const phc_kind phc_weight_curve_kind;

#endif /* PHC_CONFIG_KINDS_H */
