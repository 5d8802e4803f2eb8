#include "store.h"
#include "torus.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void vpdsi_store_init(vpdsi_store *st, vpdsi_mem *mem, int dim, const double *lo,
                      const double *hi, const double *period)
{
    int k;
    memset(st, 0, sizeof *st);
    st->mem = mem;
    st->dim = dim;
    for (k = 0; k < dim; k++) {
        st->lo[k] = lo[k];
        st->hi[k] = hi[k];
        st->period[k] = period ? period[k] : 0.0;
    }
    st->sizing.dim = dim;
    vpdsi_kd_init(&st->tree, dim);
    vpdsi_kd_set_period(&st->tree, st->period);
}

void vpdsi_store_release(vpdsi_store *st)
{
    vpdsi_mem *m = st->mem;
    vpdsi_bgrid_release(&st->grid, m);
    vpdsi_ogrid_release(&st->ogrid, m);
    vpdsi_kd_release(&st->tree, m);
    vpdsi_mem_free(m, st->x, st->cap_x * sizeof(double));
    vpdsi_mem_free(m, st->r, st->cap_r * sizeof(double));
    vpdsi_mem_free(m, st->t, st->cap_t * sizeof(double));
    vpdsi_mem_free(m, st->flags, st->cap_flags);
    if (st->sizing.grid) vpds_grid_destroy(st->sizing.grid);
    st->x = st->r = st->t = NULL;
    st->flags = NULL;
    st->sizing.grid = NULL;
    st->n = st->n_fixed = st->tree_n = 0;
}

void vpdsi_store_error(vpdsi_store *st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(st->err, sizeof st->err, fmt, ap);
    va_end(ap);
}

vpdsi_kd_samples vpdsi_store_view(const vpdsi_store *st)
{
    vpdsi_kd_samples v;
    v.x = st->x;
    v.r = st->r;
    v.flags = st->flags;
    return v;
}

void vpdsi_store_wrap(const vpdsi_store *st, double *x)
{
    int k;
    for (k = 0; k < st->dim; k++) {
        double P = st->period[k];
        if (P > 0 && (x[k] < st->lo[k] || x[k] >= st->hi[k])) {
            x[k] = st->lo[k] + fmod(x[k] - st->lo[k], P);
            if (x[k] < st->lo[k]) x[k] += P;
            if (x[k] >= st->hi[k]) x[k] = st->lo[k];
        }
    }
}

vpds_status vpdsi_store_radius_at(vpdsi_store *st, const double *p, double *r)
{
    double q[VPDS_MAX_DIM];
    if (st->sizing.kind == VPDSI_SIZING_CONSTANT) {
        *r = st->sizing.radius;
        return VPDS_OK;
    }
    memcpy(q, p, (size_t)st->dim * sizeof(double));
    vpdsi_store_wrap(st, q);
    return vpdsi_sizing_eval(&st->sizing, q, 1, r, st->err, sizeof st->err);
}

vpds_status vpdsi_store_radii(vpdsi_store *st, const double *x, size_t n, double *out)
{
    return vpdsi_sizing_eval(&st->sizing, x, n, out, st->err, sizeof st->err);
}

