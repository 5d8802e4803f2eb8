/* vpds_tiling_run: the same bytes as the tiles run one by one (vpds_tile_create, phase by phase)
 * for 1-4 threads and for executors that finish tasks in reverse and shuffled orders; the union
 * conflict-free and covered by brute force; callbacks not declared thread-safe keep it serial;
 * a caller's allocator behind the library's lock; an allocation failure anywhere fails the run
 * cleanly; the same run as a job in steps (vpds_tiling_job_*) gives the same bytes, and goes on
 * after a failed step to them; every refused argument. Run under ThreadSanitizer by make test. */
#include "check.h"
#include "vpds.h"
#include <math.h>
#include <string.h>

static double ramp(const double *x, void *u) { (void)u; return 0.02 + 0.1 * x[0]; }
static int quick(void) { return getenv("VPDS_TEST_QUICK") != NULL; } /* under valgrind */

/* The tiles one after another through the public per-tile API, in (phase, tile) order. */
static double *serial_union(const vpds_tiling *tg, int dim, size_t *total)
{
    uint64_t count = vpds_tiling_count(tg), i, dep[VPDS_TILING_MAX_DEPS];
    double **xs = (double **)calloc((size_t)count, sizeof *xs), **rs = (double **)calloc((size_t)count, sizeof *rs);
    size_t *ns = (size_t *)calloc((size_t)count, sizeof *ns), at = 0;
    double *all;
    int ph;
    vpds_tile_points pts[VPDS_TILING_MAX_DEPS];
    *total = 0;
    for (ph = 0; ph < 1 << dim; ph++)
        for (i = 0; i < count; i++) {
            vpds_sampler *s = NULL;
            size_t nd = 0, nf = 0, j, n;
            char msg[256];
            if (vpds_tiling_phase(tg, i) != ph) continue;
            CHECK(vpds_tiling_deps(tg, i, dep, VPDS_TILING_MAX_DEPS, &nd) == VPDS_OK);
            for (j = 0; j < nd; j++) {
                pts[j].tile = dep[j];
                pts[j].x = xs[dep[j]];
                pts[j].r = rs[dep[j]];
                pts[j].n = ns[dep[j]];
            }
            CHECK_MSG(vpds_tile_create(tg, i, pts, nd, NULL, &s, &nf, msg, sizeof msg) == VPDS_OK, "%s", msg);
            CHECK(vpds_run(s) == VPDS_OK);
            n = ns[i] = vpds_count(s) - nf;
            xs[i] = (double *)malloc((n + 1) * (size_t)dim * sizeof(double));
            rs[i] = (double *)malloc((n + 1) * sizeof(double));
            memcpy(xs[i], vpds_points(s) + nf * (size_t)dim, n * (size_t)dim * sizeof(double));
            memcpy(rs[i], vpds_radii(s) + nf, n * sizeof(double));
            *total += n;
            vpds_destroy(s);
        }
    all = (double *)malloc((*total + 1) * (size_t)dim * sizeof(double));
    for (ph = 0; ph < 1 << dim; ph++)
        for (i = 0; i < count; i++)
            if (vpds_tiling_phase(tg, i) == ph) {
                memcpy(all + at * (size_t)dim, xs[i], ns[i] * (size_t)dim * sizeof(double));
                at += ns[i];
            }
    for (i = 0; i < count; i++) {
        free(xs[i]);
        free(rs[i]);
    }
    free(xs);
    free(rs);
    free(ns);
    return all;
}

/* Executors of the caller's kind: every task once, in reverse or in a shuffled order. */
static void reverse_executor(vpds_task_fn run, void *batch, uint64_t n, void *user)
{
    uint64_t i;
    (void)user;
    for (i = n; i-- > 0;) run(batch, i);
}
static void shuffled_executor(vpds_task_fn run, void *batch, uint64_t n, void *user)
{
    uint64_t *perm = (uint64_t *)malloc((size_t)(n ? n : 1) * sizeof *perm), i, *state = (uint64_t *)user;
    for (i = 0; i < n; i++) perm[i] = i;
    for (i = n; i > 1; i--) {
        uint64_t j, tmp;
        *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
        j = (*state >> 33) % i;
        tmp = perm[i - 1];
        perm[i - 1] = perm[j];
        perm[j] = tmp;
    }
    for (i = 0; i < n; i++) run(batch, perm[i]);
    free(perm);
}

