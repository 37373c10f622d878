/* A plant on a balance: time-varying loss and a pot (see water_balance.h).
 * Pure C: no I/O, no globals. */
#include "model/water_balance.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/water_internal.h"

/* The system of one curve: the plant's tree (positions as in the
 * phc_water_system) plus, with a pot, the soil at position np, child of the
 * root.  State vectors: theta, then one sensitivity per entry of vkind. */
typedef struct balance {
    size_t n, np;        /* nodes, plant nodes */
    size_t *par;         /* n */
    double *w, *d, *area, *ell; /* n each (ell: g delta area of the current interval) */
    double K;            /* pressure per relative fill (d = V / K) */
    int pot;             /* soil at position np */
    double C, k;         /* capacity (g), conductance (g/s) */
    double delta, mu, mu_power, w0;
    size_t ncoef;
    size_t nv;           /* state vectors: 1 + sensitivities */
    int *vkind;          /* nv: -1 for theta, else a PHC_WB_* column */
    double *x0;          /* nv * n: state at the curve's start */
} balance;

static void balance_free(balance *b)
{
    if (!b)
        return;
    free(b->par);
    free(b->w);
    free(b->d);
    free(b->area);
    free(b->ell);
    free(b->vkind);
    free(b->x0);
}

static int balance_init(balance *b, const phc_water_system *s, const phc_water_pot *pot,
                        size_t ncoef, int sens, phc_error *err)
{
    memset(b, 0, sizeof *b);
    const size_t np = s->n, n = np + (pot ? 1 : 0);
    b->n = n;
    b->np = np;
    b->pot = pot != NULL;
    b->delta = s->delta;
    b->mu = s->mu;
    b->mu_power = s->mu_power;
    b->w0 = s->w0;
    b->ncoef = ncoef;
    b->K = s->vol[0] / s->d[0];
    b->nv = 1 + (sens ? 2 + (pot ? 2 : 0) + ncoef : 0);
    b->par = calloc(n, sizeof *b->par);
    b->w = calloc(n, sizeof *b->w);
    b->d = calloc(n, sizeof *b->d);
    b->area = calloc(n, sizeof *b->area);
    b->ell = calloc(n, sizeof *b->ell);
    b->vkind = calloc(b->nv, sizeof *b->vkind);
    b->x0 = calloc(b->nv * n, sizeof *b->x0);
    if (!b->par || !b->w || !b->d || !b->area || !b->ell || !b->vkind || !b->x0) {
        balance_free(b);
        return phc_error_set(err, PHC_ERR_NOMEM, "water balance: out of memory for %zu nodes", n);
    }
    memcpy(b->par, s->par, np * sizeof *b->par);
    memcpy(b->w, s->w, np * sizeof *b->w);
    memcpy(b->d, s->d, np * sizeof *b->d);
    memcpy(b->area, s->area, np * sizeof *b->area);
    double vsum = 0.0;
    for (size_t k = 0; k < np; ++k)
        vsum += s->vol[k];
    double plant_share = 1.0;
    if (pot) {
        b->C = pot->capacity;
        b->k = pot->conductance;
        b->par[np] = 0;
        b->w[np] = b->k / b->K;
        b->d[np] = b->C / b->K;
        plant_share = vsum / (vsum + b->C);
        b->x0[np] = b->w0 * b->C / (vsum + b->C);
    }
    for (size_t k = 0; k < np; ++k)
        b->x0[k] = b->w0 * plant_share * s->vol[k] / vsum;
    size_t v = 0;
    b->vkind[v++] = -1;
    if (sens) {
        b->vkind[v++] = PHC_WB_DELTA;
        b->vkind[v++] = PHC_WB_MU;
        if (pot) {
            /* the equilibrium split depends on C */
            double *x = b->x0 + v * n, den = (vsum + b->C) * (vsum + b->C);
            for (size_t k = 0; k < np; ++k)
                x[k] = -b->w0 * s->vol[k] / den;
            x[np] = b->w0 * vsum / den;
            b->vkind[v++] = PHC_WB_CAPACITY;
            b->vkind[v++] = PHC_WB_CONDUCTANCE;
        }
        for (size_t j = 0; j < ncoef; ++j)
            b->vkind[v++] = PHC_WB_COEF + (int)j;
    }
    return PHC_OK;
}

