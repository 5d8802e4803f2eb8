/* The stream's farthest point in 2D from the Voronoi diagram (voids.h): one candidate per
 * Delaunay triangle, the triangles in an indexed max-heap (index_heap.h). */
#include "voids.h"
#include "torus.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

void vpdsi_voids_init(vpdsi_voids *vd)
{
    memset(vd, 0, sizeof *vd);
}

void vpdsi_voids_release(vpdsi_voids *vd, vpdsi_mem *m)
{
    vpdsi_dt_release(&vd->dt, m);
    vpdsi_index_heap_release(&vd->heap, m);
    vpdsi_mem_free(m, vd->batch, vd->cap_batch * sizeof(uint64_t));
    vpdsi_voids_init(vd);
}

static double vd_dist2(const double *a, const double *b)
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]);
}

static int vd_in_box(const vpdsi_dt *dt, const double *y)
{
    return y[0] >= dt->lo[0] && y[0] <= dt->hi[0] && y[1] >= dt->lo[1] && y[1] <= dt->hi[1];
}

/* The centre of the circle through a, b, c (counter-clockwise); -1 when they are collinear. */
static int vd_circumcentre(const double *a, const double *b, const double *c, double *y)
{
    double bx = b[0] - a[0], by = b[1] - a[1], cx = c[0] - a[0], cy = c[1] - a[1];
    double den = 2 * (bx * cy - by * cx), b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    if (!(den > 0)) return -1;
    y[0] = a[0] + (cy * b2 - by * c2) / den;
    y[1] = a[1] + (bx * c2 - cx * b2) / den;
    return 0;
}

/* The farthest point where the bisector of samples p, q meets the box's boundary within
 * their Voronoi edge: no nearer to o1 (opposite in this triangle) or o2 (across the edge)
 * than to them, which on the bisector is exactly the segment between the two circumcentres.
 * Its squared gap, or -1. */
static double vd_edge_crossing(const vpdsi_voids *vd, const double *pts, uint32_t p, uint32_t q,
                               uint32_t o1, uint32_t o2, double *y)
{
    const vpdsi_dt *dt = &vd->dt;
    const double *a = vpdsi_dt_point(dt, pts, p), *b = vpdsi_dt_point(dt, pts, q);
    double best = -1;
    int k, side;
    for (k = 0; k < 2; k++) {
        int j = 1 - k;
        double dk = b[k] - a[k], dj = b[j] - a[j];
        if (dj == 0) continue; /* the bisector is parallel to the sides across axis k */
        for (side = 0; side < 2; side++) {
            double x[2], g2, s = side ? dt->hi[k] : dt->lo[k];
            /* a valid crossing is as far from a as from its nearest sample: within the bound */
            if (fabs(a[k] - s) > vd->bound) continue;
            x[k] = s;
            x[j] = 0.5 * (a[j] + b[j]) - (s - 0.5 * (a[k] + b[k])) * dk / dj;
            if (!(x[j] >= dt->lo[j] && x[j] <= dt->hi[j])) continue;
            g2 = vd_dist2(x, a);
            if (vd_dist2(x, b) < g2) g2 = vd_dist2(x, b);
            if (g2 <= best) continue;
            if (o1 >= VPDSI_DT_FAR && vd_dist2(x, vpdsi_dt_point(dt, pts, o1)) < g2) continue;
            if (o2 != VPDSI_DT_NONE && o2 >= VPDSI_DT_FAR && vd_dist2(x, vpdsi_dt_point(dt, pts, o2)) < g2)
                continue;
            best = g2;
            y[0] = x[0];
            y[1] = x[1];
        }
    }
    return best;
}

/* Whether a side of the box lies within `bound` of a (the filter of vd_edge_crossing, before
 * the triangle across the edge is read). */
static int vd_near_side(const vpdsi_dt *dt, const double *a, double bound)
{
    return a[0] - dt->lo[0] <= bound || dt->hi[0] - a[0] <= bound || a[1] - dt->lo[1] <= bound ||
           dt->hi[1] - a[1] <= bound;
}

/* Triangle t's candidate: its circumcentre when inside the box (a Voronoi vertex), and the
 * boundary crossings of the edges it owns (an edge (p, q) belongs to the triangle that sees
 * p < q, so each edge is computed once). Its squared gap (-1: none) and its point y. */
