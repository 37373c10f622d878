/* Pressure–volume curve analysis: see pressure_volume.h. */
#include "model/pressure_volume.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

phc_pv_options phc_pv_options_default(void)
{
    phc_pv_options o = {PHC_PV_BREAK_MIN_RSS, 3, 0, PHC_PV_TLP_FITTED, PHC_PV_MODULUS_ABOVE_BREAK,
                        PHC_PV_CUT_REGION_START};
    return o;
}

phc_pv_options phc_pv_options_photosynthesis(void)
{
    phc_pv_options o = {PHC_PV_BREAK_MAX_R2, 3, 0, PHC_PV_TLP_MEASURED, PHC_PV_MODULUS_SHARED_BREAK,
                        PHC_PV_CUT_PHOTOSYNTHESIS};
    return o;
}

const char *phc_pv_warning_text(unsigned bit)
{
    switch (bit) {
    case PHC_PV_WARN_NOT_MONOTONE:
        return "water potential rises while RWC falls between consecutive points (measurement noise or re-hydration)";
    case PHC_PV_WARN_APOPLAST_RANGE:
        return "apoplastic fraction outside [0, 1): the osmotic line's x-intercept is not physical";
    case PHC_PV_WARN_TLP_OUTSIDE:
        return "turgor loss point outside the measured RWC range";
    case PHC_PV_WARN_EPSILON:
        return "bulk modulus not positive: turgor does not fall with RWC above the breakpoint";
    case PHC_PV_WARN_OSMOTIC_LINE:
        return "osmotic line -1/psi vs RWC has no physical osmotic potential (slope or value at RWC 1 not positive)";
    case PHC_PV_WARN_RWC_ABOVE_ONE:
        return "RWC above 1.05 at some point: saturated mass too low or dry mass too high?";
    default:
        return "";
    }
}

double phc_pv_rwc(double fresh, double dry, double saturated)
{
    if (!(saturated > dry))
        return NAN;
    return (fresh - dry) / (saturated - dry);
}

/* Ordinary least squares y = p0 + p1 x over idx[0..m-1] (centred sums for
 * accuracy).  inv (2x2, row-major) = (XᵀX)⁻¹.  Returns 0, or 1 when x has no
 * spread. */
typedef struct ols_fit {
    double p0, p1, inv[4], rss, r2;
} ols_fit;

static int ols(const double *x, const double *y, const size_t *idx, size_t m, ols_fit *f)
{
    double mx = 0, my = 0;
    for (size_t i = 0; i < m; ++i) {
        mx += x[idx[i]];
        my += y[idx[i]];
    }
    mx /= (double)m;
    my /= (double)m;
    double sxx = 0, sxy = 0, syy = 0;
    for (size_t i = 0; i < m; ++i) {
        const double dx = x[idx[i]] - mx, dy = y[idx[i]] - my;
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    if (!(sxx > 0))
        return 1;
    f->p1 = sxy / sxx;
    f->p0 = my - f->p1 * mx;
    f->rss = 0;
    for (size_t i = 0; i < m; ++i) {
        const double r = y[idx[i]] - f->p0 - f->p1 * x[idx[i]];
        f->rss += r * r;
    }
    f->r2 = syy > 0 ? 1.0 - f->rss / syy : 1.0;
    /* (XᵀX)⁻¹ with X = [1 x]: [[1/m + mx²/sxx, −mx/sxx], [−mx/sxx, 1/sxx]] */
    f->inv[0] = 1.0 / (double)m + mx * mx / sxx;
    f->inv[1] = f->inv[2] = -mx / sxx;
    f->inv[3] = 1.0 / sxx;
    return 0;
}

int phc_pv_extrapolate_saturation(const double *psi, const double *water, size_t n,
                                  double *water_sat, double *stderr_, size_t *used,
                                  phc_error *err)
{
    if (n < 3)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "saturated mass by extrapolation needs at least 3 points, found %zu", n);
    size_t *idx = malloc(n * sizeof *idx);
    if (!idx)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n; ++i)
        idx[i] = i;
    /* wettest first: ψ closest to zero (stable insertion sort; n is small) */
    for (size_t i = 1; i < n; ++i)
        for (size_t j = i; j > 0 && psi[idx[j]] > psi[idx[j - 1]]; --j) {
            size_t t = idx[j];
            idx[j] = idx[j - 1];
            idx[j - 1] = t;
        }
    ols_fit best = {0}, f;
    size_t kbest = 0;
    for (size_t k = 3; k <= 5 && k <= n; ++k) {
        if (ols(water, psi, idx, k, &f))
            continue;
        if (kbest == 0 || f.r2 > best.r2) {
            best = f;
            kbest = k;
        }
    }
    free(idx);
    if (kbest == 0 || !(best.p1 > 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "saturated mass by extrapolation: water potential does not rise with leaf water "
                             "over the wettest points (slope %g MPa per mass unit)", kbest ? best.p1 : NAN);
    /* ψ = p0 + p1·w = 0 at w = −p0/p1 */
    const double ws = -best.p0 / best.p1;
    const double g0 = -1.0 / best.p1, g1 = best.p0 / (best.p1 * best.p1);
    const double s2 = kbest > 2 ? best.rss / (double)(kbest - 2) : NAN;
    const double var = s2 * (g0 * g0 * best.inv[0] + 2 * g0 * g1 * best.inv[1] + g1 * g1 * best.inv[3]);
    *water_sat = ws;
    *stderr_ = var >= 0 ? sqrt(var) : NAN;
    *used = kbest;
    return PHC_OK;
}