static void set_loss(balance *b, double g)
{
    for (size_t k = 0; k < b->n; ++k)
        b->ell[k] = g * b->delta * b->area[k];
}

/* rhs += c (dS/dp) th for the parameter of sensitivity kind `kind`, on an
 * interval with multiplier g and d g / d c = dg (ncoef). */
static void add_source(const balance *b, int kind, double g, const double *dg, const double *th,
                       double c, double *rhs)
{
    const size_t n = b->n, np = b->np;
    if (kind == PHC_WB_DELTA || kind >= PHC_WB_COEF) {
        /* dS/d delta = -g D_a; dS/d c_j = -delta (d g / d c_j) D_a */
        double f = kind == PHC_WB_DELTA ? g : b->delta * dg[kind - PHC_WB_COEF];
        for (size_t k = 0; k < n; ++k)
            rhs[k] -= c * f * b->area[k] * th[k];
    } else if (kind == PHC_WB_MU) {
        /* the plant's weights scale as mu^p: dS/d mu = (p/mu) R_plant D^-1 */
        double f = c * b->mu_power / b->mu;
        for (size_t k = 1; k < np; ++k) {
            size_t pk = b->par[k];
            double q = f * b->w[k] * (th[pk] / b->d[pk] - th[k] / b->d[k]);
            rhs[k] += q;
            rhs[pk] -= q;
        }
    } else if (kind == PHC_WB_CAPACITY) {
        /* soil pressure K theta_s / C: d/dC of the edge flux w_s (P_root - P_s)/K */
        double q = c * b->w[np] * th[np] * b->K / (b->C * b->C);
        rhs[np] += q;
        rhs[0] -= q;
    } else if (kind == PHC_WB_CONDUCTANCE) {
        double q = c / b->K * (th[0] / b->d[0] - th[np] / b->d[np]);
        rhs[np] += q;
        rhs[0] -= q;
    }
}

/* ---- BDF6 -------------------------------------------------------------- */

typedef struct stepper {
    balance *b;
    double g;
    const double *dg;
    double c;
    double *l, *u, *ip; /* factorisation of I - c S */
} stepper;

static void stepper_factor(stepper *st, double c)
{
    if (st->c == c)
        return;
    phc_water_tree_factor(st->b->n, st->b->par, st->b->w, st->b->d, st->b->ell, c, st->l, st->u,
                          st->ip);
    st->c = c;
}

/* x (nv * n) holds the right-hand sides; solves the implicit step. */
static void implicit_solve(stepper *st, double *x)
{
    const balance *b = st->b;
    const size_t n = b->n;
    phc_water_tree_solve(n, b->par, st->l, st->u, st->ip, x);
    for (size_t v = 1; v < b->nv; ++v) {
        double *xv = x + v * n;
        add_source(b, b->vkind[v], st->g, st->dg, x, st->c, xv);
        phc_water_tree_solve(n, b->par, st->l, st->u, st->ip, xv);
    }
}

#define START_ORDERS PHC_WATER_START_ORDERS
#define START_SUBINTERVALS 2
#define BDF6_ALPHA PHC_WATER_BDF6_ALPHA
#define bdf6_beta phc_water_bdf6_beta

static void factor_cb(void *st, double c)
{
    ((stepper *)st)->c = -1.0; /* always refactor */
    stepper_factor(st, c);
}
static void step_cb(void *st, double *y) { implicit_solve(st, y); }

