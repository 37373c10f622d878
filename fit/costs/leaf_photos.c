/* `leaf_photos` data sets: see leaf_photos.h. */
#include "fit/costs/leaf_photos.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/leaf_images.h"
#include "fit/costs/leaf_setup.h"
#include "fit/costs/origin.h"
#include "fit/costs/unique_times.h"
#include "fit/engine/cross_validation.h"
#include "measurements/photo.h"

#define KIND "leaf_photos"
/* The place of a message about option `key`: "cfg.yaml:12" from a config,
 * else the kind's name (fit/costs/origin.h). */
#define WHERE(key) phc_origin_key(opt->origin, KIND, key).text

/* Parameter slots and their defaults when no parameter of that name exists. */
enum { SL_BETA, SL_STOMATA, SL_INFLOW, SL_TIME, SL_YLO, SL_YHI, N_SLOTS };
static const char *const slot_names[N_SLOTS] = {"beta_scale", "stomata_scale", "inflow_scale",
                                                "time_scale", "y_lo", "y_hi"};
static const double slot_defaults[N_SLOTS] = {50, 0.1, 0.05, 1, 0.2, 0.8};
/* Their units where UDUNITS-2 can spell them: the transfer levels are fluid
 * amounts, dimensionless (model/leaf.h: y = 1 is a fresh leaf).  The model's
 * time unit is whatever dt is counted in and the stage's unit the user's (a
 * SPAD reading, days ...), so the scales declare none and keep `unit:` as a
 * label. */
static const char *const slot_units[N_SLOTS] = {NULL, NULL, NULL, NULL, "1", "1"};

/* Steps beyond which a trial point is refused (a runaway time scale). */
#define MAX_STEPS 200000

typedef struct lp_row {
    size_t line;          /* in the rows file */
    char *id;
    double stage;
    double dstage;        /* |stage - stage(initial)| */
    int role;             /* 0 data, 1 initial, 2 reference */
    phc_leaf_photo photo;
    double greenness;     /* mean G/(R+G+B) over the leaf */
    size_t first, count;  /* residuals of this row */
    double correlation;   /* registration ECC (pixels mode), NAN otherwise */
    double *obs;          /* pixels: 3 per valid cell (Lab means); histogram: 3 nq quantiles */
    unsigned char *cell_ok; /* pixels: per cell */
    unsigned char *mask;  /* pixels: the registered photo's mask on the model grid */
    phc_image grid;       /* the photo on the model grid (registered in pixels mode) */
} lp_row;

typedef struct lp_impl {
    phc_photo_cache *cache;
    phc_leaf_setup *su;
    lp_row *rows;
    size_t n_rows, initial, reference; /* reference == n_rows: a separate file */
    phc_leaf_photo ref_photo;          /* when the reference is a separate file */
    int slot[N_SLOTS];                 /* slot index or -1 */
    int histogram, de2000, direction;  /* direction +1 increasing, -1 decreasing */
    size_t nq, grid, cw, ch, cell;     /* cells cw x ch of cell x cell model px */
    double sigma;
    char *stage_name;
    size_t *row_of;                    /* per residual */
    double *t_unique;                  /* distinct dstage values, sorted */
    size_t m_unique, *t_at;            /* per data row index (into rows) */
    double *lab;                       /* 3 w h scratch */
    double *scratch;                   /* w h */
    int cross_validate;                /* the engine's leave-one-out (lp_cross_validation) */
} lp_impl;

static void lp_free(void *p)
{
    lp_impl *im = p;
    if (!im)
        return;
    for (size_t r = 0; r < im->n_rows; ++r) {
        free(im->rows[r].id);
        phc_leaf_photo_free(&im->rows[r].photo);
        free(im->rows[r].obs);
        free(im->rows[r].cell_ok);
        free(im->rows[r].mask);
        phc_image_free(&im->rows[r].grid);
    }
    free(im->rows);
    phc_leaf_photo_free(&im->ref_photo);
    phc_leaf_setup_free(im->su);
    phc_photo_cache_free(im->cache);
    free(im->stage_name);
    free(im->row_of);
    free(im->t_unique);
    free(im->t_at);
    free(im->lab);
    free(im->scratch);
    free(im);
}

/* Slot values with defaults for absent slots. */
static void slot_values(const lp_impl *im, const double *p, double v[N_SLOTS])
{
    for (int q = 0; q < N_SLOTS; ++q)
        v[q] = im->slot[q] >= 0 ? p[im->slot[q]] : slot_defaults[q];
}

/* Applies the scales; 1 when the point is outside the model's domain. */
static int apply_params(lp_impl *im, const double v[N_SLOTS], phc_colour_transfer *tf)
{
    if (!(v[SL_BETA] >= 0 && v[SL_STOMATA] >= 0 && v[SL_INFLOW] >= 0 && v[SL_TIME] > 0 &&
          isfinite(v[SL_YLO]) && v[SL_YHI] > v[SL_YLO]))
        return 1;
    phc_leaf_params lp = phc_leaf_get_params(im->su->leaf);
    if (im->t_unique && im->m_unique &&
        v[SL_TIME] * im->t_unique[im->m_unique - 1] / lp.dt > MAX_STEPS)
        return 1;
    lp.beta_scale = v[SL_BETA];
    lp.stomata_scale = v[SL_STOMATA];
    lp.inflow_scale = v[SL_INFLOW];
    if (phc_leaf_set_params(im->su->leaf, lp, NULL))
        return 1;
    tf->y_lo = v[SL_YLO];
    tf->y_hi = v[SL_YHI];
    return 0;
}

/* Mean CIELAB colour of cell (cx, cy) over the pixels that are leaf in
 * both the fresh leaf and row's photo; 0 when there are none. */
static size_t cell_mean(const lp_impl *im, const unsigned char *row_mask, const double *lab, size_t cx,
                        size_t cy, double s[3])
{
    const phc_leaf_setup *su = im->su;
    size_t cnt = 0;
    s[0] = s[1] = s[2] = 0;
    for (size_t y = cy * im->cell; y < (cy + 1) * im->cell && y < su->h; ++y)
        for (size_t x = cx * im->cell; x < (cx + 1) * im->cell && x < su->w; ++x) {
            const size_t i = x + su->w * y;
            if (su->mask[i] && row_mask[i]) {
                for (int c = 0; c < 3; ++c)
                    s[c] += lab[3 * i + c];
                ++cnt;
            }
        }
    for (int c = 0; cnt && c < 3; ++c)
        s[c] /= (double)cnt;
    return cnt;
}

/* Quantiles of L*, a*, b* over the leaf pixels of a Lab field (mask). */
static void lab_quantiles(lp_impl *im, const double *lab, const unsigned char *mask, size_t n_pix, double *q)
{
    size_t k = 0;
    for (size_t i = 0; i < n_pix; ++i)
        if (mask[i]) {
            memcpy(im->scratch + 3 * k, lab + 3 * i, 3 * sizeof(double));
            ++k;
        }
    double *tmp = im->scratch + 3 * k;
    for (int c = 0; c < 3; ++c)
        phc_colour_quantiles(k, im->scratch, c, im->nq, tmp, q + c * im->nq, NULL);
}

/* The model values of row r from the current colours (im->lab). */
static void row_values(lp_impl *im, const lp_row *row, double *yhat)
{
    const phc_leaf_setup *su = im->su;
    if (im->histogram) {
        lab_quantiles(im, im->lab, su->mask, su->w * su->h, yhat);
        return;
    }
    size_t k = 0;
    for (size_t cy = 0; cy < im->ch; ++cy)
        for (size_t cx = 0; cx < im->cw; ++cx) {
            if (!row->cell_ok[cx + im->cw * cy])
                continue;
            double s[3];
            cell_mean(im, row->mask, im->lab, cx, cy, s);
            if (im->de2000)
                yhat[k] = phc_colour_de2000(s, row->obs + 3 * k);
            else
                memcpy(yhat + 3 * k, s, sizeof s);
            ++k;
        }
}

