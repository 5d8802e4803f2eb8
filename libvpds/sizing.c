#include "sizing.h"
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
