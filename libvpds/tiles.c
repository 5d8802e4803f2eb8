/* Tiled sampling: the grid of tiles, its colour phases, the dependencies (direct and the whole
 * cone), the seed of a tile, and the sampler of one tile (its core, with the samples of its
 * earlier-phase neighbours within the margin as fixed points). Nothing here is mutable after
 * create: temporary memory goes through a copy of the allocator, so threads may share a tiling. */
#include "tiles.h"
#include "refuse.h"
#include "rules.h"
#include "sampler.h"
#include "sizing.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TILES_MAX_PER_AXIS (UINT64_C(1) << 40)
#define TILES_MAX_COUNT (UINT64_C(1) << 62)
#define TILES_CONE_MAX_POSITIONS (UINT64_C(1) << 22) /* lifted boxes larger than this are refused */
/* The margin exceeds the farthest reach by this relative slack: round-off in the distances
 * can then only add fixed points that do not matter, never drop one that does. */
#define TILES_MARGIN_SLACK 1e-9


static int tiles_live(const vpds_tiling *t) { return t && t->magic == VPDSI_TILING_MAGIC; }

vpds_tiling_desc vpds_default_tiling_desc(void)
{
    vpds_tiling_desc d;
    memset(&d, 0, sizeof d);
    d.cookie = VPDSI_TILING_DESC_COOKIE;
    d.struct_size = (uint32_t)sizeof d;
    d.scale = 1.0;
    return d;
}

/* L, r_min and r_max of the whole sizing: what the margin and every tile's sampler use. */
static vpds_status tiles_sizing_params(const vpds_tiling_desc *d, double *L, double *rmin,
                                       double *rmax, char *msg, size_t cap)
{
    const vpds_desc *s = d->sampler;
    int callback = s->sizing != NULL || s->sizing_batch != NULL;
    if (d->sizing_per_tile) {
        if (callback || s->sizing_grid)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.sizing_per_tile is set and desc.sampler has "
                  "a sizing too: give the sizing per tile (grid windows) or in the sampler, not both");
        if (s->lipschitz == VPDS_UNSET)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.sizing_per_tile needs desc.sampler->lipschitz "
                  "(the whole grid's L, which every tile must share)");
        if (!(s->radius_max > 0))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.sizing_per_tile needs desc.sampler->radius_max "
                  "(the whole grid's largest value: it sets the margin)");
        if (s->weighted && !(s->radius_min > 0))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.sizing_per_tile with weighted needs "
                  "desc.sampler->radius_min (the whole grid's smallest value)");
        *L = s->lipschitz;
        *rmin = s->radius_min;
        *rmax = s->radius_max;
    } else {
        if (callback && !(s->radius_max > 0))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.sampler->radius_max = %g: a tiling with a sizing "
                  "callback needs an upper bound of r (it sets the margin, the reach of a disk)",
                  s->radius_max);
        vpdsi_sizing_bounds(s, L, rmin, rmax);
    }
    return VPDS_OK;
}

