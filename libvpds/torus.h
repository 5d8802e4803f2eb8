/* Per-axis distances on a box whose periodic axes wrap (toroidal, minimum-image distance).
 * period[k] is the box side on a periodic axis and 0 on an open one; every distance in the
 * library goes through these, so a periodic axis changes no algorithm, only the metric. */
#ifndef VPDS_TORUS_H
#define VPDS_TORUS_H
#include <math.h>

/* |a - b| along an axis of period P (0: open). Points may lie up to a period outside the box. */
static inline double vpdsi_axis_diff(double a, double b, double P)
{
    double e = fabs(a - b);
    if (P > 0 && e > 0.5 * P) {
        if (e > P) e = fmod(e, P);
        if (e > 0.5 * P) e = P - e;
    }
    return e;
}

/* Distance from p to the interval [lo, hi] (hi - lo < P), nearest image. */
static inline double vpdsi_axis_gap(double p, double lo, double hi, double P)
{
    double best = p < lo ? lo - p : p > hi ? p - hi : 0, g;
    if (P > 0 && best > 0) {
        double q = p + P;
        g = q < lo ? lo - q : q > hi ? q - hi : 0;
        if (g < best) best = g;
        q = p - P;
        g = q < lo ? lo - q : q > hi ? q - hi : 0;
        if (g < best) best = g;
    }
    return best;
}

/* Farthest distance from p to [lo, hi], for the one image of p that makes it smallest: a box
 * is inside a disk of one image when this summed over axes is within the radius. */
static inline double vpdsi_axis_far(double p, double lo, double hi, double P)
{
    double a = fabs(p - lo), b = fabs(p - hi), best = a > b ? a : b;
    if (P > 0) {
        double q[2], qa, qb, f;
        int i;
        q[0] = p - P;
        q[1] = p + P;
        for (i = 0; i < 2; i++) {
            qa = fabs(q[i] - lo);
            qb = fabs(q[i] - hi);
            f = qa > qb ? qa : qb;
            if (f < best) best = f;
        }
    }
    return best;
}

static inline double vpdsi_torus_dist2(const double *a, const double *b, int dim,
                                       const double *period)
{
    double s = 0;
    int k;
    for (k = 0; k < dim; k++) {
        double e = vpdsi_axis_diff(a[k], b[k], period[k]);
        s += e * e;
    }
    return s;
}
#endif
