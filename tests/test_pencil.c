/* The ball two disks hold together (pencil.c), in 2D to 16D: every point of it lies in one of
 * the two disks, boundary included, far from the origin too; it is the smallest ball of their
 * pencil (its sphere is the one where theirs cross), so it holds boxes that neither disk holds
 * alone; the disks kept for a box are the three nearest to holding it; an image on a periodic
 * axis is taken nearest the box. */
#include "check.h"
#include "vpds.h"
#include "pencil.h"
#include <math.h>
#include <string.h>

static unsigned long long rng_state = 12345;
static double unit(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

static double dist2(int d, const double *a, const double *b)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) s += (a[k] - b[k]) * (a[k] - b[k]);
    return s;
}

/* A random point of the ball (y, r2), on its sphere one time in four. */
static void point_in(int d, const double *y, double r2, double *p)
{
    double u[VPDS_MAX_DIM], n = 0, rad;
    int k;
    for (k = 0; k < d; k++) {
        u[k] = unit() - 0.5;
        n += u[k] * u[k];
    }
    rad = sqrt(r2) * (unit() < 0.25 ? 1.0 : pow(unit(), 1.0 / d));
    for (k = 0; k < d; k++) p[k] = y[k] + rad * u[k] / sqrt(n);
}

/* Two crossing disks a, b near a box at offset `far_off`: each ball of the pencil stays inside
 * their union, and has the radius of the sphere where their spheres cross. */
static void check_pair(int d, double far_off, long *claimed, long *outside)
{
    vpdsi_pencil pen;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], a[VPDS_MAX_DIM], b[VPDS_MAX_DIM], period[VPDS_MAX_DIM] = {0};
    double fa = 0.5 + unit(), fb = 0.5 + unit(), D, y[VPDS_MAX_DIM], r2, h, cross2, p[VPDS_MAX_DIM];
    int k, i;
    for (k = 0; k < d; k++) {
        lo[k] = far_off + unit() * 0.1;
        hi[k] = lo[k] + 0.05 + unit() * 0.1;
        a[k] = lo[k] + (unit() - 0.5) * 0.5;
    }
    /* b at a distance D between |fa - fb| and fa + fb: the spheres cross */
    D = fabs(fa - fb) + (0.05 + 0.9 * unit()) * (fa + fb - fabs(fa - fb));
    {
        double u[VPDS_MAX_DIM], n = 0;
        for (k = 0; k < d; k++) {
            u[k] = unit() - 0.5;
            n += u[k] * u[k];
        }
        for (k = 0; k < d; k++) b[k] = a[k] + D * u[k] / sqrt(n);
    }
    vpdsi_pencil_reset(&pen, d, lo, hi);
    vpdsi_pencil_offer(&pen, d, a, fa * fa, 2.0 * fa * fa, lo, hi, period);
    vpdsi_pencil_offer(&pen, d, b, fb * fb, 2.0 * fb * fb, lo, hi, period);
    CHECK(pen.n == 2);
    if (!vpdsi_pencil_ball(&pen, d, 0, y, &r2)) {
        CHECK_MSG(0, "%dD: no ball for disks %g, %g at %g", d, fa, fb, D);
        return;
    }
    {
        double y2[VPDS_MAX_DIM], s2;
        CHECK(!vpdsi_pencil_ball(&pen, d, 1, y2, &s2)); /* one pair only */
    }
    /* the crossing sphere: at h from a along ab, of radius^2 fa^2 - h^2 */
    h = (D * D + fa * fa - fb * fb) / (2 * D);
    cross2 = fa * fa - h * h;
    if (h >= 0 && h <= D) /* else the smallest ball is one of the disks, clamped to it */
        CHECK_MSG(fabs(r2 - cross2) <= 1e-6 * (fa * fa + fb * fb),
                  "%dD: r^2 %.17g, the crossing sphere's %.17g", d, r2, cross2);
    for (i = 0; i < 200; i++) {
        point_in(d, y, r2, p);
        (*claimed)++;
        if (!(dist2(d, p, a) <= fa * fa || dist2(d, p, b) <= fb * fb)) (*outside)++;
    }
}

