/* The four distance functions f of Section 5 and what they imply for conflict and coverage. */
#ifndef VPDS_RULES_H
#define VPDS_RULES_H
#include "vpds.h"
#include <math.h>

/* f(x_i, y) from r(x_i) = rx and r(y) = ry. Monotone non-decreasing in both arguments, which is
 * what lets an upper bound of either radius bound f from above (kd-tree pruning). */
static inline double vpdsi_rule_f(vpds_rule rule, double rx, double ry)
{
    switch (rule) {
    case VPDS_RULE_PRIOR: return rx;
    case VPDS_RULE_CURRENT: return ry;
    case VPDS_RULE_BIGGER: return rx > ry ? rx : ry;
    default: return rx < ry ? rx : ry;
    }
}

/* Whether the rule reads r at the new point y (all but prior). */
static inline int vpdsi_rule_uses_y(vpds_rule rule) { return rule != VPDS_RULE_PRIOR; }

/* Whether f(x_i, y) may exceed r(x_i) (current, bigger): a disk then reaches beyond
 * t * coverage * r(x_i), up to the Table 1 reach of vpdsi_rule_reach. */
static inline int vpdsi_rule_may_exceed_rx(vpds_rule rule)
{
    return rule == VPDS_RULE_CURRENT || rule == VPDS_RULE_BIGGER;
}

/* Whether f(x_i, y) may exceed r(y) (prior, bigger). */
static inline int vpdsi_rule_may_exceed_ry(vpds_rule rule)
{
    return rule == VPDS_RULE_PRIOR || rule == VPDS_RULE_BIGGER;
}

/* Table 1 "Max L": the effective t*coverage*L must stay below it. */
static inline double vpdsi_rule_max_lipschitz(vpds_rule rule)
{
    return vpdsi_rule_may_exceed_ry(rule) ? 0.5 : 1.0;
}

/* The rule's default: VPDS_RULE_DEFAULT is smaller (DESIGN.md). */
static inline vpds_rule vpdsi_rule_resolve(vpds_rule rule)
{
    return rule == VPDS_RULE_DEFAULT ? VPDS_RULE_SMALLER : rule;
}

/* Upper bound of the distance at which a sample of radius r <= r_hi covers at `scale`
 * (t * coverage): r(u) <= r_hi + L |u - a| for the rules that read r(u), so
 * |u - a| <= scale r_hi / (1 - scale L) (Table 1's reach). */
static inline double vpdsi_rule_reach(vpds_rule rule, double scale, double L, double r_hi)
{
    double sl = scale * L;
    if (!vpdsi_rule_may_exceed_rx(rule)) return scale * r_hi;
    return sl < 1 ? scale * r_hi / (1 - sl) : INFINITY;
}

const char *vpdsi_rule_name(vpds_rule rule);
#endif
