/* YAML configuration documents: see yaml_doc.h.
 *
 * Built on libyaml's event API rather than its document API: the event API
 * lets us register an anchor only once its node is complete (so a node that
 * contains an alias to itself is an error, not an endless copy), bound the
 * nesting depth and the number of nodes that aliases may expand to (the
 * "billion laughs" document), and catch duplicate keys as they arrive. */
#include "measurements/yaml_doc.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <yaml.h>

#include "measurements/c_number.h"
#include "measurements/suggest.h"
#include "measurements/text_file.h"

/* A configuration is a few levels deep; the limits only stop hostile or
 * broken input from exhausting the stack (node_free and node_copy recurse)
 * or memory. */
#define YAML_MAX_DEPTH 256
#define YAML_MAX_NODES 1000000

/* Scalars quoted in messages are cut to this many bytes. */
#define YAML_SHOW_MAX 60

/* A sequence or mapping whose events are still arriving. */
struct frame {
    phc_yaml_node *node;
    size_t cap;          /* allocated items, or keys/key_lines/values */
    char *anchor;        /* registered when the node is complete */
    char *key;           /* mapping: a key waiting for its value */
    size_t key_line;
};

struct anchor {
    char *name;
    const phc_yaml_node *node;
    phc_yaml_node *owned; /* an anchored mapping key: no longer in the tree */
};

struct builder {
    const char *name;
    struct frame *stack;
    size_t depth, stack_cap;
    struct anchor *anchors;
    size_t n_anchors, anchors_cap;
    phc_yaml_node *root;
    size_t n_nodes;
    phc_error *err;
};

/* Returns `p` grown to at least `need` elements of `size` bytes (capacity
 * doubling, *cap updated), or NULL with `p` untouched when out of memory.
 * Returning the pointer, rather than writing through a void **, keeps the
 * callers' typed pointers free of aliasing casts. */
static void *grow(void *p, size_t *cap, size_t need, size_t size)
{
    size_t n = *cap ? *cap : 8;
    void *q;
    if (need <= *cap)
        return p;
    while (n < need) {
        if (n > SIZE_MAX / 2)
            return NULL;
        n *= 2;
    }
    if (n > SIZE_MAX / size)
        return NULL;
    q = realloc(p, n * size);
    if (q)
        *cap = n;
    return q;
}

static char *copy_string(const char *s, size_t n)
{
    char *c = malloc(n + 1);
    if (c) {
        memcpy(c, s, n);
        c[n] = '\0';
    }
    return c;
}

static void node_free(phc_yaml_node *node)
{
    size_t i;
    if (!node)
        return;
    free(node->scalar);
    if (node->kind == PHC_YAML_SEQUENCE) {
        for (i = 0; i < node->count; ++i)
            node_free(node->items[i]);
    } else if (node->kind == PHC_YAML_MAPPING) {
        for (i = 0; i < node->count; ++i) {
            free(node->keys[i]);
            node_free(node->values[i]);
        }
    }
    free(node->items);
    free(node->keys);
    free(node->key_lines);
    free(node->values);
    free(node);
}

static int out_of_memory(struct builder *b)
{
    phc_error_set(b->err, PHC_ERR_NOMEM, "%s: out of memory", b->name);
    return PHC_ERR_NOMEM;
}

/* A new empty node at libyaml's (0-based) mark. */
static int new_node(struct builder *b, phc_yaml_kind kind, yaml_mark_t mark,
                    phc_yaml_node **out)
{
    phc_yaml_node *node;
    *out = NULL;
    if (b->n_nodes >= YAML_MAX_NODES) {
        phc_error_set(b->err, PHC_ERR_INPUT,
                      "%s:%zu:%zu: more than %d YAML nodes (aliases expanding "
                      "without bound?)",
                      b->name, mark.line + 1, mark.column + 1, YAML_MAX_NODES);
        return PHC_ERR_INPUT;
    }
    node = calloc(1, sizeof *node);
    if (!node)
        return out_of_memory(b);
    ++b->n_nodes;
    node->kind = kind;
    /* libyaml counts from 0; messages and the header count from 1. */
    node->line = mark.line + 1;
    node->column = mark.column + 1;
    *out = node;
    return 0;
}

