/* Soil water and nutrients on a 3-D voxel grid: Rhizomorph §6
 * (Li et al., ACM TOG 2023, eqs. 25-31; DESIGN §5).
 *
 * Units are the paper's model units: time in hours (h), lengths in metres
 * (m).  Per voxel:
 *   w  water content, volume of water per volume of soil (m^3/m^3, which is
 *      the authors' "g/cm^3")
 *   v  nutrients, nutrient units per m^3 of soil
 *   c  capacity (dimensionless; w/c is the fill level that drives diffusion)
 *   p  permeability (m/h: the gravity drainage velocity at f_grav = 1);
 *      p = 0 blocks (rock)
 *   d  growth resistance delta (used by the root model; not by the flow)
 *
 * Water flux (eqs. 25-28), per unit area across a face:
 *   j = p (j_diff + j_grav),  j_diff = -f_diff grad(w/c),  j_grav = f_grav w e_down
 *   dw/dt = -div j + sources - sinks
 * f_diff (m) and f_grav (dimensionless) are the authors' diffusion and
 * gravity "forces" (SoilModel defaults 1 and 1).
 *
 * Discretisation (finite volumes, so water is conserved to round-off):
 *   - face permeability: harmonic mean of the two voxels (0 if either is 0,
 *     so p = 0 voxels block exactly).  The authors' code differentiates with
 *     a wide central stencil (2 dx) and multiplies by the voxel's p; their
 *     blocking walls mirror the field and are not conservative.  Ours is the
 *     compact conservative form of the same equations.
 *   - diffusion: F = f_diff p_f (w_i/c_i - w_j/c_j) / dx
 *   - gravity (z faces only, downward): Lax-Wendroff on q = f_grav p w, as the
 *     authors' code (which applies it to w p):
 *       F = (q_up + q_low)/2 - (h f_grav p_f / (2 dx)) (q_low - q_up)
 *   - nutrients ride on the water face flux F with a Lax-Wendroff face
 *     concentration u_f = (u_i + u_j)/2 - (nu/2)(u_j - u_i), u = v/w,
 *     nu = F h / (dx w_mean); times f_nutrient (authors' m_nutrientForce).
 *   - forward Euler in time (eq. 29-30).
 *   - params.gravity = PHC_SOIL_GRAVITY_UPWIND replaces both Lax-Wendroff
 *     forms by the donor cell (upwind): F = f_grav p_up w_up, the gravity
 *     flux of the voxel above the face, and u_f = u of the voxel the flux
 *     leaves.  Lax-Wendroff at the small Courant numbers of slow soils is
 *     nearly the centred flux (q_up + q_low)/2, so where water pools on a
 *     blocked face (a pot's bottom) it pulls half the pool's flux out of
 *     the nearly dry voxel above, which goes negative (in a 0.5 m sandy pot
 *     watered daily, w falls to -8 m^3/m^3 above the pool).  The upwind flux
 *     never takes more than a voxel holds (w stays >= 0 under the bound
 *     below), at the price of first-order numerical diffusion.  Default:
 *     LAX_WENDROFF, the authors' scheme (SoilModel.cpp).
 *
 * Boundaries, per face of the box: BLOCK (no flux), PERIODIC (wrap) or
 * ABSORB (eq. 31: no flux across the face, and the `absorb_width` voxel
 * layers next to it are damped every step by a(i), i = 0 at the face):
 *   PHC_SOIL_ABSORB_CODE  (default) a(i) = 1 - exp(-i^2 / (0.2 W^2)), the
 *                         authors' SoilModel.cpp (W = 5)
 *   PHC_SOIL_ABSORB_PAPER a(i) = 1 - exp(-i / (0.2 W^2)), as printed in eq. 31
 * The authors damp once per step of dt; we damp by a(i)^(h/dt) per sub-step
 * h, so the loss per hour does not depend on sub-stepping (params.absorb_dt,
 * when > 0, stands for dt here: a caller that lengthens dt for a while, as
 * the growth model's long steps do, keeps the loss per hour).  The code form is
 * the default because the paper's figures were made with it.  Absorbing
 * layers damp water and nutrients alike (the authors' code damps water only).
 *
 * Stability.  The explicit step is stable when, for every voxel i,
 *   h * f_diff (sum over faces of p_f) / (c_i dx^2) + (h f_grav p_i / dx)^2 <= 1
 * (the von Neumann bound 6 r + C^2 <= 1 of Lax-Wendroff plus diffusion on a
 * uniform grid); with the upwind gravity flux the bound is
 *   h * f_diff (sum over faces of p_f) / (c_i dx^2) + h f_grav p_i / dx <= 1
 * (the positivity bound of the donor cell plus diffusion: the new w is then
 * a non-negative combination of the old ones).  phc_soil_stable_dt returns
 * that limit; phc_soil_run
 * sub-steps with `safety` times the limit or refuses (params.substep = 0).
 *
 * Threads: the voxel loops run with OpenMP; every voxel's update reads only
 * the previous state, and budget sums are reduced per z-plane in a fixed
 * order, so results are bit-identical for any thread count.
 *
 * Time blocking: while only water moves (no nutrients, sink hook, absorbing
 * face, tangent, and no rain or source acting), up to `block_steps`
 * consecutive sub-steps of the same length (at most nz/8) are taken in one
 * sweep over the grid (a wavefront in z), so the per-voxel constants
 * stream from memory once per sweep; with block_steps 0 as many (up to 4)
 * as keep a sweep's planes in a core's cache (1 at 64 x 64 voxels per
 * plane, 4 at 128 x 128, where the planes come from memory anyway).
 * Layer planes: where a z-plane and the planes above and below each have
 * one c, one p (horizontal layers) and the x faces are closed, the sweep
 * reads only w there (the face permeabilities are numbers, not planes);
 * where p is either 0 or one value (layers with rocks) it reads w and p.
 * When every plane is so, block_steps 0 takes 2 sub-steps per sweep at 64
 * x 64 voxels per plane and 8 at 128 x 128.  The arithmetic is that of one
 * voxel and one sub-step at a time: the result is bit-identical for any
 * block_steps (test_soil 4b, 4c), uniform planes or not.
 *
 * Layout: voxel (i, j, k) is element i + nx (j + ny k); x east, y north,
 * z up; k = nz - 1 is the surface layer.  Voxel centres are at
 * origin + (index + 1/2) dx.
 *
 * No I/O, no globals. */
