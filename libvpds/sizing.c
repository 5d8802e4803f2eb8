#include "sizing.h"
#include "rng.h"
#include <math.h>
#include <stdio.h>

void vpdsi_format_point(char *buf, size_t cap, const double *x, int dim)
{
    int k;
    size_t used = 0;
    buf[0] = 0;
    for (k = 0; k < dim && used < cap; k++) {
        int w = snprintf(buf + used, cap - used, "%s%.17g", k ? ", " : "", x[k]);
        if (w < 0) break;
        used += (size_t)w;
    }
}

vpds_status vpdsi_sizing_eval(vpdsi_sizing *s, const double *x, size_t n, double *out, char *err,
                              size_t cap)
{
    size_t i;
    switch (s->kind) {
    case VPDSI_SIZING_CONSTANT:
        for (i = 0; i < n; i++) out[i] = s->radius;
        return VPDS_OK;
    case VPDSI_SIZING_GRID:
        for (i = 0; i < n; i++) out[i] = vpds_grid_eval(s->grid, x + i * (size_t)s->dim);
        s->calls += n;
        for (i = 0; s->grid->window && i < n; i++) {
            if (!(out[i] > 0)) { /* NaN: a window answers only inside the nodes it holds */
                if (err && cap) {
                    char pt[256];
                    vpdsi_format_point(pt, cap < sizeof pt ? cap : sizeof pt, x + i * (size_t)s->dim, s->dim);
                    snprintf(err, cap, "x = (%s) lies outside the sizing grid window", pt);
                }
                return VPDS_ERR_SIZING;
            }
        }
        return VPDS_OK;
    default:
        break;
    }
    s->calls += n;
    if (s->batch) {
        if (n && s->batch(x, n, out, s->user) != 0) {
            if (err && cap) snprintf(err, cap, "sizing_batch returned an error for %zu points", n);
            return VPDS_ERR_SIZING;
        }
    } else {
        for (i = 0; i < n; i++) out[i] = s->fn(x + i * (size_t)s->dim, s->user);
    }
    for (i = 0; i < n; i++) {
        if (!vpdsi_radius_ok(out[i])) {
            if (err && cap) {
                char pt[256];
                vpdsi_format_point(pt, sizeof pt, x + i * (size_t)s->dim, s->dim);
                snprintf(err, cap, "sizing returned r = %g at x = (%s); r must be finite and > 0%s",
                         out[i], pt, out[i] > 0 && isfinite(out[i]) ? " (within [1e-100, 1e100])" : "");
            }
            return VPDS_ERR_SIZING;
        }
    }
    return VPDS_OK;
}

void vpdsi_sizing_bounds(const vpds_desc *d, double *L, double *rmin, double *rmax)
{
    if (d->sizing || d->sizing_batch) {
        *L = d->lipschitz;
        *rmin = d->radius_min;
        *rmax = d->radius_max;
    } else if (d->sizing_grid) {
        *L = d->lipschitz != VPDS_UNSET ? d->lipschitz : d->sizing_grid->lipschitz;
        *rmin = d->sizing_grid->vmin;
        *rmax = d->sizing_grid->vmax;
    } else {
        *L = 0;
        *rmin = *rmax = d->radius;
    }
}

vpds_status vpdsi_sizing_from_desc(vpdsi_sizing *s, const vpds_desc *d)
{
    vpds_status st;
    s->dim = d->dim;
    if (d->sizing || d->sizing_batch) {
        s->kind = VPDSI_SIZING_CALLBACK;
        s->fn = d->sizing;
        s->batch = d->sizing_batch;
        s->user = d->sizing_user;
    } else if (d->sizing_grid) {
        if ((st = vpdsi_grid_clone(d->sizing_grid, &d->allocator, &s->grid)) != VPDS_OK) return st;
        s->kind = VPDSI_SIZING_GRID;
    } else {
        s->kind = VPDSI_SIZING_CONSTANT;
        s->radius = d->radius;
    }
    vpdsi_sizing_bounds(d, &s->lipschitz, &s->rmin, &s->rmax);
    return VPDS_OK;
}

