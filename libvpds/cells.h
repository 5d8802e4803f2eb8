/* The flat hyper-octree of Algorithm 1: the active cells of one level, all the same size, stored
 * as integer coordinates bit-packed into one 32-bit word per cell when they fit (a 2D lattice of
 * 2^11 base cells per axis until level 5), else into 64-bit words (covered cells cost nothing). */
#ifndef VPDS_CELLS_H
#define VPDS_CELLS_H
#include "mem.h"

typedef struct vpdsi_cells {
    uint64_t *words;     /* read and written through memcpy: 32-bit cells share the words */
    size_t cap_words;
    size_t count;        /* cells held */
    unsigned level;
    unsigned words_per_cell; /* 64-bit words per cell; 0: one 32-bit word per cell */
    unsigned bits[VPDS_MAX_DIM], offset[VPDS_MAX_DIM];
} vpdsi_cells;

/* Empty the array and lay it out for `level` over a base grid of n0[k] cells per axis. */
void vpdsi_cells_layout(vpdsi_cells *c, int dim, const uint64_t *n0, unsigned level);
int vpdsi_cells_reserve(vpdsi_cells *c, vpdsi_mem *m, size_t cells);
/* The room past the cells held given back (a level's cells, once its sweep made them all). */
void vpdsi_cells_shrink(vpdsi_cells *c, vpdsi_mem *m);
void vpdsi_cells_release(vpdsi_cells *c, vpdsi_mem *m);
/* Append (after reserve; never allocates) and read back. */
void vpdsi_cells_push(vpdsi_cells *c, int dim, const uint64_t *coord);
void vpdsi_cells_get(const vpdsi_cells *c, size_t i, int dim, uint64_t *coord);
/* A hint that cell i will be read soon (a dart's cell is drawn at random among them all). */
void vpdsi_cells_prefetch(const vpdsi_cells *c, size_t i);
/* Copy cell `from` over cell `to` (in-place compaction, to <= from). */
void vpdsi_cells_move(vpdsi_cells *c, size_t from, size_t to);
/* The geometry of the cells: a base grid of n0[k] cells of side side0[k] per axis over the box
 * [lo, hi], halved per level. Shared by Algorithm 1's cells and the stream's regions. */
typedef struct vpdsi_lattice {
    int dim;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    uint64_t n0[VPDS_MAX_DIM];
    double side0[VPDS_MAX_DIM];
} vpdsi_lattice;

/* Box of the cell at `level` with integer coordinates c (the last cell of an axis ends exactly
 * at the box's face); returns the squared diagonal. */
double vpdsi_lattice_box(const vpdsi_lattice *g, unsigned level, const uint64_t *c, double *lo,
                         double *hi);

/* Side of the base cells of a run whose largest disk reaches `reach` (t * coverage * r_max):
 * a diagonal just under it, so that a sample covers a cell of its own size. */
double vpdsi_lattice_base_side(double reach, int dim);
/* Base cells of that side over [lo, hi] (at least 1 per axis), as a double: it may be huge. */
double vpdsi_lattice_base_count(int dim, const double *lo, const double *hi, double side);

/* Bits needed to hold values below n (at least 1). */
unsigned vpdsi_bit_length(uint64_t n);
#endif
