/* Continuous decrease (Section 4.2) by branch-and-bound over cells, in any dimension.
 *
 * The next event is t* = max over the box of g(y) = min_i |y - x_i| / (coverage f(x_i, y)):
 * the set is maximal at every t >= t*. Regions of the box sit in a max-heap keyed by an upper
 * bound of g over them; the top region is searched (a best-first search inside it) until its
 * maximum is known to a relative tolerance, or until it falls below the next key and goes back
 * into the heap. Inserting a sample only lowers g, so stale keys remain upper bounds and every
 * region is re-searched lazily when it reaches the top. The sample inserted at t* covers the
 * maximiser y*: y* itself with one radius (farthest-point insertion), else a point drawn
 * uniformly from those that are free at t* * inhibition and cover y* at t* * coverage. */
#include "stream.h"
#include "gap_search.h"
#include "rules.h"
#include "torus.h"
#include <math.h>
#include <string.h>

#define STREAM_FIRST_TRIES 1000000 /* uniform draws for a first sample inside the domain */
#define STREAM_SEARCH_BUDGET 200000 /* box splits per search before VPDS_ERR_DOMAIN */
#define STREAM_SPLIT 1.0 /* a region splits while its half-diagonal exceeds STREAM_SPLIT * t * coverage * r */
/* Version 3: a search of a region that cannot become the next event stops once its bound lies
 * this far below the best g seen: far enough that it does not return to the top at once */
#define STREAM_STOP_MARGIN 3e-3

void vpdsi_stream_init(vpdsi_stream *sm)
{
    memset(sm, 0, sizeof *sm);
    vpdsi_region_heap_init(&sm->regions, 0);
    vpdsi_voids_init(&sm->voids);
    vpdsi_voids3_init(&sm->voids3);
}

void vpdsi_stream_release(vpdsi_stream *sm, vpdsi_mem *m)
{
    vpdsi_region_heap_release(&sm->regions, m);
    vpdsi_mem_free(m, sm->boxes, sm->cap_boxes * sizeof(double));
    vpdsi_mem_free(m, sm->buf, sm->cap_buf * sizeof(double));
    vpdsi_mem_free(m, sm->kids, sm->cap_kids * sizeof(double));
    vpdsi_mem_free(m, sm->kid_cells, sm->cap_kid_cells * sizeof(uint64_t));
    vpdsi_mem_free(m, sm->cand, sm->cap_cand * sizeof(int32_t));
    vpdsi_mem_free(m, sm->cand_x, sm->cap_cand_x * sizeof(double));
    vpdsi_mem_free(m, sm->lists, sm->cap_lists * sizeof(int32_t));
    vpdsi_mem_free(m, sm->near, sm->cap_near * sizeof(int32_t));
    vpdsi_voids_release(&sm->voids, m);
    vpdsi_voids3_release(&sm->voids3, m);
    vpdsi_stream_init(sm);
}

/* ---- the region heap (region_heap.h): records of (key, level, g at the cached maximiser,
 * coordinates, maximiser) ---- */

static size_t rec_words(const vpdsi_stream *sm) { return 3 + 2 * (size_t)sm->geom.dim; }
#define REC_COORD 3

static double rec_key(const uint64_t *r)
{
    double k;
    memcpy(&k, r, sizeof k);
    return k;
}

/* Swaps two records of w 8-byte words (the search's box heap of doubles). */
static void words_swap(void *a, void *b, size_t w)
{
    unsigned char *p = (unsigned char *)a, *q = (unsigned char *)b;
    size_t i;
    for (i = 0; i < w * sizeof(uint64_t); i += sizeof(uint64_t)) { /* word by word, as memcpy */
        uint64_t x, y;
        memcpy(&x, p + i, sizeof x);
        memcpy(&y, q + i, sizeof y);
        memcpy(p + i, &y, sizeof y);
        memcpy(q + i, &x, sizeof x);
    }
}

/* Push (after a reserve); y NULL: no cached maximiser (gy < 0), its words zero. */
static void heap_push(vpdsi_stream *sm, double key, uint64_t level, const uint64_t *c, double gy,
                      const double *y)
{
    int d = sm->geom.dim;
    uint64_t body[1 + 2 * VPDS_MAX_DIM];
    memcpy(body, &gy, sizeof gy);
    memcpy(body + 1, c, (size_t)d * sizeof(uint64_t));
    if (y) memcpy(body + 1 + d, y, (size_t)d * sizeof(double));
    else memset(body + 1 + d, 0, (size_t)d * sizeof(uint64_t));
    vpdsi_region_heap_push(&sm->regions, key, (unsigned)level, body);
}

/* Remove the top into out (rec_words words). */
static void heap_pop(vpdsi_stream *sm, uint64_t *out)
{
    double key;
    unsigned level;
    vpdsi_region_heap_pop(&sm->regions, &key, &level, out + 2);
    memcpy(out, &key, sizeof key);
    out[1] = level;
}

/* The top record into out, the heap unchanged. */
static void heap_top(const vpdsi_stream *sm, uint64_t *out)
{
    double key = vpdsi_region_heap_key(&sm->regions, 0);
    memcpy(out, &key, sizeof key);
    out[1] = vpdsi_region_heap_top_level(&sm->regions);
    memcpy(out + 2, vpdsi_region_heap_top(&sm->regions), (rec_words(sm) - 2) * sizeof(uint64_t));
}

static int heap_reserve(vpdsi_stream *sm, vpdsi_mem *mem, size_t more)
{
    return vpdsi_region_heap_reserve(&sm->regions, mem, more);
}

/* Box of a region as centre and half sides; the last region of an axis ends at the face. */
static void region_box(const vpdsi_stream *sm, unsigned level, const uint64_t *c, double *centre,
                       double *half)
{
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    int k;
    vpdsi_lattice_box(&sm->geom, level, c, lo, hi);
    for (k = 0; k < sm->geom.dim; k++) {
        centre[k] = 0.5 * (lo[k] + hi[k]);
        half[k] = 0.5 * (hi[k] - lo[k]);
    }
}

