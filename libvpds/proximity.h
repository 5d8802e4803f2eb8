/* The per-sample tests of Table 2's primitives, shared by every neighbour index (kdtree.c,
 * ogrid.c) so that each answers with the same bits: an index only chooses which samples to
 * test. Distances are on the torus of `period` (0 on an open axis, torus.h). */
#ifndef VPDS_PROXIMITY_H
#define VPDS_PROXIMITY_H
#include "rules.h"
#include "samples.h"
#include "torus.h"

/* Whether sample i lies within lim of the box [lo, hi] (nearest image on a periodic axis): the
 * loop the near tests below share, each with its own lim. */
static inline int vpdsi_prox_within(const vpdsi_kd_samples *s, int32_t i, int dim, const double *period,
                                    const double *lo, const double *hi, double lim)
{
    const double *x = s->x + (size_t)i * (size_t)dim;
    double lim2 = lim * lim, g2 = 0;
    int k;
    for (k = 0; k < dim; k++) {
        double e = vpdsi_axis_gap(x[k], lo[k], hi[k], period[k]);
        g2 += e * e;
        if (g2 > lim2) return 0; /* the sum only grows */
    }
    return 1;
}

/* Near (vpdsi_kd_near_box): |x - box| <= scale * max(r(x), r_bound) * (1 + 1e-9) + slack. */
static inline int vpdsi_prox_near(const vpdsi_kd_samples *s, int32_t i, int dim, const double *period,
                                  const double *lo, const double *hi, double r_bound, double scale,
                                  double slack)
{
    double r = s->r[i];
    return vpdsi_prox_within(s, i, dim, period, lo, hi, scale * (r > r_bound ? r : r_bound) * (1 + 1e-9) + slack);
}

/* Near under a rule (vpdsi_ogrid_near_rule): |x - box| <= scale * f(r(x), r_bound) * (1 + 1e-9),
 * which every sample that may cover a part of the box for a point of r <= r_bound passes (f
 * grows with r at the point under every rule). */
static inline int vpdsi_prox_near_rule(const vpdsi_kd_samples *s, int32_t i, int dim, const double *period,
                                       const double *lo, const double *hi, double r_bound, int rule,
                                       double scale)
{
    return vpdsi_prox_within(s, i, dim, period, lo, hi,
                             scale * vpdsi_rule_f((vpds_rule)rule, s->r[i], r_bound) * (1 + 1e-9));
}

/* Sample i against the dart y of radius ry: 1 when it conflicts (|y - x| < scale f), -2 when
 * (lipschitz >= 0) its radius follows the sizing and breaks |r(x) - ry| <= L |x - y|, else 0. */
static inline int vpdsi_prox_conflict(const vpdsi_kd_samples *s, int32_t i, int dim,
                                      const double *period, const double *y, double ry,
                                      int rule, double scale, double lipschitz)
{
    double f = scale * vpdsi_rule_f((vpds_rule)rule, s->r[i], ry);
    double d2 = vpdsi_torus_dist2(y, s->x + (size_t)i * (size_t)dim, dim, period);
    if (lipschitz >= 0 && !(s->flags[i] & VPDSI_SAMPLE_OWN_RADIUS)) {
        double gap = fabs(ry - s->r[i]);
        double allowed = lipschitz * sqrt(d2) * (1 + 1e-9) + 1e-12 * (ry + s->r[i]);
        if (gap > allowed) return -2;
    }
    return d2 < f * f;
}

/* Lower bound of the farthest distance, along one axis, from a point of [a, b] to the nearest
 * sub-interval (centres c0, c1 of half-width w). */
static inline double vpdsi_prox_far_bound(double a, double b, double c0, double c1, double w,
                                          double P)
{
    double g0 = vpdsi_axis_gap(c0, a, b, P), g1 = vpdsi_axis_gap(c1, a, b, P);
    return w + (g0 < g1 ? g0 : g1);
}

/* Centres (c0, c1) and half-width w of the sub-intervals gather measures against, per axis. */
static inline void vpdsi_prox_gather_centres(int d, const double *lo, const double *hi,
                                             int split, double *c0, double *c1, double *w)
{
    int k;
    for (k = 0; k < d; k++) {
        double mid = 0.5 * (lo[k] + hi[k]);
        if (split) {
            c0[k] = 0.5 * (lo[k] + mid);
            c1[k] = 0.5 * (mid + hi[k]);
            w[k] = 0.25 * (hi[k] - lo[k]);
        } else {
            c0[k] = c1[k] = mid;
            w[k] = 0.5 * (hi[k] - lo[k]);
        }
    }
}

/* Gather's test of sample i: it may cover a whole sub-box at reach scale * f(r(x), r_hi). */
static inline int vpdsi_prox_may_cover(const vpdsi_kd_samples *s, int32_t i, int dim,
                                       const double *period, const double *c0, const double *c1,
                                       const double *w, double r_hi, int rule, double scale)
{
    const double *x = s->x + (size_t)i * (size_t)dim;
    double f = scale * vpdsi_rule_f((vpds_rule)rule, s->r[i], r_hi), f2 = f * f, need = 0;
    int k;
    for (k = 0; k < dim; k++) {
        double fb = vpdsi_prox_far_bound(x[k], x[k], c0[k], c1[k], w[k], period[k]);
        need += fb * fb;
        if (need > f2) return 0; /* the sum only grows */
    }
    return !(need > f2);
}
#endif
