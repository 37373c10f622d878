/* Unit tests of fit/run_ledger.c: records round-trip bit for bit, a line cut
 * off mid-write is dropped and cut from the file, an altered record fails
 * its checksum, a ledger of another study is refused naming the key, a
 * fresh ledger never overwrites an old one unless asked to; a record's
 * exact text (hex bit patterns, CRC-32C against a bit-at-a-time reference
 * and RFC 3720's check value), with the SSE4.2 and the software CRC (the
 * test runs itself again with PHC_LEDGER_SOFT_CRC=1); a format-1 ledger
 * (%.17g, SHA-256) is resumed and appended to in format 1; a newer format
 * is refused. */
#include <math.h>
#include <nettle/sha2.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
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
    char *rec = strstr(text, "\n3\tok\t3fb999999999999a");
    CHECK(rec != NULL);
    if (rec) {
        rec[20] = 'b'; /* 0.1's last bit */
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

/* CRC-32C one bit at a time (reflected polynomial 0x82F63B78). */
static uint32_t crc32c_ref(const char *s, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i) {
        c ^= (unsigned char)s[i];
        for (int b = 0; b < 8; ++b)
            c = (c & 1u) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    }
    return ~c;
}

static size_t read_text(const char *path, char *text, size_t size)
{
    FILE *f = fopen(path, "r");
    const size_t n = f ? fread(text, 1, size - 1, f) : 0;
    text[n] = '\0';
    if (f)
        fclose(f);
    return n;
}

/* A record's text: the outputs' bit patterns, the CRC-32C of the line
 * before " #" (lines of 1 to 150 outputs: every tail length of the 8-byte
 * loop). */
static void test_record_text(const char *path)
{
    CHECK(crc32c_ref("123456789", 9) == 0xE3069283u); /* RFC 3720 B.4 */
    const char *values[2] = {"sobol", "64"};
    double y[3 * 150], v[150];
    unsigned char state[3];
    size_t found;
    phc_run_ledger *l = NULL;
    phc_error err;
    for (size_t n_out = 1; n_out <= 150; n_out += 1 + n_out / 8) {
        CHECK(phc_run_ledger_open(path, keys, values, 2, 3, n_out, 0, 1, y, state, &found, &l, &err) == PHC_OK);
        for (size_t j = 0; j < n_out; ++j)
            v[j] = (j % 3 == 0) ? 1.0 / (double)(j + 3) : -(double)j * 1e-300;
        CHECK(phc_run_ledger_append(l, 2, 0, v, &err) == PHC_OK);
        CHECK(phc_run_ledger_append(l, 1, 1, v, &err) == PHC_OK);
        CHECK(phc_run_ledger_close(l, &err) == PHC_OK);
        static char text[16384];
        read_text(path, text, sizeof text);
        const char *rec = strstr(text, "@ end\n");
        CHECK(rec != NULL);
        if (!rec)
            return;
        rec += 6;
        const char *hash = strstr(rec, " #");
        CHECK(hash != NULL && strncmp(rec, "2\tok\t", 5) == 0);
        if (!hash)
            return;
        char want[16], got[9];
        snprintf(want, sizeof want, "%08x", (unsigned)crc32c_ref(rec, (size_t)(hash - rec)));
        memcpy(got, hash + 2, 8);
        got[8] = '\0';
        CHECK(strcmp(want, got) == 0 && hash[10] == '\n');
        /* the bit patterns */
        const char *p = rec + 4;
        int exact = 1;
        for (size_t j = 0; j < n_out; ++j, p += 17) {
            uint64_t u;
            memcpy(&u, &v[j], 8);
            char h[20];
            snprintf(h, sizeof h, "\t%016llx", (unsigned long long)u);
            exact &= strncmp(p, h, 17) == 0;
        }
        CHECK(exact && p == hash);
        /* a failed row: every output the NaN pattern */
        CHECK(strstr(hash, "\n1\tfailed\t7ff8000000000000") != NULL);
        CHECK(phc_run_ledger_open(path, keys, values, 2, 3, n_out, 1, 0, y, state, &found, &l, &err) == PHC_OK);
        CHECK(found == 2 && memcmp(&y[2 * n_out], v, n_out * sizeof *v) == 0);
        CHECK(state[1] == PHC_LEDGER_FAILED && isnan(y[n_out]));
        phc_run_ledger_close(l, &err);
    }
    /* a record whose output is not 16 hex digits, with a matching checksum */
    FILE *f = fopen(path, "w");
    const char *bad = "0\tok\t3ff000000000000g";
    fprintf(f, "# phytocal run ledger 2\n@ method\tsobol\n@ samples\t64\n@ end\n%s #%08x\n", bad,
            (unsigned)crc32c_ref(bad, strlen(bad)));
    fclose(f);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 3, 1, 1, 0, y, state, &found, &l, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, ":5: ledger record: output 1 is not a number");
    /* a newer format */
    f = fopen(path, "w");
    fprintf(f, "# phytocal run ledger 3\n@ method\tsobol\n@ samples\t64\n@ end\n");
    fclose(f);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 3, 1, 1, 0, y, state, &found, &l, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, ":1: a run ledger of format '3'");
}

