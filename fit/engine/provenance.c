/* Provenance of a run: see provenance.h.  SHA-256 from nettle. */
#define _XOPEN_SOURCE 700 /* realpath, gethostname */
#include "fit/engine/provenance.h"

#include <errno.h>
#include <limits.h>
#include <nettle/sha2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static void utc_now(char out[32])
{
    const time_t t = time(NULL);
    struct tm tm;
    if (!gmtime_r(&t, &tm) || !strftime(out, 32, "%Y-%m-%dT%H:%M:%SZ", &tm))
        out[0] = '\0';
}

int phc_file_sha256(const char *path, char hex[65], long long *bytes, phc_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    unsigned char buf[1 << 16];
    size_t got;
    long long total = 0;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        sha256_update(&ctx, got, buf);
        total += (long long)got;
    }
    const int bad = ferror(f);
    fclose(f);
    if (bad)
        return phc_error_set(err, PHC_ERR_IO, "%s: read error", path);
    unsigned char digest[SHA256_DIGEST_SIZE];
    sha256_digest(&ctx, sizeof digest, digest);
    for (size_t i = 0; i < sizeof digest; ++i)
        snprintf(hex + 2 * i, 3, "%02x", digest[i]);
    if (bytes)
        *bytes = total;
    return PHC_OK;
}

