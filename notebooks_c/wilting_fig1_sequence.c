/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 1 style: a plant
 * at five times while it dries.
 *
 * The paper's setting: its teaser shows a plant wilting over time, the
 * water model advanced each frame and the position-based rods stepped with
 * the moduli of eq. 9 (absolute water, cm/g units, the authors' stiffness
 * scale, water time 500x mechanical time: model/segment_stiffness.h quirk 9).
 *
 * Ours (wilting_shape.h for the common setting): plant000, the water model
 * through time (BDF6, step 60 s) at the delta that leaves 55% of the water
 * after 8 h; frames at 0, 2, 4, 6, 8 h; at each frame theta/V per segment
 * -> E = 5e6 + 1e8 sigma(20 (theta/V - 0.8)) Pa -> static equilibrium with
 * the water's mass, each solve started from the previous frame's shape (the
 * water changes slowly against the plant's mechanics: hours against a
 * bending period of a fraction of a second, so a static equilibrium per
 * frame is what the plant shows).
 *
 * Prints per frame the water left, theta/V, the modulus, the height and the
 * solve time, and the height of the same frame solved from the rest shape
 * instead (large deflections can have more than one equilibrium; the
 * sequence follows the one reached from the previous frame).  Checks (exit 1 when one fails): the height decreases
 * strictly from frame to frame; static solves <= 20 s in all.
 * Writes wilting_fig1_sequence.png (five panels), one legacy VTK file per
 * frame (wilting_fig1_frame_K.vtk: the shape with the cell fields
 * relative_water and young_modulus_Pa, for ParaView or Blender) and
 * wilting_fig1_sequence.md.
 *
 * Usage: notebook_wilting_fig1_sequence OUTPUT_DIR */
#include "wilting_shape.h"

#include "notebook_plot.h"

