"""A grid of radii too large for memory, read one window at a time (tiled sampling).

The grid's nodes lie over the box [lo, hi] as for an in-memory grid (`SizingGrid`: C order,
axis k along x[k], multilinear). The source is a .npy file (memory-mapped), a Zarr array (a
path or the array), any array-like that slices (h5py, numpy), or an OpenEXR image read in
strips of scanlines (2D; pixels map to nodes as in vpds.exr). A window evaluates bit for bit as
the whole grid (vpds_grid_create_window), so a tiled run gives the points of the same grid in
memory. `stats()` reads the grid once, in blocks, for the whole grid's L, min and max: exactly
the values of the whole grid, since every cell lies whole in some block."""
from __future__ import annotations

import hashlib
import os
from os import PathLike
from typing import Any, Optional, Protocol, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._errors import created
from ._optional import require
from ._typing import BoundsLike
from ._vpds import ffi, lib

__all__ = ["GridArrayLike", "GridSource"]

_BLOCK_BYTES = 64 << 20  # memory for one block of stats()


class GridArrayLike(Protocol):
    """An array-like grid GridSource reads one window at a time (numpy, Zarr, h5py): a shape,
    and slicing by a tuple of slices (one per axis)."""

    @property
    def shape(self) -> tuple[int, ...]: ...

    def __getitem__(self, key: tuple[slice, ...], /) -> Any: ...


