/* Water in a plant graph (wilting paper §3-4): see water.h.
 * Pure C: no I/O, no printing, no globals.
 *
 * Internally segments are renumbered breadth-first (g->order), so that the
 * parent of position k is at a position < k: the tree elimination of BDF6
 * then runs over contiguous arrays, leaves first (k = n-1 .. 1) and back
 * (k = 1 .. n-1), without fill-in. */
#include "model/water.h"
#include "model/tree_eigen.h"
#include "model/water_internal.h"

#include <cblas.h>
#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

phc_water_params phc_water_params_default(void)
{
    phc_water_params p;
    memset(&p, 0, sizeof p);
    p.weights = PHC_WATER_POISEUILLE;
    p.loss_rate = 0.0;
    p.initial_water = 1.0;
    p.viscosity = 0.0;
    return p;
}

void phc_water_system_free(phc_water_system *s)
{
    if (!s)
        return;
    free(s->perm);
    free(s->par);
    free(s->w);
    free(s->wsum);
    free(s->d);
    free(s->vol);
    free(s->area);
    free(s->ell);
    free(s->theta0);
    free(s);
}

static void system_refresh(phc_water_system *s)
{
    double vsum = 0.0;
    for (size_t k = 0; k < s->n; ++k) {
        s->ell[k] = s->delta * s->area[k];
        vsum += s->vol[k];
    }
    for (size_t k = 0; k < s->n; ++k)
        s->theta0[k] = s->w0 * s->vol[k] / vsum;
}

int phc_water_system_new(const phc_plant_graph *g, const phc_water_params *p,
                         phc_water_system **out, phc_error *err)
{
    phc_water_system *s = NULL;
    double *gi = NULL;
    size_t *pos = NULL;
    if (out)
        *out = NULL;
    if (!g || !p || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "water model: NULL argument");
    if (g->n == 0 || !g->order || !g->parent)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "water model: the plant graph is empty or not finished");
    if ((int)p->weights < PHC_WATER_POISEUILLE || p->weights > PHC_WATER_REFERENCE_2024)
        return phc_error_set(err, PHC_ERR_INVALID, "water model: unknown weights mode %d",
                             (int)p->weights);
    if (!(p->loss_rate >= 0.0) || !isfinite(p->loss_rate))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water model: loss rate delta must be >= 0 and finite, found %g",
                             p->loss_rate);
    if (!(p->initial_water > 0.0) || !isfinite(p->initial_water))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water model: initial water must be > 0 g and finite, found %g",
                             p->initial_water);
    if (p->viscosity != 0.0 && (!(p->viscosity > 0.0) || !isfinite(p->viscosity)))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water model: viscosity must be > 0 mPa s, found %g", p->viscosity);
    int reference = p->weights == PHC_WATER_REFERENCE || p->weights == PHC_WATER_REFERENCE_2024;
    size_t n = g->n;
    if (p->edge_factor) {
        for (size_t i = 0; i < n; ++i) {
            if (g->parent[i] == PHC_PLANT_NO_PARENT)
                continue;
            double f = p->edge_factor[i];
            if (!(f >= 0.0 && f <= 1.0))
                return phc_error_set(err, PHC_ERR_DOMAIN,
                                     "water model: segment %ld: edge conductance factor must be "
                                     "in [0, 1] (0 = cut), found %g",
                                     g->source_id ? g->source_id[i] : (long)i, f);
        }
    }
    s = calloc(1, sizeof *s);
    if (!s)
        goto nomem;
    s->n = n;
    s->perm = malloc(n * sizeof *s->perm);
    s->par = calloc(n, sizeof *s->par);
    s->w = calloc(n, sizeof *s->w);
    s->wsum = calloc(n, sizeof *s->wsum);
    s->d = malloc(n * sizeof *s->d);
    s->vol = malloc(n * sizeof *s->vol);
    s->area = malloc(n * sizeof *s->area);
    s->ell = malloc(n * sizeof *s->ell);
    s->theta0 = malloc(n * sizeof *s->theta0);
    gi = malloc(n * sizeof *gi);
    pos = malloc(n * sizeof *pos);
    if (!s->perm || !s->par || !s->w || !s->wsum || !s->d || !s->vol || !s->area || !s->ell ||
        !s->theta0 || !gi || !pos)
        goto nomem;

    s->weights = p->weights;
    s->mu = p->viscosity != 0.0 ? p->viscosity : (reference ? 0.9 : 0.89);
    s->delta = p->loss_rate;
    s->w0 = p->initial_water;
    /* The weights are homogeneous in g of degree +1 (conductance forms) or
     * -1 (the resistance forms of the paper and the 2023 code); g ~ 1/mu. */
    s->mu_power = (p->weights == PHC_WATER_PAPER || p->weights == PHC_WATER_REFERENCE) ? 1.0 : -1.0;

    /* K: pressure per (g/cm^3), P = K theta / V.  Physical: R T / M_w in
     * Ba cm^3/g (J/g * 1e7 erg/J).  Reference: the authors' PRESS_CONST
     * 11.538 (T in Celsius), which multiplies: their S = PRESS_CONST * Adj *
     * diag(V)^-1 - diag(loss * Area), so d = V / PRESS_CONST. */
    double K = reference ? PHC_WATER_REFERENCE_PRESS_CONST
                         : PHC_WATER_GAS_CONSTANT * PHC_WATER_TEMPERATURE / PHC_WATER_MOLAR_MASS * 1e7;
    /* mu: physical modes in poise (1 mPa s = 1e-2 P) so that g is in
     * cm^3/(s Ba); reference: their 1e6 * pi r^4 / (8 * 0.9 * L). */
    double mu_unit = reference ? s->mu : s->mu * 1e-2;
    double g_scale = reference ? 1e6 : 1.0;

    for (size_t k = 0; k < n; ++k) {
        size_t i = g->order[k];
        s->perm[k] = i;
        pos[i] = k;
        double r = 100.0 * g->radius[i], h = 100.0 * g->length[i]; /* m -> cm */
        s->vol[k] = M_PI * r * r * h;
        int loses = g->leaf && g->leaf[i] && !(p->no_loss && p->no_loss[i]);
        s->area[k] = loses ? r * h : 0.0;
        s->d[k] = s->vol[k] / K; /* capacity: theta / pressure */
        gi[k] = g_scale * M_PI * r * r * r * r / (8.0 * mu_unit * h);
    }
    if (g->parent[s->perm[0]] != PHC_PLANT_NO_PARENT) {
        phc_error_set(err, PHC_ERR_INVALID, "water model: graph order does not start at the root");
        goto fail;
    }
    for (size_t k = 1; k < n; ++k) {
        size_t i = s->perm[k];
        size_t pk = pos[g->parent[i]];
        if (pk >= k) {
            phc_error_set(err, PHC_ERR_INVALID,
                          "water model: graph order is not parents-before-children");
            goto fail;
        }
        s->par[k] = pk;
        double a = gi[k], b = gi[pk], w;
        switch (p->weights) {
        case PHC_WATER_POISEUILLE: w = 2.0 * a * b / (a + b); break;     /* half pipes in series */
        case PHC_WATER_MEAN_CONDUCTANCE:
        case PHC_WATER_REFERENCE_2024: w = 0.5 * (a + b); break;
        default: w = 1.0 / (0.5 * (a + b)); break;                        /* paper, 2023 code */
        }
        if (p->edge_factor)
            w *= p->edge_factor[i];
        s->w[k] = w;
        s->wsum[k] += w;
        s->wsum[pk] += w;
    }
    system_refresh(s);
    free(gi);
    free(pos);
    *out = s;
    return PHC_OK;
