/* Branch-and-bound over boxes of the region's bounding box: a box is dropped when it misses
 * the region, lies outside the domain or inside one sample's coverage disk (version 12, up to
 * 5D: or two samples' together, pencil.h); a box point inside the region and the domain and
 * outside every coverage disk is an uncovered witness; anything else splits into 2^d. Boxes
 * live in coordinates around the anchor; on a periodic axis the kd-tree wraps them. The search
 * reads candidate lists handed down from box to sub-box. */
#include "uncovered.h"
#include "pencil.h"
#include "proximity.h"
#include "rules.h"
#include "torus.h"
#include <math.h>
#include <string.h>

#define UNCOVERED_DEPTH 40
#define LIST_CAP 128 /* candidates a box keeps for its sub-boxes; more and they read the kd-trees */
#define LIST_SLOTS ((size_t)(UNCOVERED_DEPTH + 1) * 2 * LIST_CAP)
#ifndef VPDSI_GRID_LIST_CAP /* tests/determinism.sh builds one tool with a tiny one */
#define VPDSI_GRID_LIST_CAP LIST_CAP /* a grid's list longer than this: the kd-tree serves */
#endif
#if VPDSI_GRID_LIST_CAP > LIST_CAP || VPDSI_GRID_LIST_CAP < 1
#error "VPDSI_GRID_LIST_CAP must lie in 1..LIST_CAP: a list fills one slot of LIST_CAP"
#endif

/* Every box of a search used to walk the kd-trees from their roots, several times; a search
 * examines thousands of boxes, most of them deep and small. Instead each box keeps two lists
 * for its sub-boxes, filtered from its parent's: the uncovered-cell centres near it and the
 * samples that may matter inside it (kdtree.h, "Near"). Depth first, the parent of a box at
 * depth k is the last box examined at depth k - 1, so one slot per depth (in u->lists) holds
 * them. The tests read the lists with the kd-tree's own per-sample arithmetic: same answers. */
typedef struct {
    int u_ok, s_ok;  /* the list is complete (else the box's tests read the kd-tree) */
    size_t u_n, s_n;
    double r_bound;  /* the sample list holds for r(u) <= r_bound */
} bb_lists;

typedef struct {
    vpdsi_uncovered *u;
    const vpdsi_problem *pb;
    vpdsi_store *st;
    vpdsi_domain *dom;
    const double *alo, *ahi;
    double centre[VPDS_MAX_DIM];
    double r_anchor, scale, L, reach, slack;
    int point, lists; /* lists: the slots are allocated */
    int grid;         /* the run's background grid serves the first lists (grid_list) */
    int tree_synced;  /* the store's kd-tree holds every sample: the tests may read it */
    int exact_region; /* version 2: a box beyond a point anchor's region is dropped */
    int in_cell;      /* the search lies in one indexed cell: the centres cannot prune */
    size_t budget;    /* boxes this search may examine */
    double *witness;  /* where the uncovered point found goes (dim coordinates, then r there) */
    int found_point;  /* *found came from such a point, not from the budget or the precision */
    int drop_kept;    /* the box examined last was dropped for good: inside one coverage disk
                         (or two, version 12), or outside the domain (not for missing this
                         question's region) */
    uint64_t *sub;    /* version 6: the cell's sub-boxes shown covered, as this search goes */
    uint64_t sub_now; /* where sub points: written back only when the search ends without an
                         error, so that a retried dart takes the same boxes as the first try */
    int sub_depth;
    int far_first;    /* version 6: a box's children from the farthest from the anchor on */
    int far_corner;   /* version 8: a box that splits tries its corner farthest from the sample
                         that covers its nearest point */
    int pencil;       /* version 12, up to 5D: a box that two coverage disks hold together is
                         dropped as one that one holds (pencil.h) */
    int32_t cover;    /* that sample (-1: p was not tested) */
    vpdsi_kd_samples view, uview;
    bb_lists lv[UNCOVERED_DEPTH + 1];
    /* the box being examined: kept here, not in the helpers' frames, which then cost nothing
     * to enter under AddressSanitizer (the fuzz builds examine millions of boxes) */
    double p[VPDS_MAX_DIM], c2[VPDS_MAX_DIM], rp, phi;
    size_t count;
    int32_t w;
} bb_search;