class GridSource:
    """A sizing grid read per tile. `source`: path (.npy, .zarr, .exr) or an array-like."""

    def __init__(self, source: Union[str, PathLike[str], GridArrayLike], l_bounds: BoundsLike,
                 u_bounds: BoundsLike, *, channel: Optional[str] = None,
                 radius_range: Optional[Sequence[float]] = None) -> None:
        self.l_bounds = tuple(float(v) for v in l_bounds)
        self.u_bounds = tuple(float(v) for v in u_bounds)
        self.channel = channel
        self.radius_range = None if radius_range is None else tuple(float(v) for v in radius_range)
        self._path: Optional[str] = None
        self._array: Any = None
        self._exr = False
        if isinstance(source, (str, PathLike)):
            self._path = os.fspath(source)
            low = self._path.lower().rstrip("/")
            if low.endswith(".exr"):
                self._exr = True
                self._exr_open()
            elif low.endswith(".npy"):
                self._array = np.load(self._path, mmap_mode="r")
            else:
                import zarr
                self._array = zarr.open_array(self._path, mode="r")
        else:
            self._array = source
        if not self._exr:
            self.shape: tuple[int, ...] = tuple(int(v) for v in self._array.shape)
        if len(self.l_bounds) != self.dim or len(self.u_bounds) != self.dim:
            raise ValueError(f"the grid has {self.dim} axes; the bounds have {len(self.l_bounds)}")
        if any(n < 2 for n in self.shape):
            raise ValueError(f"grid shape {self.shape}: need at least 2 nodes per axis")
        self._stats: Optional[tuple[float, float, float]] = None

    # pickles as its path (workers reopen the file), or with the array-like itself
    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        if self._path is not None:
            state["_array"] = None
        state.pop("_exr_file", None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        if self._path is not None:
            if self._exr:
                self._exr_open()
            elif self._path.lower().endswith(".npy"):
                self._array = np.load(self._path, mmap_mode="r")
            else:
                import zarr
                self._array = zarr.open_array(self._path, mode="r")

    @property
    def dim(self) -> int:
        return len(self.shape)

    # -- OpenEXR: grid axis 0 = columns (x[0]), axis 1 = rows from the bottom (x[1]) ---------------
    def _exr_open(self) -> None:
        OpenEXR = require("OpenEXR", "reading .exr sizing images", "OpenEXR")
        f = OpenEXR.InputFile(self._path)
        header = f.header()
        names = sorted(header["channels"])
        channel = self.channel
        if channel is None:
            channel = next((g for g in ("Y", "R", "L") if g in header["channels"]), None)
            if channel is None:
                if len(names) != 1:
                    raise ValueError(f"{self._path}: channels {names}: choose one (channel=...)")
                channel = names[0]
        if channel not in header["channels"]:
            raise ValueError(f"{self._path}: no channel {channel!r}; it has {names}")
        self.channel = channel
        dw = header["dataWindow"]
        self._exr_y0 = int(dw.min.y)
        self._exr_rows = int(dw.max.y - dw.min.y + 1)
        cols = int(dw.max.x - dw.min.x + 1)
        self._exr_type = header["channels"][channel].type
        self._exr_dtype = np.float16 if str(self._exr_type) == "HALF" else np.float32
        self._exr_file = f
        self.shape = (cols, self._exr_rows)

    def _exr_window(self, lo: Sequence[int], hi: Sequence[int]) -> npt.NDArray[np.float64]:
        rows, cols = self._exr_rows, self.shape[0]
        # grid nodes j in [lo1, hi1) are pixel rows rows-1-j: a strip of scanlines, flipped
        first, last = rows - hi[1], rows - 1 - lo[1]
        raw = self._exr_file.channel(self.channel, self._exr_type, self._exr_y0 + first, self._exr_y0 + last)
        px = np.frombuffer(raw, dtype=self._exr_dtype).reshape(last - first + 1, cols)
        px = px[::-1, lo[0]:hi[0]].astype(np.float64)
        if not np.all(np.isfinite(px)):
            raise ValueError(f"{self._path}: channel {self.channel} has non-finite pixels")
        if self.radius_range is not None:
            r_min, r_max = self.radius_range
            px = r_min + (r_max - r_min) * np.clip(px, 0.0, 1.0)
        return np.ascontiguousarray(px.T)

    # -- windows -----------------------------------------------------------------------------------
    def window(self, lo: Sequence[int], hi: Sequence[int]) -> npt.NDArray[np.float64]:
        """The values of nodes [lo[k], hi[k]) on each axis, float64."""
        if self._exr:
            return self._exr_window(lo, hi)
        sl = tuple(slice(int(a), int(b)) for a, b in zip(lo, hi))
        return np.ascontiguousarray(np.asarray(self._array[sl], dtype=np.float64))

    def make_window(self, values: npt.NDArray[np.float64], offset: Sequence[int]) -> Any:
        """A C vpds_grid holding `values` at `offset` of this grid (freed with its owner)."""
        d = self.dim
        shape = ffi.new("size_t[]", list(values.shape))
        whole = ffi.new("size_t[]", list(self.shape))
        off = ffi.new("size_t[]", [int(v) for v in offset])
        lo = ffi.new("double[]", list(self.l_bounds))
        hi = ffi.new("double[]", list(self.u_bounds))
        desc = ffi.new("vpds_grid_desc *", lib.vpds_default_grid_desc())
        desc.dim = d
        desc.shape = shape
        desc.values = ffi.cast("const double *", ffi.from_buffer(values))
        desc.lo, desc.hi = lo, hi
        return created(lib.vpds_grid_validate_window, lib.vpds_grid_create_window,
                       lib.vpds_grid_destroy, "vpds_grid", desc, whole, off)

    def stats(self) -> tuple[float, float, float]:
        """(L, min, max) of the whole grid, read in blocks that overlap by one node."""
        if self._stats is not None:
            return self._stats
        axis = 1 if self._exr else 0  # EXR: strips of scanlines; arrays: slabs of axis 0
        other = int(np.prod([n for k, n in enumerate(self.shape) if k != axis]))
        step = max(1, _BLOCK_BYTES // (8 * other) - 1)
        L, vmin, vmax = 0.0, np.inf, -np.inf
        a = 0
        n = self.shape[axis]
        while a < n - 1:
            b = min(n, a + step + 1)
            lo = [0] * self.dim
            hi = list(self.shape)
            lo[axis], hi[axis] = a, b
            vals = self.window(lo, hi)
            if not np.all(np.isfinite(vals)) or vals.min() <= 0:
                raise ValueError(f"sizing grid: nodes {lo}..{hi} hold values that are not finite and > 0")
            g = self.make_window(vals, lo)
            L = max(L, float(lib.vpds_grid_lipschitz(g)))
            vmin, vmax = min(vmin, float(vals.min())), max(vmax, float(vals.max()))
            a = b - 1
        self._stats = (L, vmin, vmax)
        return self._stats

    def token(self) -> str:
        """What identifies the grid for a resumed run: its source, shape, bounds and stats."""
        h = hashlib.sha256(repr((self._path, self.shape, self.l_bounds, self.u_bounds, self.channel,
                                 self.radius_range, self.stats())).encode())
        if self._path is not None and os.path.exists(self._path):
            h.update(str(os.path.getmtime(self._path)).encode())
        return h.hexdigest()[:32]