/* One interval of length H from x (nv * n): model/water_tree.c. */
static void extrapolated_euler(stepper *st, double H, double *x, double *T, double *y)
{
    phc_water_extrapolated_euler(st->b->nv * st->b->n, H, x, T, y, factor_cb, step_cb, st);
}

static void totals(const balance *b, const double *x, double *sums)
{
    for (size_t v = 0; v < b->nv; ++v) {
        double acc = 0.0;
        for (size_t k = 0; k < b->n; ++k)
            acc += x[v * b->n + k];
        sums[v] = acc;
    }
}

/* Workspace of the BDF6 evaluator. */
typedef struct bdf6_work {
    double *ring, *T, *y, *l, *u, *ip, *sums;
    size_t sums_cap;
} bdf6_work;

/* Integrates x (nv * n, state at a) over [a, a + len] with at least 6 steps
 * of at most hmax, writes the totals at the observation times t[i0..i1)
 * (within the interval) into out (nv per time), and leaves the state at
 * a + len in x. */
static int bdf6_interval(balance *b, stepper *st, bdf6_work *wk, double a, double len,
                         double hmax, double *x, const double *t, size_t i0, size_t i1,
                         double *out)
{
    const size_t nv = b->nv, len_v = nv * b->n;
    size_t N = (size_t)ceil(len / hmax - 1e-9);
    if (N < 6)
        N = 6;
    const double h = len / (double)N;
    if ((N + 1) * nv > wk->sums_cap) {
        double *p = realloc(wk->sums, (N + 1) * nv * sizeof *p);
        if (!p)
            return PHC_ERR_NOMEM;
        wk->sums = p;
        wk->sums_cap = (N + 1) * nv;
    }
    memcpy(wk->ring, x, len_v * sizeof *x);
    totals(b, x, wk->sums);
    for (size_t q = 1; q <= 5; ++q) {
        for (int r = 0; r < START_SUBINTERVALS; ++r)
            extrapolated_euler(st, h / START_SUBINTERVALS, x, wk->T, wk->y);
        memcpy(wk->ring + q * len_v, x, len_v * sizeof *x);
        totals(b, x, wk->sums + q * nv);
    }
    st->c = -1.0;
    stepper_factor(st, BDF6_ALPHA * h);
    for (size_t m = 6; m <= N; ++m) {
        double *outx = wk->ring + (m % 6) * len_v; /* overwrites x_{m-6} */
        for (size_t q = 0; q < len_v; ++q) {
            double r = 0.0;
            for (int j = 0; j < 6; ++j)
                r += bdf6_beta[j] * wk->ring[((m - 6 + (size_t)j) % 6) * len_v + q];
            wk->y[q] = r;
        }
        implicit_solve(st, wk->y);
        memcpy(outx, wk->y, len_v * sizeof *outx);
        totals(b, outx, wk->sums + m * nv);
    }
    memcpy(x, wk->ring + (N % 6) * len_v, len_v * sizeof *x);
    /* dense output: 7-point Lagrange on the step totals */
    for (size_t i = i0; i < i1; ++i) {
        double xs = (t[i] - a) / h;
        long k0 = (long)floor(xs) - 3;
        if (k0 < 0)
            k0 = 0;
        if (k0 > (long)N - 6)
            k0 = (long)N - 6;
        for (size_t v = 0; v < nv; ++v)
            out[i * nv + v] = 0.0;
        for (int p = 0; p < 7; ++p) {
            double L = 1.0;
            for (int j = 0; j < 7; ++j)
                if (j != p)
                    L *= (xs - (double)(k0 + j)) / (double)(p - j);
            for (size_t v = 0; v < nv; ++v)
                out[i * nv + v] += L * wk->sums[(size_t)(k0 + p) * nv + v];
        }
    }
    return PHC_OK;
}

/* ---- exact, piecewise --------------------------------------------------- */

