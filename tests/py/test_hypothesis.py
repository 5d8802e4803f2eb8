"""Property-based fuzzing of the Python entry points (Hypothesis): random valid configurations
keep the invariants and are deterministic; random invalid ones raise clean exceptions."""
import math

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import vpds  # noqa: E402
from vpds import analysis as C  # noqa: E402

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))


@st.composite
def configurations(draw):
    d = draw(st.integers(1, 3))
    lo = np.array([draw(st.floats(-5, 5)) for _ in range(d)])
    hi = lo + np.array([draw(st.floats(0.5, 3)) for _ in range(d)])
    volume = float(np.prod(hi - lo))
    r0 = (volume / 300) ** (1 / d) * draw(st.floats(1, 3))  # a few hundred samples at most
    rule = draw(st.sampled_from(sorted(vpds.RULES)))
    limit = 0.5 if rule in ("prior", "bigger") else 1.0
    kind = draw(st.sampled_from(["float", "callable", "grid"]))
    kw = dict(rule=rule, l_bounds=lo, u_bounds=hi, rng=draw(st.integers(0, 2**64 - 1)),
              progress=False)
    slope = draw(st.floats(0, 0.9)) * limit / 2
    if kind == "float":
        kw["sizing"] = r0
        L = 0.0
    elif kind == "callable":
        kw["sizing"] = lambda p, lo0=lo[0], s=slope, r=r0: r + s * (p[:, 0] - lo0)
        kw["lipschitz"] = L = slope
    else:
        values = r0 * (1 + np.array(draw(st.lists(st.floats(0, 1), min_size=2 ** d, max_size=2 ** d))))
        grid = vpds.SizingGrid(values.reshape((2,) * d), lo, hi)
        if grid.lipschitz >= limit:
            grid.enforce_lipschitz(0.9 * limit)
        kw["sizing"] = grid
        L = grid.lipschitz
    if draw(st.booleans()):
        k = draw(st.integers(1, 3))
        kw["fixed_points"] = lo + np.array(draw(st.lists(st.floats(0, 1), min_size=k * d,
                                                         max_size=k * d))).reshape(k, d) * (hi - lo)
    return d, kw, L


@SETTINGS
@given(configurations())
def test_valid_configurations_keep_the_invariants(cfg):
    d, kw, L = cfg
    engine = vpds.PoissonDisk(d, **kw)
    x = engine.fill_space()
    allp, r, fixed = engine.points, engine.radii, engine.fixed
    assert x.shape[1] == d and np.all(np.isfinite(allp)) and np.all(r > 0)
    free = allp[~fixed]
    assert np.all(free >= kw["l_bounds"]) and np.all(free <= kw["u_bounds"])
    assert engine.stats["maximal"]
    if not fixed.any():  # fixed points are not checked against each other by design
        assert C.empty_disk_violations(allp, r, kw["rule"], 1.0, L) == 0
    again = vpds.PoissonDisk(d, **kw).fill_space()
    np.testing.assert_array_equal(x, again)


bad_floats = st.sampled_from([0.0, -1.0, math.nan, math.inf, -math.inf, 1e300, 1e-300])


@SETTINGS
@given(st.integers(-2, 10), bad_floats, st.sampled_from(["prior", "largest", "", "SMALLER"]),
       st.floats(allow_nan=True, allow_infinity=True), st.booleans())
def test_invalid_arguments_raise_clean_exceptions(d, radius, rule, lipschitz, inverted):
    lo, hi = ([1.0] * max(d, 1), [0.0] * max(d, 1)) if inverted else (None, None)
    try:
        engine = vpds.PoissonDisk(d, radius=radius, rule=rule, lipschitz=lipschitz, l_bounds=lo,
                                  u_bounds=hi, progress=False)
        engine.random(3)
    except (ValueError, TypeError, NotImplementedError, vpds.VpdsError, MemoryError):
        return
    # accepted only if every argument was in fact valid
    assert 1 <= d <= 8 and rule == "prior" and not inverted and 1e-100 <= radius <= 1e100
