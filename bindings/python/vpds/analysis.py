"""Checks of a sampling against the paper's definitions, and its spectral analysis.

Written from the paper alone, with numpy and scipy: nothing here calls or copies the C library,
so it is an independent check of its output (the project's tests use it, and `vpds analyze`). A sampling is checked for
  - the empty-disk property in insertion order (Eq. 10 with the rule's f),
  - maximality (Eq. 11 empty): a branch-and-bound over the box on the coverage margin
        g(y) = min_i |y - x_i| - s f(x_i, y),
    which is (1 + s L)-Lipschitz, so a box whose centre has g(c) + K h/2 <= 0 is covered whole
    and a centre with g(c) > 0 is a gap: no gap wider than the stopping size can be missed,
  - the Delaunay bounds of Table 1 on triangles whose circumcentre lies in the box (2D),
    and those of Prop. 4.1-4.2 for two radii (R_f = t inhibition r <= R_c = t coverage r),
  - periodic boxes: every check takes `periodic` (one flag per axis) and then measures the
    toroidal (minimum-image) distance, by tiling the samples into their 3^p images; and a 3^p
    tiled copy of a periodic output must itself be a valid sampling across the seams,
  - the continuous stream's prefix property (Section 4.2): each prefix {k : t_k >= tau} is
    conflict-free and maximal at tau,
  - for a uniform radius, the exact largest empty ball of the box (Delaunay circumcentres),
    which is what farthest-point insertion must pick.

Shapes throughout: samples x (n, d) with radii r and scales t (n,) in insertion order, the box's
corners lo and hi (d,), points where r or g is evaluated (m, d) and their values (m,).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional, Sequence, Union, cast

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from ._typing import BoolArray, FloatArray, IndexArray

RULES = ("prior", "current", "bigger", "smaller")


def rule_f(rule: str, rx: FloatArray, ry: FloatArray) -> FloatArray:
    """f(x, y) of Table 1's rule from r at the earlier sample x (rx) and at y (ry), broadcast."""
    if rule == "prior":
        return np.broadcast_to(rx, np.broadcast(rx, ry).shape)
    if rule == "current":
        return np.broadcast_to(ry, np.broadcast(rx, ry).shape)
    if rule == "bigger":
        return np.maximum(rx, ry)
    return np.minimum(rx, ry)


@dataclass
class Sizing:
    """r(x) for arrays of points (m, d), with its Lipschitz constant."""

    fn: Callable[[FloatArray], FloatArray]
    lipschitz: float


def sizing_named(name: str, radius: float = 0.0) -> Sizing:
    if name == "const":
        return Sizing(lambda y: np.full(len(y), radius), 0.0)
    if name == "ramp":  # the paper's Figure 1
        return Sizing(lambda y: 0.001 + 0.3 * y[:, 0], 0.3)
    if name == "mild":  # a gentle ramp, for the weighted process
        return Sizing(lambda y: 0.04 + 0.04 * y[:, 0], 0.04)
    if name == "wide":  # radii for 9D and up, where a unit box holds a few samples
        return Sizing(lambda y: 1.2 + 0.4 * y[:, 0], 0.4)
    if name == "radial":  # the paper's Figure 10
        def radial(y: FloatArray) -> FloatArray:
            d = np.sqrt(((y - 0.5) ** 2).sum(axis=1))
            r: FloatArray = 0.015 + (0.00015 - 0.015) * np.abs(np.sin(8 * np.pi * d))
            return r
        return Sizing(radial, 0.01485 * 8 * np.pi)
    raise ValueError(name)


