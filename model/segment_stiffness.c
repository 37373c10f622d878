/* Young's modulus per segment from the water state (segment_stiffness.h). */
#include "model/segment_stiffness.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define CM_PER_M 100.0

phc_segment_stiffness_params phc_segment_stiffness_params_default(void)
{
    phc_segment_stiffness_params p;
    p.law = PHC_STIFFNESS_WATER;
    p.content = PHC_STIFFNESS_RELATIVE;
    p.logistic.kappa = 20.0;
    p.logistic.chi0 = 0.7;
    p.logistic.e_min = 1e6;
    p.logistic.e_max = 1e9;
    p.e_base = 1e9;
    return p;
}

static const char *const law_names[] = {"water", "depth", "radius"};

int phc_stiffness_law_from_name(const char *name, phc_stiffness_law *law)
{
    for (size_t i = 0; name && i < sizeof law_names / sizeof law_names[0]; ++i)
        if (strcmp(name, law_names[i]) == 0) {
            *law = (phc_stiffness_law)i;
            return 0;
        }
    return -1;
}

const char *phc_stiffness_law_name(phc_stiffness_law law)
{
    return (unsigned)law < sizeof law_names / sizeof law_names[0] ? law_names[law] : "unknown";
}

int phc_stiffness_content_from_name(const char *name, phc_stiffness_water_content *content)
{
    if (name && strcmp(name, "relative") == 0) {
        *content = PHC_STIFFNESS_RELATIVE;
        return 0;
    }
    if (name && strcmp(name, "absolute") == 0) {
        *content = PHC_STIFFNESS_ABSOLUTE;
        return 0;
    }
    return -1;
}

double phc_segment_volume_cm3(const phc_plant_graph *g, size_t i)
{
    const double r = g->radius[i] * CM_PER_M, h = g->length[i] * CM_PER_M;
    return M_PI * r * r * h;
}

static int check_graph(const phc_plant_graph *g, phc_error *err)
{
    if (!g || g->n == 0 || !g->depth || !g->radius || !g->length || !g->parent)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "segment stiffness: the plant graph is missing or not finished");
    return PHC_OK;
}

static int check_base(double e_base, phc_error *err)
{
    if (!(e_base > 0) || !isfinite(e_base))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "segment stiffness: e_base must be positive and finite (Pa), found %g",
                             e_base);
    return PHC_OK;
}

int phc_segment_stiffness_check(const phc_segment_stiffness_params *p, phc_error *err)
{
    if (!p)
        return phc_error_set(err, PHC_ERR_INVALID, "segment stiffness: no parameters");
    switch (p->law) {
    case PHC_STIFFNESS_WATER:
        if (p->content != PHC_STIFFNESS_RELATIVE && p->content != PHC_STIFFNESS_ABSOLUTE)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "segment stiffness: water_content must be relative or absolute");
        if (!(p->logistic.kappa > 0) || !isfinite(p->logistic.kappa))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "segment stiffness: kappa must be positive and finite, found %g "
                                 "(kappa <= 0 would stiffen the plant as it dries)",
                                 p->logistic.kappa);
        if (!isfinite(p->logistic.chi0))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "segment stiffness: chi0 must be finite, found %g",
                                 p->logistic.chi0);
        if (!(p->logistic.e_min > 0) || !isfinite(p->logistic.e_min))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "segment stiffness: e_min must be positive and finite (Pa), "
                                 "found %g (a zero modulus has no bending stiffness)",
                                 p->logistic.e_min);
        if (!(p->logistic.e_max >= 0) || !isfinite(p->logistic.e_max))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "segment stiffness: e_max must be >= 0 and finite (Pa), found %g",
                                 p->logistic.e_max);
        return PHC_OK;
    case PHC_STIFFNESS_DEPTH:
    case PHC_STIFFNESS_RADIUS:
        return check_base(p->e_base, err);
    }
    return phc_error_set(err, PHC_ERR_INVALID, "segment stiffness: unknown law %d", (int)p->law);
}

static int check_theta(const phc_plant_graph *g, const double *theta, const char *what,
                       phc_error *err)
{
    if (!theta)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: no water state given", what);
    for (size_t i = 0; i < g->n; ++i)
        if (!isfinite(theta[i]))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: segment %ld: water must be finite, found %g", what,
                                 g->source_id ? g->source_id[i] : (long)i, theta[i]);
    return PHC_OK;
}