void phc_pv_result_free(phc_pv_result *r)
{
    if (!r)
        return;
    free(r->order);
    free(r->rwc);
    free(r->psi);
    free(r->inv_psi);
    free(r->osmotic);
    free(r->turgor);
    free(r->modulus_rwc);
    free(r->modulus);
    free(r);
}

/* Everything that depends on the split: the two regressions, P, the joint
 * covariance and the ψ-space RSS.  m driest points are osmotic. */
typedef struct split_fit {
    ols_fit osm, tur;
    double cov[16];
    double rss_psi;
    int ok;
} split_fit;

/* m driest points osmotic; the turgor line over the k wettest points (k =
 * n − m above the break; more with a shared break). */
static void fit_split(phc_pv_result *r, size_t m, size_t k, size_t *idx, split_fit *s)
{
    const size_t n = r->n;
    memset(s, 0, sizeof *s);
    for (size_t i = 0; i < m; ++i)
        idx[i] = n - m + i;
    if (ols(r->rwc, r->inv_psi, idx, m, &s->osm))
        return;
    const double a = s->osm.p0, b = s->osm.p1;
    for (size_t i = 0; i < n; ++i) {
        const double L = a + b * r->rwc[i];
        r->osmotic[i] = -1.0 / L;
        r->turgor[i] = r->psi[i] - r->osmotic[i];
    }
    for (size_t i = 0; i < k; ++i)
        idx[i] = i;
    if (ols(r->rwc, r->turgor, idx, k, &s->tur))
        return;
    s->rss_psi = s->tur.rss;
    for (size_t i = n - m; i < n; ++i)
        s->rss_psi += r->turgor[i] * r->turgor[i];

    /* Covariances.  (c, e) = H P with H = (X_TᵀX_T)⁻¹X_Tᵀ and
     * ∂P_i/∂(a, b) = (−1/L_i², −x_i/L_i²), so G = H ∂P/∂(a, b) carries the
     * osmotic line's uncertainty into (c, e). */
    const double s2o = m > 2 ? s->osm.rss / (double)(m - 2) : NAN;
    const double s2t = k > 2 ? s->tur.rss / (double)(k - 2) : NAN;
    double cab[4];
    for (int q = 0; q < 4; ++q)
        cab[q] = s2o * s->osm.inv[q];
    double G[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < k; ++i) {
        const double x = r->rwc[i], L = a + b * x;
        const double h0 = s->tur.inv[0] + s->tur.inv[1] * x; /* row 0 of H, column i */
        const double h1 = s->tur.inv[2] + s->tur.inv[3] * x;
        const double da = -1.0 / (L * L), db = -x / (L * L);
        G[0] += h0 * da;
        G[1] += h0 * db;
        G[2] += h1 * da;
        G[3] += h1 * db;
    }
    double GC[4], GCGt[4];
    GC[0] = G[0] * cab[0] + G[1] * cab[2];
    GC[1] = G[0] * cab[1] + G[1] * cab[3];
    GC[2] = G[2] * cab[0] + G[3] * cab[2];
    GC[3] = G[2] * cab[1] + G[3] * cab[3];
    GCGt[0] = GC[0] * G[0] + GC[1] * G[1];
    GCGt[1] = GC[0] * G[2] + GC[1] * G[3];
    GCGt[2] = GC[2] * G[0] + GC[3] * G[1];
    GCGt[3] = GC[2] * G[2] + GC[3] * G[3];
    double *C = s->cov;
    C[0 * 4 + 0] = cab[0];
    C[0 * 4 + 1] = cab[1];
    C[1 * 4 + 0] = cab[2];
    C[1 * 4 + 1] = cab[3];
    C[2 * 4 + 2] = s2t * s->tur.inv[0] + GCGt[0];
    C[2 * 4 + 3] = s2t * s->tur.inv[1] + GCGt[1];
    C[3 * 4 + 2] = s2t * s->tur.inv[2] + GCGt[2];
    C[3 * 4 + 3] = s2t * s->tur.inv[3] + GCGt[3];
    /* Cov((c, e), (a, b)) = G Cov(a, b) */
    C[2 * 4 + 0] = C[0 * 4 + 2] = GC[0];
    C[2 * 4 + 1] = C[1 * 4 + 2] = GC[1];
    C[3 * 4 + 0] = C[0 * 4 + 3] = GC[2];
    C[3 * 4 + 1] = C[1 * 4 + 3] = GC[3];
    s->ok = isfinite(s->rss_psi);
}

