/* The exact largest gap (gap.c) and the version-5 stream built on it, against brute force:
 * - vpdsi_gap_max: the point it returns is in the box and has the gap it reports, and no probe
 *   of the box (random ones, a grid, the corners) has a larger gap;
 * - vpdsi_gap_max_above: below the maximum the same bits as vpdsi_gap_max, at it nothing;
 * - vpdsi_gap_dominated: never says "dominated" where some probe is nearer the dominated point;
 * - the stream with one radius: each event's t is the gap of its point before it was inserted
 *   (to round-off: the point is the farthest point, not one within the tolerance), and no probe
 *   of a grid over the box lies farther than t from every sample. */
#include "check.h"
#include "vpds.h"
#include "gap_search.h"
#include "surface_gap.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GD VPDSI_GAP_MAX_DIM /* coordinates of one point, at most */

static int quick; /* VPDS_TEST_QUICK (valgrind): fewer configurations */
static unsigned long long rng_state = 12345;
static double unit(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

static double nearest2(int d, const double *p, int n, const double *y)
{
    double best = INFINITY;
    int i, k;
    for (i = 0; i < n; i++) {
        double s = 0;
        for (k = 0; k < d; k++) s += (y[k] - p[i * d + k]) * (y[k] - p[i * d + k]);
        if (s < best) best = s;
    }
    return best;
}

/* vpdsi_gap_max_above against vpdsi_gap_max's answer v, y: below v (floors that hold most
 * faces, and none) the same bits; at v and above, -1 and y untouched. */
static void check_floors(int d, const double *lo, const double *hi, unsigned faces, const double *p,
                         int n, double v, const double *y)
{
    static const double below[4] = {0.999999, 0.99, 0.8, 0.3};
    double fy[GD], w;
    int j;
    for (j = 0; j < 4 && v > 0; j++) {
        memset(fy, 0, sizeof fy);
        w = vpdsi_gap_max_above(d, lo, hi, faces, p, n, v * below[j], fy);
        CHECK_MSG(w == v && memcmp(fy, y, (size_t)d * sizeof(double)) == 0,
                  "d %d n %d: floor %.17g gives %.17g, no floor %.17g", d, n, v * below[j], w, v);
    }
    for (j = 0; j < GD; j++) fy[j] = 7;
    w = vpdsi_gap_max_above(d, lo, hi, faces, p, n, v < 0 ? 0 : v, fy);
    CHECK(w == -1 && fy[0] == 7 && fy[d - 1] == 7);
}

/* One random configuration: a box and n points (some outside it), checked by probes. */
static void check_gap_once(int d, int n, int probes)
{
    double lo[GD], hi[GD], p[VPDSI_GAP_MAX_POINTS * GD], y[GD], v, top = 0;
    int i, k, inside = 1;
    for (k = 0; k < d; k++) {
        lo[k] = unit() * 2 - 1;
        hi[k] = lo[k] + 0.05 + unit();
    }
    for (i = 0; i < n; i++)
        for (k = 0; k < d; k++) p[i * d + k] = lo[k] - 0.5 + unit() * (hi[k] - lo[k] + 1);
    v = vpdsi_gap_max(d, lo, hi, VPDSI_GAP_ALL_FACES(d), p, n, y);
    check_floors(d, lo, hi, VPDSI_GAP_ALL_FACES(d), p, n, v, y);
    for (k = 0; k < d; k++) inside &= y[k] >= lo[k] && y[k] <= hi[k];
    CHECK(inside);
    CHECK_MSG(fabs(nearest2(d, p, n, y) - v) <= 1e-12 * v, "d %d n %d: gap at y %.17g, reported %.17g",
              d, n, nearest2(d, p, n, y), v);
    for (i = 0; i < probes; i++) {
        double q[GD], g;
        for (k = 0; k < d; k++) {
            /* a third of the probes on faces, where the boundary maxima lie */
            double u = unit();
            q[k] = lo[k] + u * (hi[k] - lo[k]);
            if (i % 3 == 0 && k == i % d) q[k] = u < 0.5 ? lo[k] : hi[k];
        }
        g = nearest2(d, p, n, q);
        if (g > top) top = g;
    }
    CHECK_MSG(top <= v * (1 + 1e-12), "d %d n %d: a probe's gap %.17g beats the maximum %.17g", d, n,
              top, v);
    {
        /* the box cut in 2^d pieces, each with the outer faces it keeps: no piece beats the
         * maximum, and the pieces holding its maximiser find it */
        unsigned b;
        double found = -1;
        for (b = 0; b < (1u << d); b++) {
            double plo[GD], phi[GD], py[GD], pv;
            unsigned faces = 0;
            int holds = 1;
            for (k = 0; k < d; k++) {
                double mid = 0.5 * (lo[k] + hi[k]);
                unsigned high = b >> k & 1u;
                plo[k] = high ? mid : lo[k];
                phi[k] = high ? hi[k] : mid;
                faces |= 1u << (2 * k + high);
                holds &= y[k] >= plo[k] && y[k] <= phi[k];
            }
            pv = vpdsi_gap_max(d, plo, phi, faces, p, n, py);
            check_floors(d, plo, phi, faces, p, n, pv, py);
            CHECK(pv <= v * (1 + 1e-12));
            if (pv >= 0) CHECK(fabs(nearest2(d, p, n, py) - pv) <= 1e-12 * pv);
            if (holds && pv > found) found = pv;
        }
        CHECK_MSG(fabs(found - v) <= 1e-12 * v, "d %d n %d: pieces found %.17g, the box %.17g", d, n,
                  found, v);
    }
}

/* The triangle form (surface_gap.c): a random triangle of R^3 and n points near it, some off its
 * plane. The reported gap is the gap at the reported point, no probe of the triangle (a third on
 * its edges, its corners) beats it, and the best probe of a fine lattice comes within the
 * lattice's spacing of it (the gap is 1-Lipschitz). */
static void check_triangle_gap_once(int n, int lattice)
{
    double e1[3], e2[3], z[3 * VPDSI_SURFACE_GAP_MAX_POINTS], ab[2], v, top = 0, edge = 0;
    int i, j, k;
    for (k = 0; k < 3; k++) {
        e1[k] = unit() * 2 - 1;
        e2[k] = unit() * 2 - 1;
    }
    for (i = 0; i < n; i++) {
        double a = unit() * 1.4 - 0.2, b = unit() * 1.4 - 0.2, off = (unit() - 0.5) * 0.6;
        for (k = 0; k < 3; k++) z[3 * i + k] = a * e1[k] + b * e2[k] + off * (k == 2 ? 1 : 0.3);
    }
    v = vpdsi_surface_gap_max(e1, e2, z, n, ab);
    CHECK(ab[0] >= 0 && ab[1] >= 0 && ab[0] + ab[1] <= 1);
    {
        double y[3];
        for (k = 0; k < 3; k++) y[k] = ab[0] * e1[k] + ab[1] * e2[k];
        CHECK_MSG(fabs(nearest2(3, z, n, y) - v) <= 1e-12 * v, "triangle n %d: gap at the point %.17g, reported %.17g",
                  n, nearest2(3, z, n, y), v);
    }
    for (k = 0; k < 3; k++) {
        double l1 = 0, l2 = 0, l3 = 0;
        l1 += e1[k] * e1[k];
        l2 += e2[k] * e2[k];
        l3 += (e1[k] - e2[k]) * (e1[k] - e2[k]);
        edge += l1 + l2 + l3;
    }
    edge = sqrt(edge); /* at least the longest edge */
    for (i = 0; i <= lattice; i++)
        for (j = 0; i + j <= lattice; j++) {
            double y[3], g;
            for (k = 0; k < 3; k++) y[k] = ((double)i * e1[k] + (double)j * e2[k]) / lattice;
            g = nearest2(3, z, n, y);
            if (g > top) top = g;
        }
    CHECK_MSG(top <= v * (1 + 1e-12), "triangle n %d: a probe's gap %.17g beats the maximum %.17g", n, top, v);
    CHECK_MSG(sqrt(v) - sqrt(top) <= edge / lattice, "triangle n %d: the maximum %.17g, the lattice's best %.17g",
              n, sqrt(v), sqrt(top));
}

/* Known answers: a lone point's farthest corner; a triangle's circumcentre. */
static void check_gap_known(void)
{
    double lo[2] = {0, 0}, hi[2] = {1, 1}, y[2], v;
    double one[2] = {0.25, 0.5}, tri[6] = {0.3, 0.3, 0.7, 0.3, 0.5, 0.7};
    v = vpdsi_gap_max(2, lo, hi, VPDSI_GAP_ALL_FACES(2), one, 1, y);
    CHECK(y[0] == 1 && (y[1] == 0 || y[1] == 1) && fabs(v - (0.75 * 0.75 + 0.25)) < 1e-15);
    /* the circumcentre (0.5, 0.45) is inside, but the corners are farther from all three */
    v = vpdsi_gap_max(2, lo, hi, VPDSI_GAP_ALL_FACES(2), tri, 3, y);
    CHECK(fabs(v - 0.34) < 1e-14 && y[1] == 1);
    {
        /* a small box around the circumcentre: there it is the maximum */
        double l2[2] = {0.45, 0.4}, h2[2] = {0.55, 0.5};
        v = vpdsi_gap_max(2, l2, h2, VPDSI_GAP_ALL_FACES(2), tri, 3, y);
        CHECK(fabs(y[0] - 0.5) < 1e-15 && fabs(y[1] - 0.45) < 1e-15 && fabs(v - 0.0625) < 1e-15);
    }
}

static void check_dominated(int d)
{
    int trial;
    for (trial = 0; trial < 2000; trial++) {
        double lo[GD], hi[GD], a[GD], b[GD];
        int k, i, dom;
        for (k = 0; k < d; k++) {
            lo[k] = unit();
            hi[k] = lo[k] + 0.1 * unit() + 1e-3;
            a[k] = unit() * 2 - 0.5;
            b[k] = unit() * 2 - 0.5;
        }
        dom = vpdsi_gap_dominated(d, lo, hi, a, b);
        for (i = 0; i < (dom ? 200 : 0); i++) {
            double q[GD];
            for (k = 0; k < d; k++) q[k] = lo[k] + unit() * (hi[k] - lo[k]);
            CHECK(nearest2(d, a, 1, q) < nearest2(d, b, 1, q));
        }
        if (!dom) {
            /* some corner is at least as near b: the test is exact, not only safe */
            unsigned c;
            int found = 0;
            for (c = 0; c < (1u << d); c++) {
                double q[GD];
                for (k = 0; k < d; k++) q[k] = c >> k & 1u ? hi[k] : lo[k];
                if (nearest2(d, a, 1, q) >= nearest2(d, b, 1, q) * (1 - 1e-12)) found = 1;
            }
            CHECK(found);
        }
    }
}

static double tdist2(int d, const int *periodic, const double *a, const double *b)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) {
        double e = fabs(a[k] - b[k]);
        if (periodic && periodic[k] && e > 0.5) e = 1 - e;
        s += e * e;
    }
    return s;
}