int phc_segment_stiffness_water(const phc_plant_graph *g, const phc_segment_stiffness_params *p,
                                const double *theta, double *E, double *dE_dparams,
                                double *dE_dtheta, phc_error *err)
{
    int rc;
    if ((rc = check_graph(g, err)) || (rc = phc_segment_stiffness_check(p, err)))
        return rc;
    if (p->law != PHC_STIFFNESS_WATER)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "segment stiffness: law '%s' given to the water mapping",
                             phc_stiffness_law_name(p->law));
    if ((rc = check_theta(g, theta, "segment stiffness", err)))
        return rc;
    for (size_t i = 0; i < g->n; ++i) {
        /* x_i = theta_i / V_i (relative) or theta_i (absolute); dx/dtheta accordingly */
        const double dx = p->content == PHC_STIFFNESS_RELATIVE ? 1.0 / phc_segment_volume_cm3(g, i)
                                                               : 1.0;
        const double x = theta[i] * dx;
        double dEdx;
        E[i] = phc_elasticity_eval(&p->logistic, x, dE_dparams ? dE_dparams + 4 * i : NULL,
                                   &dEdx);
        if (dE_dtheta)
            dE_dtheta[i] = dEdx * dx;
    }
    return PHC_OK;
}

int phc_segment_stiffness_depth(const phc_plant_graph *g, double e_base, double *E,
                                double *dE_dbase, phc_error *err)
{
    int rc;
    if ((rc = check_graph(g, err)) || (rc = check_base(e_base, err)))
        return rc;
    for (size_t i = 0; i < g->n; ++i) {
        const double f = 1.0 / (1.0 + (double)g->depth[i]); /* wilting Fig. 5 */
        E[i] = e_base * f;
        if (dE_dbase)
            dE_dbase[i] = f;
    }
    return PHC_OK;
}

int phc_segment_stiffness_radius(const phc_plant_graph *g, double e_base, double *E,
                                 double *dE_dbase, phc_error *err)
{
    int rc;
    double rmax = 0;
    if ((rc = check_graph(g, err)) || (rc = check_base(e_base, err)))
        return rc;
    for (size_t i = 0; i < g->n; ++i) {
        if (!(g->radius[i] > 0) || !isfinite(g->radius[i]))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "segment stiffness: segment %ld: radius must be positive and "
                                 "finite, found %g",
                                 g->source_id ? g->source_id[i] : (long)i, g->radius[i]);
        if (g->radius[i] > rmax)
            rmax = g->radius[i];
    }
    for (size_t i = 0; i < g->n; ++i) {
        const double f = g->radius[i] / rmax; /* wilting Fig. 5, thickest segment = E_base */
        E[i] = e_base * f;
        if (dE_dbase)
            dE_dbase[i] = f;
    }
    return PHC_OK;
}

int phc_segment_stiffness(const phc_plant_graph *g, const phc_segment_stiffness_params *p,
                          const double *theta, double *E, phc_error *err)
{
    int rc;
    if ((rc = phc_segment_stiffness_check(p, err)))
        return rc;
    switch (p->law) {
    case PHC_STIFFNESS_WATER:
        return phc_segment_stiffness_water(g, p, theta, E, NULL, NULL, err);
    case PHC_STIFFNESS_DEPTH:
        return phc_segment_stiffness_depth(g, p->e_base, E, NULL, err);
    case PHC_STIFFNESS_RADIUS:
        return phc_segment_stiffness_radius(g, p->e_base, E, NULL, err);
    }
    return phc_error_set(err, PHC_ERR_INVALID, "segment stiffness: unknown law %d", (int)p->law);
}

/* ---- the authors' demo ---------------------------------------------------- */

phc_stiffness_reference_params phc_stiffness_reference_default(void)
{
    /* Demos/Common/DemoBase.h:52-58 of filthynobleman/plant-wilting-simulation */
    phc_stiffness_reference_params p;
    p.e_min = 1.0;
    p.e_max = 1e10;
    p.steepness = 1e3;
    p.midpoint = 1.5e-2;
    p.density = 1.0;
    p.leaf_density = 2.0;
    p.mass_scale = 1e-3;
    p.use_latches = 0;
    return p;
}

