"""The rule names of the Python API and their C values (vpds_rule)."""
from __future__ import annotations

from ._vpds import lib

RULES = {"prior": lib.VPDS_RULE_PRIOR, "current": lib.VPDS_RULE_CURRENT,
         "bigger": lib.VPDS_RULE_BIGGER, "smaller": lib.VPDS_RULE_SMALLER}
