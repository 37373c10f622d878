/* Unit tests for fit/run_dir.c's durability steps (run_dir.h): between
 * phc_run_dir_begin and its commit or discard the calling thread writes
 * files without an fsync each (measurements/atomic_file.h, deferred sync),
 * and commit or discard gives the thread back the setting it had before;
 * begins nest; a begin that fails changes nothing; other threads keep
 * syncing every file; a committed run holds its files and its manifest. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fit/run_dir.h"
#include "measurements/atomic_file.h"

static char root[] = "/tmp/phc_test_run_dir_sync_XXXXXX";

/* This thread's deferred-sync setting, left as it was. */
static int setting(void)
{
    const int now = phc_atomic_file_defer_sync(0);
    phc_atomic_file_defer_sync(now);
    return now;
}

static void *setting_elsewhere(void *out)
{
    *(int *)out = setting();
    return NULL;
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Writes `name` inside tmpdir through atomic_file, as the commands do. */
static int write_file(const char *tmpdir, const char *name, const char *text)
{
    char path[8300];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    phc_atomic_file *af = NULL;
    phc_error err;
    if (phc_atomic_file_open(path, &af, &err) != PHC_OK)
        return -1;
    fputs(text, phc_atomic_file_stream(af));
    return phc_atomic_file_commit(af, &err);
}

static void test_begin_commit(void)
{
    char dir[4200], tmpdir[4300], path[8400];
    phc_error err;
    snprintf(dir, sizeof dir, "%s/one", root);
    CHECK(setting() == 0);
    CHECK(phc_run_dir_begin(dir, 0, NULL, tmpdir, sizeof tmpdir, &err) == PHC_OK);
    CHECK(setting() == 1); /* files of the run: no fsync each */
    int other = -1;
    pthread_t t;
    CHECK(pthread_create(&t, NULL, setting_elsewhere, &other) == 0);
    CHECK(pthread_join(t, NULL) == 0);
    CHECK(other == 0); /* another thread still syncs every file */
    CHECK(write_file(tmpdir, "a.txt", "a\n") == 0);
    CHECK(phc_run_dir_commit(tmpdir, dir, NULL, &err) == PHC_OK);
    CHECK(setting() == 0); /* back to an fsync per file */
    snprintf(path, sizeof path, "%s/a.txt", dir);
    CHECK(exists(path));
    snprintf(path, sizeof path, "%s/%s", dir, PHC_RUN_MANIFEST);
    CHECK(exists(path));
    CHECK(!exists(tmpdir));
}

static void test_failed_begin_and_discard(void)
{
    char dir[4200], tmpdir[4300], path[8400];
    phc_error err;
    snprintf(dir, sizeof dir, "%s/one", root);
    /* exists, no --force: refused, nothing changes */
    CHECK(phc_run_dir_begin(dir, 0, NULL, tmpdir, sizeof tmpdir, &err) != PHC_OK);
    CHECK(setting() == 0);
    /* a forced run that fails: discarded, the earlier run kept */
    CHECK(phc_run_dir_begin(dir, 1, NULL, tmpdir, sizeof tmpdir, &err) == PHC_OK);
    CHECK(setting() == 1);
    CHECK(write_file(tmpdir, "b.txt", "b\n") == 0);
    phc_run_dir_discard(tmpdir);
    CHECK(setting() == 0);
    CHECK(!exists(tmpdir));
    snprintf(path, sizeof path, "%s/a.txt", dir);
    CHECK(exists(path));
}

static void test_nested_and_caller_setting(void)
{
    char outer[4200], inner[4200], tmp_outer[4300], tmp_inner[4300];
    phc_error err;
    snprintf(outer, sizeof outer, "%s/outer", root);
    snprintf(inner, sizeof inner, "%s/inner", root);
    /* a caller that deferred syncs itself keeps its setting after the run */
    phc_atomic_file_defer_sync(1);
    CHECK(phc_run_dir_begin(outer, 0, NULL, tmp_outer, sizeof tmp_outer, &err) == PHC_OK);
    CHECK(phc_run_dir_commit(tmp_outer, outer, NULL, &err) == PHC_OK);
    CHECK(setting() == 1);
    phc_atomic_file_defer_sync(0);
    /* nested begins: the setting comes back after the last one ends */
    CHECK(phc_run_dir_begin(outer, 1, NULL, tmp_outer, sizeof tmp_outer, &err) == PHC_OK);
    CHECK(phc_run_dir_begin(inner, 0, NULL, tmp_inner, sizeof tmp_inner, &err) == PHC_OK);
    CHECK(phc_run_dir_commit(tmp_inner, inner, NULL, &err) == PHC_OK);
    CHECK(setting() == 1); /* outer still open */
    CHECK(phc_run_dir_commit(tmp_outer, outer, NULL, &err) == PHC_OK);
    CHECK(setting() == 0);
    /* a discard with no run open changes nothing */
    phc_run_dir_discard(tmp_inner);
    CHECK(setting() == 0);
}

int main(void)
{
    if (!mkdtemp(root)) {
        perror("mkdtemp");
        return 1;
    }
    test_begin_commit();
    test_failed_begin_and_discard();
    test_nested_and_caller_setting();
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", root);
    return check_finish("test_run_dir_sync");
}
