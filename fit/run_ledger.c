/* The run ledger: see run_ledger.h. */
#include "fit/run_ledger.h"

#include <errno.h>
#include <math.h>
#include <nettle/sha2.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

/* Version 2 (written): outputs as the 16 hex digits of their IEEE-754 bit
 * pattern, CRC-32C per line.  Version 1 (read, and appended to in its own
 * format when resumed): %.17g and the first 16 hex digits of SHA-256. */
#define LEDGER_MAGIC_1 "# phytocal run ledger 1"
#define LEDGER_MAGIC_2 "# phytocal run ledger 2"

struct phc_run_ledger {
    FILE *f;
    int version; /* 1 or 2: the format of the file's records */
    char *path;
    size_t rows, n_out;
    size_t line_size; /* longest record */
    char *pending;  /* records formatted, not yet written (phc_run_ledger.h: batches) */
    size_t pending_bytes, pending_records, pending_cap;
    double last_write; /* CLOCK_MONOTONIC seconds of the last write(2) */
};

/* A batch goes out when it holds this many records or bytes, or when this
 * long has passed since the last write: what a SIGKILL can lose. */
#define BATCH_RECORDS 64
#define BATCH_BYTES 65536
#define BATCH_SECONDS 0.05

static double monotonic_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Writes the pending records in one write(2) (more when the system writes
 * part of it). */
static int write_pending(phc_run_ledger *l, phc_error *err)
{
    for (size_t done = 0; done < l->pending_bytes;) {
        const ssize_t w = write(fileno(l->f), l->pending + done, l->pending_bytes - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return phc_error_set(err, PHC_ERR_IO, "%s: write error: %s", l->path,
                                 w < 0 ? strerror(errno) : "nothing written");
        done += (size_t)w;
    }
    l->pending_bytes = 0;
    l->pending_records = 0;
    l->last_write = monotonic_seconds();
    return PHC_OK;
}

/* Version 1: the first 16 hex digits of SHA-256(text[0..n-1]). */
static void checksum(const char *text, size_t n, char hex[17])
{
    struct sha256_ctx ctx;
    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_init(&ctx);
    sha256_update(&ctx, n, (const uint8_t *)text);
    sha256_digest(&ctx, SHA256_DIGEST_SIZE, digest);
    static const char digits[] = "0123456789abcdef";
    for (int i = 0; i < 8; ++i) {
        hex[2 * i] = digits[digest[i] >> 4];
        hex[2 * i + 1] = digits[digest[i] & 15];
    }
    hex[16] = '\0';
}

/* Version 2: CRC-32C (Castagnoli polynomial 0x1EDC6F41, reflected
 * 0x82F63B78; initial value and final xor 0xFFFFFFFF, as iSCSI, RFC 3720
 * appendix B.4: "123456789" -> 0xE3069283).  A checksum against torn or
 * altered lines, not against tampering.  Software slicing by 8 (8 tables of
 * 256 entries, made once), or the SSE4.2 crc32 instruction where the
 * processor has it: the same value. */
static uint32_t crc_table[8][256];
static pthread_once_t crc_once = PTHREAD_ONCE_INIT;
static int crc_hw;

static void crc_init(void)
{
    for (uint32_t i = 0; i < 256; ++i) {
        uint32_t c = i;
        for (int b = 0; b < 8; ++b)
            c = (c >> 1) ^ (0x82F63B78u & (0u - (c & 1u)));
        crc_table[0][i] = c;
    }
    for (uint32_t i = 0; i < 256; ++i)
        for (int t = 1; t < 8; ++t)
            crc_table[t][i] = (crc_table[t - 1][i] >> 8) ^ crc_table[0][crc_table[t - 1][i] & 0xFF];
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    __builtin_cpu_init();
    crc_hw = __builtin_cpu_supports("sse4.2") && !getenv("PHC_LEDGER_SOFT_CRC");
#endif
}

static uint32_t crc32c_soft(uint32_t c, const unsigned char *p, size_t n)
{
    for (; n >= 8; p += 8, n -= 8) {
        uint32_t lo, hi;
        memcpy(&lo, p, 4);
        memcpy(&hi, p + 4, 4);
        lo ^= c; /* little-endian words (x86-64, aarch64); see crc32c below */
        c = crc_table[7][lo & 0xFF] ^ crc_table[6][(lo >> 8) & 0xFF] ^ crc_table[5][(lo >> 16) & 0xFF] ^
            crc_table[4][lo >> 24] ^ crc_table[3][hi & 0xFF] ^ crc_table[2][(hi >> 8) & 0xFF] ^
            crc_table[1][(hi >> 16) & 0xFF] ^ crc_table[0][hi >> 24];
    }
    while (n--)
        c = (c >> 8) ^ crc_table[0][(c ^ *p++) & 0xFF];
    return c;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("sse4.2"))) static uint32_t crc32c_hw(uint32_t c, const unsigned char *p, size_t n)
{
    uint64_t c64 = c;
    for (; n >= 8; p += 8, n -= 8) {
        uint64_t w;
        memcpy(&w, p, 8);
        c64 = __builtin_ia32_crc32di(c64, w);
    }
    c = (uint32_t)c64;
    while (n--)
        c = __builtin_ia32_crc32qi(c, *p++);
    return c;
}
#endif

