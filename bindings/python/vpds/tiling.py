"""The C tiling from Python: a box as a grid of tiles, and one tile's run (vpds_tile_create).

A `TilingSpec` holds every parameter of a tiled run and pickles (it travels to Dask workers);
`Tiling(spec)` builds the C object. Tile k's run samples its core with the seed derived from
the global seed and k, and the samples of its earlier-phase neighbours within the margin as
fixed points (see include/vpds.h, "Tiled sampling")."""
from __future__ import annotations

import hashlib
import math
import numbers
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._args import tile_counts
from ._callbacks import raise_failure, take
from ._optional import require
from ._rules import RULES
from ._errors import VpdsValueError, _raise, created
from ._scipy_compat import _seed_from
from ._workers import check_workers, threads_for
from ._typing import BoundsLike, RngLike, SizingFunction
from ._vpds import ffi, lib
from .gridsource import GridSource
from .sizing_grid import SizingGrid

__all__ = ["TilingSpec", "Tiling"]

# tiles per thread in one C call of Tiling.run: a phase is cut into batches of this many, each
# ended by its largest tile, so larger keeps the threads busy and smaller answers Ctrl-C and
# the progress sooner
_STEP_TILES_PER_THREAD = 16

#: what `sizing` takes (TilingSpec.make, distributed.sample): see TilingSpec
SizingArg = Union[None, float, npt.NDArray[Any], SizingGrid, GridSource, SizingFunction]


@dataclass
class TilingSpec:
    """Everything that decides a tiled run's points (arrays of shape (d,) per axis).

    sizing: None (use `radius`), a float, a grid of radii in memory (numpy array or
    `SizingGrid`, multilinear over the box), a `GridSource` (a grid read one window per tile:
    .npy, Zarr or OpenEXR), or a vectorised callable (then `lipschitz` and `radius_max`)."""

    d: int
    tiles: tuple[int, ...]
    l_bounds: tuple[float, ...]
    u_bounds: tuple[float, ...]
    radius: float = 0.05
    sizing: SizingArg = None
    lipschitz: Optional[float] = None
    rule: str = "smaller"
    inhibition: float = 1.0
    coverage: float = 1.0
    periodic: Optional[tuple[bool, ...]] = None
    weighted: bool = False
    radius_min: Optional[float] = None
    radius_max: Optional[float] = None
    seed: int = 0
    scale: float = 1.0
    _token: str = field(default="", repr=False)

    @classmethod
    def make(cls, d: int, tiles: Optional[Sequence[int]], *, l_bounds: Optional[BoundsLike] = None,
             u_bounds: Optional[BoundsLike] = None, radius: float = 0.05,
             sizing: SizingArg = None, lipschitz: Optional[float] = None, rule: str = "smaller",
             inhibition: float = 1.0, coverage: float = 1.0,
             periodic: Optional[Sequence[bool]] = None, weighted: bool = False,
             radius_min: Optional[float] = None, radius_max: Optional[float] = None,
             rng: RngLike = 0, scale: float = 1.0) -> "TilingSpec":
        """Checked arguments (the C library checks the rest, with its messages). tiles=None:
        the layout default_tiles derives from the box and the radii."""
        if not isinstance(d, (numbers.Integral, np.integer)) or isinstance(d, bool):
            raise TypeError(f"d = {d!r}: must be an int")
        d = int(d)
        if rule not in RULES:
            raise ValueError(f"rule = {rule!r}: must be one of {sorted(RULES)}")
        tiles_t = (1,) * d if tiles is None else tile_counts("tiles", tiles, d)
        lo = tuple(float(v) for v in (np.zeros(d) if l_bounds is None else np.asarray(l_bounds, float).reshape(-1)))
        hi = tuple(float(v) for v in (np.ones(d) if u_bounds is None else np.asarray(u_bounds, float).reshape(-1)))
        if len(lo) != d or len(hi) != d:
            raise ValueError(f"l_bounds and u_bounds must have {d} values each")
        per = None if periodic is None else tuple(bool(p) for p in periodic)
        if per is not None and len(per) != d:
            raise ValueError(f"periodic has {len(per)} flags for {d} axes")
        if sizing is not None and not callable(sizing) and np.ndim(sizing) == 0 and not isinstance(sizing, (SizingGrid, GridSource)):
            radius, sizing = float(sizing), None
        if isinstance(sizing, SizingGrid):
            sizing = sizing.values
        if isinstance(sizing, (np.ndarray, list, tuple)):
            sizing = np.ascontiguousarray(sizing, dtype=np.float64)
            if sizing.ndim != d:
                raise ValueError(f"a sizing grid of {sizing.ndim} axes for d = {d}")
        if isinstance(sizing, GridSource):
            if sizing.dim != d:
                raise ValueError(f"the sizing source has {sizing.dim} axes for d = {d}")
            L, vmin, vmax = sizing.stats()
            lipschitz = L if lipschitz is None else float(lipschitz)
            radius_min, radius_max = vmin, vmax
        spec = cls(d, tiles_t, lo, hi, float(radius), sizing, None if lipschitz is None else float(lipschitz),
                   rule, float(inhibition), float(coverage), per, bool(weighted),
                   None if radius_min is None else float(radius_min),
                   None if radius_max is None else float(radius_max), _seed_from(rng), float(scale))
        if tiles is None:
            spec.tiles = default_tiles(spec)
        spec._token = spec._compute_token()
        Tiling(spec)  # refuse a bad tiling here, with the C message, before any work
        return spec

    def _compute_token(self) -> str:
        """A hash of everything that decides the points (a resumed run must match it)."""
        h = hashlib.sha256()
        h.update(repr(self.describe()).encode())
        s = self.sizing
        if isinstance(s, np.ndarray):
            h.update(s.tobytes())
        elif isinstance(s, GridSource):
            h.update(s.token().encode())
        elif callable(s):
            cloudpickle = require("cloudpickle", "workers or tiles with a sizing callable", "cloudpickle")
            h.update(cloudpickle.dumps(s))
        return h.hexdigest()[:32]

    @property
    def token(self) -> str:
        return self._token

    def describe(self) -> dict[str, Any]:
        """The parameters as plain values (for the store's attributes)."""
        s = self.sizing
        kind = ("radius" if s is None else "grid" if isinstance(s, np.ndarray) else
                "grid-per-tile" if isinstance(s, GridSource) else "callable")
        return {"d": self.d, "tiles": list(self.tiles), "l_bounds": list(self.l_bounds),
                "u_bounds": list(self.u_bounds), "radius": self.radius, "sizing": kind,
                "lipschitz": self.lipschitz, "rule": self.rule, "inhibition": self.inhibition,
                "coverage": self.coverage, "periodic": None if self.periodic is None else list(self.periodic),
                "weighted": self.weighted, "radius_min": self.radius_min,
                "radius_max": self.radius_max, "seed": self.seed, "scale": self.scale}


