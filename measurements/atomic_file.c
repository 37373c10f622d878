/* Writing a file all at once: see atomic_file.h. */
#include "measurements/atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define SUFFIX ".tmp-"
#define RANDOM_CHARS 6
#define ATTEMPTS 100

struct phc_atomic_file {
    char *path; /* the destination */
    char *tmp;  /* DIR/NAME.tmp-XXXXXX */
    FILE *f;
};

/* splitmix64: spreads a counter, the process id and the clock over all
 * bits (names need only differ, O_EXCL settles any clash). */
static uint64_t mix(uint64_t z)
{
    z += 0x9e3779b97f4a7c15u;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

static void random_chars(char *out)
{
    static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    static atomic_uint_fast64_t counter;
    struct timespec ts = {0, 0};
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t z = mix(atomic_fetch_add(&counter, 1) ^ ((uint64_t)getpid() << 32) ^
                     (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 20));
    for (int i = 0; i < RANDOM_CHARS; ++i) {
        out[i] = alphabet[z % (sizeof alphabet - 1)];
        z /= sizeof alphabet - 1;
    }
}

static void free_af(phc_atomic_file *af)
{
    free(af->path);
    free(af->tmp);
    free(af);
}

int phc_atomic_file_open(const char *path, phc_atomic_file **out, phc_error *err)
{
    if (out)
        *out = NULL;
    if (!path || !*path || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_atomic_file_open: a path and out are required");
    const size_t len = strlen(path);
    if (path[len - 1] == '/')
        return phc_error_set(err, PHC_ERR_INVALID, "%s: cannot open for writing: the path names a directory",
                             path);
    phc_atomic_file *af = calloc(1, sizeof *af);
    if (af) {
        af->path = malloc(len + 1);
        af->tmp = malloc(len + sizeof SUFFIX + RANDOM_CHARS);
    }
    if (!af || !af->path || !af->tmp) {
        if (af)
            free_af(af);
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    }
    memcpy(af->path, path, len + 1);
    memcpy(af->tmp, path, len);
    memcpy(af->tmp + len, SUFFIX, sizeof SUFFIX - 1);
    char *x = af->tmp + len + sizeof SUFFIX - 1;
    x[RANDOM_CHARS] = '\0';
    int fd = -1, saved = 0;
    for (int i = 0; i < ATTEMPTS && fd < 0; ++i) {
        random_chars(x);
        fd = open(af->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        saved = errno;
        if (fd < 0 && saved != EEXIST && saved != EINTR)
            break;
    }
    if (fd < 0) {
        free_af(af);
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open for writing: %s", path, strerror(saved));
    }
    af->f = fdopen(fd, "wb");
    if (!af->f) {
        saved = errno;
        close(fd);
        unlink(af->tmp);
        free_af(af);
        return phc_error_set(err, saved == ENOMEM ? PHC_ERR_NOMEM : PHC_ERR_IO,
                             "%s: cannot open for writing: %s", path, strerror(saved));
    }
    *out = af;
    return PHC_OK;
}

FILE *phc_atomic_file_stream(phc_atomic_file *af)
{
    return af ? af->f : NULL;
}

const char *phc_atomic_file_temp_path(const phc_atomic_file *af)
{
    return af ? af->tmp : NULL;
}

const char *phc_atomic_file_path(const phc_atomic_file *af)
{
    return af ? af->path : NULL;
}

/* phc_atomic_file_defer_sync: this thread's writer syncs a whole folder itself. */
static _Thread_local int sync_deferred;

int phc_atomic_file_defer_sync(int defer)
{
    const int was = sync_deferred;
    sync_deferred = defer != 0;
    return was;
}

/* fsync of the temporary file.  A library that wrote by name may have
 * replaced the file rather than rewritten it: then the file now under that
 * name is the one to flush.  File systems without fsync (EINVAL, ENOTSUP)
 * are not an error: the rename is still atomic there. */
static int sync_temp(int fd, const char *tmp)
{
    struct stat a, b;
    int own = -1, rc;
    if (fstat(fd, &a) == 0 && stat(tmp, &b) == 0 && (a.st_dev != b.st_dev || a.st_ino != b.st_ino)) {
        own = open(tmp, O_RDONLY | O_CLOEXEC);
        if (own < 0)
            return -1;
        fd = own;
    }
    rc = fsync(fd);
    if (rc != 0 && (errno == EINVAL || errno == ENOTSUP || errno == EROFS))
        rc = 0;
    if (own >= 0) {
        const int saved = errno;
        close(own);
        errno = saved;
    }
    return rc;
}

int phc_atomic_file_commit(phc_atomic_file *af, phc_error *err)
{
    if (!af)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_atomic_file_commit: no file");
    int saved = 0;
    /* The first error wins: it is the one that explains the others. */
    errno = 0;
    if (fflush(af->f) != 0 || ferror(af->f))
        saved = errno ? errno : EIO;
    if (!saved && !sync_deferred && sync_temp(fileno(af->f), af->tmp) != 0)
        saved = errno ? errno : EIO;
    errno = 0;
    if (fclose(af->f) != 0 && !saved)
        saved = errno ? errno : EIO;
    af->f = NULL;
    if (saved) {
        const int rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot write: %s", af->path, strerror(saved));
        unlink(af->tmp);
        free_af(af);
        return rc;
    }
    if (rename(af->tmp, af->path) != 0) {
        saved = errno;
        const int rc = phc_error_set(err, PHC_ERR_IO, "%s: cannot rename into place: %s", af->path,
                                     strerror(saved));
        unlink(af->tmp);
        free_af(af);
        return rc;
    }
    free_af(af);
    return PHC_OK;
}

void phc_atomic_file_abort(phc_atomic_file *af)
{
    if (!af)
        return;
    if (af->f)
        fclose(af->f);
    unlink(af->tmp);
    free_af(af);
}

void phc_atomic_file_leave(phc_atomic_file *af)
{
    if (!af)
        return;
    if (af->f)
        fclose(af->f);
    free_af(af);
}