static uint32_t crc32c(const char *text, size_t n)
{
    pthread_once(&crc_once, crc_init);
    const uint32_t one = 1;
    unsigned char little;
    memcpy(&little, &one, 1);
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    if (crc_hw)
        return ~crc32c_hw(0xFFFFFFFFu, (const unsigned char *)text, n);
#endif
    if (!little) { /* big-endian: byte at a time */
        uint32_t c = 0xFFFFFFFFu;
        for (size_t i = 0; i < n; ++i)
            c = (c >> 8) ^ crc_table[0][(c ^ (unsigned char)text[i]) & 0xFF];
        return ~c;
    }
    return ~crc32c_soft(0xFFFFFFFFu, (const unsigned char *)text, n);
}

static const char hex_digits[] = "0123456789abcdef";

/* The 8 hex digits of CRC-32C(text[0..n-1]). */
static void checksum2(const char *text, size_t n, char hex[9])
{
    const uint32_t c = crc32c(text, n);
    for (int i = 0; i < 8; ++i)
        hex[i] = hex_digits[(c >> (28 - 4 * i)) & 15];
    hex[8] = '\0';
}

/* v's 64-bit pattern as 16 lower-case hex digits, most significant first:
 * exact (every bit, NaN payloads and -0 included), and a table look-up per
 * byte instead of a decimal conversion. */
static char hex_pairs[256][2];
static pthread_once_t hex_once = PTHREAD_ONCE_INIT;

static void hex_init(void)
{
    for (int i = 0; i < 256; ++i) {
        hex_pairs[i][0] = hex_digits[i >> 4];
        hex_pairs[i][1] = hex_digits[i & 15];
    }
}

static void put_hex64(char *out, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    for (int i = 0; i < 8; ++i)
        memcpy(out + 2 * i, hex_pairs[(u >> (56 - 8 * i)) & 0xFF], 2);
}

/* Reads exactly 16 hex digits at p into *v; 0 when they are not. */
static int get_hex64(const char *p, double *v)
{
    uint64_t u = 0;
    for (int i = 0; i < 16; ++i) {
        const char c = p[i];
        unsigned d;
        if (c >= '0' && c <= '9')
            d = (unsigned)(c - '0');
        else if (c >= 'a' && c <= 'f')
            d = (unsigned)(c - 'a' + 10);
        else
            return 0;
        u = (u << 4) | d;
    }
    memcpy(v, &u, 8);
    return 1;
}

static int read_all(const char *path, char **text, size_t *size, phc_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return phc_error_set(err, errno == ENOENT ? PHC_ERR_INPUT : PHC_ERR_IO, "%s: cannot open the ledger: %s%s",
                             path, strerror(errno), errno == ENOENT ? " (nothing to resume)" : "");
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            char *grown = realloc(buf, 2 * cap + 1);
            if (!grown) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = grown;
            cap *= 2;
        }
    }
    const int bad = ferror(f);
    fclose(f);
    if (!buf)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory reading %s", path);
    if (bad) {
        free(buf);
        return phc_error_set(err, PHC_ERR_IO, "%s: read error", path);
    }
    buf[n] = '\0';
    *text = buf;
    *size = n;
    return PHC_OK;
}

/* Reads an existing ledger into y and state; *complete = bytes up to the
 * end of the last complete line. */
