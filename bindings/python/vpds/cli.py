"""The `vpds` command: `vpds sample ...` and `vpds analyze FILE` (also `python -m vpds ...`).

Every user mistake is one line on stderr naming the option, the value and why, with exit
status 2; Ctrl-C exits 130 after writing what was sampled (with -o). `sample` and `--help` need
numpy and cffi only: plotting imports matplotlib, `analyze` scipy, when asked for."""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np
import numpy.typing as npt

from ._args import room_for_samples
from ._core import MAX_DIM, RULES, PoissonDisk, VpdsError
from ._optional import MissingDependencyError, require
from ._typing import SizingFunction
from .cli_common import (UsageError, check_plot, check_unused_options, domain_from_file, exr_range_arg,
                         floats_arg, number_arg, periodic_arg, scales_arg, sizing_from_expression)
from .estimate import available_memory
from .files import check_output, write_points

# the progress bar advances by this many samples per call into the library
_STEP = 20_000


def _sizing(args: argparse.Namespace, lo: npt.NDArray[np.float64], hi: npt.NDArray[np.float64]
            ) -> tuple[Optional[SizingFunction], dict[str, Any], dict[str, npt.NDArray[np.float64]]]:
    """The sizing the options name (a SizingGrid is one too: callable on points), the
    parameters a file records for it, and its arrays."""
    meta: dict[str, Any] = {}
    if args.sizing is not None:
        meta.update(sizing=args.sizing, lipschitz=args.lipschitz)  # no L: the C message says so
        return sizing_from_expression(args.sizing, args.dim, at=(lo + hi) / 2), meta, {}
    if args.sizing_exr is not None:
        path = str(args.sizing_exr)
        if not Path(path).is_file():
            raise UsageError(f"--sizing-exr {path}: no such file")
        exr_range = exr_range_arg(args.exr_range)
        require("OpenEXR", "--sizing-exr", "OpenEXR")
        from .exr import sizing_grid_from_exr
        try:
            grid = sizing_grid_from_exr(path, lo, hi, args.channel, exr_range)
        except (ValueError, OSError) as exc:
            why = str(exc).removeprefix(f"{path}: ")
            channel = f" --channel {args.channel}" if args.channel is not None else ""
            raise UsageError(f"--sizing-exr {path}{channel}: {why}") from None
        if args.lipschitz is not None:
            grid.enforce_lipschitz(args.lipschitz)  # "smoothed for L" (lowers values only)
        meta.update(sizing_exr=path, lipschitz=grid.lipschitz)
        return grid, meta, {"sizing_grid": grid.values}  # the radii the run used, for analysis
    meta.update(radius=args.radius)
    return None, meta, {}


def _check_size(args: argparse.Namespace, engine: PoissonDisk, refine: list[float]) -> float:
    """The expected count; refuse a run that will not fit in memory unless --force."""
    if args.stream is not None:
        # the stream goes on to any count: refuse one whose points alone cannot fit
        room_for_samples(f"--stream {args.stream}", args.stream, engine.d)
        return float(args.stream)
    est = engine.estimate(min([1.0] + refine))
    avail = available_memory()
    if avail is not None and est.bytes > avail and not args.force:
        raise UsageError(f"this run needs {est} (estimated), more than the {avail / 2**20:,.0f} MiB "
                         "available: use a larger radius, or --force to run anyway")
    return est.samples


def _sample(args: argparse.Namespace, engine: PoissonDisk, expected: float, refine: list[float]) -> None:
    """Fill (then refine) or stream, with a progress bar over the expected count."""
    bar = None
    if not args.no_progress:
        try:
            from tqdm.auto import tqdm
            bar = tqdm(total=int(expected) if math.isfinite(expected) else None, unit=" samples",
                       desc="stream" if args.stream is not None else "sampling", leave=False)
        except ImportError:
            bar = None
    try:
        if args.stream is not None:
            for _ in zip(range(args.stream), engine.stream()):
                if bar is not None:
                    bar.update(1)
            return
        while engine.tiles is None and len(engine.random(_STEP)) == _STEP:
            if bar is not None:
                bar.update(_STEP)
        engine.fill_space()  # a tiled engine (--threads) fills the box at once
        for t in refine:
            engine.refine(t)
    finally:
        if bar is not None:
            bar.close()