/* Room for `more` samples; the kd-tree's too when `index` (it keeps up with the samples). */
static vpds_status store_reserve(vpdsi_store *st, size_t more, int index)
{
    size_t need = st->n + more, want, nx;
    vpdsi_mem *m = st->mem;
    if (need < st->n || need > (size_t)INT32_MAX || vpdsi_mul_size(need, (size_t)st->dim, &nx)) {
        vpdsi_store_error(st, "%zu samples would overflow the sample index (at most %d)", need,
                          INT32_MAX);
        return VPDS_ERR_OVERFLOW;
    }
    want = need <= st->expect ? st->expect : need; /* the expected count in one allocation */
    if (want != need) nx = want * (size_t)st->dim; /* expect <= VPDSI_STORE_EXPECT_MAX */
    /* the arrays grow in small steps: a run whose count is not expected up front (a variable
     * radius) holds their unused room at its peak */
    if (vpdsi_mem_reserve_fine(m, (void **)&st->x, &st->cap_x, nx, sizeof(double)) ||
        vpdsi_mem_reserve_fine(m, (void **)&st->r, &st->cap_r, want, sizeof(double)) ||
        vpdsi_mem_reserve_fine(m, (void **)&st->t, &st->cap_t, want, sizeof(double)) ||
        vpdsi_mem_reserve_fine(m, (void **)&st->flags, &st->cap_flags, want, 1) ||
        (index && !st->grid_mode && !st->ogrid_mode &&
         vpdsi_kd_reserve(&st->tree, m, need, need - st->tree_n)) ||
        (st->ogrid_mode && vpdsi_ogrid_reserve(&st->ogrid, m, need, more))) {
        vpdsi_store_error(st, "out of memory for %zu samples", need);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

vpds_status vpdsi_store_reserve(vpdsi_store *st, size_t more)
{
    return store_reserve(st, more, 1);
}

vpds_status vpdsi_store_reserve_lagging(vpdsi_store *st, size_t more)
{
    return store_reserve(st, more, 0);
}

/* Samples the tree takes per reserve: an insert may split a leaf (two nodes), so a reserve
 * for all the samples a lagging tree takes at once held up to two nodes per sample where the
 * tree ends with about one per three (a domain's tree lags a whole level: 59 B/sample of a 2D
 * annulus run went to unused nodes). The same inserts in the same order: the same tree. */
#define SYNC_BATCH 4096

vpds_status vpdsi_store_sync_tree(vpdsi_store *st)
{
    vpdsi_kd_samples v = vpdsi_store_view(st);
    while (st->tree_n < st->n) {
        size_t batch = st->n - st->tree_n < SYNC_BATCH ? st->n - st->tree_n : SYNC_BATCH, j;
        if (vpdsi_kd_reserve(&st->tree, st->mem, st->n, batch)) {
            vpdsi_store_error(st, "out of memory indexing %zu samples", st->n);
            return VPDS_ERR_OUT_OF_MEMORY; /* the samples indexed so far stay: a retry goes on */
        }
        for (j = 0; j < batch; j++) vpdsi_kd_insert(&st->tree, &v, (int32_t)st->tree_n++);
    }
    return VPDS_OK;
}

vpds_status vpdsi_store_use_tree(vpdsi_store *st)
{
    vpds_status e = vpdsi_store_sync_tree(st);
    if (e != VPDS_OK) return e;
    vpdsi_store_drop_index(st);
    return VPDS_OK;
}

void vpdsi_store_drop_index(vpdsi_store *st)
{
    if (st->grid_mode) vpdsi_bgrid_release(&st->grid, st->mem);
    if (st->ogrid_mode) vpdsi_ogrid_release(&st->ogrid, st->mem);
    st->grid_mode = st->ogrid_mode = 0;
}

vpds_status vpdsi_store_use_ogrid(vpdsi_store *st, double top, double bottom, double dense_cells)
{
    vpdsi_kd_samples v = vpdsi_store_view(st);
    size_t i;
    int fit;
    vpdsi_store_drop_index(st);
    if ((fit = vpdsi_ogrid_setup(&st->ogrid, st->dim, st->lo, st->hi, top, bottom, dense_cells)) == -2)
        return vpdsi_store_sync_tree(st); /* too wide for the grid's cells: the kd-tree serves */
    if (fit) {
        vpdsi_store_error(st, "the octave grid holds dim <= 3, not %d", st->dim);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (vpdsi_ogrid_reserve(&st->ogrid, st->mem, st->n, st->n)) {
        vpdsi_ogrid_release(&st->ogrid, st->mem);
        vpdsi_store_error(st, "out of memory indexing %zu samples", st->n);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (i = 0; i < st->n; i++) vpdsi_ogrid_insert(&st->ogrid, &v, (int32_t)i);
    st->ogrid_mode = 1;
    return VPDS_OK;
}

int32_t vpdsi_store_conflict(const vpdsi_store *st, const double *y, double ry, int rule,
                             double scale, double lipschitz, int32_t *witness)
{
    vpdsi_kd_samples v = vpdsi_store_view(st);
    if (st->ogrid_mode)
        return vpdsi_ogrid_conflict(&st->ogrid, &v, y, ry, rule, scale, lipschitz, witness);
    return vpdsi_kd_conflict(&st->tree, &v, y, ry, rule, scale, lipschitz, witness);
}

void vpdsi_store_prefetch(const vpdsi_store *st, const double *y, double ry, int stage)
{
    if (st->ogrid_mode) {
        vpdsi_kd_samples v = vpdsi_store_view(st);
        vpdsi_ogrid_prefetch(&st->ogrid, &v, y, ry, stage);
    }
}

int vpdsi_store_gather(const vpdsi_store *st, const double *lo, const double *hi, double r_hi,
                       int rule, double scale, int split, int32_t **out, size_t *count,
                       size_t *cap)
{
    vpdsi_kd_samples v = vpdsi_store_view(st);
    if (st->ogrid_mode)
        return vpdsi_ogrid_gather(&st->ogrid, &v, lo, hi, r_hi, rule, scale, split, st->mem, out,
                                  count, cap);
    return vpdsi_kd_gather(&st->tree, &v, lo, hi, r_hi, rule, scale, split, st->mem, out, count,
                           cap);
}

vpds_status vpdsi_store_near_box(vpdsi_store *st, const double *lo, const double *hi, double r_bound,
                                 double scale, int32_t **out, size_t *count, size_t *cap)
{
    vpdsi_kd_samples v = vpdsi_store_view(st);
    int e = st->ogrid_mode
                ? vpdsi_ogrid_near_box(&st->ogrid, &v, lo, hi, r_bound, scale, st->mem, out, count, cap)
                : vpdsi_kd_near_box(&st->tree, &v, lo, hi, r_bound, scale, 0, SIZE_MAX, st->mem, out,
                                    count, cap);
    if (e < 0) {
        vpdsi_store_error(st, "out of memory for a list of %zu samples near a box", *count);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

void vpdsi_store_append(vpdsi_store *st, const double *x, double r, double t, uint8_t flags)
{
    memcpy(st->x + st->n * (size_t)st->dim, x, (size_t)st->dim * sizeof(double));
    st->r[st->n] = r;
    st->t[st->n] = t;
    st->flags[st->n] = flags;
    st->n++;
    if (st->grid_mode) {
        st->grid.cell[vpdsi_bgrid_locate(&st->grid, x)] = (int32_t)(st->n - 1);
    } else if (st->ogrid_mode) {
        vpdsi_kd_samples v = vpdsi_store_view(st);
        vpdsi_ogrid_insert(&st->ogrid, &v, (int32_t)(st->n - 1));
    } else if (st->tree_n + 1 == st->n) { /* a lagging tree stays behind until synced */
        vpdsi_kd_samples v = vpdsi_store_view(st);
        vpdsi_kd_insert(&st->tree, &v, (int32_t)(st->n - 1));
        st->tree_n = st->n;
    }
}

void vpdsi_store_append_lagging(vpdsi_store *st, const double *x, double r, double t, uint8_t flags)
{
    memcpy(st->x + st->n * (size_t)st->dim, x, (size_t)st->dim * sizeof(double));
    st->r[st->n] = r;
    st->t[st->n] = t;
    st->flags[st->n] = flags;
    st->n++;
}

int vpdsi_store_has_samples(const vpdsi_store *st)
{
    size_t i;
    for (i = 0; i < st->n; i++)
        if (!(st->flags[i] & VPDSI_SAMPLE_FIXED)) return 1;
    return 0;
}

/* A step coprime with n near n / phi: sorted input then cannot make the kd-tree a list. */
static size_t scatter_step(size_t n)
{
    size_t step = n > 2 ? (size_t)(0.6180339887498949 * (double)n) | 1u : 1;
    while (n > 2 && step > 1) {
        size_t a = n, b = step;
        while (b) { size_t tmp = a % b; a = b; b = tmp; }
        if (a == 1) break;
        step += 2;
    }
    return step;
}

vpds_status vpdsi_store_add_fixed(vpdsi_store *st, const double *x, const double *r, size_t n)
{
    size_t i, pos, step, first = st->n, dim = (size_t)st->dim;
    double *radii = NULL;
    vpdsi_kd_samples v;
    vpds_status e;
    /* fixed points may share cells and carry other radii: the kd-tree takes over (until a run's
     * set-up finds they fit the background grid), and it must first hold every sample (it lags
     * after a run on the background grid) */
    if ((e = vpdsi_store_use_tree(st)) != VPDS_OK) return e;
    if ((e = vpdsi_store_reserve(st, n)) != VPDS_OK) return e;
    if (!r) {
        /* every radius first, so that a bad one leaves the store unchanged */
        if (!(radii = (double *)vpdsi_mem_alloc(st->mem, n * sizeof(double)))) {
            vpdsi_store_error(st, "out of memory for %zu radii", n);
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        if ((e = vpdsi_store_radii(st, x, n, radii)) != VPDS_OK) {
            vpdsi_mem_free(st->mem, radii, n * sizeof(double));
            return e;
        }
    }
    for (i = 0; i < n; i++) {
        double *xi = st->x + (first + i) * dim;
        memcpy(xi, x + i * dim, dim * sizeof(double));
        vpdsi_store_wrap(st, xi); /* on a periodic axis: its image inside the box */
        st->r[first + i] = r ? r[i] : radii[i];
        st->t[first + i] = INFINITY;
        st->flags[first + i] = (uint8_t)(VPDSI_SAMPLE_FIXED | (r ? VPDSI_SAMPLE_OWN_RADIUS : 0u));
    }
    if (radii) vpdsi_mem_free(st->mem, radii, n * sizeof(double));
    st->n += n;
    v = vpdsi_store_view(st);
    step = scatter_step(n);
    for (i = 0, pos = 0; i < n; i++, pos = (pos + step) % n)
        vpdsi_kd_insert(&st->tree, &v, (int32_t)(first + pos));
    st->tree_n = st->n;
    st->n_fixed += n;
    return VPDS_OK;
}

/* The dart y of radius ry met sample i whose radius breaks the sizing's L. */
vpds_status vpdsi_store_lipschitz_broken(vpdsi_store *st, const double *y, double ry, int32_t i)
{
    char py[256], px[256];
    const double *x = st->x + (size_t)i * (size_t)st->dim;
    /* the distance the check read: across the wrap on a periodic axis */
    double dist = sqrt(vpdsi_torus_dist2(y, x, st->dim, st->period));
    vpdsi_format_point(py, sizeof py, y, st->dim);
    vpdsi_format_point(px, sizeof px, x, st->dim);
    vpdsi_store_error(st, "sizing breaks lipschitz = %g: r = %.17g at (%s) and r = %.17g at (%s), "
                      "distance %.17g, slope %.17g", st->sizing.lipschitz, ry, py, st->r[i], px,
                      dist, fabs(ry - st->r[i]) / dist);
    return VPDS_ERR_LIPSCHITZ;
}