static int lp_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    (void)jac;
    lp_impl *im = ds->impl;
    double v[N_SLOTS];
    phc_colour_transfer tf;
    slot_values(im, p, v);
    if (apply_params(im, v, &tf))
        return 1;
    phc_leaf_reset(im->su->leaf, 1.0);
    double t_prev = 0;
    for (size_t u = 0; u < im->m_unique; ++u) {
        const double t = v[SL_TIME] * im->t_unique[u];
        if (phc_leaf_advance(im->su->leaf, t - t_prev))
            return 1;
        t_prev = t;
        if (phc_leaf_setup_colours(im->su, tf, im->lab, NULL, NULL))
            return -1;
        /* histogram residuals do not depend on the row: rows at the same
         * time copy the first one's quantiles instead of sorting again */
        const double *same = NULL;
        for (size_t r = 0; r < im->n_rows; ++r) {
            const lp_row *row = &im->rows[r];
            if (row->role != 0 || im->t_at[r] != u)
                continue;
            if (same)
                memcpy(yhat + row->first, same, row->count * sizeof *yhat);
            else
                row_values(im, row, yhat + row->first);
            if (im->histogram)
                same = yhat + row->first;
        }
    }
    return 0;
}

/* ---- report ------------------------------------------------------------------------ */

static const char *correction_name(phc_colour_correction_method m)
{
    return m == PHC_CC_COLORCHECKER ? "ColorChecker" : m == PHC_CC_GRAY_WORLD ? "gray world" : "none";
}

/* RMS over a row's residuals of the colour difference, in ΔE units: for
 * de76 the ΔE*ab of each cell, else the residual itself. */
static double row_rms_de(const lp_impl *im, const phc_dataset *ds, const lp_row *row, const double *yhat)
{
    double s = 0;
    size_t m = 0;
    if (!im->histogram && !im->de2000) {
        for (size_t k = 0; k < row->count / 3; ++k) {
            double d2 = 0;
            for (int c = 0; c < 3; ++c) {
                const double d = ds->y[row->first + 3 * k + c] - yhat[row->first + 3 * k + c];
                d2 += d * d;
            }
            s += d2;
            ++m;
        }
    } else
        for (size_t k = 0; k < row->count; ++k) {
            const double d = ds->y[row->first + k] - yhat[row->first + k];
            s += d * d;
            ++m;
        }
    return m ? sqrt(s / (double)m) : NAN;
}

static int lp_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    lp_impl *im = ds->impl;
    char *out = NULL;
    size_t len = 0;
    double *yhat = malloc(ds->n * sizeof *yhat);
    int rc = PHC_OK;
    if (!yhat)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (lp_predict(ds, p, yhat, NULL)) {
        free(yhat);
        return phc_error_set(err, PHC_ERR_DOMAIN, "data set '%s': the leaf model cannot be evaluated at the optimum",
                             ds->name);
    }
    FILE *f = open_memstream(&out, &len);
    if (!f) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    const phc_leaf_setup *su = im->su;
    const phc_leaf_params lp = phc_leaf_get_params(su->leaf);
    const lp_row *ini = &im->rows[im->initial];
    const phc_leaf_photo *ref = im->reference < im->n_rows ? &im->rows[im->reference].photo : &im->ref_photo;
    fprintf(f, "Leaf colour aging (Silva et al. §3): the fresh leaf is leaf %zu of `%s` (row '%s', %s %g); the "
               "senescent reference is leaf %zu of `%s`.  Model grid %zu × %zu px (%zu leaf pixels), step %g "
               "time units; histogram matching in %s; colour correction: %s",
            ini->photo.number, ini->photo.path, ini->id, im->stage_name, ini->stage, ref->number, ref->path, su->w,
            su->h, su->cells, lp.dt, su->space == PHC_COLOUR_LAB ? "CIELAB" : "sRGB (the paper's choice)",
            correction_name(ini->photo.correction.method));
    if (ini->photo.correction.method == PHC_CC_COLORCHECKER)
        fprintf(f, " (%zu patches, mean ΔE00 %.2f before, %.2f after, largest %.2f)",
                ini->photo.correction.patches, ini->photo.correction.mean_de_before, ini->photo.correction.mean_de,
                ini->photo.correction.max_de);
    fprintf(f, ".  Residuals: %s, σ = %g ΔE.\n\n",
            im->histogram ? "quantiles of L*, a*, b* over the leaf (histogram distance)"
            : im->de2000  ? "CIEDE2000 per grid cell"
                          : "ΔL*, Δa*, Δb* per grid cell (ΔE*ab)",
            im->sigma);
    fprintf(f, "| row | %s | model time | residuals | %s | %s\n|---|---|---|---|---|%s\n", im->stage_name,
            im->histogram ? "RMS quantile difference (CIELAB)" : "RMS ΔE of the cells",
            im->histogram ? "" : "registration ECC |", im->histogram ? "" : "---|");
    double v[N_SLOTS];
    slot_values(im, p, v);
    for (size_t r = 0; r < im->n_rows; ++r) {
        const lp_row *row = &im->rows[r];
        if (row->role)
            continue;
        fprintf(f, "| %s | %g | %.4g | %zu | %.3g |", row->id, row->stage, v[SL_TIME] * row->dstage, row->count,
                row_rms_de(im, ds, row, yhat));
        if (!im->histogram)
            fprintf(f, " %.4f |", row->correlation);
        fputc('\n', f);
    }
    if (ferror(f) | (fclose(f) != 0)) {
        free(out);
        out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    free(yhat);
    *markdown = out;
    return rc;
}

/* ---- cross-validation (by the engine: fit/engine/cross_validation.h) -------------------------- */

/* The stage of row r read off the model: the model time whose colours are
 * closest (weighted squared residuals) to the row's photo, searched over
 * the model's steps up to 1.5 times the largest model time of the data,
 * refined by a parabola through the best step and its neighbours. */
static int predict_stage(phc_dataset *ds, const double *p, const lp_row *row, double *stage)
{
    lp_impl *im = ds->impl;
    double v[N_SLOTS];
    phc_colour_transfer tf;
    slot_values(im, p, v);
    if (apply_params(im, v, &tf))
        return 1;
    const double dt = phc_leaf_get_params(im->su->leaf).dt;
    const double t_end = 1.5 * v[SL_TIME] * im->t_unique[im->m_unique - 1];
    const size_t steps = (size_t)ceil(t_end / dt);
    double *d = malloc((steps + 1) * sizeof *d), *yh = malloc(row->count * sizeof *yh);
    if (!d || !yh) {
        free(d);
        free(yh);
        return -1;
    }
    phc_leaf_reset(im->su->leaf, 1.0);
    size_t best = 0;
    for (size_t s = 0; s <= steps; ++s) {
        if (s > 0 && phc_leaf_step(im->su->leaf, dt)) {
            free(d);
            free(yh);
            return 1;
        }
        phc_leaf_setup_colours(im->su, tf, im->lab, NULL, NULL);
        row_values(im, row, yh);
        double q = 0;
        for (size_t i = 0; i < row->count; ++i) {
            const double e = (ds->y[row->first + i] - yh[i]) / ds->sigma[row->first + i];
            q += e * e;
        }
        d[s] = q;
        if (q < d[best])
            best = s;
    }
    double t = (double)best * dt;
    if (best > 0 && best < steps) {
        const double a = d[best - 1], b = d[best], c = d[best + 1], den = a - 2 * b + c;
        if (den > 0)
            t += 0.5 * dt * (a - c) / den;
    }
    *stage = im->rows[im->initial].stage + im->direction * t / v[SL_TIME];
    free(d);
    free(yh);
    return 0;
}

