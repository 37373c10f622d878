/* Shared pieces of the libFuzzer harnesses (tests/fuzz/fuzz_*.c).
 *
 * Readers that take a path get their input through files in one temporary
 * folder per process ($TMPDIR/phc_fuzz_XXXXXX, removed at exit).  Every input
 * starts from an empty folder: phc_fuzz_clear() removes what the previous
 * input wrote.
 *
 * Inputs that stand for several files are split at lines "%% NAME": the text
 * before the first such line is the first (unnamed) part, each "%% NAME"
 * line starts a part named NAME.  Example (the soil-probe harness):
 *     id,x,y,depth
 *     P1,1,1,0.1
 *     %% readings.csv
 *     t,probe,value
 *     0,P1,0.3
 * The harnesses never print; everything they allocate is freed. */
#ifndef PHC_FUZZ_COMMON_H
#define PHC_FUZZ_COMMON_H

#define _GNU_SOURCE
#include <ftw.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "model/status.h"

#define PHC_FUZZ_MAX_PARTS 8

typedef struct phc_fuzz_part {
    char name[64];       /* "" for the first part; else the name after "%% " (trimmed,
                            truncated to 63 bytes) */
    const uint8_t *data; /* points into the input */
    size_t size;
} phc_fuzz_part;

static char phc_fuzz_dir_path[4096];

static inline int phc_fuzz_rm_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st;
    (void)flag;
    if (ftw->level > 0) /* keep the folder itself */
        remove(path);
    return 0;
}

/* Empties the folder (recursively), keeping the folder. */
static inline void phc_fuzz_clear(void)
{
    if (phc_fuzz_dir_path[0])
        nftw(phc_fuzz_dir_path, phc_fuzz_rm_entry, 16, FTW_DEPTH | FTW_PHYS);
}

static inline void phc_fuzz_remove_dir(void)
{
    phc_fuzz_clear();
    if (phc_fuzz_dir_path[0])
        rmdir(phc_fuzz_dir_path);
}

/* The per-process folder, created on first use; aborts when it cannot be
 * made (a harness without its folder would only test the error path). */
static inline const char *phc_fuzz_dir(void)
{
    if (!phc_fuzz_dir_path[0]) {
        const char *tmp = getenv("TMPDIR");
        snprintf(phc_fuzz_dir_path, sizeof phc_fuzz_dir_path, "%s/phc_fuzz_XXXXXX",
                 tmp && *tmp ? tmp : "/tmp");
        if (!mkdtemp(phc_fuzz_dir_path))
            abort();
        atexit(phc_fuzz_remove_dir);
    }
    return phc_fuzz_dir_path;
}

/* Writes size bytes to DIR/name (name may contain one folder level that
 * phc_fuzz_mkdir made); the full path goes to path.  Aborts on failure. */
static inline void phc_fuzz_write(const char *name, const void *data, size_t size, char *path,
                           size_t path_size)
{
    snprintf(path, path_size, "%s/%s", phc_fuzz_dir(), name);
    FILE *f = fopen(path, "wb");
    if (!f)
        abort();
    if (size && fwrite(data, 1, size, f) != size)
        abort();
    if (fclose(f) != 0)
        abort();
}

static inline void phc_fuzz_mkdir(const char *name, char *path, size_t path_size)
{
    snprintf(path, path_size, "%s/%s", phc_fuzz_dir(), name);
    if (mkdir(path, 0700) != 0)
        abort();
}

/* Splits the input at "%% NAME" lines into at most PHC_FUZZ_MAX_PARTS parts
 * (further marker lines stay in the last part); returns the count (>= 1). */
static inline size_t phc_fuzz_split(const uint8_t *data, size_t size, phc_fuzz_part *parts)
{
    size_t n = 1, pos = 0;
    memset(parts, 0, sizeof(phc_fuzz_part) * PHC_FUZZ_MAX_PARTS);
    parts[0].data = data;
    while (pos < size) {
        const uint8_t *nl = memchr(data + pos, '\n', size - pos);
        size_t end = nl ? (size_t)(nl - data) : size; /* end of this line */
        if (n < PHC_FUZZ_MAX_PARTS && end - pos >= 3 && data[pos] == '%' && data[pos + 1] == '%' &&
            data[pos + 2] == ' ') {
            phc_fuzz_part *prev = &parts[n - 1];
            prev->size = (size_t)(data + pos - prev->data);
            if (prev->size && prev->data[prev->size - 1] == '\n')
                prev->size--; /* the line break before the marker belongs to it */
            phc_fuzz_part *p = &parts[n++];
            size_t len = end - pos - 3, k = 0;
            for (size_t i = 0; i < len && k + 1 < sizeof p->name; ++i) {
                uint8_t c = data[pos + 3 + i];
                if (c != '\r')
                    p->name[k++] = (char)c;
            }
            while (k > 0 && p->name[k - 1] == ' ')
                p->name[--k] = 0;
            p->data = nl ? data + end + 1 : data + size;
        }
        pos = end + 1;
    }
    phc_fuzz_part *last = &parts[n - 1];
    last->size = (size_t)(data + size - last->data);
    return n;
}

/* A copy of the input with a terminating NUL (free it). */
static inline char *phc_fuzz_string(const uint8_t *data, size_t size)
{
    char *s = malloc(size + 1);
    if (!s)
        abort();
    if (size)
        memcpy(s, data, size);
    s[size] = 0;
    return s;
}

/* 1 when name is a plain file name: [A-Za-z0-9._-], not "." or "..". */
static inline int phc_fuzz_plain_name(const char *name)
{
    if (!name[0] || !strcmp(name, ".") || !strcmp(name, ".."))
        return 0;
    for (const char *c = name; *c; ++c)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
              *c == '.' || *c == '_' || *c == '-'))
            return 0;
    return 1;
}

/* A broken promise: says which (stderr, read by scripts/fuzz) and aborts, so
 * that libFuzzer keeps the input as a reproducer. */
static inline void phc_fuzz_fail(const char *why, const char *detail)
{
    fprintf(stderr, "phc_fuzz: %s%s%s\n", why, detail ? ": " : "", detail ? detail : "");
    abort();
}

/* The promises of model/status.h for a call that returned rc: on failure
 * err->status is rc, the message is one non-empty line without control
 * characters, and an input or I/O error names the file (`name`, when given). */
static inline void phc_fuzz_check_error(int rc, const phc_error *err, const char *name)
{
    if (rc == 0)
        return;
    if (err->status != rc)
        phc_fuzz_fail("returned status differs from err->status", err->message);
    if (!err->message[0])
        phc_fuzz_fail("empty error message", NULL);
    for (const char *c = err->message; *c; ++c)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            phc_fuzz_fail("control character in the error message (not one line)", err->message);
    if (name && (rc == PHC_ERR_INPUT || rc == PHC_ERR_IO) && !strstr(err->message, name))
        phc_fuzz_fail("input error message does not name the file", err->message);
}

#endif /* PHC_FUZZ_COMMON_H */
