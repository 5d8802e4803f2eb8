/* Algorithm 1 on the pieces of a triangle mesh (see surface.h): seed pieces no wider than one
 * disk, throw darts uniform by area, sweep (drop covered pieces, split the others in four),
 * repeat until no piece is left or none can split. */
#include "surface.h"
#include "rules.h"
#include <math.h>
#include <string.h>

#define DARTS_PER_SEED_PIECE 1.5 /* A of Algorithm 1, as for the box's base cells */
#define DARTS_PER_PIECE 0.5
#define PIECE_CHUNK 256                /* darts or pieces between checks of the budget */
#define PIECE_MAX_LEVEL 52             /* lattice coordinates i * 2^-level stay exact doubles */
/* a piece smaller than this fraction of a disk's area does not split while larger pieces are
 * active (a sliver's pieces keep its shape: split while darts go elsewhere, they would multiply
 * without end); once only such pieces are left, every dart lands on them and they split too */
#define MIN_AREA_FRACTION 9.094947017729282e-13 /* 2^-40 */
#define SEED_COUNT_MAX 1099511627776.0          /* 2^40 seed pieces (never stored): refused beyond */
#define SEED_EDGE_MAX 67108864.0                /* 2^26 per edge: lattice coordinates stay exact */

void vpdsi_surface_init(vpdsi_surface *s)
{
    memset(s, 0, sizeof *s);
    s->t = 1.0;
}

static void release_pieces(vpdsi_surface *s, vpdsi_mem *m)
{
    vpdsi_piece_array_release(&s->cur, m);
    vpdsi_piece_array_release(&s->next, m);
    vpdsi_mem_free(m, s->cum, s->cap_cum * sizeof *s->cum);
    vpdsi_mem_free(m, s->near, s->cap_near * sizeof *s->near);
    vpdsi_mem_free(m, s->cache, s->cap_cache * sizeof *s->cache);
    vpdsi_mem_free(m, s->seed_m, s->cap_seed_m * sizeof *s->seed_m);
    vpdsi_mem_free(m, s->tri_cum, s->cap_tri_cum * sizeof *s->tri_cum);
    s->cum = s->tri_cum = NULL;
    s->near = s->cache = NULL;
    s->seed_m = NULL;
    s->cap_cum = s->cap_near = s->n_near = 0;
    s->n_cache = s->cap_cache = s->cap_seed_m = s->cap_tri_cum = 0;
    s->cum_ready = s->cache_ok = s->implicit = 0;
}

void vpdsi_surface_release(vpdsi_surface *s, vpdsi_mem *m)
{
    release_pieces(s, m);
}

void vpdsi_surface_done_at(vpdsi_surface *s, vpdsi_mem *m, double t)
{
    release_pieces(s, m);
    s->t = t;
    s->phase = VPDSI_SURF_DONE;
}

void vpdsi_surface_begin(vpdsi_surface *s, double t)
{
    s->prev_t = s->t;
    s->prev_phase = s->phase;
    s->floor_lifted = 0;
    s->t = t;
    s->phase = VPDSI_SURF_SEED;
    s->pos = 0;
    vpdsi_piece_array_clear(&s->cur);
    vpdsi_piece_array_clear(&s->next);
    s->cum_ready = s->cache_ok = s->implicit = 0;
}

/* Whether the piece may split: above the coordinates' precision and the area darts can find. */
static int splittable(const vpdsi_surface_ctx *ctx, const vpdsi_surface *s, const vpdsi_piece *p,
                      double r_hi)
{
    double reach = s->t * ctx->coverage * r_hi;
    uint64_t m = s->seed_m[p->tri];
    return p->level + vpdsi_lattice_bits(m) < PIECE_MAX_LEVEL &&
           vpdsi_piece_edge(ctx->mesh, m, p) >= 2 * ctx->mesh->min_edge &&
           (s->floor_lifted || vpdsi_piece_area(ctx->mesh, m, p) >= MIN_AREA_FRACTION * reach * reach);
}

/* ---- coverage ---- */

