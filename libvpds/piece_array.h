/* The active pieces of a surface run (surface.c): an array whose records take 16 bytes while
 * every coordinate of the pieces it may hold fits 32 bits (a lattice of m 2^level < 2^32 per
 * edge, as the box's cells do), 24 past it. The pieces read back are those stored. */
#ifndef VPDS_PIECE_ARRAY_H
#define VPDS_PIECE_ARRAY_H
#include "pieces.h"

typedef struct vpdsi_piece_array {
    unsigned char *data;
    size_t n;          /* pieces held */
    size_t cap;        /* bytes */
    int wide;          /* 24-byte records */
    unsigned max_level; /* deepest level pushed since the array was emptied */
} vpdsi_piece_array;

void vpdsi_piece_array_release(vpdsi_piece_array *a, vpdsi_mem *m);
/* Forget the pieces, keep the memory. */
void vpdsi_piece_array_clear(vpdsi_piece_array *a);
/* Room for `need` pieces whose coordinates stay below 2^bits (the records widen, the pieces
 * held kept, when bits passes 32); -1 on OOM, nothing changed. */
int vpdsi_piece_array_reserve(vpdsi_piece_array *a, vpdsi_mem *m, size_t need, unsigned bits);
/* Piece k. */
vpdsi_piece vpdsi_piece_array_get(const vpdsi_piece_array *a, size_t k);
/* Append a piece (after a reserve that covers it). */
void vpdsi_piece_array_push(vpdsi_piece_array *a, const vpdsi_piece *p);
#endif
