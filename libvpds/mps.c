/* Algorithm 1 (Section 3.1): darts thrown into a flat hyper-octree of active cells, then a
 * coverage sweep that splits every active cell into 2^d children and keeps the uncovered ones.
 *
 * Bias-free (Eq. 4): a dart picks an active cell uniformly (all cells of a level have the same
 * size) and a point uniformly in it; it becomes a sample iff it conflicts with no sample. The
 * active cells always contain every uncovered point, so accepted darts are uniform over the free
 * region. Work is cut into chunks; between chunks the state is complete, so a pause, an error
 * or an exhausted budget can resume to exactly the points of an uninterrupted run. */
#include "mps.h"
#include "pencil.h"
#include "rules.h"
#include "torus.h"
#include <math.h>
#include <string.h>

#ifndef DARTS_PER_CELL
#define DARTS_PER_CELL 0.5  /* A of Algorithm 1 */
#endif
#define CHUNK 256           /* darts or cells between checks of the budget */
#define PRECISION_BITS 44   /* cells stop splitting at 2^-44 of the coordinates' magnitude */

void vpdsi_mps_init(vpdsi_mps *m, int dim, const double *period)
{
    memset(m, 0, sizeof *m);
    m->holder = -1;
    vpdsi_uncovered_init(&m->unc, dim, period);
    vpdsi_mps_reset(m, 1.0);
}

void vpdsi_mps_reset(vpdsi_mps *m, double t)
{
    m->run.phase = VPDSI_IDLE;
    m->run.t = t;
}

void vpdsi_mps_release_cells(vpdsi_mps *m, vpdsi_store *st)
{
    vpdsi_cells_release(&m->run.cur, st->mem);
    vpdsi_cells_release(&m->run.next, st->mem);
    /* done at this scale: keep the samples, drop the accelerator (rebuilt on the next run) */
    vpdsi_store_drop_index(st);
}

void vpdsi_mps_release(vpdsi_mps *m, vpdsi_store *st)
{
    vpdsi_mps_release_cells(m, st);
    vpdsi_mem_free(st->mem, m->cand, m->cap_cand * sizeof(int32_t));
    vpdsi_mem_free(st->mem, m->cand_x, m->cap_cand_x * sizeof(double));
    vpdsi_mem_free(st->mem, m->cand_tag, m->cap_cand_tag * sizeof(uint16_t));
    vpdsi_mem_free(st->mem, m->strip.idx, m->strip.cap * sizeof(int32_t));
    vpdsi_mem_free(st->mem, m->base.idx, m->base.cap * sizeof(int32_t));
    vpdsi_mem_free(st->mem, m->group.idx, m->group.cap * sizeof(int32_t));
    memset(&m->strip, 0, sizeof m->strip);
    memset(&m->base, 0, sizeof m->base);
    memset(&m->group, 0, sizeof m->group);
    vpdsi_mem_free(st->mem, m->buf_x, m->cap_buf_x * sizeof(double));
    vpdsi_mem_free(st->mem, m->buf_r, m->cap_buf_r * sizeof(double));
    vpdsi_mem_free(st->mem, m->buf_u, m->cap_buf_u * sizeof(double));
    vpdsi_mem_free(st->mem, m->buf_at, m->cap_buf_at * sizeof(uint64_t));
    vpdsi_uncovered_release(&m->unc, st->mem);
    m->cand = NULL;
    m->cand_x = NULL;
    m->cand_tag = NULL;
    m->buf_x = m->buf_r = m->buf_u = NULL;
    m->buf_at = NULL;
    m->cap_cand_tag = m->cap_buf_at = 0;
    m->cap_cand = m->cap_cand_x = m->cap_buf_x = m->cap_buf_r = m->cap_buf_u = 0;
}

/* Upper bound of the distance at which a sample of r <= r_hi covers at the run's scale. */
static double coverage_reach(const vpdsi_mps *m, const vpdsi_ctx *ctx, double r_hi)
{
    const vpdsi_problem *pb = ctx->pb;
    return vpdsi_rule_reach(pb->rule, m->run.t * pb->coverage,
                            ctx->st->sizing.lipschitz, r_hi);
}

#ifndef DARTS_PER_BASE_CELL
#define DARTS_PER_BASE_CELL 1.5 /* level 0 darts are the cheapest: no cell to read */
#endif
static uint64_t darts_for(uint64_t cells, unsigned level)
{
    double n = ceil((level ? DARTS_PER_CELL : DARTS_PER_BASE_CELL) * (double)cells);
    return n < 1 ? 1 : (uint64_t)n;
}

/* Every sample into the grid just set up: 0, or -1 when the grid cannot hold them (a radius
 * other than the sizing's, or two in one cell: fixed points closer than the conflict distance).
 * Fixed points beyond the box (a tile's neighbours) go to its border cells. */
static int grid_index_all(vpdsi_store *st, const vpdsi_problem *pb)
{
    size_t i;
    for (i = 0; i < st->n; i++)
        if (st->r[i] != st->sizing.radius ||
            vpdsi_bgrid_place(&st->grid, st->x + i * (size_t)pb->dim, pb->lo, pb->hi, (int32_t)i))
            return -1;
    return 0;
}

/* The background grid serves a uniform radius where vpdsi_bgrid_serves and its setup say; the
 * kd-tree everything else. Which one serves depends on the problem alone: the two give valid
 * samplings that can differ at the precision limit, so a failed allocation is an error to retry,
 * never a switch of index (a retried run gives the points of one that never failed).
 * (vpdsi_bgrid_setup releases the grid of an earlier scale; the kd-tree path releases it below.) */
static vpds_status choose_index(vpdsi_mps *m, const vpdsi_ctx *ctx, int keep_tree)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    vpdsi_run *run = &m->run;
    double reach = run->t * pb->inhibition * st->sizing.radius;
    int fit = -1;
    st->grid_mode = 0;
    if (vpdsi_bgrid_serves(pb->dim, st->sizing.kind == VPDSI_SIZING_CONSTANT, pb->two_radii,
                           pb->any_periodic) && !keep_tree)
        fit = vpdsi_bgrid_setup(&st->grid, ctx->mem, pb->dim, run->geom.n0, pb->lo, run->geom.side0, reach);
    if (fit == 0 &&
        (vpdsi_mem_reserve(ctx->mem, (void **)&m->cand, &m->cap_cand, st->grid.n_stencil + 1,
                           sizeof(int32_t)) ||
         vpdsi_mem_reserve(ctx->mem, (void **)&m->cand_x, &m->cap_cand_x,
                           (st->grid.n_stencil + 1) * (size_t)pb->dim, sizeof(double)) ||
         vpdsi_mem_reserve(ctx->mem, (void **)&m->cand_tag, &m->cap_cand_tag, st->grid.n_stencil + 1,
                           sizeof(uint16_t))))
        fit = -2;
    if (fit == -2) {
        vpdsi_bgrid_release(&st->grid, ctx->mem);
        vpdsi_store_error(st, "out of memory setting up the background grid over %llu base cells"
                          " (t = %g)", (unsigned long long)run->base_count, run->t);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    if (fit == 0 && grid_index_all(st, pb) == 0) {
        st->grid_mode = 1;
        return VPDS_OK;
    }
    vpdsi_bgrid_release(&st->grid, ctx->mem);
    /* a variable radius with one radius on open axes: the octave grid (the two-radii search
     * and the domain's reads the kd-tree, which then lags behind until synced) */
    if (st->sizing.kind != VPDSI_SIZING_CONSTANT && pb->dim <= 3 && !pb->two_radii &&
        !pb->any_periodic && !keep_tree && !ctx->dom->fn)
        return vpdsi_store_use_ogrid(st, run->t * pb->inhibition * st->sizing.rmax, 0, 0);
    return vpdsi_store_sync_tree(st);
}

/* Base grid for the current scale: cells of diagonal t*coverage*r_max, so that in the uniform
 * case a sample covers its whole cell. */
