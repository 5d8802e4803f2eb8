"""Bias-freeness (Eq. 4) by statistics.

An unbiased process places sample k+1 uniformly over the free region S(X_k) of the samples before
it. So for any function h of position, the rank U = P(h(Y) < h(x_{k+1})) with Y uniform on
S(X_k) is Uniform(0, 1). Over many seeds, with k drawn at random, we rasterise S(X_k) (free
means no conflict: |y - x_i| >= f(x_i, y) for all i <= k) and rank x_{k+1} by h = x, h = y and
h = distance to the nearest sample; a Kolmogorov-Smirnov test against Uniform(0, 1) must not
reject. The same ranks for a biased insertion (Bridson's annulus around a random sample, from
the same prefixes) must be rejected, which shows the test has the power to see bias.
"""
import numpy as np
import pytest
from scipy import stats
from scipy.spatial import cKDTree

from vpds import analysis as C

PIXELS = 384
RUNS = 320


def free_mask(prefix, r_prefix, rule, sizing, lo, hi, L):
    """Pixels (centres) of the box that conflict with no sample of the prefix."""
    side = (hi - lo) / PIXELS
    u = lo + side * (np.arange(PIXELS) + 0.5)
    gx, gy = np.meshgrid(u, u, indexing="ij")
    pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
    r_pix = sizing.fn(pts)
    free = np.ones(len(pts), bool)
    if len(prefix):
        tree = cKDTree(pts)
        reach = r_prefix / (1 - L) if L > 0 else r_prefix
        for x, rx, R in zip(prefix, r_prefix, reach):
            near = np.asarray(tree.query_ball_point(x, max(R, rx) * 1.0001), dtype=np.int64)
            if len(near) == 0:
                continue
            d = np.linalg.norm(pts[near] - x, axis=1)
            f = C.rule_f(rule, np.full(len(near), rx), r_pix[near])
            free[near[d < f]] = False
    return pts, free


def ranks(pts, free, prefix, y, weight=None):
    """Ranks of y among the free pixels by x, y and distance to the nearest sample; with a
    weight per pixel, weighted ranks (the law of Eq. 12 instead of Eq. 4)."""
    fp = pts[free]
    w = np.ones(len(fp)) if weight is None else weight[free]
    w = w / w.sum()
    out = [w[fp[:, 0] < y[0]].sum(), w[fp[:, 1] < y[1]].sum()]
    if len(prefix):
        tree = cKDTree(prefix)
        dfree, _ = tree.query(fp)
        dy, _ = tree.query(y)
        out.append(w[dfree < dy].sum())
    else:
        out.append(np.nan)
    return out


def bridson_next(prefix, r_prefix, rule, sizing, lo, hi, rng):
    """A biased insertion: a random point in the annulus [r, 2r] of a random sample, if free."""
    for _ in range(5000):
        i = rng.integers(len(prefix))
        ang = rng.random() * 2 * np.pi
        rad = r_prefix[i] * (1 + rng.random())
        y = prefix[i] + rad * np.array([np.cos(ang), np.sin(ang)])
        if np.any(y < lo) or np.any(y > hi):
            continue
        ry = sizing.fn(y[None, :])[0]
        d = np.linalg.norm(prefix - y, axis=1)
        if np.all(d >= C.rule_f(rule, r_prefix, ry)):
            return y
    return None


CASES = [("smaller", "const", 0.08, 0.0, 1.0), ("current", "ramp", 0.0, 0.2, 0.6)]


@pytest.mark.parametrize("rule,sizing_name,radius,lo,hi", CASES)
def test_bias_free(sample, rule, sizing_name, radius, lo, hi):
    sizing = C.sizing_named(sizing_name, radius)
    rng = np.random.default_rng(7)
    ours, biased = [], []
    for seed in range(RUNS):
        x, r, _ = sample(2, rule, sizing_name, radius, 1000 + seed, lo, hi)
        k = int(rng.integers(1, len(x)))  # x[k] is the sample after the prefix x[:k]
        pts, free = free_mask(x[:k], r[:k], rule, sizing, lo, hi, sizing.lipschitz)
        if free.sum() < 20:  # too few pixels to rank against
            continue
        ours.append(ranks(pts, free, x[:k], x[k]))
        y = bridson_next(x[:k], r[:k], rule, sizing, lo, hi, rng)
        if y is not None:
            biased.append(ranks(pts, free, x[:k], y))
    ours, biased = np.array(ours), np.array(biased)
    assert len(ours) > RUNS * 0.6 and len(biased) > RUNS * 0.5
    p_ours = [stats.kstest(ours[:, j][~np.isnan(ours[:, j])], "uniform").pvalue for j in range(3)]
    p_biased = [stats.kstest(biased[:, j][~np.isnan(biased[:, j])], "uniform").pvalue for j in range(3)]
    print(f"{rule}/{sizing_name}: KS p-values ours {p_ours}, Bridson {p_biased}")
    assert min(p_ours) > 1e-3, p_ours
    assert min(p_biased) < 1e-3, p_biased  # the same level rejects the biased variant


