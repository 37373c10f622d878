/* Unit tests of the shoot-root coordination model (model/growth.h,
 * Rhizomorph §5): presets and parameter checks, seeding, determinism of
 * both randomness modes, the pipe model's exact relation, the segment
 * geometry, limit cases of the fluxes and the allocation, the water budget
 * of PHYSICAL uptake against the soil's own budget, the exports, nutrient
 * branching, the smoothness of EXPECTED mode and max_nodes with the
 * step's up-front node reservation.  One line per check group
 * with the measured numbers. */
#include "check.h"

#include <ctype.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#include "model/growth.h"
#include "model/plant_graph.h"
#include "model/soil.h"

static void must(int rc, const phc_error *err, const char *what)
{
    if (rc) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(2);
    }
}

static phc_growth_params preset(const char *name)
{
    phc_growth_params p;
    phc_error err;
    must(phc_growth_preset(name, &p, &err), &err, "preset");
    return p;
}

/* The test soil: 10 x 10 x 10 voxels of 0.03 m (a 0.3 m cube), one layer
 * of capacity 1 filled to `fill`, permeability p (m/h; 0 = nothing moves,
 * so one soil step per day), growth resistance d and nutrients v; all
 * faces blocked (the default), no rain. */
#define SOIL_N 10
#define SOIL_DX 0.03
static phc_soil *test_soil(double fill, double p, double d, double v)
{
    phc_soil *s = phc_soil_new(SOIL_N, SOIL_N, SOIL_N, SOIL_DX);
    if (!s) {
        fprintf(stderr, "phc_soil_new failed\n");
        exit(2);
    }
    phc_error err;
    phc_soil_layer L = {.thickness = 0, .c = 1, .p = p, .d = d, .water = 0, .fill = fill,
                        .nutrient = v};
    must(phc_soil_set_layers(s, &L, 1, &err), &err, "layers");
    s->params.dt = 24; /* h: one soil step per plant day (sub-stepped when p > 0) */
    return s;
}

/* Seeded at the centre of the soil surface. */
static phc_growth_options opts_at_surface(void)
{
    phc_growth_options o = phc_growth_options_default();
    o.base[0] = 0.5 * SOIL_N * SOIL_DX;
    o.base[1] = 0.5 * SOIL_N * SOIL_DX;
    o.base[2] = SOIL_N * SOIL_DX;
    return o;
}

static phc_growth *grow(const phc_growth_params *p, const phc_growth_options *o, phc_soil *s,
                        int days)
{
    phc_growth *g;
    phc_error err;
    must(phc_growth_new(p, o, s, &g, &err), &err, "growth_new");
    for (int d = 0; d < days; ++d)
        must(phc_growth_step(g, 1.0, &err), &err, "growth_step");
    return g;
}

static phc_growth_summary summary_after(const phc_growth_params *p, const phc_growth_options *o,
                                        phc_soil *s, int days)
{
    phc_growth *g = grow(p, o, s, days);
    phc_growth_summary S;
    phc_growth_summarize(g, &S);
    phc_growth_free(g);
    return S;
}

/* ---- 1. presets and parameters ------------------------------------------------ */

static void test_presets(void)
{
    phc_error err;
    phc_growth_params p;
    size_t np = 0;
    for (size_t i = 0; phc_growth_preset_name(i); ++i, ++np) {
        const char *name = phc_growth_preset_name(i);
        char upper[32], mixed[32];
        size_t k = 0;
        for (; name[k] && k < 31; ++k) {
            upper[k] = (char)toupper((unsigned char)name[k]);
            mixed[k] = k % 2 ? (char)toupper((unsigned char)name[k]) : name[k];
        }
        upper[k] = mixed[k] = 0;
        phc_growth_params a, b, c;
        CHECK(phc_growth_preset(name, &a, &err) == PHC_OK);
        CHECK(phc_growth_preset(upper, &b, &err) == PHC_OK);
        CHECK(phc_growth_preset(mixed, &c, &err) == PHC_OK);
        CHECK(memcmp(&a, &b, sizeof a) == 0 && memcmp(&a, &c, sizeof a) == 0);
        int rc = phc_growth_check(&a, &err);
        CHECK(rc == PHC_OK);
        printf("    preset %-7s (%s, %s): check rc %d, internode %g m, phi_rg %g\n", name, upper,
               mixed, rc, a.internode_length, a.phi_rg);
    }
    CHECK(np == 5);
    const char *want[5] = {"oak", "cherry", "apple", "poplar", "maple"};
    for (int i = 0; i < 5; ++i)
        CHECK(phc_growth_preset_name((size_t)i) && strcmp(phc_growth_preset_name((size_t)i), want[i]) == 0);

    phc_error_clear(&err);
    int rc = phc_growth_preset("birch", &p, &err);
    printf("    preset birch -> rc %d \"%s\"\n", rc, err.message);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "birch");
    for (int i = 0; i < 5; ++i)
        CHECK_STR_CONTAINS(err.message, want[i]);

    /* names <-> offsets: every field is a double, listed once, in struct order */
    size_t n = phc_growth_param_count();
    CHECK(n == sizeof(phc_growth_params) / sizeof(double));
    CHECK(phc_growth_param_name(n) == NULL);
    CHECK(phc_growth_param_ref(&p, n) == NULL);
    CHECK(phc_growth_param_find("no_such_parameter") == -1);
    CHECK(phc_growth_param_find(NULL) == -1);
    size_t bad_roundtrip = 0;
    p = preset("oak");
    for (size_t i = 0; i < n; ++i) {
        const char *name = phc_growth_param_name(i);
        long j = name ? phc_growth_param_find(name) : -1;
        double *r = phc_growth_param_ref(&p, i);
        if (!name || j != (long)i || r != (double *)&p + i) ++bad_roundtrip;
    }
    CHECK(bad_roundtrip == 0);
    CHECK(phc_growth_param_ref(&p, (size_t)phc_growth_param_find("internode_length")) == &p.internode_length);
    CHECK(phc_growth_param_ref(&p, (size_t)phc_growth_param_find("phi_rg")) == &p.phi_rg);
    CHECK(phc_growth_param_ref(&p, (size_t)phc_growth_param_find("nutrient_branching")) == &p.nutrient_branching);
    CHECK(phc_growth_param_ref(&p, (size_t)phc_growth_param_find("reserve_rate")) == &p.reserve_rate);

    /* every parameter, negative and NaN: INPUT naming it */
    size_t named_neg = 0, named_nan = 0;
    char last_neg[PHC_ERROR_MESSAGE_SIZE] = "", last_nan[PHC_ERROR_MESSAGE_SIZE] = "";
    for (size_t i = 0; i < n; ++i) {
        char quoted[80];
        snprintf(quoted, sizeof quoted, "'%s'", phc_growth_param_name(i));
        for (int t = 0; t < 2; ++t) {
            phc_growth_params q = preset("oak");
            *phc_growth_param_ref(&q, i) = t == 0 ? -1.0 : NAN;
            phc_error_clear(&err);
            rc = phc_growth_check(&q, &err);
            if (rc == PHC_ERR_INPUT && strstr(err.message, quoted)) {
                if (t == 0) ++named_neg; else ++named_nan;
            } else {
                fprintf(stderr, "    check with %s = %s -> rc %d \"%s\"\n", quoted,
                        t == 0 ? "-1" : "NaN", rc, err.message);
            }
            strcpy(t == 0 ? last_neg : last_nan, err.message);
        }
    }
    CHECK(named_neg == n);
    CHECK(named_nan == n);
    phc_growth_params q = preset("oak");
    q.phi_rg = 1.5;
    phc_error_clear(&err);
    rc = phc_growth_check(&q, &err);
    CHECK(rc == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "'phi_rg'");
    CHECK_STR_CONTAINS(err.message, "1.5");
    printf("  presets: %zu presets load and pass; %zu parameter names round-trip (%zu bad); "
           "check names the parameter for -1 in %zu/%zu, NaN in %zu/%zu\n"
           "    e.g. \"%s\", \"%s\"; phi_rg = 1.5 -> rc %d \"%s\"\n",
           np, n, bad_roundtrip, named_neg, n, named_nan, n, last_neg, last_nan, rc, err.message);
}

