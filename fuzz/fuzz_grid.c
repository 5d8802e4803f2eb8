/* Grid sizing: construction from arbitrary shapes and values, the exact Lipschitz constant, and
 * the envelope (values only lowered, stay positive, the result L-Lipschitz). */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_grid_desc gd = vpds_default_grid_desc();
    size_t shape[VPDS_MAX_DIM], n = 1, i;
    double values[512], before[512], lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], L, target, vmax = 0;
    int k, specials = take_u8(&b) == 0;
    vpds_grid *g = NULL;
    vpds_status st;
    char msg[256];
    gd.dim = 1 + take_u8(&b) % 3;
    for (k = 0; k < gd.dim; k++) {
        shape[k] = take_u8(&b) % 8; /* 0 and 1 are invalid */
        n *= shape[k] ? shape[k] : 1;
        lo[k] = take_double(&b, -1, 1, specials);
        hi[k] = lo[k] + take_double(&b, -0.1, 2, specials);
    }
    if (n > 512) return 0;
    for (i = 0; i < n; i++) values[i] = take_double(&b, 0.01, 1, specials);
    gd.shape = shape;
    gd.values = values;
    gd.lo = lo;
    gd.hi = hi;
    st = vpds_grid_validate(&gd, msg, sizeof msg);
    check_status(st);
    FUZZ_ASSERT(vpds_grid_create(&gd, &g) == st, "create disagrees with validate");
    if (st != VPDS_OK) {
        FUZZ_ASSERT(g == NULL, "refused grid returned");
        return 0;
    }
    L = vpds_grid_lipschitz(g);
    for (i = 0; i < n; i++) vmax = values[i] > vmax ? values[i] : vmax;
    FUZZ_ASSERT(L >= 0, "L = %g", L); /* +inf only when the largest slope itself overflows */
    /* no pair of close points along the grid breaks L */
    for (i = 0; i < 64; i++) {
        double x[VPDS_MAX_DIM], y[VPDS_MAX_DIM], big = 0, s2 = 0, dist, gap;
        for (k = 0; k < gd.dim; k++) {
            x[k] = lo[k] + (hi[k] - lo[k]) * (double)take_u8(&b) / 255.0;
            y[k] = x[k] + (hi[k] - lo[k]) * 1e-3 * ((double)take_u8(&b) - 127.5) / 127.5;
            if (y[k] > hi[k]) y[k] = hi[k];
            if (y[k] < lo[k]) y[k] = lo[k];
            if (fabs(x[k] - y[k]) > big) big = fabs(x[k] - y[k]);
        }
        for (k = 0; k < gd.dim && big > 0; k++) s2 += ((x[k] - y[k]) / big) * ((x[k] - y[k]) / big);
        dist = big * sqrt(s2); /* without squares that underflow near 1e-300 */
        gap = fabs(vpds_grid_eval(g, x) - vpds_grid_eval(g, y));
        /* evaluation rounds by a few ulps of the largest value, whatever the distance */
        FUZZ_ASSERT(!(gap > L * dist * (1 + 1e-9) + 1e-14 * vmax),
                    "slope %g above L %g", gap / dist, L);
    }
    memcpy(before, vpds_grid_values(g), n * sizeof(double));
    target = take_double(&b, 0, 2, 1);
    st = vpds_grid_enforce_lipschitz(g, target);
    check_status(st);
    if (st == VPDS_OK) {
        const double *v = vpds_grid_values(g);
        for (i = 0; i < n; i++) FUZZ_ASSERT(v[i] <= before[i] && v[i] > 0, "value %zu raised or <= 0", i);
        FUZZ_ASSERT(vpds_grid_lipschitz(g) <= target, "L %.17g > target %.17g",
                    vpds_grid_lipschitz(g), target);
    } else {
        FUZZ_ASSERT(!(target > 0) || !isfinite(target), "refused target %g", target);
        FUZZ_ASSERT(memcmp(before, vpds_grid_values(g), n * sizeof(double)) == 0, "refusal changed the grid");
    }
    vpds_grid_destroy(g);
    return 0;
}
