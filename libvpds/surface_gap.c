/* The largest gap on a triangle among a few points, by enumerating the vertices where it may lie.
 *
 * On the triangle's plane each |y - x_i|^2 is a strictly convex quadratic of (a, b), and two of
 * them differ by a linear function. As for a box (gap.c), at a maximiser y* of their minimum two
 * independent constraints meet: the bisectors of three nearest points, one bisector and an edge,
 * or two edges (a corner). Solving each such system and keeping the best point inside the
 * triangle finds y*. */
#include "surface_gap.h"
#include <math.h>

#define TRI_SLACK 1e-9 /* a vertex this far outside (in a, b) is round-off */

typedef struct {
    const double *e1, *e2, *z;
    int n;
    double best, ab[2];
} tri_gap;

static double tri_dist2(const tri_gap *g, const double *ab, int i)
{
    double s = 0;
    int k;
    for (k = 0; k < 3; k++) {
        double e = ab[0] * g->e1[k] + ab[1] * g->e2[k] - g->z[3 * i + k];
        s += e * e;
    }
    return s;
}

/* (a, b) replaces the best when its nearest point is farther than the best gap; any point at or
 * within the best gap ends the scan (the minimum is then no better). */
static void tri_consider(tri_gap *g, double a, double b)
{
    double ab[2], v = INFINITY, s;
    int i;
    if (a < -TRI_SLACK || b < -TRI_SLACK || a + b > 1 + TRI_SLACK) return;
    ab[0] = a < 0 ? 0 : a;
    ab[1] = b < 0 ? 0 : b;
    if (ab[0] + ab[1] > 1) { /* onto the hypotenuse, keeping the ratio */
        double sum = ab[0] + ab[1];
        ab[0] /= sum;
        ab[1] = 1 - ab[0];
    }
    for (i = 0; i < g->n; i++) {
        if (!((s = tri_dist2(g, ab, i)) > g->best)) return;
        if (s < v) v = s;
    }
    g->best = v;
    g->ab[0] = ab[0];
    g->ab[1] = ab[1];
}

/* The bisector of points i and j as alpha a + beta b = gamma (|y - z_i|^2 = |y - z_j|^2). */
static void tri_bisector(const tri_gap *g, int i, int j, double *row)
{
    int k;
    row[0] = row[1] = row[2] = 0;
    for (k = 0; k < 3; k++) {
        double dz = g->z[3 * j + k] - g->z[3 * i + k];
        row[0] += 2 * g->e1[k] * dz;
        row[1] += 2 * g->e2[k] * dz;
        row[2] += g->z[3 * j + k] * g->z[3 * j + k] - g->z[3 * i + k] * g->z[3 * i + k];
    }
}

/* Where a bisector row meets the three edges b = 0, a = 0 and a + b = 1. */
static void tri_edges(tri_gap *g, const double *row)
{
    double scale = fabs(row[0]) + fabs(row[1]);
    if (!(scale > 0)) return;
    if (fabs(row[0]) > 1e-13 * scale) tri_consider(g, row[2] / row[0], 0);
    if (fabs(row[1]) > 1e-13 * scale) tri_consider(g, 0, row[2] / row[1]);
    /* a + b = 1: alpha a + beta (1 - a) = gamma */
    if (fabs(row[0] - row[1]) > 1e-13 * scale) {
        double a = (row[2] - row[1]) / (row[0] - row[1]);
        tri_consider(g, a, 1 - a);
    }
}

/* Where two bisector rows meet (Cramer's rule; nothing when they are parallel). */
static void tri_meet(tri_gap *g, const double *r1, const double *r2)
{
    double det = r1[0] * r2[1] - r1[1] * r2[0];
    double scale = (fabs(r1[0]) + fabs(r1[1])) * (fabs(r2[0]) + fabs(r2[1]));
    if (!(fabs(det) > 1e-13 * scale)) return;
    tri_consider(g, (r1[2] * r2[1] - r1[1] * r2[2]) / det, (r1[0] * r2[2] - r1[2] * r2[0]) / det);
}

double vpdsi_surface_gap_max(const double *e1, const double *e2, const double *z, int n, double *ab)
{
    double rows[VPDSI_SURFACE_GAP_MAX_POINTS][3];
    tri_gap g;
    int i, j, k;
    g.e1 = e1;
    g.e2 = e2;
    g.z = z;
    g.n = n;
    g.best = -1;
    g.ab[0] = g.ab[1] = 0;
    tri_consider(&g, 0, 0);
    tri_consider(&g, 1, 0);
    tri_consider(&g, 0, 1);
    for (i = 0; i < n; i++) {
        for (j = i + 1; j < n; j++) tri_bisector(&g, i, j, rows[j]);
        for (j = i + 1; j < n; j++) {
            tri_edges(&g, rows[j]);
            for (k = j + 1; k < n; k++) tri_meet(&g, rows[j], rows[k]);
        }
    }
    ab[0] = g.ab[0];
    ab[1] = g.ab[1];
    return g.best;
}
