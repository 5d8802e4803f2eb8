#include "rules.h"

const char *vpdsi_rule_name(vpds_rule rule)
{
    switch (rule) {
    case VPDS_RULE_PRIOR: return "prior";
    case VPDS_RULE_CURRENT: return "current";
    case VPDS_RULE_BIGGER: return "bigger";
    case VPDS_RULE_SMALLER: return "smaller";
    default: return "default";
    }
}