vpds_status vpds_tiling_validate(const vpds_tiling_desc *d, char *msg, size_t cap)
{
    char inner[400];
    double L, rmin, rmax, margin, limit;
    uint64_t count = 1;
    vpds_status st;
    int k;
    vpds_rule rule;
    if (msg && cap) msg[0] = 0;
    if (!d) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc is NULL");
    if (d->cookie != VPDSI_TILING_DESC_COOKIE)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "tiling desc.cookie = 0x%08x: the descriptor did not come from "
              "vpds_default_tiling_desc()", (unsigned)d->cookie);
    if (d->struct_size != sizeof *d)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "tiling desc.struct_size = %u: a layout this library cannot read "
              "(it reads %u)", (unsigned)d->struct_size, (unsigned)sizeof *d);
    if (!d->sampler) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.sampler is NULL");
    if ((st = vpds_validate(d->sampler, inner, sizeof inner)) != VPDS_OK)
        VPDSI_REFUSE(st, "tiling desc.sampler: %s", inner);
    if (d->sampler->dim > VPDS_TILING_MAX_DIM)
        VPDSI_REFUSE(VPDS_ERR_UNSUPPORTED, "tiling desc.sampler->dim = %d: tilings go up to %d dimensions "
              "(a tile has up to 3^dim - 1 neighbours); sample the box in one run", d->sampler->dim,
              VPDS_TILING_MAX_DIM);
    if (!d->tiles) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.tiles is NULL (dim tile counts)");
    if (!isfinite(d->scale) || !(d->scale > 0))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.scale = %g: must be finite and > 0", d->scale);
    if (!vpdsi_scale_ok(d->scale * d->sampler->coverage))
        VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "tiling desc.scale = %g: scale * coverage must be within [1e-50, 1e50]",
              d->scale);
    if ((st = tiles_sizing_params(d, &L, &rmin, &rmax, msg, cap)) != VPDS_OK) return st;
    rule = vpdsi_rule_resolve(d->sampler->rule);
    limit = vpdsi_rule_max_lipschitz(rule);
    if (d->scale * d->sampler->coverage * L >= limit)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.scale = %g: scale * coverage * L = %g is at or above "
              "the %s rule's limit %g (Table 1)", d->scale, d->scale * d->sampler->coverage * L,
              vpdsi_rule_name(rule), limit);
    margin = d->scale * d->sampler->coverage * rmax * (1 + TILES_MARGIN_SLACK);
    for (k = 0; k < d->sampler->dim; k++) {
        uint64_t n = d->tiles[k];
        double lo = d->sampler->lo ? d->sampler->lo[k] : 0.0, hi = d->sampler->hi ? d->sampler->hi[k] : 1.0;
        int per = d->sampler->periodic && d->sampler->periodic[k];
        if (n < 1 || n > TILES_MAX_PER_AXIS)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.tiles[%d] = %llu: must be in 1..2^40", k,
                  (unsigned long long)n);
        if (per && n % 2 != 0)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.tiles[%d] = %llu: a periodic axis needs an even "
                  "tile count (the phases alternate by parity, and must around the wrap too)", k,
                  (unsigned long long)n);
        if (n > 1 && !((hi - lo) / (double)n >= margin))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling desc.tiles[%d] = %llu: the tile side %g is below the "
                  "margin %g = scale * coverage * r_max (tiles of one phase, a side apart, would "
                  "interact); use at most %.0f tiles on this axis", k, (unsigned long long)n,
                  (hi - lo) / (double)n, margin, floor((hi - lo) / margin));
        if (count > TILES_MAX_COUNT / n)
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "tiling desc.tiles: the tile count overflows 2^62 at tiles[%d] = %llu",
                  k, (unsigned long long)n);
        count *= n;
    }
    return VPDS_OK;
}

vpds_status vpds_tiling_create(const vpds_tiling_desc *d, vpds_tiling **out)
{
    vpdsi_mem m;
    vpds_tiling *t;
    vpds_status st;
    int k;
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if ((st = vpds_tiling_validate(d, NULL, 0)) != VPDS_OK) return st;
    vpdsi_mem_init(&m, &d->sampler->allocator);
    t = (vpds_tiling *)vpdsi_mem_alloc(&m, sizeof *t);
    if (!t) return VPDS_ERR_OUT_OF_MEMORY;
    memset(t, 0, sizeof *t);
    t->mem = m;
    t->dim = d->sampler->dim;
    t->desc = *d->sampler;
    t->count = 1;
    for (k = 0; k < t->dim; k++) {
        t->lo[k] = d->sampler->lo ? d->sampler->lo[k] : 0.0;
        t->hi[k] = d->sampler->hi ? d->sampler->hi[k] : 1.0;
        t->periodic[k] = d->sampler->periodic && d->sampler->periodic[k];
        t->tiles[k] = d->tiles[k];
        t->count *= d->tiles[k];
    }
    t->desc.lo = t->lo;
    t->desc.hi = t->hi;
    t->desc.periodic = NULL; /* a tile's run is never periodic: wraps are images of fixed points */
    t->per_tile = d->sizing_per_tile != 0;
    t->scale = d->scale;
    tiles_sizing_params(d, &t->lipschitz, &t->rmin, &t->rmax, NULL, 0);
    t->margin = t->scale * t->desc.coverage * t->rmax * (1 + TILES_MARGIN_SLACK);
    if (d->sampler->sizing_grid) {
        st = vpdsi_grid_clone(d->sampler->sizing_grid, &d->sampler->allocator, &t->grid);
        if (st != VPDS_OK) {
            vpdsi_mem_free(&m, t, sizeof *t);
            return st;
        }
        t->desc.sizing_grid = t->grid;
    }
    t->magic = VPDSI_TILING_MAGIC;
    *out = t;
    return VPDS_OK;
}

