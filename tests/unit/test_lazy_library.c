/* measurements/lazy_library: a library opened on first use.  A missing one
 * is PHC_ERR_IO naming what, the SONAME and where (no crash, retried at the
 * next call); a present one gives its functions (libm's cos, called through
 * the pointer returned); the four configured libraries open (their SONAMEs,
 * read at configure time, exist on this machine). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "measurements/lazy_library_internal.h"
#include "tests/check.h"

int main(void)
{
    phc_lazy_library missing = {"libphytocal-no-such-library.so.0", "test (missing)", NULL};
    phc_error err = {0};
    CHECK(phc_lazy_library_open(&missing, "plots/a.png", &err) == PHC_ERR_IO);
    printf("missing: %s\n", err.message);
    CHECK_STR_CONTAINS(err.message, "plots/a.png: cannot load the test (missing) library "
                                    "libphytocal-no-such-library.so.0: ");
    CHECK(phc_lazy_library_open(&missing, NULL, &err) == PHC_ERR_IO); /* retried, same answer */
    CHECK(strncmp(err.message, "cannot load the test (missing)", 30) == 0);

    phc_lazy_library libm = {"libm.so.6", "maths (libm)", NULL};
    CHECK(phc_lazy_library_open(&libm, NULL, &err) == PHC_OK);
    _Atomic(void *) slot = NULL;
    double (*f)(double);
    *(void **)&f = phc_lazy_library_function(&libm, "cos", &slot);
    CHECK(f != NULL && f(0.5) == cos(0.5));
    CHECK(atomic_load(&slot) == *(void **)&f); /* cached */

    phc_lazy_library *all[] = {&phc_lazy_plplot, &phc_lazy_lapack, &phc_lazy_blas, &phc_lazy_xml};
    for (size_t i = 0; i < sizeof all / sizeof *all; ++i) {
        const int rc = phc_lazy_library_open(all[i], NULL, &err);
        printf("%s: %s %s\n", all[i]->what, all[i]->soname, rc ? err.message : "opened");
        CHECK(rc == PHC_OK);
    }
    return check_finish("test_lazy_library");
}
