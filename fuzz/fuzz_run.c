/* Descriptor validation, create and run with arbitrary parameters (bounded so that each input
 * stays small), then the output's invariants: conflict-free, inside the box, covered.
 * Modes (first byte): 255 any dim, 254 any box, 253 any rule, 252 any radius, 251 an L too
 * small, 250 any inhibition, 249 a bad struct size, 248 periodic axes, 247 periodic axes and two
 * radii (inhibition < coverage), 246 an estimate at any scale and a memory limit (lifted after
 * the run, which must then finish as if there had been none). */
#include "fuzz_common.h"

typedef struct { double a, slope; int dim; } ramp_t;
static double ramp_fn(const double *x, void *u)
{
    const ramp_t *r = (const ramp_t *)u;
    return r->a + r->slope * fabs(x[0]);
}
static int ramp_batch(const double *x, size_t n, double *out, void *u)
{
    const ramp_t *r = (const ramp_t *)u;
    size_t i;
    for (i = 0; i < n; i++) out[i] = r->a + r->slope * fabs(x[i * (size_t)r->dim]);
    return 0;
}

/* An estimate is OK with every field >= 0 (never NaN), or a refusal of t with a message. */
static void check_estimate_and_limit(vpds_sampler *s, bytes_t *b)
{
    vpds_run_estimate e;
    double t = take_double(b, 0.2, 4, 1);
    vpds_status st = vpds_estimate(s, t, &e);
    check_status(st);
    if (st == VPDS_OK) {
        FUZZ_ASSERT(e.samples >= 0 && e.base_cells >= 1 && e.cells >= 0 && e.bytes > 0,
                    "estimate at t = %g: %g samples, %g base cells, %g cells, %g bytes", t, e.samples,
                    e.base_cells, e.cells, e.bytes);
    } else {
        FUZZ_ASSERT(st == VPDS_ERR_INVALID_ARGUMENT && vpds_last_error(s)[0] != 0,
                    "estimate at t = %g: status %d, %s", t, (int)st, vpds_last_error(s));
    }
    /* 1 KB to 64 MB: refused up front, failed mid-run, or enough */
    vpds_set_memory_limit(s, ((size_t)1 << (10 + take_u8(b) % 16)) + take_u32(b) % 1024);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_desc d = vpds_default_desc();
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], vol = 1;
    int k, kind, calls, per[VPDS_MAX_DIM];
    const int *periodic = NULL;
    char msg[512];
    vpds_sampler *s = NULL;
    vpds_status st;
    ramp_t ramp;
    uint8_t mode = take_u8(&b);
    d.dim = 1 + take_u8(&b) % 4;
    if (mode == 255) d.dim = (int)(int8_t)take_u8(&b); /* any dim, valid or not */
    for (k = 0; k < VPDS_MAX_DIM; k++) {
        lo[k] = take_double(&b, -2, 2, mode == 254);
        hi[k] = lo[k] + take_double(&b, 0.2, 2, mode == 254);
        if (k < d.dim && k >= 0) vol *= hi[k] - lo[k];
    }
    d.lo = lo;
    d.hi = hi;
    d.rule = (vpds_rule)(take_u8(&b) % (mode == 253 ? 7 : 5));
    d.seed = take_u32(&b);
    d.budget = 1 + take_u32(&b) % 2000; /* with at most 100 calls below: bounded work per input */
    kind = take_u8(&b) % 3;
    ramp.dim = d.dim;
    if (d.dim >= 1 && d.dim <= VPDS_MAX_DIM) {
        /* keep the count of samples below about a thousand: disks of radius r / 2 around the
         * samples do not overlap, so there are at most vol / (V_d (r / 2)^d) of them (boundary
         * aside), V_d the unit ball's volume; vol / r^d alone let a 16D run make 58,729 samples
         * (a 38 s input: in 16D that ball is 2^16 / 0.235 times smaller than r^d) */
        double ball = pow(3.141592653589793, 0.5 * d.dim) / tgamma(0.5 * d.dim + 1);
        double r_floor = 2 * pow(vol / (150.0 * ball), 1.0 / d.dim);
        d.radius = r_floor * (1 + take_double(&b, 0, 3, mode == 252));
        if (kind > 0) {
            ramp.a = d.radius;
            d.weighted = take_u8(&b) % 4 == 0;
            ramp.slope = take_double(&b, 0, 0.45, 0);
            if (d.weighted) ramp.slope *= 0.1; /* the weighted process slows as r varies more */
            d.lipschitz = ramp.slope * (mode == 251 ? 0.5 : 1.0); /* 251: a declared L too small */
            d.sizing_user = &ramp;
            if (kind == 1) d.sizing = ramp_fn;
            else d.sizing_batch = ramp_batch;
            d.radius_min = d.weighted ? ramp.a : 0;
        }
    }
    if (mode == 250) d.inhibition = take_double(&b, 0.1, 2, 1);
    if (mode == 249) d.struct_size ^= 8;
    if (mode == 248 || mode == 247) {
        uint8_t bits = take_u8(&b);
        /* the ramp is not periodic along axis 0: keep that axis a plain one with a sizing */
        for (k = 0; k < VPDS_MAX_DIM; k++) per[k] = (bits >> k) & 1 && !(k == 0 && kind > 0);
        d.periodic = periodic = per;
        if (mode == 247) d.inhibition = take_double(&b, 0.3, 1, 0);
    }
    st = vpds_validate(&d, msg, sizeof msg);
    check_status(st);
    {
        vpds_status created = vpds_create(&d, &s);
        FUZZ_ASSERT(created == st, "validate %d but create %d", (int)st, (int)created);
        if (created != VPDS_OK) {
            FUZZ_ASSERT(s == NULL && msg[0] != 0, "refused without a message or with a sampler");
            return 0;
        }
    }
    if (mode == 246) check_estimate_and_limit(s, &b);
    for (calls = 0; calls < 100 && (st = vpds_run(s)) == VPDS_PAUSED; calls++) {}
    check_status(st);
    if (mode == 246 && st == VPDS_ERR_OUT_OF_MEMORY) {
        FUZZ_ASSERT(strstr(vpds_last_error(s), "memory limit") != NULL, "out of memory under a limit "
                    "without saying so: %s", vpds_last_error(s));
        vpds_set_memory_limit(s, 0);
        for (calls = 0; calls < 100 && (st = vpds_run(s)) == VPDS_PAUSED; calls++) {}
        check_status(st);
    }
    check_samples_on(s, lo, hi, d.rule, d.inhibition, periodic);
    if (st == VPDS_OK) {
        FUZZ_ASSERT(vpds_get_stats(s).maximal, "run returned OK but not maximal");
        if (kind == 0) check_covered_on(s, lo, hi, d.radius, d.coverage, periodic, &b);
    } else if (st != VPDS_PAUSED) {
        /* the documented ways a valid descriptor's run can stop */
        /* with a sizing, a periodic side too short for r_max is found at run time */
        FUZZ_ASSERT((st == VPDS_ERR_LIPSCHITZ && mode == 251) || st == VPDS_ERR_OVERFLOW ||
                    (st == VPDS_ERR_INVALID_ARGUMENT && periodic && kind > 0) ||
                    st == VPDS_ERR_OUT_OF_MEMORY, "run failed: %s", vpds_last_error(s));
        FUZZ_ASSERT(vpds_last_error(s)[0] != 0, "error %d without a message", (int)st);
    }
    vpds_destroy(s);
    return 0;
}
