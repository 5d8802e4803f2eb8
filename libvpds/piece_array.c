/* Pieces in 16- or 24-byte records (piece_array.h). A narrow record: i, j, tri as 32-bit
 * words, then level and down; read and written through memcpy, so no alignment is assumed. */
#include "piece_array.h"
#include <string.h>

#define NARROW_BYTES 16

static size_t record_bytes(int wide) { return wide ? sizeof(vpdsi_piece) : NARROW_BYTES; }

void vpdsi_piece_array_release(vpdsi_piece_array *a, vpdsi_mem *m)
{
    vpdsi_mem_free(m, a->data, a->cap);
    memset(a, 0, sizeof *a);
}

void vpdsi_piece_array_clear(vpdsi_piece_array *a)
{
    a->n = 0;
    a->max_level = 0;
    a->wide = 0; /* the next reserve chooses again */
}

static void put_narrow(unsigned char *at, const vpdsi_piece *p)
{
    uint32_t w[3];
    w[0] = (uint32_t)p->i;
    w[1] = (uint32_t)p->j;
    w[2] = p->tri;
    memcpy(at, w, sizeof w);
    at[12] = p->level;
    at[13] = p->down;
    at[14] = at[15] = 0;
}

static vpdsi_piece get_narrow(const unsigned char *at)
{
    vpdsi_piece p;
    uint32_t w[3];
    memset(&p, 0, sizeof p);
    memcpy(w, at, sizeof w);
    p.i = w[0];
    p.j = w[1];
    p.tri = w[2];
    p.level = at[12];
    p.down = at[13];
    return p;
}

int vpdsi_piece_array_reserve(vpdsi_piece_array *a, vpdsi_mem *m, size_t need, unsigned bits)
{
    int wide = a->wide || bits > 32;
    size_t k, bytes = need * record_bytes(wide);
    if (need > 0 && bytes / need != record_bytes(wide)) return -1;
    if (wide && !a->wide && a->n > 0 && a->n * record_bytes(1) > bytes) bytes = a->n * record_bytes(1);
    if (vpdsi_mem_reserve(m, (void **)&a->data, &a->cap, bytes, 1)) return -1;
    if (wide && !a->wide) { /* widen in place from the last record: each lands at or past its own */
        for (k = a->n; k-- > 0;) {
            vpdsi_piece p = get_narrow(a->data + k * NARROW_BYTES);
            memcpy(a->data + k * sizeof p, &p, sizeof p);
        }
        a->wide = 1;
    }
    return 0;
}

vpdsi_piece vpdsi_piece_array_get(const vpdsi_piece_array *a, size_t k)
{
    vpdsi_piece p;
    if (!a->wide) return get_narrow(a->data + k * NARROW_BYTES);
    memcpy(&p, a->data + k * sizeof p, sizeof p);
    return p;
}

void vpdsi_piece_array_push(vpdsi_piece_array *a, const vpdsi_piece *p)
{
    if (a->wide) memcpy(a->data + a->n * sizeof *p, p, sizeof *p);
    else put_narrow(a->data + a->n * NARROW_BYTES, p);
    a->n++;
    if (p->level > a->max_level) a->max_level = p->level;
}