/* Eigen-decomposition of the symmetric form A = D^-1/2 (R D^-1 - D_l) D^1/2
 * of the current interval, and the sensitivity sources in its eigenbasis:
 * Mv = Q^T D^-1/2 (dS/dp_v) D^1/2 Q for the kinds that do not scale with
 * the interval's g (mu, C, k), Ga = Q^T D_a Q for those that do. */
typedef struct eigen {
    double g;
    double *lambda, *Q, *Ga, *Mv; /* n, n*n, n*n, nv*n*n */
    double *a;                    /* n: Q^T D^1/2 1 */
} eigen;

static void eigen_free(eigen *e)
{
    free(e->lambda);
    free(e->Q);
    free(e->Ga);
    free(e->Mv);
    free(e->a);
    memset(e, 0, sizeof *e);
}

/* Q^T B Q into out (n x n column major); tmp n*n. */
static void congruence(size_t n, const double *Q, const double *B, double *tmp, double *out)
{
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)n, (int)n, (int)n, 1.0, B, (int)n,
                Q, (int)n, 0.0, tmp, (int)n);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)n, (int)n, (int)n, 1.0, Q, (int)n,
                tmp, (int)n, 0.0, out, (int)n);
}

static int eigen_new(balance *b, double g, eigen *e, phc_error *err)
{
    const size_t n = b->n, nn = n * n;
    memset(e, 0, sizeof *e);
    e->g = g;
    e->lambda = malloc(n * sizeof *e->lambda);
    e->Q = calloc(nn, sizeof *e->Q);
    e->a = malloc(n * sizeof *e->a);
    double *sq = malloc(n * sizeof *sq), *B = NULL, *tmp = NULL;
    if (!e->lambda || !e->Q || !e->a || !sq)
        goto nomem;
    set_loss(b, g);
    for (size_t k = 0; k < n; ++k) {
        sq[k] = sqrt(b->d[k]);
        e->Q[k * n + k] = -b->ell[k];
    }
    for (size_t k = 1; k < n; ++k) {
        size_t pk = b->par[k];
        double o = b->w[k] / (sq[k] * sq[pk]);
        e->Q[k * n + k] -= b->w[k] / b->d[k];
        e->Q[pk * n + pk] -= b->w[k] / b->d[pk];
        e->Q[pk * n + k] = o;
        e->Q[k * n + pk] = o;
    }
    if (LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'L', (lapack_int)n, e->Q, (lapack_int)n, e->lambda)) {
        free(sq);
        eigen_free(e);
        return phc_error_set(err, PHC_ERR_NUMERIC, "water balance: dsyevd did not converge");
    }
    cblas_dgemv(CblasColMajor, CblasTrans, (int)n, (int)n, 1.0, e->Q, (int)n, sq, 1, 0.0, e->a, 1);
    if (b->nv > 1) {
        e->Ga = malloc(nn * sizeof *e->Ga);
        e->Mv = calloc(b->nv * nn, sizeof *e->Mv);
        B = malloc(nn * sizeof *B);
        tmp = malloc(nn * sizeof *tmp);
        if (!e->Ga || !e->Mv || !B || !tmp)
            goto nomem;
        memset(B, 0, nn * sizeof *B);
        for (size_t k = 0; k < n; ++k)
            B[k * n + k] = b->area[k];
        congruence(n, e->Q, B, tmp, e->Ga);
        for (size_t v = 1; v < b->nv; ++v) {
            int kind = b->vkind[v];
            if (kind == PHC_WB_DELTA || kind >= PHC_WB_COEF)
                continue;
            /* B = D^-1/2 (dS/dp) D^1/2, column j from dS/dp applied to e_j */
            double *col = tmp;
            for (size_t j = 0; j < n; ++j) {
                memset(col, 0, n * sizeof *col);
                double *e_j = B + j * n; /* reuse as the unit vector, then the column */
                memset(e_j, 0, n * sizeof *e_j);
                e_j[j] = sq[j];
                add_source(b, kind, g, NULL, e_j, 1.0, col);
                for (size_t k = 0; k < n; ++k)
                    e_j[k] = col[k] / sq[k];
            }
            congruence(n, e->Q, B, tmp, e->Mv + v * nn);
        }
    }
    free(sq);
    free(B);
    free(tmp);
    return PHC_OK;