static size_t slot(int depth, int samples)
{
    return ((size_t)depth * 2 + (size_t)samples) * LIST_CAP;
}

int vpdsi_uncovered_near(const vpdsi_uncovered *u, const double *p, double thr)
{
    vpdsi_kd_samples v = vpdsi_uncovered_view(u);
    if (!u->ready || !(thr < INFINITY)) return 1; /* as the nearest centre compared with thr was */
    return vpdsi_kd_ratio_within(&u->tree, &v, p, thr);
}

/* Whether a cell that may hold an uncovered point lies within thr of c2: exactly
 * vpdsi_uncovered_near(q->u, c2, thr), read from this box's list of centres when complete. */
static int near_uncovered(bb_search *q, int depth, const double *c2, double thr)
{
    bb_lists *me = &q->lv[depth];
    size_t off = slot(depth, 0);
    q->count = off;
    if (q->lists && depth > 0 && q->lv[depth - 1].u_ok) {
        me->u_n = vpdsi_kd_filter_near(&q->u->tree, &q->uview, q->u->lists + slot(depth - 1, 0),
                                       q->lv[depth - 1].u_n, c2, c2, 0.0, thr, q->slack,
                                       q->u->lists + off);
        me->u_ok = 1;
    } else if (q->lists && vpdsi_kd_near_box(&q->u->tree, &q->uview, c2, c2, 0.0, thr, q->slack,
                                             LIST_CAP, q->st->mem, &q->u->lists, &q->count,
                                             &q->u->cap_lists) == 0) {
        me->u_n = q->count - off;
        me->u_ok = 1;
    }
    if (!me->u_ok) return vpdsi_uncovered_near(q->u, c2, thr);
    return !(vpdsi_kd_list_min_ratio(&q->u->tree, &q->uview, q->u->lists + off, me->u_n, c2, 0.0, 1.0,
                                     (int)VPDS_RULE_PRIOR, NULL) > thr);
}

/* With one radius the run's background grid holds every sample near a box that lies in one of
 * its cells: its stencil reaches t * inhibition * r, no less than the coverage reach, with a
 * margin of 1e-6 (bgrid.c), above the lists' 1e-9 (their slack of 1e-12 times the largest
 * coordinate may reach past it far from the origin, but only for samples too far to cover: the
 * tests are strict). The box's list comes from there, and the kd-tree is not built (its build
 * took a sixth of an annulus run). The list's order (nearest cells first) is not the tree's:
 * the answers are the same, but far_corner's corner, and so the boxes a search counts against
 * a budget, may differ. 0: the list is in slot off; 1: the box spans cells or the list
 * overflows, the kd-tree must serve. */
static int grid_list(bb_search *q, const double *lo, const double *hi, double rb, size_t off,
                     size_t *count)
{
    const vpdsi_bgrid *g = &q->st->grid;
    const double *period = q->pb->period;
    uint64_t c[VPDS_MAX_DIM];
    size_t n, j, kept = 0;
    int k;
    for (k = 0; k < g->dim; k++) {
        double u = floor((0.5 * (lo[k] + hi[k]) - g->lo[k]) / g->side[k]), tol = 1e-9 * g->side[k];
        double clo;
        c[k] = u <= 0 ? 0 : (uint64_t)u;
        if (c[k] >= g->n[k]) c[k] = g->n[k] - 1;
        clo = g->lo[k] + (double)c[k] * g->side[k];
        if (lo[k] < clo - tol || hi[k] > clo + g->side[k] + tol) return 1;
    }
    n = vpdsi_bgrid_near(g, vpdsi_bgrid_index(g, c), q->u->grid_cand);
    for (j = 0; j < n; j++) {
        int32_t i = q->u->grid_cand[j];
        if (!vpdsi_prox_near(&q->view, i, g->dim, period, lo, hi, rb, q->scale, q->slack)) continue;
        if (kept == VPDSI_GRID_LIST_CAP) return 1;
        q->u->lists[off + kept++] = i;
    }
    *count = kept;
    return 0;
}

