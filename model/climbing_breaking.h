/* Shoots that break while a climbing plant grows (Hädrich, Benes, Deussen,
 * Pirk, "Interactive Modeling and Authoring of Climbing Plants", CGF 36(2)
 * 2017, §4.3: "branches break when their stress exceeds a threshold").
 *
 * The rule of the break is the particles' (model/particles.h, "Breaking"):
 * with particles.break_threshold > 0 every dynamics substep of a growing
 * plant (model/climbing_growth.h, step 6) measures each group's stress σ_k
 * (the relative RMS misfit to its best rigid motion, dimensionless) and
 * removes the link k–parent(k) of the most stressed group with σ_k above
 * the threshold, at most one per substep.  Or, with bending = beam,
 * particles.break_stress > 0 (Pa; not both): the link whose joint carries
 * the largest bending stress σ = 4M/(πr³) above it (model/particles.h,
 * "Breaking under a bending stress"), at most one per substep; with
 * particles.anchors_carry_moment the anchors hold what lies beyond them,
 * so an overhang breaks at its support's edge.  What follows a break is
 * the same for both rules.
 *
 * What a broken piece becomes in the plant (ours; the paper says only that
 * the branch breaks): the subtree below the broken link, k and all its
 * descendants, is FALLING from that substep on.  It is no longer part of
 * the growing plant: its tips stop growing (no tropisms, growth or
 * branching), its anchors are let go at once and it makes no new ones, no
 * new leaves grow on it (the ones it bears fall with it); it stays in the
 * particle system as free particles (their links inside the piece kept)
 * under gravity, colliding with the supports when `collide` is on, and
 * keeps its stem-light points (a falling piece still shades).  After
 * fall_time seconds (counted from the step in which it broke, checked at
 * the end of each growth step) it is DROPPED: its particles leave the
 * plant's arrays, which are compacted in index order (parents renumbered;
 * a particle's stable id, phc_climbing_id, is kept), and the particle
 * system is rebuilt from the rest with every particle's position,
 * orientation and velocities carried over (only the groups' polar warm
 * starts are lost: a difference of rounding).  fall_time = 0 drops a piece
 * at the end of the growth step that broke it.  Switching the dynamics off
 * or a failed dynamics step drops every falling piece at once (the
 * kinematic plant has no free particles).  A link that breaks inside a
 * piece that already falls only splits the piece (the parts drop with it).
 * The stump, the particle above the broken link, does not grow again
 * unless resprout_delay is finite (below); the plant grows on from its
 * other tips.
 *
 * Resprouting (reiteration).  The apex of a shoot keeps the buds below it
 * dormant; removing it releases them and the highest grows out as the new
 * leader (Cline 1991, "Apical dominance", Bot. Rev. 57:318–358;
 * reiteration: Hallé, Oldeman & Tomlinson 1978, "Tropical trees and
 * forests").  Ours: the model's buds are at the internode tips (a node's
 * lateral buds are drawn when its internode reaches σ = 1, the ones that
 * do not become shoots stay dormant), so the highest bud below a break is
 * the stump's own tip.  When the link k–p breaks and k continued p's axis
 * (k is p's successor, not a lateral: the axis lost its apex; a lateral
 * that breaks off leaves the axis's apex and so the dominance in place),
 * p is remembered with the time of the break.  At the end of the first
 * growth step whose time is resprout_delay s or more after it (the same
 * rule as fall_time's), if p is still in the plant, not falling, and has
 * no attached successor, a new tip of size σ₀ starts at p's tip and
 * continues p's axis: p's order (it takes over as the leader and grows at
 * the stump's rate r·a^order), p's radius, not a lateral (a shoot tracer
 * follows it as the same shoot), its direction drawn as a lateral's is
 * (the cone of half-angle u·variance·π/2 about p's direction, azimuth
 * 2πu: two uniform draws from the plant's generator whether or not
 * anything sprouts, stumps in the order they broke, after the step's
 * growth).  It then grows and branches as any tip; p's laterals, if any,
 * grow on as before.  resprout_delay = ∞ (the default) remembers no stump
 * and draws nothing: a plant grown without the option is the same bit for
 * bit as before it.
 *
 * This file holds the index work of it on plain arrays; the plant's own
 * arrays are handled in model/climbing_growth.c. */
#ifndef PHC_CLIMBING_BREAKING_H
#define PHC_CLIMBING_BREAKING_H

#include <stddef.h>

#include "model/particles.h"
#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The stumps waiting to resprout: stable id (phc_climbing_id) of the
 * stump particle and the time of its break (s), in the order they broke. */
typedef struct phc_climbing_stumps {
    size_t n, cap;
    size_t *id;
    double *broke_at;
} phc_climbing_stumps;

/* Remembers stump `id`, broken at time t (s).  0 or -1 (out of memory). */
int phc_climbing_stumps_add(phc_climbing_stumps *s, size_t id, double t);

/* Moves the stumps due at time `now` (now − broke_at ≥ delay, with the
 * fall_time tolerance) into due[0 .. return value), in the order they
 * broke, and keeps the others; due has room for s->n. */
size_t phc_climbing_stumps_take_due(phc_climbing_stumps *s, double now, double delay, size_t *due);

void phc_climbing_stumps_free(phc_climbing_stumps *s);

/* Index of the particle with stable id `id` in ids[0 .. n) (increasing:
 * the plant's index order is its birth order), or (size_t)-1. */
size_t phc_climbing_find_id(const size_t *ids, size_t n, size_t id);

/* 1 when particle p has a successor (a child that is not a lateral) that
 * is attached (not falling) among parent[p+1 .. n). */
int phc_climbing_has_attached_successor(const size_t *parent, const unsigned char *lateral,
                                        const unsigned char *falling, size_t n, size_t p);

/* Sets tag[i] = value for k and every descendant of k (parent[i] < i for
 * every particle with a parent, (size_t)-1 for none: the plant's index
 * order); value must be held by no particle outside the subtree.  Returns
 * the subtree's size. */
size_t phc_climbing_subtree_tag(const size_t *parent, size_t n, size_t k, unsigned char *tag,
                                unsigned char value);

/* Removes the elements i with drop[i] != 0 from the array a of n elements
 * of `size` bytes each, keeping the others' order; returns how many are
 * left. */
size_t phc_climbing_compact(void *a, size_t size, const unsigned char *drop, size_t n);

/* Renumbering for phc_climbing_compact: map[i] = new index of a kept i,
 * (size_t)-1 for a dropped one.  Returns the kept count. */
size_t phc_climbing_keep_map(const unsigned char *drop, size_t n, size_t *map);

/* A particle system of m particles made from `old`: particle j is old
 * particle from[j] (from increasing, from[0] = 0 the clamped seed) with
 * rest segment head → tail (3m each, m) and radius (m), linked to
 * parent[j] < j or to none ((size_t)-1: a free piece or a broken link),
 * at from[j]'s position, orientation, velocity and angular velocity.
 * Ages, anchors, gravity and the collider are the caller's to set (the
 * plant's hand-over does it every step).  NULL with err on failure. */
phc_particles *phc_climbing_system_rebuild(const phc_particles *old,
                                           const phc_particles_options *options, size_t m,
                                           const size_t *from, const size_t *parent,
                                           const double *head, const double *tail,
                                           const double *radius, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_BREAKING_H */
