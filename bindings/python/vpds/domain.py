"""Domains beyond the box: the sampler's domain is box ∩ {x : sdf(x) <= 0}.

`as_domain` turns what a user has into the C library's domain function:
  - a callable sdf taking points of shape (m, d) and returning (m,) signed distances (negative
    inside, 1-Lipschitz); called from C one point at a time;
  - a polygon: a shapely Polygon or MultiPolygon (holes included), an (m, 2) array of vertices,
    or a list of such rings (a ring inside another is a hole) -> the C polygon (exact distance);
  - a mask: a boolean or float numpy array with one axis per dimension (C order, axis k along
    x[k]; float: inside where value >= threshold) -> the C mask (distance transform);
  - an image file: .exr (OpenEXR) or any format Pillow reads (.png, ...), over a 2D box with the
    orientation of vpds.exr (column 0 at lo[0], row 0 at the top, hi[1]); values are scaled to
    [0, 1] for 8- and 16-bit images and compared with the threshold (default 0.5).
"""
from __future__ import annotations

import math
import os
from typing import Any, Optional, Protocol, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._args import number
from ._optional import require
from ._callbacks import as_values, escaped, keep
from ._errors import created
from ._typing import BoundsLike, DomainFunction
from ._vpds import ffi, lib

__all__ = ["Domain", "DomainLike", "GeometryLike", "as_domain", "estimate_radius", "JAMMING_DENSITY"]

#: Saturation (jamming) density of random sequential addition of equal balls, by dimension: the
#: fraction of space the balls of radius r/2 cover in a maximal set of conflict distance r.
#: d = 1 is Renyi's constant, d = 2..6 from Torquato, Uche and Stillinger (2006), 7 and 8 from
#: their fit; estimates only for other sampling processes and for small or thin domains.
JAMMING_DENSITY = {1: 0.7476, 2: 0.5470, 3: 0.3841, 4: 0.2600, 5: 0.1707, 6: 0.1093,
                   7: 0.0683, 8: 0.0424}


def jamming_density(d: int) -> float:
    """JAMMING_DENSITY[d], past 8D extrapolated by the ratio of 8D to 7D (about 0.6 per axis)."""
    return JAMMING_DENSITY[d] if d in JAMMING_DENSITY else JAMMING_DENSITY[8] * 0.6 ** (d - 8)


def estimate_radius(n: int, d: int, volume: float = 1.0) -> float:
    """The radius r at which a maximal uniform sampling of a domain of this volume holds about
    n points: n * volume_of_ball(r / 2) = JAMMING_DENSITY[d] * volume. An estimate: boundaries
    add points (more so for small n and thin domains), and two radii or a sizing change it."""
    if isinstance(d, bool) or not isinstance(d, (int, np.integer)) or not 1 <= d <= int(lib.VPDS_MAX_DIM):
        raise ValueError(f"d = {d!r}: must be in 1..{lib.VPDS_MAX_DIM} (an int)")
    if not number("n", n) >= 1:
        raise ValueError(f"n = {n}: must be >= 1")
    volume = number("volume", volume)
    if not volume > 0 or not math.isfinite(volume):
        raise ValueError(f"volume = {volume}: must be finite and > 0")
    unit_ball = math.pi ** (d / 2) / math.gamma(d / 2 + 1)
    # annotated: float ** float is Any to mypy (a negative base would give a complex)
    r: float = 2.0 * (jamming_density(d) * volume / (n * unit_ball)) ** (1.0 / d)
    return r


@ffi.def_extern(error=float("nan"), onerror=escaped("error"))
def vpds_py_domain(x: Any, user: Any) -> float:
    """Called by the C library at one point: the Python sdf on a (1, d) array. An exception is
    kept in the Domain's `error` and signalled by NaN (the library stops with VPDS_ERR_DOMAIN;
    the binding raises the exception itself); after one, every call returns NaN at once until
    the binding has taken it."""
    try:
        owner = ffi.from_handle(user)
        if owner.error is not None:
            return float("nan")
        p = np.frombuffer(ffi.buffer(x, owner.d * 8), dtype=np.float64).reshape(1, owner.d)
        return float(as_values(owner.fn(p.copy()), 1, "domain", flat=True)[0])
    except BaseException as exc:  # noqa: BLE001 - re-raised in Python after the C call returns
        keep(user, "error", exc)
        return float("nan")


