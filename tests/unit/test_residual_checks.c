/* Unit tests of fit/engine/residual_checks.c against independently computed
 * reference values.
 *
 * Reference tools (Debian 12 packages):
 *   Python 3.11 /usr/bin/python3 with scipy 1.10.1, numpy 1.24.2,
 *   statsmodels 0.13.5 (python3-statsmodels);
 *   R 4.2 with lmtest 0.9-40 (r-cran-lmtest).
 * Each reference number below says which call produced it.  Numbers printed
 * with "%.17g".
 *
 * Note on scipy.stats.shapiro: scipy runs the AS R94 Fortran in single
 * precision, so its W and p agree with a double-precision implementation only
 * to about 1e-4 relative (worse for p when W is very close to 1 at large n);
 * R's shapiro.test (swilk.c, double precision) is used as the tight
 * reference. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "check.h"
#include "fit/engine/residual_checks.h"

#define N30 30

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Residuals of R: lm(y ~ t + I(t^2)), t = 1..30, with
 * y = c(2.474, 2.925, 3.618, 3.779, 4.738, 5.449, 6.06, 7.049, 7.232, 8.376,
 *       9.22, 10.62, 11.92, 12.5, 13.271, 13.901, 15.095, 16.921, 18.87,
 *       20.23, 21.484, 22.227, 23.929, 24.872, 26.767, 28.231, 30.535,
 *       32.114, 34.655, 35.495)
 * (a quadratic trend plus AR(1) noise of growing spread, rounded to 3
 * decimals); sprintf("%.17g", residuals(fit)). */
static const double res1[N30] = {
    -0.05621169354839059, -0.066255547830926229, 0.1169083386302253,
    -0.2807200341649419, 0.070859333783571524, 0.12564644247576867,
    0.031641291911648564, 0.26684388209121329, -0.35274578698553893,
    -0.060127715318608825, -0.11630190290799297, 0.33473165024630425,
    0.63697294414428696, 0.17042197878595186, -0.15392124582869854,
    -0.66805672969966734, -0.6669844728269505, -0.082704475210552533,
    0.57578326314953099, 0.59647874225329689, 0.46238196210074806,
    -0.23150707730811992, -0.01518837597330544, -0.60666193389480383,
    -0.29492775107262031, -0.46298582750675144, 0.16016383680279636,
    0.0095212418560286782, 0.77208638765295012, -0.21514072580645194};

/* fitted(fit) of the same R fit */
static const double fit1[N30] = {
    2.5302116935483907, 2.9912555478309262, 3.5010916613697747,
    4.0597200341649415, 4.6671406662164285, 5.3233535575242312,
    6.0283587080883514, 6.7821561179087873, 7.5847457869855388,
    8.4361277153186087, 9.3363019029079943, 10.285268349753695,
    11.283027055855714, 12.329578021214049, 13.424921245828699,
    14.569056729699668, 15.761984472826951, 17.003704475210551,
    18.294216736850469, 19.633521257746704, 21.021618037899255,
    22.45850707730812, 23.944188375973305, 25.478661933894802,
    27.06192775107262, 28.693985827506754, 30.374836163197205,
    32.104478758143969, 33.882913612347053, 35.710140725806447};

/* Residuals of R: lm(y ~ 0 + X1 + X2 + X3) on the same y, with
 * X1 = exp(-t/10), X2 = t exp(-t/10), X3 = t: a regression without an
 * intercept, like the Jacobian of a nonlinear model. */
static const double res2[N30] = {
    -1.2712995539265173, -0.5246961161059881, 0.20153613463068026,
    0.16975399249789297, 0.74177065058635627, 0.89939121838068004,
    0.81488746329246509, 0.98741849380570013, 0.25140337368616311,
    0.38985100631121938, 0.15565204732805324, 0.41683708519980295,
    0.52780486617259448, -0.12247607309767794, -0.61528937085358804,
    -1.2760137381670007, -1.3939844177549736, -0.89637109378059676,
    -0.28807037621980258, -0.27761119152620639, -0.37907159685333636,
    -0.99500570041810288, -0.65337951787605486, -1.0705147257635814,
    -0.53403938987587096, -0.42584485043901571, 0.52595196151691914,
    0.75704141983374629, 1.9549498809576995, 1.4570646486089094};

/* Deterministic test data, generated identically in Python (plain floats,
 * same operation order):
 *   u1 = ((i*37 + 11) % 101 + 0.5) / 101, u2 = ((i*53 + 7) % 103 + 0.5) / 103,
 *   u3 = ((i*71 + 3) % 107 + 0.5) / 107, i = 0..n-1;
 *   kind 0: x = u1 + u2 + u3 (near normal), kind 1: x = u1^3 + 0.1 u2 (skewed). */
static void gen(double *x, size_t n, int kind)
{
    for (size_t i = 0; i < n; ++i) {
        double u1 = ((double)((i * 37 + 11) % 101) + 0.5) / 101;
        double u2 = ((double)((i * 53 + 7) % 103) + 0.5) / 103;
        double u3 = ((double)((i * 71 + 3) % 107) + 0.5) / 107;
        x[i] = kind == 0 ? u1 + u2 + u3 : u1 * u1 * u1 + 0.1 * u2;
    }
}

/* ------------------------------------------------------------------------ */

static void check_sw(const double *x, size_t n, double w_scipy, double p_scipy,
                     double w_r, double p_r)
{
    double w = 0, p = 0;
    CHECK(phc_check_shapiro_wilk(x, n, &w, &p) == PHC_OK);
    if (!isnan(w_scipy)) {
        CHECK_NEAR(w, w_scipy, 0, 1e-4);
        CHECK_NEAR(p, p_scipy, 1e-12, 1e-4);
    }
    CHECK_NEAR(w, w_r, 0, 1e-9);
    CHECK_NEAR(p, p_r, 1e-300, 1e-8);
}

