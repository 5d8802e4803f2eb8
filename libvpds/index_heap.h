/* An indexed max-heap of (key, id): each id (a triangle, a tetrahedron) holds at most one
 * entry, whose key can change or which can leave in O(log n). Equal keys come off by the lower
 * id, so the order is a function of the keys alone. The stream's candidate voids (voids.c,
 * voids3.c). */
#ifndef VPDS_INDEX_HEAP_H
#define VPDS_INDEX_HEAP_H
#include "mem.h"

#define VPDSI_INDEX_HEAP_NONE UINT32_MAX

typedef struct vpdsi_index_heap {
    double *key; size_t cap_key;   /* heap order: key[i] of id[i] */
    uint32_t *id; size_t cap_id;
    size_t count;
    uint32_t *pos; size_t cap_pos; /* each id's place, or VPDSI_INDEX_HEAP_NONE */
    size_t n_ids;                  /* ids with a place: [0, n_ids) */
} vpdsi_index_heap;

void vpdsi_index_heap_init(vpdsi_index_heap *h);
void vpdsi_index_heap_release(vpdsi_index_heap *h, vpdsi_mem *m);
/* Room for ids [0, ids) (those new to it out of the heap); -1 on OOM, nothing changed. */
int vpdsi_index_heap_reserve(vpdsi_index_heap *h, vpdsi_mem *m, size_t ids);
/* id's entry made to hold key, or taken out when key < 0 (after a reserve that covers id). */
void vpdsi_index_heap_set(vpdsi_index_heap *h, uint32_t id, double key);
#endif
