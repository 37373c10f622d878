/* Internals of model/rod shared by its source files (rod.c: the model, the
 * direct solver, statics and implicit dynamics; rod_gauss_seidel.c: the
 * authors' reference scheme) and the test hooks.  Not installed
 * (*_internal.h). */
#ifndef PHC_ROD_INTERNAL_H
#define PHC_ROD_INTERNAL_H

#include <stddef.h>

#include "model/rod.h"
#include "model/rod_joint.h"
#include "model/rod_tree_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

struct phc_rod {
    const phc_plant_graph *g;
    size_t n;
    phc_rod_options opt;
    double *young;      /* n, Pa */
    double *extra;      /* n, kg */
    double *mass;       /* n, kg */
    double *inertia;    /* 3n: body-frame principal moments (d1, d2, d3), kg m² */
    unsigned char *fixed;
    double *factor;     /* n: joint to the parent (root unused) */
    double *load;       /* 3n, N at the tail */
    phc_rod_joint_geometry *joint; /* n: joint of segment c with its parent */
    double *stiff;      /* 3n: ℓK of joint c (N m³... energy per Ω²), before the factor */
    /* state */
    double *x, *q, *v, *w, *lambda; /* 3n, 4n, 3n, 3n, 6n */
    double *x0, *q0;
    /* scratch */
    double *xs, *qs, *ls;           /* saved state for line search / refusal */
    double *xo, *qo, *xp, *qp;      /* old and predicted (dynamics) */
    double *res, *rhs, *sol;        /* 12 per node */
    size_t *ejoint, *jnode;         /* the node's joint, joint -> node */
    int *jdeg, *jleft;              /* joints touching each body; not yet assembled */
    size_t *anchors, n_anchors;
    size_t *queue;
    unsigned char *mark;
    double *schur;                  /* (6 n_anchors)² */
    int *schur_piv;
    double reach;
    double load_scale;              /* continuation factor on gravity and loads */
    phc_rod_tree *tree;
};

/* The tail of segment i relative to its centre, R(q_i)(0, 0, h_i/2), m. */
void phc_rod_internal_tail_offset(const phc_rod *rod, size_t i, double u[3]);

/* World inertia R diag(I) Rᵀ of segment i (kg m²), or its inverse. */
void phc_rod_internal_world_inertia(const phc_rod *rod, size_t i, double out[9], int inverse);

/* Start of a sub-step of h seconds: saves (x, q) as old, predicts
 * x + h v and exp(h ω) q. */
void phc_rod_internal_predict(phc_rod *rod, double h);

/* End of a sub-step: velocities from the old state; PHC_ERR_DOMAIN when a
 * segment turned by more than options.max_rotation. */
int phc_rod_internal_finish_substep(phc_rod *rod, double h, phc_error *err);

/* One sub-step of the authors' Gauss–Seidel scheme (rod_gauss_seidel.c). */
int phc_rod_internal_gauss_seidel_substep(phc_rod *rod, double h, phc_error *err);

/* Compares the Newton matrix that phc_rod_solve_static assembles at the
 * rod's current state (every node block and coupling block) with central
 * differences (step eps) of the residual, over every unknown: centre
 * displacements, world rotation increments and joint multipliers.  Writes
 * the largest |difference| and the largest |entry|.  Returns PHC_OK, or the
 * error of building the elimination tree (message in err). */
int phc_rod_internal_jacobian_check(phc_rod *rod, double eps, double *max_error,
                                    double *max_entry, phc_error *err);

/* Assembles the symmetric KKT matrix that the sensitivities
 * (phc_rod_static_sensitivity, _adjoint) factorise, at the current state,
 * and writes the largest |A[r][c] − A[c][r]| over every entry and the
 * largest |entry|.  PHC_OK or the error of building the elimination tree. */
int phc_rod_internal_symmetry_check(phc_rod *rod, double *max_asymmetry, double *max_entry,
                                    phc_error *err);

/* The parts of one static Newton iteration, for the benchmark
 * (tests/bench/bench_rod.c): _prepare_static builds the elimination tree of
 * the statics (as phc_rod_solve_static does; PHC_OK or its error);
 * _assemble_static fills the residual (rod->res) and, when `matrix`, the
 * Newton matrix (rod->tree) at the current state; then phc_rod_tree_factor
 * and phc_rod_tree_solve on rod->tree (rhs rod->sol) are the direct solve. */
int phc_rod_internal_prepare_static(phc_rod *rod, phc_error *err);
void phc_rod_internal_assemble_static(phc_rod *rod, int matrix);

#ifdef __cplusplus
}
#endif

#endif /* PHC_ROD_INTERNAL_H */
