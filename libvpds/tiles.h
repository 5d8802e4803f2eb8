/* Private layout of vpds_tiling: the whole problem, the grid of tiles and the margin. */
#ifndef VPDS_TILES_H
#define VPDS_TILES_H
#include "mem.h"

#define VPDSI_TILING_MAGIC 0x56505454u       /* 'VPTT' */
#define VPDSI_TILING_DESC_COOKIE 0x56505444u /* 'VPTD': layout 1 of vpds_tiling_desc */

struct vpds_tiling {
    uint32_t magic;
    vpdsi_mem mem;
    int dim;
    vpds_desc desc;                  /* the sampler's; lo, hi, periodic, sizing_grid point below */
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    int periodic[VPDS_MAX_DIM];
    uint64_t tiles[VPDS_MAX_DIM];    /* tiles per axis */
    uint64_t count;
    vpds_grid *grid;                 /* owned clone of the sampler's sizing_grid, or NULL */
    int per_tile;                    /* the sizing arrives as a window per tile */
    double scale, margin;
    double lipschitz, rmin, rmax;    /* the whole sizing's, imposed on every tile's sampler */
};

/* 3^dim: the neighbour offsets of a tile (itself included), the room its dependencies need. */
unsigned vpdsi_tiling_codes(int dim);
/* The tiles this tile's run needs, ascending, into buf (vpdsi_tiling_codes(dim) entries);
 * returns the count. */
size_t vpdsi_tiling_deps_into(const vpds_tiling *t, uint64_t tile, uint64_t *buf);
/* vpds_tile_create with another allocator for the tile (NULL: the tiling's): a parallel run's
 * lock around the caller's allocator. */
vpds_status vpdsi_tile_create(const vpds_tiling *t, uint64_t tile, const vpds_tile_points *deps,
                              size_t n_deps, const vpds_grid *window,
                              const vpds_allocator *allocator, vpds_sampler **out,
                              size_t *n_fixed, char *msg, size_t cap);
#endif
