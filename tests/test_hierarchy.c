/* Two radii, periodic axes, refinement and the continuous stream, checked by brute force:
 * conflict-free in insertion order and covered at every probe, for the whole set after a run
 * or refine and for stream prefixes {x_k : t_k >= tau}; determinism by seed; fixed points;
 * allocation failures during a stream leave a state that resumes to the same points. */
#include "check.h"
#include "failing_alloc.h"
#include "vpds.h"
#include "rules.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* VPDS_TEST_QUICK (set under valgrind): shorter streams and fewer configurations */
static int quick;

static double ramp(const double *x, void *u) { (void)u; return 0.02 + 0.03 * x[0]; }
/* the paper's Figure 1 ramp: near zero at x = 0, where with rule current the distance and the
 * radius grow together and the largest gap is flat over a wide area */
static double steep(const double *x, void *u) { (void)u; return 0.001 + 0.3 * x[0]; }
/* periodic along axis 0 with L = 0.01 * 2 pi */
static double wave(const double *x, void *u)
{
    (void)u;
    return 0.03 + 0.01 * sin(2 * 3.14159265358979323846 * x[0]);
}


typedef struct {
    int dim;
    const int *periodic;
    vpds_rule rule;
    double inhibition, coverage;
} setup;

static double tdist(const setup *c, const double *a, const double *b)
{
    double s = 0;
    int k;
    for (k = 0; k < c->dim; k++) {
        double e = fabs(a[k] - b[k]);
        if (c->periodic && c->periodic[k] && e > 0.5) e = 1 - e;
        s += e * e;
    }
    return sqrt(s);
}

/* Conflicts among the first n samples at scale tau*inhibition*(1 - tol), insertion order. */
static int conflicts(const setup *c, const double *x, const double *r, size_t n, double tau, double tol)
{
    size_t i, j;
    int bad = 0;
    for (j = 1; j < n; j++)
        for (i = 0; i < j; i++)
            if (tdist(c, x + i * c->dim, x + j * c->dim) <
                tau * c->inhibition * (1 - tol) * vpdsi_rule_f(c->rule, r[i], r[j]))
                bad++;
    return bad;
}

/* Probes of the unit box not covered at tau*coverage (r at the probe from the sizing). */
static int gaps(const setup *c, const double *x, const double *r, size_t n, double tau,
                double (*sizing)(const double *, void *), double radius, int probes, unsigned seed)
{
    int p, bad = 0, k;
    srand(seed);
    for (p = 0; p < probes; p++) {
        double y[3], ry;
        size_t i;
        int covered = 0;
        for (k = 0; k < c->dim; k++) y[k] = p < 8 ? (double)((p >> k) & 1) : rand() / (RAND_MAX + 1.0);
        ry = sizing ? sizing(y, NULL) : radius;
        for (i = 0; i < n && !covered; i++)
            covered = tdist(c, x + i * c->dim, y) <= tau * c->coverage * vpdsi_rule_f(c->rule, r[i], ry) * (1 + 1e-12);
        bad += !covered;
    }
    return bad;
}

static vpds_sampler *make(const setup *c, double (*sizing)(const double *, void *), double L,
                          double radius, uint64_t seed)
{
    vpds_desc d = vpds_default_desc();
    vpds_sampler *s = NULL;
    d.dim = c->dim;
    d.periodic = c->periodic;
    d.rule = c->rule;
    d.inhibition = c->inhibition;
    d.coverage = c->coverage;
    d.radius = radius;
    if (sizing) {
        d.sizing = sizing;
        d.lipschitz = L;
    }
    d.seed = seed;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    return s;
}

/* A stream of n samples: t non-increasing, prefixes valid at taus between the samples' t, each
 * conflict-free to the stream's own slack (vpds_stats.stream_slack): at most the tolerance, 1e-12
 * where version 5 finds the farthest point exactly, the domain's where a flat maximum made the
 * search give up its tolerance. */
