/* `leaf_photos` data sets: see leaf_photos.h. */
#include "fit/costs/leaf_photos.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/leaf_images.h"
#include "fit/costs/leaf_setup.h"
#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */
#include "fit/costs/unique_times.h"
#include "fit/problem.h"
#include "measurements/photo.h"
#include "measurements/table.h"

const char *const phc_leaf_photos_keys[] = {
    "file", "image", "leaf", "id", "stage", "initial", "reference", "residual", "difference", "grid",
    "quantiles", "sigma", "colour_space", "colour_correction", "register", "model_size", "dt", "veins",
    "vein_floor", "stomata", "inflow", "cross_validate", "x_label", "y_label", NULL};
const phc_key_help phc_leaf_photos_help[] = {
    {"file", "CSV table with one row per photographed leaf, relative to the config file: the "
             "fresh leaf and at least one more. Required."},
    {"image", "The photo of every row (a file relative to the config file), or {column: NAME}: "
              "a column naming each row's photo. Required."},
    {"leaf", "Column: the leaf's number in its photo, a whole number >= 1 in reading order. "
             "Default: 1 for every row."},
    {"id", "Column naming the rows (for initial and reference). Default: the leaf column, "
           "else the row's line number."},
    {"stage", "{column: NAME, direction: increasing | decreasing} or a column name: each "
              "photo's stage, a time (increasing, the default) or a measured stage such as "
              "SPAD chlorophyll (decreasing); with residual pixels the rows are in stage order. "
              "Required."},
    {"initial", "Id of the row of the fresh leaf the model ages. Default: the row with the "
                "earliest stage."},
    {"reference", "The senescent reference leaf (eq. 8): a row id (not the initial one), or "
                  "{image: FILE, leaf: N} (N default 1). Required."},
    {"residual", "pixels (CIELAB means over grid cells of the photo and the simulated leaf) or "
                 "histogram (quantiles of L*, a*, b* over the leaf; for photos of different "
                 "leaves or that cannot be registered). Default: pixels."},
    {"difference", "pixels: de76 (3 residuals per cell, dL*, da*, db*) or ciede2000 (one per "
                   "cell). Default: de76."},
    {"grid", "pixels: grid cells on the long side of the leaf, 2 to 512. Default: 24."},
    {"quantiles", "histogram: quantiles per CIELAB channel, 2 to 256. Default: 16."},
    {"sigma", "Standard deviation of each residual, delta-E units, > 0. Default: 2."},
    {"colour_space", "Space in which the fresh leaf's colours are matched to the reference's: "
                     "rgb (the paper's) or lab. Default: rgb."},
    {"colour_correction", "Colour correction of every photo: none, gray_world or colorchecker "
                          "(a 24-patch ColorChecker Classic in the frame). Default: none."},
    {"register", "pixels: align each photo to the fresh leaf's (ECC on the silhouettes). "
                 "Default: true."},
    {"model_size", "Simulation grid, px on the long side of the leaf, 16 to 4096. "
                   "Default: 128."},
    {"dt", "Model step, in model time units, > 0. Default: 0.1."},
    {"veins", "Venation map: auto (ridge map of the fresh photo), uniform, or an image file the "
              "size of the fresh leaf's photo. Default: auto."},
    {"vein_floor", "Venation value on the lamina between veins, 0 to 1. Default: 0.05."},
    {"stomata", "Stomata map: uniform or an image file. Default: uniform."},
    {"inflow", "Inflow map: veins (the venation map), uniform, none or an image file. "
               "Default: veins."},
    {"cross_validate", "After the fit, predict each row's stage with that row left out, beside "
                       "a greenness baseline, in the report. Default: false."},
    {"x_label", "Axis label of the stage. Default: the stage column's name."},
    {"y_label", "Axis label of the residuals. Default: names the residual (e.g. \"CIELAB cell "
                "mean (L*, a*, b*)\")."},
    {NULL, NULL}};

/* Parameter slots and their defaults when no parameter of that name exists. */
enum { SL_BETA, SL_STOMATA, SL_INFLOW, SL_TIME, SL_YLO, SL_YHI, N_SLOTS };
static const char *const slot_names[N_SLOTS] = {"beta_scale", "stomata_scale", "inflow_scale",
                                                "time_scale", "y_lo", "y_hi"};
