"""scipy's own tests of scipy.stats.qmc.PoissonDisk, run against vpds.PoissonDisk.

TestPoisson comes from the installed scipy (scipy/stats/tests/test_qmc.py: scipy's wheels ship
their tests), imported, not copied; the class under test is rebound (its `qmce`, and
`qmc.PoissonDisk`, which one of its tests names directly). Then the drop-in's own rules where it
follows scipy: the int seed rule, d = 0, the optimization names and their effect, the bounds'
errors, fast_forward and integers.

What does not run as scipy wrote it, and why (pytest -rs prints the reasons):
- test_sample: skipped by scipy itself for PoissonDisk: it compares against reference
  arrays scipy does not define for this engine (its values depend on the implementation).
  vpds is not Bridson's algorithm, so scipy's numbers could not match anyway.
- test_bounds: skipped by scipy ("too costly in memory"); it samples d = 100, and libvpds
  samples d = 1 to 8 (refused beyond: test_d_beyond_8_is_refused_and_d_8_stays_in_bounds runs
  its claim at d = 8).
- the [Scrambled] variants of test_0dim, test_0sample, test_1sample, test_reset, and
  test_distribution (scrambled only): skipped by scipy's own engine() since PoissonDisk has no
  `scramble` (can_scramble = False); the [Unscrambled] variants are the same calls and run.
  test_distribution also needs d = 50 (> 8).
- test_deterministic (module level): rerun with vpds, it fails at one line on purpose:
  it asserts rng=n equals rng=np.random.default_rng(n) for n = 2359834584, but an int below
  2**64 is the C seed itself in vpds (the C library's and the CLI's points for that seed),
  while a Generator gives a seed drawn from it. Asserted to fail there and nowhere else
  (test_scipy_test_deterministic_fails_only_where_an_int_is_the_c_seed); the rest of its
  claims are asserted in test_deterministic_except_int_versus_generator.
Rerun beyond what scipy runs for its PoissonDisk, because vpds's random() is a prefix of one
process: QMCEngineTests' test_fast_forward and test_continuing (exact continuation), and
test_consume_prng_state unscrambled (scipy only calls it scrambled).
"""
import functools
import inspect
import sys

import numpy as np
import pytest
from scipy.spatial.distance import pdist
from scipy.stats import qmc

import vpds
from vpds._optional import MissingDependencyError

pytest.register_assert_rewrite("scipy.stats.tests.test_qmc")
test_qmc = pytest.importorskip(
    "scipy.stats.tests.test_qmc",
    reason="this scipy does not ship its tests (scipy/stats/tests); scipy's wheels do: "
           "pip install --force-reinstall scipy")

SCIPY_SEED = 170382760648021597650530316304495310428  # QMCEngineTests.engine's default rng


class TestVpdsPoisson(test_qmc.TestPoisson):
    """scipy's TestPoisson, with vpds.PoissonDisk as the engine under test."""
    qmce = vpds.PoissonDisk

    @pytest.fixture(autouse=True)
    def _vpds_is_qmc_poissondisk(self, monkeypatch):
        # test_raises calls qmc.PoissonDisk itself rather than self.qmce
        monkeypatch.setattr(test_qmc.qmc, "PoissonDisk", vpds.PoissonDisk)

    def test_engine_under_test_is_vpds(self):
        assert isinstance(self.engine(scramble=False, d=2), vpds.PoissonDisk)
        assert test_qmc.qmc.PoissonDisk is vpds.PoissonDisk

    def test_bounds(self, *args):
        pytest.skip("d = 100: libvpds samples d = 1 to 8 (scipy skips it too: too costly in "
                    "memory); see test_d_beyond_8_is_refused_and_d_8_stays_in_bounds")

    def test_fast_forward(self):
        # scipy skips it for its PoissonDisk (its continuation loses candidates); vpds's
        # random() and fast_forward() walk one process, so the base test holds (exactly)
        test_qmc.QMCEngineTests.test_fast_forward(self, scramble=False)

    def test_continuing_exact(self):
        # the base QMCEngineTests.test_continuing that TestPoisson replaces by a weaker one
        test_qmc.QMCEngineTests.test_continuing(self, scramble=False)

    def test_consume_prng_state(self, monkeypatch):
        # scipy calls it with scramble=True only (so skips it for PoissonDisk); its claim, one
        # Generator seeding three engines gives three different samples, is not about scrambling
        unscrambled = functools.partial(test_qmc.QMCEngineTests.engine, self, False)
        monkeypatch.setattr(self, "engine", lambda scramble, **kw: unscrambled(**kw))
        test_qmc.QMCEngineTests.test_consume_prng_state(self)


