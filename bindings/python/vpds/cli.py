"""The `vpds` command: `vpds sample ...` (also `python -m vpds sample ...`)."""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

from ._core import RULES, PoissonDisk, VpdsError
from ._optional import MissingDependencyError, require

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


def domain_from_file(path: Path):
    """--domain FILE: an image (.png, .exr, ...: a mask over the box), a .npy array (a mask
    with one axis per dimension, or (m, 2) polygon vertices), or a .wkt polygon (shapely)."""
    if not path.exists():
        raise SystemExit(f"vpds sample: --domain {path}: no such file")
    if path.suffix.lower() == ".npy":
        return np.load(path)
    if path.suffix.lower() == ".wkt":
        try:
            from shapely import wkt
        except ImportError:
            raise SystemExit("vpds sample: --domain .wkt needs shapely (pip install shapely)") from None
        return wkt.loads(path.read_text())
    return str(path)


def cmd_sample(args: argparse.Namespace) -> int:
    dim = args.dim
    lo = _floats(args.lo, dim, 0.0, "--lo")
    hi = _floats(args.hi, dim, 1.0, "--hi")
    sizing = sizing_from_expression(args.sizing, dim) if args.sizing else None
    grid_lipschitz = None
    if args.sizing_exr:
        from .exr import sizing_grid_from_exr
        exr_range = [float(v) for v in args.exr_range.split(",")] if args.exr_range else None
        try:
            sizing = sizing_grid_from_exr(args.sizing_exr, lo, hi, args.channel, exr_range)
        except (ValueError, ImportError, OSError) as exc:
            raise SystemExit(f"vpds sample: --sizing-exr {args.sizing_exr}: {exc}") from None
        if args.lipschitz is not None:
            sizing.enforce_lipschitz(args.lipschitz)  # "smoothed for L" (lowers values only)
            grid_lipschitz, args.lipschitz = args.lipschitz, None
    periodic = None
    if args.periodic:
        axes = {int(a) for a in args.periodic.split(",")} if args.periodic != "all" else set(range(dim))
        periodic = [k in axes for k in range(dim)]
    domain = None
    if args.domain:
        domain = domain_from_file(Path(args.domain))
    try:
        engine = PoissonDisk(dim, radius=args.radius, rng=args.seed, l_bounds=lo, u_bounds=hi,
                             sizing=sizing, lipschitz=args.lipschitz, rule=args.rule,
                             inhibition=args.inhibition, coverage=args.coverage, periodic=periodic,
                             progress=not args.no_progress, domain=domain,
                             domain_threshold=args.domain_threshold)
    except VpdsError:
        raise  # main prints the C message and exits with 2
    except (ValueError, ImportError, OSError) as exc:  # a domain file or polygon refused
        print(f"vpds sample: {exc}", file=sys.stderr)
        return 2
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
    what = (f"r = {args.sizing}" if args.sizing else f"r from {args.sizing_exr}" if args.sizing_exr
            else f"radius {engine.radius}")
    if grid_lipschitz is not None:
        what += f", smoothed for L = {grid_lipschitz}"
    print(f"{len(x)} samples in {dim}D ({what}, rule {args.rule}, seed {engine.seed}) in "
          f"{seconds:.3f} s; maximal: {bool(engine.stats['maximal'])}")
    if args.output:
        write_points(Path(args.output), x, r, t, fixed)
        print(f"wrote {args.output}")
    if args.plot:
        from .plots import plot_points
        plot_points(Path(args.plot), x, r, lo, hi, f"{len(x)} samples, {what}, {args.rule}")
        print(f"wrote {args.plot}")
    return 0


def read_points(path: Path):
    """(points, radii or None, scales or None) from .npz, .npy, .csv or .ply as `sample` writes."""
    suffix = path.suffix.lower()
    if suffix == ".npz":
        z = np.load(path)
        return z["points"], z["radii"], z["scales"]
    if suffix == ".npy":
        return np.load(path), None, None
    if suffix == ".csv":
        header = path.read_text().splitlines()[0].split(",")
        table = np.atleast_2d(np.loadtxt(path, delimiter=",", skiprows=1))
        dims = [i for i, h in enumerate(header) if h in ("x", "y", "z") or (h[:1] == "x" and h[1:].isdigit())]
        col = {h: i for i, h in enumerate(header)}
        return table[:, dims], table[:, col["r"]] if "r" in col else None, table[:, col["t"]] if "t" in col else None
    if suffix == ".ply":
        lines = path.read_text().splitlines()
        body = np.atleast_2d(np.loadtxt(lines[lines.index("end_header") + 1:]))
        keep = [k for k in range(3) if np.any(body[:, k] != 0)] or [0]
        return body[:, : max(keep) + 1], body[:, 3], body[:, 4]
    raise SystemExit(f"vpds analyze: {path}: use .npz, .npy, .csv or .ply")


