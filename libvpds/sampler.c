/* Public entry points: lifetime, fixed points, runs, the stream, results. Every call checks its
 * arguments and leaves the sampler consistent on error. */
#include "sampler.h"
#include "estimate.h"
#include "rules.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

int vpdsi_sampler_live(const vpds_sampler *s) { return s && s->magic == VPDSI_SAMPLER_MAGIC; }

static vpdsi_ctx context(vpds_sampler *s)
{
    vpdsi_ctx c;
    c.pb = &s->pb;
    c.st = &s->store;
    c.dom = &s->domain;
    c.rng = &s->rng;
    c.stats = &s->stats;
    c.mem = &s->mem;
    return c;
}

static void problem_from_desc(vpdsi_problem *pb, const vpds_desc *d)
{
    int k;
    memset(pb, 0, sizeof *pb);
    pb->dim = d->dim;
    for (k = 0; k < d->dim; k++) {
        pb->lo[k] = d->lo ? d->lo[k] : 0.0;
        pb->hi[k] = d->hi ? d->hi[k] : 1.0;
        pb->period[k] = d->periodic && d->periodic[k] ? pb->hi[k] - pb->lo[k] : 0.0;
        if (pb->period[k] > 0) pb->any_periodic = 1;
    }
    pb->rule = vpdsi_rule_resolve(d->rule);
    pb->inhibition = d->inhibition;
    pb->coverage = d->coverage;
    pb->two_radii = d->inhibition < d->coverage;
    pb->algorithm = d->algorithm_version ? d->algorithm_version : VPDS_ALGORITHM_VERSION;
    pb->weighted = d->weighted;
}

vpds_status vpds_create(const vpds_desc *d, vpds_sampler **out)
{
    vpdsi_mem m;
    vpds_sampler *s;
    vpds_status st;
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if ((st = vpds_validate(d, NULL, 0)) != VPDS_OK) return st;
    vpdsi_mem_init(&m, &d->allocator);
    s = (vpds_sampler *)vpdsi_mem_alloc(&m, sizeof *s);
    if (!s) return VPDS_ERR_OUT_OF_MEMORY;
    memset(s, 0, sizeof *s);
    s->mem = m;
    problem_from_desc(&s->pb, d);
    vpdsi_store_init(&s->store, &s->mem, d->dim, s->pb.lo, s->pb.hi, s->pb.period);
    if ((st = vpdsi_sizing_from_desc(&s->store.sizing, d)) != VPDS_OK) {
        vpdsi_mem_free(&m, s, sizeof *s);
        return st;
    }
    s->domain.fn = d->domain;
    s->domain.user = d->domain_user;
    s->budget = d->budget;
    s->progress = d->progress;
    s->progress_user = d->progress_user;
    vpdsi_rng_seed(&s->rng, d->seed);
    vpdsi_mps_init(&s->mps, d->dim, s->pb.period);
    vpdsi_stream_init(&s->stream);
    s->stats.t = 1.0;
    s->magic = VPDSI_SAMPLER_MAGIC;
    *out = s;
    return VPDS_OK;
}

void vpds_destroy(vpds_sampler *s)
{
    vpdsi_mem m;
    if (!vpdsi_sampler_live(s)) return;
    vpdsi_mps_release(&s->mps, &s->store);
    vpdsi_stream_release(&s->stream, &s->mem);
    vpdsi_store_release(&s->store);
    m = s->mem;
    s->magic = 0;
    vpdsi_mem_free(&m, s, sizeof *s);
}

const char *vpds_last_error(const vpds_sampler *s)
{
    if (!s) return "sampler is NULL";
    if (!vpdsi_sampler_live(s)) return "not a live vpds_sampler (destroyed or never created)";
    return s->store.err;
}

static vpds_status ensure_rmax(vpds_sampler *s)
{
    return vpdsi_sizing_estimate_rmax(&s->store.sizing, &s->mem, s->pb.lo, s->pb.hi, s->pb.algorithm >= 7,
                                      s->store.err, sizeof s->store.err);
}

/* Before a run at scale t, one estimate (vpds_estimate) serves two ends: a run whose estimate
 * exceeds the memory limit is refused; and a first run with a constant radius and no domain,
 * whose count it gives to about 1% (reading neither the sizing nor a domain), has its sample
 * arrays reserved at once instead of growing by half again (88 -> 64.5 B/sample at 10^6 samples
 * in 2D, with the 32-bit cells; memory only: the same points). */
