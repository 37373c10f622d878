/* Help on the configuration keys, from the loader's own tables: see
 * config_help.h. */
#include "fit/config_help.h"

#include <stdlib.h>
#include <string.h>

#include "fit/config.h"
#include "measurements/suggest.h"

/* Lines stay within 79 columns (an 80-column terminal wraps a full line). */
#define LINE_WIDTH 79
/* Keys up to this long share their line with their help; longer ones put
 * the help on the next line. */
#define KEY_COLUMN_MAX 20

const char *phc_key_help_find(const phc_key_help *table, const char *key)
{
    for (size_t i = 0; table && key && table[i].key; ++i)
        if (strcmp(table[i].key, key) == 0)
            return table[i].help;
    return NULL;
}

/* Columns taken by n bytes of UTF-8 text: one per code point (the help's
 * non-ASCII characters, such as § and ³, are one column wide). */
static size_t columns(const char *s, size_t n)
{
    size_t c = 0;
    for (size_t i = 0; i < n; ++i)
        c += ((unsigned char)s[i] & 0xC0) != 0x80;
    return c;
}

static void spaces(FILE *out, size_t n)
{
    while (n--)
        fputc(' ', out);
}

/* A word that must not end a line (it ends with ':', as in "Default:") or
 * must not stand alone at either end of one (only symbols: "=", "->"). */
static int ends_with_colon(const char *p, const char *end)
{
    return end > p && end[-1] == ':';
}

static int symbols_only(const char *p, const char *end)
{
    for (; p < end; ++p)
        if (((unsigned char)*p >= '0' && (unsigned char)*p <= '9') || ((*p | 0x20) >= 'a' && (*p | 0x20) <= 'z') ||
            ((unsigned char)*p & 0x80))
            return 0;
    return 1;
}

/* The end of the word at p (no leading spaces). */
static const char *word_end(const char *p)
{
    while (*p && *p != ' ')
        ++p;
    return p;
}

/* Writes `text`, the cursor being at column `col`, breaking lines between
 * words so that none passes LINE_WIDTH (unless one unbreakable run is that
 * long); continuation lines are indented by `indent`.  Ends the line. */
static void wrap(FILE *out, const char *text, size_t col, size_t indent)
{
    size_t on_line = 0; /* runs written on the current line */
    const char *p = text;
    while (*p == ' ')
        ++p;
    while (*p) {
        /* A run: words that must stay together. */
        const char *end = word_end(p);
        for (;;) {
            const char *q = end;
            while (*q == ' ')
                ++q;
            if (!*q)
                break;
            const char *qe = word_end(q);
            const char *last = end;
            while (last > p && last[-1] != ' ')
                --last;
            if (!ends_with_colon(last, end) && !symbols_only(last, end) && !symbols_only(q, qe))
                break;
            end = qe;
        }
        const size_t w = columns(p, (size_t)(end - p));
        if (on_line && col + 1 + w > LINE_WIDTH) {
            fputc('\n', out);
            spaces(out, indent);
            col = indent;
            on_line = 0;
        }
        if (on_line) {
            fputc(' ', out);
            ++col;
        }
        /* Inner runs of spaces print as one. */
        for (const char *c = p; c < end; ++c)
            if (*c != ' ' || c[-1] != ' ')
                fputc(*c, out);
        col += w;
        ++on_line;
        p = end;
        while (*p == ' ')
            ++p;
    }
    fputc('\n', out);
}

/* "  key   help..." for name/text pairs: the text in a column after the
 * longest name (at most KEY_COLUMN_MAX), continuation lines aligned with it. */
static void write_item(FILE *out, const char *name, const char *text, size_t name_width)
{
    const size_t indent = 2 + name_width + 2, w = columns(name, strlen(name));
    spaces(out, 2);
    fputs(name, out);
    if (w <= name_width) {
        spaces(out, indent - 2 - w);
    } else {
        fputc('\n', out);
        spaces(out, indent);
    }
    wrap(out, text, indent, indent);
}

static size_t name_width_of(const char *const *names)
{
    size_t m = 0;
    for (size_t i = 0; names[i]; ++i) {
        const size_t w = columns(names[i], strlen(names[i]));
        if (w > m)
            m = w;
    }
    return m < KEY_COLUMN_MAX ? m : KEY_COLUMN_MAX;
}

/* A section's heading ("name: summary."), an optional introduction and
 * its keys in the loader's order. */
static void write_section(FILE *out, const phc_config_section *s, const char *intro)
{
    const size_t nl = strlen(s->name), sl = strlen(s->summary);
    char *heading = malloc(nl + sl + 4);
    if (heading) {
        snprintf(heading, nl + sl + 4, "%s: %s.", s->name, s->summary);
        wrap(out, heading, 0, 0);
        free(heading);
    } else {
        fprintf(out, "%s: ", s->name);
        wrap(out, s->summary, nl + 2, 0);
    }
    if (intro) {
        fputc('\n', out);
        wrap(out, intro, 0, 0);
    }
    const size_t width = name_width_of(s->keys);
    for (size_t i = 0; s->keys[i]; ++i) {
        const char *help = phc_key_help_find(s->help, s->keys[i]);
        write_item(out, s->keys[i], help ? help : "(no help)", width);
    }
}

