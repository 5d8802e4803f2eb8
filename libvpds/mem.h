/* Memory through the caller's allocator, with the bytes held counted for vpds_stats. */
#ifndef VPDS_MEM_H
#define VPDS_MEM_H
#include "vpds.h"

typedef struct vpdsi_mem {
    vpds_allocator a;
    size_t held;
    size_t peak;
    size_t limit;   /* most bytes held at once (0: none): past it an allocation fails */
    int limit_hit;  /* the last failed allocation failed for the limit, not the allocator */
} vpdsi_mem;

/* Fill a from the user's allocator (both NULL: malloc/free). */
void vpdsi_mem_init(vpdsi_mem *m, const vpds_allocator *a);
void *vpdsi_mem_alloc(vpdsi_mem *m, size_t size);
void vpdsi_mem_free(vpdsi_mem *m, void *p, size_t size);
/* Make *cap >= need elements of size elem, growing by half again (a quarter past 1 MiB).
 * Returns 0, or -1 when the size overflows or the allocator fails (then *p and *cap are
 * unchanged). */
int vpdsi_mem_reserve(vpdsi_mem *m, void **p, size_t *cap, size_t need, size_t elem);
/* The same growing by 1/8 past 1 MiB (a quarter for vpdsi_mem_reserve): for the arrays whose
 * room left unused adds up at the peak (the active cells of two levels). */
int vpdsi_mem_reserve_fine(vpdsi_mem *m, void **p, size_t *cap, size_t need, size_t elem);
/* Give back the room past `keep` elements (at least one), through the allocator's realloc;
 * without one, or when it fails, nothing changes. */
void vpdsi_mem_shrink(vpdsi_mem *m, void **p, size_t *cap, size_t keep, size_t elem);
/* a*b without overflow: returns 0 and writes *out, or -1. */
int vpdsi_mul_size(size_t a, size_t b, size_t *out);
/* A hint that p will be read soon (GCC, Clang); nothing elsewhere. */
#if defined(__GNUC__) || defined(__clang__)
#define VPDSI_PREFETCH(p) __builtin_prefetch(p)
#else
#define VPDSI_PREFETCH(p) ((void)(p))
#endif
#endif