def test_scipy_test_deterministic_fails_only_where_an_int_is_the_c_seed():
    """scipy's test_deterministic, rerun with vpds, fails at one assertion on purpose: the one
    after res2 = engine(d=1, rng=seed_number), which expects rng=n to equal
    rng=np.random.default_rng(n) (an int below 2**64 is the C seed itself in vpds)."""
    with pytest.raises(AssertionError) as info:
        test_qmc.test_deterministic(vpds.PoissonDisk)
    lines, first = inspect.getsourcelines(test_qmc.test_deterministic)
    int_seed = next(i for i, line in enumerate(lines) if "engine(d=1, rng=seed_number).random" in line)
    failed_at = [e.lineno + 1 for e in info.traceback if e.path.name == "test_qmc.py"][-1]
    assert failed_at == first + int_seed + 1, lines[failed_at - first]


def engine(d=2, **kw):
    return vpds.PoissonDisk(d, progress=False, **kw)


# -- the seed rule ------------------------------------------------------------------------------
def test_deterministic_except_int_versus_generator():
    n = 2359834584  # scipy's test_deterministic seed
    a = engine(1, seed=np.random.RandomState(n)).random(4)
    np.testing.assert_array_equal(a, engine(1, seed=np.random.RandomState(n)).random(4))
    b = engine(1, seed=np.random.default_rng(n)).random(4)
    np.testing.assert_array_equal(b, engine(1, rng=np.random.default_rng(n)).random(4))
    np.testing.assert_array_equal(engine(1, seed=n).random(4), engine(1, rng=n).random(4))
    assert engine(1, rng=n).seed == n  # the int, not a draw from default_rng(n): b differs
    assert not np.array_equal(b, engine(1, rng=n).random(4))
    with pytest.raises(TypeError, match="got multiple values for argument now known as `rng`"):
        engine(1, rng=n, seed=n)


@pytest.mark.parametrize("seed", [0, 1, 2**63, 2**64 - 1])
def test_int_below_2_64_is_the_c_seed(sample, seed):
    """The same points as the C library given that seed (the meaning existing outputs have)."""
    e = engine(2, radius=0.1, rng=seed)
    assert e.seed == seed
    x, _, _ = sample(2, "smaller", "const", 0.1, seed, 0.0, 1.0)
    np.testing.assert_array_equal(e.fill_space(), x)
    assert engine(2, radius=0.1, rng=np.uint64(seed)).seed == seed


@pytest.mark.parametrize("seed", [2**64, SCIPY_SEED, 2**200 + 12345])
def test_larger_int_goes_through_seed_sequence(seed):
    e = engine(2, radius=0.1, rng=seed)
    expected = int(np.random.default_rng(np.random.SeedSequence(seed)).integers(0, 2**63, dtype=np.int64))
    assert e.seed == expected
    g = engine(2, radius=0.1, rng=np.random.default_rng(seed))
    assert g.seed == e.seed  # for n >= 2**64, rng=n is rng=default_rng(n)
    np.testing.assert_array_equal(e.fill_space(), g.fill_space())
    assert engine(2, rng=seed + 1).seed != e.seed


def test_negative_int_is_refused_as_default_rng_refuses_it():
    with pytest.raises(ValueError, match="expected non-negative integer"):
        np.random.default_rng(-5)  # what scipy gets for rng=-5
    with pytest.raises(ValueError, match=r"rng = -5: an int seed must be >= 0"):
        engine(rng=-5)
    with pytest.raises(ValueError, match=r"rng = 1.5 cannot be used to seed"):
        engine(rng=1.5)


def test_one_generator_seeds_engines_in_turn_differently():
    rng = np.random.default_rng(3)
    seeds = {engine(rng=rng).seed for _ in range(3)}
    assert len(seeds) == 3


# -- d = 0 --------------------------------------------------------------------------------------
def test_d0_follows_scipy():
    ref = qmc.PoissonDisk(0, rng=1)
    e = engine(0, rng=SCIPY_SEED)
    for n in (4, 0, 3):
        got = e.random(n)
        assert got.shape == ref.random(n).shape == (n, 0) and got.dtype == np.float64
    assert e.num_generated == 7
    assert e.fill_space().shape == (0, 0)
    assert e.points.shape == (0, 0) and e.radii.shape == e.scales.shape == e.fixed.shape == (0,)
    assert e.reset().num_generated == 0
    np.testing.assert_array_equal(engine(0, optimization="random-CD").random(5), np.empty((5, 0)))
    assert e.integers(5, n=2).shape == (2, 0)