static double vd_candidate(const vpdsi_voids *vd, const double *pts, uint32_t t, double *y)
{
    const vpdsi_dt *dt = &vd->dt;
    const uint32_t *v = dt->tv + 3 * (size_t)t;
    double best = -1, z[2] = {0, 0};
    int i;
    if (v[0] >= VPDSI_DT_FAR && v[1] >= VPDSI_DT_FAR && v[2] >= VPDSI_DT_FAR) {
        const double *a = vpdsi_dt_point(dt, pts, v[0]), *b = vpdsi_dt_point(dt, pts, v[1]);
        const double *c = vpdsi_dt_point(dt, pts, v[2]);
        if (vd_circumcentre(a, b, c, z) == 0 && vd_in_box(dt, z)) {
            best = vd_dist2(z, a);
            if (vd_dist2(z, b) < best) best = vd_dist2(z, b);
            if (vd_dist2(z, c) < best) best = vd_dist2(z, c);
            y[0] = z[0];
            y[1] = z[1];
        }
    }
    for (i = 0; i < 3; i++) {
        uint32_t p = v[(i + 1) % 3], q = v[(i + 2) % 3], u = dt->tn[3 * (size_t)t + (size_t)i];
        uint32_t o2 = VPDSI_DT_NONE;
        double g2;
        int w;
        if (p >= q || p < VPDSI_DT_FAR) continue;
        if (!vd_near_side(dt, vpdsi_dt_point(dt, pts, p), vd->bound)) continue; /* none within it */
        if (u != VPDSI_DT_NONE)
            for (w = 0; w < 3; w++) {
                uint32_t c = dt->tv[3 * (size_t)u + (size_t)w];
                if (c != p && c != q) o2 = c;
            }
        g2 = vd_edge_crossing(vd, pts, p, q, v[i], o2, z);
        if (g2 > best) {
            best = g2;
            y[0] = z[0];
            y[1] = z[1];
        }
    }
    return best;
}

static void vd_update(vpdsi_voids *vd, const double *pts, uint32_t t)
{
    double y[2];
    vpdsi_index_heap_set(&vd->heap, t, vd_candidate(vd, pts, t, y));
}

/* Room for the entries of two more triangles. */
static int vd_reserve(vpdsi_voids *vd, vpdsi_mem *m)
{
    return vpdsi_index_heap_reserve(&vd->heap, m, vd->dt.n_tri + 2);
}

static int vd_start(vpdsi_voids *vd, vpdsi_mem *m, const double *lo, const double *hi)
{
    int k;
    if (vpdsi_dt_init(&vd->dt, m, lo, hi)) return -1;
    if (vd_reserve(vd, m)) {
        vpdsi_voids_release(vd, m);
        return -1;
    }
    for (k = 0; k < 4; k++) vd->corner_d2[k] = INFINITY;
    vd->hint = VPDSI_DT_NONE;
    vd->bound = INFINITY;
    vd->ready = 1;
    return 0;
}

/* Insert sample i (in the box). */
static int vd_insert(vpdsi_voids *vd, vpdsi_mem *m, const double *pts, size_t i)
{
    const vpdsi_dt *dt = &vd->dt;
    const double *p = pts + 2 * i;
    size_t j;
    int e, k;
    if (vd_reserve(vd, m)) return -1;
    e = vpdsi_dt_insert(&vd->dt, m, pts, i, vd->hint);
    if (e < 0) return e;
    if (e == 0) {
        /* the triangles across the rim keep their keys: each lost part of its Voronoi edge,
         * so its candidate can only fall, and vpdsi_voids_farthest mends a key that did */
        for (j = 0; j < dt->n_rim; j++) vd_update(vd, pts, dt->fresh[j]);
    }
    for (k = 0; k < 4; k++) {
        double c[2], d2;
        c[0] = k & 1 ? dt->hi[0] : dt->lo[0];
        c[1] = k & 2 ? dt->hi[1] : dt->lo[1];
        d2 = vd_dist2(c, p);
        if (d2 < vd->corner_d2[k]) vd->corner_d2[k] = d2;
    }
    vd->hint = VPDSI_DT_NONE;
    return 0;
}

/* Interleaves the bits of x and y (16 each). */
static uint32_t vd_morton(uint32_t x, uint32_t y)
{
    uint32_t code = 0;
    int b;
    for (b = 15; b >= 0; b--) code = code << 2 | ((y >> b) & 1u) << 1 | ((x >> b) & 1u);
    return code;
}

static int vd_cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* The samples [vd->n, n) as a batch in Morton order of a 2^16 grid over the box; -2 when one
 * lies outside the box. */
