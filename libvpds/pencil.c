/* The ball two disks hold together (pencil.h). */
#include "pencil.h"
#include "rules.h"
#include "torus.h"
#include <float.h>
#include <math.h>
#include <string.h>

void vpdsi_pencil_reset(vpdsi_pencil *p, int d, const double *lo, const double *hi)
{
    double mag = 0;
    int k;
    for (k = 0; k < d; k++) {
        if (fabs(lo[k]) > mag) mag = fabs(lo[k]);
        if (fabs(hi[k]) > mag) mag = fabs(hi[k]);
    }
    p->mag = mag;
    p->n = 0;
}

void vpdsi_pencil_offer(vpdsi_pencil *p, int d, const double *x, double f2, double far2,
                        const double *lo, const double *hi, const double *period)
{
    double q = far2 / f2;
    int k, at = p->n < VPDSI_PENCIL_KEEP ? p->n++ : VPDSI_PENCIL_KEEP;
    /* insertion by q: the disks nearest to holding the box alone make the best pairs */
    while (at > 0 && p->q[at - 1] > q) {
        if (at < VPDSI_PENCIL_KEEP) {
            p->q[at] = p->q[at - 1];
            p->f2[at] = p->f2[at - 1];
            memcpy(p->x[at], p->x[at - 1], (size_t)d * sizeof(double));
        }
        at--;
    }
    if (at == VPDSI_PENCIL_KEEP) return;
    p->q[at] = q;
    p->f2[at] = f2;
    for (k = 0; k < d; k++) {
        /* the image nearest the box's centre (an image farther off only overstates distances) */
        double v = x[k], mid = 0.5 * (lo[k] + hi[k]), P = period[k];
        if (P > 0) v -= P * floor((v - mid) / P + 0.5);
        p->x[at][k] = v;
    }
}

int vpdsi_pencil_ball(const vpdsi_pencil *p, int d, int pair, double *y, double *r2)
{
    /* pairs (0, 1), (0, 2), (1, 2), ...: the nearest to holding the box first */
    int i = 0, j = 1, k, at;
    double D2 = 0, th, s, rho, slack;
    for (at = 0; at < pair; at++)
        if (++j == p->n) j = ++i + 1;
    if (j >= p->n) return 0;
    for (k = 0; k < d; k++) {
        double e = p->x[i][k] - p->x[j][k];
        D2 += e * e;
    }
    if (!(D2 > 0)) return 0;
    th = 0.5 * (D2 - p->f2[i] + p->f2[j]) / D2;
    if (th < 0) th = 0;
    if (th > 1) th = 1;
    s = th * p->f2[i] + (1 - th) * p->f2[j] - th * (1 - th) * D2;
    /* the sum's rounding is far below 1e-9 of its terms; the centre's, below the slack */
    s -= 1e-9 * (p->f2[i] + p->f2[j] + D2);
    if (!(s > 0)) return 0;
    /* a coordinate's rounding, in the centre and in each axis's distance to the box */
    slack = 4 * (d + 4) * DBL_EPSILON * (p->mag + sqrt(p->f2[i] > p->f2[j] ? p->f2[i] : p->f2[j]));
    rho = sqrt(s) - slack;
    if (!(rho > 0)) return 0;
    for (k = 0; k < d; k++) y[k] = th * p->x[i][k] + (1 - th) * p->x[j][k];
    *r2 = rho * rho;
    return 1;
}

/* The disk (x, f2) against the box: 1 when it holds the box whole; else 0, offered when it
 * reaches into the box. */
static int take(vpdsi_pencil *p, int d, const double *x, double f2, const double *lo,
                const double *hi, const double *period)
{
    double far2 = 0, near2 = 0;
    int k;
    for (k = 0; k < d; k++) {
        double e = vpdsi_axis_far(x[k], lo[k], hi[k], period[k]);
        far2 += e * e;
    }
    if (far2 <= f2) return 1;
    for (k = 0; k < d; k++) {
        double g = vpdsi_axis_gap(x[k], lo[k], hi[k], period[k]);
        near2 += g * g;
    }
    if (near2 < f2) vpdsi_pencil_offer(p, d, x, f2, far2, lo, hi, period);
    return 0;
}

/* Whether the ball of a pair of the kept disks holds the box whole. */
static int pair_holds(const vpdsi_pencil *p, int d, const double *lo, const double *hi)
{
    int pair, k;
    for (pair = 0; pair < VPDSI_PENCIL_PAIRS; pair++) {
        double y[VPDS_MAX_DIM], r2, far2 = 0;
        if (!vpdsi_pencil_ball(p, d, pair, y, &r2)) continue;
        for (k = 0; k < d; k++) {
            double e = vpdsi_axis_far(y[k], lo[k], hi[k], 0.0);
            far2 += e * e;
        }
        if (far2 <= r2) return 1;
    }
    return 0;
}

int vpdsi_pencil_list_holds(const vpdsi_kd_samples *s, const int32_t *cand, size_t n, int d,
                            vpds_rule rule, double scale, double r_lo, const double *lo,
                            const double *hi, const double *period)
{
    vpdsi_pencil pen;
    size_t j;
    vpdsi_pencil_reset(&pen, d, lo, hi);
    for (j = 0; j < n; j++) {
        double f = scale * vpdsi_rule_f(rule, s->r[cand[j]], r_lo);
        if (f > 0 && take(&pen, d, s->x + (size_t)cand[j] * (size_t)d, f * f, lo, hi, period))
            return 1;
    }
    return pair_holds(&pen, d, lo, hi);
}
