/* vpds_next_n and vpds_mesh_next_n: the events of n calls of vpds_next in one call.
 * - in batches of any size, the same points and t, bit for bit, as one call per event (one and
 *   two radii, periodic axes, a ramp under each rule, 3D, a mesh);
 * - NULL outputs still store the events; t_min ends a batch early with VPDS_STREAM_END and the
 *   count of the events above it; bad arguments and a paused run are refused with a message,
 *   nothing changed;
 * - an allocation that fails mid-batch keeps the events before it, and the retry continues
 *   the stream a run without the failure gives. */
#include "check.h"
#include "failing_alloc.h"
#include "vpds.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static double ramp(const double *x, void *u) { (void)u; return 0.02 + 0.03 * x[0]; }


typedef struct {
    const char *name;
    int dim, ramp;
    vpds_rule rule;
    double inhibition;
    int periodic;
} config;

static vpds_desc desc_of(const config *c, const int *periodic)
{
    vpds_desc d = vpds_default_desc();
    d.dim = c->dim;
    d.radius = c->dim == 2 ? 0.05 : 0.12;
    d.rule = c->rule;
    d.inhibition = c->inhibition;
    d.periodic = c->periodic ? periodic : NULL;
    if (c->ramp) {
        d.sizing = ramp;
        d.lipschitz = 0.03;
    }
    d.seed = 21;
    return d;
}

/* n events one call each into x, t. */
static void reference(const vpds_desc *d, size_t n, double *x, double *t)
{
    vpds_sampler *s;
    size_t i;
    CHECK(vpds_create(d, &s) == VPDS_OK);
    for (i = 0; i < n; i++) CHECK(vpds_next(s, 0, x + i * (size_t)d->dim, t + i) == VPDS_OK);
    vpds_destroy(s);
}

/* The same events in batches of 1, 2, 3, ... (the last one longer than what is left). */
static void check_batches(const config *c)
{
    enum { N = 300 };
    static const int periodic[3] = {1, 1, 1};
    vpds_desc d = desc_of(c, periodic);
    double ref[N * 3], ref_t[N], x[N * 3], t[N];
    vpds_sampler *s;
    size_t done = 0, batch = 1, got;
    int dim = c->dim;
    reference(&d, N, ref, ref_t);
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    while (done < N) {
        size_t want = done + batch > N ? N - done : batch;
        vpds_status st = vpds_next_n(s, want, 0, x + done * (size_t)dim, t + done, &got);
        CHECK_MSG(st == VPDS_OK && got == want, "%s: batch of %zu at %zu: %s, %zu events", c->name, want,
                  done, vpds_status_string(st), got);
        if (st != VPDS_OK) break;
        done += got;
        batch++;
    }
    CHECK_MSG(memcmp(x, ref, sizeof(double) * N * (size_t)dim) == 0 && memcmp(t, ref_t, sizeof t) == 0,
              "%s: batched events differ from one call per event", c->name);
    CHECK(vpds_count(s) == N && memcmp(vpds_points(s), ref, sizeof(double) * N * (size_t)dim) == 0);
    /* NULL outputs: the events are still made and stored */
    CHECK(vpds_next_n(s, 5, 0, NULL, NULL, &got) == VPDS_OK && got == 5 && vpds_count(s) == N + 5);
    CHECK(vpds_get_stats(s).t == vpds_scales(s)[N + 4]);
    vpds_destroy(s);
}

