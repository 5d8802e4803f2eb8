/* The stream's farthest point in 3D (voids3.h): candidates per tetrahedron in an indexed heap,
 * the lower envelope of each edge of the box, the corners. */
#include "voids3.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define V3_TV(t, i) vd->dt.tv[4 * (size_t)(t) + (size_t)(i)]
#define V3_TN(t, i) vd->dt.tn[4 * (size_t)(t) + (size_t)(i)]
#define V3_P(v) vpdsi_dt3_point(&vd->dt, pts, (v))

void vpdsi_voids3_init(vpdsi_voids3 *vd)
{
    memset(vd, 0, sizeof *vd);
}

void vpdsi_voids3_release(vpdsi_voids3 *vd, vpdsi_mem *m)
{
    int e;
    vpdsi_dt3_release(&vd->dt, m);
    vpdsi_index_heap_release(&vd->heap, m);
    for (e = 0; e < 12; e++) {
        vpdsi_box_edge *b = &vd->edge[e];
        vpdsi_mem_free(m, b->s, b->cap_s * sizeof(double));
        vpdsi_mem_free(m, b->h2, b->cap_h2 * sizeof(double));
        vpdsi_mem_free(m, b->who, b->cap_who * sizeof(uint32_t));
    }
    vpdsi_mem_free(m, vd->batch, vd->cap_batch * sizeof(uint64_t));
    vpdsi_voids3_init(vd);
}

static double v3_dist2(const double *a, const double *b)
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

static int v3_in_box(const vpdsi_dt3 *dt, const double *y)
{
    int k;
    for (k = 0; k < 3; k++)
        if (!(y[k] >= dt->lo[k] && y[k] <= dt->hi[k])) return 0;
    return 1;
}

static void v3_cross(const double *u, const double *v, double *w)
{
    w[0] = u[1] * v[2] - u[2] * v[1];
    w[1] = u[2] * v[0] - u[0] * v[2];
    w[2] = u[0] * v[1] - u[1] * v[0];
}

