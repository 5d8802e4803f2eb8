"""How many samples a maximal run will hold and how much memory it will take, before it runs.

The model is the C library's (vpds_estimate, see include/vpds.h): the jamming density of random
sequential addition integrated over the box and the domain, the base grid's cells, and bytes per
cell and per sample measured in every dimension; within about 2x in 1D-8D. This module adds the
copies of the results the Python side holds (`PoissonDisk.estimate`), and what the system can
give."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Optional


__all__ = ["Estimate", "available_memory"]


@dataclass
class Estimate:
    samples: float      # expected count of a maximal run
    bytes: float        # expected peak memory (C library and the Python copies of the results)
    cells: float = 0.0  # expected most active cells at once

    def __str__(self) -> str:
        return f"about {self.samples:.3g} samples and {self.bytes / 2**20:,.0f} MiB"


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
