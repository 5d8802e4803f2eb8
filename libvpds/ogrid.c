#include "ogrid.h"
#include "proximity.h"
#include "rng.h"
#include <math.h>
#include <string.h>

#define CELL_MAX ((UINT64_C(1) << VPDSI_OGRID_BITS) - 1)

static const double open_axes[3] = {0, 0, 0};

/* The coarsest levels whose cells over the box number at most budget in all: arrays, not the
 * table (their cells along an axis: the box's extent over the side, rounded down, plus one). */
static void plan_dense(vpdsi_ogrid *g, const double *lo, const double *hi, double budget)
{
    double used = 0;
    int k, l;
    for (l = 0; l < g->levels; l++) {
        vpdsi_ogrid_level *lv = &g->lv[l];
        size_t cells = 1, bytes; /* bytes: only that the array's size fits a size_t */
        for (k = 0; k < 3; k++) {
            double n = k < g->dim ? floor((hi[k] - lo[k]) * lv->inv) + 1 : 1;
            if (!(n <= (double)CELL_MAX + 1) || vpdsi_mul_size(cells, (size_t)n, &cells)) break;
            lv->dn[k] = (uint64_t)n;
        }
        if (k < 3 || vpdsi_mul_size(cells, sizeof *lv->dense, &bytes) || !(used + (double)cells <= budget))
            break;
        used += (double)cells;
        lv->cells = cells;
    }
    g->n_hashed = g->levels - l;
}

int vpdsi_ogrid_setup(vpdsi_ogrid *g, int dim, const double *lo, const double *hi, double top,
                      double bottom, double dense_cells)
{
    double ext = 0;
    int k, l;
    if (dim > 3) return -1;
    memset(g, 0, sizeof *g);
    g->dim = dim;
    for (k = 0; k < dim; k++) {
        g->lo[k] = lo[k];
        if (hi[k] - lo[k] > ext) ext = hi[k] - lo[k];
    }
    if (!(top > 0)) top = ext;
    /* a box wider than 2^BITS cells of the largest radius: coordinates would be clamped and
     * samples filed where queries do not look */
    if (!(ext / top < (double)CELL_MAX)) return -2;
    /* levels while a cell coordinate fits its bits, and none past the level of the least
     * radius; smaller radii share the last level. The first is 2 top wide: a sample goes
     * where the side is at least 2r (level_of) */
    for (l = 0; l < VPDSI_OGRID_LEVELS; l++) {
        double side = ldexp(2 * top, -l);
        if (l > 0 && (!(ext / side < (double)CELL_MAX) || !(side >= 2 * bottom))) break;
        g->lv[l].side = side;
        g->lv[l].inv = 1 / side;
    }
    g->levels = l;
    plan_dense(g, lo, hi, dense_cells);
    return 0;
}

static void free_dense(vpdsi_ogrid *g, vpdsi_mem *m)
{
    int l;
    for (l = 0; l < g->levels; l++) {
        vpdsi_mem_free(m, g->lv[l].dense, g->lv[l].cells * sizeof *g->lv[l].dense);
        g->lv[l].dense = NULL;
    }
}

/* The dense levels' arrays, empty, at the first reserve: all of them, or none (-1). */
static int alloc_dense(vpdsi_ogrid *g, vpdsi_mem *m)
{
    int l;
    size_t j;
    for (l = 0; l < g->levels - g->n_hashed; l++) {
        vpdsi_ogrid_level *lv = &g->lv[l];
        if (lv->dense) continue;
        lv->dense = (int32_t *)vpdsi_mem_alloc(m, lv->cells * sizeof *lv->dense);
        if (!lv->dense) {
            free_dense(g, m);
            return -1;
        }
        for (j = 0; j < lv->cells; j++) lv->dense[j] = -1;
    }
    return 0;
}

