/* Callbacks that fail (a sizing_batch returning non-zero, a domain returning NaN), as a binding
 * does when the code behind them raises (Ctrl-C in Python): the call stops with the error, the
 * sampler is as a pause would leave it (the samples are a prefix of an uninterrupted run's, with
 * the same radii and scales), and calling again gives byte for byte the points of a run that
 * never failed. Failures are injected at every k-th call of a callback, so that one run fails
 * in many places: Algorithm 1's darts, sweep and two-radii filter, the estimate of r_max,
 * refinement, the stream's search, splits and events (and its two-radii draw), weighted darts. */
#include "check.h"
#include "vpds.h"
#include "sampler.h"
#include <math.h>
#include <stdint.h>
#include <string.h>

static int quick; /* VPDS_TEST_QUICK (valgrind): fewer periods */

/* One counter for both callbacks: the call numbered `next` fails. After each failure the driver
 * sets the next one `gap` calls later: `every` after progress, twice the last gap when the
 * retry failed where the previous attempt did (a sweep's cell or a stream's search may need
 * thousands of calls, and a retry must be able to finish them). every 0: nothing fails. */
typedef struct {
    long calls, next, every, gap, failures;
} flaky_t;

static int fail_now(flaky_t *f)
{
    f->calls++;
    if (f->every && f->calls == f->next) {
        f->failures++;
        return 1;
    }
    return 0;
}

static int ramp_batch(const double *x, size_t n, double *r, void *user)
{
    size_t i;
    if (fail_now((flaky_t *)user)) {
        for (i = 0; i < n; i++) r[i] = 1234.5; /* garbage the library must not use */
        return 1;
    }
    for (i = 0; i < n; i++) r[i] = 0.015 + 0.05 * x[2 * i];
    return 0;
}

static double disk_sdf(const double *x, void *user)
{
    if (fail_now((flaky_t *)user)) return NAN;
    return hypot(x[0] - 0.5, x[1] - 0.5) - 0.42;
}

typedef struct {
    const char *name;
    int sizing, domain;  /* which callbacks are set (and fail) */
    double inhibition;
    int weighted;
    uint64_t budget;
    int prerun;          /* first run to maximal, without failures */
    double refine_to;    /* > 0: then refine to this t */
    int stream;          /* > 0: that many vpds_next calls instead of a run */
} scenario;

typedef struct {
    size_t n;
    double *x, *r, *t;
} snapshot;

static void take(vpds_sampler *s, snapshot *o)
{
    size_t n = vpds_count(s);
    o->n = n;
    o->x = (double *)malloc((n ? n : 1) * 2 * sizeof(double));
    o->r = (double *)malloc((n ? n : 1) * sizeof(double));
    o->t = (double *)malloc((n ? n : 1) * sizeof(double));
    if (n) {
        memcpy(o->x, vpds_points(s), n * 2 * sizeof(double));
        memcpy(o->r, vpds_radii(s), n * sizeof(double));
        memcpy(o->t, vpds_scales(s), n * sizeof(double));
    }
}

static void drop(snapshot *o)
{
    free(o->x);
    free(o->r);
    free(o->t);
}

/* The sampler's samples are the first vpds_count of ref's, bit for bit. */
static int is_prefix(vpds_sampler *s, const snapshot *ref)
{
    size_t n = vpds_count(s);
    return n <= ref->n && (n == 0 || (memcmp(vpds_points(s), ref->x, n * 2 * sizeof(double)) == 0 &&
                                      memcmp(vpds_radii(s), ref->r, n * sizeof(double)) == 0 &&
                                      memcmp(vpds_scales(s), ref->t, n * sizeof(double)) == 0));
}

static vpds_sampler *make(const scenario *c, flaky_t *f)
{
    static const double lo[2] = {0, 0}, hi[2] = {1, 1};
    vpds_desc d = vpds_default_desc();
    vpds_sampler *s = NULL;
    d.dim = 2;
    d.lo = lo;
    d.hi = hi;
    d.radius = 0.03;
    d.seed = 11;
    d.inhibition = c->inhibition;
    if (c->sizing) {
        d.sizing_batch = ramp_batch;
        d.sizing_user = f;
        d.lipschitz = 0.05;
        if (c->weighted) d.radius_min = 0.015;
    }
    d.weighted = c->weighted;
    if (c->domain) {
        d.domain = disk_sdf;
        d.domain_user = f;
    }
    d.budget = c->budget;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    return s;
}

/* What a retry must get past: changes when a failed call made progress before failing. */
typedef struct {
    size_t n, heap;
    uint64_t darts, pos, vpos, cells;
    int phase;
} progress_t;

static progress_t progress_of(const vpds_sampler *s)
{
    progress_t p;
    memset(&p, 0, sizeof p);
    p.n = s->store.n;
    p.heap = s->stream.regions.count;
    p.darts = s->stats.darts;
    p.pos = s->mps.run.pos;
    p.vpos = s->mps.run.vpos;
    p.cells = s->mps.run.cur.count + s->mps.run.next.count;
    p.phase = (int)s->mps.run.phase;
    return p;
}

static int same_progress(const progress_t *a, const progress_t *b)
{
    return a->n == b->n && a->heap == b->heap && a->darts == b->darts && a->pos == b->pos &&
           a->vpos == b->vpos && a->cells == b->cells && a->phase == b->phase;
}

