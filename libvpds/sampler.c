/* Public entry points: lifetime, fixed points, runs, results. Every call checks its arguments
 * and leaves the sampler consistent on error. */
#include "sampler.h"
#include "rules.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void vpdsi_set_error(vpds_sampler *s, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->err, sizeof s->err, fmt, ap);
    va_end(ap);
}

static int live(const vpds_sampler *s) { return s && s->magic == VPDSI_SAMPLER_MAGIC; }

vpdsi_kd_samples vpdsi_samples_view(const vpds_sampler *s)
{
    vpdsi_kd_samples v;
    v.x = s->x;
    v.r = s->r;
    v.flags = s->flags;
    return v;
}

void vpdsi_wrap_point(const vpds_sampler *s, double *x)
{
    int k;
    for (k = 0; k < s->dim; k++) {
        double P = s->period[k];
        if (P > 0 && (x[k] < s->lo[k] || x[k] >= s->hi[k])) {
            x[k] = s->lo[k] + fmod(x[k] - s->lo[k], P);
            if (x[k] < s->lo[k]) x[k] += P;
            if (x[k] >= s->hi[k]) x[k] = s->lo[k];
        }
    }
}

vpds_status vpdsi_radius_at(vpds_sampler *s, const double *p, double *r)
{
    double q[VPDS_MAX_DIM];
    if (s->sizing.kind == VPDSI_SIZING_CONSTANT) {
        *r = s->sizing.radius;
        return VPDS_OK;
    }
    memcpy(q, p, (size_t)s->dim * sizeof(double));
    vpdsi_wrap_point(s, q);
    return vpdsi_sizing_eval(&s->sizing, q, 1, r, s->err, sizeof s->err);
}

