/* Domains, checked by brute force: every sample inside (sdf <= 0), no conflict in insertion
 * order, and every probe of the domain covered — random probes inside and probes on the
 * boundary itself — for an annulus, an L-shape and a polygon with a hole (uniform and
 * variable radii, every rule, two radii, the stream), a mask drawn from a polygon, and a 3D
 * ball and torus. Then each bad domain gives its clear error and changes nothing. */
#include "check.h"
#include "vpds.h"
#include "rules.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int quick; /* VPDS_TEST_QUICK (valgrind): fewer configurations */

typedef double (*fn_t)(const double *, void *);

static double annulus(const double *x, void *u)
{
    double r = hypot(x[0] - 0.5, x[1] - 0.5);
    (void)u;
    return fmax(r - 0.45, 0.2 - r);
}
static double ball(const double *x, void *u)
{
    (void)u;
    return sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5) + (x[2] - 0.5) * (x[2] - 0.5)) - 0.4;
}
static double torus(const double *x, void *u)
{
    double q = hypot(x[0] - 0.5, x[1] - 0.5) - 0.3;
    (void)u;
    return hypot(q, x[2] - 0.5) - 0.12;
}
static double ramp(const double *x, void *u) { (void)u; return 0.02 + 0.03 * x[0]; }
static double empty(const double *x, void *u) { (void)x; (void)u; return 1.0; }
static double nan_far(const double *x, void *u) { (void)u; return x[0] > 0.7 ? NAN : x[0] - 0.9; }
static double steep(const double *x, void *u) { (void)u; return 3 * (x[0] - 0.5); }
/* sdf <= 0 only on the face x0 = 0: a domain without area, where the coverage search splits
 * boxes along the face down to its precision at every cell */
static double face(const double *x, void *u) { (void)u; return 0.5 * x[0]; }
/* boundaries on the planes the stream's search splits at (x = 0.5, 0.25, 0.75) */
static double half_plane(const double *x, void *u) { (void)u; return x[0] - 0.5; }
static double prism(const double *x, void *u)
{
    double a = fabs(x[0] - 0.5), b = fabs(x[1] - 0.5);
    (void)u;
    return (a > b ? a : b) - 0.25;
}

/* A budget bounds a call's work, the coverage search's boxes included: on the face domain with
 * two radii one call of budget 3000 evaluated the domain about 290,000 times (a second of work)
 * when only darts and cells counted. Each box reads the domain at least once. */
static void check_budget_bounds_search(void)
{
    vpds_desc d = vpds_default_desc();
    vpds_sampler *s = NULL;
    uint64_t before = 0;
    int call;
    d.radius = 0.105;
    d.inhibition = 0.65;
    d.domain = face;
    d.budget = 3000;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    for (call = 0; call < 20; call++) {
        vpds_status st = vpds_run(s);
        uint64_t now = vpds_get_stats(s).domain_calls;
        CHECK_MSG(now - before < 20 * 3000, "call %d: %llu domain calls on a budget of 3000", call,
                  (unsigned long long)(now - before));
        before = now;
        if (st != VPDS_PAUSED) break;
    }
    vpds_destroy(s);
}

typedef struct {
    int dim;
    vpds_rule rule;
    double inhibition;
    fn_t sdf;
    void *user;
    fn_t sizing;
    double radius;
} setup;

static double dist(int d, const double *a, const double *b)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) s += (a[k] - b[k]) * (a[k] - b[k]);
    return sqrt(s);
}

/* Probes: random points of the box kept when inside, plus `extra` given points (boundary). */
static void check_set(const setup *c, const double *x, const double *r, size_t n, double tau,
                      double tol, const double *extra, size_t n_extra, const char *what)
{
    size_t i, j, p, outside = 0, conflicts = 0, gaps = 0, probes = 0;
    int d = c->dim, k;
    for (i = 0; i < n; i++) {
        if (c->sdf(x + i * (size_t)d, c->user) > 0) outside++;
        for (j = 0; j < i; j++)
            if (dist(d, x + i * (size_t)d, x + j * (size_t)d) <
                tau * c->inhibition * (1 - tol) * vpdsi_rule_f(c->rule, r[j], r[i]))
                conflicts++;
    }
    srand(7);
    for (p = 0; p < (quick ? 1500u : 4000u) + n_extra; p++) {
        double y[3], ry, best = INFINITY;
        if (p < n_extra) {
            memcpy(y, extra + p * (size_t)d, (size_t)d * sizeof(double));
        } else {
            for (k = 0; k < d; k++) y[k] = rand() / (RAND_MAX + 1.0);
            if (c->sdf(y, c->user) > 0) continue;
        }
        probes++;
        ry = c->sizing ? c->sizing(y, NULL) : c->radius;
        for (i = 0; i < n; i++) {
            double e = dist(d, x + i * (size_t)d, y) / vpdsi_rule_f(c->rule, r[i], ry);
            if (e < best) best = e;
        }
        if (best > tau * (1 + 1e-9)) gaps++;
    }
    CHECK_MSG(n > 0 && outside == 0 && conflicts == 0 && gaps == 0,
              "%s (rule %d, inhibition %g): %zu samples, %zu outside, %zu conflicts, %zu of %zu probes"
              " uncovered", what, (int)c->rule, c->inhibition, n, outside, conflicts, gaps, probes);
}

