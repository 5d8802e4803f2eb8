/* Built-in domain: a mask of cells over the box. Its signed distance is (d_in - d_out) / 2 at
 * the cell centres, d_in and d_out the exact Euclidean distances to the nearest inside and
 * outside centre (Felzenszwalb-Huttenlocher, one axis at a time); both are 1-Lipschitz, so
 * their half difference is too, and it is -h/2 and +h/2 across a boundary of cells h apart.
 * The multilinear interpolant between centres (the grid sizing's) can be up to sqrt(d) times
 * steeper; its exact constant L is computed and the values divided by it when above 1. */
#include "mask.h"
#include "grid.h"
#include "refuse.h"
#include "sizing.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

#define VPDSI_MASK_COOKIE 0x5650534bu /* 'VPSK' */

struct vpds_mask {
    uint32_t magic;
    vpds_grid *grid; /* the signed distances at the cell centres */
    double scale;    /* 1 / max(1, L of the interpolant) */
    vpdsi_mem mem;
};

vpds_mask_desc vpds_default_mask_desc(void)
{
    vpds_mask_desc d;
    memset(&d, 0, sizeof d);
    d.cookie = VPDSI_MASK_COOKIE;
    d.struct_size = (uint32_t)sizeof d;
    d.dim = 2;
    d.threshold = 0.5;
    return d;
}


vpds_status vpds_mask_validate(const vpds_mask_desc *d, char *msg, size_t cap)
{
    size_t n = 1, k, i, inside = 0;
    if (msg && cap) msg[0] = 0;
    if (!d) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc is NULL");
    if (d->cookie != VPDSI_MASK_COOKIE)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "mask desc: cookie 0x%08x is not from vpds_default_mask_desc()",
             (unsigned)d->cookie);
    if (d->struct_size != sizeof *d)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "mask desc: struct_size %u, this library reads %u",
             (unsigned)d->struct_size, (unsigned)sizeof *d);
    if (d->dim < 1 || d->dim > VPDS_MAX_DIM)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: dim = %d, must be in 1..%d", d->dim, VPDS_MAX_DIM);
    if (!d->shape || !d->values) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: shape or values is NULL");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: allocator.alloc and allocator.free must both be "
             "set or both NULL");
    if (!isfinite(d->threshold))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: threshold = %g, must be finite", d->threshold);
    for (k = 0; k < (size_t)d->dim; k++) {
        double lo = d->lo ? d->lo[k] : 0.0, hi = d->hi ? d->hi[k] : 1.0;
        if (d->shape[k] < 2)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: shape[%zu] = %zu, need at least 2 cells per axis",
                 k, d->shape[k]);
        if (vpdsi_mul_size(n, d->shape[k], &n) != 0 || n > ((size_t)-1) / (4 * sizeof(double)))
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "mask desc: the cell count overflows at shape[%zu] = %zu", k, d->shape[k]);
        if (!isfinite(lo) || !isfinite(hi) || !(lo < hi) || !isfinite(hi - lo))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: axis %zu has lo = %g, hi = %g; need finite lo < hi",
                 k, lo, hi);
        /* the sampler's own bounds: past them the distances' squares overflow (NaN everywhere)
         * or underflow (0 everywhere: every cell inside) */
        if (fabs(lo) > VPDSI_MAGNITUDE_MAX || fabs(hi) > VPDSI_MAGNITUDE_MAX || hi - lo < VPDSI_MAGNITUDE_MIN)
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "mask desc: axis %zu has lo = %g, hi = %g; coordinates must stay "
                 "within 1e150 in magnitude and the extent at least 1e-150 (squared distances overflow or "
                 "underflow beyond)", k, lo, hi);
    }
    for (i = 0; i < n; i++) {
        if (isnan(d->values[i])) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: values[%zu] is NaN", i);
        inside += d->values[i] >= d->threshold;
    }
    if (inside == 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "mask desc: no value is >= threshold = %g: the domain would be "
             "empty", d->threshold);
    return VPDS_OK;
}

/* Squared distance transform along one line of n values f (h apart, INFINITY: no site), into
 * out; v, z scratch of n and n + 1. The lower envelope of parabolas (FH 2012). */
static void edt_line(const double *f, size_t n, double h, double *out, size_t *v, double *z)
{
    size_t q, k = 0, m = 0;
    for (q = 0; q < n; q++) {
        double pq = h * (double)q;
        if (isinf(f[q])) continue;
        if (m == 0) {
            v[0] = q;
            z[0] = -INFINITY;
            z[1] = INFINITY;
            k = 0;
            m = 1;
            continue;
        }
        for (;;) { /* z[0] = -INFINITY: this stops at k = 0 at the latest */
            double pv = h * (double)v[k];
            double s = ((f[q] + pq * pq) - (f[v[k]] + pv * pv)) / (2 * (pq - pv));
            if (s <= z[k]) {
                k--;
                continue;
            }
            k++;
            v[k] = q;
            z[k] = s;
            z[k + 1] = INFINITY;
            break;
        }
    }
    if (m == 0) {
        for (q = 0; q < n; q++) out[q] = INFINITY;
        return;
    }
    for (k = 0, q = 0; q < n; q++) {
        double pq = h * (double)q, pv;
        while (z[k + 1] < pq) k++;
        pv = h * (double)v[k];
        out[q] = (pq - pv) * (pq - pv) + f[v[k]];
    }
}

