import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
TOOL = Path(os.environ.get("VPDS_SAMPLE_TOOL", ROOT / "build" / "tests" / "sample_tool"))


@pytest.fixture(scope="session")
def sample(tmp_path_factory):
    """sample(dim, rule, sizing, radius, seed, lo, hi, ..., extra=()) -> (x, r, t) from the C library."""
    from vpds import analysis as checker

    out_dir = tmp_path_factory.mktemp("samples")

    def run(dim, rule, sizing, radius, seed, lo, hi, budget=0, weighted=0, extra=()):
        """extra: sample_tool's KEY=VALUE options (periodic=, inhibition=, hi0=, stream=, ...)"""
        tag = "-".join(extra).replace("=", "")
        path = out_dir / f"{dim}-{rule}-{sizing}-{radius}-{seed}-{lo}-{hi}-{budget}-{weighted}-{tag}.bin"
        cmd = [str(TOOL), str(path), str(dim), rule, sizing, repr(radius), str(seed), repr(lo),
               repr(hi), str(budget), str(weighted), *extra]
        subprocess.run(cmd, check=True, capture_output=True, text=True)
        return checker.load(str(path))

    return run