static vpds_status setup(vpdsi_mps *m, const vpdsi_ctx *ctx, int keep_tree)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    vpdsi_run *run = &m->run;
    vpds_status e;
    int d = pb->dim, k;
    double target = vpdsi_lattice_base_side(run->t * pb->coverage * st->sizing.rmax, d);
    uint64_t total = 1;
    unsigned max_level = 62;
    run->geom.dim = d;
    memcpy(run->geom.lo, pb->lo, sizeof run->geom.lo);
    memcpy(run->geom.hi, pb->hi, sizeof run->geom.hi);
    for (k = 0; k < d; k++) {
        double ext = pb->hi[k] - pb->lo[k], cells = ceil(ext / target), mag, min_side;
        if (pb->period[k] > 0 && !(ext > 2 * run->t * pb->coverage * st->sizing.rmax)) {
            /* a disk would meet its own image across the wrap */
            vpdsi_store_error(st, "periodic axis %d: side %g is not above 2 * t * coverage * r_max ="
                            " %g (t = %g)", k, ext, 2 * run->t * pb->coverage * st->sizing.rmax,
                            run->t);
            return VPDS_ERR_INVALID_ARGUMENT;
        }
        unsigned lev;
        if (!(cells <= 1099511627776.0)) { /* 2^40 per axis */
            vpdsi_store_error(st, "scale t = %g: axis %d of extent %g needs %g base cells of side %g;"
                            " the cell count overflows", run->t, k, ext, cells, target);
            return VPDS_ERR_OVERFLOW;
        }
        run->geom.n0[k] = cells < 1 ? 1 : (uint64_t)cells;
        run->geom.side0[k] = ext / (double)run->geom.n0[k];
        if (total > (UINT64_C(1) << 40) / run->geom.n0[k]) {
            /* no machine holds a sampling that fine: refuse rather than exhaust memory */
            vpdsi_store_error(st, "scale t = %g: the base grid has more than 2^40 cells (radius too"
                            " small for the box); the cell count overflows", run->t);
            return VPDS_ERR_OVERFLOW;
        }
        total *= run->geom.n0[k];
        mag = fabs(pb->lo[k]) > fabs(pb->hi[k]) ? fabs(pb->lo[k]) : fabs(pb->hi[k]);
        if (ext > mag) mag = ext;
        min_side = ldexp(mag, -PRECISION_BITS);
        lev = 0;
        while (lev < 62 && ldexp(run->geom.side0[k], -(int)(lev + 1)) >= min_side) lev++;
        if (lev + vpdsi_bit_length(run->geom.n0[k]) > 63) lev = 63 - vpdsi_bit_length(run->geom.n0[k]);
        if (lev < max_level) max_level = lev;
    }
    run->base_count = total;
    run->max_level = max_level;
    m->unc.ready = 0;
    if ((e = choose_index(m, ctx, keep_tree)) != VPDS_OK) return e;
    run->implicit = 1;
    run->pos = 0;
    vpdsi_cells_layout(&run->cur, d, run->geom.n0, 0);
    vpdsi_cells_layout(&run->next, d, run->geom.n0, 0);
    if (st->n > 0) {
        run->phase = VPDSI_FILTER;
    } else {
        run->phase = VPDSI_DARTS;
        run->darts_left = darts_for(total, 0);
    }
    if (total > ctx->stats->peak_active_cells) ctx->stats->peak_active_cells = total;
    if (ctx->stats->levels < 1) ctx->stats->levels = 1;
    return VPDS_OK;
}

static void cell_coords(const vpdsi_mps *m, const vpdsi_ctx *ctx, uint64_t idx, uint64_t *c)
{
    const vpdsi_problem *pb = ctx->pb;
    const vpdsi_run *run = &m->run;
    int k;
    if (run->implicit) {
        for (k = 0; k < pb->dim; k++) {
            c[k] = idx % run->geom.n0[k];
            idx /= run->geom.n0[k];
        }
    } else {
        vpdsi_cells_get(&run->cur, (size_t)idx, pb->dim, c);
    }
}

/* The same for cells read in order (the sweep's): on from the last one read. */
static void seq_coords(vpdsi_mps *m, const vpdsi_ctx *ctx, uint64_t idx, uint64_t *c)
{
    if (m->run.implicit)
        cell_coords(m, ctx, idx, c);
    else
        vpdsi_cells_get_seq(&m->run.cur, (size_t)idx, ctx->pb->dim, c);
}

static unsigned cur_level(const vpdsi_mps *m) { return m->run.implicit ? 0 : m->run.cur.level; }

static uint64_t cur_count(const vpdsi_mps *m)
{
    return m->run.implicit ? m->run.base_count : (uint64_t)m->run.cur.count;
}

#ifndef CELL_PREFETCH
#define CELL_PREFETCH 8 /* darts ahead whose cells are asked for */
#endif
/* A copy of the dart generator CELL_PREFETCH darts ahead: the cell it will draw is asked for
 * (the cells lie anywhere in memory), then its draws are spent as the dart's. */
static void prefetch_ahead(const vpdsi_mps *m, vpdsi_rng *ahead, uint64_t total, int d, int with_u, int bucket)
{
    uint64_t idx = vpdsi_rng_below(ahead, total);
    int k;
    if (bucket)
        vpdsi_cells_prefetch_bucket(&m->run.cur, (size_t)idx);
    else if (!m->run.implicit)
        vpdsi_cells_prefetch(&m->run.cur, (size_t)idx);
    for (k = 0; k < d + with_u; k++) (void)vpdsi_rng_unit(ahead);
}

/* n darts into out (n*dim): a cell uniformly, then a point uniformly in it; in weighted mode
 * one more uniform per dart into u, for its acceptance (Eq. 12). */
static void draw_darts(const vpdsi_mps *m, const vpdsi_ctx *ctx, vpdsi_rng *rng, size_t n, double *out, double *u)
{
    uint64_t c[VPDS_MAX_DIM], total = cur_count(m);
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    unsigned level = cur_level(m);
    size_t j;
    int k, d = ctx->pb->dim, ahead_on = !m->run.implicit && n > CELL_PREFETCH;
    int two = ahead_on && m->run.cur.families && n > 2 * CELL_PREFETCH; /* bucket, then family */
    vpdsi_rng ahead = *rng, ahead2 = *rng;
    for (j = 0; two && j < 2 * CELL_PREFETCH; j++) prefetch_ahead(m, &ahead2, total, d, u != NULL, 1);
    for (j = 0; ahead_on && j < CELL_PREFETCH; j++) prefetch_ahead(m, &ahead, total, d, u != NULL, 0);
    for (j = 0; j < n; j++) {
        if (two && j + 2 * CELL_PREFETCH < n) prefetch_ahead(m, &ahead2, total, d, u != NULL, 1);
        if (ahead_on && j + CELL_PREFETCH < n) prefetch_ahead(m, &ahead, total, d, u != NULL, 0);
        cell_coords(m, ctx, vpdsi_rng_below(rng, total), c);
        vpdsi_lattice_box(&m->run.geom, level, c, lo, hi);
        for (k = 0; k < d; k++) {
            double v = lo[k] + vpdsi_rng_unit(rng) * (hi[k] - lo[k]);
            out[j * (size_t)d + (size_t)k] = v > hi[k] ? hi[k] : v;
        }
        if (u) u[j] = vpdsi_rng_unit(rng);
    }
}

