/* The 2D stream's farthest point from the Voronoi diagram (version 10) against brute force, on
 * the inputs that break triangulations: fixed points on a coarse lattice of the box (cocircular
 * and collinear ties, points on the sides and corners, duplicates), now and then one outside
 * the box (the regions then take over, exact to VPDS_STREAM_TOLERANCE), in a box of any
 * aspect. Each event's t * r is the distance from its point to the nearest earlier point, t
 * never rises, and at the end no probe
 * of a grid over the box is farther from the points than the last event's t * r. */
#include "fuzz_common.h"

#define PROBES 48

static double nearest(const double *p, size_t n, const double *y)
{
    double best = INFINITY;
    size_t i;
    for (i = 0; i < n; i++) {
        double d2 = (p[2 * i] - y[0]) * (p[2 * i] - y[0]) + (p[2 * i + 1] - y[1]) * (p[2 * i + 1] - y[1]);
        if (d2 < best) best = d2;
    }
    return sqrt(best);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_desc d = vpds_default_desc();
    double lo[2] = {0, 0}, hi[2], fixed[2 * 64], x[2], t = INFINITY, prev = INFINITY, r = 0.05;
    vpds_sampler *s = NULL;
    int lattice = 1 + take_u8(&b) % 16, n_fixed = take_u8(&b) % 64, events = 1 + take_u8(&b) % 200, i, k;
    double tol = 1e-9; /* exact; to the stream's tolerance once the regions take over */
    hi[0] = 1;
    hi[1] = 0.25 + (double)(take_u8(&b) % 16) / 4; /* a long or a tall box */
    d.lo = lo;
    d.hi = hi;
    d.radius = r;
    d.seed = take_u32(&b);
    FUZZ_ASSERT(vpds_create(&d, &s) == VPDS_OK, "create: %s", "refused");
    for (i = 0; i < n_fixed; i++) {
        uint8_t u = take_u8(&b), v = take_u8(&b);
        fixed[2 * i] = (double)(u % (lattice + 1)) / lattice;
        fixed[2 * i + 1] = hi[1] * (double)(v % (lattice + 1)) / lattice;
        if (u >= 250) { /* outside the box */
            fixed[2 * i] = 1 + (u - 249) * 0.01;
            tol = VPDS_STREAM_TOLERANCE;
        }
    }
    if (n_fixed) FUZZ_ASSERT(vpds_add_points(s, fixed, NULL, (size_t)n_fixed) == VPDS_OK, "%s", vpds_last_error(s));
    for (i = 0; i < events; i++) {
        size_t before = vpds_count(s);
        vpds_status st = vpds_next(s, 0, x, &t);
        FUZZ_ASSERT(st == VPDS_OK, "event %d: %s", i, vpds_last_error(s));
        FUZZ_ASSERT(t <= prev, "event %d: t %.17g after %.17g", i, t, prev);
        FUZZ_ASSERT(x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1], "event %d outside", i);
        if (before > 0) {
            double g = nearest(vpds_points(s), before, x);
            FUZZ_ASSERT(g <= t * r * (1 + 1e-9) && g >= t * r * (1 - tol), "event %d: its point %.17g from the set, t r %.17g",
                        i, g, t * r);
        }
        prev = t;
    }
    if (isfinite(t)) {
        double worst = 0;
        for (i = 0; i <= PROBES; i++)
            for (k = 0; k <= PROBES; k++) {
                double y[2], g;
                y[0] = lo[0] + (hi[0] - lo[0]) * i / PROBES;
                y[1] = lo[1] + (hi[1] - lo[1]) * k / PROBES;
                g = nearest(vpds_points(s), vpds_count(s) - 1, y);
                if (g > worst) worst = g;
            }
        FUZZ_ASSERT(worst <= t * r * (1 + 1e-9), "a probe %.17g from the set before the last event at t r %.17g",
                    worst, t * r);
    }
    vpds_destroy(s);
    return 0;
}