/* ---- 2. seeding --------------------------------------------------------------------- */

static void test_seeding(void)
{
    phc_soil *s = test_soil(0.5, 0, 1, 0);
    phc_growth_params p = preset("oak");
    phc_error err;
    phc_growth *g = NULL;
    const double outside[3][3] = {{0.5, 0.15, 0.15}, {0.15, -0.01, 0.15}, {0.15, 0.15, 0.31}};
    for (int t = 0; t < 3; ++t) {
        phc_growth_options o = phc_growth_options_default();
        memcpy(o.base, outside[t], sizeof o.base);
        phc_error_clear(&err);
        g = (phc_growth *)&err; /* must be reset to NULL */
        int rc = phc_growth_new(&p, &o, s, &g, &err);
        printf("    seed at (%g, %g, %g) -> rc %d \"%s\"\n", o.base[0], o.base[1], o.base[2], rc,
               err.message);
        CHECK(rc == PHC_ERR_INPUT);
        CHECK(g == NULL);
        CHECK_STR_CONTAINS(err.message, "outside the soil grid");
        CHECK(s->sink == NULL);
    }
    phc_growth_options o = opts_at_surface();
    int rc = phc_growth_new(&p, &o, s, &g, &err);
    CHECK(rc == PHC_OK && g != NULL);
    size_t n = 0;
    const phc_growth_node *nd = rc == PHC_OK ? phc_growth_nodes(g, &n) : NULL;
    CHECK(n == 2);
    if (n == 2) {
        CHECK(nd[0].system == PHC_GROWTH_SHOOT && nd[1].system == PHC_GROWTH_ROOT);
        CHECK(nd[0].head[2] == o.base[2] && nd[1].head[2] == o.base[2]);
        CHECK(nd[0].dir[2] == 1 && nd[1].dir[2] == -1);
    }
    CHECK(s->sink != NULL);
    /* one plant per soil */
    phc_growth *g2 = NULL;
    phc_error_clear(&err);
    int rc2 = phc_growth_new(&p, &o, s, &g2, &err);
    CHECK(rc2 != PHC_OK && g2 == NULL);
    phc_growth_free(g);
    CHECK(s->sink == NULL);
    printf("  seeding: base (%g, %g, %g) inside -> rc %d, %zu nodes; a second plant on the same "
           "soil -> rc %d \"%s\"\n",
           o.base[0], o.base[1], o.base[2], rc, n, rc2, err.message);
    phc_soil_free(s);
}

/* ---- 3. determinism ------------------------------------------------------------------ */

static void test_determinism(void)
{
    phc_growth_params p = preset("oak");
    phc_growth_options o = opts_at_surface();
    phc_soil *s1 = test_soil(0.5, 0, 1, 0), *s2 = test_soil(0.5, 0, 1, 0);
    phc_growth_summary a = summary_after(&p, &o, s1, 40), b = summary_after(&p, &o, s2, 40);
    int same_exp = memcmp(&a, &b, sizeof a) == 0;
    CHECK(same_exp);
    CHECK(memcmp(s1->w, s2->w, s1->n * sizeof(double)) == 0);
    phc_soil_free(s1);
    phc_soil_free(s2);

    o.mode = PHC_GROWTH_STOCHASTIC;
    o.seed = 12345;
    s1 = test_soil(0.5, 0, 1, 0);
    s2 = test_soil(0.5, 0, 1, 0);
    phc_soil *s3 = test_soil(0.5, 0, 1, 0);
    phc_growth_summary c = summary_after(&p, &o, s1, 40), d = summary_after(&p, &o, s2, 40);
    o.seed = 777;
    phc_growth_summary e = summary_after(&p, &o, s3, 40);
    int same_sto = memcmp(&c, &d, sizeof c) == 0;
    int differ = c.shoot_nodes != e.shoot_nodes || c.root_nodes != e.root_nodes ||
                 c.shoot_mass != e.shoot_mass || c.root_mass != e.root_mass;
    CHECK(same_sto);
    CHECK(differ);
    printf("  determinism (40 d, oak, soil): EXPECTED twice %s (nodes %zu+%zu, root:shoot %.17g); "
           "STOCHASTIC seed 12345 twice %s (nodes %zu+%zu, root mass %.6g g); seed 777 %s "
           "(nodes %zu+%zu, root mass %.6g g)\n",
           same_exp ? "bit-identical" : "DIFFERENT", a.shoot_nodes, a.root_nodes, a.root_shoot,
           same_sto ? "bit-identical" : "DIFFERENT", c.shoot_nodes, c.root_nodes, c.root_mass,
           differ ? "differs" : "SAME", e.shoot_nodes, e.root_nodes, e.root_mass);
    phc_soil_free(s1);
    phc_soil_free(s2);
    phc_soil_free(s3);
}

/* ---- 4. pipe model and 5. geometry ------------------------------------------------- */

/* max over nodes of |r_i^a - sum_j r_tip^a l_j / L| / sum, and the count of
 * nodes with r_i^a below the sum (beyond 1e-12 relative). */
