"""The hierarchy of Section 4 (discrete refinement and the continuous stream), two radii
(Section 3) and periodic boxes, through the Python API, checked by vpds.analysis (written from
the paper, independent of the C code).

Definitions (vpds.h): at scale t a point y conflicts with an earlier sample x_i when
|y - x_i| < t inhibition f(x_i, y), and is covered when |y - x_i| <= t coverage f(x_i, y). The
stream promises that every prefix {k : t_k >= tau} is conflict-free and maximal at tau, to the
relative tolerance vpds.STREAM_TOLERANCE on the conflict side (t is reported as an upper bound).

The last group tests the checkers themselves, on hand-made farthest-point streams, so that a
passing run above means something.
"""
import itertools
import math

import numpy as np
import pytest

import vpds
from vpds import analysis as C


TOL = vpds.STREAM_TOLERANCE
N_STREAM = 10_000


# -- sizings --------------------------------------------------------------------------------------

def const(radius):
    return C.sizing_named("const", radius)


def ramp(base=0.01, slope=0.02):
    """r(x) = base + slope x0 on the unit box, L = slope."""
    return C.Sizing(lambda y: base + slope * y[:, 0], slope)


def wave():
    """r = 0.02 + 0.01 sin^2(2 pi x0): periodic on [0, 1], r' = 0.01 2 pi sin(4 pi x0)."""
    return C.Sizing(lambda y: 0.02 + 0.01 * np.sin(2 * np.pi * y[:, 0]) ** 2, 0.02 * np.pi)


def engine(d, sizing, radius=None, **kw):
    """A PoissonDisk on the unit box: a uniform radius, or the sizing's callable with its L."""
    kw.setdefault("progress", False)
    if radius is not None:
        return vpds.PoissonDisk(d, radius=radius, **kw)
    return vpds.PoissonDisk(d, sizing=sizing.fn, lipschitz=sizing.lipschitz, **kw)


def take(pd, n):
    """n samples of the stream as arrays, checked against what the sampler then holds."""
    before = len(pd.points)
    pairs = list(itertools.islice(pd.stream(), n))
    assert len(pairs) == n
    x = np.array([p for p, _ in pairs])
    t = np.array([s for _, s in pairs])
    np.testing.assert_array_equal(pd.points[before:], x)
    np.testing.assert_array_equal(pd.scales[before:], t)
    return x, t


def unit(d):
    return np.zeros(d), np.ones(d)


def in_box(x, lo, hi, periodic=None):
    """Inside [lo, hi], and below hi on the periodic axes (hi is lo there)."""
    per = np.zeros(len(lo), bool) if periodic is None else np.asarray(periodic, bool)
    return bool(np.all((x >= lo) & (x <= hi) & ((x < hi) | ~per)))


def critical(t, ks):
    """Just above t_k: the prefix of the samples before x_k, at the smallest scale where it
    must still be maximal (the hardest tau for that prefix)."""
    return [float(np.nextafter(t[k], np.inf)) for k in ks]


def assert_prefix_report(rep, bnb_unresolved=1e-7):
    assert rep.nonincreasing, f"t increases at sample {rep.first_increase}"
    assert rep.conflicts_at_insertion == 0, "a pair closer than the later sample's scale allows"
    for p in rep.taus:
        assert p.conflicts == 0, f"tau = {p.tau!r}: {p.conflicts} conflicts in {p.size} samples"
        assert p.gaps == 0, f"tau = {p.tau!r}: gap near {p.worst_gap} ({p.size} samples, " \
                            f"{'B&B' if p.exhaustive else 'probes'})"
        if p.exhaustive:
            assert p.worst <= bnb_unresolved, p


# -- the continuous stream ------------------------------------------------------------------------

STREAMS = [  # (d, sizing, radius, rule, inhibition); a 3D stream of 10^4 costs ~40 s
    (2, "const", 0.01, "smaller", 1.0),
    (2, "const", 0.01, "smaller", 0.5),
    (2, "ramp", None, "smaller", 1.0),
    (2, "ramp", None, "prior", 0.5),
    (3, "const", 0.05, "smaller", 1.0),
    (3, "ramp", None, "prior", 0.5),
]