def load(path: str) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(x (n, d), r (n,), t (n,)) from the file tests/tools/sample_tool writes: n and d (int64),
    then x, r and t (float64)."""
    raw = np.fromfile(path, dtype=np.int64, count=2)
    n, d = int(raw[0]), int(raw[1])
    data = np.fromfile(path, dtype=np.float64, offset=16)
    x = data[: n * d].reshape(n, d)
    r = data[n * d : n * d + n]
    t = data[n * d + n : n * d + 2 * n]
    return x, r, t


#: one flag per axis, (d,): a sequence, or a bool array (the masks below); None: no periodic axis
Periodic = Optional[Union[Sequence[bool], BoolArray]]


def _periodic_mask(periodic: Periodic, d: int) -> Optional[BoolArray]:
    """The periodic flags as a bool array, or None when no axis is periodic."""
    if periodic is None:
        return None
    m = np.asarray(periodic, dtype=bool).reshape(-1)
    if m.shape != (d,):
        raise ValueError(f"periodic has {m.size} flags for {d} axes")
    return m if m.any() else None


def wrap_points(x: FloatArray, lo: FloatArray, hi: FloatArray, periodic: Periodic) -> FloatArray:
    """Points moved into [lo, hi) along the periodic axes: one representative per torus point,
    so that the 3^p images below hold the minimum image of every pair."""
    x = np.array(x, dtype=np.float64, copy=True)
    mask = _periodic_mask(periodic, x.shape[1])
    if mask is None:
        return x
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    ext = hi - lo
    x[:, mask] = lo[mask] + np.mod(x[:, mask] - lo[mask], ext[mask])
    return x


def toroidal_distance(a: FloatArray, b: FloatArray, lo: FloatArray, hi: FloatArray,
                      periodic: Periodic) -> FloatArray:
    """|a - b| with the minimum image along the periodic axes (rows broadcast)."""
    a, b = np.atleast_2d(a).astype(np.float64), np.atleast_2d(b).astype(np.float64)
    diff = np.abs(a - b)
    mask = _periodic_mask(periodic, diff.shape[1])
    if mask is not None:
        ext = (np.asarray(hi, dtype=np.float64) - np.asarray(lo, dtype=np.float64))[mask]
        dm = np.mod(diff[:, mask], ext)
        diff[:, mask] = np.minimum(dm, ext - dm)
    dist: FloatArray = np.sqrt((diff ** 2).sum(axis=1))
    return dist


def periodic_images(x: FloatArray, r: FloatArray, lo: FloatArray, hi: FloatArray,
                    periodic: Periodic, margin: Optional[float] = None
                    ) -> tuple[FloatArray, FloatArray, IndexArray]:
    """(points, radii, source index) of the 3^p copies of the wrapped points shifted by -1, 0, +1
    periods along the p periodic axes, the unshifted copy first (rows 0..n-1 are the wrapped
    samples themselves). Why: for points of the box the minimum image of any sample is among
    them, so Euclidean checks on the copies are toroidal checks. With `margin`, only copies
    within that distance of the box are kept (the unshifted copy always is)."""
    x = np.asarray(x, dtype=np.float64)
    r = np.asarray(r, dtype=np.float64)
    d = x.shape[1]
    mask = _periodic_mask(periodic, d)
    n = len(x)
    if mask is None:
        return x.copy(), r.copy(), np.arange(n)
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    ext = hi - lo
    xw = wrap_points(x, lo, hi, mask)
    axes = np.flatnonzero(mask)
    shifts = np.array(np.meshgrid(*[[0, -1, 1]] * len(axes), indexing="ij"))
    shifts = shifts.reshape(len(axes), -1).T
    pts, rad, src = [], [], []
    for sh in shifts:
        off = np.zeros(d)
        off[axes] = sh * ext[axes]
        y = xw + off
        keep = np.ones(n, bool)
        if margin is not None and sh.any():
            below = np.maximum(lo - y, 0.0)
            above = np.maximum(y - hi, 0.0)
            keep = np.sqrt(((below + above) ** 2).sum(axis=1)) <= margin
        pts.append(y[keep])
        rad.append(r[keep])
        src.append(np.flatnonzero(keep))
    return np.concatenate(pts), np.concatenate(rad), np.concatenate(src)


def _wrapped_sizing(sizing: "Sizing", lo: FloatArray, hi: FloatArray, mask: BoolArray) -> "Sizing":
    """The sizing read at the wrapped point: r of a periodic image is r of the sample."""
    return Sizing(lambda y: sizing.fn(wrap_points(y, lo, hi, mask)), sizing.lipschitz)


def empty_disk_violations(x: FloatArray, r: FloatArray, rule: str, scale: float, lipschitz: float,
                          rel_tol: float = 1e-12, *, periodic: Periodic = None,
                          lo: Optional[FloatArray] = None, hi: Optional[FloatArray] = None) -> int:
    """Pairs j < i with |x_i - x_j| < scale f(x_j, x_i) (x_j the earlier sample); with
    `periodic` (and the box lo, hi) the distance is the toroidal one."""
    scales = np.full(len(x), float(scale))
    return len(_conflict_pairs(x, r, scales, rule, lipschitz, rel_tol, periodic, lo, hi)[0])


def conflicts_at_insertion_scales(x: FloatArray, r: FloatArray, t: FloatArray, rule: str,
                                  inhibition: float, lipschitz: float, rel_tol: float = 0.0, *,
                                  periodic: Periodic = None, lo: Optional[FloatArray] = None,
                                  hi: Optional[FloatArray] = None) -> int:
    """Pairs j < i with |x_i - x_j| < t_i inhibition (1 - rel_tol) f(x_j, x_i).

    Why: a pair j < i belongs to every prefix {k : t_k >= tau} with tau <= t_i (t non-increasing),
    and conflicts most at the largest such tau, t_i; so this one pass checks the empty-disk half
    of the prefix property at every tau at once. Samples with t_i = inf (fixed points) are not
    checked against earlier samples (fixed points are not checked against each other)."""
    t = np.asarray(t, dtype=np.float64)
    scales = np.where(np.isfinite(t), t * inhibition * (1 - rel_tol), 0.0)
    return len(_conflict_pairs(x, r, scales, rule, lipschitz, 1e-12, periodic, lo, hi)[0])


def _conflict_pairs(x: FloatArray, r: FloatArray, scales: FloatArray, rule: str, lipschitz: float,
                    rel_tol: float, periodic: Periodic, lo: Optional[FloatArray],
                    hi: Optional[FloatArray]) -> tuple[IndexArray, IndexArray]:
    """(i, j), j < i, with |x_i - x_j| < scales[i] f(x_j, x_i) (1 - rel_tol), each pair once.

    Samples are processed in blocks of doubling size, each against a tree of the samples (or
    their periodic images) before the block's end: the early samples of a stream have scales
    far above the final one, and must not each drag the whole set out of one tree."""
    x = np.asarray(x, dtype=np.float64)
    r = np.asarray(r, dtype=np.float64)
    n = len(x)
    if n < 2:
        return np.empty(0, np.int64), np.empty(0, np.int64)
    mask = _periodic_mask(periodic, x.shape[1])
    if mask is not None:
        if lo is None or hi is None:
            raise ValueError("periodic checks need the box: pass lo and hi")
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        x = wrap_points(x, lo, hi, mask)
    # every conflicting earlier sample lies within s r_i / (1 - s L) of x_i (Lipschitz; prior and
    # bigger), within s r_i (current, smaller), and always within s r_max and the set's diameter
    ext = x.max(axis=0) - x.min(axis=0)
    if mask is not None:
        assert lo is not None and hi is not None  # given with the mask (checked above)
        ext = np.maximum(ext, hi - lo)
    diam = float(np.linalg.norm(ext)) * (1 + 1e-9) + 1e-300
    sl = scales * lipschitz
    if rule in ("prior", "bigger"):
        with np.errstate(divide="ignore", invalid="ignore"):
            reach = np.where(sl < 1, scales * r / np.maximum(1 - sl, 1e-300), np.inf)
    else:
        reach = scales * r
    reach = np.minimum(np.minimum(reach, scales * float(r.max())), diam) * (1 + 1e-9)
    out_i, out_j = [], []
    a = 0
    while a < n:
        b = min(n, max(1, 2 * a))
        if mask is None:
            pts, src = x[:b], np.arange(b)
        else:
            assert lo is not None and hi is not None  # given with the mask (checked above)
            pts, _, src = periodic_images(x[:b], r[:b], lo, hi, mask,
                                          margin=float(reach[a:b].max()))
        tree = cKDTree(pts)
        lists = tree.query_ball_point(x[a:b], reach[a:b], return_sorted=False)
        counts = np.fromiter((len(v) for v in lists), dtype=np.int64, count=b - a)
        i = np.repeat(np.arange(a, b), counts)
        k = np.fromiter((m for v in lists for m in v), dtype=np.int64, count=int(counts.sum()))
        j = src[k]
        keep = j < i
        i, j, k = i[keep], j[keep], k[keep]
        dist = np.linalg.norm(x[i] - pts[k], axis=1)
        f = scales[i] * rule_f(rule, r[j], r[i])
        bad = dist < f * (1 - rel_tol)
        out_i.append(i[bad])
        out_j.append(j[bad])
        a = b
    i, j = np.concatenate(out_i), np.concatenate(out_j)
    if len(i):
        key = np.unique(i * n + j)  # one pair, however many of its images conflict
        i, j = key // n, key % n
    return i, j


def coverage_margin(points: FloatArray, tree: cKDTree, x: FloatArray, r: FloatArray, rule: str,
                    scale: float, r_at: FloatArray, k: int = 24, exact: bool = False) -> FloatArray:
    """g at points: an upper bound from the k nearest samples, or exact (all samples in reach)."""
    kk = min(k, len(x))
    dist, idx = tree.query(points, k=kk)
    if kk == 1:
        dist, idx = dist[:, None], idx[:, None]
    g: FloatArray = (dist - scale * rule_f(rule, r[idx], r_at[:, None])).min(axis=1)
    if exact:
        # every sample that can lower g lies within g + scale max(r) of the point
        reach = g + scale * np.maximum(r.max(), r_at)
        m = np.flatnonzero(reach > 0)
        if len(m):
            lists = tree.query_ball_point(points[m], reach[m] * (1 + 1e-9), return_sorted=False)
            counts = np.fromiter((len(v) for v in lists), dtype=np.int64, count=len(m))
            rows = np.repeat(m, counts)
            cols = np.fromiter((c for v in lists for c in v), dtype=np.int64,
                               count=int(counts.sum()))
            nd = np.linalg.norm(x[cols] - points[rows], axis=1)
            np.minimum.at(g, rows, nd - scale * rule_f(rule, r[cols], r_at[rows]))
    return g


def box_covered_by_one(centres: FloatArray, side: FloatArray, tree: cKDTree, x: FloatArray,
                       r: FloatArray, rule: str, scale: float, r_lo: FloatArray,
                       k: int = 12) -> BoolArray:
    """Boxes (centre, side) wholly inside one sample's disk, r over the box being >= r_lo."""
    kk = min(k, len(x))
    _, idx = tree.query(centres, k=kk)
    if kk == 1:
        idx = idx[:, None]
    far = np.abs(x[idx] - centres[:, None, :]) + side / 2
    maxd = np.sqrt((far ** 2).sum(axis=2))
    reach = scale * rule_f(rule, r[idx], r_lo[:, None])
    covered: BoolArray = ((reach > 0) & (maxd <= reach)).any(axis=1)
    return covered