void vpdsi_ogrid_release(vpdsi_ogrid *g, vpdsi_mem *m)
{
    vpdsi_mem_free(m, g->keys, g->cap * sizeof *g->keys);
    vpdsi_mem_free(m, g->heads, g->cap * sizeof *g->heads);
    vpdsi_mem_free(m, g->next, g->cap_next * sizeof *g->next);
    free_dense(g, m);
    g->keys = NULL;
    g->heads = g->next = NULL;
    g->cap = g->used = g->cap_next = 0;
}

static size_t slot_of(const vpdsi_ogrid *g, uint64_t key)
{
    size_t mask = g->cap - 1, i = (size_t)vpdsi_mix64(key) & mask;
    while (g->keys[i] != 0 && g->keys[i] != key) i = (i + 1) & mask;
    return i;
}

int vpdsi_ogrid_reserve(vpdsi_ogrid *g, vpdsi_mem *m, size_t n_total, size_t more)
{
    size_t cap = g->cap ? g->cap : 64, i;
    uint64_t *keys;
    int32_t *heads;
    if (vpdsi_mem_reserve_fine(m, (void **)&g->next, &g->cap_next, n_total, sizeof *g->next) ||
        alloc_dense(g, m))
        return -1;
    if (g->n_hashed == 0) return 0; /* every level in arrays: no table */
    while (cap / 2 < g->used + more) {
        if (cap > ((size_t)-1) / 4 / sizeof *keys) return -1;
        cap *= 2;
    }
    if (cap == g->cap) return 0;
    keys = (uint64_t *)vpdsi_mem_alloc(m, cap * sizeof *keys);
    heads = (int32_t *)vpdsi_mem_alloc(m, cap * sizeof *heads);
    if (!keys || !heads) {
        if (keys) vpdsi_mem_free(m, keys, cap * sizeof *keys);
        if (heads) vpdsi_mem_free(m, heads, cap * sizeof *heads);
        return -1;
    }
    memset(keys, 0, cap * sizeof *keys);
    {
        vpdsi_ogrid old = *g;
        g->keys = keys;
        g->heads = heads;
        g->cap = cap;
        for (i = 0; i < old.cap; i++)
            if (old.keys[i]) {
                size_t j = slot_of(g, old.keys[i]);
                keys[j] = old.keys[i];
                heads[j] = old.heads[i];
            }
        vpdsi_mem_free(m, old.keys, old.cap * sizeof *old.keys);
        vpdsi_mem_free(m, old.heads, old.cap * sizeof *old.heads);
    }
    return 0;
}

/* Cell coordinate of v on axis k of level l, clamped to [a, b]. */
static uint64_t cell_at(const vpdsi_ogrid *g, int l, int k, double v, uint64_t a, uint64_t b)
{
    double q = floor((v - g->lo[k]) * g->lv[l].inv);
    if (!(q > (double)a)) return a;
    if (q >= (double)b) return b;
    return (uint64_t)q;
}

static uint64_t key_of(int l, const uint64_t *c, int dim)
{
    uint64_t key = (uint64_t)l << (3 * VPDSI_OGRID_BITS);
    int k;
    for (k = 0; k < dim; k++) key |= c[k] << (k * VPDSI_OGRID_BITS);
    return key + 1;
}

/* The last cell coordinate on axis k, where the clamp puts samples past it: the array's last,
 * or the table's key's. */
static uint64_t last_cell(const vpdsi_ogrid_level *lv, int k)
{
    return lv->dense ? lv->dn[k] - 1 : CELL_MAX;
}

/* Where a dense level keeps cell c (dim coordinates). */
static size_t dense_at(const vpdsi_ogrid_level *lv, int dim, const uint64_t *c)
{
    size_t j = 0;
    int k;
    for (k = dim - 1; k >= 0; k--) j = j * (size_t)lv->dn[k] + (size_t)c[k];
    return j;
}

