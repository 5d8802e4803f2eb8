"""Bad arguments to the Python API: each refused before the C library sees it, by an exception
that names the argument and its value; never a read past an array's end, a bare float() or
int() error, or a run that cannot fit in memory started anyway."""
import sys

import numpy as np
import pytest

import vpds


def constant(x):
    return np.full(len(x), 0.05)


@pytest.mark.parametrize("periodic, says", [
    ([1], r"periodic = \[1\]: give one flag per axis, 2 for d = 2"),
    ([True, False, True], "give one flag per axis, 2 for d = 2"),
    ("x", "periodic = 'x': give one flag per axis"),
    (True, "periodic = True: give one flag per axis"),
    ([5, 0], "axis 0 has 5; each flag must be True or False"),
    ([-1, 1], "axis 0 has -1"),
])
def test_periodic_needs_one_flag_per_axis(periodic, says):
    # cffi made an int array of len(periodic) and C read d entries from it
    with pytest.raises(ValueError, match=says):
        vpds.PoissonDisk(2, radius=0.3, periodic=periodic)


def test_periodic_flags_that_fit_are_taken():
    pts = vpds.PoissonDisk(2, radius=0.2, periodic=[True, 0], rng=3, progress=False).fill_space()
    assert len(pts) > 0
    # the periodic axis wraps: the gap across x = 0 / x = 1 is respected like any other
    gaps = np.abs(pts[:, None, 0] - pts[None, :, 0])
    d2 = np.minimum(gaps, 1 - gaps) ** 2 + (pts[:, None, 1] - pts[None, :, 1]) ** 2
    np.fill_diagonal(d2, np.inf)
    assert d2.min() >= 0.2 ** 2 * (1 - 1e-12)


def test_sizing_grid_checks_its_bounds_and_points():
    with pytest.raises(ValueError, match=r"lo = \[0, 0\]: 2 values for a grid of 3 axes"):
        vpds.SizingGrid(np.full((2, 2, 2), 0.05), [0, 0], [1, 1, 1])
    with pytest.raises(ValueError, match=r"hi = \[1\]: 1 values for a grid of 2 axes"):
        vpds.SizingGrid(np.full((2, 2), 0.05), [0, 0], [1])
    with pytest.raises(ValueError, match="grid values: not an array of numbers"):
        vpds.SizingGrid(np.array([["a", "b"], ["c", "d"]]), [0, 0], [1, 1])
    g = vpds.SizingGrid(np.array([[0.05, 0.05], [0.1, 0.1]]), [0, 0], [1, 1])
    with pytest.raises(ValueError, match=r"x: shape \(1,\), expected \(m, 2\) or \(2,\)"):
        g(np.array([0.5]))
    with pytest.raises(ValueError, match=r"x: shape \(1, 3\), expected \(m, 2\)"):
        g(np.array([[0.5, 0.5, 0.5]]))
    assert g(np.array([0.5, 0.5]))[0] == pytest.approx(0.075)
    assert g.dim == 2


def test_a_grid_of_other_axes_than_d_is_refused():
    with pytest.raises(ValueError, match="sizing: a grid of 3 axes for d = 2"):
        vpds.PoissonDisk(2, sizing=np.full((2, 2, 2), 0.05))
    grid = vpds.SizingGrid(np.full((2, 2, 2), 0.05), [0, 0, 0], [1, 1, 1])
    with pytest.raises(ValueError, match="sizing: a grid of 3 axes for d = 2"):
        vpds.PoissonDisk(2, sizing=grid)


def test_a_sizing_callable_cannot_move_the_darts():
    def moves(x):
        x[:, 0] = 5.0  # the library's own dart buffer: a write moved the samples out of the box
        return np.full(len(x), 0.05)
    with pytest.raises(ValueError, match="read-only"):
        vpds.PoissonDisk(2, sizing=moves, lipschitz=0.1, rng=1, progress=False).random(5)
    pts = vpds.PoissonDisk(2, sizing=constant, lipschitz=0.1, rng=1, progress=False).random(5)
    assert pts.shape == (5, 2) and (pts >= 0).all() and (pts <= 1).all()


