/* The leaf colour aging set-up: see leaf_setup.h. */
#include "fit/costs/leaf_setup.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- photo cache ------------------------------------------------------------ */

typedef struct cache_entry {
    char *path;
    phc_colour_correction_method method;
    phc_image img; /* colour corrected */
    phc_colour_correction correction;
    phc_segmentation seg;
} cache_entry;

struct phc_photo_cache {
    cache_entry *e;
    size_t n;
};

phc_photo_cache *phc_photo_cache_new(void)
{
    return calloc(1, sizeof(phc_photo_cache));
}

void phc_photo_cache_free(phc_photo_cache *c)
{
    if (!c)
        return;
    for (size_t i = 0; i < c->n; ++i) {
        free(c->e[i].path);
        phc_image_free(&c->e[i].img);
        phc_segmentation_free(&c->e[i].seg);
    }
    free(c->e);
    free(c);
}

static cache_entry *cache_find(phc_photo_cache *c, const char *path, phc_colour_correction_method method)
{
    for (size_t i = 0; i < c->n; ++i)
        if (c->e[i].method == method && !strcmp(c->e[i].path, path))
            return &c->e[i];
    return NULL;
}

/* A new entry for `path`: the image `img` when given (copied), else the
 * file read; colour corrected and segmented.  Errors name the photo and
 * are placed after `where`. */