static int parse(const char *path, const char *text, size_t size, const char *const *keys,
                 const char *const *values, size_t n_keys, size_t rows, size_t n_out, double *y,
                 unsigned char *state, size_t *n_found, size_t *complete, int *version, phc_error *err)
{
    size_t pos = 0, lineno = 0, key_i = 0;
    int in_header = 1;
    *n_found = 0;
    *complete = 0;
    while (pos < size) {
        const char *nl = memchr(text + pos, '\n', size - pos);
        if (!nl)
            break; /* a line cut off while being written: dropped */
        const size_t len = (size_t)(nl - (text + pos));
        char *line = malloc(len + 1);
        if (!line)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        memcpy(line, text + pos, len);
        line[len] = '\0';
        ++lineno;
        int rc = PHC_OK;
        if (lineno == 1) {
            if (strcmp(line, LEDGER_MAGIC_2) == 0)
                *version = 2;
            else if (strcmp(line, LEDGER_MAGIC_1) == 0)
                *version = 1;
            else if (strncmp(line, "# phytocal run ledger ", 22) == 0)
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:1: a run ledger of format '%s', newer than this "
                                   "phytocal reads (1 and 2): resume it with the phytocal that wrote it, or remove "
                                   "it to start afresh", path, line + 22);
            else
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:1: not a phytocal run ledger", path);
        } else if (in_header) {
            if (strcmp(line, "@ end") == 0) {
                if (key_i != n_keys)
                    rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: the ledger is from another study: it has no "
                                       "'%s'", path, lineno, keys[key_i]);
                in_header = 0;
            } else if (strncmp(line, "@ ", 2) != 0 || !strchr(line + 2, '\t')) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: expected '@ KEY<tab>VALUE' in the ledger's header",
                                   path, lineno);
            } else {
                char *tab = strchr(line + 2, '\t');
                *tab = '\0';
                const char *k = line + 2, *v = tab + 1;
                if (key_i >= n_keys || strcmp(k, keys[key_i]) != 0)
                    rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: the ledger is from another study: it records "
                                       "'%s' where this study has '%s'", path, lineno, k,
                                       key_i < n_keys ? keys[key_i] : "(nothing)");
                else if (strcmp(v, values[key_i]) != 0)
                    rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: the ledger is from another study: %s is '%s' "
                                       "there and '%s' now; remove the ledger or give another -o",
                                       path, lineno, k, v, values[key_i]);
                ++key_i;
            }
        } else {
            char *hash = strstr(line, " #");
            char hex[17];
            const size_t digits = *version == 1 ? 16 : 8;
            if (!hash || strlen(hash + 2) != digits) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: ledger record without its checksum", path, lineno);
            } else {
                if (*version == 1)
                    checksum(line, (size_t)(hash - line), hex);
                else
                    checksum2(line, (size_t)(hash - line), hex);
                if (strcmp(hex, hash + 2) != 0) {
                    rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: ledger record fails its checksum (the file "
                                       "was changed); remove the ledger to start afresh", path, lineno);
                } else {
                    *hash = '\0';
                    char *end = NULL;
                    errno = 0;
                    const unsigned long long row = strtoull(line, &end, 10);
                    const int failed = strncmp(end, "\tfailed", 7) == 0;
                    if (end == line || row >= rows || (!failed && strncmp(end, "\tok", 3) != 0)) {
                        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: ledger record: bad row or state", path, lineno);
                    } else if (state[row] != PHC_LEDGER_PENDING) {
                        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: row %llu is recorded twice", path, lineno, row);
                    } else {
                        char *p = end + (failed ? 7 : 3);
                        for (size_t j = 0; j < n_out && rc == PHC_OK; ++j) {
                            if (*p != '\t') {
                                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: ledger record: expected %zu outputs",
                                                   path, lineno, n_out);
                                break;
                            }
                            if (*version == 1) {
                                y[row * n_out + j] = strtod(p + 1, &end);
                            } else { /* exactly 16 hex digits, then a tab or the end */
                                end = p + 1;
                                if (strnlen(p + 1, 17) >= 16 && get_hex64(p + 1, &y[row * n_out + j]) &&
                                    (p[17] == '\t' || p[17] == '\0'))
                                    end = p + 17;
                            }
                            if (end == p + 1)
                                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: ledger record: output %zu is not a "
                                                   "number", path, lineno, j + 1);
                            p = end;
                        }
                        if (rc == PHC_OK && *p != '\0')
                            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: ledger record: expected %zu outputs",
                                               path, lineno, n_out);
                        if (rc == PHC_OK) {
                            state[row] = failed ? PHC_LEDGER_FAILED : PHC_LEDGER_OK;
                            ++*n_found;
                        }
                    }
                }
            }
        }
        free(line);
        if (rc)
            return rc;
        pos += len + 1;
        *complete = pos;
    }
    if (in_header)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: the ledger's header is incomplete", path);
    return PHC_OK;
}

