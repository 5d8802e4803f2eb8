/* The largest gap in a box among a few points, by enumerating the vertices where it may lie.
 *
 * At a maximiser y* of min_i |y - p_i| over the box, let S be the nearest points and F the box
 * faces through y*. If the set A where the points of S stay equidistant and the faces of F stay
 * tight had a direction to move in, the common distance (strictly convex along any line) would
 * grow one way while the other points stay farther: so y* is the one point where d independent
 * constraints meet, m - 1 bisector hyperplanes of m points of S and d - m + 1 faces. Solving
 * every such system and keeping the best point inside the box finds y*. */
#include "gap.h"
#include <math.h>
#include <string.h>

#define D VPDSI_GAP_MAX_DIM
#define CLAMP_SLACK 1e-9 /* a vertex this far outside (relative to the half side) is round-off */

static double nearest2(int d, const double *q, int n, const double *y)
{
    double best = INFINITY;
    int i, k;
    for (i = 0; i < n; i++) {
        double s = 0;
        for (k = 0; k < d; k++) {
            double e = y[k] - q[i * D + k];
            s += e * e;
        }
        if (s < best) best = s;
    }
    return best;
}

/* Solve the m x m system a x = b by elimination with partial pivoting; 0 when singular. */
static int solve(int m, double a[D][D], double *b, double *x)
{
    int i, j, r;
    for (i = 0; i < m; i++) {
        int piv = i;
        double scale = 0;
        for (r = i; r < m; r++)
            if (fabs(a[r][i]) > fabs(a[piv][i])) piv = r;
        for (j = i; j < m; j++)
            if (fabs(a[piv][j]) > scale) scale = fabs(a[piv][j]);
        if (!(fabs(a[piv][i]) > 1e-13 * scale)) return 0;
        if (piv != i) {
            double t;
            for (j = 0; j < m; j++) {
                t = a[i][j];
                a[i][j] = a[piv][j];
                a[piv][j] = t;
            }
            t = b[i];
            b[i] = b[piv];
            b[piv] = t;
        }
        for (r = i + 1; r < m; r++) {
            double f = a[r][i] / a[i][i];
            for (j = i; j < m; j++) a[r][j] -= f * a[i][j];
            b[r] -= f * b[i];
        }
    }
    for (i = m - 1; i >= 0; i--) {
        double s = b[i];
        for (j = i + 1; j < m; j++) s -= a[i][j] * x[j];
        x[i] = s / a[i][i];
    }
    return 1;
}

typedef struct {
    int d, n;
    unsigned faces;      /* the faces a vertex may lie on: bit 2k low side of axis k, 2k + 1 high */
    const double *h;     /* half sides; coordinates are relative to the box centre */
    const double *q;     /* the points, D apart */
    double best, y[D];
} gap_search;

static void consider(gap_search *g, const double *y)
{
    double v = nearest2(g->d, g->q, g->n, y);
    if (v > g->best) {
        g->best = v;
        memcpy(g->y, y, sizeof g->y);
    }
}

/* The bisectors of s[0] with s[1..m-1]: rows A y = b (|y - s0|^2 = |y - s_r|^2). */
static void bisectors(const gap_search *g, const int *s, int m, double A[D][D], double *b)
{
    int r, k;
    for (r = 0; r < m - 1; r++) {
        const double *a0 = g->q + s[0] * D, *a1 = g->q + s[r + 1] * D;
        b[r] = 0;
        for (k = 0; k < g->d; k++) {
            A[r][k] = 2 * (a1[k] - a0[k]);
            b[r] += a1[k] * a1[k] - a0[k] * a0[k];
        }
    }
}

/* The vertices of m points' bisectors (A, b) with the faces fixing every axis outside
 * `free_axes`, each at its low or high side (of those allowed). */
static void vertices(gap_search *g, int m, unsigned free_axes, double A[D][D], const double *b)
{
    int d = g->d, rows = m - 1, r, k, fixed = d - rows;
    unsigned side;
    for (side = 0; side < (1u << fixed); side++) {
        double M[D][D], rhs[D], x[D], y[D];
        int j = 0, c, ok = 1;
        for (k = 0; k < d && ok; k++) {
            unsigned high;
            if (free_axes >> k & 1u) continue;
            high = side >> j++ & 1u;
            ok = g->faces >> (2 * k + high) & 1u;
            y[k] = high ? g->h[k] : -g->h[k];
        }
        if (!ok) continue;
        for (r = 0; r < rows; r++) {
            rhs[r] = b[r];
            for (k = 0, c = 0; k < d; k++) {
                if (free_axes >> k & 1u) M[r][c++] = A[r][k];
                else rhs[r] -= A[r][k] * y[k];
            }
        }
        if (rows > 0 && !solve(rows, M, rhs, x)) continue;
        for (k = 0, c = 0; k < d && ok; k++) {
            if (!(free_axes >> k & 1u)) continue;
            y[k] = x[c++];
            if (fabs(y[k]) > g->h[k] * (1 + CLAMP_SLACK)) ok = 0;
            else if (y[k] > g->h[k]) y[k] = g->h[k];
            else if (y[k] < -g->h[k]) y[k] = -g->h[k];
        }
        if (ok) consider(g, y);
    }
}

