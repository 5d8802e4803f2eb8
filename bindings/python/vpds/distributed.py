"""Past one machine: a large box sampled as a grid of tiles on Dask, written to Zarr.

    >>> from vpds import distributed
    >>> store = distributed.sample("big.zarr", 2, tiles=(64, 64), u_bounds=(100, 100),
    ...                            radius=0.01, rng=1)          # a LocalCluster, no set-up
    >>> for tile, x, r, t in store.iter_tiles(): ...          # streams back, one tile at a time

Each tile is one libvpds run over its core, with the samples its earlier-phase neighbours
placed within the margin (scale * coverage * r_max) as fixed points and a seed derived from the
global seed and the tile index (the C library's vpds_tiling / vpds_tile_create). Tiles of one of
the 2^d colour phases never touch; Dask runs a tile as soon as its own dependencies are written,
so the result depends on the seed alone, never on the number of workers or the order in which
tasks finish. What holds across seams, and why: see the README ("Tiled sampling")."""
from __future__ import annotations

import os
import shutil
import uuid
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Optional, Sequence, Union

import numpy as np

from .gridsource import GridSource
from .tilestore import TileStore
from ._typing import BoundsLike, RngLike
from .tiling import SizingArg, Tiling, TilingSpec

if TYPE_CHECKING:  # for the annotations: dask is imported when sample() runs
    from distributed import Client, Future

__all__ = ["sample", "run_local", "GridSource", "TileStore", "TilingSpec", "Tiling"]

# per worker process: the C tiling of each run, built once (a run is identified by its token)
_TILINGS: dict[str, Tiling] = {}
_STORES: dict[str, TileStore] = {}  # per worker process: the open store of each path


def _tiling_for(spec: TilingSpec) -> Tiling:
    t = _TILINGS.get(spec.token)
    if t is None:
        if len(_TILINGS) > 8:
            _TILINGS.clear()
        t = _TILINGS[spec.token] = Tiling(spec)
    return t


Rim = tuple[np.ndarray, np.ndarray]


def run_tile(spec: TilingSpec, path: str, tile: int, dep_tiles: Sequence[int] = (),
             *dep_rims: Rim) -> Rim:
    """One tile: run it from its dependencies' samples, write it, mark it complete, and return
    its rim (Tiling.rim: what the tiles after it need). Dependencies in dep_tiles come as their
    rims (the results of their tasks, handed over by Dask), the others are read from the store
    (tiles of a resumed run). Idempotent: a tile already complete is read, not run again."""
    store = _STORES.get(path)
    if store is None:
        store = _STORES[path] = TileStore(path, mode="r+")
    tiling = _tiling_for(spec)
    if store.complete(tile):
        return tiling.rim(tile, *store.read_points(tile))
    given = dict(zip(dep_tiles, dep_rims))
    deps = {k: given[k] if k in given else store.read_points(k) for k in tiling.deps(tile)}
    x, r, t = tiling.run_tile(tile, deps)
    store.write(tile, x, r, t)
    return tiling.rim(tile, x, r)


def _dependents(tiling: Tiling, tiles: Sequence[int]) -> dict[int, int]:
    """Per tile of `tiles`: how many of `tiles` take its rim (the others' samples are read from
    the store), so that a rim is let go once they have run."""
    inside = set(tiles)
    count = {k: 0 for k in tiles}
    for tile in tiles:
        for k in tiling.deps(tile):
            if k in inside:
                count[k] += 1
    return count


def _open_store(store: Union[str, Path], spec: TilingSpec, tiling: Tiling, overwrite: bool) -> TileStore:
    path = Path(store)
    if overwrite and path.exists():
        shutil.rmtree(path)
    _STORES.pop(str(store), None)
    return TileStore.create(path, spec.describe(), spec.token,
                            [tiling.phase(k) for k in range(tiling.count)])


def _spec(d: int, tiles: Union[int, Sequence[int], None], **kw: Any) -> TilingSpec:
    if isinstance(kw.get("sizing"), (str, os.PathLike)):
        # `is None`, not `or`: bounds given as numpy arrays have no truth value
        lo, hi = kw.get("l_bounds"), kw.get("u_bounds")
        kw["sizing"] = GridSource(kw["sizing"], [0.0] * d if lo is None else lo,
                                  [1.0] * d if hi is None else hi)
    return TilingSpec.make(d, [tiles] * d if isinstance(tiles, int) else tiles, **kw)