void vpds_tiling_destroy(vpds_tiling *t)
{
    vpdsi_mem m;
    if (!tiles_live(t)) return;
    if (t->grid) vpds_grid_destroy(t->grid);
    m = t->mem;
    t->magic = 0;
    vpdsi_mem_free(&m, t, sizeof *t);
}

uint64_t vpds_tiling_count(const vpds_tiling *t) { return tiles_live(t) ? t->count : 0; }
double vpds_tiling_margin(const vpds_tiling *t) { return tiles_live(t) ? t->margin : NAN; }

static void tiles_coords_of(const vpds_tiling *t, uint64_t tile, uint64_t *c)
{
    int k;
    for (k = t->dim; k-- > 0;) {
        c[k] = tile % t->tiles[k];
        tile /= t->tiles[k];
    }
}

static uint64_t tiles_index_of(const vpds_tiling *t, const uint64_t *c)
{
    uint64_t idx = 0;
    int k;
    for (k = 0; k < t->dim; k++) idx = idx * t->tiles[k] + c[k];
    return idx;
}

static int tiles_phase_of(const vpds_tiling *t, const uint64_t *c)
{
    int k, p = 0;
    for (k = 0; k < t->dim; k++) p |= (int)(c[k] & 1u) << k;
    return p;
}

int vpds_tiling_phase(const vpds_tiling *t, uint64_t tile)
{
    uint64_t c[VPDS_MAX_DIM];
    if (!tiles_live(t) || tile >= t->count) return -1;
    tiles_coords_of(t, tile, c);
    return tiles_phase_of(t, c);
}

uint64_t vpds_tiling_seed(const vpds_tiling *t, uint64_t tile)
{
    if (!tiles_live(t)) return 0;
    return vpdsi_mix64(vpdsi_mix64(t->desc.seed + 0x9E3779B97F4A7C15ull) + (tile + 1) * 0x9E3779B97F4A7C15ull);
}

vpds_status vpds_tiling_coords(const vpds_tiling *t, uint64_t tile, uint64_t *coords)
{
    if (!tiles_live(t) || !coords || tile >= t->count) return VPDS_ERR_INVALID_ARGUMENT;
    tiles_coords_of(t, tile, coords);
    return VPDS_OK;
}

vpds_status vpds_tiling_index(const vpds_tiling *t, const int64_t *coords, uint64_t *tile)
{
    uint64_t c[VPDS_MAX_DIM];
    int k;
    if (!tiles_live(t) || !coords || !tile) return VPDS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < t->dim; k++) {
        int64_t n = (int64_t)t->tiles[k], v = coords[k];
        if (t->periodic[k]) {
            v %= n;
            if (v < 0) v += n;
        } else if (v < 0 || v >= n) {
            return VPDS_ERR_INVALID_ARGUMENT;
        }
        c[k] = (uint64_t)v;
    }
    *tile = tiles_index_of(t, c);
    return VPDS_OK;
}

/* Lower face of tile column c on axis k (c = tiles[k]: the box's upper face). Neighbours
 * share the same expression, hence exactly the same face. */
static double tiles_face(const vpds_tiling *t, int k, uint64_t c)
{
    if (c == 0) return t->lo[k];
    if (c >= t->tiles[k]) return t->hi[k];
    return t->lo[k] + (t->hi[k] - t->lo[k]) * ((double)c / (double)t->tiles[k]);
}

static void tiles_box_of(const vpds_tiling *t, const uint64_t *c, double *lo, double *hi)
{
    int k;
    for (k = 0; k < t->dim; k++) {
        lo[k] = tiles_face(t, k, c[k]);
        hi[k] = tiles_face(t, k, c[k] + 1);
    }
}

