/* The `soil:` block of a data set in a config: its keys and their help
 * (`phytocal help soil`), and its translation into phc_soil_setup_options
 * (fit/costs/soil_setup.h).  Used by the YAML translations of the kinds
 * that have a soil (soil_probe, infiltration, root_shoot). */
#ifndef PHC_CONFIG_SOIL_SETUP_YAML_H
#define PHC_CONFIG_SOIL_SETUP_YAML_H

#include "fit/config_help.h"
#include "fit/costs/soil_setup.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"

/* The soil block's keys (NULL-terminated) and their help. */
extern const char *const phc_soil_setup_keys[];
extern const phc_key_help phc_soil_setup_help[];

/* The options read from a `soil:` mapping and the storage they point into
 * (options.origin points at origin: fill in place, do not copy). */
typedef struct phc_soil_setup_yaml {
    phc_soil_setup_options options;
    phc_origin origin;           /* the soil mapping: keys, and "layers[i].soil" ... */
    phc_soil_setup_layer *layers;
    phc_soil_setup_noise rocks, pockets;
    phc_soil_rain *rain;
    phc_soil_setup_source *sources;
    phc_geo_frame geo;
} phc_soil_setup_yaml;

/* Reads the `soil:` mapping `soil` into *out.  Errors (PHC_ERR_INPUT) name
 * the config file and line: unknown or missing keys, values of the wrong
 * type, unknown boundary or absorb forms, unreadable coordinates; the
 * values' ranges are checked by phc_soil_setup_new.  *out is to be freed
 * with phc_soil_setup_yaml_free, also on failure. */
int phc_soil_setup_yaml_read(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_soil_setup_yaml *out,
                             phc_error *err);
void phc_soil_setup_yaml_free(phc_soil_setup_yaml *y);

#endif /* PHC_CONFIG_SOIL_SETUP_YAML_H */
