"""Checks of the arguments users pass, each failure naming the argument, its value and why.

float() and int() on a bad value say "could not convert string to float: 'a'" and no more;
cffi reads an array of the wrong length past its end. These turn both into a ValueError or
TypeError that names what was passed where, before anything reaches the C library."""
from __future__ import annotations

import numbers
import operator
from typing import Any, Optional

import numpy as np

from .estimate import available_memory

__all__ = ["number", "count", "axis_flags", "room_for_samples"]


def number(name: str, value: Any, hint: str = "") -> float:
    """value as a float, or a TypeError naming `name` (a real number or a 0-d array only: a
    string or a list is not a number)."""
    if isinstance(value, (bool, np.bool_)) or not (
            isinstance(value, numbers.Real) or (isinstance(value, np.ndarray) and value.ndim == 0
                                                and np.issubdtype(value.dtype, np.number))):
        raise TypeError(f"{name} = {value!r}: must be a number{hint}")
    return float(value)


def count(name: str, value: Any) -> int:
    """value as an int >= 0 (an integral float such as 1e6 too), else a ValueError or TypeError
    naming `name`."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, numbers.Real)):
        raise TypeError(f"{name} = {value!r}: must be an integer number of samples")
    if isinstance(value, numbers.Integral):
        n = operator.index(value)  # float() would overflow past 1e308
    elif float(value).is_integer():
        n = int(float(value))
    else:
        raise ValueError(f"{name} = {value!r}: must be an integer number of samples")
    if n < 0:
        raise ValueError(f"{name} = {n}: must be >= 0")
    return n


def axis_flags(name: str, value: Any, d: int) -> list[int]:
    """One flag per axis (booleans, or 0 and 1), as C ints: cffi would read d entries from a
    shorter array past its end."""
    flags = np.asarray(value, dtype=object)
    example = f"[True] * {d}" if d > 1 else "[True]"
    if flags.ndim != 1 or len(flags) != d:
        raise ValueError(f"{name} = {value!r}: give one flag per axis, {d} for d = {d} "
                         f"(e.g. {example})")
    out = []
    for k, f in enumerate(flags):
        if isinstance(f, (bool, np.bool_)) or (isinstance(f, numbers.Integral) and int(f) in (0, 1)):
            out.append(1 if f else 0)
        else:
            raise ValueError(f"{name} = {value!r}: axis {k} has {f!r}; each flag must be True or "
                             "False (or 1 or 0)")
    return out


# The least a sample holds in the C store (its point, radius, scale and flags) and in the
# copies the binding returns (points and scales): a stream of n samples needs at least n times it
def _least_bytes(d: int) -> int:
    return (8 * d + 17) + (8 * d + 8)


def room_for_samples(what: str, n: float, d: int, limit: Optional[int] = None, why: str = "") -> None:
    """A MemoryError, before any work, when n samples cannot fit: not even their points, radii
    and scales in `limit` bytes (0 or None: what the system has available now). why: how n was
    found, when it is not the count asked for."""
    n = min(n, 1e300)  # an int past a float's range needs more than any memory too
    need = float(n) * _least_bytes(d)
    room = limit or available_memory()
    if room is not None and need > room:
        where = "memory_limit" if limit else "the memory available"
        raise MemoryError(f"{what}: {n:.4g} samples{why} need at least {need / 2**20:,.4g} MiB (their "
                          f"points, radii and scales alone), more than {where} ({room / 2**20:,.0f} MiB)")


# tiles per axis past which a tiling's bookkeeping (a record per tile) is no longer what a user
# meant: the C library takes 64-bit counts, and cffi would refuse a negative one with an
# OverflowError that names nothing
_MOST_TILES = 1 << 32


def tile_counts(name: str, value: Any, d: int) -> tuple[int, ...]:
    """Tiles per axis: one int >= 1 (every axis) or d of them."""
    counts = np.atleast_1d(np.asarray(value, dtype=object))
    if counts.ndim != 1 or len(counts) not in (1, d):
        raise ValueError(f"{name} = {value!r}: give 1 or {d} tile counts")
    out = []
    for c in counts:
        if isinstance(c, (bool, np.bool_)) or not isinstance(c, numbers.Integral) or not 1 <= int(c) <= _MOST_TILES:
            raise ValueError(f"{name} = {value!r}: each count must be an int from 1 to {_MOST_TILES}")
        out.append(int(c))
    return tuple(out) * (d if len(out) == 1 else 1)
