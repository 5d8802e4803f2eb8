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

from ._optional import require
from ._typing import BoundsLike

if TYPE_CHECKING:  # for the annotation: sizing_grid_from_exr imports it itself, when called
    from .sizing_grid import SizingGrid


def _channels(path: Union[str, PathLike[str]]) -> dict[str, npt.NDArray[np.float64]]:
    """Every channel of the file by name, each (rows, columns). OpenEXR's Python API groups R, G,
    B (and A) into one channel 'RGB' or 'RGBA' of shape (rows, columns, 3 or 4), and a layer's
    into 'layer'; they are split here into R, G, B, A (and layer.R, ...) as the file names them.
    A file OpenEXR cannot open is a ValueError naming it."""
    OpenEXR = require("OpenEXR", "reading .exr images", "OpenEXR")
    try:
        try:
            f = OpenEXR.File(str(path), separate_channels=True)
        except TypeError:  # OpenEXR before 3.3: grouped channels only, split below
            f = OpenEXR.File(str(path))
        with f:
            grouped = {name: np.asarray(c.pixels, dtype=np.float64) for name, c in f.channels().items()}
    except RuntimeError as exc:  # OpenEXR's "Unable to open ..." for a missing or corrupt file
        raise ValueError(f"{path}: not a readable OpenEXR file ({exc})") from None
    channels: dict[str, npt.NDArray[np.float64]] = {}
    for name, pixels in grouped.items():
        if pixels.ndim == 3 and 1 <= pixels.shape[2] <= 4:
            letters = name if name in ("RGB", "RGBA") else "RGBA"[:pixels.shape[2]]
            prefix = "" if name in ("RGB", "RGBA") else f"{name}."
            for k, letter in enumerate(letters[:pixels.shape[2]]):
                channels[prefix + letter] = pixels[:, :, k]
        else:
            channels[name] = pixels
    return channels


def read_channel(path: Union[str, PathLike[str]], channel: Optional[str] = None) -> npt.NDArray[np.float64]:
    """One channel as float64, shape (rows, columns); half and float channels alike. The
    default: Y, else R (of an RGB or RGBA image too), else L, else the only channel."""
    channels = _channels(path)
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
    pixels = channels[channel]
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