static void test_shapiro_wilk(void)
{
    /* scipy.stats.shapiro(x) -> (W, p); R shapiro.test(x) -> (W, p) */
    const double sw3[3] = {2.1, 3.7, 2.9}; /* equally spaced: W = 1, p = 1 */
    check_sw(sw3, 3, 1.0, 0.99999892711639404, 1.0, 0.99999999999999334);
    const double sw3b[3] = {1.0, 2.0, 10.0};
    check_sw(sw3b, 3, 0.83219176530838013, 0.19391654431819916,
             0.8321917808219178, 0.19391752148144781);
    const double sw5[5] = {4.2, 1.1, 3.3, 9.8, 2.0};
    check_sw(sw5, 5, 0.85628670454025269, 0.21522054076194763,
             0.8562867033881667, 0.21522047743462655);
    const double sw11[11] = {148, 154, 158, 160, 161, 162, 166, 170, 182, 195, 236};
    check_sw(sw11, 11, 0.78881478309631348, 0.0067038331180810928,
             0.78881469483538735, 0.0067038140565029254);
    const double sw20[20] = {6.6, 5.4, 7.1, 5.9, 6.2, 8.8, 5.0, 6.1, 6.9, 7.4,
                             5.6, 6.0, 6.4, 9.7, 5.8, 6.3, 7.0, 6.7, 5.2, 11.3};
    check_sw(sw20, 20, 0.83188587427139282, 0.0026896533090621233,
             0.83188581477485724, 0.0026896506827466479);
    check_sw(res1, N30, 0.97354263067245483, 0.63989901542663574,
             0.9735427079665151, 0.63990168416152593);

    static double g[5000];
    gen(g, 50, 0);
    check_sw(g, 50, 0.98798954486846924, 0.88841992616653442,
             0.98798955865831484, 0.88842077278153397);
    gen(g, 200, 1);
    check_sw(g, 200, 0.84612548351287842, 2.7998472138836272e-13,
             0.8461250165412082, 2.7997235166141671e-13);
    /* n = 1000 and 5000: scipy's single precision gives p = 1.6274541849270463e-05
     * (rel. error 1e-3) and p = 0 (underflow); only R is used. */
    gen(g, 1000, 0);
    check_sw(g, 1000, NAN, NAN, 0.99151074934183525, 1.6258605819445481e-05);
    gen(g, 5000, 1);
    check_sw(g, 5000, NAN, NAN, 0.84663649072052349, 1.1177472150524029e-56);

    /* invariance under order, shift and positive scale */
    {
        double y[20], w0, p0, w1, p1;
        for (size_t i = 0; i < 20; ++i)
            y[i] = 1e3 + 4.0 * sw20[19 - i];
        CHECK(phc_check_shapiro_wilk(sw20, 20, &w0, &p0) == PHC_OK);
        CHECK(phc_check_shapiro_wilk(y, 20, &w1, &p1) == PHC_OK);
        CHECK_NEAR(w1, w0, 0, 1e-12);
        CHECK_NEAR(p1, p0, 0, 1e-9);
    }

    /* degenerate inputs */
    double w = 0, p = 0;
    const double two[2] = {1, 2};
    CHECK(phc_check_shapiro_wilk(two, 2, &w, &p) == PHC_ERR_INVALID);
    CHECK(isnan(w) && isnan(p));
    static double big[5001];
    gen(big, 5001, 0);
    w = p = 0;
    CHECK(phc_check_shapiro_wilk(big, 5001, &w, &p) == PHC_ERR_INVALID);
    CHECK(isnan(w) && isnan(p));
    const double cst[6] = {0.3, 0.3, 0.3, 0.3, 0.3, 0.3};
    w = p = 0;
    CHECK(phc_check_shapiro_wilk(cst, 6, &w, &p) == PHC_ERR_INVALID);
    CHECK(isnan(w) && isnan(p));
    const double withnan[5] = {1, 2, NAN, 4, 5};
    w = p = 0;
    CHECK(phc_check_shapiro_wilk(withnan, 5, &w, &p) == PHC_ERR_INVALID);
    CHECK(isnan(w) && isnan(p));
    const double withinf[5] = {1, 2, INFINITY, 4, 5};
    CHECK(phc_check_shapiro_wilk(withinf, 5, &w, &p) == PHC_ERR_INVALID);
    CHECK(phc_check_shapiro_wilk(NULL, 5, &w, &p) == PHC_ERR_INVALID);
}

/* ------------------------------------------------------------------------ */

static void check_ad(const double *x, size_t n, double a2_scipy, double p_sm)
{
    double a = 0, p = 0;
    double adj = 1.0 + 0.75 / (double)n + 2.25 / ((double)n * (double)n);
    CHECK(phc_check_anderson_darling(x, n, &a, &p) == PHC_OK);
    CHECK_NEAR(a, a2_scipy * adj, 0, 1e-10);
    CHECK_NEAR(p, p_sm, 0, 1e-10);
}

