/* Sequences of API calls decoded from the input: run, budgets, refine, next, fixed points,
 * statistics, destroy; after each call the samples keep their invariants. */
#include "fuzz_common.h"

static double ramp_fn(const double *x, void *u) { (void)u; return 0.05 + 0.2 * fabs(x[0]); }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_desc d = vpds_default_desc();
    double lo[VPDS_MAX_DIM] = {0}, hi[VPDS_MAX_DIM] = {1, 1, 1, 1, 1, 1, 1, 1};
    vpds_sampler *s = NULL;
    int ops = 0, k, periodic[VPDS_MAX_DIM] = {0};
    checked_t checked = {NULL, 0};
    d.dim = 1 + take_u8(&b) % 3;
    d.lo = lo;
    d.hi = hi;
    /* a few hundred samples at most; the ramp below gives thousands in 3D (fuzz/slow) */
    d.radius = d.dim == 1 ? 0.02 : d.dim == 2 ? 0.1 : 0.25;
    d.rule = (vpds_rule)(take_u8(&b) % 5);
    d.seed = take_u32(&b);
    if (take_u8(&b) % 2) {
        d.sizing = ramp_fn;
        d.lipschitz = 0.2;
    }
    {
        /* two radii and periodic axes (the sizing depends on |x0|: not periodic along 0) */
        uint8_t m = take_u8(&b);
        if (m & 1) {
            double v = take_double(&b, 0.3, 1.0, 1);
            d.inhibition = v >= 0.3 && v <= 1.0 ? v : 0.5;
        }
        for (k = 0; k < d.dim; k++) periodic[k] = (m >> (1 + k)) & 1 && (k > 0 || !d.sizing);
        d.periodic = periodic;
    }
    if (vpds_create(&d, &s) != VPDS_OK) {
        char msg[256];
        vpds_validate(&d, msg, sizeof msg);
        FUZZ_ASSERT(0, "create refused: %s", msg);
    }
    while (b.n && ops++ < 24) {
        vpds_status st = VPDS_OK;
        size_t count_before = vpds_count(s);
        uint8_t op = take_u8(&b) % 6;
        if (op == 0) {
            int calls;
            for (calls = 0; calls < 1000 && (st = vpds_run(s)) == VPDS_PAUSED; calls++) {}
            if (st == VPDS_OK) FUZZ_ASSERT(vpds_get_stats(s).maximal, "OK but not maximal");
        } else if (op == 1) {
            st = vpds_set_budget(s, take_u8(&b) % 3 ? take_u32(&b) % 3000 : 0);
            FUZZ_ASSERT(st == VPDS_OK, "set_budget");
        } else if (op == 2) {
            double t = take_double(&b, 0.6, 1.5, 1);
            st = vpds_refine(s, t);
            while (st == VPDS_PAUSED) st = vpds_run(s);
        } else if (op == 3) {
            vpds_stats before = vpds_get_stats(s);
            double x[VPDS_MAX_DIM], t, prev = before.maximal ? before.t : INFINITY;
            int m = 1 + take_u8(&b) % 40, batched = take_u8(&b) % 3;
            if (batched) {
                /* vpds_next_n: up to m events at once, into arrays or (batched == 2) none */
                double xs[40 * VPDS_MAX_DIM], ts[40];
                size_t got = 99, i, n0 = vpds_count(s);
                double t_min = take_u8(&b) % 4 ? 0 : take_double(&b, 0.5, 2.0, 1);
                st = vpds_next_n(s, (size_t)m, t_min, batched == 1 ? xs : NULL, batched == 1 ? ts : NULL, &got);
                FUZZ_ASSERT(got <= (size_t)m && vpds_count(s) == n0 + got, "next_n: %zu events, count %zu -> %zu",
                            got, n0, vpds_count(s));
                FUZZ_ASSERT(st != VPDS_OK || got == (size_t)m, "next_n OK after %zu of %d events", got, m);
                for (i = 0; i < got; i++) {
                    double ti = vpds_scales(s)[n0 + i];
                    FUZZ_ASSERT(ti <= prev && ti > t_min, "next_n: t %g after %g (t_min %g)", ti, prev, t_min);
                    FUZZ_ASSERT(batched == 2 || (ts[i] == ti && memcmp(xs + i * (size_t)d.dim, vpds_points(s) +
                                (n0 + i) * (size_t)d.dim, sizeof(double) * (size_t)d.dim) == 0),
                                "next_n: event %zu written differs from the one stored", i);
                    prev = ti;
                }
                if (st == VPDS_STREAM_END) st = VPDS_OK;
            } else {
                while (m-- > 0 && (st = vpds_next(s, 0, x, &t)) == VPDS_OK) {
                    FUZZ_ASSERT(t <= prev, "stream t rose: %g after %g", t, prev);
                    prev = t;
                }
            }
            /* no event's farthest point lies further below its t than the domain's tolerance */
            FUZZ_ASSERT(vpds_get_stats(s).stream_slack <= VPDS_STREAM_DOMAIN_TOLERANCE * (1 + 1e-9),
                        "stream slack %g", vpds_get_stats(s).stream_slack);
        } else if (op == 4) {
            size_t n = take_u8(&b) % 4, i;
            double x[4 * VPDS_MAX_DIM], r[4];
            int with_r = take_u8(&b) % 2;
            for (i = 0; i < n; i++) {
                for (k = 0; k < d.dim; k++) x[i * d.dim + k] = take_double(&b, -0.5, 1.5, 1);
                r[i] = take_double(&b, 0.001, 0.3, 1);
            }
            {
                size_t before = vpds_count(s);
                st = vpds_add_points(s, n ? x : NULL, with_r ? r : NULL, n);
                FUZZ_ASSERT(vpds_count(s) == (st == VPDS_OK ? before + n : before),
                            "add_points changed the count on %d", (int)st);
            }
        } else {
            vpds_stats stats = vpds_get_stats(s);
            FUZZ_ASSERT(stats.accepted + 0 <= vpds_count(s) && stats.bytes_held <= stats.peak_bytes,
                        "statistics");
        }
        check_status(st);
        if (st < 0) FUZZ_ASSERT(vpds_last_error(s)[0] != 0, "error %d without a message", (int)st);
        if (vpds_count(s) != count_before) check_new_samples(&checked, s, lo, hi, d.rule, d.inhibition, periodic);
    }
    free(checked.copy);
    vpds_destroy(s);
    return 0;
}
