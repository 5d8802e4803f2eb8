/* Every error path: the status, a message naming the argument and value, and nothing changed. */
#include "check.h"
#include "vpds.h"
#include <math.h>
#include <string.h>

static vpds_status refused(const vpds_desc *d, const char *needle, vpds_status want)
{
    char msg[512];
    vpds_sampler *s = (vpds_sampler *)&msg; /* must be reset to NULL */
    vpds_status v = vpds_validate(d, msg, sizeof msg), c = vpds_create(d, &s);
    CHECK_MSG(v == want && c == want, "want %d, validate %d, create %d (%s)", want, v, c, msg);
    CHECK_MSG(s == NULL, "create left *out set");
    CHECK_MSG(strstr(msg, needle) != NULL, "message '%s' lacks '%s'", msg, needle);
    return v;
}

static double ramp(const double *x, void *u) { (void)u; return 0.001 + 0.3 * x[0]; }
static double big(const double *x, void *u) { (void)x; (void)u; return 0.6; }
static void *only_alloc(size_t n, void *u) { (void)u; return malloc(n); }
static double steep(const double *x, void *u) { (void)u; return 0.01 + 0.4 * x[0]; }
static double seam(const double *x, void *u) { (void)u; return 0.03 + 0.04 * x[0]; }

/* Returns a bad value at the k-th call (0: never), chosen by *mode. */
typedef struct { int calls, bad_at; double bad; } flaky_t;
static double flaky(const double *x, void *u)
{
    flaky_t *f = (flaky_t *)u;
    f->calls++;
    if (f->bad_at && f->calls == f->bad_at) return f->bad;
    return 0.001 + 0.3 * x[0];
}

