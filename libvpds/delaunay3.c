/* Bowyer-Watson in 3D, as delaunay.c in 2D: the tetrahedra whose circumsphere holds the new
 * point are replaced by a cone from the point to the cavity's faces. The orientation of a face
 * is taken from its vertices in one order whichever tetrahedron asks, so that a walk between
 * two tetrahedra never finds the point beyond their common face from both; a cavity that
 * round-off leaves not star-shaped sheds the tetrahedron whose face the point does not see. */
#include "delaunay3.h"
#include <math.h>
#include <string.h>

#define DT3_REPAIRS 1000 /* repairs of one cavity before the insert gives up (-2) */

const int vpdsi_dt3_face[4][3] = {{1, 3, 2}, {0, 2, 3}, {0, 3, 1}, {0, 1, 2}};

/* det[a - d; b - d; c - d]: > 0 when (a, b, c, d) is positively oriented. */
static double dt3_orient_raw(const double *a, const double *b, const double *c, const double *d)
{
    double adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
    double bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
    double cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
    return adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) + cdx * (ady * bdz - adz * bdy);
}

static int dt3_less(const double *a, const double *b)
{
    return a[0] < b[0] || (a[0] == b[0] && (a[1] < b[1] || (a[1] == b[1] && a[2] < b[2])));
}

/* The side of face (a, b, c) that p lies on, computed from the face's vertices sorted. */
static double dt3_orient(const double *a, const double *b, const double *c, const double *p)
{
    const double *w;
    int flip = 0;
    if (dt3_less(b, a)) { w = a; a = b; b = w; flip ^= 1; }
    if (dt3_less(c, b)) { w = b; b = c; c = w; flip ^= 1; }
    if (dt3_less(b, a)) { w = a; a = b; b = w; flip ^= 1; }
    return flip ? -dt3_orient_raw(a, b, c, p) : dt3_orient_raw(a, b, c, p);
}

/* > 0 when e lies inside the sphere through a, b, c, d (positively oriented). */
static double dt3_insphere(const double *a, const double *b, const double *c, const double *d, const double *e)
{
    double aex = a[0] - e[0], aey = a[1] - e[1], aez = a[2] - e[2];
    double bex = b[0] - e[0], bey = b[1] - e[1], bez = b[2] - e[2];
    double cex = c[0] - e[0], cey = c[1] - e[1], cez = c[2] - e[2];
    double dex = d[0] - e[0], dey = d[1] - e[1], dez = d[2] - e[2];
    double ab = aex * bey - bex * aey, bc = bex * cey - cex * bey, cd = cex * dey - dex * cey;
    double da = dex * aey - aex * dey, ac = aex * cey - cex * aey, bd = bex * dey - dex * bey;
    double abc = aez * bc - bez * ac + cez * ab, bcd = bez * cd - cez * bd + dez * bc;
    double cda = cez * da + dez * ac + aez * cd, dab = dez * ab + aez * bd + bez * da;
    double al = aex * aex + aey * aey + aez * aez, bl = bex * bex + bey * bey + bez * bez;
    double cl = cex * cex + cey * cey + cez * cez, dl = dex * dex + dey * dey + dez * dez;
    return (dl * abc - cl * dab) + (bl * cda - al * bcd);
}

#define DT3_P(v) vpdsi_dt3_point(dt, pts, (v))
#define DT3_TV(t, i) dt->tv[4 * (size_t)(t) + (size_t)(i)]
#define DT3_TN(t, i) dt->tn[4 * (size_t)(t) + (size_t)(i)]