static void counting_executor(vpds_task_fn run, void *batch, uint64_t n, void *user)
{
    uint64_t i;
    ++*(uint64_t *)user;
    for (i = 0; i < n; i++) run(batch, i);
}

/* An executor that runs only the first task of a batch: the job must refuse, not spin. */
static void lazy_executor(vpds_task_fn run, void *batch, uint64_t n, void *user)
{
    (void)user;
    if (n) run(batch, 0);
}

static vpds_tiled *run_with(const vpds_tiling *tg, int threads, vpds_executor_fn ex, void *user,
                            int safe)
{
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    vpds_tiled *out = NULL;
    char msg[512];
    rd.threads = threads;
    rd.executor = ex;
    rd.executor_user = user;
    rd.callbacks_thread_safe = safe;
    CHECK_MSG(vpds_tiling_run(tg, &rd, &out, msg, sizeof msg) == VPDS_OK, "%s", msg);
    return out;
}

static int same_points(const vpds_tiled *a, const double *x, size_t n, int dim)
{
    return a && vpds_tiled_count(a) == n &&
           memcmp(vpds_tiled_points(a), x, n * (size_t)dim * sizeof(double)) == 0;
}

/* Conflict-free at inhibition * smaller rule and covered at coverage, by brute force. */
static void check_guarantees(const vpds_tiled *a, int dim, double inhibition, const int *periodic,
                             double radius)
{
    size_t n = vpds_tiled_count(a), i, j, p;
    const double *x = vpds_tiled_points(a), *r = vpds_tiled_radii(a);
    uint64_t state = 99;
    int k;
    for (i = 1; i < n; i++)
        for (j = 0; j < i; j++) {
            double d2 = 0, f = r[i] < r[j] ? r[i] : r[j];
            for (k = 0; k < dim; k++) {
                double e = fabs(x[i * dim + k] - x[j * dim + k]);
                if (periodic && periodic[k] && e > 0.5) e = 1 - e;
                d2 += e * e;
            }
            CHECK_MSG(!(d2 < inhibition * inhibition * f * f * (1 - 1e-12)), "samples %zu, %zu conflict", i, j);
        }
    for (p = 0; p < 3000; p++) {
        double y[3], best = INFINITY, ry;
        for (k = 0; k < dim; k++) {
            state = state * 6364136223846793005ULL + 1442695040888963407ULL;
            y[k] = (double)(state >> 11) / 9007199254740992.0;
        }
        ry = radius > 0 ? radius : ramp(y, NULL);
        for (i = 0; i < n; i++) {
            double d2 = 0, f = r[i] < ry ? r[i] : ry;
            for (k = 0; k < dim; k++) {
                double e = fabs(y[k] - x[i * dim + k]);
                if (periodic && periodic[k] && e > 0.5) e = 1 - e;
                d2 += e * e;
            }
            if (sqrt(d2) - f < best) best = sqrt(d2) - f;
        }
        CHECK_MSG(best <= 1e-9, "probe %zu uncovered by %g", p, best);
    }
}

/* The tiling as a job in steps of at most max_tiles tiles on `threads` threads: the progress
 * grows by at most max_tiles a step, the result exists only at the end, and it is the bytes of
 * the serial union. */
static void check_job(const vpds_tiling *tg, int threads, uint64_t max_tiles, const double *ref,
                      size_t n, int dim)
{
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    vpds_tiling_job *job = NULL;
    vpds_tiled *a = NULL;
    uint64_t count = vpds_tiling_count(tg), before = 0, steps = 0;
    vpds_status st;
    char msg[512];
    rd.threads = threads;
    rd.callbacks_thread_safe = 1;
    CHECK_MSG(vpds_tiling_job_create(tg, &rd, &job, msg, sizeof msg) == VPDS_OK, "%s", msg);
    if (!job) return;
    CHECK(vpds_tiling_job_result(job, &a, msg, sizeof msg) == VPDS_ERR_STATE && !a);
    CHECK(strstr(msg, "0 of ") != NULL);
    do {
        uint64_t now;
        st = vpds_tiling_job_step(job, max_tiles, msg, sizeof msg);
        now = vpds_tiling_job_tiles_done(job);
        CHECK_MSG(now > before && now - before <= max_tiles, "a step of %llu did %llu tiles",
                  (unsigned long long)max_tiles, (unsigned long long)(now - before));
        before = now;
        steps++;
    } while (st == VPDS_PAUSED && steps <= count);
    CHECK_MSG(st == VPDS_OK && before == count, "%d after %llu steps: %s", (int)st,
              (unsigned long long)steps, msg);
    CHECK(steps >= (count + max_tiles - 1) / max_tiles);
    CHECK(vpds_tiling_job_step(job, max_tiles, msg, sizeof msg) == VPDS_OK); /* nothing left */
    CHECK(vpds_tiling_job_result(job, &a, msg, sizeof msg) == VPDS_OK);
    CHECK_MSG(same_points(a, ref, n, dim), "%dD job, steps of %llu tiles on %d threads: not the serial bytes",
              dim, (unsigned long long)max_tiles, threads);
    vpds_tiled_destroy(a);
    vpds_tiling_job_destroy(job);
}