int main(void)
{
    vpds_desc d;
    double lo[2] = {0, 0}, hi[2] = {1, 1}, bad[2];
    int periodic[2] = {0, 1};
    vpds_sampler *s;
    char msg[256];

    /* descriptors that did not come from vpds_default_desc */
    memset(&d, 0, sizeof d);
    refused(&d, "cookie", VPDS_ERR_BAD_DESCRIPTOR);
    memset(&d, 0xAB, sizeof d);
    refused(&d, "cookie", VPDS_ERR_BAD_DESCRIPTOR);
    d = vpds_default_desc();
    d.struct_size -= 8; /* an older, shorter layout */
    refused(&d, "struct_size", VPDS_ERR_BAD_DESCRIPTOR);
    CHECK(vpds_validate(NULL, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "NULL"));
    CHECK(vpds_create(NULL, &s) == VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc();
    CHECK(vpds_create(&d, NULL) == VPDS_ERR_INVALID_ARGUMENT);
    d.algorithm_version = VPDS_ALGORITHM_VERSION + 1;
    refused(&d, "algorithm_version", VPDS_ERR_UNSUPPORTED);

    /* dimension and box */
    d = vpds_default_desc(); d.dim = 0; refused(&d, "desc.dim = 0", VPDS_ERR_INVALID_ARGUMENT);
    d.dim = VPDS_MAX_DIM + 1; refused(&d, "desc.dim = 17: must be in 1..16", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); bad[0] = 0; bad[1] = 1; d.lo = bad; d.hi = hi;
    bad[1] = 1; refused(&d, "desc.lo[1] = 1 >= desc.hi[1] = 1", VPDS_ERR_INVALID_ARGUMENT);
    bad[1] = NAN; refused(&d, "desc.lo[1] = nan", VPDS_ERR_INVALID_ARGUMENT);
    d.lo = lo; d.hi = bad; bad[0] = INFINITY; bad[1] = 1;
    refused(&d, "desc.hi[0] = inf", VPDS_ERR_INVALID_ARGUMENT);
    bad[0] = -1e308; bad[1] = 1e308; d.lo = bad; d.hi = NULL;
    d.hi = bad; lo[0] = -1e308; /* extent overflows */
    {
        double l2[2] = {-1e308, 0}, h2[2] = {1e308, 1};
        d.lo = l2; d.hi = h2;
        refused(&d, "overflows", VPDS_ERR_OVERFLOW);
    }
    d = vpds_default_desc(); d.periodic = periodic; d.radius = 0.5;
    refused(&d, "desc.periodic[1]: the side 1 is not above 2 * coverage * radius = 1", VPDS_ERR_INVALID_ARGUMENT);

    /* radius, rule, radii factors */
    d = vpds_default_desc(); d.radius = 0; refused(&d, "desc.radius = 0", VPDS_ERR_INVALID_ARGUMENT);
    d.radius = -1; refused(&d, "desc.radius = -1", VPDS_ERR_INVALID_ARGUMENT);
    d.radius = NAN; refused(&d, "desc.radius = nan", VPDS_ERR_INVALID_ARGUMENT);
    d.radius = INFINITY; refused(&d, "desc.radius = inf", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.rule = (vpds_rule)7; refused(&d, "desc.rule = 7", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.inhibition = 2; refused(&d, "desc.inhibition = 2 > desc.coverage = 1", VPDS_ERR_INVALID_ARGUMENT);
    d.inhibition = NAN; refused(&d, "desc.inhibition = nan", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.coverage = 0; refused(&d, "desc.coverage = 0", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.inhibition = 0.5;
    CHECK(vpds_validate(&d, msg, sizeof msg) == VPDS_OK); /* two radii */
    d = vpds_default_desc(); d.weighted = 1; d.sizing = ramp; d.lipschitz = 0.3;
    refused(&d, "desc.weighted with a sizing callback needs desc.radius_min", VPDS_ERR_INVALID_ARGUMENT);
    /* weighted: a callback going below the declared radius_min is caught */
    d.radius_min = 0.1; d.seed = 2;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_ERR_SIZING && strstr(vpds_last_error(s), "below radius_min = 0.1"));
    vpds_destroy(s);
    d = vpds_default_desc(); d.radius_min = -1; refused(&d, "desc.radius_min = -1", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.radius_max = NAN; refused(&d, "desc.radius_max = nan", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.radius_min = 2; d.radius_max = 1; refused(&d, "radius_min = 2 > desc.radius_max = 1", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.allocator.alloc = only_alloc;
    refused(&d, "allocator", VPDS_ERR_INVALID_ARGUMENT);

    /* Lipschitz: required with a callback; at the rule's limit refused (Table 1) */
    d = vpds_default_desc(); d.sizing = ramp; refused(&d, "desc.lipschitz is required", VPDS_ERR_INVALID_ARGUMENT);
    d.lipschitz = NAN; refused(&d, "desc.lipschitz = nan", VPDS_ERR_INVALID_ARGUMENT);
    d.lipschitz = -0.5; refused(&d, "desc.lipschitz = -0.5", VPDS_ERR_INVALID_ARGUMENT);
    d.lipschitz = 0.5; d.rule = VPDS_RULE_PRIOR; refused(&d, "prior rule's limit 0.5", VPDS_ERR_INVALID_ARGUMENT);
    d.rule = VPDS_RULE_BIGGER; refused(&d, "bigger rule's limit 0.5", VPDS_ERR_INVALID_ARGUMENT);
    d.lipschitz = 1.0; d.rule = VPDS_RULE_CURRENT; refused(&d, "current rule's limit 1", VPDS_ERR_INVALID_ARGUMENT);
    d.rule = VPDS_RULE_SMALLER; refused(&d, "smaller rule's limit 1", VPDS_ERR_INVALID_ARGUMENT);
    d.rule = VPDS_RULE_DEFAULT; refused(&d, "smaller rule's limit 1", VPDS_ERR_INVALID_ARGUMENT);
    d.lipschitz = 0.6; d.coverage = 2; d.inhibition = 2; refused(&d, "coverage * L = 2 * 0.6", VPDS_ERR_INVALID_ARGUMENT);
    d = vpds_default_desc(); d.lipschitz = 0.49; d.rule = VPDS_RULE_PRIOR; d.sizing = ramp;
    CHECK(vpds_validate(&d, msg, sizeof msg) == VPDS_OK);

    /* magnitudes whose squares would overflow or underflow */
    d = vpds_default_desc(); d.radius = 1e-300; refused(&d, "desc.radius = 1e-300: must be within [1e-100, 1e100]", VPDS_ERR_OVERFLOW);
    d.radius = 1e200; refused(&d, "desc.radius = 1e+200", VPDS_ERR_OVERFLOW);
    {
        double l3[2] = {0, 0}, h3[2] = {1e200, 1};
        d = vpds_default_desc(); d.lo = l3; d.hi = h3;
        refused(&d, "coordinates must stay within 1e150", VPDS_ERR_OVERFLOW);
        h3[0] = 1e-200;
        refused(&d, "the extent at least 1e-150", VPDS_ERR_OVERFLOW);
    }
    d = vpds_default_desc(); d.coverage = d.inhibition = 1e60; refused(&d, "must be within [1e-50, 1e50]", VPDS_ERR_OVERFLOW);

    /* a request whose base grid overflows: refused at run, sampler unchanged and usable */
    {
        static double l4[2] = {0, 0}, h4[2] = {1e100, 1};
        d = vpds_default_desc(); d.radius = 1e-90; d.lo = l4; d.hi = h4;
    }
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_ERR_OVERFLOW && strstr(vpds_last_error(s), "overflows"));
    CHECK(vpds_count(s) == 0);
    vpds_destroy(s);

    /* a sizing callback returning NaN, Inf, 0, a negative value: stops with VPDS_ERR_SIZING and
     * where; the samples before stay valid; once the callback behaves, a retry gives the points
     * of a run that never failed */
    {
        double bads[] = {NAN, INFINITY, 0.0, -0.25};
        const char *names[] = {"r = nan", "r = inf", "r = 0", "r = -0.25"};
        size_t n_ref, i;
        double *ref;
        flaky_t f = {0, 0, 0};
        d = vpds_default_desc(); d.sizing = flaky; d.sizing_user = &f; d.lipschitz = 0.3; d.seed = 5;
        CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
        n_ref = vpds_count(s);
        ref = (double *)malloc(n_ref * 2 * sizeof(double));
        memcpy(ref, vpds_points(s), n_ref * 2 * sizeof(double));
        vpds_destroy(s);
        for (i = 0; i < 4; i++) {
            size_t before;
            f.calls = 0; f.bad_at = 3000; f.bad = bads[i];
            CHECK(vpds_create(&d, &s) == VPDS_OK);
            CHECK(vpds_run(s) == VPDS_ERR_SIZING);
            CHECK_MSG(strstr(vpds_last_error(s), names[i]) && strstr(vpds_last_error(s), "at x = ("),
                      "%s", vpds_last_error(s));
            before = vpds_count(s);
            CHECK(before > 0 && before < n_ref);
            CHECK(memcmp(vpds_points(s), ref, before * 2 * sizeof(double)) == 0);
            f.bad_at = 0;
            CHECK(vpds_run(s) == VPDS_OK);
            CHECK(vpds_count(s) == n_ref && memcmp(vpds_points(s), ref, n_ref * 2 * sizeof(double)) == 0);
            vpds_destroy(s);
        }
        free(ref);
    }

    /* a sizing seen to break its declared L: a distinct status that says where */
    d = vpds_default_desc(); d.sizing = steep; d.lipschitz = 0.2; d.seed = 1;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_ERR_LIPSCHITZ);
    {
        const char *slope = strstr(vpds_last_error(s), "slope ");
        CHECK_MSG(strstr(vpds_last_error(s), "breaks lipschitz = 0.2") && slope &&
                  atof(slope + 6) > 0.2 && atof(slope + 6) <= 0.4 + 1e-12, "%s", vpds_last_error(s));
    }
    CHECK(vpds_count(s) > 0);
    vpds_destroy(s);
    {
        /* across a periodic seam: r jumps from 0.07 back to 0.03, and the message's distance and
         * slope are the wrapped ones the check read (they were the unwrapped, a slope below L) */
        int periodic[2] = {1, 0};
        const char *slope;
        d = vpds_default_desc(); d.sizing = seam; d.lipschitz = 0.05; d.periodic = periodic;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        CHECK(vpds_run(s) == VPDS_ERR_LIPSCHITZ);
        slope = strstr(vpds_last_error(s), "slope ");
        CHECK_MSG(slope && atof(slope + 6) > 0.05, "%s", vpds_last_error(s));
        vpds_destroy(s);
    }

    /* fixed points */
    d = vpds_default_desc();
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    {
        double x[4] = {0.5, 0.5, NAN, 0.2}, r[2] = {0.1, -1}, huge[2] = {1e200, 0};
        CHECK(vpds_add_points(s, huge, NULL, 1) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "within 1e150"));
        CHECK(vpds_add_points(s, NULL, NULL, 1) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "x is NULL"));
        CHECK(vpds_add_points(s, x, NULL, 2) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "x[1][0] = nan"));
        CHECK(vpds_add_points(s, x, r, 1) == VPDS_OK);
        x[2] = 0.1;
        CHECK(vpds_add_points(s, x, r, 2) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "r[1] = -1"));
        CHECK(vpds_count(s) == 1);
        CHECK(vpds_add_points(s, x, r, 0) == VPDS_OK && vpds_count(s) == 1);
    }
    /* refinement and the stream */
    CHECK(vpds_refine(s, NAN) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "t = nan"));
    CHECK(vpds_refine(s, -1) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_refine(s, 1e-60) == VPDS_ERR_OVERFLOW && strstr(vpds_last_error(s), "[1e-50, 1e50]"));
    CHECK(vpds_run(s) == VPDS_OK);
    CHECK(vpds_refine(s, 1.0) == VPDS_OK); /* already maximal at 1 */
    CHECK(vpds_refine(s, 1.5) == VPDS_ERR_STATE && strstr(vpds_last_error(s), "t = 1.5"));
    {
        double x[2], t;
        size_t n = vpds_count(s);
        CHECK(vpds_next(s, 0, NULL, &t) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "x_out"));
        CHECK(vpds_next(s, 0, x, NULL) == VPDS_ERR_INVALID_ARGUMENT);
        CHECK(vpds_next(s, NAN, x, &t) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "NaN"));
        CHECK(vpds_next(s, 1.0, x, &t) == VPDS_STREAM_END && vpds_count(s) == n); /* maximal at 1 */
        CHECK(vpds_next(s, 0, x, &t) == VPDS_OK && t <= 1.0 && vpds_count(s) == n + 1);
        CHECK(vpds_refine(s, t) == VPDS_OK);              /* already maximal at the stream's t */
        CHECK(vpds_refine(s, t * 1.01) == VPDS_ERR_STATE); /* above the stream's scale */
    }
    vpds_destroy(s);

    /* a stream cannot start inside an unfinished run */
    d = vpds_default_desc(); d.radius = 0.02; d.budget = 100;
    CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_PAUSED);
    {
        double x[2], t;
        size_t n = vpds_count(s);
        CHECK(vpds_next(s, 0, x, &t) == VPDS_ERR_STATE && strstr(vpds_last_error(s), "not finished"));
        CHECK(vpds_count(s) == n);
    }
    vpds_destroy(s);

    /* periodic: a sizing whose radius makes a disk meet its own image at the run's scale */
    d = vpds_default_desc(); d.periodic = periodic; d.sizing = big; d.lipschitz = 0;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_ERR_INVALID_ARGUMENT && strstr(vpds_last_error(s), "periodic axis 1"));
    CHECK(vpds_count(s) == 0);
    vpds_destroy(s);

    /* refining while a run at another scale is paused */
    d = vpds_default_desc(); d.radius = 0.02; d.budget = 100;
    CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_PAUSED);
    CHECK(vpds_refine(s, 0.5) == VPDS_ERR_STATE && strstr(vpds_last_error(s), "is not finished"));
    {
        size_t before = vpds_count(s);
        vpds_status st;
        while ((st = vpds_run(s)) == VPDS_PAUSED) {}
        CHECK(st == VPDS_OK && vpds_count(s) >= before);
    }
    vpds_destroy(s);

    /* a grid whose node spacing underflows */
    {
        vpds_grid_desc gd = vpds_default_grid_desc();
        size_t shape[1] = {3};
        double v[3] = {1, 1, 1}, glo[1] = {0}, ghi[1] = {4e-324};
        vpds_grid *g = NULL;
        gd.dim = 1; gd.shape = shape; gd.values = v; gd.lo = glo; gd.hi = ghi;
        CHECK(vpds_grid_validate(&gd, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "node spacing"));
        CHECK(vpds_grid_create(&gd, &g) == VPDS_ERR_INVALID_ARGUMENT && g == NULL);
    }

    /* NULL sampler everywhere */
    CHECK(vpds_run(NULL) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_refine(NULL, 0.5) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_add_points(NULL, lo, NULL, 1) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_set_budget(NULL, 1) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_count(NULL) == 0 && vpds_points(NULL) == NULL && vpds_radii(NULL) == NULL);
    CHECK(vpds_scales(NULL) == NULL && vpds_flags(NULL) == NULL && vpds_dim(NULL) == 0);
    CHECK(strstr(vpds_last_error(NULL), "NULL") != NULL);
    CHECK(vpds_get_stats(NULL).darts == 0);
    vpds_destroy(NULL);
    {
        double x[2], t;
        CHECK(vpds_next(NULL, 0, x, &t) == VPDS_ERR_INVALID_ARGUMENT);
    }
    /* every status has a name */
    CHECK(strstr(vpds_status_string(VPDS_ERR_LIPSCHITZ), "Lipschitz") != NULL);
    CHECK(strstr(vpds_status_string((vpds_status)99), "unknown") != NULL);
    CHECK(strcmp(vpds_version_string(), "1.0.0") == 0);
    CHECK_DONE();
}