static vpds_sampler *make(const setup *c, uint64_t seed)
{
    vpds_desc d = vpds_default_desc();
    vpds_sampler *s = NULL;
    d.dim = c->dim;
    d.rule = c->rule;
    d.inhibition = c->inhibition;
    d.radius = c->radius;
    d.domain = c->sdf;
    d.domain_user = c->user;
    if (c->sizing) {
        d.sizing = c->sizing;
        d.lipschitz = 0.03;
    }
    d.seed = seed;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    return s;
}

static void check_run(const setup *c, const double *extra, size_t n_extra, const char *what)
{
    vpds_sampler *s = make(c, 5);
    vpds_status st = vpds_run(s);
    CHECK_MSG(st == VPDS_OK, "%s: %s", what, vpds_last_error(s));
    check_set(c, vpds_points(s), vpds_radii(s), vpds_count(s), 1.0, 0, extra, n_extra, what);
    vpds_destroy(s);
}

/* Stream prefixes at a few scales, each inside, conflict-free and covering the domain. */
static void check_stream(const setup *c, size_t n, const double *extra, size_t n_extra, const char *what)
{
    vpds_sampler *s = make(c, 9);
    double *ts = (double *)malloc(n * sizeof(double)), x[3];
    size_t i, q;
    for (i = 0; i < n; i++) {
        vpds_status st = vpds_next(s, 0, x, ts + i);
        CHECK_MSG(st == VPDS_OK, "%s: event %zu: %s", what, i, vpds_last_error(s));
        if (st != VPDS_OK) { /* the prefixes below read only the events there were */
            free(ts);
            vpds_destroy(s);
            return;
        }
    }
    CHECK(isinf(ts[0]));
    for (q = 1; q <= 3; q++) {
        size_t m = n * q / 3 - 1;
        double tau = ts[m];
        while (m + 1 < n && ts[m + 1] == tau) m++;
        check_set(c, vpds_points(s), vpds_radii(s), m + 1, tau, VPDS_STREAM_DOMAIN_TOLERANCE, extra,
                  n_extra, what);
    }
    free(ts);
    vpds_destroy(s);
}

/* A polygon of n_rings rings, created (the setup several checks share). */
static vpds_polygon *polygon_of(const double *xy, const size_t *ring_sizes, size_t n_rings)
{
    vpds_polygon_desc pd = vpds_default_polygon_desc();
    vpds_polygon *p = NULL;
    pd.xy = xy;
    pd.ring_sizes = ring_sizes;
    pd.n_rings = n_rings;
    CHECK(vpds_polygon_create(&pd, &p) == VPDS_OK);
    return p;
}

/* A 4x4 mask of the unit square whose middle 2x2 cells are inside: its boundary lies on the
 * planes x, y = 0.25, 0.75. */
static vpds_mask *middle_of_4x4(void)
{
    static const double cells[16] = {0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 0};
    size_t shape[2] = {4, 4};
    vpds_mask_desc md = vpds_default_mask_desc();
    vpds_mask *m = NULL;
    md.shape = shape;
    md.values = cells;
    CHECK(vpds_mask_create(&md, &m) == VPDS_OK);
    return m;
}

/* Version 13: domains whose boundary lies on the planes the stream's search splits at. Version
 * 12's search found no point along such a boundary from the outside boxes (no centre lies in
 * the domain there, at any depth) and gave up with VPDS_ERR_DOMAIN after a few events. */