/* One tiling: every way of running it gives the serial union's bytes. */
static void check_tiling(int dim, uint64_t tiles_per_axis, double inhibition, int callback,
                         const int *periodic)
{
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    uint64_t tiles[3] = {tiles_per_axis, tiles_per_axis, tiles_per_axis}, state = 7;
    vpds_tiling *tg = NULL;
    vpds_tiled *a;
    double *ref;
    size_t n;
    int threads;
    d.dim = dim;
    d.seed = 11;
    d.inhibition = inhibition;
    d.periodic = periodic;
    if (callback) {
        d.sizing = ramp;
        d.lipschitz = 0.1;
        d.radius_max = 0.12;
    } else {
        d.radius = dim == 2 ? 0.03 : 0.1;
    }
    td.sampler = &d;
    td.tiles = tiles;
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    if (!tg) return;
    ref = serial_union(tg, dim, &n);
    CHECK(n > 50);
    for (threads = 0; threads <= 4; threads += quick() ? 2 : 1) {
        a = run_with(tg, threads, NULL, NULL, 1);
        CHECK_MSG(same_points(a, ref, n, dim), "%dD, %d threads: not the serial bytes", dim, threads);
        CHECK(vpds_tiled_threads(a) == (threads > 1 ? threads : 1));
        if (threads == 2) check_guarantees(a, dim, inhibition, periodic, callback ? 0 : d.radius);
        vpds_tiled_destroy(a);
    }
    check_job(tg, 1, 1, ref, n, dim);
    check_job(tg, 2, 3, ref, n, dim);
    check_job(tg, 3, vpds_tiling_count(tg) - 1, ref, n, dim);
    a = run_with(tg, 0, reverse_executor, NULL, 1);
    CHECK(same_points(a, ref, n, dim) && vpds_tiled_threads(a) == 0);
    vpds_tiled_destroy(a);
    a = run_with(tg, 0, shuffled_executor, &state, 1);
    CHECK(same_points(a, ref, n, dim));
    vpds_tiled_destroy(a);
    /* a callback not declared thread-safe: serial, the same bytes, and the executor unused */
    a = run_with(tg, 4, NULL, NULL, 0);
    CHECK(same_points(a, ref, n, dim) && vpds_tiled_threads(a) == (callback ? 1 : 4));
    vpds_tiled_destroy(a);
    {
        uint64_t batches = 0;
        a = run_with(tg, 0, counting_executor, &batches, 0);
        CHECK(same_points(a, ref, n, dim) && vpds_tiled_threads(a) == (callback ? 1 : 0));
        CHECK_MSG(callback ? batches == 0 : batches > 0, "%llu batches", (unsigned long long)batches);
        vpds_tiled_destroy(a);
    }
    free(ref);
    vpds_tiling_destroy(tg);
}

/* A caller's allocator that is not thread-safe (the library locks it), failing at call fail_at. */
typedef struct {
    size_t live, calls, fail_at;
} counting;
static void *c_alloc(size_t size, void *user)
{
    counting *c = (counting *)user;
    if (++c->calls == c->fail_at) return NULL;
    c->live += size;
    return malloc(size);
}
static void c_free(void *p, size_t size, void *user)
{
    counting *c = (counting *)user;
    c->live -= size;
    free(p);
}