static const double slot_defaults[N_SLOTS] = {50, 0.1, 0.05, 1, 0.2, 0.8};

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
    int cross_validate;
    double *mask_row_zero;             /* during cross-validation: residuals of this row zeroed */
    size_t left_out;                   /* row left out (n_rows = none) */
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
    double *cv_stage = NULL, *cv_model = NULL, *cv_base = NULL;
    char **cv_ids = NULL;
    size_t cv_n = 0;
    double rmse[2] = {NAN, NAN};
    int rc = PHC_OK;
    if (!yhat)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (lp_predict(ds, p, yhat, NULL)) {
        free(yhat);
        return phc_error_set(err, PHC_ERR_DOMAIN, "data set '%s': the leaf model cannot be evaluated at the optimum",
                             ds->name);
    }
    if (im->cross_validate &&
        (rc = phc_leaf_photos_cross_validate(ds, p, &cv_n, &cv_ids, &cv_stage, &cv_model, &cv_base, rmse, err))) {
        free(yhat);
        return rc;
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
    if (im->cross_validate) {
        fprintf(f, "\n**Leave-one-out prediction of %s** (each row left out in turn; the free parameters refitted "
                   "on the others; the stage read off the model time whose colours match the photo best).  "
                   "Baseline: a straight line in the mean chromatic greenness G/(R+G+B), fitted on the same rows.\n\n"
                   "| row | measured | model | baseline |\n|---|---|---|---|\n", im->stage_name);
        for (size_t r = 0; r < cv_n; ++r)
            if (!isnan(cv_model[r]))
                fprintf(f, "| %s | %g | %.2f | %.2f |\n", cv_ids[r], cv_stage[r], cv_model[r], cv_base[r]);
        fprintf(f, "\nRMSE of the prediction (%s units): model **%.3g**, baseline **%.3g**.\n", im->stage_name,
                rmse[0], rmse[1]);
    }
    if (ferror(f) | (fclose(f) != 0)) {
        free(out);
        out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    free(yhat);
    for (size_t r = 0; cv_ids && r < cv_n; ++r)
        free(cv_ids[r]);
    free(cv_ids);
    free(cv_stage);
    free(cv_model);
    free(cv_base);
    *markdown = out;
    return rc;
}

/* ---- cross-validation -------------------------------------------------------------- */

static int loo_residuals(const double *p, double *r, double *jac, void *user)
{
    phc_dataset *ds = user;
    lp_impl *im = ds->impl;
    const int rc = phc_dataset_residuals(p, r, jac, ds);
    if (rc == 0 && im->left_out < im->n_rows) {
        const lp_row *row = &im->rows[im->left_out];
        for (size_t i = row->first; i < row->first + row->count; ++i)
            r[i] = 0;
    }
    return rc;
}

/* Refits the data set's free slots with row `left_out` excluded, from p;
 * the result overwrites p. */
static int refit_without(phc_dataset *ds, double *p, size_t fold, size_t folds, phc_error *err)
{
    const phc_problem *pb = ds->problem;
    phc_nls *nls = phc_nls_new(ds->k);
    size_t *idx = malloc(ds->k * sizeof *idx);
    int rc = PHC_OK;
    if (!nls || !idx) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t q = 0; q < ds->k; ++q) {
        const phc_parameter *par = &pb->params[ds->param_index[q]];
        idx[q] = q;
        double lo = par->lower, hi = par->upper;
        if (p[q] < lo || p[q] > hi)
            p[q] = fmin(fmax(p[q], lo), hi);
        if ((rc = phc_nls_set_parameter(nls, q, lo, hi, par->fixed, phc_problem_scale(pb, ds->param_index[q]), err)))
            goto done;
    }
    if ((rc = phc_nls_add_block(nls, ds->n, idx, ds->k, loo_residuals, PHC_DERIV_CENTRAL, PHC_LOSS_NONE, 1.0, ds,
                                err)))
        goto done;
    phc_nls_options opt = pb->options.nls;
    phc_progress_relay relay = {ds->progress, ds->progress_data, "leave-one-out", ds->name, fold, folds, 0};
    if (ds->progress) {
        opt.on_iteration = phc_progress_relay_iteration;
        opt.on_iteration_data = &relay;
    }
    phc_nls_summary sum;
    rc = phc_nls_solve(nls, &opt, p, &sum, err);
    if (rc == PHC_OK && relay.cancelled)
        rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
done:
    phc_nls_free(nls);
    free(idx);
    return rc;
}

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