/* The kd-tree made whole before a test reads it (the grid's lists spared it so far). */
static vpds_status need_tree(bb_search *q)
{
    vpds_status e;
    if (q->tree_synced) return VPDS_OK;
    if ((e = vpdsi_store_sync_tree(q->st)) != VPDS_OK) return e;
    q->tree_synced = 1;
    return VPDS_OK;
}

/* This box's samples, from its parent's list while r stays below the parent's bound, else from
 * the grid or the tree; r_bound = r_hi + L * diag bounds r_hi of every sub-box when r is
 * L-Lipschitz, and a sub-box that finds otherwise starts again from the index. */
static vpds_status sample_list(bb_search *q, int depth, const double *lo, const double *hi,
                               double rp, double r_hi, double diag)
{
    bb_lists *me = &q->lv[depth], *up = depth > 0 ? &q->lv[depth - 1] : NULL;
    size_t off = slot(depth, 1);
    double rb = r_hi + q->L * diag;
    vpds_status e;
    if (!q->lists) return VPDS_OK; /* no lists: prepare built the tree, the tests read it */
    me->r_bound = rb;
    if (up && up->s_ok && rp <= up->r_bound && r_hi <= up->r_bound) {
        if (rb > up->r_bound) rb = up->r_bound;
        me->s_n = vpdsi_kd_filter_near(&q->st->tree, &q->view, q->u->lists + slot(depth - 1, 1), up->s_n,
                                       lo, hi, rb, q->scale, q->slack, q->u->lists + off);
        me->s_ok = 1;
        me->r_bound = rb;
        return VPDS_OK;
    }
    if (q->grid && grid_list(q, lo, hi, rb, off, &me->s_n) == 0) {
        me->s_ok = 1;
        return VPDS_OK;
    }
    if ((e = need_tree(q)) != VPDS_OK) return e;
    if (q->st->tree.n_nodes == 0) { /* no sample: the empty list is complete for any r */
        me->s_n = 0;
        me->s_ok = 1;
        me->r_bound = INFINITY;
    } else if ((q->count = off,
                vpdsi_kd_near_box(&q->st->tree, &q->view, lo, hi, rb, q->scale, q->slack, LIST_CAP,
                                  q->st->mem, &q->u->lists, &q->count, &q->u->cap_lists)) == 0) {
        me->s_n = q->count - off;
        me->s_ok = 1;
    }
    return VPDS_OK;
}

/* A sample that covers p at t * coverage, or -1 (vpdsi_kd_conflict, from the list when
 * complete). */
static int32_t p_cover(bb_search *q, int depth, const double *p, double rp)
{
    if (q->lv[depth].s_ok)
        return q->lv[depth].s_n == 0 ? -1
               : vpdsi_kd_list_conflict(&q->st->tree, &q->view, q->u->lists + slot(depth, 1),
                                        q->lv[depth].s_n, p, rp, (int)q->pb->rule, q->scale);
    return vpdsi_kd_conflict(&q->st->tree, &q->view, p, rp, (int)q->pb->rule, q->scale, -1.0, &q->w);
}

/* Version 12: whether one sample of the box's list holds it, or two together (pencil.h), at
 * radii f(r(x), r_lo) as box_covered takes them. */
static int pencil_covers(const bb_search *q, const int32_t *cand, size_t n, const double *lo,
                         const double *hi, double r_lo)
{
    return vpdsi_pencil_list_holds(&q->view, cand, n, q->pb->dim, q->pb->rule, q->scale, r_lo, lo, hi,
                                   q->pb->period);
}

/* Whether one sample covers the whole box, r_lo <= r <= r_hi over it (gather, then the test),
 * or (version 12, up to 5D) two together (pencil_covers). */
