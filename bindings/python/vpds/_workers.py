"""Worker counts in scipy's spelling (`workers`: an int >= 1, or -1 for every core): shared by
PoissonDisk (vpds._core), its tiled process (vpds._tiled) and vpds.tiling."""
from __future__ import annotations

import numbers
import os
from typing import Any

import numpy as np


def check_workers(workers: Any) -> int:
    """An int >= 1, or -1 for every core (scipy's spelling)."""
    if not isinstance(workers, (numbers.Integral, np.integer)) or isinstance(workers, bool) or \
            not (int(workers) == -1 or int(workers) >= 1):
        raise ValueError(f"workers = {workers!r}: must be an int >= 1, or -1 for every core")
    return int(workers)


def threads_for(workers: int) -> int:
    """Threads for a worker count (-1: every core)."""
    return (os.cpu_count() or 1) if workers == -1 else workers
