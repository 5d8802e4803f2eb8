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

void vpdsi_lattice_mid(const vpdsi_lattice *g, unsigned level, const uint64_t *c, double *mid)
{
    uint64_t bits = (uint64_t)(1023 - (level + 1)) << 52; /* as vpdsi_lattice_box, a level down */
    double shrink;
    int k;
    memcpy(&shrink, &bits, sizeof shrink);
    for (k = 0; k < g->dim; k++) mid[k] = g->lo[k] + (double)(2 * c[k] + 1) * (g->side0[k] * shrink);
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
    c->families = 0;
    c->n_fam = 0;
    c->seq_set = 0;
    c->reversed = 0;
}

int vpdsi_cells_families_serve(int dim, int two_radii)
{
    return !two_radii && dim >= 3 && dim <= 8;
}

void vpdsi_cells_layout_families(vpdsi_cells *c, int dim, const uint64_t *n0, unsigned level)
{
    vpdsi_cells_layout(c, dim, n0, level - 1); /* the records are the parents' coordinates */
    c->level = level;
    c->families = 1;
    c->mask_bytes = dim > 3 ? 1u << (dim - 3) : 1u;
    c->fam_bytes = vpdsi_cells_family_bytes(dim, c->words_per_cell == 0 ? 32u : 64u * c->words_per_cell);
}

unsigned vpdsi_cells_family_bytes(int dim, unsigned parent_bits)
{
    return (dim > 3 ? 1u << (dim - 3) : 1u) + (parent_bits <= 32 ? 4u : 8u * ((parent_bits + 63) / 64));
}

/* 64-bit words that n records take (0 when the size overflows). */
static size_t record_words(const vpdsi_cells *c, size_t n)
{
    size_t words;
    if (c->words_per_cell == 0) return n / 2 + n % 2;
    return vpdsi_mul_size(n, c->words_per_cell, &words) ? 0 : words;
}

int vpdsi_cells_reserve(vpdsi_cells *c, vpdsi_mem *m, size_t cells)
{
    size_t words = record_words(c, cells);
    if (words == 0 && cells > 0) return -1;
    /* two levels' cells are held at once at the peak of a run: small steps leave less unused */
    return vpdsi_mem_reserve_fine(m, (void **)&c->words, &c->cap_words, words, sizeof *c->words);
}

int vpdsi_cells_reserve_families(vpdsi_cells *c, vpdsi_mem *m, size_t more, int dim)
{
    size_t fams = c->n_fam + more, cells, bytes;
    if (fams < more || vpdsi_mul_size(more, (size_t)1 << dim, &cells) || c->count + cells < cells ||
        vpdsi_mul_size(fams, c->fam_bytes, &bytes))
        return -1;
    cells = ((c->count + cells) >> VPDSI_CELLS_BUCKET_SHIFT) + 1; /* the buckets */
    return vpdsi_mem_reserve_fine(m, (void **)&c->fam, &c->cap_fam, bytes, 1) ||
           vpdsi_mem_reserve(m, (void **)&c->bucket_fam, &c->cap_bucket_fam, cells, sizeof *c->bucket_fam) ||
           vpdsi_mem_reserve(m, (void **)&c->bucket_off, &c->cap_bucket_off, cells, sizeof *c->bucket_off);
}

