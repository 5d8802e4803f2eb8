/* Bowyer-Watson insertion: the triangles whose circumcircle holds the new point (its cavity,
 * grown from the triangle that holds it) are replaced by a fan from the point to the cavity's
 * edges. Round-off near a tie can leave a cavity an edge of which the point does not see; the
 * triangle beyond such an edge joins the cavity, so that the fan never folds over. */
#include "delaunay.h"
#include <math.h>
#include <string.h>

#define VPDSI_DT_REPAIRS 1000 /* repairs of one cavity before the insert gives up (-2) */

/* > 0 when a, b, c turn counter-clockwise. Taken from the edge's lower end, so that the two
 * triangles of an edge never both find a point beyond it (a walk between them would not end). */
static double dt_orient(const double *a, const double *b, const double *c)
{
    if (b[0] < a[0] || (b[0] == a[0] && b[1] < a[1])) {
        const double *w = a;
        a = b;
        b = w;
        return -((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    }
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* > 0 when p lies inside the circle through a, b, c (counter-clockwise). */
static double dt_incircle(const double *a, const double *b, const double *c, const double *p)
{
    double ax = a[0] - p[0], ay = a[1] - p[1], bx = b[0] - p[0], by = b[1] - p[1];
    double cx = c[0] - p[0], cy = c[1] - p[1];
    return (ax * ax + ay * ay) * (bx * cy - cx * by) + (bx * bx + by * by) * (cx * ay - ax * cy) +
           (cx * cx + cy * cy) * (ax * by - bx * ay);
}

int vpdsi_dt_init(vpdsi_dt *dt, vpdsi_mem *m, const double *lo, const double *hi)
{
    /* far vertices on a circle of 3 box diagonals around the centre: a box point is within one
     * diagonal of a sample inside the box and at least 2.5 from each of them, so the Voronoi
     * diagram inside the box is the samples' own; nearer, they spare the circle tests of the
     * triangles they are part of the round-off of large coordinates */
    static const double dir[6] = {0.0, 1.0, -0.8660254037844386, -0.5, 0.8660254037844386, -0.5};
    double diag, c[2];
    int k;
    memset(dt, 0, sizeof *dt);
    diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]));
    for (k = 0; k < 2; k++) {
        dt->lo[k] = lo[k];
        dt->hi[k] = hi[k];
        c[k] = 0.5 * (lo[k] + hi[k]);
    }
    for (k = 0; k < 6; k++) dt->far_x[k] = c[k % 2] + 3 * diag * dir[k];
    if (vpdsi_mem_reserve(m, (void **)&dt->tv, &dt->cap_tv, 3 * 64, sizeof(uint32_t)) ||
        vpdsi_mem_reserve(m, (void **)&dt->tn, &dt->cap_tn, 3 * 64, sizeof(uint32_t))) {
        vpdsi_dt_release(dt, m);
        return -1;
    }
    for (k = 0; k < 3; k++) {
        dt->tv[k] = (uint32_t)k;
        dt->tn[k] = VPDSI_DT_NONE;
    }
    dt->n_tri = 1;
    return 0;
}

void vpdsi_dt_release(vpdsi_dt *dt, vpdsi_mem *m)
{
    vpdsi_mem_free(m, dt->tv, dt->cap_tv * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->tn, dt->cap_tn * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->cavity, dt->cap_cavity * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->rim, dt->cap_rim * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->fresh, dt->cap_fresh * sizeof(uint32_t));
    memset(dt, 0, sizeof *dt);
}

/* The triangle that holds p (on its boundary counts): a visibility walk, which ends in a
 * Delaunay triangulation; past n_tri steps (round-off), every triangle in turn. */