vpds_status vpds_tiling_box(const vpds_tiling *t, uint64_t tile, double *lo, double *hi)
{
    uint64_t c[VPDS_MAX_DIM];
    if (!tiles_live(t) || !lo || !hi || tile >= t->count) return VPDS_ERR_INVALID_ARGUMENT;
    tiles_coords_of(t, tile, c);
    tiles_box_of(t, c, lo, hi);
    return VPDS_OK;
}

unsigned vpdsi_tiling_codes(int dim)
{
    unsigned n = 1;
    int k;
    for (k = 0; k < dim; k++) n *= 3;
    return n;
}

/* The neighbour of tile c at offset code (base-3 digits: 0, 1, 2 for -1, 0, +1 per axis):
 * its index and, per axis, -1 / +1 where the step wrapped below / above (its samples then
 * appear shifted by minus / plus one period). 0 for the tile itself or off a closed face. */
static int tiles_neighbour(const vpds_tiling *t, const uint64_t *c, unsigned code, uint64_t *tile,
                           int *wrap)
{
    uint64_t nc[VPDS_MAX_DIM];
    int k, self = 1;
    for (k = 0; k < t->dim; k++, code /= 3) {
        int o = (int)(code % 3) - 1;
        wrap[k] = 0;
        if (o != 0) self = 0;
        if (o < 0 && c[k] == 0) {
            if (!t->periodic[k]) return 0;
            nc[k] = t->tiles[k] - 1;
            wrap[k] = -1;
        } else if (o > 0 && c[k] + 1 == t->tiles[k]) {
            if (!t->periodic[k]) return 0;
            nc[k] = 0;
            wrap[k] = 1;
        } else {
            nc[k] = (uint64_t)((int64_t)c[k] + o);
        }
    }
    if (self) return 0;
    *tile = tiles_index_of(t, nc);
    return 1;
}

static int tiles_cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Sort and drop repeats (two wraps can reach the same tile when an axis has 2 tiles). */
static size_t tiles_unique(uint64_t *v, size_t n)
{
    size_t i, m = 0;
    if (n == 0) return 0;
    qsort(v, n, sizeof *v, tiles_cmp_u64);
    for (i = 1; i < n; i++)
        if (v[i] != v[m]) v[++m] = v[i];
    return m + 1;
}

/* The dependencies of a tile into buf (room for 3^dim - 1), ascending; returns their count. */
size_t vpdsi_tiling_deps_into(const vpds_tiling *t, uint64_t tile, uint64_t *buf)
{
    uint64_t c[VPDS_MAX_DIM], nb, nc[VPDS_MAX_DIM];
    unsigned code, codes = vpdsi_tiling_codes(t->dim);
    int wrap[VPDS_MAX_DIM], phase;
    size_t n = 0;
    tiles_coords_of(t, tile, c);
    phase = tiles_phase_of(t, c);
    for (code = 0; code < codes; code++) {
        if (!tiles_neighbour(t, c, code, &nb, wrap)) continue;
        tiles_coords_of(t, nb, nc);
        if (tiles_phase_of(t, nc) < phase) buf[n++] = nb;
    }
    return tiles_unique(buf, n);
}

vpds_status vpds_tiling_deps(const vpds_tiling *t, uint64_t tile, uint64_t *out, size_t cap, size_t *n)
{
    vpdsi_mem m;
    uint64_t *buf;
    size_t count, bytes;
    if (!tiles_live(t) || !n || tile >= t->count || (cap && !out)) return VPDS_ERR_INVALID_ARGUMENT;
    m = t->mem; /* a copy: the tiling itself stays untouched */
    bytes = (size_t)vpdsi_tiling_codes(t->dim) * sizeof *buf;
    if (!(buf = (uint64_t *)vpdsi_mem_alloc(&m, bytes))) return VPDS_ERR_OUT_OF_MEMORY;
    count = vpdsi_tiling_deps_into(t, tile, buf);
    *n = count;
    if (count > cap) {
        vpdsi_mem_free(&m, buf, bytes);
        return VPDS_ERR_OVERFLOW;
    }
    if (count) memcpy(out, buf, count * sizeof *buf);
    vpdsi_mem_free(&m, buf, bytes);
    return VPDS_OK;
}

typedef struct { uint64_t tile; int phase; } tiles_ranked;