def test_d0_still_checks_its_arguments_and_refuses_what_needs_space():
    with pytest.raises(vpds.VpdsValueError, match="desc.radius = -1"):
        engine(0, radius=-1)
    with pytest.raises(ValueError, match="rule"):
        engine(0, rule="largest")
    with pytest.raises(ValueError, match="Bounds are not consistent"):
        engine(0, l_bounds=[1.0], u_bounds=[0.0])
    with pytest.raises(ValueError, match="d = 0: sizing, domain need d >= 1"):
        engine(0, sizing=lambda p: np.full(len(p), 0.1), lipschitz=0.0, domain=lambda p: p)
    e = engine(0)
    with pytest.raises(ValueError, match=r"refine\(\) needs d >= 1"):
        e.refine(0.5)
    with pytest.raises(ValueError, match=r"stats needs d >= 1"):
        _ = e.stats
    with pytest.raises(ValueError, match=r"progressive\(\) needs d >= 1"):
        e.progressive(3)
    with pytest.raises(ValueError, match=r"stream\(\) needs d >= 1"):
        next(iter(e))


@pytest.mark.parametrize("d", [-1, 2.0, True, "2", None])
def test_bad_d_is_scipys_value_error(d):
    with pytest.raises(ValueError, match="d must be a non-negative integer value"):
        qmc.PoissonDisk(d)
    with pytest.raises(ValueError, match="d must be a non-negative integer value"):
        engine(d)


def test_d_beyond_8_is_refused_and_d_8_stays_in_bounds():
    with pytest.raises(vpds.VpdsValueError, match="desc.dim = 100"):
        engine(100)
    # scipy's test_bounds at libvpds's largest d (radius 0.05 would need more than 2**40 cells
    # in the base grid at d = 8: refused with VPDS_ERR_OVERFLOW; 0.1 does not)
    x = engine(8, radius=0.1, rng=SCIPY_SEED).random(512)
    assert x.shape == (512, 8) and np.all(x >= 0) and np.all(x <= 1)


# -- optimization -------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["random-cd", "lloyd"])
def test_optimization_names_in_any_case(name):
    ref = engine(optimization=name, rng=4).random(40)
    for spelling in (name.upper(), name.title()):
        e = engine(optimization=spelling, rng=4)
        assert e.optimization == name
        np.testing.assert_array_equal(e.random(40), ref)
    with pytest.raises(ValueError, match="'toto' is not a valid optimization method"):
        engine(optimization="toto")
    with pytest.raises(ValueError, match="3 is not a valid optimization method"):
        engine(optimization=3)


def test_random_cd_swaps_coordinates_of_the_batch_and_lowers_discrepancy():
    e = engine(optimization="random-CD", rng=8, l_bounds=[-1, 2], u_bounds=[1, 5])
    x = e.random(50)
    drawn = e.points[:50]
    assert not np.array_equal(x, drawn)
    # random-cd permutes each column: the same coordinates, other pairings
    np.testing.assert_array_equal(np.sort(x, axis=0), np.sort(drawn, axis=0))
    unit = lambda s: (s - [-1, 2]) / [2, 3]  # noqa: E731
    assert qmc.discrepancy(unit(x)) < qmc.discrepancy(unit(drawn))
    # scipy's random-cd itself, with scipy's settings and a Generator seeded with the C seed
    from scipy.stats._qmc import _random_cd
    ref = _random_cd(unit(drawn), n_iters=10_000, n_nochange=100, rng=np.random.default_rng(e.seed))
    np.testing.assert_allclose(unit(x), ref, rtol=0, atol=1e-12)
    # the drawn samples keep their guarantee; the optimized ones are not promised it
    assert pdist(drawn).min() >= 0.05 * (1 - 1e-9)
    np.testing.assert_array_equal(e.reset().random(50), x)  # reset restarts its swaps too