/* t_min stops a batch at the last event above it; bad arguments change nothing. */
static void check_ends_and_refusals(void)
{
    config c = {"one radius", 2, 0, VPDS_RULE_SMALLER, 1, 0};
    vpds_desc d = desc_of(&c, NULL);
    double ref[80 * 2], ref_t[80], x[80 * 2], t[80], tau;
    vpds_sampler *s;
    size_t got = 99, k;
    reference(&d, 80, ref, ref_t);
    tau = 0.5 * (ref_t[59] + ref_t[60]); /* 60 events lie above it */
    CHECK(ref_t[59] > tau && ref_t[60] < tau);
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_next_n(s, 80, tau, x, t, &got) == VPDS_STREAM_END && got == 60 && vpds_count(s) == 60);
    CHECK(memcmp(x, ref, sizeof(double) * 120) == 0 && memcmp(t, ref_t, sizeof(double) * 60) == 0);
    CHECK(vpds_next_n(s, 10, tau, x, t, &got) == VPDS_STREAM_END && got == 0 && vpds_count(s) == 60);
    CHECK(vpds_next_n(s, 0, 0, x, t, &got) == VPDS_OK && got == 0 && vpds_count(s) == 60);
    /* refused: count NULL, t_min NaN, no sampler; the stream then goes on unchanged */
    CHECK(vpds_next_n(s, 3, 0, x, t, NULL) == VPDS_ERR_INVALID_ARGUMENT &&
          strstr(vpds_last_error(s), "count") != NULL && vpds_count(s) == 60);
    got = 99;
    CHECK(vpds_next_n(s, 3, NAN, x, t, &got) == VPDS_ERR_INVALID_ARGUMENT && got == 0 &&
          strstr(vpds_last_error(s), "t_min") != NULL && vpds_count(s) == 60);
    got = 99;
    CHECK(vpds_next_n(NULL, 3, 0, x, t, &got) == VPDS_ERR_INVALID_ARGUMENT && got == 0);
    CHECK(vpds_next_n(s, 20, 0, x, t, &got) == VPDS_OK && got == 20);
    CHECK(memcmp(x, ref + 120, sizeof(double) * 40) == 0 && memcmp(t, ref_t + 60, sizeof(double) * 20) == 0);
    vpds_destroy(s);
    /* a paused run: the stream cannot start, nothing changes */
    d.radius = 0.01;
    CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_set_budget(s, 50) == VPDS_OK);
    CHECK(vpds_run(s) == VPDS_PAUSED);
    k = vpds_count(s);
    CHECK(vpds_next_n(s, 3, 0, x, t, &got) == VPDS_ERR_STATE && got == 0 && vpds_count(s) == k &&
          strstr(vpds_last_error(s), "vpds_next_n") != NULL);
    vpds_destroy(s);
}

/* Each allocation of a batched stream fails once in turn: the batch returns the events before
 * the failure, the retry continues, and the whole is the stream without failures. */
static void check_allocation_failures(int quick)
{
    enum { N = 200 };
    config c = {"two radii", 2, 0, VPDS_RULE_SMALLER, 0.5, 0};
    vpds_desc d = desc_of(&c, NULL);
    double ref[N * 2], ref_t[N], x[N * 2], t[N];
    failing_alloc fa;
    vpds_sampler *s;
    size_t k, total, failures = 0, stride;
    reference(&d, N, ref, ref_t);
    d.allocator.alloc = fa_alloc;
    d.allocator.free = fa_free;
    d.allocator.user = &fa;
    memset(&fa, 0, sizeof fa);
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_next_n(s, N, 0, NULL, NULL, &k) == VPDS_OK && k == N);
    vpds_destroy(s);
    total = fa.calls;
    stride = quick ? total / 8 + 1 : 1;
    for (k = 2; k <= total; k += stride) { /* the first allocation is vpds_create's own */
        size_t done = 0, got;
        vpds_status st = VPDS_OK;
        memset(&fa, 0, sizeof fa);
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        fa.fail_at = k;
        while (done < N) {
            st = vpds_next_n(s, N - done, 0, x + 2 * done, t + done, &got);
            done += got;
            CHECK(vpds_count(s) == done);
            if (st == VPDS_ERR_OUT_OF_MEMORY) {
                CHECK(strlen(vpds_last_error(s)) > 0);
                failures++;
                continue;
            }
            if (st != VPDS_OK) break;
        }
        CHECK_MSG(st == VPDS_OK && memcmp(x, ref, sizeof x) == 0 && memcmp(t, ref_t, sizeof t) == 0,
                  "batched stream differs after failing allocation %zu", k);
        vpds_destroy(s);
        CHECK_MSG(fa.live == 0, "leak after failing allocation %zu", k);
    }
    CHECK(failures > 0);
    printf("batched stream allocation failures: %zu allocations, %zu failed once each\n", total, failures);
}