nomem:
    phc_error_set(err, PHC_ERR_NOMEM, "water model: out of memory for %zu segments", g->n);
fail:
    free(gi);
    free(pos);
    phc_water_system_free(s);
    return err ? err->status : PHC_ERR_NOMEM;
}

int phc_water_system_set_loss_rate(phc_water_system *s, double delta, phc_error *err)
{
    if (!s)
        return phc_error_set(err, PHC_ERR_INVALID, "water model: NULL system");
    if (!(delta >= 0.0) || !isfinite(delta))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water model: loss rate delta must be >= 0 and finite, found %g", delta);
    s->delta = delta;
    system_refresh(s);
    return PHC_OK;
}

int phc_water_system_set_initial_water(phc_water_system *s, double w0, phc_error *err)
{
    if (!s)
        return phc_error_set(err, PHC_ERR_INVALID, "water model: NULL system");
    if (!(w0 > 0.0) || !isfinite(w0))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water model: initial water must be > 0 g and finite, found %g", w0);
    s->w0 = w0;
    system_refresh(s);
    return PHC_OK;
}

size_t phc_water_system_size(const phc_water_system *s) { return s ? s->n : 0; }
double phc_water_system_loss_rate(const phc_water_system *s) { return s->delta; }
double phc_water_system_initial_water(const phc_water_system *s) { return s->w0; }
double phc_water_system_viscosity(const phc_water_system *s) { return s->mu; }

void phc_water_system_volume(const phc_water_system *s, double *v)
{
    for (size_t k = 0; k < s->n; ++k)
        v[s->perm[k]] = s->vol[k];
}

void phc_water_system_theta0(const phc_water_system *s, double *theta0)
{
    for (size_t k = 0; k < s->n; ++k)
        theta0[s->perm[k]] = s->theta0[k];
}

/* Gershgorin bound on the spectral radius of A (= that of S). */
double phc_water_system_stiffness(const phc_water_system *s)
{
    size_t n = s->n;
    double *row = calloc(n, sizeof *row), rho = 0.0;
    if (!row)
        return INFINITY;
    for (size_t k = 1; k < n; ++k) {
        double o = s->w[k] / sqrt(s->d[k] * s->d[s->par[k]]);
        row[k] += o;
        row[s->par[k]] += o;
    }
    for (size_t k = 0; k < n; ++k) {
        double r = s->wsum[k] / s->d[k] + s->ell[k] + row[k];
        if (r > rho)
            rho = r;
    }
    free(row);
    return rho;
}

/* out = R D^-1 x (the diffusion part of S x), O(n). */
static void diffusion_apply(const phc_water_system *s, const double *x, double *out)
{
    size_t n = s->n;
    for (size_t k = 0; k < n; ++k)
        out[k] = 0.0;
    for (size_t k = 1; k < n; ++k) {
        size_t pk = s->par[k];
        double f = s->w[k] * (x[pk] / s->d[pk] - x[k] / s->d[k]);
        out[k] += f;
        out[pk] -= f;
    }
}

/* ------------------------------------------------------------------------ */
/* Exact evaluator                                                           */

/* The symmetric A = D^-1/2 R D^-1/2 - D_l (1/s; similar to S, eq. 5) as a
 * tree (model/tree_eigen.h): diag (n), off (n; off[k] = A(k, par[k]),
 * off[0] unused). */
static void symmetric_tree(const phc_water_system *s, double *diag, double *off)
{
    off[0] = 0.0;
    for (size_t k = 0; k < s->n; ++k)
        diag[k] = -s->wsum[k] / s->d[k] - s->ell[k];
    for (size_t k = 1; k < s->n; ++k)
        off[k] = s->w[k] / sqrt(s->d[k] * s->d[s->par[k]]);
}