/* A deep copy of `src` for an alias placed at nesting `level`. */
static int node_copy(struct builder *b, const phc_yaml_node *src, size_t level,
                     yaml_mark_t mark, phc_yaml_node **out)
{
    phc_yaml_node *c = NULL;
    size_t i;
    int rc;

    *out = NULL;
    if (level > YAML_MAX_DEPTH) {
        rc = phc_error_set(b->err, PHC_ERR_INPUT,
                           "%s:%zu:%zu: alias expands to more than %d nested levels",
                           b->name, mark.line + 1, mark.column + 1, YAML_MAX_DEPTH);
        goto fail;
    }
    if ((rc = new_node(b, src->kind, mark, &c)))
        goto fail;
    /* The copy keeps the anchor's positions: that is where its text is. */
    c->line = src->line;
    c->column = src->column;
    c->quoted = src->quoted;
    rc = PHC_ERR_NOMEM;
    if (src->kind == PHC_YAML_SCALAR) {
        c->scalar = copy_string(src->scalar, strlen(src->scalar));
        if (!c->scalar)
            goto fail;
    } else if (src->kind == PHC_YAML_SEQUENCE && src->count) {
        c->items = calloc(src->count, sizeof *c->items);
        if (!c->items)
            goto fail;
        for (i = 0; i < src->count; ++i) {
            if ((rc = node_copy(b, src->items[i], level + 1, mark, &c->items[i])))
                goto fail;
            c->count = i + 1;
        }
    } else if (src->kind == PHC_YAML_MAPPING && src->count) {
        c->keys = calloc(src->count, sizeof *c->keys);
        c->key_lines = calloc(src->count, sizeof *c->key_lines);
        c->values = calloc(src->count, sizeof *c->values);
        if (!c->keys || !c->key_lines || !c->values)
            goto fail;
        for (i = 0; i < src->count; ++i) {
            c->count = i + 1; /* node_free frees keys[i] and values[i], even NULL */
            c->keys[i] = copy_string(src->keys[i], strlen(src->keys[i]));
            if (!c->keys[i])
                goto fail;
            c->key_lines[i] = src->key_lines[i];
            if ((rc = node_copy(b, src->values[i], level + 1, mark, &c->values[i])))
                goto fail;
        }
    }
    *out = c;
    return 0;

fail:
    if (rc == PHC_ERR_NOMEM)
        out_of_memory(b);
    node_free(c);
    return rc;
}

/* Remembers an anchor; takes ownership of `name`. */
static int register_anchor(struct builder *b, char *name, const phc_yaml_node *node)
{
    struct anchor *q = grow(b->anchors, &b->anchors_cap, b->n_anchors + 1, sizeof *q);
    if (!q) {
        free(name);
        return out_of_memory(b);
    }
    b->anchors = q;
    b->anchors[b->n_anchors].name = name;
    b->anchors[b->n_anchors].node = node;
    b->anchors[b->n_anchors].owned = NULL;
    ++b->n_anchors;
    return 0;
}

static const char *kind_phrase(phc_yaml_kind kind)
{
    return kind == PHC_YAML_SCALAR ? "a scalar"
         : kind == PHC_YAML_SEQUENCE ? "a sequence" : "a mapping";
}

/* Hands a complete node to its parent (or makes it the root); takes
 * ownership of `node` whatever happens. */