static void corners_box(double x[3][3], double *lo, double *hi)
{
    int k, q;
    for (k = 0; k < 3; k++) {
        lo[k] = hi[k] = x[0][k];
        for (q = 1; q < 3; q++) {
            if (x[q][k] < lo[k]) lo[k] = x[q][k];
            if (x[q][k] > hi[k]) hi[k] = x[q][k];
        }
    }
}

/* The samples that may conflict with or cover a point of the piece (corners x, r <= r_hi),
 * into s->near: filtered from the cached list of an earlier piece's box when that box holds
 * this one (the samples do not change during a sweep), else from a new search of the piece's
 * own box. A box two edges wider on every side, shared by the next pieces of a row, cost more
 * than it saved: the square of two triangles at r = 0.002 took 1.16x the time. */
static vpds_status piece_near(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, double x[3][3],
                              double r_hi)
{
    vpdsi_store *st = ctx->st;
    vpdsi_kd_samples v = vpdsi_store_view(st);
    double lo[3], hi[3], scale = s->t * ctx->coverage;
    int k, inside = s->cache_ok && r_hi <= s->cache_r;
    vpds_status e;
    corners_box(x, lo, hi);
    for (k = 0; k < 3 && inside; k++) inside = lo[k] >= s->cache_lo[k] && hi[k] <= s->cache_hi[k];
    if (!inside) {
        s->cache_ok = 0;
        s->n_cache = 0;
        for (k = 0; k < 3; k++) {
            s->cache_lo[k] = lo[k];
            s->cache_hi[k] = hi[k];
        }
        s->cache_r = ctx->mesh->vr || st->sizing.kind != VPDSI_SIZING_CONSTANT ? 1.25 * r_hi : r_hi;
        if ((e = vpdsi_store_near_box(st, s->cache_lo, s->cache_hi, s->cache_r, scale, &s->cache,
                                      &s->n_cache, &s->cap_cache)) != VPDS_OK)
            return e;
        if (vpdsi_mem_reserve(st->mem, (void **)&s->near, &s->cap_near, s->n_cache, sizeof *s->near)) {
            vpdsi_store_error(st, "out of memory for a list of %zu samples near a piece", s->n_cache);
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        s->cache_ok = 1;
    }
    s->n_near = vpdsi_kd_filter_near(&st->tree, &v, s->cache, s->n_cache, lo, hi, r_hi, scale, 0, s->near);
    return VPDS_OK;
}

/* Whether sample i holds the three corners in its disk at r_lo: then the whole piece, the disk
 * being convex and f non-decreasing in r(y) (Table 2's BiX/XiB on a triangle). */
static int holds_corners(const vpdsi_surface *s, const vpdsi_surface_ctx *ctx, int32_t i,
                         double x[3][3], double r_lo)
{
    const vpdsi_store *st = ctx->st;
    const double *c = st->x + 3 * (size_t)i;
    double f = s->t * ctx->coverage * vpdsi_rule_f(ctx->rule, st->r[i], r_lo), f2 = f * f;
    int q;
    for (q = 0; q < 3; q++) {
        double d0 = x[q][0] - c[0], d1 = x[q][1] - c[1], d2 = x[q][2] - c[2];
        if (d0 * d0 + d1 * d1 + d2 * d2 > f2) return 0;
    }
    return 1;
}

/* Whether one sample of the near list holds the piece; the one found is tried first for the
 * next piece (neighbours are mostly held by the same disk). */
static int corners_covered(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, double x[3][3],
                           double r_lo)
{
    size_t n;
    for (n = 0; n < s->n_near; n++)
        if (holds_corners(s, ctx, s->near[n], x, r_lo)) {
            s->last_cover = s->near[n];
            return 1;
        }
    return 0;
}

/* ---- phases ---- */

/* Room for `need` pieces of levels up to max_level (their coordinates below m_max 2^level). */
static vpds_status reserve_pieces(const vpdsi_surface *s, vpdsi_mem *m, vpdsi_piece_array *a,
                                  size_t need, unsigned max_level, vpdsi_store *st)
{
    if (vpdsi_piece_array_reserve(a, m, need, vpdsi_lattice_bits(s->m_max) + max_level)) {
        vpdsi_store_error(st, "out of memory for %zu active pieces", need);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

/* r over live triangle k as the seed lattice sees it: exact bounds for a constant and vertex
 * radii, r at the centroid for a sizing (seed pieces only need to be about a disk wide: a piece
 * too large for one disk is split by the sweep like any other). */
static vpds_status seed_radius(const vpdsi_surface_ctx *ctx, uint32_t k, double *r)
{
    const vpdsi_trimesh *mesh = ctx->mesh;
    const uint32_t *t = mesh->tri + 3 * (size_t)mesh->live[k];
    double uv[2] = {1.0 / 3, 1.0 / 3}, c[3];
    int q;
    if (mesh->vr) {
        for (*r = INFINITY, q = 0; q < 3; q++) *r = mesh->vr[t[q]] < *r ? mesh->vr[t[q]] : *r;
        return VPDS_OK;
    }
    if (ctx->st->sizing.kind == VPDSI_SIZING_CONSTANT) {
        *r = ctx->st->sizing.radius;
        return VPDS_OK;
    }
    for (q = 0; q < 3; q++)
        c[q] = (mesh->v[3 * (size_t)t[0] + q] + mesh->v[3 * (size_t)t[1] + q] +
                mesh->v[3 * (size_t)t[2] + q]) / 3;
    return vpdsi_trimesh_radius(ctx->mesh, ctx->st, k, uv, c, r);
}

/* A maximal set's samples per r^2 of area (2D; 0.698 on the unit square at r = 0.002). */
#define SAMPLES_PER_DISK_AREA 0.7
/* Cells per expected sample that the octave grid may hold in arrays (4 bytes each). */
#define DENSE_CELLS_PER_SAMPLE 4

/* Index the samples: the octave grid when the largest radius is known, else the kd-tree. Its
 * levels stop at the least radius (vertex radii interpolate between their vertices'); the
 * coarsest go in arrays while their cells over the mesh's box are few beside the samples
 * expected (a flat or gently curved mesh; the unit sphere's box at r = 0.01 has 12 per sample). */
static vpds_status choose_sample_index(const vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    const vpdsi_trimesh *mesh = ctx->mesh;
    vpdsi_store *st = ctx->st;
    double top = 0, bottom = INFINITY, scale = s->t * ctx->coverage, expect;
    size_t k;
    vpds_status e = vpdsi_store_use_tree(st);
    if (e != VPDS_OK) return e;
    if (mesh->vr) {
        for (k = 0; k < mesh->n_vertices; k++) {
            top = mesh->vr[k] > top ? mesh->vr[k] : top;
            bottom = mesh->vr[k] < bottom ? mesh->vr[k] : bottom;
        }
    } else if (st->sizing.kind == VPDSI_SIZING_CONSTANT) {
        top = bottom = st->sizing.radius;
    }
    if (!(top > 0)) return VPDS_OK;
    expect = SAMPLES_PER_DISK_AREA * s->tri_cum[mesh->n_live - 1] / (scale * top * scale * top);
    return vpdsi_store_use_ogrid(st, scale * top, bottom, DENSE_CELLS_PER_SAMPLE * expect);
}

static void begin_piece_darts(vpdsi_surface *s, double per_piece, double pieces)
{
    double n = ceil(per_piece * pieces);
    s->phase = VPDSI_SURF_DARTS;
    s->darts_left = n < 1 ? 1 : (uint64_t)n;
    s->cum_ready = 0;
}

static void begin_piece_sweep(vpdsi_surface *s, vpdsi_surf_phase phase)
{
    s->phase = phase;
    s->pos = 0;
    s->ipos = 0;
    s->ctri = 0;
    s->crow = s->cpos = 0;
    s->split_any = 0;
    s->cache_ok = 0; /* new samples since the last sweep */
    s->last_cover = -1;
}

/* The seed lattice of each live triangle: m = ceil(longest edge / (t * coverage * r)) pieces
 * per edge. Chunks of triangles; a sizing failure leaves the triangle for the retry. */
static vpds_status seed_step(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, uint64_t limit,
                             uint64_t *done)
{
    const vpdsi_trimesh *mesh = ctx->mesh;
    vpdsi_mem *mem = ctx->st->mem;
    vpds_status e;
    if (s->pos == 0) {
        if (vpdsi_mem_reserve(mem, (void **)&s->seed_m, &s->cap_seed_m, mesh->n_live, sizeof *s->seed_m) ||
            vpdsi_mem_reserve(mem, (void **)&s->tri_cum, &s->cap_tri_cum, mesh->n_live, sizeof *s->tri_cum)) {
            vpdsi_store_error(ctx->st, "out of memory for the seed lattices of %zu triangles", mesh->n_live);
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        s->seed_total = 0;
        s->m_max = 0;
    }
    for (; s->pos < mesh->n_live && *done < limit; s->pos++, (*done)++) {
        double r, ratio, m;
        if ((e = seed_radius(ctx, (uint32_t)s->pos, &r)) != VPDS_OK) return e;
        ratio = mesh->longest[s->pos] / (s->t * ctx->coverage * r);
        m = ratio > 1 ? ceil(ratio) : 1;
        if (!(m <= SEED_EDGE_MAX) || (double)s->seed_total + m * m > SEED_COUNT_MAX) {
            vpdsi_store_error(ctx->st, "scale t = %g: triangle %u needs %.3g pieces of the size of a disk "
                              "(the mesh needs more than %.0f in all, or the radius is too small for "
                              "its triangles); the count overflows", s->t, (unsigned)mesh->live[s->pos],
                              m * m, SEED_COUNT_MAX);
            /* refused for good at this scale: back to the state before (a completed run stays) */
            release_pieces(s, ctx->st->mem);
            s->t = s->prev_t;
            s->phase = s->prev_phase;
            s->pos = 0;
            return VPDS_ERR_OVERFLOW;
        }
        s->seed_m[s->pos] = (uint64_t)m;
        if ((uint64_t)m > s->m_max) s->m_max = (uint64_t)m;
        s->seed_total += (uint64_t)m * (uint64_t)m;
        s->tri_cum[s->pos] = (s->pos ? s->tri_cum[s->pos - 1] : 0) + mesh->area[s->pos];
    }
    if (s->pos < mesh->n_live) return VPDS_OK;
    if ((e = choose_sample_index(s, ctx)) != VPDS_OK) return e;
    if (s->seed_total > ctx->stats->peak_active_cells) ctx->stats->peak_active_cells = s->seed_total;
    if (ctx->stats->levels < 1) ctx->stats->levels = 1;
    s->implicit = 1;
    if (ctx->st->n > 0) {
        /* a refinement: the earlier samples cover much of the surface already */
        begin_piece_sweep(s, VPDSI_SURF_FILTER);
    } else {
        begin_piece_darts(s, DARTS_PER_SEED_PIECE, (double)s->seed_total);
    }
    return VPDS_OK;
}

/* The first index whose running sum exceeds u (the last when none does): a binary search's
 * answer, found from where u would fall were the areas equal (they nearly are, level by level),
 * by galloping to a bracket and bisecting it: a few reads where bisection took log2 n. */
static size_t search_running_sums(const double *cum, size_t n, double u)
{
    double at = u / cum[n - 1] * (double)n;
    size_t guess = at >= 0 && at < (double)n ? (size_t)at : n - 1, lo, hi, step = 1;
    if (cum[guess] > u || guess == n - 1) {
        hi = guess; /* the answer is at most guess: down to a sum at most u */
        for (;;) {
            size_t t = hi > step ? hi - step : 0;
            if (hi == 0) return 0;
            if (cum[t] <= u) {
                lo = t + 1;
                break;
            }
            hi = t;
            step <<= 1;
        }
    } else {
        lo = guess + 1; /* the answer lies past guess: up to a sum above u, or the end */
        for (;;) {
            size_t t = n - 1 - lo > step ? lo + step : n - 1;
            if (cum[t] > u || t == n - 1) {
                hi = t;
                break;
            }
            lo = t + 1;
            step <<= 1;
        }
    }
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (cum[mid] > u) hi = mid; else lo = mid + 1;
    }
    return lo;
}

/* The dart: a piece by area (binary search of the running sums; over the seed pieces, a
 * triangle by area), then a uniform point of it (the unit square folded onto the triangle). */
static void draw_piece_dart(const vpdsi_surface *s, const vpdsi_surface_ctx *ctx, uint32_t *tri,
                      double *uv, double *x)
{
    const vpdsi_trimesh *mesh = ctx->mesh;
    vpdsi_piece p;
    double a, b, scale;
    if (s->implicit) {
        memset(&p, 0, sizeof p);
        p.tri = (uint32_t)search_running_sums(s->tri_cum, mesh->n_live,
                                      vpdsi_rng_unit(ctx->rng) * s->tri_cum[mesh->n_live - 1]);
        scale = 1;
    } else {
        p = vpdsi_piece_array_get(&s->cur, search_running_sums(s->cum, s->cur.n,
                                  vpdsi_rng_unit(ctx->rng) * s->cum[s->cur.n - 1]));
        scale = ldexp(1.0 / (double)s->seed_m[p.tri], -(int)p.level);
    }
    a = vpdsi_rng_unit(ctx->rng);
    b = vpdsi_rng_unit(ctx->rng);
    if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
    }
    if (p.down) {
        a = 1 - a;
        b = 1 - b;
    }
    *tri = p.tri;
    /* i * scale + a * scale keeps the low bits of a, which i + a would round away deep down */
    uv[0] = s->implicit ? a : (double)p.i * scale + a * scale;
    uv[1] = s->implicit ? b : (double)p.j * scale + b * scale;
    vpdsi_trimesh_point(mesh, p.tri, uv, x);
}

static vpds_status build_piece_sums(vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    double sum = 0;
    size_t k;
    if (vpdsi_mem_reserve(ctx->st->mem, (void **)&s->cum, &s->cap_cum, s->cur.n, sizeof *s->cum)) {
        vpdsi_store_error(ctx->st, "out of memory for the areas of %zu pieces", s->cur.n);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (k = 0; k < s->cur.n; k++) {
        vpdsi_piece p = vpdsi_piece_array_get(&s->cur, k);
        s->cum[k] = sum += vpdsi_piece_area(ctx->mesh, s->seed_m[p.tri], &p);
    }
    s->cum_ready = 1;
    return VPDS_OK;
}

/* A chunk of darts (Eq. 4: kept when no sample conflicts). A failed sizing value restores the
 * rng to the failing dart, so the retry throws it again. */
static vpds_status piece_darts_step(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, uint64_t limit,
                                    uint64_t *done)
{
    vpdsi_store *st = ctx->st;
    int callback = !ctx->mesh->vr && st->sizing.kind != VPDSI_SIZING_CONSTANT;
    double scale = s->t * ctx->coverage;
    vpds_status e;
    if (s->darts_left == 0) {
        begin_piece_sweep(s, VPDSI_SURF_SWEEP);
        return VPDS_OK;
    }
    if (!s->implicit && !s->cum_ready && (e = build_piece_sums(s, ctx)) != VPDS_OK) return e;
    if (s->darts_left < limit) limit = s->darts_left;
    if ((e = vpdsi_marks_reserve(ctx->marks, st, (size_t)limit)) != VPDS_OK) return e;
    while (*done < limit) {
        vpdsi_rng before = *ctx->rng;
        uint32_t tri;
        double uv[2], x[3], r;
        int32_t witness = -1, hit;
        draw_piece_dart(s, ctx, &tri, uv, x);
        if ((e = vpdsi_trimesh_radius(ctx->mesh, ctx->st, tri, uv, x, &r)) != VPDS_OK) {
            *ctx->rng = before;
            return e;
        }
        hit = vpdsi_store_conflict(st, x, r, (int)ctx->rule, scale, callback ? st->sizing.lipschitz : -1.0,
                                   &witness);
        if (hit == -2) {
            *ctx->rng = before;
            return vpdsi_store_lipschitz_broken(st, x, r, witness);
        }
        (*done)++;
        s->darts_left--;
        ctx->stats->darts++;
        if (hit != -1) continue;
        vpdsi_marks_append(ctx->marks, st, ctx->mesh, tri, uv, x, r, s->t);
        ctx->stats->accepted++;
    }
    return VPDS_OK;
}

/* One piece of a sweep: dropped when covered, else its uncovered children (split) or itself
 * into next (reserved by the caller for four). */
static vpds_status sweep_one_piece(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, const vpdsi_piece *p,
                               int split)
{
    double uv[3][2], x[3][3], r_lo, r_hi;
    vpds_status e;
    int q;
    vpdsi_piece_corners(ctx->mesh, s->seed_m[p->tri], p, uv, x);
    if ((e = vpdsi_piece_bounds(ctx->mesh, ctx->st, p->tri, uv, x, &r_lo, &r_hi)) != VPDS_OK) return e;
    if (s->last_cover >= 0 && holds_corners(s, ctx, s->last_cover, x, r_lo)) return VPDS_OK;
    if ((e = piece_near(s, ctx, x, r_hi)) != VPDS_OK) return e;
    if (corners_covered(s, ctx, x, r_lo)) return VPDS_OK;
    if (!split || !splittable(ctx, s, p, r_hi)) {
        vpdsi_piece_array_push(&s->next, p);
        return VPDS_OK;
    }
    s->split_any = 1;
    for (q = 0; q < 4; q++) {
        vpdsi_piece c = vpdsi_piece_child(p, q);
        double cuv[3][2], cx[3][3], c_lo = r_lo, c_hi = r_hi;
        vpdsi_piece_corners(ctx->mesh, s->seed_m[c.tri], &c, cuv, cx);
        /* a child lies in its parent: the parent's bounds hold, vertex radii's exact ones are
         * tighter */
        if (ctx->mesh->vr && (e = vpdsi_piece_bounds(ctx->mesh, ctx->st, c.tri, cuv, cx, &c_lo, &c_hi)) != VPDS_OK)
            return e;
        if (!corners_covered(s, ctx, cx, c_lo)) vpdsi_piece_array_push(&s->next, &c);
        if (c.level + 1u > ctx->stats->levels) ctx->stats->levels = c.level + 1u;
    }
    return VPDS_OK;
}

/* The seed piece at the implicit sweep's cursor: row crow of triangle ctri has 2 (m - row) - 1
 * pieces, up and down in turn. */
static vpdsi_piece seed_cursor_piece(const vpdsi_surface *s)
{
    vpdsi_piece p;
    memset(&p, 0, sizeof p);
    p.tri = (uint32_t)s->ctri;
    p.j = s->crow;
    p.i = s->cpos >> 1;
    p.down = (uint8_t)(s->cpos & 1);
    return p;
}

static void advance_seed_cursor(vpdsi_surface *s)
{
    uint64_t m = s->seed_m[s->ctri];
    if (++s->cpos < 2 * (m - s->crow) - 1) return;
    s->cpos = 0;
    if (++s->crow < m) return;
    s->crow = 0;
    s->ctri++;
}

/* The sweep is over: its pieces become the active ones; the run ends when none is left, or when
 * no piece could split (the precision limit: delta says how far from maximal). */
static void finish_piece_sweep(vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    vpdsi_piece_array tmp = s->cur;
    size_t k;
    int was_filter = s->phase == VPDSI_SURF_FILTER;
    s->cur = s->next;
    s->next = tmp;
    vpdsi_piece_array_clear(&s->next);
    s->pos = 0;
    s->cum_ready = 0;
    s->implicit = 0;
    if (s->cur.n > ctx->stats->peak_active_cells) ctx->stats->peak_active_cells = s->cur.n;
    if (s->cur.n == 0) {
        ctx->stats->delta = 0;
        s->phase = VPDSI_SURF_DONE;
    } else if (!was_filter && !s->split_any && !s->floor_lifted) {
        /* only pieces below the area floor are left: every dart now lands on them, so they may
         * split after all (down to the coordinates' precision) */
        s->floor_lifted = 1;
        begin_piece_darts(s, DARTS_PER_SEED_PIECE, (double)s->cur.n);
    } else if (!was_filter && !s->split_any) {
        double worst = 0;
        for (k = 0; k < s->cur.n; k++) {
            vpdsi_piece p = vpdsi_piece_array_get(&s->cur, k);
            double edge = vpdsi_piece_edge(ctx->mesh, s->seed_m[p.tri], &p);
            if (edge > worst) worst = edge;
        }
        ctx->stats->delta = worst;
        s->phase = VPDSI_SURF_DONE;
    } else {
        begin_piece_darts(s, was_filter ? DARTS_PER_SEED_PIECE : DARTS_PER_PIECE, (double)s->cur.n);
    }
    if (s->phase == VPDSI_SURF_DONE) {
        release_pieces(s, ctx->st->mem);
        vpdsi_store_drop_index(ctx->st); /* the kd-tree catches up when next needed */
    }
}

static vpds_status piece_sweep_step(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, uint64_t limit,
                                    uint64_t *done)
{
    int split = s->phase == VPDSI_SURF_SWEEP;
    uint64_t left = s->implicit ? s->seed_total - s->ipos : s->cur.n - s->pos;
    unsigned level = s->implicit ? 0 : s->cur.max_level;
    vpds_status e;
    if (left < limit) limit = left;
    if ((e = reserve_pieces(s, ctx->st->mem, &s->next, s->next.n + 4 * (size_t)limit, level + 1,
                            ctx->st)) != VPDS_OK)
        return e;
    while (*done < limit) {
        size_t kept = s->next.n;
        vpdsi_piece p = s->implicit ? seed_cursor_piece(s) : vpdsi_piece_array_get(&s->cur, s->pos);
        if ((e = sweep_one_piece(s, ctx, &p, split)) != VPDS_OK) {
            s->next.n = kept;
            return e;
        }
        if (s->implicit) {
            advance_seed_cursor(s);
            s->ipos++;
        } else {
            s->pos++;
        }
        (*done)++;
    }
    if (s->implicit ? s->ipos == s->seed_total : s->pos == s->cur.n) finish_piece_sweep(s, ctx);
    return VPDS_OK;
}

static int surface_progress_stops(const vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    vpds_progress p;
    p.darts = ctx->stats->darts;
    p.samples = ctx->st->n;
    p.active_cells = s->phase == VPDSI_SURF_DONE ? 0 : s->implicit ? s->seed_total : s->cur.n;
    p.level = ctx->stats->levels;
    p.t = s->t;
    return ctx->progress(&p, ctx->progress_user) != 0;
}

vpds_status vpdsi_surface_run(vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    uint64_t work = 0;
    for (;;) {
        uint64_t limit = PIECE_CHUNK, done = 0;
        vpds_status e;
        if (s->phase == VPDSI_SURF_DONE) return VPDS_OK;
        if (ctx->budget && work >= ctx->budget) return VPDS_PAUSED;
        if (ctx->budget && ctx->budget - work < limit) limit = ctx->budget - work;
        switch (s->phase) {
        case VPDSI_SURF_SEED: e = seed_step(s, ctx, limit, &done); break;
        case VPDSI_SURF_DARTS: e = piece_darts_step(s, ctx, limit, &done); break;
        case VPDSI_SURF_FILTER:
        case VPDSI_SURF_SWEEP: e = piece_sweep_step(s, ctx, limit, &done); break;
        default: return VPDS_ERR_STATE;
        }
        work += done;
        if (e != VPDS_OK) return e;
        if (done && ctx->progress && surface_progress_stops(s, ctx))
            return s->phase == VPDSI_SURF_DONE ? VPDS_OK : VPDS_PAUSED;
    }
}
