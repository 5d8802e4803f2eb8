/* Two radii (Section 3.1): does a region still hold a point that no sample covers at
 * t * coverage? Decides the dart test (the paper's first option, exact) and the discard of a
 * cell whose R_c-neighbourhood V is covered (Figure 2). */
#ifndef VPDS_UNCOVERED_H
#define VPDS_UNCOVERED_H
#include "vpds.h"

struct vpds_sampler;

/* The region is every u with |u - a| <= t*coverage*f(r(a), r(u)) for a point a of the anchor
 * box [alo, ahi]. For a point anchor (alo == ahi, the dart y) r_anchor is r(y) and the test is
 * exact up to round-off; for a box it bounds r over the box from above and the region is
 * widened to its largest reach (0: the box itself, the sweep's check of a cell).
 * *found is 1 when an uncovered point of the region was seen, or when the search ran out of
 * its box budget or precision (a dart then becomes a sample that may cover nothing new). */
vpds_status vpdsi_uncovered_in(struct vpds_sampler *s, const double *alo, const double *ahi,
                               double r_anchor, int *found);
/* Index the centres of the cells of run.next flagged in next_u (not inside one coverage disk):
 * every uncovered point lies in one of them, now and after any later sample. */
vpds_status vpdsi_uncovered_index(struct vpds_sampler *s);
/* Distance from p to the nearest indexed centre (+INFINITY: none; 0 when no index is ready,
 * which answers "maybe" to every question). */
double vpdsi_uncovered_nearest(const struct vpds_sampler *s, const double *p);
/* Upper bound of the distance at which a sample at a point of r <= r_hi covers (Table 1 reach:
 * r(u) <= r_hi + L |u - a| for the rules that read r(u)). */
double vpdsi_coverage_reach(const struct vpds_sampler *s, double r_hi);
#endif
