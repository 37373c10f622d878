/* The authors' reference scheme for the rods (model/rod.h,
 * PHC_ROD_GAUSS_SEIDEL): the PositionBasedDynamics library's XPBD
 * Gauss–Seidel sweep as the wilting paper's PlantDemo runs it — per step,
 * explicit prediction with gravity and loads, then options.gs_iterations
 * sweeps over the joints in breadth-first order, each joint's 6x6 system
 * (J W Jᵀ + α̃) Δλ = −(C + α̃ λ) solved locally (Deul et al. 2018 §3;
 * α̃ = 0 for stretch, (ℓK)⁻¹/h² for bend–twist), multipliers reset every
 * step, velocities from the positions, damping v ← v / (1 + c h).  Its
 * stiffness depends on the iterations and the step (README "Plant shape").
 * Pure C, no I/O. */
#include <math.h>
#include <string.h>

#include "model/quaternion.h"
#include "model/rod_internal.h"

/* The authors' scheme: XPBD Gauss–Seidel over the joints in graph order,
 * multipliers reset each sub-step, explicit prediction with gravity. */
int phc_rod_internal_gauss_seidel_substep(phc_rod *rod, double h, phc_error *err)
{
    const phc_plant_graph *g = rod->g;
    const size_t n = rod->n;
    for (size_t i = 0; i < n; ++i) {
        if (rod->fixed[i])
            continue;
        double u[3], tq[3], iwi[9];
        const double *F = rod->load + 3 * i;
        for (int k = 0; k < 3; ++k)
            rod->v[3 * i + k] += h * (rod->opt.gravity[k] + F[k] / rod->mass[i]);
        phc_rod_internal_tail_offset(rod, i, u);
        tq[0] = u[1] * F[2] - u[2] * F[1];
        tq[1] = u[2] * F[0] - u[0] * F[2];
        tq[2] = u[0] * F[1] - u[1] * F[0];
        phc_rod_internal_world_inertia(rod, i, iwi, 1);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                rod->w[3 * i + a] += h * iwi[a * 3 + b] * tq[b];
    }
    phc_rod_internal_predict(rod, h);
    for (size_t i = 0; i < n; ++i)
        if (!rod->fixed[i]) {
            memcpy(rod->x + 3 * i, rod->xp + 3 * i, 3 * sizeof *rod->x);
            memcpy(rod->q + 4 * i, rod->qp + 4 * i, 4 * sizeof *rod->q);
        }
    memset(rod->lambda, 0, 6 * n * sizeof *rod->lambda);
    for (int it = 0; it < rod->opt.gs_iterations; ++it)
        for (size_t o = 0; o < n; ++o) {
            const size_t c = g->order[o], p = g->parent[c];
            if (p == PHC_PLANT_NO_PARENT || !(rod->factor[c] > 0.0))
                continue;
            double C[6], Jp[36], Jc[36], S[36], WJp[36], WJc[36], iw[9];
            int piv[6];
            phc_rod_joint_eval(rod->joint + c, rod->x + 3 * p, rod->q + 4 * p, rod->x + 3 * c,
                               rod->q + 4 * c, C, Jp, Jc);
            /* W Jᵀ for both bodies (6x6, rows z, columns constraint rows) */
            const size_t body[2] = {p, c};
            const double *J[2] = {Jp, Jc};
            double *WJ[2] = {WJp, WJc};
            for (int b = 0; b < 2; ++b) {
                const size_t i = body[b];
                memset(WJ[b], 0, 36 * sizeof(double));
                if (rod->fixed[i])
                    continue;
                phc_rod_internal_world_inertia(rod, i, iw, 1);
                for (int r = 0; r < 6; ++r) {
                    for (int k = 0; k < 3; ++k)
                        WJ[b][k * 6 + r] = J[b][r * 6 + k] / rod->mass[i];
                    for (int k = 0; k < 3; ++k) {
                        double s = 0.0;
                        for (int l = 0; l < 3; ++l)
                            s += iw[k * 3 + l] * J[b][r * 6 + 3 + l];
                        WJ[b][(3 + k) * 6 + r] = s;
                    }
                }
            }
            double rhs[6], *lam = rod->lambda + 6 * c;
            for (int a = 0; a < 6; ++a) {
                for (int b = 0; b < 6; ++b) {
                    double s = 0.0;
                    for (int k = 0; k < 6; ++k)
                        s += Jp[a * 6 + k] * WJp[k * 6 + b] + Jc[a * 6 + k] * WJc[k * 6 + b];
                    S[a * 6 + b] = s;
                }
                const double at = a < 3 ? 0.0
                                        : 1.0 / (rod->factor[c] * rod->stiff[3 * c + a - 3] * h * h);
                S[a * 6 + a] += at;
                rhs[a] = -C[a] - at * lam[a];
            }
            if (phc_dense_lu(S, 6, piv) != 0)
                return phc_error_set(err, PHC_ERR_NUMERIC,
                                     "rod: segment %ld: singular joint system (gauss_seidel)",
                                     g->source_id[c]);
            phc_dense_lu_solve(S, 6, piv, rhs);
            for (int a = 0; a < 6; ++a)
                lam[a] += rhs[a];
            for (int b = 0; b < 2; ++b) {
                const size_t i = body[b];
                if (rod->fixed[i])
                    continue;
                double dz[6], e[4];
                for (int k = 0; k < 6; ++k) {
                    dz[k] = 0.0;
                    for (int a = 0; a < 6; ++a)
                        dz[k] += WJ[b][k * 6 + a] * rhs[a];
                }
                for (int k = 0; k < 3; ++k)
                    rod->x[3 * i + k] += dz[k];
                phc_quat_exp(dz + 3, e);
                phc_quat_mul(e, rod->q + 4 * i, rod->q + 4 * i);
                phc_quat_normalize(rod->q + 4 * i);
            }
        }
    int rc = phc_rod_internal_finish_substep(rod, h, err);
    if (rc != PHC_OK)
        return rc;
    const double damp = 1.0 / (1.0 + rod->opt.damping * h);
    for (size_t i = 0; i < 3 * n; ++i) {
        rod->v[i] *= damp;
        rod->w[i] *= damp;
    }
    return PHC_OK;
}