int phc_leaf_photos_cross_validate(phc_dataset *ds, const double *p, size_t *n_rows, char ***ids,
                                   double **stage, double **model, double **baseline, double rmse[2],
                                   phc_error *err)
{
    lp_impl *im = ds->impl;
    const size_t n = im->n_rows;
    double *pj = malloc((ds->k ? ds->k : 1) * sizeof *pj);
    *ids = calloc(n, sizeof **ids);
    *stage = malloc(n * sizeof **stage);
    *model = malloc(n * sizeof **model);
    *baseline = malloc(n * sizeof **baseline);
    *n_rows = n;
    int rc = PHC_OK;
    if (!pj || !*ids || !*stage || !*model || !*baseline) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if (!ds->problem) {
        rc = phc_error_set(err, PHC_ERR_INVALID, "data set '%s': cross-validation needs the data set's problem",
                           ds->name);
        goto done;
    }
    double s2[2] = {0, 0};
    size_t m = 0, folds = 0, fold = 0;
    for (size_t j = 0; j < n; ++j)
        folds += im->rows[j].role == 0;
    for (size_t j = 0; j < n; ++j) {
        const lp_row *row = &im->rows[j];
        if (!((*ids)[j] = strdup(row->id))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        (*stage)[j] = row->stage;
        (*model)[j] = (*baseline)[j] = NAN;
        if (row->role)
            continue;
        /* model: refit without row j, then read its stage off the model */
        memcpy(pj, p, ds->k * sizeof *pj);
        im->left_out = j;
        ++fold;
        if (phc_progress_report(ds->progress, ds->progress_data, "leave-one-out", fold, folds, -1, NAN,
                                ds->name)) {
            im->left_out = n;
            rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
            goto done;
        }
        rc = refit_without(ds, pj, fold, folds, err);
        im->left_out = n;
        if (rc)
            goto done;
        const int pr = predict_stage(ds, pj, row, &(*model)[j]);
        if (pr < 0) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        /* baseline: least-squares line stage = a + b g over the other rows */
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        size_t c = 0;
        for (size_t i = 0; i < n; ++i) {
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
        (*baseline)[j] = a + b * row->greenness;
        if (!isnan((*model)[j])) {
            s2[0] += pow((*model)[j] - row->stage, 2);
            s2[1] += pow((*baseline)[j] - row->stage, 2);
            ++m;
        }
    }
    rmse[0] = m ? sqrt(s2[0] / (double)m) : NAN;
    rmse[1] = m ? sqrt(s2[1] / (double)m) : NAN;
    /* leave the model at the fitted values */
    double *yh = malloc(ds->n * sizeof *yh);
    if (yh)
        lp_predict(ds, p, yh, NULL);
    free(yh);
done:
    free(pj);
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

static const phc_dataset_ops leaf_photos_ops = {"leaf_photos", lp_predict, NULL, lp_free, lp_report_section,
                                                lp_simulate_outputs, lp_fit_outputs, lp_name_series};

/* ---- loading ------------------------------------------------------------------------------ */

/* One of `names` (NULL-terminated) for key `key`; *choice its index. */
static int choose(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key, const char *const *names,
                  int *choice, phc_error *err)
{
    const char *v = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, key, 0, "leaf_photos data set", &v, err)) || !v)
        return rc;
    for (int i = 0; names[i]; ++i)
        if (!strcmp(v, names[i])) {
            *choice = i;
            return PHC_OK;
        }
    char list[256] = "";
    for (int i = 0; names[i]; ++i) {
        strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, names[i], sizeof list - strlen(list) - 1);
    }
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': '%s' is not one of %s", doc->path,
                         phc_key_line(node, key), key, v, list);
}

