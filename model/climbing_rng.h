/* The climbing-plant growth model's random numbers (climbing plants:
 * Hädrich et al., CGF 36(2) 2017, §4.3: branching is random).  A small
 * generator of our own so that a plant depends only on its seed, never on
 * a library's version: xoshiro256** (Blackman & Vigna 2018) seeded through
 * splitmix64, as its authors recommend.  The state lives in the caller's
 * struct (no globals). */
#ifndef PHC_CLIMBING_RNG_H
#define PHC_CLIMBING_RNG_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_climbing_rng {
    uint64_t s[4];
} phc_climbing_rng;

/* Seeds the four words with splitmix64(seed), splitmix64 steps 1..4; any
 * seed (0 included) gives a valid, non-zero state. */
void phc_climbing_rng_seed(phc_climbing_rng *r, uint64_t seed);
/* Next 64 random bits. */
uint64_t phc_climbing_rng_next(phc_climbing_rng *r);
/* Uniform on [0, 1): the top 53 bits times 2^-53. */
double phc_climbing_rng_uniform(phc_climbing_rng *r);

#ifdef __cplusplus
}
#endif

#endif /* PHC_CLIMBING_RNG_H */