def cmd_sample(args: argparse.Namespace) -> int:
    check_unused_options(args)
    if args.mesh is not None:
        from .cli_mesh import cmd_sample_mesh
        return cmd_sample_mesh(args)
    dim = args.dim
    if not 1 <= dim <= MAX_DIM:
        raise UsageError(f"--dim {dim}: must be in 1..{MAX_DIM}")
    lo = floats_arg(args.lo, dim, 0.0, "--lo")
    hi = floats_arg(args.hi, dim, 1.0, "--hi")
    bad = [k for k in range(dim) if not lo[k] < hi[k]]
    if bad:
        raise UsageError(f"--lo/--hi: axis {bad[0]} has lo = {lo[bad[0]]:g} >= hi = {hi[bad[0]]:g}")
    if args.output:
        check_output(Path(args.output), dim)
    if args.plot:
        check_plot(Path(args.plot))  # before sampling, not after
    refine = scales_arg(args.refine)
    if args.stream is not None and args.stream < 0:
        raise UsageError(f"--stream {args.stream}: must be >= 0")
    if args.stream is not None and refine:
        raise UsageError("--stream with --refine: the stream gives the points and their scales; "
                         "use one or the other")
    number_arg(args.lipschitz, "--lipschitz", strict=False)
    sizing, meta, arrays = _sizing(args, lo, hi)
    periodic = periodic_arg(args.periodic, dim)
    tiled = _threads_options(args)
    domain = _domain(args, dim, lo, hi)
    try:
        engine = PoissonDisk(dim, radius=args.radius, rng=args.seed, l_bounds=lo, u_bounds=hi,
                             sizing=sizing, lipschitz=None if args.sizing_exr else args.lipschitz,
                             rule=args.rule, inhibition=args.inhibition, coverage=args.coverage,
                             periodic=periodic, progress=False, domain=domain,
                             domain_threshold=args.domain_threshold, **tiled)
    except VpdsError:
        raise  # main prints the C message and exits with 2
    except (ValueError, ImportError, OSError) as exc:  # what the checks above did not foresee
        raise UsageError(str(exc)) from None
    stream = args.stream is not None
    meta.update(dim=dim, lo=lo.tolist(), hi=hi.tolist(), rule=args.rule, seed=engine.seed,
                inhibition=args.inhibition, coverage=args.coverage, periodic=periodic,
                domain=args.domain, domain_threshold=args.domain_threshold if args.domain else None,
                mode="stream" if stream else "refine" if refine else "run", refine=refine)
    if tiled:
        meta.update(threads=args.threads, tiles="auto")
    if stream:
        from . import STREAM_DOMAIN_TOLERANCE, STREAM_TOLERANCE
        meta["stream_tolerance"] = STREAM_DOMAIN_TOLERANCE if domain is not None else STREAM_TOLERANCE
    expected = _check_size(args, engine, refine)
    t0 = time.perf_counter()
    interrupted = False
    try:
        _sample(args, engine, expected, refine)
    except KeyboardInterrupt:
        interrupted = True
    seconds = time.perf_counter() - t0
    x, r, t, fixed = engine.points, engine.radii, engine.scales, engine.fixed
    what = (f"r = {args.sizing}" if args.sizing is not None
            else f"r from {args.sizing_exr}" if args.sizing_exr is not None
            else f"radius {engine.radius}")
    if args.sizing_exr and args.lipschitz is not None:
        what += f", smoothed for L = {args.lipschitz}"
    state = "interrupted" if interrupted else f"maximal: {bool(engine.stats['maximal'])}"
    print(f"{len(x)} samples in {dim}D ({what}, rule {args.rule}, seed {engine.seed}) in "
          f"{seconds:.3f} s; {state}")
    meta["complete"] = not interrupted
    if args.output:
        try:
            write_points(Path(args.output), x, r, t, fixed, meta, arrays)
        except OSError as exc:
            raise UsageError(f"-o {args.output}: cannot write it: {exc.strerror or exc}") from None
        print(f"wrote {args.output}" + (" (the samples so far: not maximal)" if interrupted else ""))
    if interrupted:
        print("vpds sample: interrupted", file=sys.stderr)
        return 130
    if args.plot:
        from .plots import plot_points
        try:
            plot_points(Path(args.plot), x, r, lo, hi, f"{len(x)} samples, {what}, {args.rule}")
        except OSError as exc:
            raise UsageError(f"--plot {args.plot}: cannot write it: {exc.strerror or exc}") from None
        print(f"wrote {args.plot}")
    return 0


def _domain(args: argparse.Namespace, dim: int, lo: npt.NDArray[np.float64],
            hi: npt.NDArray[np.float64]) -> Any:
    """--domain as the library's Domain, built here so that any refusal names --domain."""
    if args.domain is None:
        return None
    number_arg(args.domain_threshold, "--domain-threshold", minimum=-math.inf)
    from .domain import as_domain
    source = domain_from_file(Path(args.domain))
    try:
        return as_domain(source, dim, lo, hi, args.domain_threshold)
    except (ValueError, OSError, RuntimeError) as exc:  # VpdsValueError: the C message
        raise UsageError(f"--domain {args.domain}: {exc}") from None


