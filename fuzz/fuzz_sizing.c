/* Sizing callbacks that return NaN, Inf, zero, negative or huge values, or break the declared L:
 * the run stops with VPDS_ERR_SIZING or VPDS_ERR_LIPSCHITZ (or completes), never crashes, and the
 * samples it accepted keep the empty-disk property with the radii it recorded. */
#include "fuzz_common.h"

typedef struct {
    double table[16];
    int dim;
} zones_t;

/* piecewise constant over 16 zones of x0 (and so able to break any L), from the input */
static double zones_fn(const double *x, void *u)
{
    const zones_t *z = (const zones_t *)u;
    double t = x[0] * 16;
    int i = t < 0 ? 0 : t >= 15 ? 15 : (int)t;
    return z->table[i];
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_desc d = vpds_default_desc();
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    zones_t z;
    vpds_sampler *s = NULL;
    vpds_status st;
    int i, calls;
    z.dim = 2;
    for (i = 0; i < 16; i++) z.table[i] = take_double(&b, 0.03, 0.2, 1);
    d.lo = lo;
    d.hi = hi;
    d.sizing = zones_fn;
    d.sizing_user = &z;
    d.lipschitz = take_double(&b, 0, 0.45, 0);
    d.rule = (vpds_rule)(take_u8(&b) % 5);
    d.seed = take_u32(&b);
    d.budget = 4000;
    if (vpds_create(&d, &s) != VPDS_OK) abort();
    for (calls = 0; calls < 200 && (st = vpds_run(s)) == VPDS_PAUSED; calls++) {}
    check_status(st);
    /* a radius of 1e-300 everywhere is valid but asks for too many cells: VPDS_ERR_OVERFLOW */
    FUZZ_ASSERT(st == VPDS_OK || st == VPDS_PAUSED || st == VPDS_ERR_SIZING || st == VPDS_ERR_LIPSCHITZ ||
                st == VPDS_ERR_OVERFLOW,
                "status %d: %s", (int)st, vpds_last_error(s));
    if (st == VPDS_ERR_SIZING) FUZZ_ASSERT(strstr(vpds_last_error(s), "sizing returned"), "message");
    if (st == VPDS_ERR_LIPSCHITZ) FUZZ_ASSERT(strstr(vpds_last_error(s), "breaks lipschitz"), "message");
    check_samples(s, lo, hi, d.rule, 1.0);
    vpds_destroy(s);
    return 0;
}
