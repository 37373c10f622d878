/* Secondary growth by the pipe model: see model/climbing_cambium.h. */
#include "model/climbing_cambium.h"

#include <math.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

void phc_climbing_pipe_targets(size_t n, const size_t *parent, const double *r,
                               const double *r0, const unsigned char *leaf, double a_leaf,
                               unsigned char *has_child, double *target)
{
    memset(has_child, 0, n);
    for (size_t i = 0; i < n; ++i)
        target[i] = 0;
    for (size_t i = 0; i < n; ++i)
        if (parent[i] != (size_t)-1) {
            target[parent[i]] += PI * r[i] * r[i];
            has_child[parent[i]] = 1;
        }
    for (size_t i = 0; i < n; ++i) {
        if (!has_child[i])
            target[i] = PI * r0[i] * r0[i];
        if (leaf && leaf[i])
            target[i] += a_leaf;
    }
}

double phc_climbing_cambium_step(double r, double target_area, double kappa, double dt)
{
    const double rs = sqrt(target_area / PI);
    if (!(rs > r))
        return r;
    return r + -expm1(-kappa * dt) * (rs - r);
}