static int attach(struct builder *b, phc_yaml_node *node)
{
    struct frame *top;
    phc_yaml_node *parent;
    size_t i;
    int rc;

    if (b->depth == 0) {
        b->root = node;
        return 0;
    }
    top = &b->stack[b->depth - 1];
    parent = top->node;
    if (parent->kind == PHC_YAML_SEQUENCE) {
        phc_yaml_node **q = grow(parent->items, &top->cap, parent->count + 1, sizeof *q);
        if (!q) {
            rc = out_of_memory(b);
            goto fail;
        }
        parent->items = q;
        parent->items[parent->count++] = node;
        return 0;
    }
    if (!top->key) {
        /* This node is a key. */
        if (node->kind != PHC_YAML_SCALAR) {
            rc = phc_error_set(b->err, PHC_ERR_INPUT,
                               "%s:%zu:%zu: a mapping key must be a scalar, found %s",
                               b->name, node->line, node->column, kind_phrase(node->kind));
            goto fail;
        }
        for (i = 0; i < parent->count; ++i)
            if (!strcmp(parent->keys[i], node->scalar)) {
                rc = phc_error_set(b->err, PHC_ERR_INPUT,
                                   "%s:%zu:%zu: duplicate key '%.*s' (first on line %zu)",
                                   b->name, node->line, node->column, YAML_SHOW_MAX,
                                   node->scalar, parent->key_lines[i]);
                goto fail;
            }
        top->key = copy_string(node->scalar, strlen(node->scalar));
        if (!top->key) {
            rc = out_of_memory(b);
            goto fail;
        }
        top->key_line = node->line;
        /* An anchored key may still be aliased later: the anchor table
         * keeps it alive; otherwise the key node is done with. */
        if (b->n_anchors && b->anchors[b->n_anchors - 1].node == node)
            b->anchors[b->n_anchors - 1].owned = node;
        else
            node_free(node);
        return 0;
    }
    /* This node is the value of top->key.  The three arrays share top->cap,
     * so each is grown to the new capacity before it is recorded. */
    if (parent->count + 1 > top->cap) {
        size_t cap = top->cap, c2 = top->cap, c3 = top->cap;
        char **keys;
        size_t *key_lines;
        phc_yaml_node **values;
        /* Each array is stored as soon as it moves, so that on failure the
         * parent still owns every block and builder_clear frees it. */
        keys = grow(parent->keys, &cap, parent->count + 1, sizeof *keys);
        if (keys)
            parent->keys = keys;
        key_lines = keys ? grow(parent->key_lines, &c2, cap, sizeof *key_lines) : NULL;
        if (key_lines)
            parent->key_lines = key_lines;
        values = key_lines ? grow(parent->values, &c3, cap, sizeof *values) : NULL;
        if (!values) {
            rc = out_of_memory(b);
            goto fail;
        }
        parent->values = values;
        top->cap = cap;
    }
    parent->keys[parent->count] = top->key;
    parent->key_lines[parent->count] = top->key_line;
    parent->values[parent->count] = node;
    ++parent->count;
    top->key = NULL;
    return 0;

fail:
    node_free(node);
    return rc;
}

/* Line and column (1-based) of a byte offset, for libyaml's reader errors,
 * which carry an offset and no mark. */
static void offset_position(const char *text, size_t length, size_t offset, size_t *line,
                            size_t *column)
{
    size_t i;
    *line = 1;
    *column = 1;
    for (i = 0; i < offset && i < length; ++i) {
        if (text[i] == '\n') {
            ++*line;
            *column = 1;
        } else {
            ++*column;
        }
    }
}

