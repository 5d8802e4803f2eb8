/* The allocator interface: every byte the library holds goes through here. */
#include "mem.h"
#include <stdlib.h>
#include <string.h>

static void *default_alloc(size_t size, void *user) { (void)user; return malloc(size); }
static void *default_realloc(void *p, size_t old_size, size_t new_size, void *user)
{
    (void)old_size; (void)user;
    return realloc(p, new_size);
}
static void default_free(void *p, size_t size, void *user) { (void)size; (void)user; free(p); }

void vpdsi_mem_init(vpdsi_mem *m, const vpds_allocator *a)
{
    memset(m, 0, sizeof *m);
    if (a && a->alloc) {
        m->a = *a;
    } else {
        m->a.alloc = default_alloc;
        m->a.realloc = default_realloc;
        m->a.free = default_free;
        m->a.user = NULL;
    }
}

/* Whether `more` bytes fit under the limit (set by vpds_set_memory_limit). */
static int within_limit(vpdsi_mem *m, size_t more)
{
    if (m->limit == 0 || (m->held <= m->limit && more <= m->limit - m->held)) return 1;
    m->limit_hit = 1;
    return 0;
}

void *vpdsi_mem_alloc(vpdsi_mem *m, size_t size)
{
    void *p;
    if (size == 0) size = 1;
    if (!within_limit(m, size)) return NULL;
    p = m->a.alloc(size, m->a.user);
    if (!p) m->limit_hit = 0; /* the last failure is the allocator's own */
    if (p) {
        m->held += size;
        if (m->held > m->peak) m->peak = m->held;
    }
    return p;
}

void vpdsi_mem_free(vpdsi_mem *m, void *p, size_t size)
{
    if (!p) return;
    if (size == 0) size = 1;
    m->a.free(p, size, m->a.user);
    m->held -= size;
}

int vpdsi_mul_size(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > (size_t)-1 / a) return -1;
    *out = a * b;
    return 0;
}

/* Make *cap >= need: half again, or past 1 MiB by *cap >> large_shift. realloc moves large
 * blocks by remapping their pages, so the smaller steps cost little time and leave less room
 * unused at the peak. */
static int reserve_by(vpdsi_mem *m, void **p, size_t *cap, size_t need, size_t elem,
                      unsigned large_shift)
{
    size_t new_cap, old_bytes, new_bytes;
    void *q;
    if (need <= *cap) return 0;
    new_cap = *cap + (*cap * elem > ((size_t)1 << 20) ? *cap >> large_shift : *cap / 2) + 16;
    if (new_cap < *cap || new_cap < need) new_cap = need;
    if (vpdsi_mul_size(new_cap, elem, &new_bytes) != 0) {
        new_cap = need;
        if (vpdsi_mul_size(new_cap, elem, &new_bytes) != 0) return -1;
    }
    old_bytes = *cap * elem;
    if (*p && m->a.realloc) {
        if (!within_limit(m, new_bytes - old_bytes)) return -1;
        q = m->a.realloc(*p, old_bytes, new_bytes, m->a.user);
        if (!q) {
            m->limit_hit = 0;
            return -1;
        }
        m->held += new_bytes - old_bytes;
        if (m->held > m->peak) m->peak = m->held;
    } else {
        q = vpdsi_mem_alloc(m, new_bytes);
        if (!q) return -1;
        if (*p) {
            memcpy(q, *p, old_bytes);
            vpdsi_mem_free(m, *p, old_bytes);
        }
    }
    *p = q;
    *cap = new_cap;
    return 0;
}

int vpdsi_mem_reserve(vpdsi_mem *m, void **p, size_t *cap, size_t need, size_t elem)
{
    return reserve_by(m, p, cap, need, elem, 2);
}

int vpdsi_mem_reserve_fine(vpdsi_mem *m, void **p, size_t *cap, size_t need, size_t elem)
{
    return reserve_by(m, p, cap, need, elem, 3);
}

void vpdsi_mem_shrink(vpdsi_mem *m, void **p, size_t *cap, size_t keep, size_t elem)
{
    size_t old_bytes = *cap * elem, new_bytes;
    void *q;
    if (keep == 0) keep = 1; /* a block of no bytes is the allocator's corner case */
    /* without realloc a shrink would copy into a second block, the two held at once: the
     * peak it is meant to lower would rise */
    if (!*p || keep >= *cap || !m->a.realloc) return;
    new_bytes = keep * elem; /* below *cap * elem: no overflow */
    q = m->a.realloc(*p, old_bytes, new_bytes, m->a.user);
    if (!q) return; /* the block stays as it was: nothing is lost */
    *p = q;
    *cap = keep;
    m->held -= old_bytes - new_bytes;
}