def cmd_analyze(args: argparse.Namespace) -> int:
    analysis = require("vpds.analysis", "vpds analyze", "scipy")
    x, r, t = read_points(Path(args.file))
    n, dim = x.shape
    lo = _floats(args.lo, dim, 0.0, "--lo")
    hi = _floats(args.hi, dim, 1.0, "--hi")
    scale = args.scale if args.scale is not None else (
        float(t[np.isfinite(t)].min()) if t is not None and np.isfinite(t).any() else 1.0)
    if args.sizing:
        fn = sizing_from_expression(args.sizing, dim)
        if args.lipschitz is None:
            raise SystemExit("vpds analyze: --sizing needs --lipschitz")
        sizing = analysis.Sizing(fn, args.lipschitz)
    elif args.radius is not None or (r is not None and np.all(r == r[0])):
        sizing = analysis.sizing_named("const", args.radius if args.radius is not None else float(r[0]))
    else:
        sizing = None
    if r is None:
        if sizing is None:
            raise SystemExit("vpds analyze: the file has no radii: give --radius or --sizing")
        r = sizing.fn(x)
    lipschitz = sizing.lipschitz if sizing is not None else 0.0
    failed = []
    print(f"{n} points in {dim}D, rule {args.rule}, scale t = {scale:g}")
    bad = analysis.empty_disk_violations(x, r, args.rule, scale, lipschitz)
    print(f"empty disk (Eq. 10, insertion order): {bad} conflicting pairs -> {'OK' if bad == 0 else 'FAIL'}")
    if bad:
        failed.append("empty disk")
    if sizing is None:
        print("maximality: not checked (radii vary: give --sizing and --lipschitz)")
    else:
        rep = analysis.check_maximal(x, r, args.rule, scale, sizing, lo, hi)
        ok = rep.gaps == 0 and rep.probes_max_rel <= 1e-9
        print(f"maximality (branch-and-bound, {rep.boxes} boxes; probes): {rep.gaps} uncovered "
              f"points found -> {'OK' if ok else 'FAIL'}")
        if not ok:
            failed.append("maximality")
    report = None
    if dim == 2 and n >= 3:
        report = analysis.check_delaunay(x, r, args.rule, scale * lipschitz, lo, hi)
        emin, emax = report.edge_min_bound * scale, report.edge_max_bound * scale
        ok = (report.min_angle_deg >= report.angle_bound_deg and report.edge_min_ratio >= emin * (1 - 1e-12)
              and report.edge_max_ratio <= emax * (1 + 1e-12)) if sizing is not None else True
        print(f"Delaunay ({report.triangles} interior triangles): min angle {report.min_angle_deg:.2f} deg "
              f"(Table 1: >= {report.angle_bound_deg:.2f}), edge / r(x) in [{report.edge_min_ratio:.3f}, "
              f"{report.edge_max_ratio:.3f}] (Table 1: [{emin:.3f}, {emax:.3f}]) -> {'OK' if ok else 'FAIL'}")
        if not ok:
            failed.append("Table 1 bounds")
    if args.plot:
        from .plots import plot_analysis
        plot_analysis(Path(args.plot), x, r, lo, hi, report, args.rule, scale * lipschitz, scale)
        print(f"wrote {args.plot}")
    print("all guarantees hold" if not failed else "FAILED: " + ", ".join(failed))
    return 1 if failed else 0


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
    size.add_argument("--sizing-exr", help="r from an OpenEXR image over the box (2D); with "
                      "--lipschitz L the image is first smoothed for L (values only lowered)")
    s.add_argument("--channel", help="EXR channel (default Y, R or L, or the only one)")
    s.add_argument("--exr-range", help="r_min,r_max: pixel values in [0, 1] map linearly onto "
                   "this range (default: pixel values are radii)")
    s.add_argument("--lipschitz", type=float, help="L of r (required with --sizing)")
    s.add_argument("--rule", choices=sorted(RULES), default="smaller")
    s.add_argument("--inhibition", type=float, default=1.0)
    s.add_argument("--coverage", type=float, default=1.0)
    s.add_argument("--refine", help="comma-separated decreasing scales t1,t2,... after the fill")
    s.add_argument("--stream", type=int, help="take N samples of the continuous stream instead")
    s.add_argument("--periodic", help="periodic axes: comma-separated indices, or 'all'")
    s.add_argument("--domain", help="sample only inside: an image mask (.png, .exr, ...), a .npy "
                   "mask or (m, 2) polygon, or a .wkt polygon; maximal up to its boundary")
    s.add_argument("--domain-threshold", type=float, default=0.5,
                   help="image or float mask: inside where value >= this (default 0.5)")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("-o", "--output", help="write the samples: .npy, .npz, .csv or .ply")
    s.add_argument("--plot", help="write a PNG of the samples (with their disks for small n)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_sample)
    from .cli_tiles import add_tile_arguments  # the tiled form: vpds sample --tiles ... -o X.zarr
    add_tile_arguments(s, cmd_sample)
    a = sub.add_parser("analyze", help="check a sampling's guarantees and plot its spectrum")
    a.add_argument("file", help=".npz, .npy, .csv or .ply (as `vpds sample -o` writes)")
    a.add_argument("--rule", choices=sorted(RULES), default="smaller")
    a.add_argument("--radius", type=float, help="constant radius (when the file has none)")
    a.add_argument("--sizing", help="r(x) as a numpy expression in x (needed for maximality "
                   "when radii vary)")
    a.add_argument("--lipschitz", type=float)
    a.add_argument("--lo")
    a.add_argument("--hi")
    a.add_argument("--scale", type=float, help="the scale t to check at (default: the file's "
                   "smallest finite t, else 1)")
    a.add_argument("--plot", help="write the analysis PNG")
    a.set_defaults(func=cmd_analyze)
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
    except MissingDependencyError as exc:
        print(f"vpds {args.command}: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"vpds {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