/* Refinement of the eigenvalues (and of the slow eigenvectors) of A.  A
 * backward-stable eigensolver gives every eigenvalue to about eps |A|
 * absolute; the water model is stiff (|A| = 2.2e8 1/s on plant000 in the
 * reference mode) while W(t) at long times depends on its slowest modes
 * (|lambda| ~ 1e-5 1/s), which would then be known to a few digits only.
 * But -A = F^T F with F = [W^1/2 B D^-1/2; D_l^1/2] (B the tree's edge
 * incidence, row of edge (k, par k) = e_k - e_par; W the edge weights):
 * q^T (-A) q = |F q|^2 is a sum of positive terms, with no cancellation of
 * the large diagonal against the off-diagonal.  So
 *  1. every eigenvalue becomes the Rayleigh quotient -|F q_i|^2 of its
 *     vector (error of order |A| times the square of the vector's error);
 *  2. the K slowest modes (|lambda| <= sqrt(eps) |A|), whose vectors mix
 *     with each other (gaps below eps |A| / sqrt(eps)), are replaced by the
 *     Ritz pairs of their span: H = (F V)^T (F V) (K x K, LAPACK dsyevd),
 *     vectors V Y.  A larger K would bring faster modes into H and, with
 *     them, absolute errors eps |H| back onto the slow ones.
 * On plant000 (reference mode) W(1e4 s) moves from 1e-6 to 3e-12 of the
 * contour-integral value.  lambda ascending on entry (the slow modes are
 * the last K columns of Q); the refined values may reorder eigenvalues
 * closer than eps |A|.  Returns PHC_OK, PHC_ERR_NOMEM or PHC_ERR_NUMERIC. */
static int refine_modes(const phc_water_system *s, const double *sqd, double *lambda, double *Q,
                        phc_error *err)
{
    size_t n = s->n;
    if (n < 2)
        return PHC_OK;
    double cutoff = sqrt(DBL_EPSILON) * fmax(fabs(lambda[0]), fabs(lambda[n - 1]));
    size_t K = 0;
    while (K < n && fabs(lambda[n - 1 - K]) <= cutoff)
        ++K;
    double *p = malloc(2 * n * sizeof *p), *isqd = p + n; /* p = D^-1/2 q: pressures */
    if (!p)
        return phc_error_set(err, PHC_ERR_NOMEM, "water exact: out of memory");
    for (size_t k = 0; k < n; ++k)
        isqd[k] = 1.0 / sqd[k];
    for (size_t i = 0; i + K < n; ++i) {
        const double *q = Q + i * n;
        double fq = 0.0;
        for (size_t k = 0; k < n; ++k) {
            p[k] = q[k] * isqd[k];
            fq += s->ell[k] * q[k] * q[k];
        }
        for (size_t k = 1; k < n; ++k) {
            double g = p[k] - p[s->par[k]];
            fq += s->w[k] * g * g;
        }
        lambda[i] = -fq;
    }
    free(p);
    if (K == 0)
        return PHC_OK;
    size_t rows = n - 1;
    for (size_t k = 0; k < n; ++k)
        rows += s->ell[k] > 0.0;
    double *F = malloc(rows * K * sizeof *F), *H = malloc(K * K * sizeof *H);
    double *mu = malloc(K * sizeof *mu), *G = malloc(n * K * sizeof *G);
    if (!F || !H || !mu || !G) {
        free(F);
        free(H);
        free(mu);
        free(G);
        return phc_error_set(err, PHC_ERR_NOMEM, "water exact: out of memory for %zu slow modes", K);
    }
    const double *V = Q + (n - K) * n; /* the last K columns */
    for (size_t c = 0; c < K; ++c) {
        const double *v = V + c * n;
        double *f = F + c * rows;
        size_t r = 0;
        for (size_t k = 1; k < n; ++k) {
            size_t pk = s->par[k];
            f[r++] = sqrt(s->w[k]) * (v[k] / sqd[k] - v[pk] / sqd[pk]);
        }
        for (size_t k = 0; k < n; ++k)
            if (s->ell[k] > 0.0)
                f[r++] = sqrt(s->ell[k]) * v[k];
    }
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)K, (int)K, (int)rows, 1.0, F,
                (int)rows, F, (int)rows, 0.0, H, (int)K);
    free(F);
    if (LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'L', (lapack_int)K, H, (lapack_int)K, mu) != 0) {
        free(H);
        free(mu);
        free(G);
        return phc_error_set(err, PHC_ERR_NUMERIC,
                             "water exact: dsyevd did not converge on the %zu slow modes", K);
    }
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)n, (int)K, (int)K, 1.0, V, (int)n,
                H, (int)K, 0.0, G, (int)n);
    /* mu ascending: lambda = -mu descending, so Ritz pair c goes last - c */
    for (size_t c = 0; c < K; ++c) {
        lambda[n - 1 - c] = -mu[c];
        memcpy(Q + (n - 1 - c) * n, G + c * n, n * sizeof *G);
    }
    free(H);
    free(mu);
    free(G);
    return PHC_OK;
}

struct phc_water_exact {
    size_t n;
    phc_water_exact_kind kind;
    double *lambda;  /* n, ascending (to within eps |A|: refine_modes) */
    double *ab;      /* n: a_i b_i (g) */
    double *a, *b;   /* n (full kinds) */
    double *Q;       /* n x n column major (full kinds) */
    double *M;       /* n x n: Q^T D_a Q (sensitivity kind) */
    double *sqd;     /* n: sqrt(d) */
    size_t *perm;
    double delta, w0, mu, mu_power;
};

void phc_water_exact_free(phc_water_exact *e)
{
    if (!e)
        return;
    free(e->lambda);
    free(e->ab);
    free(e->a);
    free(e->b);
    free(e->Q);
    free(e->M);
    free(e->sqd);
    free(e->perm);
    free(e);
}

