/* Background grid for a uniform radius (Ebeida et al. 2012): cells of diagonal below the
 * conflict distance, so a cell holds at most one sample and a query scans a fixed stencil of
 * cells. Used instead of the kd-tree when every disk has the same radius and d <= 5. A border
 * of empty cells as wide as the stencil lets every query skip bounds checks. */
#ifndef VPDS_BGRID_H
#define VPDS_BGRID_H
#include "mem.h"

typedef struct vpdsi_bgrid {
    int dim;
    uint64_t n[VPDS_MAX_DIM];      /* cells per axis (the base cells of the run) */
    uint64_t stride[VPDS_MAX_DIM]; /* in the padded array */
    uint64_t pad;                  /* border width in cells */
    uint64_t origin;               /* padded index of cell (0, ..., 0) */
    double lo[VPDS_MAX_DIM], side[VPDS_MAX_DIM];
    int32_t *cell;                 /* sample index or -1 */
    size_t cap_cell, count;
    int64_t *stencil;              /* linear offsets, nearest cells first */
    size_t n_stencil, cap_stencil;
    uint16_t *stencil_tag;         /* per offset: VPDSI_BGRID_TAG of its axis-0 offset, row width */
    size_t cap_stencil_tag;
    int64_t *row;                  /* the stencil's rows along axis 0: the offset of each
                                      row's cell at axis-0 offset 0 ... */
    int *row_w;                    /* ... and the largest axis-0 offset in it */
    size_t n_rows, cap_row, cap_row_w;
    uint16_t own_tag;              /* the tag of the centre cell */
} vpdsi_bgrid;

/* A candidate's place in the stencil, for vpdsi_bgrid_slide: its cell's axis-0 offset o0 and
 * the half-width w of its row (|o0| <= w <= 8). */
#define VPDSI_BGRID_TAG(o0, w) ((uint16_t)(((o0) + 64) | ((w) << 8)))
#define VPDSI_BGRID_TAG_O0(t) ((int)((t) & 0xffu) - 64)
#define VPDSI_BGRID_TAG_W(t) ((int)((t) >> 8))

/* Past 5D the stencil (some 20,000 cells in 6D) costs more than the kd-tree's queries (1.47 s
 * against 0.25 s at r = 0.6). */
#define VPDSI_BGRID_MAX_DIM 5

/* Whether a run takes the grid (when its setup accepts the radius): one radius on open axes,
 * up to VPDSI_BGRID_MAX_DIM. Algorithm 1's index choice and the estimate of its memory. */
static inline int vpdsi_bgrid_serves(int dim, int constant_radius, int two_radii, int any_periodic)
{
    return constant_radius && dim <= VPDSI_BGRID_MAX_DIM && !two_radii && !any_periodic;
}

/* Cells (border included) of a grid of n[k] cells of side side[k] per axis for reach; 0 past
 * the stencil width setup accepts. */
double vpdsi_bgrid_cells(int dim, const double *n, const double *side, double reach);
/* Lay out over the base grid and empty it; reach is the conflict distance (>= the diagonal).
 * 0: done; -1: the grid does not serve this radius (its stencil too wide, its cells too many);
 * -2: out of memory (nothing is left allocated). */
int vpdsi_bgrid_setup(vpdsi_bgrid *g, vpdsi_mem *m, int dim, const uint64_t *n, const double *lo,
                      const double *side, double reach);
void vpdsi_bgrid_release(vpdsi_bgrid *g, vpdsi_mem *m);
/* Padded index of the cell holding x. */
uint64_t vpdsi_bgrid_locate(const vpdsi_bgrid *g, const double *x);
/* Place sample i at x for the grid's setup: inside [box_lo, box_hi] its cell (as
 * vpdsi_bgrid_locate), outside in the border when within its width, else nowhere (too far to
 * meet a query of the box). 0: placed or left out; -1: the cell already holds a sample (closer
 * than the cell's diagonal: the grid cannot hold this set). */
int vpdsi_bgrid_place(vpdsi_bgrid *g, const double *x, const double *box_lo, const double *box_hi,
                      int32_t i);
/* Padded index of base cell coordinates c. */
uint64_t vpdsi_bgrid_index(const vpdsi_bgrid *g, const uint64_t *c);
/* Samples within reach of the cell at padded index at (its own first), appended to out
 * (capacity >= 1 + n_stencil). */
size_t vpdsi_bgrid_near(const vpdsi_bgrid *g, uint64_t at, int32_t *out);
/* Asks the caches for what vpdsi_bgrid_conflict(g, x, at, y, .) will read, a few darts ahead of
 * it: stage 0 the rows of cells of its stencil, stage 1 (later, those rows cached) the points
 * in x of the nearest samples it will test. A dart's cells and samples lie anywhere in memory
 * (the samples in the order of their acceptance), and the chunk's darts are drawn before they
 * are judged. A hint only: nothing changes. */
void vpdsi_bgrid_prefetch(const vpdsi_bgrid *g, const double *x, uint64_t at, int stage);
/* vpdsi_bgrid_near with, per sample, its tag and its point (d doubles, from x) into px. */
size_t vpdsi_bgrid_near_packed(const vpdsi_bgrid *g, const double *x, uint64_t at, int32_t *out,
                               double *px, uint16_t *tag);
/* The same list for base cell at made from the n of base cell at - 1 (the one before it on axis
 * 0): the samples of that stencil's trailing cells dropped (the rest keep their order), those of
 * the new stencil's leading cells appended; a row's cells, not the whole stencil, are read (in 4D
 * about 200 of 840). The same set of samples as vpdsi_bgrid_near_packed, in another order. */
size_t vpdsi_bgrid_slide(const vpdsi_bgrid *g, const double *x, uint64_t at, int32_t *out,
                         double *px, uint16_t *tag, size_t n);
/* Asks the caches for the points vpdsi_bgrid_slide(g, x, at, ...) will copy (the samples of
 * the stencil's leading cells lie anywhere in x); at must be a base cell's, as for the slide.
 * A hint only: nothing changes. */
void vpdsi_bgrid_prefetch_slide(const vpdsi_bgrid *g, const double *x, uint64_t at);
/* The first sample within reach of y (strictly nearer), or -1; x holds the samples' points, at
 * is y's cell (vpdsi_bgrid_locate). */
int32_t vpdsi_bgrid_conflict(const vpdsi_bgrid *g, const double *x, uint64_t at, const double *y, double reach);
#endif
