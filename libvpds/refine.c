/* The discrete hierarchy (Section 4.3): vpds_refine continues a maximal set at a smaller
 * scale t, each level maximal at its own scale and conflict-free across levels. */
#include "sampler.h"
#include "rules.h"
#include <math.h>

/* Why t cannot start a refinement now (VPDS_OK: it can); said in the error sink. */
static vpds_status refine_refusal(vpds_sampler *s, double t)
{
    const vpdsi_run *run = &s->mps.run;
    double limit, L = s->store.sizing.lipschitz;
    if (!isfinite(t) || !(t > 0)) {
        vpdsi_store_error(&s->store, "t = %g: the scale must be finite and > 0", t);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (!vpdsi_scale_ok(t * s->pb.coverage)) {
        vpdsi_store_error(&s->store, "t = %g: t * coverage must be within [1e-50, 1e50]", t);
        return VPDS_ERR_OVERFLOW;
    }
    if (run->phase != VPDSI_IDLE && run->phase != VPDSI_DONE) {
        vpdsi_store_error(&s->store, "t = %g: the run at scale %g is not finished (call vpds_run "
                          "until it returns VPDS_OK before refining)", t, run->t);
        return VPDS_ERR_STATE;
    }
    if (vpdsi_store_has_samples(&s->store) && t >= run->t) {
        vpdsi_store_error(&s->store, "t = %g: refinement needs t below the current scale %g once "
                          "samples exist (their disks would conflict at a larger scale)", t, run->t);
        return VPDS_ERR_STATE;
    }
    limit = vpdsi_rule_max_lipschitz(s->pb.rule);
    if (t * s->pb.coverage * L >= limit) {
        vpdsi_store_error(&s->store, "t = %g: t * coverage * L = %g is at or above the %s rule's "
                          "limit %g", t, t * s->pb.coverage * L, vpdsi_rule_name(s->pb.rule), limit);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    return VPDS_OK;
}

vpds_status vpds_refine(vpds_sampler *s, double t)
{
    vpdsi_run *run;
    double old_t;
    vpdsi_phase old_phase;
    vpds_status st;
    if (!vpdsi_sampler_live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    run = &s->mps.run;
    s->store.err[0] = 0;
    /* a paused refinement continues; a finished one at the same scale is done */
    if (isfinite(t) && t > 0 && vpdsi_scale_ok(t * s->pb.coverage) && t == run->t) {
        if (run->phase != VPDSI_IDLE && run->phase != VPDSI_DONE) return vpdsi_sampler_run(s);
        if (run->phase == VPDSI_DONE && vpdsi_store_has_samples(&s->store)) return VPDS_OK;
    }
    if ((st = refine_refusal(s, t)) != VPDS_OK) return st;
    /* a refinement that fails before any work (out of memory, overflow) must leave the
     * sampler at its old scale, as if it had not been called */
    old_t = run->t;
    old_phase = run->phase;
    vpdsi_sampler_start_at(s, t);
    st = vpdsi_sampler_run(s);
    if (st < 0 && run->phase == VPDSI_IDLE) {
        run->t = old_t;
        run->phase = old_phase;
        s->stats.t = old_t;
    }
    return st;
}