static int level_of(const vpdsi_ogrid *g, double r)
{
    int l = 0;
    while (l + 1 < g->levels && g->lv[l + 1].side >= 2 * r) l++;
    return l;
}

void vpdsi_ogrid_insert(vpdsi_ogrid *g, const vpdsi_kd_samples *s, int32_t i)
{
    const double *x = s->x + (size_t)i * (size_t)g->dim;
    int l = level_of(g, s->r[i]), k;
    vpdsi_ogrid_level *lv = &g->lv[l];
    uint64_t c[3] = {0, 0, 0};
    size_t j;
    for (k = 0; k < g->dim; k++) {
        c[k] = cell_at(g, l, k, x[k], 0, last_cell(lv, k));
        if (lv->count == 0 || x[k] < lv->lo[k]) lv->lo[k] = x[k];
        if (lv->count == 0 || x[k] > lv->hi[k]) lv->hi[k] = x[k];
        if (lv->count == 0 || c[k] < lv->clo[k]) lv->clo[k] = c[k];
        if (lv->count == 0 || c[k] > lv->chi[k]) lv->chi[k] = c[k];
    }
    if (lv->count == 0 || s->r[i] > lv->rmax) lv->rmax = s->r[i];
    lv->count++;
    if (lv->dense) {
        j = dense_at(lv, g->dim, c);
        g->next[i] = lv->dense[j];
        lv->dense[j] = i;
        return;
    }
    j = slot_of(g, key_of(l, c, g->dim));
    if (g->keys[j] == 0) {
        g->keys[j] = key_of(l, c, g->dim);
        g->next[i] = -1;
        g->used++;
    } else {
        g->next[i] = g->heads[j];
    }
    g->heads[j] = i;
}

/* Squared gap between the boxes [alo, ahi] and [blo, bhi]. */
static double box_gap2(int dim, const double *alo, const double *ahi, const double *blo,
                       const double *bhi)
{
    double s = 0;
    int k;
    for (k = 0; k < dim; k++) {
        double e = alo[k] > bhi[k] ? alo[k] - bhi[k] : blo[k] > ahi[k] ? blo[k] - ahi[k] : 0;
        s += e * e;
    }
    return s;
}

/* The cells of level l that meet [lo - reach, hi + reach] and its samples' box: a, b (per
 * axis, inclusive); 0 when there are none. */
static int cell_range(const vpdsi_ogrid *g, int l, const double *lo, const double *hi,
                      double reach, uint64_t *a, uint64_t *b)
{
    const vpdsi_ogrid_level *lv = &g->lv[l];
    double wide = reach * (1 + 1e-9);
    int k;
    if (box_gap2(g->dim, lo, hi, lv->lo, lv->hi) > wide * wide) return 0;
    for (k = 0; k < g->dim; k++) {
        /* widened past the round-off of the coordinates, so no sample within reach is missed */
        double m = wide + 1e-15 * (fabs(lo[k]) + fabs(hi[k]) + fabs(g->lo[k]) + reach);
        a[k] = cell_at(g, l, k, lo[k] - m, lv->clo[k], lv->chi[k]);
        b[k] = cell_at(g, l, k, hi[k] + m, lv->clo[k], lv->chi[k]);
    }
    return 1;
}

/* The next cell of the range [a, b] after c (odometer); 0 past the last. */
static int next_cell(int dim, const uint64_t *a, const uint64_t *b, uint64_t *c)
{
    int k;
    for (k = 0; k < dim; k++) {
        if (c[k] < b[k]) {
            c[k]++;
            return 1;
        }
        c[k] = a[k];
    }
    return 0;
}

/* Whether cell c of level l lies farther than reach (widened as in cell_range) from the box
 * [lo, hi]: its samples need no test. A first or last cell (the clamp's) holds samples beyond
 * the box too: on that side it reaches to the level's samples. */