static void check_stream(const setup *c, double (*sizing)(const double *, void *), double L,
                         double radius, size_t n)
{
    vpds_sampler *s = make(c, sizing, L, radius, 7), *twin = make(c, sizing, L, radius, 7);
    double x[3], t, prev = INFINITY, xt[3], tt, slack;
    int exact = !sizing && c->dim <= 4; /* version 5's exact farthest point */
    size_t i;
    int q;
    if (quick) n /= 7;
    for (i = 0; i < n; i++) {
        CHECK(vpds_next(s, 0, x, &t) == VPDS_OK);
        CHECK(vpds_next(twin, 0, xt, &tt) == VPDS_OK);
        CHECK(memcmp(x, xt, sizeof(double) * (size_t)c->dim) == 0 && t == tt); /* by seed */
        CHECK(t <= prev);
        CHECK(i > 0 || isinf(t)); /* the first sample of an empty sampler: t = +inf */
        prev = t;
    }
    slack = vpds_get_stats(s).stream_slack;
    CHECK(slack <= (exact ? 2e-12 : sizing == steep ? VPDS_STREAM_DOMAIN_TOLERANCE : VPDS_STREAM_TOLERANCE));
    for (q = 0; q < 6; q++) {
        /* tau just above the t of sample k: the prefix is samples [0, k) */
        size_t k = n / 8 + (size_t)q * (n - n / 8) / 6;
        const double *ts = vpds_scales(s);
        double tau;
        if (k >= n) k = n - 1;
        tau = ts[k] * (1 + 1e-9);
        while (k > 0 && ts[k - 1] < tau) k--;
        CHECK(conflicts(c, vpds_points(s), vpds_radii(s), k, tau, slack) == 0);
        CHECK(gaps(c, vpds_points(s), vpds_radii(s), k, tau, sizing, radius, 3000, 11u + (unsigned)q) == 0);
    }
    vpds_destroy(s);
    vpds_destroy(twin);
}

static void check_run_and_refine(const setup *c, double (*sizing)(const double *, void *), double L,
                                 double radius)
{
    vpds_sampler *s = make(c, sizing, L, radius, 3);
    double taus[3] = {1.0, 0.7, 0.45}, *before = NULL;
    size_t nb = 0;
    int q;
    if (quick) radius *= 2;
    vpds_destroy(s);
    s = make(c, sizing, L, radius, 3);
    CHECK(vpds_run(s) == VPDS_OK);
    for (q = 0; q < 3; q++) {
        size_t n;
        if (q > 0) CHECK(vpds_refine(s, taus[q]) == VPDS_OK);
        n = vpds_count(s);
        CHECK(conflicts(c, vpds_points(s), vpds_radii(s), n, taus[q], 0) == 0);
        CHECK(gaps(c, vpds_points(s), vpds_radii(s), n, taus[q], sizing, radius, 4000, 5u + (unsigned)q) == 0);
        if (before) CHECK(memcmp(before, vpds_points(s), nb * sizeof(double) * (size_t)c->dim) == 0);
        free(before);
        nb = n;
        before = (double *)malloc(n * sizeof(double) * (size_t)c->dim);
        memcpy(before, vpds_points(s), n * sizeof(double) * (size_t)c->dim);
    }
    /* the stream continues from the refined state, below its scale */
    {
        double x[3], t;
        size_t n = vpds_count(s);
        int i;
        for (i = 0; i < 50; i++) CHECK(vpds_next(s, 0, x, &t) == VPDS_OK && t <= 0.45);
        CHECK(conflicts(c, vpds_points(s), vpds_radii(s), n + 50, t, VPDS_STREAM_TOLERANCE) == 0);
    }
    free(before);
    vpds_destroy(s);
}

/* A stream continued after a maximal 3D run of 6,500 samples: versions 1-2 searched the whole
 * box for the first event (23 s here, and VPDS_ERR_DOMAIN "did not converge" at r = 0.03);
 * version 3 splits the regions at the run's scale. Each prefix stays conflict-free, and the
 * set stays maximal at the last event's t. */
