/* Built-in sizing: a regular grid with multilinear interpolation, its exact Lipschitz constant,
 * and the Lipschitz envelope ("smoothed for L", Section 7 / Figure 12). */
#include "grid.h"
#include "refuse.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

vpds_grid_desc vpds_default_grid_desc(void)
{
    vpds_grid_desc d;
    memset(&d, 0, sizeof d);
    d.cookie = VPDSI_GRID_COOKIE;
    d.struct_size = (uint32_t)sizeof d;
    d.dim = 2;
    return d;
}


vpds_status vpds_grid_validate(const vpds_grid_desc *d, char *msg, size_t cap)
{
    size_t n = 1, k, i;
    if (msg && cap) msg[0] = 0;
    if (!d) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc is NULL");
    if (d->cookie != VPDSI_GRID_COOKIE)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "grid desc: cookie 0x%08x is not from vpds_default_grid_desc()",
             (unsigned)d->cookie);
    if (d->struct_size != sizeof *d)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "grid desc: struct_size %u, this library reads %u",
             (unsigned)d->struct_size, (unsigned)sizeof *d);
    if (d->dim < 1 || d->dim > VPDS_MAX_DIM)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: dim = %d, must be in 1..%d", d->dim, VPDS_MAX_DIM);
    if (!d->shape) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: shape is NULL");
    if (!d->values) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: values is NULL");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: allocator.alloc and allocator.free must both be set or both NULL");
    for (k = 0; k < (size_t)d->dim; k++) {
        double lo = d->lo ? d->lo[k] : 0.0, hi = d->hi ? d->hi[k] : 1.0;
        if (d->shape[k] < 2)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: shape[%u] = %zu, need at least 2 nodes per axis",
                 (unsigned)k, d->shape[k]);
        if (vpdsi_mul_size(n, d->shape[k], &n) != 0 || n > ((size_t)-1) / (2 * sizeof(double)))
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "grid desc: the node count overflows at shape[%u] = %zu",
                 (unsigned)k, d->shape[k]);
        if (!isfinite(lo) || !isfinite(hi) || !(lo < hi))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: axis %u has lo = %g, hi = %g; need finite lo < hi",
                 (unsigned)k, lo, hi);
        if (!isfinite(hi - lo) || !((hi - lo) / (double)(d->shape[k] - 1) > 0))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: axis %u: the node spacing (%g - %g) / %zu is "
                 "not a positive finite number", (unsigned)k, hi, lo, d->shape[k] - 1);
    }
    for (i = 0; i < n; i++)
        if (!(d->values[i] >= 1e-100 && d->values[i] <= 1e100))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "grid desc: values[%zu] = %g; radii must be finite and > 0 "
                 "(within [1e-100, 1e100])", i, d->values[i]);
    return VPDS_OK;
}

/* Largest gradient norm of the interpolant. Along any axis-parallel line in a cell the squared
 * gradient norm is a convex quadratic, so its maximum is at a corner, where each component is
 * the slope of the cell edge leaving that corner along its axis. */
static double grid_exact_lipschitz(const vpds_grid *g)
{
    size_t cell[VPDS_MAX_DIM] = {0};
    unsigned d = (unsigned)g->dim, corners = 1u << d, c, k;
    double best = 0;
    for (;;) {
        size_t base = 0;
        for (k = 0; k < d; k++) base += cell[k] * g->stride[k];
        for (c = 0; c < corners; c++) {
            double slope[VPDS_MAX_DIM], big = 0, s2 = 0, norm;
            for (k = 0; k < d; k++) {
                size_t i0 = base;
                unsigned j;
                for (j = 0; j < d; j++)
                    if (j != k && (c >> j & 1u)) i0 += g->stride[j];
                slope[k] = fabs(g->values[i0 + g->stride[k]] - g->values[i0]) / g->step[k];
                if (slope[k] > big) big = slope[k];
            }
            /* scaled, so that squares overflow only when the norm itself does */
            for (k = 0; k < d && big > 0 && isfinite(big); k++) s2 += (slope[k] / big) * (slope[k] / big);
            norm = isfinite(big) ? big * sqrt(s2) : big;
            if (norm > best) best = norm;
        }
        for (k = 0; k < d; k++) {
            if (++cell[k] < g->shape[k] - 1) break;
            cell[k] = 0;
        }
        if (k == d) break;
    }
    return best;
}

static void grid_refresh(vpds_grid *g)
{
    size_t i;
    g->vmin = g->vmax = g->values[0];
    for (i = 1; i < g->n; i++) {
        if (g->values[i] < g->vmin) g->vmin = g->values[i];
        if (g->values[i] > g->vmax) g->vmax = g->values[i];
    }
    g->lipschitz = grid_exact_lipschitz(g);
}

