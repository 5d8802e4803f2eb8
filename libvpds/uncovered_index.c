/* The uncovered-cell index of two radii (Figure 2): the cells of a level that may hold an
 * uncovered point, their centres in a kd-tree, and from version 4 what the questions learnt
 * about each cell (a witness point, or "covered"), so that a dart asks only about the cells
 * near it and a question answered once is not asked again. */
#include "uncovered.h"
#include "rules.h"
#include "torus.h"
#include <math.h>
#include <string.h>

void vpdsi_uncovered_init(vpdsi_uncovered *u, int dim, const double *period)
{
    memset(u, 0, sizeof *u);
    vpdsi_kd_init(&u->tree, dim);
    vpdsi_kd_set_period(&u->tree, period);
}

void vpdsi_uncovered_release(vpdsi_uncovered *u, vpdsi_mem *m)
{
    vpdsi_mem_free(m, u->flag, u->cap_flag);
    vpdsi_kd_release(&u->tree, m);
    vpdsi_mem_free(m, u->x, u->cap_x * sizeof(double));
    vpdsi_mem_free(m, u->r, u->cap_r * sizeof(double));
    vpdsi_mem_free(m, u->f, u->cap_f);
    vpdsi_mem_free(m, u->lists, u->cap_lists * sizeof(int32_t));
    vpdsi_mem_free(m, u->stack, u->cap_stack * sizeof(double));
    vpdsi_mem_free(m, u->cbox, u->cap_cbox * sizeof(double));
    vpdsi_mem_free(m, u->wit, u->cap_wit * sizeof(double));
    vpdsi_mem_free(m, u->nwit, u->cap_nwit * sizeof(double));
    vpdsi_mem_free(m, u->state, u->cap_state);
    vpdsi_mem_free(m, u->centre_of, u->cap_centre_of * sizeof(int32_t));
    vpdsi_mem_free(m, u->cand, u->cap_cand * sizeof(int32_t));
    vpdsi_mem_free(m, u->grid_cand, u->cap_grid_cand * sizeof(int32_t));
    vpdsi_mem_free(m, u->sub, u->cap_sub * sizeof(uint64_t));
    u->sub = NULL;
    u->cap_sub = 0;
    u->sub_depth = 0;
    u->flag = u->f = u->state = NULL;
    u->x = u->r = u->stack = u->cbox = u->wit = u->nwit = NULL;
    u->lists = u->centre_of = u->cand = u->grid_cand = NULL;
    u->cap_flag = u->cap_x = u->cap_r = u->cap_f = u->cap_lists = u->cap_stack = u->cap_grid_cand = 0;
    u->cap_cbox = u->cap_wit = u->cap_nwit = u->cap_state = u->cap_centre_of = u->cap_cand = 0;
    u->n_nwit = u->n_centre_of = 0;
    u->ready = u->learn = 0;
}

/* Room for the m indexed cells of a level of n cells: centres, and with `learn` what is learnt
 * (learn 2: their covered sub-boxes too). */
static int reserve_index(vpdsi_uncovered *u, vpdsi_mem *mem, int d, size_t m, size_t n, int learn)
{
    size_t nx, nb, nw;
    if (vpdsi_mul_size(m + 1, (size_t)d, &nx) || vpdsi_mul_size(nx, 2, &nb) ||
        vpdsi_mul_size(m + 1, (size_t)d + 1, &nw) ||
        vpdsi_mem_reserve(mem, (void **)&u->x, &u->cap_x, nx, sizeof(double)) ||
        vpdsi_mem_reserve(mem, (void **)&u->r, &u->cap_r, m + 1, sizeof(double)) ||
        vpdsi_mem_reserve(mem, (void **)&u->f, &u->cap_f, m + 1, 1))
        return -1;
    if (!learn) return 0;
    return vpdsi_mem_reserve(mem, (void **)&u->cbox, &u->cap_cbox, nb, sizeof(double)) ||
           vpdsi_mem_reserve(mem, (void **)&u->state, &u->cap_state, m + 1, 1) ||
           vpdsi_mem_reserve(mem, (void **)&u->centre_of, &u->cap_centre_of, n + 1, sizeof(int32_t)) ||
           vpdsi_mem_reserve(mem, (void **)&u->nwit, &u->cap_nwit, nw, sizeof(double)) ||
           (learn > 1 && vpdsi_sub_depth(d) > 0 &&
            vpdsi_mem_reserve(mem, (void **)&u->sub, &u->cap_sub, m + 1, sizeof(uint64_t)));
}

