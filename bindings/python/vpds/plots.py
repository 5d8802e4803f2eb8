"""Pictures of a sampling: the points (`vpds sample --plot`) and the analysis sheet
(`vpds analyze --plot`). matplotlib is imported here only, when a picture is asked for."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ._optional import require


def _pyplot():
    """matplotlib's pyplot on the Agg backend, or MissingDependencyError naming the install."""
    matplotlib = require("matplotlib", "plotting", "matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_points(path: Path, x: np.ndarray, r: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                title: str) -> None:
    """Points with their disks for small n, points alone for large n (the first two axes)."""
    plt = _pyplot()
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    fig, ax = plt.subplots(figsize=(7, 7 * (hi[1] - lo[1]) / (hi[0] - lo[0]) if len(lo) > 1 else 2))
    y = x[:, 1] if x.shape[1] > 1 else np.zeros(len(x))
    if len(x) <= 5000:
        disks = PatchCollection([Circle((a, b), rr) for a, b, rr in zip(x[:, 0], y, r)],
                                facecolor="tab:blue", alpha=0.15, edgecolor="tab:blue", lw=0.3)
        ax.add_collection(disks)
        ax.plot(x[:, 0], y, ".", ms=2, color="black")
    else:
        ax.plot(x[:, 0], y, ",", color="black")
    ax.set_xlim(lo[0], hi[0])
    if x.shape[1] > 1:
        ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)

def plot_analysis(path: Path, x: np.ndarray, r: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                  report, rule: str, lipschitz: float, scale: float) -> None:
    """One PNG: the points, the periodogram (DC removed), radial mean power, anisotropy, and in
    2D the Delaunay minimum-angle and edge-ratio histograms with the Table 1 bounds."""
    from . import analysis
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(15, 9.5))
    ax = axes[0, 0]
    ax.plot(x[:, 0], x[:, 1] if x.shape[1] > 1 else np.zeros(len(x)), ",", color="black")
    ax.set_aspect("equal")
    ax.set_title(f"{len(x)} points")
    if x.shape[1] >= 2:
        sp = analysis.spectrum(x, lo, hi)
        k = sp.frequencies
        axes[0, 1].imshow(np.log10(sp.power.T + 1e-3), origin="lower", cmap="gray",
                          extent=[k[0], k[-1], k[0], k[-1]], vmin=-1.5, vmax=1)
        axes[0, 1].set_title("periodogram, DC removed (log10)")
        axes[0, 2].plot(sp.radii, sp.radial_mean, lw=1)
        axes[0, 2].axhline(1, color="gray", lw=0.5)
        axes[0, 2].set_title("radial mean power")
        axes[0, 2].set_xlabel("|f|")
        axes[1, 0].plot(sp.radii, sp.anisotropy_db, lw=1)
        axes[1, 0].set_ylim(-20, 10)
        axes[1, 0].set_title("anisotropy (dB)")
        axes[1, 0].set_xlabel("|f|")
    if report is not None and x.shape[1] == 2:
        angles, ratios = analysis.delaunay_histograms(x, r, lo, hi)
        e_min, e_max, sin_min = analysis.table1_bounds(rule, lipschitz)
        axes[1, 1].hist(angles, bins=60, color="tab:blue")
        axes[1, 1].axvline(np.degrees(np.arcsin(sin_min)), color="red", label="Table 1 bound")
        axes[1, 1].set_title("Delaunay minimum angle (degrees)")
        axes[1, 1].legend()
        axes[1, 2].hist(ratios, bins=80, color="tab:blue")
        for b in (e_min * scale, e_max * scale):
            axes[1, 2].axvline(b, color="red")
        axes[1, 2].set_title("Delaunay edge length / r(x), Table 1 bounds")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)