/* Continuous decrease (Section 4.2): the state of the one-sample-at-a-time stream. */
#ifndef VPDS_STREAM_H
#define VPDS_STREAM_H
#include "cells.h"
#include "context.h"
#include "region_heap.h"
#include "voids.h"
#include "voids3.h"

/* The box is cut into regions (cells of a lazily refined grid) in a max-heap keyed by an upper
 * bound of g = distance to the samples over coverage * f, the scale at which a point becomes
 * covered. Samples only lower g, so a stale key stays an upper bound (DESIGN.md). */
typedef struct vpdsi_stream {
    int active;                    /* regions built */
    vpdsi_lattice geom;            /* level-0 regions and their boxes */
    unsigned max_level;
    vpdsi_region_heap regions;     /* records: key; level, g at the cached maximiser,
                                      coordinates[dim], maximiser[dim] */
    double *boxes;                 /* the search inside one region: key, centre, half sides */
    size_t n_boxes, cap_boxes;
    double *buf;                   /* centres and radii of one split */
    double *kids; size_t cap_kids; /* one split's 2^d children: centres, g, bounds */
    uint64_t *kid_cells; size_t cap_kid_cells; /* and their cells */
    double lb;                     /* version 3: the largest g seen while the store held lb_n */
    size_t lb_n;                   /* samples (lb is -1 once a sample is added) */
    size_t cap_buf;
    /* version 5: the exact search of a region (exact_region in stream.c) */
    int32_t *cand; size_t n_cand, cap_cand; /* samples within reach of the region */
    double *cand_x; size_t cap_cand_x;      /* their images within reach of it */
    int32_t *lists; size_t cap_lists;       /* the candidates left at each depth of the split */
    /* version 8: the samples that may be nearest in an open box of the search, one list per
     * split shared by its children, which filter it for theirs */
    int32_t *near; size_t n_near, cap_near;
    /* version 10, one radius in 2D (11: and 3D): the Voronoi diagram's candidates (voids.h,
     * voids3.h), until a sample outside the box or round-off makes it give way to the regions
     * (voids_off) */
    vpdsi_voids voids;
    vpdsi_voids3 voids3;
    int voids_off;
} vpdsi_stream;

void vpdsi_stream_init(vpdsi_stream *sm);
void vpdsi_stream_release(vpdsi_stream *sm, vpdsi_mem *m);
/* One event: the sample and its t, or VPDS_STREAM_END when t <= t_min (nothing consumed).
 * t_cap: the scale at which the set is already maximal (a run's, or the last event's); no
 * event is placed above it (+INFINITY: none). */
vpds_status vpdsi_stream_next(vpdsi_stream *sm, const vpdsi_ctx *ctx, double t_min, double t_cap,
                              double *x_out, double *t_out);
#endif