static double pipe_error(const phc_growth *g, size_t *below)
{
    size_t n;
    const phc_growth_node *nd = phc_growth_nodes(g, &n);
    const phc_growth_params *p = phc_growth_parameters(g);
    double a = p->pipe_exponent, *sum = malloc(n * sizeof *sum), worst = 0;
    if (!sum) exit(2);
    for (size_t i = 0; i < n; ++i) {
        int shoot = nd[i].system == PHC_GROWTH_SHOOT;
        double rt = shoot ? p->tip_radius_shoot : p->tip_radius_root;
        double L = shoot ? p->internode_length : p->root_node_length;
        sum[i] = pow(rt, a) * nd[i].length / L;
    }
    for (size_t i = n; i-- > 0;)
        if (nd[i].parent != PHC_GROWTH_NONE) sum[nd[i].parent] += sum[i];
    *below = 0;
    for (size_t i = 0; i < n; ++i) {
        double ra = pow(nd[i].radius, a);
        double e = sum[i] > 0 ? fabs(ra - sum[i]) / sum[i] : fabs(ra);
        if (ra < sum[i] * (1 - 1e-12)) ++*below;
        if (e > worst) worst = e;
    }
    free(sum);
    return worst;
}

typedef struct {
    double head_err, unit_err;
    size_t bad_order, bad_apical, bad_tip, bad_system;
} geometry_errors;

static geometry_errors geometry(const phc_growth *g)
{
    size_t n;
    const phc_growth_node *nd = phc_growth_nodes(g, &n);
    geometry_errors e = {0, 0, 0, 0, 0, 0};
    size_t bases = 0;
    for (size_t i = 0; i < n; ++i) {
        const phc_growth_node *q = &nd[i];
        double u = fabs(sqrt(q->dir[0] * q->dir[0] + q->dir[1] * q->dir[1] + q->dir[2] * q->dir[2]) - 1);
        if (u > e.unit_err) e.unit_err = u;
        if (q->parent == PHC_GROWTH_NONE) {
            ++bases;
            if (i != q->system) ++e.bad_order; /* the bases are nodes 0 (shoot) and 1 (root) */
        } else {
            if (q->parent >= i) { ++e.bad_order; continue; }
            const phc_growth_node *pa = &nd[q->parent];
            if (pa->system != q->system) ++e.bad_system;
            for (int k = 0; k < 3; ++k) {
                double want = pa->head[k] + pa->dir[k] * pa->length;
                double d = fabs(q->head[k] - want);
                if (d > e.head_err) e.head_err = d;
            }
        }
        if (q->apical_child != PHC_GROWTH_NONE) {
            if (q->apical_child >= n || q->apical_child <= i || nd[q->apical_child].parent != i)
                ++e.bad_apical;
            if (q->tip) ++e.bad_tip;
        } else if (!q->tip) {
            ++e.bad_tip;
        }
    }
    if (bases != 2) ++e.bad_order;
    return e;
}

static void check_geometry(const char *what, const phc_growth *g)
{
    geometry_errors e = geometry(g);
    size_t n;
    phc_growth_nodes(g, &n);
    printf("    geometry %s: %zu nodes, max |head - (parent head + dir length)| %.3g m, "
           "max ||dir| - 1| %.3g, order errors %zu, apical errors %zu, tip flag errors %zu, "
           "system errors %zu\n",
           what, n, e.head_err, e.unit_err, e.bad_order, e.bad_apical, e.bad_tip, e.bad_system);
    CHECK(e.head_err <= 1e-12);
    CHECK(e.unit_err <= 1e-12);
    CHECK(e.bad_order == 0);
    CHECK(e.bad_apical == 0);
    CHECK(e.bad_tip == 0);
    CHECK(e.bad_system == 0);
}

static void test_pipe_and_geometry(void)
{
    phc_growth_params p = preset("oak");
    p.prune_ratio = 0;
    phc_growth_options o = opts_at_surface();
    phc_soil *s = test_soil(0.5, 0, 1, 0);
    phc_growth *g = grow(&p, &o, s, 60);
    size_t below, n;
    phc_growth_nodes(g, &n);
    double e = pipe_error(g, &below);
    printf("  pipe model (oak, prune_ratio 0, 60 d, %zu nodes): max |r^a - sum r_tip^a l/L| / sum "
           "= %.3g, nodes below the sum %zu\n",
           n, e, below);
    CHECK(e <= 1e-12);
    CHECK(below == 0);
    check_geometry("oak 60 d no pruning", g);
    phc_growth_free(g);

    /* a = 2.5 and a stochastic plant without soil */
    p.pipe_exponent = 2.5;
    o.mode = PHC_GROWTH_STOCHASTIC;
    o.seed = 3;
    g = grow(&p, &o, NULL, 45);
    phc_growth_nodes(g, &n);
    e = pipe_error(g, &below);
    printf("  pipe model (oak, a = 2.5, STOCHASTIC, no soil, 45 d, %zu nodes): max rel error %.3g, "
           "below %zu\n",
           n, e, below);
    CHECK(e <= 1e-12);
    CHECK(below == 0);
    check_geometry("oak a=2.5 stochastic 45 d", g);
    phc_growth_free(g);

    /* with pruning (compaction): geometry must survive; radii only >= the sum
     * (above it only while the plant has not regrown the pruned pipes) */
    p = preset("apple");
    o = phc_growth_options_default();
    o.mode = PHC_GROWTH_STOCHASTIC;
    o.seed = 5;
    g = grow(&p, &o, NULL, 90);
    phc_growth_summary S;
    phc_growth_summarize(g, &S);
    e = pipe_error(g, &below);
    printf("  pipe model with pruning (apple, STOCHASTIC seed 5, no soil, 90 d, %zu+%zu nodes, %zu pruned): "
           "max rel excess of r^a over the sum %.3g, nodes below the sum %zu (must be 0)\n",
           S.shoot_nodes, S.root_nodes, S.pruned, e, below);
    CHECK(S.pruned > 0);
    CHECK(below == 0);
    check_geometry("apple 90 d pruned", g);
    phc_growth_free(g);
    phc_soil_free(s);
}

/* ---- 6. limits ------------------------------------------------------------------------- */

