/* Config keys of data sets: see yaml_keys.h. */
#include "fit/config/yaml_keys.h"

#include <stdio.h>
#include <string.h>

#include "fit/costs/source_file.h"

size_t phc_key_line(const phc_yaml_node *map, const char *key)
{
    for (size_t i = 0; i < map->count; ++i)
        if (strcmp(map->keys[i], key) == 0)
            return map->key_lines[i];
    return map->line;
}

static size_t key_line_of(const void *map, const char *key)
{
    return phc_key_line(map, key);
}

phc_origin phc_yaml_origin(const phc_yaml_doc *doc, const phc_yaml_node *map)
{
    phc_origin o = {.path = doc->path, .map = map, .key_line = key_line_of, .line = map->line};
    return o;
}

int phc_unknown_column(const phc_yaml_doc *doc, size_t line, const char *what,
                       const char *name, const phc_table *t, phc_error *err)
{
    char where[4200];
    snprintf(where, sizeof where, "%s:%zu", doc->path, line);
    return phc_unknown_column_at(where, what, name, t, err);
}

int phc_need_column(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                    const char *name, const phc_table *t, phc_error *err)
{
    if (phc_table_find(t, name) >= 0)
        return PHC_OK;
    char what[64];
    snprintf(what, sizeof what, "key '%s':", key);
    return phc_unknown_column(doc, phc_key_line(node, key), what, name, t, err);
}

int phc_column_spec(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                    const char *context, const char *default_unit, const char **column,
                    const char **unit, phc_error *err)
{
    static const char *const spec_keys[] = {"column", "unit", NULL};
    const phc_yaml_node *v = phc_yaml_get(node, key);
    char ctx[64];
    int rc;
    snprintf(ctx, sizeof ctx, "key '%s'", key);
    *unit = default_unit;
    if (!v)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: missing key '%s' ({column: NAME, unit: UNIT})",
                             doc->path, node->line, context, key);
    if (v->kind == PHC_YAML_SCALAR)
        return phc_yaml_string(doc, v, key, column, err);
    if ((rc = phc_yaml_check_keys(doc, v, spec_keys, ctx, err)) ||
        (rc = phc_yaml_map_string(doc, v, "column", 1, ctx, column, err)) ||
        (rc = phc_yaml_map_string(doc, v, "unit", 0, ctx, unit, err)))
        return rc;
    return PHC_OK;
}

int phc_yaml_map_choice(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                        const char *context, const char *const *names, int *choice, phc_error *err)
{
    const char *v = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, key, 0, context, &v, err)) || !v)
        return rc;
    char list[256] = "";
    for (int i = 0; names[i]; ++i) {
        if (!strcmp(v, names[i])) {
            *choice = i;
            return PHC_OK;
        }
        const size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", names[i]);
    }
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': '%s' is not one of %s", doc->path,
                         phc_key_line(node, key), key, v, list);
}