nomem:
    free(sq);
    free(B);
    free(tmp);
    eigen_free(e);
    return phc_error_set(err, PHC_ERR_NOMEM, "water balance: out of memory for %zu nodes", n);
}

/* From the eigen-coordinates z (nv * n: z_v = Q^T D^-1/2 x_v at the
 * interval's start) to the totals (nv) after tau, and, when xt is given, the
 * state in original coordinates (nv * n).  work: n*n + 3n. */
static void exact_advance(const balance *b, const eigen *e, const double *dg, const double *z,
                          double tau, double *tot, double *xt, double *work)
{
    const size_t n = b->n, nn = n * n;
    double *E = work, *Phi = work + n, *zt = work + n + nn, *col = zt + n;
    for (size_t i = 0; i < n; ++i)
        E[i] = exp(e->lambda[i] * tau);
    if (b->nv > 1)
        for (size_t j = 0; j < n; ++j)
            for (size_t i = 0; i < n; ++i)
                Phi[j * n + i] = phc_water_expm_divided_difference(e->lambda[i], e->lambda[j], E[i],
                                                                   E[j], tau);
    for (size_t v = 0; v < b->nv; ++v) {
        const double *zv = z + v * n;
        for (size_t i = 0; i < n; ++i)
            zt[i] = E[i] * zv[i];
        if (v > 0) {
            int kind = b->vkind[v];
            const double *M = e->Mv + v * nn;
            double scale = 1.0;
            if (kind == PHC_WB_DELTA || kind >= PHC_WB_COEF) {
                M = e->Ga;
                scale = -(kind == PHC_WB_DELTA ? e->g : b->delta * dg[kind - PHC_WB_COEF]);
            }
            for (size_t j = 0; j < n; ++j) {
                const double zj = scale * z[j];
                if (zj == 0.0)
                    continue;
                for (size_t i = 0; i < n; ++i)
                    zt[i] += Phi[j * n + i] * M[j * n + i] * zj;
            }
        }
        tot[v] = cblas_ddot((int)n, e->a, 1, zt, 1);
        if (xt) {
            cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)n, 1.0, e->Q, (int)n, zt, 1, 0.0,
                        col, 1);
            for (size_t k = 0; k < n; ++k)
                xt[v * n + k] = sqrt(b->d[k]) * col[k];
        }
    }
}

/* ---- the curve ---------------------------------------------------------- */

/* Gershgorin bound of the fastest rate, with the largest g. */
static double balance_stiffness(balance *b, double gmax)
{
    set_loss(b, gmax);
    double rho = 0.0;
    double *row = calloc(b->n, sizeof *row);
    if (!row)
        return INFINITY;
    for (size_t k = 1; k < b->n; ++k) {
        double o = b->w[k] / sqrt(b->d[k] * b->d[b->par[k]]);
        row[k] += o + b->w[k] / b->d[k];
        row[b->par[k]] += o + b->w[k] / b->d[b->par[k]];
    }
    for (size_t k = 0; k < b->n; ++k)
        rho = fmax(rho, row[k] + b->ell[k]);
    free(row);
    return rho;
}