#define NF 5
#define T_END (8.0 * 3600.0)

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, WS_PLANT, &out);
    if (started)
        return started;
    phc_error err;
    phc_error_clear(&err);
    phc_plant_graph *g = ws_read(WS_PLANT);
    phc_plant_graph *shape = g ? phc_plant_graph_copy(g) : NULL;
    if (!shape)
        return 1;
    size_t n = g->n;
    double times[NF];
    for (int k = 0; k < NF; ++k)
        times[k] = T_END * k / (NF - 1);
    double delta = ws_delta_for(g, 0.55, T_END);
    phc_water_params wp = ws_water_params(g, delta);
    double *theta = malloc(NF * n * sizeof *theta), *rwc[NF], *E[NF], *head[NF], *tail[NF];
    if (ws_water(g, &wp, times, NF, theta, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    phc_segment_stiffness_params sp = ws_stiffness(WS_KAPPA, WS_CHI0);
    phc_rod *rod = NULL;
    double height[NF], height_rest[NF], secs[NF], W[NF], lo[NF], hi[NF], total = 0.0;
    int its[NF];
    for (int k = 0; k < NF; ++k) {
        const double *th = theta + (size_t)k * n;
        rwc[k] = malloc(n * sizeof(double)), E[k] = malloc(n * sizeof(double));
        head[k] = malloc(3 * n * sizeof(double)), tail[k] = malloc(3 * n * sizeof(double));
        ws_rwc(g, th, rwc[k], &lo[k], &hi[k]);
        W[k] = 0;
        for (size_t i = 0; i < n; ++i)
            W[k] += th[i];
        if (phc_segment_stiffness_water(g, &sp, th, E[k], NULL, NULL, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        if (!rod && !(rod = ws_rod(g, E[k], &err))) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        secs[k] = 0.0;
        if (ws_solve(rod, E[k], th, &secs[k], &its[k], &err) != PHC_OK) {
            fprintf(stderr, "frame %d (t = %g h): %s\n", k, times[k] / 3600.0, err.message);
            return 1;
        }
        total += secs[k];
        height[k] = ws_shape(rod, head[k], tail[k]);
        /* the same frame solved from the rest shape (large deflections may
         * have more than one equilibrium: the sequence follows one branch) */
        phc_rod *fresh = ws_rod(g, E[k], &err);
        double rest_secs = 0.0;
        if (!fresh || ws_solve(fresh, E[k], th, &rest_secs, NULL, &err) != PHC_OK) {
            fprintf(stderr, "frame %d from rest: %s\n", k, err.message);
            return 1;
        }
        total += rest_secs;
        double *h2 = malloc(6 * n * sizeof *h2);
        height_rest[k] = ws_shape(fresh, h2, h2 + 3 * n);
        free(h2);
        phc_rod_free(fresh);
        /* the frame as VTK: the graph with the current shape and two fields */
        memcpy(shape->head, head[k], 3 * n * sizeof(double));
        memcpy(shape->tail, tail[k], 3 * n * sizeof(double));
        phc_plant_field fields[2] = {{"relative_water", rwc[k]}, {"young_modulus_Pa", E[k]}};
        char vtk[1024], vtitle[128];
        snprintf(vtk, sizeof vtk, "%s/wilting_fig1_frame_%d.vtk", out, k);
        snprintf(vtitle, sizeof vtitle, "phytocal plant000 wilting, t = %g h", times[k] / 3600.0);
        if (phc_plant_io_write_vtk(vtk, shape, vtitle, fields, 2, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
    }

    printf("plant000: %zu segments, rest height %.4f m; delta %.4e 1/(cm^2 s), W0 %.4f g\n", n,
           g->tail[3 * ws_highest(g) + 2], delta, wp.initial_water);
    printf("%-6s %10s %22s %12s %10s %10s %5s %17s\n", "t (h)", "water (g)", "theta/V (min..max)", "E (Pa)", "height",
           "solve s", "its", "height from rest");
    int ok_mono = 1;
    for (int k = 0; k < NF; ++k) {
        printf("%-6.0f %10.4f   %.6f..%.6f %12.4e %10.4f %10.3f %5d %17.4f\n", times[k] / 3600.0, W[k], lo[k], hi[k],
               E[k][0], height[k], secs[k], its[k], height_rest[k]);
        if (k > 0)
            ok_mono &= height[k] < height[k - 1];
    }
    int ok_time = total <= 20.0;
    printf("height decreases strictly with time: %s\n", ok_mono ? "yes" : "no");
    printf("static solves: %d (sequence and from rest) in %.3f s (bound 20 s); VTK frames wilting_fig1_frame_0..%d.vtk\n",
           2 * NF, total, NF - 1);

    phc_shape_panel pan[NF];
    char title[NF][64];
    for (int k = 0; k < NF; ++k) {
        snprintf(title[k], sizeof title[k], "t = %.0f h: %.1f cm", times[k] / 3600.0, 100.0 * height[k]);
        pan[k] = (phc_shape_panel){n, head[k], tail[k], g->radius, rwc[k], title[k], 0, NULL, NULL};
    }
    phc_shape_plot_options po = phc_shape_plot_options_default();
    po.title = "Fig. 1 style: plant000 drying, static equilibrium at each frame";
    po.columns = NF;
    po.value_min = 0.5, po.value_max = 1.0;
    char png[1024];
    snprintf(png, sizeof png, "%s/wilting_fig1_sequence.png", out);
    if (phc_shape_plot(png, pan, NF, &po, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig1_sequence.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Wilting paper, Fig. 1 style: a time sequence\n\n"
               "plant000 drying over 8 h (settings in the program's header); VTK frames "
               "`wilting_fig1_frame_0.vtk` .. `_%d.vtk`.\n\n"
               "![sequence](wilting_fig1_sequence.png)\n\n"
               "| t (h) | water (g) | theta/V | E (Pa) | height (m) |\n|---:|---:|---:|---:|---:|\n",
            NF - 1);
    for (int k = 0; k < NF; ++k)
        fprintf(f, "| %.0f | %.4f | %.4f | %.4e | %.4f |\n", times[k] / 3600.0, W[k], lo[k], E[k][0], height[k]);
    fprintf(f, "\nChecks: height decreases with time %s; solves %.3f s %s.\n", ok_mono ? "(pass)" : "(**FAIL**)", total,
            ok_time ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    for (int k = 0; k < NF; ++k)
        free(rwc[k]), free(E[k]), free(head[k]), free(tail[k]);
    phc_rod_free(rod);
    free(theta);
    phc_plant_graph_free(shape);
    phc_plant_graph_free(g);
    int fail = !(ok_mono && ok_time);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