static vpds_status build_regions(vpdsi_stream *sm, const vpdsi_ctx *ctx)
{
    const vpdsi_problem *pb = ctx->pb;
    int d = pb->dim, k;
    double side = INFINITY;
    uint64_t total = 1, i, c[VPDS_MAX_DIM];
    sm->geom.dim = d;
    memcpy(sm->geom.lo, pb->lo, sizeof sm->geom.lo);
    memcpy(sm->geom.hi, pb->hi, sizeof sm->geom.hi);
    for (k = 0; k < d; k++)
        if (pb->hi[k] - pb->lo[k] < side) side = pb->hi[k] - pb->lo[k];
    for (k = 0; k < d; k++) {
        double cells = ceil((pb->hi[k] - pb->lo[k]) / side * (1 - 1e-12));
        if (cells > 64) cells = 64; /* long boxes: start coarser, regions split on demand */
        sm->geom.n0[k] = cells < 1 ? 1 : (uint64_t)cells;
        sm->geom.side0[k] = (pb->hi[k] - pb->lo[k]) / (double)sm->geom.n0[k];
        total *= sm->geom.n0[k];
    }
    /* coordinates of the finest regions must fit in 64-bit integers, and stay well above
     * the precision of doubles */
    sm->max_level = 40;
    for (k = 0; k < d; k++) {
        unsigned cap = 62 - vpdsi_bit_length(sm->geom.n0[k]);
        if (cap < sm->max_level) sm->max_level = cap;
    }
    sm->regions.words = rec_words(sm) - 2;
    if (heap_reserve(sm, ctx->mem, (size_t)total)) {
        vpdsi_store_error(ctx->st, "out of memory for %llu stream regions", (unsigned long long)total);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (i = 0; i < total; i++) {
        uint64_t rest = i;
        for (k = 0; k < d; k++) {
            c[k] = rest % sm->geom.n0[k];
            rest /= sm->geom.n0[k];
        }
        heap_push(sm, INFINITY, 0, c, -1.0, NULL);
    }
    sm->active = 1;
    return VPDS_OK;
}

/* ---- the search inside one region ---- */

/* Room for the 2^d children of one split (split_box, split_if_coarse): centres, g, bounds and
 * where each g was found. */
static int reserve_kids(vpdsi_stream *sm, vpdsi_mem *m)
{
    size_t d = (size_t)sm->geom.dim, children = (size_t)1 << d;
    return vpdsi_mem_reserve(m, (void **)&sm->kids, &sm->cap_kids, children * (2 * d + 2),
                             sizeof(double)) ||
           vpdsi_mem_reserve(m, (void **)&sm->kid_cells, &sm->cap_kid_cells, children * d,
                             sizeof(uint64_t));
}

/* The reserved room of one split: its children's centres (2^d * d), g and bounds (2^d each),
 * and the points g was found at (2^d * d). */
static void kid_arrays(const vpdsi_stream *sm, double **centres, double **g, double **ub, double **at)
{
    size_t children = (size_t)1 << sm->geom.dim;
    *centres = sm->kids;
    *g = sm->kids + children * (size_t)sm->geom.dim;
    *ub = *g + children;
    *at = *ub + children;
}

/* The stream's relative tolerance (vpds.h): looser with a domain. */
static double stream_tolerance(const vpdsi_ctx *ctx)
{
    return ctx->dom->fn ? VPDS_STREAM_DOMAIN_TOLERANCE : VPDS_STREAM_TOLERANCE;
}

/* Version 8: one split's samples that may be the weighted nearest at a point of the box its
 * n centres (each +- half) span, for r within L * |half| of r at the centres (sm->buf), so that
 * the split's children filter them for their own children: from the parent's list (list->count
 * >= 0) or one query of the tree, instead of one query per centre. Appended to sm->near; *list
 * then names them. */
typedef struct {
    long from, count; /* in sm->near; count < 0: none */
} near_list;

static vpds_status near_centres(vpdsi_stream *sm, const vpdsi_ctx *ctx, const double *centres,
                                size_t n, const double *half, near_list *list)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    int d = pb->dim, k;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], r_lo = INFINITY, r_hi = 0, h = 0;
    vpdsi_kd_samples v = vpdsi_store_view(st);
    size_t j, got = sm->n_near, need;
    for (k = 0; k < d; k++) {
        lo[k] = hi[k] = centres[k];
        h += half[k] * half[k];
    }
    for (j = 0; j < n; j++) {
        for (k = 0; k < d; k++) {
            double c = centres[j * (size_t)d + (size_t)k];
            if (c < lo[k]) lo[k] = c;
            if (c > hi[k]) hi[k] = c;
        }
        if (sm->buf[j] < r_lo) r_lo = sm->buf[j];
        if (sm->buf[j] > r_hi) r_hi = sm->buf[j];
    }
    for (k = 0; k < d; k++) {
        lo[k] -= half[k];
        hi[k] += half[k];
    }
    r_lo -= st->sizing.lipschitz * sqrt(h);
    r_hi += st->sizing.lipschitz * sqrt(h);
    if (list->count < 0) {
        if (vpdsi_kd_ratio_candidates(&st->tree, &v, lo, hi, r_lo, r_hi, (int)pb->rule, ctx->mem,
                                      &sm->near, &got, &sm->cap_near))
            goto oom;
    } else {
        need = sm->n_near + (size_t)list->count;
        if (vpdsi_mem_reserve(ctx->mem, (void **)&sm->near, &sm->cap_near, need, sizeof(int32_t)))
            goto oom;
        got += vpdsi_kd_list_ratio_candidates(&st->tree, &v, sm->near + list->from,
                                              (size_t)list->count, lo, hi, r_lo, r_hi,
                                              (int)pb->rule, sm->near + sm->n_near);
    }
    list->from = (long)sm->n_near;
    list->count = (long)(got - sm->n_near);
    sm->n_near = got;
    return VPDS_OK;
oom:
    vpdsi_store_error(st, "out of memory in the stream's search");
    return VPDS_ERR_OUT_OF_MEMORY;
}

/* Version 13, up to this many dimensions: a box whose centre lies outside the domain is also
 * tried at its corners (2^d of them). A domain that meets a box only along the box's faces or
 * edges (a boundary on a plane the search splits at: x <= 0.5, an axis-aligned square, a mask of
 * 2^k cells) held no centre of the boxes along it, at any depth: the search found no point there,
 * its bound never fell, and it gave up with VPDS_ERR_DOMAIN. */
#define STREAM_CORNER_DIM 4

/* g at the corners of the box (centre c, half sides) that lie in the domain, the largest into
 * *g and its corner into at when it beats *g (the domain's closed: sdf <= 0 is inside). */
static vpds_status inside_corners(const vpdsi_ctx *ctx, const double *c, const double *half,
                                  const int32_t *list, long count, double *g, double *at)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    vpdsi_kd_samples v = vpdsi_store_view(st);
    int d = pb->dim, k;
    unsigned b;
    for (b = 0; b < 1u << d; b++) {
        double y[VPDS_MAX_DIM], phi, ry = st->sizing.radius, q;
        int32_t arg;
        vpds_status e;
        for (k = 0; k < d; k++) y[k] = (b >> k) & 1u ? c[k] + half[k] : c[k] - half[k];
        if ((e = vpdsi_domain_at(ctx->dom, st, y, &phi)) != VPDS_OK) return e;
        if (phi > 0) continue;
        if (st->sizing.kind != VPDSI_SIZING_CONSTANT && (e = vpdsi_store_radius_at(st, y, &ry)) != VPDS_OK)
            return e;
        q = count >= 0 ? vpdsi_kd_list_min_ratio(&st->tree, &v, list, (size_t)count, y, 0.0, ry, (int)pb->rule, &arg)
                       : vpdsi_kd_min_ratio(&st->tree, &v, y, 0.0, ry, (int)pb->rule, &arg);
        if (q / pb->coverage > *g) {
            *g = q / pb->coverage;
            memcpy(at, y, (size_t)d * sizeof(double));
        }
    }
    return VPDS_OK;
}

