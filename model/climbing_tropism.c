/* Tropisms (climbing plants eqs. 6–10): see model/climbing_tropism.h. */
#include "model/climbing_tropism.h"

#include <math.h>

static void cross(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double phc_climbing_angle(const double a[3], const double b[3])
{
    double c[3];
    cross(a, b, c);
    return atan2(sqrt(dot(c, c)), dot(a, b));
}

/* Rodrigues: v ← v cos β + (k × v) sin β + k (k·v)(1 − cos β), |k| = 1,
 * given c = cos β and s = sin β; then v is renormalised. */
static void rotate(double v[3], const double k[3], double c, double s)
{
    double kv[3];
    cross(k, v, kv);
    const double kd = dot(k, v) * (1 - c);
    for (int i = 0; i < 3; ++i)
        v[i] = v[i] * c + kv[i] * s + k[i] * kd;
    const double len = sqrt(dot(v, v));
    for (int i = 0; i < 3; ++i)
        v[i] /= len;
}

double phc_climbing_turn(double d[3], double rest[3], const double t[3], double fraction)
{
    if (!(fraction > 0))
        return 0;
    if (fraction > 1)
        fraction = 1;
    /* the angle as phc_climbing_angle(d, t) computes it, from the same
       cross product that gives the axis */
    double k[3];
    cross(d, t, k);
    double len = sqrt(dot(k, k));
    const double alpha = atan2(len, dot(d, t));
    if (!(alpha > 0))
        return 0;
    if (len < 1e-12) { /* t opposite to d: any axis perpendicular to d */
        int m = 0;
        for (int i = 1; i < 3; ++i)
            if (fabs(d[i]) < fabs(d[m]))
                m = i;
        const double e[3] = {m == 0, m == 1, m == 2};
        cross(d, e, k);
        len = sqrt(dot(k, k));
    }
    for (int i = 0; i < 3; ++i)
        k[i] /= len;
    const double beta = fraction * alpha;
    const double c = cos(beta), s = sin(beta); /* one evaluation for both vectors */
    rotate(d, k, c, s);
    if (rest)
        rotate(rest, k, c, s);
    return beta;
}

int phc_climbing_surface_target(const double x[3], const double c[3], const double nf[3],
                                const double d[3], double contact, double t[3])
{
    double n[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
    const double delta = sqrt(dot(n, n));
    if (delta > 0) {
        for (int i = 0; i < 3; ++i)
            n[i] /= delta;
    } else {
        const double ln = sqrt(dot(nf, nf));
        if (!(ln > 0))
            return 0;
        for (int i = 0; i < 3; ++i)
            n[i] = nf[i] / ln;
    }
    if (delta > contact) {
        for (int i = 0; i < 3; ++i)
            t[i] = -n[i];
        return 1;
    }
    const double dn = dot(d, n);
    for (int i = 0; i < 3; ++i)
        t[i] = d[i] - dn * n[i];
    const double len = sqrt(dot(t, t));
    if (len < 1e-12)
        return 0;
    for (int i = 0; i < 3; ++i)
        t[i] /= len;
    return 1;
}