static int syntax_error(struct builder *b, const yaml_parser_t *p, const char *text,
                        size_t length)
{
    const char *problem = p->problem ? p->problem : "unknown error";
    if (p->error == YAML_MEMORY_ERROR)
        return out_of_memory(b);
    if (p->error == YAML_READER_ERROR) {
        size_t line, column;
        offset_position(text, length, p->problem_offset, &line, &column);
        if (p->problem_value != -1)
            return phc_error_set(b->err, PHC_ERR_INPUT,
                                 "%s:%zu:%zu: YAML syntax error: %s (byte 0x%02X)", b->name,
                                 line, column, problem, (unsigned)p->problem_value & 0xFFu);
        return phc_error_set(b->err, PHC_ERR_INPUT, "%s:%zu:%zu: YAML syntax error: %s",
                             b->name, line, column, problem);
    }
    /* libyaml's context ("while parsing a block mapping") points at where
     * the enclosing construct began, often lines above the problem. */
    if (p->context && (p->context_mark.line != p->problem_mark.line ||
                       p->context_mark.column != p->problem_mark.column))
        return phc_error_set(b->err, PHC_ERR_INPUT,
                             "%s:%zu:%zu: YAML syntax error: %s (%s at line %zu, "
                             "column %zu)",
                             b->name, p->problem_mark.line + 1, p->problem_mark.column + 1,
                             problem, p->context, p->context_mark.line + 1,
                             p->context_mark.column + 1);
    if (p->context)
        return phc_error_set(b->err, PHC_ERR_INPUT, "%s:%zu:%zu: YAML syntax error: %s (%s)",
                             b->name, p->problem_mark.line + 1, p->problem_mark.column + 1,
                             problem, p->context);
    return phc_error_set(b->err, PHC_ERR_INPUT, "%s:%zu:%zu: YAML syntax error: %s", b->name,
                         p->problem_mark.line + 1, p->problem_mark.column + 1, problem);
}

/* Builds the tree from one event; ev stays owned by the caller. */
static int handle_event(struct builder *b, const yaml_event_t *ev)
{
    phc_yaml_node *node = NULL;
    char *anchor = NULL;
    int rc;

    switch (ev->type) {
    case YAML_SCALAR_EVENT: {
        const char *value = (const char *)ev->data.scalar.value;
        size_t length = ev->data.scalar.length;
        if (memchr(value, '\0', length))
            return phc_error_set(b->err, PHC_ERR_INPUT,
                                 "%s:%zu:%zu: a scalar contains a NUL character", b->name,
                                 ev->start_mark.line + 1, ev->start_mark.column + 1);
        if ((rc = new_node(b, PHC_YAML_SCALAR, ev->start_mark, &node)))
            return rc;
        node->scalar = copy_string(value, length);
        if (!node->scalar) {
            node_free(node);
            return out_of_memory(b);
        }
        node->quoted = ev->data.scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
                       ev->data.scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE;
        if (ev->data.scalar.anchor) {
            const char *a = (const char *)ev->data.scalar.anchor;
            anchor = copy_string(a, strlen(a));
            if (!anchor) {
                node_free(node);
                return out_of_memory(b);
            }
            if ((rc = register_anchor(b, anchor, node))) {
                node_free(node);
                return rc;
            }
        }
        return attach(b, node);
    }
    case YAML_SEQUENCE_START_EVENT:
    case YAML_MAPPING_START_EVENT: {
        const yaml_char_t *a = ev->type == YAML_SEQUENCE_START_EVENT
                                   ? ev->data.sequence_start.anchor
                                   : ev->data.mapping_start.anchor;
        struct frame *f;
        if (b->depth >= YAML_MAX_DEPTH)
            return phc_error_set(b->err, PHC_ERR_INPUT,
                                 "%s:%zu:%zu: more than %d nested levels", b->name,
                                 ev->start_mark.line + 1, ev->start_mark.column + 1,
                                 YAML_MAX_DEPTH);
        f = grow(b->stack, &b->stack_cap, b->depth + 1, sizeof *f);
        if (!f)
            return out_of_memory(b);
        b->stack = f;
        if (a) {
            anchor = copy_string((const char *)a, strlen((const char *)a));
            if (!anchor)
                return out_of_memory(b);
        }
        rc = new_node(b,
                      ev->type == YAML_SEQUENCE_START_EVENT ? PHC_YAML_SEQUENCE
                                                            : PHC_YAML_MAPPING,
                      ev->start_mark, &node);
        if (rc) {
            free(anchor);
            return rc;
        }
        f = &b->stack[b->depth++];
        memset(f, 0, sizeof *f);
        f->node = node;
        f->anchor = anchor;
        return 0;
    }
    case YAML_SEQUENCE_END_EVENT:
    case YAML_MAPPING_END_EVENT: {
        struct frame f;
        if (b->depth == 0) /* libyaml never does this; be safe anyway */
            return phc_error_set(b->err, PHC_ERR_INTERNAL, "%s: unbalanced YAML events",
                                 b->name);
        f = b->stack[--b->depth];
        free(f.key); /* libyaml always pairs keys with values; be safe */
        if (f.anchor && (rc = register_anchor(b, f.anchor, f.node))) {
            node_free(f.node);
            return rc;
        }
        return attach(b, f.node);
    }
    case YAML_ALIAS_EVENT: {
        const char *name = (const char *)ev->data.alias.anchor;
        size_t i = b->n_anchors;
        /* The latest definition wins (YAML allows redefining an anchor). */
        while (i > 0 && strcmp(b->anchors[i - 1].name, name))
            --i;
        if (i == 0)
            return phc_error_set(b->err, PHC_ERR_INPUT,
                                 "%s:%zu:%zu: alias '*%.*s' names no complete anchor "
                                 "defined before it",
                                 b->name, ev->start_mark.line + 1,
                                 ev->start_mark.column + 1, YAML_SHOW_MAX, name);
        if ((rc = node_copy(b, b->anchors[i - 1].node, b->depth, ev->start_mark, &node)))
            return rc;
        return attach(b, node);
    }
    default: /* stream and document events, tags: nothing to build */
        return 0;
    }
}