/* The row of the g-th data row (the groups of the cross-validation). */
static size_t data_row(const lp_impl *im, size_t g)
{
    for (size_t r = 0, k = 0; r < im->n_rows; ++r)
        if (im->rows[r].role == 0 && k++ == g)
            return r;
    return im->n_rows;
}

/* The greenness baseline for row j: the least-squares line stage = a + b g
 * in the mean chromatic greenness g over every other row (the fresh and
 * reference leaves included), at row j's greenness. */
static double greenness_baseline(const lp_impl *im, size_t j)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    size_t c = 0;
    for (size_t i = 0; i < im->n_rows; ++i) {
        if (i == j)
            continue;
        const double g = im->rows[i].greenness, y = im->rows[i].stage;
        sx += g;
        sy += y;
        sxx += g * g;
        sxy += g * y;
        ++c;
    }
    const double den = (double)c * sxx - sx * sx;
    const double b = den != 0 ? ((double)c * sxy - sx * sy) / den : 0, a = (sy - b * sx) / (double)c;
    return a + b * im->rows[j].greenness;
}

/* Group g (a data row) left out: its stage read off the model at the
 * refitted slot values p (NAN outside the model's domain), and the
 * greenness baseline. */
static int lp_cv_predict(phc_dataset *ds, const double *p, size_t g, double *values, phc_error *err)
{
    const lp_impl *im = ds->impl;
    const size_t j = data_row(im, g);
    if (j == im->n_rows)
        return phc_error_set(err, PHC_ERR_INVALID, "data set '%s': no data row %zu", ds->name, g);
    values[0] = NAN;
    if (predict_stage(ds, p, &im->rows[j], &values[0]) < 0)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    values[1] = greenness_baseline(im, j);
    return PHC_OK;
}

/* The plan of the leave-one-out prediction of each row's stage: a group per
 * data row (the residuals of its photo); the fresh and reference leaves
 * are never left out. */
static int lp_plan(phc_dataset *ds, phc_cv_plan *plan, phc_error *err)
{
    const lp_impl *im = ds->impl;
    size_t ng = 0;
    for (size_t r = 0; r < im->n_rows; ++r)
        ng += im->rows[r].role == 0;
    memset(plan, 0, sizeof *plan);
    plan->group = malloc((ds->n ? ds->n : 1) * sizeof *plan->group);
    plan->names = calloc(ng ? ng : 1, sizeof *plan->names);
    plan->observed = malloc((ng ? ng : 1) * sizeof *plan->observed);
    plan->n_groups = ng;
    if (!plan->group || !plan->names || !plan->observed)
        goto nomem;
    for (size_t i = 0; i < ds->n; ++i)
        plan->group[i] = PHC_CV_NO_GROUP;
    for (size_t r = 0, g = 0; r < im->n_rows; ++r) {
        const lp_row *row = &im->rows[r];
        if (row->role)
            continue;
        for (size_t i = row->first; i < row->first + row->count; ++i)
            plan->group[i] = g;
        if (!(plan->names[g] = strdup(row->id)))
            goto nomem;
        plan->observed[g++] = row->stage;
    }
    plan->n_predictions = 2;
    plan->labels[0] = "model";
    plan->labels[1] = "baseline";
    plan->quantity = im->stage_name;
    plan->group_title = "row";
    plan->how = "the stage read off the model time whose colours match the photo best";
    plan->note = "Baseline: a straight line in the mean chromatic greenness G/(R+G+B), fitted on the same rows.";
    plan->predict = lp_cv_predict;
    return PHC_OK;
nomem:
    phc_cv_plan_clear(plan);
    return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
}

/* The op: a plan when the data set asks for cross-validation. */
static int lp_cross_validation(phc_dataset *ds, phc_cv_plan *plan, phc_error *err)
{
    const lp_impl *im = ds->impl;
    return im->cross_validate ? lp_plan(ds, plan, err) : PHC_OK;
}

int phc_leaf_photos_cross_validate(phc_dataset *ds, const double *p, size_t *n_rows, char ***ids,
                                   double **stage, double **model, double **baseline, double rmse[2],
                                   phc_error *err)
{
    const lp_impl *im = ds->impl;
    const size_t n = im->n_rows;
    phc_cv_plan plan;
    phc_cv_result *res = NULL;
    *ids = calloc(n, sizeof **ids);
    *stage = malloc(n * sizeof **stage);
    *model = malloc(n * sizeof **model);
    *baseline = malloc(n * sizeof **baseline);
    *n_rows = n;
    rmse[0] = rmse[1] = NAN;
    int rc = PHC_OK;
    if (!*ids || !*stage || !*model || !*baseline) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = lp_plan(ds, &plan, err)))
        goto done;
    rc = phc_cross_validate_plan(ds->problem, ds, &plan, p, ds->progress, ds->progress_data, &res, err);
    phc_cv_plan_clear(&plan);
    if (rc)
        goto done;
    for (size_t j = 0, g = 0; j < n; ++j) {
        const lp_row *row = &im->rows[j];
        if (!((*ids)[j] = strdup(row->id))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        (*stage)[j] = row->stage;
        (*model)[j] = (*baseline)[j] = NAN;
        if (row->role == 0 && res && g < res->n_groups) {
            (*model)[j] = res->predicted[2 * g];
            (*baseline)[j] = res->predicted[2 * g + 1];
            ++g;
        }
    }
    if (res) {
        rmse[0] = res->rmse[0];
        rmse[1] = res->rmse[1];
    }
done:
    phc_cv_result_free(res);
    if (rc) {
        for (size_t j = 0; *ids && j < n; ++j)
            free((*ids)[j]);
        free(*ids);
        free(*stage);
        free(*model);
        free(*baseline);
        *ids = NULL;
        *stage = *model = *baseline = NULL;
    }
    return rc;
}

/* ---- images ---------------------------------------------------------------------------- */

/* The slot values p applied to the model (for the output writers);
 * PHC_ERR_DOMAIN naming the data set when they are outside its domain. */
static int use_point(phc_dataset *ds, const double *p, double v[N_SLOTS], phc_colour_transfer *tf, phc_error *err)
{
    lp_impl *im = ds->impl;
    slot_values(im, p, v);
    if (apply_params(im, v, tf))
        return phc_error_set(err, PHC_ERR_DOMAIN, "data set '%s': the leaf parameters are outside the model's domain",
                             ds->name);
    return PHC_OK;
}

/* Enlargement so a model-grid image is about 256 px on its long side. */
static size_t enlarge_factor(const phc_leaf_setup *su)
{
    const size_t m = su->w > su->h ? su->w : su->h;
    return m >= 256 ? 1 : (256 + m - 1) / m;
}

#define N_FRAMES 8

/* simulate: the aging sequence at N_FRAMES times from 0 to the largest
 * model time of the data (frames and fluid maps as PNG, a contact sheet),
 * and the venation, stomata and inflow maps. */
