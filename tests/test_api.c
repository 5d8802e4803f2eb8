/* The C API: determinism by seed, budgets and pauses resume to the same points, fixed points,
 * the custom allocator (every allocation failure recovers to the same points, nothing leaks). */
#define _GNU_SOURCE /* backtrace(), to count the allocation sites the failure test reaches */
#include "check.h"
#include "vpds.h"
#include "mem.h"
#ifdef __GLIBC__
#include <execinfo.h>
#endif
#include <math.h>
#include <string.h>

static double ramp(const double *x, void *u) { (void)u; return 0.001 + 0.3 * x[0]; }
static int ramp_batch(const double *x, size_t n, double *r, void *u)
{
    size_t i, *calls = (size_t *)u;
    for (i = 0; i < n; i++) r[i] = 0.001 + 0.3 * x[2 * i];
    calls[0]++;
    calls[1] += n;
    return 0;
}

typedef struct {
    size_t live_bytes, calls, fail_at; /* fail_at: the allocation that fails (0: none) */
    int failed;
    void *sites[64]; /* distinct library call sites that asked for memory */
    size_t n_sites;
} counting_alloc;

/* The library call site that asked the memory layer (mem.c) for memory: the first frame of
 * the stack that is not in this allocator or in mem.c's two functions. */
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
static int in_function(void *addr, void (*fn)(void))
{
    const char *a = (const char *)addr, *f = (const char *)(size_t)fn;
    return a >= f && a < f + 768; /* both mem.c functions are shorter than this */
}
#endif

static void *ca_alloc(size_t size, void *user);

#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void note_site(counting_alloc *a)
{
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__) /* instrumented code breaks the 768-byte window */
    void *frames[12];
    int n = backtrace(frames, 12), k;
    size_t i;
    for (k = 1; k < n; k++) {
        if (in_function(frames[k], (void (*)(void))(size_t)vpdsi_mem_alloc) ||
            in_function(frames[k], (void (*)(void))(size_t)vpdsi_mem_reserve) ||
            in_function(frames[k], (void (*)(void))(size_t)note_site) ||
            in_function(frames[k], (void (*)(void))(size_t)ca_alloc))
            continue;
        break;
    }
    if (k >= n) return;
    for (i = 0; i < a->n_sites; i++)
        if (a->sites[i] == frames[k]) return;
    if (a->n_sites < 64) a->sites[a->n_sites++] = frames[k];
#else
    (void)a;
#endif
}

static void *ca_alloc(size_t size, void *user)
{
    counting_alloc *a = (counting_alloc *)user;
    a->calls++;
    note_site(a);
    if (a->fail_at && a->calls == a->fail_at) {
        a->failed = 1;
        return NULL;
    }
    a->live_bytes += size;
    return malloc(size);
}
static void ca_free(void *p, size_t size, void *user)
{
    counting_alloc *a = (counting_alloc *)user;
    a->live_bytes -= size;
    free(p);
}

/* VPDS_TEST_QUICK (set under valgrind): the ramp from x = 0.01, a tenth of the samples */
static double ramp3_counted(const double *x, void *u)
{
    ++*(size_t *)u;
    return 0.08 + 0.2 * fabs(x[0]);
}

static const double quick_lo[2] = {0.01, 0.0};
static int quick;

static vpds_desc ramp_desc(uint64_t seed)
{
    vpds_desc d = vpds_default_desc();
    if (quick) d.lo = quick_lo;
    d.sizing = ramp;
    d.lipschitz = 0.3;
    d.rule = VPDS_RULE_PRIOR;
    d.seed = seed;
    return d;
}

/* Run to completion; returns a malloc'd copy of the points and writes the count. */
/* The disk of radius 0.45 around (0.5, 0.5) as a signed distance (negative inside). */
static double disk_domain(const double *x, void *user)
{
    (void)user;
    return sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5)) - 0.45;
}