static void test_anderson_darling(void)
{
    /* A^2 = scipy.stats.anderson(x).statistic (unadjusted; the function
     * returns A^2 (1 + 0.75/n + 2.25/n^2)); p = statsmodels
     * statsmodels.stats.diagnostic.normal_ad(x)[1] (same D'Agostino-Stephens
     * formulas on the adjusted statistic). */
    const double sw11[11] = {148, 154, 158, 160, 161, 162, 166, 170, 182, 195, 236};
    check_ad(sw11, 11, 0.94677187959888798, 0.010454024005147656); /* A* >= 0.6 */
    const double sw20[20] = {6.6, 5.4, 7.1, 5.9, 6.2, 8.8, 5.0, 6.1, 6.9, 7.4,
                             5.6, 6.0, 6.4, 9.7, 5.8, 6.3, 7.0, 6.7, 5.2, 11.3};
    check_ad(sw20, 20, 1.2035573189800495, 0.0028960477402522277);
    check_ad(res1, N30, 0.25288491722710305, 0.71197833035832847); /* 0.2..0.34 */
    double g[200];
    gen(g, 50, 0);
    check_ad(g, 50, 0.18745690527619985, 0.89863654554571148); /* A* < 0.2 */

    /* A* >= 10: scipy A^2 = 11.24943695035563 (A* = 11.29);
     * statsmodels extrapolates the last formula (p = 3.9266730297058724e-27);
     * like R nortest::ad.test we return 3.7e-24 there. */
    {
        double a = 0, p = 0;
        gen(g, 200, 1);
        CHECK(phc_check_anderson_darling(g, 200, &a, &p) == PHC_OK);
        CHECK_NEAR(a, 11.24943695035563 * (1 + 0.75 / 200 + 2.25 / 40000.0), 0, 1e-10);
        CHECK_NEAR(p, 3.7e-24, 0, 1e-12);
    }
    /* n = 8 (the minimum), A* = 0.551 in the 0.34..0.6 branch:
     * gen(8, kind 1); scipy / statsmodels as above */
    gen(g, 8, 1);
    check_ad(g, 8, 0.48835460640812123, 0.15555179329229887);

    double a = 0, p = 0;
    const double seven[7] = {1, 2, 3, 4, 5, 6, 8};
    CHECK(phc_check_anderson_darling(seven, 7, &a, &p) == PHC_ERR_INVALID);
    CHECK(isnan(a) && isnan(p));
    const double cst[9] = {2, 2, 2, 2, 2, 2, 2, 2, 2};
    a = p = 0;
    CHECK(phc_check_anderson_darling(cst, 9, &a, &p) == PHC_ERR_INVALID);
    CHECK(isnan(a) && isnan(p));
    const double withnan[9] = {1, 2, 3, 4, NAN, 6, 7, 8, 9};
    a = p = 0;
    CHECK(phc_check_anderson_darling(withnan, 9, &a, &p) == PHC_ERR_INVALID);
    CHECK(isnan(a) && isnan(p));
}

/* ------------------------------------------------------------------------ */

