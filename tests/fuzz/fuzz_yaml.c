/* libFuzzer harness: YAML documents (measurements/yaml_doc.h).
 * The input is the document's text.  A document that parses is walked the
 * way the config loader walks one: every scalar through every typed
 * accessor, every mapping through phc_yaml_get and phc_yaml_check_keys
 * (with the top-level keys of a config, so the "did you mean" path runs) and
 * the _map_ accessors with a present and an absent required key. */
#include "fuzz_common.h"

#include "measurements/yaml_doc.h"

/* Every failing call keeps the promises of model/status.h (fuzz_common.h). */
#define CHECK(call) phc_fuzz_check_error((call), &err, "fuzz.yaml")

static const char *const allowed[] = {"name", "parameters", "datasets", "solver", "report", NULL};

static void walk(const phc_yaml_doc *doc, const phc_yaml_node *node, size_t depth, size_t *budget)
{
    phc_error err;
    if (!node || *budget == 0)
        return;
    --*budget;
    switch (node->kind) {
    case PHC_YAML_SCALAR: {
        double d;
        long l;
        int b;
        const char *s;
        if (!node->scalar)
            phc_fuzz_fail("a scalar node without text", NULL);
        CHECK(phc_yaml_number(doc, node, "k", &d, &err));
        CHECK(phc_yaml_integer(doc, node, "k", &l, &err));
        CHECK(phc_yaml_boolean(doc, node, "k", &b, &err));
        CHECK(phc_yaml_string(doc, node, "k", &s, &err));
        break;
    }
    case PHC_YAML_SEQUENCE:
        for (size_t i = 0; i < node->count; ++i)
            walk(doc, node->items[i], depth + 1, budget);
        break;
    case PHC_YAML_MAPPING: {
        CHECK(phc_yaml_check_keys(doc, node, allowed, "fuzz", &err));
        for (size_t i = 0; i < node->count; ++i) {
            walk(doc, node->values[i], depth + 1, budget);
            if (i >= 32)
                continue; /* lookups are linear: a few keys suffice */
            if (phc_yaml_get(node, node->keys[i]) == NULL)
                phc_fuzz_fail("every key must be found", NULL);
            double d;
            long l;
            int b;
            const char *s;
            CHECK(phc_yaml_map_number(doc, node, node->keys[i], 1, "fuzz", &d, &err));
            CHECK(phc_yaml_map_integer(doc, node, node->keys[i], 1, "fuzz", &l, &err));
            CHECK(phc_yaml_map_boolean(doc, node, node->keys[i], 1, "fuzz", &b, &err));
            CHECK(phc_yaml_map_string(doc, node, node->keys[i], 1, "fuzz", &s, &err));
        }
        const char *s;
        CHECK(phc_yaml_map_string(doc, node, "no such key", 1, "fuzz", &s, &err));
        break;
    }
    default:
        phc_fuzz_fail("a node of no known kind", NULL);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    phc_error err;
    phc_yaml_doc *doc = NULL;
    int rc = phc_yaml_parse((const char *)data, size, "fuzz.yaml", &doc, &err);
    phc_fuzz_check_error(rc, &err, "fuzz.yaml");
    if (rc != 0) {
        if (doc)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        return 0;
    }
    size_t budget = 100000; /* aliases may expand to 10^6 nodes: walk a part */
    walk(doc, doc->root, 0, &budget);
    phc_yaml_free(doc);
    return 0;
}
