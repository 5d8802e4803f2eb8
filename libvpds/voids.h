/* The farthest point of a 2D box from the samples (algorithm version 10's stream with one
 * radius): the distance to the nearest sample, convex inside each Voronoi cell and along each
 * Voronoi edge, is largest at a Voronoi vertex inside the box, where a Voronoi edge crosses
 * the box's boundary, or at a corner. Each triangle of the Delaunay triangulation (delaunay.h)
 * holds the best of its circumcentre and the crossings of its edges' bisectors; the triangles
 * sit in a max-heap that an insertion changes only around the new sample. */
#ifndef VPDS_VOIDS_H
#define VPDS_VOIDS_H
#include "delaunay.h"
#include "index_heap.h"

typedef struct vpdsi_voids {
    int ready;                /* the triangulation is made */
    vpdsi_dt dt;
    size_t n;                 /* samples in it: the store's [0, n) */
    double corner_d2[4];      /* each corner's squared distance to its nearest sample */
    vpdsi_index_heap heap;    /* the triangles by the squared gap of their candidate */
    uint32_t hint;            /* the triangle of the last farthest point: the next walk's start */
    double bound;             /* an upper bound of the largest gap: no crossing farther from its
                                 samples than this can be valid, so none is computed */
    /* samples that came in a batch (a run's, fixed points), inserted in Morton order so that
     * each walk is short: (key << 32 | index), the next at batch[at] */
    uint64_t *batch; size_t n_batch, at, cap_batch;
} vpdsi_voids;

void vpdsi_voids_init(vpdsi_voids *vd);
void vpdsi_voids_release(vpdsi_voids *vd, vpdsi_mem *m);
/* Insert the samples [vd->n, n) of the box [lo, hi] (points pts, 2 per sample), several at
 * once in Morton order; bound: an upper bound of the box's largest gap (INFINITY: none). Returns 0, -1 on OOM (a retry goes on in the same order, so that the
 * triangulation is the one a sync that never failed makes), or -2 when a sample lies outside
 * the box or round-off broke a cavity: the triangulation then no longer serves. */
int vpdsi_voids_sync(vpdsi_voids *vd, vpdsi_mem *m, const double *lo, const double *hi,
                     const double *pts, size_t n, double bound);
/* The squared distance *d2 from x (in the box, after a sync) to its nearest sample, found
 * among the vertices of the triangles whose circumcircle holds x (the edge from x to its
 * nearest sample is Delaunay), or to a sample nearer than sqrt(below) when one of the last
 * farthest point's triangle is. Returns 0, -1 on OOM, -2 when x lies outside the far triangle
 * (never, for x in the box). */
int vpdsi_voids_nearest2(vpdsi_voids *vd, vpdsi_mem *m, const double *pts, const double *x, double below,
                         double *d2);
/* The farthest point y of the box from the samples (after a sync with at least one sample)
 * and its squared distance to the nearest one. */
double vpdsi_voids_farthest(vpdsi_voids *vd, const double *pts, double *y);
#endif