static int cell_beyond(const vpdsi_ogrid *g, int l, const uint64_t *c, const double *lo,
                       const double *hi, double reach)
{
    const vpdsi_ogrid_level *lv = &g->lv[l];
    double side = lv->side, wide = reach * (1 + 1e-9), s = 0;
    int k;
    for (k = 0; k < g->dim; k++) {
        double clo = g->lo[k] + (double)c[k] * side, chi = clo + side, e;
        double m = 1e-15 * (fabs(lo[k]) + fabs(hi[k]) + fabs(g->lo[k]) + reach) + 1e-9 * side;
        if (c[k] == 0 && lv->lo[k] < clo) clo = lv->lo[k];
        if (c[k] == last_cell(lv, k) && lv->hi[k] > chi) chi = lv->hi[k];
        e = clo > hi[k] ? clo - hi[k] : lo[k] > chi ? lo[k] - chi : 0;
        e = e > m ? e - m : 0;
        s += e * e;
    }
    return s > wide * wide;
}

/* Cells in the range [a, b] (saturating). */
static double range_cells(int dim, const uint64_t *a, const uint64_t *b)
{
    double n = 1;
    int k;
    for (k = 0; k < dim; k++) n *= (double)(b[k] - a[k] + 1);
    return n;
}

/* Whether slot j holds a cell of level l inside the range [a, b]; its coordinates into c. */
static int slot_in_range(const vpdsi_ogrid *g, size_t j, int l, const uint64_t *a,
                         const uint64_t *b, uint64_t *c)
{
    uint64_t key = g->keys[j] - 1;
    int k;
    if (g->keys[j] == 0 || (int)(key >> (3 * VPDSI_OGRID_BITS)) != l) return 0;
    for (k = 0; k < g->dim; k++) {
        c[k] = (key >> (k * VPDSI_OGRID_BITS)) & CELL_MAX;
        if (c[k] < a[k] || c[k] > b[k]) return 0;
    }
    return 1;
}

static int32_t head_of(const vpdsi_ogrid *g, int l, const uint64_t *c)
{
    size_t j;
    if (g->lv[l].dense) return g->lv[l].dense[dense_at(&g->lv[l], g->dim, c)];
    if (g->cap == 0) return -1;
    j = slot_of(g, key_of(l, c, g->dim));
    return g->keys[j] ? g->heads[j] : -1;
}

/* The cells of level l to read for the range [a, b]: the range itself, or, when it has more
 * cells than the table has slots (a reach far above the level's radii), the table's cells of
 * that level within it (scan_table, from range_cells): at most as many reads as the table has
 * slots. Returns the next cell's
 * first sample through *head (-1 at a cell without samples), 0 past the last cell. *pos is the
 * iteration state, 0 at the start. */
static int next_range_cell(const vpdsi_ogrid *g, int l, const uint64_t *a, const uint64_t *b,
                           int scan_table, uint64_t *c, size_t *pos, int32_t *head)
{
    if (scan_table) {
        while (*pos < g->cap) {
            size_t j = (*pos)++;
            if (slot_in_range(g, j, l, a, b, c)) {
                *head = g->heads[j];
                return 1;
            }
        }
        return 0;
    }
    if (*pos == 0) memcpy(c, a, (size_t)g->dim * sizeof *c);
    else if (!next_cell(g->dim, a, b, c)) return 0;
    (*pos)++;
    *head = head_of(g, l, c);
    return 1;
}

