"""scipy.stats.qmc's rules where vpds.PoissonDisk follows them: seeds, bounds, optimization."""
from __future__ import annotations

import numbers
from typing import Any, Callable, Optional

import numpy as np
import numpy.typing as npt

from ._optional import MissingDependencyError, require
from ._typing import RngLike

_SEED_LIMIT = 2**64  # ints below are the C seed itself
_OPTIMIZATIONS = "{'random-cd', 'lloyd'}"


def _seed_from(rng: RngLike) -> int:
    """The C seed of an `rng` (scipy's rule, numpy.random.default_rng, with one exception kept
    for the C library's sake):

    - an int in [0, 2**64) is the C seed itself (the same points as the C library and the
      CLI's --seed, whatever the version of numpy);
    - a larger int goes through numpy.random.SeedSequence as default_rng takes it: the seed is
      drawn from default_rng(rng), so rng=n and rng=numpy.random.default_rng(n) agree for
      n >= 2**64 (below, an int is the C seed and a Generator is drawn from: they differ);
    - a negative int is refused, as default_rng (and so scipy) refuses it;
    - a Generator (or RandomState) gives a seed drawn from it: the draw consumes its state, so
      engines made in turn from one generator differ;
    - None (fresh entropy), a SeedSequence, a BitGenerator or a sequence of ints: the seed
      is drawn from default_rng(rng).
    """
    if isinstance(rng, (numbers.Integral, np.integer)) and not isinstance(rng, bool):
        seed = int(rng)
        if seed < 0:
            raise ValueError(f"rng = {seed}: an int seed must be >= 0 (numpy.random.default_rng, "
                             "and so scipy, refuses negative seeds); an int in [0, 2**64) is the "
                             "C seed itself, a larger one goes through numpy.random.SeedSequence")
        if seed < _SEED_LIMIT:
            return seed
    if isinstance(rng, np.random.Generator):
        gen = rng
    elif isinstance(rng, np.random.RandomState):  # what default_rng does with it (numpy >= 2)
        gen = np.random.Generator(rng._bit_generator)
    else:
        try:
            gen = np.random.default_rng(rng)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"rng = {rng!r} cannot be used to seed a numpy.random.Generator "
                             f"instance ({exc}); give an int, None, a Generator, a "
                             "SeedSequence or a BitGenerator") from None
    return int(gen.integers(0, 2**63, dtype=np.int64))


def _validate_bounds(l_bounds: Optional[npt.ArrayLike], u_bounds: Optional[npt.ArrayLike],
                     d: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """scipy.stats.qmc's rule for bounds (its _validate_bounds, its messages): each broadcast
    to (d,) (default 0 and 1), l_bounds < u_bounds on every axis; float64 copies."""
    def values(name: str, v: Optional[npt.ArrayLike], default: float) -> npt.NDArray[np.float64]:
        if v is None:
            return np.full(d, default)
        try:
            return np.asarray(v, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{name} = {v!r}: must be numbers ({exc})") from None
    lo, hi = values("l_bounds", l_bounds, 0.0), values("u_bounds", u_bounds, 1.0)
    try:
        lower, upper = np.broadcast_to(lo, d).copy(), np.broadcast_to(hi, d).copy()
    except ValueError:
        raise ValueError("'l_bounds' and 'u_bounds' must be broadcastable and respect the sample "
                         f"dimension: l_bounds has shape {lo.shape}, u_bounds {hi.shape}, for "
                         f"d = {d}") from None
    # lo against hi as given, too: with d = 0 a broadcast to (0,) would hide l_bounds=[1],
    # u_bounds=[0] (both broadcast to (d,), so they broadcast to each other)
    a, b = np.broadcast_arrays(np.atleast_1d(lo), np.atleast_1d(hi))
    bad = np.flatnonzero(~(a < b))
    if bad.size:
        k = int(bad[0])
        raise ValueError(f"Bounds are not consistent 'l_bounds' < 'u_bounds': l_bounds[{k}] = "
                         f"{float(a[k])!r}, u_bounds[{k}] = {float(b[k])!r}")
    return lower, upper


def _optimization_name(optimization: Optional[str], d: int) -> Optional[str]:
    """scipy's optimization names, in any case (as its QMCEngine), lower-cased; or None."""
    if optimization is None:
        return None
    name = optimization.lower() if isinstance(optimization, str) else None
    if name not in ("random-cd", "lloyd"):
        raise ValueError(f"optimization: {optimization!r} is not a valid optimization method. "
                         f"It must be one of {_OPTIMIZATIONS} (in any case) or None")
    if name == "lloyd" and d < 2:
        raise ValueError(f"optimization = {optimization!r} with d = {d}: Lloyd's Voronoi "
                         "tessellation needs d >= 2 (scipy refuses it at the first random())")
    return name


def _scipy_optimizers(optimization: str) -> Callable[..., Any]:
    """scipy.stats.qmc's factory of optimizers (what its QMCEngine calls), imported here."""
    impl = require("scipy.stats._qmc", f"optimization = {optimization!r} (scipy.stats.qmc's "
                   "optimizers)", "scipy")
    select: Optional[Callable[..., Any]] = getattr(impl, "_select_optimizer", None)
    if select is None:
        raise MissingDependencyError(f"optimization = {optimization!r} needs scipy >= 1.10 "
                                     "(pip install 'scipy>=1.10'): this scipy has no "
                                     "scipy.stats._qmc._select_optimizer")
    return select