static uint32_t dt_locate(const vpdsi_dt *dt, const double *pts, const double *p, uint32_t t)
{
    size_t steps;
    if (t >= dt->n_tri) t = dt->last;
    for (steps = 0; steps <= dt->n_tri; steps++) {
        const uint32_t *v = dt->tv + 3 * (size_t)t;
        int i;
        for (i = 0; i < 3; i++)
            if (dt_orient(vpdsi_dt_point(dt, pts, v[(i + 1) % 3]), vpdsi_dt_point(dt, pts, v[(i + 2) % 3]), p) < 0)
                break;
        if (i == 3) return t;
        t = dt->tn[3 * (size_t)t + (size_t)i];
        if (t == VPDSI_DT_NONE) return VPDSI_DT_NONE; /* outside the far triangle */
    }
    for (t = 0; t < dt->n_tri; t++) {
        const uint32_t *v = dt->tv + 3 * (size_t)t;
        int i;
        for (i = 0; i < 3; i++)
            if (dt_orient(vpdsi_dt_point(dt, pts, v[(i + 1) % 3]), vpdsi_dt_point(dt, pts, v[(i + 2) % 3]), p) < 0)
                break;
        if (i == 3) return t;
    }
    return VPDSI_DT_NONE;
}

static int dt_push_cavity(vpdsi_dt *dt, vpdsi_mem *m, uint32_t t)
{
    if (vpdsi_mem_reserve(m, (void **)&dt->cavity, &dt->cap_cavity, dt->n_cavity + 1, sizeof(uint32_t)))
        return -1;
    dt->cavity[dt->n_cavity++] = t;
    return 0;
}

/* Whether triangle t is among cavity[from, to): a cavity holds a few triangles, so a scan
 * costs less than a mark per triangle (memory, and a cache miss). */
static int dt_among(const vpdsi_dt *dt, size_t from, size_t to, uint32_t t)
{
    size_t j;
    for (j = from; j < to; j++)
        if (dt->cavity[j] == t) return 1;
    return 0;
}

/* The round-off bound of dt_incircle, generously: its terms' magnitudes times 1e-10. */
static double dt_incircle_slack(const double *a, const double *b, const double *c, const double *p)
{
    double ax = a[0] - p[0], ay = a[1] - p[1], bx = b[0] - p[0], by = b[1] - p[1];
    double cx = c[0] - p[0], cy = c[1] - p[1];
    return 1e-10 * ((ax * ax + ay * ay) * (fabs(bx * cy) + fabs(cx * by)) +
                    (bx * bx + by * by) * (fabs(cx * ay) + fabs(ax * cy)) +
                    (cx * cx + cy * cy) * (fabs(ax * by) + fabs(bx * ay)));
}

/* How sure dt_holds must be that triangle u's circumcircle holds p: strictly (an insert's
 * cavity), within the round-off bound (a query that may take a triangle too many, never one
 * too few), or beyond it (a triangle surely in the cavity). */
enum { DT_STRICT, DT_LOOSE, DT_SURE };

static int dt_holds(const vpdsi_dt *dt, const double *pts, uint32_t u, const double *p, int how)
{
    const uint32_t *w = dt->tv + 3 * (size_t)u;
    const double *a = vpdsi_dt_point(dt, pts, w[0]), *b = vpdsi_dt_point(dt, pts, w[1]);
    const double *c = vpdsi_dt_point(dt, pts, w[2]);
    double ic = dt_incircle(a, b, c, p);
    if (how == DT_STRICT || (how == DT_LOOSE && ic > 0)) return ic > 0;
    return how == DT_LOOSE ? ic > -dt_incircle_slack(a, b, c, p) : ic > dt_incircle_slack(a, b, c, p);
}

/* The cavity of p from triangle t: every triangle reached through neighbours whose
 * circumcircle holds p (how: DT_STRICT for an insert, DT_LOOSE for a query). */
static int dt_grow_cavity(vpdsi_dt *dt, vpdsi_mem *m, const double *pts, const double *p, uint32_t t,
                          int how)
{
    size_t j;
    dt->n_cavity = 0;
    if (dt_push_cavity(dt, m, t)) return -1;
    for (j = 0; j < dt->n_cavity; j++) {
        uint32_t c = dt->cavity[j];
        int i;
        for (i = 0; i < 3; i++) {
            uint32_t u = dt->tn[3 * (size_t)c + (size_t)i];
            if (u == VPDSI_DT_NONE || dt_among(dt, 0, dt->n_cavity, u)) continue;
            if (dt_holds(dt, pts, u, p, how) && dt_push_cavity(dt, m, u)) return -1;
        }
    }
    return 0;
}

