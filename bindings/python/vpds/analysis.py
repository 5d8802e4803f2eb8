"""Checks of a sampling against the paper's definitions, and its spectral analysis.

Written from the paper alone, with numpy and scipy: nothing here calls or copies the C library,
so it is an independent check of its output (the project's tests use it, and `vpds analyze`). A sampling is checked for
  - the empty-disk property in insertion order (Eq. 10 with the rule's f),
  - maximality (Eq. 11 empty): a branch-and-bound over the box on the coverage margin
        g(y) = min_i |y - x_i| - s f(x_i, y),
    which is (1 + s L)-Lipschitz, so a box whose centre has g(c) + K h/2 <= 0 is covered whole
    and a centre with g(c) > 0 is a gap: no gap wider than the stopping size can be missed,
  - the Delaunay bounds of Table 1 on triangles whose circumcentre lies in the box (2D).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np
from scipy.spatial import Delaunay, cKDTree

RULES = ("prior", "current", "bigger", "smaller")


def rule_f(rule: str, rx: np.ndarray, ry: np.ndarray) -> np.ndarray:
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

    fn: Callable[[np.ndarray], np.ndarray]
    lipschitz: float


def sizing_named(name: str, radius: float = 0.0) -> Sizing:
    if name == "const":
        return Sizing(lambda y: np.full(len(y), radius), 0.0)
    if name == "ramp":  # the paper's Figure 1
        return Sizing(lambda y: 0.001 + 0.3 * y[:, 0], 0.3)
    if name == "mild":  # a gentle ramp, for the weighted process
        return Sizing(lambda y: 0.04 + 0.04 * y[:, 0], 0.04)
    if name == "radial":  # the paper's Figure 10
        def radial(y: np.ndarray) -> np.ndarray:
            d = np.sqrt(((y - 0.5) ** 2).sum(axis=1))
            return 0.015 + (0.00015 - 0.015) * np.abs(np.sin(8 * np.pi * d))
        return Sizing(radial, 0.01485 * 8 * np.pi)
    raise ValueError(name)


def load(path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    raw = np.fromfile(path, dtype=np.int64, count=2)
    n, d = int(raw[0]), int(raw[1])
    data = np.fromfile(path, dtype=np.float64, offset=16)
    x = data[: n * d].reshape(n, d)
    r = data[n * d : n * d + n]
    t = data[n * d + n : n * d + 2 * n]
    return x, r, t


def empty_disk_violations(x: np.ndarray, r: np.ndarray, rule: str, scale: float, lipschitz: float,
                          rel_tol: float = 1e-12) -> int:
    """Pairs j < i with |x_i - x_j| < scale f(x_j, x_i) (x_j the earlier sample)."""
    n = len(x)
    if n < 2:
        return 0
    tree = cKDTree(x)
    sl = scale * lipschitz
    # every conflicting earlier sample lies within scale r_i / (1 - sL) of x_i (Lipschitz)
    reach = scale * r / (1 - sl) if rule in ("prior", "bigger") else scale * r
    lists = tree.query_ball_point(x, reach * (1 + 1e-9), return_sorted=False)
    counts = np.fromiter((len(v) for v in lists), dtype=np.int64, count=n)
    i = np.repeat(np.arange(n), counts)
    j = np.fromiter((k for v in lists for k in v), dtype=np.int64, count=int(counts.sum()))
    keep = j < i
    i, j = i[keep], j[keep]
    dist = np.linalg.norm(x[i] - x[j], axis=1)
    f = scale * rule_f(rule, r[j], r[i])
    return int(np.count_nonzero(dist < f * (1 - rel_tol)))


def coverage_margin(points: np.ndarray, tree: cKDTree, x: np.ndarray, r: np.ndarray, rule: str,
                    scale: float, r_at: np.ndarray, k: int = 24, exact: bool = False) -> np.ndarray:
    """g at points: an upper bound from the k nearest samples, or exact (all samples in reach)."""
    kk = min(k, len(x))
    dist, idx = tree.query(points, k=kk)
    if kk == 1:
        dist, idx = dist[:, None], idx[:, None]
    g = (dist - scale * rule_f(rule, r[idx], r_at[:, None])).min(axis=1)
    if exact:
        rmax = r.max()
        for m in range(len(points)):
            reach = g[m] + scale * max(rmax, r_at[m])
            if reach <= 0:
                continue
            near = tree.query_ball_point(points[m], reach * (1 + 1e-9))
            if near:
                nd = np.linalg.norm(x[near] - points[m], axis=1)
                g[m] = min(g[m], float((nd - scale * rule_f(rule, r[near], r_at[m])).min()))
    return g


def box_covered_by_one(centres: np.ndarray, side: np.ndarray, tree: cKDTree, x: np.ndarray,
                       r: np.ndarray, rule: str, scale: float, r_lo: np.ndarray,
                       k: int = 12) -> np.ndarray:
    """Boxes (centre, side) wholly inside one sample's disk, r over the box being >= r_lo."""
    kk = min(k, len(x))
    _, idx = tree.query(centres, k=kk)
    if kk == 1:
        idx = idx[:, None]
    far = np.abs(x[idx] - centres[:, None, :]) + side / 2
    maxd = np.sqrt((far ** 2).sum(axis=2))
    reach = scale * rule_f(rule, r[idx], r_lo[:, None])
    return ((reach > 0) & (maxd <= reach)).any(axis=1)