static void check_allocator(void)
{
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    uint64_t tiles[2] = {3, 3};
    counting c = {0, 0, 0};
    vpds_tiling *tg = NULL;
    vpds_tiled *a = NULL, *b = NULL;
    size_t held, calls, k, failures = 0;
    vpds_status st;
    char msg[512];
    d.radius = 0.05;
    d.allocator.alloc = c_alloc;
    d.allocator.free = c_free;
    d.allocator.user = &c;
    td.sampler = &d;
    td.tiles = tiles;
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    held = c.live;
    rd.threads = 2;
    CHECK(vpds_tiling_run(tg, &rd, &a, msg, sizeof msg) == VPDS_OK);
    calls = c.calls;
    vpds_tiled_destroy(a);
    CHECK_MSG(c.live == held, "%zu bytes left after destroy", c.live - held);
    rd.threads = 1;
    CHECK(vpds_tiling_run(tg, &rd, &a, msg, sizeof msg) == VPDS_OK);
    /* every allocation failing in turn (a sample of them): a clean failure, nothing left */
    for (k = 1; k < calls; k += 1 + calls / (quick() ? 20 : 60)) {
        c.fail_at = c.calls + k;
        rd.threads = 2;
        b = NULL;
        st = vpds_tiling_run(tg, &rd, &b, msg, sizeof msg);
        if (st == VPDS_ERR_OUT_OF_MEMORY) {
            failures++;
            CHECK(b == NULL && msg[0] != 0);
        } else {
            CHECK_MSG(st == VPDS_OK && b && vpds_tiled_count(b) == vpds_tiled_count(a) &&
                      memcmp(vpds_tiled_points(b), vpds_tiled_points(a),
                             vpds_tiled_count(a) * 2 * sizeof(double)) == 0,
                      "k = %zu: %d %s", k, (int)st, msg);
            vpds_tiled_destroy(b);
        }
        c.fail_at = 0;
    }
    CHECK_MSG(failures > (quick() ? 5u : 10u), "only %zu of the sampled allocations failed the run", failures);
    /* a job whose step fails goes on where it stopped: the next steps give the same bytes; a
     * job destroyed half way leaves nothing */
    for (k = 1, failures = 0; k < calls; k += 1 + calls / (quick() ? 10 : 30)) {
        vpds_tiling_job *job = NULL;
        int steps = 0, failed = 0;
        rd.threads = 2;
        if (vpds_tiling_job_create(tg, &rd, &job, msg, sizeof msg) != VPDS_OK) continue;
        c.fail_at = c.calls + k;
        while ((st = vpds_tiling_job_step(job, 2, msg, sizeof msg)) != VPDS_OK && steps++ < 100) {
            if (st == VPDS_PAUSED) continue;
            CHECK_MSG(st == VPDS_ERR_OUT_OF_MEMORY && strstr(msg, "tile ") == msg, "%d %s", (int)st, msg);
            failed = 1;
            c.fail_at = 0;
        }
        failures += (size_t)failed;
        c.fail_at = 0;
        b = NULL;
        CHECK(st == VPDS_OK && vpds_tiling_job_result(job, &b, msg, sizeof msg) == VPDS_OK);
        CHECK_MSG(b && vpds_tiled_count(b) == vpds_tiled_count(a) &&
                      memcmp(vpds_tiled_points(b), vpds_tiled_points(a),
                             vpds_tiled_count(a) * 2 * sizeof(double)) == 0,
                  "k = %zu: a job resumed after a failed step gave other points", k);
        vpds_tiled_destroy(b);
        vpds_tiling_job_destroy(job);
    }
    CHECK_MSG(failures > 3, "only %zu jobs saw a failed step", failures);
    {
        vpds_tiling_job *job = NULL;
        CHECK(vpds_tiling_job_create(tg, &rd, &job, msg, sizeof msg) == VPDS_OK);
        CHECK(vpds_tiling_job_step(job, 4, msg, sizeof msg) == VPDS_PAUSED);
        vpds_tiling_job_destroy(job); /* a cancel */
    }
    vpds_tiled_destroy(a);
    CHECK_MSG(c.live == held, "%zu bytes left after the failures", c.live - held);
    vpds_tiling_destroy(tg);
    CHECK(c.live == 0);
}

