/* The active-cell array (cells.c) against a plain copy: in every dimension, for lattices whose
 * cells fit one 32-bit word and for those that take one or more 64-bit words, the coordinates
 * pushed are the coordinates read back, in order, after compaction by moves too; and a layout
 * of at most 32 bits holds 4 bytes a cell. The same for a surface's active pieces
 * (piece_array.c): 16-byte records up to 32 bits, widened with their pieces past it, and a
 * widening that fails leaves them as they were. */
#include "check.h"
#include "vpds.h"
#include "cells.h"
#include "piece_array.h"
#include <stdlib.h>
#include <string.h>

static unsigned long long rng_state = 777;
static uint64_t next_u64(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return rng_state ^ (rng_state >> 29);
}

/* The n cells of c (copy) stored back to front (flat cells, or family records): each index
 * reads the same cell, at random and in order, while a sweep's reading in order gives back the
 * room of the cells it has read, and the cells not read yet still read right from their
 * buckets (a paused or retried sweep's reads): in the end no more than an eighth of the room
 * and a word are held, the allocator's count follows each step, and a cut makes it a plain
 * array again. */
static size_t reversed_room(const vpdsi_cells *c)
{
    return c->families ? c->cap_fam : c->cap_words * sizeof *c->words;
}

static void check_reversed(vpdsi_cells *c, vpdsi_mem *mem, int d, const uint64_t *copy, size_t n)
{
    uint64_t got[VPDS_MAX_DIM];
    size_t i, start = reversed_room(c), other = mem->held - start, gave = 0;
    int same = 1;
    vpdsi_cells_reverse(c);
    CHECK(c->reversed == (n > 0) && c->count == n);
    for (i = 0; i < n; i++) {
        size_t j = (size_t)(next_u64() % n);
        vpdsi_cells_prefetch(c, j);
        vpdsi_cells_get(c, j, d, got);
        same &= memcmp(got, copy + j * d, (size_t)d * sizeof *got) == 0;
    }
    for (i = 0; i < n; i++) {
        size_t before = reversed_room(c);
        vpdsi_cells_get_seq(c, i, d, got);
        same &= memcmp(got, copy + i * d, (size_t)d * sizeof *got) == 0;
        vpdsi_cells_give_back_read(c, mem, i + 1);
        gave += reversed_room(c) < before;
        CHECK(mem->held == other + reversed_room(c));
        if (i + 1 < n) { /* a cell not read yet, found from its bucket: a paused or retried sweep's */
            size_t j = i + 1 + (size_t)(next_u64() % (n - i - 1));
            vpdsi_cells_get(c, j, d, got);
            same &= memcmp(got, copy + j * d, (size_t)d * sizeof *got) == 0;
            vpdsi_cells_get(c, i + 1, d, got);
            same &= memcmp(got, copy + (i + 1) * d, (size_t)d * sizeof *got) == 0;
        }
    }
    CHECK_MSG(same, "dim %d: a cell read back from a reversed array differs (families %d)", d, c->families);
    CHECK_MSG(reversed_room(c) <= start / 8 + 8 && (n < 64 || gave >= 8),
              "dim %d: %zu of %zu bytes still held after reading %zu cells (%zu give-backs, families %d)", d,
              reversed_room(c), start, n, gave, c->families);
    vpdsi_cells_truncate(c, 0, 0);
    CHECK(!c->reversed);
}

/* Lattice n0 (per axis) at `level`: push n random cells, read them back, keep every third by
 * moves, read again, then stored back to front (check_reversed). */
