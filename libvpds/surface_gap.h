/* The largest gap on a triangle among a few points of R^3: max over y in the triangle of
 * min_i |y - x_i|, found exactly up to round-off (the surface stream's exact local search for a
 * constant radius, algorithm version 7; gap.c is its form for boxes). */
#ifndef VPDS_SURFACE_GAP_H
#define VPDS_SURFACE_GAP_H

#define VPDSI_SURFACE_GAP_MAX_POINTS 12 /* the enumeration grows as C(n, 3) */

/* The triangle y(a, b) = X0 + a e1 + b e2, a, b >= 0, a + b <= 1; z holds n points (3 coordinates
 * each, relative to X0; 1 <= n <= VPDSI_SURFACE_GAP_MAX_POINTS). Returns the squared largest gap
 * and its maximiser's (a, b) in ab. */
double vpdsi_surface_gap_max(const double *e1, const double *e2, const double *z, int n, double *ab);
#endif