/* The case the sweep needs: a box across the radical line, near where the circles cross,
 * that neither disk holds, held by the ball. */
static void check_straddling_box(void)
{
    vpdsi_pencil pen;
    double lo[2] = {-0.3, 0.5}, hi[2] = {0.3, 0.6}, a[2] = {-0.6, 0}, b[2] = {0.6, 0}, period[2] = {0, 0};
    double y[2], r2, far2 = 0, fa2 = 0;
    int k;
    for (k = 0; k < 2; k++) {
        double e = fabs(a[k] - lo[k]) > fabs(a[k] - hi[k]) ? a[k] - lo[k] : a[k] - hi[k];
        fa2 += e * e;
    }
    CHECK(fa2 > 1.0); /* not held by a (nor, by symmetry, by b) */
    vpdsi_pencil_reset(&pen, 2, lo, hi);
    vpdsi_pencil_offer(&pen, 2, a, 1.0, fa2, lo, hi, period);
    vpdsi_pencil_offer(&pen, 2, b, 1.0, fa2, lo, hi, period);
    CHECK(vpdsi_pencil_ball(&pen, 2, 0, y, &r2));
    CHECK(fabs(y[0]) < 1e-15 && fabs(y[1]) < 1e-15 && fabs(r2 - 0.64) < 1e-8);
    for (k = 0; k < 2; k++) {
        double e = fabs(y[k] - lo[k]) > fabs(y[k] - hi[k]) ? y[k] - lo[k] : y[k] - hi[k];
        far2 += e * e;
    }
    CHECK_MSG(far2 <= r2, "the box's farthest corner %g from the ball's centre, radius %g", sqrt(far2), sqrt(r2));
    /* disks that do not cross (or barely touch) give no ball */
    vpdsi_pencil_reset(&pen, 2, lo, hi);
    b[0] = 1.4;
    vpdsi_pencil_offer(&pen, 2, a, 1.0, fa2, lo, hi, period);
    vpdsi_pencil_offer(&pen, 2, b, 1.0, fa2, lo, hi, period);
    CHECK(!vpdsi_pencil_ball(&pen, 2, 0, y, &r2));
}

/* The three disks nearest to holding the box are kept, nearest first; a periodic image is
 * taken nearest the box. */
static void check_offers(void)
{
    vpdsi_pencil pen;
    double lo[3] = {0.1, 0.1, 0.1}, hi[3] = {0.2, 0.2, 0.2}, period[3] = {1, 0, 0}, x[3];
    double q[6] = {5, 2, 9, 1, 3, 7};
    int i;
    vpdsi_pencil_reset(&pen, 3, lo, hi);
    for (i = 0; i < 6; i++) {
        x[0] = 0.95 - 0.01 * i; /* the image at -0.05 - 0.01 i is the near one */
        x[1] = x[2] = 0.15;
        vpdsi_pencil_offer(&pen, 3, x, 1.0, q[i], lo, hi, period);
    }
    CHECK(pen.n == VPDSI_PENCIL_KEEP);
    CHECK(pen.q[0] == 1 && pen.q[1] == 2 && pen.q[2] == 3);
    CHECK(fabs(pen.x[0][0] - (0.95 - 0.03 - 1)) < 1e-12 && pen.x[0][1] == 0.15);
    CHECK(fabs(pen.x[1][0] - (0.95 - 0.01 - 1)) < 1e-12);
}

int main(void)
{
    long claimed = 0, outside = 0;
    int d, t;
    for (d = 2; d <= VPDS_MAX_DIM; d++)
        for (t = 0; t < 300; t++) check_pair(d, t % 3 == 0 ? 0.0 : t % 3 == 1 ? 1e3 : -1e6, &claimed, &outside);
    CHECK_MSG(outside == 0, "%ld of %ld points of the balls outside both disks", outside, claimed);
    check_straddling_box();
    check_offers();
    CHECK_DONE();
}
