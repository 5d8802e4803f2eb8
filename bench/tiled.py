"""Tiled sampling on Dask (vpds.distributed): samples per second for 1 and 2 workers, how it
scales with the number of tiles, and the peak memory of a worker; beside one plain run of the
same box in this process (vpds.PoissonDisk) as the reference.

    python bench/tiled.py            # about 2 minutes on a 2-core machine
    python bench/tiled.py --quick    # a few seconds per row
    python bench/tiled.py --total 10000000   # the table at 10^7 samples (about 10 minutes)
    python bench/tiled.py --largest 100000000 --tiles 64   # one big run to disk

Wall clock, one run per row; the cluster is started before the clock (its start-up, about
2 s, is reported apart). Peak memory per worker is the largest high-water mark of the worker
processes (VmHWM; fresh processes for every row)."""
from __future__ import annotations

import argparse
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def peak_rss_mb() -> float:
    """This process's peak resident memory (VmHWM: unlike ru_maxrss, it does not inherit the
    parent's peak across the fork and exec that start a worker)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def dir_mb(path: Path) -> float:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file()) / 2**20


def run(client, path: Path, side: float, tiles, radius: float) -> tuple[int, float, tuple[int, ...]]:
    """One Dask run (tiles: per axis, or None for the default layout): points, seconds, tiles."""
    from vpds import distributed
    t0 = time.perf_counter()
    store = distributed.sample(path, 2, tiles, u_bounds=(side, side), radius=radius,
                               rng=1, client=client, progress=False, overwrite=True)
    seconds = time.perf_counter() - t0
    return store.total, seconds, tuple(store.params["tiles"])


def warm_up() -> None:
    """A worker's imports (numpy, the C extension, zarr), done before the clock, and a timer
    around Tiling.run_tile (the tile's own run: vpds_tile_create, vpds_run and the copies out),
    summed into vpds.tiling._bench_seconds for tile_seconds to collect."""
    import time as _time
    import numcodecs  # noqa: F401
    import zarr  # noqa: F401
    import vpds.distributed  # noqa: F401
    from vpds import tiling
    tiling._bench_seconds = 0.0
    if getattr(tiling.Tiling.run_tile, "_timed", False):
        return
    plain = tiling.Tiling.run_tile

    def timed(self, *args, **kwargs):
        t0 = _time.perf_counter()
        try:
            return plain(self, *args, **kwargs)
        finally:
            tiling._bench_seconds += _time.perf_counter() - t0

    timed._timed = True
    tiling.Tiling.run_tile = timed


def tile_seconds() -> float:
    """This worker's seconds inside Tiling.run_tile since warm_up."""
    from vpds import tiling
    return float(getattr(tiling, "_bench_seconds", 0.0))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--largest", type=int, help="one run of about this many points (2 workers)")
    ap.add_argument("--tiles", type=int, default=32, help="tiles per axis for --largest")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--total", type=int, help="samples of the table's runs (default 2e6; --quick 3e5)")
    ap.add_argument("--dir", help="where the stores go (default: a temporary directory)")
    args = ap.parse_args()
    from distributed import Client, LocalCluster
    import vpds

    radius = 0.01
    density = 1 / (1.66 * radius ** 2)  # samples per unit area of a maximal 2D set (measured)
    base = Path(args.dir or tempfile.mkdtemp(prefix="vpds-bench-"))
    base.mkdir(parents=True, exist_ok=True)
    print("tiled sampling (vpds.distributed), 2D uniform radius 0.01, LocalCluster of worker "
          "processes; this machine is shared, so figures are indicative", flush=True)

    if args.largest:
        side = float(np.sqrt(args.largest / density))
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=":0")
        client = Client(cluster)
        start = time.perf_counter() - t0
        n, s, _ = run(client, base / "largest.zarr", side, args.tiles, radius)
        rss = max(client.run(peak_rss_mb).values())
        print(f"largest run: {n:,} points, box {side:.0f} x {side:.0f}, {args.tiles}^2 tiles, "
              f"{args.workers} workers: {s:.1f} s ({n / s:,.0f} samples/s; cluster start {start:.1f} s), "
              f"peak memory per worker {rss:.0f} MB, store {dir_mb(base / 'largest.zarr'):.0f} MB on disk")
        client.close()
        cluster.close()
        if not args.dir:
            shutil.rmtree(base)
        return 0

    total = args.total or (300_000 if args.quick else 2_000_000)
    side = float(np.sqrt(total / density))
    # the reference: one run over the whole box in this process
    t0 = time.perf_counter()
    x = vpds.PoissonDisk(2, radius=radius, u_bounds=[side, side], rng=1, progress=False).fill_space()
    one = time.perf_counter() - t0
    rate_one = len(x) / one
    print(f"\none run, whole box {side:.1f}^2 (no tiles, no Dask): {len(x):,} samples in {one:.2f} s = "
          f"{len(x) / one:,.0f} samples/s, process peak {peak_rss_mb():.0f} MB")
    del x

    print("\n| workers | tiles | samples | seconds | samples/s | vs one run | tiles' own runs | "
          "overhead and idle per tile | peak MB per worker |")
    print("|---|---|---|---|---|---|---|---|---|")
    rows = [(1, None), (2, None), (2, 8)] + ([] if args.quick else [(2, 16)])
    clusters: dict = {}
    for workers, tiles in rows:
        if workers not in clusters:
            for c, cl in clusters.values():
                c.close()
                cl.close()
            clusters.clear()
            cl = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                              dashboard_address=":0")
            clusters[workers] = (Client(cl), cl)
        client = clusters[workers][0]
        client.restart()  # fresh processes: the peak memory is this row's
        client.run(warm_up)  # their imports, as the cluster's start, are not the run's
        n, s, layout = run(client, base / f"w{workers}t{tiles}.zarr", side, tiles, radius)
        rss = max(client.run(peak_rss_mb).values())
        work = sum(client.run(tile_seconds).values())  # the tiles' own runs, in this run
        count = int(np.prod(layout))
        name = f"{layout[0]}x{layout[1]}" + (" (default)" if tiles is None else "")
        # what the workers' time held beyond the tiles' own runs: Dask, Zarr, rims, waiting
        per_tile_ms = (s * workers - work) / count * 1e3
        print(f"| {workers} | {name} | {n:,} | {s:.2f} | {n / s:,.0f} | {(n / s) / rate_one:.2f}x "
              f"| {work:.2f} s | {per_tile_ms:.0f} ms ({per_tile_ms / (work / count * 1e3):.0%} of a tile's work) "
              f"| {rss:.0f} |", flush=True)
    for c, cl in clusters.values():
        c.close()
        cl.close()
    if not args.dir:
        shutil.rmtree(base)
    return 0


if __name__ == "__main__":
    sys.exit(main())
