/* The sample store: the samples in insertion order (points, radii, scales, flags), the index
 * that answers proximity questions about them (kd-tree, or the background grid for a uniform
 * radius), the radius at a point, the periodic wrap, and the error sink every layer writes to.
 * The algorithms call down into it; it calls only the leaves. */
#ifndef VPDS_STORE_H
#define VPDS_STORE_H
#include "bgrid.h"
#include "kdtree.h"
#include "ogrid.h"
#include "sizing.h"

typedef struct vpdsi_store {
    vpdsi_mem *mem;                /* the sampler's allocator */
    int dim;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    double period[VPDS_MAX_DIM];   /* box side on a periodic axis, 0 on an open one */
    vpdsi_sizing sizing;
    size_t n, n_fixed;
    size_t expect;       /* the samples a run is expected to hold (0: unknown): a reserve below it
                            takes it whole, so the arrays do not end up to half again too large */
    double *x; size_t cap_x;
    double *r; size_t cap_r;
    double *t; size_t cap_t;
    uint8_t *flags; size_t cap_flags;
    vpdsi_kdtree tree;   /* holds samples [0, tree_n); synced before kd-tree queries */
    size_t tree_n;
    vpdsi_bgrid grid;    /* the uniform-radius accelerator, in use when grid_mode */
    int grid_mode;
    vpdsi_ogrid ogrid;   /* the variable-radius index, in use when ogrid_mode */
    int ogrid_mode;
    char err[512];
} vpdsi_store;

/* The largest expected count a store reserves at once (16.7 million: 550 MB of samples in 2D). */
#define VPDSI_STORE_EXPECT_MAX ((size_t)1 << 24)

/* An empty store over the box [lo, hi] (period may be NULL: no periodic axis); the sizing is
 * filled by the caller. */
void vpdsi_store_init(vpdsi_store *st, vpdsi_mem *mem, int dim, const double *lo,
                      const double *hi, const double *period);
void vpdsi_store_release(vpdsi_store *st);
void vpdsi_store_error(vpdsi_store *st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Replace coordinates outside the box on periodic axes by their image inside. */
void vpdsi_store_wrap(const vpdsi_store *st, double *x);
/* r at a point, wrapped into the box on periodic axes (where the sizing is defined). */
vpds_status vpdsi_store_radius_at(vpdsi_store *st, const double *p, double *r);
/* r at n points (unwrapped), errors said in the store's sink. */
vpds_status vpdsi_store_radii(vpdsi_store *st, const double *x, size_t n, double *out);
/* Room for `more` samples in every per-sample array and the tree; nothing changes on failure. */
vpds_status vpdsi_store_reserve(vpdsi_store *st, size_t more);
/* Insert samples [tree_n, n) into the kd-tree (before kd-tree queries after grid mode). */
vpds_status vpdsi_store_sync_tree(vpdsi_store *st);
/* Append and index a sample (after vpdsi_store_reserve); a kd-tree that lags stays behind. */
void vpdsi_store_append(vpdsi_store *st, const double *x, double r, double t, uint8_t flags);
/* The same without the kd-tree (no grid in use): it lags until vpdsi_store_sync_tree, and a
 * reserve for it holds no room in the tree. For an algorithm that keeps its own index (the 2D
 * stream's triangulation), so that samples are not indexed twice. */
vpds_status vpdsi_store_reserve_lagging(vpdsi_store *st, size_t more);
void vpdsi_store_append_lagging(vpdsi_store *st, const double *x, double r, double t, uint8_t flags);
/* Index the samples (dim <= 3) with the octave grid (radii from bottom, 0 if unknown, up to
 * about top; its coarsest levels in arrays of up to dense_cells cells) until use_tree or
 * drop_index; queries then go through vpdsi_store_conflict and vpdsi_store_gather. A box too
 * wide for the grid's cells keeps the kd-tree (synced). On failure the store is left with no
 * accelerator (the kd-tree, maybe lagging). */
vpds_status vpdsi_store_use_ogrid(vpdsi_store *st, double top, double bottom, double dense_cells);
/* Done at a scale: drop the background or octave grid (the kd-tree lags behind, synced when
 * next needed). */
void vpdsi_store_drop_index(vpdsi_store *st);
/* vpdsi_kd_conflict / vpdsi_kd_gather on the index in use (kd-tree or octave grid). */
int32_t vpdsi_store_conflict(const vpdsi_store *st, const double *y, double ry, int rule,
                             double scale, double lipschitz, int32_t *witness);
int vpdsi_store_gather(const vpdsi_store *st, const double *lo, const double *hi, double r_hi,
                       int rule, double scale, int split, int32_t **out, size_t *count,
                       size_t *cap);
/* Ask the caches for what a conflict query at y (radius ry) will read, a few queries ahead
 * (stage 0 the index's cells, stage 1 their samples: vpdsi_ogrid_prefetch); nothing with the
 * kd-tree, nor with the background grid, whose callers know the query's cell
 * (vpdsi_bgrid_prefetch). Changes nothing. */
void vpdsi_store_prefetch(const vpdsi_store *st, const double *y, double ry, int stage);
/* vpdsi_kd_near_box without a limit on the index in use (kd-tree or octave grid): every sample
 * near the box [lo, hi] appended to *out; VPDS_ERR_OUT_OF_MEMORY said in the sink. */
vpds_status vpdsi_store_near_box(vpdsi_store *st, const double *lo, const double *hi, double r_bound,
                                 double scale, int32_t **out, size_t *count, size_t *cap);
/* Leave grid mode: the kd-tree takes over (it must hold every sample first). */
vpds_status vpdsi_store_use_tree(vpdsi_store *st);
/* Fixed points (vpds_add_points, after its checks): stored in the caller's order, each wrapped
 * into the box on periodic axes, with radius r[i] or, r NULL, the sizing's; nothing changes
 * on failure. The kd-tree takes over from the grid. */
vpds_status vpdsi_store_add_fixed(vpdsi_store *st, const double *x, const double *r, size_t n);
vpdsi_kd_samples vpdsi_store_view(const vpdsi_store *st);
/* The point y of radius ry met sample i (a conflict query's witness) whose radius breaks the
 * sizing's L: says both points and the slope, returns VPDS_ERR_LIPSCHITZ. */
vpds_status vpdsi_store_lipschitz_broken(vpdsi_store *st, const double *y, double ry, int32_t i);
/* Whether a sample not added as a fixed point exists. */
int vpdsi_store_has_samples(const vpdsi_store *st);
#endif
