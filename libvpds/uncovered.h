/* Two radii (Section 3.1): does a region still hold a point that no sample covers at
 * t * coverage? Decides the dart test (the paper's first option, exact) and the discard of a
 * cell whose R_c-neighbourhood V is covered (Figure 2). */
#ifndef VPDS_UNCOVERED_H
#define VPDS_UNCOVERED_H
#include "cells.h"
#include "context.h"

/* The uncovered-cell index and the search's scratch. */
typedef struct vpdsi_uncovered {
    /* per cell of the next level: it may hold an uncovered point (not inside one coverage
     * disk); filled by the sweep */
    uint8_t *flag; size_t cap_flag;
    /* a kd-tree of the flagged cells' centres answers "is U near?" */
    vpdsi_kdtree tree;
    double *x; size_t cap_x;
    double *r; size_t cap_r;
    uint8_t *f; size_t cap_f;
    double half;   /* largest half-diagonal of those cells */
    int ready;     /* the tree describes the current cells */
    int32_t *lists; size_t n_lists, cap_lists; /* candidate lists of a search, per depth */
    double *stack; size_t cap_stack;           /* boxes still to examine */
    uint64_t boxes; /* boxes examined so far: work units of the budget, as darts and cells */
    /* Version 4: what the questions learn about the indexed cells, so that later ones skip
     * it. Coverage at one scale only grows, so a cell shown covered stays covered, and a point
     * seen uncovered stays a witness until one conflict query says otherwise. */
    double *cbox; size_t cap_cbox;     /* per indexed cell: its box, dim lows then dim highs */
    double *wit; size_t cap_wit;       /* per indexed cell: dim coordinates and r of a witness */
    uint8_t *state; size_t cap_state;  /* per indexed cell: VPDSI_CELL_* */
    int32_t *centre_of; size_t cap_centre_of; /* per cell of the level: its index, -1: none */
    /* the sweep's witnesses, one record per flagged cell of the next level, in order */
    double *nwit; size_t n_nwit, cap_nwit;
    size_t n_centre_of;
    int32_t *cand; size_t cap_cand;    /* the indexed cells near a dart */
    int32_t *grid_cand; size_t cap_grid_cand; /* a search's first list, from the background grid */
    /* Version 6: per indexed cell, which of its sub-boxes at depth sub_depth of the search's
     * halving a search showed covered (bit i: the i-th, first halving most significant), so that
     * the later questions on the cell (about ten per cell, Figure 2's neighbourhoods overlap)
     * skip them; 0: not kept (sub_depth * dim > 6) */
    uint64_t *sub; size_t cap_sub;
    int sub_depth;
    int learn;                         /* the index keeps what is learnt (version 4) */
} vpdsi_uncovered;

#define VPDSI_UNCOVERED_BUDGET 20000 /* boxes per question before answering "yes" conservatively */

#define VPDSI_CELL_UNKNOWN 0 /* may hold an uncovered point */
#define VPDSI_CELL_WITNESS 1 /* held one (wit) when last looked at */
#define VPDSI_CELL_COVERED 2 /* holds none: left out of every question (its centre's r is 0) */

/* What a search from a given first box reports beyond *found. */
typedef struct vpdsi_search_out {
    size_t budget;    /* in: boxes it may examine (past them it answers "uncovered") */
    double *witness;  /* in: room for dim + 1 doubles, the point found and r there (or NULL) */
    int found_point;  /* out: *found came from such a point */
    int in_indexed;   /* in: the anchor box lies in an indexed cell, whose centre is then near
                         every box of the search: the centres' test is skipped (same answers) */
    uint64_t *sub;    /* in/out (or NULL): the first box is an indexed cell's image and these are
                         its sub-boxes shown covered (vpdsi_uncovered.sub): skipped, and set */
    int sub_depth;    /* the depth of those sub-boxes */
} vpdsi_search_out;

static inline vpdsi_kd_samples vpdsi_uncovered_view(const vpdsi_uncovered *u)
{
    vpdsi_kd_samples v;
    v.x = u->x;
    v.r = u->r;
    v.flags = u->f;
    return v;
}

