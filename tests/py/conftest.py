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
    """sample(dim, rule, sizing, radius, seed, lo, hi) -> (x, r, t) from the C library."""
    from vpds import analysis as checker

    out_dir = tmp_path_factory.mktemp("samples")

    def run(dim, rule, sizing, radius, seed, lo, hi, budget=0, weighted=0):
        path = out_dir / f"{dim}-{rule}-{sizing}-{radius}-{seed}-{lo}-{hi}-{budget}-{weighted}.bin"
        cmd = [str(TOOL), str(path), str(dim), rule, sizing, repr(radius), str(seed), repr(lo),
               repr(hi), str(budget), str(weighted)]
        subprocess.run(cmd, check=True, capture_output=True, text=True)
        return checker.load(str(path))

    return run