#: tiles=None: tiles of about this many samples (about a second of work each: the per-tile cost
#: of a Dask task, its Zarr write and its rim, 54-91 ms measured, stays under a tenth) ...
TILE_SAMPLES = 200_000
#: ... and at least MIN_TILES of them while each still holds MIN_TILE_SAMPLES, so that the
#: workers of a machine or two share even a smaller run
MIN_TILES, MIN_TILE_SAMPLES = 16, 20_000


def _provisional(spec: TilingSpec) -> Tiling:
    """The spec's tiling with the fewest tiles it allows (one per axis, two on a periodic one):
    the whole box's descriptor and the margin."""
    return Tiling(replace(spec, tiles=tuple(2 if spec.periodic and spec.periodic[k] else 1
                                            for k in range(spec.d))))


def estimated_samples(spec: TilingSpec, provisional: Optional[Tiling] = None) -> float:
    """Samples of the whole run (vpds_estimate on the whole box, within about 2x), through the
    spec's _provisional tiling (made here unless given). A sizing read per tile (GridSource) is
    estimated at the geometric mean of its smallest and largest radius: the grid is not read
    whole."""
    tg = provisional or _provisional(spec)
    if isinstance(spec.sizing, GridSource) and spec.radius_min and spec.radius_max:
        tg._desc.radius = math.sqrt(spec.radius_min * spec.radius_max)  # make() read them
    sampler = created(lib.vpds_validate, lib.vpds_create, lib.vpds_destroy, "vpds_sampler", tg._desc)
    out = ffi.new("vpds_run_estimate *")
    st = lib.vpds_estimate(sampler, spec.scale, out)
    cause = take(tg._owner, "_callback_error") if tg._owner is not None else None
    if st != lib.VPDS_OK or cause is not None:
        message = ffi.string(lib.vpds_last_error(sampler)).decode()
        if cause is None:
            _raise(st, message)
        raise_failure(st, message, cause, "sizing")
    return float(out.samples)