static int check_reference(const phc_stiffness_reference_params *p, phc_error *err)
{
    if (!p)
        return phc_error_set(err, PHC_ERR_INVALID, "reference stiffness: no parameters");
    const double v[7] = {p->e_min, p->e_max, p->steepness, p->midpoint,
                         p->density, p->leaf_density, p->mass_scale};
    static const char *const names[7] = {"e_min",   "e_max",        "steepness", "midpoint",
                                         "density", "leaf_density", "mass_scale"};
    for (int k = 0; k < 7; ++k) {
        if (!isfinite(v[k]))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "reference stiffness: %s must be finite, found %g", names[k],
                                 v[k]);
        if (k != 3 && v[k] < 0)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "reference stiffness: %s must be >= 0, found %g", names[k], v[k]);
    }
    return PHC_OK;
}

int phc_stiffness_reference_joints(const phc_plant_graph *g,
                                   const phc_stiffness_reference_params *p, const double *theta,
                                   double *youngs, double *torsion, double *bending,
                                   double *twisting, double *radius, double *length,
                                   double *water, phc_error *err)
{
    int rc;
    if ((rc = check_graph(g, err)) || (rc = check_reference(p, err)))
        return rc;
    if (theta && (rc = check_theta(g, theta, "reference stiffness", err)))
        return rc;
    for (size_t c = 0; c < g->n; ++c) {
        const size_t nn = g->parent[c];
        double E = 0, G = 0, K = 0, rbar = 0, lbar = 0, w = 0;
        if (nn != PHC_PLANT_NO_PARENT) {
            /* PlantDemo.cpp:321-328, in their cm units */
            const double ln = g->length[nn] * CM_PER_M, lc = g->length[c] * CM_PER_M;
            const double rn = ln * (g->radius[nn] * CM_PER_M);
            const double rc_ = lc * (g->radius[nn] * CM_PER_M); /* parent's radius (quirk 3) */
            rbar = (rn * ln + rc_ * lc) / (ln + lc);
            lbar = 0.5 * (ln + lc);
            if (theta) {
                /* PlantDemo.cpp:226-230 */
                w = 0.5 * (theta[nn] + theta[c]);
                E = p->e_min + p->e_max / (1.0 + exp(-p->steepness * (w - p->midpoint)));
            } else {
                E = p->e_max; /* PlantDemo.cpp:339-340 */
            }
            G = E;                                  /* PlantDemo.cpp:231 */
            K = M_PI / 4.0 * pow(rbar, 4.0);        /* PlantDemo.cpp:232 */
        }
        if (youngs)
            youngs[c] = E;
        if (torsion)
            torsion[c] = G;
        if (bending)
            bending[c] = E * K;
        if (twisting)
            twisting[c] = 2.0 * G * K;
        if (radius)
            radius[c] = rbar;
        if (length)
            length[c] = lbar;
        if (water)
            water[c] = w;
    }
    return PHC_OK;
}

int phc_stiffness_reference_masses(const phc_plant_graph *g,
                                   const phc_stiffness_reference_params *p, const double *theta,
                                   int build, double *mass, phc_error *err)
{
    int rc;
    if ((rc = check_graph(g, err)) || (rc = check_reference(p, err)) ||
        (rc = check_theta(g, theta, "reference mass", err)))
        return rc;
    for (size_t i = 0; i < g->n; ++i) {
        const double V = phc_segment_volume_cm3(g, i);
        if (i == g->root) {
            mass[i] = 0.0; /* PlantDemo.cpp:208-209 and 297-298 */
        } else if (build) {
            mass[i] = p->density * V + theta[i]; /* PlantDemo.cpp:300 */
        } else if (p->use_latches && g->fixed && g->fixed[i]) {
            mass[i] = 0.0; /* PlantDemo.cpp:208 */
        } else {
            /* PlantDemo.cpp:201-207 */
            const double rho = g->leaf && g->leaf[i] ? p->leaf_density : p->density;
            mass[i] = (V * rho + theta[i]) * p->mass_scale;
        }
    }
    return PHC_OK;
}
