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
/* a piece smaller than this fraction of a disk's area never splits: darts, which land by
 * area, would not find it (a sliver's pieces keep its shape) */
#define MIN_AREA_FRACTION 9.094947017729282e-13 /* 2^-40 */
#define SEED_COUNT_MAX 4294967296.0             /* 2^32 seed pieces: refused beyond */

void vpdsi_surface_init(vpdsi_surface *s)
{
    memset(s, 0, sizeof *s);
    s->t = 1.0;
}

static void release_pieces(vpdsi_surface *s, vpdsi_mem *m)
{
    vpdsi_mem_free(m, s->cur, s->cap_cur * sizeof *s->cur);
    vpdsi_mem_free(m, s->next, s->cap_next * sizeof *s->next);
    vpdsi_mem_free(m, s->cum, s->cap_cum * sizeof *s->cum);
    vpdsi_mem_free(m, s->near, s->cap_near * sizeof *s->near);
    s->cur = s->next = NULL;
    s->cum = NULL;
    s->near = NULL;
    s->n_cur = s->n_next = s->cap_cur = s->cap_next = s->cap_cum = s->cap_near = s->n_near = 0;
    s->cum_ready = 0;
}

void vpdsi_surface_release(vpdsi_surface *s, vpdsi_mem *m)
{
    release_pieces(s, m);
    vpdsi_mem_free(m, s->face, s->cap_face * sizeof *s->face);
    vpdsi_mem_free(m, s->bary, s->cap_bary * sizeof *s->bary);
    s->face = NULL;
    s->bary = NULL;
    s->cap_face = s->cap_bary = 0;
}

void vpdsi_surface_begin(vpdsi_surface *s, double t)
{
    s->t = t;
    s->phase = VPDSI_SURF_SEED;
    s->pos = 0;
    s->n_cur = s->n_next = 0;
    s->cum_ready = 0;
    s->seed_checked = 0;
}

/* ---- geometry of pieces ---- */

/* The point of live triangle k at lattice coordinates (i, j) of `level`: uv its parameters
 * along the edges v0->v1 and v0->v2 (exact), x its position. */
static void lattice_point(const vpdsi_trimesh *mesh, uint32_t k, unsigned level, uint64_t i,
                          uint64_t j, double *uv, double *x)
{
    const uint32_t *t = mesh->tri + 3 * (size_t)mesh->live[k];
    const double *a = mesh->v + 3 * (size_t)t[0], *b = mesh->v + 3 * (size_t)t[1];
    const double *c = mesh->v + 3 * (size_t)t[2];
    double u = ldexp((double)i, -(int)level), v = ldexp((double)j, -(int)level);
    int q;
    uv[0] = u;
    uv[1] = v;
    for (q = 0; q < 3; q++) x[q] = a[q] + u * (b[q] - a[q]) + v * (c[q] - a[q]);
}

static void piece_corners(const vpdsi_trimesh *mesh, const vpdsi_piece *p, double uv[3][2],
                          double x[3][3])
{
    if (p->down) {
        lattice_point(mesh, p->tri, p->level, p->i + 1, p->j, uv[0], x[0]);
        lattice_point(mesh, p->tri, p->level, p->i, p->j + 1, uv[1], x[1]);
        lattice_point(mesh, p->tri, p->level, p->i + 1, p->j + 1, uv[2], x[2]);
    } else {
        lattice_point(mesh, p->tri, p->level, p->i, p->j, uv[0], x[0]);
        lattice_point(mesh, p->tri, p->level, p->i + 1, p->j, uv[1], x[1]);
        lattice_point(mesh, p->tri, p->level, p->i, p->j + 1, uv[2], x[2]);
    }
}

/* Child q (0..3) of a piece: the midpoint split of Section 6's cells carried to triangles. */
static vpdsi_piece child_of(const vpdsi_piece *p, int q)
{
    static const uint8_t up_di[4] = {0, 1, 0, 0}, up_dj[4] = {0, 0, 1, 0}, up_down[4] = {0, 0, 0, 1};
    static const uint8_t dn_di[4] = {1, 0, 1, 1}, dn_dj[4] = {0, 1, 1, 1}, dn_down[4] = {1, 1, 1, 0};
    vpdsi_piece c = *p;
    c.level = (uint8_t)(p->level + 1);
    c.i = 2 * p->i + (p->down ? dn_di[q] : up_di[q]);
    c.j = 2 * p->j + (p->down ? dn_dj[q] : up_dj[q]);
    c.down = p->down ? dn_down[q] : up_down[q];
    return c;
}