/* Exact g at each of n centres (and argmin), and an upper bound of g over the box of half
 * sides half around each: (|c - x*| + h) / f(r(x*), r(c) - L h), x* the argmin at c. list
 * (version 8, or NULL): in, the samples that may be nearest in the enclosing box (count < 0:
 * read the tree), out, those of these boxes (near_centres). at (or NULL): where each g was
 * found, the centre or (version 13) a corner in the domain when the centre is not. */
static vpds_status eval_boxes(vpdsi_stream *sm, const vpdsi_ctx *ctx, const double *centres,
                              size_t n, const double *half, near_list *list, double *g, double *ub,
                              double *at)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    int d = pb->dim, k;
    int need_r = vpdsi_rule_uses_y(pb->rule) && st->sizing.kind != VPDSI_SIZING_CONSTANT;
    double h = 0, L = st->sizing.lipschitz;
    vpdsi_kd_samples v = vpdsi_store_view(st);
    vpds_status e;
    size_t j;
    for (k = 0; k < d; k++) h += half[k] * half[k];
    h = sqrt(h);
    if (vpdsi_mem_reserve(ctx->mem, (void **)&sm->buf, &sm->cap_buf, n, sizeof(double))) {
        vpdsi_store_error(st, "out of memory in the stream's search");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    if (need_r) {
        if ((e = vpdsi_store_radii(st, centres, n, sm->buf)) != VPDS_OK)
            return e;
    } else {
        for (j = 0; j < n; j++) sm->buf[j] = st->sizing.radius;
    }
    if (list && st->tree.n_nodes > 0 && (e = near_centres(sm, ctx, centres, n, half, list)) != VPDS_OK)
        return e;
    for (j = 0; j < n; j++) {
        const double *c = centres + j * (size_t)d;
        double rc = sm->buf[j], r_lo = rc - L * h, phi = 0;
        int32_t arg;
        double q;
        if (ctx->dom->fn) {
            /* a box outside the domain holds no candidate; a centre outside is none itself */
            if ((e = vpdsi_domain_at(ctx->dom, st, c, &phi)) != VPDS_OK) return e;
            if (phi > h) {
                g[j] = ub[j] = -1;
                continue;
            }
        }
        q = list && list->count >= 0
                ? vpdsi_kd_list_min_ratio(&st->tree, &v, sm->near + list->from, (size_t)list->count,
                                          c, 0.0, rc, (int)pb->rule, &arg)
                : vpdsi_kd_min_ratio(&st->tree, &v, c, 0.0, rc, (int)pb->rule, &arg);
        g[j] = phi > 0 ? -1 : q / pb->coverage;
        if (at) {
            memcpy(at + j * (size_t)d, c, (size_t)d * sizeof(double));
            if (phi > 0 && pb->algorithm >= 13 && d <= STREAM_CORNER_DIM &&
                (e = inside_corners(ctx, c, half, list && list->count >= 0 ? sm->near + list->from : NULL,
                                    list ? list->count : -1, &g[j], at + j * (size_t)d)) != VPDS_OK)
                return e;
        }
        if (arg < 0) {
            ub[j] = INFINITY;
            continue;
        }
        if (!(r_lo > 0)) r_lo = 0;
        {
            /* the farthest point of the box from x* (nearest image), tighter than |c - x*| + h */
            const double *xa = st->x + (size_t)arg * (size_t)d;
            double far2 = 0, f = vpdsi_rule_f(pb->rule, st->r[arg], r_lo);
            for (k = 0; k < d; k++) {
                double e = vpdsi_axis_far(xa[k], c[k] - half[k], c[k] + half[k], pb->period[k]);
                far2 += e * e;
            }
            ub[j] = f > 0 ? sqrt(far2) / (f * pb->coverage) : INFINITY;
        }
    }
    return VPDS_OK;
}

/* The state of one region's search: the best point so far and the bounds left behind. */
typedef struct {
    double best, extra;  /* g at y; the largest bound of boxes no longer searched */
    double *y;
    double tol;
    int heap;            /* version 5: the open boxes form a max-heap by bound */
    int lists;           /* version 8: each split reads the list of its parent (near_list) */
} region_search;

/* An open box: its bound, centre, half sides, and (version 8) the split's list it reads
 * (near_list: from, count). */
#define BOX_WORDS(d) (3 + 2 * (size_t)(d))
#define NEAR_POOL_MAX ((size_t)1 << 18) /* 1 MB of lists per search */

/* Version 5's open boxes: a max-heap by bound (records of BOX_WORDS doubles, the bound first).
 * Versions 1-4 scan a list for the first largest bound: the same boxes are split, in another
 * order where bounds tie; a flat maximum leaves tens of thousands open, and the scan of each
 * split was most of such a search's time. */
static void box_sift_up(vpdsi_stream *sm, size_t i)
{
    size_t w = BOX_WORDS(sm->geom.dim);
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!(sm->boxes[p * w] < sm->boxes[i * w])) break;
        words_swap(sm->boxes + p * w, sm->boxes + i * w, w);
        i = p;
    }
}

static void box_sift_down(vpdsi_stream *sm, size_t i)
{
    size_t w = BOX_WORDS(sm->geom.dim), n = sm->n_boxes;
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, m = i;
        if (l < n && sm->boxes[l * w] > sm->boxes[m * w]) m = l;
        if (r < n && sm->boxes[r * w] > sm->boxes[m * w]) m = r;
        if (m == i) return;
        words_swap(sm->boxes + m * w, sm->boxes + i * w, w);
        i = m;
    }
}

/* Split the open box (centre cb, half sides hb, already halved) into its 2^d children: each
 * may improve the best point; those that may still beat it by more than the tolerance stay
 * open, the others leave only their bound. */
