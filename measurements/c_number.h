/* Numbers in C syntax whatever LC_NUMERIC the program chose.
 *
 * strtod follows the locale: a program embedding phytocal that set a German
 * locale would read "1.5" as 1.  Data files, configurations and expressions
 * always write numbers with a '.', so every reader parses through here. */
#ifndef PHC_C_NUMBER_H
#define PHC_C_NUMBER_H

#include <locale.h>

/* A scope in which strtod uses the C locale on this thread; for loops over
 * many cells.  begin returns 0, or -1 when no C locale could be made (then
 * strtod keeps the current locale, which for a program that never called
 * setlocale is the C locale anyway).  end restores the thread's locale. */
typedef struct phc_c_numeric {
    locale_t c_locale, previous;
} phc_c_numeric;

int phc_c_numeric_begin(phc_c_numeric *scope);
void phc_c_numeric_end(phc_c_numeric *scope);

/* strtod in the C locale (a scope of its own). */
double phc_strtod_c(const char *s, char **end);

#endif /* PHC_C_NUMBER_H */