int vpdsi_dt3_init(vpdsi_dt3 *dt, vpdsi_mem *m, const double *lo, const double *hi)
{
    /* a regular tetrahedron on a sphere of 4 box diagonals around the centre: it holds the
     * box, and a box point is nearer to a sample inside the box than to any of its vertices */
    static const double dir[12] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
    double diag = 0, c[3];
    int k;
    memset(dt, 0, sizeof *dt);
    for (k = 0; k < 3; k++) {
        dt->lo[k] = lo[k];
        dt->hi[k] = hi[k];
        c[k] = 0.5 * (lo[k] + hi[k]);
        diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    diag = sqrt(diag);
    for (k = 0; k < 12; k++) dt->far_x[k] = c[k % 3] + 4 * diag * dir[k] / sqrt(3.0);
    if (vpdsi_mem_reserve(m, (void **)&dt->tv, &dt->cap_tv, 4 * 64, sizeof(uint32_t)) ||
        vpdsi_mem_reserve(m, (void **)&dt->tn, &dt->cap_tn, 4 * 64, sizeof(uint32_t))) {
        vpdsi_dt3_release(dt, m);
        return -1;
    }
    for (k = 0; k < 4; k++) {
        dt->tv[k] = (uint32_t)k;
        dt->tn[k] = VPDSI_DT3_NONE;
    }
    if (dt3_orient_raw(dt->far_x, dt->far_x + 3, dt->far_x + 6, dt->far_x + 9) < 0) {
        dt->tv[2] = 3;
        dt->tv[3] = 2;
    }
    dt->n_tet = 1;
    dt->free_tet = VPDSI_DT3_NONE;
    return 0;
}

void vpdsi_dt3_release(vpdsi_dt3 *dt, vpdsi_mem *m)
{
    vpdsi_mem_free(m, dt->tv, dt->cap_tv * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->tn, dt->cap_tn * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->cavity, dt->cap_cavity * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->rim, dt->cap_rim * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->fresh, dt->cap_fresh * sizeof(uint32_t));
    vpdsi_mem_free(m, dt->edge_key, dt->cap_edge * sizeof(uint64_t));
    vpdsi_mem_free(m, dt->edge_face, dt->cap_edge * sizeof(uint32_t));
    memset(dt, 0, sizeof *dt);
}

/* The orientation of p against face i of tetrahedron t (> 0: on the side of vertex i). */
static double dt3_face_side(const vpdsi_dt3 *dt, const double *pts, uint32_t t, int i, const double *p)
{
    const int *f = vpdsi_dt3_face[i];
    return dt3_orient(DT3_P(DT3_TV(t, f[0])), DT3_P(DT3_TV(t, f[1])), DT3_P(DT3_TV(t, f[2])), p);
}

static int dt3_holds(const vpdsi_dt3 *dt, const double *pts, uint32_t t, const double *p, int *beyond)
{
    int i;
    for (i = 0; i < 4; i++)
        if (dt3_face_side(dt, pts, t, i, p) < 0) {
            *beyond = i;
            return 0;
        }
    return 1;
}

/* The tetrahedron that holds p: a visibility walk; past n_tet steps, every one in turn. */
static uint32_t dt3_locate(const vpdsi_dt3 *dt, const double *pts, const double *p, uint32_t t)
{
    size_t steps;
    int i;
    if (t >= dt->n_tet || DT3_TV(t, 0) == VPDSI_DT3_NONE) t = dt->last;
    for (steps = 0; steps <= dt->n_tet; steps++) {
        if (dt3_holds(dt, pts, t, p, &i)) return t;
        t = DT3_TN(t, i);
        if (t == VPDSI_DT3_NONE) return VPDSI_DT3_NONE;
    }
    for (t = 0; t < dt->n_tet; t++)
        if (DT3_TV(t, 0) != VPDSI_DT3_NONE && dt3_holds(dt, pts, t, p, &i)) return t;
    return VPDSI_DT3_NONE;
}

static int dt3_among(const vpdsi_dt3 *dt, size_t from, size_t to, uint32_t t)
{
    size_t j;
    for (j = from; j < to; j++)
        if (dt->cavity[j] == t) return 1;
    return 0;
}

static int dt3_push_cavity(vpdsi_dt3 *dt, vpdsi_mem *m, uint32_t t)
{
    if (vpdsi_mem_reserve(m, (void **)&dt->cavity, &dt->cap_cavity, dt->n_cavity + 1, sizeof(uint32_t)))
        return -1;
    dt->cavity[dt->n_cavity++] = t;
    return 0;
}

static int dt3_grow_cavity(vpdsi_dt3 *dt, vpdsi_mem *m, const double *pts, const double *p, uint32_t t)
{
    size_t j;
    dt->n_cavity = 0;
    if (dt3_push_cavity(dt, m, t)) return -1;
    for (j = 0; j < dt->n_cavity; j++) {
        uint32_t c = dt->cavity[j];
        int i;
        for (i = 0; i < 4; i++) {
            uint32_t u = DT3_TN(c, i);
            if (u == VPDSI_DT3_NONE || dt3_among(dt, 0, dt->n_cavity, u)) continue;
            if (dt3_insphere(DT3_P(DT3_TV(u, 0)), DT3_P(DT3_TV(u, 1)), DT3_P(DT3_TV(u, 2)), DT3_P(DT3_TV(u, 3)), p) > 0 && dt3_push_cavity(dt, m, u))
                return -1;
        }
    }
    return 0;
}

/* Whether p, in the plane of triangle (a, b, c), lies inside its circumcircle: then it lies
 * inside the circumsphere of both tetrahedra on that face. */
static int dt3_in_circumcircle(const double *a, const double *b, const double *c, const double *p)
{
    double u[3], v[3], n[3], nu[3], vn[3], cc[3], n2, u2, v2, r2 = 0, d2 = 0;
    int k;
    for (k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (n2 == 0) return 0;
    nu[0] = n[1] * u[2] - n[2] * u[1];
    nu[1] = n[2] * u[0] - n[0] * u[2];
    nu[2] = n[0] * u[1] - n[1] * u[0];
    vn[0] = v[1] * n[2] - v[2] * n[1];
    vn[1] = v[2] * n[0] - v[0] * n[2];
    vn[2] = v[0] * n[1] - v[1] * n[0];
    u2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    for (k = 0; k < 3; k++) {
        cc[k] = a[k] + (u2 * vn[k] + v2 * nu[k]) / (2 * n2);
        r2 += (a[k] - cc[k]) * (a[k] - cc[k]);
        d2 += (p[k] - cc[k]) * (p[k] - cc[k]);
    }
    return d2 < r2;
}

/* Whether the tetrahedron (a, b, c, p) of orientation o > 0 is flat to round-off: o within
 * its bound's reach of the product of its edges from p (the determinant's size), as when p
 * and the face lie on one circle of a plane, a tie; such a tetrahedron's circumsphere is
 * noise, so the face counts as unseen (the repair then takes the tie one way). */
static int dt3_flat(const double *a, const double *b, const double *c, const double *p, double o)
{
    double la = 0, lb = 0, lc = 0;
    int k;
    for (k = 0; k < 3; k++) {
        la += (a[k] - p[k]) * (a[k] - p[k]);
        lb += (b[k] - p[k]) * (b[k] - p[k]);
        lc += (c[k] - p[k]) * (c[k] - p[k]);
    }
    return o * o <= 1e-24 * la * lb * lc;
}

/* As dt_repair in 2D: tetrahedron cavity[at] has a face that p does not see; it leaves the
 * cavity (which keeps what is still connected to the first), unless it is the first, or p lies
 * in the face's plane inside its circumcircle (so inside the circumsphere beyond too, which
 * round-off on a far vertex's large coordinates missed), when the tetrahedron beyond joins. */
static int dt3_repair(vpdsi_dt3 *dt, vpdsi_mem *m, const double *pts, const double *p, size_t at, int i,
                      double o)
{
    uint32_t c = dt->cavity[at], u = DT3_TN(c, i);
    const int *f = vpdsi_dt3_face[i];
    size_t j, kept;
    if (at == 0 || (o == 0 && dt3_in_circumcircle(DT3_P(DT3_TV(c, f[0])), DT3_P(DT3_TV(c, f[1])), DT3_P(DT3_TV(c, f[2])), p)))
        return u == VPDSI_DT3_NONE ? -2 : dt3_push_cavity(dt, m, u);
    dt->cavity[at] = dt->cavity[--dt->n_cavity];
    for (kept = 1, j = 0; j < kept; j++) {
        uint32_t t = dt->cavity[j];
        int w;
        for (w = 0; w < 4; w++) {
            uint32_t v = DT3_TN(t, w);
            size_t q;
            if (v == VPDSI_DT3_NONE || dt3_among(dt, 0, kept, v)) continue;
            for (q = kept; q < dt->n_cavity && dt->cavity[q] != v; q++) {}
            if (q == dt->n_cavity) continue;
            dt->cavity[q] = dt->cavity[kept];
            dt->cavity[kept++] = v;
        }
    }
    dt->n_cavity = kept;
    return 0;
}

/* The rim's directed edges (x, y) -> the face that runs them, by open addressing (a cavity
 * has a few dozen faces; a scan per look-up cost a fifth of an insert). */
static size_t dt3_slot(const vpdsi_dt3 *dt, uint64_t key)
{
    size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 32) & (dt->cap_edge - 1);
    while (dt->edge_key[h] != UINT64_MAX && dt->edge_key[h] != key) h = (h + 1) & (dt->cap_edge - 1);
    return h;
}

static long dt3_rim_edge(const vpdsi_dt3 *dt, uint32_t x, uint32_t y)
{
    size_t h = dt3_slot(dt, (uint64_t)x << 32 | y);
    return dt->edge_key[h] == UINT64_MAX ? -1 : (long)dt->edge_face[h];
}

/* The table of the rim's edges made, and its vertices counted (each edge's start, once: the
 * vertex keys are (v << 32 | v), apart from every edge's); -1 on OOM, -2 when an edge is run
 * twice the same way. */
static int dt3_index_rim(vpdsi_dt3 *dt, vpdsi_mem *m, size_t *verts)
{
    size_t need = 64, j, cap;
    while (need < 8 * dt->n_rim) need *= 2;
    if (need > dt->cap_edge) {
        uint64_t *k = (uint64_t *)vpdsi_mem_alloc(m, need * sizeof(uint64_t));
        uint32_t *f = k ? (uint32_t *)vpdsi_mem_alloc(m, need * sizeof(uint32_t)) : NULL;
        if (!f) {
            vpdsi_mem_free(m, k, k ? need * sizeof(uint64_t) : 0);
            return -1;
        }
        vpdsi_mem_free(m, dt->edge_key, dt->cap_edge * sizeof(uint64_t));
        vpdsi_mem_free(m, dt->edge_face, dt->cap_edge * sizeof(uint32_t));
        dt->edge_key = k;
        dt->edge_face = f;
        dt->cap_edge = need;
    }
    cap = dt->cap_edge;
    memset(dt->edge_key, 0xff, cap * sizeof(uint64_t));
    *verts = 0;
    for (j = 0; j < dt->n_rim; j++) {
        int e;
        for (e = 0; e < 3; e++) {
            uint32_t x = dt->rim[4 * j + (size_t)e], y = dt->rim[4 * j + (size_t)(e + 1) % 3];
            size_t h = dt3_slot(dt, (uint64_t)x << 32 | y), hv;
            if (dt->edge_key[h] != UINT64_MAX) return -2;
            dt->edge_key[h] = (uint64_t)x << 32 | y;
            dt->edge_face[h] = (uint32_t)j;
            hv = dt3_slot(dt, (uint64_t)x << 32 | x);
            if (dt->edge_key[hv] == UINT64_MAX) {
                dt->edge_key[hv] = (uint64_t)x << 32 | x;
                (*verts)++;
            }
        }
    }
    return 0;
}

/* The cavity's faces (a, b, c, the tetrahedron outside), each seen by p, into rim; then every
 * edge must border two of them, once each way, and V = F / 2 + 2 (a sphere around p). */
static int dt3_collect_rim(vpdsi_dt3 *dt, vpdsi_mem *m, const double *pts, const double *p)
{
    size_t j, repairs = 0, verts = 0;
    int e;
again:
    dt->n_rim = 0;
    for (j = 0; j < dt->n_cavity; j++) {
        uint32_t c = dt->cavity[j];
        int i, k;
        for (i = 0; i < 4; i++) {
            uint32_t u = DT3_TN(c, i);
            const int *f = vpdsi_dt3_face[i];
            double o;
            if (u != VPDSI_DT3_NONE && dt3_among(dt, 0, dt->n_cavity, u)) continue;
            o = dt3_face_side(dt, pts, c, i, p);
            if (o <= 0 || dt3_flat(DT3_P(DT3_TV(c, f[0])), DT3_P(DT3_TV(c, f[1])), DT3_P(DT3_TV(c, f[2])), p, o)) {
                if (o > 0) o = 0;
                e = ++repairs > DT3_REPAIRS ? -2 : dt3_repair(dt, m, pts, p, j, i, o);
                if (e) return e;
                goto again;
            }
            if (vpdsi_mem_reserve(m, (void **)&dt->rim, &dt->cap_rim, 4 * (dt->n_rim + 1), sizeof(uint32_t)))
                return -1;
            for (k = 0; k < 3; k++) dt->rim[4 * dt->n_rim + (size_t)k] = DT3_TV(c, f[k]);
            dt->rim[4 * dt->n_rim + 3] = u;
            dt->n_rim++;
        }
    }
    if ((e = dt3_index_rim(dt, m, &verts)) != 0) return e;
    for (j = 0; j < dt->n_rim; j++) {
        int q;
        for (q = 0; q < 3; q++)
            if (dt3_rim_edge(dt, dt->rim[4 * j + (size_t)(q + 1) % 3], dt->rim[4 * j + (size_t)q]) < 0) return -2;
    }
    return verts == dt->n_rim / 2 + 2 && dt->n_rim % 2 == 0 ? 0 : -2;
}

/* The cone from v over the rim (after the reserve): the cavity's slots, free ones, then new. */
static void dt3_cone(vpdsi_dt3 *dt, uint32_t v)
{
    size_t j;
    for (j = 0; j < dt->n_rim; j++) {
        uint32_t s;
        if (j < dt->n_cavity) s = dt->cavity[j];
        else if (dt->free_tet != VPDSI_DT3_NONE) {
            s = dt->free_tet;
            dt->free_tet = DT3_TN(s, 0);
        } else s = (uint32_t)dt->n_tet++;
        dt->fresh[j] = s;
    }
    for (j = dt->n_rim; j < dt->n_cavity; j++) { /* cavity slots left over: free */
        uint32_t s = dt->cavity[j];
        DT3_TV(s, 0) = VPDSI_DT3_NONE;
        DT3_TN(s, 0) = dt->free_tet;
        dt->free_tet = s;
    }
    for (j = 0; j < dt->n_rim; j++) {
        uint32_t s = dt->fresh[j], a = dt->rim[4 * j], b = dt->rim[4 * j + 1], c = dt->rim[4 * j + 2];
        uint32_t u = dt->rim[4 * j + 3];
        DT3_TV(s, 0) = a;
        DT3_TV(s, 1) = b;
        DT3_TV(s, 2) = c;
        DT3_TV(s, 3) = v;
        DT3_TN(s, 3) = u;
        if (u != VPDSI_DT3_NONE) {
            int i;
            for (i = 0; i < 4; i++)
                if (DT3_TV(u, i) != a && DT3_TV(u, i) != b && DT3_TV(u, i) != c) DT3_TN(u, i) = s;
        }
    }
    for (j = 0; j < dt->n_rim; j++) {
        uint32_t s = dt->fresh[j], a = dt->rim[4 * j], b = dt->rim[4 * j + 1], c = dt->rim[4 * j + 2];
        /* face opposite a holds edge (b, c), opposite b edge (c, a), opposite c edge (a, b):
         * each is the face of the cone over the rim face that runs the edge the other way */
        DT3_TN(s, 0) = dt->fresh[dt3_rim_edge(dt, c, b)];
        DT3_TN(s, 1) = dt->fresh[dt3_rim_edge(dt, a, c)];
        DT3_TN(s, 2) = dt->fresh[dt3_rim_edge(dt, b, a)];
    }
    dt->last = dt->fresh[0];
}

int vpdsi_dt3_prepare(vpdsi_dt3 *dt, vpdsi_mem *m, const double *pts, size_t index, uint32_t hint)
{
    const double *p = pts + 3 * index;
    uint32_t t;
    int i, e;
    if (index >= VPDSI_DT3_MAX_POINTS) return -2;
    t = dt3_locate(dt, pts, p, hint);
    if (t == VPDSI_DT3_NONE) return -2;
    for (i = 0; i < 4; i++) {
        const double *w = DT3_P(DT3_TV(t, i));
        if (w[0] == p[0] && w[1] == p[1] && w[2] == p[2]) return 1;
    }
    if ((e = dt3_grow_cavity(dt, m, pts, p, t)) != 0) return e;
    if ((e = dt3_collect_rim(dt, m, pts, p)) != 0) return e;
    if (vpdsi_mem_reserve(m, (void **)&dt->fresh, &dt->cap_fresh, dt->n_rim, sizeof(uint32_t)) ||
        vpdsi_mem_reserve(m, (void **)&dt->tv, &dt->cap_tv, 4 * (dt->n_tet + dt->n_rim), sizeof(uint32_t)) ||
        vpdsi_mem_reserve(m, (void **)&dt->tn, &dt->cap_tn, 4 * (dt->n_tet + dt->n_rim), sizeof(uint32_t)))
        return -1;
    return 0;
}

void vpdsi_dt3_commit(vpdsi_dt3 *dt, size_t index)
{
    dt3_cone(dt, (uint32_t)index + VPDSI_DT3_FAR);
}
