"""`vpds sample --tiles ...`: a tiled run on Dask into a Zarr store, with a progress bar over
tiles (vpds.distributed). The other options of `vpds sample` keep their meaning."""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Optional

import numpy as np

from ._optional import require
from .cli_common import UsageError, check_directory, check_unused_options, exr_range_arg, number_arg, periodic_arg

# more tiles than this is a mistake (each tile is a group in the store and a task on Dask)
MAX_TILES = 10**9

if TYPE_CHECKING:  # for the annotation: vpds.tiling loads the C extension
    from .tiling import SizingArg


def add_tile_arguments(s: argparse.ArgumentParser, plain: Callable[[argparse.Namespace], int]) -> None:
    """The tiled form's options on the `sample` parser; runs `plain` when --tiles is absent."""
    g = s.add_argument_group("tiled sampling (vpds.distributed, Dask, Zarr)")
    g.add_argument("--tiles", help="tiles per axis: one count for every axis, or comma-separated, "
                   "or 'auto' (tiles of about 200,000 samples, from the box and the radii); "
                   "-o must then name a .zarr store (resumed if it holds the same run)")
    g.add_argument("--workers", type=int, help="LocalCluster worker processes (default: the cores)")
    g.add_argument("--address", help="a Dask scheduler's address instead of a LocalCluster")
    g.add_argument("--radius-max", type=float, help="upper bound of r (required with --sizing "
                   "and --tiles: it sets the margin)")
    g.add_argument("--overwrite", action="store_true", help="replace the store instead of resuming")
    s.set_defaults(func=lambda args: cmd_sample_tiles(args) if args.tiles else plain(args))


def _tile_counts(text: str, dim: int) -> Optional[list[int]]:
    """--tiles: 'auto' (None), or one count for every axis, or `dim` counts, each >= 1."""
    if text == "auto":
        return None
    try:
        counts = [int(v) for v in text.split(",")]
    except ValueError:
        raise UsageError(f"--tiles {text!r}: expected tile counts separated by commas, "
                         "or auto") from None
    if len(counts) == 1:
        counts = counts * dim
    if len(counts) != dim:
        raise UsageError(f"--tiles has {len(counts)} counts for --dim {dim}")
    bad = [c for c in counts if c < 1]
    if bad:
        raise UsageError(f"--tiles {text!r}: a tile count must be >= 1 (got {bad[0]})")
    total = math.prod(counts)
    if total > MAX_TILES:
        raise UsageError(f"--tiles {text!r}: {total:.3g} tiles in all, more than {MAX_TILES:.0e}; "
                         "use fewer (or auto)")
    return counts


def cmd_sample_tiles(args: argparse.Namespace) -> int:
    from .cli_common import floats_arg as _floats, sizing_from_expression
    check_unused_options(args)
    dim = args.dim
    if args.mesh is not None:
        raise UsageError("--tiles is not available with --mesh")
    if not args.output or not args.output.rstrip("/").endswith(".zarr"):
        raise UsageError("--tiles writes a Zarr store: give -o NAME.zarr")
    check_directory(Path(args.output.rstrip("/")), "-o")
    for flag in ("refine", "stream", "plot", "threads"):
        if getattr(args, flag) is not None:
            raise UsageError(f"--{flag} is not available with --tiles (--tiles runs the tiles on "
                             "Dask, --workers processes; --threads runs them in this process)")
    counts = _tile_counts(args.tiles, dim)
    lo = _floats(args.lo, dim, 0.0, "--lo")
    hi = _floats(args.hi, dim, 1.0, "--hi")
    number_arg(args.lipschitz, "--lipschitz", strict=False)
    number_arg(args.radius_max, "--radius-max")
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers {args.workers}: must be >= 1")
    sizing: SizingArg = None
    if args.sizing is not None:
        if args.radius_max is None:
            raise UsageError("--sizing with --tiles needs --radius-max (an upper bound "
                             "of r: it sets the margin the tiles share)")
        sizing = sizing_from_expression(args.sizing, dim, at=(lo + hi) / 2)
    elif args.sizing_exr is not None:
        if args.lipschitz is not None:
            raise UsageError("--lipschitz smooths an image in memory; with --tiles the "
                             "image is read per tile: smooth it first, or run without --tiles")
        exr_range = exr_range_arg(args.exr_range)
        if str(args.sizing_exr).lower().endswith(".exr"):
            require("OpenEXR", "--sizing-exr", "OpenEXR")
    periodic = periodic_arg(args.periodic, dim)
    # what the tiled run imports, asked for before any work: one line naming the pip install
    install = '"dask[distributed]" zarr'
    require("zarr", "--tiles", install)
    require("distributed", "--tiles", install)
    if args.sizing is not None:  # the tiling hashes the sizing function with cloudpickle
        require("cloudpickle", "--sizing with --tiles", "cloudpickle")
    from . import distributed
    if args.sizing_exr is not None:
        try:
            sizing = distributed.GridSource(args.sizing_exr, lo, hi, channel=args.channel,
                                            radius_range=exr_range)
        except (ValueError, OSError) as exc:
            raise UsageError(f"--sizing-exr {args.sizing_exr}: {exc}") from None
    t0 = time.perf_counter()
    try:
        store = distributed.sample(args.output, dim, counts, l_bounds=lo, u_bounds=hi,
                                   radius=args.radius, sizing=sizing, lipschitz=args.lipschitz,
                                   radius_max=args.radius_max, rule=args.rule,
                                   inhibition=args.inhibition, coverage=args.coverage,
                                   periodic=periodic, rng=args.seed, address=args.address,
                                   n_workers=args.workers, progress=not args.no_progress,
                                   overwrite=args.overwrite)
    except ValueError as exc:  # the C library's messages, and a store of another run
        print(f"vpds sample: {exc}", file=sys.stderr)
        return 2
    seconds = time.perf_counter() - t0
    total = store.total
    import zarr  # what `vpds analyze` needs beyond the tiling's own record (vpds.files)
    zarr.open_group(args.output, mode="r+").attrs["vpds_cli"] = {
        "sizing": args.sizing, "sizing_exr": args.sizing_exr, "rule": args.rule,
        "inhibition": args.inhibition, "coverage": args.coverage, "mode": "tiles",
        "complete": True, "lipschitz": args.lipschitz, "seed": args.seed}
    counts = list(store.params["tiles"])
    print(f"{total} samples in {dim}D over {int(np.prod(counts))} tiles {tuple(counts)} "
          f"(rule {args.rule}, seed {args.seed}) in {seconds:.3f} s; all tiles complete")
    print(f"wrote {args.output} (read it back with vpds.distributed.TileStore)")
    return 0
