#include "region_heap.h"
#include <string.h>

void vpdsi_region_heap_init(vpdsi_region_heap *h, size_t words)
{
    memset(h, 0, sizeof *h);
    h->words = words;
    h->free_slot = UINT64_MAX;
}

void vpdsi_region_heap_release(vpdsi_region_heap *h, vpdsi_mem *m)
{
    vpdsi_mem_free(m, h->key, h->cap_key * sizeof *h->key);
    vpdsi_mem_free(m, h->level, h->cap_level * sizeof *h->level);
    vpdsi_mem_free(m, h->slot, h->cap_slot * sizeof *h->slot);
    vpdsi_mem_free(m, h->body, h->cap_body * sizeof *h->body);
    vpdsi_region_heap_init(h, h->words);
}

int vpdsi_region_heap_reserve(vpdsi_region_heap *h, vpdsi_mem *m, size_t more)
{
    size_t entries = h->count + more, words;
    if (entries < more || h->slots + more > (size_t)UINT32_MAX) return -1;
    /* without free slots every push takes a new one */
    if (vpdsi_mul_size(h->slots + more, h->words, &words)) return -1;
    if (vpdsi_mem_reserve(m, (void **)&h->key, &h->cap_key, entries, sizeof *h->key) ||
        vpdsi_mem_reserve(m, (void **)&h->level, &h->cap_level, entries, sizeof *h->level) ||
        vpdsi_mem_reserve(m, (void **)&h->slot, &h->cap_slot, entries, sizeof *h->slot) ||
        vpdsi_mem_reserve(m, (void **)&h->body, &h->cap_body, words, sizeof *h->body))
        return -1;
    return 0;
}

void vpdsi_region_heap_push(vpdsi_region_heap *h, double key, unsigned level, const uint64_t *body)
{
    size_t i = h->count++;
    uint64_t s;
    if (h->free_slot != UINT64_MAX) {
        s = h->free_slot;
        h->free_slot = h->body[s * h->words];
    } else {
        s = h->slots++;
    }
    memcpy(h->body + s * h->words, body, h->words * sizeof *body);
    /* sift up: a parent whose key is below the new one moves down (as a swap would) */
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!(h->key[p] < key)) break;
        h->key[i] = h->key[p];
        h->level[i] = h->level[p];
        h->slot[i] = h->slot[p];
        i = p;
    }
    h->key[i] = key;
    h->level[i] = (uint8_t)level;
    h->slot[i] = (uint32_t)s;
}

void vpdsi_region_heap_pop(vpdsi_region_heap *h, double *key, unsigned *level, uint64_t *body)
{
    size_t n, i = 0, s = h->slot[0];
    double k;
    uint32_t ks;
    uint8_t kl;
    *key = h->key[0];
    *level = h->level[0];
    memcpy(body, h->body + s * h->words, h->words * sizeof *body);
    h->body[s * h->words] = h->free_slot;
    h->free_slot = s;
    n = --h->count;
    if (n == 0) return;
    k = h->key[n];
    kl = h->level[n];
    ks = h->slot[n];
    /* sift down the last entry from the root: the larger child moves up while it beats the
     * entry (the left one on a tie between them), as the swaps of whole records did */
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, m = i;
        double km = k;
        if (l < n && h->key[l] > km) {
            m = l;
            km = h->key[l];
        }
        if (r < n && h->key[r] > km) m = r;
        if (m == i) break;
        h->key[i] = h->key[m];
        h->level[i] = h->level[m];
        h->slot[i] = h->slot[m];
        i = m;
    }
    h->key[i] = k;
    h->level[i] = kl;
    h->slot[i] = ks;
}
