/* Version 10's farthest point in 2D (delaunay.c, voids.c), against brute force and against
 * the exact search of version 9 (gap.c, a different algorithm):
 * - the triangulation: counter-clockwise triangles whose neighbours point back, 2n + 1 of them,
 *   and no point inside a circumcircle (brute force) on random points, a lattice full of
 *   cocircular ties, points on the box's sides, duplicates;
 * - the farthest point: its gap is its distance to the nearest point, and version 9's stream
 *   given the same points (as fixed points) finds the same largest gap;
 * - the stream: at checkpoints along 3,000 events, in a long box, after a run, with two radii,
 *   and after a fixed point outside the box (where the regions take over), each event's t is
 *   the largest gap version 9 finds for the points before it. */
#include "check.h"
#include "failing_alloc.h"
#include "vpds.h"
#include "voids.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int quick;
static unsigned long long rng_state = 2024;
static double unit(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

static const double *pt(const vpdsi_dt *dt, const double *pts, uint32_t v)
{
    return vpdsi_dt_point(dt, pts, v);
}

static double orient(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* The triangulation of pts[0, n) (inserted in order) is a valid Delaunay triangulation. */
static void check_triangulation(const double *pts, size_t n, const double *lo, const double *hi,
                                const char *what)
{
    vpdsi_mem m;
    vpdsi_dt dt;
    size_t i, t, dups = 0, bad_orient = 0, bad_link = 0, inside = 0;
    vpdsi_mem_init(&m, NULL);
    CHECK(vpdsi_dt_init(&dt, &m, lo, hi) == 0);
    for (i = 0; i < n; i++) {
        int e = vpdsi_dt_insert(&dt, &m, pts, i, VPDSI_DT_NONE);
        CHECK_MSG(e == 0 || e == 1, "%s: insert %zu gave %d", what, i, e);
        dups += e == 1;
    }
    CHECK_MSG(dt.n_tri == 2 * (n - dups) + 1, "%s: %zu triangles for %zu points", what, dt.n_tri, n - dups);
    for (t = 0; t < dt.n_tri; t++) {
        const uint32_t *v = dt.tv + 3 * t;
        double cx, cy, r2;
        int k;
        bad_orient += !(orient(pt(&dt, pts, v[0]), pt(&dt, pts, v[1]), pt(&dt, pts, v[2])) > 0);
        for (k = 0; k < 3; k++) {
            uint32_t u = dt.tn[3 * t + (size_t)k], a = v[(k + 1) % 3], b = v[(k + 2) % 3];
            int back = 0, w;
            if (u == VPDSI_DT_NONE) {
                bad_link += a >= VPDSI_DT_FAR || b >= VPDSI_DT_FAR; /* only the far edges are open */
                continue;
            }
            for (w = 0; w < 3; w++)
                back += dt.tn[3 * (size_t)u + (size_t)w] == t && dt.tv[3 * (size_t)u + (size_t)w] != a &&
                        dt.tv[3 * (size_t)u + (size_t)w] != b;
            bad_link += back != 1;
        }
        if (v[0] < VPDSI_DT_FAR || v[1] < VPDSI_DT_FAR || v[2] < VPDSI_DT_FAR) continue;
        { /* the empty circle, with a margin for the round-off of the centre */
            const double *a = pt(&dt, pts, v[0]), *b = pt(&dt, pts, v[1]), *c = pt(&dt, pts, v[2]);
            double bx = b[0] - a[0], by = b[1] - a[1], qx = c[0] - a[0], qy = c[1] - a[1];
            double den = 2 * (bx * qy - by * qx);
            cx = a[0] + (qy * (bx * bx + by * by) - by * (qx * qx + qy * qy)) / den;
            cy = a[1] + (bx * (qx * qx + qy * qy) - qx * (bx * bx + by * by)) / den;
            r2 = (a[0] - cx) * (a[0] - cx) + (a[1] - cy) * (a[1] - cy);
            for (i = 0; i < n; i++) {
                double d2 = (pts[2 * i] - cx) * (pts[2 * i] - cx) + (pts[2 * i + 1] - cy) * (pts[2 * i + 1] - cy);
                inside += d2 < r2 * (1 - 1e-9);
            }
        }
    }
    CHECK_MSG(bad_orient == 0 && bad_link == 0 && inside == 0,
              "%s: %zu triangles not counter-clockwise, %zu bad links, %zu points inside a circumcircle",
              what, bad_orient, bad_link, inside);
    vpdsi_dt_release(&dt, &m);
    CHECK(m.held == 0);
}

static void shuffle(double *p, size_t n)
{
    size_t i;
    for (i = n; i > 1; i--) {
        size_t j = (size_t)(unit() * (double)i);
        double x = p[2 * (i - 1)], y = p[2 * (i - 1) + 1];
        p[2 * (i - 1)] = p[2 * j];
        p[2 * (i - 1) + 1] = p[2 * j + 1];
        p[2 * j] = x;
        p[2 * j + 1] = y;
    }
}

static void check_triangulations(void)
{
    static const double lo[2] = {0, 0}, hi[2] = {1, 1};
    size_t n = quick ? 300 : 2000, i, j, g = 21;
    double *p = (double *)malloc(2 * n * sizeof(double)), *q = (double *)malloc(2 * g * g * sizeof(double));
    for (i = 0; i < 2 * n; i++) p[i] = unit();
    check_triangulation(p, n, lo, hi, "uniform points");
    for (i = 0; i < g; i++)
        for (j = 0; j < g; j++) {
            q[2 * (i * g + j)] = (double)i / (double)(g - 1);
            q[2 * (i * g + j) + 1] = (double)j / (double)(g - 1);
        }
    check_triangulation(q, g * g, lo, hi, "a lattice in row order");
    shuffle(q, g * g);
    check_triangulation(q, g * g, lo, hi, "a lattice shuffled");
    for (i = 0; i < n; i++) { /* on the sides, the corners among them, some twice */
        int side = (int)(unit() * 4);
        double s = i % 7 == 0 ? 0.0 : i % 11 == 0 ? 1.0 : unit();
        p[2 * i + (side & 1)] = side & 2 ? 1.0 : 0.0;
        p[2 * i + 1 - (side & 1)] = s;
    }
    check_triangulation(p, n, lo, hi, "points on the sides");
    free(p);
    free(q);
}

/* Version 9's largest gap of points p[0, n) (fixed points of radius r) in the box: its first
 * event's t times r. */
static double gap_v9(const double *p, size_t n, const double *lo, const double *hi, double r)
{
    vpds_desc desc = vpds_default_desc();
    vpds_sampler *s = NULL;
    double x[2], t = -1;
    desc.lo = lo;
    desc.hi = hi;
    desc.radius = r;
    desc.algorithm_version = 9;
    CHECK(vpds_create(&desc, &s) == VPDS_OK);
    if (!s) return -1;
    CHECK(vpds_add_points(s, p, NULL, n) == VPDS_OK);
    CHECK(vpds_next(s, 0, x, &t) == VPDS_OK);
    vpds_destroy(s);
    return t * r;
}

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

static void check_farthest(size_t n, const double *lo, const double *hi, int reps)
{
    double *p = (double *)malloc(2 * n * sizeof(double));
    int rep;
    for (rep = 0; rep < reps; rep++) {
        vpdsi_mem m;
        vpdsi_voids vd;
        double y[2], g, oracle;
        size_t i;
        vpdsi_mem_init(&m, NULL);
        vpdsi_voids_init(&vd);
        for (i = 0; i < n; i++) {
            p[2 * i] = lo[0] + unit() * (hi[0] - lo[0]);
            p[2 * i + 1] = lo[1] + unit() * (hi[1] - lo[1]);
        }
        CHECK(vpdsi_voids_sync(&vd, &m, lo, hi, p, n, INFINITY) == 0);
        g = sqrt(vpdsi_voids_farthest(&vd, p, y));
        CHECK(y[0] >= lo[0] && y[0] <= hi[0] && y[1] >= lo[1] && y[1] <= hi[1]);
        CHECK_MSG(fabs(nearest(p, n, y) / g - 1) < 1e-12, "%zu points: gap %.17g at its point, %.17g said",
                  n, nearest(p, n, y), g);
        oracle = gap_v9(p, n, lo, hi, 0.1);
        CHECK_MSG(fabs(oracle / g - 1) < 1e-9, "%zu points: largest gap %.17g, version 9 %.17g", n, g, oracle);
        vpdsi_voids_release(&vd, &m);
        CHECK(m.held == 0);
    }
    free(p);
}

/* A version-10 stream of n events (one_radius: R_f = R_c, so each sample is the farthest point) from the sampler s; at each checkpoint k, event k's t * r
 * equals version 9's largest gap of the points before it. */
static void check_stream_oracle(vpds_sampler *s, size_t n, const double *lo, const double *hi, double r,
                                int one_radius, const char *what)
{
    size_t i, start = vpds_count(s);
    double inhibition = one_radius ? 1.0 : 0.5; /* the two radii of these tests: R_f = 0.5 R_c */
    for (i = 0; i < n; i++) {
        double x[2], t;
        size_t k = vpds_count(s);
        vpds_status e = vpds_next(s, 0, x, &t);
        CHECK_MSG(e == VPDS_OK, "%s: event %zu: %s", what, i, vpds_last_error(s));
        if (e != VPDS_OK) return;
        /* every sample keeps off those before it, by brute force: a draw near the farthest
         * point (two radii, tested against the triangulation's neighbours) exactly, the
         * regions' farthest point (after a point outside the box) within their tolerance */
        if (k > 0)
            CHECK_MSG(nearest(vpds_points(s), k, x) >= t * inhibition * r * (1 - (one_radius ? VPDS_STREAM_TOLERANCE : 1e-12)),
                      "%s: event %zu at %.17g from the set, t R_f %.17g", what, i, nearest(vpds_points(s), k, x),
                      t * inhibition * r);
        if (k > 0 && (i < 12 || i % (n / 6) == 0 || i + 1 == n)) {
            double oracle = gap_v9(vpds_points(s), k, lo, hi, r);
            if (one_radius) /* the sample is the farthest point */
                CHECK_MSG(fabs(nearest(vpds_points(s), k, x) / (t * r) - 1) < 1e-10,
                          "%s: event %zu at %.17g from the set, t r %.17g", what, i, nearest(vpds_points(s), k, x), t * r);
            CHECK_MSG(fabs(oracle / (t * r) - 1) < 1e-9, "%s: event %zu (of %zu samples): t r %.17g, version 9 %.17g",
                      what, i, k, t * r, oracle);
        }
    }
    CHECK(vpds_count(s) == start + n);
}

/* After a run, each allocation of the stream (the run's samples go into the triangulation in
 * one batch, in Morton order) fails once in turn: the retry goes on, and the events are those
 * of a stream without failures. */
static void check_allocation_failures(double inhibition)
{
    enum { N = 40 };
    vpds_desc d = vpds_default_desc();
    double ref[2 * N], ref_t[N], x[2 * N], t[N];
    failing_alloc fa;
    vpds_sampler *s = NULL;
    size_t k, i, base, total, failures = 0;
    d.radius = 0.02;
    d.inhibition = inhibition;
    d.seed = 11;
    d.allocator.alloc = fa_alloc;
    d.allocator.free = fa_free;
    d.allocator.user = &fa;
    memset(&fa, 0, sizeof fa);
    CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
    base = fa.calls;
    for (i = 0; i < N; i++) CHECK(vpds_next(s, 0, ref + 2 * i, ref_t + i) == VPDS_OK);
    total = fa.calls - base;
    vpds_destroy(s);
    for (k = 1; k <= total; k++) {
        vpds_status st = VPDS_OK;
        memset(&fa, 0, sizeof fa);
        CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
        fa.fail_at = fa.calls + k;
        for (i = 0; i < N;) {
            st = vpds_next(s, 0, x + 2 * i, t + i);
            if (st == VPDS_ERR_OUT_OF_MEMORY) {
                failures++;
                continue;
            }
            if (st != VPDS_OK) break;
            i++;
        }
        CHECK_MSG(st == VPDS_OK && memcmp(x, ref, sizeof x) == 0 && memcmp(t, ref_t, sizeof t) == 0,
                  "the stream after a run differs after failing allocation %zu", k);
        vpds_destroy(s);
        CHECK_MSG(fa.live == 0, "leak after failing allocation %zu", k);
    }
    CHECK(failures > 0);
    printf("stream after a run, inhibition %g, allocation failures: %zu allocations, %zu failed once each\n",
           inhibition, total, failures);
}

/* 3D (version 11): each event's t * r is the distance from its point to the samples before it
 * (brute force), t never rises, at checkpoints it equals version 10's largest gap (the regions'
 * exact search) of the points before it, and at the end no probe of a grid is farther. */
static double nearest3(const double *p, size_t n, const double *y)
{
    double best = INFINITY;
    size_t i;
    for (i = 0; i < n; i++) {
        double d2 = (p[3 * i] - y[0]) * (p[3 * i] - y[0]) + (p[3 * i + 1] - y[1]) * (p[3 * i + 1] - y[1]) +
                    (p[3 * i + 2] - y[2]) * (p[3 * i + 2] - y[2]);
        if (d2 < best) best = d2;
    }
    return sqrt(best);
}

static double gap3_v10(const double *p, size_t n, const double *lo, const double *hi, double r)
{
    vpds_desc desc = vpds_default_desc();
    vpds_sampler *s = NULL;
    double x[3], t = -1;
    desc.dim = 3;
    desc.lo = lo;
    desc.hi = hi;
    desc.radius = r;
    desc.algorithm_version = 10;
    CHECK(vpds_create(&desc, &s) == VPDS_OK);
    if (!s) return -1;
    CHECK(vpds_add_points(s, p, NULL, n) == VPDS_OK);
    CHECK(vpds_next(s, 0, x, &t) == VPDS_OK);
    vpds_destroy(s);
    return t * r;
}

static void check_stream3(vpds_sampler *s, size_t n, const double *lo, const double *hi, double r, int one_radius,
                          int grid, const char *what)
{
    size_t i, start = vpds_count(s);
    double prev = INFINITY, t = INFINITY, worst = 0;
    long c, cells;
    for (i = 0; i < n; i++) {
        double x[3];
        size_t k = vpds_count(s);
        vpds_status e = vpds_next(s, 0, x, &t);
        CHECK_MSG(e == VPDS_OK, "%s: event %zu: %s", what, i, vpds_last_error(s));
        if (e != VPDS_OK) return;
        CHECK(t <= prev);
        prev = t;
        if (k > 0 && one_radius)
            CHECK_MSG(fabs(nearest3(vpds_points(s), k, x) / (t * r) - 1) < 1e-10, "%s: event %zu at %.17g, t r %.17g",
                      what, i, nearest3(vpds_points(s), k, x), t * r);
        if (k > 0 && (i < 12 || i % (n / 5) == 0 || i + 1 == n)) {
            double oracle = gap3_v10(vpds_points(s), k, lo, hi, r);
            CHECK_MSG(fabs(oracle / (t * r) - 1) < 1e-9, "%s: event %zu (of %zu samples): t r %.17g, version 10 %.17g",
                      what, i, k, t * r, oracle);
        }
    }
    for (cells = 1, c = 0; c < 3; c++) cells *= grid + 1;
    for (c = 0; c < cells; c++) {
        double q[3], g;
        long rest = c;
        int k;
        for (k = 0; k < 3; k++) {
            q[k] = lo[k] + (hi[k] - lo[k]) * (double)(rest % (grid + 1)) / grid;
            rest /= grid + 1;
        }
        g = nearest3(vpds_points(s), vpds_count(s) - 1, q);
        if (g > worst) worst = g;
    }
    CHECK_MSG(worst <= t * r * (1 + 1e-9), "%s: a probe %.17g from the set before the last event, t r %.17g", what,
              worst, t * r);
    CHECK(vpds_count(s) == start + n);
}

static vpds_sampler *make3(const double *lo, const double *hi, double r, double inhibition, uint64_t seed)
{
    vpds_desc desc = vpds_default_desc();
    vpds_sampler *s = NULL;
    desc.dim = 3;
    desc.lo = lo;
    desc.hi = hi;
    desc.radius = r;
    desc.inhibition = inhibition;
    desc.seed = seed;
    CHECK(vpds_create(&desc, &s) == VPDS_OK);
    return s;
}

static void check_3d(void)
{
    static const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, llo[3] = {-1, 0, 0.5}, lhi[3] = {2, 0.5, 1.25};
    vpds_sampler *s = make3(lo, hi, 0.05, 1, 3);
    if (s) check_stream3(s, quick ? 300 : 2000, lo, hi, 0.05, 1, quick ? 12 : 24, "3D unit cube");
    vpds_destroy(s);
    s = make3(llo, lhi, 0.05, 1, 4);
    if (s) check_stream3(s, quick ? 300 : 1500, llo, lhi, 0.05, 1, quick ? 12 : 20, "3D long box");
    vpds_destroy(s);
    s = make3(lo, hi, 0.05, 0.5, 5);
    if (s) check_stream3(s, quick ? 200 : 800, lo, hi, 0.05, 0, 12, "3D two radii");
    vpds_destroy(s);
    s = make3(lo, hi, 0.08, 1, 6);
    if (s) {
        CHECK(vpds_run(s) == VPDS_OK);
        check_stream3(s, quick ? 50 : 300, lo, hi, 0.08, 1, 16, "3D after a run");
    }
    vpds_destroy(s);
    s = make3(lo, hi, 0.05, 1, 7); /* a lattice of fixed points: cospherical ties, points on faces and edges */
    if (s) {
        double f[3 * 125];
        int a, b, c;
        for (a = 0; a < 5; a++)
            for (b = 0; b < 5; b++)
                for (c = 0; c < 5; c++) {
                    f[3 * (25 * a + 5 * b + c)] = a / 4.0;
                    f[3 * (25 * a + 5 * b + c) + 1] = b / 4.0;
                    f[3 * (25 * a + 5 * b + c) + 2] = c / 4.0;
                }
        CHECK(vpds_add_points(s, f, NULL, 125) == VPDS_OK);
        check_stream3(s, quick ? 200 : 1000, lo, hi, 0.05, 1, 16, "3D after a lattice");
    }
    vpds_destroy(s);
}

static vpds_sampler *make(const double *lo, const double *hi, double r, double inhibition, uint64_t seed)
{
    vpds_desc desc = vpds_default_desc();
    vpds_sampler *s = NULL;
    desc.lo = lo;
    desc.hi = hi;
    desc.radius = r;
    desc.inhibition = inhibition;
    desc.seed = seed;
    CHECK(vpds_create(&desc, &s) == VPDS_OK);
    return s;
}

int main(void)
{
    static const double unit_lo[2] = {0, 0}, unit_hi[2] = {1, 1};
    static const double long_lo[2] = {-1, 0.5}, long_hi[2] = {3, 1.25};
    size_t n;
    vpds_sampler *s;
    quick = getenv("VPDS_TEST_QUICK") != NULL;
    check_triangulations();
    for (n = 1; n <= 40; n++) check_farthest(n, unit_lo, unit_hi, quick ? 1 : 4);
    check_farthest(500, unit_lo, unit_hi, quick ? 1 : 5);
    check_farthest(200, long_lo, long_hi, quick ? 1 : 5);

    s = make(unit_lo, unit_hi, 0.05, 1, 3);
    if (s) check_stream_oracle(s, quick ? 300 : 3000, unit_lo, unit_hi, 0.05, 1, "unit square");
    vpds_destroy(s);
    s = make(long_lo, long_hi, 0.05, 1, 4);
    if (s) check_stream_oracle(s, quick ? 300 : 2000, long_lo, long_hi, 0.05, 1, "long box");
    vpds_destroy(s);
    s = make(unit_lo, unit_hi, 0.05, 0.5, 5);
    if (s) check_stream_oracle(s, quick ? 200 : 1000, unit_lo, unit_hi, 0.05, 0, "two radii");
    vpds_destroy(s);
    s = make(unit_lo, unit_hi, 0.03, 1, 6); /* after a maximal run */
    if (s) {
        CHECK(vpds_run(s) == VPDS_OK);
        check_stream_oracle(s, quick ? 100 : 600, unit_lo, unit_hi, 0.03, 1, "after a run");
    }
    vpds_destroy(s);
    s = make(unit_lo, unit_hi, 0.05, 1, 7); /* a fixed point outside the box: the regions */
    if (s) {
        static const double outside[2] = {1.02, 0.5}, inside[2] = {0.25, 0.25};
        check_stream_oracle(s, 50, unit_lo, unit_hi, 0.05, 1, "before a fixed point outside");
        CHECK(vpds_add_points(s, inside, NULL, 1) == VPDS_OK);
        check_stream_oracle(s, 50, unit_lo, unit_hi, 0.05, 1, "after a fixed point inside");
        CHECK(vpds_add_points(s, outside, NULL, 1) == VPDS_OK);
        check_stream_oracle(s, 100, unit_lo, unit_hi, 0.05, 1, "after a fixed point outside");
    }
    vpds_destroy(s);
    /* after a run, a fixed point outside: the regions take over and read the kd-tree, which the
     * triangulation's events left behind; then a refinement keeps off every sample */
    s = make(unit_lo, unit_hi, 0.03, 1, 8);
    if (s) {
        static const double outside[2] = {-0.01, 0.5};
        size_t i, j, n_fixed, bad = 0;
        double tau;
        CHECK(vpds_run(s) == VPDS_OK);
        check_stream_oracle(s, 100, unit_lo, unit_hi, 0.03, 1, "after a run (2)");
        n_fixed = vpds_count(s);
        CHECK(vpds_add_points(s, outside, NULL, 1) == VPDS_OK);
        check_stream_oracle(s, 100, unit_lo, unit_hi, 0.03, 1, "after a run and a fixed point outside");
        tau = 0.7 * vpds_scales(s)[vpds_count(s) - 1];
        CHECK(vpds_refine(s, tau) == VPDS_OK);
        n = vpds_count(s);
        for (j = 1; j < n; j++)
            for (i = 0; i < j; i++) {
                const double *p = vpds_points(s);
                double d2 = (p[2 * i] - p[2 * j]) * (p[2 * i] - p[2 * j]) + (p[2 * i + 1] - p[2 * j + 1]) * (p[2 * i + 1] - p[2 * j + 1]);
                if (i != n_fixed && j != n_fixed && sqrt(d2) < tau * 0.03 * (1 - 1e-12)) bad++;
            }
        CHECK_MSG(bad == 0, "after a stream and a refinement: %zu pairs closer than tau r", bad);
    }
    vpds_destroy(s);
    /* two radii after a lattice of fixed points: draws near circles through four samples */
    s = make(unit_lo, unit_hi, 0.05, 0.5, 9);
    if (s) {
        double lattice[2 * 121];
        int a, b;
        for (a = 0; a <= 10; a++)
            for (b = 0; b <= 10; b++) {
                lattice[2 * (11 * a + b)] = a / 10.0;
                lattice[2 * (11 * a + b) + 1] = b / 10.0;
            }
        CHECK(vpds_add_points(s, lattice, NULL, 121) == VPDS_OK);
        check_stream_oracle(s, quick ? 200 : 1000, unit_lo, unit_hi, 0.05, 0, "two radii after a lattice");
    }
    vpds_destroy(s);
    /* two radii, then a fixed point outside the box: the regions take over and read the
     * kd-tree, which the draws near the farthest point (against the triangulation) left
     * behind; every event keeps off the samples before it */
    s = make(unit_lo, unit_hi, 0.05, 0.5, 10);
    if (s) {
        static const double outside[2] = {1.01, 0.3};
        check_stream_oracle(s, quick ? 100 : 400, unit_lo, unit_hi, 0.05, 0, "two radii before a point outside");
        CHECK(vpds_add_points(s, outside, NULL, 1) == VPDS_OK);
        check_stream_oracle(s, quick ? 50 : 200, unit_lo, unit_hi, 0.05, 0, "two radii after a point outside");
    }
    vpds_destroy(s);
    check_allocation_failures(1.0);
    check_allocation_failures(0.5);
    check_3d();
    CHECK_DONE();
}