static void test_limits(void)
{
    phc_error err;
    /* light = 0, no seed reserve: no shoot flux, no vigor, no growth */
    phc_growth_params p = preset("oak");
    p.light = 0;
    p.seed_reserve = 0;
    phc_growth_options o = opts_at_surface();
    phc_soil *s = test_soil(0.5, 0, 1, 0);
    phc_growth *g;
    must(phc_growth_new(&p, &o, s, &g, &err), &err, "new");
    size_t n0;
    phc_growth_nodes(g, &n0);
    double max_sf = 0, max_len_change = 0;
    size_t changed = 0;
    phc_growth_summary S0, S;
    phc_growth_summarize(g, &S0);
    for (int d = 0; d < 30; ++d) {
        must(phc_growth_step(g, 1.0, &err), &err, "step");
        phc_growth_summarize(g, &S);
        if (fabs(S.shoot_flux) > max_sf) max_sf = fabs(S.shoot_flux);
        if (S.shoot_nodes != S0.shoot_nodes || S.root_nodes != S0.root_nodes) ++changed;
        double dl = fabs(S.root_length - S0.root_length) + fabs(S.height - S0.height);
        if (dl > max_len_change) max_len_change = dl;
    }
    printf("  limits: light 0, no reserve, 30 d: max shoot_flux %g, vigor %g, node counts %zu+%zu "
           "-> %zu+%zu (changed on %zu days), length change %g m, root_flux %g\n",
           max_sf, S.vigor, S0.shoot_nodes, S0.root_nodes, S.shoot_nodes, S.root_nodes, changed,
           max_len_change, S.root_flux);
    CHECK(max_sf == 0);
    CHECK(S.vigor == 0);
    CHECK(changed == 0);
    CHECK(max_len_change == 0);
    CHECK(S.root_flux > 0); /* the roots still drink: only the shoot is dark */
    phc_growth_free(g);
    phc_soil_free(s);

    /* water_uptake = 0 -> no root flux, with and without a soil */
    p = preset("oak");
    p.water_uptake = 0;
    s = test_soil(0.5, 0, 1, 0);
    double w0 = phc_soil_water_total(s);
    phc_growth_summary a = summary_after(&p, &o, s, 20);
    phc_growth_summary b = summary_after(&p, NULL, NULL, 20);
    printf("  limits: water_uptake 0, 20 d: root_flux %g (soil), %g (no soil); water_uptake %g; "
           "soil water %.17g -> %.17g m^3; shoot_flux %g\n",
           a.root_flux, b.root_flux, a.water_uptake, w0, phc_soil_water_total(s), a.shoot_flux);
    CHECK(a.root_flux == 0 && b.root_flux == 0);
    CHECK(a.water_uptake == 0);
    CHECK(phc_soil_water_total(s) == w0);
    CHECK(a.shoot_flux > 0);
    phc_soil_free(s);

    /* no soil: every root segment's fill is soil_fill */
    p = preset("oak");
    p.soil_fill = 0.37;
    g = grow(&p, NULL, NULL, 40);
    size_t n, roots = 0, bad = 0;
    const phc_growth_node *nd = phc_growth_nodes(g, &n);
    for (size_t i = 0; i < n; ++i) {
        if (nd[i].system != PHC_GROWTH_ROOT) continue;
        ++roots;
        if (nd[i].fill != p.soil_fill || nd[i].resistance != 0) ++bad;
    }
    phc_growth_summarize(g, &S);
    printf("  limits: no soil, soil_fill %g, 40 d: %zu root segments, %zu with another fill or a "
           "resistance\n",
           p.soil_fill, roots, bad);
    CHECK(roots > 1);
    CHECK(bad == 0);
    phc_growth_free(g);

    /* phi_rg = 1 vs 0: more roots with 1 */
    double rs[2];
    for (int k = 0; k < 2; ++k) {
        p = preset("oak");
        p.phi_rg = k;
        s = test_soil(0.5, 0, 1, 0);
        S = summary_after(&p, &o, s, 60);
        rs[k] = S.root_shoot;
        printf("    phi_rg %d, 60 d: root %.6g g, shoot %.6g g, root:shoot %.6g, nodes %zu+%zu\n", k,
               S.root_mass, S.shoot_mass, S.root_shoot, S.shoot_nodes, S.root_nodes);
        phc_soil_free(s);
    }
    printf("  limits: root:shoot at 60 d with phi_rg 0 = %.6g < with phi_rg 1 = %.6g\n", rs[0], rs[1]);
    CHECK(rs[0] < rs[1]);

    /* root_resistance large: a soil with d = 5 roots shallower than d = 0 */
    double depth[2];
    for (int k = 0; k < 2; ++k) {
        p = preset("oak");
        p.root_resistance = 10;
        s = test_soil(0.5, 0, k == 0 ? 0 : 5, 0);
        S = summary_after(&p, &o, s, 30);
        depth[k] = S.rooting_depth;
        phc_soil_free(s);
    }
    /* and with root_resistance 0 the soil's d does not matter */
    double same[2];
    for (int k = 0; k < 2; ++k) {
        p = preset("oak");
        p.root_resistance = 0;
        s = test_soil(0.5, 0, k == 0 ? 0 : 5, 0);
        S = summary_after(&p, &o, s, 30);
        same[k] = S.rooting_depth;
        phc_soil_free(s);
    }
    printf("  limits: root_resistance 10, 30 d: rooting depth %.6g m with d = 0, %.6g m with d = 5; "
           "root_resistance 0: %.17g vs %.17g m\n",
           depth[0], depth[1], same[0], same[1]);
    CHECK(depth[1] < depth[0]);
    CHECK(same[0] == same[1]);
}

/* ---- 7. uptake -------------------------------------------------------------------------- */

static void test_uptake(void)
{
    phc_growth_params p = preset("oak");
    phc_growth_options o = opts_at_surface();
    phc_error err;
    const int days = 60;
    /* wet, slowly moving soil: water diffuses and drains toward the bottom */
    phc_soil *s = test_soil(0.8, 0.0005, 1, 0);
    phc_soil_budget_reset(s);
    double w0 = phc_soil_water_total(s);
    phc_growth *g;
    must(phc_growth_new(&p, &o, s, &g, &err), &err, "new");
    double reported = 0, max_rate = 0;
    for (int d = 0; d < days; ++d) {
        must(phc_growth_step(g, 1.0, &err), &err, "step");
        phc_growth_summary S;
        phc_growth_summarize(g, &S);
        reported += S.water_uptake * 1.0;
        if (S.water_uptake > max_rate) max_rate = S.water_uptake;
    }
    double w1 = phc_soil_water_total(s), wmin = INFINITY;
    for (size_t i = 0; i < s->n; ++i)
        if (s->w[i] < wmin) wmin = s->w[i];
    const phc_soil_budget *B = &s->budget;
    printf("  uptake PHYSICAL (oak, %d d, p 0.0005 m/h): plant reports %.17g m^3, soil sunk %.17g "
           "m^3 (rel diff %.3g), water %.12g -> %.12g m^3 (drop %.6g), closing %.3g m^3, min w %.3g, "
           "max rate %.3g m^3/d, %zu sub-steps\n",
           days, reported, B->water_sunk, fabs(B->water_sunk - reported) / reported, w0, w1, w0 - w1,
           B->water_closing, wmin, max_rate, B->substeps);
    CHECK(reported > 0);
    CHECK_NEAR(B->water_sunk, reported, 0, 1e-9);
    CHECK_NEAR(w0 - w1, reported, 0, 1e-9);
    CHECK(fabs(B->water_closing) <= 1e-12 * w0);
    CHECK(B->water_in == 0 && B->water_absorbed == 0);
    phc_growth_free(g);
    phc_soil_free(s);

    /* UPTAKE_NONE: the soil evolves exactly as without a plant */
    phc_soil *s1 = test_soil(0.8, 0.0005, 1, 0), *s2 = test_soil(0.8, 0.0005, 1, 0);
    o.uptake = PHC_GROWTH_UPTAKE_NONE;
    must(phc_growth_new(&p, &o, s1, &g, &err), &err, "new");
    CHECK(s1->sink == NULL);
    for (int d = 0; d < days; ++d)
        must(phc_growth_step(g, 1.0, &err), &err, "step");
    phc_growth_summary S;
    phc_growth_summarize(g, &S);
    must(phc_soil_run(s2, s1->t, &err), &err, "soil alone");
    int same = memcmp(s1->w, s2->w, s1->n * sizeof(double)) == 0;
    printf("  uptake NONE: plant root_flux %.6g (it still reads the soil), soil water %.17g vs "
           "%.17g m^3 without a plant: %s\n",
           S.root_flux, phc_soil_water_total(s1), phc_soil_water_total(s2),
           same ? "bit-identical" : "DIFFERENT");
    CHECK(S.root_flux > 0);
    CHECK(same);
    CHECK(s1->t == s2->t);
    phc_growth_free(g);
    phc_soil_free(s1);
    phc_soil_free(s2);
}