static vpds_status split_box(vpdsi_stream *sm, const vpdsi_ctx *ctx, region_search *q,
                             const double *cb, const double *hb, const double *parent_list)
{
    int d = sm->geom.dim, k;
    size_t w = BOX_WORDS(d), children = (size_t)1 << d, j;
    double *cs, *gs, *ubs, *ats;
    near_list list;
    int use;
    vpds_status e;
    kid_arrays(sm, &cs, &gs, &ubs, &ats);
    for (j = 0; j < children; j++)
        for (k = 0; k < d; k++)
            cs[j * (size_t)d + (size_t)k] = cb[k] + ((j >> k) & 1u ? hb[k] : -hb[k]);
    list.from = (long)parent_list[0];
    list.count = (long)parent_list[1];
    /* a search that splits without end (a flat maximum) reads the tree once the lists hold
     * NEAR_POOL_MAX entries, so that its memory stays what it was without them */
    use = q->lists && sm->n_near < NEAR_POOL_MAX;
    if ((e = eval_boxes(sm, ctx, cs, children, hb, use ? &list : NULL, gs, ubs, ats)) != VPDS_OK)
        return e;
    if (vpdsi_mem_reserve(ctx->mem, (void **)&sm->boxes, &sm->cap_boxes,
                          (sm->n_boxes + children) * w, sizeof(double))) {
        vpdsi_store_error(ctx->st, "out of memory in the stream's search");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (j = 0; j < children; j++) {
        if (gs[j] > q->best) {
            q->best = gs[j];
            memcpy(q->y, ats + j * (size_t)d, (size_t)d * sizeof(double));
        }
    }
    for (j = 0; j < children; j++) {
        double *r;
        if (ubs[j] < 0) continue; /* outside the domain */
        if (ubs[j] <= q->best * (1 + q->tol)) {
            /* cannot beat the best by more than the tolerance: keep only its bound */
            if (ubs[j] > q->extra) q->extra = ubs[j];
            continue;
        }
        r = sm->boxes + sm->n_boxes++ * w;
        r[0] = ubs[j];
        memcpy(r + 1, cs + j * (size_t)d, (size_t)d * sizeof(double));
        memcpy(r + 1 + d, hb, (size_t)d * sizeof(double));
        r[1 + 2 * d] = use ? (double)list.from : 0;
        r[2 + 2 * d] = use ? (double)list.count : -1;
        if (q->heap) box_sift_up(sm, sm->n_boxes - 1);
    }
    return VPDS_OK;
}

/* The open box of the largest bound: the heap's top, or (versions 1-4) the first of a scan. */
static size_t best_box(const vpdsi_stream *sm, int heap, double *top)
{
    size_t w = BOX_WORDS(sm->geom.dim), j, at = 0;
    *top = -1;
    if (heap) {
        if (sm->n_boxes > 0) *top = sm->boxes[0];
        return 0;
    }
    for (j = 0; j < sm->n_boxes; j++)
        if (sm->boxes[j * w] > *top) {
            *top = sm->boxes[j * w];
            at = j;
        }
    return at;
}

/* Largest coordinate magnitude or extent of the box: the scale of the doubles' precision. */
static double box_magnitude(const vpdsi_problem *pb)
{
    double mag = 0;
    int k;
    for (k = 0; k < pb->dim; k++) {
        double m = fabs(pb->lo[k]) > fabs(pb->hi[k]) ? fabs(pb->lo[k]) : fabs(pb->hi[k]);
        if (pb->hi[k] - pb->lo[k] > m) m = pb->hi[k] - pb->lo[k];
        if (m > mag) mag = m;
    }
    return mag;
}

static vpds_status search_diverged(const vpdsi_ctx *ctx, const double *centre)
{
    /* a domain whose boundary the 1-Lipschitz bound cannot resolve (a sliver the box centres
     * miss) would otherwise keep the search going; without a domain only a search already at
     * the domain's tolerance gets here (never seen) */
    char pc[256];
    vpdsi_format_point(pc, sizeof pc, centre, ctx->pb->dim);
    vpdsi_store_error(ctx->st, "vpds_next: the search for the farthest point near (%s) did not "
                      "converge in %d box splits (a domain too thin for its signed distance to "
                      "resolve?)", pc, STREAM_SEARCH_BUDGET);
    return VPDS_ERR_DOMAIN;
}

/* ---- version 5: the exact maximum of g over a region, with one radius ---- */

#define EXACT_ROUNDING 1e-12 /* the bound's margin over the maximum found: its round-off */

/* Whether a region's maximum of g can be found exactly: with a constant radius g is the
 * distance to the nearest sample over coverage * r, and the largest gap of a box among the few
 * samples that can be nearest in it is a vertex of their bisectors (gap.c, gap_search.c). */
static int exact_applies(const vpdsi_ctx *ctx)
{
    int top = ctx->pb->algorithm >= 9 ? VPDSI_GAP_MAX_DIM : VPDSI_GAP_V5_MAX_DIM;
    return ctx->pb->algorithm >= 5 && ctx->st->sizing.kind == VPDSI_SIZING_CONSTANT &&
           !ctx->dom->fn && ctx->pb->dim <= top;
}

#define EXACT_MAX_IMAGES 4096 /* candidate images one region takes; past it, the search */

/* The images of sample x within R of the centre along every axis: on each axis `count` shifts
 * by the period from `first` (one on an open axis, several when a periodic axis is short);
 * their number, or 0 when it passes `room`. */
static size_t image_range(const vpdsi_problem *pb, const double *x, const double *centre, double R,
                          size_t room, long *first, long *count)
{
    size_t total = 1;
    int k;
    for (k = 0; k < pb->dim; k++) {
        double P = pb->period[k];
        first[k] = 0;
        count[k] = 1;
        if (P > 0) {
            /* counted in doubles first: a reach of many periods must not overflow a long */
            double lo_m = ceil((centre[k] - R - x[k]) / P), hi_m = floor((centre[k] + R - x[k]) / P);
            if (!(hi_m - lo_m + 1 <= (double)room) || !(fabs(lo_m) < 1e15)) return 0;
            first[k] = (long)lo_m;
            count[k] = (long)(hi_m - lo_m) + 1;
            if (count[k] < 1) count[k] = 1; /* round-off: the nearest image stays */
        }
        if ((double)total * (double)count[k] > (double)room) return 0;
        total *= (size_t)count[k];
    }
    return total;
}

/* Those images (image_range), d apart. */
static void write_images(int d, const double *period, const double *x, const long *first,
                         const long *count, size_t total, double *out)
{
    long m[VPDS_MAX_DIM] = {0};
    size_t i;
    int k;
    for (i = 0; i < total; i++) {
        for (k = 0; k < d; k++) out[i * (size_t)d + k] = x[k] + period[k] * (double)(first[k] + m[k]);
        for (k = 0; k < d && ++m[k] == count[k]; k++) m[k] = 0;
    }
}

/* The region's candidates: the images of every sample that may be nearest somewhere in it (within
 * the region's key, else the nearest one's farthest corner; Euclidean distance to them is then
 * the torus distance); *usable = 0 when there are too many, or a sample's radius (a fixed
 * point's) is not the sizing's. */
static vpds_status gather_exact(vpdsi_stream *sm, const vpdsi_ctx *ctx, const double *centre,
                                const double *half, double key, int *usable, size_t *n_images)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    vpdsi_kd_samples v = vpdsi_store_view(st);
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], h2 = 0, R;
    int d = pb->dim, k;
    size_t i, n = 0;
    *usable = 0;
    /* a fixed point of a larger radius may be nearest in the rule's distance from afar */
    if (st->tree.n_nodes == 0 || st->tree.nodes[0].rmax > st->sizing.radius) return VPDS_OK;
    for (k = 0; k < d; k++) {
        lo[k] = centre[k] - half[k];
        hi[k] = centre[k] + half[k];
        h2 += half[k] * half[k];
    }
    if (isfinite(key)) {
        /* the key bounds g over the region (samples only lower g): no point of it is farther
         * than key * coverage * r from its nearest sample */
        R = key * pb->coverage * st->sizing.radius;
    } else {
        int32_t arg;
        vpdsi_kd_min_ratio(&st->tree, &v, centre, 0.0, st->sizing.radius, (int)pb->rule, &arg);
        if (arg < 0) return VPDS_OK;
        R = sqrt(vpdsi_box_maxdist2(&st->tree, st->x + (size_t)arg * d, lo, hi));
    }
    R = (R + sqrt(h2)) * (1 + 1e-9);
    sm->n_cand = 0;
    if (vpdsi_kd_radius(&st->tree, &v, centre, R, ctx->mem, &sm->cand, &sm->n_cand, &sm->cap_cand))
        goto oom;
    for (i = 0; i < sm->n_cand; i++) {
        const double *x = st->x + (size_t)sm->cand[i] * d;
        long first[VPDS_MAX_DIM], count[VPDS_MAX_DIM];
        size_t got;
        if (st->r[sm->cand[i]] != st->sizing.radius) return VPDS_OK;
        got = image_range(pb, x, centre, R, EXACT_MAX_IMAGES - n, first, count);
        if (got == 0) return VPDS_OK;
        if (vpdsi_mem_reserve(ctx->mem, (void **)&sm->cand_x, &sm->cap_cand_x, (n + got) * (size_t)d,
                              sizeof(double)))
            goto oom;
        write_images(d, pb->period, x, first, count, got, sm->cand_x + n * (size_t)d);
        n += got;
    }
    if (vpdsi_mem_reserve(ctx->mem, (void **)&sm->lists, &sm->cap_lists, VPDSI_GAP_SCRATCH(n),
                          sizeof(int32_t)))
        goto oom;
    *n_images = n;
    *usable = 1;
    return VPDS_OK;