@pytest.mark.parametrize("d,sizing_name,radius,rule,inhibition", STREAMS)
def test_stream_prefix_property(d, sizing_name, radius, rule, inhibition):
    """10^4 samples: every prefix {k : t_k >= tau} conflict-free at tau inhibition (1 - tol) and
    maximal at tau coverage; probes at many random and critical taus, the branch-and-bound at a
    few critical ones; and t is the event, not a loose bound (just below it, a gap)."""
    sizing = const(radius) if sizing_name == "const" else ramp()
    pd = engine(d, sizing, radius, rule=rule, inhibition=inhibition, coverage=1.0, rng=20 + d)
    x, t = take(pd, N_STREAM)
    lo, hi = unit(d)
    r = pd.radii
    assert math.isinf(t[0]) and np.all(np.isfinite(t[1:]))
    assert in_box(x, lo, hi)
    np.testing.assert_allclose(r, sizing.fn(x), rtol=1e-12)
    rng = np.random.default_rng(d * 7 + int(inhibition * 10))
    # random taus, log-uniform between the last t and that of the 3rd sample, and critical ones
    taus = list(np.exp(rng.uniform(np.log(t[-1]), np.log(t[2]), 40)))
    taus += critical(t, rng.integers(2, N_STREAM, 20)) + [float(t[-1])]
    ks = [int(rng.integers(N_STREAM // 20, N_STREAM // 4)), N_STREAM - 1]
    if d == 2:
        ks.insert(1, int(rng.integers(N_STREAM // 4, N_STREAM - 1)))
    rep = C.check_prefixes(x, r, t, rule, inhibition, 1.0, sizing, lo, hi, taus, TOL,
                           bnb_taus=critical(t, ks), probes=5000, seed=d)
    assert_prefix_report(rep)
    # t_k is the scale where the samples before x_k stop being maximal: slightly below, a gap
    k = ks[0]
    below = C.check_maximal(x[:k], r[:k], rule, t[k] * (1 - 10 * TOL), sizing, lo, hi,
                            probes=1000, stop_at_gap=True)
    assert below.gaps > 0, f"t_{k} = {t[k]} is not where the prefix stops being maximal"


@pytest.mark.parametrize("d,n", [(2, 1500), (3, 600)])
def test_equal_radii_stream_is_farthest_point_insertion(d, n):
    """inhibition == coverage: the first point is random (t = inf), then each point is the
    farthest point of the box from the earlier ones and t_k its distance over coverage r."""
    radius, cov = 0.05, 1.0
    pd = engine(d, None, radius, inhibition=cov, coverage=cov, rng=3)
    x, t = take(pd, n)
    lo, hi = unit(d)
    assert math.isinf(t[0])
    # from one point the farthest point of a box is a corner (to the stream's tolerance)
    assert np.all(np.minimum(x[1], 1 - x[1]) <= 100 * TOL * t[1] * cov * radius), x[1]
    np.testing.assert_allclose(t[1] * cov * radius, np.linalg.norm(x[1] - x[0]), rtol=TOL)
    # a dense grid: no probe farther than t_k cov r from the samples before x_k
    m = 301 if d == 2 else 41
    grid = np.stack(np.meshgrid(*[np.linspace(0, 1, m)] * d, indexing="ij"), -1).reshape(-1, d)
    near = np.full(len(grid), np.inf)
    worst_probe = 0.0
    for k in range(1, n):
        near = np.minimum(near, np.linalg.norm(grid - x[k - 1], axis=1))
        reach = t[k] * cov * radius
        worst_probe = max(worst_probe, near.max() / reach)
        gap = np.linalg.norm(x[:k] - x[k], axis=1).min()
        assert gap >= reach * (1 - TOL), f"x_{k} at {gap} from the earlier samples, t says {reach}"
    assert worst_probe <= 1 + 1e-12
    # exactly (the largest empty ball, from Delaunay circumcentres) at some k
    rng = np.random.default_rng(d)
    for k in sorted(set(range(1, 12)) | set(rng.integers(12, n, 25).tolist())):
        _, R = C.largest_empty_ball(x[:k], lo, hi)
        reach = t[k] * cov * radius
        assert R <= reach * (1 + 1e-12), f"k = {k}: a point at {R} > t_k r = {reach}"
        assert R >= reach * (1 - TOL), f"k = {k}: t_k r = {reach} is loose (farthest {R})"
    other = engine(d, None, radius, inhibition=cov, coverage=cov, rng=4)
    x2, _ = take(other, 2)
    assert not np.array_equal(x2[0], x[0])


@pytest.mark.parametrize("inhibition,sizing_name,n", [(1.0, "const", 2000), (0.5, "const", 2000),
                                                      (0.5, "ramp", 600)])
def test_stream_is_deterministic_by_seed(inhibition, sizing_name, n):
    """Same seed, same bytes (points and t); another seed, other bytes; and a stream taken in
    two pieces is the same stream."""
    sizing = const(0.02) if sizing_name == "const" else ramp()
    radius = 0.02 if sizing_name == "const" else None

    def run(seed):
        pd = engine(2, sizing, radius, inhibition=inhibition, rng=seed)
        x, t = take(pd, n)
        return x.tobytes() + t.tobytes()

    a = run(11)
    assert run(11) == a
    assert run(12) != a
    pd = engine(2, sizing, radius, inhibition=inhibition, rng=11)
    x1, t1 = take(pd, n // 3)
    x2, t2 = take(pd, n - n // 3)
    assert np.concatenate([x1, x2]).tobytes() + np.concatenate([t1, t2]).tobytes() == a


# -- discrete refinement --------------------------------------------------------------------------


def assert_level(x, r, scales, rule, t, inhibition, coverage, sizing, lo, hi, periodic=None):
    """The whole set after a refinement to t: conflict-free at t inhibition in insertion order
    (and each pair at its later sample's scale), maximal at t coverage."""
    L = sizing.lipschitz
    assert C.empty_disk_violations(x, r, rule, t * inhibition, L, periodic=periodic,
                                   lo=lo, hi=hi) == 0
    assert C.conflicts_at_insertion_scales(x, r, scales, rule, inhibition, L, 1e-12,
                                           periodic=periodic, lo=lo, hi=hi) == 0
    rep = C.check_maximal(x, r, rule, t * coverage, sizing, lo, hi, probes=20_000,
                          periodic=periodic)
    assert rep.gaps == 0, f"t = {t}: uncovered point near {rep.worst_gap}"
    assert rep.unresolved_bound <= 1e-7
    return rep


def refine_levels(pd, levels):
    """fill_space at t = 1, then refine to each level: yields (t, points, radii, scales) after
    each, checking that earlier samples never move and that new ones carry the level's t."""
    pd.fill_space()
    prev = pd.points
    assert len(prev) and np.all(pd.scales == 1.0)
    yield 1.0, prev, pd.radii, pd.scales
    for t in levels:
        new = pd.refine(t)
        x = pd.points
        np.testing.assert_array_equal(x[: len(prev)], prev, err_msg=f"refine({t}) moved samples")
        np.testing.assert_array_equal(x[len(prev):], new)
        assert len(new) > 0
        np.testing.assert_array_equal(pd.scales[len(prev):], t)
        yield t, x, pd.radii, pd.scales
        prev = x


def test_figure7_two_radii_refinement(capsys):
    """Figure 7: radius 0.05, inhibition 0.5, coverage 1, refined to t = 0.8, 0.6, 0.4, 0.2;
    Prop. 4.1-4.2 on interior Delaunay triangles: smallest angle >= arcsin(1/4) = 14.48 deg."""
    radius, inh, cov = 0.05, 0.5, 1.0
    pd = engine(2, None, radius, inhibition=inh, coverage=cov, rng=7)
    lo, hi = unit(2)
    sizing = const(radius)
    angles = []
    for t, x, r, scales in refine_levels(pd, [0.8, 0.6, 0.4, 0.2]):
        assert np.all(r == radius)
        assert_level(x, r, scales, "smaller", t, inh, cov, sizing, lo, hi)
        rep = C.check_delaunay_two_radii(x, radius, t, inh, cov, lo, hi)
        assert rep.triangles > 20
        assert rep.angle_bound_deg == pytest.approx(math.degrees(math.asin(0.25)))
        assert not rep.violations(), rep
        angles.append((t, len(x), rep.min_angle_deg))
    with capsys.disabled():
        print("\nFigure 7 (inhibition 0.5, coverage 1): smallest interior Delaunay angle, bound "
              f"{math.degrees(math.asin(0.25)):.2f} deg")
        for t, n, a in angles:
            print(f"  t = {t:.1f}: {n:6d} samples, {a:.2f} deg")


@pytest.mark.parametrize("rule,inhibition", [(r, 0.5) for r in C.RULES] +
                         [("prior", 1.0), ("smaller", 1.0)])
def test_discrete_refinement_variable_radius(rule, inhibition):
    """Every rule with r = 0.03 + 0.06 x0 (L = 0.06; t coverage L < 1/2 for prior and bigger):
    after each refinement the whole set is conflict-free and maximal at that scale."""
    sizing = ramp(0.03, 0.06)
    pd = engine(2, sizing, rule=rule, inhibition=inhibition, coverage=1.0, rng=5)
    lo, hi = unit(2)
    for t, x, r, scales in refine_levels(pd, [0.7, 0.5]):
        np.testing.assert_allclose(r, sizing.fn(x), rtol=1e-12)
        assert_level(x, r, scales, rule, t, inhibition, 1.0, sizing, lo, hi)


# -- periodic boxes -------------------------------------------------------------------------------

PERIODIC = [([True, True], "const"), ([True, True], "wave"), ([True, False], "const"),
            ([True, False], "wave")]


def periodic_case(sizing_name):
    return (const(0.03), 0.03) if sizing_name == "const" else (wave(), None)


@pytest.mark.parametrize("periodic,sizing_name", PERIODIC)
def test_periodic_run_and_refine(periodic, sizing_name):
    """Toroidal empty-disk and maximality after a run and a refinement (two radii), and the
    3x3 (3x1) tiled copy is itself a valid sampling across the seams."""
    sizing, radius = periodic_case(sizing_name)
    inh = 0.5
    pd = engine(2, sizing, radius, periodic=periodic, inhibition=inh, coverage=1.0, rng=9)
    lo, hi = unit(2)
    for t, x, r, scales in refine_levels(pd, [0.6]):
        assert in_box(x, lo, hi, periodic)
        np.testing.assert_allclose(r, sizing.fn(x), rtol=1e-12)
        assert_level(x, r, scales, "smaller", t, inh, 1.0, sizing, lo, hi, periodic)
        tiled = C.check_tiling(x, r, "smaller", sizing, lo, hi, periodic, t * inh, t)
        assert tiled.copies == 3 ** sum(periodic)
        assert tiled.conflicts == 0
        assert tiled.maximality.gaps == 0 and tiled.maximality.unresolved_bound <= 1e-7
    # the seams are used: some pairs are within 2 t f of each other only across a seam
    wrapped = C.empty_disk_violations(x, r, "smaller", 2 * t, sizing.lipschitz)
    toroidal = C.empty_disk_violations(x, r, "smaller", 2 * t, sizing.lipschitz,
                                       periodic=periodic, lo=lo, hi=hi)
    assert toroidal > wrapped


@pytest.mark.parametrize("periodic,sizing_name,inhibition",
                         [([True, True], "const", 1.0), ([True, True], "wave", 0.5),
                          ([True, False], "wave", 1.0)])
def test_periodic_stream(periodic, sizing_name, inhibition):
    """The prefix property on the torus; a prefix's tiled copy is a valid sampling."""
    sizing, radius = periodic_case(sizing_name)
    pd = engine(2, sizing, radius, periodic=periodic, inhibition=inhibition, rng=13)
    n = 3000
    x, t = take(pd, n)
    lo, hi = unit(2)
    r = pd.radii
    assert math.isinf(t[0]) and in_box(x, lo, hi, periodic)
    rng = np.random.default_rng(1)
    taus = list(np.exp(rng.uniform(np.log(t[-1]), np.log(t[2]), 25)))
    taus += critical(t, rng.integers(2, n, 15))
    ks = [int(rng.integers(n // 4, n // 2)), n - 1]
    rep = C.check_prefixes(x, r, t, "smaller", inhibition, 1.0, sizing, lo, hi, taus, TOL,
                           periodic, bnb_taus=critical(t, ks), probes=5000)
    assert_prefix_report(rep)
    k = ks[0]
    tau = critical(t, [k])[0]
    tiled = C.check_tiling(x[:k], r[:k], "smaller", sizing, lo, hi, periodic,
                           tau * inhibition * (1 - TOL), tau)
    assert tiled.conflicts == 0
    assert tiled.maximality.gaps == 0 and tiled.maximality.unresolved_bound <= 1e-7


# -- the checkers themselves ----------------------------------------------------------------------


def farthest_point_stream(n, radius, inhibition, coverage, lo, hi, periodic=None, seed=0):
    """A stream made by hand: x_0 uniform (t = inf); then y* the exact farthest point of the box
    (toroidal with periodic axes), t = |y* - X| / (coverage r); the sample is y* with equal
    radii, else uniform by rejection over the ball about y* of radius t coverage r, among the
    points R_f-free at t (the two-radii process of Section 3 at the event)."""
    rng = np.random.default_rng(seed)
    d = len(lo)
    x, t = [lo + rng.random(d) * (hi - lo)], [math.inf]
    for _ in range(n - 1):
        prev = np.array(x)
        y, R = C.largest_empty_ball(prev, lo, hi, periodic)
        tk = R / (coverage * radius)
        p = y
        while inhibition != coverage:
            u = rng.normal(size=d)
            p = C.wrap_points((y + u / np.linalg.norm(u) * rng.random() ** (1 / d) * R)[None],
                              lo, hi, periodic)[0]
            free = C.toroidal_distance(prev, p, lo, hi, periodic).min() >= tk * inhibition * radius
            if free and np.all((p >= lo) & (p <= hi)):
                break
        x.append(p)
        t.append(tk)
    # symmetric ties on a torus may differ by an ulp
    return np.array(x), np.minimum.accumulate(np.array(t))


@pytest.fixture(scope="module")
def hand_streams():
    lo, hi = unit(2)
    return {(inh, per): farthest_point_stream(260, 0.05, inh, 1.0, lo, hi,
                                              None if per is None else list(per), seed=3)
            for inh in (1.0, 0.5) for per in (None, (True, True), (True, False))}


def test_largest_empty_ball_against_probes():
    rng = np.random.default_rng(2)
    for d, periodic in [(2, None), (2, [True, True]), (2, [False, True]), (3, None),
                        (3, [True, False, True])]:
        lo, hi = np.zeros(d), np.array([1.0, 0.7, 1.3][:d])
        for n in (1, 3, 50, 400):
            x = lo + rng.random((n, d)) * (hi - lo)
            y, R = C.largest_empty_ball(x, lo, hi, periodic)
            assert np.all((y >= lo) & (y <= hi))
            assert C.toroidal_distance(x, y, lo, hi, periodic).min() == pytest.approx(R, rel=1e-12)
            m = 150 if d == 2 else 30
            g = np.stack(np.meshgrid(*[np.linspace(lo[k], hi[k], m) for k in range(d)],
                                     indexing="ij"), -1).reshape(-1, d)
            dist = np.min([C.toroidal_distance(g, p, lo, hi, periodic) for p in x], axis=0)
            assert dist.max() <= R * (1 + 1e-12)
            assert R - dist.max() <= 0.5 * np.linalg.norm((hi - lo) / (m - 1))


@pytest.mark.parametrize("inhibition", [1.0, 0.5])
@pytest.mark.parametrize("periodic", [None, (True, True), (True, False)])
def test_check_prefixes_accepts_a_hand_made_stream_and_sees_its_faults(hand_streams, inhibition,
                                                                        periodic):
    x, t = hand_streams[(inhibition, periodic)]
    per = None if periodic is None else list(periodic)
    lo, hi = unit(2)
    n, r, sizing = len(x), np.full(len(x), 0.05), const(0.05)
    rng = np.random.default_rng(0)
    taus = list(rng.uniform(t[-1], t[3], 20)) + critical(t, rng.integers(2, n, 10))
    ks = [50, 150, 220, n - 1]
    rep = C.check_prefixes(x, r, t, "smaller", inhibition, 1.0, sizing, lo, hi, taus, 1e-9, per,
                           bnb_taus=critical(t, ks), probes=3000)
    assert rep.ok, rep.failures()
    assert_prefix_report(rep, bnb_unresolved=1e-7)
    # a t reported 1% below the event: the prefix before it is not maximal just above it
    k = 150
    low = t.copy()
    low[k:] = np.minimum(low[k:], t[k] * 0.99)
    bad = C.check_prefixes(x, r, low, "smaller", inhibition, 1.0, sizing, lo, hi, [], 1e-9, per,
                           bnb_taus=critical(low, [k]), probes=1000)
    assert bad.nonincreasing and bad.taus[0].gaps > 0 and not bad.ok
    # two samples swapped: t increases
    sw = np.r_[0:k, k + 1, k, k + 2:n]
    assert not C.check_prefixes(x[sw], r, t[sw], "smaller", inhibition, 1.0, sizing, lo, hi,
                                [], 1e-9, per).nonincreasing
    # a point inside an earlier sample's inhibition disk at its own scale: a conflict
    y = C.wrap_points((x[k] + 0.9 * t[k] * inhibition * 0.05 * np.array([0.6, 0.8]))[None],
                      lo, hi, per)
    y[0] = np.clip(y[0], lo, hi)
    xc = np.vstack([x[: k + 1], y, x[k + 1:]])
    tc = np.r_[t[: k + 1], t[k], t[k + 1:]]
    rc = np.full(len(xc), 0.05)
    bad = C.check_prefixes(xc, rc, tc, "smaller", inhibition, 1.0, sizing, lo, hi, [t[k]], 1e-9,
                           per, bnb_taus=[t[k]], probes=1000)
    assert bad.conflicts_at_insertion >= 1
    assert bad.taus[0].conflicts >= 1 and bad.taus[1].conflicts >= 1


def test_checkers_find_a_gap_and_a_conflict():
    """On a library output (a plain run) and on a hand-made two-radii stream prefix: one sample
    removed leaves a gap, one point added next to a sample makes a conflict."""
    pd = engine(2, None, 0.04, rng=1)
    x = pd.fill_space()
    r = pd.radii
    lo, hi = unit(2)
    sizing = const(0.04)
    assert C.check_maximal(x, r, "smaller", 1.0, sizing, lo, hi).gaps == 0
    keep = np.arange(len(x)) != len(x) // 2
    assert C.check_maximal(x[keep], r[keep], "smaller", 1.0, sizing, lo, hi).gaps > 0
    x2 = np.vstack([x, x[7] + [0.03, 0.0]])
    assert C.empty_disk_violations(x2, np.append(r, 0.04), "smaller", 1.0, 0.0) >= 1


def test_periodic_checkers_see_the_seam(hand_streams):
    lo, hi = unit(2)
    sizing = const(0.05)
    a = np.array([[0.002, 0.5], [0.998, 0.5]])
    np.testing.assert_allclose(C.toroidal_distance(a[0], a[1], lo, hi, [True, False]), 0.004)
    # a conflict across the seam x0 = 0 = 1, invisible without the wrap
    r = np.full(2, 0.01)
    assert C.empty_disk_violations(a, r, "smaller", 1.0, 0.0) == 0
    assert C.empty_disk_violations(a, r, "smaller", 1.0, 0.0, periodic=[True, False],
                                   lo=lo, hi=hi) == 1
    assert C.empty_disk_violations(a, r, "smaller", 1.0, 0.0, periodic=[False, True],
                                   lo=lo, hi=hi) == 0
    # the same, as the last sample of a periodic stream, and in the tiled copy
    x, t = hand_streams[(1.0, (True, True))]
    per = [True, True]
    k = 120
    tau = t[k]
    cover = np.nextafter(tau, np.inf)
    reach = tau * 0.05
    # translate the torus (a valid set stays valid) to put a sample just right of the seam
    prefix = C.wrap_points(x[:k] - [x[0, 0] - 0.2 * reach, 0.0], lo, hi, per)
    rs = np.full(k + 1, 0.05)
    y = np.array([[prefix[0, 0] - 0.5 * reach + 1.0, prefix[0, 1]]])  # 0.5 reach away, wrapped
    xs = np.vstack([prefix, y])
    flat = C.empty_disk_violations(xs, rs, "smaller", tau, 0.0)
    assert C.empty_disk_violations(xs, rs, "smaller", tau, 0.0, periodic=per, lo=lo, hi=hi) > flat
    assert C.check_tiling(xs, rs, "smaller", sizing, lo, hi, per, tau, cover).conflicts >= 1
    clean = C.check_tiling(prefix, rs[:k], "smaller", sizing, lo, hi, per, tau * (1 - 1e-9), cover)
    assert clean.conflicts == 0 and clean.maximality.gaps == 0
    # a gap on the seam (two-radii stream): drop the samples within 1.2 t r of (0, 0.5)
    x, t = hand_streams[(0.5, (True, True))]
    tau = t[k]
    cover = np.nextafter(tau, np.inf)
    reach = tau * 0.05
    prefix, r = x[:k], np.full(k, 0.05)
    keep = C.toroidal_distance(prefix, [0.0, 0.5], lo, hi, per) > 1.2 * reach
    assert 0 < np.count_nonzero(~keep) < 10
    assert C.check_maximal(prefix, r, "smaller", cover, sizing, lo, hi, periodic=per).gaps == 0
    assert C.check_maximal(prefix[keep], r[keep], "smaller", cover, sizing, lo, hi,
                           periodic=per, stop_at_gap=True).gaps > 0
    holed = C.check_tiling(prefix[keep], r[keep], "smaller", sizing, lo, hi, per,
                           tau * 0.5 * (1 - 1e-9), cover, stop_at_gap=True)
    assert holed.conflicts == 0 and holed.maximality.gaps > 0
    # without the wrap, a torus-maximal set leaves the box's rim uncovered
    assert C.check_maximal(prefix, r, "smaller", cover, sizing, lo, hi, stop_at_gap=True).gaps > 0


def test_delaunay_two_radii_checker(hand_streams):
    """Prop. 4.1-4.2 hold on a hand-made two-radii stream prefix at its scale, and the report
    sees a point pushed inside an inhibition disk."""
    lo, hi = unit(2)
    x, t = hand_streams[(0.5, None)]
    k = len(x) - 1
    tau = float(np.nextafter(t[k], np.inf))
    rep = C.check_delaunay_two_radii(x[:k], 0.05, tau, 0.5, 1.0, lo, hi)
    assert rep.triangles > 50 and not rep.violations(), rep
    assert rep.min_angle_deg >= 14.4775
    eq, te = hand_streams[(1.0, None)]
    rep1 = C.check_delaunay_two_radii(eq[:k], 0.05, float(np.nextafter(te[k], np.inf)), 1.0, 1.0,
                                      lo, hi)
    assert rep1.angle_bound_deg == pytest.approx(30.0) and not rep1.violations(), rep1
    # a sample moved to within R_f / 2 of another: the shortest edge (and angle) bound breaks
    j = int(np.argmin(np.abs(x[:k] - 0.5).sum(axis=1)))
    bad = x[:k].copy()
    i = int(np.argsort(np.linalg.norm(bad - bad[j], axis=1))[1])
    bad[i] = bad[j] + 0.25 * tau * 0.05 * (bad[i] - bad[j]) / np.linalg.norm(bad[i] - bad[j])
    worse = C.check_delaunay_two_radii(bad, 0.05, tau, 0.5, 1.0, lo, hi)
    assert any("edge" in v for v in worse.violations())