/* In place: squared distances to the sites (0) of a grid of values (INFINITY elsewhere). */
static void edt(double *g, int dim, const size_t *shape, const size_t *stride, const double *h,
                double *line, double *res, size_t *v, double *z, size_t n)
{
    int a;
    for (a = 0; a < dim; a++) {
        size_t start, len = shape[a], i;
        for (start = 0; start < n; start++) {
            if ((start / stride[a]) % len != 0) continue; /* one line per position off axis a */
            for (i = 0; i < len; i++) line[i] = g[start + i * stride[a]];
            edt_line(line, len, h[a], res, v, z);
            for (i = 0; i < len; i++) g[start + i * stride[a]] = res[i];
        }
    }
}

vpds_status vpds_mask_create(const vpds_mask_desc *d, vpds_mask **out)
{
    vpdsi_mem m;
    vpds_mask *mk;
    vpds_grid_desc gd = vpds_default_grid_desc();
    size_t n = 1, k, i, longest = 0, stride[VPDS_MAX_DIM], s;
    double h[VPDS_MAX_DIM], glo[VPDS_MAX_DIM], ghi[VPDS_MAX_DIM], diag = 0, L;
    double *din, *dout, *line, *res, *z;
    size_t *v;
    vpds_status st;
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if ((st = vpds_mask_validate(d, NULL, 0)) != VPDS_OK) return st;
    for (k = 0; k < (size_t)d->dim; k++) {
        double lo = d->lo ? d->lo[k] : 0.0, hi = d->hi ? d->hi[k] : 1.0;
        n *= d->shape[k];
        if (d->shape[k] > longest) longest = d->shape[k];
        h[k] = (hi - lo) / (double)d->shape[k];
        glo[k] = lo + 0.5 * h[k]; /* nodes at the cell centres */
        ghi[k] = hi - 0.5 * h[k];
        diag += (hi - lo) * (hi - lo);
    }
    for (s = 1, k = (size_t)d->dim; k-- > 0;) {
        stride[k] = s;
        s *= d->shape[k];
    }
    vpdsi_mem_init(&m, &d->allocator);
    mk = (vpds_mask *)vpdsi_mem_alloc(&m, sizeof *mk);
    din = (double *)vpdsi_mem_alloc(&m, 2 * n * sizeof(double));
    line = (double *)vpdsi_mem_alloc(&m, (3 * longest + 1) * sizeof(double));
    v = (size_t *)vpdsi_mem_alloc(&m, longest * sizeof(size_t));
    if (!mk || !din || !line || !v) {
        vpdsi_mem_free(&m, mk, sizeof *mk);
        vpdsi_mem_free(&m, din, 2 * n * sizeof(double));
        vpdsi_mem_free(&m, line, (3 * longest + 1) * sizeof(double));
        vpdsi_mem_free(&m, v, longest * sizeof(size_t));
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    dout = din + n;
    res = line + longest;
    z = res + longest;
    for (i = 0; i < n; i++) {
        int in = d->values[i] >= d->threshold;
        din[i] = in ? 0 : INFINITY;
        dout[i] = in ? INFINITY : 0;
    }
    edt(din, d->dim, d->shape, stride, h, line, res, v, z, n);
    edt(dout, d->dim, d->shape, stride, h, line, res, v, z, n);
    diag = sqrt(diag);
    for (i = 0; i < n; i++) {
        /* no outside cell: the whole box is inside, at most a diagonal from any outside */
        double a = sqrt(din[i]), b = isinf(dout[i]) ? diag : sqrt(dout[i]);
        din[i] = 0.5 * (a - b);
    }
    gd.dim = d->dim;
    gd.shape = d->shape;
    gd.values = din;
    gd.lo = glo;
    gd.hi = ghi;
    gd.allocator = d->allocator;
    st = vpdsi_grid_build(&gd, &mk->grid);
    vpdsi_mem_free(&m, din, 2 * n * sizeof(double));
    vpdsi_mem_free(&m, line, (3 * longest + 1) * sizeof(double));
    vpdsi_mem_free(&m, v, longest * sizeof(size_t));
    if (st != VPDS_OK) {
        vpdsi_mem_free(&m, mk, sizeof *mk);
        return st;
    }
    L = vpds_grid_lipschitz(mk->grid);
    mk->scale = L > 1 ? 1 / L : 1;
    mk->magic = VPDSI_MASK_COOKIE;
    mk->mem = m;
    *out = mk;
    return VPDS_OK;
}

void vpds_mask_destroy(vpds_mask *mk)
{
    vpdsi_mem m;
    if (!mk || mk->magic != VPDSI_MASK_COOKIE) return;
    m = mk->mem;
    vpds_grid_destroy(mk->grid);
    mk->magic = 0;
    vpdsi_mem_free(&m, mk, sizeof *mk);
}

double vpds_mask_sdf(const double *x, void *user)
{
    const vpds_mask *mk = (const vpds_mask *)user;
    if (!mk || mk->magic != VPDSI_MASK_COOKIE || !x) return NAN;
    return mk->scale * vpds_grid_eval(mk->grid, x);
}

int vpdsi_mask_dim(const void *user)
{
    const vpds_mask *mk = (const vpds_mask *)user;
    return mk && mk->magic == VPDSI_MASK_COOKIE ? mk->grid->dim : 0;
}
