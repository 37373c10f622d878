/* Unit tests for measurements/atomic_file.c: commit writes, abort leaves
 * nothing and the earlier file as it was, clear messages for directories
 * that cannot be written, distinct temporary names, failed commits (a
 * full disk, a directory in the way) that keep the earlier file, and the
 * deferred sync: a setting of the calling thread only, restored by its
 * caller, that still writes and renames every file. */
#include <dirent.h>
#include <errno.h>
#include <pthread.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "measurements/atomic_file.h"

static char dir[] = "/tmp/phc_test_atomic_file_XXXXXX";

static const char *in_dir(const char *name)
{
    static char slots[8][512];
    static int next = 0;
    char *p = slots[next++ % 8];
    snprintf(p, sizeof slots[0], "%s/%s", dir, name);
    return p;
}

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* The whole file as a string ("" when missing; static buffer). */
static const char *contents(const char *path)
{
    static char buf[4096];
    size_t n = 0;
    FILE *f = fopen(path, "rb");
    buf[0] = '\0';
    if (f) {
        n = fread(buf, 1, sizeof buf - 1, f);
        fclose(f);
    }
    buf[n] = '\0';
    return buf;
}

/* Number of entries in dir whose name starts with prefix. */
static int count_entries(const char *prefix)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    if (!d)
        return -1;
    while ((e = readdir(d)))
        n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    closedir(d);
    return n;
}

static void test_commit(void)
{
    const char *path = in_dir("a.txt");
    phc_atomic_file *af = NULL;
    phc_error err;
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (!af)
        return;
    /* the temporary file lives next to the destination, named NAME.tmp-XXXXXX */
    const char *tmp = phc_atomic_file_temp_path(af);
    CHECK(strncmp(tmp, path, strlen(path)) == 0 && strncmp(tmp + strlen(path), ".tmp-", 5) == 0 &&
          strlen(tmp) == strlen(path) + 5 + 6);
    CHECK(strcmp(phc_atomic_file_path(af), path) == 0);
    CHECK(access(tmp, F_OK) == 0);
    CHECK(access(path, F_OK) != 0); /* nothing at the destination before commit */
    fprintf(phc_atomic_file_stream(af), "hello %d\n", 42);
    CHECK(phc_atomic_file_commit(af, &err) == PHC_OK);
    CHECK(strcmp(contents(path), "hello 42\n") == 0);
    CHECK(count_entries("a.txt.tmp-") == 0);

    /* mode 0666 less the umask, as fopen(path, "w") would give */
    {
        struct stat st;
        mode_t mask = umask(022);
        umask(mask);
        CHECK(stat(path, &st) == 0 && (st.st_mode & 0777) == (0666 & ~mask));
    }

    /* a second commit replaces the first file */
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (af) {
        fputs("second\n", phc_atomic_file_stream(af));
        CHECK(phc_atomic_file_commit(af, &err) == PHC_OK);
    }
    CHECK(strcmp(contents(path), "second\n") == 0);

    /* a library that writes by name (truncating the temporary file) */
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (af) {
        FILE *g = fopen(phc_atomic_file_temp_path(af), "w");
        CHECK(g != NULL);
        if (g) {
            fputs("by name\n", g);
            fclose(g);
        }
        CHECK(phc_atomic_file_commit(af, &err) == PHC_OK);
    }
    CHECK(strcmp(contents(path), "by name\n") == 0);

    /* ... or that replaces it with a new file of the same name */
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (af) {
        unlink(phc_atomic_file_temp_path(af));
        put(phc_atomic_file_temp_path(af), "replaced\n");
        CHECK(phc_atomic_file_commit(af, &err) == PHC_OK);
    }
    CHECK(strcmp(contents(path), "replaced\n") == 0);
    CHECK(count_entries("a.txt.tmp-") == 0);
    unlink(path);
}