static void test_durbin_watson(void)
{
    double X[N30 * 4], Xd[N30 * 4], Xs[N30 * 3], Xn[N30 * 3];
    for (size_t i = 0; i < N30; ++i) {
        double t = (double)(i + 1);
        X[i * 3 + 0] = 1.0;
        X[i * 3 + 1] = t;
        X[i * 3 + 2] = t * t;
        /* rank-deficient: 4th column = 2 t - 1 */
        Xd[i * 4 + 0] = 1.0;
        Xd[i * 4 + 1] = t;
        Xd[i * 4 + 2] = t * t;
        Xd[i * 4 + 3] = 2.0 * t - 1.0;
        /* badly scaled columns, same column space as X */
        Xs[i * 3 + 0] = 1e6;
        Xs[i * 3 + 1] = 1e-6 * t;
        Xs[i * 3 + 2] = 1e3 * t * t;
        /* no intercept (Jacobian-like) */
        Xn[i * 3 + 0] = exp(-t / 10);
        Xn[i * 3 + 1] = t * exp(-t / 10);
        Xn[i * 3 + 2] = t;
    }

    double d = 0, p = 0;
    /* R: dwtest(lm(y ~ t + I(t^2)), exact = FALSE) -> DW = 1.3432138554715474,
     * p = 0.010773319287536384; statsmodels durbin_watson(res1) gives the
     * same d. */
    CHECK(phc_check_durbin_watson(res1, N30, X, 3, &d, &p) == PHC_OK);
    CHECK_NEAR(d, 1.3432138554715474, 0, 1e-12);
    CHECK_NEAR(p, 0.010773319287536384, 0, 1e-9);

    /* rank-deficient and badly scaled X span the same space: same p */
    d = p = 0;
    CHECK(phc_check_durbin_watson(res1, N30, Xd, 4, &d, &p) == PHC_OK);
    CHECK_NEAR(d, 1.3432138554715474, 0, 1e-12);
    CHECK_NEAR(p, 0.010773319287536384, 0, 1e-8);
    d = p = 0;
    CHECK(phc_check_durbin_watson(res1, N30, Xs, 3, &d, &p) == PHC_OK);
    CHECK_NEAR(p, 0.010773319287536384, 0, 1e-8);

    /* X = NULL (mean removed).  R: dwtest(res1 ~ 1, exact = FALSE) ->
     * p = 0.031387689833953368.  Hand check: with X = 1, A 1 = 0 gives
     * P = tr A = 2(n-1), Q = tr A^2 = 2(3n-4), so E[d] = 2 and
     * Var[d] = 2 (2(3n-4) - 4(n-1)) / ((n-1)(n+1)) = 4 (n-2) / (n^2 - 1). */
    d = p = 0;
    CHECK(phc_check_durbin_watson(res1, N30, NULL, 0, &d, &p) == PHC_OK);
    CHECK_NEAR(d, 1.3432138554715474, 0, 1e-12);
    CHECK_NEAR(p, 0.031387689833953368, 0, 1e-9);
    {
        double n = N30, var = 4.0 * (n - 2.0) / (n * n - 1.0);
        double z = (1.3432138554715474 - 2.0) / sqrt(var);
        CHECK_NEAR(p, 0.5 * erfc(-z / sqrt(2.0)), 0, 1e-12);
    }

    /* No intercept.  R: dwtest(lm(y ~ 0 + X1 + X2 + X3), exact = FALSE) ->
     * DW = 0.36633338696990247, p = 1.8054572648858056e-07;
     * statsmodels durbin_watson(res2) = 0.36633338696990242. */
    d = p = 0;
    CHECK(phc_check_durbin_watson(res2, N30, Xn, 3, &d, &p) == PHC_OK);
    CHECK_NEAR(d, 0.36633338696990247, 0, 1e-12);
    CHECK_NEAR(p, 1.8054572648858056e-07, 0, 1e-8);

    /* degenerate inputs */
    d = p = 0;
    CHECK(phc_check_durbin_watson(res1, 5, X, 3, &d, &p) == PHC_ERR_INVALID); /* n <= k+2 */
    CHECK(isnan(d) && isnan(p));
    d = p = 0;
    CHECK(phc_check_durbin_watson(res1, N30, NULL, 2, &d, &p) == PHC_ERR_INVALID);
    CHECK(isnan(d) && isnan(p));
    const double cst[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    d = p = 0;
    CHECK(phc_check_durbin_watson(cst, 8, NULL, 0, &d, &p) == PHC_ERR_INVALID);
    CHECK(isnan(d) && isnan(p));
    const double zero[8] = {0};
    CHECK(phc_check_durbin_watson(zero, 8, NULL, 0, &d, &p) == PHC_ERR_INVALID);
    double rn[N30];
    for (size_t i = 0; i < N30; ++i)
        rn[i] = res1[i];
    rn[7] = NAN;
    d = p = 0;
    CHECK(phc_check_durbin_watson(rn, N30, X, 3, &d, &p) == PHC_ERR_INVALID);
    CHECK(isnan(d) && isnan(p));
    double Xbad[N30 * 3];
    for (size_t i = 0; i < N30 * 3; ++i)
        Xbad[i] = X[i];
    Xbad[40] = INFINITY;
    CHECK(phc_check_durbin_watson(res1, N30, Xbad, 3, &d, &p) == PHC_ERR_INVALID);
    CHECK(phc_check_durbin_watson(NULL, N30, X, 3, &d, &p) == PHC_ERR_INVALID);
    CHECK(phc_check_durbin_watson(res1, N30, X, (size_t)-1, &d, &p) == PHC_ERR_INVALID);
}

/* ------------------------------------------------------------------------ */

static void test_acf_ljung_box(void)
{
    /* statsmodels.tsa.stattools.acf(res1, nlags=5, adjusted=False, fft=False) */
    const double acf_ref[6] = {1, 0.32235666599230434, 0.031010184518825711,
                               -0.5996306217346381, -0.54265472795694503,
                               -0.31612989160400967};
    double acf[6];
    CHECK(phc_check_acf(res1, N30, 5, acf) == PHC_OK);
    for (int h = 0; h < 6; ++h)
        CHECK_NEAR(acf[h], acf_ref[h], 1e-14, 1e-12);

    double q = 0, p = 0;
    /* statsmodels acorr_ljungbox(res1, lags=[5], model_df=0) ->
     * 30.967635898292457, 9.5060866004481177e-06; R Box.test(res1, lag = 5,
     * type = "Ljung") -> 30.96763589829245, 9.506086600441499e-06 */
    CHECK(phc_check_ljung_box(res1, N30, 5, 0, &q, &p) == PHC_OK);
    CHECK_NEAR(q, 30.967635898292457, 0, 1e-12);
    CHECK_NEAR(p, 9.5060866004481177e-06, 0, 1e-9);

    /* lags = 0 -> min(10, 30/5) = 6; statsmodels acorr_ljungbox(res1,
     * lags=[6], model_df=3) -> 31.707086376680188, 6.0327167726195751e-07 */
    q = p = 0;
    CHECK(phc_check_ljung_box(res1, N30, 0, 3, &q, &p) == PHC_OK);
    CHECK_NEAR(q, 31.707086376680188, 0, 1e-12);
    CHECK_NEAR(p, 6.0327167726195751e-07, 0, 1e-9);

    /* statsmodels acorr_ljungbox(res2, lags=[10], model_df=0) */
    q = p = 0;
    CHECK(phc_check_ljung_box(res2, N30, 10, 0, &q, &p) == PHC_OK);
    CHECK_NEAR(q, 33.294294529460579, 0, 1e-12);
    CHECK_NEAR(p, 0.00024303544947432276, 0, 1e-9);

    /* degenerate inputs */
    q = p = 0;
    CHECK(phc_check_ljung_box(res1, N30, 5, 5, &q, &p) == PHC_ERR_INVALID); /* dof 0 */
    CHECK(isnan(q) && isnan(p));
    q = p = 0;
    CHECK(phc_check_ljung_box(res1, 6, 5, 0, &q, &p) == PHC_ERR_INVALID); /* n <= lags+1 */
    CHECK(isnan(q) && isnan(p));
    const double cst[12] = {3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3};
    q = p = 0;
    CHECK(phc_check_ljung_box(cst, 12, 2, 0, &q, &p) == PHC_ERR_INVALID);
    CHECK(isnan(q) && isnan(p));
    double rn[N30];
    for (size_t i = 0; i < N30; ++i)
        rn[i] = res1[i];
    rn[0] = NAN;
    q = p = 0;
    CHECK(phc_check_ljung_box(rn, N30, 5, 0, &q, &p) == PHC_ERR_INVALID);
    CHECK(isnan(q) && isnan(p));

    q = p = 0;
    CHECK(phc_check_ljung_box(res1, N30, (size_t)-1, 0, &q, &p) == PHC_ERR_INVALID);
    CHECK(isnan(q) && isnan(p));

    double a3[3] = {0, 0, 0};
    CHECK(phc_check_acf(cst, 12, 2, a3) == PHC_ERR_INVALID);
    CHECK(isnan(a3[0]) && isnan(a3[1]) && isnan(a3[2]));
    CHECK(phc_check_acf(res1, 2, 2, a3) == PHC_ERR_INVALID); /* n <= max_lag */
    CHECK(phc_check_acf(rn, N30, 2, a3) == PHC_ERR_INVALID);
    CHECK(isnan(a3[0]));
}

/* ------------------------------------------------------------------------ */

static void test_breusch_pagan(void)
{
    double lm = 0, p = 0;
    /* statsmodels het_breuschpagan(res1, column_stack([ones, fit1]),
     * robust=True)[:2] -> 3.1239389316703789, 0.077150082337802656 */
    CHECK(phc_check_breusch_pagan(res1, fit1, N30, 1, &lm, &p) == PHC_OK);
    CHECK_NEAR(lm, 3.1239389316703789, 0, 1e-11);
    CHECK_NEAR(p, 0.077150082337802656, 0, 1e-9);

    /* Z = (t, t^2): statsmodels het_breuschpagan(res1, [1, t, t^2],
     * robust=True) -> 5.4437890958843482, 0.065750069693859284; R
     * lmtest::bptest(lm(y ~ t + I(t^2)), studentize = TRUE) ->
     * 5.4437890958843473, 0.065750069693859312 */
    double Z2[N30 * 2], Z1[N30], Zd[N30 * 2];
    for (size_t i = 0; i < N30; ++i) {
        double t = (double)(i + 1);
        Z2[i * 2] = t;
        Z2[i * 2 + 1] = t * t;
        Z1[i] = t;
        Zd[i * 2] = t;
        Zd[i * 2 + 1] = 3.0 * t + 1.0; /* collinear with t and the intercept */
    }
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(res1, Z2, N30, 2, &lm, &p) == PHC_OK);
    CHECK_NEAR(lm, 5.4437890958843482, 0, 1e-11);
    CHECK_NEAR(p, 0.065750069693859284, 0, 1e-9);

    /* statsmodels het_breuschpagan(res2, [1, t], robust=True) */
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(res2, Z1, N30, 1, &lm, &p) == PHC_OK);
    CHECK_NEAR(lm, 2.8936930049062148, 0, 1e-11);
    CHECK_NEAR(p, 0.088926871114613643, 0, 1e-9);
    /* rank-deficient Z (t, 3t + 1): same space as (1, t), so the same LM
     * and, with the rank (1) as degrees of freedom, the same p */
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(res2, Zd, N30, 2, &lm, &p) == PHC_OK);
    CHECK_NEAR(lm, 2.8936930049062148, 0, 1e-10);
    CHECK_NEAR(p, 0.088926871114613643, 0, 1e-9);

    /* a constant column whose centring leaves rounding noise (0.1 is not
     * exact in binary) must not count as a regressor: Z = (0.1, t) gives
     * the same LM and p as Z = t */
    double Zc[N30 * 2];
    for (size_t i = 0; i < N30; ++i) {
        Zc[i * 2] = 0.1;
        Zc[i * 2 + 1] = (double)(i + 1);
    }
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(res2, Zc, N30, 2, &lm, &p) == PHC_OK);
    CHECK_NEAR(lm, 2.8936930049062148, 0, 1e-10);
    CHECK_NEAR(p, 0.088926871114613643, 0, 1e-9);
    double z01[N30];
    for (size_t i = 0; i < N30; ++i)
        z01[i] = 0.1;
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(res2, z01, N30, 1, &lm, &p) == PHC_ERR_INVALID);
    CHECK(isnan(lm) && isnan(p));

    /* degenerate inputs */
    double alt[10];
    for (int i = 0; i < 10; ++i)
        alt[i] = (i % 2) ? 0.5 : -0.5; /* r^2 constant */
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(alt, Z1, 10, 1, &lm, &p) == PHC_ERR_INVALID);
    CHECK(isnan(lm) && isnan(p));
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(res1, Z2, 3, 2, &lm, &p) == PHC_ERR_INVALID); /* n <= k+1 */
    CHECK(isnan(lm) && isnan(p));
    CHECK(phc_check_breusch_pagan(res1, Z1, N30, 0, &lm, &p) == PHC_ERR_INVALID);
    CHECK(phc_check_breusch_pagan(res1, Z1, N30, (size_t)-1, &lm, &p) == PHC_ERR_INVALID);
    const double zc[5] = {2, 2, 2, 2, 2};
    const double r5[5] = {0.1, -0.4, 0.3, 0.9, -0.2};
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(r5, zc, 5, 1, &lm, &p) == PHC_ERR_INVALID); /* Z constant */
    CHECK(isnan(lm) && isnan(p));
    double Zn[N30];
    for (size_t i = 0; i < N30; ++i)
        Zn[i] = fit1[i];
    Zn[3] = NAN;
    lm = p = 0;
    CHECK(phc_check_breusch_pagan(res1, Zn, N30, 1, &lm, &p) == PHC_ERR_INVALID);
    CHECK(isnan(lm) && isnan(p));
}