static void check_layout(int d, const uint64_t *n0, unsigned level, size_t n)
{
    vpdsi_mem mem;
    vpdsi_cells c;
    uint64_t *copy = (uint64_t *)malloc(n * (size_t)d * sizeof *copy), got[VPDS_MAX_DIM];
    unsigned bits = 0;
    size_t i, kept = 0;
    int k, same = 1;
    vpdsi_mem_init(&mem, NULL);
    memset(&c, 0, sizeof c);
    vpdsi_cells_layout(&c, d, n0, level);
    for (k = 0; k < d; k++) bits += vpdsi_bit_length(n0[k]) + level;
    CHECK(copy != NULL && vpdsi_cells_reserve(&c, &mem, n) == 0);
    CHECK_MSG((bits <= 32) == (c.words_per_cell == 0), "%u bits, %u words per cell", bits,
              c.words_per_cell);
    if (bits <= 32) CHECK(c.cap_words * sizeof(uint64_t) < n * sizeof(uint32_t) + 64 * sizeof(uint64_t) + n * 2);
    for (i = 0; i < n; i++) {
        for (k = 0; k < d; k++) {
            uint64_t span = n0[k] << level; /* every value below it, the largest most of all */
            copy[i * d + k] = i % 3 == 0 ? span - 1 : next_u64() % span;
        }
        vpdsi_cells_push(&c, d, copy + i * d);
    }
    CHECK(c.count == n);
    for (i = 0; i < n; i++) {
        vpdsi_cells_get(&c, i, d, got);
        same &= memcmp(got, copy + i * d, (size_t)d * sizeof *got) == 0;
    }
    for (i = 0; i < n; i += 3) { /* compaction in place, in order */
        vpdsi_cells_move(&c, i, kept);
        memmove(copy + kept * d, copy + i * d, (size_t)d * sizeof *copy);
        kept++;
    }
    for (i = 0; i < kept; i++) {
        vpdsi_cells_get(&c, i, d, got);
        same &= memcmp(got, copy + i * d, (size_t)d * sizeof *got) == 0;
    }
    /* the room past the cells kept given back: exactly the words they take, the same cells */
    c.count = kept; /* as the two radii' filter ends its compaction */
    vpdsi_cells_shrink(&c, &mem);
    CHECK_MSG(c.cap_words == (c.words_per_cell ? kept * c.words_per_cell : (kept + 1) / 2) &&
                  mem.held == c.cap_words * sizeof *c.words,
              "dim %d, level %u: %zu words held for %zu cells after a shrink", d, level, c.cap_words, kept);
    for (i = 0; i < kept; i++) {
        vpdsi_cells_get(&c, i, d, got);
        same &= memcmp(got, copy + i * d, (size_t)d * sizeof *got) == 0;
    }
    CHECK_MSG(same, "dim %d, level %u, %u bits: a cell read back differs", d, level, bits);
    check_reversed(&c, &mem, d, copy, kept);
    vpdsi_cells_release(&c, &mem);
    CHECK(mem.held == 0);
    free(copy);
}

/* Families (cells.h) against the flat list of the same children, for d = 1..8 at random
 * levels: a sweep's order (vpdsi_cells_get_seq), a dart's (vpdsi_cells_get, random), a cut
 * back to an earlier family and pushed again (a sweep's retry after an error), a shrink, the
 * records stored back to front (check_reversed). */