void vpdsi_cells_shrink(vpdsi_cells *c, vpdsi_mem *m)
{
    if (!c->families) {
        vpdsi_mem_shrink(m, (void **)&c->words, &c->cap_words, record_words(c, c->count), sizeof *c->words);
        return;
    }
    vpdsi_mem_shrink(m, (void **)&c->fam, &c->cap_fam, c->n_fam * c->fam_bytes, 1);
    vpdsi_mem_shrink(m, (void **)&c->bucket_fam, &c->cap_bucket_fam, (c->count >> VPDSI_CELLS_BUCKET_SHIFT) + 1,
                     sizeof *c->bucket_fam);
    vpdsi_mem_shrink(m, (void **)&c->bucket_off, &c->cap_bucket_off, (c->count >> VPDSI_CELLS_BUCKET_SHIFT) + 1,
                     sizeof *c->bucket_off);
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

void vpdsi_cells_truncate(vpdsi_cells *c, size_t count, size_t n_fam)
{
    c->count = count;
    c->n_fam = n_fam;
    c->seq_set = 0;
    c->reversed = 0;
}

/* Where flat cell i, or with families record i, lies. */
static size_t place(const vpdsi_cells *c, size_t i) { return c->reversed ? c->rev_top - i : i; }

/* Family f's record: its mask, then its parent's coordinates. */
static const uint8_t *record(const vpdsi_cells *c, size_t f) { return c->fam + place(c, f) * c->fam_bytes; }

static void swap_bytes(uint8_t *a, uint8_t *b, size_t n)
{
    size_t k;
    if (n == 4) { /* a 32-bit cell, the common case: one load and store each way */
        uint32_t t;
        memcpy(&t, a, 4);
        memcpy(a, b, 4);
        memcpy(b, &t, 4);
        return;
    }
    for (k = 0; k < n; k++) {
        uint8_t t = a[k];
        a[k] = b[k];
        b[k] = t;
    }
}

void vpdsi_cells_reverse(vpdsi_cells *c)
{
    /* the records swapped whole: a family's, a 32-bit cell's, or a cell's 64-bit words */
    uint8_t *base = c->families ? c->fam : (uint8_t *)c->words;
    size_t a, b, n = c->families ? c->n_fam : c->count;
    size_t size = c->families ? c->fam_bytes : c->words_per_cell ? 8u * c->words_per_cell : 4u;
    if (c->reversed || n == 0) return;
    for (a = 0, b = n - 1; a < b; a++, b--) swap_bytes(base + a * size, base + b * size, size);
    c->reversed = 1;
    c->rev_top = n - 1;
}

void vpdsi_cells_give_back_read(vpdsi_cells *c, vpdsi_mem *m, size_t read)
{
    size_t keep;
    if (!c->reversed || read > c->count) return;
    if (c->families) {
        /* the families from the one holding the first cell of the bucket of cell read - 1 (a
         * cell past it is found from there, and get_seq's next step reads the family of the
         * cell it read last): places 0 .. n_fam - 1 - that family */
        if (read == 0) return;
        keep = (c->n_fam - c->bucket_fam[(read - 1) >> VPDSI_CELLS_BUCKET_SHIFT]) * c->fam_bytes;
        if (keep <= c->cap_fam - (c->cap_fam >> 3)) vpdsi_mem_shrink(m, (void **)&c->fam, &c->cap_fam, keep, 1);
        return;
    }
    keep = record_words(c, c->count - read); /* places 0 .. count - read - 1 */
    if (keep <= c->cap_words - (c->cap_words >> 3))
        vpdsi_mem_shrink(m, (void **)&c->words, &c->cap_words, keep, sizeof *c->words);
}

void vpdsi_cells_empty(vpdsi_cells *c, vpdsi_mem *m)
{
    vpdsi_cells_truncate(c, 0, 0);
    vpdsi_cells_shrink(c, m);
}

void vpdsi_cells_release(vpdsi_cells *c, vpdsi_mem *m)
{
    vpdsi_mem_free(m, c->words, c->cap_words * sizeof *c->words);
    vpdsi_mem_free(m, c->fam, c->cap_fam);
    vpdsi_mem_free(m, c->bucket_fam, c->cap_bucket_fam * sizeof *c->bucket_fam);
    vpdsi_mem_free(m, c->bucket_off, c->cap_bucket_off * sizeof *c->bucket_off);
    c->words = NULL;
    c->fam = NULL;
    c->bucket_fam = NULL;
    c->bucket_off = NULL;
    c->cap_words = c->cap_fam = c->cap_bucket_fam = c->cap_bucket_off = 0;
    c->count = c->n_fam = 0;
    c->seq_set = 0;
    c->reversed = 0;
}

static void unpack_at(const vpdsi_cells *c, size_t i, int dim, uint64_t *coord);

/* coord packed into w (words_per_cell words; one word holding 32 bits when it is 0). */
static void encode(const vpdsi_cells *c, int dim, const uint64_t *coord, uint64_t *w)
{
    unsigned k, words = c->words_per_cell ? c->words_per_cell : 1;
    memset(w, 0, words * sizeof *w);
    for (k = 0; k < (unsigned)dim; k++) {
        unsigned off = c->offset[k], wi = off >> 6, sh = off & 63u;
        w[wi] |= coord[k] << sh;
        if (sh && sh + c->bits[k] > 64) w[wi + 1] |= coord[k] >> (64 - sh);
    }
}

void vpdsi_cells_push(vpdsi_cells *c, int dim, const uint64_t *coord)
{
    uint64_t w[VPDSI_CELLS_MAX_WORDS];
    encode(c, dim, coord, w);
    if (c->words_per_cell == 0)
        half_set(c, c->count, (uint32_t)w[0]);
    else
        memcpy(c->words + c->count * c->words_per_cell, w, c->words_per_cell * sizeof *w);
    c->count++;
}

static unsigned popcount64(uint64_t x)
{
    x = x - ((x >> 1) & UINT64_C(0x5555555555555555));
    x = (x & UINT64_C(0x3333333333333333)) + ((x >> 2) & UINT64_C(0x3333333333333333));
    x = (x + (x >> 4)) & UINT64_C(0x0f0f0f0f0f0f0f0f);
    return (unsigned)((x * UINT64_C(0x0101010101010101)) >> 56);
}

/* Word w (64 children) of family f's mask: 1, 2, 4 or 8k bytes, read as they were written
 * (native byte order: the masks never leave the process). */
static uint64_t mask_word(const vpdsi_cells *c, size_t f, unsigned w)
{
    const uint8_t *p = record(c, f);
    uint16_t v2;
    uint32_t v4;
    uint64_t v8;
    switch (c->mask_bytes) {
    case 1: return p[0];
    case 2: memcpy(&v2, p, 2); return v2;
    case 4: memcpy(&v4, p, 4); return v4;
    default: memcpy(&v8, p + (size_t)w * 8, 8); return v8;
    }
}

static unsigned mask_words(const vpdsi_cells *c) { return (c->mask_bytes + 7) / 8; }

/* Set bits of each byte: a family of up to 8 children is sized by one load. */
static const uint8_t byte_bits[256] = {
#define B2(n) n, n + 1, n + 1, n + 2
#define B4(n) B2(n), B2(n + 1), B2(n + 1), B2(n + 2)
#define B6(n) B4(n), B4(n + 1), B4(n + 1), B4(n + 2)
    B6(0), B6(1), B6(1), B6(2)
#undef B2
#undef B4
#undef B6
};

static unsigned family_size(const vpdsi_cells *c, size_t f)
{
    const uint8_t *p = record(c, f);
    unsigned w, n = 0;
    if (c->mask_bytes <= 8) { /* up to 6D a byte's count at a time: a dart's cell walks families */
        for (w = 0; w < c->mask_bytes; w++) n += byte_bits[p[w]];
        return n;
    }
    for (w = 0; w < mask_words(c); w++) n += popcount64(mask_word(c, f, w));
    return n;
}

void vpdsi_cells_push_family(vpdsi_cells *c, int dim, const uint64_t *parent, const uint64_t *children)
{
    size_t first = c->count, j, n = 0;
    unsigned k, words = dim > 6 ? 1u << (dim - 6) : 1u;
    uint64_t w[VPDSI_CELLS_MAX_WORDS];
    uint8_t *to;
    for (k = 0; k < words; k++) n += popcount64(children[k]);
    if (n == 0) return;
    for (j = (first + VPDSI_CELLS_BUCKET - 1) >> VPDSI_CELLS_BUCKET_SHIFT;
         (j << VPDSI_CELLS_BUCKET_SHIFT) < first + n; j++) { /* the buckets that start here */
        c->bucket_fam[j] = c->n_fam;
        c->bucket_off[j] = (uint8_t)((j << VPDSI_CELLS_BUCKET_SHIFT) - first); /* < 256 children */
    }
    to = c->fam + c->n_fam * c->fam_bytes;
    encode(c, dim, parent, w);
    if (c->words_per_cell == 0) {
        uint32_t v = (uint32_t)w[0];
        memcpy(to + c->mask_bytes, &v, 4);
    } else {
        memcpy(to + c->mask_bytes, w, 8u * c->words_per_cell);
    }
    if (c->mask_bytes == 1) {
        to[0] = (uint8_t)children[0];
    } else if (c->mask_bytes == 2) {
        uint16_t v = (uint16_t)children[0];
        memcpy(to, &v, 2);
    } else if (c->mask_bytes == 4) {
        uint32_t v = (uint32_t)children[0];
        memcpy(to, &v, 4);
    } else {
        memcpy(to, children, c->mask_bytes); /* whole 64-bit words */
    }
    c->n_fam++;
    c->count += n;
}

void vpdsi_cells_move(vpdsi_cells *c, size_t from, size_t to)
{
    if (c->families) return; /* not laid out for it: the callers compact flat arrays only */
    if (from != to && c->words_per_cell == 0)
        half_set(c, to, half_get(c, from));
    else if (from != to)
        memcpy(c->words + to * c->words_per_cell, c->words + from * c->words_per_cell,
               c->words_per_cell * sizeof *c->words);
}

void vpdsi_cells_prefetch_bucket(const vpdsi_cells *c, size_t i)
{
    if (!c->families) return;
    VPDSI_PREFETCH(c->bucket_fam + (i >> VPDSI_CELLS_BUCKET_SHIFT));
    VPDSI_PREFETCH(c->bucket_off + (i >> VPDSI_CELLS_BUCKET_SHIFT));
}

void vpdsi_cells_prefetch(const vpdsi_cells *c, size_t i)
{
    if (c->families) { /* the bucket is read (a small array), its family asked for */
        size_t f = c->bucket_fam[i >> VPDSI_CELLS_BUCKET_SHIFT];
        VPDSI_PREFETCH(record(c, f));
        return;
    }
    if (c->words_per_cell == 0)
        VPDSI_PREFETCH((const unsigned char *)c->words + place(c, i) * sizeof(uint32_t));
    else
        VPDSI_PREFETCH(c->words + place(c, i) * c->words_per_cell);
}

/* The first cell of the family holding the first cell of cell i's bucket. */
static size_t bucket_first(const vpdsi_cells *c, size_t i)
{
    size_t j = i >> VPDSI_CELLS_BUCKET_SHIFT;
    return (j << VPDSI_CELLS_BUCKET_SHIFT) - c->bucket_off[j];
}

/* Cell i of families, from family f whose first cell is first (<= i): its family the one whose
 * cells reach past i, its child b the (i - first)-th set bit of the family's mask. */
static size_t family_get(const vpdsi_cells *c, size_t i, size_t *f_io, size_t first, int dim, uint64_t *coord,
                         unsigned *b_out)
{
    size_t f = *f_io;
    unsigned n, w, b = 0;
    uint64_t word;
    int k;
    while (i >= first + (n = family_size(c, f))) {
        first += n;
        f++;
    }
    *f_io = f;
    n = (unsigned)(i - first); /* set bits to pass */
    for (w = 0;; w++) {
        word = mask_word(c, f, w);
        if (n < popcount64(word)) break;
        n -= popcount64(word);
    }
    for (; n > 0; n--) word &= word - 1; /* clear the lowest n set bits */
    while (!((word >> b) & 1u)) b++;
    b += 64 * w;
    *b_out = b;
    unpack_at(c, f, dim, coord);
    for (k = 0; k < dim; k++) coord[k] = 2 * coord[k] + ((b >> k) & 1u);
    return first;
}

void vpdsi_cells_get(const vpdsi_cells *c, size_t i, int dim, uint64_t *coord)
{
    size_t f;
    unsigned b;
    if (!c->families) {
        unpack_at(c, i, dim, coord);
        return;
    }
    f = c->bucket_fam[i >> VPDSI_CELLS_BUCKET_SHIFT];
    (void)family_get(c, i, &f, bucket_first(c, i), dim, coord, &b);
}

/* Index of the lowest set bit of x (non-zero): de Bruijn, portable. */
static unsigned lowest_bit(uint64_t x)
{
    static const uint8_t at[64] = {0,  1,  48, 2,  57, 49, 28, 3,  61, 58, 50, 42, 38, 29, 17, 4,
                                   62, 55, 59, 36, 53, 51, 43, 22, 45, 39, 33, 30, 24, 18, 12, 5,
                                   63, 47, 56, 27, 60, 41, 37, 16, 54, 35, 52, 21, 44, 32, 23, 11,
                                   46, 26, 40, 15, 34, 20, 31, 10, 25, 14, 19, 9,  13, 8,  7,  6};
    return at[((x & (~x + 1)) * UINT64_C(0x03f79d71b4cb0a89)) >> 58];
}

/* The first child of family f at or after child `from`, or -1. */
static int next_child(const vpdsi_cells *c, size_t f, unsigned from)
{
    unsigned w;
    for (w = from / 64; w < mask_words(c); w++) {
        uint64_t word = mask_word(c, f, w);
        if (w == from / 64) word &= ~((UINT64_C(1) << (from % 64)) - 1);
        if (word) return (int)(w * 64 + lowest_bit(word));
    }
    return -1;
}

/* Cell i of families when cell i - 1 was the last one read: the next child of its family, or
 * the first of the next family (a family holds at least one child). */
static void seq_step(vpdsi_cells *c, int dim)
{
    int b = next_child(c, c->seq_f, c->seq_b + 1);
    if (b < 0) {
        c->seq_first += family_size(c, c->seq_f);
        c->seq_f++;
        b = next_child(c, c->seq_f, 0);
        unpack_at(c, c->seq_f, dim, c->seq_parent);
    }
    c->seq_b = (unsigned)b;
}

void vpdsi_cells_get_seq(vpdsi_cells *c, size_t i, int dim, uint64_t *coord)
{
    int k;
    if (!c->families) {
        unpack_at(c, i, dim, coord);
        return;
    }
    if (c->seq_set && i == c->seq_i + 1) {
        seq_step(c, dim);
    } else { /* from the bucket of cell i */
        size_t f = c->bucket_fam[i >> VPDSI_CELLS_BUCKET_SHIFT];
        c->seq_first = family_get(c, i, &f, bucket_first(c, i), dim, coord, &c->seq_b);
        c->seq_f = f;
        unpack_at(c, f, dim, c->seq_parent);
        c->seq_set = 1;
    }
    c->seq_i = i;
    for (k = 0; k < dim; k++) coord[k] = 2 * c->seq_parent[k] + ((c->seq_b >> k) & 1u);
}

/* coord from w (as encode wrote it). */
static void decode(const vpdsi_cells *c, const uint64_t *w, int dim, uint64_t *coord)
{
    unsigned k;
    if (c->words_per_cell <= 1) { /* the common case: every coordinate in one word */
        for (k = 0; k < (unsigned)dim; k++)
            coord[k] = (w[0] >> c->offset[k]) & ((UINT64_C(1) << c->bits[k]) - 1);
        return;
    }
    for (k = 0; k < (unsigned)dim; k++) {
        unsigned off = c->offset[k], wi = off >> 6, sh = off & 63u, b = c->bits[k];
        uint64_t v = w[wi] >> sh;
        if (sh && sh + b > 64) v |= w[wi + 1] << (64 - sh);
        coord[k] = b >= 64 ? v : (v & ((1ull << b) - 1));
    }
}

/* Record i's coordinates: cell i's, or with families parent i's (after its mask). */
static void unpack_at(const vpdsi_cells *c, size_t i, int dim, uint64_t *coord)
{
    uint64_t w[VPDSI_CELLS_MAX_WORDS];
    if (c->families) {
        const uint8_t *p = record(c, i) + c->mask_bytes;
        if (c->words_per_cell == 0) {
            uint32_t v;
            memcpy(&v, p, 4);
            w[0] = v;
        } else {
            memcpy(w, p, 8u * c->words_per_cell);
        }
        decode(c, w, dim, coord);
    } else if (c->words_per_cell == 0) {
        w[0] = half_get(c, place(c, i));
        decode(c, w, dim, coord);
    } else {
        decode(c, c->words + place(c, i) * c->words_per_cell, dim, coord);
    }
}