#define RMAX_PROBES 4096

/* The lattice where r_max is read: per^d points, per from 3 up while per^d * (per + 1) <= 4096
 * (so 3^d points from 7 dimensions on: 43 million in 16); capped (version 7 on), 4096 of them
 * at most, chosen by a hash (*hashed). */
static size_t rmax_lattice(int d, int capped, int *per, int *hashed)
{
    size_t n = 1;
    int k;
    *per = 2;
    /* the first pass always runs (3 * 1 <= 4096): n = per^d, at most 3^16 */
    while (*per < 64 && n * (size_t)(*per + 1) <= RMAX_PROBES) {
        (*per)++;
        for (n = 1, k = 0; k < d; k++) n *= (size_t)*per;
    }
    *hashed = capped && n > RMAX_PROBES;
    return *hashed ? RMAX_PROBES : n;
}

/* r_max only sizes the base cells of the kd-tree path (never a correctness bound there), so
 * estimate it from r on a lattice (rmax_lattice), capped by the bound that L gives from the
 * box's centre. The lattice is read RMAX_CHUNK points at a time: the same points, so the same
 * r_max, in memory that does not grow with 3^d (5.8 GB in 16 dimensions when it was whole). */
#define RMAX_CHUNK 4096

/* Lattice points first..first + n - 1: the digits of the index, or of a hash of it and the axis. */
static void rmax_points(const double *lo, const double *hi, int d, int per, int hashed, size_t first,
                        size_t n, double *pts)
{
    size_t i;
    int k;
    for (i = 0; i < n; i++) {
        size_t rest = first + i;
        for (k = 0; k < d; k++) {
            size_t j = rest % (size_t)per;
            if (hashed) j = (size_t)(vpdsi_mix64((uint64_t)(first + i) * VPDS_MAX_DIM + (uint64_t)k) % (uint64_t)per);
            else rest /= (size_t)per;
            pts[i * (size_t)d + (size_t)k] = lo[k] + (hi[k] - lo[k]) * (double)j / (double)(per - 1);
        }
    }
}

vpds_status vpdsi_sizing_estimate_rmax(vpdsi_sizing *s, vpdsi_mem *m, const double *lo,
                                       const double *hi, int capped, char *err, size_t cap)
{
    double c[VPDS_MAX_DIM] = {0}, rc, diag2 = 0, best = 0, *pts, *r;
    int k, d = s->dim, per, hashed;
    size_t n = rmax_lattice(d, capped, &per, &hashed), chunk = n < RMAX_CHUNK ? n : RMAX_CHUNK, i, done, bytes;
    vpds_status st;
    if (s->rmax > 0) return VPDS_OK;
    for (k = 0; k < d; k++) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    if ((st = vpdsi_sizing_eval(s, c, 1, &rc, err, cap)) != VPDS_OK) return st;
    bytes = chunk * ((size_t)d + 1) * sizeof(double);
    if (!(pts = (double *)vpdsi_mem_alloc(m, bytes))) {
        if (err && cap) snprintf(err, cap, "out of memory estimating the largest radius");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    r = pts + chunk * (size_t)d;
    for (done = 0; st == VPDS_OK && done < n; done += chunk) {
        size_t take = n - done < chunk ? n - done : chunk;
        rmax_points(lo, hi, d, per, hashed, done, take, pts);
        st = vpdsi_sizing_eval(s, pts, take, r, err, cap);
        for (i = 0; st == VPDS_OK && i < take; i++)
            if (r[i] > best) best = r[i];
    }
    vpdsi_mem_free(m, pts, bytes);
    if (st != VPDS_OK) return st;
    if (rc > best) best = rc;
    s->rmax = best;
    if (rc + s->lipschitz * sqrt(diag2) / 2 < best) s->rmax = rc + s->lipschitz * sqrt(diag2) / 2;
    return VPDS_OK;
}
