"""Domains and exactly-N sampling, checked here by brute force (scipy's kd-tree), independently
of the C code: every sample inside, no conflict in insertion order, and every probe of the domain
covered, with probes on the boundary itself."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial import cKDTree

import vpds

RULES = ["prior", "current", "bigger", "smaller"]
F = {"prior": lambda ri, ry: ri, "current": lambda ri, ry: ry,
     "bigger": np.maximum, "smaller": np.minimum}


def annulus(x: np.ndarray) -> np.ndarray:
    r = np.hypot(x[:, 0] - 0.5, x[:, 1] - 0.5)
    return np.maximum(r - 0.45, 0.2 - r)


def ramp(x: np.ndarray) -> np.ndarray:
    return 0.02 + 0.03 * x[:, 0]


L_SHAPE = np.array([[0.1, 0.1], [0.9, 0.1], [0.9, 0.4], [0.4, 0.4], [0.4, 0.9], [0.1, 0.9]])
OUTER = np.array([[0.05, 0.05], [0.95, 0.05], [0.95, 0.95], [0.05, 0.95]])
HOLE = np.array([[0.3, 0.3], [0.3, 0.7], [0.7, 0.7], [0.7, 0.3]])


def ring_probes(rings, per_edge=40) -> np.ndarray:
    out = []
    for ring in rings:
        for a, b in zip(ring, np.roll(ring, -1, axis=0)):
            s = np.linspace(0, 1, per_edge, endpoint=False)[:, None]
            out.append(a + s * (b - a))
    return np.concatenate(out)


def inside_polygon(rings, p: np.ndarray) -> np.ndarray:
    """Even-odd ray casting, written here (not the library's)."""
    inside = np.zeros(len(p), bool)
    for ring in rings:
        for a, b in zip(ring, np.roll(ring, -1, axis=0)):
            crosses = (a[1] > p[:, 1]) != (b[1] > p[:, 1])
            with np.errstate(divide="ignore", invalid="ignore"):
                xc = a[0] + (p[:, 1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
            inside ^= crosses & (p[:, 0] < xc)
    return inside


def check(x, r, radius_at, rule, inside, boundary, t=1.0, inhibition=1.0, coverage=1.0, tol=0.0,
          probes=40_000, seed=0):
    """Inside, conflict-free at t*inhibition*f*(1 - tol) in insertion order, covered at
    t*coverage*f at random probes of the domain and at the boundary probes."""
    assert len(x) > 0
    assert inside(x).all(), f"{(~inside(x)).sum()} samples outside the domain"
    tree = cKDTree(x)
    reach = t * inhibition * r.max()
    for i, j in tree.query_pairs(reach):
        a, b = min(i, j), max(i, j)
        lim = t * inhibition * F[rule](r[a], r[b]) * (1 - tol)
        assert np.linalg.norm(x[a] - x[b]) >= lim, f"samples {a} and {b} conflict"
    rng = np.random.default_rng(seed)
    y = rng.random((probes, 2))
    y = np.concatenate([y[inside(y)], boundary])
    ry = radius_at(y)
    near = tree.query_ball_point(y, t * coverage * max(r.max(), ry.max()) * (1 + 1e-9))
    gaps = 0
    for k, idx in enumerate(near):
        idx = np.asarray(idx, int)
        d = np.linalg.norm(x[idx] - y[k], axis=1) if len(idx) else np.empty(0)
        if not np.any(d <= t * coverage * F[rule](r[idx], ry[k]) * (1 + 1e-9)):
            gaps += 1
    assert gaps == 0, f"{gaps} of {len(y)} probes of the domain uncovered"


@pytest.mark.parametrize("rule", RULES)
@pytest.mark.parametrize("varying", [False, True])
def test_annulus_callable(rule, varying):
    e = vpds.PoissonDisk(2, radius=0.03, sizing=ramp if varying else None,
                         lipschitz=0.03 if varying else None, rule=rule, domain=annulus, rng=5,
                         progress=False)
    x = e.fill_space()
    a = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    bd = np.concatenate([np.c_[0.5 + 0.45 * np.cos(a), 0.5 + 0.45 * np.sin(a)],
                         np.c_[0.5 + 0.2 * np.cos(a), 0.5 + 0.2 * np.sin(a)]])
    radius_at = ramp if varying else (lambda y: np.full(len(y), 0.03))
    check(x, e.radii, radius_at, rule, lambda p: annulus(p) <= 0, bd)


@pytest.mark.parametrize("rule", RULES)
def test_polygons(rule):
    from shapely.geometry import Polygon
    for rings, dom in (([L_SHAPE], L_SHAPE), ([OUTER, HOLE], Polygon(OUTER, [HOLE]))):
        e = vpds.PoissonDisk(2, sizing=ramp, lipschitz=0.03, rule=rule, domain=dom, rng=2,
                             progress=False)
        x = e.fill_space()
        check(x, e.radii, ramp, rule, lambda p, rings=rings: inside_polygon(rings, p),
              ring_probes(rings))


def test_mask_and_its_polygon():
    rings = [OUTER, HOLE]
    m = 200
    c = (np.arange(m) + 0.5) / m
    centres = np.stack(np.meshgrid(c, c, indexing="ij"), -1).reshape(-1, 2)
    mask = inside_polygon(rings, centres).reshape(m, m)
    e = vpds.PoissonDisk(2, radius=0.025, domain=mask, rng=4, progress=False)
    x = e.fill_space()
    # the mask's domain is the polygon's up to half a cell: check against the mask's own sdf
    sdf = e._domain
    far = np.abs(sdf(centres)) > 0.75 / m
    assert (mask.reshape(-1)[far] == (sdf(centres)[far] <= 0)).all()
    check(x, e.radii, lambda y: np.full(len(y), 0.025), "smaller", lambda p: sdf(p) <= 0,
          ring_probes(rings)[np.abs(sdf(ring_probes(rings))) < 1e-12])
    poly = vpds.PoissonDisk(2, radius=0.025, domain=[OUTER, HOLE], rng=4, progress=False).fill_space()
    # the same domain up to a cell: about as many samples
    assert abs(len(poly) - len(x)) < 0.05 * len(x)


def test_image_domain_and_cli(tmp_path):
    from PIL import Image
    img = np.zeros((100, 100), np.uint8)
    img[20:60, 10:90] = 255  # rows 20..59 from the top: y in (0.4, 0.8]
    Image.fromarray(img).save(tmp_path / "m.png")
    x = vpds.PoissonDisk(2, radius=0.03, domain=str(tmp_path / "m.png"), rng=1,
                         progress=False).fill_space()
    assert (x[:, 0] > 0.1 - 0.006).all() and (x[:, 0] < 0.9 + 0.006).all()
    assert (x[:, 1] > 0.4 - 0.006).all() and (x[:, 1] < 0.8 + 0.006).all()
    out = tmp_path / "p.npz"
    res = subprocess.run([sys.executable, "-m", "vpds", "sample", "--domain", str(tmp_path / "m.png"),
                          "--radius", "0.03", "--seed", "1", "-o", str(out), "--no-progress"],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert np.array_equal(np.load(out)["points"], x)
    res = subprocess.run([sys.executable, "-m", "vpds", "sample", "--domain", str(tmp_path / "m.png"),
                          "--domain-threshold", "2", "--no-progress"], capture_output=True, text=True)
    assert res.returncode == 2 and "no value is >= threshold" in res.stderr


def test_3d_ball_and_torus():
    def ball(x):
        return np.linalg.norm(x - 0.5, axis=1) - 0.4

    def torus(x):
        q = np.hypot(x[:, 0] - 0.5, x[:, 1] - 0.5) - 0.3
        return np.hypot(q, x[:, 2] - 0.5) - 0.12
    for sdf, r in ((ball, 0.08), (torus, 0.05)):
        x = vpds.PoissonDisk(3, radius=r, domain=sdf, rng=1, progress=False).fill_space()
        assert (sdf(x) <= 0).all()
        tree = cKDTree(x)
        assert not tree.query_pairs(r * (1 - 1e-12))
        y = np.random.default_rng(0).random((60_000, 3))
        y = y[sdf(y) <= 0]
        d, _ = tree.query(y)
        assert d.max() <= r * (1 + 1e-9), f"{sdf.__name__}: a gap of {d.max() / r:.4f} r"


@pytest.mark.parametrize("domain", [None, "annulus"])
def test_progressive_exactly_n(domain):
    e = vpds.PoissonDisk(2, radius=0.05, domain=annulus if domain else None, rng=8, progress=False)
    tol = vpds.STREAM_DOMAIN_TOLERANCE if domain else vpds.STREAM_TOLERANCE
    inside = (lambda p: annulus(p) <= 0) if domain else (lambda p: np.ones(len(p), bool))
    for n in (1, 2, 3, 7, 50, 333):
        res = e.progressive(n)
        assert res.points.shape == (n, 2) and res.scales.shape == (n,)
        assert np.all(np.diff(res.scales) <= 0) and res.t == res.scales[-1]
        if n >= 7:
            # maximal at the scale reached, conflict-free at it with R_f = 0.5 R_c
            check(res.points, np.full(n, 0.05), lambda y: np.full(len(y), 0.05), "smaller",
                  inside, np.empty((0, 2)), t=res.t, inhibition=0.5, tol=tol, probes=20_000)
    # prefixes of one stream: progressive(50) is the start of progressive(333)
    assert np.array_equal(e.progressive(50).points, e.progressive(333).points[:50])
    assert len(e.points) == 0  # the sampler itself is untouched


def test_progressive_is_the_stream_across_batches():
    """progressive(n) takes its events from C in batches of vpds_next_n: past several batch
    boundaries they are the events of stream(), one C call each, bit for bit."""
    from vpds._core import STREAM_BATCH
    n = 2 * STREAM_BATCH + 17
    batched = vpds.PoissonDisk(2, radius=0.005, rng=4, progress=False).progressive(n, inhibition=None)
    one_by_one = vpds.PoissonDisk(2, radius=0.005, rng=4, progress=False)
    pts, ts = [], []
    for x, t in one_by_one.stream():
        pts.append(x)
        ts.append(t)
        if len(pts) == n:
            break
    np.testing.assert_array_equal(batched.points, np.array(pts))
    np.testing.assert_array_equal(batched.scales, np.array(ts))


def test_progressive_first_points_are_random():
    """With equal radii the second point is a corner (farthest from the first); the default
    R_f = 0.5 R_c keeps the first points random."""
    firsts = []
    for seed in range(6):
        p = vpds.PoissonDisk(2, radius=0.05, rng=seed, progress=False).progressive(4).points
        firsts.append(p)
        corner = vpds.PoissonDisk(2, radius=0.05, rng=seed, progress=False).progressive(
            2, inhibition=None).points[1]
        assert np.all(np.minimum(corner, 1 - corner) < 1e-4), corner  # a corner, to the tolerance
    firsts = np.array(firsts)
    print("first 4 points of progressive() for seeds 0..5:\n", np.round(firsts, 3))
    # no point of the first four at a corner, and no two seeds sharing a point
    assert not np.any(np.all(np.minimum(firsts, 1 - firsts) < 1e-3, axis=-1))
    flat = firsts.reshape(-1, 2)
    assert len(np.unique(np.round(flat, 9), axis=0)) == len(flat)


def test_estimate_radius():
    for d, r_target in ((2, None), (3, None)):
        r = vpds.estimate_radius(2000, d)
        n = len(vpds.PoissonDisk(d, radius=r, rng=1, progress=False).fill_space())
        assert 0.85 * 2000 < n < 1.25 * 2000, (d, r, n)
    with pytest.raises(ValueError, match="d = 17: must be in 1..16"):
        vpds.estimate_radius(10, 17)
    assert 0 < vpds.estimate_radius(10, 12) < vpds.estimate_radius(5, 12)


def test_bad_domains():
    e = vpds.PoissonDisk(2, domain=lambda x: np.ones(len(x)), progress=False)
    with pytest.raises(vpds.VpdsDomainError, match="empty"):
        e.fill_space()
    assert len(e.points) == 0 and not e.stats["maximal"]

    def nan_sdf(x):
        return np.where(x[:, 0] > 0.6, np.nan, x[:, 0] - 0.9)
    with pytest.raises(vpds.VpdsDomainError, match="NaN"):
        vpds.PoissonDisk(2, domain=nan_sdf, progress=False).fill_space()
    with pytest.raises(vpds.VpdsDomainError, match="1-Lipschitz"):
        vpds.PoissonDisk(2, domain=lambda x: 3 * (x[:, 0] - 0.5), progress=False).fill_space()
    with pytest.raises(ValueError, match="no value is >= threshold"):
        vpds.PoissonDisk(2, domain=np.zeros((8, 8), bool), progress=False)
    with pytest.raises(ValueError, match="intersects itself"):
        vpds.PoissonDisk(2, domain=np.array([[0, 0], [1, 1], [1, 0], [0, 1.0]]), progress=False)

    def boom(x):
        raise RuntimeError("boom")
    with pytest.raises(RuntimeError, match="boom") as info:  # the callable's own exception
        vpds.PoissonDisk(2, domain=boom, progress=False).fill_space()
    assert not isinstance(info.value, vpds.VpdsError)
    with pytest.raises(vpds.VpdsDomainError, match=r"shape \(2,\)"):  # the binding's check
        vpds.PoissonDisk(2, domain=lambda x: np.zeros(2), progress=False).fill_space()


def test_bias_free_in_a_domain():
    """Eq. 4 inside a domain: sample k+1 is uniform over the free part of the annulus. Ranks of
    x_{k+1} among the free pixels inside the domain (by x, y, distance to the nearest sample) are
    Uniform(0, 1); Bridson's annulus insertion from the same prefixes is rejected."""
    from scipy import stats
    from test_bias import bridson_next, free_mask, ranks

    from vpds import analysis as C
    sizing = C.sizing_named("const", 0.08)
    rng = np.random.default_rng(11)
    ours, biased = [], []
    for seed in range(320):
        e = vpds.PoissonDisk(2, radius=0.08, domain=annulus, rng=3000 + seed, progress=False)
        x = e.fill_space()
        r = e.radii
        k = int(rng.integers(1, len(x)))
        pts, free = free_mask(x[:k], r[:k], "smaller", sizing, 0.0, 1.0, 0.0)
        free &= annulus(pts) <= 0
        if free.sum() < 20:
            continue
        ours.append(ranks(pts, free, x[:k], x[k]))
        for _ in range(50):  # Bridson's insertion, kept inside the domain
            y = bridson_next(x[:k], r[:k], "smaller", sizing, 0.0, 1.0, rng)
            if y is None or annulus(y[None, :])[0] <= 0:
                break
        if y is not None and annulus(y[None, :])[0] <= 0:
            biased.append(ranks(pts, free, x[:k], y))
    ours, biased = np.array(ours), np.array(biased)
    assert len(ours) > 200 and len(biased) > 150
    p_ours = [stats.kstest(ours[:, j][~np.isnan(ours[:, j])], "uniform").pvalue for j in range(3)]
    p_biased = [stats.kstest(biased[:, j][~np.isnan(biased[:, j])], "uniform").pvalue for j in range(3)]
    print(f"annulus: KS p-values ours {p_ours}, Bridson {p_biased}")
    assert min(p_ours) > 1e-3, p_ours
    assert min(p_biased) < 1e-3, p_biased
