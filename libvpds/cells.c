#include "cells.h"
#include <math.h>
#include <string.h>

double vpdsi_lattice_box(const vpdsi_lattice *g, unsigned level, const uint64_t *c, double *lo,
                         double *hi)
{
    /* 2^-level, exact (levels stay far below 1022), made from its exponent bits rather than
     * a call of ldexp per box: the product is the correctly rounded side0 * 2^-level */
    uint64_t bits = (uint64_t)(1023 - level) << 52;
    double diag2 = 0, shrink;
    int k;
    memcpy(&shrink, &bits, sizeof shrink);
    for (k = 0; k < g->dim; k++) {
        double side = g->side0[k] * shrink;
        uint64_t last = (g->n0[k] << level) - 1;
        lo[k] = g->lo[k] + (double)c[k] * side;
        hi[k] = c[k] == last ? g->hi[k] : g->lo[k] + (double)(c[k] + 1) * side;
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    return diag2;
}

double vpdsi_lattice_base_side(double reach, int dim) { return reach / sqrt((double)dim) * (1 - 1e-9); }

double vpdsi_lattice_base_count(int dim, const double *lo, const double *hi, double side)
{
    double total = 1;
    int k;
    for (k = 0; k < dim; k++) {
        double cells = ceil((hi[k] - lo[k]) / side);
        total *= cells < 1 ? 1 : cells;
    }
    return total;
}

unsigned vpdsi_bit_length(uint64_t n)
{
    unsigned b = 0;
    if (n > 0) n -= 1;
    while (n) {
        b++;
        n >>= 1;
    }
    return b ? b : 1;
}

void vpdsi_cells_layout(vpdsi_cells *c, int dim, const uint64_t *n0, unsigned level)
{
    unsigned k, off = 0;
    for (k = 0; k < (unsigned)dim; k++) {
        c->bits[k] = vpdsi_bit_length(n0[k]) + level;
        c->offset[k] = off;
        off += c->bits[k];
    }
    c->words_per_cell = off <= 32 ? 0 : (off + 63) / 64;
    c->level = level;
    c->count = 0;
}

int vpdsi_cells_reserve(vpdsi_cells *c, vpdsi_mem *m, size_t cells)
{
    size_t words;
    if (c->words_per_cell == 0)
        words = cells / 2 + cells % 2;
    else if (vpdsi_mul_size(cells, c->words_per_cell, &words))
        return -1;
    /* two levels' cells are held at once at the peak of a run: small steps leave less unused */
    return vpdsi_mem_reserve_fine(m, (void **)&c->words, &c->cap_words, words, sizeof *c->words);
}

void vpdsi_cells_shrink(vpdsi_cells *c, vpdsi_mem *m)
{
    size_t words = c->words_per_cell == 0 ? c->count / 2 + c->count % 2 : c->count * c->words_per_cell;
    vpdsi_mem_shrink(m, (void **)&c->words, &c->cap_words, words, sizeof *c->words);
}

/* The 32-bit cell i of a layout with words_per_cell 0. */
static uint32_t half_get(const vpdsi_cells *c, size_t i)
{
    uint32_t v;
    memcpy(&v, (const unsigned char *)c->words + i * sizeof v, sizeof v);
    return v;
}

static void half_set(vpdsi_cells *c, size_t i, uint32_t v)
{
    memcpy((unsigned char *)c->words + i * sizeof v, &v, sizeof v);
}

void vpdsi_cells_release(vpdsi_cells *c, vpdsi_mem *m)
{
    vpdsi_mem_free(m, c->words, c->cap_words * sizeof *c->words);
    c->words = NULL;
    c->cap_words = 0;
    c->count = 0;
}

void vpdsi_cells_push(vpdsi_cells *c, int dim, const uint64_t *coord)
{
    uint64_t *w = c->words + c->count * c->words_per_cell;
    unsigned k;
    if (c->words_per_cell == 0) {
        uint32_t v = 0;
        for (k = 0; k < (unsigned)dim; k++) v |= (uint32_t)(coord[k] << c->offset[k]);
        half_set(c, c->count++, v);
        return;
    }
    memset(w, 0, c->words_per_cell * sizeof *w);
    for (k = 0; k < (unsigned)dim; k++) {
        unsigned off = c->offset[k], wi = off >> 6, sh = off & 63u;
        w[wi] |= coord[k] << sh;
        if (sh && sh + c->bits[k] > 64) w[wi + 1] |= coord[k] >> (64 - sh);
    }
    c->count++;
}

void vpdsi_cells_move(vpdsi_cells *c, size_t from, size_t to)
{
    if (from != to && c->words_per_cell == 0)
        half_set(c, to, half_get(c, from));
    else if (from != to)
        memcpy(c->words + to * c->words_per_cell, c->words + from * c->words_per_cell,
               c->words_per_cell * sizeof *c->words);
}

void vpdsi_cells_prefetch(const vpdsi_cells *c, size_t i)
{
    if (c->words_per_cell == 0)
        VPDSI_PREFETCH((const unsigned char *)c->words + i * sizeof(uint32_t));
    else
        VPDSI_PREFETCH(c->words + i * c->words_per_cell);
}

void vpdsi_cells_get(const vpdsi_cells *c, size_t i, int dim, uint64_t *coord)
{
    const uint64_t *w = c->words + i * c->words_per_cell;
    unsigned k;
    if (c->words_per_cell <= 1) { /* the common case: every coordinate in one word */
        uint64_t v = c->words_per_cell ? w[0] : half_get(c, i);
        for (k = 0; k < (unsigned)dim; k++)
            coord[k] = (v >> c->offset[k]) & ((UINT64_C(1) << c->bits[k]) - 1);
        return;
    }
    for (k = 0; k < (unsigned)dim; k++) {
        unsigned off = c->offset[k], wi = off >> 6, sh = off & 63u, b = c->bits[k];
        uint64_t v = w[wi] >> sh;
        if (sh && sh + b > 64) v |= w[wi + 1] << (64 - sh);
        coord[k] = b >= 64 ? v : (v & ((1ull << b) - 1));
    }
}