@dataclass
class MaximalityReport:
    gaps: int                 # centres found uncovered (g > tol)
    worst_gap: FloatArray | None
    boxes: int                # boxes examined
    unresolved_bound: float   # sup of g over boxes left at the stopping size (relative to r)
    probes_max_rel: float     # max of g / r over random probes


def check_maximal(x: FloatArray, r: FloatArray, rule: str, scale: float, sizing: Sizing,
                  lo: FloatArray, hi: FloatArray, rel_tol: float = 1e-9, probes: int = 200_000,
                  seed: int = 0, max_boxes: int = 20_000_000, *,
                  periodic: Periodic = None, stop_at_gap: bool = False) -> MaximalityReport:
    """Every point of the box within scale f of a sample (branch-and-bound, then probes); with
    `periodic`, of a sample's periodic image (the torus is covered iff the box is, by images).
    With stop_at_gap, the search ends at the first level that finds a gap (a verdict without
    resolving the gap's whole boundary, which costs boxes in proportion to its length)."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if _periodic_mask(periodic, x.shape[1]) is not None:
        x, r, _ = periodic_images(x, r, lo, hi, periodic)
    d = x.shape[1]
    tree = cKDTree(x)
    K = 1.0 + (0.0 if rule == "prior" else scale * sizing.lipschitz)
    rmin_hint = float(r.min())
    # start with boxes about the size of the largest disk
    ext = hi - lo
    per_axis = np.maximum(1, np.ceil(ext / max(scale * float(r.max()), 1e-300))).astype(int)
    per_axis = np.minimum(per_axis, max(1, int(round(200_000 ** (1.0 / d)))))
    side = ext / per_axis
    grids = np.meshgrid(*[lo[a] + side[a] * (np.arange(per_axis[a]) + 0.5) for a in range(d)],
                        indexing="ij")
    centres = np.stack([g.ravel() for g in grids], axis=1)
    gaps, worst, boxes, unresolved = 0, None, 0, 0.0
    stop_half_diag = rel_tol * scale * rmin_hint
    while len(centres):
        boxes += len(centres)
        if boxes > max_boxes:
            raise RuntimeError("branch-and-bound exceeded its box budget")
        half_diag = 0.5 * float(np.linalg.norm(side))
        r_c = sizing.fn(centres)
        g = coverage_margin(centres, tree, x, r, rule, scale, r_c)
        suspicious = g > rel_tol * r_c
        if suspicious.any():
            ge = coverage_margin(centres[suspicious], tree, x, r, rule, scale, r_c[suspicious],
                                 exact=True)
            g[suspicious] = ge
            real = ge > rel_tol * r_c[suspicious]
            if real.any():
                gaps += int(real.sum())
                worst = centres[suspicious][np.argmax(ge)]
                if stop_at_gap:
                    break
        open_ = (g + K * half_diag > 0) & ~(g > rel_tol * r_c)
        if open_.any():
            # tighter: one sample covering the whole box (its farthest corner within reach)
            idx_open = np.flatnonzero(open_)
            open_[idx_open[box_covered_by_one(centres[idx_open], side, tree, x, r, rule, scale,
                                               r_c[idx_open] - sizing.lipschitz * half_diag)]] = False
        if half_diag <= stop_half_diag:
            if open_.any():
                unresolved = max(unresolved, float(((g + K * half_diag) / r_c)[open_].max()))
            break
        centres = centres[open_]
        if not len(centres):
            break
        side = side / 2
        offs = np.array(np.meshgrid(*[[-0.5, 0.5]] * d, indexing="ij")).reshape(d, -1).T
        centres = (centres[:, None, :] + offs[None, :, :] * side).reshape(-1, d)
    rng = np.random.default_rng(seed)
    probe = lo + rng.random((probes, d)) * ext
    probe = np.vstack([probe, lo + (rng.integers(0, 2, (max(1, probes // 50), d)) * ext)])
    rp = sizing.fn(probe)
    gp = coverage_margin(probe, tree, x, r, rule, scale, rp)
    return MaximalityReport(gaps, worst, boxes, unresolved, float((gp / rp).max()))


@dataclass
class DelaunayReport:
    triangles: int
    min_angle_deg: float
    angle_bound_deg: float
    edge_min_ratio: float     # min over edges of |e| / r(x) (both endpoints)
    edge_min_bound: float
    edge_max_ratio: float     # max over edges of |e| / r(x)
    edge_max_bound: float
    circumradius_ratio: float  # max R_T / r(circumcentre) ...
    circumradius_bound: float


def table1_bounds(rule: str, L: float) -> tuple[float, float, float]:
    """(edge min, edge max, sin angle min) as factors of r(x), Table 1."""
    if rule == "prior":
        return 1 / (1 + L), 2 / (1 - 2 * L), (1 - 2 * L) / 2
    if rule == "current":
        return 1 / (1 + L), 2 / (1 - L), (1 - L) / 2
    if rule == "bigger":
        return 1.0, 2 / (1 - 2 * L), (1 - 2 * L) / 2
    return 1 / (1 + L), 2 / (1 - L), (1 - L) / 2


Triple = tuple[FloatArray, FloatArray, FloatArray]  # per vertex of each triangle (or the side opposite it)


def _interior_triangles(x: FloatArray, lo: FloatArray, hi: FloatArray, disk_inside: bool = False
                        ) -> tuple[IndexArray, Triple, FloatArray, FloatArray, Triple]:
    """Delaunay triangles whose circumcentre lies in the box (where maximality bounds them), or
    with `disk_inside` whose whole circumdisk does: vertex indices, edge lengths opposite each
    vertex, circumcentres, circumradii, angles."""
    tri = Delaunay(x)
    s = tri.simplices
    a, b, c = x[s[:, 0]], x[s[:, 1]], x[s[:, 2]]
    d = 2 * (a[:, 0] * (b[:, 1] - c[:, 1]) + b[:, 0] * (c[:, 1] - a[:, 1]) + c[:, 0] * (a[:, 1] - b[:, 1]))
    ux = ((a ** 2).sum(1) * (b[:, 1] - c[:, 1]) + (b ** 2).sum(1) * (c[:, 1] - a[:, 1]) + (c ** 2).sum(1) * (a[:, 1] - b[:, 1])) / d
    uy = ((a ** 2).sum(1) * (c[:, 0] - b[:, 0]) + (b ** 2).sum(1) * (a[:, 0] - c[:, 0]) + (c ** 2).sum(1) * (b[:, 0] - a[:, 0])) / d
    u = np.stack([ux, uy], axis=1)
    inside = np.all((u >= lo) & (u <= hi), axis=1) & np.isfinite(u).all(axis=1)
    if disk_inside:
        rad = np.linalg.norm(a - u, axis=1)[:, None]
        inside &= np.all((u - rad >= lo) & (u + rad <= hi), axis=1)
    s, a, b, c, u = s[inside], a[inside], b[inside], c[inside], u[inside]
    la = np.linalg.norm(b - c, axis=1)
    lb = np.linalg.norm(c - a, axis=1)
    lc = np.linalg.norm(a - b, axis=1)
    ang_a = np.arccos(np.clip((lb ** 2 + lc ** 2 - la ** 2) / (2 * lb * lc), -1, 1))
    ang_b = np.arccos(np.clip((la ** 2 + lc ** 2 - lb ** 2) / (2 * la * lc), -1, 1))
    ang_c = np.pi - ang_a - ang_b
    return s, (la, lb, lc), u, np.linalg.norm(a - u, axis=1), (ang_a, ang_b, ang_c)


def _edge_ratios(s: IndexArray, lengths: Triple, r: FloatArray) -> FloatArray:
    la, lb, lc = lengths
    return np.concatenate([la / r[s[:, 1]], la / r[s[:, 2]], lb / r[s[:, 2]], lb / r[s[:, 0]],
                           lc / r[s[:, 0]], lc / r[s[:, 1]]])


def check_delaunay(x: FloatArray, r: FloatArray, rule: str, L: float, lo: FloatArray,
                   hi: FloatArray, sizing: Sizing | None = None) -> DelaunayReport:
    """Table 1 on triangles whose circumcentre lies in the box (where maximality holds)."""
    s, lengths, u, R, angles = _interior_triangles(x, lo, hi)
    min_angle = float(np.degrees(np.minimum(np.minimum(*angles[:2]), angles[2]).min()))
    e_min, e_max, sin_min = table1_bounds(rule, L)
    ratios = _edge_ratios(s, lengths, r)
    circ = 0.0
    if sizing is not None:
        circ = float((R / sizing.fn(u)).max())
    circ_bound = 1 / (1 - L) if rule in ("prior", "bigger") else 1.0
    return DelaunayReport(int(len(s)), min_angle, math.degrees(math.asin(sin_min)),
                          float(ratios.min()), e_min, float(ratios.max()), e_max, circ, circ_bound)


@dataclass
class Spectrum:
    """Point Set Analysis (Schlomer 2011) of a 2D set normalised to the unit square."""

    frequencies: IndexArray     # integer frequencies -K..K along each axis
    power: FloatArray         # periodogram |sum exp(-2 pi i f.x)|^2 / n, DC removed
    radii: FloatArray         # annulus centres |f|
    radial_mean: FloatArray   # mean power per annulus
    anisotropy_db: FloatArray  # 10 log10(variance / mean^2) per annulus


def spectrum(x: FloatArray, lo: FloatArray, hi: FloatArray, k_max: Optional[int] = None,
             max_points: int = 10_000, seed: int = 0) -> Spectrum:
    """Periodogram with the DC removed, radial mean power and anisotropy (the paper's
    Figures 6-8). Large sets are subsampled to max_points (uniformly, without replacement).
    Frequencies reach twice sqrt(n), beyond the first ring of a maximal set (near sqrt(n))."""
    u = (x[:, :2] - lo[:2]) / (hi[:2] - lo[:2])
    if len(u) > max_points:
        u = u[np.random.default_rng(seed).choice(len(u), max_points, replace=False)]
    if k_max is None:
        k_max = int(min(200, max(32, 2 * np.sqrt(len(u)))))
    f = np.arange(-k_max, k_max + 1)
    ex = np.exp(-2j * np.pi * np.outer(u[:, 0], f))
    ey = np.exp(-2j * np.pi * np.outer(u[:, 1], f))
    power = np.abs(ex.T @ ey) ** 2 / len(u)
    power[k_max, k_max] = 0.0
    fx, fy = np.meshgrid(f, f, indexing="ij")
    rad = np.hypot(fx, fy)
    bins = np.arange(1, k_max + 1)
    which = np.floor(rad).astype(int)
    mean = np.array([power[which == b].mean() for b in bins])
    var = np.array([power[which == b].var() for b in bins])
    with np.errstate(divide="ignore", invalid="ignore"):
        aniso = 10 * np.log10(var / mean ** 2)
    # bins + 0.5 is float64; numpy's annotations say only floating
    return Spectrum(f, power, cast(FloatArray, bins + 0.5), mean, aniso)


def delaunay_histograms(x: FloatArray, r: FloatArray, lo: FloatArray, hi: FloatArray
                        ) -> tuple[FloatArray, FloatArray]:
    """Minimum angle (degrees) of each triangle whose circumcentre is in the box, and the edge
    length / r(x) ratios of their edges (both endpoints)."""
    s, lengths, _, _, angles = _interior_triangles(x, lo, hi)
    min_angles = np.degrees(np.minimum(np.minimum(*angles[:2]), angles[2]))
    return min_angles, _edge_ratios(s, lengths, r)


# -- two radii: Prop. 4.1-4.2 ---------------------------------------------------------------------


@dataclass
class TwoRadiiDelaunayReport:
    """Prop. 4.1-4.2 at scale t for a uniform r: R_f = t inhibition r, R_c = t coverage r."""

    triangles: int
    min_angle_deg: float
    angle_bound_deg: float     # arcsin(R_f / (2 R_c))
    edge_min: float
    edge_min_bound: float      # R_f
    edge_max: float
    edge_max_bound: float      # 2 R_c
    circumradius_max: float
    circumradius_bound: float  # R_c

    def violations(self, rel_tol: float = 1e-12) -> list[str]:
        """The bounds broken (empty when all hold), with round-off allowance rel_tol."""
        out = []
        if self.edge_min < self.edge_min_bound * (1 - rel_tol):
            out.append(f"edge {self.edge_min} < R_f = {self.edge_min_bound}")
        if self.edge_max > self.edge_max_bound * (1 + rel_tol):
            out.append(f"edge {self.edge_max} > 2 R_c = {self.edge_max_bound}")
        if self.circumradius_max > self.circumradius_bound * (1 + rel_tol):
            out.append(f"circumradius {self.circumradius_max} > R_c = {self.circumradius_bound}")
        if self.min_angle_deg < self.angle_bound_deg * (1 - rel_tol) - 1e-9:
            out.append(f"angle {self.min_angle_deg} deg < {self.angle_bound_deg} deg")
        return out


def check_delaunay_two_radii(x: FloatArray, radius: float, t: float, inhibition: float,
                             coverage: float, lo: FloatArray, hi: FloatArray,
                             disk_inside: bool = True) -> TwoRadiiDelaunayReport:
    """Prop. 4.1 (|e| in [R_f, 2R], R <= R_c) and Prop. 4.2 (sin a >= |e| / 2R, so the smallest
    angle is at least arcsin(R_f / 2R_c): 30 deg for equal radii, 14.48 deg for R_c = 2 R_f)
    on the interior Delaunay triangles (2D): those whose circumdisk lies in the box (or, with
    disk_inside False, whose circumcentre does), where the empty circumdisk is an uncovered
    region of the domain that maximality bounds."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    s, (la, lb, lc), _, R, angles = _interior_triangles(np.asarray(x, dtype=np.float64), lo, hi,
                                                        disk_inside)
    r_f, r_c = t * inhibition * radius, t * coverage * radius
    if len(s) == 0:
        return TwoRadiiDelaunayReport(0, 180.0, math.degrees(math.asin(min(1.0, r_f / (2 * r_c)))),
                                      math.inf, r_f, 0.0, 2 * r_c, 0.0, r_c)
    edges = np.concatenate([la, lb, lc])
    min_angle = float(np.degrees(np.minimum(np.minimum(*angles[:2]), angles[2]).min()))
    return TwoRadiiDelaunayReport(int(len(s)), min_angle,
                                  math.degrees(math.asin(min(1.0, r_f / (2 * r_c)))),
                                  float(edges.min()), r_f, float(edges.max()), 2 * r_c,
                                  float(R.max()), r_c)


