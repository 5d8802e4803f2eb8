/* The largest gap in a box among a few points: max over y in [lo, hi] of min_i |y - p_i|, found
 * exactly up to round-off (the stream's exact local search, algorithm version 5; in 5D to 7D
 * from version 9). */
#ifndef VPDS_GAP_H
#define VPDS_GAP_H

#define VPDSI_GAP_MAX_DIM 7    /* the vertex enumeration grows as C(n, d + 1) 2^d: small d only */
/* Versions 5-8 searched exactly up to 4D (5D and up to the tolerance); 9 up to 7D */
#define VPDSI_GAP_V5_MAX_DIM 4
#define VPDSI_GAP_MAX_POINTS 10 /* points one enumeration takes */

/* Faces argument of vpdsi_gap_max: every face of the box. */
#define VPDSI_GAP_ALL_FACES(dim) ((1u << (2 * (dim))) - 1u)

/* The squared largest gap over the box, and its maximiser in y; p holds n points of dim
 * coordinates (n >= 1, n <= VPDSI_GAP_MAX_POINTS, dim <= VPDSI_GAP_MAX_DIM), anywhere in space
 * (no torus: the caller passes the images that matter). faces (bit 2k: the low side of axis k,
 * 2k + 1 the high one) are those the maximiser may lie on: with a subset (a piece of a larger
 * box, its faces shared with that box), the answer is the largest gap among the vertices that
 * use only those faces (-1: none), a lower bound of the piece's; the larger box's maximum, when
 * it lies in this piece, is among them. */
double vpdsi_gap_max(int dim, const double *lo, const double *hi, unsigned faces, const double *p,
                     int n, double *y);

/* vpdsi_gap_max among the vertices whose gap exceeds floor: the same answer when it does, else
 * -1 and y untouched (a search passes the best it holds, and most subsets are skipped). */
double vpdsi_gap_max_above(int dim, const double *lo, const double *hi, unsigned faces,
                           const double *p, int n, double floor, double *y);

/* Whether p_j is nowhere in the box nearer than p_i: |y - p_i| < |y - p_j| for every y in it
 * (the difference of squares is linear in y, so its largest value over the box is per axis). */
int vpdsi_gap_dominated(int dim, const double *lo, const double *hi, const double *pi,
                        const double *pj);
#endif