static int popcount(unsigned v)
{
    int c = 0;
    for (; v; v &= v - 1) c++;
    return c;
}

/* The squared distance from point i (q: centred coordinates) to the farthest corner of the
 * box's face on axis k, side `side`, summed term by term (a difference from the whole box's
 * farthest corner would cancel). */
static double face_far2(int d, const double *h, const double *qi, int k, int side)
{
    double s = 0;
    int j;
    for (j = 0; j < d; j++) {
        double e = j != k ? fabs(qi[j]) + h[j] : side ? h[j] - qi[j] : -h[j] - qi[j];
        s += e * e;
    }
    return s;
}

/* The faces (of those in `faces`) no single point holds within floor: on a face whose every
 * corner lies within floor of one point, the ball being convex, no vertex can exceed floor (the
 * margin covers round-off). */
static unsigned uncovered_faces(int d, const double *h, const double *q, int n, double floor)
{
    unsigned open = 0;
    int k, side, i;
    if (!(floor > 0)) return ~0u;
    for (k = 0; k < d; k++)
        for (side = 0; side < 2; side++) {
            int held = 0;
            for (i = 0; i < n && !held; i++) held = face_far2(d, h, q + i * D, k, side) * (1 + 1e-9) <= floor;
            if (!held) open |= 1u << (2 * k + side);
        }
    return open;
}

double vpdsi_gap_max_above(int d, const double *lo, const double *hi, unsigned faces,
                           const double *p, int n, double floor, double *y)
{
    double c[D], h[D], q[VPDSI_GAP_MAX_POINTS * D], A[D][D] = {{0}}, b[D] = {0};
    gap_search g;
    unsigned mask, axes;
    int i, k, usable[1 << D], any[D + 2] = {0};
    for (k = 0; k < d; k++) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        h[k] = 0.5 * (hi[k] - lo[k]);
    }
    for (i = 0; i < n; i++)
        for (k = 0; k < d; k++) q[i * D + k] = p[i * d + k] - c[k];
    faces &= uncovered_faces(d, h, q, n, floor);
    g.d = d;
    g.n = n;
    g.faces = faces;
    g.h = h;
    g.q = q;
    g.best = floor;
    memset(g.y, 0, sizeof g.y);
    /* the free axes of a vertex: each other axis needs an allowed face; most pieces of a
     * search have none, and only the interior vertices (m = d + 1) remain */
    for (axes = 0; axes < (1u << d); axes++) {
        usable[axes] = 1;
        for (k = 0; k < d; k++)
            if (!(axes >> k & 1u) && !(faces >> (2 * k) & 3u)) usable[axes] = 0;
        if (usable[axes]) any[popcount(axes) + 1] = 1;
    }
    /* subsets of one point: the box's corners (its distance is convex, largest at a corner) */
    if (usable[0]) vertices(&g, 1, 0u, A, b);
    for (mask = 1; mask < (1u << n); mask++) {
        int s[D + 1], m = popcount(mask);
        if (m < 2 || m > d + 1 || !any[m]) continue;
        for (i = 0, k = 0; i < n; i++)
            if (mask >> i & 1u) s[k++] = i;
        bisectors(&g, s, m, A, b);
        for (axes = 0; axes < (1u << d); axes++)
            if (usable[axes] && popcount(axes) == m - 1) vertices(&g, m, axes, A, b);
    }
    if (!(g.best > floor)) return -1;
    for (k = 0; k < d; k++) {
        double v = c[k] + g.y[k];
        y[k] = v < lo[k] ? lo[k] : v > hi[k] ? hi[k] : v;
    }
    return g.best;
}

double vpdsi_gap_max(int d, const double *lo, const double *hi, unsigned faces, const double *p,
                     int n, double *y)
{
    return vpdsi_gap_max_above(d, lo, hi, faces, p, n, -1, y);
}

int vpdsi_gap_dominated(int dim, const double *lo, const double *hi, const double *pi,
                        const double *pj)
{
    /* |y - pi|^2 - |y - pj|^2 = sum over axes of (pj - pi)(2 y - pi - pj) */
    double worst = 0;
    int k;
    for (k = 0; k < dim; k++) {
        double a = (pj[k] - pi[k]) * (2 * lo[k] - pi[k] - pj[k]);
        double b = (pj[k] - pi[k]) * (2 * hi[k] - pi[k] - pj[k]);
        worst += a > b ? a : b;
    }
    return worst < 0;
}

#undef D
