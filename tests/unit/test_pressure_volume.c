/* Pressure–volume analysis (model/pressure_volume.h).  A synthetic curve from
 * known π_o, ε, apoplastic fraction and RWC_tlp (Boyle–van 't Hoff osmotic
 * potential π = π_o(1 − a_f)/(RWC − a_f), turgor P = ε(RWC − RWC_tlp) above the
 * tlp) must give them back: exactly without noise (and the breakpoint at the
 * true tlp), within its standard errors with noise, and the standard errors
 * must match the Monte-Carlo spread of the estimates. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "model/pressure_volume.h"

enum { N = 11 };
static const double PI_O = -1.5, AF = 0.2, EPS = 10.0, RWC_TLP = 0.88;
static const double RWC[N] = {1.0, 0.98, 0.96, 0.94, 0.92, 0.90, 0.86, 0.82, 0.78, 0.74, 0.70};

static double true_psi(double rwc)
{
    const double pi = PI_O * (1 - AF) / (rwc - AF);
    return pi + (rwc > RWC_TLP ? EPS * (rwc - RWC_TLP) : 0.0);
}

/* Gaussian noise from a fixed-seed generator (xorshift64 + Box–Muller). */
static uint64_t rng_state = 20261121;
static double uniform(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return ((double)(rng_state >> 11) + 0.5) / 9007199254740992.0;
}
static double gauss(void)
{
    return sqrt(-2 * log(uniform())) * cos(6.283185307179586 * uniform());
}