static double *run_copy(const vpds_desc *d, size_t *n)
{
    vpds_sampler *s = NULL;
    double *copy;
    vpds_status st = vpds_create(d, &s);
    if (st != VPDS_OK) return NULL;
    while ((st = vpds_run(s)) == VPDS_PAUSED) {}
    if (st != VPDS_OK) {
        vpds_destroy(s);
        return NULL;
    }
    *n = vpds_count(s);
    copy = (double *)malloc(*n * (size_t)vpds_dim(s) * sizeof(double) + 1);
    memcpy(copy, vpds_points(s), *n * (size_t)vpds_dim(s) * sizeof(double));
    vpds_destroy(s);
    return copy;
}

/* Counts the chunks of work (the progress callback runs after each one), never pauses. */
static int count_chunks(const vpds_progress *p, void *user)
{
    (void)p;
    ++*(long *)user;
    return 0;
}

/* Past 8D a cell's split makes 2^d children, 2^(d-8) blocks of 256: each block is a unit of
 * the budget, so that a call stays within its budget there too. A chunk is at most 256 units
 * (and one cell), so a call of budget B ends within B / 256 + 2 chunks. When a split cell
 * counted as one unit, a 12D call of budget 4096 ran about 240 chunks of 17 cells (70,000
 * cells, 280 million children; 278 chunks in a call here), and a 16D fuzz input took seconds
 * per call. */
static void test_budget_past_8d(void)
{
    vpds_desc d = vpds_default_desc();
    double hi[12];
    vpds_sampler *s;
    vpds_status st;
    long chunks = 0, calls = 0, worst = 0;
    int k;
    for (k = 0; k < 12; k++) hi[k] = 1.0;
    d.dim = 12;
    d.hi = hi;
    d.radius = 1.8; /* 2^12 base cells, each split into 4096 children */
    d.seed = 5;
    d.budget = 4096;
    d.progress = count_chunks;
    d.progress_user = &chunks;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    do {
        chunks = 0;
        st = vpds_run(s);
        calls++;
        if (chunks > worst) worst = chunks;
    } while (st == VPDS_PAUSED && calls < 40);
    CHECK_MSG(worst <= 4096 / 256 + 2, "a call of budget 4096 in 12D ran %ld chunks", worst);
    CHECK_MSG(vpds_get_stats(s).levels > 1, "no cell was split (%u levels)", vpds_get_stats(s).levels);
    vpds_destroy(s);
}

static int pause_every_third(const vpds_progress *p, void *user)
{
    int *calls = (int *)user;
    (void)p;
    return ++*calls % 3 == 0;
}