int phc_water_exact_new(const phc_water_system *s, phc_water_exact_kind kind,
                        phc_water_exact **out, phc_error *err)
{
    phc_water_exact *e = NULL;
    double *Q = NULL, *diag = NULL, *off = NULL;
    if (out)
        *out = NULL;
    if (!s || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "water exact: NULL argument");
    size_t n = s->n;
    e = calloc(1, sizeof *e);
    if (!e)
        goto nomem;
    e->n = n;
    e->kind = kind;
    e->delta = s->delta;
    e->w0 = s->w0;
    e->mu = s->mu;
    e->mu_power = s->mu_power;
    e->lambda = malloc(n * sizeof *e->lambda);
    e->ab = malloc(n * sizeof *e->ab);
    e->sqd = malloc(n * sizeof *e->sqd);
    e->perm = malloc(n * sizeof *e->perm);
    e->a = malloc(n * sizeof *e->a);
    diag = malloc(n * sizeof *diag);
    off = malloc(n * sizeof *off);
    Q = malloc(n * n * sizeof *Q);
    if (!e->lambda || !e->ab || !e->sqd || !e->perm || !e->a || !diag || !off || !Q)
        goto nomem;
    memcpy(e->perm, s->perm, n * sizeof *e->perm);
    double sumd = 0.0;
    for (size_t k = 0; k < n; ++k) {
        e->sqd[k] = sqrt(s->d[k]);
        sumd += s->d[k];
    }

    /* A = Q Lambda Q^T by divide and conquer on the plant's tree. */
    symmetric_tree(s, diag, off);
    if (phc_tree_eigen(n, s->par, diag, off, e->lambda, Q, err) ||
        refine_modes(s, e->sqd, e->lambda, Q, err))
        goto fail;
    free(diag);
    free(off);
    diag = off = NULL;
    /* theta(t) = D^1/2 Q exp(Lambda t) Q^T D^-1/2 theta0 and W = 1^T theta:
     * a = Q^T D^1/2 1, b = Q^T D^-1/2 theta0, W(t) = sum_i a_i b_i
     * exp(lambda_i t).  theta0 is proportional to d (theta0 = W0 d / sum d),
     * so b = W0 a / sum d. */
    cblas_dgemv(CblasColMajor, CblasTrans, (int)n, (int)n, 1.0, Q, (int)n, e->sqd, 1, 0.0, e->a,
                1);
    if (kind == PHC_WATER_EXACT_TOTAL_ONLY) {
        for (size_t i = 0; i < n; ++i)
            e->ab[i] = e->w0 * e->a[i] * e->a[i] / sumd;
        free(e->a);
        e->a = NULL;
        free(Q);
        *out = e;
        return PHC_OK;
    }
    e->Q = Q;
    Q = NULL;
    e->b = malloc(n * sizeof *e->b);
    if (!e->b)
        goto nomem;
    {
        double *x = malloc(n * sizeof *x);
        if (!x)
            goto nomem;
        for (size_t k = 0; k < n; ++k)
            x[k] = s->theta0[k] / e->sqd[k];
        cblas_dgemv(CblasColMajor, CblasTrans, (int)n, (int)n, 1.0, e->Q, (int)n, x, 1, 0.0, e->b, 1);
        free(x);
    }
    for (size_t i = 0; i < n; ++i)
        e->ab[i] = e->a[i] * e->b[i];
    if (kind == PHC_WATER_EXACT_SENSITIVITY) {
        /* M = Q^T D_a Q = T^T T with T = D_a^1/2 Q: only the rows of the
         * segments that lose water (leaves), so n^2 per such segment. */
        size_t nl = 0;
        for (size_t k = 0; k < n; ++k)
            nl += s->area[k] > 0.0;
        double *T = malloc((nl ? nl : 1) * n * sizeof *T);
        e->M = malloc(n * n * sizeof *e->M);
        if (!T || !e->M) {
            free(T);
            goto nomem;
        }
        for (size_t j = 0; j < n; ++j) {
            size_t r = 0;
            for (size_t k = 0; k < n; ++k)
                if (s->area[k] > 0.0)
                    T[j * nl + r++] = sqrt(s->area[k]) * e->Q[j * n + k];
        }
        if (nl == 0)
            memset(e->M, 0, n * n * sizeof *e->M);
        else
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)n, (int)n, (int)nl, 1.0, T,
                        (int)nl, T, (int)nl, 0.0, e->M, (int)n);
        free(T);
    }
    *out = e;
    return PHC_OK;
nomem:
    phc_error_set(err, PHC_ERR_NOMEM, "water exact: out of memory for %zu segments", s->n);
fail:
    free(Q);
    free(diag);
    free(off);
    phc_water_exact_free(e);
    return err ? err->status : PHC_ERR_NOMEM;
}

double phc_water_exact_total(const phc_water_exact *e, double t)
{
    double W = 0.0;
    for (size_t i = 0; i < e->n; ++i)
        W += e->ab[i] * exp(e->lambda[i] * t);
    return W;
}

int phc_water_exact_state(const phc_water_exact *e, double t, double *theta, phc_error *err)
{
    if (!e || !theta)
        return phc_error_set(err, PHC_ERR_INVALID, "water exact: NULL argument");
    if (!e->Q)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "water exact: state needs a FULL or SENSITIVITY evaluator");
    size_t n = e->n;
    double *c = calloc(2 * n, sizeof *c); /* zeroed: cblas reads c + n with beta = 0 */
    if (!c)
        return phc_error_set(err, PHC_ERR_NOMEM, "water exact: out of memory");
    for (size_t i = 0; i < n; ++i)
        c[i] = e->b[i] * exp(e->lambda[i] * t);
    cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)n, 1.0, e->Q, (int)n, c, 1, 0.0, c + n, 1);
    for (size_t k = 0; k < n; ++k)
        theta[e->perm[k]] = e->sqd[k] * c[n + k];
    free(c);
    return PHC_OK;
}