/* The largest gap of the unit box from n points by a route independent of gap.c: in 1D the
 * sorted gaps (the wrap-around one on a circle); in 2D every corner, every bisector's crossing
 * of an edge and every circumcentre inside, each scored by its nearest point. */
static int by_value(const void *a, const void *b)
{
    double u = *(const double *)a, v = *(const double *)b;
    return (u > v) - (u < v);
}

static double brute_gap(int d, int periodic, const double *p, int n)
{
    double best = 0, y[2];
    int i, j, k, e;
    if (d == 1) {
        double s[64];
        memcpy(s, p, (size_t)n * sizeof(double));
        qsort(s, (size_t)n, sizeof(double), by_value);
        best = periodic ? (s[0] + 1 - s[n - 1]) / 2 : s[0] > 1 - s[n - 1] ? s[0] : 1 - s[n - 1];
        for (i = 0; i + 1 < n; i++)
            if ((s[i + 1] - s[i]) / 2 > best) best = (s[i + 1] - s[i]) / 2;
        return best * best;
    }
    for (i = 0; i < 4; i++) {
        y[0] = i & 1;
        y[1] = i >> 1;
        if (nearest2(2, p, n, y) > best) best = nearest2(2, p, n, y);
    }
    for (i = 0; i < n; i++)
        for (j = i + 1; j < n; j++) {
            const double *a = p + 2 * i, *b = p + 2 * j;
            double A0 = 2 * (b[0] - a[0]), A1 = 2 * (b[1] - a[1]);
            double B = b[0] * b[0] + b[1] * b[1] - a[0] * a[0] - a[1] * a[1];
            for (e = 0; e < 4; e++) {
                /* edge x_(e & 1) = e >> 1 */
                int ax = e & 1;
                double fixed = e >> 1, Af = ax ? A1 : A0, Ao = ax ? A0 : A1;
                if (Ao == 0) continue;
                y[ax] = fixed;
                y[1 - ax] = (B - Af * fixed) / Ao;
                if (y[1 - ax] >= 0 && y[1 - ax] <= 1 && nearest2(2, p, n, y) > best)
                    best = nearest2(2, p, n, y);
            }
            for (k = j + 1; k < n; k++) {
                const double *c = p + 2 * k;
                double C0 = 2 * (c[0] - a[0]), C1 = 2 * (c[1] - a[1]);
                double Cb = c[0] * c[0] + c[1] * c[1] - a[0] * a[0] - a[1] * a[1];
                double det = A0 * C1 - A1 * C0;
                if (det == 0) continue;
                y[0] = (B * C1 - A1 * Cb) / det;
                y[1] = (A0 * Cb - B * C0) / det;
                if (y[0] >= 0 && y[0] <= 1 && y[1] >= 0 && y[1] <= 1 && nearest2(2, p, n, y) > best)
                    best = nearest2(2, p, n, y);
            }
        }
    return best;
}

