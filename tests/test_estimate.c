/* vpds_estimate against the runs it estimates (samples, base cells, peak bytes) in 1D-6D, with
 * a variable radius, two radii and a domain; vpds_set_memory_limit refusing up front, failing
 * mid-run like an allocator, and both leaving the sampler as it was. */
#include "check.h"
#include "vpds.h"
#include <math.h>
#include <string.h>

static double ramp(const double *x, void *u) { (void)u; return 0.002 + 0.2 * x[0]; }
static double wide_ramp(const double *x, void *u) { (void)u; return 3 + 0.2 * x[0]; }
static double bad_sizing(const double *x, void *u) { (void)u; return x[0] > 0.5 ? NAN : 0.05; }
static double disk(const double *x, void *u)
{
    (void)u;
    return sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5)) - 0.4;
}
static double nan_domain(const double *x, void *u) { (void)x; (void)u; return NAN; }

static vpds_desc uniform(int dim, double radius)
{
    vpds_desc d = vpds_default_desc();
    d.dim = dim;
    d.radius = radius;
    d.seed = 5;
    return d;
}

/* The estimate before a run against what the run then did. */
static void check_estimate(const char *what, vpds_desc d, double samples_tol, double bytes_tol)
{
    vpds_sampler *s = NULL;
    vpds_run_estimate e;
    vpds_stats st;
    double n, ratio_n, ratio_b;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    if (!s) return;
    CHECK_MSG(vpds_estimate(s, 0, &e) == VPDS_OK, "%s: %s", what, vpds_last_error(s));
    CHECK(vpds_run(s) == VPDS_OK);
    st = vpds_get_stats(s);
    n = (double)vpds_count(s);
    ratio_n = e.samples / n;
    ratio_b = e.bytes / (double)st.peak_bytes;
    CHECK_MSG(ratio_n > 1 / samples_tol && ratio_n < samples_tol, "%s: %.0f samples, estimated %.0f",
              what, n, e.samples);
    CHECK_MSG(ratio_b > 1 / bytes_tol && ratio_b < bytes_tol, "%s: peak %zu bytes, estimated %.0f",
              what, st.peak_bytes, e.bytes);
    CHECK_MSG(e.cells >= e.base_cells * 0.99 || d.domain, "%s: %g cells < %g base cells", what, e.cells,
              e.base_cells);
    vpds_destroy(s);
}

/* The base grid: side t * coverage * r / sqrt(d) (just under), so in 2D with r = 0.1 at t = 1,
 * ceil(1 / (0.1 / sqrt 2)) = 15 cells per axis; at t = 0.5, 29. */
static void check_base_cells(void)
{
    vpds_desc d = uniform(2, 0.1);
    vpds_sampler *s = NULL;
    vpds_run_estimate e;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_estimate(s, 0, &e) == VPDS_OK && e.base_cells == 15 * 15);
    CHECK(vpds_estimate(s, 0.5, &e) == VPDS_OK && e.base_cells == 29 * 29);
    /* a quarter of the radius: about 4^2 the samples */
    {
        vpds_run_estimate q;
        CHECK(vpds_estimate(s, 1, &e) == VPDS_OK && vpds_estimate(s, 0.25, &q) == VPDS_OK);
        CHECK_MSG(q.samples > 12 * e.samples && q.samples < 17 * e.samples, "%g then %g", e.samples,
                  q.samples);
    }
    vpds_destroy(s);
}

static void check_bad_arguments(void)
{
    vpds_desc d = uniform(2, 0.05);
    vpds_sampler *s = NULL;
    vpds_run_estimate e;
    CHECK(vpds_estimate(NULL, 0, &e) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_set_memory_limit(NULL, 1) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_estimate(s, 0, NULL) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vpds_last_error(s), "out is NULL") != NULL);
    CHECK(vpds_estimate(s, -1, &e) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(vpds_last_error(s), "t = -1") != NULL);
    CHECK(vpds_estimate(s, NAN, &e) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_estimate(s, INFINITY, &e) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_estimate(s, 1e-60, &e) == VPDS_ERR_INVALID_ARGUMENT);
    vpds_destroy(s);

    d.sizing = bad_sizing;
    d.lipschitz = 0.1;
    d.radius_max = 0.05;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_estimate(s, 0, &e) == VPDS_ERR_SIZING && vpds_last_error(s)[0] != 0);
    vpds_destroy(s);

    d = uniform(2, 0.05);
    d.domain = nan_domain;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_estimate(s, 0, &e) == VPDS_ERR_DOMAIN && strstr(vpds_last_error(s), "NaN") != NULL);
    vpds_destroy(s);
}