#ifndef PHC_SOIL_H
#define PHC_SOIL_H

#include <stddef.h>
#include <stdint.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum phc_soil_boundary {
    PHC_SOIL_BLOCK = 0,
    PHC_SOIL_ABSORB,
    PHC_SOIL_PERIODIC
} phc_soil_boundary;

typedef enum phc_soil_gravity {
    PHC_SOIL_GRAVITY_LAX_WENDROFF = 0, /* the authors' code (default) */
    PHC_SOIL_GRAVITY_UPWIND            /* donor cell: never drives w below 0 */
} phc_soil_gravity;

typedef enum phc_soil_absorb_form {
    PHC_SOIL_ABSORB_CODE = 0, /* i^2: the authors' code (default) */
    PHC_SOIL_ABSORB_PAPER     /* i: eq. 31 as printed */
} phc_soil_absorb_form;

/* The six faces of the box. */
enum { PHC_SOIL_XMIN, PHC_SOIL_XMAX, PHC_SOIL_YMIN, PHC_SOIL_YMAX,
       PHC_SOIL_ZMIN /* bottom */, PHC_SOIL_ZMAX /* surface */, PHC_SOIL_FACES };

typedef struct phc_soil_params {
    double f_diff;                          /* m; default 1 */
    double f_grav;                          /* dimensionless; default 1 */
    double f_nutrient;                      /* nutrient transport factor; default 1 */
    phc_soil_boundary boundary[PHC_SOIL_FACES]; /* default: BLOCK everywhere */
    phc_soil_absorb_form absorb_form;       /* default CODE */
    int absorb_width;                       /* voxel layers, default 5 */
    double dt;                              /* h, the step; default 0.001 (authors) */
    int substep;                            /* 1 (default): sub-step over the limit; 0: refuse */
    double safety;                          /* fraction of the limit used when sub-stepping, 0.9 */
    size_t max_substeps;                    /* most sub-steps per step of dt; 0 (default) = no limit */
    phc_soil_gravity gravity;               /* gravity and nutrient face fluxes; default LAX_WENDROFF */
    size_t block_steps;                     /* water-only sub-steps per sweep (time blocking); 0 (default) = up to 4 (8 on layer planes), by the cache (soil.c block_levels), 1 = none */
    double absorb_dt;                       /* h, the step the absorbing factors a(i) apply per; 0 (default) = dt */
} phc_soil_params;

/* The defaults listed above. */
phc_soil_params phc_soil_params_default(void);

/* Rain or irrigation on the surface: `rate` m/h of water depth during
 * [start, end) h, carrying `nutrient` units per m^3 of water.  It enters the
 * highest permeable voxel of every column (inside the rectangle x0..x1,
 * y0..y1 in m; all zero = the whole surface). */
typedef struct phc_soil_rain {
    double start, end;      /* h */
    double rate;            /* m/h */
    double nutrient;        /* units per m^3 of water */
    double x0, x1, y0, y1;  /* m; x1 <= x0 means the whole surface */
} phc_soil_rain;

/* A point source of water (m^3/h) and nutrients (units/h) during [start,
 * end) h, spread over the voxels within `radius` m of (x, y, z) with
 * Gaussian weights (sigma = radius/3, the authors' ChangeField), or into
 * the voxel containing the point when radius is 0.  Negative rates are
 * point sinks (they never take more than is there). */
