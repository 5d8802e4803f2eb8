/* What the algorithms (mps.c, stream.c, uncovered.c) are handed: the problem, read-only, and
 * the shared services they call down into. The entry points build it from the sampler; no
 * algorithm sees the sampler itself. */
#ifndef VPDS_CONTEXT_H
#define VPDS_CONTEXT_H
#include "domain.h"
#include "rng.h"
#include "store.h"

/* The problem as the descriptor resolved it (defaults applied); fixed for a sampler's life. */
typedef struct vpdsi_problem {
    int dim;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    vpds_rule rule;                /* never VPDS_RULE_DEFAULT */
    double inhibition, coverage;   /* R_f and R_c as multiples of r (Section 3) */
    int two_radii;                 /* inhibition < coverage */
    unsigned algorithm;            /* the dart process's version, 1..VPDS_ALGORITHM_VERSION */
    double period[VPDS_MAX_DIM];   /* box side on a periodic axis, 0 on an open one */
    int any_periodic;
    int weighted;                  /* Eq. 12: darts weighted by (r_min / r)^d */
} vpdsi_problem;

typedef struct vpdsi_ctx {
    const vpdsi_problem *pb;
    vpdsi_store *st;     /* the samples, the radius at a point, the error sink */
    vpdsi_domain *dom;   /* dom->fn NULL: the whole box */
    vpdsi_rng *rng;      /* one sequence shared by runs and the stream: determinism by seed */
    vpds_stats *stats;
    vpdsi_mem *mem;
} vpdsi_ctx;
#endif
