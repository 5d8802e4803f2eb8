"""Sizing from an OpenEXR image (read with the OpenEXR Python package).

The image covers the box: column 0 is at x[0] = lo[0], the last column at hi[0]; row 0 is the
top of the image, at x[1] = hi[1] (images count rows downwards), the last row at lo[1]. Pixels
are the nodes of a grid interpolated bilinearly. Pixel values are the radii themselves, or, with
`radius_range=(r_min, r_max)`, values in [0, 1] map linearly onto [r_min, r_max] (values outside
[0, 1] are clipped): black is r_min, white is r_max."""
from __future__ import annotations

from os import PathLike
from typing import TYPE_CHECKING, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._typing import BoundsLike

if TYPE_CHECKING:  # for the annotation: sizing_grid_from_exr imports it itself, when called
    from .sizing_grid import SizingGrid


def read_channel(path: Union[str, PathLike[str]], channel: Optional[str] = None) -> npt.NDArray[np.float64]:
    """One channel as float64, shape (rows, columns); half and float channels alike."""
    try:
        import OpenEXR
    except ImportError as exc:
        raise ImportError("reading .exr sizing images needs the OpenEXR package "
                          "(pip install OpenEXR)") from exc
    with OpenEXR.File(str(path)) as f:
        channels = f.channels()
        names = sorted(channels)
        if channel is None:
            for guess in ("Y", "R", "L"):
                if guess in channels:
                    channel = guess
                    break
            else:
                if len(names) != 1:
                    raise ValueError(f"{path}: channels {names}: choose one (channel=...)")
                channel = names[0]
        if channel not in channels:
            raise ValueError(f"{path}: no channel {channel!r}; it has {names}")
        pixels = np.asarray(channels[channel].pixels, dtype=np.float64)
    if pixels.ndim != 2:
        raise ValueError(f"{path}: channel {channel!r} has shape {pixels.shape}; expected 2D pixels")
    return pixels


def sizing_grid_from_exr(path: Union[str, PathLike[str]], lo: BoundsLike, hi: BoundsLike,
                         channel: Optional[str] = None,
                         radius_range: Optional[Sequence[float]] = None) -> SizingGrid:
    """A SizingGrid over [lo, hi] from an image (see the module's note on orientation)."""
    from .sizing_grid import SizingGrid
    if len(lo) != 2:
        raise ValueError(f"an image sizes a 2D box; the box has {len(lo)} axes")
    pixels = read_channel(path, channel)
    if not np.all(np.isfinite(pixels)):
        raise ValueError(f"{path}: channel {channel or 'default'} has non-finite pixels")
    if radius_range is not None:
        r_min, r_max = (float(v) for v in radius_range)
        if not 0 < r_min <= r_max:
            raise ValueError(f"radius_range = {tuple(radius_range)}: need 0 < r_min <= r_max")
        pixels = r_min + (r_max - r_min) * np.clip(pixels, 0.0, 1.0)
    # grid axis 0 along x[0] (columns), axis 1 along x[1] (rows, bottom to top)
    return SizingGrid(pixels[::-1, :].T, lo, hi)