static void builder_clear(struct builder *b)
{
    size_t i;
    for (i = 0; i < b->depth; ++i) {
        node_free(b->stack[i].node);
        free(b->stack[i].anchor);
        free(b->stack[i].key);
    }
    free(b->stack);
    for (i = 0; i < b->n_anchors; ++i) {
        free(b->anchors[i].name);
        node_free(b->anchors[i].owned);
    }
    free(b->anchors);
    node_free(b->root);
}

int phc_yaml_parse(const char *text, size_t length, const char *name,
                   phc_yaml_doc **out, phc_error *err)
{
    yaml_parser_t parser;
    int parser_ready = 0, have_event = 0, done = 0;
    yaml_event_t ev;
    struct builder b;
    phc_yaml_doc *doc = NULL;
    int rc;

    if (out)
        *out = NULL;
    if (!out || (!text && length))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_yaml_parse: invalid argument");
    if (!text)
        text = "";
    if (!name)
        name = "<yaml>";
    memset(&b, 0, sizeof b);
    b.name = name;
    b.err = err;
    phc_error_clear(err);

    if (!yaml_parser_initialize(&parser)) {
        rc = out_of_memory(&b);
        goto fail;
    }
    parser_ready = 1;
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, length);
    while (!done) {
        if (!yaml_parser_parse(&parser, &ev)) {
            rc = syntax_error(&b, &parser, text, length);
            goto fail;
        }
        have_event = 1;
        /* Only the first document counts; later ones are not even parsed. */
        done = ev.type == YAML_DOCUMENT_END_EVENT || ev.type == YAML_STREAM_END_EVENT;
        if ((rc = handle_event(&b, &ev)))
            goto fail;
        yaml_event_delete(&ev);
        have_event = 0;
    }

    doc = calloc(1, sizeof *doc);
    if (!doc || !(doc->path = copy_string(name, strlen(name)))) {
        rc = out_of_memory(&b);
        goto fail;
    }
    /* "---" with nothing after it comes from libyaml as an empty plain
     * scalar; the header promises a NULL root for an empty document. */
    if (b.root && b.root->kind == PHC_YAML_SCALAR && !b.root->quoted && !*b.root->scalar) {
        node_free(b.root);
        b.root = NULL;
    }
    doc->root = b.root;
    b.root = NULL;
    builder_clear(&b);
    yaml_parser_delete(&parser);
    *out = doc;
    return 0;

