/* Climbing plants (Hädrich, Benes, Deussen, Pirk, CGF 36(2) 2017, §4.2,
 * eq. 7): a shoot under an opaque plate with a gap, seeking the light.
 *
 * The scene (the same as tests/unit/test_climbing_light_field.c, part 3):
 * a horizontal plate at z = 0.4 m over x ∈ [−0.6, 0.6] m, y ∈ [−0.4, 0.4] m
 * with a gap x ∈ [0.2, 0.3] m, given as four triangles through the C API
 * (phc_climbing_set_shadow_triangles: it blocks the direct light; it is not
 * a collider here, so a shoot that reaches it is drawn through it).  Light
 * from above, ℓ = (0, 0, 1), ambient share 0.5, light grid of 0.05 m cells
 * over x ∈ [−0.45, 0.5], y ∈ [−0.3, 0.3], z ∈ [−0.05, 0.5] m.  One seed at
 * the origin growing up, no branching, r = 0.5 s⁻¹, η = 0.2 s⁻¹, 1500
 * kinematic steps of 0.1 s (150 s), grown twice:
 *   fixed:      phototropism toward ℓ (eq. 7 as in the paper);
 *   seek_light: toward the gradient of the light field
 *               (model/climbing_light_field.h).
 * Prints, for each shoot, where its final polyline first crosses the
 * plate's height z = 0.4 m, whether that point lies in the gap or on the
 * plate, its distance to the gap centre (0.25, 0, 0.4) m, and the final
 * tip; exit 1 when the seeking shoot does not cross in the gap or the fixed
 * one does not cross on the plate (the claim of the README's "Phototropism
 * toward where the light is").
 *
 * Writes climbing_seek_light.png (side view x–z of both shoots and the
 * plate) and climbing_seek_light.md.
 *
 * Usage: notebook_climbing_seek_light OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/climbing_growth.h"
#include "notebook_plot.h"

#define STEPS 1500
#define DT 0.1
#define PLATE_Z 0.4
#define GAP_X0 0.2
#define GAP_X1 0.3
#define PLATE_HALF_Y 0.4

/* The plate: two rectangles either side of the gap, four triangles (m). */
static const double PLATE_V[8 * 3] = {-0.6, -0.4, 0.4, 0.2, -0.4, 0.4, 0.2, 0.4, 0.4, -0.6, 0.4, 0.4,
                                      0.3,  -0.4, 0.4, 0.6, -0.4, 0.4, 0.6, 0.4, 0.4, 0.3,  0.4, 0.4};
static const size_t PLATE_T[4 * 3] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};

typedef struct shoot {
    size_t n;          /* particles */
    double *x, *y, *z; /* n + 1 polyline points: the seed's base, then every particle's tip (m) */
    double cross[3];   /* first crossing of z = PLATE_Z along the polyline (NAN: none), m */
    double gap_dist;   /* |cross − gap centre|, m */
    int in_gap;        /* the crossing lies in the gap */
} shoot;