static vpds_status plan_run(vpds_sampler *s, double t)
{
    vpds_run_estimate e;
    vpds_status st;
    int expect = s->store.n == 0 && s->store.sizing.kind == VPDSI_SIZING_CONSTANT && !s->domain.fn;
    s->store.expect = 0;
    if (s->mem.limit == 0 && !expect) return VPDS_OK;
    st = vpdsi_estimate_run(&s->pb, &s->store, &s->domain, t, sizeof *s, &e);
    if (st != VPDS_OK) return s->mem.limit ? st : VPDS_OK;
    if (s->mem.limit && e.bytes > (double)s->mem.limit) {
        vpdsi_store_error(&s->store, "a maximal run at scale t = %g needs about %.3g bytes (%.3g samples,"
                          " %.3g cells; vpds_estimate), above the memory limit of %zu bytes "
                          "(vpds_set_memory_limit)", t, e.bytes, e.samples, e.cells, s->mem.limit);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    if (expect && 1.02 * e.samples + 64 <= (double)VPDSI_STORE_EXPECT_MAX)
        s->store.expect = (size_t)(1.02 * e.samples + 64);
    return VPDS_OK;
}

/* An allocation refused for the limit says so, after what the failing site said. */
vpds_status vpdsi_sampler_note_limit(vpds_sampler *s, vpds_status st)
{
    size_t len;
    if (st != VPDS_ERR_OUT_OF_MEMORY || !s->mem.limit_hit) return st;
    len = strlen(s->store.err);
    snprintf(s->store.err + len, sizeof s->store.err - len, "%sthe memory limit of %zu bytes "
             "(vpds_set_memory_limit) was reached", len ? ": " : "", s->mem.limit);
    return st;
}

vpds_status vpdsi_sampler_run(vpds_sampler *s)
{
    vpdsi_ctx c = context(s);
    vpdsi_work w;
    vpds_status st;
    s->store.err[0] = 0;
    s->mem.limit_hit = 0;
    if ((st = ensure_rmax(s)) != VPDS_OK) return vpdsi_sampler_note_limit(s, st);
    if (s->mps.run.phase == VPDSI_IDLE && (st = plan_run(s, s->mps.run.t)) != VPDS_OK) return st;
    w.budget = s->budget;
    w.progress = s->progress;
    w.user = s->progress_user;
    w.keep_tree = s->stream.active;
    return vpdsi_sampler_note_limit(s, vpdsi_mps_run(&s->mps, &c, &w));
}

void vpdsi_sampler_start_at(vpds_sampler *s, double t)
{
    vpdsi_mps_reset(&s->mps, t);
    s->stats.t = t;
}

void vpdsi_sampler_share_bounds(vpds_sampler *s, double lipschitz, double rmin, double rmax)
{
    if (s->store.sizing.kind == VPDSI_SIZING_CONSTANT) return;
    s->store.sizing.lipschitz = lipschitz;
    s->store.sizing.rmin = rmin;
    s->store.sizing.rmax = rmax;
}

vpds_status vpds_run(vpds_sampler *s)
{
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    return vpdsi_sampler_run(s);
}

/* The arguments every stream call shares (who calls says in `who`), and the state it starts
 * from: empty, or a completed run. */
static vpds_status stream_may_start(vpds_sampler *s, const char *who, double t_min)
{
    const vpdsi_run *run = &s->mps.run;
    if (isnan(t_min)) {
        vpdsi_store_error(&s->store, "%s: t_min is NaN", who);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (run->phase != VPDSI_DONE && (run->phase != VPDSI_IDLE || vpdsi_store_has_samples(&s->store))) {
        vpdsi_store_error(&s->store, "%s: the run at scale %g is not finished; a stream starts "
                          "from an empty sampler or a maximal one (call vpds_run until VPDS_OK)",
                          who, run->t);
        return VPDS_ERR_STATE;
    }
    return VPDS_OK;
}

/* One event of the stream (after stream_may_start): the sample into x_out, its t into *t_out. */
static vpds_status stream_event(vpds_sampler *s, double t_min, double *x_out, double *t_out)
{
    vpdsi_run *run = &s->mps.run;
    vpdsi_ctx c;
    vpds_status st;
    double t;
    s->mem.limit_hit = 0;
    if ((st = ensure_rmax(s)) != VPDS_OK) return vpdsi_sampler_note_limit(s, st);
    c = context(s);
    st = vpdsi_stream_next(&s->stream, &c, t_min, run->phase == VPDSI_DONE ? run->t : INFINITY,
                           x_out, &t);
    if (st != VPDS_OK) return vpdsi_sampler_note_limit(s, st);
    *t_out = t;
    /* the set is now maximal at t (Section 4.2): a later vpds_refine goes below it */
    vpdsi_mps_release_cells(&s->mps, &s->store);
    run->phase = VPDSI_DONE;
    run->t = t;
    s->stats.t = t;
    return VPDS_OK;
}

vpds_status vpds_next(vpds_sampler *s, double t_min, double *x_out, double *t_out)
{
    vpds_status st;
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->store.err[0] = 0;
    if (!x_out || !t_out) {
        vpdsi_store_error(&s->store, "vpds_next: x_out and t_out must not be NULL");
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if ((st = stream_may_start(s, "vpds_next", t_min)) != VPDS_OK) return st;
    return stream_event(s, t_min, x_out, t_out);
}

vpds_status vpds_next_n(vpds_sampler *s, size_t n, double t_min, double *x_out, double *t_out,
                        size_t *count)
{
    vpds_status st;
    double x[VPDS_MAX_DIM], t;
    size_t d;
    if (count) *count = 0;
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->store.err[0] = 0;
    if (!count) {
        vpdsi_store_error(&s->store, "vpds_next_n: count must not be NULL (it says how many "
                          "events were written)");
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if ((st = stream_may_start(s, "vpds_next_n", t_min)) != VPDS_OK) return st;
    d = (size_t)s->pb.dim;
    for (; *count < n; (*count)++) {
        if ((st = stream_event(s, t_min, x, &t)) != VPDS_OK) return st;
        if (x_out) memcpy(x_out + *count * d, x, d * sizeof *x);
        if (t_out) t_out[*count] = t;
    }
    return VPDS_OK;
}

vpds_status vpds_add_points(vpds_sampler *s, const double *x, const double *r, size_t n)
{
    size_t i;
    int k, d;
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    d = s->pb.dim;
    s->store.err[0] = 0;
    if (n == 0) return VPDS_OK;
    if (!x) {
        vpdsi_store_error(&s->store, "x is NULL with n = %zu", n);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    for (i = 0; i < n; i++) {
        for (k = 0; k < d; k++)
            if (!(fabs(x[i * (size_t)d + (size_t)k]) <= VPDSI_MAGNITUDE_MAX)) {
                vpdsi_store_error(&s->store, "x[%zu][%d] = %g: fixed points must be finite (within "
                                  "1e150)", i, k, x[i * (size_t)d + (size_t)k]);
                return VPDS_ERR_INVALID_ARGUMENT;
            }
        if (r && !vpdsi_radius_ok(r[i])) {
            vpdsi_store_error(&s->store, "r[%zu] = %g: radii must be finite and > 0 (within "
                              "[1e-100, 1e100])", i, r[i]);
            return VPDS_ERR_INVALID_ARGUMENT;
        }
    }
    s->mem.limit_hit = 0;
    return vpdsi_sampler_note_limit(s, vpdsi_store_add_fixed(&s->store, x, r, n));
}

vpds_status vpds_estimate(vpds_sampler *s, double t, vpds_run_estimate *out)
{
    vpds_status st;
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->store.err[0] = 0;
    if (!out) {
        vpdsi_store_error(&s->store, "vpds_estimate: out is NULL");
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof *out);
    if (t == 0) t = s->mps.run.t;
    if (!(t > 0) || !isfinite(t) || !vpdsi_scale_ok(t * s->pb.coverage)) {
        vpdsi_store_error(&s->store, "vpds_estimate: t = %g must be finite and > 0 (t * coverage "
                          "within [1e-50, 1e50])", t);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    s->mem.limit_hit = 0;
    if ((st = ensure_rmax(s)) != VPDS_OK) return vpdsi_sampler_note_limit(s, st);
    return vpdsi_estimate_run(&s->pb, &s->store, &s->domain, t, sizeof *s, out);
}

vpds_status vpds_set_memory_limit(vpds_sampler *s, size_t bytes)
{
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->mem.limit = bytes;
    return VPDS_OK;
}

vpds_status vpds_set_budget(vpds_sampler *s, uint64_t budget)
{
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->budget = budget;
    return VPDS_OK;
}

size_t vpds_count(const vpds_sampler *s) { return vpdsi_sampler_live(s) ? s->store.n : 0; }
int vpds_dim(const vpds_sampler *s) { return vpdsi_sampler_live(s) ? s->pb.dim : 0; }
const double *vpds_points(const vpds_sampler *s) { return vpdsi_sampler_live(s) ? s->store.x : NULL; }
const double *vpds_radii(const vpds_sampler *s) { return vpdsi_sampler_live(s) ? s->store.r : NULL; }
const double *vpds_scales(const vpds_sampler *s) { return vpdsi_sampler_live(s) ? s->store.t : NULL; }
const uint8_t *vpds_flags(const vpds_sampler *s) { return vpdsi_sampler_live(s) ? s->store.flags : NULL; }

vpds_stats vpds_get_stats(const vpds_sampler *s)
{
    vpds_stats st;
    if (!vpdsi_sampler_live(s)) {
        memset(&st, 0, sizeof st);
        return st;
    }
    st = s->stats;
    st.bytes_held = s->mem.held;
    st.peak_bytes = s->mem.peak;
    st.sizing_calls = s->store.sizing.calls;
    st.domain_calls = s->domain.calls;
    st.t = s->mps.run.t;
    st.maximal = s->mps.run.phase == VPDSI_DONE;
    return st;
}
