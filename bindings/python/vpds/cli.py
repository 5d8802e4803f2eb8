"""The `vpds` command: `vpds sample ...` (also `python -m vpds sample ...`)."""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

from ._core import RULES, PoissonDisk, VpdsError

# names a --sizing expression may use, besides x (the coordinates, x[k] the k-th, shape (d, m))
_EXPR_NAMES = {name: getattr(np, name) for name in (
    "sin", "cos", "tan", "exp", "log", "sqrt", "abs", "minimum", "maximum", "clip", "where",
    "hypot", "arctan2", "pi", "e", "linalg")}
_EXPR_NAMES["np"] = np


def sizing_from_expression(expr: str, dim: int) -> Callable[[np.ndarray], np.ndarray]:
    """r(x) from a numpy expression in x, where x[k] is the k-th coordinate of all points."""
    code = compile(expr, "<--sizing>", "eval")

    def sizing(points: np.ndarray) -> np.ndarray:
        value = eval(code, {"__builtins__": {}}, dict(_EXPR_NAMES, x=points.T))  # noqa: S307
        return np.broadcast_to(np.asarray(value, dtype=np.float64), (len(points),)).copy()
    probe = np.full((1, dim), 0.5)
    try:
        sizing(probe)
    except Exception as exc:  # noqa: BLE001 - reported to the user as a usage error
        raise SystemExit(f"vpds sample: --sizing {expr!r} does not evaluate: {exc}") from None
    return sizing


def _floats(text: Optional[str], dim: int, default: float, name: str) -> np.ndarray:
    if text is None:
        return np.full(dim, default)
    values = [float(v) for v in text.split(",")]
    if len(values) == 1:
        values = values * dim
    if len(values) != dim:
        raise SystemExit(f"vpds sample: {name} has {len(values)} values for --dim {dim}")
    return np.array(values)


def write_points(path: Path, x: np.ndarray, r: np.ndarray, t: np.ndarray, fixed: np.ndarray) -> None:
    """.npy: the points (n, d); .npz: points, radii, scales, fixed; .csv: x0.., r, t, fixed;
    .ply: vertices with x, y, z (zero-padded below 3D) and radius, t as double properties."""
    suffix = path.suffix.lower()
    n, d = x.shape
    if suffix == ".npy":
        np.save(path, x)
    elif suffix == ".npz":
        np.savez(path, points=x, radii=r, scales=t, fixed=fixed)
    elif suffix == ".csv":
        header = ",".join([f"x{k}" for k in range(d)] + ["r", "t", "fixed"])
        table = np.column_stack([x, r, t, fixed.astype(float)])
        np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.17g")
    elif suffix == ".ply":
        if d > 3:
            raise SystemExit(f"vpds sample: .ply holds up to 3 coordinates, the points have {d}")
        xyz = np.zeros((n, 3))
        xyz[:, :d] = x
        with open(path, "w") as f:
            f.write("ply\nformat ascii 1.0\ncomment libvpds sample\n")
            f.write(f"element vertex {n}\nproperty double x\nproperty double y\nproperty double z\n")
            f.write("property double radius\nproperty double t\nend_header\n")
            np.savetxt(f, np.column_stack([xyz, r, t]), fmt="%.17g")
    else:
        raise SystemExit(f"vpds sample: -o {path}: use .npy, .npz, .csv or .ply")


def plot_points(path: Path, x: np.ndarray, r: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                title: str) -> None:
    """Points with their disks for small n, points alone for large n (the first two axes)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
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


def cmd_sample(args: argparse.Namespace) -> int:
    dim = args.dim
    lo = _floats(args.lo, dim, 0.0, "--lo")
    hi = _floats(args.hi, dim, 1.0, "--hi")
    if args.sizing_exr:
        raise SystemExit("vpds sample: --sizing-exr is not supported by this version")
    sizing = sizing_from_expression(args.sizing, dim) if args.sizing else None
    periodic = None
    if args.periodic:
        axes = {int(a) for a in args.periodic.split(",")} if args.periodic != "all" else set(range(dim))
        periodic = [k in axes for k in range(dim)]
    engine = PoissonDisk(dim, radius=args.radius, rng=args.seed, l_bounds=lo, u_bounds=hi,
                         sizing=sizing, lipschitz=args.lipschitz, rule=args.rule,
                         inhibition=args.inhibition, coverage=args.coverage, periodic=periodic,
                         progress=not args.no_progress)
    t0 = time.perf_counter()
    if args.stream:
        for _ in zip(range(args.stream), engine.stream()):
            pass
    else:
        engine.fill_space()
        for t in [float(v) for v in args.refine.split(",")] if args.refine else []:
            engine.refine(t)
    seconds = time.perf_counter() - t0
    x, r, t, fixed = engine.points, engine.radii, engine.scales, engine.fixed
    what = f"r = {args.sizing}" if args.sizing else f"radius {engine.radius}"
    print(f"{len(x)} samples in {dim}D ({what}, rule {args.rule}, seed {engine.seed}) in "
          f"{seconds:.3f} s; maximal: {bool(engine.stats['maximal'])}")
    if args.output:
        write_points(Path(args.output), x, r, t, fixed)
        print(f"wrote {args.output}")
    if args.plot:
        plot_points(Path(args.plot), x, r, lo, hi, f"{len(x)} samples, {what}, {args.rule}")
        print(f"wrote {args.plot}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="vpds", description="Maximal Poisson-disk sampling with "
                                     "spatially varying radii (libvpds).")
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("sample", help="sample a box and write the points")
    s.add_argument("--dim", type=int, default=2)
    s.add_argument("--lo", help="lower corner: one value for every axis, or comma-separated")
    s.add_argument("--hi", help="upper corner: one value for every axis, or comma-separated")
    size = s.add_mutually_exclusive_group()
    size.add_argument("--radius", type=float, default=0.05, help="constant radius (default 0.05)")
    size.add_argument("--sizing", help="r(x) as a numpy expression in x, e.g. '0.001 + 0.3*x[0]'")
    size.add_argument("--sizing-exr", help="(not supported by this version)")
    s.add_argument("--lipschitz", type=float, help="L of r (required with --sizing)")
    s.add_argument("--rule", choices=sorted(RULES), default="smaller")
    s.add_argument("--inhibition", type=float, default=1.0)
    s.add_argument("--coverage", type=float, default=1.0)
    s.add_argument("--refine", help="comma-separated decreasing scales t1,t2,... after the fill")
    s.add_argument("--stream", type=int, help="take N samples of the continuous stream instead")
    s.add_argument("--periodic", help="periodic axes: comma-separated indices, or 'all'")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("-o", "--output", help="write the samples: .npy, .npz, .csv or .ply")
    s.add_argument("--plot", help="write a PNG of the samples (with their disks for small n)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_sample)
    return parser


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except VpdsError as exc:
        print(f"vpds {args.command}: {exc}", file=sys.stderr)
        return 2
    except NotImplementedError as exc:
        print(f"vpds {args.command}: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"vpds {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