vpds_status vpdsi_reserve_samples(vpds_sampler *s, size_t more)
{
    size_t need = s->n + more, nx;
    if (need < s->n || need > (size_t)INT32_MAX || vpdsi_mul_size(need, (size_t)s->dim, &nx)) {
        vpdsi_set_error(s, "%zu samples would overflow the sample index (at most %d)", need, INT32_MAX);
        return VPDS_ERR_OVERFLOW;
    }
    if (vpdsi_mem_reserve(&s->mem, (void **)&s->x, &s->cap_x, nx, sizeof(double)) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->r, &s->cap_r, need, sizeof(double)) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->t, &s->cap_t, need, sizeof(double)) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->flags, &s->cap_flags, need, 1) ||
        (!s->grid_mode && vpdsi_kd_reserve(&s->tree, &s->mem, need, need - s->tree_n))) {
        vpdsi_set_error(s, "out of memory for %zu samples", need);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

vpds_status vpdsi_sync_tree(vpds_sampler *s)
{
    vpdsi_kd_samples v = vpdsi_samples_view(s);
    if (s->tree_n == s->n) return VPDS_OK;
    if (vpdsi_kd_reserve(&s->tree, &s->mem, s->n, s->n - s->tree_n)) {
        vpdsi_set_error(s, "out of memory indexing %zu samples", s->n);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    while (s->tree_n < s->n) vpdsi_kd_insert(&s->tree, &v, (int32_t)s->tree_n++);
    return VPDS_OK;
}

void vpdsi_append_sample(vpds_sampler *s, const double *x, double r, double t, uint8_t flags)
{
    memcpy(s->x + s->n * (size_t)s->dim, x, (size_t)s->dim * sizeof(double));
    s->r[s->n] = r;
    s->t[s->n] = t;
    s->flags[s->n] = flags;
    s->n++;
    if (s->grid_mode) {
        s->grid.cell[vpdsi_bgrid_locate(&s->grid, x)] = (int32_t)(s->n - 1);
    } else {
        vpdsi_kd_samples v = vpdsi_samples_view(s);
        vpdsi_kd_insert(&s->tree, &v, (int32_t)(s->n - 1));
        s->tree_n = s->n;
    }
}

vpds_status vpds_create(const vpds_desc *d, vpds_sampler **out)
{
    vpdsi_mem m;
    vpds_sampler *s;
    vpds_status st;
    int k;
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if ((st = vpds_validate(d, NULL, 0)) != VPDS_OK) return st;
    vpdsi_mem_init(&m, &d->allocator);
    s = (vpds_sampler *)vpdsi_mem_alloc(&m, sizeof *s);
    if (!s) return VPDS_ERR_OUT_OF_MEMORY;
    memset(s, 0, sizeof *s);
    s->mem = m;
    s->dim = d->dim;
    for (k = 0; k < d->dim; k++) {
        s->lo[k] = d->lo ? d->lo[k] : 0.0;
        s->hi[k] = d->hi ? d->hi[k] : 1.0;
    }
    s->rule = d->rule == VPDS_RULE_DEFAULT ? VPDS_RULE_SMALLER : d->rule;
    s->inhibition = d->inhibition;
    s->coverage = d->coverage;
    s->two_radii = d->inhibition < d->coverage;
    s->algorithm = d->algorithm_version ? d->algorithm_version : VPDS_ALGORITHM_VERSION;
    for (k = 0; k < d->dim; k++) {
        s->period[k] = d->periodic && d->periodic[k] ? s->hi[k] - s->lo[k] : 0.0;
        if (s->period[k] > 0) s->any_periodic = 1;
    }
    s->weighted = d->weighted;
    s->domain = d->domain;
    s->domain_user = d->domain_user;
    s->budget = d->budget;
    s->progress = d->progress;
    s->progress_user = d->progress_user;
    s->sizing.dim = d->dim;
    s->sizing.rmin = d->radius_min;
    s->sizing.rmax = d->radius_max;
    if (d->sizing || d->sizing_batch) {
        s->sizing.kind = VPDSI_SIZING_CALLBACK;
        s->sizing.fn = d->sizing;
        s->sizing.batch = d->sizing_batch;
        s->sizing.user = d->sizing_user;
        s->sizing.lipschitz = d->lipschitz;
    } else if (d->sizing_grid) {
        st = vpdsi_grid_clone(d->sizing_grid, &d->allocator, &s->sizing.grid);
        if (st != VPDS_OK) {
            vpdsi_mem_free(&m, s, sizeof *s);
            return st;
        }
        s->sizing.kind = VPDSI_SIZING_GRID;
        s->sizing.lipschitz = d->lipschitz != VPDS_UNSET ? d->lipschitz : s->sizing.grid->lipschitz;
        s->sizing.rmin = s->sizing.grid->vmin;
        s->sizing.rmax = s->sizing.grid->vmax;
    } else {
        s->sizing.kind = VPDSI_SIZING_CONSTANT;
        s->sizing.radius = d->radius;
        s->sizing.lipschitz = 0;
        s->sizing.rmin = s->sizing.rmax = d->radius;
    }
    vpdsi_rng_seed(&s->rng, d->seed);
    vpdsi_kd_init(&s->tree, d->dim);
    vpdsi_kd_set_period(&s->tree, s->period);
    vpdsi_kd_init(&s->utree, d->dim);
    vpdsi_kd_set_period(&s->utree, s->period);
    vpdsi_stream_init(&s->stream);
    s->magic = VPDSI_SAMPLER_MAGIC;
    vpdsi_mps_reset(s, 1.0);
    *out = s;
    return VPDS_OK;
}

void vpds_destroy(vpds_sampler *s)
{
    vpdsi_mem m;
    if (!live(s)) return;
    vpdsi_mps_release(s);
    vpdsi_bgrid_release(&s->grid, &s->mem);
    vpdsi_kd_release(&s->tree, &s->mem);
    vpdsi_mem_free(&s->mem, s->x, s->cap_x * sizeof(double));
    vpdsi_mem_free(&s->mem, s->r, s->cap_r * sizeof(double));
    vpdsi_mem_free(&s->mem, s->t, s->cap_t * sizeof(double));
    vpdsi_mem_free(&s->mem, s->flags, s->cap_flags);
    vpdsi_mem_free(&s->mem, s->cand, s->cap_cand * sizeof(int32_t));
    vpdsi_mem_free(&s->mem, s->cand2, s->cap_cand2 * sizeof(int32_t));
    vpdsi_mem_free(&s->mem, s->bb_stack, s->cap_bb_stack * sizeof(double));
    vpdsi_mem_free(&s->mem, s->next_u, s->cap_next_u);
    vpdsi_kd_release(&s->utree, &s->mem);
    vpdsi_mem_free(&s->mem, s->ux, s->cap_ux * sizeof(double));
    vpdsi_mem_free(&s->mem, s->ur, s->cap_ur * sizeof(double));
    vpdsi_mem_free(&s->mem, s->uf, s->cap_uf);
    vpdsi_stream_release(&s->stream, &s->mem);
    vpdsi_mem_free(&s->mem, s->buf_x, s->cap_buf_x * sizeof(double));
    vpdsi_mem_free(&s->mem, s->buf_r, s->cap_buf_r * sizeof(double));
    vpdsi_mem_free(&s->mem, s->buf_u, s->cap_buf_u * sizeof(double));
    if (s->sizing.grid) vpds_grid_destroy(s->sizing.grid);
    m = s->mem;
    s->magic = 0;
    vpdsi_mem_free(&m, s, sizeof *s);
}

const char *vpds_last_error(const vpds_sampler *s)
{
    if (!s) return "sampler is NULL";
    if (!live(s)) return "not a live vpds_sampler (destroyed or never created)";
    return s->err;
}

/* Unknown r_max with a callback: it only sizes the base cells of the kd-tree path (never a
 * correctness bound there), so estimate it from r on a lattice of up to 4096 points, capped by
 * the bound that L gives from the box's centre. */
static vpds_status ensure_rmax(vpds_sampler *s)
{
    double c[VPDS_MAX_DIM] = {0}, rc, diag2 = 0, best = 0, *pts = NULL;
    int k, d = s->dim, per = 2;
    size_t n = 1, i, cap = 0;
    vpds_status st;
    if (s->sizing.rmax > 0) return VPDS_OK;
    for (k = 0; k < d; k++) {
        c[k] = 0.5 * (s->lo[k] + s->hi[k]);
        diag2 += (s->hi[k] - s->lo[k]) * (s->hi[k] - s->lo[k]);
    }
    st = vpdsi_sizing_eval(&s->sizing, c, 1, &rc, s->err, sizeof s->err);
    if (st != VPDS_OK) return st;
    while (per < 64 && n * (size_t)(per + 1) <= 4096) {
        per++;
        for (n = 1, k = 0; k < d; k++) n *= (size_t)per;
    }
    for (n = 1, k = 0; k < d; k++) n *= (size_t)per;
    if (vpdsi_mem_reserve(&s->mem, (void **)&pts, &cap, n * (size_t)d, sizeof(double)) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->buf_r, &s->cap_buf_r, n, sizeof(double))) {
        vpdsi_mem_free(&s->mem, pts, cap * sizeof(double));
        vpdsi_set_error(s, "out of memory estimating the largest radius");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (i = 0; i < n; i++) {
        size_t rest = i;
        for (k = 0; k < d; k++) {
            size_t j = rest % (size_t)per;
            rest /= (size_t)per;
            pts[i * (size_t)d + (size_t)k] =
                s->lo[k] + (s->hi[k] - s->lo[k]) * (double)j / (double)(per - 1);
        }
    }
    st = vpdsi_sizing_eval(&s->sizing, pts, n, s->buf_r, s->err, sizeof s->err);
    vpdsi_mem_free(&s->mem, pts, cap * sizeof(double));
    if (st != VPDS_OK) return st;
    for (i = 0; i < n; i++)
        if (s->buf_r[i] > best) best = s->buf_r[i];
    if (rc > best) best = rc;
    s->sizing.rmax = best;
    if (rc + s->sizing.lipschitz * sqrt(diag2) / 2 < best) s->sizing.rmax = rc + s->sizing.lipschitz * sqrt(diag2) / 2;
    return VPDS_OK;
}

static vpds_status run_checked(vpds_sampler *s)
{
    vpds_status st;
    s->err[0] = 0;
    if ((st = ensure_rmax(s)) != VPDS_OK) return st;
    return vpdsi_mps_run(s);
}

vpds_status vpds_run(vpds_sampler *s)
{
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    return run_checked(s);
}

static int has_samples(const vpds_sampler *s)
{
    size_t i;
    for (i = 0; i < s->n; i++)
        if (!(s->flags[i] & VPDSI_SAMPLE_FIXED)) return 1;
    return 0;
}

vpds_status vpds_refine(vpds_sampler *s, double t)
{
    double limit;
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->err[0] = 0;
    if (!isfinite(t) || !(t > 0)) {
        vpdsi_set_error(s, "t = %g: the scale must be finite and > 0", t);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (!vpdsi_scale_ok(t * s->coverage)) {
        vpdsi_set_error(s, "t = %g: t * coverage must be within [1e-50, 1e50]", t);
        return VPDS_ERR_OVERFLOW;
    }
    if (s->run.phase != VPDSI_IDLE && s->run.phase != VPDSI_DONE) {
        if (t == s->run.t) return run_checked(s); /* a paused refinement continues */
        vpdsi_set_error(s, "t = %g: the run at scale %g is not finished (call vpds_run until it "
                        "returns VPDS_OK before refining)", t, s->run.t);
        return VPDS_ERR_STATE;
    }
    if (has_samples(s) && t >= s->run.t) {
        if (t == s->run.t && s->run.phase == VPDSI_DONE) return VPDS_OK;
        vpdsi_set_error(s, "t = %g: refinement needs t below the current scale %g once samples "
                        "exist (their disks would conflict at a larger scale)", t, s->run.t);
        return VPDS_ERR_STATE;
    }
    limit = vpdsi_rule_max_lipschitz(s->rule);
    if (t * s->coverage * s->sizing.lipschitz >= limit) {
        vpdsi_set_error(s, "t = %g: t * coverage * L = %g is at or above the %s rule's limit %g",
                        t, t * s->coverage * s->sizing.lipschitz, vpdsi_rule_name(s->rule), limit);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    {
        /* a refinement that fails before any work (out of memory, overflow) must leave the
         * sampler at its old scale, as if it had not been called */
        double old_t = s->run.t;
        vpdsi_phase old_phase = s->run.phase;
        vpds_status st;
        vpdsi_mps_reset(s, t);
        st = run_checked(s);
        if (st < 0 && s->run.phase == VPDSI_IDLE) {
            s->run.t = old_t;
            s->run.phase = old_phase;
            s->stats.t = old_t;
        }
        return st;
    }
}

vpds_status vpds_next(vpds_sampler *s, double t_min, double *x_out, double *t_out)
{
    vpds_status st;
    double t;
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->err[0] = 0;
    if (!x_out || !t_out) {
        vpdsi_set_error(s, "vpds_next: x_out and t_out must not be NULL");
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (isnan(t_min)) {
        vpdsi_set_error(s, "vpds_next: t_min is NaN");
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (s->run.phase != VPDSI_DONE && (s->run.phase != VPDSI_IDLE || has_samples(s))) {
        vpdsi_set_error(s, "vpds_next: the run at scale %g is not finished; a stream starts from "
                        "an empty sampler or a maximal one (call vpds_run until VPDS_OK)", s->run.t);
        return VPDS_ERR_STATE;
    }
    if ((st = ensure_rmax(s)) != VPDS_OK) return st;
    st = vpdsi_stream_next(s, t_min, x_out, &t);
    if (st != VPDS_OK) return st;
    *t_out = t;
    /* the set is now maximal at t (Section 4.2): a later vpds_refine goes below it */
    vpdsi_mps_release(s);
    s->run.phase = VPDSI_DONE;
    s->run.t = t;
    s->stats.t = t;
    return VPDS_OK;
}

vpds_status vpds_add_points(vpds_sampler *s, const double *x, const double *r, size_t n)
{
    size_t i, step, pos;
    int k;
    vpds_status st;
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->err[0] = 0;
    if (n == 0) return VPDS_OK;
    if (!x) {
        vpdsi_set_error(s, "x is NULL with n = %zu", n);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    for (i = 0; i < n; i++) {
        for (k = 0; k < s->dim; k++)
            if (!(fabs(x[i * (size_t)s->dim + (size_t)k]) <= VPDSI_MAGNITUDE_MAX)) {
                vpdsi_set_error(s, "x[%zu][%d] = %g: fixed points must be finite (within 1e150)", i,
                                k, x[i * (size_t)s->dim + (size_t)k]);
                return VPDS_ERR_INVALID_ARGUMENT;
            }
        if (r && !vpdsi_radius_ok(r[i])) {
            vpdsi_set_error(s, "r[%zu] = %g: radii must be finite and > 0 (within [1e-100, 1e100])",
                            i, r[i]);
            return VPDS_ERR_INVALID_ARGUMENT;
        }
    }
    /* fixed points may share cells and carry other radii: the kd-tree takes over, and it must
     * first hold every sample (it lags after a run on the background grid) */
    if ((st = vpdsi_sync_tree(s)) != VPDS_OK) return st;
    if (s->grid_mode) {
        s->grid_mode = 0;
        vpdsi_bgrid_release(&s->grid, &s->mem);
    }
    if ((st = vpdsi_reserve_samples(s, n)) != VPDS_OK) return st;
    if (!r) {
        /* every radius first, so that a bad one leaves the sampler unchanged */
        if (vpdsi_mem_reserve(&s->mem, (void **)&s->buf_r, &s->cap_buf_r, n, sizeof(double))) {
            vpdsi_set_error(s, "out of memory for %zu radii", n);
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        st = vpdsi_sizing_eval(&s->sizing, x, n, s->buf_r, s->err, sizeof s->err);
        if (st != VPDS_OK) return st;
    }
    /* insert in a scattered order so that sorted input cannot make the tree a list */
    step = n > 2 ? (size_t)(0.6180339887498949 * (double)n) | 1u : 1;
    while (n > 2 && step > 1) {
        size_t a = n, b = step;
        while (b) { size_t tmp = a % b; a = b; b = tmp; }
        if (a == 1) break;
        step += 2;
    }
    /* stored in the caller's order; inserted into the kd-tree in a scattered order */
    {
        size_t first = s->n;
        vpdsi_kd_samples v;
        for (i = 0; i < n; i++) {
            double *xi = s->x + (first + i) * (size_t)s->dim;
            memcpy(xi, x + i * (size_t)s->dim, (size_t)s->dim * sizeof(double));
            vpdsi_wrap_point(s, xi); /* on a periodic axis: its image inside the box */
            s->r[first + i] = r ? r[i] : s->buf_r[i];
            s->t[first + i] = INFINITY;
            s->flags[first + i] = (uint8_t)(VPDSI_SAMPLE_FIXED | (r ? VPDSI_SAMPLE_OWN_RADIUS : 0u));
        }
        s->n += n;
        v = vpdsi_samples_view(s);
        for (i = 0, pos = 0; i < n; i++, pos = (pos + step) % n)
            vpdsi_kd_insert(&s->tree, &v, (int32_t)(first + pos));
        s->tree_n = s->n;
    }
    s->n_fixed += n;
    return VPDS_OK;
}

vpds_status vpds_set_budget(vpds_sampler *s, uint64_t budget)
{
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->budget = budget;
    return VPDS_OK;
}

size_t vpds_count(const vpds_sampler *s) { return live(s) ? s->n : 0; }
int vpds_dim(const vpds_sampler *s) { return live(s) ? s->dim : 0; }
const double *vpds_points(const vpds_sampler *s) { return live(s) ? s->x : NULL; }
const double *vpds_radii(const vpds_sampler *s) { return live(s) ? s->r : NULL; }
const double *vpds_scales(const vpds_sampler *s) { return live(s) ? s->t : NULL; }
const uint8_t *vpds_flags(const vpds_sampler *s) { return live(s) ? s->flags : NULL; }

vpds_stats vpds_get_stats(const vpds_sampler *s)
{
    vpds_stats st;
    if (!live(s)) {
        memset(&st, 0, sizeof st);
        return st;
    }
    st = s->stats;
    st.bytes_held = s->mem.held;
    st.peak_bytes = s->mem.peak;
    st.sizing_calls = s->sizing.calls;
    st.domain_calls = s->domain_calls;
    st.t = s->run.t;
    st.maximal = s->run.phase == VPDSI_DONE;
    return st;
}