static int record_file(phc_provenance_file *f, const char *path, phc_error *err)
{
    memset(f, 0, sizeof *f);
    if (!(f->path = strdup(path)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    char resolved[PATH_MAX];
    if (realpath(path, resolved) && !(f->absolute = strdup(resolved)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return phc_file_sha256(path, f->sha256, &f->bytes, err);
}

static void clear_file(phc_provenance_file *f)
{
    if (!f)
        return;
    free(f->path);
    free(f->absolute);
}

/* Characters that need no quoting in a POSIX shell word. */
static int shell_safe(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; ++s)
        if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./=:,+@%", *s))
            return 0;
    return 1;
}

static char *join_command_line(int argc, char *const argv[])
{
    size_t size = 1;
    for (int i = 0; i < argc; ++i)
        size += 4 * strlen(argv[i]) + 3;
    char *s = malloc(size), *p = s;
    if (!s)
        return NULL;
    *p = '\0';
    for (int i = 0; i < argc; ++i) {
        if (i)
            *p++ = ' ';
        if (shell_safe(argv[i])) {
            p += sprintf(p, "%s", argv[i]);
            continue;
        }
        *p++ = '\'';
        for (const char *c = argv[i]; *c; ++c) {
            if (*c == '\'')
                p += sprintf(p, "'\\''");
            else
                *p++ = *c;
        }
        *p++ = '\'';
        *p = '\0';
    }
    return s;
}

int phc_provenance_begin(const phc_problem *pb, int argc, char *const argv[], const char *version,
                         const char *git, phc_provenance **out, phc_error *err)
{
    int rc = PHC_OK;
    *out = NULL;
    phc_provenance *pv = calloc(1, sizeof *pv);
    if (!pv)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    utc_now(pv->started);
    char cwd[PATH_MAX], host[256];
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    pv->host_processors = cpus > 0 ? (int)cpus : 0;
    if (gethostname(host, sizeof host) != 0)
        snprintf(host, sizeof host, "unknown");
    host[sizeof host - 1] = '\0';
    if (!(pv->version = strdup(version ? version : "unknown")) || !(pv->host = strdup(host)) ||
        !(pv->command_line = join_command_line(argc, argv)) ||
        (git && git[0] && !(pv->git = strdup(git))) ||
        !(pv->working_directory = strdup(getcwd(cwd, sizeof cwd) ? cwd : "unknown"))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if (pb) {
        pv->solver_threads = pb->options.nls.num_threads;
        if (pb->source) {
            if (!(pv->config = calloc(1, sizeof *pv->config))) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto fail;
            }
            if ((rc = record_file(pv->config, pb->source, err)))
                goto fail;
        }
        size_t total = 0;
        for (size_t d = 0; d < pb->n_datasets; ++d)
            total += pb->datasets[d]->n_inputs;
        if (total && !(pv->inputs = calloc(total, sizeof *pv->inputs))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t d = 0; d < pb->n_datasets; ++d)
            for (size_t i = 0; i < pb->datasets[d]->n_inputs; ++i) {
                const char *path = pb->datasets[d]->inputs[i];
                int seen = 0; /* two data sets may read one file */
                for (size_t j = 0; j < pv->n_inputs && !seen; ++j)
                    seen = strcmp(pv->inputs[j].path, path) == 0;
                if (seen)
                    continue;
                rc = record_file(&pv->inputs[pv->n_inputs], path, err);
                pv->n_inputs++;
                if (rc)
                    goto fail;
            }
        if (pb->n_seeds && !(pv->seeds = calloc(pb->n_seeds, sizeof *pv->seeds))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t i = 0; i < pb->n_seeds; ++i, pv->n_seeds++)
            if (!(pv->seeds[i] = strdup(pb->seeds[i]))) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto fail;
            }
    }
    *out = pv;
    return PHC_OK;
fail:
    phc_provenance_free(pv);
    return rc;
}

void phc_provenance_end(phc_provenance *pv)
{
    if (pv)
        utc_now(pv->finished);
}

static char *copy_text(const char *s, int *failed)
{
    char *c = s ? strdup(s) : NULL;
    *failed |= s && !c;
    return c;
}

static int copy_file_record(phc_provenance_file *to, const phc_provenance_file *from)
{
    int failed = 0;
    *to = *from;
    to->path = copy_text(from->path, &failed);
    to->absolute = copy_text(from->absolute, &failed);
    return failed;
}

int phc_provenance_restart(const phc_provenance *from, phc_provenance **out, phc_error *err)
{
    int failed = 0;
    phc_provenance *pv = calloc(1, sizeof *pv);
    if (!pv)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    *pv = *from;
    pv->version = copy_text(from->version, &failed);
    pv->git = copy_text(from->git, &failed);
    pv->command_line = copy_text(from->command_line, &failed);
    pv->working_directory = copy_text(from->working_directory, &failed);
    pv->host = copy_text(from->host, &failed);
    pv->config = from->config ? calloc(1, sizeof *pv->config) : NULL;
    pv->inputs = from->n_inputs ? calloc(from->n_inputs, sizeof *pv->inputs) : NULL;
    pv->seeds = from->n_seeds ? calloc(from->n_seeds, sizeof *pv->seeds) : NULL;
    failed |= (from->config && !pv->config) || (from->n_inputs && !pv->inputs) || (from->n_seeds && !pv->seeds);
    if (!failed && pv->config)
        failed |= copy_file_record(pv->config, from->config);
    for (size_t i = 0; !failed && i < from->n_inputs; ++i)
        failed |= copy_file_record(&pv->inputs[i], &from->inputs[i]);
    for (size_t i = 0; !failed && i < from->n_seeds; ++i)
        pv->seeds[i] = copy_text(from->seeds[i], &failed);
    if (failed) { /* phc_provenance_free frees what was copied (NULL where not) */
        if (!pv->inputs)
            pv->n_inputs = 0;
        if (!pv->seeds)
            pv->n_seeds = 0;
        phc_provenance_free(pv);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    utc_now(pv->started);
    pv->finished[0] = '\0';
    *out = pv;
    return PHC_OK;
}

void phc_provenance_free(phc_provenance *pv)
{
    if (!pv)
        return;
    free(pv->version);
    free(pv->git);
    free(pv->command_line);
    free(pv->working_directory);
    clear_file(pv->config);
    free(pv->config);
    for (size_t i = 0; i < pv->n_inputs; ++i)
        clear_file(&pv->inputs[i]);
    free(pv->inputs);
    for (size_t i = 0; i < pv->n_seeds; ++i)
        free(pv->seeds[i]);
    free(pv->seeds);
    free(pv->host);
    free(pv);
}

/* ---- JSON --------------------------------------------------------------------------- */

static json_t *file_to_json(const phc_provenance_file *f)
{
    json_t *o = json_object();
    json_object_set_new(o, "path", json_string(f->path));
    json_object_set_new(o, "absolute", f->absolute ? json_string(f->absolute) : json_null());
    json_object_set_new(o, "sha256", json_string(f->sha256));
    json_object_set_new(o, "bytes", json_integer(f->bytes));
    return o;
}

json_t *phc_provenance_to_json(const phc_provenance *pv)
{
    json_t *o = json_object();
    if (!o)
        return NULL;
    json_object_set_new(o, "version", json_string(pv->version));
    json_object_set_new(o, "git", pv->git ? json_string(pv->git) : json_null());
    json_object_set_new(o, "command_line", json_string(pv->command_line));
    json_object_set_new(o, "working_directory", json_string(pv->working_directory));
    json_object_set_new(o, "config", pv->config ? file_to_json(pv->config) : json_null());
    json_t *inputs = json_array();
    for (size_t i = 0; i < pv->n_inputs; ++i)
        json_array_append_new(inputs, file_to_json(&pv->inputs[i]));
    json_object_set_new(o, "inputs", inputs);
    json_t *seeds = json_array();
    for (size_t i = 0; i < pv->n_seeds; ++i)
        json_array_append_new(seeds, json_string(pv->seeds[i]));
    json_object_set_new(o, "seeds", seeds);
    json_object_set_new(o, "host", json_string(pv->host));
    json_object_set_new(o, "host_processors", json_integer(pv->host_processors));
    json_object_set_new(o, "solver_threads", json_integer(pv->solver_threads));
    json_object_set_new(o, "started", json_string(pv->started));
    json_object_set_new(o, "finished", pv->finished[0] ? json_string(pv->finished) : json_null());
    return o;
}

/* A string member (NULL for null or absent when optional). */
static int get_string(const json_t *o, const char *key, int required, const char *where, char **out,
                      phc_error *err)
{
    const json_t *v = json_object_get(o, key);
    *out = NULL;
    if (!v || json_is_null(v)) {
        if (required)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: provenance: missing '%s'", where, key);
        return PHC_OK;
    }
    if (!json_is_string(v))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: provenance: '%s' must be a string", where, key);
    if (!(*out = strdup(json_string_value(v))))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

static int file_from_json(const json_t *o, const char *where, phc_provenance_file *f, phc_error *err)
{
    memset(f, 0, sizeof *f);
    if (!json_is_object(o))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: provenance: a file entry must be an object", where);
    char *sha = NULL;
    int rc;
    if ((rc = get_string(o, "path", 1, where, &f->path, err)) ||
        (rc = get_string(o, "absolute", 0, where, &f->absolute, err)) ||
        (rc = get_string(o, "sha256", 1, where, &sha, err)))
        return rc;
    const size_t len = strlen(sha);
    snprintf(f->sha256, sizeof f->sha256, "%s", sha);
    free(sha);
    if (len != 64)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: provenance: '%s': sha256 must be 64 hex digits", where,
                             f->path);
    const json_t *b = json_object_get(o, "bytes");
    f->bytes = json_is_integer(b) ? (long long)json_integer_value(b) : -1;
    return PHC_OK;
}

static void copy_time(const json_t *o, const char *key, char out[32])
{
    const json_t *v = json_object_get(o, key);
    snprintf(out, 32, "%s", json_is_string(v) ? json_string_value(v) : "");
}

int phc_provenance_from_json(const json_t *o, const char *where, phc_provenance **out, phc_error *err)
{
    *out = NULL;
    if (!json_is_object(o))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: 'provenance' must be an object", where);
    phc_provenance *pv = calloc(1, sizeof *pv);
    if (!pv)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    int rc;
    if ((rc = get_string(o, "version", 1, where, &pv->version, err)) ||
        (rc = get_string(o, "git", 0, where, &pv->git, err)) ||
        (rc = get_string(o, "command_line", 1, where, &pv->command_line, err)) ||
        (rc = get_string(o, "working_directory", 0, where, &pv->working_directory, err)) ||
        (rc = get_string(o, "host", 0, where, &pv->host, err)))
        goto fail;
    const json_t *cfg = json_object_get(o, "config");
    if (cfg && !json_is_null(cfg)) {
        if (!(pv->config = calloc(1, sizeof *pv->config))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        if ((rc = file_from_json(cfg, where, pv->config, err)))
            goto fail;
    }
    const json_t *inputs = json_object_get(o, "inputs");
    if (inputs && !json_is_array(inputs)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: provenance: 'inputs' must be an array", where);
        goto fail;
    }
    const size_t ni = inputs ? json_array_size(inputs) : 0;
    if (ni && !(pv->inputs = calloc(ni, sizeof *pv->inputs))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < ni; ++i) {
        rc = file_from_json(json_array_get(inputs, i), where, &pv->inputs[i], err);
        pv->n_inputs++;
        if (rc)
            goto fail;
    }
    const json_t *seeds = json_object_get(o, "seeds");
    const size_t ns = json_is_array(seeds) ? json_array_size(seeds) : 0;
    if (ns && !(pv->seeds = calloc(ns, sizeof *pv->seeds))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < ns; ++i) {
        const json_t *s = json_array_get(seeds, i);
        if (!json_is_string(s)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s: provenance: seeds must be strings", where);
            goto fail;
        }
        if (!(pv->seeds[pv->n_seeds++] = strdup(json_string_value(s)))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
    }
    const json_t *hp = json_object_get(o, "host_processors"), *st = json_object_get(o, "solver_threads");
    pv->host_processors = json_is_integer(hp) ? (int)json_integer_value(hp) : 0;
    pv->solver_threads = json_is_integer(st) ? (int)json_integer_value(st) : 0;
    copy_time(o, "started", pv->started);
    copy_time(o, "finished", pv->finished);
    *out = pv;
    return PHC_OK;
fail:
    phc_provenance_free(pv);
    return rc;
}

/* ---- markdown ----------------------------------------------------------------------- */

static void markdown_file(FILE *f, const char *role, const phc_provenance_file *pf)
{
    fprintf(f, "| %s | `%s` | %lld | `%s` |\n", role, pf->path, pf->bytes, pf->sha256);
}

int phc_provenance_markdown(const phc_provenance *pv, char **markdown, phc_error *err)
{
    size_t size = 0;
    *markdown = NULL;
    FILE *f = open_memstream(markdown, &size);
    if (!f)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    fprintf(f, "## Provenance\n\n");
    fprintf(f, "- phytocal %s%s%s\n", pv->version, pv->git ? ", git " : "", pv->git ? pv->git : "");
    fprintf(f, "- command: `%s`\n", pv->command_line);
    fprintf(f, "- working directory: `%s`\n", pv->working_directory ? pv->working_directory : "?");
    fprintf(f, "- host: %s, %d processors online; solver threads %d\n", pv->host ? pv->host : "?",
            pv->host_processors, pv->solver_threads);
    fprintf(f, "- started %s, finished %s (UTC)\n", pv->started, pv->finished[0] ? pv->finished : "?");
    if (pv->n_seeds) {
        fprintf(f, "- seeds:");
        for (size_t i = 0; i < pv->n_seeds; ++i)
            fprintf(f, "%s `%s`", i ? "," : "", pv->seeds[i]);
        fputc('\n', f);
    } else {
        fprintf(f, "- seeds: none set in the config (every random draw, if any, uses its documented "
                   "default seed)\n");
    }
    fprintf(f, "\n| role | file | bytes | SHA-256 |\n|---|---|---:|---|\n");
    if (pv->config)
        markdown_file(f, "config", pv->config);
    for (size_t i = 0; i < pv->n_inputs; ++i)
        markdown_file(f, "data", &pv->inputs[i]);
    fprintf(f, "\n`phytocal report --check DIR` compares these files with their recorded SHA-256.\n\n");
    if (fclose(f) != 0 || !*markdown) {
        free(*markdown);
        *markdown = NULL;
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    return PHC_OK;
}

/* ---- checking ----------------------------------------------------------------------- */

phc_file_state phc_provenance_file_state(const phc_provenance_file *f, const char **where_found)
{
    const char *candidates[2] = {f->absolute, f->path};
    *where_found = NULL;
    for (int i = 0; i < 2; ++i) {
        if (!candidates[i] || access(candidates[i], R_OK) != 0)
            continue;
        char hex[65];
        long long bytes;
        phc_error err;
        phc_error_clear(&err);
        if (phc_file_sha256(candidates[i], hex, &bytes, &err) != PHC_OK)
            continue;
        *where_found = candidates[i];
        return strcmp(hex, f->sha256) == 0 ? PHC_FILE_SAME : PHC_FILE_CHANGED;
    }
    return PHC_FILE_MISSING;
}