/* The centre of the sphere through a, b, c, d; -1 when they are coplanar. */
static int v3_sphere_centre(const double *a, const double *b, const double *c, const double *d, double *y)
{
    double u[3], v[3], w[3], vw[3], wu[3], uv[3], den, u2, v2, w2;
    int k;
    for (k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    v3_cross(v, w, vw);
    v3_cross(w, u, wu);
    v3_cross(u, v, uv);
    den = 2 * (u[0] * vw[0] + u[1] * vw[1] + u[2] * vw[2]);
    if (den == 0) return -1;
    u2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    w2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    for (k = 0; k < 3; k++) y[k] = a[k] + (u2 * vw[k] + v2 * wu[k] + w2 * uv[k]) / den;
    return 0;
}

/* The farthest point where the Voronoi edge of triangle (a, b, c) (the line through its
 * circumcentre along its normal) meets a face of the box, no nearer to o1 or o2 (the opposite
 * vertices; VPDSI_DT3_NONE or far: none) than to the triangle: on the line, exactly the segment
 * between the two circumspheres' centres. Its squared gap, or -1. */
static double v3_face_crossing(const vpdsi_voids3 *vd, const double *pts, const uint32_t *abc, uint32_t o1,
                               uint32_t o2, double *y)
{
    const vpdsi_dt3 *dt = &vd->dt;
    const double *a = V3_P(abc[0]), *b = V3_P(abc[1]), *c = V3_P(abc[2]);
    double u[3], v[3], n[3], un[3], nv[3], cc[3], n2, u2, v2, best = -1;
    int k, side;
    for (k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
    }
    v3_cross(u, v, n);
    n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (n2 == 0) return -1;
    v3_cross(n, u, un);
    v3_cross(v, n, nv);
    u2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    for (k = 0; k < 3; k++) cc[k] = a[k] + (u2 * nv[k] + v2 * un[k]) / (2 * n2);
    for (k = 0; k < 3; k++) {
        if (n[k] == 0) continue; /* the line runs along the faces across axis k */
        for (side = 0; side < 2; side++) {
            double x[3], g2, s = ((side ? dt->hi[k] : dt->lo[k]) - cc[k]) / n[k];
            int q;
            /* a valid crossing is as far from a as from its nearest sample: within the bound */
            if (fabs(a[k] - (side ? dt->hi[k] : dt->lo[k])) > vd->bound) continue;
            for (q = 0; q < 3; q++) x[q] = cc[q] + s * n[q];
            x[k] = side ? dt->hi[k] : dt->lo[k];
            if (!v3_in_box(dt, x)) continue;
            g2 = v3_dist2(x, a);
            if (v3_dist2(x, b) < g2) g2 = v3_dist2(x, b);
            if (v3_dist2(x, c) < g2) g2 = v3_dist2(x, c);
            if (g2 <= best) continue;
            if (o1 != VPDSI_DT3_NONE && o1 >= VPDSI_DT3_FAR && v3_dist2(x, V3_P(o1)) < g2) continue;
            if (o2 != VPDSI_DT3_NONE && o2 >= VPDSI_DT3_FAR && v3_dist2(x, V3_P(o2)) < g2) continue;
            best = g2;
            memcpy(y, x, sizeof x);
        }
    }
    return best;
}

/* Tetrahedron t's candidate: its circumcentre when inside the box, and the face crossings of
 * the faces it owns (a face belongs to the lower of its two tetrahedra's indices: both are
 * made again when either changes). Its squared gap (-1: none) and its point y. */
static double v3_candidate(const vpdsi_voids3 *vd, const double *pts, uint32_t t, double *y)
{
    const vpdsi_dt3 *dt = &vd->dt;
    double best = -1, z[3] = {0, 0, 0};
    int i, far = 0;
    if (V3_TV(t, 0) == VPDSI_DT3_NONE) return -1;
    for (i = 0; i < 4; i++) far |= V3_TV(t, i) < VPDSI_DT3_FAR;
    if (!far && v3_sphere_centre(V3_P(V3_TV(t, 0)), V3_P(V3_TV(t, 1)), V3_P(V3_TV(t, 2)), V3_P(V3_TV(t, 3)), z) == 0 &&
        v3_in_box(dt, z)) {
        for (i = 0; i < 4; i++)
            if (best < 0 || v3_dist2(z, V3_P(V3_TV(t, i))) < best) best = v3_dist2(z, V3_P(V3_TV(t, i)));
        memcpy(y, z, sizeof z);
    }
    for (i = 0; i < 4; i++) {
        uint32_t u = V3_TN(t, i), abc[3], o2 = VPDSI_DT3_NONE;
        double g2;
        int k;
        if (u != VPDSI_DT3_NONE && u < t) continue;
        for (k = 0, far = 0; k < 3; k++) {
            abc[k] = V3_TV(t, vpdsi_dt3_face[i][k]);
            far |= abc[k] < VPDSI_DT3_FAR;
        }
        if (far) continue;
        if (u != VPDSI_DT3_NONE)
            for (k = 0; k < 4; k++)
                if (V3_TV(u, k) != abc[0] && V3_TV(u, k) != abc[1] && V3_TV(u, k) != abc[2]) o2 = V3_TV(u, k);
        g2 = v3_face_crossing(vd, pts, abc, V3_TV(t, i), o2, z);
        if (g2 > best) {
            best = g2;
            memcpy(y, z, sizeof z);
        }
    }
    return best;
}

/* ---- the edges of the box: edge e runs along axis e / 4, at the low or high side of the
 * other two axes by its bits 0 and 1 ---- */

static void v3_edge_axes(int e, int *k, int *i, int *j)
{
    *k = e / 4;
    *i = (*k + 1) % 3;
    *j = (*k + 2) % 3;
}

/* Where parabola r (lower s) stops being below parabola q: the breakpoint of the two. */
static double v3_breakpoint(const vpdsi_box_edge *b, size_t r, size_t q)
{
    return 0.5 * (b->s[r] + b->s[q]) + (b->h2[q] - b->h2[r]) / (2 * (b->s[q] - b->s[r]));
}

/* The envelope of the edge's members remade: those below the rest somewhere in [lo, hi] kept
 * (a member that is not never will be: samples only lower it), its farthest breakpoint. */
static void v3_envelope(vpdsi_box_edge *b, int e, const vpdsi_dt3 *dt)
{
    size_t q, n = 0, first;
    int k, i, j;
    v3_edge_axes(e, &k, &i, &j);
    for (q = 0; q < b->count; q++) {
        while (n > 0) {
            size_t t = n - 1;
            if (b->s[q] == b->s[t]) {
                if (b->h2[q] >= b->h2[t]) break;
                n--;
                continue;
            }
            if (n >= 2 && v3_breakpoint(b, t, q) <= v3_breakpoint(b, t - 1, t)) {
                n--;
                continue;
            }
            break;
        }
        if (n > 0 && b->s[q] == b->s[n - 1]) continue; /* q is above the member with its s */
        b->s[n] = b->s[q];
        b->h2[n] = b->h2[q];
        b->who[n] = b->who[q];
        n++;
    }
    /* members whose piece lies past either end of the edge */
    while (n > 1 && v3_breakpoint(b, n - 2, n - 1) >= dt->hi[k]) n--;
    for (first = 0; first + 1 < n && v3_breakpoint(b, first, first + 1) <= dt->lo[k]; first++) {}
    if (first) {
        memmove(b->s, b->s + first, (n - first) * sizeof(double));
        memmove(b->h2, b->h2 + first, (n - first) * sizeof(double));
        memmove(b->who, b->who + first, (n - first) * sizeof(uint32_t));
        n -= first;
    }
    b->count = n;
    b->best2 = -1;
    for (q = 0; q + 1 < n; q++) {
        double z = v3_breakpoint(b, q, q + 1), g2 = (z - b->s[q]) * (z - b->s[q]) + b->h2[q];
        if (z >= dt->lo[k] && z <= dt->hi[k] && g2 > b->best2) {
            b->best2 = g2;
            b->best[k] = z;
            b->best[i] = e & 1 ? dt->hi[i] : dt->lo[i];
            b->best[j] = e & 2 ? dt->hi[j] : dt->lo[j];
        }
    }
    b->top2 = b->best2;
    if (n) {
        double g0 = (dt->lo[k] - b->s[0]) * (dt->lo[k] - b->s[0]) + b->h2[0];
        double g1 = (dt->hi[k] - b->s[n - 1]) * (dt->hi[k] - b->s[n - 1]) + b->h2[n - 1];
        if (g0 > b->top2) b->top2 = g0;
        if (g1 > b->top2) b->top2 = g1;
    } else {
        b->top2 = INFINITY;
    }
}

/* Sample i (point p) where edge e would take it; -1 when it cannot be below the envelope. */
static double v3_edge_h2(const vpdsi_voids3 *vd, int e, const double *p, double *s)
{
    int k, i, j;
    double h2;
    v3_edge_axes(e, &k, &i, &j);
    h2 = (p[i] - (e & 1 ? vd->dt.hi[i] : vd->dt.lo[i])) * (p[i] - (e & 1 ? vd->dt.hi[i] : vd->dt.lo[i])) +
         (p[j] - (e & 2 ? vd->dt.hi[j] : vd->dt.lo[j])) * (p[j] - (e & 2 ? vd->dt.hi[j] : vd->dt.lo[j]));
    *s = p[k];
    return h2 < vd->edge[e].top2 && h2 <= vd->bound * vd->bound ? h2 : -1;
}

static int v3_edge_reserve(vpdsi_box_edge *b, vpdsi_mem *m)
{
    return vpdsi_mem_reserve(m, (void **)&b->s, &b->cap_s, b->count + 1, sizeof(double)) ||
           vpdsi_mem_reserve(m, (void **)&b->h2, &b->cap_h2, b->count + 1, sizeof(double)) ||
           vpdsi_mem_reserve(m, (void **)&b->who, &b->cap_who, b->count + 1, sizeof(uint32_t));
}

/* Sample i into edge e's members, in order of s (after v3_edge_reserve). */
static void v3_edge_add(vpdsi_voids3 *vd, int e, uint32_t i, double s, double h2)
{
    vpdsi_box_edge *b = &vd->edge[e];
    size_t q = b->count;
    while (q > 0 && b->s[q - 1] > s) q--;
    memmove(b->s + q + 1, b->s + q, (b->count - q) * sizeof(double));
    memmove(b->h2 + q + 1, b->h2 + q, (b->count - q) * sizeof(double));
    memmove(b->who + q + 1, b->who + q, (b->count - q) * sizeof(uint32_t));
    b->s[q] = s;
    b->h2[q] = h2;
    b->who[q] = i;
    b->count++;
    v3_envelope(b, e, &vd->dt);
}

static int v3_start(vpdsi_voids3 *vd, vpdsi_mem *m, const double *lo, const double *hi)
{
    int k;
    if (vpdsi_dt3_init(&vd->dt, m, lo, hi) || vpdsi_index_heap_reserve(&vd->heap, m, 64)) {
        vpdsi_voids3_release(vd, m);
        return -1;
    }
    for (k = 0; k < 8; k++) vd->corner_d2[k] = INFINITY;
    for (k = 0; k < 12; k++) {
        vd->edge[k].top2 = INFINITY;
        vd->edge[k].best2 = -1;
    }
    vd->hint = VPDSI_DT3_NONE;
    vd->bound = INFINITY;
    vd->ready = 1;
    return 0;
}

/* Insert sample i (in the box): room for everything first, then the changes. */
static int v3_insert(vpdsi_voids3 *vd, vpdsi_mem *m, const double *pts, size_t i)
{
    const double *p = pts + 3 * i;
    double s[12], h2[12];
    size_t j;
    int e, k;
    for (k = 0; k < 12; k++)
        if ((h2[k] = v3_edge_h2(vd, k, p, &s[k])) >= 0 && v3_edge_reserve(&vd->edge[k], m)) return -1;
    e = vpdsi_dt3_prepare(&vd->dt, m, pts, i, vd->hint);
    if (e < 0) return e;
    if (e == 0) {
        if (vpdsi_index_heap_reserve(&vd->heap, m, vd->dt.n_tet + vd->dt.n_rim)) return -1;
        vpdsi_dt3_commit(&vd->dt, i);
        for (j = vd->dt.n_rim; j < vd->dt.n_cavity; j++) vpdsi_index_heap_set(&vd->heap, vd->dt.cavity[j], -1);
        for (j = 0; j < vd->dt.n_rim; j++) {
            uint32_t u = vd->dt.rim[4 * j + 3], t = vd->dt.fresh[j];
            double y[3];
            vpdsi_index_heap_set(&vd->heap, t, v3_candidate(vd, pts, t, y));
            /* a tetrahedron across the rim that owns the face now (the lower index) is made
             * again; one that does not keeps its key: it lost a face or part of one, so its
             * candidate can only fall, and vpdsi_voids3_farthest mends a key that did */
            if (u != VPDSI_DT3_NONE && u < t) vpdsi_index_heap_set(&vd->heap, u, v3_candidate(vd, pts, u, y));
        }
        for (k = 0; k < 12; k++)
            if (h2[k] >= 0) v3_edge_add(vd, k, (uint32_t)i, s[k], h2[k]);
    }
    for (k = 0; k < 8; k++) {
        double c[3], d2;
        int q;
        for (q = 0; q < 3; q++) c[q] = k >> q & 1 ? vd->dt.hi[q] : vd->dt.lo[q];
        d2 = v3_dist2(c, p);
        if (d2 < vd->corner_d2[k]) vd->corner_d2[k] = d2;
    }
    vd->hint = VPDSI_DT3_NONE;
    return 0;
}

/* Spreads the 10 low bits of x to every third bit. */
static uint32_t v3_spread(uint32_t x)
{
    uint32_t r = 0;
    int b;
    for (b = 0; b < 10; b++) r |= ((x >> b) & 1u) << (3 * b);
    return r;
}

static int v3_cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* The samples [vd->n, n) as a batch in Morton order of a 2^10 grid over the box; -2 when one
 * lies outside the box. */
static int v3_make_batch(vpdsi_voids3 *vd, vpdsi_mem *m, const double *pts, size_t n)
{
    size_t i, count = n - vd->n;
    if (vpdsi_mem_reserve(m, (void **)&vd->batch, &vd->cap_batch, count, sizeof(uint64_t))) return -1;
    for (i = 0; i < count; i++) {
        const double *p = pts + 3 * (vd->n + i);
        uint32_t code = 0;
        int k;
        if (!v3_in_box(&vd->dt, p)) return -2;
        for (k = 0; k < 3; k++) {
            double u = (p[k] - vd->dt.lo[k]) / (vd->dt.hi[k] - vd->dt.lo[k]) * 1024.0;
            code |= v3_spread(u >= 1023.0 ? 1023u : (uint32_t)u) << k;
        }
        vd->batch[i] = (uint64_t)code << 32 | (uint64_t)(vd->n + i);
    }
    qsort(vd->batch, count, sizeof(uint64_t), v3_cmp_u64);
    vd->n_batch = count;
    vd->at = 0;
    vd->n = n;
    return 0;
}

int vpdsi_voids3_sync(vpdsi_voids3 *vd, vpdsi_mem *m, const double *lo, const double *hi,
                      const double *pts, size_t n, double bound)
{
    int e;
    if (n > VPDSI_DT3_MAX_POINTS) return -2;
    if (!vd->ready && v3_start(vd, m, lo, hi)) return -1;
    vd->bound = bound;
    for (;;) {
        while (vd->at < vd->n_batch) {
            if ((e = v3_insert(vd, m, pts, (size_t)(vd->batch[vd->at] & 0xffffffffu))) != 0) return e;
            vd->at++;
        }
        if (vd->n_batch) {
            vpdsi_mem_free(m, vd->batch, vd->cap_batch * sizeof(uint64_t));
            vd->batch = NULL;
            vd->cap_batch = vd->n_batch = vd->at = 0;
        }
        if (vd->n + 1 < n) {
            if ((e = v3_make_batch(vd, m, pts, n)) != 0) return e;
            continue;
        }
        if (vd->n == n) return 0;
        if (!v3_in_box(&vd->dt, pts + 3 * vd->n)) return -2;
        if ((e = v3_insert(vd, m, pts, vd->n)) != 0) return e;
        vd->n++;
        return 0;
    }
}

double vpdsi_voids3_farthest(vpdsi_voids3 *vd, const double *pts, double *y)
{
    double best = -1;
    int k;
    /* a key may lie above its tetrahedron's candidate (v3_insert): mended at the top until
     * the top's holds; every other key is at or above its candidate, so the top is the
     * largest (ties: the lowest index, as with keys kept exact) */
    while (vd->heap.count && (best = v3_candidate(vd, pts, vd->heap.id[0], y)) != vd->heap.key[0])
        vpdsi_index_heap_set(&vd->heap, vd->heap.id[0], best); /* best < 0 takes it out */
    if (vd->heap.count) vd->hint = vd->heap.id[0];
    for (k = 0; k < 12; k++)
        if (vd->edge[k].best2 > best) {
            best = vd->edge[k].best2;
            memcpy(y, vd->edge[k].best, 3 * sizeof(double));
        }
    for (k = 0; k < 8; k++)
        if (vd->corner_d2[k] > best) {
            int q;
            best = vd->corner_d2[k];
            for (q = 0; q < 3; q++) y[q] = k >> q & 1 ? vd->dt.hi[q] : vd->dt.lo[q];
        }
    return best;
}