static double piece_area(const vpdsi_trimesh *mesh, const vpdsi_piece *p)
{
    return ldexp(mesh->area[p->tri], -2 * (int)p->level);
}

static double piece_edge(const vpdsi_trimesh *mesh, const vpdsi_piece *p)
{
    return ldexp(mesh->longest[p->tri], -(int)p->level);
}

/* r at a point of live triangle k (parameters uv, position x). */
static vpds_status radius_on(const vpdsi_surface_ctx *ctx, uint32_t k, const double *uv,
                             const double *x, double *r)
{
    const vpdsi_trimesh *mesh = ctx->mesh;
    if (mesh->vr) {
        const uint32_t *t = mesh->tri + 3 * (size_t)mesh->live[k];
        *r = (1 - uv[0] - uv[1]) * mesh->vr[t[0]] + uv[0] * mesh->vr[t[1]] + uv[1] * mesh->vr[t[2]];
        return VPDS_OK;
    }
    return vpdsi_store_radius_at(ctx->st, x, r);
}

/* Bounds of r over a piece: exact at the corners for vertex radii (r is linear there), the
 * constant, or r at the centroid widened by L times the farthest corner. */
static vpds_status piece_bounds(const vpdsi_surface_ctx *ctx, const vpdsi_piece *p,
                                double uv[3][2], double x[3][3], double *r_lo, double *r_hi)
{
    const vpdsi_store *st = ctx->st;
    double r, c[3], cuv[2], h2 = 0;
    int q, k;
    vpds_status e;
    if (ctx->mesh->vr) {
        *r_lo = INFINITY;
        *r_hi = 0;
        for (q = 0; q < 3; q++) {
            if ((e = radius_on(ctx, p->tri, uv[q], x[q], &r)) != VPDS_OK) return e;
            if (r < *r_lo) *r_lo = r;
            if (r > *r_hi) *r_hi = r;
        }
        return VPDS_OK;
    }
    if (st->sizing.kind == VPDSI_SIZING_CONSTANT) {
        *r_lo = *r_hi = st->sizing.radius;
        return VPDS_OK;
    }
    for (k = 0; k < 3; k++) c[k] = (x[0][k] + x[1][k] + x[2][k]) / 3;
    cuv[0] = (uv[0][0] + uv[1][0] + uv[2][0]) / 3;
    cuv[1] = (uv[0][1] + uv[1][1] + uv[2][1]) / 3;
    for (q = 0; q < 3; q++) {
        double d2 = 0;
        for (k = 0; k < 3; k++) d2 += (x[q][k] - c[k]) * (x[q][k] - c[k]);
        if (d2 > h2) h2 = d2;
    }
    if ((e = radius_on(ctx, p->tri, cuv, c, &r)) != VPDS_OK) return e;
    *r_lo = r - st->sizing.lipschitz * sqrt(h2) * (1 + 1e-12);
    *r_hi = r + st->sizing.lipschitz * sqrt(h2) * (1 + 1e-12);
    if (*r_lo < 0) *r_lo = 0;
    return VPDS_OK;
}

/* Whether the piece may split: above the coordinates' precision and the area darts can find. */
static int splittable(const vpdsi_surface_ctx *ctx, const vpdsi_surface *s, const vpdsi_piece *p,
                      double r_hi)
{
    double reach = s->t * ctx->coverage * r_hi;
    return p->level < PIECE_MAX_LEVEL && piece_edge(ctx->mesh, p) >= 2 * ctx->mesh->min_edge &&
           piece_area(ctx->mesh, p) >= MIN_AREA_FRACTION * reach * reach;
}

/* ---- coverage ---- */

