/* Unit tests of fit/run_ledger.c: records round-trip bit for bit, a line cut
 * off mid-write is dropped and cut from the file, an altered record fails
 * its checksum, a ledger of another study is refused naming the key, a
 * fresh ledger never overwrites an old one unless asked to. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/run_ledger.h"

static const char *const keys[2] = {"method", "samples"};

static void test_round_trip(const char *path)
{
    const char *values[2] = {"sobol", "64"};
    double y[5 * 2];
    unsigned char state[5];
    size_t found = 99;
    phc_run_ledger *l = NULL;
    phc_error err;
    unlink(path);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 0, 0, y, state, &found, &l, &err) == PHC_OK);
    CHECK(found == 0 && state[0] == PHC_LEDGER_PENDING && isnan(y[0]));
    /* values whose 17 digits matter: 0.1, 1/3, a subnormal, -0.0 */
    const double a[2] = {0.1, 1.0 / 3.0}, b[2] = {4.9406564584124654e-324, -0.0};
    CHECK(phc_run_ledger_append(l, 3, 0, a, &err) == PHC_OK);
    CHECK(phc_run_ledger_append(l, 0, 0, b, &err) == PHC_OK);
    CHECK(phc_run_ledger_append(l, 4, 1, a, &err) == PHC_OK);
    CHECK(phc_run_ledger_append(l, 5, 0, a, &err) == PHC_ERR_INVALID);
    CHECK(phc_run_ledger_close(l, &err) == PHC_OK);
    /* a fresh ledger refuses to overwrite */
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 0, 0, y, state, &found, &l, &err) == PHC_ERR_EXISTS);
    /* a record cut off while being written */
    FILE *f = fopen(path, "a");
    fputs("2\tok\t0.5", f);
    fclose(f);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 1, 0, y, state, &found, &l, &err) == PHC_OK);
    CHECK(found == 3);
    CHECK(state[3] == PHC_LEDGER_OK && state[0] == PHC_LEDGER_OK && state[4] == PHC_LEDGER_FAILED);
    CHECK(state[2] == PHC_LEDGER_PENDING && state[1] == PHC_LEDGER_PENDING);
    CHECK(memcmp(&y[3 * 2], a, sizeof a) == 0); /* bit for bit */
    CHECK(memcmp(&y[0], b, sizeof b) == 0);
    CHECK(isnan(y[4 * 2]) && isnan(y[4 * 2 + 1]));
    CHECK(phc_run_ledger_append(l, 2, 0, a, &err) == PHC_OK);
    CHECK(phc_run_ledger_close(l, &err) == PHC_OK);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 1, 0, y, state, &found, &l, &err) == PHC_OK);
    CHECK(found == 4 && state[2] == PHC_LEDGER_OK);
    phc_run_ledger_close(l, &err);
    /* another study */
    const char *other[2] = {"sobol", "128"};
    CHECK(phc_run_ledger_open(path, keys, other, 2, 5, 2, 1, 0, y, state, &found, &l, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "samples is '64' there and '128' now");
    /* an altered record */
    f = fopen(path, "r+");
    char text[4096];
    const size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = '\0';
    char *rec = strstr(text, "\n3\tok\t0.1");
    CHECK(rec != NULL);
    if (rec) {
        rec[8] = '2'; /* 0.1 -> 0.2 */
        rewind(f);
        fwrite(text, 1, n, f);
    }
    fclose(f);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 1, 0, y, state, &found, &l, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "fails its checksum");
    /* replace starts afresh */
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 0, 1, y, state, &found, &l, &err) == PHC_OK);
    phc_run_ledger_close(l, &err);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 1, 0, y, state, &found, &l, &err) == PHC_OK);
    CHECK(found == 0);
    phc_run_ledger_close(l, &err);
    /* resume without a ledger */
    unlink(path);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 5, 2, 1, 0, y, state, &found, &l, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "nothing to resume");
}

int main(void)
{
    char path[] = "/tmp/phc_ledger_XXXXXX";
    const int fd = mkstemp(path);
    if (fd < 0)
        return 1;
    close(fd);
    test_round_trip(path);
    unlink(path);
    return check_finish("test_run_ledger");
}
