#include "bgrid.h"
#include <math.h>
#include <string.h>

void vpdsi_bgrid_release(vpdsi_bgrid *g, vpdsi_mem *m)
{
    vpdsi_mem_free(m, g->cell, g->cap_cell * sizeof *g->cell);
    vpdsi_mem_free(m, g->stencil, g->cap_stencil * sizeof *g->stencil);
    vpdsi_mem_free(m, g->stencil_tag, g->cap_stencil_tag * sizeof *g->stencil_tag);
    vpdsi_mem_free(m, g->row, g->cap_row * sizeof *g->row);
    vpdsi_mem_free(m, g->row_w, g->cap_row_w * sizeof *g->row_w);
    memset(g, 0, sizeof *g);
}

typedef struct {
    int64_t offset;
    double d2;
    int o0, w; /* its axis-0 offset, its row's width (row_width) */
} stencil_entry;

/* The stencil's reach in cells: the border's width (0: too wide for this grid). */
static uint64_t span_of(int dim, const double *side, double reach)
{
    uint64_t span = 0;
    int k;
    for (k = 0; k < dim; k++) {
        uint64_t sk = (uint64_t)floor(reach / side[k]) + 1;
        if (sk > 8) return 0; /* not the grid this path is for */
        if (sk > span) span = sk;
    }
    return span;
}

double vpdsi_bgrid_cells(int dim, const double *n, const double *side, double reach)
{
    double total = 1, span = (double)span_of(dim, side, reach);
    int k;
    if (span == 0) return 0;
    for (k = 0; k < dim; k++) total *= n[k] + 2 * span;
    return total;
}

/* Whether the cell at offsets o lies within reach of the centre cell (the centre itself too),
 * with a margin for the rounding of a point's cell index: the stencil's test, and its rows'. */
static int in_stencil(int dim, const double *side, double reach, const int *o)
{
    double d2 = 0;
    int k;
    for (k = 0; k < dim; k++) {
        int a = o[k] < 0 ? -o[k] : o[k];
        double gap = a > 1 ? (a - 1) * side[k] : 0;
        d2 += gap * gap;
    }
    return d2 < reach * reach * (1 + 1e-6);
}

/* The largest axis-0 offset of a stencil cell in the row through o (o[0] ignored); -1: none.
 * The row holds exactly the offsets -w..w: the gap only grows with |o0|. */
static int row_width(int dim, const double *side, double reach, uint64_t span, const int *o)
{
    int t[VPDS_MAX_DIM], w = -1, a;
    memcpy(t, o, (size_t)dim * sizeof *t);
    for (a = 0; a <= (int)span; a++) {
        t[0] = a;
        if (!in_stencil(dim, side, reach, t)) break;
        w = a;
    }
    return w;
}

/* The rows of the stencil (vpdsi_bgrid_slide) and the centre's tag. */
static int setup_rows(vpdsi_bgrid *g, vpdsi_mem *m, const double *side, double reach)
{
    int o[VPDS_MAX_DIM], k, d = g->dim, zero[VPDS_MAX_DIM] = {0};
    size_t rows = 0;
    int64_t span = (int64_t)g->pad;
    g->own_tag = VPDSI_BGRID_TAG(0, row_width(d, side, reach, g->pad, zero));
    o[0] = 0;
    for (k = 1; k < d; k++) o[k] = -(int)span;
    for (;;) {
        int w = row_width(d, side, reach, g->pad, o);
        if (w >= 0) {
            int64_t off = 0;
            if (vpdsi_mem_reserve(m, (void **)&g->row, &g->cap_row, rows + 1, sizeof *g->row) ||
                vpdsi_mem_reserve(m, (void **)&g->row_w, &g->cap_row_w, rows + 1, sizeof *g->row_w))
                return -1;
            for (k = 1; k < d; k++) off += (int64_t)o[k] * (int64_t)g->stride[k];
            g->row[rows] = off;
            g->row_w[rows] = w;
            rows++;
        }
        for (k = 1; k < d; k++) {
            if (++o[k] <= (int)span) break;
            o[k] = -(int)span;
        }
        if (k >= d) break;
    }
    g->n_rows = rows;
    return 0;
}