static int grow(int seek, shoot *s)
{
    phc_climbing_options o = phc_climbing_options_default();
    o.branch_probability = 0;
    o.growth_rate = 0.5;
    o.phototropism = 0.2;
    o.seek_light = seek;
    o.light.cell = 0.05;
    o.light.origin[0] = -0.45;
    o.light.origin[1] = -0.3;
    o.light.origin[2] = -0.05;
    o.light.dims[0] = 19;
    o.light.dims[1] = 12;
    o.light.dims[2] = 11;
    o.light.ambient = 0.5;
    const double seed[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    phc_error err;
    phc_climbing *c = phc_climbing_new(seed, up, &o, &err);
    if (!c || phc_climbing_set_shadow_triangles(c, PLATE_V, 8, PLATE_T, 4, &err)) {
        fprintf(stderr, "%s\n", err.message);
        phc_climbing_free(c);
        return -1;
    }
    for (int k = 0; k < STEPS; ++k)
        if (phc_climbing_step(c, DT, &err)) {
            fprintf(stderr, "%s\n", err.message);
            phc_climbing_free(c);
            return -1;
        }
    const size_t n = phc_climbing_count(c);
    s->n = n;
    s->x = malloc((n + 1) * sizeof *s->x);
    s->y = malloc((n + 1) * sizeof *s->y);
    s->z = malloc((n + 1) * sizeof *s->z);
    if (!s->x || !s->y || !s->z) {
        phc_climbing_free(c);
        return -1;
    }
    /* no branching: particle i's parent is i − 1, so base of 0 then the tips */
    for (size_t i = 0; i < n; ++i) {
        if (i > 0 && phc_climbing_parent(c, i) != i - 1) {
            fprintf(stderr, "particle %zu: parent %zu, expected a single chain\n", i, phc_climbing_parent(c, i));
            phc_climbing_free(c);
            return -1;
        }
        double b[3], t[3];
        phc_climbing_segment(c, i, b, t);
        if (i == 0)
            s->x[0] = b[0], s->y[0] = b[1], s->z[0] = b[2];
        s->x[i + 1] = t[0], s->y[i + 1] = t[1], s->z[i + 1] = t[2];
    }
    phc_climbing_free(c);
    s->cross[0] = s->cross[1] = s->cross[2] = NAN;
    for (size_t k = 0; k < n; ++k)
        if (s->z[k] < PLATE_Z && s->z[k + 1] >= PLATE_Z) {
            const double u = (PLATE_Z - s->z[k]) / (s->z[k + 1] - s->z[k]);
            s->cross[0] = s->x[k] + u * (s->x[k + 1] - s->x[k]);
            s->cross[1] = s->y[k] + u * (s->y[k + 1] - s->y[k]);
            s->cross[2] = PLATE_Z;
            break;
        }
    const double gx = 0.5 * (GAP_X0 + GAP_X1);
    s->gap_dist = hypot(s->cross[0] - gx, s->cross[1]);
    s->in_gap = s->cross[0] >= GAP_X0 && s->cross[0] <= GAP_X1 && fabs(s->cross[1]) <= PLATE_HALF_Y;
    return 0;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started)
        return started;
    shoot sh[2];
    memset(sh, 0, sizeof sh);
    if (grow(0, &sh[0]) || grow(1, &sh[1]))
        return 1;
    const char *name[2] = {"fixed direction", "seek_light"};
    printf("a shoot under a plate at z = %.2f m with a gap at x in [%.2f, %.2f] m, light from above, %d steps of "
           "%.2f s:\n",
           PLATE_Z, GAP_X0, GAP_X1, STEPS, DT);
    for (int k = 0; k < 2; ++k) {
        const shoot *s = &sh[k];
        printf("  %-15s %3zu particles, crosses z = %.2f m at (%.4f, %.4f) m: %s, %.4f m from the gap centre; "
               "tip (%.4f, %.4f, %.4f) m\n",
               name[k], s->n, PLATE_Z, s->cross[0], s->cross[1], isnan(s->cross[0]) ? "never"
                                                                 : s->in_gap          ? "in the gap"
                                                                                      : "on the plate",
               s->gap_dist, s->x[s->n], s->y[s->n], s->z[s->n]);
    }
    const int seek_ok = sh[1].in_gap, fixed_blocked = !isnan(sh[0].cross[0]) && !sh[0].in_gap;
    printf("check: the seeking shoot passes through the gap: %s\n", seek_ok ? "pass" : "FAIL");
    printf("check: the fixed-direction shoot meets the plate: %s\n", fixed_blocked ? "pass" : "FAIL");

    /* side view x–z: both shoots, the plate's two parts, the gap's centre */
    const double pl_x[2][2] = {{-0.45, GAP_X0}, {GAP_X1, 0.5}}, pl_z[2] = {PLATE_Z, PLATE_Z};
    const double gc_x[1] = {0.5 * (GAP_X0 + GAP_X1)}, gc_z[1] = {PLATE_Z};
    char fixed_label[96];
    snprintf(fixed_label, sizeof fixed_label, "fixed light direction (eq. 7; on to z = %.2f m)", sh[0].z[sh[0].n]);
    nb_series ser[6] = {
        {sh[0].x, sh[0].z, sh[0].n + 1, fixed_label, NB_BLUE, 1, 0, 3},
        {sh[1].x, sh[1].z, sh[1].n + 1, "seek_light (gradient of the light field)", NB_GREEN, 0, 0, 3},
        {pl_x[0], pl_z, 2, "opaque plate (shades only)", NB_BLACK, 0, 0, 7},
        {pl_x[1], pl_z, 2, NULL, NB_BLACK, 0, 0, 7},
        {gc_x, gc_z, 1, "gap centre", NB_RED, 0, 1, 0},
        {sh[1].cross, sh[1].cross + 2, 1, "seek_light crosses the plate's height", NB_ORANGE, 0, 1, 0},
    };
    const nb_panel pan = {"A shoot below a plate with a gap, light from above (side view)",
                          "x (m)", "z (m)", 0, -0.02, 0.85, 2, ser, 6};
    char png[1024];
    snprintf(png, sizeof png, "%s/climbing_seek_light.png", out);
    if (nb_plot(png, 1000, 900, 1, 1, &pan, 1)) {
        fprintf(stderr, "%s: cannot write the figure\n", png);
        return 1;
    }
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "climbing_seek_light.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f,
            "# Climbing plants: a shoot seeking the light through a gap\n\n"
            "**The claim** (Hädrich et al., CGF 2017, §4.2: growth toward where the light is): a shoot\n"
            "in the shade of an obstacle turns toward the light that comes through a gap.\n\n"
            "**What we computed** (`model/climbing_growth.h`, `model/climbing_light_field.h`): an opaque\n"
            "plate at z = 0.4 m with a gap at x ∈ [0.2, 0.3] m, light from above; one unbranched shoot\n"
            "grown 150 s with phototropism η = 0.2 /s toward the fixed light direction and toward the\n"
            "gradient of the light field (`seek_light`). The plate shades only (no collisions).\n\n"
            "![side view](climbing_seek_light.png)\n\n"
            "| shoot | particles | crosses z = 0.4 m at x (m) | where | distance to the gap centre (m) |\n"
            "|---|---|---|---|---|\n");
    for (int k = 0; k < 2; ++k)
        fprintf(f, "| %s | %zu | %.4f | %s | %.4f |\n", name[k], sh[k].n, sh[k].cross[0],
                sh[k].in_gap ? "gap" : "plate", sh[k].gap_dist);
    fprintf(f, "\n**Checks**: the seeking shoot passes through the gap: %s; the fixed one meets the plate: %s.\n",
            seek_ok ? "pass" : "FAIL", fixed_blocked ? "pass" : "FAIL");
    if (nb_close_md(f, md, mdtmp)) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    printf("wrote climbing_seek_light.png and climbing_seek_light.md\n");
    for (int k = 0; k < 2; ++k) {
        free(sh[k].x);
        free(sh[k].y);
        free(sh[k].z);
    }
    return seek_ok && fixed_blocked ? 0 : 1;
}