static int cache_insert(phc_photo_cache *c, const char *path, const phc_image *img,
                        phc_colour_correction_method method, const char *where, cache_entry **out, phc_error *err)
{
    cache_entry *grown = realloc(c->e, (c->n + 1) * sizeof *grown);
    if (!grown)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    c->e = grown;
    cache_entry *e = &c->e[c->n];
    memset(e, 0, sizeof *e);
    int rc;
    if (!(e->path = strdup(path)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    e->method = method;
    phc_segment_options so = phc_segment_options_default();
    if (img) {
        if (!(rc = phc_image_alloc(&e->img, img->width, img->height, err))) {
            memcpy(e->img.data, img->data, 3 * img->width * img->height * sizeof *img->data);
            e->img.bit_depth = img->bit_depth;
        }
    } else
        rc = phc_photo_read(path, &e->img, err);
    if (rc ||
        (rc = phc_photo_colour_correct(&e->img, NULL, method, &e->correction, err)) ||
        (rc = phc_photo_segment_leaves(&e->img, &so, &e->seg, err))) {
        if (rc == PHC_ERR_INPUT || rc == PHC_ERR_IO) {
            /* name the photo when the bridge's message does not */
            if (err && !strstr(err->message, path))
                phc_error_prefix(err, rc, "%s", path);
        }
        free(e->path);
        phc_image_free(&e->img);
        phc_segmentation_free(&e->seg);
        return where ? phc_error_prefix(err, rc, "%s", where) : rc;
    }
    c->n++;
    *out = e;
    return PHC_OK;
}

static int cache_get(phc_photo_cache *c, const char *path, phc_colour_correction_method method,
                     const char *where, cache_entry **out, phc_error *err)
{
    if ((*out = cache_find(c, path, method)))
        return PHC_OK;
    return cache_insert(c, path, NULL, method, where, out, err);
}

int phc_photo_cache_read(phc_photo_cache *cache, const char *path, phc_colour_correction_method correction,
                         const char *where, phc_error *err)
{
    cache_entry *e = NULL;
    return cache_get(cache, path, correction, where, &e, err);
}

int phc_photo_cache_add(phc_photo_cache *cache, const char *name, const phc_image *img,
                        phc_colour_correction_method correction, const char *where, phc_error *err)
{
    cache_entry *e = NULL;
    if (!name || !img || !img->data || !img->width || !img->height)
        return phc_error_set(err, PHC_ERR_INVALID, "%s%sphc_photo_cache_add: a name and a non-empty image are needed",
                             where ? where : "", where ? ": " : "");
    if (cache_find(cache, name, correction))
        return PHC_OK;
    return cache_insert(cache, name, img, correction, where, &e, err);
}

int phc_leaf_photo_load(phc_photo_cache *cache, const char *path, size_t number,
                        phc_colour_correction_method correction, const char *where,
                        phc_leaf_photo *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    cache_entry *e = NULL;
    int rc;
    if ((rc = cache_get(cache, path, correction, where, &e, err)))
        return rc;
    if (number < 1 || number > e->seg.count)
        return phc_error_set(err, PHC_ERR_INPUT, "%s%s%s: leaf %zu requested, %zu lea%s found", where ? where : "",
                             where ? ": " : "", path, number, e->seg.count, e->seg.count == 1 ? "f" : "ves");
    const size_t margin = 2;
    if ((rc = phc_photo_crop_leaf(&e->img, &e->seg, number, margin, &out->crop, &out->mask, err)))
        return where ? phc_error_prefix(err, rc, "%s", where) : rc;
    const phc_leaf_box *b = &e->seg.leaf[number - 1];
    out->x0 = b->x0 > margin ? b->x0 - margin : 0;
    out->y0 = b->y0 > margin ? b->y0 - margin : 0;
    out->photo_width = e->img.width;
    out->photo_height = e->img.height;
    out->number = number;
    out->leaves = e->seg.count;
    out->area = b->area;
    out->correction = e->correction;
    if (!(out->path = strdup(path))) {
        phc_leaf_photo_free(out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    return PHC_OK;
}

void phc_leaf_photo_free(phc_leaf_photo *p)
{
    if (!p)
        return;
    free(p->path);
    phc_image_free(&p->crop);
    free(p->mask);
    memset(p, 0, sizeof *p);
}

static void grid_size(size_t w, size_t h, size_t size, size_t *gw, size_t *gh)
{
    if (w >= h) {
        *gw = size;
        *gh = (size_t)fmax(1.0, round((double)size * (double)h / (double)w));
    } else {
        *gh = size;
        *gw = (size_t)fmax(1.0, round((double)size * (double)w / (double)h));
    }
}

int phc_leaf_photo_grid(const phc_leaf_photo *p, size_t size, phc_image *img, unsigned char **mask,
                        phc_error *err)
{
    size_t gw, gh;
    grid_size(p->crop.width, p->crop.height, size, &gw, &gh);
    int rc;
    *mask = NULL;
    if ((rc = phc_photo_resize(&p->crop, gw, gh, img, err)))
        return rc;
    if ((rc = phc_photo_resize_mask(p->mask, p->crop.width, p->crop.height, gw, gh, mask, err))) {
        phc_image_free(img);
        return rc;
    }
    for (size_t i = 0; i < gw * gh; ++i)
        if (!(*mask)[i])
            img->data[3 * i] = img->data[3 * i + 1] = img->data[3 * i + 2] = 0;
    return PHC_OK;
}

/* ---- set-up ------------------------------------------------------------------- */

phc_leaf_setup_options phc_leaf_setup_options_default(void)
{
    phc_leaf_setup_options o;
    memset(&o, 0, sizeof o);
    o.model_size = 128;
    o.space = PHC_COLOUR_RGB;
    o.vein_floor = 0.05;
    o.vein_edge_taper = 9;
    o.veins = o.stomata = o.inflow = PHC_LEAF_MAP_AUTO;
    o.dt = 0.1;
    return o;
}

void phc_leaf_setup_free(phc_leaf_setup *s)
{
    if (!s)
        return;
    free(s->mask);
    phc_image_free(&s->fresh);
    free(s->original);
    free(s->matched);
    free(s->beta);
    free(s->stomata);
    free(s->inflow);
    free(s->blend);
    free(s->lab_original);
    free(s->lab_matched);
    phc_leaf_free(s->leaf);
    free(s);
}

/* A scalar map on the crop (cw x ch) averaged down to the model grid. */
static int map_to_grid(const double *crop_map, size_t cw, size_t ch, size_t gw, size_t gh, double *out,
                       phc_error *err)
{
    phc_image a = {0}, b = {0};
    int rc;
    if ((rc = phc_image_alloc(&a, cw, ch, err)))
        return rc;
    for (size_t i = 0; i < cw * ch; ++i)
        a.data[3 * i] = a.data[3 * i + 1] = a.data[3 * i + 2] = crop_map[i];
    rc = phc_photo_resize(&a, gw, gh, &b, err);
    phc_image_free(&a);
    if (rc)
        return rc;
    for (size_t i = 0; i < gw * gh; ++i)
        out[i] = b.data[3 * i];
    phc_image_free(&b);
    return PHC_OK;
}

/* A map file: a grey image the size of the fresh leaf's photo, cropped with
 * the leaf and averaged down to the grid. */
static int map_from_file(const char *file, const char *what, const char *where, const phc_leaf_photo *fresh,
                         size_t gw, size_t gh, double *out, phc_error *err)
{
    double *full = NULL, *crop = NULL;
    int rc = phc_photo_read_map(file, fresh->photo_width, fresh->photo_height, 0, &full, err);
    if (rc) {
        return phc_error_prefix(err, rc, "%s%s%s map (the size of the photo %s)", where ? where : "",
                                where ? ": " : "", what, fresh->path);
    }
    const size_t cw = fresh->crop.width, ch = fresh->crop.height;
    if (!(crop = malloc(cw * ch * sizeof *crop))) {
        free(full);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t y = 0; y < ch; ++y)
        for (size_t x = 0; x < cw; ++x)
            crop[x + cw * y] = full[(fresh->x0 + x) + fresh->photo_width * (fresh->y0 + y)];
    free(full);
    rc = map_to_grid(crop, cw, ch, gw, gh, out, err);
    free(crop);
    return rc;
}

void phc_leaf_chamfer_distance(size_t w, size_t h, const unsigned char *src, double *d)
{
    const double big = 1e9;
    for (size_t i = 0; i < w * h; ++i)
        d[i] = src[i] ? 0 : big;
    /* forward then backward pass, steps 3 (edge) and 4 (diagonal) */
    for (size_t y = 0; y < h; ++y)
        for (size_t x = 0; x < w; ++x) {
            double *p = &d[x + w * y];
            if (x > 0)
                *p = fmin(*p, d[x - 1 + w * y] + 3);
            if (y > 0) {
                *p = fmin(*p, d[x + w * (y - 1)] + 3);
                if (x > 0)
                    *p = fmin(*p, d[x - 1 + w * (y - 1)] + 4);
                if (x + 1 < w)
                    *p = fmin(*p, d[x + 1 + w * (y - 1)] + 4);
            }
        }
    for (size_t y = h; y-- > 0;)
        for (size_t x = w; x-- > 0;) {
            double *p = &d[x + w * y];
            if (x + 1 < w)
                *p = fmin(*p, d[x + 1 + w * y] + 3);
            if (y + 1 < h) {
                *p = fmin(*p, d[x + w * (y + 1)] + 3);
                if (x + 1 < w)
                    *p = fmin(*p, d[x + 1 + w * (y + 1)] + 4);
                if (x > 0)
                    *p = fmin(*p, d[x - 1 + w * (y + 1)] + 4);
            }
        }
    for (size_t i = 0; i < w * h; ++i)
        d[i] /= 3.0;
}

/* Fades a ridge map (crop size) out near the leaf's edge: the Hessian
 * answers the step from leaf to background there, which would make the
 * whole margin a vein. */
static int taper_edge(const phc_leaf_photo *fresh, double taper, double *ridge, phc_error *err)
{
    if (!(taper > 1))
        return PHC_OK;
    const size_t cw = fresh->crop.width, ch = fresh->crop.height, n = cw * ch;
    unsigned char *outside = calloc(n ? n : 1, 1);
    double *d = malloc(n * sizeof *d);
    if (!outside || !d) {
        free(outside);
        free(d);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    /* the crop's own border counts as outside too */
    for (size_t y = 0; y < ch; ++y)
        for (size_t x = 0; x < cw; ++x)
            outside[x + cw * y] = !fresh->mask[x + cw * y] || x == 0 || y == 0 || x + 1 == cw || y + 1 == ch;
    phc_leaf_chamfer_distance(cw, ch, outside, d);
    for (size_t i = 0; i < n; ++i)
        ridge[i] *= fmin(1.0, fmax(0.0, (d[i] - 1.0) / (taper - 1.0)));
    free(outside);
    free(d);
    return PHC_OK;
}

/* Packs the colours of the mask pixels (3 per pixel). */
static void pack(const double *c, const unsigned char *mask, size_t n, double *out)
{
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        if (mask[i]) {
            memcpy(out + 3 * k, c + 3 * i, 3 * sizeof *c);
            ++k;
        }
}

/* Eq. 8: the fresh leaf's colours in the matching space (0 off the leaf)
 * and their histogram match onto the reference's leaf pixels. */
static int match_colours(phc_leaf_setup *s, phc_image *ref, const unsigned char *ref_mask, phc_error *err)
{
    const size_t n = s->w * s->h, n_px_ref = ref->width * ref->height;
    size_t n_ref = 0;
    for (size_t i = 0; i < n_px_ref; ++i)
        n_ref += ref_mask[i] != 0;
    double *a = malloc(3 * s->cells * sizeof *a), *m = malloc(3 * s->cells * sizeof *m);
    double *b = malloc(3 * n_ref * sizeof *b);
    int rc = PHC_OK;
    if (!a || !m || !b) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* Colours in the matching space; eq. 8 on the leaf pixels only. */
    phc_colour_convert(n, s->fresh.data, PHC_COLOUR_RGB, s->space, s->original);
    phc_colour_convert(n_px_ref, ref->data, PHC_COLOUR_RGB, s->space, ref->data);
    for (size_t i = 0; i < n; ++i)
        if (!s->mask[i])
            s->original[3 * i] = s->original[3 * i + 1] = s->original[3 * i + 2] = 0;
    pack(s->original, s->mask, n, a);
    pack(ref->data, ref_mask, n_px_ref, b);
    if ((rc = phc_colour_match_histograms(s->cells, a, n_ref, b, m, err)))
        goto done;
    for (size_t i = 0, k = 0; i < n; ++i)
        if (s->mask[i]) {
            memcpy(s->matched + 3 * i, m + 3 * k, 3 * sizeof *m);
            ++k;
        }
done:
    free(a);
    free(b);
    free(m);
    return rc;
}

/* Venation map β = floor + (1 - floor) ridge on the leaf: a file, uniform,
 * or the fresh crop's ridge map faded out at the edge. */
static int venation_map(phc_leaf_setup *s, const phc_leaf_photo *fresh, const phc_leaf_setup_options *opt,
                        phc_error *err)
{
    const size_t w = s->w, h = s->h, n = w * h;
    double *ridge = NULL;
    int rc = PHC_OK;
    if (opt->veins == PHC_LEAF_MAP_FILE) {
        if ((rc = map_from_file(opt->veins_file, "veins", opt->veins_where, fresh, w, h, s->beta, err)))
            return rc;
    } else if (opt->veins == PHC_LEAF_MAP_UNIFORM) {
        for (size_t i = 0; i < n; ++i)
            s->beta[i] = 1;
    } else {
        phc_vein_options vo = phc_vein_options_default();
        rc = phc_photo_vein_map(&fresh->crop, fresh->mask, &vo, &ridge, err);
        if (!rc && !(rc = taper_edge(fresh, opt->vein_edge_taper, ridge, err)))
            rc = map_to_grid(ridge, fresh->crop.width, fresh->crop.height, w, h, s->beta, err);
        free(ridge);
        if (rc)
            return rc;
    }
    if (opt->veins != PHC_LEAF_MAP_UNIFORM)
        for (size_t i = 0; i < n; ++i)
            s->beta[i] = s->mask[i] ? opt->vein_floor + (1 - opt->vein_floor) * fmin(fmax(s->beta[i], 0), 1) : 0;
    return PHC_OK;
}

/* Stomata (uniform unless a file) and inflow (through the veins unless
 * told otherwise) maps; every map 0 off the leaf. */
static int stomata_inflow_maps(phc_leaf_setup *s, const phc_leaf_photo *fresh, const phc_leaf_setup_options *opt,
                               phc_error *err)
{
    const size_t w = s->w, h = s->h, n = w * h;
    int rc;
    if (opt->stomata == PHC_LEAF_MAP_FILE) {
        if ((rc = map_from_file(opt->stomata_file, "stomata", opt->stomata_where, fresh, w, h, s->stomata, err)))
            return rc;
    } else
        for (size_t i = 0; i < n; ++i)
            s->stomata[i] = 1;
    switch (opt->inflow) {
    case PHC_LEAF_MAP_FILE:
        if ((rc = map_from_file(opt->inflow_file, "inflow", opt->inflow_where, fresh, w, h, s->inflow, err)))
            return rc;
        break;
    case PHC_LEAF_MAP_UNIFORM:
        for (size_t i = 0; i < n; ++i)
            s->inflow[i] = 1;
        break;
    case PHC_LEAF_MAP_NONE:
        break;
    default:
        memcpy(s->inflow, s->beta, n * sizeof *s->inflow);
    }
    for (size_t i = 0; i < n; ++i)
        if (!s->mask[i])
            s->stomata[i] = s->inflow[i] = s->beta[i] = 0;
    return PHC_OK;
}

int phc_leaf_setup_new(const phc_leaf_photo *fresh, const phc_leaf_photo *reference,
                       const phc_leaf_setup_options *opt, phc_leaf_setup **out, phc_error *err)
{
    phc_leaf_setup *s = calloc(1, sizeof *s);
    phc_image ref = {0};
    unsigned char *ref_mask = NULL;
    int rc;
    *out = NULL;
    if (!s)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    s->space = opt->space;
    if ((rc = phc_leaf_photo_grid(fresh, opt->model_size, &s->fresh, &s->mask, err)) ||
        (rc = phc_leaf_photo_grid(reference, opt->model_size, &ref, &ref_mask, err)))
        goto fail;
    const size_t w = s->w = s->fresh.width, h = s->h = s->fresh.height, n = w * h;
    size_t n_ref = 0;
    for (size_t i = 0; i < n; ++i)
        s->cells += s->mask[i] != 0;
    for (size_t i = 0; i < ref.width * ref.height; ++i)
        n_ref += ref_mask[i] != 0;
    if (!s->cells || !n_ref) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: leaf %zu has no pixels on a %zu px grid", s->cells ? reference->path : fresh->path,
                           s->cells ? reference->number : fresh->number, opt->model_size);
        goto fail;
    }
    s->original = calloc(3 * n, sizeof *s->original);
    s->matched = calloc(3 * n, sizeof *s->matched);
    s->blend = calloc(3 * n, sizeof *s->blend);
    s->beta = calloc(n, sizeof *s->beta);
    s->stomata = calloc(n, sizeof *s->stomata);
    s->inflow = calloc(n, sizeof *s->inflow);
    if (!s->original || !s->matched || !s->blend || !s->beta || !s->stomata || !s->inflow) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = match_colours(s, &ref, ref_mask, err)) || (rc = venation_map(s, fresh, opt, err)) ||
        (rc = stomata_inflow_maps(s, fresh, opt, err)))
        goto fail;
    if (s->space != PHC_COLOUR_LAB) {
        /* the colours of pixels wholly original or matched, converted once
           here instead of at every evaluation (phc_leaf_setup_colours) */
        s->lab_original = malloc(3 * n * sizeof *s->lab_original);
        s->lab_matched = malloc(3 * n * sizeof *s->lab_matched);
        if (!s->lab_original || !s->lab_matched) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        phc_colour_convert(n, s->original, s->space, PHC_COLOUR_LAB, s->lab_original);
        phc_colour_convert(n, s->matched, s->space, PHC_COLOUR_LAB, s->lab_matched);
    }
    phc_leaf_params lp = phc_leaf_params_default();
    lp.dt = opt->dt;
    if ((rc = phc_leaf_new(w, h, s->mask, s->beta, s->stomata, s->inflow, lp, &s->leaf, err)))
        goto fail;
    phc_image_free(&ref);
    free(ref_mask);
    *out = s;
    return PHC_OK;
fail:
    phc_image_free(&ref);
    free(ref_mask);
    phc_leaf_setup_free(s);
    return rc;
}

int phc_leaf_setup_colours(phc_leaf_setup *s, phc_colour_transfer tf, double *lab, phc_image *srgb,
                           phc_error *err)
{
    const size_t n = s->w * s->h;
    const double *y = phc_leaf_fluid(s->leaf);
    int rc;
    if (srgb && (rc = phc_image_alloc(srgb, s->w, s->h, err)))
        return rc;
    /* eq. 9: blend in the matching space, then convert, run by run of leaf
     * pixels: pixels off the leaf get 0 (Lab) or white paper (sRGB) and
     * their blend is never looked at (s->blend keeps old values there) */
    for (size_t i = 0; i < n;) {
        if (!s->mask[i]) {
            if (lab)
                lab[3 * i] = lab[3 * i + 1] = lab[3 * i + 2] = 0;
            if (srgb)
                srgb->data[3 * i] = srgb->data[3 * i + 1] = srgb->data[3 * i + 2] = 1;
            ++i;
            continue;
        }
        size_t j = i + 1;
        while (j < n && s->mask[j])
            ++j;
        const size_t o = 3 * i;
        if (srgb || !lab || !s->lab_original)
            phc_colour_blend(j - i, s->original + o, s->matched + o, y + i, tf, s->blend + o);
        if (lab && s->lab_original) {
            /* g = 1 blends to original, g = 0 to matched, to the bit (g x
               + (1 - g) z with a factor 0 adds a zero): their Lab is the
               one computed at set-up; the pixels in between are blended
               (when not done above) and converted */
            for (size_t k = i; k < j; ++k) {
                const double g = phc_colour_transfer_weight(tf, y[k], NULL, NULL, NULL);
                if (g == 1.0)
                    memcpy(lab + 3 * k, s->lab_original + 3 * k, 3 * sizeof *lab);
                else if (g == 0.0)
                    memcpy(lab + 3 * k, s->lab_matched + 3 * k, 3 * sizeof *lab);
                else {
                    if (!srgb)
                        phc_colour_blend(1, s->original + 3 * k, s->matched + 3 * k, y + k, tf, s->blend + 3 * k);
                    phc_colour_srgb_to_lab(s->blend + 3 * k, lab + 3 * k);
                }
            }
        } else if (lab)
            phc_colour_convert(j - i, s->blend + o, s->space, PHC_COLOUR_LAB, lab + o);
        if (srgb)
            phc_colour_convert(j - i, s->blend + o, s->space, PHC_COLOUR_RGB, srgb->data + o);
        i = j;
    }
    return PHC_OK;
}

int phc_leaf_lab_pixels(const phc_image *img, const unsigned char *mask, double **lab, size_t *n,
                        phc_error *err)
{
    const size_t np = img->width * img->height;
    size_t k = 0;
    for (size_t i = 0; i < np; ++i)
        k += mask[i] != 0;
    *n = k;
    if (!(*lab = malloc((k ? 3 * k : 1) * sizeof **lab)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    pack(img->data, mask, np, *lab);
    phc_colour_convert(k, *lab, PHC_COLOUR_RGB, PHC_COLOUR_LAB, *lab);
    return PHC_OK;
}
