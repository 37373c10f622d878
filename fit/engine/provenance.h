/* Provenance of a run: what produced a run directory, so that a result can
 * be traced and reproduced, and checked later against its inputs.
 *
 * Recorded: phytocal's version (and the git commit when built from a
 * checkout), the full command line and working directory, the config file
 * and every data file the loaders read (path, absolute path, size and
 * SHA-256), every `seed:` of the config, the host's online processors and
 * the solver's threads, the host name, and the start and end times (UTC,
 * ISO 8601).  result.json carries it under "provenance", report.md in a
 * section, and the run directory's manifest (run_dir.h) too, so
 * `phytocal report --check DIR` can say whether the inputs still match. */
#ifndef PHC_PROVENANCE_H
#define PHC_PROVENANCE_H

#include <jansson.h>
#include <stddef.h>

#include "fit/engine/problem.h"
#include "model/status.h"

typedef struct phc_provenance_file {
    char *path;      /* as the run named it (relative to its working directory) */
    char *absolute;  /* resolved at run time (NULL when it could not be) */
    char sha256[65]; /* lower-case hex */
    long long bytes;
} phc_provenance_file;

typedef struct phc_provenance {
    char *version;           /* "0.1.0" */
    char *git;               /* "a1b2c3d", "a1b2c3d-modified" or NULL (not built from a checkout) */
    char *command_line;      /* argv, shell-quoted where needed */
    char *working_directory;
    phc_provenance_file *config; /* NULL when the run had no config */
    phc_provenance_file *inputs; /* data files, in the order the loaders read them */
    size_t n_inputs;
    char **seeds;            /* "datasets[1].seed: 7" */
    size_t n_seeds;
    int host_processors;     /* online processors of the host */
    int solver_threads;      /* the config's solver.threads */
    char *host;
    char started[32], finished[32]; /* "2026-11-25T14:03:07Z"; finished empty until set */
} phc_provenance;

/* Records the start of a run of problem pb (may be NULL) with its config at
 * pb->source: hashes the config and every data set's inputs.  argv[0..argc-1]
 * is the command line; version and git as above (git may be NULL or ""). */
int phc_provenance_begin(const phc_problem *pb, int argc, char *const argv[], const char *version,
                         const char *git, phc_provenance **out, phc_error *err);
/* Stamps the end time. */
void phc_provenance_end(phc_provenance *pv);
void phc_provenance_free(phc_provenance *pv); /* accepts NULL */
/* A deep copy of `from` started now (finished empty): the record of a new
 * run over the same inputs, hashed once (`phytocal fit --each`: every
 * group's run shares the config and tables the batch read). */
int phc_provenance_restart(const phc_provenance *from, phc_provenance **out, phc_error *err);

/* SHA-256 of a file's bytes as 64 hex digits, and its size. */
int phc_file_sha256(const char *path, char hex[65], long long *bytes, phc_error *err);

/* JSON form (an object) and back; from_json names `where` (a file) in its
 * messages. */
json_t *phc_provenance_to_json(const phc_provenance *pv);
int phc_provenance_from_json(const json_t *obj, const char *where, phc_provenance **out, phc_error *err);

/* Markdown section "## Provenance" (malloc'd into *markdown). */
int phc_provenance_markdown(const phc_provenance *pv, char **markdown, phc_error *err);

/* A recorded file now: found at its absolute path (or, failing that, its
 * path relative to the current directory), and whether its bytes are the
 * same.  *where_found points into f (or is NULL when missing). */
typedef enum phc_file_state { PHC_FILE_SAME, PHC_FILE_CHANGED, PHC_FILE_MISSING } phc_file_state;
phc_file_state phc_provenance_file_state(const phc_provenance_file *f, const char **where_found);

#endif /* PHC_PROVENANCE_H */