@dataclass
class MaximalityReport:
    gaps: int                 # centres found uncovered (g > tol)
    worst_gap: np.ndarray | None
    boxes: int                # boxes examined
    unresolved_bound: float   # sup of g over boxes left at the stopping size (relative to r)
    probes_max_rel: float     # max of g / r over random probes


def check_maximal(x: np.ndarray, r: np.ndarray, rule: str, scale: float, sizing: Sizing,
                  lo: np.ndarray, hi: np.ndarray, rel_tol: float = 1e-9, probes: int = 200_000,
                  seed: int = 0, max_boxes: int = 20_000_000) -> MaximalityReport:
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


def _interior_triangles(x: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Delaunay triangles whose circumcentre lies in the box (where maximality bounds them):
    vertex indices, edge lengths opposite each vertex, circumcentres, circumradii, angles."""
    tri = Delaunay(x)
    s = tri.simplices
    a, b, c = x[s[:, 0]], x[s[:, 1]], x[s[:, 2]]
    d = 2 * (a[:, 0] * (b[:, 1] - c[:, 1]) + b[:, 0] * (c[:, 1] - a[:, 1]) + c[:, 0] * (a[:, 1] - b[:, 1]))
    ux = ((a ** 2).sum(1) * (b[:, 1] - c[:, 1]) + (b ** 2).sum(1) * (c[:, 1] - a[:, 1]) + (c ** 2).sum(1) * (a[:, 1] - b[:, 1])) / d
    uy = ((a ** 2).sum(1) * (c[:, 0] - b[:, 0]) + (b ** 2).sum(1) * (a[:, 0] - c[:, 0]) + (c ** 2).sum(1) * (b[:, 0] - a[:, 0])) / d
    u = np.stack([ux, uy], axis=1)
    inside = np.all((u >= lo) & (u <= hi), axis=1) & np.isfinite(u).all(axis=1)
    s, a, b, c, u = s[inside], a[inside], b[inside], c[inside], u[inside]
    la = np.linalg.norm(b - c, axis=1)
    lb = np.linalg.norm(c - a, axis=1)
    lc = np.linalg.norm(a - b, axis=1)
    ang_a = np.arccos(np.clip((lb ** 2 + lc ** 2 - la ** 2) / (2 * lb * lc), -1, 1))
    ang_b = np.arccos(np.clip((la ** 2 + lc ** 2 - lb ** 2) / (2 * la * lc), -1, 1))
    ang_c = np.pi - ang_a - ang_b
    return s, (la, lb, lc), u, np.linalg.norm(a - u, axis=1), (ang_a, ang_b, ang_c)


def _edge_ratios(s: np.ndarray, lengths, r: np.ndarray) -> np.ndarray:
    la, lb, lc = lengths
    return np.concatenate([la / r[s[:, 1]], la / r[s[:, 2]], lb / r[s[:, 2]], lb / r[s[:, 0]],
                           lc / r[s[:, 0]], lc / r[s[:, 1]]])


def check_delaunay(x: np.ndarray, r: np.ndarray, rule: str, L: float, lo: np.ndarray,
                   hi: np.ndarray, sizing: Sizing | None = None) -> DelaunayReport:
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

    frequencies: np.ndarray   # integer frequencies -K..K along each axis
    power: np.ndarray         # periodogram |sum exp(-2 pi i f.x)|^2 / n, DC removed
    radii: np.ndarray         # annulus centres |f|
    radial_mean: np.ndarray   # mean power per annulus
    anisotropy_db: np.ndarray  # 10 log10(variance / mean^2) per annulus


def spectrum(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, k_max: Optional[int] = None,
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
    return Spectrum(f, power, bins + 0.5, mean, aniso)


def delaunay_histograms(x: np.ndarray, r: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Minimum angle (degrees) of each triangle whose circumcentre is in the box, and the edge
    length / r(x) ratios of their edges (both endpoints)."""
    s, lengths, _, _, angles = _interior_triangles(x, lo, hi)
    min_angles = np.degrees(np.minimum(np.minimum(*angles[:2]), angles[2]))
    return min_angles, _edge_ratios(s, lengths, r)