/* Whether p lies strictly between a and b on their line (given that it is on it). */
static int dt_between(const double *a, const double *b, const double *p)
{
    int k = fabs(b[0] - a[0]) >= fabs(b[1] - a[1]) ? 0 : 1;
    return a[k] < b[k] ? a[k] < p[k] && p[k] < b[k] : b[k] < p[k] && p[k] < a[k];
}

/* The cavity made star-shaped from p after round-off: cavity triangle c has an edge (a, b)
 * that p does not see. Exactly, p inside c's circumcircle sees every edge of the cavity; near
 * a tie (p all but on that circle) c leaves it, and the cavity keeps the triangles still
 * connected to the first. Only when p lies on the edge itself does the triangle beyond join
 * (and when c is the first triangle, which holds p). Returns -1 on OOM. */
static int dt_repair(vpdsi_dt *dt, vpdsi_mem *m, const double *pts, const double *p, size_t at, int i,
                     double o)
{
    uint32_t c = dt->cavity[at], u = dt->tn[3 * (size_t)c + (size_t)i];
    const double *a = vpdsi_dt_point(dt, pts, dt->tv[3 * (size_t)c + (size_t)(i + 1) % 3]);
    const double *b = vpdsi_dt_point(dt, pts, dt->tv[3 * (size_t)c + (size_t)(i + 2) % 3]);
    size_t j, kept;
    if (at == 0 || (o == 0 && dt_between(a, b, p))) return u == VPDSI_DT_NONE ? -2 : dt_push_cavity(dt, m, u);
    dt->cavity[at] = dt->cavity[--dt->n_cavity];
    /* the triangles still reached from the first through the cavity stay in it: [0, kept) */
    for (kept = 1, j = 0; j < kept; j++) {
        uint32_t t = dt->cavity[j];
        int w;
        for (w = 0; w < 3; w++) {
            uint32_t v = dt->tn[3 * (size_t)t + (size_t)w];
            size_t q;
            if (v == VPDSI_DT_NONE || dt_among(dt, 0, kept, v)) continue;
            for (q = kept; q < dt->n_cavity && dt->cavity[q] != v; q++) {}
            if (q == dt->n_cavity) continue;
            dt->cavity[q] = dt->cavity[kept];
            dt->cavity[kept++] = v;
        }
    }
    dt->n_cavity = kept;
    return 0;
}

/* The cavity's edges (a, b, the triangle outside) into rim, each seen by p (counter-clockwise
 * from it), after dt_repair of any edge p does not see. Then they must form one cycle: k
 * triangles with no vertex inside have k + 2 edges, each vertex starting one. */
static int dt_collect_rim(vpdsi_dt *dt, vpdsi_mem *m, const double *pts, const double *p)
{
    size_t j, i2, repairs = 0;
again:
    dt->n_rim = 0;
    for (j = 0; j < dt->n_cavity; j++) {
        uint32_t c = dt->cavity[j];
        int i;
        for (i = 0; i < 3; i++) {
            uint32_t u = dt->tn[3 * (size_t)c + (size_t)i];
            uint32_t a = dt->tv[3 * (size_t)c + (size_t)(i + 1) % 3], b = dt->tv[3 * (size_t)c + (size_t)(i + 2) % 3];
            double o;
            if (u != VPDSI_DT_NONE && dt_among(dt, 0, dt->n_cavity, u)) continue;
            o = dt_orient(vpdsi_dt_point(dt, pts, a), vpdsi_dt_point(dt, pts, b), p);
            if (o <= 0) {
                int e = ++repairs > VPDSI_DT_REPAIRS ? -2 : dt_repair(dt, m, pts, p, j, i, o);
                if (e) return e;
                goto again;
            }
            if (vpdsi_mem_reserve(m, (void **)&dt->rim, &dt->cap_rim, 3 * (dt->n_rim + 1), sizeof(uint32_t)))
                return -1;
            dt->rim[3 * dt->n_rim] = a;
            dt->rim[3 * dt->n_rim + 1] = b;
            dt->rim[3 * dt->n_rim + 2] = u;
            dt->n_rim++;
        }
    }
    if (dt->n_rim != dt->n_cavity + 2) return -2;
    for (j = 0; j < dt->n_rim; j++) {
        size_t starts = 0;
        for (i2 = 0; i2 < dt->n_rim; i2++) starts += dt->rim[3 * i2] == dt->rim[3 * j + 1];
        if (starts != 1) return -2;
    }
    return 0;
}