static int tiles_cmp_ranked(const void *a, const void *b)
{
    const tiles_ranked *x = (const tiles_ranked *)a, *y = (const tiles_ranked *)b;
    if (x->phase != y->phase) return x->phase < y->phase ? -1 : 1;
    return x->tile < y->tile ? -1 : x->tile > y->tile;
}

/* The cone on the lifted lattice (no wrap): a chain of dependencies lowers the phase at every
 * step, so it stays within `phase` steps of the tile; marks spread from the tile to lower
 * phases, phase by phase, then project onto tiles (wrapping) and drop repeats. */
vpds_status vpds_tiling_cone(const vpds_tiling *t, uint64_t tile, uint64_t *out, size_t cap, size_t *n)
{
    vpdsi_mem m;
    uint64_t c[VPDS_MAX_DIM], w[VPDS_MAX_DIM], positions = 1, pos, found = 0;
    int64_t first[VPDS_MAX_DIM];
    unsigned codes, code;
    int k, d, ph, q;
    uint8_t *mark;
    tiles_ranked *list;
    size_t i, count;
    if (!tiles_live(t) || !n || tile >= t->count || (cap && !out)) return VPDS_ERR_INVALID_ARGUMENT;
    d = t->dim;
    codes = vpdsi_tiling_codes(d);
    tiles_coords_of(t, tile, c);
    ph = tiles_phase_of(t, c);
    *n = 0;
    if (ph == 0) return VPDS_OK;
    for (k = 0; k < d; k++) {
        int64_t a = (int64_t)c[k] - ph, b = (int64_t)c[k] + ph;
        if (!t->periodic[k]) {
            if (a < 0) a = 0;
            if (b > (int64_t)t->tiles[k] - 1) b = (int64_t)t->tiles[k] - 1;
        }
        first[k] = a;
        w[k] = (uint64_t)(b - a + 1);
        positions *= w[k];
    }
    if (positions > TILES_CONE_MAX_POSITIONS) return VPDS_ERR_OVERFLOW;
    m = t->mem;
    if (!(mark = (uint8_t *)vpdsi_mem_alloc(&m, (size_t)positions))) return VPDS_ERR_OUT_OF_MEMORY;
    memset(mark, 0, (size_t)positions);
    {
        uint64_t centre = 0;
        for (k = 0; k < d; k++) centre = centre * w[k] + (uint64_t)((int64_t)c[k] - first[k]);
        mark[centre] = 1;
    }
    for (q = ph; q >= 1; q--) {
        for (pos = 0; pos < positions; pos++) {
            int64_t lc[VPDS_MAX_DIM];
            uint64_t rest = pos;
            int p = 0;
            if (!mark[pos]) continue;
            for (k = d; k-- > 0;) {
                lc[k] = first[k] + (int64_t)(rest % w[k]);
                rest /= w[k];
                p |= (int)(lc[k] & 1) << k; /* two's complement: the parity of negatives too */
            }
            if (p != q) continue;
            for (code = 0; code < codes; code++) {
                unsigned cc = code;
                uint64_t np = 0;
                int pn = 0, inside = 1, self = 1;
                for (k = 0; k < d; k++, cc /= 3) {
                    int o = (int)(cc % 3) - 1;
                    int64_t v = lc[k] + o;
                    if (o) self = 0;
                    if (v < first[k] || v >= first[k] + (int64_t)w[k]) inside = 0;
                    pn |= (int)(v & 1) << k;
                }
                if (self || !inside || pn >= q) continue;
                for (k = 0, cc = code; k < d; k++, cc /= 3)
                    np = np * w[k] + (uint64_t)(lc[k] + (int)(cc % 3) - 1 - first[k]);
                if (!mark[np]) {
                    mark[np] = 1;
                    found++;
                }
            }
        }
    }
    list = found ? (tiles_ranked *)vpdsi_mem_alloc(&m, (size_t)found * sizeof *list) : NULL;
    if (found && !list) {
        vpdsi_mem_free(&m, mark, (size_t)positions);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (pos = 0, count = 0; pos < positions; pos++) {
        uint64_t rest = pos, tc[VPDS_MAX_DIM];
        int64_t lc;
        if (!mark[pos]) continue;
        for (k = d; k-- > 0;) {
            int64_t nk = (int64_t)t->tiles[k];
            lc = first[k] + (int64_t)(rest % w[k]);
            rest /= w[k];
            lc %= nk;
            if (lc < 0) lc += nk;
            tc[k] = (uint64_t)lc;
        }
        if (tiles_index_of(t, tc) == tile) continue;
        list[count].tile = tiles_index_of(t, tc);
        list[count].phase = tiles_phase_of(t, tc);
        count++;
    }
    vpdsi_mem_free(&m, mark, (size_t)positions);
    if (count) qsort(list, count, sizeof *list, tiles_cmp_ranked);
    for (i = 0, *n = 0; i < count; i++)
        if (i == 0 || list[i].tile != list[i - 1].tile) {
            if (*n < cap) out[*n] = list[i].tile;
            (*n)++;
        }
    if (list) vpdsi_mem_free(&m, list, (size_t)found * sizeof *list);
    return *n > cap ? VPDS_ERR_OVERFLOW : VPDS_OK;
}

/* Squared distance from y to the box [lo, hi]. */
static double tiles_box_dist2(int d, const double *y, const double *lo, const double *hi)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) {
        double g = y[k] < lo[k] ? lo[k] - y[k] : y[k] > hi[k] ? y[k] - hi[k] : 0;
        s += g * g;
    }
    return s;
}