/* ------------------------------------------------------------------------ */

static void test_runs(void)
{
    double z = 0, p = 0;
    size_t runs = 0;

    /* Hand count: 5 positives then 5 negatives: R = 2 runs, n1 = n2 = 5,
     * E[R] = 2*5*5/10 + 1 = 6, Var[R] = 2*25*(50 - 10)/(100*9) = 20/9,
     * z = (2 - 6 + 0.5)/sqrt(20/9) = -2.3478713763747794,
     * p = 2 Q(2.3478713763747794) = 0.018881040156098771 (scipy
     * 2*norm.sf; statsmodels runstest_1samp(x, cutoff=0, correction=True)
     * gives the same). */
    const double block[10] = {1, 2, 3, 4, 5, -1, -2, -3, -4, -5};
    CHECK(phc_check_runs(block, 10, &z, &p, &runs) == PHC_OK);
    CHECK(runs == 2);
    CHECK_NEAR(z, -2.3478713763747794, 0, 1e-12);
    CHECK_NEAR(p, 0.018881040156098771, 0, 1e-10);

    /* Hand count with a zero dropped: signs + + - (0) - + + + - - + -
     * -> runs (++)(--)(+++)(--)(+)(-) = 6, n1 = 6, n2 = 5,
     * E[R] = 60/11 + 1 = 6.4545..., |R - E| = 0.4545 < 1/2 -> z = 0, p = 1. */
    const double mixed[12] = {1, 2, -1, 0, -3, 4, 5, 6, -2, -1, 3, -4};
    z = p = 0;
    CHECK(phc_check_runs(mixed, 12, &z, &p, &runs) == PHC_OK);
    CHECK(runs == 6);
    CHECK_NEAR(z, 0.0, 1e-15, 0);
    CHECK_NEAR(p, 1.0, 1e-15, 0);

    /* Alternating signs: 8 runs of 8 values, n1 = n2 = 4: E = 5,
     * Var = 2*16*(32-8)/(64*7) = 12/7, z = (8 - 5 - 0.5)/sqrt(12/7). */
    const double alt[8] = {1, -1, 1, -1, 1, -1, 1, -1};
    CHECK(phc_check_runs(alt, 8, &z, &p, NULL) == PHC_OK);
    CHECK_NEAR(z, 2.5 / sqrt(12.0 / 7.0), 0, 1e-13);

    /* statsmodels runstest_1samp(res1, cutoff=0, correction=True) ->
     * z = -1.6550971545226856, p = 0.097904791999933682 (11 runs, 14
     * positive, 16 negative) */
    z = p = 0;
    CHECK(phc_check_runs(res1, N30, &z, &p, &runs) == PHC_OK);
    CHECK(runs == 11);
    CHECK_NEAR(z, -1.6550971545226856, 0, 1e-12);
    CHECK_NEAR(p, 0.097904791999933682, 0, 1e-10);

    /* degenerate inputs */
    const double onesign[6] = {1, 2, 3, 0, 5, 6};
    z = p = 0;
    runs = 99;
    CHECK(phc_check_runs(onesign, 6, &z, &p, &runs) == PHC_ERR_INVALID);
    CHECK(isnan(z) && isnan(p) && runs == 0);
    const double oneneg[6] = {1, 2, -3, 4, 5, 6};
    z = p = 0;
    CHECK(phc_check_runs(oneneg, 6, &z, &p, &runs) == PHC_ERR_INVALID);
    CHECK(isnan(z) && isnan(p));
    const double withnan[6] = {1, -2, NAN, 4, -5, 6};
    z = p = 0;
    CHECK(phc_check_runs(withnan, 6, &z, &p, &runs) == PHC_ERR_INVALID);
    CHECK(isnan(z) && isnan(p));
    const double cst[6] = {0.2, 0.2, 0.2, 0.2, 0.2, 0.2};
    CHECK(phc_check_runs(cst, 6, &z, &p, &runs) == PHC_ERR_INVALID);
    CHECK(phc_check_runs(cst, 0, &z, &p, &runs) == PHC_ERR_INVALID);
}

