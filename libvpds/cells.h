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
    /* families (vpdsi_cells_layout_families): the cells are the children of cells one level
     * up, one record per parent: its coordinates, packed as that level packs them (the fields
     * above describe it then), and a mask of its children (bit b: child b, 2 parent + bit k
     * of b on axis k), listed in the order a flat array would hold them. A parent with 8 or
     * 16 children takes 5 or 6 bytes where they took 32 or 64. Cell 64 j lies in family
     * bucket_fam[j], which begins bucket_off[j] cells before it: a cell is found in a few
     * steps. */
    int families;
    size_t n_fam;
    unsigned mask_bytes, fam_bytes; /* a record: the mask, then the coordinates */
    uint8_t *fam; size_t cap_fam;
    uint64_t *bucket_fam; size_t cap_bucket_fam;
    uint8_t *bucket_off; size_t cap_bucket_off;
    /* stored back to front (vpdsi_cells_reverse): flat cell i, or family record i, at place
     * rev_top - i (the buckets stay as they are) */
    int reversed;
    size_t rev_top;
    /* vpdsi_cells_get_seq's last read: cell seq_i, child seq_b of family seq_f (whose first
     * cell is seq_first and whose coordinates are seq_parent) */
    size_t seq_i, seq_f, seq_first;
    unsigned seq_b;
    uint64_t seq_parent[VPDS_MAX_DIM];
    int seq_set;
} vpdsi_cells;

#define VPDSI_CELLS_BUCKET_SHIFT 6
/* 64-bit words of the widest cell: no axis takes more than 64 bits */
#define VPDSI_CELLS_MAX_WORDS VPDS_MAX_DIM
#define VPDSI_CELLS_BUCKET (1u << VPDSI_CELLS_BUCKET_SHIFT)

/* Empty the array and lay it out for `level` over a base grid of n0[k] cells per axis. */
void vpdsi_cells_layout(vpdsi_cells *c, int dim, const uint64_t *n0, unsigned level);
int vpdsi_cells_reserve(vpdsi_cells *c, vpdsi_mem *m, size_t cells);
/* Whether a split's children are kept as families: from 3D (in 2D a family holds 2 to 3
 * cells, little saved for 1.18x the time) to 8D (past it children come in blocks); the two
 * radii keep a flag per child. */
int vpdsi_cells_families_serve(int dim, int two_radii);
/* Bytes of a family's record: its mask (2^dim bits, a byte at least), then its parent's
 * coordinates in parent_bits bits packed as a level packs them (4 bytes, or 64-bit words). */
unsigned vpdsi_cells_family_bytes(int dim, unsigned parent_bits);
/* Empty the array and lay it out as families (above) for cells at `level` >= 1 (dim <= 8). */
void vpdsi_cells_layout_families(vpdsi_cells *c, int dim, const uint64_t *n0, unsigned level);
/* Room for `more` families with all their children. */
int vpdsi_cells_reserve_families(vpdsi_cells *c, vpdsi_mem *m, size_t more, int dim);
/* Append the children of parent whose bits are set in children (2^dim bits, 64 a word; after
 * reserve_families, never allocates; none set: nothing). */
void vpdsi_cells_push_family(vpdsi_cells *c, int dim, const uint64_t *parent, const uint64_t *children);
/* The room past the cells held given back (a level's cells, once its sweep made them all). */
void vpdsi_cells_shrink(vpdsi_cells *c, vpdsi_mem *m);
/* Cut back to the first `count` cells and `n_fam` families (a sweep's retry after an error:
 * what it held before the failed cell); the reading cursor of get_seq starts over. */
void vpdsi_cells_truncate(vpdsi_cells *c, size_t count, size_t n_fam);
/* Empty the array and give back its room as a shrink does: through realloc, which keeps a
 * large block mapped (a free would raise glibc's mmap threshold, and the blocks that follow
 * would come from the heap, which keeps their pages: 19 MiB more at the ramp's peak). */
void vpdsi_cells_empty(vpdsi_cells *c, vpdsi_mem *m);
void vpdsi_cells_release(vpdsi_cells *c, vpdsi_mem *m);
/* Store the cells (flat) or the family records back to front, each at the same index: a sweep
 * that reads them in order then gives back the room of those it has read
 * (vpdsi_cells_give_back_read), so that its peak holds little more than the larger of the two
 * levels where it held both whole (the run's peak). Only get, get_seq, prefetch and
 * give_back_read read a reversed array; truncate, empty and layout make it a plain one again. */
void vpdsi_cells_reverse(vpdsi_cells *c);
/* The room of cells 0 .. read - 1 of a reversed array given back through realloc (with
 * families, of those before the family of the first cell of the bucket of cell read - 1),
 * an eighth of it at a time (none by an allocator without realloc, or when it refuses). */
void vpdsi_cells_give_back_read(vpdsi_cells *c, vpdsi_mem *m, size_t read);
/* Append (after reserve; never allocates) and read back. */
void vpdsi_cells_push(vpdsi_cells *c, int dim, const uint64_t *coord);
void vpdsi_cells_get(const vpdsi_cells *c, size_t i, int dim, uint64_t *coord);
/* The same, reading on from the cell this function read last when i comes right after it (a
 * sweep reads its cells in order: no bucket is searched, no parent unpacked twice). */
void vpdsi_cells_get_seq(vpdsi_cells *c, size_t i, int dim, uint64_t *coord);
/* A hint that cell i will be read soon (a dart's cell is drawn at random among them all). */
void vpdsi_cells_prefetch(const vpdsi_cells *c, size_t i);
/* With families, the first of two hints, further ahead: cell i's bucket (vpdsi_cells_prefetch
 * then reads it and asks for the family). */
void vpdsi_cells_prefetch_bucket(const vpdsi_cells *c, size_t i);
/* Copy cell `from` over cell `to` (in-place compaction, to <= from; flat arrays only). */
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
/* Where the cell's halves meet on each axis: the children's boxes at level + 1 are [lo, mid]
 * and [mid, hi], the same bits as vpdsi_lattice_box gives them (its box at `level` is theirs
 * joined: scaling by 2 is exact). */
void vpdsi_lattice_mid(const vpdsi_lattice *g, unsigned level, const uint64_t *c, double *mid);

/* Side of the base cells of a run whose largest disk reaches `reach` (t * coverage * r_max):
 * a diagonal just under it, so that a sample covers a cell of its own size. */
double vpdsi_lattice_base_side(double reach, int dim);
/* Base cells of that side over [lo, hi] (at least 1 per axis), as a double: it may be huge. */
double vpdsi_lattice_base_count(int dim, const double *lo, const double *hi, double side);

/* Bits needed to hold values below n (at least 1). */
unsigned vpdsi_bit_length(uint64_t n);
#endif
