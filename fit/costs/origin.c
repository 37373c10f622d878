/* Message places for data-set options: see origin.h. */
#include "fit/costs/origin.h"

#include <stdio.h>

size_t phc_origin_line(const phc_origin *o, const char *key)
{
    if (!o)
        return 0;
    if (key && o->key_line && o->map)
        return o->key_line(o->map, key);
    return o->line;
}

phc_where phc_origin_key(const phc_origin *o, const char *kind, const char *key)
{
    phc_where w;
    if (o && o->path)
        snprintf(w.text, sizeof w.text, "%s:%zu", o->path, phc_origin_line(o, key));
    else
        snprintf(w.text, sizeof w.text, "%s", kind ? kind : "data set");
    return w;
}