int main(void)
{
    vpds_desc d;
    size_t n_ref, n, i;
    double *ref, *other;
    quick = getenv("VPDS_TEST_QUICK") != NULL;
    d = ramp_desc(42);
    ref = run_copy(&d, &n_ref);
    CHECK(ref != NULL && n_ref > (quick ? 300u : 1000u));

    /* same seed, same bytes; another seed, other points */
    other = run_copy(&d, &n);
    CHECK(other && n == n_ref && memcmp(ref, other, n * 2 * sizeof(double)) == 0);
    free(other);
    d.seed = 43;
    other = run_copy(&d, &n);
    CHECK(other && (n != n_ref || memcmp(ref, other, n * 2 * sizeof(double)) != 0));
    free(other);

    /* the batched sizing callback: the same points as the per-point one, in far fewer calls */
    {
        size_t calls[2] = {0, 0};
        d = ramp_desc(42);
        d.sizing = NULL;
        d.sizing_batch = ramp_batch;
        d.sizing_user = calls;
        other = run_copy(&d, &n);
        CHECK(other && n == n_ref && memcmp(ref, other, n * 2 * sizeof(double)) == 0);
        CHECK_MSG(calls[1] > 100 * calls[0], "%zu points in %zu calls", calls[1], calls[0]);
        free(other);
    }

    /* budgets of several sizes: paused many times, same points */
    {
        uint64_t budgets[] = {1, 37, 1000};
        for (i = 0; i < 3; i++) {
            vpds_sampler *s;
            int pauses = 0;
            vpds_status st;
            d = ramp_desc(42);
            d.budget = budgets[i];
            CHECK(vpds_create(&d, &s) == VPDS_OK);
            while ((st = vpds_run(s)) == VPDS_PAUSED) {
                pauses++;
                /* the samples so far are readable and a prefix of the final set */
                CHECK(vpds_count(s) <= n_ref);
                if (vpds_count(s))
                    CHECK(memcmp(vpds_points(s), ref, vpds_count(s) * 2 * sizeof(double)) == 0);
            }
            CHECK(st == VPDS_OK && pauses > 0);
            CHECK_MSG(vpds_count(s) == n_ref &&
                      memcmp(vpds_points(s), ref, n_ref * 2 * sizeof(double)) == 0,
                      "budget %llu", (unsigned long long)budgets[i]);
            CHECK(vpds_get_stats(s).maximal);
            vpds_destroy(s);
        }
    }

    test_budget_past_8d();

    /* the progress callback pauses; calling again continues to the same points */
    {
        vpds_sampler *s;
        int calls = 0, pauses = 0;
        vpds_status st;
        d = ramp_desc(42);
        d.progress = pause_every_third;
        d.progress_user = &calls;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        while ((st = vpds_run(s)) == VPDS_PAUSED) pauses++;
        CHECK(st == VPDS_OK && pauses > 3);
        CHECK(vpds_count(s) == n_ref && memcmp(vpds_points(s), ref, n_ref * 2 * sizeof(double)) == 0);
        vpds_destroy(s);
    }

    /* results: radii are r(x), scales 1, statistics filled */
    {
        vpds_sampler *s;
        vpds_stats st;
        d = ramp_desc(42);
        CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
        for (i = 0; i < vpds_count(s); i++) {
            CHECK(vpds_radii(s)[i] == ramp(vpds_points(s) + 2 * i, NULL));
            CHECK(vpds_scales(s)[i] == 1.0 && vpds_flags(s)[i] == 0);
        }
        st = vpds_get_stats(s);
        CHECK(st.darts >= st.accepted && st.accepted == vpds_count(s));
        CHECK(st.levels > 1 && st.peak_active_cells > 0 && st.peak_bytes >= st.bytes_held);
        CHECK(st.bytes_held > vpds_count(s) * 2 * sizeof(double) && st.maximal && st.delta == 0);
        CHECK(vpds_run(s) == VPDS_OK && vpds_get_stats(s).darts == st.darts); /* already maximal */
        vpds_destroy(s);
    }

    /* fixed points: kept first, flagged, t = inf, respected by later samples */
    {
        vpds_sampler *s;
        double fx[] = {0.5, 0.5, 0.2, 0.8, 3.0, 3.0}, fr[] = {0.2, 0.05, 0.5};
        d = vpds_default_desc();
        d.radius = 0.03;
        d.seed = 1;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        CHECK(vpds_add_points(s, fx, fr, 3) == VPDS_OK);
        CHECK(vpds_run(s) == VPDS_OK);
        CHECK(vpds_count(s) > 100);
        for (i = 0; i < 3; i++) {
            CHECK(vpds_flags(s)[i] == (VPDS_FLAG_FIXED | VPDS_FLAG_OWN_RADIUS));
            CHECK(isinf(vpds_scales(s)[i]) && vpds_radii(s)[i] == fr[i]);
            CHECK(vpds_points(s)[2 * i] == fx[2 * i] && vpds_points(s)[2 * i + 1] == fx[2 * i + 1]);
        }
        for (i = 3; i < vpds_count(s); i++) {
            const double *p = vpds_points(s) + 2 * i;
            double d0 = hypot(p[0] - 0.5, p[1] - 0.5), d1 = hypot(p[0] - 0.2, p[1] - 0.8);
            /* smaller rule: min(r_fixed, 0.03) */
            CHECK(d0 >= 0.03 && d1 >= 0.03);
        }
        /* added between runs: still maximal, nothing to do */
        {
            double more[] = {0.9, 0.1};
            size_t before = vpds_count(s);
            CHECK(vpds_add_points(s, more, NULL, 1) == VPDS_OK);
            CHECK(vpds_count(s) == before + 1 && vpds_radii(s)[before] == 0.03);
            CHECK(vpds_flags(s)[before] == VPDS_FLAG_FIXED);
            CHECK(vpds_run(s) == VPDS_OK && vpds_count(s) == before + 1);
        }
        vpds_destroy(s);
    }

    /* the uniform-radius grid and the kd-tree give the same samples: a fixed point far outside
     * the box with a tiny radius changes nothing but moves the run onto the kd-tree */
    {
        int dim;
        for (dim = 1; dim <= 3; dim++) {
            vpds_sampler *a, *b;
            double far[3] = {100, 100, 100}, tiny = 1e-6;
            d = vpds_default_desc();
            d.dim = dim;
            d.radius = dim == 1 ? 0.001 : dim == 2 ? 0.01 : 0.05;
            d.seed = 77;
            CHECK(vpds_create(&d, &a) == VPDS_OK && vpds_run(a) == VPDS_OK);
            CHECK(vpds_create(&d, &b) == VPDS_OK && vpds_add_points(b, far, &tiny, 1) == VPDS_OK);
            CHECK(vpds_run(b) == VPDS_OK);
            CHECK_MSG(vpds_count(b) == vpds_count(a) + 1 &&
                      memcmp(vpds_points(b) + dim, vpds_points(a),
                             vpds_count(a) * (size_t)dim * sizeof(double)) == 0,
                      "grid and kd-tree differ in %dD (%zu vs %zu samples)", dim, vpds_count(a),
                      vpds_count(b) - 1);
            vpds_destroy(a);
            vpds_destroy(b);
        }
    }

    /* fixed points keep the caller's order (many of them: the kd-tree gets them scattered) */
    {
        vpds_sampler *s;
        double fx[2 * 40], fr[40];
        for (i = 0; i < 40; i++) {
            fx[2 * i] = 0.1 + 0.02 * (double)i;
            fx[2 * i + 1] = 0.5;
            fr[i] = 0.001 * (double)(i + 1);
        }
        d = vpds_default_desc();
        d.radius = 0.05;
        CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_add_points(s, fx, fr, 40) == VPDS_OK);
        CHECK(memcmp(vpds_points(s), fx, sizeof fx) == 0 && memcmp(vpds_radii(s), fr, sizeof fr) == 0);
        CHECK(vpds_run(s) == VPDS_OK && memcmp(vpds_points(s), fx, sizeof fx) == 0);
        vpds_destroy(s);
    }

    /* a refinement that fails before any work leaves the sampler at its old scale */
    {
        counting_alloc ca;
        vpds_sampler *s;
        size_t before;
        memset(&ca, 0, sizeof ca);
        d = vpds_default_desc();
        d.radius = 0.05;
        d.allocator.alloc = ca_alloc;
        d.allocator.free = ca_free;
        d.allocator.user = &ca;
        CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
        before = vpds_count(s);
        CHECK(vpds_refine(s, 1e-7) == VPDS_ERR_OVERFLOW); /* a cell count that overflows */
        CHECK(vpds_get_stats(s).t == 1.0 && vpds_get_stats(s).maximal && vpds_count(s) == before);
        ca.fail_at = ca.calls + 1; /* the next allocation fails: the grid for t = 0.5 */
        CHECK(vpds_refine(s, 0.5) == VPDS_OK || vpds_get_stats(s).t == 1.0);
        ca.fail_at = 0;
        CHECK(vpds_refine(s, 0.5) == VPDS_OK && vpds_get_stats(s).t == 0.5 && vpds_count(s) > before);
        vpds_destroy(s);
        CHECK(ca.live_bytes == 0);
    }

    /* fixed points added after a run on the background grid, then a refinement on the kd-tree:
     * the kd-tree must hold the grid's samples too (a regression: they were missing) */
    {
        vpds_sampler *s;
        double far[2] = {50, 50}, tiny = 1e-6;
        size_t i, j, n, bad = 0;
        d = vpds_default_desc();
        d.radius = 0.05;
        d.seed = 3;
        CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
        CHECK(vpds_add_points(s, far, &tiny, 1) == VPDS_OK);
        CHECK(vpds_refine(s, 0.5) == VPDS_OK);
        n = vpds_count(s);
        for (i = 0; i < n; i++)
            for (j = 0; j < i; j++) {
                const double *a = vpds_points(s) + 2 * i, *b = vpds_points(s) + 2 * j;
                double t = vpds_scales(s)[i], f = t * (vpds_radii(s)[j] < 0.05 ? vpds_radii(s)[j] : 0.05);
                if (!isinf(t) && hypot(a[0] - b[0], a[1] - b[1]) < f) bad++;
            }
        CHECK_MSG(bad == 0, "%zu conflicting pairs after add_points and refine", bad);
        vpds_destroy(s);
    }

    /* Two radii, version 4: the coverage search's index keeps what it learns (cells shown
     * covered, witnesses), so a 3D run with periodic axes gives the points of version 3 with
     * far fewer sizing evaluations (each examined box reads r once); version 6: each indexed
     * cell keeps its sub-boxes shown covered, which later questions skip: on this run the
     * points of versions 4 and 5 again, with fewer evaluations still; version 8: a box that
     * splits tests its corner farthest from the sample covering its nearest point (the search
     * stops at an uncovered wedge on a cell's edge instead of diving 40 levels): the same
     * points, 22% fewer evaluations here */
    if (!quick) { /* native builds only: under valgrind the runs take a minute */
        static const double lo3[3] = {0, 0, 0}, hi3[3] = {1, 1, 1};
        static const int periodic3[3] = {0, 1, 1};
        static const uint32_t versions[4] = {3, 4, 6, 8};
        size_t calls[4] = {0, 0, 0, 0}, n[4] = {0, 0, 0, 0};
        double *pts[4];
        int v;
        for (v = 0; v < 4; v++) {
            vpds_desc d3 = vpds_default_desc();
            d3.dim = 3;
            d3.lo = lo3;
            d3.hi = hi3;
            d3.rule = VPDS_RULE_BIGGER;
            d3.seed = 7;
            d3.sizing = ramp3_counted;
            d3.sizing_user = &calls[v];
            d3.lipschitz = 0.2;
            d3.inhibition = 0.5;
            d3.periodic = periodic3;
            d3.algorithm_version = versions[v];
            pts[v] = run_copy(&d3, &n[v]);
        }
        CHECK(pts[0] != NULL && pts[1] != NULL && pts[2] != NULL && pts[3] != NULL);
        for (v = 1; v < 4; v++)
            CHECK_MSG(pts[0] && pts[v] && n[0] > 300 && n[0] == n[v] &&
                          memcmp(pts[0], pts[v], n[0] * 3 * sizeof(double)) == 0,
                      "version %u gave other points: %zu against %zu", (unsigned)versions[v], n[v], n[0]);
        CHECK_MSG(calls[1] < 0.85 * (double)calls[0], "version 4 read r %zu times, version 3 %zu",
                  calls[1], calls[0]);
        CHECK_MSG(calls[2] < 0.97 * (double)calls[1], "version 6 read r %zu times, version 4 %zu",
                  calls[2], calls[1]);
        CHECK_MSG(calls[3] < 0.9 * (double)calls[2], "version 8 read r %zu times, version 6 %zu",
                  calls[3], calls[2]);
        for (v = 0; v < 4; v++) free(pts[v]);
    }

    /* allocator: count the allocations of a run, then fail each one in turn (a variable-radius
     * run on the kd-tree, a uniform one on the background grid, two radii with a variable
     * radius: the coverage search and what its index learns, and a domain: the domain's search
     * takes its first lists from the grid, or from the kd-tree, built then, when they fail;
     * and a uniform one in 3D, whose split levels keep their cells as families; and one in 3D
     * at the precision limit, a box of side 1e-5 at 1e6, where the grid and the kd-tree give
     * other valid samplings: a grid that fails to allocate is an error, never a switch) */
    {
        int which;
        for (which = 0; which < 6; which++) {
            counting_alloc ca;
            vpds_sampler *s = NULL;
            size_t total, k, reached = 0, n_base, sites;
            double *base;
            memset(&ca, 0, sizeof ca);
            d = ramp_desc(42);
            if (which == 1) {
                d = vpds_default_desc();
                d.radius = 0.02;
                d.seed = 3;
            } else if (which == 2) {
                static const double lo2[2] = {0.05, 0.0}, lo2_quick[2] = {0.3, 0.0};
                d.lo = quick ? lo2_quick : lo2; /* r >= 0.016 (0.091): a few hundred samples */
                d.rule = VPDS_RULE_SMALLER;
                d.inhibition = 0.5;
                d.seed = 5;
            } else if (which == 3) {
                d = vpds_default_desc();
                d.radius = quick ? 0.02 : 0.006; /* 20,000 samples: a few batches (valgrind: 1,800) */
                d.domain = disk_domain;
                d.seed = 9;
            } else if (which == 4) {
                d = vpds_default_desc();
                d.dim = 3;
                d.radius = quick ? 0.2 : 0.1; /* 1,500 samples (valgrind: 200) */
                d.seed = 4;
            } else if (which == 5) {
                static const double lo5[3] = {1e6, 1e6, 1e6}, hi5[3] = {1e6 + 1e-5, 1e6 + 1e-5, 1e6 + 1e-5};
                d = vpds_default_desc();
                d.dim = 3;
                d.lo = lo5;
                d.hi = hi5;
                d.radius = 1e-6; /* 837 samples */
                d.seed = 7;
            }
            base = run_copy(&d, &n_base);
            d.allocator.alloc = ca_alloc;
            d.allocator.free = ca_free;
            d.allocator.user = &ca;
            CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
            CHECK(vpds_count(s) == n_base && memcmp(vpds_points(s), base, n_base * (size_t)d.dim * sizeof(double)) == 0);
            vpds_destroy(s);
            CHECK(ca.live_bytes == 0);
            total = ca.calls;
            sites = ca.n_sites;
            CHECK(total > 10);
            for (k = 1; k <= total; k++) {
                vpds_status st;
                memset(&ca, 0, sizeof ca);
                ca.fail_at = k;
                s = NULL;
                st = vpds_create(&d, &s);
                if (st == VPDS_OK) {
                    while ((st = vpds_run(s)) == VPDS_ERR_OUT_OF_MEMORY) {
                        CHECK(ca.failed);
                        CHECK(strlen(vpds_last_error(s)) > 0);
                        ca.fail_at = 0; /* memory is back: continue */
                        reached++;
                    }
                    CHECK_MSG(st == VPDS_OK && vpds_count(s) == n_base &&
                              memcmp(vpds_points(s), base, n_base * (size_t)d.dim * sizeof(double)) == 0,
                              "after failing allocation %zu", k);
                    vpds_destroy(s);
                } else {
                    CHECK(st == VPDS_ERR_OUT_OF_MEMORY && s == NULL);
                    reached++;
                }
                CHECK_MSG(ca.live_bytes == 0, "leak after failing allocation %zu", k);
            }
            /* every allocation of the grid's is seen (its setup, the candidates and their packed
             * coordinates and tags: the index stays the grid); the coverage search's candidate
             * lists may fail without an error (its tests then read the kd-trees, with the same
             * answers), which two radii and a domain's search both use, and so may the domain's
             * search's buffer for the grid's candidates (it then reads the kd-tree) */
            CHECK_MSG(reached <= total && total - reached <= (which == 2 ? 1u : which == 3 ? 2u : 0u),
                      "%zu of %zu failing allocations went unseen", total - reached, total);
            printf("allocation failure (%s): %zu allocations from %zu call sites (0: not counted in"
                   " this build), each failed once, %zu seen as VPDS_ERR_OUT_OF_MEMORY\n",
                   which == 5 ? "3D uniform, precision limit" : which == 4 ? "3D uniform, families" : which == 3 ? "uniform, a domain" : which == 2 ? "ramp, two radii" : which ? "uniform, grid" : "ramp, kd-tree", total,
                   sites, reached);
            free(base);
        }
    }
    free(ref);
    CHECK_DONE();
}
