"""The Python face of libvpds: a drop-in for scipy.stats.qmc.PoissonDisk, and more."""
from __future__ import annotations

import numbers
import os
from typing import Any, Callable, Iterator, NamedTuple, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._callbacks import as_values, escaped, keep, raise_failure, take
from ._errors import (VpdsDomainError, VpdsError, VpdsSizingError, VpdsStateError,
                      VpdsUnsupportedError, VpdsValueError, _raise, created)
from ._vpds import ffi, lib
from .domain import Domain, as_domain

__all__ = ["PoissonDisk", "SizingGrid", "VpdsError", "VpdsSizingError", "VpdsDomainError",
           "Progressive", "RULES"]

RULES = {"prior": lib.VPDS_RULE_PRIOR, "current": lib.VPDS_RULE_CURRENT,
         "bigger": lib.VPDS_RULE_BIGGER, "smaller": lib.VPDS_RULE_SMALLER}
# work units (darts + cells) per C call in a fill: small enough for a responsive Ctrl-C and
# progress bar, large enough that the calls cost nothing measurable
_CHUNK = 50_000


@ffi.def_extern(error=1, onerror=escaped("_callback_error"))
def vpds_py_sizing_batch(x, n, r_out, user):  # type: ignore[no-untyped-def]
    """Called by the C library with n points: one vectorised call of the Python sizing. An
    exception is kept in the owner's _callback_error (re-raised after the C call) and fails
    the batch; after one, every call fails at once until the binding has taken it."""
    try:
        owner = ffi.from_handle(user)
        if owner._callback_error is not None:
            return 1
        pts = np.frombuffer(ffi.buffer(x, n * owner.d * 8), dtype=np.float64).reshape(n, owner.d)
        r = as_values(owner._sizing_fn(pts), n, "sizing")
        np.frombuffer(ffi.buffer(r_out, n * 8), dtype=np.float64)[:] = r
        return 0
    except BaseException as exc:  # noqa: BLE001 - re-raised in Python after the C call returns
        keep(user, "_callback_error", exc)
        return 1


class SizingGrid:
    """Radii at the nodes of a regular grid over [lo, hi] (C order, axis k along x[k]),
    interpolated multilinearly. `lipschitz` is exact (the largest gradient norm)."""

    def __init__(self, values: npt.ArrayLike, lo: Sequence[float], hi: Sequence[float]):
        v = np.ascontiguousarray(values, dtype=np.float64)
        if v.ndim < 1 or v.ndim > 8:
            raise ValueError(f"grid values have {v.ndim} dimensions; expected 1 to 8")
        self._values = v
        self._shape = ffi.new("size_t[]", list(v.shape))
        self._lo = ffi.new("double[]", [float(a) for a in lo])
        self._hi = ffi.new("double[]", [float(a) for a in hi])
        desc = ffi.new("vpds_grid_desc *", lib.vpds_default_grid_desc())
        desc.dim = v.ndim
        desc.shape = self._shape
        desc.values = ffi.cast("const double *", ffi.from_buffer(v))
        desc.lo = self._lo
        desc.hi = self._hi
        self._ptr = created(lib.vpds_grid_validate, lib.vpds_grid_create, lib.vpds_grid_destroy,
                            "vpds_grid", desc)

    @property
    def lipschitz(self) -> float:
        return float(lib.vpds_grid_lipschitz(self._ptr))

    @property
    def values(self) -> np.ndarray:
        n = lib.vpds_grid_size(self._ptr)
        buf = ffi.buffer(lib.vpds_grid_values(self._ptr), n * 8)
        return np.frombuffer(buf, dtype=np.float64).reshape(self._values.shape).copy()

    def enforce_lipschitz(self, lipschitz: float) -> "SizingGrid":
        """Lower values (only) until the interpolant is `lipschitz`-Lipschitz (every edge slope
        at most L/sqrt(d): a sufficient condition that may lower more than strictly needed)."""
        st = lib.vpds_grid_enforce_lipschitz(self._ptr, float(lipschitz))
        if st != lib.VPDS_OK:
            _raise(st, f"lipschitz = {lipschitz!r}: must be finite and > 0")
        return self

    def __call__(self, x: npt.ArrayLike) -> np.ndarray:
        pts = np.ascontiguousarray(np.atleast_2d(x), dtype=np.float64)
        return np.array([lib.vpds_grid_eval(self._ptr, ffi.cast("const double *", ffi.from_buffer(p)))
                         for p in pts])