/* ---- 8. exports --------------------------------------------------------------------------- */

static void check_branches(const phc_growth *g, phc_growth_system sys, const char *what,
                           size_t min_branches)
{
    size_t n;
    const phc_growth_node *nd = phc_growth_nodes(g, &n);
    size_t *first, *parent;
    size_t nb = phc_growth_branches(g, sys, &first, &parent);
    unsigned char *seen = calloc(n, 1);
    if (!seen) exit(2);
    size_t twice = 0, foreign = 0, bad_parent = 0, bad_start = 0, in_sys = 0, covered = 0;
    for (size_t b = 0; b < nb; ++b) {
        size_t i = first[b];
        if (i >= n) { ++bad_start; continue; }
        /* the branch's parent holds the start node's parent */
        if (nd[i].parent == PHC_GROWTH_NONE) {
            if (parent[b] != PHC_GROWTH_NONE) ++bad_parent;
        } else if (parent[b] == PHC_GROWTH_NONE || parent[b] >= b) {
            ++bad_parent;
        } else {
            if (nd[nd[i].parent].apical_child == i) ++bad_start; /* a branch starts at a lateral */
            size_t j = first[parent[b]], hit = 0;
            for (; j != PHC_GROWTH_NONE && j < n; j = nd[j].apical_child)
                if (j == nd[i].parent) hit = 1;
            if (!hit) ++bad_parent;
        }
        for (; i != PHC_GROWTH_NONE && i < n; i = nd[i].apical_child) {
            if (nd[i].system != sys) ++foreign;
            if (seen[i]++) ++twice;
        }
    }
    for (size_t i = 0; i < n; ++i) {
        if (nd[i].system != sys) continue;
        ++in_sys;
        covered += seen[i] == 1;
    }
    printf("    branches %s: %zu branches, %zu/%zu nodes covered once, %zu twice, %zu foreign, "
           "%zu bad parents, %zu bad starts\n",
           what, nb, covered, in_sys, twice, foreign, bad_parent, bad_start);
    CHECK(nb >= min_branches);
    CHECK(covered == in_sys);
    CHECK(twice == 0 && foreign == 0 && bad_parent == 0 && bad_start == 0);
    free(seen);
    free(first);
    free(parent);
}

static void check_exports(const phc_growth *g, const char *what, size_t min_shoot_branches)
{
    phc_error err;
    size_t n, grown = 0, shoot_grown = 0;
    const phc_growth_node *nd = phc_growth_nodes(g, &n);
    for (size_t i = 0; i < n; ++i)
        if (nd[i].length > 0) {
            ++grown;
            shoot_grown += nd[i].system == PHC_GROWTH_SHOOT;
        }
    phc_plant_graph *pg = phc_growth_plant_graph(g, &err);
    CHECK(pg != NULL);
    if (pg) {
        size_t leaf_on_root = 0, leaves = 0, bad_src = 0, bad_geom = 0, bad_parent = 0;
        size_t head_at_parent_tail = 0, root_base_at_collar = 0;
        for (size_t j = 0; j < pg->n; ++j) {
            long src = pg->source_id[j];
            if (src < 0 || (size_t)src >= n || nd[src].length <= 0) { ++bad_src; continue; }
            if (pg->leaf[j]) {
                ++leaves;
                if (nd[src].system != PHC_GROWTH_SHOOT) ++leaf_on_root;
            }
            if (pg->length[j] != nd[src].length || pg->radius[j] != nd[src].radius ||
                pg->head[3 * j + 2] != nd[src].head[2])
                ++bad_geom;
            size_t pj = pg->parent[j];
            if (pj == PHC_PLANT_NO_PARENT) continue;
            /* the exported parent is the nearest grown ancestor (the root
             * system's base hangs from the shoot base) */
            size_t want = nd[src].parent == PHC_GROWTH_NONE ? 0 : nd[src].parent;
            while (nd[want].length <= 0 && nd[want].parent != PHC_GROWTH_NONE) want = nd[want].parent;
            if (pg->source_id[pj] != (long)want) ++bad_parent;
            double dt = 0, dh = 0;
            for (int k = 0; k < 3; ++k) {
                dt = fmax(dt, fabs(pg->head[3 * j + k] - pg->tail[3 * pj + k]));
                dh = fmax(dh, fabs(pg->head[3 * j + k] - pg->head[3 * pj + k]));
            }
            if (dt <= 1e-12) ++head_at_parent_tail;
            else if (src == 1 && dh == 0) ++root_base_at_collar;
        }
        long root_src = pg->source_id[pg->root];
        printf("  exports %s: plant graph %zu segments (%zu nodes with length > 0, %zu shoot), "
               "%zu leaves (%zu on roots), root = node %ld, bad source ids %zu, bad parents %zu, "
               "geometry mismatches %zu; heads at the parent's tail %zu/%zu (+ root base at the "
               "collar: %zu)\n",
               what, pg->n, grown, shoot_grown, leaves, leaf_on_root, root_src, bad_src, bad_parent,
               bad_geom, head_at_parent_tail, pg->n - 1, root_base_at_collar);
        CHECK(pg->n == grown);
        CHECK(pg->order != NULL && pg->child_start != NULL && pg->depth != NULL); /* finished */
        CHECK(leaves > 0 && leaf_on_root == 0);
        CHECK(root_src == 0 && pg->parent[pg->root] == PHC_PLANT_NO_PARENT);
        CHECK(bad_src == 0 && bad_geom == 0 && bad_parent == 0);
        CHECK(head_at_parent_tail + root_base_at_collar == pg->n - 1);
        phc_plant_graph_free(pg);
    } else {
        printf("  exports %s: plant graph failed: %s\n", what, err.message);
    }
    check_branches(g, PHC_GROWTH_SHOOT, "shoot", min_shoot_branches);
    check_branches(g, PHC_GROWTH_ROOT, "root", 2);
}

