/* The continuous stream on a surface (surface_stream.h): farthest-point insertion by branch and
 * bound over pieces of the triangles (each triangle one piece at level 0, m = 1). */
#include "surface_stream.h"
#include "rules.h"
#include "surface_gap.h"
#include <math.h>
#include <string.h>

#define STREAM_MAX_LEVEL 52 /* lattice coordinates below 2^52 stay exact */
/* a piece takes its exact gap when h <= this times its distance to the nearest sample: larger
 * pieces gather more samples (at most VPDSI_SURFACE_GAP_MAX_POINTS), smaller ones split more;
 * 0.5, 1, 1.5 and 2: 0.69, 0.38, 0.31 and 0.29 s for bench meshstream 10000, 1.36, 0.89, 0.88
 * and 0.96 s for 20,000 on the golden terrain at r = 0.004 */
#define EXACT_REACH 1.5

void vpdsi_surface_stream_init(vpdsi_surface_stream *ss, uint32_t algorithm_version)
{
    memset(ss, 0, sizeof *ss);
    ss->bisect = algorithm_version >= 7;
}

void vpdsi_surface_stream_release(vpdsi_surface_stream *ss, vpdsi_mem *m)
{
    vpdsi_mem_free(m, ss->heap, ss->cap_heap * sizeof *ss->heap);
    vpdsi_mem_free(m, ss->cand, ss->cap_cand * sizeof *ss->cand);
    memset(ss, 0, sizeof *ss);
}

static void heap_sift_up(vpdsi_surface_heap_entry *h, size_t i)
{
    while (i > 0) {
        size_t parent = (i - 1) / 2;
        vpdsi_surface_heap_entry tmp;
        if (!(h[i].ub > h[parent].ub)) return;
        tmp = h[i];
        h[i] = h[parent];
        h[parent] = tmp;
        i = parent;
    }
}

static void heap_sift_down(vpdsi_surface_heap_entry *h, size_t n, size_t i)
{
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, big = i;
        vpdsi_surface_heap_entry tmp;
        if (l < n && h[l].ub > h[big].ub) big = l;
        if (r < n && h[r].ub > h[big].ub) big = r;
        if (big == i) return;
        tmp = h[i];
        h[i] = h[big];
        h[big] = tmp;
        i = big;
    }
}

/* The piece's corners (positions x), centroid (parameters cuv, position c) and its farthest
 * corner's distance. */
static double piece_centre(const vpdsi_trimesh *mesh, const vpdsi_surface_heap_entry *p,
                           double x[3][3], double *cuv, double *c)
{
    double h2 = 0;
    int q, k;
    for (q = 0; q < 3; q++) vpdsi_trimesh_point(mesh, p->tri, p->uv[q], x[q]);
    cuv[0] = (p->uv[0][0] + p->uv[1][0] + p->uv[2][0]) / 3;
    cuv[1] = (p->uv[0][1] + p->uv[1][1] + p->uv[2][1]) / 3;
    vpdsi_trimesh_point(mesh, p->tri, cuv, c);
    for (q = 0; q < 3; q++) {
        double d2 = 0;
        for (k = 0; k < 3; k++) d2 += (x[q][k] - c[k]) * (x[q][k] - c[k]);
        if (d2 > h2) h2 = d2;
    }
    return sqrt(h2) * (1 + 1e-12);
}

/* An upper bound of g over the piece: for y in it |y - x_i| <= |c - x_i| + h and
 * f(r(x_i), r(y)) >= f(r(x_i), r_lo), f being non-decreasing (vpdsi_kd_min_ratio's slack form). */
