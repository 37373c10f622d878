/* Provenance (fit/engine/provenance.h): SHA-256 against the FIPS 180-2 test
 * vectors, the JSON round trip, the markdown section, and the state of a
 * recorded file (same, changed, missing). */
#define _XOPEN_SOURCE 700
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/engine/problem.h"
#include "fit/engine/provenance.h"

static char dir[] = "/tmp/phc-provenance-XXXXXX";

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs(text, f);
    fclose(f);
}

static void test_sha256(void)
{
    char path[256], hex[65];
    long long bytes = -1;
    phc_error err;
    /* FIPS 180-2 appendix B.1 and the empty message */
    snprintf(path, sizeof path, "%s/abc.txt", dir);
    write_file(path, "abc");
    CHECK(phc_file_sha256(path, hex, &bytes, &err) == PHC_OK);
    CHECK(strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad") == 0);
    CHECK(bytes == 3);
    snprintf(path, sizeof path, "%s/empty.txt", dir);
    write_file(path, "");
    CHECK(phc_file_sha256(path, hex, &bytes, &err) == PHC_OK);
    CHECK(strcmp(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855") == 0);
    CHECK(bytes == 0);
    /* B.2: a message longer than one block */
    snprintf(path, sizeof path, "%s/two_blocks.txt", dir);
    write_file(path, "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq");
    CHECK(phc_file_sha256(path, hex, &bytes, &err) == PHC_OK);
    CHECK(strcmp(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1") == 0);
    snprintf(path, sizeof path, "%s/absent.txt", dir);
    CHECK(phc_file_sha256(path, hex, &bytes, &err) == PHC_ERR_IO);
    CHECK_STR_CONTAINS(err.message, "absent.txt");
}

static void test_round_trip(void)
{
    char cfg[256], data[256];
    snprintf(cfg, sizeof cfg, "%s/run.yaml", dir);
    snprintf(data, sizeof data, "%s/data.csv", dir);
    write_file(cfg, "name: x\n");
    write_file(data, "t,m\n0,1\n");
    phc_problem *pb = phc_problem_new("x");
    CHECK(pb != NULL);
    if (!pb)
        return;
    pb->source = strdup(cfg);
    phc_dataset *ds = phc_dataset_new(NULL, 0);
    CHECK(ds != NULL && phc_dataset_add_input(ds, data) == PHC_OK && phc_dataset_add_input(ds, data) == PHC_OK);
    CHECK(ds->n_inputs == 1); /* kept once */
    pb->datasets = malloc(sizeof *pb->datasets);
    pb->datasets[0] = ds;
    pb->n_datasets = 1;
    pb->seeds = malloc(sizeof *pb->seeds);
    pb->seeds[0] = strdup("datasets[1].seed: 7");
    pb->n_seeds = 1;
    char *argv[] = {"phytocal", "fit", "my config.yaml", "-o", "it's"};
    phc_provenance *pv = NULL;
    phc_error err;
    CHECK(phc_provenance_begin(pb, 5, argv, "9.9.9", "abc123", &pv, &err) == PHC_OK);
    if (!pv) {
        phc_problem_free(pb);
        return;
    }
    phc_provenance_end(pv);
    CHECK(strcmp(pv->command_line, "phytocal fit 'my config.yaml' -o 'it'\\''s'") == 0);
    CHECK(pv->config && strcmp(pv->config->path, cfg) == 0 && pv->n_inputs == 1 && pv->n_seeds == 1);
    CHECK(pv->host_processors >= 1 && pv->started[0] && pv->finished[0]);
    json_t *j = phc_provenance_to_json(pv);
    phc_provenance *back = NULL;
    CHECK(phc_provenance_from_json(j, "test", &back, &err) == PHC_OK);
    if (back) {
        CHECK(strcmp(back->version, "9.9.9") == 0 && strcmp(back->git, "abc123") == 0);
        CHECK(strcmp(back->command_line, pv->command_line) == 0);
        CHECK(strcmp(back->config->sha256, pv->config->sha256) == 0);
        CHECK(back->n_inputs == 1 && strcmp(back->inputs[0].sha256, pv->inputs[0].sha256) == 0);
        CHECK(back->inputs[0].bytes == 8);
        CHECK(back->n_seeds == 1 && strcmp(back->seeds[0], "datasets[1].seed: 7") == 0);
        CHECK(strcmp(back->started, pv->started) == 0 && strcmp(back->finished, pv->finished) == 0);
        const char *where;
        CHECK(phc_provenance_file_state(&back->inputs[0], &where) == PHC_FILE_SAME);
        write_file(data, "t,m\n0,2\n");
        CHECK(phc_provenance_file_state(&back->inputs[0], &where) == PHC_FILE_CHANGED);
        unlink(data);
        CHECK(phc_provenance_file_state(&back->inputs[0], &where) == PHC_FILE_MISSING && where == NULL);
    }
    char *md = NULL;
    CHECK(phc_provenance_markdown(pv, &md, &err) == PHC_OK);
    if (md) {
        CHECK_STR_CONTAINS(md, "## Provenance");
        CHECK_STR_CONTAINS(md, pv->config->sha256);
        CHECK_STR_CONTAINS(md, "datasets[1].seed: 7");
    }
    free(md);
    /* a damaged record names the file and the field */
    json_object_set_new(j, "config", json_string("x"));
    phc_provenance *bad = NULL;
    CHECK(phc_provenance_from_json(j, "result.json", &bad, &err) == PHC_ERR_INPUT && bad == NULL);
    CHECK_STR_CONTAINS(err.message, "result.json");
    json_decref(j);
    phc_provenance_free(back);
    phc_provenance_free(pv);
    phc_problem_free(pb);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_sha256();
    test_round_trip();
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_finish("test_provenance");
}