static void check_aligned_streams(void)
{
    static const double square[] = {0.25, 0.25, 0.75, 0.25, 0.75, 0.75, 0.25, 0.75};
    static const size_t square_sizes[] = {4};
    vpds_polygon *poly = polygon_of(square, square_sizes, 1);
    vpds_mask *mask = middle_of_4x4();
    setup c = {2, VPDS_RULE_SMALLER, 1.0, half_plane, NULL, NULL, 0.05};
    size_t n = quick ? 100 : 300;
    check_stream(&c, n, NULL, 0, "stream in the half-plane x <= 0.5");
    c.sdf = vpds_polygon_sdf;
    c.user = poly;
    check_stream(&c, n, NULL, 0, "stream in the square polygon [0.25, 0.75]^2");
    c.sdf = vpds_mask_sdf;
    c.user = mask;
    check_stream(&c, n, NULL, 0, "stream in a 4x4 mask (its middle 2x2 inside)");
    c.dim = 3;
    c.sdf = prism;
    c.user = NULL;
    c.radius = 0.1;
    check_stream(&c, n, NULL, 0, "stream in the 3D prism |x - 0.5|, |y - 0.5| <= 0.25");
    {
        /* version 12 still gives up there: its points are kept as they were */
        vpds_desc d = vpds_default_desc();
        vpds_sampler *s;
        size_t got;
        d.domain = half_plane;
        d.algorithm_version = 12;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        CHECK(vpds_next_n(s, 100, 0.0, NULL, NULL, &got) == VPDS_ERR_DOMAIN && got < 100);
        vpds_destroy(s);
    }
    vpds_polygon_destroy(poly);
    vpds_mask_destroy(mask);
}

/* Points along the rings of a polygon (every edge, 20 per edge). */
static size_t edge_probes(const double *xy, const size_t *sizes, size_t rings, double *out)
{
    size_t r, j, at = 0, m = 0;
    int q;
    for (r = 0; r < rings; at += sizes[r], r++)
        for (j = 0; j < sizes[r]; j++) {
            const double *a = xy + 2 * (at + j), *b = xy + 2 * (at + (j + 1) % sizes[r]);
            for (q = 0; q < 20; q++, m++) {
                out[2 * m] = a[0] + (b[0] - a[0]) * q / 20.0;
                out[2 * m + 1] = a[1] + (b[1] - a[1]) * q / 20.0;
            }
        }
    return m;
}