static void test_exports(void)
{
    phc_growth_params p = preset("oak");
    phc_growth_options o = opts_at_surface();
    phc_soil *s = test_soil(0.5, 0, 1, 0);
    phc_growth *g = grow(&p, &o, s, 60);
    check_exports(g, "oak EXPECTED 60 d in soil", 1);
    phc_growth_free(g);
    phc_soil_free(s);

    p = preset("apple");
    o = phc_growth_options_default();
    o.mode = PHC_GROWTH_STOCHASTIC;
    o.seed = 5;
    g = grow(&p, &o, NULL, 90);
    check_exports(g, "apple STOCHASTIC 90 d (pruned)", 5);
    phc_growth_free(g);

    /* a fresh seedling exports (both bases have a length) */
    p = preset("oak");
    g = grow(&p, NULL, NULL, 0);
    phc_error err;
    phc_plant_graph *pg = phc_growth_plant_graph(g, &err);
    CHECK(pg && pg->n == 2);
    phc_plant_graph_free(pg);
    phc_growth_free(g);
}

/* ---- 9. nutrients ----------------------------------------------------------------------------- */

static void test_nutrients(void)
{
    phc_growth_params p = preset("oak");
    p.nutrient_branching = 1;
    phc_growth_options o = opts_at_surface();
    size_t tips[2], nodes[2];
    for (int k = 0; k < 2; ++k) {
        phc_soil *s = test_soil(0.5, 0, 1, k == 0 ? 0 : 5);
        phc_growth_summary S = summary_after(&p, &o, s, 45);
        tips[k] = S.root_tips;
        nodes[k] = S.root_nodes;
        phc_soil_free(s);
    }
    printf("  nutrients (oak, 45 d, nutrient_branching 1): root tips %zu with v = 0, %zu with v = 5 "
           "(root nodes %zu, %zu)\n",
           tips[0], tips[1], nodes[0], nodes[1]);
    CHECK(tips[1] > tips[0]);
}

/* Long steps (options.long_step, default 7 d): an 8-day step runs the soil
 * at 0.9 x its stability limit instead of its dt of 1 h (fewer soil
 * sub-steps), restores dt and absorb_dt afterwards, keeps the absorbing
 * layer's loss per hour (absorb_dt), and changes the soil water and the
 * plant after a further day by little against long_step = 0 (the 1 h soil
 * step); a 6-day step is not a long step; a negative long_step is refused. */
static void test_long_step(void)
{
    phc_growth_summary S[2];
    double water[2], absorbed[2];
    size_t sub[2], sub6 = 0;
    double lim = 0, dt_after[2], adt_after[2];
    for (int v = 0; v < 2; ++v) {
        phc_growth_options o = opts_at_surface();
        if (v) o.long_step = 0;
        phc_growth_params p = preset("oak");
        phc_soil *s = test_soil(0.5, 0.0015, 0, 0);
        for (size_t k = 0; k < s->n; ++k) s->c[k] = 100, s->w[k] = 50;
        s->params.dt = 1;
        s->params.boundary[PHC_SOIL_ZMIN] = PHC_SOIL_ABSORB;
        phc_soil_rain r = {.start = 0, .end = 1e9, .rate = 0.0075 * 0.3};
        phc_error err;
        must(phc_soil_set_rain(s, &r, 1, &err), &err, "rain");
        lim = phc_soil_stable_dt(s, NULL);
        phc_growth *g;
        must(phc_growth_new(&p, &o, s, &g, &err), &err, "new");
        for (int d = 0; d < 20; ++d) must(phc_growth_step(g, 1.0, &err), &err, "step");
        size_t before = s->budget.substeps;
        must(phc_growth_step(g, 6.0, &err), &err, "6-day step");
        if (!v) sub6 = s->budget.substeps - before;
        must(phc_growth_step(g, 8.0, &err), &err, "8-day step");
        sub[v] = s->budget.substeps - before;
        dt_after[v] = s->params.dt;
        adt_after[v] = s->params.absorb_dt;
        must(phc_growth_step(g, 1.0, &err), &err, "step");
        phc_growth_summarize(g, &S[v]);
        water[v] = phc_soil_water_total(s);
        absorbed[v] = s->budget.water_absorbed;
        phc_growth_free(g);
        phc_soil_free(s);
    }
    double dw = fabs(water[0] / water[1] - 1), da = fabs(absorbed[0] / absorbed[1] - 1);
    double dr = fabs(S[0].root_mass / S[1].root_mass - 1), ds = fabs(S[0].shoot_mass / S[1].shoot_mass - 1);
    double dl = fabs(S[0].root_length / S[1].root_length - 1);
    printf("  long steps (oak, 20 + 6 + 8 + 1 d, soil c 100, p 0.0015 m/h, limit %.3g h): soil sub-steps of the "
           "6 + 8 days %zu (6-day step: %zu, 8-day step: %zu) vs %zu with long_step 0; dt after %g h, absorb_dt after %g; "
           "relative change: soil water %.2e, absorbed %.2e, root mass %.2e, shoot mass %.2e, root length %.2e\n",
           lim, sub[0], sub6, sub[0] - sub6, sub[1], dt_after[0], adt_after[0], dw, da, dr, ds, dl);
    CHECK(sub6 == 144 && sub[1] == 336);
    CHECK(sub[0] - sub6 == (size_t)ceil(192.0 / (0.9 * lim)));
    CHECK(dt_after[0] == 1 && adt_after[0] == 0 && dt_after[1] == 1);
    CHECK(dw < 0.01);
    CHECK(da < 0.05);
    CHECK(dr < 1e-3 && ds < 1e-3 && dl < 1e-3);
    phc_growth_options o = opts_at_surface();
    o.long_step = -1;
    phc_growth_params p = preset("oak");
    phc_growth *g = NULL;
    phc_error err;
    int rc = phc_growth_new(&p, &o, NULL, &g, &err);
    printf("  long_step -1: rc %d \"%s\"\n", rc, rc ? err.message : "");
    CHECK(rc == PHC_ERR_INPUT && strstr(err.message, "long_step") && !g);
}

