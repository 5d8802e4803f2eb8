"""The Python face of libvpds: a drop-in for scipy.stats.qmc.PoissonDisk, and more."""
from __future__ import annotations

import os
from typing import Any, Callable, Iterator, NamedTuple, Optional, Sequence, SupportsFloat, Union, cast

import numpy as np
import numpy.typing as npt

from ._args import axis_flags, number, room_for_samples, tile_counts
from ._args import count as count_arg
from ._callbacks import as_values, escaped, keep, raise_failure, take
from ._errors import (VpdsDomainError, VpdsError, VpdsSizingError, VpdsStateError,
                      VpdsUnsupportedError, VpdsValueError, _raise, created)
from ._vpds import ffi, lib
from .domain import Domain, DomainLike, as_domain
from ._scipy_compat import _optimization_name, _scipy_optimizers, _seed_from, _validate_bounds
from .sizing_grid import SizingGrid
from ._typing import RngLike, SizingFunction
from .estimate import Estimate
from ._rules import RULES
from ._tiled import TilesLike, refuse_with_tiles, tiled_fill
from ._workers import check_workers

__all__ = ["PoissonDisk", "SizingGrid", "VpdsError", "VpdsSizingError", "VpdsDomainError",
           "Progressive", "RULES", "ALGORITHM_VERSION", "MAX_DIM"]

#: the algorithm version of this library: the points a seed gives (`algorithm_version` pins one)
ALGORITHM_VERSION: int = int(lib.VPDS_ALGORITHM_VERSION)


def _algorithm_version(version: Any, first: int) -> int:
    """desc.algorithm_version from an argument: None or 0 the current one, else first..current."""
    if version is None:
        return 0
    if (not isinstance(version, (int, np.integer)) or isinstance(version, bool)
            or not (version == 0 or first <= version <= ALGORITHM_VERSION)):
        raise ValueError(f"algorithm_version = {version!r}: this library has versions "
                         f"{first}..{ALGORITHM_VERSION} (0 or None: the current one)")
    return int(version)
#: the largest dimension the library samples (VPDS_MAX_DIM)
MAX_DIM: int = int(lib.VPDS_MAX_DIM)
# work units (darts + cells) per C call in a fill: small enough for a responsive Ctrl-C and
# progress bar, large enough that the calls cost nothing measurable
_CHUNK = 50_000
# events of the stream per call of vpds_next_n (progressive): one C call for many events, and
# Ctrl-C still answered between calls
STREAM_BATCH = 4096
#: what `sizing` takes: a radius, a grid of radii (d axes), a SizingGrid, r(x), an EXR image path
SizingLike = Union[None, float, npt.ArrayLike, SizingGrid, SizingFunction, str, os.PathLike[str]]


@ffi.def_extern(error=1, onerror=escaped("_callback_error"))
def vpds_py_sizing_batch(x: Any, n: int, r_out: Any, user: Any) -> int:
    """Called by the C library with n points: one vectorised call of the Python sizing. An
    exception is kept in the owner's _callback_error (re-raised after the C call) and fails
    the batch; after one, every call fails at once until the binding has taken it."""
    try:
        owner = ffi.from_handle(user)
        if owner._callback_error is not None:
            return 1
        pts = np.frombuffer(ffi.buffer(x, n * owner.d * 8), dtype=np.float64).reshape(n, owner.d)
        pts.flags.writeable = False  # the library's own darts: a sizing that wrote them moved them
        r = as_values(owner._sizing_fn(pts), n, "sizing")
        np.frombuffer(ffi.buffer(r_out, n * 8), dtype=np.float64)[:] = r
        return 0
    except BaseException as exc:  # noqa: BLE001 - re-raised in Python after the C call returns
        keep(user, "_callback_error", exc)
        return 1


def _grid_shape(shape: Any, d: int) -> tuple[int, ...]:
    """sizing_grid_shape as d node counts >= 2 (the grid's ends are the box's)."""
    values = list(shape) if isinstance(shape, (list, tuple, np.ndarray)) else None
    if values is None or len(values) != d or not all(
            isinstance(m, (int, np.integer)) and not isinstance(m, bool) and m >= 2 for m in values):
        raise ValueError(f"sizing_grid_shape = {shape!r}: give d = {d} integers >= 2, the nodes per axis")
    return tuple(int(m) for m in values)


class Progressive(NamedTuple):
    """The first n samples of the continuous stream: each prefix is conflict-free and maximal
    at its own scale, so the n points are evenly spread at scale `t`."""
    points: npt.NDArray[np.float64]  # (n, d)
    scales: npt.NDArray[np.float64]  # (n,): the t of each sample, non-increasing (inf for the first)
    t: float                         # the scale reached: the set is maximal at t (the last sample's t)