int phc_run_ledger_open(const char *path, const char *const *keys, const char *const *values, size_t n_keys,
                        size_t rows, size_t n_out, int resume, int replace, double *y, unsigned char *state,
                        size_t *n_found, phc_run_ledger **out, phc_error *err)
{
    *out = NULL;
    *n_found = 0;
    for (size_t i = 0; i < rows * n_out; ++i)
        y[i] = NAN;
    memset(state, PHC_LEDGER_PENDING, rows);
    phc_run_ledger *l = calloc(1, sizeof *l);
    if (!l || !(l->path = strdup(path))) {
        free(l);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    l->rows = rows;
    l->n_out = n_out;
    int rc = PHC_OK;
    if (resume) {
        char *text = NULL;
        size_t size = 0, complete = 0;
        if ((rc = read_all(path, &text, &size, err)))
            goto fail;
        rc = parse(path, text, size, keys, values, n_keys, rows, n_out, y, state, n_found, &complete, &l->version,
                   err);
        free(text);
        if (rc)
            goto fail;
        if (complete < size && truncate(path, (off_t)complete) != 0) {
            rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot cut off the unfinished last line: %s", path,
                               strerror(errno));
            goto fail;
        }
        if (!(l->f = fopen(path, "a"))) {
            rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot append: %s", path, strerror(errno));
            goto fail;
        }
    } else {
        struct stat st;
        if (!replace && stat(path, &st) == 0) {
            rc = phc_error_set(err, PHC_ERR_EXISTS, "%s: an unfinished study's ledger is here: --resume continues "
                               "it, --force starts afresh", path);
            goto fail;
        }
        if (!(l->f = fopen(path, "w"))) {
            rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot create the ledger: %s", path, strerror(errno));
            goto fail;
        }
        l->version = 2;
        fprintf(l->f, "%s\n", LEDGER_MAGIC_2);
        for (size_t i = 0; i < n_keys; ++i) {
            if (strpbrk(keys[i], "\t\n") || strpbrk(values[i], "\t\n")) {
                rc = phc_error_set(err, PHC_ERR_INVALID, "ledger key '%s': tab or newline", keys[i]);
                goto fail;
            }
            fprintf(l->f, "@ %s\t%s\n", keys[i], values[i]);
        }
        fprintf(l->f, "@ end\n");
        if (fflush(l->f) != 0) {
            rc = phc_error_set(err, PHC_ERR_IO, "%s: write error: %s", path, strerror(errno));
            goto fail;
        }
    }
    /* row, state, n_out x (tab, %.17g or 16 hex digits), " #", 16 or 8 hex
       digits, newline */
    l->line_size = 96 + 26 * n_out;
    pthread_once(&hex_once, hex_init);
    /* a batch: up to BATCH_BYTES, then one more record */
    l->pending_cap = BATCH_BYTES + l->line_size;
    if (!(l->pending = malloc(l->pending_cap))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    l->last_write = monotonic_seconds();
    *out = l;
    return PHC_OK;
fail:
    if (l->f)
        fclose(l->f);
    free(l->pending);
    free(l->path);
    free(l);
    return rc;
}

int phc_run_ledger_append(phc_run_ledger *l, size_t row, int failed, const double *y, phc_error *err)
{
    if (row >= l->rows)
        return phc_error_set(err, PHC_ERR_INVALID, "ledger: row %zu of %zu", row, l->rows);
    /* formatted straight into the batch: it has room for one more record
       (pending_bytes < BATCH_BYTES after every append) */
    char *line = l->pending + l->pending_bytes;
    size_t n = (size_t)snprintf(line, l->line_size, "%zu\t%s", row, failed ? "failed" : "ok");
    char hex[17];
    size_t digits;
    if (l->version == 1) { /* a resumed ledger of version 1 stays in its format */
        for (size_t j = 0; j < l->n_out; ++j) {
            const double v = failed ? NAN : y[j];
            n += (size_t)snprintf(line + n, l->line_size - n, "\t%.17g", v);
        }
        if (n + 20 > l->line_size)
            return phc_error_set(err, PHC_ERR_INTERNAL, "%s: ledger record of %zu bytes", l->path, n);
        checksum(line, n, hex);
        digits = 16;
    } else {
        if (n + 17 * l->n_out + 12 > l->line_size)
            return phc_error_set(err, PHC_ERR_INTERNAL, "%s: ledger record of %zu bytes", l->path, n);
        for (size_t j = 0; j < l->n_out; ++j) {
            line[n] = '\t';
            put_hex64(line + n + 1, failed ? NAN : y[j]);
            n += 17;
        }
        checksum2(line, n, hex);
        digits = 8;
    }
    memcpy(line + n, " #", 2);
    memcpy(line + n + 2, hex, digits);
    line[n + 2 + digits] = '\n';
    /* the batch goes to the operating system in one write(2) when it is
       full or BATCH_SECONDS after the last write (the header went through
       the stream, flushed; nothing else is buffered there) */
    l->pending_bytes += n + 3 + digits;
    l->pending_records++;
    if (l->pending_records >= BATCH_RECORDS || l->pending_bytes >= BATCH_BYTES ||
        monotonic_seconds() - l->last_write >= BATCH_SECONDS)
        return write_pending(l, err);
    return PHC_OK;
}

int phc_run_ledger_close(phc_run_ledger *l, phc_error *err)
{
    if (!l)
        return PHC_OK;
    int rc = PHC_OK;
    if (l->f && l->pending_bytes)
        rc = write_pending(l, err);
    if (l->f && fclose(l->f) != 0 && rc == PHC_OK)
        rc = phc_error_set(err, PHC_ERR_IO, "%s: write error: %s", l->path, strerror(errno));
    free(l->pending);
    free(l->path);
    free(l);
    return rc;
}