# -- periodic: the tiled copy ---------------------------------------------------------------------


@dataclass
class TilingReport:
    copies: int                    # 3^p
    points: int                    # samples in the tiled copy
    conflicts: int                 # pairs of the tiled copy (any two copies) closer than allowed
    maximality: MaximalityReport   # over a tile-sized window of the tiled copy, seams inside


def _symmetric_f(rule: str, ra: FloatArray, rb: FloatArray) -> FloatArray:
    """f for a pair without an order: conflicting in both orders (prior, current: the smaller r)."""
    return np.maximum(ra, rb) if rule == "bigger" else np.minimum(ra, rb)


def check_tiling(x: FloatArray, r: FloatArray, rule: str, sizing: Sizing, lo: FloatArray,
                 hi: FloatArray, periodic: Periodic, conflict_scale: float, cover_scale: float,
                 shift: float = 0.5, rel_tol: float = 1e-12, probes: int = 50_000,
                 stop_at_gap: bool = False) -> TilingReport:
    """A 3^p tiled copy of a periodic output is itself a valid sampling: no two of its points
    (copies of one sample included) closer than conflict_scale f, with f for both orders of the
    pair (bigger: max r, the other rules: min r), and maximal at cover_scale over the central
    tile moved by `shift` periods along the periodic axes, so that the seams cross the window
    (shift 0: the central tile itself). Why: it checks the seams with plain Euclidean geometry,
    independently of the minimum-image bookkeeping of the periodic checks."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    mask = _periodic_mask(periodic, x.shape[1])
    if mask is None:
        raise ValueError("check_tiling needs at least one periodic axis")
    xt, rt, _ = periodic_images(x, r, lo, hi, mask)
    tree = cKDTree(xt)
    pairs = tree.query_pairs(conflict_scale * float(rt.max()) * (1 + 1e-9), output_type="ndarray")
    conflicts = 0
    if len(pairs):
        a, b = pairs[:, 0], pairs[:, 1]
        dist = np.linalg.norm(xt[a] - xt[b], axis=1)
        f = conflict_scale * _symmetric_f(rule, rt[a], rt[b])
        conflicts = int(np.count_nonzero(dist < f * (1 - rel_tol)))
    off = np.where(mask, shift * (hi - lo), 0.0)
    rep = check_maximal(xt, rt, rule, cover_scale, _wrapped_sizing(sizing, lo, hi, mask),
                        lo + off, hi + off, probes=probes, stop_at_gap=stop_at_gap)
    return TilingReport(3 ** int(mask.sum()), len(xt), conflicts, rep)


# -- the continuous stream: prefixes --------------------------------------------------------------


def probe_coverage(x: FloatArray, r: FloatArray, rule: str, scale: float, sizing: Sizing,
                   lo: FloatArray, hi: FloatArray, probes: int = 20_000, seed: int = 0, *,
                   periodic: Periodic = None) -> tuple[int, float, Optional[FloatArray]]:
    """(gaps, max g / r, worst probe) over random probes of the box (and its corners): the cheap,
    incomplete maximality check, for when the branch-and-bound would cost too much."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    d = len(lo)
    if len(x) == 0:
        return probes, math.inf, (lo + hi) / 2
    if _periodic_mask(periodic, d) is not None:
        x, r, _ = periodic_images(x, r, lo, hi, periodic)
    rng = np.random.default_rng(seed)
    corners = lo + np.array(np.meshgrid(*[[0, 1]] * d, indexing="ij")).reshape(d, -1).T * (hi - lo)
    y = np.vstack([lo + rng.random((probes, d)) * (hi - lo), corners])
    ry = sizing.fn(y)
    tree = cKDTree(x)
    g = coverage_margin(y, tree, x, r, rule, scale, ry)
    sus = g > 1e-9 * ry
    if sus.any():
        g[sus] = coverage_margin(y[sus], tree, x, r, rule, scale, ry[sus], exact=True)
    rel = g / ry
    gaps = int(np.count_nonzero(rel > 1e-9))
    w = int(np.argmax(rel))
    return gaps, float(rel[w]), (y[w] if gaps else None)


