/* Locale-independent number parsing: see c_number.h. */
#include "measurements/c_number.h"

#include <stdlib.h>

int phc_c_numeric_begin(phc_c_numeric *scope)
{
    scope->previous = (locale_t)0;
    scope->c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (!scope->c_locale)
        return -1;
    scope->previous = uselocale(scope->c_locale);
    return 0;
}

void phc_c_numeric_end(phc_c_numeric *scope)
{
    if (!scope->c_locale)
        return;
    if (scope->previous)
        uselocale(scope->previous);
    freelocale(scope->c_locale);
    scope->c_locale = scope->previous = (locale_t)0;
}

double phc_strtod_c(const char *s, char **end)
{
    phc_c_numeric scope;
    phc_c_numeric_begin(&scope);
    const double x = strtod(s, end);
    phc_c_numeric_end(&scope);
    return x;
}