static void check_families(int d, unsigned level, size_t parents)
{
    vpdsi_mem mem;
    vpdsi_cells c;
    uint64_t n0[VPDS_MAX_DIM], parent[VPDS_MAX_DIM], got[VPDS_MAX_DIM], bits[4];
    size_t cap = parents << d, n = 0, i, f, cut_n = 0, cut_fam = 0;
    uint64_t *flat = (uint64_t *)malloc(cap * (size_t)d * sizeof *flat);
    unsigned children = 1u << d, b, w;
    int k, same = 1, pass;
    for (k = 0; k < d; k++) n0[k] = 1 + next_u64() % 40;
    vpdsi_mem_init(&mem, NULL);
    memset(&c, 0, sizeof c);
    vpdsi_cells_layout_families(&c, d, n0, level);
    CHECK(flat != NULL && vpdsi_cells_reserve_families(&c, &mem, parents, d) == 0);
    for (pass = 0; pass < 2; pass++) {
        for (f = pass ? cut_fam : 0; f < parents; f++) {
            for (k = 0; k < d; k++) parent[k] = next_u64() % (n0[k] << (level - 1));
            memset(bits, 0, sizeof bits);
            for (b = 0; b < children; b++) /* sparse, dense, empty and full families */
                if (next_u64() % 4 < (f % 4)) bits[b / 64] |= UINT64_C(1) << (b % 64);
            if (f % 7 == 0)
                for (w = 0; w < 4; w++) bits[w] = children >= 64 * (w + 1) ? ~UINT64_C(0) : children > 64 * w ? (UINT64_C(1) << (children % 64)) - 1 : 0;
            if (!pass && f == parents / 2) { /* where the cut will go back to */
                cut_n = c.count;
                cut_fam = c.n_fam;
            }
            vpdsi_cells_push_family(&c, d, parent, bits);
            for (b = 0; b < children; b++) {
                if (!((bits[b / 64] >> (b % 64)) & 1u)) continue;
                for (k = 0; k < d; k++) flat[n * (size_t)d + (size_t)k] = 2 * parent[k] + ((b >> k) & 1u);
                n++;
            }
        }
        CHECK_MSG(c.count == n, "dim %d: %zu cells held, %zu pushed", d, c.count, n);
        if (pass && cut_n + 1 < n) { /* the cursor was in a family cut away: it starts over */
            vpdsi_cells_get_seq(&c, cut_n + 1, d, got);
            same &= memcmp(got, flat + (cut_n + 1) * (size_t)d, (size_t)d * sizeof *got) == 0;
        }
        for (i = 0; i < n; i++) {
            vpdsi_cells_get_seq(&c, i, d, got);
            same &= memcmp(got, flat + i * (size_t)d, (size_t)d * sizeof *got) == 0;
        }
        for (i = 0; i < 3 * n; i++) {
            size_t at = (size_t)(next_u64() % (n ? n : 1));
            if (!n) break;
            if (i % 2) vpdsi_cells_get(&c, at, d, got);
            else vpdsi_cells_get_seq(&c, at, d, got);
            same &= memcmp(got, flat + at * (size_t)d, (size_t)d * sizeof *got) == 0;
        }
        if (!pass) { /* the cut: the families after it are pushed again, others this time */
            if (cut_n < n) vpdsi_cells_get_seq(&c, cut_n, d, got);
            vpdsi_cells_truncate(&c, cut_n, cut_fam);
            n = cut_n;
        }
    }
    CHECK_MSG(same, "dim %d, level %u: a family's cell read back differs", d, level);
    vpdsi_cells_shrink(&c, &mem);
    for (i = 0; i < n; i++) {
        vpdsi_cells_get(&c, i, d, got);
        same &= memcmp(got, flat + i * (size_t)d, (size_t)d * sizeof *got) == 0;
    }
    CHECK_MSG(same, "dim %d, level %u: a cell differs after a shrink", d, level);
    CHECK_MSG(c.cap_fam == c.n_fam * c.fam_bytes, "dim %d: %zu bytes held for %zu families of %u", d, c.cap_fam,
              c.n_fam, c.fam_bytes);
    check_reversed(&c, &mem, d, flat, n);
    /* emptied (a level past its use): no cell, a byte of room each, and it fills again */
    vpdsi_cells_empty(&c, &mem);
    CHECK_MSG(c.count == 0 && c.n_fam == 0 && c.cap_fam == 1 && c.cap_bucket_fam == 1 && c.cap_bucket_off == 1 &&
                  mem.held == sizeof *c.bucket_fam + 2,
              "dim %d: %zu bytes held once emptied", d, mem.held);
    if (n > 0 && vpdsi_cells_reserve_families(&c, &mem, 1, d) == 0) {
        uint64_t all[VPDSI_CELLS_MAX_WORDS], parent[VPDS_MAX_DIM] = {0};
        unsigned w;
        for (w = 0; w < VPDSI_CELLS_MAX_WORDS; w++) all[w] = w == 0 && d < 6 ? (UINT64_C(1) << (1u << d)) - 1 : ~UINT64_C(0);
        vpdsi_cells_push_family(&c, d, parent, all);
        vpdsi_cells_get(&c, c.count - 1, d, got);
        for (k = 0; k < d; k++) same &= got[k] == 1;
        CHECK_MSG(same && c.count == ((size_t)1 << d), "dim %d: a family pushed after emptying reads back wrong", d);
    }
    vpdsi_cells_release(&c, &mem);
    CHECK(mem.held == 0);
    free(flat);
}