/* Every sub-box of a cell. */
static uint64_t all_sub(const vpdsi_uncovered *u, int d) { return vpdsi_sub_run(d, u->sub_depth, 0); }

vpds_status vpdsi_uncovered_index(vpdsi_uncovered *u, vpdsi_store *st, const vpdsi_cells *next,
                                  const vpdsi_lattice *g, int learn)
{
    int d = g->dim, k;
    size_t i, m = 0, d1 = (size_t)d + 1;
    uint64_t c[VPDS_MAX_DIM];
    vpdsi_kd_samples v;
    u->ready = 0;
    for (i = 0; i < next->count; i++) m += u->flag[i] != 0;
    /* the sweep left one record per flagged cell: they become the cells' witnesses */
    learn = u->n_nwit == m ? learn : 0;
    vpdsi_kd_clear(&u->tree);
    if (reserve_index(u, st->mem, d, m, next->count, learn) ||
        vpdsi_kd_reserve(&u->tree, st->mem, m + 1, m + 1)) {
        vpdsi_store_error(st, "out of memory indexing %zu uncovered cells", m);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    if (learn) { /* the records become wit; the old witnesses' room takes the next records */
        double *w = u->wit;
        size_t cap = u->cap_wit;
        u->wit = u->nwit;
        u->cap_wit = u->cap_nwit;
        u->nwit = w;
        u->cap_nwit = cap;
    }
    u->n_nwit = 0;
    u->learn = learn;
    u->sub_depth = learn > 1 ? vpdsi_sub_depth(d) : 0;
    u->n_centre_of = learn ? next->count : 0;
    u->half = 0;
    v = vpdsi_uncovered_view(u);
    for (i = 0, m = 0; i < next->count; i++) {
        double half2, lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
        if (learn) u->centre_of[i] = u->flag[i] ? (int32_t)m : -1;
        if (!u->flag[i]) continue;
        vpdsi_cells_get(next, i, d, c);
        half2 = 0.25 * vpdsi_lattice_box(g, next->level, c, lo, hi);
        for (k = 0; k < d; k++) u->x[m * (size_t)d + (size_t)k] = 0.5 * (lo[k] + hi[k]);
        if (sqrt(half2) > u->half) u->half = sqrt(half2);
        u->r[m] = 1.0;
        u->f[m] = 0;
        if (learn) {
            memcpy(u->cbox + m * 2 * (size_t)d, lo, (size_t)d * sizeof(double));
            memcpy(u->cbox + m * 2 * (size_t)d + d, hi, (size_t)d * sizeof(double));
            u->state[m] = u->wit[m * d1 + (size_t)d] >= 0 ? VPDSI_CELL_WITNESS : VPDSI_CELL_UNKNOWN;
            if (u->sub_depth > 0) u->sub[m] = 0;
        }
        vpdsi_kd_insert(&u->tree, &v, (int32_t)m);
        m++;
    }
    u->ready = 1;
    return VPDS_OK;
}

int vpdsi_uncovered_reserve_records(vpdsi_uncovered *u, vpdsi_mem *m, int dim, size_t more)
{
    size_t n;
    return vpdsi_mul_size(u->n_nwit + more, (size_t)dim + 1, &n) ||
           vpdsi_mem_reserve(m, (void **)&u->nwit, &u->cap_nwit, n, sizeof(double));
}

void vpdsi_uncovered_record(vpdsi_uncovered *u, int dim, const double *witness)
{
    double *rec = u->nwit + u->n_nwit++ * ((size_t)dim + 1);
    if (witness) {
        memcpy(rec, witness, ((size_t)dim + 1) * sizeof(double));
    } else {
        memset(rec, 0, (size_t)dim * sizeof(double));
        rec[dim] = -1.0; /* none */
    }
}

void vpdsi_uncovered_move(vpdsi_uncovered *u, size_t from, size_t to)
{
    u->flag[to] = u->flag[from];
    if (from < u->n_centre_of) u->centre_of[to] = u->centre_of[from];
}

/* Whether a sample covers the witness w (dim coordinates, then r there) at t * coverage. */
static int witness_covered(const vpdsi_ctx *ctx, double t, const double *w)
{
    vpdsi_kd_samples view = vpdsi_store_view(ctx->st);
    int32_t hit;
    return vpdsi_kd_conflict(&ctx->st->tree, &view, w, w[ctx->pb->dim], (int)ctx->pb->rule,
                             t * ctx->pb->coverage, -1.0, &hit) != -1;
}

/* Cell m's witness, if it still is one (else the cell forgets it). */
static const double *live_witness(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t, int32_t m)
{
    const double *w = u->wit + (size_t)m * ((size_t)ctx->pb->dim + 1);
    if (u->state[m] != VPDSI_CELL_WITNESS) return NULL;
    if (!witness_covered(ctx, t, w)) return w;
    u->state[m] = VPDSI_CELL_UNKNOWN;
    return NULL;
}

int vpdsi_uncovered_child_covered(const vpdsi_uncovered *u, size_t pos, int d, int split, unsigned child)
{
    uint64_t bits;
    int32_t m;
    if (!vpdsi_uncovered_indexed(u, pos) || u->sub_depth == 0) return 0;
    m = u->centre_of[pos];
    if (!split) return u->sub[m] == all_sub(u, d);
    /* child c's sub-boxes start at c times their count */
    bits = vpdsi_sub_run(d, u->sub_depth - 1, child << ((unsigned)d * (unsigned)(u->sub_depth - 1)));
    return (u->sub[m] & bits) == bits;
}

int vpdsi_uncovered_indexed(const vpdsi_uncovered *u, size_t pos)
{
    return u->ready && u->learn && pos < u->n_centre_of && u->centre_of[pos] >= 0;
}

vpds_status vpdsi_uncovered_parent(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t, size_t pos,
                                   int *state, const double **witness)
{
    vpds_status e;
    int32_t m;
    *state = VPDSI_CELL_UNKNOWN;
    *witness = NULL;
    if (!u->ready || !u->learn || pos >= u->n_centre_of) return VPDS_OK;
    m = u->centre_of[pos];
    if (m < 0 || u->state[m] == VPDSI_CELL_COVERED) {
        *state = VPDSI_CELL_COVERED; /* the sweep (or a dart) showed it covered */
        return VPDS_OK;
    }
    if ((e = vpdsi_store_sync_tree(ctx->st)) != VPDS_OK) return e;
    if ((*witness = live_witness(u, ctx, t, m)) != NULL) *state = VPDSI_CELL_WITNESS;
    return VPDS_OK;
}

/* Cell m's box as its image nearest y (dim lows then highs) into box; whether the region of y
 * holds it whole (then a search that finds it covered shows the cell covered). */
static vpds_status cell_image(const vpdsi_uncovered *u, const vpdsi_ctx *ctx, double scale,
                              const double *y, double ry, int32_t m, double *box, int *whole)
{
    const vpdsi_problem *pb = ctx->pb;
    int d = pb->dim, k;
    const double *cb = u->cbox + (size_t)m * 2 * (size_t)d, *c = u->x + (size_t)m * (size_t)d;
    double far2 = 0, diag2 = 0, r_lo = ry, f;
    vpds_status e;
    for (k = 0; k < d; k++) {
        double P = pb->period[k], shift = P > 0 ? P * floor((c[k] - y[k]) / P + 0.5) : 0;
        double a = fabs(y[k] - (cb[k] - shift)), b = fabs(y[k] - (cb[d + k] - shift));
        box[k] = cb[k] - shift;
        box[d + k] = cb[d + k] - shift;
        far2 += a > b ? a * a : b * b;
        diag2 += (cb[d + k] - cb[k]) * (cb[d + k] - cb[k]);
    }
    if (vpdsi_rule_uses_y(pb->rule)) { /* f(ry, r(u)) grows with r(u): bound r below */
        if ((e = vpdsi_store_radius_at(ctx->st, c, &r_lo)) != VPDS_OK) return e;
        r_lo -= ctx->st->sizing.lipschitz * 0.5 * sqrt(diag2);
    }
    f = scale * vpdsi_rule_f(pb->rule, ry, r_lo);
    *whole = r_lo > 0 && far2 <= f * f;
    return VPDS_OK;
}

/* A witness found at y's question: kept, inside the box on a periodic axis, for later ones. */
static void keep_witness(vpdsi_uncovered *u, const vpdsi_ctx *ctx, int32_t m, const double *w)
{
    double *to = u->wit + (size_t)m * ((size_t)ctx->pb->dim + 1);
    memcpy(to, w, ((size_t)ctx->pb->dim + 1) * sizeof(double));
    vpdsi_store_wrap(ctx->st, to);
    u->state[m] = VPDSI_CELL_WITNESS;
}

/* Whether y's region may reach around a periodic axis onto a second image of a cell. */
static int wraps(const vpdsi_uncovered *u, const vpdsi_problem *pb, double reach)
{
    int k;
    for (k = 0; k < pb->dim; k++)
        if (pb->period[k] > 0 && 2 * (reach + 2 * u->half) >= pb->period[k]) return 1;
    return 0;
}

vpds_status vpdsi_uncovered_dart(vpdsi_uncovered *u, const vpdsi_ctx *ctx, double t,
                                 const double *y, double ry, int *accept)
{
    const vpdsi_problem *pb = ctx->pb;
    int d = pb->dim;
    double scale = t * pb->coverage, reach, wbuf[VPDS_MAX_DIM + 1], box[2 * VPDS_MAX_DIM];
    size_t n = 0, i;
    uint64_t boxes0 = u->boxes;
    vpdsi_kd_samples v = vpdsi_uncovered_view(u);
    vpds_status e;
    *accept = 0;
    reach = vpdsi_rule_reach(pb->rule, scale, ctx->st->sizing.lipschitz, ry);
    if (!(scale * ctx->st->sizing.lipschitz < 1)) return vpdsi_uncovered_in(u, ctx, t, y, y, ry, accept);
    if ((e = vpdsi_store_sync_tree(ctx->st)) != VPDS_OK) return e;
    if (!u->ready || !u->learn || wraps(u, pb, reach)) return vpdsi_uncovered_in(u, ctx, t, y, y, ry, accept);
    if (vpdsi_kd_radius(&u->tree, &v, y, reach + u->half, ctx->st->mem, &u->cand, &n, &u->cap_cand)) {
        vpdsi_store_error(ctx->st, "out of memory listing the uncovered cells near a dart");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (i = 0; i < n; i++) { /* a witness already known inside the region answers at once */
        const double *w = live_witness(u, ctx, t, u->cand[i]);
        double f = w ? scale * vpdsi_rule_f(pb->rule, ry, w[d]) : 0;
        if (w && vpdsi_torus_dist2(w, y, d, pb->period) <= f * f) {
            *accept = 1;
            return VPDS_OK;
        }
    }
    for (i = 0; i < n; i++) {
        int32_t m = u->cand[i];
        int whole, found;
        vpdsi_search_out out;
        uint64_t used = u->boxes - boxes0;
        if (u->state[m] == VPDSI_CELL_COVERED) continue;
        if ((e = cell_image(u, ctx, scale, y, ry, m, box, &whole)) != VPDS_OK) return e;
        memset(&out, 0, sizeof out);
        out.budget = used < VPDSI_UNCOVERED_BUDGET ? (size_t)(VPDSI_UNCOVERED_BUDGET - used) : 0;
        out.witness = wbuf;
        if (u->sub_depth > 0) {
            out.sub = u->sub + m;
            out.sub_depth = u->sub_depth;
        }
        if ((e = vpdsi_uncovered_in_box(u, ctx, t, y, y, ry, box, &out, &found)) != VPDS_OK) return e;
        if (found) { /* a witness, or the budget spent: "uncovered", as the whole search says */
            if (out.found_point) keep_witness(u, ctx, m, wbuf);
            *accept = 1;
            return VPDS_OK;
        }
        if (whole || (u->sub_depth > 0 && u->sub[m] == all_sub(u, d))) {
            /* covered now, so at every later question of this scale */
            u->state[m] = VPDSI_CELL_COVERED;
            u->r[m] = 0.0;
        }
    }
    return VPDS_OK;
}