static vpds_status reserve_buffers(vpdsi_mps *m, const vpdsi_ctx *ctx, size_t n)
{
    size_t nx;
    if (vpdsi_mul_size(n, (size_t)ctx->pb->dim, &nx) ||
        vpdsi_mem_reserve(ctx->mem, (void **)&m->buf_x, &m->cap_buf_x, nx, sizeof(double)) ||
        vpdsi_mem_reserve(ctx->mem, (void **)&m->buf_r, &m->cap_buf_r, n, sizeof(double))) {
        vpdsi_store_error(ctx->st, "out of memory for a chunk of %zu points", n);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

/* An error at dart j of a chunk: keep the darts before it, as a pause would, and spend no
 * draw on the rest (a retry throws the same darts). */
static void keep_darts_before(vpdsi_mps *m, const vpdsi_ctx *ctx, const vpdsi_rng *start, size_t j, int weighted)
{
    *ctx->rng = *start;
    draw_darts(m, ctx, ctx->rng, j, m->buf_x, weighted ? m->buf_u : NULL);
    m->run.darts_left -= j;
    ctx->stats->darts += j;
}

/* A chunk's darts, their radii and, in weighted mode, which are kept (Eq. 12 by rejection:
 * with probability (r_min / r(y))^d, so accepted darts have density proportional to 1 / r^d
 * over the free region). On an error no draw is spent: a retry throws the same darts. */
static vpds_status prepare_darts(vpdsi_mps *m, const vpdsi_ctx *ctx, size_t n, int weighted)
{
    vpdsi_store *st = ctx->st;
    int d = ctx->pb->dim, k;
    vpdsi_rng start = *ctx->rng;
    vpds_status e;
    size_t j;
    if ((e = reserve_buffers(m, ctx, n)) != VPDS_OK) return e;
    if ((e = vpdsi_store_reserve(st, n)) != VPDS_OK) return e;
    if ((weighted && vpdsi_mem_reserve(ctx->mem, (void **)&m->buf_u, &m->cap_buf_u, n, sizeof(double))) ||
        (st->grid_mode && vpdsi_mem_reserve(ctx->mem, (void **)&m->buf_at, &m->cap_buf_at, n, sizeof(uint64_t)))) {
        vpdsi_store_error(st, "out of memory for a chunk of %zu darts", n);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    draw_darts(m, ctx, ctx->rng, n, m->buf_x, weighted ? m->buf_u : NULL);
    for (j = 0; st->grid_mode && j < n; j++) m->buf_at[j] = vpdsi_bgrid_locate(&st->grid, m->buf_x + j * (size_t)d);
    if (st->sizing.kind == VPDSI_SIZING_CONSTANT) {
        for (j = 0; j < n; j++) m->buf_r[j] = st->sizing.radius;
    } else if ((e = vpdsi_store_radii(st, m->buf_x, n, m->buf_r)) != VPDS_OK) {
        *ctx->rng = start;
        return e;
    }
    for (j = 0; weighted && j < n; j++) {
        double ratio = st->sizing.rmin / m->buf_r[j], keep = 1;
        if (m->buf_r[j] < st->sizing.rmin) {
            char py[256];
            vpdsi_format_point(py, sizeof py, m->buf_x + j * (size_t)d, d);
            vpdsi_store_error(st, "sizing returned r = %.17g at x = (%s), below radius_min = %.17g",
                              m->buf_r[j], py, st->sizing.rmin);
            *ctx->rng = start;
            return VPDS_ERR_SIZING;
        }
        for (k = 0; k < d; k++) keep *= ratio;
        m->buf_u[j] = m->buf_u[j] < keep ? 1.0 : 0.0;
    }
    return VPDS_OK;
}

/* Whether the dart y (radius ry) becomes a sample (Eq. 4): it conflicts with no sample, lies
 * in the domain and, with two radii, covers a point not yet covered (Section 3.1, first
 * option). */
static vpds_status judge_dart(vpdsi_mps *m, const vpdsi_ctx *ctx, const double *y, uint64_t at, double ry,
                              int *accept)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    int varying = st->sizing.kind != VPDSI_SIZING_CONSTANT;
    double scale = m->run.t * pb->inhibition;
    int32_t witness = -1, hit;
    vpds_status e;
    *accept = 0;
    if (st->grid_mode) {
        hit = vpdsi_bgrid_conflict(&st->grid, st->x, at, y, scale * st->sizing.radius);
    } else {
        hit = vpdsi_store_conflict(st, y, ry, (int)pb->rule, scale,
                                   varying ? st->sizing.lipschitz : -1.0, &witness);
    }
    if (hit == -2) return vpdsi_store_lipschitz_broken(st, y, ry, witness);
    if (hit != -1) return VPDS_OK; /* conflicts with sample hit */
    if (ctx->dom->fn) {
        double phi;
        if ((e = vpdsi_domain_at(ctx->dom, st, y, &phi)) != VPDS_OK) return e;
        if (phi > 0) return VPDS_OK; /* outside the domain: rejected, as uniform over it wants */
    }
    if (pb->two_radii) {
        /* no cell that may hold an uncovered point within reach: nothing new to cover */
        if (!vpdsi_uncovered_near(&m->unc, y, coverage_reach(m, ctx, ry) + m->unc.half))
            return VPDS_OK;
        if (pb->algorithm >= 4) return vpdsi_uncovered_dart(&m->unc, ctx, m->run.t, y, ry, accept);
        return vpdsi_uncovered_in(&m->unc, ctx, m->run.t, y, y, ry, accept);
    }
    *accept = 1;
    return VPDS_OK;
}

#ifndef DART_PREFETCH
#define DART_PREFETCH 8 /* darts ahead whose cells and samples are asked for (vpdsi_store_prefetch) */
#endif
/* Dart j of the chunk asked for (vpdsi_store_prefetch; the background grid's with its cell). */
static void prefetch_dart(const vpdsi_mps *m, const vpdsi_ctx *ctx, size_t j, int grid, int stage)
{
    const vpdsi_store *st = ctx->st;
    if (grid)
        vpdsi_bgrid_prefetch(&st->grid, st->x, m->buf_at[j], stage);
    else
        vpdsi_store_prefetch(st, m->buf_x + j * (size_t)ctx->pb->dim, m->buf_r[j], stage);
}

static vpds_status darts_chunk(vpdsi_mps *m, const vpdsi_ctx *ctx, size_t n)
{
    vpdsi_store *st = ctx->st;
    int weighted = ctx->pb->weighted && st->sizing.kind != VPDSI_SIZING_CONSTANT;
    vpdsi_rng start = *ctx->rng;
    vpds_status e;
    size_t j;
    uint64_t boxes0 = m->unc.boxes;
    int grid = st->grid_mode; /* its cells located by prepare_darts */
    if ((e = prepare_darts(m, ctx, n, weighted)) != VPDS_OK) return e;
    for (j = 0; j < n; j++) {
        const double *y = m->buf_x + j * (size_t)ctx->pb->dim;
        int accept;
        if (j + 2 * DART_PREFETCH < n)
            prefetch_dart(m, ctx, j + 2 * DART_PREFETCH, grid, 0);
        if (j + DART_PREFETCH < n)
            prefetch_dart(m, ctx, j + DART_PREFETCH, grid, 1);
        if (weighted && m->buf_u[j] == 0.0) continue;
        if ((e = judge_dart(m, ctx, y, grid ? m->buf_at[j] : 0, m->buf_r[j], &accept)) != VPDS_OK) {
            /* keep the darts before this one, as a pause would */
            keep_darts_before(m, ctx, &start, j, weighted);
            return e;
        }
        if (accept) {
            vpdsi_store_append(st, y, m->buf_r[j], m->run.t, 0);
            ctx->stats->accepted++;
        }
        if (j + 1 < n && j + 1 + (m->unc.boxes - boxes0) >= n) {
            /* the coverage searches spent the chunk's work: stop here, as a pause would */
            keep_darts_before(m, ctx, &start, j + 1, weighted);
            return VPDS_OK;
        }
    }
    m->run.darts_left -= n;
    ctx->stats->darts += n;
    return VPDS_OK;
}

/* Version 12, on the kd-tree's lists from 6D on: a cell or child that two disks hold together
 * is dropped as one that one disk holds (pencil.h). Below 6D it cost more than it saved
 * (docs/performance-log.md); the background grid and the octave grid do without it. */
#ifndef VPDSI_PENCIL_MIN_DIM
#define VPDSI_PENCIL_MIN_DIM 6
#endif
static int uses_pencil(const vpdsi_ctx *ctx)
{
    return ctx->pb->algorithm >= 12 && ctx->pb->dim >= VPDSI_PENCIL_MIN_DIM && !ctx->st->grid_mode &&
           !ctx->st->ogrid_mode;
}

/* Whether one candidate holds the box [lo, hi] whole (as box_holder finds) or, with a pencil
 * (uses_pencil), the ball of two of them does: one pass over the list for both. */
static int box_held(const vpdsi_mps *m, const vpdsi_ctx *ctx, const double *lo, const double *hi, double r_lo,
                    double scale)
{
    vpdsi_kd_samples view = vpdsi_store_view(ctx->st);
    return vpdsi_pencil_list_holds(&view, m->cand, m->n_cand, ctx->pb->dim, ctx->pb->rule, scale, r_lo, lo, hi,
                                   ctx->pb->period);
}

/* The candidate that holds the box [lo, hi] whole, or -1. */
static int32_t box_holder(const vpdsi_mps *m, const vpdsi_ctx *ctx, const double *lo, const double *hi,
                          double r_lo, double scale)
{
    vpdsi_kd_samples view = vpdsi_store_view(ctx->st);
    return vpdsi_kd_box_holder(&ctx->st->tree, &view, m->cand, m->n_cand, lo, hi, r_lo, (int)ctx->pb->rule, scale);
}

static int box_covered(const vpdsi_mps *m, const vpdsi_ctx *ctx, const double *lo, const double *hi, double r_lo,
                       double scale)
{
    return box_holder(m, ctx, lo, hi, r_lo, scale) >= 0;
}

/* Octave grid: the sample that held the cell dropped last holds most next ones too (on the
 * ramp 2 of 3 dropped cells). When it holds this cell and the gather would list it,
 * box_covered on the gathered list would find it: the cell is dropped without the gather. */
static int holder_covers(const vpdsi_mps *m, const vpdsi_ctx *ctx, const double *lo, const double *hi,
                         double r_lo, double r_hi, double scale, int split)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_kd_samples view;
    double gather_scale = m->run.t * (pb->two_radii ? pb->coverage : pb->inhibition);
    if (!ctx->st->ogrid_mode || m->holder < 0 || (size_t)m->holder >= ctx->st->n) return 0;
    view = vpdsi_store_view(ctx->st);
    return vpdsi_kd_box_covered(&ctx->st->tree, &view, &m->holder, 1, lo, hi, r_lo, (int)pb->rule, scale) &&
           vpdsi_ogrid_gathers(&view, pb->dim, m->holder, lo, hi, r_hi, (int)pb->rule, gather_scale, split);
}

/* Children are decided BLOCK_CHILDREN at a time: all of them up to 8D, 2^(d-8) blocks past. */
#define BLOCK_BITS 8
#define BLOCK_CHILDREN (1u << BLOCK_BITS)
static unsigned block_children(int d, int split)
{
    return !split ? 1u : d < BLOCK_BITS ? 1u << d : BLOCK_CHILDREN;
}

/* The number of child j of block `block` (bit k: the upper half on axis k). */
static uint64_t child_number(unsigned block, unsigned j)
{
    return ((uint64_t)block << BLOCK_BITS) + j;
}

/* Whether bits 0 .. n - 1 of bits are all set (n up to BLOCK_CHILDREN). */
static int children_all_set(const uint64_t *bits, unsigned n)
{
    unsigned w;
    for (w = 0; w < n / 64; w++)
        if (bits[w] != ~UINT64_C(0)) return 0;
    return n % 64 == 0 || bits[n / 64] == (UINT64_C(1) << (n % 64)) - 1;
}

/* The children of a block held whole by one disk, from its squared farthest distance to each
 * half of the cell on each axis (far[k][0] the lower half): a child's farthest point from x is,
 * on each axis, the farther end of its half, so all children's squared farthest distances are
 * sums of one value per axis, built child by child from a neighbour that differs in one axis.
 * Bit j of covered is child (block << 8) + j (bit k of a child's number: upper half on axis k). */
static void disk_children(int d, int low, unsigned block, const double (*far)[2], double f2, uint64_t *covered)
{
    unsigned children = 1u << low, b;
    double sums[BLOCK_CHILDREN];
    int k;
    sums[0] = 0;
    for (k = 0; k < d; k++) sums[0] += far[k][k < low ? 0 : (block >> (k - low)) & 1u];
    if (sums[0] <= f2) covered[0] |= 1u;
    for (b = 1; b < children; b++) {
        unsigned bit = 0;
        while (!((b >> bit) & 1u)) bit++;
        sums[b] = sums[b & (b - 1)] - far[bit][0] + far[bit][1];
        if (sums[b] <= f2) covered[b >> 6] |= UINT64_C(1) << (b & 63u);
    }
}

/* Version 12: children that no disk holds alone, tried against the balls of pairs of the disks
 * that reach into the cell [lo, hi] (pencil.h), as disks are. */
static void pencil_children(const vpdsi_pencil *pen, int d, int low, unsigned block, const double *lo,
                            const double *mid, const double *hi, uint64_t *covered)
{
    int pair, k;
    for (pair = 0; pair < VPDSI_PENCIL_PAIRS; pair++) {
        double y[VPDS_MAX_DIM], r2, far[VPDS_MAX_DIM][2], least = 0;
        if (!vpdsi_pencil_ball(pen, d, pair, y, &r2)) continue;
        for (k = 0; k < d; k++) {
            double a = vpdsi_axis_far(y[k], lo[k], mid[k], 0.0), z = vpdsi_axis_far(y[k], mid[k], hi[k], 0.0);
            far[k][0] = a * a;
            far[k][1] = z * z;
            least += far[k][0] < far[k][1] ? far[k][0] : far[k][1];
        }
        if (least <= r2) disk_children(d, low, block, (const double (*)[2])far, r2, covered);
    }
}

/* Which children of cell c in block `block` are covered whole by one candidate (disk_children),
 * and with pen (version 12), by the ball of a pair of them. */
static void children_covered(const vpdsi_mps *m, const vpdsi_ctx *ctx, unsigned level, const uint64_t *c, double r_lo,
                             double scale, unsigned block, uint64_t *covered, vpdsi_pencil *pen)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    int d = pb->dim, k, low = d < BLOCK_BITS ? d : BLOCK_BITS;
    double lo[VPDS_MAX_DIM], mid[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    size_t j;
    vpdsi_lattice_box(&m->run.geom, level, c, lo, hi);
    vpdsi_lattice_mid(&m->run.geom, level, c, mid); /* the children: [lo, mid] and [mid, hi] */
    if (pen) vpdsi_pencil_reset(pen, d, lo, hi);
    for (j = 0; j < m->n_cand; j++) {
        const double *x = st->x + (size_t)m->cand[j] * (size_t)d;
        double f = scale * vpdsi_rule_f(pb->rule, st->r[m->cand[j]], r_lo), f2 = f * f;
        double far[VPDS_MAX_DIM][2], least = 0, whole = 0, near2 = 0;
        if (!(f > 0)) continue;
        for (k = 0; k < d; k++) {
            double a = vpdsi_axis_far(x[k], lo[k], mid[k], pb->period[k]);
            double z = vpdsi_axis_far(x[k], mid[k], hi[k], pb->period[k]);
            far[k][0] = a * a;
            far[k][1] = z * z;
            least += far[k][0] < far[k][1] ? far[k][0] : far[k][1];
            if (pen) {
                double g = vpdsi_axis_gap(x[k], lo[k], hi[k], pb->period[k]);
                near2 += g * g;
                whole += far[k][0] > far[k][1] ? far[k][0] : far[k][1];
            }
        }
        if (pen && near2 < f2 && whole > f2) vpdsi_pencil_offer(pen, d, x, f2, whole, lo, hi, pb->period);
        if (least > f2) continue; /* covers no child */
        disk_children(d, low, block, (const double (*)[2])far, f2, covered);
    }
    if (pen && pen->n >= 2 && !children_all_set(covered, 1u << low))
        pencil_children(pen, d, low, block, lo, mid, hi, covered);
}

/* The background grid's cells (one radius, open axes, up to 8D: one block): in one pass over
 * the base cell's packed candidates, whether one disk holds cell c whole (1, as box_covered)
 * and else which children are covered whole (as children_covered). The same bits as those two:
 * on an axis the cell's farther end is the farther of its halves' (rounding is monotone), and
 * the sums run in the same order. A pass stops once every child is covered: a later disk
 * holding the whole cell would leave no child either. */
static int packed_cover(const vpdsi_mps *m, int d, unsigned level, const uint64_t *c, const double *lo,
                        const double *hi, double f, uint64_t *covered)
{
    unsigned children = 1u << d;
    double mid[VPDS_MAX_DIM], f2 = f * f;
    size_t j;
    int k;
    vpdsi_lattice_mid(&m->run.geom, level, c, mid); /* the children: [lo, mid] and [mid, hi] */
    if (!(f > 0)) return 0;
    for (j = 0; j < m->n_cand; j++) {
        const double *x = m->cand_x + j * (size_t)d;
        double far[VPDS_MAX_DIM][2], least = 0, whole = 0;
        for (k = 0; k < d; k++) {
            double a = vpdsi_axis_far(x[k], lo[k], mid[k], 0.0);
            double z = vpdsi_axis_far(x[k], mid[k], hi[k], 0.0);
            far[k][0] = a * a;
            far[k][1] = z * z;
            least += far[k][0] < far[k][1] ? far[k][0] : far[k][1];
            whole += far[k][0] > far[k][1] ? far[k][0] : far[k][1];
        }
        if (whole <= f2) return 1;
        if (least > f2) continue; /* covers no child */
        disk_children(d, d, 0, (const double (*)[2])far, f2, covered);
        if (children_all_set(covered, children)) break;
    }
    return 0;
}

/* The background grid: whether the sample filed in cell c's base cell holds c whole (as
 * box_covered would find). Its cell's diagonal is below the reach, so it nearly always does,
 * and the cell is dropped without reading the stencil. */
static int occupant_covers(const vpdsi_ctx *ctx, unsigned level, const uint64_t *c,
                           const double *lo, const double *hi, double f)
{
    const vpdsi_store *st = ctx->st;
    uint64_t base[VPDS_MAX_DIM];
    int d = ctx->pb->dim, k;
    int32_t own;
    double s = 0;
    for (k = 0; k < d; k++) base[k] = c[k] >> level;
    own = st->grid.cell[vpdsi_bgrid_index(&st->grid, base)];
    if (own < 0 || !(f > 0)) return 0;
    for (k = 0; k < d; k++) {
        double e = vpdsi_axis_far(st->x[(size_t)own * (size_t)d + (size_t)k], lo[k], hi[k], 0.0);
        s += e * e;
    }
    return s <= f * f;
}

/* Coordinates of child b of cell c (bit k of b: the upper half on axis k); without a split
 * the "child" is the cell itself. */
static void child_coords(int d, const uint64_t *c, uint64_t b, int split, uint64_t *cc)
{
    int k;
    for (k = 0; k < d; k++) cc[k] = split ? 2 * c[k] + ((b >> k) & 1u) : c[k];
}

static int bit_set(const uint64_t *bits, unsigned b) { return (int)(bits[b >> 6] >> (b & 63u) & 1u); }

/* A cell that straddles the domain's boundary (centre's sdf phi): mark as covered each kept
 * child that lies outside the domain, and, with one radius, each whose part inside the domain
 * is covered by the union of disks (a search inside it); else such children would split along
 * the boundary down to the precision limit. Without a split the "child" is the cell itself. */
static vpds_status drop_outside_children(vpdsi_mps *m, const vpdsi_ctx *ctx, unsigned level, const uint64_t *c,
                                         int split, unsigned block, const double *centre,
                                         double phi, uint64_t *covered)
{
    const vpdsi_problem *pb = ctx->pb;
    int d = pb->dim, k;
    unsigned children = block_children(d, split), b;
    uint64_t cc[VPDS_MAX_DIM];
    vpds_status e;
    for (b = 0; b < children; b++) {
        double clo[VPDS_MAX_DIM], chi[VPDS_MAX_DIM], cm[VPDS_MAX_DIM], half, phi_c = phi;
        int found = 1;
        if (bit_set(covered, b)) continue;
        child_coords(d, c, child_number(block, b), split, cc);
        half = 0.5 * sqrt(vpdsi_lattice_box(&m->run.geom, split ? level + 1 : level, cc, clo, chi));
        for (k = 0; k < d; k++) cm[k] = 0.5 * (clo[k] + chi[k]);
        if (split) {
            if ((e = vpdsi_domain_at(ctx->dom, ctx->st, cm, &phi_c)) != VPDS_OK) return e;
            if ((e = vpdsi_domain_check_pair(ctx->st, centre, phi, cm, phi_c)) != VPDS_OK) return e;
        }
        if (phi_c <= -half) continue; /* inside, whole: the usual rules apply */
        if (phi_c <= half && !pb->two_radii &&
            (e = vpdsi_uncovered_in(&m->unc, ctx, m->run.t, clo, chi, 0.0, &found)) != VPDS_OK)
            return e;
        if (phi_c > half || !found) covered[b >> 6] |= UINT64_C(1) << (b & 63u);
    }
    return VPDS_OK;
}

/* r at the centres of the n cells from run->pos: it bounds r over each cell through L. */
static vpds_status centre_radii(vpdsi_mps *m, const vpdsi_ctx *ctx, size_t n, unsigned level)
{
    int d = ctx->pb->dim, k;
    uint64_t c[VPDS_MAX_DIM];
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    vpds_status e;
    size_t j;
    if ((e = reserve_buffers(m, ctx, n)) != VPDS_OK) return e;
    for (j = 0; j < n; j++) {
        seq_coords(m, ctx, m->run.pos + j, c);
        vpdsi_lattice_box(&m->run.geom, level, c, lo, hi);
        for (k = 0; k < d; k++) m->buf_x[j * (size_t)d + (size_t)k] = 0.5 * (lo[k] + hi[k]);
    }
    return vpdsi_store_radii(ctx->st, m->buf_x, n, m->buf_r);
}

#ifndef NEAR_STRIP
#define NEAR_STRIP 4 /* base cells along axis 0 that share one search of the kd-tree */
#endif
/* Base cells b and b' share a key when they lie in one strip (near_strip) or are one cell
 * (near_base); 0 means none. */
static uint64_t near_key(const vpdsi_lattice *g, const uint64_t *base, uint64_t strip)
{
    uint64_t key = 0;
    int k;
    for (k = g->dim - 1; k >= 0; k--) key = key * g->n0[k] + (k == 0 ? base[k] / strip : base[k]);
    return key + 1;
}

/* The diagonal of [lo, hi]: how far apart two of its points can lie. */
static double box_diagonal(int d, const double *lo, const double *hi)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) s += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return sqrt(s);
}

