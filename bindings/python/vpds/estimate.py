"""How many samples a maximal run will hold and how much memory it will take, before it runs.

The count integrates the jamming density of random sequential addition over the box (and the
domain): n = JAMMING_DENSITY[d] * integral of 1 / V_ball(inhibition r(x) / 2) dx, by Monte Carlo
on a fixed set of points. Boundaries add points, so small runs get more; within ~15% otherwise.
The bytes per sample are what `vpds_stats.peak_bytes / count` measured (one run per dimension,
variable radii in 2D; 7D and 8D extrapolated), plus the copies the Python side holds."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ._typing import BoundsLike, DomainFunction, SizingFunction
from .domain import jamming_density

__all__ = ["Estimate", "estimate_run", "available_memory"]

# peak bytes of the C library per sample (measured: 1D 53, 2D 98 uniform and ~140 with varying
# radii, 3D 305, 4D 1,256, 5D 5,716; 6D-8D extrapolated by the growth of the octree's cells)
_C_BYTES = {1: 80, 2: 120, 3: 360, 4: 1400, 5: 6200, 6: 25000, 7: 100000, 8: 400000}
_PROBES = 8192


@dataclass
class Estimate:
    samples: float   # expected count of a maximal run
    bytes: float     # expected peak memory (C library and the Python copies of the results)

    def __str__(self) -> str:
        return f"about {self.samples:.3g} samples and {self.bytes / 2**20:,.0f} MiB"


def estimate_run(d: int, lo: BoundsLike, hi: BoundsLike, *, radius: float = 0.05,
                 sizing: Optional[SizingFunction] = None,
                 inhibition: float = 1.0, scale: float = 1.0,
                 domain: Optional[DomainFunction] = None) -> Estimate:
    """Samples and peak bytes of a maximal run at `scale` (the smallest t it reaches) over the
    box [lo, hi] (each of shape (d,)); `sizing` and `domain` are evaluated at points (m, d)."""
    lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    volume = float(np.prod(hi_a - lo_a))
    unit_ball = math.pi ** (d / 2) / math.gamma(d / 2 + 1)
    density = jamming_density(d)
    y = lo_a + (hi_a - lo_a) * np.random.default_rng(0).random((_PROBES, d))
    r = np.full(_PROBES, float(radius)) if sizing is None else np.asarray(sizing(y), dtype=np.float64)
    r = np.where(np.isfinite(r) & (r > 0), r, np.nan)
    inside = np.ones(_PROBES, dtype=bool) if domain is None else np.asarray(domain(y)) <= 0
    per_volume = np.where(inside, 1.0 / (unit_ball * (0.5 * scale * inhibition * r) ** d), 0.0)
    samples = density * volume * float(np.nanmean(per_volume)) if np.isfinite(per_volume).any() else 0.0
    per_sample = _C_BYTES.get(d, _C_BYTES[8] * 4 ** (d - 8)) + 2 * (8 * d + 17)
    return Estimate(samples, samples * per_sample)


def available_memory() -> Optional[int]:
    """Bytes the system can give now (MemAvailable), or None when it cannot say."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None