/* The fixed points of a tile: for each dependency (ascending), for each offset that reaches it
 * (ascending code), its samples in their order, shifted by the wrap, kept within the margin.
 * With out NULL only counts. order[j]: which entry of deps holds dependency j. */
static size_t tiles_gather(const vpds_tiling *t, const uint64_t *c, const uint64_t *dep, size_t n_dep,
                           const size_t *order, const vpds_tile_points *deps, const double *lo,
                           const double *hi, double *fx, double *fr)
{
    unsigned codes = vpdsi_tiling_codes(t->dim), code;
    double m2 = t->margin * t->margin, y[VPDS_MAX_DIM];
    size_t j, i, count = 0;
    int d = t->dim, k, wrap[VPDS_MAX_DIM];
    for (j = 0; j < n_dep; j++) {
        const vpds_tile_points *p = &deps[order[j]];
        for (code = 0; code < codes; code++) {
            uint64_t nb;
            if (!tiles_neighbour(t, c, code, &nb, wrap) || nb != dep[j]) continue;
            for (i = 0; i < p->n; i++) {
                for (k = 0; k < d; k++)
                    y[k] = p->x[i * (size_t)d + (size_t)k] + (double)wrap[k] * (t->hi[k] - t->lo[k]);
                if (tiles_box_dist2(d, y, lo, hi) > m2) continue;
                if (fx) {
                    memcpy(fx + count * (size_t)d, y, (size_t)d * sizeof(double));
                    fr[count] = p->r[i];
                }
                count++;
            }
        }
    }
    return count;
}

/* The points of deps[i] as vpds_add_points takes them, named by their place in deps: an infinite
 * coordinate was dropped as out of reach, and a NaN was refused under the index of the tile's
 * own gathered list. */
static vpds_status tiles_check_points(const vpds_tile_points *p, size_t i, int d, char *msg, size_t cap)
{
    size_t q;
    int k;
    for (q = 0; q < p->n; q++) {
        for (k = 0; k < d; k++)
            if (!(fabs(p->x[q * (size_t)d + (size_t)k]) <= VPDSI_MAGNITUDE_MAX))
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "deps[%zu].x[%zu][%d] = %g: the samples of a "
                             "dependency must be finite (within 1e150)", i, q, k, p->x[q * (size_t)d + (size_t)k]);
        if (!vpdsi_radius_ok(p->r[q]))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "deps[%zu].r[%zu] = %g: radii must be finite and > 0 "
                         "(within [1e-100, 1e100])", i, q, p->r[q]);
    }
    return VPDS_OK;
}

/* Which entry of deps is which dependency of the tile (dep, n_dep of them): each exactly once,
 * nothing else; order[j] is the entry holding dep[j]. */