/* The mesh form on an octahedron: batches give the events of one call each. */
static void check_mesh(void)
{
    static const double v[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    static const uint32_t tri[24] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    enum { N = 150 };
    vpds_mesh_desc d = vpds_default_mesh_desc();
    vpds_mesh *a, *b;
    double ref[N * 3], ref_t[N], x[N * 3], t[N];
    size_t i, done = 0, batch = 1, got;
    d.vertices = v;
    d.n_vertices = 6;
    d.triangles = tri;
    d.n_triangles = 8;
    d.radius = 0.2;
    d.seed = 3;
    CHECK(vpds_mesh_create(&d, &a) == VPDS_OK && vpds_mesh_create(&d, &b) == VPDS_OK);
    for (i = 0; i < N; i++) CHECK(vpds_mesh_next(a, 0, ref + 3 * i, ref_t + i) == VPDS_OK);
    while (done < N) {
        size_t want = done + batch > N ? N - done : batch;
        vpds_status st = vpds_mesh_next_n(b, want, 0, x + 3 * done, t + done, &got);
        CHECK(st == VPDS_OK && got == want);
        if (st != VPDS_OK) break;
        done += got;
        batch += 2;
    }
    CHECK(memcmp(x, ref, sizeof x) == 0 && memcmp(t, ref_t, sizeof t) == 0);
    CHECK(memcmp(vpds_mesh_faces(a), vpds_mesh_faces(b), N * sizeof(uint32_t)) == 0);
    CHECK(vpds_mesh_next_n(b, 4, 0, NULL, NULL, &got) == VPDS_OK && got == 4 && vpds_mesh_count(b) == N + 4);
    CHECK(vpds_mesh_next_n(b, 4, 1e9, x, t, &got) == VPDS_STREAM_END && got == 0 && vpds_mesh_count(b) == N + 4);
    CHECK(vpds_mesh_next_n(b, 4, 0, x, t, NULL) == VPDS_ERR_INVALID_ARGUMENT &&
          strstr(vpds_mesh_last_error(b), "count") != NULL && vpds_mesh_count(b) == N + 4);
    CHECK(vpds_mesh_next_n(b, 4, -1, x, t, &got) == VPDS_ERR_INVALID_ARGUMENT && got == 0 &&
          strstr(vpds_mesh_last_error(b), "t_min") != NULL && vpds_mesh_count(b) == N + 4);
    CHECK(vpds_mesh_next_n(NULL, 4, 0, x, t, &got) == VPDS_ERR_INVALID_ARGUMENT && got == 0);
    vpds_mesh_destroy(a);
    vpds_mesh_destroy(b);
}

int main(void)
{
    static const config configs[] = {
        {"one radius", 2, 0, VPDS_RULE_SMALLER, 1, 0},
        {"two radii, periodic", 2, 0, VPDS_RULE_SMALLER, 0.5, 1},
        {"ramp, prior", 2, 1, VPDS_RULE_PRIOR, 1, 0},
        {"ramp, current", 2, 1, VPDS_RULE_CURRENT, 0.7, 0},
        {"ramp, bigger", 2, 1, VPDS_RULE_BIGGER, 1, 0},
        {"ramp, smaller", 2, 1, VPDS_RULE_SMALLER, 1, 0},
        {"3D one radius", 3, 0, VPDS_RULE_SMALLER, 1, 0},
    };
    int quick = getenv("VPDS_TEST_QUICK") != NULL;
    size_t i;
    for (i = 0; i < sizeof configs / sizeof configs[0]; i++) check_batches(&configs[i]);
    check_ends_and_refusals();
    check_allocation_failures(quick);
    check_mesh();
    CHECK_DONE();
}