@dataclass
class PrefixTauReport:
    tau: float
    size: int                  # samples with t_k >= tau
    conflicts: int             # insertion-order pairs closer than tau inhibition (1 - rel_tol) f
    gaps: int                  # uncovered points found at tau coverage f
    worst: float               # max g / r found (g > 0: uncovered); B&B: its unresolved bound too
    worst_gap: Optional[FloatArray]
    exhaustive: bool           # branch-and-bound (True) or random probes (False)
    maximality_checked: bool   # False for tau below the last t (the record ends before tau)


@dataclass
class PrefixReport:
    nonincreasing: bool
    first_increase: int        # index k with t_k > t_{k-1}, or -1
    conflicts_at_insertion: int  # pairs closer than t_i inhibition (1 - rel_tol) f: all taus
    taus: list[PrefixTauReport]

    @property
    def ok(self) -> bool:
        return (self.nonincreasing and self.conflicts_at_insertion == 0 and
                all(p.conflicts == 0 and p.gaps == 0 for p in self.taus))

    def failures(self) -> list[PrefixTauReport]:
        return [p for p in self.taus if p.conflicts or p.gaps]


def check_prefixes(x: FloatArray, r: FloatArray, t: FloatArray, rule: str, inhibition: float,
                   coverage: float, sizing: Sizing, lo: FloatArray, hi: FloatArray,
                   taus: Sequence[float], rel_tol: float, periodic: Periodic = None, *,
                   bnb_taus: Sequence[float] = (), probes: int = 20_000, seed: int = 0,
                   bnb_rel_tol: float = 1e-9) -> PrefixReport:
    """The stream's prefix property (Section 4.2): t is non-increasing, and for each tau the
    prefix {k : t_k >= tau} is conflict-free at tau inhibition (1 - rel_tol) in insertion order
    and maximal (covered) at tau coverage.

    Conflicts: every pair is checked once at the scale of its later sample
    (conflicts_at_insertion, all taus at once); a pair conflicting at some tau conflicts there
    too, so the count at each of `taus` is taken from those pairs, and at each of `bnb_taus`
    it is counted afresh on the prefix (a cross-check). Maximality: random probes at `taus`,
    the branch-and-bound at `bnb_taus` (exhaustive, slower). The hardest tau for the prefix of
    the first k samples is just above t_k, e.g. np.nextafter(t[k], inf). A tau below the last
    t only gets the conflict check: the prefix there holds samples the record does not have."""
    x = np.asarray(x, dtype=np.float64)
    r = np.asarray(r, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    inc = np.flatnonzero(t[1:] > t[:-1])
    first_increase = int(inc[0] + 1) if len(inc) else -1
    scales = np.where(np.isfinite(t), t * inhibition * (1 - rel_tol), 0.0)
    pi, pj = _conflict_pairs(x, r, scales, rule, sizing.lipschitz, 1e-12, periodic, lo, hi)
    pdist = toroidal_distance(x[pi], x[pj], lo, hi, periodic) if len(pi) else np.empty(0)
    pf = rule_f(rule, r[pj], r[pi]) if len(pi) else np.empty(0)
    t_last = float(t[-1]) if len(t) else math.inf
    reports = []
    for m, (tau, exhaustive) in enumerate([(float(v), False) for v in taus] +
                                          [(float(v), True) for v in bnb_taus]):
        sel = t >= tau
        xs, rs = x[sel], r[sel]
        s_f = tau * inhibition * (1 - rel_tol)
        if exhaustive:
            conflicts = empty_disk_violations(xs, rs, rule, s_f, sizing.lipschitz,
                                              periodic=periodic, lo=lo, hi=hi)
        else:
            conflicts = int(np.count_nonzero((t[pi] >= tau) & (t[pj] >= tau) &
                                             (pdist < s_f * pf * (1 - 1e-12))))
        gaps, worst, where, checked = 0, -math.inf, None, tau >= t_last and bool(sel.any())
        if checked and exhaustive:
            rep = check_maximal(xs, rs, rule, tau * coverage, sizing, lo, hi, rel_tol=bnb_rel_tol,
                                probes=probes, seed=seed + m, periodic=periodic, stop_at_gap=True)
            gaps, where = rep.gaps, rep.worst_gap
            worst = rep.probes_max_rel
            if rep.unresolved_bound > 0:
                worst = max(worst, rep.unresolved_bound)
            if where is not None:  # how deep the worst gap the search met is
                worst = max(worst, _margin_at(where, xs, rs, rule, tau * coverage, sizing, lo, hi,
                                              periodic))
        elif checked:
            gaps, worst, where = probe_coverage(xs, rs, rule, tau * coverage, sizing, lo, hi,
                                                probes, seed + m, periodic=periodic)
        reports.append(PrefixTauReport(tau, int(sel.sum()), conflicts, gaps, worst, where,
                                       exhaustive, checked))
    return PrefixReport(first_increase < 0, first_increase, len(pi), reports)


def _margin_at(y: FloatArray, x: FloatArray, r: FloatArray, rule: str, scale: float,
               sizing: Sizing, lo: FloatArray, hi: FloatArray, periodic: Periodic) -> float:
    """g(y) / r(y) exactly, at one point of the box."""
    if _periodic_mask(periodic, x.shape[1]) is not None:
        x, r, _ = periodic_images(x, r, lo, hi, periodic)
    y = np.asarray(y, dtype=np.float64)[None, :]
    ry = sizing.fn(y)
    g = coverage_margin(y, cKDTree(x), x, r, rule, scale, ry, exact=True)
    return float(g[0] / ry[0])


# -- uniform radius: the exact farthest point -----------------------------------------------------


def _circumcentres(p: FloatArray) -> tuple[FloatArray, BoolArray]:
    """Circumcentres of simplices p (m, d+1, d) and a mask of the non-degenerate ones."""
    a = 2 * (p[:, 1:, :] - p[:, :1, :])
    b = (p[:, 1:, :] ** 2).sum(axis=2) - (p[:, :1, :] ** 2).sum(axis=2)
    scale = np.abs(a).max(axis=(1, 2)) ** a.shape[1]
    det = np.linalg.det(a)
    ok = np.abs(det) > 1e-12 * np.maximum(scale, 1e-300)
    c = np.full((len(p), p.shape[2]), np.nan)
    if ok.any():
        c[ok] = np.linalg.solve(a[ok], b[ok][..., None])[..., 0]
    return c, ok


def largest_empty_ball(x: FloatArray, lo: FloatArray, hi: FloatArray,
                       periodic: Periodic = None) -> tuple[FloatArray, float]:
    """(y, R): the point of the box farthest from the samples x and its distance (toroidal along
    periodic axes), exact up to round-off, in 2D and 3D (any d scipy's Delaunay takes).
    Samples may lie outside the box.

    Why: with a uniform radius and inhibition = coverage the stream is farthest-point insertion,
    and a set is maximal at scale t iff R <= t coverage r. The maximum of the distance to the
    nearest sample over a box is at a Voronoi vertex in the box, where a Voronoi face meets the
    box's boundary, or at a corner; mirroring the samples across each non-periodic face (and
    taking periodic images) makes all of them circumcentres of Delaunay simplices, or corners.
    Only samples within an upper bound of R of a face are mirrored (and imaged): those farther
    cannot define a ball of radius R touching the face."""
    x = np.asarray(x, dtype=np.float64)
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    d = len(lo)
    mask = _periodic_mask(periodic, d)
    pmask = np.zeros(d, bool) if mask is None else mask
    if len(x) == 0:
        return (lo + hi) / 2, math.inf
    corners = lo + np.array(np.meshgrid(*[[0, 1]] * d, indexing="ij")).reshape(d, -1).T * (hi - lo)
    # an upper bound U of R from a grid: every point is within half a cell diagonal of a node
    m = int(np.clip(np.ceil((8 * len(x)) ** (1 / d)), 4, 400))
    axes = [np.linspace(lo[k], hi[k], m) for k in range(d)]
    nodes = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, d)
    imgs, _, _ = periodic_images(x, np.zeros(len(x)), lo, hi, pmask if mask is not None else None)
    tree = cKDTree(imgs)
    U = float(tree.query(nodes)[0].max()) + 0.5 * float(np.linalg.norm((hi - lo) / (m - 1)))
    U *= 1 + 1e-9
    if mask is not None:
        imgs, _, _ = periodic_images(x, np.zeros(len(x)), lo, hi, mask, margin=2 * U)
        tree = cKDTree(imgs)
    parts = [imgs]
    for k in np.flatnonzero(~pmask):
        for face, side in ((lo[k], 1.0), (hi[k], -1.0)):
            # a sample beyond the face (a fixed point) is not mirrored: its mirror would be a
            # false, nearer sample inside the box
            gap = side * (imgs[:, k] - face)
            near = (gap >= 0) & (gap <= U)
            mir = imgs[near].copy()
            mir[:, k] = 2 * face - mir[:, k]
            parts.append(mir)
    aug = np.concatenate(parts)
    found = [corners]
    if len(aug) >= d + 1:
        try:
            tri = Delaunay(aug)
            c, ok = _circumcentres(aug[tri.simplices])
            c = c[ok]
            tol = 1e-12 * float(np.abs(hi - lo).max())
            c = c[np.all((c >= lo - tol) & (c <= hi + tol), axis=1)]
            found.append(np.clip(c, lo, hi))
        except Exception:  # noqa: BLE001 - too few or degenerate points: the grid and corners
            found.append(nodes)
    cand = np.concatenate(found)
    dist = tree.query(cand)[0]
    w = int(np.argmax(dist))
    return cand[w], float(dist[w])
