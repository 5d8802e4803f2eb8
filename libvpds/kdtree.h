/* Incremental bucket kd-tree of samples (Section 6) with the proximity primitives of Table 2.
 *
 * Each node keeps the bounding box of its samples and the largest radius among them. A branch
 * is pruned when no sample in it can reach the query even with that largest radius: a stored
 * bound, so pruning calls no sizing function (Table 2 evaluates r at the projection p_perp
 * instead) and stays valid for fixed points whose radii do not follow the sizing. */
#ifndef VPDS_KDTREE_H
#define VPDS_KDTREE_H
#include "mem.h"
#include "samples.h"

#define VPDSI_KD_LEAF 8        /* samples per leaf before it splits */
#define VPDSI_KD_MAX_DEPTH 480 /* deeper leaves stop splitting: slower, never wrong */

typedef struct vpdsi_kd_node {
    int32_t left, right;  /* left < 0: a leaf */
    int32_t head, count;  /* leaf: first sample of its list (next[]), and how many */
    double split;
    double rmax;
    int32_t axis;
    int32_t pad;
} vpdsi_kd_node;

typedef struct vpdsi_kdtree {
    int dim;
    double period[VPDS_MAX_DIM]; /* box side on a periodic axis, 0 on an open one (torus.h) */
    vpdsi_kd_node *nodes;
    size_t n_nodes, cap_nodes;
    double *box; /* per node: dim lows then dim highs */
    size_t cap_box;
    int32_t *next; /* per sample: next sample in the same leaf, -1 at the end */
    size_t cap_next;
} vpdsi_kdtree;

void vpdsi_kd_init(vpdsi_kdtree *t, int dim);
/* Measure distances on a torus along the axes with period[k] > 0 (NULL: none). */
void vpdsi_kd_set_period(vpdsi_kdtree *t, const double *period);
void vpdsi_kd_release(vpdsi_kdtree *t, vpdsi_mem *m);
/* Forget every sample, keep the memory. */
void vpdsi_kd_clear(vpdsi_kdtree *t);
/* Room to insert up to `more` samples, the tree then holding `n_total` samples. */
int vpdsi_kd_reserve(vpdsi_kdtree *t, vpdsi_mem *m, size_t n_total, size_t more);
/* Insert sample i (after vpdsi_kd_reserve). Never allocates. */
void vpdsi_kd_insert(vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t i);

/* Conflict: the first sample x (in search order) with |y - x| < scale * f(r(x), ry), or -1.
 * f is the rule (ry unused for prior). Covers PiX (prior), XiP (current), and their "or"
 * (bigger) and "and" (smaller), Table 2. When lipschitz >= 0 every sample met whose radius
 * follows the sizing is checked against |r(x) - ry| <= L |x - y|; a break returns -2 and its
 * index in *witness. */
int32_t vpdsi_kd_conflict(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *y,
                          double ry, int rule, double scale, double lipschitz, int32_t *witness);

/* Samples that might cover a whole sub-box of the box [lo, hi]: its 2^d children when split, else
 * the box itself; r_hi bounds r over the box from above. A sample's farthest distance to a
 * sub-box is, along each axis, at least half the sub-box's side plus its distance to the nearest
 * sub-box centre; summed over axes this bound prunes whole subtrees (with their largest radius)
 * and single samples. Appends indices to *out (grown with m); -1 on OOM. */
int vpdsi_kd_gather(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *lo,
                    const double *hi, double r_hi, int rule, double scale, int split,
                    vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap);

/* BiX (prior) / XiB (current) and their combinations, on candidates from vpdsi_kd_gather:
 * whether one candidate covers the whole box, |y - x| <= scale * f(r(x), r_lo) for every y in
 * it, r_lo bounding r over the box from below. The farthest corner is tested exactly. */
int vpdsi_kd_box_covered(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *cand,
                         size_t n, const double *lo, const double *hi, double r_lo, int rule,
                         double scale);
/* The same test: the first candidate that holds the box whole, or -1. */
int32_t vpdsi_kd_box_holder(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *cand,
                            size_t n, const double *lo, const double *hi, double r_lo, int rule,
                            double scale);

/* Whether some sample has |y - x| / r(x) <= bound (vpdsi_kd_min_ratio's per-sample ratio with
 * the rule prior and no slack), stopping at the first that shows it. */
int vpdsi_kd_ratio_within(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *y,
                          double bound);
