"""7D to 16D: the guarantees of the low dimensions, checked by brute force on runs small enough
for an exhaustive search (a unit box with radii of the order of its side: a few samples)."""
import math

import numpy as np
import pytest

from vpds import analysis as C

TOL = 1e-5  # VPDS_STREAM_TOLERANCE


def assert_valid(x, r, rule, sizing, lo, hi, inhibition=1.0, periodic=None):
    assert len(x) > 0
    assert np.all((x >= lo) & (x <= hi)), "samples outside the box"
    np.testing.assert_allclose(r, sizing.fn(x), rtol=1e-12, err_msg="r(x) stored != sizing")
    assert C.empty_disk_violations(x, r, rule, inhibition, sizing.lipschitz,
                                   periodic=periodic, lo=lo, hi=hi) == 0
    rep = C.check_maximal(x, r, rule, 1.0, sizing, lo, hi, periodic=periodic)
    assert rep.gaps == 0, f"uncovered point near {rep.worst_gap}"
    assert rep.unresolved_bound <= 1e-7
    assert rep.probes_max_rel <= 1e-9


# (dim, radius): 7D and 8D (test_properties stops at 6D), 9D and 11D split
# cells into 2^9 and 2^11 children, 13D into 32 blocks of 256, 16D into 256 blocks
@pytest.mark.parametrize("dim,radius", [(7, 1.0), (8, 1.2), (9, 1.5), (11, 2.0), (13, 2.5),
                                        (16, 3.0)])
def test_uniform_radius(sample, dim, radius):
    x, r, t = sample(dim, "smaller", "const", radius, 40 + dim, 0.0, 1.0)
    assert_valid(x, r, "smaller", C.sizing_named("const", radius), np.zeros(dim), np.ones(dim))
    assert np.all(t == 1.0)


def test_variable_radius(sample):
    x, r, _ = sample(9, "prior", "wide", 0.0, 2, 0.0, 1.0)
    assert_valid(x, r, "prior", C.sizing_named("wide"), np.zeros(9), np.ones(9))


def test_periodic_axis(sample):
    hi = np.ones(9)
    hi[0] = 4.0
    x, r, _ = sample(9, "smaller", "const", 1.5, 3, 0.0, 1.0, extra=("periodic=1", "hi0=4"))
    periodic = [True] + [False] * 8
    assert_valid(x, r, "smaller", C.sizing_named("const", 1.5), np.zeros(9), hi,
                 periodic=periodic)
    # the wrap is used: some pair is closer across it than inside the box
    gap = (x[:, None, 0] - x[None, :, 0]) % 4.0
    assert len(x) > 10 and np.any((gap > 2.0) & (gap < 3.9))


def test_two_radii(sample):
    """inhibition 0.8, coverage 1: conflict-free at 0.8 r, covered at r."""
    x, r, _ = sample(9, "smaller", "const", 2.0, 3, 0.0, 1.0, extra=("inhibition=0.8",))
    assert_valid(x, r, "smaller", C.sizing_named("const", 2.0), np.zeros(9), np.ones(9),
                 inhibition=0.8)


def test_stream_prefixes(sample):
    """A stream of 8 events from empty: every prefix conflict-free and maximal at its scale."""
    x, r, t = sample(9, "smaller", "const", 1.5, 3, 0.0, 1.0, extra=("run=0", "stream=8"))
    assert len(x) == 8 and math.isinf(t[0]) and np.all(np.diff(t[1:]) <= 0)
    lo, hi = np.zeros(9), np.ones(9)
    sizing = C.sizing_named("const", 1.5)
    taus = [float(np.nextafter(t[k], np.inf)) for k in range(2, 8)] + [float(t[-1])]
    rep = C.check_prefixes(x, r, t, "smaller", 1.0, 1.0, sizing, lo, hi, taus, TOL,
                           bnb_taus=taus[-2:], probes=5000, seed=9)
    assert rep.nonincreasing and rep.conflicts_at_insertion == 0
    for p in rep.taus:
        assert p.conflicts == 0 and p.gaps == 0, p
