/* Private layout of vpds_grid, shared with the sizing evaluator. */
#ifndef VPDS_GRID_H
#define VPDS_GRID_H
#include "mem.h"

#define VPDSI_GRID_COOKIE 0x56504447u /* 'VPDG' */

struct vpds_grid {
    uint32_t magic;
    int dim;
    size_t shape[VPDS_MAX_DIM];
    size_t stride[VPDS_MAX_DIM];
    size_t n;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], step[VPDS_MAX_DIM];
    /* a window (vpds_grid_create_window) holds nodes [offset, offset + shape) of a grid of
     * `whole` nodes per axis; lo, hi and step are the whole grid's (offset 0, whole = shape
     * for a plain grid), so a point evaluates bit for bit as in the whole grid */
    size_t offset[VPDS_MAX_DIM], whole[VPDS_MAX_DIM];
    int window;
    double *values;
    double lipschitz; /* exact, recomputed after every change */
    double vmin, vmax;
    vpdsi_mem mem;
};

/* The grid of a descriptor whose layout is known valid; its values may be any finite numbers
 * (the mask domain's signed distances use this). */
vpds_status vpdsi_grid_build(const vpds_grid_desc *d, vpds_grid **out);
/* A copy of g made with the allocator m (used by the sampler, which owns its copy). */
vpds_status vpdsi_grid_clone(const vpds_grid *g, const vpds_allocator *a, vpds_grid **out);
#endif