fail:
    if (have_event)
        yaml_event_delete(&ev);
    if (parser_ready)
        yaml_parser_delete(&parser);
    builder_clear(&b);
    phc_yaml_free(doc);
    return rc;
}


int phc_yaml_load(const char *path, phc_yaml_doc **out, phc_error *err)
{
    char *text = NULL;
    size_t length = 0;
    int rc;

    if (out)
        *out = NULL;
    if (!path || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_yaml_load: invalid argument");
    if ((rc = phc_read_text_file(path, &text, &length, err)))
        return rc;
    rc = phc_yaml_parse(text, length, path, out, err);
    free(text);
    return rc;
}

void phc_yaml_free(phc_yaml_doc *doc)
{
    if (!doc)
        return;
    node_free(doc->root);
    free(doc->path);
    free(doc);
}

const phc_yaml_node *phc_yaml_get(const phc_yaml_node *map, const char *key)
{
    size_t i;
    if (!map || !key || map->kind != PHC_YAML_MAPPING)
        return NULL;
    for (i = 0; i < map->count; ++i)
        if (!strcmp(map->keys[i], key))
            return map->values[i];
    return NULL;
}

/* ---- accessors ----------------------------------------------------------- */

static const char *doc_name(const phc_yaml_doc *doc)
{
    return doc && doc->path ? doc->path : "<yaml>";
}

/* A scalar shortened and flattened to one line for a message. */
static void show(const char *s, char *out, size_t size)
{
    size_t n = 0;
    for (; *s && n + 4 < size && n < YAML_SHOW_MAX; ++s)
        out[n++] = (unsigned char)*s < 32 ? ' ' : *s;
    if (*s && n + 4 <= size) {
        memcpy(out + n, "...", 3);
        n += 3;
    }
    out[n] = '\0';
}

/* An unquoted empty, '~' or 'null' scalar is YAML's null: a value the user
 * wrote but left empty, not an absent key. */
static int is_null(const phc_yaml_node *node)
{
    const char *s = node->scalar;
    return !node->quoted && (!*s || !strcmp(s, "~") || !strcmp(s, "null") ||
                             !strcmp(s, "Null") || !strcmp(s, "NULL"));
}

/* "FILE:LINE:COL: key 'K': expected WHAT, found ..." */
static int type_error(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                      const char *what, phc_error *err)
{
    char where[PHC_ERROR_MESSAGE_SIZE / 2];
    char value[YAML_SHOW_MAX + 8];

    if (key)
        snprintf(where, sizeof where, "%s:%zu:%zu: key '%.*s'", doc_name(doc), node->line,
                 node->column, YAML_SHOW_MAX, key);
    else
        snprintf(where, sizeof where, "%s:%zu:%zu", doc_name(doc), node->line,
                 node->column);
    if (node->kind != PHC_YAML_SCALAR)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: expected %s, found %s", where, what,
                             kind_phrase(node->kind));
    if (is_null(node))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: expected %s, found an empty (null) value (leave the key "
                             "out to keep the default)",
                             where, what);
    show(node->scalar, value, sizeof value);
    return phc_error_set(err, PHC_ERR_INPUT, "%s: expected %s, found '%s'", where, what,
                         value);
}

/* 0: a finite number; 1: not a number; 2: a number but not finite. */
static int parse_number(const char *s, double *out)
{
    char *end;
    double x;
    char lower[8];
    size_t i;

    if (!*s || isspace((unsigned char)*s))
        return 1;
    errno = 0;
    x = phc_strtod_c(s, &end);
    if (end != s && !*end) {
        if (!isfinite(x))
            return 2;
        *out = x;
        return 0;
    }
    /* YAML spells infinities and NaN .inf, -.inf, .NaN: recognise them only
     * to say why they are refused. */
    for (i = 0; s[i] && i + 1 < sizeof lower; ++i)
        lower[i] = (char)tolower((unsigned char)s[i]);
    lower[i] = '\0';
    if (!s[i] && (!strcmp(lower, ".inf") || !strcmp(lower, "+.inf") ||
                  !strcmp(lower, "-.inf") || !strcmp(lower, ".nan")))
        return 2;
    return 1;
}