/* A format-1 ledger (earlier phytocal) is read and appended to in format 1. */
static void sha_line(FILE *f, const char *rec)
{
    struct sha256_ctx ctx;
    uint8_t d[SHA256_DIGEST_SIZE];
    sha256_init(&ctx);
    sha256_update(&ctx, strlen(rec), (const uint8_t *)rec);
    sha256_digest(&ctx, SHA256_DIGEST_SIZE, d);
    fprintf(f, "%s #", rec);
    for (int i = 0; i < 8; ++i)
        fprintf(f, "%02x", d[i]);
    fprintf(f, "\n");
}

static void test_format_1(const char *path)
{
    const char *values[2] = {"sobol", "64"};
    FILE *f = fopen(path, "w");
    fprintf(f, "# phytocal run ledger 1\n@ method\tsobol\n@ samples\t64\n@ end\n");
    sha_line(f, "1\tok\t0.10000000000000001\t-0");
    sha_line(f, "0\tfailed\tnan\tnan");
    fclose(f);
    double y[3 * 2];
    unsigned char state[3];
    size_t found;
    phc_run_ledger *l = NULL;
    phc_error err;
    CHECK(phc_run_ledger_open(path, keys, values, 2, 3, 2, 1, 0, y, state, &found, &l, &err) == PHC_OK);
    CHECK(found == 2 && y[2] == 0.1 && y[3] == 0.0 && signbit(y[3]) && state[0] == PHC_LEDGER_FAILED);
    const double a[2] = {1.0 / 3.0, 2.5};
    CHECK(phc_run_ledger_append(l, 2, 0, a, &err) == PHC_OK);
    CHECK(phc_run_ledger_close(l, &err) == PHC_OK);
    char text[4096];
    read_text(path, text, sizeof text);
    CHECK(strstr(text, "\n2\tok\t0.33333333333333331\t2.5 #") != NULL);
    CHECK(phc_run_ledger_open(path, keys, values, 2, 3, 2, 1, 0, y, state, &found, &l, &err) == PHC_OK);
    CHECK(found == 3 && y[4] == 1.0 / 3.0 && y[5] == 2.5);
    phc_run_ledger_close(l, &err);
    /* an altered format-1 record */
    char *rec = strstr(text, "0.10000000000000001");
    CHECK(rec != NULL);
    if (rec) {
        rec[3] = '2';
        f = fopen(path, "w");
        fputs(text, f);
        fclose(f);
        CHECK(phc_run_ledger_open(path, keys, values, 2, 3, 2, 1, 0, y, state, &found, &l, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, ":5: ledger record fails its checksum");
    }
}

int main(int argc, char **argv)
{
    char path[] = "/tmp/phc_ledger_XXXXXX";
    const int fd = mkstemp(path);
    if (fd < 0)
        return 1;
    close(fd);
    test_round_trip(path);
    test_record_text(path);
    test_format_1(path);
    unlink(path);
    /* the same with the software CRC (the first run used SSE4.2 where the
       processor has it) */
    if (argc == 1 && !getenv("PHC_LEDGER_SOFT_CRC")) {
        const pid_t pid = fork();
        if (pid == 0) {
            setenv("PHC_LEDGER_SOFT_CRC", "1", 1);
            execl(argv[0], argv[0], "soft", (char *)NULL);
            _exit(127);
        }
        int status = -1;
        waitpid(pid, &status, 0);
        CHECK(pid > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    return check_finish(argc > 1 ? "test_run_ledger (software CRC-32C)" : "test_run_ledger");
}
