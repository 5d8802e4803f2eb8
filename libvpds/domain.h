/* The sampling domain: box ∩ {x : sdf(x) <= 0}, sdf a user's 1-Lipschitz signed distance. */
#ifndef VPDS_DOMAIN_H
#define VPDS_DOMAIN_H
#include "vpds.h"

struct vpds_sampler;

/* sdf at p (its image in the box on periodic axes). A NaN is VPDS_ERR_DOMAIN, said in err. */
vpds_status vpdsi_domain_at(struct vpds_sampler *s, const double *p, double *phi);
/* 1-Lipschitz where the library sees it: sdf at a and b (their distance apart) must differ by
 * at most that distance; else VPDS_ERR_DOMAIN naming both points. */
vpds_status vpdsi_domain_check_pair(struct vpds_sampler *s, const double *a, double phi_a,
                                    const double *b, double phi_b);
#endif
