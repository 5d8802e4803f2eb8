/* The farthest point of a 3D box from the samples (algorithm version 11's stream with one
 * radius): as voids.h in 2D, the distance to the nearest sample is largest at a Voronoi vertex
 * inside the box, where a Voronoi edge crosses a face of the box, where a Voronoi face crosses
 * an edge of the box, or at a corner. Each tetrahedron of the Delaunay tetrahedralisation
 * (delaunay3.h) holds the best of its circumcentre and the face crossings of the Voronoi edges
 * of the faces it owns; each edge of the box keeps the lower envelope of its samples' distances
 * along it (a 1D diagram), whose breakpoints are the edge crossings. */
#ifndef VPDS_VOIDS3_H
#define VPDS_VOIDS3_H
#include "delaunay3.h"
#include "index_heap.h"

/* The samples whose distance is least somewhere along one edge of the box, in order along it:
 * their coordinate along the edge and squared distance to its line. */
typedef struct vpdsi_box_edge {
    double *s, *h2; uint32_t *who; size_t count, cap_s, cap_h2, cap_who;
    double best2, best[3];    /* the farthest breakpoint inside the edge: squared gap, point */
    double top2;              /* the envelope's largest value over the edge (ends included) */
} vpdsi_box_edge;

typedef struct vpdsi_voids3 {
    int ready;
    vpdsi_dt3 dt;
    size_t n;                 /* samples in it: the store's [0, n) */
    double corner_d2[8];
    vpdsi_box_edge edge[12];
    vpdsi_index_heap heap;    /* the tetrahedra by the squared gap of their candidate */
    uint32_t hint;
    double bound;             /* an upper bound of the largest gap: no crossing farther from its
                                 samples is valid, so none is computed */
    uint64_t *batch; size_t n_batch, at, cap_batch; /* as vpdsi_voids */
} vpdsi_voids3;

void vpdsi_voids3_init(vpdsi_voids3 *vd);
void vpdsi_voids3_release(vpdsi_voids3 *vd, vpdsi_mem *m);
/* As vpdsi_voids_sync, in 3D (pts: 3 per sample); bound: an upper bound of the box's largest
 * gap now (the scale at which the set is maximal; +inf: none known). */
int vpdsi_voids3_sync(vpdsi_voids3 *vd, vpdsi_mem *m, const double *lo, const double *hi,
                      const double *pts, size_t n, double bound);
/* The farthest point y of the box from the samples and its squared distance to the nearest. */
double vpdsi_voids3_farthest(vpdsi_voids3 *vd, const double *pts, double *y);
#endif
