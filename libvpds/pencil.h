/* Two disks that hold a box together though neither holds it alone (algorithm version 12): in
 * six dimensions and up most of the sweep's cells lie where two spheres cross, and only a test
 * of the pair drops them before they split into 2^d children. */
#ifndef VPDS_PENCIL_H
#define VPDS_PENCIL_H
#include "samples.h"
#include "vpds.h"

#define VPDSI_PENCIL_KEEP 3 /* disks kept per box: the pairs of more cost more than they drop */
#define VPDSI_PENCIL_PAIRS (VPDSI_PENCIL_KEEP * (VPDSI_PENCIL_KEEP - 1) / 2)

/* The disks that reach into one box without holding it: the VPDSI_PENCIL_KEEP nearest to
 * holding it (least far^2 / f^2), each at the image of its centre nearest the box. */
typedef struct vpdsi_pencil {
    double x[VPDSI_PENCIL_KEEP][VPDS_MAX_DIM];
    double f2[VPDSI_PENCIL_KEEP], q[VPDSI_PENCIL_KEEP];
    double mag;   /* the box's largest coordinate: the scale of its rounding */
    int n;
} vpdsi_pencil;

/* Empty, for the box [lo, hi]. */
void vpdsi_pencil_reset(vpdsi_pencil *p, int d, const double *lo, const double *hi);
/* Offer the disk (centre x, squared radius f2) that reaches into the box (its nearest point
 * nearer than its radius) without holding it (far2, the squared distance to its farthest
 * point, above f2). period: the box side on a periodic axis, 0 on an open one. */
void vpdsi_pencil_offer(vpdsi_pencil *p, int d, const double *x, double f2, double far2,
                        const double *lo, const double *hi, const double *period);
/* Whether one sample of the list cand (n of them) holds the box [lo, hi] whole (its squared
 * farthest distance summed axis by axis, as the kd-tree's box test sums it), or the ball of a
 * pair of the kept ones does: each at the radius scale * f(r(x), r_lo) of `rule`, one pass
 * over the list for both. */
int vpdsi_pencil_list_holds(const vpdsi_kd_samples *s, const int32_t *cand, size_t n, int d,
                            vpds_rule rule, double scale, double r_lo, const double *lo,
                            const double *hi, const double *period);
/* Pair `pair` (0 .. VPDSI_PENCIL_PAIRS - 1) of the kept disks a, b: a ball (centre y, squared
 * radius *r2) inside their union. Of the balls theta (|p - a|^2 - fa^2) + (1 - theta)
 * (|p - b|^2 - fb^2) <= 0 (a point of one has one term <= 0, so lies in a or b), the one centred
 * on their radical hyperplane, whose sphere is the sphere where theirs cross; shrunk by the
 * rounding of its centre and radius, so that no point outside a and b is ever claimed.
 * 0 when the pair is not kept or the disks do not cross. */
int vpdsi_pencil_ball(const vpdsi_pencil *p, int d, int pair, double *y, double *r2);
#endif