static vpds_status piece_upper_bound(const vpdsi_surface_ctx *ctx, const vpdsi_surface_heap_entry *p,
                                     double *ub)
{
    vpdsi_kd_samples v = vpdsi_store_view(ctx->st);
    double uv[3][2], x[3][3], cuv[2], c[3], r_lo, r_hi, h = piece_centre(ctx->mesh, p, x, cuv, c);
    int32_t arg;
    vpds_status e;
    memcpy(uv, p->uv, sizeof uv);
    if ((e = vpdsi_piece_bounds(ctx->mesh, ctx->st, p->tri, uv, x, &r_lo, &r_hi)) != VPDS_OK) return e;
    *ub = vpdsi_kd_min_ratio(&ctx->st->tree, &v, c, h, r_lo, (int)ctx->rule, &arg);
    return VPDS_OK;
}

/* Parameters that rounding took past the triangle's edges (the largest gap often lies on a
 * piece's edge) put back on them, so that no barycentric is negative: v <= fl(1 - u) makes
 * (1 - u) - v >= 0 as the marks compute it. */
static void clamp_to_triangle(double *uv)
{
    if (uv[0] < 0) uv[0] = 0;
    if (uv[1] < 0) uv[1] = 0;
    if (uv[0] > 1) uv[0] = 1;
    if (uv[1] > 1 - uv[0]) uv[1] = 1 - uv[0];
}

/* Whether the stream checks a sizing's declared L at the centres it looks at (a callback or a
 * grid; vertex radii and a constant need no check). */
static int lipschitz_checked(const vpdsi_surface_ctx *ctx)
{
    return !ctx->mesh->vr && ctx->st->sizing.kind != VPDSI_SIZING_CONSTANT;
}

/* Whether pieces take their exact gap (a constant radius, version 7 on). */
static int exact_search(const vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx)
{
    return ss->bisect && !ctx->mesh->vr && ctx->st->sizing.kind == VPDSI_SIZING_CONSTANT;
}

/* A constant radius (exact_search): the largest gap of the piece exactly, into *pt (g, r and
 * where), when the piece is not large beside its nearest sample (h <= EXACT_REACH times its
 * distance): only the samples within that distance + 2h of the centre can be nearest in it, and
 * few are. *done = 0 when the piece is larger or too many samples are near (it splits instead);
 * *bound then bounds g over it (piece_upper_bound's, from the same nearest-sample query). */