static int lp_simulate_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err)
{
    lp_impl *im = ds->impl;
    phc_leaf_setup *su = im->su;
    double v[N_SLOTS];
    phc_colour_transfer tf;
    int rc;
    if ((rc = use_point(ds, p, v, &tf, err)))
        return rc;
    const size_t n = su->w * su->h, fac = enlarge_factor(su);
    phc_image colour[N_FRAMES], fluid[N_FRAMES], big[2 * N_FRAMES], sheet = {0}, bar = {0};
    char caption[2 * N_FRAMES][64], path[8192];
    /* the sheet: N_FRAMES / 2 frames and one more cell per row */
    const char *caps[2 * N_FRAMES + 4] = {0};
    const phc_image *tiles[2 * N_FRAMES + 4] = {0};
    double *y[N_FRAMES];
    memset(colour, 0, sizeof colour);
    memset(fluid, 0, sizeof fluid);
    memset(big, 0, sizeof big);
    memset(y, 0, sizeof y);
    rc = PHC_OK;
    double t_end = v[SL_TIME] * im->t_unique[im->m_unique - 1], y_max = 1;
    if (!(t_end > 0))
        t_end = 10 * phc_leaf_get_params(su->leaf).dt;
    phc_leaf_reset(su->leaf, 1.0);
    for (int k = 0; k < N_FRAMES; ++k) {
        const double t = t_end * k / (N_FRAMES - 1);
        if (phc_leaf_advance(su->leaf, t - phc_leaf_time(su->leaf))) {
            rc = phc_error_set(err, PHC_ERR_NUMERIC, "data set '%s': the leaf model failed at t = %g", ds->name, t);
            goto done;
        }
        if (!(y[k] = malloc(n * sizeof *y[k]))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        memcpy(y[k], phc_leaf_fluid(su->leaf), n * sizeof *y[k]);
        for (size_t i = 0; i < n; ++i)
            y_max = fmax(y_max, y[k][i]);
        if ((rc = phc_leaf_setup_colours(su, tf, NULL, &colour[k], err)))
            goto done;
        snprintf(path, sizeof path, "%s/%s_frame_%02d.png", dir, base, k);
        if ((rc = phc_photo_write_png(path, &colour[k], err)))
            goto done;
        snprintf(caption[k], sizeof caption[k], "colour, t = %.3g d", t);
    }
    for (int k = 0; k < N_FRAMES; ++k) {
        /* every fluid map on one scale, 0 (dark blue) to y_max (yellow):
           the colour bar beside them */
        snprintf(caption[N_FRAMES + k], sizeof caption[k], "fluid y, t = %.3g d", t_end * k / (N_FRAMES - 1));
        snprintf(path, sizeof path, "%s/%s_fluid_%02d.png", dir, base, k);
        if ((rc = phc_photo_write_map_png(path, su->w, su->h, y[k], su->mask, 0, y_max, 1, err)) ||
            (rc = phc_leaf_map_image(su->w, su->h, y[k], su->mask, 0, y_max, &fluid[k], err)) ||
            (rc = phc_leaf_enlarge(&colour[k], fac, &big[k], err)) ||
            (rc = phc_leaf_enlarge(&fluid[k], fac, &big[N_FRAMES + k], err)))
            goto done;
    }
    /* contact sheet: colour frames in the first two rows, fluid maps in
       the next two, the fluid's colour bar right of the first fluid row
       (model time t in days, the unit of phytocal's rates) */
    if ((rc = phc_leaf_colour_bar(big[N_FRAMES].height, 0, y_max, "fluid y", &bar, err)))
        goto done;
    const size_t cols = N_FRAMES / 2 + 1;
    for (int k = 0; k < 2 * N_FRAMES; ++k) {
        const size_t cell = (size_t)k / (N_FRAMES / 2) * cols + (size_t)k % (N_FRAMES / 2);
        tiles[cell] = &big[k];
        caps[cell] = caption[k];
    }
    tiles[2 * cols + cols - 1] = &bar;
    caps[2 * cols + cols - 1] = "scale of all fluid maps";
    snprintf(path, sizeof path, "%s/%s_contact_sheet.png", dir, base);
    if ((rc = phc_leaf_sheet(tiles, caps, 4 * cols, cols, 8, &sheet, err)) ||
        (rc = phc_photo_write_png(path, &sheet, err)))
        goto done;
    const struct {
        const char *name;
        const double *map;
    } maps[3] = {{"veins", su->beta}, {"stomata", su->stomata}, {"inflow", su->inflow}};
    for (int q = 0; q < 3; ++q) {
        double hi = 0;
        for (size_t i = 0; i < n; ++i)
            hi = fmax(hi, maps[q].map[i]);
        snprintf(path, sizeof path, "%s/%s_%s_map.png", dir, base, maps[q].name);
        if ((rc = phc_photo_write_map_png(path, su->w, su->h, maps[q].map, su->mask, 0, hi > 0 ? hi : 1, 0, err)))
            goto done;
    }
done:
    for (int k = 0; k < N_FRAMES; ++k) {
        phc_image_free(&colour[k]);
        phc_image_free(&fluid[k]);
        free(y[k]);
    }
    for (int k = 0; k < 2 * N_FRAMES; ++k)
        phc_image_free(&big[k]);
    phc_image_free(&sheet);
    phc_image_free(&bar);
    return rc;
}

/* fit: each photo beside the simulated leaf at its model time. */
static int lp_fit_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err)
{
    lp_impl *im = ds->impl;
    phc_leaf_setup *su = im->su;
    double v[N_SLOTS];
    phc_colour_transfer tf;
    int rc;
    if ((rc = use_point(ds, p, v, &tf, err)))
        return rc;
    const size_t fac = enlarge_factor(su);
    size_t m = 0;
    for (size_t r = 0; r < im->n_rows; ++r)
        m += im->rows[r].role == 0;
    phc_image *big = calloc(2 * m, sizeof *big), sheet = {0};
    const phc_image **tiles = calloc(2 * m, sizeof *tiles);
    char **caps = calloc(2 * m, sizeof *caps);
    char path[8192];
    rc = PHC_OK;
    if (!big || !tiles || !caps) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    phc_leaf_reset(su->leaf, 1.0);
    size_t k = 0;
    for (size_t u = 0; u < im->m_unique; ++u) {
        const double t = v[SL_TIME] * im->t_unique[u];
        if (phc_leaf_advance(su->leaf, t - phc_leaf_time(su->leaf))) {
            rc = phc_error_set(err, PHC_ERR_NUMERIC, "data set '%s': the leaf model failed at t = %g", ds->name, t);
            goto done;
        }
        for (size_t r = 0; r < im->n_rows; ++r) {
            const lp_row *row = &im->rows[r];
            if (row->role || im->t_at[r] != u)
                continue;
            phc_image sim = {0};
            if ((rc = phc_leaf_setup_colours(su, tf, NULL, &sim, err)))
                goto done;
            rc = phc_leaf_enlarge(&sim, fac, &big[2 * k + 1], err);
            phc_image_free(&sim);
            if (rc || (rc = phc_leaf_enlarge(&row->grid, fac, &big[2 * k], err)))
                goto done;
            /* the photo on white paper, like the simulated leaf */
            for (size_t y = 0; y < big[2 * k].height; ++y)
                for (size_t x = 0; x < big[2 * k].width; ++x)
                    if (!row->mask[x / fac + row->grid.width * (y / fac)])
                        for (int c = 0; c < 3; ++c)
                            big[2 * k].data[3 * (x + big[2 * k].width * y) + c] = 1;
            caps[2 * k] = malloc(64);
            caps[2 * k + 1] = malloc(64);
            if (!caps[2 * k] || !caps[2 * k + 1]) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto done;
            }
            snprintf(caps[2 * k], 64, "photo %s, %s %g", row->id, im->stage_name, row->stage);
            snprintf(caps[2 * k + 1], 64, "model, t = %.3g d", t);
            ++k;
        }
    }
    for (size_t i = 0; i < 2 * m; ++i)
        tiles[i] = &big[i];
    snprintf(path, sizeof path, "%s/%s_observed_vs_simulated.png", dir, base);
    if ((rc = phc_leaf_sheet(tiles, (const char *const *)caps, 2 * m, 6, 8, &sheet, err)) ||
        (rc = phc_photo_write_png(path, &sheet, err)))
        goto done;
done:
    for (size_t i = 0; big && i < 2 * m; ++i)
        phc_image_free(&big[i]);
    for (size_t i = 0; caps && i < 2 * m; ++i)
        free(caps[i]);
    free(big);
    free(tiles);
    free(caps);
    phc_image_free(&sheet);
    return rc;
}