class PoissonDisk:
    """Maximal Poisson-disk sampling with spatially varying radii, in any dimension (1 to MAX_DIM = 16).

    A drop-in for ``scipy.stats.qmc.PoissonDisk`` (scipy's own TestPoisson passes against it:
    tests/py/test_scipy_suite.py): `d`, `radius`, `rng` (or `seed`, not both), `l_bounds`,
    `u_bounds` (broadcast to (d,), scipy's errors), `optimization`, `random(n)`,
    `fill_space()`, `reset()`, `fast_forward(n)`, `integers(...)`, `num_generated`.
    `hypersphere` and `ncandidates` are checked and have no effect (libvpds is not Bridson's
    algorithm: it throws darts into a hyper-octree of uncovered cells, and its process is
    bias-free and maximal).

      rng:        an int in [0, 2**64) is the C seed itself (the points of the C library and
                  of `vpds sample --seed`); a larger int goes through numpy.random.SeedSequence
                  (the seed is drawn from numpy.random.default_rng(rng), so rng=n and
                  rng=default_rng(n) agree for n >= 2**64); a negative int is refused, as
                  default_rng refuses it. A Generator or RandomState gives a seed drawn from
                  it (so engines made in turn from one generator differ), and None, a
                  SeedSequence or a BitGenerator one drawn from default_rng(rng). `seed` (scipy's
                  former name) is the same argument: give one of them. The `seed` attribute is
                  the C seed in use.
      d = 0:      as scipy: random(n) gives an array of shape (n, 0) (fill_space() one of shape
                  (0, 0)) and no C sampler is made (libvpds samples d = 1 to 8); the other
                  arguments are still checked; sizing, domain, fixed points and periodic axes
                  are refused, and so are the methods beyond scipy's.
      optimization: None, "random-cd" or "lloyd" (in any case), applied as scipy's QMCEngine
                  does: to each batch random() and fill_space() return, by scipy.stats.qmc's
                  own optimizers (scipy needed), in the box mapped onto the unit cube. It gives
                  up the disk guarantee (random-cd swaps coordinates between samples, lloyd
                  moves them towards Voronoi centroids) and maximality; `points` keeps the
                  samples as drawn, with the guarantee. Refused with a domain (the moved
                  samples would leave it); lloyd needs d >= 2 and a batch of more than d
                  samples (Qhull's tessellation). Its random-cd swaps are drawn from a
                  Generator seeded with `seed`, restarted by reset().

    Beyond scipy:
      sizing:     None (use `radius`), a float, a numpy grid of radii over the bounds (d axes,
                  C order, multilinear), a `SizingGrid`, a vectorised callable r(x) taking
                  points of shape (m, d) and returning (m,) radii (called in batches from C),
                  or the path of an OpenEXR image (2D; `sizing_channel`, `sizing_range`: see
                  vpds.exr for the mapping of pixels to radii).
      sizing_grid_shape: sample a callable onto a grid of that many nodes per axis and use the
                  multilinear grid instead: an approximation of the callable (exact at the
                  nodes), with its own, computed L; no Python calls during the run.
      lipschitz:  L of r; required with a callable, computed for a grid (a larger value may be
                  given). With `enforce_lipschitz=L` a grid is first lowered to be L-Lipschitz.
      rule:       "prior", "current", "bigger" or "smaller" (Table 1 of the paper).
      fixed_points, fixed_radii: objects already placed, (k, d) and (k,) (radii None: the
                  sizing decides); they come first in the output.
      domain:     sample box ∩ {sdf <= 0} only, maximal up to its boundary: a callable sdf on
                  (m, d) points (negative inside, 1-Lipschitz), a polygon (shapely, (m, 2)
                  vertices, or a list of rings; holes by nesting), a boolean or float mask
                  over the box (inside: value >= domain_threshold), or an image file (.exr,
                  .png, ...). See vpds.domain.
      progress:   a tqdm bar during fill_space (if tqdm is installed).
      algorithm_version: pin the points a seed gives (None or 0: the library's current
                  version, `vpds.ALGORITHM_VERSION`); 1 reproduces worlds made before
                  version 2 changed the coverage search of two radii, 2 streams made
                  before version 3 changed the stream after a run; 3 the points of a run
                  before version 4's coverage search learnt (the same points, except where
                  the search's box budget or precision decided); 4 streams made before
                  version 5 found the farthest point exactly (one constant radius, no domain).
      memory_limit: most bytes the C sampler may hold (None: no limit); a run whose estimate
                  (`estimate()`) exceeds it is refused before it starts, and an allocation past
                  it fails cleanly: MemoryError, the sampler as it was.
      workers, tiles: several cores for fill_space() (scipy's spelling: an int >= 1, -1 for
                  every core). workers=1 without tiles (the default) is the serial process
                  above. Otherwise the box is sampled as a grid of tiles (vpds.tiling: every
                  guarantee across the seams, the points in the order (phase, tile, insertion))
                  on that many threads: `tiles` = "auto" (the default then: sides of about 64
                  margins in 2D, 12 in 3D, 6 past 3D, the margin being coverage * r_max; from
                  the box and radii only), an int or d ints. The tiling decides the points,
                  never the worker count: the same bytes for every `workers`, other points than
                  the serial process's. A tiled engine fills the whole box at once: random(n)
                  of finite n, refine, stream, progressive and add_points need the serial
                  process and are refused; so are a domain, fixed points, a memory limit and a
                  pinned algorithm_version, which the tiling does not take. A Python sizing
                  callable runs on the calling thread only (the GIL): the tiles then run one
                  after another; a grid (or `sizing_grid_shape`) runs on every worker.
    Results are numpy arrays of shape (n, d) (copies: they outlive the sampler).
    """

    def __init__(self, d: int, *, radius: float = 0.05, hypersphere: str = "volume",
                 ncandidates: int = 30, optimization: Optional[str] = None, rng: RngLike = None,
                 l_bounds: Optional[npt.ArrayLike] = None, u_bounds: Optional[npt.ArrayLike] = None,
                 sizing: SizingLike = None,
                 lipschitz: Optional[float] = None, enforce_lipschitz: Optional[float] = None,
                 rule: str = "smaller", inhibition: float = 1.0, coverage: float = 1.0,
                 periodic: Optional[Sequence[bool]] = None, weighted: bool = False,
                 radius_min: Optional[float] = None, radius_max: Optional[float] = None,
                 fixed_points: Optional[npt.ArrayLike] = None,
                 fixed_radii: Optional[npt.ArrayLike] = None, progress: bool = True,
                 seed: RngLike = None, sizing_channel: Optional[str] = None,
                 sizing_range: Optional[Sequence[float]] = None,
                 sizing_grid_shape: Optional[Sequence[int]] = None, domain: Optional[DomainLike] = None,
                 domain_threshold: float = 0.5, algorithm_version: Optional[int] = None,
                 memory_limit: Optional[int] = None, workers: int = 1,
                 tiles: TilesLike = None) -> None:
        if seed is not None and rng is not None:
            raise TypeError("PoissonDisk() got multiple values for argument now known as `rng`. "
                            "Specify one of `rng` or `seed`.")
        if not np.issubdtype(type(d), np.integer) or d < 0:
            raise ValueError(f"d = {d!r}: d must be a non-negative integer value (libvpds "
                             "samples d = 1 to 8; d = 0 gives scipy's arrays of shape (n, 0))")
        self.d = int(d)
        self.optimization = _optimization_name(optimization, self.d)
        if hypersphere not in ("volume", "surface"):
            raise ValueError(f"{hypersphere!r} is not a valid hypersphere sampling method. It "
                             "must be one of {'volume', 'surface'} (it has no effect here)")
        if int(ncandidates) < 1:
            raise ValueError(f"ncandidates = {ncandidates!r}: must be >= 1 (it has no effect here)")
        if rule not in RULES:
            raise ValueError(f"rule = {rule!r}: must be one of {sorted(RULES)}")
        self.l_bounds, self.u_bounds = _validate_bounds(l_bounds, u_bounds, self.d)
        if self.d == 0:
            given = [name for name, v in (("sizing", sizing), ("domain", domain),
                                          ("fixed_points", fixed_points), ("periodic", periodic),
                                          ("sizing_grid_shape", sizing_grid_shape)) if v is not None]
            if given:
                raise ValueError(f"d = 0: {', '.join(given)} need d >= 1 (d = 0 has no space to "
                                 "sample: random(n) gives scipy's arrays of shape (n, 0))")
        if self.optimization is not None:
            if domain is not None:
                raise ValueError(f"optimization = {optimization!r} with a domain: the optimizers "
                                 "move samples without regard to it (random-cd swaps "
                                 "coordinates, lloyd moves to centroids in the box)")
            self._select_optimizer = _scipy_optimizers(self.optimization)
        self.radius = number("radius", radius, " (radii that vary: sizing=)")
        self.rule = rule
        self.progress = progress
        self._seed = _seed_from(seed if seed is not None else rng)
        self._callback_error: Optional[BaseException] = None
        self._sizing_fn: Optional[SizingFunction] = None
        self._grid: Optional[SizingGrid] = None
        self._keep: list[Any] = []  # C memory the descriptor points to

        desc = ffi.new("vpds_desc *", lib.vpds_default_desc())
        desc.dim = self.d
        lo = ffi.new("double[]", [float(v) for v in self.l_bounds])
        hi = ffi.new("double[]", [float(v) for v in self.u_bounds])
        desc.lo, desc.hi = lo, hi
        self._keep += [lo, hi]
        if periodic is not None:
            per = ffi.new("int[]", axis_flags("periodic", periodic, self.d))
            desc.periodic = per
            self._keep.append(per)
        desc.radius = self.radius
        if isinstance(sizing, (str, os.PathLike)):
            from .exr import sizing_grid_from_exr
            sizing = sizing_grid_from_exr(sizing, self.l_bounds, self.u_bounds, sizing_channel,
                                          sizing_range)
        if sizing_grid_shape is not None:
            if not callable(sizing):
                raise ValueError("sizing_grid_shape samples a callable sizing onto a grid; "
                                 f"sizing is {type(sizing).__name__}")
            shape = _grid_shape(sizing_grid_shape, self.d)
            axes = [np.linspace(a, b, m) for a, b, m in zip(self.l_bounds, self.u_bounds, shape)]
            nodes = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, self.d)
            values = as_values(sizing(nodes), len(nodes), "sizing", flat=True).reshape(shape)
            sizing = SizingGrid(values, self.l_bounds, self.u_bounds)
            lipschitz = None  # the grid's own, exact L replaces the callable's
        if sizing is not None and not callable(sizing) and np.ndim(sizing) == 0:
            # np.ndim 0: a number or a 0-d array, both of which float() takes
            desc.radius = float(cast(SupportsFloat, sizing))
            self.radius = float(cast(SupportsFloat, sizing))
        elif isinstance(sizing, SizingGrid) or (sizing is not None and not callable(sizing)):
            n_axes = sizing.dim if isinstance(sizing, SizingGrid) else np.ndim(sizing)
            if n_axes != self.d:
                raise ValueError(f"sizing: a grid of {n_axes} axes for d = {self.d} (one axis of "
                                 "nodes per dimension)")
            grid = sizing if isinstance(sizing, SizingGrid) else SizingGrid(sizing, self.l_bounds, self.u_bounds)
            if enforce_lipschitz is not None:
                grid.enforce_lipschitz(enforce_lipschitz)
            self._grid = grid
            desc.sizing_grid = grid._ptr
        elif sizing is not None:
            self._sizing_fn = sizing
            self._handle = ffi.new_handle(self)
            desc.sizing_batch = lib.vpds_py_sizing_batch
            desc.sizing_user = self._handle
        if lipschitz is not None:
            desc.lipschitz = number("lipschitz", lipschitz)
            if not desc.lipschitz >= 0:  # -1 would read as the C library's "not given"
                raise ValueError(f"lipschitz = {lipschitz!r}: must be >= 0")
        desc.rule = RULES[rule]
        desc.inhibition = number("inhibition", inhibition)
        desc.coverage = number("coverage", coverage)
        desc.weighted = 1 if weighted else 0
        desc.algorithm_version = _algorithm_version(algorithm_version, 1)
        if memory_limit is not None and (not isinstance(memory_limit, (int, np.integer))
                                         or isinstance(memory_limit, bool) or memory_limit < 0):
            raise ValueError(f"memory_limit = {memory_limit!r}: must be an int number of bytes >= 0 "
                             "(0 or None: no limit)")
        self._memory_limit = 0 if memory_limit is None else int(memory_limit)
        if radius_min is not None:
            desc.radius_min = number("radius_min", radius_min)
        if radius_max is not None:
            desc.radius_max = number("radius_max", radius_max)
        self._domain: Optional[Domain] = None
        if domain is not None:
            self._domain = as_domain(domain, self.d, self.l_bounds, self.u_bounds,
                                     number("domain_threshold", domain_threshold))
            desc.domain = self._domain.fn_ptr
            desc.domain_user = self._domain.user
        desc.seed = self._seed
        self._desc = desc
        if self.d == 0:  # no sampler, but the other fields as C checks them (one axis, [0, 1])
            stand_in = ffi.new("vpds_desc *", desc[0])
            stand_in.dim, stand_in.lo, stand_in.hi = 1, ffi.NULL, ffi.NULL
            msg = ffi.new("char[]", 1024)
            st = lib.vpds_validate(stand_in, msg, 1024)
            if st != lib.VPDS_OK:
                _raise(st, ffi.string(msg).decode())
        self._periodic = None if periodic is None else tuple(bool(p) for p in periodic)
        self.workers = check_workers(workers)
        if tiles is not None and not (isinstance(tiles, str) and tiles == "auto"):
            tiles = tile_counts("tiles", tiles, self.d)
        self.tiles: TilesLike = "auto" if tiles is None and self.workers != 1 else tiles
        self._check_tiled(domain, fixed_points, memory_limit, algorithm_version)
        self._tiled: Optional[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int, int]] = None
        self._fixed = None
        if fixed_points is not None:
            self._fixed = self._points_and_radii("fixed_points", fixed_points, "fixed_radii", fixed_radii)
        self.reset()

    def _check_tiled(self, domain: Any, fixed_points: Any, memory_limit: Any,
                     algorithm_version: Any) -> None:
        """Refuse up front what a tiled engine (workers != 1 or tiles) cannot take."""
        if self.tiles is None or self.d == 0:
            return
        given = [name for name, v in (("domain", domain), ("fixed_points", fixed_points),
                                      ("memory_limit", memory_limit),
                                      ("algorithm_version", algorithm_version))
                 if v is not None and not (name in ("memory_limit", "algorithm_version") and v == 0)]
        if given:
            raise ValueError(f"workers = {self.workers}, tiles = {self.tiles!r}: the tiled process "
                             f"does not take {', '.join(given)} (workers=1 without tiles does)")
        if self.d > int(lib.VPDS_TILING_MAX_DIM):
            raise ValueError(f"workers = {self.workers}, tiles = {self.tiles!r}: tilings have at "
                             f"most {int(lib.VPDS_TILING_MAX_DIM)} axes, d = {self.d}")
        if self._grid is not None:
            glo = np.array([self._grid._lo[k] for k in range(self.d)])
            ghi = np.array([self._grid._hi[k] for k in range(self.d)])
            if not (np.array_equal(glo, self.l_bounds) and np.array_equal(ghi, self.u_bounds)):
                raise ValueError("workers/tiles: the SizingGrid spans other bounds than the box; "
                                 "the tiling reads a grid over the box")

    # -- lifetime -----------------------------------------------------------------------------
    def reset(self) -> "PoissonDisk":
        """Back to the empty sampling (the fixed points kept), with the same seed."""
        self._tiled = None
        self._s = None if self.d == 0 else self._new_sampler(self._desc)
        self.num_generated = 0 if self._s is None else int(lib.vpds_count(self._s))
        if self.optimization is not None:
            self._optimizer_rng = np.random.default_rng(self._seed)
        self._refining: Optional[tuple[float, int]] = None  # refine(t) stopped by an error
        return self

    def _sampler(self, what: str) -> Any:
        """The C sampler, or a clear refusal with d = 0 (scipy's case, with no sampler)."""
        if self._s is None:
            raise ValueError(f"{what} needs d >= 1: with d = 0 there is no space to sample (only "
                             "scipy's random(n) of shape (n, 0), fill_space() and reset())")
        return self._s

    def _optimized(self, sample: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """`sample` through scipy's optimizer (as its QMCEngine.random does), in the box mapped
        onto the unit cube where scipy's optimizers work; unchanged without optimization."""
        if self.optimization is None or len(sample) == 0:
            return sample
        if self.optimization == "lloyd" and len(sample) <= self.d:
            raise ValueError(f"optimization = 'lloyd': a batch of {len(sample)} samples in d = "
                             f"{self.d}; Lloyd's Voronoi tessellation (Qhull) needs more than d. "
                             "Draw more at once (random(n) with n > d)")
        config = {"n_nochange": 100, "n_iters": 10_000, "rng": self._optimizer_rng,  # random-cd
                  "tol": 1e-5, "maxiter": 10, "qhull_options": None}  # lloyd: scipy's own values
        span = self.u_bounds - self.l_bounds
        unit = np.clip((sample - self.l_bounds) / span, 0.0, 1.0)
        moved = np.asarray(self._select_optimizer(self.optimization, config)(unit.copy()))
        if self.optimization == "random-cd":
            # it only swaps values within columns: the same swaps of the drawn coordinates,
            # exactly (mapping back from the unit cube would round some by an ulp)
            out = np.empty_like(sample)
            for k in range(self.d):
                out[np.argsort(moved[:, k], kind="stable"), k] = \
                    sample[np.argsort(unit[:, k], kind="stable"), k]
            return out
        return np.clip(self.l_bounds + moved * span, self.l_bounds, self.u_bounds)

    def _new_sampler(self, desc: Any) -> Any:
        """A C sampler of desc (refused with the C message), holding the fixed points."""
        s = created(lib.vpds_validate, lib.vpds_create, lib.vpds_destroy, "vpds_sampler", desc)
        lib.vpds_set_memory_limit(s, self._memory_limit)
        if self._fixed is not None:
            fx, fr = self._fixed
            self._check(lib.vpds_add_points(s, ffi.cast("const double *", ffi.from_buffer(fx)),
                                            ffi.NULL if fr is None else ffi.cast("const double *", ffi.from_buffer(fr)),
                                            len(fx)), s)
        return s

    def _check(self, st: int, sampler: Any = None) -> int:
        """Raise a C error status with the message of `sampler` (default: this one's); an
        exception a Python callable raised during the call is raised as itself (the C status
        and message as a note), whatever the status."""
        cause, where = take(self, "_callback_error"), "sizing"
        if cause is None:
            cause, where = take(self._domain, "error"), "domain"
        if st < 0 or cause is not None:
            message = ffi.string(lib.vpds_last_error(self._s if sampler is None else sampler)).decode()
            if cause is None:
                _raise(st, message)
            raise_failure(st, message, cause, where)
        return st

    # -- sampling -----------------------------------------------------------------------------
    def _run_until(self, call: Callable[[], int], target: Optional[int], desc: str) -> None:
        """Call the C library in chunks of work until done (or `target` samples exist),
        updating a progress bar; Ctrl-C stops between chunks with a valid partial state."""
        bar = None
        if self.progress:
            try:
                from tqdm.auto import tqdm
                bar = tqdm(desc=desc, unit=" samples", leave=False)
            except ImportError:
                bar = None
        lib.vpds_set_budget(self._s, _CHUNK)
        try:
            while True:
                st = self._check(call())
                if bar is not None:
                    bar.update(int(lib.vpds_count(self._s)) - bar.n)
                if st == lib.VPDS_OK:
                    return
                if target is not None and lib.vpds_count(self._s) >= target:
                    return
        finally:
            lib.vpds_set_budget(self._s, 0)
            if bar is not None:
                bar.close()

    def _draw(self, n: Union[int, float]) -> npt.NDArray[np.float64]:
        """The next n samples as drawn (fewer if the set becomes maximal first)."""
        n = count_arg("n", n)
        if self._s is None:  # d = 0: scipy's n rows of no coordinates
            self.num_generated += n
            return np.empty((n, 0))
        if self._tiled is not None or (self.tiles is not None and n > 0):
            refuse_with_tiles(self, f"random({n})")
        target = self.num_generated + n
        if lib.vpds_count(self._s) < target:
            self._run_until(lambda: lib.vpds_run(self._s), target, "sampling")
        out = self.points[self.num_generated:target]
        self.num_generated += len(out)
        return out

    def random(self, n: Union[int, float] = 1, *, workers: int = 1) -> npt.NDArray[np.float64]:
        """The next n samples of the bias-free process (fewer if the set becomes maximal
        first, as scipy does), shape (n, d), through the `optimization` if one is set.
        n = inf is fill_space() (scipy's fill_space is random(inf)). `workers` is accepted
        for scipy compatibility."""
        if isinstance(n, (float, np.floating)) and float(n) == float("inf"):
            return self.fill_space()
        return self._optimized(self._draw(n))

    def fill_space(self) -> npt.NDArray[np.float64]:
        """Every remaining sample until the set is maximal (all of them, as scipy's
        fill_space returns the samples it adds), shape (m, d), through the `optimization` if
        one is set. With d = 0 there is nothing to fill: shape (0, 0)."""
        if self._s is None:
            return np.empty((0, 0))
        if self.tiles is not None:
            if self._tiled is None:
                self._tiled = tiled_fill(self, self.tiles, self.workers)
            out = self._tiled[0][self.num_generated:]
            self.num_generated += len(out)
            return self._optimized(out)
        self._run_until(lambda: lib.vpds_run(self._s), None, "filling")
        out = self.points[self.num_generated:]
        self.num_generated += len(out)
        return self._optimized(out)

    def fast_forward(self, n: int) -> "PoissonDisk":
        """Skip the next n samples (scipy's fast_forward: random(n) discarded, here without
        the optimizer's work): random(a) then random(b) after fast_forward(k) gives the
        samples a random(a + k + b) would (without optimization)."""
        self._draw(n)
        return self

    def integers(self, l_bounds: npt.ArrayLike, *, u_bounds: Optional[npt.ArrayLike] = None,
                 n: int = 1, endpoint: bool = False, workers: int = 1) -> npt.NDArray[np.int64]:
        """scipy's QMCEngine.integers: random(n) mapped from the box onto integers in
        [l_bounds, u_bounds) ([l_bounds, u_bounds] with endpoint; l_bounds 0 when u_bounds is
        None) by floor of the affine map, shape (n, d), int64. A sample on the box's upper
        face (the box is closed, scipy's unit cube is not) gives u_bounds - 1."""
        if u_bounds is None:
            u_bounds, l_bounds = l_bounds, 0
        lo, hi = np.atleast_1d(l_bounds), np.atleast_1d(u_bounds)
        if endpoint:
            hi = hi + 1
        if not (np.issubdtype(lo.dtype, np.integer) and np.issubdtype(hi.dtype, np.integer)):
            raise ValueError("'u_bounds' and 'l_bounds' must be integers or array-like of "
                             f"integers: l_bounds = {l_bounds!r}, u_bounds = {u_bounds!r}")
        lower, upper = _validate_bounds(lo, hi, self.d)
        sample = self.random(n, workers=workers)
        unit = (sample - self.l_bounds) / (self.u_bounds - self.l_bounds)
        return np.minimum(np.floor(unit * (upper - lower) + lower), upper - 1).astype(np.int64)

    def refine(self, t: float) -> npt.NDArray[np.float64]:
        """Discrete decrease (Section 4.3): maximal at the smaller scale t; returns the new
        samples, shape (m, d). After an exception (Ctrl-C, a raising callable), refine(t) again
        continues the refinement and returns all its samples, those of the stopped call included."""
        t = number("t", t)
        before = int(lib.vpds_count(self._sampler("refine()")))
        if self.tiles is not None:
            refuse_with_tiles(self, "refine()")
        st = lib.vpds_get_stats(self._s)
        if self._refining is not None and self._refining[0] == t and st.t == t and not st.maximal:
            before = self._refining[1]
        self._refining = (t, before)
        first = [True]

        def step() -> int:
            if first[0]:
                first[0] = False
                return int(lib.vpds_refine(self._s, t))
            return int(lib.vpds_run(self._s))
        self._run_until(step, None, f"refining to t={t}")
        self._refining = None
        self.num_generated = int(lib.vpds_count(self._s))
        return self.points[before:]

    def stream(self, t_min: float = 0.0) -> Iterator[tuple[npt.NDArray[np.float64], float]]:
        """The continuous decrease (Section 4.2): (point, t) one at a time, the point of shape
        (d,), t non-increasing."""
        self._sampler("stream()")
        if self.tiles is not None:
            refuse_with_tiles(self, "stream()")
        x = ffi.new("double[]", self.d)
        t = ffi.new("double *")
        while True:
            st = self._check(lib.vpds_next(self._s, float(t_min), x, t))
            if st == lib.VPDS_STREAM_END:
                return
            self.num_generated = int(lib.vpds_count(self._s))
            yield np.frombuffer(ffi.buffer(x, self.d * 8), dtype=np.float64).copy(), float(t[0])

    def progressive(self, n: int, *, inhibition: Optional[float] = 0.5) -> Progressive:
        """Exactly n points (Progressive: points (n, d), scales (n,), t; fewer points if the set
        becomes maximal first): the first n samples of the continuous stream from this sampler's
        fixed points (a fresh stream with the same seed; this sampler is not changed). Each
        prefix is maximal at its own scale, so any n gives an evenly spread set; `t` is the
        scale reached. `inhibition` is R_f / R_c for this stream: with 1 (equal radii) the
        stream is farthest-point insertion, deterministic after the first point (its second
        point is a corner of the box); the default 0.5 draws each point at random among those
        free at t * R_f that cover the farthest point, as in the paper's Figure 7 (Delaunay
        angles >= 14.48 deg). None keeps the sampler's own inhibition."""
        n = count_arg("n", n)
        self._sampler("progressive()")
        room_for_samples(f"progressive(n={n})", n, self.d, self._memory_limit)
        if self.tiles is not None:
            refuse_with_tiles(self, "progressive()")
        desc = ffi.new("vpds_desc *", self._desc[0])
        if inhibition is not None:
            if not 0 < float(inhibition) <= 1:
                raise ValueError(f"inhibition = {inhibition!r}: the ratio R_f / R_c must be in (0, 1]")
            desc.inhibition = float(inhibition) * desc.coverage
        s = self._new_sampler(desc)
        first = int(lib.vpds_count(s))
        got = ffi.new("size_t *")
        left = n
        while left > 0:
            # batches of vpds_next_n (the events of one call each), so Ctrl-C stops between them
            st = self._check(lib.vpds_next_n(s, min(left, STREAM_BATCH), 0.0, ffi.NULL, ffi.NULL, got), s)
            left -= int(got[0])
            if st == lib.VPDS_STREAM_END:
                break
        count = int(lib.vpds_count(s))
        pts = np.frombuffer(ffi.buffer(lib.vpds_points(s), count * self.d * 8),
                            dtype=np.float64).reshape(count, self.d)[first:].copy()
        scales = np.frombuffer(ffi.buffer(lib.vpds_scales(s), count * 8),
                               dtype=np.float64)[first:].copy()
        return Progressive(pts, scales, float(scales[-1]) if len(scales) else float("inf"))

    def __iter__(self) -> Iterator[tuple[npt.NDArray[np.float64], float]]:
        return self.stream()

    def add_points(self, x: npt.ArrayLike, r: Optional[npt.ArrayLike] = None) -> None:
        """Fixed points now (between runs): objects already placed, t = +inf; x of shape (k, d),
        r (k,) or None (the sizing decides)."""
        self._sampler("add_points()")
        if self.tiles is not None:
            refuse_with_tiles(self, "add_points()")
        fx, fr = self._points_and_radii("x", x, "r", r)
        self._check(lib.vpds_add_points(self._s, ffi.cast("const double *", ffi.from_buffer(fx)),
                                        ffi.NULL if fr is None else ffi.cast("const double *", ffi.from_buffer(fr)),
                                        len(fx)))
        self.num_generated = int(lib.vpds_count(self._s))

    def _points_and_radii(self, x_name: str, x: npt.ArrayLike, r_name: str,
                          r: Optional[npt.ArrayLike]) -> tuple[npt.NDArray[np.float64], Optional[npt.NDArray[np.float64]]]:
        """Points of shape (k, d) (one point: (d,)) and radii (k,) or None, as C reads them."""
        try:
            fx = np.ascontiguousarray(x, dtype=np.float64)
            fr = None if r is None else np.ascontiguousarray(r, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{x_name}, {r_name}: not arrays of numbers ({exc})") from None
        if fx.ndim == 1 and len(fx) == self.d:
            fx = fx.reshape(1, self.d)
        if fx.ndim != 2 or fx.shape[1] != self.d:
            raise ValueError(f"{x_name}: shape {fx.shape}, expected (k, {self.d}) (or ({self.d},) for one point)")
        if fr is not None and fr.shape != (len(fx),) and not (fr.ndim == 0 and len(fx) == 1):
            raise ValueError(f"{r_name}: shape {fr.shape}, expected ({len(fx)},): one radius per point")
        return fx, None if fr is None else fr.reshape(-1)

    # -- results (copies) -----------------------------------------------------------------------
    def _count(self) -> int:
        """Samples held by the C sampler (none with d = 0, which has no sampler)."""
        return 0 if self._s is None else int(lib.vpds_count(self._s))

    def _tiled_result(self, column: int) -> Optional[npt.NDArray[np.float64]]:
        """A copy of a tiled fill's points (0) or radii (1); None for the serial process."""
        if self._tiled is None:
            return None
        values: npt.NDArray[np.float64] = (self._tiled[0] if column == 0 else self._tiled[1]).copy()
        return values

    @property
    def points(self) -> npt.NDArray[np.float64]:
        """All samples so far, insertion order, shape (n, d) (as drawn: before any
        `optimization`)."""
        tiled = self._tiled_result(0)
        if tiled is not None:
            return tiled
        n = self._count()
        if n == 0:
            return np.empty((0, self.d))
        x: npt.NDArray[np.float64] = np.frombuffer(ffi.buffer(lib.vpds_points(self._s), n * self.d * 8),
                                                   dtype=np.float64).reshape(n, self.d).copy()
        return x

    @property
    def radii(self) -> npt.NDArray[np.float64]:
        """r at each sample (unscaled), shape (n,)."""
        tiled = self._tiled_result(1)
        if tiled is not None:
            return tiled
        n = self._count()
        return np.frombuffer(ffi.buffer(lib.vpds_radii(self._s), n * 8), dtype=np.float64).copy() if n else np.empty(0)

    @property
    def scales(self) -> npt.NDArray[np.float64]:
        """The scale t at which each sample was inserted (inf for fixed points), shape (n,)."""
        if self._tiled is not None:  # every tile runs at scale 1
            return np.ones(len(self._tiled[0]))
        n = self._count()
        return np.frombuffer(ffi.buffer(lib.vpds_scales(self._s), n * 8), dtype=np.float64).copy() if n else np.empty(0)

    @property
    def fixed(self) -> npt.NDArray[np.bool_]:
        """True where the sample is a fixed point, shape (n,)."""
        if self._tiled is not None:
            return np.zeros(len(self._tiled[0]), dtype=bool)
        n = self._count()
        flags = np.frombuffer(ffi.buffer(lib.vpds_flags(self._s), n), dtype=np.uint8) if n else np.empty(0, np.uint8)
        return (flags & 1).astype(bool)

    def estimate(self, t: Optional[float] = None) -> Estimate:
        """Samples, active cells and peak bytes of a maximal run at scale t (None: the scale the
        next fill_space samples), before it runs: vpds_estimate (within about 2x in 1D-8D), plus
        the copies of the results this binding makes. A sizing or domain callable is called at
        4096 fixed points; the samples do not change."""
        out = ffi.new("vpds_run_estimate *")
        self._check(lib.vpds_estimate(self._sampler("estimate"), 0.0 if t is None else float(t), out))
        copies = 2 * (8 * self.d + 17) * out.samples  # points, radii, scales, flags, twice
        return Estimate(float(out.samples), float(out.bytes + copies), float(out.cells))

    @property
    def stats(self) -> dict[str, Union[int, float]]:
        """The C sampler's statistics; for a tiled fill: samples, tiles and threads."""
        if self._tiled is not None:
            return {"samples": len(self._tiled[0]), "tiles": self._tiled[2],
                    "threads": self._tiled[3], "t": 1.0, "maximal": 1}
        st = lib.vpds_get_stats(self._sampler("stats"))
        return {k: getattr(st, k) for k in ("darts", "accepted", "levels", "peak_active_cells",
                                             "bytes_held", "peak_bytes", "sizing_calls", "delta",
                                             "t", "maximal", "domain_calls", "stream_slack")}

    @property
    def lipschitz(self) -> float:
        if self._grid is not None and self._desc.lipschitz < 0:
            return self._grid.lipschitz
        return float(self._desc.lipschitz) if self._desc.lipschitz >= 0 else 0.0

    @property
    def seed(self) -> int:
        """The C seed in use (an int rng below 2**64 is used as is)."""
        return self._seed