/* The samples that may conflict with or cover a point of the piece (corners x, r <= r_hi). */
static vpds_status gather_piece_near(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, double x[3][3],
                               double r_hi)
{
    vpdsi_store *st = ctx->st;
    vpdsi_kd_samples v = vpdsi_store_view(st);
    double lo[3], hi[3];
    int k, q;
    for (k = 0; k < 3; k++) {
        lo[k] = hi[k] = x[0][k];
        for (q = 1; q < 3; q++) {
            if (x[q][k] < lo[k]) lo[k] = x[q][k];
            if (x[q][k] > hi[k]) hi[k] = x[q][k];
        }
    }
    s->n_near = 0;
    if (vpdsi_kd_near_box(&st->tree, &v, lo, hi, r_hi, s->t * ctx->coverage, 0, SIZE_MAX, st->mem,
                          &s->near, &s->n_near, &s->cap_near) < 0) {
        vpdsi_store_error(st, "out of memory for a list of %zu samples near a piece", s->n_near);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

/* Whether one candidate holds the three corners in its disk at r_lo: then the whole piece, the
 * disk being convex and f non-decreasing in r(y) (Table 2's BiX/XiB on a triangle). */
static int corners_covered(const vpdsi_surface *s, const vpdsi_surface_ctx *ctx, double x[3][3],
                           double r_lo)
{
    const vpdsi_store *st = ctx->st;
    double scale = s->t * ctx->coverage;
    size_t n;
    for (n = 0; n < s->n_near; n++) {
        const double *c = st->x + 3 * (size_t)s->near[n];
        double f = scale * vpdsi_rule_f(ctx->rule, st->r[s->near[n]], r_lo), f2 = f * f;
        int q, ok = 1;
        for (q = 0; q < 3 && ok; q++) {
            double d0 = x[q][0] - c[0], d1 = x[q][1] - c[1], d2 = x[q][2] - c[2];
            ok = d0 * d0 + d1 * d1 + d2 * d2 <= f2;
        }
        if (ok) return 1;
    }
    return 0;
}

/* ---- phases ---- */

static vpds_status reserve_pieces(vpdsi_mem *m, vpdsi_piece **p, size_t *cap, size_t need,
                                  vpdsi_store *st)
{
    if (vpdsi_mem_reserve(m, (void **)p, cap, need, sizeof **p)) {
        vpdsi_store_error(st, "out of memory for %zu active pieces", need);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

/* Seed pieces no wider than the smallest covering disk over them: ceil(log2) levels of a
 * triangle at a known r_min; with a callback r_min is unknown and nothing is refused here. */
static vpds_status check_seed_count(vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    const vpdsi_trimesh *mesh = ctx->mesh;
    const vpdsi_store *st = ctx->st;
    double total = 0;
    size_t k;
    if (!mesh->vr && st->sizing.kind != VPDSI_SIZING_CONSTANT) return VPDS_OK;
    for (k = 0; k < mesh->n_live && total <= SEED_COUNT_MAX; k++) {
        const uint32_t *t = mesh->tri + 3 * (size_t)mesh->live[k];
        double r = st->sizing.radius, ratio;
        int q;
        if (mesh->vr)
            for (r = INFINITY, q = 0; q < 3; q++) r = mesh->vr[t[q]] < r ? mesh->vr[t[q]] : r;
        ratio = mesh->longest[k] / (s->t * ctx->coverage * r);
        if (ratio > 1) total += pow(4.0, ceil(log2(ratio)));
        else total += 1;
    }
    if (total > SEED_COUNT_MAX) {
        vpdsi_store_error(ctx->st, "scale t = %g: the mesh needs more than %.0f pieces of the size of "
                          "a disk (the radius is too small for its triangles); the count overflows",
                          s->t, SEED_COUNT_MAX);
        return VPDS_ERR_OVERFLOW;
    }
    s->seed_checked = 1;
    return VPDS_OK;
}

/* Live triangle s->pos split until each piece lies within one disk of its smallest radius,
 * depth first; on failure the triangle leaves nothing. *done: pieces made. */
static vpds_status seed_triangle(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, uint64_t *done)
{
    vpdsi_piece stack[4 * (PIECE_MAX_LEVEL + 2)];
    size_t top = 0, first = s->n_cur;
    vpds_status e = VPDS_OK;
    memset(&stack[0], 0, sizeof stack[0]);
    stack[top++].tri = (uint32_t)s->pos;
    while (top) {
        vpdsi_piece p = stack[--top];
        double uv[3][2], x[3][3], r_lo, r_hi;
        int q;
        piece_corners(ctx->mesh, &p, uv, x);
        if ((e = piece_bounds(ctx, &p, uv, x, &r_lo, &r_hi)) != VPDS_OK) break;
        if (piece_edge(ctx->mesh, &p) > s->t * ctx->coverage * r_lo && splittable(ctx, s, &p, r_hi)) {
            for (q = 3; q >= 0; q--) stack[top++] = child_of(&p, q);
            continue;
        }
        if ((e = reserve_pieces(ctx->st->mem, &s->cur, &s->cap_cur, s->n_cur + 1, ctx->st)) != VPDS_OK)
            break;
        s->cur[s->n_cur++] = p;
        if (p.level + 1u > ctx->stats->levels) ctx->stats->levels = p.level + 1u;
        (*done)++;
    }
    if (e != VPDS_OK) {
        s->n_cur = first;
        return e;
    }
    s->pos++;
    return VPDS_OK;
}

static void begin_darts(vpdsi_surface *s, double per_piece)
{
    double n = ceil(per_piece * (double)s->n_cur);
    s->phase = VPDSI_SURF_DARTS;
    s->darts_left = n < 1 ? 1 : (uint64_t)n;
    s->cum_ready = 0;
}

static vpds_status seed_step(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, uint64_t limit,
                             uint64_t *done)
{
    vpds_status e;
    if (!s->seed_checked && (e = check_seed_count(s, ctx)) != VPDS_OK) return e;
    while (s->pos < ctx->mesh->n_live && *done < limit)
        if ((e = seed_triangle(s, ctx, done)) != VPDS_OK) return e;
    if (s->pos < ctx->mesh->n_live) return VPDS_OK;
    if (s->n_cur > ctx->stats->peak_active_cells) ctx->stats->peak_active_cells = s->n_cur;
    s->pos = 0;
    if (ctx->st->n > 0) {
        s->phase = VPDSI_SURF_FILTER; /* a refinement: the earlier samples cover much already */
        s->split_any = 0;
    } else {
        begin_darts(s, DARTS_PER_SEED_PIECE);
    }
    return VPDS_OK;
}

/* The dart: a piece by area (binary search of the running sums), then a uniform point of it
 * (the unit square folded onto the triangle). */
static void draw_dart(const vpdsi_surface *s, const vpdsi_surface_ctx *ctx, vpdsi_piece *p,
                      double *uv, double *x)
{
    double total = s->cum[s->n_cur - 1], u = vpdsi_rng_unit(ctx->rng) * total, a, b;
    size_t lo = 0, hi = s->n_cur - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (s->cum[mid] > u) hi = mid; else lo = mid + 1;
    }
    *p = s->cur[lo];
    a = vpdsi_rng_unit(ctx->rng);
    b = vpdsi_rng_unit(ctx->rng);
    if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
    }
    if (p->down) {
        a = 1 - a;
        b = 1 - b;
    }
    uv[0] = ldexp((double)p->i + a, -(int)p->level);
    uv[1] = ldexp((double)p->j + b, -(int)p->level);
    {
        const uint32_t *t = ctx->mesh->tri + 3 * (size_t)ctx->mesh->live[p->tri];
        const double *va = ctx->mesh->v + 3 * (size_t)t[0], *vb = ctx->mesh->v + 3 * (size_t)t[1];
        const double *vc = ctx->mesh->v + 3 * (size_t)t[2];
        int q;
        for (q = 0; q < 3; q++) x[q] = va[q] + uv[0] * (vb[q] - va[q]) + uv[1] * (vc[q] - va[q]);
    }
}

static vpds_status reserve_samples(vpdsi_surface *s, vpdsi_store *st, size_t more)
{
    vpds_status e = vpdsi_store_reserve(st, more);
    size_t need = st->n + more;
    if (e != VPDS_OK) return e;
    if (vpdsi_mem_reserve(st->mem, (void **)&s->face, &s->cap_face, need, sizeof *s->face) ||
        vpdsi_mem_reserve(st->mem, (void **)&s->bary, &s->cap_bary, 3 * need, sizeof *s->bary)) {
        vpdsi_store_error(st, "out of memory for %zu samples", need);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

static vpds_status build_sums(vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    double sum = 0;
    size_t k;
    if (vpdsi_mem_reserve(ctx->st->mem, (void **)&s->cum, &s->cap_cum, s->n_cur, sizeof *s->cum)) {
        vpdsi_store_error(ctx->st, "out of memory for the areas of %zu pieces", s->n_cur);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (k = 0; k < s->n_cur; k++) s->cum[k] = sum += piece_area(ctx->mesh, &s->cur[k]);
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
        s->phase = VPDSI_SURF_SWEEP;
        s->pos = 0;
        s->split_any = 0;
        return VPDS_OK;
    }
    if (!s->cum_ready && (e = build_sums(s, ctx)) != VPDS_OK) return e;
    if (s->darts_left < limit) limit = s->darts_left;
    if ((e = reserve_samples(s, st, (size_t)limit)) != VPDS_OK) return e;
    while (*done < limit) {
        vpdsi_rng before = *ctx->rng;
        vpdsi_piece p;
        double uv[2], x[3], r;
        int32_t witness = -1, hit;
        draw_dart(s, ctx, &p, uv, x);
        if ((e = radius_on(ctx, p.tri, uv, x, &r)) != VPDS_OK) {
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
        s->face[st->n] = ctx->mesh->live[p.tri];
        s->bary[3 * st->n] = 1 - uv[0] - uv[1];
        s->bary[3 * st->n + 1] = uv[0];
        s->bary[3 * st->n + 2] = uv[1];
        vpdsi_store_append(st, x, r, s->t, 0);
        ctx->stats->accepted++;
    }
    return VPDS_OK;
}

/* One piece of a sweep: dropped when covered, else its uncovered children (split) or itself
 * into next (reserved by the caller for four). */
static vpds_status sweep_piece(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, const vpdsi_piece *p,
                               int split)
{
    double uv[3][2], x[3][3], r_lo, r_hi;
    vpds_status e;
    int q;
    piece_corners(ctx->mesh, p, uv, x);
    if ((e = piece_bounds(ctx, p, uv, x, &r_lo, &r_hi)) != VPDS_OK) return e;
    if ((e = gather_piece_near(s, ctx, x, r_hi)) != VPDS_OK) return e;
    if (corners_covered(s, ctx, x, r_lo)) return VPDS_OK;
    if (!split || !splittable(ctx, s, p, r_hi)) {
        s->next[s->n_next++] = *p;
        return VPDS_OK;
    }
    s->split_any = 1;
    for (q = 0; q < 4; q++) {
        vpdsi_piece c = child_of(p, q);
        double cuv[3][2], cx[3][3], c_lo = r_lo, c_hi = r_hi;
        piece_corners(ctx->mesh, &c, cuv, cx);
        /* a child lies in its parent: the parent's bounds hold, vertex radii's exact ones are
         * tighter */
        if (ctx->mesh->vr && (e = piece_bounds(ctx, &c, cuv, cx, &c_lo, &c_hi)) != VPDS_OK) return e;
        if (!corners_covered(s, ctx, cx, c_lo)) s->next[s->n_next++] = c;
        if (c.level + 1u > ctx->stats->levels) ctx->stats->levels = c.level + 1u;
    }
    return VPDS_OK;
}

/* The sweep is over: its pieces become the active ones; the run ends when none is left, or when
 * no piece could split (the precision limit: delta says how far from maximal). */
static void finish_piece_sweep(vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    vpdsi_piece *tmp = s->cur;
    size_t cap = s->cap_cur, k;
    int was_filter = s->phase == VPDSI_SURF_FILTER;
    s->cur = s->next;
    s->cap_cur = s->cap_next;
    s->n_cur = s->n_next;
    s->next = tmp;
    s->cap_next = cap;
    s->n_next = 0;
    s->pos = 0;
    s->cum_ready = 0;
    if (s->n_cur > ctx->stats->peak_active_cells) ctx->stats->peak_active_cells = s->n_cur;
    if (s->n_cur == 0) {
        ctx->stats->delta = 0;
        s->phase = VPDSI_SURF_DONE;
    } else if (!was_filter && !s->split_any) {
        double worst = 0;
        for (k = 0; k < s->n_cur; k++)
            if (piece_edge(ctx->mesh, &s->cur[k]) > worst) worst = piece_edge(ctx->mesh, &s->cur[k]);
        ctx->stats->delta = worst;
        s->phase = VPDSI_SURF_DONE;
    } else {
        begin_darts(s, was_filter ? DARTS_PER_SEED_PIECE : DARTS_PER_PIECE);
    }
    if (s->phase == VPDSI_SURF_DONE) release_pieces(s, ctx->st->mem);
}

static vpds_status piece_sweep_step(vpdsi_surface *s, const vpdsi_surface_ctx *ctx, uint64_t limit,
                              uint64_t *done)
{
    int split = s->phase == VPDSI_SURF_SWEEP;
    vpds_status e;
    if (s->n_cur - s->pos < limit) limit = s->n_cur - s->pos;
    if ((e = reserve_pieces(ctx->st->mem, &s->next, &s->cap_next, s->n_next + 4 * (size_t)limit,
                            ctx->st)) != VPDS_OK)
        return e;
    while (*done < limit) {
        size_t kept = s->n_next;
        if ((e = sweep_piece(s, ctx, &s->cur[s->pos], split)) != VPDS_OK) {
            s->n_next = kept;
            return e;
        }
        s->pos++;
        (*done)++;
    }
    if (s->pos == s->n_cur) finish_piece_sweep(s, ctx);
    return VPDS_OK;
}

static int surface_progress_stops(const vpdsi_surface *s, const vpdsi_surface_ctx *ctx)
{
    vpds_progress p;
    p.darts = ctx->stats->darts;
    p.samples = ctx->st->n;
    p.active_cells = s->phase == VPDSI_SURF_DONE ? 0 : s->n_cur;
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