class Domain:
    """A domain function for the C library, and the objects it needs kept alive."""

    _handle: Any  # from_callable's: the cffi handle `user` points through, kept alive here

    def __init__(self, d: int, fn_ptr: Any, user: Any, keep: Sequence[Any] = (),
                 sdf: Optional[DomainFunction] = None) -> None:
        self.d = d
        self.fn_ptr = fn_ptr
        self.user = user
        self._keep = list(keep)
        self.fn = sdf
        self.error: Optional[BaseException] = None

    def __call__(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The signed distance at points of shape (m, d) (or one point (d,)): shape (m,)."""
        pts = np.ascontiguousarray(np.atleast_2d(x), dtype=np.float64)
        if self.fn is not None:
            return np.asarray(self.fn(pts), dtype=np.float64).reshape(-1)
        return np.array([self.fn_ptr(ffi.cast("const double *", ffi.from_buffer(p)), self.user)
                         for p in pts])

    @classmethod
    def from_callable(cls, d: int, fn: DomainFunction) -> "Domain":
        dom = cls(d, lib.vpds_py_domain, None, sdf=fn)
        dom._handle = ffi.new_handle(dom)
        dom.user = dom._handle
        return dom

    @classmethod
    def polygon(cls, rings: Sequence[npt.ArrayLike]) -> "Domain":
        """A 2D polygon set from rings of (m, 2) vertices (a ring inside another is a hole)."""
        arrs = [np.ascontiguousarray(r, dtype=np.float64).reshape(-1, 2) for r in rings]
        arrs = [a[:-1] if len(a) > 1 and np.array_equal(a[0], a[-1]) else a for a in arrs]
        xy = np.ascontiguousarray(np.concatenate(arrs) if arrs else np.empty((0, 2)))
        sizes = ffi.new("size_t[]", [len(a) for a in arrs] or [0])
        desc = ffi.new("vpds_polygon_desc *", lib.vpds_default_polygon_desc())
        desc.xy = ffi.cast("const double *", ffi.from_buffer(xy))
        desc.ring_sizes = sizes
        desc.n_rings = len(arrs)
        return cls(2, lib.vpds_polygon_sdf,
                   created(lib.vpds_polygon_validate, lib.vpds_polygon_create,
                           lib.vpds_polygon_destroy, "vpds_polygon", desc))

    @classmethod
    def mask(cls, values: npt.ArrayLike, lo: BoundsLike, hi: BoundsLike,
             threshold: float = 0.5) -> "Domain":
        """A mask over the box [lo, hi] (each (d,)), `values` with one axis per dimension (C
        order): inside where value >= threshold (True for booleans)."""
        v = np.asarray(values)
        if v.dtype == bool:
            v = v.astype(np.float64)
            threshold = 0.5
        v = np.ascontiguousarray(v, dtype=np.float64)
        if v.ndim != len(lo):
            raise ValueError(f"domain mask has {v.ndim} axes for a box of {len(lo)}")
        shape = ffi.new("size_t[]", list(v.shape))
        clo = ffi.new("double[]", [float(a) for a in lo])
        chi = ffi.new("double[]", [float(a) for a in hi])
        desc = ffi.new("vpds_mask_desc *", lib.vpds_default_mask_desc())
        desc.dim = v.ndim
        desc.shape = shape
        desc.values = ffi.cast("const double *", ffi.from_buffer(v))
        desc.threshold = float(threshold)
        desc.lo, desc.hi = clo, chi
        return cls(v.ndim, lib.vpds_mask_sdf,
                   created(lib.vpds_mask_validate, lib.vpds_mask_create, lib.vpds_mask_destroy,
                           "vpds_mask", desc))


def _rings_of_shapely(geom: Any) -> list[npt.NDArray[Any]]:
    polys = list(geom.geoms) if geom.geom_type == "MultiPolygon" else [geom]
    rings = []
    for p in polys:
        if p.geom_type != "Polygon":
            raise ValueError(f"domain: a shapely {p.geom_type} is not a polygon")
        rings.append(np.asarray(p.exterior.coords))
        rings += [np.asarray(h.coords) for h in p.interiors]
    return rings


def read_image(path: Union[str, os.PathLike[str]]) -> npt.NDArray[np.float64]:
    """An image as float64 (rows, columns): EXR through OpenEXR, others through Pillow (integer
    images scaled to [0, 1]; colour converted to luminance)."""
    if str(path).lower().endswith(".exr"):
        from .exr import read_channel
        return read_channel(path)
    Image = require("PIL.Image", "reading image domains", "Pillow")
    with Image.open(path) as im:
        if im.mode in ("I;16", "I;16B", "I"):
            arr = np.asarray(im, dtype=np.float64) / (65535.0 if im.mode.startswith("I;16") else 1.0)
        else:
            arr = np.asarray(im.convert("L"), dtype=np.float64) / 255.0
    return arr


class GeometryLike(Protocol):
    """A shapely Polygon or MultiPolygon (holes included): as_domain knows one by its geom_type."""

    @property
    def geom_type(self) -> str: ...


#: what `domain` takes (see the module's note): an sdf, a polygon, a mask or an image file
DomainLike = Union[Domain, DomainFunction, GeometryLike, Sequence[npt.ArrayLike], npt.ArrayLike, str,
                   os.PathLike[str]]


def as_domain(obj: DomainLike, d: int, lo: BoundsLike, hi: BoundsLike,
              threshold: float = 0.5) -> Domain:
    """A Domain from a callable, a polygon, a mask or an image file (see the module's note)."""
    if isinstance(obj, Domain):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        if d != 2:
            raise ValueError(f"an image domain covers a 2D box; d = {d}")
        pixels = read_image(obj)
        # mask axis 0 along x[0] (columns), axis 1 along x[1] (rows, bottom to top)
        return Domain.mask(pixels[::-1, :].T, lo, hi, threshold)
    if hasattr(obj, "geom_type"):
        if d != 2:
            raise ValueError(f"a polygon domain is 2D; d = {d}")
        return Domain.polygon(_rings_of_shapely(obj))
    if callable(obj):
        return Domain.from_callable(d, obj)
    if isinstance(obj, (list, tuple)):
        if d != 2:
            raise ValueError(f"a polygon domain is 2D; d = {d}")
        return Domain.polygon(obj)
    arr = np.asarray(obj)
    if d == 2 and arr.ndim == 2 and arr.shape[1] == 2 and arr.dtype != bool and arr.shape[0] >= 3:
        return Domain.polygon([arr])  # (m, 2) vertices; a mask needs Domain.mask for this shape
    if arr.ndim == d:
        return Domain.mask(arr, lo, hi, threshold)
    raise ValueError(f"domain: cannot use {type(obj).__name__} of shape {arr.shape} for d = {d} "
                     "(a callable sdf, a polygon, a mask with d axes, or an image file)")