int main(void)
{
    double psi[N];
    phc_error err;
    phc_pv_result *r = NULL;
    for (int i = 0; i < N; ++i)
        psi[i] = true_psi(RWC[i]);
    const double psi_tlp = PI_O * (1 - AF) / (RWC_TLP - AF);

    /* noise-free: exact recovery, the breakpoint at the 5 points below the tlp */
    CHECK(phc_pv_analyse(psi, RWC, N, NULL, &r, &err) == PHC_OK);
    if (r) {
        CHECK(r->n_osmotic == 5 && r->n_turgor == 6);
        CHECK_NEAR(r->pi_o.value, PI_O, 1e-10, 0);
        CHECK_NEAR(r->apoplastic_fraction.value, AF, 1e-10, 0);
        CHECK_NEAR(r->epsilon.value, EPS, 1e-8, 0);
        CHECK_NEAR(r->epsilon_sym.value, EPS * (1 - AF), 1e-8, 0);
        CHECK_NEAR(r->rwc_tlp.value, RWC_TLP, 1e-10, 0);
        CHECK_NEAR(r->psi_tlp.value, psi_tlp, 1e-10, 0);
        CHECK(r->rss_psi < 1e-20);
        CHECK(r->warnings == 0);
        CHECK(r->n_modulus == N - 1);
        /* pointwise moduli: ε between turgor points, 0 between osmotic points */
        CHECK_NEAR(r->modulus[0], EPS, 1e-8, 0);
        CHECK_NEAR(r->modulus[N - 2], 0.0, 1e-8, 0);
        CHECK_NEAR(r->modulus_rwc[0], 0.99, 1e-15, 0);
    }
    phc_pv_result_free(r);

    /* input order does not matter: reversed input, same answer, order[] maps back */
    {
        double p2[N], r2[N];
        for (int i = 0; i < N; ++i) {
            p2[i] = psi[N - 1 - i];
            r2[i] = RWC[N - 1 - i];
        }
        CHECK(phc_pv_analyse(p2, r2, N, NULL, &r, &err) == PHC_OK);
        if (r) {
            CHECK_NEAR(r->pi_o.value, PI_O, 1e-10, 0);
            CHECK(r->order[0] == N - 1 && r->rwc[0] == 1.0);
        }
        phc_pv_result_free(r);
    }

    /* fixed breakpoints: the wrong split gives a worse ψ-space RSS */
    {
        phc_pv_options o = phc_pv_options_default();
        o.rule = PHC_PV_BREAK_FIXED;
        o.n_osmotic = 6;
        CHECK(phc_pv_analyse(psi, RWC, N, &o, &r, &err) == PHC_OK);
        if (r) {
            CHECK(r->n_osmotic == 6);
            CHECK(r->rss_psi > 1e-6);
        }
        phc_pv_result_free(r);
        o.n_osmotic = 9; /* leaves 2 turgor points */
        CHECK(phc_pv_analyse(psi, RWC, N, &o, &r, &err) == PHC_ERR_INVALID);
    }

    /* noisy: within 3 standard errors; SEs agree with the Monte-Carlo spread */
    {
        const double sd = 0.02; /* MPa, a good pressure chamber */
        const int reps = 2000;
        double s_pi = 0, s2_pi = 0, se_pi = 0, s_eps = 0, s2_eps = 0, se_eps = 0, s_af = 0, s2_af = 0, se_af = 0;
        double s_tlp = 0, s2_tlp = 0, se_tlp = 0;
        int ok = 0, right_break = 0;
        for (int k = 0; k < reps; ++k) {
            double pn[N];
            for (int i = 0; i < N; ++i)
                pn[i] = psi[i] + sd * gauss();
            if (phc_pv_analyse(pn, RWC, N, NULL, &r, &err) != PHC_OK)
                continue;
            ++ok;
            right_break += r->n_osmotic == 5;
            s_pi += r->pi_o.value;
            s2_pi += r->pi_o.value * r->pi_o.value;
            se_pi += r->pi_o.stderr_;
            s_eps += r->epsilon.value;
            s2_eps += r->epsilon.value * r->epsilon.value;
            se_eps += r->epsilon.stderr_;
            s_af += r->apoplastic_fraction.value;
            s2_af += r->apoplastic_fraction.value * r->apoplastic_fraction.value;
            se_af += r->apoplastic_fraction.stderr_;
            s_tlp += r->psi_tlp.value;
            s2_tlp += r->psi_tlp.value * r->psi_tlp.value;
            se_tlp += r->psi_tlp.stderr_;
            if (k == 0) {
                CHECK(fabs(r->pi_o.value - PI_O) < 3 * r->pi_o.stderr_);
                CHECK(fabs(r->epsilon.value - EPS) < 3 * r->epsilon.stderr_);
                CHECK(fabs(r->apoplastic_fraction.value - AF) < 3 * r->apoplastic_fraction.stderr_);
                CHECK(fabs(r->rwc_tlp.value - RWC_TLP) < 3 * r->rwc_tlp.stderr_);
                CHECK(fabs(r->psi_tlp.value - psi_tlp) < 3 * r->psi_tlp.stderr_);
            }
            phc_pv_result_free(r);
        }
        CHECK(ok == reps);
        const double m_pi = s_pi / ok, sd_pi = sqrt(s2_pi / ok - m_pi * m_pi);
        const double m_eps = s_eps / ok, sd_eps = sqrt(s2_eps / ok - m_eps * m_eps);
        const double m_af = s_af / ok, sd_af = sqrt(s2_af / ok - m_af * m_af);
        const double m_tlp = s_tlp / ok, sd_tlp = sqrt(s2_tlp / ok - m_tlp * m_tlp);
        printf("noise sd %.3f MPa, %d curves; breakpoint right in %.1f%%\n", sd, ok, 100.0 * right_break / ok);
        printf("  pi_o:  mean %.4f (true %.4f), MC sd %.4f, mean SE %.4f\n", m_pi, PI_O, sd_pi, se_pi / ok);
        printf("  eps:   mean %.3f (true %.3f), MC sd %.3f, mean SE %.3f\n", m_eps, EPS, sd_eps, se_eps / ok);
        printf("  a_f:   mean %.4f (true %.4f), MC sd %.4f, mean SE %.4f\n", m_af, AF, sd_af, se_af / ok);
        printf("  psi_tlp: mean %.4f (true %.4f), MC sd %.4f, mean SE %.4f\n", m_tlp, psi_tlp, sd_tlp, se_tlp / ok);
        CHECK(right_break > 0.8 * ok);
        CHECK_NEAR(m_pi, PI_O, 0.01, 0);
        CHECK_NEAR(m_af, AF, 0.01, 0);
        CHECK_NEAR(m_eps, EPS, 0.4, 0);
        /* the delta-method SEs describe the real spread (within 35%: small
         * samples, the breakpoint search and the mean of SEs all bias a bit) */
        CHECK(se_pi / ok > 0.65 * sd_pi && se_pi / ok < 1.35 * sd_pi);
        CHECK(se_af / ok > 0.65 * sd_af && se_af / ok < 1.35 * sd_af);
        CHECK(se_eps / ok > 0.65 * sd_eps && se_eps / ok < 1.35 * sd_eps);
        CHECK(se_tlp / ok > 0.65 * sd_tlp && se_tlp / ok < 1.35 * sd_tlp);
    }

    /* bad input */
    {
        double p[N], w[N];
        for (int i = 0; i < N; ++i)
            p[i] = psi[i];
        p[3] = 0.1;
        CHECK(phc_pv_analyse(p, RWC, N, NULL, &r, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "point 3");
        CHECK(r == NULL);
        CHECK(phc_pv_analyse(psi, RWC, 5, NULL, &r, &err) == PHC_ERR_INPUT);
        CHECK(phc_pv_analyse(psi, RWC, 1, NULL, &r, &err) == PHC_ERR_INPUT);
        for (int i = 0; i < N; ++i)
            w[i] = RWC[i];
        w[4] = w[3];
        CHECK(phc_pv_analyse(psi, w, N, NULL, &r, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "same RWC");
        p[3] = NAN;
        CHECK(phc_pv_analyse(p, RWC, N, NULL, &r, &err) == PHC_ERR_INPUT);
    }

    /* saturated water by extrapolation: exact on linear data, k = 3..5 */
    {
        const double water[6] = {1.25, 1.2, 1.15, 1.1, 1.0, 0.9};
        double p[6];
        for (int i = 0; i < 6; ++i)
            p[i] = 2.0 * (water[i] - 1.3) - (i >= 5 ? 0.5 : 0); /* the 6th leaves the line */
        double ws, se;
        size_t k;
        CHECK(phc_pv_extrapolate_saturation(p, water, 6, &ws, &se, &k, &err) == PHC_OK);
        CHECK_NEAR(ws, 1.3, 1e-12, 0);
        CHECK(k >= 3 && k <= 5);
        CHECK(phc_pv_extrapolate_saturation(p, water, 2, &ws, &se, &k, &err) == PHC_ERR_INPUT);
        CHECK_NEAR(phc_pv_rwc(3.0, 0.5, 3.0), 1.0, 0, 0);
        CHECK(isnan(phc_pv_rwc(3.0, 0.5, 0.5)));
    }
    return check_finish("unit/pressure_volume");
}
