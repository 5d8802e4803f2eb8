/* The sampler behind the public handle: the subsystems it owns, side by side. Only the entry
 * points (sampler.c, refine.c, tiles.c) see it; they hand the algorithms a vpdsi_ctx. */
#ifndef VPDS_SAMPLER_H
#define VPDS_SAMPLER_H
#include "context.h"
#include "mps.h"
#include "stream.h"

#define VPDSI_SAMPLER_MAGIC 0x56505353u /* 'VPSS' */

struct vpds_sampler {
    uint32_t magic;
    vpdsi_mem mem;
    vpdsi_problem pb;
    vpdsi_store store;     /* samples, indexes, sizing, error sink */
    vpdsi_domain domain;
    vpdsi_rng rng;
    vpdsi_mps mps;         /* Algorithm 1 */
    vpdsi_stream stream;   /* Section 4.2 */
    vpds_stats stats;
    uint64_t budget;
    vpds_progress_fn progress;
    void *progress_user;
};

int vpdsi_sampler_live(const vpds_sampler *s);
/* Run Algorithm 1 at the current scale (resets the error first). */
vpds_status vpdsi_sampler_run(vpds_sampler *s);
/* After an allocation failure caused by the memory limit, append so to the error message. */
vpds_status vpdsi_sampler_note_limit(vpds_sampler *s, vpds_status st);
/* The scale at which the next run starts (a tiling's scale), before any run. */
void vpdsi_sampler_start_at(vpds_sampler *s, double t);
/* Bounds of a sizing larger than this sampler's part of it (a tile of a tiling): the same
 * cells and pruning as a run over the whole sizing. No effect on a constant radius. */
void vpdsi_sampler_share_bounds(vpds_sampler *s, double lipschitz, double rmin, double rmax);
#endif