/* The bound of r a list searched for the box [lo, hi] holds for: the sizing's radius, or r_hi
 * of a cell inside it grown by L across the box (a cell found above it searches again). */
static double near_bound(const vpdsi_store *st, double r_hi, int d, const double *lo, const double *hi)
{
    if (st->sizing.kind == VPDSI_SIZING_CONSTANT) return st->sizing.radius;
    return r_hi + st->sizing.lipschitz * box_diagonal(d, lo, hi);
}

/* The samples near the base cell holding c (the kd-tree path with one radius), searched once
 * while the cells of a strip of base cells are swept one after another: m->strip holds those
 * near the strip; below level 0, m->base those of them near the base cell. Each holds for
 * cells of r <= r_bound (vpdsi_kd_near_box), so a variable radius uses them too; the list
 * gather then returns the tree's samples in the tree's order: the same bytes. */
static const vpdsi_near_list *near_lists(vpdsi_mps *m, const vpdsi_ctx *ctx, const uint64_t *c,
                                         unsigned level, double scale, double r_hi)
{
    const vpdsi_store *st = ctx->st;
    const vpdsi_lattice *g = &m->run.geom;
    vpdsi_kd_samples view = vpdsi_store_view(st);
    uint64_t base[VPDS_MAX_DIM], key, last;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], x[VPDS_MAX_DIM], rb;
    int k;
    for (k = 0; k < g->dim; k++) base[k] = c[k] >> level;
    if (m->strip.store_n != st->n) m->strip.key = m->base.key = 0;
    if ((key = near_key(g, base, NEAR_STRIP)) != m->strip.key || r_hi > m->strip.r_bound) {
        uint64_t first = base[0] - base[0] % NEAR_STRIP, b0 = base[0];
        last = first + NEAR_STRIP - 1 < g->n0[0] ? first + NEAR_STRIP - 1 : g->n0[0] - 1;
        base[0] = first;
        vpdsi_lattice_box(g, 0, base, lo, x);
        base[0] = last;
        vpdsi_lattice_box(g, 0, base, x, hi);
        base[0] = b0;
        m->strip.n = 0;
        rb = near_bound(st, r_hi, g->dim, lo, hi);
        if (vpdsi_kd_near_box(&st->tree, &view, lo, hi, rb, scale, 0.0, SIZE_MAX,
                              ctx->mem, &m->strip.idx, &m->strip.n, &m->strip.cap) < 0 ||
            vpdsi_mem_reserve(ctx->mem, (void **)&m->base.idx, &m->base.cap, m->strip.n,
                              sizeof(int32_t)) ||
            vpdsi_mem_reserve(ctx->mem, (void **)&m->cand, &m->cap_cand, m->strip.n,
                              sizeof(int32_t)))
            return NULL;
        m->strip.key = key;
        m->strip.store_n = st->n;
        m->strip.r_bound = rb;
        m->base.key = 0;
    }
    if (level == 0) return &m->strip; /* each base cell is swept once at level 0 */
    if ((key = near_key(g, base, 1)) != m->base.key || r_hi > m->base.r_bound) {
        vpdsi_lattice_box(g, 0, base, lo, hi);
        rb = near_bound(st, r_hi, g->dim, lo, hi);
        if (rb > m->strip.r_bound) rb = m->strip.r_bound; /* a filter keeps a subset */
        m->base.n = vpdsi_kd_filter_near(&st->tree, &view, m->strip.idx, m->strip.n, lo, hi,
                                         rb, scale, 0.0, m->base.idx);
        m->base.key = key;
        m->base.r_bound = rb;
    }
    return &m->base;
}