def _cubic_counts(ext: Sequence[float], periodic: Sequence[bool], want: int) -> list[int]:
    """About `want` near-cubic tiles over a box of extents ext: an axis shorter than a tile
    gets one (two if periodic) and the other axes share the count."""
    thin: dict[int, int] = {}
    while True:
        free = [k for k in range(len(ext)) if k not in thin]
        if not free:
            return [thin[k] for k in range(len(ext))]
        rest = max(1.0, want / float(np.prod(list(thin.values()) or [1])))
        side = (float(np.prod([ext[k] for k in free])) / rest) ** (1.0 / len(free))
        short = [k for k in free if ext[k] < side]
        if not short:
            return [thin[k] if k in thin else max(1, round(ext[k] / side)) for k in range(len(ext))]
        for k in short:
            thin[k] = 2 if periodic[k] else 1


def default_tiles(spec: TilingSpec) -> tuple[int, ...]:
    """The tile counts of tiles=None: from the box and the radii alone (through the estimate),
    never from the workers, so the same arguments give the same tiles, hence the same bytes,
    on any cluster and on a resume. Tiles near-cubic, of about TILE_SAMPLES samples (at least
    MIN_TILES tiles while each keeps MIN_TILE_SAMPLES), even on periodic axes, no thinner than
    the margin (the C tiling refuses thinner ones)."""
    whole = _provisional(spec)
    margin = whole.margin
    n = estimated_samples(spec, whole)
    want = max(math.ceil(n / TILE_SAMPLES), min(MIN_TILES, math.floor(n / MIN_TILE_SAMPLES)), 1)
    ext = [hi - lo for lo, hi in zip(spec.l_bounds, spec.u_bounds)]
    per = spec.periodic or (False,) * spec.d
    counts = []
    for k, c in enumerate(_cubic_counts(ext, per, want)):
        most = max(1, math.floor(ext[k] / margin)) if margin > 0 else c
        c = min(c, most)
        if per[k]:
            c = max(2, c - (c % 2))
        counts.append(c)
    while True:  # the C check has the last word (its margin carries a relative slack)
        try:
            Tiling(replace(spec, tiles=tuple(counts)))
            return tuple(counts)
        except VpdsValueError:
            over = [k for k in range(spec.d) if counts[k] > (2 if per[k] else 1)]
            if not over:
                raise
            k = max(over, key=lambda j: counts[j] / ext[j])  # the thinnest tiles that can thicken
            counts[k] -= 2 if per[k] else 1


class _CallbackOwner:
    """What vpds_py_sizing_batch needs: d, the callable, and a slot for its exception (see
    vpds._callbacks)."""

    def __init__(self, d: int, fn: SizingFunction) -> None:
        self.d = d
        self._sizing_fn = fn
        self._callback_error: Optional[BaseException] = None