/* ---- time series: time-lag ACF, Lomb–Scargle, daily cycle ---- */

/* Fixed-seed uniform (0, 1) (64-bit LCG, Knuth's MMIX constants) and
 * Box–Muller normals: the same numbers on every machine. */
static unsigned long long lcg_state;
static double lcg_uniform(void)
{
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return ((double)(lcg_state >> 11) + 0.5) / 9007199254740992.0;
}
static double lcg_normal(void)
{
    const double u = lcg_uniform(), v = lcg_uniform();
    return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
}

#define NT 240

static void test_acf_time(void)
{
    double t[NT], r[NT], acf[49];
    size_t pairs[49];
    /* hourly for 10 days, a 24 h sinusoid: with the per-pair normalisation
     * rho(12 h) = -1 and rho(24 h) = +1 exactly (228 and 216 pairs span
     * whole half-periods of sin^2) */
    for (size_t i = 0; i < NT; ++i) {
        t[i] = (double)i;
        r[i] = sin(2.0 * M_PI * t[i] / 24.0);
    }
    CHECK(phc_check_acf_time(t, r, NT, 1.0, 49, acf, pairs) == PHC_OK);
    CHECK(acf[0] == 1.0 && pairs[0] == NT);
    CHECK_NEAR(acf[12], -1.0, 1e-12, 0);
    CHECK_NEAR(acf[24], 1.0, 1e-12, 0);
    CHECK_NEAR(acf[6], 0.0, 0.02, 0); /* 234 pairs: 19.5 periods of sin a cos a */
    CHECK(pairs[12] == NT - 12 && pairs[48] == NT - 48);
    CHECK_NEAR(phc_check_acf_time_bin(t, NT, 1.0), 1.0, 0, 1e-15);
    CHECK_NEAR(phc_check_acf_time_bin(t, NT, 2.5), 2.5, 0, 1e-15);

    /* regular sampling, bin = step: the ACF with 1/(n - h) normalisation,
     * i.e. phc_check_acf's (1/n) values times n/(n - h); the times given in
     * reverse order (the function sorts them) */
    double tr[N30], acf_n[8], acf_t[8];
    for (size_t i = 0; i < N30; ++i)
        tr[i] = 3.0 * (double)(N30 - 1 - i);
    double rr[N30];
    for (size_t i = 0; i < N30; ++i)
        rr[i] = res1[N30 - 1 - i];
    CHECK(phc_check_acf(res1, N30, 7, acf_n) == PHC_OK);
    CHECK(phc_check_acf_time(tr, rr, N30, 3.0, 8, acf_t, NULL) == PHC_OK);
    for (size_t h = 1; h < 8; ++h)
        CHECK_NEAR(acf_t[h], acf_n[h] * N30 / (double)(N30 - h), 1e-14, 1e-12);

    /* irregular times (fixed seed), 1 h bins: within a bin the lag varies by
     * +-0.5 h, so rho ~ cos(2 pi lag / 24) averaged over the bin (0.9986),
     * and the pairs of a bin weight the points unevenly (the mean of sin^2
     * over them differs from c0 by a few per cent): ~ -1 at 12 h, ~ +1 at
     * 24 h */
    lcg_state = 17;
    double ti[600], ri[600], acf_i[49];
    for (size_t i = 0; i < 600; ++i) {
        ti[i] = 240.0 * lcg_uniform();
        ri[i] = sin(2.0 * M_PI * ti[i] / 24.0);
    }
    CHECK(phc_check_acf_time(ti, ri, 600, 1.0, 49, acf_i, NULL) == PHC_OK);
    CHECK_NEAR(acf_i[12], -1.0, 0.07, 0);
    CHECK_NEAR(acf_i[24], 1.0, 0.07, 0);
    const double bin = phc_check_acf_time_bin(ti, 600, 1.0);
    CHECK(bin == 1.0); /* median interval 0.4 h < 1 h */

    /* limit cases: n < 3, constant residuals, no pair in a bin, bad bin */
    CHECK(phc_check_acf_time(t, r, 2, 1.0, 49, acf, NULL) == PHC_ERR_INVALID);
    CHECK(isnan(acf[0]) && isnan(acf[24]));
    const double cst[5] = {1, 1, 1, 1, 1}, t5[5] = {0, 1, 2, 3, 4};
    CHECK(phc_check_acf_time(t5, cst, 5, 1.0, 3, acf, NULL) == PHC_ERR_INVALID);
    CHECK(phc_check_acf_time(t, r, NT, 0.0, 3, acf, NULL) == PHC_ERR_INVALID);
    const double tg[4] = {0, 1, 100, 101}, rg[4] = {1, -1, 2, 0};
    CHECK(phc_check_acf_time(tg, rg, 4, 1.0, 49, acf, pairs) == PHC_OK); /* acf, pairs hold 49 */
    CHECK(pairs[1] == 2 && isnan(acf[2]) && pairs[2] == 0);
    CHECK(isnan(phc_check_acf_time_bin(cst, 5, 1.0))); /* one distinct time */
}