/* Histogram residuals: the series are the quantiles of L*, a* and b*
 * (observation c nq + k of a photo is quantile k of channel c, at the
 * probability (k + 1/2)/nq: model/colour.h). */
static void lp_series_name(const phc_dataset *ds, size_t g, char *buf, size_t size)
{
    static const char *const channel[3] = {"L*", "a*", "b*"};
    const size_t nq = ((const lp_impl *)ds->impl)->nq;
    snprintf(buf, size, "%s, %.3g %%", channel[g / nq % 3], 100.0 * ((double)(g % nq) + 0.5) / (double)nq);
}

static int lp_name_series(phc_dataset *ds, phc_error *err)
{
    const lp_impl *im = ds->impl;
    if (!ds->series || !im->histogram)
        return PHC_OK;
    return phc_dataset_name_series(ds, "quantile", 3 * im->nq, lp_series_name, err);
}

const phc_dataset_ops phc_leaf_photos_ops = {.kind = KIND,
                                            .predict = lp_predict,
                                            .free_impl = lp_free,
                                            .report_section = lp_report_section,
                                            .simulate_outputs = lp_simulate_outputs,
                                            .fit_outputs = lp_fit_outputs,
                                            .name_series = lp_name_series,
                                            .cross_validation = lp_cross_validation};

/* ---- building ------------------------------------------------------------------------------ */

/* The row whose id is `id`, or PHC_ERR_INPUT naming the option `key`. */
static int find_row(const phc_leaf_photos_options *opt, const char *key, const lp_impl *im, const char *id,
                    size_t *row, phc_error *err)
{
    for (size_t r = 0; r < im->n_rows; ++r)
        if (!strcmp(im->rows[r].id, id)) {
            *row = r;
            return PHC_OK;
        }
    return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s': no row has id '%s'", WHERE(key), key, id);
}

/* Mean chromatic greenness G/(R+G+B) of an image's leaf pixels. */
static double mean_greenness(const phc_image *img, const unsigned char *mask)
{
    double s = 0;
    size_t n = 0;
    for (size_t i = 0; i < img->width * img->height; ++i)
        if (mask[i]) {
            const double *c = img->data + 3 * i, sum = c[0] + c[1] + c[2];
            if (sum > 0) {
                s += c[1] / sum;
                ++n;
            }
        }
    return n ? s / (double)n : NAN;
}

/* Histogram observations of a data row: the quantiles of L*, a*, b* over
 * the leaf in its photo on a grid the size of the model's. */
static int histogram_observations(lp_impl *im, lp_row *row, phc_error *err)
{
    const phc_leaf_setup *su = im->su;
    unsigned char *m = NULL;
    double *lab = NULL, *scr = NULL;
    int rc;
    if ((rc = phc_leaf_photo_grid(&row->photo, su->w > su->h ? su->w : su->h, &row->grid, &m, err)))
        return rc;
    const size_t np = row->grid.width * row->grid.height;
    lab = malloc(3 * np * sizeof *lab);
    row->obs = malloc(3 * im->nq * sizeof *row->obs);
    scr = malloc(2 * 3 * np * sizeof *scr);
    if (!lab || !row->obs || !scr) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    phc_colour_convert(np, row->grid.data, PHC_COLOUR_RGB, PHC_COLOUR_LAB, lab);
    double *keep = im->scratch;
    im->scratch = scr;
    lab_quantiles(im, lab, m, np, row->obs);
    im->scratch = keep;
    row->greenness = mean_greenness(&row->grid, m);
    row->count = 3 * im->nq;
    row->mask = m;
    m = NULL;
    rc = PHC_OK;
done:
    free(scr);
    free(m);
    free(lab);
    return rc;
}

/* Aligns a data row's photo `raw` and its mask `rm` (on the model grid) to
 * the fresh leaf by its outline: ECC on the two silhouettes (mask images),
 * because aging changes exactly the colours that ECC on the photos would
 * compare.  The warp then moves photo and mask; row->correlation is ECC's. */
static int register_row(const phc_leaf_setup *su, lp_row *row, phc_image *raw, unsigned char *rm, phc_error *err)
{
    const size_t n = su->w * su->h;
    double warp[6];
    phc_image sf = {0}, sr = {0}, aligned = {0}, warped = {0}, mw = {0};
    int rc;
    if ((rc = phc_image_alloc(&sf, su->w, su->h, err)) || (rc = phc_image_alloc(&sr, su->w, su->h, err)))
        goto done;
    for (size_t i = 0; i < n; ++i) {
        sf.data[3 * i] = sf.data[3 * i + 1] = sf.data[3 * i + 2] = su->mask[i];
        sr.data[3 * i] = sr.data[3 * i + 1] = sr.data[3 * i + 2] = rm[i];
    }
    if ((rc = phc_photo_register(&sf, &sr, NULL, NULL, &aligned, warp, &row->correlation, err)) ||
        (rc = phc_photo_warp(raw, warp, su->w, su->h, &warped, err)) ||
        (rc = phc_photo_warp(&sr, warp, su->w, su->h, &mw, err)))
        goto done;
    for (size_t i = 0; i < n; ++i)
        rm[i] = mw.data[3 * i] >= 0.5;
    phc_image_free(raw);
    *raw = warped;
    warped.data = NULL;
done:
    phc_image_free(&sf);
    phc_image_free(&sr);
    phc_image_free(&aligned);
    phc_image_free(&warped);
    phc_image_free(&mw);
    return rc;
}

/* Pixels observations of a data row: its photo on the fresh leaf's grid,
 * registered to it when asked, averaged over the cells that are at least
 * half leaf in both. */