class Tiling:
    """The C vpds_tiling of a spec, and the run of one tile."""

    def __init__(self, spec: TilingSpec) -> None:
        self.spec = spec
        self.last_threads = 0  # threads the last run() used (vpds_tiled_threads)
        d = spec.d
        self._keep: list[Any] = []
        desc = ffi.new("vpds_desc *", lib.vpds_default_desc())
        desc.dim = d
        lo = ffi.new("double[]", list(spec.l_bounds))
        hi = ffi.new("double[]", list(spec.u_bounds))
        desc.lo, desc.hi = lo, hi
        self._keep += [lo, hi]
        if spec.periodic is not None:
            per = ffi.new("int[]", [1 if p else 0 for p in spec.periodic])
            desc.periodic = per
            self._keep.append(per)
        desc.radius = spec.radius
        self._owner = None
        self._grid = None
        s = spec.sizing
        if isinstance(s, np.ndarray):
            self._grid = SizingGrid(s, spec.l_bounds, spec.u_bounds)
            desc.sizing_grid = self._grid._ptr
        elif callable(s) and not isinstance(s, GridSource):
            self._owner = _CallbackOwner(d, s)
            self._handle = ffi.new_handle(self._owner)
            desc.sizing_batch = lib.vpds_py_sizing_batch
            desc.sizing_user = self._handle
        if spec.lipschitz is not None:
            desc.lipschitz = spec.lipschitz
        if spec.radius_min is not None:
            desc.radius_min = spec.radius_min
        if spec.radius_max is not None:
            desc.radius_max = spec.radius_max
        desc.rule = RULES[spec.rule]
        desc.inhibition = spec.inhibition
        desc.coverage = spec.coverage
        desc.weighted = 1 if spec.weighted else 0
        desc.seed = spec.seed
        self._desc = desc
        tiles = ffi.new("uint64_t[]", list(spec.tiles))
        self._keep.append(tiles)
        tdesc = ffi.new("vpds_tiling_desc *", lib.vpds_default_tiling_desc())
        tdesc.sampler = desc
        tdesc.tiles = tiles
        tdesc.scale = spec.scale
        tdesc.sizing_per_tile = 1 if isinstance(s, GridSource) else 0
        self._t = created(lib.vpds_tiling_validate, lib.vpds_tiling_create,
                          lib.vpds_tiling_destroy, "vpds_tiling", tdesc)

    # -- the grid of tiles ---------------------------------------------------------------------
    @property
    def count(self) -> int:
        return int(lib.vpds_tiling_count(self._t))

    @property
    def margin(self) -> float:
        return float(lib.vpds_tiling_margin(self._t))

    def _check_tile(self, tile: int) -> int:
        tile = int(tile)
        if not 0 <= tile < self.count:
            raise ValueError(f"tile = {tile}: the tiling has tiles 0..{self.count - 1}")
        return tile

    def phase(self, tile: int) -> int:
        return int(lib.vpds_tiling_phase(self._t, self._check_tile(tile)))

    def seed(self, tile: int) -> int:
        return int(lib.vpds_tiling_seed(self._t, self._check_tile(tile)))

    def box(self, tile: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(lo, hi) of the tile's core, each of shape (d,)."""
        lo = ffi.new("double[]", self.spec.d)
        hi = ffi.new("double[]", self.spec.d)
        lib.vpds_tiling_box(self._t, self._check_tile(tile), lo, hi)
        return np.array(list(lo)), np.array(list(hi))

    def coords(self, tile: int) -> tuple[int, ...]:
        c = ffi.new("uint64_t[]", self.spec.d)
        lib.vpds_tiling_coords(self._t, self._check_tile(tile), c)
        return tuple(int(v) for v in c)

    def index(self, coords: Sequence[int]) -> int:
        c = ffi.new("int64_t[]", [int(v) for v in coords])
        out = ffi.new("uint64_t *")
        if lib.vpds_tiling_index(self._t, c, out) != lib.VPDS_OK:
            raise ValueError(f"coords = {tuple(coords)}: outside the tiles {self.spec.tiles} on a closed axis")
        return int(out[0])

    def deps(self, tile: int) -> list[int]:
        """The tiles whose samples this tile's run needs (its neighbours of lower phase)."""
        cap = 3 ** self.spec.d - 1  # VPDS_TILING_MAX_DEPS for this dimension
        buf = ffi.new("uint64_t[]", cap)
        n = ffi.new("size_t *")
        lib.vpds_tiling_deps(self._t, self._check_tile(tile), buf, cap, n)
        return [int(buf[i]) for i in range(n[0])]

    def cone(self, tile: int) -> list[int]:
        """Every tile this tile needs, directly or not, in an order that can run."""
        n = ffi.new("size_t *")
        st = lib.vpds_tiling_cone(self._t, self._check_tile(tile), ffi.NULL, 0, n)
        if st not in (lib.VPDS_OK, lib.VPDS_ERR_OVERFLOW) or (st != lib.VPDS_OK and n[0] == 0):
            _raise(st, f"tile {tile}: the cone is too large to list")
        buf = ffi.new("uint64_t[]", max(1, n[0]))
        st = lib.vpds_tiling_cone(self._t, tile, buf, n[0], n)
        if st != lib.VPDS_OK:
            _raise(st, f"tile {tile}: the cone is too large to list")
        return [int(buf[i]) for i in range(n[0])]

    def rim(self, tile: int, x: npt.ArrayLike, r: npt.ArrayLike
            ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """The samples (x (n, d), r (n,)) of this tile's own samples that lie within the margin of
        its box's faces, in their order: all that a later tile's run takes from it (a sample
        within the margin of a neighbour's box is within it of the face between them, across a
        periodic wrap too), so run_tile given rims makes the bytes it makes given whole tiles."""
        x = np.asarray(x, dtype=np.float64).reshape(-1, self.spec.d)
        r = np.asarray(r, dtype=np.float64).reshape(-1)
        lo, hi = self.box(tile)
        # a wider band than the C filter's, so that no rounding of a wrap drops one it keeps
        slack = self.margin * 1e-6 + 1e-9 * float(np.max(np.abs(np.concatenate([lo, hi]))) + 1.0)
        gap = np.minimum(x - lo, hi - x).min(axis=1, initial=np.inf) if len(x) else np.empty(0)
        keep = gap <= self.margin + slack
        return x[keep], r[keep]

    def order(self) -> list[int]:
        """All tiles in an order that can run one after another: by phase, then index."""
        return sorted(range(self.count), key=lambda k: (self.phase(k), k))

    def run(self, workers: int = 1, progress: Optional[Callable[[int, int], None]] = None
            ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.int64]]:
        """Every tile, in this process: points (n, d), radii (n,) and the tile of each sample
        (n,), in the order (phase, tile, insertion), by the C library's tiling job on
        `workers` threads (-1: every core; scipy's spelling). The same bytes for any number of
        workers, and those of run_tile over order(). A Python sizing callable keeps the run on
        the calling thread (the GIL; a numpy grid or a constant radius runs on every worker);
        a GridSource sizing is refused (its windows are read per tile: use run_tile).

        The job runs a few tiles per C call (16 per thread): progress(done, total) is called
        after each with the tiles done, and Ctrl-C stops the run between two calls (nothing
        is kept)."""
        threads = threads_for(check_workers(workers))
        rd = ffi.new("vpds_tiling_run_desc *", lib.vpds_default_tiling_run_desc())
        rd.threads = min(threads, 256)
        job_out = ffi.new("vpds_tiling_job **")
        msg = ffi.new("char[]", 1024)
        st = lib.vpds_tiling_job_create(self._t, rd, job_out, msg, 1024)
        if st < 0:
            _raise(st, ffi.string(msg).decode())
        job = ffi.gc(job_out[0], lib.vpds_tiling_job_destroy)
        # a Python callable keeps the C run on this thread (the GIL): steps of one thread's share
        busy = 1 if self._owner is not None else max(1, threads)
        step, total = _STEP_TILES_PER_THREAD * busy, int(self.count)
        while True:
            st = lib.vpds_tiling_job_step(job, step, msg, 1024)
            cause = take(self._owner, "_callback_error")
            if st < 0 or cause is not None:
                if cause is None:
                    _raise(st, ffi.string(msg).decode())
                raise_failure(st, ffi.string(msg).decode(), cause, "sizing")
            if progress is not None:
                progress(int(lib.vpds_tiling_job_tiles_done(job)), total)
            if st == lib.VPDS_OK:
                break
        out = ffi.new("vpds_tiled **")
        st = lib.vpds_tiling_job_result(job, out, msg, 1024)
        if st < 0:
            _raise(st, ffi.string(msg).decode())
        res = ffi.gc(out[0], lib.vpds_tiled_destroy)
        self.last_threads = int(lib.vpds_tiled_threads(res))  # 1 when a callback kept it serial
        n, d = int(lib.vpds_tiled_count(res)), self.spec.d
        if n == 0:
            return np.empty((0, d)), np.empty(0), np.empty(0, dtype=np.int64)
        x = np.frombuffer(ffi.buffer(lib.vpds_tiled_points(res), n * d * 8), dtype=np.float64).reshape(n, d).copy()
        r = np.frombuffer(ffi.buffer(lib.vpds_tiled_radii(res), n * 8), dtype=np.float64).copy()
        k = np.frombuffer(ffi.buffer(lib.vpds_tiled_tiles(res), n * 8), dtype=np.uint64).astype(np.int64)
        return x, r, k

    def window_range(self, tile: int) -> tuple[list[int], list[int]]:
        """Node offsets and counts of the grid window that covers this tile's core (with one
        node to spare on each side)."""
        src = self.spec.sizing
        # the nodes of a grid; the other sizings have none: (), as np.shape gives for them
        shape = src.shape if isinstance(src, (GridSource, np.ndarray)) else ()
        lo, hi = self.box(tile)
        off, cnt = [], []
        for k in range(self.spec.d):
            step = (self.spec.u_bounds[k] - self.spec.l_bounds[k]) / (shape[k] - 1)
            a0 = max(0, math.floor((lo[k] - self.spec.l_bounds[k]) / step) - 1)
            a1 = min(shape[k], math.floor((hi[k] - self.spec.l_bounds[k]) / step) + 3)
            off.append(a0)
            cnt.append(a1 - a0)
        return off, cnt

    # -- one tile's run ------------------------------------------------------------------------
    def run_tile(self, tile: int, deps: Mapping[int, tuple[npt.ArrayLike, npt.ArrayLike]],
                 budget: int = 0) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """The tile's own samples (points (n, d), radii (n,), scales (n,)) from its
        dependencies' samples: deps[k] = (points, radii) of tile k, for every k in deps(tile)."""
        tile = self._check_tile(tile)
        d = self.spec.d
        keep = []
        pts = ffi.new("vpds_tile_points[]", max(1, len(deps)))
        for i, (k, (x, r)) in enumerate(sorted(deps.items())):
            x = np.ascontiguousarray(x, dtype=np.float64).reshape(-1, d)
            r = np.ascontiguousarray(r, dtype=np.float64).reshape(-1)
            keep += [x, r]
            pts[i].tile = int(k)
            pts[i].x = ffi.cast("const double *", ffi.from_buffer(x)) if len(x) else ffi.NULL
            pts[i].r = ffi.cast("const double *", ffi.from_buffer(r)) if len(r) else ffi.NULL
            pts[i].n = len(x)
        window = ffi.NULL
        if isinstance(self.spec.sizing, GridSource):
            window = self._window(tile, self.spec.sizing)
            keep.append(window)
        out = ffi.new("vpds_sampler **")
        nfix = ffi.new("size_t *")
        msg = ffi.new("char[]", 1024)
        st = lib.vpds_tile_create(self._t, tile, pts, len(deps), window, out, nfix, msg, 1024)
        if st != lib.VPDS_OK:
            _raise(st, ffi.string(msg).decode())
        s = ffi.gc(out[0], lib.vpds_destroy)
        lib.vpds_set_budget(s, budget)
        while True:
            st = lib.vpds_run(s)
            cause = take(self._owner, "_callback_error")
            if st < 0 or cause is not None:  # a callable's exception is raised as itself
                message = ffi.string(lib.vpds_last_error(s)).decode()
                if cause is None:
                    _raise(st, message)
                raise_failure(st, message, cause, "sizing")
            if st == lib.VPDS_OK:
                break
        n, f = int(lib.vpds_count(s)), int(nfix[0])
        x = np.frombuffer(ffi.buffer(lib.vpds_points(s), n * d * 8), dtype=np.float64).reshape(n, d)[f:].copy()
        r = np.frombuffer(ffi.buffer(lib.vpds_radii(s), n * 8), dtype=np.float64)[f:].copy()
        t = np.frombuffer(ffi.buffer(lib.vpds_scales(s), n * 8), dtype=np.float64)[f:].copy()
        return x, r, t

    def _window(self, tile: int, src: GridSource) -> Any:
        """The C grid of src's window over this tile (run_tile's, with a GridSource sizing)."""
        off, cnt = self.window_range(tile)
        values = np.ascontiguousarray(src.window(off, [o + c for o, c in zip(off, cnt)]), dtype=np.float64)
        return src.make_window(values, off)