/* t_i = 0.37 i + 0.2 sin i (h), r_i = 0.4 sin(2 pi t_i / 24) + sin(7.3 i^2),
 * i < 200.  Reference: a direct transcription in Python 3.11 (math module
 * only) of Scargle's power (with tau from atan2) and of astropy's
 * fap_baluev (astropy/timeseries/periodograms/lombscargle/_statistics.py,
 * normalization "standard", dH = 1, dK = 3, W = (f_hi - f_lo) T_eff),
 * evaluated at the frequency this code found. */
static void test_lomb_scargle_reference(void)
{
    double t[200], r[200];
    for (size_t i = 0; i < 200; ++i) {
        t[i] = 0.37 * (double)i + 0.2 * sin((double)i);
        r[i] = 0.4 * sin(2.0 * M_PI * t[i] / 24.0) + sin(7.3 * (double)i * (double)i);
    }
    phc_periodogram_peak pk;
    CHECK(phc_check_periodogram_peak(t, r, 200, 1.0 / 60.0, 1.0 / 2.0, 5.0, &pk) == PHC_OK);
    /* the 24 h component is found (to within the grid: 1 / (5 T)) */
    CHECK_NEAR(pk.frequency, 1.0 / 24.0, 1.0 / (5.0 * 73.63), 0);
    /* power at the found frequency 0.040692184202909376: 0.12794185457963606
     * (Python); the refined peak is a maximum there (Python: no larger power
     * within +-2e-4 cycles/h) */
    CHECK_NEAR(pk.frequency, 0.040692184202909376, 0, 1e-9);
    CHECK_NEAR(pk.power, 0.12794185457963606, 0, 1e-12);
    double pw;
    CHECK(phc_check_lomb_scargle(t, r, 200, &pk.frequency, 1, &pw) == PHC_OK);
    CHECK_NEAR(pw, pk.power, 0, 1e-13);
    /* Baluev FAP (Python transcription of astropy): 0.0001953246767788222 */
    CHECK_NEAR(pk.fap, 0.0001953246767788222, 0, 1e-11);
    CHECK(pk.local_max);
}

