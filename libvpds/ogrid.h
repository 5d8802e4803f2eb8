/* The octave grid: the neighbour index of a variable radius in 1-3D. A sample of radius r is
 * filed at the level whose cell side s = 2 top * 2^-level is the smallest at or above 2r (so that
 * a reach up to r spans two cells per axis, four probes in 2D where r gave up to nine), in one
 * hash table of (level, cell) keys, or, for the coarsest levels while their cells over the box
 * are few, in an array by cell (no hashing). A query visits, level by level, the cells within that
 * level's reach (from the largest radius it holds, so no bound on L is assumed) and only the
 * levels whose bounding box it meets; near a point an L-Lipschitz sizing fills two or three
 * levels, so a query reads a few cells of each where the kd-tree walks from its root. */
#ifndef VPDS_OGRID_H
#define VPDS_OGRID_H
#include "mem.h"
#include "samples.h"

#define VPDSI_OGRID_LEVELS 40
#define VPDSI_OGRID_BITS 19 /* cell coordinate bits per axis (dim <= 3) */

typedef struct vpdsi_ogrid_level {
    double side, inv, rmax;        /* cell side and its inverse; largest radius filed here */
    double lo[3], hi[3];           /* bounding box of its samples */
    uint64_t clo[3], chi[3];       /* ... in cells */
    size_t count;
    /* a level with few cells over the whole box holds its cells' first samples in an array, by
     * cell, rather than in the table: dn[k] cells per axis, cells in all (0: the table); a
     * sample past the box's far side goes to its last cell (queries reach it: cell_beyond) */
    int32_t *dense;
    uint64_t dn[3];
    size_t cells;
} vpdsi_ogrid_level;

typedef struct vpdsi_ogrid {
    int dim, levels;               /* levels in use: side >= the box extent / 2^BITS and >= 2
                                      bottom (vpdsi_ogrid_setup) */
    int n_hashed;                  /* levels past the dense ones (they file in the table) */
    double lo[3];
    vpdsi_ogrid_level lv[VPDSI_OGRID_LEVELS];
    uint64_t *keys;                /* 0: empty slot; else 1 + (level, cell) */
    int32_t *heads;                /* first sample of the slot's cell */
    size_t cap, used;              /* slots (a power of two), slots in use */
    int32_t *next;                 /* per sample: the next one of its cell, -1 at the end */
    size_t cap_next;
} vpdsi_ogrid;

/* Lay out over the box [lo, hi] for radii from bottom (0: unknown) up to about top; the
 * coarsest levels whose cells over the box number at most dense_cells in all are held in arrays
 * (vpdsi_ogrid_reserve allocates them). -1 when dim > 3, -2 when the box is 2^BITS cells of side
 * top wide or more (nothing held either way). */
int vpdsi_ogrid_setup(vpdsi_ogrid *g, int dim, const double *lo, const double *hi, double top,
                      double bottom, double dense_cells);
void vpdsi_ogrid_release(vpdsi_ogrid *g, vpdsi_mem *m);
/* Room for `more` inserts, the grid then holding n_total samples; -1 on OOM (nothing lost). */
int vpdsi_ogrid_reserve(vpdsi_ogrid *g, vpdsi_mem *m, size_t n_total, size_t more);
/* File sample i (after a reserve). Never allocates. */
void vpdsi_ogrid_insert(vpdsi_ogrid *g, const vpdsi_kd_samples *s, int32_t i);
/* vpdsi_kd_conflict and vpdsi_kd_gather on the grid (open axes only): the same per-sample
 * tests (proximity.h), so the same answers; other orders. */
int32_t vpdsi_ogrid_conflict(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *y,
                             double ry, int rule, double scale, double lipschitz,
                             int32_t *witness);
int vpdsi_ogrid_gather(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *lo,
                       const double *hi, double r_hi, int rule, double scale, int split,
                       vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap);
/* Whether vpdsi_ogrid_gather(lo, hi, r_hi, rule, scale, split) lists sample i: its test of
 * the sample, which passes only within the reach that its cell ranges read (widened). */
int vpdsi_ogrid_gathers(const vpdsi_kd_samples *s, int dim, int32_t i, const double *lo,
                        const double *hi, double r_hi, int rule, double scale, int split);
/* Ask the caches for what a conflict query at y (radius ry) reads first, a few queries ahead:
 * stage 0 the table's slot of y's cell at ry's level (the query tests that cell first), stage 1
 * (once it is in) the point, radius and chain link of that cell's newest sample. Changes
 * nothing. */
void vpdsi_ogrid_prefetch(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *y,
                          double ry, int stage);
/* vpdsi_kd_near_box on the grid, without a limit: every sample near the box, appended to *out
 * (grown with m); -1 on OOM. */
int vpdsi_ogrid_near_box(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *lo,
                         const double *hi, double r_bound, double scale, vpdsi_mem *m,
                         int32_t **out, size_t *count, size_t *cap);
/* The samples within scale * f(r(x), r_bound) of the box [lo, hi] (f of the rule, widened by
 * 1e-9): every one that may cover a part of it for a point of r <= r_bound there, appended to
 * *out; -1 on OOM. */
int vpdsi_ogrid_near_rule(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *lo,
                          const double *hi, double r_bound, int rule, double scale, vpdsi_mem *m,
                          int32_t **out, size_t *count, size_t *cap);
#endif