/* vpdsi_gap_search among many points (some outside the box) against brute_gap in the unit
 * square, and against probes in 3D and 4D. */
static void check_search(void)
{
    static int32_t scratch[VPDSI_GAP_SCRATCH(400)];
    double p[400 * GD], y[GD], best;
    int trial, i, k;
    for (trial = 0; trial < (quick ? 40 : 300); trial++) {
        double lo[2] = {0, 0}, hi[2] = {1, 1};
        int n = 1 + trial % 120, side = 2 + trial % 9;
        for (i = 0; i < 2 * n; i++) p[i] = unit() * 1.4 - 0.2;
        if (trial % 2) {
            /* a jittered lattice: many local maxima within a hair of the largest */
            n = side * side;
            for (i = 0; i < n; i++) {
                p[2 * i] = (i % side + 0.5 + 0.01 * unit()) / side;
                p[2 * i + 1] = (i / side + 0.5 + 0.01 * unit()) / side;
            }
        }
        double truth = brute_gap(2, 0, p, n);
        CHECK(vpdsi_gap_search(2, lo, hi, p, n, scratch, &best, y));
        CHECK_MSG(fabs(best / truth - 1) < 1e-10, "n %d: %.17g, brute force %.17g", n, best, truth);
        CHECK(fabs(nearest2(2, p, n, y) / best - 1) < 1e-10);
    }
    for (trial = 0; trial < (quick ? 6 : 60); trial++) {
        int d = 3 + trial % 2, n = 50 + trial * 5;
        double lo[GD], hi[GD], top = 0;
        for (k = 0; k < d; k++) {
            lo[k] = 0;
            hi[k] = 1;
        }
        for (i = 0; i < d * n; i++) p[i] = unit();
        CHECK(vpdsi_gap_search(d, lo, hi, p, n, scratch, &best, y));
        CHECK(fabs(nearest2(d, p, n, y) / best - 1) < 1e-10);
        for (i = 0; i < 4000; i++) {
            double q[GD], g;
            for (k = 0; k < d; k++) q[k] = unit();
            if (i % 2) q[i % d] = (double)(i / 2 % 2);
            g = nearest2(d, p, n, q);
            if (g > top) top = g;
        }
        CHECK_MSG(top <= best * (1 + 1e-12), "d %d n %d: a probe's gap %.17g beats %.17g", d, n, top, best);
    }
    CHECK(!vpdsi_gap_search(2, p, p, p, 0, scratch, &best, y));
}