static void test_lomb_scargle(void)
{
    double t[NT], r[NT];
    for (size_t i = 0; i < NT; ++i) {
        t[i] = 1e5 + (double)i; /* a large clock offset loses no digits */
        r[i] = 2.0 + sin(2.0 * M_PI * t[i] / 24.0 + 0.3);
    }
    /* regular sampling, Fourier frequencies: the sinusoid explains all of
     * the variance at 1/24 h and none at 1/12 h or 1/40 h */
    const double f[3] = {1.0 / 24.0, 1.0 / 12.0, 1.0 / 40.0};
    double pw[3];
    CHECK(phc_check_lomb_scargle(t, r, NT, f, 3, pw) == PHC_OK);
    CHECK_NEAR(pw[0], 1.0, 1e-12, 0);
    CHECK_NEAR(pw[1], 0.0, 1e-12, 0);
    CHECK_NEAR(pw[2], 0.0, 1e-12, 0);

    /* irregular times, a 17.3 h sinusoid plus a little noise: the highest
     * peak over periods 2 h .. 240 h is at its period, to within the grid
     * spacing (1 / (5 T) cycles per hour), and highly significant */
    lcg_state = 4242;
    double ti[300], ri[300];
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < 300; ++i) {
        ti[i] = 240.0 * lcg_uniform();
        ri[i] = sin(2.0 * M_PI * ti[i] / 17.3) + 0.1 * lcg_normal();
        lo = fmin(lo, ti[i]);
        hi = fmax(hi, ti[i]);
    }
    phc_periodogram_peak pk;
    CHECK(phc_check_periodogram_peak(ti, ri, 300, 1.0 / 240.0, 0.5, 5.0, &pk) == PHC_OK);
    const double df = 1.0 / (5.0 * (hi - lo));
    CHECK_NEAR(pk.frequency, 1.0 / 17.3, df, 0);
    CHECK_NEAR(pk.period, 17.3, 17.3 * 17.3 * df, 0);
    CHECK(pk.power > 0.95 && pk.fap < 1e-50 && pk.local_max);
    CHECK(pk.n_freq > 100);
    /* the refined peak is within 1e-3 h of the true period here */
    CHECK_NEAR(pk.period, 17.3, 1e-2, 0);

    /* Deterministic irregular case for an independent check of the power
     * and of Baluev's FAP: see test_lomb_scargle_reference. */
    /* white noise (fixed seed) at irregular times: no significant peak */
    lcg_state = 99;
    for (size_t i = 0; i < 300; ++i) {
        ti[i] = 240.0 * lcg_uniform();
        ri[i] = lcg_normal();
    }
    CHECK(phc_check_periodogram_peak(ti, ri, 300, 1.0 / 240.0, 0.5, 5.0, &pk) == PHC_OK);
    CHECK(pk.fap > 0.05 && pk.fap <= 1.0);
    printf("white noise: highest peak %.3f h, power %.4f, FAP %.3f\n", pk.period, pk.power, pk.fap);

    double s, p, per;
    /* daily cycle: the 24 h sinusoid hourly over 10 days */
    CHECK(phc_check_daily_cycle(t, r, NT, &s, &p, &per) == PHC_OK);
    CHECK_NEAR(per, 24.0, 1e-3, 0);
    CHECK_NEAR(s, 1.0, 1e-3, 0); /* the line in time removed first takes a little */
    CHECK(p < 1e-100);
    /* a weak daily cycle in noise is still found; white noise is not */
    lcg_state = 7;
    for (size_t i = 0; i < 300; ++i) {
        ti[i] = 120.0 * lcg_uniform();
        ri[i] = 0.5 * sin(2.0 * M_PI * (ti[i] - 14.0) / 24.0) + lcg_normal();
    }
    CHECK(phc_check_daily_cycle(ti, ri, 300, &s, &p, &per) == PHC_OK);
    CHECK(p < 1e-4 && fabs(per - 24.0) < 1.5);
    printf("weak daily cycle: period %.3f h, power %.4f, p %.3g\n", per, s, p);
    lcg_state = 99;
    for (size_t i = 0; i < 300; ++i) {
        ti[i] = 240.0 * lcg_uniform();
        ri[i] = lcg_normal();
    }
    CHECK(phc_check_daily_cycle(ti, ri, 300, &s, &p, &per) == PHC_OK);
    CHECK(p > 0.05);
    printf("white noise, daily test: period %.3f h, power %.4f, p %.3g\n", per, s, p);
    /* a slow drift over two days (an exponential decay left in the
     * residuals): after the line in time is removed, what is left reaches
     * into 22-26 h only as the flank of the low-frequency peak */
    double tl[48], rl[48];
    for (size_t i = 0; i < 48; ++i) {
        tl[i] = (double)i;
        rl[i] = exp(-(double)i / 15.0);
    }
    CHECK(phc_check_daily_cycle(tl, rl, 48, &s, &p, &per) == PHC_OK);
    printf("exponential drift over 48 h, daily test: period %.3f h, power %.4f, p %.3g\n", per, s, p);
    CHECK(p == 1.0);
    /* a slow cycle (period 10 days) over 10 days: the band holds only its
     * sidelobes (power ~ 1e-3), not significant */
    for (size_t i = 0; i < NT; ++i)
        r[i] = sin(2.0 * M_PI * (double)i / 240.0 + 1.0);
    CHECK(phc_check_daily_cycle(t, r, NT, &s, &p, &per) == PHC_OK);
    CHECK(p > 0.05);

    /* limit cases */
    CHECK(phc_check_daily_cycle(t, r, 2, &s, &p, &per) == PHC_ERR_INVALID);
    CHECK(isnan(s) && isnan(p) && isnan(per));
    CHECK(phc_check_daily_cycle(t, r, 30, &s, &p, &per) == PHC_ERR_INVALID); /* 29 h < 36 h */
    CHECK(isnan(s) && isnan(p) && isnan(per));
    CHECK(phc_check_daily_cycle(t, r, 37, &s, &p, NULL) == PHC_OK); /* 36 h: applicable */
    const double cst[6] = {3, 3, 3, 3, 3, 3}, t6[6] = {0, 10, 20, 30, 40, 50};
    CHECK(phc_check_daily_cycle(t6, cst, 6, &s, &p, &per) == PHC_ERR_INVALID);
    CHECK(phc_check_periodogram_peak(t, r, 4, 0.01, 0.1, 5.0, &pk) == PHC_ERR_INVALID);
    CHECK(isnan(pk.period) && isnan(pk.fap));
    CHECK(phc_check_periodogram_peak(t, r, NT, 0.1, 0.01, 5.0, &pk) == PHC_ERR_INVALID);
    CHECK(phc_check_lomb_scargle(t, r, 2, f, 3, pw) == PHC_ERR_INVALID);
    CHECK(isnan(pw[0]));
}

int main(void)
{
    test_shapiro_wilk();
    test_anderson_darling();
    test_durbin_watson();
    test_acf_ljung_box();
    test_breusch_pagan();
    test_runs();
    test_acf_time();
    test_lomb_scargle();
    test_lomb_scargle_reference();
    return check_finish("test_residual_checks");
}