/* The index of the rim edge whose end `which` (0: a, 1: b) is vertex w. */
static size_t dt_rim_at(const vpdsi_dt *dt, int which, uint32_t w)
{
    size_t j;
    for (j = 0; j < dt->n_rim; j++)
        if (dt->rim[3 * j + (size_t)which] == w) return j;
    return 0; /* unreachable after dt_collect_rim's check */
}

/* The fan from v over the rim, in the cavity's slots and two new ones (after the reserve). */
static void dt_fan(vpdsi_dt *dt, uint32_t v)
{
    size_t j;
    for (j = 0; j < dt->n_rim; j++)
        dt->fresh[j] = j < dt->n_cavity ? dt->cavity[j] : (uint32_t)dt->n_tri++;
    for (j = 0; j < dt->n_rim; j++) {
        size_t s = dt->fresh[j];
        uint32_t a = dt->rim[3 * j], b = dt->rim[3 * j + 1], u = dt->rim[3 * j + 2];
        dt->tv[3 * s] = v;
        dt->tv[3 * s + 1] = a;
        dt->tv[3 * s + 2] = b;
        dt->tn[3 * s] = u;
        if (u != VPDSI_DT_NONE) { /* u's edge (b, a) now faces s */
            int i;
            for (i = 0; i < 3; i++) {
                uint32_t w = dt->tv[3 * (size_t)u + (size_t)i];
                if (w != a && w != b) dt->tn[3 * (size_t)u + (size_t)i] = (uint32_t)s;
            }
        }
    }
    for (j = 0; j < dt->n_rim; j++) {
        size_t s = dt->fresh[j];
        /* edge (b, v) is the next fan triangle's (v, a); edge (v, a) the previous one's (b, v) */
        dt->tn[3 * s + 1] = dt->fresh[dt_rim_at(dt, 0, dt->rim[3 * j + 1])];
        dt->tn[3 * s + 2] = dt->fresh[dt_rim_at(dt, 1, dt->rim[3 * j])];
    }
    dt->last = dt->fresh[0];
}

int vpdsi_dt_insert(vpdsi_dt *dt, vpdsi_mem *m, const double *pts, size_t index, uint32_t hint)
{
    const double *p = pts + 2 * index;
    uint32_t t, v = (uint32_t)index + VPDSI_DT_FAR;
    int i, e;
    if (index >= VPDSI_DT_MAX_POINTS) return -2;
    if (vpdsi_mem_reserve(m, (void **)&dt->tv, &dt->cap_tv, 3 * (dt->n_tri + 2), sizeof(uint32_t)) ||
        vpdsi_mem_reserve(m, (void **)&dt->tn, &dt->cap_tn, 3 * (dt->n_tri + 2), sizeof(uint32_t)))
        return -1;
    t = dt_locate(dt, pts, p, hint);
    if (t == VPDSI_DT_NONE) return -2;
    for (i = 0; i < 3; i++) {
        const double *w = vpdsi_dt_point(dt, pts, dt->tv[3 * (size_t)t + (size_t)i]);
        if (w[0] == p[0] && w[1] == p[1]) return 1;
    }
    if ((e = dt_grow_cavity(dt, m, pts, p, t, DT_STRICT)) != 0) return e;
    if ((e = dt_collect_rim(dt, m, pts, p)) != 0) return e;
    if (vpdsi_mem_reserve(m, (void **)&dt->fresh, &dt->cap_fresh, dt->n_rim, sizeof(uint32_t))) return -1;
    dt_fan(dt, v);
    return 0;
}

int vpdsi_dt_near(vpdsi_dt *dt, vpdsi_mem *m, const double *pts, const double *p, uint32_t hint)
{
    /* the cavity is connected: grown from the hint when p lies inside its circumcircle by
     * more than round-off, else from the triangle that holds p */
    uint32_t t = hint < dt->n_tri && dt_holds(dt, pts, hint, p, DT_SURE) ? hint : dt_locate(dt, pts, p, hint);
    if (t == VPDSI_DT_NONE) return -2;
    return dt_grow_cavity(dt, m, pts, p, t, DT_LOOSE);
}