int phc_water_exact_sensitivity(const phc_water_exact *e, double t, double *dW,
                                double *dtheta_ddelta, phc_error *err)
{
    if (!e || !dW)
        return phc_error_set(err, PHC_ERR_INVALID, "water exact: NULL argument");
    if (!e->M)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "water exact: sensitivities need a SENSITIVITY evaluator");
    size_t n = e->n;
    double *E = malloc(2 * n * sizeof *E);
    if (!E)
        return phc_error_set(err, PHC_ERR_NOMEM, "water exact: out of memory");
    double *y = E + n;
    for (size_t i = 0; i < n; ++i)
        E[i] = exp(e->lambda[i] * t);
    /* y_i = sum_j Phi_ij M_ij b_j; dW/d delta = -a^T y (dA/d delta = -D_a) */
    double dWd = 0.0, lamterm = 0.0, W = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double acc = 0.0;
        const double *Mi = e->M + i * n; /* column i = row i (symmetric) */
        for (size_t j = 0; j < n; ++j)
            acc += phc_water_expm_divided_difference(e->lambda[i], e->lambda[j], E[i], E[j], t) * Mi[j] * e->b[j];
        y[i] = acc;
        dWd -= e->a[i] * acc;
        lamterm += e->ab[i] * t * e->lambda[i] * E[i];
        W += e->ab[i] * E[i];
    }
    dW[0] = dWd;
    dW[1] = W / e->w0;
    /* dA/d mu = (p/mu) (A + D_l); Q^T (A + D_l) Q = Lambda + delta M */
    dW[2] = e->mu_power / e->mu * (lamterm - e->delta * dWd);
    if (dtheta_ddelta) {
        double *z = malloc(n * sizeof *z);
        if (!z) {
            free(E);
            return phc_error_set(err, PHC_ERR_NOMEM, "water exact: out of memory");
        }
        cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)n, -1.0, e->Q, (int)n, y, 1, 0.0, z, 1);
        for (size_t k = 0; k < n; ++k)
            dtheta_ddelta[e->perm[k]] = e->sqd[k] * z[k];
        free(z);
    }
    free(E);
    return PHC_OK;
}

/* ------------------------------------------------------------------------ */
/* BDF6                                                                      */

struct phc_water_bdf6 {
    const phc_water_system *s;
    size_t n;
    double h;
    int sens;
    /* factorisation of I - c S over the tree */
    double c;
    double *l, *u, *ipiv;
    /* ring of the last 6 states (theta, and s_delta, s_mu with sensitivities) */
    double *ring;       /* 6 * nv * n */
    size_t nv;          /* 1, 2 (theta, s_delta) or 3 (theta, s_delta, s_mu) */
    double *rhs, *tmp;  /* nv * n, n */
    double *acc;        /* n, zero between steps: children's terms in the fused step */
    size_t steps;       /* current state is at t = steps * h */
    double *Wh;         /* (steps+1) * nv: sums of the components */
    size_t Wcap;
};

/* I - c S factorised over the tree (model/water_tree.c). */
static void tree_factor(phc_water_bdf6 *b, double c)
{
    const phc_water_system *s = b->s;
    phc_water_tree_factor(b->n, s->par, s->w, s->d, s->ell, c, b->l, b->u, b->ipiv);
    b->c = c;
}

/* y <- M^-1 y. */
static void tree_solve(const phc_water_bdf6 *b, double *restrict y)
{
    phc_water_tree_solve(b->n, b->s->par, b->l, b->u, b->ipiv, y);
}

/* Implicit step for the augmented system: x[0] = theta (rhs given), then
 * the sensitivities (rhs_s + c dS/dp theta_new).  x holds rhs on entry. */
static void augmented_solve(phc_water_bdf6 *b, double *x)
{
    size_t n = b->n;
    tree_solve(b, x);
    if (b->sens) {
        const phc_water_system *s = b->s;
        double c = b->c;
        double *sd = x + n;
        for (size_t k = 0; k < n; ++k)
            sd[k] -= c * s->area[k] * x[k];        /* dS/d delta = -D_a */
        tree_solve(b, sd);
        if (b->nv == 3) {
            double *sm = x + 2 * n;
            diffusion_apply(s, x, b->tmp);         /* dS/d mu = (p/mu) R D^-1 */
            double f = c * s->mu_power / s->mu;
            for (size_t k = 0; k < n; ++k)
                sm[k] += f * b->tmp[k];
            tree_solve(b, sm);
        }
    }
}

/* Stores the sums of the nv components of the state at step b->steps. */
static int record_sums(phc_water_bdf6 *b, const double *sums)
{
    size_t idx = b->steps;
    if ((idx + 1) * b->nv > b->Wcap) {
        size_t cap = b->Wcap ? 2 * b->Wcap : 64 * b->nv;
        while (cap < (idx + 1) * b->nv)
            cap *= 2;
        double *p = realloc(b->Wh, cap * sizeof *p);
        if (!p)
            return PHC_ERR_NOMEM;
        b->Wh = p;
        b->Wcap = cap;
    }
    for (size_t v = 0; v < b->nv; ++v)
        b->Wh[idx * b->nv + v] = sums[v];
    return PHC_OK;
}

static int record_total(phc_water_bdf6 *b, const double *x)
{
    double sums[3];
    for (size_t v = 0; v < b->nv; ++v) {
        double sum = 0.0;
        const double *xv = x + v * b->n;
        for (size_t k = 0; k < b->n; ++k)
            sum += xv[k];
        sums[v] = sum;
    }
    return record_sums(b, sums);
}

