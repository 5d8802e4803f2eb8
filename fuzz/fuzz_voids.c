/* The stream's farthest point from the Voronoi diagram (version 10 in 2D, 11 in 3D) against
 * brute force, on the inputs that break triangulations: fixed points on a coarse lattice of the
 * box (cocircular / cospherical and collinear / coplanar ties, points on the sides, edges and
 * corners, duplicates), now and then one outside the box (the regions then take over, exact
 * to VPDS_STREAM_TOLERANCE, as where round-off breaks a cavity: the stream's reported slack),
 * in a box of any aspect, with one radius or two. Each event's
 * t * r is the distance from its point to the nearest earlier point (two radii: the point is
 * no nearer than t * inhibition * r), t never rises, and at the end no probe of a grid over the
 * box is farther from the points than the last event's t * r. */
#include "fuzz_common.h"

static double nearest(int dim, const double *p, size_t n, const double *y)
{
    double best = INFINITY;
    size_t i;
    for (i = 0; i < n; i++) {
        double d2 = 0;
        int k;
        for (k = 0; k < dim; k++) d2 += (p[dim * i + k] - y[k]) * (p[dim * i + k] - y[k]);
        if (d2 < best) best = d2;
    }
    return sqrt(best);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t b = {data, size};
    vpds_desc d = vpds_default_desc();
    double lo[3] = {0, 0, 0}, hi[3], fixed[3 * 64], x[3], t = INFINITY, prev = INFINITY, r = 0.05;
    vpds_sampler *s = NULL;
    uint8_t grid = take_u8(&b);
    /* the high bits: two radii (the draw near the farthest point reads the triangulation) */
    double inhibition = grid & 0x10 ? 0.25 + 0.25 * (grid >> 5 & 3) : 1.0;
    int lattice = 1 + grid % 16, n_fixed = take_u8(&b) % 64, events = 1 + take_u8(&b) % 200, i, k;
    uint8_t shape = take_u8(&b);
    int dim = 2 + (shape >> 4 & 1), probes = dim == 2 ? 48 : 14;
    double tol = 1e-9; /* exact; to the stream's tolerance once the regions take over */
    long c, cells = 1;
    hi[0] = 1;
    hi[1] = 0.25 + (double)(shape % 16) / 4; /* a long or a tall box */
    hi[2] = 0.5 + (double)(shape >> 5) / 4;
    d.dim = dim;
    d.lo = lo;
    d.hi = hi;
    d.radius = r;
    d.inhibition = inhibition;
    d.seed = take_u32(&b);
    FUZZ_ASSERT(vpds_create(&d, &s) == VPDS_OK, "create: %s", "refused");
    for (i = 0; i < n_fixed; i++) {
        for (k = 0; k < dim; k++) fixed[dim * i + k] = hi[k] * (double)(take_u8(&b) % (lattice + 1)) / lattice;
        if (take_u8(&b) >= 250) { /* outside the box */
            fixed[dim * i] = 1.03;
            tol = VPDS_STREAM_TOLERANCE;
        }
    }
    if (n_fixed) FUZZ_ASSERT(vpds_add_points(s, fixed, NULL, (size_t)n_fixed) == VPDS_OK, "%s", vpds_last_error(s));
    for (i = 0; i < events; i++) {
        size_t before = vpds_count(s);
        vpds_status st = vpds_next(s, 0, x, &t);
        FUZZ_ASSERT(st == VPDS_OK, "event %d: %s", i, vpds_last_error(s));
        FUZZ_ASSERT(t <= prev, "event %d: t %.17g after %.17g", i, t, prev);
        for (k = 0; k < dim; k++) FUZZ_ASSERT(x[k] >= lo[k] && x[k] <= hi[k], "event %d outside", i);
        if (before > 0) {
            double g = nearest(dim, vpds_points(s), before, x);
            /* where the triangulation gave way (round-off in a cavity of duplicates and ties),
             * the regions took over: to the slack the stream reports, within its tolerance */
            double slack = vpds_get_stats(s).stream_slack;
            FUZZ_ASSERT(slack <= VPDS_STREAM_TOLERANCE, "event %d: stream_slack %.17g", i, slack);
            if (slack > tol) tol = slack;
            if (inhibition == 1.0)
                FUZZ_ASSERT(g <= t * r * (1 + 1e-9) && g >= t * r * (1 - tol),
                            "event %d: its point %.17g from the set, t r %.17g", i, g, t * r);
            else /* a point drawn free at t * inhibition * r (exactly: the kd-tree's test) */
                FUZZ_ASSERT(g >= t * inhibition * r * (1 - (tol > 1e-9 ? tol : 1e-12)),
                            "event %d: its point %.17g from the set, t R_f %.17g", i, g, t * inhibition * r);
        }
        prev = t;
    }
    if (isfinite(t)) {
        double worst = 0;
        for (k = 0; k < dim; k++) cells *= probes + 1;
        for (c = 0; c < cells; c++) {
            double y[3], g;
            long rest = c;
            for (k = 0; k < dim; k++) {
                y[k] = lo[k] + (hi[k] - lo[k]) * (double)(rest % (probes + 1)) / probes;
                rest /= probes + 1;
            }
            g = nearest(dim, vpds_points(s), vpds_count(s) - 1, y);
            if (g > worst) worst = g;
        }
        FUZZ_ASSERT(worst <= t * r * (1 + 1e-9), "a probe %.17g from the set before the last event at t r %.17g",
                    worst, t * r);
    }
    vpds_destroy(s);
    return 0;
}
