/* An incremental Delaunay tetrahedralisation of points in space (Bowyer-Watson), the 3D twin
 * of delaunay.h: its dual holds the candidates of the 3D stream's farthest point (voids3.c).
 * Four far vertices (0..3) enclose the box; the sample of index i is vertex i + VPDSI_DT3_FAR,
 * its coordinates read from the caller's array. */
#ifndef VPDS_DELAUNAY3_H
#define VPDS_DELAUNAY3_H
#include "mem.h"

#define VPDSI_DT3_NONE UINT32_MAX
#define VPDSI_DT3_FAR 4u
/* The most points a tetrahedralisation takes: its tetrahedra (about 6.5 per point) must have
 * 32-bit indices. */
#define VPDSI_DT3_MAX_POINTS ((size_t)1 << 28)

/* The vertices of the face opposite vertex i of a tetrahedron, ordered so that vertex i lies
 * on its positive side (vpdsi_dt3_face). */
extern const int vpdsi_dt3_face[4][3];

typedef struct vpdsi_dt3 {
    double far_x[12];         /* the enclosing vertices */
    double lo[3], hi[3];      /* the points it takes lie in this box */
    uint32_t *tv;             /* 4 vertices per tetrahedron, positively oriented */
    uint32_t *tn;             /* tn[4t + i]: the tetrahedron across the face opposite tv[4t + i] */
    size_t n_tet, cap_tv, cap_tn;
    uint32_t *cavity; size_t n_cavity, cap_cavity;
    /* after an insert: the cavity's faces (a, b, c, the tetrahedron outside) and the new
     * tetrahedra (one per face) */
    uint32_t *rim; size_t n_rim, cap_rim;
    uint32_t *fresh; size_t cap_fresh;
    uint64_t *edge_key; uint32_t *edge_face; size_t cap_edge; /* the rim's edges (delaunay3.c) */
    uint32_t last;            /* a live tetrahedron, where a walk starts without a hint */
    uint32_t free_tet;        /* dead slots (a cavity can hold more tetrahedra than its cone):
                                 tv[4t] = VPDSI_DT3_NONE, tn[4t] the next */
} vpdsi_dt3;

int vpdsi_dt3_init(vpdsi_dt3 *dt, vpdsi_mem *m, const double *lo, const double *hi);
void vpdsi_dt3_release(vpdsi_dt3 *dt, vpdsi_mem *m);
/* Insert sample `index` (its point at pts + 3 index, inside the box) in two steps, so that
 * the caller can make room for what the insert makes before anything changes. prepare: the
 * walk from tetrahedron `hint` (VPDSI_DT3_NONE: the last one made), the cavity and its faces
 * (n_rim of them: as many new tetrahedra), the room; returns 0, 1 when the point is already a
 * vertex, -1 on OOM, -2 when round-off left a cavity that is not a ball around the point (all
 * but 0 with nothing changed). commit (after 0): the new tetrahedra in fresh[0, n_rim), the
 * ones outside the cavity's faces in rim[4j + 3], the old cavity in cavity[0, n_cavity) (its
 * slots past n_rim now dead). */
int vpdsi_dt3_prepare(vpdsi_dt3 *dt, vpdsi_mem *m, const double *pts, size_t index, uint32_t hint);
void vpdsi_dt3_commit(vpdsi_dt3 *dt, size_t index);
static inline const double *vpdsi_dt3_point(const vpdsi_dt3 *dt, const double *pts, uint32_t v)
{
    return v < VPDSI_DT3_FAR ? dt->far_x + 3 * v : pts + 3 * (size_t)(v - VPDSI_DT3_FAR);
}
#endif