static void check_stream_after_3d_run(void)
{
    setup c;
    vpds_sampler *s;
    double x[3], t, prev = 1.0;
    size_t n;
    int i;
    c.dim = 3; c.periodic = NULL; c.rule = VPDS_RULE_SMALLER; c.inhibition = 1; c.coverage = 1;
    s = make(&c, NULL, 0, 0.05, 31);
    CHECK(vpds_run(s) == VPDS_OK);
    n = vpds_count(s);
    for (i = 0; i < 50; i++) {
        vpds_status st = vpds_next(s, 0, x, &t);
        CHECK_MSG(st == VPDS_OK, "event %d after a 3D run: %s (%s)", i, vpds_status_string(st),
                  vpds_last_error(s));
        if (st != VPDS_OK) break;
        CHECK(t <= prev && t > 0.9);
        prev = t;
    }
    CHECK(vpds_count(s) == n + 50);
    CHECK(conflicts(&c, vpds_points(s), vpds_radii(s), vpds_count(s), prev, VPDS_STREAM_TOLERANCE) == 0);
    CHECK(gaps(&c, vpds_points(s), vpds_radii(s), vpds_count(s), prev, NULL, 0.05, 3000, 17u) == 0);
    vpds_destroy(s);
}

int main(void)
{
    static const int both[2] = {1, 1}, first[2] = {1, 0}, all3[3] = {1, 1, 1};
    setup c;
    vpds_rule rules[4] = {VPDS_RULE_PRIOR, VPDS_RULE_CURRENT, VPDS_RULE_BIGGER, VPDS_RULE_SMALLER};
    int q;
    quick = getenv("VPDS_TEST_QUICK") != NULL;

    /* streams: one and two radii, uniform and variable, open and periodic, 2D and 3D */
    c.dim = 2; c.periodic = NULL; c.rule = VPDS_RULE_SMALLER; c.inhibition = 1; c.coverage = 1;
    check_stream(&c, NULL, 0, 0.05, 700);
    c.inhibition = 0.5;
    check_stream(&c, NULL, 0, 0.05, 700);
    c.periodic = both;
    check_stream(&c, NULL, 0, 0.05, 700);
    c.periodic = NULL;
    for (q = 0; q < (quick ? 0 : 4); q++) {
        c.rule = rules[q];
        c.inhibition = q % 2 ? 1.0 : 0.6;
        check_stream(&c, ramp, 0.03, 0, 500);
    }
    /* the flat maxima of rules current and bigger on the steep ramp (VPDS_ERR_DOMAIN at the
     * 259th and the 64th event before the search fell back to the domain's tolerance) */
    c.inhibition = 1;
    for (q = 1; q < (quick ? 1 : 3); q++) {
        c.rule = rules[q];
        check_stream(&c, steep, 0.3, 0, q == 1 ? 270 : 80);
    }
    c.rule = VPDS_RULE_SMALLER; c.periodic = first; c.inhibition = 0.7;
    if (!quick) check_stream(&c, wave, 0.0629, 0, 500);
    c.dim = 3; c.periodic = NULL; c.inhibition = 1;
    check_stream(&c, NULL, 0, 0.1, 400);
    c.periodic = all3; c.inhibition = 0.5;
    check_stream(&c, NULL, 0, 0.1, 300);
    check_stream_after_3d_run();

    /* Algorithm 1 with two radii and periodic axes, then refinement and a stream after it */
    c.dim = 2; c.periodic = NULL; c.inhibition = 0.5; c.coverage = 1;
    for (q = 0; q < (quick ? 0 : 4); q++) {
        c.rule = rules[q];
        check_run_and_refine(&c, ramp, 0.03, 0);
    }
    c.rule = VPDS_RULE_SMALLER;
    if (!quick) check_run_and_refine(&c, NULL, 0, 0.04);
    c.periodic = both;
    check_run_and_refine(&c, NULL, 0, 0.04);
    c.inhibition = 1;
    if (!quick) check_run_and_refine(&c, NULL, 0, 0.04);
    c.periodic = first; c.inhibition = 0.8;
    if (!quick) check_run_and_refine(&c, wave, 0.0629, 0);
    c.dim = 3; c.periodic = all3; c.inhibition = 0.5;
    if (!quick) check_run_and_refine(&c, NULL, 0, 0.15);

    /* fixed points: the stream starts at a finite t and keeps off their disks */
    {
        vpds_sampler *s;
        double fx[4] = {0.5, 0.5, 0.2, 0.8}, fr[2] = {0.2, 0.1}, x[2], t;
        size_t i;
        c.dim = 2; c.periodic = NULL; c.inhibition = 1; c.rule = VPDS_RULE_PRIOR;
        s = make(&c, NULL, 0, 0.05, 1);
        CHECK(vpds_add_points(s, fx, fr, 2) == VPDS_OK);
        for (i = 0; i < 300; i++) CHECK(vpds_next(s, 0, x, &t) == VPDS_OK && isfinite(t));
        CHECK(conflicts(&c, vpds_points(s), vpds_radii(s), vpds_count(s), t, VPDS_STREAM_TOLERANCE) == 0);
        CHECK(gaps(&c, vpds_points(s), vpds_radii(s), vpds_count(s), t, NULL, 0.05, 3000, 3) == 0);
        /* STREAM_END consumes nothing: the next event is the same afterwards */
        {
            double x1[2], t1, x2[2], t2;
            size_t n = vpds_count(s);
            CHECK(vpds_next(s, t, x1, &t1) == VPDS_STREAM_END && vpds_count(s) == n);
            CHECK(vpds_next(s, 0, x1, &t1) == VPDS_OK);
            vpds_destroy(s);
            s = make(&c, NULL, 0, 0.05, 1);
            CHECK(vpds_add_points(s, fx, fr, 2) == VPDS_OK);
            for (i = 0; i < 301; i++) CHECK(vpds_next(s, 0, x2, &t2) == VPDS_OK);
            CHECK(memcmp(x1, x2, sizeof x1) == 0 && t1 == t2);
        }
        vpds_destroy(s);
    }

    /* allocation failures during a stream (one and two radii, from empty, and a ramp, whose
     * search to the tolerance keeps lists of the samples near its boxes from version 8): each
     * allocation of the stream fails once in turn; a retry gives the points and t of a stream
     * without them */
    {
        int two;
        for (two = 0; two < 3; two++) {
            enum { N = 250 };
            double ref[N * 2], ref_t[N], x[2], t;
            failing_alloc fa;
            vpds_desc d = vpds_default_desc();
            vpds_sampler *s;
            size_t i, k, total, failures = 0, stride;
            d.radius = 0.05;
            d.inhibition = two == 1 ? 0.5 : 1;
            d.seed = 11;
            if (two == 2) {
                d.sizing = ramp;
                d.lipschitz = 0.03;
            }
            d.allocator.alloc = fa_alloc;
            d.allocator.free = fa_free;
            d.allocator.user = &fa;
            memset(&fa, 0, sizeof fa);
            CHECK(vpds_create(&d, &s) == VPDS_OK);
            for (i = 0; i < N; i++) CHECK(vpds_next(s, 0, ref + 2 * i, ref_t + i) == VPDS_OK);
            vpds_destroy(s);
            CHECK(fa.live == 0);
            total = fa.calls;
            stride = quick ? total / 8 + 1 : 1;
            for (k = 2; k <= total; k += stride) { /* the first allocation is vpds_create's own */
                memset(&fa, 0, sizeof fa);
                CHECK(vpds_create(&d, &s) == VPDS_OK);
                fa.fail_at = k;
                for (i = 0; i < N; i++) {
                    vpds_status st;
                    size_t n = vpds_count(s);
                    while ((st = vpds_next(s, 0, x, &t)) == VPDS_ERR_OUT_OF_MEMORY) {
                        CHECK(vpds_count(s) == n && strlen(vpds_last_error(s)) > 0);
                        failures++;
                    }
                    CHECK_MSG(st == VPDS_OK && memcmp(x, ref + 2 * i, sizeof x) == 0 && t == ref_t[i],
                              "%s: sample %zu differs after failing allocation %zu",
                              two == 2 ? "a ramp" : two ? "two radii" : "one radius", i, k);
                    if (st != VPDS_OK) break;
                }
                vpds_destroy(s);
                CHECK_MSG(fa.live == 0, "leak after failing allocation %zu", k);
            }
            CHECK(failures > 0);
            printf("stream allocation failures (%s): %zu allocations, %zu failed once each\n",
                   two == 2 ? "a ramp" : two ? "two radii" : "one radius", total, failures);
        }
    }
    CHECK_DONE();
}