def _threads_options(args: argparse.Namespace) -> dict[str, Any]:
    """PoissonDisk's workers and radius_max for --threads (the tiled process), checked."""
    if args.threads is None:
        return {}
    if not (args.threads == -1 or args.threads >= 1):
        raise UsageError(f"--threads {args.threads}: must be >= 1, or -1 for every core")
    for flag in ("refine", "stream", "domain"):
        if getattr(args, flag) is not None:
            raise UsageError(f"--{flag.replace('_', '-')} is not available with --threads (the "
                             "tiled process fills the box at once, without a domain)")
    if args.sizing is not None:
        if args.radius_max is None:
            raise UsageError("--sizing with --threads needs --radius-max (an upper bound of r: it "
                             "sets the margin the tiles share)")
        # the tiling hashes the sizing function (its token) with cloudpickle
        require("cloudpickle", "--sizing with --threads", "cloudpickle")
    number_arg(args.radius_max, "--radius-max")
    return {"workers": args.threads, "radius_max": args.radius_max}


def _versions() -> str:
    from . import __version__
    from ._vpds import ffi, lib
    return (f"vpds {__version__} (Python package), libvpds "
            f"{ffi.string(lib.vpds_version_string()).decode()} (C library)")


def build_parser() -> argparse.ArgumentParser:
    fmt = argparse.ArgumentDefaultsHelpFormatter
    parser = argparse.ArgumentParser(prog="vpds", formatter_class=fmt, description="Maximal "
                                     "Poisson-disk sampling with spatially varying radii (libvpds).")
    parser.add_argument("--version", action="version", version=_versions())
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("sample", help="sample a box and write the points", formatter_class=fmt)
    s.add_argument("--dim", type=int, default=2, help=f"dimension, 1 to {MAX_DIM}")
    s.add_argument("--lo", help="lower corner: one value for every axis, or comma-separated "
                   "(default: 0 on every axis)")
    s.add_argument("--hi", help="upper corner: one value for every axis, or comma-separated "
                   "(default: 1 on every axis)")
    size = s.add_mutually_exclusive_group()
    size.add_argument("--radius", type=float, default=0.05, help="constant radius")
    size.add_argument("--sizing", help="r(x) as a numpy expression in x, e.g. '0.001 + 0.3*x[0]'")
    size.add_argument("--sizing-exr", help="r from an OpenEXR image over the box (2D); with "
                      "--lipschitz L the image is first smoothed for L (values only lowered)")
    s.add_argument("--channel", help="with --sizing-exr: the EXR channel; R, G, B or A pick "
                   "one of an RGB(A) image (default: Y, R or L, or the only one)")
    s.add_argument("--exr-range", help="with --sizing-exr: r_min,r_max: pixel values in [0, 1] "
                   "map linearly onto this range (default: pixel values are radii)")
    s.add_argument("--lipschitz", type=float, help="L of r (required with --sizing)")
    s.add_argument("--rule", choices=sorted(RULES), default="smaller", help="Table 1's rule")
    s.add_argument("--inhibition", type=float, default=1.0, help="R_f factor")
    s.add_argument("--coverage", type=float, default=1.0, help="R_c factor")
    s.add_argument("--refine", help="comma-separated decreasing scales t1,t2,... after the fill")
    s.add_argument("--stream", type=int, help="take the first N samples of the continuous stream "
                   "instead (N >= 0: 0 gives an empty sampling); not with --refine")
    s.add_argument("--periodic", help="periodic axes: comma-separated indices, or 'all'")
    s.add_argument("--domain", help="sample only inside: an image mask (.png, .exr, ...), a .npy "
                   "mask or (m, 2) polygon, or a .wkt polygon; maximal up to its boundary")
    s.add_argument("--domain-threshold", type=float, default=0.5,
                   help="image or float mask: inside where value >= this")
    s.add_argument("--seed", type=int, default=0, help="the C seed (same seed, same points)")
    s.add_argument("-o", "--output", help="write the samples: .npy, .npz, .csv or .ply")
    s.add_argument("--plot", help="write a picture of the samples: .png, .pdf, .svg, ... "
                   "(the formats matplotlib writes; needs matplotlib)")
    s.add_argument("--threads", type=int, help="sample the box as tiles on N threads (-1: every "
                   "core): the tiled process (tiles from the box and radii, the same points for "
                   "any N), not the serial one; without a domain, --refine or --stream")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.add_argument("--force", action="store_true", help="run even when the estimated memory "
                   "exceeds what is available")
    s.set_defaults(func=cmd_sample)
    from .cli_mesh import add_mesh_arguments
    add_mesh_arguments(s)
    from .cli_tiles import add_tile_arguments  # the tiled form: vpds sample --tiles ... -o X.zarr
    add_tile_arguments(s, cmd_sample)
    from .cli_analyze import add_analyze_parser
    add_analyze_parser(sub, fmt)
    return parser


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (UsageError, MissingDependencyError, VpdsError, NotImplementedError, MemoryError) as exc:
        # a MemoryError here is a refusal before the work (its message gives the figure)
        print(f"vpds {args.command}: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"vpds {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
