/* An incremental Delaunay triangulation of points in the plane (Bowyer-Watson). Its dual, the
 * Voronoi diagram, holds the candidates of the stream's farthest point (voids.c). Three far
 * vertices (0, 1, 2) enclose the box; the sample of index i is vertex i + VPDSI_DT_FAR, its
 * coordinates read from the caller's array (the store's, which may move between calls). */
#ifndef VPDS_DELAUNAY_H
#define VPDS_DELAUNAY_H
#include "mem.h"

#define VPDSI_DT_NONE UINT32_MAX
#define VPDSI_DT_FAR 3u
/* The most points a triangulation takes: its 2n + 1 triangles must have 32-bit indices. */
#define VPDSI_DT_MAX_POINTS ((size_t)1 << 30)

typedef struct vpdsi_dt {
    double far_x[6];          /* the enclosing vertices, far enough that no point of the box
                                 is nearer to one of them than to a sample inside it */
    double lo[2], hi[2];      /* the points it takes lie in this box */
    uint32_t *tv;             /* 3 vertices per triangle, counter-clockwise */
    uint32_t *tn;             /* tn[3t + i]: the triangle across the edge opposite tv[3t + i] */
    size_t n_tri, cap_tv, cap_tn;
    uint32_t *cavity; size_t n_cavity, cap_cavity;
    /* after an insert: the cavity's edges (a, b, the triangle outside) and the new triangles */
    uint32_t *rim; size_t n_rim, cap_rim;
    uint32_t *fresh; size_t cap_fresh;
    uint32_t last;            /* a live triangle, where a walk starts without a hint */
} vpdsi_dt;

/* The triangle of the far vertices around the box [lo, hi]; -1 on OOM. */
int vpdsi_dt_init(vpdsi_dt *dt, vpdsi_mem *m, const double *lo, const double *hi);
void vpdsi_dt_release(vpdsi_dt *dt, vpdsi_mem *m);
/* Insert sample `index` (its point at pts + 2 index, inside the box), the walk starting at
 * triangle `hint` (VPDSI_DT_NONE: the last one made). Returns 0 (the new triangles in
 * fresh[0, n_rim), the triangles outside the cavity's edges in rim[3j + 2]), 1 when the point
 * is already a vertex (nothing changed), -1 on OOM and -2 when round-off left a cavity that is
 * not a disk around the point: both with nothing changed. */
int vpdsi_dt_insert(vpdsi_dt *dt, vpdsi_mem *m, const double *pts, size_t index, uint32_t hint);
/* The triangles whose circumcircle holds p (into cavity[0, n_cavity)), grown from `hint` or
 * from the triangle that holds p, with a margin for round-off: the cavity p would have, so
 * that p's nearest point is among their vertices (the edge from p to it is Delaunay), with
 * perhaps a triangle more. Returns 0, -1 on OOM, -2 when p lies outside the far triangle. */
int vpdsi_dt_near(vpdsi_dt *dt, vpdsi_mem *m, const double *pts, const double *p, uint32_t hint);
/* A vertex's coordinates. */
static inline const double *vpdsi_dt_point(const vpdsi_dt *dt, const double *pts, uint32_t v)
{
    return v < VPDSI_DT_FAR ? dt->far_x + 2 * v : pts + 2 * (size_t)(v - VPDSI_DT_FAR);
}
#endif