/* The first n events of a stream with one radius are farthest-point insertion exactly: each
 * event's t * r is the largest gap of the points before it (brute_gap), so the t fall. */
static void check_stream_brute(int d, int periodic, int n)
{
    static const int circle[1] = {1};
    vpds_desc desc = vpds_default_desc();
    vpds_sampler *s = NULL;
    double x[2], t, r = 0.05, last = INFINITY;
    int i;
    desc.dim = d;
    desc.radius = r;
    desc.periodic = periodic ? circle : NULL;
    desc.seed = 9;
    CHECK(vpds_create(&desc, &s) == VPDS_OK);
    for (i = 0; i < n && s; i++) {
        CHECK(vpds_next(s, 0, x, &t) == VPDS_OK);
        if (i > 0) {
            double g = sqrt(brute_gap(d, periodic, vpds_points(s), i));
            CHECK_MSG(fabs(t * r / g - 1) < 1e-10, "d %d periodic %d event %d: t r %.17g, largest gap %.17g",
                      d, periodic, i, t * r, g);
            CHECK(t <= last * (1 + 1e-12));
            last = t;
        }
    }
    vpds_destroy(s);
}

/* A stream of n events with one radius r (R_f = R_c): each event's point is the farthest point
 * of the box from the samples before it, and at checkpoints a grid of probes confirms that no
 * point is farther than the event's t. */