#ifndef GROUP_UP
#define GROUP_UP 2
#endif
/* The octave grid: the samples near the ancestor of cell c GROUP_UP levels up, searched once
 * while the cells under it are swept one after another (on the ramp 4.4 of them), for cells of
 * r_hi <= r_bound (near_bound). It holds every sample a cell's gather lists: one that may cover
 * a child of the cell lies within scale * f(r(x), r_hi) <= scale * f(r(x), r_bound) of the
 * cell, so of the ancestor, grown by a margin for the round-off of far coordinates. */
static const vpdsi_near_list *group_list(vpdsi_mps *m, const vpdsi_ctx *ctx, const uint64_t *c,
                                         unsigned level, double scale, double r_hi)
{
    vpdsi_store *st = ctx->st;
    int d = ctx->pb->dim, k;
    int same = m->group.key && m->group.store_n == st->n && m->group_level == level && r_hi <= m->group.r_bound;
    uint64_t a[3];
    double lo[3], hi[3], rb;
    vpdsi_kd_samples view;
    for (k = 0; k < d; k++) {
        a[k] = c[k] >> GROUP_UP;
        same = same && a[k] == m->group_c[k];
    }
    if (same) return &m->group;
    vpdsi_lattice_box(&m->run.geom, level - GROUP_UP, a, lo, hi);
    rb = near_bound(st, r_hi, d, lo, hi);
    for (k = 0; k < d; k++) {
        double margin = 1e-14 * (fabs(lo[k]) + fabs(hi[k]) + scale * rb);
        lo[k] -= margin;
        hi[k] += margin;
    }
    m->group.key = 0;
    m->group.n = 0;
    view = vpdsi_store_view(st);
    if (vpdsi_ogrid_near_rule(&st->ogrid, &view, lo, hi, rb, (int)ctx->pb->rule, scale, ctx->mem, &m->group.idx,
                              &m->group.n, &m->group.cap) < 0 ||
        vpdsi_mem_reserve(ctx->mem, (void **)&m->cand, &m->cap_cand, m->group.n, sizeof(int32_t)))
        return NULL;
    m->group.key = 1;
    m->group.store_n = st->n;
    m->group.r_bound = rb;
    m->group_level = level;
    memcpy(m->group_c, a, (size_t)d * sizeof *a);
    return &m->group;
}