/* Typed accessors read the scalar's text whether or not it was quoted, so
 * value: "1e-3" is the number it looks like. */
int phc_yaml_number(const phc_yaml_doc *doc, const phc_yaml_node *node,
                    const char *key, double *out, phc_error *err)
{
    double x = 0;
    int r;
    if (!node)
        return 0;
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_yaml_number: invalid argument");
    if (node->kind != PHC_YAML_SCALAR)
        return type_error(doc, node, key, "a number", err);
    r = parse_number(node->scalar, &x);
    if (r == 1)
        return type_error(doc, node, key, "a number", err);
    if (r == 2)
        return type_error(doc, node, key, "a finite number", err);
    *out = x;
    return 0;
}

int phc_yaml_integer(const phc_yaml_doc *doc, const phc_yaml_node *node,
                     const char *key, long *out, phc_error *err)
{
    const char *s;
    char *end;
    long v;
    double x = 0;

    if (!node)
        return 0;
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_yaml_integer: invalid argument");
    if (node->kind != PHC_YAML_SCALAR)
        return type_error(doc, node, key, "an integer", err);
    s = node->scalar;
    if (!*s || isspace((unsigned char)*s))
        return type_error(doc, node, key, "an integer", err);
    errno = 0;
    v = strtol(s, &end, 10);
    if (end != s && !*end) {
        if (errno == ERANGE)
            return type_error(doc, node, key, "an integer in the range of a long", err);
        *out = v;
        return 0;
    }
    /* 1e3 and 100.0 are whole numbers too.  -(double)LONG_MIN is 2^63,
     * the first double above LONG_MAX. */
    if (parse_number(s, &x) == 0 && x == floor(x)) {
        if (x < (double)LONG_MIN || x >= -(double)LONG_MIN)
            return type_error(doc, node, key, "an integer in the range of a long", err);
        *out = (long)x;
        return 0;
    }
    return type_error(doc, node, key, "an integer", err);
}

static int equals_lower(const char *s, const char *lower)
{
    for (; *s && *lower; ++s, ++lower)
        if (tolower((unsigned char)*s) != *lower)
            return 0;
    return !*s && !*lower;
}

int phc_yaml_boolean(const phc_yaml_doc *doc, const phc_yaml_node *node,
                     const char *key, int *out, phc_error *err)
{
    static const char *const yes[] = {"true", "yes", "on"};
    static const char *const no[] = {"false", "no", "off"};
    size_t i;

    if (!node)
        return 0;
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_yaml_boolean: invalid argument");
    if (node->kind != PHC_YAML_SCALAR)
        return type_error(doc, node, key, "a boolean (true or false)", err);
    for (i = 0; i < 3; ++i) {
        if (equals_lower(node->scalar, yes[i])) {
            *out = 1;
            return 0;
        }
        if (equals_lower(node->scalar, no[i])) {
            *out = 0;
            return 0;
        }
    }
    return type_error(doc, node, key, "a boolean (true or false)", err);
}

int phc_yaml_string(const phc_yaml_doc *doc, const phc_yaml_node *node,
                    const char *key, const char **out, phc_error *err)
{
    if (!node)
        return 0;
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_yaml_string: invalid argument");
    /* An empty value is refused rather than read as "": a file name or an
     * expression left empty is a mistake; write "" to mean the empty string. */
    if (node->kind != PHC_YAML_SCALAR || is_null(node))
        return type_error(doc, node, key, "a string", err);
    *out = node->scalar;
    return 0;
}

