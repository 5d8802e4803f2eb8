/* Domains: a polygon (rings of arbitrary vertices) or a mask (arbitrary values and threshold)
 * from the input, validated and created, then a run or a stream inside it, or a signed
 * distance that misbehaves (NaN, steep, positive). Every refusal has a message and leaves no
 * object; every sample lies in the domain, none conflicts, and after a completed run every
 * probe of the domain is covered. */
#include "fuzz_common.h"

typedef struct {
    int mode;
    double a, b;
} odd_t;

/* A signed distance that may break its contract: NaN beyond a, slope b, or empty. */
static double odd_fn(const double *x, void *u)
{
    const odd_t *o = (const odd_t *)u;
    if (o->mode == 0) return x[0] > o->a ? NAN : x[0] - 0.9;
    if (o->mode == 1) return o->b * (x[0] - o->a);
    return 1.0 + o->a;
}

/* probes of the domain (sdf <= 0) covered at t * f, f = min of the two radii (smaller rule) */
static void check_domain_covered(const vpds_sampler *s, vpds_domain_fn fn, void *user, double radius,
                                 bytes_t *b)
{
    size_t n = vpds_count(s), i, p;
    const double *x = vpds_points(s), *r = vpds_radii(s);
    for (p = 0; p < 200; p++) {
        double y[2], best = INFINITY;
        y[0] = (double)((take_u8(b) * 131 + p * 37) % 257) / 256.0;
        y[1] = (double)((take_u8(b) * 71 + p * 101) % 257) / 256.0;
        if (fn(y, user) > 0) continue;
        for (i = 0; i < n; i++) {
            double f = r[i] < radius ? r[i] : radius, e = hypot(y[0] - x[2 * i], y[1] - x[2 * i + 1]) - f;
            if (e < best) best = e;
        }
        FUZZ_ASSERT(best <= 1e-9 * radius, "probe (%g, %g) of the domain uncovered by %g", y[0], y[1], best);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_desc d = vpds_default_desc();
    double lo[2] = {0, 0}, hi[2] = {1, 1}, xy[2 * 24], values[16 * 16];
    size_t rings[3], n_rings, total = 0, k, shape[2];
    vpds_polygon *poly = NULL;
    vpds_mask *mask = NULL;
    odd_t odd;
    vpds_sampler *s = NULL;
    vpds_status st;
    char msg[512];
    int kind = take_u8(&b) % 3, calls, stream = take_u8(&b) % 2;
    d.radius = take_double(&b, 0.03, 0.15, 0);
    d.inhibition = take_u8(&b) % 2 ? 1.0 : take_double(&b, 0.4, 1, 0);
    d.seed = take_u32(&b);
    d.budget = 3000;
    if (kind == 0) {
        vpds_polygon_desc pd = vpds_default_polygon_desc();
        n_rings = 1 + take_u8(&b) % 3;
        for (k = 0; k < n_rings; k++) {
            rings[k] = take_u8(&b) % 9; /* 0..2 vertices are refused */
            if (total + rings[k] > 24) rings[k] = 24 - total;
            total += rings[k];
        }
        for (k = 0; k < 2 * total; k++) xy[k] = take_double(&b, -0.2, 1.2, 1);
        pd.xy = xy;
        pd.ring_sizes = rings;
        pd.n_rings = n_rings;
        st = vpds_polygon_validate(&pd, msg, sizeof msg);
        check_status(st);
        poly = (vpds_polygon *)msg;
        FUZZ_ASSERT(vpds_polygon_create(&pd, &poly) == st, "validate and create disagree");
        if (st != VPDS_OK) {
            FUZZ_ASSERT(poly == NULL && msg[0], "refused without a message or with an object");
            return 0;
        }
        d.domain = vpds_polygon_sdf;
        d.domain_user = poly;
    } else if (kind == 1) {
        vpds_mask_desc md = vpds_default_mask_desc();
        shape[0] = 2 + take_u8(&b) % 15;
        shape[1] = 2 + take_u8(&b) % 15;
        for (k = 0; k < shape[0] * shape[1]; k++) values[k] = take_double(&b, 0, 1, 1);
        md.shape = shape;
        md.values = values;
        md.threshold = take_double(&b, 0, 1, 1);
        st = vpds_mask_validate(&md, msg, sizeof msg);
        check_status(st);
        mask = (vpds_mask *)msg;
        FUZZ_ASSERT(vpds_mask_create(&md, &mask) == st, "validate and create disagree");
        if (st != VPDS_OK) {
            FUZZ_ASSERT(mask == NULL && msg[0], "refused without a message or with an object");
            return 0;
        }
        d.domain = vpds_mask_sdf;
        d.domain_user = mask;
    } else {
        odd.mode = take_u8(&b) % 3;
        odd.a = take_double(&b, 0, 1, 0);
        odd.b = take_double(&b, 0.5, 4, 0);
        d.domain = odd_fn;
        d.domain_user = &odd;
    }
    FUZZ_ASSERT(vpds_create(&d, &s) == VPDS_OK, "create refused a valid descriptor");
    if (stream) {
        double x[2], t;
        for (calls = 0; calls < 60; calls++)
            if ((st = vpds_next(s, 0, x, &t)) != VPDS_OK) break;
    } else {
        for (calls = 0; calls < 100 && (st = vpds_run(s)) == VPDS_PAUSED; calls++) {}
    }
    check_status(st);
    FUZZ_ASSERT(st >= 0 || st == VPDS_ERR_DOMAIN || st == VPDS_ERR_OUT_OF_MEMORY, "status %d: %s",
                (int)st, vpds_last_error(s));
    if (st == VPDS_ERR_DOMAIN) FUZZ_ASSERT(vpds_last_error(s)[0], "domain error without a message");
    {
        size_t n = vpds_count(s), i;
        for (i = 0; i < n; i++)
            FUZZ_ASSERT(!(d.domain(vpds_points(s) + 2 * i, d.domain_user) > 0), "sample %zu outside", i);
    }
    if (stream) {
        /* conflicts at the stream's tolerance */
        size_t n = vpds_count(s), i, j;
        const double *x = vpds_points(s), *t = vpds_scales(s);
        for (i = 1; i < n; i++)
            for (j = 0; j < i; j++)
                FUZZ_ASSERT(hypot(x[2 * i] - x[2 * j], x[2 * i + 1] - x[2 * j + 1]) >=
                            t[i] * d.inhibition * d.radius * (1 - VPDS_STREAM_DOMAIN_TOLERANCE),
                            "stream samples %zu and %zu conflict", i, j);
    } else {
        check_samples(s, lo, hi, d.rule, d.inhibition);
        if (st == VPDS_OK && kind < 2) check_domain_covered(s, d.domain, d.domain_user, d.radius, &b);
    }
    vpds_destroy(s);
    vpds_polygon_destroy(poly);
    vpds_mask_destroy(mask);
    return 0;
}