/* The samples that may cover part of cell c ([lo, hi], r <= r_hi over it) into m->cand. */
static vpds_status gather_near(vpdsi_mps *m, const vpdsi_ctx *ctx, const uint64_t *c,
                               unsigned level, const double *lo, const double *hi, double r_hi,
                               int split)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    double scale = m->run.t * (pb->two_radii ? pb->coverage : pb->inhibition);
    if (st->grid_mode) {
        uint64_t base[VPDS_MAX_DIM];
        int k;
        uint64_t at;
        for (k = 0; k < pb->dim; k++) base[k] = c[k] >> level; /* the base cell holding this one */
        at = vpdsi_bgrid_index(&st->grid, base);
        /* the cells of one base cell come one after another: its list serves them all while
         * no sample comes (in 4D its stencil reads 609 grid cells), keyed as near_lists keys */
        if (m->base.key == at && m->base.store_n == st->n) {
            /* the base cell before this one on axis 0 (lattice order, as level 0 sweeps them):
             * its list slides one cell on, reading the stencil's leading face only; the tests
             * that read it (packed_cover, box_covered) ask whether any of them covers: the
             * order of the list changes nothing */
            m->n_cand = vpdsi_bgrid_slide(&st->grid, st->x, at, m->cand, m->cand_x, m->cand_tag,
                                          m->n_cand);
            m->base.key = at + 1;
        } else if (m->base.key != at + 1 || m->base.store_n != st->n) {
            /* packed once, read by every cell of the base cell (packed_cover) */
            m->n_cand = vpdsi_bgrid_near_packed(&st->grid, st->x, at, m->cand, m->cand_x,
                                                m->cand_tag);
            m->base.key = at + 1;
            m->base.store_n = st->n;
        } else {
            return VPDS_OK;
        }
        /* the next base cell's newcomers, in 2D (in 3D their rows cost more than they saved:
         * 1.05x the time at 10^5 samples), when it lies on this row: past its end the
         * stencil's leading cells would lie past the grid's border */
        if (pb->dim == 2 && base[0] + 1 < st->grid.n[0]) vpdsi_bgrid_prefetch_slide(&st->grid, st->x, at + 1);
        return VPDS_OK;
    }
    m->n_cand = 0;
    if (!st->ogrid_mode) {
        vpdsi_kd_samples view = vpdsi_store_view(st);
        const vpdsi_near_list *near = near_lists(m, ctx, c, level, scale, r_hi);
        if (!near) goto oom;
        if (pb->dim >= 4) {
            /* the base cell's list as it is (a superset: the same answers): the tests that read
             * it (box_covered, children_covered) reject a far sample as fast as the gather
             * would, and box_covered stops at the first disk that holds the cell; the gather of
             * each cell was a third of a 6D run (bench uniform 6 0.4: 0.77x without it) */
            memcpy(m->cand, near->idx, near->n * sizeof(int32_t));
            m->n_cand = near->n;
        } else {
            m->n_cand = vpdsi_kd_list_gather(&st->tree, &view, near->idx, near->n, lo, hi, r_hi,
                                             (int)pb->rule, scale, split, m->cand);
        }
    } else if (level >= GROUP_UP) { /* the octave grid, below the base cells' children */
        vpdsi_kd_samples view = vpdsi_store_view(st);
        const vpdsi_near_list *group = group_list(m, ctx, c, level, scale, r_hi);
        if (!group) goto oom;
        m->n_cand = vpdsi_kd_list_gather(&st->tree, &view, group->idx, group->n, lo, hi, r_hi,
                                         (int)pb->rule, scale, split, m->cand);
    } else if (vpdsi_store_gather(st, lo, hi, r_hi, (int)pb->rule, scale, split, &m->cand,
                                  &m->n_cand, &m->cap_cand)) {
        goto oom;
    }
    return VPDS_OK;
oom:
    vpdsi_store_error(st, "out of memory gathering the samples near a cell");
    return VPDS_ERR_OUT_OF_MEMORY;
}

static int point_in_box(int d, const double *p, const double *lo, const double *hi)
{
    int k;
    for (k = 0; k < d; k++)
        if (p[k] < lo[k] || p[k] > hi[k]) return 0;
    return 1;
}

/* Two radii: which kept children of the block may hold an uncovered point: not inside one
 * coverage disk (the gather, at the larger coverage reach, found every candidate; whole_c: the
 * cell is inside one), and not shown covered by a search inside them. */
static vpds_status flag_uncovered(vpdsi_mps *m, const vpdsi_ctx *ctx, unsigned level,
                                  const uint64_t *c, int split, unsigned block, int whole_c,
                                  double r_lo, const uint64_t *covered, uint8_t *flag)
{
    int d = ctx->pb->dim, learn = ctx->pb->algorithm >= 4, parent = VPDSI_CELL_UNKNOWN, indexed;
    unsigned children = block_children(d, split), b;
    uint64_t cov_c[4] = {0, 0, 0, 0}, cc[VPDS_MAX_DIM];
    double scale_c = m->run.t * ctx->pb->coverage, wbuf[VPDS_MAX_DIM + 1];
    const double *pw = NULL;
    vpds_status e;
    /* version 4: a parent shown covered has covered children; its witness flags one of them */
    if (learn && (e = vpdsi_uncovered_parent(&m->unc, ctx, m->run.t, m->run.pos, &parent, &pw)) != VPDS_OK)
        return e;
    indexed = learn && vpdsi_uncovered_indexed(&m->unc, m->run.pos);
    if (whole_c || parent == VPDSI_CELL_COVERED)
        cov_c[0] = cov_c[1] = cov_c[2] = cov_c[3] = ~UINT64_C(0);
    else if (split)
        children_covered(m, ctx, level, c, r_lo, scale_c, block, cov_c, NULL);
    for (b = 0; b < children; b++) {
        double clo[VPDS_MAX_DIM], chi[VPDS_MAX_DIM];
        int found = 0;
        vpdsi_search_out out;
        flag[b] = 0;
        if (bit_set(covered, b) || bit_set(cov_c, b)) continue;
        /* version 6: the darts' questions showed it covered */
        if (vpdsi_uncovered_child_covered(&m->unc, m->run.pos, d, split, (unsigned)child_number(block, b)))
            continue;
        child_coords(d, c, child_number(block, b), split, cc);
        vpdsi_lattice_box(&m->run.geom, split ? level + 1 : level, cc, clo, chi);
        if (pw && point_in_box(d, pw, clo, chi)) { /* still uncovered, so this child is flagged */
            flag[b] = 1;
            vpdsi_uncovered_record(&m->unc, d, pw);
            pw = NULL;
            continue;
        }
        memset(&out, 0, sizeof out);
        out.budget = VPDSI_UNCOVERED_BUDGET;
        out.witness = wbuf;
        out.in_indexed = indexed;
        if ((e = vpdsi_uncovered_in_box(&m->unc, ctx, m->run.t, clo, chi, 0.0, NULL, &out, &found)) != VPDS_OK)
            return e;
        flag[b] = (uint8_t)found;
        if (found && learn) vpdsi_uncovered_record(&m->unc, d, out.found_point ? wbuf : NULL);
    }
    return VPDS_OK;
}