/* The value of `key` in `map` (NULL when absent and not required). */
static int map_lookup(const phc_yaml_doc *doc, const phc_yaml_node *map, const char *key,
                      int required, const char *context, const phc_yaml_node **node,
                      phc_error *err)
{
    const char *sep = context ? ": " : "";
    *node = NULL;
    if (!key)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_yaml_map_*: key is NULL");
    if (!context)
        context = "";
    if (!map) {
        if (required)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: %s%smissing key '%s'",
                                 doc_name(doc), context, sep, key);
        return 0;
    }
    /* A scalar or list where a mapping belongs is an error even for an
     * optional key: reading it as "no keys" would drop what the user wrote. */
    if (map->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu:%zu: %s%sexpected a mapping (key: value), found %s",
                             doc_name(doc), map->line, map->column, context, sep,
                             kind_phrase(map->kind));
    *node = phc_yaml_get(map, key);
    if (!*node && required)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s%smissing key '%s'",
                             doc_name(doc), map->line, context, sep, key);
    return 0;
}

int phc_yaml_map_number(const phc_yaml_doc *doc, const phc_yaml_node *map,
                        const char *key, int required, const char *context,
                        double *out, phc_error *err)
{
    const phc_yaml_node *node;
    int rc = map_lookup(doc, map, key, required, context, &node, err);
    return rc ? rc : phc_yaml_number(doc, node, key, out, err);
}

int phc_yaml_map_integer(const phc_yaml_doc *doc, const phc_yaml_node *map,
                         const char *key, int required, const char *context,
                         long *out, phc_error *err)
{
    const phc_yaml_node *node;
    int rc = map_lookup(doc, map, key, required, context, &node, err);
    return rc ? rc : phc_yaml_integer(doc, node, key, out, err);
}

int phc_yaml_map_boolean(const phc_yaml_doc *doc, const phc_yaml_node *map,
                         const char *key, int required, const char *context,
                         int *out, phc_error *err)
{
    const phc_yaml_node *node;
    int rc = map_lookup(doc, map, key, required, context, &node, err);
    return rc ? rc : phc_yaml_boolean(doc, node, key, out, err);
}

int phc_yaml_map_string(const phc_yaml_doc *doc, const phc_yaml_node *map,
                        const char *key, int required, const char *context,
                        const char **out, phc_error *err)
{
    const phc_yaml_node *node;
    int rc = map_lookup(doc, map, key, required, context, &node, err);
    return rc ? rc : phc_yaml_string(doc, node, key, out, err);
}

int phc_yaml_check_keys(const phc_yaml_doc *doc, const phc_yaml_node *map,
                        const char *const *allowed, const char *context,
                        phc_error *err)
{
    size_t n_allowed = 0, i, j;
    if (!map)
        return 0;
    if (!context)
        context = "a mapping";
    if (map->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu:%zu: %s: expected a mapping (key: value), found %s",
                             doc_name(doc), map->line, map->column, context,
                             kind_phrase(map->kind));
    while (allowed && allowed[n_allowed])
        ++n_allowed;
    for (i = 0; i < map->count; ++i) {
        const char *key = map->keys[i];
        const char *near;
        char shown[YAML_SHOW_MAX + 8];
        char list[PHC_ERROR_MESSAGE_SIZE];
        size_t used = 0;
        for (j = 0; j < n_allowed; ++j)
            if (!strcmp(key, allowed[j]))
                break;
        if (j < n_allowed)
            continue;
        show(key, shown, sizeof shown);
        near = phc_suggest(key, allowed, n_allowed);
        if (near)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: unknown key '%s' in %s; did you mean '%s'?",
                                 doc_name(doc), map->key_lines[i], shown, context, near);
        list[0] = '\0';
        for (j = 0; j < n_allowed && used < sizeof list; ++j) {
            int n = snprintf(list + used, sizeof list - used, "%s%s", j ? ", " : "",
                             allowed[j]);
            if (n < 0)
                break;
            used += (size_t)n;
        }
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: unknown key '%s' in %s; allowed keys: %s",
                             doc_name(doc), map->key_lines[i], shown, context,
                             n_allowed ? list : "(none)");
    }
    return 0;
}
