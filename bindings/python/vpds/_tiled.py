"""PoissonDisk(workers=N): the tiled process (vpds_tiling_run on threads) behind the engine.

The tiling decides the points and the workers only how fast they come: a tiling comes from
`tiles` (or, for "auto", from the box and the margin alone), never from the number of workers,
so every worker count gives the same bytes. A tiled run is another process than one run of the
box, with other points than workers=1's serial process; that is why workers=1 without `tiles`
stays serial."""
from __future__ import annotations

import math
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

#: what `tiles` takes: None (serial unless workers != 1), "auto", or tile counts (1 or d ints)
TilesLike = Union[None, str, int, Sequence[int]]

# "auto": a tile's side in margins (scale * coverage * r_max), by dimension: large enough that
# the seams (a margin on each side) cost little, small enough for a few tiles per phase
_AUTO_SIDE = {1: 4096.0, 2: 64.0, 3: 12.0}
_AUTO_SIDE_HIGH = 6.0


def auto_tiles(lo: npt.NDArray[np.float64], hi: npt.NDArray[np.float64],
               periodic: Optional[Sequence[bool]], margin: float) -> tuple[int, ...]:
    """Tile counts from the box and the margin only: sides of about _AUTO_SIDE margins, at
    least one margin, an even count on a periodic axis."""
    d = len(lo)
    side = _AUTO_SIDE.get(d, _AUTO_SIDE_HIGH) * margin
    counts = []
    for k in range(d):
        extent = float(hi[k] - lo[k])
        n = max(1, min(int(extent // side) if side > 0 else 1, int(extent // margin) if margin > 0 else 1))
        if periodic is not None and periodic[k]:
            n = n - 1 if n % 2 else n
            if n < 2:
                if extent / 2 < margin:
                    raise ValueError(f"workers/tiles: periodic axis {k} ({extent:g} long) is shorter "
                                     f"than two margins ({2 * margin:g}): it cannot be tiled "
                                     "(workers=1 samples it in one run)")
                n = 2
        counts.append(n)
    return tuple(counts)


def tiled_fill(engine: Any, tiles: TilesLike, workers: int
               ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int, int]:
    """The tiled process of the engine's problem: points (n, d), radii (n,), tile count and
    threads, by vpds.tiling (the Dask path's tiling too)."""
    from .tiling import Tiling, TilingSpec
    desc = engine._desc
    sizing: Any = None
    r_max = engine.radius
    if engine._grid is not None:
        sizing = engine._grid
        r_max = float(np.max(engine._grid.values))
    elif engine._sizing_fn is not None:
        sizing = engine._sizing_fn
        r_max = float(desc.radius_max)
    margin = float(desc.coverage) * r_max
    if isinstance(tiles, str):
        if tiles != "auto":
            raise ValueError(f"tiles = {tiles!r}: must be 'auto', an int or {engine.d} ints")
        if not (math.isfinite(margin) and margin > 0):
            raise ValueError("workers/tiles with a sizing callable need radius_max (the margin "
                             "of the tiles)")
        tiles = auto_tiles(engine.l_bounds, engine.u_bounds, engine._periodic, margin)
    counts: Sequence[int] = [int(tiles)] if isinstance(tiles, (int, np.integer)) else list(tiles or [])
    spec = TilingSpec.make(
        engine.d, counts, l_bounds=engine.l_bounds, u_bounds=engine.u_bounds, radius=engine.radius,
        sizing=sizing, lipschitz=float(desc.lipschitz) if desc.lipschitz >= 0 else None,
        rule=engine.rule, inhibition=float(desc.inhibition), coverage=float(desc.coverage),
        periodic=engine._periodic, weighted=bool(desc.weighted),
        radius_min=float(desc.radius_min) if desc.radius_min > 0 else None,
        radius_max=float(desc.radius_max) if desc.radius_max > 0 else None, rng=engine.seed)
    tiling = Tiling(spec)
    bar = None
    if engine.progress:
        try:
            from tqdm.auto import tqdm
            bar = tqdm(desc="filling", total=int(tiling.count), unit=" tiles", leave=False)
        except ImportError:
            bar = None
    try:
        x, r, _ = tiling.run(workers=workers,
                             progress=None if bar is None else lambda done, total: bar.update(done - bar.n))
    finally:
        if bar is not None:
            bar.close()
    return x, r, int(tiling.count), tiling.last_threads


def refuse_with_tiles(engine: Any, what: str) -> None:
    """A clear refusal of what the tiled process does not offer."""
    raise ValueError(f"{what}: this engine samples by tiles (workers = {engine.workers}, tiles = "
                     f"{engine.tiles!r}), which fill the whole box at once; use fill_space() (or "
                     "random(inf)), or workers=1 without tiles for the serial process that "
                     f"{what} needs")