@pytest.mark.parametrize("kwargs, error, says", [
    ({"radius": "a"}, TypeError, "radius = 'a': must be a number"),
    ({"radius": None}, TypeError, "radius = None: must be a number"),
    ({"radius": [0.1, 0.2]}, TypeError, r"radius = \[0.1, 0.2\]: must be a number \(radii that vary: sizing="),
    ({"inhibition": "x"}, TypeError, "inhibition = 'x': must be a number"),
    ({"coverage": [1]}, TypeError, r"coverage = \[1\]: must be a number"),
    ({"sizing": constant, "lipschitz": "a"}, TypeError, "lipschitz = 'a': must be a number"),
    # -1 is the C library's "not given": it read as a missing lipschitz
    ({"sizing": constant, "lipschitz": -1}, ValueError, "lipschitz = -1: must be >= 0"),
    ({"radius_max": "big"}, TypeError, "radius_max = 'big': must be a number"),
    ({"domain": np.ones((4, 4)), "domain_threshold": "a"}, TypeError, "domain_threshold = 'a'"),
    ({"fixed_points": np.zeros((3, 5))}, ValueError, r"fixed_points: shape \(3, 5\), expected \(k, 2\)"),
    ({"fixed_points": np.zeros((2, 2, 2))}, ValueError, r"fixed_points: shape \(2, 2, 2\)"),
    ({"fixed_points": np.zeros((2, 2)), "fixed_radii": [0.1]}, ValueError, r"fixed_radii: shape \(1,\), expected \(2,\)"),
    ({"sizing": constant, "sizing_grid_shape": (-4, 4)}, ValueError, r"sizing_grid_shape = \(-4, 4\): give d = 2 integers >= 2"),
    ({"sizing": constant, "sizing_grid_shape": (4.7, 4)}, ValueError, r"sizing_grid_shape = \(4.7, 4\)"),
    ({"sizing": constant, "sizing_grid_shape": (4,)}, ValueError, r"sizing_grid_shape = \(4,\)"),
    ({"tiles": -1}, ValueError, "tiles = -1: each count must be an int from 1"),
    ({"tiles": [2, -2]}, ValueError, r"tiles = \[2, -2\]"),
    ({"tiles": 2 ** 70}, ValueError, "tiles = 1180591620717411303424"),
    ({"tiles": 2.5}, ValueError, "tiles = 2.5"),
    ({"tiles": [1, 2, 3]}, ValueError, "give 1 or 2 tile counts"),
])
def test_constructor_arguments_are_named(kwargs, error, says):
    with pytest.raises(error, match=says):
        vpds.PoissonDisk(2, **kwargs)


def test_arguments_that_fit_still_work():
    one = vpds.PoissonDisk(2, radius=0.2, fixed_points=[0.5, 0.5], rng=1, progress=False)
    one.fill_space()
    assert np.array_equal(one.points[0], [0.5, 0.5]) and one.fixed[0] and not one.fixed[1:].any()
    grid = vpds.PoissonDisk(2, sizing=constant, sizing_grid_shape=[4, 4], rng=1, progress=False)
    assert len(grid.fill_space()) > 0
    tiled = vpds.PoissonDisk(2, radius=0.05, tiles=(2, 3), rng=1, progress=False).fill_space()
    assert len(tiled) > 0


@pytest.mark.parametrize("call, error, says", [
    (lambda e: e.random("a"), TypeError, "n = 'a': must be an integer number of samples"),
    (lambda e: e.random(None), TypeError, "n = None"),
    (lambda e: e.random(1.5), ValueError, "n = 1.5: must be an integer"),
    (lambda e: e.progressive(1.5), ValueError, "n = 1.5: must be an integer"),
    (lambda e: e.progressive(-2), ValueError, "n = -2: must be >= 0"),
    (lambda e: e.refine("a"), TypeError, "t = 'a': must be a number"),
    (lambda e: e.add_points(np.zeros((3, 3))), ValueError, r"x: shape \(3, 3\), expected \(k, 2\)"),
    (lambda e: e.add_points(np.zeros((2, 2)), r=[0.1, 0.1, 0.1]), ValueError, r"r: shape \(3,\), expected \(2,\)"),
])
def test_method_arguments_are_named(call, error, says):
    with pytest.raises(error, match=says):
        call(vpds.PoissonDisk(2, radius=0.2, progress=False))