void phc_water_bdf6_free(phc_water_bdf6 *b)
{
    if (!b)
        return;
    free(b->l);
    free(b->u);
    free(b->ipiv);
    free(b->ring);
    free(b->rhs);
    free(b->tmp);
    free(b->acc);
    free(b->Wh);
    free(b);
}

#define START_ORDERS PHC_WATER_START_ORDERS
#define START_SUBINTERVALS 2
#define BDF6_ALPHA PHC_WATER_BDF6_ALPHA
#define bdf6_beta phc_water_bdf6_beta

static void factor_cb(void *b, double c) { tree_factor(b, c); }
static void step_cb(void *b, double *y) { augmented_solve(b, y); }

/* One interval of length H from x (nv*n): model/water_tree.c. */
static void extrapolated_euler(phc_water_bdf6 *b, double H, double *x, double *T, double *y)
{
    phc_water_extrapolated_euler(b->nv * b->n, H, x, T, y, factor_cb, step_cb, b);
}

int phc_water_bdf6_new(const phc_water_system *s, double h, int sensitivities,
                       phc_water_bdf6 **out, phc_error *err)
{
    phc_water_bdf6 *b = NULL;
    double *T = NULL, *y = NULL;
    if (out)
        *out = NULL;
    if (!s || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "water BDF6: NULL argument");
    if (!(h > 0.0) || !isfinite(h))
        return phc_error_set(err, PHC_ERR_DOMAIN, "water BDF6: step must be > 0 s, found %g", h);
    size_t n = s->n;
    b = calloc(1, sizeof *b);
    if (!b)
        goto nomem;
    b->s = s;
    b->n = n;
    b->h = h;
    if (sensitivities != PHC_WATER_SENS_NONE && sensitivities != PHC_WATER_SENS_ALL &&
        sensitivities != PHC_WATER_SENS_DELTA) {
        free(b);
        return phc_error_set(err, PHC_ERR_INVALID,
                             "water BDF6: sensitivities must be 0 (none), 1 (delta and mu) or 2 "
                             "(delta only), found %d", sensitivities);
    }
    b->sens = sensitivities ? 1 : 0;
    b->nv = sensitivities == PHC_WATER_SENS_ALL ? 3 : sensitivities == PHC_WATER_SENS_DELTA ? 2 : 1;
    size_t len = b->nv * n;
    b->l = calloc(n, sizeof *b->l);
    b->u = calloc(n, sizeof *b->u);
    b->ipiv = calloc(n, sizeof *b->ipiv);
    b->ring = calloc(6 * len, sizeof *b->ring);
    b->rhs = calloc(len, sizeof *b->rhs);
    b->tmp = calloc(n, sizeof *b->tmp);
    b->acc = calloc(n, sizeof *b->acc);
    T = malloc((size_t)START_ORDERS * len * sizeof *T);
    y = malloc(len * sizeof *y);
    if (!b->l || !b->u || !b->ipiv || !b->ring || !b->rhs || !b->tmp || !b->acc || !T || !y)
        goto nomem;
    /* state 0: theta0, sensitivities 0 (theta0 does not depend on delta, mu) */
    memcpy(b->ring, s->theta0, n * sizeof(double));
    if (record_total(b, b->ring))
        goto nomem;
    double *x = b->rhs;
    memcpy(x, b->ring, len * sizeof *x);
    for (int q = 1; q <= 5; ++q) {
        for (int r = 0; r < START_SUBINTERVALS; ++r)
            extrapolated_euler(b, h / START_SUBINTERVALS, x, T, y);
        memcpy(b->ring + (size_t)q * len, x, len * sizeof *x);
        b->steps = (size_t)q;
        if (record_total(b, x))
            goto nomem;
    }
    tree_factor(b, BDF6_ALPHA * h);
    free(T);
    free(y);
    *out = b;
    return PHC_OK;
nomem:
    free(T);
    free(y);
    phc_water_bdf6_free(b);
    return phc_error_set(err, PHC_ERR_NOMEM, "water BDF6: out of memory for %zu segments", n);
}