void vpdsi_ogrid_prefetch(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *y,
                          double ry, int stage)
{
    int l = level_of(g, ry), k;
    const vpdsi_ogrid_level *lv = &g->lv[l];
    uint64_t c[3], key;
    size_t j;
    if (lv->count == 0 || (!lv->dense && g->cap == 0)) return;
    for (k = 0; k < g->dim; k++) c[k] = cell_at(g, l, k, y[k], 0, last_cell(lv, k));
    if (lv->dense) {
        size_t j = dense_at(lv, g->dim, c);
        int32_t i;
        if (stage == 0) {
            VPDSI_PREFETCH(lv->dense + j);
            return;
        }
        if ((i = lv->dense[j]) >= 0) {
            VPDSI_PREFETCH(s->x + (size_t)i * (size_t)g->dim);
            VPDSI_PREFETCH(s->r + i);
            VPDSI_PREFETCH(g->next + i);
        }
        return;
    }
    key = key_of(l, c, g->dim);
    if (stage == 0) {
        j = (size_t)vpdsi_mix64(key) & (g->cap - 1);
        VPDSI_PREFETCH(g->keys + j);
        VPDSI_PREFETCH(g->heads + j);
        return;
    }
    j = slot_of(g, key);
    if (g->keys[j]) {
        int32_t i = g->heads[j];
        VPDSI_PREFETCH(s->x + (size_t)i * (size_t)g->dim);
        VPDSI_PREFETCH(s->r + i);
        VPDSI_PREFETCH(g->next + i);
    }
}

/* The conflict test over the chain from sample i: the first sample that conflicts, -2 (its
 * index in *witness) at a broken Lipschitz bound, -1 when none does. */
static int32_t chain_conflict(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, int32_t i,
                              const double *y, double ry, int rule, double scale,
                              double lipschitz, int32_t *witness)
{
    for (; i >= 0; i = g->next[i]) {
        int hit = vpdsi_prox_conflict(s, i, g->dim, open_axes, y, ry, rule, scale, lipschitz);
        if (hit == -2) {
            *witness = i;
            return -2;
        }
        if (hit) return i;
    }
    return -1;
}

int32_t vpdsi_ogrid_conflict(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *y,
                             double ry, int rule, double scale, double lipschitz,
                             int32_t *witness)
{
    int home = level_of(g, ry), step, k;
    /* the level of ry first, then outwards: conflicts are likeliest among similar radii */
    for (step = 0; step < 2 * g->levels; step++) {
        int l = home + (step % 2 ? (step + 1) / 2 : -(step / 2));
        uint64_t a[3], b[3], c[3], yc[3];
        size_t pos = 0;
        int32_t i, hit;
        int scan;
        double reach;
        if (l < 0 || l >= g->levels || g->lv[l].count == 0) continue;
        reach = scale * vpdsi_rule_f((vpds_rule)rule, g->lv[l].rmax, ry);
        if (!cell_range(g, l, y, y, reach, a, b)) continue;
        /* the cell of y first (a conflict lies likeliest there), then the rest of the range */
        for (k = 0; k < g->dim; k++) yc[k] = cell_at(g, l, k, y[k], a[k], b[k]);
        if (!cell_beyond(g, l, yc, y, y, reach) &&
            (hit = chain_conflict(g, s, head_of(g, l, yc), y, ry, rule, scale, lipschitz, witness)) != -1)
            return hit;
        scan = !g->lv[l].dense && range_cells(g->dim, a, b) > (double)g->cap;
        while (next_range_cell(g, l, a, b, scan, c, &pos, &i)) {
            if (i < 0 || !memcmp(c, yc, (size_t)g->dim * sizeof *c) || cell_beyond(g, l, c, y, y, reach))
                continue;
            if ((hit = chain_conflict(g, s, i, y, ry, rule, scale, lipschitz, witness)) != -1) return hit;
        }
    }
    return -1;
}