static double *copy_points(const vpds_sampler *s, size_t *n)
{
    size_t bytes = vpds_count(s) * (size_t)vpds_dim(s) * sizeof(double);
    double *c = (double *)malloc(bytes ? bytes : 1);
    if (c && bytes) memcpy(c, vpds_points(s), bytes);
    *n = vpds_count(s);
    return c;
}

/* A refusal changes nothing: the points after lifting the limit are those of a sampler that
 * never had one, and an estimate does not change them either. */
static void check_memory_limit(void)
{
    vpds_desc d = uniform(2, 0.01);
    vpds_sampler *ref = NULL, *s = NULL;
    vpds_run_estimate e;
    double *a, *b;
    size_t na, nb;
    vpds_status st;
    CHECK(vpds_create(&d, &ref) == VPDS_OK && vpds_run(ref) == VPDS_OK);
    CHECK(vpds_refine(ref, 0.5) == VPDS_OK);
    a = copy_points(ref, &na);

    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_estimate(s, 0, &e) == VPDS_OK);
    CHECK(vpds_set_memory_limit(s, (size_t)(e.bytes / 4)) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_ERR_OUT_OF_MEMORY && vpds_count(s) == 0);
    CHECK_MSG(strstr(vpds_last_error(s), "memory limit") && strstr(vpds_last_error(s), "samples"),
              "%s", vpds_last_error(s));
    /* under a limit the run fits in: it runs, and the refinement's estimate (4x) is refused */
    CHECK(vpds_set_memory_limit(s, (size_t)(e.bytes * 2)) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_OK);
    CHECK(vpds_refine(s, 0.5) == VPDS_ERR_OUT_OF_MEMORY);
    CHECK(vpds_get_stats(s).t == 1 && vpds_get_stats(s).maximal);
    CHECK(vpds_set_memory_limit(s, 0) == VPDS_OK && vpds_refine(s, 0.5) == VPDS_OK);
    b = copy_points(s, &nb);
    CHECK(na == nb && memcmp(a, b, na * 2 * sizeof(double)) == 0);
    free(b);
    vpds_destroy(s);

    /* mid-run (paused, so no estimate is made): the limit fails an allocation, the run can go on */
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_set_budget(s, 2000) == VPDS_OK && vpds_run(s) == VPDS_PAUSED);
    CHECK(vpds_set_memory_limit(s, vpds_get_stats(s).bytes_held + 64) == VPDS_OK);
    while ((st = vpds_run(s)) == VPDS_PAUSED) {}
    CHECK_MSG(st == VPDS_ERR_OUT_OF_MEMORY && strstr(vpds_last_error(s), "was reached"), "%d %s",
              (int)st, vpds_last_error(s));
    CHECK(vpds_get_stats(s).peak_bytes <= vpds_get_stats(s).bytes_held + 64 + 1024 * 1024);
    CHECK(vpds_set_memory_limit(s, 0) == VPDS_OK && vpds_set_budget(s, 0) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_OK && vpds_refine(s, 0.5) == VPDS_OK);
    b = copy_points(s, &nb);
    CHECK(na == nb && memcmp(a, b, na * 2 * sizeof(double)) == 0);
    free(b);
    vpds_destroy(s);
    free(a);
    vpds_destroy(ref);
}

/* 16D, r = 2.5 on the unit box: 65,536 base cells each splitting into 65,536 children, a run
 * that would not fit; the estimate says so and a limit refuses it at once. */
