"""A sizing given as radii at the nodes of a regular grid (libvpds's vpds_grid)."""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ._errors import _raise, created
from ._typing import BoundsLike
from ._vpds import ffi, lib

__all__ = ["SizingGrid"]


def _bound(name: str, value: BoundsLike, dim: int) -> list[float]:
    """lo or hi of a grid of dim axes: dim numbers."""
    try:
        b = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r}: expected {dim} numbers, one per axis of the grid") from None
    if b.shape != (dim,):
        raise ValueError(f"{name} = {value!r}: {b.size} values for a grid of {dim} axes "
                         f"(values has {dim} dimensions)")
    return [float(a) for a in b]


class SizingGrid:
    """Radii at the nodes of a regular grid over [lo, hi] (C order, axis k along x[k]),
    interpolated multilinearly: `values` has one axis per dimension, lo and hi shape (d,).
    `lipschitz` is exact (the largest gradient norm)."""

    def __init__(self, values: npt.ArrayLike, lo: BoundsLike, hi: BoundsLike) -> None:
        try:
            v = np.ascontiguousarray(values, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"grid values: not an array of numbers ({exc})") from None
        if v.ndim < 1 or v.ndim > int(lib.VPDS_MAX_DIM):
            raise ValueError(f"grid values have {v.ndim} dimensions; expected 1 to {lib.VPDS_MAX_DIM}")
        self._values = v
        self._shape = ffi.new("size_t[]", list(v.shape))
        # C reads dim entries of each: a shorter lo or hi would be read past its end
        self._lo = ffi.new("double[]", _bound("lo", lo, v.ndim))
        self._hi = ffi.new("double[]", _bound("hi", hi, v.ndim))
        desc = ffi.new("vpds_grid_desc *", lib.vpds_default_grid_desc())
        desc.dim = v.ndim
        desc.shape = self._shape
        desc.values = ffi.cast("const double *", ffi.from_buffer(v))
        desc.lo = self._lo
        desc.hi = self._hi
        self._ptr = created(lib.vpds_grid_validate, lib.vpds_grid_create, lib.vpds_grid_destroy,
                            "vpds_grid", desc)

    @property
    def dim(self) -> int:
        """The grid's axes: the dimension of the points it takes."""
        return int(self._values.ndim)

    @property
    def lipschitz(self) -> float:
        return float(lib.vpds_grid_lipschitz(self._ptr))

    @property
    def values(self) -> npt.NDArray[np.float64]:
        """The radii at the nodes (as enforce_lipschitz left them), of the grid's shape."""
        n = lib.vpds_grid_size(self._ptr)
        buf = ffi.buffer(lib.vpds_grid_values(self._ptr), n * 8)
        v: npt.NDArray[np.float64] = np.frombuffer(buf, dtype=np.float64).reshape(self._values.shape).copy()
        return v

    def enforce_lipschitz(self, lipschitz: float) -> "SizingGrid":
        """Lower values (only) until the interpolant is `lipschitz`-Lipschitz (every edge slope
        at most L/sqrt(d): a sufficient condition that may lower more than strictly needed)."""
        st = lib.vpds_grid_enforce_lipschitz(self._ptr, float(lipschitz))
        if st != lib.VPDS_OK:
            _raise(st, f"lipschitz = {lipschitz!r}: must be finite and > 0")
        return self

    def __call__(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """r at points of shape (m, d) (or one point (d,)): shape (m,)."""
        pts = np.ascontiguousarray(np.atleast_2d(x), dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != self.dim:
            raise ValueError(f"x: shape {np.shape(x)}, expected (m, {self.dim}) or ({self.dim},): "
                             f"the grid has {self.dim} axes")
        return np.array([lib.vpds_grid_eval(self._ptr, ffi.cast("const double *", ffi.from_buffer(p)))
                         for p in pts])
