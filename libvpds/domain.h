/* The sampling domain: box ∩ {x : sdf(x) <= 0}, sdf a user's 1-Lipschitz signed distance. */
#ifndef VPDS_DOMAIN_H
#define VPDS_DOMAIN_H
#include "store.h"

typedef struct vpdsi_domain {
    vpds_domain_fn fn;   /* NULL: the whole box */
    void *user;
    uint64_t calls;
} vpdsi_domain;

/* sdf at p (its image in the box on periodic axes, from the store). A NaN is VPDS_ERR_DOMAIN,
 * said in the store's error sink. */
vpds_status vpdsi_domain_at(vpdsi_domain *dm, vpdsi_store *st, const double *p, double *phi);
/* 1-Lipschitz where the library sees it: sdf at a and b (their distance apart) must differ by
 * at most that distance; else VPDS_ERR_DOMAIN naming both points. */
vpds_status vpdsi_domain_check_pair(vpdsi_store *st, const double *a, double phi_a,
                                    const double *b, double phi_b);
#endif
