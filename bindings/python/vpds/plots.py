"""Pictures of a sampling: the points (`vpds sample --plot`) and the analysis sheet
(`vpds analyze --plot`). matplotlib is imported here only, when a picture is asked for.

The points are coloured by their radius r (a colour bar labelled "r", logarithmic when the
radii span more than a factor 10) and drawn with their disks for small n. Where the points are
too dense to tell apart at the page's resolution, a second panel zooms on the densest place
(the smallest radii) and shows every point there with its disk. In 3D and above the picture is
the 2D slice through the middle of the box (x[2] = ... = mid): the cross-sections of the balls
that cut it, centred on their projected centres; in 1D a strip."""
from __future__ import annotations

import textwrap
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, Optional

import numpy as np
import numpy.typing as npt

from ._optional import require
from ._typing import FloatArray

if TYPE_CHECKING:  # for the annotations: matplotlib (and scipy) are imported when drawing
    from matplotlib.axes import Axes
    from matplotlib.colorbar import Colorbar
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    from .analysis import DelaunayReport

MAX_DISKS = 5000        # draw every disk up to this many points (the main panel)
ZOOM_POINTS = 250       # points the zoom panel aims to hold
DENSE_PIXELS = 4.0      # a zoom panel when the small radii (5% quantile) are below this many pixels
_CMAP = "viridis"