/* One block of a cell's children (or the cell itself): the uncovered ones into run->next. */
static vpds_status sweep_block(vpdsi_mps *m, const vpdsi_ctx *ctx, const uint64_t *c, int split,
                               unsigned block, double r_lo, const double *centre, double phi,
                               double h, int whole_c, const uint64_t *known)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_run *run = &m->run;
    int d = pb->dim;
    unsigned level = cur_level(m), children = block_children(d, split), b;
    double scale = run->t * pb->inhibition;
    uint64_t covered[4] = {0, 0, 0, 0}, cc[VPDS_MAX_DIM];
    uint8_t flag[BLOCK_CHILDREN]; /* two radii: the child may hold an uncovered point */
    vpdsi_pencil pen;
    vpds_status e;
    if (known) memcpy(covered, known, sizeof covered);
    else if (split) children_covered(m, ctx, level, c, r_lo, scale, block, covered, uses_pencil(ctx) ? &pen : NULL);
    if (ctx->dom->fn && phi > -0.5 * h &&
        (e = drop_outside_children(m, ctx, level, c, split, block, centre, phi, covered)) != VPDS_OK)
        return e;
    if (pb->two_radii &&
        (e = flag_uncovered(m, ctx, level, c, split, block, whole_c, r_lo, covered, flag)) != VPDS_OK)
        return e;
    if (run->next.families) { /* one record for the children left (one block: d <= 8) */
        uint64_t keep[4];
        unsigned w;
        for (w = 0; w < 4; w++) keep[w] = ~covered[w];
        if (children < 64) keep[0] &= (UINT64_C(1) << children) - 1;
        vpdsi_cells_push_family(&run->next, d, c, keep);
        return VPDS_OK;
    }
    for (b = 0; b < children; b++) {
        if (bit_set(covered, b)) continue;
        if (pb->two_radii) m->unc.flag[run->next.count] = flag[b];
        child_coords(d, c, child_number(block, b), split, cc);
        vpdsi_cells_push(&run->next, d, cc);
    }
    return VPDS_OK;
}

/* One cell of the sweep (coordinates c, r at its centre rc): its uncovered children (or the
 * cell itself) into run->next, unless the cell lies outside the domain or inside one disk.
 * On an error the cell leaves nothing in run->next (its retry sweeps it whole). */
static vpds_status sweep_cell(vpdsi_mps *m, const vpdsi_ctx *ctx, const uint64_t *c, double rc,
                              int need_r, int split)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    vpdsi_run *run = &m->run;
    int d = pb->dim, k, whole_c = 0;
    unsigned level = cur_level(m), blocks = split && d > BLOCK_BITS ? 1u << (d - BLOCK_BITS) : 1u;
    unsigned block;
    /* a cell is dropped inside one inhibition disk (with one radius: one coverage disk) */
    double scale = run->t * pb->inhibition, L = st->sizing.lipschitz;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], centre[VPDS_MAX_DIM], phi = -INFINITY;
    double h = sqrt(vpdsi_lattice_box(&run->geom, level, c, lo, hi));
    double r_lo = need_r ? rc - L * h / 2 : st->sizing.radius;
    double r_hi = need_r ? rc + L * h / 2 : st->sizing.radius;
    size_t kept = run->next.count, kept_fam = run->next.n_fam, records = m->unc.n_nwit;
    uint64_t known[4] = {0, 0, 0, 0};
    const uint64_t *pre = NULL; /* the children's bits when decided here */
    int32_t holder;
    vpds_status e;
    if (ctx->dom->fn) {
        for (k = 0; k < d; k++) centre[k] = 0.5 * (lo[k] + hi[k]);
        if ((e = vpdsi_domain_at(ctx->dom, st, centre, &phi)) != VPDS_OK) return e;
        if (phi > 0.5 * h) return VPDS_OK; /* outside the domain, whole */
    }
    if (st->grid_mode && occupant_covers(ctx, level, c, lo, hi, scale * st->sizing.radius)) return VPDS_OK;
    if (holder_covers(m, ctx, lo, hi, r_lo, r_hi, scale, split)) return VPDS_OK;
    if ((e = gather_near(m, ctx, c, level, lo, hi, r_hi, split)) != VPDS_OK) return e;
    if (st->grid_mode && split) { /* one radius, open axes, one block: one pass decides all */
        if (packed_cover(m, d, level, c, lo, hi, scale * st->sizing.radius, known)) return VPDS_OK;
        pre = known;
    } else if (uses_pencil(ctx)) {
        if (box_held(m, ctx, lo, hi, r_lo, scale)) return VPDS_OK;
    } else if ((holder = box_holder(m, ctx, lo, hi, r_lo, scale)) >= 0) {
        m->holder = holder;
        return VPDS_OK;
    }
    if (pb->two_radii) whole_c = box_covered(m, ctx, lo, hi, r_lo, run->t * pb->coverage);
    for (block = 0; block < blocks; block++) {
        if ((e = sweep_block(m, ctx, c, split, block, r_lo, centre, phi, h, whole_c, pre)) != VPDS_OK) {
            vpdsi_cells_truncate(&run->next, kept, kept_fam);
            m->unc.n_nwit = records;
            return e;
        }
    }
    return VPDS_OK;
}

/* Sweep n cells from run->pos: drop covered ones, keep the others (split: their uncovered
 * children) in run->next. run->pos advances cell by cell, so an error mid-chunk loses nothing. */
static vpds_status sweep_chunk(vpdsi_mps *m, const vpdsi_ctx *ctx, size_t n, int split)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_run *run = &m->run;
    unsigned children = split ? 1u << pb->dim : 1u; /* past 8D sweep_step caps n */
    int varying = ctx->st->sizing.kind != VPDSI_SIZING_CONSTANT;
    /* r over the cell: for a rule that reads r(y), and for the reach of two radii' V */
    int need_r = varying && (vpdsi_rule_uses_y(pb->rule) || pb->two_radii);
    uint64_t c[VPDS_MAX_DIM];
    size_t j, need;
    vpds_status e;
    if (vpdsi_mul_size(n, children, &need) ||
        (run->next.families ? vpdsi_cells_reserve_families(&run->next, ctx->mem, n, pb->dim)
                            : vpdsi_cells_reserve(&run->next, ctx->mem, run->next.count + need)) ||
        (pb->two_radii && vpdsi_mem_reserve(ctx->mem, (void **)&m->unc.flag, &m->unc.cap_flag,
                                            run->next.count + need, 1)) ||
        (pb->two_radii && pb->algorithm >= 4 &&
         vpdsi_uncovered_reserve_records(&m->unc, ctx->mem, pb->dim, need))) {
        vpdsi_store_error(ctx->st, "out of memory for the active cells of level %u", run->next.level);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    uint64_t boxes0 = m->unc.boxes;
    if (need_r && (e = centre_radii(m, ctx, n, cur_level(m))) != VPDS_OK) return e;
    for (j = 0; j < n; j++) {
        seq_coords(m, ctx, run->pos, c);
        if ((e = sweep_cell(m, ctx, c, need_r ? m->buf_r[j] : 0.0, need_r, split)) != VPDS_OK)
            return e;
        run->pos++;
        /* the coverage searches' boxes are work too: a budget bounds them */
        if (j + 1 + (m->unc.boxes - boxes0) >= n) break;
    }
    /* a level finish_sweep stored back to front (level 0's implicit cells are not) */
    vpdsi_cells_give_back_read(&run->cur, ctx->mem, (size_t)run->pos);
    return VPDS_OK;
}

/* Two radii (Figure 2): keep a new cell only if a cell that may hold an uncovered point lies
 * within the coverage reach of it; kept cells are compacted in place, in order. */
static vpds_status vfilter_chunk(vpdsi_mps *m, const vpdsi_ctx *ctx, size_t n)
{
    vpdsi_store *st = ctx->st;
    vpdsi_run *run = &m->run;
    int d = ctx->pb->dim, k;
    int varying = st->sizing.kind != VPDSI_SIZING_CONSTANT;
    uint64_t c[VPDS_MAX_DIM];
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], centre[VPDS_MAX_DIM];
    size_t j;
    vpds_status e;
    if (!m->unc.ready && (e = vpdsi_uncovered_index(&m->unc, st, &m->run.next, &m->run.geom,
                                                       ctx->pb->algorithm >= 6   ? 2
                                                       : ctx->pb->algorithm >= 4 ? 1
                                                                                 : 0)) != VPDS_OK)
        return e;
    if (varying) {
        if ((e = reserve_buffers(m, ctx, n)) != VPDS_OK) return e;
        for (j = 0; j < n; j++) {
            vpdsi_cells_get(&run->next, (size_t)run->vpos + j, d, c);
            vpdsi_lattice_box(&m->run.geom, run->next.level, c, lo, hi);
            for (k = 0; k < d; k++) m->buf_x[j * (size_t)d + (size_t)k] = 0.5 * (lo[k] + hi[k]);
        }
        e = vpdsi_store_radii(st, m->buf_x, n, m->buf_r);
        if (e != VPDS_OK) return e;
    }
    for (j = 0; j < n; j++) {
        size_t i = (size_t)run->vpos;
        double h = 0.5 * sqrt(vpdsi_lattice_box(&m->run.geom, run->next.level, (vpdsi_cells_get(&run->next, i, d, c), c), lo, hi));
        double r_hi = varying ? m->buf_r[j] + st->sizing.lipschitz * h : st->sizing.radius;
        for (k = 0; k < d; k++) centre[k] = 0.5 * (lo[k] + hi[k]);
        if (vpdsi_uncovered_near(&m->unc, centre, coverage_reach(m, ctx, r_hi) + h + m->unc.half)) {
            vpdsi_cells_move(&run->next, i, (size_t)run->wpos);
            vpdsi_uncovered_move(&m->unc, i, (size_t)run->wpos);
            run->wpos++;
        }
        run->vpos++;
    }
    return VPDS_OK;
}

