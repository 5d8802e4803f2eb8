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
} vpdsi_uncovered;

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
/* Index the centres of the cells `next` (geometry g) flagged in u->flag: every uncovered point
 * lies in one of them, now and after any later sample. */
vpds_status vpdsi_uncovered_index(vpdsi_uncovered *u, vpdsi_store *st, const vpdsi_cells *next,
                                  const vpdsi_lattice *g);
/* Distance from p to the nearest indexed centre (+INFINITY: none; 0 when no index is ready,
 * which answers "maybe" to every question). */
double vpdsi_uncovered_nearest(const vpdsi_uncovered *u, const double *p);
#endif
