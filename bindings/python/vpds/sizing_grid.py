"""A sizing given as radii at the nodes of a regular grid (libvpds's vpds_grid)."""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ._errors import _raise, created
from ._typing import BoundsLike
from ._vpds import ffi, lib

__all__ = ["SizingGrid"]


class SizingGrid:
    """Radii at the nodes of a regular grid over [lo, hi] (C order, axis k along x[k]),
    interpolated multilinearly: `values` has one axis per dimension, lo and hi shape (d,).
    `lipschitz` is exact (the largest gradient norm)."""

    def __init__(self, values: npt.ArrayLike, lo: BoundsLike, hi: BoundsLike) -> None:
        v = np.ascontiguousarray(values, dtype=np.float64)
        if v.ndim < 1 or v.ndim > int(lib.VPDS_MAX_DIM):
            raise ValueError(f"grid values have {v.ndim} dimensions; expected 1 to {lib.VPDS_MAX_DIM}")
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
        return np.array([lib.vpds_grid_eval(self._ptr, ffi.cast("const double *", ffi.from_buffer(p)))
                         for p in pts])
