/* The signed-distance domain: evaluation with its checks. A cell of half-diagonal h whose centre
 * has sdf > h lies outside (1-Lipschitz), one with sdf <= -h inside; the rest straddle. */
#include "domain.h"
#include <math.h>
#include <string.h>

vpds_status vpdsi_domain_at(vpdsi_domain *dm, vpdsi_store *st, const double *p, double *phi)
{
    double q[VPDS_MAX_DIM];
    memcpy(q, p, (size_t)st->dim * sizeof(double));
    vpdsi_store_wrap(st, q);
    *phi = dm->fn(q, dm->user);
    dm->calls++;
    if (isnan(*phi)) {
        char pq[256];
        vpdsi_format_point(pq, sizeof pq, q, st->dim);
        vpdsi_store_error(st, "domain returned NaN at x = (%s)", pq);
        return VPDS_ERR_DOMAIN;
    }
    return VPDS_OK;
}

vpds_status vpdsi_domain_check_pair(vpdsi_store *st, const double *a, double phi_a,
                                    const double *b, double phi_b)
{
    double d2 = 0, dist;
    int k;
    for (k = 0; k < st->dim; k++) d2 += (a[k] - b[k]) * (a[k] - b[k]);
    dist = sqrt(d2);
    /* infinities are allowed far from the domain; two of the same sign say nothing */
    if (isinf(phi_a) || isinf(phi_b)) {
        if (isinf(phi_a) && isinf(phi_b) && (phi_a > 0) == (phi_b > 0)) return VPDS_OK;
    } else if (fabs(phi_a - phi_b) <= dist * (1 + 1e-9) + 1e-12 * (fabs(phi_a) + fabs(phi_b))) {
        return VPDS_OK;
    }
    {
        char pa[256], pb[256];
        vpdsi_format_point(pa, sizeof pa, a, st->dim);
        vpdsi_format_point(pb, sizeof pb, b, st->dim);
        vpdsi_store_error(st, "domain is not 1-Lipschitz: sdf = %.17g at (%s) and %.17g at (%s), "
                        "%.17g apart", phi_a, pa, phi_b, pb, dist);
    }
    return VPDS_ERR_DOMAIN;
}