def test_a_stream_that_cannot_fit_is_refused_before_it_starts():
    engine = vpds.PoissonDisk(2, radius=0.1, memory_limit=10 ** 6)
    # 10^6 samples hold at least 58 bytes each (points, radii and scales): past 1 MB
    with pytest.raises(MemoryError, match=r"progressive\(n=1000000\): 1e\+06 samples need at least .* memory_limit"):
        engine.progressive(10 ** 6)
    with pytest.raises(MemoryError, match="more than the memory available|more than memory_limit"):
        vpds.PoissonDisk(2).progressive(2 ** 70)
    assert len(engine.progressive(100).points) == 100  # what fits still runs


SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
SQUARE_F = np.array([[0, 1, 2], [1, 3, 2]])


def test_a_mesh_run_that_cannot_fit_is_refused_before_it_starts():
    # the unit square at r = 1e-7 holds at least 1 / (pi 1e-14) = 3.2e13 samples
    with pytest.raises(MemoryError, match=r"run\(\): 3.183e\+13 samples \(at least"):
        vpds.sample_mesh(SQUARE_V, SQUARE_F, radius=1e-7)
    with pytest.raises(MemoryError, match=r"refine\(1e-06\)"):
        vpds.MeshSampler(SQUARE_V, SQUARE_F, radius=0.05).refine(1e-6)
    with pytest.raises(MemoryError, match=r"progressive\(n=1000000000000\)"):
        vpds.sample_mesh(SQUARE_V, SQUARE_F, radius=0.05, n=10 ** 12)
    with pytest.raises(MemoryError, match="samples"):
        vpds.sample_mesh(SQUARE_V, SQUARE_F, vertex_radii=[1e-8] * 4)
    assert len(vpds.sample_mesh(SQUARE_V, SQUARE_F, radius=0.05, rng=1).points) > 200


@pytest.mark.parametrize("kwargs, error, says", [
    ({"radius": "a"}, TypeError, "radius = 'a': must be a number"),
    ({"t": "a"}, TypeError, "t = 'a': must be a number"),
    ({"inhibition": None}, TypeError, "inhibition = None"),
    ({"sizing": constant, "lipschitz": -1}, ValueError, "lipschitz = -1: must be >= 0"),
])
def test_mesh_arguments_are_named(kwargs, error, says):
    with pytest.raises(error, match=says):
        vpds.sample_mesh(SQUARE_V, SQUARE_F, **kwargs)


def test_a_callable_returning_none_is_named_so():
    # np.asarray(None, float) is NaN: the message said the domain returned NaN
    with pytest.raises(vpds.VpdsDomainError, match="domain returned None, not numbers") as info:
        vpds.PoissonDisk(2, radius=0.1, domain=lambda x: None, progress=False).fill_space()
    assert "returned NaN" not in str(info.value)
    with pytest.raises(vpds.VpdsDomainError, match=r"domain called at x = .*returned shape \(2,\)") as info:
        vpds.PoissonDisk(2, radius=0.1, domain=lambda x: np.zeros(2), progress=False).fill_space()
    assert "returned NaN" not in str(info.value)
    with pytest.raises(vpds.VpdsSizingError, match="sizing returned None"):
        vpds.PoissonDisk(2, sizing=lambda x: None, lipschitz=0.1, progress=False).fill_space()
    # a NaN the callable did return is still called NaN
    with pytest.raises(vpds.VpdsDomainError, match="domain returned NaN at x"):
        vpds.PoissonDisk(2, radius=0.1, domain=lambda x: np.full(len(x), np.nan), progress=False).fill_space()


def test_estimate_radius_arguments():
    with pytest.raises(ValueError, match=r"d = 1.5: must be in 1..16 \(an int\)"):
        vpds.estimate_radius(100, d=1.5)
    with pytest.raises(TypeError, match="n = 'a': must be a number"):
        vpds.estimate_radius("a", 2)


def test_a_missing_cloudpickle_is_named(monkeypatch):
    monkeypatch.setitem(sys.modules, "cloudpickle", None)  # import cloudpickle now fails
    engine = vpds.PoissonDisk(2, sizing=constant, lipschitz=0.1, radius_max=0.05, workers=2, progress=False)
    with pytest.raises(ImportError, match=r"workers or tiles with a sizing callable needs cloudpickle \(pip install cloudpickle\)"):
        engine.fill_space()