/* After an error: the sampler is a prefix of the reference, and the next failure is set. */
static void after_error(const scenario *c, long every, vpds_sampler *s, vpds_status st,
                        const snapshot *ref, flaky_t *f, progress_t *last)
{
    progress_t now = progress_of(s);
    CHECK_MSG(st == VPDS_ERR_SIZING || st == VPDS_ERR_DOMAIN, "%s, every %ld: status %d (%s)",
              c->name, every, st, vpds_last_error(s));
    CHECK_MSG(strstr(vpds_last_error(s), st == VPDS_ERR_SIZING ? "sizing_batch returned an error"
                                                                : "domain returned NaN"),
              "%s: %s", c->name, vpds_last_error(s));
    CHECK_MSG(!ref || is_prefix(s, ref), "%s, every %ld: after failure %ld the samples are not "
              "a prefix of the uninterrupted run's", c->name, every, f->failures);
    f->gap = f->failures > 1 && same_progress(&now, last) ? 2 * f->gap : every;
    f->next = f->calls + f->gap;
    *last = now;
}

/* One run of the scenario, every error retried (as the binding's next call does) until the
 * run completes. every 0: nothing fails, and the result is the reference. */
static long drive(const scenario *c, long every, const snapshot *ref, snapshot *out)
{
    flaky_t f = {0, 0, 0, 0, 0};
    vpds_sampler *s = make(c, &f);
    progress_t last;
    vpds_status st;
    long errors = 0;
    int mid = 0;
    memset(&last, 0, sizeof last);
    if (c->prerun) { /* the run before a refinement or a stream does not fail */
        while ((st = vpds_run(s)) == VPDS_PAUSED) {}
        CHECK(st == VPDS_OK);
    }
    f.every = f.gap = every;
    f.next = f.calls + every;
    if (c->stream) {
        int i = 0;
        while (i < c->stream && errors < 100000) {
            double x[2], t;
            size_t n = vpds_count(s);
            st = vpds_next(s, 0.0, x, &t);
            if (st < 0) {
                errors++;
                CHECK_MSG(vpds_count(s) == n, "%s, every %ld: a failed vpds_next changed the count",
                          c->name, every);
                after_error(c, every, s, st, ref, &f, &last);
                if (st != VPDS_ERR_SIZING && st != VPDS_ERR_DOMAIN) break;
                continue;
            }
            CHECK(st == VPDS_OK && vpds_count(s) == n + 1);
            CHECK_MSG(!ref || is_prefix(s, ref), "%s, every %ld: sample %zu differs", c->name, every, n);
            i++;
        }
    } else {
        for (;;) {
            st = c->refine_to > 0 && !mid ? vpds_refine(s, c->refine_to) : vpds_run(s);
            if (st == VPDS_OK) break;
            if (st == VPDS_PAUSED) { /* a paused refinement goes on through vpds_run */
                mid = 1;
                continue;
            }
            errors++;
            after_error(c, every, s, st, ref, &f, &last);
            if ((st != VPDS_ERR_SIZING && st != VPDS_ERR_DOMAIN) || errors >= 100000) break;
            mid = 0; /* the binding's retry is a new call of the same kind: refine(t) again */
        }
    }
    CHECK_MSG(errors == f.failures, "%s, every %ld: %ld errors for %ld failed calls", c->name,
              every, errors, f.failures);
    take(s, out);
    vpds_destroy(s);
    return errors;
}

int main(void)
{
    static const scenario cases[] = {
        {"run, sizing", 1, 0, 1.0, 0, 0, 0, 0, 0},
        {"run, sizing, budget", 1, 0, 1.0, 0, 97, 0, 0, 0},
        {"run, domain", 0, 1, 1.0, 0, 0, 0, 0, 0},
        {"run, sizing and domain", 1, 1, 1.0, 0, 0, 0, 0, 0},
        {"run, weighted", 1, 0, 1.0, 1, 0, 0, 0, 0},
        {"run, two radii", 1, 1, 0.5, 0, 0, 0, 0, 0},
        {"refine, sizing and domain", 1, 1, 1.0, 0, 0, 1, 0.6, 0},
        {"refine, two radii, budget", 1, 1, 0.5, 0, 61, 1, 0.7, 0},
        {"stream, sizing", 1, 0, 1.0, 0, 0, 0, 0, 120},
        {"stream, domain", 0, 1, 1.0, 0, 0, 0, 0, 120},
        {"stream, two radii", 1, 1, 0.5, 0, 0, 0, 0, 120},
        {"stream after a run, sizing and domain", 1, 1, 1.0, 0, 0, 1, 0, 60},
    };
    static const long periods[] = {2, 3, 7, 31, 257, 4099};
    size_t i, j, n_periods = sizeof periods / sizeof periods[0];
    quick = getenv("VPDS_TEST_QUICK") != NULL;
    if (quick) n_periods = 2; /* a failure every 31 and 257 calls */
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const scenario *c = &cases[i];
        snapshot ref, got;
        long total = 0;
        CHECK(drive(c, 0, NULL, &ref) == 0);
        CHECK_MSG(ref.n > (c->stream ? (size_t)c->stream - 1 : 50u), "%s: %zu samples", c->name, ref.n);
        for (j = 0; j < n_periods; j++) {
            long every = periods[quick ? j + 3 : j];
            total += drive(c, every, &ref, &got);
            CHECK_MSG(got.n == ref.n && memcmp(got.x, ref.x, ref.n * 2 * sizeof(double)) == 0 &&
                      memcmp(got.r, ref.r, ref.n * sizeof(double)) == 0 &&
                      memcmp(got.t, ref.t, ref.n * sizeof(double)) == 0,
                      "%s, a failure every %ld calls: %zu samples, not the %zu of the uninterrupted run",
                      c->name, every, got.n, ref.n);
            drop(&got);
        }
        CHECK_MSG(total > 0, "%s: no callback failed", c->name);
        drop(&ref);
    }
    CHECK_DONE();
}
