/* Data files named in a config: see source_file.h. */
#include "fit/costs/source_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/suggest.h"

char *phc_join_path(const char *dir, const char *file)
{
    /* a config in the working directory: its files keep their own names in
     * messages ("data.csv", not "./data.csv") */
    if (file[0] == '/' || !dir || !dir[0] || strcmp(dir, ".") == 0)
        return strdup(file);
    size_t len = strlen(dir) + strlen(file) + 2;
    char *s = malloc(len);
    if (s)
        snprintf(s, len, "%s/%s", dir, file);
    return s;
}

/* A column name that is not in the table: name the columns that are. */
int phc_unknown_column(const phc_yaml_doc *doc, size_t line, const char *what,
                       const char *name, const phc_table *t, phc_error *err)
{
    size_t nc = phc_table_columns(t);
    const char *names[64];
    size_t shown = nc < 64 ? nc : 64;
    char list[512] = "";
    for (size_t j = 0; j < shown; ++j) {
        names[j] = phc_table_column_name(t, j);
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s'%s'", j ? ", " : "", names[j]);
    }
    const char *near = phc_suggest(name, names, shown);
    if (near)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s '%s' is not a column of %s; did you mean '%s'?",
                             doc->path, line, what, name, phc_table_source(t), near);
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s '%s' is not a column of %s (columns: %s)",
                         doc->path, line, what, name, phc_table_source(t), list);
}

size_t phc_key_line(const phc_yaml_node *map, const char *key)
{
    for (size_t i = 0; i < map->count; ++i)
        if (strcmp(map->keys[i], key) == 0)
            return map->key_lines[i];
    return map->line;
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
