/* Files describing a grown plant: see growth_outputs.h. */
#include "fit/growth_outputs.h"

#include <math.h>
#include <plplot.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/plot_file.h"
#include "measurements/plant_io.h"
#include "measurements/rsml.h"

int phc_growth_write_rsml(const phc_growth *g, const char *path, phc_error *err)
{
    size_t n = 0, *first = NULL, *parent = NULL;
    const phc_growth_node *node = phc_growth_nodes(g, &n);
    size_t nb = phc_growth_branches(g, PHC_GROWTH_ROOT, &first, &parent);
    phc_rsml *r = phc_rsml_new("m", 3);
    size_t *rsml_of = malloc((nb ? nb : 1) * sizeof *rsml_of);
    double *xyz = malloc(3 * (n + 1) * sizeof *xyz), *dia = malloc((n + 1) * sizeof *dia);
    int rc = PHC_OK;
    if (!r || !rsml_of || !xyz || !dia || (nb == 0 && n > 0)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    if ((rc = phc_rsml_add_plant(r, "plant", NULL, err))) goto done;
    for (size_t b = 0; b < nb; ++b) {
        size_t m = 0, i = first[b];
        memcpy(xyz, node[i].head, 3 * sizeof *xyz);
        dia[m++] = 2 * node[i].radius;
        for (; i != PHC_GROWTH_NONE; i = node[i].apical_child) {
            if (!(node[i].length > 0)) continue;
            for (int k = 0; k < 3; ++k) xyz[3 * m + k] = node[i].head[k] + node[i].length * node[i].dir[k];
            dia[m++] = 2 * node[i].radius;
        }
        size_t pb = parent[b] != PHC_GROWTH_NONE ? rsml_of[parent[b]] : PHC_RSML_NO_PARENT;
        if (m < 2) { /* a bud that has not grown yet */
            rsml_of[b] = pb;
            continue;
        }
        char id[32];
        snprintf(id, sizeof id, "root%zu", b + 1);
        if ((rc = phc_rsml_add_root(r, 0, pb, id, m, xyz, dia, &rsml_of[b], err))) goto done;
    }
    rc = phc_rsml_write(r, path, err);
done:
    phc_rsml_free(r);
    free(rsml_of);
    free(xyz);
    free(dia);
    free(first);
    free(parent);
    return rc;
}

int phc_growth_write_plant_graph(const phc_growth *g, const char *path, phc_error *err)
{
    phc_plant_graph *pg = phc_growth_plant_graph(g, err);
    if (!pg) return err ? err->status : PHC_ERR_INVALID;
    int rc = phc_plant_io_write_native(path, pg, err);
    phc_plant_graph_free(pg);
    return rc;
}

/* ---- side view ------------------------------------------------------------------- */

enum { COL_BG = 0, COL_FG, COL_SHOOT, COL_ROOT, COL_SOIL, COL_COUNT };

int phc_growth_plot_side(const char *path, const phc_growth *const *plants,
                         const char *const *titles, size_t n, double soil_top, double box_x0,
                         double box_x1, phc_error *err)
{
    if (!path || !plants || n == 0 || n > 6)
        return phc_error_set(err, PHC_ERR_INVALID, "growth side view: 1 to 6 plants needed");
    /* one common frame: every plant's extent */
    double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY;
    for (size_t p = 0; p < n; ++p) {
        size_t m = 0;
        const phc_growth_node *nd = phc_growth_nodes(plants[p], &m);
        for (size_t i = 0; i < m; ++i)
            for (int e = 0; e < 2; ++e) {
                double x = nd[i].head[0] + e * nd[i].length * nd[i].dir[0];
                double z = nd[i].head[2] + e * nd[i].length * nd[i].dir[2];
                x0 = fmin(x0, x); x1 = fmax(x1, x); z0 = fmin(z0, z); z1 = fmax(z1, z);
            }
    }
    if (box_x1 > box_x0) { x0 = fmin(x0, box_x0); x1 = fmax(x1, box_x1); }
    if (!isfinite(x0)) return phc_error_set(err, PHC_ERR_INVALID, "growth side view: empty plants");
    double padx = 0.05 * (x1 - x0 + 0.02), padz = 0.05 * (z1 - z0 + 0.02);
    x0 -= padx; x1 += padx; z0 -= padz; z1 += padz;
    const int lib = phc_plot_library_open(path, err);
    if (lib)
        return lib;
    int dev = phc_plot_device_available("pngcairo");
    if (dev <= 0)
        return dev < 0 ? phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path)
                       : phc_error_set(err, PHC_ERR_INTERNAL,
                                       "%s: PLplot has no 'pngcairo' device (install "
                                       "plplot-driver-cairo)", path);
    phc_atomic_file *af = NULL;
    int status = phc_atomic_file_open(path, &af, err);
    if (status) return status;
    PLINT old_stream, strm = -1;
    plgstrm(&old_stream);
    plmkstrm(&strm);
    if (strm < 0) {
        plsstrm(old_stream);
        phc_atomic_file_abort(af);
        return phc_error_set(err, PHC_ERR_INTERNAL, "%s: no free PLplot stream", path);
    }
    plsdev("pngcairo");
    plsfnam(phc_atomic_file_temp_path(af));
    plspage(0.0, 0.0, (PLINT)(520 * n + 180), 760, 0, 0);
    plsfam(0, 0, 0);
    plscmap0n(COL_COUNT);
    plscol0(COL_BG, 255, 255, 255);
    plscol0(COL_FG, 0, 0, 0);
    plscol0(COL_SHOOT, 46, 139, 34);
    plscol0(COL_ROOT, 139, 90, 43);
    plscol0(COL_SOIL, 222, 205, 170);
    plinit();
    pladv(0);
    plschr(0.0, 1.0);
    double w = 1.0 / (double)n;
    for (size_t p = 0; p < n; ++p) {
        plvpas(w * (double)p + 0.12 * w + 0.035, w * (double)(p + 1) - 0.02, 0.24, 0.9,
               (z1 - z0) / (x1 - x0));
        plwind(x0, x1, z0, z1);
        if (soil_top > z0) { /* soil below the surface */
            double bx0 = box_x1 > box_x0 ? box_x0 : x0, bx1 = box_x1 > box_x0 ? box_x1 : x1;
            PLFLT fx[4] = {bx0, bx1, bx1, bx0}, fz[4] = {z0, z0, soil_top, soil_top};
            plcol0(COL_SOIL);
            plfill(4, fx, fz);
        }
        size_t m = 0;
        const phc_growth_node *nd = phc_growth_nodes(plants[p], &m);
        for (size_t i = 0; i < m; ++i) {
            if (!(nd[i].length > 0)) continue;
            PLFLT lx[2] = {nd[i].head[0], nd[i].head[0] + nd[i].length * nd[i].dir[0]};
            PLFLT lz[2] = {nd[i].head[2], nd[i].head[2] + nd[i].length * nd[i].dir[2]};
            plcol0(nd[i].system == PHC_GROWTH_SHOOT ? COL_SHOOT : COL_ROOT);
            double lw = 0.6 + 1200 * nd[i].radius;
            plwidth(lw > 8 ? 8 : lw);
            plline(2, lx, lz);
        }
        plwidth(1.0);
        plcol0(COL_FG);
        plbox("bcnst", phc_plot_nice_step(x1 - x0, 4), 0, "bcnstv", phc_plot_nice_step(z1 - z0, 6), 0);
        plmtex("b", 3.0, 0.5, 0.5, "x (m)");
        plmtex("l", 4.0, 0.5, 0.5, "height z (m)");
        char *t = phc_plot_escape(titles && titles[p] ? titles[p] : "");
        if (t) {
            plschr(0.0, 0.85);
            plmtex("t", 1.5, 0.5, 0.5, t);
            plschr(0.0, 1.0);
        }
        free(t);
    }
    plschr(0.0, 0.8);
    plvpor(0, 1, 0, 1);
    plwind(0, 1, 0, 1);
    plcol0(COL_SHOOT);
    plptex(0.2, 0.06, 1, 0, 0.5, "green: shoot");
    plcol0(COL_ROOT);
    plptex(0.5, 0.06, 1, 0, 0.5, "brown: roots");
    plcol0(COL_FG);
    plptex(0.8, 0.06, 1, 0, 0.5, "tan: soil");
    plptex(0.5, 0.02, 1, 0, 0.5, "line width grows with segment radius");
    plsstrm(strm);
    plend1();
    plsstrm(old_stream);
    return phc_plot_file_finish(af, status, err);
}