oom:
    vpdsi_store_error(st, "out of memory in the stream's search");
    return VPDS_ERR_OUT_OF_MEMORY;
}

/* The maximum of g over the region exactly (*solved = 1): *bound just above it, y where it is
 * and *gy = g(y); or *solved = 0 for the best-first search. key: the region's key, an upper
 * bound of g there. */
static vpds_status exact_region(vpdsi_stream *sm, const vpdsi_ctx *ctx, const double *centre,
                                const double *half, double key, double *bound, double *y,
                                double *gy, int *solved)
{
    const vpdsi_problem *pb = ctx->pb;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], best;
    int d = pb->dim, k, usable;
    size_t n_images = 0;
    vpds_status e;
    *solved = 0;
    if ((e = gather_exact(sm, ctx, centre, half, key, &usable, &n_images)) != VPDS_OK || !usable)
        return e;
    for (k = 0; k < d; k++) {
        lo[k] = centre[k] - half[k];
        hi[k] = centre[k] + half[k];
    }
    if (!vpdsi_gap_search(d, lo, hi, sm->cand_x, (int)n_images, sm->lists, &best, y)) return VPDS_OK;
    {
        /* g at y as rounded, from the candidates (the nearest sample is one of them): far from
         * the origin it is below the search's own figure by the coordinates' round-off, which
         * vpds_stats.stream_slack then shows */
        double scale = pb->coverage * ctx->st->sizing.radius, near2 = INFINITY;
        size_t i;
        for (i = 0; i < n_images; i++) {
            double e2 = 0;
            for (k = 0; k < d; k++) {
                double e = y[k] - sm->cand_x[i * (size_t)d + k];
                e2 += e * e;
            }
            if (e2 < near2) near2 = e2;
        }
        *gy = sqrt(near2) / scale;
        *bound = sqrt(best) / scale;
        if (*gy > *bound) *bound = *gy;
        *bound *= 1 + EXACT_ROUNDING;
    }
    vpdsi_store_wrap(ctx->st, y);
    *solved = 1;
    return VPDS_OK;
}

/* Best-first search for the maximum of g over one region, to the tolerance: *bound is an upper
 * bound of g over the region and g(y) = *gy >= *bound / (1 + tolerance). With a domain the
 * tolerance is VPDS_STREAM_DOMAIN_TOLERANCE: on a curved boundary g is often maximal where it
 * varies quadratically along the boundary, so a tolerance eps costs about 1/eps boxes there. */