static int pixels_observations(lp_impl *im, lp_row *row, int do_register, phc_error *err)
{
    const phc_leaf_setup *su = im->su;
    const size_t n = su->w * su->h;
    double *lab = NULL;
    phc_image raw = {0};
    unsigned char *rm = NULL;
    int rc;
    if ((rc = phc_photo_resize(&row->photo.crop, su->w, su->h, &raw, err)) ||
        (rc = phc_photo_resize_mask(row->photo.mask, row->photo.crop.width, row->photo.crop.height, su->w, su->h, &rm,
                                    err))) {
        phc_image_free(&raw);
        return rc;
    }
    /* the fresh leaf's grid is black off the leaf: so is this photo's */
    for (size_t i = 0; i < n; ++i)
        if (!rm[i])
            raw.data[3 * i] = raw.data[3 * i + 1] = raw.data[3 * i + 2] = 0;
    if (do_register && (rc = register_row(su, row, &raw, rm, err))) {
        phc_image_free(&raw);
        free(rm);
        return rc;
    }
    phc_image full = raw;
    row->mask = rm;
    row->grid = full;
    for (size_t i = 0; i < n; ++i)
        if (!rm[i])
            full.data[3 * i] = full.data[3 * i + 1] = full.data[3 * i + 2] = 0;
    row->greenness = mean_greenness(&full, rm);
    lab = malloc(3 * n * sizeof *lab);
    row->cell_ok = calloc(im->cw * im->ch, 1);
    row->obs = malloc(3 * im->cw * im->ch * sizeof *row->obs);
    if (!lab || !row->cell_ok || !row->obs) {
        free(lab);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    phc_colour_convert(n, full.data, PHC_COLOUR_RGB, PHC_COLOUR_LAB, lab);
    size_t k = 0;
    for (size_t cy = 0; cy < im->ch; ++cy)
        for (size_t cx = 0; cx < im->cw; ++cx) {
            double s[3];
            /* a cell counts when at least half of it is leaf in both */
            if (2 * cell_mean(im, rm, lab, cx, cy, s) < im->cell * im->cell)
                continue;
            row->cell_ok[cx + im->cw * cy] = 1;
            memcpy(row->obs + 3 * k, s, sizeof s);
            ++k;
        }
    row->count = im->de2000 ? k : 3 * k;
    free(lab);
    return PHC_OK;
}

/* The observations of a data row: pixels mode registers the photo to the
 * fresh leaf and averages cells; histogram mode takes quantiles. */
static int row_observations(lp_impl *im, lp_row *row, int do_register, phc_error *err)
{
    row->correlation = NAN;
    return im->histogram ? histogram_observations(im, row, err) : pixels_observations(im, row, do_register, err);
}

phc_leaf_photos_options phc_leaf_photos_options_default(void)
{
    phc_leaf_photos_options o;
    memset(&o, 0, sizeof o);
    o.direction = 1;
    o.residual = PHC_LEAF_RESIDUAL_PIXELS;
    o.difference = PHC_LEAF_DE76;
    o.grid = 24;
    o.quantiles = 16;
    o.sigma = 2;
    o.colour_correction = PHC_CC_NONE;
    o.register_photos = 1;
    o.setup = phc_leaf_setup_options_default();
    return o;
}

/* What a leaf_photos data set is built from, while it is built. */
typedef struct lp_build {
    const phc_leaf_photos_options *opt;
    const phc_leaf_photos_row *rows;
    lp_impl *im;
    size_t n_obs, n_data, k_slots; /* residuals, data rows, slots */
} lp_build;

/* Where the options placed a message: "cfg.yaml:12: key 'grid'" (the config
 * line of the key) or, built in C, "leaf_photos: key 'grid'". */
static void key_where(const phc_leaf_photos_options *opt, const char *key, char *buf, size_t size)
{
    snprintf(buf, size, "%s: key '%s'", WHERE(key), key);
}

/* The data set as a whole: "cfg.yaml:5: leaf_photos data set" or "leaf_photos". */
static void set_where(const phc_leaf_photos_options *opt, char *buf, size_t size)
{
    if (opt->origin && opt->origin->path)
        snprintf(buf, size, "%s: leaf_photos data set", WHERE(NULL));
    else
        snprintf(buf, size, "%s", KIND);
}

/* Where row r's value came from: its table line and `column` when the rows
 * came from a table ("leaves.csv:3: column 'leaf'", or "leaves.csv:3"
 * without a column), else the row and the field ("leaf_photos: rows[2]
 * (leaf)", or "leaf_photos: rows[2]" without a field). */
static void row_where(const lp_build *b, size_t r, const char *column, const char *field, char *buf, size_t size)
{
    const phc_leaf_photos_options *opt = b->opt;
    if (opt->rows_source && b->rows[r].line) {
        if (column)
            snprintf(buf, size, "%s:%zu: column '%s'", opt->rows_source, b->rows[r].line, column);
        else
            snprintf(buf, size, "%s:%zu", opt->rows_source, b->rows[r].line);
    } else if (field)
        snprintf(buf, size, "%s: rows[%zu] (%s)", KIND, r, field);
    else
        snprintf(buf, size, "%s: rows[%zu]", KIND, r);
}

/* Where row r's photo was named: the table's image column, the config's
 * `image:` key (one photo for every row), or the row. */
static void image_where(const lp_build *b, size_t r, char *buf, size_t size)
{
    if (b->opt->image_column || !b->opt->origin)
        row_where(b, r, b->opt->image_column, "image", buf, size);
    else
        key_where(b->opt, "image", buf, size);
}

static const char *stage_name(const phc_leaf_photos_options *opt)
{
    return opt->stage_name ? opt->stage_name : "stage";
}

/* The options' values within their ranges, the reference given once, at
 * least two rows. */
static int check_options(const phc_leaf_photos_options *opt, size_t n_rows, phc_error *err)
{
    const phc_leaf_setup_options *so = &opt->setup;
    const struct {
        const char *key;
        int ok;
        const char *what;
    } checks[] = {{"grid", opt->grid >= 2 && opt->grid <= 512, "an integer from 2 to 512"},
                  {"quantiles", opt->quantiles >= 2 && opt->quantiles <= 256, "an integer from 2 to 256"},
                  {"model_size", so->model_size >= 16 && so->model_size <= 4096, "an integer from 16 to 4096"},
                  {"sigma", opt->sigma > 0, "> 0"},
                  {"dt", so->dt > 0, "> 0"},
                  {"vein_floor", so->vein_floor >= 0 && so->vein_floor <= 1, "between 0 and 1"},
                  {"residual", opt->residual == PHC_LEAF_RESIDUAL_PIXELS || opt->residual == PHC_LEAF_RESIDUAL_HISTOGRAM,
                   "pixels or histogram"},
                  {"difference", opt->difference == PHC_LEAF_DE76 || opt->difference == PHC_LEAF_CIEDE2000,
                   "de76 or ciede2000"},
                  {"colour_space", so->space == PHC_COLOUR_RGB || so->space == PHC_COLOUR_LAB, "rgb or lab"},
                  {"colour_correction", opt->colour_correction == PHC_CC_NONE ||
                                            opt->colour_correction == PHC_CC_GRAY_WORLD ||
                                            opt->colour_correction == PHC_CC_COLORCHECKER,
                   "none, gray_world or colorchecker"},
                  {"veins", so->veins != PHC_LEAF_MAP_FILE || so->veins_file, "a file when the map is a file"},
                  {"stomata", so->stomata != PHC_LEAF_MAP_FILE || so->stomata_file, "a file when the map is a file"},
                  {"inflow", so->inflow != PHC_LEAF_MAP_FILE || so->inflow_file, "a file when the map is a file"}};
    char where[4400];
    for (size_t i = 0; i < sizeof checks / sizeof checks[0]; ++i)
        if (!checks[i].ok) {
            key_where(opt, checks[i].key, where, sizeof where);
            return phc_error_set(err, PHC_ERR_INPUT, "%s: must be %s", where, checks[i].what);
        }
    if (!opt->reference && !opt->reference_image && !opt->reference_pixels) {
        set_where(opt, where, sizeof where);
        return phc_error_set(err, PHC_ERR_INPUT, "%s: missing key 'reference' (the id of the senescent leaf's row, or "
                             "{image: FILE, leaf: N})", where);
    }
    if (opt->reference && (opt->reference_image || opt->reference_pixels)) {
        key_where(opt, "reference", where, sizeof where);
        return phc_error_set(err, PHC_ERR_INPUT, "%s: a row id or an image, not both", where);
    }
    if (n_rows < 2) {
        if (opt->rows_source)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:1: %zu data row%s below the header: a leaf_photos data set "
                                 "needs a fresh leaf and at least one more photo", opt->rows_source, n_rows,
                                 n_rows == 1 ? "" : "s");
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %zu row%s: a leaf_photos data set needs a fresh leaf and at "
                             "least one more photo", KIND, n_rows, n_rows == 1 ? "" : "s");
    }
    return PHC_OK;
}

/* The rows' ids, lines and stages; an id used twice and a stage that is
 * not a number are errors naming the row. */