def test_lloyd_is_scipys_in_the_box_mapped_onto_the_unit_cube():
    from scipy.stats._qmc import _lloyd_centroidal_voronoi_tessellation as lloyd
    lo, hi = np.array([-2.0, 3.0]), np.array([2.0, 4.0])
    e = engine(optimization="lloyd", rng=2, radius=0.1, l_bounds=lo, u_bounds=hi)
    x = e.random(60)
    drawn = e.points[:60]
    assert np.all(x >= lo) and np.all(x <= hi)
    moved = np.any(x != drawn, axis=1)
    assert moved.sum() > 30  # interior samples move (scipy's Lloyd keeps unbounded cells)
    np.testing.assert_allclose(x, lo + lloyd((drawn - lo) / (hi - lo)) * (hi - lo), rtol=0,
                               atol=1e-12)
    rest = e.fill_space()
    assert len(rest) == len(e.points) - 60 and not np.array_equal(rest, e.points[60:])


def test_optimization_refusals_are_clear(monkeypatch):
    with pytest.raises(ValueError, match="'lloyd' with d = 1: Lloyd's Voronoi tessellation needs d >= 2"):
        engine(1, optimization="lloyd")
    with pytest.raises(ValueError, match="a batch of 2 samples in d = 2"):
        engine(2, optimization="lloyd").random(2)
    assert engine(2, optimization="lloyd").random(0).shape == (0, 2)
    with pytest.raises(ValueError, match="with a domain"):
        engine(2, optimization="random-cd", domain=lambda p: np.linalg.norm(p - 0.5, axis=1) - 0.4)
    monkeypatch.setitem(sys.modules, "scipy.stats._qmc", None)  # as if scipy were missing
    with pytest.raises(MissingDependencyError, match=r"optimization = 'lloyd'.*pip install scipy"):
        engine(2, optimization="lloyd")
    assert engine(2).random(3).shape == (3, 2)  # without optimization scipy is not needed


# -- bounds: scipy's errors -----------------------------------------------------------------------
@pytest.mark.parametrize("l_bounds, u_bounds", [
    ([3, 2], [-1, -2, -1]), ([3, 2], [-1, -2]), ([0, 0, 0, 0], 1),  # not broadcastable to d = 3
    ([3, 2, 1], [-1, -2, -1]), ([0, 0, 1], [1, 1, 1]), ([0, np.nan, 0], 1),  # not l < u
])
def test_bad_bounds_raise_scipys_error(l_bounds, u_bounds):
    with pytest.raises(ValueError) as theirs:
        qmc.PoissonDisk(3, l_bounds=l_bounds, u_bounds=u_bounds)
    with pytest.raises(ValueError) as ours:
        engine(3, l_bounds=l_bounds, u_bounds=u_bounds)
    assert type(ours.value) is ValueError
    assert str(ours.value).startswith(str(theirs.value))  # scipy's message, then the values
    assert len(str(ours.value)) > len(str(theirs.value))


def test_bounds_broadcast_as_scipy():
    e = engine(3, l_bounds=-1, u_bounds=[1], rng=1, radius=0.3)
    np.testing.assert_array_equal(e.l_bounds, [-1, -1, -1])
    np.testing.assert_array_equal(e.u_bounds, [1, 1, 1])
    x = e.fill_space()
    assert np.all(x >= -1) and np.all(x <= 1) and x.min() < 0
    with pytest.raises(ValueError, match="l_bounds = 'a': must be numbers"):
        engine(2, l_bounds="a")


# -- scipy's other QMCEngine methods ----------------------------------------------------------------
def test_integers_fast_forward_and_random_inf(monkeypatch):
    ref = engine(rng=6).random(30)
    e = engine(rng=6)
    k = e.integers(10, n=30)
    assert k.dtype == np.int64 and k.shape == (30, 2)
    np.testing.assert_array_equal(k, np.floor(ref * 10))
    e.reset()
    k = e.integers([-3, 0], u_bounds=[3, 1], endpoint=True, n=30)
    np.testing.assert_array_equal(k, np.floor(ref * [7, 2] + [-3, 0]))
    on_faces = engine(2, l_bounds=[1, 1], u_bounds=[2, 3])
    monkeypatch.setattr(on_faces, "random", lambda n, workers=1: np.array([[2.0, 1.0]]))
    np.testing.assert_array_equal(on_faces.integers(4), [[3, 0]])  # the box is closed
    with pytest.raises(ValueError, match="must be integers or array-like of integers"):
        e.integers(2.5)
    with pytest.raises(ValueError, match="Bounds are not consistent"):
        e.integers(3, u_bounds=[1, 4])
    f = engine(rng=6).fast_forward(10)
    np.testing.assert_array_equal(f.random(20), ref[10:])
    np.testing.assert_array_equal(engine(rng=6).random(np.inf), engine(rng=6).fill_space())
    with pytest.raises(ValueError, match="n = 2.5: must be an integer"):
        e.random(2.5)