/* Version 6's sub-box bits: halvings kept per cell in dimension d (64 bits hold 2^(d * depth)
 * sub-boxes; 0: none kept), and the run of bits of a box `levels` halvings above them whose
 * first sub-box is `first` (a box's sub-boxes are consecutive: the first halving is the most
 * significant digit of their number). */
static inline int vpdsi_sub_depth(int d) { return d >= 1 && d <= 6 ? 6 / d : 0; }
static inline uint64_t vpdsi_sub_run(int d, int levels, unsigned first)
{
    unsigned n = 1u << ((unsigned)d * (unsigned)levels);
    return (n >= 64 ? ~UINT64_C(0) : (UINT64_C(1) << n) - 1) << first;
}

void vpdsi_uncovered_init(vpdsi_uncovered *u, int dim, const double *period);
void vpdsi_uncovered_release(vpdsi_uncovered *u, vpdsi_mem *m);

/* The region is every u with |u - a| <= t*coverage*f(r(a), r(u)) for a point a of the anchor
 * box [alo, ahi]. For a point anchor (alo == ahi, the dart y) r_anchor is r(y) and the test is
 * exact up to round-off; for a box it bounds r over the box from above and the region is
 * widened to its largest reach (0: the box itself, the sweep's check of a cell).
 * *found is 1 when an uncovered point of the region was seen, or when the search ran out of
 * its box budget or precision (a dart then becomes a sample that may cover nothing new). */
vpds_status vpdsi_uncovered_in(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t,
                               const double *alo, const double *ahi, double r_anchor, int *found);
/* vpdsi_uncovered_in from the first box `cell` (dim lows then highs, in coordinates around the
 * anchor: one indexed cell's image; NULL: the region's bounding box), with `out` (or NULL). */
vpds_status vpdsi_uncovered_in_box(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t,
                                   const double *alo, const double *ahi, double r_anchor,
                                   const double *cell, vpdsi_search_out *out, int *found);

/* Version 4's dart question (the dart y, r(y) = ry): vpdsi_uncovered_in(y, y) answered cell by
 * cell over the indexed cells near y, from their witnesses first; each cell the region holds
 * whole and shows covered leaves every later question. */
vpds_status vpdsi_uncovered_dart(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t,
                                 const double *y, double ry, int *accept);
/* The state of active cell `pos` for its children's flags: *state VPDSI_CELL_COVERED (they
 * need no search), VPDSI_CELL_WITNESS with *witness a point still uncovered, else UNKNOWN. */
vpds_status vpdsi_uncovered_parent(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t, size_t pos,
                                   int *state, const double **witness);
/* Whether active cell `pos` is an indexed cell of a version-4 index (its centre is listed). */
int vpdsi_uncovered_indexed(const vpdsi_uncovered *u, size_t pos);
/* Version 6: whether the sub-boxes of active cell `pos` shown covered hold child `child` of it
 * (bit k: the upper half on axis k; split 0: the cell itself) whole. */
int vpdsi_uncovered_child_covered(const vpdsi_uncovered *u, size_t pos, int d, int split, unsigned child);
/* Room for `more` sweep records; one record (witness NULL: none) per flagged cell, in order. */
int vpdsi_uncovered_reserve_records(vpdsi_uncovered *u, vpdsi_mem *m, int dim, size_t more);
void vpdsi_uncovered_record(vpdsi_uncovered *u, int dim, const double *witness);
/* The filter moved cell `from` of the next level to `to`. */
void vpdsi_uncovered_move(vpdsi_uncovered *u, size_t from, size_t to);

/* Index the centres of the cells `next` (geometry g) flagged in u->flag: every uncovered point
 * lies in one of them, now and after any later sample; with `learn`, keep what is learnt
 * (learn 2, version 6: the covered sub-boxes too). */
vpds_status vpdsi_uncovered_index(vpdsi_uncovered *u, vpdsi_store *st, const vpdsi_cells *next,
                                  const vpdsi_lattice *g, int learn);
/* Whether an indexed centre lies within thr of p (1 when no index is ready: "maybe"). */
int vpdsi_uncovered_near(const vpdsi_uncovered *u, const double *p, double thr);
#endif