/* One BDF6 step (eq. 8): (I - alpha h S) x_{n+1} = sum_j beta_j x_{n-5+j}. */
static int bdf6_step(phc_water_bdf6 *b)
{
    size_t len = b->nv * b->n;
    size_t cur = b->steps; /* ring slot of x_m is m % 6 */
    const double *h0 = b->ring + ((cur + 1) % 6) * len; /* x_{n-5} */
    const double *h1 = b->ring + ((cur + 2) % 6) * len;
    const double *h2 = b->ring + ((cur + 3) % 6) * len;
    const double *h3 = b->ring + ((cur + 4) % 6) * len;
    const double *h4 = b->ring + ((cur + 5) % 6) * len;
    const double *h5 = b->ring + (cur % 6) * len;         /* x_n */
    double *out = b->ring + ((cur + 1) % 6) * len; /* overwrites x_{n-5} */
    const double b0 = bdf6_beta[0], b1 = bdf6_beta[1], b2 = bdf6_beta[2], b3 = bdf6_beta[3],
                 b4 = bdf6_beta[4], b5 = bdf6_beta[5];
    /* Fused: each right-hand side is formed as the elimination reaches
     * each position (leaves first; the children's terms wait in acc, which
     * is left zero), then back substitution and the sum: two passes over
     * memory per vector instead of about five.  The sensitivities' sources
     * (c dS/d delta theta_new = -c D_a theta_new, and c (p/mu) R D^-1
     * theta_new edge by edge) enter the same first pass. */
    double sums[3];
    size_t n = b->n;
    const double *hist[6] = {h0, h1, h2, h3, h4, h5};
    for (size_t v = 0; v < b->nv; ++v) {
        const size_t *restrict par = b->s->par;
        const double *restrict l = b->l, *restrict u = b->u, *restrict ip = b->ipiv;
        const double *restrict g0 = hist[0] + v * n, *restrict g1 = hist[1] + v * n,
                               *restrict g2 = hist[2] + v * n, *restrict g3 = hist[3] + v * n,
                               *restrict g4 = hist[4] + v * n, *restrict g5 = hist[5] + v * n;
        double *restrict acc = b->acc, *restrict x = out + v * n;
        const double *restrict th = out; /* theta_new, complete when v > 0 */
        const double *restrict wk = b->s->w, *restrict dk = b->s->d, *restrict ar = b->s->area;
        if (v == 0) {
            for (size_t k = n - 1; k >= 1; --k) {
                double r = (b0 * g0[k] + b1 * g1[k] + b2 * g2[k] + b3 * g3[k] + b4 * g4[k] +
                            b5 * g5[k]) + acc[k];
                acc[k] = 0.0;
                x[k] = r;
                acc[par[k]] -= l[k] * r;
            }
        } else if (v == 1) {
            const double c = b->c;
            for (size_t k = n - 1; k >= 1; --k) {
                double r = (b0 * g0[k] + b1 * g1[k] + b2 * g2[k] + b3 * g3[k] + b4 * g4[k] +
                            b5 * g5[k]) - c * ar[k] * th[k] + acc[k];
                acc[k] = 0.0;
                x[k] = r;
                acc[par[k]] -= l[k] * r;
            }
        } else {
            const double f = b->c * b->s->mu_power / b->s->mu;
            for (size_t k = n - 1; k >= 1; --k) {
                size_t pk = par[k];
                double fk = f * (wk[k] * (th[pk] / dk[pk] - th[k] / dk[k]));
                double r = (b0 * g0[k] + b1 * g1[k] + b2 * g2[k] + b3 * g3[k] + b4 * g4[k] +
                            b5 * g5[k]) + fk + acc[k];
                acc[k] = 0.0;
                x[k] = r;
                acc[pk] -= l[k] * r + fk;
            }
        }
        double r0 = (b0 * g0[0] + b1 * g1[0] + b2 * g2[0] + b3 * g3[0] + b4 * g4[0] + b5 * g5[0]) +
                    acc[0];
        if (v == 1)
            r0 -= b->c * ar[0] * th[0];
        x[0] = r0 * ip[0];
        acc[0] = 0.0;
        double sum = x[0];
        for (size_t k = 1; k < n; ++k) {
            double y = (x[k] - u[k] * x[par[k]]) * ip[k];
            x[k] = y;
            sum += y;
        }
        sums[v] = sum;
    }
    b->steps = cur + 1;
    return record_sums(b, sums);
}

int phc_water_bdf6_advance(phc_water_bdf6 *b, double t_end, phc_error *err)
{
    if (!b)
        return phc_error_set(err, PHC_ERR_INVALID, "water BDF6: NULL integrator");
    if (!isfinite(t_end))
        return phc_error_set(err, PHC_ERR_DOMAIN, "water BDF6: end time must be finite");
    if (b->c != BDF6_ALPHA * b->h)
        tree_factor(b, BDF6_ALPHA * b->h);
    while (b->steps < 6 || (double)b->steps * b->h < t_end) {
        if (bdf6_step(b))
            return phc_error_set(err, PHC_ERR_NOMEM, "water BDF6: out of memory for the history");
    }
    return PHC_OK;
}

size_t phc_water_bdf6_steps(const phc_water_bdf6 *b) { return b->steps; }
double phc_water_bdf6_time(const phc_water_bdf6 *b) { return (double)b->steps * b->h; }

int phc_water_bdf6_state_at(const phc_water_bdf6 *b, double t, double *theta, double *dtheta_ddelta,
                            phc_error *err)
{
    if (!b || !theta)
        return phc_error_set(err, PHC_ERR_INVALID, "water BDF6: NULL argument");
    if (dtheta_ddelta && !b->sens)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "water BDF6: derivatives need an integrator with sensitivities");
    /* the ring holds the states at steps - 5 .. steps (slot m % 6 for step m) */
    const size_t first = b->steps >= 5 ? b->steps - 5 : 0;
    const double lo = (double)first * b->h, hi = (double)b->steps * b->h;
    if (!(t >= lo * (1.0 - 1e-12)) || t > hi * (1.0 + 1e-12) || b->steps < 5)
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water BDF6: state at %g s asked outside the last five steps [%g, %g] s "
                             "(advance to it first)",
                             t, lo, hi);
    /* 6-point Lagrange interpolation (degree 5) in x = t / h */
    const double xs = t / b->h;
    double L[6];
    for (int i = 0; i < 6; ++i) {
        L[i] = 1.0;
        for (int j = 0; j < 6; ++j)
            if (j != i)
                L[i] *= (xs - (double)(first + (size_t)j)) / (double)(i - j);
    }
    const size_t len = b->nv * b->n;
    for (size_t k = 0; k < b->n; ++k) {
        double th = 0.0, sd = 0.0;
        for (int i = 0; i < 6; ++i) {
            const double *x = b->ring + ((first + (size_t)i) % 6) * len;
            th += L[i] * x[k];
            if (dtheta_ddelta)
                sd += L[i] * x[b->n + k];
        }
        theta[b->s->perm[k]] = th;
        if (dtheta_ddelta)
            dtheta_ddelta[b->s->perm[k]] = sd;
    }
    return PHC_OK;
}