typedef struct phc_soil_source {
    double x, y, z;         /* m, grid frame */
    double radius;          /* m */
    double water_rate;      /* m^3/h */
    double nutrient_rate;   /* units/h */
    double start, end;      /* h */
} phc_soil_source;

/* The sink hook (the root model's uptake).  Called once per (sub-)step of h
 * hours at time t; fills water[n] (m^3/m^3 to remove from each voxel during
 * the step) and nutrient[n] (units/m^3), both zeroed before the call.  The
 * model never removes more than a voxel holds.  Returns 0 to go on, nonzero
 * to stop the run (phc_soil_run then fails with PHC_ERR_DOMAIN). */
typedef int (*phc_soil_sink_fn)(void *user, double t, double h, const double *w,
                                const double *v, double *water, double *nutrient);

/* The mass budget since phc_soil_budget_reset (volumes in m^3 of water,
 * nutrients in units).  closing = stored - initial - in + absorbed + sunk,
 * zero up to round-off. */
typedef struct phc_soil_budget {
    double water_initial, water_in, water_absorbed, water_sunk, water_stored, water_closing;
    double nutrient_initial, nutrient_in, nutrient_absorbed, nutrient_sunk,
        nutrient_stored, nutrient_closing;
    size_t steps, substeps;
} phc_soil_budget;

typedef struct phc_soil_work phc_soil_work; /* private */

typedef struct phc_soil {
    size_t nx, ny, nz, n;        /* n = nx ny nz */
    double dx;                   /* m, cubic voxels */
    double origin[3];            /* m, the box's lower (west, south, bottom) corner */
    phc_soil_params params;
    double *w, *v, *c, *p, *d;   /* n each; owned; the caller may edit them between runs */
    double t;                    /* h, model time */
    phc_soil_rain *rain;         /* owned copies */
    size_t n_rain;
    phc_soil_source *sources;
    size_t n_sources;
    phc_soil_sink_fn sink;
    void *sink_user;
    phc_soil_budget budget;
    phc_soil_work *work;
} phc_soil;

/* A soil of nx x ny x nz voxels of dx m with c = 1, p = 0, d = 1, w = v = 0
 * and default parameters; NULL when out of memory or a size is 0 or dx <= 0. */
phc_soil *phc_soil_new(size_t nx, size_t ny, size_t nz, double dx);
void phc_soil_free(phc_soil *s);

/* The six soil settings of Rhizomorph Fig. 7 (capacity c, permeability p in
 * m/h): clay (10, 0.0015), clay_loam (5, 0.0015), sandy_clay_loam (75,
 * 0.033), sandy_loam (150, 0.5), silt_loam (100, 0.5), silt (50, 0.033).
 * Spaces and hyphens in `name` count as underscores; case is ignored.
 * Returns 0, or PHC_ERR_INPUT for an unknown name. */
int phc_soil_preset(const char *name, double *c, double *p);
/* The i-th preset's name (NULL past the end), for messages and loops. */
const char *phc_soil_preset_name(size_t i);

/* A horizontal layer, listed from the surface down. */
typedef struct phc_soil_layer {
    double thickness;       /* m; <= 0 for the last layer = down to the bottom */
    double c, p, d;         /* capacity, permeability (m/h), growth resistance */
    double water;           /* initial w (m^3/m^3); used when fill < 0 */
    double fill;            /* initial w/c, or < 0 to use `water` */
    double nutrient;        /* initial v (units/m^3) */
} phc_soil_layer;

/* Checks one layer (1-based `index` for the message; `last` allows no
 * thickness): finite values, c > 0, p >= 0, d >= 0, initial water (fill or
 * water) and nutrients >= 0.  PHC_OK or PHC_ERR_INPUT "soil layer 2: ...". */
int phc_soil_layer_check(const phc_soil_layer *l, size_t index, int last, phc_error *err);

/* Fills c, p, d, w, v from layers (surface first).  The voxel belongs to the
 * layer containing its centre's depth below the top of the box.  Layers
 * that stop above the bottom are extended by the last one.  Errors:
 * PHC_ERR_INPUT naming the layer (1-based) for c <= 0, p < 0, a negative
 * water or nutrient, or a non-finite value. */
int phc_soil_set_layers(phc_soil *s, const phc_soil_layer *layers, size_t n, phc_error *err);
/* The 0-based layer of every z-plane (nz entries), as set_layers chose them. */
void phc_soil_layer_of_planes(const phc_soil *s, const phc_soil_layer *layers, size_t n,
                              size_t *layer_of_k);

/* Seeded 3-D value noise in [0, 1) with features of `scale` m (trilinear
 * interpolation of hashed lattice values; the same seed gives the same
 * field on every machine). */