static vpds_status tiles_match_deps(const vpds_tiling *t, uint64_t tile, int phase,
                                    const vpds_tile_points *deps, size_t n_deps,
                                    const uint64_t *dep, size_t n_dep, size_t *order, char *msg,
                                    size_t cap)
{
    size_t i, j;
    for (j = 0; j < n_dep; j++) order[j] = (size_t)-1;
    for (i = 0; i < n_deps; i++) {
        const uint64_t *hit = (const uint64_t *)bsearch(&deps[i].tile, dep, n_dep, sizeof *dep,
                                                        tiles_cmp_u64);
        if (!hit)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "deps[%zu].tile = %llu is not a dependency of "
                         "tile %llu (phase %d; vpds_tiling_deps lists them)", i,
                         (unsigned long long)deps[i].tile, (unsigned long long)tile, phase);
        j = (size_t)(hit - dep);
        if (order[j] != (size_t)-1)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "deps[%zu].tile = %llu repeats deps[%zu]", i,
                         (unsigned long long)deps[i].tile, order[j]);
        if (deps[i].n && (!deps[i].x || !deps[i].r))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "deps[%zu] (tile %llu): x or r is NULL with "
                         "n = %zu", i, (unsigned long long)deps[i].tile, deps[i].n);
        if (tiles_check_points(&deps[i], i, t->dim, msg, cap) != VPDS_OK) return VPDS_ERR_INVALID_ARGUMENT;
        order[j] = i;
    }
    for (j = 0; j < n_dep; j++)
        if (order[j] == (size_t)-1)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tile %llu (phase %d) needs tile %llu (phase %d) "
                         "first: it is missing from deps", (unsigned long long)tile, phase,
                         (unsigned long long)dep[j], vpds_tiling_phase(t, dep[j]));
    return VPDS_OK;
}

/* The sampler of one tile, before its fixed points: the tiling's descriptor on the tile's box
 * and seed, with the whole sizing's bounds and the tiling's scale. */
static vpds_status tiles_sampler(const vpds_tiling *t, uint64_t tile, const double *lo,
                                 const double *hi, const vpds_grid *window,
                                 const vpds_allocator *allocator, vpds_sampler **out,
                                 char *msg, size_t cap)
{
    vpds_desc td = t->desc;
    char inner[400];
    vpds_status st;
    if (allocator) td.allocator = *allocator;
    td.lo = lo;
    td.hi = hi;
    td.seed = vpds_tiling_seed(t, tile);
    if (window) {
        td.sizing_grid = window;
        td.lipschitz = t->lipschitz;
    }
    if ((st = vpds_validate(&td, inner, sizeof inner)) != VPDS_OK)
        VPDSI_REFUSE(st, "tile %llu: %s", (unsigned long long)tile, inner);
    if ((st = vpds_create(&td, out)) != VPDS_OK)
        VPDSI_REFUSE(st, "tile %llu: vpds_create failed (%s)", (unsigned long long)tile,
                     vpds_status_string(st));
    /* every tile sees the whole sizing's bounds, whatever part of it it holds: the same cells
     * and pruning as the batch, and a window gives the points of the whole grid */
    vpdsi_sampler_share_bounds(*out, t->lipschitz, t->rmin, t->rmax);
    if (t->scale != 1.0) vpdsi_sampler_start_at(*out, t->scale);
    return VPDS_OK;
}

/* The dependencies' samples near the tile become its fixed points. */
static vpds_status tiles_add_fixed(const vpds_tiling *t, uint64_t tile, const uint64_t *c,
                                   const uint64_t *dep, size_t n_dep, const size_t *order,
                                   const vpds_tile_points *deps, const double *lo,
                                   const double *hi, const vpdsi_mem *mem, vpds_sampler *s,
                                   size_t *count, char *msg, size_t cap)
{
    vpdsi_mem m = *mem;
    size_t nx = 0, n = tiles_gather(t, c, dep, n_dep, order, deps, lo, hi, NULL, NULL);
    double *fx = NULL, *fr = NULL;
    vpds_status st = VPDS_OK;
    *count = n;
    if (!n) return VPDS_OK;
    if (vpdsi_mul_size(n, (size_t)t->dim, &nx) ||
        !(fx = (double *)vpdsi_mem_alloc(&m, nx * sizeof(double))) ||
        !(fr = (double *)vpdsi_mem_alloc(&m, n * sizeof(double)))) {
        if (msg && cap) snprintf(msg, cap, "out of memory for %zu fixed points of tile %llu", n,
                                 (unsigned long long)tile);
        st = VPDS_ERR_OUT_OF_MEMORY;
    } else {
        tiles_gather(t, c, dep, n_dep, order, deps, lo, hi, fx, fr);
        if ((st = vpds_add_points(s, fx, fr, n)) != VPDS_OK && msg && cap)
            snprintf(msg, cap, "tile %llu: %s", (unsigned long long)tile, vpds_last_error(s));
    }
    if (fx) vpdsi_mem_free(&m, fx, nx * sizeof(double));
    if (fr) vpdsi_mem_free(&m, fr, n * sizeof(double));
    return st;
}