/* A step reserves room for a bound on its new nodes before it grows
 * (step_nodes_bound in growth.c), capped at max_nodes: a 30-day step that
 * ends with exactly max_nodes nodes must run and give the plant of an
 * unlimited run byte for byte, and one node fewer must fail naming
 * max_nodes (the bound itself is above the real growth, so without the cap
 * the first case would fail). */
static void test_node_limit(void)
{
    for (int mode = 0; mode < 2; ++mode) {
        phc_growth_params p = preset("poplar"); /* made to branch, as the bench's plant */
        p.lateral_buds = 3, p.bud_flush = 0.3, p.apical_inhibition = 0.5, p.shoot_elongation = 0.03;
        p.root_elongation = 0.04, p.root_branching = 1.5, p.light_use = 400;
        size_t n0 = 0, n_ref = 0, n_at = 0;
        phc_growth_node *ref = NULL;
        int rc_at = -1, rc_below = -1, same = 0;
        char msg[sizeof ((phc_error *)0)->message] = "";
        for (int run = 0; run < 3; ++run) {
            phc_growth_options o = opts_at_surface();
            if (mode) o.mode = PHC_GROWTH_STOCHASTIC, o.seed = 3;
            o.max_nodes = run == 0 ? 0 : run == 1 ? n_ref : n_ref - 1;
            phc_growth *g = grow(&p, &o, NULL, 20); /* no soil: roots grow without walls */
            phc_error err;
            size_t n;
            phc_growth_nodes(g, &n);
            if (run == 0) n0 = n;
            int rc = phc_growth_step(g, 30.0, &err);
            const phc_growth_node *nd = phc_growth_nodes(g, &n);
            if (run == 0) {
                must(rc, &err, "30-day step");
                n_ref = n;
                ref = malloc(n * sizeof *ref);
                if (ref) memcpy(ref, nd, n * sizeof *ref);
            } else if (run == 1) {
                rc_at = rc;
                n_at = n;
                same = rc == 0 && ref && n == n_ref && memcmp(ref, nd, n * sizeof *ref) == 0;
            } else {
                rc_below = rc;
                if (rc) snprintf(msg, sizeof msg, "%s", err.message);
            }
            phc_growth_free(g);
        }
        free(ref);
        printf("  node limit (branchy poplar, no soil, %s, 20 d then 30 d): %zu -> %zu nodes; max_nodes %zu: rc %d, %zu nodes, %s; "
               "max_nodes %zu: rc %d \"%s\"\n", mode ? "STOCHASTIC" : "EXPECTED", n0, n_ref, n_ref, rc_at, n_at,
               same ? "byte-identical" : "DIFFERENT", n_ref - 1, rc_below, msg);
        CHECK(n_ref > n0 + 10);
        CHECK(rc_at == 0 && same);
        CHECK(rc_below == PHC_ERR_DOMAIN && strstr(msg, "max_nodes") != NULL);
    }
}

/* Eq. 24 scales the branching probability by (1 + nutrient_branching v):
 * in a uniform soil with v = 5, nutrient_branching = 1 and root_branching
 * rb must give the plant of nutrient_branching = 0 and 6 rb, for any step
 * length (with dt = 10 d a root tip lays several segments in one step, and
 * each must see the soil's nutrients). */
static void test_nutrient_scaling(void)
{
    phc_growth_options o = opts_at_surface();
    const double dts[2] = {1, 10};
    for (int t = 0; t < 2; ++t) {
        phc_growth_summary S[2];
        for (int k = 0; k < 2; ++k) {
            phc_growth_params p = preset("oak");
            p.root_branching = k == 0 ? 0.2 : 6 * 0.2;
            p.nutrient_branching = k == 0 ? 1 : 0;
            phc_soil *s = test_soil(0.5, 0, 0, 5);
            phc_growth *g;
            phc_error err;
            must(phc_growth_new(&p, &o, s, &g, &err), &err, "new");
            for (double day = 0; day < 20; day += dts[t])
                must(phc_growth_step(g, dts[t], &err), &err, "step");
            phc_growth_summarize(g, &S[k]);
            phc_growth_free(g);
            phc_soil_free(s);
        }
        printf("  nutrient scaling, 20 d in steps of %g d: (rb 0.2, nb 1, v 5) root nodes %zu, tips %zu, "
               "length %.9g m; (rb 1.2, nb 0) root nodes %zu, tips %zu, length %.9g m\n",
               dts[t], S[0].root_nodes, S[0].root_tips, S[0].root_length, S[1].root_nodes,
               S[1].root_tips, S[1].root_length);
        CHECK(S[0].root_nodes == S[1].root_nodes);
        CHECK(S[0].root_tips == S[1].root_tips);
        CHECK_NEAR(S[0].root_length, S[1].root_length, 0, 1e-9);
    }
}


/* Nutrient-weighted allocation (step 6, the authors' CalculateVigorRequirement):
 * scaling every root tip's weight by the same power of two changes no
 * number (v = 2 everywhere with a = 1 is the plant of a = 0, bit for bit);
 * in a pot split into a rich and a poor half, root length moves to the rich
 * half, measured in both mirror images so the plant's own side bias cancels. */
static double side_length(const phc_growth *g, int rich_left, double *rich, double *poor)
{
    size_t n;
    const phc_growth_node *nd = phc_growth_nodes(g, &n);
    *rich = *poor = 0;
    for (size_t i = 0; i < n; ++i) {
        if (nd[i].system != PHC_GROWTH_ROOT) continue;
        int left = nd[i].head[0] + 0.5 * nd[i].length * nd[i].dir[0] < 0.5 * SOIL_N * SOIL_DX;
        *(left == rich_left ? rich : poor) += nd[i].length;
    }
    return *rich / *poor;
}

static void test_nutrient_allocation(void)
{
    phc_growth_options o = opts_at_surface();
    o.mode = PHC_GROWTH_STOCHASTIC;
    o.seed = 7;
    phc_growth_summary S[2];
    for (int k = 0; k < 2; ++k) {
        phc_growth_params p = preset("oak");
        p.nutrient_branching = 0;
        p.nutrient_allocation = k;
        phc_soil *s = test_soil(0.5, 0, 0, 2);
        S[k] = summary_after(&p, &o, s, 45);
        phc_soil_free(s);
    }
    printf("  nutrient allocation, uniform v = 2, 45 d: a = 0 root nodes %zu, length %.17g m; a = 1 root nodes %zu, "
           "length %.17g m\n",
           S[0].root_nodes, S[0].root_length, S[1].root_nodes, S[1].root_length);
    CHECK(S[0].root_nodes == S[1].root_nodes);
    CHECK(S[0].root_length == S[1].root_length);
    CHECK(S[0].shoot_mass == S[1].shoot_mass);
    /* split: v = 0.2 on one half, 3 on the other; EXPECTED mode; mirrored */
    o.mode = PHC_GROWTH_EXPECTED;
    double ratio[2];
    for (int k = 0; k < 2; ++k) {
        double rich = 0, poor = 0;
        for (int m = 0; m < 2; ++m) {
            phc_growth_params p = preset("oak");
            p.nutrient_branching = 0;
            p.nutrient_allocation = k;
            phc_soil *s = test_soil(0.5, 0, 0, 0);
            for (size_t q = 0; q < s->n; ++q) {
                int left = q % SOIL_N < SOIL_N / 2;
                s->v[q] = left == (m == 0) ? 3.0 : 0.2;
            }
            phc_growth *g = grow(&p, &o, s, 60);
            double r, pr;
            side_length(g, m == 0, &r, &pr);
            rich += r, poor += pr;
            phc_growth_free(g);
            phc_soil_free(s);
        }
        ratio[k] = rich / poor;
    }
    printf("  nutrient allocation, split pot (v 3 | 0.2), EXPECTED 60 d, both mirror images: root length rich / poor "
           "%.3f with a = 0, %.3f with a = 1\n",
           ratio[0], ratio[1]);
    CHECK(ratio[1] > 1.5);
    CHECK(ratio[1] > ratio[0]);
}