static void check_stream_exact(int d, const int *periodic, size_t n, int grid)
{
    vpds_desc desc = vpds_default_desc();
    vpds_sampler *s = NULL;
    double x[GD], t, r = 0.05;
    size_t i, j;
    desc.dim = d;
    desc.radius = r;
    desc.periodic = periodic;
    desc.seed = 5;
    CHECK(vpds_create(&desc, &s) == VPDS_OK);
    for (i = 0; i < n && s; i++) {
        const double *p;
        double g2 = INFINITY;
        CHECK(vpds_next(s, 0, x, &t) == VPDS_OK);
        p = vpds_points(s);
        for (j = 0; j < i; j++) {
            double e = tdist2(d, periodic, p + j * d, x);
            if (e < g2) g2 = e;
        }
        if (i > 0)
            CHECK_MSG(fabs(sqrt(g2) / (t * r) - 1) < 1e-10, "d %d event %zu: t %.17g, gap of its point %.17g", d,
                      i, t, sqrt(g2) / r);
        if (i + 1 == n / 4 || i + 1 == n) {
            /* a grid of probes (cell centres and faces) no farther than t * r from the set */
            long cells = 1, c;
            int k;
            double worst = 0;
            for (k = 0; k < d; k++) cells *= grid + 1;
            for (c = 0; c < cells; c++) {
                double q[GD], e2 = INFINITY;
                long rest = c;
                for (k = 0; k < d; k++) {
                    q[k] = (double)(rest % (grid + 1)) / grid;
                    rest /= grid + 1;
                }
                for (j = 0; j <= i; j++) {
                    double e = tdist2(d, periodic, p + j * d, q);
                    if (e < e2) e2 = e;
                }
                if (e2 > worst) worst = e2;
            }
            CHECK_MSG(sqrt(worst) <= t * r * (1 + 1e-12), "%zu events: a probe %.17g from the set, t r %.17g",
                      i + 1, sqrt(worst), t * r);
        }
    }
    vpds_destroy(s);
}

int main(void)
{
    static const int both[2] = {1, 1}, one3[3] = {0, 1, 0};
    int d, n, rep;
    quick = getenv("VPDS_TEST_QUICK") != NULL;
    check_gap_known();
    for (d = 1; d <= VPDSI_GAP_MAX_DIM; d++) {
        check_dominated(d);
        for (n = 1; n <= VPDSI_GAP_MAX_POINTS; n++)
            /* 5D to 7D: few repetitions (up to 10 points with every face: 10^5 vertices) */
            for (rep = 0; rep < (d > 6 ? n == 8 : d > 4 ? (quick ? n % 3 == 0 : 3) : quick ? 5 : d > 2 ? 40 : 100); rep++)
                check_gap_once(d, n, d > 2 ? 3000 : 2000);
    }
    for (n = 1; n <= VPDSI_SURFACE_GAP_MAX_POINTS; n++)
        for (rep = 0; rep < (quick ? 5 : 60); rep++) check_triangle_gap_once(n, quick ? 60 : 200);
    check_search();
    check_stream_brute(1, 0, 64);
    check_stream_brute(1, 1, 64);
    check_stream_brute(2, 0, 70);
    check_stream_exact(1, NULL, 60, 4000);
    check_stream_exact(2, NULL, 300, 300);
    check_stream_exact(2, both, 300, 300);
    check_stream_exact(3, one3, 150, 40);
    /* version 9: exact in 5D to 7D too */
    check_stream_exact(5, NULL, quick ? 30 : 80, 6);
    check_stream_exact(6, NULL, quick ? 20 : 50, 4);
    check_stream_exact(7, NULL, quick ? 8 : 15, 3);
    CHECK_DONE();
}
