/* Tilings from arbitrary parameters (dim, tiles per axis, periodic axes, rule, radii, scale, a
 * ramp sizing), validated and created, then run whole with vpds_tiling_run on 0-3 threads and
 * again on one: the same bytes, every sample in the box, none in conflict with an earlier one in
 * the order (phase, tile, insertion); every refusal has a message and leaves no object. */
#include "fuzz_common.h"

typedef struct { double a, slope; int dim; } ramp_t;
static double ramp_fn(const double *x, void *u)
{
    const ramp_t *r = (const ramp_t *)u;
    return r->a + r->slope * fabs(x[0]);
}

static void check_union(const vpds_tiled *a, const double *lo, const double *hi, const int *per,
                        int rule, double inhibition, double scale)
{
    size_t n = vpds_tiled_count(a), i, j;
    int d = vpds_tiled_dim(a), k;
    const double *x = vpds_tiled_points(a), *r = vpds_tiled_radii(a);
    for (i = 0; i < n; i++) {
        for (k = 0; k < d; k++)
            FUZZ_ASSERT(x[i * d + k] >= lo[k] && x[i * d + k] <= hi[k], "sample %zu outside the box", i);
        for (j = 0; j < i; j++) {
            double d2 = 0, f = scale * inhibition * rule_f((vpds_rule)rule, r[j], r[i]);
            for (k = 0; k < d; k++) {
                double e = fabs(x[i * d + k] - x[j * d + k]), P = hi[k] - lo[k];
                if (per[k] && e > 0.5 * P) e = P - e;
                d2 += e * e;
            }
            FUZZ_ASSERT(!(d2 < f * f * (1 - 1e-9)), "samples %zu and %zu conflict", j, i);
        }
    }
}

/* The same tiling as a job in steps of at most max_tiles (0: all) on `threads` threads: the
 * progress grows by at most max_tiles a step, the result is refused before the end, and it is
 * the bytes of the one-thread run. */
static void check_job(const vpds_tiling *tg, int threads, uint64_t max_tiles, const vpds_tiled *one)
{
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    vpds_tiling_job *job = NULL;
    vpds_tiled *out = NULL;
    uint64_t before = 0, count = vpds_tiling_count(tg), steps = 0;
    vpds_status st;
    char msg[512];
    rd.threads = threads;
    rd.callbacks_thread_safe = 1;
    FUZZ_ASSERT(vpds_tiling_job_create(tg, &rd, &job, msg, sizeof msg) == VPDS_OK, "job: %s", msg);
    do {
        uint64_t now;
        if (before < count)
            FUZZ_ASSERT(vpds_tiling_job_result(job, &out, msg, sizeof msg) == VPDS_ERR_STATE && !out,
                        "a result before the end");
        st = vpds_tiling_job_step(job, max_tiles, msg, sizeof msg);
        now = vpds_tiling_job_tiles_done(job);
        FUZZ_ASSERT(now > before && (max_tiles == 0 || now - before <= max_tiles),
                    "a step of %u tiles went from %llu to %llu", (unsigned)max_tiles,
                    (unsigned long long)before, (unsigned long long)now);
        before = now;
    } while (st == VPDS_PAUSED && ++steps <= count);
    FUZZ_ASSERT(st == VPDS_OK && before == count, "job ended with %d: %s", (int)st, msg);
    FUZZ_ASSERT(vpds_tiling_job_result(job, &out, msg, sizeof msg) == VPDS_OK, "result: %s", msg);
    FUZZ_ASSERT(vpds_tiled_count(out) == vpds_tiled_count(one) &&
                    memcmp(vpds_tiled_points(out), vpds_tiled_points(one),
                           vpds_tiled_count(one) * (size_t)vpds_tiled_dim(one) * sizeof(double)) == 0 &&
                    memcmp(vpds_tiled_tiles(out), vpds_tiled_tiles(one),
                           vpds_tiled_count(one) * sizeof(uint64_t)) == 0,
                "a job in steps of %u on %d threads differs from one run", (unsigned)max_tiles, threads);
    vpds_tiled_destroy(out);
    vpds_tiling_job_destroy(job);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    double lo[3], hi[3], vol = 1;
    uint64_t tiles[3];
    int per[3] = {0, 0, 0}, k;
    vpds_tiling *tg = NULL;
    vpds_tiled *a = NULL, *one = NULL;
    vpds_status st;
    char msg[512];
    ramp_t ramp;
    d.dim = 1 + take_u8(&b) % 3;
    for (k = 0; k < d.dim; k++) {
        lo[k] = take_double(&b, -1, 1, 0);
        hi[k] = lo[k] + take_double(&b, 0.5, 2, 0);
        vol *= hi[k] - lo[k];
        per[k] = take_u8(&b) % 4 == 0;
        tiles[k] = (uint64_t)(take_u8(&b) % 5); /* 0 and odd counts on periodic axes are refused */
    }
    d.lo = lo;
    d.hi = hi;
    d.periodic = per;
    d.rule = (vpds_rule)(take_u8(&b) % 5);
    d.seed = take_u32(&b);
    /* at most about 600 samples: the brute-force check is quadratic */
    d.radius = pow(vol / 100.0, 1.0 / d.dim) * (1 + take_double(&b, 0, 2, 0));
    if (take_u8(&b) % 2) {
        ramp.a = d.radius;
        ramp.slope = take_double(&b, 0, 0.4, 0);
        ramp.dim = d.dim;
        d.sizing = ramp_fn;
        d.sizing_user = &ramp;
        d.lipschitz = ramp.slope;
        d.radius_max = ramp.a + ramp.slope * (fabs(lo[0]) > fabs(hi[0]) ? fabs(lo[0]) : fabs(hi[0]));
        per[0] = 0; /* the ramp is not periodic along axis 0 */
    }
    if (take_u8(&b) % 3 == 0) d.inhibition = take_double(&b, 0.4, 1, 0);
    td.sampler = &d;
    td.tiles = tiles;
    td.scale = take_double(&b, 0.8, 1.5, 0);
    st = vpds_tiling_validate(&td, msg, sizeof msg);
    check_status(st);
    FUZZ_ASSERT(vpds_tiling_create(&td, &tg) == st, "validate and create disagree");
    if (st != VPDS_OK) {
        FUZZ_ASSERT(tg == NULL && msg[0], "refused without a message or with an object");
        return 0;
    }
    rd.threads = take_u8(&b) % 4;
    rd.callbacks_thread_safe = 1; /* ramp_fn only reads */
    st = vpds_tiling_run(tg, &rd, &a, msg, sizeof msg);
    check_status(st);
    if (st == VPDS_OK) {
        rd.threads = 1;
        FUZZ_ASSERT(vpds_tiling_run(tg, &rd, &one, msg, sizeof msg) == VPDS_OK, "one thread: %s", msg);
        FUZZ_ASSERT(vpds_tiled_count(a) == vpds_tiled_count(one) &&
                    memcmp(vpds_tiled_points(a), vpds_tiled_points(one),
                           vpds_tiled_count(a) * (size_t)d.dim * sizeof(double)) == 0,
                    "%d threads and one differ", rd.threads);
        check_union(a, lo, hi, per, d.rule, d.inhibition, td.scale);
        check_job(tg, take_u8(&b) % 4, take_u8(&b) % 8, one);
    } else {
        FUZZ_ASSERT(a == NULL && msg[0], "failed without a message or with a result: %d", (int)st);
    }
    vpds_tiled_destroy(a);
    vpds_tiled_destroy(one);
    vpds_tiling_destroy(tg);
    return 0;
}
