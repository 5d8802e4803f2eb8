/* The four distance functions f of Section 5 and what they imply for conflict and coverage. */
#ifndef VPDS_RULES_H
#define VPDS_RULES_H
#include "vpds.h"

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

/* Table 1 "Max L": the effective t*coverage*L must stay below it. */
static inline double vpdsi_rule_max_lipschitz(vpds_rule rule)
{
    return (rule == VPDS_RULE_PRIOR || rule == VPDS_RULE_BIGGER) ? 0.5 : 1.0;
}

const char *vpdsi_rule_name(vpds_rule rule);
#endif