def test_weighted_bias_free(sample):
    """Eq. 12: with `weighted`, sample k+1 has density 1/r^2 over the free region. The weighted
    process passes the weighted ranks; the plain process (uniform over the free region) fails
    them, so the test tells the two laws apart."""
    sizing = C.sizing_named("mild")
    rng = np.random.default_rng(3)
    p = {}
    for weighted in (1, 0):
        got = []
        for seed in range(RUNS):
            x, r, _ = sample(2, "smaller", "mild", 0.0, 5000 + seed, 0.0, 1.0, 0, weighted)
            k = int(rng.integers(1, len(x)))
            pts, free = free_mask(x[:k], r[:k], "smaller", sizing, 0.0, 1.0, sizing.lipschitz)
            if free.sum() < 20:
                continue
            got.append(ranks(pts, free, x[:k], x[k], weight=sizing.fn(pts) ** -2.0))
        got = np.array(got)
        p[weighted] = [stats.kstest(got[:, j][~np.isnan(got[:, j])], "uniform").pvalue
                       for j in range(3)]
    print(f"weighted ranks: KS p-values weighted process {p[1]}, plain process {p[0]}")
    assert min(p[1]) > 1e-3, p[1]
    assert min(p[0]) < 1e-3, p[0]


# 4D-6D: the same ranks where a raster of the free region is out of reach. A pool of points
# uniform in the box stands in for it: for each pool point, the first sample that conflicts with
# it; the free region of a prefix x[:k] is then the pool points whose first conflict comes at k
# or later, uniform on it. Within a run the ranks at several k are independent Uniform(0, 1) too
# (each is uniform given all the samples before it), so a run gives one per k of a fixed stride;
# a prefix whose free region holds too few pool points is skipped (a choice that depends on the
# prefix only, never on the sample after it).
HIGH = [(4, 0.25), (5, 0.35), (6, 0.6)]
HIGH_RUNS = 30
HIGH_PER_RUN = 20
POOL = 40_000


def first_conflict(pool, x, radius):
    """For each pool point, the index of the first sample closer than radius (len(x): none)."""
    first = np.full(len(pool), len(x))
    alive = np.arange(len(pool))
    for i, xi in enumerate(x):
        hit = ((pool[alive] - xi) ** 2).sum(axis=1) < radius * radius
        first[alive[hit]] = i
        alive = alive[~hit]
        if len(alive) == 0:
            break
    return first


def ranks_nd(free, prefix, y):
    """Ranks of y among the free points by its first and last coordinates and its distance to
    the nearest sample of the prefix."""
    tree = cKDTree(prefix)
    dfree, _ = tree.query(free)
    dy, _ = tree.query(y)
    return [np.mean(free[:, 0] < y[0]), np.mean(free[:, -1] < y[-1]), np.mean(dfree < dy)]


def bridson_next_nd(prefix, radius, rng):
    """The biased insertion of bridson_next in any dimension, for a constant radius."""
    d = prefix.shape[1]
    for _ in range(5000):
        u = rng.normal(size=d)
        y = prefix[rng.integers(len(prefix))] + radius * (1 + rng.random()) * u / np.linalg.norm(u)
        if np.all((y >= 0) & (y <= 1)) and np.all(np.linalg.norm(prefix - y, axis=1) >= radius):
            return y
    return None


@pytest.mark.parametrize("dim,radius", HIGH)
def test_bias_free_high_dims(sample, dim, radius):
    rng = np.random.default_rng(11 + dim)
    ours, biased = [], []
    for seed in range(HIGH_RUNS):
        x, r, _ = sample(dim, "smaller", "const", radius, 3000 + seed, 0.0, 1.0)
        assert np.all(r == radius)
        pool = rng.random((POOL, dim))
        first = first_conflict(pool, x, radius)
        for k in range(1, len(x), max(1, len(x) // HIGH_PER_RUN)):
            free = pool[first >= k]
            if len(free) < 100:  # too few pool points to rank against
                continue
            ours.append(ranks_nd(free, x[:k], x[k]))
            y = bridson_next_nd(x[:k], radius, rng)
            if y is not None:
                biased.append(ranks_nd(free, x[:k], y))
    ours, biased = np.array(ours), np.array(biased)
    assert len(ours) > 200 and len(biased) > 200, (len(ours), len(biased))
    p_ours = [stats.kstest(ours[:, j], "uniform").pvalue for j in range(3)]
    p_biased = [stats.kstest(biased[:, j], "uniform").pvalue for j in range(3)]
    print(f"{dim}D: {len(ours)} ranks, KS p-values ours {p_ours}, Bridson {p_biased}")
    assert min(p_ours) > 1e-3, p_ours
    assert min(p_biased) < 1e-3, p_biased  # the same level rejects the biased variant