def sample(store: Union[str, Path], d: int, tiles: Union[int, Sequence[int], None] = None, *,
           l_bounds: Optional[BoundsLike] = None, u_bounds: Optional[BoundsLike] = None,
           radius: float = 0.05, sizing: Union[SizingArg, str, os.PathLike[str]] = None,
           lipschitz: Optional[float] = None, rule: str = "smaller", inhibition: float = 1.0,
           coverage: float = 1.0, periodic: Optional[Sequence[bool]] = None,
           weighted: bool = False, radius_min: Optional[float] = None,
           radius_max: Optional[float] = None, rng: RngLike = 0, scale: float = 1.0,
           address: Optional[str] = None, client: Optional[Client] = None, n_workers: Optional[int] = None,
           progress: bool = True, overwrite: bool = False,
           on_tile: Optional[Callable[[int, int], None]] = None) -> TileStore:
    """Sample the box [l_bounds, u_bounds] (each of shape (d,); default 0 and 1) as `tiles` tiles
    per axis into the Zarr store at `store`, on Dask, and return the store (a reader that streams
    the tiles back). tiles=None: tiles of about 200,000 samples, from the box and the radii
    alone (vpds.tiling.default_tiles), never from the cluster, so the bytes stay those of the
    arguments on any cluster and on a resume.

    The sampling arguments are PoissonDisk's (`sizing`: a float, a numpy grid in memory, a
    `GridSource` or a path to a .npy / .zarr / .exr grid read one window per tile, or a
    vectorised callable with `lipschitz` and `radius_max`). Scheduling: `client` (a
    dask.distributed Client), else `address` (a scheduler's), else a LocalCluster of
    `n_workers` processes (default: the cores) made for the call and closed after it. A store
    that already holds some tiles of the same run is resumed: only the missing tiles run, and
    the result is the bytes of a run that never stopped. `on_tile(tile, count)` is called as
    each tile completes (after the progress bar's update)."""
    spec = _spec(d, tiles, l_bounds=l_bounds, u_bounds=u_bounds, radius=radius, sizing=sizing,
                 lipschitz=lipschitz, rule=rule, inhibition=inhibition, coverage=coverage,
                 periodic=periodic, weighted=weighted, radius_min=radius_min,
                 radius_max=radius_max, rng=rng, scale=scale)
    tiling = Tiling(spec)
    out = _open_store(store, spec, tiling, overwrite)
    todo = out.missing()
    if not todo:
        return out
    from distributed import Client, LocalCluster, as_completed

    own_cluster = None
    if client is None:
        if address is not None:
            client = Client(address)
        else:
            own_cluster = LocalCluster(n_workers=n_workers or os.cpu_count() or 1, threads_per_worker=1,
                                       processes=True, dashboard_address=":0")
            client = Client(own_cluster)
    own_client = own_cluster is not None or address is not None
    bar = None
    futures: dict[int, Future[Rim]] = {}
    try:
        if progress:
            try:
                from tqdm.auto import tqdm
                bar = tqdm(total=tiling.count, initial=tiling.count - len(todo), unit=" tiles",
                           desc="tiles")
            except ImportError:
                bar = None
        spec_f = client.scatter(spec, broadcast=True, hash=False)
        nonce = uuid.uuid4().hex[:8]
        pending = set(todo)
        submitted = [k for k in tiling.order() if k in pending]
        waiting = _dependents(tiling, submitted)  # per tile: its dependents not yet done
        finished: set[int] = set()
        for tile in submitted:
            deps = [k for k in tiling.deps(tile) if k in futures]
            futures[tile] = client.submit(run_tile, spec_f, str(store), tile, deps,
                                          *[futures[k] for k in deps],
                                          key=f"vpds-tile-{spec.token[:8]}-{nonce}-{tile}", pure=False)
        back = {f.key: k for k, f in futures.items()}
        for fut in as_completed(list(futures.values())):
            if fut.status != "finished":
                fut.result()  # raises the task's error (C message included)
            tile = back[fut.key]
            finished.add(tile)
            # a tile's rim stays in the workers' memory only while a tile after it still runs
            for k in tiling.deps(tile):
                if k in waiting:
                    waiting[k] -= 1
            for k in [*tiling.deps(tile), tile]:
                if waiting.get(k) == 0 and k in finished:
                    futures.pop(k, None)
                    waiting.pop(k, None)
            if bar is not None:
                bar.update(1)
            if on_tile is not None:
                on_tile(tile, out.tile_count(tile))
    except BaseException:
        for f in futures.values():
            f.cancel()
        raise
    finally:
        if bar is not None:
            bar.close()
        if own_client:
            client.close()
        if own_cluster is not None:
            own_cluster.close()
    return out


def run_local(store: Union[str, Path], spec: TilingSpec, order: Optional[Iterable[int]] = None,
              overwrite: bool = False) -> TileStore:
    """The same run without Dask, in this process, tiles in `order` (default: by phase, then
    index; any order in which each tile follows its dependencies gives the same bytes)."""
    tiling = Tiling(spec)
    out = _open_store(store, spec, tiling, overwrite)
    _TILINGS[spec.token] = tiling
    tiles = list(tiling.order() if order is None else order)
    # the tiles run here: what later tiles take from them, kept while one of those is to run
    rims: dict[int, Rim] = {}
    later = _dependents(tiling, tiles)
    for tile in tiles:
        deps = tiling.deps(tile)
        missing = [k for k in deps if k not in rims and not out.complete(k)]
        if missing:
            raise ValueError(f"tile {tile} (phase {tiling.phase(tile)}) needs tiles {missing} first")
        given = [k for k in deps if k in rims]
        rim = run_tile(spec, str(store), tile, given, *[rims[k] for k in given])
        if later[tile]:
            rims[tile] = rim
        for k in given:
            later[k] -= 1
            if later[k] == 0:
                del rims[k]
    return out
