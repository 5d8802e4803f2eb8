/* Branch and bound for the largest gap of a box (gap_search.h): a box keeps only the points that
 * may be nearest somewhere in it; with few left, their vertices give its maximum (gap.c), else
 * it splits in 2^d. A box whose every point lies within the best gap of some point is skipped.
 * The maximum is a vertex of bisectors and the outer box's faces, never of a cut between two
 * pieces: a piece enumerates only the outer faces it keeps (most pieces none). */
#include "gap_search.h"
#include <math.h>
#include <string.h>

#define D VPDSI_GAP_MAX_DIM

typedef struct {
    int d, n;          /* dimension; points */
    const double *p;   /* the points, d apart */
    int32_t *lists;    /* (VPDSI_GAP_SEARCH_DEPTH + 1) lists of n */
    double best, y[D]; /* the largest squared gap found and where */
} gap_box_search;

/* Points one enumeration takes (its cost grows as C(n, d + 1)); a box with more splits. */
static int points_per_box(int d)
{
    return d + 3 < VPDSI_GAP_MAX_POINTS ? d + 3 : VPDSI_GAP_MAX_POINTS;
}

/* The squared distance from p to the box's nearest point (far = 0) or its farthest corner. */
static double box_dist2(int d, const double *p, const double *lo, const double *hi, int far)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) {
        double a = lo[k] - p[k], b = p[k] - hi[k], e;
        if (far) e = fabs(a) > fabs(b) ? a : b;
        else e = a > 0 ? a : b > 0 ? b : 0;
        s += e * e;
    }
    return s;
}

/* The smallest farthest-corner distance of the listed points: no point of the box is farther
 * than it from them all, so it bounds the box's gap. */
static double reach2_of(const gap_box_search *q, const int32_t *list, int n, const double *lo,
                        const double *hi)
{
    double u2 = INFINITY;
    int i;
    for (i = 0; i < n; i++) {
        double f = box_dist2(q->d, q->p + (size_t)list[i] * q->d, lo, hi, 1);
        if (f < u2) u2 = f;
    }
    return u2;
}

/* The points of list `in` that may be nearest somewhere in the box into out: within its reach
 * (reach2_of), and not farther than another one everywhere in it. */
static int filter(const gap_box_search *q, const int32_t *in, int n_in, const double *lo,
                  const double *hi, double reach2, int32_t *out)
{
    int d = q->d, i, j, n = 0;
    for (i = 0; i < n_in; i++)
        if (box_dist2(d, q->p + (size_t)in[i] * d, lo, hi, 0) <= reach2 * (1 + 1e-9)) out[n++] = in[i];
    for (j = 0, n_in = n, n = 0; j < n_in; j++) {
        int dominated = 0;
        for (i = 0; i < n_in && !dominated; i++)
            dominated = i != j && vpdsi_gap_dominated(d, lo, hi, q->p + (size_t)out[i] * d,
                                                      q->p + (size_t)out[j] * d);
        if (!dominated) out[n++] = out[j];
    }
    return n;
}

/* Child b of the box [lo, hi] (bit k of b: the upper half on axis k) into [clo, chi], and the
 * outer faces it keeps: on each axis the one on its side (the low half the low one). Made
 * again where needed rather than kept for all 2^d children: a frame stays small in 6D. */
static unsigned child_box(int d, const double *lo, const double *hi, unsigned faces, unsigned b,
                          double *clo, double *chi)
{
    unsigned kept = 0;
    int k;
    for (k = 0; k < d; k++) {
        unsigned high = b >> k & 1u;
        double mid = 0.5 * (lo[k] + hi[k]);
        clo[k] = high ? mid : lo[k];
        chi[k] = high ? hi[k] : mid;
        kept |= faces & (1u << (2 * k + high));
    }
    return kept;
}

/* The largest squared gap over the box into q (its reach2 given); 0 when the depth runs out.
 * The children go in order of their reach, largest first, so that a good best comes early. */
static int search_box(gap_box_search *q, const double *lo, const double *hi, unsigned faces,
                      double reach2, int depth, int n_in)
{
    int d = q->d, n, i, order[1 << D];
    int32_t *in = q->lists + (size_t)depth * q->n, *out = in + q->n;
    double pts[VPDSI_GAP_MAX_POINTS * D], y[D], clo[D], chi[D], key[1 << D];
    unsigned b, nb = 1u << d;
    if (reach2 <= q->best) return 1; /* no point of the box beats the best */
    n = filter(q, in, n_in, lo, hi, reach2, out);
    /* the last depth takes as many points as one enumeration can */
    if (n <= points_per_box(d) || (depth + 1 == VPDSI_GAP_SEARCH_DEPTH && n <= VPDSI_GAP_MAX_POINTS)) {
        double v;
        for (i = 0; i < n; i++) memcpy(pts + i * d, q->p + (size_t)out[i] * d, (size_t)d * sizeof(double));
        v = vpdsi_gap_max_above(d, lo, hi, faces, pts, n, q->best, y);
        if (v > q->best) {
            q->best = v;
            memcpy(q->y, y, (size_t)d * sizeof(double));
        }
        return 1;
    }
    if (depth + 1 == VPDSI_GAP_SEARCH_DEPTH) return 0;
    for (b = 0; b < nb; b++) {
        child_box(d, lo, hi, faces, b, clo, chi);
        key[b] = reach2_of(q, out, n, clo, chi);
        /* insertion into order by key, largest first */
        for (i = (int)b; i > 0 && key[order[i - 1]] < key[b]; i--) order[i] = order[i - 1];
        order[i] = (int)b;
    }
    for (b = 0; b < nb; b++) {
        unsigned kept = child_box(d, lo, hi, faces, (unsigned)order[b], clo, chi);
        if (!search_box(q, clo, chi, kept, key[order[b]], depth + 1, n)) return 0;
    }
    return 1;
}

int vpdsi_gap_search(int dim, const double *lo, const double *hi, const double *p, int n,
                     int32_t *scratch, double *best, double *y)
{
    gap_box_search q;
    int i;
    if (n < 1 || dim < 1 || dim > D) return 0;
    q.d = dim;
    q.n = n;
    q.p = p;
    q.lists = scratch;
    q.best = -1;
    for (i = 0; i < n; i++) scratch[i] = i;
    if (!search_box(&q, lo, hi, VPDSI_GAP_ALL_FACES(dim), reach2_of(&q, scratch, n, lo, hi), 0, n) ||
        q.best < 0)
        return 0;
    *best = q.best;
    memcpy(y, q.y, (size_t)dim * sizeof(double));
    return 1;
}

#undef D