static void test_abort(void)
{
    const char *path = in_dir("b.txt");
    phc_atomic_file *af = NULL;
    phc_error err;
    /* no earlier file: abort leaves nothing */
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (af) {
        fputs("half", phc_atomic_file_stream(af));
        phc_atomic_file_abort(af);
    }
    CHECK(access(path, F_OK) != 0);
    CHECK(count_entries("b.txt") == 0);
    /* an earlier file survives an aborted write unchanged */
    put(path, "earlier\n");
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (af) {
        fputs("half", phc_atomic_file_stream(af));
        fflush(phc_atomic_file_stream(af));
        CHECK(strcmp(contents(path), "earlier\n") == 0); /* not even half-written meanwhile */
        phc_atomic_file_abort(af);
    }
    CHECK(strcmp(contents(path), "earlier\n") == 0);
    CHECK(count_entries("b.txt") == 1);
    phc_atomic_file_abort(NULL); /* accepted */
    phc_atomic_file_leave(NULL);

    /* leave keeps the temporary file for inspection */
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (af) {
        char kept[600];
        snprintf(kept, sizeof kept, "%s", phc_atomic_file_temp_path(af));
        fputs("for inspection\n", phc_atomic_file_stream(af));
        phc_atomic_file_leave(af);
        CHECK(strcmp(contents(kept), "for inspection\n") == 0);
        unlink(kept);
    }
    CHECK(strcmp(contents(path), "earlier\n") == 0);
    unlink(path);
}

static void test_unwritable(void)
{
    phc_atomic_file *af = (phc_atomic_file *)&af;
    phc_error err;
    /* a directory that does not exist */
    const char *missing = in_dir("no/such/dir.csv");
    CHECK(phc_atomic_file_open(missing, &af, &err) == PHC_ERR_IO);
    CHECK(af == NULL);
    {
        char want[700];
        snprintf(want, sizeof want, "%s: cannot open for writing: %s", missing, strerror(ENOENT));
        CHECK(strcmp(err.message, want) == 0);
        printf("missing directory: %s\n", err.message);
    }
    /* a parent that is a file */
    put(in_dir("plain"), "x");
    CHECK(phc_atomic_file_open(in_dir("plain/x.csv"), &af, &err) == PHC_ERR_IO);
    CHECK_STR_CONTAINS(err.message, "plain/x.csv: cannot open for writing: ");
    CHECK_STR_CONTAINS(err.message, strerror(ENOTDIR));
    unlink(in_dir("plain"));
    /* a directory without write permission (root writes anywhere: skipped) */
    if (geteuid() != 0) {
        const char *ro = in_dir("readonly");
        CHECK(mkdir(ro, 0555) == 0);
        CHECK(phc_atomic_file_open(in_dir("readonly/x.csv"), &af, &err) == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "readonly/x.csv: cannot open for writing: ");
        CHECK_STR_CONTAINS(err.message, strerror(EACCES));
        printf("read-only directory: %s\n", err.message);
        rmdir(ro);
    }
    /* arguments */
    CHECK(phc_atomic_file_open(NULL, &af, &err) == PHC_ERR_INVALID);
    CHECK(phc_atomic_file_open("", &af, &err) == PHC_ERR_INVALID);
    CHECK(phc_atomic_file_open(in_dir("sub/"), &af, &err) == PHC_ERR_INVALID);
    CHECK(phc_atomic_file_commit(NULL, &err) == PHC_ERR_INVALID);
}

static void test_distinct_names(void)
{
    enum { N = 64 };
    const char *path = in_dir("c.txt");
    phc_atomic_file *af[N] = {0};
    phc_error err;
    int opened = 0, same = 0;
    for (int i = 0; i < N; ++i)
        opened += phc_atomic_file_open(path, &af[i], &err) == PHC_OK;
    CHECK(opened == N);
    for (int i = 0; i < N; ++i)
        for (int j = i + 1; j < N; ++j)
            same += af[i] && af[j] &&
                    strcmp(phc_atomic_file_temp_path(af[i]), phc_atomic_file_temp_path(af[j])) == 0;
    CHECK(same == 0);
    CHECK(count_entries("c.txt.tmp-") == N);
    /* each writes its own file; the last commit is what stays */
    for (int i = 0; i < N; ++i)
        if (af[i]) {
            fprintf(phc_atomic_file_stream(af[i]), "writer %d\n", i);
            CHECK(phc_atomic_file_commit(af[i], &err) == PHC_OK);
        }
    {
        char want[32];
        snprintf(want, sizeof want, "writer %d\n", N - 1);
        CHECK(strcmp(contents(path), want) == 0);
    }
    CHECK(count_entries("c.txt") == 1);
    unlink(path);
}