static void *refuse_realloc(void *p, size_t old_size, size_t new_size, void *user)
{
    (void)p; (void)old_size; (void)new_size; (void)user;
    return NULL;
}

/* A shrink the allocator refuses, or one without a realloc (it would hold two blocks at once),
 * leaves the cells and the bytes held as they were; the growth past 1 MiB is by an eighth. */
static void check_shrink_refused(void)
{
    uint64_t n0[2] = {1000, 1000}, c2[2], got[2];
    vpdsi_mem mem;
    vpdsi_cells c;
    size_t i, cap, held;
    int pass, same = 1;
    for (pass = 0; pass < 2; pass++) {
        vpdsi_mem_init(&mem, NULL);
        memset(&c, 0, sizeof c);
        vpdsi_cells_layout(&c, 2, n0, 0);
        CHECK(vpdsi_cells_reserve(&c, &mem, 1000) == 0);
        for (i = 0; i < 100; i++) {
            c2[0] = i;
            c2[1] = 999 - i;
            vpdsi_cells_push(&c, 2, c2);
        }
        cap = c.cap_words;
        held = mem.held;
        if (pass == 0) mem.a.realloc = refuse_realloc;
        else mem.a.realloc = NULL;
        vpdsi_cells_shrink(&c, &mem);
        CHECK_MSG(c.cap_words == cap && mem.held == held, "pass %d: a refused shrink changed the room", pass);
        for (i = 0; i < 100; i++) {
            vpdsi_cells_get(&c, i, 2, got);
            same &= got[0] == i && got[1] == 999 - i;
        }
        vpdsi_cells_release(&c, &mem);
        CHECK(mem.held == 0);
    }
    CHECK_MSG(same, "a cell changed under a refused shrink");
    /* 4 MiB of 32-bit cells grow by an eighth (vpdsi_mem_reserve_fine) where other arrays grow
     * by a quarter */
    vpdsi_mem_init(&mem, NULL);
    memset(&c, 0, sizeof c);
    vpdsi_cells_layout(&c, 2, n0, 0);
    CHECK(vpdsi_cells_reserve(&c, &mem, (size_t)1 << 20) == 0);
    cap = c.cap_words;
    CHECK(vpdsi_cells_reserve(&c, &mem, 2 * cap + 2) == 0);
    CHECK_MSG(c.cap_words == cap + cap / 8 + 16, "%zu words after growing from %zu", c.cap_words, cap);
    vpdsi_cells_release(&c, &mem);
}

static vpdsi_piece random_piece(unsigned bits)
{
    vpdsi_piece p;
    uint64_t span = bits >= 64 ? ~UINT64_C(0) : (UINT64_C(1) << bits) - 1;
    memset(&p, 0, sizeof p);
    p.i = next_u64() % 3 == 0 ? span : next_u64() & span;
    p.j = next_u64() & span;
    p.tri = (uint32_t)next_u64();
    p.level = (uint8_t)(next_u64() % 60);
    p.down = (uint8_t)(next_u64() & 1);
    return p;
}