void phc_water_bdf6_state(const phc_water_bdf6 *b, double *theta, double *dtheta_ddelta)
{
    size_t len = b->nv * b->n;
    const double *x = b->ring + (b->steps % 6) * len;
    for (size_t k = 0; k < b->n; ++k) {
        if (theta)
            theta[b->s->perm[k]] = x[k];
        if (dtheta_ddelta && b->sens)
            dtheta_ddelta[b->s->perm[k]] = x[b->n + k];
    }
}

int phc_water_bdf6_total(const phc_water_bdf6 *b, double t, double *W, double *dW, phc_error *err)
{
    if (!b || !W)
        return phc_error_set(err, PHC_ERR_INVALID, "water BDF6: NULL argument");
    double tend = (double)b->steps * b->h;
    if (!(t >= 0.0) || t > tend * (1.0 + 1e-12))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water BDF6: time %g s outside the integrated range [0, %g] s", t,
                             tend);
    if (dW && !b->sens)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "water BDF6: derivatives need an integrator with sensitivities");
    /* 7-point Lagrange interpolation (degree 6) on the nodes around t */
    double xs = t / b->h;
    long k0 = (long)floor(xs) - 3;
    if (k0 < 0)
        k0 = 0;
    if (k0 > (long)b->steps - 6)
        k0 = (long)b->steps - 6;
    double acc[3] = {0, 0, 0};
    for (int i = 0; i < 7; ++i) {
        double L = 1.0;
        for (int j = 0; j < 7; ++j)
            if (j != i)
                L *= (xs - (double)(k0 + j)) / (double)(i - j);
        for (size_t v = 0; v < b->nv; ++v)
            acc[v] += L * b->Wh[(size_t)(k0 + i) * b->nv + v];
    }
    *W = acc[0];
    if (dW) {
        dW[0] = acc[1];
        dW[1] = acc[0] / b->s->w0;
        dW[2] = b->nv == 3 ? acc[2] : NAN; /* d/d mu: PHC_WATER_SENS_ALL only */
    }
    return PHC_OK;
}

/* ------------------------------------------------------------------------ */

phc_water_method phc_water_system_curve_method(const phc_water_system *s, phc_water_method method,
                                               double step_or_0, double tmax, double *h)
{
    if (h)
        *h = step_or_0 > 0.0 ? step_or_0 : tmax / 1000.0;
    if (method == PHC_WATER_AUTO)
        method = (s->n <= PHC_WATER_AUTO_EXACT_MAX &&
                  phc_water_system_stiffness(s) * tmax <= 1e7)
                     ? PHC_WATER_EXACT
                     : PHC_WATER_BDF6;
    return method;
}

int phc_water_system_total_curve(const phc_water_system *s, phc_water_method method,
                                 double step_or_0, const double *t, size_t m, double *W,
                                 double *dW, phc_error *err)
{
    if (!s || !t || !W)
        return phc_error_set(err, PHC_ERR_INVALID, "water curve: NULL argument");
    if (m == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "water curve: empty time list");
    for (size_t i = 0; i < m; ++i) {
        if (!(t[i] >= 0.0) || !isfinite(t[i]))
            return phc_error_set(err, PHC_ERR_DOMAIN,
                                 "water curve: time %zu must be finite and >= 0 s, found %g", i, t[i]);
        if (i > 0 && t[i] < t[i - 1])
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "water curve: times must be sorted ascending: t[%zu] = %g < t[%zu] = %g",
                                 i, t[i], i - 1, t[i - 1]);
    }
    if (!(step_or_0 >= 0.0) || !isfinite(step_or_0))
        return phc_error_set(err, PHC_ERR_DOMAIN, "water curve: step must be >= 0 s, found %g",
                             step_or_0);
    double tmax = t[m - 1];
    if (tmax == 0.0) {
        for (size_t i = 0; i < m; ++i) {
            W[i] = s->w0;
            if (dW) {
                dW[3 * i] = 0.0;
                dW[3 * i + 1] = 1.0;
                dW[3 * i + 2] = 0.0;
            }
        }
        return PHC_OK;
    }
    double h = 0.0;
    method = phc_water_system_curve_method(s, method, step_or_0, tmax, &h);
    int rc;
    if (method == PHC_WATER_EXACT) {
        phc_water_exact *e = NULL;
        rc = phc_water_exact_new(s, dW ? PHC_WATER_EXACT_SENSITIVITY : PHC_WATER_EXACT_TOTAL_ONLY,
                                 &e, err);
        if (rc)
            return rc;
        for (size_t i = 0; i < m && !rc; ++i) {
            W[i] = phc_water_exact_total(e, t[i]);
            if (dW)
                rc = phc_water_exact_sensitivity(e, t[i], dW + 3 * i, NULL, err);
        }
        phc_water_exact_free(e);
        return rc;
    }
    if (method != PHC_WATER_BDF6)
        return phc_error_set(err, PHC_ERR_INVALID, "water curve: unknown method %d", (int)method);
    phc_water_bdf6 *b = NULL;
    rc = phc_water_bdf6_new(s, h, dW != NULL, &b, err);
    if (rc)
        return rc;
    rc = phc_water_bdf6_advance(b, tmax, err);
    for (size_t i = 0; i < m && !rc; ++i)
        rc = phc_water_bdf6_total(b, t[i], W + i, dW ? dW + 3 * i : NULL, err);
    phc_water_bdf6_free(b);
    return rc;
}

int phc_water_total_curve(const phc_plant_graph *g, const phc_water_params *p,
                          phc_water_method method, double step_or_0, const double *t, size_t m,
                          double *W, double *dW, phc_error *err)
{
    phc_water_system *s = NULL;
    int rc = phc_water_system_new(g, p, &s, err);
    if (rc)
        return rc;
    rc = phc_water_system_total_curve(s, method, step_or_0, t, m, W, dW, err);
    phc_water_system_free(s);
    return rc;
}