class Progressive(NamedTuple):
    """The first n samples of the continuous stream: each prefix is conflict-free and maximal
    at its own scale, so the n points are evenly spread at scale `t`."""
    points: np.ndarray  # (n, d)
    scales: np.ndarray  # (n,): the t of each sample, non-increasing (inf for the first)
    t: float            # the scale reached: the set is maximal at t (the last sample's t)


def _seed_from(rng: Any) -> int:
    """An int is the C seed itself (the same points as the C library); a Generator (or
    anything numpy.random.default_rng takes) gives a seed drawn from it."""
    if isinstance(rng, (numbers.Integral, np.integer)) and not isinstance(rng, bool):
        seed = int(rng)
        if not 0 <= seed < 2**64:
            raise ValueError(f"rng = {seed}: an int seed must be in [0, 2**64)")
        return seed
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    return int(gen.integers(0, 2**63, dtype=np.int64))


class PoissonDisk:
    """Maximal Poisson-disk sampling with spatially varying radii, in any dimension (1 to 8).

    A drop-in for ``scipy.stats.qmc.PoissonDisk`` where the arguments overlap (`d`, `radius`,
    `rng`, `l_bounds`, `u_bounds`, `random(n)`, `fill_space()`, `reset()`); `hypersphere`,
    `ncandidates` and `optimization` are accepted and have no effect (libvpds is not
    Bridson's algorithm: it throws darts into a hyper-octree of uncovered cells, and its
    process is bias-free and maximal).

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
    Results are numpy arrays of shape (n, d) (copies: they outlive the sampler).
    """

    def __init__(self, d: int, *, radius: float = 0.05, hypersphere: str = "volume",
                 ncandidates: int = 30, optimization: Optional[str] = None, rng: Any = None,
                 l_bounds: Optional[npt.ArrayLike] = None, u_bounds: Optional[npt.ArrayLike] = None,
                 sizing: Union[None, float, npt.ArrayLike, SizingGrid, Callable[[np.ndarray], np.ndarray]] = None,
                 lipschitz: Optional[float] = None, enforce_lipschitz: Optional[float] = None,
                 rule: str = "smaller", inhibition: float = 1.0, coverage: float = 1.0,
                 periodic: Optional[Sequence[bool]] = None, weighted: bool = False,
                 radius_min: Optional[float] = None, radius_max: Optional[float] = None,
                 fixed_points: Optional[npt.ArrayLike] = None,
                 fixed_radii: Optional[npt.ArrayLike] = None, progress: bool = True,
                 seed: Optional[int] = None, sizing_channel: Optional[str] = None,
                 sizing_range: Optional[Sequence[float]] = None,
                 sizing_grid_shape: Optional[Sequence[int]] = None, domain: Any = None,
                 domain_threshold: float = 0.5):
        if hypersphere not in ("volume", "surface"):
            raise ValueError(f"{hypersphere!r} is not a valid hypersphere sampling method. It "
                             "must be one of {'volume', 'surface'} (it has no effect here)")
        if optimization not in (None, "random-cd", "lloyd"):
            raise ValueError(f"optimization = {optimization!r}: must be None, 'random-cd' or "
                             "'lloyd' (it has no effect here: the output is maximal already)")
        if int(ncandidates) < 1:
            raise ValueError(f"ncandidates = {ncandidates!r}: must be >= 1 (it has no effect here)")
        if rule not in RULES:
            raise ValueError(f"rule = {rule!r}: must be one of {sorted(RULES)}")
        if not isinstance(d, (numbers.Integral, np.integer)) or isinstance(d, bool):
            raise TypeError(f"d = {d!r}: must be an int")
        self.d = int(d)
        self.l_bounds = np.zeros(self.d) if l_bounds is None else np.asarray(l_bounds, dtype=np.float64).reshape(-1)
        self.u_bounds = np.ones(self.d) if u_bounds is None else np.asarray(u_bounds, dtype=np.float64).reshape(-1)
        if self.l_bounds.shape != (self.d,) or self.u_bounds.shape != (self.d,):
            raise ValueError(f"l_bounds and u_bounds must have {self.d} values each")
        self.radius = float(radius)
        self.rule = rule
        self.progress = progress
        self._seed = _seed_from(seed if seed is not None else rng)
        self._callback_error: Optional[BaseException] = None
        self._sizing_fn: Optional[Callable[[np.ndarray], np.ndarray]] = None
        self._grid: Optional[SizingGrid] = None
        self._keep: list = []  # C memory the descriptor points to

        desc = ffi.new("vpds_desc *", lib.vpds_default_desc())
        desc.dim = self.d
        lo = ffi.new("double[]", [float(v) for v in self.l_bounds])
        hi = ffi.new("double[]", [float(v) for v in self.u_bounds])
        desc.lo, desc.hi = lo, hi
        self._keep += [lo, hi]
        if periodic is not None:
            per = ffi.new("int[]", [1 if p else 0 for p in periodic])
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
            axes = [np.linspace(a, b, int(m)) for a, b, m in
                    zip(self.l_bounds, self.u_bounds, sizing_grid_shape)]
            if len(axes) != self.d:
                raise ValueError(f"sizing_grid_shape has {len(axes)} values for d = {self.d}")
            nodes = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, self.d)
            values = np.asarray(sizing(nodes), dtype=np.float64).reshape(tuple(int(m) for m in sizing_grid_shape))
            sizing = SizingGrid(values, self.l_bounds, self.u_bounds)
            lipschitz = None  # the grid's own, exact L replaces the callable's
        if sizing is not None and not callable(sizing) and np.ndim(sizing) == 0:
            desc.radius = float(sizing)
            self.radius = float(sizing)
        elif isinstance(sizing, SizingGrid) or (sizing is not None and not callable(sizing)):
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
            desc.lipschitz = float(lipschitz)
        desc.rule = RULES[rule]
        desc.inhibition = float(inhibition)
        desc.coverage = float(coverage)
        desc.weighted = 1 if weighted else 0
        if radius_min is not None:
            desc.radius_min = float(radius_min)
        if radius_max is not None:
            desc.radius_max = float(radius_max)
        self._domain: Optional[Domain] = None
        if domain is not None:
            self._domain = as_domain(domain, self.d, self.l_bounds, self.u_bounds,
                                     float(domain_threshold))
            desc.domain = self._domain.fn_ptr
            desc.domain_user = self._domain.user
        desc.seed = self._seed
        self._desc = desc
        self._fixed = None
        if fixed_points is not None:
            fx = np.ascontiguousarray(fixed_points, dtype=np.float64).reshape(-1, self.d)
            fr = None if fixed_radii is None else np.ascontiguousarray(fixed_radii, dtype=np.float64).reshape(-1)
            if fr is not None and fr.shape != (len(fx),):
                raise ValueError(f"fixed_radii has {fr.shape[0]} values for {len(fx)} fixed points")
            self._fixed = (fx, fr)
        self.reset()

    # -- lifetime -----------------------------------------------------------------------------
    def reset(self) -> "PoissonDisk":
        """Back to the empty sampling (the fixed points kept), with the same seed."""
        self._s = self._new_sampler(self._desc)
        self.num_generated = int(lib.vpds_count(self._s))
        self._refining: Optional[tuple[float, int]] = None  # refine(t) stopped by an error
        return self

    def _new_sampler(self, desc: Any) -> Any:
        """A C sampler of desc (refused with the C message), holding the fixed points."""
        s = created(lib.vpds_validate, lib.vpds_create, lib.vpds_destroy, "vpds_sampler", desc)
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

    def random(self, n: int = 1, *, workers: int = 1) -> np.ndarray:
        """The next n samples of the bias-free process (fewer if the set becomes maximal
        first, as scipy does), shape (n, d). `workers` is accepted for scipy compatibility."""
        n = int(n)
        if n < 0:
            raise ValueError(f"n = {n}: must be >= 0")
        target = self.num_generated + n
        if lib.vpds_count(self._s) < target:
            self._run_until(lambda: lib.vpds_run(self._s), target, "sampling")
        out = self.points[self.num_generated:target]
        self.num_generated += len(out)
        return out

    def fill_space(self) -> np.ndarray:
        """Every remaining sample until the set is maximal (all of them, as scipy's
        fill_space returns the samples it adds), shape (m, d)."""
        self._run_until(lambda: lib.vpds_run(self._s), None, "filling")
        out = self.points[self.num_generated:]
        self.num_generated += len(out)
        return out

    def refine(self, t: float) -> np.ndarray:
        """Discrete decrease (Section 4.3): maximal at the smaller scale t; returns the new
        samples. After an exception (Ctrl-C, a raising callable), refine(t) again continues
        the refinement and returns all its samples, those of the stopped call included."""
        t = float(t)
        before = int(lib.vpds_count(self._s))
        st = lib.vpds_get_stats(self._s)
        if self._refining is not None and self._refining[0] == t and st.t == t and not st.maximal:
            before = self._refining[1]
        self._refining = (t, before)
        first = [True]

        def step() -> int:
            if first[0]:
                first[0] = False
                return lib.vpds_refine(self._s, t)
            return lib.vpds_run(self._s)
        self._run_until(step, None, f"refining to t={t}")
        self._refining = None
        self.num_generated = int(lib.vpds_count(self._s))
        return self.points[before:]

    def stream(self, t_min: float = 0.0) -> Iterator[tuple[np.ndarray, float]]:
        """The continuous decrease (Section 4.2): (point, t) one at a time, t non-increasing."""
        x = ffi.new("double[]", self.d)
        t = ffi.new("double *")
        while True:
            st = self._check(lib.vpds_next(self._s, float(t_min), x, t))
            if st == lib.VPDS_STREAM_END:
                return
            self.num_generated = int(lib.vpds_count(self._s))
            yield np.frombuffer(ffi.buffer(x, self.d * 8), dtype=np.float64).copy(), float(t[0])

    def progressive(self, n: int, *, inhibition: Optional[float] = 0.5) -> Progressive:
        """Exactly n points: the first n samples of the continuous stream from this sampler's
        fixed points (a fresh stream with the same seed; this sampler is not changed). Each
        prefix is maximal at its own scale, so any n gives an evenly spread set; `t` is the
        scale reached. `inhibition` is R_f / R_c for this stream: with 1 (equal radii) the
        stream is farthest-point insertion, deterministic after the first point (its second
        point is a corner of the box); the default 0.5 draws each point at random among those
        free at t * R_f that cover the farthest point, as in the paper's Figure 7 (Delaunay
        angles >= 14.48 deg). None keeps the sampler's own inhibition."""
        n = int(n)
        if n < 0:
            raise ValueError(f"n = {n}: must be >= 0")
        desc = ffi.new("vpds_desc *", self._desc[0])
        if inhibition is not None:
            if not 0 < float(inhibition) <= 1:
                raise ValueError(f"inhibition = {inhibition!r}: the ratio R_f / R_c must be in (0, 1]")
            desc.inhibition = float(inhibition) * desc.coverage
        s = self._new_sampler(desc)
        first = int(lib.vpds_count(s))
        x = ffi.new("double[]", self.d)
        t = ffi.new("double *")
        for _ in range(n):
            if self._check(lib.vpds_next(s, 0.0, x, t), s) == lib.VPDS_STREAM_END:
                break
        count = int(lib.vpds_count(s))
        pts = np.frombuffer(ffi.buffer(lib.vpds_points(s), count * self.d * 8),
                            dtype=np.float64).reshape(count, self.d)[first:].copy()
        scales = np.frombuffer(ffi.buffer(lib.vpds_scales(s), count * 8),
                               dtype=np.float64)[first:].copy()
        return Progressive(pts, scales, float(scales[-1]) if len(scales) else float("inf"))

    def __iter__(self) -> Iterator[tuple[np.ndarray, float]]:
        return self.stream()

    def add_points(self, x: npt.ArrayLike, r: Optional[npt.ArrayLike] = None) -> None:
        """Fixed points now (between runs): objects already placed, t = +inf."""
        fx = np.ascontiguousarray(x, dtype=np.float64).reshape(-1, self.d)
        fr = None if r is None else np.ascontiguousarray(r, dtype=np.float64).reshape(-1)
        if fr is not None and fr.shape != (len(fx),):
            raise ValueError(f"r has {fr.shape[0]} values for {len(fx)} points")
        self._check(lib.vpds_add_points(self._s, ffi.cast("const double *", ffi.from_buffer(fx)),
                                        ffi.NULL if fr is None else ffi.cast("const double *", ffi.from_buffer(fr)),
                                        len(fx)))
        self.num_generated = int(lib.vpds_count(self._s))

    # -- results (copies) -----------------------------------------------------------------------
    @property
    def points(self) -> np.ndarray:
        """All samples so far, insertion order, shape (n, d)."""
        n = int(lib.vpds_count(self._s))
        if n == 0:
            return np.empty((0, self.d))
        return np.frombuffer(ffi.buffer(lib.vpds_points(self._s), n * self.d * 8),
                             dtype=np.float64).reshape(n, self.d).copy()

    @property
    def radii(self) -> np.ndarray:
        """r at each sample (unscaled), shape (n,)."""
        n = int(lib.vpds_count(self._s))
        return np.frombuffer(ffi.buffer(lib.vpds_radii(self._s), n * 8), dtype=np.float64).copy() if n else np.empty(0)

    @property
    def scales(self) -> np.ndarray:
        """The scale t at which each sample was inserted (inf for fixed points), shape (n,)."""
        n = int(lib.vpds_count(self._s))
        return np.frombuffer(ffi.buffer(lib.vpds_scales(self._s), n * 8), dtype=np.float64).copy() if n else np.empty(0)

    @property
    def fixed(self) -> np.ndarray:
        """True where the sample is a fixed point, shape (n,)."""
        n = int(lib.vpds_count(self._s))
        flags = np.frombuffer(ffi.buffer(lib.vpds_flags(self._s), n), dtype=np.uint8) if n else np.empty(0, np.uint8)
        return (flags & 1).astype(bool)

    @property
    def stats(self) -> dict:
        st = lib.vpds_get_stats(self._s)
        return {k: getattr(st, k) for k in ("darts", "accepted", "levels", "peak_active_cells",
                                             "bytes_held", "peak_bytes", "sizing_calls", "delta",
                                             "t", "maximal", "domain_calls")}

    @property
    def lipschitz(self) -> float:
        if self._grid is not None and self._desc.lipschitz < 0:
            return self._grid.lipschitz
        return float(self._desc.lipschitz) if self._desc.lipschitz >= 0 else 0.0

    @property
    def seed(self) -> int:
        """The C seed in use (an int rng is used as is)."""
        return self._seed