int main(void)
{
    static const vpds_rule rules[4] = {VPDS_RULE_PRIOR, VPDS_RULE_CURRENT, VPDS_RULE_BIGGER,
                                       VPDS_RULE_SMALLER};
    double circles[2 * 400], edges[2 * 400];
    size_t n_circles = 0, n_edges, q;
    int i;
    setup c;
    vpds_polygon *lshape, *holed;
    vpds_polygon_desc pd;
    check_budget_bounds_search();
    /* an L-shape, and a square with a square hole (its ring reversed) */
    static const double l_xy[] = {0.1, 0.1, 0.9, 0.1, 0.9, 0.4, 0.4, 0.4, 0.4, 0.9, 0.1, 0.9};
    static const size_t l_sizes[] = {6};
    static const double h_xy[] = {0.05, 0.05, 0.95, 0.05, 0.95, 0.95, 0.05, 0.95,
                                  0.3, 0.3, 0.3, 0.7, 0.7, 0.7, 0.7, 0.3};
    static const size_t h_sizes[] = {4, 4};
    quick = getenv("VPDS_TEST_QUICK") != NULL;

    for (i = 0; i < 200; i++) { /* both circles of the annulus */
        double a = 2 * 3.14159265358979323846 * i / 200.0;
        circles[2 * n_circles] = 0.5 + 0.45 * cos(a);
        circles[2 * n_circles++ + 1] = 0.5 + 0.45 * sin(a);
        circles[2 * n_circles] = 0.5 + 0.2 * cos(a);
        circles[2 * n_circles++ + 1] = 0.5 + 0.2 * sin(a);
    }
    memset(&c, 0, sizeof c);
    c.dim = 2;
    c.inhibition = 1;
    c.sdf = annulus;
    c.radius = 0.03;
    for (q = 0; q < 4; q++) {
        c.rule = rules[q];
        c.sizing = NULL;
        check_run(&c, circles, n_circles, "annulus, uniform");
        c.sizing = ramp;
        check_run(&c, circles, n_circles, "annulus, ramp");
        if (quick) break;
    }
    c.rule = VPDS_RULE_SMALLER;
    c.sizing = NULL;
    c.inhibition = 0.5;
    check_run(&c, circles, n_circles, "annulus, two radii");
    c.sizing = ramp;
    check_stream(&c, quick ? 200 : 500, circles, n_circles, "annulus stream, two radii, ramp");
    c.inhibition = 1;
    c.sizing = NULL;
    check_stream(&c, quick ? 200 : 500, circles, n_circles, "annulus stream");

    /* polygons: the L-shape and the square with a hole */
    lshape = polygon_of(l_xy, l_sizes, 1);
    holed = polygon_of(h_xy, h_sizes, 2);
    {
        double p_in[2] = {0.2, 0.2}, p_out[2] = {0.6, 0.6}, p_hole[2] = {0.5, 0.5};
        CHECK(vpds_polygon_sdf(p_in, lshape) == -0.1 || fabs(vpds_polygon_sdf(p_in, lshape) + 0.1) < 1e-15);
        CHECK(fabs(vpds_polygon_sdf(p_out, lshape) - 0.2) < 1e-15);
        CHECK(fabs(vpds_polygon_sdf(p_hole, holed) - 0.2) < 1e-15);
    }
    c.sdf = vpds_polygon_sdf;
    for (q = 0; q < 4; q++) {
        c.rule = rules[q];
        c.user = lshape;
        n_edges = edge_probes(l_xy, l_sizes, 1, edges);
        c.sizing = q % 2 ? ramp : NULL;
        check_run(&c, edges, n_edges, "L-shape");
        c.user = holed;
        n_edges = edge_probes(h_xy, h_sizes, 2, edges);
        c.sizing = q % 2 ? NULL : ramp;
        check_run(&c, edges, n_edges, "square with a hole");
        if (quick) break;
    }

    /* a mask drawn from the polygon with a hole gives a set with the same properties, for its
     * own domain; and that domain is the polygon's up to a cell */
    {
        enum { M = 128 };
        static double values[M * M];
        size_t shape[2] = {M, M}, ii, jj, disagree = 0;
        vpds_mask_desc md = vpds_default_mask_desc();
        vpds_mask *mask;
        for (ii = 0; ii < M; ii++)
            for (jj = 0; jj < M; jj++) {
                /* axis 0 (rows) is x[0]: cell (ii, jj) has its centre at ((ii+.5)/M, (jj+.5)/M) */
                double p[2] = {(ii + 0.5) / M, (jj + 0.5) / M};
                values[ii * M + jj] = vpds_polygon_sdf(p, holed) <= 0;
            }
        md.shape = shape;
        md.values = values;
        CHECK(vpds_mask_create(&md, &mask) == VPDS_OK);
        for (ii = 0; ii < 4000; ii++) {
            double p[2] = {rand() / (RAND_MAX + 1.0), rand() / (RAND_MAX + 1.0)};
            double a = vpds_polygon_sdf(p, holed), b = vpds_mask_sdf(p, mask);
            if ((a <= 0) != (b <= 0) && fabs(a) > 1.0 / M) disagree++;
        }
        CHECK_MSG(disagree == 0, "mask and polygon disagree at %zu points farther than a cell from the boundary",
                  disagree);
        c.sdf = vpds_mask_sdf;
        c.user = mask;
        c.sizing = NULL;
        c.rule = VPDS_RULE_SMALLER;
        check_run(&c, NULL, 0, "mask of the square with a hole");
        vpds_mask_destroy(mask);
    }
    vpds_polygon_destroy(lshape);
    vpds_polygon_destroy(holed);

    /* 3D: a ball and a torus */
    c.dim = 3;
    c.user = NULL;
    c.sizing = NULL;
    c.radius = 0.08;
    c.sdf = ball;
    check_run(&c, NULL, 0, "ball");
    c.sdf = torus;
    c.radius = 0.06;
    check_run(&c, NULL, 0, "torus");
    check_stream(&c, quick ? 100 : 400, NULL, 0, "torus stream");
    check_aligned_streams();

    /* bad domains: each a clear error, nothing changed */
    {
        vpds_sampler *s;
        vpds_desc d = vpds_default_desc();
        double x[2], t;
        char msg[512];
        d.domain = empty;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        CHECK(vpds_run(s) == VPDS_ERR_DOMAIN && vpds_count(s) == 0 && strstr(vpds_last_error(s), "empty"));
        CHECK(vpds_run(s) == VPDS_ERR_DOMAIN && !vpds_get_stats(s).maximal);
        CHECK(vpds_next(s, 0, x, &t) == VPDS_ERR_DOMAIN && vpds_count(s) == 0);
        vpds_destroy(s);
        {
            /* the built-in domains know their dimension: one of another is refused at create
             * (a 2D mask was read at a 1D sampler's unwritten second coordinate) */
            static const double tri[] = {0.1, 0.1, 0.9, 0.1, 0.5, 0.9};
            static const size_t tri_sizes[] = {3};
            vpds_mask *m2 = middle_of_4x4();
            vpds_polygon *p2 = polygon_of(tri, tri_sizes, 1);
            vpds_desc e = vpds_default_desc();
            e.domain = vpds_mask_sdf;
            e.domain_user = m2;
            e.dim = 1;
            CHECK(vpds_validate(&e, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "a 2D mask"));
            e.dim = 3;
            CHECK(vpds_create(&e, &s) == VPDS_ERR_INVALID_ARGUMENT && s == NULL);
            e.dim = 2;
            CHECK(vpds_validate(&e, msg, sizeof msg) == VPDS_OK);
            e.domain = vpds_polygon_sdf;
            e.domain_user = p2;
            e.dim = 3;
            CHECK(vpds_validate(&e, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "a 2D domain"));
            e.dim = 2;
            CHECK(vpds_validate(&e, msg, sizeof msg) == VPDS_OK);
            vpds_mask_destroy(m2);
            vpds_polygon_destroy(p2);
        }
        d.domain = nan_far;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        CHECK(vpds_run(s) == VPDS_ERR_DOMAIN && strstr(vpds_last_error(s), "NaN"));
        vpds_destroy(s);
        d.domain = steep;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        CHECK_MSG(vpds_run(s) == VPDS_ERR_DOMAIN && strstr(vpds_last_error(s), "1-Lipschitz"),
                  "steep domain: %s", vpds_last_error(s));
        vpds_destroy(s);
        {
            /* a bow tie crosses itself; a mask with no inside cell */
            static const double bow[] = {0, 0, 1, 1, 1, 0, 0, 1};
            static const size_t four[] = {4};
            static const double zeros[4] = {0, 0, 0, 0.2};
            size_t shape[2] = {2, 2};
            vpds_polygon *p = (vpds_polygon *)&msg;
            vpds_mask *m = (vpds_mask *)&msg;
            vpds_mask_desc md = vpds_default_mask_desc();
            pd = vpds_default_polygon_desc();
            pd.xy = bow;
            pd.ring_sizes = four;
            pd.n_rings = 1;
            CHECK(vpds_polygon_validate(&pd, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT &&
                  strstr(msg, "intersects itself"));
            CHECK(vpds_polygon_create(&pd, &p) == VPDS_ERR_INVALID_ARGUMENT && p == NULL);
            md.shape = shape;
            md.values = zeros;
            CHECK(vpds_mask_validate(&md, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT &&
                  strstr(msg, "no value"));
            CHECK(vpds_mask_create(&md, &m) == VPDS_ERR_INVALID_ARGUMENT && m == NULL);
            {
                /* a ring flat to round-off (a run in it split cells without end), and a mask's box
                 * past the sampler's bounds (its distances NaN, or 0 everywhere) */
                static const double flat[] = {0, 0, 1, 0, 0.5, 1e-300};
                static const double thin[] = {0, 0, 1, 0, 0.5, 1e-9};
                static const size_t three[] = {3};
                static const double some[4] = {0, 1, 1, 0};
                double lo[2] = {0, 0}, huge[2] = {1e300, 1e300}, tiny[2] = {1e-300, 1e-300};
                pd.xy = flat;
                pd.ring_sizes = three;
                CHECK(vpds_polygon_validate(&pd, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT &&
                      strstr(msg, "ring 0 encloses no area"));
                pd.xy = thin; /* thin, not flat: taken (and slow to sample, as the README says) */
                CHECK(vpds_polygon_validate(&pd, msg, sizeof msg) == VPDS_OK);
                md.values = some;
                md.lo = lo;
                md.hi = huge;
                CHECK(vpds_mask_validate(&md, msg, sizeof msg) == VPDS_ERR_OVERFLOW && strstr(msg, "1e150"));
                md.hi = tiny;
                CHECK(vpds_mask_create(&md, &m) == VPDS_ERR_OVERFLOW && m == NULL);
            }
        }
    }
    CHECK_DONE();
}