vpds_status vpds_tile_create(const vpds_tiling *t, uint64_t tile, const vpds_tile_points *deps,
                             size_t n_deps, const vpds_grid *window, vpds_sampler **out,
                             size_t *n_fixed, char *msg, size_t cap)
{
    return vpdsi_tile_create(t, tile, deps, n_deps, window, NULL, out, n_fixed, msg, cap);
}

vpds_status vpdsi_tile_create(const vpds_tiling *t, uint64_t tile, const vpds_tile_points *deps,
                              size_t n_deps, const vpds_grid *window,
                              const vpds_allocator *allocator, vpds_sampler **out,
                              size_t *n_fixed, char *msg, size_t cap)
{
    vpdsi_mem m;
    uint64_t c[VPDS_MAX_DIM] = {0}, *dep = NULL;
    size_t *order = NULL, n_dep, count = 0, dep_bytes, order_bytes;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    vpds_sampler *s = NULL;
    vpds_status st = VPDS_OK;
    int phase;
    if (msg && cap) msg[0] = 0;
    if (!out) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (n_fixed) *n_fixed = 0;
    if (!tiles_live(t)) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling is NULL or not a live vpds_tiling");
    if (tile >= t->count)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tile = %llu: the tiling has tiles 0..%llu",
              (unsigned long long)tile, (unsigned long long)(t->count - 1));
    if (n_deps && !deps) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "deps is NULL with n_deps = %zu", n_deps);
    if (t->per_tile && !window)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "sizing_window is NULL: the tiling has sizing_per_tile, each "
              "tile needs its window of the grid");
    if (!t->per_tile && window)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "sizing_window is given but the tiling has no sizing_per_tile");
    if (window && (window->magic != VPDSI_GRID_COOKIE || window->dim != t->dim))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "sizing_window is not a live vpds_grid of dim %d", t->dim);
    tiles_coords_of(t, tile, c);
    phase = tiles_phase_of(t, c);
    tiles_box_of(t, c, lo, hi);
    m = t->mem;
    if (allocator) vpdsi_mem_init(&m, allocator);
    dep_bytes = (size_t)vpdsi_tiling_codes(t->dim) * sizeof *dep;
    order_bytes = (size_t)vpdsi_tiling_codes(t->dim) * sizeof *order;
    dep = (uint64_t *)vpdsi_mem_alloc(&m, dep_bytes);
    order = (size_t *)vpdsi_mem_alloc(&m, order_bytes);
    if (!dep || !order) {
        if (msg && cap) snprintf(msg, cap, "out of memory for the dependencies of tile %llu",
                                 (unsigned long long)tile);
        st = VPDS_ERR_OUT_OF_MEMORY;
        goto done;
    }
    n_dep = vpdsi_tiling_deps_into(t, tile, dep);
    if ((st = tiles_match_deps(t, tile, phase, deps, n_deps, dep, n_dep, order, msg, cap)) != VPDS_OK ||
        (st = tiles_sampler(t, tile, lo, hi, window, allocator, &s, msg, cap)) != VPDS_OK ||
        (st = tiles_add_fixed(t, tile, c, dep, n_dep, order, deps, lo, hi, &m, s, &count, msg,
                              cap)) != VPDS_OK)
        goto done;
    if (n_fixed) *n_fixed = count;
    *out = s;
    s = NULL;
done:
    if (s) vpds_destroy(s);
    if (dep) vpdsi_mem_free(&m, dep, dep_bytes);
    if (order) vpdsi_mem_free(&m, order, order_bytes);
    return st;
}