def _pyplot() -> ModuleType:
    """matplotlib's pyplot on the Agg backend, or MissingDependencyError naming the install."""
    matplotlib = require("matplotlib", "plotting", "matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _new_figure(**kwargs: Any) -> Figure:
    """A Figure outside pyplot's registry (nothing to close; garbage-collected)."""
    _pyplot()
    from matplotlib.figure import Figure
    return Figure(**kwargs)


def _as_points(x: npt.ArrayLike, dim: int) -> FloatArray:
    """x as an (n, d) float array (a flat array: 1D points; none: (0, dim))."""
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return np.zeros((0, x.shape[1] if x.ndim == 2 and x.shape[1] else dim))
    return x[:, None] if x.ndim == 1 else x


# -- what to draw ----------------------------------------------------------------------------------


class _View:
    """The points as a picture shows them: 2D coordinates u, disk radii rho (the sample's r, or
    in 3D+ its ball's cross-section with the slice), the sample radii r (for the colour), and
    a sentence saying what was selected."""

    def __init__(self, x: FloatArray, r: Optional[FloatArray], lo: FloatArray, hi: FloatArray) -> None:
        self.lo = np.asarray(lo, dtype=float).reshape(-1)
        self.hi = np.asarray(hi, dtype=float).reshape(-1)
        x = _as_points(x, len(self.lo))
        self.n, self.dim = x.shape
        r_all = np.zeros(self.n) if r is None else np.asarray(r, dtype=float).reshape(-1)
        self.r_all = r_all
        self.has_radii = r is not None and self.n > 0
        self.selection = ""
        if self.dim >= 3:
            mid = (self.lo[2:] + self.hi[2:]) / 2
            dist2 = ((x[:, 2:] - mid) ** 2).sum(axis=1)
            keep = dist2 < r_all ** 2
            self.u = x[keep, :2]
            self.r = r_all[keep]
            self.rho = np.sqrt(r_all[keep] ** 2 - dist2[keep])
            plane = ", ".join(f"x[{k}] = {m:.4g}" for k, m in zip(range(2, self.dim), mid))
            self.selection = (f"slice {plane}: the {len(self.u)} of {self.n} "
                              f"{'balls' if self.dim == 3 else 'hyperballs'} that cut it "
                              f"(their cross-sections, centres projected)")
        elif self.dim == 2:
            self.u, self.r, self.rho = x, r_all, r_all
        else:
            self.u = np.column_stack([x[:, 0], np.zeros(self.n)])
            self.r, self.rho = r_all, r_all

    @property
    def box(self) -> tuple[FloatArray, FloatArray]:
        """(lo, hi) of the two drawn axes (1D: the axis and a unit band)."""
        if self.dim >= 2:
            return self.lo[:2], self.hi[:2]
        return np.array([self.lo[0], -1.0]), np.array([self.hi[0], 1.0])


def _norm(r: FloatArray, has_radii: bool) -> Optional[Normalize]:
    """The colour scale of the radii: None for one radius, log when they span over 10x."""
    from matplotlib.colors import LogNorm, Normalize
    if not has_radii or len(r) == 0:
        return None
    r_min, r_max = float(np.min(r)), float(np.max(r))
    if not np.isfinite(r_min) or r_max <= r_min * (1 + 1e-9):
        return None
    if r_min > 0 and r_max > 10 * r_min:
        return LogNorm(vmin=r_min, vmax=r_max)
    return Normalize(vmin=r_min, vmax=r_max)


def _colours(r: FloatArray, norm: Optional[Normalize], fallback: str = "tab:blue") -> FloatArray:
    import matplotlib
    if norm is None:
        return np.array([matplotlib.colors.to_rgba(fallback)] * len(r)).reshape(len(r), 4)
    rgba: FloatArray = matplotlib.colormaps[_CMAP](norm(r))  # (n, 4), for an array of n values
    return rgba


def _zoom_window(view: _View, k: int = ZOOM_POINTS) -> Optional[tuple[FloatArray, FloatArray]]:
    """(lo, hi) of a square window around the smallest radius holding about k points, inside
    the box (a constant radius: around the point nearest the centre)."""
    u, r = view.u, view.r
    lo, hi = view.box
    if len(u) == 0:
        return None
    centre = (lo + hi) / 2
    smallest = np.flatnonzero(r <= r.min() * (1 + 1e-9))
    i = smallest[np.argmin(((u[smallest] - centre) ** 2).sum(axis=1))]
    c = u[i].copy()
    cheb = np.max(np.abs(u - c), axis=1)
    kk = min(k, len(u) - 1)
    h = float(np.partition(cheb, kk)[kk]) if kk > 0 else float(r[i])
    # at most 20 smallest radii across half the window (a steep gradient brings in the large
    # ones fast), at least 3
    h = min(h, 20 * float(view.rho[i]))
    h = max(h, 3 * float(view.rho[i]), 1e-12)
    if h > float(np.min(hi - lo)) / 8:
        return None     # a zoom by less than 4x shows nothing the whole box does not
    c = np.clip(c, lo + h, hi - h)
    return c - h, c + h


def _is_dense(view: _View, pixels_per_unit: float) -> bool:
    """Are the small radii (their 5% quantile) below DENSE_PIXELS on the page?"""
    if len(view.r) < 2 or not view.has_radii:
        return False
    return float(np.quantile(view.r, 0.05)) * pixels_per_unit < DENSE_PIXELS


# -- drawing ---------------------------------------------------------------------------------------


def _draw_2d(ax: Axes, view: _View, norm: Optional[Normalize], *, lo2: FloatArray, hi2: FloatArray,
             disks: bool, pixels_per_unit: float, dpi: float, window: Optional[bool] = None) -> None:
    """The points (and disks) in the rectangle lo2..hi2 of ax; window: only those near it."""
    from matplotlib.collections import EllipseCollection
    u, r, rho = view.u, view.r, view.rho
    if window is not None:
        reach = np.max(np.abs(u - (lo2 + hi2) / 2) - rho[:, None], axis=1) < float(np.max(hi2 - lo2)) / 2
        u, r, rho = u[reach], r[reach], rho[reach]
    colours = _colours(r, norm)
    if disks and len(u):
        fill = colours.copy()
        fill[:, 3] = 0.13
        edge = colours.copy()
        edge[:, 3] = 0.55
        ax.add_collection(EllipseCollection(
            2 * rho, 2 * rho, np.zeros(len(u)), units="xy", offsets=u, offset_transform=ax.transData,
            facecolors=fill, edgecolors=edge, linewidths=0.5, rasterized=len(u) > 500))
    # dots: about half the disk's radius across, at least one pixel, at most 7
    if len(u):
        diameter_px = np.clip((0.5 if disks else 0.8) * r * pixels_per_unit, 1.2, 7.0)
        _dots(ax, u, r, diameter_px, norm, dpi)
    ax.set_xlim(lo2[0], hi2[0])
    ax.set_ylim(lo2[1], hi2[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x[0]")
    ax.set_ylabel("x[1]")


def _dots(ax: Axes, u: FloatArray, r: FloatArray, diameter_px: FloatArray,
          norm: Optional[Normalize], dpi: float, exact_up_to: int = 20000) -> None:
    """A dot per point, coloured by r, diameter_px pixels across. Many points: grouped into 64
    colour levels x 8 sizes, each group one single-colour scatter (Agg blits one marker: ~10x
    faster than per-point colours, and the eye cannot tell 64 levels from a continuum)."""
    import matplotlib
    size = (diameter_px * 72.0 / dpi) ** 2
    if len(u) <= exact_up_to:
        ax.scatter(u[:, 0], u[:, 1], s=size, c=_colours(r, norm), linewidths=0,
                   rasterized=len(u) > 2000, zorder=3)
        return
    cmap = matplotlib.colormaps[_CMAP]
    level = (np.clip(np.asarray(norm(r), dtype=float), 0, 1) * 63.999).astype(int) if norm is not None \
        else np.zeros(len(u), dtype=int)
    edges = np.geomspace(diameter_px.min(), diameter_px.max() * (1 + 1e-9) + 1e-12, 9)
    which = np.clip(np.searchsorted(edges, diameter_px, side="right") - 1, 0, 7)
    key = level * 8 + which
    order = np.argsort(key, kind="stable")
    keys, starts = np.unique(key[order], return_index=True)
    for kk, a, b in zip(keys, starts, list(starts[1:]) + [len(order)]):
        idx = order[a:b]
        colour = cmap((kk // 8 + 0.5) / 64) if norm is not None else "tab:blue"
        ax.scatter(u[idx, 0], u[idx, 1], s=float(np.mean(size[idx])), color=colour, linewidths=0,
                   rasterized=True, zorder=3)


def _draw_1d(ax: Axes, view: _View, norm: Optional[Normalize], *, lo1: float, hi1: float,
             disks: bool) -> None:
    """A strip: each point a tick coloured by r, under it its interval [x - r, x + r] (small n),
    on three staggered rows so that neighbours' intervals stay apart."""
    from matplotlib.collections import LineCollection
    x, r = view.u[:, 0], view.r
    inside = (x + r >= lo1) & (x - r <= hi1)
    x, r = x[inside], r[inside]
    order = np.argsort(x)
    x, r = x[order], r[order]
    colours = _colours(r, norm)
    # the ignores: matplotlib's annotations want sequences, where its documentation takes the
    # arrays given here (segments (n, 2, 2), colours (n, 4))
    if disks and len(x):
        rows = -0.35 - 0.2 * (np.arange(len(x)) % 3)
        segments = np.stack([np.column_stack([x - r, rows]), np.column_stack([x + r, rows])], axis=1)
        ax.add_collection(LineCollection(segments, colors=colours, linewidths=1.5))  # type: ignore[arg-type]
    ax.vlines(x, 0, 0.8, colors=colours, linewidths=0.8, rasterized=len(x) > 2000)  # type: ignore[arg-type]
    ax.set_xlim(lo1, hi1)
    ax.set_ylim(-0.9, 1.0)
    ax.set_yticks([])
    ax.set_xlabel("x[0]")


def _wrap(title: str, width: int) -> str:
    return "\n".join(textwrap.wrap(title, width)) if title else ""


def points_figure(x: FloatArray, r: Optional[FloatArray], lo: FloatArray, hi: FloatArray,
                  title: str = "", *, zoom: Optional[bool] = None, disks: Optional[bool] = None,
                  dpi: float = 150) -> Figure:
    """The Figure of `vpds sample --plot`: the points x (n, d) in the box lo, hi (d,), coloured
    by r (n,) or None with a colour bar, their disks for small n, a zoom panel on the densest
    place when the points cannot be told apart (zoom=None: decide; False: never; True: whenever
    a window 4x smaller than the box holds the smallest radii), a slice in 3D+, a strip in 1D."""
    view = _View(x, r, lo, hi)
    norm = _norm(view.r_all, view.has_radii)
    if disks is None:
        disks = len(view.u) <= MAX_DISKS
    if view.dim == 1:
        return _points_figure_1d(view, norm, title, zoom, disks, dpi)
    lo2, hi2 = view.box
    side = hi2 - lo2
    aspect = float(np.clip(side[1] / side[0], 0.25, 4.0))
    if zoom is None:
        zoom = _is_dense(view, 5.0 * 0.85 * dpi / side[0])
    windows = []
    if zoom:
        fine = _zoom_window(view)
        if fine is not None:
            windows = [fine]
            # a zoom by more than 30x: a middle step at the geometric mean, same centre, so
            # that the eye follows from the box to the points (and sees the gradient between)
            factor = float(np.min(side)) / float(fine[1][0] - fine[0][0])
            if factor > 30:
                c, h = (fine[0] + fine[1]) / 2, float(np.min(side)) / np.sqrt(factor) / 2
                c = np.clip(c, lo2 + h, hi2 - h)
                windows.insert(0, (c - h, c + h))
    panels = 1 + len(windows)
    main_w = {1: 6.5, 2: 6.0, 3: 5.0}[panels]
    main_w = main_w if aspect <= 1 else main_w / aspect
    height = main_w * aspect                    # of a panel; the zoom panels are square
    pixels_per_unit = main_w * 0.85 * dpi / side[0]
    wrapped = _wrap(title, int(14 * (main_w + (panels - 1) * height)))
    fig = _new_figure(figsize=(main_w + (panels - 1) * height + (1.1 if norm is not None else 0.3),
                               height * 0.92 + 0.9 + 0.2 * max(1, len(wrapped.splitlines()))),
                      dpi=dpi, layout="constrained")
    axes = fig.subplots(1, panels, squeeze=False, width_ratios=[main_w] + [height] * (panels - 1))[0]
    ax = axes[0]
    _draw_2d(ax, view, norm, lo2=lo2, hi2=hi2, disks=disks, pixels_per_unit=pixels_per_unit, dpi=dpi)
    ax.set_title(view.selection or ("all points" + (" with their disks" if disks else "")),
                 fontsize=8)
    outer = ax
    for step, ((zl, zh), zax) in enumerate(zip(windows, axes[1:])):
        inside = np.all((view.u >= zl) & (view.u <= zh), axis=1)
        count = int(inside.sum())
        last = step == len(windows) - 1
        zdisks = last or count <= MAX_DISKS
        _draw_2d(zax, view, norm, lo2=zl, hi2=zh, disks=zdisks,
                 pixels_per_unit=height * 0.85 * dpi / float(zh[0] - zl[0]), dpi=dpi, window=True)
        factor = float(np.min(side)) / float(zh[0] - zl[0])
        zax.set_title(f"{'zoom on the smallest radii' if last else 'zoom'}: [{zl[0]:.4g}, {zh[0]:.4g}]"
                      f" x [{zl[1]:.4g}, {zh[1]:.4g}],\n{count} points"
                      f"{' with their disks' if zdisks else ''} ({factor:.0f}x)", fontsize=8)
        _indicate(outer, zax, zl, zh)
        outer = zax
    _colour_bar(fig, list(axes), norm, view)
    fig.suptitle(wrapped, fontsize=9)
    return fig


def _indicate(ax: Axes, zax: Axes, zl: FloatArray, zh: FloatArray) -> None:
    """The zoom window's rectangle on ax, with lines to zax; a ring around it when it is tiny."""
    ax.indicate_inset(bounds=(zl[0], zl[1], zh[0] - zl[0], zh[1] - zl[1]), inset_ax=zax,
                      edgecolor="red", alpha=0.9, linewidth=1.2)
    lo_, hi_ = ax.get_xlim()
    if (zh[0] - zl[0]) / (hi_ - lo_) < 0.02:
        c = (zl + zh) / 2
        ax.plot([c[0]], [c[1]], "o", ms=12, mfc="none", mec="red", mew=1.5, zorder=5)
    for spine in zax.spines.values():
        spine.set_edgecolor("red")
        spine.set_linewidth(1.2)


def _colour_bar(fig: Figure, axes: list[Axes], norm: Optional[Normalize], view: _View) -> Optional[Colorbar]:
    import matplotlib
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import LogNorm
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    if norm is None:
        if view.has_radii and len(view.r_all):
            axes[0].set_title(f"{axes[0].get_title()}; r = {view.r_all[0]:.4g} for all",
                              fontsize=axes[0].title.get_fontsize())
        return None
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=matplotlib.colormaps[_CMAP]), ax=axes,
                       shrink=0.85, pad=0.01, aspect=30)
    bar.set_label("r", rotation=0, fontsize=12, labelpad=8)
    if isinstance(norm, LogNorm):
        bar.ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        bar.ax.yaxis.set_minor_formatter(NullFormatter())
    return bar


def _points_figure_1d(view: _View, norm: Optional[Normalize], title: str, zoom: Optional[bool],
                      disks: bool, dpi: float) -> Figure:
    lo1, hi1 = float(view.lo[0]), float(view.hi[0])
    pixels_per_unit = 11 * 0.85 * dpi / (hi1 - lo1)
    if zoom is None:
        zoom = _is_dense(view, pixels_per_unit)
    rows = 2 if zoom and len(view.u) else 1
    wrapped = _wrap(title, 160)
    fig = _new_figure(figsize=(12, 1.1 + 1.5 * rows + 0.2 * max(1, len(wrapped.splitlines()))),
                      dpi=dpi, layout="constrained")
    axes = fig.subplots(rows, 1, squeeze=False)[:, 0]
    _draw_1d(axes[0], view, norm, lo1=lo1, hi1=hi1, disks=disks)
    axes[0].set_title("all points" + (" (ticks) with their intervals [x - r, x + r] below"
                                      if disks else " (ticks)"), fontsize=8)
    if rows == 2:
        x = view.u[:, 0]
        smallest = np.flatnonzero(view.r <= view.r.min() * (1 + 1e-9))
        i = smallest[np.argmin(np.abs(x[smallest] - (lo1 + hi1) / 2))]
        kk = min(60, len(x) - 1)
        h = min(float(np.partition(np.abs(x - x[i]), kk)[kk]), 20 * float(view.r[i]))
        h = max(h, 3 * float(view.r[i]))
        h = min(h, (hi1 - lo1) / 8)
        c = float(np.clip(x[i], lo1 + h, hi1 - h))
        _draw_1d(axes[1], view, norm, lo1=c - h, hi1=c + h, disks=True)
        count = int(((x >= c - h) & (x <= c + h)).sum())
        axes[1].set_title(f"zoom on the smallest radii: [{c - h:.4g}, {c + h:.4g}], {count} points "
                          f"with their intervals", fontsize=8)
        axes[0].axvspan(c - h, c + h, color="red", alpha=0.15, lw=0)
        for spine in axes[1].spines.values():
            spine.set_edgecolor("red")
    _colour_bar(fig, list(axes), norm, view)
    fig.suptitle(wrapped, fontsize=9)
    return fig


def plot_points(path: Path, x: FloatArray, r: Optional[FloatArray], lo: FloatArray, hi: FloatArray,
                title: str, *, zoom: Optional[bool] = None, disks: Optional[bool] = None,
                dpi: float = 150) -> None:
    """Write points_figure(...) as a PNG at path."""
    fig = points_figure(x, r, lo, hi, title, zoom=zoom, disks=disks, dpi=dpi)
    fig.savefig(path, dpi=dpi)


# -- the analysis sheet ----------------------------------------------------------------------------


def _padded_range(values: FloatArray, at_least: tuple[float, float], pad: float = 0.08) -> tuple[float, float]:
    v = values[np.isfinite(values)]
    lo_, hi_ = at_least
    if len(v):
        lo_, hi_ = min(lo_, float(v.min())), max(hi_, float(v.max()))
    span = hi_ - lo_
    return lo_ - pad * span, hi_ + pad * span


def analysis_figure(x: FloatArray, r: FloatArray, lo: FloatArray, hi: FloatArray, report: Optional[DelaunayReport],
                    rule: str, lipschitz: float, scale: float, *, title: Optional[str] = None,
                    dpi: float = 110) -> Figure:
    """The Figure of `vpds analyze --plot`: the points x (n, d) in the box lo, hi (d,), coloured
    by r (n,), the periodogram (DC removed), radial mean power, anisotropy, and in 2D the
    Delaunay minimum-angle and edge-ratio histograms with the Table 1 bounds. Every range is set
    from the data."""
    from . import analysis
    lo = np.asarray(lo, dtype=float).reshape(-1)
    hi = np.asarray(hi, dtype=float).reshape(-1)
    x = _as_points(x, len(lo))
    n, dim = x.shape
    if title is None:
        title = f"{n} points in {dim}D, rule {rule}, scale t = {scale:g}"
    view = _View(x, r, lo, hi)
    norm = _norm(view.r_all, view.has_radii)
    if dim == 1:
        return _analysis_figure_1d(view, norm, title, dpi)
    fig = _new_figure(figsize=(16, 9.5), dpi=dpi, layout="constrained")
    axes = fig.subplots(2, 3)
    ax = axes[0, 0]
    lo2, hi2 = view.box
    ppu = 4.3 * 0.85 * dpi / float(hi2[0] - lo2[0])
    _draw_2d(ax, view, norm, lo2=lo2, hi2=hi2, disks=len(view.u) <= MAX_DISKS,
             pixels_per_unit=ppu, dpi=dpi)
    ax.set_title(view.selection if dim >= 3 else f"{n} points", fontsize=9 if dim < 3 else 8)
    _colour_bar(fig, [ax], norm, view)
    ax.set_title(_wrap(ax.get_title(), 62), fontsize=ax.title.get_fontsize())
    used = {(0, 0)}
    if dim >= 2 and n >= 2:
        sp = analysis.spectrum(x, lo, hi)
        k = sp.frequencies
        logp = np.log10(sp.power.T + 1e-3)
        off_dc = np.ones_like(logp, dtype=bool)
        off_dc[len(k) // 2, len(k) // 2] = False
        vmin, vmax = np.percentile(logp[off_dc], [1, 99.5])
        vmin, vmax = min(vmin, -1.0), max(vmax, 0.5)
        im = axes[0, 1].imshow(logp, origin="lower", cmap="gray", extent=[k[0], k[-1], k[0], k[-1]],
                               vmin=vmin, vmax=vmax, interpolation="nearest")
        fig.colorbar(im, ax=axes[0, 1], shrink=0.85, pad=0.01, label="log10 power")
        axes[0, 1].set_title("periodogram, DC removed" + ("\n(the points projected on x[0], x[1])"
                                                          if dim > 2 else ""))
        axes[0, 1].set_xlabel("f_x (cycles per box side)")
        axes[0, 1].set_ylabel("f_y (cycles per box side)")
        ax = axes[0, 2]
        ax.plot(sp.radii, sp.radial_mean, lw=1)
        ax.axhline(1, color="gray", lw=0.7, ls="--", label="white noise (1)")
        positive = sp.radial_mean[np.isfinite(sp.radial_mean) & (sp.radial_mean > 0)]
        if len(positive) and positive.max() > 20 * max(np.median(positive), 1e-12):
            ax.set_yscale("log")
        ax.set_title("radial mean power")
        ax.set_xlabel("|f| (cycles per box side)")
        ax.set_ylabel("mean power")
        ax.legend(fontsize=8)
        ax = axes[1, 0]
        ax.plot(sp.radii, sp.anisotropy_db, lw=1)
        ax.axhline(0, color="gray", lw=0.7, ls="--", label="isotropic (0 dB)")
        ax.set_ylim(*_padded_range(sp.anisotropy_db, (-5.0, 5.0)))
        ax.set_title("anisotropy")
        ax.set_xlabel("|f| (cycles per box side)")
        ax.set_ylabel("10 log10(variance / mean^2) (dB)")
        ax.legend(fontsize=8)
        used |= {(0, 1), (0, 2), (1, 0)}
    if report is not None and dim == 2:
        angles, ratios = analysis.delaunay_histograms(x, r, lo, hi)
        e_min, e_max, sin_min = analysis.table1_bounds(rule, lipschitz)
        bound = float(np.degrees(np.arcsin(sin_min)))
        ax = axes[1, 1]
        ax.hist(angles, bins=60, color="tab:blue")
        ax.axvline(bound, color="red", label=f"Table 1 bound {bound:.2f}")
        ax.set_title(f"Delaunay minimum angle ({len(angles)} triangles)")
        ax.set_xlabel("minimum angle of a triangle (degrees)")
        ax.set_ylabel("triangles")
        ax.legend(fontsize=8)
        ax = axes[1, 2]
        ax.hist(ratios, bins=80, color="tab:blue")
        for b in (e_min * scale, e_max * scale):
            ax.axvline(b, color="red")
        ax.plot([], [], color="red", label=f"Table 1 bounds [{e_min * scale:.3f}, {e_max * scale:.3f}]")
        ax.set_title("Delaunay edge length / r(x)")
        ax.set_xlabel("edge length / r(x) (both endpoints)")
        ax.set_ylabel("edges")
        ax.legend(fontsize=8)
        used |= {(1, 1), (1, 2)}
    for i in range(2):
        for j in range(3):
            if (i, j) not in used:
                axes[i, j].set_axis_off()
                why = ("the spectrum needs 2 or more points" if (i, j) in ((0, 1), (0, 2), (1, 0))
                       else "Delaunay histograms: 2D only" if dim != 2
                       else "Delaunay histograms: 3 or more points")
                axes[i, j].text(0.5, 0.5, why, ha="center", va="center", color="0.4",
                                transform=axes[i, j].transAxes)
    fig.suptitle(title, fontsize=11)
    return fig


def _analysis_figure_1d(view: _View, norm: Optional[Normalize], title: str, dpi: float) -> Figure:
    """1D: the strip, and the histogram of the gaps to the next point over r (no spectrum, no
    Delaunay: those are 2D)."""
    fig = _new_figure(figsize=(16, 4.2), dpi=dpi, layout="constrained")
    ax, hax = fig.subplots(1, 2, width_ratios=[2.6, 1])
    _draw_1d(ax, view, norm, lo1=float(view.lo[0]), hi1=float(view.hi[0]), disks=view.n <= 300)
    ax.set_title(f"{view.n} points" + (" (ticks) with their intervals [x - r, x + r] below"
                                       if view.n <= 300 else " (ticks)"), fontsize=9)
    _colour_bar(fig, [ax], norm, view)
    order = np.argsort(view.u[:, 0])
    xs, rs = view.u[order, 0], view.r[order]
    if len(xs) >= 2 and np.all(rs > 0):
        gaps = np.diff(xs) / rs[:-1]
        hax.hist(gaps, bins=min(60, max(10, len(gaps) // 5)), color="tab:blue")
        hax.set_title(f"gap to the next point / r ({len(gaps)} gaps)", fontsize=9)
        hax.set_xlabel("(x[i+1] - x[i]) / r(x[i])")
        hax.set_ylabel("gaps")
    else:
        hax.set_axis_off()
        hax.text(0.5, 0.5, "gaps: 2 or more points with radii", ha="center", va="center",
                 color="0.4", transform=hax.transAxes)
    fig.suptitle(title + " (the spectrum and Delaunay histograms are 2D)", fontsize=11)
    return fig


def plot_analysis(path: Path, x: FloatArray, r: FloatArray, lo: FloatArray, hi: FloatArray,
                  report: Optional[DelaunayReport], rule: str, lipschitz: float, scale: float, *,
                  title: Optional[str] = None, dpi: float = 110) -> None:
    """Write analysis_figure(...) as a PNG at path."""
    fig = analysis_figure(x, r, lo, hi, report, rule, lipschitz, scale, title=title, dpi=dpi)
    fig.savefig(path, dpi=dpi)


# -- a sampled mesh --------------------------------------------------------------------------------


def mesh_figure(vertices: FloatArray, faces: npt.NDArray[Any], points: FloatArray, title: str,
                *, radii: Optional[FloatArray] = None, dpi: float = 150) -> Figure:
    """The mesh as light shaded triangles and its samples as dots (coloured by r when radii are
    given and vary), in two views (front, and turned half a turn) so that no side is hidden;
    the axes keep the mesh's proportions."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # type: ignore[import-untyped]
    fig = _new_figure(figsize=(12, 5.5), dpi=dpi, layout="constrained")
    v = np.asarray(vertices, dtype=float)
    tris = v[np.asarray(faces, dtype=np.int64)]
    lo, hi = v.min(axis=0), v.max(axis=0)
    extent = np.maximum(hi - lo, 0.05 * max(float((hi - lo).max()), 1e-12))
    centre = (lo + hi) / 2
    normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    shade = 0.55 + 0.4 * np.abs((normal / np.where(length > 0, length, 1)) @ np.array([0.3, -0.5, 0.8]))
    for k, azim in enumerate((-60, 120)):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        ax.add_collection3d(Poly3DCollection(tris, facecolors=np.column_stack([shade] * 3 + [np.full(len(shade), 0.35)]),
                                             edgecolors=(0.5, 0.5, 0.5, 0.15), linewidths=0.2))
        varying = radii is not None and len(radii) and float(np.ptp(radii)) > 0
        dots = ax.scatter(points[:, 0], points[:, 1], points[:, 2], s=max(0.5, min(6.0, 6e4 / max(len(points), 1))),
                          c=radii if varying else "tab:red", cmap="viridis", depthshade=True, linewidths=0)
        if varying and k == 1:
            fig.colorbar(dots, ax=ax, shrink=0.6, label="r")
        for setter, c, e in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, extent):
            setter(c - e / 2, c + e / 2)
        ax.set_box_aspect(tuple(float(e) for e in extent), zoom=1.3)
        ax.view_init(elev=35, azim=azim)
        ax.set_axis_off()
    fig.suptitle(_wrap(title, 110))
    return fig


def plot_mesh(path: Path, vertices: FloatArray, faces: npt.NDArray[Any], points: FloatArray,
              title: str, *, radii: Optional[FloatArray] = None, dpi: float = 150) -> None:
    """Write mesh_figure(...) as a PNG at path."""
    mesh_figure(vertices, faces, points, title, radii=radii, dpi=dpi).savefig(path, dpi=dpi)