double phc_soil_noise(uint64_t seed, double scale, double x, double y, double z);
/* Rocks: p = 0 where the noise exceeds its (1 - fraction) level, so about
 * `fraction` of the voxels become rock.  Returns the number of rock voxels. */
size_t phc_soil_add_rocks(phc_soil *s, uint64_t seed, double scale, double fraction);
/* Nutrient pockets: v += amount (units/m^3) where the noise exceeds its
 * (1 - fraction) level.  Returns the number of voxels enriched. */
size_t phc_soil_add_nutrient_pockets(phc_soil *s, uint64_t seed, double scale,
                                     double fraction, double amount);

/* Copies rain events and sources (replacing earlier ones); 0 or PHC_ERR_NOMEM
 * or PHC_ERR_INPUT for a negative rate, end < start or a source outside the
 * box (message names it, 1-based). */
int phc_soil_set_rain(phc_soil *s, const phc_soil_rain *rain, size_t n, phc_error *err);
int phc_soil_set_sources(phc_soil *s, const phc_soil_source *src, size_t n, phc_error *err);

/* Checks the fields and parameters: c > 0, p >= 0, w, v >= 0 and finite,
 * f_diff, f_grav, f_nutrient >= 0, dt > 0, absorb width fitting the box.
 * The message names the first bad voxel (i, j, k) or parameter. */
int phc_soil_check(const phc_soil *s, phc_error *err);

/* The stability limit of the explicit step (h) and the voxel that sets it
 * (may be NULL); +inf when nothing moves. */
double phc_soil_stable_dt(const phc_soil *s, size_t *voxel);

/* Starts the budget from the current state (water_initial = stored). */
void phc_soil_budget_reset(phc_soil *s);

/* The water-only sub-steps one sweep over the grid takes with the current
 * size, fields and params.block_steps (time blocking; see above): 1 to 8
 * for block_steps 0. */
size_t phc_soil_block_steps(const phc_soil *s);

/* Advances from s->t to t_end (h) in steps of params.dt (the last one
 * shortened to land on t_end), each sub-stepped if over the limit.  Errors:
 * PHC_ERR_INPUT when dt exceeds the limit and substep is 0 (the message
 * gives both and the voxel), PHC_ERR_DOMAIN when a step would need more
 * than max_substeps sub-steps (checked before any step is taken), when the
 * state stops being finite or the sink hook stops the run. */
int phc_soil_run(phc_soil *s, double t_end, phc_error *err);

/* Forward sensitivities of w for m parameters.  Parameter q moves the
 * fields and forces in the direction (dp[q], dinv_c[q], dfd[q], dfg[q]):
 * d p / d theta_q = dp[q] (n values or NULL = 0), d (1/c) / d theta_q =
 * dinv_c[q] (n or NULL), d f_diff / d theta_q = dfd[q], d f_grav / d theta_q
 * = dfg[q].  sw[q] (n values, the caller sets d w(t) / d theta_q at s->t)
 * is advanced with the tangent of exactly the same discrete steps as w, so
 * the derivatives are those of the numbers phc_soil_run computes.  Sinks
 * are treated as independent of the parameters; nutrients are not
 * differentiated. */
typedef struct phc_soil_tangent {
    size_t m;
    const double *const *dp;
    const double *const *dinv_c;
    const double *dfd, *dfg;
    double **sw;
} phc_soil_tangent;
int phc_soil_run_tangent(phc_soil *s, double t_end, const phc_soil_tangent *tan, phc_error *err);

/* Total water (m^3) and nutrients (units) in the box. */
double phc_soil_water_total(const phc_soil *s);
double phc_soil_nutrient_total(const phc_soil *s);

/* Trilinear interpolation of field f (n values) at (x, y, z) m in the grid
 * frame, between voxel centres (clamped to the outer centres).  With wts
 * and idx (8 each) it also returns the weights and voxels used, so callers
 * can interpolate sensitivities the same way.  Returns PHC_ERR_DOMAIN when
 * the point is outside the box. */
int phc_soil_sample(const phc_soil *s, const double *f, double x, double y, double z,
                    double *value, double wts[8], size_t idx[8]);

/* Depth (m below the top of the box) above which a fraction `frac` of the
 * water excess sum(w - w_ref) lies, with the excess taken per z-plane and
 * linear within a plane; `total` is the amount (m^3) that counts as 100%
 * (for example the rain applied, taken as independent of the parameters).
 * When ds and dd are given, ds (n) is a sensitivity field of the excess and
 * *dd receives d depth / d theta.  Returns NAN when
 * the box holds less than frac * total of excess. */
double phc_soil_infiltration_depth(const phc_soil *s, const double *w_ref, double frac,
                                   double total, const double *ds, double *dd);

#ifdef __cplusplus
}
#endif

#endif /* PHC_SOIL_H */