static void check_too_large(void)
{
    vpds_desc d = uniform(16, 2.5);
    vpds_sampler *s = NULL;
    vpds_run_estimate e;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_estimate(s, 0, &e) == VPDS_OK && e.base_cells == 65536.0);
    CHECK_MSG(e.bytes > 4e9, "16D estimate %g bytes", e.bytes);
    CHECK(vpds_set_memory_limit(s, (size_t)1 << 30) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_ERR_OUT_OF_MEMORY && vpds_count(s) == 0);
    vpds_destroy(s);
}

/* The allocator of check_rmax_memory: malloc, noting the largest single request. */
static void *largest_alloc(size_t size, void *user)
{
    size_t *largest = (size_t *)user;
    if (size > *largest) *largest = size;
    return malloc(size);
}
static void largest_free(void *p, size_t size, void *user)
{
    (void)size;
    (void)user;
    free(p);
}

/* r_max of a sizing was read on a lattice of 3^d points from 7 dimensions on (531,441 in 12D,
 * 43 million in 16D): version 6 reads it in chunks, so its memory does not grow with 3^d (it
 * was one 55 MB block in 12D and 5.8 GB in 16D: the fuzzers' out-of-memory); version 7 reads at
 * most 4096 probes in any dimension. */
static void check_rmax_memory(uint32_t version, double max_calls)
{
    vpds_desc d = uniform(12, 3);
    vpds_sampler *s = NULL;
    vpds_run_estimate e;
    size_t largest = 0;
    d.sizing = wide_ramp;
    d.lipschitz = 0.2;
    d.algorithm_version = version;
    d.allocator.alloc = largest_alloc;
    d.allocator.free = largest_free;
    d.allocator.user = &largest;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK_MSG(vpds_estimate(s, 0, &e) == VPDS_OK, "%s", vpds_last_error(s));
    CHECK_MSG(largest < 1024 * 1024, "12D sizing, version %u: a single allocation of %zu bytes", version, largest);
    CHECK_MSG((double)vpds_get_stats(s).sizing_calls <= max_calls && vpds_get_stats(s).sizing_calls > 4096,
              "12D sizing, version %u: %llu sizing calls for r_max", version,
              (unsigned long long)vpds_get_stats(s).sizing_calls);
    CHECK(vpds_set_budget(s, 200) == VPDS_OK);
    CHECK_MSG(vpds_run(s) == VPDS_PAUSED && vpds_count(s) > 0, "%s", vpds_last_error(s));
    vpds_destroy(s);
}

int main(void)
{
    static const double radius[7] = {0, 0.0005, 0.01, 0.04, 0.15, 0.4, 0.6};
    vpds_desc d;
    int dim;
    char what[64];
    /* under valgrind (VPDS_TEST_QUICK) the 5D, 6D, 3D two-radii and ramp runs are left out */
    int quick = getenv("VPDS_TEST_QUICK") != NULL;
    for (dim = 1; dim <= (quick ? 4 : 6); dim++) {
        snprintf(what, sizeof what, "%dD uniform r = %g", dim, radius[dim]);
        check_estimate(what, uniform(dim, radius[dim]), 1.3, 2);
    }
    d = uniform(2, 1);
    d.sizing = ramp;
    d.lipschitz = 0.2;
    if (!quick) check_estimate("2D ramp 0.002 + 0.2x", d, 1.3, 2);
    d = uniform(2, 0.01);
    d.inhibition = 0.5;
    check_estimate("2D two radii", d, 1.3, 2);
    d = uniform(3, 0.08);
    d.inhibition = 0.5;
    if (!quick) check_estimate("3D two radii", d, 1.3, 2);
    d = uniform(2, 0.01);
    d.domain = disk;
    check_estimate("2D disk domain", d, 1.3, 2);
    check_base_cells();
    check_bad_arguments();
    check_memory_limit();
    check_too_large();
    check_rmax_memory(6, 531441 + 4096 + 16); /* and 4096 the estimate reads itself */
    check_rmax_memory(7, 4096 + 4096 + 16);
    CHECK_DONE();
}