static int copy_rows(lp_build *b, size_t n_rows, phc_error *err)
{
    lp_impl *im = b->im;
    char where[4400];
    if (!(im->rows = calloc(n_rows, sizeof *im->rows)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    im->n_rows = n_rows;
    for (size_t r = 0; r < n_rows; ++r) {
        const phc_leaf_photos_row *in = &b->rows[r];
        lp_row *row = &im->rows[r];
        row->line = in->line;
        row->stage = in->stage;
        char buf[32];
        snprintf(buf, sizeof buf, "%zu", in->line ? in->line : r + 1);
        if (!(row->id = strdup(in->id ? in->id : buf)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        if (!isfinite(row->stage)) {
            row_where(b, r, stage_name(b->opt), "stage", where, sizeof where);
            return phc_error_set(err, PHC_ERR_INPUT, "%s: the stage must be a finite number, found %g", where,
                                 row->stage);
        }
        for (size_t q = 0; q < r; ++q)
            if (!strcmp(im->rows[q].id, row->id)) {
                if (b->opt->rows_source && row->line && im->rows[q].line)
                    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: id '%s' is used twice (also on line %zu)",
                                         b->opt->rows_source, row->line, row->id, im->rows[q].line);
                return phc_error_set(err, PHC_ERR_INPUT, "%s: rows[%zu]: id '%s' is used twice (also rows[%zu])",
                                     KIND, r, row->id, q);
            }
    }
    return PHC_OK;
}

/* The fresh leaf: the row named by `initial`, else the earliest stage. */
static int choose_initial(lp_build *b, phc_error *err)
{
    lp_impl *im = b->im;
    int rc;
    if (b->opt->initial) {
        if ((rc = find_row(b->opt, "initial", im, b->opt->initial, &im->initial, err)))
            return rc;
    } else {
        im->initial = 0;
        for (size_t r = 1; r < im->n_rows; ++r)
            if (im->direction * (im->rows[r].stage - im->rows[im->initial].stage) < 0)
                im->initial = r;
    }
    im->rows[im->initial].role = 1;
    return PHC_OK;
}

/* Reads (or takes from memory) a photo into the cache under `name`,
 * errors placed at `where`. */
static int cache_photo(lp_impl *im, const char *name, const phc_image *pixels, phc_colour_correction_method cc,
                       const char *where, phc_error *err)
{
    return pixels ? phc_photo_cache_add(im->cache, name, pixels, cc, where, err)
                  : phc_photo_cache_read(im->cache, name, cc, where, err);
}

/* The senescent reference: a row (not the fresh leaf's) or its own photo,
 * whose errors are placed at `reference: {image: ...}` and its `leaf:`. */
static int choose_reference(lp_build *b, phc_error *err)
{
    const phc_leaf_photos_options *opt = b->opt;
    lp_impl *im = b->im;
    char where[4400];
    int rc;
    im->reference = im->n_rows;
    if (opt->reference) {
        if ((rc = find_row(opt, "reference", im, opt->reference, &im->reference, err)))
            return rc;
        if (im->reference == im->initial) {
            key_where(opt, "reference", where, sizeof where);
            return phc_error_set(err, PHC_ERR_INPUT, "%s: row '%s' is also the fresh leaf (initial)", where,
                                 opt->reference);
        }
        im->rows[im->reference].role = 2;
        return PHC_OK;
    }
    const char *name = opt->reference_image ? opt->reference_image : "reference_pixels";
    snprintf(where, sizeof where, "%s: reference: key 'image'", phc_origin_key(opt->reference_origin, KIND, "image").text);
    if ((rc = cache_photo(im, name, opt->reference_pixels, opt->colour_correction, where, err)))
        return rc;
    if (opt->reference_leaf)
        snprintf(where, sizeof where, "%s: reference: key 'leaf'",
                 phc_origin_key(opt->reference_origin, KIND, "leaf").text);
    return phc_leaf_photo_load(im->cache, name, opt->reference_leaf ? opt->reference_leaf : 1, opt->colour_correction,
                               where, &im->ref_photo, err);
}

/* The name of row r's photo in the cache: its file, or the name of its
 * image in memory (an earlier row's when they share the image). */
static void photo_name(const lp_build *b, size_t r, char *buf, size_t size)
{
    const phc_leaf_photos_row *in = &b->rows[r];
    if (in->image || !in->pixels) {
        snprintf(buf, size, "%s", in->image ? in->image : "");
        return;
    }
    size_t first = r;
    for (size_t q = 0; q < r; ++q)
        if (b->rows[q].pixels == in->pixels && !b->rows[q].image) {
            first = q;
            break;
        }
    snprintf(buf, size, "rows[%zu].pixels", first);
}

/* Every row's photo, read once per file and segmented; the row's leaf cut
 * out of it.  A photo's errors are placed where it was named, a leaf
 * number beyond its leaves at the row's leaf. */
static int load_row_photos(lp_build *b, phc_error *err)
{
    const phc_leaf_photos_options *opt = b->opt;
    lp_impl *im = b->im;
    char where[4400], name[4200];
    int rc;
    for (size_t r = 0; r < im->n_rows; ++r) {
        const phc_leaf_photos_row *in = &b->rows[r];
        photo_name(b, r, name, sizeof name);
        image_where(b, r, where, sizeof where);
        if (!name[0])
            return phc_error_set(err, PHC_ERR_INPUT, "%s: no image file given", where);
        if ((rc = cache_photo(im, name, in->pixels, opt->colour_correction, where, err)))
            return rc;
        if (in->leaf)
            row_where(b, r, opt->leaf_column, "leaf", where, sizeof where);
        if ((rc = phc_leaf_photo_load(im->cache, name, in->leaf ? in->leaf : 1, opt->colour_correction, where,
                                      &im->rows[r].photo, err)))
            return rc;
    }
    return PHC_OK;
}

/* Stages: every data row after the fresh leaf; a series (pixels) in order. */
static int check_stages(lp_build *b, phc_error *err)
{
    lp_impl *im = b->im;
    const double s0 = im->rows[im->initial].stage;
    char where[4400];
    for (size_t r = 0; r < im->n_rows; ++r) {
        lp_row *row = &im->rows[r];
        row->dstage = im->direction * (row->stage - s0);
        row_where(b, r, stage_name(b->opt), "stage", where, sizeof where);
        if (row->role == 0 && row->dstage < 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: stage %g comes before the fresh leaf's (%g, row '%s'; "
                                 "direction %s)", where, row->stage, s0, im->rows[im->initial].id,
                                 im->direction > 0 ? "increasing" : "decreasing");
        if (!im->histogram && r > 0 && im->direction * (row->stage - im->rows[r - 1].stage) < 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: stages out of order (%g after %g): the photos of one leaf "
                                 "must be listed in time order", where, row->stage, im->rows[r - 1].stage);
    }
    return PHC_OK;
}

/* The model set-up from the fresh and reference leaves (errors about a map
 * file at its key, the others at the data set), its grid cells and
 * scratch space. */
static int build_model(lp_build *b, phc_error *err)
{
    const phc_leaf_photos_options *opt = b->opt;
    lp_impl *im = b->im;
    phc_leaf_setup_options so = opt->setup;
    char map_where[3][4400];
    int rc;
    key_where(opt, "veins", map_where[0], sizeof map_where[0]);
    key_where(opt, "stomata", map_where[1], sizeof map_where[1]);
    key_where(opt, "inflow", map_where[2], sizeof map_where[2]);
    if (!so.veins_where)
        so.veins_where = map_where[0];
    if (!so.stomata_where)
        so.stomata_where = map_where[1];
    if (!so.inflow_where)
        so.inflow_where = map_where[2];
    if ((rc = phc_leaf_setup_new(&im->rows[im->initial].photo,
                                 im->reference < im->n_rows ? &im->rows[im->reference].photo : &im->ref_photo, &so,
                                 &im->su, err))) {
        const char *placed = opt->origin && opt->origin->path ? opt->origin->path : KIND;
        if (strncmp(err->message, placed, strlen(placed)) != 0) /* not placed yet */
            phc_error_prefix(err, rc, "%s", WHERE(NULL));
        return rc;
    }
    const phc_leaf_setup *su = im->su;
    im->cell = ((su->w > su->h ? su->w : su->h) + opt->grid - 1) / opt->grid;
    im->cw = (su->w + im->cell - 1) / im->cell;
    im->ch = (su->h + im->cell - 1) / im->cell;
    const size_t np = su->w * su->h;
    im->lab = malloc(3 * np * sizeof *im->lab);
    im->scratch = malloc(2 * 3 * np * sizeof *im->scratch);
    if (!im->lab || !im->scratch)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

/* Every data row's observations (the fresh and reference leaves give the
 * greenness baseline only); b->n_obs residuals over b->n_data rows. */
static int collect_observations(lp_build *b, phc_error *err)
{
    const phc_leaf_photos_options *opt = b->opt;
    lp_impl *im = b->im;
    char where[4400];
    int rc;
    b->n_obs = b->n_data = 0;
    for (size_t r = 0; r < im->n_rows; ++r) {
        lp_row *row = &im->rows[r];
        if (row->role) {
            /* the greenness baseline uses the fresh and reference leaves too */
            phc_image g = {0};
            unsigned char *gm = NULL;
            if ((rc = phc_leaf_photo_grid(&row->photo, opt->setup.model_size, &g, &gm, err)))
                return rc;
            row->greenness = mean_greenness(&g, gm);
            row->grid = g;
            free(gm);
            continue;
        }
        row_where(b, r, NULL, NULL, where, sizeof where);
        if ((rc = row_observations(im, row, opt->register_photos, err)))
            return phc_error_prefix(err, rc, "%s: row '%s'", where, row->id);
        if (!row->count)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: row '%s': no grid cell is leaf in both this photo and the "
                                 "fresh leaf (registration failed, or a different leaf: use residual: histogram)",
                                 where, row->id);
        row->first = b->n_obs;
        b->n_obs += row->count;
        ++b->n_data;
    }
    if (!b->n_data) {
        set_where(opt, where, sizeof where);
        if (opt->rows_source)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: no row of %s is left to fit besides the fresh leaf "
                                 "(initial) and the reference", where, opt->rows_source);
        return phc_error_set(err, PHC_ERR_INPUT, "%s: no row is left to fit besides the fresh leaf (initial) and the "
                             "reference", where);
    }
    return PHC_OK;
}

/* The distinct model times over the data rows, and each data row's. */
static int model_times(lp_build *b, phc_error *err)
{
    lp_impl *im = b->im;
    const size_t m_data = b->n_data;
    size_t *data_rows = malloc(m_data * sizeof *data_rows), *at = NULL;
    double *dst = malloc(m_data * sizeof *dst);
    int rc = PHC_OK;
    im->t_at = calloc(im->n_rows, sizeof *im->t_at);
    if (!data_rows || !dst || !im->t_at) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t r = 0, k = 0; r < im->n_rows; ++r)
        if (!im->rows[r].role) {
            data_rows[k] = r;
            dst[k++] = im->rows[r].dstage;
        }
    if ((rc = phc_unique_times(dst, m_data, &im->t_unique, &im->m_unique, &at, err)))
        goto done;
    for (size_t k = 0; k < m_data; ++k)
        im->t_at[data_rows[k]] = at[k];
done:
    free(at);
    free(dst);
    free(data_rows);
    return rc;
}

/* The slots that are parameters (is_parameter; NULL: all six). */
static int choose_slots(lp_build *b, phc_error *err)
{
    const phc_leaf_photos_options *opt = b->opt;
    lp_impl *im = b->im;
    b->k_slots = 0;
    for (int q = 0; q < N_SLOTS; ++q)
        im->slot[q] = !opt->is_parameter || opt->is_parameter(slot_names[q], opt->user_data) ? (int)b->k_slots++ : -1;
    if (!b->k_slots) {
        char where[4400];
        set_where(opt, where, sizeof where);
        return phc_error_set(err, PHC_ERR_INPUT, "%s: no parameter to fit: name at least one of beta_scale, "
                             "stomata_scale, inflow_scale, time_scale, y_lo, y_hi under parameters", where);
    }
    return PHC_OK;
}

/* The data set's slots, observations, sigmas, lines and labels. */
static int fill_dataset(const lp_build *b, phc_dataset *ds, phc_error *err)
{
    const phc_leaf_photos_options *opt = b->opt;
    const lp_impl *im = b->im;
    const size_t n = b->n_obs;
    for (int q = 0; q < N_SLOTS; ++q)
        if (im->slot[q] >= 0 && (!(ds->slot_names[im->slot[q]] = strdup(slot_names[q])) ||
                                 (slot_units[q] && phc_dataset_declare_unit(ds, slot_names[q], slot_units[q]))))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    ds->n = n;
    ds->x = malloc(n * sizeof *ds->x);
    ds->y = malloc(n * sizeof *ds->y);
    ds->sigma = malloc(n * sizeof *ds->sigma);
    if (opt->rows_source) {
        ds->data_lines = malloc(n * sizeof *ds->data_lines);
        ds->data_file = strdup(opt->rows_source);
    }
    if (im->histogram)
        ds->series = malloc(n * sizeof *ds->series);
    if (!ds->x || !ds->y || !ds->sigma || (opt->rows_source && (!ds->data_lines || !ds->data_file)) ||
        (im->histogram && !ds->series))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t r = 0; r < im->n_rows; ++r) {
        const lp_row *row = &im->rows[r];
        if (row->role)
            continue;
        for (size_t i = 0; i < row->count; ++i) {
            const size_t j = row->first + i;
            ds->x[j] = row->stage;
            ds->y[j] = im->de2000 ? 0 : row->obs[i];
            ds->sigma[j] = opt->sigma;
            if (ds->data_lines)
                ds->data_lines[j] = row->line;
            im->row_of[j] = r;
            if (ds->series)
                ds->series[j] = i;
        }
    }
    char xl[160];
    snprintf(xl, sizeof xl, "%s", stage_name(opt));
    ds->x_label = strdup(opt->x_label ? opt->x_label : xl);
    ds->y_label = strdup(opt->y_label ? opt->y_label
                         : im->histogram ? "CIELAB quantile (L*, a*, b*)"
                         : im->de2000    ? "CIEDE2000 to the photo"
                                         : "CIELAB cell mean (L*, a*, b*)");
    if (!ds->x_label || !ds->y_label)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    ds->derivatives = PHC_DERIV_CENTRAL;
    ds->config_line = phc_origin_line(opt->origin, NULL);
    return PHC_OK;
}

