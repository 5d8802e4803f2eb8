/* Geometry of pieces of triangles (pieces.h): lattice points, corners, children, sizes, and r
 * over a piece. */
#include "pieces.h"
#include <math.h>


/* The point of live triangle k at lattice coordinates (i, j) of `level`: uv its parameters
 * along the edges v0->v1 and v0->v2, x its position. i / m is rounded once and scaled by a power
 * of two, so a point has the same bits at every level that holds it (shared corners agree). */
static void lattice_point(const vpdsi_trimesh *mesh, uint64_t m, uint32_t k, double unit,
                          uint64_t i, uint64_t j, double *uv, double *x)
{
    /* unit = 2^-level: the product is exact */
    uv[0] = (double)i / (double)m * unit;
    uv[1] = (double)j / (double)m * unit;
    vpdsi_trimesh_point(mesh, k, uv, x);
}

void vpdsi_piece_corners(const vpdsi_trimesh *mesh, uint64_t m, const vpdsi_piece *p,
                         double uv[3][2], double x[3][3])
{
    double unit = ldexp(1.0, -(int)p->level);
    if (p->down) {
        lattice_point(mesh, m, p->tri, unit, p->i + 1, p->j, uv[0], x[0]);
        lattice_point(mesh, m, p->tri, unit, p->i, p->j + 1, uv[1], x[1]);
        lattice_point(mesh, m, p->tri, unit, p->i + 1, p->j + 1, uv[2], x[2]);
    } else {
        lattice_point(mesh, m, p->tri, unit, p->i, p->j, uv[0], x[0]);
        lattice_point(mesh, m, p->tri, unit, p->i + 1, p->j, uv[1], x[1]);
        lattice_point(mesh, m, p->tri, unit, p->i, p->j + 1, uv[2], x[2]);
    }
}

vpdsi_piece vpdsi_piece_child(const vpdsi_piece *p, int q)
{
    static const uint8_t up_di[4] = {0, 1, 0, 0}, up_dj[4] = {0, 0, 1, 0}, up_down[4] = {0, 0, 0, 1};
    static const uint8_t dn_di[4] = {1, 0, 1, 1}, dn_dj[4] = {0, 1, 1, 1}, dn_down[4] = {1, 1, 1, 0};
    vpdsi_piece c = *p;
    c.level = (uint8_t)(p->level + 1);
    c.i = 2 * p->i + (p->down ? dn_di[q] : up_di[q]);
    c.j = 2 * p->j + (p->down ? dn_dj[q] : up_dj[q]);
    c.down = p->down ? dn_down[q] : up_down[q];
    return c;
}

double vpdsi_piece_area(const vpdsi_trimesh *mesh, uint64_t m, const vpdsi_piece *p)
{
    return ldexp(mesh->area[p->tri] / ((double)m * (double)m), -2 * (int)p->level);
}

double vpdsi_piece_edge(const vpdsi_trimesh *mesh, uint64_t m, const vpdsi_piece *p)
{
    return ldexp(mesh->longest[p->tri] / (double)m, -(int)p->level);
}

unsigned vpdsi_lattice_bits(uint64_t m)
{
    unsigned b = 0;
    while (m) b++, m >>= 1;
    return b;
}

vpds_status vpdsi_trimesh_radius(const vpdsi_trimesh *mesh, vpdsi_store *st, uint32_t k,
                                 const double *uv, const double *x, double *r)
{
    if (mesh->vr) {
        const uint32_t *t = mesh->tri + 3 * (size_t)mesh->live[k];
        *r = (1 - uv[0] - uv[1]) * mesh->vr[t[0]] + uv[0] * mesh->vr[t[1]] + uv[1] * mesh->vr[t[2]];
        return VPDS_OK;
    }
    return vpdsi_store_radius_at(st, x, r);
}