int phc_water_balance_curve(const phc_water_system *s, const phc_water_pot *pot,
                            const phc_water_loss_pattern *loss, double t_start,
                            phc_water_method method, double step_or_0, const double *t,
                            size_t m, double *W, double *dW, phc_error *err)
{
    if (!s || !t || !W || m == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "water balance: NULL argument or no times");
    for (size_t i = 0; i < m; ++i)
        if (!(t[i] >= t_start) || !isfinite(t[i]) || (i && t[i] < t[i - 1]))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "water balance: times must be sorted, finite and >= the start %g s "
                                 "(t[%zu] = %g)", t_start, i, t[i]);
    if (pot && (!(pot->capacity > 0.0) || !isfinite(pot->capacity) ||
                !(pot->conductance >= 0.0) || !isfinite(pot->conductance)))
        return phc_error_set(err, PHC_ERR_DOMAIN,
                             "water balance: the pot needs capacity > 0 g and conductance >= 0 g/s, "
                             "found %g and %g", pot->capacity, pot->conductance);
    static const double one = 1.0, zero = 0.0;
    phc_water_loss_pattern flat = {1, &t_start, &one, 0, NULL};
    if (!loss)
        loss = &flat;
    if (loss->n == 0 || !loss->start || !loss->g || (loss->n_coef && !loss->dg))
        return phc_error_set(err, PHC_ERR_INVALID, "water balance: an empty loss pattern");
    double gmax = 0.0;
    for (size_t k = 0; k < loss->n; ++k) {
        if (!(loss->g[k] >= 0.0) || !isfinite(loss->g[k]))
            return phc_error_set(err, PHC_ERR_DOMAIN,
                                 "water balance: the loss multiplier must be >= 0, found %g from %g s",
                                 loss->g[k], loss->start[k]);
        if (k && !(loss->start[k] > loss->start[k - 1]))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "water balance: the loss pattern's intervals must be ascending");
        gmax = fmax(gmax, loss->g[k]);
    }
    if (!(step_or_0 >= 0.0) || !isfinite(step_or_0))
        return phc_error_set(err, PHC_ERR_DOMAIN, "water balance: step must be >= 0 s, found %g",
                             step_or_0);
    balance b;
    int rc = balance_init(&b, s, pot, loss->n_coef, dW != NULL, err);
    if (rc)
        return rc;
    const size_t n = b.n, nv = b.nv, nw = PHC_WB_COEF + loss->n_coef;
    const double t_end = t[m - 1], span = t_end - t_start;
    if (method == PHC_WATER_AUTO)
        method = (n <= PHC_WATER_AUTO_EXACT_MAX && balance_stiffness(&b, gmax) * span <= 1e7)
                     ? PHC_WATER_EXACT
                     : PHC_WATER_BDF6;
    double *x = malloc(nv * n * sizeof *x), *out = malloc(m * nv * sizeof *out);
    bdf6_work wk = {0};
    stepper st = {&b, 1.0, NULL, -1.0, NULL, NULL, NULL};
    eigen e[2]; /* the last two decompositions (day and night) */
    memset(e, 0, sizeof e);
    int next_e = 0;
    double *z = NULL, *work = NULL;
    if (!x || !out)
        goto nomem;
    memcpy(x, b.x0, nv * n * sizeof *x);
    if (method == PHC_WATER_BDF6) {
        const size_t len = nv * n;
        wk.ring = malloc(6 * len * sizeof *wk.ring);
        wk.T = malloc((size_t)START_ORDERS * len * sizeof *wk.T);
        wk.y = malloc(len * sizeof *wk.y);
        st.l = malloc(n * sizeof *st.l);
        st.u = malloc(n * sizeof *st.u);
        st.ip = malloc(n * sizeof *st.ip);
        if (!wk.ring || !wk.T || !wk.y || !st.l || !st.u || !st.ip)
            goto nomem;
    } else if (method == PHC_WATER_EXACT) {
        z = malloc(nv * n * sizeof *z);
        work = malloc((n * n + 3 * n) * sizeof *work);
        if (!z || !work)
            goto nomem;
    } else {
        rc = phc_error_set(err, PHC_ERR_INVALID, "water balance: unknown method %d", (int)method);
        goto done;
    }
    const double hmax = step_or_0 > 0.0 ? step_or_0 : (span > 0 ? span / 1000.0 : 1.0);
    /* interval holding t_start */
    size_t k = 0;
    while (k + 1 < loss->n && loss->start[k + 1] <= t_start)
        ++k;
    double a = t_start;
    size_t i = 0;
    while (i < m && t[i] == t_start) { /* the start itself */
        totals(&b, x, out + i * nv);
        ++i;
    }
    while (i < m) {
        /* the interval, merged with the following ones while g and dg stay
         * the same (a schedule's or a covariate's plateaus): fewer restarts */
        size_t k_next = k + 1;
        while (k_next < loss->n && loss->start[k_next] < t_end && loss->g[k_next] == loss->g[k] &&
               (loss->n_coef == 0 || memcmp(loss->dg + k_next * loss->n_coef, loss->dg + k * loss->n_coef,
                                           loss->n_coef * sizeof *loss->dg) == 0))
            ++k_next;
        const double end = k_next < loss->n && loss->start[k_next] < t_end ? loss->start[k_next] : t_end;
        size_t i1 = i;
        while (i1 < m && t[i1] <= end)
            ++i1;
        const double g = loss->g[k];
        const double *dg = loss->n_coef ? loss->dg + k * loss->n_coef : NULL;
        if (end > a) {
            if (method == PHC_WATER_BDF6) {
                set_loss(&b, g);
                st.g = g;
                st.dg = dg;
                st.c = -1.0;
                if ((rc = bdf6_interval(&b, &st, &wk, a, end - a, hmax, x, t, i, i1, out)))
                    goto nomem;
            } else {
                eigen *ek = NULL;
                for (int q = 0; q < 2; ++q)
                    if (e[q].lambda && e[q].g == g)
                        ek = &e[q];
                if (!ek) {
                    eigen_free(&e[next_e]);
                    if ((rc = eigen_new(&b, g, &e[next_e], err)))
                        goto done;
                    ek = &e[next_e];
                    next_e ^= 1;
                }
                /* z = Q^T D^-1/2 x */
                double *col = work;
                for (size_t v = 0; v < nv; ++v) {
                    for (size_t q = 0; q < n; ++q)
                        col[q] = x[v * n + q] / sqrt(b.d[q]);
                    cblas_dgemv(CblasColMajor, CblasTrans, (int)n, (int)n, 1.0, ek->Q, (int)n, col,
                                1, 0.0, z + v * n, 1);
                }
                for (size_t q = i; q < i1; ++q)
                    exact_advance(&b, ek, dg, z, t[q] - a, out + q * nv, NULL, work);
                if (end < t_end) {
                    double tot[64];
                    double *tt = nv <= 64 ? tot : malloc(nv * sizeof *tt);
                    if (!tt)
                        goto nomem;
                    exact_advance(&b, ek, dg, z, end - a, tt, x, work);
                    if (tt != tot)
                        free(tt);
                }
            }
        }
        i = i1;
        a = end;
        k = k_next < loss->n ? k_next : loss->n - 1;
    }
    for (size_t q = 0; q < m; ++q) {
        W[q] = out[q * nv];
        if (!dW)
            continue;
        double *row = dW + q * nw;
        for (size_t c = 0; c < nw; ++c)
            row[c] = zero;
        row[PHC_WB_W0] = W[q] / b.w0;
        for (size_t v = 1; v < nv; ++v)
            row[b.vkind[v]] = out[q * nv + v];
    }
    rc = PHC_OK;
    goto done;
nomem:
    rc = phc_error_set(err, PHC_ERR_NOMEM, "water balance: out of memory for %zu nodes and %zu times",
                       n, m);
done:
    free(x);
    free(out);
    free(wk.ring);
    free(wk.T);
    free(wk.y);
    free(wk.sums);
    free(st.l);
    free(st.u);
    free(st.ip);
    free(z);
    free(work);
    eigen_free(&e[0]);
    eigen_free(&e[1]);
    balance_free(&b);
    return rc;
}