static vpds_status piece_exact(vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx,
                               const vpdsi_surface_heap_entry *p, int *done, vpdsi_surface_best *pt,
                               double *bound)
{
    vpdsi_kd_samples v = vpdsi_store_view(ctx->st);
    double x[3][3], cuv[2], c[3], e1[3], e2[3], z[3 * VPDSI_SURFACE_GAP_MAX_POINTS], ab[2], gap2 = INFINITY;
    double r = ctx->st->sizing.radius, h = piece_centre(ctx->mesh, p, x, cuv, c), near;
    int32_t arg;
    size_t i;
    int k;
    *done = 0;
    near = vpdsi_kd_min_ratio(&ctx->st->tree, &v, c, 0, r, (int)ctx->rule, &arg) * r;
    /* the bound piece_upper_bound takes, from the same query, for a piece that splits */
    *bound = (near + h) / r * (1 + 1e-15);
    if (!(h <= EXACT_REACH * near)) return VPDS_OK;
    ss->n_cand = 0;
    if (vpdsi_kd_radius(&ctx->st->tree, &v, c, (near + 2 * h) * (1 + 1e-9), ctx->st->mem, &ss->cand,
                        &ss->n_cand, &ss->cap_cand)) {
        vpdsi_store_error(ctx->st, "out of memory for the stream's search");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    if (ss->n_cand < 1 || ss->n_cand > VPDSI_SURFACE_GAP_MAX_POINTS) return VPDS_OK;
    for (k = 0; k < 3; k++) {
        e1[k] = x[1][k] - x[0][k];
        e2[k] = x[2][k] - x[0][k];
    }
    for (i = 0; i < ss->n_cand; i++)
        for (k = 0; k < 3; k++) z[3 * i + k] = ctx->st->x[3 * (size_t)ss->cand[i] + k] - x[0][k];
    vpdsi_surface_gap_max(e1, e2, z, (int)ss->n_cand, ab);
    for (k = 0; k < 2; k++)
        pt->uv[k] = p->uv[0][k] + ab[0] * (p->uv[1][k] - p->uv[0][k]) + ab[1] * (p->uv[2][k] - p->uv[0][k]);
    clamp_to_triangle(pt->uv);
    vpdsi_trimesh_point(ctx->mesh, p->tri, pt->uv, pt->x);
    /* g where the sample goes: the gap of its own coordinates */
    for (i = 0; i < ss->n_cand; i++) {
        const double *xi = ctx->st->x + 3 * (size_t)ss->cand[i];
        double d2 = 0;
        for (k = 0; k < 3; k++) d2 += (pt->x[k] - xi[k]) * (pt->x[k] - xi[k]);
        if (d2 < gap2) gap2 = d2;
    }
    pt->g = sqrt(gap2) / r;
    pt->r = r;
    pt->tri = p->tri;
    *done = 1;
    return VPDS_OK;
}

/* Room for the heap of every live triangle as one piece. */
static vpds_status reserve_heap(vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx)
{
    if (vpdsi_mem_reserve(ctx->st->mem, (void **)&ss->heap, &ss->cap_heap, ctx->mesh->n_live, sizeof *ss->heap)) {
        vpdsi_store_error(ctx->st, "out of memory for the stream's %zu pieces", ctx->mesh->n_live);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

/* Every live triangle as a piece of the heap with an unknown (infinite) bound: the stream's
 * search starts over the whole surface. */
static void start_heap(vpdsi_surface_stream *ss, const vpdsi_trimesh *mesh)
{
    size_t k;
    for (k = 0; k < mesh->n_live; k++) {
        vpdsi_surface_heap_entry *p = &ss->heap[k];
        memset(p, 0, sizeof *p);
        p->uv[1][0] = p->uv[2][1] = 1; /* corners (0, 0), (1, 0), (0, 1) */
        p->tri = (uint32_t)k;
        p->ub = INFINITY;
    }
    ss->n_heap = mesh->n_live;
    ss->started = 1;
    ss->best.g = -1;
}

/* The first sample, uniform by area over the surface (t = infinity), and the heap started. */
static vpds_status first_surface_sample(vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx,
                                double *x_out, double *t_out)
{
    const vpdsi_trimesh *mesh = ctx->mesh;
    vpdsi_rng before = *ctx->rng;
    double total = 0, u, a, b, uv[2], x[3], r;
    size_t k, pick = 0;
    vpds_status e;
    if ((e = reserve_heap(ss, ctx)) != VPDS_OK) return e;
    if ((e = vpdsi_marks_reserve(ctx->marks, ctx->st, 1)) != VPDS_OK) return e;
    for (k = 0; k < mesh->n_live; k++) total += mesh->area[k];
    u = vpdsi_rng_unit(ctx->rng) * total;
    for (k = 0, total = 0; k < mesh->n_live; k++) {
        total += mesh->area[k];
        pick = k;
        if (total > u) break;
    }
    a = vpdsi_rng_unit(ctx->rng);
    b = vpdsi_rng_unit(ctx->rng);
    if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
    }
    uv[0] = a;
    uv[1] = b;
    vpdsi_trimesh_point(mesh, (uint32_t)pick, uv, x);
    if ((e = vpdsi_trimesh_radius(mesh, ctx->st, (uint32_t)pick, uv, x, &r)) != VPDS_OK) {
        *ctx->rng = before;
        return e;
    }
    start_heap(ss, mesh);
    vpdsi_marks_append(ctx->marks, ctx->st, mesh, (uint32_t)pick, uv, x, r, INFINITY);
    ctx->stats->accepted++;
    memcpy(x_out, x, 3 * sizeof *x);
    *t_out = INFINITY;
    return VPDS_OK;
}


/* g at the piece's centroid (r there exact); a better point than *best replaces it. With a sizing
 * callback the bounds trust the declared L: it is checked against the nearest sample. */
static vpds_status look_at_centre(const vpdsi_surface_ctx *ctx, const vpdsi_surface_heap_entry *p,
                                  vpdsi_surface_best *best)
{
    vpdsi_kd_samples v = vpdsi_store_view(ctx->st);
    double x[3][3], cuv[2], c[3], r, g;
    int32_t arg;
    vpds_status e;
    piece_centre(ctx->mesh, p, x, cuv, c);
    if ((e = vpdsi_trimesh_radius(ctx->mesh, ctx->st, p->tri, cuv, c, &r)) != VPDS_OK) return e;
    g = vpdsi_kd_min_ratio(&ctx->st->tree, &v, c, 0, r, (int)ctx->rule, &arg);
    if (lipschitz_checked(ctx) && arg >= 0) {
        const double *xa = ctx->st->x + 3 * (size_t)arg;
        double d = sqrt((c[0] - xa[0]) * (c[0] - xa[0]) + (c[1] - xa[1]) * (c[1] - xa[1]) +
                        (c[2] - xa[2]) * (c[2] - xa[2]));
        if (fabs(r - ctx->st->r[arg]) > ctx->st->sizing.lipschitz * d * (1 + 1e-9) + 1e-300)
            return vpdsi_store_lipschitz_broken(ctx->st, c, r, arg);
    }
    if (g > best->g) {
        best->g = g;
        best->r = r;
        best->tri = p->tri;
        memcpy(best->uv, cuv, sizeof cuv);
        memcpy(best->x, c, sizeof c);
    }
    return VPDS_OK;
}

static void midpoint(const double *a, const double *b, double *m)
{
    m[0] = (a[0] + b[0]) / 2;
    m[1] = (a[1] + b[1]) / 2;
}

static void set_corners(vpdsi_surface_heap_entry *p, const double *a, const double *b, const double *c)
{
    memcpy(p->uv[0], a, 2 * sizeof *a);
    memcpy(p->uv[1], b, 2 * sizeof *b);
    memcpy(p->uv[2], c, 2 * sizeof *c);
}

/* The four children of the midpoint split, in the order and corner order of vpdsi_piece_child
 * (versions 3-6 give the same points). */
static int split_four(const vpdsi_surface_heap_entry *p, vpdsi_surface_heap_entry *child)
{
    double m01[2], m02[2], m12[2];
    int q;
    midpoint(p->uv[0], p->uv[1], m01);
    midpoint(p->uv[0], p->uv[2], m02);
    midpoint(p->uv[1], p->uv[2], m12);
    for (q = 0; q < 4; q++) child[q] = *p;
    set_corners(&child[0], p->uv[0], m01, m02);
    set_corners(&child[1], m01, p->uv[1], m12);
    set_corners(&child[2], m02, m12, p->uv[2]);
    set_corners(&child[3], m01, m02, m12);
    return 4;
}

/* The longest edge of a piece (in space, not in parameters): its first corner into *first. */
static double longest_edge(const vpdsi_trimesh *mesh, const vpdsi_surface_heap_entry *p, int *first)
{
    double x[3][3], best = -1;
    int q, k;
    for (q = 0; q < 3; q++) vpdsi_trimesh_point(mesh, p->tri, p->uv[q], x[q]);
    for (q = 0; q < 3; q++) {
        const double *a = x[q], *b = x[(q + 1) % 3];
        double d2 = 0;
        for (k = 0; k < 3; k++) d2 += (a[k] - b[k]) * (a[k] - b[k]);
        if (d2 > best) {
            best = d2;
            *first = q;
        }
    }
    return sqrt(best);
}

/* The two halves at the midpoint of the longest edge: a needle is cut across until its pieces
 * are as wide as long, and only then along (the four-way split halves its width each time). */
static int split_two(const vpdsi_trimesh *mesh, const vpdsi_surface_heap_entry *p,
                     vpdsi_surface_heap_entry *child)
{
    double m[2];
    int a, b, c;
    longest_edge(mesh, p, &a);
    b = (a + 1) % 3;
    c = (a + 2) % 3;
    midpoint(p->uv[a], p->uv[b], m);
    child[0] = child[1] = *p;
    set_corners(&child[0], p->uv[a], m, p->uv[c]);
    set_corners(&child[1], m, p->uv[b], p->uv[c]);
    return 2;
}

/* Split the top piece (bound ub) into its children, each with its own bound and its centre
 * looked at; nothing changes on failure. */
static vpds_status split_top(vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx, double ub,
                             vpdsi_surface_best *best)
{
    vpdsi_surface_heap_entry p = ss->heap[0], child[4];
    vpdsi_surface_best keep = *best;
    int q, n;
    vpds_status e;
    if (vpdsi_mem_reserve(ctx->st->mem, (void **)&ss->heap, &ss->cap_heap, ss->n_heap + 3, sizeof *ss->heap)) {
        vpdsi_store_error(ctx->st, "out of memory for the stream's %zu pieces", ss->n_heap + 3);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    n = ss->bisect ? split_two(ctx->mesh, &p, child) : split_four(&p, child);
    for (q = 0; q < n; q++) {
        child[q].level = p.level + 1;
        if ((e = piece_upper_bound(ctx, &child[q], &child[q].ub)) != VPDS_OK) {
            *best = keep;
            return e;
        }
        if (child[q].ub > ub) child[q].ub = ub; /* the child lies in its parent */
        /* from version 7 a centre that cannot beat the best point is not looked at (g there is
         * below the child's bound), except where a sizing callback's L is checked there */
        if (ss->bisect && child[q].ub <= best->g && !lipschitz_checked(ctx)) continue;
        if ((e = look_at_centre(ctx, &child[q], best)) != VPDS_OK) {
            *best = keep;
            return e;
        }
    }
    ss->heap[0] = child[0];
    heap_sift_down(ss->heap, ss->n_heap, 0);
    for (q = 1; q < n; q++) {
        ss->heap[ss->n_heap] = child[q];
        heap_sift_up(ss->heap, ss->n_heap++);
    }
    if (p.level + 1u > ctx->stats->levels) ctx->stats->levels = p.level + 1u;
    return VPDS_OK;
}

/* a + b without rounding (the error of the sum, Knuth's TwoSum, is zero): then (a + b) / 2 is
 * exact and two children tile their parent exactly */
static int exact_sum(double a, double b)
{
    double s = a + b, bb = s - a;
    return (a - (s - bb)) + (b - bb) == 0;
}

/* Pieces stop splitting where their corners would lose exactness or they reach the mesh's
 * smallest edge (52 four-way splits keep lattice coordinates below 2^52). */
static int may_split(const vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx,
                     const vpdsi_surface_heap_entry *p)
{
    if (ss->bisect) {
        int a, b;
        if (p->level >= 4 * STREAM_MAX_LEVEL || longest_edge(ctx->mesh, p, &a) < 2 * ctx->mesh->min_edge)
            return 0;
        b = (a + 1) % 3;
        return exact_sum(p->uv[a][0], p->uv[b][0]) && exact_sum(p->uv[a][1], p->uv[b][1]);
    }
    return p->level < STREAM_MAX_LEVEL &&
           ldexp(ctx->mesh->longest[p->tri], -(int)p->level) >= 2 * ctx->mesh->min_edge;
}

/* Insert *pt at scale t (its g over the coverage, capped by a run's scale). */
static vpds_status emit(const vpdsi_surface_ctx *ctx, vpdsi_surface_best *pt, double t, double *x_out,
                        double *t_out)
{
    vpds_status e;
    if ((e = vpdsi_marks_reserve(ctx->marks, ctx->st, 1)) != VPDS_OK) return e;
    vpdsi_marks_append(ctx->marks, ctx->st, ctx->mesh, pt->tri, pt->uv, pt->x, pt->r, t);
    ctx->stats->accepted++;
    memcpy(x_out, pt->x, sizeof pt->x);
    *t_out = t;
    return VPDS_OK;
}

vpds_status vpdsi_surface_next(vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx,
                               double t_min, double t_max, double *x_out, double *t_out)
{
    vpdsi_surface_best *best = &ss->best, exact_pt;
    int exact_mode = exact_search(ss, ctx);
    vpds_status e;
    /* a run may have filed its samples in another index: the bounds read the kd-tree */
    if ((e = vpdsi_store_sync_tree(ctx->st)) != VPDS_OK) return e;
    if (!ss->started) {
        if (ctx->st->n == 0) return first_surface_sample(ss, ctx, x_out, t_out);
        /* after a run: the search starts from its samples */
        if ((e = reserve_heap(ss, ctx)) != VPDS_OK) return e;
        start_heap(ss, ctx->mesh);
    }
    /* scales never rise: two pieces' exact gaps at one point may differ in the last bits (only
     * round-off: test_mesh checks each sample's gap against its t to 1e-12) */
    if (ss->bisect && ctx->st->n > 0 && ctx->st->t[ctx->st->n - 1] < t_max) t_max = ctx->st->t[ctx->st->n - 1];
    for (;;) {
        double ub = -1, t;
        int exact = 0;
        if (exact_mode && (e = piece_exact(ss, ctx, &ss->heap[0], &exact, &exact_pt, &ub)) != VPDS_OK) return e;
        if (exact) {
            /* its largest gap, below the bound it had if a sample came near since */
            if (exact_pt.g < ss->heap[0].ub * (1 - 1e-12)) {
                ss->heap[0].ub = exact_pt.g;
                heap_sift_down(ss->heap, ss->n_heap, 0);
                continue;
            }
            /* at or above every other piece's bound: the farthest point of the surface */
            t = exact_pt.g / ctx->coverage < t_max ? exact_pt.g / ctx->coverage : t_max;
            if (!(t > t_min)) return VPDS_STREAM_END;
            if ((e = emit(ctx, &exact_pt, t, x_out, t_out)) != VPDS_OK) return e;
            best->g = -1;
            return VPDS_OK;
        }
        if (ub < 0 && (e = piece_upper_bound(ctx, &ss->heap[0], &ub)) != VPDS_OK) return e;
        /* from version 7 the bound kept (a parent's, or taken before) holds too: the smaller is
         * the bound, so scales never rise (a half's own bound can exceed its parent's) */
        if (ss->bisect && ub > ss->heap[0].ub) ub = ss->heap[0].ub;
        if (ub < ss->heap[0].ub) {
            /* a sample came nearer since the bound was taken: it falls back in the heap */
            ss->heap[0].ub = ub;
            heap_sift_down(ss->heap, ss->n_heap, 0);
            continue;
        }
        /* after a run at t_max, maximal there up to its precision: no event above it */
        t = ub / ctx->coverage < t_max ? ub / ctx->coverage : t_max;
        if (!(t > t_min)) return VPDS_STREAM_END;
        /* ub bounds g over the whole surface: a point within the tolerance of it is the next
         * (with the exact search, only where a piece can split no more) */
        if ((e = look_at_centre(ctx, &ss->heap[0], best)) != VPDS_OK) return e;
        if ((!exact_mode && best->g >= ub * (1 - VPDS_STREAM_TOLERANCE)) || !may_split(ss, ctx, &ss->heap[0])) {
            if ((e = emit(ctx, best, t, x_out, t_out)) != VPDS_OK) return e;
            best->g = -1; /* new sample: every g seen is stale */
            return VPDS_OK;
        }
        if ((e = split_top(ss, ctx, ub, best)) != VPDS_OK) return e;
    }
}