vpds_status vpdsi_piece_bounds(const vpdsi_trimesh *mesh, vpdsi_store *st, uint32_t tri,
                               double uv[3][2], double x[3][3], double *r_lo, double *r_hi)
{
    double r, c[3], cuv[2], h2 = 0;
    int q, k;
    vpds_status e;
    if (mesh->vr) {
        *r_lo = INFINITY;
        *r_hi = 0;
        for (q = 0; q < 3; q++) {
            if ((e = vpdsi_trimesh_radius(mesh, st, tri, uv[q], x[q], &r)) != VPDS_OK) return e;
            if (r < *r_lo) *r_lo = r;
            if (r > *r_hi) *r_hi = r;
        }
        return VPDS_OK;
    }
    if (st->sizing.kind == VPDSI_SIZING_CONSTANT) {
        *r_lo = *r_hi = st->sizing.radius;
        return VPDS_OK;
    }
    for (k = 0; k < 3; k++) c[k] = (x[0][k] + x[1][k] + x[2][k]) / 3;
    cuv[0] = (uv[0][0] + uv[1][0] + uv[2][0]) / 3;
    cuv[1] = (uv[0][1] + uv[1][1] + uv[2][1]) / 3;
    for (q = 0; q < 3; q++) {
        double d2 = 0;
        for (k = 0; k < 3; k++) d2 += (x[q][k] - c[k]) * (x[q][k] - c[k]);
        if (d2 > h2) h2 = d2;
    }
    if ((e = vpdsi_trimesh_radius(mesh, st, tri, cuv, c, &r)) != VPDS_OK) return e;
    *r_lo = r - st->sizing.lipschitz * sqrt(h2) * (1 + 1e-12);
    *r_hi = r + st->sizing.lipschitz * sqrt(h2) * (1 + 1e-12);
    if (*r_lo < 0) *r_lo = 0;
    return VPDS_OK;
}

void vpdsi_trimesh_point(const vpdsi_trimesh *mesh, uint32_t k, const double *uv, double *x)
{
    const uint32_t *t = mesh->tri + 3 * (size_t)mesh->live[k];
    const double *a = mesh->v + 3 * (size_t)t[0], *b = mesh->v + 3 * (size_t)t[1];
    const double *c = mesh->v + 3 * (size_t)t[2];
    int q;
    for (q = 0; q < 3; q++) x[q] = a[q] + uv[0] * (b[q] - a[q]) + uv[1] * (c[q] - a[q]);
}

void vpdsi_marks_release(vpdsi_surface_marks *mk, vpdsi_mem *m)
{
    vpdsi_mem_free(m, mk->face, mk->cap_face * sizeof *mk->face);
    vpdsi_mem_free(m, mk->bary, mk->cap_bary * sizeof *mk->bary);
    mk->face = NULL;
    mk->bary = NULL;
    mk->cap_face = mk->cap_bary = 0;
}

vpds_status vpdsi_marks_reserve(vpdsi_surface_marks *mk, vpdsi_store *st, size_t more)
{
    vpds_status e = vpdsi_store_reserve(st, more);
    size_t need = st->n + more;
    if (e != VPDS_OK) return e;
    if (vpdsi_mem_reserve(st->mem, (void **)&mk->face, &mk->cap_face, need, sizeof *mk->face) ||
        vpdsi_mem_reserve(st->mem, (void **)&mk->bary, &mk->cap_bary, 3 * need, sizeof *mk->bary)) {
        vpdsi_store_error(st, "out of memory for %zu samples", need);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

void vpdsi_marks_append(vpdsi_surface_marks *mk, vpdsi_store *st, const vpdsi_trimesh *mesh,
                        uint32_t k, const double *uv, const double *x, double r, double t)
{
    mk->face[st->n] = mesh->live[k];
    mk->bary[3 * st->n] = 1 - uv[0] - uv[1];
    mk->bary[3 * st->n + 1] = uv[0];
    mk->bary[3 * st->n + 2] = uv[1];
    vpdsi_store_append(st, x, r, t, 0);
}
