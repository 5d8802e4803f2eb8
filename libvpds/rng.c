#include "rng.h"

static uint64_t splitmix64(uint64_t *x)
{
    return vpdsi_mix64(*x += 0x9E3779B97F4A7C15ull);
}

void vpdsi_rng_seed(vpdsi_rng *r, uint64_t seed)
{
    int i;
    for (i = 0; i < 4; i++) r->s[i] = splitmix64(&seed);
}

uint64_t vpdsi_rng_below(vpdsi_rng *r, uint64_t n)
{
    uint64_t mask = n - 1, x;
    mask |= mask >> 1; mask |= mask >> 2; mask |= mask >> 4;
    mask |= mask >> 8; mask |= mask >> 16; mask |= mask >> 32;
    do {
        x = vpdsi_rng_next(r) & mask;
    } while (x >= n);
    return x;
}