int vpdsi_ogrid_gather(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *lo,
                       const double *hi, double r_hi, int rule, double scale, int split,
                       vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap)
{
    double c0[3], c1[3], w[3];
    int l;
    vpdsi_prox_gather_centres(g->dim, lo, hi, split, c0, c1, w);
    for (l = 0; l < g->levels; l++) {
        uint64_t a[3], b[3], c[3];
        size_t pos = 0;
        int32_t i;
        int scan;
        double reach;
        if (g->lv[l].count == 0) continue;
        reach = scale * vpdsi_rule_f((vpds_rule)rule, g->lv[l].rmax, r_hi);
        /* a sample covers a sub-box only from within its reach of the box */
        if (!cell_range(g, l, lo, hi, reach, a, b)) continue;
        scan = !g->lv[l].dense && range_cells(g->dim, a, b) > (double)g->cap;
        while (next_range_cell(g, l, a, b, scan, c, &pos, &i)) {
            if (i < 0 || cell_beyond(g, l, c, lo, hi, reach)) continue;
            for (; i >= 0; i = g->next[i]) {
                if (!vpdsi_prox_may_cover(s, i, g->dim, open_axes, c0, c1, w, r_hi, rule, scale))
                    continue;
                if (*count == *cap && vpdsi_mem_reserve(m, (void **)out, cap, *count + 1, sizeof **out))
                    return -1;
                (*out)[(*count)++] = i;
            }
        }
    }
    return 0;
}

int vpdsi_ogrid_gathers(const vpdsi_kd_samples *s, int dim, int32_t i, const double *lo,
                        const double *hi, double r_hi, int rule, double scale, int split)
{
    double c0[3], c1[3], w[3];
    vpdsi_prox_gather_centres(dim, lo, hi, split, c0, c1, w);
    return vpdsi_prox_may_cover(s, i, dim, open_axes, c0, c1, w, r_hi, rule, scale);
}

/* The samples near the box [lo, hi] by vpdsi_prox_near (rule < 0) or vpdsi_prox_near_rule,
 * appended to *out; -1 on OOM. */
static int near_walk(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *lo, const double *hi,
                     double r_bound, int rule, double scale, vpdsi_mem *m, int32_t **out, size_t *count,
                     size_t *cap)
{
    int l;
    for (l = 0; l < g->levels; l++) {
        uint64_t a[3], b[3], c[3];
        size_t pos = 0;
        int32_t i;
        int scan;
        double reach, rmax = g->lv[l].rmax;
        if (g->lv[l].count == 0) continue;
        /* the widest of the level's samples' tests (f grows with r(x) under every rule) */
        reach = scale * (rule < 0 ? (rmax > r_bound ? rmax : r_bound) : vpdsi_rule_f((vpds_rule)rule, rmax, r_bound)) *
                (1 + 1e-9);
        if (!cell_range(g, l, lo, hi, reach, a, b)) continue;
        scan = !g->lv[l].dense && range_cells(g->dim, a, b) > (double)g->cap;
        while (next_range_cell(g, l, a, b, scan, c, &pos, &i)) {
            if (i < 0 || cell_beyond(g, l, c, lo, hi, reach)) continue;
            for (; i >= 0; i = g->next[i]) {
                if (rule < 0 ? !vpdsi_prox_near(s, i, g->dim, open_axes, lo, hi, r_bound, scale, 0)
                             : !vpdsi_prox_near_rule(s, i, g->dim, open_axes, lo, hi, r_bound, rule, scale))
                    continue;
                if (*count == *cap && vpdsi_mem_reserve(m, (void **)out, cap, *count + 1, sizeof **out))
                    return -1;
                (*out)[(*count)++] = i;
            }
        }
    }
    return 0;
}

int vpdsi_ogrid_near_box(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *lo,
                         const double *hi, double r_bound, double scale, vpdsi_mem *m,
                         int32_t **out, size_t *count, size_t *cap)
{
    return near_walk(g, s, lo, hi, r_bound, -1, scale, m, out, count, cap);
}

int vpdsi_ogrid_near_rule(const vpdsi_ogrid *g, const vpdsi_kd_samples *s, const double *lo,
                          const double *hi, double r_bound, int rule, double scale, vpdsi_mem *m,
                          int32_t **out, size_t *count, size_t *cap)
{
    return near_walk(g, s, lo, hi, r_bound, rule, scale, m, out, count, cap);
}