/* A map key: the keywords in `names` (their index in *source), or a file. */
static int map_key(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key, const char *base_dir,
                   const char *const *names, const phc_leaf_map_source *sources, phc_leaf_map_source *source,
                   char **file, phc_error *err)
{
    const char *v = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, key, 0, "leaf_photos data set", &v, err)) || !v)
        return rc;
    for (int i = 0; names[i]; ++i)
        if (!strcmp(v, names[i])) {
            *source = sources[i];
            return PHC_OK;
        }
    *source = PHC_LEAF_MAP_FILE;
    if (!(*file = phc_join_path(base_dir, v)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

/* The row whose id is `id`, or PHC_ERR_INPUT naming the key. */
static int find_row(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key, const lp_impl *im,
                    const char *id, size_t *row, phc_error *err)
{
    for (size_t r = 0; r < im->n_rows; ++r)
        if (!strcmp(im->rows[r].id, id)) {
            *row = r;
            return PHC_OK;
        }
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': no row has id '%s'", doc->path, phc_key_line(node, key),
                         key, id);
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

/* The observations of data row r: pixels mode registers the photo to the
 * fresh leaf and averages cells; histogram mode takes quantiles. */
static int row_observations(lp_impl *im, lp_row *row, int do_register, phc_error *err)
{
    const phc_leaf_setup *su = im->su;
    const size_t n = su->w * su->h;
    unsigned char *m = NULL;
    double *lab = NULL;
    int rc;
    row->correlation = NAN;
    if (im->histogram) {
        if ((rc = phc_leaf_photo_grid(&row->photo, su->w > su->h ? su->w : su->h, &row->grid, &m, err)))
            return rc;
        const size_t np = row->grid.width * row->grid.height;
        lab = malloc(3 * np * sizeof *lab);
        row->obs = malloc(3 * im->nq * sizeof *row->obs);
        double *scr = malloc(2 * 3 * np * sizeof *scr);
        if (!lab || !row->obs || !scr) {
            free(scr);
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        phc_colour_convert(np, row->grid.data, PHC_COLOUR_RGB, PHC_COLOUR_LAB, lab);
        double *keep = im->scratch;
        im->scratch = scr;
        lab_quantiles(im, lab, m, np, row->obs);
        im->scratch = keep;
        free(scr);
        row->greenness = mean_greenness(&row->grid, m);
        row->count = 3 * im->nq;
        row->mask = m;
        m = NULL;
        rc = PHC_OK;
        goto done;
    }
    /* pixels: the photo on the fresh leaf's grid, registered to it */
    phc_image raw = {0}, full = {0};
    unsigned char *rm = NULL;
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
    if (do_register) {
        /* Aligned by the leaf's outline: ECC on the two silhouettes (mask
         * images), because aging changes exactly the colours that ECC on
         * the photos would compare.  The warp then moves photo and mask. */
        double warp[6];
        phc_image sf = {0}, sr = {0}, aligned = {0}, warped = {0}, mw = {0};
        if ((rc = phc_image_alloc(&sf, su->w, su->h, err)) || (rc = phc_image_alloc(&sr, su->w, su->h, err)))
            goto reg_done;
        for (size_t i = 0; i < n; ++i) {
            sf.data[3 * i] = sf.data[3 * i + 1] = sf.data[3 * i + 2] = su->mask[i];
            sr.data[3 * i] = sr.data[3 * i + 1] = sr.data[3 * i + 2] = rm[i];
        }
        if ((rc = phc_photo_register(&sf, &sr, NULL, NULL, &aligned, warp, &row->correlation, err)) ||
            (rc = phc_photo_warp(&raw, warp, su->w, su->h, &warped, err)) ||
            (rc = phc_photo_warp(&sr, warp, su->w, su->h, &mw, err)))
            goto reg_done;
        for (size_t i = 0; i < n; ++i)
            rm[i] = mw.data[3 * i] >= 0.5;
        phc_image_free(&raw);
        raw = warped;
        warped.data = NULL;
    reg_done:
        phc_image_free(&sf);
        phc_image_free(&sr);
        phc_image_free(&aligned);
        phc_image_free(&warped);
        phc_image_free(&mw);
        if (rc) {
            phc_image_free(&raw);
            free(rm);
            return rc;
        }
    }
    full = raw;
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
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
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
    rc = PHC_OK;
done:
    free(m);
    free(lab);
    return rc;
}

int phc_leaf_photos_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                         phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    static const char *const residual_names[] = {"pixels", "histogram", NULL};
    static const char *const difference_names[] = {"de76", "ciede2000", NULL};
    static const char *const space_names[] = {"rgb", "lab", NULL};
    static const char *const correction_names[] = {"none", "gray_world", "colorchecker", NULL};
    static const char *const direction_names[] = {"increasing", "decreasing", NULL};
    static const char *const vein_names[] = {"auto", "uniform", NULL};
    static const phc_leaf_map_source vein_sources[] = {PHC_LEAF_MAP_AUTO, PHC_LEAF_MAP_UNIFORM};
    static const char *const stomata_names[] = {"uniform", NULL};
    static const phc_leaf_map_source stomata_sources[] = {PHC_LEAF_MAP_UNIFORM};
    static const char *const inflow_names[] = {"veins", "uniform", "none", NULL};
    static const phc_leaf_map_source inflow_sources[] = {PHC_LEAF_MAP_AUTO, PHC_LEAF_MAP_UNIFORM, PHC_LEAF_MAP_NONE};
    static const char *const stage_keys[] = {"column", "direction", NULL};
    static const char *const ref_keys[] = {"image", "leaf", NULL};
    const char *ctx = "leaf_photos data set";
    const char *file = NULL, *leaf_col = NULL, *id_col = NULL, *stage_col = NULL, *image_name = NULL,
               *image_col = NULL, *x_label = NULL, *y_label = NULL;
    char *path = NULL, *veins_file = NULL, *stomata_file = NULL, *inflow_file = NULL, *img_path = NULL;
    phc_table *t = NULL;
    phc_dataset *ds = NULL;
    double *stage = NULL, *leafno = NULL, *dst = NULL;
    size_t *data_rows = NULL;
    char where[512];
    int rc;
    *out = NULL;
    lp_impl *im = calloc(1, sizeof *im);
    if (!im || !(im->cache = phc_photo_cache_new())) {
        free(im);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    phc_leaf_setup_options so = phc_leaf_setup_options_default();
    int residual = 0, difference = 0, space = 0, correction = 0, direction = 0, do_register = 1;
    long grid = 24, nq = 16, model_size = 128;
    double sigma = 2;
    im->cross_validate = 0;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "leaf", 0, ctx, &leaf_col, err)) ||
        (rc = phc_yaml_map_string(doc, node, "id", 0, ctx, &id_col, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &y_label, err)) ||
        (rc = choose(doc, node, "residual", residual_names, &residual, err)) ||
        (rc = choose(doc, node, "difference", difference_names, &difference, err)) ||
        (rc = choose(doc, node, "colour_space", space_names, &space, err)) ||
        (rc = choose(doc, node, "colour_correction", correction_names, &correction, err)) ||
        (rc = phc_yaml_map_boolean(doc, node, "register", 0, ctx, &do_register, err)) ||
        (rc = phc_yaml_map_boolean(doc, node, "cross_validate", 0, ctx, &im->cross_validate, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "grid", 0, ctx, &grid, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "quantiles", 0, ctx, &nq, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "model_size", 0, ctx, &model_size, err)) ||
        (rc = phc_yaml_map_number(doc, node, "sigma", 0, ctx, &sigma, err)) ||
        (rc = phc_yaml_map_number(doc, node, "dt", 0, ctx, &so.dt, err)) ||
        (rc = phc_yaml_map_number(doc, node, "vein_floor", 0, ctx, &so.vein_floor, err)) ||
        (rc = map_key(doc, node, "veins", base_dir, vein_names, vein_sources, &so.veins, &veins_file, err)) ||
        (rc = map_key(doc, node, "stomata", base_dir, stomata_names, stomata_sources, &so.stomata, &stomata_file,
                      err)) ||
        (rc = map_key(doc, node, "inflow", base_dir, inflow_names, inflow_sources, &so.inflow, &inflow_file, err)))
        goto fail;
    /* ranges */
    {
        const struct {
            const char *key;
            int ok;
            const char *what;
        } checks[] = {{"grid", grid >= 2 && grid <= 512, "an integer from 2 to 512"},
                      {"quantiles", nq >= 2 && nq <= 256, "an integer from 2 to 256"},
                      {"model_size", model_size >= 16 && model_size <= 4096, "an integer from 16 to 4096"},
                      {"sigma", sigma > 0, "> 0"},
                      {"dt", so.dt > 0, "> 0"},
                      {"vein_floor", so.vein_floor >= 0 && so.vein_floor <= 1, "between 0 and 1"}};
        for (size_t i = 0; i < sizeof checks / sizeof checks[0]; ++i)
            if (!checks[i].ok) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': must be %s", doc->path,
                                   phc_key_line(node, checks[i].key), checks[i].key, checks[i].what);
                goto fail;
            }
    }
    im->histogram = residual == 1;
    im->de2000 = difference == 1;
    im->nq = (size_t)nq;
    im->sigma = sigma;
    so.space = space ? PHC_COLOUR_LAB : PHC_COLOUR_RGB;
    so.model_size = (size_t)model_size;
    so.veins_file = veins_file;
    so.stomata_file = stomata_file;
    so.inflow_file = inflow_file;
    const phc_colour_correction_method cc_method = correction == 2   ? PHC_CC_COLORCHECKER
                                                   : correction == 1 ? PHC_CC_GRAY_WORLD
                                                                     : PHC_CC_NONE;

    /* stage: {column, direction} or a bare column name */
    const phc_yaml_node *sn = phc_yaml_get(node, "stage");
    if (!sn) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: missing key 'stage' ({column: NAME, direction: "
                           "increasing | decreasing})", doc->path, node->line, ctx);
        goto fail;
    }
    if (sn->kind == PHC_YAML_MAPPING) {
        if ((rc = phc_yaml_check_keys(doc, sn, stage_keys, "stage", err)) ||
            (rc = phc_yaml_map_string(doc, sn, "column", 1, "stage", &stage_col, err)) ||
            (rc = choose(doc, sn, "direction", direction_names, &direction, err)))
            goto fail;
    } else if ((rc = phc_yaml_string(doc, sn, "stage", &stage_col, err)))
        goto fail;
    im->direction = direction ? -1 : 1;
    if (!(im->stage_name = strdup(stage_col))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    /* image: a file for every row, or {column: NAME} */
    const phc_yaml_node *in = phc_yaml_get(node, "image");
    if (!in) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: missing key 'image' (a photo file, or {column: NAME})",
                           doc->path, node->line, ctx);
        goto fail;
    }
    if (in->kind == PHC_YAML_MAPPING) {
        static const char *const image_keys[] = {"column", NULL};
        if ((rc = phc_yaml_check_keys(doc, in, image_keys, "image", err)) ||
            (rc = phc_yaml_map_string(doc, in, "column", 1, "image", &image_col, err)))
            goto fail;
    } else if ((rc = phc_yaml_string(doc, in, "image", &image_name, err)))
        goto fail;

    /* the rows */
    if (!(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = phc_table_read(path, &t, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto fail;
    }
    const size_t nr = phc_table_rows(t);
    if (nr < 2) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:1: %zu data row%s below the header: a leaf_photos data set needs a "
                           "fresh leaf and at least one more photo", path, nr, nr == 1 ? "" : "s");
        goto fail;
    }
    if ((rc = phc_need_column(doc, sn->kind == PHC_YAML_MAPPING ? sn : node, sn->kind == PHC_YAML_MAPPING ? "column" : "stage",
                              stage_col, t, err)) ||
        (leaf_col && (rc = phc_need_column(doc, node, "leaf", leaf_col, t, err))) ||
        (id_col && (rc = phc_need_column(doc, node, "id", id_col, t, err))) ||
        (image_col && (rc = phc_need_column(doc, in, "column", image_col, t, err))) ||
        (rc = phc_table_column_numbers(t, stage_col, &stage, err)) ||
        (leaf_col && (rc = phc_table_column_numbers(t, leaf_col, &leafno, err))))
        goto fail;
    if (!(im->rows = calloc(nr, sizeof *im->rows))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    im->n_rows = nr;
    const long idc = phc_table_find(t, id_col ? id_col : leaf_col ? leaf_col : "");
    for (size_t r = 0; r < nr; ++r) {
        lp_row *row = &im->rows[r];
        row->line = phc_table_row_line(t, r);
        row->stage = stage[r];
        char buf[32];
        snprintf(buf, sizeof buf, "%zu", row->line);
        if (!(row->id = strdup(idc >= 0 ? phc_table_cell(t, r, (size_t)idc) : buf))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t q = 0; q < r; ++q)
            if (!strcmp(im->rows[q].id, row->id)) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: id '%s' is used twice (also on line %zu)", path,
                                   row->line, row->id, im->rows[q].line);
                goto fail;
            }
        if (leafno && !(leafno[r] >= 1 && leafno[r] == floor(leafno[r]))) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': the leaf number must be a whole number >= 1, "
                               "found %g", path, row->line, leaf_col, leafno[r]);
            goto fail;
        }
    }
    /* the fresh leaf */
    const phc_yaml_node *ini = phc_yaml_get(node, "initial");
    if (ini) {
        const char *id;
        if ((rc = phc_yaml_string(doc, ini, "initial", &id, err)) ||
            (rc = find_row(doc, node, "initial", im, id, &im->initial, err)))
            goto fail;
    } else {
        im->initial = 0;
        for (size_t r = 1; r < nr; ++r)
            if (im->direction * (stage[r] - stage[im->initial]) < 0)
                im->initial = r;
    }
    im->rows[im->initial].role = 1;
    /* the reference: a row id or {image, leaf} */
    const phc_yaml_node *rf = phc_yaml_get(node, "reference");
    if (!rf) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: missing key 'reference' (the id of the senescent leaf's "
                           "row, or {image: FILE, leaf: N})", doc->path, node->line, ctx);
        goto fail;
    }
    im->reference = nr;
    if (rf->kind == PHC_YAML_MAPPING) {
        const char *rimg;
        long rleaf = 1;
        if ((rc = phc_yaml_check_keys(doc, rf, ref_keys, "reference", err)) ||
            (rc = phc_yaml_map_string(doc, rf, "image", 1, "reference", &rimg, err)) ||
            (rc = phc_yaml_map_integer(doc, rf, "leaf", 0, "reference", &rleaf, err)))
            goto fail;
        if (rleaf < 1) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: reference: leaf must be >= 1", doc->path, rf->line);
            goto fail;
        }
        if (!(img_path = phc_join_path(base_dir, rimg))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        /* the file's errors at `image:`, a leaf number beyond its leaves at `leaf:` */
        snprintf(where, sizeof where, "%s:%zu: reference: key 'image'", doc->path, phc_key_line(rf, "image"));
        if ((rc = phc_photo_cache_read(im->cache, img_path, cc_method, where, err)))
            goto fail;
        if (phc_yaml_get(rf, "leaf"))
            snprintf(where, sizeof where, "%s:%zu: reference: key 'leaf'", doc->path, phc_key_line(rf, "leaf"));
        if ((rc = phc_leaf_photo_load(im->cache, img_path, (size_t)rleaf, cc_method, where, &im->ref_photo, err)))
            goto fail;
        free(img_path);
        img_path = NULL;
    } else {
        const char *id;
        if ((rc = phc_yaml_string(doc, rf, "reference", &id, err)) ||
            (rc = find_row(doc, node, "reference", im, id, &im->reference, err)))
            goto fail;
        if (im->reference == im->initial) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'reference': row '%s' is also the fresh leaf (initial)",
                               doc->path, phc_key_line(node, "reference"), id);
            goto fail;
        }
        im->rows[im->reference].role = 2;
    }
    /* every row's photo */
    for (size_t r = 0; r < nr; ++r) {
        lp_row *row = &im->rows[r];
        const char *name = image_col ? phc_table_cell(t, r, (size_t)phc_table_find(t, image_col)) : image_name;
        if (!name || !*name) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': no image file given", path, row->line,
                               image_col);
            goto fail;
        }
        free(img_path);
        if (!(img_path = phc_join_path(base_dir, name))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        /* The photo's own errors where its name was given: the row's image
         * column, or the config's `image:`; a leaf number beyond its leaves
         * at the row's leaf column. */
        if (image_col)
            snprintf(where, sizeof where, "%s:%zu: column '%s'", path, row->line, image_col);
        else
            snprintf(where, sizeof where, "%s:%zu: key 'image'", doc->path, phc_key_line(node, "image"));
        if ((rc = phc_photo_cache_read(im->cache, img_path, cc_method, where, err)))
            goto fail;
        if (leafno)
            snprintf(where, sizeof where, "%s:%zu: column '%s'", path, row->line, leaf_col);
        if ((rc = phc_leaf_photo_load(im->cache, img_path, leafno ? (size_t)leafno[r] : 1, cc_method, where,
                                      &row->photo, err)))
            goto fail;
    }
    /* stages: every data row after the fresh leaf; a series in order */
    const double s0 = im->rows[im->initial].stage;
    for (size_t r = 0; r < nr; ++r) {
        lp_row *row = &im->rows[r];
        row->dstage = im->direction * (row->stage - s0);
        if (row->role == 0 && row->dstage < 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': stage %g comes before the fresh leaf's (%g, "
                               "row '%s'; direction %s)", path, row->line, stage_col, row->stage, s0,
                               im->rows[im->initial].id, im->direction > 0 ? "increasing" : "decreasing");
            goto fail;
        }
        if (!im->histogram && r > 0 && im->direction * (row->stage - im->rows[r - 1].stage) < 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': stages out of order (%g after %g): the photos "
                               "of one leaf must be listed in time order", path, row->line, stage_col, row->stage,
                               im->rows[r - 1].stage);
            goto fail;
        }
    }
    /* the model; errors about a map file at its key, the others at the data set */
    char map_where[3][256];
    snprintf(map_where[0], sizeof map_where[0], "%s:%zu: key 'veins'", doc->path, phc_key_line(node, "veins"));
    snprintf(map_where[1], sizeof map_where[1], "%s:%zu: key 'stomata'", doc->path, phc_key_line(node, "stomata"));
    snprintf(map_where[2], sizeof map_where[2], "%s:%zu: key 'inflow'", doc->path, phc_key_line(node, "inflow"));
    so.veins_where = map_where[0];
    so.stomata_where = map_where[1];
    so.inflow_where = map_where[2];
    if ((rc = phc_leaf_setup_new(&im->rows[im->initial].photo,
                                 im->reference < nr ? &im->rows[im->reference].photo : &im->ref_photo, &so, &im->su,
                                 err))) {
        if (strncmp(err->message, doc->path, strlen(doc->path)) != 0) /* not placed yet */
            phc_error_prefix(err, rc, "%s:%zu", doc->path, node->line);
        goto fail;
    }
    const phc_leaf_setup *su = im->su;
    im->cell = ((su->w > su->h ? su->w : su->h) + (size_t)grid - 1) / (size_t)grid;
    im->cw = (su->w + im->cell - 1) / im->cell;
    im->ch = (su->h + im->cell - 1) / im->cell;
    const size_t np = su->w * su->h;
    im->lab = malloc(3 * np * sizeof *im->lab);
    im->scratch = malloc(2 * 3 * np * sizeof *im->scratch);
    if (!im->lab || !im->scratch) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    size_t n = 0, m_data = 0;
    for (size_t r = 0; r < nr; ++r) {
        lp_row *row = &im->rows[r];
        if (row->role) {
            /* the greenness baseline uses the fresh and reference leaves too */
            phc_image g = {0};
            unsigned char *gm = NULL;
            if ((rc = phc_leaf_photo_grid(&row->photo, so.model_size, &g, &gm, err)))
                goto fail;
            row->greenness = mean_greenness(&g, gm);
            row->grid = g;
            free(gm);
            continue;
        }
        if ((rc = row_observations(im, row, do_register, err))) {
            snprintf(where, sizeof where, "%s:%zu: row '%s'", path, row->line, row->id);
            phc_error_prefix(err, rc, "%s", where);
            goto fail;
        }
        if (!row->count) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: row '%s': no grid cell is leaf in both this photo and the "
                               "fresh leaf (registration failed, or a different leaf: use residual: histogram)", path,
                               row->line, row->id);
            goto fail;
        }
        row->first = n;
        n += row->count;
        ++m_data;
    }
    if (!m_data) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: no row of %s is left to fit besides the fresh leaf "
                           "(initial) and the reference", doc->path, node->line, ctx, path);
        goto fail;
    }
    /* distinct model times over the data rows */
    data_rows = malloc(m_data * sizeof *data_rows);
    dst = malloc(m_data * sizeof *dst);
    im->t_at = calloc(nr, sizeof *im->t_at);
    if (!data_rows || !dst || !im->t_at) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t r = 0, k = 0; r < nr; ++r)
        if (!im->rows[r].role) {
            data_rows[k] = r;
            dst[k++] = im->rows[r].dstage;
        }
    size_t *at = NULL;
    if ((rc = phc_unique_times(dst, m_data, &im->t_unique, &im->m_unique, &at, err)))
        goto fail;
    for (size_t k = 0; k < m_data; ++k)
        im->t_at[data_rows[k]] = at[k];
    free(at);
    im->left_out = nr;

    /* slots */
    size_t k_slots = 0;
    for (int q = 0; q < N_SLOTS; ++q)
        im->slot[q] = is_parameter(slot_names[q], user_data) ? (int)k_slots++ : -1;
    if (!k_slots) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: no parameter to fit: name at least one of beta_scale, "
                           "stomata_scale, inflow_scale, time_scale, y_lo, y_hi under parameters", doc->path,
                           node->line, ctx);
        goto fail;
    }
    if (!(ds = phc_dataset_new(&leaf_photos_ops, k_slots))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (int q = 0; q < N_SLOTS; ++q)
        if (im->slot[q] >= 0 && !(ds->slot_names[im->slot[q]] = strdup(slot_names[q]))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
    ds->n = n;
    ds->x = malloc(n * sizeof *ds->x);
    ds->y = malloc(n * sizeof *ds->y);
    ds->sigma = malloc(n * sizeof *ds->sigma);
    ds->data_lines = malloc(n * sizeof *ds->data_lines);
    ds->data_file = strdup(path);
    im->row_of = malloc(n * sizeof *im->row_of);
    if (im->histogram)
        ds->series = malloc(n * sizeof *ds->series);
    if (!ds->x || !ds->y || !ds->sigma || !ds->data_lines || !ds->data_file || !im->row_of ||
        (im->histogram && !ds->series)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    /* every file read: the table, the photos, the reference photo, map files */
    rc = phc_dataset_add_input(ds, path);
    for (size_t r = 0; r < nr && !rc; ++r)
        rc = phc_dataset_add_input(ds, im->rows[r].photo.path);
    if (!rc && im->reference == nr)
        rc = phc_dataset_add_input(ds, im->ref_photo.path);
    const char *const map_files[] = {veins_file, stomata_file, inflow_file};
    for (size_t q = 0; q < 3 && !rc; ++q)
        if (map_files[q])
            rc = phc_dataset_add_input(ds, map_files[q]);
    if (rc) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t r = 0; r < nr; ++r) {
        const lp_row *row = &im->rows[r];
        if (row->role)
            continue;
        for (size_t i = 0; i < row->count; ++i) {
            const size_t j = row->first + i;
            ds->x[j] = row->stage;
            ds->y[j] = im->de2000 ? 0 : row->obs[i];
            ds->sigma[j] = sigma;
            ds->data_lines[j] = row->line;
            im->row_of[j] = r;
            if (ds->series)
                ds->series[j] = i;
        }
    }
    char xl[160];
    snprintf(xl, sizeof xl, "%s", stage_col);
    ds->x_label = strdup(x_label ? x_label : xl);
    ds->y_label = strdup(y_label ? y_label
                         : im->histogram ? "CIELAB quantile (L*, a*, b*)"
                         : im->de2000    ? "CIEDE2000 to the photo"
                                         : "CIELAB cell mean (L*, a*, b*)");
    if (!ds->x_label || !ds->y_label) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->derivatives = PHC_DERIV_CENTRAL;
    ds->config_line = node->line;
    ds->impl = im;
    im = NULL;
    phc_table_free(t);
    free(stage);
    free(leafno);
    free(dst);
    free(data_rows);
    free(path);
    free(img_path);
    free(veins_file);
    free(stomata_file);
    free(inflow_file);
    *out = ds;
    return PHC_OK;
fail:
    phc_table_free(t);
    free(stage);
    free(leafno);
    free(dst);
    free(data_rows);
    free(path);
    free(img_path);
    free(veins_file);
    free(stomata_file);
    free(inflow_file);
    lp_free(im);
    if (ds)
        ds->impl = NULL;
    phc_dataset_free(ds);
    return rc;
}
