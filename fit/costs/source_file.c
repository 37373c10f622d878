/* Data files and their columns: see source_file.h. */
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
int phc_unknown_column_at(const char *where, const char *what, const char *name,
                          const phc_table *t, phc_error *err)
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
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s '%s' is not a column of %s; did you mean '%s'?",
                             where, what, name, phc_table_source(t), near);
    return phc_error_set(err, PHC_ERR_INPUT, "%s: %s '%s' is not a column of %s (columns: %s)",
                         where, what, name, phc_table_source(t), list);
}