/* Root tips stop at the faces of the soil box: measured overshoot of the
 * deepest tail below the bottom (at most one step's elongation, since a
 * tip is stopped once its tail is outside). */
static void test_pot_walls(void)
{
    phc_growth_params p = preset("oak");
    p.root_resistance = 0;
    phc_growth_options o = opts_at_surface();
    phc_soil *s = test_soil(0.5, 0, 0, 0);
    phc_growth *g = grow(&p, &o, s, 60);
    size_t n, outside = 0, stopped = 0;
    const phc_growth_node *nd = phc_growth_nodes(g, &n);
    double over = 0, box = SOIL_N * SOIL_DX;
    for (size_t i = 0; i < n; ++i) {
        if (nd[i].system != PHC_GROWTH_ROOT) continue;
        double worst = 0;
        for (int k = 0; k < 3; ++k) {
            double tail = nd[i].head[k] + nd[i].length * nd[i].dir[k];
            worst = fmax(worst, fmax(-tail, tail - box));
        }
        if (worst > 0) {
            ++outside;
            stopped += nd[i].tip;
        }
        over = fmax(over, worst);
    }
    phc_growth_summary S;
    phc_growth_summarize(g, &S);
    printf("  pot walls (oak, 60 d, d = 0): rooting depth %.6g m in a %.2g m box; %zu root tails outside "
           "(%zu of them tips: stopped), largest overshoot %.3g m (one day's elongation %.3g m)\n",
           S.rooting_depth, box, outside, stopped, over, p.root_elongation);
    CHECK(over <= p.root_elongation * 1.0 + 1e-12);
    phc_growth_free(g);
    phc_soil_free(s);
}

/* ---- 10. smoothness of EXPECTED mode -------------------------------------------------------- */

static void test_smoothness(void)
{
    phc_growth_params p = preset("oak");
    phc_growth_options o = opts_at_surface();
    const double phi[3] = {0.50, 0.501, 0.502};
    double rs[3];
    phc_growth_summary S[3];
    for (int k = 0; k < 3; ++k) {
        p.phi_rg = phi[k];
        phc_soil *s = test_soil(0.5, 0, 1, 0);
        S[k] = summary_after(&p, &o, s, 90);
        rs[k] = S[k].root_shoot;
        phc_soil_free(s);
    }
    double d1 = rs[1] - rs[0], d2 = rs[2] - rs[1];
    double ratio = d1 != 0 ? d2 / d1 : NAN;
    printf("  smoothness (oak, 90 d): root:shoot at phi_rg 0.500, 0.501, 0.502 = %.12g, %.12g, %.12g; "
           "differences %.6g, %.6g (ratio %.4g); nodes %zu+%zu, %zu+%zu, %zu+%zu\n",
           rs[0], rs[1], rs[2], d1, d2, ratio, S[0].shoot_nodes, S[0].root_nodes, S[1].shoot_nodes,
           S[1].root_nodes, S[2].shoot_nodes, S[2].root_nodes);
    CHECK(d1 != 0 && d2 != 0);
    CHECK((d1 > 0) == (d2 > 0));
    CHECK(fabs(ratio) <= 3 && fabs(ratio) >= 1.0 / 3);
}

/* Expected and stochastic plants: the README's numbers on how much less an
 * expected plant branches (probabilities accumulate per bud).  Both grow. */
static void test_modes(void)
{
    const char *names[3] = {"apple", "maple", "poplar"};
    for (int k = 0; k < 3; ++k) {
        phc_growth_params p = preset(names[k]);
        size_t nodes[2], branches[2];
        for (int m = 0; m < 2; ++m) {
            phc_growth_options o = phc_growth_options_default();
            o.mode = m ? PHC_GROWTH_STOCHASTIC : PHC_GROWTH_EXPECTED;
            o.seed = 1;
            phc_growth *g = grow(&p, &o, NULL, 90);
            size_t *first = NULL, *parent = NULL;
            branches[m] = phc_growth_branches(g, PHC_GROWTH_SHOOT, &first, &parent);
            phc_growth_nodes(g, &nodes[m]);
            free(first);
            free(parent);
            phc_growth_free(g);
        }
        printf("  modes (%s, 90 d, no soil): expected %zu nodes, %zu shoot branches; stochastic "
               "(seed 1) %zu nodes, %zu shoot branches\n",
               names[k], nodes[0], branches[0], nodes[1], branches[1]);
        CHECK(nodes[0] > 2 && nodes[1] > 2);
        CHECK(branches[0] >= 1 && branches[1] >= 1);
    }
}

int main(void)
{
    struct { const char *name; void (*fn)(void); } groups[] = {
        {"presets", test_presets},     {"seeding", test_seeding},
        {"determinism", test_determinism}, {"pipe+geometry", test_pipe_and_geometry},
        {"limits", test_limits},       {"uptake", test_uptake},
        {"exports", test_exports},     {"nutrients", test_nutrients},
        {"nutrient scaling", test_nutrient_scaling}, {"long steps", test_long_step},
        {"nutrient allocation", test_nutrient_allocation}, {"pot walls", test_pot_walls},
        {"smoothness", test_smoothness}, {"modes", test_modes},
        {"node limit", test_node_limit},
    };
    for (size_t i = 0; i < sizeof groups / sizeof groups[0]; ++i) {
        clock_t t0 = clock();
        int f0 = check_failures;
        groups[i].fn();
        printf("  [%s: %s, %.2f s cpu]\n", groups[i].name, check_failures == f0 ? "ok" : "FAILED",
               (double)(clock() - t0) / CLOCKS_PER_SEC);
    }
    return check_finish("test_growth");
}