static vpds_status search_region(vpdsi_stream *sm, const vpdsi_ctx *ctx, const double *centre,
                                 const double *half, double next, double *lb, double *bound,
                                 double *y, double *gy)
{
    int d = ctx->pb->dim, k;
    size_t w = BOX_WORDS(d);
    double g1, ub1, mag = box_magnitude(ctx->pb);
    region_search q;
    long splits, budget = STREAM_SEARCH_BUDGET;
    vpds_status e;
    q.tol = stream_tolerance(ctx);
    q.heap = ctx->pb->algorithm >= 5;
    q.lists = ctx->pb->algorithm >= 8;
    sm->n_near = 0;
    q.extra = -1;
    q.y = y;
    if ((e = eval_boxes(sm, ctx, centre, 1, half, NULL, &g1, &ub1, y)) != VPDS_OK) return e;
    q.best = g1;
    sm->n_boxes = 0;
    if (vpdsi_mem_reserve(ctx->mem, (void **)&sm->boxes, &sm->cap_boxes, w, sizeof(double))) {
        vpdsi_store_error(ctx->st, "out of memory in the stream's search");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    sm->boxes[0] = ub1;
    memcpy(sm->boxes + 1, centre, (size_t)d * sizeof(double));
    memcpy(sm->boxes + 1 + d, half, (size_t)d * sizeof(double));
    sm->boxes[1 + 2 * d] = 0;
    sm->boxes[2 + 2 * d] = -1; /* no list yet: its split reads the tree */
    sm->n_boxes = 1;
    for (splits = 0;; splits++) {
        double top, hb[VPDS_MAX_DIM], cb[VPDS_MAX_DIM], hmax = 0, U, list[2];
        size_t at;
        if (splits == budget) {
            /* A maximum flat over a wide area (rule current on a radius ramping to zero: the
             * distance and the radius grow together) costs about 1/eps boxes: the search goes
             * on at the domain's tolerance (recorded in vpds_stats.stream_slack) */
            if (ctx->dom->fn || q.tol >= VPDS_STREAM_DOMAIN_TOLERANCE) return search_diverged(ctx, centre);
            q.tol = VPDS_STREAM_DOMAIN_TOLERANCE;
            budget = STREAM_SEARCH_BUDGET;
            splits = 0;
        }
        at = best_box(sm, q.heap, &top);
        U = top;
        if (q.best > U) U = q.best;
        if (q.extra > U) U = q.extra;
        if (q.best < 0 && (U < 0 || sm->n_boxes == 0)) {
            /* no point of the domain in the region (or none found above the precision) */
            *bound = 0;
            *gy = -1;
            return VPDS_OK;
        }
        if (lb && q.best > *lb) *lb = q.best;
        /* resolved to the tolerance; or (version 3) below the next region's key and below the
         * best g seen since the last sample by the margin: the region goes back into the heap
         * with its bound, searched again only if it returns to the top */
        if (U <= q.best * (1 + q.tol) || sm->n_boxes == 0 || (lb && U < next && U <= *lb * (1 - STREAM_STOP_MARGIN))) {
            *bound = U;
            *gy = q.best;
            return VPDS_OK;
        }
        /* take the best box out, split it in 2^d */
        memcpy(cb, sm->boxes + at * w + 1, (size_t)d * sizeof(double));
        memcpy(hb, sm->boxes + at * w + 1 + d, (size_t)d * sizeof(double));
        memcpy(list, sm->boxes + at * w + 1 + 2 * d, 2 * sizeof(double));
        memmove(sm->boxes + at * w, sm->boxes + (sm->n_boxes - 1) * w, w * sizeof(double));
        sm->n_boxes--;
        if (q.heap) box_sift_down(sm, at);
        for (k = 0; k < d; k++) {
            hb[k] *= 0.5;
            if (hb[k] > hmax) hmax = hb[k];
        }
        if (!(hmax > ldexp(mag, -46))) {
            /* at the precision of doubles: keep its bound, search no deeper; unless its centre
             * lies outside the domain: then what it holds of the domain is within the
             * precision of the boundary, covered up to it (as the box's delta) */
            double phi = 0;
            if (ctx->dom->fn && (e = vpdsi_domain_at(ctx->dom, ctx->st, cb, &phi)) != VPDS_OK) return e;
            if (phi <= 0 && top > q.extra) q.extra = top;
            continue;
        }
        if ((e = split_box(sm, ctx, &q, cb, hb, list)) != VPDS_OK) return e;
    }
}

/* ---- the sample of an event ---- */


/* Whether dart x (radius rx) conflicts at scale t * inhibition: 1 or 0, or an error. With the
 * 2D triangulation (one radius: every sample's f is the same), it conflicts exactly when its
 * nearest sample does, found among x's Delaunay neighbours and compared as the kd-tree compares
 * (proximity.h): the same answer. Else the kd-tree, synced here (the triangulation may have
 * indexed the samples alone). */
static vpds_status dart_conflicts(const vpdsi_ctx *ctx, vpdsi_voids *vd, double t, const double *x,
                                  double rx, int *hit)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    vpdsi_kd_samples v;
    double lipschitz;
    int32_t found, w = -1;
    vpds_status e;
    if (vd) {
        double d2, f = t * pb->inhibition * vpdsi_rule_f(pb->rule, st->sizing.radius, rx);
        int near = vpdsi_voids_nearest2(vd, ctx->mem, st->x, x, f * f, &d2);
        if (near == -1) {
            vpdsi_store_error(st, "out of memory for the stream's triangulation");
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        if (near == 0) {
            *hit = d2 < f * f;
            return VPDS_OK;
        }
    }
    if ((e = vpdsi_store_sync_tree(st)) != VPDS_OK) return e;
    v = vpdsi_store_view(st);
    lipschitz = st->sizing.kind == VPDSI_SIZING_CONSTANT ? -1.0 : st->sizing.lipschitz;
    found = vpdsi_kd_conflict(&st->tree, &v, x, rx, (int)pb->rule, t * pb->inhibition, lipschitz, &w);
    if (found == -2) {
        vpdsi_store_error(st, "sizing breaks lipschitz = %g near sample %d", st->sizing.lipschitz, (int)w);
        return VPDS_ERR_LIPSCHITZ;
    }
    *hit = found != -1;
    return VPDS_OK;
}

/* Two radii: a point drawn uniformly from those free at t * inhibition whose coverage disk
 * at t holds y (rejection from the cube around y); y itself if the draws keep failing. */
static vpds_status draw_near(const vpdsi_ctx *ctx, vpdsi_voids *vd, double t, const double *y, double ry,
                             double *x, double *rx)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    int d = pb->dim, k;
    int uses_x = vpdsi_rule_may_exceed_ry(pb->rule);
    double sl = t * pb->coverage * st->sizing.lipschitz, rho, diag2 = 0;
    long tries, max_tries = 64L << d;
    vpds_status e;
    for (k = 0; k < d; k++) diag2 += (pb->hi[k] - pb->lo[k]) * (pb->hi[k] - pb->lo[k]);
    rho = t * pb->coverage * ry;
    if (uses_x) rho = sl < 1 ? rho / (1 - sl) : sqrt(diag2);
    if (rho * rho > diag2) rho = sqrt(diag2);
    for (tries = 0; tries < max_tries; tries++) {
        double d2 = 0, f;
        int outside = 0, hit;
        for (k = 0; k < d; k++) {
            double u = y[k] + (2 * vpdsi_rng_unit(ctx->rng) - 1) * rho;
            d2 += (u - y[k]) * (u - y[k]);
            if (pb->period[k] == 0 && (u < pb->lo[k] || u > pb->hi[k])) outside = 1;
            x[k] = u;
        }
        if (outside || d2 > rho * rho) continue;
        vpdsi_store_wrap(st, x);
        if (ctx->dom->fn) {
            double phi;
            if ((e = vpdsi_domain_at(ctx->dom, st, x, &phi)) != VPDS_OK) return e;
            if (phi > 0) continue;
        }
        if ((e = vpdsi_store_radius_at(st, x, rx)) != VPDS_OK) return e;
        f = t * pb->coverage * vpdsi_rule_f(pb->rule, *rx, ry);
        if (d2 > f * f) continue; /* does not cover y */
        if ((e = dart_conflicts(ctx, vd, t, x, *rx, &hit)) != VPDS_OK) return e;
        if (!hit) return VPDS_OK;
    }
    memcpy(x, y, (size_t)d * sizeof(double));
    *rx = ry;
    return VPDS_OK;
}

/* The first sample: uniform over the domain (by rejection from the box), at t = +infinity. */
static vpds_status first_sample(const vpdsi_ctx *ctx, double *x_out, double *t_out)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    vpdsi_rng start = *ctx->rng;
    double x[VPDS_MAX_DIM], r;
    int d = pb->dim, k;
    long tries;
    vpds_status e;
    for (tries = 0;; tries++) {
        double phi = 0;
        if (tries == STREAM_FIRST_TRIES) {
            *ctx->rng = start;
            vpdsi_store_error(st, "domain: none of %d uniform points of the box has sdf <= 0 (the"
                              " domain is empty, or too small for a first sample)", STREAM_FIRST_TRIES);
            return VPDS_ERR_DOMAIN;
        }
        for (k = 0; k < d; k++) {
            double u = pb->lo[k] + vpdsi_rng_unit(ctx->rng) * (pb->hi[k] - pb->lo[k]);
            x[k] = u > pb->hi[k] ? pb->hi[k] : u;
        }
        if (ctx->dom->fn && (e = vpdsi_domain_at(ctx->dom, st, x, &phi)) != VPDS_OK) {
            *ctx->rng = start;
            return e;
        }
        if (phi <= 0) break;
    }
    if ((e = vpdsi_store_radius_at(st, x, &r)) != VPDS_OK) {
        *ctx->rng = start;
        return e;
    }
    vpdsi_store_append(st, x, r, INFINITY, 0);
    memcpy(x_out, x, (size_t)d * sizeof(double));
    *t_out = INFINITY;
    ctx->stats->accepted++;
    return VPDS_OK;
}