int vpdsi_bgrid_setup(vpdsi_bgrid *g, vpdsi_mem *m, int dim, const uint64_t *n, const double *lo,
                      const double *side, double reach)
{
    uint64_t total = 1, span = span_of(dim, side, reach);
    int k, o[VPDS_MAX_DIM];
    size_t count = 0, i, j, cap_tmp = 0;
    stencil_entry *tmp = NULL;
    vpdsi_bgrid_release(g, m);
    if (span == 0) return -1;
    for (k = 0; k < dim; k++) {
        g->stride[k] = total;
        if (n[k] + 2 * span > ((uint64_t)INT32_MAX) / total) return -1;
        total *= n[k] + 2 * span;
    }
    g->dim = dim;
    g->pad = span;
    g->origin = 0;
    for (k = 0; k < dim; k++) {
        g->n[k] = n[k];
        g->lo[k] = lo[k];
        g->side[k] = side[k];
        g->origin += span * g->stride[k];
    }
    /* stencil: offsets whose cells come within reach of the centre cell, with a margin for the
     * rounding of a point's cell index */
    for (k = 0; k < dim; k++) o[k] = -(int)span;
    for (;;) {
        int zero = 1;
        int64_t off = 0;
        for (k = 0; k < dim; k++) {
            if (o[k]) zero = 0;
            off += (int64_t)o[k] * (int64_t)g->stride[k];
        }
        if (!zero && in_stencil(dim, side, reach, o)) {
            double c2 = 0;
            if (vpdsi_mem_reserve(m, (void **)&tmp, &cap_tmp, count + 1, sizeof *tmp)) goto oom;
            for (k = 0; k < dim; k++) c2 += (double)o[k] * o[k] * side[k] * side[k];
            tmp[count].offset = off;
            tmp[count].d2 = c2;
            tmp[count].o0 = o[0];
            tmp[count].w = row_width(dim, side, reach, span, o);
            count++;
        }
        for (k = 0; k < dim; k++) {
            if (++o[k] <= (int)span) break;
            o[k] = -(int)span;
        }
        if (k == dim) break;
    }
    /* nearest first, so a conflict is usually found at the first look (insertion sort: small) */
    for (i = 1; i < count; i++) {
        stencil_entry e = tmp[i];
        for (j = i; j > 0 && (tmp[j - 1].d2 > e.d2 || (tmp[j - 1].d2 == e.d2 && tmp[j - 1].offset > e.offset)); j--)
            tmp[j] = tmp[j - 1];
        tmp[j] = e;
    }
    if (vpdsi_mem_reserve(m, (void **)&g->stencil, &g->cap_stencil, count, sizeof *g->stencil) ||
        vpdsi_mem_reserve(m, (void **)&g->stencil_tag, &g->cap_stencil_tag, count,
                          sizeof *g->stencil_tag) ||
        vpdsi_mem_reserve(m, (void **)&g->cell, &g->cap_cell, (size_t)total, sizeof *g->cell) ||
        setup_rows(g, m, side, reach))
        goto oom;
    for (i = 0; i < count; i++) {
        g->stencil[i] = tmp[i].offset;
        g->stencil_tag[i] = VPDSI_BGRID_TAG(tmp[i].o0, tmp[i].w);
    }
    vpdsi_mem_free(m, tmp, cap_tmp * sizeof *tmp);
    for (i = 0; i < (size_t)total; i++) g->cell[i] = -1;
    g->n_stencil = count;
    g->count = (size_t)total;
    return 0;
oom:
    vpdsi_mem_free(m, tmp, cap_tmp * sizeof *tmp);
    vpdsi_bgrid_release(g, m);
    return -2;
}

uint64_t vpdsi_bgrid_locate(const vpdsi_bgrid *g, const double *x)
{
    uint64_t idx = g->origin;
    int k;
    for (k = 0; k < g->dim; k++) {
        double u = floor((x[k] - g->lo[k]) / g->side[k]);
        uint64_t ck = u <= 0 ? 0 : (uint64_t)u;
        if (ck >= g->n[k]) ck = g->n[k] - 1;
        idx += ck * g->stride[k];
    }
    return idx;
}

int vpdsi_bgrid_place(vpdsi_bgrid *g, const double *x, const double *box_lo, const double *box_hi,
                      int32_t i)
{
    uint64_t idx = g->origin;
    int k;
    for (k = 0; k < g->dim; k++) {
        double u = floor((x[k] - g->lo[k]) / g->side[k]), n = (double)g->n[k], pad = (double)g->pad;
        if (x[k] >= box_lo[k] && x[k] <= box_hi[k]) {
            u = u < 0 ? 0 : u >= n ? n - 1 : u; /* vpdsi_bgrid_locate's cell */
        } else {
            /* a point beyond a face lies in a border cell past that face, never inside */
            if (x[k] < box_lo[k] && u > -1) u = -1;
            if (x[k] > box_hi[k] && u < n) u = n;
            if (!(u >= -pad && u < n + pad)) return 0;
        }
        idx = (uint64_t)((int64_t)idx + (int64_t)u * (int64_t)g->stride[k]);
    }
    if (g->cell[idx] >= 0) return -1;
    g->cell[idx] = i;
    return 0;
}

uint64_t vpdsi_bgrid_index(const vpdsi_bgrid *g, const uint64_t *c)
{
    uint64_t idx = g->origin;
    int k;
    for (k = 0; k < g->dim; k++) idx += c[k] * g->stride[k];
    return idx;
}