/* The sweep of a level is complete: its output becomes the active cells. */
static void finish_sweep(vpdsi_mps *m, const vpdsi_ctx *ctx, int split)
{
    vpdsi_run *run = &m->run;
    vpdsi_cells tmp = run->cur;
    run->cur = run->next;
    run->next = tmp;
    /* the next sweep holds these cells beside the ones it makes: the run's peak; stored back
     * to front, they give back their room as it reads them. The level before, emptied, gives
     * its room back (held through the darts, it was larger than this one past the largest
     * level) */
    vpdsi_cells_reverse(&run->cur);
    vpdsi_cells_shrink(&run->cur, ctx->mem);
    vpdsi_cells_empty(&run->next, ctx->mem);
    run->implicit = 0;
    run->pos = 0;
    if (run->cur.count > ctx->stats->peak_active_cells) ctx->stats->peak_active_cells = run->cur.count;
    if (run->cur.level + 1 > ctx->stats->levels) ctx->stats->levels = run->cur.level + 1;
    if (run->cur.count == 0) {
        run->phase = VPDSI_DONE;
        ctx->stats->delta = 0;
    } else if (!split && run->phase == VPDSI_SWEEP) {
        /* precision limit: report how far from maximal the set may be */
        uint64_t c[VPDS_MAX_DIM] = {0};
        double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], worst = 0;
        size_t i;
        for (i = 0; i < run->cur.count; i++) {
            double dg;
            vpdsi_cells_get_seq(&run->cur, i, ctx->pb->dim, c);
            dg = sqrt(vpdsi_lattice_box(&m->run.geom, run->cur.level, c, lo, hi));
            if (dg > worst) worst = dg;
        }
        ctx->stats->delta = worst;
        run->phase = VPDSI_DONE;
    } else {
        run->phase = VPDSI_DARTS;
        run->darts_left = darts_for(run->cur.count, run->cur.level);
    }
    if (run->phase == VPDSI_DONE) vpdsi_mps_release_cells(m, ctx->st);
}

static void begin_sweep(vpdsi_mps *m, const vpdsi_ctx *ctx, int split)
{
    /* a split's children as families (cells.h): a parent's record where its children each
     * took one (one block of children each: BLOCK_BITS is 8) */
    if (split && vpdsi_cells_families_serve(ctx->pb->dim, ctx->pb->two_radii))
        vpdsi_cells_layout_families(&m->run.next, ctx->pb->dim, m->run.geom.n0, cur_level(m) + 1u);
    else
        vpdsi_cells_layout(&m->run.next, ctx->pb->dim, m->run.geom.n0, cur_level(m) + (split ? 1u : 0u));
    m->run.pos = 0;
    m->unc.n_nwit = 0; /* the witness records of this sweep's flagged cells */
    m->strip.key = m->base.key = m->group.key = 0; /* new samples, and with a new scale new base cells */
}

/* One chunk of the sweep (or the filter) of at most limit cells; *done: work units spent. */
static vpds_status sweep_step(vpdsi_mps *m, const vpdsi_ctx *ctx, uint64_t limit, uint64_t *done)
{
    vpdsi_run *run = &m->run;
    int split = run->phase == VPDSI_SWEEP && cur_level(m) < run->max_level;
    uint64_t total = cur_count(m), before = run->pos;
    /* past 8D a cell's 2^d children are 2^(d-8) blocks of 256: each block is a unit of work,
     * in the chunk's size and in what it spent (counted as one unit per cell, a 16D call with
     * a budget of 1,500 split 1,500 cells into 98 million children: seconds, not milliseconds) */
    unsigned block_shift = split && ctx->pb->dim > BLOCK_BITS ? (unsigned)(ctx->pb->dim - BLOCK_BITS) : 0u;
    vpds_status e;
    limit = (limit >> block_shift) + (block_shift ? 1 : 0);
    uint64_t boxes0 = m->unc.boxes;
    if (total - run->pos < limit) limit = total - run->pos;
    e = sweep_chunk(m, ctx, (size_t)limit, split);
    *done = ((run->pos - before) << block_shift) + (m->unc.boxes - boxes0);
    if (e != VPDS_OK || run->pos != total) return e;
    if (ctx->pb->two_radii) {
        run->vsplit = split | (run->phase == VPDSI_FILTER ? 2 : 0);
        run->vpos = run->wpos = 0;
        m->unc.ready = 0;
        run->phase = VPDSI_VFILTER;
    } else {
        finish_sweep(m, ctx, split);
    }
    return VPDS_OK;
}

/* One chunk of the two radii' filter of the new cells. */
static vpds_status vfilter_step(vpdsi_mps *m, const vpdsi_ctx *ctx, uint64_t limit, uint64_t *done)
{
    vpdsi_run *run = &m->run;
    uint64_t total = run->next.count, before = run->vpos;
    vpds_status e;
    if (total - run->vpos < limit) limit = total - run->vpos;
    e = vfilter_chunk(m, ctx, (size_t)limit);
    *done = run->vpos - before;
    if (e != VPDS_OK || run->vpos != total) return e;
    run->next.count = (size_t)run->wpos;
    /* finish_sweep tells a precision stop by the phase: restore the sweep's */
    run->phase = run->vsplit & 2 ? VPDSI_FILTER : VPDSI_SWEEP;
    finish_sweep(m, ctx, run->vsplit & 1);
    return VPDS_OK;
}

/* One chunk of darts (or the start of the level's sweep once they are thrown). */
static vpds_status darts_step(vpdsi_mps *m, const vpdsi_ctx *ctx, uint64_t limit, uint64_t *done)
{
    vpdsi_run *run = &m->run;
    uint64_t before = run->darts_left;
    vpds_status e;
    *done = 0;
    if (run->darts_left == 0) {
        run->phase = VPDSI_SWEEP;
        begin_sweep(m, ctx, cur_level(m) < run->max_level);
        return VPDS_OK;
    }
    uint64_t boxes0 = m->unc.boxes;
    if (run->darts_left < limit) limit = run->darts_left;
    e = darts_chunk(m, ctx, (size_t)limit);
    *done = before - run->darts_left + (m->unc.boxes - boxes0);
    return e;
}

/* Whether the progress callback asks to stop. */
static int progress_stops(const vpdsi_mps *m, const vpdsi_ctx *ctx, const vpdsi_work *w)
{
    vpds_progress p;
    p.darts = ctx->stats->darts;
    p.samples = ctx->st->n;
    p.active_cells = m->run.phase == VPDSI_DONE ? 0 : cur_count(m);
    p.level = cur_level(m);
    p.t = m->run.t;
    return w->progress(&p, w->user) != 0;
}

vpds_status vpdsi_mps_run(vpdsi_mps *m, const vpdsi_ctx *ctx, const vpdsi_work *w)
{
    vpdsi_run *run = &m->run;
    uint64_t work = 0;
    vpds_status e = VPDS_OK;
    if (run->phase == VPDSI_DONE) return VPDS_OK;
    if (run->phase == VPDSI_IDLE) {
        if ((e = setup(m, ctx, w->keep_tree)) != VPDS_OK) return e;
        if (run->phase == VPDSI_FILTER) begin_sweep(m, ctx, 0);
    }
    for (;;) {
        uint64_t limit = CHUNK, done = 0;
        int begins_sweep = run->phase == VPDSI_DARTS && run->darts_left == 0;
        if (run->phase == VPDSI_DONE && ctx->st->n == 0 && ctx->dom->fn) {
            /* nothing to sample: say so, and leave the sampler as it was */
            vpdsi_mps_reset(m, run->t);
            vpdsi_store_error(ctx->st, "domain: no point of the box with sdf <= 0 was found (the "
                              "domain is empty, or too thin for darts to land in)");
            return VPDS_ERR_DOMAIN;
        }
        if (run->phase == VPDSI_DONE) return VPDS_OK;
        if (w->budget && work >= w->budget) return VPDS_PAUSED;
        if (w->budget && w->budget - work < limit) limit = w->budget - work;
        switch (run->phase) {
        case VPDSI_FILTER:
        case VPDSI_SWEEP: e = sweep_step(m, ctx, limit, &done); break;
        case VPDSI_VFILTER: e = vfilter_step(m, ctx, limit, &done); break;
        case VPDSI_DARTS: e = darts_step(m, ctx, limit, &done); break;
        default: return VPDS_ERR_STATE;
        }
        work += done;
        if (e != VPDS_OK) return e;
        if (begins_sweep) continue; /* only the sweep began: no progress to report */
        if (w->progress && progress_stops(m, ctx, w))
            return run->phase == VPDSI_DONE ? VPDS_OK : VPDS_PAUSED;
    }
}
