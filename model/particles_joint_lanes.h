/* The own-weight joint pass on four independent links at once (internal to
 * model/particles.c; see follow_one there for the equations).  The links
 * of a shoot are placed one after another, each from its parent's new
 * state, and one link's arithmetic is longer than the core's out-of-order
 * window: links that do not wait for each other (the same depth in a
 * subtree) are run here in one instruction stream, each lane with exactly
 * follow_one's operations in follow_one's order, so each lane's result is
 * follow_one's bit for bit.  Pure arithmetic, no I/O. */
#ifndef PHC_PARTICLES_JOINT_LANES_H
#define PHC_PARTICLES_JOINT_LANES_H

/* Four doubles, one per lane (GCC vector extension: AVX when the build
 * targets it, pairs of SSE2 registers on the x86-64 baseline). */
typedef double phc_v4d __attribute__((vector_size(32)));

/* One link's inputs per lane (follow_one's names): its parent u's new
 * orientation q_u and centre x_u (m), its rest terms j_i (m) and
 * q̄_u⁻¹ q̄_i, its last orientation q_i, its load a_i = g + f_i/m_i
 * (m s⁻², as follow_one sums it), half its length L_i/2 (m) and the
 * joint's fraction k (1 when held at its rest angle). */
typedef struct {
    phc_v4d qu[4], xu[3], ju[3], rel[4], qt[4], acc[3], half, k;
} phc_joint_lanes_in;

/* The new orientation q_i and centre x_i (m) per lane. */
typedef struct {
    phc_v4d q[4], x[3];
} phc_joint_lanes_out;

/* follow_one's joint (anchors excepted) on the four lanes; dt2 = Δt² (s²).
 * Returns the lanes it placed as bits (lane l: 1 << l); the others met a
 * case follow_one takes another path for (no load direction, a half turn,
 * a turn below 1e-8, an angle beyond the inline trig's ranges, |q|² not 1
 * to 1e-8) and must be placed by follow_one. */
int phc_joint_lanes(const phc_joint_lanes_in *in, double dt2, phc_joint_lanes_out *out);

#endif