static void test_failed_commit(void)
{
    const char *path = in_dir("d.txt");
    phc_atomic_file *af = NULL;
    phc_error err;
    put(path, "earlier\n");

    /* a full disk: the stream's file descriptor is pointed at /dev/full */
    int full = open("/dev/full", O_WRONLY);
    if (full >= 0) {
        CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
        if (af) {
            FILE *f = phc_atomic_file_stream(af);
            CHECK(dup2(full, fileno(f)) >= 0);
            for (int i = 0; i < 10000; ++i)
                fprintf(f, "line %d of a file that does not fit\n", i);
            CHECK(phc_atomic_file_commit(af, &err) == PHC_ERR_IO);
            char want[700];
            snprintf(want, sizeof want, "%s: cannot write: %s", path, strerror(ENOSPC));
            CHECK(strcmp(err.message, want) == 0);
            printf("full disk: %s\n", err.message);
        }
        close(full);
        CHECK(strcmp(contents(path), "earlier\n") == 0);
        CHECK(count_entries("d.txt") == 1);
    }

    /* a stream error that the caller did not check (reading a write-only
     * stream sets its error indicator) */
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    if (af) {
        FILE *f = phc_atomic_file_stream(af);
        fputs("new\n", f);
        CHECK(fgetc(f) == EOF && ferror(f));
        CHECK(phc_atomic_file_commit(af, &err) == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "d.txt: cannot write: ");
    }
    CHECK(strcmp(contents(path), "earlier\n") == 0);
    CHECK(count_entries("d.txt") == 1);

    /* rename onto a directory: the directory (and what is in it) stays */
    const char *sub = in_dir("e.dir");
    CHECK(mkdir(sub, 0777) == 0);
    put(in_dir("e.dir/inside"), "kept\n");
    CHECK(phc_atomic_file_open(sub, &af, &err) == PHC_OK);
    if (af) {
        fputs("new\n", phc_atomic_file_stream(af));
        CHECK(phc_atomic_file_commit(af, &err) == PHC_ERR_IO);
        CHECK_STR_CONTAINS(err.message, "e.dir: cannot rename into place: ");
        printf("directory in the way: %s\n", err.message);
    }
    CHECK(strcmp(contents(in_dir("e.dir/inside")), "kept\n") == 0);
    CHECK(count_entries("e.dir") == 1);
    unlink(in_dir("e.dir/inside"));
    rmdir(sub);
    unlink(path);
}

/* Another thread's setting: the default (every commit syncs), whatever
 * the main thread chose. */
static void *setting_elsewhere(void *out)
{
    *(int *)out = phc_atomic_file_defer_sync(0);
    return NULL;
}

static void test_deferred_sync(void)
{
    phc_error err;
    CHECK(phc_atomic_file_defer_sync(1) == 0); /* the default: sync */
    CHECK(phc_atomic_file_defer_sync(1) == 1); /* returns what it was */
    int other = -1;
    pthread_t t;
    CHECK(pthread_create(&t, NULL, setting_elsewhere, &other) == 0);
    CHECK(pthread_join(t, NULL) == 0);
    CHECK(other == 0);
    /* deferred: the file is still written whole and renamed into place */
    const char *path = in_dir("e.txt");
    put(path, "earlier\n");
    phc_atomic_file *af = NULL;
    CHECK(phc_atomic_file_open(path, &af, &err) == PHC_OK);
    fputs("deferred\n", phc_atomic_file_stream(af));
    CHECK(strcmp(contents(path), "earlier\n") == 0);
    CHECK(phc_atomic_file_commit(af, &err) == PHC_OK);
    CHECK(strcmp(contents(path), "deferred\n") == 0);
    CHECK(count_entries("e.txt") == 1);
    CHECK(phc_atomic_file_defer_sync(0) == 1);
    CHECK(phc_atomic_file_defer_sync(0) == 0);
    unlink(path);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_commit();
    test_abort();
    test_unwritable();
    test_distinct_names();
    test_failed_commit();
    test_deferred_sync();
    CHECK(count_entries("") == 2); /* "." and "..": nothing left behind */
    rmdir(dir);
    return check_finish("test_atomic_file");
}