static phc_pv_estimate delta(const double *cov, const double g[4], double value)
{
    double v = 0;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            v += g[i] * cov[i * 4 + j] * g[j];
    phc_pv_estimate e = {value, v >= 0 ? sqrt(v) : NAN};
    return e;
}

int phc_pv_analyse(const double *psi, const double *rwc, size_t n, const phc_pv_options *options,
                   phc_pv_result **out, phc_error *err)
{
    phc_pv_options opt = options ? *options : phc_pv_options_default();
    phc_pv_result *r = NULL;
    size_t *idx = NULL;
    int rc = PHC_OK;
    *out = NULL;
    if (opt.min_points < 3)
        return phc_error_set(err, PHC_ERR_INVALID, "pressure-volume analysis: min_points must be at least 3, found %zu",
                             opt.min_points);
    if (n < 2 * opt.min_points)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "pressure-volume analysis needs at least %zu points (%zu on each side of the turgor loss "
                             "point), found %zu", 2 * opt.min_points, opt.min_points, n);
    if (opt.rule == PHC_PV_BREAK_FIXED && (opt.n_osmotic < opt.min_points || n - opt.n_osmotic < opt.min_points))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "pressure-volume analysis: %zu osmotic points leave fewer than %zu on one side of %zu",
                             opt.n_osmotic, opt.min_points, n);
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(psi[i]) || !isfinite(rwc[i]))
            return phc_error_set(err, PHC_ERR_INPUT, "point %zu: water potential and RWC must be finite", i);
        if (!(psi[i] < 0))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "point %zu: water potential must be negative (MPa), found %g", i, psi[i]);
        if (!(rwc[i] > 0))
            return phc_error_set(err, PHC_ERR_INPUT, "point %zu: RWC must be positive, found %g", i, rwc[i]);
    }

    r = calloc(1, sizeof *r);
    idx = malloc(n * sizeof *idx);
    if (!r || !idx)
        goto nomem;
    r->n = n;
    r->n_modulus = n - 1;
    if (!(r->order = malloc(n * sizeof *r->order)) || !(r->rwc = malloc(n * sizeof *r->rwc)) ||
        !(r->psi = malloc(n * sizeof *r->psi)) || !(r->inv_psi = malloc(n * sizeof *r->inv_psi)) ||
        !(r->osmotic = malloc(n * sizeof *r->osmotic)) || !(r->turgor = malloc(n * sizeof *r->turgor)) ||
        !(r->modulus_rwc = malloc((n - 1) * sizeof *r->modulus_rwc)) ||
        !(r->modulus = malloc((n - 1) * sizeof *r->modulus)))
        goto nomem;
    for (size_t i = 0; i < n; ++i)
        r->order[i] = i;
    for (size_t i = 1; i < n; ++i) /* wettest first, stable */
        for (size_t j = i; j > 0 && rwc[r->order[j]] > rwc[r->order[j - 1]]; --j) {
            size_t t = r->order[j];
            r->order[j] = r->order[j - 1];
            r->order[j - 1] = t;
        }
    for (size_t i = 0; i < n; ++i) {
        r->rwc[i] = rwc[r->order[i]];
        r->psi[i] = psi[r->order[i]];
        r->inv_psi[i] = -1.0 / r->psi[i];
        if (i > 0 && r->rwc[i] == r->rwc[i - 1]) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "points %zu and %zu have the same RWC (%g)",
                               r->order[i - 1], r->order[i], r->rwc[i]);
            goto fail;
        }
        if (i > 0 && r->psi[i] > r->psi[i - 1])
            r->warnings |= PHC_PV_WARN_NOT_MONOTONE;
        if (r->rwc[i] > 1.05)
            r->warnings |= PHC_PV_WARN_RWC_ABOVE_ONE;
    }

    /* The breakpoint: m, the size of the osmotic region. */
    size_t m_lo = opt.min_points, m_hi = n - opt.min_points, m_best = 0;
    if (opt.rule == PHC_PV_BREAK_FIXED)
        m_lo = m_hi = opt.n_osmotic;
    if (opt.rule == PHC_PV_BREAK_MAX_R2) { /* photosynthesis: i in 3:(n − 2), rows (n − i):n */
        m_lo = 4;
        m_hi = n - 1;
    }
    split_fit s, best;
    memset(&best, 0, sizeof best);
    double crit_best = 0;
    for (size_t m = m_lo; m <= m_hi; ++m) {
        if (opt.rule == PHC_PV_BREAK_MAX_R2) { /* the osmotic line alone decides; ties: the
                                                  larger region, as the package's loop keeps
                                                  the last maximum */
            ols_fit f;
            for (size_t i = 0; i < m; ++i)
                idx[i] = n - m + i;
            if (ols(r->rwc, r->inv_psi, idx, m, &f))
                continue;
            if (m_best == 0 || -f.r2 <= crit_best) {
                crit_best = -f.r2;
                m_best = m;
            }
            continue;
        }
        fit_split(r, m, n - m, idx, &s);
        if (!s.ok)
            continue;
        if (m_best == 0 || s.rss_psi < crit_best) {
            crit_best = s.rss_psi;
            m_best = m;
        }
    }
    if (m_best == 0) {
        rc = phc_error_set(err, PHC_ERR_NUMERIC, "pressure-volume analysis: no split gives usable regressions");
        goto fail;
    }
    /* The cut and the turgor points (the conventions). */
    r->cut = opt.cut == PHC_PV_CUT_PHOTOSYNTHESIS ? m_best - 2 : n - m_best;
    const size_t k_turgor = opt.modulus_points == PHC_PV_MODULUS_SHARED_BREAK ? r->cut + 1 : n - m_best;
    if (k_turgor < 3) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "pressure-volume analysis: %zu point%s for the turgor line (the bulk modulus) with an "
                           "osmotic region of %zu of %zu points; at least 3 are needed",
                           k_turgor, k_turgor == 1 ? "" : "s", m_best, n);
        goto fail;
    }
    fit_split(r, m_best, k_turgor, idx, &best); /* leaves osmotic[] and turgor[] of the chosen split */
    if (!best.ok) {
        rc = phc_error_set(err, PHC_ERR_NUMERIC, "pressure-volume analysis: the chosen split gives no usable regressions");
        goto fail;
    }
    r->n_osmotic = m_best;
    r->n_turgor = n - m_best;
    const double a = best.osm.p0, b = best.osm.p1, c = best.tur.p0, e = best.tur.p1;
    r->coef[0] = a;
    r->coef[1] = b;
    r->coef[2] = c;
    r->coef[3] = e;
    memcpy(r->cov, best.cov, sizeof r->cov);
    r->rss_osmotic = best.osm.rss;
    r->r2_osmotic = best.osm.r2;
    r->rss_turgor = best.tur.rss;
    r->rss_psi = best.rss_psi;

    /* Derived parameters, delta method (gradients in the order a, b, c, e). */
    const double L1 = a + b;
    {
        double g[4] = {1.0 / (L1 * L1), 1.0 / (L1 * L1), 0, 0};
        r->pi_o = delta(r->cov, g, -1.0 / L1);
    }
    {
        double g[4] = {-1.0 / b, a / (b * b), 0, 0};
        r->apoplastic_fraction = delta(r->cov, g, -a / b);
    }
    const double xt = opt.tlp == PHC_PV_TLP_MEASURED ? r->rwc[r->cut] : -c / e;
    if (opt.tlp == PHC_PV_TLP_MEASURED) { /* a measured point: no standard error */
        r->rwc_tlp = (phc_pv_estimate){r->rwc[r->cut], NAN};
        r->psi_tlp = (phc_pv_estimate){r->psi[r->cut], NAN};
    } else {
        {
            double g[4] = {0, 0, -1.0 / e, c / (e * e)};
            r->rwc_tlp = delta(r->cov, g, xt);
        }
        {
            const double Lt = a + b * xt, f = 1.0 / (Lt * Lt);
            double g[4] = {f, f * xt, f * b * (-1.0 / e), f * b * c / (e * e)};
            r->psi_tlp = delta(r->cov, g, -1.0 / Lt);
        }
    }
    /* Capacitances: slopes of RWC on ψ above and below the cut (both include it). */
    {
        ols_fit f;
        for (size_t i = 0; i <= r->cut; ++i)
            idx[i] = i;
        r->capacitance_ft = (phc_pv_estimate){NAN, NAN};
        r->capacitance_tlp = (phc_pv_estimate){NAN, NAN};
        if (r->cut + 1 >= 2 && !ols(r->psi, r->rwc, idx, r->cut + 1, &f))
            r->capacitance_ft = (phc_pv_estimate){f.p1, r->cut + 1 > 2 ? sqrt(f.rss / (double)(r->cut - 1) * f.inv[3]) : NAN};
        const size_t mt = n - r->cut;
        for (size_t i = 0; i < mt; ++i)
            idx[i] = r->cut + i;
        if (mt >= 2 && !ols(r->psi, r->rwc, idx, mt, &f))
            r->capacitance_tlp = (phc_pv_estimate){f.p1, mt > 2 ? sqrt(f.rss / (double)(mt - 2) * f.inv[3]) : NAN};
    }
    {
        double g[4] = {0, 0, 0, 1};
        r->epsilon = delta(r->cov, g, e);
    }
    {
        double g[4] = {e / b, -e * a / (b * b), 0, 1.0 + a / b};
        r->epsilon_sym = delta(r->cov, g, e * (1.0 + a / b));
    }
    if (!(b > 0) || !(L1 > 0))
        r->warnings |= PHC_PV_WARN_OSMOTIC_LINE;
    if (!(r->apoplastic_fraction.value >= 0 && r->apoplastic_fraction.value < 1))
        r->warnings |= PHC_PV_WARN_APOPLAST_RANGE;
    if (!(xt >= r->rwc[n - 1] && xt <= r->rwc[0]))
        r->warnings |= PHC_PV_WARN_TLP_OUTSIDE;
    if (!(e > 0))
        r->warnings |= PHC_PV_WARN_EPSILON;

    /* Pointwise modulus series: ΔP/ΔRWC between consecutive points. */
    for (size_t i = 0; i + 1 < n; ++i) {
        r->modulus_rwc[i] = 0.5 * (r->rwc[i] + r->rwc[i + 1]);
        r->modulus[i] = (r->turgor[i] - r->turgor[i + 1]) / (r->rwc[i] - r->rwc[i + 1]);
    }
    free(idx);
    *out = r;
    return PHC_OK;
nomem:
    rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
fail:
    free(idx);
    phc_pv_result_free(r);
    return rc;
}