/* Whether the top region (record rec, box centre/half, its key) is too coarse for the scale
 * of its key; then it is replaced by its 2^d children. They inherit the key, except that from
 * version 3 a key of +infinity (a region never searched) is replaced by each child's own upper
 * bound of g, one evaluation at its centre (eval_boxes): only the regions whose bound reaches
 * the top are then searched. No event lies above t_cap, so version 3 splits at that scale. */
static vpds_status split_if_coarse(vpdsi_stream *sm, const vpdsi_ctx *ctx, uint64_t *rec,
                                   const double *centre, const double *half, double t_cap,
                                   int *split)
{
    int d = sm->geom.dim, k, v3 = ctx->pb->algorithm >= 3;
    double key = rec_key(rec), h = 0, r, L = ctx->st->sizing.lipschitz, scale = key;
    double *cs, *gs, *ubs, *ats, hs[VPDS_MAX_DIM];
    unsigned level = (unsigned)rec[1];
    uint64_t b, n = 0, *cc = sm->kid_cells, cr[VPDS_MAX_DIM];
    vpds_status e;
    kid_arrays(sm, &cs, &gs, &ubs, &ats);
    (void)ats; /* only the keys are read here */
    *split = 0;
    if (v3 && scale > t_cap) scale = t_cap;
    if (!isfinite(scale) || level >= sm->max_level) return VPDS_OK;
    for (k = 0; k < d; k++) h += half[k] * half[k];
    h = sqrt(h);
    if ((e = vpdsi_store_radius_at(ctx->st, centre, &r)) != VPDS_OK) return e;
    if (!(h > STREAM_SPLIT * scale * ctx->pb->coverage * (r - L * h) || r <= L * h)) return VPDS_OK;
    memcpy(cr, rec + REC_COORD, (size_t)d * sizeof(uint64_t));
    for (b = 0; b < ((uint64_t)1 << d); b++) {
        uint64_t *c = cc + n * (size_t)d;
        int skip = 0;
        for (k = 0; k < d; k++) {
            c[k] = 2 * cr[k] + ((b >> k) & 1u);
            if (c[k] >= (sm->geom.n0[k] << (level + 1))) skip = 1;
        }
        if (!skip) region_box(sm, level + 1, c, cs + n++ * (size_t)d, hs);
    }
    /* every callback answers before the heap changes (vpdsi_stream_next) */
    if (v3 && !isfinite(key) && n > 0) {
        for (k = 0; k < d; k++) hs[k] = 0.5 * half[k];
        if ((e = eval_boxes(sm, ctx, cs, (size_t)n, hs, NULL, gs, ubs, NULL)) != VPDS_OK) return e;
    }
    *split = 1;
    heap_pop(sm, rec);
    for (b = 0; b < n; b++) {
        double kb = v3 && !isfinite(key) ? ubs[b] : key;
        heap_push(sm, kb < 0 ? 0.0 : kb, level + 1, cc + b * (size_t)d, -1.0, NULL);
    }
    return VPDS_OK;
}

/* An upper bound of g over the top region and the point y where g = *gy is within the
 * tolerance of it: the cached maximiser when no sample since lowered g there (samples only
 * lower g, so the region's bound is unchanged), else a search. */
static vpds_status bound_region(vpdsi_stream *sm, const vpdsi_ctx *ctx, double key, double next,
                                double *lb, const double *centre, const double *half,
                                double *bound, double *y, double *gy)
{
    int v3 = ctx->pb->algorithm >= 3, exact = exact_applies(ctx);
    /* version 5's exact search: a cached point is the maximiser only when it is the key's */
    double tol = exact ? 2 * EXACT_ROUNDING : stream_tolerance(ctx);
    /* version 3 stops a search below the next key, so a cached point is the region's
     * maximiser only when it is within the tolerance of the key */
    if (*gy >= 0 && (!v3 || *gy * (1 + tol) >= key)) {
        double g1, ub1, zero[VPDS_MAX_DIM] = {0};
        vpds_status e = eval_boxes(sm, ctx, y, 1, zero, NULL, &g1, &ub1, NULL);
        if (e != VPDS_OK) return e;
        /* (the exact search's g(y) is its own arithmetic's: equal to round-off) */
        if (g1 == *gy || (exact && g1 >= *gy * (1 - EXACT_ROUNDING))) {
            *bound = key;
            *gy = g1;
            if (v3 && g1 > *lb) *lb = g1;
            return VPDS_OK;
        }
    }
    if (exact) {
        int solved;
        vpds_status e = exact_region(sm, ctx, centre, half, key, bound, y, gy, &solved);
        if (e != VPDS_OK || solved) {
            if (e == VPDS_OK && *gy > *lb) *lb = *gy;
            return e;
        }
    }
    return search_region(sm, ctx, centre, half, next, v3 ? lb : NULL, bound, y, gy);
}

/* The sample of an event at t that covers y: y itself with one radius, else a point drawn
 * near it (draw_near). */
static vpds_status event_sample(const vpdsi_ctx *ctx, vpdsi_voids *vd, double t, const double *y,
                                double *x, double *rx)
{
    double ry;
    vpds_status e = vpdsi_store_radius_at(ctx->st, y, &ry);
    if (e != VPDS_OK) return e;
    memcpy(x, y, (size_t)ctx->pb->dim * sizeof(double));
    *rx = ry;
    return ctx->pb->two_radii ? draw_near(ctx, vd, t, y, ry, x, rx) : VPDS_OK;
}

/* Version 10 finds the farthest point from the Voronoi diagram of the samples (voids.c) with
 * one radius in an open 2D box, version 11 in 3D too (voids3.c): exact, and changed only
 * around each new sample. */
static int voids_apply(const vpdsi_ctx *ctx)
{
    return ((ctx->pb->algorithm >= 10 && ctx->pb->dim == 2) || (ctx->pb->algorithm >= 11 && ctx->pb->dim == 3)) &&
           !ctx->pb->any_periodic &&
           ctx->st->sizing.kind == VPDSI_SIZING_CONSTANT && !ctx->dom->fn && !ctx->st->grid_mode &&
           !ctx->st->ogrid_mode;
}

/* One event from the Voronoi diagram (after a store reserve, with a sample in the store).
 * *served = 0 when the triangulation gave way (a sample outside the box or of another radius,
 * or round-off broke a cavity): the regions then take over, from the same samples. */