size_t vpdsi_bgrid_near(const vpdsi_bgrid *g, uint64_t at, int32_t *out)
{
    const int32_t *cell = g->cell + at;
    size_t found = 0, j;
    if (cell[0] >= 0) out[found++] = cell[0];
    for (j = 0; j < g->n_stencil; j++) {
        int32_t i = cell[g->stencil[j]];
        if (i >= 0) out[found++] = i;
    }
    return found;
}

#ifndef BGRID_PREFETCH_SAMPLES
#define BGRID_PREFETCH_SAMPLES 2 /* the nearest samples whose points stage 1 asks for */
#endif

void vpdsi_bgrid_prefetch(const vpdsi_bgrid *g, const double *x, uint64_t at, int stage)
{
    const int32_t *cell = g->cell + at;
    int64_t w = (int64_t)g->pad, a;
    size_t j, asked = 0;
    if (g->dim != 2) return;
    if (stage == 0) { /* each row along axis 0, its two ends (it may cross a cache line) */
        for (a = -w; a <= w; a++) {
            VPDSI_PREFETCH(cell + a * (int64_t)g->stride[1] - w);
            VPDSI_PREFETCH(cell + a * (int64_t)g->stride[1] + w);
        }
        return;
    }
    if (cell[0] >= 0) return; /* the test ends there without a point */
    for (j = 0; j < g->n_stencil && asked < BGRID_PREFETCH_SAMPLES; j++) {
        int32_t i = cell[g->stencil[j]];
        if (i >= 0) {
            VPDSI_PREFETCH(x + 2 * (size_t)i);
            asked++;
        }
    }
}

/* d coordinates, forwards (a library call per point cost 15% of a 2D run) */
static void copy_point(double *to, const double *from, size_t d)
{
    size_t k;
    for (k = 0; k < d; k++) to[k] = from[k];
}

size_t vpdsi_bgrid_near_packed(const vpdsi_bgrid *g, const double *x, uint64_t at, int32_t *out,
                               double *px, uint16_t *tag)
{
    const int32_t *cell = g->cell + at;
    size_t found = 0, j, d = (size_t)g->dim;
    if (cell[0] >= 0) {
        tag[found] = g->own_tag;
        out[found++] = cell[0];
    }
    for (j = 0; j < g->n_stencil; j++) {
        int32_t i = cell[g->stencil[j]];
        if (i >= 0) {
            tag[found] = g->stencil_tag[j];
            out[found++] = i;
        }
    }
    for (j = 0; j < found; j++) copy_point(px + j * d, x + (size_t)out[j] * d, d);
    return found;
}

size_t vpdsi_bgrid_slide(const vpdsi_bgrid *g, const double *x, uint64_t at, int32_t *out,
                         double *px, uint16_t *tag, size_t n)
{
    size_t kept = 0, j, r, d = (size_t)g->dim;
    for (j = 0; j < n; j++) { /* one cell further back: the trailing ones leave */
        int o0 = VPDSI_BGRID_TAG_O0(tag[j]) - 1, w = VPDSI_BGRID_TAG_W(tag[j]);
        if (o0 < -w) continue;
        out[kept] = out[j];
        tag[kept] = VPDSI_BGRID_TAG(o0, w);
        if (kept != j) copy_point(px + kept * d, px + j * d, d); /* kept < j: forwards is safe */
        kept++;
    }
    for (r = 0; r < g->n_rows; r++) { /* each row's leading cell comes in */
        int32_t i = g->cell[(int64_t)at + g->row[r] + g->row_w[r]];
        if (i < 0) continue;
        out[kept] = i;
        tag[kept] = VPDSI_BGRID_TAG(g->row_w[r], g->row_w[r]);
        copy_point(px + kept * d, x + (size_t)i * d, d);
        kept++;
    }
    return kept;
}

void vpdsi_bgrid_prefetch_slide(const vpdsi_bgrid *g, const double *x, uint64_t at)
{
    size_t r, d = (size_t)g->dim;
    for (r = 0; r < g->n_rows; r++) {
        int32_t i = g->cell[(int64_t)at + g->row[r] + g->row_w[r]];
        if (i >= 0) VPDSI_PREFETCH(x + (size_t)i * d);
    }
}

int32_t vpdsi_bgrid_conflict(const vpdsi_bgrid *g, const double *x, uint64_t at, const double *y, double reach)
{
    const int32_t *cell = g->cell + at;
    double reach2 = reach * reach;
    size_t j;
    int k, d = g->dim;
    if (cell[0] >= 0) return cell[0]; /* a cell holds one sample: any other point conflicts */
    for (j = 0; j < g->n_stencil; j++) {
        int32_t i = cell[g->stencil[j]];
        if (i >= 0) {
            const double *xi = x + (size_t)i * (size_t)d;
            double d2 = 0;
            for (k = 0; k < d; k++) d2 += (y[k] - xi[k]) * (y[k] - xi[k]);
            if (d2 < reach2) return i;
        }
    }
    return -1;
}
