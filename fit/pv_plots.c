/* The classic pressure–volume plot: see pv_plots.h. */
#include "fit/pv_plots.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "fit/plots.h"

/* Points of the fitted curve per leaf. */
#define PV_CURVE_POINTS 120

/* −1/ψ̂ of the two-part model at RWC r: the osmotic line a + b r below the
 * turgor loss point, −1/(π + P̂) above it (NAN where ψ̂ >= 0). */
static double pv_model(const phc_pv_result *res, double r, double rwc_tlp)
{
    const double a = res->coef[0], b = res->coef[1], c = res->coef[2], e = res->coef[3];
    const double inv_pi = a + b * r;
    if (!(r > rwc_tlp))
        return inv_pi;
    const double psi = -1.0 / inv_pi + c + e * r;
    return psi < 0 ? -1.0 / psi : NAN;
}

int phc_pv_plot_write(const char *name, const phc_pv_result *const *res, const char *const *labels, size_t count,
                      const char *dir, const char *base, phc_error *err)
{
    if (!count)
        return phc_error_set(err, PHC_ERR_INVALID, "pressure-volume plot: no leaves");
    /* per leaf: data (x, y), the model curve, the dashed extension (2
     * points) and the turgor loss point (1 point) */
    size_t n_pts = 0;
    for (size_t L = 0; L < count; ++L)
        n_pts += res[L]->n;
    double *buf = malloc(2 * (n_pts + count * (PV_CURVE_POINTS + 3)) * sizeof *buf);
    phc_plot_layer *layers = calloc(4 * count + 4, sizeof *layers);
    char path[8192], title[512];
    int rc;
    if (!buf || !layers) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    size_t nl = 0;
    /* the key: what the marks mean */
    layers[nl++] = (phc_plot_layer){PHC_MARK_DOTS, PHC_COLOUR_REF, NULL, NULL, 0, NULL, "measured"};
    layers[nl++] = (phc_plot_layer){PHC_MARK_LINE, PHC_COLOUR_REF, NULL, NULL, 0, NULL,
                                    "fit: \xcf\x88 = \xcf\x80 + P"};
    layers[nl++] = (phc_plot_layer){PHC_MARK_DASHED, PHC_COLOUR_REF, NULL, NULL, 0, NULL,
                                    "osmotic line to RWC = 1"};
    layers[nl++] = (phc_plot_layer){PHC_MARK_DIAMONDS, PHC_COLOUR_REF, NULL, NULL, 0, NULL,
                                    "turgor loss point"};
    double *p = buf;
    for (size_t L = 0; L < count; ++L) {
        const phc_pv_result *r = res[L];
        const double a = r->coef[0], b = r->coef[1], tlp = r->rwc_tlp.value;
        double *dx = p, *dy = p + r->n;
        p += 2 * r->n;
        for (size_t i = 0; i < r->n; ++i) {
            dx[i] = 1.0 - r->rwc[i];
            dy[i] = r->inv_psi[i];
        }
        layers[nl++] = (phc_plot_layer){PHC_MARK_DOTS, (int)L, dx, dy, r->n, NULL, NULL};
        /* the model from the wettest to the driest point */
        double *cx = p, *cy = p + PV_CURVE_POINTS;
        p += 2 * PV_CURVE_POINTS;
        const double wet = r->rwc[0], dry = r->rwc[r->n - 1];
        for (size_t j = 0; j < PV_CURVE_POINTS; ++j) {
            const double rwc = wet + (dry - wet) * (double)j / (PV_CURVE_POINTS - 1);
            cx[j] = 1.0 - rwc;
            cy[j] = pv_model(r, rwc, tlp);
        }
        layers[nl++] = (phc_plot_layer){PHC_MARK_LINE, (int)L, cx, cy, PV_CURVE_POINTS, NULL, NULL};
        if (isfinite(tlp) && tlp > 0) {
            /* the osmotic line from the turgor loss point back to RWC = 1 */
            double *ex = p, *ey = p + 2, *tx = p + 4, *ty = p + 5;
            p += 6;
            ex[0] = 0.0;
            ey[0] = a + b;
            ex[1] = 1.0 - tlp;
            ey[1] = a + b * tlp;
            tx[0] = ex[1];
            ty[0] = ey[1];
            layers[nl++] = (phc_plot_layer){PHC_MARK_DASHED, (int)L, ex, ey, 2, NULL, NULL};
            layers[nl++] = (phc_plot_layer){PHC_MARK_DIAMONDS, (int)L, tx, ty, 1, NULL, NULL};
        }
    }
    snprintf(path, sizeof path, "%s/%s_pv_curve.png", dir, base);
    snprintf(title, sizeof title, "%s: pressure\xe2\x80\x93volume curves", name);
    const phc_plot_labels lab = {title, "relative water deficit 1 \xe2\x88\x92 RWC",
                                 "\xe2\x88\x92" "1/\xcf\x88 (MPa\xe2\x81\xbb\xc2\xb9)", NULL};
    const phc_plot_groups groups = {count, NULL, labels, "leaf"};
    rc = phc_plot_layers(path, &lab, layers, nl, &groups, err);
done:
    free(buf);
    free(layers);
    return rc;
}