static void check_refusals(void)
{
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    uint64_t tiles[2] = {2, 2};
    vpds_tiling *tg = NULL;
    vpds_tiled *a = NULL;
    char msg[512];
    td.sampler = &d;
    td.tiles = tiles;
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    CHECK(vpds_tiling_run(tg, &rd, NULL, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_tiling_run(NULL, &rd, &a, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && !a);
    rd.threads = -1;
    CHECK(vpds_tiling_run(tg, &rd, &a, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(msg, "threads = -1") != NULL);
    rd.threads = 100000;
    CHECK(vpds_tiling_run(tg, &rd, &a, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    rd = vpds_default_tiling_run_desc();
    rd.cookie = 0;
    CHECK(vpds_tiling_run(tg, &rd, &a, msg, sizeof msg) == VPDS_ERR_BAD_DESCRIPTOR);
    rd = vpds_default_tiling_run_desc();
    rd.struct_size += 8;
    CHECK(vpds_tiling_run(tg, &rd, &a, msg, sizeof msg) == VPDS_ERR_BAD_DESCRIPTOR);
    /* NULL desc: the defaults (serial) */
    CHECK(vpds_tiling_run(tg, NULL, &a, msg, sizeof msg) == VPDS_OK && vpds_tiled_count(a) > 0);
    CHECK(vpds_tiled_dim(a) == 2 && vpds_tiled_tiles(a)[0] < 4 && vpds_tiled_radii(a)[0] == d.radius);
    vpds_tiled_destroy(a);
    vpds_tiled_destroy(NULL);
    CHECK(vpds_tiled_count(NULL) == 0 && vpds_tiled_points(NULL) == NULL && vpds_tiled_threads(NULL) == 0);
    {
        vpds_tiling_job *job = NULL;
        CHECK(vpds_tiling_job_create(tg, NULL, NULL, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
        CHECK(vpds_tiling_job_create(NULL, NULL, &job, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && !job);
        rd = vpds_default_tiling_run_desc();
        rd.threads = -2;
        CHECK(vpds_tiling_job_create(tg, &rd, &job, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && !job);
        CHECK(strstr(msg, "threads = -2") != NULL);
        CHECK(vpds_tiling_job_step(NULL, 0, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
        CHECK(strstr(msg, "job") != NULL);
        CHECK(vpds_tiling_job_result(NULL, &a, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && !a);
        CHECK(vpds_tiling_job_tiles_done(NULL) == 0);
        vpds_tiling_job_destroy(NULL);
        CHECK(vpds_tiling_job_create(tg, NULL, &job, msg, sizeof msg) == VPDS_OK);
        CHECK(vpds_tiling_job_result(job, NULL, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
        CHECK(vpds_tiling_job_step(job, 0, msg, sizeof msg) == VPDS_OK && vpds_tiling_job_tiles_done(job) == 4);
        vpds_tiling_job_destroy(job);
    }
    {
        /* an executor that skips tasks (4 tiles a phase): refused, naming the task, the tile it
         * ran kept */
        uint64_t t4[2] = {4, 4};
        vpds_tiling *tg4 = NULL;
        vpds_tiling_job *job = NULL;
        td.tiles = t4;
        CHECK(vpds_tiling_create(&td, &tg4) == VPDS_OK);
        rd = vpds_default_tiling_run_desc();
        rd.executor = lazy_executor;
        CHECK(vpds_tiling_job_create(tg4, &rd, &job, msg, sizeof msg) == VPDS_OK);
        CHECK(vpds_tiling_job_step(job, 0, msg, sizeof msg) == VPDS_ERR_STATE);
        CHECK_MSG(strstr(msg, "executor returned without running task 1 of 4") != NULL, "%s", msg);
        CHECK(vpds_tiling_job_tiles_done(job) == 1);
        vpds_tiling_job_destroy(job);
        CHECK(vpds_tiling_run(tg4, &rd, &a, msg, sizeof msg) == VPDS_ERR_STATE && !a);
        vpds_tiling_destroy(tg4);
        td.tiles = tiles;
    }
    vpds_tiling_destroy(tg);
    /* windows per tile come from the caller */
    d.radius_max = 0.05;
    d.lipschitz = 0.1;
    td.sizing_per_tile = 1;
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    CHECK(vpds_tiling_run(tg, NULL, &a, msg, sizeof msg) == VPDS_ERR_UNSUPPORTED);
    CHECK(strstr(msg, "sizing_per_tile") != NULL);
    vpds_tiling_destroy(tg);
}

int main(void)
{
    static const int periodic3[3] = {0, 1, 1};
    check_tiling(2, 4, 1.0, 0, NULL);
    check_tiling(2, 3, 1.0, 1, NULL);
    check_tiling(2, 4, 0.6, 1, NULL);
    if (!quick()) check_tiling(3, 2, 1.0, 0, periodic3);
    check_allocator();
    check_refusals();
    CHECK_DONE();
}
