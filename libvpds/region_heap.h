/* The stream's region heap: a max-heap of (key, level, slot) entries over records kept in place
 * in a pool of slots, so that a sift moves 13 bytes per level rather than a whole record (3 + 2d
 * words). The entries are compared and moved exactly as a heap of whole records would be, so
 * regions come off it in the same order. */
#ifndef VPDS_REGION_HEAP_H
#define VPDS_REGION_HEAP_H
#include "mem.h"

typedef struct vpdsi_region_heap {
    size_t words;           /* words of a record's body (all but its key and level) */
    double *key;            /* heap order: key[i] and level[i] of the record in slot[i] */
    uint8_t *level;
    uint32_t *slot;
    size_t count, cap_key, cap_level, cap_slot; /* entries; room in each array */
    uint64_t *body;         /* records by slot, `words` each; a free one's first word links the next */
    size_t slots, cap_body; /* slots made; room (in words) */
    uint64_t free_slot;     /* the first free slot, or UINT64_MAX */
} vpdsi_region_heap;

void vpdsi_region_heap_init(vpdsi_region_heap *h, size_t words);
void vpdsi_region_heap_release(vpdsi_region_heap *h, vpdsi_mem *m);
/* Room for `more` pushes; -1 on OOM or past 2^32 slots (nothing changed). */
int vpdsi_region_heap_reserve(vpdsi_region_heap *h, vpdsi_mem *m, size_t more);
/* Push a record (after a reserve): its key, level and body (`words` words). */
void vpdsi_region_heap_push(vpdsi_region_heap *h, double key, unsigned level, const uint64_t *body);
/* Remove the top: its key, level and body. */
void vpdsi_region_heap_pop(vpdsi_region_heap *h, double *key, unsigned *level, uint64_t *body);
/* The key of entry i (0: the top; 1 and 2 its children); the level and body of the top. */
static inline double vpdsi_region_heap_key(const vpdsi_region_heap *h, size_t i) { return h->key[i]; }
static inline unsigned vpdsi_region_heap_top_level(const vpdsi_region_heap *h) { return h->level[0]; }
static inline const uint64_t *vpdsi_region_heap_top(const vpdsi_region_heap *h)
{
    return h->body + (size_t)h->slot[0] * h->words;
}
#endif
