"""Type aliases of what the public functions take (annotations only: nothing here is checked)."""
from __future__ import annotations

from typing import Any, Callable, Sequence, Union

import numpy as np
import numpy.typing as npt

__all__ = ["BoolArray", "BoundsLike", "DomainFunction", "FloatArray", "IndexArray", "RngLike",
           "SizingFunction"]

# short names where arrays abound (analysis, plots): float64 values, bool masks, int64 indices
FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]
IndexArray = npt.NDArray[np.int64]

#: one value per axis, shape (d,): a sequence or an array (read value by value)
BoundsLike = Union[Sequence[float], npt.NDArray[Any]]
#: a vectorised r(x): points of shape (m, d) in, (m,) radii out
SizingFunction = Callable[[npt.NDArray[np.float64]], npt.ArrayLike]
#: a vectorised signed distance (negative inside, 1-Lipschitz): points (m, d) in, (m,) out
DomainFunction = Callable[[npt.NDArray[np.float64]], npt.ArrayLike]
#: what `rng` takes (scipy's rule): numpy.random.default_rng's seeds, or a RandomState
RngLike = Union[None, int, np.integer[Any], Sequence[int], np.random.SeedSequence,
                np.random.BitGenerator, np.random.Generator, np.random.RandomState]
