/* The largest gap in a box among many points: max over y in [lo, hi] of min_i |y - p_i|, exactly
 * up to round-off, by branch and bound over halvings of the box down to boxes where few points
 * can be nearest (each solved by gap.h). The stream's exact search, algorithm version 5. */
#ifndef VPDS_GAP_SEARCH_H
#define VPDS_GAP_SEARCH_H
#include "gap.h"
#include <stdint.h>

#define VPDSI_GAP_SEARCH_DEPTH 8 /* depths of boxes (the box, then 7 halvings) before it gives up */
/* int32_t scratch a search among n points takes: one list of candidates per depth */
#define VPDSI_GAP_SCRATCH(n) ((size_t)(n) * (VPDSI_GAP_SEARCH_DEPTH + 1))

/* 1 with the squared largest gap in *best and its maximiser in y; 0 when there are no points
 * or the deepest boxes (VPDSI_GAP_SEARCH_DEPTH) have too many candidates. p holds n points
 * of dim coordinates (dim <= VPDSI_GAP_MAX_DIM), in plain space (the caller passes a torus's
 * images); scratch holds VPDSI_GAP_SCRATCH(n). */
int vpdsi_gap_search(int dim, const double *lo, const double *hi, const double *p, int n,
                     int32_t *scratch, double *best, double *y);
#endif