/* The weighted nearest sample for the continuous stream (Section 4.2): the smallest
 * (|y - x| + slack) / f(r(x), ry) over all samples, with its index in *arg (-1: no sample, the
 * result is +INFINITY). With slack = 0 and ry = r(y) this is g(y) * coverage; with slack the
 * half-diagonal of a box around y and ry a lower bound of r there, it bounds g over the box. */
double vpdsi_kd_min_ratio(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *y,
                          double slack, double ry, int rule, int32_t *arg);

/* Candidate lists (uncovered.c): the samples that may matter anywhere inside a box, then the
 * tests above read from such a list instead of the tree, with the same per-sample arithmetic,
 * so they answer with the same bits whenever the list holds every sample they would accept.
 *
 * Near: |x - box| <= scale * max(r(x), r_bound) * (1 + 1e-9) + slack. Every rule's f is at most
 * max(r(x), r(u)), so for r(u) <= r_bound over the box this holds every sample that conflicts
 * with a point of the box or may cover a part of it; the margins absorb round-off between the
 * tests' formulas. vpdsi_kd_near_box appends them from the tree, at most `limit` (1: more were
 * found, the list is incomplete; -1 on OOM); vpdsi_kd_filter_near keeps those of a list (from
 * the box of an ancestor, with an r_bound no smaller) that are near a sub-box, in order. */
int vpdsi_kd_near_box(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *lo,
                      const double *hi, double r_bound, double scale, double slack, size_t limit,
                      vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap);
size_t vpdsi_kd_filter_near(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *from,
                            size_t n, const double *lo, const double *hi, double r_bound,
                            double scale, double slack, int32_t *out);
/* vpdsi_kd_gather over a list (from vpdsi_kd_near_box of an enclosing box, r_bound >= r_hi):
 * the same samples, in the list's order. */
size_t vpdsi_kd_list_gather(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *from,
                            size_t n, const double *lo, const double *hi, double r_hi, int rule,
                            double scale, int split, int32_t *out);
/* The first candidate that conflicts with y, or -1 (vpdsi_kd_conflict without the Lipschitz
 * check). */
int32_t vpdsi_kd_list_conflict(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                               const int32_t *cand, size_t n, const double *y, double ry, int rule,
                               double scale);
/* vpdsi_kd_gather (no split) at r_hi followed by vpdsi_kd_box_covered at r_lo, on candidates. */
int vpdsi_kd_list_box_covered(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                              const int32_t *cand, size_t n, const double *lo, const double *hi,
                              double r_hi, double r_lo, int rule, double scale);
/* vpdsi_kd_min_ratio over candidates (+INFINITY: none), the first of equal ones in *arg (or
 * NULL). */
double vpdsi_kd_list_min_ratio(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                               const int32_t *cand, size_t n, const double *y, double slack,
                               double ry, int rule, int32_t *arg);
/* Every sample that may be vpdsi_kd_min_ratio's (slack 0) at a point of the box [lo, hi] with
 * ry in [r_lo, r_hi]: those whose ratio there may come within 1e-9 of the smallest upper bound
 * (the farthest point of the box, the smallest f). Appended to *out in the tree's order
 * (grown with m); -1 on OOM. Over them vpdsi_kd_list_min_ratio gives the same minimum. */
int vpdsi_kd_ratio_candidates(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *lo,
                              const double *hi, double r_lo, double r_hi, int rule, vpdsi_mem *m,
                              int32_t **out, size_t *count, size_t *cap);
/* The same over a list of such candidates of an enclosing box (with an r range no narrower),
 * in the list's order, into out (room for n; not overlapping from); their count. */
size_t vpdsi_kd_list_ratio_candidates(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                                      const int32_t *from, size_t n, const double *lo,
                                      const double *hi, double r_lo, double r_hi, int rule,
                                      int32_t *out);

/* All samples with |x - p| <= radius, appended to *out; -1 on OOM. */
int vpdsi_kd_radius(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *p,
                    double radius, vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap);

/* Squared distances between a point and a box: nearest and farthest point of the box (the
 * farthest for the image of p that makes it smallest), on the tree's torus. */
double vpdsi_box_mindist2(const vpdsi_kdtree *t, const double *p, const double *lo, const double *hi);
double vpdsi_box_maxdist2(const vpdsi_kdtree *t, const double *p, const double *lo, const double *hi);
#endif