int phc_leaf_photos_new(const phc_leaf_photos_row *rows, size_t n_rows, const phc_leaf_photos_options *opt,
                        phc_dataset **out, phc_error *err)
{
    lp_build b = {.opt = opt, .rows = rows};
    phc_dataset *ds = NULL;
    int rc;
    *out = NULL;
    if ((rc = check_options(opt, n_rows, err)))
        return rc;
    lp_impl *im = b.im = calloc(1, sizeof *im);
    if (!im || !(im->cache = phc_photo_cache_new())) {
        free(im);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    im->histogram = opt->residual == PHC_LEAF_RESIDUAL_HISTOGRAM;
    im->de2000 = opt->difference == PHC_LEAF_CIEDE2000;
    im->nq = opt->quantiles;
    im->sigma = opt->sigma;
    im->direction = opt->direction < 0 ? -1 : 1;
    im->cross_validate = opt->cross_validate;
    if (!(im->stage_name = strdup(stage_name(opt)))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = copy_rows(&b, n_rows, err)) || (rc = choose_initial(&b, err)) || (rc = choose_reference(&b, err)) ||
        (rc = load_row_photos(&b, err)) || (rc = check_stages(&b, err)) || (rc = build_model(&b, err)) ||
        (rc = collect_observations(&b, err)) || (rc = model_times(&b, err)))
        goto fail;
    if ((rc = choose_slots(&b, err)))
        goto fail;
    if (!(ds = phc_dataset_new(&phc_leaf_photos_ops, b.k_slots)) ||
        !(im->row_of = malloc(b.n_obs * sizeof *im->row_of))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = fill_dataset(&b, ds, err)))
        goto fail;
    ds->impl = im;
    *out = ds;
    return PHC_OK;
fail:
    lp_free(im);
    phc_dataset_free(ds);
    return rc;
}