static int vd_make_batch(vpdsi_voids *vd, vpdsi_mem *m, const double *pts, size_t n)
{
    const vpdsi_dt *dt = &vd->dt;
    size_t i, count = n - vd->n;
    if (vpdsi_mem_reserve(m, (void **)&vd->batch, &vd->cap_batch, count, sizeof(uint64_t))) return -1;
    for (i = 0; i < count; i++) {
        const double *p = pts + 2 * (vd->n + i);
        uint32_t q[2];
        int k;
        if (!vd_in_box(dt, p)) return -2;
        for (k = 0; k < 2; k++) {
            double u = (p[k] - dt->lo[k]) / (dt->hi[k] - dt->lo[k]) * 65536.0;
            q[k] = u >= 65535.0 ? 65535u : (uint32_t)u;
        }
        vd->batch[i] = (uint64_t)vd_morton(q[0], q[1]) << 32 | (uint64_t)(vd->n + i);
    }
    qsort(vd->batch, count, sizeof(uint64_t), vd_cmp_u64);
    vd->n_batch = count;
    vd->at = 0;
    vd->n = n;
    return 0;
}

int vpdsi_voids_sync(vpdsi_voids *vd, vpdsi_mem *m, const double *lo, const double *hi,
                     const double *pts, size_t n, double bound)
{
    int e;
    if (n > VPDSI_DT_MAX_POINTS) return -2;
    if (!vd->ready && vd_start(vd, m, lo, hi)) return -1;
    vd->bound = bound;
    for (;;) {
        while (vd->at < vd->n_batch) { /* a batch first, to its end */
            if ((e = vd_insert(vd, m, pts, (size_t)(vd->batch[vd->at] & 0xffffffffu))) != 0) return e;
            vd->at++;
        }
        if (vd->n_batch) {
            vpdsi_mem_free(m, vd->batch, vd->cap_batch * sizeof(uint64_t));
            vd->batch = NULL;
            vd->cap_batch = vd->n_batch = vd->at = 0;
        }
        if (vd->n + 1 < n) {
            if ((e = vd_make_batch(vd, m, pts, n)) != 0) return e;
            continue;
        }
        if (vd->n == n) return 0;
        if (!vd_in_box(&vd->dt, pts + 2 * vd->n)) return -2;
        if ((e = vd_insert(vd, m, pts, vd->n)) != 0) return e;
        vd->n++;
        return 0;
    }
}

double vpdsi_voids_farthest(vpdsi_voids *vd, const double *pts, double *y)
{
    double best = -1;
    int k;
    /* a key may lie above its triangle's candidate (vd_insert): mended at the top until the
     * top's holds; every other key is at or above its candidate, so the top is the largest
     * (ties: the lowest index, as with keys kept exact) */
    while (vd->heap.count && (best = vd_candidate(vd, pts, vd->heap.id[0], y)) != vd->heap.key[0])
        vpdsi_index_heap_set(&vd->heap, vd->heap.id[0], best); /* best < 0 takes it out */
    if (vd->heap.count) vd->hint = vd->heap.id[0];
    for (k = 0; k < 4; k++)
        if (vd->corner_d2[k] > best) {
            best = vd->corner_d2[k];
            y[0] = k & 1 ? vd->dt.hi[0] : vd->dt.lo[0];
            y[1] = k & 2 ? vd->dt.hi[1] : vd->dt.lo[1];
        }
    return best;
}

/* The squared distance from x to sample vertex v (a far vertex: INFINITY), as the kd-tree's
 * test measures it (open axes): the same bits. */
static double vd_vertex_d2(const double *pts, uint32_t v, const double *x)
{
    static const double open_axes[2] = {0, 0};
    if (v < VPDSI_DT_FAR) return INFINITY;
    return vpdsi_torus_dist2(x, pts + 2 * (size_t)(v - VPDSI_DT_FAR), 2, open_axes);
}

int vpdsi_voids_nearest2(vpdsi_voids *vd, vpdsi_mem *m, const double *pts, const double *x, double below,
                         double *d2)
{
    const vpdsi_dt *dt = &vd->dt;
    double best = INFINITY;
    size_t j;
    int i, e;
    /* the farthest point's triangle first: a dart that conflicts mostly meets one of its
     * vertices, which spares the search of its neighbours */
    if (vd->hint < dt->n_tri)
        for (i = 0; i < 3; i++) {
            double s = vd_vertex_d2(pts, dt->tv[3 * (size_t)vd->hint + (size_t)i], x);
            if (s < best) best = s;
        }
    if (best < below) {
        *d2 = best;
        return 0;
    }
    if ((e = vpdsi_dt_near(&vd->dt, m, pts, x, vd->hint)) != 0) return e;
    for (j = 0; j < dt->n_cavity; j++)
        for (i = 0; i < 3; i++) {
            double s = vd_vertex_d2(pts, dt->tv[3 * (size_t)dt->cavity[j] + (size_t)i], x);
            if (s < best) best = s;
        }
    *d2 = best;
    return 0;
}
