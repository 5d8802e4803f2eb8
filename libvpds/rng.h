/* The library's own PRNG (xoshiro256**, seeded by splitmix64): the same bytes on every build. */
#ifndef VPDS_RNG_H
#define VPDS_RNG_H
#include <stdint.h>

typedef struct vpdsi_rng {
    uint64_t s[4];
} vpdsi_rng;

/* The splitmix64 finaliser: a bijection that scatters nearby inputs (seeds of tiles). */
static inline uint64_t vpdsi_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void vpdsi_rng_seed(vpdsi_rng *r, uint64_t seed);
/* Uniform in [0, n) exactly (rejection on a power-of-two mask), n >= 1. */
uint64_t vpdsi_rng_below(vpdsi_rng *r, uint64_t n);

static inline uint64_t vpdsi_rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static inline uint64_t vpdsi_rng_next(vpdsi_rng *r)
{
    uint64_t *s = r->s;
    uint64_t result = vpdsi_rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = vpdsi_rotl(s[3], 45);
    return result;
}

/* Uniform in [0, 1) on the 2^-53 lattice. */
static inline double vpdsi_rng_unit(vpdsi_rng *r)
{
    return (double)(vpdsi_rng_next(r) >> 11) * (1.0 / 9007199254740992.0);
}
#endif