static int has_key(const phc_config_section *s, const char *key)
{
    for (size_t i = 0; s->keys[i]; ++i)
        if (strcmp(s->keys[i], key) == 0)
            return 1;
    return 0;
}

static void write_overview(FILE *out)
{
    wrap(out, "The keys of a phytocal configuration file (YAML). `phytocal help KIND` "
              "describes the keys of one data-set kind, `phytocal help soil` those of a "
              "data set's soil: block.", 0, 0);
    static const phc_config_block_id order[] = {PHC_CONFIG_TOP, PHC_CONFIG_PARAMETER,
                                                PHC_CONFIG_DATASET, PHC_CONFIG_SOLVER,
                                                PHC_CONFIG_REPORT};
    for (size_t b = 0; b < sizeof order / sizeof order[0]; ++b) {
        fputc('\n', out);
        write_section(out, phc_config_block(order[b]), NULL);
    }
    fputc('\n', out);
    wrap(out, "Data-set kinds (`kind:`; `phytocal help KIND` for their keys):", 0, 0);
    const size_t n = phc_config_kind_count();
    size_t width = 0;
    for (size_t i = 0; i < n; ++i) {
        const size_t w = strlen(phc_config_kind_at(i)->name);
        width = w > width ? w : width;
    }
    width = width < KEY_COLUMN_MAX ? width : KEY_COLUMN_MAX;
    for (size_t i = 0; i < n; ++i)
        write_item(out, phc_config_kind_at(i)->name, phc_config_kind_at(i)->summary, width);
}

static void write_kind(FILE *out, const phc_config_section *k)
{
    /* The common keys, named from their table. */
    const phc_config_section *common = phc_config_block(PHC_CONFIG_DATASET);
    char *intro = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&intro, &len);
    if (f) {
        fprintf(f, "Keys of kind %s besides the common data-set keys (", k->name);
        for (size_t i = 0; common->keys[i]; ++i)
            fprintf(f, "%s%s", i ? ", " : "", common->keys[i]);
        fputs("; see `phytocal help`):", f);
        if (fclose(f) != 0) {
            free(intro);
            intro = NULL;
        }
    }
    write_section(out, k, intro ? intro : "Keys besides the common ones (see `phytocal help`):");
    free(intro);
    if (has_key(k, "soil")) {
        fputc('\n', out);
        write_section(out, phc_config_block(PHC_CONFIG_SOIL), NULL);
    }
}

int phc_config_write_help(FILE *out, const char *kind, phc_error *err)
{
    if (!out)
        return phc_error_set(err, PHC_ERR_INVALID, "help: no output stream");
    const phc_config_section *k = kind ? phc_config_kind_find(kind) : NULL;
    const phc_config_section *block = NULL;
    for (int b = 0; kind && !k && !block && b < PHC_CONFIG_N_BLOCKS; ++b)
        if (b != PHC_CONFIG_TOP && strcmp(phc_config_block((phc_config_block_id)b)->name, kind) == 0)
            block = phc_config_block((phc_config_block_id)b);
    if (kind && !k && !block) {
        /* Suggest among the kinds and the blocks one can ask for. */
        const char *names[64];
        size_t n = 0;
        char kinds[512] = "", blocks[128] = "";
        for (size_t i = 0; i < phc_config_kind_count() && n < 48; ++i) {
            names[n++] = phc_config_kind_at(i)->name;
            const size_t used = strlen(kinds);
            snprintf(kinds + used, sizeof kinds - used, "%s%s", i ? ", " : "", phc_config_kind_at(i)->name);
        }
        for (int b = 0; b < PHC_CONFIG_N_BLOCKS; ++b)
            if (b != PHC_CONFIG_TOP) {
                names[n++] = phc_config_block((phc_config_block_id)b)->name;
                const size_t used = strlen(blocks);
                snprintf(blocks + used, sizeof blocks - used, "%s%s", used ? ", " : "", names[n - 1]);
            }
        const char *near = phc_suggest(kind, names, n);
        return phc_error_set(err, PHC_ERR_INPUT, "help: unknown kind '%s'%s%s%s (kinds: %s; blocks: %s)", kind,
                             near ? "; did you mean '" : "", near ? near : "", near ? "'?" : "", kinds, blocks);
    }
    if (k)
        write_kind(out, k);
    else if (block)
        write_section(out, block, NULL);
    else
        write_overview(out);
    if (fflush(out) != 0 || ferror(out))
        return phc_error_set(err, PHC_ERR_IO, "help: cannot write the help");
    return PHC_OK;
}