vpds_status vpds_grid_create(const vpds_grid_desc *d, vpds_grid **out)
{
    vpds_status st;
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    st = vpds_grid_validate(d, NULL, 0);
    if (st != VPDS_OK) return st;
    return vpdsi_grid_build(d, out);
}

vpds_status vpdsi_grid_build(const vpds_grid_desc *d, vpds_grid **out)
{
    vpdsi_mem m;
    vpds_grid *g;
    size_t k, s;
    vpdsi_mem_init(&m, &d->allocator);
    g = (vpds_grid *)vpdsi_mem_alloc(&m, sizeof *g);
    if (!g) return VPDS_ERR_OUT_OF_MEMORY;
    memset(g, 0, sizeof *g);
    g->magic = VPDSI_GRID_COOKIE;
    g->dim = d->dim;
    g->n = 1;
    for (k = 0; k < (size_t)d->dim; k++) {
        g->shape[k] = d->shape[k];
        g->n *= d->shape[k];
        g->lo[k] = d->lo ? d->lo[k] : 0.0;
        g->hi[k] = d->hi ? d->hi[k] : 1.0;
        g->step[k] = (g->hi[k] - g->lo[k]) / (double)(d->shape[k] - 1);
        g->whole[k] = d->shape[k];
    }
    for (s = 1, k = (size_t)d->dim; k-- > 0;) {
        g->stride[k] = s;
        s *= g->shape[k];
    }
    g->values = (double *)vpdsi_mem_alloc(&m, g->n * sizeof(double));
    if (!g->values) {
        vpdsi_mem_free(&m, g, sizeof *g);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    memcpy(g->values, d->values, g->n * sizeof(double));
    g->mem = m;
    grid_refresh(g);
    *out = g;
    return VPDS_OK;
}

vpds_status vpdsi_grid_clone(const vpds_grid *src, const vpds_allocator *a, vpds_grid **out)
{
    vpdsi_mem m;
    vpds_grid *g;
    vpdsi_mem_init(&m, a);
    g = (vpds_grid *)vpdsi_mem_alloc(&m, sizeof *g);
    if (!g) return VPDS_ERR_OUT_OF_MEMORY;
    *g = *src;
    g->values = (double *)vpdsi_mem_alloc(&m, src->n * sizeof(double));
    if (!g->values) {
        vpdsi_mem_free(&m, g, sizeof *g);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    memcpy(g->values, src->values, src->n * sizeof(double));
    g->mem = m;
    *out = g;
    return VPDS_OK;
}

void vpds_grid_destroy(vpds_grid *g)
{
    vpdsi_mem m;
    if (!g || g->magic != VPDSI_GRID_COOKIE) return;
    m = g->mem;
    vpdsi_mem_free(&m, g->values, g->n * sizeof(double));
    g->magic = 0;
    vpdsi_mem_free(&m, g, sizeof *g);
}

double vpds_grid_lipschitz(const vpds_grid *g)
{
    return (g && g->magic == VPDSI_GRID_COOKIE) ? g->lipschitz : NAN;
}

const double *vpds_grid_values(const vpds_grid *g)
{
    return (g && g->magic == VPDSI_GRID_COOKIE) ? g->values : NULL;
}

size_t vpds_grid_size(const vpds_grid *g)
{
    return (g && g->magic == VPDSI_GRID_COOKIE) ? g->n : 0;
}

double vpds_grid_eval(const vpds_grid *g, const double *x)
{
    size_t base = 0, k;
    double frac[VPDS_MAX_DIM], sum = 0;
    unsigned c, d, corners;
    if (!g || g->magic != VPDSI_GRID_COOKIE || !x) return NAN;
    d = (unsigned)g->dim;
    for (k = 0; k < d; k++) {
        double u = (x[k] - g->lo[k]) / g->step[k], fl;
        size_t i;
        if (u != u) return NAN; /* a NaN coordinate has no value (it read the first node's) */
        if (!(u > 0)) u = 0;
        if (u > (double)(g->whole[k] - 1)) u = (double)(g->whole[k] - 1);
        fl = floor(u);
        i = (size_t)fl;
        if (i > g->whole[k] - 2) i = g->whole[k] - 2;
        frac[k] = u - (double)i;
        /* a window answers only where it holds both nodes of the cell */
        if (i < g->offset[k] || i + 1 >= g->offset[k] + g->shape[k]) return NAN;
        base += (i - g->offset[k]) * g->stride[k];
    }
    corners = 1u << d;
    for (c = 0; c < corners; c++) {
        double w = 1;
        size_t idx = base;
        for (k = 0; k < d; k++) {
            if (c >> k & 1u) {
                w *= frac[k];
                idx += g->stride[k];
            } else {
                w *= 1 - frac[k];
            }
        }
        sum += w * g->values[idx];
    }
    return sum;
}

/* The largest grid below the values whose every edge slope is at most L/sqrt(d): a weighted
 * l1 distance transform, done exactly by a forward and a backward sweep along each axis. Its
 * interpolant then has corner gradients of norm <= sqrt(d * (L/sqrt(d))^2) = L. The price of
 * this sufficient condition: slopes along an axis are held to L/sqrt(d), not L. */
static void envelope(vpds_grid *g, double L)
{
    size_t k, d = (size_t)g->dim;
    for (k = 0; k < d; k++) {
        double c = L * g->step[k] / sqrt((double)d);
        size_t len = g->shape[k], st = g->stride[k], line, lines = g->n / len;
        for (line = 0; line < lines; line++) {
            /* start index of the line-th line along axis k */
            size_t outer = line / st, inner = line % st, start = outer * st * len + inner, i;
            for (i = 1; i < len; i++) {
                double *v = &g->values[start + i * st], prev = g->values[start + (i - 1) * st] + c;
                if (prev < *v) *v = prev;
            }
            for (i = len - 1; i-- > 0;) {
                double *v = &g->values[start + i * st], next = g->values[start + (i + 1) * st] + c;
                if (next < *v) *v = next;
            }
        }
    }
}

vpds_status vpds_grid_enforce_lipschitz(vpds_grid *g, double L)
{
    double aim = L;
    int round;
    if (!g || g->magic != VPDSI_GRID_COOKIE) return VPDS_ERR_INVALID_ARGUMENT;
    if (!isfinite(L) || !(L > 0)) return VPDS_ERR_INVALID_ARGUMENT;
    if (g->window) return VPDS_ERR_UNSUPPORTED; /* the envelope of a part is not a part of the envelope */
    /* v + c rounds: when slopes are tiny beside the values the result can exceed L by a few ulps
     * of the values, so aim a little lower until the promise holds exactly */
    for (round = 0; round < 8; round++) {
        envelope(g, aim);
        grid_refresh(g);
        if (g->lipschitz <= L) return VPDS_OK;
        aim -= 2 * (g->lipschitz - L) + L * 1e-15;
        if (!(aim > 0)) break;
    }
    {
        /* below what doubles can resolve at these values: the constant grid is the answer */
        size_t i;
        for (i = 0; i < g->n; i++) g->values[i] = g->vmin;
        grid_refresh(g);
    }
    return VPDS_OK;
}

/* ---- Windows of a grid too large to hold (tiled sampling reads one per tile). */

vpds_status vpds_grid_validate_window(const vpds_grid_desc *d, const size_t *whole,
                                      const size_t *offset, char *msg, size_t cap)
{
    vpds_status st = vpds_grid_validate(d, msg, cap);
    size_t k;
    if (st != VPDS_OK) return st;
    if (!whole) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "whole_shape is NULL");
    if (!offset) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "offset is NULL");
    for (k = 0; k < (size_t)d->dim; k++) {
        double lo = d->lo ? d->lo[k] : 0.0, hi = d->hi ? d->hi[k] : 1.0;
        if (whole[k] < 2)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "whole_shape[%u] = %zu: need at least 2 nodes per axis",
                 (unsigned)k, whole[k]);
        if (offset[k] > whole[k] || d->shape[k] > whole[k] - offset[k])
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "offset[%u] = %zu + shape[%u] = %zu exceeds whole_shape[%u] "
                 "= %zu: the window must lie inside the grid", (unsigned)k, offset[k], (unsigned)k,
                 d->shape[k], (unsigned)k, whole[k]);
        if (!((hi - lo) / (double)(whole[k] - 1) > 0))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "axis %u: the node spacing (%g - %g) / %zu is not a "
                 "positive finite number", (unsigned)k, hi, lo, whole[k] - 1);
    }
    return VPDS_OK;
}

vpds_status vpds_grid_create_window(const vpds_grid_desc *d, const size_t *whole,
                                    const size_t *offset, vpds_grid **out)
{
    vpds_status st;
    size_t k;
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if ((st = vpds_grid_validate_window(d, whole, offset, NULL, 0)) != VPDS_OK) return st;
    if ((st = vpds_grid_create(d, out)) != VPDS_OK) return st;
    for (k = 0; k < (size_t)d->dim; k++) {
        (*out)->whole[k] = whole[k];
        (*out)->offset[k] = offset[k];
        (*out)->step[k] = ((*out)->hi[k] - (*out)->lo[k]) / (double)(whole[k] - 1);
    }
    (*out)->window = 1;
    grid_refresh(*out); /* slopes with the whole grid's node spacing */
    return VPDS_OK;
}