static int pieces_equal(const vpdsi_piece_array *a, const vpdsi_piece *copy, size_t n)
{
    size_t k;
    for (k = 0; k < n; k++) {
        vpdsi_piece p = vpdsi_piece_array_get(a, k);
        if (p.i != copy[k].i || p.j != copy[k].j || p.tri != copy[k].tri ||
            p.level != copy[k].level || p.down != copy[k].down)
            return 0;
    }
    return a->n == n;
}

static void check_pieces(void)
{
    enum { N = 3000 };
    static vpdsi_piece copy[2 * N];
    vpdsi_piece_array a;
    vpdsi_mem mem;
    size_t k, held;
    vpdsi_mem_init(&mem, NULL);
    memset(&a, 0, sizeof a);
    CHECK(vpdsi_piece_array_reserve(&a, &mem, N, 32) == 0 && !a.wide && a.cap < N * 16 + N * 8);
    for (k = 0; k < N; k++) {
        copy[k] = random_piece(32);
        vpdsi_piece_array_push(&a, &copy[k]);
    }
    CHECK_MSG(pieces_equal(&a, copy, N), "32-bit pieces read back differ");
    /* a widening the allocator refuses: the pieces stay, narrow */
    held = mem.held;
    mem.limit = held + 1;
    CHECK(vpdsi_piece_array_reserve(&a, &mem, 2 * N, 33) == -1 && !a.wide && pieces_equal(&a, copy, N));
    mem.limit = 0;
    CHECK(vpdsi_piece_array_reserve(&a, &mem, 2 * N, 33) == 0 && a.wide);
    CHECK_MSG(pieces_equal(&a, copy, N), "pieces differ after widening");
    for (k = N; k < 2 * N; k++) {
        copy[k] = random_piece(k % 2 ? 33 : 63);
        vpdsi_piece_array_push(&a, &copy[k]);
    }
    CHECK_MSG(pieces_equal(&a, copy, 2 * N), "wide pieces read back differ");
    vpdsi_piece_array_clear(&a); /* emptied: narrow again where the level allows */
    CHECK(vpdsi_piece_array_reserve(&a, &mem, N, 20) == 0 && !a.wide);
    for (k = 0; k < N; k++) {
        copy[k] = random_piece(20);
        vpdsi_piece_array_push(&a, &copy[k]);
    }
    CHECK(pieces_equal(&a, copy, N));
    vpdsi_piece_array_release(&a, &mem);
    CHECK(mem.held == 0);
}

int main(void)
{
    int d, rep;
    unsigned level;
    check_pieces();
    check_shrink_refused();
    for (d = 1; d <= 8; d++)
        for (level = 1; level < 30; level += 7)
            check_families(d, level, d <= 4 ? 3000 : 300);
    for (d = 1; d <= VPDS_MAX_DIM; d++)
        for (rep = 0; rep < 6; rep++)
            for (level = 0; level < 40; level += 1 + level / 4) {
                uint64_t n0[VPDS_MAX_DIM];
                unsigned total = 0;
                int k;
                for (k = 0; k < d; k++) {
                    /* 1 to 2^(6 - rep) base cells, and sometimes many more */
                    n0[k] = 1 + next_u64() % (rep == 5 ? 100000 : (UINT64_C(1) << (6 - rep)));
                    total += vpdsi_bit_length(n0[k]) + level;
                }
                if (total > 60 * (unsigned)d) continue; /* past any run's lattice */
                check_layout(d, n0, level, 1000);
            }
    /* the boundary: exactly 32 bits in one word, 33 in a 64-bit word */
    {
        uint64_t n16[2] = {UINT64_C(1) << 16, UINT64_C(1) << 16}, n17[2] = {UINT64_C(1) << 17, UINT64_C(1) << 16};
        check_layout(2, n16, 0, 5000);
        check_layout(2, n17, 0, 5000);
        check_layout(2, n16, 1, 5000);
    }
    CHECK_DONE();
}
