/* The sampler's descriptor: defaults, and the validation that explains every refusal. */
#include "desc.h"
#include "grid.h"
#include "mask.h"
#include "refuse.h"
#include "rules.h"
#include "sizing.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

vpds_desc vpds_default_desc(void)
{
    vpds_desc d;
    memset(&d, 0, sizeof d);
    d.cookie = VPDSI_DESC_COOKIE;
    d.struct_size = (uint32_t)sizeof d;
    d.dim = 2;
    d.radius = 0.05;
    d.lipschitz = VPDS_UNSET;
    d.rule = VPDS_RULE_DEFAULT;
    d.inhibition = 1.0;
    d.coverage = 1.0;
    return d;
}


vpds_status vpds_validate(const vpds_desc *d, char *msg, size_t cap)
{
    int k, callback;
    double L = 0, limit;
    if (msg && cap) msg[0] = 0;
    if (!d) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc is NULL");
    if (d->cookie != VPDSI_DESC_COOKIE)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "desc.cookie = 0x%08x: the descriptor did not come from "
               "vpds_default_desc() (uninitialised, or from another library)", (unsigned)d->cookie);
    if (d->struct_size != sizeof *d)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "desc.struct_size = %u: a layout this library cannot read "
               "(it reads %u; rebuild against this vpds.h)", (unsigned)d->struct_size,
               (unsigned)sizeof *d);
    if (d->algorithm_version > VPDS_ALGORITHM_VERSION)
        VPDSI_REFUSE(VPDS_ERR_UNSUPPORTED, "desc.algorithm_version = %u: this library has versions 1..%d",
               (unsigned)d->algorithm_version, VPDS_ALGORITHM_VERSION);
    if (d->dim < 1 || d->dim > VPDS_MAX_DIM)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.dim = %d: must be in 1..%d", d->dim, VPDS_MAX_DIM);
    for (k = 0; k < d->dim; k++) {
        double lo = d->lo ? d->lo[k] : 0.0, hi = d->hi ? d->hi[k] : 1.0;
        if (!isfinite(lo)) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.lo[%d] = %g: must be finite", k, lo);
        if (!isfinite(hi)) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.hi[%d] = %g: must be finite", k, hi);
        if (!(lo < hi))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.lo[%d] = %g >= desc.hi[%d] = %g: the box is empty",
                   k, lo, k, hi);
        if (!isfinite(hi - lo))
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "desc.hi[%d] - desc.lo[%d] overflows", k, k);
        if (fabs(lo) > VPDSI_MAGNITUDE_MAX || fabs(hi) > VPDSI_MAGNITUDE_MAX || hi - lo < VPDSI_MAGNITUDE_MIN)
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "desc axis %d: lo = %g, hi = %g; coordinates must stay within "
                   "1e150 in magnitude and the extent at least 1e-150 (squared distances overflow "
                   "or underflow beyond)", k, lo, hi);
    }
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.allocator: alloc and free must both be set or both NULL");
    if (d->rule < VPDS_RULE_DEFAULT || d->rule > VPDS_RULE_SMALLER)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.rule = %d: not a vpds_rule", (int)d->rule);
    if (!isfinite(d->inhibition) || !(d->inhibition > 0))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.inhibition = %g: must be finite and > 0", d->inhibition);
    if (!isfinite(d->coverage) || !(d->coverage > 0))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.coverage = %g: must be finite and > 0", d->coverage);
    if (!vpdsi_scale_ok(d->coverage) || !vpdsi_scale_ok(d->inhibition))
        VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "desc.inhibition = %g, desc.coverage = %g: must be within [1e-50, "
               "1e50]", d->inhibition, d->coverage);
    if (d->inhibition > d->coverage)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.inhibition = %g > desc.coverage = %g: need R_f <= R_c",
               d->inhibition, d->coverage);
    if ((d->radius_min != 0 && !vpdsi_radius_ok(d->radius_min)) ||
        (d->radius_max != 0 && !vpdsi_radius_ok(d->radius_max)))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.radius_min = %g, desc.radius_max = %g: must be 0 or "
               "within [1e-100, 1e100]", d->radius_min, d->radius_max);
    if (!isfinite(d->radius_min) || d->radius_min < 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.radius_min = %g: must be finite and >= 0", d->radius_min);
    if (!isfinite(d->radius_max) || d->radius_max < 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.radius_max = %g: must be finite and >= 0", d->radius_max);
    if (d->radius_min > 0 && d->radius_max > 0 && d->radius_min > d->radius_max)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.radius_min = %g > desc.radius_max = %g",
               d->radius_min, d->radius_max);
    if (d->lipschitz != VPDS_UNSET && (!isfinite(d->lipschitz) || d->lipschitz < 0))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.lipschitz = %g: must be finite and >= 0 (or VPDS_UNSET)",
               d->lipschitz);
    callback = d->sizing != NULL || d->sizing_batch != NULL;
    if (callback && d->sizing_grid)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.sizing and desc.sizing_grid are both set: give one sizing");
    if (callback) {
        if (d->lipschitz == VPDS_UNSET)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.lipschitz is required with a sizing callback "
                   "(the Lipschitz constant L of r)");
        L = d->lipschitz;
    } else if (d->sizing_grid) {
        const vpds_grid *g = d->sizing_grid;
        if (g->magic != VPDSI_GRID_COOKIE)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.sizing_grid is not a live vpds_grid");
        if (g->dim != d->dim)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.sizing_grid has dim %d, desc.dim = %d", g->dim, d->dim);
        L = g->lipschitz;
        if (d->lipschitz != VPDS_UNSET) {
            if (d->lipschitz < g->lipschitz * (1 - 1e-12))
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.lipschitz = %.17g is below the grid's exact "
                       "Lipschitz constant %.17g", d->lipschitz, g->lipschitz);
            L = d->lipschitz;
        }
    } else {
        if (!isfinite(d->radius) || !(d->radius > 0))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.radius = %g: must be finite and > 0", d->radius);
        if (!vpdsi_radius_ok(d->radius))
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "desc.radius = %g: must be within [1e-100, 1e100] (squared "
                   "distances overflow or underflow beyond)", d->radius);
    }
    limit = vpdsi_rule_max_lipschitz(vpdsi_rule_resolve(d->rule));
    if (d->coverage * L >= limit)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.lipschitz: coverage * L = %g * %g = %g is at or above "
               "the %s rule's limit %g (Table 1)", d->coverage, L, d->coverage * L,
               vpdsi_rule_name(vpdsi_rule_resolve(d->rule)), limit);
    if (d->periodic && !callback && !d->sizing_grid) {
        for (k = 0; k < d->dim; k++) {
            double side = (d->hi ? d->hi[k] : 1.0) - (d->lo ? d->lo[k] : 0.0);
            if (d->periodic[k] && !(side > 2 * d->coverage * d->radius))
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.periodic[%d]: the side %g is not above 2 * "
                       "coverage * radius = %g (a disk would meet its own image across the wrap)",
                       k, side, 2 * d->coverage * d->radius);
        }
    }
    /* the built-in domains know their dimension: one of another would be read at coordinates
     * the sampler never writes (a mask's extra axes) or never read (its missing ones) */
    if (d->domain == vpds_polygon_sdf && d->dim != 2)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.domain is vpds_polygon_sdf, a 2D domain; desc.dim = %d",
                     d->dim);
    if (d->domain == vpds_mask_sdf && vpdsi_mask_dim(d->domain_user) > 0 &&
        vpdsi_mask_dim(d->domain_user) != d->dim)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.domain_user: a %dD mask (vpds_mask_sdf) for desc.dim = %d",
                     vpdsi_mask_dim(d->domain_user), d->dim);
    if (d->weighted && callback && !(d->radius_min > 0))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.weighted with a sizing callback needs desc.radius_min "
               "> 0 (a lower bound of r: darts are kept with probability (radius_min / r)^dim)");
    return VPDS_OK;
}