static vpds_status voids_event(vpdsi_stream *sm, const vpdsi_ctx *ctx, double t_min, double t_cap,
                               double *x_out, double *t_out, int *served)
{
    vpdsi_store *st = ctx->st;
    vpdsi_rng start = *ctx->rng;
    double y[3], x[3], g2, ry, rx, t;
    /* no gap exceeds the last event's (t_cap): the triangulation computes no crossing past it */
    double bound = t_cap * ctx->pb->coverage * st->sizing.radius * (1 + 1e-9);
    vpds_status e;
    size_t i;
    int sync = 0, d = ctx->pb->dim;
    /* a fixed point of another radius makes g a weighted distance: the regions' search */
    for (i = d == 2 ? sm->voids.n : sm->voids3.n; i < st->n && !sync; i++)
        if (st->r[i] != st->sizing.radius) sync = -2;
    if (!sync)
        sync = d == 2 ? vpdsi_voids_sync(&sm->voids, ctx->mem, ctx->pb->lo, ctx->pb->hi, st->x, st->n, bound)
                      : vpdsi_voids3_sync(&sm->voids3, ctx->mem, ctx->pb->lo, ctx->pb->hi, st->x, st->n, bound);
    *served = sync != -2;
    if (sync == -2) {
        vpdsi_voids_release(&sm->voids, ctx->mem);
        vpdsi_voids3_release(&sm->voids3, ctx->mem);
        sm->voids_off = 1;
        return VPDS_OK;
    }
    if (sync == -1) {
        vpdsi_store_error(st, "out of memory for the stream's triangulation");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    g2 = d == 2 ? vpdsi_voids_farthest(&sm->voids, st->x, y) : vpdsi_voids3_farthest(&sm->voids3, st->x, y);
    if ((e = vpdsi_store_radius_at(st, y, &ry)) != VPDS_OK) return e;
    t = sqrt(g2) / (ctx->pb->coverage * ry);
    if (t > t_cap) t = t_cap;
    if (t <= t_min) return VPDS_STREAM_END;
    /* the draw near y reads the 2D triangulation, in 3D the kd-tree (synced by the draw) */
    if ((e = event_sample(ctx, d == 2 ? &sm->voids : NULL, t, y, x, &rx)) != VPDS_OK) {
        *ctx->rng = start;
        return e;
    }
    vpdsi_store_append_lagging(st, x, rx, t, 0);
    ctx->stats->accepted++;
    memcpy(x_out, x, (size_t)d * sizeof(double));
    *t_out = t;
    return VPDS_OK;
}

vpds_status vpdsi_stream_next(vpdsi_stream *sm, const vpdsi_ctx *ctx, double t_min, double t_cap,
                              double *x_out, double *t_out)
{
    vpdsi_store *st = ctx->st;
    int d = ctx->pb->dim;
    uint64_t rec[3 + 2 * VPDS_MAX_DIM];
    vpdsi_rng start = *ctx->rng;
    vpds_status e;
    if (st->n > 0 && !sm->voids_off && voids_apply(ctx)) {
        int served;
        if ((e = vpdsi_store_reserve_lagging(st, 1)) != VPDS_OK) return e;
        e = voids_event(sm, ctx, t_min, t_cap, x_out, t_out, &served);
        if (served) return e;
    }
    if ((e = vpdsi_store_sync_tree(st)) != VPDS_OK) return e;
    if ((e = vpdsi_store_reserve(st, 1)) != VPDS_OK) return e;
    /* version 3: sm->lb, the largest g seen since the last sample, is a lower bound of max g;
     * kept in the stream (committed after each step that succeeds), so that a call that fails
     * and its retry take the steps of a call that never failed */
    if (sm->lb_n != st->n) { /* a sample since: the bound no longer holds */
        sm->lb = -1;
        sm->lb_n = st->n;
    }
    if (st->n == 0) return t_min >= INFINITY ? VPDS_STREAM_END : first_sample(ctx, x_out, t_out);
    if (!sm->active && (e = build_regions(sm, ctx)) != VPDS_OK) return e;
    /* The top region is read, not popped, until every callback of the step has answered: a
     * failing sizing or domain callback then leaves the heap as it was, record for record (a
     * pop and a push of the same record would reorder regions of equal keys, and a retry
     * would take another of them first), and no draw is spent. The step's pop and push come
     * after, in the order of a run that never failed. */
    for (;;) {
        double key, next, centre[VPDS_MAX_DIM], half[VPDS_MAX_DIM], bound = 0, y[VPDS_MAX_DIM], gy;
        double t = 0, x[VPDS_MAX_DIM], rx = 0, step_lb;
        int split, event;
        key = vpdsi_region_heap_key(&sm->regions, 0);
        if (key <= t_min) return VPDS_STREAM_END; /* every region is below: nothing consumed */
        if (heap_reserve(sm, ctx->mem, (size_t)1 << d) || reserve_kids(sm, ctx->mem)) {
            vpdsi_store_error(st, "out of memory for the stream's regions");
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        heap_top(sm, rec);
        memcpy(&gy, rec + 2, sizeof gy);
        memcpy(y, rec + REC_COORD + d, (size_t)d * sizeof(double));
        /* the largest key below the top's: one of its children's (the key the top would
         * have after a pop) */
        next = sm->regions.count > 1 ? vpdsi_region_heap_key(&sm->regions, 1) : 0.0;
        if (sm->regions.count > 2 && vpdsi_region_heap_key(&sm->regions, 2) > next)
            next = vpdsi_region_heap_key(&sm->regions, 2);
        region_box(sm, (unsigned)rec[1], rec + REC_COORD, centre, half);
        if ((e = split_if_coarse(sm, ctx, rec, centre, half, t_cap, &split)) != VPDS_OK) return e;
        if (split) continue;
        step_lb = sm->lb;
        if ((e = bound_region(sm, ctx, key, next, &step_lb, centre, half, &bound, y, &gy)) != VPDS_OK)
            return e;
        /* an event at t = bound (an upper bound of max g), never above the scale at which the
         * set is already maximal (the last event's, or a run's) */
        event = bound >= next;
        if (event) {
            t = bound > t_cap ? t_cap : bound;
            if (t > t_min && (e = event_sample(ctx, NULL, t, y, x, &rx)) != VPDS_OK) {
                *ctx->rng = start;
                return e;
            }
        }
        heap_pop(sm, rec);
        heap_push(sm, bound, (unsigned)rec[1], rec + REC_COORD, gy, y);
        sm->lb = step_lb;
        if (!event) continue;
        if (t <= t_min) return VPDS_STREAM_END;
        vpdsi_store_append(st, x, rx, t, 0);
        ctx->stats->accepted++;
        if (gy > 0 && isfinite(t) && t / gy - 1 > ctx->stats->stream_slack)
            ctx->stats->stream_slack = t / gy - 1;
        memcpy(x_out, x, (size_t)d * sizeof(double));
        *t_out = t;
        return VPDS_OK;
    }
}
