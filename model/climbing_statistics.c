/* Summary statistics of a climbing plant: see climbing_statistics.h. */
#include "model/climbing_statistics.h"

#include <math.h>
#include <string.h>

#define PHC_STAT_PI 3.14159265358979323846

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

static int finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

int phc_climbing_summarize_segments(const phc_shoot_segment *seg, size_t n,
                                    const phc_climbing_stat_options *o, phc_climbing_summary *s,
                                    phc_error *err)
{
    if (!o || !s || (n && !seg))
        return phc_error_set(err, PHC_ERR_INVALID, "climbing statistics: NULL argument");
    const double ln = norm3(o->light);
    if (!(ln > 0) || !isfinite(ln))
        return phc_error_set(err, PHC_ERR_INVALID, "climbing statistics: the light direction is zero or not finite");
    memset(s, 0, sizeof *s);
    const double l[3] = {o->light[0] / ln, o->light[1] / ln, o->light[2] / ln};
    double attached = 0, cosine = 0, zmax = o->origin[2];
    for (size_t i = 0; i < n; ++i) {
        const phc_shoot_segment *g = &seg[i];
        if (!finite3(g->base) || !finite3(g->tip))
            return phc_error_set(err, PHC_ERR_INVALID, "climbing statistics: segment %zu is not finite", i);
        const double d[3] = {g->tip[0] - g->base[0], g->tip[1] - g->base[1], g->tip[2] - g->base[2]};
        const double len = norm3(d);
        s->total_length += len;
        if (g->order == 0) s->main_length += len;
        zmax = fmax(zmax, fmax(g->base[2], g->tip[2]));
        if (len > 0) cosine += (d[0] * l[0] + d[1] * l[1] + d[2] * l[2]);
        if (o->closest && len > 0) {
            const double mid[3] = {0.5 * (g->base[0] + g->tip[0]), 0.5 * (g->base[1] + g->tip[1]),
                                   0.5 * (g->base[2] + g->tip[2])};
            double c[3], nn[3];
            if (!o->closest(o->closest_user, mid, c, nn)) {
                const double e[3] = {mid[0] - c[0], mid[1] - c[1], mid[2] - c[2]};
                if (norm3(e) <= o->attach_distance) attached += len;
            }
        }
        if (g->lateral_start) {
            if (g->order < PHC_CLIMBING_STAT_ORDERS && g->order > 0) s->shoots[g->order] += 1;
            const double pn = norm3(g->parent_dir);
            if (len > 0 && pn > 0 && isfinite(pn)) {
                double c = (d[0] * g->parent_dir[0] + d[1] * g->parent_dir[1] + d[2] * g->parent_dir[2]) /
                           (len * pn);
                c = c > 1 ? 1 : c < -1 ? -1 : c;
                const double th = acos(c) * 180.0 / PHC_STAT_PI;
                s->angle_n++;
                s->angle_sum += th;
                s->angle_sum2 += th * th;
            }
        }
    }
    s->height = zmax - o->origin[2];
    if (s->total_length > 0) {
        s->attached_fraction = attached / s->total_length;
        s->light_cosine = cosine / s->total_length;
    }
    if (s->angle_n) {
        s->angle_mean = s->angle_sum / (double)s->angle_n;
        const double v = s->angle_sum2 / (double)s->angle_n - s->angle_mean * s->angle_mean;
        s->angle_sd = sqrt(v > 0 ? v : 0);
    } else {
        s->angle_mean = s->angle_sd = NAN;
    }
    return PHC_OK;
}

void phc_climbing_segments(const phc_climbing *c, phc_shoot_segment *seg)
{
    const size_t n = phc_climbing_count(c);
    for (size_t i = 0; i < n; ++i) {
        phc_shoot_segment *g = &seg[i];
        memset(g, 0, sizeof *g);
        phc_climbing_segment(c, i, g->base, g->tip);
        g->order = phc_climbing_order(c, i);
        const size_t p = phc_climbing_parent(c, i);
        if (p != PHC_CLIMBING_NONE && phc_climbing_is_lateral(c, i)) {
            g->lateral_start = 1;
            phc_climbing_direction(c, p, g->parent_dir);
        }
    }
}

void phc_climbing_summary_mean(const phc_climbing_summary *s, size_t m, phc_climbing_summary *mean)
{
    memset(mean, 0, sizeof *mean);
    if (!m) {
        mean->angle_mean = mean->angle_sd = NAN;
        return;
    }
    for (size_t a = 0; a < m; ++a) {
        mean->total_length += s[a].total_length;
        mean->main_length += s[a].main_length;
        mean->height += s[a].height;
        mean->attached_fraction += s[a].attached_fraction;
        mean->light_cosine += s[a].light_cosine;
        for (size_t k = 0; k < PHC_CLIMBING_STAT_ORDERS; ++k) mean->shoots[k] += s[a].shoots[k];
        mean->angle_n += s[a].angle_n;
        mean->angle_sum += s[a].angle_sum;
        mean->angle_sum2 += s[a].angle_sum2;
    }
    const double w = 1.0 / (double)m;
    mean->total_length *= w;
    mean->main_length *= w;
    mean->height *= w;
    mean->attached_fraction *= w;
    mean->light_cosine *= w;
    for (size_t k = 0; k < PHC_CLIMBING_STAT_ORDERS; ++k) mean->shoots[k] *= w;
    if (mean->angle_n) {
        mean->angle_mean = mean->angle_sum / (double)mean->angle_n;
        const double v = mean->angle_sum2 / (double)mean->angle_n - mean->angle_mean * mean->angle_mean;
        mean->angle_sd = sqrt(v > 0 ? v : 0);
    } else {
        mean->angle_mean = mean->angle_sd = NAN;
    }
}
