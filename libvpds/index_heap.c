/* The indexed max-heap (index_heap.h). */
#include "index_heap.h"
#include <string.h>

void vpdsi_index_heap_init(vpdsi_index_heap *h)
{
    memset(h, 0, sizeof *h);
}

void vpdsi_index_heap_release(vpdsi_index_heap *h, vpdsi_mem *m)
{
    vpdsi_mem_free(m, h->key, h->cap_key * sizeof(double));
    vpdsi_mem_free(m, h->id, h->cap_id * sizeof(uint32_t));
    vpdsi_mem_free(m, h->pos, h->cap_pos * sizeof(uint32_t));
    vpdsi_index_heap_init(h);
}

int vpdsi_index_heap_reserve(vpdsi_index_heap *h, vpdsi_mem *m, size_t ids)
{
    if (vpdsi_mem_reserve(m, (void **)&h->key, &h->cap_key, ids, sizeof(double)) ||
        vpdsi_mem_reserve(m, (void **)&h->id, &h->cap_id, ids, sizeof(uint32_t)) ||
        vpdsi_mem_reserve(m, (void **)&h->pos, &h->cap_pos, ids, sizeof(uint32_t)))
        return -1;
    for (; h->n_ids < ids; h->n_ids++) h->pos[h->n_ids] = VPDSI_INDEX_HEAP_NONE;
    return 0;
}

static int ih_above(const vpdsi_index_heap *h, size_t i, size_t j)
{
    return h->key[i] > h->key[j] || (h->key[i] == h->key[j] && h->id[i] < h->id[j]);
}

static void ih_swap(vpdsi_index_heap *h, size_t i, size_t j)
{
    double k = h->key[i];
    uint32_t t = h->id[i];
    h->key[i] = h->key[j];
    h->id[i] = h->id[j];
    h->key[j] = k;
    h->id[j] = t;
    h->pos[h->id[i]] = (uint32_t)i;
    h->pos[h->id[j]] = (uint32_t)j;
}

static void ih_sift(vpdsi_index_heap *h, size_t i)
{
    while (i > 0 && ih_above(h, i, (i - 1) / 2)) {
        ih_swap(h, i, (i - 1) / 2);
        i = (i - 1) / 2;
    }
    for (;;) {
        size_t c = 2 * i + 1, best = i;
        if (c < h->count && ih_above(h, c, best)) best = c;
        if (c + 1 < h->count && ih_above(h, c + 1, best)) best = c + 1;
        if (best == i) return;
        ih_swap(h, i, best);
        i = best;
    }
}

void vpdsi_index_heap_set(vpdsi_index_heap *h, uint32_t id, double key)
{
    size_t i = h->pos[id];
    if (key < 0) {
        if (h->pos[id] == VPDSI_INDEX_HEAP_NONE) return;
        h->pos[id] = VPDSI_INDEX_HEAP_NONE;
        if (i == --h->count) return;
        h->key[i] = h->key[h->count];
        h->id[i] = h->id[h->count];
        h->pos[h->id[i]] = (uint32_t)i;
    } else {
        if (h->pos[id] == VPDSI_INDEX_HEAP_NONE) i = h->count++;
        h->key[i] = key;
        h->id[i] = id;
        h->pos[id] = (uint32_t)i;
    }
    ih_sift(h, i);
}