static vpds_status search_box_covered(bb_search *q, int depth, const double *lo, const double *hi,
                               double r_lo, double r_hi, int *covered)
{
    size_t off = q->lists ? LIST_SLOTS : 0;
    if (q->lv[depth].s_ok) {
        *covered = r_lo > 0 && q->lv[depth].s_n > 0 &&
                   vpdsi_kd_list_box_covered(&q->st->tree, &q->view, q->u->lists + slot(depth, 1),
                                             q->lv[depth].s_n, lo, hi, r_hi, r_lo, (int)q->pb->rule,
                                             q->scale);
        if (!*covered && q->pencil && r_lo > 0 && q->lv[depth].s_n > 1)
            *covered = pencil_covers(q, q->u->lists + slot(depth, 1), q->lv[depth].s_n, lo, hi, r_lo);
        return VPDS_OK;
    }
    q->u->n_lists = off;
    if (q->pencil) {
        /* the gather keeps only disks that may hold the whole box: the pencil reads every disk
         * that reaches into it, as the lists hold them, so that both ways answer alike, and
         * finds one that holds it alone as the gather's test would */
        if (vpdsi_kd_near_box(&q->st->tree, &q->view, lo, hi, r_hi, q->scale, q->slack, SIZE_MAX, q->st->mem,
                              &q->u->lists, &q->u->n_lists, &q->u->cap_lists) < 0) {
            vpdsi_store_error(q->st, "out of memory listing the samples near a box");
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        *covered = r_lo > 0 && pencil_covers(q, q->u->lists + off, q->u->n_lists - off, lo, hi, r_lo);
        return VPDS_OK;
    }
    if (vpdsi_kd_gather(&q->st->tree, &q->view, lo, hi, r_hi, (int)q->pb->rule, q->scale, 0, q->st->mem,
                        &q->u->lists, &q->u->n_lists, &q->u->cap_lists)) {
        vpdsi_store_error(q->st, "out of memory gathering the samples near a box");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    *covered = r_lo > 0 && vpdsi_kd_box_covered(&q->st->tree, &q->view, q->u->lists + off,
                                                q->u->n_lists - off, lo, hi, r_lo, (int)q->pb->rule,
                                                q->scale);
    return VPDS_OK;
}

/* Squared distance from y to the anchor (a point: alo = ahi), in the boxes' coordinates. */
static double anchor_gap2(const bb_search *q, const double *y)
{
    double d2 = 0;
    int k;
    for (k = 0; k < q->pb->dim; k++) {
        const double *a = q->alo, *b = q->ahi;
        double g = y[k] < a[k] ? a[k] - y[k] : y[k] > b[k] ? y[k] - b[k] : 0;
        d2 += g * g;
    }
    return d2;
}

/* Whether a point at squared distance d2 from the anchor, where r is r_y, lies in the region:
 * within scale * f(r_anchor, r_y) of a point anchor, within the reach of a box. */
static int in_region_at(const bb_search *q, double d2, double r_y)
{
    double f;
    if (!q->point) return d2 <= q->reach * q->reach;
    f = q->scale * vpdsi_rule_f(q->pb->rule, q->r_anchor, r_y);
    return r_y > 0 && d2 <= f * f;
}

/* p, uncovered in the region and the domain at r(p) = rp: the search's witness. */
static vpds_status take_witness(bb_search *q, const double *p, double rp, int *verdict)
{
    int d = q->pb->dim;
    vpds_status st;
    q->phi = 0;
    if (q->dom->fn && (st = vpdsi_domain_at(q->dom, q->st, p, &q->phi)) != VPDS_OK) return st;
    if (q->phi > 0) return VPDS_OK;
    *verdict = 1;
    q->found_point = 1;
    if (q->witness) {
        memcpy(q->witness, p, (size_t)d * sizeof(double));
        q->witness[d] = rp;
    }
    return VPDS_OK;
}

/* Version 8: a box about to split tries a second point, its corner farthest from the sample
 * that covers p. Where that sample's coverage sphere crosses the anchor's boundary, the
 * uncovered part of the anchor is a thin wedge: p stayed covered at every depth and the search
 * dived to the precision limit (40 levels) before answering. f grows with r(u) under every
 * rule, so the corner is in the region if it is at the box's lowest r, and covered if it is
 * at that r: the sizing is read only when that does not decide. */
static vpds_status far_corner(bb_search *q, int depth, const double *lo, const double *hi,
                              double r_lo, int *verdict)
{
    int d = q->pb->dim, k;
    const double *x = q->view.x + (size_t)q->cover * (size_t)d;
    double y[VPDS_MAX_DIM], ry;
    vpds_status st;
    for (k = 0; k < d; k++) {
        double P = q->pb->period[k], e = x[k] - 0.5 * (lo[k] + hi[k]);
        if (P > 0) e -= P * floor(e / P + 0.5); /* the image of x nearest the box */
        y[k] = e > 0 ? lo[k] : hi[k];
    }
    if (!in_region_at(q, anchor_gap2(q, y), r_lo)) return VPDS_OK;
    if (q->st->sizing.kind == VPDSI_SIZING_CONSTANT) {
        ry = q->st->sizing.radius;
    } else {
        if (p_cover(q, depth, y, r_lo) >= 0) return VPDS_OK; /* covered at any r it may have */
        if ((st = vpdsi_store_radius_at(q->st, y, &ry)) != VPDS_OK) return st;
    }
    if (p_cover(q, depth, y, ry) >= 0) return VPDS_OK;
    return take_witness(q, y, ry, verdict);
}

/* One box at `depth`: *verdict 0 when it is dropped, 1 when it answers "uncovered" (a witness,
 * or unresolved at the precision), 2 when it splits. */
static vpds_status examine(bb_search *q, const double *lo, const double *hi, int depth,
                           int *verdict)
{
    int d = q->pb->dim, k, in_region;
    double *p = q->p, *c2 = q->c2, gap2 = 0, diag2 = 0, diag, r_lo, r_hi, d2;
    vpds_status st;
    *verdict = 0;
    q->drop_kept = 0;
    q->lv[depth].u_ok = q->lv[depth].s_ok = 0;
    for (k = 0; k < d; k++) {
        /* nearest point of the box to the anchor's centre, and the box-anchor gap */
        double g, c = q->centre[k];
        p[k] = c < lo[k] ? lo[k] : c > hi[k] ? hi[k] : c;
        g = q->alo[k] > hi[k] ? q->alo[k] - hi[k] : lo[k] > q->ahi[k] ? lo[k] - q->ahi[k] : 0;
        gap2 += g * g;
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
        c2[k] = 0.5 * (lo[k] + hi[k]);
    }
    if (gap2 > q->reach * q->reach) return VPDS_OK; /* misses the region */
    /* no cell that may hold an uncovered point meets the box */
    if (q->u->ready && !q->in_cell && !near_uncovered(q, depth, c2, 0.5 * sqrt(diag2) + q->u->half))
        return VPDS_OK;
    /* the box lies outside the domain: nothing there needs covering */
    if (q->dom->fn) {
        if ((st = vpdsi_domain_at(q->dom, q->st, c2, &q->phi)) != VPDS_OK) return st;
        if (q->phi > 0.5 * sqrt(diag2)) {
            q->drop_kept = 1;
            return VPDS_OK;
        }
    }
    if (q->st->sizing.kind == VPDSI_SIZING_CONSTANT)
        q->rp = q->st->sizing.radius; /* what vpdsi_radius_at answers, without its frame */
    else if ((st = vpdsi_store_radius_at(q->st, p, &q->rp)) != VPDS_OK)
        return st;
    diag = sqrt(diag2);
    r_lo = q->rp - q->L * diag;
    r_hi = q->rp + q->L * diag;
    d2 = anchor_gap2(q, p);
    in_region = in_region_at(q, d2, q->rp);
    if (q->point) {
        /* Version 2: the box's nearest point lies beyond f(r_anchor, r) for every r the box
         * holds (f is monotone), so the box misses the region. Version 1 kept such a box when
         * it straddled a coverage boundary, down to the depth limit and a false "uncovered":
         * a dart accepted that covers nothing new: 90 of the 677 samples of a 3D run with
         * two radii and the bigger rule (tests/determinism.sh, configuration 7). */
        if (q->exact_region) {
            double f_hi = q->scale * vpdsi_rule_f(q->pb->rule, q->r_anchor, r_hi);
            if (d2 > f_hi * f_hi) return VPDS_OK;
        }
    }
    if ((st = sample_list(q, depth, lo, hi, q->rp, r_hi, diag)) != VPDS_OK) return st;
    q->cover = -1;
    if (in_region && (q->cover = p_cover(q, depth, p, q->rp)) < 0) {
        /* p is uncovered: no sample within t*coverage*f of it; a witness if in the domain */
        if ((st = take_witness(q, p, q->rp, verdict)) != VPDS_OK || *verdict) return st;
    }
    if ((st = search_box_covered(q, depth, lo, hi, r_lo, r_hi, verdict)) != VPDS_OK) return st;
    if (*verdict) { /* inside one coverage disk, or two */
        *verdict = 0;
        q->drop_kept = 1;
        return VPDS_OK;
    }
    /* unresolved at the precision: count it as uncovered */
    if (depth >= UNCOVERED_DEPTH || !(diag > 1e-12 * q->reach)) {
        *verdict = 1;
        return VPDS_OK;
    }
    if (q->far_corner && q->cover >= 0 && (st = far_corner(q, depth, lo, hi, r_lo, verdict)) != VPDS_OK) return st;
    if (!*verdict) *verdict = 2;
    return VPDS_OK;
}

/* Round-off allowance of the candidate lists: a few ulps of the largest coordinate a box or an
 * image of it can reach, with room to spare. */
static double list_slack(const vpdsi_problem *pb, const double *lo, const double *hi)
{
    double m = 0;
    int k;
    for (k = 0; k < pb->dim; k++) {
        double a = fabs(lo[k]) > fabs(hi[k]) ? fabs(lo[k]) : fabs(hi[k]);
        if (a + pb->period[k] > m) m = a + pb->period[k];
    }
    return 1e-12 * m;
}

/* The search's first box: the anchor widened by the reach, clipped to the box on open axes
 * (uncovered points lie in the box), at depth 0. */
static void first_box(bb_search *q, double *bx)
{
    const vpdsi_problem *pb = q->pb;
    int d = pb->dim, k;
    for (k = 0; k < d; k++) {
        double lo = q->alo[k] - q->reach, hi = q->ahi[k] + q->reach;
        q->centre[k] = 0.5 * (q->alo[k] + q->ahi[k]);
        if (pb->period[k] == 0) {
            if (lo < pb->lo[k]) lo = pb->lo[k];
            if (hi > pb->hi[k]) hi = pb->hi[k];
        }
        bx[k] = lo;
        bx[d + k] = hi;
    }
    bx[2 * d] = 0;
}

/* A frame of the search's stack: the box (dim lows, dim highs), its depth, how many of its 2^d
 * children are still to visit (-1: the box itself is not examined yet), its first sub-box of
 * q->sub (version 6) and whether every box below it was dropped for good so far. */
#define FRAME_DEPTH(f, d) (f)[2 * (d)]
#define FRAME_LEFT(f, d) (f)[2 * (d) + 1]
#define FRAME_SUB(f, d) (f)[2 * (d) + 2]
#define FRAME_KEPT(f, d) (f)[2 * (d) + 3]
#define FRAME_DOUBLES(d) (2 * (size_t)(d) + 4)

/* Examines the box of frame bx (or skips it, its sub-boxes known covered); *verdict as examine. */
static vpds_status visit(bb_search *q, double *bx, size_t *boxes, int *found, int *verdict)
{
    int d = q->pb->dim, depth = (int)FRAME_DEPTH(bx, d);
    unsigned first = (unsigned)FRAME_SUB(bx, d);
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    if (q->sub && depth <= q->sub_depth) {
        uint64_t bits = vpdsi_sub_run(d, q->sub_depth - depth, first);
        if ((*q->sub & bits) == bits) { /* shown covered by an earlier question of this scale */
            *verdict = 0;
            q->drop_kept = 1;
            return VPDS_OK;
        }
    }
    memcpy(lo, bx, (size_t)d * sizeof(double));
    memcpy(hi, bx + d, (size_t)d * sizeof(double));
    q->u->boxes++;
    if (++*boxes > q->budget) {
        *found = 1;
        return VPDS_OK;
    }
    return examine(q, lo, hi, depth, verdict);
}

/* A frame done: what it showed covered goes into q->sub and up to its parent. */
static void frame_done(bb_search *q, double *bx, double *parent)
{
    int d = q->pb->dim, depth = (int)FRAME_DEPTH(bx, d);
    if (FRAME_KEPT(bx, d) == 0) {
        if (parent) FRAME_KEPT(parent, d) = 0;
    } else if (q->sub && depth <= q->sub_depth) {
        *q->sub |= vpdsi_sub_run(d, q->sub_depth - depth, (unsigned)FRAME_SUB(bx, d));
    }
}

/* Depth first over the boxes from the first one: *found at the first "uncovered" verdict, or
 * when the boxes exceed the budget. Children are made one at a time, the last first, so the
 * stack holds one frame per depth. */
static vpds_status search(bb_search *q, int *found)
{
    int d = q->pb->dim, k;
    size_t top = 1, boxes = 0, stride = FRAME_DOUBLES(d);
    double *stack = q->u->stack;
    vpds_status st;
    FRAME_LEFT(stack, d) = -1;
    FRAME_SUB(stack, d) = 0;
    while (top > 0) {
        double *bx = stack + (top - 1) * stride, *cb, left;
        int depth = (int)FRAME_DEPTH(bx, d), verdict;
        unsigned b;
        if (FRAME_LEFT(bx, d) < 0) {
            if ((st = visit(q, bx, &boxes, found, &verdict)) != VPDS_OK || *found) return st;
            if (verdict == 1) {
                *found = 1;
                return VPDS_OK;
            }
            FRAME_LEFT(bx, d) = verdict == 0 ? 0 : (double)(1u << d);
            FRAME_KEPT(bx, d) = verdict == 0 ? q->drop_kept : 1;
        }
        left = FRAME_LEFT(bx, d);
        if (left == 0) {
            frame_done(q, bx, top > 1 ? bx - stride : NULL);
            top--;
            continue;
        }
        b = (unsigned)left - 1;
        FRAME_LEFT(bx, d) = b;
        if (q->far_first) { /* the first child made is the one farthest from the anchor */
            unsigned far = 0;
            for (k = 0; k < d; k++)
                if (q->centre[k] < 0.5 * (bx[k] + bx[d + k])) far |= 1u << k;
            b ^= far ^ ((1u << d) - 1);
        }
        cb = stack + top++ * stride;
        for (k = 0; k < d; k++) {
            double mid = 0.5 * (bx[k] + bx[d + k]);
            cb[k] = (b >> k) & 1u ? mid : bx[k];
            cb[d + k] = (b >> k) & 1u ? bx[d + k] : mid;
        }
        FRAME_DEPTH(cb, d) = depth + 1;
        FRAME_LEFT(cb, d) = -1;
        FRAME_SUB(cb, d) = FRAME_SUB(bx, d);
        if (q->sub && depth < q->sub_depth)
            FRAME_SUB(cb, d) += (double)(b << ((unsigned)d * (unsigned)(q->sub_depth - depth - 1)));
    }
    return VPDS_OK;
}

/* The search's state for the anchor box [alo, ahi]; *found = 1 when the region cannot be
 * searched (scale * L >= 1: it has no bound), VPDS_OK with q ready otherwise. */
static vpds_status prepare(bb_search *q, vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t,
                           const double *alo, const double *ahi, double r_anchor, int *found)
{
    const vpdsi_problem *pb = ctx->pb;
    vpdsi_store *st = ctx->st;
    int d = pb->dim;
    size_t stride = FRAME_DOUBLES(d), need;
    vpds_status e;
    *found = 0;
    memset(q, 0, sizeof *q);
    q->u = u;
    q->pb = pb;
    q->st = st;
    q->dom = ctx->dom;
    q->alo = alo;
    q->ahi = ahi;
    q->r_anchor = r_anchor;
    q->scale = t * pb->coverage;
    q->L = st->sizing.lipschitz;
    q->point = memcmp(alo, ahi, (size_t)d * sizeof(double)) == 0;
    q->exact_region = pb->algorithm >= 2;
    q->far_first = pb->algorithm >= 6;
    q->far_corner = pb->algorithm >= 8;
    /* past 5D its searches end within the box budget where they spent it before (other
     * answers, 1.4x the time on a 6D run with two radii): off there */
    q->pencil = pb->algorithm >= 12 && pb->dim <= 5;
    q->budget = VPDSI_UNCOVERED_BUDGET;
    /* largest reach of the region: r(u) <= r_anchor + L |u - a| and |u - a| <= scale r(u) */
    q->reach = vpdsi_rule_reach(pb->rule, q->scale, q->L, r_anchor);
    if (!(q->scale * q->L < 1)) {
        *found = 1;
        return VPDS_OK;
    }
    if (vpdsi_mul_size((size_t)UNCOVERED_DEPTH + 2, stride, &need) ||
        vpdsi_mem_reserve(st->mem, (void **)&u->stack, &u->cap_stack, need, sizeof(double))) {
        vpdsi_store_error(st, "out of memory for the two-radii coverage search");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    /* without room for the lists every test reads the kd-trees, as fast as before them */
    q->lists = vpdsi_mem_reserve(st->mem, (void **)&u->lists, &u->cap_lists, LIST_SLOTS,
                                 sizeof(int32_t)) == 0;
    q->grid = q->lists && st->grid_mode &&
              vpdsi_mem_reserve(st->mem, (void **)&u->grid_cand, &u->cap_grid_cand,
                                st->grid.n_stencil + 1, sizeof(int32_t)) == 0;
    if (!q->grid && (e = need_tree(q)) != VPDS_OK) return e;
    q->view = vpdsi_store_view(st);
    q->uview = vpdsi_uncovered_view(u);
    return VPDS_OK;
}

vpds_status vpdsi_uncovered_in(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t,
                               const double *alo, const double *ahi, double r_anchor, int *found)
{
    return vpdsi_uncovered_in_box(u, ctx, t, alo, ahi, r_anchor, NULL, NULL, found);
}

vpds_status vpdsi_uncovered_in_box(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t,
                                   const double *alo, const double *ahi, double r_anchor,
                                   const double *cell, vpdsi_search_out *out, int *found)
{
    int d = ctx->pb->dim;
    bb_search q;
    vpds_status e = prepare(&q, u, ctx, t, alo, ahi, r_anchor, found);
    if (e != VPDS_OK || *found) return e;
    first_box(&q, u->stack);
    if (cell) { /* the region's part in that cell: the anchor's centre stays the one first_box set */
        memcpy(u->stack, cell, 2 * (size_t)d * sizeof(double));
        q.in_cell = 1;
    }
    if (out) {
        if (out->budget < q.budget) q.budget = out->budget;
        q.witness = out->witness;
        q.in_cell = q.in_cell || out->in_indexed;
        if (cell && out->sub && out->sub_depth > 0) {
            q.sub_now = *out->sub;
            q.sub = &q.sub_now;
            q.sub_depth = out->sub_depth;
        }
    }
    q.slack = list_slack(ctx->pb, u->stack, u->stack + d);
    e = search(&q, found);
    if (e == VPDS_OK && q.sub) *out->sub = q.sub_now;
    if (out) out->found_point = q.found_point;
    return e;
}
